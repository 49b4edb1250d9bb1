"""A receptor and a ligand as one file, for the CLI test of `texmap render --add`.

receptor_aspirin.xyz.gz (extended XYZ written by ASE 3.29, gzipped with mtime 0): the atoms of
../select_mda.pdb (a protein, DNA, water and ions written by MDAnalysis with element columns, as ASE reads it) followed by those of the first record of
library.sdf (aspirin, as ASE reads the SD file), positions and elements only.

    pip install ase==3.29.0
    python3 gen_scene.py
"""
import gzip
import io
import os

from ase.io import read, write

here = os.path.dirname(os.path.abspath(__file__))
receptor = read(os.path.join(here, "..", "select_mda.pdb"), format="proteindatabank")
ligand = read(os.path.join(here, "library.sdf"), index=0, format="sdf")
scene = receptor + ligand
scene.cell = [0, 0, 0]
scene.pbc = False
for key in list(scene.arrays):
    if key not in ("numbers", "positions"):
        del scene.arrays[key]
scene.info = {}
buf = io.StringIO()
write(buf, scene, format="extxyz")
with open(os.path.join(here, "receptor_aspirin.xyz.gz"), "wb") as raw:
    with gzip.GzipFile(fileobj=raw, mode="wb", mtime=0, filename="") as out:
        out.write(buf.getvalue().encode())
