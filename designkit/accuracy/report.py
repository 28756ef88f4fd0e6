"""Accuracy against run time across the pipeline, and the sweep's cost curve.

Every way designkit answers a question is measured against a high-fidelity
reference *in the same run*, so that errors and speed-ups are ratios on one
machine at one moment, not numbers copied from elsewhere. Each measurement is
a function returning :class:`Row` objects (or :class:`CostCurve` objects for
the cost curve); :func:`run_bench` runs a selection of them and
:func:`render_markdown` turns a :class:`BenchReport` into ``docs/accuracy.md``
(``designkit bench --out docs``).

Sections and their references
-----------------------------
``physics``
    eq. 2 (numpy/scipy erfc, and the log form for the deep tail) against
    mpmath at 40 digits; the thin-sample solvers (image series at its default
    tolerance, finite volumes at their default resolution) against the image
    series summed to a 1e-13 tail bound (itself checked against mpmath's
    Laplace inversion in ``tests/test_slab.py``).
``recognition``
    SVM F1 with 25-200 trials per class and 1-8 seed repeats against a long
    run (more trials, several seeds); the ideal observer's closed form against
    its own Monte Carlo (:func:`designkit.ideal.ideal_pair` on a scene with a
    1e-6 degC sensor-temperature spread takes the Monte Carlo path).
``delta``
    The staircase search against the full F1 matrix (SVM, a coarse grid where
    the full matrix is affordable); coarse effusivity grids (125, 250, 500
    intervals) against a fine one (ideal fidelity: an SVM sweep at 2000+
    intervals is unaffordable, so this isolates what the grid alone costs).
``queries``
    Table interpolation against exact answers over random pairs and scenes
    across each shipped table's grid. For ``ideal-paper`` the exact answer is
    the closed form (cheap, vectorized bisection); for ``svm-paper`` it is
    :func:`designkit.query.exact_min_contact` /
    :func:`~designkit.query.exact_distinguishable` (Monte Carlo, a modest
    number of pairs). The same ideal table cut down to sparser grids shows
    what table density buys.
``cost``
    Wall time, SVM fits and peak resident memory of the engine as the number
    of intervals, trials and the contact time grow, with exponents fitted by
    log-log least squares. Peak memory is each point's own (Linux's
    resettable high-water mark), above the resident set at its start.

All draws are seeded; the same seed gives the same errors (timings vary).
"""

from __future__ import annotations

import math
import os
import platform
import time
from dataclasses import asdict, dataclass, field, replace
from typing import Any, Callable, Iterable, Mapping, Sequence

import numpy as np

from .._validation import InputError, as_generator
from ..query.ideal_bound import _ideal_ok, _projection_noises, exact_ideal_delta, exact_ideal_max_ratio, exact_ideal_min_contact

__all__ = [
    "SECTIONS",
    "BenchReport",
    "CostCurve",
    "Row",
    "cost_curves",
    "delta_rows",
    "fit_exponent",
    "process_cost",
    "ProcessCost",
    "measure",
    "cost_curve",
    "grid_rows",
    "ideal_mc_rows",
    "physics_rows",
    "query_rows",
    "recognition_rows",
    "render_markdown",
    "run_bench",
    "slab_rows",
    "staircase_vs_full",
    "subsample_table",
    "svm_query_rows",
    "write_report",
]

SECTIONS = ("physics", "recognition", "delta", "queries", "cost")
PAPER_RATIO = 0.005  # sigma 0.05 degC over dT 10 degC: the paper's guideline scene


# ============================================================ result types
@dataclass(frozen=True)
class Row:
    """One method at one setting: its error against a reference and its run time.

    Attributes
    ----------
    question : str
        What is answered (``"SVM F1"``, ``"min-contact"``, ``"delta(e)"``, ...).
    method : str
        How designkit answers it.
    setting : str
        The method's knob(s) (trials, grid, tolerance, ...).
    metric : str
        What ``error`` measures, with units.
    error : float
        The typical error: the 95th percentile when the row summarizes many
        cases (``n > 1``), else the single value.
    worst : float
        The worst case over the cases.
    wall_s : float
        Wall time of the method per answer [s].
    reference : str
        The high-fidelity reference the error is measured against.
    reference_wall_s : float
        Wall time of the reference per answer [s] (NaN when not timed).
    n : int
        Number of cases summarized.
    note : str
        Anything needed to read the row right.
    """

    question: str
    method: str
    setting: str
    metric: str
    error: float
    worst: float
    wall_s: float
    reference: str
    reference_wall_s: float
    n: int = 1
    note: str = ""

    @property
    def speedup(self) -> float:
        """Reference time over method time (>1: the method is faster)."""
        if not (self.wall_s > 0) or not math.isfinite(self.reference_wall_s):
            return math.nan
        return self.reference_wall_s / self.wall_s

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["speedup"] = self.speedup
        return d


@dataclass(frozen=True)
class CostCurve:
    """Cost of the sweep engine as one quantity grows, with fitted exponents.

    ``cost ~ x^p`` with ``p`` from a least-squares line through
    ``(log x, log cost)``. ``peak_mb`` is each point's peak resident set above
    the resident set of its process after imports (Linux's resettable
    high-water mark; NaN where unavailable); ``base_mb`` that baseline.
    """

    name: str
    variable: str
    fidelity: str
    x: tuple[float, ...]
    wall_s: tuple[float, ...]
    fits: tuple[int, ...]
    peak_mb: tuple[float, ...]
    base_mb: float
    time_exponent: float
    fits_exponent: float | None
    memory_exponent: float | None
    setting: str = ""
    note: str = ""

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class BenchReport:
    """Everything one ``designkit bench`` run measured."""

    rows: tuple[Row, ...]
    curves: tuple[CostCurve, ...]
    facts: Mapping[str, Any]
    quick: bool
    seed: int
    wall_s: float
    environment: Mapping[str, Any]
    skipped: tuple[str, ...] = ()
    section_wall_s: Mapping[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"quick": self.quick, "seed": self.seed, "wall_s": self.wall_s,
                "section_wall_s": dict(self.section_wall_s), "environment": dict(self.environment),
                "skipped": list(self.skipped), "facts": dict(self.facts),
                "rows": [r.to_dict() for r in self.rows], "curves": [c.to_dict() for c in self.curves]}


# ============================================================ helpers
def _timed(fn: Callable[[], Any], repeat: int = 1) -> tuple[Any, float]:
    """``fn()`` and its best wall time over ``repeat`` calls [s]."""
    best, out = math.inf, None
    for _ in range(max(1, int(repeat))):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return out, best


def fit_exponent(x: Sequence[float], y: Sequence[float]) -> float:
    """Slope ``p`` of ``log y = p log x + c`` by least squares (NaN with < 2 usable points)."""
    xa, ya = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    ok = (xa > 0) & (ya > 0) & np.isfinite(xa) & np.isfinite(ya)
    if np.count_nonzero(ok) < 2 or np.ptp(np.log(xa[ok])) == 0:
        return math.nan
    return float(np.polyfit(np.log(xa[ok]), np.log(ya[ok]), 1)[0])


def _p95(x) -> float:
    a = np.asarray(x, dtype=np.float64)
    a = a[np.isfinite(a)]
    return float(np.percentile(a, 95)) if a.size else math.nan


def _max(x) -> float:
    a = np.asarray(x, dtype=np.float64)
    a = a[np.isfinite(a)]
    return float(a.max()) if a.size else math.nan


def _paper_sensor():
    from ..sensor import SENSORS

    return SENSORS["paper"]


# ============================================================ physics
def physics_rows(quick: bool = True, seed: int = 0) -> list[Row]:
    """eq. 2 in double precision against mpmath at 40 significant digits.

    Three rows: the response shape ``erfc(sqrt(tau/t))`` where it is
    representable (``tau/t`` from 1e-3 to 700), its log form deep in the tail
    (``tau/t`` up to 1e6, where erfc itself underflows), and the temperature
    change ``(To - Ts0) w(e) g(t)`` for effusivities from 1e-3 to 1e6.
    Errors are relative (the log form: absolute error of the log, i.e.
    relative error of the value). Times are for the same points: one
    vectorized numpy call against an mpmath loop.
    """
    import mpmath

    from ..models.semi_infinite import log_response_shape, response_shape, temperature_change

    rng = as_generator([seed, 801])
    n = 300 if quick else 3000
    ref = "mpmath, 40 digits"
    rows: list[Row] = []

    def mp_shape(r):
        return mpmath.erfc(mpmath.sqrt(mpmath.mpf(r)))

    with mpmath.workdps(40):
        tau = 1.3445378151260505
        ratio = 10.0 ** rng.uniform(-3.0, math.log10(700.0), n)
        t = tau / ratio
        got, sec = _timed(lambda: response_shape(t, tau), 3)
        ref_vals, ref_sec = _timed(lambda: [mp_shape(mpmath.mpf(tau) / mpmath.mpf(float(ti))) for ti in t])
        err = np.array([float(abs((mpmath.mpf(float(g)) - r) / r)) for g, r in zip(got, ref_vals)])
        rows.append(Row("physics: eq. 2", "response_shape (scipy erfc)", "tau/t 1e-3..700",
                        "relative error", _p95(err), _max(err), sec / n, ref, ref_sec / n, n))

        ratio = 10.0 ** rng.uniform(-6.0, 6.0, n)
        t = tau / ratio
        got, sec = _timed(lambda: log_response_shape(t, tau), 3)
        ref_vals, ref_sec = _timed(lambda: [mpmath.log(mp_shape(mpmath.mpf(tau) / mpmath.mpf(float(ti))))
                                            for ti in t])
        err = np.array([float(abs(mpmath.mpf(float(g)) - r)) for g, r in zip(got, ref_vals)])
        rows.append(Row("physics: eq. 2", "log_response_shape (log_ndtr)", "tau/t 1e-6..1e6",
                        "relative error (abs. error of log)", _p95(err), _max(err), sec / n, ref, ref_sec / n, n))

        e = 10.0 ** rng.uniform(-3.0, 6.0, n)
        ratio = 10.0 ** rng.uniform(-3.0, math.log10(700.0), n)
        t = tau / ratio
        dt = rng.uniform(0.1, 100.0, n)
        es = 892.0
        got, sec = _timed(lambda: temperature_change(t, e, 25.0 + dt, 25.0, es, tau), 3)

        def mp_change():
            out = []
            for ti, ei, di in zip(t, e, dt):
                ei_, di_ = mpmath.mpf(float(ei)), mpmath.mpf(float(di))
                out.append(-di_ * ei_ / (es + ei_) * mp_shape(mpmath.mpf(tau) / mpmath.mpf(float(ti))))
            return out

        ref_vals, ref_sec = _timed(mp_change)
        err = np.array([float(abs((mpmath.mpf(float(g)) - r) / r)) for g, r in zip(got, ref_vals)])
        rows.append(Row("physics: eq. 1-2", "temperature_change", "e 1e-3..1e6, dT 0.1..100 °C",
                        "relative error", _p95(err), _max(err), sec / n, ref, ref_sec / n, n))
    return rows


def slab_rows(quick: bool = True) -> list[Row]:
    """Thin-sample solvers against the image series summed to a 1e-13 tail bound.

    Scenes (paper sensor, 200 Hz, errors in degC at a 10 degC difference):
    1 mm acrylic on wood for 10 s, 1 mm copper on rigid foam for 4 s, 1 mm
    foam on copper for 10 s. ``benchmarks/bench_slab.py`` has the full study
    (every resolution, orders of convergence, stability).
    """
    from ..models import slab

    sensor = _paper_sensor()
    dt_c = 10.0
    copper, foam, acrylic = (36800.0, 1.17e-4), (30.5, 6.0e-7), (583.25, 1.18e-7)
    scenes = [
        (acrylic, 1e-3, "wood", 10.0),
        (copper, 1e-3, slab.Backing("rigid foam", *foam), 4.0),
        (foam, 1e-3, slab.Backing("copper", *copper), 10.0),
    ]
    refs, ref_total = [], 0.0
    for (e, a), L, back, contact in scenes:
        t = sensor.times_s(contact)
        r, sec = _timed(lambda: slab.slab_response(t, e, a, L, back, tolerance=1e-13, method="image-series"))
        refs.append(r.response[0])
        ref_total += sec
    methods = [("image series", "tail bound 1e-5 (default)", dict(method="image-series", tolerance=1e-5)),
               ("image series", "tail bound 1e-3", dict(method="image-series", tolerance=1e-3)),
               ("finite volumes", "default: " + ", ".join(f"{k} {v}" for k, v in slab.FV_DEFAULTS.items()),
                dict(method="finite-volume")),
               ("semi-infinite (paper eq. 2)", "no reflections", dict(method="semi-infinite"))]
    if not quick:
        methods.insert(2, ("image series", "tail bound 1e-8", dict(method="image-series", tolerance=1e-8)))
    rows = []
    repeat = 2 if quick else 3
    for label, setting, kw in methods:
        errs, total = [], 0.0
        for ((e, a), L, back, contact), ref in zip(scenes, refs):
            t = sensor.times_s(contact)
            r, sec = _timed(lambda: slab.slab_response(t, e, a, L, back, **kw), repeat)
            errs.append(float(np.max(np.abs(r.response[0] - ref))) * dt_c)
            total += sec
        rows.append(Row("physics: thin samples", label, setting, "max |error| over samples [°C] (dT 10 °C)",
                        _max(errs), _max(errs), total / len(scenes), "image series, tail bound 1e-13",
                        ref_total / len(scenes), len(scenes),
                        "3 scenes: 1 mm acrylic on wood 10 s, copper on foam 4 s, foam on copper 10 s"))
    return rows


# ============================================================ recognition
#: Pairs near the threshold at the paper's scene (sigma 0.05 degC, dT 10 degC):
#: (lower class start, higher class start, contact [s]); classes 80 wide.
RECOGNITION_PAIRS = ((20000.0, 35000.0, 1.0), (5000.0, 6000.0, 1.25), (1000.0, 1150.0, 1.0))


def recognition_rows(quick: bool = True, seed: int = 0, *, pairs=None,
                     trials: Sequence[int] = (25, 50, 100, 200), repeats: Sequence[int] = (1, 2, 4, 8),
                     progress: Callable[[str], None] | None = None) -> list[Row]:
    """SVM F1 against a long run, by trials per class and seed repeats.

    For each pair and trial count, ``P`` single-seed F1 values are computed
    (``P = max(repeats)`` quick, ``2 max(repeats)`` full); an estimate with
    ``r`` repeats is the mean of ``r`` of them, and disjoint groups give its
    error distribution. The reference is the mean F1 of ``R`` seeds with
    ``T_ref`` trials per class (quick: 400 x 4, full: 800 x 8): the
    large-sample SVM, so the error includes the bias of training on fewer
    trials as well as Monte Carlo noise.
    """
    from ..recognition.svm import interval_pair_f1
    from ..scene import Scene

    sensor = _paper_sensor()
    pairs = RECOGNITION_PAIRS[:2] if (pairs is None and quick) else (pairs or RECOGNITION_PAIRS)
    pool = max(repeats) * (1 if quick else 2)
    t_ref, r_ref = (400, 4) if quick else (800, 8)
    width = 80.0
    est: dict[int, list[np.ndarray]] = {t: [] for t in trials}
    fit_time: dict[int, float] = {t: 0.0 for t in trials}
    refs, ref_se, ref_time = [], [], 0.0
    for a, b, contact in pairs:
        scene = Scene.from_delta_t(contact_s=contact, noise_c=0.05, delta_t_c=10.0)
        ra, rb = (a, a + width), (b, b + width)
        if progress:
            progress(f"recognition: reference {a:g} vs {b:g} at {contact:g} s")
        vals, sec = _timed(lambda: [interval_pair_f1(ra, rb, sensor, scene, trials=t_ref, seed=[seed, 9000 + k]).f1
                                    for k in range(r_ref)])
        refs.append(float(np.mean(vals)))
        ref_se.append(float(np.std(vals, ddof=1) / math.sqrt(r_ref)))
        ref_time += sec / r_ref
        for t in trials:
            if progress:
                progress(f"recognition: {t} trials, {a:g} vs {b:g}")
            vals, sec = _timed(lambda: [interval_pair_f1(ra, rb, sensor, scene, trials=t, seed=[seed, 100 + k]).f1
                                        for k in range(pool)])
            est[t].append(np.asarray(vals))
            fit_time[t] += sec / pool
    n_pairs = len(pairs)
    ref_time /= n_pairs
    rows = []
    ref_label = f"SVM, {t_ref} trials/class, mean of {r_ref} seeds"
    for t in trials:
        per_fit = fit_time[t] / n_pairs
        for r in repeats:
            errs = []
            for vals, ref in zip(est[t], refs):
                groups = vals[: (vals.size // r) * r].reshape(-1, r).mean(axis=1)
                errs.extend(groups - ref)
            errs = np.asarray(errs)
            rms = float(np.sqrt(np.mean(errs ** 2)))
            rows.append(Row("SVM F1", "SVM (paper pipeline, 3-fold)", f"{t} trials x {r} seed{'s' if r > 1 else ''}",
                            "RMS |F1 - F1_ref|", rms, float(np.max(np.abs(errs))), per_fit * r, ref_label,
                            ref_time * r_ref, errs.size,
                            f"bias {float(np.mean(errs)):+.3f}; reference's own SE <= {max(ref_se):.3f}"))
    return rows


def ideal_mc_rows(quick: bool = True, seed: int = 0, *, pairs=None,
                  n_mc: Sequence[int] | None = None) -> list[Row]:
    """The ideal observer's closed form against its own Monte Carlo.

    :func:`designkit.ideal.ideal_pair` takes the Monte Carlo path (exact
    likelihood, simulated touches) when the scene varies the sensor
    temperature; a spread of 1e-6 degC makes that path answer the same
    question as the closed form. Rows: Monte Carlo at each ``n_mc`` (error
    against the closed form), and the closed form (error against the largest
    Monte Carlo run, with that run's standard error in the note).
    """
    from ..recognition.ideal import ideal_pair
    from ..scene import Scene

    sensor = _paper_sensor()
    pairs = pairs or RECOGNITION_PAIRS
    n_mc = tuple(n_mc or ((500, 2000, 8000) if quick else (500, 2000, 8000, 32000)))
    width = 80.0
    cf_vals, cf_time = [], 0.0
    mc: dict[int, list[tuple[float, float]]] = {n: [] for n in n_mc}
    mc_time: dict[int, float] = {n: 0.0 for n in n_mc}
    for k, (a, b, contact) in enumerate(pairs):
        scene = Scene.from_delta_t(contact_s=contact, noise_c=0.05, delta_t_c=10.0)
        ra, rb = (a, a + width), (b, b + width)
        r, sec = _timed(lambda: ideal_pair(ra, rb, sensor, scene), 3)
        cf_vals.append(r.f1)
        cf_time += sec
        varied = scene.replace(sensor_temp_spread_c=1e-6)
        for n in n_mc:
            r, sec = _timed(lambda: ideal_pair(ra, rb, sensor, varied, n_mc=n, seed=[seed, 700 + k]))
            if r.method != "monte-carlo":
                raise RuntimeError("ideal_pair did not take the Monte Carlo path")
            mc[n].append((r.f1, r.standard_error))
            mc_time[n] += sec
    m = len(pairs)
    rows = []
    for n in n_mc:
        diffs = np.array([abs(f - c) for (f, _), c in zip(mc[n], cf_vals)])
        ses = np.array([s for _, s in mc[n]])
        rows.append(Row("ideal F1", "ideal observer, Monte Carlo", f"n_mc = {n} per class",
                        "|F1_MC - F1_closed|", float(np.mean(diffs)), float(diffs.max()), mc_time[n] / m,
                        "ideal observer, closed form", cf_time / m, m,
                        f"MC standard error {ses.mean():.4f}; largest |diff|/SE {float((diffs / ses).max()):.1f}"))
    n_big = n_mc[-1]
    diffs = np.array([abs(f - c) for (f, _), c in zip(mc[n_big], cf_vals)])
    ses = np.array([s for _, s in mc[n_big]])
    rows.append(Row("ideal F1", "ideal observer, closed form", "Gauss-Legendre + golden section",
                    "|F1_closed - F1_MC|", float(np.mean(diffs)), float(diffs.max()), cf_time / m,
                    f"ideal observer, Monte Carlo n_mc = {n_big}", mc_time[n_big] / m, m,
                    f"agrees within {float((diffs / ses).max()):.1f} MC standard errors ({ses.mean():.4f}); "
                    f"tests/test_ideal.py checks it against mpmath"))
    return rows


# ============================================================ delta(e)
def staircase_vs_full(intervals: int, *, contact_s: float = 1.0, noise_ratio: float = PAPER_RATIO,
                      trials: int = 100, seed: int = 0, max_repeats: int = 4,
                      e_max: float = 40000.0) -> dict[str, Any]:
    """delta(e) for every reference at one scene: staircase search against the full matrix.

    Both runs use the same per-pair seeds, so every pair the staircase scores
    has exactly the F1 the full matrix gives it; the answers can differ only
    where F1 is not monotone in the distance (Monte Carlo noise).

    Returns
    -------
    dict
        ``intervals``, ``fits_staircase``, ``fits_full``, ``wall_staircase_s``,
        ``wall_full_s``, ``max_diff_intervals`` (largest difference of the
        first distinguishable partner, in intervals, over all references and
        both directions), ``n_differ`` (references whose answer differs),
        ``J_staircase``, ``J_full``.
    """
    from ..sweep.engine import SweepConfig, delta_from_staircase, run_chunk

    base = SweepConfig(name="bench", fidelity="svm", intervals=int(intervals), e_max=e_max, trials=trials,
                       seed=seed, max_repeats=max_repeats, noise_ratio=(noise_ratio,), contact_s=(contact_s,))
    stair, t_stair = _timed(lambda: run_chunk(base, (0,), 0, 0))
    full_cfg = replace(base, full_matrix=True)
    full, t_full = _timed(lambda: run_chunk(full_cfg, (0,), 0, 0))
    up_s, down_s = delta_from_staircase(stair.J, base.width)
    up_f, down_f = delta_from_staircase(full.J, base.width)

    def diff(a, b):
        both_nan = np.isnan(a) & np.isnan(b)
        one_nan = np.isnan(a) ^ np.isnan(b)
        d = np.where(both_nan, 0.0, np.abs(np.nan_to_num(a, nan=0.0) - np.nan_to_num(b, nan=0.0)) / base.width)
        # an answer on one side only: count it as the distance to the grid's end
        return np.where(one_nan, np.abs(np.nan_to_num(a, nan=e_max) - np.nan_to_num(b, nan=e_max)) / base.width, d)

    d_all = np.concatenate([diff(up_s, up_f), diff(down_s, down_f)])
    # the staircase's Monte Carlo interval [J_lo, J_hi] (z standard errors): does it hold the matrix's answer?
    covered = (full.J >= stair.J_lo) & (full.J <= stair.J_hi)
    differ = np.flatnonzero(stair.J != full.J)
    return {"intervals": int(intervals), "contact_s": contact_s, "noise_ratio": noise_ratio, "trials": trials,
            "fits_staircase": int(stair.fits), "fits_full": int(full.fits), "pairs_full": intervals * (intervals - 1) // 2,
            "wall_staircase_s": t_stair, "wall_full_s": t_full,
            "max_diff_intervals": float(d_all.max()), "n_differ": int(np.count_nonzero(d_all > 0)),
            "full_in_staircase_interval": int(np.count_nonzero(covered)),
            "differing_references": [{"i": int(i), "e_centre": float(base.centres[i]), "J_staircase": int(stair.J[i]),
                                      "J_full": int(full.J[i]), "J_lo": int(stair.J_lo[i]), "J_hi": int(stair.J_hi[i])}
                                     for i in differ],
            "J_staircase": stair.J.tolist(), "J_full": full.J.tolist(),
            "J_lo": stair.J_lo.tolist(), "J_hi": stair.J_hi.tolist()}


def grid_rows(quick: bool = True, coarse: Sequence[int] = (125, 250, 500),
              progress: Callable[[str], None] | None = None) -> list[Row]:
    """Coarse effusivity grids against a fine one, at ideal fidelity.

    delta(e) of each grid (towards higher and lower e) is interpolated
    linearly to the same points (the coarse grid's centres) and compared
    with the fine grid's; the error is relative. Part of it is the class
    width itself (a class of a coarse grid is wider, hence harder to
    separate), which is what a coarse table gets wrong about a point pair.
    An SVM sweep of 2000+ intervals is unaffordable; the ideal observer
    shows what the grid alone costs.
    """
    from ..sweep.engine import SweepConfig, delta_from_staircase, run_chunk

    fine = 2000 if quick else 4000
    scenes = [(PAPER_RATIO, 1.0), (PAPER_RATIO, 4.0)] if quick else \
        [(PAPER_RATIO, 1.0), (PAPER_RATIO, 2.0), (PAPER_RATIO, 4.0), (0.001, 2.0), (0.02, 2.0)]

    def curves(n, ratio, contact):
        cfg = SweepConfig(name="bench", fidelity="ideal", intervals=n, noise_ratio=(ratio,), contact_s=(contact,))
        res, sec = _timed(lambda: run_chunk(cfg, (0,), 0, 0))
        up, down = delta_from_staircase(res.J, cfg.width)
        return cfg.centres, up, down, sec

    rows = []
    errs: dict[int, list[float]] = {n: [] for n in coarse}
    rel: dict[int, list[float]] = {n: [] for n in coarse}
    times: dict[int, float] = {n: 0.0 for n in coarse}
    fine_time = 0.0
    for ratio, contact in scenes:
        if progress:
            progress(f"delta(e): fine grid {fine} at sigma/dT {ratio:g}, {contact:g} s")
        xf, upf, downf, sec = curves(fine, ratio, contact)
        fine_time += sec
        for n in coarse:
            xc, upc, downc, sec = curves(n, ratio, contact)
            times[n] += sec
            for c_vals, f_vals in ((upc, upf), (downc, downf)):
                ok_f = np.isfinite(f_vals)
                ref = np.interp(xc, xf[ok_f], f_vals[ok_f], left=np.nan, right=np.nan)
                ok = np.isfinite(c_vals) & np.isfinite(ref) & (xc >= xf[ok_f][0]) & (xc <= xf[ok_f][-1])
                errs[n].extend(np.abs(c_vals[ok] - ref[ok]))
                big = ok & (ref >= 5 * 40000.0 / n)
                rel[n].extend(np.abs(c_vals[big] - ref[big]) / ref[big])
    k = len(scenes)
    for n in coarse:
        e = np.asarray(errs[n])
        rows.append(Row("delta(e) grid", "ideal sweep", f"{n} intervals (width {40000 / n:g})",
                        "|delta - delta_fine| [J s^-1/2 K^-1 m^-2]", _p95(e), _max(e), times[n] / k,
                        f"ideal sweep, {fine} intervals (width {40000 / fine:g})", fine_time / k, e.size,
                        f"{k} scenes, both directions; where delta_fine >= 5 widths the relative error is "
                        f"{100 * _p95(rel[n]):.0f} % (p95), {100 * _max(rel[n]):.0f} % (worst); a grid cannot "
                        f"resolve a delta below one width, and its wider classes are harder to separate"))
    return rows


def delta_rows(quick: bool = True, seed: int = 0,
               progress: Callable[[str], None] | None = None) -> list[Row]:
    """Staircase search against the full matrix (SVM), and grid coarseness (ideal)."""
    sizes = (16,) if quick else (20, 40)
    rows = []
    for n in sizes:
        if progress:
            progress(f"delta(e): staircase vs full matrix, {n} intervals")
        r = staircase_vs_full(n, seed=seed)
        rows.append(Row("delta(e)", "staircase search (SVM)", f"{n} intervals, contact 1 s, sigma/dT 0.005",
                        "max |delta - delta_full| [intervals]", r["max_diff_intervals"], r["max_diff_intervals"],
                        r["wall_staircase_s"], f"full matrix ({r['pairs_full']} pairs)", r["wall_full_s"], 2 * n,
                        f"{r['fits_staircase']} vs {r['fits_full']} SVM fits "
                        f"({r['fits_full'] / max(r['fits_staircase'], 1):.1f}x fewer); {r['n_differ']} of {2 * n} "
                        f"answers differ; the matrix's answer lies in the staircase's Monte Carlo interval for "
                        f"{r['full_in_staircase_interval']} of {n} references; benchmarks/bench_delta_e.py scales "
                        f"this up"))
    rows.extend(grid_rows(quick, progress=progress))
    return rows


# ============================================================ queries: tables
def subsample_table(table, keep: Mapping[str, Sequence[int]], name: str | None = None):
    """An in-memory :class:`~designkit.tables.Table` restricted to some points of its axes.

    ``keep`` maps axis names (``noise_ratio``, ``contact_s``, ...) to the
    indices to keep; used to measure what a sparser table of the same
    sweep would answer (no recomputation: the kept points are exact).
    """
    from ..tables.store import Table

    names = table.axis_names
    idx = []
    for a in names:
        n = len(table.axes[a])
        sel = np.asarray(keep.get(a, range(n)), dtype=np.int64)
        if sel.size == 0 or np.any(np.diff(sel) <= 0) or sel[0] < 0 or sel[-1] >= n:
            raise InputError(f"indices kept on axis {a} must be increasing and inside 0..{n - 1}")
        idx.append(sel)
    header = dict(table.header)
    header["axes"] = [dict(ax, values=[ax["values"][i] for i in sel]) for ax, sel in zip(table.header["axes"], idx)]
    header["name"] = name or f"{table.name}-subsampled"
    arrays = {}
    for k, v in table.arrays.items():
        if v.ndim == len(names):
            arrays[k] = v[np.ix_(*idx)]
        elif v.ndim == len(names) - 1:
            arrays[k] = v[np.ix_(*idx[:-1])]
        else:
            arrays[k] = v
    return Table(name=header["name"], path=table.path, header=header, arrays=arrays)


def _axis(table, name) -> np.ndarray:
    return table.axes[name]


def _query_samples(table, n: int, seed, min_gap_intervals: float = 1.0) -> dict[str, Any]:
    """Random pairs and scenes whose exact ideal answer lies inside the table's grid.

    e1 uniform over the grid, sigma/dT log-uniform over the table's range, a
    target contact uniform over its contact range; the partner e2 = e1 +
    (exact ideal delta at that contact and noise), so that the exact
    min-contact lies near the target and every query has an in-grid answer.
    Pairs closer than ``min_gap_intervals`` table intervals are below the
    table's effusivity resolution (its smallest delta is one interval): they
    are drawn again, and their share is returned as ``unresolved_fraction``.
    """
    sensor = table.sensor
    rng = as_generator(seed)
    e_lo = float(table.header["effusivity"]["min"])
    e_hi = float(table.header["effusivity"]["max"])
    width = float(table.header["effusivity"]["width"])
    ratios, contacts = _axis(table, "noise_ratio"), _axis(table, "contact_s")
    out: dict[str, list] = {"e1": [], "e2": [], "ratio": [], "contact": []}
    got, unresolved = 0, 0
    min_gap = width * min_gap_intervals
    while got < n:
        m = 2 * (n - got) + 8
        e1 = rng.uniform(e_lo + width, e_hi - 2 * width, m)
        r = np.exp(rng.uniform(math.log(ratios[0]), math.log(ratios[-1]), m))
        c = rng.uniform(contacts[0], contacts[-1], m)
        d = exact_ideal_delta(sensor, e1, c, r, direction=+1, width=width, threshold=table.threshold, e_max=e_hi)
        e2 = e1 + d
        ok = np.isfinite(d) & (e2 <= e_hi - width)
        unresolved += int(np.count_nonzero(ok & (d < min_gap)))
        ok &= d >= min_gap
        for k, v in (("e1", e1), ("e2", e2), ("ratio", r), ("contact", c)):
            out[k].extend(v[ok][: n - got])
        got = len(out["e1"])
    res = {k: np.asarray(v[:n]) for k, v in out.items()}
    res["unresolved_fraction"] = unresolved / (unresolved + got)
    return res


def _table_answers(table, samples, dt_c: float = 10.0) -> tuple[dict[str, np.ndarray], float]:
    """Answers of every table query for the samples; seconds per query (mean over all)."""
    from ..query import table as query

    ans = {k: [] for k in ("min_contact", "max_noise", "min_delta_t", "delta_up", "delta_down", "dist")}
    n_queries = 0
    t0 = time.perf_counter()
    for e1, e2, r, c in zip(samples["e1"], samples["e2"], samples["ratio"], samples["contact"]):
        noise = float(r) * dt_c
        a = query.min_contact(e1, e2, noise_c=noise, delta_t_c=dt_c, table=table, ideal_table=table)
        ans["min_contact"].append(np.nan if a.value is None else a.value)
        a = query.max_noise(e1, e2, contact_s=float(c), delta_t_c=dt_c, table=table, ideal_table=table)
        ans["max_noise"].append(np.nan if a.value is None else a.value / dt_c)
        a = query.min_delta_t(e1, e2, contact_s=float(c), noise_c=noise, table=table, ideal_table=table)
        ans["min_delta_t"].append(np.nan if a.value is None else noise / a.value)
        a = query.delta_e(e1, contact_s=float(c), noise_c=noise, delta_t_c=dt_c, table=table, ideal_table=table)
        x = a.extra
        ans["delta_up"].append(np.nan if x.get("delta_e_upper") is None else x["delta_e_upper"])
        ans["delta_down"].append(np.nan if x.get("delta_e_lower") is None else x["delta_e_lower"])
        n_queries += 4
    per = (time.perf_counter() - t0) / max(n_queries, 1)
    return {k: np.asarray(v, dtype=np.float64) for k, v in ans.items() if v}, per


def _distinguishable_check(table, samples, seed, dt_c=10.0):
    """Table verdicts against the exact ideal verdict, for pairs near the boundary."""
    from ..query import table as query

    sensor = table.sensor
    width = float(table.header["effusivity"]["width"])
    rng = as_generator(seed)
    factor = np.exp(rng.uniform(math.log(0.8), math.log(1.25), samples["e1"].size))
    e1 = samples["e1"]
    e2 = np.minimum(e1 + (samples["e2"] - e1) * factor, float(table.header["effusivity"]["max"]) - width)
    verdict, t_tab = [], 0.0
    for a, b, r, c in zip(e1, e2, samples["ratio"], samples["contact"]):
        t0 = time.perf_counter()
        ans = query.distinguishable(a, b, contact_s=float(c), noise_c=float(r) * dt_c, delta_t_c=dt_c,
                                    table=table, ideal_table=table)
        t_tab += time.perf_counter() - t0
        verdict.append(bool(ans.extra["distinguishable"]))
    t0 = time.perf_counter()
    exact = _ideal_ok(sensor, e1, e2, width, _projection_noises(sensor, samples["contact"], samples["ratio"]),
                      table.threshold)
    t_ex = time.perf_counter() - t0
    wrong = np.asarray(verdict) != exact
    closeness = np.abs(np.log(factor))  # how far from the exact boundary each pair was (log ratio)
    return wrong, closeness, t_tab / e1.size, t_ex / e1.size


def query_rows(table, quick: bool = True, seed: int = 0, *, n: int | None = None, label: str | None = None,
               questions: Sequence[str] = ("min-contact", "max-noise", "min-delta-t", "delta-e", "distinguishable"),
               samples: Mapping[str, np.ndarray] | None = None) -> tuple[list[Row], dict[str, Any]]:
    """Table interpolation against the exact ideal-observer answer (ideal-fidelity tables).

    Returns rows (p95 and worst errors, time per query) and the raw errors
    (``facts``) for the report.
    """
    if table.fidelity != "ideal":
        raise InputError(f"query_rows measures ideal-fidelity tables; {table.name} is {table.fidelity} "
                         f"(see svm_query_rows)")
    sensor = table.sensor
    width = float(table.header["effusivity"]["width"])
    n = n or (150 if quick else 1000)
    if samples is None:
        samples = _query_samples(table, n, [seed, 802])
    name = label or table.name
    e_hi = float(table.header["effusivity"]["max"])
    tab, per_query = _table_answers(table, samples)
    e1, e2, r, c = samples["e1"], samples["e2"], samples["ratio"], samples["contact"]
    t0 = time.perf_counter()
    ex_contact = exact_ideal_min_contact(sensor, e1, e2, r, width=width, threshold=table.threshold,
                                         max_contact_s=float(_axis(table, "contact_s")[-1]))
    t_contact = (time.perf_counter() - t0) / e1.size
    t0 = time.perf_counter()
    ex_ratio = exact_ideal_max_ratio(sensor, e1, e2, c, width=width, threshold=table.threshold)
    t_ratio = (time.perf_counter() - t0) / e1.size
    t0 = time.perf_counter()
    ex_up = exact_ideal_delta(sensor, e1, c, r, direction=+1, width=width, threshold=table.threshold, e_max=e_hi)
    ex_down = exact_ideal_delta(sensor, e1, c, r, direction=-1, width=width, threshold=table.threshold, e_max=e_hi)
    t_delta = (time.perf_counter() - t0) / (2 * e1.size)
    ref = "exact ideal observer (closed form, bisection)"
    rows: list[Row] = []
    facts: dict[str, Any] = {"table": name, "n": int(e1.size), "time_per_table_query_s": per_query,
                             "unresolved_fraction": float(samples.get("unresolved_fraction", math.nan))}
    method = f"table interpolation ({name})"
    setting = _grid_label(table)

    def add(question, metric, err, t_ref, missing, note=""):
        err = np.asarray(err, dtype=np.float64)
        rows.append(Row(question, method, setting, metric, _p95(err), _max(err), per_query, ref, t_ref,
                        int(np.isfinite(err).sum()),
                        (f"{missing} of {err.size} without a table answer where the exact one exists; " if missing
                         else "") + note))
        facts[question] = {"p95": _p95(err), "worst": _max(err), "median": float(np.nanmedian(err)),
                           "n": int(np.isfinite(err).sum()), "missing": int(missing), "metric": metric}

    if "min-contact" in questions:
        both = np.isfinite(tab["min_contact"]) & np.isfinite(ex_contact)
        err = np.where(both, np.abs(tab["min_contact"] - ex_contact), np.nan)
        missing = int(np.count_nonzero(np.isfinite(ex_contact) & ~np.isfinite(tab["min_contact"])))
        below = int(np.count_nonzero(ex_contact < _axis(table, "contact_s")[0]))
        add("min-contact", "|t_table - t_exact| [s]", err, t_contact, missing,
            f"{below} exact answers below the table's first contact (table answers its first contact)" if below else "")
        rel = np.where(both, np.abs(tab["min_contact"] - ex_contact) / ex_contact, np.nan)
        facts["min-contact"]["relative_p95"] = _p95(rel)
        facts["min-contact"]["relative_worst"] = _max(rel)
        signed = np.where(both, tab["min_contact"] - ex_contact, np.nan)
        facts["min-contact"]["signed_median_s"] = float(np.nanmedian(signed))
        facts["min-contact"]["conservative_fraction"] = float(np.mean(signed[both] >= -1.0 / sensor.sample_rate_hz))
        facts["min-contact"]["by_gap"] = _by_gap(e2 - e1, width, err)
    if "max-noise" in questions:
        both = np.isfinite(tab["max_noise"]) & np.isfinite(ex_ratio)
        err = np.where(both, np.abs(tab["max_noise"] / ex_ratio - 1.0), np.nan)
        add("max-noise", "relative error of sigma_max", err, t_ratio,
            int(np.count_nonzero(np.isfinite(ex_ratio) & ~np.isfinite(tab["max_noise"]))))
        facts["max-noise"]["by_gap"] = _by_gap(e2 - e1, width, err)
        signed = tab["max_noise"][both] / ex_ratio[both] - 1.0
        facts["max-noise"]["conservative_fraction"] = float(np.mean(signed <= 1e-6))
    if "min-delta-t" in questions:
        both = np.isfinite(tab["min_delta_t"]) & np.isfinite(ex_ratio)
        # tab["min_delta_t"] holds noise / dT_min (a sigma/dT): dT_table / dT_exact = r_exact / r_table
        err = np.where(both, np.abs(ex_ratio / tab["min_delta_t"] - 1.0), np.nan)
        add("min-delta-t", "relative error of dT_min", err, t_ratio,
            int(np.count_nonzero(np.isfinite(ex_ratio) & ~np.isfinite(tab["min_delta_t"]))))
    if "delta-e" in questions:
        errs, missing = [], 0
        for t_vals, x_vals in ((tab["delta_up"], ex_up), (tab["delta_down"], ex_down)):
            both = np.isfinite(t_vals) & np.isfinite(x_vals)
            errs.append(np.where(both, np.abs(t_vals - x_vals), np.nan))
            missing += int(np.count_nonzero(np.isfinite(x_vals) & ~np.isfinite(t_vals)))
        err = np.concatenate(errs)
        add("delta-e", "|delta_table - delta_exact| [J s^-1/2 K^-1 m^-2]", err, t_delta, missing,
            f"table steps are one interval ({width:g}) wide")
        rel = np.concatenate([e / x for e, x in zip(errs, (ex_up, ex_down))])
        facts["delta-e"]["relative_p95"] = _p95(rel)
        facts["delta-e"]["relative_worst"] = _max(rel)
    if "distinguishable" in questions:
        wrong, closeness, t_tab, t_ex = _distinguishable_check(table, samples, [seed, 803])
        rate = float(np.mean(wrong))
        far = float(np.exp(closeness[wrong].max()) - 1.0) if wrong.any() else 0.0
        rows.append(Row("distinguishable", method, setting, "wrong verdicts (fraction)", rate, rate, t_tab,
                        ref, t_ex, int(wrong.size),
                        f"pairs within -20 %..+25 % of the exact boundary gap; wrong verdicts at most "
                        f"{100 * far:.0f} % from it"))
        facts["distinguishable"] = {"wrong_fraction": rate, "n": int(wrong.size), "farthest_wrong_relative": far}
    return rows, facts


GAP_BINS = (1.0, 2.0, 5.0, 20.0, math.inf)


def _by_gap(gap, width, err) -> list[dict[str, Any]]:
    """Error statistics by the pair's distance in table intervals (quantization shows at small gaps)."""
    g = np.asarray(gap) / width
    err = np.asarray(err, dtype=np.float64)
    out = []
    for a, b in zip(GAP_BINS[:-1], GAP_BINS[1:]):
        sel = (g >= a) & (g < b)
        e = err[sel]
        out.append({"gap_intervals": [a, b], "pairs": int(sel.sum()), "answered": int(np.isfinite(e).sum()),
                    "median": float(np.nanmedian(e)) if np.isfinite(e).any() else math.nan,
                    "p95": _p95(e), "worst": _max(e)})
    return out


def _grid_label(table) -> str:
    ax = table.axes
    return (f"{len(ax['noise_ratio'])} sigma/dT x {len(ax['contact_s'])} contacts x "
            f"{len(ax['e_ref'])} intervals") if "noise_ratio" in ax else table.name


def density_rows(table, quick: bool = True, seed: int = 0, svm_axes: Mapping[str, Sequence[float]] | None = None
                 ) -> list[Row]:
    """What table density buys: the ideal table cut to sparser grids, min-contact and max-noise errors.

    Same random samples for every density. ``svm_axes`` (the SVM table's
    axis values) adds the SVM table's own density, so that its
    interpolation error can be told apart from its Monte Carlo error.
    """
    ax = table.axes
    nr, nc = len(ax["noise_ratio"]), len(ax["contact_s"])
    variants = [("every 2nd contact", {"contact_s": range(0, nc, 2)}),
                ("every 2nd sigma/dT and contact", {"noise_ratio": range(0, nr, 2), "contact_s": range(0, nc, 2)}),
                ("every 4th sigma/dT and contact", {"noise_ratio": range(0, nr, 4), "contact_s": range(0, nc, 4)})]
    if svm_axes is not None:
        keep = {}
        for name, vals in svm_axes.items():
            grid = ax[name]
            idx = sorted({int(np.argmin(np.abs(np.log(grid) - math.log(v)))) for v in vals})
            keep[name] = idx
        variants.insert(0, ("svm-paper's axes (nearest points)", keep))
    samples = _query_samples(table, 100 if quick else 500, [seed, 804])
    rows = []
    for label, keep in variants:
        # every variant must still span the full range (first and last point kept)
        keep = {k: sorted(set(v) | {0, len(ax[k]) - 1}) for k, v in keep.items()}
        sub = subsample_table(table, keep, name=f"{table.name} [{label}]")
        r, _ = query_rows(sub, quick, seed, label=sub.name, questions=("min-contact", "max-noise"), samples=samples)
        for row in r:
            rows.append(replace(row, method="table interpolation (density)", setting=f"{label}: {_grid_label(sub)}",
                                note=(row.note + "; " if row.note else "") + "same sweep, fewer points kept"))
    return rows


def svm_query_rows(svm_table, quick: bool = True, seed: int = 0, *, n: int | None = None, repeats: int | None = None,
                   jobs: int = 1, progress: Callable[[str], None] | None = None) -> tuple[list[Row], dict[str, Any]]:
    """The SVM table's min-contact and distinguishable against ``--exact`` (Monte Carlo).

    Pairs: e1 uniform over the lower half of the grid, sigma/dT log-uniform
    over the table's range, a target contact uniform over the middle of its
    contact range ([1 s, 7.6 s] for svm-paper), and e2 = e1 + the table's
    delta towards higher e at that contact (so that the table's answer lies
    near the target). Exact answers use the table's trials, ``repeats`` seeds
    per evaluation (quick 2, full 4) and bisection to 0.05 s.
    """
    from ..query import table as query

    n = n or (3 if quick else 16)
    repeats = repeats or (2 if quick else 4)
    rng = as_generator([seed, 805])
    ax = svm_table.axes
    width = float(svm_table.header["effusivity"]["width"])
    e_hi = float(svm_table.header["effusivity"]["max"])
    trials = int(svm_table.header["trials"])
    dt_c = 10.0
    rows, facts = [], {"table": svm_table.name, "repeats": repeats, "trials": trials}
    c_min, c_max = float(ax["contact_s"][0]), float(ax["contact_s"][-1])
    c_lo, c_hi = c_min + 0.05 * (c_max - c_min), c_min + 0.75 * (c_max - c_min)  # [1, 7.6] s for svm-paper
    pairs = []
    while len(pairs) < n:
        e1 = float(rng.uniform(width, e_hi / 2))
        r = float(np.exp(rng.uniform(math.log(ax["noise_ratio"][0]), math.log(ax["noise_ratio"][-1]))))
        c = float(rng.uniform(c_lo, c_hi))
        d = query.delta_e(e1, contact_s=c, noise_c=r * dt_c, delta_t_c=dt_c, table=svm_table,
                          ideal_table=svm_table).extra.get("delta_e_upper")
        if d is None or e1 + d > e_hi - width:
            continue
        pairs.append((e1, e1 + d * float(rng.uniform(1.0, 1.1)), r, c))
    res = []
    for k, (e1, e2, r, c) in enumerate(pairs):
        if progress:
            progress(f"queries: exact SVM min-contact {k + 1}/{n} ({e1:.0f} vs {e2:.0f}, sigma/dT {r:.4f})")
        t0 = time.perf_counter()
        tab = query.min_contact(e1, e2, noise_c=r * dt_c, delta_t_c=dt_c, table=svm_table, ideal_table=svm_table)
        t_tab = time.perf_counter() - t0
        ex = query.exact_min_contact(e1, e2, noise_c=r * dt_c, delta_t_c=dt_c, threshold=svm_table.threshold,
                                     sensor=svm_table.sensor, width=width, trials=trials, seed=seed + 1 + k,
                                     repeats=repeats, jobs=jobs, max_contact_s=c_max)
        res.append({"e1": e1, "e2": e2, "ratio": r, "target_s": c, "table_s": tab.value,
                    "table_interval_s": list(tab.interval), "exact_s": ex.value, "exact_interval_s": list(ex.interval),
                    "exact_wall_s": ex.extra["wall_s"], "table_wall_s": t_tab})
    facts["min-contact"] = res
    both = [x for x in res if x["table_s"] is not None and x["exact_s"] is not None]
    err = np.array([abs(x["table_s"] - x["exact_s"]) for x in both]) if both else np.array([])

    def inside(v, iv):
        lo, hi = iv
        return v is not None and (lo is None or v >= lo - 1e-9) and (hi is None or v <= hi + 1e-9)

    in_table_iv = sum(inside(x["exact_s"], x["table_interval_s"]) for x in both)
    in_exact_iv = sum(inside(x["table_s"], x["exact_interval_s"]) for x in both)
    t_ex = float(np.mean([x["exact_wall_s"] for x in res]))
    t_tab = float(np.mean([x["table_wall_s"] for x in res]))
    missing = len(res) - len(both)
    rows.append(Row("min-contact", f"table interpolation ({svm_table.name})", _grid_label(svm_table),
                    "|t_table - t_exact| [s]", _p95(err), _max(err), t_tab,
                    f"--exact (SVM, {trials} trials x {repeats} seeds, bisection to 0.05 s)", t_ex, int(err.size),
                    f"exact inside the table's interval for {in_table_iv}/{len(both)}, table inside the exact "
                    f"interval for {in_exact_iv}/{len(both)}" + (f"; {missing} without both answers" if missing else "")))
    facts["min-contact-summary"] = {"p95": _p95(err), "worst": _max(err), "n": int(err.size),
                                    "exact_in_table_interval": in_table_iv, "table_in_exact_interval": in_exact_iv,
                                    "exact_wall_s_mean": t_ex}
    # distinguishable: one exact evaluation per case
    m = 2 * n
    wrong, uncertain, t_tab_d, t_ex_d = 0, 0, 0.0, 0.0
    cases = []
    for k in range(m):
        e1, e2, r, c = pairs[k % len(pairs)]
        c = float(rng.uniform(c_lo, c_hi)) if k >= len(pairs) else c
        if progress:
            progress(f"queries: exact SVM distinguishable {k + 1}/{m}")
        t0 = time.perf_counter()
        tab = query.distinguishable(e1, e2, contact_s=c, noise_c=r * dt_c, delta_t_c=dt_c, table=svm_table,
                                    ideal_table=svm_table)
        t_tab_d += time.perf_counter() - t0
        t0 = time.perf_counter()
        ex = query.exact_distinguishable(e1, e2, contact_s=c, noise_c=r * dt_c, delta_t_c=dt_c,
                                         threshold=svm_table.threshold, sensor=svm_table.sensor, width=width,
                                         trials=trials, seed=seed + 100 + k, repeats=repeats, jobs=jobs)
        t_ex_d += time.perf_counter() - t0
        bad = bool(tab.extra["distinguishable"]) != bool(ex.extra["distinguishable"])
        wrong += bad
        uncertain += bad and ex.extra["verdict"] == "uncertain"
        cases.append({"e1": e1, "e2": e2, "ratio": r, "contact_s": c, "table": bool(tab.extra["distinguishable"]),
                      "exact_f1": ex.extra["svm_f1"], "exact_se": ex.extra["svm_standard_error"]})
    facts["distinguishable"] = {"cases": cases, "wrong": wrong, "wrong_uncertain": uncertain, "n": m}
    rows.append(Row("distinguishable", f"table interpolation ({svm_table.name})", _grid_label(svm_table),
                    "wrong verdicts (fraction)", wrong / m, wrong / m, t_tab_d / m,
                    f"--exact (SVM, {trials} trials x {repeats} seeds)", t_ex_d / m, m,
                    f"{uncertain} of {wrong} wrong verdicts were within 2 SE of the threshold"))
    return rows, facts


# ============================================================ cost curve
def _proc_status_mb(key: str) -> float | None:
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) / 1024.0  # kB
    except (OSError, ValueError):
        pass
    return None


def _reset_peak_memory() -> float | None:
    """Reset this process's peak resident set (Linux ``clear_refs``); its current resident set [MB].

    None where the kernel does not offer it (then no memory is reported).
    """
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
    except OSError:
        return None
    return _proc_status_mb("VmRSS")


def measure(fn: Callable[[], Any]) -> tuple[Any, float, float | None, float | None]:
    """``fn()``, its wall time [s], and the peak resident set during it [MB] and above its start [MB].

    Peak memory uses Linux's resettable high-water mark (``/proc/self/clear_refs``,
    ``VmHWM``), so it is this call's own peak, not the process's lifetime peak.
    """
    start = _reset_peak_memory()
    t0 = time.perf_counter()
    out = fn()
    wall = time.perf_counter() - t0
    peak = _proc_status_mb("VmHWM") if start is not None else None
    return out, wall, peak, (None if peak is None else max(peak - start, 0.0))


@dataclass(frozen=True)
class ProcessCost:
    """Wall time and peak resident memory of one child process."""

    wall_s: float
    max_rss_mb: float
    returncode: int
    stdout: str
    stderr: str


def process_cost(cmd: Sequence[str], *, env: Mapping[str, str] | None = None, timeout: float = 600.0,
                 cwd: str | None = None) -> ProcessCost:
    """Run ``cmd`` as a child process: its wall time and peak resident set (``wait4`` rusage).

    The peak is the child's own (``ru_maxrss`` of exactly that process, not of
    every child this process ever had).
    """
    import subprocess
    import tempfile

    run_env = dict(os.environ)
    if env:
        run_env.update(env)
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        proc = subprocess.Popen(list(cmd), stdout=out, stderr=err, env=run_env, cwd=cwd)
        import threading

        timer = threading.Timer(timeout, proc.kill)  # a hung child is killed, not waited for forever
        timer.start()
        try:
            _, status, usage = os.wait4(proc.pid, 0)
        finally:
            timer.cancel()
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        return ProcessCost(wall, usage.ru_maxrss / 1024.0, proc.returncode, out.read().decode(errors="replace"),
                           err.read().decode(errors="replace"))


def cost_curve(name: str, variable: str, values: Sequence[float], base: Mapping[str, Any],
               setting: str = "", relative_to_mb: float | None = None) -> CostCurve:
    """Run the engine on one scene point for each value of ``variable`` and fit the exponents.

    ``variable`` is a :class:`~designkit.engine.SweepConfig` field (``intervals``,
    ``trials``), ``contact_s`` (one contact time of that length) or ``contacts``
    (that many contact times from 0.5 s to 10 s, swept with warm starts).
    Each point is ``run_scene`` + ``assemble`` (what a sweep does per scene).
    Memory: each point's peak resident set above ``relative_to_mb`` (the
    process after its imports, see :func:`cost_curves`), else above the
    resident set when the point started.
    """
    from ..sweep.engine import SweepConfig, assemble, run_scene

    xs, walls, fits, peaks, extra = [], [], [], [], []
    for v in values:
        kw = dict(base)
        if variable == "contact_s":
            kw["contact_s"] = (float(v),)
        elif variable == "contacts":
            kw["contact_s"] = tuple(float(x) for x in np.linspace(0.5, 10.0, int(v)))
        else:
            kw[variable] = int(v)
        cfg = SweepConfig(**kw)

        def sweep_one_scene(cfg=cfg):
            chunks = run_scene(cfg)
            assemble(cfg, chunks)
            return chunks

        chunks, wall, peak, above = measure(sweep_one_scene)
        xs.append(float(v))
        walls.append(wall)
        fits.append(int(sum(c.fits for c in chunks)))
        peaks.append(math.nan if peak is None else peak)
        if relative_to_mb is not None and peak is not None:
            above = max(peak - relative_to_mb, 0.0)
        extra.append(math.nan if above is None else above)
    svm = base.get("fidelity") == "svm"
    mem = np.asarray(extra)
    usable = np.isfinite(mem) & (mem > 1.0)  # below 1 MB the high-water mark is noise
    per_fit = [w / f for w, f in zip(walls, fits)] if svm and all(fits) else None
    note = ""
    if per_fit is not None:
        note = (f"time per SVM fit {', '.join(f'{x:.3g}' for x in per_fit)} s "
                f"(exponent {fit_exponent(xs, per_fit):.2f})")
    return CostCurve(
        name=name, variable=variable, fidelity=str(base.get("fidelity")), x=tuple(xs), wall_s=tuple(walls),
        fits=tuple(fits), peak_mb=tuple(float(m) for m in mem),
        base_mb=float(relative_to_mb) if relative_to_mb is not None else
        (float(np.nanmax(np.asarray(peaks) - mem)) if np.isfinite(mem).any() else math.nan),
        time_exponent=fit_exponent(xs, walls),
        fits_exponent=fit_exponent(xs, fits) if svm else None,
        memory_exponent=fit_exponent(np.asarray(xs)[usable], mem[usable]) if np.count_nonzero(usable) >= 2 else None,
        setting=setting, note=note)


def _curve_in_fresh_process(name, variable, values, base, setting) -> CostCurve:
    """Body of :func:`cost_curves` in a child: warm up, take the baseline, run the curve."""
    from ..sweep.engine import SweepConfig, assemble, run_scene

    warm = SweepConfig(**{**base, "intervals": 4, "trials": 6, "contact_s": (0.5,)})
    assemble(warm, run_scene(warm))  # imports, BLAS and libsvm loaded before the baseline
    import gc

    gc.collect()
    return cost_curve(name, variable, values, base, setting, relative_to_mb=_proc_status_mb("VmRSS"))


def cost_curves(quick: bool = True, seed: int = 0, *, isolated: bool = True,
                progress: Callable[[str], None] | None = None) -> list[CostCurve]:
    """Wall time, SVM fits and peak memory of the engine against the size of the work.

    Ideal fidelity for the big ranges (intervals up to 2000-4000, up to 16
    contact times), SVM on small ones (intervals, trials per interval,
    contact time). One scene point each (sigma/dT 0.005); a whole table
    multiplies by the number of scene points. With ``isolated`` each curve
    runs in a fresh process, and its memory is the peak resident set above
    that process's resident set after imports (the points run in increasing
    order, so each peak is that point's).
    """
    ideal = dict(name="bench", fidelity="ideal", noise_ratio=(PAPER_RATIO,), contact_s=(2.0,), seed=seed)
    svm = dict(name="bench", fidelity="svm", noise_ratio=(PAPER_RATIO,), contact_s=(1.0,), seed=seed,
               intervals=12, trials=50, max_repeats=2)
    if quick:
        specs = [
            ("ideal: intervals", "intervals", (250, 500, 1000, 2000), ideal, "contact 2 s"),
            ("ideal: contact times per table", "contacts", (2, 4, 8), {**ideal, "intervals": 125},
             "125 intervals, contacts 0.5..10 s"),
            ("SVM: intervals", "intervals", (8, 16, 32), svm, "50 trials, contact 1 s"),
            ("SVM: trials per interval", "trials", (25, 50, 100), svm, "12 intervals, contact 1 s"),
            ("SVM: contact time", "contact_s", (0.5, 1.0, 2.0, 4.0), svm, "12 intervals, 50 trials"),
        ]
    else:
        specs = [
            ("ideal: intervals", "intervals", (125, 250, 500, 1000, 2000, 4000), ideal, "contact 2 s"),
            ("ideal: contact times per table", "contacts", (2, 4, 8, 16), {**ideal, "intervals": 250},
             "250 intervals, contacts 0.5..10 s"),
            ("SVM: intervals", "intervals", (10, 20, 40, 80), {**svm, "intervals": 16}, "50 trials, contact 1 s"),
            ("SVM: trials per interval", "trials", (25, 50, 100, 200), {**svm, "intervals": 16},
             "16 intervals, contact 1 s"),
            ("SVM: contact time", "contact_s", (0.5, 1.0, 2.0, 4.0, 8.0), {**svm, "intervals": 16},
             "16 intervals, 50 trials"),
        ]
    out = []
    for name, var, values, base, setting in specs:
        if progress:
            progress(f"cost curve: {name}")
        if isolated:
            import multiprocessing as mp
            from concurrent.futures import ProcessPoolExecutor

            # a fresh process per curve: its resident set holds nothing but the curve's own work
            with ProcessPoolExecutor(max_workers=1, mp_context=mp.get_context("spawn")) as ex:
                out.append(ex.submit(_curve_in_fresh_process, name, var, values, base, setting).result())
        else:
            out.append(cost_curve(name, var, values, base, setting))
    return out


# ============================================================ the whole run
def _environment() -> dict[str, Any]:
    import numpy
    import scipy

    env = {"python": platform.python_version(), "numpy": numpy.__version__, "scipy": scipy.__version__,
           "machine": platform.machine(), "cpus": os.cpu_count()}
    try:
        import sklearn

        env["scikit-learn"] = sklearn.__version__
    except ImportError:  # pragma: no cover
        pass
    try:
        env["load_average_at_start"] = [round(x, 2) for x in os.getloadavg()]
    except OSError:  # pragma: no cover
        pass
    from .. import __version__

    env["designkit"] = __version__
    return env


def run_bench(*, quick: bool = True, seed: int = 0, sections: Iterable[str] = SECTIONS,
              svm_table: str | None = "svm-paper", ideal_table: str = "ideal-paper", jobs: int = 1,
              progress: Callable[[str], None] | None = None) -> BenchReport:
    """Run the selected sections and collect a :class:`BenchReport`.

    Parameters
    ----------
    quick : bool
        Fewer cases and smaller references (``designkit bench --quick``:
        a few minutes on 2 cores); the full run takes longer.
    seed : int
        Seed of every random draw.
    sections : iterable of str
        Any of :data:`SECTIONS`.
    svm_table, ideal_table : str
        Tables whose queries are measured; a missing SVM table is skipped
        (and listed in ``skipped``).
    jobs : int
        Processes for the exact SVM queries (1: sequential timing).
    progress : callable, optional
        Called with a short description before each step.
    """
    sections = tuple(sections)
    bad = [s for s in sections if s not in SECTIONS]
    if bad:
        raise InputError(f"unknown bench section(s) {', '.join(bad)} (choose from {', '.join(SECTIONS)})")
    env = _environment()
    t_start = time.perf_counter()
    rows: list[Row] = []
    curves: list[CostCurve] = []
    facts: dict[str, Any] = {}
    skipped: list[str] = []
    section_wall: dict[str, float] = {}
    say = progress or (lambda _msg: None)
    for sec in SECTIONS:
        if sec not in sections:
            continue
        t0 = time.perf_counter()
        if sec == "physics":
            say("physics: eq. 2 against mpmath")
            rows += physics_rows(quick, seed)
            say("physics: thin-sample solvers")
            rows += slab_rows(quick)
        elif sec == "recognition":
            say("recognition: ideal observer closed form vs Monte Carlo")
            rows += ideal_mc_rows(quick, seed)
            rows += recognition_rows(quick, seed, progress=say)
        elif sec == "delta":
            rows += delta_rows(quick, seed, progress=say)
        elif sec == "queries":
            from ..tables.store import load_table

            say(f"queries: {ideal_table} against the exact ideal observer")
            itab = load_table(ideal_table)
            r, f = query_rows(itab, quick, seed)
            rows += r
            facts[f"queries:{itab.name}"] = f
            svm = None
            if svm_table:
                try:
                    svm = load_table(svm_table)
                except InputError as exc:
                    skipped.append(f"queries against {svm_table}: {exc}")
            say("queries: table density")
            rows += density_rows(itab, quick, seed, svm_axes=None if svm is None else
                                 {k: svm.axes[k] for k in ("noise_ratio", "contact_s")})
            if svm is not None:
                r, f = svm_query_rows(svm, quick, seed, jobs=jobs, progress=say)
                rows += r
                facts[f"queries:{svm.name}"] = f
        elif sec == "cost":
            curves += cost_curves(quick, seed, progress=say)
        section_wall[sec] = time.perf_counter() - t0
    return BenchReport(rows=tuple(rows), curves=tuple(curves), facts=facts, quick=quick, seed=seed,
                       wall_s=time.perf_counter() - t_start, environment=env, skipped=tuple(skipped),
                       section_wall_s=section_wall)


# ============================================================ report
def _fmt(x: float, digits: int = 2) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "—"
    if x == 0:
        return "0"
    if abs(x) >= 1e4 or abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}" if abs(x) >= 1 else f"{x:.{digits}g}"


def _fmt_time(s: float) -> str:
    if s is None or not math.isfinite(s):
        return "—"
    if s < 1e-3:
        return f"{s * 1e6:.3g} µs"
    if s < 1:
        return f"{s * 1e3:.3g} ms"
    return f"{s:.3g} s"


def _cell(text: Any) -> str:
    """A markdown table cell: pipes escaped (metrics like |t - t_exact| contain them)."""
    return str(text).replace("|", "\\|")


def rows_markdown(rows: Sequence[Row]) -> str:
    """Markdown table of rows (one question's rows: the question is the section heading)."""
    head = "| method | setting | metric | p95 / value | worst | time per answer | reference | " \
           "reference time | speed-up | n | note |"
    lines = [head, "|" + "---|" * 11]
    for r in rows:
        cells = [r.method, r.setting, r.metric, _fmt(r.error, 3), _fmt(r.worst, 3), _fmt_time(r.wall_s), r.reference,
                 _fmt_time(r.reference_wall_s), _fmt(r.speedup, 3), r.n, r.note]
        lines.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    return "\n".join(lines)


def curves_markdown(curves: Sequence[CostCurve]) -> str:
    """Markdown table of cost curves with their exponents."""
    lines = ["| curve | setting | x | wall time [s] | SVM fits | peak memory above baseline [MB] | "
             "time exponent | fits exponent | memory exponent | note |", "|" + "---|" * 10]
    for c in curves:
        lines.append(
            f"| {_cell(c.name)} | {_cell(c.setting)} | {', '.join(f'{x:g}' for x in c.x)} | "
            f"{', '.join(f'{w:.3g}' for w in c.wall_s)} | {', '.join(str(f) for f in c.fits)} | "
            f"{', '.join(f'{m:.1f}' for m in c.peak_mb)} (process at {c.base_mb:.0f}) | {_fmt(c.time_exponent, 3)} | "
            f"{_fmt(c.fits_exponent, 3) if c.fits_exponent is not None else '—'} | "
            f"{_fmt(c.memory_exponent, 3) if c.memory_exponent is not None else '—'} | {c.note} |")
    return "\n".join(lines)


def plot_pareto(report: BenchReport, path) -> Any:
    """Error against time per answer, one panel per question (log-log), saved as PNG."""
    from pathlib import Path

    from ..figures import pyplot

    fig = pareto_figure(report)
    if fig is None:
        return None
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    pyplot().close(fig)
    return path


def pareto_figure(report: BenchReport) -> Any:
    """The matplotlib figure of :func:`plot_pareto` (None without rows)."""
    from ..figures import pyplot

    plt = pyplot()
    from matplotlib.ticker import NullFormatter

    groups: dict[str, list[Row]] = {}
    for r in report.rows:
        groups.setdefault(r.question, []).append(r)
    n_panels = len(groups)
    if n_panels == 0:
        return None
    ncol = 3
    nrow = math.ceil(n_panels / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.2 * ncol, 3.4 * nrow), constrained_layout=True, squeeze=False)
    for ax, (question, rows) in zip(axes.ravel(), groups.items()):
        methods = sorted({r.method for r in rows})
        floor = min([r.error for r in rows if r.error > 0] + [1.0]) / 10
        for m_i, m in enumerate(methods):
            sel = [r for r in rows if r.method == m]
            xs = [r.wall_s for r in sel]
            ys = [r.error if r.error > 0 else floor for r in sel]
            ax.scatter(xs, ys, s=22, color=f"C{m_i}", label=m[:40], zorder=3,
                       marker="o" if all(r.error > 0 for r in sel) else "v")
            for r, x, y in zip(sel, xs, ys):
                ax.annotate(r.setting[:22], (x, y), fontsize=5.5, xytext=(3, 2), textcoords="offset points")
        refs: dict[str, float] = {}
        for r in rows:
            if math.isfinite(r.reference_wall_s):
                refs.setdefault(r.reference, r.reference_wall_s)
        for ref_i, (name, t) in enumerate(refs.items()):
            ax.scatter([t], [floor], marker="*", s=70, color="k", zorder=4,
                       label="reference" if ref_i == 0 else None)
            ax.annotate(name[:26], (t, floor), fontsize=5.5, xytext=(3, 4), textcoords="offset points",
                        color="0.3")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.yaxis.set_minor_formatter(NullFormatter())
        ax.set_title(question, fontsize=9)
        ax.set_xlabel("time per answer [s]", fontsize=7)
        ax.set_ylabel(rows[0].metric[:48], fontsize=7)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=5.5, loc="best")
    for ax in axes.ravel()[n_panels:]:
        ax.set_visible(False)
    fig.suptitle("designkit: error against run time per answer (★ reference, drawn at the panel's floor; "
                 "▼ error 0)", fontsize=10)
    return fig


def plot_costs(report: BenchReport, path) -> Any:
    """The sweep's cost curves (time and memory against size), log-log, saved as PNG."""
    from pathlib import Path

    from ..figures import pyplot

    if not report.curves:
        return None
    plt = pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True)
    for i, c in enumerate(report.curves):
        x = np.asarray(c.x) / c.x[0]
        a1.plot(x, c.wall_s, "o-", color=f"C{i}", ms=3, label=f"{c.name} (p = {c.time_exponent:.2f})")
        mem = np.asarray(c.peak_mb)
        ok = np.isfinite(mem) & (mem > 0.5)  # below about 1 MB the high-water mark is noise
        if np.any(ok):
            exp = "" if c.memory_exponent is None else f" (p = {c.memory_exponent:.2f})"
            a2.plot(x[ok], mem[ok], "o-", color=f"C{i}", ms=3, label=c.name + exp)
    from matplotlib.ticker import NullFormatter

    for ax, lab in ((a1, "wall time [s]"), (a2, "peak memory above baseline [MB]")):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.yaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("size relative to the curve's first point")
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.suptitle("Sweep engine cost curves (one scene point)", fontsize=10)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _q(facts, table, question, key, default=math.nan):
    return facts.get(f"queries:{table}", {}).get(question, {}).get(key, default)


def render_markdown(report: BenchReport, figures: Mapping[str, str] | None = None) -> str:
    """``docs/accuracy.md``: what error to expect from each query, and how to buy more with time."""
    figures = figures or {}
    f = report.facts
    ideal = next((k.split(":", 1)[1] for k in f if k.startswith("queries:") and
                  f[k].get("table", "").startswith("ideal")), None)
    svm = next((k.split(":", 1)[1] for k in f if k.startswith("queries:") and "repeats" in f[k]), None)
    mode = "--quick" if report.quick else "(full run)"
    env = report.environment
    out = [
        "# Accuracy against run time",
        "",
        f"<!-- GENERATED by `designkit bench {'--quick ' if report.quick else ''}--out docs`: do not edit by hand; "
        "re-run the command to refresh. -->",
        "",
        f"Generated by `designkit bench {mode} --out docs` (seed {report.seed}) in {report.wall_s / 60:.1f} min on "
        f"{env.get('cpus')} CPUs (load average at start {env.get('load_average_at_start')}), designkit "
        f"{env.get('designkit')}, numpy {env.get('numpy')}, scipy {env.get('scipy')}, scikit-learn "
        f"{env.get('scikit-learn')}. Every error below is measured against a high-fidelity reference computed in "
        "the same run; every speed-up is a ratio of two times measured in that run. Timings on a shared machine "
        "vary by tens of percent; errors are reproducible with the same seed.",
        "",
    ]
    if report.skipped:
        out += ["Skipped in this run: " + "; ".join(report.skipped), ""]

    out += ["## What error to expect from the shipped tables", ""]
    if ideal:
        mc = f[f"queries:{ideal}"]
        n = mc.get("n")
        out += [
            f"Measured over {n} random pairs and scenes spread across the grid of `{ideal}` (effusivity uniform, "
            "sigma/dT log-uniform over the table's range, the partner placed so that the exact answer lies inside "
            "the grid), against the exact ideal-observer answer for the same classes (closed form, bisection, what "
            "`--exact` computes for the ideal bound):",
            "",
            "| query | error metric | median | 95th percentile | worst |",
            "|---|---|---|---|---|",
        ]
        for q in ("min-contact", "max-noise", "min-delta-t", "delta-e"):
            if q in mc:
                d = mc[q]
                out.append(f"| `{q}` | {_cell(d['metric'])} | {_fmt(d['median'], 3)} | {_fmt(d['p95'], 3)} | "
                           f"{_fmt(d['worst'], 3)} |")
        if "min-contact" in mc and "relative_p95" in mc["min-contact"]:
            d = mc["min-contact"]
            out.append(f"| `min-contact` | relative error | — | {100 * d['relative_p95']:.1f} % | "
                       f"{100 * d['relative_worst']:.1f} % |")
        if "delta-e" in mc and "relative_p95" in mc["delta-e"]:
            d = mc["delta-e"]
            out.append(f"| `delta-e` | relative error | — | {100 * d['relative_p95']:.1f} % | "
                       f"{100 * d['relative_worst']:.1f} % |")
        if "distinguishable" in mc:
            d = mc["distinguishable"]
            out.append(f"| `distinguishable` | wrong verdicts, pairs within -20..+25 % of the boundary | "
                       f"{100 * d['wrong_fraction']:.1f} % | — | wrong ones at most "
                       f"{100 * d['farthest_wrong_relative']:.0f} % from the boundary |")
        out += ["",
                f"A table query takes {_fmt_time(mc.get('time_per_table_query_s', math.nan))} in-process with the "
                "table loaded (see `benchmarks/bench_query.py` for the fresh-shell time).", ""]
        unres = mc.get("unresolved_fraction")
        if "min-contact" in mc and "by_gap" in mc["min-contact"]:
            out += ["**Where the error comes from.** A table's delta(e) is a whole number of effusivity intervals "
                    "(80 wide for the shipped tables): the first interval that is distinguishable. For pairs only a "
                    "few intervals apart this rounding dominates, and because delta falls slowly with contact at "
                    "long contacts, a fraction of an interval becomes seconds of contact time. The error by the "
                    "pair's distance:", "",
                    "| distance [intervals] | pairs | with a table answer | `min-contact` median [s] | p95 [s] | "
                    "worst [s] | `max-noise` median | p95 |",
                    "|---|---|---|---|---|---|---|---|"]
            mn = {tuple(b["gap_intervals"]): b for b in mc.get("max-noise", {}).get("by_gap", [])}
            for b in mc["min-contact"]["by_gap"]:
                a_, z_ = b["gap_intervals"]
                m = mn.get((a_, z_), {})
                out.append(f"| {a_:g} – {'∞' if not math.isfinite(z_) else f'{z_:g}'} | {b['pairs']} | "
                           f"{b['answered']} | {_fmt(b['median'], 3)} | {_fmt(b['p95'], 3)} | {_fmt(b['worst'], 3)} | "
                           f"{_fmt(m.get('median', math.nan), 3)} | {_fmt(m.get('p95', math.nan), 3)} |")
            cons = mc["min-contact"].get("conservative_fraction")
            out += ["",
                    f"The table errs on the safe side: its `min-contact` was at or above the exact answer for "
                    f"{100 * cons:.0f} % of the pairs" + (
                        f" and its `max-noise` at or below for {100 * mc['max-noise']['conservative_fraction']:.0f} %"
                        if "conservative_fraction" in mc.get("max-noise", {}) else "") +
                    ". Pairs closer than one interval cannot be resolved by a table at all: "
                    + (f"{100 * unres:.0f} % of the random boundary pairs drawn were (they were drawn again; "
                       "use `--exact` for such pairs). " if unres is not None and math.isfinite(unres) else "")
                    + "A second, smaller source is linear interpolation in contact time of a need that is convex in "
                    "it, and a neighbouring grid point with no answer (beyond the grid), which makes the query fall "
                    "back to the next grid point.", ""]
    if svm:
        s = f[f"queries:{svm}"]
        mcs = s.get("min-contact-summary", {})
        dd = s.get("distinguishable", {})
        out += [
            f"`{svm}` (the paper's SVM) against `--exact` ({s['trials']} trials per class, {s['repeats']} seeds per "
            f"evaluation) over {mcs.get('n')} random pairs: `min-contact` error 95th percentile "
            f"{_fmt(mcs.get('p95'), 3)} s, worst {_fmt(mcs.get('worst'), 3)} s; the exact answer lay inside the "
            f"table's Monte Carlo interval for {mcs.get('exact_in_table_interval')} of {mcs.get('n')} pairs. "
            f"`distinguishable`: {dd.get('wrong')} wrong verdicts of {dd.get('n')} near-boundary cases "
            f"({dd.get('wrong_uncertain')} of them within 2 standard errors of the threshold, i.e. undecidable at "
            f"that Monte Carlo effort). One `--exact min-contact` took {_fmt_time(mcs.get('exact_wall_s_mean'))} "
            "here.",
            ""]
        out += ["The SVM table's error has two parts: interpolation (how far apart its grid points are; the "
                "density rows below measure it on the ideal table cut to the SVM table's axes) and Monte Carlo "
                "(100 trials per class; the recognition rows measure it).", ""]
    else:
        out += ["`svm-paper` (the paper's SVM) was not available when this page was generated; its interpolation "
                "error on its own grid is estimated by the density rows below (the ideal table cut to sparser "
                "axes), and its Monte Carlo error by the recognition rows. Regenerate this page once the table is "
                "built: `designkit bench --out docs`.", ""]

    out += [
        "## How to buy more accuracy with time",
        "",
        "- **`--exact`** computes the one pair and scene you ask about instead of interpolating: no grid error "
        "at all, at the price of seconds instead of milliseconds (rows `min-contact` and `distinguishable` "
        "below give both times).",
        "- **`--exact --repeats R`** averages R seeds per evaluation; the Monte Carlo error of an F1 falls as "
        "1/sqrt(R) at R times the cost (rows `SVM F1`: trials x seeds). **`--trials T`** trains on more "
        "touches: it removes the bias of a small training set (the reference is the large-sample SVM), with a "
        "cost per fit growing about as T^p (cost curve `SVM: trials per interval`).",
        "- **Denser tables** (`designkit sweep` with more `noise_ratio` / `contact_s` points) cut the "
        "interpolation error roughly with the square of the spacing; rows `table interpolation (density)` show "
        "it on the same sweep with points left out. The build time grows linearly with the number of points "
        "(cost curve `ideal: contact times per table`).",
        "- **`max_repeats`** in a sweep config re-scores pairs near the threshold with more seeds, narrowing "
        "delta's Monte Carlo interval; the cost grows only for the few pairs near the threshold.",
        "- **More intervals** (`--intervals`) narrow each effusivity class: rows `delta(e)` give the error of a "
        "125/250/500-interval grid against a fine one; the cost grows about linearly (cost curves).",
        "",
        "## All measurements",
        "",
    ]
    if "pareto" in figures:
        out += [f"![error against run time]({figures['pareto']})", ""]
    groups: dict[str, list[Row]] = {}
    for r in report.rows:
        groups.setdefault(r.question, []).append(r)
    for q, rows in groups.items():
        out += [f"### {q}", "", rows_markdown(rows), ""]
    if report.curves:
        out += ["## The sweep's cost curve", "",
                "One scene point; a table costs this times its number of scene points. Exponents are "
                "least-squares slopes of log cost against log size. Memory: each point's peak resident set (Linux's "
                "resettable high-water mark) above the resident set of a fresh process after its imports; each "
                "curve runs in its own process, points in increasing order.", ""]
        if "cost" in figures:
            out += [f"![cost curves]({figures['cost']})", ""]
        out += [curves_markdown(report.curves), ""]
    out += ["## Related benchmarks", "",
            "Scripts in `benchmarks/` measure the performance targets against baselines in the same run:",
            "`bench_query.py` (a table query from a fresh shell against `python -c pass` and `import numpy`, "
            "what it imports, in-process time, memory), `bench_exact.py` (`--exact` min-contact for one pair "
            "against the table), `bench_delta_e.py` (staircase search against the full F1 matrix as the grid "
            "grows), `bench_memory.py` (peak memory of sweeps and queries), `bench_slab.py` (thin-sample "
            "solvers, see thin_samples.md) and `bench_export.py` (exported tables).", ""]
    out += ["## Section wall times", "",
            ", ".join(f"{k} {v:.0f} s" for k, v in report.section_wall_s.items()) +
            f"; total {report.wall_s:.0f} s.", ""]
    return "\n".join(out)


def write_report(report: BenchReport, out_dir) -> dict[str, Any]:
    """Write ``accuracy.md``, its figures and ``accuracy.json`` into ``out_dir``; returns the paths."""
    import json
    from pathlib import Path

    from .._io import atomic_write_text

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    figs = {}
    p = plot_pareto(report, out_dir / "accuracy_pareto.png")
    if p is not None:
        figs["pareto"] = p.name
    p = plot_costs(report, out_dir / "accuracy_cost.png")
    if p is not None:
        figs["cost"] = p.name
    md = atomic_write_text(out_dir / "accuracy.md", render_markdown(report, figs))
    js = atomic_write_text(out_dir / "accuracy.json",
                           json.dumps(_jsonable(report.to_dict()), indent=1, allow_nan=False) + "\n")
    return {"markdown": md, "json": js, **{k: out_dir / v for k, v in figs.items()}}


def _jsonable(obj):
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.generic):
        return _jsonable(obj.item())
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj
