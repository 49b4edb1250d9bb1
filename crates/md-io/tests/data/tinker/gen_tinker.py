"""Tinker coordinate files: molecules written by Open Babel 3.1.1 (openbabel-wheel), a periodic
archive written here in Tinker's own layout; all read back by MDAnalysis 2.11.

Writes, beside this script:
  caffeine.txyz   Open Babel `-otxyz` of caffeine embedded by RDKit (ETKDG, seed 7; MM2 types)
  ethanol.xyz     Open Babel `-otxyz` of ethanol, named .xyz as Tinker names its files
  water_box.arc   3 frames of 30 seeded waters in a 10 x 11 x 12 Å box (drifting), each frame a
                  header, Tinker's box line (a b c alpha beta gamma, %12.6f) and atom lines as
                  Tinker's prtxyz writes them (%6d  %-3s%12.6f x3 %6d then bonded indices %6d)
  reference.json  MDAnalysis's reading (TXYZParser + TXYZReader): names, types, bonds, positions
                  and boxes per frame
"""
import json
import os
import subprocess

import numpy as np
from rdkit import Chem
from rdkit.Chem import AllChem
import MDAnalysis as mda

here = os.path.dirname(os.path.abspath(__file__))


def obabel_txyz(smiles, out):
    mol = Chem.AddHs(Chem.MolFromSmiles(smiles))
    AllChem.EmbedMolecule(mol, randomSeed=7)
    sdf = os.path.join(here, "_tmp.sdf")
    Chem.MolToMolFile(mol, sdf)
    subprocess.run(["obabel", sdf, "-otxyz", "-O", os.path.join(here, out)],
                   check=True, capture_output=True)
    os.remove(sdf)


obabel_txyz("Cn1cnc2c1c(=O)n(C)c(=O)n2C", "caffeine.txyz")
obabel_txyz("CCO", "ethanol.xyz")

rng = np.random.default_rng(5)
box = np.array([10.0, 11.0, 12.0])
centres = rng.uniform(0, 1, size=(30, 3)) * box
lines = []
for k in range(3):
    lines.append("%6d  %s" % (90, "water box frame %d" % k))
    lines.append("".join("%12.6f" % v for v in [*(box + 0.1 * k), 90.0, 90.0, 90.0]))
    for w, c in enumerate(centres + 0.05 * k):
        o = 3 * w + 1
        h1 = c + [0.9572, 0.0, 0.0]
        h2 = c + [-0.24, 0.927, 0.0]
        lines.append("%6d  %-3s%12.6f%12.6f%12.6f%6d%6d%6d" % (o, "O", *c, 1, o + 1, o + 2))
        lines.append("%6d  %-3s%12.6f%12.6f%12.6f%6d%6d" % (o + 1, "H", *h1, 2, o))
        lines.append("%6d  %-3s%12.6f%12.6f%12.6f%6d%6d" % (o + 2, "H", *h2, 2, o))
with open(os.path.join(here, "water_box.arc"), "w") as f:
    f.write("\n".join(lines) + "\n")

ref = {}
for name, fmt in [("caffeine.txyz", "TXYZ"), ("ethanol.xyz", "TXYZ"), ("water_box.arc", "ARC")]:
    u = mda.Universe(os.path.join(here, name), format=fmt, topology_format=fmt)
    ref[name] = {
        "names": [str(x) for x in u.atoms.names],
        "types": [str(x) for x in u.atoms.types],
        "bonds": sorted([sorted([int(b[0].index), int(b[1].index)]) for b in u.bonds]),
        "positions": [ts.positions.astype(float).tolist() for ts in u.trajectory],
        "boxes": [None if ts.dimensions is None else [float(x) for x in ts.dimensions]
                  for ts in u.trajectory],
    }
with open(os.path.join(here, "reference.json"), "w") as f:
    json.dump(ref, f, separators=(",", ":"))
    f.write("\n")
