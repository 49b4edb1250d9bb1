#!/bin/sh
# DTED and ESRI .hdr (GridFloat .flt, BIL .bil) fixtures written by GDAL (gdal-bin 3.6.2, see
# gdal_version.txt) from the SRTM tile N44W072.hgt and the ramp GeoTIFFs of generate.sh, and GDAL's
# own reading of each: <file>.gdalinfo.json (gdalinfo -json -stats: size, geoTransform, no-data,
# statistics) and dem_formats_gdal_samples.txt ("file col row value" from gdallocationinfo -valonly,
# the raw value, so a no-data sample shows the file's marker). tests/dem_formats.rs compares ours
# with them. See README.md.
set -eu
cd "$(dirname "$0")"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# DTED level 0 (30" x 30" at 44° N: 121 x 121): the SRTM tile resampled by nearest neighbour onto
# level 0's lattice, so sample (c, r) is the tile's sample (10c, 10r). GDAL's DTED writer takes only
# a whole cell on the level's spacing, in pixel-is-area corners half an interval outside the cell.
gdalwarp -q -r near -te -72.00416666666667 43.99583333333333 -70.99583333333333 45.00416666666667 \
  -ts 121 121 N44W072.hgt "$T/l0.tif"
gdal_translate -q -of DTED "$T/l0.tif" n44w072.dt0

# DTED level 1 (3" x 3": 1201 x 1201, the tile's own lattice): the whole cell is 2.9 MB, so it
# holds the tile's heights in a 256 x 256 window around Mount Washington (columns 700-955, rows
# 760-1015) and void (-32767) elsewhere; gzipped (115 KB), the test unpacks it.
gdal_translate -q -srcwin 700 760 256 256 N44W072.hgt "$T/win.tif"
gdalwarp -q -r near -srcnodata None -dstnodata -32767 -ot Int16 \
  -te -72.00041666666667 43.99958333333333 -70.99958333333333 45.00041666666667 \
  -ts 1201 1201 "$T/win.tif" "$T/l1.tif"
gdal_translate -q -of DTED "$T/l1.tif" "$T/n44w072.dt1"
gzip -9 -n -c "$T/n44w072.dt1" > n44w072.dt1.gz

# GridFloat from the geographic float ramp (EPSG:4326, no-data -9999 at sample (5, 3)), as GDAL's
# EHdr driver writes it: .flt, a BIL-style .hdr (ULXMAP/ULYMAP centres, NODATA), an ESRI .prj.
gdalwarp -q -of EHdr -ot Float32 -srcnodata nan -dstnodata -9999 ramp_f32_geo.tif ramp_geo.flt
# The same samples under the header USGS's National Map writes (lower-case keys, the lower-left
# corner, cellsize, NODATA_value, byteorder LSBFIRST).
cp ramp_geo.flt ramp_usgs.flt
cp ramp_geo.prj ramp_usgs.prj
printf 'ncols         37\nnrows         29\nxllcorner     138\nyllcorner     35.971\ncellsize      0.001\nNODATA_value  -9999\nbyteorder     LSBFIRST\n' \
  > ramp_usgs.hdr
# A UTM 54N GridFloat (the int16 ramp as floats, no-data -32768).
gdal_translate -q -of EHdr -ot Float32 ramp_i16_lzw.tif ramp_utm.flt
# 16-bit BIL (EHdr writes integers with NBITS 16, PIXELTYPE SIGNEDINT), UTM 54N.
gdal_translate -q -of EHdr ramp_i16_lzw.tif ramp_i16.bil
# The same big-endian (bytes swapped, BYTEORDER M) and without a .prj: GDAL reports no system.
dd if=ramp_i16.bil of=ramp_i16_msb.bil conv=swab status=none
sed 's/^BYTEORDER .*/BYTEORDER      M/' ramp_i16.hdr > ramp_i16_msb.hdr
# Real heights as GridFloat: a 64 x 64 crop of the SRTM tile (columns 800-863, rows 850-913).
gdal_translate -q -of EHdr -ot Float32 -srcwin 800 850 64 64 N44W072.hgt n44w072_crop.flt

# GDAL's reading. gdalinfo runs beside the unpacked .dt1 so that every JSON names a bare file.
cp n44w072.dt0 ramp_*.flt ramp_*.hdr ramp_*.prj ramp_i16*.bil n44w072_crop.* "$T/"
: > dem_formats_gdal_samples.txt
samples() { # $1 file, $2 width, $3 height, $4 extra "col row" lines
  {
    printf '0 0\n%d 0\n0 %d\n%d %d\n' $(($2 - 1)) $(($3 - 1)) $(($2 - 1)) $(($3 - 1))
    i=0
    while [ $i -lt 40 ]; do
      echo "$(( (i * 397 + 11) % $2 )) $(( (i * 613 + 5) % $3 ))"
      i=$((i + 1))
    done
    printf '%s' "$4"
  } > "$T/coords"
  (cd "$T" && gdallocationinfo -valonly "$1" < coords) > "$T/values"
  paste -d ' ' "$T/coords" "$T/values" | sed "s/^/$1 /" >> dem_formats_gdal_samples.txt
}
window=$(i=0; while [ $i -lt 64 ]; do echo "$(( 700 + (i * 37) % 256 )) $(( 760 + (i * 91) % 256 ))"; i=$((i + 1)); done)
samples n44w072.dt0 121 121 ""
samples n44w072.dt1 1201 1201 "$window
"
for f in ramp_geo.flt ramp_usgs.flt ramp_utm.flt ramp_i16.bil ramp_i16_msb.bil; do
  samples $f 37 29 ""
done
samples n44w072_crop.flt 64 64 ""
for f in n44w072.dt0 n44w072.dt1 ramp_geo.flt ramp_usgs.flt ramp_utm.flt ramp_i16.bil \
  ramp_i16_msb.bil n44w072_crop.flt; do
  (cd "$T" && gdalinfo -json -stats "$f") > "$f.gdalinfo.json"
done
rm -f ./*.aux.xml
