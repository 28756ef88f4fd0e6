"""After a reconnect: is the reopened port still the session's device?

A reopened port is a new device until its stream shows otherwise: a pty path
(or a USB port) the device left may now belong to another program's device.
After a reconnect the recorder holds the samples back until it has seen
``VERIFY_S`` of them out of contact and compares them with what the session
saw before the disconnect: the device clock must restart near zero (a reset,
``RESTART_MAX_S``) or continue (``CLOCK_SLACK_S`` plus twice the real time
away), one sample must come every session's sample interval (within
``RATE_TOLERANCE``) with at least ``MIN_ARRIVING_FRACTION`` of them arriving
(two programs reading one port split its lines), and the pre-contact sensor
and object temperatures must stay within ``SENSOR_TOLERANCE_C`` and
``OBJECT_TOLERANCE_C`` of the session's (the median of its last 20 s out of
contact). A stream that matches is recorded from, its held samples first; one
that does not stops the recording (:class:`~designkit.calibration.recorder.DeviceChanged`, naming what
differs; trials already written stay), so that no touch of another device is
labelled with this session's material.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from .cutter import COL_OBJECT, COL_SENSOR

__all__ = ["CLOCK_SLACK_S", "MIN_ARRIVING_FRACTION", "OBJECT_TOLERANCE_C", "RATE_TOLERANCE", "RESTART_MAX_S",
           "SENSOR_TOLERANCE_C", "VERIFY_S", "Probation"]

#: Device seconds of samples out of contact read (and held back) before trusting a reopened port.
VERIFY_S = 1.0
#: Largest change of the pre-contact sensor temperature [degC] (a regulated heater holds its set point).
SENSOR_TOLERANCE_C = 1.0
#: Largest change of the pre-contact object (passive) temperature [degC] (the room drifts slowly).
OBJECT_TOLERANCE_C = 2.0
#: Largest first device time [s] after reopening that counts as a clock restarted by a reset.
RESTART_MAX_S = 5.0
#: Largest advance [s] of a continuing device clock beyond twice the real seconds the device was away.
CLOCK_SLACK_S = 10.0
#: Largest relative change of the median sample interval.
RATE_TOLERANCE = 0.2
#: Fewest of the samples (by device time) that must arrive: two readers of one port split its lines.
MIN_ARRIVING_FRACTION = 0.8


@dataclass
class Probation:
    """A reopened port on probation: samples held back until they show the same device."""

    sensor_c: float          # the session's pre-contact medians [degC] (NaN: none seen)
    object_c: float
    last_t: float | None     # the session's last device time [s]
    dt_s: float              # the session's median sample interval [s]
    away_s: float            # real seconds between the disconnect and the reopening
    t: list = field(default_factory=list)
    v: list = field(default_factory=list)

    @classmethod
    def start(cls, idle_t: np.ndarray, idle_v: np.ndarray, pre_contact: Sequence[tuple[float, float]],
              last_t: float | None, away_s: float, sample_rate_hz: float) -> "Probation":
        """Probation of a reopened port against the session: its recent samples out of contact ``(idle_t,
        idle_v)`` and its recorded trials' pre-contact (sensor, object) temperatures (preferred: steady by
        construction)."""
        v, t = idle_v, idle_t
        if pre_contact:   # the recorded trials' own pre-contact means: steady by construction
            v = np.array([[s, o, np.nan] for s, o in pre_contact[-10:]], dtype=np.float64)
        with np.errstate(all="ignore"):
            sensor = float(np.nanmedian(v[:, COL_SENSOR])) if np.isfinite(v[:, COL_SENSOR]).any() else float("nan")
            obj = float(np.nanmedian(v[:, COL_OBJECT])) if np.isfinite(v[:, COL_OBJECT]).any() else float("nan")
        d = np.diff(t)
        d = d[(d > 0) & (d < 3.0 / sample_rate_hz)]
        dt = float(np.median(d)) if d.size >= 10 else 1.0 / sample_rate_hz
        return cls(sensor, obj, last_t, dt, away_s)

    def judge(self, out_of_contact: Callable[[np.ndarray], np.ndarray], has_timestamp: bool,
              sample_rate_hz: float) -> tuple[list[str], list[str], np.ndarray, np.ndarray] | None:
        """``(what differs, what matches, times, values)`` of the samples held back, once ``VERIFY_S`` of them
        out of contact arrived and settled; None before. ``out_of_contact`` marks the samples out of contact."""
        t, vals = np.concatenate(self.t), np.concatenate(self.v)
        need = max(2, int(round(VERIFY_S * sample_rate_hz)))
        idle = np.flatnonzero(out_of_contact(vals))[-need:]   # the latest VERIFY_S out of contact
        if t.size < 10 * need:
            if idle.size < need:
                return None                             # not enough seen yet
            s = vals[idle, COL_SENSOR]
            if abs(np.median(s[need // 2:]) - np.median(s[:need // 2])) > SENSOR_TOLERANCE_C / 4:
                return None                            # still settling (a heater recovering from a touch)
        if idle.size == 0:
            idle = np.arange(t.size)
        reasons, same = [], []
        sensor = float(np.nanmedian(vals[idle, COL_SENSOR]))
        if math.isfinite(self.sensor_c):
            (reasons if abs(sensor - self.sensor_c) > SENSOR_TOLERANCE_C else same).append(
                f"sensor {sensor:.2f} °C out of contact, the session's {self.sensor_c:.2f} °C")
        if math.isfinite(self.object_c) and np.isfinite(vals[idle, COL_OBJECT]).any():
            obj = float(np.nanmedian(vals[idle, COL_OBJECT]))
            (reasons if abs(obj - self.object_c) > OBJECT_TOLERANCE_C else same).append(
                f"object {obj:.2f} °C, the session's {self.object_c:.2f} °C")
        if has_timestamp:
            t0 = float(t[0])
            if self.last_t is not None:
                if t0 < self.last_t and t0 > RESTART_MAX_S:
                    reasons.append(f"the device clock went back from {self.last_t:.2f} s to {t0:.2f} s, where a "
                                   "reset restarts it near 0")
                elif t0 >= self.last_t and t0 - self.last_t > CLOCK_SLACK_S + 2 * self.away_s:
                    reasons.append(f"the device clock jumped ahead by {t0 - self.last_t:.1f} s while the device was "
                                   f"away {self.away_s:.1f} s")
                else:
                    same.append("clock restarted" if t0 < self.last_t else "clock continued")
            d = np.diff(t)
            d = d[d > 0]
            if d.size >= 10:
                dt = float(np.median(d))
                if abs(dt / self.dt_s - 1.0) > RATE_TOLERANCE:
                    reasons.append(f"a sample every {1e3 * dt:.3g} ms, the session's {1e3 * self.dt_s:.3g} ms")
                span = float(t[-1] - t[0])
                if span > 0:
                    frac = t.size / (span / self.dt_s + 1.0)
                    if frac < MIN_ARRIVING_FRACTION:
                        reasons.append(f"only {100 * frac:.0f} % of the samples arrive (another program reading "
                                       "the same port splits its lines)")
        return reasons, same, t, vals
