#!/usr/bin/python3
"""What `thzmap serve`'s JSON API computes (docs/gui.md), against a real server on a free
port over a temporary root: a scene's validation (channels, meshes, spectra, the
atmosphere, errors at their JSON path or line), the material library, runs (server-sent
events, a render queued behind its map's run, batch and bands, cancel, SIGTERM), and the
post-processor's answers (cubes, pixels, A/B differences, photons) compared with the ENVI
files the run wrote. test_api.py has who may ask and where.

usage: test_api_runs.py THZMAP_BINARY REPO_DIR [--requests-only]

--requests-only: validation and the material library alone, which start no job (test_api.py
says why).
"""
import http.client
import json
import math
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import time

from serve_client import Server, check, finish
from serve_root import make_root, wait_state

BINARY, REPO = sys.argv[1], sys.argv[2]
REQUESTS_ONLY = sys.argv[3:] == ["--requests-only"]


def read_img(path):
    data = open(path, "rb").read()
    return data, struct.unpack("<%df" % (len(data) // 4), data)


def f32(values):
    """JSON numbers (9 significant digits) as the float32 values they stand for."""
    return [struct.unpack("<f", struct.pack("<f", v))[0] for v in values]


def planck_tb(freq_hz, radiance):
    h, k, c = 6.62607015e-34, 1.380649e-23, 299792458.0
    return h * freq_hz / k / math.log1p(2 * h * freq_hz ** 3 / (c * c * radiance))


def test_validate(srv, scene):
    text = json.dumps(scene)
    other = json.loads(text)
    other["sensors"][0]["normalize_to_k"] = 300  # not the room's 295 K, the default
    res = srv.json("POST", "/api/validate", body={"path": "s/scene.json", "text": json.dumps(other)})
    check(res and res["ok"] and res["scene"]["sensors"][0]["normalize_to_k"] == 300,
          "the sensor's normalize_to_k (docs/gui.md): %r" % (res and res["scene"]["sensors"]))
    res = srv.json("POST", "/api/validate", body={"path": "s/scene.json", "text": text})
    sc = res and res["scene"]
    check(res and res["ok"] and not res["errors"], "validate ok: %r" % (res and res["errors"]))
    if sc:
        check([c["centre_thz"] for c in sc["channels"]] == [0.35, 0.6], "channels")
        check(abs(sc["channels"][0]["width_thz"] - 0.0035) < 1e-9, "channel width")
        target = [o for o in sc["objects"] if o["name"] == "target"][0]
        pos, idx = target["mesh"]["positions"], target["mesh"]["indices"]
        check(len(idx) == 3 * target["triangles"] and max(idx) < len(pos) // 3, "mesh sizes")
        zs = pos[2::3]  # the cylinder 0.75 m high translated by 0.001 m
        check(abs(min(zs) - 0.001) < 1e-6 and abs(max(zs) - 0.751) < 1e-6, "mesh transformed")
        paint = [m for m in sc["materials"] if m["name"] == "paint"][0]["spectra"]
        i = min(range(len(paint["freq_thz"])), key=lambda j: abs(paint["freq_thz"][j] - 0.7))
        f = paint["freq_thz"][i]  # R is a table (0.2, 0.05) .. (1.2, 0.12), linear
        check(abs(paint["R"][i] - (0.05 + 0.07 * (f - 0.2))) < 1e-6 and
              abs(paint["emissivity"][i] - (1 - paint["R"][i])) < 1e-9, "paint spectrum")
        cam = sc["sensors"][0]
        check(cam["rows"] == 12 and cam["columns"] == 16 and cam["fov_deg"] == 40, "sensor")
        check(cam["normalize_to_k"] == scene["sensors"][0]["normalize_to_k"],
              "sensor T_ref: %r" % cam)
        atm = sc["atmosphere"]
        d = atm["sensors"][0]["distance_m"]
        check(abs(atm["sensors"][0]["transmittance"][0] - math.exp(-0.05 * d)) < 1e-9 and
              atm["channels"][0]["alpha_per_m"] == 0.05, "atmosphere: %r" % atm)
        # the air emits at the enclosure's temperature (the room's 295 K), as validate says
        check(atm["emission_temperature_k"] == 295.0 and atm["background_temperature_k"] == 295.0,
              "the air's emission: %r" % atm)
        check_scene_answer(sc, scene)
    # spectra span the channels +- 20 %, at least 0.1-1.5 THz, on 200 frequencies; air
    # that does not emit has no emission or background temperature (null)
    wide = json.loads(text)
    wide["channels"] = [{"name": "lo", "frequency_thz": 0.1, "relative_width": 0.01},
                        {"name": "hi", "frequency_thz": 2.0, "relative_width": 0.01}]
    wide["atmosphere"] = {"model": "none"}
    res = srv.json("POST", "/api/validate", body={"path": "s/scene.json", "text": json.dumps(wide)})
    f = res and res["scene"] and res["scene"]["materials"][0]["spectra"]["freq_thz"]
    check(f and len(f) == 200 and abs(f[0] - 0.08) < 1e-12 and abs(f[-1] - 2.4) < 1e-12,
          "spectra of channels at 0.1 and 2 THz: %r" % ((f and (len(f), f[0], f[-1])),))
    atm = res and res["scene"] and res["scene"]["atmosphere"]
    check(atm and atm["emission_temperature_k"] is None and atm["background_temperature_k"] is None,
          "air that does not emit: %r" % atm)
    # the meshes of an answer stop at 300 000 triangles (a cylinder of 1 000 000 segments, a
    # 1.7 KB body, made a 1 GB server and a 170 MB answer): later objects' are null
    big = json.loads(text)
    big["objects"][1]["shape"]["segments"] = 50000  # 200 000 triangles with the caps
    big["objects"].append(json.loads(json.dumps(big["objects"][1])))
    big["objects"][-1]["name"] = "target-2"
    res = srv.json("POST", "/api/validate", body={"path": "s/scene.json", "text": json.dumps(big)})
    objs = res and res["scene"] and {o["name"]: o for o in res["scene"]["objects"]}
    check(objs and objs["target"]["mesh"] and objs["target-2"]["mesh"] is None and
          objs["target-2"]["triangles"] == objs["target"]["triangles"] > 300000 // 2,
          "a scene of two large meshes: %r" % (objs and {n: (o["triangles"], o["mesh"] is None)
                                                          for n, o in objs.items()}))
    # a sensor outside the enclosure: valid, with the loader's warning
    away = json.loads(text)
    away["sensors"][0]["position_m"] = [0, -5, 0.4]
    res = srv.json("POST", "/api/validate", body={"path": "s/scene.json", "text": json.dumps(away)})
    check(res and res["ok"] and any("outside" in w for w in res["warnings"]),
          "a sensor outside the room: %r" % (res and res["warnings"]))
    bad = json.loads(text)
    bad["objects"][1]["temperature_k"] = -5
    res = srv.json("POST", "/api/validate", body={"path": "s/scene.json", "text": json.dumps(bad)})
    e = res and res["errors"] and res["errors"][0]
    check(res and not res["ok"] and e and e["json_path"] == "objects[1].temperature_k" and
          "-5" in e["message"], "validate error: %r" % res)
    res = srv.json("POST", "/api/validate", body={"path": None, "text": '{"format":\n  x}'})
    e = res and res["errors"] and res["errors"][0]
    check(e and e["line"] == 2 and e["column"] and e["json_path"] is None, "syntax error: %r" % e)
    # relative files resolve from the scene's directory: without it the table is missing
    res = srv.json("POST", "/api/validate", body={"path": None, "text": text})
    check(res and not res["ok"] and "sample.csv" in json.dumps(res["errors"]), "base_dir")


def check_scene_answer(sc, scene):
    """The objects and the sensor of /api/validate's answer against the scene file and
    their own meshes: bounding boxes, areas, temperatures, the sensor's axes, the
    distance to what it looks at, the settings."""
    for o, want in zip(sc["objects"], scene["objects"]):
        pos, idx = o["mesh"]["positions"], o["mesh"]["indices"]
        pts = [pos[3 * k:3 * k + 3] for k in range(len(pos) // 3)]
        lo = [min(p[a] for p in pts) for a in range(3)]
        hi = [max(p[a] for p in pts) for a in range(3)]
        area = 0.0
        for t in range(len(idx) // 3):
            a, b, c = (pts[idx[3 * t + v]] for v in range(3))
            u = [b[k] - a[k] for k in range(3)]
            w = [c[k] - a[k] for k in range(3)]
            n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
            area += 0.5 * math.sqrt(sum(x * x for x in n))
        check(all(abs(o["bbox_min_m"][a] - lo[a]) < 1e-6 and abs(o["bbox_max_m"][a] - hi[a]) < 1e-6
                  for a in range(3)) and abs(o["area_m2"] - area) <= 1e-6 * area and
              o["temperature_K"] == want["temperature_k"],
              "object %s: %r against its mesh's box %r %r, area %r, %r K" %
              (o["name"], {k: o[k] for k in ("bbox_min_m", "bbox_max_m", "area_m2", "temperature_K")},
               lo, hi, area, want["temperature_k"]))
    cam, want = sc["sensors"][0], scene["sensors"][0]
    check(cam["position_m"] == want["position_m"] and cam["direction"] == [0, 1, 0] and
          cam["up"] == want["up"] and cam["aperture_m2"] == want["aperture_m2"],
          "sensor axes: %r" % cam)
    # the distance: to the centre of the box around the objects but the room (which holds
    # the sensor)
    seen = [o for o in sc["objects"] if o["name"] != "room"]
    centre = [0.5 * (min(o["bbox_min_m"][a] for o in seen) + max(o["bbox_max_m"][a] for o in seen))
              for a in range(3)]
    d = math.dist(centre, want["position_m"])
    check(abs(sc["atmosphere"]["sensors"][0]["distance_m"] - d) < 1e-9,
          "distance to what the sensor sees: %r, expected %r" %
          (sc["atmosphere"]["sensors"][0]["distance_m"], d))
    check(sc["channels"][0]["relative_width"] == scene["channels"][0]["relative_width"] and
          sc["settings"]["seed"] == scene["photons"]["seed"] and
          sc["settings"]["photons_per_channel"] == scene["photons"]["per_channel"],
          "channel width and settings: %r %r" % (sc["channels"][0], sc["settings"]))


def test_materials(srv):
    lib = srv.json("GET", "/api/materials")
    check(lib and len(lib["materials"]) > 0, "material library")
    if lib and lib["materials"]:
        name = lib["materials"][0]["name"]
        m = srv.json("GET", "/api/materials/" + name)
        sp = m and m["spectra"]
        ok = sp and len(sp["freq_thz"]) == len(sp["n"]) and any(v is not None for v in sp["n"])
        check(ok, "material spectra of %s" % name)
    # one entry's spectra span its data's range, else its valid range, else 0.1-3 THz
    for e in lib["materials"] if lib else []:
        span = e["data_thz"] or e["valid_thz"] or [0.1, 3.0]
        f = srv.json("GET", "/api/materials/" + e["name"])["spectra"]["freq_thz"]
        check(len(f) == 200 and abs(f[0] - span[0]) < 1e-9 and abs(f[-1] - span[1]) < 1e-9,
              "spectra of %s over %r: %r to %r" % (e["name"], span, f[0], f[-1]))
    # an unknown name: what is known, and not where the server's data lie (the message
    # began with the library file's absolute path)
    e = srv.json("GET", "/api/materials/no-such-material", status=404) or {}
    msg = e.get("error", "")
    check(msg.startswith('no material "no-such-material"') and "known: " in msg and
          all(m["name"] in msg for m in (lib["materials"] if lib else [])) and
          "/" not in msg and "library.json" not in msg,
          "unknown material's message: %r" % msg)


def sse_events(srv, run_id):
    conn = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=60)
    conn.request("GET", "/api/runs/%d/events" % run_id,
                 headers={"Authorization": "Bearer " + srv.token})
    resp = conn.getresponse()
    check(resp.status == 200 and resp.getheader("Content-Type") == "text/event-stream", "SSE")
    events, name = [], None
    for raw in resp:
        line = raw.decode().rstrip("\n")
        if line.startswith("event: "):
            name = line[7:]
        elif line.startswith("data: "):
            events.append((name, json.loads(line[6:])))
            if name == "end":
                break
    conn.close()
    return events


def test_runs(srv, root):
    run = srv.json("POST", "/api/runs", body={
        "command": "simulate", "scene": "s/scene.json", "out": "out/a",
        "options": {"seed": 1, "save_photon_map": True, "threads": 2}}, status=202)
    events = sse_events(srv, run["id"])
    progress = [d for n, d in events if n == "progress"]
    check(events and events[-1][0] == "end" and progress and progress[-1]["state"] == "done",
          "SSE to completion: %r" % events[-3:])
    fractions = [d["progress"] for d in progress]
    check(fractions == sorted(fractions) and fractions[-1] == 1.0, "progress: %r" % fractions)
    # each count with its unit, and the output without a stale channel ("output 0/1")
    counts = [d["message"] for d in progress if d["message"].startswith("channel ")]
    check(counts and all(re.search(r"(photons [0-9]+/[0-9]+| [0-9]+/[0-9]+ rows)$", m) for m in counts),
          "progress counts without their unit: %r" % counts[-3:])
    check(not any("output" in d["message"] for d in progress),
          "output progress in a channel's terms: %r" % [d["message"] for d in progress][-3:])
    run_b = srv.json("POST", "/api/runs", body={
        "command": "simulate", "scene": "s/scene.json", "out": "out/b",
        "options": {"seed": 2, "integrator": "photon-map", "save_photon_map": True}},
        status=202)
    render = srv.json("POST", "/api/runs", body={
        "command": "render", "scene": "s/scene.json", "out": "out/r",
        "options": {"photon_map": "out/a/photon-map.thzpm", "sensor": "cam"}}, status=202)
    # a render queued behind the simulate that writes its map (not there yet: it was 404),
    # and one from a map no queued run writes
    check(not os.path.exists(os.path.join(root, "out", "b", "photon-map.thzpm")),
          "test set-up: run b's map exists before its run")
    render_b = srv.json("POST", "/api/runs", body={
        "command": "render", "scene": "s/scene.json", "out": "out/rb",
        "options": {"photon_map": "out/b/photon-map.thzpm"}}, status=202)
    srv.json("POST", "/api/runs", body={
        "command": "render", "scene": "s/scene.json", "out": "out/rc",
        "options": {"photon_map": "out/c/photon-map.thzpm"}}, status=404)
    job = wait_state(srv, render["id"], ("done", "failed"))
    check(job and job["state"] == "done", "render: %r" % job)
    check(wait_state(srv, run_b["id"], ("done",)) is not None, "second run")
    summary_b = json.load(open(os.path.join(root, "out", "b", "summary.json")))
    check(summary_b["seed"] == 2, "run b's seed option: summary seed %r" % summary_b["seed"])
    job = wait_state(srv, render_b["id"], ("done", "failed"))
    check(job and job["state"] == "done", "render queued behind its map's run: %r" % job)
    # batch (two still frames, no movies) and bands (3 candidates, choose 1)
    with open(os.path.join(root, "s", "seq.json"), "w") as f:
        json.dump({"format": "thzmap-sequence/1", "scene": "scene.json", "frames": 2}, f)
    batch = srv.json("POST", "/api/runs", body={
        "command": "batch", "scene": "s/seq.json", "out": "out/batch",
        "options": {"no_movies": True}}, status=202)
    bands = srv.json("POST", "/api/runs", body={
        "command": "bands", "scene": "s/scene.json", "out": "out/bands",
        "options": {"count": 1, "from_thz": 0.3, "to_thz": 0.4, "step_ghz": 50, "netd_k": 0.7,
                    "targets": ["target"], "seed": 3}}, status=202)
    # the batch's progress is the batch's (its frames and share), not its runs' channels
    # with a share frozen at 0 (the runs' reports once took every turn)
    running = [d for n, d in sse_events(srv, batch["id"])
               if n == "progress" and d["state"] == "running"]
    check(not running or any(d["message"].startswith("frame ") for d in running),
          "batch progress never names a frame: %r" % running[-3:])
    check(all(not d["message"].startswith("channel ") for d in running),
          "batch progress in a run's terms: %r" % running[-3:])
    job = wait_state(srv, batch["id"], ("done", "failed"))
    check(job and job["state"] == "done" and job["progress"] == 1.0, "batch: %r" % job)
    res = srv.json("GET", "/api/outputs?dir=out/batch")
    check(res and res["frames"] == ["frame-00000", "frame-00001"], "batch frames: %r" % res)
    movies = [n for _, _, names in os.walk(os.path.join(root, "out", "batch")) for n in names
              if n.endswith(".mp4")]
    check(not movies, "a batch with no_movies made %r" % movies)
    # the sequence made one frame shorter, run into the same directory: frame-00001 stays
    # on disk (scene-format.md), but the batch's frames are the one its batch.json lists
    with open(os.path.join(root, "s", "seq1.json"), "w") as f:
        json.dump({"format": "thzmap-sequence/1", "scene": "scene.json", "frames": 1}, f)
    shorter = srv.json("POST", "/api/runs", body={
        "command": "batch", "scene": "s/seq1.json", "out": "out/batch",
        "options": {"no_movies": True}}, status=202)
    job = wait_state(srv, shorter["id"], ("done", "failed"))
    check(job and job["state"] == "done", "shorter batch: %r" % job)
    res = srv.json("GET", "/api/outputs?dir=out/batch")
    check(os.path.isdir(os.path.join(root, "out", "batch", "frame-00001")) and res
          and res["frames"] == ["frame-00000"], "a shorter batch's frames: %r" % res)
    job = wait_state(srv, bands["id"], ("done", "failed"))
    check(job and job["state"] == "done" and job["progress"] == 1.0, "bands: %r" % job)
    chosen = json.load(open(os.path.join(root, "out", "bands", "bands.json")))["selected_thz"]
    check(len(chosen) == 1 and chosen[0] in (0.3, 0.35, 0.4), "bands chose %r" % chosen)
    # its NETD and its targets (the other objects seen: one class, background)
    done = json.load(open(os.path.join(root, "out", "bands", "bands.json")))
    check(done["noise"]["netd_k"] == [0.7] * 3 and
          sorted(c["name"] for c in done["classes"]) == ["background", "target"],
          "bands' noise and classes: %r %r" % (done["noise"], [c["name"] for c in done["classes"]]))
    # and its seed: `thzmap bands` with the same options gives the same classes and score
    subprocess.run([BINARY, "bands", "s/scene.json", "-o", "cli-bands", "-q", "--count", "1",
                    "--from-thz", "0.3", "--to-thz", "0.4", "--step-ghz", "50", "--netd-k", "0.7",
                    "--targets", "target", "--seed", "3"], cwd=root, check=True)
    cli = json.load(open(os.path.join(root, "cli-bands", "bands.json")))
    check(cli["classes"] == done["classes"] and cli["score"] == done["score"],
          "bands of the server and of the CLI differ: score %r, %r" % (done["score"], cli["score"]))
    listing = srv.json("GET", "/api/runs")
    check(listing and [j["id"] for j in listing][:6] == [run["id"], run_b["id"], render["id"],
                                                          render_b["id"], batch["id"],
                                                          bands["id"]],
          "runs list")
    srv.json("GET", "/api/runs/999", status=404)
    # photons (reported every 65536), then a render of 600 rows: the progress never goes
    # back (the photons' share was once the channel's whole share, the render's half after)
    tall = json.load(open(os.path.join(root, "s", "scene.json")))
    tall["channels"] = tall["channels"][:1]
    tall["sensors"][0]["resolution"] = [64, 600]
    with open(os.path.join(root, "s", "tall.json"), "w") as f:
        json.dump(tall, f)
    run_t = srv.json("POST", "/api/runs", body={
        "command": "simulate", "scene": "s/tall.json", "out": "out/tall",
        "options": {"photons": 300000}}, status=202)
    progress = [d for n, d in sse_events(srv, run_t["id"]) if n == "progress"]
    fractions = [d["progress"] for d in progress]
    check(len(fractions) >= 3 and fractions == sorted(fractions) and
          progress[-1]["state"] == "done", "progress of a run: %r" % fractions)
    srv.json("DELETE", "/api/runs/%d" % run["id"], status=409)
    # a finished job: no error (null), and its time stays what the run took
    first = srv.json("GET", "/api/runs/%d" % run["id"])
    time.sleep(0.3)
    again = srv.json("GET", "/api/runs/%d" % run["id"])
    check(first and again and first["error"] is None and
          0 < first["seconds"] == again["seconds"], "a done job: %r, then %r" % (first, again))
    # cancel: a long run while it runs, and one still queued behind it
    long_run = srv.json("POST", "/api/runs", body={
        "command": "simulate", "scene": "s/scene.json", "out": "out/long",
        "options": {"photons": 300000000}}, status=202)
    queued = srv.json("POST", "/api/runs", body={
        "command": "simulate", "scene": "s/scene.json", "out": "out/q"}, status=202)
    wait_state(srv, long_run["id"], ("running",))
    # nor from a map that a queued simulate saves nowhere, or saves into a directory whose
    # name only begins with the map's: 404 (docs/gui.md: "unless a simulate ... with
    # save_photon_map writes it")
    no_map = srv.json("POST", "/api/runs", body={
        "command": "simulate", "scene": "s/scene.json", "out": "out/nm"}, status=202)
    longer = srv.json("POST", "/api/runs", body={
        "command": "simulate", "scene": "s/scene.json", "out": "out/nmx",
        "options": {"save_photon_map": True}}, status=202)
    for d in ("nm", "n"):
        st, _, data = srv.request("POST", "/api/runs", body=json.dumps({
            "command": "render", "scene": "s/scene.json", "out": "out/rnm",
            "options": {"photon_map": "out/%s/photon-map.thzpm" % d}}))
        check(st == 404, "render of out/%s's map, which no queued run saves: %d %r"
              % (d, st, data[:200]))
    for queued_run in (no_map, longer):
        srv.request("DELETE", "/api/runs/%d" % queued_run["id"])
    # at most 64 jobs wait or run (long_run and queued, and 62 more): the next is a 409
    extra = []
    for _ in range(63):
        st, _, data = srv.request("POST", "/api/runs", body=json.dumps(
            {"command": "simulate", "scene": "s/scene.json", "out": "out/q64"}))
        if st == 202:
            extra.append(json.loads(data)["id"])
    check(len(extra) == 62 and st == 409 and b"64 jobs" in data,
          "64 jobs and one more: %d accepted, then %d %r" % (len(extra), st, data[:200]))
    for i in extra:
        srv.request("DELETE", "/api/runs/%d" % i)
    job = srv.json("DELETE", "/api/runs/%d" % queued["id"])
    check(job and job["state"] == "cancelled", "cancel queued: %r" % job)
    # cancelled is finished: cancelling it again is a 409, as for a done job
    srv.json("DELETE", "/api/runs/%d" % queued["id"], status=409)
    srv.json("DELETE", "/api/runs/%d" % long_run["id"])
    t0 = time.time()
    job = wait_state(srv, long_run["id"], ("cancelled", "done", "failed"))
    check(job and job["state"] == "cancelled", "cancel running: %r" % job)
    print("cancel took %.2f s" % (time.time() - t0))
    check(not os.path.exists(os.path.join(root, "out", "long")) and
          not os.path.exists(os.path.join(root, "out", "q")), "a cancelled run left output")
    check(sorted(os.listdir(os.path.join(root, "out"))) == ["a", "b", "bands", "batch", "r", "rb",
                                                               "tall"],
          "out/ holds %r" % os.listdir(os.path.join(root, "out")))


def test_results(srv, root):
    out = os.path.join(root, "out", "a")
    res = srv.json("GET", "/api/outputs?dir=out/a")
    cam = res and [s for s in res["sensors"] if s["name"] == "cam"]
    check(cam and "brightness_temperature" in cam[0]["cubes"] and
          "cam.visual.png" in cam[0]["images"] and res["photon_map"] == "out/a/photon-map.thzpm"
          and res["summary"]["seed"] == 1, "outputs: %r" % (res and res["sensors"]))
    st, h, data = srv.request("GET", "/api/file?path=out/a/cam.visual.png")
    check(st == 200 and h.get("Content-Type") == "image/png" and data[:4] == b"\x89PNG",
          "a PNG of the run: %d %r" % (st, h.get("Content-Type")))
    cube = srv.json("GET", "/api/cube?path=out/a/cam.brightness_temperature.hdr")
    check(cube and (cube["rows"], cube["columns"], cube["bands"]) == (12, 16, 2) and
          cube["centres_thz"] == [0.35, 0.6] and cube["units"] == "K" and
          cube["band_names"] == ["0.35 THz", "0.6 THz"], "cube: %r" % cube)
    raw, tb = read_img(os.path.join(out, "cam.brightness_temperature.img"))
    st, _, data = srv.request("GET", "/api/cube/data?path=out/a/cam.brightness_temperature.hdr")
    check(st == 200 and data == raw, "whole cube = the .img bytes")
    st, _, data = srv.request("GET",
                              "/api/cube/data?path=out/a/cam.brightness_temperature.hdr&band=1")
    check(st == 200 and data == raw[16 * 12 * 4:], "band 1 = the .img's second band")
    check(cube and f32([cube["min"][0], cube["max"][1]]) == [min(tb[:192]), max(tb[192:])],
          "cube min/max")
    srv.json("GET", "/api/cube/data?path=out/a/cam.brightness_temperature.hdr&band=2", status=400)
    # a file that is not an ENVI header: the request's fault (once a 500); none: 404
    err = srv.json("GET", "/api/cube?path=s/scene.json", status=400)
    check(err and "no such ENVI header" in err.get("error", ""), "cube of a scene: %r" % err)
    srv.json("GET", "/api/cube?path=out/a/none.hdr", status=404)
    _, rad = read_img(os.path.join(out, "cam.radiance.img"))
    _, se = read_img(os.path.join(out, "cam.radiance_stderr.img"))
    _, temp = read_img(os.path.join(out, "cam.temperature.img"))
    _, dist = read_img(os.path.join(out, "cam.distance.img"))
    _, oid = read_img(os.path.join(out, "cam.object_id.img"))
    names = ["room", "target", "cover"]
    t0 = time.time()
    for row, col in [(6, 8), (0, 0), (11, 15)]:
        p = srv.json("GET", "/api/pixel?dir=out/a&sensor=cam&row=%d&col=%d" % (row, col))
        i = row * 16 + col
        check(p and f32(p["tb_K"]) == [tb[i], tb[192 + i]] and
              f32(p["radiance"]) == [rad[i], rad[192 + i]] and p["channels_thz"] == [0.35, 0.6],
              "pixel (%d, %d) Tb: %r" % (row, col, p))
        if not p:
            continue
        for c, f in enumerate([0.35e12, 0.6e12]):
            l, s = rad[c * 192 + i], se[c * 192 + i]
            want = 0.5 * (planck_tb(f, l + s) - planck_tb(f, l - s))
            check(abs(p["tb_stderr_K"][c] - want) <= 1e-5 * max(want, 1e-3),
                  "pixel Tb standard error %r vs %r" % (p["tb_stderr_K"][c], want))
        t = p["truth"]
        check(t["object"] == names[int(oid[i])] and f32([t["temperature_K"]]) == [temp[i]] and
              f32([t["distance_m"]]) == [dist[i]], "pixel truth: %r" % t)
    print("3 pixel answers: %.1f ms each" % ((time.time() - t0) / 3 * 1e3))
    # outside the 16 x 12 image: the request's mistake, with the size (a 404 that also
    # blamed a missing cube); a sensor without a cube is the 404
    err = srv.json("GET", "/api/pixel?dir=out/a&sensor=cam&row=12&col=0", status=400)
    check(err and "row 12, col 0: outside the image of 16 x 12 pixels (row 0 to 11, col 0 to 15)"
          in err.get("error", ""), "pixel outside: %r" % err)
    srv.json("GET", "/api/pixel?dir=out/a&sensor=cam&row=0&col=-1", status=400)
    err = srv.json("GET", "/api/pixel?dir=out/a&sensor=nope&row=0&col=0", status=404)
    check(err and "no brightness temperature cube of sensor 'nope'" in err.get("error", ""),
          "pixel of no sensor: %r" % err)
    # A/B difference, in units of the combined standard error
    st, h, data = srv.request("GET", "/api/diff?a=out/a&b=out/b&sensor=cam&band=0")
    _, tb_b = read_img(os.path.join(root, "out", "b", "cam.brightness_temperature.img"))
    _, rad_b = read_img(os.path.join(root, "out", "b", "cam.radiance.img"))
    _, se_b = read_img(os.path.join(root, "out", "b", "cam.radiance_stderr.img"))
    diff = struct.unpack("<192f", data) if st == 200 and len(data) == 768 else None
    check(diff and h.get("X-Thzmap-Diff-Units") == "sigma", "diff: %d %r" % (st, h))
    for i in range(0, 192, 7) if diff else []:
        sa = 0.5 * (planck_tb(0.35e12, rad[i] + se[i]) - planck_tb(0.35e12, rad[i] - se[i]))
        sb = 0.5 * (planck_tb(0.35e12, rad_b[i] + se_b[i]) -
                    planck_tb(0.35e12, rad_b[i] - se_b[i]))
        if sa * sa + sb * sb > 0:
            want = (tb[i] - tb_b[i]) / math.sqrt(sa * sa + sb * sb)
            check(abs(diff[i] - want) <= 1e-3 * max(1, abs(want)),
                  "diff pixel %d: %r vs %r" % (i, diff[i], want))
    srv.json("GET", "/api/diff?a=out/a&b=out/b&sensor=nope&band=0", status=400)


def test_photons(srv, scene):
    info = srv.json("GET", "/api/photons/info?path=out/a/photon-map.thzpm")
    check(info and info["objects"] == ["room", "target", "cover"] and
          info["channels"][0]["photons"] > 0, "photons info: %r" % info)
    st, h, data = srv.request("GET", "/api/photons?path=out/a/photon-map.thzpm&channel=1"
                                     "&object=target&max=100")
    n, total = int(h.get("X-Thzmap-Photons", -1)), int(h.get("X-Thzmap-Photons-Total", -1))
    check(st == 200 and n == min(100, total) and total > 100 and len(data) == 32 * n,
          "photons: %d %r %d bytes" % (st, h, len(data)))
    recs = [struct.unpack_from("<8f", data, 32 * k) for k in range(len(data) // 32)]
    for x, y, z, dx, dy, dz, power, obj in recs:
        # the target is a cylinder of radius 0.1 m from z = 0.001 to 0.751 m
        ok = (obj == 1 and math.hypot(x, y) < 0.1 + 1e-4 and 0.001 - 1e-4 < z < 0.751 + 1e-4 and
              abs(dx * dx + dy * dy + dz * dz - 1) < 1e-3 and power > 0)
        if not ok:
            check(False, "photon record %r" % ((x, y, z, dx, dy, dz, power, obj),))
            break
    # the page's form: the same photons, positions then directions in signed bytes
    st, h, pts = srv.request("GET", "/api/photons?format=points&path=out/a/photon-map.thzpm"
                                    "&channel=1&object=target&max=100")
    check(st == 200 and len(pts) == 15 * n, "points: %d, %d bytes for %d" % (st, len(pts), n))
    for k, rec in enumerate(recs[:n] if len(pts) == 15 * n else []):
        pos = struct.unpack_from("<3f", pts, 12 * k)
        d = struct.unpack_from("<3b", pts, 12 * n + 3 * k)
        if pos != rec[:3] or any(abs(d[a] / 127 - rec[3 + a]) > 0.5 / 127 + 1e-6 for a in range(3)):
            check(False, "point %d: %r %r against record %r" % (k, pos, d, rec))
            break
    srv.json("GET", "/api/photons?format=xyz&path=out/a/photon-map.thzpm&channel=1", status=400)
    st, h, data = srv.request("GET", "/api/photons?path=out/a/photon-map.thzpm&channel=0")
    check(st == 200 and len(data) == 32 * info["channels"][0]["photons"], "all photons")
    srv.json("GET", "/api/photons?path=out/a/photon-map.thzpm&channel=5", status=404)
    srv.json("GET", "/api/photons?path=out/a/cam.radiance.img&channel=0&scene=s/scene.json",
             status=400)


def test_run_warnings(srv, root):
    """A job keeps the warnings `thzmap simulate|render` prints, in "warnings": an option
    its integrator does not use, the scene's (a sensor outside its room), the run's. Each
    passed as the message alone until the next report ("done; results in ..."), so a
    client polling the job saw none, and the scene's and the unused option's not even
    there."""
    scene = json.load(open(os.path.join(root, "s", "scene.json")))
    scene["sensors"][0]["position_m"] = [0, -50, 0.4]
    with open(os.path.join(root, "s", "outside.json"), "w") as f:
        json.dump(scene, f)
    run = srv.json("POST", "/api/runs", body={
        "command": "simulate", "scene": "s/outside.json", "out": "out/warned",
        "options": {"integrator": "path", "photons": 1000, "threads": 1}}, status=202)
    job = wait_state(srv, run["id"], ("done", "failed"))
    summary = json.load(open(os.path.join(root, "out", "warned", "summary.json")))
    w = job and job.get("warnings") or []
    check(job and job["state"] == "done" and len(w) >= 2 and
          w[0].startswith("options.photons 1000 is not used: the path integrator fires no") and
          "is outside the enclosure" in w[1] and w[1:] == summary["warnings"] and
          job["message"] == "done; results in out/warned (%d warnings)" % len(w),
          "a run's warnings: %r, summary %r" % (job, summary["warnings"]))
    run = srv.json("POST", "/api/runs", body={
        "command": "render", "scene": "s/scene.json", "out": "out/warned-r",
        "options": {"integrator": "path", "photon_map": "out/a/photon-map.thzpm"}}, status=202)
    job = wait_state(srv, run["id"], ("done", "failed"))
    check(job and job["state"] == "done" and job["warnings"] and
          job["warnings"][0].startswith("options.photon_map is not used: the path integrator"),
          "a path render given a photon map: %r" % job)
    listed = [j for j in srv.json("GET", "/api/runs") or [] if j["id"] == 1]
    check(listed and listed[0]["warnings"] == [] and listed[0]["message"] == "done; results in out/a",
          "a run without warnings: %r" % listed)


def test_sigterm(root, env):
    srv = Server(BINARY, root, env)
    before = sorted(os.listdir(os.path.join(root, "out")))
    run = srv.json("POST", "/api/runs", body={
        "command": "simulate", "scene": "s/scene.json", "out": "out/term",
        "options": {"photons": 300000000}}, status=202)
    queued = srv.json("POST", "/api/runs", body={
        "command": "simulate", "scene": "s/scene.json", "out": "out/term2"}, status=202)
    wait_state(srv, run["id"], ("running",))
    # a page following the run: its stream ends with the run's final state, not just "end";
    # and one following the job queued behind it, which is dropped (docs/gui.md)
    streamed, streamed_q = [], []
    follower = threading.Thread(target=lambda: streamed.extend(sse_events(srv, run["id"])))
    follower.start()
    follower_q = threading.Thread(target=lambda: streamed_q.extend(sse_events(srv, queued["id"])))
    follower_q.start()
    time.sleep(0.2)  # into the photon phase, its staging directory open
    t0 = time.time()
    rc = srv.stop(signal.SIGTERM)
    print("SIGTERM during a run: exit %s after %.2f s" % (rc, time.time() - t0))
    # ended by the signal itself, after its clean-up (subprocess: minus the signal)
    check(rc == -signal.SIGTERM, "SIGTERM: exit status %s, expected the signal's end" % rc)
    follower.join(timeout=30)
    states = [d.get("state") for n, d in streamed if n == "progress"]
    check(streamed and streamed[-1][0] == "end" and states and states[-1] == "cancelled",
          "the event stream at SIGTERM: %r" % streamed[-3:])
    follower_q.join(timeout=30)
    states = [d.get("state") for n, d in streamed_q if n == "progress"]
    check(streamed_q and streamed_q[-1][0] == "end" and states and states[-1] == "cancelled",
          "the queued job's event stream at SIGTERM: %r" % streamed_q[-3:])
    after = sorted(os.listdir(os.path.join(root, "out")))
    check(after == before and
          not os.path.exists(os.path.join(root, "out", "term")), "SIGTERM left output behind: %r -> %r" % (before, after))


def main():
    tmp = tempfile.mkdtemp(prefix="thzmap-serve-")
    root = os.path.join(tmp, "root")
    os.makedirs(root)
    try:
        scene = make_root(REPO, root)
        env = dict(os.environ, THZMAP_WEB_DIR=os.path.join(tmp, "web"))
        t0 = time.time()
        srv = Server(BINARY, root, env)
        try:
            tests = [("validate", lambda: test_validate(srv, scene)),
                     ("materials", lambda: test_materials(srv))]
            if not REQUESTS_ONLY:
                tests += [("runs", lambda: test_runs(srv, root)),
                          ("results", lambda: test_results(srv, root)),
                          ("photons", lambda: test_photons(srv, scene)),
                          ("warnings", lambda: test_run_warnings(srv, root))]
            for name, fn in tests:
                t = time.time()
                fn()
                print("%-10s %.2f s" % (name, time.time() - t), flush=True)
        finally:
            rc = srv.stop(signal.SIGINT)
            check(rc == -signal.SIGINT, "SIGINT: exit status %s, expected the signal's end" % rc)
        if not REQUESTS_ONLY:
            test_sigterm(root, env)
        print("total %.1f s" % (time.time() - t0))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    finish()


main()
