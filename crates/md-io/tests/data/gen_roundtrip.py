"""What ASE and MDAnalysis read from files OUR writers wrote (round trip, recorded at dev time).

    mkdir -p /tmp/rt && MDTEXT_WRITE_ROUNDTRIP=/tmp/rt cargo test -p texmap-md-io --test suite text_access::
    python3 gen_roundtrip.py /tmp/rt      # writes roundtrip_reference.json here

ours.xyz: our XYZ writer on the frames of ase_ext.xyz, read by ASE (extxyz).
ours.pdb: our PDB writer on the frames of mda_multi.pdb, read by MDAnalysis.
ours_h36.pdb: 100,010 atoms with hybrid-36 serials / residue numbers, read by MDAnalysis
              (probes at a few indices; the file itself is not kept: the test rebuilds it).
"""
import json
import sys
import warnings

import ase
import MDAnalysis as mda
from ase.io import read

warnings.filterwarnings("ignore")
d = sys.argv[1]
out = {"programs": {"ase": ase.__version__, "MDAnalysis": mda.__version__}}
out["ours.xyz"] = [
    {"positions": a.positions.tolist(), "cell": a.cell.array.tolist(),
     "radius": a.arrays["radius"].tolist(), "color": a.arrays["color"].tolist(),
     "symbols": a.get_chemical_symbols()}
    for a in read(f"{d}/ours.xyz", index=":", format="extxyz")
]
u = mda.Universe(f"{d}/ours.pdb")
out["ours.pdb"] = [
    {"positions": u.atoms.positions.tolist(), "names": list(u.atoms.names),
     "elements": list(u.atoms.elements), "ids": u.atoms.ids.tolist(),
     "dimensions": (ts.dimensions if ts.dimensions is not None else u.trajectory[0].dimensions).tolist()}
    for ts in u.trajectory
]
u = mda.Universe(f"{d}/ours_h36.pdb")
probes = [0, 9998, 9999, 29997, 29998, 99998, 99999, 100000, 100009]
out["ours_h36.pdb"] = {
    "n_atoms": int(u.atoms.n_atoms),
    "probes": [{"index": i, "id": int(u.atoms.ids[i]), "resid": int(u.atoms.resids[i]),
                "position": u.atoms.positions[i].tolist()} for i in probes],
}
json.dump(out, open("roundtrip_reference.json", "w"), indent=0)
