#!/usr/bin/env python3
"""Writes the small DCD / XTC / TRR files of tests/binary_*.rs with MDAnalysis, then reads them
back with MDAnalysis and records what it reports in binary_expected.json.

Run from this directory:  python3 binary_generate.py   (needs `pip install MDAnalysis`)
The Rust tests compare texmap-md-io's readers with the JSON, so the values come from another
program. Positions in the JSON are in Å, box as [a, b, c, alpha, beta, gamma] (Å, degrees),
times in ps, exactly as MDAnalysis reports them.
"""
import json

import MDAnalysis as mda
import numpy as np
from MDAnalysis.coordinates.memory import MemoryReader
from MDAnalysis.lib.formats.libmdaxdr import TRRFile

N_ATOMS, N_FRAMES = 12, 4
rng = np.random.default_rng(2024)
# Water-like triples near each other (exercises XTC runs), drifting over frames, in Å.
base = rng.uniform(0.0, 20.0, size=(N_ATOMS // 3, 1, 3)) + rng.uniform(-1, 1, size=(N_ATOMS // 3, 3, 3))
base = base.reshape(N_ATOMS, 3)
coords = np.stack([base + 0.37 * f for f in range(N_FRAMES)]).astype(np.float32)
# Frame 0, 1: orthorhombic; frame 2, 3: triclinic.
dims = np.array(
    [[21.0, 22.0, 23.0, 90.0, 90.0, 90.0],
     [21.5, 22.5, 23.5, 90.0, 90.0, 90.0],
     [24.0, 25.0, 26.0, 80.0, 95.0, 100.0],
     [24.0, 25.0, 26.0, 70.0, 75.0, 85.0]], dtype=np.float32)

u = mda.Universe.empty(N_ATOMS, trajectory=True)
u.load_new(coords, format=MemoryReader, dimensions=dims, dt=2.5)

with mda.Writer("dcd_mda.dcd", N_ATOMS) as w:
    for ts in u.trajectory:
        w.write(u.atoms)
with mda.Writer("xtc_mda.xtc", N_ATOMS) as w:
    for ts in u.trajectory:
        w.write(u.atoms)

# TRR: blocks present or absent per frame (written with MDAnalysis's xdrfile binding), nm units.
vel = rng.uniform(-1, 1, size=(N_FRAMES, N_ATOMS, 3)).astype(np.float32)
frc = rng.uniform(-100, 100, size=(N_FRAMES, N_ATOMS, 3)).astype(np.float32)
present = [(True, True, True), (True, False, False), (True, True, False), (True, False, True)]
with TRRFile("trr_mda.trr", "w") as f:
    for k in range(N_FRAMES):
        box = mda.lib.mdamath.triclinic_vectors(dims[k]) / 10.0
        x, v, fo = present[k]
        f.write(coords[k] / 10.0 if x else None, vel[k] if v else None,
                frc[k] if fo else None, box, 100 * k, 2.5 * k, 0.0, N_ATOMS)

expected = {"program": f"MDAnalysis {mda.__version__}", "n_atoms": N_ATOMS}
for fname in ["dcd_mda.dcd", "xtc_mda.xtc", "trr_mda.trr"]:
    r = mda.Universe.empty(N_ATOMS, trajectory=False)
    r.load_new(fname)
    frames = []
    for ts in r.trajectory:
        fr = {
            "positions": ts.positions.astype(np.float64).tolist(),
            "dimensions": None if ts.dimensions is None else ts.dimensions.astype(np.float64).tolist(),
            "time": float(ts.time),
        }
        if fname.endswith(".trr"):
            fr["step"] = int(ts.data["step"])
            fr["velocities"] = ts.velocities.astype(np.float64).tolist() if ts.has_velocities else None
            fr["has_forces"] = bool(ts.has_forces)
        elif fname.endswith(".xtc"):
            fr["step"] = int(ts.data["step"])
        frames.append(fr)
    expected[fname] = {"n_frames": len(r.trajectory), "frames": frames}

with open("binary_expected.json", "w") as f:
    json.dump(expected, f, indent=1)
print("wrote dcd_mda.dcd xtc_mda.xtc trr_mda.trr binary_expected.json with", expected["program"])

# MDAnalysis caches XDR frame offsets beside the file: not test data.
import glob
import os

for junk in glob.glob(".*_offsets.*"):
    os.remove(junk)
