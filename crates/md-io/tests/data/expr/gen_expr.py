"""A LAMMPS dump written by OVITO, and OVITO's Compute property modifier on it, for
tests/expr.rs.

atoms.lammpstrj: 600 atoms of two types at random in a periodic 30 A box (seed 3) with
velocities and a c_pe column, written by ovito.io.export_file (lammps/dump), with ids drawn
from 1 to 5000 in shuffled order; read back sorted by id (sort_particles), as texmap reads a
dump, so that index counts the same atoms and id is not index + 1. expr_reference.json: per case, texmap's
formula, OVITO's spelling of the same formula (Position.X for x, Velocity.X for vx,
ParticleIndex for index, ParticleIdentifier for id) and OVITO 3.17's values
(ComputePropertyModifier, muparser). OVITO has no floor, ceil or '!': those are tested in
texmap's unit tests only.

    pip install ovito==3.17.2
    python3 gen_expr.py
"""
import json
import os

import numpy as np
from ovito.data import DataCollection, ParticleType
from ovito.io import export_file, import_file
from ovito.modifiers import ComputePropertyModifier

here = os.path.dirname(os.path.abspath(__file__))
rng = np.random.default_rng(3)
n = 600
data = DataCollection()
data.create_cell(np.diag([30.0, 30.0, 30.0]), pbc=(True, True, True))
p = data.create_particles(count=n)
p.create_property("Position", data=rng.uniform(0, 30, (n, 3)))
p.create_property("Velocity", data=rng.normal(0, 2.0, (n, 3)))
p.create_property("Particle Identifier", data=rng.choice(5000, n, replace=False) + 1)
t = p.create_property("Particle Type", data=rng.integers(1, 3, n))
t.types.append(ParticleType(id=1, name="1"))
t.types.append(ParticleType(id=2, name="2"))
p.create_property("c_pe", data=rng.normal(-3.5, 0.4, n))
columns = ["Particle Identifier", "Particle Type", "Position.X", "Position.Y", "Position.Z",
           "Velocity.X", "Velocity.Y", "Velocity.Z", "c_pe"]
path = os.path.join(here, "atoms.lammpstrj")
export_file(data, path, "lammps/dump", columns=columns)

OVITO_NAMES = [("vx", "Velocity.X"), ("vy", "Velocity.Y"), ("vz", "Velocity.Z"),
               ("index", "ParticleIndex"), ("id", "ParticleIdentifier"),
               ("x", "Position.X"), ("y", "Position.Y"), ("z", "Position.Z")]


def ovito_spelling(formula):
    import re
    for ours, theirs in OVITO_NAMES:
        formula = re.sub(r"\b%s\b" % ours, theirs, formula)
    return formula


formulas = [
    "sqrt(vx^2 + vy^2 + vz^2)",
    "0.5 * (vx*vx + vy*vy + vz*vz) * (c_pe < -3.5 ? 2 : 1)",
    "z > 15 ? c_pe : -c_pe",
    "atan2(y - 15, x - 15) * 180 / pi",
    "fmod(index, 7) == 3 && c_pe < -3 || x >= 29",
    "min(x, y, z) + max(abs(vx), 1, vy)",
    "exp(-((x-10)^2 + (y-20)^2) / 20) + log10(abs(c_pe) + 1)",
    "rint(x) - rint(y / 2) * -2^2",
    "id * 2 - index + N",
    "(c_pe <= -3.5) + sin(x) * cos(y) / (1 + tanh(vz)^2)",
    "2^3^2 / 1e3 + .5e-1 - -x",
]
cases = []
for f in formulas:
    pipe = import_file(path, sort_particles=True)
    pipe.modifiers.append(ComputePropertyModifier(output_property="Out",
                                                  expressions=[ovito_spelling(f)]))
    values = pipe.compute().particles["Out"][...]
    cases.append({"formula": f, "ovito": ovito_spelling(f), "values": values.tolist()})
with open(os.path.join(here, "expr_reference.json"), "w") as out:
    json.dump(cases, out)
    out.write("\n")
