#!/usr/bin/env python3
"""A stand-in for `thzmap serve` while developing the page (not used by the tests):
python3 mock_server.py THZMAP_BINARY WEB_DIR ROOT [PORT]. No token, no limits: loopback
only, for a developer's own files. Meshes of boxes and cylinders only."""
import json, math, os, re, subprocess, sys, threading, time
from http.server import ThreadingHTTPServer, BaseHTTPRequestHandler
from urllib.parse import urlparse, parse_qs

THZMAP, WEB, ROOT = sys.argv[1], sys.argv[2], os.path.realpath(sys.argv[3])
PORT = int(sys.argv[4]) if len(sys.argv) > 4 else 8765
runs, lock = {}, threading.Lock()


def box(size, inward):
    sx, sy, sz = [s / 2 for s in size]
    p = [[x * sx, y * sy, z * sz] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    idx = []
    for a, b, c, d in quads:
        t = [[a, b, c], [a, c, d]]
        idx += [list(reversed(x)) for x in t] if inward else t
    return p, idx


def cylinder(r, h, caps, n=32):
    p = [[r * math.cos(2 * math.pi * i / n), r * math.sin(2 * math.pi * i / n), z] for z in (0, h) for i in range(n)]
    idx = [[i, (i + 1) % n, n + (i + 1) % n] for i in range(n)] + [[i, n + (i + 1) % n, n + i] for i in range(n)]
    if caps:
        p += [[0, 0, 0], [0, 0, h]]
        idx += [[2 * n, (i + 1) % n, i] for i in range(n)] + [[2 * n + 1, n + i, n + (i + 1) % n] for i in range(n)]
    return p, idx


def mesh(o):
    s = o.get("shape", {})
    if s.get("type") == "box":
        p, idx = box(s.get("size_m", [1, 1, 1]), s.get("inward", False))
    elif s.get("type") == "cylinder":
        p, idx = cylinder(s.get("radius_m", 0.1), s.get("height_m", 1), s.get("caps", True))
    else:
        return None
    t = o.get("transform", {}).get("translate_m", [0, 0, 0])
    return {"positions": [c + t[k] for v in p for k, c in enumerate(v)], "indices": [i for f in idx for i in f]}


def validate(path, text):
    tmp = os.path.join(ROOT, os.path.dirname(path), ".mock-validate.json")
    with open(tmp, "w") as f:
        f.write(text)
    r = subprocess.run([THZMAP, "validate", tmp], capture_output=True, text=True)
    os.unlink(tmp)
    errors = []
    for line in r.stderr.splitlines():
        m = re.match(r"thzmap: [^:]*:(?:(\d+):(\d+):)? ?(?:([\w\[\].]+): )?(.*)", line)
        if m and r.returncode:
            errors.append({"json_path": m.group(3) or "", "line": int(m.group(1) or 0),
                           "column": int(m.group(2) or 0), "message": m.group(4)})
    out = {"ok": r.returncode == 0, "errors": errors, "warnings": []}
    try:
        doc = json.loads(text)
        ch = doc.get("channels", {})
        freqs = [ch["from_thz"] + i * (ch["to_thz"] - ch["from_thz"]) / max(ch["count"] - 1, 1)
                 for i in range(ch["count"])] if isinstance(ch, dict) else [c.get("frequency_thz") for c in ch]
        mats = {}
        for name, m in doc.get("materials", {}).items():
            f = [0.1 + 0.05 * i for i in range(27)]
            R = m.get("reflectivity", 0.3) if not isinstance(m.get("reflectivity"), list) else 0.3
            R = R if isinstance(R, (int, float)) else 0.3
            mats[name] = {"name": name, "freq_thz": f, "R": [R] * 27, "emissivity": [1 - R] * 27, "alpha": [0] * 27}
        out["scene"] = {
            "channels": [{"frequency_thz": x} for x in freqs], "materials": mats,
            "objects": [{"name": o.get("name"), "material": o.get("material"), "type": o.get("type"),
                         "temperature_K": o.get("temperature_k"), "mesh": mesh(o)} for o in doc.get("objects", [])],
            "sensors": doc.get("sensors", []),
            "atmosphere": {"model": "none", "transmittance": [1.0] * len(freqs)}}
    except Exception:
        pass
    return out


class H(BaseHTTPRequestHandler):
    def log_message(self, *a):
        pass

    def send(self, code, body, ctype="application/json"):
        if not isinstance(body, bytes):
            body = json.dumps(body).encode()
        self.send_response(code)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def local(self, rel):
        p = os.path.realpath(os.path.join(ROOT, rel or "."))
        if not (p == ROOT or p.startswith(ROOT + "/")):
            raise PermissionError(rel)
        return p

    def body(self):
        return self.rfile.read(int(self.headers.get("Content-Length", 0)))

    def do_GET(self):
        u = urlparse(self.path)
        a = {k: v[0] for k, v in parse_qs(u.query).items()}
        if u.path == "/" or u.path.startswith("/assets/"):
            f = os.path.join(WEB, "index.html" if u.path == "/" else u.path[1:])
            ctype = {"html": "text/html", "js": "text/javascript", "css": "text/css"}[f.rsplit(".", 1)[1]]
            return self.send(200, open(f, "rb").read(), ctype)
        if u.path == "/api/info":
            return self.send(200, {"version": "mock", "root": ROOT})
        if u.path == "/api/files":
            d = self.local(a.get("dir", ""))
            es = [{"name": n, "type": "dir" if os.path.isdir(os.path.join(d, n)) else "file",
                   "size": os.path.getsize(os.path.join(d, n)), "mtime": 0} for n in sorted(os.listdir(d))]
            return self.send(200, {"dir": a.get("dir", ""), "entries": es})
        if u.path == "/api/file":
            return self.send(200, open(self.local(a["path"]), "rb").read(), "application/octet-stream")
        if u.path == "/api/materials":
            return self.send(200, {"materials": []})
        if u.path == "/api/runs":
            with lock:
                return self.send(200, [{k: v for k, v in r.items() if k != "proc"} for r in runs.values()])
        m = re.match(r"/api/runs/(\w+)/events", u.path)
        if m:
            self.send_response(200)
            self.send_header("Content-Type", "text/event-stream")
            self.end_headers()
            r = runs[m.group(1)]
            while True:
                time.sleep(0.2)
                ev = {"state": r["state"], "stage": "run", "done": 1 if r["state"] == "done" else 0, "total": 1}
                self.wfile.write(f"data: {json.dumps(ev)}\n\n".encode())
                self.wfile.flush()
                if r["state"] in ("done", "failed", "cancelled"):
                    return
        self.send(404, {"error": "not found"})

    def do_PUT(self):
        a = {k: v[0] for k, v in parse_qs(urlparse(self.path).query).items()}
        with open(self.local(a["path"]), "wb") as f:
            f.write(self.body())
        self.send(200, {"ok": True})

    def do_POST(self):
        u = urlparse(self.path)
        req = json.loads(self.body())
        if u.path == "/api/validate":
            return self.send(200, validate(req.get("path", ""), req["text"]))
        if u.path == "/api/runs":
            rid = str(len(runs) + 1)
            o = req.get("options", {})
            cmd = [THZMAP, req["command"], self.local(req["scene"]), "-o", self.local(req["out"]), "--quiet"]
            if o.get("photons"):
                cmd += ["--photons", str(o["photons"])]
            if o.get("save_photon_map"):
                cmd += ["--save-photon-map"]
            r = {"id": rid, "command": req["command"], "scene": req["scene"], "out": req["out"], "state": "running"}
            r["proc"] = subprocess.Popen(cmd)
            runs[rid] = r

            def wait():
                rc = r["proc"].wait()
                r["state"] = "done" if rc == 0 else "failed"
            threading.Thread(target=wait, daemon=True).start()
            return self.send(200, {"id": rid})
        self.send(404, {"error": "not found"})


print(f"http://127.0.0.1:{PORT}/", flush=True)
ThreadingHTTPServer(("127.0.0.1", PORT), H).serve_forever()
