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
on a table with varied initial conditions, or on one whose model has no closed-form
ideal observer (a calibrated rig's), averages the two instead, and interpolates each
scene slice's answer rather than the need (:func:`varied_contact_estimate`; why:
docs/decisions-log.md, "Question layer").

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

import math
from typing import Any, Mapping, Sequence

import numpy as np

from .._validation import InputError
from ..tables.lookup import GRID_RTOL
from ..tables.store import Table
from .answer import Answer, IdealBound, number, scene_record
from .crossing import check_coverage, z_of_coverage
from .efficiency import CLOSED_FORM_MAX_CONTACT_S, K_SLOPE_SPAN, k_baseline, noise_k_max_ratio, noise_k_min_contact, \
    table_z
from .estimates import (ABOVE, BELOW, CELL, CONTACT_ESTIMATORS, RATIO_ESTIMATORS, axis_weights_flagged, filled,
                        states_coverage, table_spread)
from .inputs import REFERENCE_RULE, PairQuestion, TableMismatch, check_contact, pair_question, reference_class, \
    scene_inputs
from .table_arrays import (CLOSED_FORM_RATIO_BRACKET, TableView, contact_arrays, delta_e_arrays,
                           distinguishable_arrays, ratio_arrays)
from .table_open import (DEFAULT_IDEAL_TABLE, DEFAULT_TABLE, SPREAD_TABLE_QUESTIONS, VARIED_TABLE, OpenedTable,
                         as_table, clear_table_cache, delta_e_ideal_view, open_table, shipped_spread_table)

__all__ = [
    "CLOSED_FORM_MAX_CONTACT_S", "CLOSED_FORM_RATIO_BRACKET", "CONTACT_ESTIMATORS", "DEFAULT_IDEAL_TABLE",
    "DEFAULT_TABLE", "GRID_KINDS", "GRID_RTOL", "K_SLOPE_SPAN", "RATIO_ESTIMATORS", "SPREAD_TABLE_QUESTIONS",
    "VARIED_TABLE", "clear_table_cache", "delta_e", "distinguishable", "grid_answer", "k_baseline", "max_noise",
    "min_contact", "min_delta_t", "noise_k_max_ratio", "noise_k_min_contact", "open_table", "shipped_spread_table",
    "EACH", "PAIR_KEYS", "distinguishable_each", "max_noise_each", "min_contact_each", "min_delta_t_each",
    "table_spread", "table_z",
]

_as_table = as_table  # (the name tests and the lab know)


# ============================================================ in-grid flags, in the user's units
def _axis_range(view: TableView, name: str) -> tuple[float, float]:
    vals = view.t.axes[name]
    return float(vals.min()), float(vals.max())


_AXIS_WORDS = {"noise_ratio": ("sigma/dT", ""), "noise_c": ("noise sigma", " degC"),
               "delta_t_c": ("temperature difference", " degC"), "contact_s": ("contact time", " s")}


def _outside_notes(view: TableView, flags: dict[str, bool], wanted: dict[str, Any]) -> list[str]:
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


def _scene_wanted(view: TableView, noise, dt) -> dict[str, Any]:
    if view.scene_axes == ["noise_ratio"]:
        return {"noise_ratio": None if noise is None or dt is None else noise / abs(dt), "noise_c": noise,
                "delta_t_c": dt}
    return {"noise_c": noise, "delta_t_c": dt}


# ============================================================ one answer builder for the route
def _answer(question: str, op: OpenedTable, *, objects, limiting, rule: str, scene: dict, value, interval,
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
        sensor=op.view.sensor_dict(), model=op.model.to_dict(), model_check=check, threshold=op.phi,
        table=op.tab.name, table_hash=op.tab.header.get("content_hash"), ideal_table=ideal_table,
        ideal_table_hash=op.ihash if ideal_table else None, in_grid=dict(in_grid), details=details,
        computation={"fidelity": op.tab.fidelity, "table_contacts_s": op.view.contacts.tolist(),
                     **(computation or {})},
        notes=tuple(n for n in notes if n), interval_kind=interval_kind, interval_coverage=interval_coverage)


#: Why a table with varied initial conditions states no coverage outside its min-contact and delta-e estimates
#: (``benchmarks/bench_coverage_varied.py``, results in benchmarks/results/bench_coverage_varied.txt: 200
#: random min-contact cases on svm-paper-varied against 16-seed exact references, seeds 1 and 2).
VARIED_COVERAGE_NOTE = (
    "this table varies the initial conditions, and this answer is its grid cell or the grid rule's reading, "
    "not one of its min-contact estimates (whose 90% intervals held the exact answer in 85 of 96 random "
    "cases): it states no coverage (such answers held it in 10 of 14); --exact states one (a few seconds for "
    "the pair)")


def _no_pair(question: str, op: OpenedTable, pq: PairQuestion, scene: dict, details: dict) -> Answer:
    """The materials overlap: no answer, said so."""
    return _answer(question, op, objects=pq.objects_dicts(), limiting=(), rule=pq.rule, scene=scene,
                   value=None, interval=(None, None), ideal=None, in_grid={}, details=details, notes=[pq.note])


def _el(r: dict, key: str, i: int) -> float | None:
    """Element ``i`` of an array answer's ``key`` (None for NaN)."""
    return number(r[key][i])


#: The object arguments of a pair question (each element of ``pairs`` in the ``*_each`` functions holds some).
PAIR_KEYS = ("e1", "e2", "m1", "m2", "objects")


def _pairs(pairs, op: OpenedTable) -> tuple[list[PairQuestion], list[int]]:
    """Each element's :func:`~designkit.query.inputs.pair_question` (a mapping of :data:`PAIR_KEYS`), and the
    indices of those with two classes to answer for (the others overlap)."""
    pqs = [pair_question(*(p.get(k) for k in PAIR_KEYS[:4]), objects=p.get("objects"), width=op.width,
                         model=op.model) for p in pairs]
    return pqs, [i for i, pq in enumerate(pqs) if pq.classes is not None]


def _points(pqs: list[PairQuestion], asked: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """The pairs' lower edges ``lo < hi`` [J s^-1/2 K^-1 m^-2] of the elements ``asked``, as arrays."""
    pts = np.array([pqs[i].points for i in asked], dtype=np.float64).reshape(len(asked), 2)
    return pts[:, 0], pts[:, 1]


# ============================================================ min-contact
def min_contact(e1: float | None = None, e2: float | None = None, *, m1: str | None = None,
                m2: str | None = None, objects=None, **options: Any) -> Answer:
    """Shortest contact time [s] that separates two objects, from a table: :func:`min_contact_each` of the one
    pair (element 0 of :func:`~designkit.query.table_arrays.contact_arrays`; its estimators:
    :data:`CONTACT_ESTIMATORS`).

    Parameters
    ----------
    e1, e2 : float, optional
        Effusivities [J s^-1/2 K^-1 m^-2].
    m1, m2 : str, optional
        Material names instead (answered by the materials rule, :mod:`designkit.query.inputs`).
    objects : (ObjectClass, ObjectClass), optional
        The classes instead.
    noise_c : float
        Noise sigma per sample [degC] (default 0.05).
    delta_t_c : float
        Sensor minus object temperature before contact [degC] (default 10).
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
        varied initial conditions :func:`~designkit.query.estimates.varied_contact_estimate`); the grid
        cell, coverage not stated, where a neighbour lies beyond the grid.

    Examples
    --------
    >>> min_contact(35000, 20000, table="ideal-paper").to_dict()["quantity"]
    'contact_s'
    """
    return min_contact_each([{"e1": e1, "e2": e2, "m1": m1, "m2": m2, "objects": objects}], **options)[0]


def min_contact_each(pairs: Sequence[Mapping[str, Any]], *, noise_c: float = 0.05, delta_t_c: float = 10.0,
                     threshold: float | None = None, table: "Table | str" = DEFAULT_TABLE,
                     ideal_table: "Table | str | None" = DEFAULT_IDEAL_TABLE, sensor=None, model=None,
                     coverage: float = 0.9, sensor_temp_spread_c: float = 0.0,
                     ideal_bound: bool = True) -> list[Answer]:
    """:func:`min_contact` of each pair of ``pairs`` (each a mapping of :data:`PAIR_KEYS`) in one scene, from one
    :func:`~designkit.query.table_arrays.contact_arrays` call over them all: element ``i`` is what
    :func:`min_contact` answers for pair ``i`` (the other arguments as there)."""
    noise, dt = scene_inputs(noise_c, delta_t_c)
    coverage = check_coverage(coverage)
    op = open_table(table, ideal_table, threshold=threshold, sensor=sensor, model=model,
                    sensor_temp_spread_c=sensor_temp_spread_c)
    pqs, asked = _pairs(pairs, op)
    view = op.view
    scene_flags = view.scene_weights(noise, dt)[1]
    r = {}
    if asked:
        lo, hi = _points(pqs, asked)
        m = lo.size
        r = contact_arrays(op, lo, hi, filled(m, noise, np.float64), filled(m, dt, np.float64),
                           ideal_bound=ideal_bound or op.closed,
                           zc=z_of_coverage(coverage), classes=[pqs[i].classes for i in asked])
    at = {i: j for j, i in enumerate(asked)}
    return [_no_pair("min-contact", op, pq, scene_record(None, noise, dt), {}) if pq.classes is None else
            _contact_answer(op, pq, r, at[i], noise, dt, dict(scene_flags), coverage, ideal_bound)
            for i, pq in enumerate(pqs)]


def _contact_answer(op: OpenedTable, pq: PairQuestion, r: dict, i: int, noise: float, dt: float,
                    flags: dict[str, bool], coverage: float, ideal_bound: bool) -> Answer:
    """min-contact's answer for ``pq`` from element ``i`` of :func:`~designkit.query.table_arrays.contact_arrays`'
    ``r`` (``flags``: the scene's in-grid flags)."""
    lo, hi = pq.points
    view = op.view
    flags["effusivity"] = view.e_in_grid(lo, hi)
    common = dict(objects=pq.objects_dicts(), limiting=pq.limiting_dicts(), rule=pq.rule,
                  scene=scene_record(None, noise, dt), classes=pq.classes)
    ideal = _el(r, "ideal", i)
    if not all(flags.values()):
        wanted = {**_scene_wanted(view, noise, dt), "effusivity": (lo, hi)}
        return _answer("min-contact", op, value=None, interval=(None, None), ideal=ideal if ideal_bound else None,
                       ideal_method="closed-form", in_grid=flags, details={},
                       notes=_outside_notes(view, flags, wanted), **common)
    raw, kind = _el(r, "raw", i), r["kind"][i]
    computation: dict[str, Any] = {"monte_carlo_interval": [_el(r, "mc_lo", i), _el(r, "mc_hi", i)]}
    if "delta_up_ideal" in view.t.arrays:  # the grid's own bound, beside the exact one (its interpolation error)
        computation["table_ideal_s"] = _el(r, "table_ideal", i)
    ideal_interval, ideal_method = None, "closed-form" if op.closed else "table"
    if not op.closed and ideal_bound:  # no closed form: the Monte Carlo bound at query time
        mcb = r["mc_bounds"][i]
        ideal, ideal_method, ideal_interval = mcb.value, "monte-carlo", mcb.interval
        computation["ideal_monte_carlo"] = {"n_mc": mcb.n_mc, "evaluations": len(mcb.evaluations)}
    value, note = _el(r, "value", i), ""
    if kind in ("table-varied-estimate", "table-estimate"):
        computation.update(interpolation_error_log=float(r["interp"][i]), rounding_error_log=float(r["rounding"][i]),
                           table_crossing_s=raw)
    elif kind == "table-efficiency":
        e = {k: float(r[f"eff_{k}"][i]) for k in ("k", "se_log", "k_a", "k_b", "t_a", "t_b")}
        computation.update(efficiency=e["k"], efficiency_se_log=e["se_log"], table_crossing_s=raw,
                           noise_efficiency_at_s={f"{e['t_a']:g}": e["k_a"], f"{e['t_b']:g}": e["k_b"]})
        first = float(view.contacts[0])
        if value < first:  # the efficiency at the first contact times, applied below them: said, not hidden
            computation["below_grid"] = True
            note = (f"{value:.3g} s lies below the table's first contact time, {first:g} s: the SVM's noise "
                    "efficiency read there is applied to the exact ideal observer (an extrapolation in contact "
                    "time; docs/accuracy.md measures it)")
    elif kind == "table-cell":
        note = _cell_note(op, int(r["k_cross"][i]), _el(r, "low", i), value)
    else:
        note = (f"no tabulated contact time up to {view.contacts[-1]:g} s separates them "
                "(the exact route examines longer contacts)")
    needed = value if value is not None else float(view.contacts[-1])
    return _answer("min-contact", op, value=value, interval=(_el(r, "low", i), _el(r, "high", i)), ideal=ideal,
                   ideal_method=ideal_method, ideal_interval=ideal_interval, in_grid=flags, details={}, notes=[note],
                   check_at=(needed, noise, dt), interval_kind=kind,
                   interval_coverage=coverage if r["stated"][i] else None, computation=computation, **common)


def _cell_note(op, k: int, low: float, value: float) -> str:
    """Why min-contact's answer is a grid cell, and the cell."""
    prev = float(op.view.contacts[k - 1]) if k > 0 else 0.0
    why = ("the table's first contact time" if k == 0 else
           f"the table's next contact time after {prev:g} s, where they are not separable within its "
           "effusivity range")
    if states_coverage(op.tab, "min-contact", "table-cell"):
        return (f"{value:g} s is {why}: the shortest time lies in ({low:g}, {value:g}] s and the grid cannot "
                "support an interval of stated coverage there (the exact route estimates it)")
    note = f"{value:g} s is {why}: the grid cell is ({low:g}, {value:g}] s"  # VARIED_COVERAGE_NOTE: no claim
    if table_spread(op.tab) > 0 and prev > 0:
        note += " (from the ideal bound: with the initial temperature varied, F1 need not rise with contact time)"
    return note


# ============================================================ max-noise / min-delta-t
def _ratio_each(question: str, pairs, *, contact_s: float, noise_c, delta_t_c, threshold=None, table=DEFAULT_TABLE,
                ideal_table=DEFAULT_IDEAL_TABLE, sensor=None, model=None, coverage: float = 0.9,
                sensor_temp_spread_c: float = 0.0) -> list[Answer]:
    """max-noise's or min-delta-t's answer for each pair of ``pairs`` in one scene, from one
    :func:`~designkit.query.table_arrays.ratio_arrays` call over them all."""
    contact = check_contact(contact_s)
    coverage = check_coverage(coverage)
    if question == "max-noise":
        _, dt = scene_inputs(0.0, delta_t_c)
        noise, scale = None, abs(dt)
    else:
        noise, _ = scene_inputs(noise_c, 1.0)
        if noise == 0:
            raise InputError("noise sigma is 0: any temperature difference separates them (no smallest one)")
        dt, scale = None, noise
    op = open_table(table, ideal_table, threshold=threshold, sensor=sensor, model=model,
                    sensor_temp_spread_c=sensor_temp_spread_c)
    if "noise_ratio" not in op.tab.axes:
        raise TableMismatch(f"table {op.tab.name} has separate noise and temperature axes (varied initial "
                            f"conditions): it cannot answer {question}; the exact route can")
    pqs, asked = _pairs(pairs, op)
    r = {}
    if asked:
        lo, hi = _points(pqs, asked)
        r = ratio_arrays(question, op, lo, hi, np.full(lo.size, contact), np.full(lo.size, scale), ideal_bound=True,
                         zc=z_of_coverage(coverage))
    at = {i: j for j, i in enumerate(asked)}
    return [_no_pair(question, op, pq, scene_record(contact, noise, dt), {}) if pq.classes is None else
            _ratio_answer(question, op, pq, r, at[i], contact, noise, dt, scale, coverage) for i, pq in enumerate(pqs)]


def _ratio_answer(question: str, op: OpenedTable, pq: PairQuestion, r: dict, i: int, contact: float, noise, dt,
                  scale: float, coverage: float) -> Answer:
    """max-noise's or min-delta-t's answer for ``pq`` from element ``i`` of
    :func:`~designkit.query.table_arrays.ratio_arrays`' ``r``."""
    lo, hi = pq.points
    view = op.view
    flags = {"contact_s": axis_weights_flagged(view.contacts, contact)[1], "effusivity": view.e_in_grid(lo, hi)}
    common = dict(objects=pq.objects_dicts(), limiting=pq.limiting_dicts(), rule=pq.rule,
                  scene=scene_record(contact, noise, dt), classes=pq.classes)
    ideal = _el(r, "ideal", i)
    if not all(flags.values()):
        notes = _outside_notes(view, flags, {"contact_s": contact, "effusivity": (lo, hi)})
        return _answer(question, op, value=None, interval=(None, None), ideal=ideal, ideal_method="closed-form",
                       in_grid=flags, details={}, notes=notes, **common)

    def to_answer(x):
        return None if x is None else x * scale if question == "max-noise" else scale / x

    where, rr, kind = int(r["where"][i]), _el(r, "r", i), r["kind"][i]
    ratios = view.t.axes["noise_ratio"]
    if where == ABOVE:
        flags["noise_ratio"] = False
    # the Monte Carlo ends: more noise allowed at the optimistic end ('lo': ratio >= the answer's)
    ends = [to_answer(_el(r, k, i)) for k in ("end_hi", "end_lo_any")]
    mc = tuple(sorted(ends)) if None not in ends else tuple(ends)
    computation: dict[str, Any] = {"monte_carlo_interval": list(mc)}
    note = ""
    if kind == "table-efficiency":
        computation.update(table_crossing_noise_ratio=rr, efficiency=float(r["eff_k"][i]),
                           efficiency_se_log=float(r["eff_se_log"][i]))
    elif kind == "table-estimate":
        computation.update(table_crossing_noise_ratio=rr, interpolation_error_log=float(r["interp"][i]),
                           rounding_error_log=float(r["rounding"][i]))
    elif kind == "table-cell" and where == CELL:
        note = (f"sigma/dT {rr:g} is the table's last noise ratio where they separate; at the next, "
                f"{float(r['next_ratio'][i]):g}, the pair lies beyond its effusivity range: the answer lies between "
                "them and the grid cannot support an interval of stated coverage there (the exact route estimates it)")
    elif kind == "table-cell":
        more = "at least" if question == "max-noise" else "at most"  # a larger ratio: more noise, a smaller dT
        note = (f"separable even at the table's largest noise ratio sigma/dT = {rr:g}: the answer is {more} this "
                "(the exact route looks further) (the grid cannot support an interval of stated coverage there)")
    elif where == BELOW:
        note = f"not separable even at the table's smallest noise ratio sigma/dT = {ratios[0]:g}"
    answered = _el(r, "ratio", i) if kind in ("table-efficiency", "table-estimate") else rr
    r_check = answered if answered is not None else float(ratios[0])
    check_at = ((contact, r_check * scale, dt) if question == "max-noise"
                else (contact, noise, noise / r_check))
    return _answer(question, op, value=_el(r, "value", i), interval=(_el(r, "low", i), _el(r, "high", i)), ideal=ideal,
                   ideal_method="closed-form" if op.closed else "table", in_grid=flags, details={}, notes=[note],
                   check_at=check_at, interval_kind=kind, interval_coverage=coverage if r["stated"][i] else None,
                   computation=computation, **common)


def max_noise(e1=None, e2=None, *, m1=None, m2=None, objects=None, **options: Any) -> Answer:
    """Largest noise sigma [degC] at which ``contact_s`` still separates the objects (table): element 0 of
    :func:`~designkit.query.table_arrays.ratio_arrays` (its estimators: :data:`RATIO_ESTIMATORS`).

    Arguments as :func:`min_contact`; ``contact_s`` [s] is the contact time (no ``noise_c``); many pairs:
    :func:`max_noise_each`.
    """
    return max_noise_each([{"e1": e1, "e2": e2, "m1": m1, "m2": m2, "objects": objects}], **options)[0]


def min_delta_t(e1=None, e2=None, *, m1=None, m2=None, objects=None, **options: Any) -> Answer:
    """Smallest sensor-object temperature difference [degC] that separates the objects (table), as
    :func:`max_noise`.

    Arguments as :func:`min_contact`; ``contact_s`` [s] is the contact time (no ``delta_t_c``); many pairs:
    :func:`min_delta_t_each`.
    """
    return min_delta_t_each([{"e1": e1, "e2": e2, "m1": m1, "m2": m2, "objects": objects}], **options)[0]


def max_noise_each(pairs: Sequence[Mapping[str, Any]], *, contact_s: float, delta_t_c: float = 10.0,
                   **options: Any) -> list[Answer]:
    """:func:`max_noise` of each pair of ``pairs`` (as :func:`min_contact_each`), from one array call."""
    return _ratio_each("max-noise", pairs, contact_s=contact_s, noise_c=None, delta_t_c=delta_t_c, **options)


def min_delta_t_each(pairs: Sequence[Mapping[str, Any]], *, contact_s: float, noise_c: float = 0.05,
                     **options: Any) -> list[Answer]:
    """:func:`min_delta_t` of each pair of ``pairs`` (as :func:`min_contact_each`), from one array call."""
    return _ratio_each("min-delta-t", pairs, contact_s=contact_s, noise_c=noise_c, delta_t_c=None, **options)


# ============================================================ delta-e
def delta_e(e: float | None = None, *, m: str | None = None, contact_s: float, noise_c: float = 0.05,
            delta_t_c: float = 10.0, threshold=None, table=DEFAULT_TABLE, ideal_table=DEFAULT_IDEAL_TABLE,
            sensor=None, model=None, coverage: float = 0.9,
            sensor_temp_spread_c: float = 0.0, ideal_bound: bool = True) -> Answer:
    """delta(e) towards lower and higher effusivity [J s^-1/2 K^-1 m^-2] (table): element 0 of
    :func:`~designkit.query.table_arrays.delta_e_arrays`.

    ``value`` is the smaller of the two; ``details["lower"]`` and
    ``details["upper"]`` hold each direction's value, interval at ``coverage``
    (the table's Monte Carlo interval rescaled, combined with the interpolation
    error: linear against log-space interpolation over contact time and sigma/dT)
    and ideal bound (None: nothing distinguishable within the grid that way).
    ``interval`` is the interval of the direction giving ``value``. ``m``: a
    material, its range's middle as the reference. ``ideal_bound``: as :func:`min_contact`'s (each
    direction's bound by Monte Carlo where no closed form holds, or False: the table's own floor).
    """
    from .ideal_mc_bound import nearer_side_interval

    contact = check_contact(contact_s)
    coverage = check_coverage(coverage)
    noise, dt = scene_inputs(noise_c, delta_t_c)
    op = open_table(table, ideal_table, threshold=threshold, sensor=sensor, model=model,
                    sensor_temp_spread_c=sensor_temp_spread_c)
    ref = reference_class(e, m, width=op.width, model=op.model)
    x = ref.e_range[0]
    view = op.view
    flags = view.scene_weights(noise, dt)[1]
    flags["contact_s"] = axis_weights_flagged(view.contacts, contact)[1]
    flags["effusivity"] = view.e_in_grid(x)
    common = dict(objects=(ref.to_dict(),), limiting=(ref.to_dict(),), rule=REFERENCE_RULE,
                  scene=scene_record(contact, noise, dt), classes=(ref,))
    r = delta_e_arrays(op, *np.array([[x], [contact], [noise], [dt]], dtype=np.float64), ideal_view=delta_e_ideal_view(op, ideal_table),
                       zc=z_of_coverage(coverage), ideal_bound=ideal_bound, classes=[ref])
    if not all(flags.values()):
        wanted = {**_scene_wanted(view, noise, dt), "contact_s": contact, "effusivity": (x,)}
        sides = {side: _no_side(_el(r, f"{side}_ideal", 0)) for side in ("lower", "upper")}
        return _answer("delta-e", op, value=None, interval=(None, None), ideal=_el(r, "ideal", 0),
                       ideal_method="closed-form", in_grid=flags, details=_delta_details(x, sides),
                       notes=_outside_notes(view, flags, wanted), **common)
    sides = {}
    for side in ("lower", "upper"):
        method = r[f"{side}_method"][0]
        iv = [_el(r, f"{side}_mc_lo", 0), _el(r, f"{side}_mc_hi", 0)]
        if method == "table-efficiency":  # the SVM's efficiency against the exact ideal observer
            sides[side] = {"value": float(r[side][0]), "interval": [float(r[f"{side}_low"][0]),
                                                                    float(r[f"{side}_high"][0])],
                           "ideal": float(r[f"{side}_ideal"][0]), "coverage": coverage,
                           "estimate_method": method, "monte_carlo_interval": iv,
                           "table_value": _el(r, f"{side}_table", 0), "table_ideal": _el(r, f"{side}_table_ideal", 0),
                           "efficiency": float(r[f"{side}_efficiency"][0])}
            continue
        stated = method == "table-estimate"
        sides[side] = {"value": _el(r, f"{side}_table", 0),
                       "interval": [_el(r, f"{side}_low", 0), _el(r, f"{side}_high", 0)] if stated else [None, None],
                       "ideal": _el(r, f"{side}_ideal", 0), "coverage": coverage if stated else None,
                       "estimate_method": method, "monte_carlo_interval": iv}
        if not op.closed and ideal_bound:  # the Monte Carlo bound, the grid's kept beside it
            mcb = r[f"{side}_mc_bounds"][0]
            sides[side].update(table_ideal=_el(r, f"{side}_table_ideal", 0),
                               ideal_interval=list(mcb.interval[:2]) if mcb.interval else None)
    kind = r["kind"][0]
    stated = kind != "none"
    return _answer("delta-e", op, value=_el(r, "value", 0),
                   interval=(_el(r, "low", 0), _el(r, "high", 0)) if stated else (None, None),
                   interval_kind=kind, interval_coverage=coverage if stated else None, ideal=_el(r, "ideal", 0),
                   ideal_method="closed-form" if kind == "table-efficiency" else "table" if op.closed or not ideal_bound
                   else "monte-carlo",
                   ideal_interval=nearer_side_interval(sides, coverage),
                   in_grid=flags, details=_delta_details(x, sides), check_at=(contact, noise, dt), **common)


def _no_side(ideal: float | None = None) -> dict[str, Any]:
    """One side of delta-e's details with no answer from the table (a new dict each time)."""
    return {"value": None, "interval": [None, None], "ideal": ideal, "coverage": None, "estimate_method": "none"}


def _delta_details(e: float, sides: dict) -> dict[str, Any]:
    return {"e": e, "lower": sides.get("lower") or _no_side(), "upper": sides.get("upper") or _no_side()}


# ============================================================ distinguishable
def distinguishable(e1=None, e2=None, *, m1=None, m2=None, objects=None, **options: Any) -> Answer:
    """Whether ``contact_s`` [s] separates the objects (table), with the ideal observer's F1 (closed form): element 0
    of :func:`~designkit.query.table_arrays.distinguishable_arrays` (arguments as :func:`min_contact`; many
    pairs: :func:`distinguishable_each`).

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
    return distinguishable_each([{"e1": e1, "e2": e2, "m1": m1, "m2": m2, "objects": objects}], **options)[0]


def distinguishable_each(pairs: Sequence[Mapping[str, Any]], *, contact_s: float, noise_c: float = 0.05,
                         delta_t_c: float = 10.0, threshold=None, table=DEFAULT_TABLE,
                         ideal_table=DEFAULT_IDEAL_TABLE, sensor=None, model=None, coverage: float = 0.9,
                         sensor_temp_spread_c: float = 0.0) -> list[Answer]:
    """:func:`distinguishable` of each pair of ``pairs`` (as :func:`min_contact_each`), from one
    :func:`~designkit.query.table_arrays.distinguishable_arrays` call over them all."""
    coverage = check_coverage(coverage)
    contact = check_contact(contact_s)
    noise, dt = scene_inputs(noise_c, delta_t_c)
    op = open_table(table, ideal_table, threshold=threshold, sensor=sensor, model=model,
                    sensor_temp_spread_c=sensor_temp_spread_c)
    pqs, asked = _pairs(pairs, op)
    view = op.view
    scene_flags = view.scene_weights(noise, dt)[1]
    scene_flags["contact_s"] = axis_weights_flagged(view.contacts, contact)[1]
    zc = z_of_coverage(coverage)
    r = {}
    if asked:
        lo, hi = _points(pqs, asked)
        m = lo.size
        r = distinguishable_arrays(op, lo, hi, np.full(m, contact), np.full(m, noise), np.full(m, dt),
                                   ideal_bound=True, zc=zc, ideal_view=delta_e_ideal_view(op, ideal_table),
                                   classes=[pqs[i].classes for i in asked])
    at = {i: j for j, i in enumerate(asked)}
    return [_no_pair("distinguishable", op, pq, scene_record(contact, noise, dt), _empty_verdict())
            if pq.classes is None else
            _distinguishable_answer(op, pq, r, at[i], contact, noise, dt, dict(scene_flags), coverage)
            for i, pq in enumerate(pqs)]


def _empty_verdict() -> dict[str, Any]:
    """distinguishable's details where it answers nothing (a new dict each time)."""
    return {"distinguishable": None, "svm_f1": None, "svm_standard_error": None, "verdict": None,
            "ideal_f1": None, "ideal_distinguishable": None}


def _distinguishable_answer(op: OpenedTable, pq: PairQuestion, r: dict, i: int, contact: float, noise: float,
                            dt: float, flags: dict[str, bool], coverage: float) -> Answer:
    """distinguishable's answer for ``pq`` from element ``i`` of
    :func:`~designkit.query.table_arrays.distinguishable_arrays`' ``r`` (``flags``: the scene's in-grid flags)."""
    lo, hi = pq.points
    view = op.view
    flags["effusivity"] = view.e_in_grid(lo, hi)
    common = dict(objects=pq.objects_dicts(), limiting=pq.limiting_dicts(), rule=pq.rule,
                  scene=scene_record(contact, noise, dt), classes=pq.classes)
    ideal_f1, ideal_method = _el(r, "ideal", i), r["ideal_method"][i]
    ideal_details = {} if ideal_f1 is None else {"ideal_f1": ideal_f1, "ideal_distinguishable": ideal_f1 >= op.phi}
    if not all(flags.values()):
        wanted = {**_scene_wanted(view, noise, dt), "contact_s": contact, "effusivity": (lo, hi)}
        return _answer("distinguishable", op, value=None, interval=(None, None), ideal=ideal_f1,
                       ideal_method=ideal_method, in_grid=flags, details={**_empty_verdict(), **ideal_details},
                       notes=_outside_notes(view, flags, wanted), **common)
    grid = {k: bool(r[f"grid_{k}"][i]) for k in ("svm", "lo", "hi")}
    yes, sure = bool(r["value"][i]), r["verdict"][i]
    t_min, interval = _el(r, "mc_value", i), (_el(r, "mc_low", i), _el(r, "mc_high", i))
    mc_kind = r["mc_kind"][i]
    mc_stated = bool(r["mc_stated"][i])
    if not states_coverage(op.tab, "min-contact", mc_kind):
        mc_kind = "table-varied"
    note = _contact_verdict(contact, t_min, interval, mc_kind, mc_stated, coverage)
    if r["unsure"][i]:  # inside min-contact's interval: max-noise or delta-e may still be sure of it
        mn = tuple(_el(r, f"mn_{k}", i) for k in ("value", "low", "high"))
        reads = _other_readings(noise, hi - lo, None if mn[0] is None else mn,
                                [tuple(_el(r, f"de_{side}_{k}", i) for k in ("value", "low", "high"))
                                 for side in ("upper", "lower")])
        a, b = interval
        inside = (f"{contact:g} s lies inside min-contact's interval ({t_min:.3g} s, {a:.3g} to {_fmt_or_open(b)} s)"
                  if a is not None else f"{contact:g} s is near min-contact's {t_min:.3g} s")
        if r["decided"][i]:
            note = f"verdict confident: {' and '.join(w for _, _, w in reads)} (while {inside})"
        elif reads:
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
                                "min_contact_s": t_min, "min_contact_interval_s": list(interval),
                                "min_contact_interval_kind": mc_kind if t_min is not None else "none"}, **common)

#: The questions answered for many pairs in one array call: question -> its ``*_each`` function (delta-e asks
#: about one reference, not a pair).
EACH = {"min-contact": min_contact_each, "max-noise": max_noise_each, "min-delta-t": min_delta_t_each,
        "distinguishable": distinguishable_each}


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


def _contact_verdict(contact: float, t: float | None, interval: tuple, kind: str, stated: bool,
                     coverage: float) -> str:
    """Why a yes/no on ``contact`` [s] against min-contact's answer ``t`` [s] (its ``interval``, of ``kind``,
    ``stated``: at ``coverage``) is as sure as it is, in words."""
    a, b = interval
    if t is None:
        return "no: no contact time within the table's grid separates them (min-contact answers none)"
    said = f"min-contact {t:.3g} s"
    if stated and a is not None:
        iv = (f"the {coverage:.0%} interval of the shortest separating contact ({said}, {a:.3g} to "
              f"{_fmt_or_open(b)} s)")
        if a <= contact <= (b if b is not None else math.inf):
            return (f"verdict uncertain: {contact:g} s lies inside {iv}: the table cannot tell; "
                    "--exact computes this pair's F1")
        return f"verdict confident: {contact:g} s lies {'above' if contact > t else 'below'} {iv}"
    if kind in ("table-cell", "table-varied") and a is not None and a < contact <= (b if b is not None else math.inf):
        where = "the grid cell" if kind == "table-cell" else "the interval"
        return (f"verdict uncertain: {contact:g} s lies in {where} ({a:.3g}, {_fmt_or_open(b)}] "
                f"s where the shortest separating contact is ({said}; no stated coverage there)")
    return f"{contact:g} s against {said} (no interval of stated coverage there)"


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
