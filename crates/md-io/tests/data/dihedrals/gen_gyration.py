"""MDAnalysis 2.11.0's radius of gyration: the reference for `--gyration-table`
(crates/cli/tests/convert.rs), on helix.pdb + helix.dcd (see gen_dihedrals.py).

Run from this directory: python3 gen_gyration.py

gyration_reference.json, per selection ('protein', 'name CA') and frame: the mass-weighted
radius of gyration (AtomGroup.radius_of_gyration(), A, masses MDAnalysis guessed from the
elements), the unweighted one (numpy: the root mean square distance from the centroid), and
gmx gyrate's radii about the x, y and z axes through the centre of mass, sqrt(sum m (y^2 + z^2)
/ M) and so on (numpy, the same masses), and the relative shape anisotropy of the mass-weighted
gyration tensor (AtomGroup.asphericity(): 0 for a sphere, 1 for a rod).
"""
import json

import numpy as np
import MDAnalysis as mda

u = mda.Universe("helix.pdb", "helix.dcd")
out = {}
for sel in ("protein", "name CA"):
    g = u.select_atoms(sel)
    rows = []
    for ts in u.trajectory:
        m = g.masses
        d = g.positions - g.center_of_mass()
        about = [np.sqrt((m * (d[:, (a + 1) % 3] ** 2 + d[:, (a + 2) % 3] ** 2)).sum() / m.sum()) for a in range(3)]
        c = g.positions - g.positions.mean(axis=0)
        rows.append({
            "rg": float(g.radius_of_gyration()),
            "unweighted": float(np.sqrt((c ** 2).sum(axis=1).mean())),
            "about": [float(x) for x in about],
            "asphericity": float(g.asphericity()),
        })
    out[sel] = {"atoms": int(g.n_atoms), "frames": rows}
    print(sel, g.n_atoms, rows[0])
with open("gyration_reference.json", "w") as f:
    json.dump(out, f)
    f.write("\n")
