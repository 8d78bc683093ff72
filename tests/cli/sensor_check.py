#!/usr/bin/python3
"""Checks of the sensor model's outputs for tests/cli/test_sensor.sh (numpy only; J1 by
its integral representation, so nothing here shares code with thzmap).

usage: sensor_check.py noise OUTDIR T_K      (the furnace: sensors tp, dicke, netd)
       sensor_check.py psf OUTDIR D_M PITCH_RAD  (the hot disk: sensor cam)
Prints what it measured; exits 1 with a message per failed check.
"""
import json
import math
import sys

import numpy as np

FWHM_PER_SIGMA = 2.0 * math.sqrt(2.0 * math.log(2.0))
C = 299792458.0
fails = []


def cube(outdir, sensor, quantity):
    hdr = open(f"{outdir}/{sensor}.{quantity}.hdr").read()
    field = lambda k: int(hdr.split(f"\n{k} = ")[1].split("\n")[0])
    s, l, b = field("samples"), field("lines"), field("bands")
    return np.fromfile(f"{outdir}/{sensor}.{quantity}.img", "<f4").reshape(b, l, s).astype(float)


def check(ok, msg):
    print(("ok:   " if ok else "FAIL: ") + msg)
    if not ok:
        fails.append(msg)


def corr(a, b):
    a = a - a.mean()
    b = b - b.mean()
    return float((a * b).sum() / math.sqrt((a * a).sum() * (b * b).sum()))


def noise(outdir, t_k):
    summary = json.load(open(f"{outdir}/summary.json"))
    channels = summary["channels"]
    scene = json.load(open(summary["scene"]["path"]))
    freqs = [c["frequency_thz"] * 1e12 for c in scene["channels"]]
    widths = [c["relative_width"] for c in scene["channels"]]
    for sn in scene["sensors"]:
        name, model = sn["name"], sn["noise"]
        truth = cube(outdir, name, "brightness_temperature")
        meas = cube(outdir, name, "measured_brightness_temperature")
        n = truth[0].size
        for c in range(len(freqs)):
            # the Gaussian's noise bandwidth: 2 sqrt(pi) sigma
            b_n = 2.0 * math.sqrt(math.pi) * widths[c] * freqs[c] / FWHM_PER_SIGMA
            if "netd_k" in model:
                netd = model["netd_k"][c] if isinstance(model["netd_k"], list) else model["netd_k"]
            else:
                k = 2.0 if model["radiometer"] == "dicke" else 1.0
                netd = k * (t_k + model["receiver_temperature_k"]) / math.sqrt(
                    b_n * model["integration_time_s"])
            d = meas[c] - truth[c]
            std = float(d.std(ddof=1))
            tol = 3.0 * netd / math.sqrt(2.0 * n)
            check(abs(std - netd) < tol, f"{name} channel {c}: std of measured Tb {std:.5f} K, "
                  f"expected {netd:.5f} K +- {tol:.5f} K")
            mean = float(d.mean())
            check(abs(mean) < 3.0 * netd / math.sqrt(n),
                  f"{name} channel {c}: mean of measured - true Tb {mean:+.5f} K "
                  f"(limit {3.0 * netd / math.sqrt(n):.5f} K)")
            r_h = corr(d[:, :-1], d[:, 1:])
            r_v = corr(d[:-1, :], d[1:, :])
            lim = 3.0 / math.sqrt(n)
            check(abs(r_h) < lim and abs(r_v) < lim,
                  f"{name} channel {c}: neighbour correlation {r_h:+.4f} (rows), {r_v:+.4f} "
                  f"(columns), limit {lim:.4f}")
        if len(freqs) > 1:
            r = corr(meas[0] - truth[0], meas[1] - truth[1])
            check(abs(r) < 3.0 / math.sqrt(n),
                  f"{name}: correlation between channels 0 and 1 {r:+.4f}")


def j1(x):
    """Bessel J1 by (1/pi) int_0^pi cos(t - x sin t) dt (trapezoid: exact to ~1e-15 for
    a periodic integrand with this many nodes at x < 60)."""
    t = np.linspace(0.0, math.pi, 401)
    v = np.cos(t[None, :] - np.asarray(x, float).reshape(-1, 1) * np.sin(t[None, :]))
    return (v[:, 1:-1].sum(axis=1) + 0.5 * (v[:, 0] + v[:, -1])) / 400.0


def airy_band(theta, f_c, w, d_m):
    """The Airy pattern per sr averaged over the Gaussian response."""
    sigma = w * f_c / FWHM_PER_SIGMA
    ts = np.linspace(-6, 6, 121)
    wts = np.exp(-0.5 * ts ** 2)
    out = np.zeros_like(theta)
    for t, g in zip(ts, wts):
        lam = C / (f_c + sigma * t)
        x = math.pi * d_m * np.sin(theta) / lam
        a = np.where(x < 1e-9, 1.0, 2.0 * j1(np.maximum(x, 1e-9)) / np.maximum(x, 1e-9))
        out += g * math.pi * d_m ** 2 / (4 * lam ** 2) * a * a
    return out / wts.sum()


def half_width(v, step):
    half = 0.5 * v[0]
    i = int(np.argmax(v < half))
    return step * ((i - 1) + (v[i - 1] - half) / (v[i - 1] - v[i]))


def psf(outdir, d_m, pitch):
    scene = json.load(open(json.load(open(f"{outdir}/summary.json"))["scene"]["path"]))
    sharp = cube(outdir, "cam", "radiance")
    meas = cube(outdir, "cam", "measured_radiance")
    for c, ch in enumerate(scene["channels"]):
        f_c, w = ch["frequency_thz"] * 1e12, ch["relative_width"]
        s, m = sharp[c].sum(), meas[c].sum()
        check(s > 0 and abs(m / s - 1) < 0.005,
              f"channel {c}: summed measured radiance / sharp = {m / s:.6f}")
        rows, cols = meas[c].shape
        r0, c0 = np.unravel_index(np.argmax(sharp[c]), sharp[c].shape)
        check(sharp[c][r0, c0] > 0.99 * s, f"channel {c}: the sharp disk is one pixel "
              f"({sharp[c][r0, c0] / s:.4f} of the power)")
        row = meas[c][r0, c0:]
        theta = np.arange(40) * pitch
        want = airy_band(theta, f_c, w, d_m)
        dev = np.abs(row[:40] / row[0] - want / want[0]).max()
        check(dev < 5e-3, f"channel {c}: radial profile vs band-averaged Airy, largest "
              f"deviation {dev:.2e} of the peak")
        fine = airy_band(np.arange(600) * pitch / 10, f_c, w, d_m)
        fwhm, fwhm_want = 2 * half_width(row, pitch), 2 * half_width(fine, pitch / 10)
        check(abs(fwhm / fwhm_want - 1) < 0.03,
              f"channel {c}: FWHM {fwhm * 1e3:.4f} mrad, band-averaged Airy "
              f"{fwhm_want * 1e3:.4f} mrad, 1.029 lambda/D {1.029 * C / f_c / d_m * 1e3:.4f} mrad")


if __name__ == "__main__":
    if sys.argv[1] == "noise":
        noise(sys.argv[2], float(sys.argv[3]))
    else:
        psf(sys.argv[2], float(sys.argv[3]), float(sys.argv[4]))
    sys.exit(1 if fails else 0)
