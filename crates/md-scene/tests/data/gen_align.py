"""A tumbling protein and MDAnalysis's superposition of it, for tests/align.rs.

align_3gwi.xtc: the 1,313 atoms of wwPDB 3GWI chain A (md-io/tests/data/dssp/3gwiA.pdb.gz,
the topology) in 6 frames; frame 0 as in the file, each later frame turned by a seeded random
rotation about a seeded point, moved by up to 20 A and jiggled by seeded Gaussian noise of
0.4 A per coordinate (so no superposition is exact), written by MDAnalysis's XTC writer.

align_reference.json: MDAnalysis 2.11's AlignTraj of that trajectory onto its frame 0 on
"backbone" (unweighted, in memory): the RMSD of each frame after the fit, and the superposed
positions of every 10th atom.

    pip install MDAnalysis==2.11.0
    python3 gen_align.py
"""
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
rng = np.random.default_rng(20261203)
u = mda.Universe(pdb)
x0 = u.atoms.positions.astype(np.float64).copy()
with mda.Writer(xtc, u.atoms.n_atoms) as w:
    for f in range(6):
        if f == 0:
            x = x0
        else:
            r = Rotation.random(random_state=rng.integers(1 << 31)).as_matrix()
            pivot = x0.mean(axis=0) + rng.normal(0, 5, 3)
            shift = rng.uniform(-20, 20, 3)
            x = (x0 - pivot) @ r.T + pivot + shift + rng.normal(0, 0.4, x0.shape)
        u.atoms.positions = x
        w.write(u.atoms)
mobile = mda.Universe(pdb, xtc)
ref = mda.Universe(pdb, xtc)
run = align.AlignTraj(mobile, ref, select="backbone", in_memory=True).run()
every = list(range(0, mobile.atoms.n_atoms, 10))
frames = []
for ts in mobile.trajectory:
    frames.append(mobile.atoms.positions[every].astype(float).round(5).tolist())
out = {
    "select": "backbone",
    "atoms": every,
    "rmsd": [float(v) for v in run.results.rmsd],
    "positions": frames,
}
with open(os.path.join(here, "align_reference.json"), "w") as fh:
    json.dump(out, fh)
    fh.write("\n")
print(out["rmsd"])
