"""The calibrated rig's fold problems that the batched solver's active set cannot solve exactly: how each way
of ending them compares with the reference (libsvm without a step cap, as the paper's scikit-learn runs it).

Usage::

    nice -n 5 python benchmarks/bench_rig_duals.py --out /tmp/rig_duals            # capture + compare
    python benchmarks/bench_rig_duals.py --out /tmp/rig_duals --replay-only         # compare saved fits again

Capture: one block of ``--rows`` references of the rig table (``tests/data/rig_sensor.yaml``, the paper's 12
materials, as ``designkit tables build --sensor`` builds it) at each contact of ``--contacts``, run as a sweep
worker runs it; every fit (a pair's three folds) with a fold problem that reached libsvm is kept (its feature
matrices and fold seed, ``fits.npz`` in ``--out``), up to ``--max-fits`` per contact.

Replay: the kept fits through :func:`designkit.recognition.batched_svm.batched_cv_f1` once per way of ending the
problems, in one process with one BLAS thread (as a sweep worker), CPU measured per way (the whole call:
standardization, Gram, solve, predict):

- ``reference``: libsvm (scikit-learn's ``SVC``, eps 1e-3) without a step cap;
- ``libsvm-cap``: libsvm capped at 200,000 steps (designkit before this benchmark);
- ``ridge-1e-3``: the exact optimum of the dual ridged by ``1e-3 * mean(diag K)`` (the active set's first
  continuation level, which converges on these problems);
- ``designkit``: what the code under test does (the rule it ships: libsvm at eps 1e-2 and its cap, then the
  exact optimum by the active set from libsvm's free and bounded sets; where that fails, the same from libsvm at
  eps 1e-3);
- ``polish-1e-3``: the same polish from libsvm at eps 1e-3 only (the rule before);
- ``ridge-polish`` (experiment): before libsvm, the same exact polish (active set, ridge 1e-9, 25 solves) from
  the ``1e-3`` ridge optimum's free and bounded sets; only the problems where it does not converge go to libsvm
  (the ridge optimum is recomputed here, a few solves per problem that the shipped code already has).

Per way against the reference: per-fit F1 difference (mean, sd, largest), touches whose cross-validated
prediction differs, and CPU. Output: a table on stdout (``benchmarks/results/rig-duals.txt`` is this output).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time
from pathlib import Path

import numpy as np

RIG = "tests/data/rig_sensor.yaml"


def capture(args) -> list[dict]:
    from designkit.recognition import batched_svm as bs
    from designkit.sweep.chunk import run_chunk
    from designkit.sweep.for_sensor import effusivity_span, sensor_sweep_config

    cfg = sensor_sweep_config(args.sensor, span=effusivity_span(material_set="paper12"))
    blocks = max(1, cfg.intervals // args.rows)
    cfg = dataclasses.replace(cfg, blocks=blocks)
    block = blocks // 2 if args.block is None else args.block
    kept: list[dict] = []
    orig = bs.batched_cv_f1
    state = {"contact": None}

    def recording(lo, hi, *, seeds, **kw):
        r = orig(lo, hi, seeds=seeds, **kw)
        for i in np.flatnonzero((r.solver >= 2).any(axis=1)):
            if sum(f["contact_s"] == state["contact"] for f in kept) < args.max_fits:
                kept.append({"lo": bs.prepare_features(lo[i]), "hi": bs.prepare_features(hi[i]), "seed": seeds[i],
                             "contact_s": state["contact"]})
        return r

    bs.batched_cv_f1 = recording
    try:
        for k in [int(x) for x in args.contacts.split(",")]:
            state["contact"] = cfg.contact_s[k]
            t = time.process_time()
            r = run_chunk(cfg, (0,), block, k)
            print(f"# captured: contact {cfg.contact_s[k]:.3f} s (model), block {block} of {blocks}, {r.fits} fits, "
                  f"{time.process_time() - t:.1f} CPU s; kept {len(kept)} fits so far", flush=True)
    finally:
        bs.batched_cv_f1 = orig
    return kept


def _seed_array(seed):
    return np.atleast_1d(np.asarray(seed, dtype=np.int64))


def save(kept, path: Path) -> None:
    arrays = {}
    for j, f in enumerate(kept):
        for c in ("lo", "hi"):  # the prepared features the sweep passed: the replay gets the same bytes
            arrays[f"{c}{j}_dev"], arrays[f"{c}{j}_mean"] = f[c].dev, f[c].mean
        arrays[f"seed{j}"] = _seed_array(f["seed"])
        arrays[f"contact{j}"] = np.float64(f["contact_s"])
    np.savez(path, n=len(kept), **arrays)


def load(path: Path) -> list[dict]:
    from designkit.recognition.batched_svm import PreparedFeatures

    z = np.load(path)
    return [{"lo": PreparedFeatures(z[f"lo{j}_dev"], z[f"lo{j}_mean"]),
             "hi": PreparedFeatures(z[f"hi{j}_dev"], z[f"hi{j}_mean"]), "seed": [int(s) for s in z[f"seed{j}"]],
             "contact_s": float(z[f"contact{j}"])} for j in range(int(z["n"]))]


def _by_contact(kept):
    return [[f for f in kept if f["contact_s"] == c] for c in sorted({f["contact_s"] for f in kept})]


def replay(kept, way: str):
    """batched_cv_f1 on the kept fits with one way of ending the problems the active set cannot; (result, CPU s)."""
    from designkit.recognition import batched_svm as bs

    saved = (bs._libsvm_smo, bs._CONTINUATION, bs._smo_polished, bs._SMO_EPS_START)
    libsvm = bs._libsvm_smo
    to_libsvm = [0]

    def orig_smo(K, y, C, eps, max_iter, xp):  # libsvm, counting the problems it runs
        to_libsvm[0] += int(K.shape[0])
        return libsvm(K, y, C, eps, max_iter, xp)

    bs._libsvm_smo = orig_smo
    if way in ("reference", "libsvm-cap"):  # libsvm's own answer, without (reference) or with its step cap
        cap = -1 if way == "reference" else 200_000
        bs._libsvm_smo = lambda K, y, C, eps, max_iter, xp: orig_smo(K, y, C, eps, cap, xp)
        # libsvm at its own eps 1e-3, not polished (solver 3 everywhere)
        bs._SMO_EPS_START = bs.LIBSVM_EPS
        bs._smo_polished = lambda K, y, C, eps, max_iter, scale, max_as, xp: (
            lambda a, _, it: (a, np.zeros(K.shape[0], dtype=bool), it))(*bs._libsvm_smo(K, y, C, eps, max_iter, xp))
    elif way == "ridge-1e-3":  # the continuation ends at the 1e-3 ridge: every problem here stops there
        bs._CONTINUATION = (1e-3,)
    elif way == "polish-1e-3":  # the polish from libsvm at its own eps 1e-3 only (the rule before eps 1e-2 first)
        bs._SMO_EPS_START = bs.LIBSVM_EPS
    elif way == "ridge-polish":
        def ridge_polish(K, y, C, eps, max_iter, xp):
            P, n = y.shape
            scale = np.mean(np.diagonal(K, axis1=1, axis2=2), axis=1)
            a_r, _, _ = bs._active_set(K, y, C, 1e-3 * scale, np.ones((P, n), bool), np.zeros((P, n), bool), 25, xp)
            a_p, ok, _ = bs._active_set(K, y, C, bs._RIDGE * scale, (a_r > 0) & (a_r < C), a_r >= C, 25, xp)
            a_p, ok = bs._restore_equality(a_p, y, ok, C, xp)
            a = np.array(a_p)
            iters = np.zeros(P, dtype=np.int64)
            if not ok.all():
                a[~ok], _, iters[~ok] = orig_smo(K[~ok], y[~ok], C, eps, max_iter, xp)
            return a, iters < max_iter, iters

        bs._libsvm_smo = ridge_polish
    elif way != "designkit":
        raise SystemExit(f"unknown way {way!r}")
    from threadpoolctl import threadpool_limits

    try:  # one BLAS thread, as a sweep worker runs (designkit.sweep.chunk): idle BLAS threads would count as CPU
        t = time.process_time()
        with threadpool_limits(limits=1):
            parts = [bs.batched_cv_f1([f["lo"] for f in group], [f["hi"] for f in group], seeds=[f["seed"] for f in group])
                     for group in _by_contact(kept)]
        cpu = time.process_time() - t
        out = {k: np.concatenate([getattr(r, k) for r in parts]) for k in ("f1", "predictions", "solver", "kkt_gap")}
        return {**out, "to_libsvm": to_libsvm[0]}, cpu
    finally:
        bs._libsvm_smo, bs._CONTINUATION, bs._smo_polished, bs._SMO_EPS_START = saved


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", required=True, help="folder for the kept fits (fits.npz)")
    p.add_argument("--sensor", default=RIG)
    p.add_argument("--rows", type=int, default=10, help="references per captured block")
    p.add_argument("--block", type=int, default=None, help="which block (default: the middle one)")
    p.add_argument("--contacts", default="4,6", help="contact indices of the rig table, comma-separated")
    p.add_argument("--max-fits", type=int, default=15, help="fits kept per contact")
    p.add_argument("--replay-only", action="store_true")
    p.add_argument("--ways", default="reference,libsvm-cap,ridge-1e-3,polish-1e-3,designkit,ridge-polish")
    args = p.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"# {' '.join(['python'] + sys.argv)}")
    print(f"# {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; load average "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}; {os.cpu_count()} cores; CPU = process CPU seconds")
    if args.replay_only:
        kept = load(out / "fits.npz")
    else:
        kept = capture(args)
        save(kept, out / "fits.npz")
    contacts = sorted({f["contact_s"] for f in kept})
    print(f"# {len(kept)} fits ({3 * len(kept)} fold problems) with a fold problem that reached libsvm; "
          f"contacts (model) {[round(c, 3) for c in contacts]}")
    res = {}
    for way in args.ways.split(","):
        r, cpu = replay(kept, way)
        res[way] = (r, cpu)
        print(f"#   {way}: {cpu:.1f} CPU s, solver stages {np.bincount(r['solver'].ravel(), minlength=4).tolist()}, "
              f"KKT gap of the exact dual: median {np.median(r['kkt_gap']):.2g}, largest {np.max(r['kkt_gap']):.2g}; "
              f"{r['to_libsvm']} problems ran libsvm; "
              f"load {os.getloadavg()[0]:.1f}", flush=True)
    ref, ref_cpu = res["reference"]
    print(f"{'way':<12} {'CPU [s]':>8} {'x ref':>6}   F1 - reference F1: {'mean':>7} {'sd':>6} {'max|d|':>6}"
          f"   {'fits equal':>10}   touches predicted otherwise")
    for way, (r, cpu) in res.items():
        d = r['f1'] - ref['f1']
        flips = int(np.sum(r['predictions'] != ref['predictions']))
        print(f"{way:<12} {cpu:8.1f} {cpu / ref_cpu:6.2f}   {'':>19}{d.mean():+7.4f} {d.std():6.4f} "
              f"{np.abs(d).max():6.4f}   {int(np.sum(d == 0)):>4} of {d.size:<3}   {flips} of {r['predictions'].size} "
              f"({flips / r['predictions'].size:.2%})")
    print(f"# reference F1 range {ref['f1'].min():.3f}-{ref['f1'].max():.3f}; load average at end "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
