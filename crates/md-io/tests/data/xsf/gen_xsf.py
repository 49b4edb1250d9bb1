"""XCrySDen XSF / AXSF fixtures for tests/xsf.rs, written by ASE and pymatgen, and the
reference (reference.json): what ASE's and pymatgen's own readers give back for each file.

Run from this directory: python3 gen_xsf.py (Python 3.11, ASE 3.29.0, pymatgen 2026.10,
numpy 2.4). Seeded: a rerun writes the same bytes.

Writes (ase.io.write(..., format="xsf") unless said otherwise)
- ase_molecule.xsf: ethanol, jiggled: an ATOMS block of atomic numbers;
- ase_crystal_forces.xsf: six atoms in a triclinic cell with forces (ASE writes them in
  Hartree/Å, eV/Å divided by its Hartree): CRYSTAL, PRIMVEC, PRIMCOORD;
- ase_slab.xsf: Pt(111), 2x2x3 with vacuum (pbc T T F): SLAB;
- ase_anim_fixed.axsf: four steps of a crystal with forces, one cell: ANIMSTEPS 4, PRIMVEC,
  PRIMCOORD 1..4;
- ase_anim_cell.axsf: three steps of a crystal whose cell changes: PRIMVEC k, PRIMCOORD k;
- ase_anim_molecule.axsf: three steps of water with forces: ANIMSTEPS 3, ATOMS 1..3;
- ase_grid_molecule.xsf: water in a box (no pbc) with a DATAGRID_3D of Gaussians on the
  atoms, origin and spanning vectors ASE's own (origin cell/n per axis, spans cell·(n+1)/n:
  a grid whose ends are not the box's), values written by ASE with 6 decimals;
- ase_grid_crystal.xsf: a triclinic crystal with a periodic function on the general grid
  over the cell (ASE given span_vectors = the cell and origin 0, as pp.x writes: n + 1 points
  per axis, the last plane the first's periodic image);
- pmg_grids.xsf: pymatgen's XSF writer: element symbols, comment lines, forces as the site
  property "vect", CONVVEC after the atoms, one BEGIN_BLOCK_DATAGRID_3D holding two grids
  (two periodic functions on the general grid over the cell, a shifted origin), 14 decimals,
  no final newline;
- ase_grid_small.xsf: Si2 in an orthorhombic cell with the periodic function on a 4 x 3 x 5
  general grid over the cell (the damage tests' grid file);
- reference.json: per file the frames ase.io.read(path, index=":") gives (atomic numbers,
  positions, cell when periodic, pbc, forces in eV/Å when the file has them); for the grid
  files what ase.io.xsf.read_xsf(read_data=True) gives (shape, origin, spanning vectors,
  values x fastest) and, for pmg_grids.xsf, what pymatgen's XSF.from_file gives for both
  grids (ASE reads neither a block of two grids nor a CONVVEC after the atoms); and the
  parameters of the analytic functions sampled.
"""

import json

import ase
import numpy as np
import pymatgen.core
from ase import Atoms
from ase.build import fcc111, molecule
from ase.calculators.singlepoint import SinglePointCalculator
from ase.geometry import cellpar_to_cell
from ase.io import read, write
from ase.io.xsf import read_xsf
from pymatgen.core import Lattice, Structure
from pymatgen.io.xcrysden import XSF, XSFGrid

rng = np.random.default_rng(20261210)
reference = {
    "written_by": f"ASE {ase.__version__}, pymatgen {pymatgen.core.__version__}, "
    f"numpy {np.__version__}",
}


def triclinic(lengths, angles):
    return Atoms(cell=cellpar_to_cell(list(lengths) + list(angles)))


def frames_of(path):
    out = []
    for a in read(path, index=":", format="xsf"):
        forces = None
        if a.calc is not None:
            forces = a.get_forces().tolist()
        out.append(
            {
                "numbers": a.numbers.tolist(),
                "positions": a.positions.tolist(),
                "pbc": a.pbc.tolist(),
                "cell": a.cell.array.tolist() if a.pbc.any() else None,
                "forces": forces,
            }
        )
    return out


def with_forces(atoms, scale=0.8):
    f = rng.normal(size=(len(atoms), 3)) * scale
    atoms.calc = SinglePointCalculator(atoms, forces=f)
    return atoms


def periodic_f(s0, s1, s2):
    """A periodic function of the fractional coordinates (period 1 along each)."""
    tau = 2 * np.pi
    return (
        0.5
        + 0.3 * np.cos(tau * s0)
        + 0.2 * np.sin(tau * (s1 + 2 * s2))
        + 0.1 * np.cos(tau * (s0 - s1 + s2))
    )


def periodic_g(s0, s1, s2):
    """A second one, of both signs."""
    tau = 2 * np.pi
    return np.sin(tau * s0) * np.cos(tau * s1) + 0.25 * np.cos(2 * tau * s2)


def general_grid(fn, shape):
    """fn on the general grid over one period: n points per axis from 0 to 1, both ends
    included; the last plane repeats the first exactly (fractions taken modulo 1)."""
    idx = [np.arange(n) % (n - 1) / (n - 1) for n in shape]
    s0, s1, s2 = np.meshgrid(*idx, indexing="ij")
    return fn(s0, s1, s2)


def grid_reference(path):
    with open(path) as f:
        data, origin, span, _ = read_xsf(f, read_data=True)
    return {
        "shape": list(data.shape),
        "origin": origin.tolist(),
        "span": span.tolist(),
        "values": data.ravel(order="F").tolist(),
    }


def write_ase(name, images, **kw):
    write(name, images, format="xsf", **kw)
    reference[name] = {"frames": frames_of(name)}


# A molecule.
eth = molecule("CH3CH2OH")
eth.positions += rng.normal(scale=0.05, size=eth.positions.shape)
write_ase("ase_molecule.xsf", eth)

# A triclinic crystal with forces.
tri = triclinic([5.1, 6.3, 7.2], [78.0, 95.0, 104.0])
tri += Atoms("Ti2O4", scaled_positions=rng.random((6, 3)), cell=tri.cell)
tri.pbc = True
write_ase("ase_crystal_forces.xsf", with_forces(tri))

# A slab.
slab = fcc111("Pt", size=(2, 2, 3), vacuum=5.0)
slab.positions += rng.normal(scale=0.02, size=slab.positions.shape)
write_ase("ase_slab.xsf", slab)

# An animation with one cell, forces in every step.
base = triclinic([4.2, 4.6, 5.3], [88.0, 97.0, 115.0])
base += Atoms("SiC2", scaled_positions=rng.random((3, 3)), cell=base.cell)
base.pbc = True
steps = []
for _ in range(4):
    a = base.copy()
    a.positions += rng.normal(scale=0.1, size=a.positions.shape)
    steps.append(with_forces(a))
write_ase("ase_anim_fixed.axsf", steps)

# An animation whose cell changes.
steps = []
for k in range(3):
    a = base.copy()
    m = np.eye(3) + 0.03 * k * np.array([[1.0, 0.2, 0.0], [0.0, -0.5, 0.1], [0.3, 0.0, 0.8]])
    a.set_cell(a.cell.array @ m, scale_atoms=True)
    a.positions += rng.normal(scale=0.05, size=a.positions.shape)
    steps.append(a)
write_ase("ase_anim_cell.axsf", steps)

# A molecule's animation with forces.
water = molecule("H2O")
steps = []
for _ in range(3):
    a = water.copy()
    a.positions += rng.normal(scale=0.08, size=a.positions.shape)
    steps.append(with_forces(a, 0.3))
write_ase("ase_anim_molecule.axsf", steps)

# A molecule in a box with a grid of Gaussians, ASE's origin and spans.
box = molecule("H2O")
box.cell = [[6.0, 0.0, 0.0], [0.5, 5.5, 0.0], [0.0, 0.3, 5.0]]
box.center()
box.pbc = False
shape = (8, 9, 10)
cell = box.cell.array
origin = sum(cell[i] / shape[i] for i in range(3))
span = np.array([cell[i] * (shape[i] + 1) / shape[i] for i in range(3)])
sigma = 1.1
weights = [1.0, 0.5, 0.5]
idx = np.meshgrid(*[np.arange(n) / (n - 1) for n in shape], indexing="ij")
points = origin + sum(idx[a][..., None] * span[a] for a in range(3))
data = np.zeros(shape)
for w, c in zip(weights, box.positions):
    data += w * np.exp(-((points - c) ** 2).sum(axis=-1) / (2 * sigma**2))
name = "ase_grid_molecule.xsf"
write(name, box, format="xsf", data=data)
reference[name] = {"frames": frames_of(name), "grids": [grid_reference(name)]}
got = reference[name]["grids"][0]
assert np.allclose(got["origin"], origin, atol=1e-6), "ASE's default origin"
assert np.allclose(got["span"], span, atol=1e-6), "ASE's default spans"
reference[name]["analytic"] = {
    "gaussians": {"sigma": sigma, "weights": weights, "centres": box.positions.tolist()}
}

# A crystal with a periodic function on the general grid over its cell.
xtal = triclinic([4.0, 4.4, 5.0], [90.0, 95.0, 110.0])
xtal += Atoms("ZnO", scaled_positions=[[0.1, 0.2, 0.3], [0.6, 0.5, 0.8]], cell=xtal.cell)
xtal.pbc = True
shape = (9, 10, 11)
name = "ase_grid_crystal.xsf"
write(
    name,
    xtal,
    format="xsf",
    data=general_grid(periodic_f, shape),
    origin=np.zeros(3),
    span_vectors=xtal.cell.array,
)
reference[name] = {
    "frames": frames_of(name),
    "grids": [grid_reference(name)],
    "analytic": {"periodic": ["f"]},
}

# pymatgen: symbols, comments, forces, CONVVEC, a block of two grids.
lattice = Lattice.from_parameters(4.6, 5.2, 6.1, 84.0, 92.0, 117.0)
frac = rng.random((5, 3))
species = ["Fe", "Fe", "O", "O", "O"]
vect = rng.normal(scale=0.4, size=(5, 3))
st = Structure(lattice, species, frac, site_properties={"vect": vect.tolist()})
shape = (5, 4, 6)
grid = XSFGrid(
    data=np.stack([general_grid(periodic_f, shape), general_grid(periodic_g, shape)]),
    lattice=lattice.matrix,
    origin=np.array([0.1, -0.2, 0.3]),
    labels=["grid/rho", "grid/phi"],
)
xsf = XSF(st)
xsf.comment = "iron oxide, two fields on one grid\nwritten by pymatgen"
xsf.conventional_lattice = 2.0 * lattice.matrix
xsf.grids["fields"] = grid
name = "pmg_grids.xsf"
xsf.write_file(name)
back = XSF.from_file(name)
bg = back.grids["fields"]
reference[name] = {
    "frames": frames_of(name),
    "pymatgen": {
        "species": [s.specie.symbol for s in back.structure],
        "cart_coords": back.structure.cart_coords.tolist(),
        "lattice": back.structure.lattice.matrix.tolist(),
        "forces": back.forces.tolist(),
    },
    "grids": [
        {
            "label": bg.labels[k],
            "block": "fields",
            "shape": list(bg.data[k].shape),
            "origin": bg.origin.tolist(),
            "span": bg.lattice.tolist(),
            "values": bg.data[k].ravel(order="F").tolist(),
        }
        for k in range(len(bg.labels))
    ],
    "analytic": {"periodic": ["f", "g"]},
}

# A small crystal grid for the damage tests (the periodic function, 4 x 3 x 5 points).
small = Atoms("Si2", scaled_positions=[[0, 0, 0], [0.25, 0.25, 0.25]], cell=[3.0, 3.2, 3.4])
small.pbc = True
name = "ase_grid_small.xsf"
write(
    name,
    small,
    format="xsf",
    data=general_grid(periodic_f, (4, 3, 5)),
    origin=np.zeros(3),
    span_vectors=small.cell.array,
)
reference[name] = {
    "frames": frames_of(name),
    "grids": [grid_reference(name)],
    "analytic": {"periodic": ["f"]},
}

with open("reference.json", "w") as f:
    json.dump(reference, f, indent=1)
    f.write("\n")
