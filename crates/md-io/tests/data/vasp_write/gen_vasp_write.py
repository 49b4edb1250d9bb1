"""What ASE and pymatgen read from the POSCAR and XDATCAR files our VASP writer wrote, for
crates/md-io/tests/vasp_writer.rs.

The files (POSCAR_*, XDATCAR_* in this directory) are our writer's output for real inputs of
tests/data; the test writes them again and compares the bytes. To make them afresh (after a
deliberate change of the writer), from crates/md-io:

    VASP_WRITE_REGENERATE=1 cargo test -p texmap-md-io --test suite vasp_writer::
    python3 tests/data/vasp_write/gen_vasp_write.py   # ASE 3.29, pymatgen 2026.10, phonopy 4.10

    POSCAR_cod        crystal/cod_9001665.cif (P-1, triclinic; species in the CIF's order)
    POSCAR_nisb       crystal/cod_1010930.cif (hexagonal NiSb)
    POSCAR_triclinic  vasp/POSCAR_ase_direct (ASE's POSCAR, selective dynamics dropped)
    POSCAR_vel        vasp/CONTCAR_ase_vel.vasp (velocities, Cartesian input)
    POSCAR_water      dynamics/vel.gro (water O H H interleaved, ions, GRO velocities)
    XDATCAR_lammps    lmp_tri.lammpstrj (3 frames, fixed triclinic box, Ar and Kr mixed)
    XDATCAR_npt       vasp/XDATCAR_ase (5 frames, the cell changes: a header per frame)
    XDATCAR_pmg       vasp/XDATCAR_pmg (6 frames, fixed cell; pymatgen's layout, which ASE
                      cannot read, written in the one it can)

Writes reference.json: per file, per reader ("ase": ase.io.read with format "vasp", or
"vasp-xdatcar" and index ":"; "pymatgen": Poscar.from_file or Xdatcar; "phonopy": its
read_vasp, POSCARs only, null for an XDATCAR), per frame the chemical symbols in order, the
cell (rows, Å), the Cartesian positions (Å) and for a POSCAR with velocities those in Å/ps
(ASE and pymatgen; phonopy reads none). `python3 gen_vasp_write.py DIR` prints the same for
the files in DIR instead (the test's live check; a reader not installed is null).
"""

import json
import os
import sys

import numpy as np
from ase.io import read
from ase.units import fs

try:
    from pymatgen.io.vasp import Poscar, Xdatcar
except ImportError:
    Poscar = Xdatcar = None
try:
    from phonopy.interface.vasp import read_vasp as phonopy_read_vasp
except ImportError:
    phonopy_read_vasp = None

here = os.path.dirname(os.path.abspath(__file__))


def ase_frames(path, xdatcar):
    if xdatcar:
        images = read(path, index=":", format="vasp-xdatcar")
    else:
        images = [read(path, format="vasp")]
    out = []
    for a in images:
        f = {
            "symbols": a.get_chemical_symbols(),
            "cell": a.cell.array.tolist(),
            "positions": a.positions.tolist(),
        }
        if not xdatcar and a.has("momenta"):
            # ASE units → Å/fs → Å/ps.
            f["velocities"] = (a.get_velocities() / (1 / fs) * 1000).tolist()
        out.append(f)
    return out


def pmg_frames(path, xdatcar):
    if xdatcar:
        structures, velocities = Xdatcar(path).structures, None
    else:
        p = Poscar.from_file(path, check_for_potcar=False)
        structures, velocities = [p.structure], p.velocities
    out = []
    for s in structures:
        f = {
            "symbols": [site.specie.symbol for site in s],
            "cell": s.lattice.matrix.tolist(),
            "positions": s.cart_coords.tolist(),
        }
        if velocities:
            f["velocities"] = [[x * 1000 for x in v] for v in velocities]
        out.append(f)
    return out


def phonopy_frames(path):
    a = phonopy_read_vasp(path)
    cell = np.array(a.cell)
    return [{
        "symbols": list(a.symbols),
        "cell": cell.tolist(),
        "positions": (np.array(a.scaled_positions) @ cell).tolist(),
    }]


def read_dir(d):
    out = {}
    for name in sorted(os.listdir(d)):
        if not name.startswith(("POSCAR_", "XDATCAR_")):
            continue
        path = os.path.join(d, name)
        xdatcar = name.startswith("XDATCAR")
        out[name] = {
            "ase": ase_frames(path, xdatcar),
            "pymatgen": pmg_frames(path, xdatcar) if Poscar else None,
            "phonopy": None if xdatcar or not phonopy_read_vasp else phonopy_frames(path),
        }
    return out


if __name__ == "__main__":
    if len(sys.argv) > 1:
        json.dump(read_dir(sys.argv[1]), sys.stdout)
    else:
        if Poscar is None or phonopy_read_vasp is None:
            sys.exit("pip install pymatgen phonopy: the reference holds what they read")
        with open(os.path.join(here, "reference.json"), "w") as f:
            json.dump(read_dir(here), f, indent=None)
            f.write("\n")
