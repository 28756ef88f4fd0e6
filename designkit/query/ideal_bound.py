"""The ideal observer's exact answers to the design questions, vectorized.

For a shared-shape model with fixed initial conditions the ideal observer
depends on the scene only through the projection noise
``s = (sigma/dT) / |g|``, ``|g|`` the Euclidean norm of the response shape
``g(t) = erfc(sqrt(tau/t))`` over the touch's samples
(:mod:`designkit.recognition.ideal`, the one closed form). Every bound here is
a cheap function of a pair's *critical noise* ``s*``
(:func:`~designkit.recognition.ideal.critical_noise`), kept in one per-process
memo: the shortest contact is the first sample where ``s`` falls to ``s*``, the
largest sigma/dT is ``s* |g|``. A table query computes them at query time:
the bound is never read from a grid.

Units: effusivity [J s^-1/2 K^-1 m^-2], contact time [s], ``ratio`` = sigma/dT [-].

Examples
--------
>>> from designkit.sensor import load_sensor
>>> t = exact_ideal_min_contact(load_sensor("paper"), 20000.0, 35000.0, 0.005)
>>> round(float(t), 3)
1.05
"""

from __future__ import annotations

import functools

import numpy as np
from cachetools import LRUCache

from ..recognition.ideal import critical_noise, cumulative_g2, separates, shape_norm
from ..sensor import last_sample_index

__all__ = [
    "BOUND_CACHE_SIZE",
    "clear_bound_cache",
    "columns",
    "contact_at_noise",
    "exact_ideal_delta",
    "exact_ideal_max_ratio",
    "exact_ideal_min_contact",
    "first_sample_at",
    "noise_k_contact",
    "pair_critical_noise",
]



def columns(*values, dtypes=None) -> list[np.ndarray]:
    """``values`` as 1-D arrays of one length (float64, or ``dtypes`` each), broadcast only where their shapes
    differ (the usual call passes arrays of one length already: no copies, no broadcasting).

    >>> [a.tolist() for a in columns(2.0, [1.0, 3.0])]
    [[2.0, 2.0], [1.0, 3.0]]
    """
    out = [np.asarray(v, dtype=d) for v, d in zip(values, dtypes or (np.float64,) * len(values))]
    shapes = {a.shape for a in out if a.ndim}
    if len(shapes) == 1 and len(shape := shapes.pop()) == 1:  # one length: numbers given once repeated
        return [a if a.ndim else np.full(shape, a) for a in out]
    return [np.atleast_1d(a) for a in np.broadcast_arrays(*out)]


def _first_good_sample(ok, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Bisection on the sample count, elementwise: the first ``n`` in ``(a, b]`` where ``ok(n, rows)`` holds,
    for a decision false at ``a`` and true from some ``n`` on (``b`` where it never turns true below ``b``).

    ``ok(n, rows)`` decides the elements ``rows`` (an index array) at counts ``n`` shaped ``(len(rows),)``;
    each step decides only the elements still bracketed wider than one sample.
    """
    a, b = a.copy(), b.copy()
    while (rows := np.nonzero(b - a > 1)[0]).size:
        mid = (a[rows] + b[rows]) // 2
        good = ok(mid, rows)
        b[rows] = np.where(good, mid, b[rows])
        a[rows] = np.where(good, a[rows], mid)
    return b


def exact_ideal_min_contact(sensor, lo, hi, ratio, *, width: float = 80.0, threshold: float = 0.9,
                            max_contact_s: float = 10.0) -> np.ndarray:
    """Ideal observer's shortest contact [s] for classes ``[lo, lo+w)``, ``[hi, hi+w)``, vectorized.

    Exact to the sample: F1 only changes when a sample arrives, and only through the projection noise
    ``s = (sigma/dT) / |g|``, which falls with every sample; so this is the first sample time ``n / fs``
    at which ``s`` reaches the pair's critical noise
    (:func:`~designkit.recognition.ideal.critical_noise`). NaN where ``max_contact_s`` does not suffice.
    Through the per-process memo (a pure function of its arguments: a hit returns what a computation would).

    Parameters
    ----------
    sensor : Sensor
        Sensor (effusivity, time constant, sample rate).
    lo, hi : array_like
        Lower edges of the two classes [J s^-1/2 K^-1 m^-2].
    ratio : array_like
        Noise sigma over temperature difference, sigma/dT [-].
    width : float or array_like
        Class width [J s^-1/2 K^-1 m^-2].
    threshold : float
        F1 threshold Phi.
    max_contact_s : float
        Longest contact examined [s].

    Returns
    -------
    ndarray
        Contact time [s] (NaN: none up to ``max_contact_s``).

    Examples
    --------
    >>> from designkit.sensor import load_sensor
    >>> round(float(exact_ideal_min_contact(load_sensor("paper"), 20000.0, 35000.0, 0.005)), 3)
    1.05
    """
    def compute(a, b, r, w):
        return contact_at_noise(sensor, r, pair_critical_noise(sensor, a, b, width=w, threshold=threshold),
                                max_contact_s)
    return _cached("min-contact", sensor, (lo, hi, ratio, width), (float(threshold), float(max_contact_s)),
                   compute)


def contact_at_noise(sensor, ratio, s_star, max_contact_s: float = 10.0) -> np.ndarray:
    """The ideal observer's shortest contact [s] of a pair whose critical noise is ``s_star`` at sigma/dT
    ``ratio``: the first sample time where ``ratio / |g|`` falls to ``s_star`` (:func:`first_sample_at`),
    elementwise; NaN where none up to ``max_contact_s`` [s] is."""
    fs = float(sensor.sample_rate_hz)
    n_max = max(int(last_sample_index(max_contact_s, fs)), 1)
    return first_sample_at(cumulative_g2(float(sensor.tau_s), fs, n_max), ratio, s_star) / fs


def first_sample_at(cum: np.ndarray, ratio, s_star) -> np.ndarray:
    """First sample count ``n >= 1`` with ``ratio / sqrt(cum[n]) <= s_star`` (``cum``: the cumulative squared
    response shape, :func:`~designkit.recognition.ideal.cumulative_g2`), elementwise; NaN where no count up
    to ``cum.size - 1`` is."""
    ratio, s_star = np.asarray(ratio, dtype=np.float64), np.asarray(s_star, dtype=np.float64)
    if ratio.shape != s_star.shape:
        ratio, s_star = np.broadcast_arrays(ratio, s_star)
    top = cum.size - 1

    def ok(k):  # the decision itself, as written, at count k (clipped into the table)
        return ratio / np.sqrt(cum[np.minimum(np.maximum(k, 1), top)]) <= s_star

    if ratio.size <= 64 and top >= 1:  # a few: the (monotone) decision at every count in one pass, as found below
        with np.errstate(divide="ignore", invalid="ignore"):
            first = (good := ratio.reshape(-1, 1) / np.sqrt(cum[1:]) <= s_star.reshape(-1, 1)).argmax(axis=1)
        return np.where(good[np.arange(first.size), first], first + 1.0, np.nan).reshape(ratio.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        need = np.where(s_star > 0, (ratio / s_star) ** 2, np.where(ratio > 0, np.inf, 0.0))
        need = np.where(np.isnan(s_star) | np.isnan(ratio), np.inf, need)
        n = 1 + cum[1:].searchsorted(need, side="left")
        # at the count and the one before (rounding of the square): the next where the count fails, else the one
        # before where it holds
        before = n - 1
        at, prev = ok(np.array([n, before]))
        n = np.where((n <= top) & ~at, n + 1, np.where((n > 1) & (before <= top) & prev, before, n))
    return np.where((n <= top) & np.isfinite(need), n, np.nan)


#: Largest sigma/dT [-] the ideal observer's max-ratio answers (a touch has at most 1e6 samples, each at a
#: signal of at most dT: no pair separates near this noise); infinity beyond it.
RATIO_CEILING = 1e6


def exact_ideal_max_ratio(sensor, lo, hi, contact_s, *, width: float = 80.0, threshold: float = 0.9,
                          bracket=(1e-6, 1.0)) -> np.ndarray:
    """Ideal observer's largest sigma/dT [-] that still separates the classes, vectorized: the pair's critical
    noise (:func:`~designkit.recognition.ideal.critical_noise`) times the response shape's norm at ``contact_s`` [s].

    NaN where even ``bracket[0]`` does not separate them. The bracket's top is no bound (at 10 s of contact
    the ideal observer separates 500 from 39,000 up to sigma/dT 4.6): answers run up to
    :data:`RATIO_CEILING`, infinity beyond it. Other arguments as :func:`exact_ideal_min_contact` (and
    through the same memo).

    Examples
    --------
    >>> from designkit.sensor import load_sensor
    >>> r = exact_ideal_max_ratio(load_sensor("paper"), 500.0, 39000.0, 10.0, bracket=(1e-5, 1.0))
    >>> 4.6 < float(r) < 4.7
    True
    """
    def compute(a, b, c, w):
        r = pair_critical_noise(sensor, a, b, width=w, threshold=threshold) * shape_norm(sensor, c)
        return np.where(r >= bracket[0], np.where(r > RATIO_CEILING, np.inf, r), np.nan)
    return _cached("max-ratio", sensor, (lo, hi, contact_s, width), (float(threshold), float(bracket[0])), compute)


def exact_ideal_delta(sensor, e, contact_s, ratio, *, direction=+1, width: float = 80.0,
                      threshold: float = 0.9, e_max: float = 40000.0, tol: float = 0.5) -> np.ndarray:
    """Ideal observer's delta(e) [J s^-1/2 K^-1 m^-2] towards higher (+1) or lower (-1) e, vectorized.

    Reference class ``[e, e+w)``, partner ``[e +- d, e +- d + w)`` (as
    :func:`designkit.query.exact_delta_e`); bisection on ``d`` to ``tol``.
    NaN where no partner inside ``(0, e_max]`` is distinguishable. ``direction`` may be an array (elementwise,
    each element's bisection its own: the answers are those of one call per direction). Through the
    per-process memo, as :func:`exact_ideal_min_contact`.

    >>> from designkit.sensor import load_sensor
    >>> s = load_sensor("paper")
    >>> both = exact_ideal_delta(s, [20000.0, 20000.0], 2.0, 0.005, direction=np.array([-1.0, 1.0]))
    >>> [float(both[0]), float(both[1])] == [float(exact_ideal_delta(s, 20000.0, 2.0, 0.005, direction=d))
    ...                                      for d in (-1, 1)]
    True
    """
    def compute(a, c, r, d):  # both directions in one bisection (each element's its own)
        return _ideal_delta(sensor, a, c, r, np.where(d > 0, 1.0, -1.0), width, threshold, e_max, tol)
    return _cached("delta", sensor, (e, contact_s, ratio, np.where(np.asarray(direction) > 0, 1.0, -1.0)),
                   (float(width), float(threshold), float(e_max), float(tol)), compute)


def _ideal_delta(sensor, e, contact, ratio, direction, width, threshold, e_max, tol) -> np.ndarray:
    norm = shape_norm(sensor, contact)
    with np.errstate(divide="ignore", invalid="ignore"):  # no signal yet (norm 0): s infinite, whatever the ratio
        s = np.where(norm > 0, ratio / norm, np.inf)
    direction = np.where(direction > 0, 1.0, -1.0)
    limit = np.where(direction > 0, e_max - e - width, e - width)

    def ok(d):
        p = e + direction * d
        return separates(sensor, np.minimum(e, p), np.maximum(e, p), width, s, threshold)

    valid = limit >= width
    lim = np.where(valid, limit, width)
    top = ok(lim) & valid
    a, b = np.zeros(e.shape), lim.copy()
    while np.any(active := b - a > tol):
        mid = 0.5 * (a + b)
        good = ok(mid)
        b, a = np.where(active & good, mid, b), np.where(active & ~good, mid, a)
    return np.where(top, b, np.nan)


# ============================================================ per-process cache of the closed-form bounds
#: Closed-form bounds kept per process (least recently used out): a table question asked again (a loop,
#: a matrix over scenes) costs a dict look-up instead of a quadrature. Entries are pure
#: functions of their key (sensor, class width, threshold, the pair and the scene), so a hit returns
#: exactly what a computation would (each element's bisection is independent of the others).
BOUND_CACHE_SIZE = 262144  # a 10,000-query array call reads ~120,000 critical noises: they must fit
_CACHE_BLOCK = 4096  # elements per vectorized search call (each element's answer is independent of the block)
_BOUNDS: "LRUCache[tuple, float]" = LRUCache(BOUND_CACHE_SIZE)


def clear_bound_cache() -> None:
    """Forget the closed-form bounds this process has computed."""
    _BOUNDS.clear()


def _cached(kind: str, sensor, columns: tuple, params: tuple, compute) -> np.ndarray:
    """``compute(*columns)`` elementwise through the cache: the distinct misses in one vectorized call."""
    cols = [np.asarray(v, dtype=np.float64) for v in np.broadcast_arrays(*columns)]
    head = (kind, float(sensor.effusivity), float(sensor.tau_s), float(sensor.sample_rate_hz)) + params
    width = len(cols)
    keys = [head + k for k in zip(*(c.ravel().tolist() for c in cols))]
    missing = list(dict.fromkeys(k for k in keys if k not in _BOUNDS))
    fresh = {}  # this call's computed values: a call with more misses than the cache holds evicts its own
    if missing:
        m = np.array([k[-width:] for k in missing], dtype=np.float64).reshape(len(missing), width)
        # in blocks: a search's temporaries are (elements x thresholds x quadrature nodes); 120,000 elements at
        # once (a 10,000-query array's table readings) took 650 MB per temporary and 4x the time
        for start in range(0, len(missing), _CACHE_BLOCK):
            block = m[start:start + _CACHE_BLOCK]
            for k, v in zip(missing[start:start + _CACHE_BLOCK], np.asarray(compute(*block.T)).tolist()):
                _BOUNDS[k] = fresh[k] = v
    out = np.empty(len(keys))
    for i, k in enumerate(keys):
        out[i] = fresh[k] if k in fresh else _BOUNDS[k]
    return out.reshape(cols[0].shape)


def pair_critical_noise(sensor, lo, hi, *, width=80.0, threshold: float = 0.9) -> np.ndarray:
    """:func:`~designkit.recognition.ideal.critical_noise` through the per-process memo, elementwise over
    ``lo``, ``hi``, ``width`` (the
    distinct misses in one vectorized call): every closed-form bound of a pair (its shortest contact, its
    largest sigma/dT, the efficiency route's readings) is a cheap function of it.

    >>> from designkit.sensor import load_sensor
    >>> s = load_sensor("paper")
    >>> float(pair_critical_noise(s, 20000.0, 35000.0)) == float(critical_noise(s, 20000.0, 35000.0))
    True
    """
    def compute(a, b, w):
        return critical_noise(sensor, a, b, width=w, threshold=threshold)
    return _cached("critical-noise", sensor, (lo, hi, width), (float(threshold),), compute)


@functools.lru_cache(maxsize=8)
def _sample_logs(tau_s: float, rate_hz: float, n_max: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The sample counts ``0 .. n_max``, ``log(n / fs)`` and ``0.5 log(cum[n])`` (:func:`cumulative_g2`) at each,
    read-only, once per sensor: what :func:`noise_k_contact` compares at every count."""
    counts = np.arange(n_max + 1)
    with np.errstate(divide="ignore"):  # (count 0: no signal yet, log 0)
        log_t, half_log_cum = np.log(counts / rate_hz), 0.5 * np.log(cumulative_g2(tau_s, rate_hz, n_max))
    for a in (counts, log_t, half_log_cum):
        a.flags.writeable = False
    return counts, log_t, half_log_cum


@np.errstate(divide="ignore", invalid="ignore")  # (one context for the whole computation)
def noise_k_contact(sensor, ratio, s_star, t_a, t_b, log_k_a, log_k_b, max_contact_s: float) -> np.ndarray:
    """First sample time [s] at which a classifier of noise efficiency ``k(t)`` separates a pair whose ideal
    observer needs projection noise at most ``s_star``: ``k(t) (sigma/dT) / |g(t)| <= s_star``, ``log k``
    linear in ``log t`` through ``(t_a, log_k_a)``, ``(t_b, log_k_b)`` (extrapolated beyond them, never
    below 0: no classifier beats the ideal observer), vectorized; NaN where no contact up to
    ``max_contact_s`` suffices. Pure numpy over the sample counts (no quadrature).

    >>> from designkit.sensor import load_sensor
    >>> s = load_sensor("paper")
    >>> star = critical_noise(s, 20000.0, 35000.0)
    >>> t1 = float(noise_k_contact(s, 0.005, star, 1.0, 2.0, 0.0, 0.0, 10.0))
    >>> abs(t1 - float(exact_ideal_min_contact(s, 20000.0, 35000.0, 0.005))) <= 0.005
    True
    >>> float(noise_k_contact(s, 0.005, star, 1.0, 2.0, 0.4, 0.5, 10.0)) > t1
    True
    """
    shapes = {x.shape if type(x) is np.ndarray else np.shape(x) for x in (ratio, s_star, t_a, t_b, log_k_a, log_k_b)}
    shape = shapes.pop() if len(shapes) == 1 else np.broadcast_shapes(*shapes)
    ratio, s_star, t_a, t_b, ka, kb = (c.ravel() for c in columns(ratio, s_star, t_a, t_b, log_k_a, log_k_b))
    fs = float(sensor.sample_rate_hz)
    n_max = int(last_sample_index(max_contact_s, fs))
    counts, log_t, half_log_cum = _sample_logs(float(sensor.tau_s), fs, max(n_max, 1))
    slope = np.where(t_a != t_b, (kb - ka) / np.log(t_b / t_a), 0.0)
    log_ta, log_r, log_s = np.log(t_a), np.log(ratio), np.log(s_star)

    def ok(n, rows):  # the classifier separates the pair at sample count n (an array, per element of rows)
        log_k = np.maximum(ka[rows] + slope[rows] * (log_t[n] - log_ta[rows]), 0.0)
        return log_k + log_r[rows] - half_log_cum[n] <= log_s[rows]

    out = np.empty(ratio.shape)
    out.fill(np.nan)
    # The response shape g rises with time, so cum[n] <= n g(n)^2 and cum[n+1] / cum[n] >= (n+1) / n: the
    # noise falls at least like n^-1/2, and where log k rises no faster than 0.5 per unit of log t the
    # decision is monotone in n and a bisection finds its first sample. Steeper k (not seen on svm-paper,
    # whose k rises 0.29 per log t) is decided at every sample: (pairs x samples) arrays, 10x the time.
    # a few elements: the scan's one pass over 2,000 samples beats a bisection's dozen small calls (same answers)
    if ratio.size <= 64:
        steep, mono = slice(None), np.zeros(0, dtype=np.int64)
    else:
        scan = ~(slope <= 0.5)
        steep, mono = np.nonzero(scan)[0], np.nonzero(~scan)[0]
    if ratio[steep].size:
        n = counts[1:n_max + 1]
        good = (np.maximum(ka[steep, None] + slope[steep, None] * (log_t[None, 1:n_max + 1] - log_ta[steep, None]),
                           0.0) + log_r[steep, None] - half_log_cum[None, 1:n_max + 1] <= log_s[steep, None])
        first = good.argmax(axis=1)  # (0 where none is good)
        out[steep] = np.where(good[np.arange(first.size), first], n[first] / fs, np.nan)
    if mono.size:
        top = ok(np.full(mono.size, max(n_max, 1)), mono)
        rows = mono[top]
        # n = 0 (the sample at contact) carries no signal (cum[0] = 0): the first good sample is >= 1
        b = _first_good_sample(lambda n, r: ok(n, rows[r]), np.zeros(rows.size, dtype=np.int64),
                               np.full(rows.size, max(n_max, 1), dtype=np.int64))
        out[rows] = b / fs
    return out.reshape(shape)
