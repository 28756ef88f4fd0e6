"""A simulated sensor rig on a pseudo-terminal, speaking a device profile's wire format.

:class:`Emulator` opens a pseudo-terminal (:func:`os.openpty`), and a thread
streams what a real rig would send: the heated sensor's temperature from the
semi-infinite model (paper eqs. 1-2) with Gaussian noise (eq. 4), a passive
thermistor, a force sensor, and periodic touches of the objects it is given.
Any serial client (pyserial, ``designkit calibrate record``, a terminal) can
open :attr:`Emulator.port` as if it were ``/dev/ttyACM0``.

Timing. Sample ``k`` belongs to device time ``k / fs``. A touch starts every
``touch_every_s`` seconds (the first at ``first_touch_s``); heat starts to
flow when force leaves zero, force ramps to ``press_force_n`` over ``ramp_s``,
holds, and ramps down so that contact lasts ``contact_s``. The detected onset
(force crossing the profile's threshold) therefore comes ``ramp_s *
threshold / press_force_n`` after heat starts to flow: the time offset the
fit has to find, like the paper's 0.5 s. After release the regulated heater
brings the sensor back to its set temperature with time constant
``recover_s``; the passive thermistor relaxes back to room temperature.

``speed`` runs the device clock faster than real time (tests, demos). Writes
never block the thread: when nobody reads the pty, the emulator pauses (as a
device's USB buffer would fill) and resumes at the current time, without a
catch-up burst.

Faults (:class:`Faults`) inject what real serial links do: garbled bytes,
partial lines, non-numeric fields, wrong field counts, out-of-range counts,
lines out of order or sent twice, a digit changed on the wire (the line still
parses; a profile's checksum catches it),
bursts (output held back, then delivered at once), gaps (samples lost while
the line is silent), a device that vanishes, and one that never speaks.
"""

from __future__ import annotations

import fcntl
import math
import os
import select
import termios
import threading
import time
import tty
from pathlib import Path
from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np

from designkit._validation import InputError, as_generator, check_effusivity, check_nonnegative, check_positive
from designkit.models.semi_infinite import object_weight, response_shape
from designkit.sensor import Sensor
from designkit.calibration.conversions import Linear, Thermistor
from designkit.calibration.profiles import DeviceProfile
from designkit.calibration.touch_plan import announcement_text, greeting_text
from designkit.calibration.trials import check_material_label

__all__ = ["EmulatedMaterial", "Emulator", "Faults", "TouchPlan", "TouchRecord"]

_MAX_PENDING = 1 << 16
#: Real seconds between a client opening the port and the first sample (a rig's reset on open).
CLIENT_SETTLE_S = 0.05


@dataclass(frozen=True)
class EmulatedMaterial:
    """An object the emulated rig touches.

    Parameters
    ----------
    label : str
        Name shown and logged.
    effusivity : float
        e_o [J s^-1/2 K^-1 m^-2].
    object_temp_c : float or None
        Object temperature [degC]; None: room temperature (the emulator's
        ambient).
    """

    label: str
    effusivity: float
    object_temp_c: float | None = None

    def __post_init__(self) -> None:
        check_material_label(self.label, "the emulated material's label")   # it labels the recorded trials
        object.__setattr__(self, "effusivity", check_effusivity(self.label, self.effusivity))


@dataclass(frozen=True)
class TouchPlan:
    """When and how the emulated rig touches.

    ``contact_s`` defaults to the profile's trial window plus half a second,
    ``press_force_n`` to twice the contact threshold.

    What real touches do beyond the paper's model (all off by default):

    ``ramp_spread``: touch ``j``'s force ramp lasts ``ramp_s (1 + ramp_spread
    v_j)``, ``v_j`` uniform in [-1, 1] (the pace differs from touch to touch).
    ``contact_force_fraction`` (c): the contact area grows with the force,
    ``A = clip((F / F_p - c) / (1 - c), 0, 1)``, each share starting its heat
    flow as it comes into contact (:class:`~designkit.models.ramp.ForceRamp`);
    None: the whole area at once when the force leaves zero.
    ``drift_c_per_s`` and ``drift_sd_c_per_s``: the heater still warms at a
    rate ``s_j`` (normal, per touch) from ``drift_lead_s`` before contact until
    release, on the sensor's side of the contact: ``T = (Ts + s_j t)(1 - u) +
    To u``; after release it settles back to its set point.
    """

    touch_every_s: float = 20.0
    first_touch_s: float = 2.0
    contact_s: float | None = None
    press_force_n: float | None = None
    ramp_s: float = 0.5
    recover_s: float = 0.4
    touches_per_material: int = 1
    ramp_spread: float = 0.0
    contact_force_fraction: float | None = None
    drift_c_per_s: float = 0.0
    drift_sd_c_per_s: float = 0.0
    drift_lead_s: float = 1.5


@dataclass(frozen=True)
class TouchRecord:
    """Ground truth of one emulated touch (device time)."""

    index: int
    material: str
    effusivity: float
    start_s: float
    expected_onset_s: float


@dataclass(frozen=True)
class Faults:
    """Serial-link faults to inject (all off by default).

    Per-line probabilities: ``garbled`` (random non-ASCII bytes), ``partial``
    (line cut short, fields missing), ``non_numeric`` (a field replaced by
    text such as ``nan`` or ``ERR``), ``field_count`` (a field added or
    dropped), ``out_of_range`` (a sensor reading at the ADC rails or outside
    the channel's valid range). Each faulty line replaces one sample.
    ``out_of_order`` (a line swapped with the next one), ``duplicate`` (a
    line sent twice) and ``corrupt`` (one digit of a mapped field changed to
    another digit after the line's checksum was computed: the line still
    parses, only a checksum or a plausibility filter can tell) keep every
    sample. They start at device time ``line_faults_after_s`` (0: from the
    first line).

    Timed faults (device seconds, 0 = off): every ``burst_every_s`` the
    output is held back for ``burst_hold_s`` real seconds and then delivered
    at once (no data lost); every ``gap_every_s`` the device goes silent for
    ``gap_s`` real seconds and the samples of that time are lost; after
    ``vanish_after_s`` the device disappears (the pty closes). ``silent``:
    the port opens but nothing is ever sent.
    """

    garbled: float = 0.0
    partial: float = 0.0
    non_numeric: float = 0.0
    field_count: float = 0.0
    out_of_range: float = 0.0
    out_of_order: float = 0.0
    duplicate: float = 0.0
    corrupt: float = 0.0
    line_faults_after_s: float = 0.0
    burst_every_s: float = 0.0
    burst_hold_s: float = 0.1
    gap_every_s: float = 0.0
    gap_s: float = 0.5
    vanish_after_s: float = 0.0
    silent: bool = False

    def __post_init__(self) -> None:
        for name in ("garbled", "partial", "non_numeric", "field_count", "out_of_range", "out_of_order",
                     "duplicate", "corrupt"):
            p = check_nonnegative(f"fault {name} probability", getattr(self, name))
            if p > 1:
                raise InputError(f"fault {name} probability must be <= 1, got {p:g}")
        for name in ("line_faults_after_s", "burst_every_s", "burst_hold_s", "gap_every_s", "gap_s",
                     "vanish_after_s"):
            check_nonnegative(f"fault {name}", getattr(self, name))

    @property
    def line_faults(self) -> bool:
        return any((self.garbled, self.partial, self.non_numeric, self.field_count, self.out_of_range,
                    self.out_of_order, self.duplicate, self.corrupt))

    @property
    def order_faults(self) -> bool:
        """Faults that keep every sample but disturb the lines (order, repeats, a changed digit)."""
        return any((self.out_of_order, self.duplicate, self.corrupt))

    @classmethod
    def parse(cls, specs: Sequence[str]) -> "Faults":
        """From CLI specs: ``garbled=0.01``, ``partial=P``, ``non-numeric=P``,
        ``field-count=P``, ``out-of-range=P``, ``out-of-order=P``, ``duplicate=P``,
        ``corrupt=P``, ``line-faults-after=S``,
        ``burst=EVERY_S[:HOLD_S]``, ``gap=EVERY_S[:SILENT_S]``, ``vanish=AFTER_S``,
        ``silent``."""
        kw: dict[str, float | bool] = {}
        probs = {"garbled", "partial", "non-numeric", "field-count", "out-of-range", "out-of-order", "duplicate",
                 "corrupt"}
        known = sorted(probs | {"line-faults-after", "burst", "gap", "vanish", "silent"})
        for spec in specs:
            name, _, value = str(spec).partition("=")
            name = name.strip().lower().replace("_", "-")
            if name not in known:
                raise InputError(f"unknown fault {name!r}: use one of {', '.join(known)}")
            try:
                if name in probs:
                    kw[name.replace("-", "_")] = float(value)
                elif name == "line-faults-after":
                    kw["line_faults_after_s"] = float(value)
                elif name in ("burst", "gap"):
                    every, _, second = value.partition(":")
                    kw[f"{name}_every_s"] = float(every)
                    if second:
                        kw["burst_hold_s" if name == "burst" else "gap_s"] = float(second)
                elif name == "vanish":
                    kw["vanish_after_s"] = float(value)
                else:
                    kw["silent"] = True
            except ValueError:
                raise InputError(f"fault {spec!r} needs a number, e.g. garbled=0.01, gap=30:0.5, "
                                 "vanish=45") from None
        return cls(**kw)  # type: ignore[arg-type]


class Emulator:
    """A simulated rig streaming a profile's wire format on a pseudo-terminal.

    Parameters
    ----------
    profile : DeviceProfile
        Wire format (and contact threshold, trial window).
    sensor : Sensor
        e_s and tau of the emulated sensor; noise from ``noise_c``.
    materials : sequence of EmulatedMaterial
        Objects touched, ``plan.touches_per_material`` touches each, in turn.
    noise_c : float
        Temperature noise sigma per sample [degC] (both thermistors).
    sensor_temp_c, ambient_c : float
        Heater set point and room temperature [degC].
    plan : TouchPlan
    speed : float
        Device seconds per real second (1 = real time).
    faults : Faults
    seed : int or Generator
        Noise and fault draws.
    force_noise_n : float
        Force noise sigma [N].
    model : ForwardModel, optional
        The forward model of the touches (default, None: the paper's
        semi-infinite model). The wire carries the raw reading: a layered
        model's host smoothing (``smoothing_window``) is left to the host,
        as on a real rig, and only its conduction and lag are streamed. A
        :class:`~designkit.models.ramp.ForceRamp` (a sensor file calibrated
        with the force-driven area) plays its base model with the area
        following the plan's own force ramp at its threshold c.
    port_link : path, optional
        Publish the port as this symbolic link to the pty (as udev's /dev/serial/by-id
        names are), removed when the device vanishes or stops. A freed /dev/pts/N is
        handed to the next program that opens a pty: a client reconnecting by the bare
        pty path after a vanish could open someone else's device, by the link it cannot.

    Examples
    --------
    >>> with Emulator(load_profile("designkit"), SENSORS["paper"],
    ...               [EmulatedMaterial("wood", 400)], speed=20) as emu:  # doctest: +SKIP
    ...     print(emu.port)
    /dev/pts/3
    """

    def __init__(self, profile: DeviceProfile, sensor: Sensor,
                 materials: Sequence[EmulatedMaterial], *, noise_c: float = 0.05,
                 sensor_temp_c: float = 35.0, ambient_c: float = 25.0, plan: TouchPlan = TouchPlan(),
                 speed: float = 1.0, faults: Faults = Faults(), seed=0, force_noise_n: float = 0.02,
                 model=None, port_link=None) -> None:
        if not materials:
            raise InputError("the emulator needs at least one material to touch")
        self.profile = profile
        self.sensor = sensor
        if model is not None:
            from designkit.models import get_model

            model = get_model(model)
            if "diffusivity_m2_s" in model.object_properties:
                raise InputError(f"the emulator touches objects by effusivity alone; the {model.name} model needs "
                                 "their diffusivity")
            if model.name == "force-ramp":
                # a sensor file's model with its force-driven contact area: the rig presses along its own
                # (linear) force ramp, the area following it with the file's threshold c
                if plan.contact_force_fraction is None:
                    plan = replace(plan, contact_force_fraction=model.force_fraction)
                model = model.base
            if model.name == "semi-infinite":
                model = None  # the closed form below, bit for bit what it always streamed
        self.model = model
        self.materials = tuple(materials)
        self.noise_c = check_nonnegative("noise sigma [degC]", noise_c)
        self.sensor_temp_c = float(sensor_temp_c)
        self.ambient_c = float(ambient_c)
        self.speed = check_positive("speed", speed)
        self.faults = faults
        self.force_noise_n = check_nonnegative("force noise [N]", force_noise_n)
        self._seed = seed if isinstance(seed, (int, np.integer)) else int(as_generator(seed).integers(2 ** 31))
        if int(self._seed) < 0:
            raise InputError(f"seed must be a non-negative integer, got {seed}")
        self._rng = as_generator([int(self._seed), 1 << 30])  # fault draws
        self._order_rng = as_generator([int(self._seed), 1 << 29])  # order faults' draws (Faults.order_faults)
        self._blocks: dict[int, np.ndarray] = {}
        self._curves: dict[tuple[int, float], tuple[np.ndarray, np.ndarray]] = {}
        fs = profile.sample_rate_hz
        threshold = profile.contact.force_threshold_n if profile.contact.rule == "force" else 5.0
        contact = plan.contact_s if plan.contact_s is not None else profile.trial.post_s + 0.5
        force = plan.press_force_n if plan.press_force_n is not None else 2.0 * threshold
        plan = replace(plan, contact_s=float(contact), press_force_n=float(force))
        check_positive("touch interval [s]", plan.touch_every_s)
        check_positive("contact time [s]", plan.contact_s)
        check_positive("press force [N]", plan.press_force_n)
        check_positive("force ramp [s]", plan.ramp_s)
        check_positive("heater recovery time constant [s]", plan.recover_s)
        if plan.touches_per_material < 1:
            raise InputError(f"touches per material must be >= 1, got {plan.touches_per_material}")
        if not 0.0 <= plan.ramp_spread < 1.0:
            raise InputError(f"ramp spread must be in [0, 1), got {plan.ramp_spread:g}")
        if plan.contact_force_fraction is not None and not 0.0 <= plan.contact_force_fraction < 1.0:
            raise InputError(f"contact force fraction must be in [0, 1), got {plan.contact_force_fraction:g}")
        check_nonnegative("drift spread [degC/s]", plan.drift_sd_c_per_s)
        drifts = bool(plan.drift_c_per_s or plan.drift_sd_c_per_s)
        if drifts and plan.drift_lead_s < profile.trial.pre_s:
            raise InputError(f"the drift must start before the recorded window ({profile.trial.pre_s:g} s before "
                             f"the onset), got drift_lead_s {plan.drift_lead_s:g}")
        if 2 * plan.ramp_s * (1.0 + plan.ramp_spread) >= plan.contact_s:
            raise InputError(f"contact ({plan.contact_s:g} s) must outlast the force ramps (2 x {plan.ramp_s:g} s)")
        if plan.press_force_n <= threshold and profile.contact.rule == "force":
            raise InputError(f"press force {plan.press_force_n:g} N never reaches the profile's contact "
                             f"threshold {threshold:g} N")
        needed = plan.contact_s + 10 * plan.recover_s + max(profile.trial.pre_s, plan.drift_lead_s if drifts else 0.0)
        if plan.touch_every_s < needed:
            raise InputError(f"touch interval {plan.touch_every_s:g} s is too short: contact {plan.contact_s:g} s, "
                             f"heater recovery and {profile.trial.pre_s:g} s before the next touch need "
                             f">= {needed:.1f} s")
        if plan.first_touch_s < profile.trial.pre_s + 1.0 / fs:
            raise InputError(f"the first touch must come after {profile.trial.pre_s:g} s of quiet data")
        self.plan = plan
        self._threshold = threshold
        self._master: int | None = None
        self._slave: int | None = None
        self._port: str | None = None
        self._link = None if port_link is None else Path(port_link)
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self._closed = threading.Event()
        self.error: BaseException | None = None
        self.samples_sent = 0
        self.lines_faulty = 0
        self.vanished = False

    def greeting(self) -> str:
        """The first line sent (a device message, with the profile's comment prefix): the touch plan.

        A recorder reads it back with :func:`~designkit.calibration.touch_plan.parse_greeting` and can
        refuse a run that would label the touches wrongly.
        """
        return greeting_text(self.profile.comment or "#", self.profile.name, [m.label for m in self.materials],
                             self.plan)

    # ----------------------------------------------------------------- truth
    def _touch_draws(self, j: int) -> tuple[float, float]:
        """Touch ``j``'s force ramp [s] and heater drift [degC/s] (seeded per touch, chunking-independent)."""
        p = self.plan
        if not (p.ramp_spread or p.drift_sd_c_per_s):
            return p.ramp_s, p.drift_c_per_s
        v = as_generator([int(self._seed), 1 << 29, int(j)]).standard_normal(2)
        from scipy.special import ndtr

        ramp = p.ramp_s * (1.0 + p.ramp_spread * (2.0 * float(ndtr(v[0])) - 1.0))
        return ramp, p.drift_c_per_s + p.drift_sd_c_per_s * float(v[1])

    @staticmethod
    def _per_touch(fn, touches: np.ndarray) -> np.ndarray:
        """``fn(j)`` for each sample's touch index, evaluated once per distinct touch."""
        if touches.size == 0:
            return np.zeros(0)
        uniq, inverse = np.unique(touches, return_inverse=True)
        return np.array([fn(int(x)) for x in uniq])[inverse.ravel()]

    def touch_ramp_s(self, j: int) -> float:
        """Seconds touch ``j``'s force takes from zero to its plateau."""
        return self._touch_draws(j)[0]

    def touch_drift_c_per_s(self, j: int) -> float:
        """Touch ``j``'s heater drift [degC/s]."""
        return self._touch_draws(j)[1]

    def material_of_touch(self, j: int) -> EmulatedMaterial:
        return self.materials[(j // self.plan.touches_per_material) % len(self.materials)]

    def touch(self, j: int) -> TouchRecord:
        """Ground truth of touch ``j`` (0-based)."""
        p = self.plan
        fs = self.profile.sample_rate_hz
        start = p.first_touch_s + j * p.touch_every_s
        delay = self.touch_ramp_s(j) * self._threshold / p.press_force_n
        onset = math.ceil((start + delay) * fs - 1e-9) / fs
        m = self.material_of_touch(j)
        return TouchRecord(j, m.label, m.effusivity, start, onset)

    @property
    def expected_time_offset_s(self) -> float:
        """Heat-flow start minus detected onset for a noise-free force signal [s] (negative).

        With a force-driven contact area (``contact_force_fraction``) each share of the area starts its
        heat flow when the force puts it down, so relative to the measured force the offset is 0.
        """
        if self.plan.contact_force_fraction is not None:
            return 0.0
        t = self.touch(0)
        return t.start_s - t.expected_onset_s

    def values(self, k0: int, k1: int) -> dict[str, np.ndarray]:
        """Noisy engineering values of samples ``k0 .. k1-1`` per role (device time ``k / fs``)."""
        p = self.plan
        fs = self.profile.sample_rate_hz
        t = np.arange(k0, k1, dtype=np.float64) / fs
        n = t.size
        j = np.floor((t - p.first_touch_s) / p.touch_every_s)
        touching = j >= 0
        j = np.where(touching, j, 0).astype(np.int64)
        rel = np.where(touching, t - (p.first_touch_s + j * p.touch_every_s), -1.0)
        mats = [self.material_of_touch(int(x)) for x in range(int(j.min()), int(j.max()) + 1)] if n else []
        base = int(j.min()) if n else 0
        e_o = np.array([mats[x - base].effusivity for x in j]) if n else np.zeros(0)
        t_obj = np.array([self.ambient_c if mats[x - base].object_temp_c is None else mats[x - base].object_temp_c
                          for x in j]) if n else np.zeros(0)
        c = p.contact_s
        ramps = self._per_touch(self.touch_ramp_s, j)
        if p.contact_force_fraction is not None:
            u_now, u_end = self._area_reading(np.clip(rel, 0.0, c), e_o, c, j)
        elif self.model is None:
            w = object_weight(self.sensor.effusivity, e_o)
            tau = self.sensor.tau_s
            u_now = w * response_shape(np.clip(rel, 0.0, c), tau)
            u_end = w * response_shape(c, tau)
        else:
            u_now, u_end = self._model_reading(np.clip(rel, 0.0, c), e_o, c)

        def curve(start_c, drift=0.0, drift_end=0.0):
            in_contact = (rel >= 0) & (rel < c)
            after = rel >= c
            during = start_c + drift + (t_obj - start_c - drift) * u_now
            released = start_c + drift_end + (t_obj - start_c - drift_end) * u_end
            decay = np.exp(-np.clip(rel - c, 0.0, None) / p.recover_s)
            out = np.full(n, start_c, dtype=np.float64)
            out = np.where(in_contact, during, out)
            return np.where(after, start_c + (released - start_c) * decay, out) + np.where(in_contact, 0.0, drift)

        if p.drift_c_per_s or p.drift_sd_c_per_s:
            # the touch whose drift window [start - lead, start + contact) holds each sample
            lead = p.drift_lead_s
            jn = np.floor((t - p.first_touch_s + lead) / p.touch_every_s)
            rel_d = t - (p.first_touch_s + jn * p.touch_every_s)
            rate = self._per_touch(self.touch_drift_c_per_s, np.maximum(jn, 0).astype(np.int64))
            drift = np.where((jn >= 0) & (rel_d < c), rate * (rel_d + lead), 0.0)
            rate_j = self._per_touch(self.touch_drift_c_per_s, j)
            sensor = curve(self.sensor_temp_c, drift, rate_j * (c + lead))
        else:
            sensor = curve(self.sensor_temp_c)
        passive = curve(self.ambient_c)
        f = p.press_force_n
        force = np.where((rel >= 0) & (rel < c),
                         f * np.clip(np.minimum(rel, c - rel) / np.maximum(ramps, 1e-12), 0.0, 1.0), 0.0)
        z = self._noise(k0, k1)
        if self.noise_c > 0:
            sensor = sensor + self.noise_c * z[0]
            passive = passive + self.noise_c * z[1]
        if self.force_noise_n > 0:
            force = np.maximum(force + self.force_noise_n * z[2], 0.0)
        return {"sensor": sensor, "object": passive, "force": force, "timestamp": t}

    def _model_reading(self, rel_s: np.ndarray, e_o: np.ndarray, contact_s: float):
        """Normalized reading of :attr:`model` at times ``rel_s`` after heat starts, and at release."""
        m = self.model
        fn = m.conduction  # the raw reading, before the host's smoothing
        now = np.zeros(rel_s.size)
        end = np.zeros(rel_s.size)
        for e in np.unique(e_o):
            sel = e_o == e
            now[sel] = fn(rel_s[sel], [float(e)], self.sensor)[0]
            end[sel] = fn(np.array([contact_s]), [float(e)], self.sensor)[0, 0]
        return now, end

    def _area_reading(self, rel_s: np.ndarray, e_o: np.ndarray, contact_s: float, touch: np.ndarray):
        """Normalized raw reading with the contact area following each touch's force ramp, and at release.

        The area share ``A(F / F_p)`` (:func:`~designkit.models.ramp.area_share`) of touch ``j``'s linear
        ramp over ``ramp_j``: the first share touches when the force reaches ``c F_p`` (``c ramp_j`` after
        the force leaves zero), and the area is whole at ``ramp_j``; the reading is the area-weighted sum
        of the model's raw step responses (Duhamel), on a 1 ms grid.
        """
        now = np.zeros(rel_s.size)
        end = np.zeros(rel_s.size)
        for jj in np.unique(touch):
            for e in np.unique(e_o[touch == jj]):
                sel = (touch == jj) & (e_o == e)
                grid, u = self._area_curve(int(jj), float(e), contact_s)
                now[sel] = np.interp(rel_s[sel], grid, u)
                end[sel] = u[-1]
        return now, end

    def _area_curve(self, j: int, e: float, contact_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Touch ``j``'s raw reading on its own sample grid from the force leaving zero to release (cached)."""
        import dataclasses

        from scipy.signal import fftconvolve

        from designkit.models import get_model
        from designkit.models.ramp import area_share

        key = (j, e)
        if key in self._curves:
            return self._curves[key]
        base = self.model if self.model is not None else get_model("semi-infinite")
        if getattr(base, "smoothing_window", 0) > 1:
            base = dataclasses.replace(base, smoothing_window=0)   # the wire carries the raw reading
        ramp_s = self.touch_ramp_s(j)
        # Duhamel's sum on a 1 ms grid: the share put down at t_j conducts from t_j on
        dt = 1e-3
        fine = np.arange(int(math.ceil(contact_s / dt)) + 1) * dt
        d_area = np.diff(area_share(np.minimum(fine / ramp_s, 1.0), float(self.plan.contact_force_fraction)),
                         prepend=0.0)
        step = np.zeros(fine.size)
        step[1:] = base.response(fine[1:], [e], self.sensor)[0]
        u_fine = fftconvolve(d_area, step)[:fine.size]
        fs = self.profile.sample_rate_hz
        grid = np.append(np.arange(0.0, contact_s, 1.0 / fs), contact_s)
        u = np.interp(grid, fine, u_fine)
        if len(self._curves) > 8:
            self._curves.pop(next(iter(self._curves)))
        self._curves[key] = (grid, u)
        return grid, u

    _BLOCK = 8192

    def _noise(self, k0: int, k1: int) -> np.ndarray:
        """Standard normal draws (3 channels) of samples k0..k1-1, the same however the stream is chunked."""
        out = np.empty((3, max(k1 - k0, 0)))
        k = k0
        while k < k1:
            b, off = divmod(k, self._BLOCK)
            if b not in self._blocks:
                if len(self._blocks) > 4:
                    self._blocks.pop(min(self._blocks))
                self._blocks[b] = as_generator([int(self._seed), b]).standard_normal((3, self._BLOCK))
            take = min(k1 - k, self._BLOCK - off)
            out[:, k - k0:k - k0 + take] = self._blocks[b][:, off:off + take]
            k += take
        return out

    # ----------------------------------------------------------------- wire
    def _bad_token(self, role: str) -> str:
        conv = self.profile.channels[role].conversion
        rng = self._rng
        if isinstance(conv, Thermistor):
            choices = ["0", str(conv.full_scale), str(conv.full_scale + 7), "-3"]
        elif isinstance(conv, Linear) and conv.adc_bits is not None:
            choices = [str(2 ** conv.adc_bits + 5), "-1"]
        else:
            valid = self.profile.channels[role].valid or (-40.0, 150.0)
            raw = conv.to_raw(np.array([valid[1] + 100.0, valid[0] - 100.0]))
            choices = [f"{v:.2f}" for v in np.asarray(raw)]
        return choices[int(rng.integers(len(choices)))]

    def lines(self, k0: int, k1: int) -> bytes:
        """Wire bytes of samples ``k0 .. k1-1`` (faults applied)."""
        prof = self.profile
        text = prof.format_lines(self.values(k0, k1))
        fl = self.faults
        if fl.line_faults and text:
            rng = self._rng
            n = len(text)
            draws = rng.random((5, n))
            delim = prof.delimiter if prof.delimiter is not None else " "
            mapped = [ch.field_index for ch in prof.channels.values()]
            clean_until = int(math.ceil(fl.line_faults_after_s * prof.sample_rate_hz - 1e-9)) - k0
            out: list[bytes] = []
            for i, line in enumerate(text):
                if i < clean_until:
                    out.append(line.encode(prof.encoding))
                    continue
                if draws[0, i] < fl.garbled:
                    out.append(bytes(rng.integers(0x80, 0x100, int(rng.integers(4, 30))).astype(np.uint8)))
                    self.lines_faulty += 1
                    continue
                parts = line.split(delim)
                if draws[1, i] < fl.partial and len(parts) > 1:
                    cut = len(delim.join(parts[:-1]))
                    line = line[:int(rng.integers(1, cut + 1))]
                    self.lines_faulty += 1
                elif draws[2, i] < fl.non_numeric:
                    parts[mapped[int(rng.integers(len(mapped)))]] = ["nan", "ERR", "--", "1.2.3", "inf", "x"][
                        int(rng.integers(6))]
                    line = delim.join(parts)
                    self.lines_faulty += 1
                elif draws[3, i] < fl.field_count:
                    line = delim.join(parts[:-1]) if rng.random() < 0.5 else line + delim + "0"
                    self.lines_faulty += 1
                elif draws[4, i] < fl.out_of_range:
                    parts[prof.channels["sensor"].field_index] = self._bad_token("sensor")
                    line = delim.join(parts)
                    self.lines_faulty += 1
                out.append(line.encode(prof.encoding))
            if fl.order_faults:
                out = self._order_faults(out, max(clean_until, 0))
        else:
            out = [line.encode(prof.encoding) for line in text]
        if prof.comment and out:  # each touch announced as it starts (before its onset): a device message
            p = self.plan
            fs = prof.sample_rate_hz
            j0 = max(0, int(math.ceil((k0 / fs - p.first_touch_s) / p.touch_every_s - 1e-9)))
            for j in range(j0, j0 + len(out) + 1):
                k = int(math.ceil((p.first_touch_s + j * p.touch_every_s) * fs - 1e-9))
                if k >= k1:
                    break
                if k >= k0:
                    out.insert(k - k0 + (j - j0), self.announcement(j).encode(prof.encoding))
        return b"\n".join(out) + b"\n" if out else b""

    def _order_faults(self, out: list[bytes], start: int) -> list[bytes]:
        """Apply ``corrupt``, ``duplicate`` and ``out_of_order`` to the wire lines from index ``start`` on.

        Drawn from their own generator, so that the other faults' draws (and
        the tests seeded on them) stay as they were.
        """
        fl, prof = self.faults, self.profile
        rng = self._order_rng
        n = len(out)
        draws = rng.random((3, n))
        delim = (prof.delimiter if prof.delimiter is not None else " ").encode(prof.encoding)
        mapped = sorted(ch.field_index for ch in prof.channels.values())
        for i in range(start, n):
            if draws[0, i] < fl.corrupt:
                body, star, tail = out[i].rpartition(b"*") if prof.checksum != "none" else (out[i], b"", b"")
                parts = body.split(delim)
                f = mapped[int(rng.integers(len(mapped)))]
                if f < len(parts):
                    digits = [k for k, c in enumerate(parts[f]) if 48 <= c <= 57]
                    if digits:
                        k = digits[int(rng.integers(len(digits)))]
                        field = bytearray(parts[f])
                        field[k] = 48 + (field[k] - 48 + int(rng.integers(1, 10))) % 10
                        parts[f] = bytes(field)
                        out[i] = delim.join(parts) + star + tail
                        self.lines_faulty += 1
        dup = [i for i in range(start, n) if draws[1, i] < fl.duplicate]
        swap = [i for i in range(start, n - 1) if draws[2, i] < fl.out_of_order]
        for i in swap:
            out[i], out[i + 1] = out[i + 1], out[i]
        self.lines_faulty += len(swap) + len(dup)
        for i in reversed(dup):
            out.insert(i + 1, out[i])
        return out

    def announcement(self, j: int) -> str:
        """The device message sent as touch ``j`` (0-based) starts, with the plan
        (:func:`~designkit.calibration.touch_plan.parse_announcement` reads it)."""
        return announcement_text(self.profile.comment or "#", j, [m.label for m in self.materials], self.plan)

    # ---------------------------------------------------------------- pty
    @property
    def port(self) -> str:
        """Path of the pseudo-terminal's device end (after :meth:`start`)."""
        if self._port is None:
            raise InputError("the emulator has not been started")
        return self._port

    def start(self) -> str:
        """Open the pseudo-terminal, start streaming in a thread, return the port path."""
        if self._thread is not None:
            raise InputError("the emulator is already running")
        master, slave = os.openpty()
        tty.setraw(slave)  # no echo, no newline translation, whoever opens it
        flags = fcntl.fcntl(master, fcntl.F_GETFL)
        fcntl.fcntl(master, fcntl.F_SETFL, flags | os.O_NONBLOCK)
        self._port = os.ttyname(slave)
        if self._link is not None:
            tmp = self._link.with_name(self._link.name + ".new")
            tmp.unlink(missing_ok=True)
            os.symlink(self._port, tmp)
            os.replace(tmp, self._link)
            self._port = str(self._link)
        # Our own end stays closed until a client opens the port: the device clock starts then
        # (_wait_for_client). Streaming into a pty nobody has opened put the first touch in the
        # kernel's buffer, which pyserial flushes on open: a client never saw touch 1, so a
        # guided run labelled every later touch with the wrong material.
        os.close(slave)
        self._master, self._slave = master, None
        self._thread = threading.Thread(target=self._run_safe, name="designkit-emulator", daemon=True)
        self._thread.start()
        return self._port

    def stop(self, timeout: float = 5.0) -> None:
        """Stop streaming and close the pseudo-terminal."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout)
        self._close()

    def wait(self, timeout: float | None = None) -> bool:
        """Block until the stream ends (vanish, :meth:`stop`); True if it did."""
        if self._thread is None:
            return True
        self._thread.join(timeout)
        return not self._thread.is_alive()

    def __enter__(self) -> "Emulator":
        self.start()
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    def _close(self) -> None:
        if self._link is not None and self._link.is_symlink():
            self._link.unlink(missing_ok=True)   # before the pty's number is freed
        for name in ("_master", "_slave"):
            fd = getattr(self, name)
            if fd is not None:
                try:
                    os.close(fd)
                except OSError:
                    pass
                setattr(self, name, None)
        self._closed.set()

    def _run_safe(self) -> None:
        try:
            self._run()
        except BaseException as exc:  # surfaced through .error; the pty closes
            self.error = exc
            self._close()

    def _wait_for_client(self) -> bool:
        """Block until a client opens the port (POLLHUP on the master clears); False if stopped first.

        Then keep a device end open ourselves (as before: a client may close and reopen the port),
        and wait ``CLIENT_SETTLE_S`` more, like a rig that resets when its port opens: the client's
        open (which flushes its input) is over before the first sample.
        """
        poller = select.poll()
        poller.register(self._master, select.POLLHUP)
        while not self._stop.is_set():
            events = poller.poll(10)
            if not any(ev & select.POLLHUP for _, ev in events):
                break
        else:
            return False
        try:
            self._slave = os.open(self._port, os.O_RDWR | os.O_NOCTTY)
        except OSError:
            pass
        return not self._stop.wait(CLIENT_SETTLE_S)

    def _run(self) -> None:
        fl = self.faults
        if not self._wait_for_client():
            return
        if fl.silent:
            self._stop.wait()
            return
        fs = self.profile.sample_rate_hz
        rate = fs * self.speed  # samples per real second
        chunk = max(1, int(rate * 0.02))
        pending = bytearray()
        if self.profile.comment:  # a newline first: a client drops the line it may have opened in the middle of
            pending += f"\n{self.greeting()}\n".encode(self.profile.encoding)
        k = 0
        anchor = time.monotonic()
        hold_until = 0.0
        next_burst = fl.burst_every_s if fl.burst_every_s > 0 else math.inf
        next_gap = fl.gap_every_s if fl.gap_every_s > 0 else math.inf
        vanish = fl.vanish_after_s if fl.vanish_after_s > 0 else math.inf
        master = self._master
        while not self._stop.is_set():
            now = time.monotonic()
            due = int((now - anchor) * rate)
            if due > k and len(pending) < _MAX_PENDING:
                k1 = min(due, k + chunk)
                t1 = k1 / fs
                if t1 >= vanish:
                    pending += self.lines(k, int(math.ceil(vanish * fs)))
                    self._flush(pending, deadline=time.monotonic() + 1.0)
                    self._read_by_host(deadline=time.monotonic() + 1.0)
                    self.vanished = True
                    self._close()
                    return
                if t1 >= next_gap:
                    kg = int(math.ceil(next_gap * fs))
                    pending += self.lines(k, kg)
                    self._flush(pending, deadline=time.monotonic() + 1.0)
                    if self._stop.wait(fl.gap_s):
                        return
                    k = kg + int(round(fl.gap_s * rate))  # the samples of the silence are lost
                    anchor = time.monotonic() - k / rate
                    while next_gap <= k / fs:
                        next_gap += fl.gap_every_s
                    continue
                if t1 >= next_burst:
                    hold_until = now + fl.burst_hold_s
                    next_burst += fl.burst_every_s
                pending += self.lines(k, k1)
                self.samples_sent += k1 - k
                k = k1
            if pending and now >= hold_until:
                try:
                    _, writable, _ = select.select([], [master], [], 0.01)
                except (OSError, ValueError):
                    return
                if writable:
                    try:
                        written = os.write(master, bytes(pending[:_MAX_PENDING]))
                    except BlockingIOError:
                        written = 0
                    except OSError:
                        return
                    del pending[:written]
            else:
                wait = (k + 1) / rate - (now - anchor)
                self._stop.wait(min(max(wait, 0.001), 0.01))
            # nobody reading (or a slow reader): pause instead of catching up later
            if (time.monotonic() - anchor) * rate - k > 0.5 * rate + chunk and len(pending) >= _MAX_PENDING:
                anchor = time.monotonic() - k / rate

    def _read_by_host(self, deadline: float) -> None:
        """Wait (until ``deadline``) for the host to read what was sent: the device vanishes after its last
        sample reached the host. Closing the pty discards what the host has not read yet, so without this
        wait how much of the stream the host saw would depend on how busy it was (a test saw the third
        touch's start lost at speed 50, where 3 s of device time are 60 ms)."""
        while self._slave is not None and time.monotonic() < deadline and not self._stop.is_set():
            try:
                waiting = int.from_bytes(fcntl.ioctl(self._slave, termios.FIONREAD, b"\0\0\0\0"), "little")
            except OSError:
                return
            if waiting == 0:
                return
            time.sleep(0.005)

    def _flush(self, pending: bytearray, deadline: float) -> None:
        master = self._master
        while pending and time.monotonic() < deadline and not self._stop.is_set():
            try:
                _, writable, _ = select.select([], [master], [], 0.01)
                if writable:
                    del pending[:os.write(master, bytes(pending))]
            except BlockingIOError:
                continue
            except OSError:
                return
