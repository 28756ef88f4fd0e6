"""The sensor: a frozen description of a heated thermal tactile sensor.

A :class:`Sensor` holds the parameters of the semi-infinite model (paper eq. 2)
that belong to the sensor rather than to the scene: its effusivity e_s, its
diffusivity alpha_s, the thermistor depth x and the sampling rate. Named
presets live in :data:`SENSORS`; calibration writes sensor YAML files that
:func:`load_sensor` reads back.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np
from cachetools import LRUCache

from ._validation import InputError, check_effusivity, check_label, check_nonnegative, check_positive
from .properties import time_constant

__all__ = ["MAX_SAMPLES_PER_TOUCH", "MODEL_KEYS", "SENSORS", "Sensor", "last_sample_index", "load_sensor",
           "remember_checked_file", "sample_times_s", "within_sample_limit"]

#: Version of the sensor files this designkit writes. 2: a calibrated file records the rig's operating
#: conditions (``conditions``, :mod:`designkit.rig`). Version 1 files (no conditions) still load.
SENSOR_FILE_VERSION = 2
_READABLE_VERSIONS = (1, 2)

#: The most samples one touch may have (10 000 s at 100 Hz, 1 s at 1 MHz): 8 MB per touch curve.
#: A longer touch or a faster sensor is refused before anything is allocated.
MAX_SAMPLES_PER_TOUCH = 1_000_000


#: Largest sensor diffusivity accepted [m^2/s]: 10x diamond's, the highest of any solid.
MAX_DIFFUSIVITY_M2_S = 1e-2
#: Deepest thermistor accepted [m]: 10 cm (a time constant of hours under any skin).
MAX_DEPTH_M = 0.1


#: Samples of tolerance when a contact time is turned into a sample count: keeps 2.0 s * 200 Hz = 400
#: (399.99999999999994 in floating point) from rounding down.
_SAMPLE_TOLERANCE = 1e-9


def last_sample_index(contact_s, sample_rate_hz: float) -> np.ndarray:
    """Index ``k`` of the last sample a contact of ``contact_s`` takes: ``floor(contact_s * fs)``, vectorized.

    The rule of :func:`sample_times_s` (samples ``0 .. k``, the first at contact) for arrays of contact
    times. Every caller allocates ``k + 1`` samples, so the per-touch budget is enforced here, before any
    allocation: a contact beyond :data:`MAX_SAMPLES_PER_TOUCH` samples (a sample rate of 1e12 Hz grew a
    question to 24 GB; a contact of 1e308 s became index -2**63), or a negative or NaN one, is a one-line
    InputError. Callers that leave such touches out test :func:`within_sample_limit` first.

    Parameters
    ----------
    contact_s : array_like
        Contact durations [s], >= 0 and finite.
    sample_rate_hz : float
        Sampling rate [Hz].

    Returns
    -------
    ndarray of int64
        Same shape as ``contact_s`` (0-d for a number).

    Examples
    --------
    >>> int(last_sample_index(2.0, 200.0)), last_sample_index([0.0, 0.004, 0.005], 200.0).tolist()
    (400, [0, 0, 1])
    """
    if type(contact_s) is float:  # one number (the common call): no array round trip, the same rule
        k1 = contact_s * float(sample_rate_hz) + _SAMPLE_TOLERANCE
        if 0.0 <= k1 < MAX_SAMPLES_PER_TOUCH:
            return np.int64(math.floor(k1))
    k = _last_index_float(contact_s, sample_rate_hz)
    ok = (k >= 0) & (k < MAX_SAMPLES_PER_TOUCH)
    if not ok.all():
        bad = float(np.broadcast_to(np.asarray(contact_s, dtype=np.float64), k.shape)[~ok].flat[0])
        if bad < 0:
            raise InputError(f"contact time must be >= 0 s, got {bad:g}")
        check_samples_per_touch(bad, sample_rate_hz)  # says why, in one line
    return np.floor(k).astype(np.int64)


def _last_index_float(contact_s, sample_rate_hz: float) -> np.ndarray:
    """``contact_s * fs`` plus the sampling tolerance, before the floor: the one rule of the sample count
    (may be inf or NaN for absurd inputs; callers compare it before converting)."""
    with np.errstate(over="ignore", invalid="ignore"):
        return np.asarray(contact_s, dtype=np.float64) * float(sample_rate_hz) + _SAMPLE_TOLERANCE


def within_sample_limit(contact_s, sample_rate_hz: float) -> np.ndarray:
    """Whether a touch of ``contact_s`` [s] has fewer samples than :data:`MAX_SAMPLES_PER_TOUCH`, vectorized.

    The rule :func:`sample_times_s` refuses beyond (an infinite or NaN product is beyond it);
    for callers that leave such a touch out instead of refusing it.

    Examples
    --------
    >>> within_sample_limit([2.0, 4999.0, 5000.0, 1e308], 200.0).tolist()
    [True, True, False, False]
    """
    return _last_index_float(contact_s, sample_rate_hz) < MAX_SAMPLES_PER_TOUCH


def check_samples_per_touch(contact_s: float, sample_rate_hz: float, what: str = "a touch",
                            advice: str = "shorten the contact or lower the sample rate") -> float:
    """The last sample index of a touch (float), or a one-line InputError beyond :data:`MAX_SAMPLES_PER_TOUCH`.

    The one limit on a touch's length in samples, whoever asks: a simulated touch, a design's longest
    contact at its highest rate, a live test's longest contact (each ran without end, or wrote hundreds
    of MB, before it was checked). ``what`` names the request, ``advice`` what to change.

    >>> int(check_samples_per_touch(2.0, 200.0))  # index 400 (with a tolerance of 1e-9 samples): 401 samples
    400
    """
    n_float = float(_last_index_float(contact_s, sample_rate_hz))  # may be inf (1e308 s)
    if n_float != n_float:
        raise InputError(f"{what}: contact time and sample rate must be numbers, got {contact_s!r} s at "
                         f"{sample_rate_hz!r} Hz")
    if not n_float < MAX_SAMPLES_PER_TOUCH:
        raise InputError(f"{what} of {contact_s:g} s at {sample_rate_hz:g} Hz has {n_float + 1:.4g} samples per "
                         f"touch; the limit is {MAX_SAMPLES_PER_TOUCH:.0e} ({advice})")
    return n_float


def sample_times_s(contact_s: float, sample_rate_hz: float) -> np.ndarray:
    """Sample times of one touch: ``k / fs`` for ``k = 0 .. floor(contact_s * fs)``.

    The first sample is taken at the instant of contact (t = 0), so a contact
    shorter than one sample period still has one sample, which carries no
    material information. A 2 s touch at 200 Hz has 401 samples.

    Parameters
    ----------
    contact_s : float
        Contact duration [s], > 0.
    sample_rate_hz : float
        Sampling rate [Hz], > 0.

    Returns
    -------
    ndarray
        Times [s], float64.

    Examples
    --------
    >>> sample_times_s(0.02, 200.0)
    array([0.   , 0.005, 0.01 , 0.015, 0.02 ])
    """
    contact_s = check_positive("contact time [s]", contact_s)
    fs = check_positive("sample rate [Hz]", sample_rate_hz)
    n_float = check_samples_per_touch(contact_s, fs)  # before math.floor sees an infinite count
    n = int(math.floor(n_float))
    return np.arange(n + 1, dtype=np.float64) / fs


@dataclass(frozen=True)
class Sensor:
    """A heated thermal sensor (paper section II, appendix).

    Parameters
    ----------
    effusivity : float
        Sensor effusivity e_s [J s^-1/2 K^-1 m^-2].
    diffusivity_m2_s : float
        Sensor diffusivity alpha_s [m^2 s^-1].
    depth_m : float
        Thermistor depth x below the contact surface [m]. Only
        ``tau = x^2 / (4 alpha_s)`` matters to the model.
    sample_rate_hz : float
        Sampling rate [Hz].
    name : str
        Label used in tables and reports.
    noise_c : float or None
        Measured noise standard deviation [degC], when known (calibration
        estimates it from pre-contact samples). Scenes set their own noise.
    provenance : mapping
        Free-form record of where the numbers came from (not compared).
    conditions : mapping or None
        The rig's operating conditions seen in calibration (:class:`designkit.rig.RigConditions`,
        sensor file version 2): questions about the sensor take them as their defaults. None:
        presets and files from before version 2.
    model : mapping or None
        The forward model the sensor was identified with, as calibration
        records it (:data:`MODEL_KEYS`): ``{"name", "params", "time_offset_s",
        "contact_spread", "object_temperature", "candidate", "contact_area",
        "drift"}``. ``contact_area`` (calibrated with a force-driven contact
        area): the threshold ``force_fraction`` c (with ``force_fraction_interval``,
        its 95 % interval ``{low, high, coverage}``),
        the calibration touches' median force over its plateau (``time_s``
        after the detected onset, ``force_share``), each touch's own
        (``touch_force_share``, rows on ``time_s``) and ``n_touches``;
        ``drift``: how the heater's drift was treated (``"per-touch"``: a
        nuisance fitted per touch like its initial temperature, not a
        property of the sensor). None (old files, presets): the paper's
        semi-infinite model. Plain data here;
        :func:`designkit.models.sensor_model` turns it into a forward model.

    Examples
    --------
    >>> s = Sensor(1982.0, 1.1e-9, model={"name": "contact", "params": {"conductance_w_m2k": 3000.0}})
    >>> s.model["name"], Sensor.from_dict(s.to_dict()) == s
    ('contact', True)
    """

    effusivity: float
    diffusivity_m2_s: float
    depth_m: float = 80e-6
    sample_rate_hz: float = 200.0
    name: str = "custom"
    noise_c: float | None = None
    provenance: Mapping[str, Any] = field(default_factory=dict, compare=False, hash=False)
    model: Mapping[str, Any] | None = field(default=None, hash=False)
    conditions: Mapping[str, Any] | None = field(default=None, compare=False, hash=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "effusivity", check_positive("sensor effusivity e_s", self.effusivity))
        check_effusivity("sensor e_s", self.effusivity)  # at most 1e7: 1e308 was taken
        object.__setattr__(self, "diffusivity_m2_s",
                           check_positive("sensor diffusivity alpha_s [m^2/s]", self.diffusivity_m2_s))
        if self.diffusivity_m2_s > MAX_DIFFUSIVITY_M2_S:
            raise InputError(f"sensor diffusivity alpha_s must be at most {MAX_DIFFUSIVITY_M2_S:g} m^2/s (diamond's "
                             f"is about 1e-3), got {self.diffusivity_m2_s:g}")
        object.__setattr__(self, "depth_m", check_nonnegative("thermistor depth [m]", self.depth_m))
        if self.depth_m > MAX_DEPTH_M:
            raise InputError(f"thermistor depth must be at most {MAX_DEPTH_M:g} m, got {self.depth_m:g}")
        object.__setattr__(self, "sample_rate_hz", check_positive("sample rate [Hz]", self.sample_rate_hz))
        check_label("sensor name", self.name)  # one line of a summary (a newline spilled it over several)
        if self.noise_c is not None:
            object.__setattr__(self, "noise_c", check_nonnegative("sensor noise [degC]", self.noise_c))
        object.__setattr__(self, "provenance", dict(self.provenance))
        if self.model is not None:
            object.__setattr__(self, "model", _model_block(self.model, "sensor model"))
        if self.conditions is not None:
            if not isinstance(self.conditions, Mapping):
                raise InputError(f"sensor conditions: expected a mapping, got {type(self.conditions).__name__}")
            unknown = sorted(set(self.conditions) - set(CONDITION_KEYS))
            if unknown:
                raise InputError(f"sensor conditions: unknown key(s) {', '.join(unknown)} "
                                 f"(known: {', '.join(CONDITION_KEYS)})")
            object.__setattr__(self, "conditions", _plain(self.conditions))

    @functools.cached_property
    def tau_s(self) -> float:
        """Time constant ``tau = x^2 / (4 alpha_s)`` [s] (1.3445 s for the paper's sensor; computed once per
        Sensor, which is frozen)."""
        return float(time_constant(self.depth_m, self.diffusivity_m2_s))

    def times_s(self, contact_s: float) -> np.ndarray:
        """Sample times [s] of a touch lasting ``contact_s`` (see :func:`sample_times_s`)."""
        return sample_times_s(contact_s, self.sample_rate_hz)

    def replace(self, **changes: Any) -> "Sensor":
        """A copy with some fields changed."""
        return dataclasses.replace(self, **changes)

    # ------------------------------------------------------------------ I/O
    def to_dict(self) -> dict[str, Any]:
        """Plain-data form, the content of a sensor YAML file."""
        out: dict[str, Any] = {
            "designkit_sensor": SENSOR_FILE_VERSION,
            "name": self.name,
            "effusivity": self.effusivity,
            "diffusivity_m2_s": self.diffusivity_m2_s,
            "depth_m": self.depth_m,
            "tau_s": self.tau_s,
            "sample_rate_hz": self.sample_rate_hz,
        }
        if self.noise_c is not None:
            out["noise_c"] = self.noise_c
        if self.provenance:
            out["provenance"] = _plain(self.provenance)
        if self.model is not None:
            out["model"] = _plain(self.model)
        if self.conditions is not None:
            out["conditions"] = _plain(self.conditions)
        return out

    @property
    def model_name(self) -> str:
        """Name of the forward model the sensor was identified with (``semi-infinite`` when none is recorded)."""
        return "semi-infinite" if self.model is None else str(self.model["name"])

    @property
    def problems(self) -> list[str]:
        """What calibration found wrong but wrote anyway (``--force``): one line each, empty when none."""
        return [str(p) for p in self.provenance.get("problems", []) or []]

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], *, source: str = "sensor", schema: bool = True) -> "Sensor":
        """Build from :meth:`to_dict` output, with one-line errors naming ``source``.

        ``schema=False`` skips the schema's type check, for data that passed it already (a shipped
        table's header, known by its content hash); the field checks below still run.
        """
        from ._schemas import schemas, validate

        if not isinstance(data, Mapping):
            raise InputError(f"{source}: a sensor must be a mapping of fields, got {type(data).__name__}")
        version = data.get("designkit_sensor", 1)
        if version not in _READABLE_VERSIONS:
            newer = isinstance(version, int) and not isinstance(version, bool) and version > SENSOR_FILE_VERSION
            raise InputError(f"{source}: sensor file version {version!r}, this designkit reads versions "
                             f"{', '.join(map(str, _READABLE_VERSIONS))}"
                             + (": it was written by a newer designkit; upgrade designkit (pip install -U designkit)"
                                if newer else ": recalibrate with 'designkit calibrate fit' to write a current one"))
        missing = [k for k in ("effusivity", "diffusivity_m2_s") if k not in data]
        if missing:
            raise InputError(f"{source}: missing sensor field(s) {', '.join(missing)}")
        known = {f.name for f in dataclasses.fields(cls)} | {"designkit_sensor", "tau_s"}
        unknown = sorted(set(data) - known)
        if unknown:
            raise InputError(f"{source}: unknown sensor field(s) {', '.join(unknown)}")
        if schema:
            checked = validate(schemas()["sensor"], dict(data), source)  # types, strictly: no [1, 2] for a number
            data = {k: getattr(checked, k) for k in data}
            if data.get("model") is not None:
                data["model"] = checked.model.model_dump(exclude_none=False)
        kwargs = {k: data[k] for k in data if k not in ("designkit_sensor", "tau_s")}
        try:
            sensor = cls(**kwargs)
        except InputError as exc:
            raise InputError(f"{source}: {exc}") from None
        if data.get("tau_s") is not None:
            tau = float(data["tau_s"])
            if not math.isclose(tau, sensor.tau_s, rel_tol=1e-6):
                raise InputError(
                    f"{source}: tau_s = {tau:g} s disagrees with depth and diffusivity "
                    f"(x^2 / (4 alpha_s) = {sensor.tau_s:g} s)")
        return sensor

    def to_yaml(self, path: str | Path) -> Path:
        """Write a sensor YAML file (atomically) and return its path."""
        import yaml

        from ._io import atomic_write_text

        text = "# designkit sensor file: effusivity [J s^-1/2 K^-1 m^-2], diffusivity [m^2/s],\n" \
               "# depth [m], tau = depth^2 / (4 diffusivity) [s], sample rate [Hz], noise [degC]\n"
        if self.model is not None:
            text += ("# model: the forward model identified with it (name, its parameters in SI units with e_s\n"
                     "# above; null = infinite), the fitted contact-time offset [s], the per-touch spread of the\n"
                     "# contact conductance (geometric SD), how each material's temperature was taken;\n"
                     "# contact_area: the area grows with the force as clip((F/F_p - c)/(1 - c), 0, 1), c =\n"
                     "# force_fraction; the calibration touches' median F/F_p (force_share at time_s after the\n"
                     "# onset) sets the model's time 0, and a simulated touch presses as one of them\n"
                     "# (touch_force_share); drift: per-touch = each touch's heater drift was fitted like its\n"
                     "# initial temperature: not a sensor property, a question's touch has none\n")
        text += yaml.safe_dump(self.to_dict(), sort_keys=False)
        return atomic_write_text(Path(path), text)

    @classmethod
    def from_yaml(cls, path: str | Path) -> "Sensor":
        """Read a sensor YAML file written by :meth:`to_yaml` or by calibration."""
        from ._schemas import load_yaml

        p = Path(path)
        data = load_yaml(p, "sensor file")  # a regular UTF-8 file (a FIFO is refused, not waited on)
        sensor = cls.from_dict(data, source=f"sensor file {p}")  # what is wrong in its fields, said first
        if "designkit_sensor" not in data:  # any YAML mapping of numbers was taken for a sensor
            raise InputError(f"sensor file {p} has no 'designkit_sensor: {SENSOR_FILE_VERSION}' line: not a sensor "
                             f"file written by designkit (calibration writes one; add the line to a file of your own)")
        return sensor


#: The keys of a sensor file's ``conditions`` record (:class:`designkit.rig.RigConditions`).
CONDITION_KEYS = ("noise_c", "noise_source", "pre_contact_noise_c", "residual_rms_c", "sensor_temp_c",
                  "object_temp_c", "delta_t_c", "sensor_temp_spread_c", "onset", "onset_offset_s", "contact_ramp",
                  "n_touches", "noise_correlation_s")

#: The keys of a sensor's ``model`` record (what calibration writes beside the sensor fields).
MODEL_KEYS = ("name", "params", "time_offset_s", "contact_spread", "object_temperature", "candidate", "contact_area",
              "drift")


def _plain(value: Any) -> Any:
    """JSON/YAML-ready copy: mappings to dicts, tuples to lists, numpy scalars to Python numbers."""
    if type(value) in (int, str, bool) or (type(value) is float and not math.isinf(value)):
        return value  # (most of a calibrated file's thousands of values: no slower Mapping check first)
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and math.isinf(value):
        return None  # what a model's to_dict writes for an infinite parameter
    return value


def _model_block(model: Any, source: str) -> dict[str, Any]:
    """A checked ``model`` record: a mapping with a name, its other keys among :data:`MODEL_KEYS`."""
    if not isinstance(model, Mapping):
        raise InputError(f"{source}: expected a mapping with a name and params, got {type(model).__name__}")
    unknown = sorted(set(model) - set(MODEL_KEYS))
    if unknown:
        raise InputError(f"{source}: unknown key(s) {', '.join(unknown)} (known: {', '.join(MODEL_KEYS)})")
    if not isinstance(model.get("name"), str) or not model["name"].strip():
        raise InputError(f"{source}: the model needs a name (e.g. layered)")
    params = model.get("params") or {}
    if not isinstance(params, Mapping):
        raise InputError(f"{source}: params must be a mapping of the model's parameters")
    out = {k: None for k in MODEL_KEYS}
    out.update(_plain(model))
    out["params"] = _plain(params)
    return out


#: Named sensor presets. ``paper``: the values identified in the paper's
#: appendix (e_s = 892, alpha_s = 1.19e-9 m^2/s) with the 80 um thermistor depth
#: of the same lab's public model code, sampled at 200 Hz.
SENSORS: dict[str, Sensor] = {
    "paper": Sensor(
        effusivity=892.0,
        diffusivity_m2_s=1.19e-9,
        depth_m=80e-6,
        sample_rate_hz=200.0,
        name="paper",
        provenance={"source": "Bai et al., appendix (e_s, alpha_s); thermistor depth 80 um"},
    ),
}


def load_sensor(name_or_path: "str | Path | Sensor") -> Sensor:
    """A sensor from a preset name (``"paper"``), a YAML path, or a :class:`Sensor`.

    Examples
    --------
    >>> s = load_sensor("paper")
    >>> s.effusivity, round(s.tau_s, 4)
    (892.0, 1.3445)
    """
    if isinstance(name_or_path, Sensor):
        return name_or_path
    key = str(name_or_path)
    if key in SENSORS:
        return SENSORS[key]
    p = Path(key)
    if p.suffix.lower() in (".yaml", ".yml") or p.exists():
        import hashlib

        from ._schemas import check_regular_file

        # parsed once per process while its content is the same (a calibrated file is thousands of lines); a
        # FIFO, folder or oversized file is refused here, before its bytes are read for the memo's key
        check_regular_file(p, "sensor file")
        try:
            content = p.read_bytes()
            stamp = (str(p.resolve()), hashlib.sha256(content).hexdigest())
        except OSError:  # from_yaml says what is missing
            return Sensor.from_yaml(p)
        if stamp not in _READ:  # a file recorded as checked by designkit tables build: no YAML, no schema
            _READ[stamp] = _checked_sensor(content, p) or Sensor.from_yaml(p)
        return _READ[stamp]
    raise InputError(f"unknown sensor {key!r}: use a preset ({', '.join(SENSORS)}) or a sensor YAML file")


def remember_checked_file(path: "str | Path", sensor: Sensor) -> None:
    """Record (:func:`designkit._schemas.record_checked`) that the sensor file ``path``, its bytes as they are now,
    reads as ``sensor``: :func:`load_sensor` then builds the Sensor from the record instead of parsing the YAML
    through the schema (``designkit tables build --sensor FILE`` records it when it registers the sensor's
    table). A file that does not read as ``sensor`` is not recorded."""
    from ._schemas import record_checked

    p = Path(path)
    try:
        content = p.read_bytes()
    except OSError:  # (a preset's name, a file gone meanwhile): nothing to record
        return
    if load_sensor(p).to_dict() == sensor.to_dict():
        record_checked("sensor", content, sensor.to_dict())


def _checked_sensor(content: bytes, p: Path) -> "Sensor | None":
    """The Sensor recorded for a sensor file of exactly ``content`` (:func:`remember_checked_file`), or None."""
    from ._schemas import recorded

    data = recorded("sensor", content)
    if not isinstance(data, dict):
        return None
    try:
        return Sensor.from_dict(data, source=f"sensor file {p}", schema=False)
    except Exception:  # (not what designkit recorded): the long way says what is wrong, if anything
        return None


#: Sensor files parsed by this process, keyed by (path, SHA-256 of the content): the frozen Sensor is shared.
#: Process-wide on purpose (the exception to "no global state" here): it memoizes a pure function of the file's
#: bytes, holds frozen Sensors, is bounded and changes no answer. The command line parses a file once and passes
#: the Sensor down; the memo serves library users who name the same file question after question, and gives one
#: Sensor per content, which registry.sensor_digest's memo relies on.
_READ: "LRUCache[tuple, Sensor]" = LRUCache(16)
