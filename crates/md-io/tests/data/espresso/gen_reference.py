"""ASE's reading of the pw.x fixtures (gen.sh runs this after pw.x): reference.json.

For every NAME.pwo, `ase.io.read(NAME.pwo, index=':', format='espresso-out')` (ASE 3.29.0):
per frame (`frames`) the chemical symbols, positions (Å), cell vectors (Å, rows), forces (eV/Å),
energy (eV) and stress (eV/Å³, Voigt order xx yy zz yz xz xy, ASE's sign), as ASE converts
them (its espresso module's CODATA 2006 units, as pw.x 6.7's).
For every NAME.pwi, `ase.io.read(NAME.pwi, format='espresso-in')` where ASE reads it (ibrav=0
with a lattice parameter for alat positions; ASE refuses any other ibrav), else null and the
error ASE gave: those files are checked against pw.x's own header geometry (frame 0 of the
.pwo) instead. `concatenated`: ASE's reading of si_md.pwo followed by si_relax.pwo in one
file (two runs: a banner each).

`xml`: for every NAME.pwi whose run left pw.x's data file (gen.sh keeps ./tmp until this
script has run; a prefix used by one input only), the geometry pw.x itself built, with its full
digits: `output/atomic_structure` of tmp/PREFIX.save/data-file-schema.xml (cell vectors and
Cartesian positions in bohr, converted to Å with pw.x 6.7's own bohr, 0.529177210903 Å: QE
6.7's Modules/constants.f90 has CODATA 2018's, where ASE's espresso module keeps CODATA 2006's
0.52917720859 Å; an A of 5.3 Å comes back from pw.x's data file as 5.3 Å only with the former).

`magn`: for every NAME.pwo with pw.x's `Magnetic moment per site` blocks, the moments read by
plain text matching, independent of ASE and of the Rust reader: per step (the lines between
one `ATOMIC_POSITIONS` block at column 0 and the next, the header's step first), the `magn:`
numbers of the step's last block. ASE 3.29 takes each such line's last field, which in pw.x
6.7's format (`atom: 1 charge: 6.2918 magn: 3.3015 constr: 0.0000`) is the constraint, not the
moment: its reading is kept as `magmoms` in each frame (all 0.0) to show it.
"""

import json
import os
import re
import xml.etree.ElementTree as ET
import tempfile

import ase
import ase.io


def frame(atoms):
    out = {
        "symbols": atoms.get_chemical_symbols(),
        "positions": atoms.positions.tolist(),
        "cell": atoms.cell.array.tolist(),
    }
    calc = atoms.calc
    if calc is not None:
        results = calc.results
        out["energy"] = results.get("energy")
        forces = results.get("forces")
        out["forces"] = None if forces is None else forces.tolist()
        stress = results.get("stress")
        out["stress"] = None if stress is None else stress.tolist()
        magmoms = results.get("magmoms")
        if magmoms is not None:
            out["magmoms"] = magmoms.tolist()
    return out


def frames(path):
    return [frame(a) for a in ase.io.read(path, index=":", format="espresso-out")]


def output(name):
    """ASE's frames of a .pwo. ASE takes every line containing ATOMIC_POSITIONS for the start of
    a positions block, so it fails on pw.x's message about a card without units ("DEPRECATED:
    no units specified in ATOMIC_POSITIONS card", ibrav8_ortho.pwo); such a file is read by ASE
    without the indented lines that hold the word (pw.x writes its blocks at the start of a
    line), and the note says so."""
    try:
        return {"frames": frames(name)}
    except Exception as e:
        with open(name) as f:
            lines = f.readlines()
        kept = [l for l in lines if "ATOMIC_POSITIONS" not in l or l.startswith("ATOMIC_POSITIONS")]
        with tempfile.TemporaryDirectory() as tmp:
            copy = os.path.join(tmp, name)
            with open(copy, "w") as f:
                f.writelines(kept)
            note = (f"ASE fails on the file ({type(e).__name__}: {e}); read without the "
                    f"{len(lines) - len(kept)} indented lines holding ATOMIC_POSITIONS")
            return {"frames": frames(copy), "note": note}


BOHR = 0.529177210903  # Å, QE 6.7's BOHR_RADIUS_ANGS (CODATA 2018)


def prefix_of(pwi):
    """The run's prefix when it is an scf (the data file then holds the input's geometry)."""
    with open(pwi) as f:
        text = f.read()
    m = re.search(r"prefix\s*=\s*'([^']*)'", text)
    scf = re.search(r"calculation\s*=\s*'scf'", text)
    return m.group(1) if m and scf else None


def xml_geometry(prefix):
    """pw.x's own cell and positions (Å) from its data file, or None without one."""
    path = os.path.join("tmp", prefix + ".save", "data-file-schema.xml")
    if not os.path.exists(path):
        return None
    s = ET.parse(path).getroot().find("output/atomic_structure")
    vec = lambda text: [float(x) * BOHR for x in text.split()]
    return {
        "cell": [vec(s.find("cell/" + a).text) for a in ("a1", "a2", "a3")],
        "positions": [vec(a.text) for a in s.find("atomic_positions")],
        "names": [a.get("name") for a in s.find("atomic_positions")],
    }


def magn_by_grep(pwo):
    """The `magn:` numbers of each step's last `Magnetic moment per site` block."""
    steps = [[]]
    block = None
    with open(pwo) as f:
        for line in f:
            if line.startswith("ATOMIC_POSITIONS"):
                steps.append([])
            elif "Magnetic moment per site" in line:
                block = []
                steps[-1] = block
            elif block is not None and "magn:" in line:
                block.append(float(line.split("magn:")[1].split()[0]))
            else:
                block = None
    return steps


here = os.path.dirname(os.path.abspath(__file__))
os.chdir(here)
reference = {"ase": ase.__version__, "outputs": {}, "inputs": {}}
for name in sorted(os.listdir(".")):
    stem, ext = os.path.splitext(name)
    if ext == ".pwo":
        reference["outputs"][stem] = output(name)
    elif ext == ".pwi":
        try:
            reference["inputs"][stem] = {"frame": frame(ase.io.read(name, format="espresso-in"))}
        except Exception as e:  # ASE refuses ibrav != 0 and alat positions without alat
            reference["inputs"][stem] = {"frame": None, "ase_error": f"{type(e).__name__}: {e}"}

prefixes = {}
for name in sorted(os.listdir(".")):
    if name.endswith(".pwi"):
        prefixes.setdefault(prefix_of(name), []).append(name[:-4])
for prefix, stems in prefixes.items():
    if prefix and len(stems) == 1:
        geometry = xml_geometry(prefix)
        if geometry is not None:
            reference["inputs"][stems[0]]["xml"] = geometry
for stem in reference["outputs"]:
    with open(stem + ".pwo") as f:
        if "Magnetic moment per site" in f.read():
            reference["outputs"][stem]["magn"] = magn_by_grep(stem + ".pwo")

with tempfile.TemporaryDirectory() as tmp:
    joined = os.path.join(tmp, "joined.pwo")
    with open(joined, "wb") as out:
        for part in ["si_md.pwo", "si_relax.pwo"]:
            with open(part, "rb") as f:
                out.write(f.read())
    reference["concatenated"] = frames(joined)

with open("reference.json", "w") as f:
    json.dump(reference, f, indent=1)
    f.write("\n")
for stem, out in reference["outputs"].items():
    print(stem, len(out["frames"]), "frames", out.get("note", ""))
for stem, r in reference["inputs"].items():
    print(stem, "read by ASE" if r["frame"] else r["ase_error"])
