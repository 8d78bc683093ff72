#!/bin/bash
# Strong scaling of `mpirun -np N thzmap simulate` (docs/mpi.md, issue 19): the same run
# (default: examples/plate-in-box, photon-map, 4 M photons = 62 batches, 1 thread per
# rank) with 1 (plain thzmap, no mpirun), 2 and 4 ranks. Prints per run the wall time of
# the command, of the photon phase (summary.json timings_s.photons: firing on every rank,
# gathering and the map's index on rank 0) and of the rest, the speed-up and the
# strong-scaling efficiency T1 / (N TN), each rank's CPU time (on a shared machine the
# busiest rank's CPU time is the wall time idle cores would give), and the bytes rank 0
# gathered; checks that the
# images equal the 1-rank run's; then an estimate for 64 ranks on a cluster from those
# measurements. Ranks beyond the machine's cores are oversubscribed (said in the output),
# and the machine may be shared: the load average before and after is printed.
# A measurement, not a test: nothing fails on the time.
# usage: bench/mpi.sh [THZMAP_BINARY] [--photons N] [--scene SCENE.json] [--ranks "1 2 4"]
set -eu
repo=$(cd "$(dirname "$0")/.." && pwd)
thzmap=$repo/build/thzmap
if [ $# -gt 0 ] && [ "${1#--}" = "$1" ]; then thzmap=$1; shift; fi
photons=4000000
scene=$repo/examples/plate-in-box/scene.json
ranks="1 2 4"
while [ $# -gt 0 ]; do
    case $1 in
    --photons) photons=$2; shift 2 ;;
    --scene) scene=$2; shift 2 ;;
    --ranks) ranks=$2; shift 2 ;;
    *) echo "bench/mpi.sh: unknown option $1" >&2; exit 2 ;;
    esac
done
command -v mpirun >/dev/null || { echo "bench/mpi.sh: mpirun is missing (scripts/install-deps.sh)" >&2; exit 1; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cores=$(nproc)
echo "bench/mpi.sh: $scene, $photons photons per channel, photon-map, 1 thread per rank," \
    "$cores cores"
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
for n in $ranks; do
    launch=()
    [ "$n" -gt 1 ] && launch=(mpirun --oversubscribe -np "$n")
    # each rank's CPU seconds (user + system) in cpu.N.RANK
    /usr/bin/time -f '%e' -o "$out/time.$n" "${launch[@]}" sh -c \
        '/usr/bin/time -f "%U %S" -o "$0.${OMPI_COMM_WORLD_RANK:-0}" "$@"' "$out/cpu.$n" \
        "$thzmap" simulate "$scene" \
        -o "$out/r$n" --photons "$photons" --threads 1 --integrator photon-map >"$out/log.$n" 2>&1 ||
        { cat "$out/log.$n"; exit 1; }
done
echo "load average after:  $(cut -d' ' -f1-3 /proc/loadavg)"
/usr/bin/python3 - "$out" "$cores" "$ranks" <<'PY'
import filecmp, json, os, re, sys
out, cores, ranks = sys.argv[1], int(sys.argv[2]), [int(r) for r in sys.argv[3].split()]
rows = {}
for n in ranks:
    d = json.load(open(f"{out}/r{n}/summary.json"))
    wall = float(open(f"{out}/time.{n}").read().split()[-1])
    log = open(f"{out}/log.{n}").read()
    m = re.search(r"\(([0-9.e+]+) MB gathered\)", log)
    stored = sum(c["photons_stored"] for c in d["channels"])
    fired = sum(c["photons_fired"] for c in d["channels"])
    cpu = [sum(float(x) for x in open(f"{out}/cpu.{n}.{r}").read().split()[-2:])
           for r in range(n)]
    rows[n] = dict(wall=wall, cpu_max=max(cpu), cpu_sum=sum(cpu), photons=d["timings_s"]["photons"], render=d["timings_s"]["render"],
                   mb=float(m.group(1)) if m else 0.0, stored=stored, fired=fired)
    if n != ranks[0]:
        a, b = f"{out}/r{ranks[0]}", f"{out}/r{n}"
        same = all(filecmp.cmp(f"{a}/{f}", f"{b}/{f}", shallow=False)
                   for f in os.listdir(a) if f != "summary.json")
        rows[n]["same"] = same
r1 = rows[ranks[0]]
print(f"{'ranks':>5} {'wall s':>7} {'photons s':>9} {'rest s':>7} {'speed-up':>8} "
      f"{'efficiency':>10} {'phase eff.':>10} {'CPU s':>6} {'max rank':>8} {'CPU eff.':>8} "
      f"{'MB gathered':>11}  note")
for n in ranks:
    r = rows[n]
    note = "oversubscribed" if n > cores else ""
    if "same" in r:
        note += ("; " if note else "") + ("files = 1-rank run's" if r["same"] else "FILES DIFFER")
    print(f"{n:>5} {r['wall']:>7.2f} {r['photons']:>9.2f} {r['wall'] - r['photons']:>7.2f} "
          f"{r1['wall'] / r['wall']:>8.2f} {r1['wall'] / (n * r['wall']):>10.2f} "
          f"{r1['photons'] / (n * r['photons']):>10.2f} {r['cpu_sum']:>6.2f} {r['cpu_max']:>8.2f} "
          f"{r1['cpu_sum'] / (n * r['cpu_max']):>8.2f} {r['mb']:>11.3g}  {note}")
print("(wall times: a shared machine's; CPU s: user + system of all ranks; max rank: of the "
      "busiest rank, the wall time on idle dedicated cores; CPU eff. = CPU(1) / (N max rank))")
# 64 ranks, from CPU times (the wall times of a shared machine say little): with 2 ranks,
# rank 1 spends u + f / 2 (start: MPI, scene, ray-casting structure; half the firing) and
# rank 0 that plus the serial part s (the map's index, rendering, writing); one process
# spends u + f + s. On 64 dedicated cores: u + f / 64 + s + the gather over the network.
if 2 in rows:
    cpu1 = [sum(float(x) for x in open(f"{out}/cpu.2.{r}").read().split()[-2:]) for r in (0, 1)]
    serial = max(0.0, cpu1[0] - cpu1[1])
    f = max(0.0, 2 * (r1["cpu_sum"] - serial - cpu1[1]))
    u = max(0.0, cpu1[1] - f / 2)
    bytes64 = (r1["stored"] * 32 + r1["fired"] / 256 * 120) * 63 / 64
    print(f"64 ranks (estimate from CPU times): start u = {u:.2f} s, firing f = {f:.2f} s "
          f"(/ 64 = {f / 64:.3f} s), serial on rank 0 s = {serial:.2f} s, "
          f"gather {bytes64 / 1e6:.3g} MB into rank 0 (32 B per stored photon)")
    for name, bw in (("10 Gbit/s Ethernet", 1.25e9), ("100 Gbit/s InfiniBand", 12.5e9)):
        t = u + f / 64 + serial + bytes64 / bw
        print(f"  over {name}: gather {bytes64 / bw:.3f} s, {t:.2f} s end to end, speed-up "
              f"{r1['cpu_sum'] / t:.2f} over one rank, efficiency {r1['cpu_sum'] / (64 * t):.3f}")
PY
