"""Fixtures for the index-group and MDAnalysis-keyword tests of crates/md-io/tests/select.rs.

- make_ndx.ndx: the default groups GROMACS 2022.5 makes for ../tpr/peptide.tpr.gz (two
  peptide chains in TIP4P water with Na+ and Cl-):
      echo q | gmx make_ndx -f peptide.tpr -o make_ndx.ndx
- select.ndx: three dynamic selections written by `gmx select` (nm):
      gmx select -s peptide.tpr -on select.ndx -select \
        '"Near ions" resname SOL and within 0.5 of resname NA CL' \
        'name CA and molindex 2' \
        'same residue as (resname SOL and within 0.6 of (molindex 1 and name CA))'
- reference.json.gz: the atoms MDAnalysis 2.11's select_atoms picks for the selections below,
  on peptide.tpr (its positions, its rhombic-dodecahedron box and its bonds) and on ../1uqc.cif
  (a DNA duplex, read through gemmi), plus MDAnalysis's fragindices (VMD's `fragment`).

    pip install MDAnalysis==2.11.0 gemmi; python3 gen_ndx.py
"""
import gzip
import json
import os
import shutil
import tempfile
import warnings

import MDAnalysis as mda

warnings.filterwarnings("ignore")
here = os.path.dirname(os.path.abspath(__file__))

PEPTIDE = [
    "bonded name CA",
    "bonded (resname SOL and name OW and index 300:400)",
    "bonded (resid 3 and name N)",
    "bonded resname NA",
    "same fragment as index 0",
    "same fragment as (name OW and index 300:400)",
    "same fragment as resname NA CL",
    "sphzone 6 resname NA",
    "sphzone 10 (resid 3 and name CA)",
    "sphlayer 4 8 resname CL",
    "point 10 10 10 5",
    "point 0 0 0 6",
    "point 38 2 55 7",
    "cyzone 8 5 -5 resname NA",
    "cylayer 3 8 6 -6 (resid 5 and name CA)",
    "cyzone 6 12 -2 protein",
    "isolayer 2 4 protein",
    "isolayer 3 5 resname NA",
    "mass 10 to 20",
    "mass 30:40",
    "mass 1.008",
    "mass 0",
    "charge -1 to -0.5",
    "charge 0.5:2",
    "charge -0.8 0.4 to 0.5",
    "resindex 0:3",
    "resindex 20",
    "name OW and sphzone 8 (bonded resname ALA and name CB)",
    "byres isolayer 0 3.5 (resname NA and not sphzone 1 resname CL)",
]
DNA = ["nucleicbackbone", "nucleicbase", "nucleicsugar", "nucleicbase and resid 3:5"]


def picks(u, selections):
    return {s: [int(i) for i in u.select_atoms(s).indices] for s in selections}


tmp = tempfile.mkdtemp()
try:
    tpr = os.path.join(tmp, "peptide.tpr")
    with gzip.open(os.path.join(here, "..", "tpr", "peptide.tpr.gz"), "rb") as f, open(tpr, "wb") as g:
        shutil.copyfileobj(f, g)
    u = mda.Universe(tpr)
    frags = [int(x) for x in u.atoms.fragindices]
    dna = mda.Universe(os.path.join(here, "..", "1uqc.cif"))
    out = {
        "program": f"MDAnalysis {mda.__version__}",
        "peptide": {"n_atoms": int(u.atoms.n_atoms), "selections": picks(u, PEPTIDE), "fragindices": frags},
        "dna": {"n_atoms": int(dna.atoms.n_atoms), "selections": picks(dna, DNA)},
    }
finally:
    shutil.rmtree(tmp)
with gzip.open(os.path.join(here, "reference.json.gz"), "wt") as f:
    json.dump(out, f)
for k in ("peptide", "dna"):
    print(k, {s: len(v) for s, v in out[k]["selections"].items()})
