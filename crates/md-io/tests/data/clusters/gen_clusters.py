"""Systems with many clusters, written by OVITO, and OVITO's cluster analysis of them, for
tests/clusters.rs.

gas.xyz: 3,000 atoms placed at random (seed 7, no two closer than 1 A) in a periodic 40 A cube, below and above
continuum percolation at the two cutoffs (2.2 A: many small clusters; 2.6 A: one cluster spans
the periodic box). fecu.xyz: a BCC iron block of 12^3 cells (a = 2.87 A) in which 5 % of the
sites (seed 11) and every site within 6 A of one point are copper: the copper clusters
(precipitate and solutes) at 2.9 A, between BCC's second and third shells. Both as extended XYZ
written by ovito.io.export_file. clusters_reference.json: OVITO 3.17's ClusterAnalysisModifier
(cutoff mode, sort_by_size) per case: every atom's "Cluster" id (0-based since OVITO 3.17, -1 for atoms not selected), the
clusters' sizes counted from the ids, and OVITO's cluster count.

    pip install ovito==3.17.2
    python3 gen_clusters.py
"""
import json
import os

import numpy as np
from ovito.data import DataCollection, ParticleType
from ovito.io import export_file, import_file
from ovito.modifiers import ClusterAnalysisModifier, SelectTypeModifier

here = os.path.dirname(os.path.abspath(__file__))


def write(name, cell, positions, types, names):
    data = DataCollection()
    data.create_cell(cell, pbc=(True, True, True))
    particles = data.create_particles(count=len(positions))
    particles.create_property("Position", data=positions)
    t = particles.create_property("Particle Type", data=types)
    for k, n in enumerate(names):
        t.types.append(ParticleType(id=k + 1, name=n))
    export_file(data, os.path.join(here, name), "xyz",
                columns=["Particle Type", "Position.X", "Position.Y", "Position.Z"])


rng = np.random.default_rng(7)
# Random sequential addition with a 1 A hard core, as a simulated gas has (texmap, like a bond
# finder, takes atoms closer than 0.4 A for damage rather than neighbours).
gas = []
while len(gas) < 3000:
    p = rng.uniform(0, 40, 3)
    if gas:
        d = np.array(gas) - p
        d -= 40 * np.round(d / 40)
        if (d * d).sum(axis=1).min() < 1.0:
            continue
    gas.append(p)
write("gas.xyz", np.diag([40.0, 40.0, 40.0]), np.array(gas), np.ones(3000, dtype=int), ["Ar"])

a, n = 2.87, 12
base = np.array([[0, 0, 0], [0.5, 0.5, 0.5]])
sites = np.array([(np.array([i, j, k]) + b) * a for i in range(n) for j in range(n)
                  for k in range(n) for b in base])
rng = np.random.default_rng(11)
cu = rng.random(len(sites)) < 0.05
cu |= np.linalg.norm(sites - np.array([12.0, 13.0, 14.0]), axis=1) < 6.0
write("fecu.xyz", np.diag([a * n] * 3), sites, np.where(cu, 2, 1), ["Fe", "Cu"])

cases = []
for name, cutoff, only in [("gas.xyz", 2.2, None), ("gas.xyz", 2.6, None), ("fecu.xyz", 2.9, "Cu")]:
    pipe = import_file(os.path.join(here, name),
                       columns=["Particle Type", "Position.X", "Position.Y", "Position.Z"])
    if only:
        pipe.modifiers.append(SelectTypeModifier(types={only}))
    pipe.modifiers.append(ClusterAnalysisModifier(cutoff=cutoff, sort_by_size=True,
                                                  only_selected=only is not None))
    d = pipe.compute()
    ids = d.particles["Cluster"][...]
    sizes = np.bincount(ids[ids >= 0]).tolist()
    cases.append({"file": name, "cutoff": cutoff, "only": only, "ids": ids.tolist(),
                  "sizes": sizes, "count": int(d.attributes["ClusterAnalysis.cluster_count"])})
with open(os.path.join(here, "clusters_reference.json"), "w") as out:
    json.dump(cases, out)
    out.write("\n")
