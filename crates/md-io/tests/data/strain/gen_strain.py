"""A deformed copper crystal written by OVITO, and OVITO's atomic strain and centrosymmetry of
it, for tests/strain.rs.

ref.xyz: FCC copper (a = 3.615 A), 8x8x6 cells with 12 A of vacuum above (two free surfaces),
thermal noise of 0.04 A (seed 5), plus three lone atoms and a dimer in the vacuum (too few
neighbours for a strain). cur.xyz: the same atoms sheared by 0.06 in x along y (cell too), with a
Gaussian bump of displacement (0.5 A in x, width 5 A) around a point inside, new noise, and
every atom wrapped back into the sheared cell, so some atoms cross the periodic faces between
the two files. Both as extended XYZ written by ovito.io.export_file.

strain_reference.json: OVITO 3.17's AtomicStrainModifier (cutoff 3.0, reference ref.xyz,
defaults: minimum image, no affine mapping) on cur.xyz: per atom "Shear Strain", "Volumetric
Strain", "Nonaffine Squared Displacement" and the "Selection" of invalid atoms, with OVITO's
invalid count. centro_reference.json: OVITO's CentroSymmetryModifier on both files, 12
neighbours in the conventional and the matching mode, and 8 in the conventional mode.

    pip install ovito==3.17.2
    python3 gen_strain.py
"""
import json
import os
import sys

import numpy as np
from ovito.io import import_file
from ovito.modifiers import AtomicStrainModifier, CentroSymmetryModifier
from ovito.pipeline import FileSource

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(here))
import ovito_single  # noqa: E402
COLUMNS = ovito_single.COLUMNS


def write(name, cell, positions):
    ovito_single.write(os.path.join(here, name), cell, positions, "Cu")


a = 3.615
nx, ny, nz = 8, 8, 6
base = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]]) + 0.25
sites = np.array([(np.array([i, j, k]) + b) * a for i in range(nx) for j in range(ny)
                  for k in range(nz) for b in base])
rng = np.random.default_rng(5)
ref = sites + rng.normal(0, 0.04, sites.shape)
lz = nz * a + 12.0
loners = np.array([[3.0, 3.0, nz * a + 6.0], [15.0, 20.0, nz * a + 6.5], [25.0, 8.0, nz * a + 5.5],
                   [10.0, 12.0, nz * a + 6.0], [12.2, 12.0, nz * a + 6.0]])
ref = np.vstack([ref, loners])
cell0 = np.array([[nx * a, 0, 0, 0], [0, ny * a, 0, 0], [0, 0, lz, 0]], dtype=float)
write("ref.xyz", cell0, ref)

gamma = 0.06
cur = ref.copy()
cur[:, 0] += gamma * cur[:, 1]
centre = np.array([14.0, 15.0, 10.0])
r2 = ((ref - centre) ** 2).sum(axis=1)
cur[:, 0] += 0.5 * np.exp(-r2 / (2 * 5.0 ** 2))
cur += rng.normal(0, 0.02, cur.shape)
cell = cell0.copy()
cell[0, 1] = gamma * ny * a  # the second cell vector (column 1) gains an x component
# Wrap into the sheared cell.
h = cell[:, :3]
frac = np.linalg.solve(h, cur.T).T
frac -= np.floor(frac)
cur = (h @ frac.T).T
write("cur.xyz", cell, cur)

pipe = import_file(os.path.join(here, "cur.xyz"), columns=COLUMNS)
mod = AtomicStrainModifier(cutoff=3.0, output_nonaffine_squared_displacements=True)
mod.reference = FileSource()
mod.reference.load(os.path.join(here, "ref.xyz"), columns=COLUMNS)
pipe.modifiers.append(mod)
d = pipe.compute()
p = d.particles
strain = {
    "cutoff": 3.0,
    "shear": p["Shear Strain"][...].tolist(),
    "volumetric": p["Volumetric Strain"][...].tolist(),
    "d2min": p["Nonaffine Squared Displacement"][...].tolist(),
    "invalid": [bool(v) for v in p["Selection"][...]],
    "invalid_count": int(d.attributes["AtomicStrain.invalid_particle_count"]),
}
with open(os.path.join(here, "strain_reference.json"), "w") as out:
    json.dump(strain, out)
    out.write("\n")

cases = []
for name in ["ref.xyz", "cur.xyz"]:
    for n, mode in [(12, CentroSymmetryModifier.Mode.Conventional),
                    (12, CentroSymmetryModifier.Mode.Matching),
                    (8, CentroSymmetryModifier.Mode.Conventional)]:
        pipe = import_file(os.path.join(here, name), columns=COLUMNS)
        pipe.modifiers.append(CentroSymmetryModifier(num_neighbors=n, mode=mode))
        csp = pipe.compute().particles["Centrosymmetry"][...]
        cases.append({"file": name, "neighbours": n,
                      "mode": "matching" if mode == CentroSymmetryModifier.Mode.Matching
                      else "conventional",
                      "csp": csp.tolist()})
with open(os.path.join(here, "centro_reference.json"), "w") as out:
    json.dump(cases, out)
    out.write("\n")
