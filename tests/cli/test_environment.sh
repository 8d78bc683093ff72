#!/usr/bin/env bash
# The process thzmap starts in (docs/reliability.md "The environment"): a standard output
# that cannot be written fails the commands whose product it is (exit 1, a message); a
# file-size limit fails a run cleanly (exit 1, nothing left, the message naming the file in
# OUTDIR, not in the staging directory) instead of SIGXFSZ killing it;
# a stack limit or OMP_STACKSIZE too small for its threads is refused up front (exit 2,
# they ended in SIGSEGV); OMP_NUM_THREADS beyond 4096 runs with 4096, the same bytes (it
# crashed libgomp); closed standard streams do not end up as the lock file's descriptor;
# an OUTDIR whose name is too long or that is not writable is refused before the run; a
# scene path that is not UTF-8 is written into summary.json with its bytes escaped;
# THZMAP_EMBREE_MAX_ISA takes Embree's instruction sets (avx2 by default), whose kernels
# give the same images (a hit's point and distance are thzmap's own arithmetic), and
# refuses anything else. More --threads than the CPUs the process may run on (its
# affinity: mpirun binds each rank to a core) are run, with a warning, and give the same bytes.
# usage: test_environment.sh THZMAP_BINARY REPO_DIR
. "$(dirname "$0")/lib.sh"
S=$REPO/examples/plate-in-box/scene.json
R=(--photons 20000 --integrator photon-map --threads 2 -q)

# expect WHAT STATUS PATTERN: the last command's status and stderr ($work/err)
expect() {
    [[ $2 == "$3" ]] || fail "$1: exit $2, expected $3: $(head -c 300 "$work/err")"
    [[ -z $4 ]] || grep -q -- "$4" "$work/err" || fail "$1: no '$4' in: $(head -c 300 "$work/err")"
}

# --- a standard output that cannot be written --------------------------------------------
"$THZMAP" --version >/dev/full 2>"$work/err"
expect "--version >/dev/full" $? 1 "cannot write the standard output"
"$THZMAP" validate "$S" >/dev/full 2>"$work/err"
expect "validate >/dev/full" $? 1 "cannot write the standard output"
"$THZMAP" materials >/dev/full 2>"$work/err"
expect "materials >/dev/full" $? 1 "cannot write the standard output"
"$THZMAP" validate "$S" 2>"$work/err" | head -c 10 >/dev/null
expect "validate | head" "${PIPESTATUS[0]}" 0 ""

# --- stderr closed: the lock file does not take its descriptor ----------------------------
"$THZMAP" simulate "$S" -o "$work/closed" --photons 20000 --integrator photon-map 2>&- >"$work/out"
rc=$?
[[ $rc -eq 0 ]] || fail "simulate with stderr closed: exit $rc"
[[ -s $work/closed/summary.json ]] || fail "simulate with stderr closed: no results"
[[ -z $(leftovers) ]] || fail "simulate with stderr closed left: $(leftovers)"

# --- a file-size limit --------------------------------------------------------------------
"$THZMAP" simulate "$S" -o "$work/before" "${R[@]}" --seed 1 2>"$work/err" || fail "the first run failed"
cp -r "$work/before" "$work/limited"
(ulimit -f 10; exec "$THZMAP" simulate "$S" -o "$work/limited" "${R[@]}" --seed 7) 2>"$work/err"
expect "ulimit -f 10" $? 1 "^thzmap: $work/limited/[^ ]*: write failed: File too large"
diff -r "$work/before" "$work/limited" >/dev/null || fail "ulimit -f: OUTDIR changed"
[[ -z $(leftovers) ]] || fail "ulimit -f left: $(leftovers)"

# --- few open files: a soft limit raised, a hard one refused ------------------------------
(ulimit -Sn 8; exec "$THZMAP" simulate "$S" -o "$work/soft8" "${R[@]}") 2>"$work/err"
expect "ulimit -Sn 8" $? 0 ""
(ulimit -n 8; exec "$THZMAP" simulate "$S" -o "$work/hard8" "${R[@]}") 2>"$work/err"
expect "ulimit -n 8" $? 2 "limit on open files (ulimit -n) is 8"

# --- a dangling symbolic link as OUTDIR ------------------------------------------------------
ln -s "$work/nowhere/x" "$work/dangling"
"$THZMAP" simulate "$S" -o "$work/dangling" "${R[@]}" 2>"$work/err"
expect "a dangling symlink OUTDIR" $? 2 "symbolic link to a missing path"

# --- stacks too small, threads too many ---------------------------------------------------
(ulimit -s 64; exec "$THZMAP" simulate "$S" -o "$work/s64" "${R[@]}") 2>"$work/err"
expect "ulimit -s 64" $? 2 "stack size limit (ulimit -s) is 64 KiB"
OMP_STACKSIZE=64K "$THZMAP" simulate "$S" -o "$work/o64" "${R[@]}" 2>"$work/err"
expect "OMP_STACKSIZE=64K" $? 2 "OMP_STACKSIZE=64K"
[[ ! -e $work/s64 && ! -e $work/o64 ]] || fail "a refused stack wrote OUTDIR"
OMP_STACKSIZE=2M "$THZMAP" validate "$S" >/dev/null 2>"$work/err"
expect "OMP_STACKSIZE=2M" $? 0 ""
# a size without a unit is in kilobytes (OpenMP's rule): 512 is 512 KiB, taken; 100 is
# 100 KiB, refused
OMP_STACKSIZE=512 "$THZMAP" validate "$S" >/dev/null 2>"$work/err"
expect "OMP_STACKSIZE=512" $? 0 ""
OMP_STACKSIZE=100 "$THZMAP" validate "$S" >/dev/null 2>"$work/err"
expect "OMP_STACKSIZE=100" $? 2 "gives each thread 100 KiB of stack"
OMP_NUM_THREADS=100000 "$THZMAP" simulate "$S" -o "$work/many" --photons 20000 \
    --integrator photon-map -q --seed 1 2>"$work/err"
expect "OMP_NUM_THREADS=100000" $? 0 ""
cmp -s "$work/many/cam.radiance.img" "$work/before/cam.radiance.img" ||
    fail "OMP_NUM_THREADS=100000: not the bytes of 2 threads"

# --- a scene in a directory whose name is not UTF-8 (Latin-1 bytes): summary.json says
#     where, the bytes written as \xNN (it failed as "out of memory" after the run) ----
odd=$work/$'sc\xff\xfe'
mkdir "$odd" && cp -r "$REPO/examples/plate-in-box/." "$odd/"
"$THZMAP" simulate "$odd/scene.json" -o "$work/odd" "${R[@]}" 2>"$work/err"
expect "a scene path that is not UTF-8" $? 0 ""
/usr/bin/python3 -c 'import json, sys; p = json.load(open(sys.argv[1]))["scene"]["path"]; assert p.endswith("sc\\xff\\xfe/scene.json"), p' \
    "$work/odd/summary.json" || fail "summary.json's scene path: $(grep '"path"' "$work/odd/summary.json")"

# --- a working directory deeper than 1024 bytes (PLplot's getcwd buffer: every figure
#     failed, PLplot ending its process) ------------------------------------------------
deep=$work
for _ in $(seq 11); do deep=$deep/$(printf 'd%.0s' $(seq 100)); done
mkdir -p "$deep"
(cd "$deep" && exec "$THZMAP" simulate "$S" -o out "${R[@]}") 2>"$work/err"
expect "a working directory of ${#deep} bytes" $? 0 ""
[[ -s $deep/out/cam.band-01.png ]] || fail "a deep working directory: no figure"

# --- OUTDIR refused before the run: a name too long, a directory not writable ------------
long=$work/$(printf 'b%.0s' $(seq 256))
"$THZMAP" simulate "$S" -o "$long" --photons 20000000 --integrator photon-map -q 2>"$work/err"
expect "a 256-byte OUTDIR name" $? 2 "its name is 256 bytes long"
[[ -z $(leftovers) ]] || fail "a 256-byte OUTDIR name left: $(leftovers)"
if [[ $(id -u) -eq 0 ]] && command -v runuser >/dev/null; then
    # as another user (root may write anywhere): OUTDIR theirs but read-only, parent writable
    mkdir "$work/ro" && chmod 755 "$work" && chown nobody "$work/ro"
    runuser -u nobody -- "$THZMAP" simulate "$S" -o "$work/ro/own" "${R[@]}" 2>"$work/err" ||
        fail "nobody's first run: $(cat "$work/err")"
    echo notes >"$work/ro/own/notes.txt"
    chmod 555 "$work/ro/own"
    runuser -u nobody -- "$THZMAP" simulate "$S" -o "$work/ro/own" "${R[@]}" --seed 9 2>"$work/err"
    expect "a read-only OUTDIR" $? 2 "exists and is not writable"
    [[ $(ls -A "$work/ro" | tr '\n' ' ') == "own " ]] ||
        fail "a read-only OUTDIR: beside it: $(ls -A "$work/ro" | tr '\n' ' ')"
    [[ -f $work/ro/own/notes.txt ]] || fail "a read-only OUTDIR lost the user's notes"
    chmod 755 "$work/ro/own"
    # a new OUTDIR in a directory the user cannot write: named, not the lock file
    chown root "$work/ro" && chmod 555 "$work/ro"
    runuser -u nobody -- "$THZMAP" simulate "$S" -o "$work/ro/new" "${R[@]}" 2>"$work/err"
    expect "OUTDIR in a read-only directory" $? 2 "ro/new: cannot write in .*/ro, where a run"
    [[ ! -e $work/ro/new ]] || fail "OUTDIR in a read-only directory was created"
    chmod 755 "$work/ro"
fi

# --- THZMAP_EMBREE_MAX_ISA: a set the processor has at most, or refused -------------------
"$THZMAP" simulate "$S" -o "$work/isa-default" "${R[@]}" 2>"$work/err"
expect "simulate" $? 0 ""
THZMAP_EMBREE_MAX_ISA=avx2 "$THZMAP" simulate "$S" -o "$work/isa-avx2" "${R[@]}" 2>"$work/err"
expect "THZMAP_EMBREE_MAX_ISA=avx2" $? 0 ""
for f in "$work/isa-default"/*.img; do # the default cap
    cmp -s "$f" "$work/isa-avx2/${f##*/}" || fail "THZMAP_EMBREE_MAX_ISA=avx2 changed ${f##*/}"
done
THZMAP_EMBREE_MAX_ISA=avx512 "$THZMAP" simulate "$S" -o "$work/isa-avx512" "${R[@]}" 2>"$work/err"
expect "THZMAP_EMBREE_MAX_ISA=avx512" $? 0 ""
THZMAP_EMBREE_MAX_ISA=sse4.2 "$THZMAP" simulate "$S" -o "$work/isa-sse" "${R[@]}" 2>"$work/err"
expect "THZMAP_EMBREE_MAX_ISA=sse4.2" $? 0 ""
for f in "$work/isa-default"/*.img; do # the kernels' own last bits stay out of the paths
    cmp -s "$f" "$work/isa-avx512/${f##*/}" || fail "THZMAP_EMBREE_MAX_ISA=avx512 changed ${f##*/}"
    cmp -s "$f" "$work/isa-sse/${f##*/}" || fail "THZMAP_EMBREE_MAX_ISA=sse4.2 changed ${f##*/}"
done
THZMAP_EMBREE_MAX_ISA=avx3 "$THZMAP" simulate "$S" -o "$work/isa-bad" "${R[@]}" 2>"$work/err"
expect "THZMAP_EMBREE_MAX_ISA=avx3" $? 2 'THZMAP_EMBREE_MAX_ISA: expected one of sse2, sse4.2'
[[ ! -e $work/isa-bad && -z $(leftovers) ]] || fail "THZMAP_EMBREE_MAX_ISA=avx3 left files"

# --- more threads than CPUs to run on (mpirun and srun bind ranks): said, same bytes ------
need taskset util-linux
taskset -c 0 "$THZMAP" simulate "$S" -o "$work/pinned" "${R[@]}" 2>"$work/err"
expect "--threads 2 on 1 CPU" $? 0 "simulate: warning: --threads 2, but this process may run on only 1 CPU"
for f in "$work/isa-default"/*.img; do
    cmp -s "$f" "$work/pinned/${f##*/}" || fail "--threads 2 on 1 CPU changed ${f##*/}"
done
taskset -c 0 "$THZMAP" simulate "$S" -o "$work/pinned1" --photons 20000 --integrator photon-map \
    --threads 1 -q 2>"$work/err"
expect "--threads 1 on 1 CPU" $? 0 ""
! grep -q "may run on only" "$work/err" || fail "--threads 1 on 1 CPU warned: $(cat "$work/err")"
echo '{"format": "thzmap-sequence/1", "scene": "'"$S"'"}' >"$work/seq.json"
taskset -c 0 "$THZMAP" batch "$work/seq.json" -o "$work/pinned-batch" --threads 3 -q --no-movies \
    2>"$work/err"
expect "batch --threads 3 on 1 CPU" $? 0 "batch: warning: --threads 3, but this process may run on only 1 CPU"

finish "environment: all passed"
