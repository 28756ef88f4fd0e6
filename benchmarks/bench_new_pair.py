"""Issue 33's speed targets of the question layer, this tree against a baseline revision in the same run.

Run from the repository root (one command; the figures are CPU seconds of each child process, the machine's
load is printed beside them)::

    python benchmarks/bench_new_pair.py                  # against 624300e (stop 45's main)
    python benchmarks/bench_new_pair.py --breakdown      # also where a single pair's time goes, per piece
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
   tables opened first) and its wall from a fresh shell (target at most 1 s; start-up is another part of
   issue 33).
5. **The answers**: ``min_contact`` (at two noises) and ``max_noise`` (at 2 s) of ``--answers`` seeded random
   pairs in each tree: how many values changed, whether each lies inside the baseline's interval, how far
   the interval ends and the ideal bounds moved.
6. **numpy calls per single new pair** (warm grid): the numpy functions and array methods one ``min_contact`` of
   a new pair calls (``sys.setprofile``: calls from outside numpy into numpy's Python functions, its C functions
   and ndarray / ufunc methods; operators such as ``a + b`` are not calls and not counted), and the Python
   function calls; a single pair's cost is mostly numpy's per-call overhead on one-element arrays.
7. **Where a single new pair's time goes** (warm grid, ``--breakdown``): each piece of the table route's path
   wrapped with a timer (its own cost about 0.3 us a call), the median over 600 new pairs of each piece's
   inclusive wall time per answer, per tree (pieces a tree does not have are blank).

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

import numpy as np

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


ANSWERS = r"""
import json, sys
import numpy as np
from designkit.query import max_noise, min_contact
rng = np.random.default_rng(33)
n = int(sys.argv[1])
a, b = rng.uniform(2000.0, 39000.0, n), rng.uniform(2000.0, 39000.0, n)
b = np.where(np.abs(a - b) < 500.0, a + 500.0, b)
out = {}
for tag, ans in (("min-contact", min_contact(a, b)), ("min-contact at 0.02 degC", min_contact(a, b, noise_c=0.02)),
                 ("max-noise at 2 s", max_noise(a, b, contact_s=2.0))):
    out[tag] = [np.asarray(getattr(ans, k), dtype=float).tolist() for k in ("value", "low", "high", "ideal")]
print(json.dumps(out))
"""

CALLS = r"""
import json, sys
import numpy as np
from designkit.query import min_contact
min_contact(35000.0, 20000.0)
rng = np.random.default_rng(int(sys.argv[1]))
w = rng.uniform(2000.0, 39000.0, size=(3000, 2))
min_contact(w[:, 0], w[:, 1])
pairs = [p for p in rng.uniform(2000.0, 39000.0, size=(60, 2)).tolist() if abs(p[0] - p[1]) >= 500.0][:40]
for a, b in pairs:  # (the grid's nodes these pairs read, solved first)
    min_contact(a, b)
n = {"numpy": 0, "python": 0}

def count(frame, event, arg):
    if event == "call":
        n["python"] += 1
        n["numpy"] += "numpy" in frame.f_code.co_filename and "numpy" not in frame.f_back.f_code.co_filename
    elif event == "c_call":
        n["numpy"] += ((getattr(arg, "__module__", None) or "").startswith("numpy")
                       or isinstance(getattr(arg, "__self__", None), (np.ndarray, np.ufunc, np.generic)))

sys.setprofile(count)
for a, b in pairs:
    min_contact(a, b)
sys.setprofile(None)
print(json.dumps({k: v / len(pairs) for k, v in n.items()}))
"""

BREAKDOWN = r"""
import functools, importlib, json, statistics, sys, time
import numpy as np
from designkit.query import min_contact, table
min_contact(35000.0, 20000.0)
rng = np.random.default_rng(100)
w = rng.uniform(2000.0, 39000.0, size=(10000, 2))
min_contact(w[:, 0], w[:, 1])
pairs = [p for p in rng.uniform(2000.0, 39000.0, size=(1200, 2)).tolist() if abs(p[0] - p[1]) >= 500.0][:900]
for a, b in pairs[:300]:  # (the grid's nodes these pairs read, solved first)
    min_contact(a, b)
acc = {}

def wrap(spec):
    mod, attr = spec.rsplit(".", 1)
    owner, parts = importlib.import_module("designkit.query." + mod), attr.split(":")
    for p in parts[:-1]:
        owner = getattr(owner, p)
    f = getattr(owner, parts[-1], None)
    if f is None:
        return

    @functools.wraps(f)
    def timed(*a, **k):
        t0 = time.perf_counter()
        try:
            return f(*a, **k)
        finally:
            acc[spec] = acc.get(spec, 0.0) + time.perf_counter() - t0
    setattr(owner, parts[-1], timed)
    for m in list(sys.modules.values()):  # (the modules that imported the function by name)
        if getattr(m, "__name__", "").startswith("designkit.") and len(parts) == 1 and getattr(m, parts[-1], None) is f:
            setattr(m, parts[-1], timed)

for spec in sys.argv[1:]:
    wrap(spec)
table.EACH["min-contact"] = table.min_contact_each
per, total = [], []
for a, b in pairs[300:]:
    acc.clear()
    t0 = time.perf_counter()
    min_contact(a, b)
    total.append(time.perf_counter() - t0)
    per.append(dict(acc))
print(json.dumps({"total": statistics.median(total), **{k: statistics.median(r.get(k, 0.0) for r in per)
                                                        for k in sys.argv[1:]}}))
"""

#: The pieces of a single pair's path the breakdown times, outermost first (module.function; a method as
#: ``module.Class:method``), each with how it nests.
PIECES = (("questions._resolve", "route and scene (choose_route)"),
          ("table.min_contact_each", "the table route (below)"),
          ("table.open_table", "  open and check the table"),
          ("table._pairs", "  the pair's objects (materials rule)"),
          ("table_arrays.contact_arrays", "  the arrays (below)"),
          ("table_arrays.TableView:readings", "    read the needs (4 kinds, 2 directions)"),
          ("table_arrays.TableView:need", "    weigh the scene slices"),
          ("estimates.grid_crossing", "    the grid crossings"),
          ("efficiency.noise_k_min_contact", "    the noise efficiency (below)"),
          ("efficiency._k_readings", "      log k from the entries (below)"),
          ("table_arrays.TableView:critical_noise", "        the critical-noise grid (2 reads an entry, and the pair)"),
          ("ideal_bound.noise_k_contact", "      the first sample k s reaches s*"),
          ("ideal_bound.contact_at_noise", "    the ideal bound's first sample"),
          ("estimates.first_applicable", "    the estimators"),
          ("table._contact_answer", "  the Answer"),
          ("questions._finished", "route reason"))


def breakdown(trees: dict[str, Path]) -> None:
    """Print the median inclusive wall time [us] per answer of each piece of :data:`PIECES`, per tree."""
    got = {name: _child(tree, BREAKDOWN, *(p for p, _ in PIECES)) for name, tree in trees.items()}
    names = list(trees)
    print(f"| piece (inclusive, median us per answer) | {' | '.join(names)} |")
    print("|---|" + "---|" * len(names))
    for spec, label in (("total", "min_contact(e1, e2), wrapped"), *PIECES):
        cells = [f"{1e6 * got[n][spec]:.0f}" if got[n].get(spec) else "" for n in names]
        print(f"| {label} (`{spec}`) | " + " | ".join(cells) + " |")
    print()


def answers_changed(trees: dict[str, Path], n: int) -> None:
    """Count the answers of ``n`` seeded random pairs that differ between the trees, and whether each lies
    inside the baseline's interval."""
    new, old = (_child(tree, ANSWERS, n) for tree in trees.values())
    for tag in new:
        (v1, lo1, hi1, i1), (v0, lo0, hi0, i0) = (np.array(x, dtype=float) for x in new[tag]), \
            (np.array(x, dtype=float) for x in old[tag])
        same = (v0 == v1) | (np.isnan(v0) & np.isnan(v1))
        inside = ~same & (lo0 <= v1) & (v1 <= hi0)
        with np.errstate(invalid="ignore", divide="ignore"):
            ends = np.nanmax(np.abs(np.r_[lo1 / lo0, hi1 / hi0] - 1.0), initial=0.0)
            moved = np.nanmax(np.abs(v1[~same] / v0[~same] - 1.0), initial=0.0)
        ideal = int(np.sum(~((i0 == i1) | (np.isnan(i0) & np.isnan(i1)))))
        print(f"{tag}: {int((~same).sum())} of {n} values changed (at most {moved:.1e} relative), "
              f"{int(inside.sum())} of them inside the baseline's interval; interval ends moved at most "
              f"{ends:.1e} relative; {ideal} ideal bounds changed")


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
    p.add_argument("--rev", default="624300e", help="baseline revision (git archive)")
    p.add_argument("--array", type=int, default=10000, help="new pairs in the array call")
    p.add_argument("--pairs", type=int, default=40, help="new pairs per process")
    p.add_argument("--runs", type=int, default=3, help="runs of each measurement per tree")
    p.add_argument("--answers", type=int, default=3000, help="random pairs whose answers are compared (0: none)")
    p.add_argument("--breakdown", action="store_true", help="also time each piece of a single pair's path")
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
              f"{min(loads):.1f}-{max(loads):.1f} over the run; ratio = baseline / this tree\n")
        calls = {name: _child(tree, CALLS, 300) for name, tree in trees.items()}
        print(" | ".join(f"{name}: {c['numpy']:.0f} numpy calls, {c['python']:.0f} Python calls per single new pair"
                         for name, c in calls.items()) + "\n")
        if a.breakdown:
            breakdown(trees)
        if a.answers:
            answers_changed(trees, a.answers)


if __name__ == "__main__":
    main()
