"""Simulated touches: noisy sensor readings from the physics model (paper eq. 4).

Random draws follow one fixed protocol so that results are reproducible and
the engine's shortcuts are exact:

1. effusivities, uniform in the class range ``[e_low, e_high)``;
2. if the sensor temperature varies, one uniform offset in [-1, 1) per trial;
3. if the ambient temperature varies, one uniform offset in [-1, 1) per trial;
4. standard normal noise, drawn **time-major** (sample by sample across all
   trials), so that the first ``m`` samples of a longer touch are exactly the
   samples of a shorter touch drawn with the same seed. Truncating trials to a
   shorter contact time (as the paper did) is therefore identical to
   simulating the shorter contact directly.

With fixed initial conditions the readings are ``Ts0 + dT * (-w g + (sigma/dT) Z)``:
an affine image of a dataset that depends on sigma and dT only through
sigma/dT, which is why standardized-feature recognition depends only on that
ratio.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validation import (
    InputError,
    as_generator,
    check_effusivity,
    check_effusivity_range,
    check_nonnegative,
)
from .physics import object_weight, response_shape
from .scene import Scene
from .sensor import Sensor

__all__ = [
    "TrialDraws",
    "Trials",
    "draw_trials",
    "noisy_readings",
    "render_trials",
    "simulate_interval",
    "simulate_trials",
]


@dataclass(frozen=True)
class TrialDraws:
    """The random part of a set of trials, before any scene is applied.

    Attributes
    ----------
    effusivity : ndarray, shape (n,)
        Object effusivity of each trial [J s^-1/2 K^-1 m^-2].
    sensor_offset, ambient_offset : ndarray, shape (n,)
        Uniform offsets in [-1, 1) scaled by the scene's spreads (zeros when
        the condition is fixed).
    noise : ndarray, shape (n, m)
        Standard normal noise, one row per trial, one column per sample.
    """

    effusivity: np.ndarray
    sensor_offset: np.ndarray
    ambient_offset: np.ndarray
    noise: np.ndarray

    @property
    def n_trials(self) -> int:
        return int(self.effusivity.shape[0])

    @property
    def n_samples(self) -> int:
        return int(self.noise.shape[1])

    def truncate(self, n_samples: int) -> "TrialDraws":
        """The same trials cut to their first ``n_samples`` samples.

        Identical to drawing the shorter trials with the same seed.
        """
        if not 1 <= n_samples <= self.n_samples:
            raise InputError(f"cannot truncate {self.n_samples} samples to {n_samples}")
        return TrialDraws(self.effusivity, self.sensor_offset, self.ambient_offset,
                          self.noise[:, :n_samples])


@dataclass(frozen=True)
class Trials:
    """Simulated touches.

    Attributes
    ----------
    time_s : ndarray, shape (m,)
        Sample times after contact [s].
    temperature_c : ndarray, shape (n, m)
        Thermistor readings [degC], one row per trial.
    effusivity : ndarray, shape (n,)
        Object effusivity of each trial [J s^-1/2 K^-1 m^-2].
    sensor_temp_c, ambient_temp_c : ndarray, shape (n,)
        Initial sensor and object temperatures of each trial [degC].
    """

    time_s: np.ndarray
    temperature_c: np.ndarray
    effusivity: np.ndarray
    sensor_temp_c: np.ndarray
    ambient_temp_c: np.ndarray


def draw_trials(e_low: float, e_high: float, n_trials: int, n_samples: int, seed,
                *, vary_sensor: bool = False, vary_ambient: bool = False) -> TrialDraws:
    """Draw the random part of ``n_trials`` trials of one effusivity class.

    Parameters
    ----------
    e_low, e_high : float
        Class range ``[e_low, e_high)`` [J s^-1/2 K^-1 m^-2]; ``e_low == e_high``
        draws that single value.
    n_trials : int
        Trials to draw (>= 1).
    n_samples : int
        Samples per trial (>= 1).
    seed : int, sequence of int, or numpy.random.Generator
        Explicit seed (see :func:`designkit._validation.as_generator`).
    vary_sensor, vary_ambient : bool
        Whether to draw per-trial offsets of the initial temperatures.
    """
    lo = check_effusivity("class lower bound", e_low, allow_zero=True)
    hi = check_effusivity("class upper bound", e_high, allow_zero=True)
    if hi < lo:
        raise InputError(f"effusivity range must have low <= high, got [{lo:g}, {hi:g})")
    if int(n_trials) < 1 or int(n_samples) < 1:
        raise InputError(f"need at least one trial and one sample, got {n_trials} and {n_samples}")
    n, m = int(n_trials), int(n_samples)
    rng = as_generator(seed)
    e = rng.uniform(lo, hi, n) if hi > lo else np.full(n, lo)
    zeros = np.zeros(n)
    s_off = rng.uniform(-1.0, 1.0, n) if vary_sensor else zeros
    a_off = rng.uniform(-1.0, 1.0, n) if vary_ambient else zeros
    noise = rng.standard_normal((m, n)).T  # time-major: prefixes do not depend on m
    return TrialDraws(e, s_off, a_off, noise)


def noisy_readings(time_s, e_object, sensor_temp_c, ambient_temp_c, sensor: Sensor,
                   noise_c: float, noise) -> np.ndarray:
    """Thermistor readings with additive Gaussian noise (paper eq. 4).

    Parameters
    ----------
    time_s : array_like, shape (m,)
        Sample times after contact [s].
    e_object, sensor_temp_c, ambient_temp_c : array_like, shape (n,) or scalar
        Per-trial object effusivity [J s^-1/2 K^-1 m^-2] and initial sensor and
        object temperatures [degC].
    sensor : Sensor
        Gives e_s and tau.
    noise_c : float
        Noise standard deviation sigma [degC].
    noise : array_like, shape (n, m)
        Standard normal draws (scaled here by ``noise_c``).

    Returns
    -------
    ndarray, shape (n, m)
        Readings [degC].
    """
    sigma = check_nonnegative("noise sigma [degC]", noise_c)
    g = response_shape(np.asarray(time_s, dtype=np.float64), sensor.tau_s)
    e = np.atleast_1d(np.asarray(e_object, dtype=np.float64))
    ts = np.atleast_1d(np.asarray(sensor_temp_c, dtype=np.float64))
    ta = np.atleast_1d(np.asarray(ambient_temp_c, dtype=np.float64))
    amp = (ta - ts) * object_weight(sensor.effusivity, e)  # Tc - Ts0 per trial
    out = ts[:, None] + amp[:, None] * g[None, :]
    if sigma > 0:
        out = out + sigma * np.asarray(noise, dtype=np.float64)
    return out


def render_trials(draws: TrialDraws, sensor: Sensor, scene: Scene) -> Trials:
    """Apply a scene to drawn trials: readings of ``draws.n_samples`` samples."""
    time_s = np.arange(draws.n_samples, dtype=np.float64) / sensor.sample_rate_hz
    ts = scene.sensor_temp_c + scene.sensor_temp_spread_c * draws.sensor_offset
    ta = scene.ambient_temp_c + scene.ambient_temp_spread_c * draws.ambient_offset
    temps = noisy_readings(time_s, draws.effusivity, ts, ta, sensor, scene.noise_c, draws.noise)
    return Trials(time_s, temps, draws.effusivity, ts, ta)


def simulate_interval(e_low: float, e_high: float, n_trials: int, sensor: Sensor,
                      scene: Scene, seed) -> Trials:
    """Trials of one effusivity class: e uniform in ``[e_low, e_high)`` (paper section IV-A).

    Examples
    --------
    >>> from designkit import SENSORS, Scene
    >>> t = simulate_interval(20000, 20080, 100, SENSORS["paper"], Scene(contact_s=2), seed=0)
    >>> t.temperature_c.shape
    (100, 401)
    """
    lo, hi = check_effusivity_range("class", e_low, e_high)
    n_samples = sensor.times_s(scene.contact_s).size
    draws = draw_trials(lo, hi, n_trials, n_samples, seed,
                        vary_sensor=scene.sensor_temp_spread_c > 0,
                        vary_ambient=scene.ambient_temp_spread_c > 0)
    return render_trials(draws, sensor, scene)


def simulate_trials(e_object: float, sensor: Sensor, scene: Scene, n_trials: int = 1,
                    seed=0) -> Trials:
    """``n_trials`` touches of one object of effusivity ``e_object``.

    ``e_object`` may be 0 (perfect insulator) or ``inf`` (perfect conductor).
    """
    e = check_effusivity("e", e_object, allow_zero=True, allow_inf=True)
    n_samples = sensor.times_s(scene.contact_s).size
    draws = draw_trials(0.0, 0.0, n_trials, n_samples, seed,
                        vary_sensor=scene.sensor_temp_spread_c > 0,
                        vary_ambient=scene.ambient_temp_spread_c > 0)
    draws = TrialDraws(np.full(draws.n_trials, e), draws.sensor_offset,
                       draws.ambient_offset, draws.noise)
    return render_trials(draws, sensor, scene)
