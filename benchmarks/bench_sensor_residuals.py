"""Held-out residuals of the sensor models on the shared robot recordings, and where in the touch they lie (issue 14).

Run from the repository root (a few minutes on the shared 2 cores; be nice)::

    nice -n 10 python benchmarks/bench_sensor_residuals.py                  # all candidates, figure
    nice -n 10 python benchmarks/bench_sensor_residuals.py --json res.json --figure docs/sensor_residuals.png

Every candidate of :data:`designkit.calibration.candidates.CANDIDATES` is fitted on the metal and wood
touches of trial sets 1-4 (:func:`~designkit.calibration.compare.compare_models`; object temperatures
from the passive channel before contact) and scored on sets 5-20, each held-out touch with its own
initial state (Ts0, and the drift where the candidate has it). Printed: the residual RMS per material,
AIC/BIC on the fitted touches, e_s with its 95 % interval, fit time and the load average; then, for the
paper's model, the previous selection (``layered+lag+smoothing``) and the selected one, the held-out
RMS in windows of the touch (before contact, the first 0.5 s, ..., the tail). The figure shows the
held-out residual of every touch against time for those three models.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

from designkit.calibration.candidates import CANDIDATES
from designkit.calibration.compare import compare_models
from designkit.calibration.identify import residual_series
from designkit.calibration.split import split_by_trial_set
from designkit.calibration.trials import load_index

RANGES = {"metal": (12767.0, 25972.0), "wood": (331.0, 506.46)}   # the paper's aluminium and wood
WINDOWS_S = ((-1.0, 0.0), (0.0, 0.5), (0.5, 1.5), (1.5, 3.0), (3.0, 5.0), (5.0, 7.01))
TARGET_C = 0.05
SHOWN = ("semi-infinite", "layered+lag+smoothing")


def _default_data() -> Path:
    env = os.environ.get("DESIGNKIT_ROBOT_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "shared" / "data" / "robot-thermal-recordings"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=_default_data(), help="folder of the recordings (index.csv)")
    ap.add_argument("--fit-sets", default="1,2,3,4", help="trial sets to fit (the others are scored)")
    ap.add_argument("--json", type=Path, default=None, help="write the table and window RMS here")
    ap.add_argument("--figure", type=Path, default=None, help="write the residual figure (PNG) here")
    args = ap.parse_args()
    index = args.data / "index.csv"
    trials = load_index(index, only=["metal", "wood"])
    fit, held = split_by_trial_set(trials, [int(s) for s in args.fit_sets.split(",")], index)
    print(f"{len(fit)} touches fitted, {len(held)} held out; load average {os.getloadavg()[0]:.2f} "
          f"(on {os.cpu_count()} cores)")
    t0 = time.perf_counter()
    cmp = compare_models(fit, held, CANDIDATES, ranges=RANGES, object_temps={"metal": "passive", "wood": "passive"})
    wall = time.perf_counter() - t0
    print(f"\n{'model':34s} {'fit':>7s} {'metal':>7s} {'wood':>7s} {'all':>7s} {'BIC':>9s} {'rank':>5s} "
          f"{'e_s [95 %]':>22s} {'time':>6s}")
    rows = []
    for res, sc in zip(cmp.results, cmp.held_out_rms_c):
        es = res.effusivity
        es_txt = "conflict" if not res.consistent else f"{es.value:.0f} [{es.ci95[0]:.0f}, {es.ci95[1]:.0f}]"
        mark = " *" if res.candidate.label == cmp.selected else ""
        print(f"{res.candidate.label + mark:34s} {res.rms_c:7.4f} {sc['metal']:7.4f} {sc['wood']:7.4f} "
              f"{sc['all']:7.4f} {res.bic:9.0f} {res.rank:>2d}/{res.n_nonlinear:<2d} {es_txt:>22s} "
              f"{res.fit_time_s:5.1f}s")
        rows.append({"model": res.candidate.label, "fit_rms_c": res.rms_c, "held_out_rms_c": dict(sc),
                     "aic": res.aic, "bic": res.bic, "rank": res.rank, "n_nonlinear": res.n_nonlinear,
                     "effusivity": es.to_dict() if es else None, "consistent": res.consistent,
                     "parameters": [p.to_dict() for p in res.parameters], "fit_time_s": res.fit_time_s})
    print(f"all candidates: {wall:.1f} s (load {os.getloadavg()[0]:.2f}); selected {cmp.selected}")
    best = next(r for r in rows if r["model"] == cmp.selected)["held_out_rms_c"]
    ok = best["metal"] <= TARGET_C and best["wood"] <= TARGET_C
    print(f"target (held-out <= {TARGET_C} degC for metal and wood with one model): {'met' if ok else 'NOT met'}")

    shown = [lab for lab in SHOWN if lab != cmp.selected] + [cmp.selected]
    series = {lab: residual_series(next(r for r in cmp.results if r.candidate.label == lab), held) for lab in shown}
    windows = {}
    print("\nheld-out RMS [degC] by window of the touch (s after the detected onset)")
    print(f"{'model':34s} {'material':9s} " + " ".join(f"{f'{a:g}..{b:g}':>8s}" for a, b in WINDOWS_S))
    for lab in shown:
        for mat in ("metal", "wood"):
            rs = [(t, r) for m, t, r in series[lab] if m == mat]
            vals = [float(np.sqrt(np.mean(np.concatenate([r[(t >= a) & (t < b)] for t, r in rs]) ** 2)))
                    for a, b in WINDOWS_S]
            windows.setdefault(lab, {})[mat] = vals
            print(f"{lab:34s} {mat:9s} " + " ".join(f"{v:8.4f}" for v in vals))
    if args.figure:
        _figure(series, shown, args.figure)
        print(f"\nwrote {args.figure}")
    if args.json:
        args.json.write_text(json.dumps({"selected": cmp.selected, "table": rows, "windows_s": WINDOWS_S,
                                         "window_rms_c": windows, "total_s": wall}, indent=1,
                                        default=lambda o: o.item() if hasattr(o, "item") else str(o)))


def _figure(series, shown, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, len(shown), figsize=(4.2 * len(shown), 6.2), sharex=True, sharey="row",
                             constrained_layout=True)
    for j, lab in enumerate(shown):
        for i, mat in enumerate(("metal", "wood")):
            ax = axes[i, j]
            rs = [(t, r) for m, t, r in series[lab] if m == mat]
            t = rs[0][0]
            R = np.array([r for _, r in rs])
            for r in R:
                ax.plot(t, r, lw=0.4, alpha=0.35, color="tab:blue")
            ax.plot(t, np.sqrt(np.mean(R ** 2, axis=0)), color="tab:red", lw=1.8, label="RMS over touches")
            ax.plot(t, R.mean(axis=0), color="k", lw=1.2, label="mean")
            ax.axvline(0.0, color="0.5", lw=0.8)
            ax.axhline(0.0, color="0.5", lw=0.5)
            ax.set_title(f"{lab}\n{mat}: held-out RMS {np.sqrt(np.mean(R ** 2)):.4f} °C", fontsize=9)
            if j == 0:
                ax.set_ylabel("prediction − reading [°C]")
            if i == 1:
                ax.set_xlabel("time after detected onset [s]")
    axes[0, 0].legend(fontsize=8, loc="lower right")
    fig.suptitle("Held-out residuals (fit on trial sets 1-4, scored on 5-20), shared robot recordings", fontsize=10)
    fig.savefig(path, dpi=90)


if __name__ == "__main__":
    main()
