"""What the Results view drew again and what it left as it was (for test_e2e_audit.py,
session 57, second pass), each a fault left after the Pixel column learned to follow the
run and frame opened: the A/B difference compared again (another sensor or channel) kept
the clicked pixel's A − B of the comparison before; the Pixel column's line of the value
shown kept the quantity and channel of the click when another was chosen; a `bands`
run's directory, which has no pixels, left the column holding the pixel of the run
before, shown again under the next run opened; the colour bar stayed 300 px tall beside
an image drawn 192 px tall at 800 x 600, so the pane scrolled; a run's warnings (its
summary.json's) were nowhere on the page, so a σ of 0.000 K not estimated read as exact;
the A/B difference's caption did not name the runs compared, under A and B boxes that
each run opened fills anew; a one-channel spectrum's frequency axis ran from −0.15 THz,
its first tick's label over the lowest y tick's; a pixel of the difference read, in the
image view, as of the image shown; a directory holding neither images nor bands.json
left the run before's image on screen. Each check failed before its fix
(web/src/results.js, plots.js)."""
import json
import os
import re

import numpy as np
from selenium.webdriver.support.ui import Select

import e2e_readouts as readouts
import e2e_view as view


def make_runs(thzmap_run, teraeye):
    """Two seeds of the path scene with two channels and two sensors, cam (12 x 8) and
    small (6 x 4), eight paths a sample (standard errors to compare in σ)."""
    with open(os.path.join(teraeye, "path.json")) as f:
        scene = json.load(f)
    scene["channels"] = [{"name": "0.35 THz", "frequency_thz": 0.35, "relative_width": 0.01},
                         {"name": "0.5 THz", "frequency_thz": 0.5, "relative_width": 0.01}]
    cam = scene["sensors"][0]
    cam.pop("noise")
    scene["sensors"].append(dict(cam, name="small", resolution=[6, 4]))
    scene["render"]["paths_per_sample"] = 8
    with open(os.path.join(teraeye, "two.json"), "w") as f:
        json.dump(scene, f, indent=2)
    for seed in (1, 2):
        thzmap_run("simulate", os.path.join(teraeye, "two.json"), "-o", os.path.join(teraeye, f"out-two{seed}"),
                   "--seed", str(seed), "--threads", "2")


def diff_z(root, sensor, shape, band):
    """(Tb_A − Tb_B) / √(σ_A² + σ_B²) of out-two1 and out-two2, channel band + 1."""
    def cubes(out):
        read = lambda qn: np.fromfile(os.path.join(root, "teraeye", out, f"{sensor}.{qn}.img"),
                                      "<f4").reshape(2, *shape)[band]
        return read("brightness_temperature"), read("radiance_stderr")
    (ta, sa), (tb, sb) = cubes("out-two1"), cubes("out-two2")
    hz = [0.35e12, 0.5e12][band]
    with np.errstate(invalid="ignore", divide="ignore"):  # σ 0 (one value over the paths): NaN
        return (ta.astype(float) - tb) / np.hypot(readouts.tb_sigma(ta, sa, hz), readouts.tb_sigma(tb, sb, hz))


def pixel_diff(driver):
    """The row, column and A − B (σ) the Pixel column shows, None for each it does not."""
    row, col, text = driver.execute_script(
        "const i = document.getElementById('pixel-info'); return [i.dataset.row ?? null, i.dataset.col ?? null,"
        " i.textContent];")
    m = re.search(r"A − B = (\S+) σ$", text)
    return row, col, float(m.group(1)) if m else None


def diff_compared_again(driver, wait, by_id, root):
    """A pixel clicked on the difference of channel 1 shows the A − B of channel 2 once
    channel 2 is chosen (each worked out here from the cubes), and is emptied, its mark
    taken off, when the sensor chosen (small, 6 x 4) has no such pixel."""
    view.open_run(driver, wait, by_id, "teraeye/out-two1")
    Select(by_id("res-view")).select_by_value("diff")
    for box, run in (("diff-a", "teraeye/out-two1"), ("diff-b", "teraeye/out-two2")):
        by_id(box).clear()
        by_id(box).send_keys(run)
    Select(by_id("res-sensor")).select_by_value("cam")
    Select(by_id("res-channel")).select_by_index(0)
    by_id("btn-diff").click()
    wait.until(lambda d: "channel 1 (" in by_id("diff-info").text and "%" in by_id("diff-info").text)
    z1, z2 = diff_z(root, "cam", (8, 12), 0), diff_z(root, "cam", (8, 12), 1)
    # a pixel that sensor small has not, whose A − B differs between the channels
    row, col = max(((r, c) for r in range(4, 8) for c in range(6, 12)), key=lambda rc: np.nan_to_num(
        abs(z1[rc] - z2[rc])) * (rc[0] != rc[1]))
    assert abs(z1[row, col] - z2[row, col]) > 0.1, (z1[row, col], z2[row, col])
    near = lambda shown, z: shown is not None and abs(shown - z) <= 1e-3 * abs(z) + 1e-4
    readouts.click_pixel(driver, wait, by_id, "diff-image", 8, 12, row, col)
    wait.until(lambda d: near(pixel_diff(d)[2], z1[row, col]), f"{pixel_diff(driver)} for {z1[row, col]}")
    Select(by_id("res-channel")).select_by_index(1)
    wait.until(lambda d: "channel 2 (" in by_id("diff-info").text and "%" in by_id("diff-info").text)
    wait.until(lambda d: pixel_diff(d)[:2] == (str(row), str(col)) and near(pixel_diff(d)[2], z2[row, col]),
               f"channel 2 compared: the Pixel column shows {pixel_diff(driver)}, channel 2's A − B is "
               f"{z2[row, col]:.4g} σ (channel 1's {z1[row, col]:.4g} σ)")
    view.marked_at(driver, "diff-image", (8, 12), row, col)
    said = f"({row}, {col}) A − B {pixel_diff(driver)[2]} σ at channel 2"
    # in the image view (no mark there) the column says which image its pixel is of
    Select(by_id("res-view")).select_by_value("image")
    assert by_id("pixel-info").text.startswith(f"row {row}, column {col} of the A/B difference: A − B = "), \
        f"the image view shows {by_id('pixel-info').text!r}, a pixel of the A/B difference"
    Select(by_id("res-view")).select_by_value("diff")
    Select(by_id("res-sensor")).select_by_value("small")
    wait.until(lambda d: pixel_diff(d) == (None, None, None) and not d.execute_script(view.GEOMETRY, "diff-image")["shown"],
               f"sensor small (6 x 4) compared: the Pixel column still shows {pixel_diff(driver)}")
    assert by_id("pixel-info").text == "Click a pixel of the image.", by_id("pixel-info").text
    Select(by_id("res-sensor")).select_by_value("cam")
    Select(by_id("res-view")).select_by_value("image")
    return said + "; emptied for sensor small (6 x 4)"


def shown_line(driver):
    """The Pixel column's line of the value of the image shown: [text, value], or None."""
    return driver.execute_script(
        "const e = document.getElementById('pixel-shown'); return e && [e.textContent, Number(e.dataset.value)];")


def value_follows_quantity(driver, wait, by_id, root, bands, size, row, col):
    """A pixel clicked on out-seed1's power image of channel 2: radiance chosen, the line
    gives the radiance cube's value there in its unit; channel 3 chosen, channel 3's;
    brightness temperature chosen, no line (the spectrum is of it)."""
    view.open_run(driver, wait, by_id, "teraeye/out-seed1")
    cube = lambda qn: np.fromfile(os.path.join(root, "teraeye", "out-seed1", f"cam.{qn}.img"),
                                  "<f4").reshape(bands, *size)[:, row, col]
    Select(by_id("res-quantity")).select_by_value("power")
    Select(by_id("res-channel")).select_by_index(1)
    readouts.click_pixel(driver, wait, by_id, "image", *size, row, col)
    wait.until(lambda d: (shown_line(d) or [""])[0].startswith("power, channel 2 ("))
    radiance = cube("radiance")
    for band, choose in ((1, lambda: Select(by_id("res-quantity")).select_by_value("radiance")),
                         (2, lambda: Select(by_id("res-channel")).select_by_index(2))):
        choose()
        want = float(radiance[band])
        wait.until(lambda d: shown_line(d) and shown_line(d)[1] == want
                   and shown_line(d)[0].startswith(f"radiance, channel {band + 1} ("),
                   f"radiance of channel {band + 1} chosen: the Pixel column says {shown_line(driver)}, "
                   f"the cube {want:.4g} W m-2 sr-1 Hz-1")
    line = shown_line(driver)[0]
    assert line.endswith(" W m-2 sr-1 Hz-1"), line
    Select(by_id("res-quantity")).select_by_value("brightness_temperature")
    wait.until(lambda d: shown_line(d) is None, f"brightness temperature chosen, the column still says {shown_line(driver)}")
    Select(by_id("res-channel")).select_by_index(0)
    return f"value line followed: {line!r}"


def bands_empties_pixel(driver, wait, by_id, click_list, size, row, col):
    """A pixel clicked on out-seed1, then the bands run's directory opened: the Pixel
    column empty and the mark off, and still so when out-seed1 is opened again."""
    view.open_run(driver, wait, by_id, "teraeye/out-seed1")
    readouts.click_pixel(driver, wait, by_id, "image", *size, row, col)
    wait.until(lambda d: view.pixel_values(d)[:2] == (str(row), str(col)))
    driver.execute_script("window.thzmap.results.browse('teraeye')")
    click_list("outputs", "out-bands-cli/")
    wait.until(lambda d: by_id("bands-pane").is_displayed())
    assert view.pixel_values(driver) == (None, None, []), \
        f"a bands run's directory open, the Pixel column holds {view.pixel_values(driver)}"
    view.open_run(driver, wait, by_id, "teraeye/out-seed1")
    assert view.pixel_values(driver) == (None, None, []) and not driver.execute_script(view.GEOMETRY, "image")["shown"], \
        f"out-seed1 opened after the bands run: the Pixel column shows {view.pixel_values(driver)} of before"
    assert by_id("pixel-info").text == "Click a pixel of the image.", by_id("pixel-info").text
    return "a bands run's directory empties the Pixel column"


def empty_dir_clears(driver, wait, by_id, click_list, root, size, row, col):
    """A directory holding neither images nor bands.json opened after out-seed1, a pixel
    clicked: the status line says so, and the run before's image, its caption, its
    controls and the Pixel column are gone (the image stayed, under a line saying there
    was none); out-seed1 opened again shows its image."""
    os.makedirs(os.path.join(root, "teraeye", "notes"), exist_ok=True)
    with open(os.path.join(root, "teraeye", "notes", "readme.txt"), "w") as f:
        f.write("no run here\n")
    view.open_run(driver, wait, by_id, "teraeye/out-seed1")
    readouts.click_pixel(driver, wait, by_id, "image", *size, row, col)
    wait.until(lambda d: view.pixel_values(d)[:2] == (str(row), str(col)))
    driver.execute_script("window.thzmap.results.browse('teraeye')")
    click_list("outputs", "notes/")
    wait.until(lambda d: by_id("status").text == "teraeye/notes: no images or bands.json here")
    shown = [i for i in ("image", "image-info", "colourbar", "diff-image", "res-sensor", "pixel-info")
             if by_id(i).is_displayed()]
    assert not shown, f"a directory without images open, still shown of out-seed1: {shown}"
    assert view.pixel_values(driver) == (None, None, []), view.pixel_values(driver)
    view.open_run(driver, wait, by_id, "teraeye/out-seed1")
    assert by_id("image").is_displayed() and by_id("res-sensor").is_displayed()
    return "a directory without images clears the image of the run before"


def bar_geometry(driver, image, bar, pane):
    return driver.execute_script(
        "const [i, b, p] = [...arguments].map((x) => document.getElementById(x));"
        "return {image: i.offsetHeight, bar: b.offsetHeight, barPixels: b.height,"
        " scroll: p.scrollHeight, client: p.clientHeight};", image, bar, pane)


def bar_follows_image(driver, wait, by_id, shot):
    """At 800 x 600 the colour bar is as tall as the image drawn (with its border) and
    the image pane does not scroll; the bar still runs from the top colour to the bottom
    one with five labels; at the window's first size it is the image's 514 px again."""
    view.open_run(driver, wait, by_id, "teraeye/out-seed1")
    Select(by_id("res-quantity")).select_by_value("brightness_temperature")
    g = bar_geometry(driver, "image", "colourbar", "image-pane")
    assert g["bar"] == g["image"] == 514, g
    window = driver.get_window_size()
    try:
        driver.set_window_size(800, 600)
        wait.until(lambda d: bar_geometry(d, "image", "colourbar", "image-pane")["image"] < 514)
        wait.until(lambda d: bar_geometry(d, "image", "colourbar", "image-pane")["bar"]
                   == bar_geometry(d, "image", "colourbar", "image-pane")["image"],
                   f"at 800 x 600: {bar_geometry(driver, 'image', 'colourbar', 'image-pane')}")
        g = bar_geometry(driver, "image", "colourbar", "image-pane")
        assert g["barPixels"] == g["bar"] and g["scroll"] <= g["client"], \
            f"at 800 x 600 the image pane scrolls: {g}"
        rgb = readouts.canvas_rgb(driver, "colourbar")
        top, bottom = rgb[10, 5], rgb[rgb.shape[0] - 24, 5]
        assert np.abs(top - readouts.VIRIDIS[-1]).max() <= 2 and np.abs(bottom - readouts.VIRIDIS[0]).max() <= 2, \
            (top, bottom)
        shot("bar-800")
    finally:
        driver.set_window_size(window["width"], window["height"])
    wait.until(lambda d: bar_geometry(d, "image", "colourbar", "image-pane")["bar"] == 514)
    return f"colour bar {g['bar']} px beside an image {g['image']} px tall at 800 x 600, 514 px at 1400"


def run_warnings(driver, wait, by_id, root):
    """A batch frame of one path a sample: its summary.json's warning (no standard error
    estimated) said above the image, where the Pixel column's σ reads 0.000 K; a run
    without warnings says nothing there."""
    out = "teraeye/out-batch/frame-00001"
    with open(os.path.join(root, out, "summary.json")) as f:
        warnings = json.load(f)["warnings"]
    assert any("standard errors are not estimated" in w for w in warnings), warnings
    view.open_run(driver, wait, by_id, out)
    note = lambda: by_id("res-note").text if by_id("res-note").is_displayed() else None
    assert note() == "\n".join(f"warning: {w}" for w in warnings), \
        f"{out} open, its warnings {warnings} not said: note {note()!r}"
    view.open_run(driver, wait, by_id, "teraeye/out-seed1")
    assert note() is None, note()
    return f"a run's warning said: {warnings[0][:60]!r}"


def diff_names_runs(driver, wait, by_id):
    """The A/B difference's caption names the runs compared: A and B above it may say
    others (filled anew with each run opened until typed into, or typed into without
    Compare), while the image is still that of the last Compare."""
    Select(by_id("res-view")).select_by_value("diff")
    for box, run in (("diff-a", "teraeye/out-seed1"), ("diff-b", "teraeye/out-seed2")):
        by_id(box).clear()
        by_id(box).send_keys(run)
    by_id("btn-diff").click()
    caption = lambda: by_id("diff-info").text
    wait.until(lambda d: "%" in caption())
    view.open_run(driver, wait, by_id, "teraeye/out-two1")
    Select(by_id("res-view")).select_by_value("diff")
    by_id("diff-a").clear()
    by_id("diff-a").send_keys("teraeye/out-two1")
    assert caption().startswith("A teraeye/out-seed1, B teraeye/out-seed2: (A − B) / √(σA² + σB²), channel "), \
        f"A {by_id('diff-a').get_attribute('value')!r}, B {by_id('diff-b').get_attribute('value')!r} " \
        f"above a difference of out-seed1 and out-seed2 captioned {caption()!r}"
    said = caption()
    Select(by_id("res-view")).select_by_value("image")
    return f"the difference names its runs: {said[:70]!r}"


def one_channel_plot(driver, wait, by_id):
    """A pixel of a one-channel frame: its spectrum's frequency axis about the channel
    (0.35 THz), no tick below 0 THz, each tick's label and the axes' names inside the
    plot and apart from each other."""
    view.open_run(driver, wait, by_id, "teraeye/out-batch/frame-00000")
    readouts.click_pixel(driver, wait, by_id, "image", 8, 12, 5, 7)
    wait.until(lambda d: d.find_elements("css selector", "#pixel-plot svg"))
    ticks, boxes, frame = driver.execute_script(
        "const svg = document.querySelector('#pixel-plot svg'); const f = svg.getBoundingClientRect();"
        "const texts = [...svg.querySelectorAll('text')].filter((t) => !t.hasAttribute('style'));"
        "return [texts.filter((t) => t.getAttribute('text-anchor') !== 'end' && !t.hasAttribute('transform'))"
        " .map((t) => t.textContent), texts.map((t) => { const b = t.getBoundingClientRect();"
        " return [t.textContent, b.left, b.top, b.right, b.bottom]; }), [f.left, f.top, f.right, f.bottom]];")
    freqs = [float(t) for t in ticks if t != "frequency (THz)"]
    assert len(freqs) == 5 and min(freqs) > 0 and freqs[0] < 0.35 < freqs[-1] and freqs[-1] - freqs[0] < 0.2, freqs
    for name, left, top, right, bottom in boxes:
        assert left >= frame[0] - 0.5 and right <= frame[2] + 0.5, f"{name!r} [{left}, {right}] beyond the plot {frame}"
    for a in boxes:
        for b in boxes:
            overlap = min(a[3], b[3]) - max(a[1], b[1]) > 0.5 and min(a[4], b[4]) - max(a[2], b[2]) > 0.5
            assert a is b or not overlap, f"{a[0]!r} over {b[0]!r}"
    return f"one channel's spectrum on {freqs[0]:g} to {freqs[-1]:g} THz"
