"""Every endpoint of the REST API and its error paths, over HTTP against `trackstar serve`."""

from __future__ import annotations

import json
import math
import re
import subprocess
import xml.etree.ElementTree as ET

import pytest
from _server import Server
from conftest import scenario_dict

import planner
import tracks

SVG_NS = 'xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"'
# Two paths in a 100 mm × 50 mm document (1 user unit = 1 mm): a 60 mm square loop and a line.
TWO_PATHS = (f'<svg {SVG_NS} width="100mm" height="50mm" viewBox="0 0 100 50">'
             '<path id="loop" inkscape:label="Ring" d="M10 10 h30 v30 h-30 z" stroke-width="4"/>'
             '<path id="road" d="M50 10 L90 10" stroke-width="2"/></svg>').encode()


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    srv = Server(tmp_path_factory.mktemp("data"), "--max-upload-mb", "0.1",
                 "--max-plan-s", "3")
    yield srv
    srv.stop()


def upload(server, data: bytes, filename="t.svg", **form):
    return server.client.post("/tracks", files={"file": (filename, data, "image/svg+xml")},
                              data=form)


def test_health_landing_and_docs(server):
    health = server.get("/health").json()
    assert health == {"status": "ok", "version": "0.1.0", "ui_port": server.ui_port}
    landing = server.get("/")
    assert landing.status_code == 200 and 'href="/docs"' in landing.text
    docs = server.get("/docs")
    assert docs.status_code == 200
    # Offline: Swagger UI's script and style come from this server, not a CDN.
    assets = re.findall(r'(?:src|href)="([^"]+\.(?:js|css))"', docs.text)
    assert len(assets) == 2 and all(a.startswith("/") for a in assets), assets
    for asset in assets:
        assert server.get(asset).status_code == 200, asset
    paths = server.get("/openapi.json").json()["paths"]
    for path in ("/api/v1/tracks", "/api/v1/tracks/{track_id}/profile", "/api/v1/plan",
                 "/api/v1/jobs/{job_id}/results.csv", "/api/v1/scenarios/{scenario_id}"):
        assert path in paths


def test_library_tracks_come_first_and_match_the_tracks_package(server):
    listed = server.client.get("/tracks").json()
    names = tracks.library_names()
    assert [t["id"] for t in listed[:len(names)]] == names
    thesis = next(t for t in listed if t["id"] == "thesis")
    assert thesis["source"] == "library" and thesis["closed"]
    assert thesis["length_m"] == pytest.approx(tracks.load_library_track("thesis").length_m)


def test_upload_lists_every_path_and_serves_geometry(server):
    resp = upload(server, TWO_PATHS, path="Ring")
    assert resp.status_code == 201, resp.text
    track = resp.json()
    assert track["source"] == "upload" and track["closed"] and track["name"] == "Ring"
    assert track["length_m"] == pytest.approx(0.12) and track["width_m"] == pytest.approx(0.004)
    assert track in server.client.get("/tracks").json()

    paths = server.client.get(f"/tracks/{track['id']}/paths").json()
    assert [(p["id"], p["label"]) for p in paths["paths"]] == [("loop", "Ring"), ("road", None)]
    assert paths["unit_m"] == pytest.approx(0.001)

    geo = server.client.get(f"/tracks/{track['id']}").json()
    centre = geo["centerline"]
    xs, ys = [p[0] for p in centre], [p[1] for p in centre]
    # World frame: x = 1 mm · svg_x, y = −1 mm · svg_y.
    assert min(xs) == pytest.approx(0.01) and max(xs) == pytest.approx(0.04)
    assert max(ys) == pytest.approx(-0.01) and min(ys) == pytest.approx(-0.04)
    assert len(geo["left"]) == len(geo["right"]) == len(centre)
    for (lx, ly), (rx, ry) in zip(geo["left"], geo["right"]):
        assert ((lx - rx) ** 2 + (ly - ry) ** 2) ** 0.5 == pytest.approx(0.004)


def test_profile_is_the_track_sample_json_object(server, tmp_path):
    got = server.client.get("/tracks/carolo/profile",
                            params={"spacing": 0.1, "wheelbase": 0.3, "max_steer_deg": 20})
    cli = subprocess.run(["trackstar", "track", "sample", "carolo", "--json", "--spacing", "0.1",
                          "--wheelbase", "0.3", "--max-steer-deg", "20"],
                         capture_output=True, text=True, check=True)
    assert got.json() == json.loads(cli.stdout)
    assert server.client.get("/tracks/carolo/profile", params={"spacing": -1}).status_code == 422
    too_fine = server.client.get("/tracks/carolo/profile", params={"spacing": 1e-7})
    assert too_fine.status_code == 422 and "points" in too_fine.json()["detail"]


def test_svg_export_round_trips(server, tmp_path):
    resp = server.client.get("/tracks/thesis/svg")
    assert resp.headers["content-type"].startswith("image/svg+xml")
    ET.fromstring(resp.content)
    again = tracks.load_svg(resp.content)
    assert again.length_m == pytest.approx(tracks.load_library_track("thesis").length_m, rel=1e-6)


def test_delete_upload_but_not_library(server):
    track_id = upload(server, TWO_PATHS).json()["id"]
    assert server.client.delete(f"/tracks/{track_id}").status_code == 204
    assert server.client.get(f"/tracks/{track_id}").status_code == 404
    assert server.client.delete(f"/tracks/{track_id}").status_code == 404
    assert server.client.delete("/tracks/thesis").status_code == 403


@pytest.mark.parametrize("data, status, words", [
    (b"hello", 400, "malformed XML"),
    (b"<html><body/></html>", 400, "not an SVG"),
    ((b'<?xml version="1.0"?><!DOCTYPE lolz [<!ENTITY lol "lol"><!ENTITY lol2 "&lol;&lol;">]>'
     b'<svg xmlns="http://www.w3.org/2000/svg"><text>&lol2;</text></svg>'), 400, "unsafe XML"),
    ((b'<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY x SYSTEM "file:///etc/passwd">]>'
     b'<svg xmlns="http://www.w3.org/2000/svg"><text>&x;</text></svg>'), 400, "unsafe XML"),
    (f'<svg {SVG_NS}><text>no paths</text></svg>'.encode(), 400, "no path"),
    (f'<svg {SVG_NS}><path d="M0 0 l{" 1 1" * 20_001}"/></svg>'.encode(), 400, "segments"),
    (b"<svg " + b"x" * 120_000 + b"/>", 413, "limit"),
    (f'<svg {SVG_NS}>{"<g>" * 2000}<path d="M0 0 L9 0"/>{"</g>" * 2000}</svg>'.encode(), 400,
     "nested"),
])
def test_bad_uploads_are_refused_with_a_message(server, data, status, words):
    resp = upload(server, data)
    assert resp.status_code == status and words in resp.json()["detail"]


def test_a_chunked_upload_above_the_limit_is_413(server):
    def chunks():  # no Content-Length: httpx sends it chunked
        yield b"--b\r\nContent-Disposition: form-data; name=file; filename=t.svg\r\n\r\n"
        for _ in range(40):
            yield b"x" * 8192
    resp = server.client.post("/tracks", content=chunks(),
                              headers={"content-type": "multipart/form-data; boundary=b"})
    assert resp.status_code == 413 and "limit" in resp.json()["detail"]


@pytest.mark.parametrize("change, words", [
    ({"name": "\ud800"}, "name"),
    ({"bounds": [-1e308, -1e308, 1e308, 1e308]}, "bounds"),
    ({"vehicle": {"wheelbase": 1e308}}, "vehicle.wheelbase"),
    ({"obstacles": [{"type": "circle", "center": [1, 1], "radius": 0.1,
                     "motion": {"velocity": [1e8, 0]}}]}, "less than or equal to 100"),
    ({"vehicle": {"footprint": {"type": "rectangle", "length": 1e300, "width": 1e-300}}},
     "vehicle.footprint.length"),
    ({"bounds": None, "track": {"name": "nested", "svg": f'<svg {SVG_NS}>{"<g>" * 2000}'
                                                          f'{"</g>" * 2000}</svg>'}}, "nested"),
])
def test_hostile_scenarios_are_4xx_naming_the_field(server, change, words):
    body = json.dumps(scenario_dict("slalom") | change)  # a lone surrogate: "\ud800"
    resp = server.client.post("/scenarios", content=body,
                              headers={"content-type": "application/json"})
    assert resp.status_code in (400, 422) and words in json.dumps(resp.json()), resp.text
    plan = server.client.post("/plan", content=f'{{"scenario": {body}, "time": 0.05}}',
                              headers={"content-type": "application/json"})
    assert plan.status_code in (400, 422) and words in json.dumps(plan.json()), plan.text


def test_upload_options_are_checked(server):
    unknown = upload(server, TWO_PATHS, path="nope")
    assert unknown.status_code == 400 and "'nope'" in unknown.json()["detail"]
    assert "loop" in unknown.json()["detail"]  # it lists what is available
    assert upload(server, TWO_PATHS, unit="furlong").status_code == 400
    km = upload(server, TWO_PATHS, unit="m")  # a 120 m loop: fine
    assert km.status_code == 201 and km.json()["length_m"] == pytest.approx(120)
    assert server.client.post("/tracks").status_code == 422  # no file


def test_unknown_ids_are_404(server):
    for path in ("/tracks/nope", "/tracks/nope/paths", "/tracks/nope/profile", "/tracks/nope/svg",
                 "/scenarios/nope", "/jobs/nope", "/jobs/nope/results.csv"):
        resp = server.client.get(path)
        assert resp.status_code == 404 and "nope" in resp.json()["detail"], path
    assert server.client.post("/plan", json={"scenario_id": "nope"}).status_code == 404


def test_the_openapi_example_plans_and_the_schema_is_served(server):
    spec = server.get("/openapi.json").json()
    example = spec["components"]["schemas"]["PlanRequest"]["examples"][0]
    report = server.client.post("/plan", json=example)
    assert report.status_code == 200 and report.json()["solved"], report.text
    schema = server.client.get("/scenarios/schema").json()
    assert {"start", "goal", "obstacles", "track"} <= schema["properties"].keys()


def test_scenarios_crud(server):
    body = scenario_dict("slalom")
    created = server.client.post("/scenarios", json=body)
    assert created.status_code == 201
    record = created.json()
    assert record["name"] == "slalom" and record["scenario"] == body
    assert record["source"] == "upload" and record["id"] != "slalom"
    assert server.client.get(f"/scenarios/{record['id']}").json() == record
    assert record in server.client.get("/scenarios").json()
    assert server.client.delete(f"/scenarios/{record['id']}").status_code == 204
    assert server.client.get(f"/scenarios/{record['id']}").status_code == 404


REFERENCE = ["open_field", "hallway", "slalom", "parking", "oval_track", "crossing"]


def test_bundled_scenarios_come_first_read_only_and_plan_by_name(server):
    listed = server.client.get("/scenarios").json()
    names = planner.scenario_names()
    assert [r["id"] for r in listed[:len(names)]] == names and set(REFERENCE) <= set(names)
    assert all(r["source"] == "library" and r["id"] == r["name"] for r in listed[:len(names)])
    slalom = server.client.get("/scenarios/slalom").json()
    assert slalom["scenario"] == scenario_dict("slalom")
    resp = server.client.delete("/scenarios/slalom")
    assert resp.status_code == 403 and "bundled" in resp.json()["detail"]
    assert server.client.get("/scenarios/slalom").status_code == 200
    report = server.client.post("/plan", json={"scenario_id": "slalom", "time": 0.3}).json()
    assert report["scenario"] == "slalom" and report["solved"]


def _broken(change) -> dict:
    body = scenario_dict("open_field")
    change(body)
    return body


@pytest.mark.parametrize("body, words", [
    (_broken(lambda b: b.update(start=[b["obstacles"][0]["center"][0],
                                       b["obstacles"][0]["center"][1], 0])), "start"),
    (_broken(lambda b: b["obstacles"][0].update(radius=-1)), "obstacles[0].radius"),
    (_broken(lambda b: b["vehicle"].update(wheelbase=float("nan"))), "vehicle.wheelbase"),
    (_broken(lambda b: b.update(obstacle=[])), "did you mean 'obstacles'"),
    (_broken(lambda b: b.update(track={"name": "nowhere"})), "nowhere"),
    ([1, 2], "valid dictionary"),
])
def test_bad_scenarios_are_422_naming_the_field(server, body, words):
    text = json.dumps(body)  # NaN goes over the wire as the JSON extension NaN
    for path, wrap in (("/scenarios", body), ("/plan", {"scenario": body})):
        resp = server.client.post(path, content=json.dumps(wrap) if path == "/plan" else text,
                                  headers={"content-type": "application/json"})
        assert resp.status_code == 422, (path, resp.text)
        assert words in json.dumps(resp.json()["detail"]), (path, resp.text)


@pytest.mark.parametrize("path, body, words", [
    ("/plan", {"scenario_id": "x", "tme": 1}, "unknown key 'tme' (did you mean 'time'?)"),
    ("/plan", {"scenario_id": "x", "steering": "dubin"},
     "'dubin' is not a steering (did you mean 'dubins'?)"),
    ("/jobs", {"scenarios": ["x"], "sedes": [1]}, "unknown key 'sedes' (did you mean 'seeds'?)"),
    ("/jobs", {"scenarios": ["x"], "parameters": [{"planer": "rrt"}]},
     "unknown key 'planer' (did you mean 'planner'?)"),
    ("/simulations", {"scenario_id": "x", "rate_hz": 3},
     "unknown key 'rate_hz' (did you mean 'rate'?)"),
    ("/simulations", {"scenario_id": "x", "timing": "fast"},
     "'fast' is not a timing (use one of constant, optimal)"),
])
def test_bad_options_are_422_naming_the_value_and_the_nearest_key(server, path, body, words):
    resp = server.client.post(path, json=body)
    assert resp.status_code == 422, resp.text
    assert words in json.dumps(resp.json()["detail"]), resp.text


def test_openapi_carries_the_scenario_schema_in_every_body(server):
    spec = server.get("/openapi.json").json()
    schemas = spec["components"]["schemas"]

    def resolved(schema: dict) -> dict:
        return schemas[schema["$ref"].rsplit("/", 1)[1]] if "$ref" in schema else schema

    def body(path: str) -> dict:
        return resolved(spec["paths"][path]["post"]["requestBody"]["content"]
                        ["application/json"]["schema"])

    scenario = schemas["Scenario"]
    assert {"start", "goal", "obstacles", "vehicle", "track"} <= scenario["properties"].keys()
    assert set(scenario["required"]) == {"name", "start", "goal"}
    obstacles = scenario["properties"]["obstacles"]["items"]
    kinds = {resolved(o)["properties"]["type"]["const"]: resolved(o) for o in obstacles["oneOf"]}
    assert kinds.keys() == {"circle", "polygon", "box"}
    assert all("motion" in kind["properties"] for kind in kinds.values())
    motion = resolved(kinds["circle"]["properties"]["motion"]["anyOf"][0])
    assert {"velocity", "waypoints", "follow_track"} <= motion["properties"].keys()
    vehicle = resolved(scenario["properties"]["vehicle"])
    assert {"radius", "footprint", "wheelbase"} <= vehicle["properties"].keys()
    ref = {"$ref": "#/components/schemas/Scenario"}
    for path in ("/api/v1/plan", "/api/v1/simulations"):
        assert ref in body(path)["properties"]["scenario"]["anyOf"], path
    assert ref in body("/api/v1/jobs")["properties"]["scenarios"]["items"]["anyOf"]
    posted = spec["paths"]["/api/v1/scenarios"]["post"]["requestBody"]["content"]
    assert posted["application/json"]["schema"]["$ref"] == ref["$ref"]
    # The schema the API validates with is the one GET /scenarios/schema publishes.
    published = server.client.get("/scenarios/schema").json()
    assert published["properties"].keys() == scenario["properties"].keys()


def test_minimal_format_scenarios_plan_inline(server):
    for name in REFERENCE:
        body = scenario_dict(name)
        report = server.client.post("/plan", json={"scenario": body, "iterations": 50})
        assert report.status_code == 200 and report.json()["scenario"] == name, report.text


def test_plan_is_the_cli_plan_json(server):
    options = {"iterations": 800, "seed": 3, "planner": "rrt"}
    got = server.client.post("/plan", json={"scenario": scenario_dict("open_field"), **options})
    assert got.status_code == 200, got.text
    cli = subprocess.run(["trackstar", "plan", "open_field", "--json",
                          "--iterations", "800", "--seed", "3", "--planner", "rrt"],
                         capture_output=True, text=True, check=True)
    report, expected = got.json(), json.loads(cli.stdout)
    assert report.keys() == expected.keys()
    assert report["path"] == expected["path"] and report["cost"] == expected["cost"]
    assert report["parameters"]["time"] == 3  # iterations only: the server's cap still holds


def test_the_plan_body_has_the_options_of_trackstar_plan_with_the_same_defaults(server):
    spec = server.get("/openapi.json").json()["components"]["schemas"]["PlanRequest"]
    api = {name: field.get("default") for name, field in spec["properties"].items()
           if name not in ("scenario", "scenario_id")}
    helped = subprocess.run(["trackstar", "plan", "--help"], capture_output=True, text=True,
                            check=True).stdout
    cli = set(re.findall(r"^  --([a-z][a-z-]*)", helped, re.MULTILINE)) - {
        "json", "help", "raceline", "animate"}  # outputs
    assert cli == {name.replace("_", "-") for name in api}
    # The defaults a run without options uses: the CLI's echo of them is the API's schema.
    ran = json.loads(subprocess.run(["trackstar", "plan", "slalom", "--iterations", "50",
                                     "--json"], capture_output=True, text=True,
                                    check=True).stdout)["parameters"]
    for name in ("planner", "steering", "seed", "goal_bias", "k_rrt"):
        assert ran[name] == api[name], name


def test_plan_by_id_on_an_uploaded_track(server):
    track = upload(server, TWO_PATHS, path="loop", unit="m").json()  # 30 m square, 4 m wide
    scenario = {"name": "square", "track": {"name": track["id"]},
                "start": [15, -10, 0], "goal": [40, -25, -1.5708]}
    created = server.client.post("/scenarios", json=scenario)
    assert created.status_code == 201, created.text
    report = server.client.post("/plan", json={"scenario_id": created.json()["id"],
                                               "time": 1}).json()
    assert report["scenario"] == "square" and report["solved"]
    for x, y, _ in report["path"]:  # inside the 4 m band around the square's centreline
        near_edge = min(abs(x - 10), abs(x - 40), abs(y + 10), abs(y + 40))
        assert near_edge <= 2.0 + 1e-6


@pytest.mark.parametrize("body, words", [
    ({"scenario_id": "x", "scenario": {}}, "exactly one"),
    ({}, "exactly one"),
    ({"scenario": scenario_dict("slalom"), "time": 10}, "limit of 3"),
    ({"scenario": {}, "time": -1}, "greater than 0"),
    ({"scenario": {}, "time": -1}, "invalid scenario: name: Field required"),  # both named
    ({"scenario": {}, "planner": "prm"}, "rrtstar"),
    ({"scenario": {}, "goal_bias": 1.5}, "less than 1"),
    ({"scenario": {}, "colour": "red"}, "colour"),
    ({"scenario": {}, "timing": "fast"}, "timing"),
    ({"scenario_id": "train", "timing": "optimal", "speed": 2.5}, "above vehicle.max_speed"),
])
def test_bad_plan_options_are_422(server, body, words):
    resp = server.client.post("/plan", json=body)
    assert resp.status_code == 422 and words in json.dumps(resp.json()["detail"]), resp.text


def _circle_csv(r: float, n: int = 120, right: float = 0.4, left: float = 0.6) -> bytes:
    rows = [f"{r * math.cos(2 * math.pi * k / n)!r},{r * math.sin(2 * math.pi * k / n)!r},"
            f"{right},{left}" for k in range(n)]
    return ("# x_m,y_m,w_tr_right_m,w_tr_left_m\n" + "\n".join(rows)).encode()


def test_a_centreline_csv_uploads_with_its_curvature_raceline_and_scenario(server):
    resp = upload(server, _circle_csv(3.0), filename="ring.csv")
    assert resp.status_code == 201, resp.text
    track = resp.json()
    assert track["name"] == "ring" and track["closed"] and track["width_m"] == pytest.approx(1.0)
    assert track["length_m"] == pytest.approx(2 * math.pi * 3.0, rel=1e-4)
    profile = server.client.get(f"/tracks/{track['id']}/profile", params={"spacing": 0.1}).json()
    kappa = [p["curvature"] for p in profile["points"]]
    assert kappa == pytest.approx([1 / 3.0] * len(kappa), rel=5e-3)
    paths = server.client.get(f"/tracks/{track['id']}/paths").json()["paths"]
    assert [(p["selector"], p["width_m"]) for p in paths] == [("centerline", 1.0)]
    line = server.client.get(f"/tracks/{track['id']}/raceline.csv",
                             params={"v_max": 10, "a_lat_max": 3}).text.splitlines()
    assert line[0] == "# s_m; x_m; y_m; psi_rad; kappa_radpm; vx_mps; ax_mps2"
    assert float(line[1].split(";")[5]) == pytest.approx(3.0, rel=5e-3)  # √(A·r)
    centre = server.client.get(f"/tracks/{track['id']}/centerline.csv").text.splitlines()
    assert centre[1].split(",")[2:] == ["0.4000000", "0.6000000"]
    scenario = {"name": "ring", "track": {"name": track["id"]},
                "start": [3.0, 0.0, 1.5708], "goal": [-3.0, 0.0, -1.5708]}
    assert server.client.post("/scenarios", json=scenario).status_code == 201
    road = upload(server, _circle_csv(3.0), filename="arc.csv", closed="false").json()
    assert not road["closed"] and road["length_m"] < track["length_m"]


@pytest.mark.parametrize("data, form, words", [
    (b"0,0,1,1\n1,0,1,1\n2,1,1\n3,3,1,1\n", {}, "cannot use this CSV: t line 3: expected 4"),
    (b"", {}, "no points"),
    (b"0,0,1,1\n1,0,1,1\n2,1,1,1\n3,3,1,1\n", {"unit": "mm"}, "'unit' is for SVG"),
])
def test_bad_csv_uploads_are_refused_with_the_line(server, data, form, words):
    resp = upload(server, data, filename="t.csv", **form)
    assert resp.status_code == 400 and words in resp.json()["detail"]


def test_raceline_options_are_checked(server):
    for params in ({"a_long_max": 0}, {"spacing": -1}, {"spacing": 1e-7}):
        resp = server.client.get("/tracks/thesis/raceline.csv", params=params)
        assert resp.status_code == 422, params
