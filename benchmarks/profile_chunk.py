"""Where a sweep chunk's CPU goes: simulation and features, each solver stage, the search (issue 12).

Run from the repository root::

    python benchmarks/profile_chunk.py                          # svm-paper, sigma/dT 0.005, 2 s, block 1 of 2
    python benchmarks/profile_chunk.py --contact 10 --blocks 10 --block 3

One chunk of ``tables/svm-paper.yaml`` (one sigma/dT, one contact time, one block of
references), run as a sweep worker runs it (``run_chunk``: BLAS on one thread). CPU
seconds of this process (``time.process_time``) per reference and per SVM fit, split
into: simulation + features (rendering trials, Savitzky-Golay slopes, preparing them
for the solver), the batched solver's stages (its own ``timings``), and the rest
(search bookkeeping, the ideal observer's floor). Also: fits and distinct pairs per
reference, feature matrices built (a bounded cache may rebuild some), solver calls
and pairs per call. This is a profile, not a comparison: run it before and after a
change (same chunk, similar load; the load average is printed).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

from designkit.recognition import batched_svm
from designkit.sweep import chunk, scorer
from designkit.sweep.config import SweepConfig


def profile(config: str, noise: float, contact: float, blocks: int, block: int) -> dict:
    cfg = SweepConfig.from_yaml(config, noise_ratio=[noise], contact_s=[contact], blocks=blocks)
    T: dict[str, float] = {}
    made: list = []
    orig_init, orig_features, orig_f1 = scorer.PairScorer.__init__, scorer.PairScorer.features, batched_svm.batched_cv_f1

    def init(self, *a, **k):
        orig_init(self, *a, **k)
        made.append(self)

    def features(self, k, rep):
        t = time.process_time()
        T["builds"] = T.get("builds", 0) + ((k, rep) not in self._features)
        out = orig_features(self, k, rep)
        T["features"] = T.get("features", 0.0) + time.process_time() - t
        return out

    def f1(*a, **k):
        t = time.process_time()
        out = orig_f1(*a, timings=T, **k)
        T["solver"] = T.get("solver", 0.0) + time.process_time() - t
        return out

    scorer.PairScorer.__init__, scorer.PairScorer.features, batched_svm.batched_cv_f1 = init, features, f1
    try:
        t = time.process_time()
        res = chunk.run_chunk(cfg, (0,), block, 0)
        cpu = time.process_time() - t
    finally:
        scorer.PairScorer.__init__, scorer.PairScorer.features, batched_svm.batched_cv_f1 = (
            orig_init, orig_features, orig_f1)
    stages = {k: T.get(k, 0.0) for k in ("folds", "standardize", "gram", "solve", "predict")}
    split = {"simulation + features": T.get("features", 0.0), **stages,
             "solver glue": T.get("solver", 0.0) - sum(stages.values()),
             "search, bookkeeping, ideal floor": cpu - T.get("solver", 0.0) - T.get("features", 0.0)}
    sc = made[0] if made else None
    return {"rows": int(res.rows.size), "fits": int(res.fits), "pairs": int(len(res.cells)), "cpu_s": cpu,
            "builds": int(T.get("builds", 0)), "calls": sc.calls if sc else 0, "fits_run": sc.fits if sc else 0,
            "split": split}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--config", default="tables/svm-paper.yaml")
    p.add_argument("--noise-ratio", type=float, default=0.005)
    p.add_argument("--contact", type=float, default=2.0)
    p.add_argument("--blocks", type=int, default=2)
    p.add_argument("--block", type=int, default=1)
    a = p.parse_args(argv)
    print(f"# {' '.join(sys.argv)}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; "
          f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}; {os.cpu_count()} cores")
    r = profile(a.config, a.noise_ratio, a.contact, a.blocks, a.block)
    n, f = r["rows"], max(r["fits"], 1)
    print(f"sigma/dT {a.noise_ratio}, contact {a.contact} s, block {a.block} of {a.blocks}: {n} references, "
          f"{r['fits']} fits ({r['fits'] / n:.1f} per reference), {r['pairs']} pairs ({r['pairs'] / n:.1f} per "
          f"reference), {r['builds']} feature matrices built, {r['calls']} solver calls "
          f"({r['fits_run'] / max(r['calls'], 1):.1f} pairs per call)")
    print(f"CPU {r['cpu_s']:.2f} s: {1e3 * r['cpu_s'] / n:.1f} ms per reference, {1e3 * r['cpu_s'] / f:.2f} ms per fit")
    width = max(len(k) for k in r["split"])
    for k, v in r["split"].items():
        print(f"  {k:<{width}}  {1e3 * v / n:7.1f} ms/ref  {1e3 * v / f:6.2f} ms/fit  {100 * v / r['cpu_s']:5.1f} %")
    return 0


if __name__ == "__main__":
    np.seterr(all="ignore")
    raise SystemExit(main())
