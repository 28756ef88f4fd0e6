"""Live material decisions from a serial device: each touch decided while it lasts.

:class:`TouchDecider` is pure logic, fed samples like the recorder's
:class:`~designkit.calibration.cutter.TrialCutter` (time [s], sensor [degC],
object [degC], force [N]): it detects the contact onset with the profile's
force rule, takes the sensor's temperature before contact (Ts0, the mean over
the profile's ``pre_s``) and the object's (Ta: the object channel's mean over
the same window, or a given temperature) and the scatter of the sensor's samples
about a straight line over that window, builds a
:class:`~designkit.recognition.sequential.SequentialTest` for that touch (with the
measured scatter instead of the test's noise where it is clearly larger: a test
that assumes less noise than the stream carries decides too soon and too often
wrongly) and
feeds it every sample after the onset, until it decides, gives up at the
longest contact, or says no contact will do. :class:`LiveClassifier` is the
:class:`~designkit.calibration.recorder.SerialRecorder` (its port handling,
line parsing, fault tolerance and gap detection) with a decider in place of the
trial cutter: ``classify(touches)`` returns one :class:`TouchDecision` per touch.

Time after contact is the sample time minus the detected onset minus the
sensor's time offset (heat-flow start minus detected onset, negative when the
force threshold is crossed after the heat starts to flow, as calibration
estimates it), rounded to the sample grid.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .._validation import InputError
from ..recognition.sequential import SequentialTest
from .profiles import DeviceProfile
from .cutter import RecordEvent
from .recorder import SerialRecorder

__all__ = ["LiveClassifier", "NOISE_MISMATCH", "TouchDecider", "TouchDecision", "pre_contact_noise_c"]


@dataclass(frozen=True)
class TouchDecision:
    """The answer for one touch.

    Attributes
    ----------
    index : int
        Touch number (0-based).
    onset_s : float
        Detected contact onset, device time [s].
    state : str
        ``"decided"``, ``"no decision by the longest contact"``, ``"no decision possible"``
        or ``"released"`` (contact ended before an answer).
    material : str or None
        The decided candidate (or the most likely one when undecided at the longest contact).
    time_to_decision_s : float
        Time after contact of the deciding sample [s].
    n_samples : int
        Samples used.
    sensor_temp_c, ambient_temp_c : float
        Ts0 and Ta the test used [degC].
    noise_c : float
        White-noise sigma the test used [degC].
    pre_contact_noise_c : float
        Scatter of the sensor's samples before contact about a straight line [degC].
    """

    index: int
    onset_s: float
    state: str
    material: str | None
    time_to_decision_s: float
    n_samples: int
    sensor_temp_c: float
    ambient_temp_c: float
    noise_c: float = float("nan")
    pre_contact_noise_c: float = float("nan")

    def to_dict(self) -> dict:
        return {"index": self.index, "onset_s": self.onset_s, "state": self.state, "material": self.material,
                "time_to_decision_s": self.time_to_decision_s, "n_samples": self.n_samples,
                "sensor_temp_c": self.sensor_temp_c, "ambient_temp_c": self.ambient_temp_c,
                "noise_c": self.noise_c, "pre_contact_noise_c": self.pre_contact_noise_c}


#: A touch is decided with the scatter measured before contact instead of the test's noise when that scatter
#: exceeds the test's noise by this factor. With the 100 samples of a 0.5 s window at 200 Hz the scatter's own
#: relative standard error is about 7 %, so 1.5 is never reached by chance; a drifting heater is taken out by
#: the straight line the scatter is measured about.
NOISE_MISMATCH = 1.5


def pre_contact_noise_c(samples_c) -> float:
    """Scatter of samples about their least-squares straight line [degC] (``ddof = 2``; NaN for < 3).

    Examples
    --------
    >>> round(pre_contact_noise_c([0.0, 1.0, 2.0, 3.0]), 12)
    0.0
    >>> round(pre_contact_noise_c([0.0, 1.0, 0.0, 1.0]), 3)
    0.632
    """
    y = np.asarray(samples_c, dtype=np.float64)
    if y.size < 3:
        return float("nan")
    x = np.arange(y.size, dtype=np.float64)
    resid = y - np.polyval(np.polyfit(x, y, 1), x)
    return float(np.sqrt(np.sum(resid * resid) / (y.size - 2)))


class TouchDecider:
    """Per-sample touch detection and live decision (the recorder's cutter interface).

    Parameters
    ----------
    profile : DeviceProfile
        Its contact rule must be ``force``; its sample rate must be the sensor's.
    make_test : callable(sensor_temp_c, ambient_temp_c, noise_c=None) -> SequentialTest
        Builds the test of one touch; ``noise_c`` (when not None) replaces the test's own noise,
        for touches whose samples before contact scatter more than :data:`NOISE_MISMATCH` times it.
    time_offset_s : float
        Heat-flow start minus detected onset [s] (<= 0 in practice).
    ambient_temp_c : float, optional
        Object temperature [degC]; default: the object channel before contact.
    """

    ARMED, DECIDING, WAIT_RELEASE = "waiting for contact", "deciding", "waiting for release"

    def __init__(self, profile: DeviceProfile, make_test: Callable[[float, float], SequentialTest], *,
                 time_offset_s: float = 0.0, ambient_temp_c: float | None = None) -> None:
        if profile.contact.rule != "force":
            raise InputError(f"live decisions need the profile's force rule for contact (profile {profile.name!r} "
                             f"uses {profile.contact.rule!r})")
        if ambient_temp_c is None and not profile.has_object:
            raise InputError(f"profile {profile.name!r} has no object thermistor: give the object temperature")
        self.profile = profile
        self.fs = float(profile.sample_rate_hz)
        self.make_test = make_test
        self.offset_k = int(round(float(time_offset_s) * self.fs))
        self.ambient_temp_c = ambient_temp_c
        self.pre_n = max(1, int(round(profile.trial.pre_s * self.fs)))
        self._pre: deque = deque(maxlen=self.pre_n)
        self.written: list[TouchDecision] = []
        self.events: list[RecordEvent] = []
        self.live: dict = {}
        self._state = self.WAIT_RELEASE
        self._test: SequentialTest | None = None

    @property
    def state(self) -> str:
        return self._state

    @property
    def in_trial(self) -> bool:
        return self._state == self.DECIDING

    def discontinuity(self, reason: str) -> list[RecordEvent]:
        """Samples were lost: a touch being decided is abandoned, detection re-arms after a release."""
        events = []
        if self._state == self.DECIDING:
            events.append(RecordEvent("skipped", f"touch being decided abandoned: {reason}"))
        self._pre.clear()
        self._state = self.WAIT_RELEASE
        self.events.extend(events)
        return events

    def feed(self, time_s, values) -> list[RecordEvent]:
        """Add samples (columns sensor [degC], object [degC], force [N]); returns the events raised."""
        t = np.asarray(time_s, dtype=np.float64)
        v = np.asarray(values, dtype=np.float64).reshape(-1, 3)
        rule = self.profile.contact
        events: list[RecordEvent] = []
        for ti, (ys, yo, f) in zip(t.tolist(), v.tolist()):
            if self._state == self.DECIDING:
                k = int(round((ti - self._onset) * self.fs)) - self.offset_k
                if k >= 0:
                    d = self._test.update(k / self.fs, ys)
                    self.live = {"t": k / self.fs, "temp_c": ys, "log_likelihoods": d.log_likelihoods}
                    if d.final:
                        self._done(d.state, d.material, d.time_s, d.n_samples, events)
                        continue
                if f < rule.release_n:
                    self._done("released", None, k / self.fs, self._test.n_samples, events)
                    self._pre.clear()
                    self._state = self.ARMED
                continue
            if self._state == self.WAIT_RELEASE:
                if f < rule.release_n:
                    self._state = self.ARMED
                    self._pre.clear()
                else:
                    continue
            # ARMED
            if f >= rule.force_threshold_n:
                if len(self._pre) < self.pre_n:
                    events.append(RecordEvent("skipped", f"touch at device time {ti:.2f} s skipped: less than "
                                                         f"{self.profile.trial.pre_s:g} s of quiet data before it"))
                    self._state = self.WAIT_RELEASE
                    continue
                pre = np.array(self._pre)
                ts0 = float(pre[:, 0].mean())
                ta = self.ambient_temp_c if self.ambient_temp_c is not None else float(pre[:, 1].mean())
                self._test = self.make_test(ts0, ta)
                self._pre_noise = pre_contact_noise_c(pre[:, 0])
                if self._pre_noise > NOISE_MISMATCH * self._test.noise_c:
                    events.append(RecordEvent("noise", (
                        f"touch {len(self.written) + 1}: the samples before contact scatter {self._pre_noise:.3g} °C, "
                        f"{self._pre_noise / self._test.noise_c:.1f}x the {self._test.noise_c:.3g} °C the test "
                        f"assumes: deciding with {self._pre_noise:.3g} °C (set it with --noise)")))
                    self._test = self.make_test(ts0, ta, noise_c=self._pre_noise)
                self._onset, self._ts0, self._ta = ti, ts0, ta
                self._state = self.DECIDING
                k = -self.offset_k
                if k == 0:
                    d = self._test.update(0.0, ys)
                    if d.final:
                        self._done(d.state, d.material, d.time_s, d.n_samples, events)
                continue
            self._pre.append((ys, yo))
        self.events.extend(events)
        return events

    def _done(self, state, material, t, n, events) -> None:
        dec = TouchDecision(len(self.written), self._onset, state, material, float(t), int(n), self._ts0, self._ta,
                            float(self._test.noise_c), self._pre_noise)
        self.written.append(dec)
        what = material if state == "decided" else f"{state}" + (f" (most likely {material})" if material else "")
        events.append(RecordEvent("decision", f"touch {dec.index + 1}: {what} after {t:.3f} s of contact"))
        self._state = self.WAIT_RELEASE


class LiveClassifier(SerialRecorder):
    """A serial recorder that decides each touch live instead of writing trials.

    Parameters
    ----------
    port : str
    profile : DeviceProfile
    make_test : callable(sensor_temp_c, ambient_temp_c) -> SequentialTest
    sample_rate_hz : float
        The sensor's sample rate: must equal the profile's.
    time_offset_s, ambient_temp_c : see :class:`TouchDecider`
    no_data_timeout_s, on_event, on_status : as for :class:`SerialRecorder`
    """

    def __init__(self, port: str, profile: DeviceProfile, make_test, *, sample_rate_hz: float,
                 time_offset_s: float = 0.0, ambient_temp_c: float | None = None, **kw) -> None:
        if not math.isclose(float(sample_rate_hz), profile.sample_rate_hz, rel_tol=1e-9):
            raise InputError(f"the stream's sample rate ({profile.sample_rate_hz:g} Hz, profile {profile.name!r}) "
                             f"does not match the sensor file's {float(sample_rate_hz):g} Hz")
        super().__init__(port, profile, None, **kw)
        self.decider = TouchDecider(profile, make_test, time_offset_s=time_offset_s, ambient_temp_c=ambient_temp_c)

    _KEPT = "decided"

    def _new_cutter(self, material: str) -> TouchDecider:  # type: ignore[override]
        return self.decider

    def _kept_words(self) -> str:
        return f"{len(self.decider.written)} touch(es) decided"

    def classify(self, touches: int) -> list[TouchDecision]:
        """Decide ``touches`` touches; returns their decisions (Ctrl-C passes through, decisions stay)."""
        self.record("live", touches)
        return list(self.decider.written)
