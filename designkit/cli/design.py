"""``designkit design``: recommend the sensor for the materials a robot must tell apart.

Exit status: 0 with a recommendation, 2 for bad input or contradictory constraints, 3 when no
allowed design separates the materials (overlapping ranges, or none within the longest contact).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated, Optional

import typer

from . import _app
from ._app import app, console
from ._format import FormatOpt, OutOpt, emit, flat_record, output_format
from ._options import Json

#: Exit status when no design is possible (as questions with no answer).
EXIT_NO_DESIGN = 3


def _plot(result, path: Path, svm: dict | None = None) -> Path:
    from .._numbers import sig
    from ..figures import log_ticks, pyplot, save_figure

    plt = pyplot()
    rig = result.contact is not None
    fig, axes = plt.subplots(1, 3 if rig else 2, figsize=(15.0 if rig else 10.0, 4.2), constrained_layout=True)
    a1, a2 = axes[0], axes[1]
    r = [x for x, _ in result.pareto]
    t = [y for _, y in result.pareto]
    a1.loglog(r, t, "o-", color="C0")
    c = result.constraints
    a1.axvline(c.noise_c / c.max_delta_t_c, color="C3", ls="--", lw=1, label="this noise floor / dT")
    a1.axhline(c.max_contact_s, color="0.5", ls=":", lw=1, label="longest contact")
    pred = (svm or {}).get("prediction") or {}
    iv = pred.get("interval") or {}
    x0 = c.noise_c / c.max_delta_t_c
    if iv.get("low") is not None and iv.get("high") is not None and pred.get("value") is not None:
        a1.errorbar([x0], [pred["value"]], yerr=[[pred["value"] - iv["low"]], [iv["high"] - pred["value"]]],
                    fmt="s", color="C2", capsize=4, label="SVM predicted (mean-F1 crossing), with its 90 % interval")
    civ = (svm or {}).get("interval") or {}
    if (svm or {}).get("value") is not None and pred and civ.get("low") is not None and civ.get("high") is not None:
        a1.errorbar([x0 * 1.06], [svm["value"]], yerr=[[svm["value"] - civ["low"]], [civ["high"] - svm["value"]]],
                    fmt="k^", ms=7, capsize=4, label=f"SVM confirmed ({svm['seeds']} fresh seeds), with its interval")
    elif (svm or {}).get("value") is not None:
        a1.plot([x0], [svm["value"]], "k^", ms=8, label="SVM confirmed")
    a1.set_xlabel("noise sigma / dT [-]  (noise floor over the heater's dT)")
    a1.set_ylabel("limiting pair's shortest contact [s]" + (" (screened)" if rig else ""))
    a1.set_title(f"trade-off of the recommended sensor ({result.best.skin}, {sig(result.best.depth_um)} µm)", fontsize=9)
    a1.legend(fontsize=8)
    by_skin: dict = {}
    for d in result.designs:  # the best over the other design variables at each depth
        row = by_skin.setdefault(d.skin, {})
        row[d.depth_um] = min(row.get(d.depth_um, float("inf")), d.min_contact_s)
    for i, (skin, row) in enumerate(sorted(by_skin.items())):
        xs = sorted(row)
        a2.semilogx(xs, [row[x] if row[x] < 1e9 else float("nan") for x in xs],
                    marker="o", ms=3, color=f"C{i % 10}", ls="-" if i < 10 else "--", label=skin[:40])
    a2.plot([result.best.depth_um], [result.best.min_contact_s], "k*", ms=12, label="recommended")
    b = result.baseline
    if b is not None and b.min_contact_s < 1e9:
        a2.plot([b.depth_um], [b.min_contact_s], "kX", ms=10, label="the rig as built")
    elif b is not None:
        a2.plot([], [], "kX", ms=10, label=f"the rig as built: not within {c.max_contact_s:g} s")
    a2.axhline(c.max_contact_s, color="0.5", ls=":", lw=1)
    log_ticks(a2.xaxis, [d.depth_um for d in result.designs])
    a2.set_xlabel("thermistor depth [µm]")
    how = "ideal observer" if not rig else f"screened under the contact, from the {result.contact.counted_from}"
    a2.set_ylabel(f"limiting pair's shortest contact [s]\n({how})")
    a2.set_title("each skin material over depth" + ("" if result.contact is None else
                                                      " (best thermistor tau, skin thickness and press)"), fontsize=9)
    a2.legend(fontsize=6, ncol=2)
    if rig:  # the thermistor's own lag and the press, for the recommended skin at its depth and thickness
        best, a3 = result.best, axes[2]
        mine = [d for d in result.designs if (d.skin, d.depth_um, d.skin_thickness_um) ==
                (best.skin, best.depth_um, best.skin_thickness_um)]
        for i, pace in enumerate(sorted({d.press_pace for d in mine}, reverse=True)):
            ds = sorted((d for d in mine if d.press_pace == pace), key=lambda d: d.thermistor_tau_s)
            a3.plot([max(d.thermistor_tau_s, 1e-3) for d in ds],
                    [d.min_contact_s if d.min_contact_s < 1e9 else float("nan") for d in ds], "o-", color=f"C{i}",
                    label="the rig's press" if pace == 1 else f"the press {1 / pace:.3g}x as fast")
        a3.plot([max(best.thermistor_tau_s, 1e-3)], [best.min_contact_s], "k*", ms=12, label="recommended")
        a3.set_xscale("log")
        a3.axhline(c.max_contact_s, color="0.5", ls=":", lw=1)
        a3.set_xlabel("thermistor's own time constant [s]")
        a3.set_ylabel("limiting pair's shortest contact [s] (screened)")
        a3.set_title(f"{best.skin[:30]}, {sig(best.depth_um)} µm: thermistor lag and press", fontsize=9)
        a3.legend(fontsize=7)
    return save_figure(fig, path)


@app.command(rich_help_panel=_app.SENSOR)
def design(
    m: Annotated[Optional[list[str]], typer.Option(
        "--m", help="A material to tell apart (repeatable): database name, NAME=MIN:MAX or NAME=E.")] = None,
    set_: Annotated[Optional[str], typer.Option(
        "--set", help="Every material of a named set, by its range as in 'matrix --set' ('paper12': the paper's 12).")] = None,
    identified: Annotated[bool, typer.Option(
        "--identified", help="Judge the --set's materials at their identified effusivities (paper12: the paper's "
                             "calibration), each a point (a class 1 wide), instead of their ranges.")] = False,
    max_contact: Annotated[float, typer.Option(
        "--max-contact", help="Longest acceptable contact [s] (under a rig's contact: from its detected onset).")] = 4.0,
    noise: Annotated[Optional[float], typer.Option(
        "--noise", help="Noise floor, sigma per sample [°C] (default 0.05, or the rig's as calibrated in --sensor).")] = None,
    max_delta_t: Annotated[Optional[float], typer.Option(
        "--max-delta-t", help="Largest temperature difference the heater can hold [°C] (default 10, or the rig's "
                              "dT as calibrated in --sensor).")] = None,
    sensor: Annotated[Optional[Path], typer.Option(
        "--sensor", help="Design under this rig's contact: a sensor file written by calibration (its contact "
                         "conductance, contact area ramp, thermistor lag, noise, dT and detected onset).")] = None,
    contact_conductance: Annotated[Optional[float], typer.Option(
        "--contact-conductance", help="Design under this sensor-object contact conductance [W m^-2 K^-1] "
                                      "(overrides the --sensor file's).")] = None,
    contact_ramp_s: Annotated[Optional[float], typer.Option(
        "--contact-ramp-s", help="Design under a contact area that takes this long to settle [s] (overrides the "
                                 "--sensor file's).")] = None,
    thermistor_tau_s: Annotated[Optional[float], typer.Option(
        "--thermistor-tau-s", help="The thermistor's own time constant [s] (the slowest searched; overrides the "
                                   "--sensor file's lag).")] = None,
    min_thermistor_tau_s: Annotated[float, typer.Option(
        "--min-thermistor-tau-s", help="Fastest thermistor that can be built [s] (under a contact).")] = 0.05,
    skin_thickness_um: Annotated[str, typer.Option(
        "--skin-thickness-um", help="Skin thicknesses that can be built, MIN:MAX [um] (under a rig whose model "
                                    "has a skin film).")] = "50:500",
    max_press_speedup: Annotated[float, typer.Option(
        "--max-press-speedup", help="How much faster than the rig's the press may be (its force ramp's pace; 1: "
                                    "the rig's).")] = 2.0,
    max_rate: Annotated[float, typer.Option("--max-rate", help="Highest sampling rate [Hz].")] = 200.0,
    depth_um: Annotated[str, typer.Option(
        "--depth-um", help="Thermistor depths that can be built, MIN:MAX [um].")] = "20:500",
    skin: Annotated[Optional[list[str]], typer.Option(
        "--skin", help="Candidate skin material (repeatable; default: a set of common polymers, ceramics, metals).")] = None,
    threshold: Annotated[float, typer.Option("--threshold", help="F1 the limiting pair must reach.")] = 0.9,
    svm: Annotated[bool, typer.Option("--svm/--no-svm", help="Confirm the recommendation with the paper's SVM.")] = True,
    plot: Annotated[Optional[Path], typer.Option("--plot", help="Write the trade-off figure (.png, .svg, .pdf).")] = None,
    format_: FormatOpt = None,
    out: OutOpt = None,
    json_: Json = False,
) -> None:
    """Recommend the sensor (skin, thermistor depth, sampling rate, dT) for materials to tell apart.

    Searches with the ideal observer's closed form (fast; a bound no classifier beats), then
    confirms the recommended design with the paper's SVM and says how far apart they are.
    Exit 3 when no allowed design separates the materials.

    Example: `designkit design --set paper12 --identified --max-contact 2 --noise 0.05 --max-delta-t 10 --plot design.png`

    Example (the recommendation as one pandas-ready record): `designkit design --m a=20000 --m b=35000 --no-svm --format csv`

    Under a rig's contact: --sensor FILE (a calibrated rig's), or the contact given explicitly.

    Example (a slow contact, given): `designkit design --m a=20000 --m b=35000 --contact-conductance 1600 --contact-ramp-s 2 --thermistor-tau-s 1 --skin peek --no-svm`
    """
    from ..design.search import SKIN_SET, Constraints, predict_and_confirm, recommend, targets_from
    from ..materials import get_material

    fmt = output_format(format_, json_, out=out)  # before the search: a bad --format or --out is refused first
    depths = _span(depth_um, "--depth-um")
    thick = _span(skin_thickness_um, "--skin-thickness-um")
    if plot is not None:
        from ._format import check_out

        check_out(plot, "--plot")  # before the search; a missing folder is not made
    contact = _contact(sensor, contact_conductance, contact_ramp_s, thermistor_tau_s, max_rate)
    from ..design.contact import rig_defaults

    rig = rig_defaults(contact) if contact is not None else {}
    noise = noise if noise is not None else rig.get("noise_c", 0.05)
    max_delta_t = max_delta_t if max_delta_t is not None else rig.get("delta_t_c", 10.0)
    cons = Constraints(max_contact_s=max_contact, noise_c=noise, max_delta_t_c=max_delta_t, max_rate_hz=max_rate,
                       depth_um=depths, threshold=threshold, min_thermistor_tau_s=min_thermistor_tau_s,
                       skin_thickness_um=thick, max_press_speedup=max_press_speedup)
    from .._validation import check_temperature

    check_temperature("--noise [°C]", noise, nonnegative=True)  # 1e308 searched, then "no design"
    check_temperature("--max-delta-t [°C]", max_delta_t)
    targets = targets_from(m or (), set_, identified=identified)
    skins = tuple(get_material(s).name for s in skin) if skin else SKIN_SET
    t0, c0 = time.perf_counter(), time.process_time()
    how = "the ideal observer" if contact is None else "the rig's contact model (screened)"
    with _app.busy(f"design: searching the designs with {how} ({len(skins)} skins)", quiet=fmt != "text"):
        result = recommend(targets, cons, skins=skins, contact=contact, n_depth=8 if contact is None else 3)
    search = {"wall_s": round(time.perf_counter() - t0, 3), "cpu_s": round(time.process_time() - c0, 3),
              "designs": len(result.designs)}
    payload = {**result.to_dict(), "search": search, "svm": None}
    if result.best is None:
        hint = _identified_hint(set_, identified, result.reason)
        payload["reason"] = result.reason + hint
        emit(fmt, out, payload=payload, records=lambda: [_record(payload)],
             text=lambda: console().print(f"No design possible: {payload['reason']}.", highlight=False))
        raise typer.Exit(EXIT_NO_DESIGN)
    if svm:
        with _app.busy("design: confirming the limiting pair with the paper's SVM", quiet=fmt != "text"):
            payload["svm"] = predict_and_confirm(result, targets)
    if plot is not None:
        payload["figure"] = str(_plot(result, plot, payload["svm"]))
    emit(fmt, out, payload=payload, records=lambda: [_record(payload)],
         text=lambda: _print_design(payload, result, threshold, plot))


def _identified_hint(set_name, identified: bool, reason: str) -> str:
    """What to do when a set's handbook ranges overlap and the set gives identified effusivities."""
    from ..materials import list_materials

    if not set_name or identified or "overlap" not in reason:
        return ""
    if not any(m.identified for m in list_materials(set=set_name)):
        return ""
    return (f"; the {set_name} set's handbook ranges overlap, so judge its materials at their identified "
            "effusivities with --identified")


def _span(text: str, flag: str) -> tuple[float, float]:
    from .._validation import InputError

    lo, sep, hi = text.partition(":")
    try:
        return (float(lo), float(hi)) if sep else (float(lo), float(lo))
    except ValueError:
        raise InputError(f"{flag} must look like MIN:MAX in um, got {text!r}") from None


def _contact(sensor, conductance, ramp_s, tau_s, rate):
    """The contact to design under: the --sensor file's (explicit values overriding it), explicit values alone,
    or None (the paper's instantaneous perfect contact)."""
    from ..design.contact import RigContact

    if sensor is not None:
        from ..sensor import load_sensor

        return RigContact.from_sensor(load_sensor(sensor), conductance_w_m2k=conductance, contact_ramp_s=ramp_s,
                                      thermistor_tau_s=tau_s)
    if conductance is None and ramp_s is None and tau_s is None:
        return None
    return RigContact.explicit(conductance_w_m2k=conductance, contact_ramp_s=ramp_s, thermistor_tau_s=tau_s,
                               sample_rate_hz=rate)


#: design's one record (docs/schema.md, "Records"): the JSON's best flattened (empty without one), the reason,
#: the constraints, the search's figures, the SVM's confirmation as svm_* (its copy of the ideal bound left out)
_BEST = ("skin", "effusivity", "diffusivity_m2_s", "depth_um", "tau_s", "sample_rate_hz", "delta_t_c",
         "thermistor_tau_s", "skin_thickness_um", "press_pace", "ideal_value", "ideal_method", "ideal_time_s",
         "limiting_a", "limiting_b")
_SVM = ("value", "svm_minus_ideal_s", "trials", "seeds", "holds", "note")


def _record(p: dict) -> dict:
    best, svm = flat_record(p["best"] or {}), p["svm"] or {}
    pred = flat_record(svm.get("prediction") or {})
    return {**{k: best.get(k) for k in _BEST}, "reason": p["reason"], **flat_record(p["constraints"]),
            "designs_searched": p["designs_searched"], "wall_s": p["search"]["wall_s"], "cpu_s": p["search"]["cpu_s"],
            **{(k if k.startswith("svm_") else f"svm_{k}"): svm.get(k) for k in _SVM},
            "svm_low": (svm.get("interval") or {}).get("low"), "svm_high": (svm.get("interval") or {}).get("high"),
            **{f"svm_prediction_{k}": pred.get(k) for k in ("value", "interval_low", "interval_high")},
            "figure": p.get("figure")}


def _estimate(e: dict) -> str:
    """An estimate of the mean-F1 crossing with its interval, for people."""
    iv = e["interval"]
    if e["value"] is not None and iv["low"] is None and iv["high"] is not None:  # reached where it was first evaluated
        return f"at most {iv['high']:.3g} s (the mean F1 reaches it at the shortest contact evaluated)"
    rng = (f"{iv['low']:.3g}-{iv['high']:.3g} s ({100 * iv['coverage']:.0f} % interval of the mean-F1 crossing)"
           if iv["low"] is not None and iv["high"] is not None and iv.get("coverage") else "no stated interval")
    return f"{'none' if e['value'] is None else format(e['value'], '.3g') + ' s'}, {rng}"


def _print_design(payload: dict, result, threshold: float, plot) -> None:
    """The recommendation for people."""
    search = payload["search"]
    con = console()
    con.print(f"Recommended: {result.reason}.", highlight=False)
    how = "ideal observer" if result.contact is None else "screened under the rig's contact"
    con.print(f"  searched {len(result.designs)} designs ({how}) in {search['wall_s']:.2f} s "
              f"({search['cpu_s']:.2f} s CPU)", highlight=False)
    if result.contact is not None:
        ct = result.contact.to_dict()
        con.print(f"  contact ({ct['source']}): conductance "
                  f"{'perfect' if ct['conductance_w_m2k'] is None else format(ct['conductance_w_m2k'], '.4g')} "
                  f"W m^-2 K^-1, contact area settling over {ct['contact_ramp_s']:.3g} s, thermistor tau "
                  f"{ct['thermistor_tau_s']:.3g} s, noise {result.constraints.noise_c:.3g} degC"
                  + (f" correlated over {ct['noise_correlation_s']:.2g} s" if ct["noise_correlation_s"] else "")
                  + f", dT {result.constraints.max_delta_t_c:.3g} degC", highlight=False)
    if result.baseline is not None:
        b = result.baseline
        when = f"after {b.min_contact_s:.3g} s" if b.min_contact_s < 1e9 else f"not within {result.constraints.max_contact_s:g} s"
        con.print(f"  the rig as built (its own skin, {b.depth_um:.3g} um, thermistor tau {b.thermistor_tau_s:.3g} s): "
                  f"{b.limiting_pair[0]} / {b.limiting_pair[1]} separates {when} (screened)", highlight=False)
    con.print(f"  rule: a design is credited at least {payload['min_samples']} samples of contact (no "
              "recommendation rests on the first samples)", highlight=False)
    s = payload["svm"]
    pred = (s or {}).get("prediction")
    if pred is not None:  # the statement, then its confirmation (the same quantity)
        con.print(f"  predicted (the exact route's estimate of where the SVM's mean F1 over seeds crosses {threshold:g} "
                  f"for the limiting pair, {pred['repeats']} seeds x {pred['trials']} touches per class and contact, "
                  f"from the {pred['counted_from']}): {_estimate(pred)}", highlight=False)
        con.print(f"  SVM confirmation (the same crossing measured again with {s['seeds']} fresh seeds x {s['trials']} "
                  f"touches per class and contact, {len(s['evaluations'])} contacts): {_estimate(s)}", highlight=False)
        if s.get("holds") is not None:
            con.print(f"  the SVM-confirmed contact {'lies' if s['holds'] else 'does NOT lie'} inside the stated "
                      "interval" + ("" if s["holds"] else " (about one confirmation in seven lands outside a right "
                                    "90 % interval: its own error is about half the statement's)"), highlight=False)
    worst = sorted((p for p in result.pairs), key=lambda p: -(p[2] if p[2] == p[2] else 1e9))[:3]
    con.print("  hardest pairs: " + "; ".join(f"{a} / {b} {t:.3g} s" if t == t else f"{a} / {b} none"
                                             for a, b, t in worst), highlight=False)
    if plot is not None:
        con.print(f"  figure: {payload['figure']}", highlight=False)
