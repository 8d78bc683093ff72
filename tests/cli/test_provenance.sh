#!/usr/bin/env bash
# A run can be reproduced from its outputs: summary.json records what made the images,
# the scene's fingerprint (its geometry, optics and channels, and `run`: those with the
# sensors and the photon and render settings), the seed, the integrator and its settings
# (photons_per_channel, paths_per_sample, gather_rays, gather_min_photons,
# min_relative_power, target_noise_k, max_seconds); a rerun from what it records alone,
# on another thread count, writes the same files with the same fingerprint. A scene
# whose physics differs has another fingerprint; one renamed and recoloured the same.
# `thzmap validate` prints a scene file's fingerprint. (Before, summary.json named the
# scene's file and name only, and none of the render settings: an output could not be
# told from one of an edited scene.)
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"

# scene NAME PYTHON: a variant of one small scene, the statement changing the dict `s`
scene() {
    python3 - "$work/$1.json" "$2" <<'PY'
import json, sys
s = {"format": "thzmap-scene/1", "name": "provenance",
     "channels": [{"frequency_thz": 0.35, "relative_width": 0.02}],
     "materials": {"wall": {"reflectivity": 0.2}, "paint": {"reflectivity": 0.5}},
     "objects": [
       {"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
        "shape": {"type": "box", "size_m": [2, 2, 2], "inward": True}},
       {"name": "plate", "type": "solid", "material": "paint", "temperature_k": 310,
        "shape": {"type": "box", "size_m": [0.5, 0.05, 0.5]}}],
     "sensors": [{"name": "cam", "position_m": [0, -0.9, 0], "look_at_m": [0, 0, 0],
                  "fov_deg": 40, "resolution": [8, 6]}],
     "render": {"gather_rays": 4},
     "photons": {"per_channel": 20000, "seed": 5, "gather_min_photons": 12}}
exec(sys.argv[2])
json.dump(s, open(sys.argv[1], "w"))
PY
}
scene base "pass"
scene renamed "s['name'] = 'other'; s['materials']['lacquer'] = s['materials'].pop('paint');
s['materials']['lacquer']['color'] = [1, 0, 0]; s['objects'][1]['material'] = 'lacquer'"
scene warmer "s['objects'][1]['temperature_k'] = 311"
scene rays "s['render']['gather_rays'] = 8"
scene moved "s['objects'][1]['transform'] = {'translate_m': [0, 0.01, 0]}"

"$THZMAP" simulate "$work/base.json" -o "$work/a" -q --threads 1 --integrator final-gather \
    --seed 11 --photons 10000 || fail "simulate: exit $?"

# what summary.json records, as the rerun's command line and as KEY=VALUE lines
python3 - "$work/a/summary.json" >"$work/recorded" <<'PY' || fail "summary.json lacks a record"
import json, sys
s = json.load(open(sys.argv[1]))
print("args", s["scene"]["path"], "--seed", s["seed"], "--integrator", s["integrator"],
      "--photons", s["photons_per_channel"])
for k in ("seed", "integrator", "photons_per_channel", "paths_per_sample", "gather_rays",
          "gather_min_photons", "min_relative_power", "target_noise_k", "max_seconds"):
    print(k, json.dumps(s[k]))
f = s["scene"]["fingerprint"]
print("fingerprint", f["geometry"], f["optics"], f["channels"], f["run"])
PY
for want in 'seed 11' 'integrator "final-gather"' 'photons_per_channel 10000' \
    'paths_per_sample 16' 'gather_rays 4' 'gather_min_photons 12' \
    'min_relative_power 0.01' 'target_noise_k null' 'max_seconds null'; do
    grep -qx "$want" "$work/recorded" || fail "summary.json does not record $want:" \
        "$(cat "$work/recorded")"
done
read -r -a rerun <<<"$(sed -n 's/^args //p' "$work/recorded")"
"$THZMAP" simulate "${rerun[@]}" -o "$work/b" -q --threads 2 ||
    fail "the rerun from summary.json (${rerun[*]}): exit $?"
diff -r -q --exclude=summary.json "$work/a" "$work/b" >"$work/diff" ||
    fail "the rerun from summary.json's record wrote other files: $(cat "$work/diff")"

# fingerprint DIR: its four hashes on one line
fingerprint() {
    python3 -c 'import json, sys; f = json.load(open(sys.argv[1]))["scene"]["fingerprint"]
print(f["geometry"], f["optics"], f["channels"], f["run"])' "$1/summary.json"
}
base=$(sed -n 's/^fingerprint //p' "$work/recorded")
[ "$(fingerprint "$work/b")" = "$base" ] || fail "the rerun's fingerprint differs"
for v in renamed warmer rays moved; do
    "$THZMAP" simulate "$work/$v.json" -o "$work/$v" -q --threads 2 --integrator final-gather \
        --seed 11 --photons 10000 || fail "simulate $v: exit $?"
done
read -r g o c r <<<"$base"
read -r g2 o2 c2 r2 <<<"$(fingerprint "$work/renamed")"
[ "$g2 $o2 $c2 $r2" = "$base" ] || fail "renamed and recoloured: another fingerprint"
read -r g2 o2 c2 r2 <<<"$(fingerprint "$work/warmer")"
if ! { [ "$g2" = "$g" ] && [ "$o2" != "$o" ] && [ "$c2" = "$c" ] && [ "$r2" != "$r" ]; }; then
    fail "a plate 1 K warmer: fingerprint $g2 $o2 $c2 $r2 against $base"
fi
read -r g2 o2 c2 r2 <<<"$(fingerprint "$work/rays")"
if ! { [ "$g2 $o2 $c2" = "$g $o $c" ] && [ "$r2" != "$r" ]; }; then
    fail "gather_rays 8: fingerprint $g2 $o2 $c2 $r2 against $base"
fi
read -r g2 o2 c2 r2 <<<"$(fingerprint "$work/moved")"
if ! { [ "$g2" != "$g" ] && [ "$o2 $c2" = "$o $c" ]; }; then
    fail "a plate moved 1 cm: fingerprint $g2 $o2 $c2 $r2 against $base"
fi
# validate prints the fingerprint a scene file has, to match with an output's: the run
# hash is of the scene's own integrator (path here; the runs above were given another)
"$THZMAP" validate "$work/base.json" >"$work/validate.out" || fail "validate: exit $?"
"$THZMAP" simulate "$work/base.json" -o "$work/own" -q --threads 2 || fail "simulate own: exit $?"
read -r g2 o2 c2 r2 <<<"$(fingerprint "$work/own")"
expect_line "$work/validate.out" \
    "^fingerprint: geometry $g, optics $o, channels $c, run $r2 \\(summary.json's"
[ "$g2 $o2 $c2" = "$g $o $c" ] || fail "the path run's fingerprint differs in its physics"
finish "summary.json records the scene's fingerprint and settings; a rerun from it writes the same files"
