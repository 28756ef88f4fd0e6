"""The one output module of the CLI: ``--format text|table|json|csv|ndjson|md`` and ``--out FILE|-``.

sqlite-utils' convention: every command that answers takes the same output
options (:data:`FormatOpt`, :data:`OutOpt`; ``--json`` is ``--format json``)
and prints through this module, so a new user learns them once. A command
adopts them in three lines::

    from ._format import FormatOpt, OutOpt, emit, output_format

    def cmd(..., format_: FormatOpt = None, out: OutOpt = None, json_: Json = False):
        fmt = output_format(format_, json_)            # before the work: a bad --format is refused first
        ...
        emit(fmt, out, payload=result.to_dict(),       # json: the library's data
             records=[...],                            # csv, ndjson, table, md: one flat row per answer
             text=lambda: print_for_people(result))    # text: the command's own rendering

========  ===================================================================
format    what is printed
========  ===================================================================
text      the command's text for people (its default; a command whose
          answer is rows prints them as ``table``)
table     a rich table for people: names and numbers never cut (on a
          terminal a table wider than the window is printed in groups
          of columns under the first one; piped, no wrapping)
json      ``payload`` (the library's ``to_dict()``) if given, else the rows
csv       a header line and one line per row: nothing else (no comments), so
          ``pandas.read_csv`` reads it with its defaults; None is empty
ndjson    one JSON object per row and line (the csv's records, typed:
          numbers, booleans and null): ``pandas.read_json(f, lines=True)``
md        a GitHub Markdown table, then ``notes`` as paragraphs
========  ===================================================================

``--out -`` (or no ``--out``) is stdout; ``--out FILE`` writes the file.
"""

from __future__ import annotations

import io
import json
import math
import sys
from contextlib import contextmanager, redirect_stdout
from pathlib import Path
from typing import Annotated, Any, Callable, Mapping, Optional, Sequence

import typer

from .._validation import InputError

from ._app import jsonable
from ._options import PANEL_OUTPUT

FORMATS = ("text", "table", "json", "csv", "ndjson", "md")

FormatOpt = Annotated[Optional[str], typer.Option(
    "--format", "-f", help="Output: text (for people, the default), table (rows for people), json (the library's "
                           "data; as --json), csv (pandas-ready: header and rows only), ndjson (one JSON record "
                           "a line) or md (Markdown table).", rich_help_panel=PANEL_OUTPUT)]
OutOpt = Annotated[Optional[str], typer.Option(
    "--out", "-o", help="Write the output to this file ('-' or none: stdout).", rich_help_panel=PANEL_OUTPUT)]


def check_format(fmt: str) -> str:
    """``fmt`` lower-cased, or an error naming the formats."""
    f = str(fmt).strip().lower()
    if f not in FORMATS:
        raise InputError(f"unknown format {fmt!r}; choose one of: {', '.join(FORMATS)}")
    return f


def output_format(format_: Optional[str], json_: bool = False, *, default: str = "text",
                  out: Optional[str] = None) -> str:
    """The format a command prints in: ``--json`` is ``--format json``; none given is ``default``. An ``out``
    file is checked too (:func:`check_out`, the error naming ``--out``), before the command's work.

    >>> output_format(None, True), output_format("CSV"), output_format(None)
    ('json', 'csv', 'text')
    >>> output_format("csv", True)
    Traceback (most recent call last):
    ...
    designkit._validation.InputError: --json and --format csv contradict each other: --json is --format json; give one
    """
    if json_ and format_ is not None and check_format(format_) != "json":
        raise InputError(f"--json and --format {format_} contradict each other: --json is --format json; give one")
    fmt = "json" if json_ else (default if format_ is None else check_format(format_))
    if out is not None and str(out) != "-":
        check_out(out, "--out")  # the refusal names the option
    return fmt


def flat_record(d: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """A nested document as one flat row: nested keys joined by ``_``, a ``range`` (a pair of numbers under a
    ``*_range*`` key) as two columns with ``_min`` / ``_max`` in place of ``_range`` (docs/schema.md, "Records"),
    other lists as JSON text.

    >>> flat_record({"a": 1, "b": {"low": 0.5, "high": None}, "diffusivity_range_m2_s": [1, 2]})
    {'a': 1, 'b_low': 0.5, 'b_high': None, 'diffusivity_min_m2_s': 1, 'diffusivity_max_m2_s': 2}
    """
    out: dict[str, Any] = {}
    for k, v in d.items():
        key = f"{prefix}{k}"
        if isinstance(v, Mapping):
            out.update(flat_record(v, f"{key}_"))
        elif isinstance(v, (list, tuple)) and "range" in str(k) and len(v) == 2:
            out[key.replace("_range", "_min", 1)], out[key.replace("_range", "_max", 1)] = v
        elif isinstance(v, (list, tuple)):
            out[key] = json.dumps(jsonable(v))
        else:
            out[key] = v
    return out


def emit(fmt: str, out: str | None, *, payload: Any, records: Sequence[Mapping[str, Any]] | Callable[[], Any],
         text: Callable[[], None] | None = None, **kw: Any) -> None:
    """Print (or write to ``out``) one command's answer in ``fmt``: ``payload`` as json, ``records`` (a list of
    flat rows, or a function giving them) as table, csv, ndjson or md, ``text()`` (the command's own rendering,
    which prints) as text (without it, text is the table). Keyword arguments are :func:`render_rows`'s."""
    if fmt == "text" and text is not None:
        with output_to(out):
            text()
        return
    rows = [] if fmt == "json" else list(records() if callable(records) else records)
    emit_rows(rows, kw.pop("columns", None), fmt="table" if fmt == "text" else fmt, out=out, payload=payload, **kw)


def cell_text(v: Any) -> str:
    """A value as people read it in a table: floats to 4 significant digits, None as '–'."""
    if v is None:
        return "–"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return "–" if not math.isfinite(v) else f"{v:.4g}"
    return str(v)


def _csv_text(v: Any) -> str:
    """One CSV cell: full precision, numpy scalars as plain numbers (``repr(np.float64(x))`` is
    ``np.float64(x)`` under numpy 2: calibrate fit --bootstrap 0 wrote such cells)."""
    if v is None:
        return ""
    if hasattr(v, "dtype") and hasattr(v, "item") and getattr(v, "ndim", 1) == 0:
        v = v.item()  # a numpy scalar (or 0-d array): its Python number
    if isinstance(v, bool):
        return str(v)
    if isinstance(v, float):
        return "" if not math.isfinite(v) else repr(float(v))
    if isinstance(v, (list, tuple, dict)):
        return json.dumps(jsonable(v))
    return str(v)


def render_rows(rows: Sequence[Mapping[str, Any]], columns: Sequence[str] | None = None, *, fmt: str = "table",
                title: str = "", notes: Sequence[str] = (), payload: Any = None,
                text: Callable[[str, Any], str] | None = None, justify: Mapping[str, str] | None = None) -> str:
    """The rows as text in format ``fmt`` (see the module docstring); what :func:`emit_rows` prints.

    ``text(column, value)`` formats a cell for ``table`` and ``md`` (default
    :func:`cell_text`); csv and json keep full precision. ``justify`` maps a
    column to ``"left"`` or ``"right"`` (default: numbers right).
    """
    fmt = check_format(fmt)
    if fmt == "text":
        fmt = "table"
    # the columns: given, else every key in the order met (rows of one answer may differ in their keys)
    cols = list(columns) if columns is not None else list(dict.fromkeys(k for r in rows for k in r))
    if fmt == "json":
        data = payload if payload is not None else [dict(r) for r in rows]
        return json.dumps(jsonable(data), indent=2, allow_nan=False) + "\n"
    if fmt == "ndjson":
        return "".join(json.dumps(jsonable({c: r.get(c) for c in cols}), allow_nan=False) + "\n" for r in rows)
    if fmt == "csv":
        import csv  # here: a question answered in text (the usual case) never loads it

        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(cols)
        for r in rows:
            w.writerow([_csv_text(r.get(c)) for c in cols])
        return buf.getvalue()
    fmt_cell = text or (lambda _c, v: cell_text(v))
    body = [[fmt_cell(c, r.get(c)) for c in cols] for r in rows]

    def right(ci: int) -> bool:
        c = cols[ci]
        if justify and c in justify:
            return justify[c] == "right"
        return any(isinstance(r.get(c), (int, float)) and not isinstance(r.get(c), bool) for r in rows)

    if fmt == "md":
        def esc(s: str) -> str:
            return s.replace("|", "\\|")

        lines = ([f"**{esc(title)}**", ""] if title else [])
        lines.append("| " + " | ".join(esc(c) for c in cols) + " |")
        lines.append("|" + "|".join("---:" if right(i) else ":---" for i in range(len(cols))) + "|")
        lines += ["| " + " | ".join(esc(s) for s in row) + " |" for row in body]
        if notes:
            lines.append("")
            lines += [n for note in notes for n in (note, "")][:-1]
        return "\n".join(lines) + "\n"
    from rich.console import Console
    from rich.table import Table
    from rich.text import Text

    width = _width()
    buf = io.StringIO()
    con = Console(file=buf, highlight=False, soft_wrap=True, width=width, force_terminal=False,
                  color_system=None)
    for k, chunk in enumerate(_fold(cols, body, width)):
        # Text, not markup: units like [s] and flags like [!] are not style tags
        table = Table(title=Text(title) if title and k == 0 else None, title_justify="left")
        for i in chunk:
            # never an ellipsis: a cell too wide for the terminal folds onto another line
            widest_word = max([len(w) for s in [cols[i]] + [row[i] for row in body] for w in s.split()] or [1])
            table.add_column(Text(cols[i]), justify="right" if right(i) else "left", overflow="fold",
                             min_width=min(widest_word, 30))
        for row in body:
            table.add_row(*(Text(row[i]) for i in chunk))
        con.print(table)
    for n in notes:
        con.print(n, markup=False)
    return buf.getvalue()


def _fold(cols: Sequence[str], body: Sequence[Sequence[str]], width: int) -> list[list[int]]:
    """The columns in groups that fit ``width`` (a terminal's), each group printed as its own table under the
    first column (the row's name), like a wide matrix in a book; one group when everything fits.

    A column's width is its widest word (a header folds onto more lines at its spaces, a cell never breaks).

    >>> _fold(["name", "a", "b", "c"], [["x" * 10, "1" * 20, "2" * 20, "3" * 20]], 60)
    [[0, 1, 2], [0, 3]]
    """
    need = [max([len(w) for w in cols[i].split()] + [len(row[i]) for row in body] + [1]) + 3
            for i in range(len(cols))]
    if sum(need) + 1 <= width or len(cols) < 3:
        return [list(range(len(cols)))]
    groups: list[list[int]] = [[0]]
    used = need[0] + 1
    for i in range(1, len(cols)):
        if used + need[i] > width and len(groups[-1]) > 1:
            groups.append([0])
            used = need[0] + 1
        groups[-1].append(i)
        used += need[i]
    return groups


def _width() -> int:
    """The terminal's width on a terminal; unlimited when piped (a line is a line)."""
    if hasattr(sys.stdout, "isatty") and sys.stdout.isatty():
        import shutil

        return shutil.get_terminal_size((100, 24)).columns
    return 100_000


def write_output(text: str, out: str | None) -> None:
    """Write ``text`` to ``out`` (a path), or stdout for None and ``-``."""
    if out is None or str(out) == "-":
        sys.stdout.write(text)
        sys.stdout.flush()
        return
    import os
    import stat

    p = check_out(out)
    try:
        fifo = stat.S_ISFIFO(os.stat(p).st_mode)
    except OSError:
        fifo = False
    if fifo:  # a named pipe: written to when something reads it, refused (not waited on) when nothing does
        try:
            fd = os.open(p, os.O_WRONLY | os.O_NONBLOCK)
        except OSError:
            raise InputError(f"cannot write {p}: a FIFO (named pipe) that nothing reads") from None
        os.set_blocking(fd, True)
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        return
    try:
        p.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise InputError(f"cannot write {p}: {exc.strerror or exc}") from None


def check_out(out: str | Path, what: str | None = None, *, probe: bool = False) -> Path:
    """``out`` as a file to write, or a one-line error naming ``what`` (an option) and the reason.

    Refused: a folder; a file in a folder that is missing or no folder (like ``cp`` and ``cc -o``, no
    folders are made for a typo); with ``probe``, a folder this process cannot write in (tried with a
    temporary file: for outputs written only after minutes of work, such as a calibration's).
    """
    p = Path(out).expanduser()
    label = f"{what} {p}" if what else f"cannot write {p}"
    if p.is_dir():
        raise InputError(f"{label}: it is a folder; give a file name")
    folder = p.parent
    if not folder.is_dir():
        why = "is not a folder" if folder.exists() else "does not exist (create it first)"
        raise InputError(f"{label}: folder {folder} {why}")
    if probe:
        import tempfile

        try:
            with tempfile.NamedTemporaryFile(dir=folder, prefix=".designkit-probe-"):
                pass
        except OSError as exc:
            raise InputError(f"{label}: cannot write in {folder} ({exc.strerror or exc})") from None
    return p


def check_out_dir(out: str | Path, what: str) -> Path:
    """``out`` as a folder to write into, or a one-line error naming ``what`` (an option) and the reason.

    The rule of :func:`check_out` for outputs that are folders (a report, recorded trials, a sweep's
    workdir): the folder itself is made if missing, but not a chain of missing folders above it (a typo), and
    a file where the folder should be is refused before any work (``bench --out FILE`` failed with "File
    exists" after its 35 s of measuring).
    """
    p = Path(out).expanduser()
    if p.exists():
        if not p.is_dir():
            raise InputError(f"{what} {p}: it is a file, not a folder; give a folder")
        return p
    folder = p.parent
    if not folder.is_dir():
        why = "is not a folder" if folder.exists() else "does not exist (create it first)"
        raise InputError(f"{what} {p}: folder {folder} {why}")
    return p


@contextmanager
def output_to(out: str | None):
    """Send what the block prints on stdout to ``out`` instead (None or ``-``: stdout, as it is).

    For the commands whose default output is text for people (or ``--json``): their ``--out FILE``
    holds exactly what they would have printed, without colour (an answer with exit status 3 too).
    The folder is checked before the block runs; nothing is written if the block fails.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "answer.txt"
    >>> with output_to(str(out)):
    ...     print("1.23 s")
    >>> out.read_text().splitlines()
    ['1.23 s']
    """
    if out is None or str(out) == "-":
        yield
        return
    check_out(out)
    buf = io.StringIO()
    try:
        with redirect_stdout(buf):
            yield
    except typer.Exit:  # an answer that says there is none (exit 3) is still the output
        write_output(buf.getvalue(), out)
        raise
    write_output(buf.getvalue(), out)


def emit_rows(rows: Sequence[Mapping[str, Any]], columns: Sequence[str] | None = None, *, fmt: str = "table",
              out: str | None = None, **kw: Any) -> None:
    """Print (or write to ``out``) the rows in format ``fmt``: the one row output of the CLI.

    Keyword arguments are :func:`render_rows`'s.
    """
    write_output(render_rows(rows, columns, fmt=fmt, **kw), out)
