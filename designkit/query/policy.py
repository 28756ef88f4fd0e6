"""Which route answers a question, and why: the policy of ``ask(..., route="auto")``.

A question is read from a table when one is built for the sensor, forward model and scene asked
(milliseconds), and computed for the pair otherwise (the exact route, seconds); a table that is named
is read (and refused when it was built for another sensor, model, threshold or spread: never used
silently for another one). :func:`table_for` is the one place that asks "is there a table for this
sensor, model and scene"; :func:`choose_route` applies it to a call's arguments and says why
(``Answer.route_reason``, shown by ``--explain`` and in ``--json``).

Examples
--------
>>> table_for("min-contact").table
'svm-fine'
>>> choose_route("min-contact", "auto", {"e1": 35000, "e2": 20000})[0]
'table'
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping

from .._validation import InputError
from ..sensor import load_sensor
from .inputs import NeedsInput, table_reroute
from .table_open import DEFAULT_TABLE, shipped_spread_table

__all__ = ["EXACT_OPTIONS", "MC_BOUND", "OutsideSensorTable", "ROUTES", "TABLE_OPTIONS", "TableChoice", "choose_route", "sensor_table_answer",
           "table_for"]

#: The routes a question may be asked by (``auto``: :func:`choose_route` decides).
ROUTES = ("auto", "table", "exact")
#: Options only the table route takes, and only the exact route: under ``auto`` those of the route not taken
#: are left out (the answer's ``route`` and ``route_reason`` say which one answered).
TABLE_OPTIONS = frozenset({"table", "ideal_table"})
EXACT_OPTIONS = frozenset({"diffusivity_m2_s", "width", "trials", "folds", "seed", "repeats", "z", "jobs", "n_mc",
                           "max_contact_s", "tolerance_s", "progress", "solver", "e_max"})


@dataclass(frozen=True)
class TableChoice:
    """The table that answers a question (``table``: a name or path; None: none does) and why (``reason``);
    ``noted``: the reason belongs in the answer's notes too (it answers for another sensor or model than the
    tables are built for); ``sensor_table``: the table was built for this sensor file (``designkit tables
    build``, :func:`designkit.tables.registry.table_for_sensor`): read without the paper's ideal table
    (:func:`sensor_table_answer`); ``loaded``: that table, loaded and checked (the route does not read it again)."""

    table: str | None
    reason: str
    noted: bool = False
    sensor_table: bool = False
    loaded: Any = field(default=None, compare=False, repr=False)


def table_for(question: str, *, sensor=None, model=None, sensor_temp_spread_c: float = 0.0,
              delta_t_c: float | None = None) -> TableChoice:
    """Is there a table for this sensor, model and scene? The one place the route policy asks it.

    Parameters
    ----------
    question : str
        A name of :data:`designkit.query.QUESTIONS`.
    sensor : name, path or Sensor, optional
        The sensor asked about (default the paper's); a sensor file's own model counts when ``model`` is None.
    model : ForwardModel or name, optional
        The forward model asked for.
    sensor_temp_spread_c : float
        Half-width [degC] of the per-touch sensor temperature (0: fixed initial conditions).
    delta_t_c : float, optional
        The asked sensor-object temperature difference [degC] (a varied table holds its dT as an axis).

    Returns
    -------
    TableChoice
        A sensor file with the rig's conditions reads the table registered for it (``designkit tables build``)
        under its own model at fixed initial conditions. The shipped tables are for the paper's sensor and the
        semi-infinite model: ``svm-fine`` at fixed initial conditions, ``svm-paper-varied`` at its spread and
        dT; anything else has none (None).
    """
    spread = float(sensor_temp_spread_c or 0.0)
    own = _registered_table(load_sensor(sensor if sensor is not None else "paper"), model, spread)
    if own is not None:
        return own
    sen, fm = _sensor_and_model(sensor, model)
    why = table_reroute(sen, fm)
    if why is not None:
        if getattr(sen, "conditions", None):
            why += "; 'designkit tables build --sensor FILE' builds this sensor's table (then milliseconds)"
        return TableChoice(None, why, noted=True)
    if spread > 0:
        name = shipped_spread_table(spread, question, delta_t_c)
        if name is None:
            at = "" if delta_t_c is None else f" at dT {abs(float(delta_t_c)):g} degC"
            return TableChoice(None, f"no shipped table answers {question} with the sensor temperature drawn per "
                                     f"touch within +-{spread:g} degC{at}: computed for the pair")
        return TableChoice(name, f"table {name} is built for the paper sensor, the semi-infinite model and the "
                                 f"sensor temperature drawn per touch within +-{spread:g} degC")
    return TableChoice(DEFAULT_TABLE, f"table {DEFAULT_TABLE} is built for the paper sensor and the semi-infinite "
                                      "model at fixed initial conditions")


def _registered_table(sen, fm, spread: float) -> TableChoice | None:
    """The table registered for sensor file ``sen`` (:func:`~designkit.tables.registry.table_for_sensor`) when it
    answers under model ``fm`` (None: the file's own, the one the table was built with) at fixed initial
    conditions; None otherwise (a registered table that is damaged or built for another sensor is refused there,
    in one line)."""
    if not getattr(sen, "conditions", None) or spread > 0:
        return None
    from ..models import get_model
    from ..tables.registry import table_for_sensor

    tab = table_for_sensor(sen)
    if tab is None or (fm is not None and get_model(fm) != tab.model):
        return None
    return TableChoice(str(tab.path), f"table {tab.name} is built for sensor {sen.name} as calibrated (designkit "
                                      "tables build)", sensor_table=True, loaded=tab)


def _sensor_and_model(sensor, model):
    """The sensor asked about (the paper's by default) and the model that answers for it (a sensor file's own
    where none is asked; None: the default)."""
    sen = load_sensor(sensor if sensor is not None else "paper")
    if model is None and getattr(sen, "model", None) is not None:
        from ..models import sensor_model

        model = sensor_model(sen)
    return sen, model


def choose_route(question: str, route: str, arguments: Mapping[str, Any]) -> tuple[str, dict[str, Any], TableChoice]:
    """The route that answers ``question`` with ``arguments`` under ``route``, the arguments that route takes,
    and why.

    ``"table"`` and ``"exact"`` are kept as asked (``"exact"`` leaves the ideal table out). ``"auto"``: a named table (``table=``) is read; else
    :func:`table_for` decides, and the options of the route not taken (:data:`TABLE_OPTIONS`,
    :data:`EXACT_OPTIONS`) are left out. A diffusivity given where a table answers is refused
    (:class:`~designkit.query.inputs.NeedsInput`): tables answer for effusivity alone.
    """
    if route not in ROUTES:
        raise InputError(f"unknown route {route!r}; known: {', '.join(ROUTES)}")
    args = dict(arguments)
    if route == "exact":  # (a table named with it is a contradiction; the ideal table has no use there)
        if args.get("table") is not None:
            raise InputError(f"route='exact' computes the answer for the pair, table={args['table']!r} reads it "
                             "from a table: give one of them")
        return route, {k: v for k, v in args.items() if k not in TABLE_OPTIONS}, TableChoice(None, "route='exact' asked")
    if route == "table":
        return route, args, TableChoice(args.get("table"), "route='table' asked")
    if args.get("table") is not None:
        choice = TableChoice(args["table"], f"table {args['table']} named")
    else:
        args.pop("table", None)
        dt = args.get("delta_t_c", 10.0)
        choice = table_for(question, sensor=args.get("sensor"), model=args.get("model"),
                           sensor_temp_spread_c=args.get("sensor_temp_spread_c", 0.0),
                           delta_t_c=dt if isinstance(dt, (int, float)) and math.isfinite(dt) else None)
    if choice.table is None:
        return "exact", {k: v for k, v in args.items() if k not in TABLE_OPTIONS}, choice
    if args.get("diffusivity_m2_s") is not None:
        raise NeedsInput("a diffusivity was given but tables answer for effusivity alone", "diffusivity-unused")
    args = {k: v for k, v in args.items() if k not in EXACT_OPTIONS}
    if "table" not in args and choice.table != DEFAULT_TABLE:
        args["table"] = choice.table
    if choice.sensor_table:  # its model has no closed-form ideal observer: no paper's ideal table either
        args["ideal_table"] = None
        args["table"] = choice.loaded  # (found and checked once: not read again by the route)
        args["model"] = choice.loaded.model  # (the file's own, or the same asked: not rebuilt from the file)
    return "table", args, choice


class OutsideSensorTable(InputError):
    """A question outside the span of the table built for its sensor (refused, never extrapolated).

    ``where`` says what lies outside; ``wider``: a table built over a wider effusivity span would answer it."""

    def __init__(self, where: str, *, wider: bool):
        self.where, self.wider = where, wider
        super().__init__(f"{where}: ask with route='exact' (computed, tens of seconds)"
                         + (", or build the sensor's table over a wider effusivity span" if wider else ""))


#: Questions whose table route estimates a missing closed-form ideal bound by Monte Carlo (seconds): not done
#: from a sensor's own table (``--exact`` does).
MC_BOUND = frozenset({"min-contact", "delta-e"})


def sensor_table_answer(question: str, ans, choice: TableChoice, sensor):
    """An answer read from a sensor's own table (``choice.sensor_table``), as it is given: a question outside the
    table's span is refused (:class:`~designkit._validation.InputError`, one line naming ``--exact`` and, where
    the effusivity is outside, a wider build), never extrapolated; an array answer's elements outside are NaN.
    The notes count contact from the rig's detected onset and say which table answered."""
    import dataclasses

    import numpy as np

    from .answer import Answer

    sen = load_sensor(sensor)
    if not isinstance(ans, Answer):  # arrays: outside the span, no answer (NaN), in_grid False says why
        out = ~np.asarray(ans.in_grid, dtype=bool)
        if not out.any():
            return ans
        nan = {k: np.where(out, np.nan, getattr(ans, k)) for k in ("value", "low", "high", "coverage", "ideal")}
        return dataclasses.replace(ans, **nan)
    if not all(ans.in_grid.values()):
        raise OutsideSensorTable("; ".join(ans.notes) + f" (the table built for sensor {sen.name})",
                                 wider=not ans.in_grid.get("effusivity", True))
    notes = ans.notes
    if question == "min-contact" and (ans.value is None or ans.interval_kind == "table-cell"):
        from ..rig import from_model_contact, model_start_s  # counted as the rig counts: from the onset

        start = model_start_s(sen)
        own = choice.loaded
        at = [f"{max(from_model_contact(float(t), start), 0.0):.3g}" for t in
              ((own.axes["contact_s"][-1],) if ans.value is None else ans.interval)]
        notes = ((f"no tabulated contact time up to {at[0]} s after the rig's detected onset separates them (--exact "
                  "examines up to 10 s)",) if ans.value is None else
                 (f"the shortest contact lies in ({at[0]}, {at[1]}] s after the rig's detected onset, a cell of the "
                  "table's contact grid: no interval of stated coverage there (--exact estimates one)",))
    return dataclasses.replace(ans, notes=(*notes, f"from the table built for sensor {sen.name} (designkit tables "
                                           "build); its model has no closed-form ideal observer: --exact estimates "
                                           "the bound by Monte Carlo"))
