#!/usr/bin/python3
"""Access to the JSON API of `thzmap serve` (docs/gui.md), against a real server on a
free port over a temporary root: the token (401, 403, the cookie), paths leaving the
root (.., absolute, %2e%2e, symlinks), oversized and malformed bodies and options, the
files a scene names confined to the root (validated, and run), and a second server on
the same port refused. test_api_runs.py has what the server computes (validation, runs,
their results).

usage: test_api.py THZMAP_BINARY REPO_DIR [--requests-only]

--requests-only: the requests that start no job, which fork nothing (all but the runs of
scenes naming files outside the root): the sanitizer build runs those (CMakeLists.txt says
why it runs no jobs).
"""
import http.client
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

from serve_client import Server, check, finish
from serve_root import MARKER, make_root, wait_state, write_outside

BINARY, REPO = sys.argv[1], sys.argv[2]
REQUESTS_ONLY = sys.argv[3:] == ["--requests-only"]


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
    # the program's version and source revision, as `thzmap --version` prints them
    line = subprocess.run([BINARY, "--version"], capture_output=True, text=True).stdout.strip()
    check(info and line == "thzmap %s (revision %s)" % (info.get("version"), info.get("revision")),
          "info's version and revision %r against --version's %r" % (info, line))
    srv.json("GET", "/api/nothing", status=404)
    srv.json("DELETE", "/api/info", status=405)
    srv.json("POST", "/", status=405)
    # every character of the token counts, the last too
    last = srv.token[:-1] + ("1" if srv.token[-1] == "0" else "0")
    st, _, _ = srv.request("GET", "/api/info", auth=False,
                           headers={"Authorization": "Bearer " + last})
    check(st == 403, "the token with its last character changed: %d, expected 403" % st)
    # the token logs in at / alone: on an API URL it is no credential (it was a 303)
    st, _, _ = srv.request("GET", "/api/info?token=" + srv.token, auth=False)
    check(st == 401, "GET /api/info?token=T without the cookie: %d, expected 401" % st)
    # every /api/ answer, JSON ones and errors too, may not run as a page nor be cached
    for path in ("/api/info", "/api/nothing"):
        st, h, _ = srv.request("GET", path)
        check(h.get("Content-Security-Policy") == "default-src 'none'; sandbox" and
              h.get("X-Content-Type-Options") == "nosniff" and
              h.get("Cache-Control") == "no-store", "headers of %s: %r" % (path, h))
    # an endpoint's name with more after it is no endpoint (/api/materials + a material's
    # name answered that material)
    lib = srv.json("GET", "/api/materials")
    if lib and lib["materials"]:
        st, _, _ = srv.request("GET", "/api/materials" + lib["materials"][0]["name"])
        check(st == 404, "/api/materials%s: %d, expected 404" % (lib["materials"][0]["name"], st))


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
    # an absolute path is refused even where it names a file inside the root
    st, _, _ = srv.request("GET", "/api/file?path=" + os.path.join(root, "s", "scene.json"))
    check(st == 403, "GET the absolute path of a file in the root: %d, expected 403" % st)
    # a listing: sorted by name, size in bytes, mtime in s since 1970 (the names are made
    # in an order that is not theirs)
    os.mkdir(os.path.join(root, "l"))
    for name, size in (("m.json", 5), ("b.txt", 1000), ("z.csv", 0), ("a.json", 77)):
        open(os.path.join(root, "l", name), "w").write("x" * size)
    os.utime(os.path.join(root, "l", "b.txt"), (1600000000, 1600000000))
    listing = srv.json("GET", "/api/files?dir=l")
    entries = listing["entries"] if listing else []
    check([e["name"] for e in entries] == ["a.json", "b.txt", "m.json", "z.csv"],
          "listing not sorted by name: %r" % [e["name"] for e in entries])
    for e in entries:
        st_ = os.stat(os.path.join(root, "l", e["name"]))
        check(e["size"] == st_.st_size and e["mtime"] == int(st_.st_mtime),
              "listed %s: %r, the file %d bytes, mtime %d" % (e["name"], e, st_.st_size,
                                                              int(st_.st_mtime)))
    # a file is no directory to list: the request's mistake
    err = srv.json("GET", "/api/files?dir=s/scene.json", status=400)
    check(err and "Not a directory" in err.get("error", ""), "list a file: %r" % err)
    # types by extension (docs/gui.md): JSON as JSON, tables as plain text
    for rel, ctype in (("s/scene.json", "application/json"),
                       ("s/materials/sample.csv", "text/plain; charset=utf-8"),
                       ("l/b.txt", "text/plain; charset=utf-8")):
        st, h, _ = srv.request("GET", "/api/file?path=" + rel)
        check(st == 200 and h.get("Content-Type") == ctype, "GET %s: %d %r, expected %s"
              % (rel, st, h.get("Content-Type"), ctype))
    # a PUT writes text: a NUL in the body is refused, nothing written; a directory that
    # does not exist is a 404 (it is not the server's fault)
    st, _, data = srv.request("PUT", "/api/file?path=l/nul.json", body=b'{"a": "\x00"}')
    check(st == 400 and b"not text" in data and not os.path.exists(os.path.join(root, "l", "nul.json")),
          "PUT a body with a NUL: %d %r" % (st, data[:200]))
    st, _, data = srv.request("PUT", "/api/file?path=l/none/x.json", body=b"{}")
    check(st == 404, "PUT into a directory that does not exist: %d %r" % (st, data[:200]))
    # the page's files are those of its bundle: a link in it to a file outside is not served
    web = os.path.join(root, "..", "web")
    os.symlink(os.path.join(root, "..", "secret.json"), os.path.join(web, "assets", "leak.js"))
    st, _, data = srv.request("GET", "/assets/leak.js")
    check(st == 404, "a link out of the bundle: %d %r" % (st, data[:100]))


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
    # 4 MiB exactly is within the limit ("above 4 MiB: 413"), declared or chunked; a
    # declared byte more is not
    pad = (4 << 20) - len('{"text": ""}')
    body = ('{"text": "%s"}' % ("x" * pad)).encode()
    st, _, _ = srv.request("POST", "/api/validate", body=body)
    check(st == 200, "a body of 4 MiB: %d, expected 200" % st)
    conn = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=60)
    conn.request("POST", "/api/validate", body=(body[i:i + (1 << 20)] for i in
                                                range(0, len(body), 1 << 20)),
                 headers={"Authorization": "Bearer " + srv.token}, encode_chunked=True)
    st = conn.getresponse().status
    conn.close()
    check(st == 200, "a chunked body of 4 MiB: %d, expected 200" % st)
    sock = socket.create_connection(("127.0.0.1", srv.port), timeout=30)
    sock.sendall(("POST /api/validate HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer %s\r\n"
                  "Content-Length: %d\r\n\r\n" % (srv.token, (4 << 20) + 1)).encode())
    answer = sock.recv(4096).decode(errors="replace")
    sock.close()
    check(answer.startswith("HTTP/1.1 413"), "declared 4 MiB + 1 byte: %r" % answer[:40])
    # a key twice is malformed JSON, as in a scene (which of the two would count?)
    err = srv.json("POST", "/api/runs", body='{"command": "simulate", "command": "bands", '
                   '"scene": "s/scene.json", "out": "o"}', status=400)
    check(err and err.get("path") == "$" and "duplicate" in err.get("error", ""),
          "a body with a key twice: %r" % err)
    err = srv.json("POST", "/api/validate", body="{bad", status=400)
    check(err and err.get("path") == "$" and "line 1" in err["error"], "malformed: %r" % err)
    err = srv.json("POST", "/api/validate", body={"text": 3}, status=400)
    check(err and err.get("path") == "$.text", "text not a string: %r" % err)
    # a misspelt key (the scene's path as "file") is a 400 at it, not a scene whose
    # relative file names were silently taken from the root
    err = srv.json("POST", "/api/validate", body={"file": "s/scene.json", "text": "{}"},
                   status=400)
    check(err and err.get("path") == "$.file" and
          err.get("error") == "unknown key (expected path, text)",
          "an unknown key of a validate body: %r" % err)
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


def ipv6_loopback():
    try:
        with socket.socket(socket.AF_INET6) as s:
            s.bind(("::1", 0))
        return True
    except OSError:
        return False


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
            tests = [("auth", lambda: test_auth(srv)),
                     ("paths", lambda: test_paths(srv, root)),
                     ("limits", lambda: test_limits(srv)),
                     ("confined", lambda: test_confined(srv, root, scene))]
            if not REQUESTS_ONLY:
                tests.append(("runs", lambda: test_runs_confined(srv, root, scene)))
            for name, fn in tests:
                t = time.time()
                fn()
                print("%-10s %.2f s" % (name, time.time() - t), flush=True)
            # IPv6's loopback (docs/gui.md: --host ::1) serves as IPv4's does (where the
            # machine has one)
            p = ipv6_loopback() and subprocess.Popen([BINARY, "serve", "--host", "::1", "--port", "0", "--root", root],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            m = p and re.search(r"http://\[::1\]:(\d+)/\?token=([0-9a-f]{32}) ",
                                p.stdout.readline())
            info = None
            if m:
                conn = http.client.HTTPConnection("::1", int(m.group(1)), timeout=30)
                conn.request("GET", "/api/info", headers={"Authorization": "Bearer " + m.group(2)})
                info = json.loads(conn.getresponse().read())
                conn.close()
            if p:
                p.send_signal(signal.SIGINT)
                p.wait(timeout=30)
                check(info and info["root"] == os.path.realpath(root),
                      "serve --host ::1: %r %r" % (m and m.group(0), info))
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
        print("total %.1f s" % (time.time() - t0))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    finish()


main()
