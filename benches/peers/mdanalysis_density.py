"""The peer of benches/md_msd.rs's density map: MDAnalysis's DensityAnalysis (delta 1 A, its
default 2 A padding around the first frame's atoms) of 10,000 atoms on Gaussian random walks
(0.2 A per axis per frame) over 1,000 frames, held in memory (MemoryReader), as texmap-md-io's
density::DensityMap is timed there (the same walk's statistics, not its exact numbers).

    pip install MDAnalysis
    python3 benches/peers/mdanalysis_density.py [repeats]

Prints the best and median time of `run()` and how many positions fell outside the grid.
"""
import sys
import time

import numpy as np
import MDAnalysis as mda
from MDAnalysis.analysis.density import DensityAnalysis

repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 3
atoms, frames = 10_000, 1000
rng = np.random.default_rng(61206)
start = rng.random((atoms, 3)) * 50.0
walk = start + np.cumsum(rng.normal(0.0, 0.2, size=(frames, atoms, 3)), axis=0)
walk = np.concatenate([start[None], walk[:-1]]).astype(np.float32)
u = mda.Universe.empty(atoms, trajectory=True)
u.load_new(walk, format=mda.coordinates.memory.MemoryReader)

runs = []
for _ in range(repeats):
    u.trajectory[0]
    d = DensityAnalysis(u.atoms, delta=1.0)
    t0 = time.perf_counter()
    d.run()
    runs.append(time.perf_counter() - t0)
grid = d.results.density
counted = grid.grid.sum() * np.prod(grid.delta) * frames
print(f"grid {grid.grid.shape}, positions outside it: {atoms * frames - counted:.0f}")
print(f"DensityAnalysis run: best {min(runs) * 1e3:.0f} ms, median {np.median(runs) * 1e3:.0f} ms")
