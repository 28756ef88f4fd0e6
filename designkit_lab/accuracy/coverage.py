"""The coverage benchmark: do the stated intervals cover the truth, and how far off are the answers?

Every question is asked, by the table route and by ``--exact`` (the product's
defaults: 100 touches per class, 4 seeds), for random pairs and scenes, and
compared with a **reference**: the same exact estimate with ``ref_repeats``
seeds (16 by default, 4x the answer's, disjoint from them; the SE is half the
answer's) solved by the batched SVM (:mod:`designkit.recognition.batched_svm`,
the same classifier, ~3x faster). For each (question, route) it reports

* **coverage**: the fraction of stated intervals that contain the reference value
  (answers whose interval has no stated coverage are counted apart, ``unstated``);
* the **error** of the answer against the reference: median and 95th percentile,
  absolute and relative;
* the **ideal-bound violations**: cases where the SVM's reference F1 at the
  ideal observer's answer already passes the threshold clearly (by
  ``z(coverage)`` standard errors): the bound would then not be a bound.

The reference's own Monte Carlo error dilutes coverage: an exactly calibrated
90 % interval measured against a reference with half its standard error covers
``2 Phi(1.645 / sqrt(1.25)) - 1 = 85.9 %`` of references
(:func:`diluted_coverage`); the report prints both.

:func:`synthetic_coverage` checks the machinery where the truth is known: a
synthetic monotone F1 curve with binomial-like noise, whose crossing is
exact.

Examples
--------
>>> round(diluted_coverage(0.9, 0.5), 3)
0.859
>>> s = synthetic_coverage(40, seed=1)
>>> 0.75 <= s["coverage"] <= 1.0, s["n"]
(True, 40)
"""

from __future__ import annotations

import math
from contextlib import nullcontext
from statistics import NormalDist
from typing import Any, Callable, Iterable, Mapping, Sequence

import numpy as np

from designkit._validation import as_generator

__all__ = [
    "COVERAGE_QUESTIONS",
    "answer_reading",
    "calibration_z",
    "case_arguments",
    "coverage_case",
    "diluted_coverage",
    "draw_case",
    "run_cases",
    "summarize",
    "synthetic_coverage",
    "table_reading",
    "worst_regions",
]

#: The questions the benchmark asks, in report order.
COVERAGE_QUESTIONS = ("min-contact", "max-noise", "min-delta-t", "delta-e", "distinguishable")
_NOISES_C = (0.01, 0.05, 0.1)  # the noise levels [degC] at dT 10 degC
_DT_C = 10.0
_E_RANGE = (100.0, 39000.0)
_WIDTH = 80.0


def diluted_coverage(coverage: float, ref_se_ratio: float) -> float:
    """Coverage of an exactly calibrated normal interval measured against a reference whose standard
    error is ``ref_se_ratio`` times the answer's.

    >>> round(diluted_coverage(0.9, 0.0), 3)
    0.9
    """
    nd = NormalDist()
    z = nd.inv_cdf(0.5 + 0.5 * coverage)
    return 2.0 * nd.cdf(z / math.sqrt(1.0 + ref_se_ratio ** 2)) - 1.0


# ============================================================ the cases
def draw_case(question: str, rng: np.random.Generator) -> dict[str, Any]:
    """One random case of ``question``: a pair (or reference) and a scene, in the user's units.

    Pairs: effusivities uniform in [100, 39000] J s^-1/2 K^-1 m^-2, three in four at
    least 5 table intervals (400) apart, the rest 1-5 intervals; noise 0.01, 0.05 or
    0.1 degC at dT 10 degC; contact times log-uniform in [0.5, 10] s. ``distinguishable``
    takes its contact near the pair's ideal-observer contact (x 1-3) so that the F1 is
    informative (far from it every F1 is 0.5 or 1).
    """
    noise = float(rng.choice(_NOISES_C))
    contact = float(np.exp(rng.uniform(math.log(0.5), math.log(10.0))))
    if question == "delta-e":
        e = float(rng.uniform(500.0, _E_RANGE[1] - 500.0))
        return {"e": round(e, 1), "noise_c": noise, "delta_t_c": _DT_C, "contact_s": round(contact, 3)}
    far = rng.random() < 0.75
    gap = float(rng.uniform(400.0, 20000.0) if far else rng.uniform(_WIDTH, 400.0))
    lo = float(rng.uniform(_E_RANGE[0], _E_RANGE[1] - gap))
    case = {"e1": round(lo + gap, 1), "e2": round(lo, 1), "gap": round(gap, 1), "noise_c": noise,
            "delta_t_c": _DT_C, "contact_s": round(contact, 3)}
    if question == "distinguishable":
        from designkit.query.ideal_bound import exact_ideal_min_contact
        from designkit.sensor import load_sensor

        t = exact_ideal_min_contact(load_sensor("paper"), case["e2"], case["e1"], noise / _DT_C, width=_WIDTH,
                                    max_contact_s=10.0)
        t = float(t) if t is not None and np.isfinite(t) else 5.0
        case["contact_s"] = round(min(10.0, t * float(rng.uniform(1.0, 3.0))), 3)
    return case


def case_arguments(question: str, case: Mapping[str, Any]) -> dict[str, Any]:
    """The question function's keyword arguments for one case (objects and scene)."""
    if question == "delta-e":
        return {"e": case["e"], "contact_s": case["contact_s"], "noise_c": case["noise_c"],
                "delta_t_c": case["delta_t_c"]}
    out = {"e1": case["e1"], "e2": case["e2"]}
    if question == "min-contact":
        return {**out, "noise_c": case["noise_c"], "delta_t_c": case["delta_t_c"]}
    if question == "max-noise":
        return {**out, "contact_s": case["contact_s"], "delta_t_c": case["delta_t_c"]}
    if question == "min-delta-t":
        return {**out, "contact_s": case["contact_s"], "noise_c": case["noise_c"]}
    return {**out, "contact_s": case["contact_s"], "noise_c": case["noise_c"], "delta_t_c": case["delta_t_c"]}


def answer_reading(question: str, ans) -> dict[str, Any]:
    """What the benchmark compares: value, interval, coverage, ideal (F1 for distinguishable)."""
    if ans is None:
        return {"value": None, "low": None, "high": None, "coverage": None, "ideal": None, "method": "error"}
    d = ans.to_dict()
    value = d["value"]
    if question == "distinguishable":
        value = d["details"]["svm_f1"]
    return {"value": value, "low": d["interval"]["low"], "high": d["interval"]["high"],
            "coverage": d["interval"]["coverage"], "method": d["interval"]["method"], "ideal": d["ideal"]["value"],
            "in_grid": all(d["in_grid"].values()) if d["in_grid"] else True,
            "verdict": d["value"] if question == "distinguishable" else None}


def table_reading(question: str, case: Mapping[str, Any], *, table: str | None = None, coverage: float = 0.9,
                  sensor_temp_spread_c: float = 0.0) -> dict[str, Any]:
    """One case asked by the table route (:func:`answer_reading`); an error is recorded in the reading
    (``"error"``), not raised, so that a benchmark goes on. ``table``: the query layer's default
    (:data:`designkit.query.table.DEFAULT_TABLE`) unless given. ``sensor_temp_spread_c`` [degC]: varied
    initial conditions (``table`` then a varied table)."""
    from designkit import query
    from designkit.query.table import DEFAULT_TABLE

    table = DEFAULT_TABLE if table is None else table

    args = case_arguments(question, case)
    if sensor_temp_spread_c:
        args["sensor_temp_spread_c"] = float(sensor_temp_spread_c)
    try:
        return answer_reading(question, query.ask(question, route="table", table=table, coverage=coverage, **args))
    except Exception as exc:  # noqa: BLE001 - recorded, the benchmark goes on
        return {**answer_reading(question, None), "error": str(exc)}


def coverage_case(question: str, case: Mapping[str, Any], index: int, *, repeats: int = 4,
                  ref_repeats: int = 16, trials: int = 100, coverage: float = 0.9,
                  table: str | None = None, exact_solver: str = "sklearn",
                  sensor_temp_spread_c: float = 0.0) -> dict[str, Any]:
    """Ask one case by the table, by ``--exact`` and by the reference; return all three readings.

    ``sensor_temp_spread_c`` [degC]: varied initial conditions (each touch's sensor temperature drawn within
    +-that), on every route (``table`` then a varied table, such as ``svm-paper-varied``).

    Seeds: the answer uses ``1000 + index``, the reference ``500000 + index`` (disjoint streams).
    For ``min-delta-t`` the exact answer is the same estimate in sigma/dT as ``max-noise``'s
    (:func:`designkit.query.exact.exact_min_delta_t`), asked at the case's noise.
    """
    import time

    from designkit.query import exact as ex

    args = case_arguments(question, case)
    if sensor_temp_spread_c:
        args["sensor_temp_spread_c"] = float(sensor_temp_spread_c)
    out: dict[str, Any] = {"question": question, "index": index, **case}
    t0 = time.perf_counter()
    out["table"] = table_reading(question, case, table=table, coverage=coverage,
                                 sensor_temp_spread_c=sensor_temp_spread_c)
    t1 = time.perf_counter()
    fn = {"min-contact": ex.exact_min_contact, "max-noise": ex.exact_max_noise,
          "min-delta-t": ex.exact_min_delta_t, "delta-e": ex.exact_delta_e,
          "distinguishable": ex.exact_distinguishable}[question]
    common = dict(trials=trials, jobs=1, coverage=coverage, **args)
    ans = fn(seed=1000 + index, repeats=repeats, solver=exact_solver, **common)
    t2 = time.perf_counter()
    ref = fn(seed=500000 + index, repeats=ref_repeats, solver="batched", **common)
    t3 = time.perf_counter()
    out["exact"] = answer_reading(question, ans)
    out["reference"] = answer_reading(question, ref)
    out["wall_s"] = {"table": t1 - t0, "exact": t2 - t1, "reference": t3 - t2}
    out["violation"] = _violation(question, ref, coverage)
    if question == "delta-e":  # both directions, each an answer of its own
        for route, a in (("exact", ans), ("reference", ref)):
            out[route]["sides"] = {s: {k: a.details[s].get(k) for k in ("value", "interval", "coverage")}
                                   for s in ("lower", "upper")}
    return out


def _violation(question: str, ref, coverage: float) -> bool | None:
    """Whether the reference's SVM clearly beats the ideal bound: an evaluation at (or past) the ideal
    observer's answer whose mean F1 passes Phi by ``z(coverage)`` standard errors."""
    z = NormalDist().inv_cdf(0.5 + 0.5 * coverage)
    ideal = ref.ideal
    if ideal is None or isinstance(ideal, bool):
        return None
    if question == "distinguishable":
        f1, se = ref.details["svm_f1"], ref.details["svm_standard_error"]
        return bool(f1 - z * se > ideal)
    if question == "delta-e":
        evals = [(e["delta_e"], e["svm_f1"], e["standard_error"]) for s in ("lower", "upper")
                 for e in ref.details[s].get("evaluations") or [] if ref.details[s].get("ideal") is not None
                 and e["delta_e"] <= ref.details[s]["ideal"] * (1 + 1e-9)]
        return any(m - z * s >= ref.threshold for _, m, s in evals)
    evals = ref.computation.get("evaluations") or []
    if question == "min-contact":  # the search starts at the bound: its first evaluation is there
        bad = [e for e in evals if e["contact_s"] <= ideal * (1 + 1e-9)]
    else:  # the noise ratio at or beyond the ideal observer's
        r_ideal = ideal / ref.scene["delta_t_c"] if question == "max-noise" else ref.scene["noise_c"] / ideal
        bad = [e for e in evals if e["noise_ratio"] >= r_ideal * (1 - 1e-9)]
    return any(e["svm_f1"] - z * e["standard_error"] >= ref.threshold for e in bad)


# ============================================================ the summary
def _stated_sd(r: Mapping[str, Any], log: bool) -> float | None:
    """The standard deviation a stated two-sided interval implies (half-width / z), on log scale for crossings."""
    lo, hi, cov = r.get("low"), r.get("high"), r.get("coverage")
    if lo is None or hi is None or not cov or hi <= lo or (log and lo <= 0):
        return None
    width = math.log(hi) - math.log(lo) if log else hi - lo
    return width / (2.0 * NormalDist().inv_cdf(0.5 + 0.5 * cov))


def calibration_z(results: Iterable[Mapping[str, Any]], question: str, route: str = "exact") -> np.ndarray:
    """``(answer - reference) / sqrt(sd_answer^2 + sd_reference^2)`` per case where both state an interval.

    The sd are the ones the stated intervals imply (log scale for the crossings, F1 scale for
    ``distinguishable``). Both sides' Monte Carlo errors are in the denominator, so the spread of
    these is 1 for calibrated intervals whatever the reference's own error (coverage against the
    reference is diluted by it, :func:`diluted_coverage`); above 1: intervals too narrow. An F1 of 1
    on either side (no spread: the interval is clipped there) leaves the case out.

    >>> r = [{"question": "q", "exact": {"value": 1.1, "low": 1.0, "high": 1.2, "coverage": 0.9},
    ...       "reference": {"value": 1.0, "low": 0.95, "high": 1.05, "coverage": 0.9}}]
    >>> round(float(calibration_z(r, "q", "exact")[0]), 2)
    1.51
    """
    log = question != "distinguishable"
    out = []
    for r in results:
        if r["question"] != question or route not in r:
            continue
        a, ref = r[route], r["reference"]
        if a.get("value") is None or isinstance(ref.get("value"), bool) or ref.get("value") is None:
            continue
        if not log and max(a["value"], ref["value"]) >= 1.0 - 1e-12:  # an F1 of 1 has no spread to calibrate
            continue
        sa, sr = _stated_sd(a, log), _stated_sd(ref, log)
        if sa is None or sr is None or (log and (a["value"] <= 0 or ref["value"] <= 0)):
            continue
        d = math.log(a["value"]) - math.log(ref["value"]) if log else a["value"] - ref["value"]
        out.append(d / math.hypot(sa, sr))
    return np.asarray(out, dtype=np.float64)


def _covered(r: Mapping[str, Any], truth: float) -> bool:
    lo = r["low"] if r["low"] is not None else -math.inf
    hi = r["high"] if r["high"] is not None else math.inf
    return lo <= truth <= hi


def summarize(results: Iterable[Mapping[str, Any]], question: str, route: str, *,
              min_gap: float | None = None) -> dict[str, Any]:
    """Coverage and error of one (question, route) over benchmark results.

    Only cases with both an answer and a reference estimate (a reference with a stated coverage, not
    a search bracket) count for the error; only those with a stated coverage for ``coverage``. ``min_gap``: only pairs at least this far apart.

    >>> r = [{"question": "q", "reference": {"value": 1.0, "coverage": 0.9}, "table": {"value": 1.1, "low": 0.9,
    ...       "high": 1.2, "coverage": 0.9}}]
    >>> s = summarize(r, "q", "table"); s["coverage"], round(s["median_rel"], 3)
    (1.0, 0.1)
    """
    rows = [r for r in results if r["question"] == question and (min_gap is None or r.get("gap", 1e9) >= min_gap)]
    # an answer at the edge of a table's axis ("separable even at the largest noise ratio: at least this")
    # is a one-sided bound, not an estimate: counted apart, not as an error
    edge = [r for r in rows if r[route]["value"] is not None and r[route].get("in_grid") is False]
    # a reference that is only a search bracket (too few informative evaluations for a fit: no stated
    # coverage, its value the bracket's geometric middle) is no measurement: counted apart, with how often
    # the answer lies inside that bracket
    bracket = [r for r in rows if r[route]["value"] is not None and r["reference"]["value"] is not None
               and not isinstance(r["reference"]["value"], bool) and not r["reference"].get("coverage")
               and r[route].get("in_grid") is not False]
    both = [r for r in rows if r[route]["value"] is not None and r["reference"]["value"] is not None
            and not isinstance(r["reference"]["value"], bool) and r[route].get("in_grid") is not False
            and r["reference"].get("coverage")]
    err = np.array([abs(r[route]["value"] - r["reference"]["value"]) for r in both], dtype=np.float64)
    rel = np.array([abs(r[route]["value"] - r["reference"]["value"]) / abs(r["reference"]["value"])
                    for r in both if r["reference"]["value"] != 0], dtype=np.float64)
    stated = [r for r in both if r[route].get("coverage")]
    hits = [_covered(r[route], r["reference"]["value"]) for r in stated]
    unstated = [r for r in both if not r[route].get("coverage") and (r[route]["low"] is not None
                                                                      or r[route]["high"] is not None)]
    return {
        "question": question, "route": route, "n": len(rows), "n_compared": len(both),
        "n_stated": len(stated), "coverage": float(np.mean(hits)) if hits else None,
        "n_unstated": len(unstated),
        "unstated_contains": float(np.mean([_covered(r[route], r["reference"]["value"]) for r in unstated]))
        if unstated else None,
        "n_no_answer": sum(1 for r in rows if r[route]["value"] is None),
        "n_reference_bracket": len(bracket),
        "reference_bracket_contains": sum(1 for r in bracket if (r["reference"]["low"] or -math.inf)
                                          <= r[route]["value"] <= (r["reference"]["high"] or math.inf)),
        "n_edge_bound": len(edge),
        "edge_bound_holds": sum(1 for r in edge if r["reference"]["value"] is not None and _covered(
            r[route], r["reference"]["value"])),
        "median_abs": float(np.median(err)) if err.size else None,
        "p95_abs": float(np.percentile(err, 95)) if err.size else None,
        "median_rel": float(np.median(rel)) if rel.size else None,
        "p95_rel": float(np.percentile(rel, 95)) if rel.size else None,
        "median_width_rel": float(np.median([(r[route]["high"] - r[route]["low"]) / abs(r[route]["value"])
                                             for r in stated if r[route]["high"] is not None
                                             and r[route]["low"] is not None and r[route]["value"]]))
        if stated else None,
        "violations": sum(1 for r in rows if r.get("violation")),
        # the reference's crossing at the bound itself: its F1 reached Phi at the ideal observer's answer
        **_z_summary(calibration_z(rows, question, route)),
        "reference_at_bound": 0 if question == "distinguishable" else sum(  # (an F1 of 1 is no violation)
            1 for r in rows if r["reference"].get("value") is not None
                                  and not isinstance(r["reference"]["value"], bool)
                                  and r["reference"].get("ideal") is not None
                                  and math.isclose(r["reference"]["value"], r["reference"]["ideal"], rel_tol=1e-9)),
    }


def _z_summary(z: np.ndarray) -> dict[str, Any]:
    """Spread of :func:`calibration_z` (robust: 1.4826 x the median absolute value, so that a few
    clipped intervals do not dominate) and the share inside the nominal 90 % band."""
    if z.size == 0:
        return {"n_z": 0, "z_sd": None, "z_robust_sd": None}
    return {"n_z": int(z.size), "z_sd": float(np.std(z)), "z_robust_sd": float(1.4826 * np.median(np.abs(z)))}


# ============================================================ the machinery on a known truth
def synthetic_coverage(n: int, *, seed: int, coverage: float = 0.9, repeats: int = 4, trials: int = 100,
                       increasing: bool = True, correlation: float = 0.0) -> dict[str, Any]:
    """Coverage of :func:`designkit.query.crossing.estimate_crossing` on synthetic F1 curves.

    Each curve is ``F1(x) = 0.5 + 0.5 / (1 + (x / x50)^-k)`` (a logistic in log x, slope
    ``k`` uniform in [2, 8], crossing 0.9 at a random ``x*`` in [0.5, 5]; with
    ``increasing=False`` the mirror image ``(x50 / x)``, falling like F1 against sigma/dT);
    an evaluation is the mean of ``repeats`` draws, each the curve plus normal noise with
    the SVM's standard error at that F1 (:func:`designkit.recognition.svm.f1_standard_error`
    with ``trials`` touches per class). The truth is ``x*`` exactly.

    ``correlation`` models common random numbers: seed ``r``'s noise is
    ``sqrt(rho) c_r + sqrt(1 - rho) e_{r,x}``, with ``c_r`` shared by every point of the
    curve (the exact route once reused its seeds at every point: measured 0.7-0.9 between
    neighbouring points on the sigma/dT and delta-e axes, 0.2-0.65 on contact time). The
    estimator assumes independent points (``correlation=0``, what the exact route now draws).

    Returns ``{"n", "coverage", "median_rel", "p95_rel", "none", "z_sd"}``; ``z_sd`` is the
    spread of ``(log x_est - log x*) / sd`` with ``sd`` the interval's stated standard deviation
    in log x (1 when the stated width is right; the coverage follows from it).
    """
    from designkit.query.crossing import estimate_crossing, z_of_coverage
    from designkit.recognition.svm import f1_standard_error

    rng = as_generator(seed)
    rho = float(correlation)
    z = z_of_coverage(coverage)
    hits, rel, zs, none = [], [], [], 0
    for _ in range(int(n)):
        k = rng.uniform(2.0, 8.0)
        x_star = float(np.exp(rng.uniform(math.log(0.5), math.log(5.0))))
        # 0.5 + 0.5 p = 0.9 -> p = 0.8 -> (x*/x50)^k = 4 rising, (x50/x*)^k = 4 falling
        x50 = x_star / 4.0 ** (1.0 / k) if increasing else x_star * 4.0 ** (1.0 / k)
        common = rng.standard_normal(repeats)

        def f(x, k=k, x50=x50, common=common):
            p = 1.0 / (1.0 + ((x / x50) if increasing else (x50 / x)) ** -k)
            m = 0.5 + 0.5 * p
            se1 = f1_standard_error(min(1.0, m), max(0.0, 1.0 - m), trials)
            noise = math.sqrt(rho) * common + math.sqrt(1.0 - rho) * rng.standard_normal(repeats)
            draws = np.clip(m + se1 * noise, 0.0, 1.0)
            return float(draws.mean()), max(se1, float(np.std(draws, ddof=1))) / math.sqrt(repeats)

        est = estimate_crossing(f, 0.05, 10.0, 0.9, coverage=coverage, increasing=increasing)
        if est.value is None:
            none += 1
            continue
        lo = est.low if est.low is not None else -math.inf
        hi = est.high if est.high is not None else math.inf
        hits.append(lo <= x_star <= hi)
        rel.append(abs(est.value - x_star) / x_star)
        if est.method == "wls-logit-log" and est.low is not None and est.high is not None and est.high > est.low:
            zs.append((math.log(est.value) - math.log(x_star)) / ((math.log(est.high) - math.log(est.low)) / (2 * z)))
    rel_a = np.array(rel)
    return {"n": int(n), "coverage": float(np.mean(hits)) if hits else None,
            "median_rel": float(np.median(rel_a)) if rel else None,
            "p95_rel": float(np.percentile(rel_a, 95)) if rel else None, "none": none,
            "z_sd": float(np.std(zs)) if zs else None}


def worst_regions(results: Sequence[Mapping[str, Any]], question: str, route: str, *,
                  noise_bands: Sequence[tuple[float, float]] | None = None) -> list[dict[str, Any]]:
    """Relative error by noise level and effusivity band (of the pair's lower edge), worst first.

    ``noise_bands``: ``[lo, hi)`` ranges of noise [degC] instead of the benchmark's three levels (cases drawn
    from a continuous noise range); each region then has ``noise_band`` instead of ``noise_c``.
    """
    bands = ((0, 2000), (2000, 8000), (8000, 20000), (20000, 40000))
    levels = [(n, n) for n in _NOISES_C] if noise_bands is None else list(noise_bands)
    out = []
    for n_lo, n_hi in levels:
        for lo, hi in bands:
            sel = [r for r in results if r["question"] == question
                   and (r["noise_c"] == n_lo if noise_bands is None else n_lo <= r["noise_c"] < n_hi)
                   and lo <= (r.get("e2", r.get("e", 0.0))) < hi and r[route]["value"] is not None
                   and r["reference"]["value"] not in (None, 0)]
            if not sel:
                continue
            rel = [abs(r[route]["value"] - r["reference"]["value"]) / abs(r["reference"]["value"]) for r in sel]
            stated = [r for r in sel if r[route].get("coverage")]
            noise = {"noise_c": n_lo} if noise_bands is None else {"noise_band": [n_lo, n_hi]}
            out.append({**noise, "e_band": [lo, hi], "n": len(sel), "median_rel": float(np.median(rel)),
                        "max_rel": float(np.max(rel)),
                        "coverage": float(np.mean([_covered(r[route], r["reference"]["value"]) for r in stated]))
                        if stated else None})
    return sorted(out, key=lambda d: -d["median_rel"])


def run_cases(question: str, n: int, *, seed: int, jobs: int = 1, done: Callable[[dict], None] | None = None,
              start: int = 0, **options: Any) -> list[dict[str, Any]]:
    """Random cases ``start .. n-1`` of ``question`` (:func:`draw_case`, seeded: case ``i`` is the same
    whatever ``start``), each through :func:`coverage_case`, over ``jobs`` processes; ``done(result)`` is
    called as each finishes (for progress and saving)."""
    from joblib import Parallel, delayed

    from designkit._workers import local_processes, worker_count

    jobs = worker_count(jobs)
    rng = as_generator([int(seed), COVERAGE_QUESTIONS.index(question)])
    cases = [draw_case(question, rng) for _ in range(int(n))]
    results = []
    with local_processes(jobs) if jobs != 1 else nullcontext():
        gen = Parallel(n_jobs=jobs, return_as="generator_unordered")(
            delayed(coverage_case)(question, c, i, **options) for i, c in enumerate(cases) if i >= start)
        for r in gen:
            results.append(r)
            if done is not None:
                done(r)
    return sorted(results, key=lambda r: r["index"])
