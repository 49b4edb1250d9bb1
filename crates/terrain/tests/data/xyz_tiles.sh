#!/bin/sh
# Web-map elevation tiles (z/x/y, EPSG:3857, XYZ scheme) made from the SRTM tile N44W072.hgt by
# independent programs, and GDAL's reading of each, for tests/dem_formats.rs and the CLI's
# tests/terrain_formats.rs:
#  - gdalwarp (GDAL 3.6.2) reprojects the tile to EPSG:3857 on each XYZ tile's exact bounds
#    (mercantile.xy_bounds: pixel-is-area, the bounds are the outer edges of the 256 x 256
#    pixels), bilinear, as float32;
#  - Mapbox Terrain-RGB: rio-rgbify 0.4.0 (PyPI rio-rgbify, Mapbox's encoder; `rio rgbify
#    -b -10000 -i 0.1`, i.e. height = -10000 + 0.1 (R 65536 + G 256 + B); it truncates to the
#    0.1 m step below), then gdal_translate
#    -of PNG: xyz/terrain_rgb/10/308/371.png and 10/309/371.png (two tiles side by side);
#  - Terrarium (AWS Terrain Tiles / Mapzen): rio-rgbify has no Terrarium mode, so numpy encodes
#    it by the published formula height = (R 256 + G + B / 256) - 32768 (v = h + 32768,
#    R = floor(v / 256), G = floor(v) mod 256, B = floor(frac(v) 256)) and Pillow writes the PNG:
#    xyz/terrarium/10/308/370.png, 10/309/370.png, 10/309/371.png (an L: 10/308/371 is missing,
#    a gap in the joined grid).
# GDAL's reading of the reprojected float tiles: xyz/10_X_Y.gdalinfo.json (gdalinfo -json -stats;
# geoTransform = the tile's corner and pixel size), xyz/joined_rgb.gdalinfo.json and
# xyz/joined_terrarium.gdalinfo.json (gdalbuildvrt of the tiles: the joined grid's size and
# corner), and xyz/gdal_samples.txt ("10_X_Y col row height" from gdallocationinfo -valonly: the
# four corners and 60 samples per tile, the float height before encoding).
# Needs gdal-bin, python3 with numpy, Pillow, mercantile, rasterio and rio-rgbify.
set -eu
cd "$(dirname "$0")"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
rm -rf xyz
mkdir -p xyz
: > xyz/gdal_samples.txt
for t in 308/370 309/370 308/371 309/371; do
  x=${t%/*}; y=${t#*/}; n=10_${x}_${y}
  b=$(python3 -c "import mercantile as m; b = m.xy_bounds($x, $y, 10); print('%.10f %.10f %.10f %.10f' % (b.left, b.bottom, b.right, b.top))")
  # shellcheck disable=SC2086
  gdalwarp -q -t_srs EPSG:3857 -te $b -ts 256 256 -r bilinear -ot Float32 -dstnodata None N44W072.hgt "$T/$n.tif"
  (cd "$T" && gdalinfo -json -stats "$n.tif") > "xyz/$n.gdalinfo.json"
  {
    printf '0 0\n255 0\n0 255\n255 255\n'
    i=0
    while [ $i -lt 60 ]; do
      echo "$(( (i * 397 + 11) % 256 )) $(( (i * 613 + 5) % 256 ))"
      i=$((i + 1))
    done
  } > "$T/coords"
  (cd "$T" && gdallocationinfo -valonly "$n.tif" < coords) > "$T/values"
  paste -d ' ' "$T/coords" "$T/values" | sed "s/^/$n /" >> xyz/gdal_samples.txt
done
# Terrain-RGB by rio-rgbify.
for t in 308/371 309/371; do
  x=${t%/*}; y=${t#*/}; n=10_${x}_${y}
  rio rgbify -b -10000 -i 0.1 "$T/$n.tif" "$T/$n.rgb.tif"
  mkdir -p "xyz/terrain_rgb/10/$x"
  gdal_translate -q -of PNG "$T/$n.rgb.tif" "xyz/terrain_rgb/10/$x/$y.png"
done
# Terrarium by numpy.
for t in 308/370 309/370 309/371; do
  x=${t%/*}; y=${t#*/}; n=10_${x}_${y}
  mkdir -p "xyz/terrarium/10/$x"
  python3 - "$T/$n.tif" "xyz/terrarium/10/$x/$y.png" <<'PY'
import sys
import numpy as np
import rasterio
from PIL import Image
with rasterio.open(sys.argv[1]) as f:
    h = f.read(1).astype(np.float64)
v = h + 32768.0
r = np.floor(v / 256.0)
g = np.floor(v) - 256.0 * r
b = np.floor((v - np.floor(v)) * 256.0)
rgb = np.dstack([r, g, b]).astype(np.uint8)
Image.fromarray(rgb, "RGB").save(sys.argv[2], optimize=True)
PY
done
gdalbuildvrt -q "$T/joined_rgb.vrt" "$T/10_308_371.tif" "$T/10_309_371.tif"
gdalbuildvrt -q "$T/joined_terrarium.vrt" "$T/10_308_370.tif" "$T/10_309_370.tif" "$T/10_309_371.tif"
(cd "$T" && gdalinfo -json joined_rgb.vrt) > xyz/joined_rgb.gdalinfo.json
(cd "$T" && gdalinfo -json joined_terrarium.vrt) > xyz/joined_terrarium.gdalinfo.json
find xyz -name '*.aux.xml' -delete
