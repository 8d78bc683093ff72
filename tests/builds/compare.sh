#!/usr/bin/env bash
# The same scene and seed give the same files whichever compiler built thzmap, for
# whichever processor: two builds (`make test-compilers`: gcc with -march=native, clang
# for any x86-64, -DTHZ_NATIVE=OFF) run the same small scenes with each integrator, and
# every output must be byte for byte the same, the same files on both sides, and
# summary.json the same but for its timings (keys ending in _s), its scene path and
# thzmap_revision: what the two builds compute is compared, not the source they were
# built from (in make test-compilers the same checkout's, but a file edited between the
# two builds makes one "-dirty"; two commits' builds may be compared too). The two
# revisions are printed.
# Where C leaves an order unspecified, an argument list that draws two random numbers
# (f(u(rng), u(rng))), gcc and clang choose differently: the paths, the photon maps and
# the gather rays of the two builds then differed in every image.
# Scenes: the paper's room (path, photon-map, final-gather; 2 channels, 32 x 32) and the
# outdoor example (emitting humid air, a glossy Ward lobe, straight transmission, library
# materials from complex indices; the sensor's Airy PSF and radiometer noise).
# Not a CTest test (CTest runs one build): make test-compilers runs it.
# argv: the first build's thzmap, the second build's thzmap, repository directory.
set -u
A=$1
B=$2
REPO=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

cp -r "$REPO/examples/teraeye" "$work/room"
python3 - "$work/room/scene.json" "$REPO/examples/outdoor-concealed/scene.json" \
    "$work/outdoor.json" <<'PY' || fail "could not write the small scenes"
import json, sys
room, outdoor_in, outdoor_out = sys.argv[1:4]
with open(room) as f:
    d = json.load(f)
d["channels"] = {"from_thz": 0.2, "to_thz": 1.0, "count": 2, "relative_width": 0.05}
d["photons"] = {"per_channel": 100000, "seed": 7}
d["sensors"][0]["resolution"] = [32, 32]
d["render"] = {"integrator": "path", "paths_per_sample": 8}
with open(room, "w") as f:
    json.dump(d, f)
with open(outdoor_in) as f:
    d = json.load(f)
d["photons"] = {"per_channel": 50000, "seed": 3}
d["sensors"][0]["resolution"] = [24, 32]
d["sensors"][0]["aperture_diameter_m"] = 0.3
d["sensors"][0]["noise"] = {"receiver_temperature_k": 1000, "integration_time_s": 0.01,
                            "radiometer": "dicke"}
d["render"] = {"integrator": "path", "paths_per_sample": 8}
with open(outdoor_out, "w") as f:
    json.dump(d, f)
PY

compare() { # $1: name, rest: simulate arguments
    local name=$1 fails_before=$fails
    shift
    for side in a b; do
        local bin=$A
        [ "$side" = b ] && bin=$B
        "$bin" simulate "$@" -o "$work/$name.$side" --quiet --threads 2 \
            > "$work/$name.$side.log" 2>&1
        local rc=$?
        if [ "$rc" != 0 ]; then
            fail "$name: $bin exited $rc: $(tail -n 3 "$work/$name.$side.log")"
            return
        fi
    done
    (cd "$work/$name.a" && find . -type f | sort) > "$work/$name.a.files"
    (cd "$work/$name.b" && find . -type f | sort) > "$work/$name.b.files"
    cmp -s "$work/$name.a.files" "$work/$name.b.files" ||
        fail "$name: the two builds wrote different files: $(diff "$work/$name.a.files" "$work/$name.b.files" | tr '\n' ' ')"
    python3 - "$work/$name.a/summary.json" "$work/$name.b/summary.json" <<'PY' ||
import json, sys
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items()
                if not k.endswith("_s") and k not in ("path", "thzmap_revision")}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
a, b = (strip(json.load(open(p))) for p in sys.argv[1:3])
sys.exit(0 if a == b else 1)
PY
        fail "$name: summary.json differs beyond its timings"
    local files=0 differ=0
    for f in $(cd "$work/$name.a" && find . -type f ! -name summary.json | sort); do
        files=$((files + 1))
        cmp -s "$work/$name.a/$f" "$work/$name.b/$f" || { differ=$((differ + 1)); echo "  $name: $f differs"; }
    done
    [ "$files" -ge 10 ] || fail "$name: only $files output files"
    [ "$differ" = 0 ] || fail "$name: $differ of $files files differ between the two builds"
    if [ "$fails" = "$fails_before" ]; then echo "ok: $name, $files files the same"; fi
}

echo "revisions: $("$A" --version) and $("$B" --version)"
compare room-path "$work/room/scene.json"
compare room-photon-map "$work/room/scene.json" --integrator photon-map
compare room-final-gather "$work/room/scene.json" --integrator final-gather --photons 30000
compare outdoor-path "$work/outdoor.json"
compare outdoor-photon-map "$work/outdoor.json" --integrator photon-map
compare outdoor-final-gather "$work/outdoor.json" --integrator final-gather

[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "compare.sh: all outputs the same"
