"""Open (non-periodic) cell edges, as OVITO 3.17.2 writes and reads them, for tests/boundaries.rs.

Run from this directory: python3 gen_boundaries.py (ovito==3.17.2, numpy).

- slab.lammpstrj (OVITO's LAMMPS dump exporter: `BOX BOUNDS abc origin pp pp ff`) and
  slab.xyz (OVITO's extended XYZ exporter: `pbc="T T F"`): 720 copper atoms, an FCC film
  (a = 3.615 A) of 6 x 6 x 5 cubic cells, each atom moved by N(0, 0.04 A) per axis (seeded),
  periodic along x and y, its cell along z shrink-wrapped to the atoms' extent as LAMMPS's `s`
  boundary makes it: across that edge the bottom layer's periodic image would sit on the top
  layer.
- particle.lammpstrj (`ff ff ff`): the 369 atoms of the same jiggled FCC lattice within 10 A of
  a lattice site, in a box shrink-wrapped to them on all three axes.
- boundaries_reference.json: what OVITO computes on each file as it imports it (pbc from the
  file): every atom's adaptive CNA type (0 other, 1 FCC, 2 HCP, 3 BCC, 4 ICO) and
  coordination number within 3.0 A (between the first and second shells), and the cell's pbc
  flags.
"""
import json
import os

import numpy as np
from ovito.data import DataCollection
from ovito.io import export_file, import_file
from ovito.modifiers import CommonNeighborAnalysisModifier, CoordinationAnalysisModifier
from ovito.pipeline import Pipeline, StaticSource

here = os.path.dirname(os.path.abspath(__file__))
rng = np.random.default_rng(61208)
a = 3.615
basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])


def lattice(n):
    cells = np.array([[i, j, k] for i in range(n[0]) for j in range(n[1]) for k in range(n[2])])
    return ((cells[:, None, :] + basis[None]) * a).reshape(-1, 3)


def write(name, positions, lengths, origin, pbc, formats):
    d = DataCollection()
    m = np.zeros((3, 4))
    m[:, :3] = np.diag(lengths)
    m[:, 3] = origin
    d.create_cell(m, pbc=pbc)
    p = d.create_particles(count=len(positions))
    p.create_property("Position", data=positions)
    types = p.create_property("Particle Type", data=np.ones(len(positions), dtype=int))
    types.add_type_id(1, p, name="Cu")
    p.create_property("Particle Identifier", data=np.arange(1, len(positions) + 1))
    pipe = Pipeline(source=StaticSource(data=d))
    for fmt, ext, cols in formats:
        export_file(pipe, os.path.join(here, name + ext), fmt, columns=cols)


dump_cols = ["Particle Identifier", "Particle Type", "Position.X", "Position.Y", "Position.Z"]
xyz_cols = ["Particle Type", "Position.X", "Position.Y", "Position.Z"]

slab = lattice((6, 6, 5)) + rng.normal(0.0, 0.04, size=(720, 3))
lo, hi = slab.min(axis=0), slab.max(axis=0)
write("slab", slab, [6 * a, 6 * a, hi[2] - lo[2]], [0.0, 0.0, lo[2]], (True, True, False),
      [("lammps/dump", ".lammpstrj", dump_cols), ("xyz", ".xyz", xyz_cols)])

bulk = lattice((8, 8, 8))
centre = bulk[np.argmin(np.linalg.norm(bulk - 4 * a, axis=1))]
ball = bulk[np.linalg.norm(bulk - centre, axis=1) <= 10.0]
ball = ball + rng.normal(0.0, 0.04, size=ball.shape)
lo, hi = ball.min(axis=0), ball.max(axis=0)
write("particle", ball, hi - lo, lo, (False, False, False),
      [("lammps/dump", ".lammpstrj", dump_cols)])

reference = {}
for name in ("slab.lammpstrj", "slab.xyz", "particle.lammpstrj"):
    pipe = import_file(os.path.join(here, name))
    pipe.modifiers.append(CommonNeighborAnalysisModifier(mode=CommonNeighborAnalysisModifier.Mode.AdaptiveCutoff))
    pipe.modifiers.append(CoordinationAnalysisModifier(cutoff=3.0, number_of_bins=50))
    d = pipe.compute()
    types = d.particles["Structure Type"][...]
    reference[name] = {
        "atoms": int(d.particles.count),
        "pbc": [bool(x) for x in d.cell.pbc],
        "types": "".join(str(int(t)) for t in types),
        "coordination": d.particles["Coordination"][...].tolist(),
        "counts": np.bincount(types, minlength=5).tolist(),
    }
    print(name, reference[name]["pbc"], reference[name]["counts"])
with open(os.path.join(here, "boundaries_reference.json"), "w") as out:
    json.dump(reference, out)
    out.write("\n")
