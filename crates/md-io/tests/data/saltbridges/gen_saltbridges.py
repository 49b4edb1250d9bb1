"""Reference salt bridges for tests/hbonds.rs (saltbridges tests), by VMD's saltbr criterion
computed with MDAnalysis 2.11's own distance functions on ../hbonds/adk_top.gro.gz +
../hbonds/adk_0_9.xtc (adenylate kinase in water, 47,681 atoms, rhombic dodecahedron box; see
gen_hbonds.py).

The criterion (VMD's Salt Bridges plugin, ks.uiuc.edu/Research/vmd/plugins/saltbr): an acidic
residue (ASP, GLU and their AMBER terminal spellings; side-chain oxygens OD1 OD2 / OE1 OE2)
and a basic one (ARG, LYS, GROMACS's LYSH and their terminal spellings; side-chain nitrogens
NH1 NH2 NE / NZ; with histidine every histidine spelling, ND1 NE2) form a salt bridge in a
frame when some oxygen and some nitrogen are within the cutoff: `distances.distance_array`
with `box=` (periodic minimum image). For each such pair the reference holds the distance
between the oxygens' and the nitrogens' centroids (each group made whole around its first
atom with `distances.minimize_vectors`, then `distance_array` with the box) and the minimum
O-N distance. The atoms are those of `select_atoms("protein")`.

Written: saltbridges/reference.json, for (cutoff 3.2, no histidine) and (cutoff 4.0, with
histidine): per frame, sorted [acid residue's first atom, base residue's first atom, centroid
distance, minimum O-N distance] rows (0-based atom indices).

    python3 gen_saltbridges.py
"""
import gzip
import json
import os
import shutil
import tempfile
import warnings

import numpy as np
import MDAnalysis as mda
from MDAnalysis.lib import distances

warnings.filterwarnings("ignore")
here = os.path.dirname(os.path.abspath(__file__))
hb = os.path.join(here, "..", "hbonds")
tmp = tempfile.mkdtemp()
gro = os.path.join(tmp, "adk_top.gro")
with gzip.open(os.path.join(hb, "adk_top.gro.gz"), "rb") as f, open(gro, "wb") as g:
    g.write(f.read())
shutil.copy(os.path.join(hb, "adk_0_9.xtc"), os.path.join(tmp, "adk_0_9.xtc"))
u = mda.Universe(gro, os.path.join(tmp, "adk_0_9.xtc"))

ACIDS = {"ASP": ["OD1", "OD2"], "GLU": ["OE1", "OE2"]}
for r in ["ASP", "GLU"]:
    ACIDS["N" + r] = ACIDS["C" + r] = ACIDS[r]
BASES = {"ARG": ["NH1", "NH2", "NE"], "LYS": ["NZ"], "LYSH": ["NZ"]}
for r in ["ARG", "LYS"]:
    BASES["N" + r] = BASES["C" + r] = BASES[r]
HIS = ["HIS", "HIS1", "HIS2", "HISA", "HISB", "HISD", "HISE", "HISH", "HSD", "HSE", "HSP",
       "HID", "HIE", "HIP", "NHID", "NHIE", "NHIP", "CHID", "CHIE", "CHIP"]

protein = u.select_atoms("protein")


def groups(table):
    out = []
    for res in protein.residues:
        names = table.get(res.resname)
        if names is None:
            continue
        atoms = res.atoms[np.isin(res.atoms.names, names)]
        if len(atoms):
            out.append((int(res.atoms[0].ix), atoms))
    return out


def centroid(atoms, box):
    p = atoms.positions.astype(np.float64)
    d = distances.minimize_vectors(p - p[0], box)
    return p[0] + d.mean(axis=0)


out = {"source": "MDAnalysis %s distances, adk_oplsaa frames [0, 9]" % mda.__version__,
       "n_atoms": len(u.atoms), "runs": []}
for cutoff, his in [(3.2, False), (4.0, True)]:
    bases_table = dict(BASES)
    if his:
        for r in HIS:
            bases_table[r] = ["ND1", "NE2"]
    acids, bases = groups(ACIDS), groups(bases_table)
    frames = []
    for ts in u.trajectory:
        box = ts.dimensions
        rows = []
        cents_a = [centroid(a, box) for _, a in acids]
        cents_b = [centroid(b, box) for _, b in bases]
        for (ka, a), ca in zip(acids, cents_a):
            for (kb, b), cb in zip(bases, cents_b):
                d = distances.distance_array(a.positions, b.positions, box=box)
                m = float(d.min())
                if m <= cutoff:
                    c = float(distances.distance_array(ca[None], cb[None], box=box)[0, 0])
                    rows.append([ka, kb, c, m])
        rows.sort()
        frames.append(rows)
    out["runs"].append({"cutoff": cutoff, "histidine": his, "acids": len(acids),
                        "bases": len(bases), "frames": frames})
    print(cutoff, his, len(acids), len(bases), [len(f) for f in frames])
with open(os.path.join(here, "reference.json"), "w") as f:
    json.dump(out, f, indent=None, separators=(",", ":"))
    f.write("\n")
shutil.rmtree(tmp)
