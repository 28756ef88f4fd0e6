"""Lookup tables on disk: one documented format, loaded without pickle.

A table ``NAME`` is two files side by side:

``NAME.npz``
    numpy arrays (``np.savez``, no object arrays; read with ``allow_pickle=False``).
``NAME.json``
    the header: ``format`` ("designkit-table"), ``schema_version``, ``name``,
    ``fidelity`` ("svm" or "ideal"), ``sensor`` (the sensor's parameters),
    ``effusivity`` (grid: ``min``, ``max``, ``intervals``, ``width``, units),
    ``axes`` (name, units, values, scale; in array order), ``arrays`` (for each
    array: shape, dtype, units, meaning), ``threshold``, ``trials``, ``folds``,
    ``seed``, ``max_repeats``, ``z``, ``designkit_version``, ``created``,
    ``config`` (the full sweep config, to rebuild it), ``stats`` (SVM fits and
    compute time per scene), and ``content_hash``: SHA-256 over every array's
    name, dtype, shape and bytes in name order. The hash is verified on load;
    a corrupted or truncated table is refused.

Arrays (shape ``[scene axes..., contact, effusivity]``; effusivity units
J s^-1/2 K^-1 m^-2; NaN where no distinguishable partner lies inside the grid):

``delta_up``, ``delta_down``
    delta(e) towards higher / lower effusivity.
``delta_up_lo``, ``delta_up_hi``, ``delta_down_lo``, ``delta_down_hi``
    Monte Carlo interval of delta (SVM tables; an ideal table is exact).
``delta_up_ideal``, ``delta_down_ideal``
    The ideal observer's delta on the same grid (SVM tables).
``fits``, ``chunk_wall_s``
    SVM fits and compute seconds per (scene point, contact).
``f1_matrix`` (optional)
    Full F1 matrices, ``[scene..., contact, n, n]``.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import io
import json
import math
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from .._validation import InputError

__all__ = [
    "SCHEMA_VERSION",
    "Table",
    "content_hash",
    "list_tables",
    "load_table",
    "resolve_table",
    "table_header",
    "write_table",
]

SCHEMA_VERSION = 1
FORMAT = "designkit-table"
E_UNITS = "J s^-1/2 K^-1 m^-2"

_ARRAY_DOCS = {
    "delta_up": (E_UNITS, "smallest distinguishable difference towards higher effusivity"),
    "delta_down": (E_UNITS, "smallest distinguishable difference towards lower effusivity"),
    "delta_up_lo": (E_UNITS, "lower end of the Monte Carlo interval of delta_up"),
    "delta_up_hi": (E_UNITS, "upper end of the Monte Carlo interval of delta_up (NaN: not confidently reached in the grid)"),
    "delta_down_lo": (E_UNITS, "lower end of the Monte Carlo interval of delta_down"),
    "delta_down_hi": (E_UNITS, "upper end of the Monte Carlo interval of delta_down"),
    "delta_up_ideal": (E_UNITS, "ideal observer's delta towards higher effusivity"),
    "delta_down_ideal": (E_UNITS, "ideal observer's delta towards lower effusivity"),
    "fits": ("1", "SVM fits (including repeats) per scene point and contact"),
    "chunk_wall_s": ("s", "compute time per scene point and contact, summed over chunks"),
    "f1_matrix": ("1", "F1 of every pair of intervals"),
}

_AXIS_DOCS = {
    "noise_ratio": ("1 (sigma / dT)", "log", "noise sigma over sensor-object temperature difference"),
    "noise_c": ("degC", "log", "noise sigma per sample"),
    "delta_t_c": ("degC", "linear", "sensor minus object temperature before contact"),
    "contact_s": ("s", "linear", "contact time"),
    "e_ref": (E_UNITS, "linear", "reference interval centre"),
}


def content_hash(arrays: Mapping[str, np.ndarray]) -> str:
    """SHA-256 over every array's name, dtype, shape and C-order bytes, in name order."""
    h = hashlib.sha256()
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(name.encode())
        h.update(a.dtype.str.encode())
        h.update(repr(tuple(a.shape)).encode())
        h.update(a.tobytes())
    return "sha256:" + h.hexdigest()


def table_header(cfg, arrays: Mapping[str, np.ndarray], *, run: Mapping[str, Any] | None = None) -> dict:
    """The JSON header of a table built from sweep config ``cfg``."""
    from .. import __version__

    sensor = cfg.resolved_sensor()
    axes = []
    for name, values in cfg.scene_axes + [("contact_s", cfg.contact_s)]:
        units, scale, meaning = _AXIS_DOCS[name]
        axes.append({"name": name, "units": units, "scale": scale, "meaning": meaning,
                     "values": [float(v) for v in values]})
    units, scale, meaning = _AXIS_DOCS["e_ref"]
    axes.append({"name": "e_ref", "units": units, "scale": scale, "meaning": meaning,
                 "values": [float(v) for v in cfg.centres]})
    fits = np.asarray(arrays.get("fits", 0))
    wall = np.asarray(arrays.get("chunk_wall_s", 0.0))
    return {
        "format": FORMAT,
        "schema_version": SCHEMA_VERSION,
        "name": cfg.name,
        "fidelity": cfg.fidelity,
        "sensor": sensor.to_dict(),
        "model": _model_of(cfg).to_dict(),
        "effusivity": {"min": cfg.e_min, "max": cfg.e_max, "intervals": cfg.intervals,
                       "width": cfg.width, "units": E_UNITS},
        "fixed_initial_conditions": not cfg.varied,
        "axes": axes,
        "arrays": {name: {"shape": list(np.shape(a)), "dtype": str(np.asarray(a).dtype),
                          "units": _ARRAY_DOCS.get(name, ("", ""))[0],
                          "meaning": _ARRAY_DOCS.get(name, ("", ""))[1]}
                   for name, a in sorted(arrays.items())},
        "threshold": cfg.threshold,
        "trials": cfg.trials,
        "folds": cfg.folds,
        "seed": cfg.seed,
        "max_repeats": cfg.max_repeats,
        "z": cfg.z,
        "designkit_version": __version__,
        "created": _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat(),
        "config": cfg.to_dict(),
        "stats": {
            "svm_fits_total": int(fits.sum()),
            "svm_fits_per_scene_mean": float(fits.mean()) if fits.size else 0.0,
            "compute_s_total": float(wall.sum()),
            "compute_s_per_scene_mean": float(wall.mean()) if wall.size else 0.0,
            **({"run": dict(run)} if run else {}),
        },
    }


def _model_of(cfg):
    """The forward model a sweep config names (configs from before the seam: the semi-infinite model)."""
    from ..models import get_model

    return get_model(getattr(cfg, "model", None))


def write_table(path: str | Path, header: dict, arrays: Mapping[str, np.ndarray]) -> Path:
    """Write ``path`` (.npz) and its .json header atomically; returns the .npz path.

    The arrays are written first, the header (with the content hash) last, so
    a crash leaves either the old table or a header-less npz that loading
    refuses.
    """
    from .._io import atomic_write_bytes, atomic_write_text

    path = Path(path)
    if path.suffix != ".npz":
        path = path.with_suffix(".npz")
    arrays = {k: np.ascontiguousarray(v) for k, v in arrays.items()}
    for name, a in arrays.items():
        if a.dtype == object:
            raise InputError(f"table array {name} has dtype object; tables hold numbers only")
    header = dict(header)
    header["content_hash"] = content_hash(arrays)
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    atomic_write_bytes(path, buf.getvalue())
    atomic_write_text(path.with_suffix(".json"), json.dumps(header, indent=1, allow_nan=False) + "\n")
    return path


@dataclass(frozen=True)
class Table:
    """A loaded lookup table: header plus arrays, verified."""

    name: str
    path: Path
    header: dict
    arrays: dict

    @property
    def fidelity(self) -> str:
        return self.header["fidelity"]

    @property
    def threshold(self) -> float:
        return float(self.header["threshold"])

    @property
    def axes(self) -> dict[str, np.ndarray]:
        return {a["name"]: np.asarray(a["values"], dtype=np.float64) for a in self.header["axes"]}

    @property
    def axis_names(self) -> list[str]:
        return [a["name"] for a in self.header["axes"]]

    @property
    def sensor(self):
        from ..sensor import Sensor

        return Sensor.from_dict(self.header["sensor"], source=f"table {self.name}")

    @property
    def fixed_initial_conditions(self) -> bool:
        return bool(self.header.get("fixed_initial_conditions", True))

    @property
    def model(self):
        """The forward model the table was built with (tables from before the header recorded it:
        the paper's semi-infinite model, the only one there was)."""
        from ..models import get_model

        return get_model(self.header.get("model"))

    def summary(self) -> dict[str, Any]:
        """What `designkit tables show` prints."""
        h = self.header
        return {
            "name": self.name,
            "path": str(self.path),
            "fidelity": h["fidelity"],
            "sensor": h["sensor"],
            "model": self.model.to_dict(),
            "effusivity": h["effusivity"],
            "axes": [{k: a[k] for k in ("name", "units", "scale")} | {
                "min": min(a["values"]), "max": max(a["values"]), "points": len(a["values"]),
                **({"values": a["values"]} if len(a["values"]) <= 40 else {})} for a in h["axes"]],
            "arrays": sorted(h["arrays"]),
            "threshold": h["threshold"],
            "trials": h["trials"],
            "folds": h["folds"],
            "seed": h["seed"],
            "designkit_version": h["designkit_version"],
            "created": h["created"],
            "content_hash": h["content_hash"],
            "stats": h.get("stats", {}),
            "size_bytes": self.path.stat().st_size + self.path.with_suffix(".json").stat().st_size,
        }


def list_tables(folder: Path | None = None) -> list[str]:
    """Names of the tables in ``folder`` (default: the shipped tables)."""
    from .._resources import shipped_tables_dir

    folder = shipped_tables_dir() if folder is None else Path(folder)
    return sorted(p.stem for p in folder.glob("*.json")
                  if p.with_suffix(".npz").is_file() and _looks_like_table(p))


def _looks_like_table(p: Path) -> bool:
    try:
        with p.open() as fh:
            return FORMAT in fh.read(200)
    except OSError:
        return False


def resolve_table(name_or_path: str | Path) -> Path:
    """The .npz path of a shipped table name or of a path (with or without suffix)."""
    from .._resources import shipped_tables_dir

    s = str(name_or_path)
    p = Path(s)
    candidates = [p, p.with_suffix(".npz")] if p.suffix in ("", ".json", ".npz") else [p]
    if p.suffix == "" and "/" not in s:
        candidates.insert(0, shipped_tables_dir() / f"{s}.npz")
    for c in candidates:
        c = c.with_suffix(".npz") if c.suffix == ".json" else c
        if c.is_file() and c.with_suffix(".json").is_file():
            return c
    shipped = ", ".join(list_tables()) or "none"
    raise InputError(f"no table {s!r} (shipped tables: {shipped}; or give a path to a .npz with its .json)")


def _read_header(path: Path) -> dict:
    jpath = path.with_suffix(".json")
    try:
        header = json.loads(jpath.read_text())
    except OSError as exc:
        raise InputError(f"cannot read table header {jpath}: {exc.strerror or exc}") from None
    except ValueError:
        raise InputError(f"table header {jpath} is not valid JSON (corrupted or truncated)") from None
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise InputError(f"{jpath} is not a designkit table header")
    version = header.get("schema_version")
    if version != SCHEMA_VERSION:
        raise InputError(f"table {path.stem} has schema version {version}; this designkit reads "
                         f"version {SCHEMA_VERSION} (rebuild it with designkit sweep)")
    return header


def load_table(name_or_path: str | Path, *, verify: bool = True) -> Table:
    """Load and verify a table (shipped name or path)."""
    path = resolve_table(name_or_path)
    header = _read_header(path)
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (zipfile.BadZipFile, ValueError, OSError, EOFError, KeyError) as exc:
        raise InputError(f"table {path.name} is corrupted or truncated ({type(exc).__name__}); "
                         f"rebuild it with designkit sweep") from None
    if verify:
        got = content_hash(arrays)
        if got != header.get("content_hash"):
            raise InputError(f"table {path.name} failed its content check (hash mismatch): corrupted or edited; "
                             f"rebuild it with designkit sweep")
    for name, spec in header.get("arrays", {}).items():
        if name not in arrays or list(arrays[name].shape) != spec["shape"]:
            raise InputError(f"table {path.name}: array {name} missing or of the wrong shape")
    return Table(name=header.get("name", path.stem), path=path, header=header, arrays=arrays)


def finite_or_none(x: float) -> float | None:
    """JSON-friendly float."""
    return None if x is None or not math.isfinite(x) else float(x)
