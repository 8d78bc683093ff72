#!/usr/bin/env bash
# `thzmap render --photon-map` reads the file one channel at a time (thz_render_file):
# on the paper's scene with 4 channels of 10^6 photons (16 x 16 pixels, photon-map),
# its peak memory above that of a render that reads no map (path, without one) is at
# most 1.5 x the largest channel's map, where holding every channel's map at once, as
# it did before, takes 4 maps (measured: 1.0 x, and 3.8 x before); and its images are
# those of the simulate that saved the map. And `thzmap simulate` without keeping the maps,
# at 3 x 10^6 photons per channel, holds at most 1.5 x its largest map above the bare
# render: one channel's map at a time and the index build's scratch of 3/8 of it
# (measured: 1.41 x; 2.04 x with the build's former second array as large as the map).
# A run too large for the memory it may have (here ulimit -v) is refused with the photon
# count that would fit, and that count is indeed accepted (10 % more refused).
# The peak is the child's maxrss (getrusage), and the sanitizers reserve more address
# space than ulimit -v allows, so this runs without sanitizers.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"

cp -r "$REPO/examples/teraeye" "$work/scene"
python3 - "$work/scene/scene.json" <<'PY' || exit 1
import json, sys
path = sys.argv[1]
with open(path) as f:
    d = json.load(f)
d["channels"] = {"from_thz": 0.3, "to_thz": 1.2, "count": 4, "relative_width": 0.01}
d["photons"]["per_channel"] = 1000000
d["sensors"][0]["resolution"] = [16, 16]
d["render"] = {"integrator": "photon-map"}
with open(path, "w") as f:
    json.dump(d, f)
PY
S=$work/scene/scene.json
M=$work/sim/photon-map.thzpm
if ! "$THZMAP" simulate "$S" -o "$work/sim" --save-photon-map --quiet --threads 2; then
    echo "FAIL: simulate"
    exit 1
fi

# Peaks come from separate Python processes, so each RUSAGE_CHILDREN is one child's.
peak() { # thzmap arguments; prints the peak resident memory in bytes
    python3 - "$THZMAP" "$@" <<'PY'
import resource, subprocess, sys
p = subprocess.run([sys.argv[1], *sys.argv[2:], "--quiet", "--threads", "2"],
                   capture_output=True, text=True)
if p.returncode != 0:
    sys.exit(f"thzmap {' '.join(sys.argv[2:])}: exit {p.returncode}\n{p.stdout}{p.stderr}")
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024)
PY
}
bare=$(peak render "$S" -o "$work/bare" --integrator path) || exit 1
full=$(peak render "$S" -o "$work/full" --photon-map "$M") || exit 1
sim=$(peak simulate "$S" -o "$work/sim2" --photons 3e6) || exit 1

# --- a run too large is refused with the photons per channel that would fit ------------
AS_KIB=2500000 # ulimit -v: about 2.4 GiB for this process's address space
fits() { # PHOTONS: prints the count the refusal names, or nothing if the run was accepted
    (ulimit -v $AS_KIB; exec "$THZMAP" simulate "$S" -o "$work/big" --photons "$1" \
        --threads 2) > /dev/null 2> "$work/big.err" &
    local pid=$!
    # accepted runs print their estimate once the memory check passed: stop them there
    for _ in $(seq 600); do
        kill -0 $pid 2>/dev/null || break
        grep -q 'estimate:' "$work/big.err" && { kill -INT $pid; break; }
        sleep 0.1
    done
    wait $pid
    echo "exit $?" >> "$work/big.err"
    sed -n 's/.*; at most about \([0-9]*\) fit[;)].*/\1/p' "$work/big.err"
}
n=$(fits 1e9)
grep -q 'would need' "$work/big.err" || { echo "FAIL: 1e9 photons not refused: $(cat "$work/big.err")"; exit 1; }
grep -q 'exit 2$' "$work/big.err" || { echo "FAIL: the refusal's exit status: $(cat "$work/big.err")"; exit 1; }
# the library names the scene key; simulate, which has the option, adds it
grep -q '; lower photons.per_channel (now 1000000000; at most about [0-9]* fit) (or --photons)$' \
    "$work/big.err" || { echo "FAIL: the refusal's remedy: $(cat "$work/big.err")"; exit 1; }
if [[ ! $n =~ ^[1-9][0-9]*$ ]] || (( n >= 1000000000 )); then
    echo "FAIL: the refusal names no count that fits: $(cat "$work/big.err")"
    exit 1
fi
m=$(fits $((n + n / 10)))
grep -q 'would need' "$work/big.err" || { echo "FAIL: $((n + n / 10)) photons (10 % over $n) not refused"; exit 1; }
# the same count within rounding (the process's own memory moves a little between runs)
(( m >= n - n / 10 && m <= n + n / 10 )) ||
    { echo "FAIL: the refusal of $((n + n / 10)) names $m, that of 1e9 $n"; exit 1; }
fits "$n" > /dev/null
if grep -q 'would need' "$work/big.err" || ! grep -q 'estimate:' "$work/big.err"; then
    echo "FAIL: $n photons, the count the refusal named, not accepted: $(cat "$work/big.err")"
    exit 1
fi
[ -z "$(ls -A "$work/big" 2>/dev/null)" ] || { echo "FAIL: the refused or interrupted runs left files"; exit 1; }
echo "refused 1e9 photons a channel under ulimit -v $AS_KIB KiB; $n fit and start"

python3 - "$work" "$bare" "$full" "$sim" <<'PY'
import json, sys
work, bare, full, sim = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
bad = []
with open(f"{work}/sim/summary.json") as f:
    stored = [c["photons_stored"] for c in json.load(f)["channels"]]
largest, total = 28 * max(stored), 28 * sum(stored)  # bytes of a record
extra = full - bare
print(f"render peak {full / 1e6:.1f} MB, {extra / 1e6:.1f} MB above the bare render's "
      f"{bare / 1e6:.1f} MB; largest map {largest / 1e6:.1f} MB, all {total / 1e6:.1f} MB")
if extra > 1.5 * largest:
    bad.append(f"render holds {extra / largest:.2f} x the largest map (at most 1.5)")
with open(f"{work}/sim2/summary.json") as f:
    largest3 = 28 * max(c["photons_stored"] for c in json.load(f)["channels"])
held = (sim - bare) / largest3
print(f"simulate (3e6 photons) peak {sim / 1e6:.1f} MB, {held:.2f} x its largest map "
      f"({largest3 / 1e6:.1f} MB) above the bare render")
if held > 1.5:
    bad.append(f"simulate holds {held:.2f} x the largest map (at most 1.5)")
for name in ["radiance", "brightness_temperature", "radiance_stderr"]:
    with open(f"{work}/sim/cam.{name}.img", "rb") as a, open(f"{work}/full/cam.{name}.img",
                                                             "rb") as b:
        if a.read() != b.read():
            bad.append(f"cam.{name}.img differs from simulate's")
for b in bad:
    print("FAIL:", b)
sys.exit(1 if bad else 0)
PY
