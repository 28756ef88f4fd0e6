"""The design questions over numpy arrays: inputs broadcast like numpy, answers come as arrays.

Every numeric input of a question (``e1``, ``e2``, ``e``, ``contact_s``,
``noise_c``, ``delta_t_c``) may be a number or an array of any shape; they
broadcast together as numpy does, and the answer is one :class:`ArrayAnswer`
whose arrays have the broadcast shape, element ``i`` being what the scalar call
with the ``i``-th inputs answers (``None`` there is NaN here; ``distinguishable``
answers 1.0 / 0.0 / NaN). The question functions of :mod:`designkit.query`
send a call here when any numeric input is an array or a list.

Routes
------
* **table** with effusivities given as numbers: vectorized. The table's
  interpolation (:mod:`designkit.tables.lookup`'s rule, the same as the scalar
  route) runs over all effusivities at once, once per distinct scene (the
  scene values, or only the contact time for max-noise / min-delta-t, are
  grouped); the closed-form ideal bound is computed for the distinct
  elements in one vectorized call and kept in the per-process cache of
  :mod:`designkit.query.ideal_bound` (a Newton solve per distinct pair the
  first time, a dictionary look-up after). ``ideal_bound=False`` skips it
  (``ideal`` is then NaN, and the intervals are not held to it). The
  rounding-corrected estimates and their intervals at ``coverage`` are the
  table route's own functions over arrays (:func:`~designkit.query.table.contact_estimate`,
  :func:`~designkit.query.table.ratio_estimate`, :func:`~designkit.query.table.delta_estimate`),
  so element ``i`` equals the scalar call.
* **exact**, and objects given as material names: one scalar call per
  element (seconds each on the exact route), assembled into the same arrays.
  The names (``m``, ``m1``, ``m2``) may be lists too, broadcast with the numbers:
  ``min_contact(m1=["copper", "glass"], m2=["wood", "PVC"])`` answers two pairs.

Bad input names the offending element: ``effusivity e1[2] must be positive, got -5``.

Examples
--------
>>> import numpy as np
>>> from designkit.query import min_contact
>>> a = min_contact(35000, np.array([20000.0, 25000.0, 30000.0]), table="ideal-paper")
>>> a.shape, a.unit
((3,), 's')
>>> bool(np.all(a.value[:-1] < a.value[1:]))   # closer pairs need longer contact
True
>>> float(a.value[0]) == min_contact(35000, 20000, table="ideal-paper").value
True
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np
from numpy.typing import NDArray

from .._validation import InputError, check_effusivity, check_positive, check_temperature
from ..sensor import within_sample_limit
from . import table as _table_route
from .answer import Answer, QuestionQuantity
from .crossing import check_coverage, coverage_of_z, z_of_coverage

__all__ = ["ARRAY_INPUTS", "ArrayAnswer", "answer_arrays", "is_array_call"]

#: The numeric inputs of each question that may be arrays (they broadcast together).
ARRAY_INPUTS: dict[str, tuple[str, ...]] = {
    "min-contact": ("e1", "e2", "noise_c", "delta_t_c"),
    "max-noise": ("e1", "e2", "contact_s", "delta_t_c"),
    "min-delta-t": ("e1", "e2", "contact_s", "noise_c"),
    "delta-e": ("e", "contact_s", "noise_c", "delta_t_c"),
    "distinguishable": ("e1", "e2", "contact_s", "noise_c", "delta_t_c"),
}
_DEFAULTS = {"noise_c": 0.05, "delta_t_c": 10.0}
#: The material-name inputs of each question that may be lists (they broadcast with the numeric ones).
NAME_INPUTS: dict[str, tuple[str, ...]] = {q: (("m",) if q == "delta-e" else ("m1", "m2")) for q in ARRAY_INPUTS}

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ArrayAnswer(QuestionQuantity):
    """Answers to one design question over arrays of inputs (all arrays share :attr:`shape`).

    Attributes
    ----------
    question : str
        As :attr:`designkit.query.Answer.question`.
    route : str
        ``"table"`` or ``"exact"``.
    quantity, unit : str
        What ``value`` measures and its unit (``contact_s`` / ``s`` ...).
    value : ndarray of float
        The SVM's answer per element; NaN where the scalar call answers None
        (``distinguishable``: 1.0 yes, 0.0 no, NaN no answer).
    low, high : ndarray of float
        The answer's interval per element (``Answer.interval``; NaN: None): at the
        call's ``coverage`` where the scalar answer states one, else the grid cell or
        a one-sided bound, as the scalar answer (``distinguishable``: NaN, no interval).
    coverage : ndarray of float
        The coverage each element's interval states (``Answer.interval_coverage``): the
        call's ``coverage`` where the scalar answer states one, NaN where it states none
        (a grid cell, a search bracket, a varied table's grid reading, no interval).
    ideal : ndarray of float
        The ideal observer's answer per element (``Answer.ideal_bound.value``;
        ``distinguishable``: the ideal F1); NaN: none, or not computed.
    in_grid : ndarray of bool
        Whether every table axis held the element's question (always True on the exact route).
    table : str or None
        Table read (None on the exact route).
    route_reason : str or None
        Why ``route`` answered (as :attr:`designkit.query.Answer.route_reason`).
    conditions : mapping or None
        A calibrated sensor's scene, each value with its source (as a single answer's ``scene["conditions"]``;
        a value given per element is an array): :func:`designkit.rig.for_rig`.
    details : mapping of str to ndarray
        Question-specific arrays: delta-e's ``lower`` / ``upper`` (each
        direction's value), ``lower_ideal`` / ``upper_ideal`` and (table route)
        each direction's interval ``lower_low`` / ``lower_high`` / ``upper_low`` /
        ``upper_high``; distinguishable's
        (table route, effusivities as numbers) ``min_contact_s`` and its interval
        ``min_contact_low`` / ``min_contact_high``, the min-contact answer the verdict
        compares the contact with (the low end not held to the ideal bound with
        ``ideal_bound=False``).
    """

    question: str
    route: str
    value: FloatArray
    low: FloatArray
    high: FloatArray
    coverage: FloatArray
    ideal: FloatArray
    in_grid: NDArray[np.bool_]
    table: str | None = None
    details: Mapping[str, FloatArray] = field(default_factory=dict)
    route_reason: str | None = None
    conditions: Mapping[str, Any] | None = None

    @property
    def shape(self) -> tuple[int, ...]:
        return self.value.shape

    @property
    def size(self) -> int:
        return int(self.value.size)

    def __len__(self) -> int:
        return len(self.value)

    def to_dict(self) -> list[dict[str, Any]]:
        """One record per element (C order), JSON-ready (None for NaN): ``pandas.DataFrame(a.to_dict())``
        reads it as is. The keys are those of a single answer's record (:func:`designkit.query.answer.to_record`:
        ``value``, ``interval_low``, ``interval_high``, ``interval_coverage``, ``bound``, ``ideal_value``,
        ``in_grid``, ``table_name`` ...), then ``details``' arrays under their own names; ``shape`` gives the
        arrays' shape (``np.reshape`` a column back)."""
        from .answer import bound_of

        def col(a):
            a = np.asarray(a, dtype=np.float64).ravel()
            return [float(x) if np.isfinite(x) else None for x in a]

        n = self.size
        cols = {"value": col(np.broadcast_to(self.value, self.shape)), "interval_low": col(self.low),
                "interval_high": col(self.high), "interval_coverage": col(self.coverage),
                "ideal_value": col(self.ideal)}
        cols.update({k: col(np.broadcast_to(v, self.shape)) for k, v in self.details.items()})
        in_grid = np.broadcast_to(self.in_grid, self.shape).ravel().tolist()
        fixed = {"question": self.question, "route": self.route, "route_reason": self.route_reason,
                 "quantity": self.quantity, "unit": self.unit}
        out = []
        for i in range(n):
            rec = dict(fixed)
            rec.update({k: v[i] for k, v in cols.items()})
            if self.question == "distinguishable":
                rec["value"] = None if rec["value"] is None else bool(rec["value"])
            numeric = rec["value"] is not None and not isinstance(rec["value"], bool)
            rec["bound"] = (bound_of(rec["interval_low"], rec["interval_high"]) or None) if numeric else None
            rec["in_grid"] = bool(in_grid[i])
            rec["table_name"] = self.table
            if self.conditions is not None:
                rec["conditions"] = {k: {**c, **{f: _element(c[f], self.shape, i) for f in ("value", "model_contact_s")
                                                 if f in c}} for k, c in self.conditions.items()}
            out.append(rec)
        return out


def _element(v: Any, shape: tuple[int, ...], i: int) -> Any:
    """Element ``i`` (C order) of a value given per element, as JSON (a scalar value is every element's)."""
    if v is None or np.ndim(v) == 0:
        return v
    x = float(np.broadcast_to(np.asarray(v, dtype=np.float64), shape).ravel()[i])
    return x if math.isfinite(x) else None


def _is_list(x: Any) -> bool:
    return x is not None and not isinstance(x, (str, bytes)) and np.ndim(x) >= 1


def is_array_call(question: str, arguments: Mapping[str, Any]) -> bool:
    """Whether any numeric input of ``question`` is an array (ndim >= 1) or a list/tuple, or any material name
    input (``m``, ``m1``, ``m2``) a list of names."""
    return any(_is_list(arguments.get(name)) for name in ARRAY_INPUTS.get(question, ()) + NAME_INPUTS.get(question, ()))


def _name_arrays(question: str, others: dict[str, Any]) -> dict[str, np.ndarray]:
    """The material-name inputs given as lists, popped from ``others``, as arrays of str (each element checked)."""
    out = {}
    for name in NAME_INPUTS.get(question, ()):
        if _is_list(others.get(name)):
            a = np.asarray(others.pop(name), dtype=object)
            for idx in np.ndindex(a.shape):
                if not isinstance(a[idx], str):
                    where = ", ".join(str(int(i)) for i in idx)
                    raise InputError(f"material names {name}[{where}] must be a name (str), got {a[idx]!r:.60}")
            out[name] = a
    return out


# ============================================================ input checks, naming the element
def _as_array(name: str, x: Any) -> np.ndarray:
    try:
        return np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be numbers (an array of floats), got {x!r:.60}") from None


def _first_bad(name: str, a: np.ndarray, fine: np.ndarray, check: Callable[[str, float], Any]) -> None:
    """Run the scalar check on every element outside ``fine`` (a conservative mask): the first bad raises."""
    if a.ndim == 0:  # a number beside a list of names
        if not fine:
            check(name, float(a))
        return
    for idx in zip(*np.nonzero(~fine)):
        where = ", ".join(str(int(i)) for i in idx)
        check(f"{name}[{where}]", float(a[idx]))


def _checked(question: str, inputs: dict[str, Any]) -> dict[str, np.ndarray]:
    """The numeric inputs as float64 arrays of one broadcast shape, each element checked as the scalar route does."""
    arrays = {n: _as_array(n, v) for n, v in inputs.items()}
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrays.values()))
    except ValueError:
        shapes = ", ".join(f"{n} {a.shape}" for n, a in arrays.items())
        raise InputError(f"the array inputs do not broadcast together: {shapes}") from None
    out = {n: np.broadcast_to(a, shape) for n, a in arrays.items()}
    for n, a in out.items():
        if n in ("e1", "e2", "e"):
            _first_bad(n, a, np.isfinite(a) & (a > 0), lambda k, v: check_effusivity(k, v))
        elif n == "contact_s":
            _first_bad(n, a, np.isfinite(a) & (a >= 1e-300),
                       lambda k, v: check_positive(f"contact time [s] {k}", v))
        elif n == "noise_c":
            _first_bad(n, a, np.isfinite(a) & (a >= 0) & (a <= 1e4),
                       lambda k, v: check_temperature(f"noise sigma [degC] {k}", v, nonnegative=True))
            if question == "min-delta-t":
                _first_bad(n, a, a != 0, lambda k, v: _raise(
                    f"{k}: noise sigma is 0: any temperature difference separates them (no smallest one)"))
        elif n == "delta_t_c":
            def dt_check(k, v):
                check_temperature(f"temperature difference [degC] {k}", v)
                if v == 0:
                    _raise(f"temperature difference {k} is 0: an unheated sensor sees no contrast between materials")
            _first_bad(n, a, np.isfinite(a) & (a != 0) & (np.abs(a) <= 1e4), dt_check)
    if "e1" in out and "e2" in out:
        _first_bad("e1", out["e1"], out["e1"] != out["e2"], lambda k, v: _raise(
            f"e1 and e2 are equal at {k.replace('e1', 'index ')} ({v:g}): nothing to separate"))
    return out


def _raise(message: str):
    raise InputError(message)


# ============================================================ vectorized interpolation (lookup's rule)
def _delta(view, name: str, combos, e: np.ndarray) -> np.ndarray:
    """``view.delta_at`` at every contact of the table and every ``e``: [contact, len(e)]."""
    arr = view.t.arrays[name]
    total = np.zeros((view.contacts.size, e.size))
    bad = np.zeros(total.shape, dtype=bool)
    for idx, w in combos:
        if w == 0:
            continue
        v = _table_route.interp_e_rows(arr[idx], view.centres, e)
        bad |= np.isnan(v)
        total = total + w * v
    return np.where(bad, np.nan, total)


def _need(view, kind: str, combos, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``view.need`` at every contact and pair: [contact, n] (NaN: not within the grid)."""
    suffix = {"svm": "", "lo": "_lo", "hi": "_hi", "ideal": "_ideal"}[kind]
    up_name, down_name = f"delta_up{suffix}", f"delta_down{suffix}"
    if up_name not in view.t.arrays:
        up_name, down_name = "delta_up", "delta_down"
    up, down = _delta(view, up_name, combos, lo), _delta(view, down_name, combos, hi)
    return np.where(np.isnan(up) | np.isnan(down), np.nan, np.maximum(up, down))


def _at_contact(cw, per_contact: np.ndarray) -> np.ndarray:
    """Contact-weighted sum of ``per_contact`` [contact, n] (NaN if a weighted term is NaN)."""
    total = np.zeros(per_contact.shape[1])
    bad = np.zeros(total.shape, dtype=bool)
    for k, w in cw:
        if w == 0:
            continue
        bad |= np.isnan(per_contact[k])
        total = total + w * per_contact[k]
    return np.where(bad, np.nan, total)


def _scenes_in_grid(x: dict[str, np.ndarray], view, e_in: np.ndarray):
    """Per distinct scene (contact, noise, dT) inside the table's grid: the scene, its weights on the scene
    axes and on the contact axis, and the indices of its elements whose effusivities are inside the grid."""
    for (contact, noise, dt), idx in _groups(x["contact_s"], x["noise_c"], x["delta_t_c"]):
        combos, flags = view.scene_weights(noise, dt)
        cw, c_ok = _table_route.axis_weights_flagged(view.contacts, contact)
        if not (all(flags.values()) and c_ok):
            continue
        idx = idx[e_in[idx]]
        if idx.size:
            yield (contact, noise, dt), combos, cw, idx


def _groups(*columns: np.ndarray):
    """Indices of the elements sharing each distinct combination of ``columns`` (1-D, equal length)."""
    stacked = np.stack(columns, axis=1)
    uniq, inverse = np.unique(stacked, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    order = np.argsort(inverse, kind="stable")
    bounds = np.searchsorted(inverse[order], np.arange(len(uniq) + 1))
    for g, row in enumerate(uniq):
        yield tuple(float(v) for v in row), order[bounds[g]:bounds[g + 1]]


def _nan(n: int) -> np.ndarray:
    return np.full(n, np.nan)


# ============================================================ the table route, vectorized
def _table_pair(question: str, x: dict[str, np.ndarray], op, ideal_bound: bool,
                zc: float, ideal_table=None) -> dict[str, np.ndarray]:
    e1, e2 = x["e1"], x["e2"]
    lo, hi = np.minimum(e1, e2), np.maximum(e1, e2)
    n = lo.size
    view = op.view
    res = {k: _nan(n) for k in ("value", "low", "high", "ideal")}
    res["in_grid"], res["stated"] = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
    e_in = (view.e_lo < lo) & (lo <= view.e_hi) & (view.e_lo < hi) & (hi <= view.e_hi)
    if question == "min-contact":
        _min_contact(x, op, lo, hi, e_in, res, ideal_bound, zc)
    elif question in ("max-noise", "min-delta-t"):
        _ratio(question, x, op, lo, hi, e_in, res, ideal_bound, zc)
    else:
        _distinguishable(x, op, lo, hi, e_in, res, ideal_bound, zc, ideal_table)
    return res


def _mc_contact_bounds(x, op, lo, hi, todo, zc: float, ideal: np.ndarray) -> np.ndarray:
    """No closed form (varied initial conditions, per-object shapes): the scalar route's Monte Carlo bound of the
    elements ``todo``, one call per element (remembered per distinct question), written into ``ideal``; returns
    the floors the intervals are held above (each bound's low end)."""
    from ..objects import ObjectClass
    from .ideal_mc_bound import cached_mc_ideal_min_contact

    floor = ideal.copy()
    spread = _table_route.table_spread(op.tab)
    for i in np.nonzero(todo)[0]:
        mcb = cached_mc_ideal_min_contact(
            ObjectClass("a", (lo[i], lo[i] + op.width)), ObjectClass("b", (hi[i], hi[i] + op.width)),
            op.tab.sensor, noise_c=float(x["noise_c"][i]), delta_t_c=float(x["delta_t_c"][i]),
            sensor_temp_spread_c=spread, model=op.model, threshold=op.phi,
            max_contact_s=_table_route.CLOSED_FORM_MAX_CONTACT_S, coverage=coverage_of_z(zc))
        ideal[i] = np.nan if mcb.value is None else mcb.value
        floor[i] = np.nan if mcb.value is None else mcb.floor
    return floor


def _min_contact(x, op, lo, hi, e_in, res, ideal_bound: bool, zc: float, outside: bool = True) -> None:
    """min-contact of the elements ``e_in`` marks; with ``outside`` the closed-form bound of the others too
    (a question outside the grid still gets it; ``distinguishable`` needs it only inside)."""
    view = op.view
    grid = view.contacts
    svm = op.tab.fidelity == "svm"
    todo = np.zeros(lo.size, dtype=bool)
    k_cross = np.full(lo.size, -1)
    n_prev, n_at = _nan(lo.size), _nan(lo.size)  # the svm need at the contact before the crossing, and at it
    # the scalar route's noise-efficiency estimate (table.noise_k_min_contact, the same function), per scene
    efficiency = svm and op.closed and "delta_up_ideal" in view.t.arrays
    eff = {k: _nan(lo.size) for k in ("value", "low", "high")}
    # varied initial conditions: the scalar route's per-slice estimate (table.varied_contact_estimate)
    varied = svm and _table_route.table_spread(op.tab) > 0 and "delta_up_lo" in view.t.arrays
    varied_groups = []
    for (noise, dt), idx in _groups(x["noise_c"], x["delta_t_c"]):
        combos, flags = view.scene_weights(noise, dt)
        if not all(flags.values()):
            continue
        idx = idx[e_in[idx]]
        if not idx.size:
            continue
        l, h = lo[idx], hi[idx]
        gap = h - l
        need = _need(view, "svm", combos, l, h)
        value, k, _, _, n0, n1 = _table_route.grid_crossing(grid, need, gap)
        k_cross[idx] = k
        n_prev[idx] = np.where(k > 0, n0, np.nan)
        n_at[idx] = n1
        ilo = _table_route.grid_crossing(grid, _need(view, "lo", combos, l, h), gap)[0] if svm else value
        ihi = _table_route.grid_crossing(grid, _need(view, "hi", combos, l, h), gap)[0] if svm else value
        if not op.closed and not ideal_bound and op.iview is not None:  # the table's own floor (the scalar's)
            icombos, iflags = op.iview.scene_weights(noise, dt)
            if all(iflags.values()):
                res["ideal"][idx] = _table_route.grid_crossing(op.iview.contacts, _need(op.iview, op.ikind, icombos,
                                                                                        l, h), gap)[0]
        if efficiency and (has := k >= 0).any():
            r = _table_route.noise_k_min_contact(op, combos, k[has], l[has], h[has], noise / abs(dt), zc=zc)
            for key in eff:
                eff[key][idx[has]] = r[key]
        res["value"][idx], res["low"][idx], res["high"][idx] = value, ilo, ihi
        res["in_grid"][idx] = True
        todo[idx] = True
        if varied:
            varied_groups.append((combos, idx))
    sel = np.ones(lo.size, dtype=bool) if outside else todo
    if op.closed and ideal_bound and sel.any():  # outside the grid too: the closed form needs no table
        from .ideal_bound import exact_ideal_min_contact

        ratio = x["noise_c"] / np.abs(x["delta_t_c"])
        res["ideal"][sel] = exact_ideal_min_contact(
            op.tab.sensor, lo[sel], hi[sel], ratio[sel], width=op.width, threshold=op.phi,
            max_contact_s=_table_route.CLOSED_FORM_MAX_CONTACT_S)
    ideal_floor = res["ideal"]
    if not op.closed and ideal_bound and todo.any():
        ideal_floor = _mc_contact_bounds(x, op, lo, hi, todo, zc, res["ideal"])
    # the scalar route's interval: an estimate where the crossing is interpolated between two tabulated needs
    # (table.contact_estimate, the same function), else the grid cell, never below the ideal bound
    raw, ideal = res["value"], ideal_floor
    low, high = _nan(lo.size), _nan(lo.size)
    value = raw.copy()
    by_estimate = np.zeros(lo.size, dtype=bool)
    if efficiency and (got := ~np.isnan(raw) & ~np.isnan(eff["value"])).any():
        j = np.nonzero(got)[0]
        value[j], high[j] = eff["value"][j], eff["high"][j]
        low[j] = np.where(np.isnan(ideal[j]), eff["low"][j], np.minimum(np.maximum(eff["low"][j], ideal[j]),
                                                                         eff["value"][j]))
        by_estimate[j] = True
    for combos, idx in varied_groups:
        r = _table_route.varied_contact_estimate(view, combos, lo[idx], hi[idx], ideal[idx], width=op.width,
                                                 z_table=_table_route.table_z(op.tab), zc=zc)
        got = ~np.isnan(r["value"])
        j = idx[got]
        value[j], low[j], high[j] = r["value"][got], r["low"][got], r["high"][got]
        by_estimate[j] = True
    est = (k_cross > 0) & ~np.isnan(n_prev) & ~np.isnan(raw) & ~by_estimate
    _grid_estimates(op, est, ~np.isnan(raw) & ~est & ~by_estimate, k_cross, n_prev, n_at, lo, hi, res, ideal,
                    value, low, high, varied=varied, zc=zc)
    if "stated" in res:  # where the interval has a stated coverage, as the scalar answer's
        res["stated"] = by_estimate | (est & _table_route.states_coverage(op.tab, "min-contact", "table-estimate"))


def _grid_estimates(op, est, cell, k_cross, n_prev, n_at, lo, hi, res, ideal, value, low, high, *, varied: bool,
                    zc: float) -> None:
    """min-contact's answers read between grid points (the scalar route's ``_rounding_estimate``, through
    :func:`~designkit.query.table.contact_estimate`) at ``est``, and its grid cells at ``cell``, never below the
    ideal bound; ``value``, ``low``, ``high`` updated and stored in ``res`` (whose ``low`` / ``high`` hold the
    Monte Carlo ends' crossings, ``value`` the raw crossing)."""
    grid, raw = op.view.contacts, res["value"]
    if est.any():
        i = np.nonzero(est)[0]
        r = _table_route.contact_estimate(
            grid[k_cross[i] - 1], grid[k_cross[i]], n_prev[i], n_at[i], hi[i] - lo[i], raw[i], res["low"][i],
            res["high"][i], ideal[i], width=op.width, svm=op.tab.fidelity == "svm",
            z_table=_table_route.table_z(op.tab), zc=zc)
        value[i], low[i], high[i] = r["value"], r["low"], r["high"]
    prev = np.where(k_cross > 0, grid[np.maximum(k_cross - 1, 0)], 0.0)
    if varied:  # the scalar route's rule: F1 need not rise with contact time, the cell starts at the bound
        prev = np.zeros_like(prev)
    res["value"] = value
    res["low"] = np.where(cell, np.where(np.isnan(ideal), prev, np.maximum(prev, ideal)), low)
    res["high"] = np.where(cell, raw, high)


_BELOW, _INSIDE, _ABOVE, _CELL = 0, 1, 2, 3  # where a largest separating ratio lies (the scalar route's words)


def _max_ratio(view, kind: str, cw, lo, hi, *, gcw=None, shift: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Per pair: largest sigma/dT that separates it, and where (``_BELOW`` ... ``_CELL``), as the scalar
    route's ``_max_ratio``: ``gcw`` (log contact weights) for its geometric interpolant, ``shift``
    subtracted from every tabulated need."""
    ratios = view.t.axes["noise_ratio"]
    logs = np.array([math.log(r) for r in ratios.tolist()])  # math.log, as the scalar route
    gap = hi - lo
    margins = []
    with np.errstate(invalid="ignore", divide="ignore"):
        for i in range(ratios.size):
            per = _need(view, kind, [((i,), 1.0)], lo, hi)
            if gcw is None:
                nd = _at_contact(cw, per) - shift
                margins.append(np.where(np.isnan(nd), -np.inf, gap - nd))
                continue
            total = np.zeros(lo.size)
            bad = np.zeros(lo.size, dtype=bool)
            for k, w in gcw:
                if not w:
                    continue
                n = per[k] - shift
                bad |= np.isnan(n) | (n <= 0)
                total = total + w * np.log(n)
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
    where = np.where(~ok[0], _BELOW, np.where(last == r_n - 1, _ABOVE,
                                              np.where(np.isfinite(m1), _INSIDE, _CELL)))
    r = np.where(where == _BELOW, np.nan, np.where(where == _INSIDE, inside, ratios[last]))
    return r, where


def _ratio_interpolants(op, contact: float, cw, j, lo, hi, alt: dict) -> None:
    """The rounding-corrected estimate's interpolants of the largest separating sigma/dT (the scalar route's:
    :func:`~designkit.query.table.ratio_estimate` takes them) for pairs ``lo < hi`` at elements ``j``, written
    into ``alt`` (NaN where one does not cross inside the grid)."""
    w, view = op.width, op.view
    gcw = _table_route.axis_weights_flagged(view.contacts, contact, log=True)[0]
    for key, kw in (("c", dict(gcw=gcw, shift=0.5 * w)), ("lin", dict(shift=0.5 * w)),
                    ("rnd", dict(gcw=gcw, shift=0.5 * w + w / math.sqrt(12))), ("geo", dict(gcw=gcw))):
        a_r, a_w = _max_ratio(view, "svm", cw, lo, hi, **kw)
        alt[key][j] = np.where(a_w == _INSIDE, a_r, np.nan)


def _ratio_by_efficiency(op, x, lo, hi, i, r_all, ri, low, high, by_k, ordered, zc: float) -> None:
    """max-noise / min-delta-t from the SVM's noise efficiency (:func:`~designkit.query.table.noise_k_max_ratio`)
    at elements ``i``, never beyond the ideal observer's ``ri``: ``r_all``, ``low``, ``high`` and ``by_k``
    updated where it applies (``ordered``: sigma/dT ends to the answer's interval)."""
    kr = _table_route.noise_k_max_ratio(op, x["contact_s"][i], r_all[i], ri[i], lo[i], hi[i], zc=zc)
    got = ~np.isnan(kr["value"])
    j = i[got]
    k_low, k_high = _nan(lo.size), _nan(lo.size)
    k_low[j], k_high[j] = kr["low"][got], np.minimum(kr["high"][got], ri[j])
    a, b = ordered(k_low, k_high)
    low[j], high[j], r_all[j] = a[j], b[j], np.minimum(kr["value"][got], ri[j])
    by_k[j] = True


def _ratio(question, x, op, lo, hi, e_in, res, ideal_bound: bool, zc: float) -> None:
    view = op.view
    ratios = view.t.axes["noise_ratio"] if "noise_ratio" in op.tab.axes else None
    if ratios is None:
        from .inputs import TableMismatch

        raise TableMismatch(f"table {op.tab.name} has separate noise and temperature axes (varied initial "
                            f"conditions): it cannot answer {question}; the exact route can")
    n = lo.size
    svm = op.tab.fidelity == "svm"
    r_all, where_all = _nan(n), np.full(n, -1)
    ends = {"hi": _nan(n), "lo": _nan(n)}       # the Monte Carlo ends (sigma/dT), NaN: none
    alt = {k: _nan(n) for k in ("c", "lin", "rnd", "geo")}  # the estimate's interpolants (NaN: not inside)
    ri = _nan(n)
    for (contact,), idx in _groups(x["contact_s"]):
        cw, c_ok = _table_route.axis_weights_flagged(view.contacts, contact)
        if not c_ok:
            continue
        idx = idx[e_in[idx]]
        if not idx.size:
            continue
        l, h = lo[idx], hi[idx]
        out = {"svm": _max_ratio(view, "svm", cw, l, h)}
        for kind in ("lo", "hi"):
            out[kind] = out["svm"] if not svm else _max_ratio(view, kind, cw, l, h)
        if not op.closed and op.iview is not None:
            icw, _ = _table_route.axis_weights_flagged(op.iview.contacts, contact)
            r_i, w_i = _max_ratio(op.iview, op.ikind, icw, l, h)
            ri[idx] = np.where(w_i == _BELOW, np.nan, r_i)
        r, where = out["svm"]
        r_all[idx], where_all[idx] = r, where
        ends["hi"][idx] = np.where(out["hi"][1] == _BELOW, np.nan, out["hi"][0])
        # the optimistic end is open where it is separable beyond the grid (the scalar route's rule)
        ends["lo"][idx] = np.where((out["lo"][1] == _BELOW) | (out["lo"][1] == _ABOVE), np.nan, out["lo"][0])
        res["in_grid"][idx] = where != _ABOVE
        est = where == _INSIDE
        if svm and est.any():
            _ratio_interpolants(op, contact, cw, idx[est], l[est], h[est], alt)
    if op.closed and ideal_bound:  # every element, outside the grid too: the closed form needs no table
        from .ideal_bound import exact_ideal_max_ratio

        ok = within_sample_limit(x["contact_s"], op.tab.sensor.sample_rate_hz)
        if ok.any():
            ri[ok] = exact_ideal_max_ratio(op.tab.sensor, lo[ok], hi[ok], x["contact_s"][ok], width=op.width,
                                           threshold=op.phi, bracket=_table_route.CLOSED_FORM_RATIO_BRACKET)

    def to_answer(r):
        return r * np.abs(x["delta_t_c"]) if question == "max-noise" else x["noise_c"] / r

    def ordered(r_low, r_high):  # the interval in the answer's units, low <= high
        a, b = to_answer(r_low), to_answer(r_high)
        return (a, b) if question == "max-noise" else (b, a)

    low, high = _nan(n), _nan(n)
    # the scalar route's noise-efficiency estimate (table.noise_k_max_ratio, the same function) where it applies
    by_k = np.zeros(n, dtype=bool)
    if (svm and op.closed and "delta_up_ideal" in view.t.arrays
            and (cand := ((where_all == _INSIDE) | (where_all == _CELL)) & ~np.isnan(ri)).any()):
        _ratio_by_efficiency(op, x, lo, hi, np.nonzero(cand)[0], r_all, ri, low, high, by_k, ordered, zc)
    inside = (where_all == _INSIDE) & ~by_k
    if "stated" in res:  # where the interval has a stated coverage, as the scalar answer's
        res["stated"] = by_k | (inside if svm else False)
    if svm and inside.any():  # the scalar route's estimate (table.ratio_estimate, the same function)
        est = _table_route.ratio_estimate(r_all, alt["c"], alt["lin"], alt["rnd"], alt["geo"], ends["hi"], ends["lo"], ri,
                                          z_table=_table_route.table_z(op.tab), zc=zc)
        a, b = ordered(est["low"], est["high"])
        low, high = np.where(inside, a, low), np.where(inside, b, high)
        r_all = np.where(inside, est["value"], r_all)
    elif inside.any():  # an ideal-observer table: the Monte Carlo ends (both the answer)
        mc = [to_answer(ends[k]) for k in ("hi", "lo")]
        both = ~np.isnan(mc[0]) & ~np.isnan(mc[1])
        low = np.where(inside, np.where(both, np.fmin(*mc), mc[0]), low)
        high = np.where(inside, np.where(both, np.fmax(*mc), mc[1]), high)
    cell = (where_all == _CELL) & ~by_k
    if cell.any():  # a neighbour beyond the grid: the grid cell, up to the next ratio (or the bound)
        k = np.searchsorted(ratios, np.where(cell, r_all, ratios[0]))
        nxt = ratios[np.minimum(k + 1, ratios.size - 1)]
        nxt = np.where(np.isnan(ri), nxt, np.minimum(nxt, ri))
        a, b = ordered(r_all, nxt)
        low, high = np.where(cell, a, low), np.where(cell, b, high)
    above = where_all == _ABOVE  # separable beyond the largest ratio: a one-sided bound
    v = to_answer(r_all)
    if question == "max-noise":
        low = np.where(above, v, low)
    else:
        high = np.where(above, v, high)
    answered = where_all >= 0
    res["value"] = np.where(answered & (where_all != _BELOW), v, np.nan)
    res["low"], res["high"] = np.where(answered, low, np.nan), np.where(answered, high, np.nan)
    res["ideal"] = to_answer(ri)  # NaN where it was not computed


def _distinguishable(x, op, lo, hi, e_in, res, ideal_bound: bool, zc: float, ideal_table) -> None:
    view = op.view
    todo = np.zeros(lo.size, dtype=bool)
    for _, _, _, idx in _scenes_in_grid(x, view, e_in):
        res["in_grid"][idx] = True
        todo[idx] = True
    # the scalar route's rule (table.distinguishable): the contact against min-contact's answer for the pair at
    # its noise and dT (_min_contact, the same estimate, its interval always held to the ideal bound as the
    # scalar's); where the contact lies inside that interval, a max-noise or delta-e answer sure of it decides
    mc = {k: _nan(lo.size) for k in ("value", "low", "high", "ideal")}
    mc["in_grid"], mc["stated"] = np.zeros(lo.size, dtype=bool), np.zeros(lo.size, dtype=bool)
    if todo.any():
        _min_contact(x, op, lo, hi, todo, mc, op.closed, zc, outside=False)  # no Monte Carlo bound (the scalar's)
    t, a, b, c = mc["value"], mc["low"], mc["high"], x["contact_s"]
    with np.errstate(invalid="ignore"):
        yes = ~np.isnan(t) & (c >= t)
        below_high = (c <= b) | np.isnan(b)
        unsure = todo & ~np.isnan(t) & ~np.isnan(a) & below_high & np.where(mc["stated"], a <= c, a < c)
    if unsure.any():
        yes = _others_decide(x, op, lo, hi, np.nonzero(unsure)[0], yes, zc, ideal_table)
    res["value"] = np.where(todo, yes.astype(np.float64), np.nan)
    for key, name in (("value", "min_contact_s"), ("low", "min_contact_low"), ("high", "min_contact_high")):
        res[name] = np.where(todo, mc[key], np.nan)
    if not ideal_bound:
        return
    if op.closed:  # every element, outside the grid too (within the sample limit): the closed form needs no table
        from ..recognition.ideal import ideal_f1, shape_norm

        ok = within_sample_limit(x["contact_s"], op.tab.sensor.sample_rate_hz)
        if not ok.any():
            return
        norm = shape_norm(op.tab.sensor, x["contact_s"][ok])
        with np.errstate(divide="ignore", invalid="ignore"):  # no signal yet (norm 0): s infinite
            s = np.where(norm > 0, (x["noise_c"][ok] / np.abs(x["delta_t_c"][ok])) / norm, np.inf)
        res["ideal"][ok] = ideal_f1(lo[ok], hi[ok], op.width, op.tab.sensor.effusivity, s)
    else:  # Monte Carlo ideal observer (varied initial conditions, per-object shapes): one call per element
        from ..recognition.ideal import ideal_pair
        from ..scene import Scene

        for i in np.nonzero(todo)[0]:
            scene = Scene.from_delta_t(contact_s=float(x["contact_s"][i]), noise_c=float(x["noise_c"][i]),
                                       delta_t_c=float(x["delta_t_c"][i]))
            res["ideal"][i] = ideal_pair((lo[i], lo[i] + op.width), (hi[i], hi[i] + op.width), op.tab.sensor, scene,
                                         model=op.model).f1


def _others_decide(x, op, lo, hi, i: np.ndarray, yes: np.ndarray, zc: float, ideal_table) -> np.ndarray:
    """``yes`` where max-noise (the asked noise outside its stated interval) or delta-e (the pair's distance
    outside the interval of the need ``max(delta_up(lo), delta_down(hi))``) is sure, for elements ``i`` whose
    contact lies inside min-contact's interval; both sure and disagreeing: unchanged (the scalar route's
    ``table._other_readings``)."""
    n = i.size
    noise, dt, c = x["noise_c"][i], x["delta_t_c"][i], x["contact_s"][i]
    l, h = lo[i], hi[i]
    sure = {}
    if "noise_ratio" in op.tab.axes:
        mn = {k: _nan(n) for k in ("value", "low", "high", "ideal")}
        mn["in_grid"], mn["stated"] = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
        _ratio("max-noise", {"contact_s": c, "delta_t_c": dt}, op, l, h, np.ones(n, dtype=bool), mn, True, zc)
        with np.errstate(invalid="ignore"):
            out = mn["stated"] & ~np.isnan(mn["low"]) & ~np.isnan(mn["high"]) & ~(
                (mn["low"] <= noise) & (noise <= mn["high"]))
            sure["max-noise"] = (out, noise <= mn["value"])
    de = _table_delta_e({"e": np.concatenate([l, h]), "contact_s": np.tile(c, 2), "noise_c": np.tile(noise, 2),
                         "delta_t_c": np.tile(dt, 2)}, op, ideal_table, zc, ideal_bound=False)
    parts = [(de[f"{side}"][sl], de[f"{side}_low"][sl], de[f"{side}_high"][sl])
             for side, sl in (("upper", slice(0, n)), ("lower", slice(n, 2 * n)))]
    with np.errstate(invalid="ignore"):
        ok = np.all([np.isfinite(p) for part in parts for p in part], axis=0)
        value, low, high = (np.fmax(parts[0][k], parts[1][k]) for k in range(3))
        gap = h - l
        sure["delta-e"] = (ok & ~((low <= gap) & (gap <= high)), gap >= value)
    (o1, v1), (o2, v2) = sure.get("max-noise", (np.zeros(n, dtype=bool), np.zeros(n, dtype=bool))), sure["delta-e"]
    decided = np.where(o1 & o2, np.where(v1 == v2, v1, yes[i]), np.where(o1, v1, np.where(o2, v2, yes[i])))
    out = yes.copy()
    out[i] = decided
    return out


def _mc_delta_bounds(op, e: np.ndarray, direction: int, contact: float, noise: float, dt: float,
                     zc: float) -> tuple[np.ndarray, np.ndarray]:
    """Per reference: the Monte Carlo ideal delta(e) of one direction and the low end of its interval (the
    scalar route's :func:`~designkit.query.ideal_mc_bound.cached_mc_ideal_delta`; NaN: none)."""
    from ..objects import ObjectClass
    from .ideal_mc_bound import cached_mc_ideal_delta

    value, floor = _nan(e.size), _nan(e.size)
    for i, xe in enumerate(e.tolist()):
        mcb = cached_mc_ideal_delta(ObjectClass("r", (xe, xe + op.width)), direction, op.tab.sensor,
                                    contact_s=contact, noise_c=noise, delta_t_c=dt,
                                    sensor_temp_spread_c=_table_route.table_spread(op.tab), model=op.model,
                                    threshold=op.phi, coverage=coverage_of_z(zc))
        if mcb.value is not None:
            value[i] = mcb.value
            floor[i] = mcb.floor
    return value, floor


def _delta_at(e: np.ndarray, v, cmb, cws, name: str) -> np.ndarray:
    """Array ``name`` of view ``v`` at effusivities ``e``, scene weights ``cmb``, contact weights ``cws`` (NaN:
    none, or no such view or array)."""
    if v is None or name not in v.t.arrays:
        return _nan(e.size)
    return _at_contact(cws, _delta(v, name, cmb, e))


def _delta_geometric(e: np.ndarray, v, cmb, cws, name: str) -> np.ndarray:
    """As :func:`_delta_at`, log delta interpolated (the scalar route's alternative interpolant)."""
    total = np.zeros(e.size)
    bad = np.zeros(e.size, dtype=bool)
    with np.errstate(invalid="ignore", divide="ignore"):
        for k, w in cws:
            if w == 0:
                continue
            for i, wi in cmb:
                if not wi:
                    continue
                y = _table_route.interp_e_rows(v.t.arrays[name][i][k:k + 1], v.centres, e)[0]
                bad |= np.isnan(y) | (y <= 0)
                total = total + w * wi * np.log(y)
        return np.where(bad, np.nan, np.exp(total))


def _table_delta_e(x: dict[str, np.ndarray], op, ideal_table, zc: float,
                   ideal_bound: bool = True) -> dict[str, np.ndarray]:
    e = x["e"]
    n = e.size
    view = op.view
    svm = op.tab.fidelity == "svm"
    res = {k: _nan(n) for k in ("value", "low", "high", "ideal", "lower", "upper", "lower_ideal", "upper_ideal",
                                "lower_low", "lower_high", "upper_low", "upper_high")}
    res["in_grid"] = np.zeros(n, dtype=bool)
    e_in = (view.e_lo < e) & (e <= view.e_hi)
    iview, ikind = _table_route.delta_e_ideal_view(op, ideal_table)
    for (contact, noise, dt), combos, cw, idx in _scenes_in_grid(x, view, e_in):
        xe = e[idx]

        at, at_geometric = (functools.partial(f, xe) for f in (_delta_at, _delta_geometric))

        icombos = iview.scene_weights(noise, dt)[0] if iview is not None else []
        icw = _table_route.axis_weights_flagged(iview.contacts, contact)[0] if iview is not None else []
        gcw = _table_route.axis_weights_flagged(view.contacts, contact, log=True)[0]
        efficiency = svm and op.closed and "delta_up_ideal" in view.t.arrays
        ends = (cw[0][0], cw[-1][0])
        for direction, side in (("down", "lower"), ("up", "upper")):
            val = at(view, combos, cw, f"delta_{direction}")
            iname = f"delta_{direction}_ideal" if ikind == "ideal" else f"delta_{direction}"
            ideal = at(iview, icombos, icw, iname)
            floor = ideal
            if not op.closed and ideal_bound:  # the scalar route's Monte Carlo bound, one call per element
                ideal, floor = _mc_delta_bounds(op, xe, 1 if direction == "up" else -1, contact, noise, dt, zc)
            mc_lo = at(view, combos, cw, f"delta_{direction}_lo") if svm else None
            mc_hi = at(view, combos, cw, f"delta_{direction}_hi") if svm else None
            by_eff = np.zeros(xe.size, dtype=bool)
            if efficiency:  # the scalar route's delta_efficiency_estimate where the tabulated value exists
                r = _table_route.delta_efficiency_estimate(
                    op.tab.sensor, xe, contact, noise / abs(dt), -1.0 if direction == "down" else 1.0,
                    view.contacts[ends[0]], view.contacts[ends[1]],
                    *_table_route.delta_entries(view, combos, ends, direction, xe), width=op.width,
                    threshold=op.phi, e_max=view.e_hi, z_table=_table_route.table_z(op.tab), zc=zc,
                    mc_factor=view.mc_calibration())
                # where the tabulated value is none (beyond the grid at one of the two contacts), the estimate
                # from the other contact, when its partner lies inside the range (table.partner_in_grid)
                by_eff = ~np.isnan(r["value"]) & (~np.isnan(val) | _table_route.partner_in_grid(
                    view, xe, r["value"], direction))
                val = np.where(by_eff, r["value"], val)
                ideal = np.where(by_eff, r["ideal"], ideal)
            res[side][idx], res[f"{side}_ideal"][idx] = val, ideal
            if svm:  # the scalar route's interval (table.delta_estimate, the same function)
                low, high = _table_route.delta_estimate(
                    val, mc_lo, mc_hi, at_geometric(view, combos, gcw, f"delta_{direction}"), floor, width=op.width,
                    z_table=_table_route.table_z(op.tab), zc=zc)
                if efficiency:
                    low, high = np.where(by_eff, r["low"], low), np.where(by_eff, r["high"], high)
                res[f"{side}_low"][idx] = np.where(np.isnan(val), np.nan, low)
                res[f"{side}_high"][idx] = np.where(np.isnan(val), np.nan, high)
        res["in_grid"][idx] = True
    # the scene outside the grid, the reference inside its range, the touch within the sample limit: the closed
    # form needs no table (the scalar's _outside_ideal_delta)
    out = np.nonzero(~res["in_grid"] & e_in & within_sample_limit(x["contact_s"], op.tab.sensor.sample_rate_hz))[0]
    if op.closed and ideal_bound and out.size:
        from .ideal_bound import exact_ideal_delta

        ratio = x["noise_c"][out] / np.abs(x["delta_t_c"][out])
        for side, sign in (("lower", -1.0), ("upper", 1.0)):
            res[f"{side}_ideal"][out] = exact_ideal_delta(op.tab.sensor, e[out], x["contact_s"][out], ratio,
                                                          direction=np.full(out.size, sign), width=op.width,
                                                          threshold=op.phi, e_max=view.e_hi)
    res["value"] = np.fmin(res["lower"], res["upper"])
    res["ideal"] = np.fmin(res["lower_ideal"], res["upper_ideal"])
    # an SVM table's estimate (table-efficiency or table-estimate) states its coverage, as the scalar route's
    states = svm and _table_route.states_coverage(op.tab, "delta-e", "table-estimate")
    res["stated"] = np.full(n, states) & ~np.isnan(res["value"])
    # the interval of the direction giving the value (the lower one on a tie, as the scalar route)
    lower = ~np.isnan(res["lower"]) & (np.isnan(res["upper"]) | (res["lower"] <= res["upper"]))
    for end in ("low", "high"):
        res[end] = np.where(lower, res[f"lower_{end}"], res[f"upper_{end}"])
    return res


# ============================================================ any route: one scalar call per element
def _from_answers(answers: list[Answer], shape: tuple[int, ...], question: str) -> dict[str, np.ndarray]:
    def num(v):
        return np.nan if v is None else float(v)

    res = {
        "value": np.array([num(a.value) for a in answers]),
        "low": np.array([num(a.interval[0]) for a in answers]),
        "high": np.array([num(a.interval[1]) for a in answers]),
        "coverage": np.array([num(a.interval_coverage) for a in answers]),
        "ideal": np.array([num(a.ideal_bound.value) for a in answers]),
        "in_grid": np.array([all(a.in_grid.values()) for a in answers], dtype=bool),
    }
    if question == "delta-e":
        for side in ("lower", "upper"):
            res[side] = np.array([num(a.details[side]["value"]) for a in answers])
            res[f"{side}_ideal"] = np.array([num(a.details[side]["ideal"]) for a in answers])
    return {k: v.reshape(shape) for k, v in res.items()}


def answer_arrays(question: str, scalar: Callable[..., Answer], route: str, arguments: dict[str, Any], *,
                  ideal_bound: bool = True) -> ArrayAnswer:
    """Answer ``question`` over array inputs (see the module docstring).

    Parameters
    ----------
    question : str
        A name of :data:`designkit.query.QUESTIONS`.
    scalar : callable
        The route's scalar function (used element by element where the route is not vectorized).
    route : str
        ``"table"`` or ``"exact"``.
    arguments : dict
        The call's keyword arguments (numeric inputs may be arrays or lists).
    ideal_bound : bool
        Compute the closed-form ideal bound on the table route (False: ``ideal`` is NaN, faster).
    """
    names = ARRAY_INPUTS[question]
    numeric = {n: arguments.get(n, _DEFAULTS.get(n)) for n in names}
    present = {n: v for n, v in numeric.items() if v is not None}
    x = _checked(question, present)
    others = {k: v for k, v in arguments.items() if k not in names}
    listed = _name_arrays(question, others)
    try:
        shape = np.broadcast_shapes(*(a.shape for a in (*x.values(), *listed.values())))
    except ValueError:
        shapes = ", ".join(f"{n} {a.shape}" for n, a in (*x.items(), *listed.items()))
        raise InputError(f"the array inputs do not broadcast together: {shapes}") from None
    flat = {n: np.broadcast_to(a, shape).ravel() for n, a in x.items()}
    by_name = bool(listed) or any(others.get(k) is not None for k in ("m", "m1", "m2", "objects"))
    pair = question != "delta-e"
    if route == "table" and not by_name and all(n in flat for n in names):
        op = _table_route.open_table(others.get("table", _table_route.DEFAULT_TABLE),
                                     others.get("ideal_table", _table_route.DEFAULT_IDEAL_TABLE),
                                     threshold=others.get("threshold"), sensor=others.get("sensor"),
                                     model=others.get("model"),
                                     sensor_temp_spread_c=others.get("sensor_temp_spread_c", 0.0))
        unknown = set(others) - {"table", "ideal_table", "threshold", "sensor", "model", "coverage",
                                 "sensor_temp_spread_c"}
        if unknown:
            raise InputError(f"{question} from a table takes no {', '.join(sorted(unknown))}")
        zc = z_of_coverage(check_coverage(others.get("coverage", 0.9)))
        res = (_table_pair(question, flat, op, ideal_bound, zc,
                           others.get("ideal_table", _table_route.DEFAULT_IDEAL_TABLE)) if pair
               else _table_delta_e(flat, op, others.get("ideal_table", _table_route.DEFAULT_IDEAL_TABLE), zc,
                                   ideal_bound))
        stated = res.pop("stated") & (question != "distinguishable")  # (it has no interval, as the scalar)
        res["coverage"] = np.where(stated, check_coverage(others.get("coverage", 0.9)), np.nan)
        res = {k: v.reshape(shape) for k, v in res.items()}
        table = op.tab.name
    else:
        n = int(np.prod(shape)) if shape else 1
        named = {k: np.broadcast_to(v, shape).ravel() for k, v in listed.items()}
        answers = [scalar(**others, **{k: float(v[i]) for k, v in flat.items()},
                          **{k: str(v[i]) for k, v in named.items()}) for i in range(n)]
        res = _from_answers(answers, shape, question)
        table = answers[0].table if answers else None
    details = {k: res.pop(k) for k in ("lower", "upper", "lower_ideal", "upper_ideal", "lower_low", "lower_high",
                                       "upper_low", "upper_high", "min_contact_s", "min_contact_low",
                                       "min_contact_high") if k in res}
    in_grid = res.pop("in_grid")
    return ArrayAnswer(question=question, route=route, table=table, in_grid=in_grid, details=details, **res)
