"""Input checks shared by every layer.

Bad input raises :class:`InputError`, a :class:`ValueError` whose message is one
line that names the offending parameter and its value. The CLI prints that line
and exits with status 2; library users catch ``ValueError``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # numpy loads where a seed is used, not with every input check (``--version``, ``--help``)
    import numpy as np

__all__ = [
    "MAX_EFFUSIVITY",
    "InputError",
    "as_generator",
    "check_effusivity",
    "check_effusivity_range",
    "check_file_name",
    "check_finite",
    "check_label",
    "error_line",
    "check_memory",
    "check_temperature",
    "check_nonnegative",
    "check_positive",
    "check_probability",
    "memory_limit_bytes",
]


#: The smallest normal float: a positive value below it is subnormal, never a physical quantity.
_TINY = 2.2250738585072014e-308


class InputError(ValueError):
    """A parameter is outside the domain the model is defined on."""


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:g}"
    return repr(value)


def check_finite(name: str, value: float) -> float:
    """Return ``value`` as float, or raise if it is NaN, infinite or not a number."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {_fmt(value)}") from None
    if not math.isfinite(v):
        raise InputError(f"{name} must be finite, got {_fmt(v)}")
    return v


def check_positive(name: str, value: float, *, allow_inf: bool = False) -> float:
    """Return ``value`` as float, or raise unless it is > 0 (and finite, unless allowed)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {_fmt(value)}") from None
    if math.isnan(v) or v <= 0 or (math.isinf(v) and not allow_inf):
        what = "positive" if allow_inf else "positive and finite"
        raise InputError(f"{name} must be {what}, got {_fmt(v)}")
    if v < _TINY:  # subnormal: never a physical quantity; 1 / v overflows or divides by zero downstream
        raise InputError(f"{name} must be at least {_TINY:.3g} (a normal float), got {_fmt(v)}")
    return v


def check_probability(name: str, value: float, *, low: float = 0.0, high: float = 1.0) -> float:
    """Return ``value`` as float, or raise unless ``low < value < high`` (an F1 threshold: (2/3, 1))."""
    v = check_finite(name, value)
    if not low < v < high:
        lo = "2/3" if abs(low - 2 / 3) < 1e-12 else f"{low:g}"
        raise InputError(f"{name} must be in ({lo}, {high:g}), got {_fmt(v)}")
    return v


def memory_limit_bytes() -> int:
    """What one request may allocate: ``DESIGNKIT_MEMORY_LIMIT_GB`` or half of this machine's memory."""
    import os

    env = os.environ.get("DESIGNKIT_MEMORY_LIMIT_GB")
    if env:
        try:
            gb = float(env)
        except ValueError:
            raise InputError(f"DESIGNKIT_MEMORY_LIMIT_GB must be a number of GB, got {env!r}") from None
        if math.isfinite(gb) and gb > 0:
            return int(gb * 1024 ** 3)
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        total = 8 * 1024 ** 3
    return int(total // 2)


def _bytes(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024 or unit == "PiB":
            return f"{n:.3g} {unit}"
        n /= 1024
    return f"{n:.3g} PiB"  # pragma: no cover


def check_memory(what: str, nbytes: float) -> None:
    """Refuse a request whose estimated memory ``nbytes`` exceeds :func:`memory_limit_bytes`, in one line."""
    limit = memory_limit_bytes()
    if not nbytes <= limit:
        raise InputError(f"{what} needs about {_bytes(float(nbytes))} of memory; the limit is {_bytes(limit)} "
                         f"(half this machine's memory; set DESIGNKIT_MEMORY_LIMIT_GB to change it)")


#: Longest label (a sensor's or material's name) in characters: a line of a summary, not a paragraph.
MAX_LABEL_CHARS = 200
#: Longest name that becomes a file (a sweep's table and workdir), in characters and in UTF-8 bytes: with a
#: suffix such as ``.npz.tmp`` and a temporary file's prefix it stays under the 255 bytes of a file name.
MAX_FILE_NAME_CHARS = 100
MAX_FILE_NAME_BYTES = 200


def check_label(what: str, text: Any, *, max_chars: int = MAX_LABEL_CHARS) -> str:
    """A label printed on one line (a sensor's name, a material's): text, not empty, no control characters
    (a newline spilled a summary over several lines), at most ``max_chars`` characters; else one-line InputError.

    >>> check_label("sensor name", "paper")
    'paper'
    >>> check_label("sensor name", "a\\nb")
    Traceback (most recent call last):
    ...
    designkit._validation.InputError: sensor name must be one line of printable text, got 'a\\nb' (a control character at position 2)
    """
    if not isinstance(text, str):
        raise InputError(f"{what} must be text, got {type(text).__name__}")
    if not text.strip():
        raise InputError(f"{what} is empty")
    for i, ch in enumerate(text):
        if ch < " " or "\x7f" <= ch <= "\x9f" or ch in "\u2028\u2029":
            raise InputError(f"{what} must be one line of printable text, got {_short(text)} (a control character "
                             f"at position {i + 1})")
    if len(text) > max_chars:
        raise InputError(f"{what} has {len(text)} characters; the limit is {max_chars}")
    return text


def check_file_name(what: str, name: Any) -> str:
    """A name that becomes a file inside a folder designkit chooses (a sweep's ``name``: its table and its
    workdir): one file name, never a path. The one rule for such names, checked before any work.

    Refused, in one line: empty, separators (``/``, ``\\``: a name is not a path, so no absolute path
    and no traversal), ``.`` and ``..``, control characters (a newline, NUL), more than
    :data:`MAX_FILE_NAME_CHARS` characters or :data:`MAX_FILE_NAME_BYTES` bytes.

    >>> check_file_name("sweep name", "svm-fine")
    'svm-fine'
    >>> check_file_name("sweep name", "../../escaped")
    Traceback (most recent call last):
    ...
    designkit._validation.InputError: sweep name must be a file name, not a path: '../../escaped' holds '/' (give a name such as 'svm-fine'; choose the folder with --out or --workdir)
    """
    name = check_label(what, name, max_chars=MAX_FILE_NAME_CHARS)
    for sep in ("/", "\\"):
        if sep in name:
            raise InputError(f"{what} must be a file name, not a path: {_short(name)} holds {sep!r} (give a name "
                             f"such as 'svm-fine'; choose the folder with --out or --workdir)")
    if name in (".", "..") or name != name.strip():
        raise InputError(f"{what} must be a file name, got {_short(name)}"
                         + (" (it begins or ends with a space)" if name.strip() not in (".", "..") else ""))
    if len(name.encode("utf-8", "surrogatepass")) > MAX_FILE_NAME_BYTES:
        raise InputError(f"{what} takes more than {MAX_FILE_NAME_BYTES} bytes as a file name")
    return name


def _short(text: str, n: int = 60) -> str:
    return repr(text if len(text) <= n else text[:n] + "...")


def error_line(exc: BaseException) -> str:
    """The first line of an exception's message (its type's name when it has none): one line for a user."""
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


#: Seeds averaged per pair (a sweep's ``max_repeats``, an exact question's ``repeats``): the Monte
#: Carlo error falls as 1/sqrt(R), 3 % of one seed's at 1,000, and each seed is a whole fit; a
#: mistyped 10^9 re-scored a pair at the threshold without end.
MAX_REPEATS = 1000


def check_repeats(name: str, value: int) -> int:
    """A count of seeds per pair: a whole number from 1 to :data:`MAX_REPEATS`, else one-line InputError.

    >>> check_repeats("repeats", 4)
    4
    """
    try:
        r = int(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name} must be a whole number of seeds, got {value!r}") from None
    if r != value or not 1 <= r <= MAX_REPEATS:
        raise InputError(f"{name} must be a whole number from 1 to {MAX_REPEATS}, got {_fmt(value)}")
    return r


#: Temperatures and temperature noise beyond this many degC are refused: no sensor survives them, and
#: 1e308 overflowed the simulation (inf readings, or an overflow error).
MAX_ABS_TEMPERATURE_C = 1e4


def check_temperature(name: str, value: float, *, nonnegative: bool = False) -> float:
    """A finite temperature (or noise, or difference) [degC] of magnitude at most 1e4."""
    v = check_nonnegative(name, value) if nonnegative else check_finite(name, value)
    if abs(v) > MAX_ABS_TEMPERATURE_C:
        raise InputError(f"{name} must be at most {MAX_ABS_TEMPERATURE_C:g} degC in magnitude, got {_fmt(v)}")
    return v


def check_nonnegative(name: str, value: float) -> float:
    """Return ``value`` as float, or raise unless it is finite and >= 0."""
    v = check_finite(name, value)
    if v < 0:
        raise InputError(f"{name} must be >= 0, got {_fmt(v)}")
    return v


#: Largest finite effusivity accepted where infinity is not [J s^-1/2 K^-1 m^-2]: about 100x diamond's (~6e4),
#: the highest of any solid. Above it a value is a typo (1e30 for 1e3), and an interval of 80 around it has no
#: width in float64.
MAX_EFFUSIVITY = 1e7


def check_effusivity(name: str, value: float, *, allow_zero: bool = False,
                     allow_inf: bool = False) -> float:
    """Check one effusivity [J s^-1/2 K^-1 m^-2].

    The physics layer accepts the limits 0 and infinity (a perfect insulator and a
    perfect conductor); recognition and query inputs do not, nor anything above
    :data:`MAX_EFFUSIVITY`.

    >>> check_effusivity("e1", 35000)
    35000.0
    >>> check_effusivity("e1", 1e30)
    Traceback (most recent call last):
    ...
    designkit._validation.InputError: effusivity e1 must be at most 1e+07 J s^-1/2 K^-1 m^-2 (the highest of any material, diamond's, is about 6e4), got 1e+30
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"effusivity {name} must be a number, got {_fmt(value)}") from None
    if math.isnan(v):
        raise InputError(f"effusivity {name} must be a number, got nan")
    if v < 0 or (v == 0 and not allow_zero):
        raise InputError(f"effusivity {name} must be positive, got {_fmt(v)}")
    if math.isinf(v) and not allow_inf:
        raise InputError(f"effusivity {name} must be finite, got {_fmt(v)}")
    if v > MAX_EFFUSIVITY and not allow_inf:
        raise InputError(f"effusivity {name} must be at most {MAX_EFFUSIVITY:g} J s^-1/2 K^-1 m^-2 (the highest of any "
                         f"material, diamond's, is about 6e4), got {_fmt(v)}")
    return v


def check_effusivity_range(name: str, low: float, high: float) -> tuple[float, float]:
    """Check an effusivity class [low, high) with 0 <= low < high < inf.

    >>> check_effusivity_range("e1", 9999999.0, 10000079.0)
    Traceback (most recent call last):
    ...
    designkit._validation.InputError: effusivity class e1, [9999999, 10000079), ends above the highest effusivity accepted, 1e+07 J s^-1/2 K^-1 m^-2 (a value E is the class [E, E + 80)): give at most 9999920
    """
    lo = check_effusivity(f"{name} lower bound", low, allow_zero=True)
    try:
        hi = float(high)
    except (TypeError, ValueError):
        hi = math.nan
    if lo <= MAX_EFFUSIVITY and hi - lo > MAX_EFFUSIVITY:  # the width itself is beyond any effusivity
        raise InputError(f"effusivity class {name}: its width {hi - lo:.10g} is above the highest effusivity accepted, "
                         f"{MAX_EFFUSIVITY:g} J s^-1/2 K^-1 m^-2")
    if lo <= MAX_EFFUSIVITY < hi < math.inf:  # the class's end, which the user did not type, is what is too high
        raise InputError(f"effusivity class {name}, [{lo:.10g}, {hi:.10g}), ends above the highest effusivity "
                         f"accepted, {MAX_EFFUSIVITY:g} J s^-1/2 K^-1 m^-2 (a value E is the class [E, E + "
                         f"{hi - lo:.10g})): give at most {MAX_EFFUSIVITY - (hi - lo):.10g}")
    hi = check_effusivity(f"{name} upper bound", high)
    if not hi > lo:
        raise InputError(
            f"effusivity range {name} must have positive width, got [{_fmt(lo)}, {_fmt(hi)})"
        )
    return lo, hi


def as_generator(seed: "int | np.random.Generator | np.random.SeedSequence | list[int] | tuple[int, ...]") -> np.random.Generator:
    """Turn an explicit seed into a :class:`numpy.random.Generator`.

    ``None`` is refused: every random draw in designkit is reproducible. A
    sequence of non-negative integers (``[seed, interval, repeat]``) is hashed by
    :class:`numpy.random.SeedSequence`, which gives independent streams for
    different keys and the same stream for the same key on every machine.
    """
    import numpy as np

    if seed is None:
        raise InputError("a seed or numpy Generator is required (designkit never draws unseeded)")
    if isinstance(seed, np.random.Generator):
        return seed
    if isinstance(seed, np.random.SeedSequence):
        return np.random.Generator(np.random.PCG64(seed))
    if isinstance(seed, (list, tuple)):
        key = [int(k) for k in seed]
        if any(k < 0 for k in key):
            raise InputError(f"seed entries must be >= 0, got {key}")
        return np.random.Generator(np.random.PCG64(np.random.SeedSequence(key)))
    try:
        s = int(seed)
    except (TypeError, ValueError):
        raise InputError(f"seed must be a non-negative integer, got {_fmt(seed)}") from None
    if s < 0 or s != seed:
        raise InputError(f"seed must be a non-negative integer, got {_fmt(seed)}")
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(s)))
