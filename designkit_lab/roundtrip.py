"""Synthetic calibration round trips over a real pseudo-terminal, for every identifiable sensor model.

One run: an :class:`~designkit_lab.emulator.Emulator` plays a rig whose
sensor follows a known forward model (:data:`CASES`), one pty per material;
:class:`~designkit.calibration.recorder.SerialRecorder` records its touches
from that pty exactly as from a USB rig; :func:`~designkit.calibration.identify.identify`
fits the candidate model to the recorded trials. :func:`round_trip` compares
what the fit found with the truth, parameter by parameter: inside its 95 %
interval, and its relative error.

What a round trip can recover is what the data identify (module docstring of
:mod:`designkit.calibration.identify`): the ratios ``e_o / e_s`` and
``h_c / e_s``, the sensor diffusivity at the fixed thermistor depth, the lag
and the contact-time offset; e_s itself only as the interval the materials'
handbook ranges allow (the truth must lie in it).

The ``+drift+area`` cases emulate touches whose heater still warms at contact
and whose contact area follows a force ramp of its own pace (:data:`CHAIN_PLAN`),
and identify them with the drift and force-area options; c is compared with the
truth like the other parameters.

The ``+smoothing`` case smooths each recorded trial as the shared recordings'
host did (Savitzky-Golay, window 99, order 3, over the whole trial) before the
fit: the wire carries the raw reading, the smoothing is the host's.

``benchmarks/bench_roundtrip.py`` runs 50 seeds per case; the test suite a few.
"""

from __future__ import annotations

import math
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from designkit._validation import InputError

__all__ = ["CASES", "VARIED_PRESS", "RoundTripCase", "RoundTripResult", "round_trip", "summarize"]

#: The emulated sensor: e_s [J s^-1/2 K^-1 m^-2], alpha_s [m^2/s] at 80 um.
TRUE_ES, TRUE_ALPHA = 1000.0, 1.5e-9
#: Objects touched and their handbook ranges [J s^-1/2 K^-1 m^-2] (the truth inside, off-centre).
OBJECTS = {"wood": 400.0, "granite": 2500.0}
RANGES = {"wood": (331.0, 506.46), "granite": (2252.32, 2749.87)}
_LAYERED = {"film_thickness_m": 150e-6, "backing_effusivity_ws05_m2k": 300.0, "conductance_w_m2k": 2500.0,
            "lag_s": 0.4}


@dataclass(frozen=True)
class RoundTripCase:
    """A sensor model to emulate and the candidate that identifies it.

    Attributes
    ----------
    label : str
    model : mapping
        The emulated forward model (``{"name": ..., **parameters}``; SI units).
    free : tuple of str
        Parameters the fit identifies besides the offset and the ratios.
    fixed : mapping
        Model fields held at their truth (effusivities as ratios to e_s), as a
        rig's known construction would.
    smoothing : bool
        The host smooths each recorded trial; the candidate models it.
    drift : bool
        The emulated heater still warms at contact, at a rate that differs from touch to touch
        (:data:`CHAIN_PLAN`); the candidate fits a drift per touch.
    force_area : bool
        The emulated contact area follows each touch's force ramp, whose pace differs from touch to
        touch (:data:`CHAIN_PLAN`, threshold c = ``contact_force_fraction``); the candidate fits c.
    """

    label: str
    model: Mapping[str, Any]
    free: tuple[str, ...]
    fixed: Mapping[str, Any] = field(default_factory=dict)
    smoothing: bool = False
    drift: bool = False
    force_area: bool = False

    def candidate(self):
        from designkit.calibration.candidates import Candidate

        free = self.free + (("contact_force_fraction",) if self.force_area else ())
        return Candidate(self.label, str(self.model["name"]), free, dict(self.fixed), self.smoothing,
                         drift=self.drift, force_area=self.force_area)

    def plan(self, touches: int, press: "tuple[float, float] | None" = None) -> dict[str, Any]:
        """The emulator's :class:`~designkit_lab.emulator.TouchPlan` settings for this case.

        ``press``: the force ramps' mean duration [s] and spread (a share of it) of the ``+area`` cases,
        default :data:`CHAIN_PLAN`'s (0.6 s +- 50 %, about as on the shared recordings);
        :data:`VARIED_PRESS` is the protocol that identifies c within 2 % (docs/sensor-models.md).
        """
        ramp_s, spread = press if press is not None else (CHAIN_PLAN["ramp_s"], CHAIN_PLAN["ramp_spread"])
        out: dict[str, Any] = {"touch_every_s": 13.0, "touches_per_material": touches}
        if self.drift:
            out.update(drift_c_per_s=CHAIN_PLAN["drift_c_per_s"], drift_sd_c_per_s=CHAIN_PLAN["drift_sd_c_per_s"])
        if self.force_area:
            # the release ramp stays after the recorded window (7 s after the onset): the fit's area follows
            # the measured force down again, the emulator's does not (unloading is not loading reversed)
            out.update(ramp_s=float(ramp_s), ramp_spread=float(spread),
                       contact_force_fraction=CHAIN_PLAN["contact_force_fraction"], contact_s=9.0,
                       touch_every_s=15.0)
        return out

    def truth(self) -> dict[str, float]:
        """The identifiable quantities' true values (ratios to e_s where only a ratio is identified)."""
        out = {"diffusivity_m2_s": TRUE_ALPHA}
        out.update({f"e_o/e_s[{k}]": v / TRUE_ES for k, v in OBJECTS.items()})
        if "conductance_w_m2k" in self.free:
            out["h_c/e_s"] = float(self.model["conductance_w_m2k"]) / TRUE_ES
        if "lag_s" in self.free:
            out["lag_s"] = float(self.model["lag_s"])
        if self.force_area:
            out["contact_force_fraction"] = CHAIN_PLAN["contact_force_fraction"]
        return out


#: What the drift and force-area cases' emulated touches do (about as on the shared recordings): the heater
#: warms at 0.1 +- 0.03 degC/s at contact; the force ramps to its plateau over 0.3-0.9 s (0.6 s +- 50 %); the
#: contact area starts to grow at c = 0.3 of the plateau force.
CHAIN_PLAN = {"drift_c_per_s": 0.1, "drift_sd_c_per_s": 0.03, "ramp_s": 0.6, "ramp_spread": 0.5,
              "contact_force_fraction": 0.3}

#: Presses of widely varied speed (0.8 s +- 80 %: 0.16-1.44 s to full force): c is identified by how the
#: onset of heat flow moves with the press's pace, and this halves its interval at equal touches.
VARIED_PRESS = (0.8, 0.8)

_LAYERED_FIXED = {"film_thickness_m": _LAYERED["film_thickness_m"],
                  "backing_effusivity_ws05_m2k": _LAYERED["backing_effusivity_ws05_m2k"] / TRUE_ES}

#: One case per identifiable sensor model (``slab`` describes the object, not the sensor).
CASES: dict[str, RoundTripCase] = {c.label: c for c in (
    RoundTripCase("semi-infinite", {"name": "semi-infinite"}, ("diffusivity_m2_s",)),
    RoundTripCase("contact", {"name": "contact", "conductance_w_m2k": 2500.0},
                  ("diffusivity_m2_s", "conductance_w_m2k")),
    RoundTripCase("layered+lag", {"name": "layered", **_LAYERED}, ("diffusivity_m2_s", "conductance_w_m2k", "lag_s"),
                  _LAYERED_FIXED),
    RoundTripCase("layered+lag+smoothing", {"name": "layered", **_LAYERED},
                  ("diffusivity_m2_s", "conductance_w_m2k", "lag_s"), _LAYERED_FIXED, smoothing=True),
    RoundTripCase("contact+drift+area", {"name": "contact", "conductance_w_m2k": 2500.0},
                  ("diffusivity_m2_s", "conductance_w_m2k"), drift=True, force_area=True),
    RoundTripCase("layered+lag+smoothing+drift+area", {"name": "layered", **_LAYERED},
                  ("diffusivity_m2_s", "conductance_w_m2k", "lag_s"), _LAYERED_FIXED, smoothing=True, drift=True,
                  force_area=True),
)}


@dataclass(frozen=True)
class RoundTripResult:
    """One run: per quantity the truth, the estimate, its 95 % interval; and what the run cost.

    ``rows`` maps a quantity to ``(truth, estimate, low, high)``; ``es`` is
    ``(truth, low, high)`` of e_s's interval from the ranges.
    """

    case: str
    seed: int
    noise_c: float
    rows: Mapping[str, tuple[float, float, float, float]]
    es: tuple[float, float, float]
    offset: tuple[float, float, float, float]
    rms_c: float
    n_trials: int
    record_s: float
    fit_s: float

    def covered(self, name: str) -> bool:
        truth, _, lo, hi = self.rows[name]
        return lo <= truth <= hi

    def rel_error(self, name: str) -> float:
        truth, est, _, _ = self.rows[name]
        return abs(est / truth - 1.0)

    def to_dict(self) -> dict[str, Any]:
        return {"case": self.case, "seed": self.seed, "noise_c": self.noise_c,
                "rows": {k: list(v) for k, v in self.rows.items()}, "es": list(self.es),
                "offset": list(self.offset), "rms_c": self.rms_c, "n_trials": self.n_trials,
                "record_s": self.record_s, "fit_s": self.fit_s}


def _record(case: RoundTripCase, seed: int, noise_c: float, touches: int, speed: float, folder: Path,
            force_noise_n: float = 0.02, press: "tuple[float, float] | None" = None):
    """Emulate and record every material over its own pty; returns the emulated time offset [s]."""
    from designkit.models import get_model
    from designkit.sensor import Sensor
    from designkit_lab.emulator import EmulatedMaterial, Emulator, TouchPlan
    from designkit.calibration.profiles import load_profile
    from designkit.calibration.recorder import SerialRecorder

    prof = load_profile("designkit")
    sensor = Sensor(TRUE_ES, TRUE_ALPHA, depth_m=80e-6, sample_rate_hz=prof.sample_rate_hz, name="emulated")
    model = get_model(dict(case.model))
    offset = math.nan
    for k, (label, e) in enumerate(OBJECTS.items()):
        emu = Emulator(prof, sensor, [EmulatedMaterial(label, e)], noise_c=noise_c, sensor_temp_c=29.5,
                       ambient_c=22.5, speed=speed, plan=TouchPlan(**case.plan(touches, press)),
                       seed=1000 * int(seed) + k, model=model, force_noise_n=force_noise_n)
        with emu, SerialRecorder(emu.port, prof, folder, no_data_timeout_s=30.0) as rec:
            rec.record(label, touches)
        offset = emu.expected_time_offset_s
    return offset


def _host_smoothed(trials):
    from designkit.models.layered import savgol_smooth
    from designkit.calibration.candidates import HOST_SMOOTHING
    from designkit.calibration.trials import Trial

    return [Trial(t.time_s, savgol_smooth(t.sensor_c, *HOST_SMOOTHING), t.object_c, t.force_n, t.material,
                  source=t.source, meta=t.meta) for t in trials]


def round_trip(case: "str | RoundTripCase", seed: int, *, noise_c: float = 0.01, touches: int = 10,
               speed: float = 200.0, folder: "str | Path | None" = None,
               force_noise_n: float = 0.02, press: "tuple[float, float] | None" = None) -> RoundTripResult:
    """Emulate, record over a real pty, fit; compare with the truth.

    Parameters
    ----------
    case : str or RoundTripCase
        A key of :data:`CASES`.
    seed : int
        Seeds the emulator's noise (both materials' streams differ).
    noise_c : float
        Noise sigma of both thermistors [degC].
    touches : int
        Touches per material.
    speed : float
        Device seconds per real second of the emulated rig.
    folder : path, optional
        Where the trials are written (default: a temporary folder, removed after).
    force_noise_n : float
        Noise sigma of the force sensor [N] (the emulator's default, 0.02 N on a 10 N press). The
        force-area cases read the area from the measured force: its noise, clipped at the plateau,
        biases the area low there (errors in variables; docs/sensor-models.md).
    press : (float, float), optional
        The ``+area`` cases' force ramps: mean duration [s] and spread (:meth:`RoundTripCase.plan`).
    """
    from designkit.calibration.identify import identify
    from designkit.calibration.trials import load_index

    c = CASES[case] if isinstance(case, str) and case in CASES else case
    if not isinstance(c, RoundTripCase):
        raise InputError(f"unknown round-trip case {case!r}; known: {', '.join(CASES)}")
    with tempfile.TemporaryDirectory(prefix="designkit-roundtrip-") as tmp:
        where = Path(folder) if folder is not None else Path(tmp)
        t0 = time.perf_counter()
        offset = _record(c, seed, noise_c, touches, speed, where, force_noise_n, press)
        t1 = time.perf_counter()
        trials = load_index(where / "index.csv")
        if c.smoothing:
            trials = _host_smoothed(trials)
        res = identify(trials, c.candidate(), ranges=RANGES, start={"lag_s": 0.2} if "lag_s" in c.free else None)
        t2 = time.perf_counter()
    es = res.effusivity
    es_lo, es_hi = es.ci95 if es is not None and res.consistent else (math.nan, math.nan)
    rows: dict[str, tuple[float, float, float, float]] = {}
    for name, truth in c.truth().items():
        if name.startswith("e_o/e_s["):
            p = res.ratios[name[len("e_o/e_s["):-1]]
            rows[name] = (truth, p.value, *p.ci95)
        elif name == "h_c/e_s":  # reported as h_c = ratio * e_s with e_s's interval folded in: unfold it
            p = res.parameter("conductance_w_m2k")
            rows[name] = (truth, p.value / es.value, p.ci95[0] / es_lo, p.ci95[1] / es_hi)
        else:
            p = res.parameter(name)
            rows[name] = (truth, p.value, *p.ci95)
    off = res.parameter("time_offset_s")
    return RoundTripResult(c.label, int(seed), float(noise_c), rows, (TRUE_ES, es_lo, es_hi),
                           (offset, off.value, *off.ci95), res.rms_c, len(trials), t1 - t0, t2 - t1)


def summarize(results) -> dict[str, dict[str, float]]:
    """Per quantity: fraction of runs with the truth in the 95 % interval, fraction within 2 %, errors.

    Errors are relative: median and worst of their sizes, mean with sign (a bias).

    Also ``e_s`` (truth in the ranges' interval) and ``time_offset_s`` (coverage; error in seconds).
    """
    results = list(results)
    if not results:
        return {}
    out: dict[str, dict[str, float]] = {}
    for name in results[0].rows:
        cov = [r.covered(name) for r in results]
        err = [r.rel_error(name) for r in results]
        signed = [r.rows[name][1] / r.rows[name][0] - 1.0 for r in results]
        out[name] = {"coverage": float(np.mean(cov)), "within_2pct": float(np.mean(np.array(err) <= 0.02)),
                     "max_rel_error": float(np.max(err)), "median_rel_error": float(np.median(err)),
                     "mean_signed_error": float(np.mean(signed))}
    out["e_s"] = {"coverage": float(np.mean([lo <= t <= hi for t, lo, hi in (r.es for r in results)]))}
    # the offset's truth is defined to a sample only: the detected onset is the first sample whose
    # (noisy) force crosses the threshold, so it is checked to one sample period, not against its interval
    offs = [r.offset for r in results]
    period = 1.0 / 200.0
    out["time_offset_s"] = {"coverage": float(np.mean([lo <= t <= hi for t, _, lo, hi in offs])),
                            "within_one_sample": float(np.mean([abs(e - t) <= period for t, e, _, _ in offs])),
                            "max_abs_error_s": float(np.max([abs(e - t) for t, e, _, _ in offs]))}
    return out
