"""The ideal observer's exact answers to the design questions, vectorized.

Closed form (:func:`designkit.recognition.ideal.ideal_scores`) plus bisection
on the asked quantity, over arrays of pairs and scenes at once: the bound that
no classifier can beat, computed at query time instead of read from a grid.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["exact_ideal_delta", "exact_ideal_max_ratio", "exact_ideal_min_contact"]


def _projection_noises(sensor, contacts, ratios) -> np.ndarray:
    """:func:`designkit.recognition.ideal.projection_noise` for arrays of contact times and sigma/dT (dT = 1)."""
    from ..recognition.ideal import projection_noise
    from ..scene import Scene

    c, r = np.broadcast_arrays(np.asarray(contacts, dtype=np.float64), np.asarray(ratios, dtype=np.float64))
    s = [projection_noise(sensor, Scene(contact_s=float(ci), noise_c=float(ri), sensor_temp_c=26.0,
                                        ambient_temp_c=25.0)) for ci, ri in zip(c.ravel(), r.ravel())]
    return np.asarray(s, dtype=np.float64).reshape(c.shape)


def _ideal_ok(sensor, lo, hi, width, s, threshold) -> np.ndarray:
    from ..recognition.ideal import ideal_scores

    f1, _ = ideal_scores(lo, lo + width, hi, hi + width, sensor.effusivity, s, accuracy=False)
    return f1 >= threshold


def exact_ideal_min_contact(sensor, lo, hi, ratio, *, width: float = 80.0, threshold: float = 0.9,
                            max_contact_s: float = 10.0) -> np.ndarray:
    """Ideal observer's shortest contact [s] for classes ``[lo, lo+w)``, ``[hi, hi+w)``, vectorized.

    Bisection on the contact time (F1 never falls with more samples) to one
    sample period; NaN where ``max_contact_s`` does not suffice. Same classes
    and answer as the ideal part of :func:`designkit.query.exact_min_contact`.
    """
    lo, hi, ratio = (np.asarray(x, dtype=np.float64) for x in np.broadcast_arrays(lo, hi, ratio))
    floor = 1.0 / sensor.sample_rate_hz
    a = np.full(lo.shape, floor)
    b = np.full(lo.shape, float(max_contact_s))
    top = _ideal_ok(sensor, lo, hi, width, _projection_noises(sensor, b, ratio), threshold)
    while np.any(b - a > 0.5 * floor):
        mid = 0.5 * (a + b)
        ok = _ideal_ok(sensor, lo, hi, width, _projection_noises(sensor, mid, ratio), threshold)
        b, a = np.where(ok, mid, b), np.where(ok, a, mid)
    return np.where(top, b, np.nan)


def exact_ideal_max_ratio(sensor, lo, hi, contact_s, *, width: float = 80.0, threshold: float = 0.9,
                          bracket=(1e-6, 1.0), rel_tol: float = 1e-5) -> np.ndarray:
    """Ideal observer's largest sigma/dT that still separates the classes, vectorized (log bisection).

    NaN where even ``bracket[0]`` does not separate them; ``bracket[1]`` when
    it still does.
    """
    lo, hi, contact = (np.asarray(x, dtype=np.float64) for x in np.broadcast_arrays(lo, hi, contact_s))
    g_over = _projection_noises(sensor, contact, np.ones(lo.shape))  # s = ratio * this
    la = np.full(lo.shape, math.log(bracket[0]))
    lb = np.full(lo.shape, math.log(bracket[1]))
    ok_lo = _ideal_ok(sensor, lo, hi, width, np.exp(la) * g_over, threshold)
    ok_hi = _ideal_ok(sensor, lo, hi, width, np.exp(lb) * g_over, threshold)
    while np.any(lb - la > rel_tol):
        mid = 0.5 * (la + lb)
        ok = _ideal_ok(sensor, lo, hi, width, np.exp(mid) * g_over, threshold)
        la, lb = np.where(ok, mid, la), np.where(ok, lb, mid)
    out = np.exp(la)
    out = np.where(ok_hi, bracket[1], out)
    return np.where(ok_lo, out, np.nan)


def exact_ideal_delta(sensor, e, contact_s, ratio, *, direction: int = +1, width: float = 80.0,
                      threshold: float = 0.9, e_max: float = 40000.0, tol: float = 0.5) -> np.ndarray:
    """Ideal observer's delta(e) towards higher (+1) or lower (-1) e, vectorized.

    Reference class ``[e, e+w)``, partner ``[e +- d, e +- d + w)`` (as
    :func:`designkit.query.exact_delta_e`); bisection on ``d`` to ``tol``.
    NaN where no partner inside ``(0, e_max]`` is distinguishable.
    """
    e, contact, ratio = (np.asarray(x, dtype=np.float64) for x in np.broadcast_arrays(e, contact_s, ratio))
    s = _projection_noises(sensor, contact, ratio)
    limit = (e_max - e - width) if direction > 0 else (e - width)

    def ok(d):
        p = e + direction * d
        lo, hi = np.minimum(e, p), np.maximum(e, p)
        return _ideal_ok(sensor, lo, hi, width, s, threshold)

    valid = limit >= width
    lim = np.where(valid, limit, width)
    top = ok(lim) & valid
    a, b = np.zeros(e.shape), lim.copy()
    while np.any(b - a > tol):
        mid = 0.5 * (a + b)
        good = ok(mid)
        b, a = np.where(good, mid, b), np.where(good, a, mid)
    return np.where(top, b, np.nan)


