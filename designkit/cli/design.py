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


def _plot(result, path: Path) -> Path:
    from .._numbers import sig
    from ..figures import log_ticks, pyplot, save_figure

    plt = pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10.0, 4.0), constrained_layout=True)
    r = [x for x, _ in result.pareto]
    t = [y for _, y in result.pareto]
    a1.loglog(r, t, "o-", color="C0")
    c = result.constraints
    a1.axvline(c.noise_c / c.max_delta_t_c, color="C3", ls="--", lw=1, label="this noise floor / dT")
    a1.axhline(c.max_contact_s, color="0.5", ls=":", lw=1, label="longest contact")
    a1.set_xlabel("noise sigma / dT [-]  (noise floor over the heater's dT)")
    a1.set_ylabel("limiting pair's shortest contact [s]")
    a1.set_title(f"trade-off of the recommended sensor ({result.best.skin}, {sig(result.best.depth_um)} µm)")
    a1.legend(fontsize=8)
    by_skin = {}
    for d in result.designs:
        by_skin.setdefault(d.skin, []).append(d)
    for i, (skin, ds) in enumerate(sorted(by_skin.items())):
        ds = sorted(ds, key=lambda d: d.depth_um)
        a2.semilogx([d.depth_um for d in ds], [d.min_contact_s if d.min_contact_s < 1e9 else float("nan") for d in ds],
                    marker="o", ms=3, color=f"C{i % 10}", ls="-" if i < 10 else "--", label=skin[:40])
    a2.plot([result.best.depth_um], [result.best.min_contact_s], "k*", ms=12, label="recommended")
    log_ticks(a2.xaxis, [d.depth_um for d in result.designs])
    a2.set_xlabel("thermistor depth [µm]")
    a2.set_ylabel("limiting pair's shortest contact [s] (ideal observer)")
    a2.set_title("each skin material over depth", fontsize=9)
    a2.legend(fontsize=6, ncol=2)
    return save_figure(fig, path)


@app.command(rich_help_panel=_app.SENSOR)
def design(
    m: Annotated[Optional[list[str]], typer.Option(
        "--m", help="A material to tell apart (repeatable): database name, NAME=MIN:MAX or NAME=E.")] = None,
    set_: Annotated[Optional[str], typer.Option(
        "--set", help="Every material of a named set, by its range as in 'matrix --set' ('paper12': the paper's 12).")] = None,
    identified: Annotated[bool, typer.Option(
        "--identified", help="Judge the --set's materials at their identified effusivities (paper12: the paper's "
                             "calibration), 80-wide classes, instead of their ranges.")] = False,
    max_contact: Annotated[float, typer.Option("--max-contact", help="Longest acceptable contact [s].")] = 4.0,
    noise: Annotated[float, typer.Option("--noise", help="Noise floor of the electronics, sigma per sample [°C].")] = 0.05,
    max_delta_t: Annotated[float, typer.Option(
        "--max-delta-t", help="Largest temperature difference the heater can hold [°C].")] = 10.0,
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
    """
    from .._validation import InputError
    from ..design.search import SKIN_SET, Constraints, confirm_with_svm, recommend, targets_from
    from ..materials import get_material

    fmt = output_format(format_, json_, out=out)  # before the search: a bad --format or --out is refused first
    lo, sep, hi = depth_um.partition(":")
    try:
        depths = (float(lo), float(hi)) if sep else (float(lo), float(lo))
    except ValueError:
        raise InputError(f"--depth-um must look like MIN:MAX in um, got {depth_um!r}") from None
    if plot is not None:
        from ._format import check_out

        check_out(plot, "--plot")  # before the search; a missing folder is not made
    cons = Constraints(max_contact_s=max_contact, noise_c=noise, max_delta_t_c=max_delta_t, max_rate_hz=max_rate,
                       depth_um=depths, threshold=threshold)
    from .._validation import check_temperature

    check_temperature("--noise [°C]", noise, nonnegative=True)  # 1e308 searched, then "no design"
    check_temperature("--max-delta-t [°C]", max_delta_t)
    targets = targets_from(m or (), set_, identified=identified)
    skins = tuple(get_material(s).name for s in skin) if skin else SKIN_SET
    t0, c0 = time.perf_counter(), time.process_time()
    with _app.busy(f"design: searching skins x depths with the ideal observer ({len(skins)} skins)", quiet=fmt != "text"):
        result = recommend(targets, cons, skins=skins)
    search = {"wall_s": round(time.perf_counter() - t0, 3), "cpu_s": round(time.process_time() - c0, 3),
              "designs": len(result.designs)}
    payload = {**result.to_dict(), "search": search, "svm": None}
    if result.best is None:
        emit(fmt, out, payload=payload, records=lambda: [_record(payload)],
             text=lambda: console().print(f"No design possible: {result.reason}.", highlight=False))
        raise typer.Exit(EXIT_NO_DESIGN)
    if svm:
        with _app.busy("design: confirming the limiting pair with the paper's SVM", quiet=fmt != "text"):
            payload["svm"] = confirm_with_svm(result, targets)
    if plot is not None:
        payload["figure"] = str(_plot(result, plot))
    emit(fmt, out, payload=payload, records=lambda: [_record(payload)],
         text=lambda: _print_design(payload, result, threshold, plot))


#: design's one record (docs/schema.md, "Records"): the JSON's best flattened (empty without one), the reason,
#: the constraints, the search's figures, the SVM's confirmation as svm_* (its copy of the ideal bound left out)
_BEST = ("skin", "effusivity", "diffusivity_m2_s", "depth_um", "tau_s", "sample_rate_hz", "delta_t_c", "ideal_value",
         "ideal_method", "limiting_a", "limiting_b")
_SVM = ("value", "svm_f1", "svm_minus_ideal_s", "grid_step_s", "trials", "seeds", "note")


def _record(p: dict) -> dict:
    best, svm = flat_record(p["best"] or {}), p["svm"] or {}
    return {**{k: best.get(k) for k in _BEST}, "reason": p["reason"], **flat_record(p["constraints"]),
            "designs_searched": p["designs_searched"], "wall_s": p["search"]["wall_s"], "cpu_s": p["search"]["cpu_s"],
            **{(k if k.startswith("svm_") else f"svm_{k}"): svm.get(k) for k in _SVM}, "figure": p.get("figure")}


def _print_design(payload: dict, result, threshold: float, plot) -> None:
    """The recommendation for people."""
    search = payload["search"]
    con = console()
    con.print(f"Recommended: {result.reason}.", highlight=False)
    con.print(f"  searched {len(result.designs)} designs (ideal observer) in {search['wall_s']:.2f} s "
              f"({search['cpu_s']:.2f} s CPU)", highlight=False)
    s = payload["svm"]
    if s is not None:
        if s["value"] is not None:
            runs = f"{s['seeds']} x {s['trials']} touches per class"
            if s["svm_minus_ideal_s"] > 0:  # checked from the ideal bound up in steps: the last step fell short
                prev = s["value"] - s["grid_step_s"]
                con.print(f"  SVM (the paper's classifier) on the limiting pair: F1 >= {threshold:g} at "
                          f"{s['value']:.3g} s, not yet at {prev:.3g} s (contacts checked from the "
                          f"ideal bound in {s['grid_step_s']:g} s steps, {runs}): its shortest contact lies in "
                          f"({prev:.3g}, {s['value']:.3g}] s, at most {s['svm_minus_ideal_s']:.3g} s "
                          "above the ideal bound", highlight=False)
            else:
                con.print(f"  SVM (the paper's classifier) on the limiting pair: F1 >= {threshold:g} already at the "
                          f"ideal bound, {s['value']:.3g} s ({runs})", highlight=False)
        else:
            con.print(f"  SVM: {s['note']}", highlight=False)
    worst = sorted((p for p in result.pairs), key=lambda p: -(p[2] if p[2] == p[2] else 1e9))[:3]
    con.print("  hardest pairs: " + "; ".join(f"{a} / {b} {t:.3g} s" if t == t else f"{a} / {b} none"
                                             for a, b, t in worst), highlight=False)
    if plot is not None:
        con.print(f"  figure: {payload['figure']}", highlight=False)
