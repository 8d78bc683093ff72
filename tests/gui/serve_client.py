"""What the API tests of `thzmap serve` (tests/gui/test_api*.py) share: a server on a free
port over a root, requests with its token, and failures collected rather than raised
(every check of a test runs; the script exits 1 at the end when any failed)."""
import http.client
import json
import re
import signal
import subprocess
import sys

FAILURES = []


def check(cond, what):
    if not cond:
        FAILURES.append(what)
        print("FAIL:", what, flush=True)


def finish():
    """Ends a test script: exit 1 with the count when any check failed, else "ok"."""
    if FAILURES:
        print("%d failure(s)" % len(FAILURES))
        sys.exit(1)
    print("ok")


class Server:
    """`BINARY serve --port 0 --root ROOT`, run through `prefix` (a command list) when
    given."""

    def __init__(self, binary, root, env=None, prefix=()):
        self.proc = subprocess.Popen(list(prefix) + [binary, "serve", "--port", "0", "--root", root],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     text=True, env=env)
        line = self.proc.stdout.readline()
        m = re.search(r"http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]{32}) ", line)
        if not m:
            self.proc.kill()
            raise SystemExit("no URL printed: %r %s" % (line, self.proc.stderr.read()))
        self.port, self.token = int(m.group(1)), m.group(2)

    def request(self, method, path, body=None, headers=None, auth=True, timeout=60):
        conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=timeout)
        h = dict(headers or {})
        if auth:
            h["Authorization"] = "Bearer " + self.token
        conn.request(method, path, body=body, headers=h)
        resp = conn.getresponse()
        data = resp.read()
        conn.close()
        return resp.status, dict(resp.getheaders()), data

    def json(self, method, path, body=None, status=200):
        if body is not None and not isinstance(body, (bytes, str)):
            body = json.dumps(body)
        st, _, data = self.request(method, path, body)
        check(st == status, "%s %s: status %d, expected %d (%s)" % (method, path, st, status,
                                                                     data[:300]))
        try:
            return json.loads(data)
        except ValueError:
            check(False, "%s %s: not JSON: %r" % (method, path, data[:200]))
            return None

    def stop(self, sig=signal.SIGINT, timeout=30):
        self.proc.send_signal(sig)
        try:
            return self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            return None
