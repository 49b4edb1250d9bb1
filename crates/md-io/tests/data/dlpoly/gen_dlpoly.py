"""DL_POLY files: CONFIGs written by ASE 3.29 (`format="dlp4"`), a HISTORY written here in
DL_POLY 4's fixed-record layout; all read back by MDAnalysis 2.11 and ASE.

Writes, beside this script:
  CONFIG          ASE: 24 seeded Na/Cl atoms in a triclinic cell (imcon 3) with velocities
                  (levcfg 1)
  CONFIG_molecule ASE: a water molecule, no cell (imcon 0), positions only (levcfg 0)
  HISTORY         3 frames of the CONFIG's atoms drifting, levcfg 2 (velocities and forces),
                  imcon 3, every record padded to 72 columns as DL_POLY 4 writes them (ASE finds
                  frames by that record length); frame 1 lists its atoms in reverse index
                  order, as a parallel run may
  reference.json  MDAnalysis's reading (ConfigReader / HistoryReader: positions, velocities,
                  forces, boxes, names, ids; atoms put in index order) and ASE's (positions,
                  cells)
"""
import json
import os

import numpy as np
import ase
import ase.io
import ase.io.dlp4
import MDAnalysis as mda

here = os.path.dirname(os.path.abspath(__file__))
rng = np.random.default_rng(3)
cell = np.array([[12.0, 0.0, 0.0], [2.0, 11.0, 0.0], [1.0, 1.5, 10.0]])
n = 24
frac = rng.uniform(0, 1, size=(n, 3))
pos = frac @ cell
symbols = ["Na", "Cl"] * (n // 2)
atoms = ase.Atoms(symbols, positions=pos, cell=cell, pbc=True)
atoms.set_velocities(rng.normal(0, 0.01, size=(n, 3)))
ase.io.write(os.path.join(here, "CONFIG"), atoms, format="dlp4", levcfg=1)
water = ase.Atoms("OH2", positions=[[0, 0, 0], [0.9572, 0, 0], [-0.24, 0.927, 0]])
ase.io.write(os.path.join(here, "CONFIG_molecule"), water, format="dlp4")

W = 72


def rec(text):
    assert len(text) <= W, text
    return f"{text:<{W}}\n"


masses = {"Na": 22.99, "Cl": 35.453}
charges = {"Na": 1.0, "Cl": -1.0}
out = [rec("DL_POLY 4 HISTORY written for texmap's tests"),
       rec(f"{2:10d}{3:10d}{n:10d}{3:21d}{3 + 3 * (4 + 4 * n):21d}")]
for k in range(3):
    nstep = 100 * (k + 1)
    out.append(rec(f"timestep{nstep:10d}{n:10d}{2:2d}{3:2d}{0.001:20.6f}{nstep * 0.001:20.6f}"))
    c = cell * (1 + 0.01 * k)
    for row in c:
        out.append(rec("".join(f"{x:20.10f}" for x in row)))
    order = range(n) if k != 1 else reversed(range(n))
    for i in order:
        p = pos[i] + 0.1 * k
        v = rng.normal(0, 1, 3)
        f = rng.normal(0, 100, 3)
        s = symbols[i]
        out.append(rec(f"{s:<8s}{i + 1:10d}{masses[s]:12.6f}{charges[s]:12.6f}{0.0:12.6f}"))
        for vec in (p, v, f):
            out.append(rec("".join(f"{x:20.10f}" for x in vec)))
with open(os.path.join(here, "HISTORY"), "w") as fh:
    fh.writelines(out)

ref = {}
for name, fmt in [("CONFIG", "CONFIG"), ("CONFIG_molecule", "CONFIG"), ("HISTORY", "HISTORY")]:
    u = mda.Universe(os.path.join(here, name), format=fmt, topology_format=fmt)
    frames = []
    for ts in u.trajectory:
        frames.append({
            "positions": ts.positions.astype(float).tolist(),
            "velocities": ts.velocities.astype(float).tolist() if ts.has_velocities else None,
            "forces": ts.forces.astype(float).tolist() if ts.has_forces else None,
            "box": None if ts.dimensions is None else [float(x) for x in ts.dimensions],
        })
    if name == "HISTORY":
        with open(os.path.join(here, name)) as fh:
            images = ase.io.dlp4.read_dlp_history(fh)
    else:
        images = [ase.io.read(os.path.join(here, name), format="dlp4")]
    ref[name] = {
        "names": [str(x) for x in u.atoms.names],
        "ids": [int(x) for x in u.atoms.ids],
        "frames": frames,
        "ase_positions": [im.positions.tolist() for im in images],
        "ase_cells": [im.cell.array.tolist() for im in images],
    }
with open(os.path.join(here, "reference.json"), "w") as fh:
    json.dump(ref, fh, separators=(",", ":"))
    fh.write("\n")
