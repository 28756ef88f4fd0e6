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

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np
from numpy.typing import NDArray

from .._validation import InputError, check_effusivity, check_positive, check_temperature
from . import table as _table_route
from . import table_arrays
from .table_open import delta_e_ideal_view
from .answer import Answer, QuestionQuantity
from .crossing import check_coverage, z_of_coverage

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
    return x is not None and not isinstance(x, (str, bytes, int, float)) and np.ndim(x) >= 1


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


# ============================================================ the table route: its one implementation, over arrays
def _table_arrays(question: str, x: dict[str, np.ndarray], op, ideal_bound: bool, zc: float,
                  ideal_table) -> dict[str, np.ndarray]:
    """The table route's arrays for ``question`` (:mod:`designkit.query.table_arrays`): value, low, high, ideal,
    in_grid, stated, and the question's details."""
    if question == "delta-e":
        r = table_arrays.delta_e_arrays(op, x["e"], x["contact_s"], x["noise_c"], x["delta_t_c"],
                                        ideal_view=delta_e_ideal_view(op, ideal_table), zc=zc,
                                        ideal_bound=ideal_bound)
        keep = ("lower", "upper", "lower_ideal", "upper_ideal", "lower_low", "lower_high", "upper_low", "upper_high")
    else:
        lo, hi = np.minimum(x["e1"], x["e2"]), np.maximum(x["e1"], x["e2"])
        if question == "min-contact":
            r = table_arrays.contact_arrays(op, lo, hi, x["noise_c"], x["delta_t_c"], ideal_bound=ideal_bound, zc=zc)
        elif question == "distinguishable":
            r = table_arrays.distinguishable_arrays(op, lo, hi, x["contact_s"], x["noise_c"], x["delta_t_c"],
                                                    ideal_bound=ideal_bound, zc=zc,
                                                    ideal_view=delta_e_ideal_view(op, ideal_table))
            r.update(min_contact_s=r["mc_value"], min_contact_low=r["mc_low"], min_contact_high=r["mc_high"])
        else:
            scale = np.abs(x["delta_t_c"]) if question == "max-noise" else x["noise_c"]
            r = table_arrays.ratio_arrays(question, op, lo, hi, x["contact_s"], scale, ideal_bound=ideal_bound, zc=zc)
        keep = ("min_contact_s", "min_contact_low", "min_contact_high") if question == "distinguishable" else ()
    return {k: r[k] for k in ("value", "low", "high", "ideal", "in_grid", "stated", *keep)}


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
        res = _table_arrays(question, flat, op, ideal_bound, zc,
                            others.get("ideal_table", _table_route.DEFAULT_IDEAL_TABLE))
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
