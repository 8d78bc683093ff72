#!/usr/bin/python3
"""The JSON API of `thzmap serve` (docs/gui.md), endpoint by endpoint, against a real
server on a free port over a temporary root: the token (401, 403, the cookie), paths
leaving the root (.., absolute, %2e%2e, symlinks), oversized and malformed bodies,
validation, runs (server-sent events, cancel, SIGTERM), and the post-processor's
answers compared with the ENVI files the run wrote.

usage: test_api.py THZMAP_BINARY REPO_DIR [--requests-only]

--requests-only: the endpoints that start no job (token, paths, limits, validation, the
files a scene names confined to the root, materials), which fork nothing: the sanitizer build runs those (CMakeLists.txt says why
it runs no jobs).
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

from serve_client import Server as Client, check, finish

BINARY, REPO = sys.argv[1], sys.argv[2]
REQUESTS_ONLY = sys.argv[3:] == ["--requests-only"]


def Server(root, env=None):
    return Client(BINARY, root, env)


def make_root(root):
    """A small scene: plate-in-box with 2 channels, 16 x 16 pixels, few photons."""
    src = os.path.join(REPO, "examples", "plate-in-box")
    shutil.copytree(os.path.join(src, "materials"), os.path.join(root, "s", "materials"))
    scene = json.load(open(os.path.join(src, "scene.json")))
    scene["channels"].append({"name": "0.6 THz", "frequency_thz": 0.6, "relative_width": 0.01})
    scene["sensors"][0]["resolution"] = [16, 12]
    scene["sensors"][0]["oversampling"] = 1
    scene["photons"]["per_channel"] = 4000
    scene.setdefault("render", {})["integrator"] = "photon-map"
    with open(os.path.join(root, "s", "scene.json"), "w") as f:
        json.dump(scene, f, indent=1)
    os.symlink("/etc", os.path.join(root, "etc-link"))
    # a sibling of the root whose name begins with the root's: outside it all the same
    os.makedirs(root + "-sibling")
    open(os.path.join(root + "-sibling", "secret.json"), "w").write("{}")
    os.symlink(root + "-sibling", os.path.join(root, "sibling-link"))
    web = os.path.join(root, "..", "web")
    os.makedirs(os.path.join(web, "assets"))
    open(os.path.join(web, "index.html"), "w").write("<!doctype html><title>t</title>")
    open(os.path.join(web, "assets", "app.js"), "w").write("console.log(1)")
    open(os.path.join(root, "..", "secret.json"), "w").write("{}")
    return scene


def read_img(path):
    data = open(path, "rb").read()
    return data, struct.unpack("<%df" % (len(data) // 4), data)


def f32(values):
    """JSON numbers (9 significant digits) as the float32 values they stand for."""
    return [struct.unpack("<f", struct.pack("<f", v))[0] for v in values]


def planck_tb(freq_hz, radiance):
    h, k, c = 6.62607015e-34, 1.380649e-23, 299792458.0
    return h * freq_hz / k / math.log1p(2 * h * freq_hz ** 3 / (c * c * radiance))


def wait_state(srv, run_id, states, limit_s=240):
    t0 = time.time()
    while time.time() - t0 < limit_s:
        job = srv.json("GET", "/api/runs/%d" % run_id)
        if job and job["state"] in states:
            return job
        time.sleep(0.05)
    check(False, "run %d never reached %s" % (run_id, states))
    return None


def test_auth(srv):
    st, _, _ = srv.request("GET", "/api/info", auth=False)
    check(st == 401, "no token: %d, expected 401" % st)
    st, _, _ = srv.request("GET", "/api/info", auth=False,
                           headers={"Authorization": "Bearer " + "0" * 32})
    check(st == 403, "wrong bearer token: %d, expected 403" % st)
    st, _, _ = srv.request("GET", "/api/info", auth=False,
                           headers={"Cookie": "thzmap_token=" + "1" * 32})
    check(st == 403, "wrong cookie: %d, expected 403" % st)
    st, _, _ = srv.request("GET", "/api/info", auth=False,
                           headers={"Authorization": "Bearer " + srv.token + "0"})
    check(st == 403, "the token with a character more: %d, expected 403" % st)
    st, _, _ = srv.request("GET", "/?token=" + "2" * 32, auth=False)
    check(st == 403, "login with a wrong token: %d, expected 403" % st)
    st, h, _ = srv.request("GET", "/?token=" + srv.token, auth=False)
    cookie = h.get("Set-Cookie", "")
    check(st == 303 and h.get("Location") == "/", "login: %d %s" % (st, h))
    check("thzmap_token=" + srv.token in cookie and "HttpOnly" in cookie and
          "SameSite=Strict" in cookie, "login cookie: %r" % cookie)
    st, _, data = srv.request("GET", "/api/info", auth=False,
                              headers={"Cookie": "thzmap_token=" + srv.token})
    check(st == 200 and json.loads(data)["version"], "cookie accepted: %d" % st)
    st, h, data = srv.request("GET", "/")
    check(st == 200 and b"<title>t</title>" in data, "index.html: %d %r" % (st, data[:80]))
    st, h, data = srv.request("GET", "/assets/app.js")
    check(st == 200 and data == b"console.log(1)" and "javascript" in h["Content-Type"],
          "assets: %d %r" % (st, data))
    info = srv.json("GET", "/api/info")
    check(info and "photon-map" in info["integrators"] and "simulate" in info["commands"],
          "info: %r" % info)
    srv.json("GET", "/api/nothing", status=404)
    srv.json("DELETE", "/api/info", status=405)


def test_paths(srv, root):
    for path in ["/api/file?path=../secret.json", "/api/file?path=/etc/passwd",
                 "/api/file?path=%2e%2e/secret.json", "/api/file?path=s/%2E%2E/%2e%2e/secret.json",
                 "/api/file?path=etc-link/passwd", "/api/files?dir=etc-link",
                 "/api/files?dir=..", "/api/files?dir=/", "/api/cube?path=../x.hdr",
                 "/api/outputs?dir=etc-link", "/api/pixel?dir=..&sensor=cam&row=0&col=0",
                 "/api/file?path=sibling-link/secret.json", "/api/files?dir=sibling-link"]:
        st, _, data = srv.request("GET", path)
        check(st == 403 and "error" in json.loads(data), "%s: %d, expected 403" % (path, st))
    for path in ["/assets/../../secret.json", "/assets/%2e%2e/%2e%2e/secret.json",
                 "/assets/%2e%2e/index.html"]:
        st, _, data = srv.request("GET", path)
        check(st in (403, 404), "%s: %d, expected 403 or 404" % (path, st))
    for path in ["/api/file?path=etc-link/x.json", "/api/file?path=../x.json",
                 "/api/file?path=s/x.txt"]:
        st, _, _ = srv.request("PUT", path, body=b"{}")
        check(st == 403, "PUT %s: %d, expected 403" % (path, st))
    check(not os.path.exists(os.path.join(root, "..", "x.json")), "a PUT escaped the root")
    # a .json name that is a directory is not written over
    os.makedirs(os.path.join(root, "s", "dir.json"))
    st, _, data = srv.request("PUT", "/api/file?path=s/dir.json", body=b"{}")
    check(st == 403 and b"not a regular file" in data, "PUT onto a directory: %d %r" % (st, data))
    os.rmdir(os.path.join(root, "s", "dir.json"))
    # a dangling symbolic link: where it points is unknown, so it is outside (a PUT through
    # it would create a file wherever it points; without the refusal a GET was a 404)
    target = os.path.join(root, "..", "nowhere", "x.json")
    os.symlink(target, os.path.join(root, "s", "dangle.json"))
    st, _, _ = srv.request("GET", "/api/file?path=s/dangle.json")
    check(st == 403, "GET through a dangling link: %d, expected 403" % st)
    os.makedirs(os.path.dirname(target))
    st, _, _ = srv.request("PUT", "/api/file?path=s/dangle.json", body=b"{}")
    check(st == 403 and not os.path.exists(target),
          "PUT through a dangling link: %d, expected 403, nothing written" % st)
    os.rmdir(os.path.dirname(target))
    os.unlink(os.path.join(root, "s", "dangle.json"))
    # the file endpoints inside the root
    listing = srv.json("GET", "/api/files?dir=s")
    names = {e["name"]: e for e in listing["entries"]} if listing else {}
    check(names.get("scene.json", {}).get("type") == "file" and
          names.get("materials", {}).get("type") == "dir", "files: %r" % listing)
    # an empty directory, and one with nothing listable (a FIFO): no entries (the
    # listing once sorted a NULL array, which the sanitizer build's server died of)
    os.mkdir(os.path.join(root, "empty"))
    os.mkdir(os.path.join(root, "pipes"))
    os.mkfifo(os.path.join(root, "pipes", "fifo"))
    for d in ("empty", "pipes"):
        listing = srv.json("GET", "/api/files?dir=" + d)
        check(listing is not None and listing["entries"] == [], "files of %s: %r" % (d, listing))
    root_list = srv.json("GET", "/api/files")
    check(root_list and "etc-link" not in [e["name"] for e in root_list["entries"]],
          "a symlink out of the root is listed")
    st, _, data = srv.request("GET", "/api/file?path=s/scene.json")
    check(st == 200 and data == open(os.path.join(root, "s", "scene.json"), "rb").read(),
          "GET file: %d" % st)
    # files of the root never run as pages: HTML goes as bytes, sandboxed
    open(os.path.join(root, "s", "page.html"), "w").write("<script>alert(1)</script>")
    st, h, _ = srv.request("GET", "/api/file?path=s/page.html")
    check(st == 200 and h.get("Content-Type") == "application/octet-stream" and
          "sandbox" in h.get("Content-Security-Policy", ""), "HTML from the root: %r" % h)
    os.unlink(os.path.join(root, "s", "page.html"))
    text = b'{"edited": true}\n'
    res = srv.json("PUT", "/api/file?path=s/new.json", body=text)
    check(res and res["size"] == len(text) and
          open(os.path.join(root, "s", "new.json"), "rb").read() == text, "PUT file: %r" % res)
    check(sorted(os.listdir(os.path.join(root, "s"))) == ["materials", "new.json", "scene.json"],
          "PUT left files behind: %r" % os.listdir(os.path.join(root, "s")))
    # a new file gets 0666 less the umask (the server's is the test's); a private file
    # saved again stays private (it came back 0644, readable by every user)
    mask = os.umask(0)
    os.umask(mask)
    mode = os.stat(os.path.join(root, "s", "new.json")).st_mode & 0o7777
    check(mode == 0o666 & ~mask, "PUT new file: mode %o, umask %o" % (mode, mask))
    os.chmod(os.path.join(root, "s", "new.json"), 0o600)
    srv.json("PUT", "/api/file?path=s/new.json", body=text)
    mode = os.stat(os.path.join(root, "s", "new.json")).st_mode & 0o7777
    check(mode == 0o600, "PUT over a private file: mode %o, not 600" % mode)
    srv.json("GET", "/api/file?path=s/none.json", status=404)


def test_limits(srv):
    # a declared length above 4 MiB is refused before the body is read
    import socket
    sock = socket.create_connection(("127.0.0.1", srv.port), timeout=30)
    sock.sendall(("POST /api/validate HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer %s\r\n"
                  "Content-Length: %d\r\n\r\n" % (srv.token, 5 << 20)).encode())
    answer = sock.recv(4096).decode(errors="replace")
    sock.close()
    check(answer.startswith("HTTP/1.1 413"), "declared 5 MiB body: %r" % answer[:40])
    # and so is a chunked body that grows past it
    conn = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=60)
    conn.request("POST", "/api/validate", body=(b"x" * (1 << 20) for _ in range(5)),
                 headers={"Authorization": "Bearer " + srv.token}, encode_chunked=True)
    st = conn.getresponse().status
    conn.close()
    check(st == 413, "chunked 5 MiB body: %d, expected 413" % st)
    err = srv.json("POST", "/api/validate", body="{bad", status=400)
    check(err and err.get("path") == "$" and "line 1" in err["error"], "malformed: %r" % err)
    err = srv.json("POST", "/api/validate", body={"text": 3}, status=400)
    check(err and err.get("path") == "$.text", "text not a string: %r" % err)
    err = srv.json("POST", "/api/runs", body={"command": "simulate", "scene": "s/scene.json",
                                               "out": "o", "options": {"integrator": "path",
                                                                       "save_photon_map": True}},
                   status=400)
    check(err and err.get("path") == "$.options.save_photon_map", "path with a map: %r" % err)
    err = srv.json("POST", "/api/runs", body={"command": 3}, status=400)
    check(err and err.get("path") == "$.command", "bad command: %r" % err)
    err = srv.json("POST", "/api/runs", body={"command": "simulate", "scene": "s/scene.json",
                                               "out": "o", "options": {"photons": "many"}},
                   status=400)
    check(err and err.get("path") == "$.options.photons", "bad option: %r" % err)
    err = srv.json("POST", "/api/runs", body={"command": "simulate", "scene": "s/scene.json",
                                               "out": "o", "options": {"sensor": "cam"}},
                   status=400)
    check(err and err.get("path") == "$.options.sensor", "option of another command: %r" % err)
    err = srv.json("POST", "/api/runs", body={"command": "bands", "scene": "s/scene.json",
                                               "out": "o"}, status=400)
    check(err and err.get("path") == "$.options.count", "bands without count: %r" % err)
    # the library's limit, 32 (the server took up to 64, and the job failed after its 202)
    err = srv.json("POST", "/api/runs", body={"command": "bands", "scene": "s/scene.json",
                                               "out": "o", "options": {"count": 33}}, status=400)
    check(err and err.get("path") == "$.options.count" and "1 to 32" in err.get("error", ""),
          "bands count 33: %r" % err)
    srv.json("POST", "/api/runs", body={"command": "simulate", "scene": "../secret.json",
                                         "out": "o"}, status=403)
    srv.json("POST", "/api/runs", body={"command": "simulate", "scene": "s/scene.json",
                                         "out": "etc-link/o"}, status=403)


def test_validate(srv, scene):
    text = json.dumps(scene)
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
        atm = sc["atmosphere"]
        d = atm["sensors"][0]["distance_m"]
        check(abs(atm["sensors"][0]["transmittance"][0] - math.exp(-0.05 * d)) < 1e-9 and
              atm["channels"][0]["alpha_per_m"] == 0.05, "atmosphere: %r" % atm)
        # the air emits at the enclosure's temperature (the room's 295 K), as validate says
        check(atm["emission_temperature_k"] == 295.0 and atm["background_temperature_k"] == 295.0,
              "the air's emission: %r" % atm)
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


MARKER = "OUTSIDE-MARKER-%d" % os.getpid()


def write_outside(root):
    """A table outside the root, its first line a marker no answer may contain, and a
    symlink to it from inside; the scene files of the refused runs."""
    outside = os.path.join(os.path.dirname(root), "outside.csv")
    with open(outside, "w") as f:
        f.write(MARKER + "\nfrequency_thz,reflectivity\n0.1,0.1\n2.0,0.2\n")
    link = os.path.join(root, "s", "materials", "link.csv")
    if not os.path.lexists(link):
        os.symlink(outside, link)
    return outside


def test_confined(srv, root, scene):
    """The files a scene names are confined to the root: a table named by '..', by an
    absolute path or through a symlink is refused at its key, and nothing of it shows."""
    outside = write_outside(root)
    for name, why in (("../../outside.csv", "is outside the served root"),
                      (outside, "is an absolute path"),
                      ("materials/link.csv", "is outside the served root"),
                      ("materials/missing.csv", "does not exist under the served root")):
        bad = json.loads(json.dumps(scene))
        bad["materials"]["table"]["file"] = name
        st, _, data = srv.request("POST", "/api/validate",
                                  json.dumps({"path": "s/scene.json", "text": json.dumps(bad)}))
        res = json.loads(data) if st == 200 else None
        e = res and res["errors"] and res["errors"][0]
        check(e and not res["ok"] and e["json_path"] == "materials.table.file" and
              why in e["message"] and name in e["message"], "validate %s: %r" % (name, res))
        check(MARKER.encode() not in data and b"frequency_thz" not in data,
              "validate %s: the answer quotes the file: %r" % (name, data[:300]))
    # the scene's own path outside the root: 403 naming it (the message was once made
    # from the request after it was freed: a 500 "out of memory", or ASan's abort)
    for name in ("../x.json", "/etc/x.json", "s/../../x.json"):
        err = srv.json("POST", "/api/validate", body={"path": name, "text": "{}"}, status=403)
        check(err and name in err.get("error", ""), "validate at %s: %r" % (name, err))
    # the same scene text naming the table inside validates
    res = srv.json("POST", "/api/validate",
                   body={"path": "s/scene.json", "text": json.dumps(scene)})
    check(res and res["ok"], "validate inside: %r" % (res and res["errors"]))


def test_runs_confined(srv, root, scene):
    """Runs of a scene or sequence naming a file outside the root fail before writing."""
    write_outside(root)
    bad = json.loads(json.dumps(scene))
    bad["materials"]["table"]["file"] = "../../outside.csv"
    with open(os.path.join(root, "s", "outside-scene.json"), "w") as f:
        json.dump(bad, f)
    with open(os.path.join(root, "s", "outside-seq.json"), "w") as f:
        json.dump({"format": "thzmap-sequence/1", "scene": "../../outside.csv"}, f)
    runs = [srv.json("POST", "/api/runs", body={
        "command": command, "scene": "s/" + file, "out": "out/refused-" + command,
        "options": options}, status=202)
        for command, file, options in (("simulate", "outside-scene.json", {}),
                                       ("batch", "outside-seq.json", {"no_movies": True}),
                                       ("bands", "outside-scene.json", {"count": 1}))]
    for run in runs:
        job = run and wait_state(srv, run["id"], ("done", "failed"))
        check(job and job["state"] == "failed" and
              "is outside the served root" in (job["error"] or "") and
              MARKER not in json.dumps(job), "refused run: %r" % job)
        check(not os.path.exists(os.path.join(root, "out", "refused-" + job["command"])),
              "a refused run wrote %s" % job["command"])


def test_materials(srv):
    lib = srv.json("GET", "/api/materials")
    check(lib and len(lib["materials"]) > 0, "material library")
    if lib and lib["materials"]:
        name = lib["materials"][0]["name"]
        m = srv.json("GET", "/api/materials/" + name)
        sp = m and m["spectra"]
        ok = sp and len(sp["freq_thz"]) == len(sp["n"]) and any(v is not None for v in sp["n"])
        check(ok, "material spectra of %s" % name)
    srv.json("GET", "/api/materials/no-such-material", status=404)


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
        "options": {"count": 1, "from_thz": 0.3, "to_thz": 0.4, "step_ghz": 50,
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
    check(job and job["state"] == "done", "bands: %r" % job)
    chosen = json.load(open(os.path.join(root, "out", "bands", "bands.json")))["selected_thz"]
    check(len(chosen) == 1 and chosen[0] in (0.3, 0.35, 0.4), "bands chose %r" % chosen)
    listing = srv.json("GET", "/api/runs")
    check(listing and [j["id"] for j in listing][:6] == [run["id"], run_b["id"], render["id"],
                                                          render_b["id"], batch["id"],
                                                          bands["id"]],
          "runs list")
    srv.json("GET", "/api/runs/999", status=404)
    srv.json("DELETE", "/api/runs/%d" % run["id"], status=409)
    # cancel: a long run while it runs, and one still queued behind it
    long_run = srv.json("POST", "/api/runs", body={
        "command": "simulate", "scene": "s/scene.json", "out": "out/long",
        "options": {"photons": 300000000}}, status=202)
    queued = srv.json("POST", "/api/runs", body={
        "command": "simulate", "scene": "s/scene.json", "out": "out/q"}, status=202)
    wait_state(srv, long_run["id"], ("running",))
    job = srv.json("DELETE", "/api/runs/%d" % queued["id"])
    check(job and job["state"] == "cancelled", "cancel queued: %r" % job)
    srv.json("DELETE", "/api/runs/%d" % long_run["id"])
    t0 = time.time()
    job = wait_state(srv, long_run["id"], ("cancelled", "done", "failed"))
    check(job and job["state"] == "cancelled", "cancel running: %r" % job)
    print("cancel took %.2f s" % (time.time() - t0))
    check(not os.path.exists(os.path.join(root, "out", "long")) and
          not os.path.exists(os.path.join(root, "out", "q")), "a cancelled run left output")
    test_runs_confined(srv, root, json.load(open(os.path.join(root, "s", "scene.json"))))
    check(sorted(os.listdir(os.path.join(root, "out"))) == ["a", "b", "bands", "batch", "r", "rb"],
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


def test_sigterm(root, env):
    srv = Server(root, env)
    before = sorted(os.listdir(os.path.join(root, "out")))
    run = srv.json("POST", "/api/runs", body={
        "command": "simulate", "scene": "s/scene.json", "out": "out/term",
        "options": {"photons": 300000000}}, status=202)
    wait_state(srv, run["id"], ("running",))
    # a page following the run: its stream ends with the run's final state, not just "end"
    streamed = []
    follower = threading.Thread(target=lambda: streamed.extend(sse_events(srv, run["id"])))
    follower.start()
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
    after = sorted(os.listdir(os.path.join(root, "out")))
    check(after == before and
          not os.path.exists(os.path.join(root, "out", "term")), "SIGTERM left output behind: %r -> %r" % (before, after))


def main():
    tmp = tempfile.mkdtemp(prefix="thzmap-serve-")
    root = os.path.join(tmp, "root")
    os.makedirs(root)
    try:
        scene = make_root(root)
        env = dict(os.environ, THZMAP_WEB_DIR=os.path.join(tmp, "web"))
        t0 = time.time()
        srv = Server(root, env)
        try:
            for name, fn in [("auth", lambda: test_auth(srv)),
                             ("paths", lambda: test_paths(srv, root)),
                             ("limits", lambda: test_limits(srv)),
                             ("validate", lambda: test_validate(srv, scene)),
                             ("confined", lambda: test_confined(srv, root, scene)),
                             ("materials", lambda: test_materials(srv)),
                             ("runs", lambda: test_runs(srv, root)),
                             ("results", lambda: test_results(srv, root)),
                             ("photons", lambda: test_photons(srv, scene))][
                                 :6 if REQUESTS_ONLY else None]:
                t = time.time()
                fn()
                print("%-10s %.2f s" % (name, time.time() - t), flush=True)
            # a second server on the same port, or on a root that is no directory: exit 2
            for args in (["--port", str(srv.port), "--root", root],
                         ["--port", "0", "--root", os.path.join(root, "s", "scene.json")],
                         ["--port", "0", "--host", "localhost"]):
                p = subprocess.run([BINARY, "serve"] + args, capture_output=True, text=True,
                                   timeout=30)
                check(p.returncode == 2 and "thzmap serve: " in p.stderr,
                      "serve %s: exit %d %r" % (args, p.returncode, p.stderr))
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
