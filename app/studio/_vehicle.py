"""The Vehicle folder: the scenario's car, which the planner plans, Drive car drives and Simulate
simulates, edited as the scenario's ``vehicle`` so a downloaded or saved scenario carries it.

`VehicleForm` fills the folder from a loaded scenario and turns an edit into a new vehicle,
validated by the scenario model (planner/scenario.py `Vehicle`); a refused value leaves the car
as it was and the model's message in the folder.
"""

from __future__ import annotations

from pydantic import ValidationError

from planner.scenario import Vehicle
from planner.validation import describe

__all__ = ["APPLIED", "FOOTPRINTS", "VehicleForm", "fields_of", "vehicle_from_fields"]

FOOTPRINTS = ("disc", "rectangle")
APPLIED = "Planned, driven and simulated with this car."
APPLYING = "Applying this car…"


def fields_of(vehicle: Vehicle) -> dict:
    """The folder's values for ``vehicle`` (a disc car keeps the panel's rectangle as is)."""
    fields = {"wheelbase": vehicle.wheelbase, "max_steer_deg": vehicle.max_steer_deg,
              "max_steer_rate_deg_s": vehicle.max_steer_rate_deg_s,
              "footprint": "disc" if vehicle.footprint is None else "rectangle",
              "radius": vehicle.radius, "speed": vehicle.speed,
              "safety_margin": vehicle.safety_margin}
    if vehicle.footprint is not None:
        fields.update(length=vehicle.footprint.length, width=vehicle.footprint.width)
    return fields


def vehicle_from_fields(base: dict, fields: dict) -> dict:
    """``base`` (the scenario's vehicle dict) with the folder's ``fields`` set. The fields it
    does not show (acceleration, rear overhang, …) are kept; a given turning radius is dropped
    once the wheelbase or steering angle changes, or it would overrule them. Raises ValueError
    with the model's one-line message for a car the scenario model refuses."""
    out = {k: v for k, v in base.items() if k not in ("radius", "footprint")}
    out.update({k: float(fields[k]) for k in ("wheelbase", "max_steer_deg", "speed",
                                              "safety_margin")})
    rate = float(fields["max_steer_rate_deg_s"])
    default = Vehicle.model_fields["max_steer_rate_deg_s"].default
    if rate != base.get("max_steer_rate_deg_s", default):
        out["max_steer_rate_deg_s"] = rate  # the scenario's, or its default, stays implicit
    steering = (base.get("wheelbase"), base.get("max_steer_deg"))
    if steering != (out["wheelbase"], out["max_steer_deg"]):
        out.pop("min_turning_radius", None)
    if fields["footprint"] == "rectangle":
        old = base.get("footprint") or {}
        out["footprint"] = {"type": "rectangle", "length": float(fields["length"]),
                            "width": float(fields["width"]),
                            **({"rear_overhang": old["rear_overhang"]}
                               if old.get("rear_overhang") is not None else {})}
    else:
        out["radius"] = float(fields["radius"])
    try:
        Vehicle.model_validate(out)
    except ValidationError as exc:
        raise ValueError(describe(exc)) from None
    return out


class VehicleForm:
    """The folder's controls (``ui.vehicle`` of the panel) bound to the session's scenario."""

    def __init__(self, controls: dict, note, scenario_vehicle, set_vehicle) -> None:
        """``controls``: field name → GUI handle; ``scenario_vehicle()`` the stage's vehicle
        dict; ``set_vehicle(vehicle) -> str | None`` applies a car, or says why it cannot."""
        self.controls, self.note = controls, note
        self._vehicle, self._set_vehicle = scenario_vehicle, set_vehicle
        self._filling = False
        for handle in controls.values():
            handle.on_update(lambda _: self.edited())

    def show(self, vehicle: Vehicle) -> None:
        """Fill the folder from a newly loaded scenario's car (no edit: nothing is applied)."""
        self._filling = True
        try:
            for name, value in fields_of(vehicle).items():
                self.controls[name].value = value
        finally:
            self._filling = False
        self._show_shape()
        self.note.content = APPLIED

    def edited(self) -> None:
        if self._filling:
            return
        # Said first, so that a browser that sees the new fields sees this too, and a Run
        # clicked before the car is applied can tell (applying resets the planner).
        self.note.content = APPLYING
        self._show_shape()
        try:
            vehicle = vehicle_from_fields(self._vehicle(), {
                name: handle.value for name, handle in self.controls.items()})
        except ValueError as exc:
            self._refuse(str(exc))
            return
        error = self._set_vehicle(vehicle)
        if error is not None:
            self._refuse(error)

    def _refuse(self, message: str) -> None:
        self.note.content = f"**Not applied, the car is unchanged:** {message}"

    def _show_shape(self) -> None:
        """The radius for a disc, length and width for a rectangle."""
        rectangle = self.controls["footprint"].value == "rectangle"
        self.controls["radius"].visible = not rectangle
        self.controls["length"].visible = self.controls["width"].visible = rectangle
