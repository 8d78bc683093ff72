#!/usr/bin/env bash
# thzmap batch (issue 17; scene-format.md "Sequences, sweeps and movies"): the frames,
# the movies and resuming, with tests/inputs/batch's sequence (test_batch_inputs.sh has
# lists of scenes, warnings, movies skipped, bad sequence files):
#  - a 5-frame sequence (a box walking from x = -0.5 to 0.5 m while warming from 300 to
#    308 K, fps 4): frame.json of frames 1 and 3 hold the hand values (x = -0.25 and
#    0.25 m, 302 and 306 K), and their files equal, bit for bit, `thzmap simulate` of
#    hand-written scenes with those values (summary.json aside: timings);
#  - the movies: H.264, 5 frames, 1.25 s, the size batch.json states; decoded, the
#    pixels' lightness ranks like the frame's brightness temperatures, and each frame's
#    caption reads its time ("t = 0.25 s");
#  - resuming: a batch interrupted by SIGTERM (exit 143) after a frame, then killed
#    with SIGKILL after more, and run again, redoes no finished frame (frame.json's
#    inode and time unchanged; batch.json's counts) and ends with every file identical
#    to an uninterrupted run's (summary.json and batch.json aside: timings);
#  - a changed keyframe redoes exactly the frames it changes; a changed fps, frames per
#    sweep value or base frame leaves OUTDIR as a fresh run of the new sequence leaves it
#    (a kept frame's frame.json: its time, its number, its photons' frame);
#  - a sensor-only sequence (the camera moving, photon-map integrator, 3 frames) fires
#    photons once (batch.json, frame.json) and its frames equal, bit for bit, `thzmap
#    render` of each frame's scene from the map `simulate --save-photon-map` fires for
#    frame 0 (summary.json aside); resumed after losing frames 1-2 or after a SIGKILL,
#    it ends with the same files;
#  - a sweep without keyframes: sweep-NN/frame-00000 per value (three digits past 100
#    values: tests/api/test_api_sequence.c, which needs no 101 frames run), its movies on
#    one colour scale spanning every value's frames;
#  - a camera moving into another room (another enclosure, so other air) fires photons
#    for that frame, each frame equal to simulate's; render refuses the first room's
#    map for the second.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/batch_lib.sh"

# --- an uninterrupted batch ---------------------------------------------------------
"$THZMAP" batch "$seq" -o "$work/A" --threads 2 --quiet > "$work/A.out" 2> "$work/A.err" ||
    { fail "batch A: exit $?"; cat "$work/A.err"; }
[ -s "$work/A.err" ] && fail "batch --quiet printed on stderr: $(head -c 300 "$work/A.err")"
# not quiet (all frames reused, the movies made again): the movies are announced once
# (the stage is reported before and after them; the second said it again)
cp -r "$work/A" "$work/A2"
"$THZMAP" batch "$seq" -o "$work/A2" --threads 2 > /dev/null 2> "$work/A2.err" ||
    fail "batch A again: exit $?"
rm -rf "$work/A2"
[ "$(grep -c 'encoding the movies' "$work/A2.err")" = 1 ] ||
    fail "the movies announced $(grep -c 'encoding the movies' "$work/A2.err") times, not once"
for i in 0 1 2 3 4; do
    [ -f "$work/A/frame-0000$i/cam.brightness_temperature.img" ] || fail "frame $i missing"
done
[ -e "$work/A/frame-00005" ] && fail "a sixth frame"
"$PY" - "$work/A/batch.json" <<'PY' || fail "batch.json of A"
import json, sys
b = json.load(open(sys.argv[1]))
assert b["format"] == "thzmap-batch/1" and b["n_frames"] == 5, b
assert b["frames_computed"] == 5 and b["frames_reused"] == 0 and b["complete"], b
assert [f["time_s"] for f in b["frames"]] == [0, 0.25, 0.5, 0.75, 1.0], b["frames"]
assert all(f["status"] == "done" and f["seconds"] > 0 for f in b["frames"])
# path fires no photons: none fired, none reused (it once said "fired" for every frame)
assert b["photon_phases_fired"] == 0, b
assert all(f["photons"] == "none" for f in b["frames"]), b["frames"]
m = {x["file"]: x for x in b["movies"]}
assert set(m) == {"cam.band-01.mp4", "cam.band-02.mp4"}, m
s = m["cam.band-01.mp4"]["colour_scale"]
assert 280 < s["min_k"] < s["max_k"] < 320, s
PY

# --- frames against simulate of hand-written scenes ---------------------------------
for case in "1 -0.25 302" "3 0.25 306"; do
    set -- $case
    "$PY" - "$work/scene.json" "$work/hand-$1.json" "$2" "$3" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
person = [o for o in s["objects"] if o["name"] == "person"][0]
person["transform"]["translate_m"] = [float(sys.argv[3]), 0, 0.8]
person["temperature_k"] = int(sys.argv[4])
json.dump(s, open(sys.argv[2], "w"), indent=1)
PY
    "$PY" - "$work/A/frame-0000$1/frame.json" "$2" "$3" <<'PY' || fail "frame $1: frame.json's scene is not the hand values"
import json, sys
f = json.load(open(sys.argv[1]))
p = [o for o in f["scene"]["objects"] if o["name"] == "person"][0]
assert p["transform"]["translate_m"] == [float(sys.argv[2]), 0, 0.8], p
assert p["temperature_k"] == float(sys.argv[3]), p
PY
    "$THZMAP" simulate "$work/hand-$1.json" -o "$work/S$1" --threads 1 --quiet >/dev/null ||
        fail "simulate of hand-$1.json"
    same_files "$work/S$1" "$work/A/frame-0000$1" "frame $1 against simulate's"
done

# --- the movies ---------------------------------------------------------------------
probe=$(ffprobe -v error -count_frames -show_entries stream=codec_name,nb_read_frames,width,height,duration \
        -of default=nw=1 "$work/A/cam.band-01.mp4")
echo "$probe" | grep -qx 'codec_name=h264' || fail "movie codec: $probe"
echo "$probe" | grep -qx 'nb_read_frames=5' || fail "movie frames: $probe"
echo "$probe" | grep -qx 'duration=1.250000' || fail "movie duration (5 frames at 4 fps): $probe"
ffmpeg -v error -i "$work/A/cam.band-01.mp4" -f rawvideo -pix_fmt gray "$work/movie.gray" ||
    fail "decoding the movie"
"$PY" - "$work/A" "$work/movie.gray" <<'PY' || fail "movie pixels against the Tb images"
import json, sys
import numpy as np
out, raw = sys.argv[1], sys.argv[2]
b = json.load(open(out + "/batch.json"))
m = [x for x in b["movies"] if x["file"] == "cam.band-01.mp4"][0]
L = m["layout"]
w, h, k = L["width_px"], L["height_px"], L["pixel_px"]
video = np.fromfile(raw, np.uint8).reshape(-1, h, w)
assert video.shape[0] == 5, video.shape
cols, rows = 16, 12
for i in range(5):
    tb = np.fromfile(f"{out}/frame-{i:05d}/cam.brightness_temperature.img", "<f4")[: cols * rows]
    tb = tb.reshape(rows, cols)
    ys = L["image_y_px"] + np.arange(rows) * k + k // 2
    xs = L["image_x_px"] + np.arange(cols) * k + k // 2
    luma = video[i][np.ix_(ys, xs)].astype(float)
    # ranks agree: for every pair of pixels more than 5 % of the scale apart in Tb,
    # the warmer is the lighter
    span = m["colour_scale"]["max_k"] - m["colour_scale"]["min_k"]
    t, y = tb.ravel(), luma.ravel()
    dt = t[:, None] - t[None, :]
    dy = y[:, None] - y[None, :]
    far = dt > 0.05 * span
    assert far.sum() > 100, far.sum()
    bad = (far & (dy <= 0)).sum()
    assert bad == 0, (i, bad, far.sum())
# the caption: the frame's time with the interval's decimals (4 fps: 0.25 s) and a space
# before the unit, in the movies' 3x5 font (2 pixels a dot) at (2, 3)
chars = "0123456789.-=tsK"
glyphs = [(7, 5, 5, 5, 7), (2, 6, 2, 2, 7), (7, 1, 7, 4, 7), (7, 1, 7, 1, 7), (5, 5, 7, 1, 1),
          (7, 4, 7, 1, 7), (7, 4, 7, 5, 7), (7, 1, 1, 1, 1), (7, 5, 7, 5, 7), (7, 5, 7, 1, 7),
          (0, 0, 0, 0, 2), (0, 0, 7, 0, 0), (0, 7, 0, 7, 0), (2, 7, 2, 2, 1), (3, 4, 2, 1, 6),
          (5, 6, 4, 6, 5)]
def caption(text):
    mask = np.zeros((10, 8 * len(text) + 8), bool)
    for n, ch in enumerate(text):
        rows = glyphs[chars.index(ch)] if ch in chars else (0,) * 5
        for r in range(10):
            for c in range(6):
                mask[r, 8 * n + c] = rows[r // 2] >> (2 - c // 2) & 1
    return mask
for i in range(5):
    want = caption("t = %.2f s" % (i / 4))
    got = video[i][3:13, 2:2 + want.shape[1]] > 127
    wrong = (got != want).sum()
    assert wrong <= 0.05 * want.sum(), (i, "caption", wrong, want.sum())
# the colour bar's labels, right of the image at its top and the frame's bottom: the
# colour_scale of batch.json rounded to 0.1 K (a README's figure quotes them), to the dot
# (a label 0.1 K off differs by 4 or more of the 2 x 2 dots' pixels)
for end, y in (("max_k", L["image_y_px"] + 6), ("min_k", h - 18)):
    want = caption("%.1f K" % m["colour_scale"][end])
    strip = video[0][y:y + 10, cols * k:] > 127
    wrong = min((strip[:, x:x + want.shape[1]] != want).sum()
                for x in range(strip.shape[1] - want.shape[1] + 1))
    assert wrong <= 2, (end, m["colour_scale"][end], wrong, want.sum())
# the colour bar between them (16 pixels wide, 8 right of the image): lightest at the top,
# beside max_k, darkening all the way down to min_k (viridis' lightness rises with Tb)
bar = video[0][L["image_y_px"] + 8:h - 10, cols * k + 16].astype(float)
assert bar[0] > bar[-1] + 100 and (np.diff(bar[::8]) <= 4).all(), bar[::8]
PY

# --- interrupted, killed, resumed ---------------------------------------------------
# frames_done DIR: frames whose frame.json is there
frames_done() { ls "$1"/frame-*/frame.json 2>/dev/null | wc -l; }
# wait_frames DIR N PID: until N frames are done (or the batch ended)
wait_frames() {
    for _ in $(seq 1 600); do
        [ "$(frames_done "$1")" -ge "$2" ] && return 0
        kill -0 "$3" 2>/dev/null || return 1
        sleep 0.02
    done
    return 1
}
"$THZMAP" batch "$seq" -o "$work/B" --quiet > /dev/null 2>&1 &
pid=$!
wait_frames "$work/B" 1 $pid || fail "batch B ended before its first frame"
kill -TERM $pid
wait $pid
rc=$?
[ $rc -eq 143 ] || [ $rc -eq 0 ] || fail "SIGTERM: exit $rc, expected 143"
n1=$(frames_done "$work/B")
# its own process group killed whole (see the sensor-only resume below)
setsid "$THZMAP" batch "$seq" -o "$work/B" --quiet > /dev/null 2>&1 &
pid=$!
wait_frames "$work/B" $((n1 + 2)) $pid
kill -KILL -- -$pid 2>/dev/null
wait $pid 2>/dev/null
# and until the group's other members (a figure's process) are gone: they share OUTDIR's
# lock, which the kernel lets go as the last of them exits (a resume a few ms earlier was
# refused, "another thzmap batch is running", in a fresh-clone check on 2 busy cores)
for _ in $(seq 1 250); do pgrep -g $pid > /dev/null || break; sleep 0.02; done
n2=$(frames_done "$work/B")
echo "interrupted after $n1 frame(s) (SIGTERM), killed after $n2 (SIGKILL)"
[ "$n2" -lt 5 ] || echo "note: the SIGKILL came after the last frame"
stat -c '%n %i %Y.%y' "$work"/B/frame-*/frame.json | sort > "$work/B.before"
"$THZMAP" batch "$seq" -o "$work/B" --quiet > /dev/null 2> "$work/B.err" || fail "batch B, resumed: exit $?: $(cat "$work/B.err")"
stat -c '%n %i %Y.%y' "$work"/B/frame-*/frame.json | sort | head -n "$n2" > "$work/B.after"
cmp -s "$work/B.before" "$work/B.after" || fail "a finished frame was redone: $(diff "$work/B.before" "$work/B.after")"
"$PY" - "$work/B/batch.json" "$n2" <<'PY' || fail "batch.json of the resumed run"
import json, sys
b = json.load(open(sys.argv[1]))
n = int(sys.argv[2])
assert b["frames_reused"] == n and b["frames_computed"] == 5 - n and b["complete"], (b["frames_reused"], n)
PY
(cd "$work/A" && find . -type f ! -name summary.json ! -name batch.json ! -name '.*' | sort) > "$work/A.files"
(cd "$work/B" && find . -type f ! -name summary.json ! -name batch.json ! -name '.*' | sort) > "$work/B.files"
cmp -s "$work/A.files" "$work/B.files" || fail "resumed run's files: $(diff "$work/A.files" "$work/B.files" | head)"
while read -r f; do
    cmp -s "$work/A/$f" "$work/B/$f" || fail "resumed run: $f differs from the uninterrupted run's"
done < "$work/A.files"
leftovers=$(cd "$work/B" && find . -name '.*' ! -name .thzmap-batch-lock ! -name . | head)
[ -z "$leftovers" ] || fail "leftovers in OUTDIR after the resumed run: $leftovers"

# --- a changed keyframe redoes the frames it changes --------------------------------
sed 's/"temperature_k": 308/"temperature_k": 312/' "$seq" > "$work/changed.json"
"$THZMAP" batch "$work/changed.json" -o "$work/A" --quiet > /dev/null 2>&1 || fail "changed batch: exit $?"
"$PY" - "$work/A/batch.json" <<'PY' || fail "a changed sequence must redo frames 1-4 and keep frame 0"
import json, sys
b = json.load(open(sys.argv[1]))
assert b["frames_reused"] == 1 and b["frames_computed"] == 4, b
assert [f["computed"] for f in b["frames"]][0] == "an earlier run"
PY

# --- a sweep without keyframes ------------------------------------------------------
cat > "$work/sweep.json" <<'JSON'
{"format": "thzmap-sequence/1", "scene": "scene.json",
 "sweep": {"objects.person.temperature_k": [300, 310], "materials.skin.reflectivity": [0.1],
           "materials.wall.reflectivity": [0.100000000000001], "render.integrator": ["path"]}}
JSON
"$THZMAP" batch "$work/sweep.json" -o "$work/W" --quiet > /dev/null 2>&1 || fail "sweep batch: exit $?"
for s in 00 01; do
    [ -f "$work/W/sweep-$s/frame-00000/cam.brightness_temperature.img" ] || fail "sweep-$s/frame-00000 missing"
    [ -f "$work/W/sweep-$s/cam.band-01.mp4" ] || fail "sweep-$s/cam.band-01.mp4 missing"
done
grep -q '"temperature_k": 310' "$work/W/sweep-01/frame-00000/frame.json" || fail "sweep-01 is not at 310 K"
# the sweep values as JSON values, written as the sequence file wrote them (they were one
# string, "materials.skin.reflectivity = 0.10000000000000001, ..."; and batch.json's 12
# digits would round 0.100000000000001), with a label in the shortest numbers too
"$PY" - "$work/W" <<'PY' || fail "the sweep values in batch.json and frame.json"
import json, sys
d = sys.argv[1]
b = json.load(open(f"{d}/batch.json"))
values = {"objects.person.temperature_k": 310, "materials.skin.reflectivity": 0.1,
          "materials.wall.reflectivity": 0.100000000000001, "render.integrator": "path"}
label = ("objects.person.temperature_k = 310, materials.skin.reflectivity = 0.1, "
         "materials.wall.reflectivity = 0.100000000000001, render.integrator = \"path\"")
assert b["sweeps"][1] == {"dir": "sweep-01", "values": values, "label": label}, b["sweeps"]
assert list(b["sweeps"][1]["values"]) == list(values), "not in the sequence file's order"
f = json.load(open(f"{d}/sweep-01/frame-00000/frame.json"))
assert f["sweep_values"] == values and f["sweep_label"] == label, f
# (frame.json's scene keeps 17 digits: it must read back to the same doubles)
for name in ("batch.json", "sweep-01/frame-00000/frame.json"):
    text = "".join(l for l in open(f"{d}/{name}") if '"values"' in l or '"sweep_values"' in l)
    assert "0.10000000000000001" not in text and '"materials.skin.reflectivity": 0.1,' in text, name
    assert '"materials.wall.reflectivity": 0.100000000000001,' in text, name
PY
# one colour scale for every sweep value's movie, spanning every frame of every value
# (sweep-01's person is 10 K warmer: a scale over sweep-00's frames alone clipped it)
"$PY" - "$work/W" <<'PY' || fail "the sweep's movies' colour scale"
import array, json, math, re, sys
d = sys.argv[1]
b = json.load(open(f"{d}/batch.json"))
scales = [m["colour_scale"] for m in b["movies"] if m["file"].endswith("cam.band-01.mp4")]
assert len(scales) == 2 and scales[0] == scales[1], scales
values = []
for s in ("00", "01"):
    stem = f"{d}/sweep-{s}/frame-00000/cam.brightness_temperature"
    hdr = open(stem + ".hdr").read()
    n = int(re.search(r"samples = (\d+)", hdr).group(1)) * int(re.search(r"lines = (\d+)", hdr).group(1))
    a = array.array("f")
    a.frombytes(open(stem + ".img", "rb").read()[:4 * n])  # band 1 (bsq, little-endian)
    values += [v for v in a if math.isfinite(v)]
assert abs(scales[0]["min_k"] - min(values)) < 1e-6 and abs(scales[0]["max_k"] - max(values)) < 1e-6, \
    (scales[0], min(values), max(values))
PY
# each sweep value's movie starts at t = 0 (frame i of a value at i / fps): sweep-01's
# caption is sweep-00's, "t = 0 s" (not 1 s, the frame's number in the whole batch)
for s in 00 01; do
    ffmpeg -v error -i "$work/W/sweep-$s/cam.band-01.mp4" -frames:v 1 -f rawvideo -pix_fmt gray \
        "$work/W$s.gray" || fail "decoding sweep-$s's movie"
done
"$PY" - "$work/W" <<'PY' || fail "sweep-01's movie: its first caption is not sweep-00's (t = 0 s)"
import json, sys
import numpy as np
d = sys.argv[1]
L = json.load(open(f"{d}/batch.json"))["movies"][0]["layout"]
a, b = (np.fromfile(f"{d}{s}.gray", np.uint8).reshape(L["height_px"], L["width_px"])[3:13] > 127
        for s in ("00", "01"))
assert a.sum() > 50 and (a != b).sum() <= 4, (a.sum(), (a != b).sum())
PY
# without a sweep, frame.json has no sweep values
"$PY" - "$work/A/frame-00000/frame.json" <<'PY' || fail "frame.json without a sweep"
import json, sys
f = json.load(open(sys.argv[1]))
assert f["sweep_values"] is None and f["sweep_label"] is None, f
PY

# --- a sensor-only sequence: photons fired once, frames rendered from them ----------
"$PY" - "$work/scene.json" "$work/pm-scene.json" "$work/pm-seq.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["render"] = {"integrator": "photon-map"}
s["photons"] = {"seed": 7, "per_channel": 20000}
json.dump(s, open(sys.argv[2], "w"), indent=1)
q = {"format": "thzmap-sequence/1", "scene": "pm-scene.json", "fps": 2, "frames": 3,
     "keyframes": [{"time_s": 0, "sensors": {"cam": {"position_m": [-0.3, -1.4, 0.9]}}},
                   {"time_s": 1, "sensors": {"cam": {"position_m": [0.3, -1.4, 0.9]}}}]}
json.dump(q, open(sys.argv[3], "w"))
PY
"$THZMAP" batch "$work/pm-seq.json" -o "$work/P" --threads 2 --quiet > /dev/null 2>&1 ||
    fail "sensor-only batch: exit $?"
"$PY" - "$work/P" <<'PY' || fail "sensor-only batch: photons must be fired once (batch.json, frame.json)"
import json, sys
b = json.load(open(sys.argv[1] + "/batch.json"))
assert b["photon_phases_fired"] == 1 and b["frames_rerendered"] == 2, b
assert [f["photons"] for f in b["frames"]] == ["fired", "reused", "reused"], b["frames"]
assert [f["photon_base_frame"] for f in b["frames"]] == [0, 0, 0], b["frames"]
for i, want in enumerate([None, 0, 0]):
    f = json.load(open(f"{sys.argv[1]}/frame-{i:05d}/frame.json"))
    assert f["photons_reused_from_frame"] == want, (i, f["photons_reused_from_frame"])
    json.dump(f["scene"], open(f"{sys.argv[1]}/../pm-frame-{i}.json", "w"))
PY
# the map fired for frame 0, and every frame rendered from it by `thzmap render`
"$THZMAP" simulate "$work/pm-frame-0.json" -o "$work/PM" --save-photon-map --threads 1 --quiet \
    > /dev/null || fail "simulate --save-photon-map of frame 0"
for i in 0 1 2; do
    "$THZMAP" render "$work/pm-frame-$i.json" --photon-map "$work/PM/photon-map.thzpm" \
        -o "$work/PR$i" --threads 1 --quiet > /dev/null || fail "render of frame $i"
    same_files "$work/PR$i" "$work/P/frame-0000$i" "sensor-only frame $i against render's"
done
cmp -s "$work/P/frame-00001/cam.radiance.img" "$work/P/frame-00002/cam.radiance.img" &&
    fail "sensor-only frames 1 and 2 are the same picture: the camera did not move"
# resumed inside the run of sensor-only frames: frame 0's photons are fired again, the
# same; once after removing frames 1-2, once after a SIGKILL once frame 0 is done
for how in removed killed; do
    rm -rf "$work/Q"
    if [ $how = removed ]; then
        cp -r "$work/P" "$work/Q"
        rm -rf "$work/Q/frame-00001" "$work/Q/frame-00002"
    else
        # in its own process group, killed whole: a plotting child (core/child.c) of a
        # batch killed alone would keep frame 1's output lock for a moment
        setsid "$THZMAP" batch "$work/pm-seq.json" -o "$work/Q" --threads 1 --quiet > /dev/null 2>&1 &
        pid=$!
        wait_frames "$work/Q" 1 $pid
        kill -KILL -- -$pid 2>/dev/null
        wait $pid 2>/dev/null
    fi
    "$THZMAP" batch "$work/pm-seq.json" -o "$work/Q" --threads 1 > /dev/null 2> "$work/Q.err" ||
        fail "sensor-only batch resumed ($how): exit $?"
    # frame 0 found done: the progress says what it counts (it said "frame 3/3 (2 done, 1
    # reused)", as if 3 frames were finished)
    [ $how = removed ] && expect_line "$work/Q.err" \
        '^thzmap batch: frame 3/3 \(2 of 3 frames finished so far: 1 computed, 1 already done\), '
    # frame 0's photons fired again are counted as this run's photon phase
    [ $how = removed ] && { "$PY" -c 'import json, sys; b = json.load(open(sys.argv[1]))
assert b["photon_phases_fired"] == 1 and b["frames_rerendered"] == 2, b' "$work/Q/batch.json" ||
        fail "sensor-only batch resumed: frame 0's photons fired again are not counted"; }
    (cd "$work/P" && find . -type f ! -name summary.json ! -name batch.json ! -name '.*' | sort) > "$work/P.files"
    while read -r f; do
        cmp -s "$work/P/$f" "$work/Q/$f" || fail "sensor-only batch resumed ($how): $f differs"
    done < "$work/P.files"
done
"$PY" - "$work/Q/batch.json" <<'PY' || fail "resumed sensor-only batch.json"
import json, sys
b = json.load(open(sys.argv[1]))
assert b["complete"] and b["photon_phases_fired"] <= 1, b
PY

# --- a kept frame says what a fresh run of the changed sequence says ----------------
# A changed sequence keeps the frames whose scenes did not change, and their frame.json
# must then be what a fresh run writes (it kept its time at the old fps and its number
# at the old frames per sweep value): OUTDIR after the change equals a fresh run's of
# the new sequence, every file (summary.json's timings and batch.json's record of which
# run computed which frame aside; batch.json's time_s as frame.json's, 17 digits), with
# no temporary file left. Three changes: the fps (2 to 1.9: frames 0, 2, 3, 4 hold
# keyframe values and are kept); the frames per sweep value (2 to 3:
# sweep-01/frame-00001, rendered from sweep-01/frame-00000's photons, is renumbered 3 to
# 4 and its base 2 to 3); a changed base frame (frame 0 warmer, 1 and 2 as before: they
# were rendered from frame 0's photons, a fresh run fires them for frame 1, so both are
# run again).
# same_outdir KEPT FRESH LABEL NREUSED
same_outdir() {
    "$PY" - "$1" "$2" "$4" <<'PY' || fail "$3: the changed sequence's OUTDIR is not a fresh run's"
import json, os, sys
kept, fresh, nreused = sys.argv[1], sys.argv[2], int(sys.argv[3])
def untimed(v):  # summary.json without its timings (keys ending in _s)
    if isinstance(v, dict):
        return {k: untimed(x) for k, x in v.items() if not k.endswith("_s")}
    return [untimed(x) for x in v] if isinstance(v, list) else v
left = [n for _, _, ns in os.walk(kept) for n in ns if n.endswith(".part")]
assert not left, left
def files(d):
    return sorted(os.path.relpath(os.path.join(r, n), d) for r, _, ns in os.walk(d)
                  for n in ns if not n.startswith("."))
assert files(kept) == files(fresh), (files(kept), files(fresh))
bad = []
for name in files(fresh):
    a, b = (open(os.path.join(d, name), "rb").read() for d in (kept, fresh))
    if name.endswith("summary.json"):
        a, b = untimed(json.loads(a)), untimed(json.loads(b))
    elif name == "batch.json":
        a, b = json.loads(a), json.loads(b)
        assert a["frames_reused"] == nreused, (a["frames_reused"], nreused)
        assert all(f["computed"] == "this run" for f in b["frames"])
        for x in (a, b):
            for k in ("frames_computed", "frames_reused", "photon_phases_fired",
                      "frames_rerendered", "timings_s"):
                del x[k]
            for f in x["frames"]:
                for k in ("computed", "photons", "seconds"):
                    f.pop(k, None)
        # one time, one text: batch.json's time_s as frame.json's (17 digits, not 12)
        times = [json.load(open(os.path.join(kept, f["dir"], "frame.json")))["time_s"]
                 for f in a["frames"]]
        assert [f["time_s"] for f in a["frames"]] == times, ([f["time_s"] for f in a["frames"]], times)
    if a != b:
        bad.append(name)
assert not bad, bad
PY
}
sed 's/"fps": 4, "frames": 5/"fps": 2, "frames": 5/' "$seq" > "$work/fps2.json"
sed 's/"fps": 4, "frames": 5/"fps": 1.9, "frames": 5/' "$seq" > "$work/fps19.json"
"$PY" - "$work/pm-seq.json" "$work/pm-sweep2.json" "$work/pm-sweep3.json" "$work/pm-warm0.json" <<'PY'
import json, sys
q = json.load(open(sys.argv[1]))
q["sweep"] = {"objects.person.temperature_k": [300, 310]}
for n, name in ((2, sys.argv[2]), (3, sys.argv[3])):
    q["frames"] = n
    json.dump(q, open(name, "w"))
q = json.load(open(sys.argv[1]))
q["keyframes"][0]["objects"] = {"person": {"temperature_k": 301}}
q["keyframes"].insert(1, {"time_s": 0.5, "objects": {"person": {"temperature_k": 300}}})
json.dump(q, open(sys.argv[4], "w"))
PY
for change in "fps2 fps19 4" "pm-sweep2 pm-sweep3 4" "pm-seq pm-warm0 0"; do
    set -- $change
    rm -rf "$work/K" "$work/F"
    "$THZMAP" batch "$work/$1.json" -o "$work/K" --threads 2 --quiet --no-movies > /dev/null 2>&1 &&
        "$THZMAP" batch "$work/$2.json" -o "$work/K" --threads 2 --quiet --no-movies > /dev/null 2>&1 &&
        "$THZMAP" batch "$work/$2.json" -o "$work/F" --threads 2 --quiet --no-movies > /dev/null 2>&1 ||
        fail "$1 then $2: exit $?"
    same_outdir "$work/K" "$work/F" "$1 then $2" "$3"
done

# --- a sensor moving into another enclosure: that frame fires its own photons --------
# The air's temperature defaults to the enclosure around the sensors (scene-format.md),
# so the two rooms' air emits at 290 and 310 K: a frame reusing the first room's photons
# would see the wrong air. Each frame equals simulate's of its own scene.
cat > "$work/rooms.json" <<'JSON'
{"format": "thzmap-scene/1", "name": "two-rooms",
 "channels": [{"frequency_thz": 0.5, "relative_width": 0.05}],
 "materials": {"wall": {"reflectivity": 0.3}},
 "atmosphere": {"model": "constant", "attenuation_per_m": 0.5},
 "objects": [
  {"name": "a", "type": "solid", "material": "wall", "temperature_k": 290,
   "shape": {"type": "box", "size_m": [1.5, 1.5, 1.5], "inward": true},
   "transform": {"translate_m": [-2, 0, 0]}},
  {"name": "b", "type": "solid", "material": "wall", "temperature_k": 310,
   "shape": {"type": "box", "size_m": [1.5, 1.5, 1.5], "inward": true},
   "transform": {"translate_m": [2, 0, 0]}}],
 "sensors": [{"name": "cam", "position_m": [-2, -0.5, 0], "direction": [0, 1, 0],
              "fov_deg": 40, "resolution": [6, 4]}],
 "photons": {"per_channel": 20000, "seed": 5},
 "render": {"integrator": "photon-map"}}
JSON
echo '{"format": "thzmap-sequence/1", "scene": "rooms.json", "fps": 1, "frames": 2,
 "keyframes": [{"time_s": 0, "sensors": {"cam": {"position_m": [-2, -0.5, 0]}}},
               {"time_s": 1, "sensors": {"cam": {"position_m": [2, -0.5, 0]}}}]}' > "$work/rooms-seq.json"
"$THZMAP" batch "$work/rooms-seq.json" -o "$work/R" --threads 2 --quiet > /dev/null 2>&1 ||
    fail "two-room batch: exit $?"
"$PY" - "$work/R" <<'PY' || fail "two-room batch: the frame in the other room must fire its own photons"
import json, sys
b = json.load(open(sys.argv[1] + "/batch.json"))
assert b["photon_phases_fired"] == 2, b
assert [f["photons"] for f in b["frames"]] == ["fired", "fired"], b["frames"]
for i in range(2):
    f = json.load(open(f"{sys.argv[1]}/frame-{i:05d}/frame.json"))
    assert f["photons_reused_from_frame"] is None, (i, f["photons_reused_from_frame"])
    json.dump(f["scene"], open(f"{sys.argv[1]}/../rooms-frame-{i}.json", "w"))
PY
for i in 0 1; do
    "$THZMAP" simulate "$work/rooms-frame-$i.json" -o "$work/RS$i" --threads 1 --quiet > /dev/null ||
        fail "simulate of two-room frame $i"
    same_files "$work/RS$i" "$work/R/frame-0000$i" "two-room frame $i against simulate's"
done
# render refuses the first room's map for the second, and says why the camera matters
"$THZMAP" simulate "$work/rooms-frame-0.json" -o "$work/RM" --save-photon-map --quiet > /dev/null ||
    fail "simulate --save-photon-map of two-room frame 0"
"$THZMAP" render "$work/rooms-frame-1.json" --photon-map "$work/RM/photon-map.thzpm" \
    -o "$work/RR" --quiet 2> "$work/RR.err"
rc=$?
[ $rc -eq 2 ] && grep -q "enclosure's around the sensors" "$work/RR.err" ||
    fail "render of the second room from the first room's map: exit $rc: $(cat "$work/RR.err")"

finish_counted "test_batch: all passed"
