#!/usr/bin/env bash
# simulate --save-photon-map --ply-max-points N writes a PLY with exactly N points when
# more photons were stored, and refuses a cap of 0; uncapped, photon-map.ply read back
# by a generic PLY reader holds the photon map's photons (tests/cli/photon_ply.py).
. "$(dirname "$0")/lib.sh"
# unlike lib.sh's fail: the test stops at the first failure
fail() { echo "FAIL: $*"; exit 1; }

"$THZMAP" simulate "$REPO/examples/plate-in-box/scene.json" -o "$work/out" --integrator photon-map --photons 2000 \
    --save-photon-map --ply-max-points 100 --quiet || fail "simulate exited $?"
header=$(head -c 2000 "$work/out/photon-map.ply" | tr -d '\0' | sed -n '1,/end_header/p')
grep -q '^format binary_little_endian 1.0' <<<"$header" || fail "not a binary LE PLY: $header"
grep -q '^element vertex 100$' <<<"$header" || fail "expected 100 points: $header"
stored=$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['channels'][0]['photons_stored'])" "$work/out/summary.json")
[ "$stored" -gt 100 ] || fail "only $stored photons stored: the cap was not exercised"

# Uncapped: every photon, compared with photon-map.thzpm; two channels, and final-gather's
# deviation maps (from B(T0)): the sphere, colder than T0 (the room's), sends photons of
# negative power
cat >"$work/two.json" <<'JSON'
{"format": "thzmap-scene/1", "name": "two",
 "channels": [{"frequency_thz": 0.35, "relative_width": 0.01},
              {"frequency_thz": 0.7, "relative_width": 0.01}],
 "materials": {"wall": {"reflectivity": 0.1}, "paint": {"reflectivity": 0.3}},
 "objects": [
   {"name": "room", "type": "solid", "material": "wall", "temperature_k": 330,
    "shape": {"type": "box", "size_m": [1, 1, 1], "inward": true}},
   {"name": "target", "type": "solid", "material": "paint", "temperature_k": 280,
    "shape": {"type": "sphere", "radius_m": 0.2}}],
 "sensors": [{"name": "cam", "position_m": [0, -0.45, 0], "look_at_m": [0, 0, 0],
              "fov_deg": 40, "resolution": [8, 8]}],
 "render": {"integrator": "final-gather"},
 "photons": {"per_channel": 2000, "seed": 5}}
JSON
"$THZMAP" simulate "$work/two.json" -o "$work/all" --save-photon-map --quiet ||
    fail "simulate exited $?"
/usr/bin/python3 "$REPO/tests/cli/photon_ply.py" "$work/all" 2 2 --negative ||
    fail "photon-map.ply"

"$THZMAP" simulate "$REPO/examples/plate-in-box/scene.json" -o "$work/out2" \
    --save-photon-map --ply-max-points 0 --quiet 2>"$work/err"
status=$?
[ $status -eq 2 ] || fail "--ply-max-points 0: exit $status, expected 2"
grep -q -- "--ply-max-points" "$work/err" || fail "message does not name the option: $(cat "$work/err")"
[ ! -e "$work/out2" ] || [ -z "$(ls -A "$work/out2")" ] || fail "a refused run wrote files"
echo "1 passed, 0 failed"
