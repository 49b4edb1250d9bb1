"""What RDKit reads from the SD files our SDF writer wrote (tests/writers.rs `sdf_*`), as an
independent check of the files in this directory.

    pip install rdkit          (written with RDKit 2026.09.1)
    python3 gen_rdkit_reference.py [DIR] [OUT]   (default: this directory, rdkit_reference.json)

Per file (every *.sdf in DIR, sorted by name) and record, read by
`Chem.SDMolSupplier(path, removeHs=False, sanitize=False)`: the title (`_Name`), atom symbols,
coordinates (rounded to 4 decimals, as written), bonds as [i, j, order] (0-based, i < j,
sorted; single 1, double 2, triple 3, aromatic 4, anything else 0), formal charges and the
data items (as strings). `sanitized` says whether the same record reads with sanitize=True
(RDKit's valence and aromaticity checks), and `sanitized_charges` its formal charges then.
"""
import json
import os
import sys

from rdkit import Chem, RDLogger

RDLogger.DisableLog("rdApp.*")

ORDER = {
    Chem.BondType.SINGLE: 1,
    Chem.BondType.DOUBLE: 2,
    Chem.BondType.TRIPLE: 3,
    Chem.BondType.AROMATIC: 4,
}

here = os.path.dirname(os.path.abspath(__file__))
src = sys.argv[1] if len(sys.argv) > 1 else here
out_path = sys.argv[2] if len(sys.argv) > 2 else os.path.join(here, "rdkit_reference.json")

out = {}
for name in sorted(n for n in os.listdir(src) if n.endswith(".sdf")):
    path = os.path.join(src, name)
    records = []
    raw = list(Chem.SDMolSupplier(path, removeHs=False, sanitize=False))
    sane = list(Chem.SDMolSupplier(path, removeHs=False, sanitize=True))
    for mol, s in zip(raw, sane):
        conf = mol.GetConformer()
        bonds = sorted(
            [*sorted((b.GetBeginAtomIdx(), b.GetEndAtomIdx())), ORDER.get(b.GetBondType(), 0)]
            for b in mol.GetBonds()
        )
        props = mol.GetPropsAsDict(includePrivate=False, includeComputed=False)
        records.append(
            {
                "name": mol.GetProp("_Name"),
                "symbols": [a.GetSymbol() for a in mol.GetAtoms()],
                "coords": [
                    [round(v, 4) for v in (p.x, p.y, p.z)]
                    for p in (conf.GetAtomPosition(i) for i in range(mol.GetNumAtoms()))
                ],
                "bonds": bonds,
                "charges": [a.GetFormalCharge() for a in mol.GetAtoms()],
                "props": {k: str(v) for k, v in sorted(props.items())},
                "sanitized": s is not None,
                "sanitized_charges": [a.GetFormalCharge() for a in s.GetAtoms()] if s else None,
            }
        )
    out[name] = records
with open(out_path, "w") as f:
    json.dump(out, f, separators=(",", ":"), sort_keys=True)
    f.write("\n")
print({k: len(v) for k, v in out.items()})
