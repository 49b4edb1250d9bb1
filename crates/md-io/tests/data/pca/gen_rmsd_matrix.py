"""MDAnalysis 2.11.0's pairwise RMSD matrix: the reference for md-io's `rmsd::rmsd_matrix` and
`texmap convert --rmsd-matrix` (crates/cli/tests/convert.rs).

Run from this directory: python3 gen_rmsd_matrix.py

rmsd_matrix_reference.json: analysis.diffusionmap.DistanceMatrix(u, select='name CA',
metric=partial(rms.rmsd, center=True, superposition=True)).run(step=2).results.dist_matrix
on ../dihedrals/helix.pdb + helix_pca.xtc (the bending, twisting helix of gen_pca.py, turned
and moved at random every frame): every second frame (0, 2, ..., 78), each pair's RMSD after
the optimal superposition (unweighted; as gmx rms -m and cpptraj's 2drms fit by default;
DistanceMatrix's own default metric does not superpose), 40 x 40, row-major, seven
significant digits.
"""
import json
import warnings

from functools import partial

import MDAnalysis as mda
from MDAnalysis.analysis import rms
from MDAnalysis.analysis.diffusionmap import DistanceMatrix

warnings.simplefilter("ignore")
u = mda.Universe("../dihedrals/helix.pdb", "helix_pca.xtc")
metric = partial(rms.rmsd, center=True, superposition=True)
d = DistanceMatrix(u, select="name CA", metric=metric).run(step=2)
m = d.results.dist_matrix
print(m.shape, m[0, :4], m.max())
with open("rmsd_matrix_reference.json", "w") as f:
    json.dump({"select": "name CA", "step": 2, "frames": int(m.shape[0]),
               "matrix": [float(f"{x:.7g}") for x in m.ravel()]}, f)
    f.write("\n")
