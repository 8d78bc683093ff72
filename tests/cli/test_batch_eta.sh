#!/usr/bin/env bash
# batch's ETA counts from the first frame, not from the batch's start: the sequence's load
# and the frames' memory check (each frame's scene loaded) are behind it when the frames
# run. Counted from the start, a 5000-frame batch of a tiny scene said "ETA 43779 s" after
# its first frame (8.6 s of checks over one frame, times 4999) for about 1 100 s of frames.
# 1000 frames of a 2 x 1 sensor in a room with 100 crates (so that the checks, 2-3 ms a
# frame, 10-15 ms under the sanitizers, take several times a frame's figures and files):
# after the first frame, the ETA must be below the time so far times the frames left (what
# the old ETA was) by a wide margin, and so must it after four frames: below half the time
# so far over the frames done, times the frames left. (An absolute bound, 2 s a frame, and
# a wait of at most 120 s for frame 5 made the test depend on the machine's speed: the
# sanitizer build on a loaded 2-core machine took 38 s to the first frame and 0.64 s a
# frame.) The batch is stopped (SIGINT) once frame 4 has begun.
# usage: test_batch_eta.sh THZMAP_BINARY REPO_DIR
. "$(dirname "$0")/lib.sh"
/usr/bin/python3 - "$work/scene.json" <<'PY'
import json, sys
crates = [{"name": f"crate{i}", "type": "solid", "material": "m", "temperature_k": 295,
           "shape": {"type": "box", "size_m": [0.05, 0.05, 0.05]},
           "transform": {"translate_m": [-4 + 0.08 * i, 4, 0.1]}} for i in range(100)]
json.dump({"format": "thzmap-scene/1",
           "channels": [{"frequency_thz": 0.35, "relative_width": 0.01}],
           "materials": {"wall": {"reflectivity": 0.0}, "m": {"reflectivity": 0.2}},
           "objects": [{"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
                        "shape": {"type": "box", "size_m": [10, 10, 4], "inward": True},
                        "transform": {"translate_m": [0, 0, 2]}},
                       {"name": "ball", "type": "solid", "material": "m", "temperature_k": 310,
                        "shape": {"type": "sphere", "radius_m": 0.5, "subdivisions": 1}}] + crates,
           "sensors": [{"name": "cam", "position_m": [0, -4, 1], "look_at_m": [0, 0, 1],
                        "fov_deg": 40, "resolution": [2, 1]}],
           "render": {"integrator": "path", "paths_per_sample": 1}}, open(sys.argv[1], "w"))
PY
cat >"$work/seq.json" <<'JSON'
{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 10, "frames": 1000,
 "keyframes": [{"time_s": 0, "objects": {"ball": {"transform": {"translate_m": [-1, 0, 1]}}}},
               {"time_s": 99.9, "objects": {"ball": {"transform": {"translate_m": [1, 0, 1]}}}}]}
JSON
"$THZMAP" batch "$work/seq.json" -o "$work/out" --no-movies --threads 1 >"$work/log" 2>&1 &
pid=$!
for _ in $(seq 1 4500); do # at most 450 s (ctest gives the test 600 s)
    grep -q "frame 5/1000" "$work/log" && break
    kill -0 $pid 2>/dev/null || break
    sleep 0.1
done
kill -INT $pid 2>/dev/null
wait $pid
line2=$(grep -m1 "frame 2/1000" "$work/log")
line5=$(grep -m1 "frame 5/1000" "$work/log")
[[ -n $line2 && -n $line5 ]] || fail "no frame lines: $(tail -3 "$work/log")"
if [[ -n $line2 && -n $line5 ]]; then
    /usr/bin/python3 - "$line2" "$line5" <<'PY' || fails=$((fails + 1))
import re, sys
def parse(line):
    m = re.search(r"\), ([0-9.]+) s, ETA ([0-9.]+) (s|min|h)", line)
    if not m:
        sys.exit("FAIL: cannot read the time and ETA in: " + line)
    scale = {"s": 1, "min": 60, "h": 3600}[m.group(3)]
    return float(m.group(1)), float(m.group(2)) * scale
t2, eta2 = parse(sys.argv[1])
t5, eta5 = parse(sys.argv[2])
old2 = t2 * 999  # the ETA counted from the batch's start
if not eta2 < 0.5 * old2:
    sys.exit("FAIL: after frame 1 the ETA %g s is the time since the start (%g s) times the "
             "frames left: %s" % (eta2, t2, sys.argv[1]))
old5 = t5 / 4 * 996  # the ETA counted from the batch's start
if not eta5 < 0.5 * old5:
    sys.exit("FAIL: after frame 4 the ETA %g s is the time since the start (%g s) over the "
             "4 frames done, times the frames left: %s" % (eta5, t5, sys.argv[2]))
print("ETA after frame 1: %g s (%g s so far); after frame 4: %g s" % (eta2, t2, eta5))
PY
fi
finish "ok: batch ETA counts from the first frame"
