#!/bin/sh
# Writes the GeoTIFF / ASCII-grid fixtures of the terrain tests with GDAL (gdal-bin from Debian;
# gdal_version.txt records the version). The heights are analytic so that the tests compare against
# the formula, and gdalinfo -json records GDAL's own reading of each georeference.
#   height(col, row) = 100 + 2*col + 3*row (metres); sample (5, 3) is no-data (-32768 or nan).
set -eu
cd "$(dirname "$0")"
W=37; H=29
src() { # $1 = no-data marker
  awk -v W=$W -v H=$H -v ND="$1" 'BEGIN {
    print "ncols " W; print "nrows " H; print "xllcorner 500000"; print "yllcorner 3900000";
    print "cellsize 30"; print "NODATA_value " ND;
    for (r = 0; r < H; r++) { line = "";
      for (c = 0; c < W; c++) { v = (c == 5 && r == 3) ? ND : 100 + 2*c + 3*r; line = line (c ? " " : "") v }
      print line } }'
}
src -32768 > ramp.asc
# int16, strips, LZW, projected UTM 54N, PixelIsArea
gdal_translate -q -ot Int16 -a_srs EPSG:32654 -co COMPRESS=LZW ramp.asc ramp_i16_lzw.tif
# uint16, 16x16 tiles, Deflate with predictor 2, BigTIFF
gdal_translate -q -ot UInt16 -a_srs EPSG:32654 -a_nodata 0 -co TILED=YES -co BLOCKXSIZE=16 -co BLOCKYSIZE=16 \
  -co COMPRESS=DEFLATE -co PREDICTOR=2 -co BIGTIFF=YES ramp.asc ramp_u16_tiled_bigtiff.tif
# int32 PackBits, PixelIsPoint
gdal_translate -q -ot Int32 -a_srs EPSG:32654 -mo AREA_OR_POINT=Point -co COMPRESS=PACKBITS ramp.asc ramp_i32_point.tif
# float32, tiles, predictor 3, geographic (degrees), nan no-data
gdal_translate -q -ot Float32 -a_srs EPSG:4326 -a_ullr 138.0 36.0 138.037 35.971 ramp.asc ramp_geo_tmp.tif
gdalwarp -q -srcnodata -32768 -dstnodata nan -co TILED=YES -co BLOCKXSIZE=16 -co BLOCKYSIZE=16 \
  -co COMPRESS=DEFLATE -co PREDICTOR=3 ramp_geo_tmp.tif ramp_f32_geo.tif
# float64, strips of 4 rows, uncompressed
gdal_translate -q -ot Float64 -a_srs EPSG:32654 -co BLOCKYSIZE=4 ramp.asc ramp_f64.tif
# ESRI ASCII grid written by GDAL's AAIGrid driver (xllcorner form)
gdal_translate -q -of AAIGrid ramp_i16_lzw.tif ramp_gdal.asc
for f in ramp_i16_lzw ramp_u16_tiled_bigtiff ramp_i32_point ramp_f32_geo ramp_f64; do
  gdalinfo -json $f.tif > $f.gdalinfo.json
done
# A 3-band byte orthophoto over the east part of the grid, and a 4-band uint16 "multispectral" one
# (band-interleaved): R = (12*col) mod 256, G = (8*row) mod 256, B = 77; 20 x 29 pixels of 30 m.
band() { awk -v F="$1" 'BEGIN { print "ncols 20"; print "nrows 29"; print "xllcorner 500540";
  print "yllcorner 3900000"; print "cellsize 30";
  for (r = 0; r < 29; r++) { line = ""; for (c = 0; c < 20; c++) {
    v = (F == "r") ? (c*12)%256 : (F == "g") ? (r*8)%256 : 77; line = line (c ? " " : "") v } print line } }'; }
band r > pr.asc; band g > pg.asc; band b > pb.asc
gdalbuildvrt -q -separate p3.vrt pr.asc pg.asc pb.asc
gdal_translate -q -ot Byte -a_srs EPSG:32654 -co PHOTOMETRIC=RGB p3.vrt photo_rgb.tif
gdalbuildvrt -q -separate p4.vrt pr.asc pg.asc pb.asc pr.asc
gdal_translate -q -ot UInt16 -a_srs EPSG:32654 -co INTERLEAVE=BAND p4.vrt photo_4band.tif
rm -f ramp.asc ramp_geo_tmp.tif pr.asc pg.asc pb.asc p3.vrt p4.vrt *.prj *.aux.xml
gdalinfo --version > gdal_version.txt
