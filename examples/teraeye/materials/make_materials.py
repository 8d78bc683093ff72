#!/usr/bin/env python3
"""Writes the material tables of the teraeye example (the paper's test case).

Three artificial target materials, each with one strong emissivity band (a dip in its
reflectivity, emissivity 1 - R rising from ~0.45 to 0.95) at a different frequency, so
that their spectra differ clearly across the six channels 0.2-1.2 THz even though the
targets are only 7-17 K warmer than the box (a near-isothermal scene shows emissivity
contrast times temperature contrast, about 1-3 % of the normalised radiance here); and one cover material whose attenuation rises with frequency,
alpha_M = 200 1/m * (f / 0.2 THz)^1.51, i.e. ~200 1/m at 0.2 THz to ~3000 1/m at 1.2 THz,
so that the 0.1, 0.5 and 1 mm stripes hide the targets increasingly with frequency.

The tables run from 0.1 to 1.4 THz, past every channel's band (centre +- 2 FWHM).
Run it from this directory: python3 make_materials.py
"""
import math

FREQS = [round(0.1 + 0.025 * i, 3) for i in range(53)]  # 0.1 ... 1.4 THz


def dip(base, depth, centre_thz, sigma_thz):
    return lambda f: base - depth * math.exp(-((f - centre_thz) ** 2) / (2 * sigma_thz ** 2))


TARGETS = {
    "target_a.csv": ("target A: reflectivity 0.60 with a dip to 0.05 at 0.4 THz",
                     dip(0.60, 0.55, 0.40, 0.08)),
    "target_b.csv": ("target B: reflectivity 0.55 with a dip to 0.05 at 0.8 THz",
                     dip(0.55, 0.50, 0.80, 0.08)),
    "target_c.csv": ("target C: reflectivity 0.50 with a dip to 0.05 at 1.0 THz",
                     dip(0.50, 0.45, 1.00, 0.10)),
}

for name, (title, reflectivity) in TARGETS.items():
    with open(name, "w") as f:
        f.write(f"# {title} (written by make_materials.py)\n")
        f.write("frequency_thz,reflectivity\n")
        for fr in FREQS:
            f.write(f"{fr:.3f},{reflectivity(fr):.5f}\n")

with open("cover.csv", "w") as f:
    f.write("# cover: reflectivity 0.05, attenuation 200 1/m * (f / 0.2 THz)^1.51 "
            "(written by make_materials.py)\n")
    f.write("frequency_thz,reflectivity,attenuation_per_m\n")
    for fr in FREQS:
        f.write(f"{fr:.3f},0.05,{200.0 * (fr / 0.2) ** 1.51:.2f}\n")
