"""AMBER ASCII coordinate files written by ParmEd, read back by MDAnalysis and ParmEd.

Writes, beside this script:
  box.mdcrd     ParmEd 4.3.1 AmberMdcrd(hasbox=True): the 66 atoms of ../prmtop_parmed.prmtop,
                the 4 frames of ../amber_mda.ncdf and a fifth moved to (-150, +1200, -99) Å so
                that 8-column fields run together ("-150.123" fills its field, "1234.567" too)
  nobox.mdcrd   the same 5 frames without box lines
  ten.mdcrd     10 seeded atoms (30 numbers: the last coordinate line is full), 3 frames with boxes
  vel_box.rst7  ParmEd Rst7: the 66 atoms' frame 0, seeded velocities, box, time
  odd.inpcrd    ParmEd Rst7: 7 seeded atoms (a half line), coordinates only
  vel_box.ncrst ParmEd NetCDFRestart (AMBERRESTART convention, over scipy's NetCDF-3 writer):
                the same frame, velocities, box and time as vel_box.rst7
  truncoct.parm7  ParmEd (load_file + box + save) of ../prmtop_parmed.prmtop in a truncated
                octahedron (IFBOX 2, BOX_DIMENSIONS)
  reference.json
                MDAnalysis 2.11 (TRJReader with the atom count, INPCRDReader) and ParmEd's own readers
                (AmberMdcrd(mode="r"), Rst7.open): positions, boxes, velocities, times.
Seeded (numpy default_rng(11)): reruns give the same files.
"""
import json
import os

import numpy as np
import MDAnalysis as mda
from parmed.amber import AmberMdcrd, Rst7

here = os.path.dirname(os.path.abspath(__file__))
data = os.path.dirname(here)
rng = np.random.default_rng(11)

u = mda.Universe(os.path.join(data, "prmtop_parmed.prmtop"), os.path.join(data, "amber_mda.ncdf"))
n = len(u.atoms)
frames = [ts.positions.astype(np.float64).copy() for ts in u.trajectory]
moved = frames[0] + np.array([-150.0, 1200.0, -99.0])
frames.append(moved)
boxes = [[18.0 + 0.25 * k, 18.5 + 0.25 * k, 19.0 + 0.125 * k] for k in range(len(frames))]


def write_mdcrd(name, frames, boxes, natom):
    f = AmberMdcrd(os.path.join(here, name), natom=natom, hasbox=boxes is not None, mode="w",
                   title="written by ParmEd for texmap's tests")
    for k, xyz in enumerate(frames):
        f.add_coordinates(np.asarray(xyz).reshape(-1))
        if boxes is not None:
            f.add_box(boxes[k])
    f.close()


write_mdcrd("box.mdcrd", frames, boxes, n)
write_mdcrd("nobox.mdcrd", frames, None, n)
ten = [rng.uniform(-20, 20, size=(10, 3)) for _ in range(3)]
ten_boxes = [[40.0, 41.0, 42.0 + k] for k in range(3)]
write_mdcrd("ten.mdcrd", ten, ten_boxes, 10)

rst = Rst7(natom=n, title="ParmEd restart for texmap's tests")
rst.coordinates = frames[0].reshape(1, n, 3)
rst.vels = rng.normal(0.0, 0.5, size=(1, n, 3))
rst.box = [30.5, 31.25, 32.0, 90.0, 101.5, 90.0]
rst.time = 1234.5
rst.write(os.path.join(here, "vel_box.rst7"))

from parmed.amber.netcdffiles import NetCDFRestart
nc = NetCDFRestart.open_new(os.path.join(here, "vel_box.ncrst"), natom=n, box=True, vels=True,
                            title="ParmEd NetCDF restart for texmap's tests")
nc.coordinates = rst.coordinates.reshape(n, 3)
nc.velocities = rst.vels.reshape(n, 3)
nc.box = rst.box
nc.time = rst.time
nc.close()

odd = Rst7(natom=7, title="seven atoms")
odd.coordinates = rng.uniform(-9, 9, size=(1, 7, 3))
odd.write(os.path.join(here, "odd.inpcrd"))

import parmed
for name, box in [("truncoct.parm7", [40.0, 40.0, 40.0, 109.4712206, 109.4712206, 109.4712206])]:
    parm = parmed.load_file(os.path.join(data, "prmtop_parmed.prmtop"))
    parm.box = box
    parm.save(os.path.join(here, name), overwrite=True)

ref = {}
for name in ["truncoct.parm7"]:
    back = parmed.load_file(os.path.join(here, name))
    ref[name] = {"parmed_box": [float(x) for x in back.box],
                 "ifbox": int(back.parm_data["POINTERS"][27])}


def mda_traj(name, natom):
    r = mda.coordinates.TRJ.TRJReader(os.path.join(here, name), n_atoms=natom)
    out = {"n_atoms": natom, "periodic": bool(r.periodic), "positions": [], "boxes": []}
    for ts in r:
        out["positions"].append(ts.positions.astype(float).tolist())
        out["boxes"].append(None if ts.dimensions is None else [float(x) for x in ts.dimensions])
    return out


for name, natom in [("box.mdcrd", n), ("nobox.mdcrd", n), ("ten.mdcrd", 10)]:
    ref[name] = {"mdanalysis": mda_traj(name, natom)}
    if natom * 3 % 10 == 0:
        continue  # ParmEd's reader misreads a frame whose last coordinate line is full
    back = AmberMdcrd(os.path.join(here, name), natom=natom, hasbox=name != "nobox.mdcrd")
    ref[name]["parmed"] = {
        "positions": np.asarray(back.coordinates).tolist(),
        "boxes": None if name == "nobox.mdcrd" else np.asarray(back.box).tolist(),
    }

for name in ["vel_box.rst7", "odd.inpcrd"]:
    r = Rst7.open(os.path.join(here, name))
    entry = {
        "parmed": {
            "natom": r.natom,
            "positions": np.asarray(r.coordinates).reshape(-1, 3).tolist(),
            "velocities": np.asarray(r.vels).reshape(-1, 3).tolist() if r.hasvels else None,
            "box": list(map(float, r.box)) if r.hasbox else None,
            "time": float(r.time) if getattr(r, "time", None) is not None else None,
        }
    }
    m = mda.coordinates.INPCRD.INPReader(os.path.join(here, name))
    entry["mdanalysis"] = {"positions": m.ts.positions.astype(float).tolist(), "time": float(m.ts.time)}
    ref[name] = entry

with open(os.path.join(here, "reference.json"), "w") as f:
    json.dump(ref, f, indent=None, separators=(",", ":"))
    f.write("\n")
