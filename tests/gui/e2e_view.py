"""The Results view as a user looks at it (for test_e2e_audit.py, session 57), each a fault
noticed and left by earlier sessions: the image kept its size when the window was
resized (cut off at the pane's edge in a narrower one); a summary.json that was there
but damaged was shown as no summary at all. Each check failed before its fix (web/src,
src/serve/serve_results.c)."""
import os
import shutil

from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select


def open_run(driver, wait, by_id, out):
    driver.execute_script("window.thzmap.showTab('results'); window.thzmap.results.open(arguments[0])", out)
    wait.until(lambda d: f"{out}/cam:" in by_id("status").text and "loaded" in by_id("status").text)
    Select(by_id("res-view")).select_by_value("image")


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
