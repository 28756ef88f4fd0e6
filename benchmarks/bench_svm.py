"""The batched SVM solver against the reference scikit-learn path (issue 12 targets).

Run from the repository root::

    python benchmarks/bench_svm.py                  # agreement on 1000 pairs + speed (a few minutes)
    python benchmarks/bench_svm.py --pairs 100      # quicker agreement run
    python benchmarks/bench_svm.py --skip-agreement --batches 8 32 128

Agreement: random pairs across contact times (0.5-4 s), noise ratios sigma/dT
(0.001-0.05, log-uniform) and effusivity pairs from near-identical (one interval
apart) to far apart, simulated as ``svm.interval_pair_f1`` does (100 trials per
class, intervals 80 wide). For each pair the reference F1
(``svm.f1_from_features``) and its cross-validated decision values
(``cross_val_predict(make_classifier(), ..., method="decision_function")``, whose
sign is libsvm's prediction) are compared with :func:`batched_cv_f1`. Printed:
pairs, predictions, pairs whose F1 differs, predictions that differ and their
|decision| (reference and batched; the functional margin is 1, so |decision| << 1
is a near-tie), the largest |decision| difference overall, and the solver stages used.

Speed: 2 s contact, 100 trials per class, 3 folds: CPU time per pair
(``time.process_time`` of this process, median of repeats) of the reference and of
the batched solver at several batch sizes, with the batched stages (fold
assignment, standardization, Gram products, dual solves, test decisions), the
peak memory traced per pair, and the floor of any exact solver on this CPU (the
Gram products and one factorization of each fold's free block, measured on the
first pair in the same run: the best ratio to the reference this CPU allows). BLAS threads are limited (``--threads``, default 1)
for both paths; the load average is printed because the machines are shared. ``--steady-heap`` runs both
paths as a sweep chunk runs its fits, with freed memory kept for reuse.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
import tracemalloc

import numpy as np

from designkit import Scene
from designkit.objects import ObjectClass
from designkit.recognition.batched_svm import batched_cv_f1, prepare_features
from designkit.recognition.features import feature_matrix
from designkit.recognition.svm import f1_from_features
from designkit.sensor import SENSORS
from designkit.simulation import simulate_class

SENSOR = SENSORS["paper"]
WIDTH = 80.0


def pair_features(e_low: float, e_high: float, contact_s: float, noise_ratio: float, seed: int, trials: int = 100):
    """Features of one interval pair, drawn as ``interval_pair_f1`` draws them (dT = 1 degC)."""
    scene = Scene(contact_s=contact_s, noise_c=noise_ratio, sensor_temp_c=26.0, ambient_temp_c=25.0)
    lo = simulate_class(ObjectClass("low", (e_low, e_low + WIDTH)), trials, SENSOR, scene, [seed, 0])
    hi = simulate_class(ObjectClass("high", (e_high, e_high + WIDTH)), trials, SENSOR, scene, [seed, 1])
    fs = SENSOR.sample_rate_hz
    return feature_matrix(lo.temperature_c, fs), feature_matrix(hi.temperature_c, fs)


def random_pairs(n: int, seed: int = 0):
    """(contact, ratio, e_low, e_high, seed) of n random pairs: contacts 0.5-4 s, ratios 0.001-0.05."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        contact = float(rng.choice([0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0]))
        ratio = float(np.exp(rng.uniform(np.log(0.001), np.log(0.05))))
        e_low = WIDTH * int(rng.integers(0, 480))
        gap = WIDTH * int(np.clip(np.round(np.exp(rng.uniform(0, np.log(200)))), 1, 499 - e_low / WIDTH))
        out.append((contact, ratio, e_low, e_low + gap, k))
    return out


def reference_decisions(lo, hi, seed):
    """Cross-validated decision values of the reference pipeline (sign = its prediction)."""
    import sklearn
    from sklearn.model_selection import StratifiedKFold, cross_val_predict

    from designkit._validation import as_generator
    from designkit.recognition.svm import make_classifier

    X = np.vstack([lo, hi])
    y = np.r_[np.zeros(len(lo), dtype=int), np.ones(len(hi), dtype=int)]
    cv = StratifiedKFold(n_splits=3, shuffle=True, random_state=int(as_generator(seed).integers(0, 2**31 - 1)))
    with sklearn.config_context(assume_finite=True, skip_parameter_validation=True):
        return cross_val_predict(make_classifier(), X, y, cv=cv, method="decision_function")


def agreement(n_pairs: int, seed: int, group: int = 16) -> dict:
    specs = random_pairs(n_pairs, seed)
    by_contact: dict[float, list] = {}
    for s in specs:
        by_contact.setdefault(s[0], []).append(s)
    n_pred = n_f1_diff = 0
    diffs = []  # (|dec ref|, |dec ours|, contact, ratio, gap)
    max_abs = 0.0
    stages = np.zeros(4, dtype=int)  # active set, continuation, libsvm + exact polish, libsvm alone
    max_gap = 0.0
    t_ref = t_new = 0.0
    for contact, group_specs in sorted(by_contact.items()):
        for g0 in range(0, len(group_specs), group):
            chunk = group_specs[g0:g0 + group]
            feats = [pair_features(e1, e2, c, r, k) for c, r, e1, e2, k in chunk]
            seeds = [[k, 2] for *_, k in chunk]
            t = time.process_time()
            ours = batched_cv_f1([f[0] for f in feats], [f[1] for f in feats], seeds=seeds)
            t_new += time.process_time() - t
            stages += np.bincount(ours.solver.ravel(), minlength=4)
            max_gap = max(max_gap, float(ours.kkt_gap.max()))
            for i, ((lo, hi), spec) in enumerate(zip(feats, chunk)):
                t = time.process_time()
                ref = f1_from_features(lo, hi, seed=seeds[i])
                t_ref += time.process_time() - t
                dec = reference_decisions(lo, hi, seeds[i])
                pred_ref = dec >= 0
                pred_new = ours.predictions[i] == 1
                n_pred += pred_ref.size
                max_abs = max(max_abs, float(np.max(np.abs(dec - ours.decision[i]))))
                n_f1_diff += int(ref.f1 != ours.f1[i])
                for j in np.flatnonzero(pred_ref != pred_new):
                    diffs.append((abs(float(dec[j])), abs(float(ours.decision[i, j])), spec[0], spec[1],
                                  (spec[3] - spec[2]) / WIDTH))
        print(f"  contact {contact:g} s: {len(group_specs)} pairs done", file=sys.stderr, flush=True)
    return {"pairs": n_pairs, "predictions": n_pred, "f1_differs": n_f1_diff, "differing_predictions": diffs,
            "max_abs_decision_difference": max_abs, "solver_stages": stages.tolist(), "max_kkt_gap": max_gap,
            "cpu_reference_s": t_ref, "cpu_batched_s": t_new}


def speed(batches, repeats: int, seed: int, n_ref: int) -> dict:
    specs = [(2.0, 0.005, e, e + g, k) for k, (e, g) in
             enumerate(zip(np.linspace(1000, 30000, max(batches)), np.tile([80, 400, 2000, 8000], max(batches))))]
    feats = [pair_features(e1, e2, c, r, k) for c, r, e1, e2, k in specs]
    lo = np.stack([f[0] for f in feats])
    hi = np.stack([f[1] for f in feats])
    seeds = [[k, 2] for k in range(len(specs))]
    f1_from_features(lo[0], hi[0], seed=seeds[0])  # warm up imports
    ref = []
    for _ in range(repeats):
        t = time.process_time()
        for i in range(n_ref):
            f1_from_features(lo[i], hi[i], seed=seeds[i])
        ref.append((time.process_time() - t) / n_ref)
    out = {"reference_cpu_s_per_pair": statistics.median(ref), "batched": [],
           "floor": floor(lo[0], hi[0], seeds[0])}
    batched_cv_f1(lo[:2], hi[:2], seeds=seeds[:2])
    for b in batches:
        per, stages = [], []
        for _ in range(repeats):
            tm: dict = {}
            t = time.process_time()
            batched_cv_f1(lo[:b], hi[:b], seeds=seeds[:b], timings=tm)
            per.append((time.process_time() - t) / b)
            stages.append({k: v / b for k, v in tm.items()})
        k = int(np.argsort(per)[len(per) // 2])
        tracemalloc.start()
        batched_cv_f1(lo[:b], hi[:b], seeds=seeds[:b])
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        out["batched"].append({"batch": b, "cpu_s_per_pair": per[k], "stages": stages[k],
                               "peak_mb": peak / 2**20, "input_mb_per_pair": (lo[0].nbytes + hi[0].nbytes) / 2**20})
        # as a sweep passes them: prepared features from its per-interval cache (prepare_features runs
        # once per interval and seed, and each interval serves several pairs: timed apart, per matrix)
        t = time.process_time()
        lo_l, hi_l = [prepare_features(x) for x in lo[:b]], [prepare_features(x) for x in hi[:b]]
        out["batched"][-1]["cpu_s_per_prepare"] = (time.process_time() - t) / (2 * b)
        per_l = []
        for _ in range(repeats):
            t = time.process_time()
            batched_cv_f1(lo_l, hi_l, seeds=seeds[:b])
            per_l.append((time.process_time() - t) / b)
        out["batched"][-1]["cpu_s_per_pair_lists"] = statistics.median(per_l)
    return out


def floor(lo, hi, seed, repeats: int = 200) -> dict:
    """CPU time of the two steps every exact solver of this classifier must take in each fold.

    Per fold: the Gram product of the fold's standardized training touches (float32,
    ``Z @ Z.T`` as the batched solver forms it) and one factorization of the free block
    of the dual at its solution (LAPACK ``dposv``, ridged as the active set solves it).
    The batched active set factors that block 3-4 times per fold (its iterations); a
    solver that guessed the final active set would still factor it once. Their sum over
    the folds is a floor on the CPU time per fit of any exact solver written on this
    BLAS and LAPACK: the best ratio to the reference that this CPU allows.
    """
    from scipy.linalg.lapack import dposv

    from designkit.recognition.batched_svm import _RIDGE, solve_svc_duals, stratified_test_folds

    X = np.vstack([lo, hi])
    test = stratified_test_folds(len(lo), len(hi), seed, 3)
    y_all = np.r_[np.ones(len(lo)), -np.ones(len(hi))]  # libsvm: the lower class is +1
    gram, chol, free = [], [], []
    for f in range(3):
        tr = test != f
        Xt = X[tr]
        sd = Xt.std(axis=0)
        Z = ((Xt - Xt.mean(axis=0)) / np.where(sd > 0, sd, 1.0)).astype(np.float32)
        ts = []
        for _ in range(repeats):
            t = time.process_time()
            K32 = Z @ Z.T
            ts.append(time.process_time() - t)
        gram.append(statistics.median(ts))
        K = K32.astype(np.float64)
        a, _, _ = solve_svc_duals(K[None], y_all[tr])
        F = np.flatnonzero((a[0] > 0) & (a[0] < 1.0))
        free.append(F.size)
        A0 = K[np.ix_(F, F)] + _RIDGE * float(np.mean(np.diag(K))) * np.eye(F.size)
        rhs0 = np.ones((F.size, 2), order="F")
        ts = []
        for _ in range(repeats):
            A, rhs = np.array(A0, order="F"), rhs0.copy(order="F")
            t = time.process_time()
            dposv(A, rhs, overwrite_a=1, overwrite_b=1)
            ts.append(time.process_time() - t)
        chol.append(statistics.median(ts))
    return {"gram_s": sum(gram), "factor_s": sum(chol), "free": free}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--pairs", type=int, default=1000, help="random pairs for the agreement run (default 1000)")
    p.add_argument("--batches", type=int, nargs="+", default=[8, 32, 128], help="batch sizes timed")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--reference-pairs", type=int, default=24, help="pairs per reference timing repeat")
    p.add_argument("--threads", type=int, default=1, help="BLAS threads for both paths (default 1)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--skip-agreement", action="store_true")
    p.add_argument("--skip-speed", action="store_true")
    p.add_argument("--steady-heap", action="store_true",
                   help="both paths with freed memory kept for reuse, as a sweep chunk runs its fits "
                        "(designkit._workers.steady_heap)")
    args = p.parse_args(argv)
    from contextlib import nullcontext

    from threadpoolctl import threadpool_limits

    from designkit._workers import steady_heap

    print(f"load average at start: {os.getloadavg()}; cores: {os.cpu_count()}; BLAS threads: {args.threads}; "
          f"heap {'kept for reuse (--steady-heap)' if args.steady_heap else 'as the allocators default'}")
    with threadpool_limits(args.threads), steady_heap() if args.steady_heap else nullcontext():
        if not args.skip_speed:
            s = speed(args.batches, args.repeats, args.seed, args.reference_pairs)
            r = s["reference_cpu_s_per_pair"]
            print(f"\nspeed, 2 s contact, 100 trials per class, 3 folds (CPU time per pair, median of {args.repeats}):")
            print(f"  reference (scikit-learn pipeline, f1_from_features): {r * 1e3:.2f} ms")
            for b in s["batched"]:
                st = "  ".join(f"{k} {v * 1e3:.3f}" for k, v in b["stages"].items())
                print(f"  batched, batch {b['batch']:4d}: {b['cpu_s_per_pair'] * 1e3:.3f} ms  "
                      f"({r / b['cpu_s_per_pair']:.1f}x less CPU)   stages [ms]: {st}")
                print(f"      from prepared features, as a sweep's cache passes them: "
                      f"{b['cpu_s_per_pair_lists'] * 1e3:.3f} ms ({r / b['cpu_s_per_pair_lists']:.1f}x less CPU); "
                      f"preparing one feature matrix (once per interval and seed): {b['cpu_s_per_prepare'] * 1e3:.3f} ms")
                print(f"      peak traced memory {b['peak_mb']:.1f} MB for the batch "
                      f"({b['peak_mb'] / b['batch']:.2f} MB per pair; inputs {b['input_mb_per_pair']:.2f} MB per pair, "
                      "not counted)")
            fl = s["floor"]
            low = fl["gram_s"] + fl["factor_s"]
            print(f"  floor of an exact solver on this CPU, measured on the first pair: Gram products "
                  f"{fl['gram_s'] * 1e3:.3f} ms + one factorization of each fold's free block "
                  f"({'/'.join(map(str, fl['free']))} free variables) {fl['factor_s'] * 1e3:.3f} ms = "
                  f"{low * 1e3:.3f} ms per fit: at most {r / low:.1f}x less CPU than the reference")
        if not args.skip_agreement:
            a = agreement(args.pairs, args.seed)
            d = a["differing_predictions"]
            print(f"\nagreement on {a['pairs']} random pairs (contact 0.5-4 s, sigma/dT 0.001-0.05, gaps 1-200 intervals):")
            print(f"  test predictions compared: {a['predictions']}")
            print(f"  pairs whose F1 differs from the reference: {a['f1_differs']}")
            print(f"  differing predictions: {len(d)} ({100 * len(d) / a['predictions']:.4f} % of predictions)")
            for dr, dn, c, ratio, gap in sorted(d):
                print(f"    |decision| reference {dr:.2e}, batched {dn:.2e}   (contact {c:g} s, "
                      f"sigma/dT {ratio:.4f}, {gap:g} intervals apart)")
            print(f"  largest |decision difference| over all predictions: {a['max_abs_decision_difference']:.2e}"
                  " (functional margin = 1; libsvm stops at a KKT gap of 1e-3)")
            print(f"  fold problems by solver stage [active set, continuation, SMO]: {a['solver_stages']}; "
                  f"largest KKT gap {a['max_kkt_gap']:.1e}")
            print(f"  CPU in this run: reference {a['cpu_reference_s']:.1f} s, batched {a['cpu_batched_s']:.1f} s")
    print(f"\nload average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()
