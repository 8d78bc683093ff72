#!/usr/bin/env python3
"""End-to-end test of the browser page in headless Chromium: what audits of the page
found, each a fault a user met (test_e2e.py has the paper's session; e2e_session.py what
both share):

    python3 test_e2e_audit.py THZMAP_BINARY REPO_DIR SCREENSHOT_DIR

On a root holding the paper's trimmed scene, two runs of it made by `thzmap simulate`
(seeds 1 and 2, with their photon maps), a one-channel path scene, files that are no
scene, a `bands` run and a batch: files that broke the scene panels, runs started from
the Run tab (of the path integrator, failing, refused, eight queued), a bands run's
directory in Results, edits not saved, a library material, a narrow window, the A/B
difference of the channel chosen, the value of the image clicked, the integrator chosen in
the Run tab; the clicked pixel's mark, the image at the window's size, a batch's frames on
one colour scale and a damaged summary.json (e2e_view.py); the Pixel column of an A/B
difference compared again, of another quantity chosen and of a bands run's directory,
the colour bar at the image's height, a run's warnings, the runs an A/B difference
compared, a directory without images (e2e_refresh.py); the build's revision in the
status line. Screenshots go to SCREENSHOT_DIR/gui-*.png."""
import json
import os
import re
import subprocess
import sys
import time

import numpy as np
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import Select

import e2e_readouts as readouts
import e2e_refresh as refresh
import e2e_session
import e2e_user as user
import e2e_view as view
from e2e_session import log

THZMAP, REPO, SHOTS = sys.argv[1], sys.argv[2], sys.argv[3]


def make_root(root):
    """The trimmed paper's scene and its runs, the scenes and runs the audits need."""
    scene = e2e_session.make_root(root, REPO)
    teraeye = os.path.join(root, "teraeye")
    run = lambda *args: subprocess.run([THZMAP, *args, "-q"], check=True)
    for seed in (1, 2):  # as test_e2e.py makes them through the page
        run("simulate", os.path.join(teraeye, "scene.json"), "-o", os.path.join(teraeye, f"out-seed{seed}"),
            "--seed", str(seed), "--photons", "12000", "--save-photon-map", "--threads", "2")
    # one channel, the path integrator (fires no photons, needs no map), 12 x 8 pixels
    # (columns x rows: a click on an image not square reads the row and column apart)
    one = json.loads(json.dumps(scene))
    one["channels"] = [{"name": "0.35 THz", "frequency_thz": 0.35, "relative_width": 0.01}]
    one["sensors"][0].update(resolution=[12, 8], noise={"netd_k": 2})  # and a measured cube
    one["format"] = "thzmap-scene/1.1"
    one["render"] = {"integrator": "path", "paths_per_sample": 1}
    with open(os.path.join(root, "teraeye", "path.json"), "w") as f:
        json.dump(one, f, indent=2)
    # and one that runs for minutes unless cancelled, in little memory
    one["sensors"][0].update(resolution=[256, 256])
    one["render"]["paths_per_sample"] = 100000
    with open(os.path.join(root, "teraeye", "slow.json"), "w") as f:
        json.dump(one, f, indent=2)
    # files the scene panels once choked on (TypeErrors) before validating them
    for name, doc in (("bad-objects.json", {"format": "thzmap-scene/1", "objects": {"a": 1}}),
                      ("bad-null.json", {"objects": [None, 5]})):
        with open(os.path.join(root, "teraeye", name), "w") as f:
            json.dump(doc, f)
    # text that is no JSON at all: opened after a scene, it showed that scene's panels
    with open(os.path.join(root, "teraeye", "not-json.json"), "w") as f:
        f.write("not json\n")
    # a bands run's directory (no images): plates whose emissivity peaks at 0.4 and 0.8 THz
    subprocess.run([THZMAP, "bands", os.path.join(REPO, "tests", "inputs", "analysis", "features.json"),
                    "-o", os.path.join(root, "teraeye", "out-bands-cli"), "--count", "2",
                    "--from-thz", "0.3", "--to-thz", "0.9", "--step-ghz", "100", "--paths", "4", "-q"],
                   check=True)
    # a batch of three frames of the path scene, its walls warming from 280 to 340 K: each
    # frame's own colour scale would give 280 K in the first the colour of 340 K in the last
    with open(os.path.join(teraeye, "sequence.json"), "w") as f:
        json.dump({"format": "thzmap-sequence/1", "scene": "path.json", "fps": 1, "frames": 3,
                   "keyframes": [{"time_s": 0, "objects": {"box": {"temperature_k": 280}}},
                                 {"time_s": 2, "objects": {"box": {"temperature_k": 340}}}]}, f)
    run("batch", os.path.join(teraeye, "sequence.json"), "-o", os.path.join(teraeye, "out-batch"),
        "--no-movies", "--threads", "2")
    refresh.make_runs(run, teraeye)  # two seeds of two sensors and two channels
    return scene


def audit_fixes(driver, wait, patient, by_id, click_list, field, root):
    """What the audit of the page found (each failed before its fix): files that broke the
    scene panels, an object made a shell, a path-integrator scene simulated and rendered
    from the form, its one channel captioned, fields of other commands not sent, the JSON
    path of an error shown, and eight runs queued without the page freezing."""
    status = lambda: by_id("status").text
    state = lambda: by_id("validation-state").text
    by_id("tab-scene").click()
    for name in ("bad-objects.json", "bad-null.json"):
        click_list("files", name)
        wait.until(lambda d: f"opened teraeye/{name}" in status() or "Error" in status())
        wait.until(lambda d: "✗" in state())
        assert "Error" not in status(), status()
        log(f"{name}: {state()}, status {status()!r}")
    # the object's type decides its fields: a shell has a thickness
    click_list("files", "path.json")
    wait.until(lambda d: "✓" in state())
    # a file that does not parse, opened after it: none of path.json's objects, sensors or
    # plots under its name (they all stayed, with the status saying "opened not-json.json")
    click_list("files", "not-json.json")
    wait.until(lambda d: "opened teraeye/not-json.json" in status() and "✗" in state())
    assert not driver.find_elements(By.CSS_SELECTOR, "#objects li, #sensors li"), \
        by_id("objects").text
    assert "cylinder" not in by_id("material-plots").text, by_id("material-plots").text
    # where the text stops parsing: its line and column
    assert re.search(r"\(line 1:\d+\)", by_id("validation").text), by_id("validation").text
    log(f"not-json.json: {state()}, no objects or sensors shown")
    click_list("files", "path.json")
    wait.until(lambda d: "✓" in state())
    with open(os.path.join(root, "teraeye", "path.json")) as f:  # its sensor is 12 x 8
        readouts.sensor_frustum(driver, json.load(f)["sensors"][0])
    click_list("sensors", "cam")
    readouts.sensor_units(driver, {"sensors[0].position_m": "position (m)", "sensors[0].fov_deg": "horizontal fov (°)",
                                   "sensors[0].aperture_m2": "aperture (m²)"})
    click_list("objects", "cylinder-A")
    assert not driver.find_elements(By.CSS_SELECTOR, '.field[data-path="objects[1].thickness_m"]')
    # a shape's key with its unit once: "radius (m)" (it read "radius_m (m)")
    radius = field("objects[1].shape.radius_m").find_element(By.TAG_NAME, "label")
    assert radius.get_attribute("textContent").strip() == "radius (m)", radius.get_attribute("textContent")
    Select(field("objects[1].type").find_element(By.TAG_NAME, "select")).select_by_value("shell")
    wait.until(lambda d: d.find_elements(By.CSS_SELECTOR, '.field[data-path="objects[1].thickness_m"]'))
    log("a shell shows its thickness")
    click_list("files", "path.json")  # opened again: that edit dropped (a run reads the file)
    wait.until(lambda d: "unsaved" not in (by_id("scene-path").get_attribute("class") or ""))
    # Run: the scene open is path.json (the path integrator): no map to save, none to read
    by_id("tab-run").click()
    wait.until(lambda d: by_id("run-scene").get_attribute("value") == "teraeye/path.json")
    wait.until(lambda d: not by_id("run-save-map").is_selected() and not by_id("run-save-map").is_enabled())

    def start(command, out, **fields):
        Select(by_id("run-command")).select_by_visible_text(command)
        for name, value in fields.items():
            box = by_id(f"run-{name}")
            if box.is_enabled():
                box.clear()
                box.send_keys(value)
        by_id("run-out").clear()
        by_id("run-out").send_keys(out)
        # every text the status line shows from the click on: a short run's "queued" may
        # be replaced by its results' "loaded" before a poll reads it (a busy machine)
        driver.execute_script(
            "window.statusSeen = []; window.statusWatch?.disconnect();"
            "const s = document.getElementById('status');"
            "window.statusWatch = new MutationObserver(() => window.statusSeen.push(s.textContent));"
            "window.statusWatch.observe(s, {childList: true, characterData: true, subtree: true});")
        by_id("btn-run").click()
        said = lambda d: next((t for t in d.execute_script("return window.statusSeen")
                               if "queued" in t or "/api/" in t), None)
        patient(10).until(said)
        return said(driver)

    def final_state(out):
        row = lambda d: d.execute_script(
            "const r = [...document.querySelectorAll('#runs tbody tr')].find((x) => x.cells[3].textContent === arguments[0]);"
            "return r ? r.dataset.state : null;", out)
        patient(60, 0.1).until(lambda d: row(d) in ("done", "failed", "cancelled"))
        return row(driver)

    by_id("run-seed").clear()
    by_id("run-seed").send_keys("3")  # left in the form: batch and render take no seed
    said = start("simulate", "teraeye/out-path-sim")
    assert "queued" in said, said
    assert final_state("teraeye/out-path-sim") == "done"
    # it opens in Results: its one channel is captioned as such
    wait.until(lambda d: "out-path-sim" in status() and "loaded" in status())
    by_id("tab-results").click()
    Select(by_id("res-view")).select_by_value("image")
    Select(by_id("res-quantity")).select_by_value("brightness_temperature")
    caption = lambda: by_id("image-info").get_attribute("textContent")
    wait.until(lambda d: caption().startswith("brightness temperature, "))
    shown = caption()
    assert shown.startswith("brightness temperature, channel 1 (0.35 THz)"), shown
    tb = np.fromfile(os.path.join(root, "teraeye", "out-path-sim", "cam.brightness_temperature.img"),
                     "<f4").reshape(1, 8, 12)
    readouts.pixel_not_square(driver, wait, by_id, tb, 5, 9)
    measured = np.fromfile(os.path.join(root, "teraeye", "out-path-sim", "cam.measured_brightness_temperature.img"),
                           "<f4").reshape(1, 8, 12)
    readouts.measured_pixel(driver, wait, by_id, measured, 5, 9)
    log(f"one-channel run: {shown[:60]!r}; pixel (5, 9) of 8 x 12 read back, measured too")
    by_id("tab-run").click()
    said = start("render", "teraeye/out-path-render", **{"photon-map": ""})
    assert "queued" in said, said
    assert not by_id("run-seed").is_enabled() and not by_id("run-photons").is_enabled()
    assert final_state("teraeye/out-path-render") == "done"
    # a render of the photon-map scene from its map, with the seed still filled in
    by_id("run-scene").clear()
    by_id("run-scene").send_keys("teraeye/scene.json")
    said = start("render", "teraeye/out-render", **{"photon-map": "teraeye/out-seed1/photon-map.thzpm"})
    assert "queued" in said, said
    assert final_state("teraeye/out-render") == "done"
    log("simulate and render of the path scene, render from a map: done")
    # a run that fails: its error in its row and in the status line
    said = start("render", "teraeye/out-bad-map", **{"photon-map": "teraeye/path.json"})
    assert "queued" in said and final_state("teraeye/out-bad-map") == "failed", said
    log(f"a run that failed: {readouts.failed_run(driver, wait, by_id, 'teraeye/out-bad-map', 'path.json')!r}")
    # an error names where in the request it is
    driver.execute_script(readouts.RECORD_RUNS)
    said = start("bands", "teraeye/out-bands", count="0")
    assert "$.options.count" in said, said
    # bands takes the seed (still 3) and the count, nothing else
    sent = driver.execute_script("return window.sentRuns.at(-1)")
    assert sent["options"] == {"seed": 3, "count": 0}, sent
    log(f"error: {said!r}")
    # eight runs queued: the page still answers (one stream, not one per run)
    by_id("run-count").clear()
    by_id("run-count").send_keys("4")
    by_id("run-scene").clear()
    by_id("run-scene").send_keys("teraeye/slow.json")
    for k in range(8):
        said = start("simulate", f"teraeye/out-many-{k}", photons="")
        assert "queued" in said, said
    answered = driver.execute_async_script(
        "const done = arguments[arguments.length - 1];"
        "const t = setTimeout(() => done('no answer in 5 s'), 5000);"
        "fetch('/api/info').then((r) => { clearTimeout(t); done(r.status); }, (e) => done(String(e)));")
    assert answered == 200, answered
    # the page's own requests too: a validation of the scene
    by_id("tab-scene").click()
    click_list("files", "scene.json")
    wait.until(lambda d: "✓" in state())
    log("eight runs queued: the page still answers")
    by_id("tab-run").click()
    driver.execute_async_script(
        "const done = arguments[arguments.length - 1];"
        "fetch('/api/runs').then((r) => r.json()).then((runs) => Promise.all(runs"
        ".filter((r) => r.state === 'queued' || r.state === 'running')"
        ".map((r) => fetch(`/api/runs/${r.id}`, {method: 'DELETE'})))).then(() => done(), () => done());")
    states = [final_state(f"teraeye/out-many-{k}") for k in range(8)]
    assert states == ["cancelled"] * 8, states
    user.cancelled_not_error(wait, by_id)
    # the errors the browser logged are the bands run's, asked for above
    errors = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"
              and "/api/runs - Failed to load resource" not in e["message"]
              and "(at $.options.count)" not in e["message"]]
    assert not errors, errors


def bands_results(driver, wait, by_id, click_list, root, shot):
    """A bands run's directory opens in Results as its chosen channels, the best set of
    each size with its score, and its figures (it said "no images here"); an image run
    opened after it hides them again."""
    by_id("tab-results").click()
    driver.execute_script("window.thzmap.results.browse('teraeye')")
    click_list("outputs", "out-bands-cli/")
    wait.until(lambda d: by_id("bands-pane").is_displayed())
    doc = json.load(open(os.path.join(root, "teraeye", "out-bands-cli", "bands.json")))
    assert doc["selected_thz"] == [0.4, 0.8], doc["selected_thz"]
    summary = by_id("bands-summary").text
    assert "chosen 0.4, 0.8 THz (relative width 1 %, 1 %)" in summary, summary
    assert f"({' vs '.join(doc['worst_pair'])})" in summary, summary
    rows = driver.execute_script(
        "return [...document.querySelectorAll('#bands-table tbody tr')].map((r) =>"
        " [...r.cells].map((c) => c.textContent));")
    assert [r[0] for r in rows] == ["1", "2"], rows
    for row, k in zip(rows, doc["per_k"]):
        assert row[1] == ", ".join("%g" % v for v in k["selected_thz"]), (row, k)
        assert abs(float(row[3]) - k["score"]) <= 5e-4 * max(1.0, k["score"]), (row, k)
        assert row[4] == " vs ".join(k["worst_pair"]), (row, k)
        assert abs(float(row[5]) - k["mean_jm"]) <= 5e-4 * max(1.0, k["mean_jm"]), (row, k)
    # the chosen set's worst-pair JM (its score) and mean JM, each where the line names it
    m = re.search(r"worst-pair JM (\S+) of 2 .*, mean JM (\S+);", summary)
    near = lambda text, value: abs(float(text) - value) <= 5e-4 * max(1.0, value)
    assert m and near(m.group(1), doc["score"]) and near(m.group(2), doc["mean_jm"]), \
        (summary, doc["score"], doc["mean_jm"])
    figures = lambda d: d.execute_script(
        "return [...document.querySelectorAll('#bands-figures img')].map((i) =>"
        " [i.alt, i.complete && i.naturalWidth > 0]);")
    wait.until(lambda d: all(ok for _, ok in figures(d)))
    assert [name for name, _ in figures(driver)] == ["bands-score.png", "bands-spectra.png"], figures(driver)
    # the image's controls and the pixel column of the run opened before: hidden
    assert not by_id("image-pane").is_displayed() and not by_id("res-sensor").is_displayed()
    assert not by_id("pixel-info").is_displayed()
    shot("bands")
    log(f"bands run: {summary[:70]!r}, {len(rows)} sets, figures shown")
    click_list("outputs", "..")
    click_list("outputs", "out-seed1/")
    wait.until(lambda d: "loaded" in by_id("status").text and "out-seed1" in by_id("status").text)
    assert not by_id("bands-pane").is_displayed() and by_id("image-pane").is_displayed()
    assert by_id("res-sensor").is_displayed() and by_id("pixel-info").is_displayed()


def unsaved_edits(driver, wait, by_id, click_list, field):
    """A second audit (2026-12-06): a run started with edits not saved ran the file on
    disk without a word; an edit of a field while the JSON text did not parse rewrote the
    text from the last valid document, losing the edits made in the text; "Save as" left
    the Run tab on the old file."""
    status = lambda: by_id("status").text
    by_id("tab-scene").click()
    click_list("files", "path.json")
    wait.until(lambda d: by_id("scene-path").get_attribute("value") == "teraeye/path.json")
    wait.until(lambda d: "✓" in by_id("validation-state").text)
    unsaved = lambda: "unsaved" in (by_id("scene-path").get_attribute("class") or "")
    assert not unsaved()
    click_list("objects", "cylinder-A")
    box = field("objects[1].temperature_k").find_element(By.TAG_NAME, "input")
    box.send_keys(Keys.CONTROL, "a")
    box.send_keys("400")
    box.send_keys(Keys.TAB)
    wait.until(lambda d: unsaved())
    by_id("tab-run").click()
    wait.until(lambda d: by_id("run-scene").get_attribute("value") == "teraeye/path.json")
    by_id("btn-run").click()
    wait.until(lambda d: "not saved" in status())
    log(f"a run with edits not saved: {status()[:80]!r}")
    # the text broken: the fields are out of use, the text's edits kept
    by_id("tab-scene").click()
    text = by_id("scene-text").get_attribute("value")
    broken = text.replace('"name"', '"name-edited-in-text"', 1).rstrip().rstrip("}") + ",}"
    driver.execute_script("const t = document.getElementById('scene-text'); t.value = arguments[0];"
                          "t.dispatchEvent(new Event('input'));", broken)
    wait.until(lambda d: d.execute_script("return document.getElementById('props').inert"))
    assert by_id("scene-text").get_attribute("value") == broken
    # mended in the text: the fields come back; saved as another file, which Run then takes
    driver.execute_script("const t = document.getElementById('scene-text'); t.value = arguments[0];"
                          "t.dispatchEvent(new Event('input'));", text)
    wait.until(lambda d: not d.execute_script("return document.getElementById('props').inert"))
    by_id("scene-path").clear()
    by_id("scene-path").send_keys("teraeye/saved-as.json")
    by_id("btn-save").click()
    wait.until(lambda d: "saved teraeye/saved-as.json" in status())
    assert not unsaved()
    by_id("tab-run").click()
    wait.until(lambda d: by_id("run-scene").get_attribute("value") == "teraeye/saved-as.json")
    log("fields out of use while the text is broken; Save as moves the Run tab to the new file")


def main():
    s = e2e_session.Session(THZMAP, SHOTS, "failure-audit")
    root = s.root
    scene = make_root(root)
    try:
        s.start()
        driver, wait, patient, by_id = s.driver, s.wait, s.patient, s.by_id
        shot, click_list, field = s.shot, s.click_list, s.field
        # the status line names the build as `thzmap --version` does, its revision too
        # (/api/info's "revision"; the line said "thzmap 0.1.0" alone)
        version = subprocess.run([THZMAP, "--version"], capture_output=True, text=True, check=True).stdout.strip()
        assert "(revision " in version, version
        wait.until(lambda d: by_id("status").text.startswith("thzmap "))
        assert by_id("status").text.startswith(f"{version} · root "), (by_id("status").text, version)
        click_list("files", "teraeye/")
        click_list("files", "scene.json")
        wait.until(lambda d: "✓" in by_id("validation-state").text)
        audit_fixes(driver, wait, patient, by_id, click_list, field, root)
        bands_results(driver, wait, by_id, click_list, root, shot)
        unsaved_edits(driver, wait, by_id, click_list, field)
        t_user = time.monotonic()
        lib, legend = user.library_material(driver, wait, by_id, click_list, field, 1, "cylinder-A")
        width = user.narrow_window(driver, wait, by_id)
        out = os.path.join(root, "teraeye", "out-seed1")
        bands = len(json.load(open(os.path.join(out, "summary.json")))["channels"])
        oid = np.fromfile(os.path.join(out, "cam.object_id.img"), "<f4").reshape(32, 32)
        rows, cols = np.nonzero(oid == [o["name"] for o in scene["objects"]].index("cylinder-C"))
        row, col = int(rows[len(rows) // 2]), int(cols[len(cols) // 2])
        diff = user.diff_follows_channel(driver, wait, by_id, "teraeye/out-seed1", "teraeye/out-seed2")
        diff += "; " + user.pixel_of_quantity(driver, wait, by_id, out, bands, (32, 32), row, col)
        ran = user.run_integrator(driver, wait, by_id, root, "teraeye/saved-as.json", "teraeye/out-integrator")
        log(f"library material {lib} chosen, legend {legend} in its curves' colours; 3D view {width} px "
            f"at 800 px; {diff!r}; a path scene run as {ran} ({time.monotonic() - t_user:.1f} s)")
        # the run the Run tab started last opens in Results when done: not over those below
        wait.until(lambda d: d.execute_script("return window.thzmap.results.base") == "teraeye/out-integrator/cam")
        log(view.fits_window(driver, wait, by_id, shot))
        log(view.marker(driver, wait, by_id, shot, (32, 32), row, col))
        log(view.pixel_follows_run(driver, wait, by_id, click_list, root, row, col))
        log(view.frames_scale(driver, wait, by_id, click_list, root, shot))
        log(view.damaged_summary(driver, wait, by_id, click_list, root))
        log(refresh.diff_compared_again(driver, wait, by_id, root))
        log(refresh.value_follows_quantity(driver, wait, by_id, root, bands, (32, 32), row, col))
        log(refresh.bands_empties_pixel(driver, wait, by_id, click_list, (32, 32), row, col))
        log(refresh.empty_dir_clears(driver, wait, by_id, click_list, root, (32, 32), row, col))
        log(refresh.bar_follows_image(driver, wait, by_id, shot))
        log(refresh.run_warnings(driver, wait, by_id, root))
        log(refresh.diff_names_runs(driver, wait, by_id))
        log(refresh.one_channel_plot(driver, wait, by_id))
    except Exception:
        s.failed()
        raise
    finally:
        s.close()
    log("PASS")


if __name__ == "__main__":
    main()
