"""A glider's flight over the Mount Washington grid (hillshade_dem_utm.tif), written by other
programs for tests/track.rs, with their own readers' readings of what they wrote.

A glide north-east along the grid, two thermalling circles of 300 m at 24 m/s (one a second, the
fixes at whole seconds), a glide out past the grid's east edge; 280 fixes from 2023-07-15
14:58:30 UTC, climbing from 1,950 m. Written as
  track_gpxpy.gpx     GPX 1.1 by gpxpy
  track_ogr.gpx       GPX 1.1 by GDAL's GPX driver (ogr2ogr from a CSV of the fixes)
  track_aerofiles.igc an IGC file by aerofiles' igc.Writer (thousandths of minutes, whole metres)
and track_reference.txt: each file's fixes as gpxpy / aerofiles read them back
(file lat lon altitude unix_time per line). Needs gpxpy, aerofiles and GDAL's ogr2ogr.
Run: python3 track.py (from this directory)."""
import datetime as dt
import math
import os
import subprocess

import aerofiles.igc
import gpxpy
import gpxpy.gpx

here = os.path.dirname(os.path.abspath(__file__))
t0 = dt.datetime(2023, 7, 15, 14, 58, 30, tzinfo=dt.timezone.utc)
# Local tangent plane around the grid's south-west quarter: metres to degrees.
lat0, lon0 = 44.255, -71.29
m_lat = 111_132.92 - 559.82 * math.cos(2 * math.radians(lat0))
m_lon = 111_412.84 * math.cos(math.radians(lat0))

fixes = []
x, y, alt, heading = 0.0, 0.0, 1950.0, 50.0
v, r = 24.0, 300.0
for i in range(280):
    fixes.append((lat0 + y / m_lat, lon0 + x / m_lon, alt, t0 + dt.timedelta(seconds=i)))
    if 40 <= i < 40 + 2 * round(2 * math.pi * r / v):  # two circles, turning right
        heading += math.degrees(v / r)
        alt += 1.5
    else:
        alt -= 0.8
    x += v * math.sin(math.radians(heading))
    y += v * math.cos(math.radians(heading))

g = gpxpy.gpx.GPX()
trk = gpxpy.gpx.GPXTrack(name="glider")
seg = gpxpy.gpx.GPXTrackSegment()
for lat, lon, a, t in fixes:
    seg.points.append(gpxpy.gpx.GPXTrackPoint(round(lat, 7), round(lon, 7), elevation=round(a, 1), time=t))
trk.segments.append(seg)
g.tracks.append(trk)
with open(os.path.join(here, "track_gpxpy.gpx"), "w") as f:
    f.write(g.to_xml(version="1.1"))

import tempfile
csv = os.path.join(tempfile.mkdtemp(), "track_ogr.csv")
with open(csv, "w") as f:
    f.write("track_fid,track_seg_id,ele,time,lon,lat\n")
    for lat, lon, a, t in fixes:
        f.write(f"0,0,{a:.1f},{t.strftime('%Y/%m/%d %H:%M:%S+00')},{lon:.7f},{lat:.7f}\n")
out = os.path.join(here, "track_ogr.gpx")
if os.path.exists(out):
    os.remove(out)
subprocess.run(["ogr2ogr", "-f", "GPX", out, csv,
                "-oo", "X_POSSIBLE_NAMES=lon", "-oo", "Y_POSSIBLE_NAMES=lat", "-oo", "KEEP_GEOM_COLUMNS=NO",
                "-oo", "AUTODETECT_TYPE=YES", "-nln", "track_points"], check=True)

with open(os.path.join(here, "track_aerofiles.igc"), "wb") as f:
    w = aerofiles.igc.Writer(f)
    w.write_logger_id("XXX", "ABC", "TEXMAP")
    w.write_date(t0.date())
    w.write_pilot("Test Pilot")
    for lat, lon, a, t in fixes:
        w.write_fix(t.time(), latitude=lat, longitude=lon, valid=True,
                    pressure_alt=round(a) - 30, gps_alt=round(a))

with open(os.path.join(here, "track_reference.txt"), "w") as f:
    f.write("# file lat lon altitude unix_time, as gpxpy and aerofiles read the files back\n")
    for name in ["track_gpxpy.gpx", "track_ogr.gpx"]:
        with open(os.path.join(here, name)) as g2:
            gpx = gpxpy.parse(g2)
        for p in gpx.tracks[0].segments[0].points:
            f.write(f"{name} {p.latitude!r} {p.longitude!r} {p.elevation!r} {p.time.timestamp()!r}\n")
    with open(os.path.join(here, "track_aerofiles.igc")) as g3:
        rec = aerofiles.igc.Reader().read(g3)
    date = rec["header"][1]["utc_date"]
    for fx in rec["fix_records"][1]:
        t = dt.datetime.combine(date, fx["time"]).replace(tzinfo=dt.timezone.utc)
        f.write(f"track_aerofiles.igc {fx['lat']!r} {fx['lon']!r} {float(fx['gps_alt'])!r} {t.timestamp()!r}\n")
