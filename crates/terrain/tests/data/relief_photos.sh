#!/bin/sh
# Orthophoto fixtures over the real SRTM tile N44W072.hgt, written by GDAL (gdaldem, gdal_calc.py,
# gdal_translate): a shaded relief of the Presidential Range (71.45-71.15 W, 44.15-44.40 N) as
#  - relief_tiled.tif: 3-band byte, 64x64 tiles, Deflate, 320 x 240 pixels, EPSG:4326
#  - relief_planar_u16.tif: the same three bands scaled to 0..4000 plus the hillshade as a fourth,
#    uint16, band-interleaved (planar), 32x32 tiles, LZW — a "multispectral" scene
# tests/photo.rs reads them by rows and whole and builds GST pyramids from both.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
cp "$here/N44W072.hgt" .
gdaldem hillshade -q -z 2 -compute_edges N44W072.hgt hs.tif
gdaldem color-relief -q N44W072.hgt "$here/../../../../docs/charts/flight_srtm/relief_colours.txt" cr.tif
for b in 1 2 3; do
  gdal_calc.py --quiet -A cr.tif --A_band=$b -B hs.tif --outfile=b$b.tif --type=Byte \
    --calc="numpy.clip(A*(0.35+0.9*B/255.0),0,255)" --overwrite
done
gdalbuildvrt -q -separate rgb.vrt b1.tif b2.tif b3.tif
gdal_translate -q -projwin -71.45 44.40 -71.15 44.15 -outsize 320 240 -r bilinear \
  -co TILED=YES -co BLOCKXSIZE=64 -co BLOCKYSIZE=64 -co COMPRESS=DEFLATE -co PHOTOMETRIC=RGB \
  rgb.vrt "$here/relief_tiled.tif"
gdalbuildvrt -q -separate rgbh.vrt b1.tif b2.tif b3.tif hs.tif
gdal_translate -q -projwin -71.45 44.40 -71.15 44.15 -outsize 320 240 -r bilinear -ot UInt16 \
  -scale 0 255 0 4000 -co TILED=YES -co BLOCKXSIZE=32 -co BLOCKYSIZE=32 -co COMPRESS=LZW \
  -co INTERLEAVE=BAND rgbh.vrt "$here/relief_planar_u16.tif"
rm -f "$here"/*.aux.xml
