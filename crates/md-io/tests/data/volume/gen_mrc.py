"""CCP4/MRC maps written by mrcfile 1.5.4 (the CCP-EM reference implementation), and what
GridDataFormats 1.2.0 (MDAnalysis's grid reader) reads from them: references for md-io's MRC
reader (crates/md-io/tests/volume.rs).

Run from this directory: python3 gen_mrc.py

- emd_float.mrc: float32, little-endian, 20 x 24 x 28 (x, y, z), voxels 1.25 x 1.5 x 0.75 A,
  ORIGIN (10.5, -3.0, 7.25), NSTART 0, values f(x, y, z) at the points (below), a label.
- ccp4_int16_be.map: int16, big-endian, columns along Z, rows along X, sections along Y (MAPC,
  MAPR, MAPS = 3, 1, 2), NSTART (-4, 6, 2) in that order, ORIGIN 0, 1 A voxels, an extended
  header of 160 bytes; values round(100 f).
- uint16_half.mrc: uint16 (mode 6) and half_float.mrc: float16 (mode 12), 6 x 5 x 4.
- mrc_reference.json: for each file, GridDataFormats' shape, origin, delta and every value in
  x, y, z order (x slowest), and f's formula.
"""
import json

import numpy as np
import mrcfile
import gridData


def f(x, y, z):
    return np.sin(0.3 * x) + 0.05 * y * y - 0.1 * z + 0.02 * x * z


ref = {"formula": "sin(0.3 x) + 0.05 y^2 - 0.1 z + 0.02 x z"}

# 1. float32, standard axes.
nx, ny, nz = 20, 24, 28
vox = (1.25, 1.5, 0.75)
org = (10.5, -3.0, 7.25)
X, Y, Z = np.meshgrid(*[org[a] + vox[a] * np.arange(n) for a, n in enumerate((nx, ny, nz))],
                      indexing="ij")
with mrcfile.new("emd_float.mrc", overwrite=True) as m:
    m.set_data(np.ascontiguousarray(f(X, Y, Z).astype(np.float32).transpose(2, 1, 0)))
    m.voxel_size = vox
    m.header.origin = org
    m.header.label[0] = b"texmap test map: f(x, y, z) at the grid points"
    m.header.nlabl = 1

# 2. int16 big-endian, permuted axes, nstart, extended header.
nx, ny, nz = 9, 7, 11
# Columns along Z, rows along X, sections along Y: data[s, r, c] = data[y, x, z].
nstart_crs = (-4, 6, 2)  # along Z, X, Y
start_xyz = (6, 2, -4)
X, Y, Z = np.meshgrid(*[np.arange(n) + start_xyz[a] for a, n in enumerate((nx, ny, nz))],
                      indexing="ij")
vals = np.round(100 * f(X * 1.0, Y * 1.0, Z * 1.0)).astype(np.int16)  # [x, y, z]
with mrcfile.new("ccp4_int16_be.map", overwrite=True) as m:
    m.set_data(np.ascontiguousarray(vals.transpose(1, 0, 2)).astype(">i2"))
    m.set_extended_header(np.zeros(160, dtype="V1"))
    m.voxel_size = 1.0
    m.header.mapc, m.header.mapr, m.header.maps = 3, 1, 2
    m.header.nxstart, m.header.nystart, m.header.nzstart = nstart_crs
    m.header.cella = (nx * 1.0, ny * 1.0, nz * 1.0)
    m.header.mx, m.header.my, m.header.mz = nx, ny, nz

# 3. uint16 and float16.
small = (np.arange(120).reshape(4, 5, 6) * 7 % 251)
with mrcfile.new("uint16_half.mrc", overwrite=True) as m:
    m.set_data(small.astype(np.uint16))
    m.voxel_size = 2.0
with mrcfile.new("half_float.mrc", overwrite=True) as m:
    m.set_data((small / 8.0 - 10.0).astype(np.float16))
    m.voxel_size = 0.5

for name in ["emd_float.mrc", "ccp4_int16_be.map", "uint16_half.mrc", "half_float.mrc"]:
    with mrcfile.open(name) as m:
        print(name, m.data.dtype, m.header.mode, m.header.machst, m.header.nsymbt,
              m.header.mapc, m.header.mapr, m.header.maps)
    g = gridData.Grid(name, file_format="MRC")
    ref[name] = {
        "shape": list(g.grid.shape),
        "origin": np.asarray(g.origin, dtype=float).tolist(),
        "delta": np.asarray(np.diag(g.delta) if g.delta.ndim == 2 else g.delta, float).tolist(),
        "values": g.grid.astype(float).ravel().tolist(),
    }
json.dump(ref, open("mrc_reference.json", "w"))
