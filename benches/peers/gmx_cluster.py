"""The peer of `texmap convert --rmsd-clusters` (benches/md_pca.rs times the library part):
GROMACS's gmx cluster, end to end on the same XTC file, in the same minutes.

The file: 1,000 frames of 214 atoms (the size of adenylate kinase's CA atoms) written by
MDAnalysis, random positions in a 50 A box moved along five seeded collective modes plus 0.3 A
of noise (the bench's kind of walk, not its exact numbers), each frame turned at random so
that every pair must be fitted. Both programs read it, fit every pair of frames (499,500),
cluster with the gromos method at 0.15 nm and write each frame's cluster:

    gmx cluster -f walk.xtc -s walk.pdb -n walk.ndx -method gromos -cutoff 0.15 -clid ...
    texmap convert walk.xtc --topology walk.pdb --rmsd-matrix-select all
        --rmsd-clusters ... --rmsd-cluster-cutoff 1.5

    apt-get install gromacs; pip install MDAnalysis
    cargo build --release -p texmap-cli
    python3 benches/peers/gmx_cluster.py [repeats]

Prints each program's best and median wall time and the cluster count each found (they must
agree). gmx cluster runs on one thread; texmap uses every core it is given.
"""
import os
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np
import MDAnalysis as mda
from scipy.spatial.transform import Rotation

warnings.simplefilter("ignore")
repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 3
root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
texmap = os.path.join(root, "target", "release", "texmap")
frames, atoms = 1000, 214
rng = np.random.default_rng(61207)
base = rng.random((atoms, 3)) * 50.0
modes = rng.normal(size=(5, atoms, 3))
with tempfile.TemporaryDirectory() as d:
    xtc, pdb, ndx = (os.path.join(d, n) for n in ("walk.xtc", "walk.pdb", "walk.ndx"))
    u = mda.Universe.empty(atoms, trajectory=True)
    u.add_TopologyAttr("names", ["CA"] * atoms)
    u.add_TopologyAttr("resnames", ["ALA"])
    u.add_TopologyAttr("resids", [1])
    u.atoms.positions = base
    u.atoms.write(pdb)
    with mda.Writer(xtc, atoms) as w:
        for f in range(frames):
            phase = 2 * np.pi * f / frames
            amp = [np.sin(phase * (m + 1)) / (m + 1) for m in range(5)]
            p = base + np.einsum("m,mai->ai", amp, modes) + rng.normal(0.0, 0.3, (atoms, 3))
            p = Rotation.random(random_state=rng.integers(1 << 31)).apply(p - 25.0) + 25.0
            u.atoms.positions = p
            u.trajectory.ts.time = float(f)
            w.write(u.atoms)
    with open(ndx, "w") as f:
        f.write("[ all ]\n" + " ".join(str(i + 1) for i in range(atoms)) + "\n")

    def gmx():
        out = os.path.join(d, "gmx")
        os.makedirs(out, exist_ok=True)
        subprocess.run(["gmx", "-quiet", "cluster", "-f", xtc, "-s", pdb, "-n", ndx,
                        "-method", "gromos", "-cutoff", "0.15", "-g", f"{out}/cl.log",
                        "-clid", f"{out}/clid.xvg", "-o", f"{out}/m.xpm",
                        "-dist", f"{out}/dist.xvg"],
                       input="0\n0\n", text=True, check=True, capture_output=True)
        ids = [int(l.split()[1]) for l in open(f"{out}/clid.xvg") if l[0] not in "#@"]
        return max(ids)

    def ours():
        out = os.path.join(d, "clid.csv")
        subprocess.run([texmap, "convert", xtc, "--topology", pdb, "--rmsd-matrix-select",
                        "all", "--rmsd-clusters", out, "--rmsd-cluster-cutoff", "1.5", "-q"],
                       check=True, capture_output=True)
        return max(int(l.split(",")[2]) for l in open(out).read().splitlines()[1:])

    for name, run in (("gmx cluster", gmx), ("texmap convert", ours)):
        times = []
        for _ in range(repeats):
            t = time.perf_counter()
            count = run()
            times.append(time.perf_counter() - t)
        print(f"{name}: best {min(times):.3f} s, median {np.median(times):.3f} s, "
              f"{count} clusters")
