#!/bin/sh
# Viewsheds written by GDAL 3.6.2's gdal_viewshed (Debian gdal-bin; `gdalinfo --version` is
# recorded in gdal_version.txt), for tests/srtm.rs to compare texmap's viewsheds with, cell by
# cell. Rerun to regenerate (needs gdalwarp, gdal_translate, gdal_viewshed).
#
# DEMs, both cut from the real SRTM tile ../N44W072.hgt (the White Mountains, Mount Washington):
#   dem_utm.tif  the tile warped to UTM 19N (EPSG:32619) at 90 m, 192 x 160, float32 (bilinear):
#                gdal_viewshed wants a projected grid (its distances are the grid's units)
#   dem_geo.tif  a 160 x 150 window of the tile as it is (3 arc-seconds, EPSG:4326), int16
# Observers are sample centres (no rounding can move them):
#   summit  (101, 65) of dem_utm: 316135 E, 4904505 N, Mount Washington's highest sample
#   notch   (146, 84) of dem_utm: 320185 E, 4902795 N, the floor of Pinkham Notch
#   slope   (40, 100) of dem_geo: 71.3366667 W, 44.25 N, on the Southern Presidentials' flank
# Outputs (Deflate-compressed; all other options gdal_viewshed's defaults: -oz 2 -tz 0
# -cc 0.85714 -vv 255 -iv 0 -ov 0, -om NORMAL):
#   summit.tif              summit, defaults
#   summit_cc0_tz5.tif      summit, -cc 0 (no curvature) -tz 5
#   notch_oz10_md5000.tif   notch, -oz 10 -md 5000 (the output is cut to the range's square)
#   notch_ground_md2500.tif notch, -om GROUND -md 2500 (float64 heights a target needs)
#   geo_slope_cc0.tif       slope on the geographic grid, -cc 0 (on a geographic grid GDAL takes
#                           distances in degrees, so its curvature would vanish: 0 says so)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
hgt="$here/../N44W072.hgt"
cd "$here"
gdalinfo --version > gdal_version.txt
co="-co COMPRESS=DEFLATE"
gdalwarp -q -overwrite -s_srs EPSG:4326 -t_srs EPSG:32619 -tr 90 90 \
  -te 307000 4896000 324280 4910400 -r bilinear -ot Float32 $co -co PREDICTOR=3 \
  "$hgt" dem_utm.tif
gdal_translate -q -srcwin 756 800 160 150 $co -co PREDICTOR=2 "$hgt" dem_geo.tif
vs() { gdal_viewshed -q $co "$@"; }
vs -ox 316135 -oy 4904505 dem_utm.tif summit.tif
vs -cc 0 -tz 5 -ox 316135 -oy 4904505 dem_utm.tif summit_cc0_tz5.tif
vs -oz 10 -md 5000 -ox 320185 -oy 4902795 dem_utm.tif notch_oz10_md5000.tif
vs -om GROUND -md 2500 -co PREDICTOR=3 -ox 320185 -oy 4902795 dem_utm.tif notch_ground_md2500.tif
vs -cc 0 -ox -71.3366667 -oy 44.25 dem_geo.tif geo_slope_cc0.tif
rm -f ./*.aux.xml
