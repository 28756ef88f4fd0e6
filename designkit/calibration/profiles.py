"""Device profiles: how a sensor rig speaks over serial, and how to read it.

A profile (YAML, see ``calibration/README.md``) says which serial settings to
use, how one text line is split into fields, which field carries which
channel (heated sensor temperature, object/passive temperature, force,
optional timestamp), how each raw field converts to engineering units, how a
touch is detected and which window around it is a trial.

Each raw field converts by one of :mod:`~designkit.calibration.conversions`
(none, linear, thermistor).

A line may end in a checksum (``line.checksum``): ``xor8`` appends ``*HH``,
the XOR of the line's bytes before the ``*`` in two hex digits (as NMEA 0183
sentences do), ``crc16`` appends ``*HHHH``, their CRC-16/CCITT (polynomial
0x1021, initial value 0xFFFF, :func:`binascii.crc_hqx`). A line whose checksum
is missing or wrong is skipped as unreadable: a digit changed on the wire
(``24.9884`` read as ``26.9884``) still parses, and only a checksum tells.

Everything is validated on load; a bad profile raises
:class:`~designkit._validation.InputError` with one line naming the file and
the key.
"""

from __future__ import annotations

import binascii
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from .._validation import InputError
from .conversions import KELVIN, Conversion, Identity, Linear, Thermistor

__all__ = [
    "CHECKSUMS",
    "ROLES",
    "Channel",
    "ContactRule",
    "DeviceProfile",
    "ParsedLines",
    "SerialSettings",
    "TrialWindow",
    "list_profiles",
    "load_profile",
]

PROFILE_FILE_VERSION = 1

#: Channel roles a profile can map, in the order the recorder keeps them.
ROLES = ("sensor", "object", "force", "timestamp")

#: Line checksums a profile can ask for (module docstring), and the hex digits each appends after ``*``.
CHECKSUMS = {"none": 0, "xor8": 2, "crc16": 4}


def line_checksum(payload: bytes, kind: str) -> str:
    """The checksum ``kind`` (``xor8`` or ``crc16``) of a line's bytes before ``*``, as upper-case hex.

    >>> line_checksum(b"12.3450,34.9987,24.9975,0.012", "xor8")
    '22'
    >>> line_checksum(b"123456789", "crc16")   # the CRC-16/CCITT-FALSE check value
    '29B1'
    """
    if kind == "xor8":
        x = 0
        for b in payload:
            x ^= b
        return f"{x:02X}"
    if kind == "crc16":
        return f"{binascii.crc_hqx(payload, 0xFFFF):04X}"
    raise ValueError(f"unknown checksum {kind!r}")

_PARITY = {"none": "N", "even": "E", "odd": "O", "mark": "M", "space": "S",
           "n": "N", "e": "E", "o": "O", "m": "M", "s": "S"}


# ---------------------------------------------------------------------- helpers
#: Longest duration a profile may give (a trial window, a timeout) [s]: a day.
MAX_PROFILE_SECONDS = 86400.0


class _Reader:
    """Walks a YAML mapping, remembering the key path for error messages."""

    def __init__(self, source: str, data: Any, path: str = "") -> None:
        self.source = source
        self.path = path
        if not isinstance(data, Mapping):
            where = f" {path}" if path else ""
            raise InputError(f"{source}:{where} must be a mapping of keys, got {type(data).__name__}")
        self.data = data
        self.used: set[str] = set()

    def _key(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def err(self, key: str, message: str) -> InputError:
        return InputError(f"{self.source}: {self._key(key)} {message}")

    def has(self, key: str) -> bool:
        return key in self.data and self.data[key] is not None

    def raw(self, key: str, default: Any = ..., *, required: bool = False) -> Any:
        self.used.add(key)
        if key not in self.data or self.data[key] is None:
            if required or default is ...:
                raise InputError(f"{self.source}: missing key {self._key(key)}")
            return default
        return self.data[key]

    def sub(self, key: str, *, required: bool = False) -> "_Reader | None":
        value = self.raw(key, None, required=required)
        if value is None:
            return None
        return _Reader(self.source, value, self._key(key))

    def number(self, key: str, default: Any = ..., *, positive: bool = False,
               nonnegative: bool = False, required: bool = False) -> float:
        value = self.raw(key, default, required=required)
        if isinstance(value, bool):
            raise self.err(key, f"must be a number, got {value!r}")
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise self.err(key, f"must be a number, got {value!r}") from None
        if not math.isfinite(v):
            raise self.err(key, f"must be finite, got {value!r}")
        if key.endswith("_s") and abs(v) > MAX_PROFILE_SECONDS:  # 1e308 s overflowed a count of samples
            raise self.err(key, f"must be at most {MAX_PROFILE_SECONDS:g} s (a day), got {v:g}")
        if positive and v <= 0:
            raise self.err(key, f"must be > 0, got {v:g}")
        if nonnegative and v < 0:
            raise self.err(key, f"must be >= 0, got {v:g}")
        return v

    def integer(self, key: str, default: Any = ..., *, low: int | None = None,
                high: int | None = None) -> int:
        value = self.raw(key, default)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or int(value) != value:
            raise self.err(key, f"must be an integer, got {value!r}")
        v = int(value)
        if (low is not None and v < low) or (high is not None and v > high):
            raise self.err(key, f"must be between {low} and {high}, got {v}")
        return v

    def text(self, key: str, default: Any = ..., *, choices: Sequence[str] | None = None) -> str:
        value = self.raw(key, default)
        if not isinstance(value, str):
            raise self.err(key, f"must be text, got {value!r}")
        if choices is not None and value not in choices:
            raise self.err(key, f"must be one of {', '.join(choices)}; got {value!r}")
        return value

    def pair(self, key: str, default: Any = ...) -> tuple[float, float] | None:
        value = self.raw(key, default)
        if value is None:
            return None
        if not isinstance(value, (list, tuple)) or len(value) != 2:
            raise self.err(key, f"must be a pair [min, max], got {value!r}")
        try:
            lo, hi = float(value[0]), float(value[1])
        except (TypeError, ValueError):
            raise self.err(key, f"must be a pair of numbers [min, max], got {value!r}") from None
        if not (math.isfinite(lo) and math.isfinite(hi)) or not lo < hi:
            raise self.err(key, f"must be finite with min < max, got {value!r}")
        return lo, hi

    def done(self) -> None:
        # repr() for keys with newlines or control characters: the message stays one line
        unknown = sorted(str(k) if str(k).isprintable() else repr(str(k)) for k in self.data if k not in self.used)
        if unknown:
            where = f" in {self.path}" if self.path else ""
            raise InputError(f"{self.source}: unknown key(s) {', '.join(unknown)}{where}")


def _conversion(rd: _Reader | None) -> Conversion:
    if rd is None:
        return Identity()
    kind = rd.text("type", "none", choices=("none", "linear", "thermistor"))
    if kind == "none":
        conv: Conversion = Identity(decimals=rd.integer("decimals", 4, low=0, high=12))
    elif kind == "linear":
        gain = rd.number("gain", required=True)
        if gain == 0:
            raise rd.err("gain", "must not be 0")
        bits = rd.integer("adc_bits", None, low=1, high=32) if rd.has("adc_bits") else None
        rd.used.add("adc_bits")
        conv = Linear(gain=gain, offset=rd.number("offset", 0.0),
                      decimals=rd.integer("decimals", 0, low=0, high=12), adc_bits=bits)
    else:
        bits = rd.integer("adc_bits", low=1, high=32)
        side = rd.text("thermistor_side", "high", choices=("high", "low"))
        v_supply = rd.number("v_supply", None, positive=True) if rd.has("v_supply") else None
        rd.used.add("v_supply")
        beta = rd.sub("beta")
        sh = rd.sub("steinhart_hart")
        if (beta is None) == (sh is None):
            raise InputError(f"{rd.source}: {rd.path} needs exactly one of beta or steinhart_hart")
        kwargs: dict[str, Any] = {}
        if beta is not None:
            kwargs = {"beta_k": beta.number("beta_k", required=True, positive=True),
                      "r0_ohm": beta.number("r0_ohm", required=True, positive=True),
                      "t0_c": beta.number("t0_c", required=True)}
            if kwargs["t0_c"] <= -KELVIN:
                raise beta.err("t0_c", "must be above absolute zero")
            beta.done()
        else:
            coeffs = (sh.number("a", required=True), sh.number("b", required=True, positive=True),
                      sh.number("c", required=True, nonnegative=True))
            sh.done()
            kwargs = {"sh": coeffs}
        conv = Thermistor(adc_bits=bits, v_ref=rd.number("v_ref", required=True, positive=True),
                          series_ohm=rd.number("series_ohm", required=True, positive=True),
                          thermistor_side=side, v_supply=v_supply, **kwargs)
    rd.done()
    return conv


# ----------------------------------------------------------------------- parts
@dataclass(frozen=True)
class Channel:
    """One channel: which field of a line, how it converts, what is plausible.

    ``valid``: (min, max) in engineering units; readings outside are refused
    as out of range (a loose connector, an open thermistor).
    """

    role: str
    field_name: str
    field_index: int
    conversion: Conversion
    valid: tuple[float, float] | None = None

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"field": self.field_name, "conversion": self.conversion.to_dict()}
        if self.valid is not None:
            out["valid"] = list(self.valid)
        return out


@dataclass(frozen=True)
class SerialSettings:
    """pyserial settings and the recorder's time limits (real seconds)."""

    baudrate: int = 115200
    bytesize: int = 8
    parity: str = "N"
    stopbits: float = 1
    read_timeout_s: float = 0.05
    no_data_timeout_s: float = 5.0
    stall_s: float = 0.25
    reconnect_s: float = 2.0

    def to_dict(self) -> dict[str, Any]:
        names = {"N": "none", "E": "even", "O": "odd", "M": "mark", "S": "space"}
        return {"baudrate": self.baudrate, "bytesize": self.bytesize, "parity": names[self.parity],
                "stopbits": self.stopbits, "read_timeout_s": self.read_timeout_s,
                "no_data_timeout_s": self.no_data_timeout_s, "stall_s": self.stall_s,
                "reconnect_s": self.reconnect_s}


@dataclass(frozen=True)
class ContactRule:
    """How a touch is detected.

    ``rule="force"``: contact starts at the first sample with force >=
    ``force_threshold_n`` (5 N as in the paper), and the detector re-arms
    once force falls below ``release_n``. ``rule="temperature_slope"`` (rigs
    without a force sensor): contact starts where the sensor temperature,
    smoothed over ``slope_window_s``, falls faster than ``slope_c_per_s``;
    the detector re-arms after the trial once the slope has been within a
    quarter of that for ``pre_s``. Either way the fit's time offset absorbs
    the detection delay.
    """

    rule: str = "force"
    force_threshold_n: float = 5.0
    release_n: float = 2.5
    slope_c_per_s: float = 0.3
    slope_window_s: float = 0.5

    def to_dict(self) -> dict[str, Any]:
        if self.rule == "force":
            return {"rule": "force", "force_threshold_n": self.force_threshold_n, "release_n": self.release_n}
        return {"rule": "temperature_slope", "slope_c_per_s": self.slope_c_per_s,
                "slope_window_s": self.slope_window_s}


@dataclass(frozen=True)
class TrialWindow:
    """Seconds kept before and after the detected contact onset."""

    pre_s: float = 1.0
    post_s: float = 7.0


@dataclass(frozen=True)
class ParsedLines:
    """A batch of lines read into raw numbers.

    Attributes
    ----------
    raw : ndarray, shape (n, len(ROLES))
        Raw numbers of the mapped channels (NaN for an unmapped role), one row
        per line that split into numbers.
    rows : list of int
        Index of each row's line in the batch.
    errors : list of (int, str, str)
        (line index, kind, line text) of lines that did not parse; kind is
        ``garbled``, ``checksum``, ``field_count`` or ``non_numeric``.
    messages : list of str
        Device messages (comment lines), skipped.
    slots : ndarray of int, shape (n,)
        Sample slot of each row: every non-empty line that is not a device
        message counts as one sample, readable or not, so that a clock made
        by counting lines stays right when some lines are lost to garbling.
    n_slots : int
        Sample slots in the batch.
    """

    raw: np.ndarray
    rows: list[int]
    errors: list[tuple[int, str, str]]
    messages: list[str]
    slots: np.ndarray
    n_slots: int


@dataclass(frozen=True)
class DeviceProfile:
    """A device profile (see the module docstring and ``calibration/README.md``)."""

    name: str
    description: str
    serial: SerialSettings
    delimiter: str | None
    comment: str | None
    encoding: str
    fields: tuple[str, ...]
    channels: Mapping[str, Channel]
    sample_rate_hz: float
    contact: ContactRule
    trial: TrialWindow
    source: str = "profile"
    checksum: str = "none"
    _index: tuple[int, ...] = field(default=(), repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "channels", dict(self.channels))
        object.__setattr__(self, "_index", tuple(
            self.channels[r].field_index if r in self.channels else -1 for r in ROLES))

    @property
    def has_timestamp(self) -> bool:
        return "timestamp" in self.channels

    @property
    def has_object(self) -> bool:
        return "object" in self.channels

    @property
    def has_force(self) -> bool:
        return "force" in self.channels

    # ------------------------------------------------------------- reading
    def parse_lines(self, lines: Sequence[bytes]) -> ParsedLines:
        """Split lines into raw numbers; report the ones that do not parse.

        A line must decode in the profile's encoding, be printable, carry a
        right checksum when the profile asks for one (kind ``checksum``
        otherwise), have exactly ``len(fields)`` fields, and every mapped
        field must be a finite number. Empty lines are ignored.
        """
        nf = len(self.fields)
        idx = self._index
        rows: list[list[float]] = []
        where: list[int] = []
        errors: list[tuple[int, str, str]] = []
        messages: list[str] = []
        slots: list[int] = []
        slot = -1
        delim = self.delimiter
        comment = self.comment.encode(self.encoding) if self.comment else None
        check = CHECKSUMS[self.checksum]
        for i, line in enumerate(lines):
            stripped = line.strip()
            if not stripped:
                continue
            if comment and stripped.startswith(comment):
                messages.append(stripped.decode(self.encoding, "replace"))
                continue
            slot += 1
            try:
                text = stripped.decode(self.encoding)
            except UnicodeDecodeError:
                errors.append((i, "garbled", stripped[:60].decode(self.encoding, "replace")))
                continue
            if not text.isprintable():
                errors.append((i, "garbled", text[:60]))
                continue
            if check:
                payload, star, got = text.rpartition("*")
                if not star or len(got) != check or got.upper() != line_checksum(
                        payload.encode(self.encoding), self.checksum):
                    errors.append((i, "checksum", text[:60]))
                    continue
                text = payload
            parts = text.split(delim) if delim is not None else text.split()
            if len(parts) != nf:
                errors.append((i, "field_count", text[:60]))
                continue
            try:
                vals = [float(parts[j]) if j >= 0 else math.nan for j in idx]
            except ValueError:
                errors.append((i, "non_numeric", text[:60]))
                continue
            if any(j >= 0 and not math.isfinite(v) for j, v in zip(idx, vals)):
                errors.append((i, "non_numeric", text[:60]))
                continue
            rows.append(vals)
            where.append(i)
            slots.append(slot)
        raw = np.array(rows, dtype=np.float64).reshape(len(rows), len(ROLES))
        return ParsedLines(raw, where, errors, messages, np.array(slots, dtype=np.int64), slot + 1)

    def convert(self, raw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Raw numbers (from :meth:`parse_lines`) to engineering units.

        Returns
        -------
        values : ndarray, shape (n, len(ROLES))
            sensor [degC], object [degC], force [N], timestamp [s]; NaN for a
            role the profile does not map.
        bad : ndarray of bool, shape (n,)
            Rows with an out-of-range reading (raw counts the conversion
            cannot take, or a value outside the channel's ``valid`` range).
        """
        raw = np.asarray(raw, dtype=np.float64).reshape(-1, len(ROLES))
        values = np.full(raw.shape, np.nan)
        bad = np.zeros(raw.shape[0], dtype=bool)
        for k, role in enumerate(ROLES):
            ch = self.channels.get(role)
            if ch is None:
                continue
            col = raw[:, k]
            invalid = ch.conversion.raw_invalid(col)
            safe = np.where(invalid, np.nan, col)
            with np.errstate(invalid="ignore", divide="ignore"):
                v = ch.conversion.to_value(safe)
            invalid |= ~np.isfinite(v)
            if ch.valid is not None:
                with np.errstate(invalid="ignore"):
                    invalid |= (v < ch.valid[0]) | (v > ch.valid[1])
            values[:, k] = v
            bad |= invalid
        return values, bad

    # ------------------------------------------------------------- writing
    def format_lines(self, values: Mapping[str, np.ndarray]) -> list[str]:
        """Wire lines (without newline) for engineering values per role.

        Roles the profile maps but ``values`` lacks, and unmapped fields, are
        sent as ``0``. The emulator's only way of speaking.
        """
        n = len(next(iter(values.values())))
        cols: list[list[str]] = [["0"] * n for _ in self.fields]
        for role, ch in self.channels.items():
            if role in values:
                raw = ch.conversion.encode(np.asarray(values[role], dtype=np.float64))
                cols[ch.field_index] = ch.conversion.format(raw)
        delim = self.delimiter if self.delimiter is not None else " "
        lines = [delim.join(parts) for parts in zip(*cols)]
        if self.checksum != "none":
            lines = [f"{x}*{line_checksum(x.encode(self.encoding), self.checksum)}" for x in lines]
        return lines

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (the YAML schema)."""
        return {
            "designkit_profile": PROFILE_FILE_VERSION,
            "name": self.name,
            "description": self.description,
            "serial": self.serial.to_dict(),
            "line": {"delimiter": "whitespace" if self.delimiter is None else self.delimiter,
                     "comment": self.comment, "encoding": self.encoding, "fields": list(self.fields),
                     "checksum": self.checksum},
            "sample_rate_hz": self.sample_rate_hz,
            "channels": {r: self.channels[r].to_dict() for r in ROLES if r in self.channels},
            "contact": self.contact.to_dict(),
            "trial": {"pre_s": self.trial.pre_s, "post_s": self.trial.post_s},
        }


# ---------------------------------------------------------------------- loading
def _parse_profile(data: Any, source: str) -> DeviceProfile:
    rd = _Reader(source, data)
    version = rd.raw("designkit_profile", PROFILE_FILE_VERSION)
    if version != PROFILE_FILE_VERSION:
        raise InputError(f"{source}: unsupported profile version {version!r} "
                         f"(this designkit reads version {PROFILE_FILE_VERSION})")
    name = rd.text("name")
    description = rd.text("description", "")

    serial = _serial(rd.sub("serial") or _Reader(source, {}, "serial"))
    delimiter, comment, encoding, checksum, fields = _line(rd.sub("line", required=True))
    named = [f for f in fields if f != "_"]

    ch_rd = rd.sub("channels", required=True)
    channels: dict[str, Channel] = {}
    default_valid = {"sensor": (-40.0, 150.0), "object": (-40.0, 150.0), "force": None, "timestamp": None}
    for role in ROLES:
        sub = ch_rd.sub(role)
        if sub is None:
            continue
        fname = sub.text("field")
        if fname not in named:
            raise sub.err("field", f"names no field of line.fields ({', '.join(named)}): {fname!r}")
        conv = _conversion(sub.sub("conversion"))
        valid = sub.pair("valid", default_valid[role])
        sub.done()
        if role == "timestamp" and isinstance(conv, Thermistor):
            raise sub.err("conversion", "of a timestamp cannot be a thermistor")
        channels[role] = Channel(role, fname, fields.index(fname), conv, valid)
    ch_rd.done()
    if "sensor" not in channels:
        raise InputError(f"{source}: channels.sensor (the heated sensor's temperature) is required")
    used = [c.field_name for c in channels.values()]
    twice = sorted({f for f in used if used.count(f) > 1})
    if twice:
        raise InputError(f"{source}: field(s) {', '.join(twice)} mapped to more than one channel")

    sample_rate = rd.number("sample_rate_hz", required=True, positive=True)

    con = rd.sub("contact") or _Reader(source, {}, "contact")
    rule = con.text("rule", "force", choices=("force", "temperature_slope"))
    threshold = con.number("force_threshold_n", 5.0, positive=True)
    release = con.number("release_n", threshold / 2.0, nonnegative=True)
    if release >= threshold:
        raise con.err("release_n", f"must be below force_threshold_n ({threshold:g}), got {release:g}")
    contact = ContactRule(rule=rule, force_threshold_n=threshold, release_n=release,
                          slope_c_per_s=con.number("slope_c_per_s", 0.3, positive=True),
                          slope_window_s=con.number("slope_window_s", 0.5, positive=True))
    con.done()
    if rule == "force" and "force" not in channels:
        raise InputError(f"{source}: contact.rule force needs a channels.force entry "
                         "(or use rule: temperature_slope)")
    if rule == "temperature_slope" and contact.slope_window_s * sample_rate < 4:
        raise InputError(f"{source}: contact.slope_window_s must span at least 4 samples "
                         f"at {sample_rate:g} Hz, got {contact.slope_window_s:g} s")

    tr = rd.sub("trial") or _Reader(source, {}, "trial")
    trial = TrialWindow(pre_s=tr.number("pre_s", 1.0, positive=True),
                        post_s=tr.number("post_s", 7.0, positive=True))
    tr.done()
    if trial.pre_s * sample_rate < 3:
        raise InputError(f"{source}: trial.pre_s must hold at least 3 samples at {sample_rate:g} Hz")
    from ..sensor import check_samples_per_touch

    check_samples_per_touch(trial.pre_s + trial.post_s, sample_rate, f"{source}: a trial window (pre_s + post_s)",
                            "shorten trial.pre_s and trial.post_s or lower reading.sample_rate_hz")
    rd.done()
    return DeviceProfile(name=str(name), description=description, serial=serial, delimiter=delimiter,
                         comment=comment, encoding=encoding, fields=fields, channels=channels,
                         sample_rate_hz=sample_rate, contact=contact, trial=trial, source=source, checksum=checksum)


def _serial(ser: _Reader) -> SerialSettings:
    """The ``serial`` section."""
    parity_text = ser.text("parity", "none").strip().lower()
    if parity_text not in _PARITY:
        raise ser.err("parity", f"must be one of none, even, odd, mark, space; got {parity_text!r}")
    stopbits = ser.number("stopbits", 1)
    if stopbits not in (1, 1.5, 2):
        raise ser.err("stopbits", f"must be 1, 1.5 or 2, got {stopbits:g}")
    serial = SerialSettings(
        baudrate=ser.integer("baudrate", 115200, low=50, high=20_000_000),
        bytesize=ser.integer("bytesize", 8, low=5, high=8),
        parity=_PARITY[parity_text],
        stopbits=stopbits,
        read_timeout_s=ser.number("read_timeout_s", 0.05, positive=True),
        no_data_timeout_s=ser.number("no_data_timeout_s", 5.0, positive=True),
        stall_s=ser.number("stall_s", 0.25, positive=True),
        reconnect_s=ser.number("reconnect_s", 2.0, nonnegative=True),
    )
    ser.done()
    return serial


def _line(line: _Reader) -> tuple[str | None, str | None, str, str, tuple[str, ...]]:
    """The ``line`` section: ``(delimiter, comment, encoding, checksum, fields)``."""
    delim_text = line.text("delimiter", ",")
    delimiter = None if delim_text == "whitespace" else delim_text
    if delimiter is not None and (delimiter == "" or "\n" in delimiter or "\r" in delimiter):
        raise line.err("delimiter", f"must be a non-empty string without newlines or 'whitespace', got {delim_text!r}")
    comment = line.text("comment") if line.has("comment") else None
    line.used.add("comment")
    encoding = line.text("encoding", "ascii")
    try:
        "x".encode(encoding)
    except LookupError:
        raise line.err("encoding", f"is not a known text encoding: {encoding!r}") from None
    checksum = line.text("checksum", "none", choices=tuple(CHECKSUMS))
    if checksum != "none" and delimiter is not None and "*" in delimiter:
        raise line.err("checksum", "needs a delimiter without '*' (the checksum follows the last '*')")
    fields_raw = line.raw("fields", required=True)
    if not isinstance(fields_raw, list) or not fields_raw:
        raise line.err("fields", f"must be a non-empty list of field names, got {fields_raw!r}")
    fields = tuple("_" if f is None else str(f) for f in fields_raw)
    named = [f for f in fields if f != "_"]
    dupes = sorted({f for f in named if named.count(f) > 1})
    if dupes:
        raise line.err("fields", f"has duplicate name(s) {', '.join(dupes)}")
    line.done()
    return delimiter, comment, encoding, checksum, fields


def list_profiles() -> dict[str, Path]:
    """Shipped profiles: name -> file."""
    from .._resources import profiles_dir

    folder = profiles_dir()
    if not folder.is_dir():
        return {}
    return {p.stem: p for p in sorted(folder.glob("*.yaml"))}


def load_profile(name_or_path: "str | Path | DeviceProfile") -> DeviceProfile:
    """A device profile from a shipped name (``designkit``, ``adc12-thermistor``) or a YAML path."""
    if isinstance(name_or_path, DeviceProfile):
        return name_or_path
    key = str(name_or_path)
    shipped = list_profiles()
    if key in shipped:
        path = shipped[key]
    else:
        path = Path(key)
        if not path.exists():
            names = ", ".join(shipped) or "none found"
            raise InputError(f"unknown device profile {key!r}: use a shipped name ({names}) or a profile YAML file")
    from .._schemas import load_yaml

    # a regular UTF-8 file (a FIFO or a folder is refused before reading), parsed by the one YAML reader
    data = load_yaml(path, "profile")  # an empty file: "is empty" (it said "got NoneType")
    return _parse_profile(data, f"profile {path}")


def profile_from_dict(data: Mapping[str, Any], source: str = "profile") -> DeviceProfile:
    """Build and validate a profile from plain data (the YAML content)."""
    return _parse_profile(data, source)


__all__.append("profile_from_dict")
