"""The library as a program uses it: table queries in a loop, and many queries at once (issue 16).

Run from the repository root::

    /work/main/.venv/bin/python benchmarks/bench_library.py                 # all parts, 10,000 queries
    /work/main/.venv/bin/python benchmarks/bench_library.py --n 2000 --json out.json

Measured in one process, on whatever machine runs it (CPU time per call as well
as wall time: on a shared machine wall time measures the neighbours):

1. ``designkit.query.min_contact(35000, 20000)`` in a loop, **tables named by
   string** (as the README shows): the tables are loaded once per process, the
   closed-form ideal bound computed once per scene (then a cache hit).
   Target: at most 0.5 ms per call.
2. The same with **loaded Table objects** passed to every call.
3. ``min_contact`` on **a new pair every call** (the bound computed each time,
   the cost a first question pays).
4. **N queries, different pairs**: one **array call** with the bounds not yet
   computed (cold: the closed form, vectorized, for every distinct element),
   then **N scalar calls** and **the same array call** again with the bounds
   cached (warm), and the array call with ``ideal_bound=False``; the array
   answers are checked equal to the scalar calls. Target: the array call at
   least 50x faster than the N scalar calls.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numpy as np

from designkit.query import delta_e, distinguishable, max_noise, min_contact, min_delta_t
from designkit.query.ideal_bound import clear_bound_cache
from designkit.tables.store import load_table

PAIR = (35000.0, 20000.0)


def _timed(fn, n: int) -> dict:
    """Median wall and CPU seconds per call of ``fn`` over ``n`` calls (after one warm-up call)."""
    fn()
    walls, cpus = [], []
    for _ in range(n):
        w0, c0 = time.perf_counter(), time.process_time()
        fn()
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    return {"calls": n, "wall_ms_median": 1e3 * statistics.median(walls),
            "cpu_ms_median": 1e3 * statistics.median(cpus), "wall_ms_best": 1e3 * min(walls)}


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000, help="queries in part 4 (default 10,000)")
    ap.add_argument("--loop", type=int, default=200, help="calls timed in parts 1-2")
    ap.add_argument("--json", type=Path, help="also write the figures here")
    args = ap.parse_args(argv)

    svm, ideal = load_table("svm-paper"), load_table("ideal-paper")
    out: dict = {"n": args.n}
    out["by_name"] = _timed(lambda: min_contact(*PAIR, table="svm-paper", ideal_table="ideal-paper"), args.loop)
    # every other question, tables named by string, in a loop (the same target)
    others = {
        "max_noise(35000, 20000, contact_s=2)": lambda: max_noise(*PAIR, contact_s=2.0, table="svm-paper",
                                                                   ideal_table="ideal-paper"),
        "min_delta_t(35000, 20000, contact_s=2)": lambda: min_delta_t(*PAIR, contact_s=2.0, table="svm-paper",
                                                                       ideal_table="ideal-paper"),
        "distinguishable(35000, 20000, contact_s=2)": lambda: distinguishable(*PAIR, contact_s=2.0, table="svm-paper",
                                                                               ideal_table="ideal-paper"),
        "delta_e(20000, contact_s=2)": lambda: delta_e(20000.0, contact_s=2.0, table="svm-paper",
                                                       ideal_table="ideal-paper"),
    }
    out["other_questions_by_name"] = {k: _timed(f, args.loop) for k, f in others.items()}
    out["loaded_tables"] = _timed(lambda: min_contact(*PAIR, table=svm, ideal_table=ideal), args.loop)
    fresh = iter(np.linspace(21000.0, 39000.0, 1000).tolist())
    out["new_pair_each_call"] = _timed(lambda: min_contact(next(fresh), 20000.0, table=svm), 20)

    rng = np.random.default_rng(16)
    e_min, e_max = float(svm.header["effusivity"]["min"]), float(svm.header["effusivity"]["max"])
    e1 = rng.uniform(e_min + 100, e_max - 100, args.n)
    e2 = e1 + rng.uniform(200, 8000, args.n) * rng.choice([-1, 1], args.n)
    e2 = np.clip(e2, e_min + 100, e_max - 100)
    e2 = np.where(np.abs(e2 - e1) < 100, e1 + 150, e2)

    clear_bound_cache()
    w0, c0 = time.perf_counter(), time.process_time()
    min_contact(e1, e2, table=svm)
    out["array_cold"] = {"wall_s": time.perf_counter() - w0, "cpu_s": time.process_time() - c0}

    w0, c0 = time.perf_counter(), time.process_time()
    scalar = [min_contact(a, b, table=svm) for a, b in zip(e1.tolist(), e2.tolist())]
    out["scalar_calls"] = {"wall_s": time.perf_counter() - w0, "cpu_s": time.process_time() - c0}

    def num(v):
        return np.nan if v is None else v

    reps = 5
    for key, kw in (("array_warm", {}), ("array_no_bound", {"ideal_bound": False})):
        w0, c0 = time.perf_counter(), time.process_time()
        for _ in range(reps):
            arr = min_contact(e1, e2, table=svm, **kw)
        out[key] = {"wall_s": (time.perf_counter() - w0) / reps, "cpu_s": (time.process_time() - c0) / reps}
        fields = [("value", [num(a.value) for a in scalar])]
        if not kw:  # without the bound only the value is the scalar call's (the interval stops at the bound)
            fields += [("low", [num(a.interval[0]) for a in scalar]), ("high", [num(a.interval[1]) for a in scalar]),
                       ("ideal", [num(a.ideal_bound.value) for a in scalar])]
        out[key]["equals_scalar_calls"] = all(np.allclose(getattr(arr, f), np.array(v, dtype=float), rtol=1e-12,
                                                          atol=0.0, equal_nan=True) for f, v in fields)
    out["answered"] = int(np.isfinite(arr.value).sum())
    out["speedup_cpu"] = out["scalar_calls"]["cpu_s"] / out["array_warm"]["cpu_s"]
    out["speedup_cpu_no_bound"] = out["scalar_calls"]["cpu_s"] / out["array_no_bound"]["cpu_s"]

    print("min_contact(35000, 20000), median per call (wall / CPU):")
    for key, label in (("by_name", "tables named by string (target <= 0.5 ms)"),
                       ("loaded_tables", "loaded Table objects"),
                       ("new_pair_each_call", "a new pair each call (bound computed)")):
        r = out[key]
        print(f"  {label:<46} {r['wall_ms_median']:8.3f} ms / {r['cpu_ms_median']:.3f} ms  ({r['calls']} calls)")
    print("every other question, tables named by string, median per call (wall / CPU; target <= 0.5 ms):")
    for label, r in out["other_questions_by_name"].items():
        print(f"  {label:<46} {r['wall_ms_median']:8.3f} ms / {r['cpu_ms_median']:.3f} ms  ({r['calls']} calls)")
    c, s_, a, nb = out["array_cold"], out["scalar_calls"], out["array_warm"], out["array_no_bound"]
    print(f"{args.n:,} different pairs, loaded tables ({out['answered']:,} answered):")
    print(f"  array call, bounds cold (closed form, vectorized) {c['wall_s']:8.3f} s wall / {c['cpu_s']:.3f} s CPU"
          f"  ({1e3 * c['cpu_s'] / args.n:.2f} ms CPU per query)")
    print(f"  scalar calls, bounds cached                  {s_['wall_s']:8.3f} s wall / {s_['cpu_s']:.3f} s CPU")
    print(f"  array call, bounds cached                    {a['wall_s'] * 1e3:8.1f} ms wall / {a['cpu_s'] * 1e3:.1f} ms CPU"
          f"; equal to the scalar calls: {a['equals_scalar_calls']}")
    print(f"  array call, ideal_bound=False                {nb['wall_s'] * 1e3:8.1f} ms wall / {nb['cpu_s'] * 1e3:.1f} ms CPU"
          f"; equal to the scalar calls: {nb['equals_scalar_calls']}")
    print(f"  speed-up of the array call (CPU, target >= 50x)  {out['speedup_cpu']:8.0f}x"
          f"  ({out['speedup_cpu_no_bound']:.0f}x without the bound)")
    if args.json:
        args.json.write_text(json.dumps(out, indent=2))
    return out


if __name__ == "__main__":
    main()
