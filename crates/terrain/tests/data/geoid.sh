#!/bin/sh
# EGM96 geoid fixtures for tests/geoid.rs, cut from PROJ's own grid (proj-data's
# /usr/share/proj/egm96_15.gtx: 15' spacing, 721 x 1440 samples from 90S 180W) by GDAL:
#   egm96_cut.gtx   gdal_translate -of GTX of the 4 x 4 degree window around N44W072.hgt
#   egm96_cut.tif   the same window as a Float32 GeoTIFF (the form of PROJ's us_nga_egm96_15.tif)
#   geoid_proj.txt  lon lat N: the undulation PROJ applies at 40 points of the window, from
#                   `gdaltransform -s_srs EPSG:4326+5773 -t_srs EPSG:4979` (EGM96 heights to
#                   ellipsoidal heights, i.e. h = H + N) at H = 0, plus the four SRTM tile
#                   corners' sample centres (N44W072.gdal_samples.txt lines 1-4) at their heights:
#                   lon lat H h.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
grid=/usr/share/proj/egm96_15.gtx
cd "$here"
gdal_translate -q -of GTX -projwin -73.5 46.5 -69.5 42.5 "$grid" egm96_cut.gtx
gdal_translate -q -of GTiff -ot Float32 -projwin -73.5 46.5 -69.5 42.5 "$grid" egm96_cut.tif
rm -f egm96_cut.tif.aux.xml egm96_cut.gtx.aux.xml
awk 'BEGIN { srand(20261203); for (i = 0; i < 40; i++) printf "%.6f %.6f 0\n", -72.9 + 2.8 * rand(), 43.1 + 2.8 * rand() }' \
  | gdaltransform -s_srs EPSG:4326+5773 -t_srs EPSG:4979 > geoid_proj.txt
# The SRTM tile's corner samples: 1° / 1200 spacing from the 44°N 72°W corner, north up.
head -4 N44W072.gdal_samples.txt | awk '{ printf "%.10f %.10f %s\n", -72 + $1 / 1200, 45 - $2 / 1200, $3 }' \
  > corners.tmp
gdaltransform -s_srs EPSG:4326+5773 -t_srs EPSG:4979 < corners.tmp | paste -d' ' corners.tmp - \
  | awk '{ print "corner", $1, $2, $3, $6 }' >> geoid_proj.txt
rm -f corners.tmp
