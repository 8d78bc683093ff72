"""A user's session of the page (for test_e2e.py, session 56): what a person saw go
wrong. A plot's legend was grey for every curve (app.css's fill for the axes' text beat
the labels' fill attribute), so R and ε could not be told apart; a material of the
library chosen in an object's material list was refused ("unknown material", the scene
did not define it); resizing the window raised "ResizeObserver loop completed with
undelivered notifications" error events; at 800 px the side columns left the 3D view and
the image some 190 px, where the image was drawn 512 px wide all the same, its colour
bar and unit beyond the pane's edge, and the runs' Cancel and Results buttons beyond the
Run tab's; a channel chosen in the A/B difference's view left
the difference of the channel compared before, under a list naming the new one, and the
image's quantity and scale stayed in view where they act on nothing; A was filled with
the first run the page opened, whatever was open since, and B left empty; a pixel
clicked on an image of power or radiance showed Tb alone, not the value of the image; the
Run tab had no integrator to choose, so seeing a path scene's photons meant editing its
render.integrator; a run cancelled was announced in the error's red."""
import json
import os

import numpy as np

from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select

ERRORS = ("window.userErrors = []; window.addEventListener('error', (e) =>"
          " window.userErrors.push(String(e.message)));")


def legend_colours(driver):
    """Each plot's legend labels are drawn in the colour of their curves, in order."""
    plots = driver.execute_script(
        "return [...document.querySelectorAll('#material-plots svg')].map((s) => ["
        " [...s.querySelectorAll('polyline')].map((p) => getComputedStyle(p).stroke),"
        " [...s.querySelectorAll('text')].filter((t) => t.hasAttribute('style'))"
        "   .map((t) => [t.textContent, getComputedStyle(t).fill])]);")
    assert plots, "no material plot"
    for strokes, labels in plots:
        assert [f for _, f in labels] == strokes, f"legend {labels} for curves {strokes}"
    return [n for _, labels in plots for n, _ in labels]


def library_material(driver, wait, by_id, click_list, field, index, name):
    """The library's material chosen for object `index` (the scene open, saved, valid):
    the scene defines it as {"library": NAME} and stays valid; its plots are drawn."""
    by_id("tab-scene").click()
    click_list("objects", name)
    path = f"objects[{index}].material"
    choice = Select(field(path).find_element(By.TAG_NAME, "select"))
    defined = json.loads(by_id("scene-text").get_attribute("value")).get("materials", {})
    lib = next(o.get_attribute("value") for o in choice.options if o.get_attribute("value") not in defined)
    choice.select_by_value(lib)
    wait.until(lambda d: json.loads(by_id("scene-text").get_attribute("value"))["objects"][index]["material"] == lib)
    doc = json.loads(by_id("scene-text").get_attribute("value"))
    assert doc["materials"].get(lib) == {"library": lib}, f"materials.{lib}: {doc['materials'].get(lib)}"
    # its spectra are plotted once the scene validates with it
    wait.until(lambda d: d.execute_script(
        "return document.querySelector('#material-plots div')?.textContent || ''").startswith(f"material {lib}"))
    assert "✓" in by_id("validation-state").text, by_id("validation").text
    return lib, legend_colours(driver)


def narrow_window(driver, wait, by_id):
    """At 800 x 600 the 3D view keeps 300 px, a run's image and colour bar fit their pane,
    the runs' Cancel and Results buttons theirs;
    resizing raises no error event."""
    driver.execute_script(ERRORS)
    size = driver.get_window_size()
    try:
        driver.set_window_size(800, 600)
        wait.until(lambda d: d.execute_script("return document.getElementById('view3d').clientWidth") < 500)
        width = driver.execute_script("return document.getElementById('view3d').clientWidth")
        assert width >= 300, f"the 3D view at 800 px: {width} px wide"
        # the image (of the run open in Results) drawn in the narrow window: it and its
        # colour bar fit the pane (512 px always, the colour bar and its unit needed a scroll)
        by_id("tab-results").click()
        channel = Select(by_id("res-channel"))
        channel.select_by_index(1 - [o.is_selected() for o in channel.options].index(True) % 2)
        fits = lambda d: d.execute_script(
            "const p = document.getElementById('image-pane').getBoundingClientRect();"
            "const b = document.getElementById('colourbar').getBoundingClientRect();"
            "const i = document.getElementById('image').getBoundingClientRect();"
            "return [b.right, p.right, i.width];")
        bar_right, pane_right, image_width = fits(driver)
        assert bar_right <= pane_right and image_width >= 64, \
            f"at 800 px: colour bar's right edge {bar_right} px, the pane's {pane_right} px; image {image_width} px"
        # the Run tab: the runs table's last column (Cancel, Results) within its panel
        by_id("tab-run").click()
        right = driver.execute_script(
            "const t = document.querySelector('#runs thead tr').lastElementChild.getBoundingClientRect();"
            "const p = document.querySelector('#runs').closest('.panel').getBoundingClientRect();"
            "return [t.right, p.right];")
        assert right[0] <= right[1], f"at 800 px the runs' buttons end at {right[0]} px, their panel at {right[1]} px"
        by_id("tab-scene").click()
        driver.set_window_size(1000, 700)
        driver.execute_script("return new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))")
    finally:
        driver.set_window_size(size["width"], size["height"])
    driver.execute_script("return new Promise((r) => setTimeout(r, 300))")
    errors = driver.execute_script("return window.userErrors")
    assert not errors, f"error events while resizing: {errors}"
    return width


def diff_follows_channel(driver, wait, by_id, a, b):
    """In the A/B view the difference shown is of the channel chosen; quantity and scale
    (the image's) are out of sight there, and sensor and channel in the photon view."""
    by_id("tab-results").click()
    Select(by_id("res-view")).select_by_value("diff")
    shown = lambda i: by_id(i).is_displayed()
    assert not shown("res-quantity") and not shown("res-scale") and shown("res-channel"), \
        "the A/B view shows the image's quantity and scale"
    for box, run in (("diff-a", a), ("diff-b", b)):
        by_id(box).clear()
        by_id(box).send_keys(run)
    channel = Select(by_id("res-channel"))
    channel.select_by_index(0)
    by_id("btn-diff").click()
    caption = lambda: by_id("diff-info").text
    wait.until(lambda d: "channel 1 (" in caption())
    channel.select_by_index(2)
    wait.until(lambda d: "channel 3 (" in caption() and "%" in caption())
    said = caption()
    Select(by_id("res-view")).select_by_value("photons")
    assert not shown("res-channel") and not shown("res-sensor") and not shown("res-quantity"), \
        "the photon view shows the image's sensor, channel or quantity"
    Select(by_id("res-view")).select_by_value("image")
    assert shown("res-quantity") and shown("res-scale") and shown("res-channel")
    return said


def diff_prefilled(by_id, a, b):
    """A and B hold the run open and the one opened before it (A stayed the first run the
    page opened, B empty)."""
    shown = by_id("diff-a").get_attribute("value"), by_id("diff-b").get_attribute("value")
    assert shown == (a, b), f"A/B prefilled with {shown}, not the run open {a} and the one before {b}"


def pixel_of_quantity(driver, wait, by_id, out, bands, size, row, col):
    """A pixel clicked on the power image of channel 2: the column gives the cube's value,
    in its unit, beside the Tb spectrum."""
    from e2e_readouts import click_pixel
    Select(by_id("res-quantity")).select_by_value("power")
    Select(by_id("res-channel")).select_by_index(1)
    wait.until(lambda d: by_id("image-info").text.startswith("power, channel 2 ("))
    click_pixel(driver, wait, by_id, "image", size[0], size[1], row, col)
    wait.until(lambda d: d.execute_script(
        "const e = document.getElementById('pixel-shown'); return e && e.textContent.startsWith('power, channel 2')"
        " && document.getElementById('pixel-info').dataset.row === arguments[0];", str(row)))
    power = np.fromfile(os.path.join(out, "cam.power.img"), "<f4").reshape(bands, *size)[1, row, col]
    line = by_id("pixel-shown")
    assert float(line.get_attribute("data-value")) == float(power), (line.get_attribute("data-value"), power)
    text = line.text  # (the line goes with the power image)
    assert text.endswith(" W") and f"{power:.3e}" in text, (text, power)
    Select(by_id("res-quantity")).select_by_value("brightness_temperature")
    return text


def run_integrator(driver, wait, by_id, root, scene, out):
    """A path scene simulated with the integrator chosen in the Run tab, photon-map: its
    photon map can be saved, and the run is of that integrator with its map written."""
    by_id("tab-scene").click()
    by_id("btn-save").click()  # the edits of library_material
    wait.until(lambda d: by_id("status").text == f"saved {scene}")
    by_id("tab-run").click()
    wait.until(lambda d: by_id("run-scene").get_attribute("value") == scene)
    Select(by_id("run-command")).select_by_visible_text("simulate")
    save = by_id("run-save-map")
    wait.until(lambda d: not save.is_enabled())  # the scene's integrator is path
    Select(by_id("run-integrator")).select_by_visible_text("photon-map")
    assert save.is_enabled(), "save the photon map stays greyed out with photon-map chosen"
    if not save.is_selected():
        save.click()
    by_id("run-out").clear()
    by_id("run-out").send_keys(out)
    by_id("btn-run").click()
    summary = os.path.join(root, out, "summary.json")
    wait.until(lambda d: os.path.exists(summary))
    with open(summary) as f:
        integrator = json.load(f)["integrator"]
    assert integrator == "photon-map", integrator
    assert os.path.exists(os.path.join(root, out, "photon-map.thzpm"))
    Select(by_id("run-integrator")).select_by_value("")
    return integrator


def cancelled_not_error(wait, by_id):
    """A run cancelled is said so in the status line, not in the error's red."""
    wait.until(lambda d: " cancelled" in by_id("status").text)
    assert "error" not in (by_id("status").get_attribute("class") or ""), by_id("status").text
