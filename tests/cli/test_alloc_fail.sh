#!/usr/bin/env bash
# Out of memory at any allocation (issue 20; docs/reliability.md): validate, simulate and
# render a small scene (a mesh, a material table, two channels, a saved photon map) with
# the Nth allocation failing, through the LD_PRELOAD shim tests/support/failalloc.c.
# A counting run gives each command's total: its own allocations and those of the
# child processes that draw the figures (they continue the count). N takes every value
# up to 120, then 100 log-spaced values up to the process's total, then 25 log-spaced
# values through the children's range (THZ_ALLOC_FAIL_SCALE, else THZ_TEST_SCALE, thins
# the sample: the sanitizer build sets 0.25; THZ_ALLOC_FAIL_FULL=1 takes every N up to
# the total). Every run must:
#  - exit 0 with complete results (a library absorbed the failure), or 1 with a message
#    on stderr; "out of memory" when the failure hit thzmap's own process (also when
#    libgomp ended it with exit(): the CLI's exit handler says so and cleans up); never
#    2 (the scene is valid), never a signal (crash), never a sanitizer report (but one:
#    see figure_crashes_only), no hang;
#  - leave nothing beside OUTDIR (no staging directory, no lock file), and OUTDIR as it
#    was: absent stays absent, a previous run stays byte for byte.
# Then render with each of zstd's own allocations failing in turn (THZ_FAIL_ALLOC_IN),
# which the sample may miss: exit 1, "out of memory".
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
SHIM=$(dirname "$THZMAP")/libthz_failalloc.so
[ -f "$SHIM" ] || { echo "FAIL: $SHIM is missing (built with the thzmap target's CMake)"; exit 1; }
SCALE=${THZ_ALLOC_FAIL_SCALE:-${THZ_TEST_SCALE:-1}}

mkdir -p "$work/scene/materials"
cp "$REPO/examples/meshes/pyramid.obj" "$work/scene/"
cp "$REPO/examples/plate-in-box/materials/sample.csv" "$work/scene/materials/"
cat > "$work/scene/scene.json" <<'JSON'
{
  "format": "thzmap-scene/1",
  "name": "alloc-fail",
  "channels": [{"frequency_thz": 0.35, "relative_width": 0.05},
               {"frequency_thz": 0.6, "relative_width": 0.05}],
  "materials": {"wall": {"reflectivity": 0.2}, "table": {"file": "materials/sample.csv"}},
  "atmosphere": {"model": "constant", "attenuation_per_m": 0.05},
  "objects": [
    {"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
     "shape": {"type": "box", "size_m": [2, 2, 2], "inward": true}},
    {"name": "pyramid", "type": "solid", "material": "table", "temperature_k": 310,
     "shape": {"type": "mesh", "file": "pyramid.obj"}, "transform": {"scale": 0.3}}
  ],
  "sensors": [{"name": "cam", "position_m": [0, -0.9, 0], "look_at_m": [0, 0, 0],
               "fov_deg": 60, "resolution": [6, 5]}],
  "photons": {"per_channel": 200, "seed": 3, "gather_min_photons": 4},
  "render": {"integrator": "photon-map"}
}
JSON
scene=$work/scene/scene.json
"$THZMAP" simulate "$scene" -o "$work/pm" --threads 1 --quiet --save-photon-map ||
  { echo "FAIL: the scene does not simulate without failures"; exit 1; }
# A previous run's results, the OUTDIR content that must survive a failed run.
"$THZMAP" render "$scene" --photon-map "$work/pm/photon-map.thzpm" -o "$work/previous" \
  --threads 1 --quiet || { echo "FAIL: the scene does not render without failures"; exit 1; }
(cd "$work/previous" && find . -type f | sort | xargs sha256sum) > "$work/previous.sums"

# The commands; OUT is replaced by the run's OUTDIR.
cmd_validate=(validate "$scene")
cmd_simulate=(simulate "$scene" -o OUT --threads 1 --quiet --save-photon-map)
cmd_render=(render "$scene" --photon-map "$work/pm/photon-map.thzpm" -o OUT --threads 1 --quiet)

# Behind the sanitizer's allocator (the sanitizer build) the shim must come first.
export ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0
export THZMAP SHIM work

# In the sanitizer build, the one kind of sanitizer report a run may contain: a memory
# error inside the libraries that draw a figure, in the child process that draws it,
# when they do not check an allocation (seen: fontconfig dereferencing NULL in its XML
# parser and font matching; PLplot's device enumeration passing the NULL of a failed
# plstrdup to strcmp, reading a directory entry after closedir, freeing an uninitialised
# pointer in plend, calling through the NULL of a driver's set-up function it could not
# look up: "Unable to locate dispatch table initialization function", then a one-frame
# stack at address 0). The release build sees the same child crash, or not, and the run
# fails "while plotting" either way; AddressSanitizer reports it and aborts the child
# (signal 6). Each such report must be AddressSanitizer's, and its innermost frame that
# is neither the sanitizer's runtime, the shim nor the C library (frames with a relative
# source path: glibc, libsanitizer) must be in one of these libraries; thzmap's process
# must have survived and said "the process doing it ended by signal". Anything else is a
# failure: a leak (tests/lsan.supp names the library caches that are not leaks), UBSan's
# "runtime error" (only thzmap's code is instrumented), a report from thzmap's code or
# thzmap's process.
FIGURE_LIBS='/lib(fontconfig|expat|freetype|harfbuzz|pango[a-z0-9]*-1\.0|cairo|pixman-1|glib-2\.0|gobject-2\.0|plplot|ltdl)\.so|/plplot[0-9.]*/drivers/'
export FIGURE_LIBS

# Succeeds when every sanitizer report in file $1 is such a report from a figure's child.
figure_crashes_only() {
  grep -q 'runtime error' "$1" && return 1
  grep -q 'the process doing it ended by signal' "$1" || return 1
  awk '
    BEGIN { libs = ENVIRON["FIGURE_LIBS"] }
    /==[0-9]+==ERROR: / {
      if (in_stack) bad = 1 # the last report had no frame outside the runtime: no evidence
      reports++
      if ($0 !~ /ERROR: AddressSanitizer: /) bad = 1
      in_stack = 1; next
    }
    /Unable to locate dispatch table initialization function for driver/ { null_driver = 1 }
    in_stack && /^ +#[0-9]+ / {
      # the runtime, the shim, the C library: by its file, or by a source path that is
      # relative (glibc frames read "in ___pthread_mutex_init nptl/pthread_mutex_init.c:89")
      if ($0 ~ / \.\.\/|libasan|failalloc|\/libc\.so/) next
      if ($0 ~ / in [^ ]+ [^\/( ][^ ]*:[0-9]+(:[0-9]+)?$/) next
      in_stack = 0
      # PLplot, the set-up function of its driver not found for want of memory (its message
      # above), calls through the NULL it got: a single frame at address 0
      if (null_driver && $0 ~ /^ +#0 0x0 +\(<unknown module>\)$/) next
      if ($0 !~ libs) bad = 1
    }
    END { exit !(reports > 0 && !bad && !in_stack) }' "$1"
}
export -f figure_crashes_only

# The other library crash seen under the sanitizers (2026-12-03, a few runs in a
# hundred through the figures' range): a thread that a library started in a figure's
# process (thzmap's code there starts none) meets the failed allocation after the
# figure is written; AddressSanitizer prints its SEGV header with no stack and the
# figure's process ends, thzmap's process having its figure: exit 0, results complete.
# Succeeds when thzmap's process ($2, the report: its own line is the last) did not fail
# an allocation and every report in file $1 is such a header from the process whose
# allocation failed, in a thread other than its first, with no frame printed.
figure_thread_crash_only() {
  grep -qE 'LeakSanitizer|runtime error' "$1" && return 1
  local parent failed
  parent=$(awk 'END { print $1 }' "$2" 2>/dev/null)
  failed=$(awk '$3 == 1 { print $1 }' "$2" 2>/dev/null)
  [ -n "$parent" ] && [ -n "$failed" ] && [ "$failed" != "$parent" ] || return 1
  awk -v failed="$failed" '
    /==[0-9]+==ERROR: / {
      reports++
      if ($0 !~ /ERROR: AddressSanitizer: SEGV on unknown address .* T[1-9][0-9]*\)$/) bad = 1
      if (index($0, "==" failed "==") != 1) bad = 1
    }
    /^ +#[0-9]+ / { bad = 1 }
    END { exit !(reports > 0 && !bad) }' "$1"
}
export -f figure_thread_crash_only

# Embree leaks what its BVH build had allocated when an allocation in the build fails
# (seen 2026-12-05 in the sanitizer build, a render whose failure hit Embree's build: 160
# bytes from operator new and 1024 from posix_memalign, every frame inside libembree3).
# thzmap reports out of memory and releases the scene and the device (accel_destroy);
# what Embree keeps of its failed build is beyond its API. Succeeds when thzmap said so,
# and every sanitizer report in file $1 is LeakSanitizer's, each leak's innermost frame
# beyond the runtime, the shim and the C library in libembree3.
embree_leak_only() {
  grep -q 'Embree failed while building the acceleration structure: out of memory' "$1" ||
    return 1
  grep -q 'runtime error' "$1" && return 1
  awk '
    /==[0-9]+==ERROR: / { if ($0 !~ /ERROR: LeakSanitizer: detected memory leaks/) bad = 1 }
    /^(Direct|Indirect) leak of / { leaks++; if (in_stack) bad = 1; in_stack = 1; next }
    in_stack && /^ +#[0-9]+ / {
      if ($0 ~ / \.\.\/|libasan|failalloc|\/libc\.so/) next
      in_stack = 0
      if ($0 !~ /\/libembree3\.so/) bad = 1
    }
    END { exit !(leaks > 0 && !bad && !in_stack) }' "$1"
}
export -f embree_leak_only

# One run: run_one NAME N ARGS...; prints one result line "N verdict detail".
run_one() {
  local name=$1 n=$2
  shift 2
  local dir=$work/runs/$name-$n
  mkdir -p "$dir"
  local has_out=$((n % 2)) # odd N: OUTDIR holds a previous run; even N: it is absent
  [ "$has_out" = 1 ] && [ "$name" != validate ] && cp -a "$work/previous" "$dir/out"
  local args=()
  for a in "$@"; do args+=("${a/#OUT/$dir/out}"); done
  local t0=$(date +%s%N)
  timeout -s KILL 90 env THZ_FAIL_ALLOC_AT="$n" THZ_FAIL_ALLOC_REPORT="$dir/report" \
    LD_PRELOAD="$SHIM" "$THZMAP" "${args[@]}" >/dev/null 2>"$dir/err"
  local rc=$?
  local ms=$(( ($(date +%s%N) - t0) / 1000000 ))
  local parent_failed
  parent_failed=$(awk 'END { print $3 }' "$dir/report" 2>/dev/null)
  local verdict=ok detail="exit $rc, $ms ms"
  local msg
  msg=$(grep -v '^failalloc' "$dir/err" | head -c 300 | tr '\n' ' ')
  if grep -q LeakSanitizer "$dir/err" && embree_leak_only "$dir/err"; then
    verdict=embree-leak # exit 134 (abort_on_error) or LeakSanitizer's 23
  elif [ "$rc" -ge 124 ]; then
    verdict=bad detail="exit $rc (signal or timeout after $ms ms): $msg"
  elif grep -qE 'AddressSanitizer|LeakSanitizer|runtime error' "$dir/err"; then
    if [ "$rc" = 1 ] && figure_crashes_only "$dir/err"; then
      verdict=figure-crash
    elif [ "$rc" = 0 ] && figure_thread_crash_only "$dir/err" "$dir/report"; then
      verdict=figure-thread-crash
    else
      verdict=bad detail="sanitizer report: $msg"
    fi
  elif [ "$rc" = 2 ]; then
    verdict=bad detail="exit 2 (bad input) for a valid scene: $msg"
  elif [ "$rc" = 1 ] && [ -z "$msg" ]; then
    verdict=bad detail="exit 1 without a message"
  elif [ "$rc" = 1 ] && [ "$parent_failed" = 1 ] && ! grep -qi 'out of memory' "$dir/err"; then
    verdict=bad detail="the failure hit thzmap's process but the message does not say out of memory: $msg"
  elif [ "$rc" != 0 ] && [ "$rc" != 1 ]; then
    verdict=bad detail="exit $rc: $msg"
  fi
  # Nothing beside OUTDIR, OUTDIR as it was (or complete after a success).
  local left
  left=$(ls -A "$dir" | grep -vxE 'out|err|report' | tr '\n' ' ')
  [ -n "$left" ] && verdict=bad detail="$detail; left beside OUTDIR: $left"
  if [ "$name" != validate ]; then
    if [ "$rc" = 0 ]; then
      [ -f "$dir/out/summary.json" ] || { verdict=bad; detail="$detail; exit 0 without summary.json"; }
    elif [ "$has_out" = 1 ]; then
      (cd "$dir/out" && find . -type f | sort | xargs sha256sum) | cmp -s - "$work/previous.sums" ||
        { verdict=bad; detail="$detail; the previous run in OUTDIR changed"; }
    elif [ -e "$dir/out" ]; then
      verdict=bad detail="$detail; a failed run created OUTDIR"
    fi
  fi
  [ "$rc" = 0 ] && [ "$verdict" = ok ] && verdict=absorbed
  [ "$verdict" = ok ] && grep -q 'a library ended the process' "$dir/err" && verdict=exited
  echo "$n $verdict $detail"
  [ "$verdict" = bad ] || rm -rf "$dir"
}
export -f run_one

# N values: every one up to DENSE, LOG log-spaced ones up to the process's own count,
# CHILD log-spaced ones through the figure processes' range (each times THZ_TEST_SCALE).
# THZ_ALLOC_FAIL_FULL=1: every N up to the process's own count, 200 in the children's.
DENSE=120 LOG=100 CHILD=25
[ "${THZ_ALLOC_FAIL_FULL:-0}" = 1 ] && DENSE=1000000 LOG=0 CHILD=200 SCALE=1
sample() {
  python3 - "$1" "$2" "$SCALE" "$DENSE" "$LOG" "$CHILD" <<'PY'
import math, sys
own, most = int(sys.argv[1]), int(sys.argv[2])
scale, dense, n_log, n_child = float(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), int(sys.argv[6])
def logspace(lo, hi, k):
    if hi <= lo or k <= 0: return set()
    return {int(round(math.exp(math.log(lo) + (math.log(hi) - math.log(lo)) * i / k)))
            for i in range(1, k + 1)}
dense = max(1, int(dense * min(scale, 1.0)))
ns = set(range(1, min(dense, own) + 1)) | logspace(dense, own, int(n_log * scale)) \
    | logspace(own, most, int(n_child * scale))
print("\n".join(str(n) for n in sorted(ns)))
PY
}

t_start=$(date +%s)
total_runs=0
for name in validate simulate render; do
  declare -n cmd="cmd_$name"
  args=()
  for a in "${cmd[@]}"; do args+=("${a/#OUT/$work/count-$name}"); done
  rm -f "$work/count.report"
  THZ_FAIL_ALLOC_REPORT=$work/count.report LD_PRELOAD=$SHIM "$THZMAP" "${args[@]}" \
    >/dev/null 2>"$work/count.err" || fail "$name: the counting run failed: $(cat "$work/count.err")"
  # the last line is the parent's (it exits last); the largest count is a child's
  own=$(tail -n 1 "$work/count.report" | awk '{ print $2 }')
  most=$(awk 'BEGIN { m = 0 } $2 > m { m = $2 } END { print m }' "$work/count.report")
  sample "$own" "$most" > "$work/ns-$name"
  runs=$(wc -l < "$work/ns-$name")
  total_runs=$((total_runs + runs))
  t0=$(date +%s)
  xargs -P 2 -I{} bash -c 'run_one "$@"' _ "$name" {} "${cmd[@]}" < "$work/ns-$name" \
    > "$work/results-$name"
  bad=$(grep -c ' bad ' "$work/results-$name")
  absorbed=$(grep -c ' absorbed ' "$work/results-$name")
  oom=$(grep -c ' ok exit 1' "$work/results-$name")
  exited=$(grep -c ' exited ' "$work/results-$name")
  crashed=$(grep -c ' figure-crash ' "$work/results-$name")
  threads=$(grep -c ' figure-thread-crash ' "$work/results-$name")
  embree=$(grep -c ' embree-leak' "$work/results-$name")
  echo "$name: $own allocations in thzmap's process, up to $most with its child processes (figures, mesh import);" \
    "$runs runs in $(($(date +%s) - t0)) s: $oom exit 1 (out of memory reported)," \
    "$exited exit 1 (a library's exit(), cleaned up), $crashed exit 1 (a figure's process" \
    "crashed in a library, under the sanitizers), $absorbed exit 0 (absorbed)," \
    "$threads exit 0 (a library's thread in a figure's process crashed after the figure," \
    "under the sanitizers), $embree out of memory in Embree's build (its leak, under the" \
    "sanitizers), $bad bad"
  if [ "$bad" != 0 ]; then
    fail "$name: $bad runs misbehaved; the first ones:"
    grep ' bad ' "$work/results-$name" | sort -n | head -n 20
  fi
  unset -n cmd
done
echo "alloc fail: $total_runs runs in $(($(date +%s) - t_start)) s"

# zstd's own allocations as render reads the map, each in turn (THZ_FAIL_ALLOC_IN counts
# only the calls from libzstd's code, so no change elsewhere moves them): the decoder's
# window buffer, its second, was reported as a corrupted map with exit status 2. Each
# must end in exit 1, "out of memory", no sanitizer report and no OUTDIR; the first run
# with none left to fail must succeed.
k=1
while :; do
  rm -rf "$work/z" "$work/z.report"
  timeout -s KILL 90 env THZ_FAIL_ALLOC_IN="libzstd:$k" THZ_FAIL_ALLOC_REPORT="$work/z.report" \
    LD_PRELOAD="$SHIM" "$THZMAP" "${cmd_render[@]/#OUT/$work/z}" > /dev/null 2> "$work/z.err"
  rc=$?
  if ! awk '$3 == 1 { hit = 1 } END { exit !hit }' "$work/z.report"; then
    [ "$rc" = 0 ] || fail "render, none of zstd's allocations failing: exit $rc: $(head -c 300 "$work/z.err")"
    break
  fi
  { [ "$rc" = 1 ] && grep -q 'out of memory' "$work/z.err" && ! grep -q 'ERROR: ' "$work/z.err" &&
      [ ! -e "$work/z" ]; } ||
    fail "render, zstd's allocation $k failing: exit $rc: $(head -c 300 "$work/z.err")"
  k=$((k + 1))
  [ "$k" -le 64 ] || { fail "render: more than 64 allocations by zstd"; break; }
done
[ "$k" -ge 3 ] || fail "render: zstd made $((k - 1)) allocations; its context and window make 2"
echo "alloc fail: zstd's $((k - 1)) allocations in render failed in turn"
finish "alloc fail: all checks passed"
