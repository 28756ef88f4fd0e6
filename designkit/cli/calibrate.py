"""``designkit calibrate`` (record, fit, and the guided run).

Turning one's own sensor into a sensor file that ``--sensor`` accepts:
record touches of materials with known effusivity ranges over serial, then
identify e_s and alpha_s (paper appendix). ``designkit emulate`` (the lab's)
plays a simulated rig on a pseudo-terminal, for trying all of this without hardware.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from ._app import EXIT_INTERRUPTED, console, emit_json, sub_app
from . import _app
from ._options import PANEL_OUTPUT, Json

#: ``designkit calibrate --help``: the group's and the guided run's (the group's callback) help in one,
#: since typer shows the group's text, not the callback's docstring.
_CALIBRATE_HELP = """Calibrate your sensor: record touches over serial ('record'), identify e_s and alpha_s ('fit'), \
or both in one guided run (the options below).

The guided run records --trials touches of the first --material, then of the next, and so on, then fits \
and writes the sensor file. Against 'designkit emulate': it touches each of its materials \
--touches-per-material times (default 10, as --trials here) in the order given, starting when the port \
is opened; give the same materials in the same order and --yes (the emulator does not wait for Enter). \
The command it prints after 'try:' does this; a run whose labels its plan contradicts stops before \
recording.

Example: `designkit calibrate --port /dev/ttyACM0 --material wood --material "aluminium alloys" --out trials/ --yes`
"""

calibrate_app = sub_app("calibrate", _CALIBRATE_HELP, panel=_app.SENSOR)

PortOpt = Annotated[Optional[str], typer.Option(
    "--port", help="Serial port of the rig (/dev/ttyACM0, COM3, or the pty 'designkit emulate' prints).")]
ProfileOpt = Annotated[str, typer.Option(
    "--profile", help="Device profile: a shipped name ('designkit', 'adc12-thermistor') or a profile YAML file.")]
TrialsOpt = Annotated[int, typer.Option("--trials", help="Touches to record per material (at most 1000).")]
#: Touches per material the guided run records and the emulator plays by default: the same, so that
#: 'designkit emulate' with two materials and the guided run agree on which touch is which.
DEFAULT_TRIALS = 10
TimeoutOpt = Annotated[Optional[float], typer.Option(
    "--timeout", help="Give up when the device sends nothing for this long [s] (default: the profile's).")]
RangeOpt = Annotated[Optional[list[str]], typer.Option(
    "--range", help="Effusivity range of a material: NAME=MIN:MAX [J s^-1/2 K^-1 m^-2] or NAME=DATABASE_NAME "
                    "(repeatable); materials without one are looked up in the materials database.")]
ObjectTempOpt = Annotated[Optional[list[str]], typer.Option(
    "--object-temp", help="Object temperature of a material: NAME=passive (pre-contact passive channel, the "
                          "default), NAME=passive-end, NAME=free (unknown: fitted per trial) or NAME=DEGC.")]
DepthOpt = Annotated[float, typer.Option(
    "--depth-um", help="Thermistor depth below the contact surface [um], held fixed (only x^2/alpha_s is "
                       "identifiable).")]
#: Most touches per material one run records (a touch takes at least the trial window, 8 s by default).
MAX_TRIALS = 1000


# ---------------------------------------------------------------- helpers
def _check_trials(trials: int) -> None:
    from .._validation import InputError

    if not 1 <= trials <= MAX_TRIALS:
        raise InputError(f"--trials must be 1 to {MAX_TRIALS} touches per material, got {trials}")


def _check_timeout(timeout: Optional[float]) -> None:
    """Refuse a --timeout the recorder could never reach (NaN compares false: it waited forever)."""
    from .._validation import InputError

    if timeout is not None and not (math.isfinite(timeout) and timeout > 0):
        raise InputError(f"--timeout must be a positive, finite number of seconds, got {timeout:g}")


def _status_table(st) -> Any:
    from rich.table import Table

    table = Table.grid(padding=(0, 2))
    table.add_column(style="dim")
    table.add_column()

    def num(v, fmt, unit):
        return "–" if v is None or not math.isfinite(v) else f"{v:{fmt}} {unit}"

    table.add_row("port", f"{st.port}   material [bold]{st.material}[/]")
    table.add_row("trials", f"[bold]{st.trials}[/] / {st.target}   ({st.state})")
    table.add_row("sensor", num(st.sensor_c, ".3f", "°C"))
    table.add_row("object", num(st.object_c, ".3f", "°C"))
    table.add_row("force", num(st.force_n, ".2f", "N"))
    bad = ", ".join(f"{k} {v}" for k, v in sorted(st.bad_by_kind.items())) or "none"
    table.add_row("lines", f"{st.lines_ok} ok, bad: {bad}; gaps {st.gaps}, touches skipped {st.skipped}")
    table.add_row("device time", f"{st.device_time_s:.1f} s")
    return table


class _Display:
    """Live rich display on stderr when it is a terminal; plain event lines otherwise."""

    def __init__(self, quiet: bool) -> None:
        self.con = console(stderr=True)
        self.quiet = quiet
        self.live = None
        self.last = 0.0

    def __enter__(self) -> "_Display":
        if not self.quiet and self.con.is_terminal:
            from rich.live import Live

            self.live = Live(console=self.con, refresh_per_second=6, transient=False)
            self.live.__enter__()
        return self

    def __exit__(self, *exc) -> None:
        if self.live is not None:
            self.live.__exit__(*exc)

    def event(self, e) -> None:
        if self.quiet:
            return
        style = {"trial": "green", "skipped": "yellow", "bad_line": "yellow", "gap": "yellow",
                 "reconnect": "cyan"}.get(e.kind, "dim")
        self.con.print(f"[{style}]{e.message}[/]", markup=True, highlight=False)

    def status(self, st) -> None:
        if self.live is not None:
            self.live.update(_status_table(st))


class _ForceWatch:
    """Touches the contact rule misses: force rises and falls again, peaking below the threshold.

    Fed the recorder's live status (a few times a second); after ``MISSED`` such touches with no
    trial recorded it raises an InputError naming the observed peaks and the threshold.
    """

    MISSED = 3

    def __init__(self, profile) -> None:
        rule = profile.contact
        self.threshold = rule.force_threshold_n if rule.rule == "force" else None
        self.peaks: list[float] = []
        self.current: float | None = None

    def __call__(self, st) -> None:
        if self.threshold is None or st.trials > 0 or not math.isfinite(st.force_n):
            self.current = None
            return
        lo = 0.2 * self.threshold
        if st.force_n > lo:
            self.current = max(self.current or 0.0, st.force_n)
        elif self.current is not None:
            if self.current < self.threshold:
                self.peaks.append(self.current)
            self.current = None
        if len(self.peaks) >= self.MISSED:
            from .._validation import InputError

            lo, hi = f"{min(self.peaks):.2g}", f"{max(self.peaks):.2g}"
            raise InputError(
                f"{len(self.peaks)} touches were not recorded: their force peaked at "
                f"{lo if lo == hi else f'{lo}-{hi}'} N, below the profile's contact threshold of {self.threshold:g} N. Lower "
                f"force_threshold_n in the profile (e.g. to {0.75 * min(self.peaks):.2g} N, with release_n below "
                "it), or press harder")


class _CommentWatch:
    """A stream whose every line starts with the profile's comment prefix: samples taken for messages.

    Fed the recorder's events; after ``LIMIT`` device messages and not one sample it raises an
    InputError (a rig whose data lines start with, say, ``#T`` under ``comment: "#"``).
    """

    LIMIT = 200

    def __init__(self, profile) -> None:
        self.profile = profile
        self.n = 0
        self.example = ""

    def __call__(self, event, lines_ok: int) -> None:
        if event.kind != "device" or not self.profile.comment or lines_ok:
            return
        self.n += 1
        self.example = event.message.removeprefix("device: ")
        if self.n >= self.LIMIT:
            from .._validation import InputError

            rest = self.example[len(self.profile.comment):]
            data_like = sum(c.isdigit() for c in rest) >= 3
            raise InputError(
                f"all {self.n} lines from the device start with the profile's comment prefix "
                f"{self.profile.comment!r} (e.g. {self.example[:60]!r}), so each was taken as a device message "
                "and not one sample was read"
                + (": they look like data lines that begin with it" if data_like else "")
                + ". Set the profile's comment to a prefix the data lines do not start with (or remove it), or "
                  "make the rig send its messages with a different prefix")


class _EmulatorWatch:
    """``designkit emulate``'s own announcements (device messages) against this run's labels.

    Its first line announces the plan: a run whose labels it contradicts is refused before its
    first trial. Each touch is announced as it starts (before its onset): a touch that would get
    another material's label (a run out of step: touches lost while waiting for Enter) stops the
    run before it is recorded. Each of the run's names must stand for one of the emulator's
    materials and no two for the same; a name that is one of its labels (any case) for that one.
    """

    def __init__(self, materials: list[str], trials: int, port: str, out: Path) -> None:
        self.materials, self.trials, self.port, self.out = materials, trials, port, out
        self.pairs: dict[str, str] = {}
        self.labels: set[str] = set()
        self.session = ""   # the recorder's: its trials' sidecars name it

    def _kept(self) -> str:
        from ..calibration.trials import session_trials

        n = len(session_trials(self.out, self.session))
        return f"{n} trial(s) kept" + (f" in {self.out}" if n else "")

    def __call__(self, message: str, material: str) -> None:
        from .._validation import InputError
        from ..calibration.touch_plan import parse_announcement, parse_greeting

        advice = ("with the emulator, give its materials in its order, --trials equal to its "
                  "--touches-per-material, and --yes (the command it prints after 'try:')")
        plan = parse_greeting(message)
        if plan is not None:
            self.labels |= {lab.lower() for lab in plan.labels}
            why = plan.mislabels(self.materials, self.trials)
            if why is not None:
                fix = guided_command(self.port, None, list(plan.labels), plan.touches_per_material)
                raise InputError(
                    f"{why}: every trial would get a wrong label, so none is recorded. Record what the emulator "
                    f"plays (e.g. {fix}), or restart it with its --material options in the order of this run's "
                    f"and --touches-per-material {self.trials}")
            return
        touch = parse_announcement(message)
        if touch is None:
            return
        j, label, plan = touch
        self.labels.add(label.lower())
        if plan is not None:
            self.labels |= {lab.lower() for lab in plan.labels}
        prev = self.pairs.get(material)
        other = next((m for m, lab in self.pairs.items() if lab == label and m != material), None)
        if prev is not None and prev != label:
            why = f"this run's touches of {material} so far were {prev}"
        elif other is not None:
            why = f"this run recorded {label} as {other}"
        elif material.lower() in self.labels and material.lower() != label.lower():
            why = f"{material} is another of its materials"
        else:
            self.pairs[material] = label
            return
        raise InputError(f"the emulator on {self.port} starts touch {j} with {label} while this run records "
                         f"{material} ({why}): recording stops before a touch gets the wrong label; "
                         f"{self._kept()}. {advice[0].upper()}{advice[1:]}")


def guided_command(port: str, profile: Optional[str], materials: list[str], trials: int,
                    ranges: Optional[list[str]] = None) -> str:
    """A guided ``designkit calibrate`` command line a shell reads back as these arguments."""
    import shlex

    args = ["designkit", "calibrate", "--port", port]
    if profile is not None:
        args += ["--profile", profile]
    for m in materials:
        args += ["--material", m]
    for r in ranges or []:
        args += ["--range", r]
    args += ["--trials", str(trials), "--out", "trials/", "--yes"]
    return shlex.join(args)


def _record_materials(port: str, profile, out: Path, materials: list[str], trials: int, timeout: Optional[float],
                      quiet: bool, prompt: bool):
    """Record each material in turn on one open connection; returns (recorder, paths, interrupted).

    ``paths`` are the trials this run added to the folder's index, read back
    from disk: after Ctrl-C the recorder cannot know how far it got (the
    interrupt may come between a trial's commit and its being remembered).
    """
    from ..calibration.recorder import SerialRecorder
    from ..calibration.trials import session_trials

    display = _Display(quiet)
    watch = _ForceWatch(profile)

    def on_status(st) -> None:
        display.status(st)
        watch(st)

    comments = _CommentWatch(profile)

    def on_event(e) -> None:
        if not (e.kind == "device" and comments.n >= 3 and rec.status.lines_ok == 0):
            display.event(e)  # a stream of nothing but messages: show the first few, then the verdict
        comments(e, rec.status.lines_ok)
        if e.kind == "device":
            emulator(e.message, rec.status.material)

    emulator = _EmulatorWatch(materials, trials, port, out)
    rec = SerialRecorder(port, profile, out, no_data_timeout_s=timeout, on_event=on_event,
                         on_status=on_status)
    emulator.session = rec.session
    interrupted = False
    try:
        rec.open()
        for i, material in enumerate(materials):
            if prompt:
                con = console(stderr=True)
                con.print(f"[bold]Next: {trials} touches of {material}.[/] Put the sample under the sensor, "
                          "then press Enter. Press each touch to the same force, some quickly and some slowly "
                          "(about 0.2 to 1.5 s to full force): that tells where the contact area starts from "
                          "when the heat flows.")
                sys.stdin.readline()
                rec.flush_input()
            elif i > 0:
                rec.flush_input()
            with display:
                watch.peaks.clear()
                rec.record(material, trials)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        rec.close()
    order = {p: i for i, p in enumerate(rec.written)}  # recording order; index order for any other
    # this session's trials (their sidecars name it), not others a rebuilt index lists too
    paths = sorted(session_trials(out, rec.session), key=lambda p: order.get(p, len(order)))
    return rec, paths, interrupted


def _record_payload(rec, paths, out: Path, interrupted: bool) -> dict:
    st = rec.status
    return {
        "trials": [str(p) for p in paths],
        "n_trials": len(paths),
        "session": rec.session,   # named in each of these trials' sidecars
        "out": str(out),
        "index": str(out / "index.csv") if paths else None,
        "interrupted": interrupted,
        "lines_ok": st.lines_ok,
        "bad_lines": dict(st.bad_by_kind),
        "gaps": st.gaps,
        "touches_skipped": st.skipped,
        "events": [{"kind": e.kind, "message": e.message} for e in rec.events],
    }


def _parse_sets(spec: str) -> list[int]:
    from .._validation import InputError

    out: list[int] = []
    try:
        for part in spec.split(","):
            lo, sep, hi = part.strip().partition("-")
            out += list(range(int(lo), int(hi) + 1)) if sep else [int(lo)]
    except ValueError:
        raise InputError(f"--fit-sets must look like 1-4 or 1,2,3 (or 'all'), got {spec!r}") from None
    if not out:
        raise InputError(f"--fit-sets names no trial set: {spec!r}")
    return out


def _offset_bounds(offset_range: str) -> tuple[float, float]:
    """``--offset-range MIN:MAX`` [s], checked."""
    from .._validation import InputError

    lo, sep, hi = offset_range.partition(":")
    try:
        bounds = (float(lo), float(hi))
    except ValueError:
        raise InputError(f"--offset-range must look like MIN:MAX in seconds, got {offset_range!r}") from None
    if not sep or not (math.isfinite(bounds[0]) and math.isfinite(bounds[1]) and bounds[0] < bounds[1]):
        raise InputError(f"--offset-range must look like MIN:MAX in seconds with MIN < MAX, got {offset_range!r}")
    return bounds


def _cut(trials, fit_to: Optional[float]):
    """The touches up to ``fit_to`` s after the onset (all of each without it)."""
    from .._validation import InputError
    from ..calibration.trials import Trial

    if fit_to is None:
        return trials
    if not (math.isfinite(fit_to) and fit_to > 0):
        raise InputError(f"--fit-to must be a positive, finite time after onset [s], got {fit_to:g}")
    out = []
    for tr in trials:
        keep = tr.time_s <= fit_to
        out.append(Trial(tr.time_s[keep], tr.sensor_c[keep], tr.object_c[keep], tr.force_n[keep], tr.material,
                         tr.source, tr.meta))
    return out


#: Least contact after the detected onset [s] a touch needs for any candidate (the host smoothing's window
#: is 0.5 s; the force-area candidates also need the force to 1 s after the onset, and are left out below it).
MIN_CONTACT_S = 0.5


def _write_identified(best, trials, out: Path, name: Optional[str], index: Path, force: bool, names,
                      extra: Optional[dict] = None) -> list[str]:
    """Write the selected model's sensor file, or refuse (exit 2) when its fit is unusable and not forced.

    Returns the problems written into the file's provenance (so that ``--sensor`` can warn).
    """
    from ._app import escape

    from .._validation import InputError
    from ..calibration.fit import check_calibration

    problems = [p.text() for p in check_calibration(best, trials) if p.fatal]
    con = console(stderr=True)
    for text in problems:
        con.print(f"[bold red]{'warning' if force else 'error'}:[/] {escape(text)}")
    if problems and not force:
        raise InputError(f"calibration unusable ({len(problems)} problem(s) above): {out} not written; "
                         "--force writes the sensor file anyway")
    prov = {"index": str(index), "materials_fitted": list(names), **dict(extra or {})}
    if problems:
        prov["problems"] = problems
    sensor = best.sensor(name=name or out.stem)
    sensor = sensor.replace(provenance={**sensor.provenance, **prov})
    sensor.to_yaml(out)
    return problems


#: The columns of ``calibrate fit --format csv|md``: one row per identified quantity.
PARAMETER_COLUMNS = ("parameter", "material", "value", "std_error", "low_95", "high_95", "unit")


def _run_identify(index: Path, model: Optional[str], fit_sets: Optional[str], ranges: list[str],
                  only: Optional[list[str]], object_temps: list[str], depth_um: float, out: Optional[Path],
                  quiet: bool, touch_conductance: Optional[str] = None, name: Optional[str] = None,
                  force: bool = False, rows_fmt: Optional[str] = None, plot: Optional[Path] = None,
                  offset_bounds_s: tuple[float, float] = (-1.5, 1.5), fit_to: Optional[float] = None,
                  record: Optional[dict] = None) -> Optional[dict]:
    """Identify one model, or choose among them all (``model`` None or 'all'), and write the sensor file.

    The touches are split by :func:`~designkit.calibration.split.choose_split` (``fit_sets``
    None: from the trial sets present; 'all': nothing held out) and the candidate with the smallest
    held-out residual wins (BIC where nothing is held out). Prints the report unless ``quiet``;
    returns the JSON payload (None after ``rows_fmt`` rows).
    """
    from .._validation import InputError
    from ..calibration.candidates import CANDIDATES, candidate
    from ..calibration.compare import compare_models
    from ..calibration.split import Split, choose_split

    auto = model is None or model.strip().lower() in ("all", "auto")
    cands = list(CANDIDATES) if auto else [candidate(model)]
    if depth_um is not None and not (depth_um > 0 and math.isfinite(depth_um)):
        raise InputError(f"--depth-um must be positive, got {depth_um:g}")
    trials = _load_trials(index, only, fit_to)
    names = sorted({tr.material for tr in trials})
    rng, temps, per_touch, cands = _identify_inputs(names, ranges, object_temps, touch_conductance, cands, model)
    _refuse_unusable(trials, force, out)
    if fit_sets is not None and fit_sets.strip().lower() == "all":
        split = Split(tuple(trials), (), (), (), "trial set", "--fit-sets all: every touch fitted")
    else:
        split = choose_split(trials, index, None if fit_sets is None else _parse_sets(fit_sets))
    fit, held = list(split.fit), list(split.held_out)
    kw = dict(ranges=rng, object_temps=temps, depth_m=depth_um * 1e-6, touch_conductance=tuple(per_touch),
              offset_bounds_s=offset_bounds_s)
    with _app.busy(f"identifying {len(cands)} model(s) on {len(fit)} touches", quiet=quiet or rows_fmt is not None):
        cmp = compare_models(fit, held, cands, **kw)   # no held-out touches: selected by BIC
    results, scores, selected = cmp.results, cmp.held_out_rms_c, cmp.selected
    best = next(r for r in results if r.candidate.label == selected)
    best_score = scores[results.index(best)]
    if plot is not None:  # before the sensor file: a refused fit is worth seeing too
        from ..calibration.compare import plot_identification

        plot_identification(results, selected, fit, held, plot, held_out_rms_c=scores, object_temps=temps)
    selection = {"selected": selected, "reason": cmp.reason, "split": split.to_dict(),
                 "held_out_rms_c": dict(best_score)}
    if out is not None:
        _write_identified(best, trials, out, name, index, force, names, extra={"selection": selection})
    if rows_fmt is not None:  # the selected model's parameters (the comparison stays in the report and --json)
        from ._format import emit_rows

        emit_rows(_parameter_rows(best), PARAMETER_COLUMNS, fmt=rows_fmt, notes=[f"model {selected}, {split.describe()}"])
        return None
    payload = {"index": str(index), "n_fit": len(fit), "n_held_out": len(held), "selected": selected,
               "reason": cmp.reason, "split": split.to_dict(),
               "out": str(out) if out is not None else None, "plot": str(plot) if plot is not None else None,
               "results": [dict(r.to_dict(), held_out_rms_c=dict(sc)) for r, sc in zip(results, scores)]}
    if not quiet:
        _print_identification(cmp, best, split, names, out, plot, len(fit), record)
    return payload


def _load_trials(index: Path, only: Optional[list[str]], fit_to: Optional[float]) -> list:
    """The index's touches (``only`` these materials), cut at ``fit_to``; refused if any is too short to fit."""
    from .._validation import InputError
    from ..calibration.trials import load_index

    trials = load_index(index, only=only)
    if not trials:
        raise InputError(f"index {index} lists no trials")
    trials = _cut(trials, fit_to)
    short = [tr for tr in trials if tr.time_s[-1] < MIN_CONTACT_S]
    if short:
        raise InputError(f"{len(short)} touch(es) end before {MIN_CONTACT_S:g} s after the onset (e.g. "
                         f"{Path(short[0].source).name}, {max(short[0].time_s[-1], 0.0):.3g} s): the sensor models "
                         f"need at least {MIN_CONTACT_S:g} s of contact" + (" (raise --fit-to)" if fit_to else
                                                                           "; record longer touches"))
    return trials


def _identify_inputs(names: list[str], ranges: list[str], object_temps: list[str], touch_conductance: Optional[str],
                     cands: list, model: Optional[str]) -> tuple:
    """The options of an identification, checked against the materials fitted: (ranges, object temperatures,
    materials with a conductance per touch, the candidate models that can fit them)."""
    from .._validation import InputError
    from ..calibration.fit import parse_object_temps, parse_ranges, resolve_ranges

    rng = resolve_ranges(names, parse_ranges(ranges))
    affine = [spec for spec in object_temps if spec.strip().lower().endswith("-affine")]
    temps = parse_object_temps([spec for spec in object_temps if spec not in affine])
    for spec in affine:  # the passive reading through a fitted offset and slope (identification only)
        mat, _, mode = spec.partition("=")
        if mode.strip().lower() not in ("passive-affine", "passive-end-affine"):
            raise InputError(f"--object-temp {spec!r}: the fitted-channel modes are passive-affine and "
                             "passive-end-affine")
        temps[mat.strip()] = mode.strip().lower()
    unknown = sorted(set(temps) - set(names))
    if unknown:
        raise InputError(f"--object-temp names material(s) not being fitted: {', '.join(unknown)}")
    per_touch = [n.strip() for n in (touch_conductance or "").split(",") if n.strip()]
    unknown = sorted(set(per_touch) - set(names))
    if unknown:
        raise InputError(f"--touch-conductance names material(s) not being fitted: {', '.join(unknown)} "
                         f"(fitted: {', '.join(names)})")
    if per_touch:
        cands = [c for c in cands if "conductance_w_m2k" in c.free]
        if not cands:
            raise InputError(f"--touch-conductance needs a model that fits the contact conductance "
                             f"(contact, layered...), not {model}")
    return rng, temps, per_touch, cands


def _refuse_unusable(trials: list, force: bool, out: Optional[Path]) -> None:
    """Refuse, before minutes of fitting, touches that cannot calibrate (unless ``force``), each problem said."""
    from ._app import escape

    from .._validation import InputError
    from ..calibration.fit import check_calibration

    before = [p for p in check_calibration(None, trials) if p.fatal]
    if before and not force:
        con = console(stderr=True)
        for p in before:
            con.print(f"[bold red]error:[/] {escape(p.text())}")
        raise InputError(f"calibration unusable ({', '.join(sorted({p.kind for p in before}))}): "
                         + (f"{out} not written; " if out is not None else "")
                         + "see the messages above; --force fits and writes the sensor file anyway")


def _parameter_rows(best) -> list[dict]:
    """The selected model's parameters as rows (:data:`PARAMETER_COLUMNS`): e_s first where it is known."""
    es = best.effusivity
    head = [] if es is None or not best.consistent else [
        {"parameter": "e_s", "material": None, "value": es.value, "std_error": None, "low_95": es.ci95[0],
         "high_95": es.ci95[1], "unit": "J s^-1/2 K^-1 m^-2"}]
    return head + [{"parameter": q.name, "material": None, "value": q.value, "std_error": None,
                    "low_95": q.ci95[0], "high_95": q.ci95[1], "unit": q.unit} for q in best.parameters]


def _print_identification(cmp, best, split, names: list[str], out: Optional[Path], plot: Optional[Path],
                          n_fit: int, record: Optional[dict]) -> None:
    """The identification's report for people: the models compared, the one selected and its parameters."""
    from ._app import escape
    from rich.table import Table

    results, scores, selected = cmp.results, cmp.held_out_rms_c, cmp.selected
    con = console()
    if record is not None:
        con.print(f"Recorded {record['n_trials']} trial(s) in {record['out']}")
    t = Table(title=f"Sensor models: {split.describe()}", title_justify="left")
    for c in ("model", "fit RMS", *(f"held-out {n}" for n in names), "AIC", "BIC", "rank", "e_s [95 %]",
              "fit time"):
        t.add_column(escape(c), justify="left" if c == "model" else "right")
    for r, sc in zip(results, scores):
        es = "–" if r.effusivity is None else (f"{r.effusivity.value:.4g} [{r.effusivity.ci95[0]:.4g}, "
                                               f"{r.effusivity.ci95[1]:.4g}]" if r.consistent else "conflict")
        t.add_row(escape(r.candidate.label + (" *" if r.candidate.label == selected else "")), f"{r.rms_c:.4f} °C",
                  *(f"{sc[n]:.4f} °C" if n in sc else "–" for n in names), f"{r.aic:.0f}", f"{r.bic:.0f}",
                  f"{r.rank}/{r.n_nonlinear}", escape(es), f"{r.fit_time_s:.1f} s")
    con.print(t)
    con.print(f"selected {escape(cmp.reason)}")
    con.print(f"[dim]split: {escape(split.reason)}[/]")
    p = Table(title=f"Selected: {selected} ({best.model().describe()})", title_justify="left")
    for c in ("parameter", "value", "95 % interval", "unit", "identified"):
        p.add_column(c, justify="left" if c in ("parameter", "unit", "identified") else "right")
    for q in best.parameters:
        p.add_row(escape(q.name), f"{q.value:.4g}", f"[{q.ci95[0]:.4g}, {q.ci95[1]:.4g}]", escape(q.unit),
                  "yes" if q.identifiable else f"no: {escape(q.note or 'see notes')}")
    con.print(p)
    con.print(f"noise sigma before contact {best.noise_c:.4g} °C; object temperature: "
              + ", ".join(f"{n} {m}" for n, m in best.object_modes.items()))
    for n, (lo, hi) in best.es_allowed.items():
        con.print(f"[dim]{escape(n)} allows e_s in [{lo:.4g}, {hi:.4g}][/]")
    for note in best.notes:
        con.print(f"[yellow]note:[/] {escape(note)}")
    if out is not None:
        con.print(f"wrote {out} with the {selected} model, as fitted on the {n_fit} fitted touches  "
                  f"(use it with --sensor {out})")
    if plot is not None:
        con.print(f"wrote {plot}")


# ------------------------------------------------------------------ record
@calibrate_app.command()
def record(
    port: PortOpt = None,
    profile: ProfileOpt = "designkit",
    material: Annotated[Optional[str], typer.Option("--material", help="Label of the material being touched.")] = None,
    trials: TrialsOpt = DEFAULT_TRIALS,
    out: Annotated[Optional[Path], typer.Option("--out", help="Folder for the trials (CSV + JSON each, index.csv).")] = None,
    timeout: TimeoutOpt = None,
    json_: Json = False,
) -> None:
    """Record touches from a serial device: detect each contact, write each trial at once.

    Example: `designkit calibrate record --port /dev/ttyACM0 --profile designkit --material wood --out trials/`
    """
    from .._validation import InputError
    from ..calibration.profiles import load_profile

    if port is None or material is None or out is None:
        raise InputError("give --port, --material and --out")
    from ..calibration.trials import check_material_label

    check_material_label(material, "--material")  # before recording: a label that cannot name a trial lost it
    _check_trials(trials)
    _check_timeout(timeout)
    prof = load_profile(profile)
    rec, paths, interrupted = _record_materials(port, prof, out, [material], trials, timeout, quiet=json_,
                                                prompt=False)
    payload = _record_payload(rec, paths, out, interrupted)
    if json_:
        emit_json(payload)
    else:
        con = console(stderr=interrupted)
        con.print(f"{'Interrupted: ' if interrupted else ''}{len(paths)} trial(s) of {material} written to {out}"
                  + (f" (index {out / 'index.csv'})" if paths else ""))
    if interrupted:
        raise typer.Exit(EXIT_INTERRUPTED)


# --------------------------------------------------------------------- fit
ModelOpt = Annotated[Optional[str], typer.Option(
    "--model", help="Sensor model: by default every candidate is fitted and the one with the smallest residual "
                    "on held-out touches is chosen (BIC when none can be held out), and the report says which and "
                    "why; or one of semi-infinite (the paper's), contact, contact+smoothing, layered, layered+lag, "
                    "layered+lag+smoothing, layered+lag+smoothing+drift, contact+smoothing+drift+area, "
                    "layered+lag+smoothing+drift+area (+drift: a heater still warming at contact; +area: a contact "
                    "area growing with the measured force); 'all' is the default.")]


@calibrate_app.command()
def fit(
    index: Annotated[Path, typer.Argument(help="CSV with columns file and material (e.g. the index.csv that "
                                               "'calibrate record' writes, or the shared recordings').")],
    range_: RangeOpt = None,
    only: Annotated[Optional[list[str]], typer.Option(
        "--only", help="Fit only these materials (repeatable, or comma-separated).")] = None,
    object_temp: ObjectTempOpt = None,
    depth_um: DepthOpt = 80.0,
    out: Annotated[Optional[Path], typer.Option("--out", help="Write the sensor YAML here (for --sensor).")] = None,
    name: Annotated[Optional[str], typer.Option("--name", help="Sensor name in the file (default: file stem).")] = None,
    offset_range: Annotated[str, typer.Option(
        "--offset-range", help="Search range of the contact-time offset MIN:MAX [s].")] = "-1.5:1.5",
    fit_to: Annotated[Optional[float], typer.Option(
        "--fit-to", help="Use samples up to this time after onset [s] (default: all).")] = None,
    plot: Annotated[Optional[Path], typer.Option("--plot", help="Write a PNG of the fit (needs matplotlib).")] = None,
    model: ModelOpt = None,
    fit_sets: Annotated[Optional[str], typer.Option(
        "--fit-sets", help="Trial sets to fit (FIRST-LAST or a comma list); every other set present is held "
                           "out and scored ('all': fit every touch, select by BIC). Default: the first fifth "
                           "of the sets present (at least one); an index without trial sets: the first half "
                           "of each material's touches.")] = None,
    force: Annotated[bool, typer.Option(
        "--force", help="Write the sensor file even when the calibration is unusable (conflicting ranges, "
                        "mislabelled touches, a sensor colder than the object).")] = False,
    touch_conductance: Annotated[Optional[str], typer.Option(
        "--touch-conductance", help="Give each touch of these materials (comma-separated) its own contact "
                                    "conductance, e.g. metal (contact area differs between touches); only "
                                    "models that fit h_c.")] = None,
    format_: Annotated[Optional[str], typer.Option(
        "--format", "-f", help="text (the report, default), json (as --json), or table / csv / ndjson / md: the "
                               "identified sensor's parameters as rows (parameter, material, value, std_error, "
                               "low_95, high_95, unit), pandas-ready.", rich_help_panel=PANEL_OUTPUT)] = None,
    json_: Json = False,
) -> None:
    """Identify your sensor's model from recorded touches: e_s, alpha_s, each e_o, the contact offset.

    Example: `designkit calibrate fit trials/index.csv --range wood=331:506 --out my-sensor.yaml`

    Example (the paper's model only, parameters as CSV): `designkit calibrate fit trials/index.csv --model semi-infinite --format csv`
    """
    from ._format import check_out, output_format

    fmt = output_format(format_, json_)
    if out is not None:
        if str(out) == "-":  # it wrote a file named '-' and advised '--sensor -'
            from .._validation import InputError

            raise InputError("--out - : give the sensor file a name (it is read back with --sensor FILE)")
        check_out(out, "--out", probe=True)  # before the fit: its minutes were lost to an unwritable path
    bounds = _offset_bounds(offset_range)
    only_list = [s.strip() for item in only for s in item.split(",") if s.strip()] if only else None
    payload = _run_identify(index, model, fit_sets, range_ or [], only_list, object_temp or [], depth_um, out,
                            fmt != "text", touch_conductance, name=name, force=force,
                            rows_fmt=None if fmt in ("text", "json") else fmt, plot=plot, offset_bounds_s=bounds,
                            fit_to=fit_to)
    if fmt == "json":
        emit_json(payload)


# ------------------------------------------------------------ guided run
@calibrate_app.callback(invoke_without_command=True)
def guided(
    ctx: typer.Context,
    port: PortOpt = None,
    profile: ProfileOpt = "designkit",
    material: Annotated[Optional[list[str]], typer.Option(
        "--material", help="A material to touch (repeatable; recorded in this order).")] = None,
    trials: TrialsOpt = DEFAULT_TRIALS,
    out: Annotated[Optional[Path], typer.Option("--out", help="Folder for the trials.")] = None,
    sensor_out: Annotated[Optional[Path], typer.Option(
        "--sensor-out", help="Sensor YAML to write (default: OUT/sensor.yaml).")] = None,
    range_: RangeOpt = None,
    object_temp: ObjectTempOpt = None,
    depth_um: DepthOpt = 80.0,
    timeout: TimeoutOpt = None,
    yes: Annotated[bool, typer.Option("--yes", "-y", help="Do not wait for Enter before each material.")] = False,
    force: Annotated[bool, typer.Option(
        "--force", help="Write the sensor file even when the calibration is unusable.")] = False,
    model: ModelOpt = None,
    json_: Json = False,
) -> None:
    """Guided calibration: record every material over serial, then fit and write the sensor file.

    Its ``--help`` text is :data:`_CALIBRATE_HELP` (the group's).
    """
    from .._validation import InputError

    if ctx.invoked_subcommand is not None:
        if port is not None or material:
            raise InputError(f"options like --port go after '{ctx.invoked_subcommand}', not before it")
        return
    if port is None or not material or out is None:
        raise InputError("the guided run needs --port, at least one --material and --out "
                         "(or use 'calibrate record' and 'calibrate fit')")
    from ..calibration.trials import check_material_label

    for m in material:  # before anything is recorded: a label that cannot name a trial lost 8 s of touch
        check_material_label(m, "--material")
    _check_trials(trials)
    _check_timeout(timeout)
    if not (depth_um > 0 and math.isfinite(depth_um)):
        raise InputError(f"--depth-um must be positive, got {depth_um:g}")
    from ..calibration.fit import parse_object_temps, parse_ranges, resolve_ranges
    from ..calibration.profiles import load_profile

    prof = load_profile(profile)
    materials = list(dict.fromkeys(material))
    # everything the fit will need is checked before the first touch (a session's work was lost to a typo)
    resolve_ranges(materials, parse_ranges(range_ or []))
    unknown = [n for n in parse_object_temps(object_temp or []) if n not in materials]
    if unknown:
        raise InputError(f"--object-temp names {', '.join(map(repr, unknown))}, not a material of this run "
                         f"({', '.join(materials)})")
    if model is not None and model.strip().lower() not in ("all", "auto"):
        from ..calibration.candidates import candidate

        candidate(model)
    if sensor_out is not None:
        from ._format import check_out

        check_out(sensor_out, "--sensor-out", probe=True)
    rec, paths, interrupted = _record_materials(port, prof, out, materials, trials, timeout, quiet=json_,
                                                prompt=not yes)
    if interrupted:
        if json_:
            emit_json(_record_payload(rec, paths, out, True))
        console(stderr=True).print(f"Interrupted: {len(paths)} trial(s) kept in {out}; fit them later with "
                                   f"'designkit calibrate fit {out / 'index.csv'}'")
        raise typer.Exit(EXIT_INTERRUPTED)
    sensor_path = sensor_out or out / "sensor.yaml"
    record = _record_payload(rec, paths, out, False)
    payload = _run_identify(out / "index.csv", model, None, range_ or [], materials, object_temp or [], depth_um,
                            sensor_path, json_, name=None, force=force, record=record)
    if json_:
        emit_json({"record": record, "fit": payload, "sensor": str(sensor_path)})
