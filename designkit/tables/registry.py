"""Tables for your sensor: build the table a calibrated sensor's questions need, register it, find it.

``designkit tables build --sensor rig.yaml`` sweeps the config :func:`designkit.sweep.for_sensor.sensor_sweep_config`
derives from the sensor file (:func:`designkit.sweep.for_sensor.build_sensor_table`) and registers the table for that sensor; later questions about the sensor
(``designkit min-contact --sensor rig.yaml ...``) call :func:`table_for_sensor` and answer from it in
milliseconds instead of computing each answer (tens of seconds).

Where. Tables are registered in the user's data folder (:func:`registry_dir`:
``platformdirs.user_data_dir("designkit")/sensor-tables``, e.g. ``~/.local/share/designkit/sensor-tables``
on Linux; ``$DESIGNKIT_DATA_DIR/sensor-tables`` when that variable is set), one entry per sensor:
``<digest>.json`` names the table's files (by default in the folder ``<digest>/`` beside it, or wherever
``--out`` put them) and its content hash.

Keyed by the sensor's content. :func:`sensor_digest` hashes everything the sensor file says but its
provenance (the calibration's report, which changes no answer): its parameters, its model and the rig's
conditions. A sensor file edited, or recalibrated, has another digest, so it never answers from the table
of the sensor it was; the same sensor copied elsewhere or renamed on disk finds its table.

Checks. The table found is loaded like any table (content hash, schema, consistency) and must have been
built for a sensor of the same digest; anything else is refused in one line (:class:`~designkit._validation.InputError`),
never used, never silently passed over.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any, Mapping

from cachetools import LRUCache

from .. import __version__
from .._resources import DATA_DIR_VARIABLE, data_dir
from .._validation import InputError
from ..materials import remember_shipped_table
from ..sensor import remember_checked_file

__all__ = ["DATA_DIR_VARIABLE", "default_table_dir", "entry_path", "register_table", "registry_dir", "sensor_digest",
           "table_for_sensor"]

_ENTRY_FORMAT = "designkit-sensor-table"


def registry_dir() -> Path:
    """The folder of the sensor-table registry: ``$DESIGNKIT_DATA_DIR/sensor-tables`` or the user's data folder's."""
    return data_dir() / "sensor-tables"


def sensor_digest(sensor) -> str:
    """SHA-256 of a sensor's content but its provenance: ``"sha256:..."``.

    Examples
    --------
    >>> from designkit import SENSORS
    >>> a = sensor_digest(SENSORS["paper"])
    >>> a == sensor_digest(SENSORS["paper"].replace(provenance={"note": "no answer changes"}))
    True
    >>> a == sensor_digest(SENSORS["paper"].replace(noise_c=0.01))
    False
    """
    import weakref

    from ..sensor import load_sensor

    sen = load_sensor(sensor)
    hit = _DIGESTS.get(id(sen))
    if hit is not None and hit[0]() is sen:  # the same (frozen) sensor: a calibrated file's is thousands of values
        return hit[1]
    digest = _content_digest(sen.to_dict())
    _DIGESTS[id(sen)] = (weakref.ref(sen), digest)
    return digest


#: :func:`sensor_digest` per sensor object alive in this process (load_sensor gives one object per file content).
_DIGESTS: "LRUCache[int, tuple]" = LRUCache(16)


def _content_digest(record: Mapping[str, Any]) -> str:
    """:func:`sensor_digest` of a sensor's plain-data form (a sensor file's, or a table header's ``sensor``)."""
    d = {k: v for k, v in record.items() if k != "provenance"}
    text = json.dumps(d, sort_keys=True, separators=(",", ":"), allow_nan=False, default=str)
    return "sha256:" + hashlib.sha256(text.encode()).hexdigest()


def _key(digest: str) -> str:
    return digest.split(":", 1)[-1][:32]


def entry_path(sensor) -> Path:
    """The registry entry of ``sensor`` (it may not exist)."""
    return registry_dir() / f"{_key(sensor_digest(sensor))}.json"


def default_table_dir(sensor) -> Path:
    """Where ``tables build`` puts a sensor's table without ``--out``."""
    return registry_dir() / _key(sensor_digest(sensor))


def register_table(sensor, table_path: str | Path, *, sensor_file: str | None = None) -> Path:
    """Register the table at ``table_path`` for ``sensor`` (replacing an earlier one); returns the entry's path.

    The entry: ``sensor_digest``, ``sensor_name``, ``sensor_file`` (where it was built from), ``table`` (the
    .npz's absolute path), ``content_hash`` (the table's, checked when it is used) and ``registered`` (UTC).

    The table must have been built for this sensor (same :func:`sensor_digest`): checked here, before
    anything is written.
    """
    import datetime as _dt

    from .._io import atomic_write_text
    from .store import load_table

    digest = sensor_digest(sensor)
    table = load_table(table_path)
    _check_built_for(table, digest, getattr(sensor, "name", "?"))
    entry = {"format": _ENTRY_FORMAT, "sensor_digest": digest, "sensor_name": getattr(sensor, "name", None),
             "sensor_file": None if sensor_file is None else str(Path(sensor_file).resolve()),
             "table": str(Path(table.path).resolve()), "content_hash": table.header["content_hash"],
             "checked_by": __version__,
             "registered": _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat()}
    path = registry_dir() / f"{_key(digest)}.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, json.dumps(entry, indent=1) + "\n")
    if sensor_file is not None:  # later questions about it read the sensor file and the materials without YAML
        remember_checked_file(sensor_file, sensor)  # or the schema (their import and parse: about 0.3 s)
        remember_shipped_table()
    return path


def table_for_sensor(sensor):
    """The table registered for ``sensor`` (a :class:`~designkit.tables.store.Table`), or None.

    None: no table is registered for this sensor's content (a preset, a file from an older designkit, a
    sensor nobody built a table for, or one edited since). A registered table whose files are missing,
    damaged, edited or built for another sensor is refused (:class:`~designkit._validation.InputError`,
    one line saying what to do), never used and never silently skipped.

    The library's route policy calls it for a question about a sensor file (:func:`designkit.query.policy.
    table_for`); a table found answers the question (:mod:`designkit.query.table`), else it is computed (the
    exact route). Found once per process while its files are unchanged.
    """
    from ..sensor import load_sensor

    sensor = load_sensor(sensor)
    if not getattr(sensor, "conditions", None):  # presets and older files: no rig conditions, no sensor table
        return None
    digest = sensor_digest(sensor)
    path = registry_dir() / f"{_key(digest)}.json"
    try:
        raw = path.read_text()
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise InputError(f"sensor table registry entry {path} cannot be read ({exc.strerror}): delete it, or rebuild "
                         f"with 'designkit tables build --sensor FILE'") from None
    entry = _entry(raw, path)
    if entry.get("sensor_digest") != digest:
        raise InputError(f"sensor table registry entry {path} is for another sensor: delete it, or rebuild with "
                         "'designkit tables build --sensor FILE'")
    npz = Path(entry["table"])
    try:
        key = (digest, raw, *((st.st_mtime_ns, st.st_size) for st in (npz.stat(), npz.with_suffix(".json").stat())))
    except OSError:
        raise InputError(f"the table registered for sensor {sensor.name} ({npz}) is missing: rebuild it with "
                         "'designkit tables build --sensor FILE', or ask with --exact") from None
    if key in _FOUND:  # found and checked by this process, its files unchanged since
        return _FOUND[key]
    from .store import load_table

    # its content was checked in full when this designkit registered it: that content skips the schema's check
    table = load_table(npz, checked_hash=entry.get("content_hash") if entry.get("checked_by") == __version__ else None)
    if table.header.get("content_hash") != entry.get("content_hash"):
        raise InputError(f"the table registered for sensor {sensor.name} ({npz}) was replaced since it was "
                         "registered: rebuild it with 'designkit tables build --sensor FILE', or ask with --exact")
    _check_built_for(table, digest, sensor.name)
    _FOUND[key] = table
    return table


#: Tables found by :func:`table_for_sensor` in this process, keyed by the sensor's digest, its registry entry and
#: the table's files' modification times and sizes (a question reads and hashes the table once, not every time).
_FOUND: "LRUCache[tuple, Any]" = LRUCache(8)


def _entry(raw: str, path: Path) -> Mapping[str, Any]:
    try:
        entry = json.loads(raw)
    except ValueError:
        entry = None
    if not isinstance(entry, dict) or entry.get("format") != _ENTRY_FORMAT or not isinstance(entry.get("table"), str):
        raise InputError(f"sensor table registry entry {path} is damaged: delete it, or rebuild with "
                         "'designkit tables build --sensor FILE'")
    return entry


def _check_built_for(table, digest: str, name: str) -> None:
    """Refuse a table whose header's sensor is not the sensor of ``digest``."""
    if _content_digest(table.header["sensor"]) != digest:
        raise InputError(f"table {table.name} was built for sensor {table.sensor.name!r} as it was then "
                         f"(another content), not for sensor {name!r} as it is now: rebuild it with "
                         "'designkit tables build --sensor FILE'")
