"""Scoring interval pairs by the paper's SVM: cross-validated F1 with repeats near the threshold.

Each pair's F1 carries a standard error (delta method on the confusion
counts; with repeats, the larger of that and the spread of the repeats).
Pairs within ``z`` standard errors of the threshold are re-scored with fresh
seeds (up to ``max_repeats``). Trials are rendered by the sweep's forward
model; an interval's features are a deterministic function of (interval,
repeat), so a bounded cache never changes a result.

Two solvers score a fit (``SweepConfig.solver``): ``sklearn``, scikit-learn's
pipeline one pair at a time (the reference), and ``batched`` (the default; ``batched-cupy``
is the same code on CuPy arrays, ``batched-array-api`` that code on numpy),
:func:`~designkit.recognition.batched_svm.batched_cv_f1` on every pair a
search step asks for at once (the same classifier; predictions can differ
from the reference's only on near-ties). Batches are cut so that their
inputs stay under :data:`BATCH_MB`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from cachetools import LRUCache

from .._validation import InputError
from ..recognition.features import feature_matrix
from ..scene import Scene
from ..sensor import Sensor
from ..simulation import draw_trials, render_trials, touch_picks, window_times_s
from .config import SweepConfig

__all__ = ["BATCH_MB", "CHUNK_PAIRS", "CV_KEY", "ENGINE_VERSION", "FEATURE_CACHE_MB", "PairCell", "PairScorer", "array_namespace",
           "batch_pairs"]

#: Seed-key suffix of the fold-shuffle streams (distinguishes them from the trial streams).
CV_KEY = 7919

#: Version of the arithmetic that turns a config into a table (features, solver, search path), recorded in
#: every table's header (``engine_version``; a table without one is version 1) and in a sweep's working folder.
#: The same config gives the same bytes on every run, split and backend of one version; another version
#: rounds or searches differently, so its answers may move within their Monte Carlo intervals. What each
#: version changed: docs/engine.md ("Engine version 2", "3", "4").
ENGINE_VERSION = 4


@dataclass
class PairCell:
    """Scores of one pair (i, j) so far."""

    f1: list[float] = field(default_factory=list)
    se: list[float] = field(default_factory=list)

    @property
    def reps(self) -> int:
        return len(self.f1)

    @property
    def mean(self) -> float:
        return float(np.mean(self.f1))

    @property
    def stderr(self) -> float:
        r = len(self.f1)
        var_fold = float(np.mean(np.square(self.se)))
        var_rep = float(np.var(self.f1, ddof=1)) if r >= 2 else 0.0
        return math.sqrt(max(var_fold, var_rep) / r)


#: Feature cache of one chunk [MiB]: bounds a sweep worker's memory whatever the grid (at 10 s,
#: 200 Hz and 100 trials an interval's features take 3 MiB, so 500 intervals would take 1.5 GiB).
FEATURE_CACHE_MB = 512

#: Working memory of one batched-solver chunk [MiB]: the stacked features of its pairs plus the
#: solver's own arrays. Together with the feature cache it keeps a worker under 1 GB.
BATCH_MB = 128

#: Most pairs in one batched-solver call (beyond this a batch is no faster per pair).
MAX_BATCH = 64

#: Pairs the batched solver stacks and solves together inside a call (its ``chunk_size``) on numpy's
#: fast path; a call itself carries every pair of a search step (bounded by the feature cache, not by
#: this). The array-API path (``batched-cupy``, ``batched-array-api``) stacks the whole batch
#: (:func:`batch_pairs`): on a GPU each array operation is a kernel launch whatever its size, so a
#: stack of 8 pairs left it launch-bound. A pair's arithmetic does not depend on its neighbours in the
#: stack, so the chunk size changes no result (tests/test_engine.py builds the same table both ways).
CHUNK_PAIRS = 8


def array_namespace(solver: str):
    """Array namespace of a batched solver's name (``batched``: numpy; ``batched-cupy``: CuPy;
    ``batched-array-api``: numpy through array_api_compat, the GPU's code path).

    Raises :class:`~designkit.InputError` (one line) where the library is not installed.

    Examples
    --------
    >>> array_namespace("batched").__name__
    'numpy'
    """
    from ..recognition.batched_svm import array_library

    return array_library(solver.partition("-")[2] or "numpy")


def batch_pairs(trials: int, n_samples: int, folds: int = 3) -> int:
    """Pairs the batched solver may stack at once within :data:`BATCH_MB` (0: not even one pair fits).

    Per pair: the two classes' features stacked and centered (``2 x 2 trials x
    2 n_samples`` float64 values), each fold's standardized training touches
    (float32) and the Gram and KKT matrices of ``(n_train + 1)^2`` float64 values.

    Parameters
    ----------
    trials : int
        Touches per interval.
    n_samples : int
        Samples per touch (the feature count is twice this).
    folds : int
        Cross-validation folds.

    Returns
    -------
    int
        Pairs per solver chunk, at most :data:`MAX_BATCH`.

    Examples
    --------
    >>> batch_pairs(100, 400)   # 2 s at 200 Hz
    37
    >>> batch_pairs(100, 100_000)  # 500 s at 200 Hz: one pair would need about 0.5 GiB
    0
    """
    d = 2 * n_samples
    n_train = 2 * trials - (2 * trials) // folds
    per_pair = 2 * (2 * trials) * d * 8 + n_train * d * 4 + 4 * (n_train + 1) ** 2 * 8
    return int(min(MAX_BATCH, BATCH_MB * 2**20 // per_pair))


class PairScorer:
    """SVM F1 of interval pairs for one scene, with repeats and caches local to a chunk."""

    def __init__(self, cfg: SweepConfig, sensor: Sensor, scene: Scene):
        self.cfg = cfg
        self.sensor = sensor
        self.scene = scene
        # the recorder's window, from the scene's onset to its contact, as simulate_class reads a touch (the whole
        # contact from the onset on read a rig's touches 0.64 s longer than the exact route: answers that early)
        self.n_samples = window_times_s(sensor, scene).size
        self.edges = cfg.edges
        # features of (interval, seed), least recently used first; they are a deterministic function
        # of their key, so evicting one only costs its regeneration, never changes a result
        self._prepare = cfg.solver == "batched"  # numpy's batched path: cache PreparedFeatures
        # raw samples + slope: float64, or float32 deviations as the batched solver's numpy path keeps them
        per_entry = cfg.trials * 2 * self.n_samples * (4 if self._prepare else 8)
        self.max_features = max(8, int(FEATURE_CACHE_MB * 2**20 // max(per_entry, 1)))  # cache entries
        self._features: LRUCache[tuple[int, int], Any] = LRUCache(self.max_features)
        self.scored: dict[tuple[int, int], PairCell] = {}  # every pair scored so far
        self.fits = 0
        self.calls = 0  # batched-solver calls (fits / calls: pairs per call)

    def features(self, k: int, rep: int):
        """Features of interval ``k`` with seed ``rep``: the ``(trials, 2 n_samples)`` matrix, or with the
        ``batched`` solver its :class:`~designkit.recognition.batched_svm.PreparedFeatures` (what that
        solver reads; half the float64 matrix's bytes, prepared once per cache entry)."""
        key = (k, rep)
        feats = self._features.get(key)
        if feats is None:
            cfg = self.cfg
            draws = draw_trials(self.edges[k], self.edges[k + 1], cfg.trials, self.n_samples,
                                seed=[cfg.seed, k, rep],
                                vary_sensor=cfg.sensor_temp_spread_c > 0,
                                vary_ambient=cfg.ambient_temp_spread_c > 0)
            # a force ramp with the calibration touches' presses: each trial presses as one of them, picked from
            # the stream simulate_class picks from (the exact route's touches); the nominal press for all was
            # less varied than the rig, and its table answered earlier than --exact
            temps = render_trials(draws, self.sensor, self.scene, cfg.model, cfg.trial_diffusivity(),
                                  touch_picks(cfg.model, [cfg.seed, k, rep], cfg.trials)).temperature_c
            feats = feature_matrix(temps, self.sensor.sample_rate_hz, cfg.slope_window_s)
            if self._prepare:  # the batched solver's numpy path reads these (half the float64 matrix's bytes)
                from ..recognition.batched_svm import prepare_features

                feats = prepare_features(feats)
            self._features[key] = feats
        return feats

    def score_many(self, keys: list[tuple[int, int, int]]) -> list[tuple[float, float]]:
        """``(F1, standard error)`` of each ``(i, j, repeat)``, by the config's solver."""
        if self.cfg.solver == "sklearn":
            return [self.score(i, j, rep) for i, j, rep in keys]
        out: list[tuple[float, float]] = []
        for part, r in self._batched(keys):
            self.fits += len(part)
            self.calls += 1
            out += [(float(f), float(e)) for f, e in zip(r.f1, r.standard_error)]
        return out

    def decisions(self, keys: list[tuple[int, int, int]]) -> np.ndarray:
        """Cross-validated decision value of every touch of each ``(i, j, repeat)``, shape ``(len(keys), 2
        trials)``, with the batched solver, the features and the fold seeds the sweep scores that pair with
        (lower class first; >= 0 predicts the higher). Not counted as fits: what comparisons of the solver's
        arithmetic across machines read (``benchmarks/bench_machines.py``)."""
        return np.concatenate([r.decision for _, r in self._batched(keys)])

    def _batched(self, keys: list[tuple[int, int, int]]):
        """``(part of keys, BatchedF1)`` of each call of the batched solver that scores ``keys``."""
        from ..recognition.batched_svm import batched_cv_f1

        size = batch_pairs(self.cfg.trials, self.n_samples, self.cfg.folds)
        if size < 1:
            raise InputError(f"one pair of {self.cfg.trials} trials x {self.n_samples} samples does not fit "
                             f"in the batched solver's {BATCH_MB} MiB; use --solver sklearn")
        xp = array_namespace(self.cfg.solver)
        for part in self._calls(keys):
            # the solver stacks the features one chunk of `size` pairs at a time: a call of any length
            # needs one chunk's working memory, plus the features it references (bounded in _calls)
            yield part, batched_cv_f1([self.features(i, rep) for i, _, rep in part],
                                      [self.features(j, rep) for _, j, rep in part],
                                      seeds=[[self.cfg.seed, i, j, rep, CV_KEY] for i, j, rep in part],
                                      folds=self.cfg.folds, chunk_size=size if xp is not np else min(size, CHUNK_PAIRS),
                                      xp=xp)

    def _calls(self, keys: list[tuple[int, int, int]]):
        """Consecutive runs of ``keys`` whose distinct feature matrices fit a quarter of the feature cache.

        A call holds every feature matrix it references until it returns, cached or not, so
        this bounds a call's features to a quarter of the cache's budget (:data:`FEATURE_CACHE_MB`)
        on top of the cache itself; at 2 s of contact a whole search step fits one call.
        """
        cap = max(2, self.max_features // 4)
        part: list[tuple[int, int, int]] = []
        seen: set[tuple[int, int]] = set()
        for i, j, rep in keys:
            new = {(i, rep), (j, rep)} - seen
            if part and len(seen) + len(new) > cap:
                yield part
                part, seen = [], set()
                new = {(i, rep), (j, rep)}
            part.append((i, j, rep))
            seen |= new
        if part:
            yield part

    def cells(self, pairs: list[tuple[int, int]]) -> list[PairCell]:
        """:meth:`cell` of many pairs: each round of repeats scored as one batch."""
        out = []
        for i, j in pairs:
            if (i, j) not in self.scored:
                self.scored[(i, j)] = PairCell()
            out.append(self.scored[(i, j)])
        while True:
            need = sorted({(i, j) for (i, j), c in zip(pairs, out) if self._unsettled(c)})
            if not need:
                return out
            keys = [(i, j, self.scored[(i, j)].reps) for i, j in need]
            for (i, j, _), (f, s) in zip(keys, self.score_many(keys)):
                self.scored[(i, j)].f1.append(f)
                self.scored[(i, j)].se.append(s)

    def _unsettled(self, c: PairCell) -> bool:
        cfg = self.cfg
        return c.reps < cfg.max_repeats and (c.reps == 0 or abs(c.mean - cfg.threshold) < cfg.z * c.stderr)

    def score(self, i: int, j: int, rep: int) -> tuple[float, float]:
        from ..recognition.svm import f1_from_features

        r = f1_from_features(self.features(i, rep), self.features(j, rep), folds=self.cfg.folds,
                             seed=[self.cfg.seed, i, j, rep, CV_KEY])
        self.fits += 1
        return r.f1, r.standard_error

    def cell(self, i: int, j: int) -> PairCell:
        """Score (i, j), adding repeats while the verdict is within z standard errors of Phi."""
        return self.cells([(i, j)])[0]

