"""Fixtures for crates/md-io/tests/netcdf_writer.rs: AMBER NetCDF files our writer wrote, and
what two independent readers read from them.

- gsd_tri.nc, vel_trr.nc, nacl_rotated.nc: written by texmap-md-io's `Writer` (Format::Netcdf)
  from the inputs `cases()` in tests/netcdf_writer.rs lists:
    gsd_tri       ../gsd/hoomd_tri.gsd frames 0-3 (200 particles, triclinic box changing in
                  frame 3, velocities, no times: time is the frame index);
    vel_trr       ../dynamics/vel.trr frames 0-4 (36 atoms, cubic box, times, velocities);
    nacl_rotated  ../lammps_write/nacl_primitive.vasp (ASE's rocksalt primitive cell, whose
                  lattice vectors are not in AMBER's orientation: the writer rotates the atoms)
                  with made-up velocities [0.5 - 0.25 i, 0.125 i, -1.5] for atom i.
  This script has the test write them (NETCDF_WRITE_REGENERATE=1); the test itself writes them
  again and requires the same bytes.
- reference.json.gz (gzip without a time stamp, so reruns give the same bytes): per file
    "mdanalysis": MDAnalysis's NCDFReader (scipy's NetCDF-3 reader, scale_factor applied by
                  MDAnalysis): n_atoms, n_frames, per frame time, dimensions (float32 a b c
                  alpha beta gamma), positions and velocities (Å/ps);
    "netcdf4":    the netCDF4 Python module over Unidata's netCDF-C library: file format,
                  dimensions [size, unlimited], global attributes, each variable's dimensions,
                  type and attributes, the char variables as text, time, coordinates,
                  cell_lengths, cell_angles, velocities auto-scaled (float64, stored value x
                  scale_factor) and as stored (velocities_stored, float32, AMBER units);
    "ncdump_k":   `ncdump -k` (netcdf-bin): the container kind libnetcdf reports.

    pip install MDAnalysis==2.11.0 netCDF4; apt install netcdf-bin
    python3 gen_netcdf_write.py        (from anywhere; runs cargo in the workspace)
"""
import gzip
import io
import json
import os
import subprocess

import MDAnalysis
import netCDF4
import numpy as np
from MDAnalysis.coordinates.TRJ import NCDFReader

here = os.path.dirname(os.path.abspath(__file__))
workspace = os.path.abspath(os.path.join(here, "..", "..", "..", "..", ".."))
CASES = ["gsd_tri", "vel_trr", "nacl_rotated"]

env = dict(os.environ, NETCDF_WRITE_REGENERATE="1")
subprocess.run(
    ["cargo", "test", "-p", "texmap-md-io", "--test", "netcdf_writer", "--",
     "--exact", "committed_files_are_what_the_writer_writes"],
    cwd=workspace, env=env, check=True)


def text(v):
    """A char variable's bytes as text, a row per string for 2-D ones."""
    a = np.asarray(v[:])
    if a.ndim == 1:
        return b"".join(a.tolist()).decode()
    return [b"".join(row).decode() for row in a.tolist()]


def attr(x):
    if isinstance(x, (np.floating, float)):
        return float(x)
    if isinstance(x, bytes):
        return x.decode()
    return x


def read_netcdf4(path):
    out = {}
    with netCDF4.Dataset(path) as d:
        out["file_format"] = d.file_format
        out["dimensions"] = {n: [len(x), x.isunlimited()] for n, x in d.dimensions.items()}
        out["attributes"] = {a: attr(d.getncattr(a)) for a in d.ncattrs()}
        out["variables"] = {
            n: {
                "dimensions": list(v.dimensions),
                "dtype": "S1" if v.dtype.kind == "S" else v.dtype.name,
                "attributes": {a: attr(v.getncattr(a)) for a in v.ncattrs()},
            }
            for n, v in d.variables.items()
        }
        for n in ["spatial", "cell_spatial", "cell_angular"]:
            if n in d.variables:
                out[n] = text(d[n])
        for n in ["time", "coordinates", "cell_lengths", "cell_angles", "velocities"]:
            if n in d.variables:
                out[n] = np.asarray(d[n][:]).tolist()
        if "velocities" in d.variables:
            v = d["velocities"]
            v.set_auto_scale(False)
            stored = np.asarray(v[:])
            assert stored.dtype == np.float32
            out["velocities_stored"] = stored.tolist()
    return out


def read_mdanalysis(path):
    r = NCDFReader(path)
    frames = []
    for ts in r:
        frames.append({
            "time": float(ts.time),
            "dimensions": None if ts.dimensions is None else ts.dimensions.tolist(),
            "positions": ts.positions.tolist(),
            "velocities": ts.velocities.tolist() if ts.has_velocities else None,
        })
    return {"n_atoms": r.n_atoms, "n_frames": r.n_frames, "frames": frames}


reference = {
    "program": {
        "MDAnalysis": MDAnalysis.__version__,
        "netCDF4": netCDF4.__version__,
        "libnetcdf": netCDF4.__netcdf4libversion__,
    },
    "cases": {},
}
for name in CASES:
    path = os.path.join(here, name + ".nc")
    kind = subprocess.run(["ncdump", "-k", path], capture_output=True, text=True, check=True)
    reference["cases"][name] = {
        "mdanalysis": read_mdanalysis(path),
        "netcdf4": read_netcdf4(path),
        "ncdump_k": kind.stdout.strip(),
    }

buf = io.BytesIO()
with gzip.GzipFile(fileobj=buf, mode="wb", mtime=0, filename="") as gz:
    gz.write(json.dumps(reference, sort_keys=True).encode())
with open(os.path.join(here, "reference.json.gz"), "wb") as f:
    f.write(buf.getvalue())
print("wrote", ", ".join(n + ".nc" for n in CASES), "and reference.json.gz with",
      reference["program"])
