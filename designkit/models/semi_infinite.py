"""Heat transfer between a heated sensor and an object: the semi-infinite model.

Pure, vectorized functions of the reference paper's section II (Bai et al.,
"Analyzing Material Recognition Performance of Thermal Tactile Sensing using a
Large Materials Database and a Real Robot", eqs. 1-4). Inputs broadcast against
each other like numpy ufuncs.

Units
-----
effusivity ``e = k / sqrt(alpha) = sqrt(k rho c)``  [J s^-1/2 K^-1 m^-2]
diffusivity ``alpha``                               [m^2 s^-1]
thermistor depth ``x``                              [m]
time after contact ``t``                            [s]
temperatures                                        [degC]

The two model parameters of the sensor, its depth ``x`` and diffusivity
``alpha_s``, enter only through the time constant ``tau = x^2 / (4 alpha_s)``
[s]: the argument of erfc in eq. 2 is ``sqrt(tau / t)``. Data identify ``tau``,
not ``x`` and ``alpha_s`` apart.

Limits handled exactly (no NaN, no warning): ``t = 0`` (the reading is still
the initial sensor temperature), ``x = 0`` (``tau = 0``: the thermistor sits on
the contact surface and jumps to the contact temperature at once), ``e_o = 0``
(a perfect insulator: nothing changes), ``e_o = inf`` (a perfect conductor:
the surface takes the object's temperature), ``t << tau`` (erfc deep in its
tail, available in log form through :func:`log_response_shape`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..properties import effusivity, effusivity_from_conductivity_diffusivity, time_constant
from .base import ForwardModel

__all__ = [
    "SemiInfinite",
    "contact_temperature",
    "effusivity",
    "effusivity_from_conductivity_diffusivity",
    "log_response_shape",
    "object_weight",
    "response_shape",
    "sensor_temperature",
    "temperature_change",
    "time_constant",
]

_LOG2 = float(np.log(2.0))
_SQRT2 = float(np.sqrt(2.0))


def object_weight(e_sensor, e_object):
    """Share of the sensor-object temperature difference taken by the surface.

    ``w = e_o / (e_s + e_o)`` in [0, 1], computed as ``1 / (1 + e_s / e_o)`` so
    that ``e_o = inf`` gives exactly 1 and ``e_o = 0`` exactly 0. The contact
    temperature (paper eq. 1) is ``Tc = Ts0 + (To - Ts0) * w``.

    Parameters
    ----------
    e_sensor : array_like
        Sensor effusivity e_s [J s^-1/2 K^-1 m^-2] (> 0).
    e_object : array_like
        Object effusivity e_o [J s^-1/2 K^-1 m^-2] (>= 0, may be inf).

    Returns
    -------
    ndarray
        w, dimensionless.

    Examples
    --------
    >>> object_weight(892.0, np.array([0.0, 892.0, np.inf]))
    array([0. , 0.5, 1. ])
    """
    es = np.asarray(e_sensor, dtype=np.float64)
    eo = np.asarray(e_object, dtype=np.float64)
    with np.errstate(divide="ignore", over="ignore"):
        ratio = es / eo  # inf for e_o = 0 (or denormal), 0 for e_o = inf
    return 1.0 / (1.0 + ratio)


def contact_temperature(sensor_temp_c, object_temp_c, e_sensor, e_object):
    """Contact surface temperature Tc (paper eq. 1).

    ``Tc = (Ts0 e_s + To e_o) / (e_s + e_o)``, evaluated as
    ``Ts0 + (To - Ts0) * w`` with :func:`object_weight`, which is exact at
    ``e_o = 0`` and ``e_o = inf``.

    Parameters
    ----------
    sensor_temp_c : array_like
        Initial sensor temperature Ts0 [degC].
    object_temp_c : array_like
        Initial object temperature To (= ambient Ta in the paper) [degC].
    e_sensor, e_object : array_like
        Effusivities [J s^-1/2 K^-1 m^-2].

    Returns
    -------
    ndarray
        Tc [degC].

    Examples
    --------
    >>> float(contact_temperature(35.0, 25.0, 892.0, 892.0))  # equal effusivities meet half way [degC]
    30.0
    """
    ts = np.asarray(sensor_temp_c, dtype=np.float64)
    to = np.asarray(object_temp_c, dtype=np.float64)
    return ts + (to - ts) * object_weight(e_sensor, e_object)


def _tau_over_t(time_s, tau_s):
    t = np.asarray(time_s, dtype=np.float64)
    tau = np.asarray(tau_s, dtype=np.float64)
    t, tau = np.broadcast_arrays(t, tau)
    out = np.empty(t.shape, dtype=np.float64)
    pos = t > 0
    with np.errstate(over="ignore"):  # tau / (denormal t) -> inf: the correct limit
        np.divide(tau, t, out=out, where=pos)
    # At t = 0: a buried thermistor (tau > 0) has not moved yet (ratio = inf, erfc = 0);
    # one on the surface (tau = 0) is already at the contact temperature (ratio = 0).
    out[~pos] = np.where(tau[~pos] > 0, np.inf, 0.0)
    return out


def response_shape(time_s, tau_s):
    """Normalized sensor response ``g(t) = erfc(sqrt(tau / t))`` (paper eq. 2).

    Every noise-free curve of a scene is ``Ts0 + (Tc - Ts0) * g(t)``: the object
    only sets the amplitude, g sets the shape.

    Parameters
    ----------
    time_s : array_like
        Time after contact [s], >= 0.
    tau_s : array_like
        Sensor time constant [s], >= 0 (see :func:`time_constant`).

    Returns
    -------
    ndarray
        g in [0, 1], increasing in t. ``g(0) = 0`` for a buried thermistor;
        with ``tau = 0`` (thermistor at the surface), ``g = 1`` for all t >= 0.
        Underflows to 0 for ``tau / t`` above about 740; use
        :func:`log_response_shape` there.

    Examples
    --------
    >>> response_shape(np.array([0.0, 1.3445, 100.0]), 1.3445).round(4)  # the paper's sensor, tau = 1.3445 s
    array([0.    , 0.1573, 0.8697])
    """
    from scipy import special  # imported here: a table query never needs it (~150 ms)

    return special.erfc(np.sqrt(_tau_over_t(time_s, tau_s)))


def log_response_shape(time_s, tau_s):
    """Natural log of :func:`response_shape`, accurate deep in the erfc tail.

    Uses ``erfc(z) = 2 Phi(-sqrt(2) z)`` and :func:`scipy.special.log_ndtr`, so
    ``t << tau`` (ratio ``tau / t`` in the thousands) gives a finite, accurate
    value where ``erfc`` itself underflows.

    Returns
    -------
    ndarray
        log g; ``-inf`` at t = 0 for tau > 0.
    """
    from scipy import special

    z = np.sqrt(_tau_over_t(time_s, tau_s))
    return _LOG2 + special.log_ndtr(-_SQRT2 * z)


def temperature_change(time_s, e_object, sensor_temp_c, object_temp_c, e_sensor, tau_s):
    """Noise-free change of the sensor reading since contact, ``T(t) - Ts0``.

    ``(Tc - Ts0) * g(t) = (To - Ts0) * w(e_o) * erfc(sqrt(tau / t))``
    (paper eqs. 1-2). This is the part of the reading that carries material
    information; it is accurate to full relative precision also where it is
    tiny (early times, t << tau), unlike ``T(t)`` itself, whose value there is
    dominated by Ts0.

    Parameters
    ----------
    time_s : array_like
        Time after contact [s].
    e_object : array_like
        Object effusivity [J s^-1/2 K^-1 m^-2].
    sensor_temp_c, object_temp_c : array_like
        Initial sensor and object temperatures [degC].
    e_sensor : array_like
        Sensor effusivity [J s^-1/2 K^-1 m^-2].
    tau_s : array_like
        Sensor time constant [s].

    Returns
    -------
    ndarray
        [K], broadcast over all inputs.

    Examples
    --------
    >>> temperature_change(np.array([1.0]), 20000.0, 35.0, 25.0, 892.0, 1.3445).round(3)  # after 1 s [degC]
    array([-0.967])
    """
    ts = np.asarray(sensor_temp_c, dtype=np.float64)
    to = np.asarray(object_temp_c, dtype=np.float64)
    amp = (to - ts) * object_weight(e_sensor, e_object)
    return amp * response_shape(time_s, tau_s)


def sensor_temperature(time_s, e_object, sensor_temp_c, object_temp_c, e_sensor, tau_s):
    """Noise-free thermistor reading T(t) (paper eq. 2).

    ``T(t) = Ts0 + (Tc - Ts0) * erfc(x / (2 sqrt(alpha_s t)))``. Add i.i.d.
    ``N(0, sigma^2)`` per sample for paper eq. 4
    (:func:`designkit.simulation.simulate_trials`).

    Parameters
    ----------
    time_s : array_like
        Time after contact [s], >= 0.
    e_object : array_like
        Object effusivity [J s^-1/2 K^-1 m^-2], 0 to inf.
    sensor_temp_c, object_temp_c : array_like
        Initial sensor temperature Ts0 and object temperature To [degC].
    e_sensor : array_like
        Sensor effusivity e_s [J s^-1/2 K^-1 m^-2].
    tau_s : array_like
        Sensor time constant tau = x^2 / (4 alpha_s) [s].

    Returns
    -------
    ndarray
        T(t) [degC].

    Examples
    --------
    >>> from designkit.models.semi_infinite import sensor_temperature, time_constant
    >>> tau = time_constant(80e-6, 1.19e-9)
    >>> round(float(sensor_temperature(4.0, 20000.0, 35.0, 25.0, 892.0, tau)), 4)
    31.0534
    """
    ts = np.asarray(sensor_temp_c, dtype=np.float64)
    return ts + temperature_change(time_s, e_object, sensor_temp_c, object_temp_c,
                                   e_sensor, tau_s)


@dataclass(frozen=True)
class SemiInfinite(ForwardModel):
    """The paper's model: sensor and object as semi-infinite solids in perfect contact.

    ``u(t) = w(e_o) g(t)`` with ``w = e_o / (e_s + e_o)`` (:func:`object_weight`,
    paper eq. 1) and ``g = erfc(sqrt(tau / t))`` (:func:`response_shape`, eq. 2):
    one shape for every object of a scene. No parameters beyond the sensor's.

    Validity: objects thick enough that heat has not reached their far side
    (Fourier number ``alpha_o t / L^2`` small; :class:`designkit.models.slab.Slab`
    says when), perfect thermal contact (:class:`designkit.models.contact.Contact`
    relaxes it), temperature-independent properties.

    Examples
    --------
    >>> from designkit import SENSORS
    >>> u = SemiInfinite().response([0.0, 1.0, 4.0], [892.0], SENSORS["paper"])
    >>> [round(float(x), 4) for x in u[0]]
    [0.0, 0.0505, 0.2061]
    """

    name = "semi-infinite"
    shared_shape = True

    def shape(self, time_s, sensor) -> np.ndarray:
        return response_shape(np.asarray(time_s, dtype=np.float64), sensor.tau_s)

    def weight(self, e_object, sensor) -> np.ndarray:
        return object_weight(sensor.effusivity, e_object)
