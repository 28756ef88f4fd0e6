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
from dataclasses import dataclass
from typing import Any, Mapping

from .._validation import InputError
from .inputs import NeedsInput, table_reroute

__all__ = ["EXACT_OPTIONS", "ROUTES", "TABLE_OPTIONS", "TableChoice", "choose_route", "table_for"]

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
    tables are built for)."""

    table: str | None
    reason: str
    noted: bool = False


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
        The shipped tables are for the paper's sensor and the semi-infinite model: ``svm-fine`` at fixed
        initial conditions, ``svm-paper-varied`` at its spread and dT; anything else has none (None).
    """
    from .table import DEFAULT_TABLE, shipped_spread_table

    sen, fm = _sensor_and_model(sensor, model)
    why = table_reroute(sen, fm)
    if why is not None:
        return TableChoice(None, why, noted=True)
    spread = float(sensor_temp_spread_c or 0.0)
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


def _sensor_and_model(sensor, model):
    """The sensor asked about (the paper's by default) and the model that answers for it (a sensor file's own
    where none is asked; None: the default)."""
    from ..sensor import load_sensor

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
    from .table import DEFAULT_TABLE

    args = {k: v for k, v in args.items() if k not in EXACT_OPTIONS}
    if "table" not in args and choice.table != DEFAULT_TABLE:
        args["table"] = choice.table
    return "table", args, choice
