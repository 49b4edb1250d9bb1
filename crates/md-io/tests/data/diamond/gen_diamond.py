"""Diamond-lattice crystals written by OVITO, and OVITO's Identify diamond structure of them,
for tests/diamond.rs (md-io).

As extended XYZ by ovito.io.export_file (through ../ovito_single.py), silicon:

- cubic.xyz: cubic diamond, a = 5.431 A, 5^3 unit cells (1,000 sites), periodic, one vacancy
  (site 0 removed) and thermal noise of 0.05 A (seed 31);
- hexagonal.xyz: hexagonal diamond (lonsdaleite stacking), a = 3.840 A, c = 6.271 A,
  6 x 6 x 4 cells on an orthogonal box (8 atoms per rectangular cell), periodic, noise 0.04 A;
- slab.xyz: cubic diamond 4^3 cells with 12 A of vacuum above and below along z (free
  surfaces), noise 0.03 A.

diamond_reference.json: per file, OVITO 3.17's IdentifyDiamondModifier "Structure Type" of
every atom (0 other, 1 cubic diamond, 2 and 3 its first and second neighbours, 4 hexagonal
diamond, 5 and 6 its first and second neighbours).

    pip install ovito==3.17.2
    python3 gen_diamond.py
"""
import json
import os
import sys

import numpy as np
from ovito.io import import_file
from ovito.modifiers import IdentifyDiamondModifier

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(here))
import ovito_single  # noqa: E402

fcc = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])
cubic_basis = np.concatenate([fcc, fcc + 0.25]) + 0.05


def cubic(n, a):
    return np.array([(np.array([i, j, k]) + b) * a for i in range(n) for j in range(n)
                     for k in range(n) for b in cubic_basis])


cases = []
rng = np.random.default_rng(31)
a = 5.431
sites = cubic(5, a)[1:]
ovito_single.write(os.path.join(here, "cubic.xyz"), np.eye(3) * 5 * a,
                   sites + rng.normal(0, 0.05, sites.shape), "Si")

# Hexagonal diamond on an orthogonal cell: a, sqrt(3) a, c with 8 atoms.
ah, ch, u = 3.840, 6.271, 3.0 / 8.0
basis = []
for fx, fy, fz in [(0, 0, 0), (0.5, 0.5, 0), (0, 1 / 3, 0.5), (0.5, 5 / 6, 0.5)]:
    basis.append([fx, fy, fz])
for fx, fy, fz in [(0, 1 / 3, u), (0.5, 5 / 6, u), (0, 0, 0.5 + u), (0.5, 0.5, 0.5 + u)]:
    basis.append([fx, fy, fz])
basis = np.array(basis) + 0.02
cell = np.array([ah, ah * np.sqrt(3), ch])
nx, ny, nz = 6, 4, 4
hexa = np.array([(np.array([i, j, k]) + b) * cell for i in range(nx) for j in range(ny)
                 for k in range(nz) for b in basis])
rng = np.random.default_rng(32)
ovito_single.write(os.path.join(here, "hexagonal.xyz"), np.diag(cell * [nx, ny, nz]),
                   hexa + rng.normal(0, 0.04, hexa.shape), "Si")

rng = np.random.default_rng(33)
slab = cubic(4, a)
slab[:, 2] += 12.0
ovito_single.write(os.path.join(here, "slab.xyz"), np.diag([4 * a, 4 * a, 4 * a + 24.0]),
                   slab + rng.normal(0, 0.03, slab.shape), "Si")

for name in ["cubic.xyz", "hexagonal.xyz", "slab.xyz"]:
    pipe = import_file(os.path.join(here, name), columns=ovito_single.COLUMNS)
    pipe.modifiers.append(IdentifyDiamondModifier())
    types = pipe.compute().particles["Structure Type"][...].tolist()
    cases.append({"file": name, "structure": types})
    print(name, len(types), [types.count(t) for t in range(7)])
with open(os.path.join(here, "diamond_reference.json"), "w") as out:
    json.dump(cases, out)
    out.write("\n")
