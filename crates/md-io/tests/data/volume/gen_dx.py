"""MDAnalysis 2.11.0's DensityAnalysis (GridDataFormats 1.2.0 writes the OpenDX files): references
for md-io's OpenDX reader and `density::DensityMap` (crates/md-io/tests/volume.rs) and for
`--density-map` (crates/cli/tests/convert.rs).

Run from this directory: python3 gen_dx.py

The trajectory is ../dynamics/walk.gro + walk.dcd (gen_dynamics.py): 200 OW and 100 NA atoms on
random walks wrapped into an 18 A box, 40 frames.
- density_ow.dx: the OW atoms' density, delta 1.5 A, MDAnalysis's default padding (2 A) around
  frame 0's atoms, averaged over the 40 frames (atoms per A^3).
- density_na.dx.gz: the NA atoms', delta 1.0 A, padding 0: later frames put some NA atoms
  outside the grid that frame 0's atoms span, which MDAnalysis drops; numpy counts them here.
- density_reference.json: per map the grid's cells, edges, origin and delta as MDAnalysis and
  GridDataFormats hold them, the frames, the positions counted and those outside the grid.
"""
import json

import numpy as np
import MDAnalysis as mda
from MDAnalysis.analysis.density import DensityAnalysis

ref = {}
for key, sel, delta, padding, out in [
    ("ow", "name OW", 1.5, 2.0, "density_ow.dx"),
    ("na", "name NA", 1.0, 0.0, "density_na.dx.gz"),
]:
    u = mda.Universe("../dynamics/walk.gro", "../dynamics/walk.dcd")
    group = u.select_atoms(sel)
    d = DensityAnalysis(group, delta=delta, padding=padding).run()
    grid = d.results.density
    grid.export(out)
    edges = d._edges
    lo = np.array([e[0] for e in edges])
    hi = np.array([e[-1] for e in edges])
    outside = 0
    counted = 0
    for ts in u.trajectory:
        p = group.positions.astype(np.float64)
        inside = np.all((p >= lo) & (p <= hi), axis=1)
        outside += int((~inside).sum())
        counted += int(inside.sum())
    cell = float(np.prod([np.diff(e)[0] for e in edges]))
    ref[key] = {
        "select": sel,
        "delta": delta,
        "padding": padding,
        "cells": list(grid.grid.shape),
        "lo": lo.tolist(),
        "hi": hi.tolist(),
        "origin": grid.origin.tolist(),
        "grid_delta": (np.diag(grid.delta) if grid.delta.ndim == 2 else grid.delta).tolist(),
        "frames": int(d.n_frames),
        "counted": counted,
        "outside": outside,
        "sum": float(grid.grid.sum()),
        "max": float(grid.grid.max()),
        "counted_from_grid": float(grid.grid.sum() * cell * d.n_frames),
    }
    print(key, ref[key]["cells"], "outside", outside, "counted", counted,
          "from grid", ref[key]["counted_from_grid"])
json.dump(ref, open("density_reference.json", "w"), indent=1)
