"""The table route's estimates over numpy arrays: the grid crossing, the rounding-corrected estimates of
min-contact, max-noise / min-delta-t and delta-e and their stated intervals (NaN for "none" throughout), and
min-contact's and max-noise / min-delta-t's estimators as small named strategies (:data:`CONTACT_ESTIMATORS`,
:data:`RATIO_ESTIMATORS`): each says where it applies, and per element the first that applies answers
(:func:`first_applicable`).

Every function is elementwise over arrays: a single question is one element of an array question
(:mod:`designkit.query.table_arrays`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ..tables import lookup
from ..tables.store import Table
from .efficiency import interp_e_by, noise_k_max_ratio, table_z

__all__ = [
    "ABOVE", "BELOW", "CELL", "CONTACT_ESTIMATORS", "ContactReading", "Estimates", "INSIDE",
    "RATIO_ESTIMATORS", "RatioReading", "axis_weights_flagged", "cell_estimate", "contact_estimate", "cross2",
    "delta_estimate", "efficiency_estimate", "filled", "first_applicable", "grid_crossing", "held_interval",
    "nans", "pair_need_both", "partner_in_grid", "ratio_beyond", "ratio_cell", "ratio_efficiency", "ratio_estimate",
    "ratio_ideal_table", "ratio_rounding", "rounded_crossing", "rounding_estimate", "stated_log", "states_coverage",
    "table_spread", "varied_contact_estimate", "varied_estimate"
]


def axis_weights_flagged(vals: np.ndarray, x: float, *,
                         log: bool = False) -> tuple[list[tuple[int, float]], bool]:
    """Weights of ``x`` on one axis (:func:`designkit.tables.lookup.axis_weights`, the one lookup),
    plus an in-grid flag; outside the grid the nearest end, flagged (nothing is extrapolated)."""
    pts = lookup.axis_weights(vals, x, log=log, grid=np.log(vals) if log and vals[0] > 0 else vals)
    if pts is not None:
        return pts, True
    return [(0 if (x < vals[0] or (log and x <= 0)) else vals.size - 1, 1.0)], False



def cross2(x0, x1, n0, n1, gap) -> np.ndarray:
    """:func:`designkit.tables.lookup.crossing` on two grid points, elementwise over arrays (NaN: none).

    >>> float(cross2(1.0, 2.0, 300.0, 50.0, 100.0))
    1.8
    """
    x0, x1, n0, n1, gap = (np.asarray(a, dtype=np.float64) for a in (x0, x1, n0, n1, gap))  # (they broadcast)
    with np.errstate(invalid="ignore", divide="ignore"):
        ok0, ok1 = n0 <= gap, n1 <= gap  # (False at NaN)
        w = np.where(n0 != n1, (n0 - gap) / (n0 - n1), 1.0)
        inside = np.where(np.isnan(n0), x1, x0 + w * (x1 - x0))
    return np.where(ok0, x0, np.where(ok1, inside, np.nan))


def stated_log(value, lo_end, hi_end, interp, z_table: float, zc: float) -> tuple[np.ndarray, np.ndarray]:
    """``value``'s interval at the coverage of ``zc``, in log space, elementwise: the table's Monte Carlo ends
    (``lo_end``, ``hi_end``, each ``z_table`` standard errors from the value) rescaled to ``zc``, combined in
    quadrature with the interpolation error ``interp`` (one standard error, log) on each side. A missing end
    (NaN, or not positive) leaves that side open (NaN).

    >>> [round(float(v), 4) for v in stated_log(2.0, 1.0, 4.0, 0.0, 2.0, 2.0)]
    [1.0, 4.0]
    """
    v = np.log(np.asarray(value, dtype=np.float64))
    out = []
    for end, sign in ((lo_end, -1.0), (hi_end, +1.0)):
        end = np.asarray(end, dtype=np.float64)
        with np.errstate(invalid="ignore", divide="ignore"):
            mc = np.abs(np.log(end) - v) / z_table
            x = np.exp(v + sign * zc * np.hypot(mc, interp))
        out.append(np.where(np.isnan(end) | (end <= 0), np.nan, x))
    return out[0], out[1]


def held_interval(value, mc_lo, mc_hi, interp, ideal, side: str, *, raw=None, z_table: float,
                  zc: float) -> tuple[np.ndarray, np.ndarray]:
    """An estimate's stated interval, elementwise: the table's Monte Carlo ends ``mc_lo`` / ``mc_hi`` of the
    raw crossing ``raw`` carried to ``value`` (shifted by ``log(value) - log(raw)``; None: they are the
    value's own), :func:`stated_log` with the interpolation error ``interp`` (log), and the end on ``side``
    ("low" for a contact time or a distance, "high" for a sigma/dT) held at the ideal bound ``ideal`` (NaN:
    none), which no classifier beats, unless the value itself is beyond it.

    >>> [float(x) for x in held_interval(2.0, 1.0, 4.0, 0.0, 1.5, "low", z_table=2.0, zc=2.0)]
    [1.5, 4.0]
    """
    if raw is not None:
        with np.errstate(invalid="ignore", divide="ignore"):
            shift = np.log(value) - np.log(raw)
            mc_lo, mc_hi = (np.exp(np.log(np.asarray(m, dtype=np.float64)) + shift) for m in (mc_lo, mc_hi))
    low, high = stated_log(value, mc_lo, mc_hi, interp, z_table, zc)
    ideal = np.asarray(ideal, dtype=np.float64)
    if side == "low":
        return np.where(np.isnan(low) | np.isnan(ideal), low, np.minimum(np.maximum(low, ideal), value)), high
    return low, np.where(np.isnan(high) | np.isnan(ideal), high, np.maximum(np.minimum(high, ideal), value))


def contact_estimate(x0, x1, n0, n1, gap, raw, mc_lo, mc_hi, ideal, *, width: float, svm: bool,
                     z_table: float, zc: float) -> dict[str, np.ndarray]:
    """min-contact's estimate where the crossing ``raw`` [s] is interpolated between tabulated contact times
    ``x0 < x1`` [s] with needs ``n0 > gap >= n1`` [J s^-1/2 K^-1 m^-2], elementwise over arrays.

    A tabulated delta is the first grid distance whose F1 reaches Phi: the crossing of the mean F1 lies up
    to one width ``width`` below it, on average w/2 (uniform: SD w/sqrt(12)). On an SVM table (``svm``) the
    estimate subtracts w/2 from the needs and interpolates log-log (the need falls roughly as a power of the
    contact time), which removes the raw linear crossing's bias (always late: the need is convex in contact
    time); the interpolation error is the distance between the two interpolants (log), the rounding's SD
    enters through the local log-log slope. Where the corrected need no longer crosses inside the cell (or
    the grid is coarser than the needs), the raw crossing stays, with the log-log interpolant's distance as
    its error. The Monte Carlo ends ``mc_lo`` / ``mc_hi`` (the table's delta_lo / delta_hi crossings, NaN:
    none) are carried from the raw crossing to the estimate; the interval (:func:`stated_log`) never reaches
    below the ideal bound ``ideal`` (NaN: none) unless the estimate does.

    Returns
    -------
    dict of ndarray
        ``value``, ``low``, ``high`` [s], ``interp`` and ``rounding`` (log errors).

    >>> r = contact_estimate(1.0, 1.5, 6000.0, 2000.0, 3000.0, 1.375, 1.2, 1.6, 1.05, width=80.0, svm=True,
    ...                      z_table=2.0, zc=1.645)
    >>> 1.0 < float(r["value"]) < 1.375 and float(r["low"]) < float(r["value"]) < float(r["high"])
    True
    """
    x0, x1, n0, n1, gap, raw = np.broadcast_arrays(
        *(np.asarray(a, dtype=np.float64) for a in (x0, x1, n0, n1, gap, raw)))
    with np.errstate(invalid="ignore", divide="ignore"):
        lx0, lx1, lg = np.log(x0), np.log(x1), np.log(gap)
        raw_loglog = cross2(lx0, lx1, np.log(n0), np.log(n1), lg)
        raw_interp = np.where(np.isnan(raw_loglog), 0.0, np.abs(np.log(raw) - raw_loglog))
        if svm:
            c0, c1 = n0 - 0.5 * width, n1 - 0.5 * width
            ok_c = np.minimum(c0, c1) > 0  # a grid coarser than the needs themselves: no correction
            l0, l1 = np.log(c0), np.log(c1)
            loglog = np.where(ok_c, cross2(lx0, lx1, l0, l1, lg), np.nan)
            linear = cross2(x0, x1, c0, c1, gap)
            est = np.exp(loglog)
            use = ~np.isnan(loglog) & ~np.isnan(linear) & (x0 < est) & (est <= x1)
            slope = np.where(l1 != l0, np.abs((lx1 - lx0) / (l1 - l0)), 0.0)
            value = np.where(use, est, raw)
            interp = np.where(use, np.abs(loglog - np.log(linear)), raw_interp)
            rounding = np.where(use, slope * (width / math.sqrt(12.0)) / gap, 0.0)
        else:
            value, interp, rounding = raw, raw_interp, np.zeros_like(raw)
    low, high = held_interval(value, mc_lo, mc_hi, np.hypot(interp, rounding), ideal, "low", raw=raw,
                              z_table=z_table, zc=zc)
    return {"value": value, "low": low, "high": high, "interp": interp, "rounding": rounding}


def pair_need_both(view, kind: str, idx: tuple[int, ...], lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """One scene slice's need of pairs ``lo < hi`` at every contact, both directions averaged: [contact, n].

    ``delta_up(lo)`` and ``delta_down(hi)`` [J s^-1/2 K^-1 m^-2] each estimate the same thing, the distance at
    which the pair's F1 reaches Phi, so both cross ``hi - lo`` at the same contact time up to Monte Carlo
    noise: their geometric mean crosses there too, with less noise than either, where their maximum (the grid
    rule, :mod:`designkit.tables.lookup`) crosses late. A direction whose partner lies beyond the effusivity
    range (NaN) is censored: it enters at its least possible value, the distance to the range's end plus one
    width (more than ``hi - lo``: such a contact never separates the pair); both censored: NaN.
    """
    suffix = {"svm": "", "lo": "_lo", "hi": "_hi"}[kind]
    w = float(view.t.header["effusivity"]["width"])
    up, down = (interp_e_by(lambda c, rows=view.t.arrays[f"delta_{d}{suffix}"][idx]: rows[..., c], view.centres, e)
                for d, e in (("up", lo), ("down", hi)))
    both_out = np.isnan(up) & np.isnan(down)
    up = np.where(np.isnan(up), view.e_hi - lo + w, up)
    down = np.where(np.isnan(down), hi - view.e_lo + w, down)
    return np.where(both_out, np.nan, np.sqrt(up * down))


def grid_crossing(grid: np.ndarray, need: np.ndarray, gap) -> tuple[np.ndarray, ...]:
    """Per column of ``need`` [grid point, n]: the first grid point whose need is at most ``gap``, interpolated
    linearly from the point before (:func:`cross2`; that point itself where it is the first, or follows a NaN
    need; NaN where none suffices): the one grid crossing of the table route, over arrays
    (:func:`designkit.tables.lookup.crossing`'s rule). Returns ``(crossing, k, x0, x1, n0, n1)``: the index
    of the first point that suffices (-1: none), and the two points and needs the crossing lies between.

    >>> [float(v[0]) for v in grid_crossing(np.array([1.0, 2.0, 3.0]), np.array([[300.0], [150.0], [50.0]]), 100.0)]
    [2.5, 2.0, 2.0, 3.0, 150.0, 50.0]
    """
    ok = need <= gap  # (False at NaN)
    cols, k1 = np.arange(need.shape[1]), ok.argmax(axis=0)  # (the first that suffices; 0 where none does)
    k, k0 = np.where(ok[k1, cols], k1, -1), np.maximum(k1 - 1, 0)
    x0, x1, n0, n1 = grid[k0], grid[k1], need[k0, cols], need[k1, cols]
    x = np.where(k > 0, cross2(x0, x1, n0, n1, gap), np.where(k == 0, grid[0], np.nan))
    return x, k, x0, x1, n0, n1


def rounded_crossing(grid: np.ndarray, need: np.ndarray, gap, width: float) -> tuple[np.ndarray, ...]:
    """Where a tabulated need [grid point, n] crosses ``gap``, its rounding corrected: ``(value, interp,
    rounding)`` per column (NaN where the corrected need suffices at the first grid point or never).

    A tabulated delta is the first grid distance whose F1 reaches Phi, on average w/2 (``width``) above the mean
    F1's crossing: the need less w/2 crosses, in *its* own cell, log-log between its first grid point at most
    ``gap`` and the one before (the uncorrected need's cell answered late: benchmarks/results/sensor_table_bias.txt).
    ``interp``: the distance (log) to the linear interpolant's crossing; ``rounding``: w/sqrt(12) through the log-log
    slope (log).

    >>> v, interp, rounding = rounded_crossing(np.array([1.0, 2.0, 4.0]), np.array([[600.0], [360.0], [160.0]]),
    ...                                        np.array([300.0]), 80.0)
    >>> round(float(v[0]), 3), round(float(interp[0]), 3) > 0, round(float(rounding[0]), 3)
    (2.093, True, 0.054)
    """
    gap = np.asarray(gap, dtype=np.float64)
    _, k, x0, x1, c0, c1 = grid_crossing(grid, np.asarray(need, dtype=np.float64) - 0.5 * width, gap)
    with np.errstate(invalid="ignore", divide="ignore"):
        ok = (k > 0) & (np.minimum(c0, c1) > 0)
        lx0, lx1, l0, l1 = np.log(x0), np.log(x1), np.log(c0), np.log(c1)
        loglog = np.where(ok, cross2(lx0, lx1, l0, l1, np.log(gap)), np.nan)
        interp = np.abs(loglog - np.log(cross2(x0, x1, c0, c1, gap)))
        slope = np.where(l1 != l0, np.abs((lx1 - lx0) / (l1 - l0)), 0.0)
    return np.exp(loglog), interp, np.where(ok, slope * (width / math.sqrt(12.0)) / gap, np.nan)


def varied_contact_estimate(view, combos, lo, hi, ideal, *, width: float, z_table: float,
                            zc: float) -> dict[str, np.ndarray]:
    """min-contact [s] on a table with varied initial conditions, elementwise over pairs ``lo < hi``.

    Each scene slice the question lies between (``combos``: the noise and dT grid points around it, with their
    weights) answers on its own: the pair's need with both directions averaged (:func:`pair_need_both`), its crossing estimated between the two contact times around it
    as :func:`contact_estimate` does (the Monte Carlo ends from the table's ``delta_lo`` / ``delta_hi``). The
    answers are then interpolated across the slices, ``log t`` linear in the axes' own scale, instead of
    the needs (a need beyond the effusivity range in one slice made the interpolated need unknown, and the
    answer a contact later). The interval combines the slices' ends with the same weights and, in
    quadrature, the interpolation error across slices: a quarter of the weighted mean distance of the
    slices' ``log t`` from the interpolated one (for two slices at weights ``1 - u, u``, ``u (1 - u)`` times
    half their distance, the rule of :func:`noise_k_min_contact`); its low end never below the ideal bound
    ``ideal`` (NaN: none), and at the bound where the table leaves it open; an estimate below the bound is
    raised to it.

    Returns
    -------
    dict of ndarray
        ``value``, ``low``, ``high`` [s] (NaN where a slice's crossing is the table's first contact, follows
        a contact where the pair is beyond the grid in both directions, or lies beyond the last contact: the
        caller's grid reading stands there), ``interp`` (log, across slices) and ``rounding`` (log, the
        slices' weighted).
    """
    lo, hi = np.atleast_1d(np.asarray(lo, dtype=np.float64)), np.atleast_1d(np.asarray(hi, dtype=np.float64))
    ideal = np.broadcast_to(np.asarray(ideal, dtype=np.float64), lo.shape)
    gap, grid = hi - lo, view.contacts
    log_v, log_lo, log_hi, rounding = (np.zeros(lo.size) for _ in range(4))
    slices = [(idx, w) for idx, w in combos if w != 0]
    per_slice = []
    for idx, w in slices:
        # the estimate and each Monte Carlo end read by one rule from their own need (a crossing at the first
        # contact is not interpolated: the caller's grid reading stands there)
        v, r_interp, r_round = zip(*(rounded_crossing(grid, pair_need_both(view, kind, idx, lo, hi), gap, width)
                                     for kind in ("svm", "lo", "hi")))
        with np.errstate(invalid="ignore", divide="ignore"):
            low_s, high_s = held_interval(v[0], v[1], v[2], np.hypot(r_interp[0], r_round[0]), np.nan, "low",
                                          z_table=z_table, zc=zc)
        r = {"value": v[0], "low": low_s, "high": high_s, "rounding": r_round[0]}
        per_slice.append(np.log(r["value"]))
        log_v += w * np.log(r["value"])
        log_lo += w * np.log(r["low"])
        log_hi += w * np.log(r["high"])
        rounding += w * r["rounding"]
    with np.errstate(invalid="ignore"):
        interp = 0.25 * sum(w * np.abs(lv - log_v) for (_, w), lv in zip(slices, per_slice))
        value = np.exp(log_v)
        low = np.exp(log_v - np.hypot(log_v - log_lo, zc * interp))
        high = np.exp(log_v + np.hypot(log_hi - log_v, zc * interp))
        # never below the ideal bound, which no classifier beats: an estimate below it (log-linear interpolation
        # between the first contacts runs early, seen on 2 of 46 sharp cases of bench_coverage_varied.py's seed 1,
        # 10 % and 9 % early) is raised to it
        below = value < ideal
        value = np.where(below, ideal, value)
        high = np.where(below, np.maximum(high, ideal), high)
        # the low end never below the ideal bound; an open low end (the table's delta_lo already separates
        # the pair at its first contact) closes there
        low = np.where(np.isnan(ideal), low, np.minimum(np.where(np.isnan(low), ideal, np.maximum(low, ideal)),
                                                        value))
    return {"value": value, "low": low, "high": high, "interp": interp, "rounding": rounding}


def ratio_estimate(raw, r_c, r_lin, r_rnd, r_geo, end_lo, end_hi, ideal, *, z_table: float,
                   zc: float) -> dict[str, np.ndarray]:
    """max-noise / min-delta-t's estimate of the largest separating sigma/dT where the raw crossing ``raw``
    lies inside the table's noise ratios, elementwise over arrays (NaN: none).

    As :func:`contact_estimate`: the tabulated deltas are rounded up to the grid (on average half a width
    late), so the raw crossing tolerates too little noise. ``r_c`` is the crossing with w/2 subtracted from
    every need and log interpolation (log need, log contact time), ``r_lin`` the same shift interpolated
    linearly, ``r_rnd`` the log one shifted by a further w/sqrt(12) (the rounding's SD), ``r_geo`` the log one
    without shift; each NaN where it does not cross inside the grid. Where ``r_c`` and ``r_lin`` both exist the
    estimate is ``r_c``, its interpolation error their log distance and its rounding error ``r_rnd``'s;
    otherwise the raw crossing with ``r_geo``'s distance. ``end_lo`` / ``end_hi`` are the table's Monte Carlo
    ends (sigma/dT, carried from the raw crossing to the estimate); ``high`` never exceeds the ideal
    bound ``ideal`` (sigma/dT, NaN: none) unless the estimate does.

    >>> r = ratio_estimate(0.010, 0.011, 0.0112, 0.0105, 0.0101, 0.008, 0.012, 0.02, z_table=2.0, zc=1.645)
    >>> float(r["value"]), float(r["low"]) < 0.011 < float(r["high"])
    (0.011, True)
    """
    raw, r_c, r_lin, r_rnd, r_geo = np.broadcast_arrays(
        *(np.asarray(a, dtype=np.float64) for a in (raw, r_c, r_lin, r_rnd, r_geo)))
    use = ~np.isnan(r_c) & ~np.isnan(r_lin)
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.where(use, r_c, raw)
        interp = np.where(use, np.abs(np.log(r_c) - np.log(r_lin)),
                          np.where(np.isnan(r_geo), 0.0, np.abs(np.log(raw) - np.log(r_geo))))
        rounding = np.where(use & ~np.isnan(r_rnd), np.abs(np.log(r_rnd) - np.log(r_c)), 0.0)
    low, high = held_interval(r, end_lo, end_hi, np.hypot(interp, rounding), ideal, "high", raw=raw,
                              z_table=z_table, zc=zc)
    return {"value": r, "low": low, "high": high, "interp": interp, "rounding": rounding}


def delta_estimate(value, mc_lo, mc_hi, geometric, ideal, *, width: float, z_table: float,
                   zc: float) -> tuple[np.ndarray, np.ndarray]:
    """delta-e's interval of one direction's delta(e) ``value`` [J s^-1/2 K^-1 m^-2] at the coverage of ``zc``,
    elementwise over arrays (NaN: none): the table's Monte Carlo ends ``mc_lo`` / ``mc_hi`` rescaled, in
    quadrature with the interpolation error (``value`` against ``geometric``, the log-space interpolant; NaN:
    none) and the grid's rounding (the first grid distance reaching Phi: the crossing lies up to one width
    ``width`` below it, SD w/sqrt(12)); the low end never below the ideal bound ``ideal`` unless the value is.

    >>> low, high = delta_estimate(3000.0, 2800.0, 3300.0, 3050.0, 2000.0, width=80.0, z_table=2.0, zc=1.645)
    >>> 2000.0 < float(low) < 3000.0 < float(high)
    True
    """
    value = np.asarray(value, dtype=np.float64)
    geometric = np.asarray(geometric, dtype=np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        interp = np.where(np.isnan(geometric), 0.0, np.abs(np.log(value) - np.log(geometric)))
        rounding = (width / math.sqrt(12.0)) / value
    return held_interval(value, mc_lo, mc_hi, np.hypot(interp, rounding), ideal, "low", z_table=z_table, zc=zc)



def partner_in_grid(view, e, delta, direction: str):
    """Whether ``e`` moved by ``delta`` towards ``direction`` ("up" / "down") stays inside the table's effusivity
    range, elementwise. Where the tabulated delta(e) is beyond the grid at one of the two contacts around the
    asked one (the interpolated value is then none), the efficiency estimate from the other contact answers
    only where its partner lies inside the range (at 1.3 s upwards from 20000 on svm-paper: none within the
    grid at 1 s, 8680 at 1.5 s; min-contact says 35000 separates from 1.22 s).

    >>> from designkit.query.table import open_table
    >>> v = open_table("svm-paper").view
    >>> partner_in_grid(v, 20000.0, 9000.0, "up"), partner_in_grid(v, 35000.0, 9000.0, "up")
    (True, False)
    """
    with np.errstate(invalid="ignore"):
        out = e + delta <= view.e_hi if direction == "up" else e - delta > view.e_lo
    return bool(out) if np.ndim(out) == 0 else out



# ============================================================ the estimators: named strategies over arrays
def nans(n) -> np.ndarray:
    """``n`` NaNs (an int or a shape): an answer array before its elements are answered ("none" until then)."""
    out = np.empty(n)  # (not np.full: a Python-level call, several times the cost on a single question's arrays)
    out.fill(np.nan)
    return out


def filled(n: int, value, dtype=None) -> np.ndarray:
    """``n`` copies of ``value`` (as :func:`numpy.full`, at the cost of :func:`numpy.empty`)."""
    out = np.empty(n, dtype=dtype if dtype is not None else np.asarray(value).dtype)
    out.fill(value)
    return out


#: The (question, interval kind) pairs a table with varied initial conditions shows as ``table-varied``, with
#: no coverage (:data:`designkit.query.table.VARIED_COVERAGE_NOTE`): min-contact's grid-rule estimate and grid
#: cell. Its min-contact estimates (``table-varied-estimate``) and delta-e's (``table-estimate``) state theirs,
#: measured to hold there (``bench_coverage_varied.py``, 200 random cases each against 16-seed exact references).
VARIED_UNMEASURED = frozenset({("min-contact", "table-estimate"), ("min-contact", "table-cell")})


def table_spread(tab: Table) -> float:
    """Half-width [degC] of the per-touch sensor temperature a table was built with (0: fixed conditions)."""
    return float(tab.header.get("config", {}).get("sensor_temp_spread_c") or 0.0)


def states_coverage(tab: Table, question: str, interval_kind: str | None) -> bool:
    """Whether an answer of ``question`` from ``tab`` may state the coverage of an interval of this kind:
    everywhere but on a varied table's :data:`VARIED_UNMEASURED` kinds."""
    return not (table_spread(tab) > 0 and (question, interval_kind) in VARIED_UNMEASURED)


@dataclass(frozen=True)
class Estimates:
    """One estimator's answers over the elements it ``applies`` to (elsewhere ignored): value and interval in the
    answer's units, the interval's kind, whether it states the asked coverage, further arrays (``extra``)."""

    applies: np.ndarray
    value: np.ndarray
    low: np.ndarray
    high: np.ndarray
    kind: str
    stated: bool
    extra: dict = field(default_factory=dict)


def _at(v, m: np.ndarray):
    """``v`` (an array of the elements, or one value for all) at the elements ``m``."""
    return v[m] if np.ndim(v) else v


def first_applicable(estimators, rd, n: int) -> dict[str, np.ndarray]:
    """Per element, the answer of the first estimator (in order) that applies to it (``kind`` "none" where none
    does)."""
    out: dict[str, np.ndarray] = {}
    taken, n_taken = None, 0  # (the elements answered, None: none yet; and how many)
    for estimator in estimators:
        if n_taken == n:  # (the later ones would answer nothing)
            break
        r = estimator(rd)
        if r is None:
            continue
        m = r.applies if taken is None else r.applies & ~taken
        if not (n_m := np.count_nonzero(m)):
            continue
        if n_m == n:  # it answers every element (a single question's usual case): its arrays whole
            for k, v in (*((k, getattr(r, k)) for k in ("value", "low", "high")), *r.extra.items()):
                out[k] = np.array(v, dtype=np.float64) if np.ndim(v) else filled(n, v, np.float64)
            out["kind"], out["stated"] = filled(n, r.kind, object), filled(n, r.stated, bool)
            return out
        if not out:
            out = _unanswered(n)
        for k in ("value", "low", "high"):
            out[k][m] = _at(getattr(r, k), m)
        out["kind"][m], out["stated"][m] = r.kind, r.stated
        for k, v in r.extra.items():
            out.setdefault(k, nans(n))[m] = _at(v, m)
        taken, n_taken = (m if taken is None else taken | m), n_taken + n_m
    return out or _unanswered(n)


def _unanswered(n: int) -> dict[str, np.ndarray]:
    """:func:`first_applicable`'s answers before any estimator answers: none."""
    out = dict(zip(("value", "low", "high"), nans((3, n))))
    out["kind"], out["stated"] = filled(n, "none", object), np.zeros(n, dtype=bool)
    return out


# ---------------------------------------------------------------- min-contact's
@dataclass(frozen=True)
class ContactReading:
    """What min-contact read from the table for pairs ``lo < hi``: the crossing ``raw`` [s] of the tabulated need
    (NaN: none within the table), its contact index ``k_cross`` (-1: none) and the needs around it, the Monte
    Carlo ends' crossings, the ideal bound and the floor the intervals are held above, the noise-efficiency
    readings (None: the route does not apply), the scene slices of each scene's elements."""

    op: Any
    lo: np.ndarray
    hi: np.ndarray
    raw: np.ndarray
    k_cross: np.ndarray
    n_prev: np.ndarray
    n_at: np.ndarray
    mc_lo: np.ndarray
    mc_hi: np.ndarray
    ideal: np.ndarray
    floor: np.ndarray
    eff: dict | None
    slices: list
    zc: float

    @property
    def svm(self) -> bool:
        return self.op.tab.fidelity == "svm"


def varied_estimate(rd: ContactReading) -> Estimates | None:
    """Each scene slice's estimate, both directions averaged, interpolated across the slices
    (:func:`~designkit.query.estimates.varied_contact_estimate`): an SVM table with varied initial conditions,
    or one whose model has no closed-form ideal observer (a calibrated rig's: no efficiency route; the grid
    rule's maximum of the two directions answered its pairs late, by 3 % and 8 % on two of five measured against
    fresh seeds, benchmarks/results/sensor_table_bias.txt)."""
    op, n = rd.op, rd.lo.size
    varied = table_spread(op.tab) > 0
    if not (rd.svm and (varied or not op.closed) and "delta_up_lo" in op.view.t.arrays):
        return None
    # the estimate averages two independent readings of one distance (each direction's staircase): its Monte
    # Carlo error is each one's over sqrt(2). On the rig's fixed-condition table the intervals without it held
    # all 11 exact answers of a first run (z-scores' SD 0.38); a varied table's intervals are kept as measured
    # (bench_coverage_varied.py: 85 of 96), where the slices' interpolation adds its own error
    z_mc = table_z(op.tab) * (1.0 if varied else math.sqrt(2.0))
    out = {k: nans(n) for k in ("value", "low", "high", "interp", "rounding")}
    for combos, idx in rd.slices:
        r = varied_contact_estimate(op.view, combos, rd.lo[idx], rd.hi[idx], rd.floor[idx], width=op.width,
                                    z_table=z_mc, zc=rd.zc)
        for k in out:
            out[k][idx] = r[k]
    return Estimates(~np.isnan(out["value"]), out["value"], out["low"], out["high"],
                     "table-varied-estimate" if varied else "table-estimate", True,
                     {"interp": out["interp"], "rounding": out["rounding"]})


def efficiency_estimate(rd: ContactReading) -> Estimates | None:
    """The SVM's noise efficiency against the exact ideal observer
    (:func:`~designkit.query.efficiency.noise_k_min_contact`): no interpolation of the steep need between grid
    points (an SVM table of a model with a closed form)."""
    eff = rd.eff
    if eff is None:
        return None
    with np.errstate(invalid="ignore"):
        low = np.where(np.isnan(rd.ideal), eff["low"], np.minimum(np.maximum(eff["low"], rd.ideal), eff["value"]))
    return Estimates(~(np.isnan(rd.raw) | np.isnan(eff["value"])), eff["value"], low, eff["high"],
                     "table-efficiency", True, {f"eff_{k}": eff[k] for k in ("k", "se_log", "k_a", "k_b", "t_a", "t_b")})


def rounding_estimate(rd: ContactReading) -> Estimates | None:
    """Interpolated between two tabulated needs (:func:`~designkit.query.estimates.contact_estimate`): the table's
    Monte Carlo interval (its deltas' z-SE ends, rescaled to the coverage) and the interpolation error (the
    distance to a log-log interpolation's crossing), the grid's rounding corrected on an SVM table."""
    op, k = rd.op, rd.k_cross
    applies = (k > 0) & ~np.isnan(rd.n_prev) & ~np.isnan(rd.raw)
    if not applies.any():
        return None
    grid = op.view.contacts
    with np.errstate(invalid="ignore", divide="ignore"):
        r = contact_estimate(grid[np.maximum(k - 1, 0)], grid[np.maximum(k, 0)], rd.n_prev, rd.n_at, rd.hi - rd.lo,
                             rd.raw, rd.mc_lo, rd.mc_hi, rd.floor, width=op.width, svm=rd.svm,
                             z_table=table_z(op.tab), zc=rd.zc)
    return Estimates(applies, r["value"], r["low"], r["high"], "table-estimate",
                     states_coverage(op.tab, "min-contact", "table-estimate"),
                     {"interp": r["interp"], "rounding": r["rounding"]})


def cell_estimate(rd: ContactReading) -> Estimates | None:
    """The grid cell the crossing lies in, no stated coverage: where the crossing is the table's first contact,
    or follows a contact where the pair is beyond the grid. With the initial temperature varied per touch F1
    need not rise with contact time: the cell then starts at the ideal bound."""
    grid, k = rd.op.view.contacts, rd.k_cross
    start = np.where(k > 0, grid[np.maximum(k - 1, 0)], 0.0)
    if table_spread(rd.op.tab) > 0:
        start = np.zeros_like(start)
    low = np.where(np.isnan(rd.floor), start, np.maximum(start, rd.floor))
    return Estimates(~np.isnan(rd.raw), rd.raw, low, rd.raw, "table-cell", False)


#: min-contact's estimators from a table, in the order tried: per element the first that applies answers.
CONTACT_ESTIMATORS: tuple[Callable[[ContactReading], Estimates | None], ...] = (
    varied_estimate, efficiency_estimate, rounding_estimate, cell_estimate)


# ---------------------------------------------------------------- max-noise / min-delta-t's
BELOW, INSIDE, ABOVE, CELL = 0, 1, 2, 3  # where a largest separating ratio lies




@dataclass(frozen=True)
class RatioReading:
    """What max-noise / min-delta-t read for pairs ``lo < hi`` at contacts ``contact`` [s]: the largest separating
    sigma/dT ``r`` and where it lies (``where``, -1: not read), the Monte Carlo ends ``end_hi`` / ``end_lo``
    (sigma/dT), the ideal observer's ``ri`` (NaN: none), the rounding estimate's interpolants ``alt``, and the
    conversion of sigma/dT to the answer (``scale``: dT for max-noise, noise for min-delta-t)."""

    op: Any
    question: str
    contact: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    r: np.ndarray
    where: np.ndarray
    end_hi: np.ndarray
    end_lo: np.ndarray
    ri: np.ndarray
    alt: dict
    scale: np.ndarray
    zc: float

    def answer(self, r):
        """sigma/dT in the answer's units [degC]."""
        return r * self.scale if self.question == "max-noise" else self.scale / r

    def interval(self, r_low, r_high):
        """An interval of sigma/dT ends in the answer's units, low <= high."""
        a, b = self.answer(r_low), self.answer(r_high)
        return (a, b) if self.question == "max-noise" else (b, a)

    @property
    def svm(self) -> bool:
        return self.op.tab.fidelity == "svm"


def ratio_efficiency(rd: RatioReading) -> Estimates | None:
    """The SVM's noise efficiency against the exact ideal observer
    (:func:`~designkit.query.efficiency.noise_k_max_ratio`), never beyond the ideal observer's."""
    op = rd.op
    cand = ((rd.where == INSIDE) | (rd.where == CELL)) & ~np.isnan(rd.ri)
    if not (rd.svm and op.closed and "delta_up_ideal" in op.view.t.arrays and cand.any()):
        return None
    i = np.nonzero(cand)[0]
    kr = noise_k_max_ratio(op, rd.contact[i], rd.r[i], rd.ri[i], rd.lo[i], rd.hi[i], zc=rd.zc)
    out = {k: nans(rd.lo.size) for k in ("r", "low", "high", "k", "se_log")}
    out["r"][i], out["low"][i] = np.minimum(kr["value"], rd.ri[i]), kr["low"]
    out["high"][i], out["k"][i], out["se_log"][i] = np.minimum(kr["high"], rd.ri[i]), kr["k"], kr["se_log"]
    with np.errstate(invalid="ignore", divide="ignore"):
        low, high = rd.interval(out["low"], out["high"])
        value = rd.answer(out["r"])
    return Estimates(~np.isnan(out["r"]), value, low, high, "table-efficiency", True,
                     {"ratio": out["r"], "eff_k": out["k"], "eff_se_log": out["se_log"]})


def ratio_rounding(rd: RatioReading) -> Estimates | None:
    """As min-contact's: the tabulated deltas are rounded up to the grid (on average half a width late), so the
    raw crossing tolerates too little noise; the answer subtracts w/2 from the need and interpolates log-log,
    the interval carries the interpolants' difference and the rounding's SD
    (:func:`~designkit.query.estimates.ratio_estimate`)."""
    applies = rd.where == INSIDE
    if not (rd.svm and applies.any()):
        return None
    a = rd.alt
    est = ratio_estimate(rd.r, a["c"], a["lin"], a["rnd"], a["geo"], rd.end_hi, rd.end_lo, rd.ri,
                         z_table=table_z(rd.op.tab), zc=rd.zc)
    with np.errstate(invalid="ignore", divide="ignore"):
        low, high = rd.interval(est["low"], est["high"])
        value = rd.answer(est["value"])
    return Estimates(applies, value, low, high, "table-estimate", True,
                     {"ratio": est["value"], "interp": est["interp"], "rounding": est["rounding"]})


def ratio_cell(rd: RatioReading) -> Estimates | None:
    """A neighbour beyond the grid: the crossing lies in the cell up to the next ratio (or the ideal bound), no
    stated coverage."""
    applies = rd.where == CELL
    if not applies.any():
        return None
    ratios = rd.op.view.t.axes["noise_ratio"]
    k = np.searchsorted(ratios, np.where(applies, rd.r, ratios[0]))
    nxt = ratios[np.minimum(k + 1, ratios.size - 1)]
    nxt = np.where(np.isnan(rd.ri), nxt, np.minimum(nxt, rd.ri))
    with np.errstate(invalid="ignore", divide="ignore"):
        low, high = rd.interval(rd.r, nxt)
        value = rd.answer(rd.r)
    return Estimates(applies, value, low, high, "table-cell", False, {"next_ratio": nxt})


def ratio_ideal_table(rd: RatioReading) -> Estimates | None:
    """An ideal-observer table: the answer with its Monte Carlo ends, no stated coverage."""
    applies = rd.where == INSIDE
    if not applies.any():
        return None
    with np.errstate(invalid="ignore", divide="ignore"):
        mc = [rd.answer(rd.end_hi), rd.answer(rd.end_lo)]
        both = ~np.isnan(mc[0]) & ~np.isnan(mc[1])
        return Estimates(applies, rd.answer(rd.r), np.where(both, np.fmin(*mc), mc[0]),
                         np.where(both, np.fmax(*mc), mc[1]), "table", False)


def ratio_beyond(rd: RatioReading) -> Estimates | None:
    """Separable beyond the table's largest ratio: the answer is a one-sided bound."""
    applies = rd.where == ABOVE
    if not applies.any():
        return None
    with np.errstate(invalid="ignore", divide="ignore"):
        v = rd.answer(rd.r)
    nan = nans(v.size)
    return Estimates(applies, v, *((v, nan) if rd.question == "max-noise" else (nan, v)), "table-cell", False)


#: max-noise / min-delta-t's estimators from a table, in the order tried: per element the first that applies.
RATIO_ESTIMATORS: tuple[Callable[[RatioReading], Estimates | None], ...] = (
    ratio_efficiency, ratio_rounding, ratio_cell, ratio_ideal_table, ratio_beyond)


