#!/usr/bin/env python3
"""Fixtures for photo stretches (tests/photo.rs): a 16-bit and a float32 "satellite" scene and
GDAL's 8-bit renderings of them.

sat_u16.tif: 3 bands UInt16, 240 x 180, UTM 33N, GDAL_NODATA 0: land reflectance x 10000 in
350..2600 per band (smooth fields plus texture), a cloud covering 1.6 % of the scene at
7000..9800 (which leaves the land dark under a min-max stretch), and a no-data wedge in the
corner as a scene's edge has. sat_f32.tif: the same scene as reflectance (float32, / 10000).
sat_percentiles.json: numpy's percentiles of each band over the covered pixels (numpy
percentile, method "lower" for the low end and "higher" for the high one), read from the
arrays written, independently of any TIFF reader. sat_*_gdal.tif: gdal_translate -ot Byte
-scale_N LO HI 0 255 [-exponent E] with those percentiles, i.e. GDAL's mapping of the samples
to 8 bits, which ours must match. sat_u16.vrt: gdalbuildvrt of sat_u16.tif; sat_u16_crop.png:
its window (40, 40, 160 x 120) as a 16-bit PNG, with numpy's percentiles of that window.
sat_dem.tif: an int16 ramp under the scene, for databases.
"""
import json, os, subprocess
import numpy as np

os.chdir(os.path.dirname(os.path.abspath(__file__)))
W, H = 240, 180
y, x = np.mgrid[0:H, 0:W].astype(np.float64)
rng = np.random.default_rng(7)
bands = []
for k, (base, amp) in enumerate([(600, 500), (800, 700), (700, 1300)]):
    field = base + amp * (0.5 + 0.5 * np.sin(x / (23 + 7 * k)) * np.cos(y / (31 - 5 * k)))
    field += rng.normal(0, 60, size=(H, W))
    bands.append(np.clip(field, 350, 2600))
cloud = ((x - 170) / 18) ** 2 + ((y - 50) / 12) ** 2 < 1
for k in range(3):
    bands[k][cloud] = 7000 + 2800 * rng.random(cloud.sum())
wedge = x + y < 30
u16 = np.stack([np.round(b).astype(np.uint16) for b in bands])
u16[:, wedge] = 0
f32 = (u16.astype(np.float32) / 10000).astype(np.float32)


def geotiff(arr, name, dtype):
    raw = name + ".bsq"
    arr.tofile(raw)
    with open(name + ".hdr", "w") as f:
        f.write(f"ENVI\nsamples = {W}\nlines = {H}\nbands = 3\nheader offset = 0\n"
                f"file type = ENVI Standard\ndata type = {dtype}\ninterleave = bsq\nbyte order = 0\n")
    subprocess.run(["gdal_translate", "-q", "-of", "GTiff", "-co", "COMPRESS=DEFLATE",
                    "-a_srs", "EPSG:32633", "-a_ullr", "500000", "4650000", str(500000 + 20 * W),
                    str(4650000 - 20 * H), "-a_nodata", "0", raw, name + ".tif"], check=True)
    os.remove(raw)
    os.remove(name + ".hdr")


geotiff(u16, "sat_u16", 12)
geotiff(f32, "sat_f32", 4)

covered = ~wedge
pct = {}
for name, arr in [("sat_u16", u16), ("sat_f32", f32)]:
    for lo, hi in [(2, 98), (1, 99)]:
        pct[f"{name} {lo},{hi}"] = [
            [float(np.percentile(arr[k][covered], lo, method="lower")),
             float(np.percentile(arr[k][covered], hi, method="higher"))] for k in range(3)]
crop = u16[:, 40:160, 40:200]
pct["sat_u16_crop.png 2,98"] = [
    [float(np.percentile(crop[k], 2, method="lower")),
     float(np.percentile(crop[k], 98, method="higher"))] for k in range(3)]
pct["sat_u16 minmax"] = [[float(u16[k][covered].min()), float(u16[k][covered].max())] for k in range(3)]
with open("sat_percentiles.json", "w") as f:
    json.dump(pct, f, indent=1)


def scaled(src, ranges, out, exponent=None):
    cmd = ["gdal_translate", "-q", "-ot", "Byte", "-a_nodata", "none", "-co", "COMPRESS=DEFLATE"]
    for k, (lo, hi) in enumerate(ranges):
        cmd += [f"-scale_{k + 1}", repr(lo), repr(hi), "0", "255"]
    if exponent is not None:
        for k in range(3):
            cmd += [f"-exponent_{k + 1}", repr(exponent)]
    subprocess.run(cmd + [src, out], check=True)


scaled("sat_u16.tif", pct["sat_u16 2,98"], "sat_u16_p2_98_gdal.tif")
scaled("sat_u16.tif", pct["sat_u16 1,99"], "sat_u16_p1_99_gamma2_gdal.tif", exponent=0.5)
scaled("sat_u16.tif", [(0, 3000)] * 3, "sat_u16_range_gdal.tif")
scaled("sat_f32.tif", pct["sat_f32 2,98"], "sat_f32_p2_98_gdal.tif")
# A DEM under the scene (int16 ramp, 61 x 46 samples at 80 m), for databases built with it.
dem = (200 + 2 * np.mgrid[0:46, 0:61][1] + 3 * np.mgrid[0:46, 0:61][0]).astype(np.int16)
dem.tofile("sat_dem.bsq")
with open("sat_dem.hdr", "w") as f:
    f.write("ENVI\nsamples = 61\nlines = 46\nbands = 1\nheader offset = 0\n"
            "file type = ENVI Standard\ndata type = 2\ninterleave = bsq\nbyte order = 0\n")
subprocess.run(["gdal_translate", "-q", "-of", "GTiff", "-a_srs", "EPSG:32633", "-a_ullr", "500000",
                "4650000", "504880", "4646320", "sat_dem.bsq", "sat_dem.tif"], check=True)
os.remove("sat_dem.bsq")
os.remove("sat_dem.hdr")
# The same scene through a VRT, and a window of it as a 16-bit PNG (no no-data in it).
subprocess.run(["gdalbuildvrt", "-q", "sat_u16.vrt", "sat_u16.tif"], check=True)
subprocess.run(["gdal_translate", "-q", "-of", "PNG", "-srcwin", "40", "40", "160", "120",
                "sat_u16.tif", "sat_u16_crop.png"], check=True)
for f in os.listdir("."):
    if f.endswith(".aux.xml"):
        os.remove(f)
