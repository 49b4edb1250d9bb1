"""Decode a quantized-mesh-1.0 terrain directory with an independent reader, the
quantized-mesh-tile package (geoadmin, `pip install quantized-mesh-tile`), for
crates/terrain/tests/qmesh.rs.

Usage: python3 qmesh_decode.py DIR > decoded.txt

Tiles may be gzip-compressed (told by their first two bytes). For every tile that
DIR/layer.json lists as available, in level, x, y order:
  tile Z X Y WEST SOUTH EAST NORTH N_VERTICES N_TRIANGLES MIN_H MAX_H
  v LON LAT H                       (one line per vertex, in file order)
  t A B C                           (one line per triangle, decoded indices)
  edges W S E N                     (the four edge-vertex lists, comma-separated)
  sphere CX CY CZ R                 (the header's bounding sphere)
  n X Y Z                           (one line per vertex: the decoded oct-encoded normal)
"""
import json
import os
import sys

from quantized_mesh_tile.global_geodetic import GlobalGeodetic
from quantized_mesh_tile.terrain import TerrainTile

root = sys.argv[1]
layer = json.load(open(os.path.join(root, "layer.json")))
assert layer["format"] == "quantized-mesh-1.0" and layer["scheme"] == "tms"
geodetic = GlobalGeodetic(True)
out = sys.stdout
for z, ranges in enumerate(layer["available"]):
    for r in ranges:
        for x in range(r["startX"], r["endX"] + 1):
            for y in range(r["startY"], r["endY"] + 1):
                w, s, e, n = geodetic.TileBounds(x, y, z)
                t = TerrainTile(west=w, south=s, east=e, north=n)
                path = os.path.join(root, str(z), str(x), "%d.terrain" % y)
                with open(path, "rb") as f:
                    gzipped = f.read(2) == b"\x1f\x8b"
                t.fromFile(path, hasLighting=True, gzipped=gzipped)
                verts = t.getVerticesCoordinates()
                h = t.header
                out.write("tile %d %d %d %.12f %.12f %.12f %.12f %d %d %.9g %.9g\n" % (
                    z, x, y, w, s, e, n, len(verts), len(t.indices) // 3,
                    h["minimumHeight"], h["maximumHeight"]))
                for lon, lat, hh in verts:
                    out.write("v %.12f %.12f %.6f\n" % (lon, lat, hh))
                for k in range(0, len(t.indices), 3):
                    out.write("t %d %d %d\n" % tuple(t.indices[k:k + 3]))
                out.write("edges %s %s %s %s\n" % tuple(
                    ",".join(map(str, l)) or "-" for l in (t.westI, t.southI, t.eastI, t.northI)))
                out.write("sphere %.6f %.6f %.6f %.6f\n" % (
                    h["boundingSphereCenterX"], h["boundingSphereCenterY"],
                    h["boundingSphereCenterZ"], h["boundingSphereRadius"]))
                assert len(t.vLight) == len(verts)
                for nx, ny, nz in t.vLight:
                    out.write("n %.6f %.6f %.6f\n" % (nx, ny, nz))
