"""Section ``queries``: table answers against exact answers, through the question layer users call.

Table interpolation against exact answers over random pairs and scenes
across each shipped table's grid. For ``ideal-paper`` the exact answer is the
ideal observer's closed form with bisection, vectorized
(:mod:`designkit.query.ideal_bound`, the answers behind ``--exact`` for the
ideal bound); for ``svm-paper`` it is
:func:`designkit.query.exact_min_contact` /
:func:`~designkit.query.exact_distinguishable` (Monte Carlo, a modest
number of pairs). The same ideal table cut down to sparser grids shows what
table density buys.

Every table answer comes from the public question functions of
:mod:`designkit.query.table` (``min_contact``, ``max_noise``,
``min_delta_t``, ``delta_e``, ``distinguishable``), the code a user's
question runs; how their answers are read is kept in one block below
(:func:`_table_answers`, :func:`_table_verdict`, :func:`_svm_table_delta`).
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from designkit._validation import InputError, as_generator
from designkit.query.ideal_bound import exact_ideal_delta, exact_ideal_max_ratio, exact_ideal_min_contact
from .results import Row, p95, worst

__all__ = ["GAP_BINS", "QUESTIONS", "density_rows", "query_rows", "subsample_table", "svm_query_rows"]

#: The questions :func:`query_rows` can check, in the order of its rows.
QUESTIONS = ("min-contact", "max-noise", "min-delta-t", "delta-e", "distinguishable")
#: Bins of a pair's distance [table intervals] for the error-by-gap facts.
GAP_BINS = (1.0, 2.0, 5.0, 20.0, math.inf)
_DT_C = 10.0  # the temperature difference every query is asked at [degC]; errors depend on sigma/dT only
_IDEAL_REF = "exact ideal observer (closed form, bisection)"


# ============================================================ tables
def subsample_table(table, keep: Mapping[str, Sequence[int]], name: str | None = None):
    """An in-memory :class:`~designkit.tables.store.Table` restricted to some points of its axes.

    ``keep`` maps axis names (``noise_ratio``, ``contact_s``, ...) to the
    indices to keep; used to measure what a sparser table of the same
    sweep would answer (no recomputation: the kept points are exact).

    Raises
    ------
    InputError
        When the kept indices of an axis are not increasing or not inside it.
    """
    from designkit.tables.store import Table

    names = table.axis_names
    idx = [_kept_indices(a, len(table.axes[a]), keep) for a in names]
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


def _kept_indices(axis: str, n: int, keep) -> np.ndarray:
    sel = np.asarray(keep.get(axis, range(n)), dtype=np.int64)
    if sel.size == 0 or np.any(np.diff(sel) <= 0) or sel[0] < 0 or sel[-1] >= n:
        raise InputError(f"indices kept on axis {axis} must be increasing and inside 0..{n - 1}")
    return sel


def _effusivity_grid(table) -> tuple[float, float, float]:
    """The table's effusivity (min, max, interval width) [J s^-1/2 K^-1 m^-2]."""
    e = table.header["effusivity"]
    return float(e["min"]), float(e["max"]), float(e["width"])


def _grid_label(table) -> str:
    ax = table.axes
    return (f"{len(ax['noise_ratio'])} sigma/dT x {len(ax['contact_s'])} contacts x "
            f"{len(ax['e_ref'])} intervals") if "noise_ratio" in ax else table.name


# ============================================================ the question layer, as users call it
def _number(x) -> float:
    return math.nan if x is None else float(x)


def _table_answers(table, samples) -> tuple[dict[str, np.ndarray], float]:
    """Answers of every table query for the samples (ratios, not noises); seconds per query (mean over all)."""
    from designkit.query import table as query

    ans: dict[str, list[float]] = {k: [] for k in ("min_contact", "max_noise", "min_delta_t", "delta_up",
                                                   "delta_down")}
    kw = dict(table=table, ideal_table=table)
    t0 = time.perf_counter()
    for e1, e2, r, c in zip(samples["e1"], samples["e2"], samples["ratio"], samples["contact"]):
        noise, c = float(r) * _DT_C, float(c)
        ans["min_contact"].append(_number(query.min_contact(e1, e2, noise_c=noise, delta_t_c=_DT_C, **kw).value))
        ans["max_noise"].append(_number(query.max_noise(e1, e2, contact_s=c, delta_t_c=_DT_C, **kw).value) / _DT_C)
        dt_min = _number(query.min_delta_t(e1, e2, contact_s=c, noise_c=noise, **kw).value)
        ans["min_delta_t"].append(noise / dt_min)
        x = query.delta_e(e1, contact_s=c, noise_c=noise, delta_t_c=_DT_C, **kw).extra
        ans["delta_up"].append(_number(x.get("delta_e_upper")))
        ans["delta_down"].append(_number(x.get("delta_e_lower")))
    per = (time.perf_counter() - t0) / max(4 * len(samples["e1"]), 1)
    return {k: np.asarray(v, dtype=np.float64) for k, v in ans.items()}, per


def _table_verdict(table, e1, e2, contact_s, ratio, svm_table=None) -> bool:
    """The table's distinguishable verdict (``svm_table``: that table's, else ``table`` for both)."""
    from designkit.query import table as query

    ans = query.distinguishable(e1, e2, contact_s=float(contact_s), noise_c=float(ratio) * _DT_C, delta_t_c=_DT_C,
                                table=svm_table or table, ideal_table=svm_table or table)
    return bool(ans.extra["distinguishable"])


def _svm_table_delta(svm_table, e1, ratio, contact_s) -> float | None:
    """The table's delta(e) towards higher e [J s^-1/2 K^-1 m^-2] (None: none in the grid)."""
    from designkit.query import table as query

    return query.delta_e(e1, contact_s=contact_s, noise_c=ratio * _DT_C, delta_t_c=_DT_C, table=svm_table,
                         ideal_table=svm_table).extra.get("delta_e_upper")


def _exact_verdicts(table, e1, e2, contacts, ratios) -> np.ndarray:
    """The ideal observer's verdicts for classes one table interval wide (closed form)."""
    from designkit.recognition.ideal import ideal_scores, projection_noise
    from designkit.scene import Scene

    sensor, width = table.sensor, _effusivity_grid(table)[2]
    s = np.array([projection_noise(sensor, Scene(contact_s=float(c), noise_c=float(r), sensor_temp_c=26.0,
                                                 ambient_temp_c=25.0)) for c, r in zip(contacts, ratios)])
    f1, _ = ideal_scores(e1, e1 + width, e2, e2 + width, sensor.effusivity, s, accuracy=False)
    return f1 >= table.threshold


# ============================================================ ideal tables against the exact ideal observer
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
    rng = as_generator(seed)
    e_lo, e_hi, width = _effusivity_grid(table)
    ratios, contacts = table.axes["noise_ratio"], table.axes["contact_s"]
    out: dict[str, list] = {"e1": [], "e2": [], "ratio": [], "contact": []}
    got, unresolved = 0, 0
    min_gap = width * min_gap_intervals
    while got < n:
        m = 2 * (n - got) + 8
        e1 = rng.uniform(e_lo + width, e_hi - 2 * width, m)
        r = np.exp(rng.uniform(math.log(ratios[0]), math.log(ratios[-1]), m))
        c = rng.uniform(contacts[0], contacts[-1], m)
        d = exact_ideal_delta(table.sensor, e1, c, r, direction=+1, width=width, threshold=table.threshold,
                              e_max=e_hi)
        ok = np.isfinite(d) & (e1 + d <= e_hi - width)
        unresolved += int(np.count_nonzero(ok & (d < min_gap)))
        ok &= d >= min_gap
        for k, v in (("e1", e1), ("e2", e1 + d), ("ratio", r), ("contact", c)):
            out[k].extend(v[ok][: n - got])
        got = len(out["e1"])
    res = {k: np.asarray(v[:n]) for k, v in out.items()}
    res["unresolved_fraction"] = unresolved / (unresolved + got)
    return res


def _exact_answers(table, samples) -> dict[str, Any]:
    """The exact ideal answers to every question for the samples, and seconds per answer."""
    sensor = table.sensor
    _, e_hi, width = _effusivity_grid(table)
    e1, e2, r, c = samples["e1"], samples["e2"], samples["ratio"], samples["contact"]
    kw = dict(width=width, threshold=table.threshold)
    out: dict[str, Any] = {}
    t0 = time.perf_counter()
    out["min_contact"] = exact_ideal_min_contact(sensor, e1, e2, r, max_contact_s=float(table.axes["contact_s"][-1]),
                                                 **kw)
    out["t_contact"] = (time.perf_counter() - t0) / e1.size
    t0 = time.perf_counter()
    out["ratio"] = exact_ideal_max_ratio(sensor, e1, e2, c, **kw)
    out["t_ratio"] = (time.perf_counter() - t0) / e1.size
    t0 = time.perf_counter()
    out["delta_up"] = exact_ideal_delta(sensor, e1, c, r, direction=+1, e_max=e_hi, **kw)
    out["delta_down"] = exact_ideal_delta(sensor, e1, c, r, direction=-1, e_max=e_hi, **kw)
    out["t_delta"] = (time.perf_counter() - t0) / (2 * e1.size)
    return out


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
                    "p95": p95(e), "worst": worst(e)})
    return out


def _missing(exact, tab) -> int:
    """Cases with an exact answer but no table answer."""
    return int(np.count_nonzero(np.isfinite(exact) & ~np.isfinite(tab)))


class _Check:
    """What :func:`query_rows` collects: rows and facts, for one table and one set of samples."""

    def __init__(self, table, samples, tab, per_query, exact, label):
        self.table, self.samples, self.tab, self.exact = table, samples, tab, exact
        self.width = _effusivity_grid(table)[2]
        self.gap = samples["e2"] - samples["e1"]
        self.per_query = per_query
        self.method = f"table interpolation ({label})"
        self.setting = _grid_label(table)
        self.rows: list[Row] = []
        self.facts: dict[str, Any] = {"table": label, "n": int(samples["e1"].size),
                                      "time_per_table_query_s": per_query,
                                      "unresolved_fraction": float(samples.get("unresolved_fraction", math.nan))}

    def add(self, question, metric, err, t_ref, missing, note="") -> dict[str, Any]:
        err = np.asarray(err, dtype=np.float64)
        n = int(np.isfinite(err).sum())
        self.rows.append(Row(question, self.method, self.setting, metric, p95(err), worst(err), self.per_query,
                             _IDEAL_REF, t_ref, n,
                             (f"{missing} of {err.size} without a table answer where the exact one exists; "
                              if missing else "") + note))
        self.facts[question] = {"p95": p95(err), "worst": worst(err), "median": float(np.nanmedian(err)),
                                "n": n, "missing": int(missing), "metric": metric}
        return self.facts[question]


def _check_min_contact(ck: _Check, seed) -> None:
    tab, ex = ck.tab["min_contact"], ck.exact["min_contact"]
    both = np.isfinite(tab) & np.isfinite(ex)
    err = np.where(both, np.abs(tab - ex), np.nan)
    below = int(np.count_nonzero(ex < ck.table.axes["contact_s"][0]))
    f = ck.add("min-contact", "|t_table - t_exact| [s]", err, ck.exact["t_contact"], _missing(ex, tab),
               f"{below} exact answers below the table's first contact (table answers its first contact)"
               if below else "")
    rel = np.where(both, np.abs(tab - ex) / ex, np.nan)
    f["relative_p95"], f["relative_worst"] = p95(rel), worst(rel)
    signed = np.where(both, tab - ex, np.nan)
    f["signed_median_s"] = float(np.nanmedian(signed))
    f["conservative_fraction"] = float(np.mean(signed[both] >= -1.0 / ck.table.sensor.sample_rate_hz))
    f["by_gap"] = _by_gap(ck.gap, ck.width, err)


def _check_max_noise(ck: _Check, seed) -> None:
    tab, ex = ck.tab["max_noise"], ck.exact["ratio"]
    both = np.isfinite(tab) & np.isfinite(ex)
    err = np.where(both, np.abs(tab / ex - 1.0), np.nan)
    f = ck.add("max-noise", "relative error of sigma_max", err, ck.exact["t_ratio"], _missing(ex, tab))
    f["by_gap"] = _by_gap(ck.gap, ck.width, err)
    f["conservative_fraction"] = float(np.mean(tab[both] / ex[both] - 1.0 <= 1e-6))


def _check_min_delta_t(ck: _Check, seed) -> None:
    tab, ex = ck.tab["min_delta_t"], ck.exact["ratio"]
    both = np.isfinite(tab) & np.isfinite(ex)
    # tab holds noise / dT_min (a sigma/dT): dT_table / dT_exact = r_exact / r_table
    err = np.where(both, np.abs(ex / tab - 1.0), np.nan)
    ck.add("min-delta-t", "relative error of dT_min", err, ck.exact["t_ratio"], _missing(ex, tab))


def _check_delta_e(ck: _Check, seed) -> None:
    errs, rels, missing = [], [], 0
    for key in ("delta_up", "delta_down"):
        tab, ex = ck.tab[key], ck.exact[key]
        both = np.isfinite(tab) & np.isfinite(ex)
        errs.append(np.where(both, np.abs(tab - ex), np.nan))
        rels.append(errs[-1] / ex)
        missing += _missing(ex, tab)
    f = ck.add("delta-e", "|delta_table - delta_exact| [J s^-1/2 K^-1 m^-2]", np.concatenate(errs),
               ck.exact["t_delta"], missing, f"table steps are one interval ({ck.width:g}) wide")
    rel = np.concatenate(rels)
    f["relative_p95"], f["relative_worst"] = p95(rel), worst(rel)


def _check_distinguishable(ck: _Check, seed) -> None:
    """Table verdicts against the exact ideal verdict, for pairs within -20..+25 % of the boundary gap."""
    s = ck.samples
    e_max = _effusivity_grid(ck.table)[1]
    factor = np.exp(as_generator([seed, 803]).uniform(math.log(0.8), math.log(1.25), s["e1"].size))
    e1 = s["e1"]
    e2 = np.minimum(e1 + (s["e2"] - e1) * factor, e_max - ck.width)
    t0 = time.perf_counter()
    verdict = np.array([_table_verdict(ck.table, a, b, c, r) for a, b, r, c in zip(e1, e2, s["ratio"], s["contact"])])
    t_tab = (time.perf_counter() - t0) / e1.size
    t0 = time.perf_counter()
    exact = _exact_verdicts(ck.table, e1, e2, s["contact"], s["ratio"])
    t_ex = (time.perf_counter() - t0) / e1.size
    wrong = verdict != exact
    rate = float(np.mean(wrong))
    far = float(np.exp(np.abs(np.log(factor))[wrong].max()) - 1.0) if wrong.any() else 0.0
    ck.rows.append(Row("distinguishable", ck.method, ck.setting, "wrong verdicts (fraction)", rate, rate, t_tab,
                       _IDEAL_REF, t_ex, int(wrong.size),
                       f"pairs within -20 %..+25 % of the exact boundary gap; wrong verdicts at most "
                       f"{100 * far:.0f} % from it"))
    ck.facts["distinguishable"] = {"wrong_fraction": rate, "n": int(wrong.size), "farthest_wrong_relative": far}


_CHECKS: dict[str, Callable[[_Check, Any], None]] = {
    "min-contact": _check_min_contact, "max-noise": _check_max_noise, "min-delta-t": _check_min_delta_t,
    "delta-e": _check_delta_e, "distinguishable": _check_distinguishable}


def query_rows(table, quick: bool = True, seed: int = 0, *, n: int | None = None, label: str | None = None,
               questions: Sequence[str] = QUESTIONS,
               samples: Mapping[str, np.ndarray] | None = None) -> tuple[list[Row], dict[str, Any]]:
    """Table interpolation against the exact ideal-observer answer (ideal-fidelity tables).

    Parameters
    ----------
    table : Table
        An ideal-fidelity table (its own ideal bound).
    quick : bool
        150 random pairs and scenes (else 1000), unless ``n`` or ``samples``.
    seed : int
        Seed of the draws.
    label : str, optional
        The table's name in the rows (default: its name).
    questions : sequence of str
        Any of :data:`QUESTIONS`; rows come in that order.
    samples : mapping, optional
        Pairs and scenes to use (``e1``, ``e2``, ``ratio``, ``contact``) instead of drawing them.

    Returns
    -------
    rows : list of Row
        p95 and worst errors, time per query.
    facts : dict
        The raw statistics for the report (per question, by gap, conservativeness).
    """
    if table.fidelity != "ideal":
        raise InputError(f"query_rows measures ideal-fidelity tables; {table.name} is {table.fidelity} "
                         f"(see svm_query_rows)")
    if samples is None:
        samples = _query_samples(table, n or (150 if quick else 1000), [seed, 802])
    tab, per_query = _table_answers(table, samples)
    ck = _Check(table, samples, tab, per_query, _exact_answers(table, samples), label or table.name)
    for q in QUESTIONS:
        if q in questions:
            _CHECKS[q](ck, seed)
    return ck.rows, ck.facts


def density_rows(table, quick: bool = True, seed: int = 0, svm_axes: Mapping[str, Sequence[float]] | None = None
                 ) -> list[Row]:
    """What table density buys: the ideal table cut to sparser grids, min-contact and max-noise errors.

    Same random samples for every density. ``svm_axes`` (the SVM table's
    axis values) adds the SVM table's own density, so that its
    interpolation error can be told apart from its Monte Carlo error.
    """
    ax = table.axes
    samples = _query_samples(table, 100 if quick else 500, [seed, 804])
    rows = []
    for label, keep in _density_variants(ax, svm_axes):
        # every variant must still span the full range (first and last point kept)
        keep = {k: sorted(set(v) | {0, len(ax[k]) - 1}) for k, v in keep.items()}
        sub = subsample_table(table, keep, name=f"{table.name} [{label}]")
        r, _ = query_rows(sub, quick, seed, label=sub.name, questions=("min-contact", "max-noise"), samples=samples)
        for row in r:
            rows.append(replace(row, method="table interpolation (density)", setting=f"{label}: {_grid_label(sub)}",
                                note=(row.note + "; " if row.note else "") + "same sweep, fewer points kept"))
    return rows


def _density_variants(ax, svm_axes) -> list[tuple[str, dict[str, Any]]]:
    nr, nc = len(ax["noise_ratio"]), len(ax["contact_s"])
    variants = [("every 2nd contact", {"contact_s": range(0, nc, 2)}),
                ("every 2nd sigma/dT and contact", {"noise_ratio": range(0, nr, 2), "contact_s": range(0, nc, 2)}),
                ("every 4th sigma/dT and contact", {"noise_ratio": range(0, nr, 4), "contact_s": range(0, nc, 4)})]
    if svm_axes is not None:
        keep = {name: sorted({int(np.argmin(np.abs(np.log(ax[name]) - math.log(v)))) for v in vals})
                for name, vals in svm_axes.items()}
        variants.insert(0, ("svm-paper's axes (nearest points)", keep))
    return variants


# ============================================================ the SVM table against --exact
def _contact_window(svm_table) -> tuple[float, float, float]:
    """Target contacts [s]: the middle of the table's contact range ([1, 7.6] s for svm-paper), and its end."""
    c = svm_table.axes["contact_s"]
    c_min, c_max = float(c[0]), float(c[-1])
    return c_min + 0.05 * (c_max - c_min), c_min + 0.75 * (c_max - c_min), c_max


def _svm_pairs(svm_table, n: int, rng) -> list[tuple[float, float, float, float]]:
    """(e1, e2, sigma/dT, contact) with e2 just beyond the table's delta(e1) at that scene."""
    _, e_hi, width = _effusivity_grid(svm_table)
    ratios = svm_table.axes["noise_ratio"]
    c_lo, c_hi, _ = _contact_window(svm_table)
    pairs: list[tuple[float, float, float, float]] = []
    tries = 0
    while len(pairs) < n:
        tries += 1
        if tries > 200 * n:  # a table whose deltas leave no room in its grid: say so instead of looping
            raise InputError(f"table {svm_table.name}: no pair with a distinguishable partner inside its "
                             f"effusivity grid in {tries - 1} random draws")
        e1 = float(rng.uniform(width, e_hi / 2))
        r = float(np.exp(rng.uniform(math.log(ratios[0]), math.log(ratios[-1]))))
        c = float(rng.uniform(c_lo, c_hi))
        d = _svm_table_delta(svm_table, e1, r, c)
        if d is None or e1 + d > e_hi - width:
            continue
        pairs.append((e1, e1 + d * float(rng.uniform(1.0, 1.1)), r, c))
    return pairs


def _exact_kw(svm_table, trials, repeats, jobs) -> dict[str, Any]:
    return dict(delta_t_c=_DT_C, threshold=svm_table.threshold, sensor=svm_table.sensor,
                width=_effusivity_grid(svm_table)[2], trials=trials, repeats=repeats, jobs=jobs)


def _svm_min_contact_cases(svm_table, pairs, seed, exact_kw, progress) -> list[dict[str, Any]]:
    """Table and ``--exact`` min-contact, their intervals and times, per pair."""
    from designkit import query

    res = []
    for k, (e1, e2, r, c) in enumerate(pairs):
        if progress:
            progress(f"queries: exact SVM min-contact {k + 1}/{len(pairs)} ({e1:.0f} vs {e2:.0f}, sigma/dT {r:.4f})")
        t0 = time.perf_counter()
        tab = query.min_contact(e1, e2, noise_c=r * _DT_C, delta_t_c=_DT_C, table=svm_table, ideal_table=svm_table)
        t_tab = time.perf_counter() - t0
        ex = query.exact_min_contact(e1, e2, noise_c=r * _DT_C, seed=seed + 1 + k,
                                     max_contact_s=_contact_window(svm_table)[2], **exact_kw)
        res.append({"e1": e1, "e2": e2, "ratio": r, "target_s": c, "table_s": tab.value,
                    "table_interval_s": list(tab.interval), "exact_s": ex.value, "exact_interval_s": list(ex.interval),
                    "exact_wall_s": ex.extra["wall_s"], "table_wall_s": t_tab})
    return res


def _inside(v, iv) -> bool:
    lo, hi = iv
    return v is not None and (lo is None or v >= lo - 1e-9) and (hi is None or v <= hi + 1e-9)


def _svm_min_contact_row(svm_table, res, trials, repeats) -> tuple[Row, dict[str, Any]]:
    both = [x for x in res if x["table_s"] is not None and x["exact_s"] is not None]
    err = np.array([abs(x["table_s"] - x["exact_s"]) for x in both]) if both else np.array([])
    in_table_iv = sum(_inside(x["exact_s"], x["table_interval_s"]) for x in both)
    in_exact_iv = sum(_inside(x["table_s"], x["exact_interval_s"]) for x in both)
    t_ex = float(np.mean([x["exact_wall_s"] for x in res]))
    t_tab = float(np.mean([x["table_wall_s"] for x in res]))
    missing = len(res) - len(both)
    row = Row("min-contact", f"table interpolation ({svm_table.name})", _grid_label(svm_table),
              "|t_table - t_exact| [s]", p95(err), worst(err), t_tab,
              f"--exact (SVM, {trials} trials x {repeats} seeds, bisection to 0.05 s)", t_ex, int(err.size),
              f"exact inside the table's interval for {in_table_iv}/{len(both)}, table inside the exact "
              f"interval for {in_exact_iv}/{len(both)}" + (f"; {missing} without both answers" if missing else ""))
    summary = {"p95": p95(err), "worst": worst(err), "n": int(err.size), "drawn": len(res),
               "exact_in_table_interval": in_table_iv,
               "table_in_exact_interval": in_exact_iv, "exact_wall_s_mean": t_ex}
    return row, summary


def _svm_distinguishable(svm_table, pairs, rng, seed, exact_kw, progress) -> tuple[Row, dict[str, Any]]:
    """Table verdicts against one ``--exact`` evaluation each: the pairs, then the pairs at other contacts."""
    from designkit import query

    c_lo, c_hi, _ = _contact_window(svm_table)
    m = 2 * len(pairs)
    wrong, uncertain, t_tab, t_ex = 0, 0, 0.0, 0.0
    cases = []
    for k in range(m):
        e1, e2, r, c = pairs[k % len(pairs)]
        c = float(rng.uniform(c_lo, c_hi)) if k >= len(pairs) else c
        if progress:
            progress(f"queries: exact SVM distinguishable {k + 1}/{m}")
        t0 = time.perf_counter()
        tab = _table_verdict(svm_table, e1, e2, c, r, svm_table=svm_table)
        t_tab += time.perf_counter() - t0
        t0 = time.perf_counter()
        ex = query.exact_distinguishable(e1, e2, contact_s=c, noise_c=r * _DT_C, seed=seed + 100 + k, **exact_kw)
        t_ex += time.perf_counter() - t0
        bad = tab != bool(ex.extra["distinguishable"])
        wrong += bad
        uncertain += bad and ex.extra["verdict"] == "uncertain"
        cases.append({"e1": e1, "e2": e2, "ratio": r, "contact_s": c, "table": tab,
                      "exact_f1": ex.extra["svm_f1"], "exact_se": ex.extra["svm_standard_error"]})
    row = Row("distinguishable", f"table interpolation ({svm_table.name})", _grid_label(svm_table),
              "wrong verdicts (fraction)", wrong / m, wrong / m, t_tab / m,
              f"--exact (SVM, {exact_kw['trials']} trials x {exact_kw['repeats']} seeds)", t_ex / m, m,
              f"{uncertain} of {wrong} wrong verdicts were within 2 SE of the threshold")
    return row, {"cases": cases, "wrong": wrong, "wrong_uncertain": uncertain, "n": m}


def svm_query_rows(svm_table, quick: bool = True, seed: int = 0, *, n: int | None = None, repeats: int | None = None,
                   jobs: int = 1, progress: Callable[[str], None] | None = None) -> tuple[list[Row], dict[str, Any]]:
    """The SVM table's min-contact and distinguishable against ``--exact`` (Monte Carlo).

    Pairs: e1 uniform over the lower half of the grid, sigma/dT log-uniform
    over the table's range, a target contact uniform over the middle of its
    contact range ([1 s, 7.6 s] for svm-paper), and e2 = e1 + the table's
    delta towards higher e at that contact (so that the table's answer lies
    near the target). Exact answers use the table's trials, ``repeats`` seeds
    per evaluation (quick 2, full 4) and bisection to 0.05 s.

    Returns
    -------
    rows : list of Row
        ``min-contact``, then ``distinguishable``.
    facts : dict
        Every case, and the summaries the report quotes.
    """
    n = n or (3 if quick else 16)
    repeats = repeats or (2 if quick else 4)
    rng = as_generator([seed, 805])
    trials = int(svm_table.header["trials"])
    exact_kw = _exact_kw(svm_table, trials, repeats, jobs)
    pairs = _svm_pairs(svm_table, n, rng)
    res = _svm_min_contact_cases(svm_table, pairs, seed, exact_kw, progress)
    row_c, summary = _svm_min_contact_row(svm_table, res, trials, repeats)
    row_d, dist = _svm_distinguishable(svm_table, pairs, rng, seed, exact_kw, progress)
    facts = {"table": svm_table.name, "repeats": repeats, "trials": trials, "min-contact": res,
             "min-contact-summary": summary, "distinguishable": dist}
    return [row_c, row_d], facts
