"""MDAnalysis 2.11.0's fraction of native contacts (analysis.contacts.Contacts): the reference
for md-io's `contacts` and `--contacts-table` (tests/contacts in crates/md-io/tests/hbonds.rs,
crates/cli/tests/convert.rs).

Run from this directory: python3 gen_contacts.py

On helix.pdb + helix.dcd (gen_dihedrals.py: 3JQH's 23-residue protein, 12 noisy frames), with
frame 0 as the reference (refgroup) and the periodic box (pbc=True), Q per frame for:
- backbone N to O, frame 0's pairs within 3.5 A: by the hard cut (method "hard_cut": the
  share no longer than in frame 0) and by the radius (method "radius_cut": within 3.5 A);
- CA to CA, soft cut (method "soft_cut": 1 / (1 + exp(5 (r - 1.8 r0))) averaged over frame
  0's pairs within 4.5 A, self pairs included as MDAnalysis counts them).
contacts_reference.json holds each case's selections, radius, method, native pair count and Q.
"""
import json

import MDAnalysis as mda
from MDAnalysis.analysis import contacts

cases = [
    ("backbone_hbonds", "name N", "name O", 3.5, "hard_cut"),
    ("backbone_radius", "name N", "name O", 3.5, "radius_cut"),
    ("ca_soft", "name CA", "name CA", 4.5, "soft_cut"),
]
ref = {}
for key, sa, sb, radius, method in cases:
    u = mda.Universe("helix.pdb", "helix.dcd")
    r = mda.Universe("helix.pdb", "helix.dcd")
    r.trajectory[0]
    a, b = r.select_atoms(sa), r.select_atoms(sb)
    c = contacts.Contacts(u, select=(sa, sb), refgroup=(a, b), radius=radius,
                          method=method).run()
    ref[key] = {
        "select_a": sa,
        "select_b": sb,
        "radius": radius,
        "method": method,
        "native": int(c.initial_contacts[0].sum()),
        "q": c.results.timeseries[:, 1].tolist(),
    }
    print(key, ref[key]["native"], [round(q, 4) for q in ref[key]["q"]])
json.dump(ref, open("contacts_reference.json", "w"), indent=1)
