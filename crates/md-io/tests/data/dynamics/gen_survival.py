"""The waterdynamics MDAKit's SurvivalProbability (1.2, on MDAnalysis 2.11.0): the reference for
`--survival-table` (crates/cli/tests/convert.rs).

Run from this directory: python3 gen_survival.py   (pip install waterdynamics)

On walk.gro + walk.dcd (gen_dynamics.py: 200 OW and 100 NA atoms on random walks in an 18 A
periodic box, 40 frames), the OW atoms within 2 A of an NA atom (the selection evaluated every
frame, through the periodic box), tau_max 10, continuous and with intermittency 2.
survival_reference.json holds both curves (tau 0..10) and the atoms selected per frame.
"""
import json

import MDAnalysis as mda
from waterdynamics import SurvivalProbability

select = "name OW and around 2.0 name NA"
ref = {"select": select, "tau_max": 10}
for inter in (0, 2):
    u = mda.Universe("walk.gro", "walk.dcd")
    sp = SurvivalProbability(u, select).run(tau_max=10, intermittency=inter)
    ref[f"intermittency_{inter}"] = [float(x) for x in sp.sp_timeseries]
    print(inter, [round(x, 4) for x in sp.sp_timeseries])
u = mda.Universe("walk.gro", "walk.dcd")
ref["selected"] = [sorted(int(i) for i in u.select_atoms(select).indices) for ts in u.trajectory]
json.dump(ref, open("survival_reference.json", "w"))
