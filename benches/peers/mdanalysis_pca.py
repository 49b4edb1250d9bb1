"""The peer of benches/md_pca.rs: MDAnalysis's analysis.pca.PCA (select all, no alignment:
the frames are generated still) and transform() onto five components, for 214 atoms (the
CA atoms of adenylate kinase) and 855 atoms (its backbone) over 1,000 frames held in memory
(MemoryReader): random positions in a 50 A box moved along five seeded collective modes plus
0.3 A of noise, the sizes of the bench's, not its exact numbers.

    pip install MDAnalysis
    python3 benches/peers/mdanalysis_pca.py [repeats]

Prints the best and median time of run() + transform() per size, then of
DistanceMatrix(metric=rms.rmsd with center and superposition).run() on the first 500 frames
of the 214 atoms (the bench's rmsd_matrix).
"""
import sys
import time
import warnings

import numpy as np
import MDAnalysis as mda
from functools import partial

from MDAnalysis.analysis import rms
from MDAnalysis.analysis.diffusionmap import DistanceMatrix
from MDAnalysis.analysis.pca import PCA

warnings.simplefilter("ignore")
repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 3
frames = 1000
rng = np.random.default_rng(61207)
for atoms in (214, 855):
    base = rng.random((atoms, 3)) * 50.0
    modes = rng.normal(size=(5, atoms, 3))
    phase = 2 * np.pi * np.arange(frames) / frames
    amp = np.stack([np.sin(phase * (m + 1)) / (m + 1) for m in range(5)], axis=1)
    walk = base[None] + np.einsum("fm,mai->fai", amp, modes)
    walk += rng.normal(0.0, 0.3, size=walk.shape)
    u = mda.Universe.empty(atoms, trajectory=True)
    u.add_TopologyAttr("types", ["C"] * atoms)  # transform() compares them
    u.load_new(walk.astype(np.float32), format=mda.coordinates.memory.MemoryReader)
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        pc = PCA(u, select="all").run()
        space = pc.transform(u.atoms, n_components=5)
        runs.append(time.perf_counter() - t0)
    top = np.real(pc.results.cumulated_variance[4])
    print(f"{atoms} atoms x {frames} frames: five components carry {top:.3f}; "
          f"PCA run + transform: best {min(runs) * 1e3:.0f} ms, median {np.median(runs) * 1e3:.0f} ms")
    if atoms == 214:
        metric = partial(rms.rmsd, center=True, superposition=True)
        runs = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            DistanceMatrix(u, select="all", metric=metric).run(stop=frames // 2)
            runs.append(time.perf_counter() - t0)
        print(f"{atoms} atoms x {frames // 2} frames: DistanceMatrix (superposed): "
              f"best {min(runs) * 1e3:.0f} ms, median {np.median(runs) * 1e3:.0f} ms")
