"""Convert PDB fixtures of this directory to PDBx/mmCIF with gemmi, and write what gemmi itself
reads from each mmCIF file (mmcif_reference.json), for crates/md-io/tests/mmcif.rs.

- gemmi_multi.cif, gemmi_topo.cif, gemmi_select.cif: gemmi's conversion of mda_multi.pdb (3
  models, triclinic CRYST1, ions), topo_mda.pdb (66 atoms, 18 A cube) and select_mda.pdb (905
  atoms, the 1 A placeholder cell): `gemmi.read_structure` + `setup_entities` +
  `make_mmcif_document`, as `gemmi convert x.pdb x.cif` does.
- 3jqh.cif (X-ray, alternate locations and two microheterogeneities) and 1uqc.cif (NMR, quoted
  atom names such as "O5'"), written by the wwPDB, copied from the Biopython and biotite test
  suites (see README.md): not written here, only read.

For every file the JSON holds gemmi's reading after `remove_alternative_conformations()` (the
first conformation of each atom): per model the atoms in file order with name, residue name,
sequence number, chain, element and x y z; plus the number of _atom_site rows of each model
before the removal, the cell and _struct.title.
"""
import json

import gemmi

assert gemmi.__version__ == "0.7.5", gemmi.__version__

for pdb, cif in [
    ("mda_multi.pdb", "gemmi_multi.cif"),
    ("topo_mda.pdb", "gemmi_topo.cif"),
    ("select_mda.pdb", "gemmi_select.cif"),
]:
    st = gemmi.read_structure(pdb)
    st.setup_entities()
    st.make_mmcif_document().write_file(cif)


def reference(path):
    block = gemmi.cif.read(path).sole_block()
    models = block.find_values("_atom_site.pdbx_PDB_model_num")
    rows = {}
    for m in models:
        rows[m] = rows.get(m, 0) + 1
    title = block.find_value("_struct.title")
    st = gemmi.read_structure(path)
    st.remove_alternative_conformations()
    out = []
    for model, n_rows in zip(st, rows.values()):
        atoms = []
        for chain in model:
            for res in chain:
                for a in res:
                    atoms.append([a.name, res.name, res.seqid.num, chain.name, a.element.name,
                                  round(a.pos.x, 4), round(a.pos.y, 4), round(a.pos.z, 4)])
        out.append({"rows": n_rows, "atoms": atoms})
    c = st.cell
    return {
        "gemmi": gemmi.__version__,
        "cell": [c.a, c.b, c.c, c.alpha, c.beta, c.gamma] if c.is_crystal() else None,
        "title": gemmi.cif.as_string(title) if title is not None else None,
        "models": out,
    }


files = ["gemmi_multi.cif", "gemmi_topo.cif", "gemmi_select.cif", "3jqh.cif", "1uqc.cif"]
with open("mmcif_reference.json", "w") as f:
    json.dump({name: reference(name) for name in files}, f, indent=1)
    f.write("\n")
