"""The readings of many touches from a few: a scene's response in effusivity, read once and shared by its classes.

A sweep reads hundreds of classes (100 touches each, effusivity uniform in the class's range) on one time
grid. For a model whose reading costs much per object (:class:`~designkit.models.layered.Layered`'s inverse
Laplace transform, :class:`~designkit.models.ramp.ForceRamp`'s sum over its shares) every touch's reading is
a polynomial in the contact weight ``w = e_o / (e_s + e_o)`` (the paper's model is linear in it), evaluated
by the barycentric formula (Berrut & Trefethen 2004) on dyadic panels ``[i / 2^L, (i + 1) / 2^L]`` of ``w``.
A panel is read once (5 Chebyshev-Lobatto points, one call of the model) and serves every class and repeat
whose touches fall in it (:class:`SceneResponse`, one per model, sensor, time grid and tolerance:
:func:`scene_response`). The error is measured: the panel's 3-point interpolant against the model at the 2
points between them; within the tolerance (:func:`designkit.simulation.response_tolerance`: 1 % of the noise
over the curve, at most 1e-5) the 5-point interpolant answers, else the panel's halves are read, down to
:data:`MAX_LEVEL` (then directly). A class starts at panels 8-16 times its width (:func:`start_level`).
A reading depends on the touch's effusivity and its class's range alone, never on the classes read before:
the same draws give the same readings bit for bit in any order, split or process.

Examples
--------
>>> import numpy as np
>>> from designkit import SENSORS
>>> from designkit.models import get_model
>>> m = get_model("layered", film_thickness_m=2e-4, backing_effusivity_ws05_m2k=600.0, conductance_w_m2k=3000.0)
>>> t = np.arange(1, 401) / 200.0
>>> e = np.random.default_rng(0).uniform(331.0, 506.0, 50)
>>> u = class_readings(m, t, e, SENSORS["paper"], tolerance=1e-7)
>>> bool(np.max(np.abs(u - m.response(t, e, SENSORS["paper"]))) < 1e-7)
True
"""

from __future__ import annotations

import functools
import math
import pickle
from typing import NamedTuple

import numpy as np

from .._validation import InputError
from .base import ForwardModel
from .semi_infinite import object_weight

__all__ = ["MAX_LEVEL", "Panel", "SceneResponse", "class_readings", "scene_response", "start_level"]

#: Deepest panel level (width ``2^-MAX_LEVEL`` in w); touches in a panel that fails there are read directly.
MAX_LEVEL = 40
#: Fewest distinct effusivities worth a panel (5 readings); a class with fewer is read directly.
MIN_DISTINCT = 6


def _lobatto(n: int, lo: float, hi: float) -> np.ndarray:
    """The ``n + 1`` Chebyshev-Lobatto points of ``[lo, hi]``, increasing (``lo`` and ``hi`` included)."""
    x = -np.cos(np.arange(n + 1) * math.pi / n)
    x[0], x[-1] = -1.0, 1.0
    out = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x
    out[0], out[-1] = lo, hi
    return out


def _effusivity(w: np.ndarray, e_sensor: float) -> np.ndarray:
    """The effusivity of a contact weight: ``e_o = e_s w / (1 - w)`` (inf at ``w = 1``)."""
    with np.errstate(divide="ignore"):
        return np.where(w >= 1.0, np.inf, e_sensor * w / np.where(w >= 1.0, 1.0, 1.0 - w))


class Panel(NamedTuple):
    """The model read at 5 Chebyshev-Lobatto ``weights`` of ``[index / 2^level, (index + 1) / 2^level]``:
    ``values`` (5, m), or (5, R, m) for every touch ramp (:class:`SceneResponse` ``touches``); ``error``: the
    3-point interpolant's measured error (above the 5-point one's)."""

    level: int
    index: int
    weights: np.ndarray
    values: np.ndarray
    error: float


class SceneResponse:
    """A model's readings on one time grid at any effusivity: dyadic panels in w, each read when first needed.

    Parameters
    ----------
    model : ForwardModel
        A model whose reading depends on the object through its effusivity only.
    time_s : array_like, shape (m,)
        Times after contact [s] (what :meth:`ForwardModel.response` takes).
    sensor : designkit.Sensor
    tolerance : float
        Largest interpolation error (normalized reading), > 0.
    touches : bool
        Read the model's every touch ramp at once (a :class:`~designkit.models.ramp.ForceRamp` with
        ``touch_ramps``: :meth:`~designkit.models.ramp.ForceRamp.touch_responses`): a panel's values are
        (5, R, m), one step response per node shared by the R ramps, and a touch reads its own ramp's.
    """

    def __init__(self, model: ForwardModel, time_s, sensor, tolerance: float, *, touches: bool = False):
        if not (tolerance > 0):
            raise InputError(f"interpolation tolerance must be > 0, got {tolerance!r}")
        self.model = model
        self.time_s = np.atleast_1d(np.asarray(time_s, dtype=np.float64))
        self.sensor = sensor
        self.tolerance = float(tolerance)
        self.touches = bool(touches)
        self.e_sensor = float(sensor.effusivity)
        self._panels: dict[tuple[int, int], Panel | None] = {}   # None: failed, read its halves
        self.model_readings = 0   # effusivities the model was read at (for benchmarks)

    def panel(self, level: int, index: int) -> Panel | None:
        """Panel ``index`` of ``level`` (read on first use), or None where it misses the tolerance."""
        key = (int(level), int(index))
        if key not in self._panels:
            a, b = math.ldexp(index, -level), math.ldexp(index + 1, -level)
            w = _lobatto(4, a, b)
            read = self.model.touch_responses if self.touches else self.model.response
            v = read(self.time_s, _effusivity(w, self.e_sensor), self.sensor, tolerance=0.1 * self.tolerance)
            self.model_readings += w.size
            flat = v.reshape(w.size, -1)
            error = float(np.max(np.abs(_interpolate(w[0::2], flat[0::2], w[1::2]) - flat[1::2])))
            self._panels[key] = Panel(key[0], key[1], w, v, error) if error <= self.tolerance else None
        return self._panels[key]

    def readings(self, e_object, level: int = 0, touch=None) -> np.ndarray:
        """Normalized readings (K, m) of objects of effusivities ``e_object`` (>= 0, finite or inf), each
        from the first panel that meets the tolerance on its way down from ``level``; with ``touches``, object
        ``k`` pressing as touch ramp ``touch[k]``."""
        e = np.atleast_1d(np.asarray(e_object, dtype=np.float64))
        touch = None if touch is None else np.asarray(touch)
        w = object_weight(self.e_sensor, e)
        out = np.empty((e.size, self.time_s.size))
        pending = np.arange(e.size)
        for lev in range(int(level), MAX_LEVEL + 1):
            if pending.size == 0:
                return out
            idx = np.minimum(np.floor(np.ldexp(w[pending], lev)), 2.0 ** lev - 1).astype(np.int64)
            keep = np.ones(pending.size, dtype=bool)
            for i in np.unique(idx).tolist():
                p = self.panel(lev, i)
                if p is not None:
                    sel = idx == i
                    values = p.values if touch is None else p.values[:, touch[pending[sel]]]   # (5, k, m)
                    out[pending[sel]] = _interpolate(p.weights, values, w[pending[sel]])
                    keep &= ~sel
            pending = pending[keep]
        if pending.size and touch is not None:   # no panel met the tolerance: read directly
            out[pending] = self.model.touch_readings(self.time_s, e[pending], touch[pending], self.sensor,
                                                     tolerance=self.tolerance)
            self.model_readings += pending.size
        elif pending.size:
            uniq, inverse = np.unique(e[pending], return_inverse=True)
            out[pending] = self.model.response(self.time_s, uniq, self.sensor, tolerance=self.tolerance)[inverse.ravel()]
            self.model_readings += uniq.size
        return out

    @property
    def panels(self) -> list[Panel]:
        """The panels read so far that met the tolerance, by level and index."""
        return [p for _, p in sorted(self._panels.items()) if p is not None]


class _SensorKey(bytes):
    """A sensor's pickle as a cache key, carrying the sensor (which holds mappings: not hashable itself; its
    repr cost 5 ms for a calibrated rig's, per class and touch ramp)."""


class _Same:
    """An object compared by identity (a frozen sensor: its pickle made once per object, not per class)."""

    __slots__ = ("obj",)

    def __init__(self, obj):
        self.obj = obj

    def __hash__(self) -> int:
        return id(self.obj)

    def __eq__(self, other) -> bool:
        return isinstance(other, _Same) and other.obj is self.obj


@functools.lru_cache(maxsize=8)   # holds the sensor, so its id is not reused while cached
def _sensor_key(sensor: _Same) -> _SensorKey:
    key = _SensorKey(pickle.dumps(sensor.obj, protocol=5))
    key.sensor = sensor.obj
    return key


def _new_scene(model: ForwardModel, sensor: _SensorKey, time_bytes: bytes, tolerance: float,
               touches: bool) -> SceneResponse:
    return SceneResponse(model, np.frombuffer(time_bytes, dtype=np.float64).copy(), sensor.sensor, tolerance,
                         touches=touches)


#: The last 64 scenes (a sweep's contacts and scene points); of every touch ramp at once, the last 2 (their panels
#: hold R = 24 ramps each: up to 64 MB a scene at a calibrated rig's longest contact; a sweep renders contact after
#: contact).
_cached_scene = functools.lru_cache(maxsize=64)(_new_scene)
_cached_touch_scene = functools.lru_cache(maxsize=2)(_new_scene)


def scene_response(model: ForwardModel, time_s, sensor, *, tolerance: float, touches: bool = False) -> SceneResponse:
    """The :class:`SceneResponse` of a model, sensor, time grid, tolerance and ``touches``, one per process (the
    last 64 kept; with ``touches`` the last 2).

    Its panels are a pure function of those five, so sharing them changes no reading: it only saves reading
    the model again for the next class or repeat of the same scene.
    """
    t = np.ascontiguousarray(np.atleast_1d(np.asarray(time_s, dtype=np.float64)))
    try:
        hash(model)
    except TypeError:   # a model with unhashable parameters: a response of its own, not shared
        return SceneResponse(model, t, sensor, tolerance, touches=touches)
    key = _sensor_key(_Same(sensor))
    return (_cached_touch_scene if touches else _cached_scene)(model, key, t.tobytes(), float(tolerance), bool(touches))


def start_level(w_low: float, w_high: float) -> int:
    """The panel level a class of weights ``[w_low, w_high]`` starts from: panels 8 to 16 times its width
    (0 for a class wider than 1/16 of the weights; :data:`MAX_LEVEL` for one of no width). Wider panels are
    shared by more classes; a panel that misses the tolerance costs its 5 readings and is read in halves.

    >>> start_level(0.14, 0.2), start_level(0.0, 1.0), start_level(0.5, 0.5 + 2 ** -10)
    (1, 0, 7)
    """
    width = float(w_high) - float(w_low)
    if not width > 0:
        return MAX_LEVEL
    return int(min(max(math.floor(-math.log2(width)) - 3, 0), MAX_LEVEL))


def _interpolate(x_nodes: np.ndarray, values: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The polynomial through ``(x_nodes, values)`` (rows; Chebyshev-Lobatto nodes) at ``x``: shape (len(x), m).

    The barycentric formula with the Chebyshev-Lobatto weights ``(-1)^j`` (halved at the ends;
    Berrut & Trefethen, SIAM Review 46 (2004) 501), summed node by node in a fixed order: elementwise
    operations only (no BLAS, whose sums may depend on threads and memory alignment), so the same
    inputs give the same readings bit for bit on every run.
    """
    x = np.atleast_1d(np.asarray(x, dtype=np.float64))
    n = x_nodes.size
    lam = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    lam[0] *= 0.5
    lam[-1] *= 0.5
    diff = x[:, None] - x_nodes[None, :]                     # (K, n)
    hit = diff == 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        c = lam[None, :] / diff
        total = c[:, 0].copy()
        for j in range(1, n):
            total += c[:, j]
        basis = c / total[:, None]
    exact = hit.any(axis=1)
    if exact.any():                                          # x on a node: that node's value
        basis[exact] = hit[exact].astype(np.float64)
    out = basis[:, :1] * values[0]
    term = np.empty_like(out)
    for j in range(1, n):
        out += np.multiply(basis[:, j:j + 1], values[j], out=term)
    return out


def class_readings(model: ForwardModel, time_s, e_object, sensor, *, tolerance: float,
                   diffusivity_m2_s=None, touch=None) -> np.ndarray:
    """Normalized readings (K, m) of touches of one class: interpolated where the model is costly, else direct.

    Models with ``shared_response`` (the layered model, a force ramp) whose
    reading depends on the effusivity alone are read from the scene's panels
    (:func:`scene_response`), starting at the class's :func:`start_level`;
    others, touches with a per-touch diffusivity, and classes of fewer than
    :data:`MIN_DISTINCT` distinct effusivities are read directly by
    :meth:`ForwardModel.response`. With ``touch`` (a force ramp with ``touch_ramps``), touch ``k`` presses as
    touch ramp ``touch[k]``: from the scene's panels of every touch ramp at once (one step response per panel
    node for all ramps, :meth:`~designkit.models.ramp.ForceRamp.touch_responses`), or directly by
    :meth:`~designkit.models.ramp.ForceRamp.touch_readings`.

    Parameters
    ----------
    model : ForwardModel
    time_s : array_like, shape (m,)
        Times after contact [s].
    e_object : array_like, shape (K,)
        The touches' effusivities [J s^-1/2 K^-1 m^-2].
    sensor : designkit.Sensor
    tolerance : float
        Largest error asked of the readings (normalized).
    diffusivity_m2_s : array_like, shape (K,), optional
        Per-touch diffusivities (then read directly).
    touch : array_like of int, shape (K,), optional
        Per-touch touch ramp (indices into ``model.touch_ramps``).
    """
    e = np.atleast_1d(np.asarray(e_object, dtype=np.float64))
    t = np.atleast_1d(np.asarray(time_s, dtype=np.float64))
    direct = not getattr(model, "shared_response", False) or diffusivity_m2_s is not None or e.size == 0 \
        or not np.all(np.isfinite(e)) or np.any(e < 0)
    uniq, inverse = (None, None) if direct else np.unique(e, return_inverse=True)
    if touch is not None and (direct or uniq.size < MIN_DISTINCT):
        return model.touch_readings(t, e, touch, sensor, diffusivity_m2_s=diffusivity_m2_s, tolerance=tolerance)
    if direct:
        return model.response(t, e, sensor, diffusivity_m2_s=diffusivity_m2_s, tolerance=tolerance)
    if uniq.size < MIN_DISTINCT:
        return model.response(t, uniq, sensor, tolerance=tolerance)[inverse.ravel()]
    es = float(sensor.effusivity)
    level = start_level(float(object_weight(es, uniq[0])), float(object_weight(es, uniq[-1])))
    out = scene_response(model, t, sensor, tolerance=tolerance, touches=touch is not None).readings(e, level, touch)
    return np.clip(out, 0.0, 1.0, out=out)
