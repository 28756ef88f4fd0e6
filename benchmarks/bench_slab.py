"""Thin samples: error against run time of every solver and resolution, stability, evidence.

Run from the repository root::

    /work/venv/bin/python benchmarks/bench_slab.py            # full study (about 1 min)
    /work/venv/bin/python benchmarks/bench_slab.py --quick    # fewer resolutions
    /work/venv/bin/python benchmarks/bench_slab.py --out docs # also write the docs' figures

What it measures (all at a 10 degC sensor-object difference, 200 Hz samples,
the paper's sensor), printed as markdown tables for ``docs/thin_samples.md``:

1. Error against run time. For each solver and resolution, the largest
   error [degC] over all samples of seven scenes (thin/thick, copper/foam
   extremes, 4-60 s contacts) against a converged reference, and the wall
   time (sum over the scenes, best of ``--repeat``). Reference: the image
   series summed to a 1e-13 tail bound (verified against mpmath's Laplace
   inversion in ``tests/test_slab.py``), cross-checked here against the
   finest finite-volume run. Ratios are against the reference's own time.
2. The default finite-volume resolution: the cheapest setting under 1e-3 degC.
3. Observed orders of convergence in space and time (formal: 2 and 2).
4. Stability: forward Euler against Crank-Nicolson on the same grids.
5. Vectorized use: K effusivity classes at once (the query layer's need).
6. Evidence: 3 mm acrylic on wood vs on steel (and thinner sheets), with the
   ideal observer's view of when the difference becomes detectable.

Timings are wall clock on whatever machine runs it (the committed numbers in
docs/thin_samples.md came from 2 shared cores, so expect noise of tens of %);
ratios are against the reference measured in the same run.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from designkit import SENSORS
from designkit.models import fv, slab
from designkit_lab import explicit_euler

SENSOR = SENSORS["paper"]
DT_C = 10.0  # sensor - object temperature difference [degC]

# (label, e_object, alpha_object, thickness, backing, contact_s). Explicit
# handbook-type numbers so that the study does not move when the materials
# table is edited: PMMA 583 / 1.18e-7 (designkit.materials mid-range), copper
# 36,800 / 1.17e-4, low-density rigid foam 30.5 / 6.0e-7.
COPPER = (36800.0, 1.17e-4)
FOAM = (30.5, 6.0e-7)
ACRYLIC = (583.25, 1.18e-7)
FOAM_BACK = slab.Backing("rigid foam", FOAM[0], FOAM[1])
COPPER_BACK = slab.Backing("copper", COPPER[0], COPPER[1])
SCENES = [
    ("acrylic 3 mm on steel, 60 s", *ACRYLIC, 3e-3, "steel", 60.0),
    ("acrylic 1 mm on wood, 10 s", *ACRYLIC, 1e-3, "wood", 10.0),
    ("copper 1 mm on foam, 4 s", *COPPER, 1e-3, FOAM_BACK, 4.0),
    ("copper 1 mm on foam, 60 s", *COPPER, 1e-3, FOAM_BACK, 60.0),
    ("foam 1 mm on copper, 10 s", *FOAM, 1e-3, COPPER_BACK, 10.0),
    ("copper foil 0.1 mm on wood, 4 s", *COPPER, 1e-4, "wood", 4.0),
    ("acrylic 100 mm block, 4 s", *ACRYLIC, 0.1, "insulated", 4.0),
]


def timed(fn, repeat):
    best = math.inf
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return out, best


def fv_run(scene, cells, ratio, integrator):
    _, e, a, L, back, contact = scene
    t = SENSOR.times_s(contact)
    u, _ = slab._fv_solve(t, np.array([e]), np.array([a]), L, slab.resolve_backing(back), SENSOR,
                          cells, ratio, integrator)
    return u[0]


def references():
    refs = []
    for scene in SCENES:
        _, e, a, L, back, contact = scene
        t = SENSOR.times_s(contact)
        r, sec = timed(lambda: slab.slab_response(t, e, a, L, back, tolerance=1e-13, method="image-series"), 1)
        refs.append((r.response[0], sec, r.n_terms))
    return refs


def error_runtime(refs, quick, repeat):
    rows = []
    ref_time = sum(r[1] for r in refs)

    def add(solver, setting, fn, cells=None):
        errs, total = [], 0.0
        for scene, (ref, _, _) in zip(SCENES, refs):
            u, sec = timed(lambda: fn(scene), repeat)
            errs.append(float(np.max(np.abs(u - ref))) * DT_C)
            total += sec
        rows.append({"solver": solver, "setting": setting, "max_error_c": max(errs),
                     "errors_c": errs, "time_s": total, "cells": cells})
        print(f"  {solver:<22} {setting:<28} max err {max(errs):9.2e} degC   {total * 1e3:8.1f} ms",
              file=sys.stderr)

    def paper(scene):
        _, e, a, L, back, contact = scene
        return slab.slab_response(SENSOR.times_s(contact), e, a, L, back, method="semi-infinite").response[0]

    add("semi-infinite (paper)", "eq. 2, no reflections", paper)
    for tol in ([1e-3, 1e-5, 1e-7] if quick else [1e-2, 1e-3, 1e-4, 1e-5, 1e-7, 1e-9]):
        def series(scene, tol=tol):
            _, e, a, L, back, contact = scene
            return slab.slab_response(SENSOR.times_s(contact), e, a, L, back, tolerance=tol,
                                      method="image-series").response[0]
        add("image series", f"tail bound {tol:g}", series)
    cells_list = [16, 32, 64] if quick else [12, 16, 24, 32, 48, 64, 96, 128]
    ratios = [0.1, 0.05] if quick else [0.2, 0.1, 0.05, 0.025]
    for n in cells_list:
        for r in ratios:
            add("FV Crank-Nicolson", f"n={n}, dt/t={r:g}", lambda s, n=n, r=r: fv_run(s, n, r, "crank-nicolson"),
                cells=n)
    for n in ([16, 32, 64] if quick else [16, 32, 64, 128]):
        for rtol in ([1e-5] if quick else [1e-3, 1e-5, 1e-7]):
            add("FV BDF (solve_ivp)", f"n={n}, rtol={rtol:g}", lambda s, n=n, q=rtol: fv_run(s, n, q, "bdf"),
                cells=n)
    return rows, ref_time


def cross_check(refs):
    """Finest FV run against the series reference: how converged is the reference itself?"""
    worst = 0.0
    for scene, (ref, _, _) in zip(SCENES, refs):
        u = fv_run(scene, 256, 0.0125, "crank-nicolson")
        worst = max(worst, float(np.max(np.abs(u - ref))) * DT_C)
    return worst


def convergence():
    """Observed orders: space (thick acrylic vs eq. 2, BDF far tighter than space) and
    time (Crank-Nicolson vs a tight BDF solution of the same semi-discrete system)."""
    from designkit.models.semi_infinite import object_weight, response_shape

    e, a = ACRYLIC
    t = np.array([0.5, 1.0, 2.0, 4.0])
    exact = object_weight(SENSOR.effusivity, e) * response_shape(t, SENSOR.tau_s)
    space = []
    for n in (12, 24, 48, 96, 192):
        grid = _grid(e, a, 0.1, "insulated", 4.0, n)
        u = fv.integrate_bdf(grid, t, rtol=1e-11, atol=1e-14)[0]
        space.append((n, grid.n_cells, float(np.max(np.abs(u - exact))) * DT_C))
    grid = _grid(*COPPER, 1e-3, FOAM_BACK, 4.0, 24)
    ref = fv.integrate_bdf(grid, t, rtol=1e-12, atol=1e-15)[0]
    tim = []
    for r in (0.4, 0.2, 0.1, 0.05, 0.025):
        u = fv.integrate_crank_nicolson(grid, t, step_ratio=r)[0]
        tim.append((r, float(np.max(np.abs(u - ref))) * DT_C))
    order_space = -np.polyfit(np.log([x[0] for x in space]), np.log([x[2] for x in space]), 1)[0]
    order_time = np.polyfit(np.log([x[0] for x in tim]), np.log([x[1] for x in tim]), 1)[0]
    return space, tim, float(order_space), float(order_time)


def stability():
    """Forward Euler vs Crank-Nicolson on the grids the solver builds."""
    cases = [
        ("copper foil 0.1 mm on foam, 4 s", COPPER, 1e-4, FOAM_BACK, 4.0),
        ("copper 1 mm on foam, 4 s", COPPER, 1e-3, FOAM_BACK, 4.0),
        ("foam 1 mm on copper, 4 s", FOAM, 1e-3, COPPER_BACK, 4.0),
    ]
    rows = []
    for label, (e, a), L, back, contact in cases:
        grid = _grid(e, a, L, back, contact, slab.FV_DEFAULTS["cells_per_layer"])
        limit = float(explicit_euler.explicit_step_limit_s(grid)[0])
        t = SENSOR.times_s(contact)
        levels = fv.time_levels_s(t, slab.FV_DEFAULTS["step_ratio"])
        cn = fv.integrate_crank_nicolson(grid, t, slab.FV_DEFAULTS["step_ratio"])[0]
        ref = slab.slab_response(t, e, a, L, back, tolerance=1e-12, method="image-series").response[0]
        dt_try = 1.0 / SENSOR.sample_rate_hz
        bad = explicit_euler.integrate_explicit(grid, min(dt_try, 2.0 * limit), 2000)
        good = explicit_euler.integrate_explicit(grid, 0.9 * limit, 2000)
        rows.append({
            "case": label,
            "cells": grid.n_cells,
            "finest_cell_m": float(grid.widths_m.min()),
            "explicit_limit_s": limit,
            "explicit_steps_needed": contact / limit,
            "cn_steps": int(levels.size - 1),
            "cn_max_error_c": float(np.max(np.abs(cn - ref))) * DT_C,
            "cn_within_0_1": bool(np.all((cn >= -1e-12) & (cn <= 1 + 1e-12))),
            "explicit_2x_diverged": bad.diverged,
            "explicit_2x_steps_to_blow_up": bad.steps_taken,
            "explicit_0_9x_max_abs": float(np.nanmax(good.max_abs)),
        })
    return rows


def _grid(e, a, L, back, contact, cells):
    b = slab.resolve_backing(back)
    sensor = fv.Layer(SENSOR.effusivity, SENSOR.diffusivity_m2_s, math.inf, 0.0)
    body = [fv.Layer(e, a, L, 1.0)]
    if not b.insulated:
        body.append(fv.Layer(b.effusivity, b.diffusivity_m2_s, math.inf, 1.0))
    return fv.build_grid(sensor, body, SENSOR.depth_m, contact, cells, time_min_s=0.075)


def vectorized(repeat):
    """K effusivity classes of one diffusivity at once: the recognition layer's call."""
    rows = []
    t = SENSOR.times_s(4.0)
    for k in (1, 10, 100, 500):
        e = np.linspace(100.0, 40000.0, k)
        r, sec = timed(lambda: slab.slab_response(t, e, 1.18e-7, 1e-3, "steel", tolerance=1e-6), repeat)
        _, sec_fv = timed(lambda: slab.slab_response(t, e, 1.18e-7, 1e-3, "steel", method="finite-volume"),
                          1 if k > 10 else repeat)
        rows.append({"classes": k, "auto_method": r.method, "auto_time_s": sec, "fv_time_s": sec_fv})
    return rows


def acrylic_evidence():
    """3 mm acrylic on wood vs on steel: reading difference, and when it exceeds the noise."""
    m = slab.material_properties("acrylic")
    t = np.arange(0.0, 60.0 + 1e-9, 0.005)
    out = {"material": m.name, "e": m.effusivity, "alpha_m2_s": m.diffusivity_m2_s, "thickness_m": 3e-3}
    res = {}
    for b in ("wood", "steel", "insulated"):
        r = slab.slab_response(t, m.effusivity, m.diffusivity_m2_s, 3e-3, b, tolerance=1e-8)
        res[b] = r
    semi = slab.slab_response(t, m.effusivity, m.diffusivity_m2_s, math.inf, "insulated")
    temp = {b: r.temperature_c(35.0, 25.0)[0] for b, r in res.items()}
    temp["semi-infinite"] = semi.temperature_c(35.0, 25.0)[0]
    diff = temp["wood"] - temp["steel"]
    out["time_s"] = [1, 2, 3, 4, 10, 20, 30, 45, 60]
    idx = [int(round(x / 0.005)) for x in out["time_s"]]
    out["wood_c"] = [float(temp["wood"][i]) for i in idx]
    out["steel_c"] = [float(temp["steel"][i]) for i in idx]
    out["semi_c"] = [float(temp["semi-infinite"][i]) for i in idx]
    out["difference_c"] = [float(diff[i]) for i in idx]
    over = np.nonzero(np.abs(diff) > 0.05)[0]
    out["exceeds_0_05_at_s"] = float(t[over[0]]) if over.size else None
    over = np.nonzero(np.abs(diff) > 0.01)[0]
    out["exceeds_0_01_at_s"] = float(t[over[0]]) if over.size else None
    out["ideal_90_at_s"] = ideal_from(t, diff)
    out["methods"] = {b: r.method for b, r in res.items()}
    # thinner sheets: when does wood vs steel exceed 0.05 degC?
    thick = []
    for L in (0.5e-3, 1e-3, 2e-3, 3e-3, 5e-3):
        w = slab.slab_response(t, m.effusivity, m.diffusivity_m2_s, L, "wood", tolerance=1e-8).response[0]
        s = slab.slab_response(t, m.effusivity, m.diffusivity_m2_s, L, "steel", tolerance=1e-8).response[0]
        d = np.abs(w - s) * DT_C
        over = np.nonzero(d > 0.05)[0]
        v_w = slab.semi_infinite_validity(m.effusivity, m.diffusivity_m2_s, L, "wood")
        v_s = slab.semi_infinite_validity(m.effusivity, m.diffusivity_m2_s, L, "steel")
        thick.append({"thickness_mm": L * 1e3, "exceeds_0_05_at_s": float(t[over[0]]) if over.size else None,
                      "ideal_90_at_s": ideal_from(t, d),
                      "difference_at_4s_c": float(d[800]), "valid_wood_s": v_w.time_s, "valid_steel_s": v_s.time_s})
    out["by_thickness"] = thick
    out["_curves"] = {k: v for k, v in temp.items()}
    out["_t"] = t
    return out


def _s(x):
    return "> 60" if x is None else f"{x:.2f}"


def ideal_from(t, diff_c, sigma_c=0.05, d_prime=2.5631):
    """Shortest contact time at which ||diff over samples up to t|| / sigma reaches d'.

    For two known noise-free curves with i.i.d. Gaussian noise the likelihood ratio
    test has accuracy Phi(d'/2); d' = 2.5631 gives 90 %."""
    d = np.sqrt(np.cumsum(np.asarray(diff_c) ** 2)) / sigma_c
    over = np.nonzero(d >= d_prime)[0]
    return float(t[over[0]]) if over.size else None


def md_table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(lines)


def plots(out_dir: Path, rows, ref_time, evidence):
    from designkit.figures import pyplot

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.6, 4.4), constrained_layout=True)
    styles = {"semi-infinite (paper)": ("k", "x"), "image series": ("C0", "o"),
              "FV Crank-Nicolson": ("C1", "s"), "FV BDF (solve_ivp)": ("C2", "^")}
    for solver, (col, mk) in styles.items():
        sel = [r for r in rows if r["solver"] == solver]
        ax.scatter([r["time_s"] * 1e3 for r in sel], [max(r["max_error_c"], 1e-12) for r in sel],
                   c=col, marker=mk, label=solver, s=28)
    ax.axhline(1e-3, color="grey", ls="--", lw=0.8)
    ax.text(ax.get_xlim()[0] if False else 0.02, 1.15e-3, "1e-3 °C", transform=ax.get_yaxis_transform(),
            fontsize=8, color="grey")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time for seven scenes [ms]")
    ax.set_ylabel("max error over all samples [°C] (dT = 10 °C)")
    ax.set_title("Thin-sample solvers: error against run time", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.savefig(out_dir / "thin_samples_error_runtime.png", dpi=120)
    plt.close(fig)

    t = evidence["_t"]
    c = evidence["_curves"]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9.6, 3.8), constrained_layout=True)
    for k, col in (("semi-infinite", "k"), ("wood", "C1"), ("steel", "C0"), ("insulated", "C2")):
        a1.plot(t, c[k], color=col, lw=1.0, ls="--" if k == "semi-infinite" else "-", label=k)
    a1.set_xlabel("time after contact [s]")
    a1.set_ylabel("thermistor reading [°C]")
    a1.set_title("3 mm acrylic, sensor 35 °C, object 25 °C", fontsize=9)
    a1.legend(fontsize=8)
    a1.grid(alpha=0.3)
    a2.plot(t, c["wood"] - c["steel"], color="C3", lw=1.0, label="on wood - on steel")
    a2.plot(t, c["wood"] - c["semi-infinite"], color="C1", lw=0.8, ls=":", label="on wood - semi-infinite")
    a2.plot(t, c["steel"] - c["semi-infinite"], color="C0", lw=0.8, ls=":", label="on steel - semi-infinite")
    a2.axhline(0.05, color="grey", ls="--", lw=0.8)
    a2.axhline(-0.05, color="grey", ls="--", lw=0.8)
    a2.set_xlabel("time after contact [s]")
    a2.set_ylabel("reading difference [°C]")
    a2.set_title("what the backing changes (±0.05 °C noise dashed)", fontsize=9)
    a2.legend(fontsize=8)
    a2.grid(alpha=0.3)
    fig.savefig(out_dir / "thin_samples_acrylic.png", dpi=120)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="fewer resolutions")
    p.add_argument("--repeat", type=int, default=2, help="timing repeats (best of)")
    p.add_argument("--out", type=Path, default=None, help="folder for the figures (docs/ for the docs)")
    p.add_argument("--json", type=Path, default=None, help="also write all measured numbers to this JSON file")
    args = p.parse_args(argv)

    t_start = time.perf_counter()
    refs = references()
    print("## Reference: image series to a 1e-13 tail bound", file=sys.stderr)
    rows, ref_time = error_runtime(refs, args.quick, args.repeat)
    finest = None if args.quick else cross_check(refs)

    print("\n### Error against run time (worst case over seven scenes, dT = 10 °C)\n")
    table = []
    for r in rows:
        table.append([r["solver"], r["setting"], f"{r['max_error_c']:.1e}", f"{r['time_s'] * 1e3:.1f}",
                      f"{r['time_s'] / ref_time:.2f}"])
    print(md_table(["solver", "resolution", "max error [°C]", "wall time [ms]", "time / reference"], table))
    print(f"\nReference (series, 1e-13): {ref_time * 1e3:.1f} ms for the seven scenes; terms per scene: "
          + ", ".join(str(r[2]) for r in refs))
    if finest is not None:
        print(f"Finest finite-volume run (n=256, dt/t=0.0125) against the reference: {finest:.1e} °C")
    fvrows = [r for r in rows if r["solver"].startswith("FV") and r["max_error_c"] < 1e-3]
    if fvrows:
        best = min(fvrows, key=lambda r: r["time_s"])
        print(f"\nCheapest finite-volume setting under 1e-3 °C: {best['solver']} {best['setting']} "
              f"({best['max_error_c']:.1e} °C, {best['time_s'] * 1e3:.1f} ms); "
              f"designkit default: {slab.FV_DEFAULTS}")
    print("\nPer-scene errors [°C] of the default-like rows:")
    for r in rows:
        if r["solver"].startswith("FV") and r["cells"] == slab.FV_DEFAULTS["cells_per_layer"]:
            print(f"  {r['solver']} {r['setting']}: " + ", ".join(f"{x:.1e}" for x in r["errors_c"]))

    space, tim, p_space, p_time = convergence()
    print("\n### Observed order of convergence\n")
    print(md_table(["cells per layer n", "cells", "error vs eq. 2 [°C] (100 mm acrylic, BDF rtol 1e-11)"],
                   [[n, c, f"{err:.2e}"] for n, c, err in space]))
    print(f"\nfitted spatial order: {p_space:.2f} (formal: 2)\n")
    print(md_table(["dt / t", "Crank-Nicolson error vs BDF on the same grid [°C] (copper 1 mm on foam)"],
                   [[f"{r:g}", f"{err:.2e}"] for r, err in tim]))
    print(f"\nfitted temporal order: {p_time:.2f} (formal: 2)")

    stab = stability()
    print("\n### Stability: forward Euler against Crank-Nicolson on the same grid\n")
    print(md_table(
        ["case", "cells", "finest cell [µm]", "explicit dt limit [s]", "explicit steps for the contact",
         "CN steps", "CN max error [°C]", "Euler at 2x limit", "Euler at 0.9x limit: largest abs(u)"],
        [[s["case"], s["cells"], f"{s['finest_cell_m'] * 1e6:.2f}", f"{s['explicit_limit_s']:.1e}",
          f"{s['explicit_steps_needed']:.1e}", s["cn_steps"], f"{s['cn_max_error_c']:.1e}",
          f"diverged after {s['explicit_2x_steps_to_blow_up']} steps" if s["explicit_2x_diverged"] else "stable",
          f"{s['explicit_0_9x_max_abs']:.3f}"] for s in stab]))

    vec = vectorized(args.repeat)
    print("\n### K effusivity classes at once (1 mm, alpha 1.18e-7, on steel, 4 s at 200 Hz)\n")
    print(md_table(["classes", "auto method", "auto [ms]", "finite volume [ms]"],
                   [[v["classes"], v["auto_method"], f"{v['auto_time_s'] * 1e3:.1f}",
                     f"{v['fv_time_s'] * 1e3:.1f}"] for v in vec]))

    ev = acrylic_evidence()
    print(f"\n### Evidence: 3 mm {ev['material']} (e {ev['e']:.0f}, alpha {ev['alpha_m2_s']:.3g} m²/s), "
          "sensor 35 °C, object and backing 25 °C\n")
    print(md_table(["t [s]", "on wood [°C]", "on steel [°C]", "semi-infinite [°C]", "wood - steel [°C]"],
                   [[t, f"{w:.4f}", f"{s:.4f}", f"{si:.4f}", f"{d:+.4f}"] for t, w, s, si, d in
                    zip(ev["time_s"], ev["wood_c"], ev["steel_c"], ev["semi_c"], ev["difference_c"])]))
    print(f"\nThe wood - steel difference exceeds 0.01 °C at {ev['exceeds_0_01_at_s']} s and 0.05 °C at "
          f"{ev['exceeds_0_05_at_s']} s (methods: {ev['methods']}). An ideal observer (known curves, "
          f"i.i.d. noise 0.05 °C at 200 Hz, d' = ||wood - steel|| / sigma over the touch) reaches 90 % "
          f"accuracy (d' = 2.56) for contacts from {ev['ideal_90_at_s']} s.\n")
    print(md_table(["thickness [mm]", "difference > 0.05 °C from [s]", "ideal observer 90 % from [s]",
                    "difference at 4 s [°C]", "semi-infinite within 0.01 °C, on wood [s]", "on steel [s]"],
                   [[f"{r['thickness_mm']:g}", _s(r["exceeds_0_05_at_s"]), _s(r["ideal_90_at_s"]),
                     f"{r['difference_at_4s_c']:.1e}", f"{r['valid_wood_s']:.2f}", f"{r['valid_steel_s']:.2f}"]
                    for r in ev["by_thickness"]]))
    total = time.perf_counter() - t_start
    print(f"\nbench_slab total wall time: {total:.1f} s")

    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        plots(args.out, rows, ref_time, ev)
        print(f"wrote {args.out / 'thin_samples_error_runtime.png'}, {args.out / 'thin_samples_acrylic.png'}",
              file=sys.stderr)
    if args.json is not None:
        from designkit._io import atomic_write_text

        payload = {"error_runtime": rows, "reference_time_s": ref_time, "finest_fv_vs_reference_c": finest,
                   "convergence": {"space": space, "time": tim, "order_space": p_space, "order_time": p_time},
                   "stability": stab, "vectorized": vec,
                   "acrylic": {k: v for k, v in ev.items() if not k.startswith("_")},
                   "fv_defaults": slab.FV_DEFAULTS}
        atomic_write_text(args.json, json.dumps(payload, indent=1, default=float) + "\n")
        print(f"wrote {args.json}", file=sys.stderr)


if __name__ == "__main__":
    main()
