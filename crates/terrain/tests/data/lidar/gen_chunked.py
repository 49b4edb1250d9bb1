#!/usr/bin/env python3
"""Multi-chunk LAZ fixtures for the parallel LAZ decoding (crates/terrain/tests/dem_formats.rs).

LASzip (laspy's laszip backend, the C++ library) cuts its compressed points into chunks of 50,000;
the fixtures of gen_lidar.py hold one chunk each. These hold 110,017 points (3 chunks, the last
partial) of a regular 2 m survey over 332 x 662 m with a smooth relief and every 13th point
vegetation (class 5):

- lidar_chunked_12.laz: LAS 1.2, point format 1 (point-wise chunked compression).
- lidar_chunked_14.laz: LAS 1.4, point format 6 (layered chunked compression).
- lidar_chunked_laspy.json: laspy's reading of each (as gen_lidar.py's describe: header, first and
  last points, sums of the raw integers, class counts) plus every 997th point and the chunk
  table's point counts (lazrs), with both LAZ backends agreeing.

Rerun: python3 gen_chunked.py (laspy, lazrs, laszip, numpy).
"""

import datetime
import json
import os

import laspy
import lazrs
import numpy as np

from gen_lidar import describe, geokeys_vlr

HERE = os.path.dirname(os.path.abspath(__file__))
N = 110_017


def make(version, fmt):
    i = np.arange(N)
    x = 316000.0 + (i % 166) * 2.0
    y = 4904000.0 + (i // 166) * 2.0
    z = 1800.0 + 30.0 * np.sin(x / 97.0) * np.cos(y / 131.0) + (i * 7919 % 101) * 0.01
    veg = i % 13 == 0
    header = laspy.LasHeader(point_format=fmt, version=version)
    header.scales = np.array([0.01, 0.01, 0.01])
    header.offsets = np.array([316000.0, 4904000.0, 0.0])
    header.creation_date = datetime.date(2024, 6, 11)
    header.vlrs.append(geokeys_vlr())
    las = laspy.LasData(header)
    las.x, las.y = x, y
    las.z = np.where(veg, z + 12.5, z)
    las.classification = np.where(veg, 5, 2).astype(np.uint8)
    las.return_number = np.ones(N, np.uint8)
    las.number_of_returns = np.where(veg, 2, 1).astype(np.uint8)
    las.gps_time = 400000.0 + i * 1e-4
    las.intensity = (i * 37 % 4000).astype(np.uint16)
    return las


def main():
    ref = {}
    for name, version, fmt in [("lidar_chunked_12.laz", "1.2", 1), ("lidar_chunked_14.laz", "1.4", 6)]:
        path = os.path.join(HERE, name)
        make(version, fmt).write(path, laz_backend=laspy.LazBackend.Laszip)
        d = describe(path)
        assert describe(path, laspy.LazBackend.Lazrs) == d
        las = laspy.read(path)
        d["samples"] = [[k, float(las.x[k]), float(las.y[k]), float(las.z[k]),
                         int(las.classification[k])] for k in range(0, N, 997)]
        with open(path, "rb") as f:
            raw = f.read()
            at = raw.index(b"laszip encoded") - 2  # the VLR header: reserved, user id, ...
            size = int.from_bytes(raw[at + 20:at + 22], "little")
            vlr = lazrs.LazVlr(raw[at + 54:at + 54 + size])
            f.seek(int.from_bytes(raw[96:100], "little"))  # offset to point data
            table = lazrs.read_chunk_table(f, vlr)
        d["chunk_points"] = [int(c[0]) for c in table]
        ref[name] = d
    with open(os.path.join(HERE, "lidar_chunked_laspy.json"), "w") as f:
        json.dump(ref, f, indent=1, sort_keys=True)
        f.write("\n")


if __name__ == "__main__":
    main()
