"""Systems written by OVITO, and OVITO's Voronoi analysis of them, for tests/voronoi.rs.

fcc.xyz: FCC copper (a = 3.615 A), 5^3 cells (500 atoms), periodic, thermal noise of 0.03 A
(seed 4): cells close to rhombic dodecahedra (12 faces) with the slivers noise opens at the
octahedral corners. glass.xyz: 864 atoms of two sizes placed by random sequential addition in a
periodic 23 A cube (seed 8, no two closer than 2.0 A), then relaxed by a few steps of soft
repulsion: a dense, disordered packing. Both as extended XYZ written by ovito.io.export_file.
voronoi_reference.json: OVITO 3.17's VoronoiAnalysisModifier (compute_indices, no radii, no
edge or face thresholds) per file: each atom's "Atomic Volume", "Coordination" and
"Voronoi Index" (faces with 3, 4, 5, 6 edges: components 2 to 5 of OVITO's array, whose
component k counts the faces with k + 1 edges).

    pip install ovito==3.17.2
    python3 gen_voronoi.py
"""
import json
import os
import sys

import numpy as np
from ovito.io import import_file
from ovito.modifiers import VoronoiAnalysisModifier

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(here))
import ovito_single  # noqa: E402
COLUMNS = ovito_single.COLUMNS


def write(name, L, positions):
    ovito_single.write(os.path.join(here, name), np.diag([L, L, L]), positions, "Cu")


a, n = 3.615, 5
base = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]]) + 0.1
sites = np.array([(np.array([i, j, k]) + b) * a for i in range(n) for j in range(n)
                  for k in range(n) for b in base])
rng = np.random.default_rng(4)
write("fcc.xyz", a * n, sites + rng.normal(0, 0.03, sites.shape))

rng = np.random.default_rng(8)
L = 23.0
pts = []
while len(pts) < 864:
    p = rng.uniform(0, L, 3)
    if pts:
        d = np.array(pts) - p
        d -= L * np.round(d / L)
        if (d * d).sum(axis=1).min() < 2.0 ** 2:
            continue
    pts.append(p)
pts = np.array(pts)
for _ in range(20):
    d = pts[:, None, :] - pts[None, :, :]
    d -= L * np.round(d / L)
    r = np.sqrt((d * d).sum(axis=2)) + np.eye(len(pts)) * 1e9
    f = np.where(r < 2.6, (2.6 - r) / r, 0.0)[:, :, None] * d
    pts = (pts + 0.2 * f.sum(axis=1)) % L
write("glass.xyz", L, pts)

cases = []
for name in ["fcc.xyz", "glass.xyz"]:
    pipe = import_file(os.path.join(here, name), columns=COLUMNS)
    pipe.modifiers.append(VoronoiAnalysisModifier(compute_indices=True))
    p = pipe.compute().particles
    index = p["Voronoi Index"][...]
    cases.append({"file": name,
                  "volume": p["Atomic Volume"][...].tolist(),
                  "faces": p["Coordination"][...].tolist(),
                  "index": index[:, 2:6].tolist(),
                  "index_width": int(index.shape[1])})
with open(os.path.join(here, "voronoi_reference.json"), "w") as out:
    json.dump(cases, out)
    out.write("\n")
