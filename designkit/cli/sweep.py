"""``designkit sweep``: build a delta(e) lookup table (the precomputation engine)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated, Optional

import typer

from ._app import EXIT_INTERRUPTED, app, console, emit_json
from . import _app
from ._options import (BackingOpt, Conductance, Diffusivity, Json, ModelOpt, Thickness, model_from_options,
                       sensor_and_model)


def _floats(text: Optional[str], name: str) -> Optional[tuple[float, ...]]:
    if text is None:
        return None
    try:
        vals = tuple(float(x) for x in text.replace(" ", "").split(",") if x)
    except ValueError:
        raise ValueError(f"{name} must be a comma-separated list of numbers, got {text!r}") from None
    if not vals:
        raise ValueError(f"{name} is empty")
    return vals


@app.command(rich_help_panel=_app.MODEL)
def sweep(
    config: Annotated[Optional[Path], typer.Option("--config", help="Sweep config YAML (tables/*.yaml); options below override it.")] = None,
    name: Annotated[Optional[str], typer.Option("--name", help="Table name.")] = None,
    sensor: Annotated[Optional[str], typer.Option("--sensor", help="Sensor preset or sensor YAML (from calibration).")] = None,
    fidelity: Annotated[Optional[str], typer.Option("--fidelity", help="svm (the paper's classifier) or ideal (the bound).")] = None,
    e_min: Annotated[Optional[float], typer.Option("--e-min", help="Effusivity grid lower end [J s^-1/2 K^-1 m^-2].")] = None,
    e_max: Annotated[Optional[float], typer.Option("--e-max", help="Effusivity grid upper end.")] = None,
    intervals: Annotated[Optional[int], typer.Option("--intervals", help="Number of effusivity intervals (paper: 500).")] = None,
    trials: Annotated[Optional[int], typer.Option("--trials", help="Trials per interval (paper: 100).")] = None,
    folds: Annotated[Optional[int], typer.Option("--folds", help="Cross-validation folds (paper: 3).")] = None,
    threshold: Annotated[Optional[float], typer.Option("--threshold", help="F1 threshold Phi (paper: 0.9).")] = None,
    seed: Annotated[Optional[int], typer.Option("--seed", help="Random seed.")] = None,
    max_repeats: Annotated[Optional[int], typer.Option("--max-repeats", help="Seeds per pair near the threshold.")] = None,
    noise_ratio: Annotated[Optional[str], typer.Option("--noise-ratio", help="sigma/dT axis, comma-separated (fixed initial conditions).")] = None,
    noise: Annotated[Optional[str], typer.Option("--noise", help="sigma axis [°C], comma-separated (varied initial conditions).")] = None,
    delta_t: Annotated[Optional[str], typer.Option("--delta-t", help="dT axis [°C], comma-separated (varied initial conditions).")] = None,
    sensor_temp_spread: Annotated[Optional[float], typer.Option("--sensor-temp-spread", help="Half-width of per-trial Ts0 variation [°C].")] = None,
    ambient_temp_spread: Annotated[Optional[float], typer.Option("--ambient-temp-spread", help="Half-width of per-trial Ta variation [°C].")] = None,
    contact: Annotated[Optional[str], typer.Option("--contact", help="Contact time axis [s], comma-separated.")] = None,
    sample_rate: Annotated[Optional[float], typer.Option("--sample-rate", help="Sampling rate [Hz] (default: the sensor's).")] = None,
    blocks: Annotated[Optional[int], typer.Option("--blocks", help="Split each scene's references into this many parallel blocks.")] = None,
    full_matrix: Annotated[Optional[bool], typer.Option("--full-matrix/--no-full-matrix", help="Score every pair (slow; stores F1 matrices).")] = None,
    model: ModelOpt = None,
    conductance: Conductance = None,
    thickness: Thickness = None,
    backing: BackingOpt = None,
    diffusivity: Diffusivity = None,
    solver: Annotated[Optional[str], typer.Option("--solver", help="SVM solver: batched (default: many pairs at once, same classifier), sklearn (the reference, one pair at a time), batched-cupy (the batched solver on a GPU; pip install 'designkit[gpu]') or batched-array-api (the GPU's code on numpy: what a GPU build should give, checked on the CPU).")] = None,
    jobs: Annotated[int, typer.Option("--jobs", "-j", help="Local worker processes (-1: all cores).")] = -1,
    backend: Annotated[str, typer.Option("--backend", help="loky (local processes) or dask.")] = "loky",
    scheduler: Annotated[Optional[str], typer.Option("--scheduler", help="Dask scheduler address (with --backend dask).")] = None,
    workdir: Annotated[Optional[Path], typer.Option("--workdir", help="Folder for resumable chunks (default: sweeps/NAME).")] = None,
    out: Annotated[Optional[Path], typer.Option("--out", help="Table file or folder (default: WORKDIR/NAME.npz).")] = None,
    resume: Annotated[bool, typer.Option("--resume", help="Continue an interrupted sweep in WORKDIR.")] = False,
    fresh: Annotated[bool, typer.Option("--fresh", help="Discard WORKDIR's finished chunks first.")] = False,
    uncompressed: Annotated[bool, typer.Option("--uncompressed", help="Store the table's arrays uncompressed: larger on disk, but a question maps only the slices it reads (large shipped tables; the content hash is the same).")] = False,
    json_: Json = False,
) -> None:
    """Sweep the physics + classifier model and write a delta(e) lookup table (resumable).

    The forward model comes from the config's `model:` key (default: the paper's semi-infinite
    model); the model options, when given, replace it as a whole (`--thickness 0.002` is a 2 mm
    slab on the default backing, whatever the config said). A slab also needs `--diffusivity`
    (or `diffusivity_m2_s:` in the config): one object diffusivity for every interval.

    Example (a small table of your own; hours for the paper's 500 intervals): `designkit sweep --name my-table --intervals 10 --trials 20 --contact 1,2 --noise-ratio 0.005`
    """
    import time

    from .._validation import InputError
    from ..sweep import SweepInterrupted, run_sweep

    if resume and fresh:
        raise InputError("--resume and --fresh contradict each other: give one")
    if config is None and (intervals is None or contact is None):
        raise InputError("sweep needs --config FILE, or at least --intervals and --contact (without them it "
                         "would start the paper's 500-interval sweep: hours of work)")
    if out is not None and out.suffix and out.parent.exists() and not out.parent.is_dir():
        raise InputError(f"--out {out}: {out.parent} is not a folder")
    fm = None
    if any(v is not None for v in (model, conductance, thickness, backing)):
        fm = model_from_options(model, conductance=conductance, thickness=thickness, backing=backing)
    if sensor is not None:  # a forced sensor file is named; its recorded model answers unless options say otherwise
        sensor_and_model(sensor, model, conductance=conductance, thickness=thickness, backing=backing)
    overrides = dict(name=name, sensor=sensor, fidelity=fidelity, e_min=e_min, e_max=e_max, intervals=intervals,
                     trials=trials, folds=folds, threshold=threshold, seed=seed, max_repeats=max_repeats,
                     noise_ratio=_floats(noise_ratio, "--noise-ratio"), noise_c=_floats(noise, "--noise"),
                     delta_t_c=_floats(delta_t, "--delta-t"), sensor_temp_spread_c=sensor_temp_spread,
                     ambient_temp_spread_c=ambient_temp_spread, contact_s=_floats(contact, "--contact"),
                     sample_rate_hz=sample_rate, blocks=blocks, full_matrix=full_matrix, model=fm,
                     diffusivity_m2_s=diffusivity, solver=solver)
    cfg = _config(config, overrides)
    wd, target = _outputs(cfg, workdir, out)
    con = console(stderr=True)
    total = len(cfg.scene_points()) * len(cfg.blocks_of()) * len(cfg.contact_s)
    started = time.perf_counter()
    stats = {"fits": 0, "computed": 0}
    progress, on_chunk = _progress(con, cfg, total, stats, started, quiet=json_)
    try:
        path = run_sweep(cfg, wd, out=target, jobs=jobs, backend=backend, scheduler=scheduler, resume=resume,
                         fresh=fresh, on_chunk=on_chunk, compress=not uncompressed)
    except SweepInterrupted as exc:
        if progress is not None:
            progress.stop()
        typer.echo(f"Interrupted: {exc.done} of {exc.total} chunks are saved in {exc.workdir}; "
                   f"run the same command with --resume to continue.", err=True)
        raise typer.Exit(EXIT_INTERRUPTED) from None
    finally:
        if progress is not None:
            progress.stop()
    elapsed = time.perf_counter() - started
    summary = {"table": str(path), "header": str(path.with_suffix(".json")), "workdir": str(wd),
               "chunks_total": total, "chunks_computed": stats["computed"], "svm_fits": stats["fits"],
               "elapsed_s": elapsed, "model": cfg.model.to_dict(), "config": cfg.to_dict()}
    if json_:
        emit_json(summary)
        return
    out_con = console()
    out_con.print(f"[bold green]Wrote[/] {path} (+ .json): {total} chunks "
                  f"({stats['computed']} computed now), {stats['fits']} SVM fits, {elapsed:.1f} s; "
                  f"model {_markup_escape(cfg.model.describe())}"
                  + (f" (recorded in sensor file {_markup_escape(cfg.sensor)})" if fm is None and cfg.model.name !=
                     "semi-infinite" else ""))
    sys.stdout.flush()


def _markup_escape(text: str) -> str:
    from ._app import escape

    return escape(text)


def _config(config: Optional[Path], overrides: dict):
    """The sweep's configuration: the YAML file with the options over it, or the options alone."""
    from ..sweep import SweepConfig

    if overrides["noise_c"] is not None or overrides["delta_t_c"] is not None:
        overrides.setdefault("noise_ratio", None)
    if config is not None:
        return SweepConfig.from_yaml(config, **overrides)
    given = {k: v for k, v in overrides.items() if v is not None}
    if "noise_c" in given:
        given.setdefault("noise_ratio", None)
    return SweepConfig.from_mapping(given, source="options")


def _outputs(cfg, workdir: Optional[Path], out: Optional[Path]) -> tuple[Path, Optional[Path]]:
    """The work folder and the table file, checked before any work (as every command's outputs)."""
    from ._format import check_out, check_out_dir

    if workdir is not None:
        check_out_dir(workdir, "--workdir")
    wd = workdir if workdir is not None else Path("sweeps") / cfg.name
    target = out
    if target is not None and (target.is_dir() or target.suffix == ""):
        target = check_out_dir(target, "--out") / f"{cfg.name}.npz"
    elif target is not None:
        check_out(target, "--out")
    return wd, target


def _progress(con, cfg, total: int, stats: dict, started: float, *, quiet: bool):
    """What the sweep shows while it runs: a bar on a terminal, else a line per chunk computed on stderr.

    Returns (the rich Progress to stop, or None; the per-chunk callback, which counts into ``stats``)."""
    import time

    if con.is_terminal and not quiet:
        from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn,
                                   TimeRemainingColumn)

        progress = Progress(TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                            TextColumn("chunks"), TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
                            TextColumn("{task.fields[fits]} SVM fits"), console=con, transient=False)
        task = progress.add_task(f"sweep {cfg.name}", total=total, fits=0)
        progress.start()

        def on_bar(res, computed, done, total_):
            stats["fits"] += res.fits
            stats["computed"] += computed
            progress.update(task, completed=done, fits=stats["fits"])

        return progress, on_bar

    def on_chunk(res, computed, done, total_):
        stats["fits"] += res.fits
        stats["computed"] += computed
        if computed:
            con.print(f"[{time.perf_counter() - started:8.1f} s] chunk {done}/{total_}: scene {res.point} "
                      f"contact {cfg.contact_s[res.contact_index]:g} s, {res.fits} fits, {res.wall_s:.1f} s",
                      highlight=False)

    return None, on_chunk
