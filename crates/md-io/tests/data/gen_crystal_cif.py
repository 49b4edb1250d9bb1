"""Write what ASE reads from the crystallographic CIF files of crystal/ (crystal/reference.json),
for crates/md-io/tests/crystal_cif.rs.

- crystal/cod_*.cif: the eight COD mineral files ASE ships as test data
  (ase/test/testdata/minerals/, COD data are public domain), copied unchanged: hexagonal,
  cubic F-centred, triclinic, monoclinic, orthorhombic, rhombohedral (rhombohedral and
  hexagonal axes) and tetragonal cells, with `_symmetry_equiv_pos_as_xyz` or
  `_space_group_symop_operation_xyz`, special positions and charges in type symbols.
- crystal/two_blocks.cif: cod_9004218.cif followed by cod_1010995.cif (written here), two data
  blocks, so two frames.

For every file the JSON holds, per data block with a structure, ASE's reading by
`ase.io.read(path, index=":")` (the asymmetric unit expanded by the file's operations, images
closer than symprec = 1e-3 in fractional coordinates merged; these files have no partial
occupancies): the atom count, the cell matrix (rows, A), the elements and the Cartesian
positions (A) in ASE's order.

Run from this directory: python3 gen_crystal_cif.py
"""
import glob
import json
import os

import ase
import ase.io

assert ase.__version__ == "3.29.0", ase.__version__

HERE = os.path.dirname(os.path.abspath(__file__))
CRYSTAL = os.path.join(HERE, "crystal")

with open(os.path.join(CRYSTAL, "two_blocks.cif"), "w") as out:
    for part in ["cod_9004218.cif", "cod_1010995.cif"]:
        with open(os.path.join(CRYSTAL, part)) as f:
            out.write(f.read())

reference = {}
for path in sorted(glob.glob(os.path.join(CRYSTAL, "*.cif"))):
    frames = []
    for atoms in ase.io.read(path, index=":"):
        frames.append(
            {
                "n_atoms": len(atoms),
                "cell": atoms.cell[:].tolist(),
                "elements": atoms.get_chemical_symbols(),
                "positions": atoms.get_positions().tolist(),
            }
        )
    reference[os.path.basename(path)] = frames

with open(os.path.join(CRYSTAL, "reference.json"), "w") as f:
    json.dump(reference, f, indent=1)
    f.write("\n")

for name, frames in reference.items():
    print(name, [fr["n_atoms"] for fr in frames])
