"""The viewer in a real browser (tests/viewer.rs runs this): headless Chromium, driven by
Selenium through Debian's chromedriver, opens the view.html of a run, a sequence and a compare
that the Rust test made, moves the pointer over display pixels and reads what the page says
against the files beside it (the EXRs read here with OpenEXR, frames.csv as text).

usage: viewer_in_chromium.py RUN_DIR SEQUENCE_DIR COMPARE_DIR DATASET_DIR SCREENSHOT_DIR
Prints one line per check; exits non-zero on the first failure.
"""

import csv
import json
import math
import os
import sys

import numpy as np
import OpenEXR
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import WebDriverWait

CHROMIUM = os.environ.get("SEETHRU_CHROMIUM", "/usr/bin/chromium")
CHROMEDRIVER = os.environ.get("SEETHRU_CHROMEDRIVER", "/usr/bin/chromedriver")


def browser(profile):
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    # As this machine's notes say Chromium runs headless here: no sandbox as root, and no
    # background connections to a network that is closed.
    for flag in [
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--disable-dev-shm-usage",
        "--window-size=1400,1000",
        "--force-device-scale-factor=1",
        f"--user-data-dir={profile}",
    ]:
        options.add_argument(flag)
    return webdriver.Chrome(service=Service(executable_path=CHROMEDRIVER), options=options)


def channels(path):
    with OpenEXR.File(path) as f:
        return {name: ch.pixels for name, ch in f.channels().items()}


def open_page(driver, folder):
    driver.get("file://" + os.path.abspath(os.path.join(folder, "view.html")))
    WebDriverWait(driver, 20).until(
        lambda d: d.execute_script("return document.body.dataset.ready === '1'")
    )
    errors = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
    assert not errors, f"the page logged errors: {errors}"


def text(driver, css):
    return driver.find_element(By.CSS_SELECTOR, css).text


def point_at(driver, stage, x, y):
    """Moves the pointer to the centre of driver-view pixel (x, y) of the stage."""
    rect = driver.execute_script(
        "const r = arguments[0].getBoundingClientRect(); return [r.width, r.height];", stage
    )
    width, height = int(stage.get_attribute("data-width")), int(stage.get_attribute("data-height"))
    scale_x, scale_y = rect[0] / width, rect[1] / height
    assert scale_x >= 2 and scale_y >= 2, f"the test needs ≥ 2 CSS px per pixel, has {scale_x}"
    # Offsets from the element's centre (W3C actions), integers: the middle of the pixel's cell.
    dx = math.floor((x + 0.5) * scale_x - rect[0] / 2)
    dy = math.floor((y + 0.5) * scale_y - rect[1] / 2)
    ActionChains(driver).move_to_element_with_offset(stage, dx, dy).perform()


def check_run(driver, folder, shots):
    open_page(driver, folder)
    maps = channels(os.path.join(folder, "misregistration.exr"))
    truth = channels(os.path.join(folder, "truth.exr"))
    seethru = channels(os.path.join(folder, "seethru.exr"))
    names = json.load(open(os.path.join(folder, "run.json")))["object_names"]
    mis, display = maps["Y"], maps["display.mask"]
    h, w = mis.shape

    def name(i):
        return "sky (id 0)" if i == 0 else f"{names[i - 1]} (id {i})"

    stage = driver.find_element(By.ID, "stage")
    ys, xs = np.nonzero(np.isfinite(mis))
    assert len(xs) > 10, "the run has display pixels with a value"
    # The first and last display pixels with a value, the largest value, and a few between.
    picks = sorted({0, len(xs) - 1, int(np.nanargmax(mis[ys, xs])), len(xs) // 3, 2 * len(xs) // 3})
    for k in picks:
        x, y = int(xs[k]), int(ys[k])
        point_at(driver, stage, x, y)
        assert text(driver, "#r-pixel") == f"{x}, {y}", (text(driver, "#r-pixel"), x, y)
        shown = text(driver, "#r-misregistration")
        want = f"{mis[y, x]:.2f}′"
        assert shown == want, f"pixel ({x}, {y}): the page says {shown}, misregistration.exr {want}"
        for field, want in [
            ("r-depth", f"{z:.3f} m" if np.isfinite(z := truth["Z"][y, x]) else "∞ (sky)"),
            ("r-should", name(int(truth["id.object"][y, x]))),
            ("r-shown", name(int(seethru["id.object"][y, x]))),
        ]:
            got = text(driver, "#" + field)
            assert got == want, f"pixel ({x}, {y}): {field} reads {got}, the EXRs {want}"
        assert text(driver, "#r-state").startswith("on the display")
        print(f"ok: run readout at ({x}, {y}) = {shown}, as misregistration.exr")
    # A pixel off the display says so and shows no value.
    off = np.argwhere(display < 0.5)
    y, x = (int(v) for v in off[len(off) // 2])
    point_at(driver, stage, x, y)
    assert text(driver, "#r-state") == "outside the display", text(driver, "#r-state")
    assert text(driver, "#r-misregistration") == "—"
    print(f"ok: run readout at ({x}, {y}) outside the display")
    # Flick with keys, overlay the heatmap, wipe: the page's state follows.
    body = driver.find_element(By.TAG_NAME, "body")
    body.send_keys("2")
    assert stage.get_attribute("data-view") == "seethru"
    assert driver.find_element(By.ID, "layer-a").get_attribute("src").endswith("/seethru.png")
    body.send_keys("h")
    assert driver.find_element(By.ID, "overlay").value_of_css_property("display") != "none"
    driver.save_screenshot(os.path.join(shots, "run_heatmap.png"))
    body.send_keys("1")
    body.send_keys("h")
    for _ in range(10):
        body.send_keys(Keys.ARROW_RIGHT)
    assert driver.find_element(By.ID, "wipe").get_attribute("value") == "500"
    clip = driver.find_element(By.ID, "layer-b").value_of_css_property("clip-path")
    assert "50%" in clip, clip
    driver.save_screenshot(os.path.join(shots, "run_wipe.png"))
    print("ok: run keys flick the views, show the heatmap and wipe")


def check_sequence(driver, folder, shots):
    open_page(driver, folder)
    runs = sorted(d for d in os.listdir(folder) if os.path.isfile(os.path.join(folder, d, "frames.csv")))
    assert len(runs) >= 2, runs
    slider = driver.find_element(By.ID, "frame")
    for index, run in enumerate(runs):
        if index:
            driver.find_element(By.CSS_SELECTOR, f"#latency option[value='{run}']").click()
        with open(os.path.join(folder, run, "frames.csv"), newline="") as f:
            rows = list(csv.DictReader(f))
        k = len(rows) - 2
        slider.click()  # focus; a click may move it: go home first
        slider.send_keys(Keys.HOME)
        for _ in range(k):
            slider.send_keys(Keys.ARROW_RIGHT)
        assert slider.get_attribute("value") == str(k)
        for column in ["frame", "t_s", "misregistration_mean_arcmin", "coverage", "eye_error_mm"]:
            got = text(driver, f"#frame-metrics td[data-col='{column}']")
            assert got == rows[k][column], f"{run} frame {k}: {column} is {got}, frames.csv {rows[k][column]}"
        src = driver.find_element(By.ID, "layer-a").get_attribute("src")
        assert src.endswith(f"/{run}/frames/truth_{k:05d}.png"), src
        print(f"ok: sequence {run} scrubbed to frame {k}: its frames.csv row and images")
    driver.save_screenshot(os.path.join(shots, "sequence.png"))


def check_compare(driver, folder, shots):
    open_page(driver, folder)
    rows = json.load(open(os.path.join(folder, "compare.json")))["rows"]
    shown = [f.get_attribute("data-method") for f in driver.find_elements(By.CSS_SELECTOR, "#methods figure")]
    assert shown == [r["method"] for r in rows], shown
    for figure, row in zip(driver.find_elements(By.CSS_SELECTOR, "#methods figure"), rows):
        loaded = driver.execute_script("return arguments[0].querySelector('img').naturalWidth > 0", figure)
        assert loaded, f"strip of {row['method']} did not load"
        assert f"{row['misregistration_mean_arcmin']:.2f}′" in figure.text, figure.text
    driver.save_screenshot(os.path.join(shots, "compare.png"))
    print(f"ok: compare shows {len(rows)} methods with their strips and means")


def check_dataset(driver, folder, shots):
    open_page(driver, folder)
    with open(os.path.join(folder, "manifest.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    from selenium.webdriver.support.ui import Select

    for column, order in [("misregistration_mean_arcmin", "asc"), ("theta_f", "desc"), ("sample", "asc")]:
        Select(driver.find_element(By.ID, "sort-by")).select_by_value(column)
        Select(driver.find_element(By.ID, "sort-order")).select_by_value(order)
        shown = [f.get_attribute("data-sample") for f in driver.find_elements(By.CSS_SELECTOR, "#samples figure")]
        want = sorted(rows, key=lambda r: (float(r[column]) * (1 if order == "asc" else -1), int(r["sample"])))
        assert shown == [r["sample"] for r in want], f"sorted by {column} {order}: {shown}"
        print(f"ok: dataset grid sorted by {column} ({order}): {' '.join(shown)}")
    # Each sample's caption and image are its own row's, a drawn vector (a quoted CSV field
    # with commas) included: a naive split would shift every later column.
    by_sample = {r["sample"]: r for r in rows}
    for figure in driver.find_elements(By.CSS_SELECTOR, "#samples figure"):
        row = by_sample[figure.get_attribute("data-sample")]
        src = figure.find_element(By.TAG_NAME, "img").get_attribute("src")
        assert src.endswith("/" + row["seethru_png"]), (src, row["seethru_png"])
        vector = row["scene.object.car.translate"]
        assert "," in vector and f"scene.object.car.translate = {vector}" in figure.text, figure.text
    print("ok: each sample shows its own row, its drawn vector whole")
    driver.save_screenshot(os.path.join(shots, "dataset.png"))
    # A sample opens its own viewer.
    driver.find_element(By.CSS_SELECTOR, "#samples figure a").click()
    WebDriverWait(driver, 20).until(lambda d: d.execute_script("return document.body.dataset.ready === '1'"))
    assert driver.current_url.endswith("/view.html") and "/samples/" in driver.current_url, driver.current_url
    assert driver.find_element(By.ID, "stage").is_displayed()
    print("ok: a dataset sample opens its run viewer")


def main():
    run_dir, sequence_dir, compare_dir, dataset_dir, shots = sys.argv[1:6]
    os.makedirs(shots, exist_ok=True)
    driver = browser(os.path.join(shots, "profile"))
    try:
        check_run(driver, run_dir, shots)
        check_sequence(driver, sequence_dir, shots)
        check_compare(driver, compare_dir, shots)
        check_dataset(driver, dataset_dir, shots)
    finally:
        driver.quit()


if __name__ == "__main__":
    main()
