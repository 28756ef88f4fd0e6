"""The library as a program uses it, against a baseline tree in the same run (issues 16 and 33).

Run from the repository root::

    python benchmarks/bench_library.py                          # this tree against c8fe4cc, 10,000 pairs
    python benchmarks/bench_library.py --baseline /work/main     # against another tree
    python benchmarks/bench_library.py --n 2000 --json out.json

Each tree is measured in a fresh child process (``PYTHONPATH`` set to the tree), one after the other; the
baseline is ``git archive`` of ``--baseline-ref`` unless ``--baseline`` names a folder. CPU time is printed
beside wall time: on a shared machine wall time measures the neighbours. Parts:

1. **N new pairs as one array call** (``min_contact(e1, e2, table=svm)``, the per-process memo cleared
   first: every closed-form bound and critical noise computed). Target (issue 33): 10,000 pairs in at most
   2 s on 2 cores.
2. **1,000 other new pairs** as one array call.
3. **A new pair each call** (median of 30 scalar calls, each pair new). Target: at most 1 ms.
4. **A repeated pair** (median of ``--loop`` calls, tables named by string as the README shows). Target
   (issue 16): at most 0.5 ms.
5. Every other question, tables named by string, in a loop.
6. The array answers against ``--scalar`` scalar calls of the same tree (element i equals the scalar call).
7. ``designkit matrix --set paper12`` from a fresh shell (median of 3 runs, ``.pyc`` files compiled first).
   Target (issue 33): at most 1 s wall.

The two trees' answers to part 1 are compared element by element: identical, changed (and whether the
new value lies inside the baseline's interval), NaN changed.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAIR = (35000.0, 20000.0)
FIELDS = ("value", "low", "high", "ideal")


def _pairs(n: int, seed: int, e_min: float, e_max: float):
    import numpy as np

    rng = np.random.default_rng(seed)
    e1 = rng.uniform(e_min + 100, e_max - 100, n)
    e2 = e1 + rng.uniform(200, 8000, n) * rng.choice([-1, 1], n)
    e2 = np.clip(e2, e_min + 100, e_max - 100)
    return e1, np.where(np.abs(e2 - e1) < 100, e1 + 150, e2)


def _median_call(fn, n: int) -> dict:
    """Median wall and CPU milliseconds per call of ``fn`` over ``n`` calls (after one warm-up call)."""
    fn()
    walls, cpus = [], []
    for _ in range(n):
        w0, c0 = time.perf_counter(), time.process_time()
        fn()
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    return {"calls": n, "wall_ms": 1e3 * statistics.median(walls), "cpu_ms": 1e3 * statistics.median(cpus)}


def _once(fn) -> dict:
    w0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return {"wall_s": time.perf_counter() - w0, "cpu_s": time.process_time() - c0, "result": out}


def worker(args) -> None:
    """Measure the tree this process imports; print one JSON line, save part 1's answers to ``--answers``."""
    import numpy as np

    from designkit.query import delta_e, distinguishable, max_noise, min_contact, min_delta_t
    from designkit.query.ideal_bound import clear_bound_cache
    from designkit.tables.store import load_table

    svm = load_table("svm-paper")
    e_min, e_max = float(svm.header["effusivity"]["min"]), float(svm.header["effusivity"]["max"])
    min_contact(*PAIR, table=svm)  # tables opened, first-call costs paid
    out: dict = {"n": args.n}
    e1, e2 = _pairs(args.n, 16, e_min, e_max)
    clear_bound_cache()
    r = _once(lambda: min_contact(e1, e2, table=svm))
    arr = r.pop("result")
    out["array_new"] = r
    np.savez(args.answers, **{f: np.asarray(getattr(arr, f), dtype=float) for f in FIELDS})
    f1, f2 = _pairs(1000, 17, e_min, e_max)
    r = _once(lambda: min_contact(f1, f2, table=svm))
    r.pop("result")
    out["array_new_1000"] = r
    fresh = iter(np.linspace(21003.0, 38997.0, 997).tolist())
    out["new_pair_each_call"] = _median_call(lambda: min_contact(next(fresh), 20000.0, table=svm), 30)
    out["repeated_pair_by_name"] = _median_call(
        lambda: min_contact(*PAIR, table="svm-paper", ideal_table="ideal-paper"), args.loop)
    others = {
        "max_noise": lambda: max_noise(*PAIR, contact_s=2.0, table="svm-paper", ideal_table="ideal-paper"),
        "min_delta_t": lambda: min_delta_t(*PAIR, contact_s=2.0, table="svm-paper", ideal_table="ideal-paper"),
        "distinguishable": lambda: distinguishable(*PAIR, contact_s=2.0, table="svm-paper",
                                                   ideal_table="ideal-paper"),
        "delta_e": lambda: delta_e(20000.0, contact_s=2.0, table="svm-paper", ideal_table="ideal-paper"),
    }
    out["other_questions_by_name"] = {k: _median_call(f, args.loop) for k, f in others.items()}
    k = min(args.scalar, args.n)
    scalar = [min_contact(a, b, table=svm) for a, b in zip(e1[:k].tolist(), e2[:k].tolist())]

    def num(v):
        return np.nan if v is None else v

    want = {"value": [num(a.value) for a in scalar], "low": [num(a.interval[0]) for a in scalar],
            "high": [num(a.interval[1]) for a in scalar], "ideal": [num(a.ideal_bound.value) for a in scalar]}
    out["array_equals_scalar_calls"] = {"checked": k, "equal": all(
        np.allclose(np.asarray(getattr(arr, f))[:k], np.array(v, dtype=float), rtol=1e-12, atol=0.0,
                    equal_nan=True) for f, v in want.items())}
    print(json.dumps(out))


def _matrix(tree: Path, runs: int) -> dict:
    """Median wall and CPU seconds of ``designkit matrix --set paper12`` from a fresh shell in ``tree``."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(tree / "designkit")], env=env,
                   stdout=subprocess.DEVNULL, check=False)
    cmd = [sys.executable, "-m", "designkit", "matrix", "--set", "paper12"]
    walls, cpus = [], []
    for _ in range(runs + 1):  # the first: page cache
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        _, status, usage = os.wait4(p.pid, 0)
        walls.append(time.perf_counter() - t0)
        cpus.append(usage.ru_utime + usage.ru_stime)
    return {"runs": runs, "wall_s": statistics.median(walls[1:]), "cpu_s": statistics.median(cpus[1:])}


def _measure(tree: Path, args, answers: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(tree))
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", "--n", str(args.n), "--loop",
           str(args.loop), "--scalar", str(args.scalar), "--answers", str(answers)]
    p = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=str(tree))
    if p.returncode != 0:
        raise SystemExit(f"measuring {tree} failed:\n{p.stderr[-3000:]}")
    out = json.loads(p.stdout.strip().splitlines()[-1])
    out["matrix_paper12"] = _matrix(tree, args.matrix_runs)
    return out


def _compare(old: Path, new: Path) -> dict:
    import numpy as np

    o, n = np.load(old), np.load(new)
    v0, v1, lo0, hi0 = o["value"], n["value"], o["low"], o["high"]
    same = (v0 == v1) | (np.isnan(v0) & np.isnan(v1))
    nan_changed = np.isnan(v0) != np.isnan(v1)
    changed = ~same & ~nan_changed
    inside = changed & (v1 >= np.nan_to_num(lo0, nan=-np.inf)) & (v1 <= np.nan_to_num(hi0, nan=np.inf))
    out = {"elements": int(v0.size), "value_identical": int(same.sum()), "value_changed": int(changed.sum()),
           "changed_inside_baseline_interval": int(inside.sum()), "value_nan_changed": int(nan_changed.sum())}
    for f in ("low", "high", "ideal"):
        a, b = o[f], n[f]
        d = ~((a == b) | (np.isnan(a) & np.isnan(b)))
        both = d & np.isfinite(a) & np.isfinite(b)
        out[f"{f}_changed"] = int(d.sum())
        out[f"{f}_max_rel_change"] = float(np.max(np.abs(b[both] / a[both] - 1))) if both.any() else 0.0
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000, help="new pairs in part 1 (default 10,000)")
    ap.add_argument("--loop", type=int, default=200, help="calls timed in parts 4-5")
    ap.add_argument("--scalar", type=int, default=300, help="scalar calls checked against the array call")
    ap.add_argument("--matrix-runs", type=int, default=3)
    ap.add_argument("--baseline", type=Path, help="a tree to compare with (default: git archive of the ref)")
    ap.add_argument("--baseline-ref", default="c8fe4cc", help="commit measured as the baseline (default c8fe4cc)")
    ap.add_argument("--json", type=Path, help="also write the figures here")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--answers", type=Path, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        worker(args)
        return {}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        base = args.baseline
        if base is None:
            base = tmp / "baseline"
            base.mkdir()
            archive = subprocess.run(["git", "-C", str(ROOT), "archive", args.baseline_ref], capture_output=True,
                                     check=True).stdout
            subprocess.run(["tar", "-x", "-C", str(base)], input=archive, check=True)
        label = args.baseline_ref if args.baseline is None else str(base)
        figures = {"baseline": label, "load_average_start": os.getloadavg()}
        figures["trees"] = {"baseline": _measure(base, args, tmp / "old.npz"),
                            "this tree": _measure(ROOT, args, tmp / "new.npz")}
        figures["answers"] = _compare(tmp / "old.npz", tmp / "new.npz")
        figures["load_average_end"] = os.getloadavg()
    _print(figures, args.n)
    if args.json:
        args.json.write_text(json.dumps(figures, indent=2))
    return figures


def _print(f: dict, n: int) -> None:
    old, new = f["trees"]["baseline"], f["trees"]["this tree"]
    print(f"baseline {f['baseline']} against this tree; load average {f['load_average_start'][0]:.1f} at the "
          f"start, {f['load_average_end'][0]:.1f} at the end (2 cores; CPU time is the steadier figure)")
    print(f"{'':46} {'baseline':>22} {'this tree':>22} {'CPU ratio':>10}")

    def row(label, a, b, unit, key_w, key_c):
        ratio = a[key_c] / b[key_c] if b[key_c] else float("inf")
        print(f"{label:<46} {a[key_w]:9.3f} / {a[key_c]:7.3f} {unit:<2} {b[key_w]:9.3f} / {b[key_c]:7.3f} {unit:<2}"
              f" {ratio:9.1f}x")

    print(f"{'(wall / CPU)':<46}")
    row(f"{n:,} new pairs, one array call (target <= 2 s)", old["array_new"], new["array_new"], "s",
        "wall_s", "cpu_s")
    row("1,000 new pairs, one array call", old["array_new_1000"], new["array_new_1000"], "s", "wall_s", "cpu_s")
    row("a new pair each call (target <= 1 ms)", old["new_pair_each_call"], new["new_pair_each_call"], "ms",
        "wall_ms", "cpu_ms")
    row("a repeated pair, tables by name (<= 0.5 ms)", old["repeated_pair_by_name"],
        new["repeated_pair_by_name"], "ms", "wall_ms", "cpu_ms")
    for k in new["other_questions_by_name"]:
        row(f"  {k}, repeated", old["other_questions_by_name"][k], new["other_questions_by_name"][k], "ms",
            "wall_ms", "cpu_ms")
    row("designkit matrix --set paper12 (target <= 1 s)", old["matrix_paper12"], new["matrix_paper12"], "s",
        "wall_s", "cpu_s")
    for name, t in (("baseline", old), ("this tree", new)):
        e = t["array_equals_scalar_calls"]
        print(f"{name}: array answers equal {e['checked']} scalar calls: {e['equal']}")
    a = f["answers"]
    print(f"answers to part 1, this tree against the baseline ({a['elements']:,} pairs): value identical "
          f"{a['value_identical']:,}, changed {a['value_changed']:,} (inside the baseline's interval: "
          f"{a['changed_inside_baseline_interval']:,}), NaN changed {a['value_nan_changed']:,}; interval ends "
          f"changed {a['low_changed']:,} / {a['high_changed']:,} (at most {a['low_max_rel_change']:.1e} / "
          f"{a['high_max_rel_change']:.1e} relative); ideal bound changed {a['ideal_changed']:,} "
          f"(at most {a['ideal_max_rel_change']:.1e})")


if __name__ == "__main__":
    main()
