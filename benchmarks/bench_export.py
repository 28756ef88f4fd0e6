"""Exports: size of a full table and of a one-scene slice in every format, and the time per
lookup of the C header, the stdlib-only Python module and designkit's own Python query.

Run from the repository root::

    /work/venv/bin/python benchmarks/bench_export.py                 # ideal-paper (and svm-paper if built)
    /work/venv/bin/python benchmarks/bench_export.py --table svm-paper --calls 200000

What it measures, printed as markdown tables:

1. Sizes [bytes] of the export of the whole table and of the one scene a robot
   needs (``--noise 0.05 --delta-t 10``), plus a narrower slice (contact 1-4 s,
   effusivity 15,000-36,000), in each format; ratios against the table's own
   files (npz + json) and slice against full.
2. Time per call of ``min_contact_s``, ``delta_e`` and ``distinguishable`` on
   random inputs inside the grid: the C header (compiled with ``cc -O2`` into a
   timing harness; the inputs are drawn once, outside the timed loop), the
   generated stdlib module, and ``designkit.query`` on a loaded table (the
   baseline; ``ideal_table=None`` so that it answers from the one table).
   Ratios are against the baseline measured in the same run.

Timings are wall clock on whatever machine runs it (2 shared cores when the
numbers in the issue's closing note were taken: expect noise of tens of %).
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from designkit.query import table as q
from designkit.export import FORMATS, render, slice_table
from designkit.tables.store import list_tables, load_table

NOISE_C, DELTA_T_C = 0.05, 10.0

HARNESS = r'''
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "designkit_table.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int main(int argc, char **argv)
{
    int n = atoi(argv[1]), reps = atoi(argv[2]), i, r;
    float *e1 = malloc(n * sizeof *e1), *e2 = malloc(n * sizeof *e2), *c = malloc(n * sizeof *c);
    float noise = (float)atof(argv[3]), dt = (float)atof(argv[4]);
    double sum = 0, t0, best[3] = {1e30, 1e30, 1e30};
    long yes = 0;
    for (i = 0; i < n; i++)
        if (scanf("%f %f %f", &e1[i], &e2[i], &c[i]) != 3) return 2;
    for (r = 0; r < reps; r++) {
        t0 = now();
        for (i = 0; i < n; i++) sum += designkit_min_contact_s(e1[i], e2[i], noise, dt);
        if (now() - t0 < best[0]) best[0] = now() - t0;
        t0 = now();
        for (i = 0; i < n; i++) sum += designkit_delta_e(e1[i], noise, dt, c[i]);
        if (now() - t0 < best[1]) best[1] = now() - t0;
        t0 = now();
        for (i = 0; i < n; i++) yes += designkit_distinguishable(e1[i], e2[i], noise, dt, c[i]);
        if (now() - t0 < best[2]) best[2] = now() - t0;
    }
    printf("%.6g %.6g %.6g %.17g %ld\n", 1e9 * best[0] / n, 1e9 * best[1] / n, 1e9 * best[2] / n, sum, yes);
    return 0;
}
'''

_CC_POSIX = ["-D_POSIX_C_SOURCE=199309L"]  # clock_gettime under -std=c99


def sizes(tab) -> list[tuple[str, dict[str, int]]]:
    full = slice_table(tab)
    one = slice_table(tab, noise_c=NOISE_C, delta_t_c=DELTA_T_C)
    narrow = slice_table(tab, noise_c=NOISE_C, delta_t_c=DELTA_T_C, contact="1:4", e_min=15000.0, e_max=36000.0)
    rows = []
    for label, exp in (("whole table", full), (f"one scene (noise {NOISE_C:g} degC, dT {DELTA_T_C:g} degC)", one),
                       ("one scene, contact 1-4 s, e 15,000-36,000", narrow)):
        rows.append((f"{label}: {' x '.join(str(n) for n in exp.shape)}",
                     {fmt: len(render(exp, fmt)) for fmt in FORMATS}))
    return rows


def inputs(tab, n: int, rng) -> np.ndarray:
    """Random in-grid (e1, e2, contact) as float32: e in the table's range, contact in its grid."""
    lo, hi = float(tab.header["effusivity"]["min"]), float(tab.header["effusivity"]["max"])
    c = tab.axes["contact_s"]
    return np.column_stack([rng.uniform(lo + 1, hi, n), rng.uniform(lo + 1, hi, n),
                            rng.uniform(c[0], c[-1], n)]).astype(np.float32)


def time_c(header: bytes, x: np.ndarray, reps: int, workdir: Path) -> tuple[float, float, float] | None:
    cc = shutil.which(os.environ.get("CC", "cc"))
    if cc is None:
        return None
    (workdir / "designkit_table.h").write_bytes(header)
    (workdir / "harness.c").write_text(HARNESS)
    exe = workdir / "harness"
    subprocess.run([cc, "-std=c99", "-O2", *_CC_POSIX, "-o", str(exe), str(workdir / "harness.c"), "-lm"], check=True)
    text = "\n".join(f"{a!r} {b!r} {c!r}" for a, b, c in x.astype(float).tolist())
    out = subprocess.run([str(exe), str(len(x)), str(reps), repr(NOISE_C), repr(DELTA_T_C)], input=text,
                         capture_output=True, text=True, check=True).stdout.split()
    return float(out[0]), float(out[1]), float(out[2])


def time_python(calls, x: np.ndarray, reps: int) -> tuple[float, float, float]:
    """Best-of-reps ns per call of (min_contact, delta_e, distinguishable) over the inputs."""
    best = [math.inf] * 3
    rows = x.astype(float).tolist()
    for _ in range(reps):
        for j, f in enumerate(calls):
            t0 = time.perf_counter()
            for a, b, c in rows:
                f(a, b, c)
            best[j] = min(best[j], time.perf_counter() - t0)
    return tuple(1e9 * t / len(rows) for t in best)


def module_from(src: bytes, workdir: Path, name: str):
    path = workdir / f"{name}.py"
    path.write_bytes(src)
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def stdlib_calls(mod):
    def mc(a, b, c):
        try:
            return mod.min_contact_s(a, b, NOISE_C, DELTA_T_C)
        except ValueError:
            return None

    def de(a, b, c):
        return mod.delta_e(a, NOISE_C, DELTA_T_C, c)

    def di(a, b, c):
        try:
            return mod.distinguishable(a, b, NOISE_C, DELTA_T_C, c)
        except ValueError:
            return None

    return mc, de, di


def query_calls(tab):
    def mc(a, b, c):
        return q.min_contact(a, b, noise_c=NOISE_C, delta_t_c=DELTA_T_C, table=tab, ideal_table=None) if a != b else None

    def de(a, b, c):
        return q.delta_e(a, contact_s=c, noise_c=NOISE_C, delta_t_c=DELTA_T_C, table=tab, ideal_table=None)

    def di(a, b, c):
        return q.distinguishable(a, b, contact_s=c, noise_c=NOISE_C, delta_t_c=DELTA_T_C, table=tab,
                                 ideal_table=None) if a != b else None

    return mc, de, di


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--table", action="append", help="table(s) to measure (default: ideal-paper, svm-paper if built)")
    ap.add_argument("--calls", type=int, default=100_000, help="C calls per function and repeat")
    ap.add_argument("--py-calls", type=int, default=150, help="Python query calls per function and repeat")
    ap.add_argument("--reps", type=int, default=2, help="repeats (best is reported)")
    args = ap.parse_args(argv)
    names = args.table or ["ideal-paper"] + (["svm-paper"] if "svm-paper" in list_tables() else [])
    rng = np.random.default_rng(0)
    for name in names:
        tab = load_table(name)
        own = tab.path.stat().st_size + tab.path.with_suffix(".json").stat().st_size
        print(f"\n## {name} ({tab.fidelity}; the table's own npz + json: {own:,} bytes)\n")
        print("| export | " + " | ".join(FORMATS) + " |")
        print("|---|" + "---:|" * len(FORMATS))
        rows = sizes(tab)
        for label, s in rows:
            print(f"| {label} | " + " | ".join(f"{s[f]:,}" for f in FORMATS) + " |")
        full = rows[0][1]
        for label, s in rows[1:]:
            print(f"| ratio to whole ({label.split(':')[0]}) | " + " | ".join(f"{s[f] / full[f]:.3f}" for f in FORMATS)
                  + " |")
        print("| whole / table's own files | " + " | ".join(f"{full[f] / own:.2f}" for f in FORMATS) + " |")

        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            x_c = inputs(tab, args.calls, rng)
            x_py = x_c[: args.py_calls]
            base = time_python(query_calls(tab), x_py, args.reps)
            print(f"\nTime per call [ns], inputs inside the grid (noise {NOISE_C:g} degC, dT {DELTA_T_C:g} degC); "
                  f"ratio = designkit.query / this:\n")
            print("| implementation | min_contact_s | delta_e | distinguishable | speed-up vs query |")
            print("|---|---:|---:|---:|---:|")
            print("| designkit.query (baseline, loaded table) | " + " | ".join(f"{t:,.0f}" for t in base) + " | 1 |")
            note = ("query.distinguishable also computes the ideal observer's F1 in closed form, which the "
                    "exports do not carry: most of its time")
            for label, exp in (("whole table", slice_table(tab)),
                               ("one scene", slice_table(tab, noise_c=NOISE_C, delta_t_c=DELTA_T_C))):
                mod = module_from(render(exp, "python"), tmp, f"mod_{len(exp.shape)}_{exp.shape[0]}")
                t_py = time_python(stdlib_calls(mod), x_c[: 20 * args.py_calls], args.reps)
                print(f"| stdlib module, {label} | " + " | ".join(f"{t:,.0f}" for t in t_py) + " | "
                      + " / ".join(f"{b / t:.0f}x" for b, t in zip(base, t_py)) + " |")
                sub = tmp / f"c_{label.replace(' ', '_')}"
                sub.mkdir()
                t_c = time_c(render(exp, "c"), x_c, args.reps, sub)
                if t_c is None:
                    print(f"| C header, {label} | (no C compiler) | | | |")
                    continue
                print(f"| C header -O2, {label} | " + " | ".join(f"{t:,.0f}" for t in t_c) + " | "
                      + " / ".join(f"{b / t:,.0f}x" for b, t in zip(base, t_c)) + " |")
            print(f"\n({note}.)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
