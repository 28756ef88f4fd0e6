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
maximizes accuracy and F1 over the threshold.

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

import math

import numpy as np
from scipy import special

from .._validation import InputError, check_effusivity_range
from .scores import TRIVIAL_F1
from .scores import IdealResult, score_llr
from ..models.semi_infinite import object_weight, response_shape
from ..scene import Scene
from ..sensor import Sensor

__all__ = [
    "IdealResult",
    "class_survival",
    "ideal_pair",
    "ideal_scores",
    "log_ndtr_diff",
    "projection_noise",
    "score_llr",
]

_GL_X, _GL_W = np.polynomial.legendre.leggauss(40)
_CUT = 8.5  # Phi(-8.5) = 9.5e-18: outside +-8.5 s the integrand is 0 or 1 to double precision
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


# ----------------------------------------------------------------- closed form
def projection_noise(sensor: Sensor, scene: Scene) -> float:
    """Noise ``s`` of the projected statistic ``v`` (dimensionless, units of ``w``).

    ``s = (sigma / |Ts0 - Ta|) / |g|`` with ``|g|`` the Euclidean norm of the
    response shape over the touch's samples. ``inf`` when there is no signal
    (no temperature difference, or no sample after contact); 0 when noise-free.
    """
    ratio = scene.noise_ratio
    g = response_shape(sensor.times_s(scene.contact_s), sensor.tau_s)
    norm = float(np.sqrt(np.dot(g, g)))
    if math.isinf(ratio) or norm == 0.0:
        return math.inf
    return ratio / norm


def _e_of_w(w, e_sensor):
    """Inverse of ``w = e / (e_s + e)``; inf for w >= 1."""
    w = np.asarray(w, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        e = np.where(w < 1.0, e_sensor * w / (1.0 - w), np.inf)
    return np.where(w <= 0.0, 0.0, e)


def _cut_point(w_cut, wa, wb, a, b, e_sensor):
    inside = np.clip(_e_of_w(np.clip(w_cut, wa, wb), e_sensor), a, b)
    return np.where(w_cut <= wa, a, np.where(w_cut >= wb, b, inside))


def class_survival(t, e_low, e_high, e_sensor, s):
    """``P(v > t)`` for ``v = w(e) + N(0, s^2)``, ``e ~ U[e_low, e_high)``.

    All arguments broadcast. ``s = 0`` gives the exact step-function limit.

    Parameters
    ----------
    t : array_like
        Threshold on ``v`` (units of ``w``).
    e_low, e_high : array_like
        Class range [J s^-1/2 K^-1 m^-2].
    e_sensor : float
        Sensor effusivity [J s^-1/2 K^-1 m^-2].
    s : array_like
        Projection noise (>= 0, finite).

    Returns
    -------
    ndarray
        Probability in [0, 1].
    """
    t, a, b, s = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64) for x in (t, e_low, e_high, s)))
    wa = object_weight(e_sensor, a)
    wb = object_weight(e_sensor, b)
    # [e_lo, e_hi]: where Phi((w(e) - t)/s) is neither 0 nor 1 to double precision.
    # Cuts outside the class use its exact ends: w -> e -> w does not round-trip
    # exactly, which would matter for very narrow classes.
    e_lo = _cut_point(t - _CUT * s, wa, wb, a, b, e_sensor)
    e_hi = _cut_point(t + _CUT * s, wa, wb, a, b, e_sensor)
    half = 0.5 * (e_hi - e_lo)
    mid = 0.5 * (e_hi + e_lo)
    nodes = mid[..., None] + half[..., None] * _GL_X
    with np.errstate(divide="ignore", invalid="ignore"):
        z = (object_weight(e_sensor, nodes) - t[..., None]) / s[..., None]
    z = np.where(np.isnan(z), 0.0, z)  # s = 0 and w == t: measure zero, value irrelevant
    middle = half * np.sum(_GL_W * special.ndtr(z), axis=-1)
    return np.clip(((b - e_hi) + middle) / (b - a), 0.0, 1.0)


def _golden_max(f, lo, hi, iters: int = 60):
    """Vectorized golden-section maximization of quasi-concave ``f`` on [lo, hi].

    Elementwise over arrays of brackets. scipy's elementwise minimizer needs a
    valid interior bracket, which F1 (whose optimum may be the all-positive
    limit at the bracket's end) does not always have.
    """
    a, b = np.array(lo, dtype=np.float64), np.array(hi, dtype=np.float64)
    c = b - _GOLDEN * (b - a)
    d = a + _GOLDEN * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(iters):
        left = fc >= fd  # the maximum lies in [a, d]: drop (d, b]; else drop [a, c)
        a, b = np.where(left, a, c), np.where(left, d, b)
        # the surviving interior point is reused; one new point per iteration
        x_new = np.where(left, b - _GOLDEN * (b - a), a + _GOLDEN * (b - a))
        f_new = f(x_new)
        c, d, fc, fd = (np.where(left, x_new, d), np.where(left, c, x_new),
                        np.where(left, f_new, fd), np.where(left, fc, f_new))
    x = np.where(fc >= fd, c, d)
    fx = np.maximum(fc, fd)
    # the bracket ends themselves (optimum at an end)
    fa, fb = f(np.asarray(lo, dtype=np.float64)), f(np.asarray(hi, dtype=np.float64))
    best = np.maximum(fx, np.maximum(fa, fb))
    return best, x


def ideal_scores(low_a, low_b, high_a, high_b, e_sensor: float, s, *, accuracy: bool = True):
    """Best F1 and Bayes accuracy for fixed initial conditions, vectorized.

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

    Returns
    -------
    f1, accuracy : ndarray (accuracy None when not asked for)
        Broadcast over the inputs.
    """
    la, lb, ha, hb, s = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64)
                                             for x in (low_a, low_b, high_a, high_b, s)))
    shape = la.shape
    la, lb, ha, hb, s = (x.ravel() for x in (la, lb, ha, hb, s))
    f1 = np.full(la.shape, TRIVIAL_F1)
    acc = np.full(la.shape, 0.5)
    ok = np.isfinite(s)
    if ok.any():
        la_, lb_, ha_, hb_, s_ = la[ok], lb[ok], ha[ok], hb[ok], s[ok]
        lo = object_weight(e_sensor, np.minimum(la_, ha_)) - (_CUT + 1) * s_
        hi = object_weight(e_sensor, np.maximum(lb_, hb_)) + (_CUT + 1) * s_

        def rates(t):
            return class_survival(t, ha_, hb_, e_sensor, s_), class_survival(t, la_, lb_, e_sensor, s_)

        def accuracy_at(t):
            tpr, fpr = rates(t)
            return 0.5 * (1.0 + tpr - fpr)

        def f1_at(t):
            tpr, fpr = rates(t)
            return 2.0 * tpr / (1.0 + tpr + fpr)

        f1_best, _ = _golden_max(f1_at, lo, hi)
        f1[ok] = np.maximum(f1_best, TRIVIAL_F1)
        if accuracy:
            acc[ok], _ = _golden_max(accuracy_at, lo, hi)
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
    Y0, Y1, YY = stats
    a, b = e_range
    e = a + (np.arange(n_grid) + 0.5) * (b - a) / n_grid
    w = object_weight(sensor.effusivity, e)[None, :]
    m, S1, S2 = float(g.size), float(g.sum()), float(np.dot(g, g))
    if scene.ambient_temp_spread_c > 0:
        xs, ws = np.polynomial.legendre.leggauss(16)
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
    physics invisible here, :meth:`ForwardModel.equivalent_shared_shape`)."""
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
