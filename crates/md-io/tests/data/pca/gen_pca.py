"""MDAnalysis 2.11.0's principal component analysis: the reference for md-io's `pca` and
`texmap convert --pca-table` (crates/md-io/tests/pca.rs, crates/cli/tests/convert.rs).

Run from this directory: python3 gen_pca.py

- helix_pca.xtc (written by MDAnalysis): the 185 atoms of ../dihedrals/helix.pdb (PDB 3JQH's
  23-residue helix) over 80 frames. Each frame bends the helix (a displacement across its axis
  growing with the square of the distance along it, amplitude a sine of one period over the
  run), twists it (a rotation about the axis growing linearly along it, two periods), adds
  seeded Gaussian noise of 0.15 A per axis on every atom, then turns and moves the whole
  molecule by a random rotation and shift, so that only a superposition recovers the motion.
- pca_reference.json, for the selections 'name CA' (23 atoms: 69 coordinates < 80 frames, the
  covariance matrix) and 'backbone' (92 atoms: 276 > 80, the frames' products), "aligned"
  after align.AlignTraj superposes every frame on frame 0 by that selection (unweighted, in
  memory) and "raw" as the file holds them: pca.PCA(u, select=SEL).run()'s variance (every component), cumulated_variance, the first
  three p_components, transform() onto them for every frame, the mean, and
  pca.cosine_content of the first three projections.
"""
import json
import warnings

import numpy as np
import MDAnalysis as mda
from MDAnalysis.analysis import align, pca
from scipy.spatial.transform import Rotation

warnings.simplefilter("ignore")
rng = np.random.default_rng(20261207)
u = mda.Universe("../dihedrals/helix.pdb")
atoms = u.atoms
base = atoms.positions.astype(np.float64)
centre = base.mean(axis=0)
# The helix axis: the principal axis of the CA atoms.
ca = u.select_atoms("name CA").positions.astype(np.float64)
w, v = np.linalg.eigh(np.cov((ca - ca.mean(axis=0)).T))
axis = v[:, -1]
across = v[:, -2]
s = (base - centre) @ axis
s /= np.abs(s).max()
frames = 80
with mda.Writer("helix_pca.xtc", atoms.n_atoms) as out:
    for f in range(frames):
        phase = 2 * np.pi * f / frames
        bend = 2.0 * np.sin(phase)
        twist = 0.25 * np.sin(2 * phase)
        p = base - centre
        p = p + bend * (s ** 2)[:, None] * across[None, :]
        for i in range(len(p)):
            r = Rotation.from_rotvec(twist * s[i] * axis)
            p[i] = r.apply(p[i])
        p += rng.normal(0.0, 0.15, size=p.shape)
        p = Rotation.random(random_state=rng.integers(1 << 31)).apply(p)
        p += centre + rng.normal(0.0, 3.0, size=3)
        atoms.positions = p
        out.write(atoms)

out = {}
for sel, aligned in [("name CA", True), ("backbone", True), ("name CA", False), ("backbone", False)]:
    u = mda.Universe("../dihedrals/helix.pdb", "helix_pca.xtc")
    if aligned:
        align.AlignTraj(u, u, select=sel, in_memory=True).run()
    pc = pca.PCA(u, select=sel).run()
    group = u.select_atoms(sel)
    space = pc.transform(group, n_components=3)
    key = ("aligned " if aligned else "raw ") + sel
    out[key] = {
        "atoms": int(group.n_atoms),
        "frames": int(len(u.trajectory)),
        "variance": [float(x) for x in np.real(pc.results.variance)],
        "cumulated_variance": [float(x) for x in np.real(pc.results.cumulated_variance)],
        "components": [[float(x) for x in np.real(pc.results.p_components[:, k])] for k in range(3)],
        "projections": [[float(x) for x in row] for row in np.real(space)],
        "mean": [float(x) for x in np.ravel(pc.mean)],
        "cosine_content": [float(pca.cosine_content(np.real(space), k)) for k in range(3)],
    }
    print(aligned, sel, group.n_atoms, np.real(pc.results.variance[:4]), out[key]["cosine_content"])
def rounded(x):
    """Ten significant digits: the file's size, far below the tests' tolerances."""
    if isinstance(x, float):
        return float(f"{x:.10g}")
    if isinstance(x, list):
        return [rounded(y) for y in x]
    if isinstance(x, dict):
        return {k: rounded(y) for k, y in x.items()}
    return x


with open("pca_reference.json", "w") as f:
    json.dump(rounded(out), f)
    f.write("\n")
