#!/bin/sh
# A hillshade written by GDAL, for tests/srtm.rs to compare ours with: the real SRTM tile
# N44W072.hgt around Mount Washington warped to UTM 19N (EPSG:32619) at 90 m, 64 x 64 samples,
# float32 (hillshade_dem_utm.tif), and `gdaldem hillshade` of it with its defaults (azimuth 315,
# altitude 45, z 1, Horn) and -compute_edges, as an ESRI ASCII grid (hillshade_gdal.asc: bytes
# 1 + 254 * cos, 1 where the cosine is <= 0). tests/srtm.rs compares the interior samples.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
gdalwarp -q -s_srs EPSG:4326 -t_srs EPSG:32619 -tr 90 90 -te 313300 4901600 319060 4907360 \
  -r bilinear -ot Float32 "$here/N44W072.hgt" "$here/hillshade_dem_utm.tif"
gdaldem hillshade -q -compute_edges "$here/hillshade_dem_utm.tif" hs.tif
gdal_translate -q -of AAIGrid hs.tif "$here/hillshade_gdal.asc"
rm -f "$here"/*.aux.xml "$here"/*.prj
