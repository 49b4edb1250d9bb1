"""Small-molecule files written by RDKit and Open Babel, and what those programs and MDAnalysis
read from them, for tests/molecules.rs.

imatinib_confs.sdf    RDKit 2026.09.1: imatinib with hydrogens, 5 ETKDG conformers (seed 7),
                      V2000, one record per conformer.
library.sdf           RDKit: aspirin, caffeine, ibuprofen, acetate (a formal charge: M  CHG) and
                      tetramethylammonium, one record each, with SD data items (a docking-style
                      score), V2000; atom counts differ between records.
caffeine_v3000.mol    RDKit: caffeine, V3000 connection table, a single molfile (no $$$$).
imatinib_poses.mol2   Open Babel 3.1.1 (pybel): imatinib_confs.sdf as MOL2, Gasteiger charges.
library.mol2          Open Babel: library.sdf as MOL2.
molecules_reference.json
  sdf:  per file and record, what RDKit holds: name, element symbols, positions, bonds (0-based,
        sorted pairs);
  mol2_mdanalysis: MDAnalysis 2.11 reading imatinib_poses.mol2: names, types, resnames, resids,
        charges, bonds, positions of every frame;
  mol2_openbabel: per molecule of library.mol2 as pybel reads it back: element numbers,
        positions, bonds.

    pip install rdkit==2026.9.1 openbabel-wheel==3.1.1.23 MDAnalysis==2.11.0
    python3 gen_molecules.py
"""
import json
import os

import MDAnalysis as mda
from openbabel import pybel
from rdkit import Chem
from rdkit.Chem import AllChem

here = os.path.dirname(os.path.abspath(__file__))
path = lambda name: os.path.join(here, name)


def mol3d(smiles, name, confs=1, seed=7):
    m = Chem.AddHs(Chem.MolFromSmiles(smiles))
    ids = AllChem.EmbedMultipleConfs(m, numConfs=confs, randomSeed=seed)
    assert len(ids) == confs
    AllChem.MMFFOptimizeMoleculeConfs(m, maxIters=200)
    m.SetProp("_Name", name)
    return m


def record(m, conf_id):
    conf = m.GetConformer(conf_id)
    return {
        "name": m.GetProp("_Name"),
        "elements": [a.GetSymbol() for a in m.GetAtoms()],
        "positions": [[round(c, 4) for c in conf.GetAtomPosition(i)] for i in range(m.GetNumAtoms())],
        "bonds": sorted(sorted([b.GetBeginAtomIdx(), b.GetEndAtomIdx()]) for b in m.GetBonds()),
    }


imatinib = mol3d("Cc1ccc(NC(=O)c2ccc(CN3CCN(C)CC3)cc2)cc1Nc1nccc(-c2cccnc2)n1", "imatinib", 5)
w = Chem.SDWriter(path("imatinib_confs.sdf"))
for c in range(5):
    w.write(imatinib, confId=c)
w.close()

library = [
    mol3d("CC(=O)Oc1ccccc1C(=O)O", "aspirin"),
    mol3d("Cn1cnc2c1c(=O)n(C)c(=O)n2C", "caffeine"),
    mol3d("CC(C)Cc1ccc(cc1)C(C)C(=O)O", "ibuprofen"),
    mol3d("CC(=O)[O-]", "acetate"),
    mol3d("C[N+](C)(C)C", "tetramethylammonium"),
]
w = Chem.SDWriter(path("library.sdf"))
for k, m in enumerate(library):
    m.SetProp("score", f"{-7.5 + 0.8 * k:.2f}")
    w.write(m)
w.close()

with open(path("caffeine_v3000.mol"), "w") as f:
    f.write(Chem.MolToMolBlock(library[1], forceV3000=True))

for src, dst in [("imatinib_confs.sdf", "imatinib_poses.mol2"), ("library.sdf", "library.mol2")]:
    out = pybel.Outputfile("mol2", path(dst), overwrite=True)
    for m in pybel.readfile("sdf", path(src)):
        out.write(m)
    out.close()

u = mda.Universe(path("imatinib_poses.mol2"))
mol2_mda = {
    "names": list(map(str, u.atoms.names)),
    "types": list(map(str, u.atoms.types)),
    "resnames": list(map(str, u.atoms.resnames)),
    "resids": [int(r) for r in u.atoms.resids],
    "charges": [float(q) for q in u.atoms.charges],
    "bonds": sorted(sorted(map(int, b.indices)) for b in u.bonds),
    "frames": [[[round(float(c), 4) for c in p] for p in ts.positions] for ts in u.trajectory],
}

mol2_ob = []
for m in pybel.readfile("mol2", path("library.mol2")):
    ob = m.OBMol
    mol2_ob.append({
        "atomic_numbers": [a.atomicnum for a in m.atoms],
        "positions": [[round(c, 4) for c in a.coords] for a in m.atoms],
        "bonds": sorted(sorted([b.GetBeginAtomIdx() - 1, b.GetEndAtomIdx() - 1])
                        for b in pybel.ob.OBMolBondIter(ob)),
    })

ref = {
    "sdf": {
        "imatinib_confs.sdf": [record(imatinib, c) for c in range(5)],
        "library.sdf": [record(m, 0) for m in library],
        "caffeine_v3000.mol": [record(library[1], 0)],
    },
    "mol2_mdanalysis": mol2_mda,
    "mol2_openbabel": mol2_ob,
}
with open(path("molecules_reference.json"), "w") as f:
    json.dump(ref, f)
    f.write("\n")
