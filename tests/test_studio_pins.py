"""What a pin says of its run (issue 20), without a browser: the car it planned for, in the
pins' legend and the comparison CSV."""

from __future__ import annotations

import csv
import io
from types import SimpleNamespace

import numpy as np
import pytest

import planner
from app.studio._compare import Pins, Run, comparison_csv
from planner.scenario import Vehicle

CAR = Vehicle(wheelbase=0.3, max_steer_deg=30.0, safety_margin=0.05,
              footprint={"type": "rectangle", "length": 0.4, "width": 0.2})


def _reversing_path() -> np.ndarray:
    """Rows x, y, θ, κ, direction, t: 4 m forward along x, then 2 m back."""
    x = np.r_[np.linspace(0, 4, 41), np.linspace(3.9, 2, 20)]
    rows = np.zeros((len(x), 6))
    rows[:, 0], rows[:, 4] = x, np.r_[1.0, np.ones(40), -np.ones(20)]
    return rows


def _pins(*cars) -> Pins:
    pins = Pins(SimpleNamespace(remove_by_name=lambda name: None))
    for car in cars:
        pins.add(Run(planner.PlanOptions(steering="reeds-shepp"), {"iterations": 10, "cost": 6.0},
                     _reversing_path(), [], car))
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
