"""Per-atom properties written by other programs, and what those programs read back
(properties_reference.json), for crates/md-io/tests/properties.rs.

- 3jqh.cif and 1uqc.cif (the wwPDB's files, see README.md): gemmi's occupancy and B-factor of
  every atom after `remove_alternative_conformations()` (the first conformation, as our reader
  keeps), model 1.
- 3jqh_gemmi.pdb: gemmi's PDB of 3jqh.cif (`write_pdb` after the same removal); the reference
  for it is what MDAnalysis reads back (`occupancies`, `tempfactors`) and the atoms its `prop`
  selections select.
- ase_props.xyz: ASE's extended XYZ of 40 seeded atoms with `masses`, `initial_charges` and a
  user array `von_mises` (real, one component) and `tags` (integer); the reference is ASE's
  reading back of the file.

Run with gemmi 0.7.5, MDAnalysis 2.11 and ASE 3.29.0: `python3 gen_properties.py`.
"""
import json
import warnings

import ase
import ase.io
import gemmi
import MDAnalysis as mda
import numpy as np

warnings.filterwarnings("ignore")
assert gemmi.__version__ == "0.7.5", gemmi.__version__

ref = {}
for path in ("3jqh.cif", "1uqc.cif"):
    st = gemmi.read_structure(path)
    st.remove_alternative_conformations()
    occ, b = [], []
    for chain in st[0]:
        for res in chain:
            for a in res:
                occ.append(round(a.occ, 4))
                b.append(round(a.b_iso, 4))
    ref[path] = {"occupancy": occ, "bfactor": b}
    if path == "3jqh.cif":
        st.setup_entities()
        st.write_pdb("3jqh_gemmi.pdb")

u = mda.Universe("3jqh_gemmi.pdb")
ref["3jqh_gemmi.pdb"] = {
    "occupancy": [round(float(x), 4) for x in u.atoms.occupancies],
    "bfactor": [round(float(x), 4) for x in u.atoms.tempfactors],
}
# MDAnalysis's `prop` selections on the same file: the indices it selects.
ref["prop_selections"] = {
    sel: [int(i) for i in u.select_atoms(sel).indices]
    for sel in [
        "prop tempfactor > 60",
        "prop tempfactor>=57.5 and name CA",
        "prop abs x < 5",
        "prop z <= 20.5 or prop y > 30",
        "prop 50 > tempfactor",
        "prop occupancy < 1",
        "prop occupancy == 1",
        "not prop x != 3.278",
        "prop x> 10 and prop x <12",
    ]
}

rng = np.random.default_rng(7)
n = 40
atoms = ase.Atoms(
    symbols=rng.choice(["C", "H", "O", "N"], size=n),
    positions=rng.uniform(0, 12, size=(n, 3)),
    cell=[12, 12, 12],
    pbc=True,
)
atoms.set_initial_charges(rng.uniform(-1, 1, size=n))
atoms.set_tags(rng.integers(0, 5, size=n))
atoms.set_masses(atoms.get_masses() * rng.uniform(0.9, 1.1, size=n))
atoms.new_array("von_mises", rng.gamma(2.0, 0.5, size=n))
ase.io.write("ase_props.xyz", atoms, format="extxyz")
back = ase.io.read("ase_props.xyz", format="extxyz")
ref["ase_props.xyz"] = {
    "masses": back.get_masses().tolist(),
    "initial_charges": back.get_initial_charges().tolist(),
    "von_mises": back.arrays["von_mises"].tolist(),
    "tags": [int(t) for t in back.get_tags()],
}
with open("properties_reference.json", "w") as f:
    json.dump(ref, f)
for k, v in ref.items():
    print(k, {p: len(x) for p, x in v.items()})
