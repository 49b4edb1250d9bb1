"""NAMD binary coordinates written by MDAnalysis 2.11 (NAMDBINWriter), read back by it.

Writes, beside this script:
  topo_mda.coor     frame 2 of ../topo_mda.xtc (66 atoms) in the writer's (little-endian) order
  topo_mda_be.coor  the same bytes in big-endian order (numpy byteswap), as NAMD on a big-endian
                    machine writes them
  reference.json    MDAnalysis's reading of topo_mda.coor (NAMDBINReader): n_atoms, positions
"""
import json
import os

import numpy as np
import MDAnalysis as mda

here = os.path.dirname(os.path.abspath(__file__))
data = os.path.dirname(here)
u = mda.Universe(os.path.join(data, "topo_mda.pdb"), os.path.join(data, "topo_mda.xtc"))
u.trajectory[2]
out = os.path.join(here, "topo_mda.coor")
with mda.Writer(out, n_atoms=len(u.atoms)) as w:
    w.write(u.atoms)
raw = open(out, "rb").read()
n = np.frombuffer(raw[:4], dtype="<i4")
xyz = np.frombuffer(raw[4:], dtype="<f8")
with open(os.path.join(here, "topo_mda_be.coor"), "wb") as f:
    f.write(n.astype(">i4").tobytes())
    f.write(xyz.astype(">f8").tobytes())
back = mda.Universe(os.path.join(data, "topo_mda.pdb"), out, format="NAMDBIN")
with open(os.path.join(here, "reference.json"), "w") as f:
    json.dump({"n_atoms": len(back.atoms),
               "positions": back.atoms.positions.astype(float).tolist()}, f)
    f.write("\n")
