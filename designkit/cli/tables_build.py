"""``designkit tables build --sensor FILE``: the table a calibrated sensor's questions need, registered for it."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated, Optional

import typer

from ._app import EXIT_INTERRUPTED, console, emit_json
from ._options import Json


def tables_build(
    sensor: Annotated[str, typer.Option("--sensor", help="Sensor file written by 'designkit calibrate fit' (with "
                                        "the rig's conditions).")],
    materials: Annotated[Optional[str], typer.Option(
        "--materials", help="Span the effusivities of a material set (paper12 or database).")] = None,
    m: Annotated[Optional[list[str]], typer.Option(
        "--m", help="Span the effusivities of these materials (repeatable).")] = None,
    e_range: Annotated[Optional[tuple[float, float]], typer.Option(
        "--e-range", help="Span this effusivity range LO HI [J s^-1/2 K^-1 m^-2] (default, with no materials: "
                          "0 to 40000, the shipped tables').")] = None,
    out: Annotated[Optional[Path], typer.Option(
        "--out", help="Folder (or .npz) for the table's files (default: the sensor-table registry in the user's "
                      "data folder; 'designkit tables build --help' says where).")] = None,
    contact_points: Annotated[Optional[int], typer.Option(
        "--contact-points", help="Contact times tabulated, geometric from one of the sensor's time scales after the "
                                 "rig's detected onset to 8 of them (default: a ratio of at most 1.35 between "
                                 "neighbours; 8 for the real rig, 0.75 to 6 s).")] = None,
    noise_factors: Annotated[Optional[str], typer.Option(
        "--noise-factors", help="sigma/dT tabulated, as multiples of the rig's own, comma-separated, 1 among them "
                                "(default 1: the rig's alone; each factor costs as much as the first).")] = None,
    trials: Annotated[int, typer.Option("--trials", help="Touches per effusivity interval (the paper: 100).")] = 100,
    seed: Annotated[int, typer.Option("--seed", help="Random seed.")] = 0,
    jobs: Annotated[int, typer.Option("--jobs", "-j", help="Worker processes (-1: all cores).")] = -1,
    json_: Json = False,
) -> None:
    """Build the lookup table of a calibrated sensor and register it, so that its questions answer in
    milliseconds.

    The table is swept at the rig's conditions as calibrated (its model, its sigma/dT, its correlated
    noise, touches read and contact times counted from the rig's detected onset) over the effusivities of the materials named
    (or a range, or 0 to 40000). It is registered under the digest of the sensor's content in the user's
    data folder (``$DESIGNKIT_DATA_DIR`` when set): later `--sensor FILE` questions read it; an edited or
    recalibrated sensor file has another digest and is computed again until its own table is built. A
    question outside the table's span (another material, noise or contact time) is refused in one line
    (exit 2) naming the way out: `--exact`, or a table built over a wider span.

    The paper's 12 materials at the paper's 100 trials per interval: `--materials paper12` (for the real rig 1,337
    CPU s, 11 min 22 s on 2 idle cores with engine version 4; benchmarks/results/sensor_table_build.txt).

    Example (two materials, a quick coarse table): `designkit tables build --sensor my-sensor.yaml --m wood --m glass --trials 10 --contact-points 4`
    """
    from ..sweep import SweepInterrupted
    from ..sweep.for_sensor import build_sensor_table, effusivity_span, sensor_sweep_config
    from ._format import check_out, check_out_dir

    span = effusivity_span(material_set=materials, materials=tuple(m or ()), e_range=e_range)
    cfg = sensor_sweep_config(sensor, span=span, contact_points=contact_points, trials=trials, seed=seed,
                              noise_factors=_factors(noise_factors))
    if out is not None:
        if out.suffix == ".npz":
            check_out(out, "--out")
        else:
            out = check_out_dir(out, "--out") / f"{cfg.name}.npz"
    con = console(stderr=True)
    total = len(cfg.scene_points()) * len(cfg.blocks_of()) * len(cfg.contact_s)
    stats = {"fits": 0}
    started, cpu0 = time.perf_counter(), _cpu_s()
    progress = None
    if con.is_terminal and not json_:
        from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn,
                                   TimeRemainingColumn)

        progress = Progress(TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                            TextColumn("chunks"), TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
                            TextColumn("{task.fields[fits]} SVM fits, {task.fields[where]}"), console=con)
        task = progress.add_task(f"table for sensor {Path(sensor).name}", total=total, fits=0, where="")
        progress.start()

    def on_chunk(res, computed, done, total_):
        stats["fits"] += res.fits
        where = f"sigma/dT {cfg.noise_ratio[res.point[0]]:.3g}, contact {cfg.contact_s[res.contact_index]:.3g} s"
        if progress is not None:
            progress.update(task, completed=done, fits=stats["fits"], where=where)
        elif not json_:
            con.print(f"[{time.perf_counter() - started:7.1f} s] chunk {done}/{total_}: {where}, {res.fits} fits",
                      highlight=False)
    try:
        built = build_sensor_table(cfg, out=out, jobs=jobs, on_chunk=on_chunk)
    except SweepInterrupted as exc:
        if progress is not None:
            progress.stop()
        typer.echo(f"Interrupted: {exc.done} of {exc.total} chunks are saved; the same command continues.", err=True)
        raise typer.Exit(EXIT_INTERRUPTED) from None
    finally:
        if progress is not None:
            progress.stop()
    summary = {**built.to_dict(), "effusivity_span": {"min": span.e_min, "max": span.e_max, "source": span.source},
               "svm_fits": stats["fits"], "elapsed_s": time.perf_counter() - started,
               "cpu_s": _cpu_s() - cpu0}
    if json_:
        emit_json(summary)
        return
    from ._app import escape

    console().print(
        f"[bold green]Built[/] {escape(str(built.table))} for sensor {escape(built.sensor_name)} "
        f"({span.source}, {cfg.intervals} intervals; sigma/dT {', '.join(f'{r:.3g}' for r in cfg.noise_ratio)}; "
        f"contact {built.contacts_from_onset_s[0]:g} to {built.contacts_from_onset_s[-1]:g} s from the onset): "
        f"{stats['fits']} SVM fits, {summary['elapsed_s']:.0f} s, {summary['cpu_s']:.0f} CPU s\n"
        f"registered: {escape(str(built.entry))}; questions with --sensor {escape(sensor)} now answer from it")


def _cpu_s() -> float:
    """CPU seconds of this process and its workers, running or finished (the build's own cost, what a shared
    machine's wall clock does not show)."""
    import os

    import psutil

    t = os.times()
    alive = 0.0
    for child in psutil.Process().children(recursive=True):
        try:
            c = child.cpu_times()
            alive += c.user + c.system
        except psutil.Error:  # gone meanwhile: counted in children_* once waited for
            pass
    return t.user + t.system + t.children_user + t.children_system + alive


def _factors(text: Optional[str]) -> tuple[float, ...]:
    """``--noise-factors`` read (one line naming what is wrong otherwise)."""
    from .._validation import InputError
    from ..sweep.for_sensor import NOISE_FACTORS

    if text is None:
        return NOISE_FACTORS
    try:
        return tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise InputError(f"--noise-factors must be numbers separated by commas, got {text!r}") from None
