"""Sweep engine: delta(e), the smallest distinguishable effusivity difference, over a grid.

The paper's protocol (section IV): cut ``(e_min, e_max]`` into equal intervals
("material categories"), simulate ``trials`` touches per interval with ``e``
uniform inside it, score every pair of intervals by the SVM's cross-validated
F1, and call a pair distinguishable when ``F1 >= Phi``. ``delta(e)`` for a
reference interval is the smallest distance (in effusivity, between interval
centres) to a distinguishable interval, towards higher (``delta_up``) or lower
(``delta_down``) effusivity.

Computing only what the answer needs
------------------------------------
The naive route scores all ``n (n - 1) / 2`` pairs (124,750 for 500 intervals).
This engine scores a few per reference, and each shortcut is exact or tested:

* **sigma/dT invariance.** With fixed initial conditions and standardized
  features the F1 depends on noise and temperature difference only through
  ``sigma / dT`` (docs/physics.md, "Invariance"; tests/test_recognition.py), so one axis replaces
  two and every sweep is run at ``dT = 1``.
* **Staircase search.** Distinguishability is monotone in the pair's distance:
  if ``(i, j)`` is distinguishable so is ``(i - 1, j)`` and ``(i, j + 1)``. Hence
  ``J(i)``, the first distinguishable partner above ``i``, never decreases with
  ``i``, and ``J`` alone determines both directions of ``delta`` for every
  reference. ``J(i)`` is found by bracketing (from ``J(i - 1)`` upwards, with the
  neighbouring contact time's answer as the first guess) and bisection.
* **Ideal-observer certificate.** A pair whose ideal-observer F1 is below
  ``Phi`` cannot be distinguishable by any classifier, so the search starts at
  the ideal staircase (closed form, milliseconds) and never fits an SVM below it.
* **Warm start across contact times.** Contact times are swept in increasing
  order; the previous (shorter) contact's staircase bounds the next from above.
* **Trials generated once.** Noise is drawn time-major
  (:mod:`designkit.simulation`), so the trials of a shorter contact are exact
  prefixes of a longer one: drawing the shorter trials directly *is* truncating
  the long ones, bit for bit.

Monte Carlo error
-----------------
Each pair's F1 carries a standard error (delta method on the confusion
counts; with repeats, the larger of that and the spread of the repeats). Pairs
within ``z`` standard errors of ``Phi`` are re-scored with fresh seeds (up to
``max_repeats``). Three staircases are walked on the same cached scores:
``mean >= Phi`` gives delta, ``mean + z se >= Phi`` its lower end and
``mean - z se >= Phi`` its upper end.

Execution
---------
Work is cut into chunks, one per (scene point, block of references, contact
time), run through joblib (local processes, or a dask cluster) and written
atomically as they finish; an interrupted sweep resumes without recomputing
finished chunks and gives bit-identical results.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import time
from collections import OrderedDict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping, Sequence

import numpy as np

from .._validation import InputError, check_positive
from ..recognition.features import DEFAULT_SLOPE_WINDOW_S, feature_matrix
from ..recognition.ideal import ideal_scores, projection_noise
from ..scene import Scene
from ..sensor import Sensor, load_sensor
from ..simulation import draw_trials, render_trials

__all__ = [
    "ChunkResult",
    "SweepConfig",
    "SweepInterrupted",
    "delta_from_staircase",
    "run_scene",
    "run_sweep",
    "staircase_search",
]

FIDELITIES = ("svm", "ideal")
_CV_KEY = 7919  # distinguishes fold-shuffle streams from trial streams


# ============================================================ configuration
@dataclass(frozen=True)
class SweepConfig:
    """Everything that determines a sweep's result.

    Fixed initial conditions use the ``noise_ratio`` axis (sigma / dT); varied
    initial conditions (``sensor_temp_spread_c`` or ``ambient_temp_spread_c``
    > 0) need the ``noise_c`` and ``delta_t_c`` axes, because the invariance
    no longer holds.
    """

    name: str = "sweep"
    sensor: str = "paper"
    fidelity: str = "svm"
    e_min: float = 0.0
    e_max: float = 40000.0
    intervals: int = 500
    trials: int = 100
    folds: int = 3
    threshold: float = 0.9
    seed: int = 0
    max_repeats: int = 4
    z: float = 2.0
    noise_ratio: tuple[float, ...] | None = (0.005,)
    noise_c: tuple[float, ...] | None = None
    delta_t_c: tuple[float, ...] | None = None
    ambient_temp_c: float = 25.0
    sensor_temp_spread_c: float = 0.0
    ambient_temp_spread_c: float = 0.0
    contact_s: tuple[float, ...] = (1.0, 2.0, 3.0, 4.0)
    sample_rate_hz: float | None = None
    slope_window_s: float = DEFAULT_SLOPE_WINDOW_S
    blocks: int = 1
    full_matrix: bool = False
    ideal_bound: bool = True

    def __post_init__(self) -> None:
        def tup(name: str) -> None:
            v = getattr(self, name)
            if v is None:
                return
            if isinstance(v, (int, float)):
                v = (v,)
            vals = tuple(float(x) for x in v)
            if not vals:
                raise InputError(f"sweep axis {name} is empty")
            object.__setattr__(self, name, vals)

        for name in ("noise_ratio", "noise_c", "delta_t_c", "contact_s"):
            tup(name)
        if self.fidelity not in FIDELITIES:
            raise InputError(f"fidelity must be one of {', '.join(FIDELITIES)}, got {self.fidelity!r}")
        if not (0 <= self.e_min < self.e_max < math.inf):
            raise InputError(f"effusivity range must satisfy 0 <= min < max < inf, got ({self.e_min:g}, {self.e_max:g}]")
        if int(self.intervals) != self.intervals or self.intervals < 2:
            raise InputError(f"intervals must be an integer >= 2, got {self.intervals}")
        if int(self.folds) != self.folds or self.folds < 2:
            raise InputError(f"folds must be >= 2, got {self.folds}")
        if int(self.trials) != self.trials or self.trials < self.folds:
            raise InputError(f"trials per interval ({self.trials}) must be at least the number of folds ({self.folds})")
        if not (2 / 3 < self.threshold < 1):
            raise InputError(f"threshold must be in (2/3, 1) (F1 of a blind all-positive guess is 2/3), got {self.threshold:g}")
        if int(self.max_repeats) != self.max_repeats or self.max_repeats < 1:
            raise InputError(f"max_repeats must be >= 1, got {self.max_repeats}")
        check_positive("z", self.z)
        if int(self.blocks) != self.blocks or self.blocks < 1:
            raise InputError(f"blocks must be >= 1, got {self.blocks}")
        if self.seed < 0 or int(self.seed) != self.seed:
            raise InputError(f"seed must be a non-negative integer, got {self.seed}")
        contacts = self.contact_s
        if any(not (c > 0 and math.isfinite(c)) for c in contacts) or list(contacts) != sorted(set(contacts)):
            raise InputError(f"contact times must be positive, finite, increasing and distinct, got {list(contacts)}")
        if self.varied:
            if self.noise_c is None or self.delta_t_c is None:
                raise InputError("varied initial conditions need the noise_c and delta_t_c axes "
                                 "(sigma/dT invariance does not hold there)")
            if self.noise_ratio is not None:
                raise InputError("give either noise_ratio (fixed conditions) or noise_c and delta_t_c, not both")
        else:
            if (self.noise_c is None) != (self.delta_t_c is None):
                raise InputError("noise_c and delta_t_c go together")
            if self.noise_c is not None and self.noise_ratio is not None:
                raise InputError("give either noise_ratio or noise_c and delta_t_c, not both")
            if self.noise_c is None and self.noise_ratio is None:
                raise InputError("no noise axis: give noise_ratio (sigma/dT) or noise_c and delta_t_c")
        for name, vals in (("noise_ratio", self.noise_ratio), ("noise_c", self.noise_c)):
            if vals is not None and any(not (v >= 0 and math.isfinite(v)) for v in vals):
                raise InputError(f"{name} values must be finite and >= 0, got {list(vals)}")
        if self.delta_t_c is not None and any(not (v != 0 and math.isfinite(v)) for v in self.delta_t_c):
            raise InputError(f"delta_t_c values must be finite and non-zero, got {list(self.delta_t_c)}")
        if self.sample_rate_hz is not None:
            object.__setattr__(self, "sample_rate_hz", check_positive("sample rate [Hz]", self.sample_rate_hz))
        for name in ("sensor_temp_spread_c", "ambient_temp_spread_c"):
            if getattr(self, name) < 0:
                raise InputError(f"{name} must be >= 0")

    # ----------------------------------------------------------------- derived
    @property
    def varied(self) -> bool:
        return self.sensor_temp_spread_c > 0 or self.ambient_temp_spread_c > 0

    @property
    def width(self) -> float:
        """Width of one effusivity interval [J s^-1/2 K^-1 m^-2]."""
        return (self.e_max - self.e_min) / self.intervals

    @property
    def edges(self) -> np.ndarray:
        return self.e_min + self.width * np.arange(self.intervals + 1)

    @property
    def centres(self) -> np.ndarray:
        return self.e_min + self.width * (np.arange(self.intervals) + 0.5)

    @property
    def scene_axes(self) -> list[tuple[str, tuple[float, ...]]]:
        if self.noise_ratio is not None:
            return [("noise_ratio", self.noise_ratio)]
        return [("noise_c", self.noise_c), ("delta_t_c", self.delta_t_c)]

    @property
    def scene_shape(self) -> tuple[int, ...]:
        return tuple(len(v) for _, v in self.scene_axes)

    def scene_points(self) -> list[tuple[int, ...]]:
        return [tuple(int(x) for x in idx) for idx in np.ndindex(*self.scene_shape)]

    def scene(self, point: Sequence[int], contact_s: float) -> Scene:
        """The scene at a scene-axis point (for noise_ratio: dT = 1, sigma = ratio)."""
        if self.noise_ratio is not None:
            return Scene(contact_s=contact_s, noise_c=self.noise_ratio[point[0]],
                         sensor_temp_c=self.ambient_temp_c + 1.0, ambient_temp_c=self.ambient_temp_c)
        return Scene(contact_s=contact_s, noise_c=self.noise_c[point[0]],
                     sensor_temp_c=self.ambient_temp_c + self.delta_t_c[point[1]],
                     ambient_temp_c=self.ambient_temp_c,
                     sensor_temp_spread_c=self.sensor_temp_spread_c,
                     ambient_temp_spread_c=self.ambient_temp_spread_c)

    def resolved_sensor(self) -> Sensor:
        sensor = load_sensor(self.sensor)
        if self.sample_rate_hz is not None:
            sensor = sensor.replace(sample_rate_hz=self.sample_rate_hz)
        return sensor

    def blocks_of(self) -> list[np.ndarray]:
        return [b for b in np.array_split(np.arange(self.intervals), self.blocks) if b.size]

    # --------------------------------------------------------------------- I/O
    def to_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        for k, v in d.items():
            if isinstance(v, tuple):
                d[k] = list(v)
        return d

    def digest(self) -> str:
        """Hash of everything that determines the result (sensor file content included)."""
        payload = self.to_dict()
        payload["sensor_resolved"] = self.resolved_sensor().to_dict()
        payload["sensor_resolved"].pop("provenance", None)
        text = json.dumps(payload, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any], *, source: str = "config") -> "SweepConfig":
        if not isinstance(data, Mapping):
            raise InputError(f"{source}: a sweep config must be a mapping of keys")
        known = {f.name for f in dataclasses.fields(cls)}
        flat = _flatten(data, source)
        unknown = sorted(set(flat) - known)
        if unknown:
            raise InputError(f"{source}: unknown key(s) {', '.join(unknown)} (known: {', '.join(sorted(known))})")
        try:
            return cls(**flat)
        except InputError as exc:
            raise InputError(f"{source}: {exc}") from None
        except (TypeError, ValueError) as exc:
            raise InputError(f"{source}: {exc}") from None

    @classmethod
    def from_yaml(cls, path: str | Path, **overrides: Any) -> "SweepConfig":
        """Read a YAML config; non-None ``overrides`` (CLI options) win over the file."""
        import yaml

        p = Path(path)
        try:
            text = p.read_text()
        except OSError as exc:
            raise InputError(f"cannot read sweep config {p}: {exc.strerror or exc}") from None
        try:
            data = yaml.safe_load(text) or {}
        except yaml.YAMLError:
            raise InputError(f"sweep config {p} is not valid YAML") from None
        if not isinstance(data, Mapping):
            raise InputError(f"sweep config {p} must be a mapping of keys")
        data = _flatten(data, f"sweep config {p}")
        if isinstance(data.get("sensor"), str) and not Path(data["sensor"]).is_absolute() \
                and data["sensor"].endswith((".yaml", ".yml")):
            data["sensor"] = str((p.parent / data["sensor"]).resolve())  # relative to the config
        data.update({k: v for k, v in overrides.items() if v is not None})
        return cls.from_mapping(data, source=f"sweep config {p}")


def _flatten(data: Mapping[str, Any], source: str) -> dict[str, Any]:
    """Expand ``effusivity: {min, max, intervals}`` into e_min, e_max, intervals."""
    flat = dict(data)
    eff = flat.pop("effusivity", None)
    if eff is not None:
        if not isinstance(eff, Mapping):
            raise InputError(f"{source}: effusivity must be a mapping with min, max, intervals")
        extra = sorted(set(eff) - {"min", "max", "intervals"})
        if extra:
            raise InputError(f"{source}: unknown effusivity key(s) {', '.join(extra)} (min, max, intervals)")
        for k_in, k_out in (("min", "e_min"), ("max", "e_max"), ("intervals", "intervals")):
            if k_in in eff:
                if k_out in flat and flat[k_out] != eff[k_in]:
                    raise InputError(f"{source}: {k_out} given twice ({flat[k_out]} and effusivity.{k_in} = {eff[k_in]})")
                flat[k_out] = eff[k_in]
    return flat


# ============================================================ pair scoring
@dataclass
class _Cell:
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


class _PairScorer:
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
        self.cells: dict[tuple[int, int], _Cell] = {}
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
            temps = render_trials(draws, self.sensor, self.scene).temperature_c
            feats = feature_matrix(temps, self.sensor.sample_rate_hz, cfg.slope_window_s)
            self._features[key] = feats
            while len(self._features) > self._max_features:
                self._features.popitem(last=False)
        return feats

    def score(self, i: int, j: int, rep: int) -> tuple[float, float]:
        from ..recognition.svm import f1_from_features

        r = f1_from_features(self.features(i, rep), self.features(j, rep), folds=self.cfg.folds,
                             seed=[self.cfg.seed, i, j, rep, _CV_KEY])
        self.fits += 1
        return r.f1, r.standard_error

    def cell(self, i: int, j: int) -> _Cell:
        """Score (i, j), adding repeats while the verdict is within z standard errors of Phi."""
        c = self.cells.get((i, j))
        if c is None:
            c = self.cells[(i, j)] = _Cell()
        cfg = self.cfg
        while c.reps < cfg.max_repeats and (c.reps == 0 or abs(c.mean - cfg.threshold) < cfg.z * c.stderr):
            f, s = self.score(i, j, c.reps)
            c.f1.append(f)
            c.se.append(s)
        return c


# ============================================================ staircases
def staircase_search(decide: Callable[[int, int], bool], rows: Sequence[int], n: int, *,
                     floor: np.ndarray | None = None, hint: np.ndarray | None = None) -> np.ndarray:
    """``J(i) = min{j > i : decide(i, j)}`` for the rows ``i`` (ascending), ``n`` if none.

    Assumes monotone decisions (true at (i, j) implies true at (i - 1, j) and
    (i, j + 1)), so ``J`` never decreases with ``i`` and each row starts at
    the previous row's answer. ``floor[i]`` is a known lower bound of ``J(i)``
    (the ideal observer's staircase); ``hint[i]`` a likely upper bound (the
    previous contact time's). The first guess extrapolates the previous row's
    step (capped by the hint); from a true guess the search steps down, from a
    false one it doubles its steps up, then bisects: two decisions per row
    when the guess is right, ``O(log n)`` when it is not.

    Returns
    -------
    ndarray of int
        ``J`` for each row, in row order.
    """
    out = np.full(len(rows), n, dtype=np.int64)
    prev, step_prev = 0, 1
    for r, i in enumerate(rows):
        bound = max(i + 1, prev, int(floor[i]) if floor is not None else 0)  # J(i) >= bound
        if bound >= n:
            break  # J = n here and for every later row
        guess = prev + step_prev if r > 0 else bound
        if hint is not None and hint[i] < n:
            guess = min(guess, int(hint[i]))
        guess = min(max(guess, bound), n - 1)
        lo = bound - 1  # known (or assumed) false
        if decide(i, guess):
            hi, step = guess, 1
            while hi - 1 > lo:  # step down until a false cell
                probe = max(hi - step, lo + 1)
                if decide(i, probe):
                    hi, step = probe, step * 2
                else:
                    lo = probe
                    break
        else:
            lo, step = guess, max(step_prev, 1)
            hi = n
            while lo < n - 1:  # step up until a true cell
                probe = min(lo + step, n - 1)
                if decide(i, probe):
                    hi = probe
                    break
                lo, step = probe, step * 2
            if hi >= n:
                break
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if decide(i, mid):
                hi = mid
            else:
                lo = mid
        step_prev = max(hi - prev, 1) if r > 0 else 1
        out[r] = prev = hi
    return out


def _ideal_staircase(cfg: SweepConfig, sensor: Sensor, s: float, rows: np.ndarray) -> np.ndarray:
    """J for the ideal observer (closed form), by vectorized bisection over partners."""
    n = cfg.intervals
    edges = cfg.edges
    rows = np.asarray(rows, dtype=np.int64)

    def dist(i, j):
        f1, _ = ideal_scores(edges[i], edges[i + 1], edges[j], edges[j + 1], sensor.effusivity, s,
                             accuracy=False)
        return f1 >= cfg.threshold

    J = np.full(rows.size, n, dtype=np.int64)
    live = rows < n - 1
    if not live.any():
        return J
    i = rows[live]
    top_ok = dist(i, np.full(i.size, n - 1))
    lo = i + 1
    hi = np.full(i.size, n - 1)
    first_ok = dist(i, lo)
    # invariant for unresolved rows: lo false, hi true
    res = np.where(first_ok, lo, np.where(top_ok, -1, n))
    todo = res == -1
    lo, hi = lo[todo], hi[todo]
    idx_todo = np.flatnonzero(todo)
    while lo.size and np.any(hi - lo > 1):
        mid = (lo + hi) // 2
        active = hi - lo > 1
        ok = np.ones(lo.size, dtype=bool)
        ok[active] = dist(i[idx_todo][active], mid[active])
        hi = np.where(active & ok, mid, hi)
        lo = np.where(active & ~ok, mid, lo)
    res[idx_todo] = hi
    J[live] = res
    return J


def _ideal_bound_s(cfg: SweepConfig, sensor: Sensor, scene: Scene) -> float:
    """Projection noise of an observer at least as good as any at this scene.

    With varied initial conditions, an observer told each trial's Ts0 and Ta at
    the largest temperature difference the spreads allow does at least as well.
    """
    if scene.fixed_initial_conditions:
        return projection_noise(sensor, scene)
    best_dt = abs(scene.delta_t_c) + scene.sensor_temp_spread_c + scene.ambient_temp_spread_c
    fixed = Scene(contact_s=scene.contact_s, noise_c=scene.noise_c,
                  sensor_temp_c=scene.ambient_temp_c + best_dt, ambient_temp_c=scene.ambient_temp_c)
    return projection_noise(sensor, fixed)


def delta_from_staircase(J: np.ndarray, width: float) -> tuple[np.ndarray, np.ndarray]:
    """delta towards higher and lower effusivity [J s^-1/2 K^-1 m^-2] from ``J``.

    ``delta_up[i] = (J(i) - i) * width``; ``delta_down[j] = (j - I(j)) * width``
    with ``I(j) = max{i < j : J(i) <= j}``; NaN where no distinguishable
    partner lies inside the grid.
    """
    J = np.asarray(J, dtype=np.int64)
    n = J.size
    idx = np.arange(n)
    up = np.where(J < n, (J - idx) * width, np.nan)
    # I(j) = max{i : max(J(i), i + 1) <= j}: a running maximum over the first j each i reaches,
    # O(n) memory (an n x n comparison would need gigabytes at tens of thousands of intervals)
    first = np.maximum(J, idx + 1)
    best = np.full(n + 1, -1, dtype=np.int64)
    np.maximum.at(best, np.minimum(first, n), idx)
    I = np.maximum.accumulate(best[:n])
    down = np.where(I >= 0, (idx - I) * width, np.nan)
    return up.astype(np.float64), down.astype(np.float64)


# ============================================================ one chunk
@dataclass(frozen=True)
class ChunkResult:
    """Staircases of one (scene point, block, contact) chunk."""

    point: tuple[int, ...]
    block: int
    contact_index: int
    rows: np.ndarray
    J: np.ndarray
    J_lo: np.ndarray
    J_hi: np.ndarray
    J_ideal: np.ndarray
    fits: int
    cells: np.ndarray  # (k, 5): i, j, mean F1, standard error, repeats
    wall_s: float
    f1_rows: np.ndarray | None = None  # full-matrix mode: F1 of (row, j) for all j

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


def run_chunk(cfg: SweepConfig, point: tuple[int, ...], block: int, contact_index: int,
              hint_J: np.ndarray | None = None, hint_J_hi: np.ndarray | None = None) -> ChunkResult:
    """Compute one chunk (a picklable top-level function for joblib/dask workers).

    A chunk is the unit of parallelism: everything inside it runs sequentially in its
    worker. (On a dask worker joblib's active backend is dask, and scikit-learn's own
    joblib calls, such as the folds of cross-validation, would otherwise be sent back to
    the cluster one by one: measured 5x slower per chunk.)
    """
    from joblib import parallel_config

    with parallel_config(backend="sequential"):
        return _run_chunk(cfg, point, block, contact_index, hint_J, hint_J_hi)


def _run_chunk(cfg, point, block, contact_index, hint_J, hint_J_hi) -> ChunkResult:
    t0 = time.perf_counter()
    sensor = cfg.resolved_sensor()
    scene = cfg.scene(point, cfg.contact_s[contact_index])
    rows = cfg.blocks_of()[block]
    n = cfg.intervals
    floor_full = np.zeros(n, dtype=np.int64)
    J_ideal_rows = _ideal_staircase(cfg, sensor, _ideal_bound_s(cfg, sensor, scene), rows)
    floor_full[rows] = J_ideal_rows

    if cfg.fidelity == "ideal":
        if cfg.varied:
            J = _ideal_mc_staircase(cfg, sensor, scene, rows, floor_full, hint_J)
        else:
            J = J_ideal_rows
        return ChunkResult(point, block, contact_index, rows, J, J.copy(), J.copy(), J_ideal_rows, 0,
                           np.zeros((0, 5)), time.perf_counter() - t0)

    scorer = _PairScorer(cfg, sensor, scene)
    phi, z = cfg.threshold, cfg.z
    f1_rows = None
    if cfg.full_matrix:
        f1_rows = np.full((rows.size, n), np.nan, dtype=np.float32)
        for r, i in enumerate(rows):
            for j in range(i + 1, n):
                f1_rows[r, j] = scorer.cell(i, j).mean  # same repeat rule as the search
        J, J_lo, J_hi = (_first_crossing(scorer, rows, n, lambda c, k=k: c.mean + k * c.stderr >= phi)
                         for k in (0.0, z, -z))
    else:
        floor = floor_full if cfg.ideal_bound else None
        J = staircase_search(lambda i, j: scorer.cell(i, j).mean >= phi, rows, n, floor=floor,
                             hint=_full(hint_J, rows, n))
        J_full = _full(J, rows, n)
        J_lo = staircase_search(lambda i, j: scorer.cell(i, j).mean + z * scorer.cell(i, j).stderr >= phi,
                                rows, n, floor=floor, hint=J_full)
        J_hi = staircase_search(lambda i, j: scorer.cell(i, j).mean - z * scorer.cell(i, j).stderr >= phi,
                                rows, n, floor=J_full, hint=_full(hint_J_hi, rows, n))
    cells = np.array([(i, j, c.mean, c.stderr, c.reps) for (i, j), c in sorted(scorer.cells.items())],
                     dtype=np.float64).reshape(-1, 5)
    return ChunkResult(point, block, contact_index, rows, J, J_lo, J_hi, J_ideal_rows, scorer.fits,
                       cells, time.perf_counter() - t0, f1_rows)


def _full(J_rows: np.ndarray | None, rows: np.ndarray, n: int) -> np.ndarray | None:
    if J_rows is None:
        return None
    out = np.full(n, n, dtype=np.int64)
    out[rows] = J_rows
    return out


def _first_crossing(scorer: _PairScorer, rows, n, ok: Callable[[_Cell], bool]) -> np.ndarray:
    """Full-matrix rule: the first partner above i whose score passes, no monotonicity assumed."""
    out = np.full(len(rows), n, dtype=np.int64)
    for r, i in enumerate(rows):
        for j in range(i + 1, n):
            if ok(scorer.cells[(i, j)]):
                out[r] = j
                break
    return out


def _ideal_mc_staircase(cfg, sensor, scene, rows, floor, hint) -> np.ndarray:
    """Ideal observer with varied initial conditions: Monte Carlo F1 per pair on the staircase."""
    from ..recognition.ideal import ideal_pair

    edges = cfg.edges
    cache: dict[tuple[int, int], float] = {}

    def decide(i, j):
        if (i, j) not in cache:
            r = ideal_pair((edges[i], edges[i + 1]), (edges[j], edges[j + 1]), sensor, scene,
                           n_mc=max(200, cfg.trials * 5), seed=[cfg.seed, i, j])
            cache[(i, j)] = r.f1
        return cache[(i, j)] >= cfg.threshold

    return staircase_search(decide, rows, cfg.intervals, floor=floor, hint=_full(hint, rows, cfg.intervals))


def run_scene(cfg: SweepConfig, point: tuple[int, ...] = (0,), *,
              contact_indices: Sequence[int] | None = None) -> list[ChunkResult]:
    """All blocks and contact times of one scene point, in-process (library convenience)."""
    out = []
    prev: dict[int, ChunkResult] = {}
    for k in (range(len(cfg.contact_s)) if contact_indices is None else contact_indices):
        for b in range(len(cfg.blocks_of())):
            p = prev.get(b)
            res = run_chunk(cfg, tuple(point), b, k, None if p is None else p.J, None if p is None else p.J_hi)
            prev[b] = res
            out.append(res)
    return out


# ============================================================ a whole sweep
class SweepInterrupted(Exception):
    """Raised when a sweep is interrupted; finished chunks are on disk."""

    def __init__(self, done: int, total: int, workdir: Path):
        super().__init__(f"interrupted: {done} of {total} chunks saved in {workdir}; "
                         f"run the same command with --resume to continue")
        self.done, self.total, self.workdir = done, total, workdir


def _chunk_path(workdir: Path, point, block, k) -> Path:
    p = "-".join(f"{x:03d}" for x in point)
    return workdir / "chunks" / f"p{p}-b{block:03d}-c{k:03d}.npz"


def _save_chunk(path: Path, res: ChunkResult) -> None:
    import io

    from .._io import atomic_write_bytes

    buf = io.BytesIO()
    np.savez(buf, **res.to_arrays())
    atomic_write_bytes(path, buf.getvalue())


def _load_chunk(path: Path) -> ChunkResult:
    try:
        with np.load(path, allow_pickle=False) as z:
            return ChunkResult.from_arrays({k: z[k] for k in z.files})
    except Exception as exc:  # a damaged chunk is recomputed, never trusted
        raise InputError(f"chunk {path.name} is unreadable ({exc}); delete it and resume") from None


def prepare_workdir(cfg: SweepConfig, workdir: Path, *, resume: bool, fresh: bool) -> None:
    """Create or check a sweep's working folder (its config and chunks)."""
    from .._io import atomic_write_text

    workdir = Path(workdir)
    meta = workdir / "sweep.json"
    chunks = workdir / "chunks"
    if meta.exists() and not fresh:
        try:
            old = json.loads(meta.read_text())
        except (OSError, ValueError):
            raise InputError(f"{meta} is unreadable; use --fresh to start over") from None
        if old.get("digest") != cfg.digest():
            raise InputError(f"{workdir} holds a different sweep (config changed); use another --workdir or --fresh")
        if not resume and any(chunks.glob("*.npz")):
            raise InputError(f"{workdir} already has finished chunks; use --resume to continue or --fresh to discard them")
    if fresh and chunks.exists():
        for f in chunks.glob("*.npz"):
            f.unlink()
    chunks.mkdir(parents=True, exist_ok=True)
    atomic_write_text(meta, json.dumps({"digest": cfg.digest(), "config": cfg.to_dict()}, indent=2))


def iter_sweep(cfg: SweepConfig, workdir: Path, *, jobs: int = 1, backend: str = "loky",
               scheduler: str | None = None) -> Iterator[tuple[ChunkResult, bool]]:
    """Run the missing chunks, wave by wave (one wave per contact time).

    Yields ``(chunk, computed)`` for every chunk of the sweep, reading the
    finished ones from ``workdir`` and computing the rest in parallel; each
    computed chunk is written atomically before it is yielded.
    """
    from joblib import Parallel, delayed, parallel_config

    workdir = Path(workdir)
    blocks = range(len(cfg.blocks_of()))
    points = cfg.scene_points()
    prev: dict[tuple, ChunkResult] = {}
    client = None
    if backend == "dask":
        try:
            from dask.distributed import Client
        except ImportError:
            raise InputError("the dask backend needs dask.distributed: pip install 'designkit[distributed]'") from None
        client = Client(scheduler) if scheduler else Client(processes=True, n_workers=max(jobs, 1),
                                                            threads_per_worker=1)
    elif backend not in ("loky", "sequential"):
        raise InputError(f"backend must be loky, sequential or dask, got {backend!r}")
    try:
        for k in range(len(cfg.contact_s)):
            todo = []
            for p in points:
                for b in blocks:
                    path = _chunk_path(workdir, p, b, k)
                    if path.exists():
                        res = _load_chunk(path)
                        prev[(p, b)] = res
                        yield res, False
                    else:
                        todo.append((p, b))
            if not todo:
                continue
            calls = []
            for p, b in todo:
                h = prev.get((p, b))
                calls.append(delayed(run_chunk)(cfg, p, b, k, None if h is None else h.J,
                                                None if h is None else h.J_hi))
            if backend == "dask":
                ctx = parallel_config(backend="dask")
                n_jobs = -1
            else:
                ctx = parallel_config(backend="loky" if jobs != 1 else "sequential")
                n_jobs = jobs
            with ctx:
                stream = Parallel(n_jobs=n_jobs, return_as="generator_unordered")(calls)
                for res in stream:
                    _save_chunk(_chunk_path(workdir, res.point, res.block, res.contact_index), res)
                    prev[(res.point, res.block)] = res
                    yield res, True
    finally:
        if client is not None:
            client.close()


def assemble(cfg: SweepConfig, chunks: Sequence[ChunkResult]) -> dict[str, np.ndarray]:
    """Table arrays from all chunks of a sweep."""
    n, K = cfg.intervals, len(cfg.contact_s)
    shape = cfg.scene_shape + (K,)
    width = cfg.width
    J = {name: np.full(shape + (n,), n, dtype=np.int64) for name in ("J", "J_lo", "J_hi", "J_ideal")}
    fits = np.zeros(shape, dtype=np.int64)
    wall = np.zeros(shape, dtype=np.float64)
    f1 = np.full(shape + (n, n), np.nan, dtype=np.float32) if cfg.full_matrix else None
    for c in chunks:
        key = tuple(c.point) + (c.contact_index,)
        for name in J:
            J[name][key][c.rows] = getattr(c, name)
        fits[key] += c.fits
        wall[key] += c.wall_s
        if f1 is not None and c.f1_rows is not None:
            f1[key][c.rows] = c.f1_rows
    # The Monte Carlo interval holds its own estimate: at J the mean F1 reaches the threshold, so
    # the first "not clearly below" partner is at most J, the first "clearly above" at least J.
    # Separate staircase walks over noisy (not exactly monotone) F1 can land either side of J
    # (about 1 in 1,600 references of svm-paper did): clip them.
    J["J_lo"] = np.minimum(J["J_lo"], J["J"])
    J["J_hi"] = np.maximum(J["J_hi"], J["J"])
    out: dict[str, np.ndarray] = {}
    for tag, name in (("", "J"), ("_lo", "J_lo"), ("_hi", "J_hi"), ("_ideal", "J_ideal")):
        up = np.empty(shape + (n,))
        down = np.empty(shape + (n,))
        for key in np.ndindex(*shape):
            up[key], down[key] = delta_from_staircase(J[name][key], width)
        out[f"delta_up{tag}"] = up
        out[f"delta_down{tag}"] = down
    if cfg.fidelity == "ideal":
        for tag in ("_lo", "_hi", "_ideal"):  # identical to delta: leave them out
            out.pop(f"delta_up{tag}")
            out.pop(f"delta_down{tag}")
    out["fits"] = fits
    out["chunk_wall_s"] = wall
    if f1 is not None:
        iu = np.triu_indices(n, 1)
        for key in np.ndindex(*shape):
            m = f1[key]
            m[(iu[1], iu[0])] = m[iu]
        out["f1_matrix"] = f1
    return out


def run_sweep(cfg: SweepConfig, workdir: str | Path, *, out: str | Path | None = None, jobs: int = 1,
              backend: str = "loky", scheduler: str | None = None, resume: bool = False,
              fresh: bool = False, on_chunk: Callable[[ChunkResult, bool, int, int], None] | None = None) -> Path:
    """Run (or resume) a sweep and write its table; returns the table's path.

    Parameters
    ----------
    cfg : SweepConfig
    workdir : path
        Folder for the sweep's chunks (resumable state).
    out : path, optional
        Table path (``.npz``; a ``.json`` header is written beside it).
        Default: ``workdir / f"{cfg.name}.npz"``.
    jobs : int
        Local worker processes (``-1``: all cores).
    backend : {"loky", "sequential", "dask"}
    scheduler : str, optional
        Address of a dask scheduler (with ``backend="dask"``).
    resume, fresh : bool
        Continue a previous run in ``workdir`` / discard its chunks.
    on_chunk : callable, optional
        Called as ``on_chunk(chunk, computed, done, total)`` after each chunk
        (progress display).
    """
    from ..tables.store import table_header, write_table

    workdir = Path(workdir)
    prepare_workdir(cfg, workdir, resume=resume, fresh=fresh)
    total = len(cfg.scene_points()) * len(cfg.blocks_of()) * len(cfg.contact_s)
    chunks: list[ChunkResult] = []
    t0 = time.perf_counter()
    computed = 0
    try:
        for res, was_computed in iter_sweep(cfg, workdir, jobs=jobs, backend=backend, scheduler=scheduler):
            chunks.append(res)
            computed += was_computed
            if on_chunk is not None:
                on_chunk(res, was_computed, len(chunks), total)
    except KeyboardInterrupt:
        raise SweepInterrupted(len(list((workdir / "chunks").glob("*.npz"))), total, workdir) from None
    arrays = assemble(cfg, chunks)
    elapsed = time.perf_counter() - t0
    header = table_header(cfg, arrays, run={"elapsed_s": elapsed, "chunks_computed": computed,
                                            "chunks_total": total, "jobs": jobs, "backend": backend})
    path = Path(out) if out is not None else workdir / f"{cfg.name}.npz"
    return write_table(path, header, arrays)
