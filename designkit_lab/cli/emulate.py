"""``designkit emulate``: a sensor rig on a pseudo-terminal, for calibrating and classifying without hardware."""

from __future__ import annotations

import math
import sys
import time
from typing import Annotated, Optional

import typer

from designkit.cli import _app
from designkit.cli._app import app, console, emit_json
from designkit.cli._options import Json, Noise, Seed, SensorOpt, sensor_and_model
from designkit.cli.calibrate import DEFAULT_TRIALS, ProfileOpt, guided_command


def _hint_ranges(mats) -> list[str]:
    """--range options the guided run needs for emulated materials the materials database does not know.

    The emulator knows their effusivity exactly; the hint gives it +-10 %, as an effusivity meter would.
    """
    from designkit._validation import InputError
    from designkit.materials import get_material

    out = []
    for m in mats:
        try:
            get_material(m.label)
        except InputError:
            out.append(f"{m.label}={0.9 * m.effusivity:.4g}:{1.1 * m.effusivity:.4g}")
    return out


@app.command(rich_help_panel=_app.SENSOR)
def emulate(
    profile: ProfileOpt = "designkit",
    material: Annotated[Optional[list[str]], typer.Option(
        "--material", help="Object to touch: a materials database name, or LABEL=E with E the effusivity "
                           "[J s^-1/2 K^-1 m^-2] (repeatable: touched in turn).")] = None,
    e: Annotated[Optional[float], typer.Option("--e", help="Effusivity of the object [J s^-1/2 K^-1 m^-2].")] = None,
    touch_every: Annotated[float, typer.Option("--touch-every", help="Seconds (device time) between touches.")] = 20.0,
    touches_per_material: Annotated[int, typer.Option(
        "--touches-per-material", help="Touches of each material before the next one (as the guided "
                                       "'calibrate --trials' records them).")] = DEFAULT_TRIALS,
    noise: Noise = 0.05,
    sensor: SensorOpt = "paper",
    sensor_temp: Annotated[float, typer.Option("--sensor-temp", help="Heater set point [°C].")] = 35.0,
    ambient: Annotated[float, typer.Option("--ambient", help="Room temperature [°C].")] = 25.0,
    object_temp: Annotated[Optional[float], typer.Option(
        "--object-temp", help="Object temperature [°C] (default: room temperature).")] = None,
    speed: Annotated[float, typer.Option("--speed", help="Device seconds per real second (20: 20x real time).")] = 1.0,
    fault: Annotated[Optional[list[str]], typer.Option(
        "--fault", help="Inject a fault (repeatable): garbled=P, partial=P, non-numeric=P, field-count=P, "
                        "out-of-range=P, out-of-order=P, duplicate=P, corrupt=P (per-line probabilities, from device time "
                        "line-faults-after=S on), "
                        "burst=EVERY_S[:HOLD_S], gap=EVERY_S[:SILENT_S], vanish=AFTER_S, silent.")] = None,
    duration: Annotated[Optional[float], typer.Option(
        "--duration", help="Stop after this many real seconds (default: run until Ctrl-C).")] = None,
    seed: Seed = 0,
    json_: Json = False,
) -> None:
    """Emulate a sensor rig on a pseudo-terminal: prints its path, streams the profile's wire format.

    Example (a rig playing two objects for 5 s; without --duration until Ctrl-C): `designkit emulate --material wood=400 --material aluminium=20000 --speed 20 --duration 5`
    """
    from designkit._validation import InputError, check_temperature
    from designkit.calibration.profiles import load_profile

    from .. import emulator as lab

    sensor_temp = check_temperature("--sensor-temp [degC]", sensor_temp)
    ambient = check_temperature("--ambient [degC]", ambient)
    check_temperature("--noise [degC]", noise, nonnegative=True)  # 1e308 was taken
    _check_emulation(touch_every, duration, speed, touches_per_material)
    mats = _emulated_materials(material, e, object_temp)
    prof = load_profile(profile)
    sen, fm, _ = sensor_and_model(sensor)   # a sensor file's recorded model is what the rig plays
    emu = lab.Emulator(prof, sen, mats, noise_c=noise, sensor_temp_c=sensor_temp, ambient_c=ambient,
                       plan=lab.TouchPlan(touch_every_s=touch_every, touches_per_material=touches_per_material),
                       speed=speed, faults=lab.Faults.parse(fault or []), seed=seed, model=fm)
    port = emu.start()
    try_cmd = guided_command(port, profile, [m.label for m in mats], touches_per_material,
                              _hint_ranges(mats))
    # classify's default --time-offset is 0 (a calibrated sensor file carries its own); this emulator's onset
    # detection lags by expected_time_offset_s, and without it every touch was decided as the same material
    import shlex

    classify_cmd = None if len(mats) < 2 else (
        f"designkit classify --port {port}" + ("" if profile is None else f" --profile {shlex.quote(profile)}")
        + "".join(f" --m {shlex.quote(f'{m.label}={m.effusivity:g}')}" for m in mats)
        + f" --time-offset {emu.expected_time_offset_s:g}")
    info = {"port": port, "profile": prof.name, "speed": speed, "touch_every_s": touch_every,
            "touches_per_material": touches_per_material, "try": try_cmd, "try_classify": classify_cmd,
            "materials": [{"label": m.label, "effusivity": m.effusivity} for m in mats],
            "noise_c": noise, "sensor": emu.sensor.to_dict(), "model": fm.to_dict(),
            "time_offset_s": emu.expected_time_offset_s,
            "faults": [str(f) for f in fault or []]}
    if json_:
        emit_json(info)
    else:
        _print_emulation(emu, prof, fm, mats, info)
    start = time.monotonic()
    announced = -1
    try:
        while duration is None or time.monotonic() - start < duration:
            if emu.wait(0.2):
                break
            if not json_:
                device_t = emu.samples_sent / prof.sample_rate_hz
                j = int(math.floor((device_t - emu.plan.first_touch_s) / emu.plan.touch_every_s))
                if j > announced and j >= 0:
                    tr = emu.touch(j)
                    console().print(f"[dim]touch {j + 1}: {tr.material} at device time {tr.start_s:g} s[/]")
                    announced = j
    except KeyboardInterrupt:
        pass
    finally:
        emu.stop()
    if emu.error is not None:
        raise InputError(f"the emulator failed: {emu.error}")
    if emu.vanished and not json_:
        console().print("the emulated device vanished (fault injected)")


def _check_emulation(touch_every: float, duration: Optional[float], speed: float, touches_per_material: int) -> None:
    """emulate's timing options, each refused in one line before the rig starts."""
    from designkit._validation import InputError
    from designkit.calibration.profiles import MAX_PROFILE_SECONDS

    if not 0 < touch_every <= MAX_PROFILE_SECONDS:
        raise InputError(f"--touch-every must be a positive number of seconds up to {MAX_PROFILE_SECONDS:g} (a day), "
                         f"got {touch_every:g}")
    if duration is not None and not 0 < duration <= MAX_PROFILE_SECONDS:  # inf, 1e308: never stopped
        raise InputError(f"--duration must be a positive number of seconds up to {MAX_PROFILE_SECONDS:g} (a day; "
                         f"leave it out to run until Ctrl-C), got {duration:g}")
    if not 0 < speed <= 1e4:
        raise InputError(f"--speed must be a positive factor up to 10000, got {speed:g}")
    if not 1 <= touches_per_material <= 1_000_000:
        raise InputError(f"--touches-per-material must be 1 to 1000000, got {touches_per_material}")


def _emulated_materials(material: Optional[list[str]], e: Optional[float], object_temp: Optional[float]) -> list:
    """The objects the emulated rig touches: ``--material`` NAME or LABEL=E (in turn), then ``--e``."""
    from designkit._validation import InputError

    from ..emulator import EmulatedMaterial

    mats = []
    for spec in material or []:
        label, sep, value = spec.rpartition("=")   # the effusivity follows the last "="
        if sep:
            from designkit._validation import check_label

            check_label(f"--material {spec!r}: the label", label)  # '=400' and a newline were taken
            try:
                e_label = float(value)
            except ValueError:
                raise InputError(f"--material {spec!r}: use NAME or LABEL=EFFUSIVITY") from None
            mats.append(EmulatedMaterial(label.strip(" "), e_label, object_temp))  # a newline is refused, not cut
        else:
            from designkit.materials import get_material

            m = get_material(spec)
            eo = m.identified if m.identified is not None else math.sqrt(m.e_min * m.e_max)
            mats.append(EmulatedMaterial(m.name, eo, object_temp))
    if e is not None:
        mats.append(EmulatedMaterial("object", e, object_temp))
    if not mats:
        raise InputError("give --material NAME (or LABEL=E) or --e E: what should the rig touch?")
    return mats


def _print_emulation(emu, prof, fm, mats: list, info: dict) -> None:
    """emulate's banner for people: the port, what the rig touches, and the commands to try on it."""
    from designkit.cli._app import escape

    con = console()
    con.print(f"Emulating a '{prof.name}' rig on [bold]{info['port']}[/]  (speed {info['speed']:g}x; Ctrl-C to stop)")
    con.print("  touching " + ", ".join(f"{m.label} (e = {m.effusivity:g})" for m in mats)
              + f" every {info['touch_every_s']:g} s; noise {info['noise_c']:g} °C; sensor e_s = "
                f"{emu.sensor.effusivity:g}, tau = {emu.sensor.tau_s:.3f} s")
    if fm.name != "semi-infinite":
        played = fm.describe() if fm.name != "force-ramp" else (
            f"{fm.base.describe()} with the contact area following the emulator's force ramp "
            f"({emu.plan.ramp_s:g} s) at c = {emu.plan.contact_force_fraction:.3g}")
        con.print(escape(f"  model {played} (recorded in sensor file {emu.sensor.name}; the wire "
                         "carries the raw reading: any host smoothing is the host's)"))
    con.print(f"  touches {info['touches_per_material']} of each material in turn, from when a program opens the port")
    con.print(f"  try: {escape(info['try'])}", soft_wrap=True)
    if info["try_classify"] is not None:
        con.print(f"  or:  {escape(info['try_classify'])}", soft_wrap=True)
    sys.stdout.flush()
