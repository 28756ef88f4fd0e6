"""``designkit validity``: how long a thin sample looks semi-infinite to the sensor."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from ._app import app, console
from ._format import FormatOpt, OutOpt, check_out, emit, flat_record, output_format
from . import _app
from ._options import PANEL_OUTPUT, PANEL_QUESTION, BackingOpt, DeltaT, Json, SensorOpt

#: Contact times [s] at which the deviation is reported (the paper's 1-4 s, and longer).
REPORT_TIMES_S = (1.0, 2.0, 3.0, 4.0, 10.0, 30.0, 60.0)


@app.command(rich_help_panel=_app.ASK)
def validity(
    thickness: Annotated[float, typer.Option("--thickness", help="Object thickness \\[m] (e.g. 0.003 for 3 mm).", rich_help_panel=PANEL_QUESTION)],
    material: Annotated[Optional[str], typer.Option(
        "--m", "--material", help="Object material (see 'designkit materials list'); its ranges give a worst "
                                  "case.", rich_help_panel=PANEL_QUESTION)] = None,
    e: Annotated[Optional[float], typer.Option(
        "--e", help="Object effusivity [J s^-1/2 K^-1 m^-2] (instead of --m; needs --diffusivity).", rich_help_panel=PANEL_QUESTION)] = None,
    alpha: Annotated[Optional[float], typer.Option(
        "--diffusivity", "--alpha", help="Object diffusivity \\[m^2/s] (instead of --m; needs --e).", rich_help_panel=PANEL_QUESTION)] = None,
    backing: BackingOpt = None,
    tolerance: Annotated[float, typer.Option(
        "--tolerance", help="Acceptable deviation from the semi-infinite reading [°C] "
                            "(default 0.01: the paper's smallest noise level).", rich_help_panel=PANEL_QUESTION)] = 0.01,
    delta_t: DeltaT = 10.0,
    sensor: SensorOpt = "paper",
    horizon: Annotated[float, typer.Option("--horizon", help="Longest contact time examined \\[s].", rich_help_panel=PANEL_QUESTION)] = 3600.0,
    plot: Annotated[Optional[Path], typer.Option(
        "--plot", help="Write a figure of the deviation against contact time (.png, or vector .svg / .pdf).", rich_help_panel=PANEL_OUTPUT)] = None,
    format_: FormatOpt = None,
    out: OutOpt = None,
    json_: Json = False,
) -> None:
    """Contact time up to which the semi-infinite model (paper eq. 2) holds for a slab of this thickness.

    The reading of a slab differs from the semi-infinite one once heat reflected
    at its back face reaches the thermistor (image series, docs/thin_samples.md).
    Prints the first contact time at which that difference exceeds --tolerance.

    Example: `designkit validity --m acrylic --thickness 0.003 --backing table`

    Example (one flat record, pandas-ready): `designkit validity --m acrylic --thickness 0.003 --format csv`
    """
    import numpy as np

    from .._validation import InputError, check_positive
    from ..sensor import load_sensor
    from ..models.slab import material_validity, resolve_backing, semi_infinite_deviation, semi_infinite_validity

    fmt = output_format(format_, json_, out=out)
    L = check_positive("thickness [m]", thickness)
    from .._validation import check_temperature

    check_temperature("--tolerance [°C]", tolerance, nonnegative=True)  # 1e308 was answered
    if plot is not None:
        check_out(plot, "--plot")  # before the work; a missing folder is not made
    if delta_t == 0:
        raise InputError("--delta-t must be non-zero: an unheated sensor sees no difference to hold a tolerance to")
    sen = load_sensor(sensor)
    back = resolve_backing("table" if backing is None else backing)  # the queries' default: on a table
    kw = dict(delta_t_c=delta_t, tolerance_c=tolerance, horizon_s=horizon)
    if material is not None:
        if e is not None or alpha is not None:
            raise InputError("give either --m or --e with --diffusivity, not both")
        mv = material_validity(material, L, back, sen, **kw)
        nominal, worst, name = mv.nominal, mv.worst, mv.material.name
        ranges = {"effusivity_range": [mv.material.e_min, mv.material.e_max],
                  "diffusivity_range_m2_s": [mv.material.diffusivity_min_m2_s, mv.material.diffusivity_max_m2_s]}
    else:
        if e is None or alpha is None:
            raise InputError("give --m MATERIAL, or both --e and --diffusivity (formerly --alpha)")
        nominal = worst = semi_infinite_validity(e, alpha, L, back, sen, **kw)
        name, ranges = None, None
    t_report = np.array(REPORT_TIMES_S)
    dev = delta_t * semi_infinite_deviation(t_report, nominal.e_object, nominal.alpha_object_m2_s, L, back,
                                            sen)[0]
    # T - Ts0 = (Ta - Ts0) u with Ta - Ts0 = -delta_t: a slab reading minus the semi-infinite one
    dev_c = -dev
    if plot is not None:
        _plot(plot, nominal, L, back, sen, delta_t, tolerance, name)
    payload = {
        "valid_up_to_s": _finite(worst.time_s),
        "nominal_valid_up_to_s": _finite(nominal.time_s),
        "fourier_number_at_limit": _finite(worst.fourier_number),
        "limiting_object": {"effusivity": worst.e_object, "diffusivity_m2_s": worst.alpha_object_m2_s},
        "material": name,
        "material_ranges": ranges,
        "object": {"effusivity": nominal.e_object, "diffusivity_m2_s": nominal.alpha_object_m2_s},
        "thickness_m": L,
        "backing": {"name": back.name, "effusivity": back.effusivity,
                    "diffusivity_m2_s": back.diffusivity_m2_s if not back.insulated else None},
        "tolerance_c": tolerance,
        "delta_t_c": delta_t,
        "horizon_s": horizon,
        "sensor": sen.to_dict(),
        "deviation_c": {f"{t:g}": float(d) for t, d in zip(REPORT_TIMES_S, dev_c)},
        "plot": str(plot) if plot else None,
    }
    emit(fmt, out, payload=payload, records=lambda: [flat_record({**{k: v for k, v in payload.items() if k not in ("sensor", "material_ranges")},
                                        **(payload["material_ranges"] or {}), "sensor": payload["sensor"]["name"]})],
         text=lambda: _print_validity(payload, nominal, worst, name, back, sen, L, plot))


def _print_validity(payload: dict, nominal, worst, name, back, sen, L: float, plot) -> None:
    """validity's text for people: the headline is the answer --json gives (the worst case over the ranges)."""
    tolerance, delta_t, horizon = payload["tolerance_c"], payload["delta_t_c"], payload["horizon_s"]
    dev_c = list(payload["deviation_c"].values())
    con = console()
    what = name if name else f"object (e {nominal.e_object:.4g}, alpha {nominal.alpha_object_m2_s:.3g} m²/s)"
    con.print(f"[bold]{L * 1e3:g} mm {what}[/] on {back.name}")
    con.print(f"  (backing e_b {back.effusivity:.4g}; {sen.name} sensor {delta_t:g} °C above the object)")
    # the headline is the answer --json gives (valid_up_to_s: the worst case over the material's ranges)
    fo = f" (Fo = {worst.fourier_number:.3g})" if math.isfinite(worst.time_s) else ""
    over = " over the material's ranges" if name is not None else ""
    con.print(f"  semi-infinite model within {tolerance:g} °C{over} up to "
              f"[bold]{_fmt_time(worst.time_s, horizon)}[/] of contact{fo}")
    if name is not None:
        con.print(f"  limited by e {worst.e_object:.4g}, alpha {worst.alpha_object_m2_s:.3g} m²/s; at the ranges' "
                  f"middle (e {nominal.e_object:.4g}): {_fmt_time(nominal.time_s, horizon)}")
    # below 1e-9 degC the difference is the solvers' own rounding (they agree to 1e-10): not a reading
    cells = ", ".join(f"{t:g} s " + (f"{d + 0.0:.2g}" if abs(d) >= 1e-9 else "<1e-9") for t, d in zip(REPORT_TIMES_S, dev_c))
    con.print(f"  slab minus semi-infinite reading [°C]: {cells}")
    if plot is not None:
        con.print(f"  wrote {plot}")


def _finite(x: float):
    return x if math.isfinite(x) else None


def _fmt_time(t: float, horizon: float) -> str:
    if not math.isfinite(t):
        return f"beyond {horizon:g} s (the horizon examined)"
    return f"{t:.3g} s"


def _plot(path: Path, v, L, back, sen, delta_t, tolerance, name) -> None:
    import numpy as np

    from ..figures import pyplot
    from ..models.slab import semi_infinite_deviation

    plt = pyplot()
    t_end = v.time_s * 3 if math.isfinite(v.time_s) else v.horizon_s
    t = np.geomspace(1e-2, max(t_end, 1.0), 400)
    dev = -delta_t * semi_infinite_deviation(t, v.e_object, v.alpha_object_m2_s, L, back, sen)[0]
    fig, ax = plt.subplots(figsize=(6.4, 4.0), constrained_layout=True)
    floor = tolerance * 1e-4
    # below the floor the difference is not drawn (a gap, not a flat line at the floor: it is no value)
    shown = np.where(np.abs(dev) >= floor, np.abs(dev), np.nan)
    ax.plot(t, shown, color="C0", lw=1.2, label=f"|slab - semi-infinite| (not drawn below {floor:g} °C)")
    ax.axhline(tolerance, color="grey", ls="--", lw=0.8, label=f"tolerance {tolerance:g} °C")
    if math.isfinite(v.time_s):
        ax.axvline(v.time_s, color="C3", lw=0.8, label=f"valid up to {v.time_s:.3g} s")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(bottom=floor)
    ax.set_xlim(t[0], t[-1])  # the whole time range examined, also where the difference is below the floor
    ax.set_xlabel("contact time [s]")
    ax.set_ylabel("reading difference [°C]")
    ax.set_title(f"{L * 1e3:g} mm {name or 'object'} on {back.name}, dT = {delta_t:g} °C", fontsize=9)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    from ..figures import save_figure

    save_figure(fig, path)  # by suffix: png, or vector svg / pdf
