"""Reads what `texmap convert` writes with OVITO 3.17.2 and compares it with OVITO's own export.

    python3 check_with_ovito.py ../../../../../target/release/texmap

Runs the two requests of README.md, writing LAMMPS dump and extended XYZ files to a temporary
directory, imports each with ovito.io.import_file and checks: the atom count, positions
(to f32), the cell, the particle type names, and the columns (structure type, coordination,
occupancy) against gen_convert.py's exports. Prints one line per file; exits non-zero on a
mismatch.
"""

import subprocess
import sys
import tempfile

import numpy as np
from ovito.io import import_file

texmap = sys.argv[1]
MD = "../../../../md-io/tests/data/"


def load(path, columns=None):
    if columns:
        return import_file(path, columns=columns).compute()
    return import_file(path).compute()


def check(ours, theirs, pairs, what):
    assert ours.particles.count == theirs.particles.count, what
    np.testing.assert_allclose(ours.particles.positions, theirs.particles.positions, rtol=1e-6, atol=1e-5)
    np.testing.assert_allclose(ours.cell[...], theirs.cell[...], atol=1e-6)
    for a, b in pairs:
        # A LAMMPS dump's `coordination` is imported as OVITO's standard Coordination.
        name = a if a in ours.particles.keys() else a.capitalize()
        assert np.array_equal(np.asarray(ours.particles[name]), np.asarray(theirs.particles[b])), (what, a)
    names = sorted(t.name for t in ours.particles.particle_types.types)
    print(f"{what}: {ours.particles.count} atoms, types {names}, columns {[a for a, _ in pairs]}: same as OVITO's")


with tempfile.TemporaryDirectory() as tmp:
    for ext in ["lammpstrj", "xyz"]:
        out = f"{tmp}/defects.{ext}"
        subprocess.run(
            [texmap, "convert", MD + "grains/fcc_poly.xyz", "--coordination", "3.2",
             "--select", "not cna fcc", "--columns", "cna,coordination", "-q", "-o", out],
            check=True,
        )
        ours = load(out)
        theirs = load("ovito_defects.lammpstrj")
        check(ours, theirs, [("cna", "Structure Type"), ("coordination", "Coordination")], out.split("/")[-1])
    out = f"{tmp}/ws.xyz"
    subprocess.run(
        [texmap, "convert", MD + "wigner_seitz/cur.xyz", "--wigner-seitz", "atoms",
         "--displacement-reference", MD + "wigner_seitz/ref.xyz",
         "--select", "prop site_occupancy != 1", "--columns", "site_occupancy", "-q", "-o", out],
        check=True,
    )
    check(load(out), load("ovito_ws_defects.xyz"), [("site_occupancy", "Occupancy")], "ws.xyz")
