"""Batch questions: a CSV of pairs and scenes in, one array answer out (one record per row).

A batch file is a CSV with a header; its columns are named as the command line's options
(``e1, e2`` or ``m1, m2`` for a pair, ``e`` or ``m`` for delta-e's reference, ``noise``,
``delta_t``, ``contact``; the schema's names ``noise_c``, ``delta_t_c``, ``contact_s`` and
``delta-t`` are read too). A column left out, or a scene cell left empty, takes the value given
for the whole call. :func:`read_batch` checks the file (one line naming the row and column of what is
wrong); :func:`answer_batch` answers every row with one array call of :func:`designkit.query.ask`
(materials by name too: the library takes lists of names).

Examples
--------
>>> import io
>>> b = read_batch(io.StringIO("e1,e2,noise\\n35000,20000,0.05\\n35000,20000,0.1\\n"), "min-contact")
>>> b.rows, sorted(b.columns)
(2, ['e1', 'e2', 'noise_c'])
>>> [round(r["value"], 3) for r in answer_batch(b)]
[1.225, 1.835]
"""

from __future__ import annotations

import csv
import io
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, Mapping

import numpy as np

from ._validation import InputError

__all__ = ["COLUMNS", "MAX_BATCH_ROWS", "MAX_BATCH_ROWS_EXACT", "Batch", "answer_batch", "read_batch"]

#: A batch file's column names -> the library's argument (the CLI option's name, and the schema's).
COLUMNS: dict[str, str] = {
    "e1": "e1", "e2": "e2", "m1": "m1", "m2": "m2", "e": "e", "m": "m",
    "noise": "noise_c", "noise_c": "noise_c",
    "delta_t": "delta_t_c", "delta-t": "delta_t_c", "delta_t_c": "delta_t_c",
    "contact": "contact_s", "contact_s": "contact_s",
}

#: Rows answered in one call from a table (10,000 new pairs take about a second); split larger files.
MAX_BATCH_ROWS = 100_000
#: Rows answered in one call by the exact route (each row is seconds of simulation and SVM fits).
MAX_BATCH_ROWS_EXACT = 100

_OBJECTS = {"delta-e": ("e", "m")}
_PAIR = ("e1", "e2", "m1", "m2")
_NAMES = frozenset({"m1", "m2", "m"})


def _allowed(question: str) -> tuple[str, ...]:
    """The library arguments a batch file of ``question`` may give."""
    from .query import QUESTIONS

    if question not in QUESTIONS:
        raise InputError(f"unknown question {question!r}; known: {', '.join(QUESTIONS)}")
    return _OBJECTS.get(question, _PAIR) + QUESTIONS[question].scene


@dataclass(frozen=True)
class Batch:
    """A checked batch file.

    Attributes
    ----------
    question : str
        The question every row asks.
    columns : dict
        Library argument (``e1``, ``m1``, ``noise_c`` ...) -> one value per row: float64 arrays for numbers
        (NaN where a scene cell was empty: the call's value), tuples of str for material names.
    rows : int
        Number of rows.
    source : str
        Where the rows came from (a path, or ``<stream>``), for messages.
    lines : tuple of int
        The file's line number of each row (the header is line 1), for messages.
    """

    question: str
    columns: Mapping[str, Any]
    rows: int
    source: str = "<stream>"
    lines: tuple[int, ...] = ()

    def line(self, k: int) -> int:
        """The file's line of row ``k`` (0-based)."""
        return self.lines[k] if k < len(self.lines) else k + 2


def read_batch(src: "str | Path | IO[str]", question: str, *, max_rows: int = MAX_BATCH_ROWS) -> Batch:
    """Read and check a batch file of ``question`` (a path, ``-`` for stdin, or an open text stream).

    Raises :class:`~designkit._validation.InputError` with one line naming the file, and the line and
    column of what is wrong: a missing or unreadable file, an empty one, an unknown or repeated column,
    objects given both by effusivity and by name or only half of a pair, a row of another length than the
    header, a cell that is not a number (or an empty object cell), more than ``max_rows`` rows.
    """
    allowed = _allowed(question)
    name, text = _text(src)
    reader = csv.reader(io.StringIO(text))
    header = [h.strip() for h in next(reader, [])]
    if not any(header):
        raise InputError(f"batch file {name} is empty: give a header line ({', '.join(_options(allowed))}) and "
                         "one row per question")
    args = []
    for h in header:
        arg = COLUMNS.get(h.lower())
        if arg is None or arg not in allowed:
            raise InputError(f"batch file {name}: unknown column {h!r} for {question}; known: "
                             f"{', '.join(_options(allowed))}")
        if arg in args:
            raise InputError(f"batch file {name}: column {h!r} is given twice")
        args.append(arg)
    _check_objects(name, question, args)
    cells: list[list[str]] = []
    lines: list[int] = []
    for row in reader:
        if not row or not any(c.strip() for c in row):
            continue  # a blank line (often the last)
        if len(cells) >= max_rows:
            raise InputError(f"batch file {name} has more than {max_rows:,} rows, the most one call answers: "
                             "split it")
        if len(row) != len(header):
            raise InputError(f"batch file {name}, line {reader.line_num}: {len(row)} cells, the header has "
                             f"{len(header)}")
        cells.append(row)
        lines.append(reader.line_num)
    if not cells:
        raise InputError(f"batch file {name} has a header but no rows: give one row per question")
    columns = {arg: _column(name, arg, h, [r[i] for r in cells], lines)
               for i, (arg, h) in enumerate(zip(args, header))}
    return Batch(question=question, columns=columns, rows=len(cells), source=name, lines=tuple(lines))


def _options(allowed: tuple[str, ...]) -> list[str]:
    """The column names of the arguments, as the command line's options."""
    words = {"noise_c": "noise", "delta_t_c": "delta_t", "contact_s": "contact"}
    return [words.get(a, a) for a in allowed]


def _text(src: "str | Path | IO[str]") -> tuple[str, str]:
    if hasattr(src, "read"):
        return "<stream>", src.read()
    if str(src) == "-":
        import sys

        return "<stdin>", sys.stdin.read()
    p = Path(src).expanduser()
    if p.is_dir():
        raise InputError(f"batch file {p} is a folder; give a CSV file")
    try:
        raw = p.read_bytes()
    except FileNotFoundError:
        raise InputError(f"batch file {p}: no such file") from None
    except OSError as exc:
        raise InputError(f"batch file {p}: cannot read it ({exc.strerror or exc})") from None
    try:
        return str(p), raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise InputError(f"batch file {p} is not UTF-8 text: give a CSV file") from None


def _check_objects(name: str, question: str, args: list[str]) -> None:
    given = set(args)
    if question == "delta-e":
        if {"e", "m"} <= given:
            raise InputError(f"batch file {name}: give the reference as column e or m, not both")
        return
    numbers, names = given & {"e1", "e2"}, given & {"m1", "m2"}
    if numbers and names:
        raise InputError(f"batch file {name}: give the pair as columns e1,e2 or m1,m2, not both")
    for pair in (numbers, names):
        if len(pair) == 1:
            have = next(iter(pair))
            raise InputError(f"batch file {name}: column {have} without {have[0]}{3 - int(have[1])}: give both "
                             "objects of the pair")


def _column(name: str, arg: str, header: str, cells: list[str], lines: list[int]) -> Any:
    """One column's cells as the library's values (names, or float64 with NaN for an empty scene cell)."""
    if arg in _NAMES:
        for k, c in enumerate(cells):
            if not c.strip():
                raise InputError(f"batch file {name}, line {lines[k]}, column {header}: empty; give a material name")
        return tuple(c.strip() for c in cells)
    out = np.empty(len(cells))
    for k, c in enumerate(cells):
        c = c.strip()
        if not c and arg not in ("e1", "e2", "e"):
            out[k] = np.nan  # the call's value
            continue
        try:
            out[k] = float(c)
        except ValueError:
            raise InputError(f"batch file {name}, line {lines[k]}, column {header}: {c!r} is not a number") from None
        if not math.isfinite(out[k]):
            raise InputError(f"batch file {name}, line {lines[k]}, column {header}: {c!r} is not a finite number")
    return out


def answer_batch(batch: Batch, defaults: Mapping[str, Any] | None = None, *, route: str = "auto",
                 **options: Any) -> list[dict[str, Any]]:
    """Answer every row of ``batch``: one record per row, in the file's order.

    Parameters
    ----------
    batch : Batch
        From :func:`read_batch`.
    defaults : mapping, optional
        Library argument -> the value of a column the file leaves out, or of its empty cells (the command's
        options: ``noise_c=0.05`` ...). A scene value neither in the file nor here is the library's default.
    route : str
        ``"auto"`` (the library's policy, :func:`designkit.query.policy.choose_route`, decided once for the
        file), ``"table"`` or ``"exact"`` (:func:`designkit.query.ask`).
    **options
        The route's options (``table=``, ``threshold=``, ``coverage=`` ...).

    Returns
    -------
    list of dict
        Per row: the row's inputs under the schema's names (``e1``, ``e2`` or ``m1``, ``m2``, ``contact_s``,
        ``noise_c``, ``delta_t_c``), then the array answer's record (``value``, ``interval_low`` ...,
        :meth:`designkit.query.ArrayAnswer.to_dict`).
    """
    from .query import ask
    from .query.policy import choose_route

    defaults = {k: v for k, v in (defaults or {}).items() if v is not None}
    # the route the library's policy takes for this file (the scene's dT decides a varied table): the exact
    # route's row limit applies to it
    taken = choose_route(batch.question, route, {**options, **{k: v for k, v in defaults.items()
                                                               if k == "delta_t_c"}})[0]
    if taken == "exact" and batch.rows > MAX_BATCH_ROWS_EXACT:
        raise InputError(f"batch file {batch.source} has {batch.rows:,} rows: the exact route answers at most "
                         f"{MAX_BATCH_ROWS_EXACT} in one call (each is seconds); split it, or read a table")
    inputs = _inputs(batch, defaults)
    names = [a for a in inputs if a in _NAMES]
    scene = {a: v for a, v in inputs.items() if a not in _NAMES}
    # arrays everywhere: a file of one row is still an array call (one record out)
    scene = {a: np.broadcast_to(np.asarray(v, dtype=np.float64), (batch.rows,)) for a, v in scene.items()}
    arguments = {**{a: list(inputs[a]) for a in names}, **scene}
    try:
        answer = ask(batch.question, route=route, **arguments, **options)
    except InputError as exc:  # the library names an element (noise_c[3]): said as the file's line
        text = re.sub(r"\b(\w+)\[(\d+)\]", lambda m: f"{m.group(1)} (line {batch.line(int(m.group(2)))})"
                      if int(m.group(2)) < batch.rows else m.group(0), str(exc))
        raise InputError(f"batch file {batch.source}: {text}") from None
    records = []
    for k, rec in enumerate(answer.to_dict()):
        row = {a: (inputs[a][k] if a in _NAMES else _number(scene[a][k])) for a in inputs}
        records.append({**row, **rec})
    return records


def _inputs(batch: Batch, defaults: Mapping[str, Any]) -> dict[str, Any]:
    """Every argument of the call, per row: the file's columns (an empty scene cell: ``defaults``'), then the
    ``defaults`` the file leaves out (objects only where the file names none)."""
    out: dict[str, Any] = {}
    allowed = _allowed(batch.question)
    file_objects = set(batch.columns) & {"e1", "e2", "m1", "m2", "e", "m"}
    for arg in allowed:
        if arg in batch.columns:
            col = batch.columns[arg]
            if arg not in _NAMES and np.isnan(col).any():
                if arg not in defaults:
                    k = int(np.flatnonzero(np.isnan(col))[0])
                    raise InputError(f"batch file {batch.source}, line {batch.line(k)}: {arg} is empty and the call "
                                     "gives no value for it: fill the cell or give the option")
                col = np.where(np.isnan(col), float(defaults[arg]), col)
            out[arg] = col
        elif arg in defaults and not (file_objects and arg in ("e1", "e2", "m1", "m2", "e", "m")):
            out[arg] = (tuple([defaults[arg]] * batch.rows) if arg in _NAMES else float(defaults[arg]))
    return out


def _number(x: Any) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None
