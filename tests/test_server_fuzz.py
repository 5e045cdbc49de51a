"""Fuzzing the API with hypothesis: whatever the body, path or query, the answer is a 2xx or a
4xx with a message — never a 500, never a hang."""

from __future__ import annotations

import asyncio
import json
import time

import msgspec
import pytest
import viser
from _server import Server
from conftest import scenario_dict
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from websockets.asyncio.client import connect
from websockets.exceptions import ConnectionClosed

JSON = st.recursive(
    st.none() | st.booleans() | st.integers(-2**70, 2**70) | st.text(max_size=8)
    | st.floats(allow_nan=True, allow_infinity=True),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner,
                                                                 max_size=4),
    max_leaves=12,
)
KEYS = st.sampled_from(["name", "bounds", "start", "goal", "vehicle", "obstacles", "track",
                        "goal_tolerance", "radius", "center", "points", "motion", "type",
                        "wheelbase", "max_steer_deg", "velocity", "waypoints", "size", "speed"])
FUZZ = settings(max_examples=40, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    srv = Server(tmp_path_factory.mktemp("data"), "--max-plan-s", "0.2")
    yield srv
    srv.stop()


def mutate(data, path: list, value):
    """Replace (or add) the element at ``path`` (indices wrap, keys may be new)."""
    if not path or not isinstance(data, dict | list) or not data:
        return value
    head, *rest = path
    if isinstance(data, list):
        i = head % len(data) if isinstance(head, int) else 0
        return [mutate(v, rest, value) if j == i else v for j, v in enumerate(data)]
    key = head if isinstance(head, str) else sorted(data)[head % len(data)]
    return {**data, key: mutate(data.get(key), rest, value)}


def near_valid_scenario():
    base = scenario_dict("crossing")
    return st.builds(mutate, st.just(base),
                     st.lists(st.integers(0, 20) | KEYS, min_size=1, max_size=4), JSON)


def post(server, path: str, body):
    """POST any JSON, NaN and infinity included (as Python's json writes them)."""
    return server.client.post(path, content=json.dumps(body, allow_nan=True),
                              headers={"content-type": "application/json"})


def check(resp):
    assert resp.status_code < 500, resp.text
    if resp.status_code >= 400:
        assert resp.json()["detail"], resp.text


@FUZZ
@given(scenario=near_valid_scenario(), options=st.dictionaries(
    st.sampled_from(["planner", "steering", "time", "iterations", "seed", "eps", "goal_bias",
                     "informed", "speed", "k_rrt"]), JSON, max_size=3))
def test_plan_and_scenarios_never_fail_on_the_server(server, scenario, options):
    check(post(server, "/plan", {"scenario": scenario, **options}))
    check(post(server, "/scenarios", scenario))


@FUZZ
@given(body=JSON, seeds=st.lists(JSON, max_size=3))
def test_jobs_never_fail_on_the_server(server, body, seeds):
    check(post(server, "/jobs", {"scenarios": [body], "seeds": seeds}
               if isinstance(body, dict) else body))


@FUZZ
@given(track=st.sampled_from(["thesis", "nope", "..", "%00", "a" * 300]),
       endpoint=st.sampled_from(["", "/paths", "/profile", "/svg"]),
       query=st.dictionaries(st.sampled_from(["spacing", "wheelbase", "max_steer_deg"]),
                             st.text(max_size=6) | st.floats().map(str), max_size=3))
def test_track_reads_never_fail_on_the_server(server, track, endpoint, query):
    check(server.client.get(f"/tracks/{track}{endpoint}", params=query))


@FUZZ
@given(svg=st.binary(max_size=200) | st.text(max_size=200).map(
    lambda t: f'<svg xmlns="http://www.w3.org/2000/svg"><path d="{t}"/></svg>'.encode()),
       path=st.none() | st.text(max_size=5), unit=st.none() | st.text(max_size=4))
def test_uploads_never_fail_on_the_server(server, svg, path, unit):
    form = {k: v for k, v in (("path", path), ("unit", unit)) if v is not None}
    check(server.client.post("/tracks", files={"file": ("f.svg", svg)}, data=form))


def test_malformed_studio_frames_close_that_socket_with_one_log_line(server):
    """Random bytes, a text frame and msgpack of the wrong types: each socket is closed and
    logged in one line, without a traceback; the studio still opens for the next tab."""
    frames = [bytes(range(256)) * 2, "hello", msgspec.msgpack.encode([1, 2, 3]),
              msgspec.msgpack.encode({"type": "GuiUpdateMessage", "id": 5, "updates": 3}),
              msgspec.msgpack.encode({"type": "ViewerCameraMessage", "wxyz": 1})]
    before = len(server.err)

    async def send(frame) -> str:
        async with connect(f"ws://127.0.0.1:{server.ui_port}/",
                           subprotocols=[f"viser-v{viser.__version__}"],
                           additional_headers={"Origin": f"http://127.0.0.1:{server.ui_port}"}
                           ) as ws:
            await asyncio.wait_for(ws.recv(), 30)
            if frame is None:
                return "open"
            await ws.send(frame)
            try:
                while True:
                    await asyncio.wait_for(ws.recv(), 10)
            except ConnectionClosed as closed:
                return f"closed {closed.rcvd.code}"

    for frame in frames:
        assert asyncio.run(send(frame)).startswith("closed"), frame
    assert asyncio.run(send(None)) == "open"
    time.sleep(0.5)  # the reader thread takes the last lines
    logged = [line for line in server.err[before:] if "warn" not in line.lower()]
    closes = [line for line in logged if "closed a websocket that sent a malformed" in line]
    assert len(closes) == len(frames), logged
    assert not any("Traceback" in line or line.startswith("  ") for line in logged), logged
