"""HOOMD-blue GSD fixtures for tests/gsd.rs, written by gsd.hoomd (gsd 5.0.1), and the
reference: every frame of every file read back by gsd.hoomd.open, the reader HOOMD users trust.

Run from this directory: python3 gen_gsd.py (gsd 5.0.1, numpy).
Writes
- hoomd_tri.gsd: 200 particles of types A, Colloid, Na in a triclinic box (non-zero xy, xz,
  yz), 5 frames. gsd.hoomd writes a chunk only when it differs from frame 0 (or from the schema
  default when frame 0 lacks it), so the frames exercise the schema's default rule: step 0 is
  not written (the default); typeid, charge, body and the 60 bonds are written in frame 0 only;
  diameter in frames 0, 2 and 4 (frame 3 takes frame 0's, not frame 2's); mass in frame 2 only
  (frames 0, 1, 3 are the default 1.0); the box changes in frame 3; frame 4 has 180 particles,
  so its unwritten chunks are schema defaults, not frame 0's, and no bonds (gsd.hoomd writes
  bonds/N = 0 there, frame 0 having bonds/N). Velocities every frame, orientations in frames
  0 and 2, images in frames 0 and 4.
- hoomd_2d.gsd: a 2-D system (dimensions 2, Lz = 0, tilt xy), 120 particles, 3 frames.
- hoomd_one.gsd: one frame of 40 particles in an orthorhombic box, written in double precision.
- hoomd_v1.gsd: hoomd_one.gsd rewritten here as a GSD file format 1.0 file (the version field
  1.0 and the namelist in 64-byte segments, appended at the end; index and data unchanged),
  checked by reading it back with gsd 5.0.1, which still reads 1.0 files.
- reference.json.gz (gzip: 200 kB of numbers as text): per file, per frame, what gsd.hoomd reads back (step, dimensions, box, N,
  types, typeid, position, velocity, diameter, mass, charge, orientation, image, body, bonds/N,
  bonds/group), the chunks present in that frame (gsd.fl), and the cell as tests/gsd.rs expects
  it: edges a1 = (Lx, 0, 0), a2 = (xy Ly, Ly, 0), a3 = (xz Lz, yz Lz, Lz), a 2-D box's zero Lz
  taken as 1, origin -(a1 + a2 + a3) / 2.
"""

import gzip
import json
import struct

import gsd.fl
import gsd.hoomd
import numpy as np

rng = np.random.default_rng(20260611)


def edges(box):
    """The cell rows of a HOOMD box [Lx, Ly, Lz, xy, xz, yz] (2-D: Lz = 0 taken as 1)."""
    lx, ly, lz, xy, xz, yz = (float(v) for v in box)
    if lz == 0.0:
        lz = 1.0
    return np.array([[lx, 0.0, 0.0], [xy * ly, ly, 0.0], [xz * lz, yz * lz, lz]])


def inside(box, n, two_d=False):
    """n positions inside the box, from fractional coordinates (z = 0 in 2-D)."""
    m = edges(box)
    f = rng.random((n, 3)) * 0.98 + 0.01
    if two_d:
        f[:, 2] = 0.5
    return ((f - 0.5) @ m).astype(np.float32)


def quaternions(n):
    q = rng.normal(size=(n, 4))
    return (q / np.linalg.norm(q, axis=1)[:, None]).astype(np.float32)


def base_frame(step, box, n, types, dims=3):
    f = gsd.hoomd.Frame()
    f.configuration.step = step
    f.configuration.box = box
    f.configuration.dimensions = dims
    f.particles.N = n
    f.particles.types = types
    return f


def write_tri(path):
    box0 = [12.0, 11.0, 10.0, 0.3, -0.2, 0.15]
    box3 = [12.5, 10.5, 10.2, 0.25, -0.1, 0.2]
    types = ["A", "Colloid", "Na"]
    n = 200
    typeid = rng.integers(0, 3, n).astype(np.uint32)
    charge = rng.normal(0, 0.5, n).astype(np.float32)
    body = np.where(rng.random(n) < 0.3, rng.integers(0, 20, n), -1).astype(np.int32)
    diameter0 = rng.uniform(0.8, 1.4, n).astype(np.float32)
    orient0 = quaternions(n)
    # Bonds, some written high index first and one twice (both orders), as a writer may.
    pairs = rng.choice(n, size=(60, 2), replace=True)
    pairs[pairs[:, 0] == pairs[:, 1], 1] = (pairs[pairs[:, 0] == pairs[:, 1], 1] + 1) % n
    pairs[59] = pairs[3][::-1]
    group = pairs.astype(np.uint32)
    frames = []
    for k in range(5):
        box = box3 if k == 3 else box0
        nk = 180 if k == 4 else n
        f = base_frame(1000 * k, box, nk, types)
        f.particles.position = inside(box, nk)
        f.particles.velocity = rng.normal(0, 1.0, (nk, 3)).astype(np.float32)
        if k < 4:
            f.particles.typeid = typeid
            f.particles.charge = charge
            f.particles.body = body
            f.bonds.N = len(group)
            f.bonds.types = ["backbone"]
            f.bonds.typeid = np.zeros(len(group), dtype=np.uint32)
            f.bonds.group = group
        if k in (0, 1, 3):
            f.particles.diameter = diameter0
        elif k == 2:
            f.particles.diameter = rng.uniform(0.5, 1.0, n).astype(np.float32)
        else:
            f.particles.diameter = rng.uniform(0.5, 1.0, nk).astype(np.float32)
        if k == 2:
            f.particles.mass = rng.uniform(1.0, 3.0, n).astype(np.float32)
            f.particles.orientation = quaternions(n)
        elif k < 4:
            f.particles.orientation = orient0
        if k == 0:
            f.particles.image = rng.integers(-2, 3, (n, 3)).astype(np.int32)
        elif k == 4:
            f.particles.image = rng.integers(-3, 4, (nk, 3)).astype(np.int32)
        frames.append(f)
    with gsd.hoomd.open(path, mode="w") as t:
        t.extend(frames)


def write_2d(path):
    box = [9.0, 8.0, 0.0, 0.4, 0.0, 0.0]
    n = 120
    typeid = rng.integers(0, 2, n).astype(np.uint32)
    frames = []
    for k in range(3):
        f = base_frame(50 * k + 7, box, n, ["A", "B"], dims=2)
        f.particles.position = inside(box, n, two_d=True)
        f.particles.typeid = typeid
        f.particles.velocity = np.c_[rng.normal(0, 1.0, (n, 2)), np.zeros(n)].astype(
            np.float32
        )
        frames.append(f)
    with gsd.hoomd.open(path, mode="w") as t:
        t.extend(frames)


def write_one(path):
    box = [5.0, 6.0, 7.0, 0.0, 0.0, 0.0]
    n = 40
    f = base_frame(123456789012, box, n, ["A", "B"])
    f.particles.position = inside(box, n).astype(np.float64)
    f.particles.typeid = rng.integers(0, 2, n).astype(np.uint32)
    f.particles.diameter = rng.uniform(0.5, 2.0, n)
    f.particles.mass = rng.uniform(1.0, 2.0, n)
    with gsd.hoomd.open(path, mode="w", precision="double") as t:
        t.append(f)


def write_v1(src, path):
    """src rewritten as a GSD 1.0 file: version 1.0, the names in 64-byte segments at the end."""
    b = bytearray(open(src, "rb").read())
    magic, index_loc, index_alloc, names_loc, names_alloc = struct.unpack_from("<5Q", b, 0)
    assert magic == 0x65DF65DF65DF65DF
    raw = bytes(b[names_loc : names_loc + 64 * names_alloc])
    names = []
    for s in raw.split(b"\0"):
        if not s:
            break
        names.append(s)
    seg = b"".join(s.ljust(64, b"\0") for s in names)
    seg = seg.ljust(64 * (len(names) + 2), b"\0")
    new_loc = len(b)
    struct.pack_into("<QQ", b, 24, new_loc, len(seg) // 64)
    struct.pack_into("<I", b, 44, 1 << 16)
    open(path, "wb").write(bytes(b) + seg)


def lists(a):
    return np.asarray(a).tolist()


def reference(path):
    out = []
    with gsd.fl.open(path, "r") as fl:
        present = [
            sorted(n for n in fl.find_matching_chunk_names("") if fl.chunk_exists(k, n))
            for k in range(fl.nframes)
        ]
        version = fl.gsd_version
    with gsd.hoomd.open(path, "r") as t:
        for k, f in enumerate(t):
            m = edges(f.configuration.box)
            p = f.particles
            out.append(
                {
                    "chunks": present[k],
                    "step": int(f.configuration.step),
                    "dimensions": int(f.configuration.dimensions),
                    "box": lists(f.configuration.box),
                    "cell": m.tolist(),
                    "origin": (-0.5 * m.sum(axis=0)).tolist(),
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
                }
            )
    return {"gsd_version": list(version), "frames": out}


write_tri("hoomd_tri.gsd")
write_2d("hoomd_2d.gsd")
write_one("hoomd_one.gsd")
write_v1("hoomd_one.gsd", "hoomd_v1.gsd")
ref = {
    name: reference(name)
    for name in ["hoomd_tri.gsd", "hoomd_2d.gsd", "hoomd_one.gsd", "hoomd_v1.gsd"]
}
assert ref["hoomd_v1.gsd"]["gsd_version"] == [1, 0]
assert ref["hoomd_v1.gsd"]["frames"] == ref["hoomd_one.gsd"]["frames"]
tri = ref["hoomd_tri.gsd"]["frames"]
# The default rule is exercised as described above.
assert "configuration/step" not in tri[0]["chunks"]
assert "particles/diameter" not in tri[3]["chunks"] and tri[3]["diameter"] == tri[0]["diameter"]
assert "particles/mass" in tri[2]["chunks"] and tri[3]["mass"] == [1.0] * 200
assert tri[4]["N"] == 180 and tri[4]["charge"] == [0.0] * 180 and tri[4]["typeid"] == [0] * 180
assert tri[3]["bonds_N"] == 60 and tri[4]["bonds_N"] == 0
assert "bonds/group" not in tri[1]["chunks"]


def short(o):
    """float32 values as their shortest decimal (which parses back to the same float32)."""
    if isinstance(o, float):
        return float(str(np.float32(o))) if float(np.float32(o)) == o else o
    if isinstance(o, list):
        return [short(x) for x in o]
    if isinstance(o, dict):
        # The cell and origin are float64 products: kept as they are.
        return {k: v if k in ("cell", "origin") else short(v) for k, v in o.items()}
    return o


text = json.dumps(short(ref), separators=(",", ":")).encode()
with open("reference.json.gz", "wb") as fh:
    fh.write(gzip.compress(text, compresslevel=9, mtime=0))
