"""End-to-end test of candela's HTML report (docs/report-html.md) in headless Chromium.

A 48×36 room (one wall removed, so that some pixels see no surface) is rendered with --illuminance --alpha-opic --report-html; the page is opened from
disk, the probe moved to pixels chosen here (mouse and keyboard), and every probe line must be
the very text `candela probe` prints for that pixel (SI and imperial), and its numbers must
agree with `candela probe --json` to the printed precision. False colour must show the legend
of `candela falsecolour`'s automatic range and paint pixels with the palette; the page must make
no network request. Screenshots and a PDF print go to target/browser/ (CI artifacts, not
compared).

Run: target/venv/bin/python -m pytest -q tests/browser (CANDELA_BIN overrides the binary,
CHROMEDRIVER the driver).
"""

import base64
import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.actions.action_builder import ActionBuilder
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.common.print_page_options import PrintOptions
from selenium.webdriver.support.ui import Select, WebDriverWait

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "tests" / "python" / "data" / "small-room.ron"
ARTIFACTS = ROOT / "target" / "browser"
PROBE_ROWS = {
    "luminance": "p-lum",
    "illuminance": "p-ill",
    "XYZ": "p-xyz",
    "xy": "p-xy",
    "u′v′": "p-upvp",
    "CCT": "p-cct",
    "sRGB linear": "p-srgb-linear",
    "sRGB encoded": "p-srgb-encoded",
}


@pytest.fixture(scope="session")
def candela():
    env = os.environ.get("CANDELA_BIN")
    if env:
        return Path(env)
    # The binary `cargo test` built in this run first, then a release build.
    for profile in ("debug", "release"):
        path = ROOT / "target" / profile / "candela"
        if path.exists():
            return path
    subprocess.run(["cargo", "build", "--profile", "test", "--bin", "candela"], cwd=ROOT, check=True)
    return ROOT / "target" / "debug" / "candela"


@pytest.fixture(scope="session")
def render(candela, tmp_path_factory):
    d = tmp_path_factory.mktemp("html")
    # Without its wall at x = 0 the room opens onto nothing: pixels there see no surface.
    text = SCENE.read_text()
    wall = '        (name: "wall x=0", material: "wall",\n'
    start = text.index(wall)
    end = text.index("\n", text.index("shape:", start)) + 1
    (d / "room.ron").write_text(text[:start] + text[end:])
    out = d / "room"
    run = subprocess.run(
        [candela, "render", d / "room.ron", "--out", out, "--illuminance", "--alpha-opic", "--quiet",
         "--checkpoint-interval", "0s", "--report-html"],
        capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert (d / "room.html").is_file(), run.stdout
    return d


@pytest.fixture(scope="session")
def driver():
    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "/usr/bin/chromium"
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              "--window-size=1400,1000", "--force-device-scale-factor=1"):
        options.add_argument(a)
    options.set_capability("goog:loggingPrefs", {"performance": "ALL"})
    service = Service(os.environ.get("CHROMEDRIVER") or shutil.which("chromedriver") or "/usr/bin/chromedriver")
    drv = webdriver.Chrome(options=options, service=service)
    yield drv
    drv.quit()


def probe_lines(candela, exr, x, y, units="si"):
    """The value column of `candela probe` text: {row name: text}."""
    run = subprocess.run([candela, "probe", exr, str(x), str(y), "--units", units],
                         capture_output=True, text=True, check=True)
    rows = {}
    for line in run.stdout.splitlines()[1:]:
        # format!("  {k:<13} {v}")
        rows[line[2:15].strip()] = line[16:]
    return rows


def probe_json(candela, exr, x, y, units="si"):
    run = subprocess.run([candela, "probe", exr, str(x), str(y), "--units", units, "--json"],
                         capture_output=True, text=True, check=True)
    return json.loads(run.stdout)


def open_page(driver, page):
    driver.get_log("performance")  # drop the entries of earlier pages
    driver.get(page.as_uri())
    WebDriverWait(driver, 60).until(
        lambda d: d.execute_script("return document.body.dataset.ready || null"))
    assert driver.execute_script("return document.body.dataset.ready") == "1", \
        driver.find_element(By.ID, "status").text


def text(driver, id_):
    return driver.execute_script(f"return document.getElementById('{id_}').textContent")


def hover(driver, x, y, size):
    """Moves the mouse over the centre of image pixel (x, y), in viewport coordinates (the
    element-relative origin of WebDriver is the centre of the element's visible part)."""
    canvas = driver.find_element(By.ID, "image")
    r = driver.execute_script(
        "arguments[0].scrollIntoView({block: 'center'}); return arguments[0].getBoundingClientRect().toJSON()",
        canvas)
    w, h = size
    vx = r["left"] + (x + 0.5) * r["width"] / w
    vy = r["top"] + (y + 0.5) * r["height"] / h
    actions = ActionBuilder(driver)
    actions.pointer_action.move_to_location(int(vx), int(vy))
    actions.perform()


def close_to_printed(shown, exact):
    """`shown` (as printed, 3 to 5 significant digits) is `exact` rounded: within half a unit
    of its last printed digit."""
    s = shown.lower()
    m = re.fullmatch(r"-?(\d+)(?:\.(\d+))?(?:e(-?\d+))?", s)
    assert m, shown
    decimals = len(m.group(2) or "")
    exp = int(m.group(3) or 0)
    return abs(float(s) - exact) <= 0.5 * 10 ** (exp - decimals) * (1 + 1e-9)


def check_probe(driver, candela, exr, x, y, units):
    assert text(driver, "p-pixel").startswith(f"pixel ({x}, {y})")
    want = probe_lines(candela, exr, x, y, units)
    for row, id_ in PROBE_ROWS.items():
        # `candela probe` leaves out the lines that do not apply (sRGB of a black pixel).
        assert text(driver, id_) == want.get(row, ""), (x, y, units, row)
    # The numbers against the JSON: mean, ± half-width, interval ends, standard error.
    j = probe_json(candela, exr, x, y, units)
    for key, id_ in (("luminance", "p-lum"), ("illuminance", "p-ill")):
        est = j[key]
        shown = text(driver, id_)
        if est.get("mean") is None:
            assert "undefined" in shown
            continue
        parts = re.match(r"(\S+)(?: ± (\S+))? \S+ {3}\((?:95 % CI (\S+) … (\S+); standard error (\S+)\))?", shown)
        assert parts, shown
        assert close_to_printed(parts.group(1), est["mean"])
        if est["ci95"] is not None:
            lo, hi = est["ci95"]
            assert close_to_printed(parts.group(2), (hi - lo) / 2)
            assert close_to_printed(parts.group(3), lo)
            assert close_to_printed(parts.group(4), hi)
            assert close_to_printed(parts.group(5), est["stderr"])
    return j


def requests_made(driver, page):
    """URLs the browser requested, other than the page itself (CDP Network events)."""
    urls = []
    for entry in driver.get_log("performance"):
        msg = json.loads(entry["message"])["message"]
        if msg["method"] in ("Network.requestWillBeSent", "Network.webSocketCreated"):
            url = msg["params"].get("request", {}).get("url") or msg["params"].get("url", "")
            if url != page.as_uri():
                urls.append(url)
    return urls


def test_probe_false_colour_units_and_no_network(render, candela, driver):
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    exr, page = render / "room.exr", render / "room.html"
    source = page.read_text()
    assert "http://" not in source and "https://" not in source
    open_page(driver, page)
    size = driver.execute_script("return [document.getElementById('image').width, document.getElementById('image').height]")
    assert size == [48, 36]
    w, h = size

    # Pixels chosen here: corners, centre, the desk, the open side, and a seeded spread.
    import random
    rng = random.Random(24)
    pixels = [(0, 0), (w - 1, h - 1), (w // 2, h // 2), (30, 28), (5, 30), (46, 3), (2, 12)]
    pixels += [(rng.randrange(w), rng.randrange(h)) for _ in range(6)]
    seen_undefined = seen_defined = False
    for x, y in pixels:
        hover(driver, x, y, size)
        j = check_probe(driver, candela, exr, x, y, "si")
        seen_defined |= bool(j["illuminance"]["defined"])
        seen_undefined |= not j["illuminance"]["defined"]
        assert text(driver, "p-medl") and text(driver, "p-medi")
    assert seen_defined and seen_undefined
    driver.save_screenshot(str(ARTIFACTS / "probe.png"))

    # Keyboard: a click pins the probe, arrows move it one pixel (Shift: ten).
    hover(driver, 10, 10, size)
    ActionChains(driver).click().perform()
    canvas = driver.find_element(By.ID, "image")
    canvas.send_keys(Keys.ARROW_RIGHT)
    canvas.send_keys(Keys.ARROW_DOWN)
    canvas.send_keys(Keys.SHIFT, Keys.ARROW_RIGHT)
    check_probe(driver, candela, exr, 21, 11, "si")
    assert "pinned" in text(driver, "p-pixel")

    # False colour: luminance with the automatic range of `candela falsecolour`.
    assert driver.execute_script("return document.getElementById('legend').hidden")
    driver.find_element(By.ID, "fc-on").click()
    assert not driver.execute_script("return document.getElementById('legend').hidden")
    assert "luminance (cd/m²), linear scale" == text(driver, "legend-title")
    # The legend narrowed the image: the probe's marker still sits on pixel (21, 11).
    c, m = driver.execute_script("""return ['image', 'marker'].map(id =>
        document.getElementById(id).getBoundingClientRect().toJSON())""")
    mx = (m["left"] + m["right"]) / 2 - c["left"]
    my = (m["top"] + m["bottom"]) / 2 - c["top"]
    assert (int(mx / c["width"] * w), int(my / c["height"] * h)) == (21, 11), (m, c)
    fc = subprocess.run([candela, "falsecolour", exr, "-o", render / "fc.png"],
                        capture_output=True, text=True, check=True).stdout
    top = re.search(r"0 – (\S+) cd/m²", fc)
    assert top, fc
    ticks = driver.execute_script("return [...document.querySelectorAll('#legend-ticks li')].map(e => e.textContent)")
    assert len(ticks) == 11 and ticks[0] == "0"
    assert abs(float(ticks[-1]) - float(top.group(1))) <= 1e-9 * float(top.group(1)), (ticks, fc)
    # A pixel is painted with the palette at its position on the scale.
    painted = driver.execute_script("""
        const c = document.getElementById('image').getContext('2d');
        return Array.from(c.getImageData(30, 28, 1, 1).data.slice(0, 3));""")
    lum = probe_json(candela, exr, 30, 28)["luminance"]["mean"]
    pal = json.loads(driver.execute_script("return document.getElementById('candela-data').textContent"))["palettes"]["turbo"]
    assert painted == pal[round(min(lum / float(top.group(1)), 1.0) * 255)]
    driver.save_screenshot(str(ARTIFACTS / "falsecolour-luminance.png"))

    Select(driver.find_element(By.ID, "fc-q")).select_by_value("illuminance")
    assert text(driver, "legend-title") == "illuminance (lx), linear scale"
    assert not driver.execute_script("return document.getElementById('legend-undefined').hidden")
    Select(driver.find_element(By.ID, "fc-scale")).select_by_value("log")
    assert text(driver, "legend-title") == "illuminance (lx), log scale"
    driver.save_screenshot(str(ARTIFACTS / "falsecolour-illuminance-log.png"))

    # Imperial units: the probe equals `candela probe --units imperial`, the legend and the
    # grid statistics are converted (1 fc = 10.7639 lx).
    driver.find_element(By.ID, "units-imperial").click()
    assert text(driver, "legend-title") == "illuminance (fc), log scale"
    check_probe(driver, candela, exr, 21, 11, "imperial")
    canvas.send_keys(Keys.ESCAPE)
    for x, y in [(30, 28), (2, 12), (40, 20)]:
        hover(driver, x, y, size)
        check_probe(driver, candela, exr, x, y, "imperial")

    # A range typed in: the legend runs from its minimum to its maximum.
    Select(driver.find_element(By.ID, "fc-scale")).select_by_value("linear")
    for id_, v in (("fc-min", "2"), ("fc-max", "12")):
        field = driver.find_element(By.ID, id_)
        field.clear()
        field.send_keys(v, Keys.TAB)
    ticks = driver.execute_script("return [...document.querySelectorAll('#legend-ticks li')].map(e => e.textContent)")
    assert ticks == ["2", "3", "4", "5", "6", "7", "8", "9", "10", "11", "12"], ticks
    report = json.loads((render / "room.report.json").read_text())
    g = report["grids"][0]
    caption = text(driver, "grids").replace("\u202f", " ")
    shown_avg = re.search(r"E_avg (\S+) fc", caption).group(1)
    assert close_to_printed(shown_avg, g["E_avg"] / 10.763910416709722)
    driver.find_element(By.ID, "units-si").click()
    caption = text(driver, "grids")
    assert close_to_printed(re.search(r"E_avg (\S+) lx", caption).group(1), g["E_avg"])
    # Meters and run information.
    meters = text(driver, "meters")
    for m in report["meters"]:
        assert m["name"] in meters
    run = text(driver, "run")
    assert report["progressive"]["stop_reason"] in run and report["scene"] in run
    driver.save_screenshot(str(ARTIFACTS / "tables.png"))

    # No request left the page: CDP's Network events, and the resource timing list.
    assert requests_made(driver, page) == []
    assert driver.execute_script("return performance.getEntriesByType('resource').length") == 0

    # Time to the image (the page's own mark) and to the first contentful paint, for the docs.
    timing = driver.execute_script("""
        const m = performance.getEntriesByName('candela-image-drawn')[0];
        const p = performance.getEntriesByName('first-contentful-paint')[0];
        return {image_drawn_ms: m ? m.startTime : null, first_contentful_paint_ms: p ? p.startTime : null};""")
    assert timing["image_drawn_ms"] is not None
    (ARTIFACTS / "timing.json").write_text(json.dumps(timing))


def test_zoom_and_print(render, driver):
    page = render / "room.html"
    open_page(driver, page)
    # 200 % zoom of a 1280 px wide window: a 640 CSS px viewport at 2 device pixels per CSS
    # pixel. Nothing may need sideways scrolling.
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                           {"width": 640, "height": 900, "deviceScaleFactor": 2, "mobile": False})
    over = driver.execute_script("return document.documentElement.scrollWidth - document.documentElement.clientWidth")
    driver.save_screenshot(str(ARTIFACTS / "zoom-200.png"))
    driver.execute_cdp_cmd("Emulation.clearDeviceMetricsOverride", {})
    assert over <= 0, over
    # Print: controls hidden, image, legend and tables on A4 pages.
    driver.find_element(By.ID, "fc-on").click()
    driver.execute_cdp_cmd("Emulation.setEmulatedMedia", {"media": "print"})
    shown = driver.execute_script("""return ['controls', 'image', 'legend', 'grids-section', 'meters-section']
        .map(id => getComputedStyle(document.getElementById(id)).display)""")
    breaks = driver.execute_script("""return ['grids-section', 'probe']
        .map(id => getComputedStyle(document.getElementById(id)))
        .map(s => [s.breakBefore, s.breakInside])""")
    driver.execute_cdp_cmd("Emulation.setEmulatedMedia", {"media": ""})
    assert shown[0] == "none" and "none" not in shown[1:], shown
    assert breaks == [["page", "auto"], ["auto", "avoid"]], breaks
    opts = PrintOptions()
    opts.page_width, opts.page_height = 21.0, 29.7
    pdf = base64.b64decode(driver.print_page(opts))
    assert pdf.startswith(b"%PDF")
    (ARTIFACTS / "report-a4.pdf").write_bytes(pdf)


def test_report_command_with_glare(render, candela, driver):
    exr = render / "room.exr"
    glare = subprocess.run([candela, "glare", exr, "--json", "--draws", "0"], capture_output=True, text=True)
    if glare.returncode != 0:
        pytest.skip(f"candela glare refused the perspective image: {glare.stderr}")
    (render / "room.glare.json").write_text(glare.stdout)
    page = render / "glare.html"
    run = subprocess.run([candela, "report", exr, "--glare", render / "room.glare.json", "-o", page],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    open_page(driver, page)
    g = json.loads(glare.stdout)
    shown = text(driver, "glare")
    assert f"{g['dgp']['value']:.3f}" in shown
    assert len(driver.find_elements(By.CSS_SELECTOR, "#glare table:nth-of-type(2) tbody tr")) == len(g["sources"])
    driver.save_screenshot(str(ARTIFACTS / "glare.png"))


@pytest.mark.skipif(not os.environ.get("CANDELA_HTML_LARGE"), reason="set CANDELA_HTML_LARGE=1")
def test_large_page_size_and_time_to_image(candela, driver, tmp_path):
    """The figures of docs/report-html.md: a 1920×1080 render with E, its page's size, and the
    time from navigation to the first paint and to the decoded image."""
    scene = tmp_path / "large.ron"
    scene.write_text(SCENE.read_text().replace("resolution: (48, 36)", "resolution: (1920, 1080)"))
    run = subprocess.run([candela, "render", scene, "--out", tmp_path / "large", "--illuminance",
                          "--quiet", "--checkpoint-interval", "0s", "--spp", "16", "--report-html"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    page = tmp_path / "large.html"
    open_page(driver, page)
    timing = driver.execute_script("""
        const m = performance.getEntriesByName('candela-image-drawn')[0];
        const p = performance.getEntriesByName('first-contentful-paint')[0];
        return {image_drawn_ms: m.startTime, first_contentful_paint_ms: p ? p.startTime : null};""")
    timing.update(page_bytes=page.stat().st_size, exr_bytes=(tmp_path / "large.exr").stat().st_size)
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    (ARTIFACTS / "large.json").write_text(json.dumps(timing))
    print(timing)
