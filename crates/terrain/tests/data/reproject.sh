#!/bin/sh
# Photos in other coordinate systems than their elevation grid, and GDAL's warp of each onto the
# grid, for tests/reproject.rs. One smooth test pattern (100 x 100 pixels: R = 128 + 110 sin(c/4),
# G = 128 + 110 sin(r/3.5), B = 128 + 100 sin((c + r)/6)) is placed over the west two thirds of
# the Mount Washington area (lon -71.37..-71.29, lat 44.23..44.31) in three systems:
#   photo_geo.tif    EPSG:4326 (degrees)
#   photo_merc.tif   EPSG:3857 (Web Mercator, as web map imagery comes)
#   photo_utm18.tif  EPSG:32618 (UTM 18N: the zone west of the grids' 19N)
# The grids: hillshade_dem_utm.tif (UTM 19N, 64², from hillshade.sh) and dem_geo.tif (90 x 70
# samples of N44W072.hgt, EPSG:4326); dem_merc.tif is dem_geo.tif warped to EPSG:3857. ref_<grid>_<photo>.png is `gdalwarp -r bilinear -et 0`
# (exact PROJ transforms) of the photo onto the texel lattice of a 129² texture over the grid's
# sample-centre extent (texel (i, j) at u = i/128, v = j/128), RGBA with alpha 0 off the photo.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
band() { awk -v F="$1" 'BEGIN { print "ncols 100"; print "nrows 100"; print "xllcorner 0";
  print "yllcorner 0"; print "cellsize 1";
  for (r = 0; r < 100; r++) { line = ""; for (c = 0; c < 100; c++) {
    v = (F == "r") ? 128 + 110 * sin(c / 4) : (F == "g") ? 128 + 110 * sin(r / 3.5) : 128 + 100 * sin((c + r) / 6);
    line = line (c ? " " : "") int(v + 0.5) } print line } }'; }
band r > r.asc; band g > g.asc; band b > b.asc
gdalbuildvrt -q -separate p.vrt r.asc g.asc b.asc
corners() { # $1 = EPSG: the area's upper-left and lower-right corners in it
  printf '%s\n%s\n' "-71.37 44.31" "-71.29 44.23" | gdaltransform -s_srs EPSG:4326 -t_srs "EPSG:$1" \
    | awk '{ printf "%s %s ", $1, $2 }'
}
for p in "geo 4326" "merc 3857" "utm18 32618"; do
  set -- $p
  gdal_translate -q -ot Byte -a_srs "EPSG:$2" -a_ullr $(corners "$2") -co PHOTOMETRIC=RGB \
    -co COMPRESS=DEFLATE p.vrt "$here/photo_$1.tif"
done
gdal_translate -q -srcwin 790 842 90 70 -co COMPRESS=DEFLATE "$here/N44W072.hgt" "$here/dem_geo.tif"
# The same area's heights in Web Mercator at 100 m (about 72 m on the ground at 44.3° N)
rm -f "$here/dem_merc.tif"
gdalwarp -q -t_srs EPSG:3857 -tr 100 100 -r bilinear -ot Float32 -co COMPRESS=DEFLATE \
  "$here/dem_geo.tif" "$here/dem_merc.tif"
# texel-centred extents: sample-centre extent grown by half a texel (128 texel steps) each side
extent() { # $1 = grid file: prints "xmin ymin xmax ymax" for -te
  gdalinfo -json "$1" | python3 -c '
import json, sys
j = json.load(sys.stdin); g = j["geoTransform"]; w, h = j["size"]
x0, y0 = g[0] + g[1] / 2, g[3] + g[5] / 2          # centre of sample (0, 0)
x1, y1 = x0 + (w - 1) * g[1], y0 + (h - 1) * g[5]  # centre of the last sample
sx, sy = (x1 - x0) / 256, (y0 - y1) / 256            # half a texel
print(repr(x0 - sx), repr(y1 - sy), repr(x1 + sx), repr(y0 + sy))'
}
for g in "utm19 hillshade_dem_utm.tif 32619" "geo dem_geo.tif 4326" "merc dem_merc.tif 3857"; do
  set -- $g
  for p in geo merc utm18; do
    [ "$1" = "$p" ] && continue
    rm -f w.tif
    gdalwarp -q -t_srs "EPSG:$3" -te $(extent "$here/$2") -ts 129 129 -r bilinear -et 0 -dstalpha \
      "$here/photo_$p.tif" w.tif
    gdal_translate -q -of PNG w.tif "$here/ref_$1_$p.png"
  done
done
rm -f "$here"/*.aux.xml "$here"/*.prj
