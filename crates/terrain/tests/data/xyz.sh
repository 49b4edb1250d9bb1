#!/bin/sh
# Gridded XYZ fixtures written by GDAL 3.6.2's XYZ driver (gdal_translate -of XYZ) from the ramp
# GeoTIFFs of generate.sh and the SRTM tile, and GDAL's reading of them (*.gdalinfo.json, and
# xyz_gdal_samples.txt: "file col row value" by gdallocationinfo). tests/dem_formats.rs compares.
set -eu
cd "$(dirname "$0")"
# int16 ramp, space separated, no header; sample (5, 3) holds the GeoTIFF's no-data, -32768.
gdal_translate -q -of XYZ ramp_i16_lzw.tif ramp_i16.xyz
# float32 geographic ramp with a header line and semicolons (sample (5, 3) is nan); its system is
# in ramp_geo.prj beside it (dem_formats.sh writes it for ramp_geo.flt: ESRI WKT of WGS 84).
gdal_translate -q -of XYZ -co ADD_HEADER_LINE=YES -co COLUMN_SEPARATOR=';' ramp_f32_geo.tif ramp_geo.xyz
# The same int16 ramp as a spreadsheet exports it: "X;Y;Z" with decimal commas (awk, not GDAL).
awk 'BEGIN { print "Rechtswert;Hochwert;Hoehe" } { printf "%s,5;%s,0;%s,25\n", $1, $2, $3 }' ramp_i16.xyz > ramp_comma.xyz
# Real heights with gaps, south row first (a lidar DGM tile with water masked out): a 64 x 64
# window of the SRTM tile, every line whose height ends in 7 removed, rows in reverse order.
gdal_translate -q -of XYZ -srcwin 800 850 64 64 N44W072.hgt "${TMPDIR:-/tmp}/crop.xyz"
awk '$3 % 10 != 7' "${TMPDIR:-/tmp}/crop.xyz" | sort -s -k2,2g > srtm_gaps.xyz
rm -f "${TMPDIR:-/tmp}/crop.xyz"
for f in ramp_i16 ramp_geo srtm_gaps; do gdalinfo -json $f.xyz > $f.xyz.gdalinfo.json; done
: > xyz_gdal_samples.txt
for f in ramp_i16 ramp_geo srtm_gaps; do
  w=$(gdalinfo $f.xyz | sed -n 's/^Size is \([0-9]*\), \([0-9]*\)/\1 \2/p')
  set -- $w
  i=0
  while [ $i -lt 60 ]; do
    c=$(( (i * 397 + 11) % $1 )); r=$(( (i * 613 + 5) % $2 ))
    echo "$f.xyz $c $r $(gdallocationinfo -valonly $f.xyz $c $r)" >> xyz_gdal_samples.txt
    i=$((i + 1))
  done
done
rm -f *.aux.xml
