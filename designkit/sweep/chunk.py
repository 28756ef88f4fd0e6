"""One chunk of a sweep: the staircases of one (scene point, block of references, contact time).

A chunk is the unit of parallelism and of resumable state. It finds the
ideal observer's staircase where the forward model allows a closed form (the
floor of the SVM search), then walks three staircases on one cache of SVM
scores: ``mean >= Phi`` gives delta, ``mean + z se >= Phi`` its lower end and
``mean - z se >= Phi`` its upper end. A chunk depends on nothing but the
config and its own coordinates (no hints from other chunks), so the table is
the same however the sweep is split.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable, Mapping, Sequence

import numpy as np

from ..scene import Scene
from ..sensor import Sensor
from .config import SweepConfig
from .scorer import PairCell, PairScorer
from .search import (ANCHOR_EVERY, IDEAL_UNKNOWN, closed_form_model, ideal_bound_s, ideal_staircase,
                     staircase_search, staircase_searches, with_anchors)

__all__ = ["ChunkResult", "estimated_costs", "run_chunk", "run_scene", "search_window"]


@dataclass(frozen=True)
class ChunkResult:
    """Staircases of one (scene point, block, contact) chunk.

    Attributes
    ----------
    point : tuple of int
        Index on the scene axes (:attr:`SweepConfig.scene_axes`).
    block : int
        Block of references (:meth:`SweepConfig.blocks_of`).
    contact_index : int
        Index in :attr:`SweepConfig.contact_s`.
    rows : ndarray of int
        The block's reference intervals.
    J, J_lo, J_hi : ndarray of int
        First distinguishable partner of each row, and its Monte Carlo interval
        (``intervals`` where none is in the grid).
    J_ideal : ndarray of int
        The ideal observer's ``J`` (:data:`~designkit.sweep.search.IDEAL_UNKNOWN`
        where the model has no closed form here).
    fits : int
        SVM fits made (repeats included).
    cells : ndarray, shape (k, 5)
        Every scored pair: ``i, j``, mean F1, standard error, repeats.
    wall_s : float
        Compute time [s].
    f1_rows : ndarray, optional
        Full-matrix mode: F1 of ``(row, j)`` for every ``j``.
    """

    point: tuple[int, ...]
    block: int
    contact_index: int
    rows: np.ndarray
    J: np.ndarray
    J_lo: np.ndarray
    J_hi: np.ndarray
    J_ideal: np.ndarray
    fits: int
    cells: np.ndarray
    wall_s: float
    f1_rows: np.ndarray | None = None

    def to_arrays(self) -> dict[str, np.ndarray]:
        out = {
            "point": np.asarray(self.point, dtype=np.int64),
            "block": np.asarray(self.block),
            "contact_index": np.asarray(self.contact_index),
            "rows": self.rows, "J": self.J, "J_lo": self.J_lo, "J_hi": self.J_hi,
            "J_ideal": self.J_ideal, "fits": np.asarray(self.fits), "cells": self.cells,
            "wall_s": np.asarray(self.wall_s),
        }
        if self.f1_rows is not None:
            out["f1_rows"] = self.f1_rows
        return out

    @classmethod
    def from_arrays(cls, a: Mapping[str, np.ndarray]) -> "ChunkResult":
        return cls(point=tuple(int(x) for x in a["point"]), block=int(a["block"]),
                   contact_index=int(a["contact_index"]), rows=a["rows"], J=a["J"], J_lo=a["J_lo"],
                   J_hi=a["J_hi"], J_ideal=a["J_ideal"], fits=int(a["fits"]), cells=a["cells"],
                   wall_s=float(a["wall_s"]), f1_rows=a["f1_rows"] if "f1_rows" in a else None)


def run_chunk(cfg: SweepConfig, point: tuple[int, ...], block: int, contact_index: int) -> ChunkResult:
    """Compute one chunk (a picklable top-level function for joblib/dask workers).

    A chunk is the unit of parallelism: everything inside it runs sequentially in its
    worker, with joblib's local backend (scikit-learn's own joblib calls are not sent back
    to a dask cluster), BLAS and LAPACK on one thread (the same floating-point order
    whatever the worker count) and freed arrays kept for reuse
    (:func:`~designkit._workers.steady_heap`). scipy's LAPACK (the solver's) is imported
    before the thread limit is set, so that the limit reaches it. Why, with the measurements:
    docs/decisions-log.md.
    """
    import scipy.linalg.lapack  # noqa: F401  (the solver's LAPACK: loaded now, so that the limit below reaches it)
    from joblib import parallel_config
    from threadpoolctl import threadpool_limits

    from .._workers import steady_heap

    with parallel_config(backend="sequential"), threadpool_limits(limits=1), steady_heap():
        return _run_chunk(cfg, point, block, contact_index)


def _run_chunk(cfg: SweepConfig, point, block: int, contact_index: int) -> ChunkResult:
    t0 = time.perf_counter()
    sensor = cfg.resolved_sensor()
    scene = cfg.scene(point, cfg.contact_s[contact_index])
    rows = cfg.blocks_of()[block]
    floor = ideal_floor(cfg, sensor, scene, rows)
    J_ideal = floor[rows] if floor is not None else np.full(rows.size, IDEAL_UNKNOWN, dtype=np.int64)

    if cfg.fidelity == "ideal":
        J = _ideal_mc_staircase(cfg, sensor, scene, rows, floor) if cfg.varied else J_ideal
        return ChunkResult(point, block, contact_index, rows, J, J.copy(), J.copy(), J_ideal, 0,
                           np.zeros((0, 5)), time.perf_counter() - t0)

    scorer = PairScorer(cfg, sensor, scene)
    f1_rows = None
    if cfg.full_matrix:
        f1_rows, (J, J_lo, J_hi) = _full_matrix(cfg, scorer, rows)
    else:
        J, J_lo, J_hi = _svm_staircases(cfg, scorer, rows, floor if cfg.ideal_bound else None)
    # the chunk's own rows only: the anchors of a guided search outside the block are scored here too,
    # but counted (and kept) by the chunk they belong to, so fits and cells do not depend on the split
    own = set(rows.tolist())
    cells = np.array([(i, j, c.mean, c.stderr, c.reps) for (i, j), c in sorted(scorer.scored.items()) if i in own],
                     dtype=np.float64).reshape(-1, 5)
    fits = int(cells[:, 4].sum()) if not cfg.full_matrix else scorer.fits
    return ChunkResult(point, block, contact_index, rows, J, J_lo, J_hi, J_ideal, fits,
                       cells, time.perf_counter() - t0, f1_rows)


def ideal_floor(cfg: SweepConfig, sensor: Sensor, scene: Scene, rows) -> np.ndarray | None:
    """The ideal observer's ``J`` (closed form), a lower bound of every ``J``, for ``rows`` and the anchor rows
    their guided search starts from (:func:`~designkit.sweep.search.with_anchors`), indexed by interval (0
    elsewhere); None where the model and scene have no closed form.

    The anchors get it too, inside the block or not: an anchor searched from another floor than in its own
    block may find another crossing of noisy decisions, and the rows guessed from it would follow.
    """
    if closed_form_model(cfg, sensor, scene) is None:
        return None
    need = with_anchors(rows, cfg.intervals, ANCHOR_EVERY)
    floor = np.zeros(cfg.intervals, dtype=np.int64)
    floor[need] = ideal_staircase(cfg, sensor, ideal_bound_s(cfg, sensor, scene), need)
    return floor


def _svm_staircases(cfg: SweepConfig, scorer: PairScorer, rows, floor):
    """``J``, ``J_lo``, ``J_hi`` of the SVM by guided staircase search on one cache of scores.

    Every search step's probes go to the scorer as one batch (the batched solver
    scores them together; the reference solver one by one). Rows are searched in
    windows of consecutive references (:func:`search_window`) so that the features a
    window's probes need stay in the scorer's bounded cache; a row's answer does not
    depend on the window it is searched in
    (:func:`~designkit.sweep.search.staircase_searches`).
    """
    n, phi, z = cfg.intervals, cfg.threshold, cfg.z

    def by(*ks: float):
        def decide(probes):
            cells = scorer.cells([(i, j) for _, i, j in probes])
            return [c.mean + ks[s] * c.stderr >= phi for (s, _, _), c in zip(probes, cells)]
        return decide

    rows = np.asarray(rows, dtype=np.int64)
    out = {name: np.full(rows.size, n, dtype=np.int64) for name in ("J", "J_lo", "J_hi")}
    W = search_window(scorer)
    for w in np.unique(rows // W):
        part = np.flatnonzero(rows // W == w)
        ext = with_anchors(rows[part], n, ANCHOR_EVERY)
        where = np.searchsorted(ext, rows[part])
        # J and J_lo in lockstep (one scorer call per step for both); J_hi starts from J, so after it
        J, J_lo = staircase_searches([(ext, floor), (ext, floor)], n, by(0.0, z), anchor_every=ANCHOR_EVERY)
        (J_hi,) = staircase_searches([(ext, _full(J, ext, n))], n, by(-z), anchor_every=ANCHOR_EVERY)
        for name, v in (("J", J), ("J_lo", J_lo), ("J_hi", J_hi)):
            out[name][part] = v[where]
    return out["J"], out["J_lo"], out["J_hi"]


#: The SVM's need over the ideal observer's, for :func:`estimated_costs` only (an ordering, not a result):
#: svm-paper's noise efficiency at 2 s of contact.
_SVM_OVER_IDEAL = 1.7


def estimated_costs(cfg: SweepConfig, point: tuple[int, ...], contact_index: int) -> np.ndarray:
    """Relative cost of each block of one scene point and contact, to hand the costly chunks out first.

    Nothing computed depends on it. An SVM chunk's cost is its staircase searches: about ``1 + log2(g)``
    probes for a reference whose partner is ``g`` intervals away, next to nothing where the partner lies
    beyond the grid; each probe a fit over ``contact_s`` seconds of samples. ``g`` is guessed as
    ``1.7`` times the closed-form ideal observer's (at every :data:`ANCHOR_EVERY`-th reference, one
    vectorized call for all blocks); where no closed form holds, every reference counts 1.
    """
    blocks = cfg.blocks_of()
    contact = float(cfg.contact_s[contact_index])
    sizes = np.array([b.size for b in blocks], dtype=np.float64)
    if cfg.fidelity == "ideal":
        return contact * sizes
    sensor = cfg.resolved_sensor()
    scene = cfg.scene(point, contact)
    if closed_form_model(cfg, sensor, scene) is None:
        return contact * sizes
    sample = [b[::ANCHOR_EVERY] for b in blocks]
    rows = np.concatenate(sample)
    gap = _SVM_OVER_IDEAL * (ideal_staircase(cfg, sensor, ideal_bound_s(cfg, sensor, scene), rows) - rows)
    live = rows + gap < cfg.intervals
    probes = np.where(live, 1.0 + np.log2(np.maximum(gap, 1.0)), 0.0)
    ends = np.cumsum([r.size for r in sample])[:-1]
    return contact * ANCHOR_EVERY * np.array([p.sum() for p in np.split(probes, ends)])


def search_window(scorer: PairScorer) -> int:
    """References searched together: a multiple of the anchor spacing whose features fit the scorer's cache.

    A window's probes reach about three times its width of intervals, each with up to
    two seeds; a sixth of the cache per window leaves room for the partners' spread.
    """
    A = ANCHOR_EVERY
    return max(A, scorer.max_features // 12 // A * A)


def _full_matrix(cfg: SweepConfig, scorer: PairScorer, rows):
    """Score every pair above each row; ``(f1_rows, (J, J_lo, J_hi))`` without assuming monotonicity."""
    n, phi, z = cfg.intervals, cfg.threshold, cfg.z
    f1_rows = np.full((rows.size, n), np.nan, dtype=np.float32)
    for r, i in enumerate(rows):
        # a row's pairs in one call of the solver, each round of repeats as one batch (the search's repeat
        # rule; a pair's arithmetic does not depend on the pairs beside it, so the same cells as pair by pair,
        # which cost the batched solver 1.4-1.6x the CPU per fit at 500 intervals: bench_full_matrix.py)
        cells = scorer.cells([(int(i), j) for j in range(int(i) + 1, n)])
        f1_rows[r, i + 1:] = [c.mean for c in cells]
    staircases = tuple(_first_crossing(scorer, rows, n, lambda c, k=k: c.mean + k * c.stderr >= phi)
                       for k in (0.0, z, -z))
    return f1_rows, staircases


def _full(J_rows: np.ndarray | None, rows: np.ndarray, n: int) -> np.ndarray | None:
    if J_rows is None:
        return None
    out = np.full(n, n, dtype=np.int64)
    out[rows] = J_rows
    return out


def _first_crossing(scorer: PairScorer, rows, n, ok: Callable[[PairCell], bool]) -> np.ndarray:
    """Full-matrix rule: the first partner above i whose score passes, no monotonicity assumed."""
    out = np.full(len(rows), n, dtype=np.int64)
    for r, i in enumerate(rows):
        for j in range(i + 1, n):
            if ok(scorer.scored[(i, j)]):
                out[r] = j
                break
    return out


def _ideal_mc_staircase(cfg: SweepConfig, sensor: Sensor, scene: Scene, rows, floor) -> np.ndarray:
    """Ideal observer with varied initial conditions: Monte Carlo F1 per pair on the staircase."""
    from ..recognition.ideal import ideal_pair

    edges = cfg.edges
    cache: dict[tuple[int, int], float] = {}

    def decide(i, j):
        if (i, j) not in cache:
            r = ideal_pair((edges[i], edges[i + 1]), (edges[j], edges[j + 1]), sensor, scene,
                           n_mc=max(200, cfg.trials * 5), seed=[cfg.seed, i, j], model=cfg.model)
            cache[(i, j)] = r.f1
        return cache[(i, j)] >= cfg.threshold

    return staircase_search(decide, rows, cfg.intervals, floor=floor)


def run_scene(cfg: SweepConfig, point: tuple[int, ...] = (0,), *,
              contact_indices: Sequence[int] | None = None) -> list[ChunkResult]:
    """All blocks and contact times of one scene point, in-process (library convenience)."""
    return [run_chunk(cfg, tuple(point), b, k)
            for k in (range(len(cfg.contact_s)) if contact_indices is None else contact_indices)
            for b in range(len(cfg.blocks_of()))]
