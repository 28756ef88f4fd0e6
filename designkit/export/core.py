"""Lookup tables for projects where designkit does not run: JSON, CSV, NumPy, C99, stdlib Python.

A robot controller or a microcontroller needs the answers of :mod:`designkit.query`
(how long to touch, is this pair separable, what is delta(e)) without numpy,
scikit-learn or designkit itself. This module cuts a table down to what a
deployment needs and writes it in one of five formats:

``json``, ``csv``, ``npz``
    the data (delta(e) towards higher and lower effusivity on the table's
    axes) and its provenance, for other languages and analysis tools.
``c``
    one self-contained C99 header: ``static const`` arrays (no allocation, only
    ``<math.h>``) and the functions ``PREFIX_delta_e``, ``PREFIX_delta_e_lower``,
    ``PREFIX_delta_e_upper``, ``PREFIX_min_contact_s`` and
    ``PREFIX_distinguishable``.
``python``
    one module that needs only the standard library, with ``delta_e``,
    ``delta_e_lower``, ``delta_e_upper``, ``min_contact_s`` and
    ``distinguishable``.

What a deployment needs (leave out the rest)
--------------------------------------------
``noise_c`` and ``delta_t_c`` select one scene: the table's sigma/dT rows (or
sigma and dT rows) are combined with the query's weights (log-linear in
sigma/dT) into one row. Because :meth:`designkit.query._View.need` sums over
the scene weights *before* taking the maximum of the two directions, the
combined row gives the same answers as the full table for that scene.
``contact`` keeps the contact-time columns a robot uses (single values keep
the one or two columns that interpolate them; ranges ``(a, b)`` keep every
column between, plus the neighbours that bracket the ends). ``e_min`` and
``e_max`` keep the reference intervals needed to interpolate delta(e) anywhere
in ``[e_min, e_max]``, i.e. one interval of margin on each side.

Semantics (the same as :mod:`designkit.query`)
----------------------------------------------
* delta(e) is interpolated linearly in effusivity between interval centres
  (``_interp_e``: a NaN neighbour gives NaN), linearly in contact time and
  log-linearly in sigma/dT (or sigma) and linearly in dT between grid rows
  (``_axis_weights``); nothing is extrapolated: an input outside the grid gets
  no answer.
* Separating ``lo < hi`` needs the distance ``max(delta_up(lo),
  delta_down(hi))`` (NaN: no partner within the grid: not separable).
* ``min_contact_s``: the first contact column whose need is at most
  ``hi - lo``, interpolated linearly towards the previous column
  (``_crossing``).
* ``distinguishable``: the need interpolated at the contact time is at most
  ``hi - lo``.
* ``delta_e``: the smaller of the two directions (``query.delta_e``'s value).

Two additions for slices, both refusing rather than guessing: a slice answers
only its own scene (noise/dT must match it to within float precision), and an
answer that would interpolate between two kept contact columns that are not
neighbours in the source table is refused (``delta_e``, ``distinguishable``)
or taken at the longer column (``min_contact_s``: the shortest *exported*
contact time that suffices).

Sentinels (C), ``None``/exceptions (Python)
--------------------------------------------
==================  ===========================  ===============================
meaning             C (float / int functions)    generated Python module
==================  ===========================  ===============================
answer              ``>= 0`` / ``1`` or ``0``    float / ``True`` or ``False``
nothing suffices    ``PREFIX_NONE`` (-1)         ``None``
outside the grid    ``PREFIX_OUTSIDE`` (-2)      raises ``OutsideTable``
invalid input       ``PREFIX_INVALID`` (-3)      raises ``ValueError``
==================  ===========================  ===============================

"Nothing suffices" is: no tabulated contact time separates the pair
(``min_contact_s``), or no distinguishable effusivity within the grid in
either direction (``delta_e``). Invalid input is what :mod:`designkit.query`
refuses with ``InputError``: NaN or infinite values, effusivity ``<= 0``,
noise ``< 0``, ``dT == 0``, contact ``<= 0``, ``e1 == e2``.
"""

from __future__ import annotations

import base64
import hashlib
import io
import json
import math
import pprint
import re
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from .._validation import InputError, check_finite, check_nonnegative, check_positive
from ..tables.store import E_UNITS, Table, content_hash, load_table

__all__ = [
    "EXPORT_FORMAT",
    "FORMATS",
    "KINDS",
    "ExportResult",
    "Exported",
    "export_table",
    "parse_contact",
    "read_export",
    "render",
    "slice_table",
]

EXPORT_FORMAT = "designkit-export"
EXPORT_SCHEMA = 1
FORMATS = ("json", "csv", "npz", "c", "python")
SUFFIXES = {".json": "json", ".csv": "csv", ".npz": "npz", ".h": "c", ".py": "python"}
KINDS = ("svm", "lo", "hi", "ideal")
_KIND_SUFFIX = {"svm": "", "lo": "_lo", "hi": "_hi", "ideal": "_ideal"}
_KIND_MEANING = {
    "svm": "delta of the table's classifier (the value designkit's queries answer)",
    "lo": "optimistic end of the Monte Carlo interval of delta (query intervals' first end)",
    "hi": "conservative end of the Monte Carlo interval of delta (query intervals' second end)",
    "ideal": "ideal observer's delta (the bound no classifier can beat)",
}
_PREFIX_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,39}$")
# A value within this relative distance of a grid value is that grid value (the rule of
# designkit.query.GRID_RTOL: a float argument such as 0.2f / 10.0f cannot hit a sigma/dT
# grid value of 0.02 more closely than about 1e-7).
from ..query.table import GRID_RTOL as C_EDGE_RTOL  # noqa: E402


# ============================================================ the sliced data
@dataclass(frozen=True)
class Axis:
    """One axis of an export: name, units, scale ("log" or "linear") and grid values."""

    name: str
    units: str
    scale: str
    values: tuple[float, ...]

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "units": self.units, "scale": self.scale, "values": list(self.values)}


@dataclass(frozen=True, eq=False)
class Exported:
    """A table, or the slice of it a deployment needs, ready to be written.

    Attributes
    ----------
    axes : tuple of Axis
        Scene axes (``noise_ratio``, or ``noise_c`` and ``delta_t_c``), then
        ``contact_s`` and ``e_ref``, in array order.
    delta_up, delta_down : ndarray
        float64, shape ``[scene..., contact, e_ref]``: delta(e) towards higher
        / lower effusivity [J s^-1/2 K^-1 m^-2]; NaN where no distinguishable
        partner lies inside the grid.
    contact_adjacent : tuple of bool
        ``contact_adjacent[k]``: contact columns ``k`` and ``k + 1`` are
        neighbours in the source table (interpolating between them is the
        source table's interpolation).
    e_lo, e_hi, e_lo_inclusive : float, float, bool
        Effusivities answered: ``e_lo < e <= e_hi`` (``<=`` at ``e_lo`` when
        inclusive: a slice's ``--e-min``).
    provenance : dict
        Source table, its content hash, sensor, fidelity, threshold, kind,
        versions, the slice taken, and ``export_hash``.
    """

    axes: tuple[Axis, ...]
    delta_up: np.ndarray
    delta_down: np.ndarray
    contact_adjacent: tuple[bool, ...]
    e_lo: float
    e_hi: float
    e_lo_inclusive: bool
    provenance: dict

    @property
    def scene_axes(self) -> tuple[Axis, ...]:
        return self.axes[:-2]

    @property
    def contact(self) -> Axis:
        return self.axes[-2]

    @property
    def e_ref(self) -> Axis:
        return self.axes[-1]

    @property
    def shape(self) -> tuple[int, ...]:
        return self.delta_up.shape


@dataclass(frozen=True)
class ExportResult:
    """What :func:`export_table` wrote."""

    path: Path
    format: str
    size_bytes: int
    provenance: dict

    def to_dict(self) -> dict[str, Any]:
        return {"path": str(self.path), "format": self.format, "size_bytes": self.size_bytes,
                "provenance": self.provenance}


# ============================================================ slicing
def parse_contact(items: Sequence[Any] | str | float | None) -> tuple[float | tuple[float, float], ...] | None:
    """Contact-time request from text: ``"2"``, ``"1:4"`` (a range), ``"1,2,3"``, or a list of these.

    Returns a tuple of single values [s] and ``(a, b)`` ranges, or None.
    """
    if items is None:
        return None
    if isinstance(items, (str, int, float)) or (isinstance(items, tuple) and len(items) == 2
                                                   and all(isinstance(x, (int, float)) for x in items)):
        items = [items]
    out: list[float | tuple[float, float]] = []
    for item in items:
        if isinstance(item, tuple):
            a, b = (check_positive("contact time [s]", x) for x in item)
            out.append((a, b))
            continue
        if isinstance(item, (int, float)):
            out.append(check_positive("contact time [s]", item))
            continue
        for part in str(item).replace(" ", "").split(","):
            if not part:
                continue
            if ":" in part:
                lo, _, hi = part.partition(":")
                try:
                    a, b = float(lo), float(hi)
                except ValueError:
                    raise InputError(f"contact range must look like 1:4 (seconds), got {part!r}") from None
                out.append((check_positive("contact time [s]", a), check_positive("contact time [s]", b)))
            else:
                try:
                    v = float(part)
                except ValueError:
                    raise InputError(f"contact time must be a number or a range like 1:4, got {part!r}") from None
                out.append(check_positive("contact time [s]", v))
    if not out:
        raise InputError("--contact is empty")
    for r in out:
        if isinstance(r, tuple) and not r[0] <= r[1]:
            raise InputError(f"contact range {r[0]:g}:{r[1]:g} must go from shorter to longer")
    return tuple(out)


def _kept_contacts(contacts: np.ndarray, request) -> list[int]:
    """Source contact columns needed to answer at every requested contact time."""
    from ..query.table import _axis_weights

    def needed(c: float) -> list[int]:
        pts, ok = _axis_weights(contacts, c, log=False)
        if not ok:
            raise InputError(f"contact time {c:g} s is outside the table's contact grid "
                             f"[{contacts[0]:g}, {contacts[-1]:g}] s (no extrapolation)")
        return [k for k, w in pts if w != 0] or [pts[0][0]]

    keep: set[int] = set()
    for item in request:
        if isinstance(item, tuple):
            lo, hi = needed(item[0]), needed(item[1])
            keep.update(range(min(lo), max(hi) + 1))
        else:
            keep.update(needed(item))
    return sorted(keep)


def _kept_centres(centres: np.ndarray, a: float, b: float) -> tuple[int, int]:
    """First and last reference interval needed to interpolate delta(e) like ``_interp_e`` on [a, b].

    ``_interp_e`` uses the centres j, j + 1 with ``centres[j] <= e < centres[j + 1]``
    (an ``e`` on a centre reads that centre only), and clamps at the ends.
    """
    n = centres.size
    i0 = max(int(np.searchsorted(centres, a, side="right")) - 1, 0)
    i1 = min(int(np.searchsorted(centres, b, side="left")), n - 1)
    return i0, i1


def _array_names(table: Table, kind: str) -> tuple[str, str]:
    """delta arrays of ``kind``, with query.need's fallback for tables that hold only delta_up/down."""
    if kind not in KINDS:
        raise InputError(f"kind must be one of {', '.join(KINDS)}, got {kind!r}")
    sfx = _KIND_SUFFIX[kind]
    up, down = f"delta_up{sfx}", f"delta_down{sfx}"
    if up not in table.arrays:
        up, down = "delta_up", "delta_down"
    return up, down


def slice_table(table: "Table | str", *, noise_c: float | None = None, delta_t_c: float | None = None,
                contact=None, e_min: float | None = None, e_max: float | None = None,
                kind: str = "svm") -> Exported:
    """The part of ``table`` a deployment needs, interpolated exactly as :mod:`designkit.query` does.

    Parameters
    ----------
    table : Table or name or path
    noise_c, delta_t_c : float, optional
        Together: one scene (noise sigma per sample [degC], sensor minus object
        temperature [degC]); the scene rows are combined with
        ``query._View.scene_weights`` (log-linear in sigma/dT).
    contact : str, float, or sequence, optional
        Contact times [s] a deployment uses: values and ``(a, b)`` ranges (see
        :func:`parse_contact`).
    e_min, e_max : float, optional
        Effusivity range [J s^-1/2 K^-1 m^-2] that must be answered (inclusive).
    kind : {"svm", "lo", "hi", "ideal"}
        Which delta arrays: the classifier's value, the ends of its Monte Carlo
        interval, or the ideal observer's.

    Returns
    -------
    Exported
    """
    from .. import __version__
    from ..query.table import _View

    tab = table if isinstance(table, Table) else load_table(table)
    up_name, down_name = _array_names(tab, kind)
    up, down = np.asarray(tab.arrays[up_name], dtype=np.float64), np.asarray(tab.arrays[down_name], dtype=np.float64)
    view = _View(tab)
    hdr = tab.header
    ax_meta = {a["name"]: a for a in hdr["axes"]}
    scene_names = view.scene_axes
    slice_info: dict[str, Any] = {"scene": None, "contact_s": None, "effusivity": None}

    # ---- scene: one combined row
    if (noise_c is None) != (delta_t_c is None):
        raise InputError("give --noise and --delta-t together (one scene), or neither (all scenes)")
    if noise_c is not None:
        noise = check_nonnegative("noise sigma [degC]", noise_c)
        dt = check_finite("temperature difference [degC]", delta_t_c)
        if dt == 0:
            raise InputError("temperature difference is 0: an unheated sensor sees no contrast between materials")
        combos, flags = view.scene_weights(noise, dt)
        bad = [k for k, ok in flags.items() if not ok]
        if bad:
            ranges = ", ".join(f"{k} [{min(ax_meta[k]['values']):g}, {max(ax_meta[k]['values']):g}]" for k in bad)
            raise InputError(f"noise {noise:g} degC, dT {dt:g} degC lies outside table {tab.name}'s grid "
                             f"along {ranges} (no extrapolation)")

        def combine(arr: np.ndarray) -> np.ndarray:
            total = np.zeros(arr.shape[len(scene_names):])
            for idx, w in combos:
                if w == 0:
                    continue
                total = total + w * arr[idx]  # NaN in any weighted row stays NaN, as in _View.delta_at
            return total[(None,) * len(scene_names)]

        up, down = combine(up), combine(down)
        if scene_names == ["noise_ratio"]:
            point = {"noise_ratio": noise / abs(dt)}
        else:
            point = {"noise_c": noise, "delta_t_c": dt}
        scene_axes = [Axis(n, ax_meta[n]["units"], ax_meta[n]["scale"], (float(point[n]),)) for n in scene_names]
        slice_info["scene"] = {"noise_c": noise, "delta_t_c": dt, **point,
                               "rows": [{"index": list(idx), "weight": w} for idx, w in combos if w != 0]}
    else:
        scene_axes = [Axis(n, ax_meta[n]["units"], ax_meta[n]["scale"], tuple(float(v) for v in ax_meta[n]["values"]))
                      for n in scene_names]

    # ---- contact columns
    contacts = view.contacts
    request = parse_contact(contact)
    if request is not None:
        cols = _kept_contacts(contacts, request)
        slice_info["contact_s"] = {"requested": [list(r) if isinstance(r, tuple) else r for r in request],
                                   "source_columns": cols}
    else:
        cols = list(range(contacts.size))
    up, down = up[..., cols, :], down[..., cols, :]
    adjacent = tuple(bool(cols[k + 1] == cols[k] + 1) for k in range(len(cols) - 1))

    # ---- effusivity
    centres = view.centres
    e_lo, e_hi, inclusive = view.e_lo, view.e_hi, False
    if e_min is not None or e_max is not None:
        a = check_finite("--e-min", e_min) if e_min is not None else None
        b = check_finite("--e-max", e_max) if e_max is not None else None
        grid = f"({view.e_lo:g}, {view.e_hi:g}]"
        if a is not None:
            if not (view.e_lo <= a <= view.e_hi):
                raise InputError(f"--e-min {a:g} is outside table {tab.name}'s effusivity grid {grid}")
            if a > view.e_lo:
                e_lo, inclusive = a, True
        if b is not None:
            if not (view.e_lo < b <= view.e_hi):
                raise InputError(f"--e-max {b:g} is outside table {tab.name}'s effusivity grid {grid}")
            e_hi = b
        if not e_hi > e_lo:
            raise InputError(f"--e-min must be below --e-max, got {e_lo:g} and {e_hi:g}")
        i0, i1 = _kept_centres(centres, e_lo, e_hi)
        slice_info["effusivity"] = {"e_min": a, "e_max": b, "source_intervals": [i0, i1]}
    else:
        i0, i1 = 0, centres.size - 1
    up, down = up[..., i0:i1 + 1], down[..., i0:i1 + 1]
    up, down = np.ascontiguousarray(up), np.ascontiguousarray(down)

    for name, arr in (("delta_up", up), ("delta_down", down)):
        finite = arr[~np.isnan(arr)]
        if np.isinf(arr).any() or (finite < 0).any():
            raise InputError(f"table {tab.name}: {name} holds negative or infinite values; not a delta table")

    axes = tuple(scene_axes) + (
        Axis("contact_s", ax_meta["contact_s"]["units"], "linear", tuple(float(contacts[k]) for k in cols)),
        Axis("e_ref", E_UNITS, "linear", tuple(float(c) for c in centres[i0:i1 + 1])),
    )
    export_hash = content_hash({"delta_up": up, "delta_down": down,
                                **{f"axis_{a.name}": np.asarray(a.values) for a in axes}})
    sensor = hdr["sensor"]
    provenance = {
        "format": EXPORT_FORMAT,
        "schema_version": EXPORT_SCHEMA,
        "source_table": tab.name,
        "source_content_hash": hdr.get("content_hash"),
        "source_created": hdr.get("created"),
        "source_designkit_version": hdr.get("designkit_version"),
        "designkit_version": __version__,
        "fidelity": tab.fidelity,
        "threshold": tab.threshold,
        "trials": hdr.get("trials"),
        "sensor": sensor,
        "kind": kind,
        "kind_meaning": (_KIND_MEANING[kind] if tab.fidelity == "svm" or up_name != "delta_up"
                         else "delta of the ideal observer (an ideal-fidelity table holds only that)"),
        "source_arrays": {"delta_up": up_name, "delta_down": down_name},
        "units": {"delta": E_UNITS, "effusivity": E_UNITS, "contact_s": "s", "noise_c": "degC",
                  "delta_t_c": "degC", "noise_ratio": "1 (sigma / dT)"},
        "axes": [{"name": a.name, "units": a.units, "scale": a.scale, "points": len(a.values),
                  "min": min(a.values), "max": max(a.values)} for a in axes],
        "effusivity_answered": {"min": e_lo, "min_inclusive": inclusive, "max": e_hi, "max_inclusive": True,
                                "units": E_UNITS},
        "slice": slice_info,
        "shape": list(up.shape),
        "nan_means": "no distinguishable partner within the table's effusivity grid (not separable)",
        "decision_rule": "lo < hi are distinguishable when hi - lo >= max(delta_up(lo), delta_down(hi))",
        "interpolation": ("linear in e_ref between interval centres (a NaN neighbour gives NaN), linear in "
                          "contact_s and delta_t_c, log-linear in noise_ratio and noise_c; no extrapolation"),
        "export_hash": export_hash,
    }
    return Exported(axes=axes, delta_up=up, delta_down=down, contact_adjacent=adjacent, e_lo=float(e_lo),
                    e_hi=float(e_hi), e_lo_inclusive=inclusive, provenance=provenance)


# ============================================================ formats
def _nan_to_none(a: np.ndarray) -> list:
    return np.where(np.isnan(a), None, a).tolist() if a.size else []


def _structure(exp: Exported) -> dict[str, Any]:
    return {"axes": [a.to_dict() for a in exp.axes], "contact_adjacent": list(exp.contact_adjacent),
            "effusivity_answered": exp.provenance["effusivity_answered"]}


def to_json(exp: Exported) -> bytes:
    """JSON: provenance, axes, and the two arrays as nested lists (null = NaN = none within the grid)."""
    doc = {"format": EXPORT_FORMAT, "schema_version": EXPORT_SCHEMA, "provenance": exp.provenance,
           **_structure(exp), "array_order": [a.name for a in exp.axes]}
    head = json.dumps(doc, indent=1, allow_nan=False)
    body = ",\n".join(f' "{name}": ' + json.dumps(_nan_to_none(arr), separators=(",", ":"), allow_nan=False)
                      for name, arr in (("delta_up", exp.delta_up), ("delta_down", exp.delta_down)))
    return (head[:-2] + ",\n" + body + "\n}\n").encode()


def _num_strings(a: np.ndarray, nan: str) -> np.ndarray:
    """Shortest round-trip text of every float64 value (formatted once per distinct value)."""
    flat = a.ravel()
    u, inv = np.unique(flat, return_inverse=True)
    text = np.array([nan if math.isnan(x) else repr(float(x)) for x in u.tolist()] or [""], dtype=object)
    return text[inv.ravel()] if flat.size else np.array([], dtype=object)


def to_csv(exp: Exported) -> bytes:
    """CSV, one row per grid point: scene axes, contact_s, e_ref, delta_up, delta_down ("nan": none).

    The column names come first, then the provenance as ``#`` comment lines (the
    last one is the provenance as one line of JSON), then the data: read with
    ``pandas.read_csv(path, comment="#")`` or ``numpy.genfromtxt(path,
    delimiter=",", names=True)`` (both skip the comments; numpy would take a
    leading comment line for the column names, hence this order).
    """
    grids = np.meshgrid(*[np.asarray(a.values) for a in exp.axes], indexing="ij")
    cols = [_num_strings(g, "nan") for g in grids] + [_num_strings(exp.delta_up, "nan"),
                                                      _num_strings(exp.delta_down, "nan")]
    p = exp.provenance
    names = ",".join([a.name for a in exp.axes] + ["delta_up", "delta_down"])
    lines = [names, f"# designkit export of table {p['source_table']} ({p['source_content_hash']})",
             f"# fidelity {p['fidelity']}, kind {p['kind']}, threshold F1 >= {p['threshold']:g}, "
             f"sensor {p['sensor'].get('name')}, designkit {p['designkit_version']}",
             f"# delta_up/delta_down: {E_UNITS}; nan = {p['nan_means']}",
             f"# {p['decision_rule']}; interpolation: {p['interpolation']}",
             "# units: " + ", ".join(f"{a.name} [{a.units}]" for a in exp.axes),
             "# contact_adjacent: " + json.dumps(list(exp.contact_adjacent)),
             "# provenance: " + json.dumps(p, separators=(",", ":"), allow_nan=False)]
    rows = map(",".join, zip(*[c.tolist() for c in cols]))
    return ("\n".join(lines) + "\n" + "\n".join(rows) + "\n").encode()


def to_npz(exp: Exported) -> bytes:
    """NumPy ``.npz`` (compressed, no pickles): ``delta_up``, ``delta_down``, ``axis_<name>``,
    ``contact_adjacent``, ``array_order``, and ``provenance`` (a JSON string)."""
    arrays = {"delta_up": exp.delta_up, "delta_down": exp.delta_down,
              "contact_adjacent": np.asarray(exp.contact_adjacent, dtype=bool),
              "array_order": np.asarray([a.name for a in exp.axes]),
              "axis_scales": np.asarray([a.scale for a in exp.axes]),
              "provenance": np.asarray(json.dumps(exp.provenance, allow_nan=False))}
    for a in exp.axes:
        arrays[f"axis_{a.name}"] = np.asarray(a.values, dtype=np.float64)
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    return buf.getvalue()


def read_export(path: str | Path) -> Exported:
    """Read back a ``json``, ``csv`` or ``npz`` export (the C and Python exports are code)."""
    p = Path(path)
    fmt = SUFFIXES.get(p.suffix.lower())
    try:
        if fmt == "json":
            doc = json.loads(p.read_text())
            axes = tuple(Axis(a["name"], a["units"], a["scale"], tuple(a["values"])) for a in doc["axes"])
            arr = {k: np.array(doc[k], dtype=np.float64) for k in ("delta_up", "delta_down")}  # None -> nan
            prov, adjacent = doc["provenance"], doc["contact_adjacent"]
        elif fmt == "npz":
            with np.load(p, allow_pickle=False) as z:
                prov = json.loads(str(z["provenance"]))
                scales = [str(s) for s in z["axis_scales"]]
                names = [str(s) for s in z["array_order"]]
                units = {a["name"]: a["units"] for a in prov["axes"]}
                axes = tuple(Axis(n, units[n], s, tuple(z[f"axis_{n}"].tolist())) for n, s in zip(names, scales))
                arr = {k: z[k] for k in ("delta_up", "delta_down")}
                adjacent = z["contact_adjacent"].tolist()
        elif fmt == "csv":
            text = p.read_text()
            prov = adjacent = None
            for line in text.splitlines():
                if line.startswith("# provenance: "):
                    prov = json.loads(line[len("# provenance: "):])
                elif line.startswith("# contact_adjacent: "):
                    adjacent = json.loads(line[len("# contact_adjacent: "):])
            if prov is None or adjacent is None:
                raise InputError(f"{p} is not a designkit CSV export (no provenance line)")
            data = np.genfromtxt(io.StringIO(text), delimiter=",", comments="#", skip_header=0, names=True)
            shape = tuple(prov["shape"])
            names = [a["name"] for a in prov["axes"]]
            axes = tuple(Axis(a["name"], a["units"], a["scale"],
                              tuple(np.unique(np.atleast_1d(data[a["name"]])).tolist())) for a in prov["axes"])
            if tuple(len(a.values) for a in axes) != shape:
                raise InputError(f"{p}: axes do not match the shape in its provenance")
            order = np.lexsort([np.atleast_1d(data[n]) for n in reversed(names)])
            arr = {k: np.atleast_1d(data[k])[order].reshape(shape) for k in ("delta_up", "delta_down")}
        else:
            raise InputError(f"cannot read {p}: give a .json, .csv or .npz export")
    except OSError as exc:
        raise InputError(f"cannot read export {p}: {exc.strerror or exc}") from None
    except (KeyError, ValueError, TypeError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError(f"{p} is not a readable designkit export ({type(exc).__name__}: {exc})") from None
    if prov.get("format") != EXPORT_FORMAT:
        raise InputError(f"{p} is not a designkit export")
    ea = prov["effusivity_answered"]
    return Exported(axes=axes, delta_up=np.asarray(arr["delta_up"], dtype=np.float64),
                    delta_down=np.asarray(arr["delta_down"], dtype=np.float64),
                    contact_adjacent=tuple(bool(x) for x in adjacent), e_lo=float(ea["min"]), e_hi=float(ea["max"]),
                    e_lo_inclusive=bool(ea["min_inclusive"]), provenance=prov)


# ---------------------------------------------------------------- shared by code generators
def _regenerate_command(exp: Exported, fmt: str, prefix: str | None) -> str:
    p, s = exp.provenance, exp.provenance["slice"]
    cmd = [f"designkit export --table {p['source_table']} --format {fmt}"]
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


def _slice_lines(exp: Exported) -> list[str]:
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
    ea = exp.provenance["effusivity_answered"]
    out.append(f"effusivity answered: {ea['min']:g} {'<=' if ea['min_inclusive'] else '<'} e <= {ea['max']:g}, "
               f"{len(exp.e_ref.values)} reference intervals (centres {exp.e_ref.values[0]:g}..{exp.e_ref.values[-1]:g})")
    return out


def _log_grid(a: Axis) -> list[float]:
    return np.log(np.asarray(a.values)).tolist() if a.scale == "log" and min(a.values) > 0 else list(a.values)


# ---------------------------------------------------------------- C99 header
def _c_doubles(vals) -> str:
    return ", ".join(repr(float(v)) for v in vals)


def _c_float_rows(arr: np.ndarray, exp: Exported, per_line: int = 16) -> str:
    """Float initializer text: one commented block per (scene, contact) row; NaN -> -1 (none)."""
    a32 = arr.astype(np.float32)
    flat = a32.ravel()
    u, inv = np.unique(flat, return_inverse=True)
    words = []
    for x in u.tolist():
        if math.isnan(x):
            words.append("-1")
        elif x.is_integer() and abs(x) < 2 ** 24:
            words.append(str(int(x)))
        else:
            words.append(np.format_float_positional(np.float32(x), unique=True) + "f")
    text = np.array(words, dtype=object)[inv.ravel()].reshape(a32.shape)
    ne = a32.shape[-1]
    blocks = []
    for idx in np.ndindex(*a32.shape[:-1]):
        label = ", ".join(f"{ax.name} {ax.values[i]:g}" for ax, i in zip(exp.axes, idx))
        row = text[idx].tolist()
        lines = [", ".join(row[i:i + per_line]) for i in range(0, ne, per_line)]
        blocks.append(f"    /* {label} */\n    " + ",\n    ".join(lines))
    return ",\n".join(blocks)


def _c_string(s: str) -> str:
    """A C string literal (ASCII; JSON's escapes of ASCII text are C escapes too)."""
    return json.dumps(str(s).encode("ascii", "replace").decode("ascii"))


def _c_comment(s: str) -> str:
    return str(s).encode("ascii", "replace").decode("ascii").replace("*/", "* /")


_C_HEADER = r'''/*
 * @P@: designkit lookup table for C99 (self-contained; generated, do not edit).
 *
 * Regenerate:  @COMMAND@
 * Generated by designkit @VERSION@ from table "@TABLE@"
 *   (@HASH@, created @CREATED@).
 * Sensor "@SENSOR@": @SENSOR_LINE@
 * Fidelity @FIDELITY@, kind @KIND@ (@KIND_MEANING@); pairs count as
 * distinguishable at F1 >= @THRESHOLD@.
@SLICE@
 * Export hash @EXPORT_HASH@; @BYTES@ bytes of static const data.
 *
 * What it answers (the same interpolation as designkit.query, designkit/query.py):
 *   delta(e) [J s^-1/2 K^-1 m^-2] is tabulated at reference-interval centres, per
 *   contact time and scene; it is interpolated linearly in e and in contact time,
 *   log-linearly in @SCENE_WORDS@; nothing is extrapolated.
 *   Two effusivities lo < hi are distinguishable when
 *       hi - lo >= max(delta_up(lo), delta_down(hi)).
 *
 *   float @p@_delta_e(e, noise_c, delta_t_c, contact_s)
 *       smallest distinguishable difference from e: the smaller of the two
 *       directions (designkit.query.delta_e's value); @p@_delta_e_lower /
 *       @p@_delta_e_upper give each direction.
 *   float @p@_min_contact_s(e1, e2, noise_c, delta_t_c)
 *       shortest contact time [s] that separates e1 from e2.
 *   int   @p@_distinguishable(e1, e2, noise_c, delta_t_c, contact_s)
 *       1: contact_s separates them, 0: it does not.
 *   Units: effusivity J s^-1/2 K^-1 m^-2, noise sigma per sample degC, delta_t_c
 *   = sensor minus object temperature before contact degC, contact time s.
 *
 * Return conventions (never reads out of bounds, never allocates):
 *   float functions:  >= 0                   the answer
 *                     @P@_NONE    (-1.0f)  nothing in the table suffices: no
 *                                            tabulated contact time separates the
 *                                            pair / no distinguishable effusivity
 *                                            within the grid in either direction
 *                     @P@_OUTSIDE (-2.0f)  an input lies outside the table's grid
 *                                            (query.py's in_grid false); ask designkit
 *                     @P@_INVALID (-3.0f)  invalid input: NaN or infinite, e <= 0,
 *                                            noise < 0, dT == 0, contact <= 0, e1 == e2
 *   @p@_distinguishable: @P@_YES (1), @P@_NO (0), @P@_OUTSIDE_I (-2),
 *                        @P@_INVALID_I (-3): test "== @P@_YES", never "if (result)".
 *
 * Float arguments are matched to grid values and edges with a relative tolerance
 * of 1e-6 (designkit's Python query uses 1e-12 on doubles): 0.05f / 10.0f is the
 * sigma/dT row 0.005 itself, as 0.05 / 10 is in Python. A slice answers only its own
 * scene and refuses
 * contact times that fall between kept columns that are not neighbours in the
 * source table; min_contact_s then answers the longer kept column.
 *
 * Arithmetic is in double; define @P@_FLOAT_MATH before including this header to
 * compute in float (for FPUs without double; answers then agree to about 1e-6
 * relative). Needs only <math.h> (link with -lm). All symbols are static: include it
 * in one .c file of a program (each inclusion carries its own copy of the data).
 * "None within the grid" is stored as -1, not NaN, so -ffast-math keeps the lookups
 * right; only the detection of NaN arguments (@P@_INVALID) relies on isnan().
 */
#ifndef @P@_LOOKUP_H_INCLUDED
#define @P@_LOOKUP_H_INCLUDED

#include <math.h>

/* ---- return conventions */
#define @P@_NONE (-1.0f)
#define @P@_OUTSIDE (-2.0f)
#define @P@_INVALID (-3.0f)
#define @P@_YES 1
#define @P@_NO 0
#define @P@_OUTSIDE_I (-2)
#define @P@_INVALID_I (-3)

/* ---- provenance */
#define @P@_SOURCE_TABLE @S_TABLE@
#define @P@_SOURCE_HASH @S_HASH@
#define @P@_SOURCE_CREATED @S_CREATED@
#define @P@_EXPORT_HASH @S_EXPORT_HASH@
#define @P@_DESIGNKIT_VERSION @S_VERSION@
#define @P@_FIDELITY @S_FIDELITY@
#define @P@_KIND @S_KIND@
#define @P@_THRESHOLD @THRESHOLD_D@
#define @P@_SENSOR_NAME @S_SENSOR@
#define @P@_SENSOR_EFFUSIVITY @SENSOR_E@ /* J s^-1/2 K^-1 m^-2 */
#define @P@_SENSOR_DIFFUSIVITY_M2_S @SENSOR_A@
#define @P@_SENSOR_DEPTH_M @SENSOR_D@
#define @P@_SENSOR_SAMPLE_RATE_HZ @SENSOR_F@
#define @P@_SLICE @S_SLICE@
/* effusivities answered: @P@_E_MIN < e (<= when @P@_E_MIN_INCLUSIVE) and e <= @P@_E_MAX */
#define @P@_E_MIN @E_MIN@
#define @P@_E_MAX @E_MAX@
#define @P@_E_MIN_INCLUSIVE @E_INCL@
#define @P@_CONTACT_MIN_S @C_MIN@
#define @P@_CONTACT_MAX_S @C_MAX@
@SCENE_DEFINES@
#define @P@_N_CONTACT @NC@
#define @P@_N_E @NE@

#ifdef @P@_FLOAT_MATH
typedef float @p@_real_;
#define @P@_LOG_(x) logf(x)
#define @P@_FABS_(x) fabsf(x)
#else
typedef double @p@_real_;
#define @P@_LOG_(x) log(x)
#define @P@_FABS_(x) fabs(x)
#endif
#define @P@_RTOL_ ((@p@_real_)@RTOL@)

/* ---- axes (values; log axes also as natural logarithms, computed by numpy) */
@SCENE_ARRAYS@
static const @p@_real_ @p@_contact_s_[@NC@] = {@CONTACTS@};
/* 1: contact columns k and k + 1 are neighbours in the source table */
static const unsigned char @p@_contact_adjacent_[@NC@] = {@ADJACENT@};
static const @p@_real_ @p@_e_ref_[@NE@] = {@CENTRES@};

/* ---- delta(e) [J s^-1/2 K^-1 m^-2], [scene][contact][e_ref]; -1: none within the grid */
static const float @p@_delta_up_[@NDATA@] = {
@DELTA_UP@
};
static const float @p@_delta_down_[@NDATA@] = {
@DELTA_DOWN@
};

/* ---- interpolation: designkit.query._axis_weights, _interp_e, _View.need, _crossing */

/* numpy.searchsorted(v, x, side="left"): first i in [0, n] with v[i] >= x */
static inline int @p@_lower_bound_(const @p@_real_ *v, int n, @p@_real_ x)
{
    int lo = 0, hi = n;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (v[mid] < x) lo = mid + 1; else hi = mid;
    }
    return lo;
}

/* numpy.searchsorted(v, x, side="right"): first i in [0, n] with v[i] > x */
static inline int @p@_upper_bound_(const @p@_real_ *v, int n, @p@_real_ x)
{
    int lo = 0, hi = n;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (v[mid] <= x) lo = mid + 1; else hi = mid;
    }
    return lo;
}

/* Weights of x on axis v (grid g: log(v) or v): 0 outside; else *j and *w with
   x = (1 - w) at j + w at j + 1 (n == 1: j = 0, w = 0). A value within a relative
   RTOL of a grid value is that grid value (designkit.query.GRID_RTOL). */
static inline int @p@_axis_(const @p@_real_ *v, const @p@_real_ *g, int n, int logscale,
                             @p@_real_ x, int *j, @p@_real_ *w)
{
    @p@_real_ u, ww;
    int k;
    *j = 0;
    *w = 0;
    for (k = 0; k < n; k++) {
        if (@P@_FABS_(x - v[k]) <= @P@_RTOL_ * @P@_FABS_(v[k])) {
            if (k < n - 1) { *j = k; *w = 0; }
            else if (n > 1) { *j = n - 2; *w = 1; }
            return 1;
        }
    }
    if (n == 1 || x < v[0] || x > v[n - 1])
        return 0;
    u = x;
    if (logscale) {
        if (x <= 0 || v[0] <= 0)
            return 0;
        u = @P@_LOG_(x);
    }
    k = @p@_lower_bound_(g, n, u) - 1;
    if (k < 0) k = 0;
    if (k > n - 2) k = n - 2;
    ww = (u - g[k]) / (g[k + 1] - g[k]);
    if (ww < 0) ww = 0;
    if (ww > 1) ww = 1;
    *j = k;
    *w = ww;
    return 1;
}

/* delta at effusivity e from one row of interval centres; -1 if a neighbour is none */
static inline @p@_real_ @p@_interp_e_(const float *row, @p@_real_ e)
{
    int j;
    @p@_real_ a, b, w;
    if (e <= @p@_e_ref_[0]) return row[0];
    if (e >= @p@_e_ref_[@NE@ - 1]) return row[@NE@ - 1];
    j = @p@_upper_bound_(@p@_e_ref_, @NE@, e) - 1; /* e_ref[j] <= e < e_ref[j + 1] */
    a = row[j];
    b = row[j + 1];
    w = (e - @p@_e_ref_[j]) / (@p@_e_ref_[j + 1] - @p@_e_ref_[j]);
    if (w == 0) return a; /* on a grid point: its own value */
    if (a < 0 || b < 0) return -1;
    return a + w * (b - a);
}

/* scene rows and weights (at most 4); returns their count, 0 when outside */
static inline int @p@_scene_(@p@_real_ noise, @p@_real_ dt, long *rows, @p@_real_ *wts)
{
@SCENE_BODY@
}

/* delta array at scene weights, contact column k, effusivity e (-1: none) */
static inline @p@_real_ @p@_delta_at_(const float *arr, const long *rows, const @p@_real_ *wts, int nw,
                                        int k, @p@_real_ e)
{
    @p@_real_ total = 0, v;
    int c;
    for (c = 0; c < nw; c++) {
        if (wts[c] == 0) continue;
        v = @p@_interp_e_(arr + (rows[c] * @NC@ + k) * (long)@NE@, e);
        if (v < 0) return -1;
        total += wts[c] * v;
    }
    return total;
}

/* distance needed to separate lo < hi at contact column k (-1: not within the grid) */
static inline @p@_real_ @p@_need_(const long *rows, const @p@_real_ *wts, int nw, int k,
                                   @p@_real_ lo, @p@_real_ hi)
{
    @p@_real_ up = @p@_delta_at_(@p@_delta_up_, rows, wts, nw, k, lo);
    @p@_real_ down = @p@_delta_at_(@p@_delta_down_, rows, wts, nw, k, hi);
    if (up < 0 || down < 0) return -1;
    return up >= down ? up : down;
}

static inline int @p@_bad_e_(float e) { return isnan(e) || isinf(e) || e <= 0; }
static inline int @p@_bad_scene_(float noise_c, float delta_t_c)
{
    return !isfinite(noise_c) || noise_c < 0 || !isfinite(delta_t_c) || delta_t_c == 0;
}
static inline int @p@_bad_contact_(float c) { return isnan(c) || isinf(c) || c <= 0; }
static inline int @p@_e_ok_(@p@_real_ e)
{
    return (@P@_E_MIN_INCLUSIVE ? e >= (@p@_real_)@P@_E_MIN : e > (@p@_real_)@P@_E_MIN)
        && e <= (@p@_real_)@P@_E_MAX;
}

/* contact weights; 0 outside or between kept columns that are not source neighbours */
static inline int @p@_contact_(@p@_real_ contact, int *k, @p@_real_ *w)
{
    if (!@p@_axis_(@p@_contact_s_, @p@_contact_s_, @NC@, 0, contact, k, w)) return 0;
    if (@NC@ > 1 && !@p@_contact_adjacent_[*k] && *w > 0 && *w < 1) return 0;
    return 1;
}

/* both directions of delta(e); returns 0, or -2 (outside) / -3 (invalid) */
static inline int @p@_delta_pair_(float e, float noise_c, float delta_t_c, float contact_s,
                                  @p@_real_ *lower, @p@_real_ *upper)
{
    long rows[4];
    @p@_real_ wts[4], wc = 0, cw[2], x, tot[2];
    int nw, kc = 0, ck[2], nc, i, d;
    const float *arrs[2];
    if (@p@_bad_e_(e) || @p@_bad_contact_(contact_s) || @p@_bad_scene_(noise_c, delta_t_c)) return -3;
    nw = @p@_scene_(noise_c, delta_t_c, rows, wts);
    if (!nw || !@p@_contact_(contact_s, &kc, &wc) || !@p@_e_ok_(e)) return -2;
    nc = 0;
    ck[nc] = kc; cw[nc++] = @NC@ == 1 ? 1 : 1 - wc;
    if (@NC@ > 1) { ck[nc] = kc + 1; cw[nc++] = wc; }
    arrs[0] = @p@_delta_down_;
    arrs[1] = @p@_delta_up_;
    for (d = 0; d < 2; d++) {
        tot[d] = 0;
        for (i = 0; i < nc; i++) {
            if (cw[i] == 0) continue;
            x = @p@_delta_at_(arrs[d], rows, wts, nw, ck[i], e);
            if (x < 0) { tot[d] = -1; break; }
            tot[d] += cw[i] * x;
        }
    }
    *lower = tot[0];
    *upper = tot[1];
    return 0;
}

/* ---- public API */

/* delta(e) towards lower effusivity [J s^-1/2 K^-1 m^-2] (@P@_NONE / _OUTSIDE / _INVALID) */
static inline float @p@_delta_e_lower(float e, float noise_c, float delta_t_c, float contact_s)
{
    @p@_real_ lower, upper;
    int s = @p@_delta_pair_(e, noise_c, delta_t_c, contact_s, &lower, &upper);
    if (s) return (float)s;
    return lower < 0 ? @P@_NONE : (float)lower;
}

/* delta(e) towards higher effusivity [J s^-1/2 K^-1 m^-2] (@P@_NONE / _OUTSIDE / _INVALID) */
static inline float @p@_delta_e_upper(float e, float noise_c, float delta_t_c, float contact_s)
{
    @p@_real_ lower, upper;
    int s = @p@_delta_pair_(e, noise_c, delta_t_c, contact_s, &lower, &upper);
    if (s) return (float)s;
    return upper < 0 ? @P@_NONE : (float)upper;
}

/* smallest distinguishable effusivity difference from e, the smaller of the two
   directions [J s^-1/2 K^-1 m^-2] (@P@_NONE / _OUTSIDE / _INVALID) */
static inline float @p@_delta_e(float e, float noise_c, float delta_t_c, float contact_s)
{
    @p@_real_ lower, upper;
    int s = @p@_delta_pair_(e, noise_c, delta_t_c, contact_s, &lower, &upper);
    if (s) return (float)s;
    if (lower < 0 && upper < 0) return @P@_NONE;
    if (lower < 0) return (float)upper;
    if (upper < 0) return (float)lower;
    return (float)(lower <= upper ? lower : upper);
}

/* shortest contact time [s] that separates e1 from e2 (@P@_NONE: no tabulated
   contact time suffices; @P@_OUTSIDE / _INVALID) */
static inline float @p@_min_contact_s(float e1, float e2, float noise_c, float delta_t_c)
{
    long rows[4];
    @p@_real_ wts[4], lo, hi, gap, nd, prev = -1, w;
    int nw, k;
    if (@p@_bad_e_(e1) || @p@_bad_e_(e2) || e1 == e2 || @p@_bad_scene_(noise_c, delta_t_c)) return @P@_INVALID;
    lo = e1 < e2 ? e1 : e2;
    hi = e1 < e2 ? e2 : e1;
    nw = @p@_scene_(noise_c, delta_t_c, rows, wts);
    if (!nw || !@p@_e_ok_(lo) || !@p@_e_ok_(hi)) return @P@_OUTSIDE;
    gap = hi - lo;
    for (k = 0; k < @NC@; k++) {
        nd = @p@_need_(rows, wts, nw, k, lo, hi);
        if (nd >= 0 && nd <= gap) {
            if (k == 0) return (float)@p@_contact_s_[0];
            if (!@p@_contact_adjacent_[k - 1] || prev < 0) return (float)@p@_contact_s_[k];
            w = prev != nd ? (prev - gap) / (prev - nd) : 1;
            return (float)(@p@_contact_s_[k - 1] + w * (@p@_contact_s_[k] - @p@_contact_s_[k - 1]));
        }
        prev = nd;
    }
    return @P@_NONE;
}

/* 1 (@P@_YES) when contact_s separates e1 from e2, 0 (@P@_NO) when not;
   @P@_OUTSIDE_I (-2) / @P@_INVALID_I (-3) */
static inline int @p@_distinguishable(float e1, float e2, float noise_c, float delta_t_c, float contact_s)
{
    long rows[4];
    @p@_real_ wts[4], lo, hi, wc = 0, cw[2], total = 0, nd;
    int nw, kc = 0, ck[2], nc = 0, i;
    if (@p@_bad_e_(e1) || @p@_bad_e_(e2) || e1 == e2 || @p@_bad_contact_(contact_s)
        || @p@_bad_scene_(noise_c, delta_t_c))
        return @P@_INVALID_I;
    lo = e1 < e2 ? e1 : e2;
    hi = e1 < e2 ? e2 : e1;
    nw = @p@_scene_(noise_c, delta_t_c, rows, wts);
    if (!nw || !@p@_contact_(contact_s, &kc, &wc) || !@p@_e_ok_(lo) || !@p@_e_ok_(hi)) return @P@_OUTSIDE_I;
    ck[nc] = kc; cw[nc++] = @NC@ == 1 ? 1 : 1 - wc;
    if (@NC@ > 1) { ck[nc] = kc + 1; cw[nc++] = wc; }
    for (i = 0; i < nc; i++) {
        if (cw[i] == 0) continue;
        nd = @p@_need_(rows, wts, nw, ck[i], lo, hi);
        if (nd < 0) return @P@_NO;
        total += cw[i] * nd;
    }
    return total <= hi - lo ? @P@_YES : @P@_NO;
}

#undef @P@_LOG_
#undef @P@_FABS_
#undef @P@_RTOL_
#endif /* @P@_LOOKUP_H_INCLUDED */
'''

_C_SCENE_RATIO = '''    /* noise_ratio = noise / |dT| (sigma/dT invariance, fixed initial conditions) */
    int j;
    @p@_real_ w;
    if (!@p@_axis_(@p@_noise_ratio_, @p@_noise_ratio_g_, @N0@, @LOG0@, noise / @P@_FABS_(dt), &j, &w)) return 0;
    rows[0] = j;
    wts[0] = @N0@ == 1 ? 1 : 1 - w;
    if (@N0@ == 1) return 1;
    rows[1] = j + 1;
    wts[1] = w;
    return 2;'''

_C_SCENE_VARIED = '''    /* noise_c (log) x delta_t_c (linear), varied initial conditions */
    int j0, j1, a, b, n0 = @N0@ == 1 ? 1 : 2, n1 = @N1@ == 1 ? 1 : 2, n = 0;
    @p@_real_ w0, w1, wa, wb;
    if (!@p@_axis_(@p@_noise_c_, @p@_noise_c_g_, @N0@, @LOG0@, noise, &j0, &w0)) return 0;
    if (!@p@_axis_(@p@_delta_t_c_, @p@_delta_t_c_g_, @N1@, @LOG1@, dt, &j1, &w1)) return 0;
    for (a = 0; a < n0; a++) {
        wa = n0 == 1 ? 1 : (a ? w0 : 1 - w0);
        for (b = 0; b < n1; b++) {
            wb = n1 == 1 ? 1 : (b ? w1 : 1 - w1);
            rows[n] = (long)(j0 + a) * @N1@ + (j1 + b);
            wts[n++] = wa * wb;
        }
    }
    return n;'''


def _fill(template: str, values: dict[str, str]) -> str:
    for key, val in values.items():
        template = template.replace(f"@{key}@", val)
    return template


def to_c(exp: Exported, prefix: str = "designkit") -> bytes:
    """A self-contained C99 header (see the module docstring for the API and sentinels)."""
    if not _PREFIX_RE.match(prefix or ""):
        raise InputError(f"prefix must be a C identifier (a letter, then letters, digits or _; up to 40), "
                         f"got {prefix!r}")
    p = exp.provenance
    sensor = p["sensor"]
    scene = exp.scene_axes
    nc, ne = len(exp.contact.values), len(exp.e_ref.values)
    ndata = int(exp.delta_up.size)
    defines, arrays = [], []
    for i, a in enumerate(scene):
        defines.append(f"#define @P@_N_{a.name.upper()} {len(a.values)}")
        defines.append(f"#define @P@_{a.name.upper()}_MIN {min(a.values)!r}")
        defines.append(f"#define @P@_{a.name.upper()}_MAX {max(a.values)!r}")
        arrays.append(f"/* {a.name} [{a.units}], {a.scale} */")
        arrays.append(f"static const @p@_real_ @p@_{a.name}_[{len(a.values)}] = {{{_c_doubles(a.values)}}};")
        arrays.append(f"static const @p@_real_ @p@_{a.name}_g_[{len(a.values)}] = {{{_c_doubles(_log_grid(a))}}};")
    subs = {f"N{i}": str(len(a.values)) for i, a in enumerate(scene)}
    subs.update({f"LOG{i}": "1" if a.scale == "log" else "0" for i, a in enumerate(scene)})
    body = _fill(_C_SCENE_RATIO if [a.name for a in scene] == ["noise_ratio"] else _C_SCENE_VARIED, subs)
    nbytes = 8 * ndata + 8 * (nc + ne + 2 * sum(len(a.values) for a in scene)) + nc
    scene_words = ("sigma/dT" if scene[0].name == "noise_ratio" else "sigma and linearly in dT")
    text = _fill(_C_HEADER, {
        "SCENE_BODY": body,
        "SCENE_DEFINES": "\n".join(defines),
        "SCENE_ARRAYS": "\n".join(arrays),
        "SLICE": "\n".join(" * " + _c_comment(line) for line in _slice_lines(exp)),
        "COMMAND": _regenerate_command(exp, "c", prefix),
        "VERSION": p["designkit_version"], "TABLE": _c_comment(p["source_table"]), "HASH": str(p["source_content_hash"]),
        "CREATED": str(p["source_created"]), "SENSOR": _c_comment(sensor.get("name")),
        "SENSOR_LINE": (f"e_s {sensor.get('effusivity')!r} J s^-1/2 K^-1 m^-2, alpha_s "
                        f"{sensor.get('diffusivity_m2_s')!r} m^2/s, depth {sensor.get('depth_m')!r} m, "
                        f"{sensor.get('sample_rate_hz')!r} Hz"),
        "FIDELITY": p["fidelity"], "KIND": p["kind"], "KIND_MEANING": p["kind_meaning"],
        "THRESHOLD": f"{p['threshold']:g}", "EXPORT_HASH": p["export_hash"], "BYTES": str(nbytes),
        "SCENE_WORDS": scene_words,
        "S_TABLE": _c_string(p["source_table"]), "S_HASH": _c_string(str(p["source_content_hash"])),
        "S_CREATED": _c_string(str(p["source_created"])), "S_EXPORT_HASH": _c_string(p["export_hash"]),
        "S_VERSION": _c_string(p["designkit_version"]), "S_FIDELITY": _c_string(p["fidelity"]),
        "S_KIND": _c_string(p["kind"]), "THRESHOLD_D": repr(float(p["threshold"])),
        "S_SENSOR": _c_string(str(sensor.get("name"))),
        "SENSOR_E": repr(float(sensor.get("effusivity", math.nan))),
        "SENSOR_A": repr(float(sensor.get("diffusivity_m2_s", math.nan))),
        "SENSOR_D": repr(float(sensor.get("depth_m", math.nan))),
        "SENSOR_F": repr(float(sensor.get("sample_rate_hz", math.nan))),
        "S_SLICE": _c_string("; ".join(_slice_lines(exp))),
        "E_MIN": repr(exp.e_lo), "E_MAX": repr(exp.e_hi), "E_INCL": "1" if exp.e_lo_inclusive else "0",
        "C_MIN": repr(exp.contact.values[0]), "C_MAX": repr(exp.contact.values[-1]),
        "NC": str(nc), "NE": str(ne), "NDATA": str(ndata), "RTOL": repr(C_EDGE_RTOL),
        "CONTACTS": _c_doubles(exp.contact.values),
        "ADJACENT": ", ".join(["1" if x else "0" for x in exp.contact_adjacent] + ["0"]),
        "CENTRES": _c_doubles(exp.e_ref.values),
        "DELTA_UP": _c_float_rows(exp.delta_up, exp), "DELTA_DOWN": _c_float_rows(exp.delta_down, exp),
    })
    text = text.replace("@P@", prefix.upper()).replace("@p@", prefix)
    return text.encode()


# ---------------------------------------------------------------- stdlib Python module
_PY_MODULE = r'''"""@TITLE@

Generated by designkit @VERSION@ (do not edit); needs only the Python standard library.
Regenerate:  @COMMAND@

@SLICE@

Functions (the same interpolation and decision rule as designkit.query):

    delta_e(e, noise_c, delta_t_c, contact_s)        -> float or None
    delta_e_lower(...), delta_e_upper(...)          -> float or None
    min_contact_s(e1, e2, noise_c, delta_t_c)        -> float or None
    distinguishable(e1, e2, noise_c, delta_t_c, contact_s) -> bool

Units: effusivity [J s^-1/2 K^-1 m^-2], noise sigma per sample [degC],
delta_t_c = sensor minus object temperature before contact [degC], contact [s].
delta_e is the smaller of the two directions (query.delta_e's value). None means
nothing in the table suffices (no tabulated contact time separates the pair; no
distinguishable effusivity within the grid in either direction). An input outside
the table's grid raises OutsideTable (a ValueError; nothing is extrapolated);
invalid input (NaN, infinite, e <= 0, noise < 0, dT == 0, contact <= 0, e1 == e2)
raises ValueError. Two effusivities lo < hi are distinguishable when
hi - lo >= max(delta_up(lo), delta_down(hi)).
"""

import array as _array
import base64 as _base64
import bisect as _bisect
import hashlib as _hashlib
import math as _math
import sys as _sys
import zlib as _zlib

__all__ = ["OutsideTable", "PROVENANCE", "delta_e", "delta_e_lower", "delta_e_upper", "distinguishable",
           "min_contact_s"]

PROVENANCE = @PROVENANCE@

SOURCE_TABLE = PROVENANCE["source_table"]
SOURCE_HASH = PROVENANCE["source_content_hash"]
EXPORT_HASH = PROVENANCE["export_hash"]
THRESHOLD = PROVENANCE["threshold"]
FIDELITY = PROVENANCE["fidelity"]
KIND = PROVENANCE["kind"]
# a value within this relative distance of a grid value is that value (designkit.query.GRID_RTOL)
GRID_RTOL = @GRID_RTOL@

# axes: (name, scale, values, grid used for interpolation: log(values) for log axes, from numpy)
_SCENE = @SCENE@
CONTACT_S = @CONTACTS@
_CONTACT_ADJACENT = @ADJACENT@
E_REF = @CENTRES@
E_MIN, E_MIN_INCLUSIVE, E_MAX = @E_MIN@, @E_INCL@, @E_MAX@
_NC, _NE = len(CONTACT_S), len(E_REF)

# delta_up then delta_down, float64 little-endian, zlib, base85; NaN: none within the grid
_DATA = (
@DATA@
)
_DATA_SHA256 = "@DATA_SHA@"


def _load():
    raw = _zlib.decompress(_base64.b85decode("".join(_DATA)))
    if _hashlib.sha256(raw).hexdigest() != _DATA_SHA256:
        raise ImportError(__name__ + ": table data corrupted (checksum mismatch); regenerate it")
    a = _array.array("d")
    a.frombytes(raw)
    if _sys.byteorder == "big":
        a.byteswap()
    half = len(a) // 2
    return a[:half], a[half:]


_UP, _DOWN = _load()


class OutsideTable(ValueError):
    """An input lies outside the table's grid (no extrapolation): ask designkit (--exact)."""


def _number(name, x):
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise ValueError(name + " must be a number, got " + repr(x)) from None
    if not _math.isfinite(v):
        raise ValueError(name + " must be finite, got " + repr(v))
    return v


def _effusivity(name, x):
    v = _number("effusivity " + name, x)
    if v <= 0:
        raise ValueError("effusivity " + name + " must be positive, got " + repr(v))
    return v


def _scene_inputs(noise_c, delta_t_c):
    noise = _number("noise sigma [degC]", noise_c)
    if noise < 0:
        raise ValueError("noise sigma [degC] must be >= 0, got " + repr(noise))
    dt = _number("temperature difference [degC]", delta_t_c)
    if dt == 0:
        raise ValueError("temperature difference is 0: an unheated sensor sees no contrast between materials")
    return noise, dt


def _contact_input(contact_s):
    c = _number("contact time [s]", contact_s)
    if c <= 0:
        raise ValueError("contact time [s] must be positive, got " + repr(c))
    return c


def _pair(e1, e2):
    a, b = _effusivity("e1", e1), _effusivity("e2", e2)
    if a == b:
        raise ValueError("e1 and e2 are equal (" + repr(a) + "): nothing to separate")
    return (a, b) if a < b else (b, a)


def _axis(vals, grid, x, log):
    """designkit.query._axis_weights: [(index, weight)], or None outside."""
    n = len(vals)
    for k, v in enumerate(vals):  # within GRID_RTOL of a grid value: that value
        if abs(x - v) <= GRID_RTOL * abs(v):
            return [(k, 1.0)]
    if n == 1 or x < vals[0] or x > vals[-1]:
        return None
    if log:
        if x <= 0 or vals[0] <= 0:
            return None
        u = _math.log(x)
    else:
        u = x
    j = min(max(_bisect.bisect_left(grid, u) - 1, 0), n - 2)
    w = min(max((u - grid[j]) / (grid[j + 1] - grid[j]), 0.0), 1.0)
    return [(j, 1.0 - w), (j + 1, w)]


def _outside(name, x, vals):
    raise OutsideTable("%s %g is outside table %s's grid [%g, %g] (no extrapolation)"
                       % (name, x, SOURCE_TABLE, min(vals), max(vals)))


def _scene(noise, dt):
    """Scene rows and weights (designkit.query._View.scene_weights)."""
    if [s[0] for s in _SCENE] == ["noise_ratio"]:
        wanted = {"noise_ratio": noise / abs(dt)}
    else:
        wanted = {"noise_c": noise, "delta_t_c": dt}
    combos = [(0, 1.0)]
    for name, scale, vals, grid in _SCENE:
        pts = _axis(vals, grid, wanted[name], scale == "log")
        if pts is None:
            _outside(name, wanted[name], vals)
        combos = [(idx * len(vals) + k, w * wk) for idx, w in combos for k, wk in pts]
    return combos


def _contact(contact):
    pts = _axis(CONTACT_S, CONTACT_S, contact, False)
    if pts is None:
        _outside("contact_s", contact, CONTACT_S)
    if len(pts) == 2 and not _CONTACT_ADJACENT[pts[0][0]] and 0 < pts[1][1] < 1:
        raise OutsideTable("contact time %g s falls between exported columns %g and %g s, which are not "
                           "neighbours in table %s" % (contact, CONTACT_S[pts[0][0]], CONTACT_S[pts[1][0]],
                                                       SOURCE_TABLE))
    return pts


def _check_e(*es):
    for e in es:
        if not ((e >= E_MIN if E_MIN_INCLUSIVE else e > E_MIN) and e <= E_MAX):
            raise OutsideTable("effusivity %g is outside the exported range %s%g, %g] (no extrapolation)"
                               % (e, "[" if E_MIN_INCLUSIVE else "(", E_MIN, E_MAX))


def _interp_e(arr, start, e):
    """designkit.query._interp_e on the row arr[start:start + _NE] (NaN: none)."""
    if e <= E_REF[0]:
        return arr[start]
    if e >= E_REF[-1]:
        return arr[start + _NE - 1]
    j = _bisect.bisect_right(E_REF, e) - 1  # E_REF[j] <= e < E_REF[j + 1]
    a, b = arr[start + j], arr[start + j + 1]
    w = (e - E_REF[j]) / (E_REF[j + 1] - E_REF[j])
    if w == 0:  # on a grid point: its own value
        return a
    if _math.isnan(a) or _math.isnan(b):
        return _math.nan
    return a + w * (b - a)


def _delta_at(arr, combos, k, e):
    total = 0.0
    for row, w in combos:
        if w == 0:
            continue
        v = _interp_e(arr, (row * _NC + k) * _NE, e)
        if _math.isnan(v):
            return _math.nan
        total += w * v
    return total


def _need(combos, k, lo, hi):
    up = _delta_at(_UP, combos, k, lo)
    down = _delta_at(_DOWN, combos, k, hi)
    if _math.isnan(up) or _math.isnan(down):
        return _math.nan
    return max(up, down)


def _over_contact(cw, value_at):
    """Contact-weighted sum of value_at(k); None when a needed grid point has no value."""
    total = 0.0
    for k, w in cw:
        if w == 0:
            continue
        x = value_at(k)
        if _math.isnan(x):
            return None
        total += w * x
    return total


def _deltas(e, noise_c, delta_t_c, contact_s):
    e = _effusivity("e", e)
    contact = _contact_input(contact_s)
    noise, dt = _scene_inputs(noise_c, delta_t_c)
    combos = _scene(noise, dt)
    cw = _contact(contact)
    _check_e(e)
    return [_over_contact(cw, lambda k, arr=arr: _delta_at(arr, combos, k, e)) for arr in (_DOWN, _UP)]


def delta_e_lower(e, noise_c, delta_t_c, contact_s):
    """delta(e) towards lower effusivity [J s^-1/2 K^-1 m^-2]; None: none within the grid."""
    return _deltas(e, noise_c, delta_t_c, contact_s)[0]


def delta_e_upper(e, noise_c, delta_t_c, contact_s):
    """delta(e) towards higher effusivity [J s^-1/2 K^-1 m^-2]; None: none within the grid."""
    return _deltas(e, noise_c, delta_t_c, contact_s)[1]


def delta_e(e, noise_c, delta_t_c, contact_s):
    """Smallest distinguishable effusivity difference from e (the smaller direction); None: none."""
    finite = [v for v in _deltas(e, noise_c, delta_t_c, contact_s) if v is not None]
    return min(finite) if finite else None


def min_contact_s(e1, e2, noise_c, delta_t_c):
    """Shortest contact time [s] that separates e1 from e2; None: no tabulated contact time suffices."""
    noise, dt = _scene_inputs(noise_c, delta_t_c)
    lo, hi = _pair(e1, e2)
    combos = _scene(noise, dt)
    _check_e(lo, hi)
    gap = hi - lo
    prev = _math.nan
    for k in range(_NC):  # designkit.query._crossing, stopping at the first column that suffices
        nd = _need(combos, k, lo, hi)
        if not _math.isnan(nd) and nd <= gap:
            if k == 0:
                return float(CONTACT_S[0])
            if not _CONTACT_ADJACENT[k - 1] or _math.isnan(prev):
                return float(CONTACT_S[k])
            w = (prev - gap) / (prev - nd) if prev != nd else 1.0
            return float(CONTACT_S[k - 1] + w * (CONTACT_S[k] - CONTACT_S[k - 1]))
        prev = nd
    return None


def distinguishable(e1, e2, noise_c, delta_t_c, contact_s):
    """Whether contact_s separates e1 from e2 (need <= distance)."""
    contact = _contact_input(contact_s)
    noise, dt = _scene_inputs(noise_c, delta_t_c)
    lo, hi = _pair(e1, e2)
    combos = _scene(noise, dt)
    cw = _contact(contact)
    _check_e(lo, hi)
    total = _over_contact(cw, lambda k: _need(combos, k, lo, hi))
    return total is not None and total <= hi - lo
'''


def _py_list(vals) -> str:
    return "[" + ", ".join(repr(float(v)) for v in vals) + "]"


def to_python(exp: Exported) -> bytes:
    """A single-file module that needs only the standard library (same functions as the C header)."""
    p = exp.provenance
    raw = np.concatenate([exp.delta_up.ravel(), exp.delta_down.ravel()]).astype("<f8").tobytes()
    b85 = base64.b85encode(zlib.compress(raw, 9)).decode("ascii")
    data = "\n".join(f'    "{b85[i:i + 96]}",' for i in range(0, len(b85), 96))
    scene = "[\n" + "".join(f"    ({a.name!r}, {a.scale!r}, {_py_list(a.values)}, {_py_list(_log_grid(a))}),\n"
                            for a in exp.scene_axes) + "]"
    title = (f"designkit lookup table {p['source_table']} ({p['fidelity']}, kind {p['kind']}, "
             f"F1 >= {p['threshold']:g}, sensor {p['sensor'].get('name')})")
    slice_text = "\n".join(["Source: " + f"{p['source_table']} {p['source_content_hash']}",
                            f"Export hash: {p['export_hash']}"] + [line.replace("\\", "/") for line in _slice_lines(exp)])
    text = _fill(_PY_MODULE, {
        "TITLE": title, "VERSION": p["designkit_version"], "COMMAND": _regenerate_command(exp, "python", None),
        "SLICE": slice_text, "GRID_RTOL": repr(C_EDGE_RTOL), "PROVENANCE": pprint.pformat(p, width=100, sort_dicts=False),
        "SCENE": scene, "CONTACTS": _py_list(exp.contact.values),
        "ADJACENT": repr([bool(x) for x in exp.contact_adjacent]), "CENTRES": _py_list(exp.e_ref.values),
        "E_MIN": repr(exp.e_lo), "E_INCL": repr(bool(exp.e_lo_inclusive)), "E_MAX": repr(exp.e_hi),
        "DATA": data, "DATA_SHA": hashlib.sha256(raw).hexdigest(),
    })
    return text.encode()


# ============================================================ write
def render(exp: Exported, fmt: str, *, prefix: str = "designkit") -> bytes:
    """The bytes of ``exp`` in format ``fmt`` (json, csv, npz, c, python)."""
    if fmt == "json":
        return to_json(exp)
    if fmt == "csv":
        return to_csv(exp)
    if fmt == "npz":
        return to_npz(exp)
    if fmt == "c":
        return to_c(exp, prefix)
    if fmt == "python":
        return to_python(exp)
    raise InputError(f"format must be one of {', '.join(FORMATS)}, got {fmt!r}")


def format_for(out: str | Path, fmt: str | None) -> str:
    """The export format: ``fmt``, or inferred from the output's suffix."""
    if fmt is not None:
        fmt = fmt.lower()
        if fmt not in FORMATS:
            raise InputError(f"format must be one of {', '.join(FORMATS)}, got {fmt!r}")
        return fmt
    guess = SUFFIXES.get(Path(out).suffix.lower())
    if guess is None:
        raise InputError(f"cannot tell the format from {str(out)!r}: give --format ({', '.join(FORMATS)})")
    return guess


def export_table(table: "Table | str", out: str | Path, fmt: str | None = None, *, prefix: str = "designkit",
                 noise_c: float | None = None, delta_t_c: float | None = None, contact=None,
                 e_min: float | None = None, e_max: float | None = None, kind: str = "svm") -> ExportResult:
    """Slice ``table`` (see :func:`slice_table`) and write it to ``out`` atomically in format ``fmt``."""
    from .._io import atomic_write_bytes

    fmt = format_for(out, fmt)
    if fmt == "c" and not _PREFIX_RE.match(prefix or ""):
        raise InputError(f"prefix must be a C identifier (a letter, then letters, digits or _), got {prefix!r}")
    exp = slice_table(table, noise_c=noise_c, delta_t_c=delta_t_c, contact=contact, e_min=e_min, e_max=e_max,
                      kind=kind)
    data = render(exp, fmt, prefix=prefix)
    path = Path(out)
    if path.is_dir():
        raise InputError(f"--out {path} is a folder; give a file name")
    atomic_write_bytes(path, data)
    return ExportResult(path=path, format=fmt, size_bytes=len(data), provenance=exp.provenance)

