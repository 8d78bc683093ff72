#!/usr/bin/env bash
# A newcomer's run (issue 13): scene warnings for the usual unit, placement and winding mistakes
# (each triggered by a scene made for it, none on the shipped examples), warnings printed
# in full on stderr also with --quiet, the estimate before the run, the noise figures
# (median and 95th percentile per channel and per object, the noisiest object named on
# the last line with its unit) and the command-line items (--photons 1e6, an option
# given as a value, a run too large for the machine exits 2).
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"

# variants of one small scene: NAME and a Python statement changing the dict `s`
make_scene() {
python3 - "$work/$1.json" "$2" <<'PY'
import json, sys
s = {"format": "thzmap-scene/1",
     "channels": [{"frequency_thz": 0.35, "relative_width": 0.02}],
     "materials": {"wall": {"reflectivity": 0.1}, "metal": {"reflectivity": 0.9}},
     "atmosphere": {"model": "constant", "attenuation_per_m": 0.05},
     "objects": [
       {"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
        "shape": {"type": "box", "size_m": [2, 2, 2], "inward": True}},
       {"name": "target", "type": "solid", "material": "metal", "temperature_k": 310,
        "shape": {"type": "box", "size_m": [0.4, 0.4, 0.4]},
        "transform": {"translate_m": [0, 0.5, 0]}}],
     "sensors": [{"name": "cam", "position_m": [0, -0.9, 0], "direction": [0, 1, 0],
                  "fov_deg": 60, "resolution": [12, 10]}]}
exec(sys.argv[2])
json.dump(s, open(sys.argv[1], "w"))
PY
}

make_scene plain "pass"
make_scene celsius "s['objects'][0]['temperature_k'] = 22; s['objects'][1]['temperature_k'] = 37"
make_scene millimetres "s['objects'][1]['transform']['scale'] = 1000"
make_scene ghz "s['channels'][0]['frequency_thz'] = 350"
# (two channels: the run warning counts the samples of both, 2 x 12 x 10)
make_scene outside "s['sensors'][0]['position_m'] = [0, -3, 0]; s['channels'].append({'frequency_thz': 0.5, 'relative_width': 0.02})"
make_scene inside "s['sensors'][0]['position_m'] = [0, 0.5, 0]"
make_scene nonemitting "s['atmosphere']['emitting'] = False"
make_scene background "s['atmosphere']['background_temperature_k'] = 3"
# an aperture area no circle of the given diameter has (0.05 m^2 > pi 0.1^2 / 4)
make_scene aperture "s['sensors'][0].update(aperture_m2=0.05, aperture_diameter_m=0.1)"
# but not the circle's own area rounded up to four digits, nor less (an obstructed aperture)
make_scene circle "s['sensors'][0].update(aperture_m2=0.007854, aperture_diameter_m=0.1)"
make_scene obstructed "s['sensors'][0].update(aperture_m2=0.006, aperture_diameter_m=0.1)"
# a bolt 4 cm long drawn in millimetres: 42 m across, 12 times the room (the ratio of 100
# to the median object or the enclosure let it pass; an object cannot be 10 times the room
# it stands in)
make_scene bolt "s['objects'].append({'name': 'bolt', 'type': 'solid', 'material': 'metal', 'temperature_k': 300, 'shape': {'type': 'cylinder', 'radius_m': 0.005, 'height_m': 0.04}, 'transform': {'scale': 1000}})"
# a solid whose normals point inwards (a mesh wound clockwise, here a box given inward)
# in the room: seen from outside, only back faces (radiance 0); validate said nothing
make_scene inverted "s['objects'][1]['shape']['inward'] = True"
# and a second one beside it, a crate (the run's warning names both)
make_scene inverted2 "s['objects'][1]['shape']['inward'] = True; s['objects'].append({'name': 'crate', 'type': 'solid', 'material': 'metal', 'temperature_k': 300, 'shape': {'type': 'box', 'size_m': [0.3, 0.3, 0.3], 'inward': True}, 'transform': {'translate_m': [-0.6, 0.5, 0]}})"
# the room without inward: the sensor is inside a solid, and the warning must not only
# say to move the sensor out of the room
make_scene outward "del s['objects'][0]['shape']['inward']"
# a material table in GHz under a frequency_thz heading: the warning that the channel
# leaves the table says so (it gave only the ranges, 300 to 400 THz against 0.35 THz)
make_scene ghztable "s['materials']['wall']['reflectivity'] = [[300, 0.1], [400, 0.12]]"
# the same for a table of n and k (format 1.1)
make_scene ghzindex "s['format'] = 'thzmap-scene/1.1'; s['materials']['metal'] = {'refractive_index': [[300, 3, 0.1], [400, 3, 0.2]]}"
# a box's size in millimetres: the warning does not speak of a mesh alone
make_scene sizemm "s['objects'][1]['shape']['size_m'] = [400, 400, 400]"
# a position in centimetres: the target 50 m away, outside the room, seen by no sensor
make_scene centimetres "s['objects'][1]['transform']['translate_m'] = [0, 50, 0]"
# the whole scene 1000 km from the origin: single precision blurs it to 0.12 m
make_scene far "
for o in s['objects']:
    t = o.setdefault('transform', {}); x = t.get('translate_m', [0, 0, 0]); t['translate_m'] = [x[0] + 1e6, x[1], x[2]]
s['sensors'][0]['position_m'][0] += 1e6"

check_warning() { # $1: scene, $2: text the warning must contain
    "$THZMAP" validate "$work/$1.json" > /dev/null 2> "$work/$1.err" ||
        fail "$1: validate failed: $(cat "$work/$1.err")"
    grep -q "^thzmap validate: warning: .*$2" "$work/$1.err" || fail "$1: no warning with '$2': $(cat "$work/$1.err")"
}
check_warning celsius "look like degrees Celsius"
check_warning millimetres "scales differ by orders of magnitude"
check_warning bolt 'object "bolt" is 42.4 m across, 12 times the enclosure "room" .*millimetres'
check_warning inverted 'object "target" is closed with its normals pointing inwards, as a room.s, but no sensor is inside it'
check_warning outward 'sensor "cam" .* is inside object "room" .*"inward": true on a box'
check_warning centimetres 'object "target" (bounds \[-0.2, 49.8, -0.2\] to \[0.2, 50.2, 0.2\] m) lies wholly outside "room"'
check_warning ghz "outside 0.05 to 10 THz"
check_warning sizemm 'object "target" is 693 m across, 200 times the enclosure "room" .*is a mesh or a size in millimetres'
check_warning ghzindex 'materials.metal: the table of n and k covers 300 to 400 THz (a table beyond 10 THz: are its frequencies in GHz?'
check_warning ghztable 'material "wall", reflectivity: the table covers 300 to 400 THz (a table beyond 10 THz: are its frequencies in GHz? frequency_thz is in THz, 300 GHz = 0.3 THz) but channel'
check_warning outside 'sensor "cam" .* is outside the enclosure "room"'
check_warning inside 'sensor "cam" .* is inside object "target"'
check_warning nonemitting "breaks equilibrium"
check_warning background "no ray leaves the scene"
check_warning aperture 'sensors\[0\]\.aperture_m2: 0\.05 m^2 is more than a circular aperture of aperture_diameter_m 0\.1 m can have (pi D^2 / 4 = 0\.00785398 m^2)'
for v in circle obstructed; do
    "$THZMAP" validate "$work/$v.json" > /dev/null 2> "$work/$v.err" || fail "$v: $(cat "$work/$v.err")"
    [ -s "$work/$v.err" ] && fail "$v aperture warns: $(cat "$work/$v.err")"
done
check_warning far 'the objects lie up to 1e+06 m from the origin, .* times the scene.s size .*single precision'
# but not a 2 mm pellet in the room: small, yet among the objects around the origin
make_scene pellet "s['objects'].append({'name': 'pellet', 'type': 'solid', 'material': 'metal', 'temperature_k': 300, 'shape': {'type': 'sphere', 'radius_m': 0.001}, 'transform': {'translate_m': [0.5, 0.5, 0.5]}})"
"$THZMAP" validate "$work/pellet.json" > /dev/null 2> "$work/pellet.err" || fail "pellet: $(cat "$work/pellet.err")"
[ -s "$work/pellet.err" ] && fail "a 2 mm pellet in the room warns: $(cat "$work/pellet.err")"
"$THZMAP" validate "$work/plain.json" > /dev/null 2> "$work/plain.err"
[ -s "$work/plain.err" ] && fail "the plain scene warns: $(cat "$work/plain.err")"
for ex in "$REPO"/examples/*/scene.json; do
    "$THZMAP" validate "$ex" > /dev/null 2> "$work/ex.err" || fail "$ex does not validate"
    [ -s "$work/ex.err" ] && fail "$ex warns: $(cat "$work/ex.err")"
done

# --- warnings on stderr in full, also with --quiet; the misplaced sensor's back faces
# are not blamed on the normals ------------------------------------------------------------
"$THZMAP" simulate "$work/outside.json" -o "$work/out-outside" --quiet \
    > "$work/o.out" 2> "$work/o.err" || fail "simulate outside: $(cat "$work/o.err")"
grep -q "warning: sensor \"cam\" .* is outside the enclosure" "$work/o.err" ||
    fail "--quiet hid the scene warning: $(cat "$work/o.err")"
grep -q "warning: sensor 'cam': [1-9][0-9]* of 240 samples saw the back side" "$work/o.err" ||
    fail "the run warning is not printed in full, or not of both channels' 240 samples: $(cat "$work/o.err")"
grep -q "mesh normals" "$work/o.err" && fail "a misplaced sensor's warning blames the normals"
grep -q "see .*summary.json" "$work/o.err" && fail "warnings point to summary.json instead"
grep -q "channel 1/1" "$work/o.err" && fail "--quiet printed progress"
# the run's back-face warning names the solid seen from the back, as validate does (it
# said "a one-sided solid"), and of several the first and the last in the scene
for v in inverted inverted2; do
    "$THZMAP" simulate "$work/$v.json" -o "$work/out-$v" --integrator path --quiet \
        2> "$work/$v-run.err" || fail "simulate $v: $(cat "$work/$v-run.err")"
done
grep -q "warning: sensor 'cam': [1-9][0-9]* of 120 samples saw the back side of one-sided solid 'target' (radiance 0); check its mesh normals" \
    "$work/inverted-run.err" || fail "an inverted target not named: $(cat "$work/inverted-run.err")"
grep -q "warning: sensor 'cam': [1-9][0-9]* of 120 samples saw the back side of one-sided solids, among them 'target' and 'crate' (radiance 0); check their mesh normals" \
    "$work/inverted2-run.err" || fail "two inverted solids not named: $(cat "$work/inverted2-run.err")"

# --- estimate, noise figures, last line ---------------------------------------------------
"$THZMAP" simulate "$work/plain.json" -o "$work/out-plain" > "$work/p.out" 2> "$work/p.err" ||
    fail "simulate plain: $(cat "$work/p.err")"
grep -q "estimate: .* s .*memory .* GiB" "$work/p.err" || fail "no estimate: $(cat "$work/p.err")"
tail -1 "$work/p.out" | grep -q "noisiest object: '.*', 95th percentile standard error [0-9.e-]* K" ||
    fail "last line: $(tail -1 "$work/p.out")"
python3 - "$work/out-plain/summary.json" "$work/p.out" <<'PY' || fail "summary.json noise figures"
import json, re, sys
d = json.load(open(sys.argv[1]))
# the last line names the object of the largest 95th percentile over channels, its value
last = open(sys.argv[2]).read().splitlines()[-1]
m = re.search(r"noisiest object: '(.*)', 95th percentile standard error ([0-9.e+-]*) K", last)
worst = max((o["p95_stderr_k"], o["name"]) for c in d["channels"] for o in c["objects"]
            if o["pixels"] > 0)
assert m and m.group(1) == worst[1] and abs(float(m.group(2)) - worst[0]) <= 5e-3 * worst[0], \
    (last, worst)
# the line before it gives the worst median and the worst 95th percentile over the
# channels, each in its place
first = open(sys.argv[2]).read().splitlines()[-2]
m = re.search(r"pixel standard error: median <= ([0-9.e+-]*) K, 95th percentile <= ([0-9.e+-]*) K",
              first)
want = (max(c["median_stderr_k"] for c in d["channels"]),
        max(c["p95_stderr_k"] for c in d["channels"]))
assert m and all(abs(float(g) - w) <= 5e-3 * w for g, w in zip(m.groups(), want)), (first, want)
assert d["integrator"] == "path", d["integrator"]
assert d["target_noise_k"] == 0.1 and d["target_noise_source"] == "default", d["target_noise_k"]
for c in d["channels"]:
    assert c["p95_stderr_k"] >= c["median_stderr_k"] >= 0, c
    assert c["p95_stderr_k"] <= 0.1, c  # the default target was reached
    objs = {o["name"]: o for o in c["objects"]}
    assert set(objs) == {"room", "target"}, objs
    assert objs["target"]["pixels"] > 0 and objs["room"]["pixels"] > 0
    assert objs["target"]["pixels"] + objs["room"]["pixels"] <= 12 * 10
    for o in objs.values():
        assert o["p95_stderr_k"] >= o["median_stderr_k"] >= 0, o
PY

# --- command line -------------------------------------------------------------------------
"$THZMAP" simulate "$work/plain.json" -o "$work/out-e" --integrator photon-map --photons 2e4 \
    --quiet > /dev/null 2> "$work/e.err" || fail "--photons 2e4 refused: $(cat "$work/e.err")"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['photons_per_channel'] == 20000 and d['target_noise_k'] is None" \
    "$work/out-e/summary.json" || fail "--photons 2e4: not 20000 photons in one pass"
"$THZMAP" simulate "$work/plain.json" -o "$work/out-f" --photons 2.5e4.5 2> /dev/null
[ $? -eq 2 ] || fail "--photons 2.5e4.5 should exit 2"
"$THZMAP" simulate "$work/plain.json" -o "$work/out-f" --photons 1.5 2> /dev/null
[ $? -eq 2 ] || fail "--photons 1.5 (not whole) should exit 2"
(cd "$work" && "$THZMAP" simulate plain.json -o --quiet 2> q.err)
[ $? -eq 2 ] || fail "-o --quiet should exit 2"
[ -e "$work/--quiet" ] && fail "-o --quiet created a directory named --quiet"
grep -q "needs a value" "$work/q.err" || fail "-o --quiet message: $(cat "$work/q.err")"
make_scene huge "s['sensors'][0]['resolution'] = [65536, 65536]; s['channels'] = {'from_thz': 0.2, 'to_thz': 1.2, 'count': 400, 'relative_width': 0.01}"
"$THZMAP" simulate "$work/huge.json" -o "$work/out-h" --quiet 2> "$work/h.err"
[ $? -eq 2 ] || fail "a run too large for the machine should exit 2"
grep -q "sensors\[0\].resolution" "$work/h.err" || fail "too large: $(cat "$work/h.err")"
"$THZMAP" simulate --help | grep -q "95th" || fail "--help does not say the target is the 95th percentile"

# photon-map and a narrow glossy lobe: warned, in summary.json too (it read half the
# radiance at alpha 0.001 with a standard error under 1 %, and had pixels 79 standard
# errors off at 0.15); not with a broad one, nor with final-gather
for a in 0.03 0.15 0.5; do
    make_scene "ward-$a" "s['materials']['metal']['reflection'] = {'model': 'ward', 'alpha_x': $a, 'alpha_y': 0.5}"
done
# a narrow lobe in a material that no object uses: no warning (it shapes no image)
make_scene ward-unused "s['materials']['spare'] = {'reflectivity': 0.9, 'reflection': {'model': 'ward', 'alpha_x': 0.03, 'alpha_y': 0.5}}"
glossy() { # $1: scene, $2: integrator; prints the warnings in summary.json matching "glossy lobe"
    "$THZMAP" simulate "$work/$1.json" -o "$work/out-$1-$2" --integrator "$2" --photons 2000 \
        --quiet 2> "$work/g.err" || fail "$1 $2: $(cat "$work/g.err")"
    python3 -c "import json,sys; print(sum('glossy lobe' in w for w in json.load(open(sys.argv[1]))['warnings']))" \
        "$work/out-$1-$2/summary.json"
}
[ "$(glossy ward-0.03 photon-map)" = 1 ] || fail "photon-map, Ward alpha 0.03: no warning in summary.json"
grep -q 'material "metal": photon-map cannot resolve its glossy lobe (alpha 0.03' "$work/g.err" ||
    fail "photon-map, Ward alpha 0.03: no warning on stderr: $(cat "$work/g.err")"
[ "$(glossy ward-0.15 photon-map)" = 1 ] || fail "photon-map, Ward alpha 0.15: no warning (pixels 79 standard errors off)"
[ "$(glossy ward-0.5 photon-map)" = 0 ] || fail "photon-map, Ward alpha 0.5: warned"
[ "$(glossy ward-0.03 final-gather)" = 0 ] || fail "final-gather, Ward alpha 0.03: warned"
[ "$(glossy ward-unused photon-map)" = 0 ] || fail "photon-map, Ward alpha 0.03 in a material no object uses: warned"

# one path a sample: a pass gives each pixel one estimate, whose spread is unknown, not 0 K.
# Towards a target the passes go on past the first (it stopped there, "0 K", target met;
# in this room, at T0 but for the metal that mirrors it, 0 K is then the true spread);
# without one (a count given: no default target) one pass is rendered, its standard
# errors reported as 0 K (scene-format.md says so).
make_scene onepath "s['render'] = {'integrator': 'path', 'paths_per_sample': 1, 'target_noise_k': 0.5}"
"$THZMAP" simulate "$work/onepath.json" -o "$work/out-onepath" --quiet 2> "$work/op.err" ||
    fail "one path, target: $(cat "$work/op.err")"
python3 - "$work/out-onepath/summary.json" <<'PY' || fail "one path a sample, towards 0.5 K"
import json, sys
c = json.load(open(sys.argv[1]))["channels"][0]
assert c["render_passes"] >= 2 and 0 <= c["p95_stderr_k"] <= 0.5, c
PY
# without the target: one pass, its standard errors read 0 K, and the run says they are
# not estimated (it did not: a cube of zeros passed for exact pixels); 2 paths do not
make_scene onepass "s['render'] = {'integrator': 'path', 'paths_per_sample': 1}"
make_scene twopaths "s['render'] = {'integrator': 'path', 'paths_per_sample': 2}"
for v in onepass twopaths; do
    "$THZMAP" simulate "$work/$v.json" -o "$work/out-$v" --quiet 2>"$work/$v.err" ||
        fail "$v: $(cat "$work/$v.err")"
done
expect_line "$work/onepass.err" "^thzmap simulate: warning: the standard errors are not estimated: paths_per_sample 1 in one pass"
grep -q 'not estimated' "$work/out-onepass/summary.json" ||
    fail "one path a sample, one pass: summary.json's warnings do not say the errors are not estimated"
grep -q 'not estimated' "$work/twopaths.err" "$work/out-twopaths/summary.json" &&
    fail "two paths a sample: warned that the errors are not estimated"

finish "honest defaults: all checks passed"
