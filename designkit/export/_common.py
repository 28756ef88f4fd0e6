"""Helpers shared by the export writers (the one home of them): names, escaping, templates.

Every string that an export embeds in generated code goes through one of the
escapers here, chosen for where it lands:

==================  ==========================================================
:func:`c_string`    a C string literal (octal escapes for everything outside
                    printable ASCII; ``\\``, ``"`` and ``?`` escaped, so no
                    trigraph can form)
:func:`c_comment`   text inside a ``/* ... */`` comment (one line, printable
                    ASCII, no ``*/``, ``/*`` or ``??`` left)
:func:`c_double`    a C double constant (``NAN`` / ``INFINITY`` from
                    ``<math.h>`` for non-finite values)
:func:`py_docstring`  a Python docstring (every ``"`` and ``\\`` escaped)
:func:`py_literal`  a Python literal of JSON-like data (checked with
                    :func:`ast.literal_eval`, ASCII only)
==================  ==========================================================

Names that an export cannot quote in every language (a table's or sensor's
name, a C prefix) are validated instead (:func:`check_name`,
:func:`check_prefix`).
"""

from __future__ import annotations

import ast
import pprint
import re
import shlex
from importlib import resources
from typing import TYPE_CHECKING, Any, Mapping

from .._validation import InputError

if TYPE_CHECKING:  # pragma: no cover
    from .slicing import Axis, Exported

__all__ = [
    "NAME_RULE",
    "c_comment",
    "c_double",
    "c_string",
    "check_name",
    "check_prefix",
    "fill_template",
    "log_grid",
    "printable",
    "py_docstring",
    "py_literal",
    "read_template",
    "regenerate_command",
    "slice_lines",
]

_NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9 ._+-]{0,99}")
#: What a table or sensor name may hold, in words (the error messages say it).
NAME_RULE = "a letter or digit, then up to 99 letters, digits, spaces or . _ + -"
_PREFIX_RE = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,39}")
_PLACEHOLDER = re.compile(r"@([A-Za-z0-9_]+)@")


# ============================================================ names
def check_name(what: str, name: Any) -> str:
    """``name`` if it is a safe name (see :data:`NAME_RULE`), else a one-line :class:`InputError`.

    Examples
    --------
    >>> check_name("table name", "svm-paper")
    'svm-paper'
    >>> check_name("table name", 'x */ int y; /*')
    Traceback (most recent call last):
    ...
    designkit._validation.InputError: table name 'x */ int y; /*' cannot be exported safely: it must be a letter or digit, then up to 99 letters, digits, spaces or . _ + -
    """
    if not isinstance(name, str) or not _NAME_RE.fullmatch(name):
        raise InputError(f"{what} {printable(repr(name))[:120]} cannot be exported safely: it must be {NAME_RULE}")
    return name


def check_prefix(prefix: Any) -> str:
    """A C prefix: a letter, then up to 39 letters, digits or ``_`` (the whole string, no newline).

    Examples
    --------
    >>> check_prefix("robot_arm")
    'robot_arm'
    >>> check_prefix("designkit\\n")
    Traceback (most recent call last):
    ...
    designkit._validation.InputError: prefix must be a C identifier (a letter, then letters, digits or _; up to 40), got 'designkit\\n'
    """
    if not isinstance(prefix, str) or not _PREFIX_RE.fullmatch(prefix):
        raise InputError(f"prefix must be a C identifier (a letter, then letters, digits or _; up to 40), "
                         f"got {printable(repr(prefix))}")
    return prefix


# ============================================================ escaping
def printable(s: Any) -> str:
    """``str(s)`` on one line of printable ASCII: other characters as ``\\xNN``, ``\\uNNNN`` or ``\\UNNNNNNNN``.

    Examples
    --------
    >>> printable("a\\nb \\u00b0C")
    'a\\\\x0ab \\\\xb0C'
    """
    out = []
    for ch in str(s):
        o = ord(ch)
        if 0x20 <= o < 0x7F:
            out.append(ch)
        elif o < 0x100:
            out.append(f"\\x{o:02x}")
        elif o < 0x10000:
            out.append(f"\\u{o:04x}")
        else:
            out.append(f"\\U{o:08x}")
    return "".join(out)


def c_string(s: Any) -> str:
    """A C99 string literal holding the UTF-8 bytes of ``str(s)``.

    Examples
    --------
    >>> print(c_string('a"b??/ \\u00b0'))
    "a\\"b\\?\\?/ \\302\\260"
    """
    out = ['"']
    for b in str(s).encode("utf-8", "backslashreplace"):
        ch = chr(b)
        if ch in '\\"?':
            out.append("\\" + ch)
        elif 0x20 <= b < 0x7F:
            out.append(ch)
        else:
            out.append(f"\\{b:03o}")
    out.append('"')
    return "".join(out)


def c_comment(s: Any) -> str:
    """Text safe inside a C block comment: one line of printable ASCII that cannot end the comment.

    A space goes between ``*`` and ``/`` in either order (no ``*/``, and no
    ``/*`` for ``-Wcomment``) and between two ``?`` (no trigraph).

    Examples
    --------
    >>> c_comment("x */ int y; /* ??/")
    'x * / int y; / * ? ?/'
    """
    text = printable(s)
    return re.sub(r"(?<=/)(?=\*)|(?<=\*)(?=/)|(?<=\?)(?=\?)", " ", text).rstrip()


def c_double(x: Any) -> str:
    """A C double constant: the shortest round-trip text, or ``NAN`` / ``INFINITY`` (``<math.h>``).

    Examples
    --------
    >>> c_double(0.1), c_double(float("nan")), c_double(-float("inf"))
    ('0.1', 'NAN', '(-INFINITY)')
    """
    v = float(x)
    if v != v:
        return "NAN"
    if v in (float("inf"), float("-inf")):
        return "INFINITY" if v > 0 else "(-INFINITY)"
    return repr(v)


def py_docstring(text: str) -> str:
    """A triple-quoted Python string literal of ``text`` (lines kept; ``\\`` and ``"`` escaped).

    Examples
    --------
    >>> import ast
    >>> payload = "x" + '"' * 3 + "; import os"
    >>> ast.literal_eval(py_docstring(payload)) == payload + "\\n"
    True
    """
    body = "\n".join(printable(line) for line in str(text).split("\n"))
    return '"""' + body.replace("\\", "\\\\").replace('"', '\\"') + '\n"""'


def py_literal(obj: Any, *, width: int = 100) -> str:
    """A Python literal of JSON-like data (dicts, lists, str, numbers, bool, None), ASCII only.

    Raises
    ------
    ValueError
        The data does not round-trip through :func:`ast.literal_eval` (a
        non-finite float, an object that is not plain data).

    Examples
    --------
    >>> py_literal({"name": 'x"; import os', "n": 2})
    '{\\'name\\': \\'x"; import os\\', \\'n\\': 2}'
    """
    text = pprint.pformat(obj, width=width, sort_dicts=False).encode("ascii", "backslashreplace").decode("ascii")
    try:
        ok = ast.literal_eval(text) == obj
    except (ValueError, SyntaxError):
        ok = False
    if not ok:
        raise ValueError("export data is not plain JSON-like data (a non-finite number or an object?)")
    return text


# ============================================================ templates
def read_template(name: str) -> str:
    """The text of ``designkit/export/templates/<name>`` (shipped as package data)."""
    return resources.files("designkit.export").joinpath("templates", name).read_text(encoding="utf-8")


def fill_template(template: str, values: Mapping[str, str]) -> str:
    """Replace every ``@KEY@`` in ``template`` by ``values[KEY]``, in one pass.

    Replacement text is never scanned again, so a value that itself holds
    ``@KEY@`` stays as it is. A placeholder without a value is a bug in the
    writer (KeyError).

    Examples
    --------
    >>> fill_template("int @p@_x = @N@;", {"p": "dk", "N": "@p@"})
    'int dk_x = @p@;'
    """
    def sub(m: re.Match) -> str:
        key = m.group(1)
        if key not in values:
            raise KeyError(f"template placeholder @{key}@ has no value")
        return values[key]

    return _PLACEHOLDER.sub(sub, template)


# ============================================================ texts about a slice
def log_grid(a: "Axis") -> list[float]:
    """The grid an axis is interpolated on: numpy's ``log(values)`` for a log axis, else its values."""
    import numpy as np

    return np.log(np.asarray(a.values)).tolist() if a.scale == "log" and min(a.values) > 0 else list(a.values)


def regenerate_command(exp: "Exported", fmt: str, prefix: str | None) -> str:
    """The ``designkit export`` command line that writes this export again (shell-quoted)."""
    p, s = exp.provenance, exp.provenance["slice"]
    table = exp.source_ref if exp.source_ref is not None else p["source_table"]
    cmd = [f"designkit export --table {shlex.quote(str(table))} --format {fmt}"]
    if s["scene"]:
        cmd.append(f"--noise {s['scene']['noise_c']!r} --delta-t {s['scene']['delta_t_c']!r}")
    if s["contact_s"]:
        cmd += [f"--contact {r[0]!r}:{r[1]!r}" if isinstance(r, list) else f"--contact {r!r}"
                for r in s["contact_s"]["requested"]]
    if s["effusivity"]:
        for key in ("e_min", "e_max"):
            if s["effusivity"][key] is not None:
                cmd.append(f"--{key.replace('_', '-')} {s['effusivity'][key]!r}")
    if p["kind"] != "svm":
        cmd.append(f"--kind {p['kind']}")
    if prefix and prefix != "designkit":
        cmd.append(f"--prefix {prefix}")
    return " ".join(cmd) + " --out FILE"


def slice_lines(exp: "Exported") -> list[str]:
    """Human description of the slice taken, one line per axis."""
    s = exp.provenance["slice"]
    out = []
    if s["scene"]:
        sc = s["scene"]
        out.append(f"scene: noise {sc['noise_c']:g} degC, dT {sc['delta_t_c']:g} degC"
                   + (f" (sigma/dT {sc['noise_ratio']:g})" if "noise_ratio" in sc else "")
                   + ", combined from source rows " + ", ".join(f"{r['index']} x {r['weight']:.6g}" for r in sc["rows"]))
    else:
        out.append("scene: all " + " x ".join(f"{len(a.values)} {a.name}" for a in exp.scene_axes) + " rows")
    c = exp.contact.values
    if s["contact_s"]:
        out.append(f"contact: requested {s['contact_s']['requested']}, kept source columns "
                   f"{s['contact_s']['source_columns']} = {list(c)} s")
    else:
        out.append(f"contact: all {len(c)} columns {c[0]:g}..{c[-1]:g} s")
    frame = exp.provenance.get("contact_frame") or {}
    if frame.get("onset_offset_s") is not None:  # a calibrated rig's: its controller counts from the onset
        out.append(f"contact times count from {frame['counted_from']}: {frame['from_onset']}")
    ea = exp.provenance["effusivity_answered"]
    out.append(f"effusivity answered: {ea['min']:g} {'<=' if ea['min_inclusive'] else '<'} e <= {ea['max']:g}, "
               f"{len(exp.e_ref.values)} reference intervals (centres {exp.e_ref.values[0]:g}..{exp.e_ref.values[-1]:g})")
    return out
