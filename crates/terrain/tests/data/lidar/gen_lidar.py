#!/usr/bin/env python3
"""Lidar fixtures for crates/terrain/tests/dem_formats.rs (the `lidar_*` tests) and the fuzz campaign.

A synthetic airborne survey over 300 x 240 m of the real SRTM terrain around Mount Washington
(`../hillshade_dem_utm.tif`, UTM 19N, heights 1,800-1,900 m), written by laspy and LASzip, and
gridded by GDAL's gdal_grid and by numpy as references:

- 1,800 ground points (class 2, last returns) on the DEM (bilinear between its 90 m samples, plus
  5 cm of noise), none inside a 40 x 30 m building or a pond of 22 m radius, and 3 more exactly on
  the centres of 10 m cells (PDAL's idw takes their height; their diagonal neighbours' centres are
  exactly 10 * sqrt(2) = R away, where PDAL's `d < R` leaves them out and gdal_grid's `<=` counts
  them); vegetation (classes 3, 4, 5: first of two returns, 0.2-25 m above the ground), roofs
  (class 6), the pond's water (class 9), unclassified points (class 1), noise (class 7 below and
  class 18 above the ground) and 5 withheld ground points 40 m up; shuffled.
- lidar_12.las: LAS 1.2, point format 1, a GeoKey directory (ProjectedCSTypeGeoKey 32619).
- lidar_14.las: LAS 1.4, point format 6, OGC WKT 1 of EPSG:32619 in a VLR (global encoding bit 4).
- lidar_12.laz, lidar_14.laz: the same compressed by LASzip (laspy's laszip backend: the C++
  LASzip, not the Rust port texmap reads with); lidar_14.laz carries WKT 2 in an EVLR instead.
- lidar_laspy.json: laspy's reading of each file (header, first and last points, sums of the raw
  X, Y, Z integers, class counts, withheld and last-return counts, the CRS by pyproj), read with
  both LAZ backends for the .laz files (they must agree).
- lidar_gdal_{average,minimum,maximum,invdist}.asc: gdal_grid of the ground points (class 2, not
  withheld: the default choice) on the 10 m lattice of the points (30 x 24 cells; -txe/-tye the
  lattice's edges, so GDAL's nodes are the cell centres), radius1 = radius2 = 10 * sqrt(2),
  invdist with power 1 (PDAL's default), written by gdal_translate as ESRI ASCII grids with 6
  decimals, no-data -9999.
- lidar_numpy.txt: the same cells by PDAL writers.gdal's rule (`d < R`) in numpy: count, mean,
  min, max, idw, the mean window-filled with window_size 2, and whether a point lies within 1e-9 m
  of R of the centre (where GDAL's rule differs).

Versions: see lidar_versions.txt (written by this script). Rerun: python3 gen_lidar.py (needs
`pip install laspy lazrs laszip pyproj numpy` and gdal-bin).
"""

import datetime
import json
import math
import os
import subprocess
import tempfile

import laspy
import laspy.vlrs.vlrlist
import numpy as np
import pyproj

HERE = os.path.dirname(os.path.abspath(__file__))
DEM = os.path.join(HERE, "..", "hillshade_dem_utm.tif")
CELL = 10.0
R = CELL * math.sqrt(2.0)
X0, X1, Y0, Y1 = 316000.0, 316300.0, 4904200.0, 4904440.0
BUILDING = (316080.0, 316120.0, 4904300.0, 4904330.0)
POND = (316230.0, 4904260.0, 22.0)


def run(*args):
    subprocess.run(args, check=True)


def read_dem(work):
    asc = os.path.join(work, "dem.asc")
    run("gdal_translate", "-q", "-of", "AAIGrid", DEM, asc)
    head = {}
    with open(asc) as f:
        for _ in range(6):
            k, v = f.readline().split()
            head[k.lower()] = float(v)
    z = np.loadtxt(asc, skiprows=6)
    return head, z


def bilinear(head, z, x, y):
    c = (x - head["xllcorner"]) / head["cellsize"] - 0.5
    r = (head["yllcorner"] + head["nrows"] * head["cellsize"] - y) / head["cellsize"] - 0.5
    c0, r0 = np.floor(c).astype(int), np.floor(r).astype(int)
    fc, fr = c - c0, r - r0
    return (
        z[r0, c0] * (1 - fc) * (1 - fr)
        + z[r0, c0 + 1] * fc * (1 - fr)
        + z[r0 + 1, c0] * (1 - fc) * fr
        + z[r0 + 1, c0 + 1] * fc * fr
    )


def survey(head, z):
    rng = np.random.default_rng(20240611)
    q = lambda v: np.round(v, 2)  # the files' 0.01 m scale

    def uniform(n):
        return q(rng.uniform(X0, X1 - 0.01, n)), q(rng.uniform(Y0, Y1 - 0.01, n))

    def outside(x, y):
        bx0, bx1, by0, by1 = BUILDING
        in_b = (x >= bx0) & (x <= bx1) & (y >= by0) & (y <= by1)
        in_p = (x - POND[0]) ** 2 + (y - POND[1]) ** 2 <= POND[2] ** 2
        return ~(in_b | in_p)

    parts = []  # (x, y, z, class, return, returns, withheld)

    def add(x, y, zz, cls, ret, nret, withheld=False):
        n = len(x)
        parts.append((x, y, q(zz), np.full(n, cls), np.broadcast_to(ret, n), np.broadcast_to(nret, n),
                      np.full(n, withheld)))

    x, y = uniform(2600)
    keep = outside(x, y)
    x, y = x[keep][:1800], y[keep][:1800]
    ground = bilinear(head, z, x, y) + rng.normal(0, 0.05, len(x))
    nret = np.where(rng.uniform(size=len(x)) < 0.7, 1, 2)
    add(x, y, ground, 2, nret, nret)
    cx = np.array([316055.0, 316155.0, 316205.0])
    cy = np.array([4904255.0, 4904385.0, 4904215.0])
    add(cx, cy, bilinear(head, z, cx, cy), 2, 1, 1)
    for cls, lo, hi, n in [(3, 0.2, 1.0, 150), (4, 1.0, 5.0, 150), (5, 5.0, 25.0, 150)]:
        x, y = uniform(n)
        add(x, y, bilinear(head, z, x, y) + rng.uniform(lo, hi, n), cls, 1, 2)
    bx0, bx1, by0, by1 = BUILDING
    x, y = q(rng.uniform(bx0, bx1, 60)), q(rng.uniform(by0, by1, 60))
    add(x, y, bilinear(head, z, x, y) + 8.0, 6, 1, 1)
    a, rr = rng.uniform(0, 2 * math.pi, 40), POND[2] * np.sqrt(rng.uniform(0, 1, 40)) * 0.95
    x, y = q(POND[0] + rr * np.cos(a)), q(POND[1] + rr * np.sin(a))
    level = float(bilinear(head, z, np.array([POND[0]]), np.array([POND[1]]))[0]) - 1.0
    add(x, y, np.full(40, level), 9, 1, 1)
    x, y = uniform(60)
    add(x, y, bilinear(head, z, x, y) + rng.uniform(0, 2, 60), 1, 1, 1)
    x, y = uniform(12)
    add(x, y, bilinear(head, z, x, y) - rng.uniform(20, 40, 12), 7, 1, 1)
    x, y = uniform(6)
    add(x, y, bilinear(head, z, x, y) + rng.uniform(60, 100, 6), 18, 1, 1)
    x, y = uniform(5)
    add(x, y, bilinear(head, z, x, y) + 40.0, 2, 1, 1, withheld=True)

    cols = [np.concatenate([p[k] for p in parts]) for k in range(7)]
    order = rng.permutation(len(cols[0]))
    return [c[order] for c in cols]


def geokeys_vlr():
    # GeoKey directory: version 1.1.0, 4 keys: GTModelType 1 (projected), GTRasterType 1
    # (PixelIsArea), ProjectedCSType 32619, ProjLinearUnits 9001 (metre).
    keys = [1, 1, 0, 4, 1024, 0, 1, 1, 1025, 0, 1, 1, 3072, 0, 1, 32619, 3076, 0, 1, 9001]
    return laspy.VLR("LASF_Projection", 34735, "GeoKeyDirectoryTag",
                     np.array(keys, dtype="<u2").tobytes())


def wkt_vlr(wkt):
    return laspy.VLR("LASF_Projection", 2112, "OGC WKT", wkt.encode() + b"\0")


def make(points, version, fmt, crs_record, evlr=False):
    x, y, zz, cls, ret, nret, withheld = points
    header = laspy.LasHeader(point_format=fmt, version=version)
    header.scales = np.array([0.01, 0.01, 0.01])
    header.offsets = np.array([316000.0, 4904000.0, 0.0])
    header.creation_date = datetime.date(2024, 6, 11)  # reruns write the same bytes
    if version == "1.4":
        header.global_encoding.wkt = True
    if not evlr:
        header.vlrs.append(crs_record)
    las = laspy.LasData(header)
    las.x, las.y, las.z = x, y, zz
    las.classification = cls
    las.return_number = ret
    las.number_of_returns = nret
    las.withheld = withheld
    las.gps_time = 400000.0 + np.arange(len(x)) * 1e-4
    las.intensity = (np.arange(len(x)) * 37 % 4000).astype(np.uint16)
    if evlr:
        las.evlrs = laspy.vlrs.vlrlist.VLRList([crs_record])
    return las


def describe(path, backend=None):
    kw = {} if backend is None else {"laz_backend": backend}
    with laspy.open(path, **kw) as f:
        las = f.read()
    h = las.header
    crs = h.parse_crs()

    def point(i):
        return {
            "x": float(las.x[i]), "y": float(las.y[i]), "z": float(las.z[i]),
            "class": int(las.classification[i]), "return_number": int(las.return_number[i]),
            "number_of_returns": int(las.number_of_returns[i]),
            "withheld": bool(las.withheld[i]),
        }

    classes = np.bincount(np.asarray(las.classification), minlength=256)
    last = (np.asarray(las.return_number) >= np.asarray(las.number_of_returns)) | (
        np.asarray(las.number_of_returns) == 0)
    return {
        "version": str(h.version), "point_format": int(h.point_format.id),
        "compressed": bool(h.are_points_compressed) if hasattr(h, "are_points_compressed") else path.endswith(".laz"),
        "point_count": int(h.point_count),
        "scales": [float(v) for v in h.scales], "offsets": [float(v) for v in h.offsets],
        "mins": [float(v) for v in h.mins], "maxs": [float(v) for v in h.maxs],
        "first": point(0), "last": point(len(las.x) - 1),
        "sum_X": int(np.asarray(las.X, dtype=np.int64).sum()),
        "sum_Y": int(np.asarray(las.Y, dtype=np.int64).sum()),
        "sum_Z": int(np.asarray(las.Z, dtype=np.int64).sum()),
        "classes": {str(c): int(n) for c, n in enumerate(classes) if n},
        "withheld": int(np.asarray(las.withheld).sum()),
        "last_returns": int(last.sum()),
        "epsg": crs.to_epsg() if crs is not None else None,
    }


def write_asc_reference(work, pts, name, algorithm, lattice):
    x0, y0, w, h = lattice
    csv = os.path.join(work, "ground.csv")
    vrt = os.path.join(work, "ground.vrt")
    if not os.path.exists(csv):
        with open(csv, "w") as f:
            f.write("x,y,z\n")
            for px, py, pz in zip(*pts):
                f.write(f"{float(px)!r},{float(py)!r},{float(pz)!r}\n")
        with open(vrt, "w") as f:
            f.write('<OGRVRTDataSource><OGRVRTLayer name="ground"><SrcDataSource>' + csv +
                    '</SrcDataSource><GeometryType>wkbPoint</GeometryType>'
                    '<GeometryField encoding="PointFromColumns" x="x" y="y" z="z"/>'
                    '</OGRVRTLayer></OGRVRTDataSource>')
    tif = os.path.join(work, name + ".tif")
    run("gdal_grid", "-q", "-a", algorithm, "-txe", repr(x0), repr(x0 + w * CELL),
        "-tye", repr(y0), repr(y0 + h * CELL), "-outsize", str(w), str(h), "-ot", "Float64",
        "-of", "GTiff", "-l", "ground", vrt, tif)
    run("gdal_translate", "-q", "-of", "AAIGrid", "-co", "DECIMAL_PRECISION=6", tif,
        os.path.join(HERE, name + ".asc"))


def pdal_rule(pts, lattice):
    """PDAL writers.gdal (io/private/GDALGrid.cpp) in numpy: every point counts in every cell
    whose centre is at d < R; idw with power 1, a point at d == 0 (the first in file order)
    giving its height; window_size 2 fill of the mean."""
    x, y, zz = pts
    x0, y0, w, h = lattice
    rows = []
    mean = np.full((h, w), np.nan)
    count = np.zeros((h, w), dtype=int)
    for row in range(h):
        cy = y0 + ((h - 1 - row) + 0.5) * CELL
        for col in range(w):
            cx = x0 + (col + 0.5) * CELL
            d = np.sqrt((cx - x) ** 2 + (cy - y) ** 2)
            m = d < R
            n = int(m.sum())
            boundary = int(np.any(np.abs(d - R) <= 1e-9))
            if n:
                zs, ds = zz[m], d[m]
                at = np.nonzero(ds == 0)[0]
                idw = zs[at[0]] if len(at) else np.sum(zs / ds) / np.sum(1 / ds)
                vals = [zs.mean(), zs.min(), zs.max(), idw]
                mean[row, col] = vals[0]
            else:
                vals = [np.nan] * 4
            count[row, col] = n
            rows.append([row, col, n] + vals + [boundary])
    # window_size 2: PDAL's order, columns west to east, each from south to north.
    fill = mean.copy()
    for row in range(h):
        for col in range(w):
            if count[row, col]:
                continue
            s = ws = 0.0
            for c in range(max(col - 2, 0), min(col + 2, w - 1) + 1):
                for r in range(min(row + 2, h - 1), max(row - 2, 0) - 1, -1):
                    if count[r, c] == 0:
                        continue
                    dd = float(max(abs(c - col), abs(r - row)))
                    s += mean[r, c] / dd
                    ws += 1 / dd
            fill[row, col] = s / ws if ws > 0 else np.nan
    with open(os.path.join(HERE, "lidar_numpy.txt"), "w") as f:
        f.write("# PDAL writers.gdal's rule in numpy (gen_lidar.py): cell size 10, radius "
                f"{R!r}, lattice x0 {x0!r} y0 {y0!r} (south-west corner) {w} x {h}\n")
        f.write("# row col count mean min max idw fill2 boundary (row 0 the north)\n")
        for r in rows:
            row, col = r[0], r[1]
            vals = " ".join("nan" if np.isnan(v) else f"{v:.9f}" for v in r[3:7])
            fv = fill[row, col]
            f.write(f"{row} {col} {r[2]} {vals} {'nan' if np.isnan(fv) else f'{fv:.9f}'} {r[7]}\n")


def main():
    work = tempfile.mkdtemp()
    head, z = read_dem(work)
    points = survey(head, z)
    wkt1 = pyproj.CRS.from_epsg(32619).to_wkt(pyproj.enums.WktVersion.WKT1_GDAL)
    wkt2 = pyproj.CRS.from_epsg(32619).to_wkt()
    files = {
        "lidar_12.las": make(points, "1.2", 1, geokeys_vlr()),
        "lidar_14.las": make(points, "1.4", 6, wkt_vlr(wkt1)),
        "lidar_12.laz": make(points, "1.2", 1, geokeys_vlr()),
        "lidar_14.laz": make(points, "1.4", 6, wkt_vlr(wkt2), evlr=True),
    }
    for name, las in files.items():
        path = os.path.join(HERE, name)
        if name.endswith(".laz"):
            las.write(path, laz_backend=laspy.LazBackend.Laszip)
        else:
            las.write(path)
    ref = {}
    for name in files:
        path = os.path.join(HERE, name)
        ref[name] = describe(path)
        if name.endswith(".laz"):
            for backend in (laspy.LazBackend.Lazrs, laspy.LazBackend.Laszip):
                other = describe(path, backend)
                assert other == ref[name], (name, backend)
    with open(os.path.join(HERE, "lidar_laspy.json"), "w") as f:
        json.dump(ref, f, indent=1, sort_keys=True)
        f.write("\n")

    # The default choice: ground (class 2), not withheld.
    x, y, zz, cls, _, _, withheld = points
    m = (cls == 2) & ~withheld
    pts = (x[m], y[m], zz[m])
    kx0, kx1 = math.floor(pts[0].min() / CELL), math.floor(pts[0].max() / CELL)
    ky0, ky1 = math.floor(pts[1].min() / CELL), math.floor(pts[1].max() / CELL)
    lattice = (kx0 * CELL, ky0 * CELL, kx1 - kx0 + 1, ky1 - ky0 + 1)
    r = repr(R)
    for name, algorithm in [
        ("lidar_gdal_average", f"average:radius1={r}:radius2={r}:angle=0:min_points=1:nodata=-9999"),
        ("lidar_gdal_minimum", f"minimum:radius1={r}:radius2={r}:angle=0:min_points=1:nodata=-9999"),
        ("lidar_gdal_maximum", f"maximum:radius1={r}:radius2={r}:angle=0:min_points=1:nodata=-9999"),
        ("lidar_gdal_invdist", f"invdist:power=1:smoothing=0:radius1={r}:radius2={r}:angle=0:"
                               "max_points=0:min_points=1:nodata=-9999"),
    ]:
        write_asc_reference(work, pts, name, algorithm, lattice)
    for f in os.listdir(HERE):
        if f.endswith(".prj") or f.endswith(".aux.xml"):
            os.remove(os.path.join(HERE, f))
    pdal_rule(pts, lattice)

    import laszip
    import lazrs  # noqa: F401
    gdal = subprocess.run(["gdal_grid", "--version"], capture_output=True, text=True).stdout.strip()
    with open(os.path.join(HERE, "lidar_versions.txt"), "w") as f:
        f.write(f"laspy {laspy.__version__}\n")
        f.write(f"laszip (python bindings) {__import__('importlib.metadata').metadata.version('laszip')}, "
                f"LASzip {laszip.get_version()}\n")
        f.write(f"lazrs {__import__('importlib.metadata').metadata.version('lazrs')}\n")
        f.write(f"pyproj {pyproj.__version__} (PROJ {pyproj.proj_version_str})\n")
        f.write(f"numpy {np.__version__}\n")
        f.write(f"{gdal}\n")


if __name__ == "__main__":
    main()
