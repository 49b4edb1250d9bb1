"""What gsd.hoomd reads from our GSD writer's files (crates/md-io/tests/gsd_writer.rs).

The files tri.gsd, vel.gsd, nacl.gsd and twod.gsd are our writer's rewrites of ../gsd/hoomd_tri.gsd
(written by gsd.hoomd), ../mda_vel.gro (MDAnalysis), ../lammps_write/nacl_primitive.vasp (ASE)
and ../gsd/hoomd_2d.gsd (gsd.hoomd, 2-D):
    TEXMAP_BLESS=1 cargo test -p texmap-md-io --test suite gsd_writer::rewriting
then, from this directory, with the gsd package (pip install gsd; 5.0.1 here):
    python3 gen_gsd_write.py
writes gsd_hoomd.json.gz: per file, per frame, what gsd.hoomd.open reads back, in the layout of
../gsd/reference.json.gz (float32 values as their shortest decimal).
"""

import gzip
import json

import gsd.hoomd
import numpy as np


def lists(a):
    return np.asarray(a).tolist()


def short(o):
    if isinstance(o, float):
        return float(str(np.float32(o))) if float(np.float32(o)) == o else o
    if isinstance(o, list):
        return [short(x) for x in o]
    if isinstance(o, dict):
        return {k: short(v) for k, v in o.items()}
    return o


def read(path):
    out = []
    with gsd.hoomd.open(path, "r") as t:
        for f in t:
            p = f.particles
            out.append({
                "step": int(f.configuration.step),
                "dimensions": int(f.configuration.dimensions),
                "box": lists(f.configuration.box),
                "N": int(p.N),
                "types": list(p.types),
                "typeid": lists(p.typeid),
                "position": lists(p.position),
                "velocity": lists(p.velocity),
                "diameter": lists(p.diameter),
                "mass": lists(p.mass),
                "charge": lists(p.charge),
                "orientation": lists(p.orientation),
                "image": lists(p.image),
                "body": lists(p.body),
                "bonds_N": int(f.bonds.N),
                "bonds_group": lists(f.bonds.group),
            })
    return {"frames": out}


ref = {case: read(f"{case}.gsd") for case in ["tri", "vel", "nacl", "twod"]}
text = json.dumps(short(ref), separators=(",", ":")).encode()
with open("gsd_hoomd.json.gz", "wb") as fh:
    fh.write(gzip.compress(text, compresslevel=9, mtime=0))
