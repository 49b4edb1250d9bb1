#!/usr/bin/env python3
"""Writes the model fixtures of crates/terrain/tests/models.rs (standard library only):

- box.obj / box.mtl / box.png: a unit cube (x, z in [-0.5, 0.5], y in [0, 1]) with one texture
  square per face, counter-clockwise from outside; box.png is 64 x 64 sRGB RGBA, four coloured
  quadrants with a darker 8-texel grid, so a wrong uv or a flipped v shows.
- broken.obj: a face referring to a vertex that does not exist.
- notex.gltf: one triangle, no texture (drawn with the flat colour).

Run from this directory: python3 make_models.py
"""
import base64, struct, zlib

def png(path, w, h, pixel):
    raw = b"".join(b"\x00" + b"".join(bytes(pixel(x, y)) for x in range(w)) for y in range(h))
    def chunk(t, d):
        c = struct.pack(">I", len(d)) + t + d
        return c + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
    data += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    open(path, "wb").write(data)

def texel(x, y):
    quad = [(200, 60, 50), (60, 170, 70), (60, 90, 200), (220, 200, 60)][(x >= 32) + 2 * (y >= 32)]
    if x % 8 == 0 or y % 8 == 0:
        quad = tuple(c // 2 for c in quad)
    return quad + (255,)

png("box.png", 64, 64, texel)
open("box.mtl", "w").write("newmtl skin\nKd 1 1 1\nmap_Kd box.png\n")

# Cube corners, then per face four vertices with uvs (OBJ v up).
faces = [  # (corner indices counter-clockwise seen from outside)
    [(-1, 0, 1), (1, 0, 1), (1, 1, 1), (-1, 1, 1)],      # +z (south)
    [(1, 0, -1), (-1, 0, -1), (-1, 1, -1), (1, 1, -1)],  # -z (north)
    [(1, 0, 1), (1, 0, -1), (1, 1, -1), (1, 1, 1)],      # +x
    [(-1, 0, -1), (-1, 0, 1), (-1, 1, 1), (-1, 1, -1)],  # -x
    [(-1, 1, 1), (1, 1, 1), (1, 1, -1), (-1, 1, -1)],    # top
    [(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)],    # bottom
]
lines = ["# unit textured box, made by make_models.py", "mtllib box.mtl", "o box"]
vt = [(0, 0), (1, 0), (1, 1), (0, 1)]
for f in faces:
    for (x, y, z) in f:
        lines.append(f"v {0.5 * x} {y} {0.5 * z}")
for (u, v) in vt:
    lines.append(f"vt {u} {v}")
lines.append("usemtl skin")
for i in range(len(faces)):
    b = 4 * i + 1
    lines.append(f"f {b}/1 {b + 1}/2 {b + 2}/3 {b + 3}/4")
open("box.obj", "w").write("\n".join(lines) + "\n")

open("broken.obj", "w").write("# face refers to vertex 9 of 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")

buf = b"".join(struct.pack("<3f", *p) for p in [(0, 0, 0), (1, 0, 0), (0, 1, 0)])
gltf = ('{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],'
        '"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],'
        '"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,'
        + base64.b64encode(buf).decode() + '"}],'
        '"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36}],'
        '"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",'
        '"min":[0,0,0],"max":[1,1,0]}]}\n')
open("notex.gltf", "w").write(gltf)
