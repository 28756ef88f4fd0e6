"""Simulated touches: noisy sensor readings from any forward model (paper eq. 4).

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

5. where the forward model needs the object's diffusivity (a slab), one
   uniform draw per trial in the class's diffusivity range, from the
   independent stream ``seed + [7]``;
6. where the model is a force ramp with calibration touches' own presses,
   one of them per trial, uniformly, from the stream ``seed + [8]``.

A rig's scene (:func:`designkit.rig.rig_scene`) makes the noise correlated
(``Scene.noise_correlation_s``: the white draws through a lower-triangular
factor, so prefixes still hold, to rounding) and starts the samples at the recorder's
detected onset (``Scene.onset_s``), as the rig's recognizer sees a touch.

The noise-free reading is ``Ts0 + (Ta - Ts0) u(t)`` with ``u`` from the forward
model (:mod:`designkit.models`; the paper's semi-infinite one by default).
With fixed initial conditions the readings are ``Ts0 + dT * (-u + (sigma/dT) Z)``:
an affine image of a dataset that depends on sigma and dT only through
sigma/dT, which is why standardized-feature recognition depends only on that
ratio, for every (linear) model.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np

from ._validation import (
    InputError,
    as_generator,
    check_effusivity,
    check_effusivity_range,
    check_nonnegative,
)
from .models import ForwardModel, get_model
from .models.semi_infinite import object_weight, response_shape
from .models.shared import class_readings
from .objects import ObjectClass
from .scene import Scene
from .sensor import Sensor

__all__ = [
    "DIFFUSIVITY_STREAM",
    "RAMP_STREAM",
    "TrialDraws",
    "Trials",
    "check_touch_budget",
    "correlate_noise",
    "noise_cholesky",
    "draw_trials",
    "noisy_readings",
    "render_trials",
    "response_tolerance",
    "seed_key",
    "simulate_class",
    "simulate_interval",
    "simulate_trials",
    "touch_picks",
    "window_times_s",
]

#: Seed-key suffix of the per-trial diffusivity draws (independent of the noise).
DIFFUSIVITY_STREAM = 7
#: Seed-key suffix of the per-trial choice of a calibration touch's press (a force ramp with touch ramps).
RAMP_STREAM = 8


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
    diffusivity_m2_s : ndarray, shape (n,), or None
        Object diffusivity of each trial [m^2 s^-1], where the model needs it.
    model : str
        Forward model that made the readings.
    """

    time_s: np.ndarray
    temperature_c: np.ndarray
    effusivity: np.ndarray
    sensor_temp_c: np.ndarray
    ambient_temp_c: np.ndarray
    diffusivity_m2_s: np.ndarray | None = None
    model: str = "semi-infinite"


#: float64 arrays of one touch's length that a simulation holds at once per touch (the noise drawn, the
#: response rendered, the readings).
SIMULATION_COPIES = 4


def check_touch_budget(what: str, n_touches: int, n_samples: int, *, copies: int = SIMULATION_COPIES) -> None:
    """The per-request budget of simulated touches, checked before anything is drawn: at most
    :data:`designkit.sensor.MAX_SAMPLES_PER_TOUCH` samples per touch, and ``copies`` float64 arrays of
    ``n_touches x n_samples`` within :func:`designkit._validation.memory_limit_bytes`. One line otherwise.

    The one check of every command that simulates (simulate, f1, design, classify, a sweep's chunk):
    :func:`draw_trials` applies it, and commands that hold more copies call it first with their count.

    >>> check_touch_budget("f1", 200, 401)
    """
    from ._validation import check_memory
    from .sensor import MAX_SAMPLES_PER_TOUCH

    if not 0 < n_samples <= MAX_SAMPLES_PER_TOUCH:
        raise InputError(f"{what}: {n_samples:g} samples per touch; the limit is {MAX_SAMPLES_PER_TOUCH:.0e} "
                         f"(shorten the contact or lower the sample rate)")
    check_memory(f"{what}: {n_touches:g} touches x {n_samples:g} samples", float(n_touches) * n_samples * 8 * copies)


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
    check_touch_budget("simulated touches", n, m)  # before the draw: a 1e12 Hz sensor grew to 24 GB
    rng = as_generator(seed)
    e = rng.uniform(lo, hi, n) if hi > lo else np.full(n, lo)
    zeros = np.zeros(n)
    s_off = rng.uniform(-1.0, 1.0, n) if vary_sensor else zeros
    a_off = rng.uniform(-1.0, 1.0, n) if vary_ambient else zeros
    noise = rng.standard_normal((m, n)).T  # time-major: prefixes do not depend on m
    return TrialDraws(e, s_off, a_off, noise)


def noisy_readings(time_s, e_object, sensor_temp_c, ambient_temp_c, sensor: Sensor,
                   noise_c: float, noise, model: "ForwardModel | None" = None) -> np.ndarray:
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
    model : ForwardModel, optional
        A shared-shape forward model (default: the paper's semi-infinite one).

    Returns
    -------
    ndarray, shape (n, m)
        Readings [degC].
    """
    sigma = check_nonnegative("noise sigma [degC]", noise_c)
    t = np.asarray(time_s, dtype=np.float64)
    e = np.atleast_1d(np.asarray(e_object, dtype=np.float64))
    ts = np.atleast_1d(np.asarray(sensor_temp_c, dtype=np.float64))
    ta = np.atleast_1d(np.asarray(ambient_temp_c, dtype=np.float64))
    if model is None:
        g, w = response_shape(t, sensor.tau_s), object_weight(sensor.effusivity, e)
    else:
        g, w = model.shape(t, sensor), model.weight(e, sensor)
    amp = (ta - ts) * w  # Tc - Ts0 per trial
    out = ts[:, None] + amp[:, None] * g[None, :]
    if sigma > 0:
        out = out + sigma * np.asarray(noise, dtype=np.float64)
    return out


@functools.lru_cache(maxsize=8)
def noise_cholesky(n_samples: int, sample_rate_hz: float, correlation_s: float) -> np.ndarray:
    """Lower Cholesky factor ``L`` of the noise's correlation matrix on ``n_samples`` samples.

    The Matern-3/2 autocorrelation ``(1 + a) exp(-a)``, ``a = sqrt(3) |t_i - t_j| / l`` (a smooth
    Gaussian process, as a real rig's misfit wanders from touch to touch), plus ``1e-9`` on the
    diagonal for a stable factor. ``L`` is lower triangular, so the correlated noise of the first
    ``m`` samples is made from the first ``m`` white draws only: truncating a touch stays the same as
    simulating the shorter one (to rounding: the products' summation order differs).

    >>> L = noise_cholesky(3, 200.0, 0.5)
    >>> bool(np.allclose(np.diag(L @ L.T), 1.0)), bool(np.allclose(np.triu(L, 1), 0.0))
    (True, True)
    """
    from ._validation import check_memory

    n = int(n_samples)
    check_memory(f"noise correlation over {n} samples", float(n) * n * 8 * 2)
    lag = np.arange(n, dtype=np.float64) / float(sample_rate_hz)
    a = math.sqrt(3.0) * np.abs(lag[:, None] - lag[None, :]) / float(correlation_s)
    corr = (1.0 + a) * np.exp(-a)
    corr[np.diag_indices(n)] += 1e-9
    L = np.linalg.cholesky(corr / (1.0 + 1e-9))
    L.flags.writeable = False  # one factor per process and size, shared by every class, contact and seed
    return L


def correlate_noise(noise, sample_rate_hz: float, correlation_s: float) -> np.ndarray:
    """Standard normal draws (n, m), time along axis 1, made into unit-variance noise correlated over
    ``correlation_s`` [s] (:func:`noise_cholesky`; 0: returned unchanged, white)."""
    z = np.asarray(noise, dtype=np.float64)
    if not correlation_s or z.shape[-1] < 2:
        return z
    return z @ noise_cholesky(z.shape[-1], sample_rate_hz, correlation_s).T


def response_tolerance(noise_ratio: float, n_samples: int) -> float:
    """Tolerance asked of a numerically solved model: 1 % of the noise over the whole curve, at most 1e-5.

    Normalized units (times ``|Ts0 - Ta|`` for degC); ``noise_ratio`` is sigma/dT.
    """
    if not math.isfinite(noise_ratio):
        return 1e-5
    return float(np.clip(0.01 * noise_ratio / math.sqrt(max(n_samples, 1)), 1e-10, 1e-5))


def render_trials(draws: TrialDraws, sensor: Sensor, scene: Scene, model: "ForwardModel | str | None" = None,
                  diffusivity_m2_s=None, ramp_index=None) -> Trials:
    """Apply a scene to drawn trials: readings of ``draws.n_samples`` samples.

    Parameters
    ----------
    draws : TrialDraws
    sensor : Sensor
    scene : Scene
    model : ForwardModel, name or None
        Forward model (default: the paper's semi-infinite model).
    diffusivity_m2_s : array_like, shape (n,), optional
        Per-trial object diffusivity, for models that need it.
    ramp_index : array_like of int, shape (n,), optional
        Per-trial calibration touch whose press the trial plays (a force ramp with ``touch_ramps``).
    """
    fm = get_model(model)
    # the recorder's window: from its onset (model time; 0: the first heat flow) on
    time_s = scene.onset_s + np.arange(draws.n_samples, dtype=np.float64) / sensor.sample_rate_hz
    if scene.noise_correlation_s > 0 and scene.noise_c > 0:
        draws = dataclasses.replace(draws, noise=correlate_noise(draws.noise, sensor.sample_rate_hz,
                                                                 scene.noise_correlation_s))
    ts = scene.sensor_temp_c + scene.sensor_temp_spread_c * draws.sensor_offset
    ta = scene.ambient_temp_c + scene.ambient_temp_spread_c * draws.ambient_offset
    if fm.shared_shape:
        # amplitude times shape, in this order: the paper's readings to the last bit
        temps = noisy_readings(time_s, draws.effusivity, ts, ta, sensor, scene.noise_c, draws.noise, model=fm)
    else:
        tol = response_tolerance(scene.noise_ratio, draws.n_samples)
        # a costly model is read at a few effusivities of the class and interpolated within tol
        u = class_readings(fm, time_s, draws.effusivity, sensor, diffusivity_m2_s=diffusivity_m2_s, tolerance=tol,
                           touch=ramp_index)
        temps = np.multiply(u, (ta - ts)[:, None], out=u)        # in place: ts + (ta - ts) u, as before
        temps += ts[:, None]
        if scene.noise_c > 0:
            temps += scene.noise_c * draws.noise
    return Trials(time_s, temps, draws.effusivity, ts, ta,
                  None if diffusivity_m2_s is None else np.asarray(diffusivity_m2_s, dtype=np.float64), fm.name)


def window_times_s(sensor: Sensor, scene: Scene) -> np.ndarray:
    """Model times [s] of the samples a recognizer sees: from the scene's onset (the recorder's; 0: the first
    heat flow) to its contact, one sample period apart; one sample, at the onset, when contact ends before it."""
    window = scene.window_s()
    return scene.onset_s + (sensor.times_s(window) if window > 0 else np.zeros(1))


def seed_key(seed) -> list[int]:
    """A seed as a list of integers, so that sub-streams (``key + [k]``) can be derived from it."""
    if isinstance(seed, (list, tuple)):
        key = [int(s) for s in seed]
        as_generator(key)  # validates
        return key
    if isinstance(seed, (np.random.Generator, np.random.SeedSequence)):
        raise InputError("this simulation needs an integer seed or a list of integers "
                         "(its sub-streams are derived from it)")
    as_generator(seed)  # validates (refuses None and negatives)
    return [int(seed)]


def simulate_class(obj: ObjectClass, n_trials: int, sensor: Sensor, scene: Scene, seed,
                   model: "ForwardModel | str | None" = None) -> Trials:
    """``n_trials`` touches of one object class under any forward model.

    Draws follow the module's protocol (:func:`draw_trials` with ``seed``);
    the diffusivity, where the model needs it, is uniform in the class's
    range from the stream ``seed + [7]``.

    Examples
    --------
    >>> from designkit import SENSORS, Scene
    >>> from designkit.objects import object_class
    >>> t = simulate_class(object_class(20000), 100, SENSORS["paper"], Scene(contact_s=2), seed=0,
    ...                    model="contact")
    >>> t.temperature_c.shape, t.model
    ((100, 401), 'contact')
    """
    fm = get_model(model)
    obj.require(fm.object_properties)
    key = seed_key(seed)
    n_samples = window_times_s(sensor, scene).size
    draws = draw_trials(*obj.e_range, n_trials, n_samples, key,
                        vary_sensor=scene.sensor_temp_spread_c > 0,
                        vary_ambient=scene.ambient_temp_spread_c > 0)
    alpha = None
    if "diffusivity_m2_s" in fm.object_properties:
        a_lo, a_hi = obj.diffusivity_range_m2_s
        alpha = (as_generator(key + [DIFFUSIVITY_STREAM]).uniform(a_lo, a_hi, draws.n_trials) if a_hi > a_lo
                 else np.full(draws.n_trials, a_lo))
    return render_trials(draws, sensor, scene, fm, alpha, touch_picks(fm, key, draws.n_trials))


def touch_picks(model, key, n_trials: int) -> np.ndarray | None:
    """Which calibration touch's press each of ``n_trials`` trials plays (indices into ``model.touch_ramps``),
    drawn from the ``key + [RAMP_STREAM]`` stream; None for a model without touch ramps (every trial presses
    alike). The one rule for the exact route's touches and a sweep's."""
    ramps = getattr(model, "touch_ramps", ())
    return as_generator(list(key) + [RAMP_STREAM]).integers(0, len(ramps), n_trials) if ramps else None


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
    n_samples = window_times_s(sensor, scene).size
    draws = draw_trials(lo, hi, n_trials, n_samples, seed,
                        vary_sensor=scene.sensor_temp_spread_c > 0,
                        vary_ambient=scene.ambient_temp_spread_c > 0)
    return render_trials(draws, sensor, scene)


def simulate_trials(e_object: float, sensor: Sensor, scene: Scene, n_trials: int = 1,
                    seed=0) -> Trials:
    """``n_trials`` touches of one object of effusivity ``e_object``.

    ``e_object`` may be 0 (perfect insulator) or ``inf`` (perfect conductor).

    Examples
    --------
    >>> from designkit import SENSORS, Scene
    >>> tr = simulate_trials(20000.0, SENSORS["paper"], Scene(contact_s=1.0), n_trials=3, seed=0)
    >>> tr.temperature_c.shape  # 3 touches, 1 s at 200 Hz from t = 0
    (3, 201)
    """
    e = check_effusivity("e", e_object, allow_zero=True, allow_inf=True)
    n_samples = window_times_s(sensor, scene).size
    draws = draw_trials(0.0, 0.0, n_trials, n_samples, seed,
                        vary_sensor=scene.sensor_temp_spread_c > 0,
                        vary_ambient=scene.ambient_temp_spread_c > 0)
    draws = TrialDraws(np.full(draws.n_trials, e), draws.sensor_offset,
                       draws.ambient_offset, draws.noise)
    return render_trials(draws, sensor, scene)
