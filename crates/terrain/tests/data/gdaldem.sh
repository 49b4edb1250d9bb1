#!/bin/sh
# `gdaldem` 3.6.2's products, for tests/dem_products.rs to compare `dem_products` with. Inputs:
# - hillshade_dem_utm.tif (hillshade.sh): 64 x 64 float32 samples in UTM 19N at 90 m, no holes;
# - gdaldem_holes.asc: the same heights rounded to centimetres with five no-data holes (-9999):
#   a single sample, a 3 x 2 block, one on the west edge, one on the north edge and the
#   south-east corner;
# - gdaldem_geo.tif: 64 x 64 int16 samples of N44W072.hgt (degrees, 3" spacing) from column
#   600, row 600, run with -s 111120 as gdaldem's documentation asks for a geographic grid;
# - gdaldem_colors.txt: a colour file using every syntax (percentages, nv, named colours, the
#   four separators, an optional alpha); gdaldem_colors_exact.txt: entries at heights the geo
#   crop holds, for -exact_color_entry.
# Byte products are written as PNG (lossless; gdaldem's no-data 0 is the value 0), float32 ones
# as Deflate GeoTIFFs with gdaldem's no-data -9999. The expected file's name says the options.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
utm="$here/hillshade_dem_utm.tif"
holes="$here/gdaldem_holes.asc"
geo="$here/gdaldem_geo.tif"
colors="$here/gdaldem_colors.txt"
exact="$here/gdaldem_colors_exact.txt"
out="$here/gdaldem"
mkdir -p "$out"
rm -f "$out"/*

# The inputs.
gdal_translate -q -of AAIGrid "$utm" full.asc
python3 - full.asc "$holes" <<'PY'
import sys
import numpy as np
src, dst = sys.argv[1], sys.argv[2]
lines = open(src).read().split("\n")
nhead = len([l for l in lines[:6] if l[:1].isalpha()])
header = [l for l in lines[:nhead] if not l.startswith("NODATA")]
z = np.loadtxt(src, skiprows=nhead)
z = np.round(z, 2)
holes = [(20, 30)] + [(40 + r, 10 + c) for r in range(2) for c in range(3)] \
    + [(33, 0), (0, 47), (63, 63)]
for r, c in holes:
    z[r, c] = -9999
with open(dst, "w") as f:
    f.write("\n".join(header) + "\nNODATA_value -9999\n")
    for row in z:
        f.write(" ".join("%.2f" % v if v != -9999 else "-9999" for v in row) + "\n")
PY
gdal_translate -q -srcwin 600 600 64 64 -co COMPRESS=DEFLATE "$here/N44W072.hgt" "$geo"
printf '%s\n' \
  'nv 0 0 255 0' \
  '0% 20,80,40' \
  '1100:120:160:60' \
  '1250	170	140	90	200' \
  '50% 200 170 120' \
  '1500 brown' \
  '1600,white' \
  '100% 255 250 240 255' > "$colors"
printf '%s\n' '0% 20 80 40' '500 200 0 0' '700 0 0 200 128' '100% 255 255 255' > "$exact"

g() { gdaldem "$@" -q; }
png() { gdal_translate -q -of PNG "$1" "$out/$2.png"; }
f32() { gdal_translate -q -co COMPRESS=DEFLATE -co PREDICTOR=3 "$1" "$out/$2.tif"; }

# Hillshade (Byte, no-data 0).
g hillshade "$utm" t.tif && png t.tif hs_utm
g hillshade "$holes" t.tif && png t.tif hs_holes
g hillshade -compute_edges "$holes" t.tif && png t.tif hs_holes_edges
g hillshade -alg ZevenbergenThorne -z 2 -az 200 -alt 30 "$holes" t.tif && png t.tif hs_zt_z2_az200_alt30_holes
g hillshade -alg ZevenbergenThorne -compute_edges "$holes" t.tif && png t.tif hs_zt_holes_edges
g hillshade -combined -compute_edges "$holes" t.tif && png t.tif hs_combined_holes_edges
g hillshade -multidirectional -z 3 "$holes" t.tif && png t.tif hs_multi_z3_holes
g hillshade -multidirectional -alg ZevenbergenThorne -compute_edges "$utm" t.tif && png t.tif hs_multi_zt_utm_edges
g hillshade -igor -az 100 "$holes" t.tif && png t.tif hs_igor_az100_holes
g hillshade -s 111120 -z 2 -compute_edges "$geo" t.tif && png t.tif hs_geo_s111120_z2_edges

# Slope and aspect (Float32, no-data -9999).
g slope "$utm" t.tif && f32 t.tif slope_utm
g slope -p -compute_edges "$holes" t.tif && f32 t.tif slope_percent_holes_edges
g slope -alg ZevenbergenThorne "$holes" t.tif && f32 t.tif slope_zt_holes
g slope -s 111120 "$geo" t.tif && f32 t.tif slope_geo_s111120
g aspect "$holes" t.tif && f32 t.tif aspect_holes
g aspect -trigonometric -zero_for_flat -compute_edges "$geo" t.tif && f32 t.tif aspect_trig_zero_geo_edges
g aspect -alg ZevenbergenThorne -compute_edges "$holes" t.tif && f32 t.tif aspect_zt_holes_edges

# Colour relief (RGB or RGBA Byte).
g color-relief "$holes" "$colors" t.tif && png t.tif cr_holes
g color-relief -alpha "$holes" "$colors" t.tif && png t.tif cr_alpha_holes
g color-relief -exact_color_entry -alpha "$geo" "$exact" t.tif && png t.tif cr_exact_alpha_geo
g color-relief -nearest_color_entry "$holes" "$colors" t.tif && png t.tif cr_nearest_holes

# Roughness indices (Float32, no-data -9999).
g TRI "$holes" t.tif && f32 t.tif tri_riley_holes
g TRI -alg Wilson -compute_edges "$holes" t.tif && f32 t.tif tri_wilson_holes_edges
g TPI "$holes" t.tif && f32 t.tif tpi_holes
g TPI -compute_edges "$geo" t.tif && f32 t.tif tpi_geo_edges
g roughness -compute_edges "$holes" t.tif && f32 t.tif roughness_holes_edges
g roughness "$utm" t.tif && f32 t.tif roughness_utm
rm -f "$here"/*.aux.xml "$out"/*.aux.xml
