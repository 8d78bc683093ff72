"""What the two end-to-end tests of the page (test_e2e.py: the paper's session of the
pre- and post-processor; test_e2e_audit.py: what audits of the page found) share: the
served root (a copy of the paper's scene, trimmed so that a run takes seconds), `thzmap
serve` started on it, headless Chromium driven by Selenium (Debian's chromium,
chromium-driver, python3-selenium), and the helpers that find and click the page's
elements as a user would.

THZ_GUI_URL=http://... THZ_GUI_ROOT=DIR runs a test against a server already running on
DIR instead (while developing the page)."""
import json
import os
import re
import shutil
import subprocess
import tempfile
import time

from selenium import webdriver
from selenium.common.exceptions import StaleElementReferenceException
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import WebDriverWait

T0 = time.monotonic()


def log(msg):
    print(f"[{time.monotonic() - T0:5.1f} s] {msg}", flush=True)


def make_root(root, repo):
    """The paper's scene, trimmed for speed (32 x 32 pixels, 10 000 photons per channel,
    the photon-map integrator); its materials as they are. Returns the scene."""
    shutil.copytree(os.path.join(repo, "examples", "teraeye"), os.path.join(root, "teraeye"))
    path = os.path.join(root, "teraeye", "scene.json")
    with open(path) as f:
        scene = json.load(f)
    scene["sensors"][0].update(resolution=[32, 32], oversampling=1)
    scene["photons"]["per_channel"] = 10000
    scene["render"] = {"integrator": "photon-map"}
    with open(path, "w") as f:
        json.dump(scene, f, indent=2)
    return scene


def start_server(thzmap, root):
    if os.environ.get("THZ_GUI_URL"):
        return None, os.environ["THZ_GUI_URL"]
    proc = subprocess.Popen([thzmap, "serve", "--root", root, "--port", "0"],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        if not line:
            break
        m = re.search(r"http://\S+token=\S+", line)
        if m:
            return proc, m.group(0)
    proc.kill()
    raise SystemExit(f"FAIL: thzmap serve printed no URL with a token (exit {proc.wait()})")


def browser():
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
                "--window-size=1400,850", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"):
        options.add_argument(arg)
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)


class Session:
    """A served root, its server and a browser on the page; the helpers as attributes
    (driver, wait, patient, by_id, shot, click_list, field, type_into)."""

    def __init__(self, thzmap, shots, failure_name):
        self.shots, self.failure = shots, failure_name
        os.makedirs(shots, exist_ok=True)
        if os.path.exists(os.path.join(shots, f"gui-{failure_name}.png")):
            os.unlink(os.path.join(shots, f"gui-{failure_name}.png"))  # of an earlier run
        self.root = os.environ.get("THZ_GUI_ROOT") or tempfile.mkdtemp(prefix="thzmap-gui-")
        shutil.rmtree(os.path.join(self.root, "teraeye"), ignore_errors=True)
        self.thzmap = thzmap
        self.proc = self.driver = None

    def start(self):
        self.proc, self.url = start_server(self.thzmap, self.root)
        log(f"server at {self.url.split('?')[0]}")
        driver = self.driver = browser()
        log("browser started")
        # the page redraws what it shows: an element found may be replaced before it is read
        self.patient = lambda seconds, poll=0.05: WebDriverWait(
            driver, seconds, poll_frequency=poll, ignored_exceptions=[StaleElementReferenceException])
        self.wait = self.patient(30)
        self.by_id = lambda i: driver.find_element(By.ID, i)
        driver.get(self.url)
        log("page loaded")

    def shot(self, name):
        self.driver.save_screenshot(os.path.join(self.shots, f"gui-{name}.png"))

    def click_list(self, list_id, text):
        # in the page's own turn: the list may be redrawn between finding and clicking
        self.wait.until(lambda d: d.execute_script(
            "const li = [...document.querySelectorAll(`#${arguments[0]} li`)]"
            ".find((x) => x.textContent === arguments[1]); if (li) li.click(); return !!li;",
            list_id, text))

    def field(self, path):
        return self.driver.find_element(By.CSS_SELECTOR, f'.field[data-path="{path}"]')

    def type_into(self, path, text):
        box = self.field(path).find_element(By.TAG_NAME, "input")
        box.send_keys(Keys.CONTROL, "a")
        box.send_keys(text)

    def failed(self):
        """What a failure leaves to read: a screenshot, the status line, the browser's log."""
        if not self.driver:
            return
        self.shot(self.failure)
        print("status line:", self.driver.find_element(By.ID, "status").text)
        for e in self.driver.get_log("browser"):
            print("browser:", e)

    def close(self):
        if self.driver:
            self.driver.quit()
        if self.proc:
            self.proc.terminate()
            self.proc.wait(timeout=10)
        if not os.environ.get("THZ_GUI_ROOT"):
            shutil.rmtree(self.root, ignore_errors=True)
