"""delta(e) curves (Figs. 4 and 5), the database's effusivity ranges (Fig. 7), the guideline.

delta(e) curves are drawn straight from the shipped tables (``svm-paper`` for
the paper's SVM with its Monte Carlo interval as a band, ``ideal-paper`` for
the ideal-observer bound); the numbers printed beside them come from
:func:`designkit.query.delta_e`, the same call ``designkit delta-e`` makes, so
the report and the query command agree by construction.
"""

from __future__ import annotations

import time

import numpy as np

from ._report import Comparison, Context, SectionResult, fmt, md_table
from .matrices import AMBIENT_C, FAMILY_COLOURS, IDEAL_TABLE, STAIRCASE_TABLE, axis_index
from .paper import GUIDELINE, PAPER_EXTREMES

__all__ = ["section_delta_curves", "section_effusivity", "section_guideline"]

CONTACTS_S = (1.0, 2.0, 3.0, 4.0)
REFERENCE_E = (500.0, 1000.0, 2000.0, 5000.0, 10000.0, 20000.0, 30000.0)
#: (panel label, Ts0 [degC], sigma [degC]) of Fig. 4 (sigma 0.05, Ts0 30 / 35) and Fig. 5 (Ts0 35).
FIG4 = (("Ts0 30 °C, σ 0.05 °C", 30.0, 0.05), ("Ts0 35 °C, σ 0.05 °C", 35.0, 0.05))
FIG5 = (("σ 0.01 °C", 35.0, 0.01), ("σ 0.05 °C", 35.0, 0.05), ("σ 0.1 °C", 35.0, 0.1))


def _curve(table, array: str, ratio: float, contact: float) -> np.ndarray | None:
    if table is None or array not in table.arrays:
        return None
    ri = axis_index(table.axes["noise_ratio"], ratio)
    ci = axis_index(table.axes["contact_s"], contact)
    if ri is None or ci is None:
        return None
    return np.asarray(table.arrays[array][ri, ci], dtype=np.float64)


def _panel(ax, svm, ideal, ratio: float, label: str) -> None:
    colours = ["#440154", "#31688e", "#35b779", "#e3a019"]
    for c, col in zip(CONTACTS_S, colours):
        ideal_d = _curve(ideal, "delta_up", ratio, c)
        if ideal_d is not None:
            # on top of every SVM curve (an ideal curve can coincide with another contact's SVM curve)
            ax.plot(ideal.axes["e_ref"], ideal_d, ls=(0, (4, 2)), lw=1.4, color=col, zorder=4)
        d = _curve(svm, "delta_up", ratio, c)
        if d is None:
            continue
        e = svm.axes["e_ref"]
        lo, hi = _curve(svm, "delta_up_lo", ratio, c), _curve(svm, "delta_up_hi", ratio, c)
        if lo is not None and hi is not None:
            ok = np.isfinite(lo) & np.isfinite(hi)
            ax.fill_between(e, np.where(ok, lo, np.nan), np.where(ok, hi, np.nan), color=col, alpha=0.25, lw=0)
        ax.plot(e, d, lw=1.6, color=col, label=f"{c:g} s", zorder=2)
    ax.set_title(label, fontsize=10)
    ax.set_xlabel("reference effusivity e [J s$^{-1/2}$ K$^{-1}$ m$^{-2}$]")
    ax.set_ylabel("δ(e) [J s$^{-1/2}$ K$^{-1}$ m$^{-2}$]")
    ax.set_xlim(0, 40000)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)


def _delta_numbers(ctx: Context, ts0: float, sigma: float, svm_ok: bool) -> list[dict]:
    from designkit.query.table import delta_e

    out = []
    dt = ts0 - AMBIENT_C
    for c in CONTACTS_S:
        for e in REFERENCE_E:
            row = {"contact_s": c, "e": e, "ts0_c": ts0, "noise_c": sigma, "delta_t_c": dt}
            if svm_ok:
                a = delta_e(e, contact_s=c, noise_c=sigma, delta_t_c=dt, table=ctx.table(STAIRCASE_TABLE),
                            ideal_table=ctx.table(IDEAL_TABLE)).extra
                row.update({"delta_up": a["delta_e_upper"], "delta_up_interval": a["delta_e_upper_interval"],
                            "delta_down": a["delta_e_lower"], "delta_up_ideal": a["delta_e_upper_ideal"]})
            else:
                a = delta_e(e, contact_s=c, noise_c=sigma, delta_t_c=dt, table=ctx.table(IDEAL_TABLE),
                            ideal_table=ctx.table(IDEAL_TABLE)).extra
                row.update({"delta_up": None, "delta_up_interval": [None, None], "delta_down": None,
                            "delta_up_ideal": a["delta_e_upper"]})
            out.append(row)
    return out


def section_delta_curves(ctx: Context) -> SectionResult:
    """Figs. 4 and 5: delta(e) for contact 1-4 s, Ts0 30/35 degC and sigma 0.01/0.05/0.1 degC."""
    t0 = time.perf_counter()
    title = "δ(e) curves (paper Figs. 4 and 5)"
    svm, ideal = ctx.table(STAIRCASE_TABLE), ctx.table(IDEAL_TABLE)
    if ideal is None and svm is None:
        why = ctx.table_problem(STAIRCASE_TABLE) + "; " + ctx.table_problem(IDEAL_TABLE)
        return SectionResult("delta-curves", title, f"*Skipped: {why}.*", skipped=why, wall_s=time.perf_counter() - t0)
    from designkit.figures import pyplot

    plt = pyplot()
    figs = []
    for name, panels in (("fig4_delta_initial_condition", FIG4), ("fig5_delta_noise", FIG5)):
        fig, axes = plt.subplots(1, len(panels), figsize=(5.2 * len(panels), 4.0), constrained_layout=True,
                                 sharey=True)
        for ax, (label, ts0, sigma) in zip(np.atleast_1d(axes), panels):
            _panel(ax, svm, ideal, sigma / (ts0 - AMBIENT_C), f"{label} (σ/dT {sigma / (ts0 - AMBIENT_C):g})")
        np.atleast_1d(axes)[0].legend(title="contact (solid: SVM,\nband: MC interval,\ndashed: ideal)",
                                      fontsize=8, title_fontsize=8)
        figs.append(ctx.save_figure(fig, name))
    settings = sorted({(ts0, s) for _, ts0, s in FIG4 + FIG5})
    numbers: dict = {"tables": {"svm": svm.name if svm else None, "ideal": ideal.name if ideal else None}}
    blocks = []
    for k, (ts0, sigma) in enumerate(settings):
        rows = _delta_numbers(ctx, ts0, sigma, svm is not None)
        numbers[f"ts0_{ts0:g}_sigma_{sigma:g}"] = rows
        csv = ctx.save_csv(f"delta_e_ts0_{ts0:g}_sigma_{sigma:g}",
                           ["contact_s", "e", "delta_up", "delta_up_lo", "delta_up_hi", "delta_down", "delta_up_ideal"],
                           [[r["contact_s"], r["e"], r["delta_up"], *r["delta_up_interval"], r["delta_down"],
                             r["delta_up_ideal"]] for r in rows])
        table_rows = []
        for e in REFERENCE_E:
            cells = [fmt(e, 5)]
            for c in CONTACTS_S:
                r = next(x for x in rows if x["e"] == e and x["contact_s"] == c)
                lo, hi = r["delta_up_interval"]
                band = f" [{fmt(lo, 3)}–{fmt(hi, 3)}]" if svm is not None else ""
                cells.append(f"{fmt(r['delta_up'], 3)}{band} / {fmt(r['delta_up_ideal'], 3)}")
            table_rows.append(cells)
        blocks += [f"**Ts0 {ts0:g} °C, σ {sigma:g} °C (σ/dT {sigma / (ts0 - AMBIENT_C):g})** — δ(e) towards higher "
                   f"effusivity, SVM [Monte Carlo interval] / ideal bound ([{csv}]({csv})):", "",
                   md_table(["e"] + [f"contact {c:g} s" for c in CONTACTS_S], table_rows), ""]
        ctx.step(k + 1, len(settings))
    lines = []
    if svm is None:
        lines += [f"*The SVM curves are missing: {ctx.table_problem(STAIRCASE_TABLE)}. Only the ideal-observer "
                  f"bound (from `{IDEAL_TABLE}`) is drawn.*", ""]
    lines += [
        f"Curves from `{STAIRCASE_TABLE}` (the paper's SVM"
        + (f" on {svm.header['effusivity']['intervals']} intervals of {svm.header['effusivity']['width']:g}, "
           f"{svm.header['trials']} trials per interval, {svm.header['folds']}-fold F1 >= {svm.threshold:g}"
           if svm is not None else "") + "; solid) with the Monte Carlo interval of δ as a band (pairs within two standard "
        f"errors of the threshold re-scored), and the ideal observer from `{IDEAL_TABLE}` (dashed: no "
        f"classifier can do better). δ is the distance to the first distinguishable interval above e (NaN "
        f"where none lies below 40,000).",
        "",
        f"![Fig. 4]({figs[0]})",
        "",
        f"![Fig. 5]({figs[1]})",
        "",
    ] + blocks + [
        "As in the paper: longer contact, a larger temperature difference and lower noise all lower δ(e); δ(e) "
        "rises with e, steeply above a few thousand (the contact temperature saturates at the object's for "
        "large effusivities).",
    ]
    return SectionResult("delta-curves", title, "\n".join(lines), numbers, tuple(figs),
                         skipped=None if svm is not None else ctx.table_problem(STAIRCASE_TABLE),
                         wall_s=time.perf_counter() - t0)


# ============================================================ Fig. 7
def section_effusivity(ctx: Context) -> SectionResult:
    """Fig. 7: effusivity ranges of the database materials on a log scale."""
    t0 = time.perf_counter()
    from matplotlib.lines import Line2D

    from designkit.figures import pyplot
    from designkit.materials import FAMILY_LABELS, list_materials

    mats = sorted(list_materials(), key=lambda m: (m.e_min, m.e_max))
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8.5, 0.16 * len(mats) + 1.4), constrained_layout=True)
    for k, m in enumerate(mats):
        lo, hi = m.effusivity_range
        ax.plot([lo, hi], [k, k], lw=4, color=FAMILY_COLOURS[m.family], solid_capstyle="butt")
        ax.plot([lo, hi], [k, k], "|", color="black", ms=5)
    ax.set_yticks(range(len(mats)), [m.name for m in mats], fontsize=6)
    ax.set_xscale("log")
    ax.set_xlabel("effusivity [J s$^{-1/2}$ K$^{-1}$ m$^{-2}$] (log scale)")
    ax.grid(axis="x", which="both", alpha=0.3)
    ax.set_ylim(-1, len(mats))
    ax.legend(handles=[Line2D([], [], lw=4, color=c, label=FAMILY_LABELS[f]) for f, c in FAMILY_COLOURS.items()],
              fontsize=7, loc="lower right")
    fig_path = ctx.save_figure(fig, "fig7_effusivity_ranges")
    csv = ctx.save_csv("effusivity_ranges", ["material", "family", "e_min", "e_max"],
                       [[m.name, m.family, m.e_min, m.e_max] for m in mats])
    lo_m = min(mats, key=lambda m: m.e_min)
    hi_m = max(mats, key=lambda m: m.e_max)
    counts = {f: sum(1 for m in mats if m.family == f) for f in FAMILY_COLOURS}
    comps = (Comparison("lowest effusivity in the database", lo_m.e_min, PAPER_EXTREMES["min"], 0.1 * PAPER_EXTREMES["min"]),
             Comparison("highest effusivity in the database", hi_m.e_max, PAPER_EXTREMES["max"], 0.03 * PAPER_EXTREMES["max"]))
    rows = [[m.name, m.family, fmt(m.e_min, 4), fmt(m.e_max, 4)] for m in mats]
    lines = [
        f"{len(mats)} materials of the public handbook table shipped with designkit (`designkit materials list`; "
        f"{', '.join(f'{v} {f}' for f, v in counts.items())}), standing in for the 69 CES EduPack Level-1 "
        f"materials the paper used (a commercial database that cannot be shipped). Ranges from the corner rule "
        f"e = sqrt(k ρ c) at the property extremes.",
        "",
        f"![Fig. 7]({fig_path})",
        "",
        md_table(["extreme", "ours", "paper"], [
            ["lowest", f"{lo_m.name}: {lo_m.e_min:.1f}", f"{PAPER_EXTREMES['min_name']}: {PAPER_EXTREMES['min']:g}"],
            ["highest", f"{hi_m.name}: {hi_m.e_max:,.0f}", f"{PAPER_EXTREMES['max_name']}: {PAPER_EXTREMES['max']:,.0f}"],
        ], align="lll"),
        "",
        f"<details><summary>All {len(mats)} ranges (also in [{csv}]({csv}))</summary>",
        "",
        md_table(["material", "family", "e min", "e max"], rows, align="llrr"),
        "",
        "</details>",
    ]
    numbers = {"materials": len(mats), "families": counts, "lowest": [lo_m.name, lo_m.e_min],
               "highest": [hi_m.name, hi_m.e_max], "csv": csv}
    return SectionResult("effusivity", "Effusivity ranges of the materials database (paper Fig. 7)",
                         "\n".join(lines), numbers, (fig_path,), comps, wall_s=time.perf_counter() - t0)


# ============================================================ guideline
def section_guideline(ctx: Context) -> SectionResult:
    """The design guideline: contact time to separate e = 35,000 from 20,000 (sigma 0.05, dT 10)."""
    t0 = time.perf_counter()
    from designkit import query

    title = "Guideline: 35,000 vs 20,000 needs how long a contact?"
    e1, e2, sigma, dt = GUIDELINE["e1"], GUIDELINE["e2"], GUIDELINE["noise_c"], GUIDELINE["delta_t_c"]
    svm, ideal = ctx.table(STAIRCASE_TABLE), ctx.table(IDEAL_TABLE)
    numbers: dict = {"e1": e1, "e2": e2, "noise_c": sigma, "delta_t_c": dt}
    lines = []
    if svm is not None:
        a = query.min_contact(e1, e2, noise_c=sigma, delta_t_c=dt, table=svm, ideal_table=ideal)
        numbers["table"] = {"contact_s": a.value, "interval_s": list(a.interval), "ideal_contact_s": a.ideal,
                            "table": a.table, "note": a.note}
    else:
        lines.append(f"*Table route skipped: {ctx.table_problem(STAIRCASE_TABLE)}.*")
    quick = ctx.settings.quick
    repeats = 2 if quick else 4
    trials = 30 if quick else 100
    ctx.step(0.1, 1)
    grid = []
    for k, c in enumerate(GUIDELINE["contact_grid_s"]):
        d = query.exact_distinguishable(e1, e2, contact_s=c, noise_c=sigma, delta_t_c=dt, trials=trials,
                                        repeats=repeats, seed=ctx.settings.seed, jobs=ctx.settings.jobs)
        grid.append({"contact_s": c, "svm_f1": d.extra["svm_f1"], "standard_error": d.extra["svm_standard_error"],
                     "ideal_f1": d.extra["ideal_f1"], "distinguishable": bool(d.extra["distinguishable"])})
        ctx.step(0.1 + 0.4 * (k + 1) / 4, 1)
    numbers["paper_grid"] = grid
    ex = query.exact_min_contact(e1, e2, noise_c=sigma, delta_t_c=dt, trials=trials, repeats=repeats,
                                 seed=ctx.settings.seed, jobs=ctx.settings.jobs, max_contact_s=4.0,
                                 tolerance_s=0.1 if quick else 0.05)
    numbers["exact"] = {"contact_s": ex.value, "interval_s": list(ex.interval), "ideal_contact_s": ex.ideal,
                        "evaluations": ex.extra["evaluations"], "trials": trials, "repeats": repeats}
    ctx.step(1, 1)
    first_ok = next((g["contact_s"] for g in grid if g["distinguishable"]), None)
    numbers["first_grid_contact_s"] = first_ok
    comps = (Comparison("guideline: shortest contact on the paper's 1-4 s grid [s]", first_ok,
                        GUIDELINE["min_contact_s"], 0.0),)
    t = numbers.get("table", {})
    rows = [[f"{g['contact_s']:g} s", f"{g['svm_f1']:.3f} ± {g['standard_error']:.3f}", f"{g['ideal_f1']:.3f}",
             "yes" if g["distinguishable"] else "no"] for g in grid]
    lines += [
        f"e = {e1:,.0f} vs {e2:,.0f} J s^-1/2 K^-1 m^-2, σ {sigma:g} °C, sensor {dt:g} °C above the object "
        f"(the paper, section VIII-B: contact for at least {GUIDELINE['min_contact_s']:g} s on its 1–4 s grid).",
        "",
        md_table(["route", "shortest contact", "interval", "ideal observer"], [
            [f"table (`designkit min-contact --e1 {e1:g} --e2 {e2:g}`)", fmt(t.get("contact_s"), 3, " s"),
             f"{fmt((t.get('interval_s') or [None])[0], 3)}–{fmt((t.get('interval_s') or [None, None])[1], 3)} s",
             fmt(t.get("ideal_contact_s"), 3, " s")],
            [f"exact (`--exact`: bisection on the SVM's F1, {repeats} seeds x {trials} trials)",
             fmt(ex.value, 3, " s"), f"{fmt(ex.interval[0], 3)}–{fmt(ex.interval[1], 3)} s", fmt(ex.ideal, 3, " s")],
        ], align="llll"),
        "",
        "On the paper's contact grid (classes 80 wide at each effusivity, exact route):",
        "",
        md_table(["contact", "SVM F1 ± s.e.", "ideal F1", "F1 >= 0.9"], rows),
        "",
        f"Shortest contact of the grid that separates them: **{fmt(first_ok, 3, ' s')}** (paper: "
        f"{GUIDELINE['min_contact_s']:g} s).",
    ]
    return SectionResult("guideline", title, "\n".join(lines), numbers, (), comps, wall_s=time.perf_counter() - t0)
