#!/usr/bin/python3
"""GET /api/pixel reads a run directory's cubes one after the other. A run that commits
into the directory between two of those reads must not give an answer mixing both runs
(it gave run 1's Tb beside run 2's truth object and run 1's temperature): the server
reads the pixel again. strace stops the server (SIGSTOP) at its first open of the truth
header, `thzmap simulate` commits run 2 into the directory, and the server goes on
(SIGCONT). A delay of 2 s there, in place of the stop, made the test depend on the
simulate ending within it: under the sanitizer build on a loaded 2-core machine it did
not, and the server read run 1 whole.

usage: test_api_pixel_race.py THZMAP_BINARY REPO_DIR [--requests-only]

The server starts no job here (the runs are the CLI's), so --requests-only changes nothing.
"""
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

from serve_client import Server, check, finish

BINARY, REPO = sys.argv[1], sys.argv[2]
if not shutil.which("strace"):
    check(False, "strace is missing (scripts/install-deps.sh installs it)")
    finish()
root = tempfile.mkdtemp()
try:
    src = os.path.join(REPO, "examples", "plate-in-box")
    shutil.copytree(os.path.join(src, "materials"), os.path.join(root, "materials"))
    scene = json.load(open(os.path.join(src, "scene.json")))
    scene["channels"].append({"name": "0.8 THz", "frequency_thz": 0.8, "relative_width": 0.01})
    scene["sensors"][0].update(resolution=[24, 24], oversampling=1)
    scene["render"] = {"integrator": "path", "paths_per_sample": 2}
    with open(os.path.join(root, "one.json"), "w") as f:
        json.dump(scene, f)
    for o in scene["objects"][1:]:  # the target and its cover moved aside, the target warmer
        o["transform"]["translate_m"][0] = 0.15
    scene["objects"][1]["temperature_k"] = 320
    with open(os.path.join(root, "two.json"), "w") as f:
        json.dump(scene, f)

    def simulate(name, out):
        subprocess.run([BINARY, "simulate", name, "-o", out, "-q"], cwd=root, check=True)

    simulate("one.json", "one")
    simulate("two.json", "two")
    simulate("one.json", "run")
    # LeakSanitizer cannot run under ptrace (the sanitizer build checks the rest)
    env = dict(os.environ, ASAN_OPTIONS=":".join(
        filter(None, [os.environ.get("ASAN_OPTIONS"), "detect_leaks=0"])))
    log = os.path.join(root, "strace.log")
    srv = Server(BINARY, root, env=env, prefix=[
        "strace", "-f", "-qq", "-o", log, "-e", "trace=openat", "-e",
        "inject=openat:signal=SIGSTOP:when=1", "-P",
        os.path.join(root, "run", "cam.object_id.hdr")])

    def server_pids():  # the server itself, strace's child
        with open("/proc/%d/task/%d/children" % (srv.proc.pid, srv.proc.pid)) as f:
            return [int(pid) for pid in f.read().split()]

    def stopped():
        with open(log) as f:
            return "stopped by SIGSTOP" in f.read()
    try:
        # a pixel where run one sees the target and run two the room
        q = "/api/pixel?dir=%s&sensor=cam&row=12&col=10"
        one, two = srv.json("GET", q % "one"), srv.json("GET", q % "two")
        check(one["truth"]["object"] != two["truth"]["object"], "the runs see the same object")
        got = {}
        t = threading.Thread(target=lambda: got.update(a=srv.json("GET", q % "run")))
        t.start()
        for _ in range(1200):  # at most 120 s
            if stopped() or not t.is_alive():
                break
            time.sleep(0.1)
        check(stopped(), "the server never opened the truth header")
        try:
            simulate("two.json", "run")
        finally:
            for pid in server_pids():
                os.kill(pid, signal.SIGCONT)
        t.join()
        a = got.get("a") or {}
        check(a.get("tb_K") == two["tb_K"] and a.get("truth") == two["truth"],
              "the pixel read while run two committed is not run two's: %r (one: %r, two: %r)"
              % (a, one, two))
    finally:
        # SIGINT to the server itself (strace, told, would detach and leave it running)
        for pid in server_pids():
            os.kill(pid, signal.SIGINT)
        srv.proc.wait(timeout=30)
finally:
    shutil.rmtree(root, ignore_errors=True)
finish()
