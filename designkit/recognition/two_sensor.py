"""Two sensors at different temperatures: the heated sensor and a passive thermistor on the object side.

The heated sensor's reading ``T(t) = Ts0 + (To - Ts0) u(t; e_o)`` mixes the object's temperature with its
effusivity (a cold block of wood reads as room-temperature metal); the rig's passive thermistor, at room
temperature ``Tp0`` and touching the same object, reads

.. math::

    T_p(t) = T_{p0} + (T_o - T_{p0})\\, u_p(t; e_o),

which moves only when the object is *not* at room temperature (Bhattacharjee et al., cited by the paper;
docs/sensor-models.md, "Two sensors"). Each channel is a reading of the same forward-model seam with its
own noise draw; the features are the paper's (:func:`~designkit.recognition.features.feature_matrix`) of
both channels side by side, the classifier the paper's (standardized in each fold, linear SVM).

Examples
--------
A block of wood from the fridge (8 degC) draws from a sensor heated to 29.5 degC
what room-temperature metal does (the same amplitude, and under the
semi-infinite model the same shape): one sensor cannot tell them apart, the
passive thermistor at room temperature can.

>>> from designkit import SENSORS, Scene
>>> from designkit.objects import object_class
>>> metal = TouchClass(object_class(17530, width=10), object_temp_c=22.5)
>>> cold_wood = TouchClass(object_class(400, width=10), object_temp_c=7.985)
>>> scene = Scene(contact_s=2, noise_c=0.05, sensor_temp_c=29.5, ambient_temp_c=22.5)
>>> r = two_sensor_pair_f1(metal, cold_wood, SENSORS["paper"], scene, trials=50)
>>> r.one_sensor.f1 < 0.9, r.two_sensors.f1 > 0.95, r.resolves
(True, True, True)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import InputError, check_temperature
from ..models import get_model
from ..objects import ObjectClass
from ..scene import Scene
from ..sensor import Sensor
from ..simulation import draw_trials, render_trials, seed_key
from .features import DEFAULT_SLOPE_WINDOW_S, feature_matrix
from .svm import F1Result, f1_from_features

__all__ = ["TouchClass", "TwoSensorF1", "TwoSensorTrials", "simulate_two_sensor", "two_sensor_features",
           "two_sensor_pair_f1"]

#: Seed-key suffix of the passive channel's noise (independent of the heated channel's).
PASSIVE_STREAM = 11


@dataclass(frozen=True)
class TouchClass:
    """An object class at a temperature: what the two sensors touch.

    Attributes
    ----------
    obj : ObjectClass
        Its effusivity (and diffusivity) ranges.
    object_temp_c : float or None
        The object's temperature [degC]; None: the scene's ambient (room)
        temperature.
    label : str
        Name in results (default: the class label and its temperature).
    """

    obj: ObjectClass
    object_temp_c: float | None = None
    label: str = ""

    def temperature(self, scene: Scene) -> float:
        if self.object_temp_c is None:
            return float(scene.ambient_temp_c)
        return check_temperature("object temperature [degC]", self.object_temp_c)

    def name(self, scene: Scene) -> str:
        return self.label or f"{self.obj.label} at {self.temperature(scene):g} degC"


@dataclass(frozen=True)
class TwoSensorTrials:
    """Simulated touches of both channels: ``heated_c`` and ``passive_c`` [degC], shape (n, m) each."""

    time_s: np.ndarray
    heated_c: np.ndarray
    passive_c: np.ndarray
    effusivity: np.ndarray
    object_temp_c: float


def simulate_two_sensor(cls: TouchClass, n_trials: int, sensor: Sensor, scene: Scene, seed, *, model=None,
                        passive_sensor: Sensor | None = None, passive_model=None) -> TwoSensorTrials:
    """``n_trials`` touches of one class read by the heated sensor and by the passive thermistor.

    The heated sensor starts at ``scene.sensor_temp_c``; the passive
    thermistor at the room temperature ``scene.ambient_temp_c``; the object is
    at ``cls.object_temp_c``. Both channels touch the same objects (one
    effusivity draw per touch) with independent noise of ``scene.noise_c``.
    Fixed initial conditions only (the spreads of the scene are refused: the
    passive channel's point is a known room temperature).

    Parameters
    ----------
    cls : TouchClass
    n_trials : int
    sensor : Sensor
        The heated sensor.
    scene : Scene
        Contact time, noise, heated sensor and room temperatures.
    seed : int or list of int
        Heated channel: the stream ``seed`` (:func:`designkit.simulation.draw_trials`,
        the same touches :func:`~designkit.simulation.simulate_class` draws);
        passive channel noise: ``seed + [11]``.
    model : ForwardModel or name, optional
        Forward model of the heated sensor (default: semi-infinite).
    passive_sensor, passive_model : optional
        The passive thermistor and its model (default: the heated sensor's).
    """
    if scene.sensor_temp_spread_c > 0 or scene.ambient_temp_spread_c > 0:
        raise InputError("two-sensor touches take fixed initial temperatures (the passive thermistor rests at "
                         "the room temperature); set the spreads to 0")
    fm = get_model(model)
    pm = fm if passive_model is None else get_model(passive_model)
    ps = sensor if passive_sensor is None else passive_sensor
    if ps.sample_rate_hz != sensor.sample_rate_hz:
        raise InputError("the two sensors must be sampled at the same rate")
    for m in (fm, pm):
        if "diffusivity_m2_s" in m.object_properties:
            raise InputError(f"two-sensor touches are simulated by effusivity alone, not the {m.name} model")
    key = seed_key(seed)
    n_samples = sensor.times_s(scene.contact_s).size
    to = cls.temperature(scene)
    draws = draw_trials(*cls.obj.e_range, n_trials, n_samples, key)
    heated = render_trials(draws, sensor, Scene(contact_s=scene.contact_s, noise_c=scene.noise_c,
                                                sensor_temp_c=scene.sensor_temp_c, ambient_temp_c=to), fm)
    passive_noise = draw_trials(0.0, 0.0, n_trials, n_samples, key + [PASSIVE_STREAM]).noise
    pdraws = type(draws)(draws.effusivity, draws.sensor_offset, draws.ambient_offset, passive_noise)
    # Scene refuses equal temperatures only where it matters (a zero difference is a flat passive channel)
    passive = render_trials(pdraws, ps, Scene(contact_s=scene.contact_s, noise_c=scene.noise_c,
                                              sensor_temp_c=scene.ambient_temp_c, ambient_temp_c=to), pm)
    return TwoSensorTrials(heated.time_s, heated.temperature_c, passive.temperature_c, draws.effusivity, to)


def two_sensor_features(heated_c, passive_c, sample_rate_hz: float,
                        window_s: float = DEFAULT_SLOPE_WINDOW_S) -> np.ndarray:
    """The two-sensor feature set: the paper's features of each channel, side by side, shape (n, 4 m).

    Examples
    --------
    >>> two_sensor_features(np.zeros((3, 10)), np.ones((3, 10)), 200.0).shape
    (3, 40)
    """
    h = np.atleast_2d(np.asarray(heated_c, dtype=np.float64))
    p = np.atleast_2d(np.asarray(passive_c, dtype=np.float64))
    if h.shape != p.shape:
        raise InputError(f"the two channels must have the same shape, got {h.shape} and {p.shape}")
    return np.hstack([feature_matrix(h, sample_rate_hz, window_s), feature_matrix(p, sample_rate_hz, window_s)])


@dataclass(frozen=True)
class TwoSensorF1:
    """The paper's SVM on one pair with the heated sensor alone and with both sensors.

    ``resolves`` is True when both sensors reach the threshold and the heated
    sensor alone does not: the pair is one only the second sensor resolves.
    """

    one_sensor: F1Result
    two_sensors: F1Result
    threshold: float
    labels: tuple[str, str]

    @property
    def resolves(self) -> bool:
        return self.two_sensors.f1 >= self.threshold > self.one_sensor.f1

    def to_dict(self) -> dict:
        def d(r: F1Result) -> dict:
            return {"f1": r.f1, "standard_error": r.standard_error, "fold_f1": list(r.fold_f1),
                    "accuracy": r.accuracy}

        return {"classes": list(self.labels), "one_sensor": d(self.one_sensor), "two_sensors": d(self.two_sensors),
                "threshold": self.threshold, "one_sensor_distinguishes": self.one_sensor.f1 >= self.threshold,
                "two_sensors_distinguish": self.two_sensors.f1 >= self.threshold,
                "second_sensor_resolves": self.resolves}


def two_sensor_pair_f1(a: TouchClass, b: TouchClass, sensor: Sensor, scene: Scene, *, model=None,
                       trials: int = 100, folds: int = 3, seed=0, threshold: float = 0.9,
                       passive_sensor: Sensor | None = None, passive_model=None) -> TwoSensorF1:
    """F1 of the paper's SVM for two touch classes, from the heated sensor alone and from both sensors.

    The same simulated touches and the same folds feed both classifiers
    (streams ``seed + [0]``, ``seed + [1]`` for the classes, ``seed + [2]``
    for the folds), so the difference is the second channel alone.
    """
    base = seed_key(seed)
    ta = simulate_two_sensor(a, trials, sensor, scene, base + [0], model=model, passive_sensor=passive_sensor,
                             passive_model=passive_model)
    tb = simulate_two_sensor(b, trials, sensor, scene, base + [1], model=model, passive_sensor=passive_sensor,
                             passive_model=passive_model)
    fs = sensor.sample_rate_hz
    one = f1_from_features(feature_matrix(ta.heated_c, fs), feature_matrix(tb.heated_c, fs), folds=folds,
                           seed=base + [2])
    two = f1_from_features(two_sensor_features(ta.heated_c, ta.passive_c, fs),
                           two_sensor_features(tb.heated_c, tb.passive_c, fs), folds=folds, seed=base + [2])
    return TwoSensorF1(one, two, float(threshold), (a.name(scene), b.name(scene)))
