#!/usr/bin/python3
"""The post-processor's answers of `thzmap serve` (docs/gui.md), checked against the ENVI
files and the photon map that `thzmap simulate` wrote: the fields of a cube (its
quantity, the object names), one pixel (its edge, a run without radiance_stderr, the
measured brightness temperature), the A/B difference (a second band, its size headers,
images of two sizes, K without a standard error, errors of 0), the frames of a sweep, a
sensor's images, and the photons (evenly subsampled, counted per channel).
test_api_runs.py has the rest of them, from runs the server made.

usage: test_api_results.py THZMAP_BINARY REPO_DIR [--requests-only]

The server starts no job here (the runs are the CLI's), so --requests-only changes nothing.
"""
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import tempfile

from serve_client import Server, check, finish
from serve_root import make_root

BINARY, REPO = sys.argv[1], sys.argv[2]
ROWS, COLS, PLANE = 12, 16, 192


def floats(path):
    data = open(path, "rb").read()
    return list(struct.unpack("<%df" % (len(data) // 4), data))


def f32(values):
    """JSON numbers (9 significant digits) as the float32 values they stand for."""
    return [struct.unpack("<f", struct.pack("<f", v))[0] for v in values]


def planck_tb(freq_hz, radiance):
    h, k, c = 6.62607015e-34, 1.380649e-23, 299792458.0
    return h * freq_hz / k / math.log1p(2 * h * freq_hz ** 3 / (c * c * radiance))


def copy_run(root, src, dst, drop=()):
    """out/src copied to out/dst without the files whose names hold one of drop."""
    shutil.copytree(os.path.join(root, "out", src), os.path.join(root, "out", dst),
                    ignore=lambda d, names: [n for n in names if any(x in n for x in drop)])


def test_cubes(srv):
    st, h, _ = srv.request("GET", "/api/cube/data?path=out/a/cam.radiance.hdr&band=0")
    check(st == 200 and h.get("Content-Type") == "application/octet-stream" and
          h.get("Content-Security-Policy") == "default-src 'none'; sandbox" and
          h.get("X-Content-Type-Options") == "nosniff", "binary answer's headers: %r" % h)
    for q in ("brightness_temperature", "radiance_stderr", "object_id"):
        cube = srv.json("GET", "/api/cube?path=out/a/cam.%s.hdr" % q)
        check(cube and cube["quantity"] == q, "cube of %s: quantity %r" % (q, cube and cube["quantity"]))
    cube = srv.json("GET", "/api/cube?path=out/a/cam.object_id.hdr")
    check(cube and cube["object_names"] == ["room", "target", "cover"],
          "object_id cube's object names: %r" % (cube and cube["object_names"]))
    # a header of another program in Latin-1 (main): the answer was 500 "out of memory"
    # for its unit, its band names and object names were left out; each byte that is not
    # UTF-8 is told as '?'
    cube = srv.json("GET", "/api/cube?path=out/latin1/cam.brightness_temperature.hdr")
    check(cube and cube["units"] == "?K" and len(cube["band_names"]) == cube["bands"] and
          cube["band_names"][0].startswith("?"), "a Latin-1 header's cube: %r" % cube)
    cube = srv.json("GET", "/api/cube?path=out/latin1/cam.object_id.hdr")
    check(cube and cube["object_names"] == ["r?om", "target", "cover"],
          "a Latin-1 header's object names: %r" % (cube and cube["object_names"]))


def test_pixel(root, srv):
    err = srv.json("GET", "/api/pixel?dir=out/a&sensor=cam&row=0&col=%d" % COLS, status=400)
    # numbers that are not whole numbers are no pixel nor band (they were read as 0 and 1)
    srv.json("GET", "/api/pixel?dir=out/a&sensor=cam&row=x&col=0", status=400)
    srv.json("GET", "/api/cube/data?path=out/a/cam.radiance.hdr&band=1x", status=400)
    check(err and "outside the image of 16 x 12 pixels" in err.get("error", ""),
          "pixel one column right of the image: %r" % err)
    # a run without radiance_stderr: no standard error (null), the rest as it is
    p = srv.json("GET", "/api/pixel?dir=out/nose&sensor=cam&row=3&col=4")
    tb = floats(os.path.join(root, "out", "a", "cam.brightness_temperature.img"))
    check(p and p["tb_stderr_K"] is None and p["radiance_stderr"] is None and
          f32(p["tb_K"]) == [tb[3 * COLS + 4], tb[PLANE + 3 * COLS + 4]],
          "pixel of a run without radiance_stderr: %r" % p)
    # the noisy sensor's measured brightness temperature, from its own cube
    small = os.path.join(root, "out", "small")
    measured = floats(os.path.join(small, "cam.measured_brightness_temperature.img"))
    clean = floats(os.path.join(small, "cam.brightness_temperature.img"))
    p = srv.json("GET", "/api/pixel?dir=out/small&sensor=cam&row=5&col=3")
    i = 5 * 8 + 3
    check(p and f32(p["measured_tb_K"]) == [measured[i]] and f32(p["tb_K"]) == [clean[i]] and
          measured[i] != clean[i], "measured Tb of a noisy sensor: %r, the cubes %r %r"
          % (p, measured[i], clean[i]))
    # a pixel that sees nothing: the truth maps' -1 (their data ignore value), no object
    ids = floats(os.path.join(small, "cam.object_id.img"))
    miss = ids.index(-1.0) if -1.0 in ids else None
    p = miss is not None and srv.json("GET", "/api/pixel?dir=out/small&sensor=cam&row=%d&col=%d"
                                      % (miss // 8, miss % 8))
    check(p and p["truth"] == {"object": None, "object_id": -1, "temperature_K": -1,
                               "distance_m": -1}, "a pixel that sees nothing: %r" % p)
    for q in ("object_id", "temperature", "distance"):
        cube = srv.json("GET", "/api/cube?path=out/small/cam.%s.hdr" % q)
        check(cube and cube["min"] == [-1], "min of %s where pixels see nothing: %r"
              % (q, cube and cube["min"]))


def test_diff(root, srv):
    out = lambda run, q: floats(os.path.join(root, "out", run, "cam.%s.img" % q))
    tb_a, tb_b = out("a", "brightness_temperature"), out("b", "brightness_temperature")
    rad_a, rad_b = out("a", "radiance"), out("b", "radiance")
    se_a, se_b = out("a", "radiance_stderr"), out("b", "radiance_stderr")
    # band 1 (0.6 THz): its own Tb, and its standard error at its own centre
    st, h, data = srv.request("GET", "/api/diff?a=out/a&b=out/b&sensor=cam&band=1")
    diff = struct.unpack("<192f", data) if st == 200 and len(data) == 4 * PLANE else None
    check(diff and h.get("X-Thzmap-Diff-Units") == "sigma" and h.get("X-Thzmap-Rows") == "12"
          and h.get("X-Thzmap-Columns") == "16", "diff of band 1: %d %r" % (st, h))
    worst = 0.0
    for i in range(PLANE) if diff else []:
        j = PLANE + i
        sa = 0.5 * (planck_tb(0.6e12, rad_a[j] + se_a[j]) - planck_tb(0.6e12, rad_a[j] - se_a[j]))
        sb = 0.5 * (planck_tb(0.6e12, rad_b[j] + se_b[j]) - planck_tb(0.6e12, rad_b[j] - se_b[j]))
        if sa * sa + sb * sb > 0:
            want = (tb_a[j] - tb_b[j]) / math.sqrt(sa * sa + sb * sb)
            worst = max(worst, abs(diff[i] - want) / max(1, abs(want)))
    check(worst <= 1e-3, "diff of band 1: off by %g of the independent value" % worst)
    # images of different sizes (16 x 12 and 8 x 12: the rows agree)
    err = srv.json("GET", "/api/diff?a=out/a&b=out/small&sensor=cam&band=0", status=400)
    check(err and "differ in size" in err.get("error", ""), "diff of 16 x 12 and 8 x 12: %r" % err)
    # one run without radiance_stderr: Tb_a - Tb_b in K
    st, h, data = srv.request("GET", "/api/diff?a=out/b&b=out/nose&sensor=cam&band=0")
    diff = struct.unpack("<192f", data) if st == 200 and len(data) == 4 * PLANE else None
    check(diff and h.get("X-Thzmap-Diff-Units") == "K" and
          list(diff) == f32([tb_b[i] - tb_a[i] for i in range(PLANE)]),
          "diff against a run without radiance_stderr: %d %r" % (st, h))
    # errors of 0 on both sides: 0 where the two agree, else NaN
    st, h, data = srv.request("GET", "/api/diff?a=out/z1&b=out/z2&sensor=cam&band=0")
    diff = struct.unpack("<192f", data) if st == 200 and len(data) == 4 * PLANE else None
    check(diff and h.get("X-Thzmap-Diff-Units") == "sigma" and math.isnan(diff[5]) and
          all(diff[i] == 0.0 for i in range(PLANE) if i != 5),
          "diff with errors of 0: %r" % (diff and diff[:8],))


def test_damaged_cubes(root, srv):
    """A standard-error or radiance cube that is there but cannot be read (here a header
    without its sizes), or is not of Tb's size, is said: a 400 naming it, relative to the
    root. /api/diff answered Tb_a - Tb_b in K and /api/pixel a null standard error, as for
    a run that wrote no such cube, and /api/cube named the file by its absolute path."""
    for q in ("radiance_stderr", "radiance"):
        copy_run(root, "b", "bad-" + q)
        with open(os.path.join(root, "out", "bad-" + q, "cam.%s.hdr" % q), "w") as f:
            f.write("ENVI\ngarbage\n")
        want = "out/bad-%s/cam.%s.hdr: " % (q, q)
        err = srv.json("GET", "/api/diff?a=out/a&b=out/bad-%s&sensor=cam&band=0" % q,
                       status=400)
        check(err and err.get("error", "").startswith(want), "diff, damaged %s: %r" % (q, err))
        err = srv.json("GET", "/api/pixel?dir=out/bad-%s&sensor=cam&row=3&col=4" % q, status=400)
        check(err and err.get("error", "").startswith(want), "pixel, damaged %s: %r" % (q, err))
        err = srv.json("GET", "/api/cube?path=out/bad-%s/cam.%s.hdr" % (q, q), status=400)
        check(err and err.get("error", "").startswith(want) and root not in err["error"],
              "cube, damaged %s: %r" % (q, err))
    # a standard error of another run's size beside Tb (out/small's 8 x 12 cubes)
    copy_run(root, "b", "mixed")
    for ext in ("hdr", "img"):
        shutil.copy(os.path.join(root, "out", "small", "cam.radiance_stderr." + ext),
                    os.path.join(root, "out", "mixed", "cam.radiance_stderr." + ext))
    err = srv.json("GET", "/api/diff?a=out/a&b=out/mixed&sensor=cam&band=0", status=400)
    check(err and "out/mixed/cam.radiance_stderr.hdr: 8 x 12 pixels" in err.get("error", ""),
          "diff, a standard error of another size: %r" % err)


def test_outputs(root, srv):
    res = srv.json("GET", "/api/outputs?dir=out/nose")
    cam = res and [s for s in res["sensors"] if s["name"] == "cam"]
    check(cam and "cam.visual.png" in cam[0]["images"] and
          "camera.visual.png" not in cam[0]["images"],
          "images of sensor cam: %r" % (cam and cam[0]["images"]))
    # a map at the root itself: its path relative to the root, not "/photon-map.thzpm"
    shutil.copy(os.path.join(root, "out", "a", "photon-map.thzpm"), root)
    res = srv.json("GET", "/api/outputs?dir=")
    check(res and res["photon_map"] == "photon-map.thzpm", "a map at the root: %r"
          % (res and res["photon_map"]))
    os.remove(os.path.join(root, "photon-map.thzpm"))
    err = srv.json("GET", "/api/outputs?dir=s/scene.json", status=400)
    check(err and "not a directory" in err.get("error", ""), "outputs of a file: %r" % err)
    # a summary.json that is there but damaged: said so, naming the file and where the
    # JSON breaks (it was "summary": null, as for a directory with none)
    res = srv.json("GET", "/api/outputs?dir=out/a")
    check(res and isinstance(res["summary"], dict) and res["summary_error"] is None,
          "a run's summary: %r" % (res and res.get("summary_error")))
    copy_run(root, "a", "cut", drop=("photon-map",))
    path = os.path.join(root, "out", "cut", "summary.json")
    text = open(path).read()
    open(path, "w").write(text[:len(text) // 2])
    res = srv.json("GET", "/api/outputs?dir=out/cut/")
    why = res and res.get("summary_error") or ""
    check(res and res["summary"] is None and why.startswith("out/cut/summary.json: line ")
          and ", column " in why, "a summary cut in half: %r" % why)
    open(path, "w").write("[1, 2]")
    res = srv.json("GET", "/api/outputs?dir=out/cut")
    check(res and res["summary"] is None and res["summary_error"] ==
          "out/cut/summary.json: expected a JSON object, got an array", "an array: %r" % res)
    os.remove(path)
    res = srv.json("GET", "/api/outputs?dir=out/cut")
    check(res and res["summary"] is None and res["summary_error"] is None,
          "no summary.json: %r" % (res and res.get("summary_error")))
    # a sweep's frames, without a batch.json (docs/gui.md: sweep-NN/frame-NNNNN)
    for d in ("sweep-01/frame-00000", "sweep-01/frame-00001", "sweep-02/frame-00000"):
        os.makedirs(os.path.join(root, "out", "sw", d))
    res = srv.json("GET", "/api/outputs?dir=out/sw")
    check(res and res["frames"] == ["sweep-01/frame-00000", "sweep-01/frame-00001",
                                    "sweep-02/frame-00000"], "frames of a sweep: %r" % res)


def test_photons(srv):
    info = srv.json("GET", "/api/photons/info?path=out/a/photon-map.thzpm")
    for c in range(2):
        st, h, _ = srv.request("GET", "/api/photons?path=out/a/photon-map.thzpm&channel=%d&max=1"
                               % c)
        total = int(h.get("X-Thzmap-Photons-Total", -1))
        check(info and total > 0 and info["channels"][c]["photons"] == total,
              "channel %d: info %r, the photons' total %d" % (c, info and info["channels"][c], total))
    # evenly subsampled: the k-th of 100 sent lies in the k-th hundredth of all of them
    q = "/api/photons?path=out/a/photon-map.thzpm&channel=1&object=target&max=%d"
    _, _, whole = srv.request("GET", q % 20000000)
    _, h, part = srv.request("GET", q % 100)
    recs = [whole[32 * k:32 * k + 32] for k in range(len(whole) // 32)]
    index = {r: k for k, r in reversed(list(enumerate(recs)))}
    total = len(recs)
    sent = [index.get(part[32 * k:32 * k + 32], -1) for k in range(len(part) // 32)]
    check(total > 100 and len(sent) == 100 and
          all(k * total / 100 <= j < (k + 1) * total / 100 for k, j in enumerate(sent)),
          "100 of %d photons not evenly spread: %r" % (total, sent[:5] + sent[-5:]))
    err = srv.json("GET", "/api/photons?path=out/a/photon-map.thzpm&channel=0&object=nobody",
                   status=404)
    check(err and "nobody" in err.get("error", ""), "photons of no such object: %r" % err)
    srv.json("GET", "/api/photons?path=out/a/photon-map.thzpm&channel=0&max=20000001", status=400)
    # the room's photons (object 0) are the room's alone
    st, h, data = srv.request("GET", "/api/photons?path=out/a/photon-map.thzpm&channel=0&object=room"
                              "&max=20000000")
    objs = {struct.unpack_from("<f", data, 32 * k + 28)[0] for k in range(len(data) // 32)}
    check(st == 200 and objs == {0.0} and len(data) == 32 * int(h["X-Thzmap-Photons-Total"]),
          "photons of the room: %d, objects %r" % (st, objs))
    # a map without a summary.json beside it: its scene is the one given (else a 400)
    srv.json("GET", "/api/photons/info?path=out/maponly/photon-map.thzpm", status=400)
    info = srv.json("GET", "/api/photons/info?path=out/maponly/photon-map.thzpm&scene=s/scene.json")
    check(info and info["objects"] == ["room", "target", "cover"], "a map with scene=: %r" % info)
    # channel 2 of two (0 and 1): no such channel
    srv.json("GET", "/api/photons?path=out/a/photon-map.thzpm&channel=2", status=404)


def main():
    tmp = tempfile.mkdtemp(prefix="thzmap-results-")
    root = os.path.join(tmp, "root")
    os.makedirs(root)
    try:
        scene = make_root(REPO, root)
        # 8 x 12 pixels, a noisy sensor, no photons, no room: pixels that see nothing
        small = json.loads(json.dumps(scene))
        small["objects"] = small["objects"][1:]
        small["channels"] = small["channels"][:1]
        small["sensors"][0].update(resolution=[8, 12], noise={"netd_k": 0.5})
        small["render"] = {"integrator": "path", "paths_per_sample": 1}
        with open(os.path.join(root, "s", "small.json"), "w") as f:
            json.dump(small, f)
        for args in (["s/scene.json", "-o", "out/a", "--seed", "1", "--save-photon-map"],
                     ["s/scene.json", "-o", "out/b", "--seed", "2"],
                     ["s/small.json", "-o", "out/small"]):
            subprocess.run([BINARY, "simulate", "-q"] + args, cwd=root, check=True)
        copy_run(root, "a", "nose", drop=("radiance_stderr",))
        copy_run(root, "a", "latin1", drop=("photon-map",))
        for stem, old, new in (("brightness_temperature", b"data units = K", b"data units = \xb0K"),
                               ("brightness_temperature", b"band names = {", b"band names = {\xb5"),
                               ("object_id", b"object names = {room", b"object names = {r\xf6om")):
            path = os.path.join(root, "out", "latin1", "cam.%s.hdr" % stem)
            with open(path, "rb") as f:
                text = f.read()
            check(old in text, "%s holds %r" % (path, old))
            with open(path, "wb") as f:
                f.write(text.replace(old, new))
        os.makedirs(os.path.join(root, "out", "maponly"))
        shutil.copy(os.path.join(root, "out", "a", "photon-map.thzpm"),
                    os.path.join(root, "out", "maponly"))
        shutil.copy(os.path.join(root, "out", "nose", "cam.visual.png"),
                    os.path.join(root, "out", "nose", "camera.visual.png"))
        # errors of 0 everywhere, and a second run like it but 1 K warmer at pixel 5
        copy_run(root, "a", "z1", drop=("photon-map",))
        with open(os.path.join(root, "out", "z1", "cam.radiance_stderr.img"), "r+b") as f:
            size = len(f.read())
            f.seek(0)
            f.write(bytes(size))
        copy_run(root, "z1", "z2")
        with open(os.path.join(root, "out", "z2", "cam.brightness_temperature.img"), "r+b") as f:
            f.seek(4 * 5)
            v = struct.unpack("<f", f.read(4))[0]
            f.seek(4 * 5)
            f.write(struct.pack("<f", v + 1.0))
        env = dict(os.environ, THZMAP_WEB_DIR=os.path.join(tmp, "web"))
        srv = Server(BINARY, root, env)
        try:
            test_cubes(srv)
            test_pixel(root, srv)
            test_diff(root, srv)
            test_damaged_cubes(root, srv)
            test_outputs(root, srv)
            test_photons(srv)
        finally:
            srv.stop()
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    finish()


main()
