#!/bin/sh
# Orthophoto tiles and GDAL's mosaics of them, for tests/photo.rs (several --photo files and
# GDAL VRTs as photos). Cut from relief_tiled.tif (320 x 240 pixels, EPSG:4326, its no-data tag
# dropped: the relief has no pixel of 0 or 255) as `gdal_translate -srcwin` windows (column, row,
# width, height), all on the relief's lattice:
#   mosaic_photo_a.tif    0   0 180 140  plain RGB
#   mosaic_photo_b.tif  150   0 170 140  RGB, GDAL_NODATA 0, two holes of 0 in every band burnt
#                                        by gdal_rasterize: one over tile a (a shows through),
#                                        one over no other tile (nothing does)
#   mosaic_photo_c.tif   60 110 200 130  RGBA: alpha (ExtraSamples 2) 255 inside a pentagon,
#                                        0 outside (the tiles below show through)
#   mosaic_photo_d_utm.tif               columns 230..319, rows 120..239 warped to UTM 19N at
#                                        75 m (bilinear, -dstalpha): a tile in another system
# mosaic_photo.vrt is `gdalbuildvrt -addalpha` of a, b, c (in that order: later wins; gdalbuildvrt
# skips d, whose system differs) and mosaic_photo_gdal.tif GDAL's translation of it (RGBA).
# ref_mosaic_photo.png is `gdalwarp -r bilinear -et 0 -dstalpha` of a, b, c, d (in that order)
# onto the texel lattice of a 257² texture over a grid in degrees whose sample centres span
# -71.40..-71.18 E, 44.20..44.38 N (texel (i, j) at u = i/256, v = j/256; finer than the tiles
# on both axes, where gdalwarp's bilinear is the 2 x 2 one), RGBA.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
co="-co COMPRESS=DEFLATE -co PREDICTOR=2"
cut() { gdal_translate -q -a_nodata none -srcwin $2 $3 $4 $5 "$here/relief_tiled.tif" "$1"; }
cut a.tif 0 0 180 140
cut b.tif 150 0 170 140
cut c.tif 60 110 200 130
cut d.tif 230 120 90 120
gdal_translate -q $co a.tif "$here/mosaic_photo_a.tif"
# b: holes of 0 in all three bands (polygons in the tiles' degrees)
cat > holes.csv <<'EOF'
id,WKT
1,"POLYGON((-71.3094 44.38,-71.2844 44.38,-71.2844 44.34,-71.3094 44.34,-71.3094 44.38))"
2,"POLYGON((-71.215 44.37,-71.17 44.37,-71.17 44.33,-71.215 44.33,-71.215 44.37))"
EOF
gdal_rasterize -q -b 1 -b 2 -b 3 -burn 0 -burn 0 -burn 0 -l holes holes.csv b.tif
gdal_translate -q -a_nodata 0 $co b.tif "$here/mosaic_photo_b.tif"
# c: an alpha band burnt from a pentagon, beside the three colour bands
cat > pentagon.csv <<'EOF'
id,WKT
1,"POLYGON((-71.39 44.24,-71.33 44.284,-71.22 44.27,-71.21 44.17,-71.36 44.152,-71.39 44.24))"
EOF
for k in 1 2 3; do gdal_translate -q -b $k c.tif c$k.tif; done
gdal_translate -q -b 1 -scale 0 255 0 0 c.tif calpha.tif
gdal_rasterize -q -b 1 -burn 255 -l pentagon pentagon.csv calpha.tif
gdalbuildvrt -q -separate c4.vrt c1.tif c2.tif c3.tif calpha.tif
gdal_translate -q -colorinterp red,green,blue,alpha -co PHOTOMETRIC=RGB -co ALPHA=YES \
  $co c4.vrt "$here/mosaic_photo_c.tif"
rm -f "$here/mosaic_photo_d_utm.tif"
gdalwarp -q -t_srs EPSG:32619 -tr 75 75 -r bilinear -dstalpha $co d.tif "$here/mosaic_photo_d_utm.tif"
cd "$here"
rm -f mosaic_photo.vrt mosaic_photo_gdal.tif
gdalbuildvrt -q -addalpha mosaic_photo.vrt mosaic_photo_a.tif mosaic_photo_b.tif mosaic_photo_c.tif
gdal_translate -q -co PHOTOMETRIC=RGB $co mosaic_photo.vrt mosaic_photo_gdal.tif
# GDAL's warp of all four onto the 257² texel lattice: sample-centre extent grown by half a texel.
x0=-71.40; x1=-71.18; y0=44.38; y1=44.20
te=$(awk -v a=$x0 -v b=$x1 -v c=$y0 -v d=$y1 'BEGIN { sx = (b - a) / 512; sy = (c - d) / 512;
  printf "%.15g %.15g %.15g %.15g", a - sx, d - sy, b + sx, c + sy }')
gdalwarp -q -t_srs EPSG:4326 -te $te -ts 257 257 -r bilinear -et 0 -dstalpha \
  mosaic_photo_a.tif mosaic_photo_b.tif mosaic_photo_c.tif mosaic_photo_d_utm.tif "$work/w.tif"
gdal_translate -q -of PNG "$work/w.tif" ref_mosaic_photo.png
rm -f "$here"/*.aux.xml
