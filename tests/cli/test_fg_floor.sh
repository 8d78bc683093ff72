#!/usr/bin/env bash
# final-gather stops at its photon map's floor (docs/integrators.md "Noise targets and
# passes"): on a small copy of the paper's scene (24 x 24, 0.2 THz, 20 000 photons, 8
# gather rays a pass),
#  - a noise target below the map's own noise (0.001 K) stops after 2 passes, exit 0,
#    with one warning that gives the floor F in K and the photons; F is above the target
#    and at most the run's reported 95th percentile (the floor is a part of it);
#  - a target of 1.2 F, which more gather rays do reach, runs past 2 passes to it, without
#    that warning;
#  - render from the saved map stops the same way and names the map's photons;
#  - path, which has no map, never stops there (it runs to --max-seconds, which overrides
#    the scene's render.max_seconds).
# The floor's estimate itself (the spread between the map's photon batches) is checked
# against the spread over photon seeds in tests/physics/test_integrators.c.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"

cp -r "$REPO/examples/teraeye" "$work/scene"
S=$work/scene/scene.json
python3 - "$S" <<'PY' || fail "could not write the small scene"
import json, sys
path = sys.argv[1]
with open(path) as f:
    d = json.load(f)
d["channels"] = {"from_thz": 0.2, "to_thz": 0.2, "count": 1, "relative_width": 0.01}
d["photons"]["per_channel"] = 20000
d["sensors"][0]["resolution"] = [24, 24]
d["render"] = {"integrator": "final-gather", "gather_rays": 8}
with open(path, "w") as f:
    json.dump(d, f)
PY
run() { # $1: what, rest: thzmap arguments
    local what=$1
    shift
    if ! "$THZMAP" "$@" --quiet --threads 2 > "$work/$what.log" 2>&1; then
        fail "$what: exit $?"
        cat "$work/$what.log"
    fi
}
run low simulate "$S" -o "$work/low" --target-noise-k 0.001 --save-photon-map \
    --max-seconds 20 # without the stop: passes until then, not 2
floor=$(python3 - "$work/low/summary.json" <<'PY'
import json, re, sys
s = json.load(open(sys.argv[1]))
hits = [m for w in s["warnings"] for m in
        [re.search(r"final-gather's photon map alone leaves ([0-9.e+-]+) K at the 95th "
                   r"percentile, at or above the noise target of 0.001 K.*stopped after 2 "
                   r"passes.*now 20000 per channel", w)] if m]
c = s["channels"][0]
if len(hits) != 1:
    sys.exit(f"expected one floor warning, got {s['warnings']}")
f = float(hits[0].group(1))
if c["render_passes"] != 2:
    sys.exit(f"{c['render_passes']} passes, expected 2")
if not (0.001 < f <= c["p95_stderr_k"] * 1.001):  # the warning rounds to 3 digits
    sys.exit(f"floor {f} K outside (0.001, p95 {c['p95_stderr_k']}] K")
print(f)
PY
) || fail "simulate with a target below the floor: $floor"

if [ -n "$floor" ] && [[ $floor =~ ^[0-9.e+-]+$ ]]; then
    target=$(python3 -c "print(1.2 * $floor)")
    run high simulate "$S" -o "$work/high" --target-noise-k "$target"
    python3 - "$work/high/summary.json" "$target" <<'PY' || fail "simulate with a target of 1.2 x the floor"
import json, sys
s, t = json.load(open(sys.argv[1])), float(sys.argv[2])
c = s["channels"][0]
if any("photon map alone" in w for w in s["warnings"]):
    sys.exit(f"a floor warning at a reachable target: {s['warnings']}")
if not (c["render_passes"] > 2 and c["p95_stderr_k"] <= t):
    sys.exit(f"{c['render_passes']} passes, p95 {c['p95_stderr_k']} K, target {t} K")
PY
fi

run again render "$S" -o "$work/again" --photon-map "$work/low/photon-map.thzpm" \
    --target-noise-k 0.001 --max-seconds 20
python3 - "$work/again/summary.json" <<'PY' || fail "render from the saved map"
import json, sys
s = json.load(open(sys.argv[1]))
if not any("photon map alone" in w and "the map read has 20000 per channel" in w
           for w in s["warnings"]) or s["channels"][0]["render_passes"] != 2:
    sys.exit(f"passes {s['channels'][0]['render_passes']}, warnings {s['warnings']}")
PY

# (the scene's own render.max_seconds, 5 s, yields to the command line's 0.3 s)
python3 - "$S" "$work/scene/limited.json" <<'PY' || fail "could not write the limited scene"
import json, sys
d = json.load(open(sys.argv[1]))
d["render"]["max_seconds"] = 5
json.dump(d, open(sys.argv[2], "w"))
PY
run path simulate "$work/scene/limited.json" -o "$work/path" --integrator path \
    --target-noise-k 0.001 --max-seconds 0.3
python3 - "$work/path/summary.json" <<'PY' || fail "path at a low target"
import json, sys
s = json.load(open(sys.argv[1]))
if any("photon map alone" in w for w in s["warnings"]):
    sys.exit(f"path stopped at a map floor: {s['warnings']}")
if not any("stopped by the time limit of 0.3 s" in w for w in s["warnings"]):
    sys.exit(f"not stopped by --max-seconds 0.3: {s['warnings']}")
PY

finish "all final-gather floor checks passed"
