"""``designkit bench``: accuracy against run time across the pipeline, and the sweep's cost curve."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, List, Optional

import typer

from designkit.cli._app import app, console, emit_json
from designkit.cli._options import Json

from . import REPORTS

SECTION_HELP = "Only these sections (repeatable): physics, recognition, delta, queries, cost. Default: all."


@app.command("bench", rich_help_panel=REPORTS)
def bench_cmd(
    quick: Annotated[bool, typer.Option("--quick", help="Fewer cases and smaller references: a few minutes on 2 cores.")] = False,
    out: Annotated[Optional[Path], typer.Option("--out", help="Folder to write accuracy.md, its figures and accuracy.json into (docs/ for the shipped page).")] = None,
    section: Annotated[Optional[List[str]], typer.Option("--section", "-s", help=SECTION_HELP)] = None,
    seed: Annotated[int, typer.Option("--seed", help="Seed of every random draw (same seed, same errors).")] = 0,
    table: Annotated[str, typer.Option("--table", help="SVM table whose queries are checked against --exact (skipped if absent).")] = "svm-paper",
    ideal_table: Annotated[str, typer.Option("--ideal-table", help="Ideal-observer table checked against the closed form.")] = "ideal-paper",
    jobs: Annotated[int, typer.Option("--jobs", "-j", help="Processes for the exact SVM queries (1 keeps timings sequential).")] = 1,
    json_: Json = False,
) -> None:
    """Measure every way designkit answers a question against a high-fidelity reference, in one run.

    Prints one row per method and setting: error against the reference, time
    per answer, speed-up; then the sweep's cost curves with fitted exponents.
    `--quick` takes a few minutes on 2 cores; the full run about half an hour.

    Example: `designkit bench --quick --section physics --out bench`
    """
    import time

    from designkit.cli._format import check_out_dir

    from .. import accuracy

    sections = accuracy.check_sections(section or accuracy.SECTIONS)
    from designkit._workers import worker_count

    worker_count(jobs)  # the one rule of --jobs, before minutes of measuring (0 was taken)
    if out is not None:
        check_out_dir(out, "--out")  # a file there failed "File exists" after the whole run
        accuracy.require_figures()  # refuse now, not after minutes of measuring
    err = console(stderr=True)
    started = time.perf_counter()
    if err.is_terminal and not json_:
        from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

        progress = Progress(SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn(), console=err,
                            transient=True)
        task = progress.add_task("starting", total=None)
        progress.start()

        def say(msg: str) -> None:
            progress.update(task, description=msg)
    else:
        progress = None

        def say(msg: str) -> None:
            if not json_:
                err.print(f"[{time.perf_counter() - started:6.1f} s] {msg}", highlight=False)
    try:
        report = accuracy.run_bench(quick=quick, seed=seed, sections=sections, svm_table=table, ideal_table=ideal_table,
                                 jobs=jobs, progress=say)
    finally:
        if progress is not None:
            progress.stop()
    written = accuracy.write_report(report, out) if out is not None else {}
    if json_:
        payload = report.to_dict()
        payload["written"] = {k: str(v) for k, v in written.items()}
        emit_json(payload)
        return
    con = console()
    if not con.is_terminal:
        con.width = max(con.width, 160)  # piped into a file: do not squeeze the table to 80 columns
    accuracy.print_report(report, written, con)
