"""References for the CONECT records of our PDB writer (crates/md-io/tests/writers.rs).

The two PDB files here are our writer's output (regenerate them, then run this script):
    texmap convert ../molecules/library.sdf --frames 0 -o aspirin.pdb
    texmap convert ../topo_mda.gro --topology ../psf_parmed.psf -o peptide_psf.pdb
The test checks that our writer still writes exactly these files, so what other programs read
from them here is what they read from our output:

- RDKit (`pip install rdkit`): Chem.MolFromPDBFile(removeHs=False, proximityBonding=False),
  whose bonds come from CONECT only, repeated partners as bond orders; and the SDF the ligand
  came from, read by RDKit, for the bonds and orders to expect;
- MDAnalysis: the bonds its PDB parser makes of the CONECT records; and the CONECT lines its
  PDBWriter writes (bonds="all") for the peptide's atoms and the PSF's bonds, to compare with
  ours byte for byte;
- gemmi (`pip install gemmi`): its conect_map (partners as listed, repeats kept).
"""
import json
import os
import tempfile
import warnings

import gemmi
import MDAnalysis as mda
from rdkit import Chem

warnings.filterwarnings("ignore")


def rdkit_bonds(mol):
    out = []
    for b in mol.GetBonds():
        i, j = sorted((b.GetBeginAtomIdx(), b.GetEndAtomIdx()))
        out.append([i, j, b.GetBondTypeAsDouble()])
    return sorted(out)


def rdkit_pdb(path):
    m = Chem.MolFromPDBFile(path, removeHs=False, proximityBonding=False, sanitize=False)
    return {"n_atoms": m.GetNumAtoms(), "bonds": rdkit_bonds(m)}


def mda_bonds(u):
    return sorted(sorted([int(b[0]), int(b[1])]) for b in u.bonds.indices)


def gemmi_conect(path):
    st = gemmi.read_structure(path)
    return {str(k): list(v) for k, v in sorted(st.conect_map.items())}


sdf = Chem.SDMolSupplier("../molecules/library.sdf", removeHs=False, sanitize=False)[0]
ref = {
    "aspirin": {
        "sdf_rdkit_bonds": rdkit_bonds(sdf),
        "rdkit": rdkit_pdb("aspirin.pdb"),
        "mdanalysis_bonds": mda_bonds(mda.Universe("aspirin.pdb")),
        "gemmi_conect": gemmi_conect("aspirin.pdb"),
    },
}

u = mda.Universe("../psf_parmed.psf", "../topo_mda.gro")
with tempfile.TemporaryDirectory() as d:
    out = os.path.join(d, "mda.pdb")
    u.atoms.write(out, bonds="all")
    with open(out) as f:
        mda_conect = [line.rstrip("\n") for line in f if line.startswith("CONECT")]
ref["peptide"] = {
    "psf_bonds": mda_bonds(u),
    "mdanalysis_bonds": mda_bonds(mda.Universe("peptide_psf.pdb")),
    "mdanalysis_conect_lines": mda_conect,
    "rdkit": rdkit_pdb("peptide_psf.pdb"),
}
with open("reference.json", "w") as f:
    json.dump(ref, f, indent=1)
print(
    len(ref["aspirin"]["rdkit"]["bonds"]), "ligand bonds,",
    len(ref["peptide"]["mdanalysis_bonds"]), "peptide bonds,",
    len(mda_conect), "MDAnalysis CONECT lines",
)
