#!/usr/bin/env bash
# A run into an OUTDIR that an earlier run filled: what OUTDIR then holds of the run's
# sensors, photon map and figures is the new run's alone (scene-format.md "Exit status
# and atomic results"). The earlier run's files that the new one does not write went on
# standing beside it: a sensor's measured cubes after its noise was removed (classify and
# the GUI then read them as this run's), the figure of a channel the scene no longer has,
# a photon map beside a simulation that saved none (render read it as this run's),
# bands-air.png beside a band selection in clear air. The user's own files, another
# sensor's, and a photon map a render reads stay.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"

cp -r "$REPO/examples/plate-in-box/." "$work/"
# cam with noise, two channels, and a second sensor; then cam without noise, one channel
python3 - "$work/scene.json" "$work" <<'EOF'
import copy, json, sys
s = json.load(open(sys.argv[1]))
s["sensors"][0]["resolution"] = [16, 12]
s["render"] = {"integrator": "path", "paths_per_sample": 1}
two = copy.deepcopy(s)
two["channels"] = s["channels"] + [dict(s["channels"][0], name="second",
                                        frequency_thz=1.1 * s["channels"][0]["frequency_thz"])]
two["sensors"][0]["noise"] = {"netd_k": 0.5}
two["sensors"].append(dict(s["sensors"][0], name="side"))
json.dump(two, open(sys.argv[2] + "/before.json", "w"))
json.dump(s, open(sys.argv[2] + "/after.json", "w"))
EOF
sim() { "$THZMAP" simulate "$work/$1.json" -o "$work/$2" --quiet "${@:3}"; }
sim before out --integrator final-gather --photons 20000 --save-photon-map ||
    fail "first run exited $?"
echo "mine" > "$work/out/notes.txt"
echo "mine" > "$work/out/cam.notes.txt"
for f in cam.measured_radiance.hdr cam.band-02.png photon-map.thzpm side.radiance.hdr; do
    [ -f "$work/out/$f" ] || fail "the first run wrote no $f: the test tests nothing"
done

# a render from the map in OUTDIR, into OUTDIR: the map it read stays
"$THZMAP" render "$work/before.json" --photon-map "$work/out/photon-map.thzpm" -o "$work/out" \
    --integrator photon-map --sensor cam --quiet || fail "render into the map's OUTDIR exited $?"
[ -f "$work/out/photon-map.thzpm" ] || fail "render removed the photon map it rendered from"

sim after out || fail "second run exited $?"
for f in cam.measured_radiance.hdr cam.measured_radiance.img cam.measured_brightness_temperature.hdr \
    cam.measured-band-01.png cam.band-02.png photon-map.thzpm photon-map.ply; do
    [ ! -e "$work/out/$f" ] || fail "$f of the earlier run stayed beside the new run's"
done
for f in notes.txt cam.notes.txt side.radiance.hdr side.radiance.img cam.radiance.hdr; do
    [ -f "$work/out/$f" ] || fail "$f is gone"
done
[ "$(cat "$work/out/cam.notes.txt")" = mine ] || fail "the user's cam.notes.txt changed"
# cam's files are exactly those of the same run into an empty directory (a quantity the
# claims do not know would stay from the first run)
sim after fresh || fail "run into an empty directory exited $?"
diff <(ls "$work/out" | grep '^cam\.' | grep -v -x cam.notes.txt) <(ls "$work/fresh" | grep '^cam\.') ||
    fail "cam's files differ from a fresh run's (<: OUTDIR used again, >: fresh)"
# classify now reads the run's own noise-free cube, as in a fresh directory
"$THZMAP" classify "$work/out" --sensor cam --method mahalanobis -o "$work/cls" -q 2> "$work/cls.err" ||
    fail "classify exited $?: $(cat "$work/cls.err")"
grep -q '"source": "cam.brightness_temperature"' "$work/cls/classification.json" ||
    fail "classify's source: $(grep '"source"' "$work/cls/classification.json")"

# bands in humid air, then in dry air: no bands-air.png of the humid run stays
IN="$REPO/tests/inputs/analysis"
for air in humid dry; do
    "$THZMAP" bands "$IN/water-line-$air.json" -o "$work/bands" --count 1 --from-thz 0.5 \
        --to-thz 0.6 --step-ghz 50 --paths 2 -q || fail "bands ($air) exited $?"
    [ $air = dry ] || [ -f "$work/bands/bands-air.png" ] || fail "no bands-air.png in humid air"
done
[ ! -e "$work/bands/bands-air.png" ] || fail "the humid run's bands-air.png stayed"
[ -f "$work/bands/bands.json" ] || fail "no bands.json"

finish "ok: an OUTDIR used again holds the new run's files alone"
