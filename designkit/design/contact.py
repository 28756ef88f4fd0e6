"""Design under a rig's contact: the interface conductance, the area's ramp and the thermistor's own lag.

The closed-form search (:mod:`designkit.design.search`) designs under the paper's instantaneous perfect
contact, where a ceramic skin with a thermistor 20 um deep "separates" after one sample. A real touch
is slower: calibration of the lab's rig (``designkit calibrate fit`` on the shared recordings) found an
interface conductance of about 1,800 W m^-2 K^-1, a contact area that grows for 2 s while the finger
presses in, a thermistor (and host filter) lag of about 1 s, and a misfit noise correlated over 0.7 s.
:class:`RigContact` holds that contact (from a sensor file, or given explicitly) and makes the sensor
of any design under it, with the existing forward models: :class:`~designkit.models.layered.Layered`
(film = the skin, its thickness, the interface conductance, the thermistor lag, the host smoothing)
inside :class:`~designkit.models.ramp.ForceRamp` (the area's ramp).

What a builder can change, and what the search varies (:func:`designkit.design.search.recommend`): the skin material
(effusivity and diffusivity), its thickness (where the rig's model has a film of finite thickness),
the thermistor depth in it and the thermistor's own time constant, the sampling rate and dT (the
largest allowed: neither hurts the ideal observer), and the press (its pace: the rig's force ramp
played up to ``max_press_speedup`` times faster). The conductance is the interface's and stays.

Screening: these models have no shared shape, so the closed form does not apply and the Monte Carlo
ideal observer costs seconds per point. Every design is screened instead by the discriminability of
the two classes' mean curves (class centres) through the rig's correlated noise,
``d'(t)^2 = |L^-1 dT (u_b - u_a)|^2 / sigma^2`` over the recognizer's window (from the detected onset to
``t``; ``L`` the noise's Cholesky factor, :func:`designkit.simulation.noise_cholesky`): two point
classes with Gaussian noise reach accuracy (and F1) 0.9 at ``d' = 2 Phi^-1(0.9) = 2.563``
(:func:`d_star`). The screened contact is the first sample where the limiting pair's ``d'`` reaches it;
the recommendation is then predicted and confirmed by the SVM under the same model and scene
(:func:`designkit.design.search.predict_and_confirm`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import NormalDist
from typing import Any

import numpy as np

from .._validation import InputError, check_positive
from ..sensor import Sensor

__all__ = ["RigContact", "d_star", "rig_defaults", "screen_contact"]

#: Area ramp of an explicit ``--contact-ramp-s``: this many linear steps to the full area.
_RAMP_STEPS = 20


def d_star(threshold: float) -> float:
    """Discriminability at which two point classes with Gaussian noise reach accuracy ``threshold``.

    >>> round(d_star(0.9), 4)
    2.5631
    """
    return 2.0 * NormalDist().inv_cdf(float(threshold))


def _layered_params(record: dict, e_sensor: float) -> dict:
    """The rig model's full-contact part as :class:`~designkit.models.layered.Layered` parameters (the
    paper's and the contact model are a layered one with a semi-infinite film and no lag)."""
    name, params = record.get("name", "semi-infinite"), dict(record.get("params") or {})
    if name == "layered":
        return params
    if name in ("semi-infinite", "contact"):
        return {"film_thickness_m": None, "backing_effusivity_ws05_m2k": float(e_sensor),
                "conductance_w_m2k": params.get("conductance_w_m2k"), "lag_s": 0.0}
    raise InputError(f"design under a rig's contact needs a layered, contact or semi-infinite sensor model, "
                     f"the sensor file records {name!r}")


@dataclass(frozen=True)
class RigContact:
    """The contact a design is made under: a rig's as calibrated (its sensor file), or given explicitly.

    Attributes
    ----------
    rig : Sensor
        The rig's sensor: its conditions (noise, dT, correlated noise, detected onset) and its model
        record (layered parameters, time offset, contact area); a design's sensor is this one with the
        skin, depth, rate, thermistor lag, skin thickness and press pace replaced.
    source : str
        Where the contact came from (for people).
    """

    rig: Sensor
    source: str

    @classmethod
    def from_sensor(cls, sensor: Sensor, *, conductance_w_m2k: float | None = None,
                    contact_ramp_s: float | None = None, thermistor_tau_s: float | None = None) -> "RigContact":
        """A rig's contact from its sensor file, any of the three given values overriding the file's."""
        record = dict(sensor.model or {"name": "semi-infinite", "params": {}})
        params = _layered_params(record, sensor.effusivity)
        if conductance_w_m2k is not None:
            params["conductance_w_m2k"] = check_positive("--contact-conductance [W m^-2 K^-1]", conductance_w_m2k)
        if thermistor_tau_s is not None:
            params["lag_s"] = _check_tau(thermistor_tau_s)
        record.update(name="layered", params=params)
        rig = sensor.replace(model=record)
        if contact_ramp_s is not None:
            now = RigContact(rig, "").ramp_s
            ramp = _check_ramp(contact_ramp_s)
            if now > 0:
                rig = RigContact(rig, "").sensor(pace=ramp / now, name=sensor.name)
            else:
                rig = rig.replace(model={**record, "contact_area": _linear_area(ramp)})
        given = [f"{k} {v:g} {u}" for k, v, u in (("contact conductance", conductance_w_m2k, "W m^-2 K^-1"),
                                                  ("contact ramp", contact_ramp_s, "s"),
                                                  ("thermistor tau", thermistor_tau_s, "s")) if v is not None]
        return cls(rig, f"sensor file {sensor.name}" + (f" ({', '.join(given)} given)" if given else ""))

    @classmethod
    def explicit(cls, *, conductance_w_m2k: float | None, contact_ramp_s: float | None,
                 thermistor_tau_s: float | None, sample_rate_hz: float = 200.0) -> "RigContact":
        """A contact from explicit values (None: perfect contact, instant area, no lag), counted from the
        first contact (no recorder's onset), white noise."""
        h = None if conductance_w_m2k is None else check_positive("--contact-conductance [W m^-2 K^-1]",
                                                                    conductance_w_m2k)
        record: dict[str, Any] = {"name": "layered", "params": {
            "film_thickness_m": None, "backing_effusivity_ws05_m2k": 1000.0, "conductance_w_m2k": h,
            "lag_s": 0.0 if thermistor_tau_s is None else _check_tau(thermistor_tau_s)}}
        if contact_ramp_s is not None:
            record["contact_area"] = _linear_area(_check_ramp(contact_ramp_s))
        rig = Sensor(1000.0, 1e-7, sample_rate_hz=sample_rate_hz, name="explicit contact", model=record)
        return cls(rig, "the values given")

    # ------------------------------------------------------------ what the rig has
    @property
    def params(self) -> dict:
        return dict(self.rig.model["params"])

    @property
    def conductance_w_m2k(self) -> float:
        h = self.params.get("conductance_w_m2k")
        return math.inf if h is None else float(h)

    @property
    def thermistor_tau_s(self) -> float:
        return float(self.params.get("lag_s") or 0.0)

    @property
    def skin_thickness_m(self) -> float:
        L = self.params.get("film_thickness_m")
        return math.inf if L is None else float(L)

    @property
    def ramp_s(self) -> float:
        """Time from the first contact until the whole area is in contact [s] (0: at once)."""
        from ..models import sensor_model

        fm = sensor_model(self.rig)
        return float(getattr(fm, "ramp_duration_s", 0.0) or 0.0)

    @property
    def counted_from(self) -> str:
        """Where a contact time counts from: the rig's detected onset (a calibrated rig) or the first contact."""
        from ..rig import model_start_s

        return "detected onset" if model_start_s(self.rig) is not None else "first contact"

    def to_dict(self) -> dict:
        from ..rig import model_start_s

        cond = self.rig.conditions or {}
        return {"source": self.source, "conductance_w_m2k": _num(self.conductance_w_m2k),
                "contact_ramp_s": self.ramp_s, "thermistor_tau_s": self.thermistor_tau_s,
                "skin_thickness_um": _num(self.skin_thickness_m * 1e6),
                "noise_correlation_s": float(cond.get("noise_correlation_s") or 0.0),
                "onset_offset_s": model_start_s(self.rig)}

    # ------------------------------------------------------------ a design under it
    def sensor(self, *, effusivity: float | None = None, diffusivity_m2_s: float | None = None,
               depth_m: float | None = None, sample_rate_hz: float | None = None, thermistor_tau_s: float | None = None,
               skin_thickness_m: float | None = None, pace: float = 1.0, name: str = "design") -> Sensor:
        """The rig's sensor with a design's changes (None: the rig's own value); ``pace`` scales the
        press's times (0.5: the force ramp played twice as fast)."""
        rig = self.rig
        record = dict(rig.model)
        params = dict(record["params"])
        if thermistor_tau_s is not None:
            params["lag_s"] = float(thermistor_tau_s)
        if skin_thickness_m is not None and math.isfinite(self.skin_thickness_m):
            params["film_thickness_m"] = float(skin_thickness_m)
        rate = rig.sample_rate_hz if sample_rate_hz is None else float(sample_rate_hz)
        window = int(params.get("smoothing_window") or 0)
        if window > 1 and rate != rig.sample_rate_hz:  # the host's smoothing lasts as long in time
            params["smoothing_window"] = max(5, int(round(window * rate / rig.sample_rate_hz)) | 1)
        record["params"] = params
        area = record.get("contact_area")
        if area and pace != 1.0:
            record["contact_area"] = {**area, "time_s": [float(t) * pace for t in area["time_s"]]}
        return rig.replace(effusivity=rig.effusivity if effusivity is None else float(effusivity),
                           diffusivity_m2_s=rig.diffusivity_m2_s if diffusivity_m2_s is None else float(diffusivity_m2_s),
                           depth_m=rig.depth_m if depth_m is None else float(depth_m), sample_rate_hz=rate,
                           model=record, name=name)


def _num(x):
    return None if x is None or not math.isfinite(x) else float(x)


def _check_tau(v: float) -> float:
    v = float(v)
    if not (math.isfinite(v) and v >= 0):
        raise InputError(f"--thermistor-tau-s must be >= 0 and finite [s], got {v:g}")
    return v


def _check_ramp(v: float) -> float:
    v = float(v)
    if not (math.isfinite(v) and 0 <= v <= 60):
        raise InputError(f"--contact-ramp-s must be between 0 and 60 s, got {v:g}")
    return v


def _linear_area(ramp_s: float) -> dict | None:
    """A contact area growing linearly to the whole over ``ramp_s`` (as a force profile with c = 0)."""
    if ramp_s <= 0:
        return None
    k = np.arange(_RAMP_STEPS + 1)
    return {"force_fraction": 0.0, "time_s": (k * ramp_s / _RAMP_STEPS).tolist(),
            "force_share": ((k + 1) / (_RAMP_STEPS + 1)).tolist(), "n_touches": 0}


# ============================================================ the screen
def screen_contact(sensor: Sensor, e_low, e_high, ratio: float, *, max_contact_s: float, threshold: float,
                   ratios=None) -> np.ndarray:
    """Screened shortest contact [s, from the rig's detected onset] of pairs, under the sensor's model.

    Parameters
    ----------
    sensor : Sensor
        A design's sensor (:meth:`RigContact.sensor`): its model record and the rig's conditions.
    e_low, e_high : array_like, shape (P,)
        The two classes' centres [J s^-1/2 K^-1 m^-2] of each pair.
    ratio : float
        sigma / dT.
    max_contact_s : float
        Longest contact [s, from the onset].
    threshold : float
        F1 to reach (through :func:`d_star`).
    ratios : array_like, optional
        Several sigma/dT at once (the trade-off curve): the result is then (R, P).

    Returns
    -------
    ndarray
        The first sample time [s from the onset] where ``d'`` reaches :func:`d_star`, inf where it does not
        by ``max_contact_s``.
    """
    from scipy.linalg import solve_triangular

    from ..models import sensor_model
    from ..rig import rig_scene
    from ..simulation import noise_cholesky

    fm = sensor_model(sensor)
    fm = fm.nominal() if hasattr(fm, "nominal") else fm
    extra = rig_scene(sensor)
    onset = float(extra.get("onset_s") or 0.0)
    corr = float(extra.get("noise_correlation_s") or 0.0)
    fs = sensor.sample_rate_hz
    n = int(math.floor(max_contact_s * fs + 1e-9)) + 1
    t = onset + np.arange(n) / fs
    t = np.where(t > 0, t, 1e-9)
    lo, hi = np.atleast_1d(np.asarray(e_low, dtype=np.float64)), np.atleast_1d(np.asarray(e_high, dtype=np.float64))
    u = fm.response(t, np.concatenate([lo, hi]), sensor)
    diff = (u[lo.size:] - u[:lo.size]).T                           # (n, P), normalized
    if corr > 0 and n > 1:
        diff = solve_triangular(noise_cholesky(n, fs, corr), diff, lower=True)
    cum = np.sqrt(np.cumsum(diff * diff, axis=0))                   # d' * ratio
    rs = np.atleast_1d(np.asarray(ratio if ratios is None else ratios, dtype=np.float64))
    need = d_star(threshold) * rs[:, None, None]                   # (R, 1, 1)
    ok = cum[None, :, :] >= need
    first = np.where(ok.any(axis=1), np.argmax(ok, axis=1) / fs, np.inf)   # (R, P)
    return first[0] if ratios is None else first


def rig_defaults(contact: RigContact) -> dict:
    """The rig's noise [degC] and dT [degC] as its sensor file records them (empty when it records none)."""
    cond = contact.rig.conditions or {}
    out = {}
    if cond.get("noise_c") is not None:
        out["noise_c"] = float(cond["noise_c"])
    dt = (cond.get("delta_t_c") or {}).get("mean")
    if dt is not None and math.isfinite(float(dt)) and float(dt) > 0:
        out["delta_t_c"] = float(dt)
    return out

