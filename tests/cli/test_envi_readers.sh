#!/usr/bin/env bash
# Real clients read thzmap's ENVI output: a tiny scene is simulated, then every header
# is opened with Spectral Python and GDAL (tests/cli/envi_readers.py), which must report
# the scene's channel names as band names, the channel centres in GHz, each quantity's
# `data units` and the truth maps' `data ignore value` (-1, where nothing is hit).
#   usage: test_envi_readers.sh THZMAP REPO
set -euo pipefail
thzmap=$1
repo=$2
py=/usr/bin/python3 # Debian's: python3-spectral and python3-gdal live there

for need in "$py" gdalinfo; do
    command -v "$need" >/dev/null || { echo "FAIL: $need is missing (scripts/install-deps.sh)"; exit 1; }
done
"$py" -c 'import spectral, numpy; from osgeo import gdal' ||
    { echo "FAIL: $py lacks spectral, numpy or osgeo (python3-spectral, python3-gdal)"; exit 1; }

tmp=$(mktemp -d "${TMPDIR:-/tmp}/thz-envi-readers-XXXXXX")
trap 'rm -rf "$tmp"' EXIT

# Two channels with names that are not the default ones, a closed box, two sensors in it
# and one above it looking away (nothing hit: the truth maps' ignore value).
cat >"$tmp/tiny.json" <<'JSON'
{
  "format": "thzmap-scene/1",
  "name": "tiny",
  "channels": [
    {"name": "low band", "frequency_thz": 0.35, "relative_width": 0.01},
    {"name": "high band", "frequency_thz": 0.7, "relative_width": 0.02}
  ],
  "materials": {
    "wall": {"reflectivity": 0.0},
    "paint": {"reflectivity": [[0.2, 0.05], [1.2, 0.3]], "color": [0.8, 0.2, 0.2]}
  },
  "objects": [
    {"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
     "shape": {"type": "box", "size_m": [1, 1, 1], "inward": true},
     "transform": {"translate_m": [0, 0, 0.5]}},
    {"name": "target", "type": "solid", "material": "paint", "temperature_k": 310,
     "shape": {"type": "cylinder", "radius_m": 0.15, "height_m": 0.6, "caps": true},
     "transform": {"translate_m": [0, 0, 0.01]}}
  ],
  "sensors": [
    {"name": "cam", "position_m": [0, -0.45, 0.3], "look_at_m": [0, 0, 0.3],
     "fov_deg": 60, "resolution": [8, 6]},
    {"name": "top", "position_m": [0, 0, 0.95], "direction": [0, 0, -1], "up": [0, 1, 0],
     "fov_deg": 70, "resolution": [5, 5], "normalize_to_k": 300},
    {"name": "sky", "position_m": [0, 0, 1.5], "direction": [0, 0, 1], "up": [0, 1, 0],
     "fov_deg": 30, "resolution": [3, 2]}
  ],
  "photons": {"per_channel": 20000, "seed": 3}
}
JSON

"$thzmap" validate "$tmp/tiny.json" >/dev/null
set +e
"$thzmap" simulate "$tmp/tiny.json" -o "$tmp/out" --quiet >"$tmp/stdout" 2>"$tmp/stderr"
rc=$?
set -e
if [ $rc -ne 0 ]; then
    echo "FAIL: thzmap simulate exited $rc:"
    cat "$tmp/stderr"
    exit 1
fi
"$py" "$repo/tests/cli/envi_readers.py" "$tmp/out" "$tmp/tiny.json"
