"""SVGs as found in public repositories: W3C DOCTYPEs, hairline decorations, id-less paths,
paths of several subpaths (issue 18)."""

import math

import pytest

from tracks import TrackError, inspect_svg, load_svg
from tracks._svg_import import DEFAULT_WIDTH_M

MM = 0.001
NS = 'xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100"'
W3C = ('<!DOCTYPE svg PUBLIC "-//W3C//DTD SVG 1.1//EN" '
       '"http://www.w3.org/Graphics/SVG/1.1/DTD/svg11.dtd">')


def doc(body: str, doctype: str = "") -> bytes:
    return f'<?xml version="1.0" standalone="no"?>{doctype}<svg {NS}>{body}</svg>'.encode()


def test_the_w3c_doctype_is_accepted_and_its_dtd_never_read():
    assert load_svg(doc('<path d="M0 0H10"/>', W3C)).length_m == pytest.approx(10 * MM)


def test_a_local_external_dtd_is_not_loaded_so_its_entities_stay_undefined(tmp_path):
    dtd = tmp_path / "ent.dtd"
    dtd.write_text('<!ENTITY x "M0 0H10">')
    # expat skips (or refuses) the unknown entity: the path never gets the DTD's data
    with pytest.raises(TrackError, match="undefined entity|no path of positive length"):
        load_svg(doc('<path d="&x;"/>', f'<!DOCTYPE svg SYSTEM "{dtd.as_uri()}">'))


@pytest.mark.parametrize("subset", [
    '<!ENTITY a "aaaa"><!ENTITY b "&a;&a;&a;&a;">',  # a bomb's beginning
    '<!ENTITY x SYSTEM "file:///etc/passwd">',  # an external entity
    '<!ATTLIST path d CDATA "M0 0H10">',  # any internal subset
])
def test_an_internal_subset_is_refused(subset):
    with pytest.raises(TrackError, match="unsafe XML refused"):
        load_svg(doc('<path d="M0 0H10"/>', f"<!DOCTYPE svg [{subset}]>"))


def test_a_zero_width_decoration_is_listed_without_width_and_usable_with_the_default():
    data = doc('<path id="deco" style="stroke-width:0" d="M0 0H50"/>'
               '<path id="road" stroke-width="4" d="M0 10H20"/>')
    paths = {p["id"]: p for p in inspect_svg(data)["paths"]}
    assert paths["deco"]["width_m"] is None and paths["road"]["width_m"] == pytest.approx(4 * MM)
    assert load_svg(data).width_m == DEFAULT_WIDTH_M  # the longest is the decoration
    assert load_svg(data, path_id="road").width_m == pytest.approx(4 * MM)


def test_id_less_paths_get_stable_selectors_that_choose_them():
    data = doc('<g><path d="M0 0H10"/></g><rect x="0" y="0" width="5" height="5"/>'
               '<path inkscape:label="Lane" xmlns:inkscape="http://www.inkscape.org/namespaces/'
               'inkscape" d="M0 0H30"/><path id="p" d="M0 0H40"/>')
    selectors = [p["selector"] for p in inspect_svg(data)["paths"]]
    assert selectors == ["path-1", "rect-2", "Lane", "p"]
    assert [p["selector"] for p in inspect_svg(data)["paths"]] == selectors
    lengths = [load_svg(data, path_id=s).length_m for s in selectors]
    assert lengths == pytest.approx([10 * MM, 20 * MM, 30 * MM, 40 * MM])


def test_a_path_of_two_subpaths_reports_its_whole_length_and_each_edge():
    ribbon = ("M 10,50 a 40,40 0 1 0 80,0 a 40,40 0 1 0 -80,0 z "
              "M 20,50 a 30,30 0 1 0 60,0 a 30,30 0 1 0 -60,0 z")
    data = doc(f'<path id="ribbon" d="{ribbon}"/>')
    whole, outer, inner = inspect_svg(data)["paths"]
    assert [whole["selector"], outer["selector"], inner["selector"]] == [
        "ribbon", "ribbon:0", "ribbon:1"]
    assert (whole["subpath"], outer["subpath"], inner["subpath"]) == (None, 0, 1)
    assert whole["length_m"] == pytest.approx(2 * math.pi * 70 * MM, rel=1e-12)
    assert outer["length_m"] == pytest.approx(2 * math.pi * 40 * MM, rel=1e-12)
    assert whole["bbox_m"] == pytest.approx(outer["bbox_m"])
    assert load_svg(data, path_id="ribbon:1").length_m == pytest.approx(2 * math.pi * 30 * MM)
    assert load_svg(data, path_id="ribbon").length_m == pytest.approx(outer["length_m"])
    with pytest.raises(TrackError, match="no subpath 2"):
        load_svg(data, path_id="ribbon:2")
