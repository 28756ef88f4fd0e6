"""Is the exact route's crossing fit biased where the F1 curve is logit-linear? Curvature term against the line.

Issue 34 gave :func:`designkit.query.crossing.estimate_crossing` a curvature term (the rig's F1 bends through
the threshold and the straight line answered early). Where the curve has no bend the quadratic should cost only
variance, not bias: this replays both fits on the same synthetic logit-linear curves (the coverage benchmark's
known truth: slope 2-8 in log x, crossings 0.5-5, the SVM's binomial F1 error at 100 touches per class), with
the answer's 4 seeds and the reference's 16, and prints the signed median and mean log error, the median
absolute log error and the 90 % intervals' coverage of the true crossing.

A shift between two fits of the same evaluations that is one-signed on real curves (the coverage benchmark's
references, 16 seeds, the same seeds in both runs) then says the curve bends, not that the fit is biased.

Run from the repository root (about a minute of CPU)::

    python benchmarks/bench_crossing_fit_synthetic.py
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from designkit.query.crossing import estimate_crossing
from designkit.recognition.svm import f1_standard_error


def replay(curvature: bool, *, n: int, seed: int, repeats: int, trials: int = 100) -> tuple[float, ...]:
    """(signed median, mean, median |log error|, coverage) of ``n`` crossings."""
    rng = np.random.default_rng(seed)
    errs, held = [], []
    for _ in range(n):
        k = rng.uniform(2.0, 8.0)
        x_star = float(np.exp(rng.uniform(math.log(0.5), math.log(5.0))))
        x50 = x_star / 4.0 ** (1.0 / k)   # 0.5 + 0.5 p = 0.9 at x*
        draws_rng = np.random.default_rng(rng.integers(2 ** 31))   # the same draws for both fits

        def f(x, k=k, x50=x50, draws_rng=draws_rng):
            m = 0.5 + 0.5 / (1.0 + (x / x50) ** -k)
            se1 = f1_standard_error(min(1.0, m), max(0.0, 1.0 - m), trials)
            draws = np.clip(m + se1 * draws_rng.standard_normal(repeats), 0.0, 1.0)
            return float(draws.mean()), max(se1, float(np.std(draws, ddof=1))) / math.sqrt(repeats)

        e = estimate_crossing(f, 0.05, 10.0, 0.9, curvature=curvature)
        if e.value is None:
            continue
        errs.append(math.log(e.value / x_star))
        held.append((e.low or 0.0) <= x_star <= (e.high or math.inf))
    a = np.array(errs)
    return float(np.median(a)), float(a.mean()), float(np.median(np.abs(a))), float(np.mean(held))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=600)
    ap.add_argument("--seed", type=int, default=5)
    a = ap.parse_args(argv)
    print(f"{a.n} logit-linear curves, seed {a.seed}: log error of the crossing [signed median, mean, median |.|], "
          "coverage of the 90 % interval")
    for repeats in (4, 16):
        for curvature in (False, True):
            med, mean, mad, cov = replay(curvature, n=a.n, seed=a.seed, repeats=repeats)
            print(f"  {repeats:2d} seeds, {'curvature term' if curvature else 'straight line '}: "
                  f"{med:+.2%} {mean:+.2%} {mad:.2%}  coverage {cov:.1%}")


if __name__ == "__main__":
    main()
