"""A whole bin of materials at once: the pairwise matrix of a question and the multi-class view.

:func:`material_matrix` asks one design question (``min-contact``,
``max-noise``, ``min-delta-t`` or ``distinguishable``) for every pair of N
materials, every cell from one call of the public question API
(:func:`designkit.query.questions.ask_each`, table route, the materials rule: the hardest
pair of facing-edge classes; one array call over all pairs), names the **limiting pair** (the pair that
decides the design), and adds the **multi-class view**: the accuracy of
telling all N apart at once against contact time.

The tables are loaded and verified once per call of :func:`material_matrix`
and passed to the query as :class:`~designkit.tables.store.Table` objects,
and the pairs are answered together, so a 12-material matrix (66 pairs) costs tens of milliseconds.

Multi-class view
----------------
Each material is one class whose touches have effusivity uniform over the
material's whole range (not the facing-edge classes of the pair matrix: all N
are present at once). The ideal observer's accuracy (equal priors) is exact
for a model with a shared response shape under fixed initial conditions: every
touch reduces to one number ``v ~ w(e) + N(0, s^2)``
(:mod:`designkit.recognition.ideal`), so the Bayes classifier picks the class
of highest density of ``v``; :func:`multiclass_ideal_accuracy` integrates each
class's density over the runs of ``v`` where it is the highest, between the
crossings of the densities. Overlapping materials cap it below 1
at any contact time. The SVM's multi-class accuracy needs simulated touches
and a classifier fit (seconds): it is computed only when asked for
(``svm_trials``; otherwise ``svm_accuracy`` is None and the result says so).

Examples
--------
>>> r = material_matrix(["paper12:glass", "paper12:stainless steel", "paper12:copper"])
>>> r.names
('Glass', 'Stainless Steel', 'Copper')
>>> r.limiting.names
('Stainless Steel', 'Copper')
>>> r.to_dict()["limiting"]["a"], r.to_dict()["limiting"]["b"]
('Stainless Steel', 'Copper')
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from .._validation import InputError
from ..materials import Material, get_material, list_materials
from .answer import QUANTITIES, Answer, QuestionQuantity, interval_dict, number
from .questions import QUESTIONS, ask_each

__all__ = [
    "MATRIX_QUESTIONS",
    "MaterialMatrix",
    "MatrixCell",
    "MulticlassCurve",
    "material_matrix",
    "multiclass_ideal_accuracy",
    "multiclass_svm_accuracy",
    "resolve_materials",
]

#: The questions a matrix can ask, and which way is worse ("higher" / "lower" value is harder).
MATRIX_QUESTIONS: dict[str, str] = {
    "min-contact": "higher",
    "max-noise": "lower",
    "min-delta-t": "higher",
    "distinguishable": "lower",
}

_MAX_BINS = 100_000
_CUT = 8.5  # as designkit.recognition.ideal: outside +-8.5 s a class's density is exactly 0


# ============================================================ results
@dataclass(frozen=True)
class MatrixCell:
    """One pair of the matrix (``i < j`` index the result's materials).

    Attributes
    ----------
    i, j : int
        Indices of the two materials.
    value : float, bool or None
        The answer's value (the SVM table's), in the question's quantity.
    ideal : float or None
        The ideal observer's value (for ``distinguishable``: its F1).
    status : str
        ``"answered"``; ``"overlap"`` (the effusivity ranges overlap: no scene
        tells every object of one from every object of the other); or
        ``"none"`` (no answer within the table, see ``note``).
    note : str
        The answer's notes.
    bound : str
        ``"at-most"`` or ``"at-least"`` when the value is only a bound (the
        answer's :attr:`~designkit.query.Answer.bound`: its interval open at one
        end, e.g. ``max-noise`` still separable at the table's largest noise
        ratio: at least that); ``""`` otherwise.
    answer : Answer
        The full answer of this cell.
    """

    i: int
    j: int
    value: float | bool | None
    ideal: float | None
    status: str
    note: str
    bound: str
    answer: Answer = field(repr=False, compare=False)

    def to_dict(self, names: Sequence[str]) -> dict[str, Any]:
        value = self.value if isinstance(self.value, bool) else number(self.value)
        # the keys and shapes of a single answer's (docs/schema.md): ideal {value, method}, interval {low, high}
        return {"a": names[self.i], "b": names[self.j], "value": value, "ideal": self.answer.ideal_bound.to_dict(),
                "status": self.status, "bound": self.bound or None,
                "interval": interval_dict(self.answer.interval, coverage=self.answer.interval_coverage),
                "limiting_pair": [dict(c) for c in self.answer.limiting_pair], "note": self.note}


@dataclass(frozen=True)
class LimitingPair:
    """The pair that decides the design (the hardest one that can be answered).

    ``names`` is empty when no pair has an answer (all overlap).
    """

    names: tuple[str, ...]
    value: float | bool | None
    ideal: float | None
    status: str
    why: str

    def to_dict(self) -> dict[str, Any]:
        value = self.value if isinstance(self.value, bool) else number(self.value)
        a, b = self.names if self.names else (None, None)
        return {"a": a, "b": b, "value": value, "status": self.status, "why": self.why}


@dataclass(frozen=True)
class MulticlassCurve:
    """Accuracy of telling all N materials apart at once, against contact time.

    Attributes
    ----------
    contact_s : ndarray
        Contact times [s] (the table's contact axis).
    ideal_accuracy : ndarray or None
        The ideal observer's accuracy (None: not computed, see ``note``).
    svm_accuracy : ndarray or None
        The SVM's (None: not computed, see ``note``).
    chance : float
        1 / N.
    scene : dict
        ``noise_c`` and ``delta_t_c`` the curve is for.
    note : str
        What was and was not computed, and why.
    """

    contact_s: np.ndarray
    ideal_accuracy: np.ndarray | None
    svm_accuracy: np.ndarray | None
    chance: float
    scene: Mapping[str, Any]
    note: str

    def to_dict(self) -> dict[str, Any]:
        def arr(a):
            return None if a is None else [number(x) for x in a]

        return {"contact_s": arr(self.contact_s), "ideal_accuracy": arr(self.ideal_accuracy),
                "svm_accuracy": arr(self.svm_accuracy), "chance": self.chance, "scene": dict(self.scene),
                "note": self.note}


@dataclass(frozen=True)
class MaterialMatrix(QuestionQuantity):
    """The pairwise matrix of one question over N materials, its limiting pair and the multi-class view.

    :meth:`to_dict` is the ``designkit matrix --format json`` output.

    Attributes
    ----------
    question : str
        The question asked of every pair.
    materials : tuple of Material
        The N materials, in the order given.
    cells : tuple of MatrixCell
        One per pair ``i < j`` (row-major).
    limiting : LimitingPair
        The pair that decides the design.
    multiclass : MulticlassCurve or None
        None when not asked for.
    scene : dict
        The scene the question was asked with.
    table, ideal_table : str or None
        Names of the tables read (None: none).
    threshold : float
        F1 threshold Phi of the table.
    wall_s : float
        Seconds taken.
    """

    question: str
    materials: tuple[Material, ...]
    cells: tuple[MatrixCell, ...]
    limiting: LimitingPair
    multiclass: MulticlassCurve | None
    scene: Mapping[str, Any]
    table: str | None
    ideal_table: str | None
    threshold: float
    wall_s: float

    @property
    def names(self) -> tuple[str, ...]:
        """Display names of the materials."""
        return tuple(m.name for m in self.materials)

    def values(self, ideal: bool = False) -> np.ndarray:
        """The symmetric N x N matrix of values (float; NaN: no answer or the diagonal; bools as 0/1).

        ``ideal=True``: the ideal observer's values instead.
        """
        n = len(self.materials)
        out = np.full((n, n), np.nan)
        for c in self.cells:
            v = c.ideal if ideal else c.value
            if v is not None:
                out[c.i, c.j] = out[c.j, c.i] = float(v)
        return out

    def status(self) -> np.ndarray:
        """N x N array of cell statuses (``""`` on the diagonal)."""
        n = len(self.materials)
        out = np.full((n, n), "", dtype=object)
        for c in self.cells:
            out[c.i, c.j] = out[c.j, c.i] = c.status
        return out

    def rows(self) -> list[dict[str, Any]]:
        """One row per pair (``a``, ``b``, ``value``, ``ideal``, ``status``, ``note``): the long form."""
        return [{"a": self.names[c.i], "b": self.names[c.j], "value": c.to_dict(self.names)["value"],
                 "bound": c.bound or None, "ideal": number(c.ideal), "status": c.status, "note": c.note}
                for c in self.cells]

    def _table_dict(self, name: str | None, which: str) -> dict[str, Any] | None:
        """A table as every answer names it: ``{name, content_hash}`` (the hash as the cells' answers read it)."""
        if name is None:
            return None
        hashes = [getattr(c.answer, which + "_hash") for c in self.cells if getattr(c.answer, which) == name]
        return {"name": name, "content_hash": next((h for h in hashes if h), None)}

    def to_dict(self) -> dict[str, Any]:
        """Plain data, JSON-ready (no NaN): the ``--format json`` schema."""
        vals, ideal, st = self.values(), self.values(ideal=True), self.status()
        n = len(self.materials)

        def cell(m, i, j):
            if i == j:
                return None
            v = number(m[i, j])
            if self.question == "distinguishable" and m is vals and v is not None:
                return bool(v)
            return v

        return {
            "question": self.question,
            "quantity": self.quantity,
            "unit": self.unit,
            "materials": [{"name": m.name, "set": m.set, "qualified_name": m.qualified_name,
                           "effusivity_range": [m.e_min, m.e_max]} for m in self.materials],
            "matrix": {"value": [[cell(vals, i, j) for j in range(n)] for i in range(n)],
                       "ideal": [[cell(ideal, i, j) for j in range(n)] for i in range(n)],
                       "status": [[st[i, j] or None for j in range(n)] for i in range(n)]},
            "cells": [c.to_dict(self.names) for c in self.cells],
            "limiting": self.limiting.to_dict(),
            "multiclass": None if self.multiclass is None else self.multiclass.to_dict(),
            "scene": dict(self.scene),
            "table": self._table_dict(self.table, "table"),
            "ideal_table": self._table_dict(self.ideal_table, "ideal_table"),
            "threshold": self.threshold,
            "computation": {"queries": len(self.cells), "wall_s": self.wall_s},
        }


# ============================================================ inputs
def resolve_materials(materials: Sequence[str | Material] = (), *,
                      set: str | None = None) -> tuple[Material, ...]:  # noqa: A002 - the set's name
    """The materials of a matrix: names (or Material objects), and/or a whole named set.

    >>> [m.name for m in resolve_materials(["paper12:copper", "paper12:glass"])]
    ['Copper', 'Glass']
    >>> len(resolve_materials(set="paper12"))
    12
    """
    out: list[Material] = [] if set is None else list(list_materials(set=set))
    for m in materials:
        out.append(m if isinstance(m, Material) else get_material(m))
    seen: dict[str, Material] = {}
    for m in out:
        seen.setdefault(m.qualified_name, m)
    mats = tuple(seen.values())
    if len(mats) < 2:
        raise InputError(f"a matrix needs at least two distinct materials, got {len(mats)}")
    return mats


# ============================================================ multi-class ideal observer
def multiclass_ideal_accuracy(ranges, sensor, scene, *, max_bins: int = _MAX_BINS) -> float:
    """Best accuracy of any classifier telling K classes apart (equal priors), classes uniform over ``ranges``.

    The paper's semi-infinite model, fixed initial conditions. The Bayes
    classifier picks the class of highest density of ``v`` (:func:`~designkit.recognition.ideal.class_density`),
    so the accuracy is ``(1/K)`` times the sum, over the runs of ``v`` where one class ``k`` is the
    highest, of ``S_k(start) - S_k(end)`` (``S_k``: :func:`~designkit.recognition.ideal.class_survival`).
    The densities are compared on a grid of ``v`` every ``s / 2`` (``s``: the projection noise); each
    change of the highest class between two grid points is located by bisection, and where a third
    class is higher at that point (it leads only between the two grid points) the change is split
    in two and bisected again. A class that leads only between two grid points with the same class
    leading at both is not seen. The values agree to 1e-15 with a grid every ``s / 16``, to 1e-8 with
    scipy's adaptive quadrature (tests/test_matrix.py), and lie up to 1.5e-4 above the bin-wise rule
    this replaced (bins of ``s / 8``: a lower bound; ``benchmarks/bench_matrix.py``).

    Parameters
    ----------
    ranges : array_like, shape (K, 2)
        Effusivity range of each class [J s^-1/2 K^-1 m^-2].
    sensor : Sensor
    scene : Scene
    max_bins : int
        At most this many steps of the grid of ``v`` (for nearly noise-free scenes the step is wider
        than ``s / 2``, and a class narrower than a step may be missed).

    Returns
    -------
    float
        Accuracy in [1/K, 1].

    Examples
    --------
    >>> from designkit.scene import Scene
    >>> from designkit.sensor import SENSORS
    >>> acc = multiclass_ideal_accuracy([(400, 500), (20000, 30000)], SENSORS["paper"],
    ...                                 Scene.from_delta_t(contact_s=2.0))
    >>> round(acc, 6)
    1.0
    """
    from ..recognition.ideal import projection_noise

    return float(_bayes_accuracy(ranges, sensor.effusivity, [projection_noise(sensor, scene)], max_bins)[0])


def _bayes_accuracy(ranges, e_s: float, s, max_bins: int = _MAX_BINS) -> np.ndarray:
    """:func:`multiclass_ideal_accuracy` at each projection noise of ``s`` (1-D), in one pass: the grids of
    every noise side by side, their densities in one call, every crossing's bisection together."""
    from ..models.semi_infinite import object_weight
    from ..recognition.ideal import class_density, class_survival

    r = np.asarray(ranges, dtype=np.float64)
    s = np.asarray(s, dtype=np.float64)
    K = r.shape[0]
    acc = np.full(s.shape, 1.0 / K)  # infinite noise: chance
    if np.any(s == 0.0):  # no noise: the class of the narrowest range wins wherever ranges overlap
        ends = np.unique(r)
        mid = 0.5 * (ends[1:] + ends[:-1])
        inside = (r[:, :1] <= mid) & (mid < r[:, 1:])
        best = np.max(np.where(inside, 1.0 / (r[:, 1:] - r[:, :1]), 0.0), axis=0)
        acc[s == 0.0] = np.sum(np.diff(ends) * best) / K
    noisy = np.flatnonzero(np.isfinite(s) & (s > 0.0))
    if noisy.size == 0:
        return acc
    w = object_weight(e_s, r)
    grids, rows, cols, first = [], [], [], [0]
    for n in noisy:  # each noise's grid of v, and where each class's density is not 0 on it (w(range) +- 8.5 s)
        sn = s[n]
        lo, hi = float(w.min()) - 9.0 * sn, float(w.max()) + 9.0 * sn
        v = np.arange(lo, hi + max(sn / 2.0, (hi - lo) / max_bins), max(sn / 2.0, (hi - lo) / max_bins))
        for k, (wa, wb) in enumerate(w):
            i0, i1 = np.searchsorted(v, [wa - _CUT * sn, wb + _CUT * sn])
            rows.append(np.full(i1 - i0, k))
            cols.append(first[-1] + np.arange(i0, i1))
        grids.append(v)
        first.append(first[-1] + v.size)
    v = np.concatenate(grids)
    which = np.repeat(noisy, np.diff(first))  # the noise of each grid point
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    dens = np.zeros((K, v.size))
    dens[rows, cols] = class_density(v[cols], r[rows, 0], r[rows, 1], e_s, s[which[cols]])
    top = np.argmax(dens, axis=0)
    at = np.flatnonzero((top[1:] != top[:-1]) & (which[1:] == which[:-1]))
    cross, after, noise = [], [], []
    j, k, left, right, n = top[at], top[at + 1], v[at], v[at + 1], which[at]
    for _ in range(K):  # each round: bisect the pending changes, then look for a class above both at each
        c = _crossing(r, e_s, s[n], j, k, left, right)
        every = class_density(np.tile(c, K), np.repeat(r[:, 0], c.size), np.repeat(r[:, 1], c.size), e_s,
                              np.tile(s[n], K)).reshape(K, c.size)
        m = np.argmax(every, axis=0)
        cols = np.arange(c.size)
        hidden = every[m, cols] > np.maximum(every[j, cols], every[k, cols])  # j -> m -> k within one step
        cross.append(c[~hidden]), after.append(k[~hidden]), noise.append(n[~hidden])
        if not hidden.any():
            break
        h = np.flatnonzero(hidden)
        j, k = np.concatenate([j[h], m[h]]), np.concatenate([m[h], k[h]])
        left, right = np.concatenate([left[h], c[h]]), np.concatenate([c[h], right[h]])
        n = np.concatenate([n[h], n[h]])
    # the runs of one highest class: from the grid's start or a crossing to the next crossing or the grid's end
    start = np.concatenate([v[first[:-1]], *cross])
    run = np.concatenate([top[first[:-1]], *after])
    noise = np.concatenate([noisy, *noise])
    order = np.lexsort((start, noise))
    start, run, noise = start[order], run[order], noise[order]
    end = np.append(start[1:], 0.0)
    last = np.append(noise[1:] != noise[:-1], True)
    end[last] = v[np.array(first[1:]) - 1]
    mass = (class_survival(start, r[run, 0], r[run, 1], e_s, s[noise])
            - class_survival(end, r[run, 0], r[run, 1], e_s, s[noise]))
    acc[noisy] = np.bincount(np.searchsorted(noisy, noise), weights=mass, minlength=noisy.size) / K
    return acc


def _crossing(r, e_s: float, s, j, k, left, right) -> np.ndarray:
    """Where class ``j``'s density falls below class ``k``'s between ``left`` and ``right`` (``p_j >= p_k`` at
    ``left``, ``<`` at ``right``), by bisection to 2^-24 of the interval, elementwise.

    Hand-written on purpose: ``scipy.optimize.elementwise.find_root`` does this, but importing
    scipy.optimize takes about 0.7 s here (measured, scipy 1.17), most of ``matrix``'s 1 s budget, and a
    matrix imports no scipy otherwise."""
    from ..recognition.ideal import class_density

    jk, s2 = np.concatenate([j, k]), np.concatenate([s, s])
    for _ in range(24):
        mid = 0.5 * (left + right)
        p = class_density(np.concatenate([mid, mid]), r[jk, 0], r[jk, 1], e_s, s2)
        ahead = p[:mid.size] >= p[mid.size:]
        left, right = np.where(ahead, mid, left), np.where(ahead, right, mid)
    return 0.5 * (left + right)


def multiclass_svm_accuracy(ranges, trials: int, sensor, scene, seed) -> dict:
    """Cross-validated (stratified 3-fold) accuracy and confusion of the paper's SVM on K classes at once.

    Each class: ``trials`` simulated touches with effusivity uniform over its
    range (:func:`designkit.simulation.simulate_interval`), the paper's
    features and linear SVM, multi-class one-vs-one (scikit-learn's SVC).

    Parameters
    ----------
    ranges : array_like, shape (K, 2)
        Effusivity range of each class [J s^-1/2 K^-1 m^-2].
    trials : int
        Simulated touches per class.
    sensor : Sensor
    scene : Scene
    seed : sequence of int
        Seed of the touches and of the folds.

    Returns
    -------
    dict
        ``accuracy`` (float) and ``confusion`` (K x K counts, true x predicted).
    """
    import sklearn
    from sklearn.metrics import confusion_matrix
    from sklearn.model_selection import StratifiedKFold, cross_val_predict

    from .._validation import as_generator
    from ..recognition.features import feature_matrix
    from ..recognition.svm import make_classifier
    from ..simulation import simulate_interval

    seed = list(seed)
    X, y = [], []
    for k, (lo, hi) in enumerate(np.asarray(ranges, dtype=np.float64)):
        t = simulate_interval(lo, hi, trials, sensor, scene, seed=seed + [1, k])
        X.append(feature_matrix(t.temperature_c, sensor.sample_rate_hz))
        y.append(np.full(trials, k))
    X, y = np.vstack(X), np.concatenate(y)
    rs = int(as_generator(seed + [2]).integers(0, 2**31 - 1))
    with sklearn.config_context(assume_finite=True, skip_parameter_validation=True):
        pred = cross_val_predict(make_classifier(), X, y, cv=StratifiedKFold(3, shuffle=True, random_state=rs))
    K = len(ranges)
    return {"accuracy": float(np.mean(pred == y)), "confusion": confusion_matrix(y, pred, labels=list(range(K)))}


def _multiclass(mats, tab, *, noise_c: float, delta_t_c: float, svm_trials: int | None, seed: int,
                step: Callable[[], None]) -> MulticlassCurve:
    from ..scene import Scene

    contacts = np.asarray(tab.axes["contact_s"], dtype=np.float64)
    scene = {"noise_c": noise_c, "delta_t_c": delta_t_c}
    sensor = tab.sensor
    ranges = [m.effusivity_range for m in mats]
    scenes = [Scene.from_delta_t(contact_s=float(c), noise_c=noise_c, delta_t_c=delta_t_c) for c in contacts]
    svm = None
    if svm_trials:
        svm = np.empty(contacts.size)
        for k, sc in enumerate(scenes):
            svm[k] = multiclass_svm_accuracy(ranges, svm_trials, sensor, sc, [seed, 16, k])["accuracy"]
            step()
        svm_note = (f"SVM: the paper's pipeline on {svm_trials} simulated touches per material, one-vs-one, "
                    "stratified 3-fold cross-validated accuracy")
    else:
        svm_note = ("SVM accuracy not computed (it needs simulated touches and a classifier fit, seconds: "
                    "ask for it with svm_trials, designkit matrix --svm-trials N)")
    model = tab.model
    if getattr(model, "name", "") != "semi-infinite" or not tab.fixed_initial_conditions:
        return MulticlassCurve(contacts, None, svm, 1.0 / len(mats), scene,
                               f"ideal accuracy not computed: the closed form needs the semi-infinite model with "
                               f"fixed initial conditions (table {tab.name}: {model.describe()}); " + svm_note)
    from ..recognition.ideal import projection_noise

    acc = _bayes_accuracy(ranges, sensor.effusivity, [projection_noise(sensor, sc) for sc in scenes])
    note = ("ideal observer: exact Bayes accuracy (equal priors), each material uniform over its whole effusivity "
            "range; " + svm_note)
    return MulticlassCurve(contacts, acc, svm, 1.0 / len(mats), scene, note)


# ============================================================ the matrix
def _worse_key(question: str) -> Callable[[MatrixCell], tuple]:
    """Sort key: the largest key is the hardest answered pair (no value within the table is hardest)."""
    sign = 1.0 if MATRIX_QUESTIONS[question] == "higher" else -1.0

    def key(c: MatrixCell) -> tuple:
        if c.value is None:
            return (1, 0.0)
        ideal = -math.inf if c.ideal is None else float(c.ideal)
        return (0, sign * float(c.value), sign * ideal)

    return key


def _limiting(question: str, cells: Sequence[MatrixCell], names: Sequence[str]) -> LimitingPair:
    candidates = [c for c in cells if c.status != "overlap"]
    overlaps = len(cells) - len(candidates)
    tail = (f"; {overlaps} pair(s) overlap in effusivity and are never told apart whatever the scene"
            if overlaps else "")
    if not candidates:
        return LimitingPair((), None, None, "overlap", "every pair overlaps in effusivity" + tail)
    c = max(candidates, key=_worse_key(question))
    pair = (names[c.i], names[c.j])
    if c.status == "none":
        why = f"no answer within the table for {pair[0]} / {pair[1]} ({c.note})" + tail
    elif question == "distinguishable":
        why = (("every non-overlapping pair is distinguishable; the hardest" if c.value else "not distinguishable")
               + f": {pair[0]} / {pair[1]}" + tail)
    else:
        quantity, unit = QUANTITIES[question]
        word = "longest" if question == "min-contact" else ("smallest" if question == "max-noise" else "largest")
        qual = {"at-most": "at most ", "at-least": "at least "}.get(c.bound, "")
        from .._numbers import sig

        why = (f"the {word} {quantity} of all non-overlapping pairs: {qual}{sig(c.value, unit)} "
               f"for {pair[0]} / {pair[1]}" + tail)
    return LimitingPair(pair, c.value, c.ideal, c.status, why)


def material_matrix(materials: Sequence[str | Material] = (), question: str = "min-contact", *,
                    set: str | None = None, table: Any = None, ideal_table: Any = "ideal-paper",  # noqa: A002
                    multiclass: bool = True, svm_trials: int | None = None, seed: int = 0,
                    progress: Callable[[int, int], None] | None = None, **scene: Any) -> MaterialMatrix:
    """The pairwise matrix of ``question`` over N materials, its limiting pair and the multi-class view.

    Parameters
    ----------
    materials : sequence of str or Material
        Material names (``"copper"``, ``"paper12:glass"``) or objects.
    question : str
        One of :data:`MATRIX_QUESTIONS`.
    set : str, optional
        Add every material of a named set (``"paper12"``, ``"database"``).
    table, ideal_table : Table, name or path, optional
        The SVM table (default: the table route's default) and the ideal-bound
        table; each is loaded and verified once and passed to every query.
    multiclass : bool
        Compute the multi-class view.
    svm_trials : int, optional
        Also the SVM's multi-class accuracy at each contact time of the table,
        on this many simulated touches per material (seconds; needs
        scikit-learn). None: not computed (said so in the result).
    seed : int
        Seed of the SVM's simulated touches and folds.
    progress : callable(done, total), optional
        Called after each pair and each SVM contact time (for a progress display).
    **scene
        The question's scene arguments and table-route options:
        ``contact_s`` [s], ``noise_c`` [degC], ``delta_t_c`` [degC],
        ``threshold``, ``sensor``, ``model`` (see
        :func:`designkit.query.table.min_contact`).

    Returns
    -------
    MaterialMatrix
    """
    from .table_open import as_table

    t0 = time.perf_counter()
    if question not in MATRIX_QUESTIONS:
        raise InputError(f"a matrix asks one of: {', '.join(MATRIX_QUESTIONS)}; got {question!r}")
    mats = resolve_materials(materials, set=set)
    # the route policy's table for this sensor and model (a sensor file's registered one), as a question's
    from .inputs import TableMismatch
    from .policy import table_for

    choice = table_for(question, sensor=scene.get("sensor"), model=scene.get("model")) if table is None else None
    if choice is not None and choice.table is None:
        raise TableMismatch(choice.reason)
    if choice is not None and choice.sensor_table:  # each question reads it as a single question does
        tab, route = choice.loaded, {"route": "auto"}
    else:  # (loaded once per process, with the table's memo: as every table question loads it)
        tab = as_table(table if choice is None else choice.table)
        route = {"route": "table", "table": tab, "ideal_table": None if ideal_table is None else as_table(ideal_table)}
    allowed = frozenset({"contact_s", "noise_c", "delta_t_c", "threshold", "sensor", "model"})
    unknown = sorted(k for k in scene if k not in allowed)
    if unknown:
        raise InputError(f"unknown argument(s) {', '.join(unknown)}; a matrix takes {', '.join(sorted(allowed))}")
    # the set parameter shadows the builtin here: frozenset for the question's scene quantities
    takes = allowed - (frozenset({"contact_s", "noise_c", "delta_t_c"}) - frozenset(QUESTIONS[question].scene))
    given = {k: v for k, v in scene.items() if k in takes and v is not None}
    names = tuple(m.name for m in mats)
    cells = []
    n = len(mats)
    n_svm = tab.axes["contact_s"].size if multiclass and svm_trials else 0
    total = n * (n - 1) // 2 + n_svm
    if svm_trials is not None and (int(svm_trials) != svm_trials or svm_trials < 3):
        raise InputError(f"svm_trials must be an integer of at least 3 (3-fold cross-validation), got {svm_trials}")
    pairs = [(i, j) for i in range(n) for j in range(i + 1, n)]
    # every pair from one array call of the table route (its closed-form bounds solved together)
    answers = ask_each(question, [{"m1": mats[i].qualified_name, "m2": mats[j].qualified_name} for i, j in pairs],
                       **route, **given)
    for (i, j), a in zip(pairs, answers):
        status = "overlap" if not a.limiting_pair else ("answered" if a.value is not None else "none")
        ideal = a.ideal_bound.value
        if question == "distinguishable":
            ideal = a.details.get("ideal_f1")
        cells.append(MatrixCell(i, j, a.value, None if ideal is None else float(ideal), status, a.note,
                                a.bound, a))  # (the answer's own: one source for every surface)
        if progress is not None:
            progress(len(cells), total)
    curve = None
    if multiclass:
        noise = float(scene.get("noise_c") if scene.get("noise_c") is not None else 0.05)
        dt = float(scene.get("delta_t_c") if scene.get("delta_t_c") is not None else 10.0)
        done = [len(cells)]

        def step() -> None:
            done[0] += 1
            if progress is not None:
                progress(done[0], total)

        curve = _multiclass(mats, tab, noise_c=noise, delta_t_c=dt, svm_trials=svm_trials, seed=seed, step=step)
    first = cells[0].answer
    return MaterialMatrix(question, mats, tuple(cells), _limiting(question, cells, names), curve,
                          {k: first.scene.get(k) for k in ("contact_s", "noise_c", "delta_t_c", "noise_ratio")},
                          tab.name, first.ideal_table, first.threshold, time.perf_counter() - t0)
