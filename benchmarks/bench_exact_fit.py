"""The exact route's crossing fit before and after issue 34, on the same SVM evaluations (paper sensor by default).

Every exact crossing (min-contact, max-noise, min-delta-t, delta-e) is estimated by
:func:`designkit.query.crossing.estimate_crossing`: a bisection and a design of SVM evaluations, then a fit. Issue 34
added a curvature term to the fit; the evaluations asked do not depend on the fit, so each question is computed
once with this tree and every estimate it makes is fitted again with the straight line alone (``curvature=False``,
the estimator before) on the same evaluations. Printed per question: both estimates with their 90 % intervals
(the crossing estimate, before the route clips it at the ideal observer), how far the answer moved, and whether
the new estimate lies inside the old interval.

Run from the repository root (about half a minute of CPU per question, sklearn solver as ``--exact``)::

    nice -n 5 python benchmarks/bench_exact_fit.py --cases 8 --seed 45
"""

from __future__ import annotations

import argparse
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
    args = p.parse_args()
    real = crossing.estimate_crossing
    fits: list = []

    def both(f, *a, **kw):  # the route's own estimate, and the straight line on the same evaluations
        seen: dict = {}

        def rec(x):
            seen[x] = f(x)
            return seen[x]

        new = real(rec, *a, **kw)
        old = real(lambda x: seen[x], *a, **{**kw, "progress": None, "curvature": False})
        fits.append((old, new))
        return new

    crossing.estimate_crossing = both  # the exact route imports it at call time
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


if __name__ == "__main__":
    main()
