"""Write the small solvated peptide of gen_topology.py (topo_mda.pdb) as a CHARMM/X-PLOR PSF with
ParmEd (another program's PSF writer: `pip install parmed`), and what MDAnalysis reads back from
that PSF (psf_reference.json: names, residue names and numbers, types, masses, bonds), for
crates/md-io/tests/topology.rs.

ParmEd needs atom types to write a PSF; a PDB has none, so each atom's type is its name.
"""
import json
import warnings

import MDAnalysis as mda
import parmed

warnings.filterwarnings("ignore")
s = parmed.load_file("topo_mda.pdb")
for a in s.atoms:
    if not a.type:
        a.type = a.name
s.save("psf_parmed.psf", overwrite=True)

u = mda.Universe("psf_parmed.psf")
ref = {
    "n_atoms": len(u.atoms),
    "names": [str(x) for x in u.atoms.names],
    "resnames": [str(x) for x in u.atoms.resnames],
    "resids": [int(x) for x in u.atoms.resids],
    "types": [str(x) for x in u.atoms.types],
    "masses": [float(x) for x in u.atoms.masses],
    "bonds": sorted(sorted([int(b[0]), int(b[1])]) for b in u.bonds.indices),
}
with open("psf_reference.json", "w") as f:
    json.dump(ref, f)
print(ref["n_atoms"], "atoms,", len(ref["bonds"]), "bonds")
