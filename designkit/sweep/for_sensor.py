"""The sweep a calibrated sensor's questions need: its config, derived from the sensor file.

A sensor file written by calibration (version 2) records the rig's conditions
(:mod:`designkit.rig`). :func:`sensor_sweep_config` turns them into a
:class:`~designkit.sweep.SweepConfig` whose table answers that sensor's questions as the
rig sees them (the choices and their evidence: docs/engine.md, "Tables for your sensor"):
the file's model; the effusivity span of the materials named, a range given, or the
shipped tables' (0, 40000], in classes of 80 on the shipped grid's multiples, one class
beyond each end; sigma/dT at the rig's noise and dT (:data:`NOISE_FACTORS`); the rig's
touches (``SweepConfig.rig_scene``), as the exact route plays them; and contact times
counted from the detected onset, geometric from one of the sensor's time scales
(:func:`time_scale_s`) to :data:`LONGEST_CONTACT_SCALES` of them (capped at
:data:`MAX_CONTACT_S`, at a ratio of at most :data:`CONTACT_RATIO`: the need, convex in
contact time, is not read late between two points), stored as the model counts them
(:func:`designkit.rig.to_model_contact`).

Units: effusivity [J s^-1/2 K^-1 m^-2], times [s], noise [degC].
"""

from __future__ import annotations

import math
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from .._validation import InputError
from ..objects import DEFAULT_CLASS_WIDTH
from .config import SweepConfig

__all__ = ["BuiltTable", "CONTACT_RATIO", "LONGEST_CONTACT_SCALES", "MAX_CONTACT_S", "NOISE_FACTORS", "SensorSpan",
           "build_sensor_table", "contact_grid", "effusivity_span", "rig_noise_ratio", "sensor_sweep_config",
           "time_scale_s"]

#: sigma/dT of the table's noise axis, as multiples of the rig's own (1 *is* the rig's: a question at the rig's
#: conditions lands on a grid point, not between two). The rig's alone by default: each factor costs a whole
#: build again, and a question at another noise is refused in one line (``--exact`` answers it).
NOISE_FACTORS = (1.0,)
#: The longest tabulated contact after the onset, in units of the sensor's time scale (:func:`time_scale_s`): 6 s for
#: the real rig (0.75 s), where the exact route found the paper's pairs separating at 1.2-3.1 s from the onset and
#: a few of the hardest (effusivities within 25 % above 9000) beyond (benchmarks/results/sensor_table_rig_scene.txt).
LONGEST_CONTACT_SCALES = 8.0
#: Cap of the contact axis in the model's time [s]: the exact route's longest contact (``max_contact_s``).
MAX_CONTACT_S = 10.0
#: Largest ratio between neighbouring contact times (0.75-6 s: 8 points for the rig).
CONTACT_RATIO = 1.35
#: Samples a touch has at least at the first tabulated contact (a time scale shorter than a few sample periods).
MIN_SAMPLES = 10
#: Seeds per pair at most (the search re-scores only pairs within z standard errors of Phi): 2, not the
#: paper tables' 4; each seed near the threshold is a fit where the rig's classes overlap, its costliest kind.
MAX_REPEATS = 2
#: The whole range (the shipped tables'): a table for no materials in particular [J s^-1/2 K^-1 m^-2].
WHOLE_RANGE = (0.0, 40000.0)


@dataclass(frozen=True)
class SensorSpan:
    """The effusivity span a sensor table answers, and what it was taken from.

    Attributes
    ----------
    e_min, e_max : float
        The grid's ends [J s^-1/2 K^-1 m^-2] (multiples of ``width``).
    width : float
        Class width [J s^-1/2 K^-1 m^-2].
    source : str
        ``"set paper12"``, ``"materials wood, glass"``, ``"range 300-2000"`` or ``"whole range"``.
    """

    e_min: float
    e_max: float
    width: float
    source: str

    @property
    def intervals(self) -> int:
        return int(round((self.e_max - self.e_min) / self.width))


def effusivity_span(*, material_set: str | None = None, materials: Sequence[str] = (),
                    e_range: tuple[float, float] | None = None,
                    width: float = DEFAULT_CLASS_WIDTH) -> SensorSpan:
    """The span of the materials named, a range, or the whole range, on the grid of ``width``.

    The ends are rounded outwards to multiples of ``width`` and widened by one class, so that each
    material's hardest class (one class width at the edge of its range) lies inside.

    Examples
    --------
    >>> s = effusivity_span(materials=["wood", "glass"])
    >>> s.e_min, s.e_max, s.intervals, s.source
    (240.0, 1680.0, 18, 'materials Wood, Glass')
    >>> effusivity_span().intervals
    500
    """
    from ..materials import get_material, list_materials

    given = [x for x in (material_set, materials or None, e_range) if x is not None]
    if len(given) > 1:
        raise InputError("give one of a material set, materials by name, or an effusivity range")
    if not (width > 0 and math.isfinite(width)):
        raise InputError(f"class width must be positive and finite, got {width!r}")
    if material_set is not None:
        try:
            mats = list_materials(set=material_set)
        except (InputError, KeyError, ValueError):
            from ..materials import SETS

            raise InputError(f"unknown material set {material_set!r}; known: {', '.join(SETS)}") from None
        lo, hi, source = min(m.e_min for m in mats), max(m.e_max for m in mats), f"set {material_set}"
    elif materials:
        mats = [get_material(m) for m in materials]
        lo, hi = min(m.e_min for m in mats), max(m.e_max for m in mats)
        source = "materials " + ", ".join(dict.fromkeys(m.name for m in mats))
    elif e_range is not None:
        lo, hi = (float(x) for x in e_range)
        if not (0 <= lo < hi and math.isfinite(hi)):
            raise InputError(f"effusivity range must satisfy 0 <= LO < HI (finite), got {lo:g} {hi:g}")
        source = f"range {lo:g}-{hi:g}"
    else:
        return SensorSpan(*WHOLE_RANGE, float(width), "whole range")
    e_min = max(0.0, (math.floor(lo / width) - 1) * width)
    e_max = (math.ceil(hi / width) + 1) * width
    return SensorSpan(float(e_min), float(e_max), float(width), source)


def rig_noise_ratio(sensor) -> float:
    """sigma/dT of the rig as calibrated: the sensor file's noise over its mean dT [1].

    The same arithmetic as a question's scene (:func:`designkit.rig.resolve_scene` takes the same two
    values), so that a question at the rig's conditions lands on the grid point exactly.
    """
    cond = getattr(sensor, "conditions", None) or {}
    noise = cond.get("noise_c")
    dt = (cond.get("delta_t_c") or {}).get("mean")
    if noise is None or dt is None or not (math.isfinite(float(noise)) and math.isfinite(float(dt))) \
            or float(dt) == 0 or float(noise) <= 0:
        raise InputError(f"sensor {sensor.name}: the file records no usable noise and dT of the rig "
                         f"(noise {noise!r}, dT {dt!r}); recalibrate it with 'designkit calibrate fit'")
    return float(noise) / abs(float(dt))


def time_scale_s(sensor) -> float:
    """The sensor's own time scale [s]: the longest of the contact ramp's rise (from the onset until the force
    reaches 90 % of its plateau), the correlation length of the rig's noise and the thermistor's tau.

    Examples
    --------
    >>> from designkit.sensor import load_sensor
    >>> round(time_scale_s(load_sensor("tests/data/rig_sensor.yaml")), 4)   # the real rig's ramp
    0.7525
    """
    cond = getattr(sensor, "conditions", None) or {}
    ramp = cond.get("contact_ramp") or {}
    return max(float(ramp.get("rise_s") or 0.0), float(cond.get("noise_correlation_s") or 0.0), float(sensor.tau_s))


def contact_grid(sensor, points: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Contact times from the rig's detected onset, and the same as the model counts them [s].

    Geometric from one time scale (:func:`time_scale_s`, at least :data:`MIN_SAMPLES` sample periods, and after
    the model's first heat flow) to :data:`LONGEST_CONTACT_SCALES` of them, capped at :data:`MAX_CONTACT_S` in
    the model's time; ``points`` (default: the fewest at a ratio of at most :data:`CONTACT_RATIO`). Rounded to
    1 ms (onset times).
    """
    from ..rig import model_start_s, to_model_contact

    scale = time_scale_s(sensor)
    start = model_start_s(sensor)
    first = max(scale, MIN_SAMPLES / float(sensor.sample_rate_hz))
    if start is not None and start > 0:  # the model's heat flow begins after the onset: tabulate from there on
        first = max(first, start + MIN_SAMPLES / float(sensor.sample_rate_hz))
    cap = MAX_CONTACT_S - max(-(start or 0.0), 0.0) if start is not None and start < 0 else MAX_CONTACT_S
    last = max(min(LONGEST_CONTACT_SCALES * scale, cap), 2 * first)
    if points is None:
        points = int(math.ceil(math.log(last / first) / math.log(CONTACT_RATIO) - 1e-9)) + 1
    if int(points) != points or points < 2:
        raise InputError(f"contact points must be an integer >= 2, got {points!r}")
    onset = np.round(np.geomspace(first, last, int(points)), 3)
    model = np.array([to_model_contact(float(c), start) for c in onset])
    return onset, model


def sensor_sweep_config(sensor_file: str, *, span: SensorSpan | None = None, name: str | None = None,
                        noise_factors: Sequence[float] = NOISE_FACTORS, contact_points: int | None = None,
                        trials: int = 100, seed: int = 0, max_repeats: int = MAX_REPEATS) -> SweepConfig:
    """The sweep config of the table that answers a calibrated sensor's questions (module docstring).

    Parameters
    ----------
    sensor_file : str
        A sensor YAML file written by calibration, with the rig's conditions (version 2).
    span : SensorSpan, optional
        Effusivity span (default: the whole range, :func:`effusivity_span`).
    name : str, optional
        Table name (default ``sensor-NAME``).
    noise_factors : sequence of float
        sigma/dT of the noise axis as multiples of the rig's own (1 must be one of them).
    contact_points : int, optional
        Contact times tabulated (default: :func:`contact_grid`'s, from the sensor's time scale).
    trials, seed, max_repeats : int
        The classifier protocol (the paper's: 100 trials per interval, 3 folds) and its Monte Carlo.

    Raises
    ------
    InputError
        A sensor without the rig's conditions (a preset, or a file from an older designkit).
    """
    from ..sensor import SENSORS, load_sensor

    if str(sensor_file) in SENSORS:
        raise InputError(f"sensor {sensor_file!r} is a preset: the shipped tables answer for it; a sensor "
                         "table is for a sensor file written by 'designkit calibrate fit'")
    sensor = load_sensor(str(sensor_file))
    if not getattr(sensor, "conditions", None):
        raise InputError(f"sensor file {sensor_file} records no rig conditions (written by an older designkit, or "
                         "by hand): recalibrate it with 'designkit calibrate fit' to record them, or build a table "
                         "at conditions of your choice with 'designkit sweep --sensor FILE ...'")
    factors = tuple(sorted(float(f) for f in noise_factors))
    if 1.0 not in factors or any(not (f > 0 and math.isfinite(f)) for f in factors):
        raise InputError(f"noise factors must be positive and include 1 (the rig's own), got {list(noise_factors)}")
    span = span or effusivity_span()
    r0 = rig_noise_ratio(sensor)
    _, model_contacts = contact_grid(sensor, contact_points)
    if np.any(model_contacts <= 0):
        raise InputError(f"sensor {sensor.name}: its contact grid starts before the model's first heat flow")
    return SweepConfig(name=name or f"sensor-{_slug(sensor.name)}", sensor=str(sensor_file), e_min=span.e_min,
                       e_max=span.e_max, intervals=span.intervals, trials=trials, seed=seed,
                       max_repeats=max_repeats, noise_ratio=tuple(r0 * f for f in factors),
                       contact_s=tuple(float(c) for c in model_contacts), rig_scene=True)


def _slug(text: str) -> str:
    import re

    s = re.sub(r"[^A-Za-z0-9._-]+", "-", str(text)).strip("-.")
    return s[:60] or "sensor"


@dataclass(frozen=True)
class BuiltTable:
    """What :func:`build_sensor_table` made: the table's path, its registry entry and what it holds.

    Attributes
    ----------
    table, entry : Path
        The table's .npz (its .json beside it) and its registry entry.
    sensor_name, sensor_digest, content_hash : str
    contacts_from_onset_s : tuple of float
        The tabulated contact times, counted from the rig's detected onset [s].
    config : SweepConfig
    """

    table: Path
    entry: Path
    sensor_name: str
    sensor_digest: str
    content_hash: str
    contacts_from_onset_s: tuple[float, ...]
    config: Any

    def to_dict(self) -> dict[str, Any]:
        return {"table": str(self.table), "header": str(self.table.with_suffix(".json")),
                "registry_entry": str(self.entry), "sensor": {"name": self.sensor_name, "digest": self.sensor_digest},
                "content_hash": self.content_hash, "contacts_from_onset_s": list(self.contacts_from_onset_s),
                "config": self.config.to_dict()}


def build_sensor_table(cfg, *, out: str | Path | None = None, jobs: int = -1, on_chunk=None) -> BuiltTable:
    """Sweep ``cfg`` (:func:`designkit.sweep.for_sensor.sensor_sweep_config`) and register its table for the sensor.

    The chunks are kept in a working folder named by the config's digest beside the registry entry, so an
    interrupted build continues where it stopped when run again; it is removed once the table is registered.
    ``out``: the table's .npz (default: in the registry folder, :func:`default_table_dir`).
    """
    import shutil

    from ..rig import from_model_contact, model_start_s
    from ..tables.registry import default_table_dir, register_table, sensor_digest
    from .run import run_sweep

    sensor = cfg.resolved_sensor()
    home = default_table_dir(sensor)
    work = home / f"work-{cfg.digest()[:16]}"
    path = Path(out) if out is not None else home / f"{cfg.name}.npz"
    table = run_sweep(cfg, work, out=path, jobs=jobs, resume=True, on_chunk=on_chunk)
    entry = register_table(sensor, table, sensor_file=cfg.sensor)
    shutil.rmtree(work, ignore_errors=True)
    start = model_start_s(sensor)
    return BuiltTable(Path(table), entry, sensor.name, sensor_digest(sensor),
                      json.loads(entry.read_text())["content_hash"],
                      tuple(round(float(from_model_contact(c, start)), 6) for c in cfg.contact_s), cfg)
