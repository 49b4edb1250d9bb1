#!/bin/sh
# CesiumJS (the npm package `cesium`) drawing a 3D Tiles export of the real SRTM tile N44W072 on
# the WGS 84 globe, in headless Chromium (Debian's `chromium`, driven by playwright-core), with no
# base imagery (the globe is a flat colour). Writes cesium_srtm.png and cesium_srtm_near.png here.
# Needs: chromium (apt-get install chromium), node/npm, and a release build of texmap.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../../.." && pwd)
work=$(mktemp -d)
trap 'kill $server 2>/dev/null || true; rm -rf "$work"' EXIT
cd "$work"
texmap="$repo/target/release/texmap"
"$texmap" terrain build --dem "$repo/crates/terrain/tests/data/N44W072.hgt" --out srtm.db -q
"$texmap" terrain export srtm.db --3d-tiles -o tiles -q
npm init -y >/dev/null
npm install --silent --no-audit --no-fund cesium@1.140.0 playwright-core@1
cp "$here/view.html" "$here/shot.mjs" .
python3 -m http.server 8765 --bind 127.0.0.1 >/dev/null 2>&1 &
server=$!
sleep 1
node shot.mjs "" "$here/cesium_srtm.png"
node shot.mjs "?range=9000&pitch=-20" "$here/cesium_srtm_near.png"
