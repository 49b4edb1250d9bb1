#!/bin/sh
# Vector overlays written and rasterised by GDAL/OGR, for tests/vector.rs.
#
# vector_src.csv holds a lake with an island (a polygon with a hole), a forest in two parts (a
# multipolygon, one part over the grid's east edge), a road and a trail (line strings, one leaving
# the grid), a summit and two huts (points) and a feature without geometry, as WKT in UTM 19N
# (EPSG:32619) over hillshade_dem_utm.tif. ogr2ogr writes them as
#   vector_utm.geojson     GeoJSON with the 2008 "crs" member (EPSG:32619 coordinates)
#   vector_wgs84.geojson   RFC 7946 GeoJSON (WGS 84 degrees, 7 decimals)
#   vector_wgs84.geojsons  a GeoJSON text sequence (RFC 8142, record separators)
# and gdal_rasterize burns the WGS 84 file (reprojected to UTM by GDAL/PROJ) onto the texel
# lattice of a 256² texture over the grid (texel i's centre at sample i·63/255, as texmap lays a
# texture over its grid from the first sample's centre to the last's):
#   vector_gdal_area.png          the polygons, pixel-centre rule
#   vector_gdal_line.png          the lines (GDAL's default line rule)
#   vector_gdal_line_touched.png  the lines, every pixel touched (-at)
#   vector_gdal_point.png         the points
#   vector_gdal_area_utm.png      the polygons from vector_utm.geojson (no reprojection)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
cp "$here/vector_src.csv" src.csv
ogr2ogr -q -f GeoJSON -oo EMPTY_STRING_AS_NULL=YES -oo KEEP_GEOM_COLUMNS=NO -a_srs EPSG:32619 -lco RFC7946=NO \
  "$here/vector_utm.geojson" src.csv
ogr2ogr -q -f GeoJSON -oo EMPTY_STRING_AS_NULL=YES -oo KEEP_GEOM_COLUMNS=NO -s_srs EPSG:32619 -t_srs EPSG:4326 \
  -lco RFC7946=YES "$here/vector_wgs84.geojson" src.csv
ogr2ogr -q -f GeoJSONSeq -oo EMPTY_STRING_AS_NULL=YES -oo KEEP_GEOM_COLUMNS=NO -s_srs EPSG:32619 -t_srs EPSG:4326 \
  -lco RS=YES "$here/vector_wgs84.geojsons" src.csv
# GDAL's reading of the grid: corner of pixel (0, 0) and the pixel size; sample centres are
# half a pixel in. The texture spans the centres of samples 0 and 63: 256 texels.
set -- $(gdalinfo -json "$here/hillshade_dem_utm.tif" | python3 -c '
import json, sys
g = json.load(sys.stdin)["geoTransform"]
x0, dx, y0, dy = g[0] + g[1] / 2, g[1], g[3] + g[5] / 2, g[5]
t = 63 / 255
print(x0 - t * dx / 2, y0 - t * dy / 2, x0 + 63 * dx + t * dx / 2, y0 + 63 * dy + t * dy / 2)')
ullr="$1 $2 $3 $4"
burn() { # name, source, where, extra options
  gdal_create -q -of GTiff -outsize 256 256 -bands 1 -ot Byte -burn 0 -a_srs EPSG:32619 \
    -a_ullr $ullr "$1.tif"
  gdal_rasterize -q -burn 255 -where "$3" $4 "$2" "$1.tif"
  gdal_translate -q -of PNG "$1.tif" "$here/vector_gdal_$1.png"
}
burn area "$here/vector_wgs84.geojson" "kind = 'area'" ""
burn line "$here/vector_wgs84.geojson" "kind = 'line'" ""
burn line_touched "$here/vector_wgs84.geojson" "kind = 'line'" "-at"
burn point "$here/vector_wgs84.geojson" "kind = 'point'" ""
burn area_utm "$here/vector_utm.geojson" "kind = 'area'" ""
rm -f "$here"/*.aux.xml
