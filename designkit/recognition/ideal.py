"""The ideal observer: the best recognition any classifier can reach.

Two classes of objects, effusivity uniform in ``[a1, b1)`` and ``[a2, b2)``,
touched under the same scene; readings are the model of paper eq. 4 with
i.i.d. Gaussian noise. The ideal (Bayes) observer knows all of that.

Fixed initial conditions (closed form)
--------------------------------------
A reading is ``y = Ts0 + (Ta - Ts0) w(e) g + sigma z`` with the response shape
``g(t) = erfc(sqrt(tau/t))`` and ``w(e) = e / (e_s + e)``. Only the amplitude
``w`` depends on the object, so the likelihood ratio of the two classes
depends on the data only through the projection of ``y - Ts0`` on ``g``:

    v = (Ts0 - y) . g / (dT |g|^2)  ~  w(e) + N(0, s^2),   s = (sigma / |dT|) / |g|

(``|g|`` is the Euclidean norm over the samples of the touch). The recognition
problem therefore collapses to one number per touch and one number per scene,
the projection noise ``s``. Each class's law of ``v`` is a uniform-in-``e``
mixture of Gaussians; the Gaussian kernel is totally positive, so classes with
ordered, disjoint effusivity ranges have a monotone likelihood ratio in ``v``
and every optimal classifier is a threshold on ``v``. This module evaluates

    P(v > t | class) = 1/(b - a) * integral_a^b Phi((w(e) - t) / s) de

by Gauss-Legendre quadrature on the part of ``[a, b)`` where the integrand
is not 0 or 1 to double precision (``|w - t| < 8.5 s``), which is exact at
``s = 0`` and accurate to about 1e-11 elsewhere (tested against mpmath), and
maximizes accuracy and F1 over the threshold. Inverted, it gives the
*critical noise* ``s*`` at which the best F1 equals a threshold
(:func:`critical_noise`, Newton's method on the pair of conditions), from which
every closed-form bound of :mod:`designkit.query.ideal_bound` follows.

The normal CDF is numpy's own here (:func:`ndtr`, cubic Hermite pieces of a
table of :func:`math.erfc`, within 5e-14, tested against mpmath), not
:mod:`scipy.special`, so that a table question from a fresh shell never imports
scipy (``tests/test_startup.py``; docs/decisions-log.md). The Monte Carlo
observer below imports ``scipy.special`` when it runs.

Varied initial conditions (Monte Carlo on the exact likelihood)
---------------------------------------------------------------
When Ts0 and/or Ta vary per trial (uniformly, as :class:`~designkit.scene.Scene`
describes), the sufficient statistic is the pair ``(1 . y, g . y)`` and the
likelihood of a class is an integral over ``e``, Ts0 and Ta. The Ts0 integral
is done in closed form (a Gaussian integrated over a uniform prior), the Ta
integral by Gauss-Legendre, the ``e`` integral on a midpoint grid finer than
the projection noise; test touches are simulated, classified by the exact
log-likelihood ratio, and scored. The result carries its Monte Carlo standard
error.

F1 convention
-------------
The positive class is the higher-effusivity range. Because F1 is not
symmetric, the best F1 is never below 2/3 (call every touch positive) even
when the classes cannot be told apart; the best *accuracy* is 0.5 then.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from .._validation import InputError, check_effusivity_range
from .scores import TRIVIAL_F1
from .scores import IdealResult, score_llr
from ..models.semi_infinite import object_weight, response_shape
from ..scene import Scene
from ..sensor import Sensor, last_sample_index

__all__ = [
    "IdealResult",
    "class_density",
    "class_survival",
    "critical_noise",
    "cumulative_g2",
    "ideal_f1",
    "ideal_method",
    "ideal_pair",
    "ideal_scores",
    "log_ndtr_diff",
    "ndtr",
    "projection_noise",
    "score_llr",
    "separates",
    "shape_norm",
]



# ----------------------------------------------------------------- closed form
#: Gauss-Legendre nodes of :func:`class_survival` and :func:`class_density` (accurate to about 1e-11).
_NODES = 40
_CUT = 8.5  # Phi(-8.5) = 9.5e-18: the integrand is 0 or 1 to double precision outside +-8.5 s
_SQRT1_2 = math.sqrt(0.5)
_PHI_H = 1.0 / 512.0  # grid step of the tabulated normal CDF (a power of two: exact node positions)
_PHI_Z = 9.0  # beyond +-9 the CDF is 0 or 1 to 1e-19


@functools.lru_cache(maxsize=1)
def _phi_table() -> tuple[np.ndarray, np.ndarray]:
    """The standard normal CDF and density on [-9, 9] every 1/512, from :func:`math.erfc` (once per process)."""
    z = np.arange(-_PHI_Z, _PHI_Z + _PHI_H / 2, _PHI_H)
    cdf = np.array([0.5 * math.erfc(-_SQRT1_2 * x) for x in z.tolist()])
    return cdf, np.exp(-0.5 * z * z) / math.sqrt(2.0 * math.pi)


@functools.lru_cache(maxsize=1)
def _phi_horner() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Coefficients ``c0..c3`` of the cubic Hermite piece on each interval of :func:`_phi_table`, in
    ``x = (z + 9) * 512 - k`` on [0, 1]: ``Phi = ((c3 x + c2) x + c1) x + c0``."""
    cdf, pdf = _phi_table()
    p0, p1, m0, m1 = cdf[:-1], cdf[1:], _PHI_H * pdf[:-1], _PHI_H * pdf[1:]
    return p0, m0, -3.0 * p0 - 2.0 * m0 + 3.0 * p1 - m1, 2.0 * p0 + m0 - 2.0 * p1 + m1


def ndtr(z) -> np.ndarray:
    """Standard normal CDF, elementwise (a new array; float64): cubic Hermite interpolation of :func:`_phi_table`.

    Interpolation error at most h^4 max|d4 Phi| / 384 = 5e-14 (h = 1/512), tested against
    :func:`math.erfc`. Evaluated in Horner form from per-interval coefficients, in place, with 1-D
    ``take`` gathers.

    Examples
    --------
    >>> float(ndtr(np.array([0.0]))[0])
    0.5
    """
    c0, c1, c2, c3 = _phi_horner()
    u = np.clip(z, -_PHI_Z, _PHI_Z)
    u += _PHI_Z
    u *= 1.0 / _PHI_H
    k = u.astype(np.int64)
    np.minimum(k, c0.size - 1, out=k)
    u -= k
    r = c3.take(k)
    r *= u
    r += c2.take(k)
    r *= u
    r += c1.take(k)
    r *= u
    r += c0.take(k)
    return r


def cumulative_g2(tau_s: float, rate_hz: float, n_max: int) -> np.ndarray:
    """``sum_{k <= n} g(k/fs)^2`` for n = 0 .. n_max (the first sample is at contact, t = 0).

    A read-only view of one array per sensor, grown to the next power of two (a running sum: its first
    ``n_max + 1`` entries do not depend on its length), so that calls with other ``n_max`` reuse it."""
    size = 4096
    while size < n_max + 1:
        size *= 2
    return _cumulative_g2_table(float(tau_s), float(rate_hz), size)[:n_max + 1]


@functools.lru_cache(maxsize=16)
def _cumulative_g2_table(tau_s: float, rate_hz: float, size: int) -> np.ndarray:
    if tau_s == 0.0:
        g = np.ones(size)
    else:
        g = np.array([0.0] + [math.erfc(math.sqrt(tau_s * rate_hz / k)) for k in range(1, size)])
    cum = np.cumsum(g * g)
    cum.flags.writeable = False
    return cum


def shape_norm(sensor, contact_s) -> np.ndarray:
    """``|g|``, the norm of the response shape over a touch's samples, vectorized over ``contact_s`` [s].

    The projection noise is ``(sigma/dT) / shape_norm`` (0 for no sample after contact: no signal).

    >>> from designkit.sensor import load_sensor
    >>> round(float(shape_norm(load_sensor("paper"), 2.0)), 4)
    2.6732
    """
    n = last_sample_index(contact_s, sensor.sample_rate_hz)
    cum = cumulative_g2(float(sensor.tau_s), float(sensor.sample_rate_hz), int(max(np.asarray(n).max(), 1)))
    return np.sqrt(cum[n])


def _weight(e_s: float, e):
    """``w = e / (e_s + e)`` (:func:`designkit.models.semi_infinite.object_weight`), for e > 0."""
    with np.errstate(divide="ignore"):
        return 1.0 / (1.0 + e_s / e)


def _window(w_cut, a, b, wa, wb, e_s):
    """The effusivity [J s^-1/2 K^-1 m^-2] at contact weight ``w_cut``, clipped to the class ``[a, b)``
    (``wa, wb`` its weights; the class's exact ends outside it): one end of a survival integral's window."""
    w = np.minimum(np.maximum(w_cut, wa), wb)
    with np.errstate(divide="ignore", invalid="ignore"):
        e = e_s * w / (1.0 - w)
    e = np.minimum(np.maximum(e, a), b)
    return np.where(w_cut <= wa, a, np.where(w_cut >= wb, b, e))


def _survival(t, a, b, wa, wb, e_s, s):
    """``P(w(e) + s N(0,1) > t)`` with ``e ~ U[a, b)`` (:func:`class_survival`).

    ``wa, wb`` are ``w(a), w(b)``; the cuts outside the class use its exact ends.
    """
    e_lo, e_hi = _window(t - _CUT * s, a, b, wa, wb, e_s), _window(t + _CUT * s, a, b, wa, wb, e_s)
    half, mid = 0.5 * (e_hi - e_lo), 0.5 * (e_hi + e_lo)
    gx, gw = _rule(_NODES)
    nodes = mid[..., None] + half[..., None] * gx
    with np.errstate(divide="ignore", invalid="ignore"):
        z = (_weight(e_s, nodes) - t[..., None]) / s[..., None]
    z[np.isnan(z)] = 0.0
    middle = ndtr(z)
    middle *= gw  # a row's sum alone (a matrix-vector product's blocking depends on the row count)
    middle = half * middle.sum(axis=-1)
    return np.minimum(np.maximum(((b - e_hi) + middle) / (b - a), 0.0), 1.0)


def class_survival(t, e_low, e_high, e_sensor: float, s) -> np.ndarray:
    """``P(w(e) + s N(0,1) > t)`` for ``e ~ U[e_low, e_high)``, elementwise (all arguments but ``e_sensor``
    broadcast; ``s`` >= 0 and finite, 0 the exact step limit).

    Gauss-Legendre quadrature (40 nodes) on the part of ``[e_low, e_high)`` where the integrand is neither
    0 nor 1 to double precision; accurate to about 1e-11 (tested against mpmath).

    >>> float(class_survival([0.0], 20000.0, 20080.0, 892.0, 0.01)[0])
    1.0
    """
    t, a, b, s = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64) for x in (t, e_low, e_high, s)))
    return _survival(t, a, b, _weight(e_sensor, a), _weight(e_sensor, b), e_sensor, s)


def class_density(t, e_low, e_high, e_sensor: float, s) -> np.ndarray:
    """Density of ``w(e) + s N(0,1)`` at ``t`` for ``e ~ U[e_low, e_high)``, elementwise (all arguments but
    ``e_sensor`` broadcast, as 1-D; ``s`` > 0 and finite): minus :func:`class_survival`'s derivative in
    ``t``, by the same quadrature.

    >>> round(float(class_density([0.5], 892.0, 892.0 * 1.0001, 892.0, 0.01)[0]), 4)  # nearly N(0.5, 0.01)
    39.8942
    """
    t, a, b, s = (np.ravel(x) for x in np.broadcast_arrays(*(np.asarray(x, dtype=np.float64)
                                                             for x in (t, e_low, e_high, s))))
    gx, gw = _rule(_NODES)
    _, half, z = _window_z(t, s, a, b, _weight(e_sensor, a), _weight(e_sensor, b), e_sensor, gx)
    pdf = _gauss(z)
    pdf *= gw  # a row's sum alone, as in _survival
    return (_INV_SQRT_2PI * half / ((b - a) * s)) * pdf.sum(axis=1)


def _zoom_max(f, a, b, *, points: int, passes: int, stop_at: float | None = None) -> np.ndarray:
    """Maximum of ``f(t, rows)`` over thresholds ``t`` in ``[a, b]`` per element, ``f`` quasi-concave in ``t``:
    a grid of ``points`` thresholds, then ``passes - 1`` zooms onto the best cell (one vectorized call per
    pass: the small-array overhead dominates a golden-section search). ``rows``: the elements still zooming
    (None: all); with ``stop_at`` those below it (a decision ``max >= stop_at`` needs no more zooming)."""
    a, b = a.copy(), b.copy()
    best = np.full(a.shape, -np.inf)
    u = np.linspace(0.0, 1.0, points)
    rows = None
    for _ in range(passes):
        ra, rb = (a, b) if rows is None else (a[rows], b[rows])
        t = ra[:, None] + (rb - ra)[:, None] * u
        v = f(t, rows)
        k = np.argmax(v, axis=1)
        top = v[np.arange(k.size), k]
        step = (rb - ra) / (points - 1)
        centre = t[np.arange(k.size), k]
        if rows is None:
            best = np.maximum(best, top)
            a, b = centre - step, centre + step
        else:
            best[rows] = np.maximum(best[rows], top)
            a[rows], b[rows] = centre - step, centre + step
        if stop_at is not None:
            rows = np.nonzero(best < stop_at)[0]
            if rows.size == 0:
                break
    return best


def ideal_f1(lo, hi, width, e_sensor: float, s, *, points: int = 17, passes: int = 7,
             stop_at: float | None = None) -> np.ndarray:
    """Best F1 of the ideal observer for classes ``[lo, lo+width)`` and ``[hi, hi+width)``, vectorized
    (:func:`ideal_scores`' F1).

    Parameters
    ----------
    lo, hi : array_like
        Lower edges of the lower and higher class [J s^-1/2 K^-1 m^-2] (``hi`` positive).
    width : float or array_like
        Class width [J s^-1/2 K^-1 m^-2].
    e_sensor : float
        Sensor effusivity [J s^-1/2 K^-1 m^-2].
    s : array_like
        Projection noise [-] (>= 0, may be inf: no signal).
    points, passes, stop_at
        As :func:`ideal_scores`.

    Returns
    -------
    ndarray
        F1 in [2/3, 1].

    Examples
    --------
    >>> round(float(ideal_f1(20000.0, 35000.0, 80.0, 892.0, 0.0)), 6)
    1.0
    """
    lo, width = np.asarray(lo, dtype=np.float64), np.asarray(width, dtype=np.float64)
    return ideal_scores(lo, lo + width, hi, np.asarray(hi, dtype=np.float64) + width, e_sensor, s, accuracy=False,
                        points=points, passes=passes, stop_at=stop_at)[0]


def separates(sensor, lo, hi, width, s, threshold) -> np.ndarray:
    """Whether the ideal observer's best F1 of ``[lo, lo+w)``, ``[hi, hi+w)`` at projection noise ``s`` reaches
    ``threshold`` (elementwise; F1 zoomed only as far as the decision needs)."""
    return ideal_f1(lo, hi, width, sensor.effusivity, s, stop_at=threshold) >= threshold


def _bisect_noise(sensor, lo, hi, per_ratio, width, threshold, bracket, rel_tol) -> np.ndarray:
    """Largest sigma/dT inside ``bracket`` at which :func:`separates` holds, by bisection in log (to ``rel_tol``):
    NaN where its low end does not separate, its top where that still does (1-D arrays; ``per_ratio``: the
    projection noise per unit sigma/dT). The fallback of :func:`critical_noise`."""
    def ok(log_r):
        return separates(sensor, lo, hi, width, np.exp(log_r) * per_ratio, threshold)

    ok_lo, ok_hi = ok(np.full(lo.shape, math.log(bracket[0]))), ok(np.full(lo.shape, math.log(bracket[1])))
    out = np.where(ok_lo, np.where(ok_hi, bracket[1], np.nan), np.nan)
    # only the elements decided inside the bracket are bisected (classes that never separate, NaN, are most
    # of a coarse export grid's fallbacks: bisecting them too cost an export of f1-matrix-paper about 60 s)
    r = np.flatnonzero(ok_lo & ~ok_hi)
    lo, hi, per_ratio, width = lo[r], hi[r], per_ratio[r], width[r]
    la = np.full(r.shape, math.log(bracket[0]))
    lb = np.full(r.shape, math.log(bracket[1]))
    while np.any(active := lb - la > rel_tol):  # an element stops when it converges: its answer does not
        mid = 0.5 * (la + lb)                    # depend on the other elements of the call (nor on a cache)
        good = ok(mid)
        la, lb = np.where(active & good, mid, la), np.where(active & ~good, mid, lb)
    out[r] = np.exp(la)
    return out


@functools.lru_cache(maxsize=8)
def _z_of(threshold: float) -> float:
    """``Phi^-1(threshold)``, read off :func:`_phi_table` (enough for a starting guess)."""
    cdf, _ = _phi_table()
    return float(np.interp(threshold, cdf, np.arange(-_PHI_Z, _PHI_Z + _PHI_H / 2, _PHI_H)))


def _gaussian_noise_guess(sensor, lo, hi, width, threshold) -> np.ndarray:
    """The largest projection noise that still separates ``[lo, lo+w)`` from ``[hi, hi+w)`` if each class's
    weight ``w(e)`` were Gaussian with its uniform spread (variance ``(w(b) - w(a))^2 / 12``) added to the
    noise: for two equal Gaussians the best F1 is about ``Phi(d/2)``, ``d = (w_hi - w_lo) / s_total``, so
    ``s* = sqrt((dw / (2 z))^2 - spread^2)`` with ``z = Phi^-1(threshold)``. Only the starting point of
    :func:`critical_noise` (within a few per cent); NaN where it says no noise is small enough."""
    z = _z_of(float(threshold))
    e_s = sensor.effusivity
    wl = _weight(e_s, np.stack([lo, lo + width]))
    wh = _weight(e_s, np.stack([hi, hi + width]))
    spread2 = ((wl[1] - wl[0]) ** 2 + (wh[1] - wh[0]) ** 2) / 24.0
    dw = np.abs(0.5 * (wh[0] + wh[1] - wl[0] - wl[1]))
    with np.errstate(invalid="ignore"):
        return np.sqrt((dw / (2.0 * z)) ** 2 - spread2)


_INV_SQRT_2PI = 1.0 / math.sqrt(2.0 * math.pi)
#: Quadrature nodes of the cheap first Newton steps of :func:`critical_noise` (the last steps use the 40 of
#: :func:`class_survival`, which decide the answer).
_COARSE_NODES = 12


@functools.lru_cache(maxsize=4)
def _rule(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights of ``n`` points on [-1, 1] (numpy's, once per process)."""
    from numpy.polynomial.legendre import leggauss

    x, w = leggauss(n)
    x.flags.writeable = w.flags.writeable = False  # shared by every caller
    return x, w


def _window_z(t, s, a, b, wa, wb, e_s, gx):
    """The upper end ``e_hi`` [J s^-1/2 K^-1 m^-2] of a survival integral's window at threshold ``t`` (1-D),
    its half width, and ``z = (w(e) - t) / s`` at the window's quadrature nodes ``gx`` (on [-1, 1])."""
    e_lo, e_hi = _window(t - _CUT * s, a, b, wa, wb, e_s), _window(t + _CUT * s, a, b, wa, wb, e_s)
    half, mid = 0.5 * (e_hi - e_lo), 0.5 * (e_hi + e_lo)
    # (in place: the (elements x nodes) temporaries are most of a quadrature's time; the same operations as
    # _weight(e_s, mid + half * gx))
    z = half[:, None] * gx
    z += mid[:, None]
    with np.errstate(divide="ignore"):
        np.divide(e_s, z, out=z)
        z += 1.0
        np.divide(1.0, z, out=z)
    z -= t[:, None]
    z /= s[:, None]
    return e_hi, half, z


def _gauss(z: np.ndarray) -> np.ndarray:
    """``exp(-0.5 z z)``, its temporaries in place (a new array; ``z`` kept)."""
    out = z * -0.5
    out *= z
    return np.exp(out, out=out)


def _survival_derivatives(t, s, a, b, wa, wb, e_s, nodes: int):
    """``S(t, s) = P(w(e) + s N(0,1) > t)`` for ``e ~ U[a, b)`` (as :func:`_survival`) and its derivatives in
    the threshold ``t`` and in ``x = log s``: ``S, S_t, S_x, S_tt, S_tx`` (1-D arrays; ``nodes`` quadrature
    nodes). The window cut at +-8.5 s moves with ``t`` and ``s``, but the integrand is 0 or 1 to double
    precision at its ends, so the derivatives are the integrals of the integrand's."""
    gx, gw = _rule(nodes)
    e_hi, half, z = _window_z(t, s, a, b, wa, wb, e_s, gx)
    pdf = _gauss(z)
    pdf *= _INV_SQRT_2PI
    c = half / (b - a)

    def quad(f):  # a row's sum alone (a matrix-vector product's blocking depends on the row count)
        f *= gw
        return f.sum(axis=1)

    surv = np.minimum(np.maximum(((b - e_hi) + half * quad(ndtr(z))) / (b - a), 0.0), 1.0)
    m0 = c * quad(pdf.copy())   # (1/(b-a)) integral of phi(z) de, and of z phi, z^2 phi
    pdf *= z
    m1 = c * quad(pdf.copy())
    pdf *= z
    m2 = c * quad(pdf)
    return surv, -m0 / s, -m1, -m1 / (s * s), (m0 - m2) / s


def critical_noise(sensor, lo, hi, *, width=80.0, threshold: float = 0.9, iterations: int = 40) -> np.ndarray:
    """Projection noise ``s*`` [-] at which the ideal observer's best F1 of ``[lo, lo+w)``, ``[hi, hi+w)`` is
    ``threshold``, vectorized over ``lo``, ``hi`` and ``width`` (the F1 falls as the noise grows).

    A classifier that needs the pair's separation at noise ``s`` behaves like an ideal observer at the
    larger noise ``k s``: ``k`` (>= 1) is its *noise efficiency*, ``s*(its need) / s``
    (:func:`designkit.query.table.noise_k_min_contact`); the ideal observer's own shortest contact is the
    first sample where ``(sigma/dT) / |g|`` falls to ``s*``
    (:func:`designkit.query.ideal_bound.exact_ideal_min_contact`).

    Solved as one system in the threshold ``t`` and ``x = log s``: ``F1(t, s) = threshold`` and
    ``dF1/dt = 0`` (the threshold is the best one), by Newton's method with the analytic derivatives of
    the class survivals (:func:`_survival_derivatives`), from the Gaussian guess
    (:func:`_gaussian_noise_guess`) and the threshold midway between the classes: steps on a 12-node
    quadrature until they are below 1e-4, then on the 40-node one of :func:`class_survival` until ``x``
    moves less than 1e-13 (4-6 steps in all). The F1 there equals ``threshold`` to about 1e-12
    (tested). Elements where the system does not converge (none seen on 20,000 random pairs; e.g. classes
    whose F1 never reaches the threshold) are decided by a bisection in log s of :func:`ideal_f1`'s F1
    (NaN where even noise 1e-12 does not separate them). An element's path depends on its own values only
    (the answers are cacheable per element).

    >>> from designkit.sensor import load_sensor
    >>> s = load_sensor("paper")
    >>> star = float(critical_noise(s, 20000.0, 35000.0))
    >>> bool(ideal_f1(20000.0, 35000.0, 80.0, s.effusivity, 0.99999 * star) >= 0.9 > ideal_f1(
    ...     20000.0, 35000.0, 80.0, s.effusivity, 1.00001 * star))
    True
    """
    cols = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64) for x in (lo, hi, width)))
    shape = cols[0].shape
    lo, hi, width = (c.ravel() for c in cols)
    e_s, phi = float(sensor.effusivity), float(threshold)
    out = np.full(lo.shape, np.nan)
    if lo.size == 0:
        return out.reshape(shape)
    n = lo.size
    a, b = np.concatenate([hi, lo]), np.concatenate([hi, lo]) + np.concatenate([width, width])
    ends = (a, b, _weight(e_s, a), _weight(e_s, b))  # the class ends and their weights: the higher, the lower
    guess = _gaussian_noise_guess(sensor, lo, hi, width, phi)
    x = np.log(np.where(np.isfinite(guess) & (guess > 0), guess, 1e-4))
    t = 0.25 * (ends[2][:n] + ends[3][:n] + ends[2][n:] + ends[3][n:])
    live = np.arange(lo.size)
    nodes = np.full(lo.size, _COARSE_NODES)
    for _ in range(iterations):
        if not live.size:
            break
        coarse = nodes[live] == _COARSE_NODES
        for n_q, r in ((_COARSE_NODES, live[coarse]), (_NODES, live[~coarse])):
            if not r.size:
                continue
            tr, xr = t[r], x[r]
            s = np.exp(xr)
            k = r.size  # both classes in one evaluation: rows [0, k) the higher, [k, 2k) the lower
            both = _survival_derivatives(np.concatenate([tr, tr]), np.concatenate([s, s]), ends[0][r2 := np.concatenate(
                [r, r + n])], ends[1][r2], ends[2][r2], ends[3][r2], e_s, n_q)
            (T, F), (T_t, F_t), (T_x, F_x), (T_tt, F_tt), (T_tx, F_tx) = ((v[:k], v[k:]) for v in both)
            d2 = (1.0 + T + F) ** 2
            g1 = 2.0 * T / (1.0 + T + F) - phi          # F1 - threshold
            g2 = T_t * (1.0 + F) - T * F_t              # dF1/dt * (1 + T + F)^2 / 2
            j11, j12 = 2.0 * g2 / d2, 2.0 * (T_x * (1.0 + F) - T * F_x) / d2
            j21, j22 = T_tt * (1.0 + F) - T * F_tt, T_tx * (1.0 + F) + T_t * F_x - T_x * F_t - T * F_tx
            with np.errstate(divide="ignore", invalid="ignore"):
                det = j11 * j22 - j12 * j21
                dt = (j12 * g2 - g1 * j22) / det
                dx = (j21 * g1 - j11 * g2) / det
            bad = ~(np.isfinite(dt) & np.isfinite(dx))
            dx = np.clip(np.where(bad, 0.0, dx), -0.5, 0.5)
            dt = np.clip(np.where(bad, 0.0, dt), -3.0 * s, 3.0 * s)
            t[r], x[r] = tr + dt, xr + dx
            small = (np.abs(dx) < 1e-4) & (np.abs(dt) < 1e-4 * s)
            fine = n_q != _COARSE_NODES
            nodes[r[small]] = _NODES
            # quadratic convergence: after a step below 1e-7 the error is below ~1e-14
            done = fine & (np.abs(dx) < 1e-7) & (np.abs(dt) < 1e-7 * s) & ~bad
            out[r[done]] = np.exp(x[r[done]])
            nodes[r[bad]] = -1  # not converging: the bisection below
        live = live[np.isnan(out[live]) & (nodes[live] > 0)]
    rest = np.flatnonzero(np.isnan(out))
    if rest.size:
        out[rest] = _bisect_noise(sensor, lo[rest], hi[rest], np.ones(rest.size), width[rest], phi,
                                  (1e-12, 1e3), 1e-12)
    return out.reshape(shape)


def projection_noise(sensor: Sensor, scene: Scene) -> float:
    """Noise ``s`` of the projected statistic ``v`` (dimensionless, units of ``w``).

    ``s = (sigma / |Ts0 - Ta|) / |g|`` with ``|g|`` the Euclidean norm of the
    response shape over the touch's samples (:func:`shape_norm`). ``inf`` when there is no signal
    (no temperature difference, or no sample after contact); 0 when noise-free.

    Examples
    --------
    >>> from designkit import SENSORS, Scene
    >>> round(projection_noise(SENSORS["paper"], Scene(contact_s=1.0, noise_c=0.05)), 5)  # sigma/dT 0.005
    0.00776
    """
    ratio = scene.noise_ratio
    norm = float(shape_norm(sensor, scene.contact_s))
    if math.isinf(ratio) or norm == 0.0:
        return math.inf
    return ratio / norm


def ideal_scores(low_a, low_b, high_a, high_b, e_sensor: float, s, *, accuracy: bool = True, points: int = 17,
                 passes: int = 7, stop_at: float | None = None):
    """Best F1 and Bayes accuracy for fixed initial conditions, vectorized: the one maximizer of the ideal
    observer's scores over the decision threshold (:func:`_zoom_max`; F1 and accuracy are quasi-concave in it).

    Parameters
    ----------
    low_a, low_b : array_like
        Lower-effusivity class range ``[low_a, low_b)``.
    high_a, high_b : array_like
        Higher-effusivity (positive) class range.
    e_sensor : float
        Sensor effusivity [J s^-1/2 K^-1 m^-2].
    s : array_like
        Projection noise (:func:`projection_noise`), >= 0, may be inf.
    accuracy : bool
        Also compute the Bayes accuracy (else it is returned as None, at half
        the cost; the sweep engine needs F1 only).
    points, passes : int
        Thresholds per pass and passes (each zooms onto the best cell: the
        threshold is located to ``(2 / (points - 1)) ** passes`` of its bracket).
    stop_at : float, optional
        Stop zooming F1 once every element's reaches this (a decision ``F1 >= stop_at``
        needs no more: F1 only grows with the passes). The F1 returned are then
        lower bounds, exact as decisions.

    Returns
    -------
    f1, accuracy : ndarray (accuracy None when not asked for)
        Broadcast over the inputs.

    Examples
    --------
    >>> f1, accuracy = ideal_scores(20000, 20080, 35000, 35080, 892.0, 0.01)
    >>> round(float(f1), 3), round(float(accuracy), 3)
    (0.818, 0.813)
    """
    la, lb, ha, hb, s = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64)
                                             for x in (low_a, low_b, high_a, high_b, s)))
    shape = la.shape
    la, lb, ha, hb, s = (x.ravel() for x in (la, lb, ha, hb, s))
    f1 = np.full(la.shape, TRIVIAL_F1)
    acc = np.full(la.shape, 0.5)
    ok = np.isfinite(s)
    if ok.any():
        la, lb, ha, hb, s = la[ok], lb[ok], ha[ok], hb[ok], s[ok]
        cols = [x[:, None] for x in (ha, hb, _weight(e_sensor, ha), _weight(e_sensor, hb),
                                     la, lb, _weight(e_sensor, la), _weight(e_sensor, lb), s)]

        def rates(t, rows):  # t: (len(rows), k) thresholds per pair of ``rows``
            c = cols if rows is None else [x[rows] for x in cols]
            return _survival(t, *c[0:4], e_sensor, c[8]), _survival(t, *c[4:8], e_sensor, c[8])

        def f1_at(t, rows):
            tpr, fpr = rates(t, rows)
            return 2.0 * tpr / (1.0 + tpr + fpr)

        def accuracy_at(t, rows):
            tpr, fpr = rates(t, rows)
            return 0.5 * (1.0 + tpr - fpr)

        a = _weight(e_sensor, np.minimum(la, ha)) - (_CUT + 1) * s
        b = _weight(e_sensor, np.maximum(lb, hb)) + (_CUT + 1) * s
        f1[ok] = np.maximum(_zoom_max(f1_at, a, b, points=points, passes=passes, stop_at=stop_at), TRIVIAL_F1)
        if accuracy:
            acc[ok] = _zoom_max(accuracy_at, a, b, points=points, passes=passes)
    return f1.reshape(shape), (acc.reshape(shape) if accuracy else None)


# ----------------------------------------------------------------- Monte Carlo
def _log1mexp(x):
    """log(1 - exp(x)) for x <= 0, accurate everywhere."""
    x = np.asarray(x, dtype=np.float64)
    with np.errstate(divide="ignore"):
        return np.where(x > -math.log(2.0), np.log(-np.expm1(x)), np.log1p(-np.exp(x)))


def log_ndtr_diff(lo, hi):
    """log(Phi(hi) - Phi(lo)) for lo <= hi, stable in both tails (Phi: the standard normal CDF).

    >>> round(float(log_ndtr_diff(40.0, 41.0)), 3)  # Phi(-40) - Phi(-41), far below double precision
    -804.608
    """
    from scipy import special

    lo, hi = np.broadcast_arrays(lo, hi)
    upper = lo > 0  # both in the upper tail: use Phi(-lo) - Phi(-hi)
    a = np.where(upper, -hi, lo)
    b = np.where(upper, -lo, hi)
    lb = special.log_ndtr(b)
    with np.errstate(invalid="ignore"):
        return lb + _log1mexp(special.log_ndtr(a) - lb)


def _loglik_sensor_integrated(Y0, Y1, YY, w, ta, m, S1, S2, mu_s, h_s, sigma):
    """log p(y | e, Ta), with Ts0 integrated over U[mu_s - h_s, mu_s + h_s] (or fixed).

    Shapes: statistics (n, 1), w (1, K); constants dropped that do not depend
    on the class (m/2 log(2 pi sigma^2)).
    """
    u_dot_u = m - 2.0 * w * S1 + w * w * S2          # |1 - w g|^2
    u_dot_y = (Y0 - w * Y1) - ta * w * (S1 - w * S2)  # (1 - w g) . (y - Ta w g)
    r_dot_r = YY - 2.0 * ta * w * Y1 + ta * ta * w * w * S2
    var = sigma * sigma
    if h_s == 0.0:
        x = mu_s
        return -(u_dot_u * x * x - 2.0 * u_dot_y * x + r_dot_r) / (2.0 * var)
    x_hat = u_dot_y / u_dot_u
    resid = r_dot_r - u_dot_y * x_hat
    scale = np.sqrt(u_dot_u) / sigma
    log_mass = log_ndtr_diff((mu_s - h_s - x_hat) * scale, (mu_s + h_s - x_hat) * scale)
    return -resid / (2.0 * var) + 0.5 * np.log(2.0 * math.pi * var / u_dot_u) + log_mass - math.log(2.0 * h_s)


def _class_loglik(stats, e_range, sensor, scene, g, sigma, n_grid):
    from scipy import special

    Y0, Y1, YY = stats
    a, b = e_range
    e = a + (np.arange(n_grid) + 0.5) * (b - a) / n_grid
    w = object_weight(sensor.effusivity, e)[None, :]
    m, S1, S2 = float(g.size), float(g.sum()), float(np.dot(g, g))
    if scene.ambient_temp_spread_c > 0:
        xs, ws = _rule(16)
        ta_nodes = scene.ambient_temp_c + scene.ambient_temp_spread_c * xs
        log_wts = np.log(ws / 2.0)
    else:
        ta_nodes, log_wts = np.array([scene.ambient_temp_c]), np.array([0.0])
    terms = []
    for ta, lw in zip(ta_nodes, log_wts):
        ll = _loglik_sensor_integrated(Y0[:, None], Y1[:, None], YY[:, None], w, ta, m, S1, S2,
                                       scene.sensor_temp_c, scene.sensor_temp_spread_c, sigma)
        terms.append(special.logsumexp(ll, axis=1) - math.log(n_grid) + lw)
    return special.logsumexp(np.stack(terms), axis=0)


def _ideal_monte_carlo(low, high, sensor: Sensor, scene: Scene, n_mc: int, seed) -> IdealResult:
    from ..simulation import simulate_interval

    n_mc = int(n_mc)
    if n_mc < 10:
        raise InputError(f"Monte Carlo ideal observer needs at least 10 touches per class, got {n_mc}")
    g = response_shape(sensor.times_s(scene.contact_s), sensor.tau_s)
    # a noise-free varied scene is handled as the limit of a tiny noise
    sigma = max(scene.noise_c, 1e-6 * max(abs(scene.delta_t_c), 1.0))
    mc_scene = scene.replace(noise_c=sigma)
    key = [int(k) for k in (seed if isinstance(seed, (list, tuple)) else [seed])]
    t_low = simulate_interval(*low, n_mc, sensor, mc_scene, seed=key + [10])
    t_high = simulate_interval(*high, n_mc, sensor, mc_scene, seed=key + [11])
    y = np.vstack([t_low.temperature_c, t_high.temperature_c])
    labels = np.r_[np.zeros(n_mc, dtype=int), np.ones(n_mc, dtype=int)]
    stats = (y.sum(axis=1), y @ g, np.einsum("ij,ij->i", y, y))
    s = (sigma / max(abs(scene.delta_t_c), 1e-12)) / max(float(np.sqrt(np.dot(g, g))), 1e-300)
    llr = np.empty(y.shape[0])
    for lo_i in range(0, y.shape[0], 256):
        sl = slice(lo_i, lo_i + 256)
        chunk = tuple(v[sl] for v in stats)
        ll = []
        for rng_ in (low, high):
            dw = float(object_weight(sensor.effusivity, rng_[1]) - object_weight(sensor.effusivity, rng_[0]))
            n_grid = int(np.clip(math.ceil(4.0 * dw / max(s, 1e-300)), 16, 4096))
            ll.append(_class_loglik(chunk, rng_, sensor, mc_scene, g, sigma, n_grid))
        llr[sl] = ll[1] - ll[0]
    f1, se, acc, acc_se = score_llr(llr, labels, n_mc)
    return IdealResult(f1=f1, accuracy=acc, method="monte-carlo", standard_error=se,
                       accuracy_standard_error=acc_se, projection_noise=None, n_mc=n_mc)


# ----------------------------------------------------------------- public entry
def _as_class(x, name: str):
    from ..objects import ObjectClass

    if isinstance(x, ObjectClass):
        return x
    lo, hi = check_effusivity_range(name, *x)
    return ObjectClass(name, (lo, hi))


def ideal_pair(range_a, range_b, sensor: Sensor, scene: Scene, *, n_mc: int = 2000, seed=0,
               model=None) -> IdealResult:
    """Best achievable F1 and accuracy for two object classes, under any forward model.

    Closed form for fixed initial conditions and a shared-shape model (or one
    whose extra physics is invisible here, :meth:`ForwardModel.equivalent_shared_shape`);
    Monte Carlo on the exact likelihood (``n_mc`` simulated touches per class,
    ``seed``) when the scene varies Ts0 or Ta, or the model's curves differ in
    shape per object (:mod:`designkit.recognition.ideal_mc`).

    Parameters
    ----------
    range_a, range_b : (float, float) or ObjectClass
        Class ranges ``[low, high)`` [J s^-1/2 K^-1 m^-2] or object classes;
        order does not matter.
    sensor : Sensor
    scene : Scene
    model : ForwardModel or name, optional
        Default: the paper's semi-infinite model.

    Examples
    --------
    >>> from designkit import SENSORS, Scene
    >>> r = ideal_pair((35000, 35080), (20000, 20080), SENSORS["paper"], Scene(contact_s=1))
    >>> round(r.accuracy, 3)
    0.874
    """
    from ..models import get_model

    fm = get_model(model)
    a, b = _as_class(range_a, "e1"), _as_class(range_b, "e2")
    if a.e_range == b.e_range and a.diffusivity_range_m2_s == b.diffusivity_range_m2_s:
        lo_, hi_ = a.e_range
        raise InputError(f"the two effusivity ranges are identical ([{lo_:g}, {hi_:g})): nothing to separate")
    if not _shape_shared_here(fm, a, b, sensor, scene):
        from .ideal_mc import ideal_pair_mc

        return ideal_pair_mc(a, b, sensor, scene, model=fm, n_mc=n_mc, seed=seed)
    low, high = sorted([a.e_range, b.e_range])
    if scene.fixed_initial_conditions:
        s = projection_noise(sensor, scene)
        f1, acc = ideal_scores(low[0], low[1], high[0], high[1], sensor.effusivity, s)
        return IdealResult(f1=float(f1), accuracy=float(acc), method="closed-form",
                           projection_noise=s)
    return _ideal_monte_carlo(low, high, sensor, scene, n_mc, seed)


def ideal_method(range_a, range_b, sensor: Sensor, scene: Scene, *, model=None) -> str:
    """How :func:`ideal_pair` scores this pair and scene, without scoring it: ``"closed-form"`` or
    ``"monte-carlo"``.

    Examples
    --------
    >>> from designkit import SENSORS, Scene
    >>> ideal_method((35000, 35080), (20000, 20080), SENSORS["paper"], Scene(contact_s=1))
    'closed-form'
    >>> ideal_method((35000, 35080), (20000, 20080), SENSORS["paper"],
    ...              Scene(contact_s=1, sensor_temp_c=32.5, sensor_temp_spread_c=2.5))
    'monte-carlo'
    """
    from ..models import get_model

    fm = get_model(model)
    a, b = _as_class(range_a, "e1"), _as_class(range_b, "e2")
    closed = _shape_shared_here(fm, a, b, sensor, scene) and scene.fixed_initial_conditions
    return "closed-form" if closed else "monte-carlo"


def _shape_shared_here(fm, a, b, sensor: Sensor, scene: Scene) -> bool:
    """Whether the model's curves share one shape for these classes in this scene (its own, or its extra
    physics invisible here, :meth:`ForwardModel.equivalent_shared_shape`). A rig's scene (correlated noise,
    a recorder's window after its onset) takes the Monte Carlo route, which whitens the noise."""
    if scene.noise_correlation_s > 0 or scene.onset_s > 0:
        return False
    return fm.shared_shape or fm.equivalent_shared_shape(
        (a, b), sensor, contact_s=scene.contact_s, tolerance=_invisible_tolerance(sensor, scene)) is not None


#: A model's extra physics below this fraction of the noise over the whole
#: touch (in norm) leaves the closed-form answer as it is.
INVISIBLE_NOISE_FRACTION = 0.01


def _invisible_tolerance(sensor: Sensor, scene: Scene) -> float:
    """Largest per-sample normalized deviation whose curve norm stays below 1 % of the noise."""
    m = sensor.times_s(scene.contact_s).size
    ratio = scene.noise_ratio
    if not math.isfinite(ratio):
        return math.inf
    return INVISIBLE_NOISE_FRACTION * ratio / math.sqrt(m)
