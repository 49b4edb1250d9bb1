"""OVITO's radial distribution functions: the reference for md-io's `rdf` (tests/rdf.rs).

Run with OVITO 3.17.2 and numpy from this directory: python3 gen_rdf.py

Writes, with ovito.io.export_file, two periodic binary systems as extended XYZ:
- mixture.xyz: 1,500 atoms (1,000 Si, 500 O) at random positions at least 1.2 A apart (nearest image) in a
  triclinic cell (24 x 25 x 26 A, xy tilt 3 A, xz 2 A), two frames (the second with every atom
  moved by up to 0.2 A);
- small.xyz: 300 atoms (200 Ar, 100 Kr) in a 15 A cube, for a cutoff of 7 A (more than a third
  of the cell, less than half).
and rdf_reference.json: for each file and frame, OVITO's CoordinationAnalysisModifier table
(cutoff, bins): the bin centres, the total g(r), and with partial=True each type pair's g(r)
under the names OVITO gives the columns.
"""
import json

import numpy as np
from ovito.data import DataCollection, SimulationCell, Particles
from ovito.io import export_file, import_file
from ovito.modifiers import CoordinationAnalysisModifier
from ovito.pipeline import Pipeline, StaticSource

rng = np.random.default_rng(20261206)


def random_positions(n, cell, min_dist):
    """n points of the cell, none closer than min_dist to another (nearest image)."""
    m = np.array(cell, dtype=float)
    fracs = np.empty((0, 3))
    while len(fracs) < n:
        f = rng.random(3)
        d = fracs - f
        d -= np.round(d)
        if len(fracs) == 0 or np.min(np.linalg.norm(d @ m, axis=1)) >= min_dist:
            fracs = np.vstack([fracs, f])
    return fracs @ m


def system(path, cell, names, counts, frames, min_dist, jiggle):
    n = sum(counts)
    pos = random_positions(n, cell, min_dist)
    types = np.concatenate([[k + 1] * c for k, c in enumerate(counts)])
    out = []
    for f in range(frames):
        data = DataCollection()
        c = data.create_cell(np.column_stack([np.array(cell).T, [0, 0, 0]]), pbc=(True, True, True))
        parts = data.create_particles(count=n)
        parts.create_property("Position", data=pos)
        t = parts.create_property("Particle Type", data=types)
        for k, name in enumerate(names):
            t.types.append(ovito.data.ParticleType(id=k + 1, name=name))
        out.append(data)
        pos = pos + rng.uniform(-jiggle, jiggle, size=pos.shape)
    return out


import ovito.data  # noqa: E402

reference = []
for path, cell, names, counts, frames, cutoff, bins in [
    ("mixture.xyz", [[24, 0, 0], [3, 25, 0], [2, 0, 26]], ["Si", "O"], [1000, 500], 2, 6.0, 60),
    ("small.xyz", [[15, 0, 0], [0, 15, 0], [0, 0, 15]], ["Ar", "Kr"], [200, 100], 1, 7.0, 35),
]:
    datas = system(path, cell, names, counts, frames, 1.2, 0.2)
    # One file, a frame per configuration.
    pipe = Pipeline(source=StaticSource(data=datas[0]))
    export_file(pipe, path, "xyz", columns=["Particle Type", "Position.X", "Position.Y", "Position.Z"])
    if frames > 1:
        text = open(path).read()
        for d in datas[1:]:
            p = Pipeline(source=StaticSource(data=d))
            export_file(p, "tmp.xyz", "xyz", columns=["Particle Type", "Position.X", "Position.Y", "Position.Z"])
            text += open("tmp.xyz").read()
        open(path, "w").write(text)
        import os
        os.remove("tmp.xyz")
    # OVITO's RDF of each frame as read back from the file (the written precision).
    pipe = import_file(path)
    pipe.modifiers.append(CoordinationAnalysisModifier(cutoff=cutoff, number_of_bins=bins, partial=True))
    total = import_file(path)
    total.modifiers.append(CoordinationAnalysisModifier(cutoff=cutoff, number_of_bins=bins))
    for f in range(pipe.source.num_frames):
        data = pipe.compute(f)
        table = data.tables["coordination-rdf"]
        xy = table.xy()
        g_total = total.compute(f).tables["coordination-rdf"].xy()[:, 1].tolist()
        reference.append({
            "total": g_total,
            "file": path,
            "frame": f,
            "cutoff": cutoff,
            "bins": bins,
            "r": xy[:, 0].tolist(),
            "columns": list(table.y.component_names),
            "g": xy[:, 1:].T.tolist(),
        })
        print(path, f, table.y.component_names, xy.shape)

json.dump(reference, open("rdf_reference.json", "w"))
