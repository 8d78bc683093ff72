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
set -uo pipefail
build=${1:?usage: run.sh BUILD_DIR SECONDS [HARNESS...]}
seconds=${2:?usage: run.sh BUILD_DIR SECONDS [HARNESS...]}
shift 2
here=$(cd "$(dirname "$0")" && pwd)
harnesses=("$@")
[ ${#harnesses[@]} -gt 0 ] || harnesses=(scene csv lines photon_map mesh)
declare -A max_len=([scene]=8192 [csv]=4096 [lines]=8192 [photon_map]=16384 [mesh]=16384)

failed=()
for h in "${harnesses[@]}"; do
  bin=$build/tests/fuzz/fuzz_$h
  [ -x "$bin" ] || { echo "fuzz: $bin missing (build with THZ_FUZZ=ON)" >&2; exit 2; }
  work=$build/fuzz-work/$h
  findings=$build/fuzz-findings/$h
  log=$build/fuzz-work/$h.log
  rm -rf "$work"
  mkdir -p "$work" "$findings"
  cp "$here/corpus/$h"/* "$work"/
  dict=()
  [ -f "$here/$h.dict" ] && dict=(-dict="$here/$h.dict")
  ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 \
  LSAN_OPTIONS=suppressions=$here/../lsan.supp:print_suppressions=0 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$bin" -max_total_time="$seconds" -timeout=1 -rss_limit_mb=2048 -malloc_limit_mb=2048 \
      -max_len="${max_len[$h]}" -print_final_stats=1 -artifact_prefix="$findings/" \
      "${dict[@]}" "$work" >"$log" 2>&1
  rc=$?
  # the last status line: "#N DONE cov: C ft: F corp: K/B lim: ... exec/s: E rss: R"
  status=$(grep -E '^#[0-9]+[[:space:]]+(DONE|pulse|NEW|REDUCE|INITED)' "$log" | tail -1)
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$status")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$status")
  corp=$(sed -n 's/.* corp: \([0-9]*\/[0-9a-zA-Z]*\).*/\1/p' <<<"$status")
  rate=$(sed -n 's/.* exec\/s: \([0-9]*\).*/\1/p' <<<"$status")
  printf 'fuzz %-10s %4ss: %9s execs (%s exec/s), cov: %s ft: %s corpus: %s' "$h" "$seconds" \
    "${execs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" "${corp:-?}"
  if [ $rc -ne 0 ] || [ -n "$(ls -A "$findings")" ]; then
    printf '  FAILED (exit %s)\n' "$rc"
    grep -E '^(==[0-9]+==ERROR|SUMMARY|ALARM|.*runtime error|==[0-9]+== ERROR|MS: |artifact_prefix|Test unit written)' \
      "$log" | head -20 | sed 's/^/  | /'
    echo "  | full log: $log; inputs: $findings/"
    failed+=("$h")
  else
    printf '  ok\n'
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: findings in: ${failed[*]}" >&2
  exit 1
fi
