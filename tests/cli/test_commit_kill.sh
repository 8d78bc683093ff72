#!/usr/bin/env bash
# A kill -9 at any instant of a run, the output commit included, leaves OUTDIR holding
# the previous run or the new one, each whole (issue 20; docs/reliability.md):
#  - OUTDIR holds run A (seed 1); run B (seed 2) into it is killed with SIGKILL at 8
#    moments spread over its duration, its file-system calls slowed by strace's fault
#    injection (every rename, link and unlink waits 40 ms) so that the commit spans
#    most of the run; after each kill OUTDIR must be exactly A's files or exactly B's
#    (checksums of every file but summary.json, whose seed must match);
#  - the next run into that OUTDIR cleans up what the killed one left beside it;
#  - a second run into an OUTDIR in use is refused with a message, exit 1.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
need strace

cat > "$work/scene.json" <<JSON
{
  "format": "thzmap-scene/1",
  "name": "commit-kill",
  "channels": [{"frequency_thz": 0.35, "relative_width": 0.05},
               {"frequency_thz": 0.6, "relative_width": 0.05}],
$(plate_in_room)
  "sensors": [
    {"name": "a", "position_m": [0, -0.9, 0], "look_at_m": [0, 0, 0], "fov_deg": 60,
     "resolution": [8, 8]},
    {"name": "b", "position_m": [0, 0.9, 0], "look_at_m": [0, 0, 0], "fov_deg": 60,
     "resolution": [8, 8]}
  ],
  "render": {"integrator": "path", "paths_per_sample": 4}
}
JSON

# The checksums of a run's files (summary.json aside: it holds timings).
sums() { (cd "$1" && find . -maxdepth 1 -type f ! -name summary.json -printf '%f\n' | sort |
          xargs -r sha256sum); }
seed_of() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["seed"])' "$1/summary.json" 2>/dev/null; }

"$THZMAP" simulate "$work/scene.json" -o "$work/A" --seed 1 --quiet >/dev/null || fail "run A"
"$THZMAP" simulate "$work/scene.json" -o "$work/B" --seed 2 --quiet >/dev/null || fail "run B"
sums "$work/A" > "$work/A.sums"
sums "$work/B" > "$work/B.sums"
cmp -s "$work/A.sums" "$work/B.sums" && fail "runs A and B must differ for this test to mean anything"

# LeakSanitizer cannot run under ptrace (it aborts): the slowed runs of the sanitizer
# build check everything but leaks, which the unslowed runs here still check.
slow=(env "ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
      strace -f -qq -o /dev/null
      -e trace=rename,renameat,renameat2,link,linkat,unlink,unlinkat,rmdir
      -e inject=rename,renameat,renameat2,link,linkat,unlink,unlinkat,rmdir:delay_enter=40000)

# How long a slowed run takes, to spread the kills over it.
rm -rf "$work/out" && cp -a "$work/A" "$work/out"
t0=$(date +%s%N)
"${slow[@]}" "$THZMAP" simulate "$work/scene.json" -o "$work/out" --seed 2 --quiet >/dev/null ||
  fail "slowed run"
total_ms=$(( ($(date +%s%N) - t0) / 1000000 ))
cmp -s <(sums "$work/out") "$work/B.sums" || fail "a slowed run gives other files than run B"

n_old=0 n_new=0
for k in 1 2 3 4 5 6 7 8; do
  rm -rf "$work/out" && cp -a "$work/A" "$work/out"
  "${slow[@]}" "$THZMAP" simulate "$work/scene.json" -o "$work/out" --seed 2 --quiet \
    >/dev/null 2>&1 &
  tracer=$!
  sleep "$(awk -v t="$total_ms" -v k="$k" 'BEGIN { printf "%.3f", t * k / 9 / 1000 }')"
  pkill -KILL -P "$tracer" -x thzmap 2>/dev/null
  wait "$tracer" 2>/dev/null
  got=$(sums "$work/out")
  seed=$(seed_of "$work/out")
  if [ "$got" = "$(cat "$work/A.sums")" ] && [ "$seed" = 1 ]; then
    n_old=$((n_old + 1))
  elif [ "$got" = "$(cat "$work/B.sums")" ] && [ "$seed" = 2 ]; then
    n_new=$((n_new + 1))
  else
    fail "kill $k of 8 (at $k/9 of $total_ms ms): OUTDIR is neither run whole (seed '$seed')"
    ls -la "$work/out" "$work"
  fi
  # The next run cleans up what the killed one left beside OUTDIR.
  "$THZMAP" simulate "$work/scene.json" -o "$work/out" --seed 2 --quiet >/dev/null ||
    fail "the run after kill $k"
  left=$(find "$work" -maxdepth 1 -name '.thzmap-*' | wc -l)
  [ "$left" = 0 ] || fail "after kill $k and a clean run, $left .thzmap-* entries beside OUTDIR"
  cmp -s <(sums "$work/out") "$work/B.sums" || fail "the run after kill $k gives other files"
done
echo "kills that left the old run: $n_old, the new run: $n_new (of 8)"

# A second run into an OUTDIR in use is refused, saying why.
"${slow[@]}" "$THZMAP" simulate "$work/scene.json" -o "$work/busy" --quiet >/dev/null 2>&1 &
tracer=$!
for _ in $(seq 100); do
  ls -a "$work" | grep -q '^\.thzmap-.*-lock$' && break
  sleep 0.05
done
"$THZMAP" simulate "$work/scene.json" -o "$work/busy" --quiet >/dev/null 2>"$work/err"
rc=$?
[ "$rc" = 1 ] || fail "a second run into an OUTDIR in use exits $rc, expected 1"
grep -q 'another thzmap run' "$work/err" || fail "no clear message: $(cat "$work/err")"
wait "$tracer" || fail "the first run into busy/ failed"

finish "commit kill: all checks passed"
