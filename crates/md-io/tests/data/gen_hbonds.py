"""Reference hydrogen bonds for tests/hbonds.rs, found by MDAnalysis's HydrogenBondAnalysis.

The system is MDAnalysis's test system adk_oplsaa (MDAnalysisTests 2.11.0 sdist on PyPI,
data/adk_oplsaa.{tpr,xtc}): adenylate kinase in water with Na+ ions, OPLS-AA, 47,681 atoms in
a triclinic (rhombic dodecahedron) box of 80.017 A, angles 60/60/90. Written here by
MDAnalysis:

- hbonds/adk_top.gro.gz: the topology (names, residues) as GRO, every position set to 0 so
  that it compresses (the positions come from the trajectory);
- hbonds/adk_0_9.xtc: frames 0 and 9 of adk_oplsaa.xtc, as read (positions to 0.01 A);
- hbonds/reference.json.gz: per frame, the hydrogen bonds HydrogenBondAnalysis finds with its
  default cutoffs (donor-acceptor <= 3.0 A, donor-hydrogen-acceptor angle >= 150 degrees,
  periodic minimum image) for hydrogens bonded to N or O (bonds from the TPR, which texmap
  does not read: the test finds them by distance) and N or O acceptors, as sorted flat
  (donor, hydrogen, acceptor) 0-based index triples.

    pip install MDAnalysis==2.11.0
    python3 gen_hbonds.py PATH/TO/MDAnalysisTests/data
"""
import gzip
import json
import os
import sys
import warnings

import MDAnalysis as mda
from MDAnalysis.analysis.hydrogenbonds import HydrogenBondAnalysis

warnings.filterwarnings("ignore")
data = sys.argv[1]
here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "hbonds")
os.makedirs(here, exist_ok=True)
u = mda.Universe(os.path.join(data, "adk_oplsaa.tpr"), os.path.join(data, "adk_oplsaa.xtc"))
FRAMES = [0, 9]

u.trajectory[0]
saved = u.atoms.positions.copy()
u.atoms.positions = saved * 0.0
gro = os.path.join(here, "adk_top.gro")
u.atoms.write(gro)
with open(gro, "rb") as f, gzip.GzipFile(gro + ".gz", "wb", 9, mtime=0) as g:
    g.write(f.read())
os.remove(gro)
u.atoms.positions = saved
with mda.Writer(os.path.join(here, "adk_0_9.xtc"), len(u.atoms)) as w:
    for ts in u.trajectory[FRAMES]:
        w.write(u.atoms)

# Read back what was written, so the reference sees the same positions as the test.
v = mda.Universe(os.path.join(data, "adk_oplsaa.tpr"), os.path.join(here, "adk_0_9.xtc"))
hba = HydrogenBondAnalysis(
    v,
    hydrogens_sel="element H and bonded (element N O)",
    acceptors_sel="element N O",
    d_a_cutoff=3.0,
    d_h_a_angle_cutoff=150,
    update_selections=False,
)
hba.run()
frames = []
for k in range(len(v.trajectory)):
    rows = hba.results.hbonds[hba.results.hbonds[:, 0] == k]
    rows = sorted(rows.tolist(), key=lambda r: (r[1], r[2], r[3]))
    frames.append({"dha": [int(x) for r in rows for x in r[1:4]]})
out = {
    "source": "MDAnalysis %s HydrogenBondAnalysis, adk_oplsaa frames %s" % (mda.__version__, FRAMES),
    "d_a_cutoff": 3.0,
    "d_h_a_angle_cutoff": 150.0,
    "n_atoms": len(v.atoms),
    "frames": frames,
}
with gzip.GzipFile(os.path.join(here, "reference.json.gz"), "wb", 9, mtime=0) as g:
    g.write(json.dumps(out, separators=(",", ":")).encode())
for f in os.listdir(here):
    if f.startswith(".adk_0_9.xtc_offsets"):
        os.remove(os.path.join(here, f))
print([len(f["dha"]) // 3 for f in frames])
