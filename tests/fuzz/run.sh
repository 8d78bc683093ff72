#!/usr/bin/env bash
# Runs every libFuzzer harness of a THZ_FUZZ build for SECONDS each (`make fuzz`,
# `make fuzz-ci`; tests/fuzz/README.md):
#   bash tests/fuzz/run.sh BUILD_DIR SECONDS [HARNESS...]
# Each harness starts from a copy of its seed corpus (tests/fuzz/corpus/<name>/, left
# unchanged) with its dictionary, -timeout=1 (an input slower than 1 s is a finding),
# -rss_limit_mb=2048 and leak detection. Prints per harness the executions, exec/s,
# coverage (cov:, ft:) and corpus size. Exits 1 if any harness found anything: a crash,
# a sanitizer report, a leak, a timeout or memory beyond the limit; the input is kept in
# BUILD_DIR/fuzz-findings/<name>/ (replay it with fuzz_replay_<name> FILE).
# libFuzzer's timeout is wall-clock time, which a busy machine stretches: it runs in fork
# mode (-fork=1) so that a timeout does not end the run, and each timeout input is then
# replayed by fuzz_replay_<name>, which counts it only if it takes more than 1 s of both
# wall-clock and CPU time. A crash, leak or out-of-memory ends the run at once.
# The harnesses run FUZZ_JOBS at a time (default: the processor count; each is one
# process on one core), their lines printed in the order above.
set -uo pipefail
build=${1:?usage: run.sh BUILD_DIR SECONDS [HARNESS...]}
seconds=${2:?usage: run.sh BUILD_DIR SECONDS [HARNESS...]}
shift 2
# absolute: the serve harness's server works in its root directory (chdir), and libFuzzer
# writes the corpus and findings it finds after that
build=$(cd "$build" && pwd) || exit 2
here=$(cd "$(dirname "$0")" && pwd)
harnesses=("$@")
if [ ${#harnesses[@]} -eq 0 ]; then
  harnesses=(scene csv lines photon_map mesh envi sequence)
  # the server's only where libmicrohttpd was found (tests/fuzz/CMakeLists.txt)
  [ -x "$build/tests/fuzz/fuzz_serve" ] && harnesses+=(serve)
fi
declare -A max_len=([scene]=8192 [csv]=4096 [lines]=8192 [photon_map]=16384 [mesh]=16384 [envi]=8192
  [sequence]=8192 [serve]=8192)

# One harness: its line on stdout; exit 0 if it found nothing.
fuzz_one() {
  local h=$1
  local bin=$build/tests/fuzz/fuzz_$h
  local work=$build/fuzz-work/$h
  local findings=$build/fuzz-findings/$h
  local log=$build/fuzz-work/$h.log
  rm -rf "$work" "$findings"
  mkdir -p "$work" "$findings"
  cp "$here/corpus/$h"/* "$work"/
  local dict=()
  [ -f "$here/$h.dict" ] && dict=(-dict="$here/$h.dict")
  ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 \
  LSAN_OPTIONS=suppressions=$here/../lsan.supp:print_suppressions=0 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$bin" -fork=1 -ignore_timeouts=1 -max_total_time="$seconds" -timeout=1 \
      -rss_limit_mb=2048 -malloc_limit_mb=2048 -max_len="${max_len[$h]}" \
      -artifact_prefix="$findings/" "${dict[@]}" "$work" >"$log" 2>&1
  local rc=$?
  # confirm the timeouts (see the top)
  local t
  for t in "$findings"/timeout-*; do
    [ -e "$t" ] || continue
    if timeout 120 "$build/tests/fuzz/fuzz_replay_$h" --max-seconds 1 "$t" >>"$log" 2>&1; then
      echo "run.sh: $t: not slow when replayed (the machine was busy)" >>"$log"
      mkdir -p "$findings/unconfirmed"
      mv "$t" "$findings/unconfirmed/"
    fi
  done
  # fork mode's status line: "#N: cov: C ft: F corp: K exec/s E oom/timeout/crash: ..."
  local status execs cov ft corp rate
  status=$(grep -E '^#[0-9]+: cov:' "$log" | tail -1)
  execs=$(sed -n 's/^#\([0-9]*\):.*/\1/p' <<<"$status")
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$status")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$status")
  corp=$(ls "$work" | wc -l)
  rate=$(sed -n 's/.* exec\/s \([0-9]*\).*/\1/p' <<<"$status")
  printf 'fuzz %-10s %4ss: %9s execs (%s exec/s), cov: %s ft: %s corpus: %s files' "$h" \
    "$seconds" "${execs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" "$corp"
  # 70: libFuzzer's exit status when there were timeouts; they were just confirmed or not
  [ $rc -eq 70 ] && [ -d "$findings/unconfirmed" ] && rc=0
  if [ $rc -ne 0 ] || [ -n "$(find "$findings" -maxdepth 1 -type f)" ] || [ -z "$status" ]; then
    printf '  FAILED (exit %s)\n' "$rc"
    grep -E '^(==[0-9]+==ERROR|SUMMARY|ALARM|.*slow input|.*runtime error|==[0-9]+== ERROR|MS: |artifact_prefix|Test unit written)' \
      "$log" | head -20 | sed 's/^/  | /'
    echo "  | full log: $log; inputs: $findings/"
    return 1
  fi
  printf '  ok\n'
}

for h in "${harnesses[@]}"; do
  [ -x "$build/tests/fuzz/fuzz_$h" ] ||
    { echo "fuzz: $build/tests/fuzz/fuzz_$h missing (build with THZ_FUZZ=ON)" >&2; exit 2; }
done
jobs_max=${FUZZ_JOBS:-$(nproc)}
mkdir -p "$build/fuzz-work"
failed=()
# Each harness starts once fewer than jobs_max run; its line goes to fuzz-work/<h>.line,
# its status to fuzz-work/<h>.rc.
running=0
for h in "${harnesses[@]}"; do
  while [ "$running" -ge "$jobs_max" ]; do
    wait -n
    running=$((running - 1))
  done
  rm -f "$build/fuzz-work/$h.rc"
  (
    fuzz_one "$h" >"$build/fuzz-work/$h.line"
    echo $? >"$build/fuzz-work/$h.rc"
  ) &
  running=$((running + 1))
done
wait
for h in "${harnesses[@]}"; do
  cat "$build/fuzz-work/$h.line"
  [ "$(cat "$build/fuzz-work/$h.rc" 2>/dev/null)" = 0 ] || failed+=("$h")
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: findings in: ${failed[*]}" >&2
  exit 1
fi
