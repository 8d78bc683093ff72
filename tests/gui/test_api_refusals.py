#!/usr/bin/python3
"""What `thzmap serve` refuses, and in which words (docs/gui.md): files that are no
regular files (a FIFO once held the request, and then the server's stop, for ever), files
and directories the server may not read, paths with "." components, over-long strings,
runs whose integrator (the option, or else the scene's render.integrator, or else path)
contradicts save_photon_map or a missing photon_map, a scene whose PSF no run could build;
and the event stream's headers and numbers, as every other /api/ answer's.

usage: test_api_refusals.py THZMAP_BINARY REPO_DIR [--requests-only]

--requests-only: only the requests that start no job (test_api.py says why).
"""
import json
import os
import re
import shutil
import signal
import socket
import stat
import sys
import tempfile
import time

from serve_client import Server, check, finish

BINARY, REPO = sys.argv[1], sys.argv[2]
REQUESTS_ONLY = sys.argv[3:] == ["--requests-only"]
# root reads every file whatever its mode: the server runs without that capability, so
# that a mode-000 file is as unreadable to it as to any other user
NO_DAC = (["setpriv", "--bounding-set", "-dac_override,-dac_read_search"]
          if os.geteuid() == 0 and shutil.which("setpriv") else [])


def make_root(root):
    """plate-in-box at 8 x 6 pixels, three times: integrator photon-map, path, and none."""
    src = os.path.join(REPO, "examples", "plate-in-box")
    shutil.copytree(os.path.join(src, "materials"), os.path.join(root, "s", "materials"))
    scene = json.load(open(os.path.join(src, "scene.json")))
    scene["sensors"][0].update(resolution=[8, 6], oversampling=1)
    scene["photons"]["per_channel"] = 2000
    scene.pop("render", None)
    for name, render in (("pm", {"integrator": "photon-map"}),
                         ("path", {"integrator": "path", "paths_per_sample": 1}), ("none", None)):
        if render:
            scene["render"] = render
        else:
            scene.pop("render", None)
        with open(os.path.join(root, "s", name + ".json"), "w") as f:
            json.dump(scene, f)
    os.mkfifo(os.path.join(root, "s", "fifo.json"))
    open(os.path.join(root, "s", "locked.json"), "w").write("{}")
    os.chmod(os.path.join(root, "s", "locked.json"), 0)
    os.makedirs(os.path.join(root, "s", "closed"))
    open(os.path.join(root, "s", "closed", "x.json"), "w").write("{}")
    os.chmod(os.path.join(root, "s", "closed"), 0)
    os.makedirs(os.path.join(root, "s", "ro"))
    os.chmod(os.path.join(root, "s", "ro"), 0o555)


def get_within(srv, path, seconds):
    """GET path: (status, JSON body), or (None, None) when no answer came in time."""
    try:
        st, _, data = srv.request("GET", path, timeout=seconds)
        return st, json.loads(data)
    except (socket.timeout, TimeoutError, ValueError):
        return None, None


def test_files(srv, root):
    # a FIFO: refused at once, not opened to wait for a writer
    st, err = get_within(srv, "/api/file?path=s/fifo.json", 5)
    check(st == 400 and "not a regular file" in err["error"], "GET a FIFO: %s %r" % (st, err))
    # a FIFO where a results directory's summary.json would be: /api/outputs answers
    os.makedirs(os.path.join(root, "f"), exist_ok=True)
    if not os.path.exists(os.path.join(root, "f", "summary.json")):
        os.mkfifo(os.path.join(root, "f", "summary.json"))
    st, res = get_within(srv, "/api/outputs?dir=f", 5)
    check(st is not None, "GET /api/outputs of a directory whose summary.json is a FIFO hung")
    check(res["summary"] is None and res["summary_error"] == "f/summary.json: not a regular file",
          "a FIFO as summary.json: %r" % res)
    err = srv.json("POST", "/api/runs", body={"command": "simulate", "scene": "s/fifo.json",
                                               "out": "o"}, status=400)
    check(err and err.get("path") == "$.scene" and "not a regular file" in err["error"],
          "a FIFO's run: %r" % err)
    # "." components name the same file wherever they are
    want = open(os.path.join(root, "s", "pm.json"), "rb").read()
    for path in ("s/./pm.json", "./s/pm.json", "s/.//./pm.json"):
        st, _, data = srv.request("GET", "/api/file?path=" + path)
        check(st == 200 and data == want, "GET %s: %d %r" % (path, st, data[:100]))
    st, _, _ = srv.request("GET", "/api/file?path=s/./../../secret.json")
    check(st == 403, "'..' after '.': %d, expected 403" % st)
    # what the server may not read is said so, not "not a file" or "outside the root"
    if os.geteuid() == 0 and not NO_DAC:
        print("skipped: permission denied (root without setpriv reads everything)")
        return
    for path in ("s/locked.json", "s/closed/x.json"):
        st, err = get_within(srv, "/api/file?path=" + path, 10)
        check(st == 403 and "permission denied" in err["error"], "GET %s: %s %r" % (path, st, err))
        # and a run asked of such a scene is refused at once, not queued to fail
        st, _, data = srv.request("POST", "/api/runs", body=json.dumps(
            {"command": "simulate", "scene": path, "out": "o"}))
        check(st == 403 and b"permission denied" in data, "POST a run of %s: %s %r"
              % (path, st, data[:200]))
    # a directory it may not write in: a PUT there is a 403 "permission denied", not the
    # server's fault (500)
    st, _, data = srv.request("PUT", "/api/file?path=s/ro/x.json", body="{}")
    check(st == 403 and b"permission denied" in data, "PUT into a read-only directory: %s %r"
          % (st, data[:200]))
    # a directory it may not list, likewise (it said "not a directory" and 404)
    for path in ("/api/files?dir=s/closed", "/api/outputs?dir=s/closed"):
        st, err = get_within(srv, path, 10)
        check(st == 403 and "permission denied" in err["error"], "GET %s: %s %r" % (path, st, err))


def test_lengths(srv):
    long_path = "s/" + "d/" * 2100 + "scene.json"
    st, err = get_within(srv, "/api/file?path=" + long_path, 10)
    check(st == 400 and "longer than the 4093 allowed" in err["error"],
          "GET a path of %d bytes: %s %r" % (len(long_path), st, err))
    # one name longer than the file system's: not "outside the root"
    st, err = get_within(srv, "/api/files?dir=s/" + "n" * 300, 10)
    check(st == 400 and "longer than the file system allows" in err["error"],
          "GET a 300-byte name: %s %r" % (st, err))
    for key, value, words in (("scene", long_path, "at most 4093 bytes"),
                              ("options.sensor", "c" * 300, "at most 255 bytes"),
                              ("options.integrator", "i" * 100,
                               "expected path, final-gather or photon-map")):
        body = {"command": "render", "scene": "s/path.json", "out": "o", "options": {}}
        if key == "scene":
            body["scene"] = value
        else:
            body["options"][key.split(".")[1]] = value
        err = srv.json("POST", "/api/runs", body=body, status=400)
        check(err and err.get("path") == "$." + key and words in err["error"],
              "%s of %d bytes: %r" % (key, len(value), err))


def raw_request(srv, method, url, body=None):
    """The whole answer to a request sent by hand on a socket (http.client sends ASCII
    methods only), with the token."""
    head = method + b" " + url + b" HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer " + \
        srv.token.encode() + b"\r\nConnection: close\r\n"
    if body is not None:
        head += b"Content-Length: %d\r\n" % len(body)
    with socket.create_connection(("127.0.0.1", srv.port), timeout=60) as s:
        s.sendall(head + b"\r\n" + (body or b""))
        data = b""
        while chunk := s.recv(65536):
            data += chunk
    return data


def test_text_and_limits(srv, root):
    """Bytes that are not UTF-8 in the method, URL or query are refused with 400 (the answers, which
    quote them, were 500 "out of memory": jansson refuses such strings; a PUT had written
    its file first); a run asks for at most the machine's processors (more made OpenMP end
    the server where the system refused the threads); a PUT of a 255-byte name works (its
    temporary name passed the limit on names)."""
    for method, url in (("GET", "/api/file?path=missing%FF.json"), ("GET", "/api/nope%FF"),
                        ("GET", "/api/files?dir=nodir%C3"), ("PUT", "/api/file?path=s/n%FF.json")):
        st, _, data = srv.request(method, url, body="{}" if method == "PUT" else None)
        check(st == 400 and b"not UTF-8 text" in data, "%s %s: %s %r" % (method, url, st, data))
    check(not [n for n in os.listdir(os.path.join(root, "s").encode()) if b"\xff" in n],
          "a refused PUT wrote its file")
    # nor a method (the 405 naming it was 500 "out of memory"; the fuzzer found it), sent
    # by hand: http.client sends ASCII methods only
    for method in (b"\xc7ET", b"P\xffT"):
        data = raw_request(srv, method, b"/api/materials/skin")
        check(data.startswith(b"HTTP/1.1 400 ") and b"not UTF-8 text" in data,
              "method %r: %r" % (method, data[:300]))
    # a body whose syntax error jansson quotes cut inside a character (the escape \ then
    # U+07BC: "near '...\\\xde'") was 500 "out of memory" too (the fuzzer found it); the
    # byte is told as '?'
    for url in (b"/api/validate", b"/api/runs"):
        data = raw_request(srv, b"POST", url, b'{"text": "{\\"a\\\xde\xbc \\"b\\"}"}')
        body = data.split(b"\r\n\r\n", 1)[-1]
        err = json.loads(body) if data.startswith(b"HTTP/1.1 400 ") else {}
        check(err.get("path") == "$" and "invalid JSON at line 1, column" in err["error"] and
              err["error"].endswith("\\?'"),
              "POST %r with a body cut inside a character: %r" % (url, data[-300:]))
    st, _, data = srv.request("PATCH", "/api/materials/skin")
    check(st == 405 and b"PATCH is not allowed on /api/materials/skin" in data,
          "PATCH: %s %r" % (st, data))
    st, _, data = srv.request("GET", "/api/info")
    check(st == 200 and json.loads(data)["web"] is False, "/api/info without a bundle: %r" % data)
    # and / says so (docs/gui.md), as a page
    st, h, data = srv.request("GET", "/")
    check(st == 200 and h.get("Content-Type", "").startswith("text/html") and
          b"not built" in data, "/ without a bundle: %s %r" % (st, data[:200]))
    # an empty body: its syntax error at column 1, the first (it said column 0)
    err = srv.json("POST", "/api/runs", body="", status=400)
    check(err and "line 1, column 1:" in err["error"], "an empty body: %r" % err)
    # a NUL (%00) ended the C string: "n.json%00.txt" wrote n.json
    for method, url in (("PUT", "/api/file?path=s/nul.json%00.txt"),
                        ("GET", "/api/files?dir=s%00x"), ("GET", "/api/file?path=s/pm.json%00z")):
        st, _, data = srv.request(method, url, body="{}" if method == "PUT" else None)
        check(st == 400 and b"NUL" in data, "%s %s: %s %r" % (method, url, st, data))
    check(not os.path.exists(os.path.join(root, "s", "nul.json")), "a PUT with %00 wrote its file")
    procs = os.cpu_count() or 1
    err = srv.json("POST", "/api/runs", body={"command": "simulate", "scene": "s/path.json",
                                               "out": "o", "options": {"threads": procs + 1}},
                   status=400)
    check(err and err.get("path") == "$.options.threads" and
          ("from 0 to %d" % procs) in err["error"], "threads %d: %r" % (procs + 1, err))
    name = "s/" + "n" * 250 + ".json"
    st, _, data = srv.request("PUT", "/api/file?path=" + name, body="{}")
    check(st == 200, "PUT a 255-byte name: %s %r" % (st, data[:200]))
    os.remove(os.path.join(root, name))


def test_integrators(srv):
    """The integrator is the option's, else the scene's, else path (the default)."""
    for scene, options, key in (
            ("s/path.json", {"save_photon_map": True}, "save_photon_map"),
            ("s/none.json", {"save_photon_map": True}, "save_photon_map"),
            ("s/pm.json", {"integrator": "path", "save_photon_map": True}, "save_photon_map")):
        err = srv.json("POST", "/api/runs", body={"command": "simulate", "scene": scene,
                                                   "out": "o", "options": options}, status=400)
        check(err and err.get("path") == "$.options." + key and "path integrator" in err["error"],
              "simulate %s %r: %r" % (scene, options, err))
    for scene, options in (("s/pm.json", {}), ("s/path.json", {"integrator": "final-gather"})):
        err = srv.json("POST", "/api/runs", body={"command": "render", "scene": scene,
                                                   "out": "o", "options": options}, status=400)
        check(err and err.get("path") == "$.options.photon_map" and
              "renders from a photon map" in err["error"], "render %s %r: %r" % (scene, options, err))


def test_options(srv):
    """Each command takes its own options (docs/gui.md), of their types and ranges: an
    option of another command, a count that is no whole number or out of range, or an
    unknown key of the body is a 400 at its JSON path (taken silently, a render's seed or
    a batch's integrator did nothing)."""
    for command, key, value in (("render", "seed", 3), ("batch", "seed", 3),
                                ("batch", "integrator", "path"), ("simulate", "photons", 1.5),
                                ("simulate", "photons", 0), ("simulate", "target_noise_k", 0),
                                ("render", "max_seconds", 0)):
        err = srv.json("POST", "/api/runs", body={"command": command, "scene": "s/path.json",
                                                   "out": "o", "options": {key: value}},
                       status=400)
        check(err and err.get("path") == "$.options." + key,
              "%s with %s %r: %r" % (command, key, value, err))
    err = srv.json("POST", "/api/runs", body={"command": "simulate", "scene": "s/path.json",
                                               "out": "o", "output": "p"}, status=400)
    check(err and err.get("path") == "$.output", "an unknown key of the body: %r" % err)


def test_psf(srv, root):
    """/api/validate refuses a PSF too much wider than the image to fold onto it, as a run
    would (it answered ok, and the run then failed), at the key that sets its width."""
    scene = json.load(open(os.path.join(root, "s", "pm.json")))
    scene["sensors"][0].update(psf="gaussian", psf_fwhm_deg=120, fov_deg=0.01)
    res = srv.json("POST", "/api/validate", body={"path": "s/wide.json", "text": json.dumps(scene)})
    e = res and res["errors"] and res["errors"][0]
    check(res and not res["ok"] and e and e["json_path"] == "sensors[0].psf_fwhm_deg" and
          "the PSF reaches" in e["message"], "validate a 120 deg PSF on 0.01 deg: %r" % res)


def wait_state(srv, run_id):
    """The job once it is done, failed or cancelled (None after 60 s)."""
    for _ in range(600):
        st, _, data = srv.request("GET", "/api/runs/%d" % run_id)
        job = json.loads(data) if st == 200 else None
        if job and job["state"] not in ("queued", "running"):
            return job
        time.sleep(0.1)
    return None


def test_events(srv, root):
    """A render of the path scene without a photon map runs; its event stream carries the
    headers of every /api/ answer and reals of 9 significant digits."""
    run = srv.json("POST", "/api/runs", body={"command": "render", "scene": "s/path.json",
                                               "out": "out/path"}, status=202)
    if not run:
        return
    # the stream is GET's alone (docs/gui.md: 405 wrong method)
    srv.json("POST", "/api/runs/%d/events" % run["id"], status=405)
    sock = socket.create_connection(("127.0.0.1", srv.port), timeout=60)
    sock.sendall(("GET /api/runs/%d/events HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer %s\r\n"
                  "\r\n" % (run["id"], srv.token)).encode())
    raw = b""
    while b"event: end" not in raw:
        chunk = sock.recv(65536)
        if not chunk:
            break
        raw += chunk
    sock.close()
    head, _, body = raw.decode().partition("\r\n\r\n")
    check("content-security-policy: default-src 'none'; sandbox" in head.lower() and
          "x-content-type-options: nosniff" in head.lower(), "event stream headers: %r" % head)
    datas = [json.loads(line[6:]) for line in body.splitlines() if line.startswith("data: {\"")]
    check(datas and datas[-1]["state"] == "done", "render of the path scene: %r" % datas[-1:])
    reals = [m for line in body.splitlines() if line.startswith("data: ")
             for m in re.findall(r"(?<![\w.])-?\d+\.\d+(?:[eE][-+]?\d+)?", line)]
    digits = lambda x: len(x.lstrip("-").split("e")[0].split("E")[0].replace(".", "").lstrip("0"))
    check(reals and max(digits(x) for x in reals) <= 9,
          "reals of more than 9 digits: %r" % [x for x in reals if digits(x) > 9][:5])
    check(os.path.exists(os.path.join(root, "out", "path", "summary.json")), "no output written")
    # the options reach the run: the integrator over the scene's, the noise target, the
    # time limit (which, without a target, a run warning says it does not use), the sensor
    runs = {name: srv.json("POST", "/api/runs", body={
        "command": "render", "scene": scene, "out": "out/" + name, "options": options},
        status=202) for name, scene, options in (
            ("integrator", "s/pm.json", {"integrator": "path", "max_seconds": 5}),
            ("unused", "s/path.json", {"max_seconds": 30}),
            ("target", "s/path.json", {"target_noise_k": 50}),
            ("sensor", "s/path.json", {"sensor": "nope"}))}
    jobs = {name: run and wait_state(srv, run["id"]) for name, run in runs.items()}
    summary = lambda name: json.load(open(os.path.join(root, "out", name, "summary.json")))
    check(jobs["integrator"] and jobs["integrator"]["state"] == "done" and
          summary("integrator")["integrator"] == "path",
          "render of the photon-map scene with integrator path: %r" % jobs["integrator"])
    check(jobs["unused"] and jobs["unused"]["state"] == "done" and
          any("max_seconds 30 s is not used" in w for w in summary("unused")["warnings"]),
          "render with max_seconds and no target: %r" % jobs["unused"])
    check(jobs["target"] and jobs["target"]["state"] == "done" and
          summary("target")["target_noise_k"] == 50, "render with target_noise_k 50: %r"
          % jobs["target"])
    check(jobs["sensor"] and jobs["sensor"]["state"] == "failed" and
          "no sensor named 'nope'" in (jobs["sensor"]["error"] or ""),
          "render of a sensor the scene does not have: %r" % jobs["sensor"])
    # an out path of two-byte characters whose "done; results in ..." message is cut inside
    # one: the job stays in the list, its answer 200 (it was 500 and gone from the list)
    out = "o/x" + "\u00e9" * 100 + "/" + "\u00e9" * 20
    run = srv.json("POST", "/api/runs", body={"command": "render", "scene": "s/path.json",
                                               "out": out}, status=202)
    job = None
    for _ in range(600):
        st, _, data = srv.request("GET", "/api/runs/%d" % run["id"])
        job = json.loads(data) if st == 200 else None
        if not job or job["state"] not in ("queued", "running"):
            break
        time.sleep(0.1)
    check(job and job["state"] == "done" and job["message"].startswith("done; results in o/x"),
          "a run into %d bytes of accented names: %r" % (len(out.encode()), job))
    st, _, data = srv.request("GET", "/api/runs")
    check(st == 200 and run["id"] in [j["id"] for j in json.loads(data)],
          "the run is missing from the list: %s %r" % (st, data[:200]))
    # finished jobs beyond the last 256 go: 256 stay, and the new one (every job stayed,
    # 14 KB each, until the stop)
    with open(os.path.join(root, "s", "broken.json"), "w") as f:
        f.write("{")
    ids = []
    while len(ids) < 270:
        st, _, data = srv.request("POST", "/api/runs", body=json.dumps(
            {"command": "simulate", "scene": "s/broken.json", "out": "o"}))
        if st == 202:
            ids.append(json.loads(data)["id"])
        else:
            check(st == 409, "POST a failing run: %s %r" % (st, data[:200]))
            time.sleep(0.05)
    for _ in range(600):
        st, _, data = srv.request("GET", "/api/runs/%d" % ids[-1])
        if st == 200 and json.loads(data)["state"] not in ("queued", "running"):
            break
        time.sleep(0.05)
    srv.request("POST", "/api/runs", body=json.dumps(
        {"command": "simulate", "scene": "s/broken.json", "out": "o"}))  # prunes
    st, _, data = srv.request("GET", "/api/runs")
    listed = [j["id"] for j in json.loads(data)] if st == 200 else []
    check(len(listed) == 257 and ids[-1] in listed and run["id"] not in listed,
          "after 270 more jobs: %d listed, the first kept: %s" % (len(listed), listed[:1]))
    st, _, _ = srv.request("GET", "/api/runs/%d" % run["id"])
    check(st == 404, "a job pruned from the list: %s, expected 404" % st)


def main():
    tmp = tempfile.mkdtemp(prefix="thzmap-refusals-")
    root = os.path.join(tmp, "root")
    os.makedirs(root)
    try:
        make_root(root)
        open(os.path.join(tmp, "secret.json"), "w").write("{}")
        # a web directory without the page's bundle: no page (it said "web": true)
        os.makedirs(os.path.join(tmp, "web"))
        env = dict(os.environ, THZMAP_WEB_DIR=os.path.join(tmp, "web"))
        srv = Server(BINARY, root, env, prefix=NO_DAC)
        try:
            tests = [("files", lambda: test_files(srv, root)), ("lengths", lambda: test_lengths(srv)),
                     ("integrators", lambda: test_integrators(srv)),
                     ("options", lambda: test_options(srv)),
                     ("psf", lambda: test_psf(srv, root)),
                     ("text", lambda: test_text_and_limits(srv, root))]
            if not REQUESTS_ONLY:
                tests.append(("events", lambda: test_events(srv, root)))
            for name, fn in tests:
                t = time.time()
                fn()
                print("%-12s %.2f s" % (name, time.time() - t), flush=True)
        finally:
            # the FIFO asked for above must not hold the stop
            rc = srv.stop(signal.SIGINT, timeout=10)
            check(rc == -signal.SIGINT, "SIGINT: exit status %s, expected the signal's end" % rc)
    finally:
        os.chmod(os.path.join(root, "s", "closed"), stat.S_IRWXU)
        shutil.rmtree(tmp, ignore_errors=True)
    finish()


main()
