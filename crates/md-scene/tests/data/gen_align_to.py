"""MDAnalysis's mass-weighted superposition onto a separate reference structure, for
tests/align.rs.

align_target.pdb.gz: wwPDB 3GWI chain A (md-io/tests/data/dssp/3gwiA.pdb.gz) turned by a seeded
random rotation, moved by (30, -40, 25) A and jiggled by seeded Gaussian noise of 0.3 A per
coordinate, written by MDAnalysis's PDB writer (gzipped with mtime 0): a structure in its own coordinates, as a
crystal structure or an equilibrated frame would be.

align_to_reference.json: MDAnalysis 2.11's AlignTraj of align_3gwi.xtc (topology 3gwiA.pdb.gz)
onto align_target.pdb.gz on "backbone" with weights="mass" (in memory): the mass-weighted RMSD of
each frame after the fit, and the superposed positions of every 10th atom.

    pip install MDAnalysis==2.11.0 scipy
    python3 gen_align_to.py
"""
import gzip
import json
import os
import warnings

import MDAnalysis as mda
import numpy as np
from MDAnalysis.analysis import align
from scipy.spatial.transform import Rotation

warnings.filterwarnings("ignore")
here = os.path.dirname(os.path.abspath(__file__))
pdb = os.path.join(here, "../../../md-io/tests/data/dssp/3gwiA.pdb.gz")
xtc = os.path.join(here, "align_3gwi.xtc")
plain = os.path.join(here, "align_target.pdb")
target = plain + ".gz"
rng = np.random.default_rng(20261204)
u = mda.Universe(pdb)
x0 = u.atoms.positions.astype(np.float64)
r = Rotation.random(random_state=rng.integers(1 << 31)).as_matrix()
centre = x0.mean(axis=0)
u.atoms.positions = (x0 - centre) @ r.T + centre + [30.0, -40.0, 25.0] + rng.normal(0, 0.3, x0.shape)
u.atoms.write(plain)
with open(plain, "rb") as fh, open(target, "wb") as raw:
    with gzip.GzipFile(fileobj=raw, mode="wb", mtime=0, filename="") as gz:
        gz.write(fh.read())
os.remove(plain)
mobile = mda.Universe(pdb, xtc)
ref = mda.Universe(target)
run = align.AlignTraj(mobile, ref, select="backbone", weights="mass", in_memory=True).run()
every = list(range(0, mobile.atoms.n_atoms, 10))
frames = []
for ts in mobile.trajectory:
    frames.append(mobile.atoms.positions[every].astype(float).round(5).tolist())
out = {
    "select": "backbone",
    "weights": "mass",
    "atoms": every,
    "rmsd": [float(v) for v in run.results.rmsd],
    "positions": frames,
}
with open(os.path.join(here, "align_to_reference.json"), "w") as fh:
    json.dump(out, fh)
    fh.write("\n")
print(out["rmsd"])
