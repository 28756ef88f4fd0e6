"""Searching the staircase of first distinguishable partners, and turning it into delta(e).

Distinguishability is monotone in the pair's distance: if ``(i, j)`` is
distinguishable so is ``(i - 1, j)`` and ``(i, j + 1)``. Hence ``J(i)``, the
first distinguishable partner above ``i``, never decreases with ``i``, and
``J`` alone determines both directions of ``delta`` for every reference
(:func:`delta_from_staircase`). :func:`staircase_search` finds ``J`` with a
few decisions per reference, each row on its own (so the answer does not
depend on how a sweep is split); :func:`ideal_staircase` finds the ideal
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
    "ANCHOR_EVERY",
    "IDEAL_UNKNOWN",
    "SUPER_EVERY",
    "assemble",
    "chunk_wall_s",
    "closed_form_model",
    "delta_from_staircase",
    "ideal_bound_s",
    "ideal_staircase",
    "staircase_search",
    "staircase_searches",
    "with_anchors",
]

#: ``J_ideal`` of a reference whose ideal observer has no closed form (model and scene).
IDEAL_UNKNOWN = -1


def staircase_search(decide: Callable[[int, int], bool] | None, rows: Sequence[int], n: int, *,
                     floor: np.ndarray | None = None,
                     decide_many: Callable[[list[tuple[int, int]]], Sequence[bool]] | None = None,
                     anchor_every: int | None = None) -> np.ndarray:
    """``J(i)``, the first distinguishable partner above ``i``, for each row (``n`` if none).

    Each row is searched on its own, from its own floor only: ``f = max(i + 1,
    floor[i])`` (``floor`` is a known lower bound, the ideal observer's
    staircase), probing ``f, f + 2, f + 6, f + 14, ...`` (steps doubling) up to
    the first true probe, then bisecting between it and the last false one.
    The probes a row makes depend on nothing but that row's decisions, so the
    answer of a row is the same whatever other rows are searched with it (the
    blocks, jobs and contact times a sweep is split into): a table is a
    function of its config alone. On exactly monotone decisions (true at
    ``(i, j)`` implies true at ``(i, j + 1)``) this is ``min{j > i : decide(i,
    j)}``; on noisy ones it is a crossing (false below, true at ``J``) found
    by a fixed path. About ``2 log2(J - f + 1) + 1`` decisions per row.

    Parameters
    ----------
    decide : callable ``(i, j) -> bool``, optional
        One decision.
    rows : sequence of int
        Reference intervals.
    n : int
        Number of intervals.
    floor : ndarray of int, optional
        Lower bound of ``J`` per interval (indexed by ``i``).
    decide_many : callable ``[(i, j), ...] -> [bool, ...]``, optional
        Many decisions at once (a batched scorer); the rows then advance in
        lockstep, all pending probes of a step in one call. Either this or
        ``decide``; the answer is the same.
    anchor_every : int, optional
        Guided search from anchor rows (:func:`staircase_searches`).

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
    >>> staircase_search(None, range(6), 6, decide_many=lambda p: [j >= truth[i] for i, j in p]).tolist()
    [2, 2, 4, 5, 6, 6]
    """
    if decide_many is None:
        if decide is None:
            raise TypeError("staircase_search needs decide or decide_many")
        decide_many = lambda pairs: [decide(i, j) for i, j in pairs]  # noqa: E731
    return staircase_searches([(rows, floor)], n, lambda probes: decide_many([(i, j) for _, i, j in probes]),
                              anchor_every=anchor_every)[0]


#: Spacing of the anchor rows of a guided search (:func:`staircase_searches`): every row ``i`` with
#: ``i % ANCHOR_EVERY == 0`` is searched from its floor alone; every other row starts from a guess
#: interpolated between the answers of its two anchors (fewer pairs per reference than searching every
#: row from its floor).
ANCHOR_EVERY = 8


#: Spacing of the top-level anchors of a guided search: every row ``i`` with
#: ``i % SUPER_EVERY == 0`` is searched from its floor alone; the other anchors start from their floor's distance
#: times the efficiency (``(J - i) / (floor - i)``) of these, interpolated (:func:`staircase_searches`).
SUPER_EVERY = 64


def with_anchors(rows: Sequence[int], n: int, every: int = ANCHOR_EVERY, super_every: int | None = SUPER_EVERY) -> np.ndarray:
    """``rows`` and the anchor rows their guided search needs (sorted, unique): the anchors of ``every``
    spacing around each row and the top-level anchors (``super_every``) around each anchor.

    Examples
    --------
    >>> with_anchors([3, 9, 16], 20, every=8).tolist()
    [0, 3, 8, 9, 16]
    >>> with_anchors([70, 130], 200, every=8, super_every=64).tolist()
    [64, 70, 72, 128, 130, 136, 192]
    """
    rows = np.asarray(rows, dtype=np.int64).reshape(-1)
    a0 = (rows // every) * every
    a1 = (a0 + every)[(rows % every != 0) & (a0 + every < n)]  # an anchor needs no other anchor
    anchors = np.unique(np.concatenate([a0, a1]))
    if super_every:
        s0 = (anchors // super_every) * super_every
        s1 = (s0 + super_every)[(anchors % super_every != 0) & (s0 + super_every < n)]
        anchors = np.concatenate([anchors, s0, s1])
    return np.unique(np.concatenate([rows, anchors]))


def staircase_searches(searches: Sequence[tuple[Sequence[int], np.ndarray | None]], n: int,
                       decide_many: Callable[[list[tuple[int, int, int]]], Sequence[bool]], *,
                       anchor_every: int | None = None) -> list[np.ndarray]:
    """Several :func:`staircase_search` runs in lockstep: every step's probes of all of them in one call.

    Each search ``s`` is ``(rows, floor)`` and decides by its own rule; ``decide_many``
    receives ``(s, i, j)`` probes and returns one decision each. Each row's path depends
    only on its own decisions, so the answers are those of separate runs; only the calls
    are fewer and larger (what a batched scorer needs).

    With ``anchor_every = A`` the search is *guided*: the anchor rows (``i % A == 0``; the
    ones the given rows need are added, see :func:`with_anchors`) are searched first: the
    top-level ones (``i % SUPER_EVERY == 0``) each from its floor alone, the others from a
    guess, the floor's distance ``floor[i] - i`` times the top anchors' efficiency
    ``(J - a) / (floor[a] - a)`` interpolated between them (without a floor: the distance
    ``J - a`` interpolated geometrically). Every other row ``i`` between anchors
    ``a0 < i < a1 = a0 + A`` then starts from ``g = J(a0) + (J(a1) - J(a0)) (i - a0) / A``
    (``J(a0)`` above the last anchor), raised to its floor: one probe at ``g``, then galloping
    down (if true) or up (if false) to ``g -+ 1, 2, 4, ...`` and bisecting. A row's path
    depends on its own decisions and its anchors', which depend on theirs and their top
    anchors' alone, so the answer is the same whatever other rows are searched with it. On
    exactly monotone decisions it is ``min{j > i : decide(i, j)}``; on noisy ones the crossing
    nearest the guess. Where ``J`` follows its neighbours' staircase a row costs 2-4 probes
    instead of ``2 log2(J - f + 1) + 1`` (the engine versions that chose these steps, and
    their measured costs: docs/engine.md).

    Examples
    --------
    >>> import numpy as np
    >>> truth = np.array([2, 2, 4, 5, 6, 6])
    >>> J, J_late = staircase_searches([(range(6), None), (range(6), None)], 6,
    ...                                lambda p: [j >= truth[i] + s for s, i, j in p])
    >>> J.tolist(), J_late.tolist()
    ([2, 2, 4, 5, 6, 6], [3, 3, 5, 6, 6, 6])
    >>> staircase_searches([(range(6), None)], 6, lambda p: [j >= truth[i] for _, i, j in p],
    ...                    anchor_every=2)[0].tolist()
    [2, 2, 4, 5, 6, 6]
    """
    rows_of = [[int(i) for i in rows] for rows, _ in searches]
    floors = [floor for _, floor in searches]
    if anchor_every is None:
        found = _lockstep([(rows_of[s], floors[s], None) for s in range(len(searches))], n, decide_many)
        return [np.array([found[s][i] for i in rows_of[s]], dtype=np.int64) for s in range(len(searches))]
    A = int(anchor_every)
    S = SUPER_EVERY if SUPER_EVERY % A == 0 else None
    ext = [with_anchors(r, n, A, S).tolist() if r else [] for r in rows_of]
    if S is None:
        anchors = [[i for i in e if i % A == 0] for e in ext]
        found = _lockstep([(anchors[s], floors[s], None) for s in range(len(searches))], n, decide_many)
    else:
        tops = [[i for i in e if i % S == 0] for e in ext]
        found = _lockstep([(tops[s], floors[s], None) for s in range(len(searches))], n, decide_many)
        mids = [[i for i in e if i % A == 0 and i % S] for e in ext]
        more = _lockstep([(mids[s], floors[s], _efficiency_guesses(mids[s], found[s], floors[s], S, n))
                          for s in range(len(searches))], n, decide_many)
        found = [{**found[s], **more[s]} for s in range(len(searches))]
    guesses = []
    for s in range(len(searches)):
        g = {}
        for i in ext[s]:
            if i % A:
                a0 = (i // A) * A
                J0 = found[s][a0]
                J1 = found[s].get(a0 + A, J0)
                g[i] = int(np.floor(J0 + (J1 - J0) * (i - a0) / A + 0.5))
        guesses.append(g)
    rest = _lockstep([([i for i in ext[s] if i % A], floors[s], guesses[s]) for s in range(len(searches))],
                     n, decide_many)
    return [np.array([rest[s].get(i, found[s].get(i)) for i in rows_of[s]], dtype=np.int64)
            for s in range(len(searches))]


def _efficiency_guesses(rows: list[int], top: dict[int, int], floor: np.ndarray | None, S: int, n: int) -> dict[int, int]:
    """Guesses of the anchors ``rows`` from the top-level anchors' answers ``top`` (spacing ``S``).

    With a floor, the floor's distance ``floor[i] - i`` times the efficiency ``(J - a) / (floor[a] - a)`` of the
    top anchors ``a`` either side, interpolated linearly in ``i`` (the SVM needs about a constant multiple of
    the ideal observer's distance, a multiple that changes slowly along the references); without one, their
    distances ``J - a`` interpolated geometrically (linearly, a rig's need growing about as a power of ``e`` made
    1.12x version 3's fits on a slice). The top anchor below alone where the one above has no partner in the grid; ``n - 1`` where
    the one below has none.
    """
    out = {}
    for i in rows:
        a0 = (i // S) * S
        a1 = a0 + S if a0 + S in top and top[a0 + S] < n else a0
        if top[a0] >= n:  # no partner in the grid below: most likely none here either (one probe at n - 1)
            out[i] = n - 1
            continue
        w = (i - a0) / S if a1 != a0 else 0.0
        if floor is None:  # the distance interpolated geometrically (a need grows about as a power of e)
            d0, d1 = top[a0] - a0, top[a1] - a1
            g = i + d0 * (d1 / d0) ** w
        else:
            e0, e1 = ((top[a] - a) / max(int(floor[a]) - a, 1) for a in (a0, a1))
            g = i + (e0 + (e1 - e0) * w) * max(int(floor[i]) - i, 1)
        out[i] = int(np.floor(g + 0.5))
    return out


def _lockstep(searches, n, decide_many) -> list[dict[int, int]]:
    """``J`` of each row of each ``(rows, floor, guesses)`` search, all pending probes of a step in one call."""
    outs, gens, pending, rows_of = [], {}, {}, []
    for s, (rows, floor, guess) in enumerate(searches):
        rows_of.append(rows)
        outs.append({i: n for i in rows})
        for r, i in enumerate(rows):
            f = max(i + 1, int(floor[i]) if floor is not None else 0)
            if f < n:
                g = _row_search(f, n, None if guess is None else guess.get(i))
                pending[(s, r)] = next(g)
                gens[(s, r)] = g
    while pending:
        order = sorted(pending)
        answers = decide_many([(s, rows_of[s][r], pending[(s, r)]) for s, r in order])
        for key, ok in zip(order, answers):
            try:
                pending[key] = gens[key].send(bool(ok))
            except StopIteration as stop:
                outs[key[0]][rows_of[key[0]][key[1]]] = stop.value
                del pending[key], gens[key]
    return outs


def _row_search(f: int, n: int, guess: int | None = None):
    """One row's search from its floor ``f``, starting at ``guess`` if above it: yields probes, is sent
    their decisions, returns ``J``."""
    lo, step, hi = f - 1, 1, None  # lo: known (or assumed) false; hi: known true
    start = None  # a gallop from a guess probes g -+ 1, 2, 4, ...; from the floor, each step twice the last
    if guess is not None and guess > f:
        g = min(int(guess), n - 1)
        if (yield g):  # gallop down from a true guess to the first false probe (or the floor)
            hi = g
            while hi > f:
                probe = max(g - step, f)
                if (yield probe):
                    hi = probe
                    step *= 2
                else:
                    lo = probe
                    break
            if hi == f:
                return f
        elif g >= n - 1:
            return n
        else:
            lo = start = g
    if hi is None:
        while True:  # gallop up to the first true probe
            probe = min((lo if start is None else start) + step, n - 1)
            if (yield probe):
                hi = probe
                break
            if probe >= n - 1:
                return n
            lo, step = probe, step * 2
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if (yield mid):
            hi = mid
        else:
            lo = mid
    return hi


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
        # zooming stops for a pair once its F1 reaches the threshold (F1 only grows with the zoom's passes, and a
        # pair's passes do not depend on the others'): the same decisions as zooming every pair to the end, in
        # 0.42x the CPU (all 500 references of svm-paper's sigma/dT 0.0005, 0.002, 0.005, 0.01 x 0.5, 2, 10 s)
        f1, _ = ideal_scores(edges[i], edges[i + 1], edges[j], edges[j + 1], sensor.effusivity, s,
                             accuracy=False, stop_at=cfg.threshold)
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
    ``J_ideal``, ``fits`` and ``f1_rows``). The array names and units are
    the table format's (:mod:`designkit.tables.store`): ``delta_*``
    [J s^-1/2 K^-1 m^-2], ``fits``, ``f1_matrix``. Nothing that depends on the
    machine or the run goes in here (the arrays are the table's identity):
    compute times are in the header's run stats (:func:`chunk_wall_s`).
    """
    n = cfg.intervals
    shape = cfg.scene_shape + (len(cfg.contact_s),)
    J = {name: np.full(shape + (n,), n, dtype=np.int64) for name in ("J", "J_lo", "J_hi", "J_ideal")}
    fits = np.zeros(shape, dtype=np.int64)
    f1 = np.full(shape + (n, n), np.nan, dtype=np.float32) if cfg.full_matrix else None
    for c in chunks:
        key = tuple(c.point) + (c.contact_index,)
        for name in J:
            J[name][key][c.rows] = getattr(c, name)
        fits[key] += c.fits
        if f1 is not None and c.f1_rows is not None:
            f1[key][c.rows] = c.f1_rows
    out = _deltas(cfg, J, shape)
    out["fits"] = fits
    if f1 is not None:
        iu = np.triu_indices(n, 1)
        for key in np.ndindex(*shape):
            m = f1[key]
            m[(iu[1], iu[0])] = m[iu]
        out["f1_matrix"] = f1
    return out


def chunk_wall_s(cfg: SweepConfig, chunks: Sequence) -> np.ndarray:
    """Compute time [s] per scene point and contact time, summed over blocks (for the run stats).

    Shaped like the table's ``fits`` array; timings are kept out of the
    table's arrays so that two builds of one config are identical.
    """
    wall = np.zeros(cfg.scene_shape + (len(cfg.contact_s),), dtype=np.float64)
    for c in chunks:
        wall[tuple(c.point) + (c.contact_index,)] += c.wall_s
    return wall


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
