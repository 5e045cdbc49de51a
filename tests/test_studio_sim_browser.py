"""The studio's live simulation in a real browser: load the crossing scenario, press Simulate,
see the car move among the mover and the Soll/Ist and lateral error plots fill.

Shares the server, browser and helpers of test_studio_browser.py; screenshots land in
tests/artifacts/studio/ (sim_*.png).
"""

from __future__ import annotations

import io
import time

import numpy as np
import test_studio_browser as sb

import planner

pytestmark = sb.pytestmark
# The studio browser tests' fixtures: its server (ui_url, and urls where it has them), chromium
# and the closing of every tab after a test.
globals().update({k: getattr(sb, k) for k in ("urls", "ui_url", "browser", "close_tabs")
                  if hasattr(sb, k)})

PATH_RGB = (255, 90, 200)  # the committed path (app/studio/_live_view.py)


def colour_pixels(img: np.ndarray, rgb, tol: int = 60) -> int:
    return int((np.abs(img - rgb).sum(axis=2) < tol).sum())


def lane_box(img: np.ndarray) -> tuple[int, int, int, int]:
    """Rows and columns of the crossing's lane (its dark asphalt), a few pixels inside."""
    dark = img.sum(axis=2) < 300
    rows, cols = np.flatnonzero(dark.mean(axis=1) > 0.3), np.flatnonzero(dark.mean(axis=0) > 0.3)
    return rows[0] + 5, rows[-1] - 5, cols[0] + 5, cols[-1] - 5


def car_along(img: np.ndarray, lane) -> float | None:
    """How far along the lane the car is (0 left, 1 right of the view): its white body is the
    only white on the asphalt."""
    r0, r1, c0, c1 = lane
    cols = np.nonzero(img[r0:r1, c0:c1].min(axis=2) > 200)[1]
    return float(cols.mean() / (c1 - c0)) if len(cols) > 20 else None


def sim_status(page) -> str:
    return page.locator("p", has_text="Simulation:").first.inner_text()


def wait_status(page, word: str, timeout: float) -> str:
    deadline = time.monotonic() + timeout
    while word not in (text := sim_status(page)) and time.monotonic() < deadline:
        time.sleep(0.3)
    return text


def test_simulate_plays_the_crossing_live(browser, ui_url):
    page = sb.open_tab(browser, ui_url)
    page.set_default_timeout(60000)  # a live run keeps software WebGL busy: screenshots queue
    thesis = sb.canvas_pixels(page)
    page.locator("input[type=file][accept='.json']").set_input_files(
        str(planner.bundled_scenario_path("crossing")))
    sb.wait_until(page, lambda img: np.abs(img - thesis).sum(axis=2).astype(bool).mean() > 0.2)
    sb.wait_still(page)
    lane = lane_box(sb.canvas_pixels(page, "sim_00_crossing"))
    scroll_to(page.locator(".uplot", has_text="Soll"))  # in the pictures
    sb.click(page, "Simulate")
    # Software WebGL on two cores lags the live run by seconds (on a loaded machine one
    # screenshot can take longer than the run): look at where the car is, not when.
    shots = []
    while not shots or (len(shots) < 5 and "done" not in sim_status(page)):
        png = page.screenshot(path=str(sb.ARTIFACTS / f"sim_{len(shots) + 1:02d}.png"))
        shots.append(pixels(png)[:, :960])
        time.sleep(2.0)  # a few shots spread over the ~19 s run, not a queue of them
    seen = [x for x in (car_along(img, lane) for img in shots) if x is not None]
    assert seen, "no car on the lane"
    assert seen[-1] > 0.3, seen  # it starts 5 % along the lane and drives right
    # The committed path: a metre or more of pink even when the car is at the goal.
    assert max(colour_pixels(img, PATH_RGB) for img in shots) > 50, "no committed path drawn"
    # The run ends with its summary (whether the goal is reached is test_simulate.py's
    # question; measured cycle times on a loaded machine change the run).
    assert "done" in wait_status(page, "done", 120), sim_status(page)
    # The plots: two more uPlot charts, with their curves drawn.
    assert page.locator(".uplot canvas").count() >= 6
    steering = page.locator(".uplot", has_text="Soll")
    assert colour_pixels(chart(page, steering, "sim_steering"), (74, 144, 226)) > 30, "no Ist"
    lateral = page.locator(".uplot", has_text="lateral error")
    assert colour_pixels(chart(page, lateral, "sim_lateral"), (142, 68, 173)) > 30, "no error"
    safety = page.locator(".uplot", has_text="Safety timeline")  # issue 30: speed, guard, contacts
    assert colour_pixels(chart(page, safety, "sim_safety"), (46, 139, 87)) > 30, "no speed"
    assert "guard" in page.locator("td", has_text="guard").first.inner_text()
    assert sb.metric(page, "cycles") > 100
    page.screenshot(path=str(sb.ARTIFACTS / "sim_done_panel.png"))
    page.close()


def scroll_to(locator) -> None:
    """Scroll the panel to an element without Playwright's stability wait (live content keeps
    shifting the panel's layout)."""
    locator.evaluate("e => e.scrollIntoView({block: 'center'})")


def chart(page, plot, name: str) -> np.ndarray:
    """A uPlot chart's pixels (saved as a PNG): scrolled into view and clipped from the page,
    since an element screenshot waits for a still layout."""
    scroll_to(plot)
    box = plot.locator("canvas").first.bounding_box()
    assert box and box["width"] > 100 and box["height"] > 50, box
    return pixels(page.screenshot(path=str(sb.ARTIFACTS / f"{name}.png"), clip=box))


def pixels(png: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
