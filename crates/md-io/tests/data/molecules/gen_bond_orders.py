"""Bond orders of the small-molecule fixtures as other programs read them from the files, for
tests/molecules.rs: the SD files and the V3000 molfile by RDKit (unsanitized, so the file's
Kekulé single and double bonds stay as written; `GetBondTypeAsDouble`, aromatic 1.5 as 4), the
MOL2 files by MDAnalysis 2.11 (each bond's `order`: '1', '2', '3', 'ar', 'am', ...).

    pip install rdkit MDAnalysis==2.11.0
    python3 gen_bond_orders.py   (in this directory)

Writes bond_orders_reference.json: per file and record, the bonds as [i, j, order] with i < j,
sorted, 0-based; orders 1-3, 4 aromatic, 'am' as 1, anything else 0.
"""
import json

import MDAnalysis as mda
from rdkit import Chem

out = {}
for name in ["imatinib_confs.sdf", "library.sdf"]:
    records = []
    for mol in Chem.SDMolSupplier(name, sanitize=False, removeHs=False):
        bonds = []
        for b in mol.GetBonds():
            i, j = sorted((b.GetBeginAtomIdx(), b.GetEndAtomIdx()))
            t = b.GetBondTypeAsDouble()
            order = {1.0: 1, 2.0: 2, 3.0: 3, 1.5: 4}.get(t, 0)
            bonds.append([i, j, order])
        records.append(sorted(bonds))
    out[name] = records
mol = Chem.MolFromMolFile("caffeine_v3000.mol", sanitize=False, removeHs=False)
out["caffeine_v3000.mol"] = [
    sorted(
        [*sorted((b.GetBeginAtomIdx(), b.GetEndAtomIdx())),
         {1.0: 1, 2.0: 2, 3.0: 3, 1.5: 4}.get(b.GetBondTypeAsDouble(), 0)]
        for b in mol.GetBonds()
    )
]
ORDER = {"1": 1, "2": 2, "3": 3, "ar": 4, "am": 1}
for name in ["imatinib_poses.mol2", "library.mol2"]:
    records = []
    # MDAnalysis takes a MOL2 file's topology from its first molecule: each molecule is read
    # on its own, from its own block.
    text = open(name).read()
    blocks = ["@<TRIPOS>MOLECULE" + b for b in text.split("@<TRIPOS>MOLECULE")[1:]]
    for k, block in enumerate(blocks):
        path = f"/tmp/_block{k}.mol2"
        open(path, "w").write(block)
        u = mda.Universe(path)
        bonds = []
        for b in u.bonds:
            i, j = sorted(int(x) for x in b.indices)
            bonds.append([i, j, ORDER.get(str(b.order), 0)])
        records.append(sorted(bonds))
    out[name] = records
json.dump(out, open("bond_orders_reference.json", "w"), separators=(",", ":"))
print({k: [len(r) for r in v] for k, v in out.items()})
