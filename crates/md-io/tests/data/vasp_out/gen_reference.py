"""ASE's reading of every VASP output in this directory, for tests/vasp_out.rs.

Run from this directory: python3 gen_reference.py (ASE 3.29.0). Writes reference.json: per
file, per frame (ase.io.read(path, ':')), the symbols, positions (Å), cell (rows, Å), forces
(eV/Å), energy and free energy (eV) and stress (eV/Å³, Voigt order xx yy zz yz xz xy, ASE's
sign) when ASE has them. The tests also re-run this reading live when ASE is installed.
"""

import json
import sys

import ase
import ase.io

FILES = {
    "vasprun_li_relax.xml": "vasp-xml",
    "vasprun_sio2.xml": "vasp-xml",
    "OUTCAR_li_relax": "vasp-out",
    "OUTCAR_gaas": "vasp-out",
}


def frame(atoms):
    calc = atoms.calc
    results = calc.results if calc is not None else {}

    def get(key):
        v = results.get(key)
        return None if v is None else v.tolist() if hasattr(v, "tolist") else float(v)

    return {
        "symbols": atoms.get_chemical_symbols(),
        "positions": atoms.get_positions().tolist(),
        "cell": atoms.cell.array.tolist(),
        "forces": get("forces"),
        "energy": get("energy"),
        "free_energy": get("free_energy"),
        "stress": get("stress"),
    }


def read(path, fmt):
    return [frame(a) for a in ase.io.read(path, ":", format=fmt)]


def main():
    out = {"ase": ase.__version__, "files": {}}
    for path, fmt in FILES.items():
        out["files"][path] = {"format": fmt, "frames": read(path, fmt)}
    if len(sys.argv) > 1 and sys.argv[1] == "-":
        json.dump(out, sys.stdout)
        return
    with open("reference.json", "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
