"""The session's GUI controls, built once per browser tab (labels are what tests click)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import planner
import tracks
from app.studio._extend import FIRST_NOTE, render
from app.studio._live_view import legend_html
from app.studio._replay_slider import NO_REPLAY
from app.studio._vehicle import APPLIED, FOOTPRINTS
from app.studio._worker import STEP_CAP
from planner.sim.control import CONTROLLERS
from planner.sim.run import GUARD_CODES

__all__ = ["DEFAULT_BUDGET", "MOTIONS", "PLANNERS", "SPEEDS", "STEERINGS", "TIMINGS", "Panel",
           "SimControls", "build_panel", "build_sim_controls"]

PLANNERS = {"RRT*": "rrtstar", "RRT": "rrt"}
STEERINGS = {s.label: s.name for s in planner.STEERINGS.values()}
TIMINGS = {"constant speed": "constant", "fastest arrival (may wait)": "optimal"}
MOTIONS = ("static", "velocity", "waypoints", "follow track")
# Iterations: a lecture run ends while its tree is readable and the browser fast (past ~10 000
# nodes software WebGL crawls); Run on a finished run goes on for as many again.
DEFAULT_BUDGET = 5000
START_HINT = ("**Start here:** press **Run** to grow the tree, or **Step** for one "
              "iteration; click an obstacle, the start or the goal to move it.")
SPEEDS = {"max": None, "2000 it/s": 2000.0, "200 it/s": 200.0, "20 it/s": 20.0}


@dataclass
class Panel:
    """Handles of every control a session reads or wires up."""

    track: object
    svg_upload: object
    svg_path: object
    fit: object
    draw: object
    draw_width: object
    draw_close: object
    draw_undo: object
    draw_use: object
    draw_download: object
    add_circle: object
    add_box: object
    polygon: object
    close_polygon: object
    clear_obstacles: object
    handles: object
    motion: object
    velocity: object
    waypoints: object
    track_speed: object
    set_motion: object
    scene_time: object
    play: object
    scenario_download: object
    scenario_upload: object
    scenario_save: object
    scenario_load: object
    scenario_name: object
    vehicle: dict  # field name → control (app/studio/_vehicle.py)
    vehicle_note: object
    planner_name: object
    steering: object
    timing: object
    eps: object
    gamma: object
    k_rrt: object
    goal_bias: object
    budget: object
    seed: object
    rate: object
    split: object  # the two-up split (issue 20): run B beside A, its settings
    b_planner: object
    b_steering: object
    b_seed: object
    run: object
    pause: object
    step: object
    reset: object
    replay: object
    replay_note: object
    pin: object
    clear_pins: object
    pins_legend: object
    comparison_csv: object
    comparison_png: object
    drive: object
    raceline_download: object
    animation_download: object
    status: object
    metrics: object
    extend: object
    # Step tools and the View folder (issue 20)
    planner_folder: object
    extend_folder: object
    step_node: object
    step_rewire: object
    projector: object
    fade_tree: object
    projector_css: object
    plots: object


def build_panel(gui) -> Panel:
    with gui.add_folder("Track"):
        track = gui.add_dropdown("Track", tuple(tracks.library_names()), initial_value="thesis")
        svg_upload = gui.add_upload_button("Upload SVG or CSV",
                                           mime_type=".svg,.csv,image/svg+xml,text/csv")
        svg_path = gui.add_dropdown("SVG path", ("—",), visible=False)
        fit = gui.add_button("Fit view")
    with gui.add_folder("Draw a track", expand_by_default=False):
        draw = gui.add_checkbox("Draw (click the ground)", False)
        draw_width = gui.add_number("Width (m)", 0.6, min=0.1, max=10.0, step=0.05)
        draw_close = gui.add_checkbox("Closed loop", True)
        draw_undo = gui.add_button("Undo point")
        draw_use = gui.add_button("Use drawn track")
        draw_download = gui.add_button("Download track SVG")
    with gui.add_folder("Obstacles"):
        add_circle = gui.add_button("Add circle")
        add_box = gui.add_button("Add box")
        polygon = gui.add_checkbox("Polygon (click the ground)", False)
        close_polygon = gui.add_button("Close polygon")
        clear_obstacles = gui.add_button("Clear obstacles")
        handles = gui.add_checkbox("Drag handles", True)
        motion = gui.add_dropdown("Motion", tuple(MOTIONS), initial_value="static")
        velocity = gui.add_vector2("Velocity (m/s)", (0.3, 0.0), step=0.05)
        waypoints = gui.add_text("Waypoints (t dx dy; …)", "0 0 0; 3 0.5 0; 6 0.5 0.5")
        track_speed = gui.add_number("Speed along track (m/s)", 0.5, step=0.1)
        set_motion = gui.add_button("Set motion of selected")
        scene_time = gui.add_slider("Scene time (s)", 0.0, 30.0, 0.1, 0.0)
        play = gui.add_checkbox("Play scene time", False)
    with gui.add_folder("Scenario", expand_by_default=False):
        scenario_name = gui.add_text(
            "Name", "studio", hint="Save and load by this name; load a bundled scenario by its "
                                   "name (slalom, crossing, hallway, …)")
        scenario_download = gui.add_button("Download scenario (JSON)")
        scenario_upload = gui.add_upload_button("Upload scenario (JSON)", mime_type=".json")
        scenario_save = gui.add_button("Save to server")
        scenario_load = gui.add_button("Load from server")
    with gui.add_folder("Vehicle", expand_by_default=False):
        vehicle = {
            "wheelbase": gui.add_number("Wheelbase (m)", 0.44, step=0.01),
            "max_steer_deg": gui.add_number("Max steering angle (deg)", 26.0, step=1.0),
            "max_steer_rate_deg_s": gui.add_number(
                "Max steering rate (deg/s)", 180.0, step=10.0,
                hint="How fast the steering servo turns: the CC steerings ramp their curvature "
                     "so that the planned speed never asks for more; Simulate's servo turns "
                     "this fast"),
            "footprint": gui.add_dropdown("Footprint", FOOTPRINTS, initial_value="disc"),
            "radius": gui.add_number("Disc radius (m)", 0.0, step=0.01,
                                     hint="0: the car is a point"),
            "length": gui.add_number("Car length (m)", 0.4, step=0.01, visible=False),
            "width": gui.add_number("Car width (m)", 0.2, step=0.01, visible=False),
            "speed": gui.add_number("Speed (m/s)", 1.0, step=0.1,
                                    hint="The speed the planner times its paths for"),
            "safety_margin": gui.add_number(
                "Safety margin (m)", 0.0, step=0.01,
                hint="Distance planned paths keep from every obstacle and boundary"),
        }
        vehicle_note = gui.add_markdown(APPLIED)
    with gui.add_folder("Planner", order=-8) as planner_folder:
        # The run controls first: at 1280 × 800 they are in sight without scrolling.
        run = gui.add_button("Run")
        pause = gui.add_button("Pause")
        step = gui.add_button("Step")
        reset = gui.add_button("Reset")
        planner_name = gui.add_dropdown("Planner", tuple(PLANNERS), initial_value="RRT*")
        steering = gui.add_dropdown("Steering", tuple(STEERINGS))
        timing = gui.add_dropdown(
            "Timing", tuple(TIMINGS), initial_value="constant speed",
            hint="Constant speed: the car drives the path at the vehicle's speed. Fastest "
                 "arrival: at any speed up to the vehicle's max_speed, standing still too; the "
                 "plan arriving first, which waits for a moving obstacle when that beats going "
                 "round it")
        eps = gui.add_number("ε (step length, m; 0 = auto)", 0.0, min=0.0, step=0.05,
                             hint="The longest edge one iteration adds; auto: 15 % of the "
                                  "track's size, at least two turning radii")
        gamma = gui.add_number("γ (rewiring radius scale; 0 = auto)", 0.0, min=0.0, step=0.5,
                               hint="RRT* rewires within r = γ (log n / n)^(1/d) of a new "
                                    "node; auto: from the free area")
        k_rrt = gui.add_number("k-nearest factor (0: use the radius)", 0.0, min=0.0, step=0.5,
                               hint="RRT* rewires the k·log n nearest nodes instead of those "
                                    "within the radius (OMPL: 5.5)")
        goal_bias = gui.add_slider("Goal bias (probability)", 0.0, 0.5, 0.01, 0.05,
                                   hint="How often the goal is sampled instead of a random pose")
        budget = gui.add_number("Budget (iterations)", DEFAULT_BUDGET, min=1, step=1000)
        seed = gui.add_number("Seed", 0, min=0, step=1)
        rate = gui.add_dropdown("Pace (it/s)", tuple(SPEEDS), initial_value="max",
                                hint="Slows the planner down to watch the tree grow")
        with gui.add_folder("Two-up split (A | B)", expand_by_default=False):
            split = gui.add_checkbox(
                "Split: run B beside A", False,
                hint="A second run on the same scenario, drawn to the right of this one (A); "
                     "Run, Pause, Step and the pace drive both, iteration for iteration")
            b_planner = gui.add_dropdown("B: planner", tuple(PLANNERS), initial_value="RRT")
            b_steering = gui.add_dropdown("B: steering", tuple(STEERINGS))
            b_seed = gui.add_number("B: seed", 0, min=0, step=1)
        replay = gui.add_slider(
            "Replay (iteration)", 0, 1, 1, 0, disabled=True,
            hint="When the run is paused or done: the tree and the best path as they stood "
                 "after this iteration; the last one, Run or Step go back to the run")
        replay_note = gui.add_markdown(NO_REPLAY)
        pin = gui.add_button(
            "Pin this run", hint="Keeps this run's best path, profiles and cost over time "
                                 "drawn in a colour of its own under the next runs (4 at most: "
                                 "a fifth replaces the oldest)")
        clear_pins = gui.add_button("Clear pins")
        pins_legend = gui.add_html("", visible=False)
        comparison_csv = gui.add_button(
            "Download comparison (CSV)", hint="One row per pinned run and the current one")
        comparison_png = gui.add_button(
            "Download comparison plots (PNG)",
            hint="Curvature, steering and best cost over time of the pinned runs and the "
                 "current one")
        drive = gui.add_button("Drive car")
        raceline_download = gui.add_button("Download raceline (CSV)",
                                            hint="The best path in the TUM raceline layout")
        animation_download = gui.add_button(
            "Download animation (GIF)",
            hint="The run on screen as 40 frames: the tree growing, its rewires and the best "
                 "path, for slides; where obstacles move, 24 more drive the car among them")
        status = gui.add_markdown("Status: ready")
    with gui.add_folder("Metrics"):
        metrics = gui.add_markdown("—")
    with gui.add_folder("EXTEND") as extend_folder:
        extend = gui.add_html(render(None, FIRST_NOTE))
        gui.add_html(legend_html())
    plots = gui.add_folder("Profiles")
    # Step tools (issue 20): in the Planner folder right after Step (a folder shows its rows
    # by `order`), and the View folder, first in the panel.
    with planner_folder:
        step_node = gui.add_button(
            "Step until a node is added", order=step.order + 0.3,
            hint=f"Single iterations until one adds a node ({STEP_CAP:,} at most)")
        step_rewire = gui.add_button(
            "Step until a rewire", order=step.order + 0.6,
            hint=f"Single iterations until one rewires the tree (RRT*; {STEP_CAP:,} at most)")
    gui.add_markdown(START_HINT, order=-9)
    with gui.add_folder("View", order=-10):
        projector = gui.add_checkbox(
            "Projector mode", False,
            hint="Larger text, lines and labels, the run controls on top, no gizmos once a "
                 "run has started (Reset brings them back), the view fitted beside the panel")
        fade_tree = gui.add_checkbox("Fade the tree", False,
                                     hint="Draw the tree dim, so the best path and a step "
                                          "stand out")
        projector_css = gui.add_html("")
    return Panel(**{k: v for k, v in locals().items() if k != "gui"})


@dataclass
class SimControls:
    """The `Simulate` folder's handles."""

    rate: object
    controller: object
    noise: object
    seed: object
    simulate: object
    stop: object
    status: object
    metrics: object
    steering: object
    lateral: object
    safety: object


def build_sim_controls(gui) -> SimControls:
    """The `Simulate` folder (`SimView` drives it)."""
    with gui.add_folder("Simulate"):
        rate = gui.add_number("Replanning rate (Hz)", 30.0, min=1.0, max=100.0, step=1.0)
        controller = gui.add_dropdown("Controller", CONTROLLERS, initial_value=CONTROLLERS[0])
        noise = gui.add_number("Noise σ (m)", 0.0, min=0.0, max=1.0, step=0.01)
        seed = gui.add_number("Simulation seed", 0, min=0, step=1)
        simulate_ = gui.add_button("Simulate")
        stop = gui.add_button("Stop")
        status = gui.add_markdown("Simulation: ready")
        metrics = gui.add_markdown("—")
        t = np.array([0.0, 1.0])
        nan = np.full(2, math.nan)
        common = {"aspect": 2.0, "legend": {"show": True}, "scales": {"x": {"time": False}}}
        steering = gui.add_uplot(
            (t, nan, nan), ({"label": "t (s)"},
                            {"label": "δ commanded (deg)", "stroke": "#e8542f", "width": 1.5},
                            {"label": "δ actual (deg)", "stroke": "#4a90e2", "width": 2.0}),
            title="Steering: commanded (Soll) vs actual (Ist)", **common)
        lateral = gui.add_uplot(
            (t, nan), ({"label": "t (s)"},
                       {"label": "lateral error (cm)", "stroke": "#8e44ad", "width": 1.5}),
            title="Lateral error to the path being followed", **common)
        codes = " ".join(f"{v} {k}" for k, v in GUARD_CODES.items())
        safety = gui.add_uplot(
            (t, nan, nan, nan),
            ({"label": "t (s)"},
             {"label": "speed (m/s)", "stroke": "#2e8b57", "width": 1.5},
             {"label": f"guard ({codes})", "stroke": "#ff7800", "width": 1.5},
             {"label": "contact (1 moving, 2 at rest)", "stroke": "#e61e1e", "width": 2.0}),
            title="Safety timeline: speed, what the guard did, contacts", **common)
    return SimControls(rate, controller, noise, seed, simulate_, stop, status, metrics,
                       steering, lateral, safety)
