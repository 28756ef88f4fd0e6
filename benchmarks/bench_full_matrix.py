"""The paper's Table I at its own resolution: what full F1 matrices of 500 intervals cost, from measured slices.

Run from the repository root::

    python benchmarks/bench_full_matrix.py --old-tree /tmp/oldtree [--blocks 100 --sample 10 50 90]

Table I counts indistinguishable pairs over all 124,750 pairs of the paper's 500 intervals at 2 s of contact,
one full matrix per sigma/dT (``tables/f1-matrix-2s.yaml`` has the five; 100 intervals there). This runs a few
blocks of reference rows of that matrix at 500 intervals (``full_matrix: true``, the batched solver, the
config's trials, folds, repeats and seed), each as a sweep worker runs it (``run_chunk``: one BLAS thread, the
steady heap) in a fresh process, with another source tree's code (``--old-tree``) and this tree's, alternately,
so that both see the same load. Printed per block and sigma/dT: CPU seconds, fits (repeats included), pairs,
CPU ms per fit, and whether both engines' F1 rows are identical; then the projected CPU of the whole matrices
(every row's ``n - 1 - i`` pairs at the CPU per pair of the sampled block nearest to it)
and their wall on 2 cores (CPU / 2: the chunks are independent). On a loaded machine CPU per fit is inflated (the
cores' other threads share their caches), so the same run also times a reference chunk whose idle cost is known
(``--reference``: svm-paper's staircase at sigma/dT 0.005 and 2 s, references 250-311, this tree's code; the
staircase's CPU per fit on 2 idle cores, ``--reference-ms``, from benchmarks/results/profile_chunk.txt times engine
version 2's 0.97) and scales the projection by idle / measured. No figure here is asserted anywhere.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

_WORKER = r"""
import json, sys, time
import numpy as np
from designkit.sweep.config import SweepConfig
from designkit.sweep.chunk import run_chunk
a = json.loads(sys.argv[1])
if a.get("reference"):
    cfg = SweepConfig.from_yaml(a["config"], noise_ratio=[0.005], contact_s=[2.0], blocks=8)
else:
    cfg = SweepConfig.from_yaml(a["config"], noise_ratio=[a["noise"]], contact_s=[2.0], intervals=a["intervals"],
                                blocks=a["blocks"], solver="batched", full_matrix=True)
t = time.process_time()
res = run_chunk(cfg, (0,), a["block"], 0)
cpu = time.process_time() - t
f1 = np.nan_to_num(res.f1_rows if res.f1_rows is not None else np.zeros((0, 1)), nan=-1.0)
print(json.dumps({"cpu_s": cpu, "fits": int(res.fits), "pairs": int(np.sum(f1 >= 0)), "rows": res.rows.tolist(),
                  "f1": f1.tobytes().hex()}))
"""


def run_one(tree: str, a: argparse.Namespace, noise: float, block: int, reference: bool = False) -> dict:
    env = {**os.environ, "PYTHONPATH": str(Path(tree).resolve()), "OPENBLAS_NUM_THREADS": "1",
           "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    config = a.reference if reference else a.config
    payload = json.dumps({"config": str(Path(config).resolve()), "noise": noise, "intervals": a.intervals,
                          "blocks": a.blocks, "block": block, "reference": reference})
    r = subprocess.run([sys.executable, "-c", _WORKER, payload], capture_output=True, text=True, env=env,
                       cwd=str(Path(tree).resolve()))
    if r.returncode != 0:
        raise SystemExit(f"error: block {block} failed with {tree}: "
                         f"{r.stderr.strip().splitlines()[-1] if r.stderr.strip() else r.returncode}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--old-tree", required=True, help="source tree of the engine to compare with")
    p.add_argument("--new-tree", default=".", help="source tree of the new engine (default: this one)")
    p.add_argument("--config", default="tables/f1-matrix-2s.yaml")
    p.add_argument("--intervals", type=int, default=500)
    p.add_argument("--noise-ratio", type=float, nargs="*", default=[0.005])
    p.add_argument("--blocks", type=int, default=100)
    p.add_argument("--sample", type=int, nargs="*", default=[10, 50, 90], help="blocks to run")
    p.add_argument("--settings", type=int, default=5, help="matrices in the table (distinct sigma/dT)")
    p.add_argument("--reference", default="tables/svm-paper.yaml", help="the reference chunk's config")
    p.add_argument("--reference-ms", type=float, default=2.93,
                   help="the reference chunk's CPU ms per fit on 2 idle cores")
    a = p.parse_args(argv)
    n = a.intervals
    print(f"# bench_full_matrix: {a.config} at {n} intervals, 2 s, sigma/dT {a.noise_ratio}, blocks {a.sample} of "
          f"{a.blocks}; old {a.old_tree}, new {a.new_tree}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; "
          f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}", flush=True)
    print("  sigma/dT  block  pairs   old: CPU [s]  fits  ms/fit   new: CPU [s]  fits  ms/fit   new/old   same F1",
          flush=True)
    per_pair = {"old": [], "new": []}
    for noise in a.noise_ratio:
        for k, block in enumerate(a.sample):
            row = {}
            order = (("old", a.old_tree), ("new", a.new_tree)) if k % 2 == 0 else \
                (("new", a.new_tree), ("old", a.old_tree))
            for name, tree in order:
                row[name] = run_one(tree, a, noise, block)
            o, w = row["old"], row["new"]
            for name in ("old", "new"):
                per_pair[name].append(row[name]["cpu_s"] / max(row[name]["pairs"], 1))
            ratio = (w["cpu_s"] / max(w["fits"], 1)) / (o["cpu_s"] / max(o["fits"], 1))
            print(f"  {noise:8g} {block:6d} {w['pairs']:6d}   {o['cpu_s']:11.1f} {o['fits']:5d} "
                  f"{1e3 * o['cpu_s'] / max(o['fits'], 1):7.2f}   {w['cpu_s']:11.1f} {w['fits']:5d} "
                  f"{1e3 * w['cpu_s'] / max(w['fits'], 1):7.2f}   {ratio:7.3f}   {o['f1'] == w['f1']}", flush=True)
    ref = run_one(a.new_tree, a, 0.005, 4, reference=True)
    ref_ms = 1e3 * ref["cpu_s"] / max(ref["fits"], 1)
    idle = a.reference_ms / ref_ms
    print(f"reference chunk (svm-paper staircase, 2 s, this tree): {ref['cpu_s']:.1f} CPU s, {ref['fits']} fits, "
          f"{ref_ms:.2f} ms/fit here against {a.reference_ms:.2f} idle: idle/here = {idle:.2f}")
    pairs = n * (n - 1) // 2
    # every row of the matrix at the CPU per pair of the sampled block nearest to it, weighted by its n - 1 - i
    # pairs (a row near the top has few partners, all near it: costlier per pair), averaged over the sigma/dT
    rows_of = [(b * n // a.blocks + (b + 1) * n // a.blocks - 1) / 2 for b in a.sample]
    nearest = [min(range(len(rows_of)), key=lambda k: abs(rows_of[k] - i)) for i in range(n)]
    weight = [sum(n - 1 - i for i in range(n) if nearest[i] == k) / pairs for k in range(len(rows_of))]
    for name in ("old", "new"):
        per = [per_pair[name][q * len(a.sample):(q + 1) * len(a.sample)] for q in range(len(a.noise_ratio))]
        mean = sum(sum(w * c for w, c in zip(weight, row)) for row in per) / len(per)
        per_pair[name] = [mean]
        cpu = pairs * mean * a.settings
        print(f"{name}: {1e3 * mean:.2f} ms CPU per pair (repeats included; blocks weighted {[round(w, 2) for w in weight]}); "
              f"{a.settings} matrices of {pairs:,} pairs: {cpu:,.0f} CPU s here ({cpu / 2 / 60:.1f} min on 2 cores at "
              f"this load), {cpu * idle:,.0f} CPU s and {cpu * idle / 2 / 60:.1f} min on 2 idle cores")
    print(f"load average at end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
