"""Crystals and OVITO's adaptive common neighbour analysis of them, for tests/cna.rs.

crystals.xyz.gz (extended XYZ, written by ASE, gzipped with mtime 0): five frames, each a different system,
  0 FCC Cu 7x7x7 conventional cells, 1,372 atoms, three atoms removed (a vacancy cluster),
    Gaussian noise 0.06 A;
  1 BCC Fe 8x8x8, 1,024 atoms, noise 0.06 A;
  2 HCP Mg 8x8x6 orthorhombic-free (ASE's hexagonal cell, triclinic), 768 atoms, noise 0.05 A;
  3 FCC Al 6x6x6 with an intrinsic stacking fault (a (111) layer shifted), noise 0.04 A,
    non-periodic along z (a free surface: no cell in z is not expressible in extended XYZ,
    so the cell is made 30 A longer than the crystal);
  4 an icosahedral Cu cluster of 147 atoms (no cell).
cna_reference.json: per frame, OVITO 3.17's CommonNeighborAnalysisModifier (adaptive mode)
structure type per atom (0 other, 1 FCC, 2 HCP, 3 BCC, 4 ICO) and the counts.

    pip install ase==3.29.0 ovito==3.17.2
    python3 gen_cna.py
"""
import gzip
import json
import os

import numpy as np
from ase.build import bulk
from ase.cluster import Icosahedron
from ase.io import write

here = os.path.dirname(os.path.abspath(__file__))
rng = np.random.default_rng(20261204)


def jiggle(atoms, sigma):
    atoms.positions += rng.normal(0, sigma, atoms.positions.shape)
    return atoms


frames = []
cu = bulk("Cu", "fcc", a=3.615, cubic=True).repeat((7, 7, 7))
centre = cu.cell.sum(axis=0) / 2
gone = np.argsort(np.linalg.norm(cu.positions - centre, axis=1))[:3]
del cu[list(gone)]
frames.append(jiggle(cu, 0.06))
frames.append(jiggle(bulk("Fe", "bcc", a=2.8665, cubic=True).repeat((8, 8, 8)), 0.06))
frames.append(jiggle(bulk("Mg", "hcp", a=3.209, c=5.211).repeat((8, 8, 6)), 0.05))
# FCC along [111]: the hexagonal setting of fcc (ABC stacking) via ase.build.fcc111.
from ase.build import fcc111
al = fcc111("Al", size=(8, 8, 12), a=4.05, periodic=True, orthogonal=False)
z = al.positions[:, 2]
layers = np.unique(np.round(z, 3))
# Shift every layer above the middle by a/sqrt(6) along [11-2]-ish in-plane: an intrinsic fault.
shift = al.cell[0] / 3 + al.cell[1] / 3
shift = shift / np.linalg.norm(shift) * 4.05 / np.sqrt(6)
above = z > layers[len(layers) // 2] + 0.1
al.positions[above] += shift
al.cell[2] = al.cell[2] + [0, 0, 30.0]
al.pbc = [True, True, True]
frames.append(jiggle(al, 0.04))
ico = Icosahedron("Cu", noshells=4, latticeconstant=3.615)
ico.cell = [0, 0, 0]
ico.pbc = False
frames.append(jiggle(ico, 0.02))
xyz = os.path.join(here, "crystals.xyz")
write(xyz, frames, format="extxyz")

from ovito.io import import_file
from ovito.modifiers import CommonNeighborAnalysisModifier

out = {"program": "ovito", "modifier": "CommonNeighborAnalysisModifier(mode=AdaptiveCutoff)",
       "types": ["other", "fcc", "hcp", "bcc", "ico"], "frames": []}
for k, atoms in enumerate(frames):
    single = os.path.join(here, "_single.xyz")
    write(single, atoms, format="extxyz")
    pipe = import_file(single)
    pipe.modifiers.append(CommonNeighborAnalysisModifier(mode=CommonNeighborAnalysisModifier.Mode.AdaptiveCutoff))
    data = pipe.compute()
    types = [int(t) for t in data.particles["Structure Type"]]
    counts = [types.count(t) for t in range(5)]
    out["frames"].append({"atoms": len(atoms), "pbc": bool(atoms.pbc.any()), "counts": counts,
                          "types": "".join(str(t) for t in types)})
    os.remove(single)
    print(k, len(atoms), counts)
with open(xyz, "rb") as fh, open(xyz + ".gz", "wb") as raw:
    with gzip.GzipFile(fileobj=raw, mode="wb", mtime=0, filename="") as gz:
        gz.write(fh.read())
os.remove(xyz)
with open(os.path.join(here, "cna_reference.json"), "w") as fh:
    json.dump(out, fh)
    fh.write("\n")
