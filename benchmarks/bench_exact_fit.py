"""The exact route's crossing fit before and after a change, on the same SVM evaluations (paper sensor by default).

Every exact crossing (min-contact, max-noise, min-delta-t, delta-e) is estimated by
:func:`designkit.query.crossing.estimate_crossing`: a bisection and a design of SVM evaluations, then a fit. The
evaluations asked depend only on their means, not on the fit or its errors, so each question is computed once with
this tree and every estimate it makes is fitted again the way before on the same evaluations:

* ``--compare errors`` (default): each evaluation's own error (the larger of its seeds' own CV errors and their
  spread, over sqrt(n), the normal quantile) against the pooled error model of issue 34
  (:func:`designkit.query.crossing.pooled_seed_scale`, Student's t);
* ``--compare curvature``: the straight line alone (``curvature=False``) against the curvature fit.

Printed per question: both estimates with their 90 % intervals (the crossing estimate, before the route clips it at
the ideal observer), how far the answer moved, and whether the new estimate lies inside the old interval.

``--coverage-cases FILE`` recomputes the first ``--take`` min-contact cases of a coverage run
(designkit_lab.accuracy.coverage's cases: the answer with 4 seeds from ``1000 + index``, sklearn; the reference with
16 seeds from ``500000 + index``, batched) and scores both fits' intervals against the reference fitted the same
way: coverage, the spread of ``(answer - reference) / sqrt(sd_answer^2 + sd_reference^2)`` (1 when calibrated;
a calibrated 90 % interval holds a reference with half its error 85.9 % of the time) and the median relative width.

Run from the repository root (about half a minute of CPU per question, sklearn solver as ``--exact``)::

    nice -n 5 python benchmarks/bench_exact_fit.py --cases 8 --seed 45
    nice -n 5 python benchmarks/bench_exact_fit.py --coverage-cases benchmarks/results/coverage_curvature_cases.jsonl --take 10
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import time

import numpy as np


def draw_cases(n: int, seed: int) -> list[dict]:
    """Random questions for the paper sensor: min-contact at noise 0.01-0.1 degC (dT 10), and every fourth a
    max-noise at a contact of 1-4 s and every fourth a delta-e at 2 s."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        lo = float(np.exp(rng.uniform(np.log(300.0), np.log(30000.0))))
        hi = min(lo * float(np.exp(rng.uniform(np.log(1.05), np.log(2.0)))), 39000.0)
        noise = float(rng.choice([0.01, 0.05, 0.1]))
        q = "max-noise" if i % 4 == 1 else "delta-e" if i % 4 == 3 else "min-contact"
        out.append({"question": q, "e1": round(lo, 1), "e2": round(hi, 1), "noise_c": noise,
                    "contact_s": round(float(rng.uniform(1.0, 4.0)), 2)})
    return out


def main() -> None:
    from designkit.query import crossing, exact

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cases", type=int, default=8)
    p.add_argument("--seed", type=int, default=45)
    p.add_argument("--solver", default="sklearn")
    p.add_argument("--jobs", type=int, default=1)
    p.add_argument("--compare", choices=("errors", "curvature"), default="errors")
    p.add_argument("--coverage-cases", default=None, help="a coverage run's cases (JSON lines): recompute min-contact ones")
    p.add_argument("--take", type=int, default=10, help="--coverage-cases: how many")
    p.add_argument("--skip", type=int, default=0, help="--coverage-cases: after the first this many")
    args = p.parse_args()
    real = crossing.estimate_crossing
    fits: list = []

    def own(r):  # an evaluation with its own error only (the error model before the pooled one)
        return (r.mean, r.standard_error()) if isinstance(r, crossing.SeedDraws) else r

    def both(f, *a, **kw):  # the route's own estimate, and the fit before on the same evaluations
        seen: dict = {}

        def rec(x):
            seen[x] = f(x)
            return seen[x]

        new = real(rec, *a, **kw)
        before = {"curvature": False} if args.compare == "curvature" else {}
        old = real((lambda x: seen[x]) if args.compare == "curvature" else (lambda x: own(seen[x])), *a,
                   **{**kw, "progress": None, **before})
        fits.append((old, new))
        return new

    crossing.estimate_crossing = both  # the exact route imports it at call time
    if args.coverage_cases:
        coverage_cases(args, exact, fits)
        return
    moved, inside, held_new = [], 0, 0
    print(f"load {os.getloadavg()[0]:.1f}", flush=True)
    for i, c in enumerate(draw_cases(args.cases, args.seed)):
        fits.clear()
        t0 = time.process_time()
        common = dict(noise_c=c["noise_c"], solver=args.solver, jobs=args.jobs, seed=i)
        if c["question"] == "min-contact":
            exact.exact_min_contact(c["e1"], c["e2"], **common)
            what = f"min-contact {c['e1']:g} vs {c['e2']:g} at {c['noise_c']:g} degC"
        elif c["question"] == "max-noise":
            exact.exact_max_noise(c["e1"], c["e2"], contact_s=c["contact_s"], solver=args.solver, jobs=args.jobs, seed=i)
            what = f"max-noise {c['e1']:g} vs {c['e2']:g} at {c['contact_s']:g} s"
        else:
            exact.exact_delta_e(c["e1"], contact_s=2.0, **common)
            what = f"delta-e at {c['e1']:g}, 2 s, {c['noise_c']:g} degC"
        for old, new in fits:
            if old.value is None or new.value is None or not (old.stated and new.stated):
                print(f"{what}: old {old.value} ({old.method}), new {new.value} ({new.method})", flush=True)
                continue
            m = math.log(new.value / old.value)
            moved.append(m)
            ins = old.low <= new.value <= old.high
            inside += ins
            width = math.log(new.high / new.low) / math.log(old.high / old.low)
            print(f"{what}: old {old.value:.4g} [{old.low:.4g}, {old.high:.4g}], new {new.value:.4g} "
                  f"[{new.low:.4g}, {new.high:.4g}]: moved {m:+.1%}, width x{width:.2f}, "
                  f"{'inside' if ins else 'OUTSIDE'} the old interval ({time.process_time() - t0:.0f} CPU s)",
                  flush=True)
    if moved:
        print(f"{len(moved)} estimates: {inside} inside their old interval; moved median "
              f"{statistics.median(moved):+.1%}, median |moved| {statistics.median(abs(m) for m in moved):.1%}, largest {max(moved, key=abs):+.1%}")


def coverage_cases(args, exact, fits: list) -> None:
    """Recompute min-contact cases of a coverage run, answer and reference, and score both fits (module doc)."""
    rows = [json.loads(line) for line in open(args.coverage_cases)]
    cases = [r for r in rows if r["question"] == "min-contact" and r["exact"].get("coverage")
             and r["reference"].get("coverage")][args.skip:args.skip + args.take]
    z90 = 1.6448536269514722
    out: dict = {"old": [], "new": []}
    print(f"load {os.getloadavg()[0]:.1f}; {len(cases)} min-contact cases of {args.coverage_cases}", flush=True)
    for c in cases:
        t0 = time.process_time()
        common = dict(noise_c=c["noise_c"], delta_t_c=c["delta_t_c"], trials=100, jobs=1, coverage=0.9)
        fits.clear()
        exact.exact_min_contact(c["e1"], c["e2"], seed=1000 + c["index"], repeats=4, solver="sklearn", **common)
        answer = fits[-1]
        fits.clear()
        exact.exact_min_contact(c["e1"], c["e2"], seed=500000 + c["index"], repeats=16, solver="batched", **common)
        ref = fits[-1]
        line = f"case {c['index']:3d} {c['e1']:g} vs {c['e2']:g} at {c['noise_c']:g} degC:"
        for k, a, r in (("old", answer[0], ref[0]), ("new", answer[1], ref[1])):
            if not (a.stated and r.stated):
                line += f" {k} {a.value} ({a.method}) ref {r.value} ({r.method});"
                continue
            sa, sr = (math.log(e.high / e.low) / (2 * z90) for e in (a, r))
            held = a.low <= r.value <= a.high
            out[k].append((held, math.log(a.value / r.value) / math.hypot(sa, sr), (a.high - a.low) / a.value))
            line += (f" {k} {a.value:.4g} [{a.low:.4g}, {a.high:.4g}] ref {r.value:.4g} "
                     f"{'held' if held else 'MISSED'}{'' if k == 'new' else ' |'}")
        print(f"{line} ({time.process_time() - t0:.0f} CPU s)", flush=True)
    for k, label in (("old", "each evaluation's own error (before)"), ("new", "pooled error (now)")):
        if out[k]:
            h, z, w = (np.array(v) for v in zip(*out[k]))
            print(f"{label}: {int(h.sum())} of {h.size} intervals hold the reference ({h.mean():.0%}; 85.9 % if "
                  f"calibrated), z sd {z.std():.2f}, median relative width {np.median(w):.1%}")


if __name__ == "__main__":
    main()
