"""The peer of `texmap convert --distance-map` (benches/md_pca.rs times one frame of the
library part): GROMACS's gmx mdmat, end to end on the same XTC file, in the same minutes.

The file: adenylate kinase in water (md-io's tests/data/hbonds: 47,681 atoms in a truncated
octahedron), its first frame written 100 times by MDAnalysis with seeded noise of 0.2 A on
every atom. Both programs read it and map the protein's 214 residues (3,341 atoms) by their
smallest atom distance to the nearest image, averaged over the frames:

    gmx mdmat -f adk100.xtc -s adk.gro -mean dm.xpm   (group Protein)
    texmap convert adk100.xtc --topology adk.gro --distance-map dm.csv

    apt-get install gromacs; pip install MDAnalysis
    cargo build --release -p texmap-cli
    python3 benches/peers/gmx_mdmat.py [repeats]

Prints each program's best and median wall time. gmx mdmat runs on one thread; texmap uses
every core it is given.
"""
import gzip
import os
import shutil
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np
import MDAnalysis as mda

warnings.simplefilter("ignore")
repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 3
root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
texmap = os.path.join(root, "target", "release", "texmap")
data = os.path.join(root, "crates", "md-io", "tests", "data", "hbonds")
with tempfile.TemporaryDirectory() as d:
    gro, xtc = os.path.join(d, "adk.gro"), os.path.join(d, "adk100.xtc")
    with gzip.open(os.path.join(data, "adk_top.gro.gz")) as src, open(gro, "wb") as dst:
        shutil.copyfileobj(src, dst)
    u = mda.Universe(gro, os.path.join(data, "adk_0_9.xtc"))
    rng = np.random.default_rng(20261206)
    base = u.atoms.positions.copy()
    with mda.Writer(xtc, u.atoms.n_atoms) as w:
        for f in range(100):
            u.atoms.positions = base + rng.normal(0.0, 0.2, base.shape)
            u.trajectory.ts.time = float(f)
            w.write(u.atoms)

    def gmx():
        subprocess.run(["gmx", "-quiet", "mdmat", "-f", xtc, "-s", gro, "-mean",
                        os.path.join(d, "dm.xpm")], input="1\n", text=True, check=True,
                       capture_output=True)

    def ours():
        subprocess.run([texmap, "convert", xtc, "--topology", gro, "--distance-map",
                        os.path.join(d, "dm.csv"), "-q"], check=True, capture_output=True)

    for name, run in (("gmx mdmat", gmx), ("texmap convert", ours)):
        times = []
        for _ in range(repeats):
            t = time.perf_counter()
            run()
            times.append(time.perf_counter() - t)
        print(f"{name}: best {min(times):.3f} s, median {np.median(times):.3f} s")
