"""The table route over numpy arrays: the one implementation of every table-route question.

Each question is computed for n elements at once (pairs ``lo < hi`` or references ``e`` with their scenes,
1-D arrays); a single question is element 0 of a one-element call (:mod:`designkit.query.table` builds its
:class:`~designkit.query.answer.Answer` from it, :mod:`designkit.query.vectorized` its
:class:`~designkit.query.vectorized.ArrayAnswer`). The table's interpolation (:mod:`designkit.tables.lookup`'s
rule) runs over all effusivities at once, once per distinct scene; the estimates and their intervals are
:mod:`designkit.query.estimates`' and :mod:`designkit.query.efficiency`'s.

min-contact's and max-noise / min-delta-t's estimators are small named strategies
(:data:`~designkit.query.estimates.CONTACT_ESTIMATORS`, :data:`~designkit.query.estimates.RATIO_ESTIMATORS`):
each says where it applies, and per element the first that applies answers.
Results are dicts of arrays, NaN for "none"; ``kind`` holds each element's interval kind and ``stated``
whether its interval states the asked coverage.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..sensor import within_sample_limit
from ..tables.store import Table
from .crossing import coverage_of_z
from .efficiency import (CLOSED_FORM_MAX_CONTACT_S, CriticalNoiseGrid, delta_efficiency_estimate, delta_entries,
                         interp_e_by, k_baseline, mc_calibration, noise_k_min_contact, table_z)
from .ideal_bound import contact_at_noise, exact_ideal_delta, exact_ideal_max_ratio
from .estimates import (ABOVE, BELOW, CELL, CONTACT_ESTIMATORS, INSIDE, RATIO_ESTIMATORS,
                        ContactReading, RatioReading, axis_weights_flagged, delta_estimate, filled, first_applicable,
                        grid_crossing, nans, partner_in_grid, states_coverage, table_spread)

__all__ = ["CLOSED_FORM_RATIO_BRACKET", "TableView", "at_contact", "contact_arrays", "delta_e_arrays",
           "distinguishable_arrays", "groups", "max_ratio", "ratio_arrays", "scene_groups"]

#: sigma/dT the closed-form ideal bound searches (the exact route's bracket).
CLOSED_FORM_RATIO_BRACKET = (1e-5, 1.0)

# ============================================================ the table, read over arrays
class TableView:
    """One table's axes and its interpolation (:mod:`designkit.tables.lookup`'s rule) over arrays, and the
    table's memo of what no question changes: kept with the loaded table
    (:func:`~designkit.query.table_open.open_table`), so it is computed once per process and table."""

    def __init__(self, table: Table):
        self.t = table
        ax = table.axes
        self.centres = ax["e_ref"]
        self.contacts = ax["contact_s"]
        self.scene_axes = [n for n in table.axis_names if n not in ("contact_s", "e_ref")]
        self.e_lo = float(table.header["effusivity"]["min"])
        self.e_hi = float(table.header["effusivity"]["max"])
        self._noise_grid: CriticalNoiseGrid | None = None
        self._sensor_dict: dict | None = None
        self._mc_factor: float | None = None
        self._contact_norms: np.ndarray | None = None
        self._baselines: np.ndarray | None = None
        self._scenes: dict[tuple[float, float], tuple[list, dict[str, bool]]] = {}
        # the entries' arrays as one plain array (_plain), and what questions read again for each pair (memo)
        self._names = {n: i for i, n in enumerate(n for n in table.arrays if n.startswith("delta_"))}
        self._plain_rows: np.ndarray | None = None
        self._plain_read: set[int] = set()
        self._memo: dict[tuple, Any] = {}

    def critical_noise(self, lo, hi) -> np.ndarray:
        """The ideal observer's critical noise of the table's classes ``[lo, lo + w)``, ``[hi, hi + w)`` (its
        sensor, width and threshold), elementwise, read off the table's
        :class:`~designkit.query.efficiency.CriticalNoiseGrid` (filled on demand, kept with the table)."""
        if self._noise_grid is None:
            self._noise_grid = CriticalNoiseGrid(self.t.sensor, float(self.t.header["effusivity"]["width"]),
                                                 self.t.threshold, self.e_hi)
        return self._noise_grid(lo, hi)

    def baselines(self) -> np.ndarray:
        """:func:`~designkit.query.efficiency.k_baseline` of each tabulated contact index, computed once."""
        if self._baselines is None:
            self._baselines = k_baseline(self.contacts, np.arange(self.contacts.size))
        return self._baselines

    def contact_norms(self) -> np.ndarray:
        """``|g|`` (:func:`~designkit.recognition.ideal.shape_norm`) of the table's sensor at each tabulated
        contact time, computed once."""
        if self._contact_norms is None:
            from ..recognition.ideal import shape_norm

            self._contact_norms = shape_norm(self.t.sensor, self.contacts)
        return self._contact_norms

    def sensor_dict(self) -> dict:
        """The table's ``sensor.to_dict()``, computed once (each caller gets its own top-level dict)."""
        if self._sensor_dict is None:
            self._sensor_dict = self.t.sensor.to_dict()
        return dict(self._sensor_dict)

    def scene_weights(self, noise_c: float, delta_t_c: float) -> tuple[list[tuple[tuple[int, ...], float]], dict[str, bool]]:
        """Multilinear weights over the scene axes; in-grid flags per axis (the caller's own dict). Kept per
        scene (a table's weights of a scene never change; a question reads them more than once)."""
        key = (noise_c, delta_t_c)
        if key not in self._scenes:
            if len(self._scenes) >= 256:  # (a sweep over scenes: the memo stays small)
                self._scenes.clear()
            self._scenes[key] = self._scene_weights(noise_c, delta_t_c)
        combos, flags = self._scenes[key]
        return combos, dict(flags)

    def _scene_weights(self, noise_c: float, delta_t_c: float):
        ax = self.t.axes
        coords: list[list[tuple[int, float]]] = []
        flags: dict[str, bool] = {}
        if self.scene_axes == ["noise_ratio"]:
            wanted = {"noise_ratio": noise_c / abs(delta_t_c)}
        else:
            wanted = {"noise_c": noise_c, "delta_t_c": delta_t_c}
        for name in self.scene_axes:
            scale = next(a["scale"] for a in self.t.header["axes"] if a["name"] == name)
            pts, ok = axis_weights_flagged(ax[name], wanted[name], log=scale == "log")
            coords.append(pts)
            flags[name] = ok
        combos = [((), 1.0)]
        for pts in coords:
            combos = [(idx + (k,), w * wk) for idx, w in combos for k, wk in pts]
        return combos, flags

    def memo(self, key: tuple, make):
        """``make()``, kept with the view under ``key`` (what every pair of a scene reads again); at most 256."""
        hit = self._memo.get(key)
        if hit is None:
            if len(self._memo) >= 256:
                self._memo.clear()
            hit = self._memo[key] = make()
        return hit

    def mc_calibration(self) -> float:
        """:func:`designkit.query.efficiency.mc_calibration` of this table (computed once)."""
        if self._mc_factor is None:
            self._mc_factor = mc_calibration(self.t)
        return self._mc_factor

    def e_in_grid(self, *es: float) -> bool:
        return all(self.e_lo < e <= self.e_hi for e in es)

    def e_in(self, e: np.ndarray) -> np.ndarray:
        """:meth:`e_in_grid` elementwise."""
        return (self.e_lo < e) & (e <= self.e_hi)

    def delta(self, names, combos, e: np.ndarray) -> np.ndarray:
        """The arrays ``names`` (one name, or a sequence) at scene weights ``combos``, every contact and every
        ``e``: [contact, len(e)], or [len(names), contact, len(e)] for a sequence (NaN: none), all the weighted
        scene slices of all the arrays in one reading."""
        many = not isinstance(names, str)
        out = _weighted(combos, self._read((tuple(names) if many else (names,),), combos, e[None])[0])
        return out if many else out[0]

    def _read(self, names: tuple[tuple[str, ...], ...], combos, e: np.ndarray) -> np.ndarray:
        """Groups of arrays, ``names[g]`` each at its own effusivities ``e[g]`` (``e``: [group, n]), in each
        weighted scene slice of ``combos`` (in their order), at every contact: [group, name, slice, contact, n]
        (NaN: none), in one interpolation (two gathers of the view's plain copy of the table, :meth:`_plain`)."""
        live = tuple(idx for idx, w in combos if w != 0)

        def index():  # the flat index of every entry [group, name, slice, contact, 1] at the first effusivity
            self._plain({k[0] for k in live})  # centre (each row read once), and the flat copy it indexes
            step = np.array(self._plain_rows.strides) // self._plain_rows.itemsize  # (C order: the last is 1)
            at = ((np.array([[self._names[n] for n in group] for group in names]) * step[0])[:, :, None, None, None]
                  + sum(np.array(k)[None, None, :, None, None] * st for k, st in zip(zip(*live), step[1:-2]))
                  + (np.arange(self.contacts.size) * step[-2])[None, None, None, :, None])
            return at, self._plain_rows.reshape(-1)
        at, flat = self.memo(("read", names, live), index)
        return interp_e_by(lambda c: flat[at + c], self.centres, e[:, None, None, None, :])

    def _plain(self, first: set[int]) -> None:
        """Read the scene rows ``first`` (on the first scene axis) of every ``delta_*`` array into the view's plain
        copy [array, scene..., contact, e_ref] through the table's (checked) reader, once per process and row."""
        if not (todo := sorted(first - self._plain_read)):
            return
        if self._plain_rows is None:  # (memory taken as rows are read)
            self._plain_rows = np.empty((len(self._names),) + tuple(self.t.arrays[next(iter(self._names))].shape))
        for name, i in self._names.items():
            for r in todo:
                self._plain_rows[i, r] = self.t.arrays[name][r]
        self._plain_read.update(todo)

    def readings(self, kinds, combos, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """What :meth:`need` of the sequence ``kinds`` is made of: ``delta_up`` at ``lo`` and ``delta_down`` at
        ``hi`` of each kind in each weighted scene slice, [direction (up, down), kind, slice, contact, n]."""
        def arrays():  # each kind's arrays, upwards and downwards (ideal tables carry only delta_up / delta_down)
            x = [s if f"delta_up{s}" in self.t.arrays else "" for s in (
                {"svm": "", "lo": "_lo", "hi": "_hi", "ideal": "_ideal"}[k] for k in kinds)]
            return tuple(f"delta_up{s}" for s in x), tuple(f"delta_down{s}" for s in x)
        return self._read(self.memo(("arrays", tuple(kinds)), arrays), combos, np.array([lo, hi]))

    def need(self, kind, combos, lo: np.ndarray, hi: np.ndarray, readings=None) -> np.ndarray:
        """Distance needed to separate ``lo < hi``, ``max(delta_up(lo), delta_down(hi))``, at every contact and
        pair: [contact, n] (NaN: not within the grid). ``kind``: svm, lo, hi (the Monte Carlo ends), ideal; or a
        sequence of them: [kind, contact, n], in one reading (``readings``: :meth:`readings` of them, read
        already)."""
        many = not isinstance(kind, str)
        up, down = _weighted(combos, readings if readings is not None else
                             self.readings(kind if many else [kind], combos, lo, hi))  # (both directions at once)
        out = np.maximum(up, down)  # (NaN where either is: maximum propagates it)
        return out if many else out[0]


def _weighted(combos, per_slice: np.ndarray) -> np.ndarray:
    """The weighted sum over the scene slices (the third axis from the end: [..., slice, contact, n]) of
    ``per_slice`` (NaN where any weighted slice is NaN; summed in the slices' order)."""
    w = np.array([w for _, w in combos if w != 0])
    return np.add.reduce(w[:, None, None] * per_slice, axis=-3)


def at_contact(cw, per_contact: np.ndarray) -> np.ndarray:
    """Contact-weighted sum of ``per_contact`` [contact, n] (NaN if a weighted term is NaN)."""
    total = np.zeros(per_contact.shape[1])
    bad = np.zeros(total.shape, dtype=bool)
    for k, w in cw:
        if w == 0:
            continue
        bad |= np.isnan(per_contact[k])
        total = total + w * per_contact[k]
    return np.where(bad, np.nan, total)


def groups(*columns: np.ndarray):
    """Indices of the elements sharing each distinct combination of ``columns`` (1-D, equal length)."""
    if columns[0].size == 1:  # a single question: one group
        yield tuple(float(c[0]) for c in columns), np.zeros(1, dtype=np.int64)
        return
    stacked = np.stack(columns, axis=1)
    uniq, inverse = np.unique(stacked, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    order = np.argsort(inverse, kind="stable")
    bounds = np.searchsorted(inverse[order], np.arange(len(uniq) + 1))
    for g, row in enumerate(uniq):
        yield tuple(float(v) for v in row), order[bounds[g]:bounds[g + 1]]


def scene_groups(view, contact, noise, dt, e_in):
    """The in-grid groups of elements sharing a scene (contact [s], noise, dT [degC]): per group its scene, the
    indices of its elements whose effusivities lie inside the grid (``e_in``), its scene weights and its contact
    weights; groups outside the grid on a scene axis or the contact axis, or with no element inside it, left
    out."""
    for scene, idx in groups(contact, noise, dt):
        c, nz, d = scene
        combos, flags = view.scene_weights(nz, d)
        cw, c_ok = axis_weights_flagged(view.contacts, c)
        idx = idx[e_in[idx]]
        if all(flags.values()) and c_ok and idx.size:
            yield scene, idx, combos, cw


def _boxes(op, lo, hi, classes, i):
    """The classes of element ``i``: those given, or ``[lo, lo + w)``, ``[hi, hi + w)``."""
    from ..objects import ObjectClass

    if classes is not None:
        return classes[i]
    return ObjectClass("a", (lo[i], lo[i] + op.width)), ObjectClass("b", (hi[i], hi[i] + op.width))


# ============================================================ min-contact
def contact_arrays(op, lo, hi, noise, dt, *, ideal_bound: bool, zc: float, classes=None,
                   outside: bool = True) -> dict[str, Any]:
    """min-contact [s] of pairs ``lo < hi`` at noise ``noise`` and dT ``dt`` [degC] (1-D arrays).

    ``ideal_bound``: the closed-form bound (every element with ``outside``, else only inside the grid), or the
    Monte Carlo one where no closed form holds (``classes``: each element's two classes for it; default
    ``[e, e + w)``); False: none on a closed-form table, the table's own floor elsewhere.

    Returns
    -------
    dict
        ``value``, ``low``, ``high``, ``ideal``, ``floor``, ``in_grid``, ``kind``, ``stated``, the table's
        crossing ``raw`` and its Monte Carlo ends ``mc_lo`` / ``mc_hi``, ``table_ideal`` (the grid's ideal
        observer), the estimators' ``interp`` / ``rounding`` / ``eff_*`` readings, ``mc_bounds`` (element ->
        Monte Carlo bound).
    """
    view, n = op.view, lo.size
    grid, svm = view.contacts, op.tab.fidelity == "svm"
    res: dict[str, Any] = dict(zip(("raw", "n_prev", "n_at", "mc_lo", "mc_hi", "ideal", "table_ideal"), nans((7, n))))
    res["k_cross"], res["in_grid"], res["mc_bounds"] = filled(n, -1), np.zeros(n, dtype=bool), {}
    efficiency = svm and op.closed and "delta_up_ideal" in view.t.arrays
    eff = dict(zip(("value", "low", "high", "k", "se_log", "k_a", "k_b", "t_a", "t_b"), nans((9, n)))) if efficiency else None
    e_in = view.e_in(lo) & view.e_in(hi)
    # the pairs' own critical noises (the efficiency route's target, the closed-form bound): read with the
    # efficiency route's entries where it reads them (one call of the grid), the others' after the loop
    star, have_star = nans(n), np.zeros(n, dtype=bool)
    slices = []
    for (nz, d), idx in groups(noise, dt):
        combos, flags = view.scene_weights(nz, d)
        idx = idx[e_in[idx]]
        if not (all(flags.values()) and idx.size):
            continue
        l, h = lo[idx], hi[idx]
        gap = h - l
        # every need in one reading, every crossing in one: svm, its Monte Carlo ends, the grid's own bound
        kinds = ["svm"] + (["lo", "hi"] if svm else []) + (["ideal"] if "delta_up_ideal" in view.t.arrays else [])
        readings = view.readings(kinds, combos, l, h)  # the efficiency route reads its entries from them
        need = view.need(kinds, combos, l, h, readings)  # [kind, contact, pair]
        m = l.size
        value, k, _, _, n0, n1 = grid_crossing(grid, need.transpose(1, 0, 2).reshape(grid.size, -1),
                                               np.concatenate([gap] * len(kinds)))
        cross = dict(zip(kinds, value.reshape(len(kinds), m)))
        k, n0, n1 = k[:m], n0[:m], n1[:m]
        at = slice(None) if m == n else idx  # (every element in this group: slices, not index arrays)
        res["raw"][at], res["k_cross"][at] = cross["svm"], k
        res["n_prev"][at], res["n_at"][at] = np.where(k > 0, n0, np.nan), n1
        for end in ("lo", "hi"):
            res[f"mc_{end}"][at] = cross.get(end, cross["svm"])
        if "ideal" in cross:  # the grid's own bound, beside the exact one
            res["table_ideal"][at] = cross["ideal"]
        if not op.closed and not ideal_bound and op.iview is not None:  # the table's own floor (no Monte Carlo)
            icombos, iflags = op.iview.scene_weights(nz, d)
            if all(iflags.values()):
                res["ideal"][idx] = grid_crossing(op.iview.contacts, op.iview.need(op.ikind, icombos, l, h), gap)[0]
        if efficiency and (n_has := np.count_nonzero(has := k >= 0)):  # (count_nonzero: any / all at a tenth
            every = n_has == has.size  # of ndarray.any's cost on a single question's arrays)
            sel = slice(None) if every else has  # (every pair: the readings themselves, no copy)
            r = noise_k_min_contact(op, combos, k[sel], l[sel], h[sel], nz / abs(d), zc=zc,
                                    readings=readings[:, :3][..., sel])
            hat = at if every else idx[has]
            for key in eff:
                eff[key][hat] = r[key]
            star[hat], have_star[hat] = r["s_pair"], True
        res["in_grid"][at] = True
        slices.append((combos, idx))
    sel = slice(None) if outside else res["in_grid"]  # (every element: a slice)
    if op.closed and ideal_bound and (n > 0 if outside else np.count_nonzero(sel)):  # outside the grid: no table
        if np.count_nonzero(rest := ~have_star if outside else sel & ~have_star):
            star[rest] = view.critical_noise(lo[rest], hi[rest])
        res["ideal"][sel] = contact_at_noise(op.tab.sensor, (noise / np.abs(dt))[sel], star[sel],
                                             CLOSED_FORM_MAX_CONTACT_S)
    res["floor"] = res["ideal"].copy()
    if not op.closed and ideal_bound:  # no closed form: Monte Carlo at query time, one per element
        from .ideal_mc_bound import mc_ideal_min_contact, remembered

        for i in np.nonzero(res["in_grid"])[0].tolist():
            mcb = remembered(
                mc_ideal_min_contact, *_boxes(op, lo, hi, classes, i), op.tab.sensor, noise_c=float(noise[i]), delta_t_c=float(dt[i]),
                sensor_temp_spread_c=table_spread(op.tab), model=op.model, threshold=op.phi,
                max_contact_s=CLOSED_FORM_MAX_CONTACT_S, coverage=coverage_of_z(zc))
            res["mc_bounds"][i] = mcb
            res["ideal"][i] = np.nan if mcb.value is None else mcb.value
            res["floor"][i] = np.nan if mcb.value is None else mcb.floor
    rd = ContactReading(op, lo, hi, res["raw"], res["k_cross"], res["n_prev"], res["n_at"], res["mc_lo"],
                        res["mc_hi"], res["ideal"], res["floor"], eff, slices, zc)
    res.update(first_applicable(CONTACT_ESTIMATORS, rd, n))
    return res


# ============================================================ max-noise / min-delta-t
def max_ratio(view, kind: str, cw, lo, hi, *, gcw=None, shift: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Per pair: the largest sigma/dT that separates it, and where it lies (:data:`BELOW` ... :data:`CELL`),
    interpolated in log(ratio) between the rows around it; ``gcw`` (log contact weights): the alternative
    interpolant (log need, log-log in contact time); ``shift`` subtracted from every tabulated need."""
    ratios = view.t.axes["noise_ratio"]
    logs = np.array([math.log(r) for r in ratios.tolist()])
    gap = hi - lo
    margins = []
    with np.errstate(invalid="ignore", divide="ignore"):
        for i in range(ratios.size):
            per = view.need(kind, [((i,), 1.0)], lo, hi)
            if gcw is None:
                nd = at_contact(cw, per) - shift
                margins.append(np.where(np.isnan(nd), -np.inf, gap - nd))
                continue
            total = np.zeros(lo.size)
            bad = np.zeros(lo.size, dtype=bool)
            for k, w in gcw:
                if not w:
                    continue
                nk = per[k] - shift
                bad |= np.isnan(nk) | (nk <= 0)
                total = total + w * np.log(nk)
            margins.append(np.where(bad, -np.inf, np.log(gap) - np.log(np.exp(total))))
    m = np.array(margins)  # [ratio, n]
    ok = m >= 0
    r_n = ratios.size
    last = r_n - 1 - np.argmax(ok[::-1], axis=0)
    cols = np.arange(lo.size)
    nxt = np.minimum(last + 1, r_n - 1)
    m0, m1 = m[last, cols], m[nxt, cols]
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.where(m0 != m1, m0 / (m0 - m1), 0.0)
        inside = np.exp(logs[last] + w * (logs[nxt] - logs[last]))
    where = np.where(~ok[0], BELOW, np.where(last == r_n - 1, ABOVE, np.where(np.isfinite(m1), INSIDE, CELL)))
    r = np.where(where == BELOW, np.nan, np.where(where == INSIDE, inside, ratios[last]))
    return r, where


def ratio_arrays(question: str, op, lo, hi, contact, scale, *, ideal_bound: bool, zc: float) -> dict[str, Any]:
    """max-noise [degC] (``scale``: dT [degC]) or min-delta-t [degC] (``scale``: noise sigma [degC]) of pairs
    ``lo < hi`` at contacts ``contact`` [s] (1-D arrays).

    Returns
    -------
    dict
        ``value``, ``low``, ``high``, ``ideal``, ``in_grid``, ``kind``, ``stated``, the table's crossing ``r``
        (sigma/dT) and where it lies (``where``), the ratio answered (``ratio``), the Monte Carlo ends (sigma/dT,
        ``end_hi``, ``end_lo_any``: the optimistic one also where separable beyond the grid), the estimators'
        readings.
    """
    from .inputs import TableMismatch

    view, n = op.view, lo.size
    if "noise_ratio" not in op.tab.axes:
        raise TableMismatch(f"table {op.tab.name} has separate noise and temperature axes (varied initial "
                            f"conditions): it cannot answer {question}; the exact route can")
    svm = op.tab.fidelity == "svm"
    r_all, where_all, ri = nans(n), np.full(n, -1), nans(n)
    ends = {k: nans(n) for k in ("hi", "lo", "lo_any")}
    alt = {k: nans(n) for k in ("c", "lin", "rnd", "geo")}  # the rounding estimate's interpolants
    e_in = view.e_in(lo) & view.e_in(hi)
    for (c,), idx in groups(contact):
        cw, c_ok = axis_weights_flagged(view.contacts, c)
        idx = idx[e_in[idx]]
        if not (c_ok and idx.size):
            continue
        l, h = lo[idx], hi[idx]
        out = {"svm": max_ratio(view, "svm", cw, l, h)}
        for kind in ("lo", "hi"):
            out[kind] = max_ratio(view, kind, cw, l, h) if svm else out["svm"]
        if not op.closed and op.iview is not None:
            icw, _ = axis_weights_flagged(op.iview.contacts, c)
            r_i, w_i = max_ratio(op.iview, op.ikind, icw, l, h)
            ri[idx] = np.where(w_i == BELOW, np.nan, r_i)
        r, where = out["svm"]
        r_all[idx], where_all[idx] = r, where
        ends["hi"][idx] = np.where(out["hi"][1] == BELOW, np.nan, out["hi"][0])
        ends["lo_any"][idx] = np.where(out["lo"][1] == BELOW, np.nan, out["lo"][0])
        # the optimistic end is open where it is separable beyond the grid
        ends["lo"][idx] = np.where(out["lo"][1] == ABOVE, np.nan, ends["lo_any"][idx])
        est = where == INSIDE
        if svm and est.any():
            gcw = axis_weights_flagged(view.contacts, c, log=True)[0]
            j, w = idx[est], op.width
            for key, kw in (("c", dict(gcw=gcw, shift=0.5 * w)), ("lin", dict(shift=0.5 * w)),
                            ("rnd", dict(gcw=gcw, shift=0.5 * w + w / math.sqrt(12))), ("geo", dict(gcw=gcw))):
                a_r, a_w = max_ratio(view, "svm", cw, l[est], h[est], **kw)
                alt[key][j] = np.where(a_w == INSIDE, a_r, np.nan)
    if op.closed and ideal_bound:  # every element, outside the grid too: the closed form needs no table
        ok = within_sample_limit(contact, op.tab.sensor.sample_rate_hz)
        if ok.any():
            ri[ok] = exact_ideal_max_ratio(op.tab.sensor, lo[ok], hi[ok], contact[ok], width=op.width,
                                           threshold=op.phi, bracket=CLOSED_FORM_RATIO_BRACKET)
    ri = np.where(np.isfinite(ri), ri, np.nan)
    rd = RatioReading(op, question, contact, lo, hi, r_all, where_all, ends["hi"], ends["lo"], ri, alt, scale, zc)
    res = first_applicable(RATIO_ESTIMATORS, rd, n)
    with np.errstate(invalid="ignore", divide="ignore"):
        res["ideal"] = rd.answer(ri)
    res.update(r=r_all, where=where_all, end_hi=ends["hi"], end_lo_any=ends["lo_any"], ri=ri,
               in_grid=(where_all >= 0) & (where_all != ABOVE))
    return res


# ============================================================ delta-e
def delta_at(e: np.ndarray, v, cmb, cws, name: str) -> np.ndarray:
    """Array ``name`` of view ``v`` at effusivities ``e``, scene weights ``cmb``, contact weights ``cws`` (NaN:
    none, or no such view or array)."""
    if v is None or name not in v.t.arrays:
        return nans(e.size)
    return at_contact(cws, v.delta(name, cmb, e))


def delta_geometric(e: np.ndarray, v, cmb, cws, name: str) -> np.ndarray:
    """As :func:`delta_at`, log delta interpolated (weights in log contact, log sigma/dT)."""
    total = np.zeros(e.size)
    bad = np.zeros(e.size, dtype=bool)
    with np.errstate(invalid="ignore", divide="ignore"):
        for k, w in cws:
            if w == 0:
                continue
            for i, wi in cmb:
                if not wi:
                    continue
                y = interp_e_by(lambda c, rows=v.t.arrays[name][i][k:k + 1]: rows[..., c], v.centres, e)[0]
                bad |= np.isnan(y) | (y <= 0)
                total = total + w * wi * np.log(y)
        return np.where(bad, np.nan, np.exp(total))


def delta_e_arrays(op, e, contact, noise, dt, *, ideal_view, zc: float, ideal_bound: bool = True,
                   classes=None) -> dict[str, Any]:
    """delta(e) [J s^-1/2 K^-1 m^-2] towards lower and higher effusivity from references ``e`` at the scenes
    ``contact`` [s], ``noise``, ``dt`` [degC] (1-D arrays); ``ideal_view``: the (view, kind) its grid ideal bound
    is read from (:func:`designkit.query.table_open.delta_e_ideal_view`).

    Per side (``lower``, ``upper``): the value, ``{side}_ideal``, its interval ``{side}_low`` / ``{side}_high``,
    ``{side}_method`` (table-efficiency, table-estimate, none), the table's own reading ``{side}_table`` and its
    Monte Carlo ends ``{side}_mc_lo`` / ``{side}_mc_hi``, the grid's ideal ``{side}_table_ideal``, the efficiency
    ``{side}_efficiency`` and the Monte Carlo bounds ``{side}_mc_bounds`` (element -> bound). ``value``,
    ``low``, ``high``, ``ideal``: the nearer side's; ``kind``, ``stated``, ``in_grid``.
    """
    n, view = e.size, op.view
    svm = op.tab.fidelity == "svm"
    res: dict[str, Any] = {}
    for side in ("lower", "upper"):
        for k in ("", "_ideal", "_low", "_high", "_table", "_mc_lo", "_mc_hi", "_table_ideal", "_efficiency"):
            res[side + k] = nans(n)
        res[f"{side}_method"], res[f"{side}_mc_bounds"] = np.full(n, "none", dtype=object), {}
    res["in_grid"] = np.zeros(n, dtype=bool)
    e_in = view.e_in(e)
    iview, ikind = ideal_view
    efficiency = svm and op.closed and "delta_up_ideal" in view.t.arrays
    for (c, nz, d), idx, combos, cw in scene_groups(view, contact, noise, dt, e_in):
        xe = e[idx]
        icombos = iview.scene_weights(nz, d)[0] if iview is not None else []
        icw = axis_weights_flagged(iview.contacts, c)[0] if iview is not None else []
        gcw = axis_weights_flagged(view.contacts, c, log=True)[0]
        ends = (cw[0][0], cw[-1][0])  # the tabulated contacts around the asked one (the same where it is on one)
        for direction, side in (("down", "lower"), ("up", "upper")):
            val = delta_at(xe, view, combos, cw, f"delta_{direction}")
            mc_lo = delta_at(xe, view, combos, cw, f"delta_{direction}_lo") if svm else val
            mc_hi = delta_at(xe, view, combos, cw, f"delta_{direction}_hi") if svm else val
            ideal = floor = table_ideal = delta_at(xe, iview, icombos, icw,
                                                   f"delta_{direction}_ideal" if ikind == "ideal" else f"delta_{direction}")
            if not op.closed and ideal_bound:  # no closed form: Monte Carlo at query time, one per element
                ideal, floor = _mc_delta_bounds(op, e, classes, idx, direction, c, nz, d, zc,
                                                res[f"{side}_mc_bounds"])
            method = np.full(idx.size, "table-estimate" if svm else "none", dtype=object)
            low = high = nans(idx.size)
            if svm:
                low, high = delta_estimate(val, mc_lo, mc_hi, delta_geometric(xe, view, combos, gcw,
                                                                              f"delta_{direction}"),
                                           floor, width=op.width, z_table=table_z(op.tab), zc=zc)
            value, eff = val, nans(idx.size)
            if efficiency:  # the SVM's efficiency against the exact ideal observer, where it applies
                r = delta_efficiency_estimate(
                    op.tab.sensor, xe, c, nz / abs(d), -1.0 if direction == "down" else 1.0, view.contacts[ends[0]],
                    view.contacts[ends[1]], *delta_entries(view, combos, ends, direction, xe), width=op.width,
                    threshold=op.phi, e_max=view.e_hi, z_table=table_z(op.tab), zc=zc,
                    mc_factor=view.mc_calibration())
                # where the tabulated value is none (beyond the grid at one of the two contacts), the estimate
                # from the other contact, when its partner lies inside the range
                by_eff = ~np.isnan(r["value"]) & (~np.isnan(val) | partner_in_grid(view, xe, r["value"], direction))
                value, ideal = np.where(by_eff, r["value"], val), np.where(by_eff, r["ideal"], ideal)
                low, high = np.where(by_eff, r["low"], low), np.where(by_eff, r["high"], high)
                eff = np.where(by_eff, r["efficiency"], np.nan)
                method = np.where(by_eff, "table-efficiency", method)
            none = np.isnan(value)
            method = np.where(none, "none", method)
            for k, v in (("", value), ("_ideal", ideal), ("_low", np.where(none, np.nan, low)),
                         ("_high", np.where(none, np.nan, high)), ("_table", val), ("_mc_lo", mc_lo),
                         ("_mc_hi", mc_hi), ("_table_ideal", table_ideal), ("_efficiency", eff), ("_method", method)):
                res[side + k][idx] = v
        res["in_grid"][idx] = True
    # the scene outside the grid, the reference inside its range, the touch within the sample limit: the closed
    # form needs no table
    out = np.nonzero(~res["in_grid"] & e_in & within_sample_limit(contact, op.tab.sensor.sample_rate_hz))[0]
    if op.closed and ideal_bound and out.size:
        ratio = noise[out] / np.abs(dt[out])
        for side, sign in (("lower", -1.0), ("upper", 1.0)):
            res[f"{side}_ideal"][out] = exact_ideal_delta(op.tab.sensor, e[out], contact[out], ratio,
                                                          direction=np.full(out.size, sign), width=op.width,
                                                          threshold=op.phi, e_max=view.e_hi)
    res["value"] = np.fmin(res["lower"], res["upper"])
    res["ideal"] = np.fmin(res["lower_ideal"], res["upper_ideal"])
    # the interval and kind of the direction giving the value (the lower one on a tie)
    lower = ~np.isnan(res["lower"]) & (np.isnan(res["upper"]) | (res["lower"] <= res["upper"]))
    for k in ("low", "high", "method"):
        res["kind" if k == "method" else k] = np.where(lower, res[f"lower_{k}"], res[f"upper_{k}"])
    res["stated"] = (res["kind"] != "none") & states_coverage(op.tab, "delta-e", "table-estimate")
    return res


def _mc_delta_bounds(op, e, classes, idx, direction: str, contact: float, noise: float, dt: float, zc: float,
                     store: dict) -> tuple[np.ndarray, np.ndarray]:
    """Per reference ``e[idx]``: the Monte Carlo ideal delta(e) of one direction and the low end of its
    interval (NaN: none), each bound kept in ``store`` (element -> bound)."""
    from ..objects import ObjectClass
    from .ideal_mc_bound import mc_ideal_delta, remembered

    value, floor = nans(idx.size), nans(idx.size)
    for j, i in enumerate(idx.tolist()):
        ref = classes[i] if classes is not None else ObjectClass("r", (e[i], e[i] + op.width))
        mcb = remembered(mc_ideal_delta, ref, 1 if direction == "up" else -1, op.tab.sensor, contact_s=contact,
                         noise_c=noise, delta_t_c=dt, sensor_temp_spread_c=table_spread(op.tab), model=op.model,
                         threshold=op.phi, coverage=coverage_of_z(zc))
        store[i] = mcb
        if mcb.value is not None:
            value[j], floor[j] = mcb.value, mcb.floor
    return value, floor


# ============================================================ distinguishable
def distinguishable_arrays(op, lo, hi, contact, noise, dt, *, ideal_bound: bool, zc: float, ideal_view,
                           classes=None) -> dict[str, Any]:
    """Whether ``contact`` [s] separates pairs ``lo < hi`` at ``noise``, ``dt`` [degC] (1-D arrays): 1.0 / 0.0 /
    NaN (outside the grid).

    The contact against min-contact's answer for the pair at its noise and dT (:func:`contact_arrays`, its
    interval held to the closed-form bound where there is one, else to the table's floor); where the contact
    lies inside that interval (``unsure``), a max-noise or delta-e answer sure of it decides (``decided``: by
    which, both sure and disagreeing: unchanged). Also ``verdict`` (confident / uncertain / None), the grid's own
    verdicts ``grid_svm`` / ``grid_lo`` / ``grid_hi`` (the need interpolated at the contact against the pair's
    distance), min-contact's ``mc_*`` and the readings of the others (``mn_*``, ``de_*``), ``ideal`` (the ideal
    F1) and ``ideal_method``.
    """
    n, view = lo.size, op.view
    svm = op.tab.fidelity == "svm"
    res: dict[str, Any] = {k: nans(n) for k in ("grid_svm", "grid_lo", "grid_hi", "ideal")}
    res["in_grid"], res["ideal_method"] = np.zeros(n, dtype=bool), np.full(n, "none", dtype=object)
    e_in = view.e_in(lo) & view.e_in(hi)
    for _, idx, combos, cw in scene_groups(view, contact, noise, dt, e_in):
        res["in_grid"][idx] = True
        l, h = lo[idx], hi[idx]
        for kind in (("svm", "lo", "hi") if svm else ("svm",)):
            nd = at_contact(cw, view.need(kind, combos, l, h))
            res[f"grid_{kind}"][idx] = (nd <= h - l).astype(np.float64)  # (False at NaN)
    if not svm:
        res["grid_lo"] = res["grid_hi"] = res["grid_svm"]
    todo = res["in_grid"]
    mc = contact_arrays(op, lo, hi, noise, dt, ideal_bound=op.closed, zc=zc, outside=False)
    t, a, b, stated = mc["value"], mc["low"], mc["high"], mc["stated"]
    with np.errstate(invalid="ignore"):
        yes = contact >= t  # (False at NaN)
        below_high = (contact <= b) | np.isnan(b)
        unsure = todo & ~np.isnan(t) & ~np.isnan(a) & below_high & np.where(stated, a <= contact, a < contact)
    verdict = np.where(~todo | np.isnan(t), None, np.where(unsure, "uncertain", np.where(stated & ~np.isnan(a),
                                                                                          "confident", None)))
    res["decided"] = np.zeros(n, dtype=bool)
    if unsure.any():
        yes, decided = _others_decide(op, lo, hi, contact, noise, dt, np.nonzero(unsure)[0], yes, zc, ideal_view, res)
        res["decided"] = decided
        verdict = np.where(decided, "confident", verdict)
    res["value"] = np.where(todo, yes.astype(np.float64), np.nan)
    res["verdict"], res["unsure"] = verdict, unsure
    for key in ("value", "low", "high", "kind", "stated"):
        res[f"mc_{key}"] = np.where(todo, mc[key], np.nan if key in ("value", "low", "high") else mc[key])
    res["kind"], res["stated"] = np.full(n, "none", dtype=object), np.zeros(n, dtype=bool)
    res["low"] = res["high"] = nans(n)
    if ideal_bound:
        _ideal_f1(op, lo, hi, contact, noise, dt, classes, res)
    return res


def _ideal_f1(op, lo, hi, contact, noise, dt, classes, res) -> None:
    """The ideal observer's F1 of each pair: the closed form where there is one (within the sample limit, inside
    the grid or outside it), else its Monte Carlo estimate inside the grid."""
    if op.closed:
        from ..recognition.ideal import ideal_f1, shape_norm

        ok = within_sample_limit(contact, op.tab.sensor.sample_rate_hz)
        if not ok.any():
            return
        norm = shape_norm(op.tab.sensor, contact[ok])
        with np.errstate(divide="ignore", invalid="ignore"):  # no signal yet (norm 0): s infinite
            s = np.where(norm > 0, (noise[ok] / np.abs(dt[ok])) / norm, np.inf)
        res["ideal"][ok] = ideal_f1(lo[ok], hi[ok], op.width, op.tab.sensor.effusivity, s)
        res["ideal_method"][ok] = "closed-form"
        return
    from ..recognition.ideal import ideal_pair
    from ..scene import Scene

    for i in np.nonzero(res["in_grid"])[0].tolist():
        scene = Scene.from_delta_t(contact_s=float(contact[i]), noise_c=float(noise[i]), delta_t_c=float(dt[i]),
                                   sensor_temp_spread_c=table_spread(op.tab))
        r = ideal_pair(*_boxes(op, lo, hi, classes, i), op.tab.sensor, scene, model=op.model)
        res["ideal"][i], res["ideal_method"][i] = r.f1, r.method


def _others_decide(op, lo, hi, contact, noise, dt, i: np.ndarray, yes: np.ndarray, zc: float, ideal_view, res):
    """``yes`` where max-noise (the asked noise outside its stated interval) or delta-e (the pair's distance
    outside the interval of the need ``max(delta_up(lo), delta_down(hi))``) is sure, for elements ``i`` whose
    contact lies inside min-contact's interval; both sure and disagreeing: unchanged. Their readings are kept in
    ``res`` (``mn_*``, ``de_up_*`` at ``lo``, ``de_down_*`` at ``hi``)."""
    n, size = i.size, lo.size
    nz, d, c, l, h = noise[i], dt[i], contact[i], lo[i], hi[i]
    sure = {"max-noise": (np.zeros(n, dtype=bool), np.zeros(n, dtype=bool))}
    for k in ("mn_value", "mn_low", "mn_high", "de_upper_value", "de_upper_low", "de_upper_high", "de_lower_value",
              "de_lower_low", "de_lower_high"):
        res[k] = nans(size)
    if "noise_ratio" in op.tab.axes:
        mn = ratio_arrays("max-noise", op, l, h, c, np.abs(d), ideal_bound=True, zc=zc)
        mn_stated = mn["stated"] & ~np.isnan(mn["low"]) & ~np.isnan(mn["high"])
        for k in ("value", "low", "high"):
            res[f"mn_{k}"][i] = np.where(mn_stated, mn[k], np.nan)
        with np.errstate(invalid="ignore"):
            sure["max-noise"] = (mn_stated & ~((mn["low"] <= nz) & (nz <= mn["high"])), nz <= mn["value"])
    de = delta_e_arrays(op, np.concatenate([l, h]), np.tile(c, 2), np.tile(nz, 2), np.tile(d, 2),
                        ideal_view=ideal_view, zc=zc, ideal_bound=False)
    parts = []
    for side, sl in (("upper", slice(0, n)), ("lower", slice(n, 2 * n))):
        stated = de[f"{side}_method"][sl] != "none"
        part = [np.where(stated, de[f"{side}{k}"][sl], np.nan) for k in ("", "_low", "_high")]
        for k, v in zip(("value", "low", "high"), part):
            res[f"de_{side}_{k}"][i] = v
        parts.append(part)
    with np.errstate(invalid="ignore"):
        ok = np.all([np.isfinite(p) for part in parts for p in part], axis=0)
        value, low, high = (np.fmax(parts[0][k], parts[1][k]) for k in range(3))
        gap = h - l
        sure["delta-e"] = (ok & ~((low <= gap) & (gap <= high)), gap >= value)
    (o1, v1), (o2, v2) = sure["max-noise"], sure["delta-e"]
    decided = np.where(o1 & o2, np.where(v1 == v2, v1, yes[i]), np.where(o1, v1, np.where(o2, v2, yes[i])))
    out, by = yes.copy(), np.zeros(size, dtype=bool)
    out[i] = decided
    by[i] = (o1 | o2) & ~(o1 & o2 & (v1 != v2))
    return out, by
