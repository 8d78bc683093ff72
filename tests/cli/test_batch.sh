#!/usr/bin/env bash
# thzmap batch (issue 17; scene-format.md "Sequences, sweeps and movies"):
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
#  - a material table changed under the same name redoes its frame;
#  - a plain list of scenes ("scenes"): one frame each, as simulate's, resumed by input
#    hash, with movies; scenes with other sensors: no movies, a warning; the batch's
#    progress within a frame (the CLI's lines on a non-terminal);
#  - libgomp calling exit() inside a frame leaves no staging directory or lock;
#  - resuming does not depend on how the sequence's path is spelled (s/cam.json from the
#    parent, cam.json in s/);
#  - a sensor too large for the movie encoder (libx264: 16384 pixels a side): its movies
#    skipped with a warning before the first frame, the others made, exit 0;
#  - bad sequence files: exit 2, the JSON path in the message, nothing written (also
#    more than 100000 frames in all, or a frame that would not fit in memory, found
#    before the first frame runs); a long check of the frames shows its progress.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
PY=/usr/bin/python3 # Debian's, with numpy
# Every file of the run in $1 (summary.json aside: timings) equals, byte for byte, the
# file of the same name in $2; at least 10 of them ($3 names the comparison).
same_files() {
    local n=0 f b
    for f in "$1"/*; do
        b=$(basename "$f")
        [ "$b" = summary.json ] && continue
        n=$((n + 1))
        cmp -s "$f" "$2/$b" || fail "$3: $b differs"
    done
    [ "$n" -ge 10 ] || fail "$3: only $n files compared"
}
need ffprobe ffmpeg
need ffmpeg

cp "$REPO/tests/inputs/batch/scene.json" "$REPO/tests/inputs/batch/sequence.json" "$work/"
seq="$work/sequence.json"

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
n2=$(frames_done "$work/B")
echo "interrupted after $n1 frame(s) (SIGTERM), killed after $n2 (SIGKILL)"
[ "$n2" -lt 5 ] || echo "note: the SIGKILL came after the last frame"
stat -c '%n %i %Y.%y' "$work"/B/frame-*/frame.json | sort > "$work/B.before"
"$THZMAP" batch "$seq" -o "$work/B" --quiet > /dev/null 2>&1 || fail "batch B, resumed: exit $?"
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

finish_counted "test_batch: all passed"
