"""Trajectories in several files, for tests/sequence.rs.

- `source.lammpstrj`: 12 steps of 30 atoms in a 20 Å box (a random walk, steps 0, 100, ...,
  1100), written here.
- `ovito/dump.*.lammpstrj`: OVITO 3.17.2 exports the source one file per frame (dump.0 ...
  dump.11: the wildcard is the frame number, so dump.10 sorts before dump.2 by name).
- `part1.xtc`, `part2.xtc`: MDAnalysis 2.11 writes frames 0-6 and 7-11 of the source as two
  XTC files, as a run continued in parts.
- `sequence_read.json`: what OVITO reads from the pattern `ovito/dump.*.lammpstrj` (its file
  sequence) and MDAnalysis from `[part1.xtc, part2.xtc]` (its ChainReader): per frame the
  positions (atoms ordered by id) and the timestep or time.

Run: `pip install ovito==3.17.2 MDAnalysis==2.11.0; python3 gen_sequence.py`.
"""
import json
import os

import numpy as np

rng = np.random.default_rng(12)
n, steps, L = 30, 12, 20.0
pos = rng.uniform(2, 18, (n, 3))
with open("source.lammpstrj", "w") as f:
    for s in range(steps):
        f.write("ITEM: TIMESTEP\n%d\nITEM: NUMBER OF ATOMS\n%d\n" % (100 * s, n))
        f.write("ITEM: BOX BOUNDS pp pp pp\n" + ("0 %r\n" % L) * 3)
        f.write("ITEM: ATOMS id type x y z\n")
        for i in range(n):
            f.write("%d %d %.4f %.4f %.4f\n" % (i + 1, 1 + i % 3, *pos[i]))
        pos += rng.normal(0, 0.3, pos.shape)

from ovito.io import export_file, import_file  # noqa: E402

os.makedirs("ovito", exist_ok=True)
pipeline = import_file("source.lammpstrj")
export_file(
    pipeline, "ovito/dump.*.lammpstrj", "lammps/dump", multiple_frames=True,
    columns=["Particle Identifier", "Particle Type", "Position.X", "Position.Y", "Position.Z"],
)
seq = import_file("ovito/dump.*.lammpstrj")
ovito_frames = []
for k in range(seq.source.num_frames):
    d = seq.compute(k)
    order = np.argsort(d.particles["Particle Identifier"][...])
    ovito_frames.append({
        "timestep": int(d.attributes["Timestep"]),
        "positions": d.particles["Position"][...][order].tolist(),
    })

import MDAnalysis as mda  # noqa: E402

u = mda.Universe("source.lammpstrj", format="LAMMPSDUMP")
for name, frames in [("part1.xtc", range(0, 7)), ("part2.xtc", range(7, 12))]:
    with mda.Writer(name, n) as w:
        for k in frames:
            u.trajectory[k]
            w.write(u.atoms)
chain = mda.Universe("source.lammpstrj", ["part1.xtc", "part2.xtc"], format="XTC",
                     topology_format="LAMMPSDUMP")
mda_frames = [{"time": float(ts.time), "positions": chain.atoms.positions.tolist()}
              for ts in chain.trajectory]

with open("sequence_read.json", "w") as f:
    json.dump({"ovito": ovito_frames, "mdanalysis": mda_frames}, f)
