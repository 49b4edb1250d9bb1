"""Writes ase_forces.xyz and ase_forces.json: a 2-frame extended XYZ file as ASE writes a
machine-learning training set (energy, stress and free energy in the comment, forces and
momenta as 3-component columns, a string info key), and ASE's own values read back from it.

    python3 gen_ase_forces.py   # ASE 3.29 (ase.io.write / ase.io.read)
"""
import json

import numpy as np
from ase import Atoms
from ase.calculators.singlepoint import SinglePointCalculator
from ase.io import read, write

rng = np.random.default_rng(7)
frames = []
for k in range(2):
    a = Atoms(
        "Cu3O2",
        positions=rng.uniform(0.0, 6.0, (5, 3)),
        cell=[[6.0, 0.0, 0.0], [0.5, 6.5, 0.0], [0.0, 0.25, 7.0]],
        pbc=True,
    )
    a.set_momenta(rng.normal(0.0, 0.3, (5, 3)))
    a.info["config_type"] = "bulk md"
    calc = SinglePointCalculator(
        a,
        energy=-12.5 - 0.25 * k,
        free_energy=-12.75 - 0.25 * k,
        forces=rng.normal(0.0, 1.0, (5, 3)),
        stress=rng.normal(0.0, 0.01, 6),
    )
    a.calc = calc
    frames.append(a)
write("ase_forces.xyz", frames, format="extxyz")
back = read("ase_forces.xyz", ":")
ref = [
    {
        "energy": b.get_potential_energy(),
        "forces": b.get_forces().tolist(),
        "momenta": b.get_momenta().tolist(),
        "stress": b.get_stress(voigt=False).tolist(),
        "config_type": b.info["config_type"],
    }
    for b in back
]
import ase

json.dump({"ase": ase.__version__, "frames": ref}, open("ase_forces.json", "w"), indent=1)
