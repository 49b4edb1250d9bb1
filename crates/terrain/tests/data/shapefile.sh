#!/bin/sh
# ESRI shapefiles written by GDAL/OGR from vector_src.csv (the features of vector.sh), for
# tests/shapefile.rs. Each layer holds one kind of feature, as shapefiles must:
#   shp_utm_area.shp / .prj    the polygons (a polygon with a hole, a multipolygon), UTM 19N
#   shp_utm_line.shp / .prj    the line strings, UTM 19N
#   shp_utm_point.shp / .prj   the points as one multipoint layer (-nlt MULTIPOINT), UTM 19N
#   shp_z_area.shp / .prj      the polygons as PolygonZ (-dim XYZ), UTM 19N
#   shp_wgs84_line.shp / .prj  the line strings reprojected to WGS 84 degrees by GDAL/PROJ
#   shp_noprj_point.shp        the summit (a Point layer) in WGS 84 degrees, without a .prj
# Only the .shp and .prj files are kept (texmap reads no attributes).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
cp "$here/vector_src.csv" src.csv
shp() { # name, kind, extra options
  ogr2ogr -q -f "ESRI Shapefile" -oo KEEP_GEOM_COLUMNS=NO -a_srs EPSG:32619 -where "kind = '$2'" $3 "$1.shp" src.csv
}
shp shp_utm_area area ""
shp shp_utm_line line ""
shp shp_utm_point point "-nlt MULTIPOINT"
shp shp_z_area area "-dim XYZ"
ogr2ogr -q -f "ESRI Shapefile" -oo KEEP_GEOM_COLUMNS=NO -s_srs EPSG:32619 -t_srs EPSG:4326 -where "kind = 'line'" shp_wgs84_line.shp src.csv
ogr2ogr -q -f "ESRI Shapefile" -oo KEEP_GEOM_COLUMNS=NO -s_srs EPSG:32619 -t_srs EPSG:4326 -where "name = 'summit'" shp_noprj_point.shp src.csv
rm shp_noprj_point.prj
cp shp_*.shp shp_*.prj "$here/"
