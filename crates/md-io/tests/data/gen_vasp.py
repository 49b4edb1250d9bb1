"""VASP fixtures for tests/vasp.rs, written by ASE and pymatgen, and the reference: every file
read back by ASE (ase.io.read), the reader users of VASP files trust; pymatgen's XDATCAR (a
species after each coordinate, which ASE's reader refuses) read back by pymatgen.

Run from this directory: python3 gen_vasp.py (ASE 3.29, pymatgen 2026.10, numpy).
Writes vasp/*: POSCAR, CONTCAR and XDATCAR files in the layouts those programs write, and
vasp/reference.json: per file, per frame, the chemical symbols, the cell (rows, Å), the
Cartesian positions (Å) (pmg_frames.extxyz: XDATCAR_pmg's frames as ASE writes extended
XYZ), and for POSCAR / CONTCAR files with velocities those in Å/ps as
pymatgen reads them (checked against ASE where no constraint makes ASE project them), or
as ASE reads them where pymatgen reads none.
"""

import json
import os

import numpy as np
from ase import Atoms
from ase.constraints import FixAtoms
from ase.io import read, write
from ase.units import fs
from pymatgen.core import Lattice, Structure
from pymatgen.core.trajectory import Trajectory
from pymatgen.io.vasp import Poscar, Xdatcar

rng = np.random.default_rng(20261204)
out = "vasp"
os.makedirs(out, exist_ok=True)

# A triclinic cell with three species, atoms grouped by species as VASP wants them.
cell = np.array([[7.1, 0.0, 0.0], [1.3, 6.4, 0.0], [-0.9, 1.1, 8.2]])
symbols = ["Fe"] * 3 + ["O"] * 4 + ["Li"] * 2
frac = rng.random((len(symbols), 3))
atoms = Atoms(symbols, scaled_positions=frac, cell=cell, pbc=True)

# ASE: direct coordinates with selective dynamics (two atoms fixed).
a = atoms.copy()
a.set_constraint(FixAtoms(indices=[0, 4]))
write(f"{out}/POSCAR_ase_direct", a, format="vasp", direct=True)

# ASE: Cartesian coordinates with velocities (a CONTCAR of an MD run), .vasp extension.
a = atoms.copy()
a.set_velocities(rng.normal(0, 0.01, (len(a), 3)) * (1 / fs))  # Å/fs in ASE units
write(f"{out}/CONTCAR_ase_vel.vasp", a, format="vasp", direct=False)

# ASE: VASP 4 layout (no species line; the symbols on the comment line).
write(f"{out}/POSCAR_ase_vasp4", atoms, format="vasp", direct=True, vasp5=False)

# ASE: an XDATCAR of a run whose cell changes (ASE writes the header before every frame).
images = []
for k in range(5):
    b = atoms.copy()
    b.set_cell(cell * (1 + 0.01 * k), scale_atoms=True)
    b.positions += rng.normal(0, 0.05, b.positions.shape)
    images.append(b)
write(f"{out}/XDATCAR_ase", images, format="vasp-xdatcar")

# pymatgen: a fixed-cell XDATCAR (one header, a species after each coordinate).
lattice = Lattice(cell)
structs = []
for k in range(6):
    f = frac + rng.normal(0, 0.004, frac.shape)
    structs.append(Structure(lattice, symbols, f))
Trajectory.from_structures(structs, constant_lattice=True).write_Xdatcar(f"{out}/XDATCAR_pmg")

# pymatgen: a POSCAR with selective dynamics and velocities.
s = structs[0]
sd = [[bool(x) for x in row] for row in rng.random((len(s), 3)) > 0.3]
vel = rng.normal(0, 0.01, (len(s), 3)).tolist()
Poscar(s, comment="pymatgen POSCAR", selective_dynamics=sd, velocities=vel).write_file(
    f"{out}/POSCAR_pmg_vel"
)

# ASE: rutile TiO2 from its space group (P4_2/mnm, Baur's 1956 parameters), for the polyhedra
# style; with the volume of each Ti's O6 octahedron by scipy's ConvexHull (the six O within
# 2.3 Å, nearest images by ase.neighborlist) in vasp/rutile_polyhedra.json.
from ase.neighborlist import neighbor_list
from ase.spacegroup import crystal
from scipy.spatial import ConvexHull

rutile = crystal(
    ["Ti", "O"],
    basis=[(0, 0, 0), (0.3048, 0.3048, 0)],
    spacegroup=136,
    cellpar=[4.594, 4.594, 2.959, 90, 90, 90],
)
write(f"{out}/POSCAR_rutile", rutile, format="vasp", direct=True)
i, j, d = neighbor_list("ijD", rutile, 2.3)
volumes = []
for ti in [k for k, s in enumerate(rutile.get_chemical_symbols()) if s == "Ti"]:
    shell = d[(i == ti) & (np.array(rutile.get_chemical_symbols())[j] == "O")]
    assert len(shell) == 6
    volumes.append(ConvexHull(shell).volume)
with open(f"{out}/rutile_polyhedra.json", "w") as fh:
    json.dump({"octahedron_volumes": volumes, "faces": 8}, fh)

reference = {}
for name in sorted(os.listdir(out)):
    if name.endswith((".json", ".extxyz")):
        continue
    fmt = "vasp-xdatcar" if name.startswith("XDATCAR") else "vasp"
    if name == "XDATCAR_pmg":
        frames = [
            Atoms(
                [str(site.specie) for site in st],
                positions=st.cart_coords,
                cell=st.lattice.matrix,
                pbc=True,
            )
            for st in Xdatcar(f"{out}/{name}").structures
        ]
    else:
        frames = read(f"{out}/{name}", index=":", format=fmt)
    rows = []
    for fr in frames:
        row = {
            "symbols": fr.get_chemical_symbols(),
            "cell": fr.cell.array.tolist(),
            "positions": fr.positions.tolist(),
        }
        if fmt == "vasp":
            # Velocities as pymatgen reads them (Å/fs): ASE projects them onto the
            # selective-dynamics constraints, which changes what the file holds.
            # pymatgen misses velocities after a `Cartesian` line (ASE's layout): ASE's then.
            v = Poscar.from_file(f"{out}/{name}").velocities
            w = fr.get_velocities()
            if v is not None:
                row["velocities"] = (np.array(v) * 1000).tolist()  # Å/fs to Å/ps
                if not fr.constraints:
                    assert np.allclose(w * fs * 1000, row["velocities"]), name
            elif w is not None and np.any(w != 0):
                assert not fr.constraints, name
                row["velocities"] = (w * fs * 1000).tolist()
        rows.append(row)
    reference[name] = rows
    if name == "XDATCAR_pmg":
        # The same frames as extended XYZ, for the command line's end-to-end test.
        write(f"{out}/pmg_frames.extxyz", frames, format="extxyz")
with open(f"{out}/reference.json", "w") as fh:
    json.dump(reference, fh, indent=None, separators=(",", ":"))
print({k: len(v) for k, v in reference.items()})
