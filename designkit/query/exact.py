"""The exact route: a design question computed for one pair and scene, under any forward model.

The SVM's answer comes from simulated touches (:func:`designkit.recognition.svm.pair_f1`,
``repeats`` seeds per evaluation, the model through the seam). min-contact,
max-noise, min-delta-t and each direction of delta-e are estimates of where the
noisy monotone mean F1 crosses the threshold, with a confidence interval at the
asked ``coverage`` (:mod:`designkit.query.crossing`); distinguishable states the
mean F1 with its ``coverage`` interval.

The ideal observer's bound: for a shared-shape model (the paper's) the
vectorized closed-form answers of :mod:`designkit.query.ideal_bound`; for
any other model a bisection on :func:`designkit.recognition.ideal.ideal_pair`,
which is closed form where the model's extra physics is invisible and Monte
Carlo on the exact likelihood otherwise (``n_mc`` touches per class).

Readings depend on sigma and dT only through sigma/dT (standardized features,
fixed initial conditions, every model linear in the temperatures), so
``max-noise`` and ``min-delta-t`` are one search over sigma/dT.

Every answer carries the model's :meth:`~designkit.models.ForwardModel.check`
at the scene the answer names.

Examples
--------
>>> a = exact_distinguishable(35000, 20000, contact_s=2.0, trials=30, repeats=1, jobs=1)
>>> a.route, a.value, a.ideal_bound.method
('exact', True, 'closed-form')
"""

from __future__ import annotations

import math
import time
from contextlib import nullcontext
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from .._validation import InputError, check_positive, check_repeats
from ..objects import DEFAULT_CLASS_WIDTH, ObjectClass
from .answer import Answer, IdealBound, ideal_floor, number, scene_record
from .inputs import (
    REFERENCE_RULE,
    check_contact,
    check_threshold,
    pair_question,
    reference_class,
    scene_inputs,
)

__all__ = [
    "RATIO_BRACKET",
    "SOLVERS",
    "bisect",
    "exact_delta_e",
    "exact_distinguishable",
    "exact_max_noise",
    "exact_min_contact",
    "exact_min_delta_t",
]

#: SVM solvers of the exact route: scikit-learn one seed at a time (the reference), or every seed's
#: cross-validation at once (:mod:`designkit.recognition.batched_svm`, the same classifier).
SOLVERS = ("sklearn", "batched")

#: sigma/dT searched by max-noise and min-delta-t: 10 uK per K up to noise as large as the contrast.
RATIO_BRACKET = (1e-5, 1.0)


# ============================================================ search routines
def bisect(f_ok: Callable[[float], bool], lo: float, hi: float, tol: float, *, log: bool = False) -> float:
    """Smallest x in (lo, hi] with ``f_ok(x)`` (monotone), to ``tol`` (relative if ``log``).

    >>> round(bisect(lambda x: x >= 0.3, 0.0, 1.0, 1e-6), 5)
    0.3
    """
    for _ in range(60):
        if (math.log(hi / lo) if log else hi - lo) <= tol:
            break
        mid = math.sqrt(lo * hi) if log else 0.5 * (lo + hi)
        if f_ok(mid):
            hi = mid
        else:
            lo = mid
    return hi


# ============================================================ one question's computation
@dataclass
class _Run:
    """The sensor, model and Monte Carlo settings of one exact question, and its ideal-observer log."""

    sensor: Any
    model: Any
    phi: float
    width: float
    trials: int
    folds: int
    seed: int
    repeats: int
    z: float
    jobs: int
    n_mc: int
    solver: str = "sklearn"
    spread: float = 0.0
    t0: float = field(default_factory=time.perf_counter)
    ideal_calls: list = field(default_factory=list)
    svm_calls: int = 0
    pool_started: bool = False  # the worker pool was started for this run (designkit._workers.local_processes)

    @classmethod
    def make(cls, *, sensor, model, threshold, width, trials, folds, seed, repeats, z, jobs, n_mc,
             solver="sklearn", sensor_temp_spread_c=0.0) -> "_Run":
        from ..models import get_model
        from ..sensor import load_sensor

        if int(folds) < 2:
            raise InputError(f"folds must be >= 2, got {folds}")
        if int(trials) < int(folds):
            raise InputError(f"trials per class ({trials}) must be at least the number of folds ({folds})")
        repeats = check_repeats("repeats", repeats)
        if int(n_mc) < 10:
            raise InputError(f"the Monte Carlo ideal observer needs at least 10 touches per class, got {n_mc}")
        if solver not in SOLVERS:
            raise InputError(f"unknown solver {solver!r}; known: {', '.join(SOLVERS)}")
        from .._validation import check_nonnegative
        from .._workers import worker_count
        from ..models import sensor_model

        spread = check_nonnegative("sensor temperature spread [degC]", sensor_temp_spread_c)
        sen = load_sensor(sensor if sensor is not None else "paper")
        return cls(sen, sensor_model(sen) if model is None else get_model(model),  # a sensor file's own model
                   check_threshold(threshold), check_positive("class width", width), int(trials), int(folds),
                   int(seed), repeats, check_positive("z", z), worker_count(jobs), int(n_mc), solver, spread)

    # ---------------------------------------------------------------- the SVM
    def seeds(self) -> list[list[int]]:
        """The ``repeats`` seeds of the next SVM evaluation: ``[seed, r, k]`` for the question's k-th evaluation.

        Every evaluation draws fresh touches. Common random numbers (the same ``[seed, r]`` at every
        point) made the F1 errors of a crossing's design points correlated (0.7-0.9 between
        neighbours on the sigma/dT and delta-e axes, measured), which the crossing fit, assuming
        independent points, turned into intervals about half as wide as the real spread
        (issue 13: 54-62 % coverage of 90 % intervals).

        >>> run = _Run.make(sensor=None, model=None, threshold=0.9, width=80, trials=10, folds=2, seed=5,
        ...                 repeats=2, z=2, jobs=1, n_mc=10)
        >>> run.seeds(), run.seeds()
        ([[5, 0, 0], [5, 1, 0]], [[5, 0, 1], [5, 1, 1]])
        """
        k, self.svm_calls = self.svm_calls, self.svm_calls + 1
        return [[self.seed, r, k] for r in range(self.repeats)]

    def svm(self, classes, scene):
        """Each of ``repeats`` seeds' SVM F1 with its own (cross-validation) standard error, for the pair's
        classes (fresh seeds at every call, :meth:`seeds`): a :class:`~designkit.query.crossing.SeedDraws`,
        whose error the crossing estimate pools over its evaluations."""
        from joblib import Parallel, delayed

        from .._workers import local_processes
        from ..recognition.svm import pair_f1

        a, b = classes
        if self.solver == "batched":
            return self._svm_batched(a, b, scene)
        jobs = self.jobs if self.repeats > 1 else 1
        with local_processes(jobs, start=not self.pool_started) if jobs != 1 else nullcontext():
            self.pool_started = jobs != 1
            results = Parallel(n_jobs=jobs)(
                delayed(pair_f1)(a, b, self.sensor, scene, model=self.model, trials=self.trials, folds=self.folds,
                                 seed=s) for s in self.seeds())
        from .crossing import SeedDraws

        return SeedDraws([r.f1 for r in results], [r.standard_error for r in results])

    def _svm_batched(self, a, b, scene):
        """:meth:`svm` with every seed's cross-validation solved at once (same touches, folds and
        classifier as :func:`~designkit.recognition.svm.pair_f1`; predictions can differ only at
        near-ties, :mod:`designkit.recognition.batched_svm`)."""
        from ..objects import ordered_pair
        from ..recognition.batched_svm import batched_cv_f1
        from ..recognition.features import feature_matrix
        from ..simulation import simulate_class

        low, high = ordered_pair(a, b)
        fs = self.sensor.sample_rate_hz
        lo, hi, seeds = [], [], []
        for base in self.seeds():
            lo.append(feature_matrix(simulate_class(low, self.trials, self.sensor, scene, base + [0],
                                                    self.model).temperature_c, fs))
            hi.append(feature_matrix(simulate_class(high, self.trials, self.sensor, scene, base + [1],
                                                    self.model).temperature_c, fs))
            seeds.append(base + [2])
        from .crossing import SeedDraws

        res = batched_cv_f1(lo, hi, seeds=seeds, folds=self.folds)
        return SeedDraws(np.asarray(res.f1, dtype=np.float64), np.asarray(res.standard_error, dtype=np.float64))

    # ---------------------------------------------------------------- the ideal observer
    def scene(self, contact_s: float, noise_c: float, delta_t_c: float):
        """The scene of one evaluation: Ts0 = Ta + dT (Ta 25 degC), drawn per touch uniformly within
        +-``spread`` degC of it when the question has a sensor temperature spread (varied initial conditions);
        for a calibrated rig, its correlated noise and its recorder's window from the detected onset
        (:func:`designkit.rig.rig_scene`)."""
        from ..rig import question_scene

        return question_scene(self.sensor, contact_s=contact_s, noise_c=noise_c, delta_t_c=delta_t_c,
                              sensor_temp_spread_c=self.spread)

    def closed_form(self, *classes: ObjectClass) -> bool:
        """Whether the vectorized closed form answers (shared shape, fixed initial conditions, every class
        ``width`` wide); varied initial conditions take the Monte Carlo ideal observer."""
        from ..rig import rig_scene

        return self.spread == 0 and self.model.shared_shape and not any(rig_scene(self.sensor).values()) and all(
            math.isclose(c.e_range[1] - c.e_range[0], self.width, rel_tol=1e-9) for c in classes)

    def ideal_f1(self, classes, scene) -> float:
        """Ideal F1 of the pair (closed form or Monte Carlo, :func:`designkit.recognition.ideal.ideal_pair`)."""
        from ..recognition.ideal import ideal_pair

        r = ideal_pair(classes[0], classes[1], self.sensor, scene, model=self.model, n_mc=self.n_mc,
                       seed=self.seed)
        self.ideal_calls.append({"contact_s": scene.contact_s, "noise_ratio": scene.noise_ratio, "f1": r.f1,
                                 "standard_error": r.standard_error, "method": r.method})
        return r.f1

    def ideal_method_at(self, classes, scene) -> str:
        """How :meth:`ideal_f1` would score this scene (``"closed-form"`` or ``"monte-carlo"``), without
        scoring it (:func:`designkit.recognition.ideal.ideal_method`)."""
        from ..recognition.ideal import ideal_method

        return ideal_method(classes[0], classes[1], self.sensor, scene, model=self.model)

    def ideal_method(self, closed: bool) -> str:
        if closed:
            return "closed-form"
        methods = sorted({c["method"] for c in self.ideal_calls})
        return "+".join(methods) if methods else "none"

    # ---------------------------------------------------------------- the answer
    def answer(self, question: str, *, value, interval, ideal, ideal_method: str, objects, limiting, rule: str,
               scene: dict, details: dict, check_classes, check_at, notes=(), interval_coverage=None,
               interval_kind=None, ideal_interval=None, **computation) -> Answer:
        check = None
        if check_classes:
            c, n, d = check_at
            check = self.model.check(tuple(check_classes), self.sensor, contact_s=c, noise_c=n,
                                     delta_t_c=d).to_dict()
        comp = {"fidelity": "svm", "trials": self.trials, "folds": self.folds, "repeats": self.repeats,
                "seed": self.seed, "z": self.z, "n_mc": self.n_mc, "width": self.width,
                "sensor_temp_spread_c": self.spread, "solver": self.solver, **computation,
                "ideal_evaluations": list(self.ideal_calls), "wall_s": time.perf_counter() - self.t0}
        return Answer(
            question=question, route="exact", value=value, interval=tuple(interval),
            ideal_bound=IdealBound(ideal if isinstance(ideal, bool) else number(ideal),
                                   ideal_method if ideal is not None else "none",
                                   ideal_interval if ideal is not None else None),
            objects=tuple(objects), limiting_pair=tuple(limiting), materials_rule=rule, scene=scene,
            sensor=self.sensor.to_dict(), model=self.model.to_dict(), model_check=check, threshold=self.phi,
            details=details, computation=comp, notes=tuple(n for n in notes if n),
            interval_coverage=interval_coverage, interval_kind=interval_kind)


def _make(kw: dict) -> _Run:
    return _Run.make(**{k: kw[k] for k in ("sensor", "model", "threshold", "width", "trials", "folds", "seed",
                                           "repeats", "z", "jobs", "n_mc")}, solver=kw.get("solver", "sklearn"),
                     sensor_temp_spread_c=kw.get("sensor_temp_spread_c", 0.0))


def _check_spread(spread: float, dt: float) -> None:
    """A sensor temperature spread must leave dT on one side of zero in every touch."""
    if spread and spread >= abs(dt):
        raise InputError(f"a sensor temperature spread of {spread:g} degC around dT {dt:g} degC makes the "
                         "sensor-object temperature difference cross zero; give a spread below |dT|")


def _evaluations(est, axis: str) -> list[dict]:
    """A crossing estimate's evaluations as an answer records them: ``axis`` (the asked quantity), the mean F1,
    the standard error the fit used and the seeds' own F1 and errors (``per_seed``, from which a replay refits)."""
    return [{axis: e["x"], "svm_f1": e["svm_f1"], "standard_error": e["standard_error"],
             **({"per_seed": e["per_seed"]} if "per_seed" in e else {})} for e in est.evaluations]


def _error_model(est) -> dict:
    """The pooled error model of a crossing estimate (:func:`designkit.query.crossing.pooled_seed_scale`):
    ``seed_spread_scale`` (how far the seeds' F1 scatter in units of their own errors) and ``error_dof``."""
    return {"seed_spread_scale": est.seed_spread_scale, "error_dof": est.error_dof}


def _no_pair(question, run: _Run, pq, scene, details) -> Answer:
    return run.answer(question, value=None, interval=(None, None), ideal=None, ideal_method="none",
                      objects=pq.objects_dicts(), limiting=(), rule=pq.rule, scene=scene, details=details,
                      check_classes=(), check_at=None, notes=[pq.note])


# ============================================================ min-contact
def exact_min_contact(e1=None, e2=None, *, m1=None, m2=None, objects=None, noise_c: float = 0.05,
                      delta_t_c: float = 10.0, threshold: float = 0.9, sensor=None, model=None,
                      diffusivity_m2_s=None, width: float = DEFAULT_CLASS_WIDTH, trials: int = 100, folds: int = 3,
                      seed: int = 0, repeats: int = 4, z: float = 2.0, jobs: int = -1, n_mc: int = 1000,
                      max_contact_s: float = 10.0, tolerance_s: float = 0.05, coverage: float = 0.9,
                      progress=None, solver: str = "sklearn",
                      sensor_temp_spread_c: float = 0.0) -> Answer:
    """Shortest contact time [s] computed for this pair: an estimate of where the SVM's mean F1 crosses Phi.

    The crossing of the noisy monotone F1 curve is estimated by a logistic fit in
    log(contact), with a curvature term, near it (:func:`designkit.query.crossing.estimate_crossing`),
    with a confidence interval at ``coverage``, clipped below at the exact
    ideal-observer bound (no classifier needs less contact).

    Parameters
    ----------
    e1, e2, m1, m2, objects
        The objects (:func:`designkit.query.inputs.pair_question`; materials by its rule).
    noise_c, delta_t_c : float
        Noise sigma [degC] and sensor minus object temperature [degC].
    threshold : float
        F1 threshold Phi.
    sensor : name, path or Sensor, optional
        Default the paper's.
    model : ForwardModel, name or dict, optional
        Forward model of the touches (default the paper's semi-infinite).
    diffusivity_m2_s : float, optional
        Diffusivity [m^2 s^-1] of objects given as numbers (models that need it).
    width : float
        Class width [J s^-1/2 K^-1 m^-2].
    trials, folds, seed, repeats, z, jobs
        Touches per class, cross-validation folds, seed, seeds per evaluation,
        interval width in standard errors, worker processes (-1: all cores).
    n_mc : int
        Touches per class of the Monte Carlo ideal observer (models without a shared shape).
    max_contact_s, tolerance_s : float
        Longest contact examined [s]; ``tolerance_s`` is kept for callers (the estimate replaces bisection).
    coverage : float
        Nominal coverage of the interval, in (0, 1).
    progress : callable, optional
        ``progress(done, total, message)`` after each SVM evaluation.
    solver : {"sklearn", "batched"}
        :data:`SOLVERS`: scikit-learn seed by seed, or all seeds at once (faster, same classifier).
    sensor_temp_spread_c : float
        Varied initial conditions: each touch's sensor temperature is drawn uniformly within
        +-this [degC] of Ta + dT (the paper's robot: dT 7.5, spread 2.5, i.e. Ts0 in 30-35 degC
        with Ta 25 degC); 0 is fixed. Must stay below |dT|. The ideal bound is then Monte Carlo
        (``n_mc`` touches per class) with its standard error under ``computation``.
    """

    kw = dict(locals())
    noise, dt = scene_inputs(noise_c, delta_t_c)
    run = _make(kw)
    tmax = check_positive("maximum contact time [s]", max_contact_s)
    pq = pair_question(e1, e2, m1, m2, objects=objects, width=run.width, diffusivity_m2_s=diffusivity_m2_s,
                       model=run.model)
    scene_d = scene_record(None, noise, dt)
    if pq.classes is None:
        return _no_pair("min-contact", run, pq, scene_d, {})
    cls = pq.classes

    _check_spread(run.spread, dt)

    def scene(c):
        return run.scene(c, noise, dt)

    from .crossing import check_coverage, estimate_crossing

    cov = check_coverage(coverage)
    floor = 1.0 / run.sensor.sample_rate_hz
    closed = run.closed_form(*cls)
    ideal_interval = None
    if closed:
        from .ideal_bound import exact_ideal_min_contact

        ideal = number(exact_ideal_min_contact(run.sensor, cls[0].e_range[0], cls[1].e_range[0],
                                               noise / abs(dt), width=run.width, threshold=run.phi,
                                               max_contact_s=tmax))
    elif run.ideal_method_at(cls, scene(tmax)) == "closed-form":
        # a model whose extra physics is invisible in this scene: the closed form along the search
        ideal_ok = lambda c: run.ideal_f1(cls, scene(c)) >= run.phi  # noqa: E731
        ideal = bisect(ideal_ok, floor, tmax, min(0.01, tolerance_s)) if ideal_ok(tmax) else None
    else:  # Monte Carlo: the crossing of the ideal F1 estimated with its interval (ideal_mc_bound)
        from .ideal_mc_bound import mc_ideal_min_contact

        mcb = mc_ideal_min_contact(cls[0], cls[1], run.sensor, noise_c=noise, delta_t_c=dt,
                                   sensor_temp_spread_c=run.spread, model=run.model, threshold=run.phi,
                                   max_contact_s=tmax, n_mc=run.n_mc, seed=run.seed, coverage=cov)
        run.ideal_calls.extend(dict(e) for e in mcb.evaluations)
        ideal, ideal_interval = mcb.value, mcb.interval
    # the SVM needs at least the ideal observer's contact: search from there (from just below the longest
    # contact where the Monte Carlo bound's estimate reaches it: the search needs a range)
    start = min(max(floor, ideal if ideal is not None else floor), tmax / 1.0001)
    def svm_at(c):
        return run.svm(cls, scene(c))

    est = estimate_crossing(svm_at, start, tmax, run.phi, coverage=cov, progress=progress)
    falls = None
    if est.value is None and est.low is None and est.evaluations:
        # below Phi at the longest contact: the SVM's F1 need not rise for ever (with the sensor temperature
        # varied per touch its F1 peaks and falls again as the touch, and with it the feature vector, grows:
        # 0.977 at 4 s, 0.865 at 10 s for 35000 vs 20000 at 0.05 degC, dT 7.5 +- 2.5 degC), so look for a
        # shorter contact that separates them on a doubling ladder from the start, and estimate the first
        # crossing below it
        f_top = est.evaluations[-1]["svm_f1"]
        c = 2.0 * start
        while c < tmax:
            f_c = svm_at(c).mean
            if f_c >= run.phi:
                est = estimate_crossing(svm_at, start, c, run.phi, coverage=cov, progress=progress)
                falls = (c, f_c, tmax, f_top)
                break
            c *= 2.0
    value = est.value if est.value is None or ideal is None else max(est.value, ideal)
    # the SVM's interval never reaches below the ideal observer's (a Monte Carlo bound: its low end)
    floor = ideal_floor(ideal, ideal_interval)
    interval = (est.low if est.low is None or floor is None else max(est.low, floor), est.high)
    evaluations = _evaluations(est, "contact_s")
    needed = tmax if value is None else max(x for x in (value, ideal, interval[1]) if x is not None)
    note = "" if value is not None else f"not separable by any contact time up to {tmax:g} s"
    if falls is not None:
        note = (f"the SVM's F1 is not monotone in contact time here: {falls[1]:.3f} at {falls[0]:.3g} s but "
                f"{falls[3]:.3f} at {falls[2]:g} s; the answer is its first crossing")
    return run.answer("min-contact", value=value, interval=interval, ideal=ideal, ideal_interval=ideal_interval,
                      ideal_method=run.ideal_method(closed), objects=pq.objects_dicts(),
                      limiting=pq.limiting_dicts(), rule=pq.rule, scene=scene_d, details={}, check_classes=cls,
                      check_at=(needed, noise, dt), notes=[note], evaluations=evaluations, max_contact_s=tmax,
                      estimate_method=est.method, **_error_model(est),
                      interval_coverage=cov if est.stated else None,
                      interval_kind="exact-estimate" if est.stated else "exact")


# ============================================================ max-noise / min-delta-t
def _exact_ratio(question: str, kw: dict) -> Answer:
    from .crossing import check_coverage, estimate_crossing

    contact = check_contact(kw["contact_s"])
    if question == "max-noise":
        _, dt = scene_inputs(0.0, kw["delta_t_c"])
        scene_d = scene_record(contact, None, dt)
    else:
        noise, _ = scene_inputs(kw["noise_c"], 1.0)
        if noise == 0:
            raise InputError("noise sigma is 0: any temperature difference separates them (no smallest one)")
        scene_d = scene_record(contact, noise, None)
    cov = check_coverage(kw["coverage"])
    run = _make(kw)
    pq = pair_question(kw["e1"], kw["e2"], kw["m1"], kw["m2"], objects=kw["objects"], width=run.width,
                       diffusivity_m2_s=kw["diffusivity_m2_s"], model=run.model)
    if pq.classes is None:
        return _no_pair(question, run, pq, scene_d, {})
    cls = pq.classes
    lo_r, hi_r = RATIO_BRACKET
    if run.spread == 0:
        def scene(r):  # readings depend on sigma and dT only through r
            return run.scene(contact, r, 1.0)
    elif question == "max-noise":  # varied Ts0: the ratio invariance is gone, sigma moves at the asked dT
        _check_spread(run.spread, dt)

        def scene(r):
            return run.scene(contact, r * abs(dt), dt)
    else:  # min-delta-t with varied Ts0: dT = sigma / r, which must stay above the spread
        hi_r = min(hi_r, noise / run.spread * (1 - 1e-9))

        def scene(r):
            return run.scene(contact, noise, noise / r)

    closed = run.closed_form(*cls)
    ideal_iv = None  # (low, high) in sigma/dT of a Monte Carlo bound
    if closed:
        from .ideal_bound import exact_ideal_max_ratio

        ideal_r = number(exact_ideal_max_ratio(run.sensor, cls[0].e_range[0], cls[1].e_range[0], contact,
                                               width=run.width, threshold=run.phi, bracket=RATIO_BRACKET))
    elif run.ideal_method_at(cls, scene(lo_r)) == "closed-form":  # extra physics invisible here
        ideal_r = None
        if run.ideal_f1(cls, scene(lo_r)) >= run.phi:
            ideal_r = hi_r if run.ideal_f1(cls, scene(hi_r)) >= run.phi else \
                bisect(lambda x: run.ideal_f1(cls, scene(x)) < run.phi, lo_r, hi_r, 2e-3, log=True)
    else:  # Monte Carlo: the crossing estimated with its interval (ideal_mc_bound)
        from .ideal_mc_bound import mc_ideal_max_ratio

        mcb = mc_ideal_max_ratio(cls[0], cls[1], run.sensor, scene, lo_r, hi_r, model=run.model,
                                 threshold=run.phi, n_mc=run.n_mc, seed=run.seed, coverage=cov)
        run.ideal_calls.extend({"contact_s": contact, **e} for e in mcb.evaluations)
        ideal_r = mcb.value
        ideal_iv = mcb.interval[:2] if mcb.interval else None
    # no classifier tolerates more noise than the ideal observer: search below its ratio (a Monte Carlo
    # bound's high end). The mean SVM F1 falls with sigma/dT; one crossing in log(sigma/dT) answers both
    ideal_cap = ideal_r if ideal_iv is None else ideal_iv[1]
    # the SVM's crossing lies below the ideal's, so that is the top of its search, above the bracket's end too
    # where nothing else caps the ratio (min-delta-t with varied Ts0 caps it: dT must stay above the spread)
    if ideal_cap is None:
        top = hi_r
    elif hi_r < RATIO_BRACKET[1]:  # capped below the bracket's end
        top = min(hi_r, ideal_cap)
    else:
        top = ideal_cap
    est = estimate_crossing(lambda x: run.svm(cls, scene(x)), lo_r, max(top, lo_r * 1.0001), run.phi,
                            increasing=False, coverage=cov, progress=kw.get("progress"))
    r, r_lo, r_hi = est.value, est.low, est.high
    if ideal_r is not None:
        r, r_hi = (None if r is None else min(r, ideal_r)), (None if r_hi is None else min(r_hi, ideal_cap))
    if question == "max-noise":
        conv = lambda x: None if x is None else x * abs(dt)  # noqa: E731
        interval = (conv(r_lo), conv(r_hi))
        ideal_interval = None if ideal_iv is None else (conv(ideal_iv[0]), conv(ideal_iv[1]), cov)
    else:
        conv = lambda x: None if x is None else noise / x  # noqa: E731
        interval = (conv(r_hi), conv(r_lo))
        ideal_interval = None if ideal_iv is None else (conv(ideal_iv[1]), conv(ideal_iv[0]), cov)
    evaluations = _evaluations(est, "noise_ratio")
    # the model check at the answer: the smaller sigma/dT of the SVM's and the ideal observer's is the stricter
    r_check = min([x for x in (r, ideal_r) if x is not None], default=lo_r)
    check_at = (contact, r_check * abs(dt), dt) if question == "max-noise" else (contact, noise, noise / r_check)
    note = "" if r is not None else f"not separable even at sigma/dT = {lo_r:g}"
    return run.answer(question, value=conv(r), interval=interval, ideal=conv(ideal_r), ideal_interval=ideal_interval,
                      ideal_method=run.ideal_method(closed), objects=pq.objects_dicts(),
                      limiting=pq.limiting_dicts(), rule=pq.rule, scene=scene_d, details={}, check_classes=cls,
                      check_at=check_at, notes=[note], evaluations=evaluations, estimate_method=est.method,
                      noise_ratio_estimate={"value": r, "low": r_lo, "high": r_hi}, **_error_model(est),
                      interval_coverage=cov if est.stated else None,
                      interval_kind="exact-estimate" if est.stated else "exact")


def exact_max_noise(e1=None, e2=None, *, m1=None, m2=None, objects=None, contact_s: float, delta_t_c: float = 10.0,
                    threshold: float = 0.9, sensor=None, model=None, diffusivity_m2_s=None,
                    width: float = DEFAULT_CLASS_WIDTH, trials: int = 100, folds: int = 3, seed: int = 0,
                    repeats: int = 4, z: float = 2.0, jobs: int = -1, n_mc: int = 1000, coverage: float = 0.9,
                    progress=None, solver: str = "sklearn",
                      sensor_temp_spread_c: float = 0.0) -> Answer:
    """Largest noise sigma [degC] that still separates the pair: an estimate with a ``coverage`` interval.

    The mean SVM F1 depends on sigma and dT only through sigma/dT (fixed initial
    conditions, standardized features, a model linear in the temperatures), so the
    answer is where the F1 against log(sigma/dT) crosses Phi
    (:func:`designkit.query.crossing.estimate_crossing`, searched below the exact
    ideal-observer ratio), times |dT|. Arguments as :func:`exact_min_contact`;
    ``contact_s`` [s] is the contact time.
    """
    return _exact_ratio("max-noise", dict(locals(), noise_c=None))


def exact_min_delta_t(e1=None, e2=None, *, m1=None, m2=None, objects=None, contact_s: float, noise_c: float = 0.05,
                      threshold: float = 0.9, sensor=None, model=None, diffusivity_m2_s=None,
                      width: float = DEFAULT_CLASS_WIDTH, trials: int = 100, folds: int = 3, seed: int = 0,
                      repeats: int = 4, z: float = 2.0, jobs: int = -1, n_mc: int = 1000, coverage: float = 0.9,
                      progress=None, solver: str = "sklearn",
                      sensor_temp_spread_c: float = 0.0) -> Answer:
    """Smallest sensor-object temperature difference [degC] that separates the pair (estimate, interval).

    sigma divided by the crossing of :func:`exact_max_noise` (the same estimate
    in log(sigma/dT)). Arguments as :func:`exact_min_contact`; ``contact_s`` [s] is
    the contact time.
    """
    return _exact_ratio("min-delta-t", dict(locals(), delta_t_c=None))


# ============================================================ distinguishable
def exact_distinguishable(e1=None, e2=None, *, m1=None, m2=None, objects=None, contact_s: float,
                          noise_c: float = 0.05, delta_t_c: float = 10.0, threshold: float = 0.9, sensor=None,
                          model=None, diffusivity_m2_s=None, width: float = DEFAULT_CLASS_WIDTH, trials: int = 100,
                          folds: int = 3, seed: int = 0, repeats: int = 4, z: float = 2.0, jobs: int = -1,
                          n_mc: int = 1000, coverage: float = 0.9, progress=None,
                          solver: str = "sklearn",
                      sensor_temp_spread_c: float = 0.0) -> Answer:
    """SVM F1 (mean of ``repeats`` seeds) and ideal F1 of the pair's classes at this scene.

    ``value``: whether the mean SVM F1 reaches the threshold; ``interval``: the
    ``coverage`` confidence interval of the mean SVM F1 (normal, the larger of the
    fold-level and seed-to-seed standard errors); ``details``: the F1s, the SVM's
    standard error and whether the verdict is confident (the threshold outside
    that interval).
    """
    from .crossing import check_coverage, z_of_coverage

    kw = dict(locals())
    zc = z_of_coverage(check_coverage(coverage))
    noise, dt = scene_inputs(noise_c, delta_t_c)
    contact = check_contact(contact_s)
    run = _make(kw)
    pq = pair_question(e1, e2, m1, m2, objects=objects, width=run.width, diffusivity_m2_s=diffusivity_m2_s,
                       model=run.model)
    scene_d = scene_record(contact, noise, dt)
    if pq.classes is None:
        return _no_pair("distinguishable", run, pq, scene_d,
                        {"distinguishable": None, "svm_f1": None, "svm_standard_error": None, "verdict": None,
                         "ideal_f1": None, "ideal_distinguishable": None})
    cls = pq.classes
    _check_spread(run.spread, dt)
    scene = run.scene(contact, noise, dt)
    draws = run.svm(cls, scene)
    f1, se = draws.mean, draws.standard_error()  # one evaluation: its own seeds' spread or their own error
    if progress is not None:
        progress(1, 1, f"F1 {f1:.3f}")
    ideal = run.ideal_f1(cls, scene)
    yes = f1 >= run.phi
    low, high = max(0.0, f1 - zc * se), min(1.0, f1 + zc * se)
    details = {"distinguishable": yes, "svm_f1": f1, "svm_standard_error": se,
               "verdict": "confident" if not low <= run.phi <= high else "uncertain",
               "ideal_f1": ideal, "ideal_distinguishable": ideal >= run.phi}
    return run.answer("distinguishable", value=yes, interval=(low, high), ideal=ideal,
                      ideal_method=run.ideal_method(False), objects=pq.objects_dicts(),
                      limiting=pq.limiting_dicts(), rule=pq.rule, scene=scene_d, details=details,
                      check_classes=cls, check_at=(contact, noise, dt), interval_coverage=kw["coverage"],
                      interval_kind="exact-f1")


# ============================================================ delta-e
def exact_delta_e(e: float | None = None, *, m: str | None = None, contact_s: float, noise_c: float = 0.05,
                  delta_t_c: float = 10.0, threshold: float = 0.9, sensor=None, model=None, diffusivity_m2_s=None,
                  width: float = DEFAULT_CLASS_WIDTH, trials: int = 100, folds: int = 3, seed: int = 0,
                  repeats: int = 4, z: float = 2.0, jobs: int = -1, n_mc: int = 1000,
                  e_max: float = 40000.0, coverage: float = 0.9, progress=None,
                  solver: str = "sklearn",
                      sensor_temp_spread_c: float = 0.0) -> Answer:
    """delta(e) computed for this reference, both directions: estimates with ``coverage`` intervals.

    Per direction, the mean SVM F1 of the reference against a partner ``d`` away
    rises with ``d``; its crossing of Phi is estimated like min-contact's
    (:func:`designkit.query.crossing.estimate_crossing`, logistic fit in log d with a curvature term,
    searched from the exact ideal-observer delta up). ``interval`` is the
    interval of the direction giving ``value``; each direction's is in ``details``.

    The reference is ``[e, e + width)`` (``m``: a material, at the middle of its
    range with its diffusivity range; ``diffusivity_m2_s``: one value or a
    ``(low, high)`` range for a reference given as a number); partners
    ``[e +- d, e +- d + width)`` differ from it only in effusivity. ``e_max``:
    the largest effusivity a partner may reach.
    """
    from .crossing import check_coverage, estimate_crossing

    kw = dict(locals())
    contact = check_contact(contact_s)
    noise, dt = scene_inputs(noise_c, delta_t_c)
    cov = check_coverage(coverage)
    run = _make(kw)
    ref = reference_class(e, m, width=run.width, diffusivity_m2_s=diffusivity_m2_s, model=run.model)
    x, w = ref.e_range[0], run.width
    _check_spread(run.spread, dt)
    scene = run.scene(contact, noise, dt)
    closed = run.closed_form(ref)
    sides: dict[str, dict[str, Any]] = {}
    checked = [ref]
    for side, sign, limit in (("upper", +1, e_max - x - w), ("lower", -1, x - w)):
        if limit < w:
            sides[side] = {"value": None, "interval": [None, None], "ideal": None, "coverage": None,
                           "estimate_method": "none", "evaluations": []}
            continue

        def part(d, sign=sign):
            lo = x + sign * d
            return ObjectClass(f"{lo:g}", (lo, lo + w), ref.diffusivity_range_m2_s)

        ideal_interval = None
        if closed:
            from .ideal_bound import exact_ideal_delta

            ideal = number(exact_ideal_delta(run.sensor, x, contact, noise / abs(dt), direction=sign, width=w,
                                             threshold=run.phi, e_max=e_max))
        elif run.ideal_method_at((ref, part(limit)), scene) == "closed-form":  # extra physics invisible here
            def iok(d, part=part):
                return run.ideal_f1((ref, part(d)), scene) >= run.phi

            ideal = bisect(iok, 0.0, limit, 1.0) if iok(limit) else None
        else:  # Monte Carlo: the crossing estimated with its interval (ideal_mc_bound)
            from .ideal_mc_bound import mc_ideal_delta

            mcb = mc_ideal_delta(ref, sign, run.sensor, contact_s=contact, noise_c=noise, delta_t_c=dt,
                                 sensor_temp_spread_c=run.spread, model=run.model, threshold=run.phi, e_max=e_max,
                                 n_mc=run.n_mc, seed=run.seed, coverage=cov)
            run.ideal_calls.extend({"contact_s": contact, **e} for e in mcb.evaluations)
            ideal = mcb.value
            ideal_interval = list(mcb.interval[:2]) if mcb.interval else None
        if ideal is None:  # not even the ideal observer separates a partner within the range: nor does the SVM
            sides[side] = {"value": None, "interval": [None, None], "ideal": None, "coverage": None,
                           "estimate_method": "none", "evaluations": []}
            continue
        # no classifier separates a nearer partner than the ideal observer: search from its delta up
        start = min(max(w / 2.0, ideal), limit / 1.0001)
        est = estimate_crossing(lambda d, part=part: run.svm((ref, part(d)), scene), start, limit, run.phi,
                                coverage=cov, progress=progress)
        val, lo_d, hi_d = est.value, est.low, est.high
        if ideal is not None and val is not None:
            val, lo_d = max(val, ideal), (None if lo_d is None else max(lo_d, ideal_floor(ideal, ideal_interval)))
        sides[side] = {"value": val, "interval": [lo_d, hi_d], "ideal": ideal, "ideal_interval": ideal_interval,
                       "coverage": cov if est.stated else None, "estimate_method": est.method,
                       **_error_model(est), "evaluations": _evaluations(est, "delta_e")}
        found = [v for v in (val, ideal) if v is not None]
        if found:
            checked.append(part(max(found)))
    finite = [s["value"] for s in sides.values() if s["value"] is not None]
    ifinite = [s["ideal"] for s in sides.values() if s["ideal"] is not None]
    details = {"e": x, "lower": sides["lower"], "upper": sides["upper"]}
    best = min((s for s in sides.values() if s["value"] is not None), key=lambda s: s["value"], default=None)
    interval = tuple(best["interval"]) if best is not None else (None, None)
    stated = best is not None and best.get("coverage") is not None
    from .ideal_mc_bound import nearer_side_interval

    ideal_interval = nearer_side_interval(sides, cov)
    return run.answer("delta-e", value=min(finite) if finite else None, interval=interval,
                      ideal_interval=ideal_interval,
                      interval_coverage=cov if stated else None,
                      interval_kind="exact-estimate" if stated else "exact",
                      ideal=min(ifinite) if ifinite else None, ideal_method=run.ideal_method(closed),
                      objects=(ref.to_dict(),), limiting=(ref.to_dict(),), rule=REFERENCE_RULE,
                      scene=scene_record(contact, noise, dt), details=details, check_classes=checked,
                      check_at=(contact, noise, dt), e_max=e_max)
