#!/usr/bin/env python3
"""Point counts and population standard deviations of lidar_12.las's ground points per cell by
PDAL writers.gdal's rule (every point counts in every cell whose centre is at d < R), in numpy on
laspy's reading of the file, on lidar_numpy.txt's lattice: lidar_numpy_stats.txt, which
tests/dem_formats.rs compares with `--lidar-method count` and `stdev`."""
import os
import re
import laspy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
CELL = 10.0
head = open(os.path.join(HERE, "lidar_numpy.txt")).readline()
R, x0, y0, w, h = re.search(
    r"radius ([0-9.e+-]+), lattice x0 ([0-9.e+-]+) y0 ([0-9.e+-]+) \(south-west corner\) (\d+) x (\d+)",
    head).groups()
R, x0, y0, w, h = float(R), float(x0), float(y0), int(w), int(h)
las = laspy.read(os.path.join(HERE, "lidar_12.las"))
keep = (np.asarray(las.classification) == 2) & ~np.asarray(las.withheld, dtype=bool)
x, y, z = (np.asarray(v, dtype=np.float64)[keep] for v in (las.x, las.y, las.z))
with open(os.path.join(HERE, "lidar_numpy_stats.txt"), "w") as f:
    f.write(f"# count and population stdev of the ground points at d < {R!r} (stats_numpy.py)\n")
    f.write("# row col count stdev (row 0 the north)\n")
    for row in range(h):
        cy = y0 + ((h - 1 - row) + 0.5) * CELL
        for col in range(w):
            cx = x0 + (col + 0.5) * CELL
            m = np.sqrt((cx - x) ** 2 + (cy - y) ** 2) < R
            sd = f"{z[m].std():.9f}" if m.any() else "nan"
            f.write(f"{row} {col} {int(m.sum())} {sd}\n")
