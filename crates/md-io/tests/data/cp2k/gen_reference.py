"""What ASE 3.29 reads from the CP2K outputs (gen.sh), and the CP2K restart's cell and
positions of the last step, for crates/md-io/tests/cp2k.rs.

reference.json:
  npt_frames / opt_frames: per frame of the -pos-1.xyz, ASE's info (i, time, E) and positions;
  npt_wrapped: per frame of ar_npt-pos-1.xyz, the positions ASE's Atoms.wrap() gives with the
      cell the .cell file holds at the frame's step (read here with numpy, independently of
      our reader);
  restart: the &CELL vectors and &COORD positions of ar_npt-1.restart (step 40).
"""
import json
import numpy as np
from ase.io import read

out = {}
for key, name in [("npt_frames", "ar_npt-pos-1.xyz"), ("opt_frames", "ar_opt-pos-1.xyz")]:
    frames = []
    for atoms in read(name, ":"):
        info = {k: (int(v) if isinstance(v, (int, np.integer)) else float(v)) for k, v in atoms.info.items()}
        frames.append({"info": info, "symbols": atoms.get_chemical_symbols(),
                       "positions": atoms.positions.tolist()})
    out[key] = frames

table = np.loadtxt("ar_npt-1.cell")
cells = {int(row[0]): row[2:11].reshape(3, 3) for row in table}
wrapped = []
for atoms in read("ar_npt-pos-1.xyz", ":"):
    atoms.set_cell(cells[int(atoms.info["i"])])
    atoms.pbc = True
    atoms.wrap()
    wrapped.append(atoms.positions.tolist())
out["npt_wrapped"] = wrapped

lines = open("ar_npt-1.restart").read().splitlines()
cell, coords, in_coord = {}, [], False
for line in lines:
    f = line.split()
    if not f:
        continue
    if f[0] in ("A", "B", "C") and len(f) == 4 and f[0] not in cell:
        cell[f[0]] = [float(x) for x in f[1:]]
    if f[0] == "&COORD":
        in_coord = True
        continue
    if f[0] == "&END" and in_coord:
        in_coord = False
    elif in_coord and f[0] == "Ar":
        coords.append([float(x) for x in f[1:4]])
out["restart"] = {"step": 40, "cell": [cell["A"], cell["B"], cell["C"]], "positions": coords}
json.dump(out, open("reference.json", "w"), indent=0)
print({k: len(v) for k, v in out.items()})
