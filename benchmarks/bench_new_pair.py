"""Issue 33's speed targets of the question layer, this tree against a baseline revision in the same run.

Run from the repository root (one command; the figures are CPU seconds of each child process, the machine's
load is printed beside them)::

    python benchmarks/bench_new_pair.py                  # against e9a377f (before the critical-noise grid)
    python benchmarks/bench_new_pair.py --rev HEAD~3 --pairs 60 --runs 3

1. **A single new pair in-process** (target at most 1 ms): ``min_contact(e1, e2)`` on the default table, each
   pair asked once (no per-pair memo holds it), the median over ``--pairs`` random pairs inside the grid
   (seeded), in a fresh process per tree, the trees interleaved. Two figures: *cold*, the tables opened by one
   question first (the table's critical-noise grid, :class:`designkit.query.efficiency.CriticalNoiseGrid`,
   still mostly unsolved: the first questions of a process solve the nodes they read), and *warm*, after one
   array call of ``--array`` other pairs (the grid then holds the nodes a question reads; the baseline's
   per-process memos hold nothing of the new pairs either way).
2. **A repeated pair**: the same pair asked again (the median of ``--pairs`` asks of one pair).
3. **10,000 new pairs as one array call** (target at most 2 s): ``min_contact(e1, e2)`` with arrays of
   ``--array`` random pairs inside the grid (seeded), in a fresh process per tree (the tables opened first).
4. **``designkit matrix --set paper12``**: its compute in-process (``material_matrix(set="paper12")``, the
   tables opened first: what this helper's area owns) and its wall from a fresh shell (target at most 1 s;
   start-up is another part of issue 33).

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
seed, count, n_warm = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
min_contact(35000.0, 20000.0)  # the tables opened, the caches of the sensor filled
rng = np.random.default_rng(seed)
if n_warm:  # other pairs, one array call: what a table's per-table memo holds after it
    w = rng.uniform(2000.0, 39000.0, size=(n_warm, 2))
    min_contact(w[:, 0], w[:, 1])
pairs = rng.uniform(2000.0, 39000.0, size=(count, 2))
times = []
for a, b in pairs.tolist():
    if abs(a - b) < 500.0:
        continue
    t0 = time.process_time()
    min_contact(a, b)
    times.append(time.process_time() - t0)
rep = []
for _ in range(count):
    t0 = time.process_time()
    min_contact(pairs[0, 0], pairs[0, 1])
    rep.append(time.process_time() - t0)
print(json.dumps([times, rep]))
"""

ARRAY = r"""
import json, sys, time
import numpy as np
from designkit.query import min_contact
min_contact(35000.0, 20000.0)  # the tables opened
rng = np.random.default_rng(int(sys.argv[1]))
pairs = rng.uniform(2000.0, 39000.0, size=(int(sys.argv[2]), 2))
pairs[:, 1] = np.where(np.abs(pairs[:, 0] - pairs[:, 1]) < 500.0, pairs[:, 0] + 500.0, pairs[:, 1])
t0 = time.process_time()
min_contact(pairs[:, 0], pairs[:, 1])
print(json.dumps(time.process_time() - t0))
"""

MATRIX = r"""
import json, time
from designkit.query import min_contact
from designkit.query.matrix import material_matrix
min_contact(35000.0, 20000.0)  # the tables opened
t0 = time.process_time()
material_matrix(set="paper12")
print(json.dumps(time.process_time() - t0))
"""


def _tree(rev: str, into: Path) -> Path:
    data = subprocess.run(["git", "-C", str(ROOT), "archive", rev], check=True, capture_output=True).stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        tar.extractall(into, filter="data")
    return into


def _env(tree: Path) -> dict:
    return {**os.environ, "PYTHONPATH": str(tree)}


def _child(tree: Path, script: str, *args) -> object:
    out = subprocess.run([sys.executable, "-c", script, *map(str, args)], cwd=tree, env=_env(tree), check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def matrix_wall(tree: Path) -> float:
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "designkit", "matrix", "--set", "paper12"], cwd=tree, env=_env(tree),
                   check=True, capture_output=True)
    return time.perf_counter() - t0


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rev", default="e9a377f", help="baseline revision (git archive)")
    p.add_argument("--array", type=int, default=10000, help="new pairs in the array call")
    p.add_argument("--pairs", type=int, default=40, help="new pairs per process")
    p.add_argument("--runs", type=int, default=3, help="runs of each measurement per tree")
    a = p.parse_args(argv)
    loads = [os.getloadavg()[0]]
    with tempfile.TemporaryDirectory(prefix="dk-bench-") as tmp:
        trees = {"this tree": ROOT, f"baseline {a.rev}": _tree(a.rev, Path(tmp))}
        figs: dict[str, dict[str, list[float]]] = {k: {f: [] for f in ("cold", "warm", "repeat", "array", "mx",
                                                                         "mxwall")} for k in trees}
        for run in range(a.runs):
            for name, tree in trees.items():  # interleaved: the machine's load falls on both alike
                f = figs[name]
                cold, rep = _child(tree, SINGLE, 100 + run, a.pairs, 0)
                f["cold"] += cold
                f["repeat"] += rep
                f["warm"] += _child(tree, SINGLE, 100 + run, a.pairs, a.array)[0]
                f["array"].append(_child(tree, ARRAY, 200 + run, a.array))
                f["mx"].append(_child(tree, MATRIX))
                f["mxwall"].append(matrix_wall(tree))
                loads.append(os.getloadavg()[0])
        rows = [("single new pair, cold grid, median CPU [ms]", "cold", 1e3, "<= 1"),
                ("single new pair, warm grid, median CPU [ms]", "warm", 1e3, "<= 1"),
                ("repeated pair, median CPU [ms]", "repeat", 1e3, ""),
                (f"{a.array:,} new pairs, one array call, median CPU [s]", "array", 1.0, "<= 2"),
                ("matrix --set paper12 compute in-process, median CPU [s]", "mx", 1.0, ""),
                ("matrix --set paper12 from a fresh shell, median wall [s]", "mxwall", 1.0, "<= 1")]
        names = list(trees)
        print(f"| figure | {' | '.join(names)} | ratio | target |")
        print("|---|" + "---|" * (len(names) + 2))
        for label, key, scale, target in rows:
            v = [scale * statistics.median(figs[k][key]) for k in names]
            print(f"| {label} | " + " | ".join(f"{x:.3g}" for x in v) + f" | {v[1] / v[0]:.2f}x | {target} |")
        print(f"\n{len(figs['this tree']['cold'])} new pairs and {a.runs} runs per tree; load (1 min) "
              f"{min(loads):.1f}-{max(loads):.1f} over the run; ratio = baseline / this tree")


if __name__ == "__main__":
    main()
