#!/usr/bin/env bash
# The benchmark harness (bench/thzbench, issues 6 and 19) in its --small form, so that the
# harness itself cannot rot: it runs, prints its table, and writes JSON that parses and
# has every section and field the README's table is made from, with finite numbers, and
# a verdict for every target of issue 19. Asserts nothing about speed. The thzbench
# binary sits next to thzmap in the build directory.
# usage: test_bench_small.sh THZMAP_BINARY REPO_DIR
. "$(dirname "$0")/lib.sh"
bench="$(dirname "$THZMAP")/thzbench"

[[ -x $bench ]] || { echo "FAIL: no $bench"; exit 1; }
TMPDIR=$work "$bench" --small --json "$work/bench.json" \
    --scene "$REPO/examples/teraeye/scene.json" >"$work/out" 2>"$work/err"
status=$?
cat "$work/out"
[[ $status -eq 0 ]] || { echo "FAIL: thzbench --small exited $status: $(cat "$work/err")"; exit 1; }
grep -q '^Targets' "$work/out" || { echo "FAIL: no table of targets"; exit 1; }
# every ratio printed with its x, every time per photon said so, no negative floor in K
printed_fails=0
printed() { # printed EXTENDED-REGEX WHAT
    grep -Eq -- "$1" "$work/out" || { echo "FAIL: the table lacks $2"; printed_fails=1; }
}
printed 'photon phase / raw trace = [0-9.]+ x \(tracing alone: [0-9.]+ x\)' "the tracing ratios' x"
printed 'trace ns/photon +index ns/photon +CPU ns/photon +fastest CPU ns/photon' \
    "section 3's per-photon headers"
printed '^  path +[0-9]+( +[0-9.]+){7} +[0-9.]+ x +[0-9.]+-[0-9.]+ x +[0-9.]+ x ' \
    "section 5's speed-up, pair range and fastest with their x"
grep -q 'with a floor -' "$work/out" && { echo "FAIL: a negative floor in K"; printed_fails=1; }
[[ $printed_fails -eq 0 ]] || exit 1

python3 - "$work/bench.json" <<'PY'
import json, math, sys
with open(sys.argv[1]) as f:
    r = json.load(f)
def need(obj, keys, where):
    for k in keys:
        if k not in obj:
            sys.exit(f"FAIL: {where} has no '{k}'")
def finite(obj, keys, where, positive=False):
    need(obj, keys, where)
    for k in keys:
        vals = obj[k] if isinstance(obj[k], list) else [obj[k]]
        for v in vals:
            if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v) \
                    or (positive and v <= 0):
                sys.exit(f"FAIL: {where}.{k} is {obj[k]!r}, not a finite"
                         f"{' positive' if positive else ''} number")
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
assert p["peak_memory_bytes"] > 0 and p["bytes_per_stored_photon"] >= 28  # a record's bytes
# a stored photon's memory counts the renderers' directory over its map too
need(p, ["largest_map_bytes", "largest_map_stored", "largest_map_directory_bytes"], "paper_case")
bpp = (p["largest_map_bytes"] + p["largest_map_directory_bytes"]) / p["largest_map_stored"]
assert abs(p["bytes_per_stored_photon"] / bpp - 1) < 1e-9, (p["bytes_per_stored_photon"], bpp)
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
# Speed-ups from alternating pairs (bench/bench_pairs.h): the median of the pairs' ratios,
# each pair's seconds, and the machine's own ceiling measured alike.
need(r["scaling_threads"], ["speedup", "raw_speedup", "photon_phase", "raw_probe", "ceiling"],
     "scaling_threads")
for k in ["photon_phase", "raw_probe", "ceiling"]:
    q = r["scaling_threads"][k]
    finite(q, ["speedup", "speedup_fastest", "pair_min", "pair_max"], k, positive=True)
    assert len(q["seconds_1"]) == len(q["seconds_all"]) >= 1, q
    assert q["pair_min"] <= q["speedup"] <= q["pair_max"], q
    # the median of the pairs' ratios (3 pairs with --small), not fastest over fastest
    ratios = sorted(a / b for a, b in zip(q["seconds_1"], q["seconds_all"]))
    assert len(ratios) == 3, ratios
    assert abs(q["speedup"] - ratios[1]) <= 1e-9 * ratios[1], (q["speedup"], ratios)
    assert abs(q["speedup_fastest"] - min(q["seconds_1"]) / min(q["seconds_all"])) <= 1e-9, q
assert r["scaling_threads"]["speedup"] == r["scaling_threads"]["photon_phase"]["speedup"]
# The photon phase over the probe from the same rounds: the median of round k's all-thread
# phase over round k's all-thread probe, not a ratio of the two medians.
th = r["scaling_threads"]
ratios = sorted(a / b for a, b in zip(th["photon_phase"]["seconds_all"],
                                      th["raw_probe"]["seconds_all"]))
q = th["photon_phase_over_raw"]
assert abs(q["median"] - ratios[1]) <= 1e-9 * ratios[1], (q, ratios)
assert abs(q["round_min"] - ratios[0]) <= 1e-9 * ratios[0], q
assert abs(q["round_max"] - ratios[2]) <= 1e-9 * ratios[2], q
# A scaling point's photon phase: the median of its runs (one with --small), never below
# its fastest run.
for k in ["scaling_photons", "scaling_triangles"]:
    for pt in r[k]:
        assert pt["runs"] >= 1, pt
        assert 0 < pt["cpu_ns_per_photon_fastest"] <= pt["cpu_ns_per_photon"], pt
        assert 0 < pt["seconds_fastest"] <= pt["seconds"], pt

# End to end: the paper's method (photon-map, the stage-by-stage photon count) and the
# scene's default integrator (path, no photons), each on its own.
e = p["run_simulate"]
finite(e, ["seconds", "cpu_seconds", "peak_memory_bytes"], "run_simulate", positive=True)
assert e["integrator"] == "photon-map", e["integrator"]
assert e["photons_fired"] == p["photons_fired"], (e["photons_fired"], p["photons_fired"])
d = p["run_simulate_default"]
finite(d, ["seconds", "worst_p95_stderr_k", "peak_memory_bytes"], "run_simulate_default",
       positive=True)
assert d["integrator"] == "path" and d["photons_fired"] == 0, d

# The integrators' speed-ups: all three, measured on both sides.
s = r["integrator_speedups"]
assert [x["integrator"] for x in s["integrators"]] == ["photon-map", "final-gather", "path"]
for x in s["integrators"]:
    finite(x, ["seconds_1", "seconds_all", "speedup", "cpu_seconds_1", "cpu_seconds_all",
               "samples"], "integrator_speedups", positive=True)
    assert (x["map_photons"] > 0) == (x["integrator"] != "path"), x
    assert x["runs"]["pair_min"] <= x["speedup"] <= x["runs"]["pair_max"], x

# Time to a converged image: per channel, two runs of growing work, finite noise figures
# over the objects' pixels (the enclosure left out), finite extrapolated seconds, and the
# worst channel's run at the target.
for name in ["path", "final-gather"]:
    c = r["converged_image"][name]
    assert c["enclosure"] == "box", c["enclosure"]
    # --small renders this section on 16 x 16 pixels
    assert 0 < c["object_pixels"] < c["pixels"] == 16 * 16, (c["object_pixels"], c["pixels"])
    assert len(c["runs"]) == 2 and c["runs"][0]["estimates_per_pass"] < c["runs"][1]["estimates_per_pass"]
    for run in c["runs"]:
        finite(run, ["rms_stderr_k", "seconds_render"], name, positive=True)
        finite(run, ["seconds_photons"], name, positive=(name == "final-gather"))
        assert len(run["rms_stderr_k"]) == 6
    assert len(c["channels"]) == 6
    for ch in c["channels"]:
        finite(ch, ["seconds_to_target", "ratio_to_limit"], name, positive=True)
        finite(ch, ["exponent"], name)
    finite(c, ["worst_seconds_to_target"], name, positive=True)
    # every channel run alone at the estimates its extrapolation asks for (--small caps
    # them at 8): its noise where 1/sqrt(estimates) from the larger run puts it, and the
    # worst figure the largest of those runs' (none extrapolated)
    runs = c["runs_at_target"]
    assert [t["frequency_thz"] for t in runs] == [ch["frequency_thz"] for ch in c["channels"]]
    for w, t in enumerate(runs):
        finite(t, ["rms_stderr_k", "seconds_render", "seconds_to_target"], name, positive=True)
        j1, j2 = c["runs"][1]["estimates_per_pass"], t["estimates_per_pass"]
        assert j1 <= j2 <= 8, (j1, j2)
        expect = c["runs"][1]["rms_stderr_k"][w] * (j1 / j2) ** 0.5
        assert expect / 1.5 < t["rms_stderr_k"] < expect * 1.5, (name, t["rms_stderr_k"], expect)
        # a first run at the target that missed it is reported beside the second (null: none)
        first = t["first_estimates_per_pass"]
        assert first is None or (first < j2 and t["first_rms_stderr_k"] > c["target_k"]), t
    assert c["worst_seconds_to_target"] == max(t["seconds_to_target"] for t in runs), c

# Every target with a finite value, its limit and a verdict; none left unmeasured.
assert "targets_not_measured" not in r
names = [t["target"] for t in r["targets"]]
for want in ["end to end", "raw Embree", "photon phase speed-up", "render speed-up",
             "photon-map", "final-gather", "path", "to 0.05 K", "bytes per stored photon",
             "CPU time per photon, 0.01 M"]:
    if not any(want in n for n in names):
        sys.exit(f"FAIL: no target mentions '{want}': {names}")
assert len(r["targets"]) == 13, len(r["targets"])
for t in r["targets"]:
    need(t, ["target", "limit", "met", "verdict"], "targets[]")
    finite(t, ["value", "limit"], f"target '{t['target']}'")
    assert t["verdict"] in ("met", "not met", "not shown"), t
# Flatness: each point's CPU per photon against the reference runs just before its own
# runs (the first point's count), not the points against each other.
flat = [t for t in r["targets"] if t["target"].startswith("CPU time per photon, 0.01 M")][0]
rel = [pt["cpu_vs_reference"] for pt in r["scaling_photons"]]
assert all(x > 0 for x in rel), rel
want = 100 * max(abs(x - 1) for x in rel)
assert abs(flat["value"] - want) <= 1e-6 * max(want, 1), (flat, rel)
finite(r, ["flatness_between_points_percent"], "root")

# Each figure as docs/benchmark.md "What it measures" computes it from its parts, each
# target's value the figure its section reports, and each verdict what value and limit say.
def near(a, b, what, rel=1e-9):
    if not abs(a - b) <= rel * max(abs(a), abs(b), 1e-300):
        sys.exit(f"FAIL: {what}: {a!r}, its parts give {b!r}")
sec = p["seconds"]
near(p["photons_per_s"], p["photons_fired"] / sec["photon_phase"], "photons per second")
for run in [e, d]:  # end to end: the scene's load counted (run: thz_simulate and the writing)
    near(run["seconds"], run["seconds_load"] + run["seconds_run"], "end-to-end seconds", rel=1e-6)
near(p["peak_memory_over_map"], p["peak_memory_bytes"] / p["largest_map_bytes"],
     "peak memory over the map")
tl = r["tracing_limit"]
near(tl["photon_phase_over_raw"], sec["photon_phase"] / tl["seconds"], "photon phase / raw")
near(tl["tracing_over_raw"], sec["tracing"] / tl["seconds"], "tracing / raw")
near(th["raw_speedup"], th["raw_probe"]["speedup"], "the probe's speed-up")
for k in ["photon_phase", "raw_probe", "ceiling"]:
    q = th[k]
    ratios = [a / b for a, b in zip(q["seconds_1"], q["seconds_all"])]
    near(q["pair_min"], min(ratios), f"{k}'s smallest pair")
    near(q["pair_max"], max(ratios), f"{k}'s largest pair")
for x in s["integrators"]:
    q = x["runs"]
    near(x["speedup"], q["speedup"], f"{x['integrator']}'s speed-up")
    ratios = [a / b for a, b in zip(q["seconds_1"], q["seconds_all"])]
    assert len(ratios) == 3, ratios
    m = sorted(range(3), key=lambda i: ratios[i])[1]  # the median pair's seconds
    near(x["seconds_1"], q["seconds_1"][m], "the median pair's 1-thread seconds")
    near(x["seconds_all"], q["seconds_all"][m], "the median pair's all-thread seconds")
for pt in r["scaling_photons"]:
    near(pt["ns_per_photon"], 1e9 * pt["seconds"] / pt["photons"], "ns per photon")
for pt in r["rendering"]:
    near(pt["gathers_per_s"], pt["gathers"] / pt["seconds"], "gathers per second")
# time to a converged image: the larger run's render time x (RMS / target)^2 plus its
# photon phase; each channel run at J* = 4 J (RMS / target)^2 (at least 2, at most
# --small's 8), its seconds scaled up only where it missed the target
for name in ["path", "final-gather"]:
    c = r["converged_image"][name]
    tk, lim, big, small_run = c["target_k"], c["limit_seconds_per_channel"], c["runs"][1], c["runs"][0]
    assert tk == 0.05, tk
    # the photon phase: none for path, final-gather's own map in every run (its
    # seconds counted, not the render's read twice)
    for run in c["runs"] + c["runs_at_target"]:
        ph = run["seconds_photons"] if isinstance(run["seconds_photons"], list) \
            else [run["seconds_photons"]]
        assert all((x == 0) if name == "path" else (x > 0) for x in ph), (name, run)
    for w, ch in enumerate(c["channels"]):
        q = (big["rms_stderr_k"][w] / tk) ** 2
        near(ch["seconds_to_target"], big["seconds_photons"][w] + big["seconds_render"][w] * q,
             f"{name} {ch['frequency_thz']} THz extrapolated seconds")
        near(ch["ratio_to_limit"], ch["seconds_to_target"] / lim, f"{name} ratio to the limit")
        r0, r1 = small_run["seconds_render"][w], big["seconds_render"][w]
        k = (math.log(big["rms_stderr_k"][w] / small_run["rms_stderr_k"][w]) / math.log(r1 / r0)
             if r1 > r0 else 0.0)
        near(ch["exponent"], k, f"{name} exponent", rel=1e-6)
        t = c["runs_at_target"][w]
        sc = big["rms_stderr_k"][w] / tk  # in the order bench_converge_confirm multiplies
        want = max(2, min(8, math.ceil(big["estimates_per_pass"] * sc * sc)))
        first = t["first_estimates_per_pass"]
        assert (first if first is not None else t["estimates_per_pass"]) == want, (name, w, t, want)
        near(t["seconds_to_target"], t["seconds_photons"]
             + t["seconds_render"] * max(1.0, (t["rms_stderr_k"] / tk) ** 2),
             f"{name} {t['frequency_thz']} THz seconds at the target")
    near(c["worst_ratio_to_limit"], c["worst_seconds_to_target"] / lim, f"{name} worst ratio")

# the targets: each value the figure above, each verdict what the value and limit say
def target(start):
    found = [t for t in r["targets"] if t["target"].startswith(start)]
    assert len(found) == 1, (start, found)
    return found[0]
sp = r["scaling_photons"]
tri = r["scaling_triangles"]
for start, value in [
        ("paper's case (photon-map) end to end", e["seconds"]),
        ("photon phase / raw Embree", tl["photon_phase_over_raw"]),
        (f"photon phase speed-up, {r['threads']} threads", th["speedup"]),
        ("path: s per channel", r["converged_image"]["path"]["worst_seconds_to_target"]),
        ("final-gather: s per channel",
         r["converged_image"]["final-gather"]["worst_seconds_to_target"]),
        ("bytes per stored photon", p["bytes_per_stored_photon"]),
        ("peak memory / photon map", p["peak_memory_over_map"]),
        ("CPU time per photon, 1 k..1 M triangles",
         tri[-1]["cpu_ns_per_photon"] / tri[0]["cpu_ns_per_photon"]),
        ("rendering share", 100 * sec["render"] / sec["total"])] + [
        (f"render speed-up, {r['threads']} threads against 1: {x['integrator']}", x["speedup"])
        for x in s["integrators"]]:
    near(target(start)["value"], value, f"target '{start}'")
for t in r["targets"]:
    shown = True
    if "speed-up" in t["target"]:
        shown = r["threads"] == 2
    if t["target"].startswith("CPU time per photon, 0.01 M"):
        shown = sp[0]["photons"] <= 1000000 and sp[-1]["photons"] >= 100000000
    assert t["comparison"] == (">=" if "speed-up" in t["target"] else "<="), t
    met = t["value"] >= t["limit"] if t["comparison"] == ">=" else t["value"] <= t["limit"]
    want = "not shown" if not shown else "met" if met else "not met"
    assert t["verdict"] == want and t["met"] == (want == "met"), (t, want)
assert r["targets_met"] == sum(t["met"] for t in r["targets"]), r["targets_met"]
print("bench JSON ok")
PY
