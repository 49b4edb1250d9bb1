"""Aspherical particles for the ellipsoids tests, written and read back by OVITO.

- `ovito_export.dump`: a Gay-Berne-like system (3:1:1 and 2:1.5:0.5 ellipsoids, one sphere of
  shape 0 0 0) that OVITO 3.17 exports to a LAMMPS dump: its "Aspherical Shape" as
  c_shape[1..3] (semi-axes), its "Orientation" as quati quatj quatk quatw.
- `lammps_columns.dump`: the same particles as LAMMPS's `compute property/atom` writes them:
  shapex shapey shapez (diameters) and quatw quati quatj quatk, w first.
- `ovito_read.json`: what OVITO reads from each file: positions, "Aspherical Shape" (semi-axes,
  Å) and "Orientation" (x, y, z, w), per particle; the tests compare ours with it.

Run with OVITO's Python module (`pip install ovito`, 3.17.2 here): `python3 gen_ellipsoids.py`.
"""
import json

import numpy as np
from ovito.data import DataCollection
from ovito.io import export_file, import_file

rng = np.random.default_rng(2026)
n = 60
L = 24.0
pos = rng.uniform(0, L, (n, 3))
quat = rng.normal(size=(n, 4))
quat /= np.linalg.norm(quat, axis=1)[:, None]  # x, y, z, w (OVITO's order)
shape = np.where((np.arange(n) % 2 == 0)[:, None], [3.0, 1.0, 1.0], [2.0, 1.5, 0.5])
shape[7] = 0.0  # a LAMMPS sphere
types = 1 + (np.arange(n) % 2)

data = DataCollection()
data.create_cell(np.array([[L, 0, 0, 0], [0, L, 0, 0], [0, 0, L, 0]], dtype=float), pbc=(True,) * 3)
p = data.create_particles(count=n)
p.create_property("Particle Identifier", data=np.arange(1, n + 1))
p.create_property("Position", data=pos)
p.create_property("Aspherical Shape", data=shape)
p.create_property("Orientation", data=quat)
p.create_property("Particle Type", data=types)
export_file(
    data,
    "ovito_export.dump",
    "lammps/dump",
    columns=[
        "Particle Identifier", "Particle Type", "Position.X", "Position.Y", "Position.Z",
        "Aspherical Shape.X", "Aspherical Shape.Y", "Aspherical Shape.Z",
        "Orientation.X", "Orientation.Y", "Orientation.Z", "Orientation.W",
    ],
)

with open("lammps_columns.dump", "w") as f:
    f.write("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n%d\n" % n)
    f.write("ITEM: BOX BOUNDS pp pp pp\n" + ("0 %r\n" % L) * 3)
    f.write("ITEM: ATOMS id type x y z shapex shapey shapez quatw quati quatj quatk\n")
    for i in range(n):
        x, y, z, w = quat[i]
        d = 2 * shape[i]
        f.write("%d %d %.6f %.6f %.6f %.6f %.6f %.6f %.8f %.8f %.8f %.8f\n"
                % (i + 1, types[i], *pos[i], *d, w, x, y, z))

out = {}
for name in ["ovito_export.dump", "lammps_columns.dump"]:
    d = import_file(name).compute()
    order = np.argsort(d.particles["Particle Identifier"][...])
    out[name] = {
        "positions": d.particles["Position"][...][order].tolist(),
        "semi_axes": d.particles["Aspherical Shape"][...][order].tolist(),
        "orientation_xyzw": d.particles["Orientation"][...][order].tolist(),
    }
with open("ovito_read.json", "w") as f:
    json.dump(out, f, indent=1)
