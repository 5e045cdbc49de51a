"""planner._clothoid: Fresnel integrals, clothoid integrals and poses against SciPy's quadrature
and special functions, and the geometry a clothoid segment must have."""

from __future__ import annotations

import itertools
import math
import warnings

import numpy as np
import pytest
import scipy.special
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.integrate import IntegrationWarning, quad

from planner._clothoid import (
    FAR_VERTEX,
    SERIES_A,
    SERIES_A_MAX,
    _xy_fresnel,
    _xy_series,
    _xy_unit,
    clothoid_integrals,
    clothoid_pose,
    fresnel,
)

PHASE_BUDGET = 200.0  # rad: the total phase up to which quad is a reliable reference

# x² = 2.5625 is where fresnel leaves its rational approximations for the auxiliary functions
_EDGE = math.sqrt(2.5625)
FRESNEL_GRID = [0.0, 1e-300, 1e-8, 0.1, 0.5, 1.0, 1.5, np.nextafter(_EDGE, 0.0), _EDGE,
                np.nextafter(_EDGE, 2.0), 1.7, 2.5, 3.3, 5.0, 7.77, 10.0, 31.4, 100.0, 1e3,
                1234.5678, 1e4, 36973.0, 1e5, 1e6]


@pytest.mark.parametrize("x", FRESNEL_GRID + [-v for v in FRESNEL_GRID if v])
def test_fresnel_matches_scipy(x):
    """To 1e-15, and SciPy's own rounding of its phase πx²/2 (~eps·x/2: none for these x
    up to 1e6, whose squares are exact; 3e-13 at 1234.5678)."""
    s, c = scipy.special.fresnel(x)  # SciPy's order: (S, C)
    got_c, got_s = fresnel(x)
    tol = 1e-15 + 2.3e-16 * abs(x)
    assert abs(got_c - c) <= tol and abs(got_s - s) <= tol


@pytest.mark.parametrize("x", [2.7182818, 777.77, 1234.5678, -3141.59, 98765.4321, 3.3e9])
def test_fresnel_keeps_its_phase_for_large_x(x):
    """Against mpmath where x² is not a double: the phase is reduced exactly, so C and S hold
    to ~1e-16 (a plain π/2·x·x would be 1e-13 off at x = 3141.59)."""
    mp = pytest.importorskip("mpmath")
    got_c, got_s = fresnel(x)
    with mp.workdps(40):
        c, s = mp.fresnelc(mp.mpf(x)), mp.fresnels(mp.mpf(x))
        assert abs(got_c - c) <= 2e-16 and abs(got_s - s) <= 2e-16


def test_fresnel_is_odd_and_tends_to_one_half():
    for x in (0.3, 1.9, 42.0, 1e20, math.inf):
        assert fresnel(-x) == tuple(-v for v in fresnel(x))
    assert fresnel(1e20) == (0.5, 0.5)
    assert fresnel(0.0) == (0.0, 0.0)


@pytest.mark.parametrize("x", [0.3, 1.0, 1.6, 2.2, 3.7, 5.0])
def test_fresnel_matches_quadrature(x):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)  # roundoff flagged at 1e-14
        c = quad(lambda t: math.cos(0.5 * math.pi * t * t), 0.0, x, epsabs=1e-14,
                 epsrel=1e-14)[0]
        s = quad(lambda t: math.sin(0.5 * math.pi * t * t), 0.0, x, epsabs=1e-14,
                 epsrel=1e-14)[0]
    got_c, got_s = fresnel(x)
    assert abs(got_c - c) <= 1e-14 and abs(got_s - s) <= 1e-14


def quad_xy(k0: float, sigma: float, u: float) -> tuple[float, float]:
    """The clothoid integrals by adaptive quadrature (limit 500, epsabs 1e-13), summed over
    pieces of at most π of phase each."""
    phase = abs(k0) * u + 0.5 * abs(sigma) * u * u
    edges = np.linspace(0.0, u, int(phase / math.pi) + 2)
    x = y = 0.0
    with warnings.catch_warnings():
        # QUADPACK may flag roundoff at this tolerance; its results stay within ~3e-15·u
        # (checked against mpmath's Fresnel integrals at 60 digits)
        warnings.simplefilter("ignore", IntegrationWarning)
        for lo, hi in itertools.pairwise(edges):
            x += quad(lambda v: math.cos(k0 * v + 0.5 * sigma * v * v), lo, hi, limit=500,
                      epsabs=1e-13, epsrel=1e-13)[0]
            y += quad(lambda v: math.sin(k0 * v + 0.5 * sigma * v * v), lo, hi, limit=500,
                      epsabs=1e-13, epsrel=1e-13)[0]
    return x, y


def assert_close_to_quad(k0: float, sigma: float, u: float) -> None:
    x, y = clothoid_integrals(k0, sigma, u)
    qx, qy = quad_xy(k0, sigma, u)
    tol = 1e-12 * max(1.0, u)
    assert abs(x - qx) <= tol and abs(y - qy) <= tol, (x - qx, y - qy)


def longest_within_budget(k0: float, sigma: float) -> float:
    """The u ≤ 200 at which |k0|u + |σ|u²/2 reaches the phase budget."""
    root = abs(k0) + math.sqrt(k0 * k0 + 2.0 * PHASE_BUDGET * abs(sigma))
    return 200.0 if root == 0.0 else min(200.0, 2.0 * PHASE_BUDGET / root)


def signed_log(low: float, high: float):
    return st.tuples(st.sampled_from((-1.0, 1.0)), st.floats(low, high)).map(
        lambda p: p[0] * 10.0 ** p[1])


CURVATURES = st.one_of(st.just(0.0), st.floats(-20.0, 20.0), signed_log(-14.0, math.log10(20.0)))
SHARPNESSES = st.one_of(st.just(0.0), st.floats(-1e4, 1e4), signed_log(-14.0, 4.0))


@settings(max_examples=250, deadline=None)
@given(CURVATURES, SHARPNESSES, st.floats(0.0, 1.0))
@example(1.0, 0.0, 1.0)
@example(-3.0, 1e-12, 1.0)
@example(0.4, 1e-6, 1.0)
@example(-0.4, -1e-6, 1.0)
@example(0.0, 2.5, 1.0)
@example(20.0, 1e-6, 1.0)
@example(0.0, 0.0, 1.0)
@example(-20.0, 1e4, 1.0)
@example(7.0, -0.035, 1.0)  # the curvature's zero at the segment's end
def test_integrals_match_quadrature(k0, sigma, fraction):
    """Over |k0| ≤ 20, |σ| ≤ 1e4, u ≤ 200 wherever the total phase is within quad's reach."""
    assert_close_to_quad(k0, sigma, fraction * longest_within_budget(k0, sigma))


@pytest.mark.parametrize("k0", [0.0, 1e-300, 1e-9, -1e-4, 0.25, -1.0, 3.0, 20.0])
@pytest.mark.parametrize("u", [0.0, 1e-6, 0.7, 1.0, 9.5, 200.0])
def test_arcs_and_straights_have_their_closed_forms(k0, u):
    """σ = 0 is an arc, sin and 1 − cos over κ, and a straight for κ = 0 (exactly)."""
    x, y = clothoid_integrals(k0, 0.0, u)
    if k0 == 0.0:
        assert (x, y) == (u, 0.0)
        return
    px, py = math.sin(k0 * u) / k0, 2.0 * math.sin(0.5 * k0 * u) ** 2 / k0
    assert abs(x - px) <= 2e-16 * max(1.0, u) and abs(y - py) <= 2e-16 * max(1.0, u)
    for tiny in (1e-300, -1e-300, 1e-20):  # σ → 0 is continuous into σ = 0
        tx, ty = clothoid_integrals(k0, tiny, u)
        assert abs(tx - x) <= 1e-15 * max(1.0, u) and abs(ty - y) <= 1e-15 * max(1.0, u)


@pytest.mark.parametrize("sigma", [1e-12, -1e-12, 1e-6, -1e-6])
@pytest.mark.parametrize("k0", [0.0, 1e-8, 0.5, -20.0])
@pytest.mark.parametrize("u", [0.3, 17.0, 200.0])
def test_nearly_arcs_match_quadrature(sigma, k0, u):
    """σ → 0, where completing the square would divide by it (up to 4000 rad of phase)."""
    assert_close_to_quad(k0, sigma, u)


def test_far_phases_match_mpmath():
    """Where quad cannot follow (up to 10⁸ rad of phase), against the closed form in 60
    digits."""
    mp = pytest.importorskip("mpmath")

    def reference(k0, sigma, u):
        with mp.workdps(60):
            a, b = mp.mpf(sigma) * u * u, mp.mpf(k0) * u
            s = 1 if a > 0 else -1
            w, ell = mp.sqrt(abs(a) / mp.pi), s * b / mp.sqrt(mp.pi * abs(a))
            g = -b * b / (2 * a)
            dc = mp.fresnelc(ell + w) - mp.fresnelc(ell)
            ds = mp.fresnels(ell + w) - mp.fresnels(ell)
            return (float(u * (mp.cos(g) * dc - s * mp.sin(g) * ds) / w),
                    float(u * (mp.sin(g) * dc + s * mp.cos(g) * ds) / w))

    for k0, sigma, u in [(20.0, 1e4, 200.0), (-20.0, -1e4, 199.0), (3.0, 7.5, 150.0),
                         (20.0, -0.1, 200.0), (-19.0, 1e-3, 200.0), (7.1, 1.77e-4, 169.0),
                         (20.0, 1.6e-4, 125.0), (-20.0, 4e-5, 200.0), (0.0, -2.0, 200.0),
                         # a vertex 10⁵ lengths away: the closed form would be 2e-11·u off
                         (-13.84, 3.28e-7, 200.0), (14.0, -3.3e-7, 200.0), (9.4, 3.2e-7, 200.0)]:
        x, y = clothoid_integrals(k0, sigma, u)
        rx, ry = reference(k0, sigma, u)
        assert abs(x - rx) <= 1e-12 * u and abs(y - ry) <= 1e-12 * u, (k0, sigma, u)


@pytest.mark.parametrize("a", [0.02, -0.3, 1.0, 4.5, -12.0, 15.9])
def test_series_and_closed_form_agree_where_both_hold(a):
    """Both ways, where the series converges and the vertex −b/a is near."""
    near = FAR_VERTEX * abs(a)
    for b in np.concatenate([np.linspace(-20.0, 20.0, 41), [0.0, 1e-9, -3e-5, -near, near]]):
        if abs(b) > near:
            continue
        sx, sy = _xy_series(a, b)
        fx, fy = _xy_fresnel(a, b)
        assert abs(sx - fx) <= 1e-13 and abs(sy - fy) <= 1e-13, b


@pytest.mark.parametrize("b", [0.0, 1e-7, -0.8, 2.0, -2.5, FAR_VERTEX * SERIES_A])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_no_jump_at_the_series_threshold(b, sign):
    """|a| just below SERIES_A takes the series, at it the closed form: the same values."""
    below = _xy_unit(sign * np.nextafter(SERIES_A, 0.0), b)
    at = _xy_unit(sign * SERIES_A, b)
    assert abs(below[0] - at[0]) <= 1e-12 and abs(below[1] - at[1]) <= 1e-12


@pytest.mark.parametrize("a", [0.05, -0.7, 3.0, -9.0, np.nextafter(SERIES_A_MAX, 0.0)])
def test_no_jump_at_the_far_vertex_threshold(a):
    """|b| just above FAR_VERTEX·|a| takes the series, at it the closed form."""
    for sign in (1.0, -1.0):
        edge = sign * FAR_VERTEX * abs(a)
        far = _xy_unit(a, np.nextafter(edge, sign * math.inf))
        near = _xy_unit(a, edge)
        assert abs(far[0] - near[0]) <= 1e-12 and abs(far[1] - near[1]) <= 1e-12
    b = 1.5 * FAR_VERTEX * SERIES_A_MAX  # beyond, at |a| = SERIES_A_MAX the closed form
    below = _xy_unit(np.nextafter(SERIES_A_MAX, 0.0), b)
    at = _xy_unit(SERIES_A_MAX, b)
    assert abs(below[0] - at[0]) <= 1e-12 and abs(below[1] - at[1]) <= 1e-12


POSES = st.tuples(st.floats(-50.0, 50.0), st.floats(-50.0, 50.0), st.floats(-7.0, 7.0))
MILD_CURVATURES = st.floats(-2.0, 2.0)
MILD_SHARPNESSES = st.one_of(st.just(0.0), st.floats(-5.0, 5.0))
LENGTHS = st.floats(0.0, 10.0)


def assert_same_pose(p, q, tol=1e-10):
    assert abs(p[0] - q[0]) <= tol and abs(p[1] - q[1]) <= tol and abs(p[2] - q[2]) <= tol, (p, q)


@settings(max_examples=100, deadline=None)
@given(POSES, MILD_CURVATURES, MILD_SHARPNESSES, LENGTHS, LENGTHS, st.sampled_from((1.0, -1.0)))
def test_driving_on_composes(pose, k0, sigma, l1, l2, d):
    """l1 then l2 on the continued clothoid (curvature k0 + σ|l1| on) is l1 + l2 in one."""
    mid = clothoid_pose(*pose, k0, sigma, d * l1)
    assert_same_pose(clothoid_pose(*mid, k0 + sigma * l1, sigma, d * l2),
                     clothoid_pose(*pose, k0, sigma, d * (l1 + l2)))


@settings(max_examples=100, deadline=None)
@given(POSES, MILD_CURVATURES, MILD_SHARPNESSES, LENGTHS, st.sampled_from((1.0, -1.0)))
def test_driving_back_returns(pose, k0, sigma, length, d):
    """Driving l, then −l from the curvature reached with the sharpness negated (the curvature
    retraced: k0 + σ(|l| − u) at u back), ends where it started, heading included."""
    end = clothoid_pose(*pose, k0, sigma, d * length)
    assert_same_pose(clothoid_pose(*end, k0 + sigma * length, -sigma, -d * length), pose)


@settings(max_examples=100, deadline=None)
@given(MILD_CURVATURES, MILD_SHARPNESSES, LENGTHS)
def test_reversing_mirrors_driving_forward(k0, sigma, length):
    """Reversing with the same curvature function from the origin gives (−x, y, −θ) of the
    forward pose: the heading turns the other way, and the car moves backwards."""
    fx, fy, fth = clothoid_pose(0.0, 0.0, 0.0, k0, sigma, length)
    rx, ry, rth = clothoid_pose(0.0, 0.0, 0.0, k0, sigma, -length)
    assert_same_pose((rx, ry, rth), (-fx, fy, -fth), tol=1e-13)


@settings(max_examples=100, deadline=None)
@given(POSES, MILD_CURVATURES, MILD_SHARPNESSES, st.floats(0.01, 10.0), st.sampled_from((1, -1)))
def test_heading_is_the_direction_of_motion(pose, k0, sigma, u, d):
    """θ' = θ + d(k0 u + σu²/2), and the position moves along d·(cos θ', sin θ')."""
    th = clothoid_pose(*pose, k0, sigma, d * u)[2]
    assert th == pytest.approx(pose[2] + d * (k0 * u + 0.5 * sigma * u * u), abs=1e-12)
    h = 1e-5
    ahead = clothoid_pose(*pose, k0, sigma, d * (u + h))
    behind = clothoid_pose(*pose, k0, sigma, d * (u - h))
    vx, vy = (ahead[0] - behind[0]) / (2 * h), (ahead[1] - behind[1]) / (2 * h)
    assert abs(vx - d * math.cos(th)) <= 1e-6 and abs(vy - d * math.sin(th)) <= 1e-6


@pytest.mark.parametrize("rho", [0.3, 1.0, -2.5, 40.0])
@pytest.mark.parametrize("length", [0.0, 0.4, -1.7, 12.0, -30.0])
def test_arcs_follow_the_circle_formula(rho, length):
    x, y, th = 1.5, -2.0, 0.7
    th2 = th + length / rho
    expected = (x + rho * (math.sin(th2) - math.sin(th)), y - rho * (math.cos(th2) - math.cos(th)),
                th2)
    assert_same_pose(clothoid_pose(x, y, th, 1.0 / rho, 0.0, length), expected, tol=1e-12)


@pytest.mark.parametrize("sigma,kmax", [(0.5, 1.0), (2.0, 0.25), (1e-3, 0.1), (30.0, 5.0),
                                        (0.7, -0.9)])
def test_clothoid_from_straight_ends_at_the_textbook_point(sigma, kmax):
    """From κ = 0 to κmax at sharpness σ (κmax/σ metres) from the origin, heading 0: the end
    is √(π/σ)·(C(t), S(t)), t = κmax/√(πσ), heading κmax²/(2σ); a negative κ mirrors it."""
    sign = math.copysign(1.0, kmax)
    s = sign * sigma
    length = kmax / s
    t = abs(kmax) / math.sqrt(math.pi * sigma)
    fs, fc = scipy.special.fresnel(t)
    scale = math.sqrt(math.pi / sigma)
    assert_same_pose(clothoid_pose(0.0, 0.0, 0.0, 0.0, s, length),
                     (scale * fc, sign * scale * fs, sign * kmax * kmax / (2.0 * sigma)),
                     tol=1e-12 * max(1.0, scale))
