"""Section ``recognition``: the classifiers' F1 against long runs of themselves.

SVM F1 with 25-200 trials per class and 1-8 seed repeats against a long run
(more trials, several seeds); the ideal observer's closed form against its
own Monte Carlo (:func:`designkit.recognition.ideal.ideal_pair` on a scene
with a 1e-6 degC sensor-temperature spread takes the Monte Carlo path).
"""

from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np

from .instruments import timed
from .results import Row, paper_sensor

__all__ = ["RECOGNITION_PAIRS", "ideal_mc_rows", "recognition_rows"]

#: Pairs near the threshold at the paper's scene (sigma 0.05 degC, dT 10 degC):
#: (lower class start, higher class start, contact [s]); classes 80 wide.
RECOGNITION_PAIRS = ((20000.0, 35000.0, 1.0), (5000.0, 6000.0, 1.25), (1000.0, 1150.0, 1.0))
_WIDTH = 80.0


def _paper_scene(contact_s: float):
    from designkit.scene import Scene

    return Scene.from_delta_t(contact_s=contact_s, noise_c=0.05, delta_t_c=10.0)


def _svm_runs(pairs, trials, pool, t_ref, r_ref, seed, progress):
    """Reference F1 per pair (mean, SE, time per seed) and ``pool`` single-seed F1s per trial count."""
    from designkit.recognition.svm import interval_pair_f1

    sensor = paper_sensor()
    est: dict[int, list[np.ndarray]] = {t: [] for t in trials}
    fit_time: dict[int, float] = {t: 0.0 for t in trials}
    refs, ref_se, ref_time = [], [], 0.0
    for a, b, contact in pairs:
        scene, ra, rb = _paper_scene(contact), (a, a + _WIDTH), (b, b + _WIDTH)
        if progress:
            progress(f"recognition: reference {a:g} vs {b:g} at {contact:g} s")
        vals, sec = timed(lambda: [interval_pair_f1(ra, rb, sensor, scene, trials=t_ref, seed=[seed, 9000 + k]).f1
                                   for k in range(r_ref)])
        refs.append(float(np.mean(vals)))
        ref_se.append(float(np.std(vals, ddof=1) / math.sqrt(r_ref)))
        ref_time += sec / r_ref
        for t in trials:
            if progress:
                progress(f"recognition: {t} trials, {a:g} vs {b:g}")
            vals, sec = timed(lambda: [interval_pair_f1(ra, rb, sensor, scene, trials=t, seed=[seed, 100 + k]).f1
                                       for k in range(pool)])
            est[t].append(np.asarray(vals))
            fit_time[t] += sec / pool
    return refs, ref_se, ref_time, est, fit_time


def _repeat_errors(est_t, refs, r) -> np.ndarray:
    """Errors of r-seed means (disjoint groups of the single-seed values) against the references."""
    errs = []
    for vals, ref in zip(est_t, refs):
        groups = vals[: (vals.size // r) * r].reshape(-1, r).mean(axis=1)
        errs.extend(groups - ref)
    return np.asarray(errs)


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

    Returns
    -------
    list of Row
        One per trial count and number of repeats.
    """
    pairs = RECOGNITION_PAIRS[:2] if (pairs is None and quick) else (pairs or RECOGNITION_PAIRS)
    pool = max(repeats) * (1 if quick else 2)
    t_ref, r_ref = (400, 4) if quick else (800, 8)
    refs, ref_se, ref_time, est, fit_time = _svm_runs(pairs, trials, pool, t_ref, r_ref, seed, progress)
    n_pairs = len(pairs)
    ref_time /= n_pairs
    rows = []
    ref_label = f"SVM, {t_ref} trials/class, mean of {r_ref} seeds"
    for t in trials:
        per_fit = fit_time[t] / n_pairs
        for r in repeats:
            errs = _repeat_errors(est[t], refs, r)
            rms = float(np.sqrt(np.mean(errs ** 2)))
            rows.append(Row("SVM F1", "SVM (paper pipeline, 3-fold)", f"{t} trials x {r} seed{'s' if r > 1 else ''}",
                            "RMS |F1 - F1_ref|", rms, float(np.max(np.abs(errs))), per_fit * r, ref_label,
                            ref_time * r_ref, errs.size,
                            f"bias {float(np.mean(errs)):+.3f}; reference's own SE <= {max(ref_se):.3f}"))
    return rows


def _ideal_runs(pairs, n_mc, seed):
    """Closed-form F1 per pair and its time; Monte Carlo (F1, SE) per pair and time per ``n_mc``."""
    from designkit.recognition.ideal import ideal_pair

    sensor = paper_sensor()
    cf_vals, cf_time = [], 0.0
    mc: dict[int, list[tuple[float, float]]] = {n: [] for n in n_mc}
    mc_time: dict[int, float] = {n: 0.0 for n in n_mc}
    for k, (a, b, contact) in enumerate(pairs):
        scene, ra, rb = _paper_scene(contact), (a, a + _WIDTH), (b, b + _WIDTH)
        r, sec = timed(lambda: ideal_pair(ra, rb, sensor, scene), 3)
        cf_vals.append(r.f1)
        cf_time += sec
        varied = scene.replace(sensor_temp_spread_c=1e-6)
        for n in n_mc:
            r, sec = timed(lambda: ideal_pair(ra, rb, sensor, varied, n_mc=n, seed=[seed, 700 + k]))
            if r.method != "monte-carlo":
                raise RuntimeError("ideal_pair did not take the Monte Carlo path")
            mc[n].append((r.f1, r.standard_error))
            mc_time[n] += sec
    return cf_vals, cf_time, mc, mc_time


def _mc_diffs(mc_n, cf_vals) -> tuple[np.ndarray, np.ndarray]:
    """|F1_MC - F1_closed| and the Monte Carlo standard errors, per pair."""
    diffs = np.array([abs(f - c) for (f, _), c in zip(mc_n, cf_vals)])
    return diffs, np.array([s for _, s in mc_n])


def ideal_mc_rows(quick: bool = True, seed: int = 0, *, pairs=None,
                  n_mc: Sequence[int] | None = None) -> list[Row]:
    """The ideal observer's closed form against its own Monte Carlo.

    :func:`designkit.recognition.ideal.ideal_pair` takes the Monte Carlo path
    (exact likelihood, simulated touches) when the scene varies the sensor
    temperature; a spread of 1e-6 degC makes that path answer the same
    question as the closed form. Rows: Monte Carlo at each ``n_mc`` (error
    against the closed form), and the closed form (error against the largest
    Monte Carlo run, with that run's standard error in the note).

    Returns
    -------
    list of Row
        One per ``n_mc``, then the closed form's.
    """
    pairs = pairs or RECOGNITION_PAIRS
    n_mc = tuple(n_mc or ((500, 2000, 8000) if quick else (500, 2000, 8000, 32000)))
    cf_vals, cf_time, mc, mc_time = _ideal_runs(pairs, n_mc, seed)
    m = len(pairs)
    rows = []
    for n in n_mc:
        diffs, ses = _mc_diffs(mc[n], cf_vals)
        rows.append(Row("ideal F1", "ideal observer, Monte Carlo", f"n_mc = {n} per class",
                        "|F1_MC - F1_closed|", float(np.mean(diffs)), float(diffs.max()), mc_time[n] / m,
                        "ideal observer, closed form", cf_time / m, m,
                        f"MC standard error {ses.mean():.4f}; largest |diff|/SE {float((diffs / ses).max()):.1f}"))
    n_big = n_mc[-1]
    diffs, ses = _mc_diffs(mc[n_big], cf_vals)
    rows.append(Row("ideal F1", "ideal observer, closed form", "Gauss-Legendre + golden section",
                    "|F1_closed - F1_MC|", float(np.mean(diffs)), float(diffs.max()), cf_time / m,
                    f"ideal observer, Monte Carlo n_mc = {n_big}", mc_time[n_big] / m, m,
                    f"agrees within {float((diffs / ses).max()):.1f} MC standard errors ({ses.mean():.4f}); "
                    f"tests/test_ideal.py checks it against mpmath"))
    return rows
