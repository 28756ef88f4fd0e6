"""Is a table the same on another machine? A slice of a config swept under emulated older CPUs (issue 12).

Run from the repository root::

    python benchmarks/bench_machines.py                      # svm-paper, 3 sigma/dT x 3 contact times
    python benchmarks/bench_machines.py --noise-ratio 0.005 --contact 2

A table is to be a function of its config alone, whatever ``--blocks``, ``--jobs``,
backend *or machine*. Machines differ in the SIMD code numpy's loops dispatch to and
in the BLAS kernels (the solver's float32 Gram products and float64 solves), and each
rounds differently. One machine can stand in for older ones: the OpenBLAS in numpy's
wheels (built with ``DYNAMIC_ARCH``) takes its kernels from ``OPENBLAS_CORETYPE``,
and numpy leaves out the instruction sets ``NPY_DISABLE_CPU_FEATURES`` names. Under
each emulated CPU, in a fresh process, this script

1. sweeps the slice with ``designkit sweep --jobs 2`` and compares every array with
   the native run's and with the shipped table's slice;
2. computes the cross-validated decision values of sample pairs near the threshold
   (reference ``i`` against its first distinguishable partner ``J(i)`` and against
   ``J(i) - 1``, the pairs whose F1 decides the staircase) with the sweep's own
   features and fold seeds, and compares them with the native ones: how far the
   arithmetic moves a decision, and how many predictions lie nearer a tie than that
   (only those could change side, and with them an F1).

A GPU is another machine too: the last row runs the code a GPU build runs (the batched
solver's generic array-API path, which ``--solver batched-cupy`` runs on CuPy) on numpy,
``--solver batched-array-api``, in place of the numpy fast path every other row runs.

Where the emulation does not take (no x86-64, a BLAS without ``DYNAMIC_ARCH``) the
CPU's line says so and its comparison is left out.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

#: Emulated CPUs: (name, OPENBLAS_CORETYPE, NPY_DISABLE_CPU_FEATURES, solver). numpy 2's dispatch groups are
#: X86_V2 (SSE4.2, its baseline), X86_V3 (AVX2, FMA3) and X86_V4 plus AVX512_ICL / AVX512_SPR (AVX-512). The last
#: row is a GPU's code path on this CPU: the batched solver's generic array-API code, which `batched-cupy` runs,
#: on numpy (`--solver batched-array-api`) instead of its numpy fast path.
CPUS = (
    ("native", None, None, "batched"),
    ("AVX2 + FMA (Haswell)", "Haswell", "X86_V4 AVX512_ICL AVX512_SPR", "batched"),
    ("AVX, no FMA (Sandy Bridge)", "Sandybridge", "X86_V3 X86_V4 AVX512_ICL AVX512_SPR", "batched"),
    ("SSE4.2 (Nehalem)", "Nehalem", "X86_V3 X86_V4 AVX512_ICL AVX512_SPR", "batched"),
    ("a GPU's code path, on this CPU", None, None, "batched-array-api"),
)


def _env(coretype, disable):
    """This process's environment with the emulation's two variables set as asked (None: unset)."""
    asked = {"OPENBLAS_CORETYPE": coretype, "NPY_DISABLE_CPU_FEATURES": disable}
    return {**{k: v for k, v in os.environ.items() if k not in asked},
            **{k: v for k, v in asked.items() if v is not None}}


def worker(args) -> int:
    """In the emulated process: what the CPU looks like, and the decisions of the sample pairs."""
    import threadpoolctl

    from designkit.sweep.config import SweepConfig
    from designkit.sweep.scorer import PairScorer

    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__

    blas = [i.get("architecture") for i in threadpoolctl.threadpool_info() if i.get("user_api") == "blas"]
    disabled = set((os.environ.get("NPY_DISABLE_CPU_FEATURES") or "").split())
    simd = [f for f in __cpu_dispatch__ if __cpu_features__.get(f) and f not in disabled]
    pairs = json.loads(Path(args.pairs).read_text())
    out = {}
    for key, plist in pairs.items():
        noise, contact = map(float, key.split("|"))
        cfg = SweepConfig.from_yaml(args.config, noise_ratio=[noise], contact_s=[contact], solver=args.solver)
        out[key] = PairScorer(cfg, cfg.resolved_sensor(), cfg.scene((0,), contact)).decisions(
            [(i, j, 0) for i, j in plist])
    np.savez(args.worker, **out)
    Path(args.worker + ".json").write_text(json.dumps({"blas": blas, "simd": simd}))
    return 0


def _arrays(path):
    with np.load(path) as z:
        return {k: z[k] for k in z.files if k.startswith("delta") or k == "fits"}


def _differs(a, b):
    """Entries that differ (NaN equals NaN), per array name; empty when identical."""
    out = {}
    for k in sorted(set(a) | set(b)):
        if k not in a or k not in b or a[k].shape != b[k].shape:
            out[k] = "missing or reshaped"
            continue
        same = (a[k] == b[k]) | (np.isnan(a[k]) & np.isnan(b[k])) if a[k].dtype.kind == "f" else a[k] == b[k]
        if not same.all():
            out[k] = int((~same).sum())
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--config", default=str(ROOT / "tables" / "svm-paper.yaml"))
    p.add_argument("--table", default=str(ROOT / "tables" / "svm-paper.npz"),
                   help="the shipped table the config built ('' to skip that comparison)")
    p.add_argument("--noise-ratio", default="0.001,0.005,0.02")
    p.add_argument("--contact", default="0.5,2,10")
    p.add_argument("--sample", type=int, default=25, help="references per scene whose near-threshold pairs are sampled")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--worker", help=argparse.SUPPRESS)
    p.add_argument("--pairs", help=argparse.SUPPRESS)
    p.add_argument("--solver", default="batched", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.worker:
        return worker(args)

    from designkit.sweep.config import SweepConfig

    noises = [float(x) for x in args.noise_ratio.split(",")]
    contacts = [float(x) for x in args.contact.split(",")]
    full = SweepConfig.from_yaml(args.config)
    print(f"# python benchmarks/bench_machines.py {' '.join(sys.argv[1:] if argv is None else argv)}; "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; {os.cpu_count()} cores; load average "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(f"slice of {Path(args.config).name}: sigma/dT {noises} x contact {contacts} s, {full.intervals} intervals "
          f"({len(noises) * len(contacts) * full.intervals} references)")
    shipped, table_fits = None, None
    if args.table:
        with np.load(args.table) as z:
            table_fits = int(z["fits"].sum())
            ni = [list(full.noise_ratio).index(x) for x in noises]
            ci = [list(full.contact_s).index(x) for x in contacts]
            shipped = {k: z[k][np.ix_(ni, ci)] for k in z.files if k.startswith("delta") or k == "fits"}

    results, decisions = {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        pairs_file = tmp / "pairs.json"
        for name, coretype, disable, solver in CPUS:
            env = _env(coretype, disable)
            out = tmp / f"{len(results)}.npz"
            t = time.perf_counter()
            cmd = [sys.executable, "-m", "designkit", "sweep", "--config", args.config,
                   "--noise-ratio", args.noise_ratio, "--contact", args.contact, "--jobs", str(args.jobs),
                   "--solver", solver,
                   "--workdir", str(tmp / f"w{len(results)}"), "--out", str(out)]
            run = subprocess.run(cmd, env=env, capture_output=True, text=True)
            wall = time.perf_counter() - t
            if run.returncode != 0:
                print(f"{name}: the sweep failed: {run.stderr.strip().splitlines()[-1:]}")
                return 1
            arrays = _arrays(out)
            if not pairs_file.exists():  # the native run's staircase picks the pairs every CPU scores
                rng = np.random.default_rng(0)
                plist = {}
                for a, noise in enumerate(noises):
                    for b, contact in enumerate(contacts):
                        up = arrays["delta_up"][a, b]
                        ok = np.flatnonzero(np.isfinite(up) & (up > full.width))
                        rows = rng.choice(ok, size=min(args.sample, ok.size), replace=False)
                        J = rows + np.rint(up[rows] / full.width).astype(int)
                        plist[f"{noise}|{contact}"] = [[int(i), int(j)] for i, j in zip(rows, J)] + \
                                                      [[int(i), int(j) - 1] for i, j in zip(rows, J)]
                pairs_file.write_text(json.dumps(plist))
            dec_out = str(tmp / f"d{len(results)}.npz")
            w = subprocess.run([sys.executable, __file__, "--worker", dec_out, "--pairs", str(pairs_file),
                                "--config", args.config, "--solver", solver], env=env, capture_output=True, text=True)
            if w.returncode != 0:
                print(f"{name}: the decision worker failed: {w.stderr.strip().splitlines()[-1:]}")
                return 1
            info = json.loads(Path(dec_out + ".json").read_text())
            with np.load(dec_out) as z:
                decisions[name] = {k: z[k] for k in z.files}
            results[name] = (arrays, wall, info, coretype)

    native_arrays, _, native_info, _ = results["native"]
    native_dec = decisions["native"]
    all_native = np.concatenate([v.ravel() for v in native_dec.values()])
    n_pairs = sum(v.shape[0] for v in native_dec.values())
    print(f"sample: {n_pairs} near-threshold pairs (reference i with J(i) and J(i) - 1), {all_native.size} "
          f"cross-validated decisions; the functional margin is 1, and |decision| < 1e-3 is libsvm's own tolerance\n")
    print("| CPU | BLAS kernel | numpy SIMD | sweep wall [s] | arrays vs native | arrays vs shipped | "
          "decisions moved (max abs) | predictions nearer a tie than that | predictions changed |")
    print("|---|---|---|---|---|---|---|---|---|")
    ok_all = True
    for name, (arrays, wall, info, coretype) in results.items():
        took = coretype is None or (info["blas"] and info["blas"][0].lower() == coretype.lower())
        simd = " ".join(s for s in info["simd"] if s.startswith(("X86", "AVX512"))) or "baseline"
        blas = ", ".join(sorted({str(b) for b in info["blas"]})) or "?"
        if not took:
            print(f"| {name} | {blas} (asked {coretype}: not emulated here) | {simd} | {wall:.1f} | - | - | - | - | - |")
            continue
        vs_native = _differs(arrays, native_arrays)
        vs_ship = _differs(arrays, shipped) if shipped is not None else None
        ok_all &= not vs_native and not vs_ship
        d = np.concatenate([v.ravel() for v in decisions[name].values()])
        moved = float(np.max(np.abs(d - all_native)))
        near = int(np.sum(np.abs(all_native) <= moved))
        flipped = int(np.sum((d >= 0) != (all_native >= 0)))
        print(f"| {name} | {blas} | {simd} | {wall:.1f} | {'identical' if not vs_native else vs_native} | "
              f"{'-' if vs_ship is None else ('identical' if not vs_ship else vs_ship)} | {moved:.2e} | {near} | "
              f"{flipped} |")
    smallest = float(np.min(np.abs(all_native)))
    band = 1e-2
    in_band = int(np.sum(np.abs(all_native) < band))
    moves = [np.abs(np.concatenate([v.ravel() for v in decisions[k].values()]) - all_native) for k in decisions
             if k != "native"]
    if moves:
        mean_move = max(float(m.mean()) for m in moves)
        expected = in_band / all_native.size * mean_move / band  # P(|decision| < its own move), density flat near 0
        print(f"\nsmallest |decision| in the native sample: {smallest:.2e}; {in_band} of {all_native.size} lie within "
              f"{band:g} of a tie. Taking their density as flat below {band:g}, a prediction changes side on another "
              f"CPU with probability about {expected:.1e} (the largest mean move over the CPUs, {mean_move:.1e}): "
              f"{1e6 * expected:.2g} per million predictions"
              + (f", {expected * 2 * full.trials * table_fits:.2g} over the {table_fits:,} fits of "
                 f"{Path(args.table).name} ({2 * full.trials} predictions each)" if table_fits else "")
              + ". A changed prediction moves one fold's F1; it changes the table only where the pair's F1 then "
                "crosses the threshold or the re-scoring band.")
    print("every emulated CPU gave the native arrays" + (" and the shipped table's" if shipped is not None else "")
          if ok_all else "SOME ARRAYS DIFFER (above)")
    return 0 if ok_all else 1


if __name__ == "__main__":
    raise SystemExit(main())
