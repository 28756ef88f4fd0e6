"""The readings of a class of objects from a few: interpolation in effusivity, computed once per class.

A simulated class is many touches (100 in a sweep) of objects whose effusivity
is drawn uniformly in the class's range ``[e_low, e_high)``, all read on one
time grid. For a model whose reading costs much per object (an inverse Laplace
transform per time, :class:`~designkit.models.layered.Layered`; a sum over a
force ramp's shares, :class:`~designkit.models.ramp.ForceRamp`) the readings of
the whole class come from the model's readings at a few effusivities of the
range: a polynomial in the contact weight ``w = e_o / (e_s + e_o)`` (in which
the paper's model is exactly linear and every model here nearly so), through
Chebyshev points, evaluated by the barycentric formula
(:class:`scipy.interpolate.BarycentricInterpolator`).

The error is measured, not assumed: the interpolant through ``n + 1``
Chebyshev-Lobatto points is compared with the model at the ``n`` points that
interlace them (the next level's new points, ``n = 2, 4, 8, 16, 32``); once the
largest difference over every time is within the tolerance, the next level's
interpolant (through all ``2n + 1`` points, more accurate still) answers. A
class whose readings do not converge by 33 points, or whose touches have no
more distinct effusivities than the points it would need, is read directly
(the model at every distinct effusivity). The tolerance is the one a
simulation asks of a numerically solved model
(:func:`designkit.simulation.response_tolerance`: 1 % of the noise over the
whole curve, at most 1e-5 of the temperature difference).

Examples
--------
>>> import numpy as np
>>> from designkit import SENSORS
>>> from designkit.models import get_model
>>> m = get_model("layered", film_thickness_m=2e-4, backing_effusivity_ws05_m2k=600.0, conductance_w_m2k=3000.0)
>>> t = np.arange(1, 401) / 200.0
>>> table = SharedResponse.build(m, t, 331.0, 506.0, SENSORS["paper"], tolerance=1e-7)
>>> e = np.random.default_rng(0).uniform(331.0, 506.0, 50)
>>> bool(np.max(np.abs(table.readings(e) - m.response(t, e, SENSORS["paper"]))) < 1e-7), table.nodes.size <= 9
(True, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import InputError
from .base import ForwardModel
from .semi_infinite import object_weight

__all__ = ["MAX_LEVEL", "SharedResponse", "class_readings"]

#: Most interpolation intervals (33 Chebyshev-Lobatto points); beyond, the class is read directly.
MAX_LEVEL = 32


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


@dataclass(frozen=True)
class SharedResponse:
    """A class's readings on one time grid: the model at a few effusivities, interpolated between them.

    Build it once per (model, sensor, time grid, class range, tolerance) with
    :meth:`build`; :meth:`readings` gives any touches' readings of the range at
    the cost of a ``(K, n) @ (n, m)`` product.

    Attributes
    ----------
    model : ForwardModel
        The model read.
    time_s : ndarray, shape (m,)
        The time grid [s].
    e_low, e_high : float
        The effusivity range covered [J s^-1/2 K^-1 m^-2].
    weights : ndarray, shape (n,)
        The contact weights ``w = e_o / (e_s + e_o)`` read (Chebyshev-Lobatto
        points of the range's weights); empty when ``direct``.
    values : ndarray, shape (n, m)
        The model's readings there.
    tolerance : float
        The largest interpolation error allowed (normalized reading).
    error : float
        The measured interpolation error of the level below the one used (an
        upper estimate of this one's); 0 when ``direct``.
    direct : bool
        True when no interpolant met the tolerance: the touches are to be read
        directly (:func:`class_readings` does).
    e_sensor : float
        The sensor's effusivity [J s^-1/2 K^-1 m^-2] (the weights' scale).
    """

    model: ForwardModel
    time_s: np.ndarray
    e_low: float
    e_high: float
    weights: np.ndarray
    values: np.ndarray
    tolerance: float
    error: float
    direct: bool
    e_sensor: float

    @classmethod
    def build(cls, model: ForwardModel, time_s, e_low: float, e_high: float, sensor, *, tolerance: float,
              distinct: int | None = None) -> "SharedResponse":
        """Read ``model`` at Chebyshev points of ``[e_low, e_high]`` until the interpolation is within ``tolerance``.

        Parameters
        ----------
        model : ForwardModel
            A model whose reading depends on the object through its effusivity only.
        time_s : array_like, shape (m,)
            Times after contact [s] (what :meth:`ForwardModel.response` takes).
        e_low, e_high : float
            The class range [J s^-1/2 K^-1 m^-2], ``0 <= e_low <= e_high <= inf``.
        sensor : designkit.Sensor
        tolerance : float
            Largest interpolation error (normalized reading), > 0.
        distinct : int, optional
            How many distinct effusivities the touches have: a level that would
            need as many model readings is not worth it (the caller reads them
            directly instead; :func:`class_readings`).

        Returns
        -------
        SharedResponse
            ``direct`` is False when an interpolant met the tolerance; True (with
            no nodes) when none did within :data:`MAX_LEVEL` or ``distinct`` points.
        """
        if not (tolerance > 0):
            raise InputError(f"interpolation tolerance must be > 0, got {tolerance!r}")
        lo, hi = float(e_low), float(e_high)
        if not (0.0 <= lo <= hi):
            raise InputError(f"effusivity range must have 0 <= low <= high, got [{lo:g}, {hi:g}]")
        t = np.atleast_1d(np.asarray(time_s, dtype=np.float64))
        es = float(sensor.effusivity)
        w_lo, w_hi = float(object_weight(es, lo)), float(object_weight(es, hi))
        limit = MAX_LEVEL if distinct is None else min(MAX_LEVEL, int(distinct) - 2)
        n = 2
        if w_hi <= w_lo or n > limit // 2:
            return cls(model, t, lo, hi, np.empty(0), np.empty((0, t.size)), float(tolerance), 0.0, True, es)
        # the first level and its check points in one reading (one pass of the model's fixed costs)
        w_all = _lobatto(2 * n, w_lo, w_hi)
        v_all = model.response(t, _effusivity(w_all, es), sensor, tolerance=0.1 * tolerance)
        w, values, w_new, u_new = w_all[0::2], v_all[0::2], w_all[1::2], v_all[1::2]
        while True:
            error = float(np.max(np.abs(_interpolate(w, values, w_new) - u_new)))
            if error <= tolerance:
                return cls(model, t, lo, hi, w_all, v_all, float(tolerance), error, False, es)
            n *= 2
            if 2 * n > limit:
                break
            w, values = w_all, v_all
            w_new = _lobatto(2 * n, w_lo, w_hi)[1::2]      # the points interlacing the current ones
            u_new = model.response(t, _effusivity(w_new, es), sensor, tolerance=0.1 * tolerance)
            w_all = np.empty(2 * n + 1)
            w_all[0::2], w_all[1::2] = w, w_new
            v_all = np.empty((2 * n + 1, t.size))
            v_all[0::2], v_all[1::2] = values, u_new
        return cls(model, t, lo, hi, np.empty(0), np.empty((0, t.size)), float(tolerance), 0.0, True, es)

    def readings(self, e_object) -> np.ndarray:
        """Normalized readings (K, m) of objects of effusivities ``e_object`` in ``[e_low, e_high]``."""
        e = np.atleast_1d(np.asarray(e_object, dtype=np.float64))
        if self.direct:
            raise InputError("this class response reads its touches directly (no interpolant): use class_readings")
        if e.size and (np.min(e) < self.e_low or np.max(e) > self.e_high):
            raise InputError(f"effusivities [{np.min(e):g}, {np.max(e):g}] outside the class response's range "
                             f"[{self.e_low:g}, {self.e_high:g}]")
        return np.clip(_interpolate(self.weights, self.values, object_weight(self.e_sensor, e)), 0.0, 1.0)

    @property
    def nodes(self) -> np.ndarray:
        """The effusivities read by the model [J s^-1/2 K^-1 m^-2]."""
        return _effusivity(self.weights, self.e_sensor)


def _interpolate(x_nodes: np.ndarray, values: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The polynomial through ``(x_nodes, values)`` (rows) at ``x``: shape (len(x), m)."""
    from scipy.interpolate import BarycentricInterpolator

    # the Lagrange basis at x (scipy's barycentric weights), then a sum of the nodes' rows: n passes over
    # (K, m), no BLAS (whose threads cost more than they save on a few rows, and vary the rounding)
    basis = np.atleast_2d(BarycentricInterpolator(x_nodes, np.eye(x_nodes.size), axis=0)(x))
    out = basis[:, :1] * values[0]
    for j in range(1, x_nodes.size):
        out += basis[:, j:j + 1] * values[j]
    return out


def class_readings(model: ForwardModel, time_s, e_object, sensor, *, tolerance: float,
                   diffusivity_m2_s=None, **build: Any) -> np.ndarray:
    """Normalized readings (K, m) of touches of one class: interpolated where the model is costly, else direct.

    Models with ``shared_response`` (the layered model, a force ramp) whose
    reading depends on the effusivity alone are read at a few effusivities of
    the touches' range (:class:`SharedResponse`); others, and touches with a
    per-touch diffusivity, are read directly by :meth:`ForwardModel.response`.

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
    """
    e = np.atleast_1d(np.asarray(e_object, dtype=np.float64))
    t = np.atleast_1d(np.asarray(time_s, dtype=np.float64))
    if not getattr(model, "shared_response", False) or diffusivity_m2_s is not None or e.size == 0 \
            or not np.all(np.isfinite(e)) or np.any(e < 0):
        return model.response(t, e, sensor, diffusivity_m2_s=diffusivity_m2_s, tolerance=tolerance)
    uniq, inverse = np.unique(e, return_inverse=True)
    table = SharedResponse.build(model, t, float(uniq[0]), float(uniq[-1]), sensor, tolerance=tolerance,
                                 distinct=uniq.size, **build)
    if table.direct:
        return model.response(t, uniq, sensor, tolerance=tolerance)[inverse.ravel()]
    return table.readings(e)
