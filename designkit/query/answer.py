"""Typed answers to design questions; :meth:`Answer.to_dict` *is* the ``--json`` schema.

Every question (:mod:`designkit.query.questions`), through every route (a
lookup table or the exact computation) and every forward model, answers with
one :class:`Answer`. Its dictionary has the same keys whatever the question and
route; question-specific figures sit under ``details`` with keys fixed per
question, and what the route did (trials, evaluations, wall time, the table's
grid) under ``computation``.

Vocabulary (one name per concept, units in names): ``contact_s`` [s],
``noise_c`` and ``delta_t_c`` [degC], ``noise_ratio`` (sigma/dT, [-]),
effusivity [J s^-1/2 K^-1 m^-2], diffusivity ``*_m2_s`` [m^2 s^-1].

Examples
--------
>>> sorted(ANSWER_KEYS)[:4]
['bound', 'computation', 'details', 'ideal']
>>> QUANTITIES["min-contact"]
('contact_s', 's')
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any, Mapping, Sequence

__all__ = ["ANSWER_KEYS", "INTERVAL_MEANING", "QUANTITIES", "Answer", "IdealBound", "QuestionQuantity", "bound_of",
           "interval_dict", "number", "scene_record", "to_record"]

#: question -> (quantity name of ``value``, its unit).
QUANTITIES: dict[str, tuple[str, str]] = {
    "min-contact": ("contact_s", "s"),
    "max-noise": ("noise_c", "degC"),
    "min-delta-t": ("delta_t_c", "degC"),
    "delta-e": ("delta_e", "J s^-1/2 K^-1 m^-2"),
    "distinguishable": ("distinguishable", ""),
}

class QuestionQuantity:
    """``quantity`` and ``unit`` of a result of one question (its ``question`` attribute, :data:`QUANTITIES`):
    shared by :class:`Answer`, the array route's answers and the material matrix."""

    __slots__ = ()

    @property
    def quantity(self) -> str:
        """Name of the quantity ``value`` is in (``contact_s``, ``noise_c`` ...)."""
        return QUANTITIES[self.question][0]

    @property
    def unit(self) -> str:
        """Its unit."""
        return QUANTITIES[self.question][1]


#: What ``interval`` means, per kind (``interval.method`` in the ``--json`` schema).
INTERVAL_MEANING = {
    "table": "the answer at the two ends of the table's Monte Carlo interval of delta(e) "
             "(optimistic, conservative); equal ends for an ideal-observer table (coverage not stated)",
    "exact": "the search bracket the crossing lies in: too few informative evaluations for a fit "
             "(coverage not stated)",
    "exact-estimate": "confidence interval, at the stated coverage, of where the mean SVM F1 (infinitely many "
                      "seeds) crosses the threshold: a logistic fit of F1 against log(quantity) near the crossing "
                      "(delta method); never beyond the ideal-observer bound",
    "exact-f1": "confidence interval, at the stated coverage, of the mean SVM F1 of the pair (normal, the "
                "larger of the fold-level and seed-to-seed standard errors)",
    "table-estimate": "interval at the stated coverage from the table: its Monte Carlo interval of delta(e) "
                      "(rescaled from the table's z to the coverage) combined with the interpolation error "
                      "between grid points (the difference between linear and log-log interpolation); "
                      "never beyond the ideal-observer bound",
    "table-efficiency": "interval at the stated coverage: the SVM's efficiency read from the table at the "
                        "tabulated contact times around the answer (min-contact, max-noise, min-delta-t: its noise "
                        "efficiency, the noise at which the ideal observer needs the tabulated separation over the "
                        "table's; delta-e: its tabulated delta(e) over the ideal observer's), log-linear in log t, "
                        "applied to the exact ideal observer; it combines the tabulated needs' rounding and Monte "
                        "Carlo interval and the efficiency's change across the cell; never beyond the "
                        "ideal-observer bound",
    "table-cell": "the grid cell the crossing lies in, from the last tabulated value where the pair is not "
                  "separable to the first where it is: the grid cannot support an interval of stated "
                  "coverage here (a neighbour is beyond the grid)",
    "table-varied-estimate": "interval at the stated coverage from a table with varied initial conditions "
                             "(min-contact): each scene slice around the question (noise, dT) estimates the "
                             "crossing from its tabulated needs, both directions averaged, with the table's Monte "
                             "Carlo interval and the interpolation error between contact times; the slices' "
                             "answers are interpolated (log time) and their change across the cell adds an "
                             "interpolation error; never beyond the ideal-observer bound",
    "table-varied": "on a table with varied initial conditions: the interval the table gives (interpolated, or "
                    "the grid cell), with no coverage stated because measured coverage did not hold there (the "
                    "answer's notes give the figures); --exact states one",
    "none": "no interval: see the answer's notes for why",
    "distinguishable": "the verdict at the ends of the table's Monte Carlo interval (1 = yes; coverage not "
                       "stated)",
}

#: The keys of every answer's dictionary (the ``--json`` schema), whatever the question and route.
ANSWER_KEYS = frozenset({
    "question", "route", "route_reason", "quantity", "unit", "value", "interval", "bound", "ideal", "objects", "limiting_pair",
    "materials_rule", "scene", "sensor", "model", "model_check", "threshold", "table", "ideal_table",
    "in_grid", "details", "computation", "notes",
})


def interval_dict(ends: Sequence | None, **more: Any) -> dict[str, Any]:
    """An interval in the schema's one shape: ``{"low", "high", ...}`` (docs/schema.md; None: an open end).

    >>> interval_dict([1.0, float("inf")], coverage=0.9)
    {'low': 1.0, 'high': None, 'coverage': 0.9}
    """
    low, high = (None, None) if ends is None else ends
    return {"low": number(low), "high": number(high), **more}


def bound_of(low: Any, high: Any) -> str:
    """Which way a value is only a bound, from its interval's ends: ``"at-most"`` (no low end: the true
    answer is this or less), ``"at-least"`` (no high end) or ``""`` (both ends, or neither).

    >>> bound_of(None, 2.0), bound_of(0.5, None), bound_of(0.46, 0.49)
    ('at-most', 'at-least', '')
    """
    lo, hi = number(low), number(high)
    return "at-most" if lo is None and hi is not None else ("at-least" if hi is None and lo is not None else "")


def _side(side: Mapping[str, Any], ideal_method: str) -> dict[str, Any]:
    """One direction of delta-e in the schema's shapes (its interval and ideal as everywhere else)."""
    out = {k: v for k, v in side.items() if k not in ("interval", "coverage", "estimate_method", "ideal")}
    out["value"] = number(side.get("value"))
    out["interval"] = interval_dict(side.get("interval"), coverage=side.get("coverage"),
                                    method=side.get("estimate_method"))
    out["ideal"] = {"value": number(side.get("ideal")), "method": ideal_method}
    if "monte_carlo_interval" in side:
        out["monte_carlo_interval"] = interval_dict(side["monte_carlo_interval"])
    return out


def _schema_shapes(part: Mapping[str, Any], ideal_method: str) -> dict[str, Any]:
    """``details`` / ``computation`` with the schema's shapes: every interval ``{low, high}``, delta-e's
    directions as answers (docs/schema.md); the routes keep building plain lists."""
    out: dict[str, Any] = {}
    for k, v in part.items():
        if k in ("lower", "upper") and isinstance(v, Mapping):
            out[k] = _side(v, ideal_method)
        elif k == "min_contact_interval_s":
            out["min_contact_interval"] = interval_dict(v, method=part.get("min_contact_interval_kind"))
        elif k == "min_contact_interval_kind":
            continue
        elif k == "e":  # delta-e's reference: one effusivity is `effusivity` everywhere
            out["effusivity"] = v
        elif k.endswith("interval") and isinstance(v, (list, tuple)) and len(v) == 2:
            out[k] = interval_dict(v)
        else:
            out[k] = v
    return out


def number(x: Any) -> float | None:
    """``x`` as a Python float, or None for None, NaN and infinities (JSON-ready).

    >>> number(float("nan")) is None, number(2)
    (True, 2.0)
    """
    if x is None:
        return None
    v = float(x)
    return v if math.isfinite(v) else None


def scene_record(contact_s=None, noise_c=None, delta_t_c=None) -> dict[str, Any]:
    """An answer's ``scene``: the asked contact [s], noise and dT [degC], and sigma/dT (None: not asked).

    >>> scene_record(noise_c=0.05, delta_t_c=-10.0)["noise_ratio"]
    0.005
    """
    ratio = None if noise_c is None or delta_t_c is None else noise_c / abs(delta_t_c)
    return {"contact_s": contact_s, "noise_c": noise_c, "delta_t_c": delta_t_c, "noise_ratio": ratio}


@dataclass(frozen=True)
class IdealBound:
    """The ideal observer's answer to the same question: what no classifier can beat.

    Attributes
    ----------
    value : float or None
        In the question's quantity and unit (None: not reachable within the range examined).
    method : str
        ``"closed-form"``, ``"monte-carlo"``, ``"closed-form+monte-carlo"`` (both were
        used along the search), ``"table"`` (interpolated from a table) or
        ``"none"`` (not available, see the answer's notes).
    interval : (float or None, float or None, float) or None
        ``(low, high, coverage)`` of a Monte Carlo bound estimated at query time
        (:mod:`designkit.query.ideal_mc_bound`); None for a closed form (exact to its tolerance) or a table.
        In ``to_dict`` only where present.
    """

    value: float | None
    method: str
    interval: tuple | None = None

    def to_dict(self) -> dict[str, Any]:
        out = {"value": number(self.value) if not isinstance(self.value, bool) else self.value,
               "method": self.method}
        if self.interval is not None:
            low, high, cov = self.interval
            out["interval"] = interval_dict((low, high), coverage=cov)
        return out


@dataclass(frozen=True)
class Answer(QuestionQuantity):
    """One answer to a design question.

    Attributes
    ----------
    question : str
        ``min-contact``, ``max-noise``, ``min-delta-t``, ``delta-e`` or ``distinguishable``.
    route : str
        ``"table"`` or ``"exact"``.
    value : float, bool or None
        The SVM's answer in :data:`QUANTITIES` ``[question]`` (None: no answer,
        see ``notes``); a bool for ``distinguishable``.
    interval : (low, high)
        Interval of ``value`` (see :data:`INTERVAL_MEANING`); its coverage is
        ``interval_coverage`` where stated.
    ideal_bound : IdealBound
        The ideal observer's answer.
    objects : tuple of dict
        The objects asked about (label, material, effusivity and diffusivity ranges).
    limiting_pair : tuple of dict
        The two classes the answer is for (the materials rule's hardest pair).
    materials_rule : str
        The rule that turned ``objects`` into ``limiting_pair``.
    scene : dict
        ``contact_s``, ``noise_c``, ``delta_t_c``, ``noise_ratio`` as asked (the
        asked quantity None).
    sensor, model, model_check : dict
        The sensor (:meth:`designkit.Sensor.to_dict`), the forward model
        (:meth:`~designkit.models.ForwardModel.to_dict`) and its check for this answer.
    threshold : float
        F1 threshold Phi.
    table, table_hash, ideal_table, ideal_table_hash : str or None
        Tables read (name and content hash; None on the exact route).
    in_grid : dict
        Per table axis, whether the question lies inside the grid (empty on the exact route).
    details : dict
        Question-specific figures (same keys on every route).
    computation : dict
        What the route did (route-specific).
    notes : tuple of str
        Sentences for people.
    interval_coverage : float or None
        Nominal coverage of ``interval`` (None: not stated).
    interval_kind : str or None
        Key of :data:`INTERVAL_MEANING` for ``interval`` (None: by route).
    route_reason : str or None
        Why ``route`` answered (:func:`designkit.query.ask`'s policy, :mod:`designkit.query.policy`);
        None where a route function was called directly.
    """

    question: str
    route: str
    value: float | bool | None
    interval: tuple[Any, Any]
    ideal_bound: IdealBound
    objects: tuple[Mapping[str, Any], ...]
    limiting_pair: tuple[Mapping[str, Any], ...]
    materials_rule: str
    scene: Mapping[str, Any]
    sensor: Mapping[str, Any]
    model: Mapping[str, Any]
    model_check: Mapping[str, Any] | None
    threshold: float
    table: str | None = None
    table_hash: str | None = None
    ideal_table: str | None = None
    ideal_table_hash: str | None = None
    in_grid: Mapping[str, bool] = field(default_factory=dict)
    details: Mapping[str, Any] = field(default_factory=dict)
    computation: Mapping[str, Any] = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    interval_coverage: float | None = None
    interval_kind: str | None = None
    route_reason: str | None = None

    def replaced(self, **changes: Any) -> "Answer":
        """:func:`dataclasses.replace` (every field is an ``__init__`` field, none derived), at a tenth of its cost."""
        if unknown := changes.keys() - _FIELDS:
            raise TypeError(f"Answer has no field {sorted(unknown)[0]!r}")
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__, **changes)
        return new

    # ------------------------------------------------------------ schema
    @property
    def ideal(self) -> float | None:
        """The ideal observer's value (``ideal_bound.value``)."""
        return self.ideal_bound.value

    @property
    def bound(self) -> str:
        """``"at-most"`` / ``"at-least"`` where ``value`` is only a bound (its interval open at one end, e.g. an
        answer at a table's edge), else ``""``: the one source of the words "at most" / "at least" (and ≤ / ≥)."""
        if self.value is None or isinstance(self.value, bool):
            return ""
        return bound_of(*self.interval)

    @property
    def note(self) -> str:
        """``notes`` as one string."""
        return "; ".join(self.notes)

    def to_dict(self) -> dict[str, Any]:
        """The ``--json`` schema: :data:`ANSWER_KEYS`, JSON-ready (no NaN, no infinities)."""
        kind = self.interval_kind or ("distinguishable" if self.question == "distinguishable" else self.route)
        if self.interval[0] is None and self.interval[1] is None and self.interval_kind is None:
            kind = "none"
        meaning = INTERVAL_MEANING[kind]
        value = self.value if isinstance(self.value, bool) else number(self.value)
        return {
            "question": self.question,
            "route": self.route,
            "route_reason": self.route_reason,
            "quantity": self.quantity,
            "unit": self.unit,
            "value": value,
            "interval": interval_dict(self.interval, coverage=self.interval_coverage, method=kind, meaning=meaning),
            "bound": self.bound or None,
            "ideal": self.ideal_bound.to_dict(),
            "objects": [dict(o) for o in self.objects],
            "limiting_pair": [dict(o) for o in self.limiting_pair],
            "materials_rule": self.materials_rule,
            "scene": dict(self.scene),
            "sensor": dict(self.sensor),
            "model": dict(self.model),
            "model_check": None if self.model_check is None else dict(self.model_check),
            "threshold": self.threshold,
            "table": None if self.table is None else {"name": self.table, "content_hash": self.table_hash},
            "ideal_table": None if self.ideal_table is None else {"name": self.ideal_table,
                                                                  "content_hash": self.ideal_table_hash},
            "in_grid": dict(self.in_grid),
            "details": _schema_shapes(self.details, self.ideal_bound.method),
            "computation": _schema_shapes(self.computation, self.ideal_bound.method),
            "notes": list(self.notes),
        }

    # ------------------------------------------------------------ the pre-redesign view
    @property
    def source(self) -> str:
        """``"table"`` or ``"computed"`` (the pre-redesign name of the route)."""
        return "table" if self.route == "table" else "computed"

    @property
    def extra(self) -> dict[str, Any]:
        """``details`` and ``computation`` flattened under their pre-redesign names.

        Kept for callers written before the typed answer (``extra["svm_f1"]``,
        ``extra["delta_e_upper"]``, ``extra["evaluations"]``, ``extra["wall_s"]``);
        new code reads ``details`` and ``computation``.
        """
        out: dict[str, Any] = dict(self.computation)
        d = dict(self.details)
        if self.question == "delta-e":
            for side in ("lower", "upper"):
                part = d.get(side) or {}
                key = f"delta_e_{side}"
                out[key] = part.get("value")
                out[key + "_interval"] = list(part.get("interval") or [None, None])
                out[key + "_ideal"] = part.get("ideal")
        else:
            out.update(d)
        return out


_FIELDS = frozenset(f.name for f in fields(Answer))

#: The parts of an answer's dictionary a record (one flat row: CSV, pandas) keeps, flattened ``part_key``;
#: ``scene``'s keys keep their own names (``contact_s`` ...).
RECORD_PARTS = ("interval", "ideal", "table", "ideal_table")


def to_record(answer: Mapping[str, Any]) -> dict[str, Any]:
    """An answer's dictionary (:meth:`Answer.to_dict`) as one flat record: the scalars, ``interval_low``,
    ``ideal_value``, ``table_name`` ... (nested keys joined by ``_``), the scene's quantities; the same keys
    as each record of :meth:`designkit.query.vectorized.ArrayAnswer.to_dict` (docs/schema.md, "Records").

    >>> to_record({"value": 1.0, "interval": {"low": 0.5, "high": 2.0, "meaning": "..."}, "notes": []})
    {'value': 1.0, 'interval_low': 0.5, 'interval_high': 2.0}
    """
    out: dict[str, Any] = {}
    for k, v in answer.items():
        if k == "scene" and isinstance(v, Mapping):
            out.update(v)
        elif k in RECORD_PARTS and isinstance(v, Mapping):
            out.update({f"{k}_{kk}": vv for kk, vv in v.items() if kk != "meaning" and not isinstance(vv, (dict, list))})
        elif k in RECORD_PARTS and v is None:
            out[f"{k}_name" if "table" in k else f"{k}_value"] = None
        elif k == "in_grid" and isinstance(v, Mapping):
            out[k] = all(v.values())
        elif not isinstance(v, (dict, list, tuple)):
            out[k] = v
    return out


def ideal_floor(value: float | None, interval: Sequence | None) -> float | None:
    """The floor an SVM answer's interval is held above: the ideal bound's low end where the bound is a
    Monte Carlo estimate with an interval (``(low, high, ...)``), else the bound itself.

    >>> ideal_floor(1.41, (1.39, 1.42, 0.9)), ideal_floor(1.05, None)
    (1.39, 1.05)
    """
    return value if interval is None else interval[0]
