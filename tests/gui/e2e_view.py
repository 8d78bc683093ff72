"""The Results view as a user looks at it (for test_e2e_audit.py, session 57), each a fault
noticed and left by earlier sessions: a summary.json that was there but damaged was
shown as no summary at all. Each check failed before its fix (web/src,
src/serve/serve_results.c)."""
import os
import shutil

from selenium.webdriver.common.by import By


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
