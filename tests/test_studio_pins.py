"""What a pin shows of its run (issue 20), without a browser: the car it planned for, in the
pins' legend and the comparison CSV, and its reverse stretches shaded in the profiles."""

from __future__ import annotations

import csv
import io
from types import SimpleNamespace

import numpy as np
import pytest

import planner
from app.raceline import raceline_limits
from app.studio._compare import PALETTE, Pins, Run, comparison_csv
from app.studio._plots import SHADE, Profiles
from planner.scenario import Vehicle

CAR = Vehicle(wheelbase=0.3, max_steer_deg=30.0, safety_margin=0.05,
              footprint={"type": "rectangle", "length": 0.4, "width": 0.2})


def reversing_path() -> np.ndarray:
    """Rows x, y, θ, κ, direction, t: 4 m forward along x, then 2 m back."""
    x = np.r_[np.linspace(0, 4, 41), np.linspace(3.9, 2, 20)]
    rows = np.zeros((len(x), 6))
    rows[:, 0], rows[:, 4] = x, np.r_[1.0, np.ones(40), -np.ones(20)]
    return rows


def _pins(*cars) -> Pins:
    pins = Pins(SimpleNamespace(remove_by_name=lambda name: None))
    for car in cars:
        pins.add(Run(planner.PlanOptions(steering="reeds-shepp"), {"iterations": 10, "cost": 6.0},
                     reversing_path(), [], car))
    return pins


def test_a_pin_names_its_car_in_the_legend_and_the_csv():
    pins = _pins(CAR, Vehicle(radius=0.1), Vehicle())
    legend = pins.legend_html()
    for car in ("car: wheelbase 0.3 m, δmax 30°, 0.4 × 0.2 m, margin 0.05 m",
                "car: wheelbase 0.44 m, δmax 26°, disc r 0.1 m<",
                "car: wheelbase 0.44 m, δmax 26°, point<"):
        assert car in legend
    rows = list(csv.DictReader(io.StringIO(comparison_csv(pins.runs))))
    cells = [(r["wheelbase_m"], r["max_steer_deg"], r["footprint"], r["disc_radius_m"],
              r["car_length_m"], r["car_width_m"], r["safety_margin_m"]) for r in rows]
    assert cells == [("0.3", "30", "rectangle", "", "0.4", "0.2", "0.05"),
                     ("0.44", "26", "disc", "0.1", "", "", "0"),
                     ("0.44", "26", "point", "0", "", "", "0")]
    assert float(rows[0]["turning_radius_m"]) == pytest.approx(CAR.turning_radius)


def test_the_profiles_shade_each_pins_reverse_in_its_colour():
    charts = []
    gui = SimpleNamespace(add_uplot=lambda data, series, **k: charts.append(
        SimpleNamespace(data=data, series=series)) or charts[-1],
                          add_markdown=lambda content: SimpleNamespace(content=content))
    profiles = Profiles(gui, np.linspace(0, 14, 50), np.zeros(50), 10.0, 0.3, 30.0, 180.0,
                        raceline_limits(vehicle=CAR))
    profiles.set_pins(_pins(CAR, CAR).runs)
    for chart, symbol in zip(charts[:2], (" κ", " δ")):  # curvature, steering
        labels = [s["label"] for s in chart.series]
        grid, top = chart.data[0], chart.data[3][0] * SHADE
        for pin, colour in zip(("pin 1", "pin 2"), PALETTE):
            k = labels.index(f"{pin} reverse")
            assert chart.series[k]["fill"] == "rgba({},{},{},0.13)".format(
                *(int(colour[i:i + 2], 16) for i in (1, 3, 5)))
            assert chart.series[k]["fillTo"] == -top
            assert np.allclose(chart.data[k][(grid > 4.05) & (grid < 5.95)], top)  # 2 m back
            assert np.allclose(chart.data[k][grid < 3.95], -top)  # forward: no height
        assert labels[-2:] == [f"pin 1{symbol}", f"pin 2{symbol}"]  # the curves above
        assert len(chart.series) == len(chart.data)
