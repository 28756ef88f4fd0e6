"""``designkit classify``: decide each touch live over serial (a sequential test on the streaming samples).

Exit status: 0 when every touch was answered, 2 for bad input (a stream whose
sample rate differs from the sensor file's, unknown materials, ...), 3 when no
contact time up to ``--max-contact`` can separate the materials at the requested
error rates (said before the first touch), 130 on Ctrl-C (decisions so far are
printed). A device that disappears or falls silent mid-session ends it with 2,
after the decisions made so far (under ``--json`` in the same document, with
``"interrupted": true`` and the ``"error"``).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from . import _app
from ._app import EXIT_INTERRUPTED, app, console
from ._format import FormatOpt, emit, flat_record, output_format
from ._options import Json, SensorOpt

#: Exit status when no decision is possible (as questions with no answer).
EXIT_NO_DECISION = 3

MOpt = Annotated[Optional[list[str]], typer.Option(
    "--m", help="A candidate material (repeatable, two or more): a materials database name, NAME=MIN:MAX or "
                "NAME=E [J s^-1/2 K^-1 m^-2].")]


def parse_candidates(specs: list[str]) -> list:
    """``--m`` values as SequentialTest candidates (database names, NAME=MIN:MAX, NAME=E)."""
    from .._validation import InputError

    out = []
    for spec in specs:
        name, sep, value = spec.partition("=")
        if not sep:
            out.append(spec.strip())
            continue
        lo, colon, hi = value.partition(":")
        try:
            rng = (float(lo), float(hi)) if colon else (float(lo), float(lo))
        except ValueError:
            raise InputError(f"--m {spec!r}: give NAME=MIN:MAX or NAME=E with effusivities in "
                             "J s^-1/2 K^-1 m^-2, or a database name") from None
        if not name.strip():
            raise InputError(f"--m {spec!r}: the material needs a name before '='")
        if not all(math.isfinite(x) and x > 0 for x in rng) or rng[1] < rng[0]:
            raise InputError(f"--m {spec!r}: effusivities must be positive and finite, MIN <= MAX")
        out.append((name.strip(), rng))
    return out


def _table(decisions, live, candidates) -> object:
    from rich.table import Table

    t = Table(title="live decisions", title_justify="left")
    for col in ("touch", "decision", "time to decision [s]", "samples", "Ts0 [°C]", "Ta [°C]"):
        t.add_column(col)
    for d in decisions[-12:]:
        t.add_row(str(d.index + 1), d.material if d.state == "decided" else d.state,
                  f"{d.time_to_decision_s:.3f}", str(d.n_samples), f"{d.sensor_temp_c:.2f}", f"{d.ambient_temp_c:.2f}")
    if live:
        ll = live.get("log_likelihoods") or ()
        lead = ", ".join(f"{c.name} {x - max(ll):.1f}" for c, x in zip(candidates, ll)) if ll else ""
        t.caption = f"now: t = {live['t']:.3f} s, {live['temp_c']:.3f} °C; log-likelihood vs best: {lead}"
    return t


def _decision_words(d, what: str, time_offset_s: float, rate_hz: float) -> str:
    """One touch's line: time and samples both counted from the detected contact onset (the heat flow starts
    ``time_offset_s`` after it), so that samples = time x rate; ``--json`` keeps the test's own figures."""
    after_onset_s = d.time_to_decision_s + time_offset_s
    samples = int(round(after_onset_s * rate_hz))
    return (f"touch {d.index + 1}: {what} after {after_onset_s:.3f} s of contact, {samples} samples at {rate_hz:g} Hz "
            f"(both from the detected onset; Ts0 {d.sensor_temp_c:.2f} °C, Ta {d.ambient_temp_c:.2f} °C)")


@app.command(rich_help_panel=_app.SENSOR)
def classify(
    port: Annotated[Optional[str], typer.Option(
        "--port", help="Serial port of the rig (/dev/ttyACM0, COM3, or the pty 'designkit emulate' prints).")] = None,
    profile: Annotated[str, typer.Option(
        "--profile", help="Device profile: a shipped name ('designkit', 'adc12-thermistor') or a YAML file.")] = "designkit",
    m: MOpt = None,
    sensor: SensorOpt = "paper",
    noise: Annotated[Optional[float], typer.Option(
        "--noise", help="White-noise sigma per sample [°C] (default: the sensor file's, else 0.05).")] = None,
    error_rate: Annotated[float, typer.Option(
        "--error-rate", help="Requested probability of a wrong decision on a touch of each material.")] = 0.01,
    max_contact: Annotated[float, typer.Option(
        "--max-contact", help="Longest contact [s]: no decision by then is said so.")] = 5.0,
    delta_t: Annotated[float, typer.Option(
        "--delta-t", help="Expected sensor minus object temperature [°C], for the check before the first touch "
                          "(each touch uses its own, measured before contact).")] = 10.0,
    object_temp: Annotated[Optional[float], typer.Option(
        "--object-temp", help="Object temperature [°C] (default: the profile's object thermistor before contact).")] = None,
    time_offset: Annotated[Optional[float], typer.Option(
        "--time-offset", help="Heat-flow start minus detected onset [s] (default: the time offset the sensor "
                              "file's calibration found, else 0; the emulator's is -0.25 s).")] = None,
    touches: Annotated[int, typer.Option("--touches", help="Touches to decide, then stop (1 to 1000).")] = 1,
    timeout: Annotated[Optional[float], typer.Option(
        "--timeout", help="Give up when the device sends nothing for this long [s] (default: the profile's).")] = None,
    export_c: Annotated[Optional[Path], typer.Option(
        "--export-c", help="Write the test as a C99 header (fixed memory, no allocation, one update call per "
                           "sample) to this file instead of reading a port.")] = None,
    prefix: Annotated[str, typer.Option("--prefix", help="Prefix of the C header's names (with --export-c).")] = "designkit_seq",
    format_: FormatOpt = None,
    json_: Json = False,
) -> None:
    """Decide each touch while it lasts: material, or keep touching, or no contact time will do.

    A sequential probability ratio test on the streaming samples (designkit.recognition.sequential), with
    the error rate you ask for; prints each touch's decision and its time to decision. Exit 3 when no
    contact up to --max-contact can separate the materials at that error rate.

    Example: `designkit classify --port /dev/ttyACM0 --sensor my-sensor.yaml --m wood --m "aluminium alloys"`

    Example (the emulator's rig, its onset 0.25 s late): `designkit classify --port /dev/pts/3 --m wood --m "aluminium alloys" --time-offset -0.25`

    Example: `designkit classify --m wood --m "aluminium alloys" --error-rate 0.001 --export-c robot_seq.h`
    """
    from ..calibration.profiles import load_profile
    from ..recognition.sequential import SequentialTest
    from ..sensor import load_sensor

    fmt = output_format(format_, json_)
    _check_options(port, export_c, m, touches, timeout, delta_t, time_offset, object_temp, noise, error_rate)
    sens = load_sensor(sensor)
    from .._validation import check_positive
    from ..sensor import check_samples_per_touch

    check_samples_per_touch(check_positive("--max-contact [s]", max_contact), sens.sample_rate_hz,
                            "--max-contact", "lower --max-contact")  # a 411 MB header, 3 GB of memory at 1e5 s
    sigma = noise if noise is not None else (sens.noise_c if sens.noise_c else 0.05)
    if time_offset is None:  # the calibrated sensor's own offset: its onset detection is what this run uses
        time_offset = float((sens.model or {}).get("time_offset_s") or 0.0)
    prof = load_profile(profile)
    cands = parse_candidates(m)

    def make_test(ts0: float, ta: float, noise_c: Optional[float] = None) -> SequentialTest:
        return SequentialTest(cands, sens, noise_c=sigma if noise_c is None else noise_c, sensor_temp_c=ts0,
                              ambient_temp_c=ta, error_rate=error_rate, max_contact_s=max_contact)

    check = make_test(35.0, 35.0 - delta_t)
    if export_c is not None:
        _export_c(check, export_c, prefix, fmt)
    payload = {"port": port, "profile": prof.name, "sensor": sens.name, "noise_c": sigma, "time_offset_s": time_offset,
               "error_rate": error_rate,
               "plan": check.plan.to_dict(), "decisions": [], "interrupted": False}
    if not check.plan.separable:
        emit(fmt, None, payload=payload, records=[],
             text=lambda: console().print(f"No decision possible: {check.plan.reason}.", highlight=False))
        raise typer.Exit(EXIT_NO_DECISION)
    clf, interrupted, failed = _run_live(port, prof, make_test, sens, time_offset, object_temp, timeout, touches,
                                         check, quiet=fmt == "json")
    decisions = clf.decider.written
    payload["decisions"] = [d.to_dict() for d in decisions]
    payload["interrupted"] = interrupted
    if failed is not None:
        payload["error"] = {"kind": "input", "message": str(failed), "exit_status": 2}

    def text() -> None:
        out = console(stderr=interrupted and failed is None)  # Ctrl-C: the decisions so far on stderr
        out.print(f"{check.plan.reason}.", highlight=False)
        for d in decisions:
            what = d.material if d.state == "decided" else d.state
            out.print(_decision_words(d, what, time_offset, sens.sample_rate_hz), highlight=False)

    emit(fmt, None, payload=payload, records=lambda: [flat_record(d) for d in payload["decisions"]], text=text)
    if failed is not None:
        typer.echo(f"Error: {failed}", err=True)
        raise typer.Exit(2)
    if interrupted:
        raise typer.Exit(EXIT_INTERRUPTED)


def _check_options(port, export_c, m, touches, timeout, delta_t, time_offset, object_temp, noise, error_rate) -> None:
    """classify's options, each refused in one line before the port is opened."""
    from .._validation import InputError, check_probability, check_temperature

    from ._format import check_out
    from ._options import refuse_together

    if port is None and export_c is None:
        raise InputError("give --port (the serial device of the rig), or --export-c FILE for a C header")
    refuse_together(("--port", port), ("--export-c", export_c),
                    why="--port runs the test on a rig, --export-c writes it as a C header")
    if export_c is not None:
        check_out(export_c, "--export-c")  # a missing folder is not made (as export's --out)
    if not m or len(m) < 2:
        raise InputError("give two or more candidate materials with --m")
    if not 1 <= touches <= 1000:
        raise InputError(f"--touches must be 1 to 1000, got {touches}")
    if timeout is not None and not (math.isfinite(timeout) and timeout > 0):
        raise InputError(f"--timeout must be a positive, finite number of seconds, got {timeout:g}")
    if not (math.isfinite(delta_t) and delta_t != 0):
        raise InputError(f"--delta-t must be a non-zero temperature difference [°C], got {delta_t:g}")
    if time_offset is not None and (not math.isfinite(time_offset) or abs(time_offset) > 5):
        raise InputError(f"--time-offset must be within ±5 s, got {time_offset:g}")
    if object_temp is not None:  # 1e9 degC was taken (and printed as Ta); NaN got another option's message
        check_temperature("--object-temp", object_temp)
    check_temperature("--delta-t [°C]", delta_t)  # 1e308 was taken
    if noise is not None:
        check_temperature("--noise [°C]", noise, nonnegative=True)
    check_probability("--error-rate", error_rate, low=0.0, high=0.5)


def _export_c(check, export_c: Path, prefix: str, fmt: str) -> None:
    """--export-c: the test as a C99 header; exits (3 when no contact time separates the materials)."""
    from .._io import atomic_write_bytes
    from ..export.sequential_c import write_sequential_c

    data = write_sequential_c(check, prefix)
    atomic_write_bytes(Path(export_c), data)
    info = {"out": str(export_c), "bytes": len(data), "plan": check.plan.to_dict()}
    emit(fmt, None, payload=info, records=lambda: [flat_record(info)],
         text=lambda: console().print(f"wrote {export_c} ({len(data):,} bytes): {check.plan.reason}",
                                      highlight=False))
    raise typer.Exit(0 if check.plan.separable else EXIT_NO_DECISION)


def _run_live(port, prof, make_test, sens, time_offset, object_temp, timeout, touches, check, *, quiet: bool):
    """Decide ``touches`` touches on the rig, with a live table on a terminal (unless ``quiet``).

    Returns (the classifier, interrupted, the error that ended the session or None): a device that went away
    or fell silent mid-session keeps the decisions made so far."""
    from .._validation import InputError
    from ..calibration.live import LiveClassifier

    con = console(stderr=True)
    live_view = None
    clf = None

    def refresh(_status=None) -> None:
        if live_view is not None and clf is not None:
            live_view.update(_table(clf.decider.written, clf.decider.live, check.candidates))

    def on_event(e) -> None:
        # the decisions are printed once, on stdout at the end (and live in the terminal's table); stderr
        # carries what is not in that summary
        if not quiet and live_view is None and e.kind in ("skipped", "gap", "bad_line", "noise"):
            con.print(e.message, highlight=False)
        refresh()

    clf = LiveClassifier(port, prof, make_test, sample_rate_hz=sens.sample_rate_hz, time_offset_s=time_offset,
                         ambient_temp_c=object_temp, no_data_timeout_s=timeout, on_event=on_event,
                         on_status=refresh)
    interrupted = False
    failed = None
    try:
        clf.open()  # a port that cannot be opened is refused as it is (nothing decided yet)
        if not quiet and con.is_terminal:
            from rich.live import Live

            live_view = Live(console=con, refresh_per_second=8)
            live_view.__enter__()
        try:
            clf.classify(touches)
        except InputError as exc:
            failed, interrupted = exc, True
    except KeyboardInterrupt:
        interrupted = True
    finally:
        if live_view is not None:
            live_view.__exit__(None, None, None)
        clf.close()
    return clf, interrupted, failed
