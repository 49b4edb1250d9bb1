"""Reference element data from ASE, used to write and to test src/elements.rs.

Writes elements.json: for Z = 1..103 the symbol, the Alvarez (2013) van der Waals radius
(ase.data.vdw_alvarez, null where Alvarez gives none), the Jmol colour (ase.data.colors,
as 8-bit sRGB), the covalent radius of Cordero et al. 2008 (ase.data.covalent_radii) and the
standard atomic weight (IUPAC 2016, ase.data.atomic_masses). With --rust it prints the Rust
table bodies used in src/elements.rs instead (TABLE, then MASSES).
"""
import json
import math
import sys

import ase
from ase.data import atomic_masses, chemical_symbols, covalent_radii
from ase.data.colors import jmol_colors
from ase.data.vdw_alvarez import vdw_radii

# Where Alvarez has no radius: Mantina et al. 2009 (J. Phys. Chem. A 113, 5806) for Po..Ra,
# 2.00 Å otherwise (Pm, Fm..Lr) -- documented in src/elements.rs.
FALLBACK = {61: 2.00, 84: 1.97, 85: 2.02, 86: 2.20, 87: 3.48, 88: 2.83,
            100: 2.00, 101: 2.00, 102: 2.00, 103: 2.00}

rows = []
for z in range(1, 104):
    r = float(vdw_radii[z])
    rgb = [int(round(float(c) * 255)) for c in jmol_colors[z]]
    rows.append({"z": z, "symbol": chemical_symbols[z],
                 "alvarez": None if math.isnan(r) else r, "jmol": rgb,
                 "cordero": float(covalent_radii[z]), "mass": float(atomic_masses[z])})

if "--rust" in sys.argv:
    for row in rows:
        r = row["alvarez"] if row["alvarez"] is not None else FALLBACK[row["z"]]
        print('    ("%s", %.2f, [%d, %d, %d], %.2f),'
              % (row["symbol"], r, *row["jmol"], row["cordero"]))
    print()
    for row in rows:
        print("    %r, // %s" % (row["mass"], row["symbol"]))
else:
    with open("elements.json", "w") as f:
        json.dump({"program": "ase", "version": ase.__version__, "elements": rows}, f, indent=0)
