#!/usr/bin/env bash
# The memory estimate a run prints and refuses by: it counts the renderer's tables per
# object (74 KB each: 20 000 boxes peaked at 1.4 GiB against an estimate of 0.2 MiB) and
# what the process holds already, so it is not below the measured peak; and it refuses
# against the memory the process may have, an address-space limit (ulimit -v) included
# (a run estimated at 14.9 GiB under `ulimit -v 6G` was accepted and failed after 26 s).
# usage: test_memory_estimate.sh THZMAP_BINARY REPO_DIR
. "$(dirname "$0")/lib.sh"
# the sanitizer build's shadow memory is in its resident set and its address space
if grep -q '^THZ_SANITIZE:BOOL=ON' "$(dirname "$THZMAP")/CMakeCache.txt" 2>/dev/null; then
    echo "skipped: a sanitizer build (its shadow memory is neither estimated nor limitable)"
    exit 0
fi
/usr/bin/python3 - "$THZMAP" "$REPO" "$work" <<'PY'
import json, os, re, resource, subprocess, sys
T, repo, work = sys.argv[1:4]
base = os.path.join(repo, "examples", "plate-in-box")
s = json.load(open(os.path.join(base, "scene.json")))
for m in s["materials"].values():
    for k, v in list(m.items()):
        if k == "file" or k.endswith("_file"):
            m[k] = os.path.join(base, v)
objs = [o for o in s["objects"] if o["name"] == "room"]
for i in range(3000):  # small boxes in a grid
    objs.append({"name": "b%d" % i, "type": "solid", "material": "paint", "temperature_k": 300,
                 "shape": {"type": "box", "size_m": [0.01, 0.01, 0.01]},
                 "transform": {"translate_m": [(i % 50) * 0.02 - 0.5, (i // 50) * 0.02 - 0.5, 0.5]}})
s["objects"] = objs
s["sensors"][0]["resolution"] = [16, 12]
s["render"] = {"integrator": "path", "paths_per_sample": 1}
scene = os.path.join(work, "boxes.json")
json.dump(s, open(scene, "w"))
p = subprocess.run([T, "simulate", scene, "-o", os.path.join(work, "out"), "--threads", "2"],
                   capture_output=True, text=True)
assert p.returncode == 0, p.stderr
m = re.search(r"memory ([0-9.]+) (KiB|MiB|GiB) of", p.stderr)
assert m, p.stderr
estimate = float(m.group(1)) * {"KiB": 2**10, "MiB": 2**20, "GiB": 2**30}[m.group(2)]
peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024
print("3000 boxes: estimate %.0f MiB, measured peak %.0f MiB" % (estimate / 2**20, peak / 2**20))
assert estimate >= 0.85 * peak, (estimate, peak)
assert estimate <= 2.0 * peak, (estimate, peak)

# under an address-space limit of 3 GiB: 2e8 photons (about 10 GiB of maps) refused at once
def limited():
    resource.setrlimit(resource.RLIMIT_AS, (3 << 30, resource.RLIM_INFINITY))
p = subprocess.run([T, "simulate", os.path.join(base, "scene.json"), "-o", os.path.join(work, "big"),
                    "--photons", "200000000", "--integrator", "photon-map", "--threads", "2"],
                   capture_output=True, text=True, preexec_fn=limited, timeout=60)
assert p.returncode == 2, (p.returncode, p.stderr)
assert "but ulimit -v limits this process to 3145728 KiB" in p.stderr, p.stderr
assert not os.path.exists(os.path.join(work, "big"))

# the estimate's line says what the process may have in binary units: 4 GiB under
# ulimit -v 4194304 (KiB), 879 MiB under 900000 (900000 / 1024 = 878.9)
for kib, said in ((4194304, "of 4 GiB"), (900000, "of 879 MiB")):
    def limit_to(kib=kib):
        resource.setrlimit(resource.RLIMIT_AS, (kib << 10, resource.RLIM_INFINITY))
    p = subprocess.run([T, "simulate", os.path.join(base, "scene.json"), "-o",
                        os.path.join(work, "est"), "--threads", "2"],
                       capture_output=True, text=True, preexec_fn=limit_to, timeout=120)
    line = [l for l in p.stderr.splitlines() if "estimate:" in l]
    assert p.returncode == 0 and line and line[0].endswith(said), (kib, p.returncode, p.stderr)
print("ok")
PY
