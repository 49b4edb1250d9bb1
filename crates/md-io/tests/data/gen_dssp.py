"""Reference secondary structure for tests/secondary.rs, written by MDAnalysis's DSSP.

The chains in dssp/ are wwPDB entries as MDAnalysis's test suite ships them
(MDAnalysisTests 2.11.0, data/dssp/; 1mr1D_failing lacks the C and O of residue 219).
For each chain: the residue numbers and the C3 string of MDAnalysis 2.11's
DSSP(guess_hydrogens=True); for three chains also the two halves on their own
(resid < K and resid >= K), which tests/secondary.rs compares with the chain whose
second half it moves 100 A away (a chain break).

    pip install MDAnalysis==2.11.0
    python3 gen_dssp.py
"""
import glob
import json
import os
import warnings

import MDAnalysis as mda
from MDAnalysis.analysis.dssp import DSSP

warnings.filterwarnings("ignore")
here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "dssp")
SPLIT = {"1h4aX.pdb.gz": None, "3gwiA.pdb.gz": None, "2xcjA.pdb.gz": None}


def run(ag):
    r = DSSP(ag, guess_hydrogens=True).run()
    return [int(x) for x in r.results.resids], "".join(r.results.dssp[0])


out = {}
for f in sorted(glob.glob(os.path.join(here, "*.pdb.gz"))):
    name = os.path.basename(f)
    if "failing" in name:
        continue
    u = mda.Universe(f)
    resids, codes = run(u.atoms)
    e = {"resids": resids, "dssp": codes}
    if name in SPLIT:
        k = resids[len(resids) // 2]
        e["split"] = {
            "at": k,
            "first": run(u.atoms[u.atoms.resids < k])[1],
            "second": run(u.atoms[u.atoms.resids >= k])[1],
        }
    out[name] = e
with open(os.path.join(here, "reference.json"), "w") as fh:
    json.dump(out, fh, indent=1)
    fh.write("\n")
print(len(out), "chains")
