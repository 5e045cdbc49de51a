"""The length of the 2011 thesis track (Listing 5.1, 1 user unit = 1 cm), by two independent methods."""

import numpy as np
import pytest

from tracks import Bezier, Track, de_casteljau, length_bounds, load_library_track

THESIS_TABLE_5_2 = {
    80: 1447.53,
    400: 1444.49,
    2000: 1447.37,
    10000: 1447.94,
    50000: 1448.05,
    250000: 1448.08,
}
TABLE_5_1 = [  # rounded control points, y flipped
    [237, 441, 180, 441, 110, 444, 69, 404],
    [69, 404, 29, 364, 33, 295, 33, 238],
    [33, 238, 33, 182, 30, 112, 69, 72],
    [69, 72, 109, 32, 178, 35, 235, 36],
    [235, 36, 291, 36, 360, 34, 400, 73],
    [400, 73, 440, 113, 437, 182, 437, 239],
    [437, 239, 439, 296, 443, 365, 403, 405],
    [403, 405, 363, 445, 294, 441, 237, 441],
]


@pytest.fixture(scope="module")
def controls_cm():
    """The eight cubic control polygons of Listing 5.1 in centimetres (y up)."""
    track = load_library_track("thesis")
    return [seg.ctrl * 100 for seg in track.segments], track.length_m * 100


def chord_sum(controls, per_segment):
    t = np.linspace(0, 1, per_segment + 1)
    return sum(np.hypot(*np.diff(de_casteljau(c, t), axis=0).T).sum() for c in controls)


def richardson(controls, n):
    """Chord sums err by C/n² + O(1/n⁴): two levels cancel the leading term."""
    return (4 * chord_sum(controls, 2 * n) - chord_sum(controls, n)) / 3


def gauss_legendre_length_cm(controls):
    segments = tuple(Bezier(np.asarray(c, dtype=float)) for c in controls)
    return Track(name="t", closed=False, width_m=1, segments=segments).length_m


def test_listing_5_1_is_1400_33_cm_by_quadrature_and_by_extrapolated_chords(controls_cm):
    controls, quadrature = controls_cm
    chords = richardson(controls, 4000)
    lower = sum(length_bounds(c, 12)[0] for c in controls)
    upper = sum(length_bounds(c, 12)[1] for c in controls)
    assert quadrature == pytest.approx(1400.3325889, abs=1e-6)
    assert chords == pytest.approx(quadrature, abs=1e-6)
    assert lower <= quadrature <= upper and upper - lower < 1e-5


def test_the_thesis_1448_08_cm_cannot_be_a_chord_sum_of_listing_5_1(controls_cm):
    """Why Table 5.2's 1448.08 cm is wrong, and what it was instead.

    * A chord sum of points on a curve is never longer than the curve (triangle inequality),
      whatever the sampling, nested or not, so no sampling of Listing 5.1 can give more than
      1400.3326 cm — the de Casteljau control-polygon bound proves even less than 1448.08 is
      reachable. The table is also not monotone (1447.53 at Δt = 0.1, then 1444.49 at
      Δt = 0.02, which refines it), a second sign of an arithmetic slip.
    * It is not the rounding of Table 5.1: those integer control points give 1396.70 cm, shorter.
    * It is not the misprinted Z₁ of eq. 5.14 either: integrating √(Z₄t⁴ + … + Z₁t + Z₀) with
      Z₁ = 4·X₂X₁ + Y₂Y₁ gives 1325.94 cm, far shorter.
    * What fits: the first and last rows are the true chord sums at 80 and 250 000 points times
      the same factor 1.03410 (1447.53 / 1399.79 and 1448.08 / 1400.33). The thesis summed
      chords of a curve about 3.4 % larger than Listing 5.1 (a scaled or stretched copy, e.g. a
      drawing in other units than the listing); its sampling method was fine.
    """
    controls, true_length = controls_cm
    upper_bound = sum(length_bounds(c, 12)[1] for c in controls)
    assert THESIS_TABLE_5_2[250000] > upper_bound + 47
    assert THESIS_TABLE_5_2[400] < THESIS_TABLE_5_2[80]

    table_5_1 = [np.array(row, dtype=float).reshape(4, 2) for row in TABLE_5_1]
    assert gauss_legendre_length_cm(table_5_1) == pytest.approx(1396.6969, abs=1e-3)

    def misprinted_speed(c, t):
        (x0, y0), (x1, y1), (x2, y2), (x3, y3) = c
        X = [-3 * x0 + 3 * x1, 3 * x0 - 6 * x1 + 3 * x2, -x0 + 3 * x1 - 3 * x2 + x3]
        Y = [-3 * y0 + 3 * y1, 3 * y0 - 6 * y1 + 3 * y2, -y0 + 3 * y1 - 3 * y2 + y3]
        z4, z3 = 9 * (X[2] ** 2 + Y[2] ** 2), 12 * (X[2] * X[1] + Y[2] * Y[1])
        z2 = 6 * (X[2] * X[0] + Y[2] * Y[0]) + 4 * (X[1] ** 2 + Y[1] ** 2)
        z1, z0 = 4 * X[1] * X[0] + Y[1] * Y[0], X[0] ** 2 + Y[0] ** 2
        return np.sqrt(np.maximum(z4 * t**4 + z3 * t**3 + z2 * t**2 + z1 * t + z0, 0))

    t = (np.arange(200_000) + 0.5) / 200_000
    misprinted = sum(misprinted_speed(c, t).mean() for c in controls)
    assert misprinted == pytest.approx(1325.94, abs=0.01)
    assert max(gauss_legendre_length_cm(table_5_1), misprinted, true_length) < 1448.08 - 47

    factors = [THESIS_TABLE_5_2[n] / chord_sum(controls, n // 8) for n in (80, 250000)]
    assert factors[0] == pytest.approx(1.03410, abs=2e-5)
    assert factors[1] == pytest.approx(factors[0], abs=2e-5)
