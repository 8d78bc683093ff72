#!/usr/bin/env python3
"""Chooses three channels for the teraeye targets (the paper's test case: three
cylinders of materials A, B, C under covers of three thicknesses) at a given NETD with
`thzmap bands`, then simulates the scene with the chosen channels and with three evenly
spaced channels over the same range, and classifies both runs with `thzmap classify`
at the same NETD. Prints both accuracies; the chosen set should classify better.

    python3 examples/bands-teraeye/run.py [--netd-k 0.5] [--out out/bands-teraeye]
        [--thzmap build/thzmap]

Uses only the thzmap program (found with --thzmap, $THZMAP, build/thzmap or PATH).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
SCENE = os.path.join(REPO, "examples", "teraeye", "scene.json")
TARGETS = ["cylinder-A", "cylinder-B", "cylinder-C"]


def find_thzmap(given):
    for candidate in (given, os.environ.get("THZMAP"), os.path.join(REPO, "build", "thzmap"),
                      shutil.which("thzmap")):
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    sys.exit("thzmap not found: build it (make build) or pass --thzmap")


def run(cmd):
    print("$ " + " ".join(cmd), flush=True)
    subprocess.run(cmd, check=True)


def scene_with_channels(freqs_thz, path):
    """The teraeye scene with the given channels (and its material tables found)."""
    with open(SCENE) as f:
        d = json.load(f)
    d["channels"] = [{"frequency_thz": f, "relative_width": 0.01} for f in freqs_thz]
    d["render"] = {"integrator": "path", "paths_per_sample": 16}
    for m in d["materials"].values():
        if "file" in m:
            m["file"] = os.path.join(os.path.dirname(SCENE), m["file"])
    with open(path, "w") as f:
        json.dump(d, f, indent=1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--netd-k", type=float, default=0.5, help="sensor NETD, K (default 0.5)")
    ap.add_argument("--from-thz", type=float, default=0.2)
    ap.add_argument("--to-thz", type=float, default=1.2)
    ap.add_argument("--step-ghz", type=float, default=20.0)
    ap.add_argument("--out", default=os.path.join(REPO, "out", "bands-teraeye"))
    ap.add_argument("--thzmap", default=None)
    args = ap.parse_args()
    thz = find_thzmap(args.thzmap)
    netd = f"{args.netd_k:g}"
    os.makedirs(args.out, exist_ok=True)

    bands_dir = os.path.join(args.out, "bands")
    run([thz, "bands", SCENE, "-o", bands_dir, "--count", "3", "--from-thz", f"{args.from_thz:g}",
         "--to-thz", f"{args.to_thz:g}", "--step-ghz", f"{args.step_ghz:g}", "--targets",
         ",".join(TARGETS), "--netd-k", netd, "--paths", "8", "-q"])
    with open(os.path.join(bands_dir, "bands.json")) as f:
        chosen = json.load(f)["selected_thz"]
    even = [args.from_thz + i * (args.to_thz - args.from_thz) / 2 for i in range(3)]

    results = {}
    for name, freqs in (("chosen", chosen), ("even", even)):
        scene = os.path.join(args.out, f"scene-{name}.json")
        scene_with_channels(freqs, scene)
        run_dir = os.path.join(args.out, f"run-{name}")
        run([thz, "simulate", scene, "-o", run_dir, "-q", "--seed", "2"])
        cls_dir = os.path.join(args.out, f"classify-{name}")
        run([thz, "classify", run_dir, "--sensor", "cam", "-o", cls_dir, "--method", "lda",
             "--netd-k", netd, "-q"])
        with open(os.path.join(cls_dir, "classification.json")) as f:
            c = json.load(f)
        targets = {k["name"]: k["accuracy"] for k in c["classes"] if k["name"] in TARGETS}
        results[name] = (freqs, c["accuracy"], c["held_out_accuracy"], targets)

    print(f"\nNETD {args.netd_k:g} K, LDA on the brightness temperature, every object a class:")
    for name, (freqs, acc, held, targets) in results.items():
        print(f"  {name:6s} channels {', '.join(f'{f:.3f}' for f in freqs)} THz: "
              f"accuracy {100 * acc:.1f} % (held-out {100 * held:.1f} %); cylinders " +
              ", ".join(f"{k[-1]} {100 * v:.1f} %" for k, v in sorted(targets.items())))
    better = results["chosen"][1] >= results["even"][1]
    print("the chosen channels classify " + ("at least as well as" if better else "WORSE than") +
          " the evenly spaced ones")
    return 0 if better else 1


if __name__ == "__main__":
    sys.exit(main())
