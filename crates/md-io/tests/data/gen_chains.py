"""Write chains_mda.pdb with MDAnalysis (chain identifiers in column 22, segment identifiers in
columns 73-76) and what MDAnalysis selects on it for chain and segment selections
(chains_reference.json), for crates/md-io/tests/select.rs. Also records the segment of every
atom of psf_parmed.psf (ParmEd's PSF, see gen_psf.py) as MDAnalysis reads it.

The system: two alanine chains A and B (segments PROA, PROB, 8 residues of N H CA HA CB HB1 HB2
HB3 C O each), 60 waters in chain W (segment SOLV), 4 sodium ions with a blank chain, which
MDAnalysis's writer turns into its default chain X (segment IONS), and a 6-nucleotide DNA strand
(P C4' N1 per residue, DA5 ... DC3) in chain D (segment DNA1): 362 atoms at seeded random
positions in a 30 A cube. ParmEd names its PSF's one segment SYS.

Run with MDAnalysis 2.11 (`pip install MDAnalysis`): `python3 gen_chains.py`.
"""
import json
import warnings

import MDAnalysis as mda
import numpy as np

warnings.filterwarnings("ignore")

ala = ["N", "H", "CA", "HA", "CB", "HB1", "HB2", "HB3", "C", "O"]
names, elements, resindex = [], [], []
resnames, resids, segindex = [], [], []
chain_of_segment = {"PROA": "A", "PROB": "B", "SOLV": "W", "IONS": "", "DNA1": "D"}
segments = list(chain_of_segment)
r = 0
for seg in (0, 1):
    for k in range(8):
        for a in ala:
            names.append(a); elements.append(a[0]); resindex.append(r)
        resnames.append("ALA"); resids.append(k + 1); segindex.append(seg); r += 1
for k in range(60):
    for a, e in (("OW", "O"), ("HW1", "H"), ("HW2", "H")):
        names.append(a); elements.append(e); resindex.append(r)
    resnames.append("SOL"); resids.append(k + 1); segindex.append(2); r += 1
for k in range(4):
    names.append("NA"); elements.append("Na"); resindex.append(r)
    resnames.append("NA"); resids.append(k + 1); segindex.append(3); r += 1
for k, base in enumerate(["DA5", "DC", "DG", "DT", "DA", "DC3"]):
    for a, e in (("P", "P"), ("C4'", "C"), ("N1", "N")):
        names.append(a); elements.append(e); resindex.append(r)
    resnames.append(base); resids.append(k + 1); segindex.append(4); r += 1

n = len(names)
u = mda.Universe.empty(n, n_residues=r, n_segments=len(segments), atom_resindex=resindex,
                       residue_segindex=segindex, trajectory=True)
u.add_TopologyAttr("name", names)
u.add_TopologyAttr("resname", resnames)
u.add_TopologyAttr("resid", resids)
u.add_TopologyAttr("segid", segments)
u.add_TopologyAttr("element", elements)
u.add_TopologyAttr("chainID", [chain_of_segment[segments[segindex[resindex[i]]]]
                               for i in range(n)])
rng = np.random.default_rng(20261203)
u.atoms.positions = rng.uniform(0.0, 30.0, size=(n, 3)).astype(np.float32)
u.atoms.write("chains_mda.pdb")

# Read it back, as a user would, and select.
v = mda.Universe("chains_mda.pdb")
selections = [
    "chainID A",
    "chainID A B",
    "chainID W and name OW",
    "segid PROB",
    "segid PRO*",
    "segid IONS SOLV",
    "not segid SOLV",
    "chainID B and resid 3:5 and name CA",
    "protein and not chainID A",
    "segid PROA and around 3.0 segid PROB",
    "nucleic",
    "nucleic and name P and not resname DA5",
]
psf = mda.Universe("psf_parmed.psf")
out = {
    "program": f"MDAnalysis {mda.__version__}",
    "n_atoms": int(v.atoms.n_atoms),
    "chains": [str(c) for c in v.atoms.chainIDs],
    "segments": [str(s) for s in v.atoms.segids],
    "selections": {s: [int(i) for i in v.select_atoms(s).indices] for s in selections},
    "psf_segments": [str(s) for s in psf.atoms.segids],
}
with open("chains_reference.json", "w") as f:
    json.dump(out, f, indent=1)
    f.write("\n")
print(out["n_atoms"], {s: len(ix) for s, ix in out["selections"].items()})
