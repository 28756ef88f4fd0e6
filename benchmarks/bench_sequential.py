"""Live sequential decisions against the fixed contact time reaching the same error rates (issue 17).

Run from the repository root::

    python benchmarks/bench_sequential.py --figure docs/decisions_times.png  # 10,000 touches per class, ~15 min
    python benchmarks/bench_sequential.py --touches 2000 --no-svm --no-optimal   # ~1 min

The paper's guideline pair (35,000 vs 20,000 J s^-1/2 K^-1 m^-2, classes 80 wide,
noise 0.05 degC, dT 10 degC, the paper's sensor at 200 Hz, fixed initial
conditions). For each requested error rate eps (the same on both classes):

- touches simulated by :func:`designkit.simulation.simulate_class` (seeded, 5 s),
  fed to :func:`designkit.recognition.sequential.run_batch` (identical to the
  per-sample object, tested); printed: the error rate on each class with its
  95 % Clopper-Pearson interval, undecided touches, mean / median / p95 time to
  decision;
- the fixed contact reaching both error rates for the ideal observer (closed
  form, no classifier does better: the honest baseline) and for the paper's SVM
  (the shortest contact on a 0.05 s grid whose cross-validated accuracy,
  300 touches per class, is at least 1 - eps: what a robot using designkit's
  tables waits);
- the ratios fixed / mean time to decision;
- the optimal sequential test (:func:`designkit_lab.sequential_bound.optimal_test`,
  backward induction, longest contact 3 s, each class at its centre: 3 points per class
  gave the same figures to 4 decimals at eps 0.01, 2.5x slower):
  the bound no test reaches the same mean error rate under (Lagrangian dual), and the
  deterministic optimal rule's boundaries applied to the same simulated touches
  (error rates and mean time to decision measured, like the SPRT's).

A second, harder pair (5,000 vs 6,000) shows the gain where the decision falls on
the flat part of the response.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np
from scipy import stats

from designkit import SENSORS, Scene
from designkit.objects import ObjectClass
from designkit.recognition.sequential import SequentialTest, run_batch
from designkit_lab.sequential_bound import optimal_test, run_boundaries
from designkit.recognition.svm import pair_f1
from designkit.simulation import simulate_class

PAPER = SENSORS["paper"]


def svm_curve(lo, hi, contacts, trials, seed=0):
    """SVM cross-validated accuracy at each contact of the grid (paper features, 3 folds)."""
    return [pair_f1(ObjectClass("lo", lo), ObjectClass("hi", hi), PAPER, Scene(contact_s=float(c)),
                    trials=trials, seed=[seed, int(round(c * 1000))]).accuracy for c in contacts]


def svm_fixed_contact(curve, contacts, eps):
    """Shortest contact on the grid whose SVM accuracy is >= 1 - eps (None if none)."""
    for c, acc in zip(contacts, curve):
        if acc >= 1 - eps:
            return float(c), acc
    return None, None


def optimal_line(lo, hi, eps, trials, svm_t=None, points=1, horizon=3.0):
    """The optimal test at eps: the bound and its rule measured on the simulated touches."""
    t0 = time.perf_counter()
    dp_test = SequentialTest([("low", lo), ("high", hi)], PAPER, noise_c=0.05, sensor_temp_c=35.0,
                             ambient_temp_c=25.0, error_rate=eps, max_contact_s=horizon)
    o = optimal_test(dp_test, eps, points=points, iterations=14)
    t_dp = time.perf_counter() - t0
    res = [run_boundaries(dp_test, tr.temperature_c, o.upper, o.lower) for tr in trials]
    n = trials[0].temperature_c.shape[0]
    errs = [int(np.sum(r.decided != i)) for i, r in enumerate(res)]
    times = np.concatenate([r.time_s for r in res])
    mean_t = float(times.mean())
    fixed = dp_test.plan.fixed_contact_s
    cis = [stats.binomtest(k, n).proportion_ci(0.95) for k in errs]
    print(f"          optimal test (backward induction, {t_dp:.0f} s): bound {o.bound_s:.3f} s -> fixed ideal "
          f"{fixed / o.bound_s:.2f}x" + (f", fixed SVM {svm_t / o.bound_s:.2f}x" if svm_t else "") +
          f"; its rule (cost of an error {o.cost_s:.3g} s, mean error {o.error:.4f}) computed {o.expected_time_s:.3f} s, "
          f"measured: errors low {errs[0] / n:.4f} [{cis[0].low:.4f}, {cis[0].high:.4f}], high {errs[1] / n:.4f} "
          f"[{cis[1].low:.4f}, {cis[1].high:.4f}], mean time {mean_t:.3f} s -> {fixed / mean_t:.2f}x; "
          f"the SPRT by the same recursion {o.sprt_time_s:.3f} s (error {o.sprt_error:.4f})")
    return o, mean_t, times


def run_pair(lo, hi, eps_list, n, contact, svm, svm_trials, hist, optimal=True):
    print(f"\npair {lo[0]:g} vs {hi[0]:g} (classes 80 wide), noise 0.05 degC, dT 10 degC, paper sensor, "
          f"{n:,} touches per class, seed 1")
    rows = []
    t0 = time.perf_counter()
    trials = [simulate_class(ObjectClass(str(i), r), n, PAPER, Scene(contact_s=contact), seed=[1, i])
              for i, r in enumerate((lo, hi))]
    t_sim = time.perf_counter() - t0
    grid = np.round(np.arange(0.8, 3.0 + 1e-9, 0.05), 2)
    curve = svm_curve(lo, hi, grid, svm_trials) if svm else None
    for eps in eps_list:
        test = SequentialTest([("low", lo), ("high", hi)], PAPER, noise_c=0.05, sensor_temp_c=35.0,
                              ambient_temp_c=25.0, error_rate=eps, max_contact_s=contact)
        t0 = time.perf_counter()
        res = [run_batch(test, tr.temperature_c) for tr in trials]
        t_run = time.perf_counter() - t0
        errs = []
        for i, r in enumerate(res):
            k = int(np.sum(r.decided != i))
            ci = stats.binomtest(k, n).proportion_ci(0.95)
            errs.append((k / n, ci.low, ci.high, int(np.sum(r.decided < 0))))
        times = np.concatenate([r.time_s for r in res])
        mean_t = float(times.mean())
        ideal_t = test.plan.fixed_contact_s
        svm_t, svm_acc = svm_fixed_contact(curve, grid, eps) if svm else (None, None)
        rows.append((eps, errs, mean_t, float(np.median(times)), float(np.percentile(times, 95)), ideal_t,
                     svm_t, svm_acc))
        print(f"  eps {eps:g}: errors low {errs[0][0]:.4f} [95 % {errs[0][1]:.4f}, {errs[0][2]:.4f}], "
              f"high {errs[1][0]:.4f} [{errs[1][1]:.4f}, {errs[1][2]:.4f}], undecided {errs[0][3] + errs[1][3]}; "
              f"time to decision mean {mean_t:.3f} s, median {rows[-1][3]:.3f}, p95 {rows[-1][4]:.3f} "
              f"({t_run / (2 * n) * 1e6:.1f} us per touch batched)")
        line = f"          fixed contact, ideal observer {ideal_t:.3f} s -> {ideal_t / mean_t:.2f}x the mean"
        if svm:
            line += ("; SVM (accuracy >= 1 - eps, 0.05 s grid) " +
                     (f"{svm_t:.2f} s (acc {svm_acc:.4f}) -> {svm_t / mean_t:.2f}x" if svm_t else "none by 3 s"))
        print(line)
        if optimal:
            o, opt_mean, opt_times = optimal_line(lo, hi, eps, trials, svm_t)
        if hist is not None:
            hist.append((eps, times, ideal_t, svm_t, o.bound_s if optimal else None, opt_times if optimal else None))
    print(f"  (simulation of {2 * n:,} touches: {t_sim:.1f} s)")
    return rows


def run_paper12(n, eps, contact):
    """Neighbouring pairs of the paper's 12 materials at their identified effusivities (1-wide classes)."""
    from designkit.materials import list_materials

    mats = sorted(list_materials(set="paper12"), key=lambda m: m.identified)
    print(f"\npaper12 neighbours (identified effusivities, classes 1 wide), eps {eps:g}, {n:,} touches per class, "
          f"longest contact {contact:g} s, noise 0.05 degC, dT 10 degC, paper sensor")
    ratios = []
    for a, b in zip(mats, mats[1:]):
        lo, hi = (a.identified, a.identified + 1.0), (b.identified, b.identified + 1.0)
        test = SequentialTest([(a.name, lo), (b.name, hi)], PAPER, noise_c=0.05, sensor_temp_c=35.0,
                              ambient_temp_c=25.0, error_rate=eps, max_contact_s=contact)
        if not test.plan.separable:
            print(f"  {a.name} / {b.name}: {test.plan.reason}")
            continue
        m = int(round(contact * PAPER.sample_rate_hz)) + 1
        res = []
        for i, r in enumerate((lo, hi)):
            tr = simulate_class(ObjectClass(str(i), r), n, PAPER, Scene(contact_s=contact), seed=[3, i])
            res.append(run_batch(test, tr.temperature_c[:, :m]))
        err = [float(np.mean(x.decided != i)) for i, x in enumerate(res)]
        mean_t = float(np.mean(np.concatenate([x.time_s for x in res])))
        fixed = test.plan.fixed_contact_s
        ratios.append(fixed / mean_t)
        print(f"  {a.name} / {b.name}: errors {err[0]:.4f} / {err[1]:.4f}; mean time to decision {mean_t:.3f} s, "
              f"fixed contact (ideal observer) {fixed:.3f} s -> {fixed / mean_t:.2f}x")
    if ratios:
        print(f"  ratio fixed / mean: median {np.median(ratios):.2f}x, range {min(ratios):.2f}-{max(ratios):.2f}x")


def figure(hist, path):
    from designkit.figures import pyplot, save_figure

    plt = pyplot()
    keep = [h for h in hist if h[0] in (0.1, 0.01, 0.001)] or hist
    fig, axes = plt.subplots(len(keep), 1, figsize=(10.0, 2.3 * len(keep) + 0.6), sharex=True,
                             constrained_layout=True, squeeze=False)
    bins = np.arange(0.3, 2.2, 0.02)
    for ax, (eps, times, ideal_t, svm_t, bound_t, opt_times) in zip(axes[:, 0], keep):
        ax.hist(times, bins=bins, histtype="step", color="C0", label=f"SPRT (mean {times.mean():.3f} s)")
        if opt_times is not None:
            ax.hist(opt_times, bins=bins, histtype="step", color="C1",
                    label=f"optimal test's rule (mean {opt_times.mean():.3f} s)")
        ax.axvline(times.mean(), color="C0", lw=1.2)
        if bound_t is not None:
            ax.axvline(bound_t, color="C1", lw=1.2, ls="-.", label=f"bound on the mean, any test ({bound_t:.3f} s)")
        ax.axvline(ideal_t, color="k", ls="--", lw=1, label=f"fixed, ideal observer ({ideal_t:.3f} s)")
        if svm_t:
            ax.axvline(svm_t, color="k", ls=":", lw=1, label=f"fixed, SVM ({svm_t:.2f} s)")
        ax.axvline(ideal_t / 2, color="r", lw=0.8, alpha=0.6, label="2x target (half the ideal fixed)")
        ax.set_ylabel("touches")
        ax.set_title(f"requested error rate {eps:g}", fontsize=9)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)  # beside: no overlap
    axes[-1, 0].set_xlabel("time to decision [s]")
    fig.suptitle("35,000 vs 20,000 J s^-1/2 K^-1 m^-2, noise 0.05 °C, dT 10 °C, paper sensor, "
                 f"{len(keep[0][1]):,} touches", fontsize=9)
    save_figure(fig, path)
    print(f"figure: {path}")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--touches", type=int, default=10_000)
    p.add_argument("--eps", type=float, nargs="+", default=[0.1, 0.05, 0.01, 0.001])
    p.add_argument("--no-svm", action="store_true")
    p.add_argument("--no-optimal", action="store_true", help="skip the optimal test (backward induction, ~1 min per eps)")
    p.add_argument("--svm-trials", type=int, default=300)
    p.add_argument("--figure", default=None)
    p.add_argument("--paper12", type=int, default=0, help="also the paper's 12 materials, this many touches per class")
    a = p.parse_args(argv)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    hist = [] if a.figure else None
    run_pair((20000.0, 20080.0), (35000.0, 35080.0), a.eps, a.touches, 5.0, not a.no_svm, a.svm_trials, hist,
             optimal=not a.no_optimal)
    run_pair((5000.0, 5080.0), (6000.0, 6080.0), [0.05, 0.01], a.touches // 2, 15.0, False, a.svm_trials, None,
             optimal=not a.no_optimal)
    if a.paper12:
        run_paper12(a.paper12, 0.05, 10.0)
    if a.figure:
        figure(hist, a.figure)
    return 0


if __name__ == "__main__":
    sys.exit(main())
