"""Write a small solvated peptide as a topology (PDB with CONECT, GRO, LAMMPS data file) plus
trajectories of the same atoms (XTC, DCD, AMBER NetCDF) with MDAnalysis, and what MDAnalysis
reads back from each (topology_reference.json), for crates/md-io/tests/topology.rs and
tests/netcdf.rs.

3 alanines (N H CA HA CB HB1 HB2 HB3 C O, bonded as in the amino acid, peptide bonds C-N) and
12 waters (OW HW1 HW2, resname SOL, bonds OW-HW1 OW-HW2): 66 atoms at seeded positions in a
periodic 18 Å cube; 4 frames, each displaced by seeded noise, times 0, 2.5, 5, 7.5 ps.
"""
import json
import warnings

import MDAnalysis as mda
import numpy as np
from MDAnalysis.coordinates.TRJ import NCDFWriter

warnings.filterwarnings("ignore")
ala = ["N", "H", "CA", "HA", "CB", "HB1", "HB2", "HB3", "C", "O"]
ala_bonds = [(0, 1), (0, 2), (2, 3), (2, 4), (4, 5), (4, 6), (4, 7), (2, 8), (8, 9)]
names, resnames, resids, elements, resindex, types, bonds = [], [], [], [], [], [], []
r = 0
for k in range(3):
    base = len(names)
    for a in ala:
        names.append(a); elements.append(a[0]); resindex.append(r)
        types.append({"N": "1", "H": "2", "C": "3", "O": "4"}[a[0]])
    bonds += [(base + i, base + j) for i, j in ala_bonds]
    if k > 0:
        bonds.append((base - 2, base))  # C(k-1) - N(k)
    resnames.append("ALA"); resids.append(k + 1); r += 1
for k in range(12):
    base = len(names)
    for a, e in (("OW", "O"), ("HW1", "H"), ("HW2", "H")):
        names.append(a); elements.append(e); resindex.append(r)
        types.append({"O": "5", "H": "6"}[e])
    bonds += [(base, base + 1), (base, base + 2)]
    resnames.append("SOL"); resids.append(4 + k); r += 1
n = len(names)
u = mda.Universe.empty(n, n_residues=r, atom_resindex=resindex, trajectory=True)
u.add_TopologyAttr("name", names)
u.add_TopologyAttr("resname", resnames)
u.add_TopologyAttr("resid", resids)
u.add_TopologyAttr("element", elements)
u.add_TopologyAttr("type", types)
u.add_TopologyAttr("masses", [{"N": 14.007, "H": 1.008, "C": 12.011, "O": 15.999}[e] for e in elements])
u.add_TopologyAttr("charges", [0.1 * ((i % 5) - 2) for i in range(n)])
u.add_bonds(bonds, types=["1"] * len(bonds), guessed=False)
for _attr in ("angles", "dihedrals", "impropers"):
    u.add_TopologyAttr(_attr, [])
rng = np.random.default_rng(20261203)
start = rng.uniform(1.0, 17.0, size=(n, 3)).astype(np.float32)
frames = [start + rng.normal(0.0, 0.3, size=(n, 3)).astype(np.float32) for _ in range(4)]
box = np.array([18.0, 18.0, 18.0, 90.0, 90.0, 90.0], dtype=np.float32)
u.atoms.positions = frames[0]
u.dimensions = box
u.atoms.write("topo_mda.pdb", bonds="all")
u.atoms.write("topo_mda.gro")
u.atoms.write("topo_mda.data")
times = [0.0, 2.5, 5.0, 7.5]
with mda.Writer("topo_mda.xtc", n) as w_xtc, mda.Writer("topo_mda.dcd", n) as w_dcd, \
        NCDFWriter("amber_mda.ncdf", n) as w_nc:
    for k, f in enumerate(frames):
        u.atoms.positions = f
        # A triclinic cell on the NetCDF frames after the first, to check angles.
        u.dimensions = box if k == 0 else np.array([18.0 + k, 19.0, 20.0, 90.0, 80.0 + k, 95.0], dtype=np.float32)
        u.trajectory.ts.time = times[k]
        w_xtc.write(u.atoms)
        w_dcd.write(u.atoms)
        w_nc.write(u.atoms)

def topo(path, **kw):
    v = mda.Universe(path, **kw)
    a = v.atoms
    out = {"n_atoms": len(a),
           "bonds": sorted(sorted(map(int, b)) for b in v.bonds.indices) if hasattr(v, "bonds") else []}
    for attr in ("names", "resnames", "resids", "types", "elements", "ids"):
        try:
            vals = getattr(a, attr)
            out[attr] = [x.item() if hasattr(x, "item") else x for x in vals]
        except Exception:
            pass
    out["positions"] = a.positions.astype(float).tolist()
    return out

ref = {"pdb": topo("topo_mda.pdb"), "gro": topo("topo_mda.gro"),
       "data": topo("topo_mda.data", format="DATA", atom_style="id resid type charge x y z")}
nc = mda.Universe("topo_mda.gro", "amber_mda.ncdf")
ref["ncdf"] = [{"time": float(ts.time), "dimensions": ts.dimensions.astype(float).tolist(),
                "positions": nc.atoms.positions.astype(float).tolist()} for ts in nc.trajectory]
xtc = mda.Universe("topo_mda.gro", "topo_mda.xtc")
ref["xtc_frames"] = len(xtc.trajectory)
with open("topology_reference.json", "w") as f:
    json.dump(ref, f, indent=None)

# A CDF-1 (classic) AMBER file with velocities carrying AMBER's scale_factor, written by scipy's
# own NetCDF-3 writer, and what scipy reads back (velocities times scale_factor, in Å/ps).
from scipy.io import netcdf_file

m = 5
with netcdf_file("amber_scipy_cdf1.nc", "w", version=1) as f:
    f.Conventions = "AMBER"
    f.ConventionVersion = "1.0"
    f.createDimension("frame", None)
    f.createDimension("atom", m)
    f.createDimension("spatial", 3)
    f.createDimension("cell_spatial", 3)
    f.createDimension("cell_angular", 3)
    c = f.createVariable("coordinates", "f", ("frame", "atom", "spatial"))
    c.units = "angstrom"
    v = f.createVariable("velocities", "f", ("frame", "atom", "spatial"))
    v.units = "angstrom/picosecond"
    v.scale_factor = np.float64(20.455)
    t = f.createVariable("time", "f", ("frame",))
    t.units = "picosecond"
    cl = f.createVariable("cell_lengths", "d", ("frame", "cell_spatial"))
    ca = f.createVariable("cell_angles", "d", ("frame", "cell_angular"))
    for k in range(3):
        c[k] = rng.uniform(-5.0, 5.0, size=(m, 3)).astype(np.float32)
        v[k] = rng.normal(0.0, 0.05, size=(m, 3)).astype(np.float32)
        t[k] = 1.0 + k
        cl[k] = [30.0, 31.0, 32.0 + k]
        ca[k] = [90.0, 90.0, 90.0]
with netcdf_file("amber_scipy_cdf1.nc", "r", mmap=False) as f:
    ref["scipy_cdf1"] = {
        "positions": f.variables["coordinates"][:].astype(float).tolist(),
        "velocities": (f.variables["velocities"][:].astype(float) * 20.455).tolist(),
        "time": f.variables["time"][:].astype(float).tolist(),
        "cell_lengths": f.variables["cell_lengths"][:].astype(float).tolist(),
    }
with open("topology_reference.json", "w") as f:
    json.dump(ref, f, indent=None)
