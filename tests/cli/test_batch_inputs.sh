#!/usr/bin/env bash
# thzmap batch (scene-format.md "Sequences, sweeps and movies") beyond one sequence's
# frames (test_batch.sh): its inputs, warnings, movies skipped and refusals:
#  - a plain list of scenes ("scenes"): one frame each, as simulate's, resumed by input
#    hash, with movies; scenes with other sensors: no movies, a warning; the batch's
#    progress within a frame (the CLI's lines on a non-terminal); a movie at 1e-4 fps
#    plays at 0.01 fps; --no-movies makes none;
#  - a material table changed under the same name redoes its frame;
#  - libgomp calling exit() inside a frame leaves no staging directory or lock;
#  - a warning every frame gives (a run's, a scene's) is said once, naming its frame,
#    then counted;
#  - a sensor too large for the movie encoder (libx264: 16384 pixels a side): its movies
#    skipped with a warning before the first frame, the others made, exit 0;
#  - resuming does not depend on how the sequence's path is spelled (s/cam.json from the
#    parent, cam.json in s/);
#  - bad sequence files: exit 2, the JSON path in the message, nothing written (also
#    more than 100000 frames in all, or a frame that would not fit in memory, found
#    before the first frame runs); a long check of the frames shows its progress;
#  - a FIFO or device that a frame's scene names but the loader does not read, and a
#    FIFO frame.json in OUTDIR, are not opened and waited on.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/batch_lib.sh"

# --- a plain list of scenes, and progress within a frame ---------------------------
# frame 0 is scene.json, frame 1 sub/b.json (paths relative to the sequence file): as
# they are, frame 1 equal to simulate's; the movies have 2 frames; a changed sub/b.json
# redoes frame 1 only. Not quiet, on a non-terminal: the batch's progress passes a tenth
# of the batch inside the first frame (its channel 1 is half of it: a quarter).
mkdir -p "$work/sub"
sed 's/"temperature_k": 300/"temperature_k": 306/' "$work/scene.json" > "$work/sub/b.json"
echo '{"format": "thzmap-sequence/1", "scenes": ["scene.json", "sub/b.json"], "fps": 2}' > "$work/list.json"
"$THZMAP" batch "$work/list.json" -o "$work/L" --threads 2 > /dev/null 2> "$work/L.err" ||
    fail "list of scenes: exit $?: $(cat "$work/L.err")"
grep -Eq '^thzmap batch: [1-4]0 % of the batch done \(in frame 1/2\)' "$work/L.err" ||
    fail "no progress within frame 1 of 2: $(cat "$work/L.err")"
# frames of a fraction of a second: an ETA below 1 s reads "< 1 s", never "0 s" while
# frames remain
grep -q 'ETA 0 s' "$work/L.err" && fail "an ETA of '0 s' while frames remained: $(cat "$work/L.err")"
"$THZMAP" simulate "$work/sub/b.json" -o "$work/SB" --threads 1 --quiet >/dev/null || fail "simulate of sub/b.json"
same_files "$work/SB" "$work/L/frame-00001" "list frame 1 against simulate's"
"$PY" - "$work/L" <<'PY' || fail "list of scenes: batch.json, frame.json"
import json, sys
b = json.load(open(sys.argv[1] + "/batch.json"))
assert b["n_frames"] == 2 and b["frames_computed"] == 2 and b["complete"], b
assert b["scene"] is None and [s.rsplit("/", 1)[-1] for s in b["scenes"]] == ["scene.json", "b.json"], b
assert [f["time_s"] for f in b["frames"]] == [0, 0.5] and b["movies_skipped"] is None, b
assert len(b["movies"]) == 2 and all(m["frames"] == 2 for m in b["movies"]), b["movies"]
f = json.load(open(sys.argv[1] + "/frame-00001/frame.json"))
assert f["scene_file"].endswith("sub/b.json") and f["scene_dir"].endswith("sub"), f
assert [o["temperature_k"] for o in f["scene"]["objects"]] == [293, 306], f["scene"]
PY
ffprobe -v error -count_frames -show_entries stream=nb_read_frames -of default=nw=1 "$work/L/cam.band-02.mp4" |
    grep -qx 'nb_read_frames=2' || fail "list of scenes: the movie has not 2 frames"
# a slow process (a frame every 10 000 s): the movie plays at the slowest rate held,
# 0.01 frames/s, and batch.json says so (a rate of 1e-4 once failed the whole batch)
echo '{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 1e-4, "frames": 2}' \
    > "$work/slow.json"
"$THZMAP" batch "$work/slow.json" -o "$work/S" --threads 2 --quiet > /dev/null 2>&1 ||
    fail "a sequence at 1e-4 fps: exit $?"
ffprobe -v error -show_entries stream=r_frame_rate -of default=nw=1 "$work/S/cam.band-01.mp4" |
    grep -qx 'r_frame_rate=1/100' || fail "a sequence at 1e-4 fps: the movie is not at 0.01 fps"
grep -q '"fps": 0.01' "$work/S/batch.json" || fail "a sequence at 1e-4 fps: batch.json's movie rate"
# --no-movies: the frames (reused here) and batch.json, no movie
"$THZMAP" batch "$work/slow.json" -o "$work/S" --no-movies --quiet > /dev/null 2>&1 ||
    fail "batch --no-movies: exit $?"
"$PY" - "$work/S/batch.json" <<'PY' || fail "batch --no-movies: batch.json lists movies"
import json, sys
b = json.load(open(sys.argv[1]))
assert b["movies"] == [] and b["frames_reused"] == len(b["frames"]), b
PY
sed -i 's/"temperature_k": 306/"temperature_k": 307/' "$work/sub/b.json"
"$THZMAP" batch "$work/list.json" -o "$work/L" --quiet > /dev/null 2>&1 || fail "list, changed: exit $?"
"$PY" - "$work/L/batch.json" <<'PY' || fail "a changed scene of the list must redo its frame only"
import json, sys
b = json.load(open(sys.argv[1]))
assert b["frames_reused"] == 1 and b["frames_computed"] == 1, b
assert [f["computed"] for f in b["frames"]] == ["an earlier run", "this run"], b["frames"]
PY
# a file the scene names is part of a frame's inputs: its content changed under the same
# name, the frame is redone (the resume hash covered only the scene's text once a
# helper's mutant left the files out, and every test passed)
mkdir -p "$work/tab"
cp "$REPO/examples/plate-in-box/materials/sample.csv" "$work/tab/skin.csv"
"$PY" - "$work/scene.json" "$work/tab/scene.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["materials"]["skin"] = {"file": "skin.csv"}
json.dump(s, open(sys.argv[2], "w"))
PY
echo '{"format": "thzmap-sequence/1", "scenes": ["scene.json"], "fps": 1}' > "$work/tab/list.json"
"$THZMAP" batch "$work/tab/list.json" -o "$work/T" --no-movies --quiet > /dev/null 2>&1 ||
    fail "a scene with a material table: exit $?"
sed -i 's/^0.35,0.10,120$/0.35,0.30,120/' "$work/tab/skin.csv"
grep -q '^0.35,0.30,120$' "$work/tab/skin.csv" || fail "the material table was not changed"
"$THZMAP" batch "$work/tab/list.json" -o "$work/T" --no-movies --quiet > /dev/null 2>&1 ||
    fail "a scene with a changed material table: exit $?"
"$PY" - "$work/T/batch.json" <<'PY' || fail "a changed material table must redo its frame"
import json, sys
b = json.load(open(sys.argv[1]))
assert b["frames_reused"] == 0 and b["frames_computed"] == 1, b
PY
# scenes with other sensors: the frames, no movies, a warning saying why, exit 0
sed 's/"resolution": \[16, 12\]/"resolution": [8, 6]/' "$work/scene.json" > "$work/small.json"
echo '{"format": "thzmap-sequence/1", "scenes": ["scene.json", "small.json"]}' > "$work/mixed.json"
"$THZMAP" batch "$work/mixed.json" -o "$work/M" --quiet > /dev/null 2> "$work/M.err" ||
    fail "list of scenes with other sensors: exit $?"
grep -q 'warning: no movies: frame frame-00001 has other sensors or channels' "$work/M.err" ||
    fail "no warning about the movies: $(cat "$work/M.err")"
ls "$work"/M/*.mp4 >/dev/null 2>&1 && fail "movies from frames of other sizes"
"$PY" - "$work/M/batch.json" <<'PY' || fail "batch.json of a list with other sensors"
import json, sys
b = json.load(open(sys.argv[1]))
assert b["movies"] == [] and "8 x 6" in b["movies_skipped"] and b["frames_computed"] == 2, b
PY

# --- libgomp's exit() inside a frame -------------------------------------------------
# No thread can start with a stack larger than the address space: libgomp calls exit()
# while frame 0 is open. The exit handler removes its staging directory and lock and
# says so (any non-zero status: a sanitizer build may add its leak report).
OMP_STACKSIZE=1000000G "$THZMAP" batch "$work/list.json" -o "$work/X" --threads 2 --quiet \
    > /dev/null 2> "$work/X.err"
[ $? -ne 0 ] || fail "libgomp exit: exit status 0"
grep -q 'a library ended the process early' "$work/X.err" || fail "libgomp exit: $(cat "$work/X.err")"
left=$(ls -A "$work/X" | grep -v -x -e batch.json -e .thzmap-batch-lock)
[ -z "$left" ] || fail "libgomp exit left in OUTDIR: $left"

# --- a warning every frame gives: said once, naming its frame, then counted ------------
"$PY" - "$work/scene.json" "$work/few.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["render"] = {"integrator": "photon-map"}
s["photons"] = {"per_channel": 500, "seed": 1}
json.dump(s, open(sys.argv[2], "w"))
PY
echo '{"format": "thzmap-sequence/1", "scene": "few.json", "fps": 1, "frames": 3}' > "$work/few-seq.json"
"$THZMAP" batch "$work/few-seq.json" -o "$work/F" --threads 2 --quiet > /dev/null 2> "$work/F.err" ||
    fail "few photons: exit $?"
[ "$(grep -c 'fewer photons than a density estimate needs' "$work/F.err")" = 2 ] &&
    grep -q '^thzmap batch: warning: frame-00000: ' "$work/F.err" &&
    grep -q '^thzmap batch: warning: the same in 2 later frames: ' "$work/F.err" ||
    fail "a warning of every frame: not once with its frame, then counted: $(cat "$work/F.err")"

# a frame's scene warnings are printed as simulate prints its scene's, folded alike
"$PY" - "$work/scene.json" "$work/bg.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["atmosphere"] = {"model": "constant", "attenuation_per_m": 0.01, "background_temperature_k": 3}
s["sensors"][0]["resolution"] = [4, 3]
json.dump(s, open(sys.argv[2], "w"))
PY
echo '{"format": "thzmap-sequence/1", "scene": "bg.json", "fps": 1, "frames": 2}' > "$work/bg-seq.json"
"$THZMAP" batch "$work/bg-seq.json" -o "$work/BG" --threads 2 --quiet > /dev/null 2> "$work/BG.err" ||
    fail "scene warnings: exit $?"
grep -q '^thzmap batch: warning: frame-00000: atmosphere.background_temperature_k is given' "$work/BG.err" &&
    grep -q '^thzmap batch: warning: the same in 1 later frame: atmosphere.background' "$work/BG.err" ||
    fail "a frame's scene warning not printed once with its frame: $(cat "$work/BG.err")"

# --- a sensor too large for the movie encoder: its movies skipped, said up front -------
# (libx264 takes at most 16384 pixels a side; a 1 x 1100 sensor is enlarged 16 times to
# 17616 rows.) The batch encoded every frame and then failed with exit 1, again on rerun.
mkdir -p "$work/big"
"$PY" - "$work/big" <<'PY'
import json, sys
d = sys.argv[1]
cam = {"position_m": [0, -1.4, 0], "look_at_m": [0, 0, 0], "fov_deg": 40}
scene = {"format": "thzmap-scene/1",
         "channels": [{"frequency_thz": 0.35, "relative_width": 0.01}],
         "materials": {"wall": {"reflectivity": 0.1}},
         "objects": [{"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
                      "shape": {"type": "box", "size_m": [3, 3, 3], "inward": True}}],
         "sensors": [dict(cam, name="cam", resolution=[4, 4]),
                     dict(cam, name="tall", resolution=[1, 1100])],
         "render": {"integrator": "path", "paths_per_sample": 1}}
json.dump(scene, open(f"{d}/tall.json", "w"))
json.dump({"format": "thzmap-sequence/1", "scene": "tall.json", "frames": 2},
          open(f"{d}/seq.json", "w"))
PY
for run in 1 2; do
    timeout 120 "$THZMAP" batch "$work/big/seq.json" -o "$work/big/out" > "$work/big/out$run.log" 2>&1
    rc=$?
    [ $rc -eq 0 ] || fail "batch with a too tall sensor (run $run): exit $rc: $(tail -3 "$work/big/out$run.log")"
done
# the warning comes before the first frame, once
first=$(grep -n 'warning: no movies of sensor "tall"' "$work/big/out1.log" | head -1 | cut -d: -f1)
frame1=$(grep -n 'frame 1/2' "$work/big/out1.log" | head -1 | cut -d: -f1)
{ [ -n "$first" ] && [ -n "$frame1" ] && [ "$first" -lt "$frame1" ] &&
    [ "$(grep -c 'no movies of sensor' "$work/big/out1.log")" -eq 1 ]; } ||
    fail "too tall sensor: one warning before the frames: $(cat "$work/big/out1.log")"
"$PY" - "$work/big/out" <<'PY' || fail "batch.json of the too tall sensor's batch"
import json, os, sys
d = sys.argv[1]
b = json.load(open(f"{d}/batch.json"))
assert b["complete"] and b["frames_done"] == 2, b
assert "sensor \"tall\"" in b["movies_skipped"] and "16384" in b["movies_skipped"], b["movies_skipped"]
assert [m["file"] for m in b["movies"]] == ["cam.band-01.mp4"], b["movies"]
assert os.path.exists(f"{d}/cam.band-01.mp4") and not os.path.exists(f"{d}/tall.band-01.mp4")
PY

# --- resuming does not depend on how the sequence's path is spelled --------------------
# the hash took the scene's directory as written: `cam.json` in s/ and `s/cam.json` from
# the parent hashed differently, and the second batch recomputed every frame
mkdir -p "$work/spell/s"
cp "$work/big/tall.json" "$work/spell/s/scene.json"
"$PY" - "$work/spell/s/scene.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["sensors"] = s["sensors"][:1]
json.dump(s, open(sys.argv[1], "w"))
PY
echo '{"format": "thzmap-sequence/1", "scene": "scene.json", "frames": 2}' > "$work/spell/s/cam.json"
(cd "$work/spell/s" && "$THZMAP" batch cam.json -o camout --quiet --no-movies) ||
    fail "batch in s/: exit $?"
(cd "$work/spell" && "$THZMAP" batch s/cam.json -o s/camout --quiet --no-movies) ||
    fail "batch from the parent: exit $?"
"$PY" - "$work/spell/s/camout/batch.json" <<'PY' || fail "the same frames spelled otherwise were recomputed"
import json, sys
b = json.load(open(sys.argv[1]))
assert b["frames_reused"] == 2 and b["frames_computed"] == 0, b
PY

# --- bad sequence files -------------------------------------------------------------
bad() { # bad NAME EXPECTED-TEXT JSON
    printf '%s\n' "$3" > "$work/bad-$1.json"
    timeout 60 "$THZMAP" batch "$work/bad-$1.json" -o "$work/bad-out" > "$work/bad.out" 2> "$work/bad.err"
    rc=$?
    [ $rc -eq 2 ] || fail "bad $1: exit $rc, expected 2"
    grep -qF -- "$2" "$work/bad.err" || fail "bad $1: expected '$2' in: $(cat "$work/bad.err")"
    [ -e "$work/bad-out" ] && { fail "bad $1: wrote $work/bad-out"; rm -rf "$work/bad-out"; }
}
K0='{"time_s": 0, "objects": {"person": {"temperature_k": 300}}}'
bad format 'bad-format.json: format: expected "thzmap-sequence/1"' \
    '{"format": "thzmap-scene/1", "scene": "scene.json"}'
# a scene file given as a sequence: its format named first, not its first key as unknown
bad scene_file 'bad-scene_file.json: format: expected "thzmap-sequence/1", got "thzmap-scene/1" (a scene file, which `thzmap simulate` runs' \
    '{"format": "thzmap-scene/1", "name": "room", "channels": []}'
bad unknown 'bad-unknown.json: fsp: unknown key' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "fsp": 4}'
bad order 'keyframes[1].time_s: expected keyframe times in increasing order' \
    "{\"format\": \"thzmap-sequence/1\", \"scene\": \"scene.json\", \"fps\": 4, \"keyframes\": [{\"time_s\": 1}, $K0]}"
bad nobody 'keyframes[0].objects.nobody: the scene has no object named "nobody"' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 4, "keyframes": [{"time_s": 0, "objects": {"nobody": {"temperature_k": 3}}}]}'
bad empty_block 'keyframes[0].cameras: "cameras" cannot be set' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 4, "keyframes": [{"time_s": 0, "cameras": {}}]}'
bad string 'keyframes[0].objects.person.temperature_k: expected a number or an array of numbers, got a string' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 4, "keyframes": [{"time_s": 0, "objects": {"person": {"temperature_k": "hot"}}}]}'
bad shape 'keyframes[1].sensors.cam.position_m: expected the same kind of value' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 4, "keyframes": [{"time_s": 0, "sensors": {"cam": {"position_m": [0, -1, 1]}}}, {"time_s": 1, "sensors": {"cam": {"position_m": [0, 1]}}}]}'
# a sweep key that names an object, not a value of it (it set a key "person" inside the
# object, which the scene then refused as unknown, not saying what the sweep lacked)
bad whole_object 'bad-whole_object.json: sweep.objects.person: expected a path to a value, e.g. objects.NAME.temperature_k' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "sweep": {"objects.person": [300]}}'
bad frames 'frames: expected a whole number of frames' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 4, "frames": 0}'
bad fps 'fps: required with keyframes' \
    "{\"format\": \"thzmap-sequence/1\", \"scene\": \"scene.json\", \"keyframes\": [$K0]}"
# every frame checked against the memory before the first runs: 10^11 photons of the
# second sweep value were refused only after the first value's frame had run
"$PY" - "$work" <<'PY'
import json, sys
s = json.load(open(f"{sys.argv[1]}/scene.json"))
s["render"] = {"integrator": "photon-map"}
s["sensors"][0]["resolution"] = [4, 4]
json.dump(s, open(f"{sys.argv[1]}/scene-pm.json", "w"))
PY
bad memory 'bad-memory.json: sweep-01/frame-00000: ' \
    '{"format": "thzmap-sequence/1", "scene": "scene-pm.json", "sweep": {"photons.per_channel": [1000, 100000000000]}}'
grep -qF 'lower photons.per_channel (now 100000000000' "$work/bad.err" || fail "bad memory: the photons named: $(cat "$work/bad.err")"
# a rate so small that frame times are infinite (time_s was missing from frame.json)
bad fps_tiny 'bad-fps_tiny.json: fps: expected frames per second of at least 1e-9 (a frame in 31.7 years), got 5e-324' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 5e-324, "frames": 2}'
# a message that shows the sweep values shows them in their shortest numbers
bad sweep_label 'materials.skin.reflectivity = 0.1, ' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "sweep": {"materials.skin.reflectivity": [0.1], "objects.room.shape.size_m": [[3, 3, -2]]}}'
grep -qF '0.10000000000000001' "$work/bad.err" && fail "bad sweep_label: 17 digits: $(cat "$work/bad.err")"
bad sweep 'sweep.objects.person.temperature_k: expected a non-empty array' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "sweep": {"objects.person.temperature_k": []}}'
# --- too many frames in all; a long check of the frames is shown -----------------------
# frames (<= 100000) and sweep values (<= 10000) were limited each, their product not:
# such a sequence was accepted and then loaded frame after frame, silently, for hours.
bad total_frames 'bad-total_frames.json: frames: 100000 frames per sweep value x 2 sweep values = 200000 frames, more than the 100000 a sequence may have' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "frames": 100000, "sweep": {"objects.person.temperature_k": [300, 310]}}'
# a long check of the frames (each frame's scene is loaded: a scene of 100 crates, 2-3 ms
# a frame in the release build, 10-15 ms under the sanitizers: 3000 frames, 375 there, so
# that a machine several times faster still takes more than a second) shows the share
# checked after the first second; the last frame is bad, so nothing runs
"$PY" - "$work" <<'PY'
import json, sys
s = json.load(open(f"{sys.argv[1]}/scene.json"))
for i in range(100):
    s["objects"].append({"name": f"crate{i}", "type": "solid", "material": "wall",
                         "temperature_k": 295, "shape": {"type": "box", "size_m": [0.05, 0.05, 0.05]},
                         "transform": {"translate_m": [-1.2 + 0.024 * i, 1.2, 0.1]}})
json.dump(s, open(f"{sys.argv[1]}/crates.json", "w"))
PY
nl=3000
[ "${THZ_TEST_SCALE:-1}" = 1 ] || nl=375
bad long_check "keyframes[2].objects.person.temperature_k: expected a number in [0, 1e+06], got -10 (the scene crates.json's objects[1].temperature_k, frame-$(printf %05d $((nl - 1))), t = $((nl - 1)) s)" \
    "{\"format\": \"thzmap-sequence/1\", \"scene\": \"crates.json\", \"fps\": 1, \"frames\": $nl, \"keyframes\": [{\"time_s\": 0, \"objects\": {\"person\": {\"temperature_k\": 300}}}, {\"time_s\": $((nl - 2)), \"objects\": {\"person\": {\"temperature_k\": 300}}}, {\"time_s\": $((nl - 1)), \"objects\": {\"person\": {\"temperature_k\": -10}}}]}"
grep -qE "checking the frames' scenes: [0-9]+ % \([0-9]+ of $nl frames\), [0-9.]+ s" "$work/bad.err" ||
    fail "a long check of the frames shows no progress: $(head -c 600 "$work/bad.err")"
# validate shows the same check (it showed nothing for as long), each tenth once, and the
# same error
timeout 120 "$THZMAP" validate "$work/bad-long_check.json" > /dev/null 2> "$work/val.err"
rc=$?
{ [ $rc -eq 2 ] && grep -qF 'got -10 (the scene crates.json' "$work/val.err" &&
    grep -qE "^thzmap validate: checking the frames' scenes: [0-9]+ % \([0-9]+ of $nl frames\), [0-9.]+ s$" "$work/val.err" &&
    [ -z "$(grep -oE ': [0-9]+ % \(' "$work/val.err" | sort | uniq -d)" ]; } ||
    fail "validate of a long sequence: exit $rc, its progress: $(head -c 600 "$work/val.err")"
mkfifo "$work/pipe.json" # a FIFO as the scene would block the open: refused at once
bad fifo_scene 'pipe.json: is a FIFO' '{"format": "thzmap-sequence/1", "scene": "pipe.json"}'
# and the other way round: simulate given a sequence file
"$THZMAP" simulate "$work/list.json" -o "$work/bad-out" 2> "$work/bad.err"
rc=$?
{ [ $rc -eq 2 ] && [ ! -e "$work/bad-out" ] &&
    grep -qF 'list.json: format: expected "thzmap-scene/1" or "thzmap-scene/1.1", got "thzmap-sequence/1" (a sequence file, which `thzmap batch` runs)' "$work/bad.err"; } ||
  fail "simulate given a sequence file: exit $rc: $(cat "$work/bad.err")"
bad syntax 'bad-syntax.json:1:' '{"format": "thzmap-sequence/1",, }'
# a bad value a keyframe or the sweep set: named where the sequence file sets it (the
# message led to the scene's JSON path, which the scene file does not have: "frame 2 (t =
# 0.5 s): scene.json: objects[1].temperature_k"), then the scene's path and the frame by
# its directory, as the warnings name it (errors counted frames from 0, warnings from 1)
bad frame_scene 'bad-frame_scene.json: keyframes[1].objects.person.temperature_k: expected a number in [0, 1e+06], got -10 (the scene scene.json'"'"'s objects[1].temperature_k, frame-00002, t = 0.5 s)' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 4, "frames": 3, "keyframes": [{"time_s": 0, "objects": {"person": {"temperature_k": 300}}}, {"time_s": 0.5, "objects": {"person": {"temperature_k": -10}}}]}'
bad frame_key 'bad-frame_key.json: keyframes[0].sensors.cam.fov: unknown key (expected one of: ' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 1, "frames": 2, "keyframes": [{"time_s": 0, "sensors": {"cam": {"fov": 30}}}]}'
grep -qF "(the scene scene.json's sensors[0].fov, frame-00000, t = 0 s)" "$work/bad.err" || fail "bad frame_key: the scene's path: $(cat "$work/bad.err")"
bad frame_between 'bad-frame_between.json: keyframes[1].sensors.cam.position_m[2]: ' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 4, "frames": 4, "keyframes": [{"time_s": 0, "sensors": {"cam": {"position_m": [0, -1.4, 0.9]}}}, {"time_s": 1, "sensors": {"cam": {"position_m": [0, -1.4, 1e300]}}}]}'
grep -qF "(interpolated between keyframes[0] and keyframes[1]; the scene scene.json's sensors[0].position_m[2], frame-00001, t = 0.25 s)" "$work/bad.err" || fail "bad frame_between: $(cat "$work/bad.err")"
bad frame_sweep "bad-frame_sweep.json: sweep.objects.room.temperature_k[1]: expected a number in [0, 1e+06], got -1 (the scene scene.json's objects[0].temperature_k, sweep-01/frame-00000: objects.room.temperature_k = -1, t = 0 s)" \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 1, "frames": 1, "keyframes": [{"time_s": 0, "objects": {"room": {"temperature_k": 300}}}], "sweep": {"objects.room.temperature_k": [1, -1]}}'
# a value inside one the sweep set: its place within that value
bad frame_sweep_deep "bad-frame_sweep_deep.json: sweep.objects.person.transform[0].bogus: unknown key" \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "sweep": {"objects.person.transform": [{"translate_m": [0, 0, 0.8], "bogus": 1}]}}'
# an error the sequence did not make: the scene's own, after the frame's directory
"$PY" - "$work" <<'PY'
import json, sys
s = json.load(open(f"{sys.argv[1]}/scene.json"))
s["sensors"][0]["fov"] = 30
json.dump(s, open(f"{sys.argv[1]}/scene-fov.json", "w"))
PY
bad frame_own "bad-frame_own.json: frame-00000 (t = 0 s): $work/scene-fov.json: sensors[0].fov: unknown key" \
    '{"format": "thzmap-sequence/1", "scene": "scene-fov.json", "fps": 1, "frames": 2, "keyframes": [{"time_s": 1, "sensors": {"cam": {"fov_deg": 60}}}]}'
bad both 'bad-both.json: scenes: give either "scene"' \
    '{"format": "thzmap-sequence/1", "scene": "scene.json", "scenes": ["scene.json"]}'
bad empty_list 'bad-empty_list.json: scenes: expected a non-empty list of scene files, got an empty one' \
    '{"format": "thzmap-sequence/1", "scenes": []}'
bad missing 'bad-missing.json: scenes[1]: ' \
    '{"format": "thzmap-sequence/1", "scenes": ["scene.json", "nowhere.json"]}'
grep -qF 'nowhere.json' "$work/bad.err" || fail "bad missing: the file's name: $(cat "$work/bad.err")"
bad list_keyframes 'bad-list_keyframes.json: keyframes: not with "scenes"' \
    "{\"format\": \"thzmap-sequence/1\", \"scenes\": [\"scene.json\"], \"fps\": 4, \"keyframes\": [$K0]}"
bad list_frames 'bad-list_frames.json: frames: not with "scenes"' \
    '{"format": "thzmap-sequence/1", "scenes": ["scene.json"], "frames": 3}'
bad list_sweep 'sweep.objects.nobody.temperature_k: scenes[0] (scene.json) has no object named "nobody"' \
    '{"format": "thzmap-sequence/1", "scenes": ["scene.json"], "sweep": {"objects.nobody.temperature_k": [300]}}'
"$THZMAP" batch "$seq" > /dev/null 2>&1
[ $? -eq 2 ] || fail "batch without -o: expected exit 2"
# an OUTDIR under a file is bad usage, as for simulate (it exited 1)
touch "$work/a-file"
"$THZMAP" batch "$seq" -o "$work/a-file/out" -q 2> "$work/under-file.err"
rc=$?
[ $rc -eq 2 ] && grep -q "a-file/out: cannot create the directory: Not a directory" "$work/under-file.err" ||
    fail "batch into a path under a file: exit $rc, $(cat "$work/under-file.err")"
# and an OUTDIR that is a file is said as simulate says it
"$THZMAP" batch "$seq" -o "$work/a-file" -q 2> "$work/is-file.err"
rc=$?
[ $rc -eq 2 ] && grep -q "a-file: exists and is not a directory (expected a directory" "$work/is-file.err" ||
    fail "batch into a file: exit $rc, $(cat "$work/is-file.err")"
# before the sequence is loaded, whose check of every frame's scene takes seconds (1.4 s
# for 12 frames in humid air): a sequence that cannot load gets the OUTDIR's refusal
echo '{"format": "thzmap-sequence/1", "scene": "no-such-scene.json", "frames": 2}' > "$work/noscene.json"
"$THZMAP" batch "$work/noscene.json" -o "$work/a-file" -q 2> "$work/is-file-first.err"
rc=$?
[ $rc -eq 2 ] && grep -q "a-file: exists and is not a directory" "$work/is-file-first.err" ||
    fail "batch into a file, refused after loading the sequence: exit $rc, $(cat "$work/is-file-first.err")"

# A FIFO or device that a frame's scene names but the loader does not read (the continuum
# table of a lines model without the continuum) and a FIFO frame.json in OUTDIR: the
# frames' input hash and the resume check opened them and waited (or read /dev/zero) for ever.
mkdir -p "$work/fifo"
cp "$REPO/tests/inputs/atm_h2o_subset.csv" "$REPO/tests/inputs/atm_o2_subset.csv" "$work/fifo/"
mkfifo "$work/fifo/fifo.csv"
python3 - "$work/fifo" <<'PY'
import json, sys
d = sys.argv[1]
scene = {"format": "thzmap-scene/1.1",
         "channels": [{"frequency_thz": 0.35, "relative_width": 0.01}],
         "materials": {"wall": {"reflectivity": 0.1}},
         "objects": [{"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
                      "shape": {"type": "box", "size_m": [3, 3, 3], "inward": True}}],
         "sensors": [{"name": "cam", "position_m": [0, -1.4, 0], "look_at_m": [0, 0, 0],
                      "fov_deg": 40, "resolution": [4, 4]}],
         "render": {"paths_per_sample": 1},
         "atmosphere": {"model": "lines", "temperature_k": 295, "pressure_hpa": 1000,
                        "relative_humidity": 0.5, "h2o_lines_file": "atm_h2o_subset.csv",
                        "o2_lines_file": "atm_o2_subset.csv", "continuum": False}}
for name, unread in (("fifo", "fifo.csv"), ("zero", "/dev/zero")):
    scene["atmosphere"]["continuum_file"] = unread
    json.dump(scene, open(f"{d}/{name}.json", "w"))
    json.dump({"format": "thzmap-sequence/1", "scene": f"{name}.json", "frames": 1},
              open(f"{d}/seq-{name}.json", "w"))
PY
for name in fifo zero; do
    timeout 60 "$THZMAP" batch "$work/fifo/seq-$name.json" -o "$work/fifo/o-$name" --quiet \
        > "$work/fifo/$name.log" 2>&1
    rc=$?
    [ $rc -eq 0 ] || fail "batch of a scene naming an unread $name: exit $rc: $(tail -2 "$work/fifo/$name.log")"
done
rm -f "$work/fifo/o-fifo/frame-00000/frame.json"
mkfifo "$work/fifo/o-fifo/frame-00000/frame.json"
timeout 60 "$THZMAP" batch "$work/fifo/seq-fifo.json" -o "$work/fifo/o-fifo" --quiet \
    > "$work/fifo/resume.log" 2>&1
rc=$?
[ $rc -ne 124 ] || fail "batch resuming with a FIFO frame.json hung"

finish_counted "test_batch_inputs: all passed"
