#!/usr/bin/env bash
# A batch that resumes into OUTDIR reads which frames are finished before it locks OUTDIR
# (and before its memory check, which builds every frame to run). A batch of other values
# that runs into OUTDIR and ends in that window replaces those frames with its own; the
# resumed batch must see that once it holds the lock and run them again, not count them
# as finished (it wrote a batch.json of sequence B over the images of sequence A).
# strace stops the resumed batch (SIGSTOP) at its open of the lock file until the other
# batch has ended, which makes the window sure. A delay of 5 s there, in place of the
# stop, made the test depend on the other batch ending within it: under the sanitizer
# build on a loaded 2-core machine it did not, and the resumed batch met its lock.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
need strace

cat > "$work/scene.json" <<JSON
{
  "format": "thzmap-scene/1",
  "name": "batch-reuse-race",
  "channels": [{"frequency_thz": 0.35, "relative_width": 0.05}],
$(plate_in_room)
  "sensors": [
    {"name": "a", "position_m": [0, -0.9, 0], "look_at_m": [0, 0, 0], "fov_deg": 60,
     "resolution": [8, 6]}
  ],
  "render": {"integrator": "path", "paths_per_sample": 2},
  "photons": {"seed": 1}
}
JSON
for t in A:320:300 B:340:305; do
  IFS=: read -r name t0 t1 <<<"$t"
  cat > "$work/seq$name.json" <<JSON
{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 1, "frames": 2,
 "keyframes": [{"time_s": 0, "objects": {"plate": {"temperature_k": $t0}}},
               {"time_s": 1, "objects": {"plate": {"temperature_k": $t1}}}]}
JSON
done
cd "$work" || exit 1
"$THZMAP" batch seqA.json -o pureA -q --no-movies --threads 1 || fail "batch A"
"$THZMAP" batch seqB.json -o out -q --no-movies --threads 1 || fail "batch B"
# resume B (every frame finished), stopped at its lock; A runs and ends meanwhile
# (LeakSanitizer cannot run under ptrace: the sanitizer build checks the rest)
ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0 strace -f -qq -o "$work/strace.log" -e trace=openat -e inject=openat:signal=SIGSTOP:when=1 \
  -P out/.thzmap-batch-lock "$THZMAP" batch seqB.json -o out -q --no-movies --threads 1 2>/dev/null &
resumed=$!
for _ in $(seq 1 1200); do # at most 120 s
  grep -q "stopped by SIGSTOP" "$work/strace.log" 2>/dev/null && break
  kill -0 $resumed 2>/dev/null || break
  sleep 0.1
done
grep -q "stopped by SIGSTOP" "$work/strace.log" 2>/dev/null || fail "the resumed batch never opened its lock"
"$THZMAP" batch seqA.json -o out -q --no-movies --threads 1 || fail "batch A into out"
# SIGCONT to the batch itself, strace's child
for pid in $(cat /proc/$resumed/task/$resumed/children 2>/dev/null); do kill -CONT "$pid"; done
wait $resumed || fail "resumed batch B: exit $?"
grep -q '"sequence": ".*seqB.json"' out/batch.json || fail "batch.json is not B's"
for f in frame-00000 frame-00001; do
  cmp -s out/$f/a.brightness_temperature.img pureA/$f/a.brightness_temperature.img &&
    fail "$f holds A's images under B's batch.json"
done
grep -q '"frames_computed": 2' out/batch.json || fail "B did not run its frames again: $(grep frames_ out/batch.json | tr -d '\n ')"
finish ok
