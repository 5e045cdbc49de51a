"""The studio's live simulation in a real browser: load the crossing scenario, press Simulate,
see the car move among the mover and the Soll/Ist and lateral error plots fill.

Shares the server, browser and helpers of test_studio_browser.py; screenshots land in
tests/artifacts/studio/ (sim_*.png).
"""

from __future__ import annotations

import io
import itertools
import time

import numpy as np
import test_studio_browser as sb
from conftest import SCENARIOS

pytestmark = sb.pytestmark
# The studio browser tests' fixtures: its server (ui_url, and urls where it has them) and chromium.
globals().update({k: getattr(sb, k) for k in ("urls", "ui_url", "browser") if hasattr(sb, k)})

PATH_RGB = (255, 90, 200)  # the committed path (app/studio/_live_view.py)


def colour_pixels(img: np.ndarray, rgb, tol: int = 60) -> int:
    return int((np.abs(img - rgb).sum(axis=2) < tol).sum())


def sim_status(page) -> str:
    return page.locator("p", has_text="Simulation:").first.inner_text()


def wait_status(page, word: str, timeout: float) -> str:
    deadline = time.monotonic() + timeout
    while word not in (text := sim_status(page)) and time.monotonic() < deadline:
        time.sleep(0.3)
    return text


def test_simulate_plays_the_crossing_live(browser, ui_url):
    page = sb.open_tab(browser, ui_url)
    thesis = sb.canvas_pixels(page)
    page.locator("input[type=file][accept='.json']").set_input_files(
        str(SCENARIOS / "crossing.json"))
    sb.wait_until(page, lambda img: np.abs(img - thesis).sum(axis=2).astype(bool).mean() > 0.2)
    sb.wait_still(page)
    sb.canvas_pixels(page, "sim_00_crossing")
    page.locator(".uplot", has_text="Soll").scroll_into_view_if_needed()  # for the pictures
    sb.click(page, "Simulate")
    # Software WebGL on two cores lags the live run by seconds: compare frames, not clocks.
    # The car drives and the mover moves, so consecutive views differ; the committed path
    # shows up.
    shots = []
    while len(shots) < 12 and "done" not in sim_status(page):
        png = page.screenshot(path=str(sb.ARTIFACTS / f"sim_{len(shots) + 1:02d}.png"))
        shots.append(pixels(png)[:, :960])
    changed = [int((np.abs(b - a).sum(axis=2) > 60).sum()) for a, b in itertools.pairwise(shots)]
    assert len(shots) >= 2 and max(changed) > 300, changed
    assert max(colour_pixels(img, PATH_RGB) for img in shots) > 200, "no committed path drawn"
    assert "goal reached" in wait_status(page, "done", 90), sim_status(page)
    # The plots: two more uPlot charts, with their curves drawn.
    steering = page.locator(".uplot", has_text="Soll")
    steering.scroll_into_view_if_needed()
    assert page.locator(".uplot canvas").count() >= 5
    box = steering.locator("canvas").first.bounding_box()
    assert box and box["width"] > 100 and box["height"] > 50
    assert colour_pixels(chart(steering, "sim_steering"), (74, 144, 226)) > 30, "no Ist curve"
    lateral = page.locator(".uplot", has_text="lateral error")
    assert colour_pixels(chart(lateral, "sim_lateral"), (142, 68, 173)) > 30, "no error curve"
    assert sb.metric(page, "cycles") > 100
    page.screenshot(path=str(sb.ARTIFACTS / "sim_done_panel.png"))
    page.close()


def chart(plot, name: str) -> np.ndarray:
    """A uPlot chart's pixels (saved as a PNG)."""
    return pixels(plot.screenshot(path=str(sb.ARTIFACTS / f"{name}.png")))


def pixels(png: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
