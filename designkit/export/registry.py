"""The export formats by name, and the calls that slice a table and write it in one of them.

:data:`WRITERS` is the one registry: format name -> :class:`Writer` (its
module in :mod:`designkit.export.formats`, file suffixes, options). Modules load
on first use, so naming a format costs nothing until it is written (the
``.mat`` writer imports scipy only then).

==========  ==========  =======================================================
format      suffixes    what it is
==========  ==========  =======================================================
``json``    .json       data and provenance, strict JSON (null: NaN)
``csv``     .csv        one row per grid point; provenance in a ``.json`` sidecar
``npz``     .npz        NumPy arrays and provenance (no pickles)
``mat``     .mat        MATLAB / Octave variables and provenance
``c``       .h          a self-contained C99 header with the lookup functions
``python``  .py         a module needing only the standard library
==========  ==========  =======================================================

Adding a format is one module in ``formats/`` with ``write(exp, ...) -> bytes``
(and ``read(path)`` if it is data) plus one entry here.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .._validation import InputError
from ..tables.store import Table, load_table
from ._common import check_prefix, printable
from .slicing import EXPORT_FORMAT, Exported, slice_table

__all__ = [
    "FORMATS",
    "SUFFIXES",
    "WRITERS",
    "ExportResult",
    "Rendered",
    "Writer",
    "export_bytes",
    "export_table",
    "format_for",
    "get_writer",
    "read_export",
    "render",
]


@dataclass(frozen=True)
class Writer:
    """One export format.

    Attributes
    ----------
    name : str
        Format name (``--format``).
    module : str
        Module with ``write(exp, **options) -> bytes`` (and ``read(path)``,
        ``sidecar(exp, name)`` where the format has them).
    suffixes : tuple of str
        File suffixes that select it (the first is the usual one).
    description : str
        One line for people.
    options : tuple of str
        Keyword options ``write`` takes (``prefix`` for C).
    """

    name: str
    module: str
    suffixes: tuple[str, ...]
    description: str
    options: tuple[str, ...] = ()
    binary: bool = False

    def load(self):
        """The format's module (imported on first use)."""
        return importlib.import_module(self.module)

    @property
    def readable(self) -> bool:
        """Whether :func:`read_export` reads this format back (the data formats)."""
        return hasattr(self.load(), "read")

    def write(self, exp: Exported, **options: Any) -> bytes:
        """``exp`` in this format; options the format does not take are ignored."""
        return self.load().write(exp, **{k: v for k, v in options.items() if k in self.options})

    def sidecar_path(self, path: Path) -> Path | None:
        """Where the format writes a sidecar next to ``path`` (CSV: its provenance), or None."""
        mod = self.load()
        return mod.sidecar_path(path) if hasattr(mod, "sidecar") else None

    def sidecar(self, exp: Exported, name: str) -> bytes:
        """The sidecar of ``exp`` written as the file ``name`` (formats that have one)."""
        return self.load().sidecar(exp, name)


#: Format name -> writer: the registry of export formats.
WRITERS: dict[str, Writer] = {w.name: w for w in (
    Writer("json", "designkit.export.formats.json", (".json",), "JSON: data and provenance"),
    Writer("csv", "designkit.export.formats.csv", (".csv",),
           "CSV: one row per grid point (pandas.read_csv reads it as is); provenance in FILE.csv.json"),
    Writer("npz", "designkit.export.formats.npz", (".npz",), "NumPy npz: arrays and provenance", binary=True),
    Writer("mat", "designkit.export.formats.mat", (".mat",), "MATLAB .mat: arrays and provenance", binary=True),
    Writer("c", "designkit.export.formats.c", (".h",), "C99 header with the lookup functions", ("prefix",)),
    Writer("python", "designkit.export.formats.python", (".py",), "Python module (standard library only)"),
)}
#: The format names, in registry order.
FORMATS = tuple(WRITERS)
#: File suffix -> format name.
SUFFIXES = {s: w.name for w in WRITERS.values() for s in w.suffixes}


def get_writer(fmt: str) -> Writer:
    """The writer of format ``fmt`` (unknown: a one-line error listing the valid ones).

    Examples
    --------
    >>> get_writer("c").suffixes
    ('.h',)
    >>> get_writer("xml")
    Traceback (most recent call last):
    ...
    designkit._validation.InputError: format must be one of json, csv, npz, mat, c, python, got 'xml'
    """
    key = fmt.lower() if isinstance(fmt, str) else fmt
    if key not in WRITERS:
        raise InputError(f"format must be one of {', '.join(FORMATS)}, got {printable(repr(fmt))}")
    return WRITERS[key]


def format_for(out: str | Path, fmt: str | None) -> str:
    """The export format: ``fmt``, or the one ``out``'s suffix names.

    Examples
    --------
    >>> format_for("robot/table.h", None), format_for("-", "csv")
    ('c', 'csv')
    """
    if fmt is not None:
        return get_writer(fmt).name
    guess = SUFFIXES.get(Path(str(out)).suffix.lower())
    if guess is None:
        raise InputError(f"cannot tell the format from {printable(str(out))!r}: give --format ({', '.join(FORMATS)})")
    return guess


def render(exp: Exported, fmt: str, **options: Any) -> bytes:
    """The bytes of ``exp`` in format ``fmt`` (``prefix=`` for C)."""
    return get_writer(fmt).write(exp, **options)


# ============================================================ slice and write
@dataclass(frozen=True)
class Rendered:
    """An export in memory: its format, bytes, provenance, and the sliced table itself."""

    format: str
    data: bytes
    provenance: dict
    exported: Exported = field(repr=False)


@dataclass(frozen=True)
class ExportResult:
    """What :func:`export_table` wrote."""

    path: Path
    format: str
    size_bytes: int
    provenance: dict
    sidecar: Path | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"path": str(self.path), "format": self.format, "size_bytes": self.size_bytes,
                "sidecar": None if self.sidecar is None else str(self.sidecar), "provenance": self.provenance}


def export_bytes(table: "Table | str", fmt: str, *, prefix: str = "designkit", noise_c: float | None = None,
                 delta_t_c: float | None = None, contact=None, e_min: float | None = None,
                 e_max: float | None = None, kind: str = "svm") -> Rendered:
    """Slice ``table`` (see :func:`~designkit.export.slicing.slice_table`) and render it as format ``fmt``.

    Parameters
    ----------
    table : Table or name or path
    fmt : str
        One of :data:`FORMATS`.
    prefix : str
        C only: prefix of every function, macro and constant (a C identifier).
    noise_c, delta_t_c, contact, e_min, e_max, kind
        The slice (see :func:`~designkit.export.slicing.slice_table`).

    Returns
    -------
    Rendered
    """
    writer = get_writer(fmt)
    if "prefix" in writer.options:
        check_prefix(prefix)
    exp = slice_table(table, noise_c=noise_c, delta_t_c=delta_t_c, contact=contact, e_min=e_min, e_max=e_max,
                      kind=kind)
    return Rendered(writer.name, writer.write(exp, prefix=prefix), exp.provenance, exp)


def export_table(table: "Table | str", out: str | Path, fmt: str | None = None, *, prefix: str = "designkit",
                 noise_c: float | None = None, delta_t_c: float | None = None, contact=None,
                 e_min: float | None = None, e_max: float | None = None, kind: str = "svm") -> ExportResult:
    """Slice ``table`` and write it to the file ``out`` atomically, in ``fmt`` or the format its suffix names.

    A CSV export also writes its provenance next to it, as ``out`` + ``.json``
    (``ExportResult.sidecar``).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "robot.csv"
    >>> res = export_table("ideal-paper", out, noise_c=0.05, delta_t_c=10.0, contact="2")
    >>> res.format, res.sidecar.name, out.read_text().splitlines()[0]
    ('csv', 'robot.csv.json', 'noise_ratio,contact_s,e_ref,delta_up,delta_down')
    """
    from .._io import atomic_write_bytes

    path = Path(out)
    fmt = format_for(path, fmt)
    if path.is_dir():
        raise InputError(f"--out {printable(str(path))} is a folder; give a file name")
    writer = get_writer(fmt)
    side_path = writer.sidecar_path(path)
    if side_path is not None and side_path.is_dir():
        raise InputError(f"the sidecar {printable(str(side_path))} would replace a folder")
    tab = table if isinstance(table, Table) else load_table(table)  # loaded once: checked here, sliced below
    _check_not_the_source(tab, path, side_path)
    res = export_bytes(tab, fmt, prefix=prefix, noise_c=noise_c, delta_t_c=delta_t_c, contact=contact,
                       e_min=e_min, e_max=e_max, kind=kind)
    atomic_write_bytes(path, res.data)
    if side_path is not None:
        atomic_write_bytes(side_path, writer.sidecar(res.exported, path.name))
    return ExportResult(path=path, format=fmt, size_bytes=len(res.data), provenance=res.provenance,
                        sidecar=side_path)


def _check_not_the_source(table: Table, path: Path, sidecar: Path | None) -> None:
    """Refuse an export whose file or sidecar is the table it is read from (its ``.npz`` or ``.json``)."""
    src = table.path
    for out, what in ((path, f"--out {printable(str(path))}"),
                      (sidecar, f"the provenance sidecar {printable(str(sidecar))} of --out {printable(str(path))}")):
        if out is not None and out.exists() and any(out.samefile(f) for f in (src, src.with_suffix(".json"))):
            raise InputError(f"{what} is the table being exported ({printable(src.name)} or its .json); "
                             "write the export to another file")


def read_export(path: str | Path) -> Exported:
    """Read back a ``json``, ``csv`` (with its sidecar), ``npz`` or ``mat`` export (C and Python exports are code)."""
    p = Path(path)
    fmt = SUFFIXES.get(p.suffix.lower())
    readable = [n for n, w in WRITERS.items() if w.readable]
    if fmt not in readable:
        raise InputError(f"cannot read {printable(str(p))}: give a {', '.join('.' + n for n in readable)} export")
    try:
        exp = WRITERS[fmt].load().read(p)
    except OSError as exc:
        raise InputError(f"cannot read export {printable(str(p))}: {exc.strerror or exc}") from None
    except (KeyError, ValueError, TypeError, IndexError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError(f"{printable(str(p))} is not a readable designkit export "
                         f"({type(exc).__name__}: {printable(exc)})") from None
    if not isinstance(exp.provenance, dict) or exp.provenance.get("format") != EXPORT_FORMAT:
        raise InputError(f"{printable(str(p))} is not a designkit export")
    return exp

