#!/bin/sh
# The flight-view study on a real orthophoto over its real surface model: a drone survey of a field
# trial processed by OpenDroneMap (dsm.tif: 395 x 407 Float32 samples 0.27 m apart, UTM 16N, LZW,
# nodata -3.4e38; odm_orthophoto.tif: 535 x 550 x 3 Float32 bands 0.2 m, band-planar, same nodata),
# from the public FIELDimageR workshop repository (not redistributed here: it is fetched). Writes this
# folder's results.{csv,json}, summary.md and charts, and ../../images/drone_trilinear.png.
# Needs git, network access and a release `texmap` on PATH; ~60 s.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
git clone -q https://github.com/filipematias23/FIELDimageR-Workshop-10 src
git -C src checkout -q df52c1de6038c6d0edb96809dcc05c8318296ed0
# The field's relief is ~2 m: a 5 cm bound keeps the mesh's own error below the texture's.
texmap terrain build --dem src/dsm.tif --photo src/odm_orthophoto.tif --max-error 0.05 --out db -q
texmap terrain compare db --out study -q
cp study/results.csv study/results.json study/summary.md study/*.svg "$here/"
texmap terrain render db --size 640x480 --pitch -30 --altitude 300 -o "$here/../../images/drone_trilinear.png" -q
