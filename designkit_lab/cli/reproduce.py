"""``designkit reproduce``: the paper's analyses as a report (:mod:`designkit_lab.reproduce`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, List, Optional

import typer

from designkit.cli._app import app, console, emit_json
from designkit.cli._options import Json, Seed

from . import REPORTS

_SECTIONS_HELP = ("f1-matrices, delta-curves, effusivity, node-graphs, table1, guideline, real-robot, "
                  "sim-to-real, multiclass")


@app.command(rich_help_panel=REPORTS)
def reproduce(
    out: Annotated[Path, typer.Option("--out", help="Report folder: report.md, report.json, figures/, data/.")],
    only: Annotated[Optional[List[str]], typer.Option(
        "--only", help=f"Only these sections (repeat or comma-separate): {_SECTIONS_HELP}.")] = None,
    tables: Annotated[Optional[Path], typer.Option(
        "--tables", help="Folder searched for lookup tables before the shipped ones.")] = None,
    robot_data: Annotated[Optional[Path], typer.Option(
        "--robot-data", help="Folder of the real robot recordings (default: $DESIGNKIT_ROBOT_DATA, else "
                             "shared/data/robot-thermal-recordings in the current folder or the nearest folder "
                             "above it that has one).")] = None,
    quick: Annotated[bool, typer.Option(
        "--quick", help="Fewer Monte Carlo repeats and trials in the parts computed now (a first look; tests).")] = False,
    jobs: Annotated[int, typer.Option("--jobs", "-j", help="Worker processes for the computed queries (-1: all cores).")] = 1,
    figure_format: Annotated[str, typer.Option(
        "--figure-format", help="Figures as png (200 dpi) or vector: svg, pdf.")] = "png",
    seed: Seed = 0,
    json_: Json = False,
) -> None:
    """Reproduce the paper's figures and tables (F1 matrices, δ(e) curves, node graphs, Table I, guideline,
    real robot, sim-to-real, multi-class) into a markdown report with figures, beside the paper's numbers.

    The whole report, every section: `designkit reproduce --out report` (minutes).

    Example: `designkit reproduce --out report --only f1-matrices,guideline`

    Example: `designkit reproduce --out report --only f1-matrices --figure-format svg`
    """
    from ..reproduce import ReproduceSettings, parse_only
    from ..reproduce import reproduce as run

    names = parse_only(only)
    settings = ReproduceSettings(tables_dir=tables, robot_data=robot_data, quick=quick, seed=seed, jobs=jobs,
                                 figure_format=figure_format)
    con = console(stderr=True)
    progress = None
    if con.is_terminal and not json_:
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

        progress = Progress(TextColumn("[bold]reproduce[/] {task.fields[section]:<13}"), BarColumn(),
                            TextColumn("{task.percentage:>3.0f}%"), TimeElapsedColumn(), TextColumn("ETA"),
                            TimeRemainingColumn(), console=con, transient=False)
        task = progress.add_task("reproduce", total=1.0, section="")
        progress.start()

        def on_progress(section, completed, total):
            progress.update(task, completed=completed / total if total else 1.0, section=section)
    else:
        last = {"section": None}

        def on_progress(section, completed, total):
            if section != last["section"] and not json_:
                last["section"] = section
                con.print(f"reproduce: {section} ...", highlight=False)
    try:
        result = run(out, names, settings, on_progress)
    finally:
        if progress is not None:
            progress.stop()
    if json_:
        emit_json(result.to_dict())
        return
    out_con = console()
    skipped = [s for s in result.sections if s.skipped]
    out_con.print(f"[bold green]Wrote[/] {result.report} ({len(result.sections)} sections, "
                  f"{len(result.figures)} figures, {result.wall_s:.0f} s); numbers in {result.report_json}")
    for s in skipped:
        out_con.print(f"  [yellow]{s.name}: partly skipped[/] — {s.skipped}")
