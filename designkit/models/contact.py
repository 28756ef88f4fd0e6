"""Imperfect thermal contact: a finite interface conductance between sensor and object.

Two semi-infinite solids (sensor at ``Ts0``, object at ``Ta``) touch through
an interface of conductance ``h_c`` [W m^-2 K^-1] (a thin air gap, surface
roughness, low contact force). Solving the heat equation in each body with
``q = h_c (T_o - T_s)`` at the interface (Laplace transform, inverted with
Carslaw & Jaeger's table [1]_, their section 2.7) gives, for the thermistor at
depth ``x`` in the sensor,

.. math::

    u(t) = w \\left[ \\operatorname{erfc}\\sqrt{\\tau/t}
           - e^{-\\tau/t}\\, \\operatorname{erfcx}\\!\\left(\\sqrt{\\tau/t} + \\beta\\sqrt{t}\\right)\\right],
    \\qquad \\beta = h_c \\left(\\frac{1}{e_s} + \\frac{1}{e_o}\\right),

with ``w = e_o / (e_s + e_o)`` and ``tau = x^2 / (4 alpha_s)`` as in the
paper's model. (``exp(2 beta sqrt(tau) + beta^2 t) erfc(sqrt(tau/t) + beta sqrt(t))``
is written with the scaled ``erfcx`` so that nothing overflows.) As
``h_c -> inf`` (``beta -> inf``) the second term vanishes and this is the
semi-infinite model; at ``x = 0`` it is the classic ``w (1 - erfcx(beta sqrt(t)))``.

The lag ``1 / beta^2`` [s] depends on the object, so the curves of a scene no
longer share one shape: the ideal observer is computed by Monte Carlo.

References
----------
.. [1] H. S. Carslaw and J. C. Jaeger, *Conduction of Heat in Solids*, 2nd ed.,
   Oxford, 1959, sections 2.7 and 14.2 (Laplace inversion table, entry 11).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validation import check_positive
from .base import ForwardModel
from .semi_infinite import SemiInfinite, object_weight

__all__ = ["Contact"]


@dataclass(frozen=True)
class Contact(ForwardModel):
    """Semi-infinite sensor and object with a finite interface conductance.

    Parameters
    ----------
    conductance_w_m2k : float
        Interface conductance h_c [W m^-2 K^-1] (> 0; ``inf`` — or None, as
        JSON records it — is perfect contact, the paper's model). Typical: 10^3-10^4 for a light touch of
        smooth solids, 10^2 through a thin air gap.

    Examples
    --------
    >>> from designkit import SENSORS
    >>> from designkit.models import SemiInfinite
    >>> s = SENSORS["paper"]
    >>> good = Contact(1e12).response([2.0], [20000.0], s)
    >>> ideal = SemiInfinite().response([2.0], [20000.0], s)
    >>> abs(float(good[0, 0] - ideal[0, 0])) < 1e-9
    True
    >>> float(Contact(500.0).response([2.0], [20000.0], s)[0, 0]) < float(ideal[0, 0])
    True
    """

    conductance_w_m2k: float = 2000.0

    name = "contact"
    shared_shape = False
    units = {"conductance_w_m2k": "W m^-2 K^-1"}

    def __post_init__(self) -> None:
        if self.conductance_w_m2k is None:  # what to_dict() writes for inf (JSON has no infinity)
            object.__setattr__(self, "conductance_w_m2k", math.inf)
        object.__setattr__(self, "conductance_w_m2k",
                           check_positive("interface conductance h_c [W m^-2 K^-1]", self.conductance_w_m2k,
                                          allow_inf=True))

    def beta(self, e_object, sensor) -> np.ndarray:
        """``beta = h_c (1/e_s + 1/e_o)`` [s^-1/2]; inf for perfect contact or an insulator."""
        eo = np.asarray(e_object, dtype=np.float64)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            b = self.conductance_w_m2k * (1.0 / sensor.effusivity + 1.0 / eo)
        return np.where(np.isnan(b), np.inf, b)

    def response(self, time_s, e_object, sensor, *, diffusivity_m2_s=None, tolerance: float = 1e-9) -> np.ndarray:
        from scipy import special

        t = np.asarray(time_s, dtype=np.float64)[None, :]
        eo = np.atleast_1d(np.asarray(e_object, dtype=np.float64))[:, None]
        w = object_weight(sensor.effusivity, eo)
        beta = self.beta(eo, sensor)
        tau = sensor.tau_s
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            r = np.sqrt(np.where(t > 0, tau / t, np.inf)) if tau > 0 else np.zeros_like(t)
            first = special.erfc(r)
            arg = r + beta * np.sqrt(t)
            lag = np.exp(-np.square(r)) * special.erfcx(arg)
        # erfcx(inf) = 0 (perfect contact, or t = 0 with tau > 0); at t = 0 and tau = 0, arg = 0: lag = 1.
        lag = np.where(np.isinf(arg), 0.0, lag)
        lag = np.where(np.isnan(lag), 0.0, lag)
        u = w * (first - lag)
        return np.clip(u, 0.0, 1.0)

    def equivalent_shared_shape(self, objects, sensor, *, contact_s: float, tolerance: float):
        """The semi-infinite model where the lag term is below ``tolerance`` at every time.

        ``exp(-tau/t) erfcx(r + beta sqrt(t)) <= 1 / (sqrt(pi) (r + beta sqrt(t)))``
        and ``w <= 1``, largest at the first sample (``t = 1/fs``) and the
        object with the smallest ``beta`` (the highest effusivity).
        """
        if math.isinf(self.conductance_w_m2k):
            return SemiInfinite()
        e_hi = max(float(np.max(o.e_range)) for o in objects)
        t0 = 1.0 / sensor.sample_rate_hz
        b = float(self.beta(e_hi, sensor))
        bound = 1.0 / (math.sqrt(math.pi) * b * math.sqrt(t0))
        return SemiInfinite() if bound <= tolerance else None
