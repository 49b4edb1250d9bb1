"""Per-atom values written by numpy, for `texmap render --property` (tests/md_inputs.rs).

From md-io's MDAnalysis fixture (tests/data/topo_mda.gro + topo_mda.xtc: 66 atoms, 4 frames):
- `rmsf.txt`: each atom's RMSF over the 4 frames (MDAnalysis 2.11 `RMSF`, no fit), one column,
  `numpy.savetxt` with a header comment;
- `dist.csv`: per frame (rows) each atom's distance from the frame's centre of geometry,
  `numpy.savetxt(delimiter=",")`;
- `values_reference.json`: the atom indices numpy selects: RMSF above its median, and in frame 3
  distance below 6 Å.

Run: `pip install MDAnalysis==2.11.0 numpy; python3 gen_values.py`.
"""
import json

import MDAnalysis as mda
import numpy as np
from MDAnalysis.analysis.rms import RMSF

data = "../../../../md-io/tests/data/"
u = mda.Universe(data + "topo_mda.gro", data + "topo_mda.xtc")
rmsf = RMSF(u.atoms).run().results.rmsf
np.savetxt("rmsf.txt", rmsf, fmt="%.6f", header="RMSF (A) per atom, MDAnalysis 2.11")
dist = np.array([np.linalg.norm(u.atoms.positions - u.atoms.center_of_geometry(), axis=1)
                 for ts in u.trajectory])
np.savetxt("dist.csv", dist, fmt="%.5f", delimiter=",")
median = float(np.median(rmsf))
json.dump({
    "rmsf_threshold": median,
    "rmsf_above": [int(i) for i in np.where(rmsf > median)[0]],
    "dist_frame3_below_6": [int(i) for i in np.where(dist[3] < 6.0)[0]],
}, open("values_reference.json", "w"), indent=1)
print(len(rmsf), dist.shape, median)
