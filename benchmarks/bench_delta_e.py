"""delta(e) for every reference at one scene: staircase search against the full matrix loop (issue 3 target).

Run from the repository root::

    /work/venv/bin/python benchmarks/bench_delta_e.py            # 40, 80, 120 intervals (about 1 h on 1 core)
    /work/venv/bin/python benchmarks/bench_delta_e.py --quick    # 20, 40 intervals (a few minutes)
    /work/venv/bin/python benchmarks/bench_delta_e.py --intervals 40 80 --contact 2

The full F1 matrix (every pair of intervals, the paper's 124,750-pair loop at
500 intervals) is affordable only on coarse grids; on each, both routes run in
the same process with the same per-pair seeds, so every pair the staircase
scores has exactly the F1 the matrix gives it. Printed for each grid: SVM
fits and wall time of both, the ratios, and whether the two agree on delta(e)
within one interval for every reference in both directions. Then the growth
with the number of intervals: exponents of fits and time by log-log least
squares (the matrix ~2 by construction; the staircase close to 1), and what
the fitted laws predict at the paper's 500 intervals. When ``tables/svm-paper``
exists, its own measured fits and compute time per scene (from its header) are
printed beside that prediction.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from designkit_lab.accuracy import fit_exponent, staircase_vs_full


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="20 and 40 intervals")
    p.add_argument("--intervals", type=int, nargs="+", default=None, help="grids (default 40 80 120)")
    p.add_argument("--contact", type=float, default=1.0, help="contact time [s] (default 1)")
    p.add_argument("--noise-ratio", type=float, default=0.005, help="sigma/dT (default 0.005: 0.05 °C at 10 °C)")
    p.add_argument("--trials", type=int, default=100)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", type=Path, default=None, help="also write the numbers to this JSON file")
    args = p.parse_args(argv)
    sizes = args.intervals or ([20, 40] if args.quick else [40, 80, 120])

    rows = []
    for n in sizes:
        print(f"  {n} intervals ...", file=sys.stderr, flush=True)
        r = staircase_vs_full(n, contact_s=args.contact, noise_ratio=args.noise_ratio, trials=args.trials,
                              seed=args.seed)
        rows.append(r)
        print(f"  {n}: staircase {r['fits_staircase']} fits {r['wall_staircase_s']:.1f} s, full "
              f"{r['fits_full']} fits {r['wall_full_s']:.1f} s, max diff {r['max_diff_intervals']:g}",
              file=sys.stderr, flush=True)

    print(f"### delta(e) for all references at one scene: sigma/dT {args.noise_ratio:g}, contact "
          f"{args.contact:g} s, {args.trials} trials per interval, (0, 40000]\n")
    print("| intervals | pairs | full matrix: fits | time [s] | staircase: fits | time [s] | fewer fits | "
          "less time | max delta difference [intervals] | answers differing | matrix inside the staircase's "
          "MC interval |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        n = r["intervals"]
        print(f"| {n} | {r['pairs_full']} | {r['fits_full']} | {r['wall_full_s']:.1f} | {r['fits_staircase']} | "
              f"{r['wall_staircase_s']:.1f} | {r['fits_full'] / r['fits_staircase']:.1f}x | "
              f"{r['wall_full_s'] / r['wall_staircase_s']:.1f}x | {r['max_diff_intervals']:g} | "
              f"{r['n_differ']} of {2 * n} | {r['full_in_staircase_interval']} of {n} |")
    ok = all(r["max_diff_intervals"] <= 1 for r in rows)
    print(f"\nSame delta(e) within one interval for every reference and both directions: {ok}.")
    for r in rows:
        if r["differing_references"]:
            print(f"\n{r['intervals']} intervals, references whose first distinguishable partner differs "
                  f"(J: partner index; [J_lo, J_hi]: the staircase's Monte Carlo interval):\n")
            print("| reference i | centre | J staircase | J full matrix | J_lo | J_hi |\n|---|---|---|---|---|---|")
            for d in r["differing_references"]:
                print(f"| {d['i']} | {d['e_centre']:.0f} | {d['J_staircase']} | {d['J_full']} | {d['J_lo']} | "
                      f"{d['J_hi']} |")
    n = np.array([r["intervals"] for r in rows], dtype=float)
    out = {"rows": rows, "same_within_one_interval": ok}
    if len(rows) >= 2:
        ex = {k: fit_exponent(n, [r[k] for r in rows])
              for k in ("fits_full", "wall_full_s", "fits_staircase", "wall_staircase_s")}
        out["exponents"] = ex
        print(f"\nGrowth with the number of intervals n (log-log least squares over {', '.join(map(str, sizes))}):\n")
        print("| route | fits ~ n^p | time ~ n^p |\n|---|---|---|")
        print(f"| full matrix | {ex['fits_full']:.2f} | {ex['wall_full_s']:.2f} |")
        print(f"| staircase | {ex['fits_staircase']:.2f} | {ex['wall_staircase_s']:.2f} |")

        def predict(key):
            last = rows[-1]
            return last[key] * (500.0 / last["intervals"]) ** ex[key]

        per_fit = rows[-1]["wall_full_s"] / rows[-1]["fits_full"]
        pred = {"full_fits": 124750 * rows[-1]["fits_full"] / rows[-1]["pairs_full"],
                "full_wall_s": 124750 * rows[-1]["fits_full"] / rows[-1]["pairs_full"] * per_fit,
                "staircase_fits": predict("fits_staircase"), "staircase_wall_s": predict("wall_staircase_s")}
        out["prediction_500"] = pred
        print(f"\nAt 500 intervals (one scene, this contact): the full matrix needs {pred['full_fits']:.0f} fits "
              f"(124,750 pairs x the repeat rate measured at {rows[-1]['intervals']}), about "
              f"{pred['full_wall_s'] / 3600:.1f} h at {per_fit:.3f} s per fit; the staircase law predicts "
              f"{pred['staircase_fits']:.0f} fits and {pred['staircase_wall_s'] / 60:.1f} min "
              f"({pred['full_fits'] / pred['staircase_fits']:.0f}x fewer fits, "
              f"{pred['full_wall_s'] / pred['staircase_wall_s']:.0f}x less time).")
    try:
        from designkit.tables.store import load_table

        t = load_table("svm-paper")
        ax = t.axes
        i_r = int(np.argmin(np.abs(np.log(ax["noise_ratio"]) - np.log(args.noise_ratio))))
        i_c = int(np.argmin(np.abs(ax["contact_s"] - args.contact)))
        fits = int(t.arrays["fits"][i_r, i_c])
        run = t.header.get("stats", {}).get("run", {})
        walls = np.asarray(t.arrays["chunk_wall_s"] if "chunk_wall_s" in t.arrays  # tables before the timings moved
                           else run.get("chunk_wall_s", np.zeros(t.arrays["fits"].shape)))
        wall = float(walls[i_r, i_c])
        out["svm_paper"] = {"noise_ratio": float(ax["noise_ratio"][i_r]), "contact_s": float(ax["contact_s"][i_c]),
                            "fits": fits, "compute_s": wall}
        print(f"\nThe shipped svm-paper build at sigma/dT {ax['noise_ratio'][i_r]:g}, contact "
              f"{ax['contact_s'][i_c]:g} s (500 intervals, all references, both directions, with its Monte Carlo "
              f"interval staircases): {fits} SVM fits, {wall / 60:.1f} min of compute (header stats) against the "
              f"124,750-pair matrix: {124750 / max(fits, 1):.0f}x fewer fits.")
        per_scene = t.header.get("stats", {})
        print(f"Whole table: {per_scene.get('svm_fits_total')} fits, {(per_scene.get('compute_s_total') or run.get('compute_s_total', 0)) / 3600:.2f} "
              f"h of compute over {t.arrays['fits'].size} (scene, contact) points.")
    except Exception as exc:  # the table is optional here
        print(f"\n(svm-paper table not available: {exc})")
    if args.json is not None:
        from designkit._io import atomic_write_text

        atomic_write_text(args.json, json.dumps(out, indent=1, default=float) + "\n")


if __name__ == "__main__":
    main()
