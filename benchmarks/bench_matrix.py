"""``designkit matrix --set paper12`` from a fresh shell against a baseline tree, in one run (issue 33: at most 1 s).

Run from the repository root::

    git archive a467a6c designkit designkit_lab tables | tar -x -C /tmp/base   # the tree to compare with
    python -m compileall -q designkit /tmp/base/designkit
    python benchmarks/bench_matrix.py --runs 5 --baseline /tmp/base

Each tree's ``python -m designkit matrix --set paper12 --json`` runs ``--runs`` times as a new process, round
robin (a neighbour's load spreads over both), after one warm-up each; printed: the median wall and CPU time
(user + sys of the child) of each, their ratio, and how far the new multi-class ideal accuracy curve lies from
the baseline's at full precision (the matrix cells must be equal). In-process, the multi-class curve alone is
timed too.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
COMMAND = ["-m", "designkit", "matrix", "--set", "paper12", "--json"]


def _run(tree: Path) -> tuple[float, float, dict]:
    """Wall and CPU seconds of one fresh ``designkit matrix`` run in ``tree`` (first on the path), and its JSON."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    t0 = time.perf_counter()
    p = subprocess.Popen([sys.executable, *COMMAND], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env,
                         cwd=tree)
    out = p.stdout.read()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"designkit matrix failed in {tree}")
    return wall, usage.ru_utime + usage.ru_stime, json.loads(out)


_CURVE = """
import json, time
from designkit.query.matrix import _multiclass, resolve_materials
from designkit.query.table_open import DEFAULT_TABLE, as_table
mats, tab = resolve_materials((), set="paper12"), as_table(DEFAULT_TABLE)
def curve():
    return _multiclass(mats, tab, noise_c=0.05, delta_t_c=10.0, svm_trials=None, seed=0, step=lambda: None)
curve()
t0 = time.process_time()
acc = curve().ideal_accuracy
print(json.dumps({"cpu": time.process_time() - t0, "acc": acc.tolist()}))
"""


def _curve(tree: Path) -> dict:
    """The multi-class ideal curve of paper12 computed in ``tree`` (full precision) and its CPU seconds (after a
    warm-up, in-process)."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    return json.loads(subprocess.run([sys.executable, "-c", _CURVE], capture_output=True, text=True, env=env,
                                     cwd=tree, check=True).stdout)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--baseline", type=Path, help="another designkit tree (e.g. a checkout of main)")
    args = ap.parse_args(argv)
    trees = {"this tree": REPO, **({"baseline": args.baseline} if args.baseline else {})}
    times = {name: [] for name in trees}
    docs = {name: _run(tree)[2] for name, tree in trees.items()}  # warm-up (and the answers)
    for _ in range(args.runs):
        for name, tree in trees.items():
            wall, cpu, _ = _run(tree)
            times[name].append((wall, cpu))
    print(f"designkit matrix --set paper12, median of {args.runs} fresh runs (load average {os.getloadavg()[0]:.2f}):")
    med = {name: (statistics.median(w for w, _ in t), statistics.median(c for _, c in t)) for name, t in times.items()}
    for name, (wall, cpu) in med.items():
        print(f"  {name:10s} wall {wall * 1e3:7.0f} ms   CPU {cpu * 1e3:7.0f} ms   target wall <= 1000 ms")
    curves = {name: _curve(tree) for name, tree in trees.items()}
    for name, c in curves.items():
        print(f"  multi-class ideal curve alone, {name}: CPU {c['cpu'] * 1e3:.0f} ms (in-process)")
    if args.baseline:
        (w0, c0), (w1, c1) = med["baseline"], med["this tree"]
        print(f"  ratio this/baseline: wall {w1 / w0:.2f}x, CPU {c1 / c0:.2f}x")
        new, old = docs["this tree"], docs["baseline"]
        a, b = curves["this tree"]["acc"], curves["baseline"]["acc"]
        diff = [x - y for x, y in zip(a, b)]
        print(f"  ideal accuracy curve, this - baseline: min {min(diff):+.2e}, max {max(diff):+.2e} "
              f"({len(a)} contact times, full precision); in the --json: "
              f"{'equal' if new['multiclass'] == old['multiclass'] else 'DIFFERENT'}")
        same = new["matrix"] == old["matrix"]
        print(f"  matrix cells equal to the baseline's: {same}")


if __name__ == "__main__":
    main()
