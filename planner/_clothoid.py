"""Clothoid (Euler spiral) segments: the exact pose after driving one, for continuous-curvature
paths (CC-Dubins, CC-Reeds-Shepp: Fraichard & Scheuer 2004).

A clothoid segment steers with a curvature linear in the distance driven into it,
κ(u) = κ0 + σu for 0 ≤ u ≤ |l|, l the segment's signed length (negative = reversing) and
d = sign(l). The heading turns as dθ/du = d·κ(u) and the position moves as (dx, dy)/du =
d·(cos θ, sin θ), so with

    X + iY = ∫0^u exp(i(κ0 v + σv²/2)) dv                     (`clothoid_integrals`)

the pose after u = |l| is θ' = θ + d(κ0 u + σu²/2), x' = x + d·cos θ·X − sin θ·Y,
y' = y + d·sin θ·X + cos θ·Y (`clothoid_pose`). For σ = 0 that is the arc X = sin(κ0 u)/κ0,
Y = (1 − cos κ0 u)/κ0, and for κ0 = 0 too the straight X = u, Y = 0.

The integral is computed as X + iY = u·I(a, b), I(a, b) = ∫0^1 exp(i(a t²/2 + b t)) dt with
a = σu², b = κ0 u, in one of two ways (Bertolazzi & Frego, "G1 fitting with clothoids", 2015):

* Completing the square: with w = √(|a|/π), ℓ = sign(a)·b/√(π|a|) and g = −b²/(2a),
  I = e^{ig}/w · (C(ℓ+w) − C(ℓ) + i·sign(a)·(S(ℓ+w) − S(ℓ))), C and S the Fresnel integrals
  (`fresnel`). It carries the phase of the square's vertex t* = −b/a, and that costs
  precision when the vertex is far from [0, 1]: the phases πℓ²/2 and g, ~|b·t*|/2, are
  rounded to eps of themselves, an error of ~eps·|t*| in I; and as a → 0 (σ = 0 divides by
  zero) the difference of Fresnel integrals over the short w cancels, ~eps/w.
* A series in a: I = Σ_n (ia/2)^n/n! · M_2n(b), M_k(b) = ∫0^1 t^k e^{ibt} dt. The moments
  follow M_k = (e^{ib} − k·M_{k−1})/(ib) upward while k ≤ |b| (where the recurrence damps
  errors); above, downward from M_K summed directly (Kummer's transformation,
  M_K = e^{ib} Σ_j (−ib)^j/((K+1)…(K+j+1))). M_0 = sin b/b + i·2sin²(b/2)/b is exact-form
  for b → 0 as well. Its terms fall like (|a|/2)^n/n!, so it serves only small |a|.

The series is taken for |a| < 0.01, and for |a| < 16 when |b| > 250|a| (the vertex is more than
250 lengths away); the closed form otherwise. Over |κ0| ≤ 20 1/m, |σ| ≤ 1e4 1/m², 0 ≤ u ≤ 200 m
(|b| ≤ 4000, so a far vertex always gets the series) the absolute error of X and Y is below
1e-12·max(1, u); under 1e-13·max(1, u) measured (tests/test_clothoid.py). Beyond |b| = 4000 the
closed form's error grows as ~eps·|b/a|·u.
"""

from __future__ import annotations

import math

from planner._jit import njit

_HALF_PI = 0.5 * math.pi
_SPLITTER = 134217729.0  # 2**27 + 1: Veltkamp's split of a double into two 26-bit halves
_FRESNEL_HALF = 1e17  # |x| beyond: C, S = ±0.5 within 1/(πx) < 4e-18

# The series in a (see the module's docstring).
SERIES_A = 0.01  # |a| below: the series (faster there than two Fresnel integrals)
SERIES_A_MAX = 16.0  # |a| up to which a far vertex still takes the series: 8^n/n! converges
FAR_VERTEX = 250.0  # |b/a| above: the vertex is far, the closed form would lose eps·|b/a|
_SERIES_TAIL = 1e-17  # a term bound below which the sums stop

# Cephes' fresnl (S. L. Moshier): rational approximations of S(x)/x³ and C(x)/x in x⁴ for
# x² < 2.5625, and of the auxiliary functions f and g in 1/(πx²)² beyond. Highest power first;
# the denominators written out with their leading 1.
_SN = (-2.99181919401019853726E3, 7.08840045257738576863E5, -6.29741486205862506537E7,
       2.54890880573376359104E9, -4.42979518059697779103E10, 3.18016297876567817986E11)
_SD = (1.0, 2.81376268889994315696E2, 4.55847810806532581675E4, 5.17343888770096400730E6,
       4.19320245898111231129E8, 2.24411795645340920940E10, 6.07366389490084639049E11)
_CN = (-4.98843114573573548651E-8, 9.50428062829859605134E-6, -6.45191435683965050962E-4,
       1.88843319396703850064E-2, -2.05525900955013891793E-1, 9.99999999999999998822E-1)
_CD = (3.99982968972495980367E-12, 9.15439215774657478799E-10, 1.25001862479598821474E-7,
       1.22262789024179030997E-5, 8.68029542941784300606E-4, 4.12142090722199792936E-2,
       1.00000000000000000118E0)
_FN = (4.21543555043677546506E-1, 1.43407919780758885261E-1, 1.15220955073585758835E-2,
       3.45017939782574027900E-4, 4.63613749287867322088E-6, 3.05568983790257605827E-8,
       1.02304514164907233465E-10, 1.72010743268161828879E-13, 1.34283276233062758925E-16,
       3.76329711269987889006E-20)
_FD = (1.0, 7.51586398353378947175E-1, 1.16888925859191382142E-1, 6.44051526508858611005E-3,
       1.55934409164153020873E-4, 1.84627567348930545870E-6, 1.12699224763999035261E-8,
       3.60140029589371370404E-11, 5.88754533621578410010E-14, 4.52001434074129701496E-17,
       1.25443237090011264384E-20)
_GN = (5.04442073643383265887E-1, 1.97102833525523411709E-1, 1.87648584092575249293E-2,
       6.84079380915393090172E-4, 1.15138826111884280931E-5, 9.82852443688422223854E-8,
       4.45344415861750144738E-10, 1.08268041139020870318E-12, 1.37555460633261799868E-15,
       8.36354435630677421531E-19, 1.86958710162783235106E-22)
_GD = (1.0, 1.47495759925128324529E0, 3.37748989120019970451E-1, 2.53603741420338795122E-2,
       8.14679107184306179049E-4, 1.27545075667729118702E-5, 1.04314589657571990585E-7,
       4.60680728146520428211E-10, 1.10273215066240270757E-12, 1.38796531259578871258E-15,
       8.39158816283118707363E-19, 1.86958710162783236342E-22)


@njit(cache=True, inline="always")
def _poly(t: float, coeffs) -> float:
    """Horner's rule, highest power first (Cephes' polevl)."""
    acc = 0.0
    for c in coeffs:
        acc = acc * t + c
    return acc


@njit(cache=True)
def _cos_sin_half_pi_square(x: float):
    """cos and sin of πx²/2, to a few ulps for large x too: x² is split exactly into hi + lo
    (Veltkamp) and hi reduced modulo 4, the period in x², before π/2 multiplies. π/2·x·x would
    round away eps·x² of phase: 5e-14 of C(x) at x = 1e3 already."""
    hi = x * x
    c = _SPLITTER * x
    xh = c - (c - x)
    xl = x - xh
    lo = ((xh * xh - hi) + 2.0 * xh * xl) + xl * xl
    phase = _HALF_PI * ((hi - 4.0 * math.floor(0.25 * hi)) + lo)  # the reduction is exact
    return math.cos(phase), math.sin(phase)


@njit(cache=True)
def fresnel(x: float):
    """(C(x), S(x)) = (∫0^x cos(πt²/2) dt, ∫0^x sin(πt²/2) dt), both odd in x, to ~1e-16
    absolute: Cephes' fresnl, with its large-x phase kept exact (`_cos_sin_half_pi_square`)
    and its auxiliary functions used up to |x| = 1e17 (Cephes stops at 36974, 9e-6 short of
    the limit)."""
    ax = abs(x)
    x2 = ax * ax
    if x2 < 2.5625:
        t = x2 * x2
        c = ax * _poly(t, _CN) / _poly(t, _CD)
        s = ax * x2 * _poly(t, _SN) / _poly(t, _SD)
    elif ax > _FRESNEL_HALF:
        c = 0.5
        s = 0.5
    else:
        t = math.pi * x2
        w = 1.0 / (t * t)
        f = 1.0 - w * _poly(w, _FN) / _poly(w, _FD)
        g = _poly(w, _GN) / (t * _poly(w, _GD))
        cp, sp = _cos_sin_half_pi_square(ax)
        px = math.pi * ax
        c = 0.5 + (f * sp - g * cp) / px
        s = 0.5 - (f * cp + g * sp) / px
    if x < 0.0:
        return -c, -s
    return c, s


@njit(cache=True)
def _xy_fresnel(a: float, b: float):
    """I(a, b) by completing the square (a ≠ 0): precise while the vertex −b/a is near."""
    s = 1.0 if a > 0.0 else -1.0
    aa = abs(a)
    w = math.sqrt(aa / math.pi)
    ell = s * b / math.sqrt(math.pi * aa)
    g = -0.5 * s * b * b / aa
    cl, sl = fresnel(ell)
    cz, sz = fresnel(ell + w)
    dc = cz - cl
    ds = sz - sl
    cg = math.cos(g) / w
    sg = math.sin(g) / w
    return cg * dc - s * sg * ds, sg * dc + s * cg * ds


@njit(cache=True)
def _top_moment(k: int, b: float, e: complex) -> complex:
    """M_k(b) for k > |b| from Kummer's transformation: its terms shrink from the first. The
    j-th is |b|^j/((k+1)…(k+j+1)) times (−i·sign b)^j."""
    mag = 1.0 / (k + 1)
    re = mag
    im = 0.0
    ab = abs(b)
    sb = 1.0 if b > 0.0 else -1.0
    j = 0
    while mag > _SERIES_TAIL:
        j += 1
        mag *= ab / (k + j + 1)
        q = j & 3  # (−i)^j: 1, −i, −1, i
        if q == 0:
            re += mag
        elif q == 1:
            im -= sb * mag
        elif q == 2:
            re -= mag
        else:
            im += sb * mag
    return e * complex(re, im)


@njit(cache=True)
def _xy_series(a: float, b: float):
    """I(a, b) as Σ (ia/2)^n/n!·M_2n(b): precise for small |a|, whatever b (a = 0 too)."""
    iha = complex(0.0, 0.5 * a)
    # the last term n_top: the next one's bound (|a|/2)^n/n!/(2n+1) is below the tail
    n_top = 0
    c_top = complex(1.0, 0.0)
    bound = 0.5 * abs(a) / 3.0
    while bound >= _SERIES_TAIL:
        n_top += 1
        c_top = c_top * iha / n_top
        bound *= 0.5 * abs(a) * (2 * n_top + 1) / ((n_top + 1) * (2 * n_top + 3))
    top = 2 * n_top
    e = complex(math.cos(b), math.sin(b))
    if b == 0.0:
        m = complex(1.0, 0.0)
    else:
        h = math.sin(0.5 * b)
        m = complex(math.sin(b) / b, 2.0 * h * h / b)
    total = m
    # upward while k ≤ |b|
    up = int(abs(b)) if abs(b) < top else top  # (NaN: top)
    inv_ib = complex(0.0, -1.0 / b) if up > 0 else complex(0.0, 0.0)
    c = complex(1.0, 0.0)
    for k in range(1, up + 1):
        m = (e - k * m) * inv_ib
        if k % 2 == 0:
            c = c * iha / (k // 2)
            total += c * m
    # downward from the top for k > |b|
    if up < top:
        ib = complex(0.0, b)
        m = _top_moment(top, b, e)
        c = c_top
        for k in range(top, up, -1):
            if k % 2 == 0:
                total += c * m
                if k > up + 2:
                    c = c * (k // 2) / iha
            m = (e - ib * m) / k
    return total.real, total.imag


@njit(cache=True)
def _xy_unit(a: float, b: float):
    """I(a, b) = ∫0^1 exp(i(a t²/2 + b t)) dt by the series or the closed form, whichever is
    precise there."""
    aa = abs(a)
    if aa < SERIES_A or (aa < SERIES_A_MAX and abs(b) > FAR_VERTEX * aa):
        return _xy_series(a, b)
    return _xy_fresnel(a, b)


@njit(cache=True)
def clothoid_integrals(k0: float, sigma: float, u: float):
    """(X, Y) = (∫0^u cos(k0 v + σv²/2) dv, ∫0^u sin(k0 v + σv²/2) dv) for u ≥ 0: the
    displacement along a clothoid from heading 0, σ = 0 (arcs, straights) included."""
    x, y = _xy_unit(sigma * u * u, k0 * u)
    return u * x, u * y


@njit(cache=True, inline="always")
def clothoid_pose(x: float, y: float, th: float, k0: float, sigma: float, length: float):
    """Pose after driving the signed ``length`` from (x, y, th) on curvature k0 + σu, u ≤
    |length| the distance driven: reversing (length < 0), the car backs up and its heading
    turns by −κ per metre."""
    d = 1.0 if length >= 0.0 else -1.0
    u = abs(length)
    cx, cy = clothoid_integrals(k0, sigma, u)
    c = math.cos(th)
    s = math.sin(th)
    return (x + d * c * cx - s * cy, y + d * s * cx + c * cy,
            th + d * (k0 * u + 0.5 * sigma * u * u))
