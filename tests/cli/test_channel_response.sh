#!/usr/bin/env bash
# Measured channel responses through the command line: validate prints each channel's
# centre (THz), FWHM, B_c and B_n (GHz) for a top-hat, a triangle from a CSV file and a
# Gaussian (closed forms); an itu-p676 atmosphere is tabulated over a table's band;
# simulate writes summary.json's response keys and the ENVI fwhm; render refuses the
# saved photon map once a response changes and takes it while it does not; a bad
# response exits 2 naming the JSON path.
# usage: test_channel_response.sh THZMAP_BINARY REPO_DIR
. "$(dirname "$0")/lib.sh"

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
printf '# triangle\nfrequency_thz,weight\n0.58,0\n0.60,2\n0.62,0\n' >"$work/tri.csv"
scene 0.36 '{"model": "none"}' >"$work/scene.json"

"$THZMAP" validate "$work/scene.json" >"$work/out" 2>"$work/err" || fail "validate: $(cat "$work/err")"
# top-hat: B_c = B_n = FWHM = 20 GHz, centre its middle; triangle of base 40 GHz and
# peak 2: B_c = 40, B_n = 30, FWHM 20 GHz, centre its centroid 0.6 THz; 1 % Gaussian at 0.35 THz:
# FWHM 3.5, B_c = 1.0645 FWHM = 3.726, B_n = 1.5054 FWHM = 5.269 GHz
expect_line "$work/out" 'hat +centre 0\.3500 THz +FWHM 20\.000 GHz +bandwidth B_c 20\.000 GHz +noise bandwidth B_n 20\.000 GHz +measured response \(2 points\)'
expect_line "$work/out" 'tri +centre 0\.6000 THz +FWHM 20\.000 GHz +bandwidth B_c 40\.000 GHz +noise bandwidth B_n 30\.000 GHz +measured response \(3 points\)'
expect_line "$work/out" 'gauss +centre 0\.3500 THz +FWHM 3\.500 GHz +bandwidth B_c 3\.726 GHz +noise bandwidth B_n 5\.269 GHz +Gaussian'

# an atmosphere model tabulated over the measured bands
scene 0.36 '{"model": "itu-p676", "temperature_k": 293, "pressure_hpa": 1013, "relative_humidity": 0.5}' >"$work/air.json"
"$THZMAP" validate "$work/air.json" >"$work/out" 2>"$work/err" || fail "validate itu-p676: $(cat "$work/err")"

"$THZMAP" simulate "$work/scene.json" -o "$work/sim" --integrator final-gather --save-photon-map \
    --quiet --threads 2 >/dev/null 2>"$work/err" || fail "simulate: $(cat "$work/err")"
python3 - "$work/sim/summary.json" <<'PY' || fail "summary.json's channel keys"
import json, sys
ch = json.load(open(sys.argv[1]))["channels"]
assert [c["response"] for c in ch] == ["table", "table", "gaussian"], ch
assert ch[0]["relative_width"] is None and ch[2]["relative_width"] == 0.01
assert abs(ch[1]["bandwidth_ghz"] - 40) < 1e-9 and abs(ch[1]["noise_bandwidth_ghz"] - 30) < 1e-9
PY
expect_line "$work/sim/cam.radiance.hdr" '^fwhm = \{20, 20, 3\.5\}'

"$THZMAP" render "$work/scene.json" --photon-map "$work/sim/photon-map.thzpm" -o "$work/r1" \
    --integrator final-gather --quiet --threads 2 >/dev/null 2>"$work/err" || fail "render, same responses: $(cat "$work/err")"
scene 0.361 '{"model": "none"}' >"$work/other.json"
"$THZMAP" render "$work/other.json" --photon-map "$work/sim/photon-map.thzpm" -o "$work/r2" \
    --integrator final-gather --quiet >/dev/null 2>"$work/err"
status=$?
[[ $status -eq 2 ]] || fail "render with another response: exit $status, expected 2"
expect_line "$work/err" 'another channel set \(frequencies, widths or responses differ'
[[ -e $work/r2 ]] && fail "render with another response left $work/r2 behind"

# a bad response: exit 2, the JSON path
sed 's/\[0.34, 1\]/[0.34, -1]/' "$work/scene.json" >"$work/bad.json"
"$THZMAP" validate "$work/bad.json" >/dev/null 2>"$work/err"
status=$?
[[ $status -eq 2 ]] || fail "negative weight: exit $status, expected 2"
expect_line "$work/err" 'bad\.json: channels\[0\]\.response\[0\]\[1\]: expected a number >= 0, got -1'

finish "all channel response checks passed"
