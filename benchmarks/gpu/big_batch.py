"""How the GPU path's time per fit moves with the pairs stacked per solver call (an experiment, issue 35).

The sweep caps a batched-solver call's stack at ``MAX_BATCH`` pairs and ``BATCH_MB`` MiB (sized for a
CPU worker's 1 GB). On a GPU every array operation is a kernel launch whatever its size, so a larger
stack should cost about the same per call. This script raises both caps for one run (in this process
only) and prints the wall of the sweep and its fits::

    python benchmarks/gpu/big_batch.py CONFIG.yaml MAX_BATCH [--solver batched-cupy] [--blocks 1]
"""

from __future__ import annotations

import argparse
import tempfile
import time

from designkit.sweep import run_sweep, scorer
from designkit.sweep.config import SweepConfig
from designkit.tables.store import load_table


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("config")
    p.add_argument("max_batch", type=int)
    p.add_argument("--solver", default="batched-cupy")
    p.add_argument("--blocks", type=int, default=1)
    args = p.parse_args()
    scorer.MAX_BATCH = args.max_batch
    scorer.BATCH_MB = 64 * 1024
    cfg = SweepConfig.from_yaml(args.config, solver=args.solver, blocks=args.blocks)
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        path = run_sweep(cfg, d, out=f"{d}/t.npz", backend="sequential")
        wall = time.perf_counter() - t0
        fits = int(load_table(path).arrays["fits"].sum())
    print(f"{args.solver} max_batch={args.max_batch} blocks={args.blocks}: {fits} fits in {wall:.1f} s "
          f"({1e3 * wall / max(fits, 1):.2f} ms per fit)")


if __name__ == "__main__":
    main()
