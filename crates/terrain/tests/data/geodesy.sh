#!/bin/sh
# Reference coordinates written by GDAL's gdaltransform (PROJ) for tests/geodesy.rs: WGS 84
# longitude, latitude, height against UTM (EPSG:326xx north, 327xx south) and against
# earth-centred, earth-fixed X, Y, Z (EPSG:4978) and Web Mercator (EPSG:3857). Output:
# geodesy_gdal.txt, one point a line:
#   utm EPSG lon lat E N     or     ecef lon lat h X Y Z     or     merc lon lat X Y
set -eu
cd "$(dirname "$0")"
{
  utm() { # $1 = EPSG, then lon lat pairs
    epsg=$1; shift
    while [ $# -gt 0 ]; do
      out=$(echo "$1 $2 0" | gdaltransform -s_srs EPSG:4326 -t_srs EPSG:$epsg)
      set -- "$@"
      echo "utm $epsg $1 $2 $(echo "$out" | awk '{print $1, $2}')"
      shift 2
    done
  }
  utm 32619 -71.3033 44.2706 -72.0 45.0 -69.0 0.5 -66.2 60.0
  utm 32654 138.7274 35.3606 141.0 36.0 139.5 70.1
  utm 32733 15.0 -33.9 12.1 -20.0 17.9 -0.2
  for p in "-71.3033 44.2706 1917" "138.7274 35.3606 3776" "15.0 -33.9 10" "0 0 0" "-120 -89 -50"; do
    echo "ecef $p $(echo "$p" | gdaltransform -s_srs EPSG:4979 -t_srs EPSG:4978)"
  done
  for p in "-71.3033 44.2706" "138.7274 35.3606" "15.0 -33.9" "0 0" "-179.9 85.0" "120 -60"; do
    echo "merc $p $(echo "$p" | gdaltransform -s_srs EPSG:4326 -t_srs EPSG:3857 | awk '{print $1, $2}')"
  done
} > geodesy_gdal.txt
