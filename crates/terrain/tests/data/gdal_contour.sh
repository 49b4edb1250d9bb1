#!/bin/sh
# `gdal_contour` 3.6.2's lines, for tests/contour_lines.rs to compare `contour_lines` with, as
# GeoJSON (`-f GeoJSON`). Inputs:
# - contour_onlevel.asc: 6 x 5 integer heights, every one on a level of `-i 1`, one of them a 0
#   (a pit, or with `-snodata 0` a hole); no NODATA_value;
# - contour_rings.asc: 12 x 10 heights with a peak and a pit, whose lines close into rings:
#   100 + 60·exp(−((c−3)² + (r−4)²)/4) − 45·exp(−((c−8.5)² + (r−5)²)/3) + 1.5·c at column c,
#   row r, to 2 decimals, 30 m cells;
# - gdaldem_holes.asc (gdaldem.sh): 64 x 64 heights with five no-data holes, on the edges too;
# - gdaldem_geo.tif (gdaldem.sh): 64 x 64 int16 of N44W072.hgt in degrees (the CRS84 member);
# - hillshade_dem_utm.tif (hillshade.sh): 64 x 64 float32 in UTM 19N (an EPSG URN member).
# The expected file's name says the input and the options.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
out="$here/gdal_contour"
mkdir -p "$out"
rm -f "$out"/*.geojson
run() {
  name=$1
  shift
  gdal_contour -q -f GeoJSON "$@" "$out/$name.geojson"
}
run onlevel_i1 -i 1 -a ELEV "$here/contour_onlevel.asc"
run onlevel_i1_snodata0 -i 1 -a ELEV -snodata 0 "$here/contour_onlevel.asc"
run onlevel_fl -fl 2.5 4 6.5 9 -a ELEV "$here/contour_onlevel.asc"
run onlevel_e2 -e 2 -a ELEV "$here/contour_onlevel.asc"
run onlevel_noattr -i 2 "$here/contour_onlevel.asc"
run rings_i10 -i 10 -a ELEV "$here/contour_rings.asc"
run rings_i7_off3_3d -i 7 -off 3 -a ELEV -3d "$here/contour_rings.asc"
run holes_i100 -i 100 -a ELEV "$here/gdaldem_holes.asc"
run geo_i40 -i 40 -a ELEV "$here/gdaldem_geo.tif"
run utm_i200_off50_3d -i 200 -off 50 -a HEIGHT -3d "$here/hillshade_dem_utm.tif"
