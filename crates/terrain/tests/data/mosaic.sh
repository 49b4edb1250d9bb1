#!/bin/sh
# Three overlapping pieces of the SRTM tile N44W072.hgt as GeoTIFFs, and GDAL's mosaic of them,
# for tests/mosaic.rs. The pieces (int16, no-data -32768), as `gdal_translate -srcwin` windows
# (column, row, width, height) of the tile:
#   mosaic_nw.tif  800 840 60 40
#   mosaic_ne.tif  859 840 50 40   (shares column 859 with nw, as adjacent SRTM tiles share edges)
#   mosaic_s.tif   820 879 70 30   (shares row 879 with both; the south-west and south-east
#                                   corners of the union are covered by no piece)
# mosaic_gdal.tif is `gdalbuildvrt` of the three (in that order; no-data is transparent, the
# later file wins where both have data), mosaic.vrt, written out by gdal_translate.
# GDAL VRTs over the pieces, read as elevation grids by tests/mosaic.rs, each beside GDAL's
# translation of it (<name>_gdal.tif):
#   mosaic_window.vrt  gdal_translate -of VRT -srcwin 10 5 40 30 of nw (a SimpleSource window)
#   mosaic_half.vrt    gdal_translate -of VRT -outsize 50% 50% of s (a SrcRect twice its DstRect:
#                      nearest neighbour)
#   mosaic_scaled.vrt  gdal_translate -of VRT -ot Float32 -scale 0 2000 0 1 of ne (a ComplexSource
#                      with NODATA, ScaleOffset and ScaleRatio)
#   mosaic_nested.vrt  gdalbuildvrt of mosaic_window.vrt and s (a VRT as a source)
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
cd "$here"
rm -f mosaic.vrt mosaic_window.vrt mosaic_half.vrt mosaic_scaled.vrt mosaic_nested.vrt
gdalbuildvrt -q mosaic.vrt mosaic_nw.tif mosaic_ne.tif mosaic_s.tif
gdal_translate -q -of VRT -srcwin 10 5 40 30 mosaic_nw.tif mosaic_window.vrt
gdal_translate -q -of VRT -outsize 50% 50% mosaic_s.tif mosaic_half.vrt
gdal_translate -q -of VRT -ot Float32 -scale 0 2000 0 1 mosaic_ne.tif mosaic_scaled.vrt
gdalbuildvrt -q mosaic_nested.vrt mosaic_window.vrt mosaic_s.tif
rm -f mosaic_gdal.tif
gdal_translate -q -co COMPRESS=DEFLATE mosaic.vrt mosaic_gdal.tif
for v in window half scaled nested; do
  rm -f mosaic_${v}_gdal.tif
  gdal_translate -q -co COMPRESS=DEFLATE mosaic_$v.vrt mosaic_${v}_gdal.tif
done
rm -f "$here"/*.aux.xml
