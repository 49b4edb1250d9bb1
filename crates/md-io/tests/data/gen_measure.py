"""Reference values for the CLI's --measure test (crates/cli/tests/md_inputs.rs): distances,
angles and dihedrals among atoms of MDAnalysis's adk_oplsaa fixture (hbonds/, written by
gen_hbonds.py), frame by frame, by MDAnalysis 2.11's calc_bonds / calc_angles /
calc_dihedrals with the box (nearest periodic images, triclinic).

Run from this directory: python3 gen_measure.py. Writes hbonds/measure_reference.json: per
measurement its spec (as --measure takes it) and its value in each frame.
"""

import json

import MDAnalysis as mda
from MDAnalysis.lib.distances import calc_angles, calc_bonds, calc_dihedrals

u = mda.Universe("hbonds/adk_top.gro.gz", "hbonds/adk_0_9.xtc")
specs = [
    "resid 10 and name CA; resid 20 and name CA",
    # A water far across the box from the protein atom: the nearest image is measured.
    "resid 10 and name CA; index 40000",
    "resid 10 and name N; resid 10 and name CA; resid 10 and name C",
    # The backbone phi of residue 10: C(9)-N-CA-C.
    "resid 9 and name C; resid 10 and name N; resid 10 and name CA; resid 10 and name C",
]
out = []
for spec in specs:
    groups = [u.select_atoms(s.strip()) for s in spec.split(";")]
    assert all(len(g) == 1 for g in groups), spec
    values = []
    for ts in u.trajectory:
        p = [g.positions for g in groups]
        box = ts.dimensions
        if len(p) == 2:
            v = calc_bonds(p[0], p[1], box=box)[0]
        elif len(p) == 3:
            v = calc_angles(p[0], p[1], p[2], box=box)[0] * 180 / 3.141592653589793
        else:
            v = calc_dihedrals(p[0], p[1], p[2], p[3], box=box)[0] * 180 / 3.141592653589793
        values.append(float(v))
    out.append({"spec": spec, "values": values})
with open("hbonds/measure_reference.json", "w") as f:
    json.dump(out, f, indent=1)
print(out)
