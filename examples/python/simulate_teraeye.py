#!/usr/bin/env python3
"""Simulates the paper's test scene (examples/teraeye) and plots each object's mean
brightness temperature against frequency (the paper's Fig. 6) to a PNG.

    PYTHONPATH=python python3 examples/python/simulate_teraeye.py [--out spectra.png]
        [--small] [--integrator path|final-gather|photon-map] [--photons N]

It renders with the converged `path` integrator by default (a few seconds for the six
channels at 64 x 64 pixels); --small (or THZMAP_EXAMPLE_SMALL=1) renders 16 x 16 pixels,
for tests.
"""
import argparse
import json
import os

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
import thzmap  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE_DIR = os.path.join(HERE, "..", "teraeye")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="teraeye-spectra.png", help="the PNG to write")
    ap.add_argument("--small", action="store_true",
                    default=os.environ.get("THZMAP_EXAMPLE_SMALL") == "1")
    ap.add_argument("--integrator", default="path")
    ap.add_argument("--photons", type=int, default=None,
                    help="photons per channel (photon-map, final-gather)")
    args = ap.parse_args()

    # The scene as a dict, so that it can be changed before loading; its material
    # files are relative to its own directory.
    with open(os.path.join(SCENE_DIR, "scene.json")) as f:
        d = json.load(f)
    if args.small:
        d["sensors"][0]["resolution"] = [16, 16]
        d["sensors"][0]["oversampling"] = 1
    scene = thzmap.scene_from_dict(d, base_dir=SCENE_DIR, label="teraeye (modified)")

    result = thzmap.simulate(scene, integrator=args.integrator, photons=args.photons,
                             seed=1, progress=not args.small)
    image = result.image(scene.sensor_names[0])
    tb = image.brightness_temperature  # (rows, columns, channels), K
    ids = image.object_id.astype(int)  # (rows, columns), -1: nothing hit
    freqs = image.frequencies_thz

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for k, obj in enumerate(scene.objects):
        mask = ids == k
        if mask.sum() < 2:
            continue
        spectrum = tb[mask].mean(axis=0)  # mean over the object's pixels, per channel
        style = "-o" if obj.type == "solid" else "--."
        ax.plot(freqs, spectrum, style, color=plt.cm.tab20(k % 20),
                label=f"{obj.name} ({mask.sum()} px)")
    ax.set_xlabel("frequency (THz)")
    ax.set_ylabel("mean brightness temperature (K)")
    ax.set_title(f"{scene.name}: {args.integrator}, "
                 f"{image.columns} x {image.rows} pixels")
    ax.legend(fontsize=7, ncol=2)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    worst = max(c["median_stderr_k"] for c in result.summary["channels"])
    print(f"wrote {args.out}: {len(freqs)} channels, worst median standard error "
          f"{worst:.3f} K, run {result.totals.seconds:.2f} s")


if __name__ == "__main__":
    main()
