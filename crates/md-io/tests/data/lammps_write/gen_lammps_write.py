"""Fixtures for crates/md-io/tests/lammps_write.rs: LAMMPS data files our writer wrote, what
LAMMPS itself made of them, and what ASE writes for the same crystal.

- nacl_primitive.vasp: ASE 3.29's rocksalt NaCl primitive cell (a = 5.64 Å) doubled along a
  and rattled (seed 7), a POSCAR whose lattice vectors are not LAMMPS's restricted form;
  nacl_ase.data: ASE's write_lammps_data of the same atoms (its Prism rotation).
- written/*.data: `texmap convert INPUT -o written/NAME.data` (the test writes them again and
  compares the bytes), for
    nacl.data     from nacl_primitive.vasp (atomic style, the cell rotated);
    cod.data      from ../crystal/cod_9001665.cif (P-1, triclinic, atomic style);
    nisb.data     from ../crystal/cod_1010930.cif (hexagonal: xy = -a/2, the tilt limit);
    peptide.data  from ../tpr/peptide.tpr.gz, its first 1000 atoms without TIP4P's massless
                  sites (full style: charges, masses, residues, the .tpr's bonds; a rhombic
                  dodecahedron whose c edge leans past half of a and b in single precision, so
                  the tilts are reduced); gzipped, as is LAMMPS's;
    caffeine.data from ../molecules/caffeine_v3000.mol (no cell: the bounding box grown by
                  1 Å; bonds from the file: molecular style; read with boundary f f f).
- lammps/*.data: LAMMPS (Debian's 20220106) `read_data written/NAME.data` then
  `write_data lammps/NAME.data nocoeff`, with the atom style the file names.

    pip install ase==3.29.0; apt install lammps
    python3 gen_lammps_write.py PATH/TO/texmap
"""
import os
import re
import subprocess
import sys
import tempfile

from ase.build import bulk
from ase.io import write
from ase.io.lammpsdata import write_lammps_data

here = os.path.dirname(os.path.abspath(__file__))
texmap = sys.argv[1]
data = os.path.join(here, "..")

atoms = bulk("NaCl", "rocksalt", a=5.64) * (2, 1, 1)
atoms.rattle(0.05, seed=7)
write(os.path.join(here, "nacl_primitive.vasp"), atoms, format="vasp", direct=True)
write_lammps_data(os.path.join(here, "nacl_ase.data"), atoms, atom_style="atomic",
                  masses=True, specorder=["Na", "Cl"])

CASES = {
    "nacl": [os.path.join(here, "nacl_primitive.vasp")],
    "cod": [os.path.join(data, "crystal", "cod_9001665.cif")],
    "nisb": [os.path.join(data, "crystal", "cod_1010930.cif")],
    "peptide": [os.path.join(data, "tpr", "peptide.tpr.gz"), "--select", "not name MW and index 0:999"],
    "caffeine": [os.path.join(data, "molecules", "caffeine_v3000.mol")],
}
os.makedirs(os.path.join(here, "written"), exist_ok=True)
os.makedirs(os.path.join(here, "lammps"), exist_ok=True)
for name, args in CASES.items():
    out = os.path.join(here, "written", name + ".data")
    subprocess.run([texmap, "convert", "-q", *args, "-o", out], check=True)
    style = re.search(r"^Atoms # (\w+)", open(out).read(), re.M).group(1)
    with tempfile.TemporaryDirectory() as tmp:
        script = os.path.join(tmp, "in.lmp")
        with open(script, "w") as f:
            boundary = "f f f" if name == "caffeine" else "p p p"
            f.write(f"units real\natom_style {style}\nboundary {boundary}\n")
            f.write(f"read_data {out}\n")
            f.write(f"write_data {os.path.join(here, 'lammps', name + '.data')} nocoeff\n")
        r = subprocess.run(["lmp", "-in", script, "-log", "none"], cwd=tmp, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"{name}: LAMMPS failed:\n{r.stdout}\n{r.stderr}")
    if name == "peptide":
        for path in (out, os.path.join(here, "lammps", name + ".data")):
            subprocess.run(["gzip", "-9nf", path], check=True)
    print(name, style)
