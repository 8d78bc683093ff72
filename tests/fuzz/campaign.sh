#!/usr/bin/env bash
# A long fuzzing campaign (the hour issue 20 asks for before it is resolved), one harness
# after the other so that it takes one core:
#   bash tests/fuzz/campaign.sh BUILD_DIR OUT_DIR SECONDS_PER_HARNESS [HARNESS...]
# Copies the harness programs to OUT_DIR/bin (a rebuild meanwhile does not disturb it),
# grows OUT_DIR/corpus/<name>/ from the seed corpus, and runs libFuzzer in fork mode
# (-fork=1) so that a finding does not end the campaign: crashes, leaks, timeouts (> 1 s)
# and memory beyond 2048 MB land in OUT_DIR/findings/<name>/. Logs: OUT_DIR/<name>.log;
# the last "#N: cov: C ft: F corp: K ..." line of each gives its totals.
set -uo pipefail
build=${1:?usage: campaign.sh BUILD_DIR OUT_DIR SECONDS [HARNESS...]}
out=${2:?usage: campaign.sh BUILD_DIR OUT_DIR SECONDS [HARNESS...]}
seconds=${3:?usage: campaign.sh BUILD_DIR OUT_DIR SECONDS [HARNESS...]}
shift 3
here=$(cd "$(dirname "$0")" && pwd)
harnesses=("$@")
[ ${#harnesses[@]} -gt 0 ] || harnesses=(scene csv lines photon_map mesh)
declare -A max_len=([scene]=8192 [csv]=4096 [lines]=8192 [photon_map]=16384 [mesh]=16384)
mkdir -p "$out/bin"
for h in "${harnesses[@]}"; do
  cp "$build/tests/fuzz/fuzz_$h" "$out/bin/"
done
for h in "${harnesses[@]}"; do
  mkdir -p "$out/corpus/$h" "$out/findings/$h"
  cp -n "$here/corpus/$h"/* "$out/corpus/$h/"
  dict=()
  [ -f "$here/$h.dict" ] && dict=(-dict="$here/$h.dict")
  echo "campaign: $h for $seconds s from $(date -u +%H:%M:%S) UTC" >>"$out/campaign.log"
  ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 \
  LSAN_OPTIONS=suppressions=$here/../lsan.supp:print_suppressions=0 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$out/bin/fuzz_$h" -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
      -max_total_time="$seconds" -timeout=1 -rss_limit_mb=2048 -malloc_limit_mb=2048 \
      -max_len="${max_len[$h]}" -artifact_prefix="$out/findings/$h/" "${dict[@]}" \
      "$out/corpus/$h" >"$out/$h.log" 2>&1
  echo "campaign: $h ended with status $? at $(date -u +%H:%M:%S) UTC;" \
    "$(grep -E '^#[0-9]+: cov:' "$out/$h.log" | tail -1)" >>"$out/campaign.log"
done
echo "campaign: done at $(date -u +%H:%M:%S) UTC" >>"$out/campaign.log"
