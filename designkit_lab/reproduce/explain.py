"""Measured evidence for the differences between our Table I and the paper's.

Every explanation the report gives is backed by a number computed here or
read from a shipped table, never by a guess:

* **Sensor depth.** The paper does not print the thermistor depth; designkit
  assumes 80 um (tau = 1.34 s). The ideal observer's % indistinguishable
  pairs is exact and cheap (closed form), so its dependence on the depth is
  computed here; where the paper's % lies *below* the ideal bound at 80 um no
  classifier could reach it with that sensor, and the depth at which the
  bound meets the paper's number is found by bisection.
* **Classifier efficiency.** Our SVM's % against the bound on the same grid.
* **Grid coarseness.** The mean F1 of the low-effusivity region on the coarse
  (width 400) and the paper's (width 80) grid, from two full-matrix tables.
* **What mean F1 implies.** The paper's mean F1 and % together imply the
  mean F1 of its indistinguishable pairs (if its distinguishable pairs scored
  as ours do); it is compared with ours and with the measured chance F1.
* **Database.** Materials whose ranges overlap make pairs that no sensor can
  separate; their share in our database is counted.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np

from ._report import Context, fmt, md_table
from .matrices import COARSE_TABLE, TABLE1_CONTACT_S, f1_matrix, staircase_percent
from .paper import TABLE1

__all__ = ["explain_table1", "ideal_percent", "implied_depth_m", "table1_evidence"]

DEPTHS_UM = (40.0, 60.0, 80.0, 100.0)
GRADIENT_TABLE = "evidence-gradient-slope"


def ideal_percent(depth_m: float, noise_ratio: float, contact_s: float = TABLE1_CONTACT_S,
                  intervals: int = 500, workdir: Path | None = None) -> float:
    """Ideal observer's % indistinguishable interval pairs on the paper's grid for the paper's
    sensor at thermistor depth ``depth_m`` (closed form, through the sweep engine)."""
    from designkit.sweep import SweepConfig, run_scene
    from designkit.sensor import SENSORS

    sensor = SENSORS["paper"].replace(depth_m=float(depth_m), name=f"paper-depth-{depth_m * 1e6:g}um")
    with tempfile.TemporaryDirectory(dir=workdir) as tmp:
        path = sensor.to_yaml(Path(tmp) / "sensor.yaml")
        cfg = SweepConfig(name="depth", sensor=str(path), fidelity="ideal", intervals=intervals,
                          noise_ratio=(float(noise_ratio),), contact_s=(float(contact_s),))
        J = run_scene(cfg)[0].J
    n = intervals
    return 100.0 * (1.0 - float(np.sum(n - J)) / (n * (n - 1) / 2))


def implied_depth_m(target_percent: float, noise_ratio: float, *, lo_m: float = 5e-6, hi_m: float = 80e-6,
                    iterations: int = 8, intervals: int = 500) -> float | None:
    """Largest depth [m] in (lo, hi] at which the ideal bound is still at or below ``target_percent``.

    Bisection in log depth (the bound grows with depth); None when even
    ``lo_m`` is above the target.
    """
    def bound(depth_m):
        return ideal_percent(depth_m, noise_ratio, intervals=intervals)

    if bound(lo_m) > target_percent:
        return None
    if bound(hi_m) <= target_percent:
        return hi_m
    a, b = math.log(lo_m), math.log(hi_m)
    for _ in range(iterations):
        mid = 0.5 * (a + b)
        if bound(math.exp(mid)) <= target_percent:
            a = mid
        else:
            b = mid
    return math.exp(a)


def _f1_split(ctx: Context, ratio: float) -> dict | None:
    """Mean F1 of the coarse matrix's distinguishable and indistinguishable pairs."""
    t = ctx.table(COARSE_TABLE)
    m = f1_matrix(t, ratio, TABLE1_CONTACT_S)
    if m is None:
        return None
    v = m[np.triu_indices(m.shape[0], 1)]
    phi = t.threshold
    ok = v >= phi
    return {"share_distinguishable": float(ok.mean()),
            "mean_f1_distinguishable": float(v[ok].mean()) if ok.any() else math.nan,
            "mean_f1_indistinguishable": float(v[~ok].mean()) if (~ok).any() else math.nan}


def _overlap_share(ctx: Context) -> dict:
    from designkit.materials import list_materials

    r = np.array([m.effusivity_range for m in list_materials()])
    K = r.shape[0]
    iu = np.triu_indices(K, 1)
    overlap = np.maximum(r[iu[0], 0], r[iu[1], 0]) <= np.minimum(r[iu[0], 1], r[iu[1], 1])
    return {"pairs": int(iu[0].size), "overlapping": int(overlap.sum()),
            "percent_overlapping": 100.0 * float(overlap.mean())}


def table1_evidence(ctx: Context, rows: list[dict]) -> dict:
    """Numbers behind the Table I explanations, and their markdown."""
    quick = ctx.settings.quick
    ratios = sorted({r["noise_ratio"] for r in rows})
    ev: dict = {"depth": {}, "implied_depth_um": {}, "f1_split": {}, "low_region": {}}
    depths = (80.0,) if quick else DEPTHS_UM
    grid = 100 if quick else 500  # quick mode: the bound on a coarser grid (the report says quick)
    ev["grid_intervals"] = grid
    for k, ratio in enumerate(ratios):
        ev["depth"][f"{ratio:g}"] = {f"{d:g}": ideal_percent(d * 1e-6, ratio, intervals=grid) for d in depths}
        ev["f1_split"][f"{ratio:g}"] = _f1_split(ctx, ratio)
        ctx.step(len(rows) + k + 0.5, len(rows) + len(ratios))
    for r in rows:
        key = f"{r['noise_ratio']:g}"
        ideal80 = r["intervals"]["percent_ideal"]
        paper = r["paper"]["intervals_percent"]
        if ideal80 is not None and paper < ideal80 and key not in ev["implied_depth_um"]:
            d = implied_depth_m(paper, r["noise_ratio"], iterations=3 if quick else 8, intervals=grid)
            ev["implied_depth_um"][key] = None if d is None else d * 1e6
        if r["intervals"].get("low_region"):
            ev["low_region"][key] = r["intervals"]["low_region"]
    ev["overlap"] = _overlap_share(ctx)
    grad_t, sg_t = ctx.table(GRADIENT_TABLE), ctx.table(COARSE_TABLE)
    ev["slope"] = {}
    if grad_t is not None and sg_t is not None:
        for ratio in ratios:
            g = staircase_percent(grad_t, ratio, TABLE1_CONTACT_S)
            sg = staircase_percent(sg_t, ratio, TABLE1_CONTACT_S)
            if g is not None and sg is not None:
                ev["slope"][f"{ratio:g}"] = {"savgol_0.25s": sg, "central_difference": g}

    md = []
    depth_rows = []
    for ratio in ratios:
        key = f"{ratio:g}"
        paper_pct = [r["paper"]["intervals_percent"] for r in rows if math.isclose(r["noise_ratio"], ratio)]
        ours = next(r["intervals"]["percent"] for r in rows if math.isclose(r["noise_ratio"], ratio))
        depth_rows.append([key, ", ".join(f"{p:g}" for p in paper_pct), fmt(ours, 4)]
                          + [fmt(ev["depth"][key].get(f"{d:g}"), 4) for d in depths]
                          + [fmt(ev["implied_depth_um"].get(key), 3)])
    md += [
        f"**Sensor depth (measured: ideal-observer bound, closed form, {grid}-interval grid, contact 2 s).** "
        "% indistinguishable interval pairs no classifier can beat, for thermistor depths the paper does not "
        "print (designkit assumes 80 µm, τ = 1.34 s); last column: the largest depth at which the bound is "
        "still at or below the paper's number (blank: the paper's number is above the 80 µm bound, i.e. "
        "reachable):",
        "",
        md_table(["σ/dT", "% paper", "% ours (SVM)"] + [f"bound at {d:g} µm" for d in depths]
                 + ["depth matching the paper [µm]"], depth_rows),
        "",
    ]
    split_rows = []
    for r in rows:
        key = f"{r['noise_ratio']:g}"
        sp = ev["f1_split"].get(key)
        if not sp:
            continue
        p = r["paper"]["intervals_percent"] / 100.0
        implied = (r["paper"]["intervals_f1"] - (1 - p) * sp["mean_f1_distinguishable"]) / p
        r.setdefault("evidence", {})["paper_implied_indistinguishable_f1"] = implied
        split_rows.append([fmt(r["noise_c"]), fmt(r["delta_t_c"]), fmt(sp["mean_f1_distinguishable"], 3),
                           fmt(sp["mean_f1_indistinguishable"], 3), fmt(implied, 3)])
    if split_rows:
        chance = ctx.cache.get("chance_f1")
        md += [
            "**What the paper's mean F1 implies (measured on our coarse matrices).** If the paper's "
            "distinguishable pairs scored as ours do, its mean F1 and % together imply the mean F1 of its "
            "indistinguishable pairs (last column), to compare with ours"
            + (f" and with the SVM's chance F1 on identical classes ({chance['mean']:.3f})" if chance else "")
            + ":",
            "",
            md_table(["σ", "dT", "our mean F1, F1 >= 0.9 pairs", "our mean F1, F1 < 0.9 pairs",
                      "paper's implied mean F1, indistinguishable pairs"], split_rows),
            "",
        ]
    low_rows = [[k, fmt(v["coarse"]["mean_f1"], 3), fmt(v["fine"]["mean_f1"], 3),
                 fmt(v["coarse"]["percent_indistinguishable"], 3), fmt(v["fine"]["percent_indistinguishable"], 3)]
                for k, v in sorted(ev["low_region"].items(), key=lambda kv: float(kv[0]))]
    if low_rows:
        e_max = next(iter(ev["low_region"].values()))["e_max"]
        md += [
            f"**Grid coarseness (measured: the same region, (0, {e_max:g}], scored on both grids).** Mean F1 "
            f"and % F1 < 0.9 of all interval pairs of the region with intervals 400 wide (`f1-matrix-2s`) and "
            f"80 wide (`f1-matrix-fine-low`, the paper's width):",
            "",
            md_table(["σ/dT", "mean F1, width 400", "mean F1, width 80", "% F1 < 0.9, width 400",
                      "% F1 < 0.9, width 80"], low_rows),
            "",
        ]
    if ev["slope"]:
        md += [
            "**Slope estimator (measured: two full sweeps on the same 100-interval grid, contact 2 s).** % "
            "indistinguishable interval pairs (first distinguishable partner per row) with designkit's "
            "Savitzky-Golay slope over 0.25 s (`f1-matrix-2s`) and with a central-difference slope "
            "(np.gradient's rule, `evidence-gradient-slope`), everything else equal:",
            "",
            md_table(["σ/dT", "% paper (500 grid)", "% Savitzky-Golay 0.25 s", "% central difference"],
                     [[k, ", ".join(f"{r['paper']['intervals_percent']:g}" for r in rows
                                    if math.isclose(r["noise_ratio"], float(k))),
                       fmt(v["savgol_0.25s"], 4), fmt(v["central_difference"], 4)]
                      for k, v in sorted(ev["slope"].items(), key=lambda kv: float(kv[0]))]),
            "",
        ]
    elif grad_t is None:
        md += [f"*Slope-estimator evidence missing: {ctx.table_problem(GRADIENT_TABLE)}.*", ""]
    ov = ev["overlap"]
    md += [
        f"**Database (measured).** {ov['overlapping']} of our {ov['pairs']} material pairs "
        f"({ov['percent_overlapping']:.1f} %) have overlapping effusivity ranges, so some objects of the two "
        f"materials are identical to the sensor and the pair's mean F1 includes chance-level cells; the paper's "
        f"69 CES materials cannot be checked the same way (their ranges are not public).",
        "",
    ]
    ev["markdown"] = md
    return ev


def explain_table1(quantity: str, row: dict, ev: dict) -> str:
    """One explanation for a Table I difference beyond tolerance, citing the measured evidence."""
    key = f"{row['noise_ratio']:g}"
    ours_i = row["intervals"]
    paper = row["paper"]
    if quantity == "intervals % indistinguishable":
        ideal = ours_i["percent_ideal"]
        ours = ours_i["percent"]
        parts = []
        if ideal is not None and paper["intervals_percent"] < ideal:
            d = ev["implied_depth_um"].get(key)
            parts.append(f"the paper's {paper['intervals_percent']:g} % is below the ideal-observer bound "
                         f"({ideal:.2f} %) for the 80 µm thermistor depth designkit assumes: no classifier can "
                         f"reach it with that sensor; the bound comes down to the paper's number at a depth of "
                         f"{fmt(d, 3)} µm (sensor depth assumption, measured above)")
        elif ideal is not None and ours is not None:
            parts.append(f"the paper's {paper['intervals_percent']:g} % lies well above the ideal bound "
                         f"({ideal:.2f} %) and above our SVM ({ours:.2f} %): its classifier was less efficient than "
                         f"ours at this low noise (the paper's % barely changes with noise — "
                         f"{min(p.intervals_percent for p in TABLE1):g} % to "
                         f"{max(p.intervals_percent for p in TABLE1):g} % over a 20-fold range of σ/dT — while the "
                         f"bound changes "
                         f"{ev['depth'].get('0.001', {}).get('80', math.nan):.1f} % to "
                         f"{ev['depth'].get('0.02', {}).get('80', math.nan):.1f} %, so something other than "
                         f"noise limited it: its slope estimator and SVM settings are not given; ours uses a "
                         f"Savitzky-Golay slope and standardized features, docs/physics.md section 2)")
        return "; ".join(parts)
    if quantity == "intervals mean F1":
        implied = row.get("evidence", {}).get("paper_implied_indistinguishable_f1")
        sp = ev["f1_split"].get(key) or {}
        low = ev["low_region"].get(key)
        text = (f"our indistinguishable pairs average F1 {fmt(sp.get('mean_f1_indistinguishable'), 3)}; the "
                f"paper's numbers imply {fmt(implied, 3)} for its own (if its distinguishable pairs scored as ours), "
                f"so the mean F1 difference comes from how the failing pairs score, not from how many fail")
        if low:
            text += (f"; the coarse grid changes the low-effusivity region's mean F1 by "
                     f"{low['coarse']['mean_f1'] - low['fine']['mean_f1']:+.3f} (width 400 minus width 80, measured)")
        return text
    mat = row.get("materials") or {}
    co = mat.get("coarse_only") or {}
    ov = ev["overlap"]
    if quantity == "materials % indistinguishable":
        return (f"different databases (our {mat.get('materials')} public handbook families, "
                f"{ov['percent_overlapping']:.1f} % of whose pairs overlap in effusivity, against the paper's 69 CES "
                f"materials), and the interval-level difference of this setting carries over "
                f"(intervals: ours {fmt(ours_i['percent'], 4)} % vs {paper['intervals_percent']:g} %); the coarse "
                f"grid alone would give {fmt(co.get('percent_indistinguishable'), 4)} %")
    if quantity == "materials mean F1":
        return (f"pairs of overlapping materials average near chance F1 and {ov['percent_overlapping']:.1f} % of our "
                f"pairs overlap; different database (our {mat.get('materials')} families vs the paper's 69); "
                f"the coarse grid alone would give {fmt(co.get('mean_f1'), 3)}")
    return ""
