"""What the page shows, checked against the runs' own files read by numpy (for
test_e2e.py): the Results image's colours and colour bar (viridis over the 1st to 99th
percentile of the channel chosen, in K), the channel chosen by its label, a clicked pixel
of an image that is not square and of a measured cube, the pixel's truth, channel centres
and error bars, the A/B difference (its share beyond 3 σ, a clicked pixel's value, its
colour bar), the photons drawn of the channel chosen, the runs' seed and photons as typed,
and the Scene tab's colours by temperature. Each check failed with a mutant of web/src
that every other test passed (session 55): a user would have seen a wrong colour, number,
unit, channel or run."""
import json
import math
import re

import numpy as np
from selenium.webdriver import ActionChains
from selenium.webdriver.support.ui import Select

# matplotlib's viridis at the 9 stops docs/gui.md's colour bar interpolates linearly
VIRIDIS = np.array([[68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141],
                    [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37]], float)
H, K, C = 6.62607015e-34, 1.380649e-23, 299792458.0

# every text drawn on a canvas, with the canvas's id (a colour bar's labels and unit)
HOOK = ("if (!window.canvasText) { const f = CanvasRenderingContext2D.prototype.fillText;"
        " CanvasRenderingContext2D.prototype.fillText = function (t, x, y) {"
        " window.canvasText.push([this.canvas.id, String(t), x, y]); return f.apply(this, arguments); }; }"
        " window.canvasText = [];")

# the bodies the page posts to /api/runs, in window.sentRuns
RECORD_RUNS = ("window.sentRuns = []; const f = window.fetch; window.fetch = (u, o) => {"
               " if (String(u) === '/api/runs' && o?.body) window.sentRuns.push(JSON.parse(o.body));"
               " return f(u, o); };")


def viridis(t):
    x = np.clip(t, 0, 1) * 8
    i = np.minimum(np.floor(x).astype(int), 7)
    f = (x - i)[..., None]
    return VIRIDIS[i] + f * (VIRIDIS[i + 1] - VIRIDIS[i])


def percentiles(values):
    """The 1st and 99th percentile as docs/gui.md defines the scale (no value: 0 K)."""
    s = np.sort(values[np.isfinite(values) & (values != 0)].astype(float))
    return s[math.floor(0.01 * (len(s) - 1))], s[math.ceil(0.99 * (len(s) - 1))]


def canvas_rgb(driver, canvas_id):
    w, h, data = driver.execute_script(
        "const c = document.getElementById(arguments[0]);"
        "return [c.width, c.height, Array.from(c.getContext('2d').getImageData(0, 0, c.width, c.height).data)];",
        canvas_id)
    return np.array(data, float).reshape(h, w, 4)[:, :, :3]


def bar_texts(driver, canvas_id):
    """The colour bar's labels top to bottom (x = 20) and its unit (x = 2)."""
    texts = [t for t in driver.execute_script("return window.canvasText") if t[0] == canvas_id]
    labels = [float(t[1]) for t in sorted(texts, key=lambda t: t[3]) if t[2] == 20]
    units = [t[1] for t in texts if t[2] == 2]
    return labels, units


def close(shown, value, digits=4):
    return abs(shown - value) <= 0.6 * 10.0 ** (math.floor(math.log10(abs(value))) - digits + 1)


def image_scale(driver, wait, by_id, tb, freq_thz, band):
    """Channel band+1 chosen by its label: the caption names it as the Channel list and
    the photon view's list do (the scene loader's name of an unnamed channel, "0.600 THz";
    the caption said "0.6 THz"), the colours span the 1st to 99th percentile of that
    channel in K, each pixel's colour is viridis there, and the colour bar runs from the
    hottest (top) to the coldest with its labels and unit K."""
    driver.execute_script(HOOK)
    Select(by_id("res-quantity")).select_by_value("brightness_temperature")
    choice = Select(by_id("res-channel"))
    label = next(o.text for o in choice.options if o.text.startswith(f"{band + 1}: "))
    choice.select_by_visible_text(label)
    caption = lambda: by_id("image-info").get_attribute("textContent")
    wait.until(lambda d: caption().startswith(f"brightness temperature, channel {band + 1} ("))
    name = label.split(": ", 1)[1]
    assert name == f"{freq_thz[band]:.3f} THz", label
    assert f"channel {band + 1} ({name})" in caption(), caption()
    photon_list = [o.get_attribute("textContent") for o in Select(by_id("ph-channel")).options]
    assert photon_list == [o.text.split(": ", 1)[1] for o in choice.options], photon_list
    lo, hi = percentiles(tb[band])
    m = re.search(r"percentile: (\S+) to (\S+) K$", caption())
    assert m and close(float(m.group(1)), lo) and close(float(m.group(2)), hi), (caption(), lo, hi)
    rgb = canvas_rgb(driver, "image")
    want = viridis(np.round((tb[band] - lo) * (255 / (hi - lo))) / 255)
    want[~np.isfinite(tb[band]) | (tb[band] == 0)] = 40  # grey: nothing hit
    worst = np.abs(rgb - want).max()
    assert worst <= 3, f"channel {band + 1}: pixel colours up to {worst} off viridis over [{lo}, {hi}] K"
    bar = canvas_rgb(driver, "colourbar")
    assert np.abs(bar[10, 5] - VIRIDIS[-1]).max() <= 2 and np.abs(bar[bar.shape[0] - 24, 5] - VIRIDIS[0]).max() <= 2, \
        f"colour bar top {bar[10, 5]}, bottom {bar[bar.shape[0] - 24, 5]}"
    labels, units = bar_texts(driver, "colourbar")
    assert len(labels) == 5 and close(labels[0], hi) and close(labels[-1], lo), (labels, lo, hi)
    assert units == ["K"], units
    return caption()


def click_pixel(driver, wait, by_id, canvas_id, rows, cols, row, col):
    canvas = by_id(canvas_id)
    w, h = canvas.size["width"], canvas.size["height"]
    ActionChains(driver).move_to_element_with_offset(
        canvas, int((col + 0.5) * w / cols - w / 2), int((row + 0.5) * h / rows - h / 2)).click().perform()


def pixel_not_square(driver, wait, by_id, tb, row, col):
    """A pixel of an image wider than high: the row and column read back, its values the cube's."""
    bands, rows, cols = tb.shape
    assert rows != cols and row != col
    click_pixel(driver, wait, by_id, "image", rows, cols, row, col)
    wait.until(lambda d: by_id("pixel-info").get_attribute("data-row") == str(row)
               and by_id("pixel-info").get_attribute("data-col") == str(col))
    values = [float(td.get_attribute("data-value")) for td in driver.find_elements("css selector", "#pixel-table td.tb")]
    assert values == [float(v) for v in tb[:, row, col]], (values, tb[:, row, col])


def tb_sigma(tb, s_l, centre_hz):
    """σ_Tb = σ_L / ∂B/∂T at the channel's centre and Tb (docs/gui.md)."""
    t = tb.astype(float)
    x = H * centre_hz / (K * t)
    b_nu = 2 * H * centre_hz ** 3 / C ** 2 / np.expm1(x)
    return s_l / (b_nu * x * np.exp(x) / (np.expm1(x) * t))


def difference(driver, wait, by_id, a, b, band):
    """The A/B difference of channel band+1 (chosen before): (Tb_A − Tb_B) / √(σ_A² + σ_B²)
    worked out here from the cubes a and b = (tb, s_l, centre_hz); the share beyond ±3 σ
    the page gives, the value of a clicked pixel (row ≠ column), and the bar's −4 to +4 σ."""
    driver.execute_script(HOOK)
    by_id("btn-diff").click()
    wait.until(lambda d: "beyond" in by_id("diff-info").text)
    info = by_id("diff-info").text
    freq = a[2][band] / 1e12
    assert f"channel {band + 1} ({freq:.3f} THz)" in info, info  # as the Channel list names it
    za = tb_sigma(a[0][band], a[1][band], a[2][band])
    zb = tb_sigma(b[0][band], b[1][band], a[2][band])
    z = (a[0][band].astype(float) - b[0][band]) / np.sqrt(za ** 2 + zb ** 2)
    finite = np.isfinite(z)
    share = 100 * np.count_nonzero(np.abs(z[finite]) > 3) / np.count_nonzero(finite)
    m = re.search(r"([0-9.]+) % of (\d+) pixels", info)
    assert m and int(m.group(2)) == np.count_nonzero(finite), (info, np.count_nonzero(finite))
    assert abs(float(m.group(1)) - share) <= 0.006, f"page {info!r}, worked out {share:.3f} %"
    labels, units = bar_texts(driver, "diff-bar")
    assert labels == [4, 2, 0, -2, -4] and units == ["σ"], (labels, units)
    rows, cols = z.shape
    # a pixel whose transposed one differs: a row and a column read the wrong way show
    row, col = max(((r, c) for r in range(rows) for c in range(cols) if r != c and finite[r, c]),
                   key=lambda rc: abs(z[rc] - z[rc[::-1]]))
    click_pixel(driver, wait, by_id, "diff-image", rows, cols, row, col)
    wait.until(lambda d: by_id("pixel-info").text.startswith(f"row {row}, column {col} of the A/B difference: A − B = "))
    m = re.search(r"A − B = (\S+) σ$", by_id("pixel-info").text)
    assert m and abs(float(m.group(1)) - z[row, col]) <= 1e-3 * abs(z[row, col]) + 1e-4, \
        (by_id("pixel-info").text, z[row, col])
    # no spectrum or table of another pixel under it: they stayed those of the pixel last
    # clicked on the image, under this pixel's row and column
    left = driver.execute_script(
        "return document.querySelectorAll('#pixel-table td').length +"
        " document.getElementById('pixel-plot').childElementCount;")
    assert left == 0, f"{left} cells and plots of another pixel under {by_id('pixel-info').text!r}"
    return info


def photons_drawn(by_id, summary, at_most):
    """The photon view's line: as many photons as stored for the channel its list shows
    (summary.json's photons_stored), at most the number asked for."""
    label = Select(by_id("ph-channel")).first_selected_option.text
    freqs = [c["frequency_thz"] for c in summary["channels"]]
    k = freqs.index(float(label.split()[0]))
    m = re.match(r"(\d+) of (\d+) photons", by_id("ph-info").text)
    stored = summary["channels"][k]["photons_stored"]
    assert m and int(m.group(2)) == stored and int(m.group(1)) == min(stored, at_most), \
        f"{label} chosen, {stored} photons stored: {by_id('ph-info').text!r}"


def measured_pixel(driver, wait, by_id, measured, row, col):
    """With the measured quantity chosen (a sensor with noise), a clicked pixel's spectrum
    is the measured cube's, without error bars (docs/gui.md)."""
    Select(by_id("res-quantity")).select_by_value("measured_brightness_temperature")
    rows, cols = measured.shape[1:]
    click_pixel(driver, wait, by_id, "image", rows, cols, row, col)
    wait.until(lambda d: by_id("pixel-info").text.startswith(f"row {row}, column {col} (measured): "))
    values = [float(td.get_attribute("data-value")) for td in driver.find_elements("css selector", "#pixel-table td.tb")]
    sigmas = [td.text for td in driver.find_elements("css selector", "#pixel-table td.sigma")]
    assert values == [float(v) for v in measured[:, row, col]], (values, measured[:, row, col])
    assert sigmas == ["–"] * len(values), sigmas


def temperature_colours(driver, by_id, scene):
    """Scene tab, colour by temperature: each object viridis from the coldest object to the
    hottest (docs/gui.md), the key's ends in K."""
    Select(by_id("colour-by")).select_by_value("temperature")
    temps = [o["temperature_k"] for o in scene["objects"]]
    lo, hi = min(temps), max(temps)
    m = re.fullmatch(r"(\S+) K\s*(\S+) K", by_id("legend3d").text.strip())
    assert m and float(m.group(1)) == lo and float(m.group(2)) == hi, (by_id("legend3d").text, lo, hi)
    shown = driver.execute_script("return window.thzmap.editor.view.meshes.map((m) =>"
                                  " [m.userData.index, m.material.color.r, m.material.color.g, m.material.color.b]);")
    assert len(shown) == len(temps), shown
    for i, *rgb in shown:
        want = viridis((temps[i] - lo) / (hi - lo)) / 255
        assert np.abs(np.array(rgb) - want).max() < 2e-3, (scene["objects"][i]["name"], temps[i], rgb, want)
    Select(by_id("colour-by")).select_by_value("material")



def pixel_column(driver, by_id, out, shape, row, col, centre_hz, seen):
    """The clicked pixel's column: the truth (seen: "NAME, T K") at its distance in m (the
    cam.distance cube, rows x columns = shape), each table row's channel centre in THz, and
    one error bar a channel."""
    truth = by_id("pixel-truth").text
    dist = np.fromfile(f"{out}/cam.distance.img", "<f4").reshape(shape)[row, col]
    m = re.fullmatch(re.escape(seen) + r" at (\S+) m", truth)
    assert m and close(float(m.group(1)), dist), (truth, dist)
    thz = [float(r[1]) for r in driver.execute_script(
        "return [...document.querySelectorAll('#pixel-table tbody tr')].map((r) =>"
        " [...r.cells].map((c) => c.textContent));")]
    assert np.allclose(thz, centre_hz / 1e12, rtol=1e-9), (thz, centre_hz)
    bars = len(driver.find_elements("css selector", "#pixel-plot svg line"))
    assert bars == len(centre_hz), f"{bars} error bars for {len(centre_hz)} channels"
    return truth


def runs_as_typed(root, seeds, photons):
    """Each run ran with the seed and photons per channel typed in the Run tab (seeds:
    output directory -> seed). Without the seed two "seeds" were both the scene's, and
    their A/B difference, 0 % beyond 3 σ, passed for two runs that agree."""
    for out, seed in seeds.items():
        with open(f"{root}/{out}/summary.json") as f:
            summary = json.load(f)
        assert summary["seed"] == seed, f"{out}: run with seed {summary['seed']}, not {seed}"
        assert summary["photons_per_channel"] == photons, f"{out}: {summary['photons_per_channel']} photons"


def object_colours(driver, wait, by_id, oid, names):
    """The truth map of objects: object i of n in viridis(i / (n − 1)), in the picture and
    in its swatch beside its name (oid: the cam.object_id band, −1 where nothing was hit)."""
    wait.until(lambda d: by_id("image-info").text.startswith("object seen, truth"))
    swatches = driver.execute_script(
        "return [...document.querySelectorAll('#image-info .swatch')].map((s) =>"
        " [s.nextSibling.textContent.trim(), getComputedStyle(s).backgroundColor]);")
    assert sorted(n for n, _ in swatches) == sorted(names[int(i)] for i in set(oid.flat) if i >= 0), swatches
    want = lambda i: viridis(i / (len(names) - 1))
    for name, css in swatches:
        rgb = [float(v) for v in re.findall(r"[0-9.]+", css)[:3]]
        assert np.abs(np.array(rgb) - np.round(want(names.index(name)))).max() <= 1, (name, css)
    rgb = canvas_rgb(driver, "image")
    hit = oid >= 0
    worst = np.abs(rgb[hit] - want(oid[hit].astype(int))).max()
    assert worst <= 3, f"object colours up to {worst} off viridis(i / (n − 1))"


def sensor_frustum(driver, sensor):
    """The selected sensor's frustum in the 3D view (sensor: the scene file's): at its
    position, looking at its look-at point, its horizontal angle of view, the aspect of its
    columns to rows, and the tick on the image's top side towards its up."""
    pts = np.array(driver.execute_script(
        "const f = window.thzmap.editor.view.group.children.find((c) => c.isLineSegments"
        " && c.userData.helper && c.material.color.getHex() === 0xe06000);"
        "return f ? Array.from(f.geometry.getAttribute('position').array) : [];"), float).reshape(-1, 3)
    assert len(pts) == 20, f"no frustum of the selected sensor: {len(pts)} points"
    origin, corners, tick = pts[0], pts[[1, 5, 9, 13]], pts[17]
    assert np.allclose(origin, sensor["position_m"], atol=1e-6), (origin, sensor["position_m"])
    centre = corners.mean(axis=0)
    look = np.subtract(sensor["look_at_m"], origin)
    axis = centre - origin
    assert np.allclose(axis / np.linalg.norm(axis), look / np.linalg.norm(look), atol=1e-5), (axis, look)
    width, height = np.linalg.norm(corners[1] - corners[0]), np.linalg.norm(corners[2] - corners[1])
    cols, rows = sensor["resolution"]
    assert abs(width / height - cols / rows) < 1e-5, (width, height, cols, rows)
    fov = 2 * math.degrees(math.atan(width / 2 / np.linalg.norm(axis)))
    assert abs(fov - sensor["fov_deg"]) < 1e-4, (fov, sensor["fov_deg"])
    up = (tick - centre) / np.linalg.norm(tick - centre)
    assert np.dot(up, sensor["up"]) > 0.99, (up, sensor["up"])


def failed_run(driver, wait, by_id, out, named):
    """A run that failed: its error (naming named) in its row and in the status line."""
    error = driver.execute_script(
        "return [...document.querySelectorAll('#runs tbody tr')].find((x) => x.cells[3].textContent ==="
        " arguments[0]).cells[5].textContent;", out)
    assert named in error, error
    wait.until(lambda d: re.search(r"run \d+ failed: ", by_id("status").text))
    assert by_id("status").text.endswith(error), (by_id("status").text, error)
    assert "error" in by_id("status").get_attribute("class"), "the status line not shown as an error"
    return error[:70]


def grey_wall_plot(driver, reflectivity):
    """The selected object's R, ε plot for an opaque grey material: R flat at its
    reflectivity and ε at 1 − R (Kirchhoff), read back through the axis's 0 and 1 ticks."""
    ticks, lines = driver.execute_script(
        "const svg = [...document.querySelectorAll('#material-plots svg')].find((s) =>"
        " [...s.querySelectorAll('text')].some((t) => t.textContent === 'R, ε (1)'));"
        "return [[...svg.querySelectorAll('text[text-anchor=end]')].map((t) => [t.textContent, Number(t.getAttribute('y'))]),"
        " [...svg.querySelectorAll('polyline')].map((p) => p.getAttribute('points'))];")
    at = {float(v): y for v, y in ticks}
    value = lambda y: (y - at[0]) / (at[1] - at[0])
    curves = [[value(float(p.split(",")[1]) + 3) for p in line.split()] for line in lines]
    assert len(curves) == 2, lines
    r, eps = curves
    assert np.allclose(r, reflectivity, atol=1e-3) and np.allclose(eps, 1 - reflectivity, atol=1e-3), (r, eps)


def sensor_units(driver, fields):
    """The selected sensor's fields each with its unit (fields: JSON path -> label)."""
    for path, label in fields.items():
        shown = driver.execute_script(
            "return document.querySelector(`.field[data-path='${arguments[0]}'] label`)?.textContent;", path)
        assert shown == label, (path, shown, label)
