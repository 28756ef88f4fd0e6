"""``designkit matrix``: one question over every pair of N materials (designkit.query.matrix).

One library call (:func:`designkit.query.matrix.material_matrix`), printed
through the one row output (:mod:`designkit.cli._format`): the N x N matrix as
rows (table, csv, md) or the library's ``to_dict()`` (json), and a figure on
request (``--plot``).
"""

from __future__ import annotations

from typing import Annotated, List, Optional

import typer

from . import _app
from ._app import app, console
from ._format import FormatOpt, OutOpt, emit_rows, output_format
from ._options import (PANEL_OUTPUT, PANEL_QUESTION, PANEL_SCENE, Explain, IdealTableOpt, Json, SensorOpt, TableOpt,
                       sensor_and_model)

_QUESTIONS = "min-contact, max-noise, min-delta-t or distinguishable"


@app.command("matrix", rich_help_panel=_app.ASK)
def matrix(
    m: Annotated[Optional[List[str]], typer.Option(
        "--m", help="A material (repeat: --m copper --m glass ...); see 'designkit materials list'.", rich_help_panel=PANEL_QUESTION)] = None,
    set_: Annotated[Optional[str], typer.Option(
        "--set", help="Every material of a named set: 'paper12' (the paper's robot materials) or 'database'.", rich_help_panel=PANEL_QUESTION)] = None,
    from_: Annotated[Optional[str], typer.Option(
        "--from", help="Read materials from a file ('-': stdin): one name a line, or a CSV with a 'name' column "
                       "(and 'set'), as 'designkit materials list --format csv' writes it.", rich_help_panel=PANEL_QUESTION)] = None,
    question: Annotated[str, typer.Option("--question", "-q", help=f"What to ask of every pair: {_QUESTIONS}.", rich_help_panel=PANEL_QUESTION)]
    = "min-contact",
    contact: Annotated[Optional[float], typer.Option(
        "--contact", help="Contact time [s] (max-noise, min-delta-t, distinguishable).", rich_help_panel=PANEL_SCENE)] = None,
    noise: Annotated[Optional[float], typer.Option(
        "--noise", help="Noise sigma per sample [°C] (default 0.05; with max-noise only the multi-class curve "
                        "uses it).", rich_help_panel=PANEL_SCENE)] = None,
    delta_t: Annotated[Optional[float], typer.Option(
        "--delta-t", help="Sensor minus object temperature before contact [°C] (default 10; with min-delta-t "
                          "only the multi-class curve uses it).", rich_help_panel=PANEL_SCENE)]
    = None,
    threshold: Annotated[Optional[float], typer.Option(
        "--threshold", help="F1 threshold; must be the table's (0.9 for the shipped tables).", rich_help_panel=PANEL_QUESTION)] = None,
    table: TableOpt = None,
    ideal_table: IdealTableOpt = "ideal-paper",
    multiclass: Annotated[bool, typer.Option(
        "--multiclass/--no-multiclass", help="Add the accuracy of telling all N apart against contact time.", rich_help_panel=PANEL_QUESTION)]
    = True,
    svm_trials: Annotated[Optional[int], typer.Option(
        "--svm-trials", help="Also the SVM's multi-class accuracy, on this many simulated touches per material "
                             "(seconds; e.g. 60).", rich_help_panel=PANEL_QUESTION)] = None,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the SVM's simulated touches.", rich_help_panel=PANEL_QUESTION)] = 0,
    plot: Annotated[Optional[str], typer.Option(
        "--plot", help="Save a figure: heatmap + multi-class accuracy (.png, .svg or .pdf).", rich_help_panel=PANEL_OUTPUT)] = None,
    format_: FormatOpt = None,
    out: OutOpt = None,
    sensor: SensorOpt = "paper",
    json_: Json = False,
    explain: Explain = False,
) -> None:
    """The pairwise matrix of one question over N materials, the pair that limits the design, and the
    accuracy of telling all N apart at once; from the lookup tables (the materials rule: the hardest pair of
    facing-edge classes).

    Example: `designkit matrix --set paper12`

    Example: `designkit matrix --m copper --m "stainless steel" --m glass --m granite -q max-noise --contact 2 --format csv`

    Example: `designkit materials list --family metals --format csv | designkit matrix --from -`

    Cells (table, md and csv alike): the value; ≥ / ≤ before it when the answer lies beyond the table's grid
    (at least / at most that value); 'overlap' when the two effusivity ranges overlap (never told apart);
    'n/a' when the table has no answer; the diagonal is empty. --json gives plain numbers with a status and a
    bound per pair.
    """
    from ..query.inputs import TableMismatch
    from ..query.matrix import material_matrix

    from ._format import check_out
    from ._options import refuse_together

    refuse_together(("--m", m), ("--set", set_), ("--from", from_), why="each names the materials")
    if plot:
        check_out(plot, "--plot")  # before the work, as export's --out
    names = list(m or ()) + (read_material_names(from_) if from_ else [])
    fmt = output_format(format_, json_, default="table")
    from .._validation import check_positive, check_temperature

    if noise is not None:  # -inf, nan and 1e400 were answered
        check_temperature("--noise [°C]", noise, nonnegative=True)
    if delta_t is not None:
        check_temperature("--delta-t [°C]", delta_t)
    if contact is not None:  # a touch the sensor can take (1e308 s: an IndexError, then "n/a")
        from ..sensor import check_samples_per_touch, load_sensor

        check_samples_per_touch(check_positive("--contact [s]", contact), load_sensor(sensor).sample_rate_hz,
                                "--contact", "give a contact time a touch can last")
    scene = {"contact_s": contact, "noise_c": noise, "delta_t_c": delta_t, "threshold": threshold}
    if question in ("max-noise", "min-delta-t", "distinguishable") and contact is None:
        from .._validation import InputError

        raise InputError(f"{question} needs a contact time: give --contact SECONDS")
    if question == "min-contact" and contact is not None:
        from .._validation import InputError

        raise InputError("min-contact asks for the contact time: drop --contact")
    if sensor != "paper":  # a sensor file: its model too; a table built for another sensor is refused
        sen, fm, _ = sensor_and_model(sensor)
        scene.update(sensor=sen, model=fm)
    progress = _progress(json_ or fmt == "json")
    try:
        result = material_matrix(names, question, set=set_, table=table, ideal_table=ideal_table,
                                 multiclass=multiclass, svm_trials=svm_trials, seed=seed,
                                 progress=progress.step if progress else None,
                                 **{k: v for k, v in scene.items() if v is not None})
    except TableMismatch as exc:
        raise TableMismatch(f"{exc}: matrix reads tables only; build this sensor's with 'designkit tables build "
                            f"--sensor {sensor}' (later matrices read it), or ask one pair with --exact "
                            "(designkit distinguishable --sensor ...)") from None
    finally:
        if progress:
            progress.stop()
    if plot:
        from ..figures import plot_matrix

        path = plot_matrix(result, plot)
        console(stderr=True).print(f"figure: {path}", markup=False)
    names = result.names
    rows = []
    vals, status = result.values(), result.status()
    bounds = {}
    for c in result.cells:
        bounds[c.i, c.j] = bounds[c.j, c.i] = c.bound
    for i, a in enumerate(names):
        row = {"material": a}
        for j, b in enumerate(names):
            row[b] = None if i == j else _cell(result.question, vals[i, j], status[i, j], bounds.get((i, j), ""))
        rows.append(row)
    # csv keeps the table's cell text ("≥0.2", "overlap", "n/a", "yes"/"no"; the diagonal empty): a plain number
    # would drop the bound and make an overlap look like the diagonal. --json has plain numbers and a status.
    emit_rows(rows, ["material", *names], fmt=fmt, out=out, payload=result.to_dict(), title=_title(result),
              notes=_notes(result, explain), text=lambda _c, v: "·" if v is None else str(v),
              justify={"material": "left", **{n: "right" for n in names}})


def read_material_names(path: str) -> list[str]:
    """Material names from a file or stdin (``-``): one a line (``#`` comments and blank lines skipped), or a
    CSV whose header has a ``name`` column (a ``set`` column qualifies each name: ``paper12:Glass``)."""
    import csv
    import io
    import sys
    from pathlib import Path

    try:
        text = sys.stdin.read() if path == "-" else Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        from .._validation import InputError

        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else "not a UTF-8 text file"
        raise InputError(f"--from {path}: cannot read it ({why})") from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        from .._validation import InputError

        raise InputError(f"no material names in {'stdin' if path == '-' else path}")
    header = next(csv.reader([lines[0]]))
    if "name" in header:  # a CSV with a 'name' column, a one-column one too (its header was read as a material)
        rows = list(csv.DictReader(io.StringIO("\n".join(lines))))
        return [f"{r['set']}:{r['name']}" if r.get("set") else r["name"] for r in rows if r.get("name")]
    return [ln.strip() for ln in lines]


def _cell(question: str, v: float, status: str, bound: str) -> str:
    if status == "overlap":
        return "overlap"
    if v != v:  # NaN: no answer within the table
        return "n/a"
    if question == "distinguishable":
        return "yes" if v else "no"
    from .._numbers import sig

    return {"at-most": "≤", "at-least": "≥"}.get(bound, "") + sig(v)


#: The library's names of the scene's quantities, as the user wrote them on the command line, with units.
_WORDS = {"contact_s": ("contact", "s"), "noise_c": ("noise", "°C"), "delta_t_c": ("dT", "°C"),
          "threshold": ("F1 threshold", "")}


def _unit(unit: str) -> str:
    return "°C" if unit == "degC" else unit


def _user_words(text: str, r) -> str:
    """The library's sentence in the command line's words: its quantity name and units, the --svm-trials flag."""
    if r.quantity in _WORDS:
        text = text.replace(f" {r.quantity} ", f" {_WORDS[r.quantity][0]} ")
    return (text.replace(" degC", " °C").replace("with svm_trials, designkit matrix --svm-trials N",
                                                  "with designkit matrix --svm-trials N"))


def _title(r) -> str:
    unit = f" [{_unit(r.unit)}]" if r.unit else ""
    sc = ", ".join(f"{_WORDS.get(k, (k,))[0]} {v:g}" + (f" {_WORDS[k][1]}" if _WORDS.get(k, ("", ""))[1] else "")
                   for k, v in r.scene.items() if v is not None and k != "noise_ratio")
    return f"{r.question}{unit} for {len(r.materials)} materials ({sc}; table {r.table})"


def _notes(r, explain: bool = False) -> list[str]:
    """The summary under the matrix: the limiting pair with its interval and ideal bound, the accuracy of telling
    all N apart, a short legend (at most 3 lines); with ``explain`` the whole of it in the library's words."""
    if explain:
        return [_user_words(n, r) for n in _raw_notes(r)]
    return [_user_words(n, r) for n in _short_notes(r)]


def _short_notes(r) -> list[str]:
    from .._numbers import sig

    lim = r.limiting
    overlaps = sum(c.status == "overlap" for c in r.cells)
    tail = f"; {overlaps} pair(s) overlap in effusivity (never told apart)" if overlaps else ""
    unit = _unit(r.unit) if r.unit else ""
    if lim.names and r.question != "distinguishable" and lim.status not in ("none", "overlap"):
        cell = next(c for c in r.cells if {r.names[c.i], r.names[c.j]} == set(lim.names))
        low, high = cell.answer.interval[:2] if cell.answer.interval else (None, None)
        qual = {"at-most": "at most ", "at-least": "at least "}.get(cell.bound, "")
        iv = f" ({sig(low)} to {sig(high, unit)})" if low is not None and high is not None else ""
        notes = [f"Limiting pair: {lim.names[0]} / {lim.names[1]}, {qual}{sig(lim.value, unit)}{iv}, "
                 f"ideal bound {sig(lim.ideal, unit)}{tail}."]
    else:
        notes = [f"Limiting pair: {lim.why}."]
    mc = r.multiclass
    if mc is not None and mc.ideal_accuracy is not None:
        pts = ", ".join(f"{c:g} s {a:.2f}" for c, a in zip(mc.contact_s, mc.ideal_accuracy)
                        if c in (0.5, 1.0, 2.0, 4.0, 10.0))
        notes.append(f"All {len(r.materials)} at once (ideal observer, chance {mc.chance:.2f}): {pts}.")
    notes.append("≤ / ≥: beyond the table's grid; overlap: effusivity ranges overlap; --explain for more.")
    return notes


def _raw_notes(r) -> list[str]:
    notes = [f"Limiting pair: {r.limiting.why}."]
    # one legend for every question: ≤ / ≥ are the answer's own bound (Answer.bound), as min-contact prints it
    notes.append("≤ / ≥: the answer lies beyond the table's grid, at most / at least the value shown; overlap: "
                 "the effusivity ranges overlap, no scene tells every object of one from every object of the "
                 "other; n/a: no answer within the table.")
    mc = r.multiclass
    if mc is not None:
        if mc.ideal_accuracy is not None:
            pts = ", ".join(f"{c:g} s {a:.3f}" for c, a in zip(mc.contact_s, mc.ideal_accuracy)
                            if c in (0.5, 1.0, 2.0, 4.0, 10.0))
            notes.append(f"Telling all {len(r.materials)} apart at once (ideal observer, chance "
                         f"{mc.chance:.3f}): {pts}.")
        if mc.svm_accuracy is not None:
            pts = ", ".join(f"{c:g} s {a:.3f}" for c, a in zip(mc.contact_s, mc.svm_accuracy)
                            if c in (0.5, 1.0, 2.0, 4.0, 10.0))
            notes.append(f"Telling all {len(r.materials)} apart at once (SVM): {pts}.")
        notes.append(mc.note[0].upper() + mc.note[1:] + ".")
    return notes


class _Bar:
    """A rich progress bar on stderr, shown only once the matrix has taken over a second."""

    def __init__(self):
        import time

        self._t0 = time.perf_counter()
        self._time = time.perf_counter
        self._progress = None
        self._task = None

    def step(self, done: int, total: int) -> None:
        if self._progress is None:
            if self._time() - self._t0 < 1.0 or done >= total:
                return
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

            self._progress = Progress(TextColumn("[bold]matrix[/] pairs"), BarColumn(), MofNCompleteColumn(),
                                      TimeRemainingColumn(), console=console(stderr=True), transient=True)
            self._task = self._progress.add_task("pairs", total=total)
            self._progress.start()
        self._progress.update(self._task, completed=done)

    def stop(self) -> None:
        if self._progress is not None:
            self._progress.stop()


def _progress(quiet: bool) -> _Bar | None:
    import sys

    if quiet or not (hasattr(sys.stderr, "isatty") and sys.stderr.isatty()):
        return None
    return _Bar()
