"""The ideal observer's shortest contact where it has no closed form: a Monte Carlo estimate with its interval.

With the sensor temperature drawn per touch (varied initial conditions) or a
forward model whose curves differ in shape per object, the ideal observer's F1
has no closed form; :func:`designkit.recognition.ideal.ideal_pair` estimates
it from simulated touches scored by the exact likelihood ratio, with a Monte
Carlo standard error. Its shortest contact is then the crossing of the
threshold by a noisy monotone curve, the problem
:func:`designkit.query.crossing.estimate_crossing` solves for the SVM: coarse
bisection in log contact time, a logistic fit in log time on a few points
around the crossing, and a delta-method interval at the stated coverage.

Each evaluation draws its own touches (a seed derived from the asked seed and
the contact time), so the evaluations' errors are independent, as the fit
assumes. The interval covers the crossing of the *mean* ideal F1 curve (the
bound with infinitely many touches); ``benchmarks/bench_ideal_mc_bound.py``
measures how often it does against a reference with 16x the touches.

The ideal observer's F1 changes only at sample times, so the curve is evaluated
at sample times and the crossing, like the closed form's
(:func:`designkit.query.ideal_bound.exact_ideal_min_contact`), is reported as
the first sample time at or after the estimate; the interval's ends likewise.

Computed at query time, never read from a table grid (issue 13): about ten
evaluations of ``n_mc`` touches per class, 0.5-2 s at the defaults.
"""

from __future__ import annotations

import math
import struct
import zlib
from dataclasses import dataclass

from cachetools import LRUCache

from ..objects import ObjectClass
from ..scene import Scene
from ..sensor import Sensor
from .answer import ideal_floor
from .crossing import check_coverage, estimate_crossing

__all__ = ["MC_BOUND_TOUCHES", "MonteCarloBound", "mc_ideal_delta", "mc_ideal_max_ratio", "mc_ideal_min_contact",
           "nearer_side_interval", "remembered"]

#: Bisection stops at a bracket this wide (ratio) before the fit: the ideal F1's logit bends in log time, and a
#: fit across the SVM route's 1.6 put its crossing about 1 % early (several SEs at these touch counts).
BRACKET_RATIO = 1.08

#: Touches per class per evaluation of the table route's Monte Carlo bound (SE of F1 about 0.004 near 0.9).
MC_BOUND_TOUCHES = 4000


@dataclass(frozen=True)
class MonteCarloBound:
    """The ideal observer's shortest contact [s] estimated by Monte Carlo.

    Attributes
    ----------
    value : float or None
        Estimate of the shortest contact [s] (:func:`mc_ideal_min_contact`) or the smallest effusivity
        difference [J s^-1/2 K^-1 m^-2] (:func:`mc_ideal_delta`) at which the ideal observer's mean F1
        reaches the threshold; None when it does not within the range examined.
    low, high : float or None
        Its interval at ``coverage`` (None: open on that side, or no stated interval).
    coverage : float or None
        Nominal coverage of ``(low, high)``; None where the points did not support the fit (the interval is
        then the bisection bracket).
    n_mc : int
        Touches per class per evaluation.
    evaluations : tuple of dict
        ``{"contact_s" or "delta_e", "f1", "standard_error", "method"}`` per evaluated point (``method`` as
        :class:`designkit.recognition.scores.IdealResult`'s: a model whose extra physics is invisible at a
        contact time is scored in closed form there).
    """

    value: float | None
    low: float | None
    high: float | None
    coverage: float | None
    n_mc: int
    evaluations: tuple = ()

    @property
    def interval(self) -> tuple | None:
        """``(low, high, coverage)``, as :class:`~designkit.query.answer.IdealBound` takes it; None where no
        coverage is stated."""
        return None if self.coverage is None else (self.low, self.high, self.coverage)

    @property
    def floor(self) -> float | None:
        """What no classifier beats at the bound's stated confidence: the interval's low end, or the estimate
        where no interval is stated (:func:`ideal_floor`)."""
        return ideal_floor(self.value, self.interval)

    def to_dict(self) -> dict:
        return {"value": self.value, "low": self.low, "high": self.high, "coverage": self.coverage,
                "n_mc": self.n_mc, "evaluations": [dict(e) for e in self.evaluations]}


def _point_seed(seed: int, x: float) -> list[int]:
    """The seed of one evaluation: the asked seed and a stable 31-bit hash of the evaluated point's bits."""
    return [int(seed), zlib.crc32(struct.pack("<d", float(x))) & 0x7FFFFFFF]


def _estimate(score, name: str, x_lo: float, x_hi: float, threshold: float, *, seed: int, coverage: float,
              progress=None, increasing: bool = True, snap=None):
    """The crossing of the mean ideal F1 along one quantity (``name``: its key in each evaluation record):
    ``score(x, seed)`` is the :class:`~designkit.recognition.scores.IdealResult` at ``x`` with that seed
    (:func:`_point_seed`: independent touches per point), ``x`` first moved by ``snap`` where given.
    Returns ``(estimate, evaluations sorted by x)``."""
    evals: list[dict] = []

    def f(x: float) -> tuple[float, float]:
        x = snap(x) if snap is not None else x
        r = score(x, _point_seed(seed, x))
        evals.append({name: x, "f1": r.f1, "standard_error": r.standard_error, "method": r.method})
        return r.f1, r.standard_error

    # the straight line: over this narrow bracket the bend is small, and the curvature term overfitted its
    # precise points (a delta interval 3.8 wide 10 from the closed form, tests/test_ideal_mc_bound.py)
    est = estimate_crossing(f, float(x_lo), float(x_hi), threshold, increasing=increasing, coverage=coverage,
                            progress=progress, bracket_ratio=BRACKET_RATIO, curvature=False)
    return est, tuple(sorted(evals, key=lambda e: e[name]))


def mc_ideal_min_contact(a: ObjectClass, b: ObjectClass, sensor: Sensor, *, noise_c: float, delta_t_c: float,
                         sensor_temp_spread_c: float = 0.0, model=None, threshold: float = 0.9,
                         max_contact_s: float = 10.0, n_mc: int = MC_BOUND_TOUCHES, seed: int = 0,
                         coverage: float = 0.9, progress=None) -> MonteCarloBound:
    """Shortest contact [s] at which the ideal observer separates ``a`` from ``b``, by Monte Carlo.

    Parameters
    ----------
    a, b : ObjectClass
        The two classes (effusivity ranges [J s^-1/2 K^-1 m^-2]).
    sensor : Sensor
    noise_c : float
        Noise sigma per sample [degC].
    delta_t_c : float
        Sensor minus object temperature before contact [degC] (the middle of the drawn range).
    sensor_temp_spread_c : float
        Half-width [degC] of the uniform per-touch sensor temperature (0: fixed).
    model : ForwardModel or name, optional
        Forward model (default: the paper's).
    threshold : float
        F1 threshold Phi.
    max_contact_s : float
        Longest contact examined [s].
    n_mc : int
        Touches per class per evaluation.
    seed : int
        Seed; each evaluation derives its own from it and the contact time.
    coverage : float
        Nominal coverage of the interval, in (0, 1).
    progress : callable, optional
        ``progress(done, total, message)``.

    Returns
    -------
    MonteCarloBound

    Examples
    --------
    >>> from designkit import SENSORS
    >>> from designkit.objects import ObjectClass
    >>> r = mc_ideal_min_contact(ObjectClass("a", (35000, 35080)), ObjectClass("b", (20000, 20080)),
    ...                          SENSORS["paper"], noise_c=0.05, delta_t_c=7.5, sensor_temp_spread_c=2.5,
    ...                          n_mc=1000)
    >>> r.low < r.value < r.high, 1.0 < r.value < 1.6, r.coverage
    (True, True, 0.9)
    """
    from ..recognition.ideal import ideal_pair
    from ..rig import question_scene

    cov = check_coverage(coverage)
    fs = float(sensor.sample_rate_hz)

    def score(c, point_seed):
        scene = question_scene(sensor, contact_s=c, noise_c=noise_c, delta_t_c=delta_t_c,
                       sensor_temp_spread_c=sensor_temp_spread_c)
        return ideal_pair(a, b, sensor, scene, model=model, n_mc=n_mc, seed=point_seed)

    # evaluated at sample times: the curve through those is smooth
    est, evs = _estimate(score, "contact_s", 1.0 / fs, max_contact_s, threshold, seed=seed, coverage=cov,
                         progress=progress, snap=lambda c: max(1, round(c * fs)) / fs)
    if est.value is None:
        return MonteCarloBound(None, None, None, None, int(n_mc), evs)

    def first_sample(x):  # the first sample time at or after x: the ideal F1 changes only at samples
        return None if x is None else max(1, math.ceil(x * fs - 1e-9)) / fs

    return MonteCarloBound(first_sample(est.value), first_sample(est.low), first_sample(est.high),
                           cov if est.stated else None, int(n_mc), evs)


def mc_ideal_delta(ref: ObjectClass, direction: int, sensor: Sensor, *, contact_s: float, noise_c: float,
                   delta_t_c: float, sensor_temp_spread_c: float = 0.0, model=None, threshold: float = 0.9,
                   e_max: float = 40000.0, n_mc: int = MC_BOUND_TOUCHES, seed: int = 0,
                   coverage: float = 0.9, progress=None) -> MonteCarloBound:
    """The ideal observer's delta(e) [J s^-1/2 K^-1 m^-2] of one direction, by Monte Carlo.

    The reference is ``ref`` (``[e, e + w)``), partners ``[e +- d, e +- d + w)`` with its diffusivity range,
    as :func:`designkit.query.exact.exact_delta_e`; the mean ideal F1 rises with ``d`` and its crossing of
    the threshold is estimated in log ``d`` (:func:`designkit.query.crossing.estimate_crossing`) over
    ``[w / 2, limit]``, ``limit`` the farthest partner inside ``(0, e_max]``.

    Parameters
    ----------
    ref : ObjectClass
        The reference class.
    direction : {+1, -1}
        Towards higher or lower effusivity.
    sensor : Sensor
    contact_s, noise_c, delta_t_c, sensor_temp_spread_c
        The scene: contact [s], noise sigma [degC], sensor minus object temperature [degC], half-width of
        the per-touch sensor temperature [degC].
    model, threshold, n_mc, seed, coverage, progress
        As :func:`mc_ideal_min_contact`.
    e_max : float
        Largest effusivity a partner may reach [J s^-1/2 K^-1 m^-2].

    Returns
    -------
    MonteCarloBound
        ``value`` None where no partner within the range is separated.

    Examples
    --------
    >>> from designkit import SENSORS
    >>> r = mc_ideal_delta(ObjectClass("ref", (20000.0, 20080.0)), +1, SENSORS["paper"], contact_s=2.0,
    ...                    noise_c=0.05, delta_t_c=7.5, sensor_temp_spread_c=2.5, n_mc=1000)
    >>> r.low < r.value < r.high, 3000 < r.value < 12000
    (True, True)
    """
    from ..recognition.ideal import ideal_pair
    from ..rig import question_scene

    cov = check_coverage(coverage)
    x, w = ref.e_range[0], ref.e_range[1] - ref.e_range[0]
    w = w if w > 0 else 80.0
    sign = 1 if direction > 0 else -1
    limit = (e_max - x - w) if sign > 0 else (x - w)
    if limit < w:
        return MonteCarloBound(None, None, None, None, int(n_mc), ())
    scene = question_scene(sensor, contact_s=contact_s, noise_c=noise_c, delta_t_c=delta_t_c,
                   sensor_temp_spread_c=sensor_temp_spread_c)

    def score(d, point_seed):
        lo = x + sign * d
        part = ObjectClass(f"{lo:g}", (lo, lo + w), ref.diffusivity_range_m2_s)
        return ideal_pair(ref, part, sensor, scene, model=model, n_mc=n_mc, seed=point_seed)

    est, evs = _estimate(score, "delta_e", w / 2.0, limit, threshold, seed=seed, coverage=cov, progress=progress)
    if est.value is None:
        return MonteCarloBound(None, None, None, None, int(n_mc), evs)
    return MonteCarloBound(est.value, est.low, est.high, cov if est.stated else None, int(n_mc), evs)


def mc_ideal_max_ratio(a: ObjectClass, b: ObjectClass, sensor: Sensor, scene_of, ratio_lo: float, ratio_hi: float,
                       *, model=None, threshold: float = 0.9, n_mc: int = MC_BOUND_TOUCHES, seed: int = 0,
                       coverage: float = 0.9, progress=None) -> MonteCarloBound:
    """The largest sigma/dT [-] at which the ideal observer separates ``a`` from ``b``, by Monte Carlo.

    ``scene_of(ratio)`` is the scene at a noise ratio (with varied initial conditions sigma and dT are no
    longer interchangeable, so the caller says which one moves: max-noise moves sigma at the asked dT,
    min-delta-t moves dT at the asked sigma). The mean ideal F1 falls with the ratio; its crossing is
    estimated in log ratio on ``[ratio_lo, ratio_hi]`` like :func:`mc_ideal_min_contact`'s (no rounding:
    the ratio is continuous).

    Returns
    -------
    MonteCarloBound
        ``value`` None where even ``ratio_lo`` does not separate them; ``ratio_hi`` (and ``high`` None)
        where even ``ratio_hi`` does.

    Examples
    --------
    >>> from designkit import SENSORS, Scene
    >>> scene_of = lambda r: Scene.from_delta_t(contact_s=2.0, noise_c=r * 7.5, delta_t_c=7.5,
    ...                                         sensor_temp_spread_c=2.5)
    >>> r = mc_ideal_max_ratio(ObjectClass("a", (20000.0, 20080.0)), ObjectClass("b", (35000.0, 35080.0)),
    ...                        SENSORS["paper"], scene_of, 1e-4, 1.0, n_mc=1000)
    >>> r.low < r.value < r.high, 0.005 < r.value < 0.05
    (True, True)
    """
    from ..recognition.ideal import ideal_pair

    cov = check_coverage(coverage)
    est, evs = _estimate(lambda r, point_seed: ideal_pair(a, b, sensor, scene_of(r), model=model, n_mc=n_mc,
                                                          seed=point_seed),
                         "noise_ratio", ratio_lo, ratio_hi, threshold, seed=seed, coverage=cov, progress=progress,
                         increasing=False)
    return MonteCarloBound(est.value, est.low, est.high, cov if est.stated else None, int(n_mc), evs)


def nearer_side_interval(sides: dict, coverage: float):
    """delta-e's bound interval: ``(low, high, coverage)`` of the nearer direction's Monte Carlo bound (each
    side a dict with ``ideal`` and ``ideal_interval``), None where that direction has none."""
    best = min((s for s in sides.values() if s.get("ideal") is not None), key=lambda s: s["ideal"], default=None)
    if best is None or best.get("ideal_interval") is None:
        return None
    return (*best["ideal_interval"], coverage)


#: Most distinct questions :func:`remembered` keeps per process.
_CACHE_SIZE = 64
_CACHE: "LRUCache[tuple, MonteCarloBound]" = LRUCache(_CACHE_SIZE)


def remembered(fn, *args, **kwargs) -> MonteCarloBound:
    """``fn(*args, **kwargs)`` (:func:`mc_ideal_min_contact`, :func:`mc_ideal_delta`), remembered per process for
    the last :data:`_CACHE_SIZE` distinct questions: a repeated question, as a table route asks it, costs
    nothing the second time (the answer is a function of the question and the seed, so remembering changes
    nothing). The question is its arguments with the defaults filled in, the classes by their ranges, the
    sensor and the forward model by their content."""
    import inspect

    bound = inspect.signature(fn).bind(*args, **kwargs)
    bound.apply_defaults()
    key = (fn.__name__, *((k, _content(k, v)) for k, v in bound.arguments.items()))
    r = _CACHE.get(key)
    if r is None:
        r = _CACHE[key] = fn(*args, **kwargs)
    return r


def _content(name: str, value):
    """What identifies an argument of a Monte Carlo bound's question in :func:`remembered`'s key."""
    if name == "model":
        from ..models import get_model

        return repr(get_model(value).to_dict())
    if isinstance(value, ObjectClass):
        return value.e_range, value.diffusivity_range_m2_s
    if isinstance(value, Sensor):
        return repr(value.to_dict())
    return value
