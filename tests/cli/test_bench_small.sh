#!/usr/bin/env bash
# The benchmark harness (bench/thzbench, issue 6) in its --small form, so that the
# harness itself cannot rot: it runs, prints its table, and writes JSON that parses and
# has every section and field the README's table is made from. Asserts nothing about
# speed. The thzbench binary sits next to thzmap in the build directory.
# usage: test_bench_small.sh THZMAP_BINARY REPO_DIR
set -u
thzmap=$1
repo=$2
bench="$(dirname "$thzmap")/thzbench"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

[[ -x $bench ]] || { echo "FAIL: no $bench"; exit 1; }
TMPDIR=$tmp "$bench" --small --json "$tmp/bench.json" \
    --scene "$repo/examples/teraeye/scene.json" >"$tmp/out" 2>"$tmp/err"
status=$?
cat "$tmp/out"
[[ $status -eq 0 ]] || { echo "FAIL: thzbench --small exited $status: $(cat "$tmp/err")"; exit 1; }
grep -q '^Targets' "$tmp/out" || { echo "FAIL: no table of targets"; exit 1; }

python3 - "$tmp/bench.json" <<'PY'
import json, sys
with open(sys.argv[1]) as f:
    r = json.load(f)
def need(obj, keys, where):
    for k in keys:
        if k not in obj:
            sys.exit(f"FAIL: {where} has no '{k}'")
need(r, ["small", "threads", "load_average_start", "paper_case", "tracing_limit",
         "scaling_photons", "scaling_triangles", "scaling_threads", "rendering", "targets"], "root")
assert r["small"] is True
p = r["paper_case"]
need(p, ["photons_per_channel", "channels", "resolution", "oversampling", "seconds",
         "photons_fired", "photons_stored", "rays", "photons_per_s", "bytes_per_stored_photon",
         "peak_memory_bytes", "peak_memory_over_map", "run_simulate"], "paper_case")
need(p["seconds"], ["load", "accel", "emission_table", "tracing", "index", "photon_phase",
                    "render", "output", "total"], "paper_case.seconds")
assert p["channels"] == 6 and p["resolution"] == [64, 64] and p["oversampling"] == 2
assert p["photons_fired"] == 6 * p["photons_per_channel"] > 0
assert p["photons_stored"] > 0 and p["rays"] >= p["photons_stored"]
assert p["peak_memory_bytes"] > 0 and p["bytes_per_stored_photon"] >= 32
need(r["tracing_limit"], ["rays", "seconds", "rays_per_s", "photon_phase_over_raw",
                          "tracing_over_raw"], "tracing_limit")
assert r["tracing_limit"]["rays"] == p["rays"]
for k, keys in [("scaling_photons", ["photons", "stored", "seconds", "ns_per_photon"]),
                ("scaling_triangles", ["triangles", "photons", "seconds", "ns_per_photon",
                                       "raw_ns_per_ray"]),
                ("rendering", ["photons_stored", "photons_per_pixel", "gathers", "seconds",
                               "gathers_per_s", "us_per_pixel"])]:
    if len(r[k]) < 2:
        sys.exit(f"FAIL: {k} has {len(r[k])} points")
    for i, pt in enumerate(r[k]):
        need(pt, keys, f"{k}[{i}]")
tri = [pt["triangles"] for pt in r["scaling_triangles"]]
assert tri == sorted(tri) and tri[0] < tri[-1], tri
need(r["scaling_threads"], ["seconds_1", "seconds_all", "speedup", "raw_speedup"], "scaling_threads")
assert len(r["targets"]) == 8
for t in r["targets"]:
    need(t, ["target", "value", "limit", "met"], "targets[]")
print("bench JSON ok")
PY
