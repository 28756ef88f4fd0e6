"""Is the exact route's crossing fit biased, and do its intervals cover? Synthetic curves and the rig's real draws.

Issue 34 gave :func:`designkit.query.crossing.estimate_crossing` a curvature term (the rig's F1 bends through
the threshold and the straight line answered early). Where the curve has no bend the quadratic should cost only
variance, not bias: this replays both fits on the same synthetic logit-linear curves (the coverage benchmark's
known truth: slope 2-8 in log x, crossings 0.5-5, the SVM's binomial F1 error at 100 touches per class), with
the answer's 4 seeds and the reference's 16, and prints the signed median and mean log error, the median
absolute log error and the 90 % intervals' coverage of the true crossing.

A shift between two fits of the same evaluations that is one-signed on real curves (the coverage benchmark's
references, 16 seeds, the same seeds in both runs) then says the curve bends, not that the fit is biased.

``--rig-truth FILE`` (benchmarks/results/sensor_table_truth.jsonl: fresh seeds' F1 and own CV errors at 7 contacts
of 10 rig pairs, 16-32 seeds each) measures the error model instead (issue 34):

1. how far the seeds' F1 scatter beyond their own CV errors (pooled, and by F1);
2. the exact route's stored evaluations of those pairs (``--evaluations``) against the truth's mean F1 at the same
   contact: z in the truth's error and in the error the route stated;
3. replays of the estimator on each pair's curve (a complementary log-log quadratic in log contact through the
   truth's means, continued by its end slopes), each evaluation 4 seeds resampled with their own CV errors from
   the nearest measured contact (residuals scaled with sqrt(1 - F1)), searched from 0.7 x* to 10 x*: the error
   model before (each evaluation's own error, the normal quantile) and the pooled one, on the same draws.

Run from the repository root (about a minute of CPU each)::

    python benchmarks/bench_crossing_fit_synthetic.py
    python benchmarks/bench_crossing_fit_synthetic.py --rig-truth benchmarks/results/sensor_table_truth.jsonl
"""

from __future__ import annotations

import argparse
import json
import math
from collections import defaultdict

import numpy as np

from designkit.query.crossing import SeedDraws, estimate_crossing
from designkit.recognition.svm import f1_standard_error


def replay(curvature: bool, *, n: int, seed: int, repeats: int, trials: int = 100,
           pooled: bool = True) -> tuple[float, ...]:
    """(signed median, mean, median |log error|, coverage) of ``n`` crossings; each seed with its own error (the
    route's pooled error model), or with ``pooled=False`` each evaluation's own error (the model before)."""
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
            d = SeedDraws(draws, [f1_standard_error(v, 1.0 - v, trials) for v in draws])
            return d if pooled else (d.mean, d.standard_error())

        e = estimate_crossing(f, 0.05, 10.0, 0.9, curvature=curvature)
        if e.value is None:
            continue
        errs.append(math.log(e.value / x_star))
        held.append((e.low or 0.0) <= x_star <= (e.high or math.inf))
    a = np.array(errs)
    return float(np.median(a)), float(a.mean()), float(np.median(np.abs(a))), float(np.mean(held))


def _cloglog(m):
    p = np.clip(2.0 * np.asarray(m, dtype=np.float64) - 1.0, 1e-9, 1.0 - 1e-9)
    return np.log(-np.log(1.0 - p))


def truth_draws(path: str) -> dict:
    """``{pair: {contact_s: (F1 per seed, own CV error per seed)}}`` of a truth file."""
    by: dict = defaultdict(lambda: defaultdict(lambda: ([], [])))
    for line in open(path):
        r = json.loads(line)
        f1, se = by[r["index"]][r["contact_model_s"]]
        f1.extend(r["f1"])
        se.extend(r["fold_se"])
    return {i: {c: (np.array(f), np.array(s)) for c, (f, s) in cs.items()} for i, cs in by.items()}


def smooth_curve(contacts, means, counts):
    """A mean F1 curve through measured means: cloglog(2 F1 - 1) quadratic in log contact (weighted by seeds),
    continued by its end slopes; returns ``(curve, its crossing of 0.9)``."""
    from scipy.optimize import brentq

    u = np.log(contacts)
    c = np.polyfit(u, _cloglog(means), 2, w=np.sqrt(counts))
    dc = np.polyder(c)

    def curve(x: float) -> float:
        v = math.log(x)
        e = min(max(v, u.min()), u.max())
        eta = np.polyval(c, e) + np.polyval(dc, e) * (v - e)
        return 0.5 + 0.5 * (1.0 - math.exp(-math.exp(min(eta, 30.0))))

    return curve, brentq(lambda x: curve(x) - 0.9, contacts[0] * 0.5, contacts[-1] * 2.0)


def rig_truth(path: str, evaluations: str | None, n: int, seed: int) -> None:
    """The error model measured on the rig's fresh-seed draws (module doc, ``--rig-truth``)."""
    truth = truth_draws(path)
    cells = [(f.size, f.mean(), f.var(ddof=1), float(np.mean(s ** 2))) for cs in truth.values() for f, s in cs.values()]
    n_, m_, v_, w_ = (np.array(a) for a in zip(*cells))
    print(f"1. seeds' F1 against their own CV errors: {len(cells)} contacts of {len(truth)} pairs, {int(n_.sum())} seeds")
    for lo, hi in ((0.75, 0.85), (0.85, 0.9), (0.9, 0.93), (0.93, 0.96), (0.96, 0.99), (0.75, 0.99)):
        k = (m_ >= lo) & (m_ < hi)
        print(f"   F1 {lo:.2f}-{hi:.2f}: {int(k.sum()):2d} contacts, seed sd / own error "
              f"{math.sqrt(np.sum((n_ - 1) * v_ / w_ * k) / np.sum((n_ - 1) * k)):.2f} (pooled as the route pools)")
    if evaluations:
        z_true, z_stated, ratio = [], [], []
        for row in map(json.loads, open(evaluations)):
            cs = truth.get(row["index"])
            if not cs:
                continue
            xs = np.array(sorted(cs))
            curve, _ = smooth_curve(xs, np.array([cs[c][0].mean() for c in xs]), np.array([cs[c][0].size for c in xs]))
            sds = np.array([cs[c][0].std(ddof=1) for c in xs])
            for e in row["exact"]["evaluations"]:
                x = e["contact_s"]
                if 0.97 * xs[0] <= x <= 1.03 * xs[-1]:
                    se_true = float(np.interp(math.log(x), np.log(xs), sds)) / 2.0
                    z_true.append((e["svm_f1"] - curve(x)) / se_true)
                    z_stated.append((e["svm_f1"] - curve(x)) / e["standard_error"])
                    ratio.append(e["standard_error"] / se_true)
        zt, zs, r = np.array(z_true), np.array(z_stated), np.array(ratio)
        print(f"2. the route's {zt.size} stored evaluations inside the truth's contacts: rms z {np.sqrt(np.mean(zt ** 2)):.2f} "
              f"in the truth's error, {np.sqrt(np.mean(zs ** 2)):.2f} in the stated one; stated / true error "
              f"{r.min():.2f}-{r.max():.2f} (median {np.median(r):.2f}, sd of its log {np.std(np.log(r)):.2f}); "
              f"largest |z| {np.abs(zt).max():.1f}")
    print(f"3. replays, {n} searches a pair (4 seeds an evaluation; same draws for both error models):")
    res: dict = {"before": [], "pooled": []}
    for i, cs in sorted(truth.items()):
        xs = np.array(sorted(cs))
        F, S = [cs[c][0] for c in xs], [cs[c][1] for c in xs]
        ms = np.array([f.mean() for f in F])
        curve, x_star = smooth_curve(xs, ms, np.array([f.size for f in F]))
        line = f"   pair {i:2d}, x* {x_star:.3f} s (model time):"
        for mode in res:
            rng = np.random.default_rng(seed + i)

            def f(x, rng=rng, mode=mode, curve=curve, xs=xs, F=F, S=S, ms=ms):
                k = int(np.argmin(np.abs(np.log(xs) - math.log(x))))
                m = curve(x)
                scale = math.sqrt(max(1.0 - m, 1e-6) / max(1.0 - ms[k], 1e-6))
                j = rng.integers(F[k].size, size=4)
                d = SeedDraws(np.minimum(m + (F[k][j] - ms[k]) * scale, 1.0), S[k][j] * scale)
                return d if mode == "pooled" else (d.mean, d.standard_error())

            out = []
            for _ in range(n):
                e = estimate_crossing(f, 0.7 * x_star, 10.0 * x_star, 0.9)
                if e.low is not None and e.high is not None:
                    out.append((e.low <= x_star <= e.high, math.log(e.value / x_star), math.log(e.high / e.low)))
            res[mode] += out
            h, err, w = (np.array(v) for v in zip(*out))
            line += f" {mode} held {h.mean():.0%} err sd {err.std():.2%} width {np.median(w):.1%} |"
        print(line.rstrip(" |"), flush=True)
    for mode, out in res.items():
        h, err, w = (np.array(v) for v in zip(*out))
        print(f"   {mode}: {h.mean():.1%} of {h.size} intervals held x*; log error median {np.median(err):+.2%}, "
              f"sd {err.std():.2%}; median width (log high/low) {np.median(w):.2%}; error / stated sd: sd "
              f"{np.std(err / (w / 2 / 1.6448536)):.2f}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=600)
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--rig-truth", default=None, help="a truth file of fresh-seed draws (module doc)")
    ap.add_argument("--evaluations", default="benchmarks/results/sensor_table_exact_evaluations.jsonl",
                    help="--rig-truth: the route's stored evaluations of those pairs")
    a = ap.parse_args(argv)
    if a.rig_truth:
        rig_truth(a.rig_truth, a.evaluations, min(a.n, 150), a.seed)
        return
    print(f"{a.n} logit-linear curves, seed {a.seed}: log error of the crossing [signed median, mean, median |.|], "
          "coverage of the 90 % interval")
    for repeats in (4, 16):
        for curvature, pooled in ((False, True), (True, False), (True, True)):
            med, mean, mad, cov = replay(curvature, n=a.n, seed=a.seed, repeats=repeats, pooled=pooled)
            print(f"  {repeats:2d} seeds, {'curvature term' if curvature else 'straight line '}, "
                  f"{'pooled error' if pooled else 'own error   '}: {med:+.2%} {mean:+.2%} {mad:.2%}  coverage {cov:.1%}")


if __name__ == "__main__":
    main()
