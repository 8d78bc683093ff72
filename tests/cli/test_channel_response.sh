#!/usr/bin/env bash
# Measured channel responses through the command line: validate prints each channel's
# centre (THz), FWHM, B_c and B_n (GHz) for a top-hat, a triangle from a CSV file and a
# Gaussian (closed forms); an itu-p676 atmosphere is tabulated over a table's band;
# simulate writes summary.json's response keys and the ENVI fwhm; render refuses the
# saved photon map once a response changes and takes it while it does not; a bad
# response exits 2 naming the JSON path.
# usage: test_channel_response.sh THZMAP_BINARY REPO_DIR
set -u
thzmap=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0

fail() {
    echo "FAIL: $*"
    failures=$((failures + 1))
}

expect_line() {
    grep -Eq -- "$2" "$1" || fail "no line matching '$2' in $(basename "$1"):" "$(cat "$1")"
}

# scene HAT_HI_THZ ATMOSPHERE: a black box with a grey plate; channels: a top-hat
# 0.34..HAT_HI THz, a triangle 0.58/0.60/0.62 THz (peak 2 in the file), a 1 % Gaussian.
scene() {
    cat <<JSON
{"format": "thzmap-scene/1", "name": "responses",
 "channels": [{"name": "hat", "response": [[0.34, 1], [$1, 1]]},
              {"name": "tri", "response_file": "tri.csv"},
              {"name": "gauss", "frequency_thz": 0.35, "relative_width": 0.01}],
 "materials": {"black": {"reflectivity": 0}, "grey": {"reflectivity": 0.3}},
 "atmosphere": $2,
 "objects": [
   {"name": "room", "type": "solid", "material": "black", "temperature_k": 300,
    "shape": {"type": "box", "size_m": [1, 1, 1], "inward": true}},
   {"name": "plate", "type": "solid", "material": "grey", "temperature_k": 320,
    "shape": {"type": "rectangle", "size_m": [0.5, 0.5]},
    "transform": {"rotate_deg": [90, 0, 0]}}],
 "sensors": [{"name": "cam", "position_m": [0, -0.4, 0], "direction": [0, 1, 0],
   "fov_deg": 40, "resolution": [4, 4]}],
 "photons": {"per_channel": 3000, "seed": 2}}
JSON
}
printf '# triangle\nfrequency_thz,weight\n0.58,0\n0.60,2\n0.62,0\n' >"$tmp/tri.csv"
scene 0.36 '{"model": "none"}' >"$tmp/scene.json"

"$thzmap" validate "$tmp/scene.json" >"$tmp/out" 2>"$tmp/err" || fail "validate: $(cat "$tmp/err")"
# top-hat: B_c = B_n = FWHM = 20 GHz, centre its middle; triangle of base 40 GHz and
# peak 2: B_c = 40, B_n = 30, FWHM 20 GHz, centre its centroid 0.6 THz; 1 % Gaussian at 0.35 THz:
# FWHM 3.5, B_c = 1.0645 FWHM = 3.726, B_n = 1.5054 FWHM = 5.269 GHz
expect_line "$tmp/out" 'hat +centre 0\.3500 THz +FWHM 20\.000 GHz +bandwidth B_c 20\.000 GHz +noise bandwidth B_n 20\.000 GHz +measured response \(2 points\)'
expect_line "$tmp/out" 'tri +centre 0\.6000 THz +FWHM 20\.000 GHz +bandwidth B_c 40\.000 GHz +noise bandwidth B_n 30\.000 GHz +measured response \(3 points\)'
expect_line "$tmp/out" 'gauss +centre 0\.3500 THz +FWHM 3\.500 GHz +bandwidth B_c 3\.726 GHz +noise bandwidth B_n 5\.269 GHz +Gaussian'

# an atmosphere model tabulated over the measured bands
scene 0.36 '{"model": "itu-p676", "temperature_k": 293, "pressure_hpa": 1013, "relative_humidity": 0.5}' >"$tmp/air.json"
"$thzmap" validate "$tmp/air.json" >"$tmp/out" 2>"$tmp/err" || fail "validate itu-p676: $(cat "$tmp/err")"

"$thzmap" simulate "$tmp/scene.json" -o "$tmp/sim" --integrator final-gather --save-photon-map \
    --quiet --threads 2 >/dev/null 2>"$tmp/err" || fail "simulate: $(cat "$tmp/err")"
python3 - "$tmp/sim/summary.json" <<'PY' || fail "summary.json's channel keys"
import json, sys
ch = json.load(open(sys.argv[1]))["channels"]
assert [c["response"] for c in ch] == ["table", "table", "gaussian"], ch
assert ch[0]["relative_width"] is None and ch[2]["relative_width"] == 0.01
assert abs(ch[1]["bandwidth_ghz"] - 40) < 1e-9 and abs(ch[1]["noise_bandwidth_ghz"] - 30) < 1e-9
PY
expect_line "$tmp/sim/cam.radiance.hdr" '^fwhm = \{20, 20, 3\.5\}'

"$thzmap" render "$tmp/scene.json" --photon-map "$tmp/sim/photon-map.thzpm" -o "$tmp/r1" \
    --integrator final-gather --quiet --threads 2 >/dev/null 2>"$tmp/err" || fail "render, same responses: $(cat "$tmp/err")"
scene 0.361 '{"model": "none"}' >"$tmp/other.json"
"$thzmap" render "$tmp/other.json" --photon-map "$tmp/sim/photon-map.thzpm" -o "$tmp/r2" \
    --integrator final-gather --quiet >/dev/null 2>"$tmp/err"
status=$?
[[ $status -eq 2 ]] || fail "render with another response: exit $status, expected 2"
expect_line "$tmp/err" 'another channel set \(frequencies, widths or responses differ'
[[ -e $tmp/r2 ]] && fail "render with another response left $tmp/r2 behind"

# a bad response: exit 2, the JSON path
sed 's/\[0.34, 1\]/[0.34, -1]/' "$tmp/scene.json" >"$tmp/bad.json"
"$thzmap" validate "$tmp/bad.json" >/dev/null 2>"$tmp/err"
status=$?
[[ $status -eq 2 ]] || fail "negative weight: exit $status, expected 2"
expect_line "$tmp/err" 'bad\.json: channels\[0\]\.response\[0\]\[1\]: expected a number >= 0, got -1'

[[ $failures -eq 0 ]] && echo "all channel response checks passed"
exit $((failures > 0))
