"""GROMACS 2022.5's gmx mdmat and MDAnalysis 2.11's distances: the references for md-io's
`distance_map` and `texmap convert --distance-map` / `--contact-map`
(crates/md-io/tests/distance_map.rs, crates/cli/tests/convert.rs).

Run from this directory (needs MDAnalysis and gmx on the PATH; Debian's `gromacs` package):
python3 gen_distance_map.py

On ../hbonds/adk_top.gro.gz + ../hbonds/adk_0_9.xtc (adenylate kinase in water, a
truncated octahedron; the protein's 3,341 atoms in 214 residues, 2 frames):

- mdmat_mean.xpm.gz: `gmx mdmat -f adk_0_9.xtc -s adk_top.gro -mean ... -t 1.5 -nlevels 1000`
  on the Protein group, gzipped: the mean over the frames of each residue pair's smallest
  atom distance, in 1000 levels from 0 to 1.5 nm (a level is 1.5 / 999 nm; longer distances
  are the top level).
- reference.json.gz: MDAnalysis's `distances.distance_array` of the protein's atoms with the
  frame's box (minimum image) reduced to each residue pair's smallest distance: the mean over
  the frames (A, the upper triangle row by row, 5 decimals) and the fraction of frames in
  which it is below 4.5 A.
"""
import gzip
import json
import os
import shutil
import subprocess
import tempfile
import warnings

import numpy as np
import MDAnalysis as mda
from MDAnalysis.analysis import distances

warnings.simplefilter("ignore")
HERE = os.path.dirname(os.path.abspath(__file__))
GRO = os.path.join(HERE, "..", "hbonds", "adk_top.gro.gz")
XTC = os.path.join(HERE, "..", "hbonds", "adk_0_9.xtc")
CUTOFF = 4.5

with tempfile.TemporaryDirectory() as d:
    gro = os.path.join(d, "adk.gro")
    with gzip.open(GRO) as src, open(gro, "wb") as dst:
        shutil.copyfileobj(src, dst)
    xpm = os.path.join(d, "dm.xpm")
    subprocess.run(["gmx", "-quiet", "mdmat", "-f", XTC, "-s", gro, "-mean", xpm, "-t", "1.5",
                    "-nlevels", "1000"], input="1\n", text=True, check=True, capture_output=True)
    with open(xpm, "rb") as src, gzip.GzipFile(os.path.join(HERE, "mdmat_mean.xpm.gz"), "wb",
                                               mtime=0) as dst:
        shutil.copyfileobj(src, dst)
    u = mda.Universe(gro, XTC)

protein = u.select_atoms("protein")
starts = np.flatnonzero(np.r_[True, np.diff(protein.resindices) != 0])
n = len(starts)
total = np.zeros((n, n))
contacts = np.zeros((n, n))
for ts in u.trajectory:
    d = distances.distance_array(protein.positions, protein.positions, box=ts.dimensions)
    rows = np.minimum.reduceat(d, starts, axis=0)
    m = np.minimum.reduceat(rows, starts, axis=1)
    total += m
    contacts += m < CUTOFF
frames = len(u.trajectory)
mean, fraction = total / frames, contacts / frames
iu = np.triu_indices(n, 1)
out = {"residues": int(n), "frames": frames, "atoms": int(protein.n_atoms), "cutoff": CUTOFF,
       "mean": [round(float(v), 5) for v in mean[iu]],
       "contact_fraction": [float(v) for v in fraction[iu]]}
with gzip.GzipFile(os.path.join(HERE, "reference.json.gz"), "wb", mtime=0) as f:
    f.write((json.dumps(out) + "\n").encode())
print(n, frames, mean[iu].min(), mean.max(), fraction[iu].sum())
