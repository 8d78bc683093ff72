#!/usr/bin/env bash
# A batch killed (SIGKILL) while a frame's output is being committed, and run again,
# ends with the files of an uninterrupted batch (issue 17; docs/reliability.md):
#  - OUTDIR holds the 2 frames of sequence OLD; sequence NEW (other temperatures, so
#    both frames are redone) is run into it with its file-system calls slowed by
#    strace's fault injection (every rename, link and unlink waits 20 ms), so that the
#    commit of a frame over the old one (the exchange, then deleting the old frame's
#    files one by one) takes about half a second;
#  - it is killed whole (SIGKILL to its process group) at three moments found by
#    watching OUTDIR: inside frame 0's commit (frame-00000 already NEW's, its staging
#    directory still there), inside frame 1's, and while frame 1 is staged but not yet
#    committed;
#  - after each kill every frame directory is whole: OLD's frame or NEW's (checksums of
#    every file but summary.json, whose timings differ);
#  - run again unslowed, the batch ends with every file equal to an uninterrupted NEW
#    batch's (summary.json and batch.json aside: timings) and nothing left beside them.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
need strace

cat > "$work/scene.json" <<JSON
{
  "format": "thzmap-scene/1",
  "name": "batch-commit-kill",
  "channels": [{"frequency_thz": 0.35, "relative_width": 0.05},
               {"frequency_thz": 0.6, "relative_width": 0.05}],
$(plate_in_room)
  "sensors": [
    {"name": "a", "position_m": [0, -0.9, 0], "look_at_m": [0, 0, 0], "fov_deg": 60,
     "resolution": [8, 8]}
  ],
  "render": {"integrator": "path", "paths_per_sample": 2}
}
JSON
# sequence T0 T1: the plate at T0 K in frame 0 and T1 K in frame 1
sequence() {
    printf '{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 1, "frames": 2, "keyframes": [%s, %s]}\n' \
        "{\"time_s\": 0, \"objects\": {\"plate\": {\"temperature_k\": $1}}}" \
        "{\"time_s\": 1, \"objects\": {\"plate\": {\"temperature_k\": $2}}}"
}
sequence 320 330 > "$work/old.json"
sequence 300 310 > "$work/new.json"

# checksums of one frame directory's files (summary.json aside)
sums() { (cd "$1" 2>/dev/null && find . -maxdepth 1 -type f ! -name summary.json -printf '%f\n' |
          sort | xargs -r sha256sum); }
hash_of() { grep -o '"input_hash": "[0-9a-f]*"' "$1" 2>/dev/null; }

"$THZMAP" batch "$work/old.json" -o "$work/OLD" --quiet > /dev/null 2>&1 || fail "batch OLD"
"$THZMAP" batch "$work/new.json" -o "$work/NEW" --quiet > /dev/null 2>&1 || fail "batch NEW"
for i in 0 1; do
    sums "$work/OLD/frame-0000$i" > "$work/old-$i.sums"
    sums "$work/NEW/frame-0000$i" > "$work/new-$i.sums"
    cmp -s "$work/old-$i.sums" "$work/new-$i.sums" && fail "frame $i: OLD and NEW must differ for this test to mean anything"
    [ "$(wc -l < "$work/new-$i.sums")" -ge 10 ] || fail "frame $i: fewer than 10 files"
done
new_hash1=$(hash_of "$work/NEW/frame-00001/frame.json")
new_hash0=$(hash_of "$work/NEW/frame-00000/frame.json")

# LeakSanitizer cannot run under ptrace (test_commit_kill.sh)
slow=(env "ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
      strace -f -qq -o /dev/null
      -e trace=rename,renameat,renameat2,link,linkat,unlink,unlinkat,rmdir
      -e inject=rename,renameat,renameat2,link,linkat,unlink,unlinkat,rmdir:delay_enter=20000)

# moment NAME: true once the slowed batch into $work/out has reached it. Staging
# directories are named .thzmap-H-stage-PID-N, H a hash of the frame directory's name:
# H0, frame 0's, is learnt at the first moment.
stages() { ls -A "$work/out" | grep '^\.thzmap-.*-stage-'; }
h0=
moment() {
    local s
    s=$(stages | head -n 1)
    [ -n "$s" ] || return 1
    case $1 in
    commit-0) [ "$(hash_of "$work/out/frame-00000/frame.json")" = "$new_hash0" ] &&
              h0=${s%%-stage-*} ;;
    commit-1) [ "$(hash_of "$work/out/frame-00001/frame.json")" = "$new_hash1" ] ;;
    staged-1) [ -n "$h0" ] && [ "${s%%-stage-*}" != "$h0" ] &&
              [ "$(hash_of "$work/out/frame-00001/frame.json")" != "$new_hash1" ] ;;
    esac
}

n_hit=0
for at in commit-0 commit-1 staged-1; do
    rm -rf "$work/out" && cp -a "$work/OLD" "$work/out"
    setsid "${slow[@]}" "$THZMAP" batch "$work/new.json" -o "$work/out" --quiet > /dev/null 2>&1 &
    pid=$!
    hit=0
    for _ in $(seq 1 1500); do
        if moment "$at"; then hit=1; break; fi
        kill -0 $pid 2>/dev/null || break
        sleep 0.01
    done
    kill -KILL -- -$pid 2>/dev/null
    wait $pid 2>/dev/null
    [ $hit = 1 ] && n_hit=$((n_hit + 1)) || echo "note: the batch ended before the moment '$at'"
    for i in 0 1; do
        got=$(sums "$work/out/frame-0000$i")
        if [ "$got" != "$(cat "$work/old-$i.sums")" ] && [ "$got" != "$(cat "$work/new-$i.sums")" ]; then
            fail "killed at $at: frame $i is neither OLD's nor NEW's whole"
            ls -la "$work/out" "$work/out/frame-0000$i"
        fi
    done
    "$THZMAP" batch "$work/new.json" -o "$work/out" --quiet > /dev/null 2>&1 ||
        fail "the batch after the kill at $at: exit $?"
    for i in 0 1; do
        cmp -s <(sums "$work/out/frame-0000$i") "$work/new-$i.sums" ||
            fail "after the kill at $at and a rerun, frame $i differs from the uninterrupted batch's"
    done
    for f in "$work"/NEW/*.mp4; do
        cmp -s "$f" "$work/out/$(basename "$f")" || fail "after the kill at $at: $(basename "$f") differs"
    done
    left=$(ls -A "$work/out" | grep -v -x -e batch.json -e .thzmap-batch-lock -e 'frame-0000[01]' -e '.*\.mp4')
    [ -z "$left" ] || fail "after the kill at $at and a rerun, left in OUTDIR: $left"
done
echo "kills at the moment aimed at: $n_hit of 3"
[ $n_hit -ge 2 ] || fail "only $n_hit of 3 kills came at the moment aimed at"

finish "batch commit kill: all checks passed"
