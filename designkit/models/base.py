"""The forward-model seam: what every physical model of a touch provides.

A *forward model* maps an object (its effusivity, and whatever else the model
needs, for example its diffusivity) and a sensor to the **normalized reading**
of a touch,

.. math::

    u(t) = \\frac{T(t) - T_{s0}}{T_a - T_{s0}},

0 before contact and 1 when the thermistor has taken the object's
temperature. Every model here is linear in the temperatures (constant
properties, heat equation), so a reading is ``Ts0 + (Ta - Ts0) u(t)`` plus
noise, and with fixed initial conditions recognition from standardized
features depends on noise and temperature difference only through
``sigma / |Ts0 - Ta|`` (docs/physics.md, section "Invariance").

Some models also have a **shared shape**: ``u(t) = w(e_o) g(t)`` with one
``g`` for every object of a scene (the paper's semi-infinite model,
``g = erfc(sqrt(tau/t))``, ``w = e_o / (e_s + e_o)``). Then the ideal observer
is exact in closed form (:mod:`designkit.recognition.ideal`); other models are
answered by Monte Carlo on the exact likelihood.

Models are small frozen dataclasses whose fields are the model's parameters
(units in the names); the registry in :mod:`designkit.models` finds them by
name, like pvlib's model catalogues.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, ClassVar, Mapping

import numpy as np

from .._validation import InputError

__all__ = ["ForwardModel", "ModelCheck"]


@dataclass(frozen=True)
class ModelCheck:
    """Whether a model's answer for a question can be trusted, and what limits it.

    Attributes
    ----------
    model : str
        The model checked.
    holds : bool
        False when the model is outside its validity range for the question.
    message : str
        One line for people.
    details : dict
        Model-specific figures (JSON-ready).
    """

    model: str
    holds: bool
    message: str = ""
    details: Mapping[str, Any] = dataclasses.field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.model, "holds": self.holds, "message": self.message, "details": dict(self.details)}


@dataclass(frozen=True)
class ForwardModel:
    """Base of every forward model (subclass it as a frozen dataclass).

    Attributes
    ----------
    name : str
        Registry name (``"semi-infinite"``, ``"slab"``, ``"contact"``).
    shared_shape : bool
        True when ``u(t) = weight(e_o) * shape(t)`` for every object: then
        :meth:`shape` and :meth:`weight` are defined and the closed-form ideal
        observer applies.
    object_properties : tuple of str
        What an object class must give: ``"effusivity"`` always,
        ``"diffusivity_m2_s"`` for models whose reading depends on it.
    units : dict
        Unit of each parameter (dataclass field), for documentation and
        messages.
    """

    name: ClassVar[str] = ""
    shared_shape: ClassVar[bool] = False
    object_properties: ClassVar[tuple[str, ...]] = ("effusivity",)
    units: ClassVar[dict[str, str]] = {}
    #: Solved numerically (an inverse Laplace transform, say): a caller evaluating it at many times may
    #: interpolate it between fewer (the identification does).
    solved_numerically: ClassVar[bool] = False
    #: Costly per object (an inverse Laplace transform per time, a sum over a force ramp): a simulation of
    #: many touches of one class reads it at a few effusivities of the class and interpolates between them,
    #: within the simulation's tolerance (:mod:`designkit.models.shared`).
    shared_response: ClassVar[bool] = False

    # ------------------------------------------------------------ the physics
    def response(self, time_s, e_object, sensor, *, diffusivity_m2_s=None, tolerance: float = 1e-9) -> np.ndarray:
        """Normalized reading ``u`` of touches, shape ``(K, m)``.

        Parameters
        ----------
        time_s : array_like, shape (m,)
            Times after contact [s] (>= 0).
        e_object : array_like, shape (K,)
            Object effusivities [J s^-1/2 K^-1 m^-2].
        sensor : designkit.Sensor
            The sensor (effusivity e_s, time constant tau, ...).
        diffusivity_m2_s : array_like, shape (K,), optional
            Object diffusivities [m^2 s^-1]; required when
            ``"diffusivity_m2_s"`` is in :attr:`object_properties`.
        tolerance : float
            Largest acceptable error of ``u`` (models solved numerically use it
            to choose their method; closed forms ignore it).
        """
        if self.shared_shape:
            t = np.asarray(time_s, dtype=np.float64)
            w = np.atleast_1d(self.weight(e_object, sensor))
            return w[:, None] * self.shape(t, sensor)[None, :]
        raise NotImplementedError(f"model {self.name!r} defines no response")

    def conduction(self, time_s, e_object, sensor, *, nodes: int | None = None) -> np.ndarray:
        """The reading before any smoothing by the measurement chain, shape ``(K, m)``: what an emulated
        rig streams raw and what a calibration fit smooths itself. This default is :meth:`response` (a
        model without a smoothing stage); ``nodes`` is for numerically inverted models (ignored here)."""
        return self.response(time_s, e_object, sensor)

    def shape(self, time_s, sensor) -> np.ndarray:
        """Shared shape ``g(t)`` (shared-shape models only)."""
        raise InputError(f"model {self.name!r} has no shared response shape: its curves differ per object")

    def weight(self, e_object, sensor) -> np.ndarray:
        """Amplitude ``w(e_o)`` of the shared shape (shared-shape models only)."""
        raise InputError(f"model {self.name!r} has no shared response shape: its curves differ per object")

    # ------------------------------------------------------------ the catalogue entry
    def check(self, objects, sensor, *, contact_s: float, noise_c: float, delta_t_c: float) -> ModelCheck:
        """Whether this model holds for these objects over ``contact_s``.

        The default says nothing is known against it; models with a validity
        range override it.
        """
        return ModelCheck(self.name, True)

    def equivalent_shared_shape(self, objects, sensor, *, contact_s: float, tolerance: float) -> "ForwardModel | None":
        """A shared-shape model whose readings differ from this one's by at most ``tolerance``
        (normalized) for these objects up to ``contact_s``, or None.

        Lets the closed-form ideal observer answer where the extra physics is
        invisible (a slab too thick to matter, a contact too good to lag).
        """
        return self if self.shared_shape else None

    def parameters(self) -> dict[str, Any]:
        """The model's parameters, JSON-ready (field name -> value)."""
        out = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            out[f.name] = v.to_dict() if hasattr(v, "to_dict") else (None if isinstance(v, float) and
                                                                      math.isinf(v) else v)
        return out

    def to_dict(self) -> dict[str, Any]:
        """``{"name": ..., **parameters}``: what a table header or an answer records."""
        return {"name": self.name, **self.parameters()}

    def describe(self) -> str:
        """One line for people: the name and the parameters with units."""
        parts = [f"{k} = {v:g} {self.units.get(k, '')}".rstrip() if isinstance(v, (int, float)) else f"{k} = {v}"
                 for k, v in self.parameters().items()]
        return self.name + (f" ({', '.join(parts)})" if parts else "")
