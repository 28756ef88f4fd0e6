"""The one validation layer for designkit's file formats.

Every file designkit reads (a sensor YAML, a sweep config, a device profile, a
table header, a trial sidecar) goes through here:

* :func:`read_text` refuses what is not a regular file *before* opening it (a
  FIFO would block the read forever, ``/dev/null`` reads as empty, a folder
  raises IsADirectoryError) and decodes UTF-8 naming the file and the line.
* :func:`load_yaml` / :func:`load_json` parse it with one-line errors.
* :func:`validate` checks the data against a strict pydantic schema and turns
  the first problem into one line: ``FILE: KEY: expected ..., got ...``.

Types are strict: a number is an int or float (YAML 1.1 writes ``1e9`` as a
string, so a string that is a float literal is read as that number; ``"ten"``
is refused), an integer is an integral number, a boolean is ``true``/``false``
(never the string ``"no"``), text is a string (never a list). Domain checks
(positive, finite, ranges) stay with the objects the data builds.

pydantic is imported on first use, not with designkit.
"""

from __future__ import annotations

import functools

import math
import numbers
import os
import re
import stat
from pathlib import Path
from typing import Any, Mapping

from ._validation import InputError

__all__ = ["MAX_FILE_BYTES", "check_regular_file", "load_json", "load_yaml", "read_text", "recorded", "record_checked",
           "schemas", "validate"]

#: The largest text file designkit parses (headers, configs, profiles, sidecars are kilobytes).
MAX_FILE_BYTES = 64 * 1024 * 1024

_FLOAT_LITERAL = re.compile(r"^[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?$")


def check_regular_file(path: str | Path, what: str) -> Path:
    """``path`` as a Path if it is an existing regular file (symlinks followed), else InputError.

    Checked with ``stat`` before anything opens it: opening a FIFO for reading blocks until a
    writer appears, and a device or folder is never a designkit file.
    """
    p = Path(path)
    if str(path) == "":
        raise InputError(f"{what}: the path is empty")
    try:
        st = os.stat(p)
    except FileNotFoundError:
        raise InputError(f"cannot read {what} {p}: no such file") from None
    except OSError as exc:
        raise InputError(f"cannot read {what} {p}: {exc.strerror or exc}") from None
    if not stat.S_ISREG(st.st_mode):
        kind = ("a folder" if stat.S_ISDIR(st.st_mode) else "a FIFO (named pipe)" if stat.S_ISFIFO(st.st_mode)
                else "a device" if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode)
                else "a socket" if stat.S_ISSOCK(st.st_mode) else "not a regular file")
        raise InputError(f"{what} {p} is {kind}, not a regular file")
    if st.st_size > MAX_FILE_BYTES:
        raise InputError(f"{what} {p} is {st.st_size} bytes; the limit for a {what} is {MAX_FILE_BYTES} bytes")
    return p


def read_text(path: str | Path, what: str) -> str:
    """The UTF-8 text (a byte-order mark allowed) of the regular file ``path``; InputError naming it otherwise."""
    p = check_regular_file(path, what)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read {what} {p}: {exc.strerror or exc}") from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise InputError(f"{what} {p} is not UTF-8 text (byte 0x{data[exc.start]:02x} on line {line})") from None


def load_yaml(path: str | Path, what: str, *, empty_ok: bool = False) -> Any:
    """Parse the YAML file ``path`` (safe loader); an empty file is refused unless ``empty_ok``."""
    import yaml

    text = read_text(path, what)
    try:
        data = yaml.load(text, Loader=_unique_key_loader())  # a SafeLoader that refuses a key given twice
    except _DuplicateKey as exc:
        raise InputError(f"{what} {path} gives the key {exc.key!r} twice (line {exc.line}): the last would win "
                         f"unnoticed; keep one") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" (line {mark.line + 1})" if mark is not None else ""
        raise InputError(f"{what} {path} is not valid YAML{where}") from None
    except RecursionError:
        raise InputError(f"{what} {path} is nested too deeply") from None
    if data is None and not empty_ok:
        raise InputError(f"{what} {path} is empty")
    return data


# ------------------------------------------------------------------- checked files, recorded
#: The format of a record :func:`record_checked` writes.
_RECORD_FORMAT = "designkit-checked-file"


def _record_path(kind: str, sha256: str) -> Path:
    from ._resources import data_dir

    return data_dir() / "checked-files" / f"{kind}-{sha256[:32]}.json"


def record_checked(kind: str, content: bytes, data: Any) -> None:
    """Record in designkit's data folder that a file of ``kind`` with exactly ``content`` reads, checked, as the
    plain data ``data`` (JSON: numbers, strings, lists, mappings), so that a later process reads the record
    (:func:`recorded`) instead of parsing the file through YAML and its schema: what a question from a fresh
    shell about a registered sensor pays otherwise (pydantic's import and first model build, the YAML of a
    calibrated file's thousands of numbers: about 0.3 s). ``designkit tables build --sensor FILE`` records
    the sensor file and the shipped materials when it registers the table. A record that cannot be written
    (a read-only data folder) is left out: the files are then read the long way."""
    import hashlib
    import json

    from . import __version__
    from ._io import atomic_write_text

    sha = hashlib.sha256(content).hexdigest()
    try:
        text = json.dumps({"format": _RECORD_FORMAT, "kind": kind, "designkit_version": __version__, "sha256": sha,
                           "data": data}, allow_nan=False)
        if json.loads(text)["data"] != data:  # (a type JSON does not keep: not recorded)
            return
        out = _record_path(kind, sha)
        out.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(out, text + "\n")
    except (OSError, ValueError, TypeError):
        return


def recorded(kind: str, content: bytes) -> Any | None:
    """The data :func:`record_checked` recorded for a file of ``kind`` with exactly ``content``, by this designkit
    (another version's record is not read); None where there is none (the file is then read the long way,
    which says what is wrong with it, if anything)."""
    import hashlib
    import json

    from . import __version__

    sha = hashlib.sha256(content).hexdigest()
    try:
        rec = json.loads(_record_path(kind, sha).read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(rec, dict) or (rec.get("format"), rec.get("kind"), rec.get("designkit_version"),
                                     rec.get("sha256")) != (_RECORD_FORMAT, kind, __version__, sha):
        return None
    return rec.get("data")


class _DuplicateKey(ValueError):
    def __init__(self, key: Any, line: int):
        super().__init__(f"duplicate key {key!r}")
        self.key, self.line = key, line


@functools.lru_cache(maxsize=1)
def _unique_key_loader():
    """yaml's safe loader (libyaml's where present: 10x faster), refusing a mapping that gives one key twice
    (PyYAML keeps the last, silently). The one YAML loader of designkit's inputs."""
    import yaml

    class UniqueKeySafeLoader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
        def construct_mapping(self, node, deep=False):
            if isinstance(node, yaml.MappingNode):
                seen = set()
                for key_node, _ in node.value:
                    if key_node.tag == "tag:yaml.org,2002:merge":
                        continue
                    key = self.construct_object(key_node, deep=True)
                    try:
                        new = key not in seen
                    except TypeError:  # an unhashable key: the SafeLoader's own error says so
                        break
                    if not new:
                        raise _DuplicateKey(key, key_node.start_mark.line + 1)
                    seen.add(key)
            return super().construct_mapping(node, deep=deep)

    return UniqueKeySafeLoader


def _unique_pairs(pairs: list) -> dict:
    out = {}
    for k, v in pairs:
        if k in out:
            raise _DuplicateKey(k, 0)
        out[k] = v
    return out


def load_json(path: str | Path, what: str) -> Any:
    """Parse the JSON file ``path`` (a key given twice in one object is refused: the last would win)."""
    import json

    text = read_text(path, what)
    try:
        return json.loads(text, object_pairs_hook=_unique_pairs)
    except _DuplicateKey as exc:
        raise InputError(f"{what} {path} gives the key {exc.key!r} twice in one object: the last would win "
                         f"unnoticed; keep one") from None
    except ValueError:
        raise InputError(f"{what} {path} is not valid JSON (corrupted or truncated)") from None
    except RecursionError:
        raise InputError(f"{what} {path} is nested too deeply") from None


# ------------------------------------------------------------------ messages
_EXPECTED = {
    "float_type": "a number", "float_parsing": "a number", "finite_number": "a finite number",
    "int_type": "an integer", "int_parsing": "an integer", "int_from_float": "an integer",
    "bool_type": "true or false", "bool_parsing": "true or false",
    "string_type": "text", "list_type": "a list", "tuple_type": "a list", "dict_type": "a mapping of keys",
    "model_type": "a mapping of keys", "model_attributes_type": "a mapping of keys",
    "missing": "a value (the key is missing)", "extra_forbidden": "no such key (unknown key)",
    "too_short": "a non-empty list", "none_required": "nothing",
}


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _message(source: str, err: dict) -> str:
    parts = [str(x) for x in err.get("loc", ()) if not (isinstance(x, str) and x.startswith("function-"))]
    loc = ".".join(p if p.isprintable() else repr(p) for p in parts)  # a key with a newline stays one line
    kind = err.get("type", "")
    if kind == "missing":
        return f"{source}: {loc}: missing key"
    if kind == "extra_forbidden":
        return f"{source}: {loc}: unknown key"
    expected = _EXPECTED.get(kind)
    if expected is None:
        msg = str(err.get("msg", "invalid")).removeprefix("Value error, ").removeprefix("Input should be ")
        expected = msg[:1].lower() + msg[1:]
    got = err.get("input")
    where = f"{loc}: " if loc else ""
    return f"{source}: {where}expected {expected}, got {_short(got)}"


def validate(schema: type, data: Any, source: str) -> Any:
    """``schema.model_validate(data)``, its first error as one line naming ``source`` and the key."""
    from pydantic import ValidationError

    try:
        return schema.model_validate(data)
    except ValidationError as exc:
        errors = exc.errors(include_url=False)
        first = errors[0] if errors else {"msg": str(exc)}
        more = f" (and {len(errors) - 1} more problem(s))" if len(errors) > 1 else ""
        raise InputError(_message(source, first) + more) from None


# ------------------------------------------------------------------- schemas
def _number(value: Any) -> Any:
    """YAML 1.1 reads ``1e9`` as a string: a string that is a float literal is that number."""
    if isinstance(value, str) and _FLOAT_LITERAL.match(value.strip()):
        return float(value)
    return value


def _strict_number(value: Any) -> Any:
    """An int or float kept as given (a float literal string read as float); anything else refused."""
    value = _number(value)
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or type(value).__name__ == "bool_":
        raise ValueError("a number")  # numpy's bool_ is no Real, but be explicit
    return value


def _strict_integer(value: Any) -> int:
    """An integer (an integral float such as YAML's ``1e3`` included); anything else refused."""
    value = _number(value)
    if isinstance(value, numbers.Real) and not isinstance(value, (bool, numbers.Integral)) \
            and math.isfinite(value) and value == int(value):
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError("an integer")
    return int(value)


def _json_number(value: Any) -> Any:
    """JSON has real numbers: a string is never one (no YAML 1.1 quirk to forgive)."""
    if isinstance(value, str):
        raise ValueError("a number")
    return _strict_number(value)


def _json_integer(value: Any) -> int:
    if isinstance(value, str) or isinstance(value, float):
        raise ValueError("an integer")
    return _strict_integer(value)


def _strict_axis(value: Any) -> Any:
    """A number or a non-empty list of numbers."""
    if isinstance(value, (list, tuple)):
        if not value:
            raise ValueError("a non-empty list of numbers")
        try:
            return [_strict_number(v) for v in value]
        except ValueError:
            raise ValueError("a number or a list of numbers") from None
    try:
        return _strict_number(value)
    except ValueError:
        raise ValueError("a number or a list of numbers") from None


def schemas() -> Mapping[str, type]:
    """The pydantic models by file kind (``sensor``, ``sweep``, ``table``, ``sidecar``).

    A kind's model is built on its first lookup, once per process: reading a sensor file builds the sensor
    file's schema only (pydantic's import and first model build stay: about 0.2 s of CPU).
    """
    return _SCHEMAS


class _Built(dict):
    """The models built so far, by kind; a kind not built yet is built when looked up (KeyError: no such kind)."""

    def __missing__(self, kind: str) -> type:
        self[kind] = _build(kind)
        return self[kind]


_SCHEMAS = _Built()


def _build(kind: str) -> type:
    """The pydantic model of one file kind (pydantic is imported here, on first use)."""
    from typing import Annotated, Literal, Optional, Union

    from pydantic import BaseModel, ConfigDict, Field, PlainValidator, StrictBool, StrictStr

    class _Strict(BaseModel):
        model_config = ConfigDict(extra="forbid", strict=True, frozen=True)

    if kind in ("sensor", "sweep"):  # YAML formats: a float literal string is that number (YAML 1.1's 1e9)
        Number = Annotated[Any, PlainValidator(_strict_number)]
        Integer = Annotated[Any, PlainValidator(_strict_integer)]
    else:  # JSON formats (table header, trial sidecar): numbers are numbers, never strings
        Number = Annotated[Any, PlainValidator(_json_number)]
        Integer = Annotated[Any, PlainValidator(_json_integer)]

    if kind == "sensor":
        class SensorModel(_Strict):
            name: StrictStr
            params: dict[str, Any] = {}   # the model's own fields: checked by designkit.models.get_model
            time_offset_s: Optional[Number] = None
            contact_spread: Optional[dict[str, Optional[Number]]] = None
            object_temperature: Optional[dict[str, Union[StrictStr, Number]]] = None
            candidate: Optional[StrictStr] = None
            contact_area: Optional[dict[str, Any]] = None   # checked by designkit.models.sensor_model
            drift: Optional[StrictStr] = None

        class SensorFile(_Strict):
            designkit_sensor: Integer = 1
            name: StrictStr = "custom"
            effusivity: Number
            diffusivity_m2_s: Number
            depth_m: Number = 80e-6
            tau_s: Optional[Number] = None
            sample_rate_hz: Number = 200.0
            noise_c: Optional[Number] = None
            provenance: dict[str, Any] = {}
            model: Optional[SensorModel] = None
            conditions: Optional[dict[str, Any]] = None   # the rig as calibrated (designkit.rig; file version 2)

        return SensorFile

    if kind == "sweep":
        Axis = Annotated[Any, PlainValidator(_strict_axis)]

        class EffusivityGrid(_Strict):
            min: Optional[Number] = None
            max: Optional[Number] = None
            intervals: Optional[Integer] = None

        class SweepFile(_Strict):
            name: Optional[StrictStr] = None
            sensor: Optional[StrictStr] = None
            fidelity: Optional[StrictStr] = None
            effusivity: Optional[EffusivityGrid] = None
            e_min: Optional[Number] = None
            e_max: Optional[Number] = None
            intervals: Optional[Integer] = None
            trials: Optional[Integer] = None
            folds: Optional[Integer] = None
            threshold: Optional[Number] = None
            seed: Optional[Integer] = None
            max_repeats: Optional[Integer] = None
            z: Optional[Number] = None
            noise_ratio: Optional[Axis] = None
            noise_c: Optional[Axis] = None
            delta_t_c: Optional[Axis] = None
            ambient_temp_c: Optional[Number] = None
            sensor_temp_spread_c: Optional[Number] = None
            ambient_temp_spread_c: Optional[Number] = None
            contact_s: Optional[Axis] = None
            sample_rate_hz: Optional[Number] = None
            slope_window_s: Optional[Number] = None
            blocks: Optional[Integer] = None
            full_matrix: Optional[StrictBool] = None
            ideal_bound: Optional[StrictBool] = None
            model: Any = None  # a name, a mapping or a ForwardModel: checked by designkit.models
            diffusivity_m2_s: Optional[Number] = None
            solver: Optional[StrictStr] = None
            rig_scene: Optional[StrictBool] = None

        return SweepFile

    if kind == "table":
        class TableAxis(_Strict):
            name: Literal["noise_ratio", "noise_c", "delta_t_c", "contact_s", "e_ref"]
            units: StrictStr
            scale: Literal["linear", "log"]
            meaning: StrictStr = ""
            values: Annotated[list[Number], Field(min_length=1)]

        class TableEffusivity(_Strict):
            min: Number
            max: Number
            intervals: Integer
            width: Number
            units: Literal["J s^-1/2 K^-1 m^-2"]

        class TableArray(_Strict):
            shape: list[Integer]
            dtype: StrictStr
            units: StrictStr
            meaning: StrictStr

        class TableHeader(BaseModel):
            # Unknown top-level keys are kept (and covered by the content hash): a newer writer may add them.
            model_config = ConfigDict(extra="allow", strict=True, frozen=True)
            format: Literal["designkit-table"]
            schema_version: Integer
            name: StrictStr
            fidelity: Literal["svm", "ideal"]
            sensor: dict[str, Any]
            model: Optional[dict[str, Any]] = None
            effusivity: TableEffusivity
            fixed_initial_conditions: StrictBool = True
            axes: Annotated[list[TableAxis], Field(min_length=2)]
            arrays: dict[str, TableArray]
            threshold: Number
            trials: Integer
            folds: Integer
            seed: Integer
            max_repeats: Integer
            z: Number
            designkit_version: StrictStr
            created: StrictStr
            config: dict[str, Any]
            stats: dict[str, Any] = {}
            content_hash: StrictStr

        return TableHeader

    if kind != "sidecar":
        raise KeyError(kind)

    class TrialSidecar(BaseModel):
        model_config = ConfigDict(extra="allow", strict=True, frozen=True)
        designkit_trial: Integer
        # a file name beside the sidecar, never a path elsewhere
        file: Optional[Annotated[StrictStr, Field(pattern=r"^[^/\\\x00]+$")]] = None
        material: StrictStr = ""
        trial_index: Optional[Integer] = None
        release_s: Optional[Number] = None

    return TrialSidecar
