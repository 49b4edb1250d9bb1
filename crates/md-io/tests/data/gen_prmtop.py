"""Write AMBER prmtop files with ParmEd (another program's prmtop writer: `pip install parmed`)
and what MDAnalysis reads back from them (prmtop_reference.json: names, types, residue names
and numbers, elements, chains, bonds), for crates/md-io/tests/prmtop.rs.

- prmtop_parmed.prmtop: the solvated peptide of gen_topology.py (topo_mda.pdb: 3 alanines and
  12 waters, 66 atoms, 53 CONECT bonds), the atoms of amber_mda.ncdf, so the pair is the AMBER
  user's topology + trajectory.
- prmtop_chains.parm7: chains_mda.pdb of gen_chains.py (two alanine chains, waters, sodium ions,
  a DNA strand: 362 atoms) with the bonds ParmEd assigns from its residue templates and a
  RESIDUE_CHAINID section (ParmEd's add_flag, formatted by ParmEd) holding each residue's chain.

A PDB has no force field: ParmEd needs parameters to write a prmtop, so every atom's type is
its name with one Lennard-Jones pair and every bond one bond type, and atom i's charge is
0.1 * ((i % 5) - 2) e, as gen_topology.py gives topo_mda.data's.

Run with ParmEd 4.3.1 and MDAnalysis 2.11: `python3 gen_prmtop.py`.
"""
import json
import warnings

import MDAnalysis as mda
import parmed
from parmed.topologyobjects import AtomType, BondType

warnings.filterwarnings("ignore")


def parametrised(pdb):
    s = parmed.load_file(pdb)
    bt = BondType(300.0, 1.0, list=s.bond_types)
    s.bond_types.append(bt)
    for b in s.bonds:
        b.type = bt
    for i, a in enumerate(s.atoms):
        if not a.type:
            a.type = a.name
        t = AtomType(a.type, None, a.mass, a.atomic_number)
        t.set_lj_params(0.1, 1.5)
        a.atom_type = t
        a.charge = 0.1 * ((i % 5) - 2)
    return s


def build(pdb, out, chains):
    s = parametrised(pdb)
    p = parmed.amber.AmberParm.from_structure(s)
    if chains:
        p.add_flag("RESIDUE_CHAINID", "20a4", data=[r.chain for r in s.residues])
    p.save(out, overwrite=True)


build("topo_mda.pdb", "prmtop_parmed.prmtop", chains=False)
build("chains_mda.pdb", "prmtop_chains.parm7", chains=True)

ref = {}
for name in ("prmtop_parmed.prmtop", "prmtop_chains.parm7"):
    u = mda.Universe(name, topology_format="TOP")
    r = {
        "n_atoms": len(u.atoms),
        "names": [str(x) for x in u.atoms.names],
        "types": [str(x) for x in u.atoms.types],
        "resnames": [str(x) for x in u.atoms.resnames],
        "resids": [int(x) for x in u.atoms.resids],
        "elements": [str(x) for x in u.atoms.elements],
        "charges": [float(x) for x in u.atoms.charges],
        "bonds": sorted(sorted([int(b[0]), int(b[1])]) for b in u.bonds.indices),
    }
    if hasattr(u.atoms, "segids") and name.endswith(".parm7"):
        r["chains"] = [str(x) for x in u.atoms.segids]
    ref[name] = r
    print(name, r["n_atoms"], "atoms,", len(r["bonds"]), "bonds")
with open("prmtop_reference.json", "w") as f:
    json.dump(ref, f)
