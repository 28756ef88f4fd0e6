"""A sweep's configuration: everything that determines its table, validated and hashed.

A :class:`SweepConfig` is read from a YAML file (``tables/*.yaml``), from a
mapping (a table header's ``config``) or built in code; its :meth:`~SweepConfig.digest`
is the identity a resumed sweep is checked against.

Units: effusivity [J s^-1/2 K^-1 m^-2], times [s], temperatures and noise
[degC], diffusivity [m^2 s^-1]; ``noise_ratio`` is sigma / dT [-].
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from .._validation import check_file_name, InputError, check_positive, check_repeats
from ..models import get_model
from ..objects import ObjectClass
from ..recognition.features import DEFAULT_SLOPE_WINDOW_S
from ..scene import Scene
from ..sensor import Sensor, load_sensor

__all__ = ["FIDELITIES", "SOLVERS", "SweepConfig", "check_chunk", "chunk_identity", "stamp_chunk"]

#: Limits checked before any work: more intervals than this cannot be swept (the full F1 matrix of
#: 100 000 intervals is 80 GB per scene point and contact), nor axes longer than this.
MAX_INTERVALS = 100_000
MAX_AXIS_POINTS = 10_000
#: Effusivity grids end below this [J s^-1/2 K^-1 m^-2] (diamond ~1e5); 1e308 overflowed the grid.
MAX_EFFUSIVITY = 1e7
#: Trials per interval: 1 000 000 touches of one interval is already ~6 GB of curves at 800 samples.
MAX_TRIALS = 1_000_000

#: What decides distinguishability: the paper's SVM, or the ideal observer (the bound).
FIDELITIES = ("svm", "ideal")

#: What fits the SVM: the batched libsvm-equivalent solver (default; ``batched-cupy`` is the same code
#: on a GPU through CuPy, ``batched-array-api`` that GPU code on numpy, to check a GPU build's table on
#: a CPU) or scikit-learn's pipeline one pair at a time (the reference).
SOLVERS = ("batched", "sklearn", "batched-cupy", "batched-array-api")


@dataclass(frozen=True)
class SweepConfig:
    """Everything that determines a sweep's result.

    Fixed initial conditions use the ``noise_ratio`` axis (sigma / dT); varied
    initial conditions (``sensor_temp_spread_c`` or ``ambient_temp_spread_c``
    > 0) need the ``noise_c`` and ``delta_t_c`` axes, because the invariance
    no longer holds. The invariance holds for every forward model here (all
    are linear in the temperatures), so the ``noise_ratio`` axis serves them all.

    ``model`` is the forward model of the touches: a name, a mapping
    ``{name: contact, conductance_w_m2k: 2000}`` (what a YAML config holds)
    or a :class:`~designkit.models.ForwardModel`; default the paper's
    semi-infinite model. Models that need the object's diffusivity (``slab``)
    take ``diffusivity_m2_s`` [m^2 s^-1], one value for every interval.
    ``fidelity: ideal`` needs a closed-form ideal observer, which exists only
    for shared-shape models.

    Examples
    --------
    >>> cfg = SweepConfig(model={"name": "contact", "conductance_w_m2k": 2000}, intervals=10)
    >>> cfg.model.describe()
    'contact (conductance_w_m2k = 2000 W m^-2 K^-1)'
    >>> cfg.to_dict()["model"]
    {'name': 'contact', 'conductance_w_m2k': 2000.0}
    >>> SweepConfig(model="slab", diffusivity_m2_s=1e-7).model.name
    'slab'
    """

    name: str = "sweep"
    sensor: str = "paper"
    fidelity: str = "svm"
    e_min: float = 0.0
    e_max: float = 40000.0
    intervals: int = 500
    trials: int = 100
    folds: int = 3
    threshold: float = 0.9
    seed: int = 0
    max_repeats: int = 4
    z: float = 2.0
    noise_ratio: tuple[float, ...] | None = (0.005,)
    noise_c: tuple[float, ...] | None = None
    delta_t_c: tuple[float, ...] | None = None
    ambient_temp_c: float = 25.0
    sensor_temp_spread_c: float = 0.0
    ambient_temp_spread_c: float = 0.0
    contact_s: tuple[float, ...] = (1.0, 2.0, 3.0, 4.0)
    sample_rate_hz: float | None = None
    slope_window_s: float = DEFAULT_SLOPE_WINDOW_S
    blocks: int = 1
    full_matrix: bool = False
    ideal_bound: bool = True
    model: Any = None
    diffusivity_m2_s: float | None = None
    solver: str = "batched"
    #: Play the sensor file's rig as a question about it does (:func:`designkit.rig.rig_scene`: its correlated
    #: noise, touches read from the detected onset): what ``tables build --sensor FILE`` sets.
    rig_scene: bool = False

    def __post_init__(self) -> None:
        for name in ("noise_ratio", "noise_c", "delta_t_c", "contact_s"):
            object.__setattr__(self, name, _axis(name, getattr(self, name)))
        self._check_grid()
        self._check_axes()
        self._check_model()
        self._check_size()

    def _check_size(self) -> None:
        """The table's arrays must fit: scene points x contacts x intervals (x intervals for F1 matrices)."""
        from .._validation import check_memory

        from ..sensor import MAX_SAMPLES_PER_TOUCH

        fs = self.sample_rate_hz if self.sample_rate_hz is not None else load_sensor(self.sensor).sample_rate_hz
        longest = max(self.contact_s)
        if not longest * fs < MAX_SAMPLES_PER_TOUCH:
            raise InputError(f"contact_s: a touch of {longest:g} s at {fs:g} Hz has {longest * fs:.4g} samples; the limit "
                             f"is {MAX_SAMPLES_PER_TOUCH:.0e} per touch")
        cells = math.prod(self.scene_shape) * len(self.contact_s) * self.intervals
        per_cell = 8 * 12 + (8 * self.intervals if self.full_matrix else 0)
        check_memory(f"a table of {cells:g} cells ({self.intervals} intervals"
                     + (", full F1 matrices" if self.full_matrix else "") + ")", cells * per_cell)

    def _check_grid(self) -> None:
        """The effusivity grid, the classifier protocol and the search settings."""
        if self.solver not in SOLVERS:
            raise InputError(f"solver must be one of {', '.join(SOLVERS)}, got {self.solver!r}")
        if self.fidelity not in FIDELITIES:
            raise InputError(f"fidelity must be one of {', '.join(FIDELITIES)}, got {self.fidelity!r}")
        if self.e_max > MAX_EFFUSIVITY:
            raise InputError(f"effusivity range max = {self.e_max:g} is above {MAX_EFFUSIVITY:g} J s^-1/2 K^-1 m^-2 "
                             "(no material comes near: diamond is about 1e5)")
        if not (0 <= self.e_min < self.e_max < math.inf):
            raise InputError(f"effusivity range must satisfy 0 <= min < max < inf, got ({self.e_min:g}, {self.e_max:g}]")
        for key in ("intervals", "folds", "trials", "max_repeats", "blocks", "seed"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                    or not math.isfinite(value):
                raise InputError(f"{key}: expected an integer, got {value!r}")
        for key in ("e_min", "e_max", "threshold", "z", "ambient_temp_c", "sensor_temp_spread_c",
                    "ambient_temp_spread_c", "slope_window_s"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                    or not math.isfinite(value):
                raise InputError(f"{key}: expected a finite number, got {value!r}")
        for key in ("full_matrix", "ideal_bound"):
            if not isinstance(getattr(self, key), (bool, np.bool_)):
                raise InputError(f"{key}: expected true or false, got {getattr(self, key)!r}")
        if not isinstance(self.name, str) or not isinstance(self.sensor, str):
            bad = "name" if not isinstance(self.name, str) else "sensor"
            raise InputError(f"{bad}: expected text, got {getattr(self, bad)!r}")
        check_file_name("name (the table's file name)", self.name)  # before any work: it names files
        if int(self.intervals) != self.intervals or self.intervals < 2:
            raise InputError(f"intervals must be an integer >= 2, got {self.intervals}")
        if self.intervals > MAX_INTERVALS:
            raise InputError(f"intervals = {self.intervals:g} is more than this designkit sweeps "
                             f"(limit {MAX_INTERVALS}: the grid, its staircases and F1 matrices must fit in memory)")
        if self.trials > MAX_TRIALS:
            raise InputError(f"trials = {self.trials:g} per interval is more than the limit {MAX_TRIALS}")
        if int(self.folds) != self.folds or self.folds < 2:
            raise InputError(f"folds must be >= 2, got {self.folds}")
        if int(self.trials) != self.trials or self.trials < self.folds:
            raise InputError(f"trials per interval ({self.trials}) must be at least the number of folds ({self.folds})")
        if not (2 / 3 < self.threshold < 1):
            raise InputError(f"threshold must be in (2/3, 1) (F1 of a blind all-positive guess is 2/3), got {self.threshold:g}")
        check_repeats("max_repeats", self.max_repeats)
        check_positive("z", self.z)
        if int(self.blocks) != self.blocks or self.blocks < 1:
            raise InputError(f"blocks must be >= 1, got {self.blocks}")
        if self.seed < 0 or int(self.seed) != self.seed:
            raise InputError(f"seed must be a non-negative integer, got {self.seed}")

    def _check_axes(self) -> None:
        """Contact times, the noise axes (which depend on fixed or varied conditions), the scene."""
        contacts = self.contact_s
        if any(not (c > 0 and math.isfinite(c)) for c in contacts) or list(contacts) != sorted(set(contacts)):
            raise InputError(f"contact times must be positive, finite, increasing and distinct, got {list(contacts)}")
        if self.varied:
            if self.noise_c is None or self.delta_t_c is None:
                raise InputError("varied initial conditions need the noise_c and delta_t_c axes "
                                 "(sigma/dT invariance does not hold there)")
            if self.noise_ratio is not None:
                raise InputError("give either noise_ratio (fixed conditions) or noise_c and delta_t_c, not both")
        else:
            if (self.noise_c is None) != (self.delta_t_c is None):
                raise InputError("noise_c and delta_t_c go together")
            if self.noise_c is not None and self.noise_ratio is not None:
                raise InputError("give either noise_ratio or noise_c and delta_t_c, not both")
            if self.noise_c is None and self.noise_ratio is None:
                raise InputError("no noise axis: give noise_ratio (sigma/dT) or noise_c and delta_t_c")
        for name, vals in (("noise_ratio", self.noise_ratio), ("noise_c", self.noise_c)):
            if vals is not None and any(not (v >= 0 and math.isfinite(v)) for v in vals):
                raise InputError(f"{name} values must be finite and >= 0, got {list(vals)}")
        if self.delta_t_c is not None and any(not (v != 0 and math.isfinite(v)) for v in self.delta_t_c):
            raise InputError(f"delta_t_c values must be finite and non-zero, got {list(self.delta_t_c)}")
        from .._validation import check_temperature

        for name in ("noise_ratio", "noise_c", "delta_t_c"):  # 1e308 overflowed the simulation
            for v in getattr(self, name) or ():
                check_temperature(f"{name} value", v)
        check_temperature("ambient_temp_c", self.ambient_temp_c)
        check_temperature("sensor_temp_spread_c", self.sensor_temp_spread_c)
        check_temperature("ambient_temp_spread_c", self.ambient_temp_spread_c)
        if self.sample_rate_hz is not None:
            object.__setattr__(self, "sample_rate_hz", check_positive("sample rate [Hz]", self.sample_rate_hz))
        for name in ("sensor_temp_spread_c", "ambient_temp_spread_c"):
            if getattr(self, name) < 0:
                raise InputError(f"{name} must be >= 0")

    def _check_model(self) -> None:
        """Resolve ``model`` to a ForwardModel and check what it needs from the config."""
        try:
            if self.model is None:  # the model a sensor file records (semi-infinite for presets)
                from ..models import sensor_model

                model = sensor_model(load_sensor(self.sensor))
            else:
                model = get_model(self.model)
        except InputError as exc:
            raise InputError(f"model: {exc}") from None
        object.__setattr__(self, "model", model)
        needs_alpha = "diffusivity_m2_s" in model.object_properties
        if self.diffusivity_m2_s is not None:
            if not needs_alpha:
                raise InputError(f"diffusivity_m2_s: the {model.name} model does not use the objects' "
                                 "diffusivity; leave it out")
            object.__setattr__(self, "diffusivity_m2_s",
                               check_positive("diffusivity_m2_s [m^2/s]", self.diffusivity_m2_s))
        elif needs_alpha:
            raise InputError(f"model: the {model.name} model needs the objects' diffusivity; give "
                             "diffusivity_m2_s [m^2/s] (one value for every interval)")
        if self.fidelity == "ideal" and not model.shared_shape:
            raise InputError(f"fidelity ideal needs the closed-form ideal observer, which exists only for "
                             f"shared-shape models; the {model.name} model's curves differ per object "
                             "(use fidelity svm)")

    # ----------------------------------------------------------------- derived
    @property
    def varied(self) -> bool:
        return self.sensor_temp_spread_c > 0 or self.ambient_temp_spread_c > 0

    @property
    def width(self) -> float:
        """Width of one effusivity interval [J s^-1/2 K^-1 m^-2]."""
        return (self.e_max - self.e_min) / self.intervals

    @property
    def edges(self) -> np.ndarray:
        return self.e_min + self.width * np.arange(self.intervals + 1)

    @property
    def centres(self) -> np.ndarray:
        return self.e_min + self.width * (np.arange(self.intervals) + 0.5)

    @property
    def scene_axes(self) -> list[tuple[str, tuple[float, ...]]]:
        if self.noise_ratio is not None:
            return [("noise_ratio", self.noise_ratio)]
        return [("noise_c", self.noise_c), ("delta_t_c", self.delta_t_c)]

    @property
    def scene_shape(self) -> tuple[int, ...]:
        return tuple(len(v) for _, v in self.scene_axes)

    def scene_points(self) -> list[tuple[int, ...]]:
        return [tuple(int(x) for x in idx) for idx in np.ndindex(*self.scene_shape)]

    def scene(self, point: Sequence[int], contact_s: float) -> Scene:
        """The scene at a scene-axis point (for noise_ratio: dT = 1, sigma = ratio); with ``rig_scene`` the
        sensor file's rig (the scene the exact route plays for a question about it)."""
        if self.noise_ratio is not None:
            sc = Scene(contact_s=contact_s, noise_c=self.noise_ratio[point[0]],
                       sensor_temp_c=self.ambient_temp_c + 1.0, ambient_temp_c=self.ambient_temp_c)
        else:
            sc = Scene(contact_s=contact_s, noise_c=self.noise_c[point[0]],
                       sensor_temp_c=self.ambient_temp_c + self.delta_t_c[point[1]],
                       ambient_temp_c=self.ambient_temp_c,
                       sensor_temp_spread_c=self.sensor_temp_spread_c,
                       ambient_temp_spread_c=self.ambient_temp_spread_c)
        if not self.rig_scene:
            return sc
        from ..rig import rig_scene

        return sc.replace(**rig_scene(self.resolved_sensor()))

    def resolved_sensor(self) -> Sensor:
        sensor = load_sensor(self.sensor)
        if self.sample_rate_hz is not None:
            sensor = sensor.replace(sample_rate_hz=self.sample_rate_hz)
        return sensor

    def blocks_of(self) -> list[np.ndarray]:
        return [b for b in np.array_split(np.arange(self.intervals), self.blocks) if b.size]

    def grid_class(self) -> ObjectClass:
        """The whole effusivity grid as one object class (what a model's validity checks take)."""
        alpha = self.diffusivity_m2_s
        return ObjectClass("sweep grid", (self.e_min, self.e_max), None if alpha is None else (alpha, alpha))

    def trial_diffusivity(self) -> np.ndarray | None:
        """Per-trial object diffusivity [m^2 s^-1] for models that need it, else None."""
        if self.diffusivity_m2_s is None:
            return None
        return np.full(self.trials, self.diffusivity_m2_s)

    # --------------------------------------------------------------------- I/O
    def to_dict(self) -> dict[str, Any]:
        """The config as plain JSON-ready data (``model`` as :meth:`ForwardModel.to_dict`)."""
        d: dict[str, Any] = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            d[f.name] = list(v) if isinstance(v, tuple) else v
        d["model"] = self.model.to_dict()
        return d

    def digest(self) -> str:
        """Hash of everything that determines the result (sensor file content included).

        Keys added after the first tables were built are left out at their
        defaults (the semi-infinite model, no diffusivity), so a working folder
        started before the forward-model seam still resumes.
        """
        payload = self.to_dict()
        for key, default in _DIGEST_DEFAULTS.items():
            if payload.get(key) == default:
                del payload[key]
        payload["sensor_resolved"] = self.resolved_sensor().to_dict()
        payload["sensor_resolved"].pop("provenance", None)
        text = json.dumps(payload, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()

    def changes_from(self, recorded: Any) -> list[str]:
        """Keys whose value differs from a recorded ``to_dict()`` (a working folder's), sorted.

        Keys a record from before they existed lacks count at their defaults.
        Empty with a different :meth:`digest`: the sensor file's content changed.
        """
        if not isinstance(recorded, Mapping):
            return ["config"]
        now = self.to_dict()
        return sorted(k for k in set(recorded) | set(now)
                      if recorded.get(k, _DIGEST_DEFAULTS.get(k)) != now.get(k, _DIGEST_DEFAULTS.get(k)))

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any], *, source: str = "config") -> "SweepConfig":
        if not isinstance(data, Mapping):
            raise InputError(f"{source}: a sweep config must be a mapping of keys")
        from .._schemas import schemas, validate

        known = {f.name for f in dataclasses.fields(cls)}
        # strict types first, naming the key: "intervals: expected an integer, got 'ten'"
        checked = validate(schemas()["sweep"], dict(data), source)
        data = {k: _plain(getattr(checked, k)) for k in data}
        flat = _flatten(data, source)
        unknown = sorted(set(flat) - known)
        if unknown:
            raise InputError(f"{source}: unknown key(s) {', '.join(unknown)} (known: {', '.join(sorted(known))})")
        try:
            return cls(**flat)
        except InputError as exc:
            raise InputError(f"{source}: {exc}") from None
        except (TypeError, ValueError) as exc:
            raise InputError(f"{source}: {exc}") from None

    @classmethod
    def from_yaml(cls, path: str | Path, **overrides: Any) -> "SweepConfig":
        """Read a YAML config; non-None ``overrides`` (CLI options) win over the file."""
        from .._schemas import load_yaml

        p = Path(path)
        # An empty config is refused: its defaults are the paper's 500-interval sweep (hours of work)
        data = load_yaml(p, "sweep config")
        if not isinstance(data, Mapping):
            raise InputError(f"sweep config {p} must be a mapping of keys, got {type(data).__name__}")
        if not data:
            raise InputError(f"sweep config {p} is empty (a sweep needs at least its grid and axes)")
        from .._schemas import schemas, validate

        validate(schemas()["sweep"], dict(data), f"sweep config {p}")  # before flattening: keys as written
        data = _flatten(data, f"sweep config {p}")
        if isinstance(data.get("sensor"), str) and not Path(data["sensor"]).is_absolute() \
                and data["sensor"].endswith((".yaml", ".yml")):
            data["sensor"] = str((p.parent / data["sensor"]).resolve())  # relative to the config
        data.update({k: v for k, v in overrides.items() if v is not None})
        return cls.from_mapping(data, source=f"sweep config {p}")


def _plain(value: Any) -> Any:
    """A validated schema value back as plain data (nested models as dicts)."""
    if hasattr(value, "model_dump"):
        return {k: v for k, v in value.model_dump().items() if v is not None}
    return value


def _axis(name: str, values: Any) -> tuple[float, ...] | None:
    """A sweep axis as a tuple of floats (a single number is a one-point axis; None stays None)."""
    if values is None:
        return None
    if isinstance(values, (int, float)) and not isinstance(values, bool):
        values = (values,)
    if isinstance(values, (str, bytes, bool)) or not hasattr(values, "__iter__"):
        raise InputError(f"{name}: expected a number or a list of numbers, got {values!r}")
    try:
        vals = tuple(float(x) for x in values)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected a number or a list of numbers, got {list(values)!r}") from None
    if len(vals) > MAX_AXIS_POINTS:
        raise InputError(f"sweep axis {name} has {len(vals)} points; the limit is {MAX_AXIS_POINTS}")
    if not vals:
        raise InputError(f"sweep axis {name} is empty")
    return vals


#: Config keys newer than the first tables, with the default that keeps an older digest.
_DIGEST_DEFAULTS: dict[str, Any] = {"model": {"name": "semi-infinite"}, "diffusivity_m2_s": None,
                                    "solver": "sklearn", "rig_scene": False}


def _flatten(data: Mapping[str, Any], source: str) -> dict[str, Any]:
    """Expand ``effusivity: {min, max, intervals}`` into e_min, e_max, intervals."""
    flat = dict(data)
    eff = flat.pop("effusivity", None)
    if eff is not None:
        if not isinstance(eff, Mapping):
            raise InputError(f"{source}: effusivity must be a mapping with min, max, intervals")
        extra = sorted(set(eff) - {"min", "max", "intervals"})
        if extra:
            raise InputError(f"{source}: unknown effusivity key(s) {', '.join(extra)} (min, max, intervals)")
        for k_in, k_out in (("min", "e_min"), ("max", "e_max"), ("intervals", "intervals")):
            if k_in in eff:
                if k_out in flat and flat[k_out] != eff[k_in]:
                    raise InputError(f"{source}: {k_out} given twice ({flat[k_out]} and effusivity.{k_in} = {eff[k_in]})")
                flat[k_out] = eff[k_in]
    return flat



# ------------------------------------------------------------------ chunk identity
def chunk_identity(cfg: SweepConfig, point: Sequence[int], block: int, contact_index: int) -> str:
    """The identity of one chunk slot: the sweep's :meth:`~SweepConfig.digest` and the slot's indices.

    A chunk file carries it (:func:`stamp_chunk`) and :func:`check_chunk` compares it on resume, so a
    chunk copied into another slot, or from another sweep's folder, is refused rather than trusted.
    """
    key = f"{cfg.digest()}|point={','.join(str(int(x)) for x in point)}|block={int(block)}|contact={int(contact_index)}"
    return "sha256:" + hashlib.sha256(key.encode()).hexdigest()


def stamp_chunk(arrays: Mapping[str, np.ndarray], cfg: SweepConfig, point: Sequence[int], block: int,
                contact_index: int) -> dict[str, np.ndarray]:
    """``arrays`` plus ``identity`` (a string array, readable with ``allow_pickle=False``) for the chunk file."""
    return {**arrays, "identity": np.asarray(chunk_identity(cfg, point, block, contact_index))}


def check_chunk(arrays: Mapping[str, np.ndarray], cfg: SweepConfig, point: Sequence[int], block: int,
                contact_index: int, path: str | Path = "chunk") -> None:
    """Refuse (InputError) a chunk file that is not the one of this slot of this sweep.

    The chunk's own ``point``, ``block`` and ``contact_index`` must be the slot's, and its
    ``identity`` (see :func:`stamp_chunk`) the slot's :func:`chunk_identity`. A chunk written
    before chunks carried an identity is checked on its indices only.
    """
    name = Path(path).name
    try:
        own = (tuple(int(x) for x in np.atleast_1d(arrays["point"])), int(arrays["block"]),
               int(arrays["contact_index"]))
    except (KeyError, TypeError, ValueError):
        raise InputError(f"chunk {name} lacks its point, block or contact index: delete it and resume") from None
    slot = (tuple(int(x) for x in point), int(block), int(contact_index))
    if own != slot:
        raise InputError(f"chunk {name} holds point {own[0]}, block {own[1]}, contact {own[2]} but sits in the slot of "
                         f"point {slot[0]}, block {slot[1]}, contact {slot[2]} (copied or renamed?): delete it and resume")
    if "identity" in arrays:
        ident = str(np.asarray(arrays["identity"]).reshape(()).item()) if np.asarray(arrays["identity"]).size == 1 else ""
        if ident != chunk_identity(cfg, point, block, contact_index):
            raise InputError(f"chunk {name} belongs to another sweep (its identity is not this sweep's slot): "
                             "delete it and resume")
