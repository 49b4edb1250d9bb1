#!/bin/sh
# CesiumJS (the npm package `cesium`) drawing texmap's quantized-mesh export of the real SRTM tile
# N44W072 as the globe's terrain (CesiumTerrainProvider, lit by the tiles' oct-encoded normals,
# heights made ellipsoidal with PROJ's EGM96 grid), in headless Chromium (Debian's `chromium`,
# driven by playwright-core, with ../tiles3d/shot.mjs). Writes cesium_qmesh.png here and prints
# the summit height CesiumJS samples from the tiles.
# Needs: chromium, node/npm, proj-data's /usr/share/proj/egm96_15.gtx, a release build of texmap.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../../.." && pwd)
work=$(mktemp -d)
trap 'kill $server 2>/dev/null || true; rm -rf "$work"' EXIT
cd "$work"
texmap="$repo/target/release/texmap"
"$texmap" terrain build --dem "$repo/crates/terrain/tests/data/N44W072.hgt" --out srtm.db -q
"$texmap" terrain export srtm.db --quantized-mesh --geoid /usr/share/proj/egm96_15.gtx -o qm -q
npm init -y >/dev/null
npm install --silent --no-audit --no-fund cesium@1.140.0 playwright-core@1
cp "$here/view.html" "$here/../tiles3d/shot.mjs" .
python3 -m http.server 8766 --bind 127.0.0.1 >/dev/null 2>&1 &
server=$!
sleep 1
PORT=8766 node shot.mjs "" "$here/cesium_qmesh.png"
