"""Issue 33's speed targets of the question layer, this tree against a baseline revision in the same run.

Run from the repository root::

    python benchmarks/bench_new_pair.py                  # against 2bf154e (before the array-native table route)
    python benchmarks/bench_new_pair.py --rev HEAD~3 --pairs 60 --runs 5

1. **A single new pair in-process** (target at most 1 ms): ``min_contact(e1, e2)`` on the default table,
   the tables already opened, each pair asked once (nothing in the per-process memos): the median over
   ``--pairs`` random pairs inside the grid (seeded), in a fresh process per tree, the trees interleaved.
2. **10,000 new pairs as one array call** (target at most 2 s): ``min_contact(e1, e2)`` with arrays of
   ``--array`` random pairs inside the grid (seeded), in a fresh process per tree (the tables opened first).
3. **``designkit matrix --set paper12``** from a fresh shell (target at most 1 s wall): median wall over
   ``--runs`` runs of ``python -m designkit matrix --set paper12``, trees interleaved.

The baseline is ``git archive`` of ``--rev`` into a temporary folder, imported through ``PYTHONPATH``
(the tables are read from each tree's own ``tables/``).
"""

from __future__ import annotations

import argparse
import io
import json
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

SINGLE = r"""
import json, sys, time
import numpy as np
from designkit.query import min_contact
min_contact(35000.0, 20000.0)  # the tables opened, the caches of the sensor filled
rng = np.random.default_rng(int(sys.argv[1]))
pairs = rng.uniform(2000.0, 39000.0, size=(int(sys.argv[2]), 2))
times = []
for a, b in pairs.tolist():
    if abs(a - b) < 500.0:
        continue
    t0 = time.perf_counter()
    min_contact(a, b)
    times.append(time.perf_counter() - t0)
print(json.dumps(times))
"""


ARRAY = r"""
import json, sys, time
import numpy as np
from designkit.query import min_contact
min_contact(35000.0, 20000.0)  # the tables opened
rng = np.random.default_rng(int(sys.argv[1]))
pairs = rng.uniform(2000.0, 39000.0, size=(int(sys.argv[2]), 2))
pairs[:, 1] = np.where(np.abs(pairs[:, 0] - pairs[:, 1]) < 500.0, pairs[:, 0] + 500.0, pairs[:, 1])
t0 = time.perf_counter()
min_contact(pairs[:, 0], pairs[:, 1])
print(json.dumps(time.perf_counter() - t0))
"""


def _tree(rev: str, into: Path) -> Path:
    data = subprocess.run(["git", "-C", str(ROOT), "archive", rev], check=True, capture_output=True).stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        tar.extractall(into, filter="data")
    return into


def _env(tree: Path) -> dict:
    return {**os.environ, "PYTHONPATH": str(tree)}


def single_pair(tree: Path, seed: int, pairs: int) -> list[float]:
    out = subprocess.run([sys.executable, "-c", SINGLE, str(seed), str(pairs)], cwd=tree, env=_env(tree),
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def array_call(tree: Path, seed: int, pairs: int) -> float:
    out = subprocess.run([sys.executable, "-c", ARRAY, str(seed), str(pairs)], cwd=tree, env=_env(tree),
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def matrix_wall(tree: Path) -> float:
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "designkit", "matrix", "--set", "paper12"], cwd=tree, env=_env(tree),
                   check=True, capture_output=True)
    return time.perf_counter() - t0


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rev", default="2bf154e", help="baseline revision (git archive)")
    p.add_argument("--array", type=int, default=10000, help="new pairs in the array call")
    p.add_argument("--pairs", type=int, default=40, help="new pairs per process")
    p.add_argument("--runs", type=int, default=5, help="runs of each measurement per tree")
    a = p.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="dk-bench-") as tmp:
        trees = {"this tree": ROOT, f"baseline {a.rev}": _tree(a.rev, Path(tmp))}
        single: dict[str, list[float]] = {k: [] for k in trees}
        matrix: dict[str, list[float]] = {k: [] for k in trees}
        arrays: dict[str, list[float]] = {k: [] for k in trees}
        for run in range(a.runs):
            for name, tree in trees.items():  # interleaved: the machine's load falls on both alike
                single[name] += single_pair(tree, 100 + run, a.pairs)
                matrix[name].append(matrix_wall(tree))
                if run < 2:  # (seconds each)
                    arrays[name].append(array_call(tree, 200 + run, a.array))
        print(f"| figure | {' | '.join(trees)} | target |")
        print("|---|" + "---|" * (len(trees) + 1))
        med = {k: 1e3 * statistics.median(v) for k, v in single.items()}
        print("| single new pair, median [ms] | " + " | ".join(f"{v:.2f}" for v in med.values()) + " | <= 1 |")
        aw = {k: statistics.median(v) for k, v in arrays.items()}
        print(f"| {a.array:,} new pairs, one array call, median [s] | " + " | ".join(f"{v:.2f}" for v in aw.values())
              + " | <= 2 |")
        mw = {k: statistics.median(v) for k, v in matrix.items()}
        print("| matrix --set paper12, median wall [s] | " + " | ".join(f"{v:.2f}" for v in mw.values())
              + " | <= 1 |")
        base = list(trees)[1]
        print(f"\nratios (baseline / this tree): single pair {med[base] / med['this tree']:.2f}x, "
              f"array {aw[base] / aw['this tree']:.2f}x, matrix {mw[base] / mw['this tree']:.2f}x; "
              f"{len(single['this tree'])} pairs and {a.runs} matrix runs per tree; load "
              f"{os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
