#!/usr/bin/env python3
"""Time to a converged image, per integrator (issue 7; docs/integrators.md).

For the paper's scene (examples/teraeye/scene.json: 64 x 64 pixels, 2 x 2 oversampling,
six channels 0.2-1.2 THz) and each integrator, measures the time to reach a 95th
percentile over the pixels of the per-pixel standard error of TARGET kelvin of brightness
temperature (what --target-noise-k aims at; the median is shown beside it), per channel
and in total, on THREADS threads, and prints a table; writes the numbers as JSON.

  path          thzmap simulate --integrator path --target-noise-k TARGET
  final-gather  the same with --photons PHOTONS; the time includes the photon phase;
                stops at --max-seconds per channel, or at the floor its photon map
                leaves (then "not reached" and the figures reached are shown)
  photon-map    its photon passes (simulate --target-noise-k) would need ~1e12 photons
                on this scene: one run with PHOTONS photons, and the photon count (and
                time) the target would need if the standard error falls as
                1/sqrt(photons) (extrapolated, marked ~)

Times come from summary.json (photon_phase_s, render_s per channel); they depend on the
machine and on what else runs on it.

usage: bench_integrators.py [--thzmap BUILD/thzmap] [--scene SCENE] [--target 0.05]
                            [--threads 2] [--photons 1000000] [--max-seconds 60]
                            [--integrators path,final-gather,photon-map] [--json OUT.json]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))


def run(thzmap, scene, outdir, args):
    cmd = [thzmap, "simulate", scene, "-o", outdir, "--quiet"] + args
    t0 = time.monotonic()
    subprocess.run(cmd, check=True)
    wall = time.monotonic() - t0
    with open(os.path.join(outdir, "summary.json")) as f:
        return json.load(f), wall


def channel_rows(summary, target):
    rows = []
    for c in summary["channels"]:
        photons = c.get("photon_phase_s") or 0.0
        render = c.get("render_s") or 0.0
        p95 = c.get("p95_stderr_k")
        rows.append({
            "channel": c["name"],
            "photon_phase_s": photons,
            "render_s": render,
            "seconds": photons + render,
            "passes": c.get("render_passes"),
            "median_stderr_k": c.get("median_stderr_k"),
            "p95_stderr_k": p95,
            "reached": p95 is not None and p95 <= target,
        })
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--thzmap", default=os.path.join(REPO, "build", "thzmap"))
    ap.add_argument("--scene", default=os.path.join(REPO, "examples", "teraeye", "scene.json"))
    ap.add_argument("--target", type=float, default=0.05, help="K")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--photons", type=int, default=1000000)
    ap.add_argument("--max-seconds", type=float, default=60.0, help="per channel, s")
    ap.add_argument("--integrators", default="path,final-gather,photon-map")
    ap.add_argument("--json", default=os.path.join(tempfile.gettempdir(),
                                                   "thzmap-bench-integrators.json"))
    a = ap.parse_args()
    results = {"scene": a.scene, "target_k": a.target, "threads": a.threads,
               "photons_per_channel": a.photons, "max_seconds_per_channel": a.max_seconds,
               "integrators": {}}
    common = ["--threads", str(a.threads)]
    with tempfile.TemporaryDirectory() as tmp:
        for integ in a.integrators.split(","):
            out = os.path.join(tmp, integ)
            if integ == "path":
                args = ["--integrator", "path", "--target-noise-k", str(a.target),
                        "--max-seconds", str(a.max_seconds)]
            elif integ == "final-gather":
                args = ["--integrator", "final-gather", "--photons", str(a.photons),
                        "--target-noise-k", str(a.target), "--max-seconds", str(a.max_seconds)]
            elif integ == "photon-map":
                args = ["--integrator", "photon-map", "--photons", str(a.photons)]
            else:
                sys.exit("unknown integrator " + integ)
            summary, wall = run(a.thzmap, a.scene, out, common + args)
            rows = channel_rows(summary, a.target)
            if integ == "photon-map":
                for r in rows:
                    # standard error ~ 1/sqrt(K): the photons (and, in proportion, the time)
                    # the target would need
                    f = (r["p95_stderr_k"] / a.target) ** 2 if r["p95_stderr_k"] else 1.0
                    r["photons_needed_extrapolated"] = int(a.photons * f)
                    r["seconds_extrapolated"] = r["seconds"] * f
            results["integrators"][integ] = {
                "channels": rows,
                "seconds_total": sum(r["seconds"] for r in rows),
                "wall_s": wall,
                "all_reached": all(r["reached"] for r in rows),
            }
    print("Target: 95th percentile of the per-pixel standard error %.3g K on %s, %d threads"
          % (a.target, os.path.relpath(a.scene, REPO), a.threads))
    print("%-13s %-10s %10s %10s %10s %7s %10s %10s" % ("integrator", "channel", "photons s",
                                                       "render s", "total s", "passes",
                                                       "median K", "p95 K"))
    for integ, res in results["integrators"].items():
        for r in res["channels"]:
            total = "%.2f" % r["seconds"]
            note = "" if r["reached"] else "  (not reached)"
            if integ == "photon-map":
                total = "~%.0f" % r["seconds_extrapolated"]
                note = "  (~%.2g photons needed)" % r["photons_needed_extrapolated"]
            print("%-13s %-10s %10.2f %10.2f %10s %7s %10.4f %10.4f%s"
                  % (integ, r["channel"], r["photon_phase_s"], r["render_s"], total,
                     r["passes"], r["median_stderr_k"], r["p95_stderr_k"], note))
        if integ == "photon-map":
            tot = sum(r["seconds_extrapolated"] for r in res["channels"])
            print("%-13s %-10s %32s" % (integ, "total", "~%.0f s (extrapolated)" % tot))
        else:
            print("%-13s %-10s %32s" % (integ, "total", "%.2f s%s" % (
                res["seconds_total"], "" if res["all_reached"] else ", target not reached")))
    with open(a.json, "w") as f:
        json.dump(results, f, indent=2)
    print("JSON: " + a.json)


if __name__ == "__main__":
    main()
