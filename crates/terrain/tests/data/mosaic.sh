#!/bin/sh
# Three overlapping pieces of the SRTM tile N44W072.hgt as GeoTIFFs, and GDAL's mosaic of them,
# for tests/mosaic.rs. The pieces (int16, no-data -32768), as `gdal_translate -srcwin` windows
# (column, row, width, height) of the tile:
#   mosaic_nw.tif  800 840 60 40
#   mosaic_ne.tif  859 840 50 40   (shares column 859 with nw, as adjacent SRTM tiles share edges)
#   mosaic_s.tif   820 879 70 30   (shares row 879 with both; the south-west and south-east
#                                   corners of the union are covered by no piece)
# mosaic_gdal.tif is `gdalbuildvrt` of the three (in that order; no-data is transparent, the
# later file wins where both have data) written out by gdal_translate.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
piece() { gdal_translate -q -srcwin $2 $3 $4 $5 -a_nodata -32768 -co COMPRESS=DEFLATE \
  "$here/N44W072.hgt" "$here/mosaic_$1.tif"; }
piece nw 800 840 60 40
piece ne 859 840 50 40
piece s 820 879 70 30
gdalbuildvrt -q m.vrt "$here/mosaic_nw.tif" "$here/mosaic_ne.tif" "$here/mosaic_s.tif"
rm -f "$here/mosaic_gdal.tif"
gdal_translate -q -co COMPRESS=DEFLATE m.vrt "$here/mosaic_gdal.tif"
rm -f "$here"/*.aux.xml
