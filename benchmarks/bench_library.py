"""The library as a program uses it: table queries in a loop, and many queries at once (issue 16).

Run from the repository root::

    /work/main/.venv/bin/python benchmarks/bench_library.py                 # all parts, 10,000 scalar calls
    /work/main/.venv/bin/python benchmarks/bench_library.py --n 2000 --json out.json

Measured in one process, on whatever machine runs it (CPU time per call as well
as wall time: on a shared machine wall time measures the neighbours):

1. ``designkit.query.min_contact(35000, 20000)`` in a loop, **tables named by
   string** (as the README shows): every call resolves, reads and hashes both
   table files (``svm-paper`` and the ideal bound ``ideal-paper``).
   Target: at most 0.5 ms per call.
2. The same with **loaded Table objects** (``load_table`` once, the objects
   passed to every call).
3. The same with a **per-process cache of verified tables** keyed by (path,
   mtime, size), as proposed for :mod:`designkit.query.table` (issue 16):
   emulated here outside the library (``_cached``: resolve the name, ``stat``
   both files, a dict hit), so the figure is what the change would give.
4. **10,000 queries as scalar calls** (loaded tables, different pairs): the
   total; the library has no array call yet.
5. The same 10,000 queries through a **prototype array call** written here in
   numpy (min-contact's value for effusivities given as numbers, one scene;
   the table route's rule, :mod:`designkit.tables.lookup`): checked equal to
   the scalar calls, and timed, as evidence for the proposed array-valued
   question calls. Target: at least 50x faster than 4.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import time
from pathlib import Path

import numpy as np

from designkit.query import min_contact
from designkit.tables.store import Table, load_table, resolve_table

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


_CACHE: dict[tuple, Table] = {}


def _cached(name: str) -> Table:
    """The proposed per-process cache, emulated: one verified load per (path, mtime, size) of both files."""
    npz = resolve_table(name)
    key = tuple((str(p), st.st_mtime_ns, st.st_size) for p in (npz, npz.with_suffix(".json"))
                for st in (os.stat(p),))
    hit = _CACHE.get(key)
    if hit is None:
        hit = _CACHE[key] = load_table(npz)
    return hit


def min_contact_array(e1, e2, table: Table, *, noise_c: float = 0.05, delta_t_c: float = 10.0) -> np.ndarray:
    """Prototype array call: min-contact's SVM value [s] for effusivities given as numbers (NaN: none).

    ``e1`` and ``e2`` broadcast like numpy; one scene (``noise_c``, ``delta_t_c``)
    on a table with a ``noise_ratio`` axis. Outside the effusivity grid or the
    scene grid: NaN (the scalar call answers None there).
    """
    from designkit.tables.lookup import axis_weights

    e1, e2 = np.broadcast_arrays(np.asarray(e1, dtype=np.float64), np.asarray(e2, dtype=np.float64))
    lo, hi = np.minimum(e1, e2), np.maximum(e1, e2)
    gap = hi - lo
    ax = table.axes
    centres, contacts, ratios = ax["e_ref"], ax["contact_s"], ax["noise_ratio"]
    pts = axis_weights(ratios, noise_c / abs(delta_t_c), log=True, grid=np.log(ratios))
    if pts is None:
        return np.full(lo.shape, np.nan)

    def interp(arr_name: str, e: np.ndarray) -> np.ndarray:  # [contact, ...e.shape]
        rows = sum(w * table.arrays[arr_name][r] for r, w in pts if w)  # [contact, centre]
        j = np.clip(np.searchsorted(centres, e, side="right") - 1, 0, centres.size - 2)
        w = np.clip((e - centres[j]) / (centres[j + 1] - centres[j]), 0.0, 1.0)
        a, b = rows[:, j], rows[:, j + 1]
        out = np.where(w == 0.0, a, a + w * (b - a))
        return np.where(e >= centres[-1], rows[:, -1:].reshape((-1,) + (1,) * e.ndim), out)

    up, down = interp("delta_up", lo), interp("delta_down", hi)
    need = np.where(np.isnan(up) | np.isnan(down), np.nan, np.maximum(up, down))  # NaN: beyond the grid
    ok = ~np.isnan(need) & (need <= gap)
    k = np.argmax(ok, axis=0)
    found = ok.any(axis=0)
    prev = np.where(k > 0, need[np.maximum(k - 1, 0), *np.indices(k.shape)], np.nan)
    cur = need[k, *np.indices(k.shape)]
    with np.errstate(divide="ignore", invalid="ignore"):
        w = np.where(prev != cur, (prev - gap) / (prev - cur), 1.0)
    x = np.where((k == 0) | np.isnan(prev), contacts[k], contacts[np.maximum(k - 1, 0)] + w * (
        contacts[k] - contacts[np.maximum(k - 1, 0)]))
    e_lo, e_hi = float(table.header["effusivity"]["min"]), float(table.header["effusivity"]["max"])
    inside = (lo > e_lo) & (hi <= e_hi)
    return np.where(found & inside, x, np.nan)


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000, help="queries in parts 4 and 5 (default 10,000)")
    ap.add_argument("--loop", type=int, default=50, help="calls timed in parts 1-3")
    ap.add_argument("--json", type=Path, help="also write the figures here")
    args = ap.parse_args(argv)

    svm, ideal = load_table("svm-paper"), load_table("ideal-paper")
    out: dict = {"n": args.n}
    out["by_name"] = _timed(lambda: min_contact(*PAIR, table="svm-paper", ideal_table="ideal-paper"), args.loop)
    out["loaded_tables"] = _timed(lambda: min_contact(*PAIR, table=svm, ideal_table=ideal), args.loop * 4)
    out["cached_by_name"] = _timed(lambda: min_contact(*PAIR, table=_cached("svm-paper"),
                                                       ideal_table=_cached("ideal-paper")), args.loop * 4)

    rng = np.random.default_rng(16)
    e_min, e_max = float(svm.header["effusivity"]["min"]), float(svm.header["effusivity"]["max"])
    e1 = rng.uniform(e_min + 100, e_max - 100, args.n)
    e2 = e1 + rng.uniform(200, 8000, args.n) * rng.choice([-1, 1], args.n)
    e2 = np.clip(e2, e_min + 100, e_max - 100)
    e2 = np.where(np.abs(e2 - e1) < 100, e1 + 150, e2)

    w0, c0 = time.perf_counter(), time.process_time()
    scalar = np.array([np.nan if (v := min_contact(a, b, table=svm, ideal_table=ideal).value) is None else v
                       for a, b in zip(e1.tolist(), e2.tolist())])
    out["scalar_calls"] = {"wall_s": time.perf_counter() - w0, "cpu_s": time.process_time() - c0}

    min_contact_array(e1[:10], e2[:10], svm)  # warm-up
    reps = 20
    w0, c0 = time.perf_counter(), time.process_time()
    for _ in range(reps):
        arr = min_contact_array(e1, e2, svm)
    out["array_prototype"] = {"wall_s": (time.perf_counter() - w0) / reps, "cpu_s": (time.process_time() - c0) / reps}
    agree = np.allclose(arr, scalar, rtol=1e-12, atol=0.0, equal_nan=True)
    out["array_prototype"]["equals_scalar_calls"] = bool(agree)
    out["array_prototype"]["answered"] = int(np.isfinite(scalar).sum())
    out["speedup_cpu"] = out["scalar_calls"]["cpu_s"] / out["array_prototype"]["cpu_s"]

    print(f"min_contact(35000, 20000), median per call (wall / CPU):")
    for key, label in (("by_name", "tables named by string"), ("loaded_tables", "loaded Table objects"),
                       ("cached_by_name", "by name, proposed (path, mtime, size) cache")):
        r = out[key]
        print(f"  {label:<46} {r['wall_ms_median']:8.3f} ms / {r['cpu_ms_median']:.3f} ms  ({r['calls']} calls)")
    s, a = out["scalar_calls"], out["array_prototype"]
    print(f"{args.n:,} different pairs, loaded tables:")
    print(f"  scalar calls                                  {s['wall_s']:8.3f} s wall / {s['cpu_s']:.3f} s CPU")
    print(f"  prototype array call (numpy, this file)       {a['wall_s'] * 1e3:8.3f} ms wall / "
          f"{a['cpu_s'] * 1e3:.3f} ms CPU; equal to the scalar calls: {agree} ({a['answered']} answered)")
    print(f"  speed-up (CPU)                                {out['speedup_cpu']:8.0f}x")
    if args.json:
        args.json.write_text(json.dumps(out, indent=2))
    return out


if __name__ == "__main__":
    main()
