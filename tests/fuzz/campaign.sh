#!/usr/bin/env bash
# A long fuzzing campaign (the hour issue 20 asks for before it is resolved), counted in
# CPU time so that a busy machine (run it under `nice -n 19`) delays it but does not
# shorten it:
#   bash tests/fuzz/campaign.sh BUILD_DIR OUT_DIR CPU_SECONDS_PER_HARNESS [HARNESS...]
# Copies the harness programs to OUT_DIR/bin (a rebuild meanwhile does not disturb it) and
# runs them in turn, CHUNK (default 120) wall-clock seconds at a time, until each has had
# its CPU seconds; OUT_DIR/corpus/<name>/ grows from the seed corpus, findings (crashes,
# leaks, inputs slower than 1 s, memory beyond 2048 MB) land in OUT_DIR/findings/<name>/
# and are confirmed like run.sh's. Progress: OUT_DIR/status (rewritten after each chunk:
# CPU seconds, executions, cov, ft, corpus files, findings per harness); logs:
# OUT_DIR/<name>.log. Stopped and started again, it carries on where it was.
set -uo pipefail
build=${1:?usage: campaign.sh BUILD_DIR OUT_DIR CPU_SECONDS [HARNESS...]}
out=${2:?usage: campaign.sh BUILD_DIR OUT_DIR CPU_SECONDS [HARNESS...]}
budget=${3:?usage: campaign.sh BUILD_DIR OUT_DIR CPU_SECONDS [HARNESS...]}
shift 3
# absolute: the serve harness's server works in its root directory (chdir)
mkdir -p "$out" && out=$(cd "$out" && pwd) && build=$(cd "$build" && pwd) || exit 2
chunk=${CHUNK:-120}
here=$(cd "$(dirname "$0")" && pwd)
harnesses=("$@")
if [ ${#harnesses[@]} -eq 0 ]; then
  harnesses=(scene csv lines photon_map mesh envi sequence)
  # the server's only where libmicrohttpd was found (tests/fuzz/CMakeLists.txt)
  [ -x "$build/tests/fuzz/fuzz_serve" ] && harnesses+=(serve)
fi
declare -A max_len=([scene]=8192 [csv]=4096 [lines]=8192 [photon_map]=16384 [mesh]=16384 [envi]=8192
  [sequence]=8192 [serve]=8192)
mkdir -p "$out/bin" "$out/state"
for h in "${harnesses[@]}"; do
  [ -x "$out/bin/fuzz_$h" ] || cp "$build/tests/fuzz/fuzz_$h" "$build/tests/fuzz/fuzz_replay_$h" "$out/bin/"
  mkdir -p "$out/corpus/$h" "$out/findings/$h"
  cp -n "$here/corpus/$h"/* "$out/corpus/$h/"
  for k in cpu execs; do [ -f "$out/state/$h.$k" ] || echo 0 >"$out/state/$h.$k"; done
done

write_status() {
  {
    echo "campaign status at $(date -u +%H:%M:%S) UTC (budget $budget CPU s per harness)"
    for h in "${harnesses[@]}"; do
      local last
      last=$(grep -E '^#[0-9]+[[:space:]]+(DONE|pulse|NEW|REDUCE|INITED)' "$out/$h.log" 2>/dev/null | tail -1)
      printf '%-10s cpu %7s s  execs %9s  cov %5s  ft %5s  corpus %4s files %6s KB  findings %s\n' "$h" \
        "$(cat "$out/state/$h.cpu")" "$(cat "$out/state/$h.execs")" \
        "$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")" \
        "$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")" \
        "$(ls "$out/corpus/$h" | wc -l)" "$(du -sk "$out/corpus/$h" | cut -f1)" \
        "$(find "$out/findings/$h" -maxdepth 1 -type f | wc -l)"
    done
  } >"$out/status.new"
  mv "$out/status.new" "$out/status"
}

while :; do
  pending=0
  for h in "${harnesses[@]}"; do
    cpu=$(cat "$out/state/$h.cpu")
    awk -v c="$cpu" -v b="$budget" 'BEGIN { exit !(c < b) }' || continue
    pending=1
    dict=()
    [ -f "$here/$h.dict" ] && dict=(-dict="$here/$h.dict")
    echo "=== chunk at $(date -u +%H:%M:%S) UTC" >>"$out/$h.log"
    start=$(wc -l <"$out/$h.log")
    ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 \
    LSAN_OPTIONS=suppressions=$here/../lsan.supp:print_suppressions=0 \
    UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      /usr/bin/time -o "$out/state/$h.time" -f '%U %S' \
      "$out/bin/fuzz_$h" -max_total_time="$chunk" -timeout=1 -rss_limit_mb=2048 \
        -malloc_limit_mb=2048 -max_len="${max_len[$h]}" -print_final_stats=1 \
        -artifact_prefix="$out/findings/$h/" "${dict[@]}" "$out/corpus/$h" >>"$out/$h.log" 2>&1
    used=$(tail -1 "$out/state/$h.time" | awk '{print $1 + $2}')
    execs=$(tail -n +"$((start + 1))" "$out/$h.log" | grep '^stat::number_of_executed_units:' |
      tail -1 | awk '{print $2}')
    awk -v a="$cpu" -v b="${used:-0}" 'BEGIN { printf "%.1f\n", a + b }' >"$out/state/$h.cpu"
    echo $(($(cat "$out/state/$h.execs") + ${execs:-0})) >"$out/state/$h.execs"
    for t in "$out/findings/$h"/timeout-*; do
      [ -e "$t" ] || continue
      if timeout 120 "$out/bin/fuzz_replay_$h" --max-seconds 1 "$t" >>"$out/$h.log" 2>&1; then
        mkdir -p "$out/findings/$h/unconfirmed"
        mv "$t" "$out/findings/$h/unconfirmed/"
      fi
    done
    write_status
  done
  [ $pending -eq 1 ] || break
done
echo "campaign: done at $(date -u +%H:%M:%S) UTC" >>"$out/status"
