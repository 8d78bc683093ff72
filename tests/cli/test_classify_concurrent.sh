#!/usr/bin/env bash
# classify reads RUN_DIR's cube and then its truth map. A simulate that commits into
# RUN_DIR between the two reads (made sure here by stopping classify, with strace's
# SIGSTOP at its open of the truth header, until the simulate has ended) must not give a
# classification of one run's cube against the other's truth: classify reads RUN_DIR
# again and classifies the new run, as if it had started after it (it paired them, exit
# 0, accuracy 0.27 where each run alone gives 0.99). A delay of 2 s at that open, in
# place of the stop, made the test depend on the simulate ending within it: under the
# sanitizer build on a loaded 2-core machine it did not, and classify read run 1 whole.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
need strace

for x in 1:0:310 2:0.15:320; do
  IFS=: read -r n dx t <<<"$x"
  cat > "$work/scene$n.json" <<JSON
{
  "format": "thzmap-scene/1",
  "name": "classify-concurrent",
  "channels": [{"frequency_thz": 0.35, "relative_width": 0.01},
               {"frequency_thz": 0.8, "relative_width": 0.01}],
  "materials": {"wall": {"reflectivity": 0.0},
                "paint": {"reflectivity": [[0.2, 0.05], [1.2, 0.12]]}},
  "objects": [
    {"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
     "shape": {"type": "box", "size_m": [1, 1, 2], "inward": true},
     "transform": {"translate_m": [0, 0, 1]}},
    {"name": "target", "type": "solid", "material": "paint", "temperature_k": $t,
     "shape": {"type": "cylinder", "radius_m": 0.1, "height_m": 0.75, "caps": true},
     "transform": {"translate_m": [$dx, 0, 0.001]}}
  ],
  "sensors": [
    {"name": "cam", "position_m": [0, -0.45, 0.4], "look_at_m": [0, 0, 0.4],
     "up": [0, 0, 1], "fov_deg": 40, "resolution": [24, 24]}
  ],
  "render": {"integrator": "path", "paths_per_sample": 2},
  "photons": {"seed": 1}
}
JSON
done
cd "$work" || exit 1
"$THZMAP" simulate scene2.json -o run2 -q && "$THZMAP" classify run2 --sensor cam -o pure2 -q ||
  fail "run 2 alone"
"$THZMAP" simulate scene1.json -o run -q || fail "run 1"
# (LeakSanitizer cannot run under ptrace: the sanitizer build checks the rest)
ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0 strace -f -qq -o "$work/strace.log" -e trace=openat -e inject=openat:signal=SIGSTOP:when=1 \
  -P run/cam.object_id.hdr "$THZMAP" classify run --sensor cam -o mixed -q 2>"$work/classify.err" &
classify=$!
for _ in $(seq 1 1200); do # at most 120 s
  grep -q "stopped by SIGSTOP" "$work/strace.log" 2>/dev/null && break
  kill -0 $classify 2>/dev/null || break
  sleep 0.1
done
grep -q "stopped by SIGSTOP" "$work/strace.log" 2>/dev/null || fail "classify never opened the truth header"
"$THZMAP" simulate scene2.json -o run -q || fail "run 2 into run"
# SIGCONT to classify itself, strace's child
for pid in $(cat /proc/$classify/task/$classify/children 2>/dev/null); do kill -CONT "$pid"; done
wait $classify || fail "classify: exit $?: $(cat "$work/classify.err")"
cmp -s mixed/cam.class.img pure2/cam.class.img ||
  fail "the classification is not run 2's: $(grep -m1 '"accuracy"' mixed/classification.json)"
finish ok
