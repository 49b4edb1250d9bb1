"""LAMMPS data files written by ASE and MDAnalysis, and what each program reads back from them,
for tests/lammps_data.rs.

lammps_data/ase_atomic_tri.data: ASE 3.29 `write(..., format="lammps-data", atom_style="atomic",
  masses=True, velocities=True)`: 40 seeded Cu/Ni/Al atoms in a triclinic box with tilt
  (xy, xz, yz = 2.5, -1.5, 1.0), Maxwell-Boltzmann velocities (units metal: A/ps).
lammps_data/ase_full.data: ASE, atom_style full: 8 waters with molecule ids, charges and the
  O-H bonds (ASE's `bonds` array), an orthogonal box.
lammps_data/ase_charge.data: ASE, atom_style charge: rock-salt NaCl, 2x2x2 cells sheared
  (negative tilts), charges +-1.
lammps_data/mda_full_tri.data: MDAnalysis 2.11 `DATAWriter` (no style comment: 7 columns, full):
  30 atoms in 10 three-atom molecules of types 1-4 with masses 12.011, 15.999, 14.027 (united-atom
  CH2) and 72.0 (a coarse-grained bead), charges, bonds, velocities, a triclinic box.
lammps_data_reference.json: per file, what the writing program reads back (ASE
  `read(..., format="lammps-data")`, MDAnalysis `Universe(..., format="DATA")`): atom count,
  positions, cell (edge vectors as rows) and origin, types, elements (ASE: from masses; MDAnalysis:
  none), masses, charges, molecule ids, bonds as sorted index pairs, velocities as written in the
  file (ASE's and MDAnalysis's converted back to the file's units), and the same for
  topo_mda.data (gen_topology.py).

    pip install ase==3.29.0 MDAnalysis==2.11.0
    python3 gen_lammps_data.py
"""
import json
import os
import warnings

import numpy as np
from ase import Atoms
from ase.calculators.lammps import convert
from ase.io import read, write
from ase.md.velocitydistribution import MaxwellBoltzmannDistribution

import MDAnalysis as mda

warnings.filterwarnings("ignore")
here = os.path.dirname(os.path.abspath(__file__))
out = os.path.join(here, "lammps_data")
os.makedirs(out, exist_ok=True)
rng = np.random.default_rng(7)
ref = {}


def ase_reference(path, style):
    a = read(path, format="lammps-data", atom_style=style, units="metal")
    r = {
        "program": "ASE 3.29.0 read(format='lammps-data', atom_style=%r, units='metal')" % style,
        "n_atoms": len(a),
        "positions": a.get_positions().tolist(),
        "cell": a.cell[:].tolist(),
        "origin": np.asarray(a.get_celldisp()).reshape(3).tolist(),
        "types": [str(t) for t in a.arrays["type"]],
        "elements": a.get_chemical_symbols(),
        "masses": a.get_masses().tolist(),
    }
    if style in ("full", "charge"):
        r["charges"] = a.get_initial_charges().tolist()
    if style == "full":
        r["mol_ids"] = [int(m) for m in a.arrays["mol-id"]]
        bonds = set()
        for i, s in enumerate(a.arrays.get("bonds", [])):
            if s != "_":
                for b in s.split(","):
                    j = int(b.split("(")[0])
                    bonds.add((min(i, j), max(i, j)))
        r["bonds"] = sorted(list(b) for b in bonds)
    if a.has("momenta"):
        v = a.get_velocities()
        r["velocities"] = convert(v, "velocity", "ASE", "metal").tolist()
    return r


# ASE, atomic, triclinic with tilt, velocities.
cell = np.array([[12.0, 0.0, 0.0], [2.5, 11.0, 0.0], [-1.5, 1.0, 10.0]])
n = 40
symbols = rng.choice(["Cu", "Ni", "Al"], size=n)
frac = rng.random((n, 3))
a = Atoms(symbols=list(symbols), scaled_positions=frac, cell=cell, pbc=True)
MaxwellBoltzmannDistribution(a, temperature_K=600, rng=np.random.RandomState(7))
p = os.path.join(out, "ase_atomic_tri.data")
write(p, a, format="lammps-data", atom_style="atomic", masses=True, velocities=True,
      specorder=["Cu", "Ni", "Al"], units="metal")
ref["ase_atomic_tri.data"] = ase_reference(p, "atomic")

# ASE, full: waters with molecule ids, charges and bonds.
pos, sym, mol, q, bonds = [], [], [], [], []
for m in range(8):
    o = rng.random(3) * 12.0 + 1.0
    half = np.radians(104.5 / 2)
    pos += [o, o + 0.96 * np.array([np.sin(half), np.cos(half), 0]),
            o + 0.96 * np.array([-np.sin(half), np.cos(half), 0])]
    sym += ["O", "H", "H"]
    mol += [m + 1] * 3
    q += [-0.8476, 0.4238, 0.4238]
    base = 3 * m
    bonds += ["%d(1),%d(1)" % (base + 1, base + 2), "_", "_"]
w = Atoms(symbols=sym, positions=pos, cell=[15.0, 15.0, 15.0], pbc=True)
w.set_initial_charges(q)
w.set_array("mol-id", np.array(mol, dtype=int))
w.set_array("bonds", np.array(bonds, dtype=object))
p = os.path.join(out, "ase_full.data")
write(p, w, format="lammps-data", atom_style="full", masses=True, specorder=["O", "H"],
      units="metal")
ref["ase_full.data"] = ase_reference(p, "full")

# ASE, charge: rock salt, sheared.
from ase.build import bulk

nacl = bulk("NaCl", "rocksalt", a=5.64, cubic=True).repeat((2, 2, 2))
c = nacl.cell[:].copy()
c[1, 0] = -1.2
c[2, 0] = -0.8
c[2, 1] = -0.6
nacl.set_cell(c, scale_atoms=True)
nacl.set_initial_charges([1.0 if s == "Na" else -1.0 for s in nacl.get_chemical_symbols()])
p = os.path.join(out, "ase_charge.data")
write(p, nacl, format="lammps-data", atom_style="charge", masses=True, specorder=["Na", "Cl"],
      units="metal")
ref["ase_charge.data"] = ase_reference(p, "charge")


# MDAnalysis, full (no style comment), triclinic, masses of no element, velocities.
def mda_reference(path):
    u = mda.Universe(path, format="DATA", atom_style="id resid type charge x y z")
    ts = u.trajectory.ts
    r = {
        "program": "MDAnalysis %s Universe(format='DATA')" % mda.__version__,
        "n_atoms": len(u.atoms),
        "positions": u.atoms.positions.astype(float).tolist(),
        "cell": mda.lib.mdamath.triclinic_vectors(ts.dimensions).astype(float).tolist(),
        "origin": [0.0, 0.0, 0.0],
        "types": [str(t) for t in u.atoms.types],
        "masses": u.atoms.masses.astype(float).tolist(),
        "charges": u.atoms.charges.astype(float).tolist(),
        "mol_ids": [int(m) for m in u.atoms.resids],
        "bonds": sorted(sorted(map(int, b)) for b in u.bonds.indices),
    }
    if ts.has_velocities:
        # DATAReader converts the file's A/fs to A/ps; back to the file's numbers.
        r["velocities"] = (u.atoms.velocities.astype(float) / 1000.0).tolist()
    return r


n_mol = 10
u = mda.Universe.empty(3 * n_mol, n_residues=n_mol,
                       atom_resindex=np.repeat(np.arange(n_mol), 3),
                       trajectory=True, velocities=True)
u.add_TopologyAttr("types", [str(t) for t in np.tile([1, 2, 3], n_mol)[:3 * n_mol]])
types = np.array([1, 2, 3] * n_mol)
types[::7] = 4
u.atoms.types = [str(t) for t in types]
masses = {1: 12.011, 2: 15.999, 3: 14.027, 4: 72.0}
u.add_TopologyAttr("masses", [masses[t] for t in types])
u.add_TopologyAttr("charges", np.round(rng.normal(0, 0.3, 3 * n_mol), 4))
u.add_TopologyAttr("resids", np.arange(1, n_mol + 1))
pairs = [(3 * m, 3 * m + 1) for m in range(n_mol)] + [(3 * m + 1, 3 * m + 2) for m in range(n_mol)]
u.add_bonds(pairs, types=["1"] * len(pairs), guessed=False)
for kind in ("angles", "dihedrals", "impropers"):
    u.add_TopologyAttr(kind, [])
u.dimensions = [20.0, 18.0, 16.0, 80.0, 100.0, 70.0]
tri = mda.lib.mdamath.triclinic_vectors(u.dimensions)
u.atoms.positions = (rng.random((3 * n_mol, 3)) @ tri).astype(np.float32)
u.atoms.velocities = rng.normal(0, 5.0, (3 * n_mol, 3)).astype(np.float32)
p = os.path.join(out, "mda_full_tri.data")
u.atoms.write(p)
ref["mda_full_tri.data"] = mda_reference(p)
ref["topo_mda.data"] = mda_reference(os.path.join(here, "topo_mda.data"))

with open(os.path.join(here, "lammps_data_reference.json"), "w") as f:
    json.dump(ref, f, indent=0)
    f.write("\n")
print({k: v["n_atoms"] for k, v in ref.items()})
