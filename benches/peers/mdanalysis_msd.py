"""The peer of benches/md_msd.rs: MDAnalysis's EinsteinMSD (msd_type xyz, fft=True, which
computes each atom's MSD over every time origin through tidynamics) on 10,000 atoms on Gaussian
random walks (0.2 A per axis per frame) over 1,000 frames, held in memory (MemoryReader), as
texmap-md-io's msd::AllOrigins::mean is timed there.

    pip install MDAnalysis tidynamics
    python3 benches/peers/mdanalysis_msd.py [repeats]

Prints the best and median time of `run()` (which copies each frame's positions, then
transforms every atom) and of its averaging step alone (`_conclude`).
"""
import sys
import time

import numpy as np
import MDAnalysis as mda
from MDAnalysis.analysis.msd import EinsteinMSD

repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 3
atoms, frames = 10_000, 1000
rng = np.random.default_rng(61206)
start = rng.random((atoms, 3)) * 50.0
walk = start + np.cumsum(rng.normal(0.0, 0.2, size=(frames, atoms, 3)), axis=0)
walk = np.concatenate([start[None], walk[:-1]]).astype(np.float32)
u = mda.Universe.empty(atoms, trajectory=True)
u.load_new(walk, format=mda.coordinates.memory.MemoryReader)

runs, concludes = [], []
for _ in range(repeats):
    m = EinsteinMSD(u, select="all", msd_type="xyz", fft=True)
    t0 = time.perf_counter()
    m.run()
    runs.append(time.perf_counter() - t0)
    t0 = time.perf_counter()
    m._conclude()
    concludes.append(time.perf_counter() - t0)
slope = m.results.timeseries[frames // 10] / (frames // 10)
print(f"MSD slope {slope:.4f} A^2 per frame (0.12 expected)")
print(f"EinsteinMSD run: best {min(runs) * 1e3:.0f} ms, median {np.median(runs) * 1e3:.0f} ms")
print(f"  averaging alone (_conclude): best {min(concludes) * 1e3:.0f} ms")
