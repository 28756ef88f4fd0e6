"""Opening a table for a question: the table named (loaded and verified once per process), checked against
the question's threshold, sensor, forward model and sensor temperature spread, with the view its ideal bound
is read from (:class:`OpenedTable`). A table built for another one is refused
(:class:`~designkit.query.inputs.TableMismatch`), never used silently.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from cachetools import LRUCache

from .._validation import check_nonnegative
from ..models import get_model
from ..tables.store import Table, load_table, resolve_table
from .estimates import table_spread
from .inputs import TableMismatch, check_threshold
from .table_arrays import TableView

__all__ = ["DEFAULT_IDEAL_TABLE", "DEFAULT_TABLE", "SPREAD_TABLE_QUESTIONS", "VARIED_TABLE", "OpenedTable",
           "as_table", "clear_table_cache", "delta_e_ideal_view", "ideal_view", "open_table", "shipped_spread_table",
           "table_view"]

DEFAULT_TABLE = "svm-fine"
#: The shipped table for the paper's second setting (the sensor's temperature drawn per touch, uniform in
#: 30-35 degC with the object at 25 degC: dT 7.5 degC, spread 2.5 degC): a question with that spread reads it.
VARIED_TABLE = "svm-paper-varied"
DEFAULT_IDEAL_TABLE = "ideal-paper"


#: Tables loaded (and verified) by this process, keyed by their files' identity, each with its
#: :class:`~designkit.query.table_arrays.TableView` (the table's memo): a name or path is read and hashed
#: once, not on every question. Least recently used out.
_LOADED: "LRUCache[tuple, tuple[Table, TableView]]" = LRUCache(16)
#: The files each table name given as a string resolved to (:func:`~designkit.tables.store.resolve_table`), so
#: that a question stats two files instead of searching for them; resolved again when they are gone.
_RESOLVED: "LRUCache[tuple, tuple[str, str]]" = LRUCache(64)


def as_table(table: "Table | str") -> Table:
    """A Table object, or the table a name or path names, loaded once per process while its files
    are unchanged (same path, size and modification time of the .npz and the .json header)."""
    if isinstance(table, Table):
        return table
    named = ("name", table) if isinstance(table, str) else None
    files = _RESOLVED.get(named) if named else None
    if files is None:
        npz = resolve_table(table)
        files = (str(npz), str(npz.with_suffix(".json")))
    try:
        key = tuple((p, st.st_mtime_ns, st.st_size) for p in files for st in (os.stat(p),))
    except OSError:  # let load_table say what is missing
        _RESOLVED.pop(named, None)
        return load_table(resolve_table(table))
    if named:
        _RESOLVED[named] = files
    hit = _LOADED.get(key)
    if hit is None:
        t = load_table(Path(files[0]))
        hit = _LOADED[key] = (t, TableView(t))
    return hit[0]


def table_view(tab: Table) -> TableView:
    """The view of ``tab`` kept with it (its memo: the critical noises, computed once per table): the one made
    when this process loaded it, or when a question first read this Table object (kept beside the loaded
    tables, least recently used out)."""
    for t, view in list(_LOADED.values()):
        if t is tab:
            return view
    view = TableView(tab)
    _LOADED[("object", id(tab))] = (tab, view)  # (the entry holds the table: its id is not reused meanwhile)
    return view


def clear_table_cache() -> None:
    """Forget the tables this process has loaded (they are re-read and re-verified on next use), and what
    their views computed of them."""
    _LOADED.clear()
    _RESOLVED.clear()


# ============================================================ opening a table for a question
@dataclass(frozen=True)
class OpenedTable:
    """A table checked against the question (threshold, sensor, model), and its ideal-bound view."""

    tab: Table
    view: TableView
    phi: float
    model: Any
    iview: TableView | None
    ikind: str
    iname: str | None
    ihash: str | None
    #: The ideal bound is computed in closed form at query time (never read from a grid): :func:`_closed_form`.
    closed: bool = False

    @property
    def width(self) -> float:
        return float(self.tab.header["effusivity"]["width"])


def ideal_view(svm: TableView, ideal_table: "Table | str | None") -> tuple[TableView, str, Table | None]:
    """The view answering the ideal bound: a dedicated ideal table built for the same sensor, model and
    threshold, else the SVM table's own ideal arrays, else none (``(None, "", None)``: no bound from
    tables; never the SVM's own answer passed off as the bound). An ideal table that cannot be read is
    an error, not a silent fallback."""
    if ideal_table is not None:
        t = as_table(ideal_table)
        if (t.sensor == svm.t.sensor and t.fidelity == "ideal" and t.threshold == svm.t.threshold
                and t.model == svm.t.model):
            return table_view(t), "svm", t
    if "delta_up_ideal" in svm.t.arrays:
        return svm, "ideal", svm.t
    if svm.t.fidelity == "ideal":
        return svm, "svm", svm.t
    return None, "", None


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
    tab = as_table(VARIED_TABLE)
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


def open_table(table: "Table | str" = DEFAULT_TABLE, ideal_table: "Table | str | None" = DEFAULT_IDEAL_TABLE, *,
               threshold=None, sensor=None, model=None, sensor_temp_spread_c: float = 0.0) -> OpenedTable:
    """Load ``table`` and refuse it when it was built for another threshold, sensor, model or sensor
    temperature spread (``sensor_temp_spread_c`` [degC]: the question's; a spread reads :data:`VARIED_TABLE`
    by default). Returns the :class:`OpenedTable`: ``tab``, ``view`` (:class:`~designkit.query.table_arrays.TableView`),
    ``phi``, ``model``, ``width``, ``closed`` (the ideal bound is computed in closed form), ``iview`` / ``ikind``
    (the ideal bound's view and array kind when read from a grid)."""
    spread = check_nonnegative("sensor temperature spread [degC]", sensor_temp_spread_c)
    if spread > 0 and isinstance(table, str) and table == DEFAULT_TABLE:
        table = VARIED_TABLE
    tab = as_table(table)
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
    view = table_view(tab)
    if _closed_form(tab, fm):  # the bound is computed at query time: the default ideal table is not read
        if ideal_table is not None and ideal_table != DEFAULT_IDEAL_TABLE:
            as_table(ideal_table)  # a table the caller named must exist: an error, not a silent fallback
        return OpenedTable(tab, view, tab.threshold, fm, None, "", None, None, closed=True)
    iview, ikind, it = ideal_view(view, ideal_table)
    return OpenedTable(tab, view, tab.threshold, fm, iview, ikind, None if it is None else it.name,
                       None if it is None else it.header.get("content_hash"))


def _closed_form(tab: Table, fm) -> bool:
    """Whether the ideal bound is computed in closed form (shared-shape model, fixed initial conditions)."""
    return bool(fm.shared_shape) and "noise_ratio" in tab.axes


def delta_e_ideal_view(op: OpenedTable, ideal_table: "Table | str | None" = DEFAULT_IDEAL_TABLE):
    """The view and kind delta-e reads its grid ideal bound from (a grid even where a closed form exists)."""
    if not op.closed:
        return op.iview, op.ikind
    iview, ikind, _ = ideal_view(op.view, ideal_table)
    return iview, ikind
