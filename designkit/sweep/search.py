"""Searching the staircase of first distinguishable partners, and turning it into delta(e).

Distinguishability is monotone in the pair's distance: if ``(i, j)`` is
distinguishable so is ``(i - 1, j)`` and ``(i, j + 1)``. Hence ``J(i)``, the
first distinguishable partner above ``i``, never decreases with ``i``, and
``J`` alone determines both directions of ``delta`` for every reference
(:func:`delta_from_staircase`). :func:`staircase_search` finds ``J`` with a
few decisions per reference; :func:`ideal_staircase` finds the ideal
observer's ``J`` in closed form, a floor no classifier goes below, where the
forward model allows a closed form (:func:`closed_form_model`);
:func:`assemble` turns the staircases of all chunks into a table's arrays.
"""

from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

from ..models import ForwardModel
from ..recognition.ideal import ideal_scores, projection_noise
from ..scene import Scene
from ..sensor import Sensor
from ..simulation import response_tolerance
from .config import SweepConfig

__all__ = [
    "IDEAL_UNKNOWN",
    "assemble",
    "closed_form_model",
    "delta_from_staircase",
    "ideal_bound_s",
    "ideal_staircase",
    "staircase_search",
]

#: ``J_ideal`` of a reference whose ideal observer has no closed form (model and scene).
IDEAL_UNKNOWN = -1


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

    Examples
    --------
    >>> import numpy as np
    >>> truth = np.array([2, 2, 4, 5, 6, 6])  # first distinguishable partner of each reference
    >>> staircase_search(lambda i, j: j >= truth[i], range(6), 6).tolist()
    [2, 2, 4, 5, 6, 6]
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


def ideal_staircase(cfg: SweepConfig, sensor: Sensor, s: float, rows: np.ndarray) -> np.ndarray:
    """``J`` of the ideal observer (closed form) for the reference ``rows``, by vectorized bisection.

    ``s`` is the projection noise (:func:`ideal_bound_s`); valid for a
    shared-shape model (:func:`closed_form_model`). Returns one ``J`` per
    row (``cfg.intervals`` where no partner is distinguishable).
    """
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


def closed_form_model(cfg: SweepConfig, sensor: Sensor, scene: Scene) -> ForwardModel | None:
    """The shared-shape model whose closed-form ideal observer holds for this sweep's scene, or None.

    The config's model when it has a shared shape; otherwise the shared-shape
    model it cannot be told from here (its extra physics below
    :func:`~designkit.simulation.response_tolerance` at every sample of every
    interval: a contact too good to lag, a slab too thick to matter), if any.
    Only then is the ideal observer's staircase a certificate (the floor of
    the SVM search, and ``J_ideal``).
    """
    model = cfg.model
    if model.shared_shape:
        return model
    tol = response_tolerance(scene.noise_ratio, sensor.times_s(scene.contact_s).size)
    return model.equivalent_shared_shape((cfg.grid_class(),), sensor, contact_s=scene.contact_s, tolerance=tol)


def ideal_bound_s(cfg: SweepConfig, sensor: Sensor, scene: Scene) -> float:
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

    Examples
    --------
    >>> up, down = delta_from_staircase([2, 2, 3, 4], 80.0)  # reference 3 has no partner above
    >>> up.tolist(), down.tolist()
    ([160.0, 80.0, 80.0, nan], [nan, nan, 80.0, 80.0])
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


def assemble(cfg: SweepConfig, chunks: Sequence) -> dict[str, np.ndarray]:
    """Table arrays from all chunks of a sweep.

    ``chunks`` are :class:`~designkit.sweep.chunk.ChunkResult` (anything with
    their ``point``, ``contact_index``, ``rows``, ``J``, ``J_lo``, ``J_hi``,
    ``J_ideal``, ``fits``, ``wall_s`` and ``f1_rows``). The array names and
    units are the table format's (:mod:`designkit.tables.store`): ``delta_*``
    [J s^-1/2 K^-1 m^-2], ``fits``, ``chunk_wall_s`` [s], ``f1_matrix``.
    """
    n = cfg.intervals
    shape = cfg.scene_shape + (len(cfg.contact_s),)
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
    out = _deltas(cfg, J, shape)
    out["fits"] = fits
    out["chunk_wall_s"] = wall
    if f1 is not None:
        iu = np.triu_indices(n, 1)
        for key in np.ndindex(*shape):
            m = f1[key]
            m[(iu[1], iu[0])] = m[iu]
        out["f1_matrix"] = f1
    return out


def _deltas(cfg: SweepConfig, J: dict[str, np.ndarray], shape: tuple[int, ...]) -> dict[str, np.ndarray]:
    """``delta_up*`` and ``delta_down*`` from the assembled staircases (which it may clip)."""
    # The Monte Carlo interval holds its own estimate: at J the mean F1 reaches the threshold, so
    # the first "not clearly below" partner is at most J, the first "clearly above" at least J.
    # Separate staircase walks over noisy (not exactly monotone) F1 can land either side of J
    # (about 1 in 1,600 references of svm-paper did): clip them.
    J["J_lo"] = np.minimum(J["J_lo"], J["J"])
    J["J_hi"] = np.maximum(J["J_hi"], J["J"])
    tags = {"": "J", "_lo": "J_lo", "_hi": "J_hi", "_ideal": "J_ideal"}
    if cfg.fidelity == "ideal":  # the interval and the bound are delta itself: leave them out
        tags = {"": "J"}
    elif np.any(J["J_ideal"] == IDEAL_UNKNOWN):
        # the ideal arrays only where every chunk had a closed-form ideal observer: a partial array
        # would mix "unknown" with the NaN that means "no distinguishable partner in the grid"
        del tags["_ideal"]
    out: dict[str, np.ndarray] = {}
    for tag, name in tags.items():
        up = np.empty(shape + (cfg.intervals,))
        down = np.empty(shape + (cfg.intervals,))
        for key in np.ndindex(*shape):
            up[key], down[key] = delta_from_staircase(J[name][key], cfg.width)
        out[f"delta_up{tag}"] = up
        out[f"delta_down{tag}"] = down
    return out
