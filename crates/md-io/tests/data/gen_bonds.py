"""Bonds by distance as ASE 3.29.0 finds them (ase.neighborlist.neighbor_list with
natural_cutoffs, i.e. Cordero 2008 covalent radii, plus a 0.225 Å skin per atom: bonded when
d < r_i + r_j + 0.45 Å), for crates/md-io/tests/bonds.rs. Writes bonds_ase.json: seeded random
C/H/N/O atoms (float32 positions) in a triclinic periodic box and the pairs (i < j, 0.4 Å < d)
ASE finds with and without periodic boundaries.
"""
import json

import ase
import numpy as np
from ase import Atoms
from ase.neighborlist import natural_cutoffs, neighbor_list

rng = np.random.default_rng(20261204)
n = 1500
symbols = rng.choice(["C", "H", "N", "O"], size=n).tolist()
cellpar = [24.0, 26.0, 25.0, 85.0, 95.0, 100.0]
atoms = Atoms(symbols, cell=cellpar, pbc=True)
frac = rng.uniform(0.0, 1.0, size=(n, 3))
pos = (frac @ atoms.cell.array).astype(np.float32).astype(np.float64)
atoms.positions = pos
cut = [c + 0.225 for c in natural_cutoffs(atoms, mult=1.0)]
out = {"program": "ase", "version": ase.__version__, "cellpar": cellpar, "symbols": symbols,
       "positions": pos.tolist()}
for key, pbc in (("periodic", True), ("open", False)):
    atoms.pbc = pbc
    i, j, d = neighbor_list("ijd", atoms, cut)
    keep = (i < j) & (d > 0.4)
    out[key] = sorted({(int(a), int(b)) for a, b in zip(i[keep], j[keep])})
with open("bonds_ase.json", "w") as f:
    json.dump(out, f)
print(len(out["periodic"]), len(out["open"]))
