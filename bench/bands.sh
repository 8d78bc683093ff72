#!/bin/bash
# Band values for a 200-candidate grid of the paper's scene (issue 16): `thzmap bands`
# on examples/teraeye (64 x 64 pixels, oversampling 2) with candidates 0.10-2.09 THz
# every 10 GHz, the three cylinders as targets, K = 3 (exhaustive: 1.33 M sets). Prints
# the wall and CPU seconds of the whole command (renders, statistics and search), the
# renders it made (one full, the others coarse: docs/analysis.md) and the load average
# before and after, since the development machine is shared.
# A measurement, not a test: nothing fails on the time.
# usage: bench/bands.sh [THZMAP_BINARY] [--paths N] [--threads T]
set -eu
repo=$(cd "$(dirname "$0")/.." && pwd)
thzmap=${1:-$repo/build/thzmap}
shift || true
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
load_before=$(cut -d' ' -f1 /proc/loadavg)
/usr/bin/time -f '%e %U %S' -o "$out/time" "$thzmap" bands "$repo/examples/teraeye/scene.json" \
    -o "$out/bands" --count 3 --from-thz 0.1 --to-thz 2.09 --step-ghz 10 \
    --targets cylinder-A,cylinder-B,cylinder-C --netd-k 0.5 -q "$@"
load_after=$(cut -d' ' -f1 /proc/loadavg)
read -r wall user sys <"$out/time"
/usr/bin/python3 - "$out/bands/bands.json" "$wall" "$user" "$sys" "$load_before" "$load_after" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
wall, user, sys_s, lb, la = (float(x) for x in sys.argv[2:7])
print(f"candidates {len(d['candidates']['frequency_thz'])}, renders {d['renders']}, "
      f"paths per sample {d['paths_per_sample']}, search {d['search']} ({d['sets_scored']} sets)")
print(f"wall {wall:.1f} s, CPU {user + sys_s:.1f} s (user {user:.1f}, system {sys_s:.1f}); "
      f"load average {lb:.2f} before, {la:.2f} after")
print(f"chosen {d['selected_thz']} THz, worst-pair JM {d['score']:.4f} ({' vs '.join(d['worst_pair'])})")
PY
