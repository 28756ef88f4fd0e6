"""Scoring interval pairs by the paper's SVM: cross-validated F1 with repeats near the threshold.

Each pair's F1 carries a standard error (delta method on the confusion
counts; with repeats, the larger of that and the spread of the repeats).
Pairs within ``z`` standard errors of the threshold are re-scored with fresh
seeds (up to ``max_repeats``). Trials are rendered by the sweep's forward
model; an interval's features are a deterministic function of (interval,
repeat), so a bounded cache never changes a result.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from ..recognition.features import feature_matrix
from ..scene import Scene
from ..sensor import Sensor
from ..simulation import draw_trials, render_trials
from .config import SweepConfig

__all__ = ["CV_KEY", "FEATURE_CACHE_MB", "PairCell", "PairScorer"]

#: Seed-key suffix of the fold-shuffle streams (distinguishes them from the trial streams).
CV_KEY = 7919


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


class PairScorer:
    """SVM F1 of interval pairs for one scene, with repeats and caches local to a chunk."""

    def __init__(self, cfg: SweepConfig, sensor: Sensor, scene: Scene):
        self.cfg = cfg
        self.sensor = sensor
        self.scene = scene
        self.n_samples = sensor.times_s(scene.contact_s).size
        self.edges = cfg.edges
        # features of (interval, seed), least recently used first; they are a deterministic function
        # of their key, so evicting one only costs its regeneration, never changes a result
        self._features: OrderedDict[tuple[int, int], np.ndarray] = OrderedDict()
        per_entry = cfg.trials * 2 * self.n_samples * 8  # raw samples + slope, float64
        self._max_features = max(8, int(FEATURE_CACHE_MB * 2**20 // max(per_entry, 1)))
        self.cells: dict[tuple[int, int], PairCell] = {}
        self.fits = 0

    def features(self, k: int, rep: int) -> np.ndarray:
        key = (k, rep)
        feats = self._features.get(key)
        if feats is not None:
            self._features.move_to_end(key)
        else:
            cfg = self.cfg
            draws = draw_trials(self.edges[k], self.edges[k + 1], cfg.trials, self.n_samples,
                                seed=[cfg.seed, k, rep],
                                vary_sensor=cfg.sensor_temp_spread_c > 0,
                                vary_ambient=cfg.ambient_temp_spread_c > 0)
            temps = render_trials(draws, self.sensor, self.scene, cfg.model, cfg.trial_diffusivity()).temperature_c
            feats = feature_matrix(temps, self.sensor.sample_rate_hz, cfg.slope_window_s)
            self._features[key] = feats
            while len(self._features) > self._max_features:
                self._features.popitem(last=False)
        return feats

    def score(self, i: int, j: int, rep: int) -> tuple[float, float]:
        from ..recognition.svm import f1_from_features

        r = f1_from_features(self.features(i, rep), self.features(j, rep), folds=self.cfg.folds,
                             seed=[self.cfg.seed, i, j, rep, CV_KEY])
        self.fits += 1
        return r.f1, r.standard_error

    def cell(self, i: int, j: int) -> PairCell:
        """Score (i, j), adding repeats while the verdict is within z standard errors of Phi."""
        c = self.cells.get((i, j))
        if c is None:
            c = self.cells[(i, j)] = PairCell()
        cfg = self.cfg
        while c.reps < cfg.max_repeats and (c.reps == 0 or abs(c.mean - cfg.threshold) < cfg.z * c.stderr):
            f, s = self.score(i, j, c.reps)
            c.f1.append(f)
            c.se.append(s)
        return c

