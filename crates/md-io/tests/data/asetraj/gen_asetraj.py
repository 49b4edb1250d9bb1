"""ASE trajectory files (.traj, ASE's ULM binary format) and what ASE itself reads from them,
for crates/md-io/tests/asetraj.rs.

- cu_md.traj: 32 Cu atoms (EMT calculator), 2 fs velocity-Verlet steps from a seeded
  Maxwell-Boltzmann start: 4 frames with momenta, forces, per-atom energies, energy, stress.
- slab.traj: an Al(111) slab (triclinic cell, pbc T T F) with FixAtoms, tags and custom
  masses, 3 rattled frames and no calculator.
- mixed.traj: a water molecule (no cell, pbc F F F, initial charges and magnetic moments),
  then methane, then water again: frames whose atoms differ (ASE then writes the numbers in
  every item).
- reference.json.gz: per file and frame, ASE's Trajectory reading: numbers, positions, cell,
  pbc, masses, velocities (ASE's get_velocities() in Å/ps: times 1000 units.fs), forces,
  per-atom energies, energy, tags, charges, magnetic moments.

    pip install ase==3.29.0; python3 gen_asetraj.py
"""
import gzip
import json
import os

import numpy as np
from ase import Atoms, units
from ase.build import bulk, fcc111, molecule
from ase.calculators.emt import EMT
from ase.constraints import FixAtoms
from ase.io import Trajectory
from ase.md.velocitydistribution import MaxwellBoltzmannDistribution
from ase.md.verlet import VelocityVerlet

here = os.path.dirname(os.path.abspath(__file__))
os.chdir(here)

cu = bulk("Cu", "fcc", a=3.6, cubic=True) * (2, 2, 2)
cu.calc = EMT()
MaxwellBoltzmannDistribution(cu, temperature_K=300, rng=np.random.default_rng(3))
with Trajectory("cu_md.traj", "w", cu) as t:
    dyn = VelocityVerlet(cu, 2 * units.fs)
    dyn.attach(t.write, interval=1)
    dyn.run(3)

slab = fcc111("Al", size=(2, 2, 3), vacuum=6.0)
slab.set_constraint(FixAtoms(indices=[a.index for a in slab if a.tag == 3]))
slab.set_masses([26.98 + 0.01 * i for i in range(len(slab))])
rng = np.random.default_rng(7)
with Trajectory("slab.traj", "w") as t:
    for k in range(3):
        s = slab.copy()
        s.positions += rng.normal(0.0, 0.05, s.positions.shape)
        t.write(s)

water = molecule("H2O")
water.set_initial_charges([-0.8, 0.4, 0.4])
water.set_initial_magnetic_moments([0.0, 0.5, 0.5])
methane = molecule("CH4")
with Trajectory("mixed.traj", "w") as t:
    t.write(water)
    t.write(methane)
    w2 = water.copy()
    w2.positions += 0.1
    t.write(w2)


def frames(path):
    out = []
    for a in Trajectory(path):
        f = {
            "numbers": a.numbers.tolist(),
            "positions": a.positions.tolist(),
            "cell": a.cell.array.tolist(),
            "pbc": a.pbc.tolist(),
            "masses": a.get_masses().tolist(),
            "tags": a.get_tags().tolist(),
            "charges": a.get_initial_charges().tolist(),
            "magmoms": a.get_initial_magnetic_moments().tolist(),
        }
        if a.has("momenta"):
            f["velocities"] = (a.get_velocities() * 1000 * units.fs).tolist()
        if a.calc is not None:
            f["energy"] = a.get_potential_energy()
            f["forces"] = a.get_forces().tolist()
            f["energies"] = a.calc.results["energies"].tolist()
        out.append(f)
    return out


ref = {name: frames(name) for name in ("cu_md.traj", "slab.traj", "mixed.traj")}
ref["program"] = "ASE 3.29.0"
with gzip.open("reference.json.gz", "wt") as f:
    json.dump(ref, f)
print({k: len(v) for k, v in ref.items() if k != "program"})
