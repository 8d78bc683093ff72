#!/usr/bin/env bash
# batch.json is rewritten as frames finish, not after every frame: a long sequence's file
# is megabytes, and writing it each frame made a 20 000-frame batch take 2.3 times as long
# per frame as a 100-frame one. 40 quick frames: batch.json is renamed into place at most
# once at the start, once a second, after the last frame and at the end (strace counts
# the renames), and the final file is complete and lists every frame.
# usage: test_batch_json_rate.sh THZMAP_BINARY REPO_DIR
. "$(dirname "$0")/lib.sh"
command -v strace >/dev/null || { echo "FAIL: strace is not installed (scripts/install-deps.sh)"; exit 1; }
/usr/bin/python3 - "$REPO/examples/walker/scene.json" "$work" <<'PY'
import json, sys
sc = json.load(open(sys.argv[1]))
for m in sc["materials"].values():  # absolute paths: the scene moves to tmp
    for k, v in list(m.items()):
        if k == "file" or k.endswith("_file"):
            m[k] = sys.argv[1].rsplit("/", 1)[0] + "/" + v
sc["sensors"][0]["resolution"] = [16, 12]
sc["render"] = {"integrator": "path", "paths_per_sample": 1}
json.dump(sc, open(sys.argv[2] + "/scene.json", "w"))
json.dump({"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 25, "frames": 40,
           "keyframes": [{"time_s": 0, "objects": {"person": {"transform": {"translate_m": [-1.6, 0.6, 0]}}}},
                         {"time_s": 1.6, "objects": {"person": {"transform": {"translate_m": [1.6, 0.6, 0]}}}}]},
          open(sys.argv[2] + "/seq.json", "w"))
PY
t0=$(date +%s.%N)
# LeakSanitizer (the sanitizer build) cannot run under ptrace: no leak check here
ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0 strace -f -qq -e trace=rename,renameat,renameat2 -o "$work/trace" \
    "$THZMAP" batch "$work/seq.json" -o "$work/out" --quiet >"$work/log" 2>&1
status=$?
t1=$(date +%s.%N)
[[ $status -eq 0 ]] || fail "batch: exit $status: $(tail -5 "$work/log")"
writes=$(grep -c 'batch\.json"' "$work/trace")
allowed=$(/usr/bin/python3 -c "import math; print(3 + math.ceil($t1 - $t0))")
[[ $writes -ge 2 && $writes -le $allowed ]] ||
    fail "batch.json written $writes times for 40 frames in $(/usr/bin/python3 -c "print(round($t1 - $t0, 2))") s (expected 2 to $allowed)"
/usr/bin/python3 - "$work/out/batch.json" <<'PY' || fail "the final batch.json"
import json, sys
b = json.load(open(sys.argv[1]))
assert b["complete"] and b["frames_done"] == 40 and len(b["frames"]) == 40, b["frames_done"]
assert all(f["status"] == "done" for f in b["frames"])
PY
finish_counted "ok: batch.json written $writes times for 40 frames in $(/usr/bin/python3 -c "print(round($t1 - $t0, 2))") s"
