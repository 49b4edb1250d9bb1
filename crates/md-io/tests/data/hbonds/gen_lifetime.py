"""MDAnalysis 2.11.0's hydrogen-bond lifetime autocorrelation (lib.correlations: the
correct_intermittency and autocorrelation that HydrogenBondAnalysis.lifetime calls) on
synthetic bond sets: the reference for md-io's `hbonds::lifetime` (tests/hbonds.rs).

Run from this directory: python3 gen_lifetime.py

80 possible bonds (hydrogen, acceptor pairs) over 200 frames, each switching on with
probability 0.08 and off with 0.25 per frame (seeded), some never present; per intermittency 0
and 2, MDAnalysis's C(tau) for tau 0..30 (window_step 1). lifetime_reference.json holds the
frames' pairs and the curves.
"""
import json

import numpy as np
from MDAnalysis.lib.correlations import autocorrelation, correct_intermittency

rng = np.random.default_rng(61206)
n_frames, n_bonds = 200, 80
pairs = [(int(rng.integers(0, 500)), int(rng.integers(500, 900))) for _ in range(n_bonds)]
on = rng.random(n_bonds) < 0.3
frames = []
for f in range(n_frames):
    flip = rng.random(n_bonds)
    on = np.where(on, flip >= 0.25, flip < 0.08)
    on[:5] = False  # never present
    frames.append([list(pairs[b]) for b in range(n_bonds) if on[b]])

ref = {"frames": frames, "tau_max": 30}
for inter in (0, 2):
    sets = [set(frozenset(p) for p in fr) for fr in frames]
    sets = correct_intermittency(sets, intermittency=inter)
    tau, c, _ = autocorrelation(sets, 30, window_step=1)
    ref[f"intermittency_{inter}"] = [float(x) for x in c]
    print(inter, [round(x, 4) for x in c[:6]])
json.dump(ref, open("lifetime_reference.json", "w"))
