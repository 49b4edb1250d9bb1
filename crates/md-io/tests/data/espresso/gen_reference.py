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
"""

import json
import os
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
