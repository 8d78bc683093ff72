#!/usr/bin/env bash
# The Python package's MPI runs (docs/python.md "MPI"): a script started by
# `mpirun -np N python3 -m mpi4py` whose simulate, render and batch calls pass mpi=True
# gives, byte for byte, the files of the same script run as one process (summary.json
# and batch.json aside: wall times, threads, mpi_ranks); rank 0 gets the result (with the
# bytes it communicated), the other ranks None; only rank 0 writes and warns; a failure
# on rank 1, an argument only rank 0 refuses, and Ctrl-C on rank 0 while it waits for a
# stopped rank, or once its run has returned, each end the job with a message naming the
# rank and a non-zero exit, never a hang, and leave no OUTDIR; a script's own SIGINT
# handler keeps Ctrl-C; an argument every rank refuses raises on every rank;
# without a launcher mpi=True runs alone; examples/python/simulate_mpi.py runs on 2 ranks.
# Usage: bash test_python_mpi.sh THZMAP_BINARY REPO_DIR (the library beside the binary)
set -u
THZMAP=$1
REPO=$(cd "$2" && pwd)
PY=/usr/bin/python3
export THZMAP_LIBRARY=${THZMAP_LIBRARY:-$(cd "$(dirname "$THZMAP")" && pwd)/libthzmap.so}
export PYTHONPATH=$REPO/python PYTHONDONTWRITEBYTECODE=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
command -v mpirun >/dev/null || { echo "FAIL: mpirun is missing (scripts/install-deps.sh installs openmpi-bin)"; exit 1; }
$PY -c 'import mpi4py' 2>/dev/null ||
    { echo "FAIL: mpi4py is missing (scripts/install-deps.sh installs python3-mpi4py)"; exit 1; }
# CI runs as root, which Open MPI refuses unless told; --oversubscribe: 3 ranks on 2 cores
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1
mpi() { timeout 120 mpirun --oversubscribe -np "$@"; }

# plate-in-box with a small camera; 140 000 photons are 3 batches of 65 536, shared 2 + 1
# by 2 ranks. A 4-frame sequence of the batch test scene (3 photon groups: dealt whole to
# 3 ranks).
$PY - "$REPO" "$work" <<'PY'
import json, os, sys
repo, work = sys.argv[1:]
src = os.path.join(repo, "examples/plate-in-box/scene.json")
s = json.load(open(src))
s["materials"]["table"]["file"] = os.path.join(os.path.dirname(src), "materials/sample.csv")
s["sensors"][0]["resolution"] = [24, 24]
s["sensors"][0]["oversampling"] = 1
s["photons"]["per_channel"] = 140000
s.setdefault("render", {}).update({"gather_rays": 4})
json.dump(s, open(os.path.join(work, "scene.json"), "w"))
s["photons"]["per_channel"] = 70000  # what rank 1 loads in the failing run
json.dump(s, open(os.path.join(work, "other.json"), "w"))
b = json.load(open(os.path.join(repo, "tests/inputs/batch/scene.json")))
b["render"] = {"integrator": "photon-map"}
b["photons"] = {"seed": 7, "per_channel": 20000}
json.dump(b, open(os.path.join(work, "batch-scene.json"), "w"))
q = {"format": "thzmap-sequence/1", "scene": "batch-scene.json", "fps": 2, "frames": 4,
     "keyframes": [{"time_s": 0, "objects": {"person": {"transform": {"translate_m": [-0.5, 0, 0.8]}}},
                    "sensors": {"cam": {"position_m": [-0.3, -1.4, 0.9]}}},
                   {"time_s": 1, "objects": {"person": {"transform": {"translate_m": [0.5, 0, 0.8]}}},
                    "sensors": {"cam": {"position_m": [-0.3, -1.4, 0.9]}}},
                   {"time_s": 1.5, "sensors": {"cam": {"position_m": [0.3, -1.4, 0.9]}}}]}
json.dump(q, open(os.path.join(work, "seq.json"), "w"))
b["photons"] = {"seed": 7, "per_channel": 300, "gather_min_photons": 64}  # warns
json.dump(b, open(os.path.join(work, "warn-scene.json"), "w"))
q["scene"] = "warn-scene.json"
json.dump(q, open(os.path.join(work, "warn-seq.json"), "w"))
PY

# The script every rank runs: run.py WHAT OUT; each rank records in OUT.rank-R what its
# call returned (rank 0: the bytes it communicated) and the RunWarnings it gave, and its
# pid in OUT.pid-R.
cat > "$work/run.py" <<'PY'
import os, sys, warnings
import thzmap

what, out = sys.argv[1], sys.argv[2]
work = os.path.dirname(out)
rank = int(os.environ.get("OMPI_COMM_WORLD_RANK", "0"))
with open(f"{out}.pid-{rank}", "w") as f:
    f.write(str(os.getpid()))
with warnings.catch_warnings(record=True) as said:
    warnings.simplefilter("always", thzmap.RunWarning)
    if what in ("batch", "warn"):
        r = thzmap.batch(os.path.join(work, "seq.json" if what == "batch" else "warn-seq.json"),
                         out, threads=1, movies=what == "batch", mpi=True)
    else:
        name = "other.json" if what == "fail" and rank == 1 else "scene.json"
        scene = thzmap.load_scene(os.path.join(work, name))
        if what == "render":
            r = thzmap.render(scene, out + ".thzpm", integrator="final-gather", threads=1,
                              mpi=True)
        elif what == "seed":  # a seed with a map is refused; ranks 1.. give no map
            r = thzmap.render(scene, out + ".thzpm" if rank == 0 else None, seed=3,
                              integrator="final-gather", threads=1, mpi=True)
        elif what == "progress":  # refused alike on every rank
            try:
                thzmap.simulate(scene, progress=42, mpi=True)
            except thzmap.ArgumentError:
                # one write of the whole line: print's text and newline, written apart, can
                # interleave with the other rank's in the shared file
                sys.stdout.write(f"rank {rank}: refused\n")
                sys.stdout.flush()
            sys.exit(0)
        else:
            long = what in ("long", "own", "late")

            def started(p):  # rank 0 in its photon phase: the ranks' team has formed
                if not os.path.exists(out + ".started"):
                    open(out + ".started", "w").close()
            if what == "own":  # the script's own SIGINT handler: Ctrl-C is the script's
                import signal
                signal.signal(signal.SIGINT, lambda *a: open(out + ".caught", "w").close())
            if what == "late":  # a window after the run's C call, before the call ends
                import time
                bytes_ = thzmap.mpi.Shared.bytes

                def slow(self):
                    open(out + ".returned", "w").close()
                    time.sleep(3)
                    return bytes_(self)
                thzmap.mpi.Shared.bytes = slow
            r = thzmap.simulate(scene, integrator="photon-map", threads=1, keep_photons=True,
                                photons=4_000_000 if long else None,
                                progress=started if long else None, mpi=True)
        if r is not None:
            r.save(out, photon_map=what != "render")
with open(f"{out}.rank-{rank}", "w") as f:
    f.write("None" if r is None else str(getattr(r, "mpi_bytes", "batch")))
with open(f"{out}.warnings-{rank}", "w") as f:
    f.write(str(len(said)))
PY

# Every file below $1 equals $2's (summary.json and batch.json: times, threads, ranks
# and which run computed what aside); at least $4 files.
same() {
    $PY - "$@" <<'PY' || fail "$3"
import json, os, sys
a, b, what, least = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
def files(d):
    return sorted(os.path.relpath(os.path.join(r, f), d) for r, _, fs in os.walk(d)
                  for f in fs if f != ".thzmap-batch-lock")
def strip(path):
    d = json.load(open(path))
    for k in ("timings_s", "threads", "mpi_ranks", "frames_computed", "frames_reused",
              "photon_phases_fired", "frames_rerendered"):
        d.pop(k, None)
    for c in d.get("channels", []):
        c.pop("photon_phase_s", None); c.pop("render_s", None)
    for fr in d.get("frames", []) if isinstance(d.get("frames"), list) else []:
        for k in ("seconds", "computed", "photons"):
            fr.pop(k, None)
    return d
fa, fb = files(a), files(b)
bad = [] if fa == fb else [f"not the same files: {sorted(set(fa) ^ set(fb))}"]
for f in fa if not bad else []:
    pa, pb = os.path.join(a, f), os.path.join(b, f)
    if os.path.basename(f) in ("summary.json", "batch.json"):
        if strip(pa) != strip(pb):
            bad.append(f"{f} differs beyond times and ranks")
    elif open(pa, "rb").read() != open(pb, "rb").read():
        bad.append(f"{f} differs")
if len(fa) < least:
    bad.append(f"only {len(fa)} files")
for m in bad:
    print(f"{what}: {m}")
sys.exit(1 if bad else 0)
PY
}
said() { cat "$1" 2>/dev/null; }

# --- one process (no launcher: mpi=True runs alone) ------------------------------------
$PY "$work/run.py" simulate "$work/one" || fail "one process: simulate exited $?"
[ "$(said "$work/one.rank-0")" = 0 ] || fail "one process: mpi_bytes $(said "$work/one.rank-0"), not 0"
cp "$work/one/photon-map.thzpm" "$work/one-render.thzpm"
cp "$work/one/photon-map.thzpm" "$work/two-render.thzpm"
$PY "$work/run.py" render "$work/one-render" || fail "one process: render exited $?"
$PY "$work/run.py" batch "$work/one-batch" || fail "one process: batch exited $?"

# --- 2 ranks: simulate, then render from the saved map (rank 0 reads and sends it) -----
mpi 2 $PY -m mpi4py "$work/run.py" simulate "$work/two" > "$work/two.out" 2>&1 ||
    { fail "2 ranks: simulate exited $?"; cat "$work/two.out"; }
same "$work/two" "$work/one" "2 ranks, simulate (photon-map, its map kept)" 15
[ "$(said "$work/two.rank-1")" = None ] || fail "2 ranks: rank 1's simulate returned $(said "$work/two.rank-1")"
[ "$(said "$work/two.rank-0")" -gt 100000 ] 2>/dev/null ||
    fail "2 ranks: rank 0's mpi_bytes $(said "$work/two.rank-0") (the shares of 140 000 photons are more)"
$PY -c 'import json,sys; assert json.load(open(sys.argv[1]))["mpi_ranks"] == 2' "$work/two/summary.json" ||
    fail "2 ranks: summary.json's mpi_ranks is not 2"
mpi 2 $PY -m mpi4py "$work/run.py" render "$work/two-render" > "$work/two-render.out" 2>&1 ||
    { fail "2 ranks: render exited $?"; cat "$work/two-render.out"; }
same "$work/two-render" "$work/one-render" "2 ranks, render (final-gather from the map)" 10

# --- 3 ranks: a batch, its frames dealt whole ------------------------------------------
mpi 3 $PY -m mpi4py "$work/run.py" batch "$work/three-batch" > "$work/three-batch.out" 2>&1 ||
    { fail "3 ranks: batch exited $?"; cat "$work/three-batch.out"; }
same "$work/three-batch" "$work/one-batch" "3 ranks, batch" 40
for r in 1 2; do
    [ "$(said "$work/three-batch.rank-$r")" = None ] || fail "3 ranks: rank $r's batch returned $(said "$work/three-batch.rank-$r")"
done

# warnings: rank 0's alone (the others computed frames too), as `mpirun thzmap batch`
mpi 3 $PY -m mpi4py "$work/run.py" warn "$work/warn" > "$work/warn.out" 2>&1 ||
    { fail "3 ranks: the warning batch exited $?"; cat "$work/warn.out"; }
[ "$(said "$work/warn.warnings-0")" -gt 0 ] 2>/dev/null || fail "3 ranks: rank 0 gave no warnings"
for r in 1 2; do
    [ "$(said "$work/warn.warnings-$r")" = 0 ] || fail "3 ranks: rank $r gave $(said "$work/warn.warnings-$r") warnings"
done

# --- a rank that fails ends the job, says which, and leaves no OUTDIR ------------------
start=$SECONDS
mpi 2 $PY -m mpi4py "$work/run.py" fail "$work/fail" > "$work/fail.out" 2>&1
rc=$?
[ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] || fail "rank 1 with another scene: exit $rc (124: a hang)"
grep -q "thzmap (MPI rank 1): the run failed; ending the MPI job" "$work/fail.out" ||
    fail "rank 1 with another scene: no message naming the rank: $(cat "$work/fail.out")"
[ -e "$work/fail" ] && fail "rank 1 with another scene: rank 0 wrote OUTDIR"
[ $((SECONDS - start)) -lt 60 ] || fail "the failed job took $((SECONDS - start)) s to end"

# --- the example, small: 2 ranks, rank 0 says what it did --------------------------------
(cd "$work" && THZMAP_EXAMPLE_SMALL=1 mpi 2 $PY -m mpi4py "$REPO/examples/python/simulate_mpi.py" \
    --out "$work/example" > "$work/example.out" 2>&1) ||
    { fail "examples/python/simulate_mpi.py on 2 ranks exited $?"; cat "$work/example.out"; }
grep -q "^2 MPI rank(s), 1 thread(s) each: 6 channels, .* MB communicated" "$work/example.out" ||
    fail "the example's line: $(cat "$work/example.out")"
[ -f "$work/example/cam.brightness_temperature.img" ] || fail "the example wrote no images"

# an argument rank 0 alone refuses (ranks 1.. give no photon map) ends the job
mpi 2 $PY -m mpi4py "$work/run.py" seed "$work/seed" > "$work/seed.out" 2>&1
rc=$?
[ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] || fail "a seed with rank 0's map: exit $rc (124: a hang)"
grep -q "thzmap (MPI rank 0): the run failed" "$work/seed.out" &&
    grep -q "seed: a render from a photon map uses the map's seed" "$work/seed.out" ||
    fail "a seed with rank 0's map: $(cat "$work/seed.out")"
# an argument every rank refuses raises on every rank, which may go on
mpi 2 $PY -m mpi4py "$work/run.py" progress "$work/progress" > "$work/progress.out" 2>&1 ||
    fail "progress=42 on 2 ranks: exit $?"
[ "$(grep -o "rank [01]: refused" "$work/progress.out" | sort -u | wc -l)" = 2 ] ||
    fail "progress=42: $(cat "$work/progress.out")"

# Ctrl-C reaches rank 0 while it waits for rank 1, stopped in the photon phase: the job
# ends (the program's handler does the same through thz_mpi_interrupt). Not before the
# phase: forming the ranks' team (MPI_Comm_dup) cannot be interrupted.
mpi 2 $PY -m mpi4py "$work/run.py" long "$work/long" > "$work/long.out" 2>&1 &
job=$!
for _ in $(seq 200); do [ -e "$work/long.started" ] && break; sleep 0.05; done
kill -STOP "$(said "$work/long.pid-1")" 2>/dev/null || fail "Ctrl-C: rank 1 did not start"
sleep 2 # rank 0 fires its share (2 M photons, about 1 s) and waits for rank 1's
start=$SECONDS
kill -INT "$(said "$work/long.pid-0")" 2>/dev/null
wait "$job"
rc=$?
kill -CONT "$(said "$work/long.pid-1")" 2>/dev/null
[ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] || fail "Ctrl-C while rank 0 waits: exit $rc (124: a hang)"
[ $((SECONDS - start)) -lt 20 ] || fail "Ctrl-C while rank 0 waits: the job took $((SECONDS - start)) s to end"
grep -q "thzmap (MPI rank 0): the run failed" "$work/long.out" && grep -q KeyboardInterrupt "$work/long.out" ||
    fail "Ctrl-C while rank 0 waits: $(cat "$work/long.out")"
[ -e "$work/long" ] && fail "Ctrl-C while rank 0 waits: rank 0 wrote OUTDIR"

# Ctrl-C once rank 0's run has returned from C, before its call ends: the library's
# interrupt stays in force for the rest of the process, so the job ends (130), not the
# next shared call
mpi 2 $PY -m mpi4py "$work/run.py" late "$work/late" > "$work/late.out" 2>&1 &
job=$!
for _ in $(seq 400); do [ -e "$work/late.returned" ] && break; sleep 0.05; done
sleep 0.5
kill -INT "$(said "$work/late.pid-0")" 2>/dev/null || fail "late Ctrl-C: no rank 0"
wait "$job"
rc=$?
[ "$rc" = 130 ] || fail "Ctrl-C after the run returned: exit $rc, not 130: $(cat "$work/late.out")"
[ -e "$work/late" ] && fail "Ctrl-C after the run returned: rank 0 wrote OUTDIR"

# a script with its own SIGINT handler keeps Ctrl-C: the run goes on to its end
mpi 2 $PY -m mpi4py "$work/run.py" own "$work/own" > "$work/own.out" 2>&1 &
job=$!
for _ in $(seq 400); do [ -e "$work/own.started" ] && break; sleep 0.05; done
kill -INT "$(said "$work/own.pid-0")" 2>/dev/null || fail "own handler: no rank 0"
wait "$job" || fail "Ctrl-C with the script's own handler: exit $?: $(cat "$work/own.out")"
[ -e "$work/own.caught" ] && [ -f "$work/own/summary.json" ] ||
    fail "Ctrl-C with the script's own handler: not caught, or no results: $(cat "$work/own.out")"

# --- mpi takes True or False -----------------------------------------------------------
$PY - "$work/scene.json" <<'PY' || fail "mpi='yes' was not refused"
import sys, thzmap
try:
    thzmap.simulate(thzmap.load_scene(sys.argv[1]), mpi="yes")
except thzmap.ArgumentError as e:
    assert "mpi: expected True or False" in str(e), e
else:
    sys.exit(1)
PY

[ "$fails" -eq 0 ] && echo "test_python_mpi: all passed"
exit $((fails > 0))
