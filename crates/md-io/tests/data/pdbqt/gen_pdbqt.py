"""AutoDock PDBQT files written by Meeko 0.8.0 and AutoDock Vina 1.2.7, read back by MDAnalysis.

Writes, beside this script:
  receptor.pdbqt  Meeko's mk_prepare_receptor.py --read_pqr of ../pdb2pqr_amber.pqr (PDB2PQR's
                  protonated 3JQH), Gasteiger charges, AD4 types (rigid receptor)
  ligand.pdbqt    Meeko MoleculePreparation of 2-bromo-4-chlorobenzamide (RDKit ETKDG, seed 7):
                  ROOT/BRANCH torsion tree, aromatic carbons 'A', acceptors 'OA'/'NA', 'HD', Cl, Br
  poses.pdbqt     Vina 1.2.7 (scoring vina, seed 7, exhaustiveness 4) docking the ligand on the
                  receptor: one MODEL per pose with its REMARK VINA RESULT line
  reference.json  MDAnalysis 2.11's PDBQT reader (positions, names, resnames, resids, chains,
                  charges, AD types per model) and Vina's own energies of the poses
"""
import json
import os
import subprocess

import numpy as np
from rdkit import Chem
from rdkit.Chem import AllChem
from meeko import MoleculePreparation, PDBQTWriterLegacy
from vina import Vina
import MDAnalysis as mda

here = os.path.dirname(os.path.abspath(__file__))
data = os.path.dirname(here)

subprocess.run(
    ["mk_prepare_receptor.py", "--read_pqr", os.path.join(data, "pdb2pqr_amber.pqr"),
     "-o", os.path.join(here, "receptor"), "-p", "--allow_bad_res"],
    check=True, capture_output=True)
for extra in ["receptor.json", "receptor.gpf", "receptor.box.pdb"]:
    p = os.path.join(here, extra)
    if os.path.exists(p):
        os.remove(p)

mol = Chem.AddHs(Chem.MolFromSmiles("NC(=O)c1ccc(Cl)cc1Br"))
AllChem.EmbedMolecule(mol, randomSeed=7)
AllChem.MMFFOptimizeMolecule(mol)
setups = MoleculePreparation().prepare(mol)
pdbqt, ok, err = PDBQTWriterLegacy.write_string(setups[0])
assert ok, err
with open(os.path.join(here, "ligand.pdbqt"), "w") as f:
    f.write(pdbqt)

rec = mda.Universe(os.path.join(here, "receptor.pdbqt"))
center = rec.atoms.positions.mean(axis=0)
v = Vina(sf_name="vina", seed=7, verbosity=0, cpu=1)
v.set_receptor(os.path.join(here, "receptor.pdbqt"))
v.set_ligand_from_file(os.path.join(here, "ligand.pdbqt"))
v.compute_vina_maps(center=[float(c) for c in center], box_size=[22.0, 22.0, 22.0])
v.dock(exhaustiveness=4, n_poses=5)
v.write_poses(os.path.join(here, "poses.pdbqt"), n_poses=5, overwrite=True)
energies = v.energies(n_poses=5)

ref = {}
for name in ["receptor.pdbqt", "ligand.pdbqt", "poses.pdbqt"]:
    u = mda.Universe(os.path.join(here, name))
    a = u.atoms
    ref[name] = {
        "names": [str(x) for x in a.names],
        "resnames": [str(x) for x in a.resnames],
        "resids": [int(x) for x in a.resids],
        "chains": [str(x) for x in a.chainIDs],
        "charges": [float(x) for x in a.charges],
        "types": [str(x) for x in a.types],
        "positions": [ts.positions.astype(float).tolist() for ts in u.trajectory],
    }
ref["poses.pdbqt"]["vina_energies"] = [[float(x) for x in row] for row in energies]
with open(os.path.join(here, "reference.json"), "w") as f:
    json.dump(ref, f, separators=(",", ":"))
    f.write("\n")
