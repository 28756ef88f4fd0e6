"""delta(e) of one scene, three ways in one run: naive matrix loop, staircase + sklearn, staircase + batched.

Run from the repository root::

    python benchmarks/bench_engine.py                       # 100 intervals, 2 s, sigma/dT 0.005 (a few minutes)
    python benchmarks/bench_engine.py --intervals 40 --repeat 3

One scene (``--intervals`` intervals over (0, 40000], one contact time, one
noise ratio, ``--trials`` touches per interval, the sweep's own seeds):

* **naive**: the paper's loop, one scikit-learn fit of every pair of the
  ``n (n - 1) / 2``; timed on ``--naive-pairs`` random pairs and extrapolated
  (wall per fit times the number of pairs);
* **staircase + sklearn**: ``run_chunk`` with ``solver: sklearn`` (the reference);
* **staircase + batched**: ``run_chunk`` with ``solver: batched``;
* with ``--dask``, the sweep also on a dask ``LocalCluster`` (one worker process per core), once started by
  the sweep (``--backend dask``) and once already running (``--scheduler``, start-up not timed).

Printed for each: wall [s], SVM fits, fits per second and the ratios to the
naive loop and to the sklearn staircase; the agreement of the two staircases
(references whose ``J``, ``J_lo``, ``J_hi`` differ, and by how many intervals);
and the parallel efficiency of the batched sweep (``run_sweep`` with two blocks per
core, so that no worker waits long for the other's last block) on ``--jobs 1`` and ``2`` local processes: ``T1 / (jobs x Tjobs)``,
with the wall of the sweep on every core against the naive loop (on one core, as
the paper's loop runs, and spread perfectly over the same cores). CPU seconds
are this process's (the in-process routes; the naive loop's extrapolated like its
wall). The staircases' agreement is also stated against each other's Monte Carlo
interval ``[J_lo, J_hi]``. BLAS threads
are limited to 1 per process. Wall times are medians of ``--repeat`` runs;
the load average before and after is printed, because the machines are shared.
No figure here is asserted anywhere.
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from designkit.sweep import SweepConfig, run_chunk, run_sweep  # noqa: E402
from designkit.sweep.run import local_cluster  # noqa: E402
from designkit.sweep.scorer import CV_KEY, PairScorer  # noqa: E402


def _median_run(fn, repeat, cpu=None):
    walls, cpus, out = [], [], None
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        out = fn()
        walls.append(time.perf_counter() - t)
        cpus.append(time.process_time() - c)
    if cpu is not None:
        cpu.append(statistics.median(cpus))
    return statistics.median(walls), out


def naive(cfg: SweepConfig, pairs: int, seed: int = 0):
    """Wall [s] per fit of the naive loop on ``pairs`` random pairs (features cached as the loop would)."""
    from designkit.recognition.svm import f1_from_features

    sensor = cfg.resolved_sensor()
    # the reference solver's scorer caches raw feature matrices (the batched one caches prepared ones)
    scorer = PairScorer(dataclasses.replace(cfg, solver="sklearn"), sensor, cfg.scene((0,), cfg.contact_s[0]))
    rng = np.random.default_rng(seed)
    n = cfg.intervals
    ij = set()
    while len(ij) < min(pairs, n * (n - 1) // 2):
        i, j = sorted(rng.choice(n, 2, replace=False).tolist())
        ij.add((i, j))
    ij = sorted(ij)
    for i, j in ij:  # features first: the full loop draws each interval's touches once
        scorer.features(i, 0), scorer.features(j, 0)
    f1_from_features(scorer.features(ij[0][0], 0), scorer.features(ij[0][1], 0), folds=cfg.folds, seed=0)  # warm-up
    t, c = time.perf_counter(), time.process_time()
    for i, j in ij:
        f1_from_features(scorer.features(i, 0), scorer.features(j, 0), folds=cfg.folds, seed=[cfg.seed, i, j, 0, CV_KEY])
    return (time.perf_counter() - t) / len(ij), len(ij), (time.process_time() - c) / len(ij)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--intervals", type=int, default=100)
    p.add_argument("--contact", type=float, default=2.0, help="contact time [s]")
    p.add_argument("--noise-ratio", type=float, default=0.005, help="sigma/dT")
    p.add_argument("--trials", type=int, default=100)
    p.add_argument("--naive-pairs", type=int, default=30, help="pairs timed for the naive loop's extrapolation")
    p.add_argument("--repeat", type=int, default=1, help="runs per wall figure (median)")
    p.add_argument("--skip-parallel", action="store_true")
    p.add_argument("--dask", action="store_true",
                   help="also the sweep on a dask LocalCluster of one worker process per core, against --jobs 1: "
                        "started by the sweep (start-up included) and already running (--scheduler)")
    args = p.parse_args(argv)

    base = dict(intervals=args.intervals, trials=args.trials, noise_ratio=(args.noise_ratio,),
                contact_s=(args.contact,))
    load0 = os.getloadavg()
    print(f"scene: {args.intervals} intervals over (0, 40000], contact {args.contact:g} s, sigma/dT "
          f"{args.noise_ratio:g}, {args.trials} trials per interval; {os.cpu_count()} cores, load average "
          f"{load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f} at the start", flush=True)

    per_fit, timed, cpu_fit = naive(SweepConfig(**base), args.naive_pairs)
    n_pairs = args.intervals * (args.intervals - 1) // 2
    rows = {"naive (extrapolated)": (per_fit * n_pairs, n_pairs, cpu_fit * n_pairs)}
    print(f"  naive: {timed} pairs timed, {per_fit * 1e3:.1f} ms per fit ({cpu_fit * 1e3:.1f} ms CPU)",
          file=sys.stderr, flush=True)
    res = {}
    for solver in ("sklearn", "batched"):
        cpu: list = []
        wall, r = _median_run(lambda: run_chunk(SweepConfig(solver=solver, **base), (0,), 0, 0), args.repeat, cpu)
        res[solver] = r
        rows[f"staircase + {solver}"] = (wall, r.fits, cpu[0])
        print(f"  staircase + {solver}: {wall:.1f} s, {r.fits} fits", file=sys.stderr, flush=True)

    print("\n| route | wall [s] | CPU [s] | SVM fits | fits/s | less wall than naive | less CPU than naive "
          "| less wall than staircase + sklearn |")
    print("|---|---|---|---|---|---|---|---|")
    ref_wall = rows["staircase + sklearn"][0]
    naive_wall, _, naive_cpu = rows["naive (extrapolated)"]
    for name, (wall, fits, cpu_s) in rows.items():
        print(f"| {name} | {wall:.1f} | {cpu_s:.1f} | {fits} | {fits / wall:.1f} | {naive_wall / wall:.1f}x "
              f"| {naive_cpu / cpu_s:.1f}x | {ref_wall / wall:.2f}x |")

    a, b = res["sklearn"], res["batched"]
    print("\nAgreement of the two staircases (references differing, largest difference in intervals):")
    for name in ("J", "J_lo", "J_hi"):
        d = np.abs(getattr(a, name) - getattr(b, name))
        print(f"  {name}: {int(np.sum(d > 0))} of {d.size}, max {int(d.max())}")
    for x, y, label in ((b, a, "batched J inside the sklearn staircase's Monte Carlo interval"),
                        (a, b, "sklearn J inside the batched staircase's Monte Carlo interval")):
        inside = (x.J >= y.J_lo) & (x.J <= y.J_hi)
        print(f"  {label}: {int(inside.sum())} of {inside.size}")
    ca = {(int(c[0]), int(c[1])): c for c in a.cells}
    cb = {(int(c[0]), int(c[1])): c for c in b.cells}
    both = sorted(set(ca) & set(cb))
    dF = np.array([abs(ca[k][2] - cb[k][2]) for k in both])
    print(f"  cells scored by both: {len(both)}; mean F1 differs in {int(np.sum(dF > 0))} "
          f"(max |dF1| {dF.max() if dF.size else 0:.4f})")

    if not args.skip_parallel:
        walls, busy = {}, {}  # busy: the chunks' own walls summed (last run of each), to tell contention from idling
        for jobs in sorted({1, 2, os.cpu_count() or 1}):
            def go(jobs=jobs):
                busy[jobs] = 0.0

                def add(res, computed, done, total):
                    busy[jobs] += res.wall_s
                with tempfile.TemporaryDirectory() as tmp:
                    cfg = SweepConfig(name="bench", solver="batched", blocks=2 * (os.cpu_count() or 1), **base)
                    run_sweep(cfg, Path(tmp), jobs=jobs, backend="loky" if jobs > 1 else "sequential", on_chunk=add)
            walls[jobs], _ = _median_run(go, args.repeat)
        eff = walls[1] / (2 * walls[2])
        print(f"\nParallel (batched solver, {2 * (os.cpu_count() or 1)} blocks): --jobs 1 {walls[1]:.1f} s, --jobs 2 {walls[2]:.1f} s: "
              f"speed-up {walls[1] / walls[2]:.2f}x, efficiency {eff:.0%} (process start-up included)")
        print(f"  the chunks' own walls summed: {busy[1]:.1f} s one at a time, {busy[2]:.1f} s two side by side "
              f"({busy[2] / busy[1]:.2f}x: what sharing the cores' cache and memory bandwidth costs; "
              f"{busy[1] / (2 * walls[2]):.0%} of the wall on two workers is their work as alone)")
        # the engine as a user runs it on this machine (every core), against the paper's loop as it runs
        # (one process) and against that loop spread perfectly over the same cores (its wall / cores)
        cores = os.cpu_count() or 1
        print(f"  the sweep on {cores} cores (--jobs {cores}): {walls[cores]:.1f} s wall, "
              f"{naive_wall / walls[cores]:.1f}x less than the naive loop on one core, "
              f"{naive_wall / cores / walls[cores]:.1f}x less than the naive loop spread over {cores} cores")
        if args.dask:  # the backend that goes past one machine, on a real local cluster of this machine's cores
            def go_dask(scheduler=None):
                with tempfile.TemporaryDirectory() as tmp:
                    cfg = SweepConfig(name="bench", solver="batched", blocks=2 * cores, **base)
                    run_sweep(cfg, Path(tmp), jobs=cores, backend="dask", scheduler=scheduler)
            wd, _ = _median_run(go_dask, args.repeat)
            print(f"  dask LocalCluster, {cores} worker processes (--backend dask --jobs {cores}): {wd:.1f} s wall, "
                  f"efficiency {walls[1] / (cores * wd):.0%} against --jobs 1 (cluster start-up included)")
            # as on a cluster that is already running (--scheduler ADDRESS): the same LocalCluster, started
            # (and its workers' imports warmed by one small task) before the clock starts
            with local_cluster(cores) as client:
                client.run(lambda: __import__("designkit.sweep.chunk"))
                wr, _ = _median_run(lambda: go_dask(client.cluster.scheduler_address), args.repeat)
            print(f"  the same cluster already running (--scheduler ADDRESS): {wr:.1f} s wall, "
                  f"efficiency {walls[1] / (cores * wr):.0%} against --jobs 1")
    load1 = os.getloadavg()
    print(f"\nload average {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f} at the end (2 cores shared with other users: "
          "wall figures are upper bounds)")


if __name__ == "__main__":
    main()
