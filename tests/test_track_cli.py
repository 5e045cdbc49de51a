"""`trackstar track …` through the installed console script: output contracts and bad input."""

import csv
import io
import json
import subprocess
import time
from pathlib import Path

import pytest

DATA = Path(__file__).parent / "data"


def run(*args, cwd=None):
    started = time.perf_counter()
    done = subprocess.run(
        ["trackstar", "track", *args],
        capture_output=True,
        text=True,
        check=False,
        cwd=cwd,
        timeout=60,
    )
    return done, time.perf_counter() - started


def test_inspect_json_lists_every_rendered_path_with_its_measures():
    done, _ = run("inspect", str(DATA / "nested_mm.svg"), "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert set(report) == {"format", "unit_m", "paths"} and report["format"] == "svg"
    keys = {"selector", "id", "label", "subpath", "closed", "length_m", "length_user", "bbox_m",
            "width_m"}
    assert all(set(p) == keys and len(p["bbox_m"]) == 4 for p in report["paths"])
    assert [p["id"] for p in report["paths"]][:2] == ["arcpath", "mirror"]


def test_inspect_unit_option_rescales_the_document():
    done, _ = run("inspect", str(DATA / "nested_mm.svg"), "--unit", "cm", "--json")
    report = json.loads(done.stdout)
    assert report["unit_m"] == 0.01
    assert report["paths"][0]["length_user"] == pytest.approx(2 * (25 + 5 * 3.141592653589793))


def test_sample_json_starts_at_the_start_and_ends_at_the_end():
    done, _ = run("sample", "thesis", "--json", "--spacing", "0.05")
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    assert set(out) == {"length_m", "closed", "points"} and out["closed"] is True
    first, last = out["points"][0], out["points"][-1]
    assert set(first) == {"s", "x", "y", "heading", "curvature", "steering_deg", "feasible"}
    assert first["s"] == 0 and last["s"] == pytest.approx(out["length_m"])
    assert (first["x"], first["y"]) == pytest.approx((2.3732491, -0.26388819))
    assert (last["x"], last["y"]) == pytest.approx((first["x"], first["y"]), abs=1e-9)


def test_sample_csv_with_path_wheelbase_and_steering_limit(tmp_path):
    done, _ = run(
        "sample",
        str(DATA / "nested_mm.svg"),
        "--path",
        "centre",
        "--csv",
        "--spacing",
        "0.001",
        "--wheelbase",
        "0.02",
        "--max-steer-deg",
        "30",
    )
    assert done.returncode == 0, done.stderr
    rows = list(csv.DictReader(io.StringIO(done.stdout)))
    assert float(rows[-1]["s"]) == pytest.approx(0.0814159, abs=1e-6)
    on_arc = [r for r in rows if abs(float(r["curvature"])) > 1]
    assert on_arc and all(r["feasible"] == "False" for r in on_arc)  # atan(0.02·50) = 45° > 30°


def test_sampling_an_element_of_several_subpaths_says_which_one_it_took(tmp_path):
    """A ring drawn as one path with its inner edge: --path ring takes the longest subpath,
    and says so on stderr and in the JSON; ring:1 chooses the inner one, without a note."""
    svg = tmp_path / "ring.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="50mm" '
                   'viewBox="0 0 100 50"><path id="ring" stroke-width="2" '
                   'd="M15 15 h20 v20 h-20 z M10 10 h30 v30 h-30 z"/></svg>')
    note = "ring has 2 subpaths; took ring:1, the longest; choose one with ring:N"
    done, _ = run("sample", str(svg), "--path", "ring", "--json")
    assert done.returncode == 0 and done.stderr.strip() == note
    data = json.loads(done.stdout)
    assert data["note"] == note and data["length_m"] == pytest.approx(0.12)
    done, _ = run("sample", str(svg), "--path", "ring:0", "--json")
    assert done.returncode == 0 and done.stderr == ""
    data = json.loads(done.stdout)
    assert "note" not in data and data["length_m"] == pytest.approx(0.08)


def test_plot_writes_a_figure(tmp_path):
    for name in ("profile.png", "profile.svg"):
        done, _ = run("plot", "carolo", "-o", str(tmp_path / name))
        assert done.returncode == 0, done.stderr
        assert (tmp_path / name).stat().st_size > 10_000


@pytest.mark.parametrize(
    ("args", "content"),
    [
        (["inspect", "missing.svg"], None),
        (["sample", "bad.svg"], b"this is not xml"),
        (["sample", "page.svg"], b"<html><p>hello</p></html>"),
        (
            ["inspect", "bomb.svg"],
            b'<?xml version="1.0"?><!DOCTYPE s [<!ENTITY a "aaaaaaaaaa">'
            b'<!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;"><!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;">]>'
            b'<svg xmlns="http://www.w3.org/2000/svg"><text>&c;</text></svg>',
        ),
        (
            ["sample", "ok.svg", "--path", "nope"],
            b'<svg xmlns="http://www.w3.org/2000/svg"><path id="p" d="M0 0H9"/></svg>',
        ),
        (
            ["plot", "ok.svg", "-o", "figure.txt"],
            b'<svg xmlns="http://www.w3.org/2000/svg"><path d="M0 0H9"/></svg>',
        ),
        (
            ["sample", "ok.svg", "--spacing", "-1"],
            b'<svg xmlns="http://www.w3.org/2000/svg"><path d="M0 0H9"/></svg>',
        ),
    ],
)
def test_bad_input_exits_2_with_one_line_on_stderr_quickly(tmp_path, args, content):
    """Quickly: no hang (the entity bomb would expand to 10⁹ characters); a start takes about
    0.5 s alone, and up to 3 s beside the other test worker's browser, so the bound is 5 s."""
    if content is not None:
        (tmp_path / args[1]).write_bytes(content)
    done, seconds = run(*args, cwd=tmp_path)
    assert done.returncode == 2
    assert done.stdout == ""
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), done.stderr
    assert seconds < 5.0


def test_csv_in_export_and_raceline_out(tmp_path):
    done, _ = run("export", "thesis", "-o", str(tmp_path / "thesis.csv"), "--spacing", "0.1")
    assert done.returncode == 0, done.stderr
    done, _ = run("inspect", str(tmp_path / "thesis.csv"), "--json")
    (entry,) = json.loads(done.stdout)["paths"]
    assert entry["closed"] and entry["width_m"] == pytest.approx(0.5)
    assert entry["length_m"] == pytest.approx(14.0033259, rel=1e-4)
    done, _ = run("raceline", str(tmp_path / "thesis.csv"), "--open", "--v-max", "2.5")
    lines = done.stdout.splitlines()
    assert lines[0] == "# s_m; x_m; y_m; psi_rad; kappa_radpm; vx_mps; ax_mps2"
    vx = [float(line.split(";")[5]) for line in lines[1:]]
    assert vx[0] == vx[-1] == 0 and max(vx) == pytest.approx(2.5)  # a road: from and to rest


def test_a_bad_csv_exits_2_with_one_line_naming_the_line(tmp_path):
    (tmp_path / "bad.csv").write_text("# x_m,y_m,w_tr_right_m,w_tr_left_m\n0,0,1,1\n1,0,-1,1\n")
    done, _ = run("sample", "bad.csv", cwd=tmp_path)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.strip() == "error: bad line 3: negative width"
