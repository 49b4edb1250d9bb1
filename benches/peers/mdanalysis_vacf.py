"""The peer of benches/md_msd.rs's vacf bench: the transport-analysis MDAKit's VelocityAutocorr
(dim_type xyz, fft=True, each atom's autocorrelation over every time origin through
tidynamics) on 10,000 atoms' Ornstein-Uhlenbeck velocities (v <- 0.9 v + N(0, 1) per axis and
frame) over 1,000 frames, held in memory (MemoryReader), as texmap-md-io's
vacf::Velocities::autocorrelation is timed there.

    pip install MDAnalysis tidynamics transport-analysis
    python3 benches/peers/mdanalysis_vacf.py [repeats]

Prints the best and median time of `run()` (which copies each frame's velocities, then
transforms every atom) and of its averaging step alone (`_conclude`).
"""
import sys
import time

import numpy as np
import MDAnalysis as mda
from transport_analysis.velocityautocorr import VelocityAutocorr

repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 3
atoms, frames = 10_000, 1000
rng = np.random.default_rng(61206)
v = np.zeros((frames, atoms, 3), dtype=np.float32)
w = np.zeros((atoms, 3))
for f in range(frames):
    w = 0.9 * w + rng.normal(size=(atoms, 3))
    v[f] = w
u = mda.Universe.empty(atoms, trajectory=True)
u.load_new(np.zeros_like(v), format=mda.coordinates.memory.MemoryReader, velocities=v)

runs, concludes = [], []
for _ in range(repeats):
    m = VelocityAutocorr(u.atoms, dim_type="xyz", fft=True)
    t0 = time.perf_counter()
    m.run()
    runs.append(time.perf_counter() - t0)
    t0 = time.perf_counter()
    m._conclude()
    concludes.append(time.perf_counter() - t0)
c = m.results.timeseries
print(f"C(5)/C(0) {c[5] / c[0]:.4f} ({0.9 ** 5:.4f} expected)")
print(f"VelocityAutocorr run: best {min(runs) * 1e3:.0f} ms, median {np.median(runs) * 1e3:.0f} ms")
print(f"  averaging alone (_conclude): best {min(concludes) * 1e3:.0f} ms")
