"""The Results view as a user looks at it (for test_e2e_audit.py, session 57), each a fault
noticed and left by earlier sessions: the pixel clicked had no mark on the image, so the
Pixel column's spectrum was of a pixel the user had to remember; the image kept its size
when the window was resized (cut off at the pane's edge in a narrower one); a batch's
frames were each coloured on their own scale, so one colour meant another temperature in
the next frame; a summary.json that was there but damaged was shown as no summary at
all; the Pixel column kept a pixel's values when another run or frame was opened. Each
check failed before its fix (web/src, src/serve/serve_results.c)."""
import json
import os
import re
import shutil

import numpy as np
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select

import e2e_readouts as readouts

GEOMETRY = ("const c = document.getElementById(arguments[0]); const r = c.getBoundingClientRect();"
            "const m = document.getElementById(arguments[0] + '-marker');"
            "const box = m.hasAttribute('hidden') ? null : m.querySelector('path.over').getBoundingClientRect();"
            "const over = m.querySelector('path.over'), under = m.querySelector('path.under');"
            "return {left: r.left + c.clientLeft, top: r.top + c.clientTop, width: c.clientWidth,"
            " height: c.clientHeight, box: box && [box.left, box.top, box.width, box.height],"
            " shown: !m.hasAttribute('hidden') && getComputedStyle(m).display !== 'none',"
            " strokes: over && [getComputedStyle(over).stroke, getComputedStyle(under).stroke],"
            " at: [m.dataset.row, m.dataset.col]};")


def marked_at(driver, canvas_id, size, row, col):
    """The mark is shown, white over black, centred on pixel (row, col) of the image as
    drawn now (to a screen pixel), a box at least as large as the pixel and 9 px."""
    g = driver.execute_script(GEOMETRY, canvas_id)
    assert g["shown"] and g["box"], f"no mark on the pixel clicked: {g}"
    assert g["strokes"] == ["rgb(255, 255, 255)", "rgb(0, 0, 0)"], g["strokes"]
    cell = g["width"] / size[1]
    x, y = g["left"] + (col + 0.5) * cell, g["top"] + (row + 0.5) * cell
    bx, by, bw, bh = g["box"]  # the ticks included: the box's centre is the path's
    assert abs(bx + bw / 2 - x) <= 1 and abs(by + bh / 2 - y) <= 1, \
        f"mark centred at ({bx + bw / 2}, {by + bh / 2}), pixel ({row}, {col}) at ({x}, {y}); {g}"
    assert bw >= max(cell, 9) + 12, f"mark {bw} px for a pixel of {cell} px"
    assert g["at"] == [str(row), str(col)], g["at"]
    return cell


def open_run(driver, wait, by_id, out):
    driver.execute_script("window.thzmap.showTab('results'); window.thzmap.results.open(arguments[0])", out)
    wait.until(lambda d: f"{out}/cam:" in by_id("status").text and "loaded" in by_id("status").text)
    Select(by_id("res-view")).select_by_value("image")


def marker(driver, wait, by_id, shot, size, row, col):
    """A pixel clicked is marked on the image (of the run open, size rows x columns); the
    mark stays on it when the image is drawn again (another channel) and moves with it
    when the window narrows."""
    Select(by_id("res-quantity")).select_by_value("brightness_temperature")
    readouts.click_pixel(driver, wait, by_id, "image", size[0], size[1], row, col)
    wait.until(lambda d: by_id("pixel-info").get_attribute("data-row") == str(row)
               and by_id("pixel-info").get_attribute("data-col") == str(col))
    wide = marked_at(driver, "image", size, row, col)
    shot("marker")
    channel = Select(by_id("res-channel"))
    channel.select_by_index(3)
    wait.until(lambda d: by_id("image-info").text.startswith("brightness temperature, channel 4 ("))
    marked_at(driver, "image", size, row, col)
    window = driver.get_window_size()
    try:
        driver.set_window_size(800, 600)
        wait.until(lambda d: driver.execute_script(GEOMETRY, "image")["width"] < size[1] * wide)
        narrow = marked_at(driver, "image", size, row, col)
        shot("marker-800")
    finally:
        driver.set_window_size(window["width"], window["height"])
    wait.until(lambda d: driver.execute_script(GEOMETRY, "image")["width"] == size[1] * wide)
    marked_at(driver, "image", size, row, col)
    channel.select_by_index(0)
    return f"pixel ({row}, {col}) marked: {wide:g} px a pixel at 1400 px, {narrow:g} px at 800 px"


def pixel_values(driver):
    """The Pixel column's row, column and Tb values (None, None, [] when it holds none),
    read at once (the table is rebuilt while a frame opens)."""
    row, col, values = driver.execute_script(
        "const i = document.getElementById('pixel-info');"
        "return [i.dataset.row ?? null, i.dataset.col ?? null,"
        " [...document.querySelectorAll('#pixel-table td.tb')].map((td) => td.dataset.value)];")
    return row, col, [float(v) for v in values]


def pixel_follows_run(driver, wait, by_id, click_list, root, row, col):
    """The pixel clicked (row, col of out-seed1, marked) follows the run open: another run
    of the same size shows its values there; a batch's frame of 8 x 12 pixels, which has
    no such pixel, empties the Pixel column and takes the mark off; a pixel clicked on
    frame 1 shows frame 3's values once frame 3 is chosen. (The column kept the last
    pixel's values under every run and frame opened after it.)"""
    cube = lambda out, rows, cols: np.fromfile(
        os.path.join(root, "teraeye", out, "cam.brightness_temperature.img"), "<f4").reshape(-1, rows, cols)
    seed1, seed2 = cube("out-seed1", 32, 32), cube("out-seed2", 32, 32)
    assert (seed1[:, row, col] != seed2[:, row, col]).any(), "the two seeds agree at the pixel"
    assert pixel_values(driver) == (str(row), str(col), [float(v) for v in seed1[:, row, col]]), \
        pixel_values(driver)
    open_run(driver, wait, by_id, "teraeye/out-seed2")
    want = (str(row), str(col), [float(v) for v in seed2[:, row, col]])
    wait.until(lambda d: pixel_values(d) == want,
               f"out-seed2 open, the Pixel column does not show its {want}")
    marked_at(driver, "image", (32, 32), row, col)

    out = os.path.join(root, "teraeye", "out-batch")
    dirs = [f["dir"] for f in json.load(open(os.path.join(out, "batch.json")))["frames"]]
    frames = [cube(os.path.join("out-batch", d), 8, 12) for d in dirs]
    assert row >= 8 or col >= 12, (row, col)
    driver.execute_script("window.thzmap.results.browse('teraeye')")
    click_list("outputs", "out-batch/")
    wait.until(lambda d: "(1/3)" in by_id("frame-name").text and pixel_values(d) == (None, None, []),
               "frame 1 (8 x 12 pixels) open, the Pixel column still holds a pixel")
    assert by_id("pixel-info").text == "Click a pixel of the image.", by_id("pixel-info").text
    assert not driver.execute_script(GEOMETRY, "image")["shown"], "a mark on a pixel the frame has not"
    readouts.click_pixel(driver, wait, by_id, "image", 8, 12, 5, 7)
    wait.until(lambda d: pixel_values(d) == ("5", "7", [float(v) for v in frames[0][:, 5, 7]]))
    assert (frames[0][:, 5, 7] != frames[2][:, 5, 7]).any(), "frames 1 and 3 agree at the pixel"
    driver.execute_script("const f = document.getElementById('frame'); f.value = 2;"
                          "f.dispatchEvent(new Event('input'));")
    want = ("5", "7", [float(v) for v in frames[2][:, 5, 7]])
    wait.until(lambda d: "(3/3)" in by_id("frame-name").text and pixel_values(d) == want,
               f"frame 3 chosen, the Pixel column does not show its {want}")
    marked_at(driver, "image", (8, 12), 5, 7)
    return f"pixel ({row}, {col}) followed out-seed2, dropped for an 8 x 12 frame; (5, 7) followed frame 3"


def fits_window(driver, wait, by_id, shot):
    """The image drawn at the window's size when the window is resized, nothing else
    changed: narrower, it and its colour bar fit the pane (a whole number of screen pixels
    a pixel); wider again, it is as large as before. Of out-seed1's image."""
    open_run(driver, wait, by_id, "teraeye/out-seed1")
    size = lambda: driver.execute_script(
        "const p = document.getElementById('image-pane').getBoundingClientRect();"
        "const b = document.getElementById('colourbar').getBoundingClientRect();"
        "const c = document.getElementById('image');"
        "return [c.clientWidth, c.width, b.right, p.right];")
    wide, cols, _, _ = size()
    window = driver.get_window_size()
    try:
        for width in (800, 1000):
            driver.set_window_size(width, 600)
            wait.until(lambda d: size()[0] < wide, f"at {width} px the image stays {size()[0]} px wide, "
                       f"its colour bar ending at {size()[2]} px, the pane at {size()[3]} px")
            narrow, _, bar_right, pane_right = size()
            assert bar_right <= pane_right and narrow % cols == 0, \
                f"at {width} px: image {narrow} px for {cols} columns, colour bar ends {bar_right}, pane {pane_right}"
            if width == 800:
                at_800 = narrow
                shot("resized-800")
    finally:
        driver.set_window_size(window["width"], window["height"])
    wait.until(lambda d: size()[0] == wide, f"the image {size()[0]} px wide again, not {wide} px")
    return f"the image {wide} px wide at {window['width']} px, {at_800} px at 800 px, {wide} px again"


def frames_scale(driver, wait, by_id, click_list, root, shot):
    """A batch's frames on one colour scale, the 1st to 99th percentile over all its
    frames, said in the caption and the colour bar; unlocked, each frame's own."""
    driver.execute_script(readouts.HOOK)
    driver.execute_script("window.thzmap.results.browse('teraeye')")
    click_list("outputs", "out-batch/")
    wait.until(lambda d: by_id("frames").is_displayed() and "(1/3)" in by_id("frame-name").text)
    out = os.path.join(root, "teraeye", "out-batch")
    dirs = [f["dir"] for f in json.load(open(os.path.join(out, "batch.json")))["frames"]]
    tb = [np.fromfile(os.path.join(out, d, "cam.brightness_temperature.img"), "<f4").reshape(8, 12) for d in dirs]
    lo, hi = readouts.percentiles(np.concatenate([t.ravel() for t in tb]))
    own = readouts.percentiles(tb[2].ravel())
    assert own[0] > lo + 10, f"the frames' temperatures barely differ: {own} against {lo, hi}"

    def coloured(frame, lo, hi):
        rgb = readouts.canvas_rgb(driver, "image")
        want = readouts.viridis(np.round((tb[frame] - lo) * (255 / (hi - lo))) / 255)
        return rgb.shape == want.shape and np.abs(rgb - want).max() <= 3

    caption = lambda: by_id("image-info").get_attribute("textContent")
    scale = r"percentile of all 3 frames \(one scale\): (\S+) to (\S+) K$"
    assert by_id("frames-lock").is_selected(), "the frames' scale is not locked by default"
    for frame in (0, 2):
        driver.execute_script("window.canvasText = [];")
        driver.execute_script("const f = document.getElementById('frame'); f.value = arguments[0];"
                              "f.dispatchEvent(new Event('input'));", frame)
        wait.until(lambda d: f"({frame + 1}/3)" in by_id("frame-name").text and coloured(frame, lo, hi),
                   f"frame {frame + 1} not coloured over {lo} to {hi} K, the frames' percentiles: {caption()!r}")
        m = re.search(scale, caption())
        assert m and readouts.close(float(m.group(1)), lo) and readouts.close(float(m.group(2)), hi), \
            (caption(), lo, hi)
        labels, _ = readouts.bar_texts(driver, "colourbar")
        assert readouts.close(labels[0], hi) and readouts.close(labels[-1], lo), (labels, lo, hi)
    shot("frames")
    by_id("frames-lock").click()  # each frame its own scale, as before
    wait.until(lambda d: coloured(2, *own) and "frames" not in caption())
    by_id("frames-lock").click()
    wait.until(lambda d: coloured(2, lo, hi))
    return f"frames on one scale, {lo:.2f} to {hi:.2f} K (frame 3's own: {own[0]:.2f} to {own[1]:.2f} K)"


def damaged_summary(driver, wait, by_id, click_list, root):
    """A run whose summary.json is cut short: the page says so above its image, naming the
    file and where its JSON breaks; another run opened after it says nothing."""
    src = os.path.join(root, "teraeye", "out-seed1")
    dst = os.path.join(root, "teraeye", "out-damaged")
    shutil.copytree(src, dst, ignore=lambda d, names: [n for n in names if n.endswith(".thzpm")])
    text = open(os.path.join(dst, "summary.json")).read()
    open(os.path.join(dst, "summary.json"), "w").write(text[:len(text) // 2])
    by_id("tab-results").click()
    driver.execute_script("window.thzmap.results.browse('teraeye')")
    click_list("outputs", "out-damaged/")
    wait.until(lambda d: d.find_elements(By.ID, "res-note") and by_id("res-note").is_displayed(),
               "nothing says that out-damaged/summary.json is damaged")
    note = by_id("res-note").text
    assert note.startswith("damaged: teraeye/out-damaged/summary.json: line "), note
    wait.until(lambda d: "out-damaged/cam:" in by_id("status").text)  # its image all the same
    click_list("outputs", "..")
    click_list("outputs", "out-seed1/")
    wait.until(lambda d: "out-seed1/cam:" in by_id("status").text)
    assert not by_id("res-note").is_displayed(), by_id("res-note").text
    return f"a damaged summary: {note[:90]!r}"
