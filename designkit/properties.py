"""Thermal properties: effusivity and the sensor's time constant (paper eq. 1 and section II).

Units: conductivity k [W m^-1 K^-1], density rho [kg m^-3], specific heat c
[J kg^-1 K^-1], diffusivity alpha [m^2 s^-1], effusivity e [J s^-1/2 K^-1 m^-2],
depth x [m], time constant tau [s]. Used by the nouns (sensors, materials) and
the forward models alike.

Examples
--------
>>> round(float(effusivity(1.0, 2500.0, 840.0)))  # glass-like: k 1 W/(m K), 2500 kg/m^3, 840 J/(kg K)
1449
>>> round(float(time_constant(80e-6, 1.19e-9)), 4)  # the paper's sensor
1.3445
"""

from __future__ import annotations

import numpy as np

__all__ = ["effusivity", "effusivity_from_conductivity_diffusivity", "time_constant"]


def effusivity(conductivity_w_mk, density_kg_m3, specific_heat_j_kgk):
    """Thermal effusivity ``e = sqrt(k rho c)``.

    Parameters
    ----------
    conductivity_w_mk : array_like
        Thermal conductivity k [W m^-1 K^-1].
    density_kg_m3 : array_like
        Density rho [kg m^-3].
    specific_heat_j_kgk : array_like
        Specific heat capacity c [J kg^-1 K^-1].

    Returns
    -------
    ndarray
        Effusivity [J s^-1/2 K^-1 m^-2] (paper eq. 1, ``e = k / sqrt(alpha)``
        with ``alpha = k / (rho c)``).
    """
    k = np.asarray(conductivity_w_mk, dtype=np.float64)
    rho = np.asarray(density_kg_m3, dtype=np.float64)
    c = np.asarray(specific_heat_j_kgk, dtype=np.float64)
    return np.sqrt(k * rho * c)


def effusivity_from_conductivity_diffusivity(conductivity_w_mk, diffusivity_m2_s):
    """Thermal effusivity ``e = k / sqrt(alpha)`` (paper eq. 1).

    Parameters
    ----------
    conductivity_w_mk : array_like
        Thermal conductivity k [W m^-1 K^-1].
    diffusivity_m2_s : array_like
        Thermal diffusivity alpha [m^2 s^-1].

    Returns
    -------
    ndarray
        Effusivity [J s^-1/2 K^-1 m^-2].
    """
    k = np.asarray(conductivity_w_mk, dtype=np.float64)
    a = np.asarray(diffusivity_m2_s, dtype=np.float64)
    return k / np.sqrt(a)


def time_constant(depth_m, diffusivity_m2_s):
    """Sensor time constant ``tau = x^2 / (4 alpha_s)`` [s].

    Parameters
    ----------
    depth_m : array_like
        Thermistor depth x below the contact surface [m] (>= 0).
    diffusivity_m2_s : array_like
        Sensor diffusivity alpha_s [m^2 s^-1] (> 0).

    Returns
    -------
    ndarray
        tau [s]; the argument of erfc in paper eq. 2 is ``sqrt(tau / t)``.
        For the paper's sensor (80 um, 1.19e-9 m^2/s) tau = 1.3445 s.
    """
    x = np.asarray(depth_m, dtype=np.float64)
    a = np.asarray(diffusivity_m2_s, dtype=np.float64)
    return x * x / (4.0 * a)
