"""designkit's predictions against the real robot (issue 34): calibrate on some trial sets, compare on the others.

Run from the repository root (several minutes on the shared 2 cores; be nice)::

    nice -n 10 python benchmarks/bench_real_prediction.py [--candidate NAME] [--json out.json]

1. Calibration as ``designkit calibrate fit`` does by default: the metal and wood touches split by
   :func:`~designkit.calibration.identify.choose_split` (the first fifth of the trial sets fitted:
   sets 1-4 of the shared recordings' 20), every candidate fitted and the one chosen on the held-out
   touches (``--candidate NAME`` fits that one only), its sensor file with the rig's conditions
   (:mod:`designkit.rig`: noise, dT, the model's start relative to the detected onset).
2. Prediction for the rig as calibrated: the paper's SVM F1 of the identified aluminium against the
   identified wood (their e_o, classes [e, e + 80)) at contact times counted from the detected onset
   (the exact route, the file's model, noise and dT), and the min-contact with its interval.
3. Reality: the paper's protocol on the real touches of the *other* trial sets (never used by
   calibration), each cut after its detected onset (samples 0 .. c): features and SVM as the paper,
   3 folds x ``--repeats`` shuffles (:func:`designkit_lab.reproduce.robot.real_pair_f1`); the real
   min-contact is where that F1 first reaches 0.9 on a 0.05 s grid (linear between grid points).

Printed: contact time, predicted F1 with its interval, real F1 with its SD, the error; the
predicted and real min-contact; the targets (real min-contact inside the predicted 90 % interval or
within 25 %; predicted F1 within 0.05 of the real one at every contact time from 0.25 to 1.5 s).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

from designkit import query
from designkit.calibration.fit import resolve_ranges
from designkit.calibration.identify import CANDIDATES, choose_split, compare_models
from designkit.calibration.trials import load_index
from designkit.models import sensor_model
from designkit.rig import from_model_contact, model_start_s, resolve_scene

RANGES = {"metal": "aluminium"}
CONTACTS_S = (0.25, 0.5, 0.75, 1.0, 1.25, 1.5)


def _default_data() -> Path:
    env = os.environ.get("DESIGNKIT_ROBOT_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "shared" / "data" / "robot-thermal-recordings"


def real_f1_curve(data: Path, test_files: set[str], contacts, repeats: int, seed: int) -> list[dict]:
    """The real rig's SVM F1 (wood vs metal) on the test touches cut at each contact after the onset."""
    import dataclasses

    from designkit_lab.reproduce.robot import load_real, real_pair_f1

    touches = load_real(data, contact_s=float(max(contacts)))
    touches = touches.select(np.array([Path(f).name in test_files for f in touches.files]))
    fs = 1.0 / float(touches.time_s[1] - touches.time_s[0])
    out = []
    for c in contacts:
        k = int(round(float(c) * fs)) + 1          # samples 0 .. c after the detected onset
        cut = dataclasses.replace(touches, time_s=touches.time_s[:k], sensor_c=touches.sensor_c[:, :k])
        out.append({"contact_s": float(c), **real_pair_f1(cut, ("wood", "metal"), repeats=repeats, seed=seed)})
    return out


def crossing(xs, ys, level: float = 0.9) -> float | None:
    """First x where y reaches ``level`` (linear between points); None if never."""
    for i, y in enumerate(ys):
        if y >= level:
            if i == 0:
                return float(xs[0])
            x0, x1, y0, y1 = xs[i - 1], xs[i], ys[i - 1], ys[i]
            return float(x0 + (level - y0) * (x1 - x0) / (y1 - y0))
    return None


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=_default_data())
    ap.add_argument("--candidate", default=None, help="fit this candidate only (default: choose as calibrate does)")
    ap.add_argument("--repeats", type=int, default=10, help="real F1: shuffles of the 3-fold CV")
    ap.add_argument("--trials", type=int, default=100, help="predicted F1: simulated touches per class")
    ap.add_argument("--sim-repeats", type=int, default=4, help="predicted F1: seeds per evaluation")
    ap.add_argument("--no-min-contact", action="store_true", help="skip the predicted min-contact (minutes)")
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args()
    t0 = time.perf_counter()
    index = args.data / "index.csv"
    trials = load_index(index, only=["metal", "wood"])
    split = choose_split(trials, index)
    ranges = resolve_ranges(["metal", "wood"], RANGES)
    cands = CANDIDATES if args.candidate is None else [args.candidate]
    cmp = compare_models(list(split.fit), list(split.held_out), cands, ranges=ranges)
    best = next(r for r in cmp.results if r.candidate.label == cmp.selected)
    sen = best.sensor(name="rig")
    fm = sensor_model(sen)
    start = model_start_s(sen)
    scene = resolve_scene(sen, {"noise_c": None, "delta_t_c": None})
    noise, dt = scene.values["noise_c"], scene.values["delta_t_c"]
    es = best.effusivity.value
    e_wood, e_metal = best.ratios["wood"].value * es, best.ratios["metal"].value * es
    print(f"calibration: {split.describe()}; selected {cmp.reason} ({time.perf_counter() - t0:.0f} s)")
    print(f"rig as calibrated: noise {noise:.4f} °C ({scene.sources['noise_c']}), dT {dt:.3f} °C, model start "
          f"{start:+.3f} s from the detected onset; e_o wood {e_wood:.0f}, metal {e_metal:.0f}, e_s {es:.0f}")

    test_files = {Path(tr.source).name for tr in split.held_out}
    grid = np.round(np.arange(0.05, 1.5001, 0.05), 3)
    t1 = time.perf_counter()
    real = real_f1_curve(args.data, test_files, grid, args.repeats, seed=0)
    real_min = crossing(grid, [r["f1"] for r in real])
    print(f"real SVM F1 on {len(test_files)} held-out touches, 3 folds x {args.repeats} ({time.perf_counter() - t1:.0f} s)")

    rows = []
    for c in CONTACTS_S:
        t2 = time.perf_counter()
        ans = query.ask("distinguishable", route="exact", e1=e_wood, e2=e_metal, contact_s=c - start, noise_c=noise,
                        delta_t_c=dt, sensor=sen, model=fm, trials=args.trials, repeats=args.sim_repeats, seed=0,
                        jobs=1)
        f1 = ans.details["svm_f1"]
        r = next(x for x in real if abs(x["contact_s"] - c) < 1e-9)
        rows.append({"contact_s": c, "model_contact_s": c - start, "predicted_f1": f1,
                     "predicted_interval": [ans.interval[0], ans.interval[1]], "ideal_f1": ans.ideal_bound.value,
                     "real_f1": r["f1"], "real_f1_sd": r["f1_sd"], "error": f1 - r["f1"],
                     "wall_s": time.perf_counter() - t2})
        print(f"  contact {c:4.2f} s from onset: predicted F1 {f1:.3f} [{ans.interval[0]:.3f}, {ans.interval[1]:.3f}], "
              f"real {r['f1']:.3f} ± {r['f1_sd']:.3f}, error {f1 - r['f1']:+.3f}  ({rows[-1]['wall_s']:.0f} s)")
    pred = None
    if not args.no_min_contact:
        t3 = time.perf_counter()
        mc = query.ask("min-contact", route="exact", e1=e_wood, e2=e_metal, noise_c=noise, delta_t_c=dt, sensor=sen,
                       model=fm, trials=args.trials, repeats=args.sim_repeats, seed=0, jobs=1, max_contact_s=5.0)
        pred = {"value": from_model_contact(mc.value, start),
                "interval": [from_model_contact(v, start) for v in mc.interval],
                "wall_s": time.perf_counter() - t3}
        print(f"min-contact from the onset: predicted {pred['value']} (90 % interval {pred['interval']}), real "
              f"{real_min}  ({pred['wall_s']:.0f} s)")
    worst = max(abs(r["error"]) for r in rows)
    inside = None
    if pred is not None and pred["value"] is not None and real_min is not None:
        lo, hi = pred["interval"]
        inside = (lo is not None and hi is not None and lo <= real_min <= hi) or \
            abs(pred["value"] - real_min) <= 0.25 * real_min
    print(f"targets: |predicted - real F1| <= 0.05 at every contact 0.25-1.5 s: worst {worst:.3f} "
          f"({'met' if worst <= 0.05 else 'missed'}); real min-contact inside the interval or within 25 %: "
          f"{inside}; total {time.perf_counter() - t0:.0f} s, load {os.getloadavg()[0]:.1f}")
    if args.json:
        args.json.write_text(json.dumps({"split": split.to_dict(), "selected": cmp.selected, "reason": cmp.reason,
                                         "conditions": sen.conditions, "e_o": {"wood": e_wood, "metal": e_metal},
                                         "rows": rows, "real_curve": real, "real_min_contact_s": real_min,
                                         "predicted_min_contact": pred}, indent=1, default=float))


if __name__ == "__main__":
    main()
