#!/bin/sh
# Seeds fuzz/corpus/<target>/ with the fixtures of crates/md-io/tests/data (files written by
# MDAnalysis; see the README there) and the GeoTIFFs of crates/terrain/tests/data (GDAL). Run from the repository root or from fuzz/.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
data="$here/../crates/md-io/tests/data"
for t in xtc trr dcd; do
    mkdir -p "$here/corpus/$t"
    cp "$data"/*."$t" "$here/corpus/$t/"
done
mkdir -p "$here/corpus/geotiff"
cp "$here"/../crates/terrain/tests/data/*.tif "$here/corpus/geotiff/"
ls -l "$here"/corpus/*
