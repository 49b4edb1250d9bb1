#!/bin/sh
# GeoTIFFs in the compressions GDAL's COG driver offers beyond LZW/Deflate/PackBits (generate.sh):
# ZSTD (GDAL's recommendation for elevation COGs), lossless WebP and JPEG in YCbCr (orthophoto COGs),
# written by GDAL 3.6.2 from generate.sh's ramp and photo, and GDAL's own decoding of the JPEG
# (photo_rgb_jpeg_gdal.tif, uncompressed RGB), which tests/photo.rs compares ours with.
set -eu
cd "$(dirname "$0")"
# float32, 16x16 tiles, ZSTD + predictor 3, EPSG:4326, no-data nan (the ramp_f32_geo samples)
gdal_translate -q -co TILED=YES -co BLOCKXSIZE=16 -co BLOCKYSIZE=16 -co COMPRESS=ZSTD -co PREDICTOR=3 \
  ramp_f32_geo.tif ramp_f32_zstd.tif
# int16, strips, ZSTD + predictor 2, UTM 54N (the ramp_i16_lzw samples)
gdal_translate -q -co COMPRESS=ZSTD -co PREDICTOR=2 -co ZSTD_LEVEL=19 ramp_i16_lzw.tif ramp_i16_zstd.tif
# The 3-band photo as lossless WebP (16x16 tiles) and as JPEG in YCbCr (4:2:0, quality 90).
gdal_translate -q -co TILED=YES -co BLOCKXSIZE=16 -co BLOCKYSIZE=16 -co COMPRESS=WEBP -co WEBP_LOSSLESS=TRUE \
  photo_rgb.tif photo_rgb_webp.tif
gdal_translate -q -co TILED=YES -co BLOCKXSIZE=16 -co BLOCKYSIZE=16 -co COMPRESS=JPEG -co PHOTOMETRIC=YCBCR \
  -co JPEG_QUALITY=90 photo_rgb.tif photo_rgb_jpeg.tif
gdal_translate -q photo_rgb_jpeg.tif photo_rgb_jpeg_gdal.tif
for f in ramp_f32_zstd ramp_i16_zstd; do gdalinfo -json $f.tif > $f.gdalinfo.json; done
rm -f *.aux.xml
