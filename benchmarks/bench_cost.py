"""The sweep engine's cost curves: wall time, SVM fits and peak memory against the size of the work.

Run from the repository root::

    /work/venv/bin/python benchmarks/bench_cost.py                  # the report's quick curves (about 20 s)
    /work/venv/bin/python benchmarks/bench_cost.py --full           # the full report's curves
    /work/venv/bin/python benchmarks/bench_cost.py --curve "ideal: intervals" --json cost.json

Each curve runs in a fresh process (``designkit_lab.accuracy.cost_curves``), one
scene point per size; printed: the sizes, wall times, SVM fits, peak memory
above the process after its imports, and the exponents ``p`` of
``cost ~ size^p`` by log-log least squares. The expectation the ideal engine
was built for, time about linear in the number of intervals (``p`` near 1,
and under 2: no pair matrix), is printed beside the measured exponent with
its verdict; it is a measurement on this machine at this load, not a test
(timings on shared cores vary by tens of percent).
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

from designkit_lab.accuracy import cost_curve_specs, cost_curves, curves_markdown

#: Curve name -> (what the design expects of the time exponent, lower, upper bound).
EXPECTED = {"ideal: intervals": ("about linear in intervals (staircase, no pair matrix)", 0.3, 2.0)}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--full", action="store_true", help="the full report's curves (larger sizes)")
    p.add_argument("--curve", action="append", default=None, help="only this curve (repeatable; default all)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", type=Path, default=None, help="also write the curves to this JSON file")
    args = p.parse_args(argv)
    names = [s[0] for s in cost_curve_specs(not args.full, args.seed)]
    unknown = sorted(set(args.curve or ()) - set(names))
    if unknown:
        p.error(f"unknown curve(s) {', '.join(unknown)}: choose from {', '.join(names)}")
    curves = cost_curves(not args.full, args.seed, only=args.curve,
                         progress=lambda m: print(f"  {m} ...", flush=True))
    print("\n" + curves_markdown(curves) + "\n")
    for c in curves:
        if c.name in EXPECTED:
            what, lo, hi = EXPECTED[c.name]
            ok = math.isfinite(c.time_exponent) and lo < c.time_exponent < hi
            print(f"{c.name}: time exponent {c.time_exponent:.2f}; expected {what}, {lo:g} < p < {hi:g}: "
                  f"{'as expected' if ok else 'OUTSIDE the expected range'}")
    if args.json:
        args.json.write_text(json.dumps([c.to_dict() for c in curves], indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
