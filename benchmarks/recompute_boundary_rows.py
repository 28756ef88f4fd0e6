"""Recompute, in a sweep's finished chunks, the references whose guided search needs an anchor in another block.

Before the fix in CHANGELOG ("A table depended on `--blocks` after all"), an anchor row lying in another
block was searched from floor 0 instead of the ideal observer's floor. The fix changes the search of
exactly the rows whose anchors lie outside their chunk's block (with ``blocks: 2`` and 500 intervals:
249-255); every other row's floor, path and cells are unchanged. This script recomputes those rows with
the current engine in each finished chunk of a work folder and rewrites the chunk (its ``J``, ``J_lo``,
``J_hi``, their cells and fits; its compute time grows by the recomputation's); ``designkit sweep ...
--resume`` then assembles the table. It is how the shipped ``svm-fine`` was brought up to the fix (a
rebuild from scratch is about 5 CPU hours); on a 12-chunk sweep it gave the content hash of a rebuild from
scratch. Work on a COPY of the work folder::

    cp -r build/svm-fine build/svm-fine-fixed
    python benchmarks/recompute_boundary_rows.py build/svm-fine-fixed --jobs 2
    designkit sweep --config tables/svm-fine.yaml --workdir build/svm-fine-fixed --resume --uncompressed --out tables/
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np


def recompute(workdir: str, name: str) -> tuple[str, int, bool]:
    """``(chunk file, rows recomputed, whether anything changed)`` for one chunk, rewritten in place."""
    from threadpoolctl import threadpool_limits

    from designkit.sweep.chunk import ChunkResult, _svm_staircases, ideal_floor
    from designkit.sweep.config import SweepConfig, check_chunk
    from designkit.sweep.run import _save_chunk
    from designkit.sweep.scorer import PairScorer
    from designkit.sweep.search import ANCHOR_EVERY, with_anchors

    cfg = SweepConfig.from_mapping(json.loads((Path(workdir) / "sweep.json").read_text())["config"])
    path = Path(workdir) / "chunks" / name
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    res = ChunkResult.from_arrays(arrays)
    check_chunk(arrays, cfg, res.point, res.block, res.contact_index, path)  # its identity: this sweep's chunk
    t0 = time.process_time()
    n, rows = cfg.intervals, res.rows
    in_block = set(rows.tolist())  # the rows whose guided search needs an anchor outside the block: the anchors
    # every ANCHOR_EVERY of the builds this script fixes (engine version 4's top anchors came after the fix)
    aff = np.array([i for i in rows.tolist()
                    if not set(with_anchors([i], n, ANCHOR_EVERY, super_every=None).tolist()) <= in_block],
                   dtype=np.int64)
    if aff.size == 0 or cfg.fidelity != "svm" or cfg.full_matrix or not cfg.ideal_bound:
        return name, 0, False
    with threadpool_limits(limits=1):
        sensor = cfg.resolved_sensor()
        scene = cfg.scene(res.point, cfg.contact_s[res.contact_index])
        floor = ideal_floor(cfg, sensor, scene, rows)  # the floor the fixed engine searches from
        if floor is None:  # no closed form: nothing was searched from an ideal floor
            return name, 0, False
        assert np.array_equal(floor[rows], res.J_ideal)
        scorer = PairScorer(cfg, sensor, scene)
        new = dict(zip(("J", "J_lo", "J_hi"), _svm_staircases(cfg, scorer, aff, floor)))
    at = np.searchsorted(rows, aff)
    J = {k: getattr(res, k).copy() for k in ("J", "J_lo", "J_hi")}
    for k in J:
        J[k][at] = new[k]
    mine = set(aff.tolist())
    fresh = np.array([(i, j, c.mean, c.stderr, c.reps) for (i, j), c in scorer.scored.items() if i in mine],
                     dtype=np.float64).reshape(-1, 5)
    cells = np.concatenate([res.cells[~np.isin(res.cells[:, 0].astype(np.int64), aff)], fresh])
    cells = cells[np.lexsort((cells[:, 1], cells[:, 0]))]  # as a chunk stores them: sorted by (i, j)
    changed = not (all(np.array_equal(J[k], getattr(res, k)) for k in J) and np.array_equal(cells, res.cells))
    _save_chunk(path, ChunkResult(res.point, res.block, res.contact_index, rows, J["J"], J["J_lo"], J["J_hi"],
                                  res.J_ideal, int(cells[:, 4].sum()), cells,
                                  res.wall_s + time.process_time() - t0), cfg)
    return name, int(aff.size), changed


def main(argv=None) -> int:
    from joblib import Parallel, delayed

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("workdir", help="a COPY of the sweep's work folder (its chunks are rewritten)")
    p.add_argument("--jobs", type=int, default=1)
    args = p.parse_args(argv)
    names = sorted(f.name for f in (Path(args.workdir) / "chunks").glob("*.npz"))
    t = time.perf_counter()
    got = Parallel(n_jobs=args.jobs)(delayed(recompute)(args.workdir, name) for name in names)
    print(f"{len(names)} chunks: {sum(1 for g in got if g[1])} with rows beside a block boundary "
          f"({sum(g[1] for g in got)} rows recomputed), {sum(1 for g in got if g[2])} changed; "
          f"{time.perf_counter() - t:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
