#!/bin/sh
# The flight-view study on a real DEM: SRTM tile N44W072 (crates/terrain/tests/data) draped with a
# shaded-relief texture that GDAL makes from the same tile (gdaldem color-relief with
# relief_colours.txt, times 0.35 + 0.9 x gdaldem hillshade -z 2). Writes this folder's
# results.{csv,json}, summary.md and charts. Needs gdal-bin (gdaldem, gdal_calc.py, gdal_merge.py)
# and a release `texmap` on PATH.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
hgt="$here/../../../crates/terrain/tests/data/N44W072.hgt"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$hgt" "$work/N44W072.hgt"
cd "$work"
gdaldem hillshade -q -z 2 -compute_edges N44W072.hgt hs.tif
gdaldem color-relief -q N44W072.hgt "$here/relief_colours.txt" cr.tif
for b in 1 2 3; do
  gdal_calc.py --quiet -A cr.tif --A_band=$b -B hs.tif --outfile=b$b.tif --type=Byte \
    --calc="numpy.clip(A*(0.35+0.9*B/255.0),0,255)" --overwrite
done
gdal_merge.py -q -separate -o relief.tif b1.tif b2.tif b3.tif
texmap terrain build --dem N44W072.hgt --photo relief.tif --max-error 2 --out db -q
texmap terrain compare db --out study -q
cp study/results.csv study/results.json study/summary.md study/*.svg "$here/"
