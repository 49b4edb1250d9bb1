"""Write select_mda.pdb with MDAnalysis and the atoms MDAnalysis itself selects for each of a list
of selection strings (select_reference.json), for crates/md-io/tests/select.rs.

30 alanines (N H CA HA CB HB1 HB2 HB3 C O), 200 waters (OW HW1 HW2, resname SOL) and 5 sodium
ions (NA), 905 atoms at seeded random positions in a 40 Å cube, no periodic box (so `around`
uses plain distances in both programs).
"""
import json

import MDAnalysis as mda
import numpy as np

ala = ["N", "H", "CA", "HA", "CB", "HB1", "HB2", "HB3", "C", "O"]
names, resnames, resids, elements, resindex = [], [], [], [], []
r = 0
for k in range(30):
    for a in ala:
        names.append(a); resnames.append("ALA"); elements.append(a[0]); resindex.append(r)
    resids.append(k + 1); r += 1
for k in range(200):
    for a, e in (("OW", "O"), ("HW1", "H"), ("HW2", "H")):
        names.append(a); resnames.append("SOL"); elements.append(e); resindex.append(r)
    resids.append(31 + k); r += 1
for k in range(5):
    names.append("NA"); resnames.append("NA"); elements.append("Na"); resindex.append(r)
    resids.append(231 + k); r += 1

n = len(names)
u = mda.Universe.empty(n, n_residues=r, atom_resindex=resindex, trajectory=True)
u.add_TopologyAttr("name", names)
u.add_TopologyAttr("resname", [resnames[resindex.index(i)] for i in range(r)])
u.add_TopologyAttr("resid", resids)
u.add_TopologyAttr("element", elements)
rng = np.random.default_rng(20261202)
u.atoms.positions = rng.uniform(0.0, 40.0, size=(n, 3)).astype(np.float32)
u.atoms.write("select_mda.pdb")

# Read it back, as a user would, and select.
v = mda.Universe("select_mda.pdb")
selections = [
    "name CA",
    "not resname SOL",
    "element O and resid 1:20",
    "resid 5-10 and not name H*",
    "backbone",
    "protein",
    "index 10:20",
    "bynum 1:5",
    "around 4.0 resname NA",
    "name C* and not (resname SOL or element H)",
    "resname NA or (resid 3 and name O)",
    "name HW? and resid 40:45",
    "not protein and not resname SOL",
    "byres around 4.0 resname NA",
    "byres name CA and resid 3:5",
    "same resname as around 3.0 resname NA",
    "same residue as (name OW and around 3.0 resname NA)",
    "name O and around 4.0 resname NA and resid 1:15",
    "same resid as bynum 1 2 3",
]
out = {
    "program": f"MDAnalysis {mda.__version__}",
    "n_atoms": int(v.atoms.n_atoms),
    "selections": {s: [int(i) for i in v.select_atoms(s).indices] for s in selections},
}
with open("select_reference.json", "w") as f:
    json.dump(out, f, indent=1)
print({s: len(ix) for s, ix in out["selections"].items()})
