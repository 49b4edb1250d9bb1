#!/bin/sh
# GDAL's reading of the real SRTM tile N44W072.hgt (see README.md): its statistics and georeference
# (gdalinfo -json -stats) and the values GDAL's SRTMHGT driver returns at the four corners and 256 pixel
# positions spread over the tile (gdallocationinfo, pixel/line coordinates) — what tests/srtm.rs compares ours with.
set -eu
cd "$(dirname "$0")"
gdalinfo -json -stats N44W072.hgt > N44W072.gdalinfo.json
rm -f N44W072.hgt.aux.xml
: > N44W072.gdal_samples.txt
for cr in "0 0" "1200 0" "0 1200" "1200 1200"; do
  echo "$cr $(gdallocationinfo -valonly N44W072.hgt $cr)" >> N44W072.gdal_samples.txt
done
i=0
while [ $i -lt 256 ]; do
  col=$(( (i * 397 + 11) % 1201 )); row=$(( (i * 613 + 5) % 1201 ))
  v=$(gdallocationinfo -valonly N44W072.hgt $col $row)
  echo "$col $row $v" >> N44W072.gdal_samples.txt
  i=$((i + 1))
done
