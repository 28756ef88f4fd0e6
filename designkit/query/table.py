"""The table route: design questions answered from a lookup table in milliseconds.

delta(e) is interpolated linearly in effusivity and contact time and
log-linearly in sigma/dT between the table's grid points. A question outside
the grid gets no value (``in_grid`` says which axis, the notes say the range
in the user's units), never an extrapolation; where the ideal observer has a
closed form its bound is still given (it needs no table). A table built for another
forward model, sensor or threshold than the one asked is refused
(:class:`~designkit.query.inputs.TableMismatch`). This route imports neither
scikit-learn nor matplotlib.

Decision rule for a pair ``e1 < e2`` (the lower edges of the two classes,
:mod:`designkit.query.inputs`): distinguishable when the distance ``e2 - e1``
reaches both ``delta_up(e1)`` (seen from the lower effusivity) and
``delta_down(e2)`` (seen from the higher one); the two agree up to Monte Carlo
noise, and requiring both is the conservative choice. ``min-contact``'s estimate
on a table with varied initial conditions averages the two instead, and
interpolates each scene slice's answer rather than the need
(:func:`varied_contact_estimate`; why: docs/decisions-log.md, "Question layer").

The ideal bound comes from an ideal-observer table (``ideal_table``) or the
SVM table's own ideal arrays, interpolated the same way; ``distinguishable``
computes the ideal F1 in closed form.

``distinguishable`` does not compare the need interpolated at the asked contact
with the pair's distance (that grid-only verdict, what an export answers, is kept
beside it: :func:`grid_answer`): its yes / no is the asked contact against
:func:`min_contact`'s answer for the pair at the asked noise and dT, and it is
"confident" only outside min-contact's stated interval, so the questions agree.

``min-contact``, ``max-noise`` and ``min-delta-t`` on an SVM table, where the model
has a closed-form ideal observer, do not interpolate the SVM's need between
tabulated points (it falls steeply there): they read the SVM's *noise
efficiency* k at the tabulated contact times around the answer (the noise at
which the ideal observer needs the tabulated separation, over the table's) and
apply it to the exact ideal observer (:func:`noise_k_min_contact`,
:func:`noise_k_max_ratio`; docs/accuracy.md has their coverage). ``delta-e``
reads the ratio of the SVM's tabulated need to the ideal observer's, computed
exactly at each tabulated entry (:func:`delta_efficiency_estimate`).

Examples
--------
>>> a = min_contact(35000, 20000, noise_c=0.05, delta_t_c=10.0, table="ideal-paper")
>>> a.route, a.table, 1.0 < a.value <= 2.0
('table', 'ideal-paper', True)
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
from cachetools import LRUCache

from .._validation import InputError, check_nonnegative
from ..sensor import within_sample_limit
from ..tables import lookup
from ..tables.lookup import GRID_RTOL
from ..tables.store import Table, load_table, resolve_table
from .answer import Answer, IdealBound, ideal_floor, number
from .crossing import check_coverage, z_of_coverage
from .inputs import (
    REFERENCE_RULE,
    PairQuestion,
    TableMismatch,
    check_contact,
    check_threshold,
    pair_question,
    reference_class,
    scene_inputs,
)

__all__ = [
    "axis_weights_flagged",
    "table_z",
    "DEFAULT_IDEAL_TABLE",
    "CLOSED_FORM_MAX_CONTACT_S",
    "CLOSED_FORM_RATIO_BRACKET",
    "delta_efficiency_estimate",
    "delta_entries",
    "DEFAULT_TABLE",
    "SPREAD_TABLE_QUESTIONS",
    "VARIED_TABLE",
    "GRID_RTOL",
    "clear_table_cache",
    "contact_estimate",
    "cross2",
    "delta_e",
    "delta_e_ideal_view",
    "GRID_KINDS",
    "grid_answer",
    "grid_crossing",
    "delta_estimate",
    "distinguishable",
    "max_noise",
    "min_contact",
    "min_delta_t",
    "noise_k_max_ratio",
    "noise_k_min_contact",
    "open_table",
    "partner_in_grid",
    "ratio_estimate",
    "stated_log",
    "shipped_spread_table",
    "table_spread",
]

DEFAULT_TABLE = "svm-fine"
#: The shipped table for the paper's second setting (the sensor's temperature drawn per touch, uniform in
#: 30-35 degC with the object at 25 degC: dT 7.5 degC, spread 2.5 degC): a question with that spread reads it.
VARIED_TABLE = "svm-paper-varied"
#: Longest contact [s] the closed-form ideal bound examines (the exact route's default).
CLOSED_FORM_MAX_CONTACT_S = 10.0
#: sigma/dT the closed-form ideal bound searches (the exact route's bracket).
CLOSED_FORM_RATIO_BRACKET = (1e-5, 1.0)
DEFAULT_IDEAL_TABLE = "ideal-paper"


#: Tables loaded (and verified) by this process, keyed by their files' identity: a name or path is
#: read and hashed once, not on every question. Least recently used out.
_LOADED: "LRUCache[tuple, Table]" = LRUCache(16)


def _as_table(table: "Table | str") -> Table:
    """A Table object, or the table a name or path names, loaded once per process while its files
    are unchanged (same path, size and modification time of the .npz and the .json header)."""
    if isinstance(table, Table):
        return table
    npz = resolve_table(table)
    try:
        key = tuple((str(p), st.st_mtime_ns, st.st_size) for p in (npz, npz.with_suffix(".json"))
                    for st in (p.stat(),))
    except OSError:  # let load_table say what is missing
        return load_table(npz)
    t = _LOADED.get(key)
    if t is None:
        t = _LOADED[key] = load_table(npz)
    return t


#: :meth:`_View.mc_calibration` per table content (a view is made per question; the measure is the table's:
#: computed once per process, not on every question).
_MC_CALIBRATION: dict[str, float] = {}
#: :meth:`_View.need` per table content (at most 65,536 a table, then forgotten).
_NEEDS: dict[str, dict[tuple, float]] = {}


def clear_table_cache() -> None:
    """Forget the tables this process has loaded (they are re-read and re-verified on next use), and the
    noise-efficiency readings taken from them."""
    _LOADED.clear()
    _K_READINGS.clear()
    _MC_CALIBRATION.clear()
    _DELTA_EFF.clear()
    _NEEDS.clear()


# ============================================================ interpolation
class _View:
    """Interpolation on one table."""

    def __init__(self, table: Table):
        self.t = table
        ax = table.axes
        self.centres = ax["e_ref"]
        self.contacts = ax["contact_s"]
        self.scene_axes = [n for n in table.axis_names if n not in ("contact_s", "e_ref")]
        self.e_lo = float(table.header["effusivity"]["min"])
        self.e_hi = float(table.header["effusivity"]["max"])
        # need() is a function of the table's content and its arguments: asked again (by any question on this
        # table in this process: a view is made per question), not recomputed
        h = table.header.get("content_hash")
        self._needs: dict[tuple, float] = _NEEDS.setdefault(h, {}) if h is not None else {}

    # ---- scene axes -> weights
    def scene_weights(self, noise_c: float, delta_t_c: float) -> tuple[list[tuple[tuple[int, ...], float]], dict[str, bool]]:
        """Multilinear weights over the scene axes; in-grid flags per axis."""
        ax = self.t.axes
        coords: list[list[tuple[int, float]]] = []
        flags: dict[str, bool] = {}
        if self.scene_axes == ["noise_ratio"]:
            wanted = {"noise_ratio": noise_c / abs(delta_t_c)}
        else:
            wanted = {"noise_c": noise_c, "delta_t_c": delta_t_c}
        for name in self.scene_axes:
            vals = ax[name]
            scale = next(a["scale"] for a in self.t.header["axes"] if a["name"] == name)
            pts, ok = axis_weights_flagged(vals, wanted[name], log=scale == "log")
            coords.append(pts)
            flags[name] = ok
        combos = [((), 1.0)]
        for pts in coords:
            combos = [(idx + (k,), w * wk) for idx, w in combos for k, wk in pts]
        return combos, flags

    def delta_at(self, name: str, combos, k: int, e: float) -> float:
        """delta array ``name`` at scene weights, contact index ``k``, effusivity ``e`` (NaN = none)."""
        arr = self.t.arrays[name]
        total = 0.0
        for idx, w in combos:
            if w == 0:
                continue
            v = _interp_e(arr[idx + (k,)], self.centres, e)
            if math.isnan(v):
                return math.nan
            total += w * v
        return total

    def need(self, kind: str, combos, k: int, lo: float, hi: float) -> float:
        """Distance needed to separate lo < hi at contact index k (NaN: not within the grid)."""
        key = (kind, tuple(combos), k, lo, hi)
        hit = self._needs.get(key)
        if hit is not None:
            return hit
        if len(self._needs) >= 65536:
            self._needs.clear()
        self._needs[key] = value = self._need(kind, combos, k, lo, hi)
        return value

    def _need(self, kind: str, combos, k: int, lo: float, hi: float) -> float:
        suffix = {"svm": "", "lo": "_lo", "hi": "_hi", "ideal": "_ideal"}[kind]
        up_name, down_name = f"delta_up{suffix}", f"delta_down{suffix}"
        if up_name not in self.t.arrays:  # ideal tables carry only delta_up / delta_down
            up_name, down_name = "delta_up", "delta_down"
        up = self.delta_at(up_name, combos, k, lo)
        down = self.delta_at(down_name, combos, k, hi)
        if math.isnan(up) or math.isnan(down):
            return math.nan
        return max(up, down)

    def mc_calibration(self) -> float:
        """Factor on the table's Monte Carlo standard errors that matches the scatter of its own entries.

        Measured on the table itself (leave one contact out): every interior contact's log efficiency
        ``log((svm need - w/2) / (ideal need - w/2))`` (both directions, every noise-ratio slice and
        effusivity) is predicted from its two neighbours on the contact axis at least :data:`K_SLOPE_SPAN`
        away on each side (linear in log t); each residual
        is standardized by the SD its three entries' stated errors give: ``f`` times the table's Monte Carlo
        SE of each SVM need (``delta_lo`` / ``delta_hi``, ``z`` SEs each) and the rounding of both needs
        (``w/sqrt(12)`` each). The factor ``f`` is the one that makes the standardized residuals' robust SD
        (1.4826 x median |r|) 1. Entries whose ideal need is under four widths (rounding dominates there)
        are left out. The residuals also carry the need's curvature across two cells, so ``f`` errs high
        (on svm-paper 0.78: its Monte Carlo intervals are a quarter wider than its entries scatter; on
        svm-fine 0.72).
        1 where the table has no ideal needs or no Monte Carlo interval to calibrate (fewer than 20
        residuals).
        """
        key = self.t.header.get("content_hash")
        hit = _MC_CALIBRATION.get(key) if key is not None else None  # a table without a hash: not cached
        if hit is not None:
            return hit
        arrays, h = self.t.arrays, 0.5 * float(self.t.header["effusivity"]["width"])
        rnd_sd, z = 2.0 * h / math.sqrt(12.0), table_z(self.t)
        lt = np.log(self.contacts)
        res, vm, vr = [], [], []
        for d in ("up", "down"):
            if f"delta_{d}_ideal" not in arrays or f"delta_{d}_lo" not in arrays:
                continue
            svm, ideal = arrays[f"delta_{d}"], arrays[f"delta_{d}_ideal"]  # [slice, contact, e_ref]
            lo, hi = arrays[f"delta_{d}_lo"], arrays[f"delta_{d}_hi"]
            with np.errstate(invalid="ignore", divide="ignore"):
                le = np.log((svm - h) / (ideal - h))
                rnd2 = (rnd_sd / (svm - h)) ** 2 + (rnd_sd / (ideal - h)) ** 2
                mc = np.where(np.isfinite(hi) & (lo > h), np.log((hi - h) / (lo - h)) / (2.0 * z),
                              np.where(lo > h, np.log((svm - h) / (lo - h)) / z, np.nan))
            # the neighbours at least K_SLOPE_SPAN away: entries closer than that share most of their touches (a
            # shorter contact is a prefix of a longer one) and their Monte Carlo errors correlate, which shrinks the
            # residuals (on svm-fine f is 0.65 from neighbours 0.1 s apart, 0.71, 0.75, 0.77 from 0.2, 0.3, 0.4 s);
            # on svm-paper's axis these are the next contacts
            backs, aheads = span_neighbours(self.contacts, np.arange(lt.size))
            for k, a, b in zip(range(lt.size), backs, aheads):
                if a < 0 or b < 0:
                    continue
                w = (lt[k] - lt[a]) / (lt[b] - lt[a])
                # entries at or below half a width give infinite logs (inf - inf here): left out by `ok`
                with np.errstate(invalid="ignore", over="ignore"):
                    r = le[:, k] - ((1.0 - w) * le[:, a] + w * le[:, b])
                    v_mc = mc[:, k] ** 2 + ((1.0 - w) * mc[:, a]) ** 2 + (w * mc[:, b]) ** 2
                    v_rnd = rnd2[:, k] + (1.0 - w) ** 2 * rnd2[:, a] + w ** 2 * rnd2[:, b]
                    ok = (np.isfinite(r) & np.isfinite(v_mc) & (v_mc > 0) & np.isfinite(v_rnd)
                          & (np.fmin(np.fmin(ideal[:, a], ideal[:, k]), ideal[:, b]) >= 8.0 * h))
                res.append(r[ok]), vm.append(v_mc[ok]), vr.append(v_rnd[ok])
        r = np.abs(np.concatenate(res)) if res else np.zeros(0)
        value = 1.0
        if r.size >= 20:
            v_mc, v_rnd = np.concatenate(vm), np.concatenate(vr)
            a, b = math.log(0.05), math.log(20.0)  # bisection on log f: the robust SD falls as f grows
            for _ in range(30):
                f = math.exp(0.5 * (a + b))
                if 1.4826 * _median(r / np.sqrt(f * f * v_mc + v_rnd)) > 1.0:
                    a = math.log(f)
                else:
                    b = math.log(f)
            value = math.exp(0.5 * (a + b))
        if key is not None:
            _MC_CALIBRATION[key] = value
        return value

    def e_in_grid(self, *es: float) -> bool:
        return all(self.e_lo < e <= self.e_hi for e in es)


def _median(x: np.ndarray) -> float:
    """The median of a non-empty 1-D array (not ``np.median``, whose first call imports ``numpy.ma``:
    docs/decisions-log.md).

    >>> _median(np.array([3.0, 1.0, 10.0, 2.0])), _median(np.array([5.0, 1.0, 4.0]))
    (2.5, 4.0)
    """
    k = x.size // 2
    p = np.partition(x, [k - 1, k] if x.size > 1 else [0])
    return float(p[k]) if x.size % 2 else 0.5 * float(p[k - 1] + p[k])


def axis_weights_flagged(vals: np.ndarray, x: float, *,
                         log: bool = False) -> tuple[list[tuple[int, float]], bool]:
    """Weights of ``x`` on one axis (:func:`designkit.tables.lookup.axis_weights`, the one lookup),
    plus an in-grid flag; outside the grid the nearest end, flagged (nothing is extrapolated)."""
    pts = lookup.axis_weights(vals, x, log=log, grid=np.log(vals) if log and vals[0] > 0 else vals)
    if pts is not None:
        return pts, True
    return [(0 if (x < vals[0] or (log and x <= 0)) else vals.size - 1, 1.0)], False


def _interp_e(row: np.ndarray, centres: np.ndarray, e: float) -> float:
    """delta at effusivity e (:func:`designkit.tables.lookup.interp_e`); NaN if a neighbour is NaN."""
    return float(lookup.interp_e(row, centres, e))


def _crossing(xs: Sequence[float], needs: Sequence[float], gap: float) -> tuple[float | None, int | None]:
    """First x where need(x) <= gap, interpolated (:func:`designkit.tables.lookup.crossing`)."""
    return lookup.crossing(xs, needs, gap)


def table_z(tab: Table) -> float:
    """The z (standard errors) of the table's Monte Carlo interval of delta(e) (its header; 2 if absent)."""
    return float(tab.header.get("z") or 2.0)


# ============================================================ estimates shared with the array route
# The rounding correction and the stated intervals are written once, over numpy arrays (NaN for "none"):
# the scalar questions below call them with one element, designkit.query.vectorized with many.
def _arr(x) -> np.ndarray:
    return np.asarray(np.nan if x is None else x, dtype=np.float64)


def _opt(x) -> float | None:
    """One element back to the scalar route's convention (None for NaN)."""
    v = float(x)
    return None if math.isnan(v) else v


def cross2(x0, x1, n0, n1, gap) -> np.ndarray:
    """:func:`designkit.tables.lookup.crossing` on two grid points, elementwise over arrays (NaN: none).

    >>> float(cross2(1.0, 2.0, 300.0, 50.0, 100.0))
    1.8
    """
    x0, x1, n0, n1, gap = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in (x0, x1, n0, n1, gap)))
    with np.errstate(invalid="ignore", divide="ignore"):
        ok0 = ~np.isnan(n0) & (n0 <= gap)
        ok1 = ~np.isnan(n1) & (n1 <= gap)
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
        shift = np.log(value) - np.log(raw)
        ends = [np.exp(np.log(np.asarray(m, dtype=np.float64)) + shift) for m in (mc_lo, mc_hi)]
    low, high = stated_log(value, ends[0], ends[1], np.hypot(interp, rounding), z_table, zc)
    ideal = np.asarray(ideal, dtype=np.float64)
    low = np.where(np.isnan(low) | np.isnan(ideal), low, np.minimum(np.maximum(low, ideal), value))
    return {"value": value, "low": low, "high": high, "interp": interp, "rounding": rounding}


def _interp_e_by(at, centres: np.ndarray, e: np.ndarray) -> np.ndarray:
    """:func:`designkit.tables.lookup.interp_e`'s rule over arrays: ``at(c)`` gives the tabulated values at
    centre indices ``c`` (an array shaped as ``e``), and the result is shaped as what ``at`` returns."""
    n = centres.size
    c = np.clip(np.searchsorted(centres, e, side="right") - 1, 0, n - 2)
    a, b = at(c), at(c + 1)
    w = (e - centres[c]) / (centres[c + 1] - centres[c])
    with np.errstate(invalid="ignore"):
        out = np.where(w == 0.0, a, np.where(np.isnan(a) | np.isnan(b), np.nan, a + w * (b - a)))
    out = np.where(e >= centres[-1], at(np.full_like(c, n - 1)), out)
    return np.where(e <= centres[0], at(np.zeros_like(c)), out)


def interp_e_rows(rows: np.ndarray, centres: np.ndarray, e: np.ndarray) -> np.ndarray:
    """:func:`designkit.tables.lookup.interp_e` for every row of ``rows`` [contact, centre] at every ``e``:
    shape [contact, len(e)]."""
    return _interp_e_by(lambda c: rows[:, c], centres, e)


def _pair_need_both(view: _View, kind: str, idx: tuple[int, ...], lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
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
    up = interp_e_rows(view.t.arrays[f"delta_up{suffix}"][idx], view.centres, lo)
    down = interp_e_rows(view.t.arrays[f"delta_down{suffix}"][idx], view.centres, hi)
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
    with np.errstate(invalid="ignore"):
        ok = ~np.isnan(need) & (need <= gap)
    k = np.where(ok.any(axis=0), ok.argmax(axis=0), -1)
    cols, k0, k1 = np.arange(need.shape[1]), np.maximum(k - 1, 0), np.maximum(k, 0)
    x0, x1, n0, n1 = grid[k0], grid[k1], need[k0, cols], need[k1, cols]
    with np.errstate(invalid="ignore", divide="ignore"):
        x = np.where(k > 0, cross2(x0, x1, n0, n1, gap), np.where(k == 0, grid[0], np.nan))
    return x, k, x0, x1, n0, n1


def varied_contact_estimate(view: _View, combos, lo, hi, ideal, *, width: float, z_table: float,
                            zc: float) -> dict[str, np.ndarray]:
    """min-contact [s] on a table with varied initial conditions, elementwise over pairs ``lo < hi``.

    Each scene slice the question lies between (``combos``: the noise and dT grid points around it, with their
    weights) answers on its own: the pair's need with both directions averaged (:func:`_pair_need_both`), its crossing estimated between the two contact times around it
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
        # (a crossing at the first contact is not interpolated: the caller's grid reading stands there)
        raw, k, x0, x1, n0, n1 = grid_crossing(grid, _pair_need_both(view, "svm", idx, lo, hi), gap)
        raw = np.where(k > 0, raw, np.nan)
        ends = [np.where(kk > 0, x, np.nan) for x, kk in (
            grid_crossing(grid, _pair_need_both(view, kind, idx, lo, hi), gap)[:2] for kind in ("lo", "hi"))]
        with np.errstate(invalid="ignore", divide="ignore"):
            r = contact_estimate(x0, x1, n0, n1, gap, raw, ends[0], ends[1], np.nan, width=width, svm=True,
                                 z_table=z_table, zc=zc)
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


# ============================================================ the noise efficiency (min-contact)
def _interp_at(arr3d: np.ndarray, centres: np.ndarray, si: np.ndarray, j: np.ndarray, e: np.ndarray) -> np.ndarray:
    """:func:`designkit.tables.lookup.interp_e` of ``arr3d[si[p], j[p]]`` (a [slice, contact, centre] array) at
    ``e[p]``, per p."""
    return _interp_e_by(lambda c: arr3d[si, j, c], centres, e)


#: The noise-efficiency readings of small calls (a single question's), kept per process (least recently used
#: out): a question asked again reads them from here instead of re-reading 12 table entries and their critical
#: noises. Pure functions of the key: the table's content and the arguments.
_K_READINGS_PAIRS = 16
_K_READINGS: "LRUCache[tuple, tuple]" = LRUCache(4096)


def _k_readings(op, slices, sw, ka, kb, lo, hi, extra=None):
    """:func:`_k_readings_computed`, through a per-process cache for calls of at most 16 pairs."""
    if lo.size > _K_READINGS_PAIRS:
        return _k_readings_computed(op, slices, sw, ka, kb, lo, hi, extra)
    arrays = (slices, sw, ka, kb, lo, hi) + (tuple(extra) if extra is not None else ())
    if op.tab.header.get("content_hash") is None:  # a table without a hash: its content is not a key
        return _k_readings_computed(op, slices, sw, ka, kb, lo, hi, extra)
    key = (op.tab.header.get("content_hash"), float(op.width), float(op.phi), extra is not None) + tuple(
        (a.dtype.str, a.shape, a.tobytes()) for a in (np.ascontiguousarray(x) for x in arrays))
    hit = _K_READINGS.get(key)
    if hit is None:
        hit = _k_readings_computed(op, slices, sw, ka, kb, lo, hi, extra)
        _K_READINGS[key] = hit
    lk, se, star = hit
    return lk.copy(), se.copy(), None if star is None else star.copy()


def _k_readings_computed(op, slices, sw, ka, kb, lo, hi, extra=None):
    """The noise efficiency ``log k`` and its standard error at the tabulated contacts ``ka`` and ``kb`` (rows
    0 and 1 of the (2, n) arrays; NaN: no usable entry), per pair, from the pair's own entries (upwards at
    ``lo``, downwards at ``hi``) in the noise-ratio slices ``slices`` (n, m) weighted ``sw`` (n, m); see
    :func:`noise_k_min_contact`. ``extra``: (lo, hi) of further pairs whose critical noises are computed in
    the same call, returned third (or None)."""
    from ..recognition.ideal import shape_norm
    from .ideal_bound import pair_critical_noise

    view, tab = op.view, op.tab
    sensor, width = tab.sensor, op.width
    z_table = table_z(tab)
    n = lo.size
    h, rnd_sd = 0.5 * width, width / math.sqrt(12.0)
    ratios = view.t.axes["noise_ratio"]
    P, Cc, W, D, DL, DH, SIGN, RS, T = ([] for _ in range(9))
    for c, j in ((0, ka), (1, kb)):
        ok_j = (j >= 0) & (j < view.contacts.size)
        jj = np.clip(j, 0, view.contacts.size - 1)
        t = view.contacts[jj]
        for col in range(slices.shape[1]):
            si, ws = slices[:, col], sw[:, col]
            for sign, e, name in ((+1, lo, "delta_up"), (-1, hi, "delta_down")):
                d = _interp_at(view.t.arrays[name], view.centres, si, jj, e)
                dl = _interp_at(view.t.arrays[f"{name}_lo"], view.centres, si, jj, e)
                dh = _interp_at(view.t.arrays[f"{name}_hi"], view.centres, si, jj, e)
                ok = np.isfinite(d) & (d > width) & ok_j & (ws > 0)
                if sign < 0:
                    ok &= e - (d - h) > 0
                p = np.nonzero(ok)[0]
                P.append(p), Cc.append(np.full(p.size, c)), W.append(ws[p]), D.append(d[p])
                DL.append(dl[p]), DH.append(dh[p]), SIGN.append(np.full(p.size, sign))
                RS.append(ratios[si[p]]), T.append(t[p])
    P, Cc, W, D, DL, DH, SIGN, RS, T = (np.concatenate(x) for x in (P, Cc, W, D, DL, DH, SIGN, RS, T))
    P, Cc = P.astype(np.int64), Cc.astype(np.int64)
    e_ref = np.where(SIGN > 0, lo[P], hi[P])
    s_t = RS / shape_norm(sensor, T) if T.size else np.zeros(0)

    def pair_of(d):  # the entry's pair of lower edges at distance d from its reference
        return np.where(SIGN > 0, e_ref, e_ref - d), np.where(SIGN > 0, e_ref + d, e_ref)

    a1, b1 = pair_of(D - h)
    a2, b2 = pair_of(D - h + width)
    a2 = np.maximum(a2, 0.0)
    m = P.size
    xa, xb = extra if extra is not None else (np.zeros(0),) * 2
    # one computation: every entry at its need and one width further (and the extra pairs)
    star = pair_critical_noise(sensor, np.concatenate([a1, a2, xa]), np.concatenate([b1, b2, xb]), width=width,
                               threshold=op.phi)
    s1, s2 = star[:m], star[m:2 * m]
    with np.errstate(divide="ignore", invalid="ignore"):
        log_k = np.log(s1 / s_t)
        gamma = np.log(s2 / s1) / np.log((D - h + width) / (D - h))
        mc = np.where(np.isfinite(DH) & np.isfinite(DL) & (DL > h), np.log((DH - h) / (DL - h)) / (2.0 * z_table),
                      np.where(np.isfinite(DL) & (DL > h), np.log((D - h) / (DL - h)) / z_table, 0.0))
        rnd = np.abs(gamma) * rnd_sd / (D - h)
        mck = np.abs(gamma) * mc
        sd = np.maximum(np.hypot(rnd, mck), 1e-3)
    good = np.isfinite(log_k) & np.isfinite(sd)
    # the entries' Monte Carlo errors are combined as independent (measured on svm-paper, the residuals of
    # log k about each slice's trend correlate 0.14 between neighbouring noise-ratio slices and 0.07 between
    # neighbouring contact times, needs >= 5 widths); their rounding errors are not: the grid rounds the
    # similar needs of neighbouring entries the same way (at needs under 5 widths neighbouring readings of
    # log k are identical), so the rounding term is the entries' weighted mean, not reduced by averaging
    om = np.where(good, W / sd ** 2, 0.0)
    lk, se = np.full((2, n), np.nan), np.full((2, n), np.nan)
    for c in (0, 1):
        sel = Cc == c
        num = np.bincount(P[sel], om[sel] * np.where(good[sel], log_k[sel], 0.0), minlength=n)
        den = np.bincount(P[sel], om[sel], minlength=n)
        var = np.bincount(P[sel], om[sel] ** 2 * np.where(good[sel], mck[sel] ** 2, 0.0), minlength=n)
        rnd_mean = np.bincount(P[sel], om[sel] * np.where(good[sel], rnd[sel], 0.0), minlength=n)
        with np.errstate(divide="ignore", invalid="ignore"):
            lk[c] = np.where(den > 0, num / den, np.nan)
            se[c] = np.where(den > 0, np.hypot(np.sqrt(var) / den, rnd_mean / den), np.nan)
    return lk, se, (star[2 * m:] if extra is not None else None)


def _k_line(lk, se, t_a, t_b):
    """``log k`` at ``t_a`` and ``t_b`` (one held at the other's where it has no reading; two that fall pooled:
    k never falls with contact time, on svm-paper the slice medians rise at every step in every slice), the
    weights and the readings' disagreement where they fell."""
    have_a, have_b = np.isfinite(lk[0]), np.isfinite(lk[1])
    la_, lb_ = np.where(have_a, lk[0], lk[1]), np.where(have_b, lk[1], lk[0])
    with np.errstate(invalid="ignore", divide="ignore"):
        wa, wb = np.where(have_a, 1.0 / se[0] ** 2, 0.0), np.where(have_b, 1.0 / se[1] ** 2, 0.0)
        falls = have_a & have_b & ((lb_ - la_) * np.sign(np.log(t_b / t_a)) < 0)
        pooled = (np.nan_to_num(la_) * wa + np.nan_to_num(lb_) * wb) / (wa + wb)
        disagree = np.where(falls, np.abs(lb_ - la_), 0.0)
    la_, lb_ = np.where(falls, pooled, la_), np.where(falls, pooled, lb_)
    return la_, lb_, have_a, have_b, falls, wa, wb, disagree


def _k_var(u, se, la_, lb_, have_a, have_b, falls, wa, wb, disagree, far):
    """Variance of ``log k`` at fraction ``u`` of the way from ``t_a`` to ``t_b`` (``far``: log distance to
    the one reading where only one exists)."""
    dk = np.abs(lb_ - la_)
    v = np.where(have_a & have_b, ((1 - u) * se[0]) ** 2 + (u * se[1]) ** 2 + (u * (1 - u) * dk / 2) ** 2,
                 np.where(have_a, se[0], se[1]) ** 2 + (0.5 * far) ** 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(falls, 1.0 / (wa + wb) + (disagree / 2) ** 2, v)


def _slices(combos, n):
    """Shared scene weights as per-pair slice arrays (n, m)."""
    live = [(idx[0], w) for idx, w in combos if w]
    return (np.tile(np.array([i for i, _ in live], dtype=np.int64), (n, 1)),
            np.tile(np.array([w for _, w in live], dtype=np.float64), (n, 1)))


#: The shortest span in contact time [ratio] over which min-contact reads the slope of ``log k`` in ``log t``:
#: closer readings give a slope that is mostly the table's Monte Carlo noise (docs/decisions-log.md).
K_SLOPE_SPAN = 1.14


def span_neighbours(contacts_s, k):
    """The contacts at least :data:`K_SLOPE_SPAN` away from ``contacts_s[k]`` on each side: the index of the latest
    at or below ``contacts_s[k] / K_SLOPE_SPAN`` and of the first at or above ``contacts_s[k] * K_SLOPE_SPAN``
    (-1 where none), elementwise over the indices ``k``.

    >>> c = np.array([0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.5, 2.0])
    >>> [a.tolist() for a in span_neighbours(c, np.array([0, 1, 5, 7]))]
    [[-1, 0, 3, 6], [1, 2, 6, -1]]
    """
    c, k = np.asarray(contacts_s, dtype=np.float64), np.asarray(k, dtype=np.int64)
    back = np.searchsorted(c, c[k] / K_SLOPE_SPAN * (1 + 1e-12), side="right") - 1
    ahead = np.searchsorted(c, c[k] * K_SLOPE_SPAN * (1 - 1e-12), side="left")
    return back, np.where(ahead < c.size, ahead, -1)


def k_baseline(contacts_s, k_cross):
    """Index of the contact where min-contact reads ``k`` beside the crossing's contact ``k_cross``: the
    latest at or below ``contacts_s[k_cross] / K_SLOPE_SPAN`` (at least one step back, and the first contact
    where none lies that far back), or, where ``k_cross`` is the first, the first at or above
    ``contacts_s[0] * K_SLOPE_SPAN``; -1 where none.

    >>> c = np.array([0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.5, 2.0])
    >>> k_baseline(c, np.array([5, 6, 7, 0, 1])).tolist()
    [3, 5, 6, 1, 0]
    """
    kb = np.asarray(k_cross, dtype=np.int64)
    back, ahead = span_neighbours(contacts_s, kb)  # (where kb is the first contact, ahead is read from it)
    return np.where(kb > 0, np.maximum(back, 0), ahead)


def noise_k_min_contact(op, combos, k_cross, lo, hi, ratio, *, zc: float,
                        max_contact_s: float = CLOSED_FORM_MAX_CONTACT_S) -> dict[str, np.ndarray]:
    """min-contact from the SVM's *noise efficiency* against the exact ideal observer, for pairs of one scene.

    The SVM separates a pair when the ideal observer would at a larger noise: ``k(t)`` times the projection
    noise ``s(t) = (sigma/dT) / |g(t)|`` (:mod:`designkit.query.ideal_bound`). Every tabulated need gives
    one reading of ``k``: the noise at which the ideal observer needs exactly that separation (less the
    grid's rounding, w/2: :func:`~designkit.recognition.ideal.critical_noise`) over ``s(t)`` of its slice.
    ``k`` is a property of the classifier and the contact time (on svm-paper it is the same for every
    sigma/dT, direction and effusivity to about 1 %, docs/accuracy.md), unlike the ratio of the needs in
    effusivity, which changes with the pair's width because the signal ``w(e) = e / (e_s + e)`` is concave
    (that ratio, read at pairs narrower and wider than the asked one, put the answers late). ``k`` is read at
    the crossing's tabulated contact ``t_b`` (index ``k_cross``) and one before, ``t_a`` (after, where
    ``t_b`` is the first), at least a factor :data:`K_SLOPE_SPAN` away (:func:`k_baseline`), from the pair's
    own entries (upwards at ``lo``, downwards at ``hi``) in every scene slice the question interpolates
    between; ``log k`` is linear in ``log t`` through them. The answer is the first sample time where ``k(t) s(t)`` reaches the pair's own critical noise
    (:func:`~designkit.query.ideal_bound.noise_k_contact`).

    Standard error of ``log k`` at a contact: the entries' inverse-variance mean (their Monte Carlo errors
    nearly independent, measured on the table; their rounding errors alike, so that term is not reduced by
    averaging), each entry's in log k the local slope
    ``gamma = dlog s*/dlog need`` (a second critical noise, one width further) times its need's relative
    error: the grid's rounding (w/sqrt(12)) and the table's Monte Carlo interval
    (``delta_lo`` / ``delta_hi``, ``z`` standard errors each). Between the two contacts: ``(1-u)`` and ``u``
    weights, plus ``u (1-u)`` times half the change of ``log k`` across the cell (interpolation; the
    measured curvature of log k in log t on the table is below this). In log t it is that over
    ``beta_g - beta_k``, the local log-log slopes of ``|g|`` and ``k``.

    Parameters
    ----------
    op : the opened table (:func:`open_table`)
    combos : scene weights (``view.scene_weights``)
    k_cross : array_like of int
        Index of the first tabulated contact whose need suffices, per pair (>= 0).
    lo, hi, ratio : array_like
        Pairs [J s^-1/2 K^-1 m^-2] and the asked sigma/dT.
    zc : float
        z of the asked coverage.

    Returns
    -------
    dict of ndarray
        ``value``, ``low``, ``high`` [s], ``k_a``, ``k_b`` (NaN: no reading there), ``t_a``, ``t_b``,
        ``se_log`` (of the answer, log); ``value`` NaN where the route does not apply.
    """
    from ..recognition.ideal import shape_norm
    from .ideal_bound import noise_k_contact

    view, sensor = op.view, op.tab.sensor
    lo, hi, ratio, kb = (np.atleast_1d(a) for a in np.broadcast_arrays(
        np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64), np.asarray(ratio, dtype=np.float64),
        np.asarray(k_cross, dtype=np.int64)))
    n = lo.size
    ka = k_baseline(view.contacts, kb)
    slices, sw = _slices(combos, n)
    lk, se, s_pair = _k_readings(op, slices, sw, ka, kb, lo, hi, extra=(lo, hi))
    t_a, t_b = view.contacts[np.where(ka >= 0, ka, kb)], view.contacts[kb]
    la_, lb_, have_a, have_b, falls, wa, wb, disagree = _k_line(lk, se, t_a, t_b)
    ok = have_a | have_b
    value = np.full(n, np.nan)
    if ok.any():
        value[ok] = noise_k_contact(sensor, ratio[ok], s_pair[ok], t_a[ok], t_b[ok], la_[ok], lb_[ok], max_contact_s)
    ok &= np.isfinite(value)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.log(value / t_a) / np.log(t_b / t_a)
        var_k = _k_var(u, se, la_, lb_, have_a, have_b, falls, wa, wb, disagree,
                       np.log(value / np.where(have_a, t_a, t_b)))
        slope_k = np.where(have_a & have_b & (t_a != t_b), (lb_ - la_) / np.log(t_b / t_a), 0.0)
        v_ok = np.where(ok, value, 1.0)  # (shape_norm takes finite contact times only)
        beta_g = np.log(shape_norm(sensor, v_ok * 1.05) / shape_norm(sensor, v_ok / 1.05)) / (2 * math.log(1.05))
        se_t = np.sqrt(var_k) / np.maximum(beta_g - slope_k, 0.05)
        low, high = value * np.exp(-zc * se_t), value * np.exp(zc * se_t)
        k_at = np.exp(np.maximum(la_ + slope_k * np.log(value / t_a), 0.0))
    nan = ~ok
    return {"value": np.where(nan, np.nan, value), "low": np.where(nan, np.nan, low),
            "high": np.where(nan, np.nan, high), "k_a": np.where(have_a & ok, np.exp(lk[0]), np.nan),
            "k_b": np.where(have_b & ok, np.exp(lk[1]), np.nan), "t_a": t_a, "t_b": t_b,
            "k": np.where(nan, np.nan, k_at), "se_log": np.where(nan, np.nan, se_t)}


def noise_k_max_ratio(op, contact_s, r_table, r_ideal, lo, hi, *, zc: float) -> dict[str, np.ndarray]:
    """max-noise / min-delta-t from the SVM's noise efficiency (:func:`noise_k_min_contact`): the SVM separates
    the pair up to ``sigma/dT = r_ideal / k(contact)``, ``r_ideal`` the ideal observer's exact largest
    sigma/dT, ``k`` read at the two tabulated contacts around ``contact_s`` (log-linear in log t) in the two
    noise-ratio slices around ``r_table`` (the table's own crossing), elementwise. Standard error in log:
    that of ``log k`` there (as min-contact's), no slope to divide by.

    Returns
    -------
    dict of ndarray
        ``value``, ``low``, ``high`` (sigma/dT), ``k``, ``se_log``; NaN where it does not apply.
    """
    view = op.view
    contact, r_table, r_ideal, lo, hi = (np.atleast_1d(a) for a in np.broadcast_arrays(*(
        np.asarray(x, dtype=np.float64) for x in (contact_s, r_table, r_ideal, lo, hi))))
    C = view.contacts
    kb = np.clip(np.searchsorted(C, contact, side="left"), 0, C.size - 1)  # the first contact >= the asked one
    ka = np.where(C[kb] == contact, kb, np.maximum(kb - 1, 0))
    lr, lrt = np.log(view.t.axes["noise_ratio"]), np.log(r_table)
    i0 = np.clip(np.searchsorted(lr, lrt, side="right") - 1, 0, lr.size - 2)
    w1 = np.clip((lrt - lr[i0]) / (lr[i0 + 1] - lr[i0]), 0.0, 1.0)
    slices, sw = np.stack([i0, i0 + 1], axis=1), np.stack([1.0 - w1, w1], axis=1)
    lk, se, _ = _k_readings(op, slices, sw, ka, kb, lo, hi)
    t_a, t_b = C[ka], C[kb]
    la_, lb_, have_a, have_b, falls, wa, wb, disagree = _k_line(lk, se, t_a, t_b)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.where(t_a != t_b, np.log(contact / t_a) / np.log(t_b / t_a), 1.0)
        log_k = np.maximum((1 - u) * la_ + u * lb_, 0.0)
        var_k = _k_var(u, se, la_, lb_, have_a, have_b, falls, wa, wb, disagree,
                       np.log(contact / np.where(have_a, t_a, t_b)))
        sd = np.sqrt(var_k)
    ok = (have_a | have_b) & np.isfinite(r_ideal) & np.isfinite(sd)
    value = r_ideal * np.exp(-log_k)
    return {"value": np.where(ok, value, np.nan), "low": np.where(ok, value * np.exp(-zc * sd), np.nan),
            "high": np.where(ok, value * np.exp(zc * sd), np.nan), "k": np.where(ok, np.exp(log_k), np.nan),
            "se_log": np.where(ok, sd, np.nan)}


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
        shift = np.log(r) - np.log(raw)
        ends = [np.exp(np.log(np.asarray(m, dtype=np.float64)) + shift) for m in (end_lo, end_hi)]
    low, high = stated_log(r, ends[0], ends[1], np.hypot(interp, rounding), z_table, zc)
    ideal = np.asarray(ideal, dtype=np.float64)
    high = np.where(np.isnan(high) | np.isnan(ideal), high, np.maximum(np.minimum(high, ideal), r))
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
    low, high = stated_log(value, mc_lo, mc_hi, np.hypot(interp, rounding), z_table, zc)
    ideal = np.asarray(ideal, dtype=np.float64)
    low = np.where(np.isnan(low) | np.isnan(ideal), low, np.minimum(np.maximum(low, ideal), value))
    return low, high


def delta_entries(view, combos, ends, direction: str, e) -> tuple[np.ndarray, ...]:
    """The tabulated SVM delta(e) towards ``direction`` (``"up"`` / ``"down"``) and its Monte Carlo ends at
    effusivities ``e`` (interpolated between centres as :func:`designkit.tables.lookup.interp_e`), at the
    contact indices ``ends`` (two) in each weighted noise-ratio slice of ``combos``: the slices' sigma/dT (m,),
    their weights (m,), and the delta, its low and its high end, each (2, m, n) (NaN: none within the grid);
    what :func:`delta_efficiency_estimate` takes."""
    live = [(idx[0], w) for idx, w in combos if w]
    e = np.atleast_1d(np.asarray(e, dtype=np.float64))
    si = np.array([i for i, _ in live], dtype=np.int64)
    shape = (2, si.size, e.size)
    sl, kk, ee = (np.broadcast_to(a, shape).ravel() for a in (
        si[None, :, None], np.asarray(ends, dtype=np.int64)[:, None, None], e[None, None, :]))
    out = [_interp_at(view.t.arrays[f"delta_{direction}{suffix}"], view.centres, sl, kk, ee).reshape(shape)
           for suffix in ("", "_lo", "_hi")]
    return (view.t.axes["noise_ratio"][si], np.array([w for _, w in live], dtype=np.float64), *out)


def delta_efficiency_estimate(sensor, e, contact_s, ratio, direction, t_a, t_b, slice_ratios, slice_weights, svm,
                              svm_lo, svm_hi, *, width: float, threshold: float, e_max: float, z_table: float,
                              zc: float, mc_factor: float = 1.0) -> dict[str, np.ndarray]:
    """delta-e's estimate of one direction from the SVM's efficiency against the exact ideal observer.

    The SVM's efficiency is its need over the ideal observer's for the asked reference class and direction,
    ``eff = s / i``. At every tabulated entry around the question (the contact times ``t_a``, ``t_b`` and the
    noise-ratio slices ``slice_ratios``) the ideal need ``i`` is computed exactly
    (:func:`designkit.query.ideal_bound.exact_ideal_delta`; the table's own ideal needs are rounded up to its
    grid, and at small needs that rounding dominated the ratio) and the SVM's ``s`` is the middle of what its
    tabulated need ``S`` allows: the first grid distance whose F1 reaches Phi, so the crossing lies in
    ``(S - w, S]``, and never below the ideal observer's, ``[max(i, S - w), S]`` (SD its length / sqrt(12)).
    ``log eff`` is interpolated linearly in log t between the two contacts and with ``slice_weights`` between
    the slices, floored at 1 (no classifier beats the ideal observer), and applied to the ideal observer's
    delta(e) computed exactly at the asked contact and sigma/dT: no interpolation of the steep need itself.

    Standard error in log, each term measured on the table (docs/accuracy.md): the entries' Monte Carlo
    errors (the table's ``delta_lo`` / ``delta_hi``, ``z_table`` SEs each, times ``mc_factor``, the table's
    own calibration :meth:`_View.mc_calibration`), combined as independent (the table's entries are
    separate simulations); their rounding errors combined as alike (neighbouring needs round the same way),
    the weighted mean, not reduced by averaging; and the interpolation across the cell, ``u (1 - u)`` times
    half the change of ``log eff`` across it (as min-contact's noise efficiency). Where one contact's
    entries cannot be read (a need beyond the grid) the other's stand alone.

    Parameters
    ----------
    e : array_like, shape (n,)
        Reference class's lower edge [J s^-1/2 K^-1 m^-2].
    contact_s, ratio, direction : array_like, shape (n,) or scalar
        Contact time [s], sigma/dT [-], and +1 (towards higher effusivity) or -1.
    t_a, t_b : array_like
        The tabulated contact times [s] around ``contact_s`` (equal where it is one).
    slice_ratios, slice_weights : array_like, shape (m,) or (m, n)
        The noise-ratio slices the question interpolates between and their weights.
    svm, svm_lo, svm_hi : array_like, shape (2, m, n)
        The tabulated SVM delta and its Monte Carlo ends at ``e`` (interpolated in effusivity) at ``t_a``
        (row 0) and ``t_b`` (row 1) in each slice [J s^-1/2 K^-1 m^-2].
    width, threshold, e_max, z_table, zc : float
        Grid width, F1 threshold, upper end of the effusivity range, the table's z and the asked coverage's.
    mc_factor : float
        Calibration of the table's Monte Carlo errors (:meth:`_View.mc_calibration`).

    Returns
    -------
    dict of ndarray
        ``value``, ``low``, ``high``, ``ideal`` [J s^-1/2 K^-1 m^-2], ``efficiency``, ``se_log`` (NaN where
        it does not apply).

    Examples
    --------
    >>> from designkit.sensor import load_sensor
    >>> S = [[[8760.0]], [[5000.0]]]
    >>> r = delta_efficiency_estimate(load_sensor("paper"), 20000.0, 1.75, 0.005, +1, 1.5, 2.0, [0.005], [1.0],
    ...                               S, [[[8300.0]], [[4750.0]]], [[[9200.0]], [[5300.0]]], width=80.0,
    ...                               threshold=0.9, e_max=40000.0, z_table=2.0, zc=1.645)
    >>> float(r["ideal"][0]) < float(r["low"][0]) < float(r["value"][0]) < float(r["high"][0])
    True
    """
    from .ideal_bound import exact_ideal_delta

    S, L, H = (np.asarray(a, dtype=np.float64) for a in (svm, svm_lo, svm_hi))
    m, n = S.shape[1], S.shape[2]
    e, contact, ratio, direction, t_a, t_b = (np.broadcast_to(np.asarray(a, dtype=np.float64), (n,)) for a in (
        e, contact_s, ratio, direction, t_a, t_b))
    rs = np.broadcast_to(np.asarray(slice_ratios, dtype=np.float64).reshape(m, -1), (m, n))
    ws = np.broadcast_to(np.asarray(slice_weights, dtype=np.float64).reshape(m, -1), (m, n))
    h = 0.5 * width
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.where(t_a != t_b, np.log(contact / t_a) / np.log(t_b / t_a), 0.0)
    wc = np.stack([1.0 - u, u])  # (2, n): the contacts' weights
    needed = (wc[:, None, :] > 0) & (ws[None, :, :] > 0)
    live = needed & np.isfinite(S) & (S > 0)
    # the ideal observer's delta at every live entry and at the asked point: one (cached) computation
    shape = (2, m, n)
    cols = [np.concatenate([np.broadcast_to(a, shape)[live], b]) for a, b in (
        (e, e), (np.stack([t_a, t_b])[:, None, :], contact), (rs[None], ratio), (direction, direction))]
    ideal_all = exact_ideal_delta(sensor, *cols[:3], direction=cols[3], width=width, threshold=threshold,
                                  e_max=e_max)
    k = int(live.sum())
    i_entry = np.full(shape, np.nan)
    i_entry[live] = ideal_all[:k]
    ideal = ideal_all[k:]
    usable = live & np.isfinite(i_entry) & (i_entry > 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        lower = np.minimum(np.maximum(i_entry, S - width), S)
        mid = 0.5 * (lower + S)
        rnd = (S - lower) / math.sqrt(12.0) / mid
        le = np.log(mid / i_entry)
        mc = np.where(np.isfinite(H) & (L > h), np.log((H - h) / (L - h)) / (2.0 * z_table),
                      np.where(L > h, np.log((S - h) / (L - h)) / z_table, 0.0))
        mc = np.where(np.isfinite(mc), mc, 0.0)
        # a contact counts where all its weighted slices are usable; where only one does, it stands alone
        ok_c = (wc > 0) & np.all(usable | ~needed, axis=1)
        wcn = np.where(ok_c, wc, 0.0)
        wcn = wcn / wcn.sum(axis=0)
        wsn = ws / ws.sum(axis=0)
        W = np.where(usable, wcn[:, None, :] * wsn[None, :, :], 0.0)
        log_eff = np.sum(W * np.where(usable, le, 0.0), axis=(0, 1))
        var_mc = np.sum((W * mc) ** 2, axis=(0, 1))
        rounding = np.sum(W * np.where(usable, rnd, 0.0), axis=(0, 1))
        per_c = np.sum(wsn[None] * np.where(usable, le, 0.0), axis=1)  # log eff at each contact
        both = ok_c.all(axis=0)
        interp = np.where(both, u * (1.0 - u) * np.abs(per_c[1] - per_c[0]) / 2.0, 0.0)
        se = np.sqrt(mc_factor ** 2 * var_mc + rounding ** 2 + interp ** 2)
        eff = np.maximum(np.exp(log_eff), 1.0)  # no classifier beats the ideal observer
    ok = ok_c.any(axis=0) & np.isfinite(log_eff) & np.isfinite(se) & np.isfinite(ideal)
    with np.errstate(invalid="ignore"):
        value = np.where(ok, eff * ideal, np.nan)
        low = np.where(ok, np.maximum(value * np.exp(-zc * se), ideal), np.nan)
        high = np.where(ok, value * np.exp(zc * se), np.nan)
    return {"value": value, "low": low, "high": high, "ideal": np.where(ok, ideal, np.nan),
            "efficiency": np.where(ok, eff, np.nan), "se_log": np.where(ok, se, np.nan)}


# ============================================================ opening a table for a question
@dataclass(frozen=True)
class _Opened:
    """A table checked against the question (threshold, sensor, model), and its ideal-bound view."""

    tab: Table
    view: _View
    phi: float
    model: Any
    iview: _View | None
    ikind: str
    iname: str | None
    ihash: str | None

    @property
    def width(self) -> float:
        return float(self.tab.header["effusivity"]["width"])

    @property
    def closed(self) -> bool:
        """The ideal bound is computed in closed form at query time (never read from a grid)."""
        return _closed_form(self.tab, self.model)


def _ideal_view(svm: _View, ideal_table: "Table | str | None") -> tuple[_View, str, Table | None]:
    """The view answering the ideal bound: a dedicated ideal table built for the same sensor, model and
    threshold, else the SVM table's own ideal arrays, else none (``(None, "", None)``: no bound from
    tables; never the SVM's own answer passed off as the bound). An ideal table that cannot be read is
    an error, not a silent fallback."""
    if ideal_table is not None:
        t = _as_table(ideal_table)
        if (t.sensor == svm.t.sensor and t.fidelity == "ideal" and t.threshold == svm.t.threshold
                and t.model == svm.t.model):
            return _View(t), "svm", t
    if "delta_up_ideal" in svm.t.arrays:
        return svm, "ideal", svm.t
    if svm.t.fidelity == "ideal":
        return svm, "svm", svm.t
    return None, "", None


def table_spread(tab: Table) -> float:
    """Half-width [degC] of the per-touch sensor temperature a table was built with (0: fixed conditions)."""
    return float(tab.header.get("config", {}).get("sensor_temp_spread_c") or 0.0)


#: The questions a table with varied initial conditions answers (its noise and dT are separate axes, not
#: sigma/dT: max-noise and min-delta-t are refused by it and need the exact route).
SPREAD_TABLE_QUESTIONS = ("min-contact", "delta-e", "distinguishable")


def shipped_spread_table(spread: float, question: str = "min-contact", delta_t_c: float | None = None) -> str | None:
    """The shipped table that answers ``question`` with sensor temperature spread ``spread`` [degC], or None.

    With ``delta_t_c`` [degC], also None where the table holds no such temperature difference: its dT is an
    axis of its own (the spread is about the sensor's temperature, so sigma/dT is no invariance there), and
    a question at another dT is computed for the pair instead of refused as outside the grid.

    >>> shipped_spread_table(2.5)
    'svm-paper-varied'
    >>> shipped_spread_table(1.0) is None, shipped_spread_table(2.5, "max-noise") is None
    (True, True)
    >>> shipped_spread_table(2.5, delta_t_c=7.5), shipped_spread_table(2.5, delta_t_c=10.0)
    ('svm-paper-varied', None)
    """
    if question not in SPREAD_TABLE_QUESTIONS or not spread > 0:
        return None
    tab = _as_table(VARIED_TABLE)
    if not math.isclose(table_spread(tab), spread, rel_tol=1e-9):
        return None
    if delta_t_c is not None:
        held = tab.axes.get("delta_t_c")
        if held is not None and not np.any(np.isclose(held, abs(float(delta_t_c)), rtol=1e-9)):
            return None
    return VARIED_TABLE


def _spread_words(spread: float) -> str:
    return (f"the sensor temperature drawn per touch within +-{spread:g} degC" if spread > 0
            else "fixed initial conditions")


def _open(table, ideal_table, *, threshold, sensor, model, spread: float = 0.0) -> _Opened:
    """Load ``table`` and refuse it when it was built for another threshold, sensor, model or sensor
    temperature spread (``spread`` [degC]: the question's; a spread reads :data:`VARIED_TABLE` by default)."""
    from ..models import get_model

    spread = check_nonnegative("sensor temperature spread [degC]", spread)
    if spread > 0 and isinstance(table, str) and table == DEFAULT_TABLE:
        table = VARIED_TABLE
    tab = _as_table(table)
    held = table_spread(tab)
    if not math.isclose(spread, held, rel_tol=1e-9, abs_tol=1e-12) or tab.header.get("config", {}).get(
            "ambient_temp_spread_c"):
        raise TableMismatch(f"table {tab.name} was built with {_spread_words(held)}, not with "
                            f"{_spread_words(spread)}")
    if threshold is not None and not math.isclose(check_threshold(threshold), tab.threshold, rel_tol=1e-9):
        raise TableMismatch(f"table {tab.name} was built for threshold {tab.threshold:g}, not {threshold:g}")
    if sensor is not None:
        from ..sensor import load_sensor

        s = load_sensor(sensor)
        if s != tab.sensor:
            raise TableMismatch(f"table {tab.name} was built for sensor {tab.sensor.name!r}, not {s.name!r}")
        if model is None and s.model is not None:  # a sensor file's own model must be the table's too
            from ..models import sensor_model

            model = sensor_model(s)
    fm = tab.model
    if model is not None:
        asked = get_model(model)
        if asked != fm:
            raise TableMismatch(f"table {tab.name} was built for the {fm.describe()} model, "
                                f"not the {asked.describe()} model")
    view = _View(tab)
    if _closed_form(tab, fm):  # the bound is computed at query time: the default ideal table is not read
        if ideal_table is not None and ideal_table != DEFAULT_IDEAL_TABLE:
            _as_table(ideal_table)  # a table the caller named must exist: an error, not a silent fallback
        return _Opened(tab, view, tab.threshold, fm, None, "", None, None)
    iview, ikind, it = _ideal_view(view, ideal_table)
    return _Opened(tab, view, tab.threshold, fm, iview, ikind, None if it is None else it.name,
                   None if it is None else it.header.get("content_hash"))


def _closed_form(tab: Table, fm) -> bool:
    """Whether the ideal bound is computed in closed form (shared-shape model, fixed initial conditions)."""
    return bool(fm.shared_shape) and "noise_ratio" in tab.axes


# ============================================================ in-grid flags, in the user's units
def _axis_range(view: _View, name: str) -> tuple[float, float]:
    vals = view.t.axes[name]
    return float(vals.min()), float(vals.max())


_AXIS_WORDS = {"noise_ratio": ("sigma/dT", ""), "noise_c": ("noise sigma", " degC"),
               "delta_t_c": ("temperature difference", " degC"), "contact_s": ("contact time", " s")}


def _outside_notes(view: _View, flags: dict[str, bool], wanted: dict[str, Any]) -> list[str]:
    """One sentence per axis the question lies outside, with the asked value and the table's range."""
    notes = []
    for name, ok in flags.items():
        if ok:
            continue
        if name == "effusivity":
            es = ", ".join(f"{e:g}" for e in wanted.get("effusivity", ()))
            notes.append(f"effusivity {es} outside table {view.t.name}'s ({view.e_lo:g}, {view.e_hi:g}] "
                         "J s^-1/2 K^-1 m^-2 (no extrapolation)")
        elif name == "noise_ratio" and wanted.get("noise_c") is not None and wanted.get("delta_t_c") is not None:
            lo, hi = _axis_range(view, name)
            n, d = wanted["noise_c"], abs(wanted["delta_t_c"])
            notes.append(f"noise {n:g} degC at dT {d:g} degC (sigma/dT {n / d:g}) outside table {view.t.name}'s "
                         f"sigma/dT [{lo:g}, {hi:g}]: at dT {d:g} degC it answers for noise {lo * d:g} to "
                         f"{hi * d:g} degC (no extrapolation)")
        else:
            word, unit = _AXIS_WORDS.get(name, (name, ""))
            lo, hi = _axis_range(view, name)
            x = wanted.get(name)
            asked = f" {x:g}{unit}" if isinstance(x, (int, float)) else ""
            notes.append(f"{word}{asked} outside table {view.t.name}'s [{lo:g}, {hi:g}]{unit} (no extrapolation)")
    return notes


def _scene_wanted(view: _View, noise, dt) -> dict[str, Any]:
    if view.scene_axes == ["noise_ratio"]:
        return {"noise_ratio": None if noise is None or dt is None else noise / abs(dt), "noise_c": noise,
                "delta_t_c": dt}
    return {"noise_c": noise, "delta_t_c": dt}


# ============================================================ one answer builder for the route
def _answer(question: str, op: _Opened, *, objects, limiting, rule: str, scene: dict, value, interval,
            ideal, ideal_method: str = "table", in_grid: dict, details: dict, notes: Sequence[str] = (),
            check_at: tuple[float, float, float] | None = None, classes=(), interval_kind=None,
            interval_coverage=None, computation: dict | None = None, ideal_interval=None) -> Answer:
    check = None
    if check_at is not None and classes:
        c, n, d = check_at
        check = op.model.check(classes, op.tab.sensor, contact_s=c, noise_c=n, delta_t_c=d).to_dict()
    ideal_table = op.iname if ideal_method == "table" else None
    if not states_coverage(op.tab, question, interval_kind):
        # measured not to hold on the varied table (VARIED_COVERAGE_NOTE): no coverage is claimed
        interval_kind, interval_coverage = "table-varied", None
        notes = [*notes, VARIED_COVERAGE_NOTE]
    return Answer(
        question=question, route="table", value=value, interval=tuple(interval),
        ideal_bound=IdealBound(number(ideal) if not isinstance(ideal, bool) else ideal,
                               ideal_method if ideal is not None else "none",
                               ideal_interval if ideal is not None else None),
        objects=tuple(objects), limiting_pair=tuple(limiting), materials_rule=rule, scene=scene,
        sensor=op.tab.sensor.to_dict(), model=op.model.to_dict(), model_check=check, threshold=op.phi,
        table=op.tab.name, table_hash=op.tab.header.get("content_hash"), ideal_table=ideal_table,
        ideal_table_hash=op.ihash if ideal_table else None, in_grid=dict(in_grid), details=details,
        computation={"fidelity": op.tab.fidelity, "table_contacts_s": op.view.contacts.tolist(),
                     **(computation or {})},
        notes=tuple(n for n in notes if n), interval_kind=interval_kind, interval_coverage=interval_coverage)


#: The (question, interval kind) pairs a table with varied initial conditions shows as ``table-varied``, with
#: no coverage (see :data:`VARIED_COVERAGE_NOTE`): min-contact's grid-rule estimate and grid cell. Its
#: min-contact estimates (``table-varied-estimate``) and delta-e's (``table-estimate``) state theirs, measured
#: to hold there (``bench_coverage_varied.py``, 200 random cases each against 16-seed exact references).
VARIED_UNMEASURED = frozenset({("min-contact", "table-estimate"), ("min-contact", "table-cell")})


def states_coverage(tab: Table, question: str, interval_kind: str | None) -> bool:
    """Whether an answer of ``question`` from ``tab`` may state the coverage of an interval of this kind:
    everywhere but on a varied table's :data:`VARIED_UNMEASURED` kinds (the array route asks the same)."""
    return not (table_spread(tab) > 0 and (question, interval_kind) in VARIED_UNMEASURED)

#: Why a table with varied initial conditions states no coverage outside its min-contact and delta-e estimates
#: (``benchmarks/bench_coverage_varied.py``, results in benchmarks/results/bench_coverage_varied.txt: 200
#: random min-contact cases on svm-paper-varied against 16-seed exact references, seeds 1 and 2).
VARIED_COVERAGE_NOTE = (
    "this table varies the initial conditions, and this answer is its grid cell or the grid rule's reading, "
    "not one of its min-contact estimates (whose 90% intervals held the exact answer in 85 of 96 random "
    "cases): it states no coverage (such answers held it in 10 of 14); --exact states one (a few seconds for "
    "the pair)")


def _scene(contact_s=None, noise_c=None, delta_t_c=None) -> dict[str, Any]:
    ratio = None if noise_c is None or delta_t_c is None else noise_c / abs(delta_t_c)
    return {"contact_s": contact_s, "noise_c": noise_c, "delta_t_c": delta_t_c, "noise_ratio": ratio}


def _no_pair(question: str, op: _Opened, pq: PairQuestion, scene: dict, details: dict) -> Answer:
    """The materials overlap: no answer, said so."""
    return _answer(question, op, objects=pq.objects_dicts(), limiting=(), rule=pq.rule, scene=scene,
                   value=None, interval=(None, None), ideal=None, in_grid={}, details=details, notes=[pq.note])


def _contact_weights(view: _View, contact_s: float) -> tuple[list[tuple[int, float]], bool]:
    return axis_weights_flagged(view.contacts, contact_s, log=False)


def _need_at_contact(view: _View, kind: str, combos, cw, lo: float, hi: float) -> float:
    total = 0.0
    for k, w in cw:
        if w == 0:
            continue
        nd = view.need(kind, combos, k, lo, hi)
        if math.isnan(nd):
            return math.nan
        total += w * nd
    return total


# ============================================================ min-contact
def _closed_ideal_contact(op: _Opened, lo: float, hi: float, noise: float, dt: float) -> float | None:
    """min-contact's ideal bound in closed form, inside the table's grid or outside it, or None.

    The ideal observer needs no table where its F1 has a closed form (fixed initial conditions, a
    shared-shape model): a question the table cannot answer still gets the floor no classifier beats.
    Without a closed form (its bound would be a Monte Carlo run) None, and the caller decides.
    """
    if not op.closed:
        return None
    from .ideal_bound import exact_ideal_min_contact

    return number(exact_ideal_min_contact(op.tab.sensor, lo, hi, noise / abs(dt), width=op.width,
                                          threshold=op.phi, max_contact_s=CLOSED_FORM_MAX_CONTACT_S))


def _closed_ideal_ratio(op: _Opened, lo: float, hi: float, contact: float) -> float | None:
    """The ideal observer's largest separating sigma/dT in closed form (as :func:`_closed_ideal_contact`), or
    None: no closed form, a touch beyond the sample limit, or not separable even at the bracket's low end."""
    if not (op.closed and within_sample_limit(contact, op.tab.sensor.sample_rate_hz)):
        return None
    from .ideal_bound import exact_ideal_max_ratio

    return number(exact_ideal_max_ratio(op.tab.sensor, lo, hi, contact, width=op.width, threshold=op.phi,
                                        bracket=CLOSED_FORM_RATIO_BRACKET))


def min_contact(e1: float | None = None, e2: float | None = None, *, m1: str | None = None,
                m2: str | None = None, objects=None, noise_c: float = 0.05, delta_t_c: float = 10.0,
                threshold: float | None = None, table: "Table | str" = DEFAULT_TABLE,
                ideal_table: "Table | str | None" = DEFAULT_IDEAL_TABLE, sensor=None, model=None,
                coverage: float = 0.9,
                sensor_temp_spread_c: float = 0.0, ideal_bound: bool = True) -> Answer:
    """Shortest contact time [s] that separates two objects, from a table.

    Parameters
    ----------
    e1, e2 : float, optional
        Effusivities [J s^-1/2 K^-1 m^-2].
    m1, m2 : str, optional
        Material names instead (answered by the materials rule, :mod:`designkit.query.inputs`).
    objects : (ObjectClass, ObjectClass), optional
        The classes instead.
    noise_c : float
        Noise sigma per sample [degC].
    delta_t_c : float
        Sensor minus object temperature before contact [degC].
    threshold : float, optional
        F1 threshold Phi; must be the table's (0.9 for the shipped tables).
    table, ideal_table : Table or name or path
        SVM table, and the table for the ideal bound (None: the SVM table's own ideal arrays).
    sensor : name, path or Sensor, optional
        Must be the table's.
    model : ForwardModel or name, optional
        Must be the table's (default: whatever the table was built with).
    coverage : float
        Nominal coverage of the interval, in (0, 1).
    sensor_temp_spread_c : float
        Half-width [degC] of the per-touch sensor temperature; must be the table's.
    ideal_bound : bool
        Where the bound has no closed form (varied initial conditions), estimate it by Monte Carlo at
        query time (:mod:`designkit.query.ideal_mc_bound`, 1-2 s). False: read the table's own floor
        instead (method ``"table"``; for a varied table an observer told each touch's Ts0, looser): what
        the grid reads of exports and :func:`grid_answer` need, and distinguishable's own readings.

    Returns
    -------
    Answer
        ``value``: contact time [s], None when no tabulated contact time up to
        the table's longest suffices. ``interval``: at ``coverage`` where the
        crossing is interpolated between two tabulated contact times (the
        table's Monte Carlo error and the interpolation error; on a table with
        varied initial conditions :func:`varied_contact_estimate`); the grid
        cell, coverage not stated, where a neighbour lies beyond the grid.

    Examples
    --------
    >>> min_contact(35000, 20000, table="ideal-paper").to_dict()["quantity"]
    'contact_s'
    """
    noise, dt = scene_inputs(noise_c, delta_t_c)
    coverage = check_coverage(coverage)
    op = _open(table, ideal_table, threshold=threshold, sensor=sensor, model=model,
               spread=sensor_temp_spread_c)
    pq = pair_question(e1, e2, m1, m2, objects=objects, width=op.width, model=op.model)
    scene = _scene(None, noise, dt)
    if pq.classes is None:
        return _no_pair("min-contact", op, pq, scene, {})
    lo, hi = pq.points
    view = op.view
    combos, flags = view.scene_weights(noise, dt)
    flags["effusivity"] = view.e_in_grid(lo, hi)
    common = dict(objects=pq.objects_dicts(), limiting=pq.limiting_dicts(), rule=pq.rule, scene=scene,
                  classes=pq.classes)
    if not all(flags.values()):
        wanted = {**_scene_wanted(view, noise, dt), "effusivity": (lo, hi)}
        ideal = _closed_ideal_contact(op, lo, hi, noise, dt) if ideal_bound else None
        return _answer("min-contact", op, value=None, interval=(None, None), ideal=ideal,
                       ideal_method="closed-form", in_grid=flags, details={},
                       notes=_outside_notes(view, flags, wanted), **common)
    def needs_read(v: _View, kind: str, cmb) -> tuple[list[float], Any]:
        """The needs read lazily up to the crossing (a generator), and the list of those read so far."""
        read: list[float] = []

        def gen():
            for k in range(v.contacts.size):
                read.append(v.need(kind, cmb, k, lo, hi))
                yield read[-1]
        return read, gen()

    def contact_for(v: _View, kind: str, cmb) -> float | None:
        x, _ = _crossing(v.contacts, needs_read(v, kind, cmb)[1], hi - lo)  # read up to the crossing
        return x

    needs, lazy = needs_read(view, "svm", combos)
    value, k_cross = _crossing(view.contacts, lazy, hi - lo)  # needs[:k_cross + 1] read
    if op.tab.fidelity == "svm":
        mc_interval = (contact_for(view, "lo", combos), contact_for(view, "hi", combos))
    else:
        mc_interval = (value, value)
    monte_carlo = {"monte_carlo_interval": list(mc_interval)}  # the table's delta_lo / delta_hi answers alone
    if "delta_up_ideal" in view.t.arrays:  # the grid's own bound, beside the exact one (its interpolation error)
        monte_carlo["table_ideal_s"] = contact_for(view, "ideal", combos)
    efficiency = None
    if value is not None and op.closed and op.tab.fidelity == "svm" and "delta_up_ideal" in view.t.arrays:
        # the efficiency estimate's critical noises first, the pair's own among them, in one solve: the
        # closed-form bound below then reads the pair's from the per-process memo (one Newton solve a new pair)
        r = noise_k_min_contact(op, combos, [k_cross], [lo], [hi], [noise / abs(dt)], zc=z_of_coverage(coverage))
        efficiency = {key: float(v[0]) for key, v in r.items()}
    ideal_interval = None
    if op.closed:
        ideal, ideal_method = _closed_ideal_contact(op, lo, hi, noise, dt), "closed-form"
    elif not ideal_bound:  # the table's own floor (no Monte Carlo)
        icombos, iflags = op.iview.scene_weights(noise, dt) if op.iview is not None else ([], {"ideal": False})
        ideal = contact_for(op.iview, op.ikind, icombos) if all(iflags.values()) else None
        ideal_method = "table"
    else:  # no closed form (varied initial conditions, per-object shapes): Monte Carlo at query time
        from .ideal_mc_bound import cached_mc_ideal_min_contact

        mcb = cached_mc_ideal_min_contact(*pq.classes, op.tab.sensor, noise_c=noise, delta_t_c=dt,
                                          sensor_temp_spread_c=table_spread(op.tab), model=op.model,
                                          threshold=op.phi, max_contact_s=CLOSED_FORM_MAX_CONTACT_S,
                                          coverage=coverage)
        ideal, ideal_method, ideal_interval = mcb.value, "monte-carlo", mcb.interval
        monte_carlo["ideal_monte_carlo"] = {"n_mc": mcb.n_mc, "evaluations": len(mcb.evaluations)}
    rd = _Reading(op, lo, hi, noise, dt, combos, needs, k_cross, value, mc_interval, ideal, ideal_interval,
                  coverage, efficiency)
    est = next((e for e in (estimator(rd) for estimator in CONTACT_ESTIMATORS) if e is not None), None)
    if est is None:
        est = _Estimate(None, (None, None), "none", None, note=(
            f"no tabulated contact time up to {view.contacts[-1]:g} s separates them "
            "(the exact route examines longer contacts)"))
    monte_carlo.update(est.computation)
    needed = est.value if est.value is not None else float(view.contacts[-1])
    return _answer("min-contact", op, value=est.value, interval=est.interval, ideal=ideal, ideal_method=ideal_method,
                   ideal_interval=ideal_interval, in_grid=flags, details={}, notes=[est.note],
                   check_at=(needed, noise, dt), interval_kind=est.kind, interval_coverage=est.coverage,
                   computation=monte_carlo, **common)


# ---------------------------------------------------------------- min-contact's estimators
@dataclass(frozen=True)
class _Reading:
    """What min-contact read from the table for one pair ``lo < hi`` at one scene: the tabulated SVM needs up to
    the crossing (``needs``), the crossing's contact index ``k_cross`` and value ``raw`` [s] (None: none
    within the table), the Monte Carlo ends' crossings, the ideal bound (and its Monte Carlo interval, or None),
    the noise-efficiency reading (:func:`noise_k_min_contact`'s element, or None where it does not apply)."""

    op: Any
    lo: float
    hi: float
    noise: float
    dt: float
    combos: Any
    needs: list
    k_cross: int
    raw: float
    mc_interval: tuple
    ideal: float | None
    ideal_interval: tuple | None
    coverage: float
    efficiency: dict | None

    @property
    def floor(self) -> float | None:
        return ideal_floor(self.ideal, self.ideal_interval)

    @property
    def svm(self) -> bool:
        return self.op.tab.fidelity == "svm"


@dataclass(frozen=True)
class _Estimate:
    """One estimator's answer: value [s], interval, its kind and coverage, what goes to ``computation``, a note."""

    value: float | None
    interval: tuple
    kind: str
    coverage: float | None
    computation: dict = field(default_factory=dict)
    note: str = ""
    ratio: float | None = None  # (max-noise / min-delta-t: the sigma/dT answered)


def _varied_estimate(rd: _Reading) -> _Estimate | None:
    """Varied initial conditions: each scene slice's estimate, both directions averaged, interpolated across the
    slices (:func:`varied_contact_estimate`)."""
    op = rd.op
    if not (rd.svm and table_spread(op.tab) > 0 and "delta_up_lo" in op.view.t.arrays):
        return None
    r = varied_contact_estimate(op.view, rd.combos, rd.lo, rd.hi, _arr(rd.floor), width=op.width,
                                z_table=table_z(op.tab), zc=z_of_coverage(rd.coverage))
    v = {key: float(x[0]) for key, x in r.items()}
    if math.isnan(v["value"]):
        return None
    return _Estimate(v["value"], (_opt(v["low"]), _opt(v["high"])), "table-varied-estimate", rd.coverage,
                     dict(interpolation_error_log=v["interp"], rounding_error_log=v["rounding"],
                          table_crossing_s=rd.raw))


def _efficiency_estimate(rd: _Reading) -> _Estimate | None:
    """The SVM's noise efficiency against the exact ideal observer (:func:`noise_k_min_contact`): no
    interpolation of the steep need between grid points (an SVM table of a model with a closed form)."""
    op, eff = rd.op, rd.efficiency
    if eff is None or math.isnan(eff["value"]):
        return None
    low = eff["low"] if rd.ideal is None else min(max(eff["low"], rd.ideal), eff["value"])
    comp = dict(efficiency=eff["k"], efficiency_se_log=eff["se_log"], table_crossing_s=rd.raw,
                noise_efficiency_at_s={f"{eff['t_a']:g}": eff["k_a"], f"{eff['t_b']:g}": eff["k_b"]})
    note = ""
    first = float(op.view.contacts[0])
    if eff["value"] < first:  # the efficiency at the first contact times, applied below them: said, not hidden
        comp["below_grid"] = True
        note = (f"{eff['value']:.3g} s lies below the table's first contact time, {first:g} s: the SVM's noise "
                "efficiency read there is applied to the exact ideal observer (an extrapolation in contact "
                "time; docs/accuracy.md measures it)")
    return _Estimate(eff["value"], (low, eff["high"]), "table-efficiency", rd.coverage, comp, note)


def _rounding_estimate(rd: _Reading) -> _Estimate | None:
    """Interpolated between two tabulated needs (:func:`contact_estimate`): the table's Monte Carlo interval
    (its deltas' z-SE ends, rescaled to the coverage) and the interpolation error (the distance to a log-log
    interpolation's crossing: the need falls roughly as a power of the contact time), the grid's rounding
    corrected on an SVM table."""
    k = rd.k_cross
    if rd.raw is None or not (k > 0 and not math.isnan(rd.needs[k - 1])):
        return None
    grid, op = rd.op.view.contacts, rd.op
    est = contact_estimate(float(grid[k - 1]), float(grid[k]), rd.needs[k - 1], rd.needs[k], rd.hi - rd.lo, rd.raw,
                           _arr(rd.mc_interval[0]), _arr(rd.mc_interval[1]), _arr(rd.floor), width=op.width,
                           svm=rd.svm, z_table=table_z(op.tab), zc=z_of_coverage(rd.coverage))
    return _Estimate(float(est["value"]), (_opt(est["low"]), _opt(est["high"])), "table-estimate", rd.coverage,
                     dict(interpolation_error_log=float(est["interp"]), rounding_error_log=float(est["rounding"]),
                          table_crossing_s=rd.raw))


def _cell_estimate(rd: _Reading) -> _Estimate | None:
    """The grid cell the crossing lies in, no stated coverage: where the crossing is the table's first contact,
    or follows a contact where the pair is beyond the grid."""
    k, op, value = rd.k_cross, rd.op, rd.raw
    if value is None:
        return None
    prev = float(op.view.contacts[k - 1]) if k > 0 else 0.0
    # with the initial temperature varied per touch, F1 need not rise with contact time (an F1 of 0.9 at
    # 0.44 s, and not at the table's 0.5 s, was measured): not separable at the previous contact does
    # not bound the shortest time from below, so the cell starts at the ideal bound
    start = 0.0 if table_spread(op.tab) > 0 else prev
    low = max(start, rd.floor) if rd.floor is not None else start
    why = ("the table's first contact time" if k == 0 else
           f"the table's next contact time after {prev:g} s, where they are not separable within its "
           "effusivity range")
    note = (f"{value:g} s is {why}: the shortest time lies in ({low:g}, {value:g}] s and the grid cannot "
            "support an interval of stated coverage there (the exact route estimates it)")
    if not states_coverage(op.tab, "min-contact", "table-cell"):  # VARIED_COVERAGE_NOTE: no claim
        note = f"{value:g} s is {why}: the grid cell is ({low:g}, {value:g}] s"
        if start < prev:
            note += (" (from the ideal bound: with the initial temperature varied, F1 need not rise "
                     "with contact time)")
    return _Estimate(value, (low, value), "table-cell", None, note=note)


#: min-contact's estimators from a table, in the order tried: the first that applies answers.
CONTACT_ESTIMATORS = (_varied_estimate, _efficiency_estimate, _rounding_estimate, _cell_estimate)


# ============================================================ max-noise / min-delta-t
def _max_ratio(view: _View, kind: str, contact_s: float, lo: float, hi: float, *,
               geometric: bool = False, shift: float = 0.0) -> tuple[float | None, str]:
    """Largest sigma/dT (fixed-condition table) at which the pair separates, and where it lies.

    ``geometric``: the alternative interpolant (log need, log-log in contact time) instead of
    the linear one. ``shift``: subtracted from every tabulated need (the grid's rounding of delta).
    """
    ratios = view.t.axes["noise_ratio"]
    cw, _ = _contact_weights(view, contact_s)
    if geometric:
        cw = axis_weights_flagged(view.contacts, contact_s, log=True)[0]

    def margin(r_idx):
        if geometric:
            nds = [view.need(kind, [((r_idx,), 1.0)], k, lo, hi) - shift if w else 1.0 for k, w in cw]
            if any(math.isnan(n) or n <= 0 for n in nds):
                return -math.inf
            nd = math.exp(sum(w * math.log(n) for (_, w), n in zip(cw, nds)))
            return math.log(hi - lo) - math.log(nd)
        nd = _need_at_contact(view, kind, [((r_idx,), 1.0)], cw, lo, hi) - shift
        return -math.inf if math.isnan(nd) else (hi - lo) - nd

    ok_rows = [margin(i) >= 0 for i in range(ratios.size)]
    if not ok_rows[0]:
        return None, "below"
    last = max(i for i, ok in enumerate(ok_rows) if ok)
    if last == ratios.size - 1:
        return float(ratios[-1]), "above"
    m0, m1 = margin(last), margin(last + 1)  # interpolate the crossing in log(ratio)
    if not math.isfinite(m1):  # the next row's delta lies beyond the grid: the crossing is in the cell
        return float(ratios[last]), "cell"
    w = m0 / (m0 - m1) if m0 != m1 else 0.0
    lr = math.log(ratios[last]) + w * (math.log(ratios[last + 1]) - math.log(ratios[last]))
    return math.exp(lr), "inside"


def _ratio_question(question: str, e1, e2, m1, m2, objects, contact_s, noise_c, delta_t_c, threshold, table,
                    ideal_table, sensor, model, coverage: float = 0.9,
                    sensor_temp_spread_c: float = 0.0) -> Answer:
    contact = check_contact(contact_s)
    coverage = check_coverage(coverage)
    if question == "max-noise":
        _, dt = scene_inputs(0.0, delta_t_c)
        scene = _scene(contact, None, dt)
    else:
        noise, _ = scene_inputs(noise_c, 1.0)
        if noise == 0:
            raise InputError("noise sigma is 0: any temperature difference separates them (no smallest one)")
        scene = _scene(contact, noise, None)
    op = _open(table, ideal_table, threshold=threshold, sensor=sensor, model=model,
               spread=sensor_temp_spread_c)
    if "noise_ratio" not in op.tab.axes:
        raise TableMismatch(f"table {op.tab.name} has separate noise and temperature axes (varied initial "
                            f"conditions): it cannot answer {question}; the exact route can")
    pq = pair_question(e1, e2, m1, m2, objects=objects, width=op.width, model=op.model)
    if pq.classes is None:
        return _no_pair(question, op, pq, scene, {})
    lo, hi = pq.points
    view = op.view
    _, c_ok = _contact_weights(view, contact)
    flags = {"contact_s": c_ok, "effusivity": view.e_in_grid(lo, hi)}
    common = dict(objects=pq.objects_dicts(), limiting=pq.limiting_dicts(), rule=pq.rule, scene=scene,
                  classes=pq.classes)

    def to_answer(r):
        if r is None:
            return None
        return r * abs(dt) if question == "max-noise" else noise / r

    if not all(flags.values()):
        notes = _outside_notes(view, flags, {"contact_s": contact, "effusivity": (lo, hi)})
        return _answer(question, op, value=None, interval=(None, None),
                       ideal=to_answer(_closed_ideal_ratio(op, lo, hi, contact)), ideal_method="closed-form",
                       in_grid=flags, details={}, notes=notes, **common)

    out = {}
    for kind, v in (("svm", view), ("lo", view), ("hi", view), ("ideal", op.iview)):
        if kind == "ideal" and op.closed:
            ri = _closed_ideal_ratio(op, lo, hi, contact)
            out[kind] = (ri, "inside" if ri is not None else "below")
            continue
        if op.tab.fidelity == "ideal" and kind in ("lo", "hi"):
            out[kind] = out["svm"]
            continue
        if v is None:  # no ideal-observer source for this table: no bound rather than a wrong one
            out[kind] = (None, "below")
            continue
        out[kind] = _max_ratio(v, op.ikind if kind == "ideal" else kind, contact, lo, hi)
    r, where = out["svm"]
    ratios = view.t.axes["noise_ratio"]
    if where == "above":
        flags["noise_ratio"] = False
    # the Monte Carlo ends: more noise allowed at the optimistic end ('lo': ratio >= the answer's)
    ends = [to_answer(out[k][0]) if out[k][1] != "below" else None for k in ("hi", "lo")]
    mc = tuple(sorted(ends, key=lambda x: (x is None, x))) if all(e is not None for e in ends) else tuple(ends)
    rd = _RatioReading(op, question, contact, lo, hi, r, where, out, mc, coverage, dt if question == "max-noise"
                       else None, None if question == "max-noise" else noise)
    est = next((e for e in (estimator(rd) for estimator in RATIO_ESTIMATORS) if e is not None), None)
    if est is None:  # not separable within the table
        est = _Estimate(None, (None, None), "none", None,
                        note=f"not separable even at the table's smallest noise ratio sigma/dT = {ratios[0]:g}")
    computation = {"monte_carlo_interval": list(mc), **est.computation}
    r = est.ratio if est.ratio is not None else r
    r_check = r if r is not None else float(ratios[0])
    check_at = (contact, r_check * abs(dt), dt) if question == "max-noise" else (contact, noise, noise / r_check)
    ideal = to_answer(out["ideal"][0]) if out["ideal"][1] != "below" else None
    return _answer(question, op, value=est.value, interval=est.interval, ideal=ideal,
                   ideal_method="closed-form" if op.closed else "table", in_grid=flags, details={},
                   notes=[est.note], check_at=check_at,
                   interval_kind=est.kind, interval_coverage=est.coverage, computation=computation, **common)


# ---------------------------------------------------------------- max-noise / min-delta-t's estimators
@dataclass(frozen=True)
class _RatioReading:
    """What max-noise / min-delta-t read from the table for one pair ``lo < hi`` at one contact [s]: the largest
    separating sigma/dT ``r`` and where it lies (``where``: below / inside / cell / above the table's ratios),
    each kind's reading (``out``: svm, lo, hi, ideal -> (ratio, where)), the Monte Carlo ends in the answer's
    units (``mc``), and the scene's dT (max-noise) or noise (min-delta-t) [degC]."""

    op: Any
    question: str
    contact: float
    lo: float
    hi: float
    r: float | None
    where: str
    out: dict
    mc: tuple
    coverage: float
    dt: float | None
    noise: float | None

    def answer(self, r: float | None) -> float | None:
        """A sigma/dT in the answer's units (degC)."""
        if r is None:
            return None
        return r * abs(self.dt) if self.question == "max-noise" else self.noise / r

    def interval(self, r_low, r_high) -> tuple:
        """The interval of sigma/dT ends in the answer's units, low <= high."""
        iv = (self.answer(r_low), self.answer(r_high))
        return iv if self.question == "max-noise" else (iv[1], iv[0])

    @property
    def ideal_ratio(self) -> float | None:
        return self.out["ideal"][0] if self.out["ideal"][1] != "below" else None


def _ratio_efficiency(rd: _RatioReading) -> _Estimate | None:
    """The SVM's noise efficiency against the exact ideal observer (:func:`noise_k_max_ratio`)."""
    op = rd.op
    if not (rd.where in ("inside", "cell") and op.tab.fidelity == "svm" and op.closed and rd.ideal_ratio is not None
            and "delta_up_ideal" in op.view.t.arrays):
        return None
    kr = noise_k_max_ratio(op, rd.contact, rd.r, rd.ideal_ratio, rd.lo, rd.hi, zc=z_of_coverage(rd.coverage))
    if math.isnan(float(kr["value"][0])):
        return None
    kr = {key: float(v[0]) for key, v in kr.items()}
    r = min(kr["value"], rd.ideal_ratio)
    return _Estimate(rd.answer(r), rd.interval(kr["low"], min(kr["high"], rd.ideal_ratio)), "table-efficiency",
                     rd.coverage, dict(table_crossing_noise_ratio=rd.r, efficiency=kr["k"],
                                       efficiency_se_log=kr["se_log"]), ratio=r)


def _ratio_rounding(rd: _RatioReading) -> _Estimate | None:
    """As min-contact's: the tabulated deltas are rounded up to the grid (on average half a width late), so the
    raw crossing tolerates too little noise; the answer subtracts w/2 from the need and interpolates log-log,
    the interval carries the interpolants' difference and the rounding's SD (:func:`ratio_estimate`)."""
    op, out = rd.op, rd.out
    if not (rd.where == "inside" and op.tab.fidelity == "svm"):
        return None
    w, view, lo, hi, contact = op.width, op.view, rd.lo, rd.hi, rd.contact

    def inside(v):
        return v[0] if v[1] == "inside" else math.nan

    r_c = inside(_max_ratio(view, "svm", contact, lo, hi, geometric=True, shift=0.5 * w))
    r_lin = inside(_max_ratio(view, "svm", contact, lo, hi, shift=0.5 * w))
    both = not (math.isnan(r_c) or math.isnan(r_lin))
    r_rnd = inside(_max_ratio(view, "svm", contact, lo, hi, geometric=True,
                              shift=0.5 * w + w / math.sqrt(12))) if both else math.nan
    r_geo = math.nan if both else inside(_max_ratio(view, "svm", contact, lo, hi, geometric=True))
    ends = [math.nan if out[k][1] == "below" or (k == "lo" and out[k][1] == "above") else out[k][0]
            for k in ("hi", "lo")]
    est = ratio_estimate(rd.r, r_c, r_lin, r_rnd, r_geo, ends[0], ends[1], _arr(rd.ideal_ratio),
                         z_table=table_z(op.tab), zc=z_of_coverage(rd.coverage))
    r = float(est["value"])
    return _Estimate(rd.answer(r), rd.interval(_opt(est["low"]), _opt(est["high"])), "table-estimate", rd.coverage,
                     dict(table_crossing_noise_ratio=rd.r, interpolation_error_log=float(est["interp"]),
                          rounding_error_log=float(est["rounding"])), ratio=r)


def _ratio_cell(rd: _RatioReading) -> _Estimate | None:
    """A neighbour beyond the grid: the crossing lies in the cell up to the next ratio (or the ideal bound), no
    stated coverage."""
    if rd.where != "cell":
        return None
    ratios = rd.op.view.t.axes["noise_ratio"]
    k = int(np.searchsorted(ratios, rd.r))
    nxt = float(ratios[min(k + 1, ratios.size - 1)])
    nxt = min(nxt, rd.ideal_ratio) if rd.ideal_ratio is not None else nxt
    return _Estimate(rd.answer(rd.r), rd.interval(rd.r, nxt), "table-cell", None, note=(
        f"sigma/dT {rd.r:g} is the table's last noise ratio where they separate; at the next, {nxt:g}, the "
        "pair lies beyond its effusivity range: the answer lies between them and the grid cannot support "
        "an interval of stated coverage there (the exact route estimates it)"))


def _ratio_ideal_table(rd: _RatioReading) -> _Estimate | None:
    """An ideal-observer table: the answer with its Monte Carlo ends, no stated coverage."""
    return _Estimate(rd.answer(rd.r), rd.mc, "table", None) if rd.where == "inside" else None


def _ratio_beyond(rd: _RatioReading) -> _Estimate | None:
    """Separable beyond the table's largest ratio: the answer is a one-sided bound."""
    if rd.where != "above":
        return None
    value = rd.answer(rd.r)
    more = "at least" if rd.question == "max-noise" else "at most"  # a larger ratio: more noise, a smaller dT
    return _Estimate(value, (value, None) if rd.question == "max-noise" else (None, value), "table-cell", None,
                     note=(f"separable even at the table's largest noise ratio sigma/dT = {rd.r:g}: the answer is "
                           f"{more} this (the exact route looks further) (the grid cannot support an interval of "
                           "stated coverage there)"))


#: max-noise / min-delta-t's estimators from a table, in the order tried: the first that applies answers.
RATIO_ESTIMATORS = (_ratio_efficiency, _ratio_rounding, _ratio_cell, _ratio_ideal_table, _ratio_beyond)


def max_noise(e1=None, e2=None, *, m1=None, m2=None, objects=None, contact_s: float, delta_t_c: float = 10.0,
              threshold=None, table=DEFAULT_TABLE, ideal_table=DEFAULT_IDEAL_TABLE, sensor=None,
              model=None, coverage: float = 0.9,
              sensor_temp_spread_c: float = 0.0) -> Answer:
    """Largest noise sigma [degC] at which ``contact_s`` still separates the objects (table).

    Arguments as :func:`min_contact`; ``contact_s`` [s] is the contact time.
    """
    return _ratio_question("max-noise", e1, e2, m1, m2, objects, contact_s, None, delta_t_c, threshold, table,
                           ideal_table, sensor, model, coverage, sensor_temp_spread_c)


def min_delta_t(e1=None, e2=None, *, m1=None, m2=None, objects=None, contact_s: float, noise_c: float = 0.05,
                threshold=None, table=DEFAULT_TABLE, ideal_table=DEFAULT_IDEAL_TABLE, sensor=None,
                model=None, coverage: float = 0.9,
                sensor_temp_spread_c: float = 0.0) -> Answer:
    """Smallest sensor-object temperature difference [degC] that separates the objects (table).

    Arguments as :func:`min_contact`; ``contact_s`` [s] is the contact time.
    """
    return _ratio_question("min-delta-t", e1, e2, m1, m2, objects, contact_s, noise_c, None, threshold, table,
                           ideal_table, sensor, model, coverage, sensor_temp_spread_c)


# ============================================================ delta-e
def delta_e(e: float | None = None, *, m: str | None = None, contact_s: float, noise_c: float = 0.05,
            delta_t_c: float = 10.0, threshold=None, table=DEFAULT_TABLE, ideal_table=DEFAULT_IDEAL_TABLE,
            sensor=None, model=None, coverage: float = 0.9,
            sensor_temp_spread_c: float = 0.0, ideal_bound: bool = True) -> Answer:
    """delta(e) towards lower and higher effusivity [J s^-1/2 K^-1 m^-2] (table).

    ``value`` is the smaller of the two; ``details["lower"]`` and
    ``details["upper"]`` hold each direction's value, interval at ``coverage``
    (the table's Monte Carlo interval rescaled, combined with the interpolation
    error: linear against log-space interpolation over contact time and sigma/dT)
    and ideal bound (None: nothing distinguishable within the grid that way).
    ``interval`` is the interval of the direction giving ``value``. ``m``: a
    material, its range's middle as the reference. ``ideal_bound``: as :func:`min_contact`'s (each
    direction's bound by Monte Carlo where no closed form holds, or False: the table's own floor).
    """
    contact = check_contact(contact_s)
    coverage = check_coverage(coverage)
    noise, dt = scene_inputs(noise_c, delta_t_c)
    op = _open(table, ideal_table, threshold=threshold, sensor=sensor, model=model,
               spread=sensor_temp_spread_c)
    ref = reference_class(e, m, width=op.width, model=op.model)
    x = ref.e_range[0]
    view = op.view
    combos, flags = view.scene_weights(noise, dt)
    cw, flags["contact_s"] = _contact_weights(view, contact)
    flags["effusivity"] = view.e_in_grid(x)
    scene = _scene(contact, noise, dt)
    common = dict(objects=(ref.to_dict(),), limiting=(ref.to_dict(),), rule=REFERENCE_RULE, scene=scene,
                  classes=(ref,))
    if not all(flags.values()):
        wanted = {**_scene_wanted(view, noise, dt), "contact_s": contact, "effusivity": (x,)}
        sides = _outside_ideal_delta(op, x, contact, noise / abs(dt)) if ideal_bound and flags["effusivity"] else {}
        ideals = [sd["ideal"] for sd in sides.values() if sd["ideal"] is not None]
        return _answer("delta-e", op, value=None, interval=(None, None), ideal=min(ideals) if ideals else None,
                       ideal_method="closed-form", in_grid=flags, details=_delta_details(x, sides),
                       notes=_outside_notes(view, flags, wanted), **common)
    # the grid's ideal delta(e) (the bound of the route without a closed form; with one, the efficiency route
    # below computes the bound exactly and keeps this beside it as "table_ideal")
    iview, ikind, _ = (op.iview, op.ikind, None) if not op.closed else _ideal_view(view, ideal_table)
    icombos, _ = iview.scene_weights(noise, dt) if iview is not None else ([], {})
    icw, _ = _contact_weights(iview, contact) if iview is not None else ([], False)

    at = functools.partial(_delta_read, x)  # (view, scene weights, contact weights, array name[, geometric])

    zc, z_t = z_of_coverage(coverage), table_z(op.tab)
    gcw = axis_weights_flagged(view.contacts, contact, log=True)[0]

    efficiency = op.tab.fidelity == "svm" and op.closed and "delta_up_ideal" in view.t.arrays
    ends = (cw[0][0], cw[-1][0])  # the tabulated contacts around the asked one (the same where it is on one)
    both = (_delta_efficiency_both(op, combos, ends, x, contact, noise / abs(dt), zc) if efficiency
            else {"down": None, "up": None})
    sides = {}
    for direction, side in (("down", "lower"), ("up", "upper")):
        val = at(view, combos, cw, f"delta_{direction}")
        iv = ([at(view, combos, cw, f"delta_{direction}_lo"), at(view, combos, cw, f"delta_{direction}_hi")]
              if op.tab.fidelity == "svm" else [val, val])
        iname = f"delta_{direction}_ideal" if ikind == "ideal" else f"delta_{direction}"
        ideal_side = at(iview, icombos, icw, iname)
        side_floor, extra = ideal_side, {}
        if not op.closed and ideal_bound:  # no closed form: Monte Carlo at query time, the grid's kept beside it
            ideal_side, side_floor, extra = _mc_delta_side(op, ref, direction, contact, noise, dt, coverage,
                                                           ideal_side)
        stated, cov_side, method = [None, None], None, "none"
        eff = both[direction]
        if eff is not None and val is None and not partner_in_grid(view, x, eff["value"], direction):
            eff = None
        if eff is not None:  # the SVM's efficiency against the exact ideal observer (delta_efficiency_estimate)
            sides[side] = {"value": eff["value"], "interval": [eff["low"], eff["high"]], "ideal": eff["ideal"],
                           "coverage": coverage, "estimate_method": "table-efficiency", "monte_carlo_interval": iv,
                           "table_value": val, "table_ideal": ideal_side, "efficiency": eff["efficiency"]}
            continue
        if val is not None and op.tab.fidelity == "svm":
            geo = at(view, combos, gcw, f"delta_{direction}", geometric=True)
            low, high = (_opt(v) for v in delta_estimate(val, _arr(iv[0]), _arr(iv[1]), _arr(geo), _arr(side_floor),
                                                         width=op.width, z_table=z_t, zc=zc))
            stated, cov_side, method = [low, high], coverage, "table-estimate"
        sides[side] = {"value": val, "interval": stated, "ideal": ideal_side, "coverage": cov_side,
                       "estimate_method": method, "monte_carlo_interval": iv, **extra}
    finite = [s["value"] for s in sides.values() if s["value"] is not None]
    ifinite = [s["ideal"] for s in sides.values() if s["ideal"] is not None]
    best = min((s for s in sides.values() if s["value"] is not None), key=lambda s: s["value"], default=None)
    stated = best is not None and best["coverage"] is not None
    closed = best is not None and best["estimate_method"] == "table-efficiency"
    from .ideal_mc_bound import nearer_side_interval

    return _answer("delta-e", op, value=min(finite) if finite else None,
                   interval=tuple(best["interval"]) if stated else (None, None),
                   interval_kind=best["estimate_method"] if stated else "none",
                   interval_coverage=coverage if stated else None,
                   ideal=min(ifinite) if ifinite else None,
                   ideal_method="closed-form" if closed else "table" if op.closed or not ideal_bound
                   else "monte-carlo",
                   ideal_interval=nearer_side_interval(sides, coverage),
                   in_grid=flags, details=_delta_details(x, sides),
                   check_at=(contact, noise, dt), **common)


def _mc_delta_side(op, ref, direction: str, contact: float, noise: float, dt: float, coverage: float,
                   grid_ideal: float | None) -> tuple:
    """delta-e's ideal bound of one direction by Monte Carlo at query time (no closed form): its value, the floor
    the interval is held above (its low end), and the grid's bound and the Monte Carlo interval for ``details``."""
    from .ideal_mc_bound import cached_mc_ideal_delta

    mcb = cached_mc_ideal_delta(ref, 1 if direction == "up" else -1, op.tab.sensor, contact_s=contact,
                                noise_c=noise, delta_t_c=dt, sensor_temp_spread_c=table_spread(op.tab),
                                model=op.model, threshold=op.phi, coverage=coverage)
    extra = {"table_ideal": grid_ideal, "ideal_interval": list(mcb.interval[:2]) if mcb.interval else None}
    return mcb.value, mcb.floor, extra


def _delta_read(x: float, v: "_View | None", cmb, cws, name: str, geometric: bool = False) -> float | None:
    """Array ``name`` of view ``v`` at effusivity ``x``, scene weights ``cmb`` and contact weights ``cws`` (None:
    no such view or array, or a NaN within the weights); ``geometric``: log delta interpolated (weights in log
    contact, log sigma/dT)."""
    if v is None or name not in v.t.arrays:
        return None
    total = 0.0
    for k, w in cws:
        if w == 0:
            continue
        if geometric:
            for idx, wi in cmb:
                y = _interp_e(v.t.arrays[name][idx + (k,)], v.centres, x) if wi else 1.0
                if math.isnan(y) or y <= 0:
                    return None
                total += w * wi * math.log(y)
            continue
        y = v.delta_at(name, cmb, k, x)
        if math.isnan(y):
            return None
        total += w * y
    return math.exp(total) if geometric else total


def partner_in_grid(view: _View, e, delta, direction: str):
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


#: The scalar route's efficiency estimates (:func:`delta_efficiency_estimate`, both directions), per process (least
#: recently used out): a question asked again reads them from here (the estimate re-reads 24 table entries and 10
#: cached ideal deltas, ~1 ms of numpy overhead). A pure function of the key: the table's content and the arguments.
_DELTA_EFF: "LRUCache[tuple, dict]" = LRUCache(4096)


def _delta_efficiency_both(op, combos, ends, x: float, contact: float, ratio: float,
                           zc: float) -> dict[str, dict[str, float] | None]:
    """Both directions' :func:`delta_efficiency_estimate` for the scalar route in one computation (the ideal
    observer's bisections of both directions at once), cached; per direction ("down", "up") a dict, or None
    where it does not apply."""
    h = op.tab.header.get("content_hash")
    key = (h, float(op.width), float(op.phi), tuple(combos), tuple(ends), x, contact, ratio, zc)
    hit = _DELTA_EFF.get(key) if h is not None else None
    if hit is not None:
        return hit
    view = op.view
    (ratios, weights, *down), (_, _, *up) = (delta_entries(view, combos, ends, d, x) for d in ("down", "up"))
    r = delta_efficiency_estimate(
        op.tab.sensor, np.array([x, x]), contact, ratio, np.array([-1.0, 1.0]), *(view.contacts[k] for k in ends),
        ratios, weights, *(np.concatenate([a, b], axis=2) for a, b in zip(down, up)), width=op.width,
        threshold=op.phi, e_max=view.e_hi, z_table=table_z(op.tab), zc=zc, mc_factor=view.mc_calibration())
    out = {d: None if math.isnan(float(r["value"][i])) else {k: float(v[i]) for k, v in r.items()}
           for i, d in enumerate(("down", "up"))}
    if h is not None:  # a table without a hash: its content is not a key
        _DELTA_EFF[key] = out
    return out


def _outside_ideal_delta(op: _Opened, e: float, contact: float, ratio: float) -> dict[str, dict]:
    """Both sides of delta-e with only the ideal observer's delta(e) (closed form, inside the table's effusivity
    range) for a question whose scene lies outside the table's grid; empty without a closed form."""
    if not (op.closed and within_sample_limit(contact, op.tab.sensor.sample_rate_hz)):
        return {}
    from .ideal_bound import exact_ideal_delta

    down, up = exact_ideal_delta(op.tab.sensor, np.array([e, e]), contact, ratio,
                                 direction=np.array([-1.0, 1.0]), width=op.width, threshold=op.phi,
                                 e_max=op.view.e_hi)
    return {"lower": _no_side(number(down)), "upper": _no_side(number(up))}


def _no_side(ideal: float | None = None) -> dict[str, Any]:
    """One side of delta-e's details with no answer from the table (a new dict each time)."""
    return {"value": None, "interval": [None, None], "ideal": ideal, "coverage": None, "estimate_method": "none"}


def _delta_details(e: float, sides: dict) -> dict[str, Any]:
    return {"e": e, "lower": sides.get("lower") or _no_side(), "upper": sides.get("upper") or _no_side()}


# ============================================================ distinguishable
#: Ideal F1 of a pair at a scene, per process (the closed form's search costs ~30 ms; a loop of
#: ``distinguishable`` calls asks the same pair again): a function of its key, so a hit returns exactly
#: what the computation would.
_IDEAL_F1: "LRUCache[tuple, tuple[float, str]]" = LRUCache(4096)


def _ideal_pair_f1(classes, op, contact: float, noise: float, dt: float, spread: float = 0.0) -> tuple[float, str]:
    """:func:`designkit.recognition.ideal.ideal_pair`'s F1 and method for the table route's pair, cached
    (``spread`` [degC]: the sensor temperature drawn per touch within +-spread of Ta + dT, Ta 25 degC, as the
    exact route's scene; the ideal observer is then a Monte Carlo one)."""
    from ..recognition.ideal import ideal_pair
    from ..scene import Scene

    sen = op.tab.sensor
    key = (tuple(classes), float(sen.effusivity), float(sen.tau_s),
           float(sen.sample_rate_hz), contact, noise, dt, spread, op.tab.header["content_hash"], op.model.name)
    hit = _IDEAL_F1.get(key)
    if hit is None:
        scene = Scene.from_delta_t(contact_s=contact, noise_c=noise, delta_t_c=dt, sensor_temp_spread_c=spread)
        res = ideal_pair(*classes, sen, scene, model=op.model)
        hit = _IDEAL_F1[key] = (float(res.f1), res.method)
    return hit


def distinguishable(e1=None, e2=None, *, m1=None, m2=None, objects=None, contact_s: float, noise_c: float = 0.05,
                    delta_t_c: float = 10.0, threshold=None, table=DEFAULT_TABLE, ideal_table=DEFAULT_IDEAL_TABLE,
                    sensor=None, model=None, coverage: float = 0.9,
                    sensor_temp_spread_c: float = 0.0) -> Answer:
    """Whether ``contact_s`` separates the objects (table), with the ideal observer's F1 (closed form).

    ``value`` follows from the same estimate :func:`min_contact` gives for the pair at the asked noise and
    dT (on a fixed-condition SVM table the noise-efficiency route, elsewhere the table's crossing): True iff
    ``contact_s`` is at least that shortest separating contact, so the two questions never contradict each
    other. ``details["verdict"]`` is ``"confident"`` when ``contact_s`` lies outside min-contact's
    ``coverage`` interval, ``"uncertain"`` inside it (the table cannot tell; the exact route computes the
    pair's F1), ``"uncertain"`` inside a grid cell whose interval has no stated coverage, None where no
    interval is stated (none within the grid separates, or outside the cell). Where the contact lies
    inside min-contact's interval but :func:`max_noise` (the asked noise outside its interval) or
    :func:`delta_e` (the pair's distance outside the interval of the need ``max(delta_up(lo),
    delta_down(hi))``) is sure, that answer decides and the verdict is ``"confident"`` (both sure and
    disagreeing: min-contact's, ``"uncertain"``, the note says so); so ``value`` never contradicts any of
    the three where the asked point lies outside its interval (tests/test_table_agreement.py). The SVM's
    F1 of the pair itself is not in a table (``details["svm_f1"]`` None): no interval of the F1.
    ``computation["min_contact_s"]`` / ``["min_contact_interval_s"]`` hold the answer compared with.

    What the table's grid interpolation alone answers (the need ``max(delta_up(lo), delta_down(hi))``
    interpolated at ``contact_s``, compared with the pair's distance: what ``designkit export``'s lookup
    functions answer) is kept in ``computation["grid_verdicts"]`` (:func:`grid_answer` reads it).

    Examples
    --------
    >>> a = distinguishable(35000, 20000, contact_s=1.45)
    >>> m = min_contact(35000, 20000)
    >>> a.value == (1.45 >= m.value), a.details["verdict"]
    (True, 'confident')
    """
    coverage = check_coverage(coverage)
    contact = check_contact(contact_s)
    noise, dt = scene_inputs(noise_c, delta_t_c)
    op = _open(table, ideal_table, threshold=threshold, sensor=sensor, model=model,
               spread=sensor_temp_spread_c)
    pq = pair_question(e1, e2, m1, m2, objects=objects, width=op.width, model=op.model)
    scene = _scene(contact, noise, dt)
    empty = {"distinguishable": None, "svm_f1": None, "svm_standard_error": None, "verdict": None,
             "ideal_f1": None, "ideal_distinguishable": None}
    if pq.classes is None:
        return _no_pair("distinguishable", op, pq, scene, empty)
    lo, hi = pq.points
    view = op.view
    combos, flags = view.scene_weights(noise, dt)
    cw, flags["contact_s"] = _contact_weights(view, contact)
    flags["effusivity"] = view.e_in_grid(lo, hi)
    common = dict(objects=pq.objects_dicts(), limiting=pq.limiting_dicts(), rule=pq.rule, scene=scene,
                  classes=pq.classes)
    if not all(flags.values()):
        wanted = {**_scene_wanted(view, noise, dt), "contact_s": contact, "effusivity": (lo, hi)}
        ideal_f1, ideal_method, details = None, "none", dict(empty)
        if op.closed and within_sample_limit(contact, op.tab.sensor.sample_rate_hz):  # the closed form: no table
            ideal_f1, ideal_method = _ideal_pair_f1(pq.classes, op, contact, noise, dt)
            details.update(ideal_f1=ideal_f1, ideal_distinguishable=ideal_f1 >= op.phi)
        return _answer("distinguishable", op, value=None, interval=(None, None), ideal=ideal_f1,
                       ideal_method=ideal_method, in_grid=flags, details=details,
                       notes=_outside_notes(view, flags, wanted), **common)

    def grid_verdict(kind):  # the grid's need interpolated at the contact (what an export answers)
        nd = _need_at_contact(view, kind, combos, cw, lo, hi)
        return not math.isnan(nd) and nd <= hi - lo

    svm = op.tab.fidelity == "svm"
    grid = {k: grid_verdict(k) for k in (("svm", "lo", "hi") if svm else ("svm",))}
    if not svm:
        grid["lo"] = grid["hi"] = grid["svm"]
    ideal_f1, ideal_method = _ideal_pair_f1(pq.classes, op, contact, noise, dt, table_spread(op.tab))
    # the answer: the contact against min-contact's own estimate for this pair and scene (where the bound has
    # no closed form, with the table's own floor under its interval: the verdict needs no Monte Carlo bound)
    mc = min_contact(objects=pq.classes, noise_c=noise, delta_t_c=dt, table=op.tab, ideal_table=ideal_table,
                     sensor_temp_spread_c=sensor_temp_spread_c, coverage=coverage, ideal_bound=False)
    t_min = mc.value
    yes = t_min is not None and contact >= t_min
    sure, note = _contact_verdict(contact, mc, coverage)
    if sure == "uncertain":  # inside min-contact's interval: max-noise or delta-e may still be sure of it
        ask = dict(table=op.tab, ideal_table=ideal_table, sensor_temp_spread_c=sensor_temp_spread_c,
                   coverage=coverage)
        mn = (max_noise(objects=pq.classes, contact_s=contact, delta_t_c=dt, **ask)
              if "noise_ratio" in op.tab.axes else None)
        de = [delta_e(e, contact_s=contact, noise_c=noise, delta_t_c=dt, ideal_bound=False, **ask)
              for e in (lo, hi)]
        reads = _other_readings(noise, hi - lo, None if mn is None else (mn.value, *mn.interval)
                                if mn.interval_coverage is not None else None,
                                [(d.details[side]["value"], *d.details[side]["interval"])
                                 if d.details[side].get("coverage") is not None else None
                                 for d, side in zip(de, ("upper", "lower"))])
        said = {v for _, v, _ in reads}
        a, b = mc.interval
        inside = (f"{contact:g} s lies inside min-contact's interval ({t_min:.3g} s, {a:.3g} to {_fmt_or_open(b)} s)"
                  if a is not None else f"{contact:g} s is near min-contact's {t_min:.3g} s")
        if len(said) == 1:
            yes, sure = said.pop(), "confident"
            note = f"verdict confident: {' and '.join(w for _, _, w in reads)} (while {inside})"
        elif said:
            note += "; " + " but ".join(w for _, _, w in reads) + " (they disagree here)"
    details = {"distinguishable": yes, "svm_f1": None, "svm_standard_error": None, "verdict": sure,
               "ideal_f1": ideal_f1, "ideal_distinguishable": ideal_f1 >= op.phi}
    notes = ["no interval: a table holds delta(e), not this pair's F1 (the exact route states the F1's interval)",
             note]
    if grid["svm"] != yes:
        notes.append(f"the table's grid interpolated at {contact:g} s alone (what designkit export answers) says "
                     f"{'yes' if grid['svm'] else 'no'}: min-contact's estimate is finer than the grid")
    return _answer("distinguishable", op, value=yes, interval=(None, None), ideal=ideal_f1,
                   ideal_method=ideal_method, in_grid=flags, details=details, check_at=(contact, noise, dt),
                   notes=notes, interval_kind="none",
                   computation={"grid_verdicts": grid, "monte_carlo_verdicts": [grid["hi"], grid["lo"]],
                                "min_contact_s": t_min, "min_contact_interval_s": list(mc.interval),
                                "min_contact_interval_kind": mc.interval_kind}, **common)


def _other_readings(noise: float, gap: float, mn, needs) -> list[tuple[str, bool, str]]:
    """The verdicts max-noise and delta-e are sure of, where min-contact is not: the asked ``noise`` [degC]
    outside max-noise's interval ``mn`` = (value, low, high) (None: not stated), the pair's distance ``gap``
    outside the interval of the need ``max(delta_up(lo), delta_down(hi))`` from ``needs`` (each direction's
    (value, low, high) or None) [J s^-1/2 K^-1 m^-2]. Per sure answer: its name, its verdict and the words.

    >>> [(q, v) for q, v, _ in _other_readings(0.05, 3000.0, (0.04, 0.035, 0.045), [None, None])]
    [('max-noise', False)]
    >>> [(q, v) for q, v, _ in _other_readings(0.05, 3000.0, None, [(2000.0, 1900.0, 2100.0), (2500.0, 2400.0, 2600.0)])]
    [('delta-e', True)]
    """
    out = []
    if mn is not None and mn[1] is not None and mn[2] is not None and not mn[1] <= noise <= mn[2]:
        out.append(("max-noise", noise <= mn[0], f"the noise {noise:g} degC lies {'below' if noise < mn[1] else 'above'}"
                    f" max-noise's interval ({mn[1]:.3g} to {mn[2]:.3g} degC)"))
    if all(n is not None and None not in n for n in needs):
        low, high, value = (max(n[i] for n in needs) for i in (1, 2, 0))
        if not low <= gap <= high:
            out.append(("delta-e", gap >= value, f"the pair's distance {gap:.4g} lies {'below' if gap < low else 'above'}"
                        f" delta-e's interval of the need ({low:.4g} to {high:.4g} J s^-1/2 K^-1 m^-2)"))
    return out


def _contact_verdict(contact: float, mc: Answer, coverage: float) -> tuple[str | None, str]:
    """How sure a yes/no on ``contact`` [s] against min-contact's answer ``mc`` is, and the note saying why."""
    t, (a, b) = mc.value, mc.interval
    if t is None:
        return None, "no: no contact time within the table's grid separates them (min-contact answers none)"
    said = f"min-contact {t:.3g} s"
    if mc.interval_coverage is not None and a is not None:
        inside = a <= contact <= (b if b is not None else math.inf)
        iv = (f"the {coverage:.0%} interval of the shortest separating contact ({said}, {a:.3g} to "
              f"{_fmt_or_open(b)} s)")
        if inside:
            return "uncertain", (f"verdict uncertain: {contact:g} s lies inside {iv}: the table cannot tell; "
                                 "--exact computes this pair's F1")
        return "confident", f"verdict confident: {contact:g} s lies {'above' if contact > t else 'below'} {iv}"
    if (mc.interval_kind in ("table-cell", "table-varied") and a is not None
            and a < contact <= (b if b is not None else math.inf)):
        where = "the grid cell" if mc.interval_kind == "table-cell" else "the interval"
        return "uncertain", (f"verdict uncertain: {contact:g} s lies in {where} ({a:.3g}, {_fmt_or_open(b)}] "
                             f"s where the shortest separating contact is ({said}; no stated coverage there)")
    return None, f"{contact:g} s against {said} (no interval of stated coverage there)"


#: The kinds :func:`grid_answer` reads: the SVM's tabulated answer, its Monte Carlo ends, the grid's ideal observer.
GRID_KINDS = ("svm", "lo", "hi", "ideal")


def grid_answer(answer: Answer, kind: str = "svm", part: str | None = None):
    """The table's grid interpolation alone, behind a table-route ``answer``: what ``designkit export``'s lookup
    functions (C header, Python module; :mod:`designkit.export`) answer for the same question.

    An export carries the table's arrays and interpolates them (:mod:`designkit.tables.lookup`); it cannot run
    the exact ideal observer that the table route's estimates apply the SVM's efficiency to. This reads the
    grid's own answer the route keeps beside its estimate: min-contact the crossing of the tabulated need
    (``computation["table_crossing_s"]``, or the value where it was not refined), delta-e each direction's
    tabulated delta(e) (``details[side]["table_value"]``), distinguishable the need at the contact against the
    pair's distance (``computation["grid_verdicts"]``).

    Parameters
    ----------
    answer : Answer
        A table-route answer of min-contact, delta-e or distinguishable, inside the grid.
    kind : str
        ``"svm"`` (the tabulated answer), ``"lo"`` / ``"hi"`` (the ends of the table's Monte Carlo interval),
        ``"ideal"`` (the grid's ideal-observer arrays; not for distinguishable).
    part : str, optional
        delta-e only: ``"lower"`` or ``"upper"`` (one direction); default the smaller of the two.

    Returns
    -------
    float, bool or None
        Seconds (min-contact), J s^-1/2 K^-1 m^-2 (delta-e), a verdict (distinguishable); None: none.

    Examples
    --------
    >>> a = min_contact(35000, 20000)
    >>> t = grid_answer(a)
    >>> t >= a.value, t == a.computation["table_crossing_s"]
    (True, True)
    """
    if kind not in GRID_KINDS:
        raise InputError(f"grid answer kind must be one of {', '.join(GRID_KINDS)}, got {kind!r}")
    comp, d = answer.computation, answer.details
    if answer.question == "min-contact":
        mc = comp.get("monte_carlo_interval", [None, None])
        return {"svm": comp.get("table_crossing_s", answer.value), "lo": mc[0], "hi": mc[1],
                "ideal": comp.get("table_ideal_s", answer.ideal_bound.value)}[kind]
    if answer.question == "distinguishable":
        if kind == "ideal":
            raise InputError("the table route answers the ideal observer's F1 in closed form, not from the grid")
        return comp["grid_verdicts"][kind]
    if answer.question != "delta-e":
        raise InputError(f"no grid answer kept for {answer.question}")
    sides = {}
    for s in ("lower", "upper"):
        x = d[s]
        if kind == "svm":
            sides[s] = x.get("table_value", x["value"])
        elif kind == "ideal":
            sides[s] = x.get("table_ideal", x["ideal"])
        else:
            sides[s] = (x.get("monte_carlo_interval") or [None, None])[0 if kind == "lo" else 1]
    if part is not None:
        return sides[part]
    finite = [v for v in sides.values() if v is not None]
    return min(finite) if finite else None


def _fmt_or_open(x) -> str:
    return "(open)" if x is None else f"{x:.3g}"


# ============================================================ for the array route (designkit.query.vectorized)
def open_table(table: "Table | str" = DEFAULT_TABLE, ideal_table: "Table | str | None" = DEFAULT_IDEAL_TABLE, *,
               threshold=None, sensor=None, model=None, sensor_temp_spread_c: float = 0.0):
    """The table checked against the question, as this route opens it (for the array route).

    Returns an object with ``tab`` (the :class:`~designkit.tables.store.Table`), ``view`` (its
    interpolation view: ``scene_weights``, ``delta_at``, ``need``, ``contacts``, ``centres``, ``e_lo``,
    ``e_hi``), ``phi``, ``model``, ``width``, ``closed`` (the ideal bound is computed in closed form),
    ``iview`` / ``ikind`` (the ideal bound's view and array kind when read from a grid).
    """
    return _open(table, ideal_table, threshold=threshold, sensor=sensor, model=model,
                 spread=sensor_temp_spread_c)


def delta_e_ideal_view(opened, ideal_table: "Table | str | None" = DEFAULT_IDEAL_TABLE):
    """The view and kind delta-e reads its ideal bound from (a grid even where a closed form exists)."""
    if not opened.closed:
        return opened.iview, opened.ikind
    iview, ikind, _ = _ideal_view(opened.view, ideal_table)
    return iview, ikind
