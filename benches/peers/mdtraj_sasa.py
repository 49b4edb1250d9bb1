"""The peer of benches/md_sasa.rs: MDTraj's shrake_rupley (probe 0.14 nm, 960 points, mode
'atom'; C++ with OpenMP over the atoms) on frame 0 of MDAnalysis's adenylate kinase in water
(md-io's tests/data/hbonds), the protein alone (3,341 atoms, sliced out) and the whole solvated
system (47,681 atoms less TIP4P's 11,084 virtual sites; MDTraj ignores the periodic box).

    pip install mdtraj
    OMP_NUM_THREADS=2 python3 benches/peers/mdtraj_sasa.py [repeats]

Prints the protein's total area and the best and median time of each.
"""
import gzip
import os
import shutil
import sys
import tempfile
import time

import mdtraj as md
import numpy as np

repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 5
data = os.path.join(os.path.dirname(os.path.abspath(__file__)), "../../crates/md-io/tests/data/hbonds")
with tempfile.TemporaryDirectory() as tmp:
    gro = os.path.join(tmp, "adk_top.gro")
    with gzip.open(os.path.join(data, "adk_top.gro.gz")) as src, open(gro, "wb") as dst:
        shutil.copyfileobj(src, dst)
    t = md.load_frame(os.path.join(data, "adk_0_9.xtc"), 0, top=gro)
# The protein is the file's first 3,341 atoms (MDTraj's "protein" misses the GROMOS names
# LYSH, HISB, CYSH); TIP4P's virtual sites (MW, element VS, which MDTraj has no radius for and
# texmap leaves out) are dropped from the solvated system.
protein = t.atom_slice(np.arange(3341))
solvated = t.atom_slice([a.index for a in t.topology.atoms if a.element.symbol != "VS"])
print(f"protein atoms {protein.n_atoms}, solvated {solvated.n_atoms}")
for name, traj in [("protein", protein), ("solvated", solvated)]:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        a = md.shrake_rupley(traj, probe_radius=0.14, n_sphere_points=960)
        times.append(time.perf_counter() - t0)
    extra = f", total {a.sum() * 100:.1f} A^2" if name == "protein" else ""
    print(f"{name}: best {min(times) * 1e3:.1f} ms, median {np.median(times) * 1e3:.1f} ms{extra}")
