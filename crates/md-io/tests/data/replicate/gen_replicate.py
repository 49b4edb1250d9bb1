"""Water in a triclinic box and OVITO's Replicate modifier applied to it, for tests/replicate.rs.

water.data (LAMMPS data file, atom_style bond, written by OVITO 3.17.2): 60 rigid-ish waters
  placed at random in a triclinic cell (a = 18, b = (4, 16, 0), c = (3, -2, 15) A, origin
  (-2, 1, 0.5)) and wrapped into it, so that many O-H bonds cross a face of the box.
water.lammpstrj (LAMMPS dump of the same atoms, written by OVITO): id mol type x y z.
water_2x2x1.data.gz, water_2x2x1.lammpstrj.gz: OVITO's Replicate (2 x 2 x 1) of them, exported
  by OVITO (gzipped with mtime 0), for the CLI test that draws both.
replicate_reference.json: OVITO's ReplicateModifier (num 2 x 3 x 2, adjust_box, unique_ids)
  applied to them: positions, particle and molecule identifiers, the cell (edge vectors as
  rows, origin) and the bonds as sorted index pairs.

    pip install ovito==3.17.2
    python3 gen_replicate.py
"""
import gzip
import json
import os
import shutil

import numpy as np
from ovito.data import DataCollection
from ovito.io import export_file
from ovito.modifiers import ReplicateModifier
from ovito.pipeline import Pipeline, StaticSource

here = os.path.dirname(os.path.abspath(__file__))
rng = np.random.default_rng(20261205)

a = np.array([18.0, 0.0, 0.0])
b = np.array([4.0, 16.0, 0.0])
c = np.array([3.0, -2.0, 15.0])
origin = np.array([-2.0, 1.0, 0.5])
M = np.array([a, b, c])

n_mol = 60
pos, types, mols, bonds = [], [], [], []
for m in range(n_mol):
    o = origin + rng.random(3) @ M
    # Two hydrogens at 0.96 A, 104.5 degrees apart, in a random orientation.
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    half = np.radians(104.5 / 2)
    h1 = o + 0.96 * (q @ [np.sin(half), np.cos(half), 0])
    h2 = o + 0.96 * (q @ [-np.sin(half), np.cos(half), 0])
    base = len(pos)
    pos += [o, h1, h2]
    types += [1, 2, 2]
    mols += [m + 1] * 3
    bonds += [[base, base + 1], [base, base + 2]]
pos = np.array(pos)
# Wrap every atom into the cell: bonds now cross faces.
frac = (pos - origin) @ np.linalg.inv(M)
frac -= np.floor(frac)
pos = origin + frac @ M
bonds = np.array(bonds)
pbc_vectors = -np.round(frac[bonds[:, 1]] - frac[bonds[:, 0]]).astype(int)

dc = DataCollection()
dc.create_cell(np.column_stack([a, b, c, origin]), pbc=(True, True, True))
p = dc.create_particles(count=len(pos))
p.create_property("Position", data=pos)
p.create_property("Particle Identifier", data=np.arange(1, len(pos) + 1))
p.create_property("Molecule Identifier", data=mols)
tp = p.create_property("Particle Type", data=types)
bt = p.create_bonds(count=len(bonds))
bt.create_property("Topology", data=bonds)
bt.create_property("Periodic Image", data=pbc_vectors)
bt.create_property("Bond Type", data=np.ones(len(bonds), dtype=int))

pipe = Pipeline(source=StaticSource(data=dc))
export_file(pipe, os.path.join(here, "water.data"), "lammps/data", atom_style="bond")
export_file(pipe, os.path.join(here, "water.lammpstrj"), "lammps/dump",
            columns=["Particle Identifier", "Molecule Identifier", "Particle Type",
                     "Position.X", "Position.Y", "Position.Z"])



def export_gz(pipe, name, *args, **kw):
    path = os.path.join(here, name)
    export_file(pipe, path, *args, **kw)
    with open(path, "rb") as src, open(path + ".gz", "wb") as raw:
        with gzip.GzipFile(fileobj=raw, mode="wb", mtime=0, filename="") as dst:
            shutil.copyfileobj(src, dst)
    os.remove(path)


small = ReplicateModifier(num_x=2, num_y=2, num_z=1)
pipe.modifiers.append(small)
export_gz(pipe, "water_2x2x1.data", "lammps/data", atom_style="bond")
export_gz(pipe, "water_2x2x1.lammpstrj", "lammps/dump",
          columns=["Particle Identifier", "Molecule Identifier", "Particle Type",
                   "Position.X", "Position.Y", "Position.Z"])
pipe.modifiers.remove(small)

pipe.modifiers.append(ReplicateModifier(num_x=2, num_y=3, num_z=2))
d = pipe.compute()
cell = np.array(d.cell[...])
topo = np.sort(np.array(d.particles.bonds.topology[...]), axis=1)
ref = {
    "n": [2, 3, 2],
    "positions": np.round(d.particles.positions[...], 5).tolist(),
    "ids": d.particles.identifiers[...].tolist(),
    "molecules": d.particles["Molecule Identifier"][...].tolist(),
    "cell": cell[:, :3].T.tolist(),
    "origin": cell[:, 3].tolist(),
    "bonds": sorted(map(list, set(map(tuple, topo.tolist())))),
}
with open(os.path.join(here, "replicate_reference.json"), "w") as f:
    json.dump(ref, f)
    f.write("\n")
