#!/bin/bash
# Strong scaling of `mpirun -np N thzmap simulate|render|batch` (docs/mpi.md, issue 19):
# the same work with 1 (plain thzmap, no mpirun), 2 and 4 ranks of 1 thread:
#   simulate: examples/plate-in-box (64 x 64, oversampling 2), photon-map, 16 M photons
#             (245 batches): photons shared by batch, pixels by tile;
#   render:   final-gather, 512 gather rays (a pass; plate-in-box's default 32 reach its
#             noise target in one pass) from a photon map of 1 M photons that simulate
#             saved first (not timed): pixels shared by tile, the map sent by rank 0 to
#             the others;
#   batch:    8 frames of plate-in-box whose target warms by 1 K a frame, photon-map,
#             1 M photons per frame: 8 photon groups, dealt whole to the ranks
#             (each frame computed by one rank, sent to rank 0, which writes it).
# The workloads take several seconds on one rank (2026-12-04; they were a quarter of
# these before, when the program was slower): mpirun's own start, about 0.35 s here,
# would otherwise be much of a run.
# Prints per run the wall time of the command, the speed-up and the strong-scaling
# efficiency T1 / (N TN), each rank's CPU time (on a shared machine the busiest rank's
# CPU time is the wall time idle cores would give, and CPU eff. = CPU(1) / (N max rank)
# the efficiency they would give), and the megabytes communicated (each broadcast counted
# once per receiving rank, each gather once); checks
# that every file equals the 1-rank run's (summary.json and batch.json aside); then an
# estimate for 64 ranks on a cluster from those measurements. Ranks beyond the
# machine's cores are oversubscribed (said in the output), and the machine may be
# shared: the load average before and after is printed.
# A measurement, not a test: nothing fails on the time.
# usage: bench/mpi.sh [THZMAP_BINARY] [--photons N] [--frame-photons N] [--ranks "1 2 4"]
#                     [--what "simulate render batch"]
set -eu
repo=$(cd "$(dirname "$0")/.." && pwd)
thzmap=$repo/build/thzmap
if [ $# -gt 0 ] && [ "${1#--}" = "$1" ]; then thzmap=$1; shift; fi
photons=16000000
frame_photons=1000000
ranks="1 2 4"
what="simulate render batch"
while [ $# -gt 0 ]; do
    case $1 in
    --photons) photons=$2; shift 2 ;;
    --frame-photons) frame_photons=$2; shift 2 ;;
    --ranks) ranks=$2; shift 2 ;;
    --what) what=$2; shift 2 ;;
    *) echo "bench/mpi.sh: unknown option $1" >&2; exit 2 ;;
    esac
done
command -v mpirun >/dev/null || { echo "bench/mpi.sh: mpirun is missing (scripts/install-deps.sh)" >&2; exit 1; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cores=$(nproc)
scene=$repo/examples/plate-in-box/scene.json
# the batch: plate-in-box with absolute paths, the target warming from 305 to 312 K in
# 8 frames (every frame fires its own photons: 8 groups to deal)
/usr/bin/python3 - "$scene" "$out/scene.json" "$out/seq.json" "$frame_photons" "$out/render.json" <<'PY'
import json, os, sys
s = json.load(open(sys.argv[1]))
s["materials"]["table"]["file"] = os.path.join(os.path.dirname(sys.argv[1]), "materials/sample.csv")
json.dump(dict(s, render={"gather_rays": 512}), open(sys.argv[5], "w"))
s["render"] = {"integrator": "photon-map"}
s["photons"]["per_channel"] = int(sys.argv[4])
json.dump(s, open(sys.argv[2], "w"))
q = {"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 7, "frames": 8,
     "keyframes": [{"time_s": 0, "objects": {"target": {"temperature_k": 305}}},
                   {"time_s": 1, "objects": {"target": {"temperature_k": 312}}}]}
json.dump(q, open(sys.argv[3], "w"))
PY
echo "bench/mpi.sh: $cores cores, 1 thread per rank; ranks: $ranks"
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
if [[ " $what " == *" render "* ]]; then
    "$thzmap" simulate "$scene" -o "$out/map" --photons 1000000 --integrator final-gather \
        --save-photon-map --quiet
fi
for w in $what; do
    case $w in
    simulate) cmd=(simulate "$scene" --photons "$photons" --integrator photon-map) ;;
    render) cmd=(render "$out/render.json" --photon-map "$out/map/photon-map.thzpm"
                 --integrator final-gather) ;;
    batch) cmd=(batch "$out/seq.json") ;;
    *) echo "bench/mpi.sh: unknown --what $w" >&2; exit 2 ;;
    esac
    for n in $ranks; do
        launch=()
        [ "$n" -gt 1 ] && launch=(mpirun --oversubscribe -np "$n")
        # each rank's CPU seconds (user + system) in cpu.W.N.RANK
        /usr/bin/time -f '%e' -o "$out/time.$w.$n" "${launch[@]}" sh -c \
            '/usr/bin/time -f "%U %S" -o "$0.${OMPI_COMM_WORLD_RANK:-0}" "$@"' "$out/cpu.$w.$n" \
            "$thzmap" "${cmd[@]}" -o "$out/$w.$n" --threads 1 >"$out/log.$w.$n" 2>&1 ||
            { cat "$out/log.$w.$n"; exit 1; }
    done
done
echo "load average after:  $(cut -d' ' -f1-3 /proc/loadavg)"
/usr/bin/python3 - "$out" "$cores" "$ranks" "$what" "$photons" <<'PY'
import filecmp, json, math, os, re, sys
out, cores = sys.argv[1], int(sys.argv[2])
ranks, what = [int(r) for r in sys.argv[3].split()], sys.argv[4].split()
photons = int(float(sys.argv[5]))
def cpu_of(w, n):
    return [sum(float(x) for x in open(f"{out}/cpu.{w}.{n}.{r}").read().split()[-2:])
            for r in range(n)]
def same_tree(a, b):
    for root, _, files in os.walk(a):
        for f in files:
            if f in ("summary.json", "batch.json") or f.startswith("."):
                continue
            p = os.path.join(root, f)
            q = os.path.join(b, os.path.relpath(p, a))
            if not os.path.exists(q) or not filecmp.cmp(p, q, shallow=False):
                return False
    return True
est = {}
for w in what:
    rows = {}
    for n in ranks:
        log = open(f"{out}/log.{w}.{n}").read()
        m = re.search(r"\(([0-9.e+]+) MB communicated\)", log)
        cpu = cpu_of(w, n)
        rows[n] = dict(wall=float(open(f"{out}/time.{w}.{n}").read().split()[-1]),
                       cpu_max=max(cpu), cpu_sum=sum(cpu), mb=float(m.group(1)) if m else 0.0)
        if n != ranks[0]:
            rows[n]["same"] = same_tree(f"{out}/{w}.{ranks[0]}", f"{out}/{w}.{n}")
    r1 = rows[ranks[0]]
    print(f"\n{w}:")
    print(f"{'ranks':>5} {'wall s':>7} {'speed-up':>8} {'efficiency':>10} {'CPU s':>6} "
          f"{'max rank':>8} {'CPU eff.':>8} {'MB comm.':>9}  note")
    for n in ranks:
        r = rows[n]
        note = "oversubscribed" if n > cores else ""
        if "same" in r:
            note += ("; " if note else "") + ("files = 1-rank run's" if r["same"] else "FILES DIFFER")
        print(f"{n:>5} {r['wall']:>7.2f} {r1['wall'] / r['wall']:>8.2f} "
              f"{r1['wall'] / (n * r['wall']):>10.2f} {r['cpu_sum']:>6.2f} {r['cpu_max']:>8.2f} "
              f"{r1['cpu_sum'] / (n * r['cpu_max']):>8.2f} {r['mb']:>9.3g}  {note}")
    # 64 ranks, from CPU times (a shared machine's wall times say little): with 2 ranks,
    # rank 1 spends u + f / 2 (its start: MPI, scene, ray-casting structure, the map's
    # index when it receives one; half the shared work) and rank 0 that plus the part only
    # it does, s (gathering, writing, movies); one process spends u + f + s. On 64
    # dedicated cores: u + f x ceil(items / 64) / items + s + the messages over the
    # network, items the pieces the shared work comes in (simulate: photon batches of
    # 65 536, which dominate it; render: 16-pixel tiles, 256 and more; batch: its 8 photon
    # groups, so no more than 8 ranks share its work).
    if 2 in rows:
        c2 = cpu_of(w, 2)
        serial = max(0.0, c2[0] - c2[1])
        f = max(0.0, 2 * (r1["cpu_sum"] - serial - c2[1]))
        u = max(0.0, c2[1] - f / 2)
        items = {"simulate": math.ceil(photons / 65536), "render": 256, "batch": 8}[w]
        shared = f * math.ceil(items / 64) / items
        # Bytes: the count adds a broadcast once for each rank that receives it and a
        # gather (shares, tiles) once: MB(N) = (N - 1) b + g. From the 2- and 4-rank runs b
        # and g; with 2 ranks alone, all of it as b (the larger estimate). At 64 ranks:
        # (63 b + g) in all; through rank 0's link every gather and the broadcast between
        # once (a pipelined broadcast) and log2(64) = 6 times (a binomial tree). A dealt
        # batch sends rank 0 each frame computed elsewhere once, (N - 1) / N of them: with
        # 2 ranks half its F bytes of frames, at 64 ranks 63/64 of them.
        if w == "batch":
            b, g = 0.0, 2 * rows[2]["mb"] * 63 / 64
        else:
            b = rows[2]["mb"] if 4 not in rows else max(0.0, (rows[4]["mb"] - rows[2]["mb"]) / 2)
            g = max(0.0, rows[2]["mb"] - b)
        total64, root_lo, root_hi = 63 * b + g, b + g, 6 * b + g
        print(f"64 ranks (estimate from CPU times): start u = {u:.2f} s, shared work f = "
              f"{f:.2f} s (in {items} pieces: {shared:.3f} s on 64 ranks), rank 0 alone "
              f"s = {serial:.2f} s; bytes: broadcast b = {b:.3g} MB, gathered g = {g:.3g} MB, "
              f"{total64:.3g} MB in all, {root_lo:.3g} to {root_hi:.3g} MB through rank 0's "
              f"link")
        for name, bw in (("10 Gbit/s Ethernet", 1.25e9), ("100 Gbit/s InfiniBand", 12.5e9)):
            t_lo = u + shared + serial + root_lo * 1e6 / bw
            t_hi = u + shared + serial + root_hi * 1e6 / bw
            print(f"  over {name}: {t_lo:.2f} to {t_hi:.2f} s end to end, speed-up "
                  f"{r1['cpu_sum'] / t_hi:.2f} to {r1['cpu_sum'] / t_lo:.2f} over one rank, "
                  f"efficiency {r1['cpu_sum'] / (64 * t_hi):.3f} to "
                  f"{r1['cpu_sum'] / (64 * t_lo):.3f}")
PY
