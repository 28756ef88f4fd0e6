"""``designkit simulate`` and ``designkit f1``: the model and the recognizer, one scene at a time."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated, Optional

import typer

from ._app import app, console, emit_json
from ._format import FormatOpt, OutOpt, emit, flat_record, output_format
from . import _app
from ._options import (E1, E2, Ambient, BackingOpt, Conductance, Contact, DeltaT, Diffusivity, Folds, Json,
                       ModelOpt, Noise, Seed, SensorOpt, Thickness, Threshold, Trials, Width, model_words,
                       sensor_and_model)


@app.command(rich_help_panel=_app.MODEL)
def simulate(
    e: Annotated[float, typer.Option("--e", help="Object effusivity [J s^-1/2 K^-1 m^-2] (0 and inf allowed).")],
    contact: Contact = 4.0,
    noise: Noise = 0.05,
    sensor_temp: Annotated[float, typer.Option("--sensor-temp", help="Initial sensor temperature [°C].")] = 35.0,
    ambient: Ambient = 25.0,
    trials: Annotated[int, typer.Option("--trials", help="Number of touches.")] = 1,
    seed: Seed = 0,
    sensor: SensorOpt = "paper",
    plot: Annotated[Optional[Path], typer.Option("--plot", help="Write a PNG of the curves (needs designkit[figures]).")] = None,
    model: ModelOpt = None,
    conductance: Conductance = None,
    thickness: Thickness = None,
    backing: BackingOpt = None,
    diffusivity: Diffusivity = None,
    format_: FormatOpt = None,
    out: OutOpt = None,
    json_: Json = False,
) -> None:
    """Simulate touches of one object (paper eq. 4): sensor temperature against time, under any forward model.

    csv and ndjson: one row per sample time, time_s then one temperature_c_K column per touch K (the JSON's
    time_s and temperature_c); --out FILE without --format writes that CSV.

    Example: `designkit simulate --e 20000 --contact 2 --conductance 2000 --out curve.csv`

    Example (the curves as JSON records, one a line): `designkit simulate --e 20000 --contact 0.1 --trials 2 --format ndjson`
    """
    import numpy as np

    from ..models.semi_infinite import contact_temperature
    from ..scene import Scene
    from .._validation import check_temperature

    if trials < 1:
        raise ValueError(f"trials must be >= 1, got {trials}")
    # --out alone writes the curves' CSV, as it always has (the other formats when asked)
    fmt = output_format(format_, json_, default="text" if out is None else "csv", out=out)
    check_temperature("--sensor-temp [°C]", sensor_temp)
    check_temperature("--ambient [°C]", ambient)
    check_temperature("--noise [°C]", noise, nonnegative=True)
    from ._format import check_out

    if plot is not None:
        check_out(plot, "--plot")
    sen, fm, source = sensor_and_model(sensor, model, conductance=conductance, thickness=thickness,
                                       backing=backing)
    scene = Scene(contact_s=contact, noise_c=noise, sensor_temp_c=sensor_temp, ambient_temp_c=ambient)
    _check_touch_memory("simulate", trials, sen, contact, copies=6)
    result = _touches(e, sen, scene, trials, seed, fm, diffusivity)
    # the paper's contact temperature (eq. 1): where the surface jumps at once under a shared-shape
    # model; other models reach it later (a contact's lag) or never (a slab on its backing)
    tc = float(contact_temperature(sensor_temp, ambient, sen.effusivity, e)) if fm.shared_shape else None
    if plot is not None:
        from ..figures import plot_curves

        plot_curves(plot, result.time_s, result.temperature_c,
                    title=f"e = {e:g} J s^-1/2 K^-1 m^-2, sigma = {noise:g} °C, {sen.name} sensor")
    payload = {"time_s": result.time_s, "temperature_c": result.temperature_c, "effusivity": e,
               "contact_temperature_c": tc, "scene": scene.to_dict(), "sensor": sen.to_dict(), "model": fm.to_dict(),
               "model_source": source, "diffusivity_m2_s": diffusivity, "seed": seed,
               "out": None if out in (None, "-") else str(out), "plot": str(plot) if plot else None}
    cols = ["time_s"] + [f"temperature_c_{k + 1}" for k in range(trials)]  # one row per sample time
    emit(fmt, out, payload=payload, text=lambda: _print_simulation(payload, result, sen, fm),
         records=lambda: [dict(zip(cols, row)) for row in np.column_stack([result.time_s, result.temperature_c.T]).tolist()])


def _print_simulation(p: dict, result, sen, fm) -> None:
    """simulate's text for people, from its JSON document ``p``."""
    from ._app import escape

    con, sc, final = console(), p["scene"], result.temperature_c[:, -1]
    con.print(f"[bold]{final.size} touch(es)[/] of e = {p['effusivity']:g} J s^-1/2 K^-1 m^-2 for {sc['contact_s']:g} s "
              f"({result.time_s.size} samples at {sen.sample_rate_hz:g} Hz, {sen.name} sensor, tau = {sen.tau_s:.3f} s)")
    con.print(escape("  " + model_words(sen, fm, p["model_source"]) + (
        f", object diffusivity {p['diffusivity_m2_s']:g} m^2/s" if p["diffusivity_m2_s"] is not None else "")))
    con.print(f"  sensor {sc['sensor_temp_c']:g} °C, object {sc['ambient_temp_c']:g} °C" + (
        f", contact surface Tc = {p['contact_temperature_c']:.4f} °C" if p["contact_temperature_c"] is not None else ""))
    con.print(f"  reading at {result.time_s[-1]:g} s: {final.mean():.4f} °C"
              + (f" (trials {final.min():.4f} to {final.max():.4f})" if final.size > 1 else ""))
    if p["plot"] is not None:
        con.print(f"  wrote {p['plot']}")


def _check_touch_memory(what: str, touches: int, sensor, contact_s: float, *, copies: int) -> None:
    """Refuse, before any allocation, ``touches`` curves of ``contact_s`` that cannot fit in memory.

    The samples per touch are bounded by the sensor (:data:`designkit.sensor.MAX_SAMPLES_PER_TOUCH`);
    ``copies`` counts the float64 arrays of that size the computation holds at once.
    """
    from ..simulation import check_touch_budget

    check_touch_budget(what, touches, sensor.times_s(contact_s).size, copies=copies)


def _touches(e: float, sensor, scene, trials: int, seed: int, model, diffusivity_m2_s: Optional[float]):
    """``trials`` touches of one object of effusivity ``e`` (0 and inf allowed) under ``model``.

    The draws of :func:`designkit.simulation.simulate_trials` (so the semi-infinite readings are
    its readings to the bit), rendered by the model, with the object's diffusivity where the
    model needs it.
    """
    import numpy as np

    from .._validation import InputError, check_effusivity, check_positive
    from ..simulation import TrialDraws, draw_trials, render_trials

    e = check_effusivity("e", e, allow_zero=True, allow_inf=True)
    alpha = None
    if "diffusivity_m2_s" in model.object_properties:
        if diffusivity_m2_s is None:
            raise InputError(f"the {model.name} model needs the object's --diffusivity [m^2/s]")
        alpha = np.full(trials, check_positive("diffusivity [m^2/s]", diffusivity_m2_s))
    elif diffusivity_m2_s is not None:
        raise InputError(f"--diffusivity is for models that need it (slab), not the {model.name} model")
    draws = draw_trials(0.0, 0.0, trials, sensor.times_s(scene.contact_s).size, seed)
    draws = TrialDraws(np.full(trials, e), draws.sensor_offset, draws.ambient_offset, draws.noise)
    return render_trials(draws, sensor, scene, model, alpha)


@app.command(rich_help_panel=_app.MODEL)
def f1(
    e1: E1 = None,
    e2: E2 = None,
    contact: Contact = 2.0,
    noise: Noise = 0.05,
    delta_t: DeltaT = 10.0,
    ambient: Ambient = 25.0,
    width: Width = 80.0,
    trials: Trials = 100,
    folds: Folds = 3,
    seed: Seed = 0,
    threshold: Threshold = 0.9,
    sensor: SensorOpt = "paper",
    model: ModelOpt = None,
    conductance: Conductance = None,
    thickness: Thickness = None,
    backing: BackingOpt = None,
    diffusivity: Diffusivity = None,
    two_sensor: Annotated[bool, typer.Option(
        "--two-sensor", help="Also read each touch with a passive thermistor resting at --ambient (room) "
                             "temperature beside the heated sensor, and say whether it resolves the pair.")] = False,
    object_temp1: Annotated[Optional[float], typer.Option(
        "--object-temp1", help="With --two-sensor: temperature of the first object [°C] (default: --ambient).")] = None,
    object_temp2: Annotated[Optional[float], typer.Option(
        "--object-temp2", help="With --two-sensor: temperature of the second object [°C] (default: --ambient).")]
    = None,
    format_: FormatOpt = None,
    out: OutOpt = None,
    json_: Json = False,
) -> None:
    """F1 of the paper's SVM and of the ideal observer for classes [e1, e1+width) and [e2, e2+width), under any
    forward model.

    Example: `designkit f1 --e1 35000 --e2 20000 --contact 2 --thickness 0.003 --diffusivity 1e-7`

    Example (a cold block of wood against room-temperature metal, one sensor and two): `designkit f1 --e1 17530 --e2 400 --width 10 --delta-t 7 --ambient 22.5 --object-temp2 8 --two-sensor`

    Example (one record, pandas-ready): `designkit f1 --e1 35000 --e2 20000 --trials 30 --format csv`
    """
    from .._validation import InputError
    from ..objects import object_class
    from ..recognition.ideal import ideal_pair
    from ..recognition.svm import pair_f1
    from ..scene import Scene

    fmt = output_format(format_, json_, out=out)
    e1, e2 = _check_f1(e1, e2, threshold, noise, delta_t, two_sensor, width, ambient, folds, trials)
    sen, fm, source = sensor_and_model(sensor, model, conductance=conductance, thickness=thickness,
                                       backing=backing)
    if diffusivity is not None and "diffusivity_m2_s" not in fm.object_properties:
        raise InputError(f"--diffusivity is for models that need it (slab), not the {fm.name} model")
    if diffusivity is None and "diffusivity_m2_s" in fm.object_properties:
        raise InputError(f"the {fm.name} model needs the objects' --diffusivity [m^2/s]")
    scene = Scene.from_delta_t(contact_s=contact, noise_c=noise, delta_t_c=delta_t, ambient_temp_c=ambient)
    _check_touch_memory("f1", 2 * trials, sen, contact, copies=16 if two_sensor else 8)  # raw, slope, folds
    obj1 = object_class(e1, width=width, diffusivity_m2_s=diffusivity)
    obj2 = object_class(e2, width=width, diffusivity_m2_s=diffusivity)
    if two_sensor or object_temp1 is not None or object_temp2 is not None:
        if not two_sensor:
            raise InputError("--object-temp1/--object-temp2 go with --two-sensor (one sensor's scene has one "
                             "object temperature: --ambient, with --delta-t)")
        if fmt not in ("text", "json") or out not in (None, "-"):
            raise InputError("--two-sensor prints text or --json on stdout")
        _f1_two_sensor(obj1, obj2, object_temp1, object_temp2, sen, fm, source, scene, trials, folds, seed,
                       threshold, fmt == "json")
        return
    t0 = time.perf_counter()
    with _app.busy("f1: simulating touches, fitting the SVM, the ideal observer", quiet=fmt != "text"):
        svm = pair_f1(obj1, obj2, sen, scene, model=fm, trials=trials, folds=folds, seed=seed)
        t1 = time.perf_counter()
        ideal = ideal_pair(obj1, obj2, sen, scene, seed=seed, model=fm)
    t2 = time.perf_counter()
    payload = {
        "svm_f1": svm.f1,
        "svm_standard_error": svm.standard_error,
        "fold_f1": list(svm.fold_f1),
        "svm_accuracy": svm.accuracy,
        "ideal_f1": ideal.f1,
        "ideal_accuracy": ideal.accuracy,
        "ideal_method": ideal.method,
        "threshold": threshold,
        "distinguishable": svm.f1 >= threshold,
        "ideal_distinguishable": ideal.f1 >= threshold,
        "objects": [obj1.to_dict(), obj2.to_dict()],  # as every answer's (docs/schema.md)
        "positive_class": "higher effusivity",
        "trials": trials,
        "folds": folds,
        "seed": seed,
        "scene": scene.to_dict(),
        "sensor": sen.to_dict(),
        "model": fm.to_dict(),
        "model_source": source,
        "diffusivity_m2_s": diffusivity,
        "svm_time_s": t1 - t0,
        "ideal_time_s": t2 - t1,
    }
    emit(fmt, out, payload=payload, text=lambda: _print_f1(payload, svm, ideal, sen, fm, source, width),
         records=lambda: [flat_record({**{k: v for k, v in payload.items() if k not in ("sensor", "model", "objects", "scene")},
                                       **payload["scene"],
                                       "effusivity_range_1": payload["objects"][0]["effusivity_range"],
                                       "effusivity_range_2": payload["objects"][1]["effusivity_range"],
                                       "sensor": sen.name, "model": fm.name})])


def _check_f1(e1, e2, threshold, noise, delta_t, two_sensor, width, ambient, folds, trials) -> tuple[float, float]:
    """f1's objects and scene, each refused in one line before any simulation; the two effusivities checked."""
    from .._validation import InputError, check_effusivity, check_positive, check_probability, check_temperature
    from ..sweep.config import MAX_EFFUSIVITY

    if e1 is None or e2 is None:
        raise InputError("give both --e1 and --e2")
    e1 = check_effusivity("e1", e1)
    e2 = check_effusivity("e2", e2)
    if e1 == e2:
        raise InputError(f"e1 and e2 are equal ({e1:g}): nothing to separate")
    check_probability("--threshold (F1)", threshold, low=2 / 3, high=1.0)  # a blind guess scores 2/3
    check_temperature("--noise [°C]", noise, nonnegative=True)
    check_temperature("--delta-t [°C]", delta_t)
    if delta_t == 0 and not two_sensor:  # sensor and objects at one temperature: no heat flows, nothing to tell
        raise InputError("--delta-t must be non-zero: a sensor at the objects' temperature reads no difference "
                         "(F1 is chance)")
    check_positive("--width", width)
    for label, value in (("--width", width), ("--e1", e1 + width), ("--e2", e2 + width)):
        if value > MAX_EFFUSIVITY:  # 1e308 overflowed the class edges
            raise InputError(f"{label}: classes must end below {MAX_EFFUSIVITY:g} J s^-1/2 K^-1 m^-2, got one "
                             f"ending at {value:g} (no material comes near: diamond is about 1e5)")
    check_temperature("--ambient [°C]", ambient)
    if folds < 2:
        raise InputError(f"folds must be >= 2, got {folds}")
    if trials < folds:
        raise InputError(f"trials per class ({trials}) must be at least the number of folds ({folds})")
    return e1, e2


def _print_f1(payload: dict, svm, ideal, sen, fm, source: str, width: float) -> None:
    """f1's answer for people: the pair and scene, the model, the SVM's F1 and verdict, the ideal bound."""
    from ._app import escape

    sc, threshold = payload["scene"], payload["threshold"]
    (o1, o2), diffusivity = payload["objects"], payload["diffusivity_m2_s"]
    con = console()
    con.print(f"[bold]{o1['effusivity_range'][0]:g}[/] vs [bold]{o2['effusivity_range'][0]:g}[/] J s^-1/2 K^-1 m^-2 "
              f"(classes {width:g} wide), contact {sc['contact_s']:g} s, noise {sc['noise_c']:g} °C, "
              f"dT {sc['delta_t_c']:g} °C, {sen.name} sensor")
    con.print(escape("  " + model_words(sen, fm, source)
                     + (f", object diffusivity {diffusivity:g} m^2/s" if diffusivity is not None else "")))
    verdict = "[green]distinguishable[/]" if svm.f1 >= threshold else "[red]not distinguishable[/]"
    folds_txt = ", ".join(f"{f:.3f}" for f in svm.fold_f1)
    con.print(f"  SVM F1    {svm.f1:.3f} ± {svm.standard_error:.3f}  (folds {folds_txt}; {payload['trials']} "
              f"trials/class)  -> {verdict} at F1 >= {threshold:g}")
    con.print(f"  ideal F1  {ideal.f1:.3f}, accuracy {ideal.accuracy:.3f}  ({ideal.method}; no classifier does better)")
    con.print(f"  [dim]{payload['svm_time_s'] * 1e3:.0f} ms SVM, {payload['ideal_time_s'] * 1e3:.0f} ms ideal[/]")


def _f1_two_sensor(obj1, obj2, temp1, temp2, sen, fm, source, scene, trials, folds, seed, threshold, json_) -> None:
    """``f1 --two-sensor``: the heated sensor alone, then with the passive thermistor at room temperature."""
    from .._validation import check_temperature
    from ..recognition.two_sensor import TouchClass, two_sensor_pair_f1

    temps = [None if t is None else check_temperature(f"--object-temp{i} [°C]", t)
             for i, t in ((1, temp1), (2, temp2))]
    a, b = (TouchClass(o, t, f"{o.label} at {scene.ambient_temp_c if t is None else t:g} °C")
            for o, t in zip((obj1, obj2), temps))
    t0 = time.perf_counter()
    r = two_sensor_pair_f1(a, b, sen, scene, model=fm, trials=trials, folds=folds, seed=seed, threshold=threshold)
    wall = time.perf_counter() - t0
    payload = dict(r.to_dict(), scene=scene.to_dict(), sensor=sen.to_dict(), model=fm.to_dict(),
                   model_source=source, passive_sensor={"initial_temp_c": scene.ambient_temp_c,
                                                      "like": "the heated sensor, unheated"},
                   trials=trials, folds=folds, seed=seed, wall_s=wall)
    if json_:
        emit_json(payload)
        return
    from ._app import escape

    con = console()
    con.print(f"[bold]{escape(a.label)}[/] vs [bold]{escape(b.label)}[/] (classes {obj1.e_range[1] - obj1.e_range[0]:g} "
              f"wide), contact {scene.contact_s:g} s, noise {scene.noise_c:g} °C, heated sensor at "
              f"{scene.sensor_temp_c:g} °C, room {scene.ambient_temp_c:g} °C, {escape(sen.name)} sensor")
    con.print(escape("  " + model_words(sen, fm, source)))

    def line(words, res):
        ok = "[green]distinguishable[/]" if res.f1 >= threshold else "[red]not distinguishable[/]"
        return f"  {words} F1 {res.f1:.3f} ± {res.standard_error:.3f}  -> {ok}"

    con.print(line("heated sensor alone:        ", r.one_sensor))
    con.print(line("with the passive thermistor:", r.two_sensors))
    if r.resolves:
        con.print("  [bold]the second sensor resolves this pair[/]: one heated sensor cannot tell them apart")
    elif r.one_sensor.f1 >= threshold:
        con.print("  [dim]one sensor already suffices[/]")
    else:
        con.print("  [yellow]not even two sensors separate them here[/]")
    con.print(f"  [dim]{trials} trials/class, {folds} folds, {wall:.1f} s[/]")
