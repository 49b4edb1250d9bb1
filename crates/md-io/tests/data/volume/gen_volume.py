"""Volumetric fixtures for tests/volume.rs, written by ASE and pymatgen, and the reference
(expected.json): what ASE's and pymatgen's own readers give back for each file.

Run from this directory: python3 gen_volume.py (ASE 3.29, pymatgen 2026.10, numpy).

Writes
- ase_ch3oh.cube: methanol in a sheared, non-cubic cell, a non-symmetric analytic field on
  24 x 20 x 16 points (ase.io.write(format="cube"), Bohr axes, one value per line);
- ase_small.cube: water, 4 x 3 x 5 points (the damage tests' cube);
- CHGCAR_pmg_spin: a hexagonal ZnO cell, "total" and "diff" (spin-polarised) on 12 x 12 x 15
  points with augmentation occupancies after each grid (pymatgen Chgcar.write_file);
- CHGCAR_small: the same cell, 3 x 3 x 4 points, total and diff with a short augmentation
  block each (the damage tests' CHGCAR);
- LOCPOT_pmg: a monoclinic cell, one potential on 10 x 10 x 12 points (pymatgen Locpot);
- expected.json: per file the atoms' symbols and Cartesian positions (Å), the grid origin,
  the step vectors (Å: cube spacing as ASE reads it; lattice vectors / N for VASP), the dims,
  and per data set the sum (and the sum of magnitudes, the scale of its
  tolerance), min, max and the values at listed (i, j, k) indices, as ASE's
  read_cube and pymatgen's Chgcar/Locpot.from_file read them back; densities divided by the
  cell volume (pymatgen's data["total"] / structure.volume), a LOCPOT as written.
"""

import json

import numpy as np
from ase.build import molecule
from ase.io import write
from ase.io.cube import read_cube
from pymatgen.core import Lattice, Structure
from pymatgen.io.vasp import Chgcar, Locpot, Poscar

SAMPLES = 10
rng = np.random.default_rng(20261207)
expected = {}


def field(points):
    """A smooth field with no symmetry: two off-centre Gaussians and a tilted plane."""
    x, y, z = points[..., 0], points[..., 1], points[..., 2]
    g1 = np.exp(-((x - 2.1) ** 2 + 0.5 * (y - 3.3) ** 2 + 2.0 * (z - 2.6) ** 2))
    g2 = 0.4 * np.exp(-0.7 * ((x - 5.0) ** 2 + (y - 1.2) ** 2 + (z - 4.1) ** 2))
    return g1 + g2 + 0.01 * x - 0.02 * y + 0.005 * x * z


def grid_points(origin, steps, dims):
    i, j, k = np.meshgrid(*[np.arange(n) for n in dims], indexing="ij")
    return origin + i[..., None] * steps[0] + j[..., None] * steps[1] + k[..., None] * steps[2]


def sets_summary(datas, dims):
    picks = [(0, 0, 0), tuple(n - 1 for n in dims)]
    while len(picks) < SAMPLES:
        picks.append(tuple(int(rng.integers(n)) for n in dims))
    out = []
    for d in datas:
        out.append(
            {
                "sum": float(d.sum()),
                "abs_sum": float(np.abs(d).sum()),
                "min": float(d.min()),
                "max": float(d.max()),
                "samples": [[i, j, k, float(d[i, j, k])] for (i, j, k) in picks],
            }
        )
    return out


def cube(name, atoms, dims):
    steps = atoms.cell.array / np.array(dims)[:, None]
    data = field(grid_points(np.zeros(3), steps, dims))
    with open(name, "w") as f:
        write(f, atoms, format="cube", data=data, comment="analytic field, written by ASE")
    with open(name) as f:
        back = read_cube(f)
    a = back["atoms"]
    expected[name] = {
        "symbols": a.get_chemical_symbols(),
        "positions": a.positions.tolist(),
        "origin": back["origin"].tolist(),
        "steps": back["spacing"].tolist(),
        "dims": list(back["data"].shape),
        "periodic": False,
        "sets": sets_summary([back["data"]], back["data"].shape),
    }


def vasp(name, reader, structure, sets):
    back = reader.from_file(name)
    s = back.structure
    dims = list(back.dim)
    lattice = s.lattice.matrix
    keys = [k for k in ("total", "diff") if k in back.data]
    volume_divisor = s.volume if reader is Chgcar else 1.0
    expected[name] = {
        "symbols": [site.specie.symbol for site in s],
        "positions": s.cart_coords.tolist(),
        "origin": [0.0, 0.0, 0.0],
        "steps": (lattice / np.array(dims)[:, None]).tolist(),
        "dims": dims,
        "periodic": True,
        "names": sets,
        "sets": sets_summary([back.data[k] / volume_divisor for k in keys], dims),
    }


# A cube of methanol in a sheared, non-cubic cell, and a small one of water.
m = molecule("CH3OH")
m.set_cell([[7.5, 0.0, 0.0], [0.8, 6.9, 0.0], [0.0, 0.6, 6.2]])
m.positions += [3.2, 3.1, 2.9]
cube("ase_ch3oh.cube", m, (24, 20, 16))
w = molecule("H2O")
w.set_cell([[4.0, 0.0, 0.0], [0.0, 3.6, 0.0], [0.3, 0.0, 4.4]])
w.positions += [2.0, 1.8, 2.2]
cube("ase_small.cube", w, (4, 3, 5))

# A spin-polarised CHGCAR of hexagonal ZnO, with augmentation occupancies.
zno = Structure(
    Lattice.hexagonal(3.25, 5.21),
    ["Zn", "Zn", "O", "O"],
    [[1 / 3, 2 / 3, 0.0], [2 / 3, 1 / 3, 0.5], [1 / 3, 2 / 3, 0.382], [2 / 3, 1 / 3, 0.882]],
)


def chgcar(name, dims, aug_size):
    steps = zno.lattice.matrix / np.array(dims)[:, None]
    pts = grid_points(np.zeros(3), steps, dims)
    total = field(pts) * zno.volume  # VASP stores rho * V_cell
    diff = (0.3 * field(pts[..., [1, 2, 0]]) - 0.05) * zno.volume
    aug = {
        key: {k + 1: rng.normal(0, 0.1, aug_size) for k in range(len(zno))}
        for key in ("total", "diff")
    }
    Chgcar(Poscar(zno), {"total": total, "diff": diff}, data_aug=aug).write_file(name)
    vasp(
        name,
        Chgcar,
        zno,
        ["total density (e/Å³)", "magnetisation density (e/Å³)"],
    )


chgcar("CHGCAR_pmg_spin", (12, 12, 15), 9)
chgcar("CHGCAR_small", (3, 3, 4), 2)

# A LOCPOT of a monoclinic cell.
mono = Structure(
    Lattice.monoclinic(4.1, 3.7, 5.3, 104.0),
    ["Si", "Si", "C"],
    [[0.1, 0.2, 0.3], [0.6, 0.7, 0.75], [0.35, 0.5, 0.05]],
)
dims = (10, 10, 12)
pot = -5.0 * field(grid_points(np.zeros(3), mono.lattice.matrix / np.array(dims)[:, None], dims))
Locpot(Poscar(mono), {"total": pot}).write_file("LOCPOT_pmg")
vasp("LOCPOT_pmg", Locpot, mono, ["local potential (eV)"])

with open("expected.json", "w") as f:
    json.dump(expected, f, indent=1)
