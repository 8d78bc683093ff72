"""What test_api.py and test_api_runs.py share: the served root (a small scene, with
the traps outside it that the paths must not reach), a table outside the root that no
answer may quote, and a wait for a run's state."""
import json
import os
import shutil
import time

from serve_client import check


def make_root(repo, root):
    """The served root: a small scene in s/ (plate-in-box with 2 channels, 16 x 12 pixels,
    few photons), a symlink to /etc, one to a sibling of the root, and beside the root a
    page (web/) and a secret.json; the scene."""
    src = os.path.join(repo, "examples", "plate-in-box")
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


def wait_state(srv, run_id, states, limit_s=240):
    """The run's job once its state is one of states (None, and a failure, after limit_s)."""
    t0 = time.time()
    while time.time() - t0 < limit_s:
        job = srv.json("GET", "/api/runs/%d" % run_id)
        if job and job["state"] in states:
            return job
        time.sleep(0.05)
    check(False, "run %d never reached %s" % (run_id, states))
    return None


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
