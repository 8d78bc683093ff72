#!/usr/bin/env bash
# A batch that cannot lock OUTDIR for another reason than another batch's lock (ENOLCK:
# a network file system without a lock service; EINVAL: a kernel or file system without
# open file description locks) says why, not "another thzmap batch is running into this
# directory", which sent the user looking for a batch that did not exist; a lock held,
# which fcntl may report as EACCES or EAGAIN, is another batch's. strace makes the batch's
# fcntl on its lock file fail with ENOLCK, then EACCES.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
need strace
cat > "$work/scene.json" <<'JSON'
{
  "format": "thzmap-scene/1",
  "channels": [{"frequency_thz": 0.35, "relative_width": 0.05}],
  "materials": {"wall": {"reflectivity": 0.2}},
  "objects": [
    {"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
     "shape": {"type": "box", "size_m": [2, 2, 2], "inward": true}}
  ],
  "sensors": [
    {"name": "a", "position_m": [0, 0, 0], "look_at_m": [0, 1, 0], "fov_deg": 60,
     "resolution": [4, 3]}
  ],
  "render": {"integrator": "path", "paths_per_sample": 1}
}
JSON
cat > "$work/seq.json" <<'JSON'
{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 1, "frames": 1,
 "keyframes": [{"time_s": 0, "objects": {"room": {"temperature_k": 300}}}]}
JSON
cd "$work" || exit 1
mkdir out && : > out/.thzmap-batch-lock
# (LeakSanitizer cannot run under ptrace)
ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0 strace -f -qq -o /dev/null -e trace=fcntl -e inject=fcntl:error=ENOLCK \
  -P out/.thzmap-batch-lock "$THZMAP" batch seq.json -o out -q --no-movies --threads 1 2>"$work/err"
status=$?
[ $status -eq 1 ] || fail "exit $status, expected 1: $(cat "$work/err")"
grep -q "out/.thzmap-batch-lock: cannot lock: No locks available" "$work/err" ||
  fail "the message does not say why: $(cat "$work/err")"
grep -q "another thzmap batch" "$work/err" && fail "blames another batch: $(cat "$work/err")"
# and a lock held by another batch, which POSIX lets fcntl report as EACCES as well as
# EAGAIN, is that batch's (it said "cannot lock: Permission denied", a file's permissions)
ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0 strace -f -qq -o /dev/null -e trace=fcntl -e inject=fcntl:error=EACCES \
  -P out/.thzmap-batch-lock "$THZMAP" batch seq.json -o out -q --no-movies --threads 1 2>"$work/err"
status=$?
[ $status -eq 1 ] || fail "EACCES: exit $status, expected 1: $(cat "$work/err")"
grep -q "out: another thzmap batch is running into this directory" "$work/err" ||
  fail "EACCES: not said to be another batch's lock: $(cat "$work/err")"
finish ok
