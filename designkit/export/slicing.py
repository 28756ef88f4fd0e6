"""The part of a table a deployment needs: one scene, some contact times, an effusivity range.

A robot controller or a microcontroller needs the answers of
:mod:`designkit.query` (how long to touch, is this pair separable, what is
delta(e)), not the whole table. :func:`slice_table` cuts a table down to
:class:`Exported`, which every writer (:mod:`designkit.export.formats`) turns
into bytes.

What a deployment needs (leave out the rest)
--------------------------------------------
``noise_c`` and ``delta_t_c`` select one scene: the table's sigma/dT rows (or
sigma and dT rows) are combined with the query's weights (log-linear in
sigma/dT, :func:`designkit.tables.lookup.axis_weights`) into one row. Because
the need sums over the scene weights *before* taking the maximum of the two
directions, the combined row gives the same answers as the full table for
that scene. ``contact`` keeps the contact-time columns a robot uses (single
values keep the one or two columns that interpolate them; ranges ``(a, b)``
keep every column between, plus the neighbours that bracket the ends).
``e_min`` and ``e_max`` keep the reference intervals needed to interpolate
delta(e) anywhere in ``[e_min, e_max]``, i.e. one interval of margin on each
side.

A slice answers only its own scene (noise/dT must match it to within float
precision), and an answer that would interpolate between two kept contact
columns that are not neighbours in the source table is refused (``delta_e``,
``distinguishable``) or taken at the longer column (``min_contact_s``: the
shortest *exported* contact time that suffices).

What a table must hold to be exported
-------------------------------------
Everything a writer embeds is checked here once: the table's and its sensor's
names are safe names (:data:`designkit.export._common.NAME_RULE`), the axes are
the known ones with known scales and finite increasing values that match the
arrays' shape, the sensor's numbers are numbers, and the provenance is plain
JSON (no NaN). Anything else is refused in one line.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from .._validation import InputError, check_finite, check_nonnegative, check_positive
from ..tables.lookup import axis_weights
from ..tables.store import E_UNITS, SHIPPED_TABLES, Table, content_hash, load_table
from ._common import check_name, printable

__all__ = [
    "EXPORT_FORMAT",
    "EXPORT_SCHEMA",
    "KINDS",
    "KIND_MEANING",
    "Axis",
    "Exported",
    "parse_contact",
    "slice_table",
]

EXPORT_FORMAT = "designkit-export"
EXPORT_SCHEMA = 1
KINDS = ("svm", "lo", "hi", "ideal")
_KIND_SUFFIX = {"svm": "", "lo": "_lo", "hi": "_hi", "ideal": "_ideal"}
#: What each kind of delta array means (written into every export's provenance).
KIND_MEANING = {
    "svm": "delta of the table's classifier (the value designkit's queries answer)",
    "lo": "optimistic end of the Monte Carlo interval of delta (query intervals' first end)",
    "hi": "conservative end of the Monte Carlo interval of delta (query intervals' second end)",
    "ideal": "ideal observer's delta (the bound no classifier can beat)",
}
_SCENE_LAYOUTS = (["noise_ratio"], ["noise_c", "delta_t_c"])
_SCALES = ("log", "linear")
_SENSOR_NUMBERS = ("effusivity", "diffusivity_m2_s", "depth_m", "sample_rate_hz")


# ============================================================ the sliced data
@dataclass(frozen=True)
class Axis:
    """One axis of an export.

    Attributes
    ----------
    name : str
        ``noise_ratio``, ``noise_c``, ``delta_t_c``, ``contact_s`` or ``e_ref``.
    units : str
        Its unit, as the source table's header writes it.
    scale : {"log", "linear"}
        How it is interpolated.
    values : tuple of float
        Grid values, increasing.
    """

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
        Effusivities answered [J s^-1/2 K^-1 m^-2]: ``e_lo < e <= e_hi``
        (``<=`` at ``e_lo`` when inclusive: a slice's ``--e-min``).
    provenance : dict
        Source table, its content hash, forward model, sensor, fidelity,
        threshold, kind, versions, the slice taken, and ``export_hash``.
    source_ref : str, optional
        How ``designkit export --table`` finds the source again: a shipped
        table's name, else the path it was read from (None for an export
        read back from a file).
    more : dict of ndarray
        ``delta_up_lo``, ``delta_down_lo``, ``delta_up_hi``, ``delta_down_hi``
        (the ends of the table's Monte Carlo interval, shaped as ``delta_up``)
        where the export carries the library's estimator; else empty.
    estimator : dict, optional
        The estimator's constants (:func:`designkit.export.estimator_data.estimator_params`);
        None where the export answers by the grid rule only (``provenance["estimator"]`` says why).
    """

    axes: tuple[Axis, ...]
    delta_up: np.ndarray
    delta_down: np.ndarray
    contact_adjacent: tuple[bool, ...]
    e_lo: float
    e_hi: float
    e_lo_inclusive: bool
    provenance: dict
    source_ref: str | None = None
    more: dict = field(default_factory=dict)
    estimator: dict | None = None

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


# ============================================================ requests
def parse_contact(items: Sequence[Any] | str | float | None) -> tuple[float | tuple[float, float], ...] | None:
    """Contact-time request from text: ``"2"``, ``"1:4"`` (a range), ``"1,2,3"``, or a list of these.

    Returns
    -------
    tuple or None
        Single values [s] and ``(a, b)`` ranges [s], or None for no request.

    Examples
    --------
    >>> parse_contact("1,2:3")
    (1.0, (2.0, 3.0))
    >>> parse_contact(["0.5", (1, 4)])
    (0.5, (1.0, 4.0))
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
        text = str(item).replace(" ", "")
        for part in text.split(","):
            if not part:  # 1,,2 (a value left out), or a trailing comma: refused, not skipped
                raise InputError(f"contact times must be values or ranges separated by single commas, got "
                                 f"{printable(text)!r}")
            if ":" in part:
                lo, _, hi = part.partition(":")
                try:
                    a, b = float(lo), float(hi)
                except ValueError:
                    raise InputError(f"contact range must look like 1:4 (seconds), got {printable(part)!r}") from None
                out.append((check_positive("contact time [s]", a), check_positive("contact time [s]", b)))
            else:
                try:
                    v = float(part)
                except ValueError:
                    raise InputError(f"contact time must be a number or a range like 1:4, "
                                     f"got {printable(part)!r}") from None
                out.append(check_positive("contact time [s]", v))
    if not out:
        raise InputError("--contact is empty")
    for r in out:
        if isinstance(r, tuple) and not r[0] <= r[1]:
            raise InputError(f"contact range {r[0]:g}:{r[1]:g} must go from shorter to longer")
    return tuple(out)


def _kept_contacts(contacts: np.ndarray, request) -> list[int]:
    """Source contact columns needed to answer at every requested contact time."""
    def needed(c: float) -> list[int]:
        pts = axis_weights(contacts, c)
        if pts is None:
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
    """First and last reference interval needed to interpolate delta(e) on [a, b].

    :func:`~designkit.tables.lookup.interp_e` uses the centres j, j + 1 with
    ``centres[j] <= e < centres[j + 1]`` (an ``e`` on a centre reads that
    centre only), and clamps at the ends.
    """
    n = centres.size
    i0 = max(int(np.searchsorted(centres, a, side="right")) - 1, 0)
    i1 = min(int(np.searchsorted(centres, b, side="left")), n - 1)
    return i0, i1


def _array_names(table: Table, kind: str) -> tuple[str, str]:
    """delta arrays of ``kind``, with the query's fallback for tables that hold only delta_up/down."""
    if kind not in KINDS:
        raise InputError(f"kind must be one of {', '.join(KINDS)}, got {printable(repr(kind))}")
    sfx = _KIND_SUFFIX[kind]
    up, down = f"delta_up{sfx}", f"delta_down{sfx}"
    if up not in table.arrays:
        up, down = "delta_up", "delta_down"
    if up not in table.arrays or down not in table.arrays:
        raise InputError(f"table {table.name} holds no delta_up / delta_down arrays; not a delta table")
    return up, down


# ============================================================ what a table must hold
def _axes_of(tab: Table, shape: tuple[int, ...]) -> tuple[list[str], dict[str, dict], dict[str, np.ndarray]]:
    """Scene axis names, each axis' header entry, and its values; refuses what a writer could not embed."""
    try:
        meta = {str(a["name"]): a for a in tab.header["axes"]}
        names = [str(a["name"]) for a in tab.header["axes"]]
    except (KeyError, TypeError):
        raise InputError(f"table {tab.name}: its header's axes are not a list of named axes") from None
    scene = names[:-2]
    if scene not in _SCENE_LAYOUTS or names[-2:] != ["contact_s", "e_ref"]:
        raise InputError(f"table {tab.name}: axes {printable(names)} are not an exportable layout "
                         f"(noise_ratio, or noise_c and delta_t_c; then contact_s, e_ref)")
    values = {}
    for name in names:
        a = meta[name]
        if a.get("scale") not in _SCALES:
            raise InputError(f"table {tab.name}: axis {name} has scale {printable(repr(a.get('scale')))}; "
                             f"known: {', '.join(_SCALES)}")
        try:
            v = np.asarray(a["values"], dtype=np.float64).ravel()
        except (KeyError, TypeError, ValueError):
            raise InputError(f"table {tab.name}: axis {name} has no list of numbers as values") from None
        if v.size == 0 or not np.isfinite(v).all() or (np.diff(v) <= 0).any():
            raise InputError(f"table {tab.name}: axis {name} values must be finite and increasing")
        values[name] = v
    if tuple(values[n].size for n in names) != tuple(shape):
        raise InputError(f"table {tab.name}: its axes ({' x '.join(str(values[n].size) for n in names)}) do not "
                         f"match its arrays ({' x '.join(map(str, shape))})")
    return scene, meta, values


def _sensor_of(tab: Table) -> dict:
    sensor = tab.header.get("sensor")
    if not isinstance(sensor, dict):
        raise InputError(f"table {tab.name}: its header has no sensor")
    check_name(f"table {tab.name}'s sensor name", sensor.get("name"))
    for key in _SENSOR_NUMBERS:
        if key in sensor and (isinstance(sensor[key], bool) or not isinstance(sensor[key], (int, float))):
            raise InputError(f"table {tab.name}: sensor {key} must be a number, got {printable(repr(sensor[key]))}")
    return sensor


def _plain_json(tab: Table, provenance: dict) -> None:
    try:
        json.dumps(provenance, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise InputError(f"table {tab.name}: its header holds what an export cannot write as plain JSON "
                         f"({printable(exc)})") from None


def _units(meta: dict[str, dict], name: str) -> str:
    return str(meta[name].get("units", ""))


def _scene_cut(tab: Table, names: list[str], meta: dict[str, dict], values: dict[str, np.ndarray], noise_c, delta_t_c,
               arrays: dict[str, np.ndarray], keep_rows: bool):
    """One scene of ``arrays`` (name -> array, scene axes first): the rows combined with the query's weights, or
    (``keep_rows``, an estimator export) the one or two rows around it kept apart, each with its own ratio.

    Returns ``(arrays, scene axes, the slice's scene record)``; every scene and None when neither
    ``noise_c`` nor ``delta_t_c`` is given."""
    if (noise_c is None) != (delta_t_c is None):
        raise InputError("give --noise and --delta-t together (one scene), or neither (all scenes)")
    if noise_c is None:
        return arrays, [Axis(n, _units(meta, n), meta[n]["scale"], tuple(values[n].tolist())) for n in names], None
    noise = check_nonnegative("noise sigma [degC]", noise_c)
    dt = check_finite("temperature difference [degC]", delta_t_c)
    if dt == 0:
        raise InputError("temperature difference is 0: an unheated sensor sees no contrast between materials")
    point = {"noise_ratio": noise / abs(dt)} if names == ["noise_ratio"] else {"noise_c": noise, "delta_t_c": dt}
    combos: list[tuple[tuple[int, ...], float]] = [((), 1.0)]
    bad = []
    for name in names:
        vals = values[name]
        log = meta[name]["scale"] == "log"
        pts = axis_weights(vals, point[name], log, np.log(vals) if log and vals[0] > 0 else None)
        if pts is None:
            bad.append(name)
            continue
        combos = [(idx + (k,), w * wk) for idx, w in combos for k, wk in pts]
    if bad:
        ranges = ", ".join(f"{k} [{values[k].min():g}, {values[k].max():g}]" for k in bad)
        raise InputError(f"noise {noise:g} degC, dT {dt:g} degC lies outside table {tab.name}'s grid "
                         f"along {ranges} (no extrapolation)")
    if keep_rows:  # noise_ratio layout: the rows themselves (the estimator reads each row's ratio)
        rows = sorted({idx[0] for idx, w in combos if w != 0})
        arrays = {k: a[rows] for k, a in arrays.items()}
        ratios = values["noise_ratio"][rows]
        axes = [Axis("noise_ratio", _units(meta, "noise_ratio"), meta["noise_ratio"]["scale"],
                     tuple(float(r) for r in ratios))]
    else:
        arrays = {k: _combine(a, combos, len(names)) for k, a in arrays.items()}
        axes = [Axis(n, _units(meta, n), meta[n]["scale"], (float(point[n]),)) for n in names]
    info = {"noise_c": noise, "delta_t_c": dt, **point,
            "rows": [{"index": list(idx), "weight": w} for idx, w in combos if w != 0]}
    return arrays, axes, info


def _combine(arr: np.ndarray, combos, n_scene: int) -> np.ndarray:
    """The scene rows of ``arr`` summed with their weights, as one row (NaN in a weighted row stays NaN, as in
    the query)."""
    total = np.zeros(arr.shape[n_scene:])
    for idx, w in combos:
        if w == 0:
            continue
        total = total + w * arr[idx]
    return total[(None,) * n_scene]


def _contact_cut(contacts: np.ndarray, contact, arrays: dict[str, np.ndarray]):
    """The contact columns a deployment uses: ``(arrays, kept columns, neighbours in the source, record)``."""
    request = parse_contact(contact)
    info = None
    if request is not None:
        cols = _kept_contacts(contacts, request)
        info = {"requested": [list(r) if isinstance(r, tuple) else r for r in request], "source_columns": cols}
    else:
        cols = list(range(contacts.size))
    arrays = {k: a[..., cols, :] for k, a in arrays.items()}
    return arrays, cols, tuple(bool(cols[k + 1] == cols[k] + 1) for k in range(len(cols) - 1)), info


def _effusivity_cut(tab: Table, centres: np.ndarray, e_min, e_max):
    """The effusivities answered: ``(e_lo, e_hi, e_lo inclusive, first and last interval kept, record)``."""
    try:
        grid_lo = check_finite(f"table {tab.name}'s effusivity min", tab.header["effusivity"]["min"])
        grid_hi = check_finite(f"table {tab.name}'s effusivity max", tab.header["effusivity"]["max"])
    except (KeyError, TypeError):
        raise InputError(f"table {tab.name}: its header has no effusivity min and max") from None
    if e_min is None and e_max is None:
        return grid_lo, grid_hi, False, 0, centres.size - 1, None
    e_lo, e_hi, inclusive = grid_lo, grid_hi, False
    a = check_finite("--e-min", e_min) if e_min is not None else None
    b = check_finite("--e-max", e_max) if e_max is not None else None
    grid = f"({grid_lo:g}, {grid_hi:g}]"
    if a is not None:
        if not (grid_lo <= a <= grid_hi):
            raise InputError(f"--e-min {a:g} is outside table {tab.name}'s effusivity grid {grid}")
        if a > grid_lo:
            e_lo, inclusive = a, True
    if b is not None:
        if not (grid_lo < b <= grid_hi):
            raise InputError(f"--e-max {b:g} is outside table {tab.name}'s effusivity grid {grid}")
        e_hi = b
    if not e_hi > e_lo:
        raise InputError(f"--e-min must be below --e-max, got {e_lo:g} and {e_hi:g}")
    i0, i1 = _kept_centres(centres, e_lo, e_hi)
    return e_lo, e_hi, inclusive, i0, i1, {"e_min": a, "e_max": b, "source_intervals": [i0, i1]}


def _check_deltas(tab: Table, arrays: dict[str, np.ndarray]) -> None:
    for name in ("delta_up", "delta_down"):
        arr = arrays[name]
        finite = arr[~np.isnan(arr)]
        if np.isinf(arr).any() or (finite < 0).any():
            raise InputError(f"table {tab.name}: {name} holds negative or infinite values; not a delta table")


def _provenance(tab: Table, kind: str, names: tuple[str, str], sensor: dict, axes, shape, answered: tuple,
                slice_info: dict, export_hash: str, params: dict | None, why_not: str | None) -> dict:
    """What an export records about itself (plain JSON)."""
    from .. import __version__
    from .estimator import ESTIMATOR, ESTIMATOR_VERSION
    from .estimator_data import contact_frame

    hdr = tab.header
    fidelity = hdr.get("fidelity")
    answers = "grid rule only" if params is None else "library"
    e_lo, e_hi, inclusive = answered
    return {
        "format": EXPORT_FORMAT,
        "schema_version": EXPORT_SCHEMA,
        "source_table": tab.name,
        "source_content_hash": hdr.get("content_hash"),
        "source_created": hdr.get("created"),
        "source_designkit_version": hdr.get("designkit_version"),
        "designkit_version": __version__,
        "model": tab.model.to_dict(),
        "fidelity": fidelity,
        "threshold": check_finite(f"table {tab.name}'s threshold", hdr.get("threshold")),
        "trials": hdr.get("trials"),
        "sensor": sensor,
        "kind": kind,
        "kind_meaning": (KIND_MEANING[kind] if fidelity == "svm" or names[0] != "delta_up"
                         else "delta of the ideal observer (an ideal-fidelity table holds only that)"),
        "source_arrays": {"delta_up": names[0], "delta_down": names[1]},
        "units": {"delta": E_UNITS, "effusivity": E_UNITS, "contact_s": "s", "noise_c": "degC",
                  "delta_t_c": "degC", "noise_ratio": "1 (sigma / dT)"},
        "axes": [{"name": a.name, "units": a.units, "scale": a.scale, "points": len(a.values),
                  "min": min(a.values), "max": max(a.values)} for a in axes],
        "effusivity_answered": {"min": e_lo, "min_inclusive": inclusive, "max": e_hi, "max_inclusive": True,
                                "units": E_UNITS},
        "slice": slice_info,
        "contact_frame": contact_frame(tab),
        "shape": list(shape),
        "nan_means": "no distinguishable partner within the table's effusivity grid (not separable)",
        "decision_rule": "lo < hi are distinguishable when hi - lo >= max(delta_up(lo), delta_down(hi))",
        "interpolation": ("linear in e_ref between interval centres (a NaN neighbour gives NaN), linear in "
                          "contact_s and delta_t_c, log-linear in noise_ratio and noise_c; no extrapolation"),
        "export_hash": export_hash,
        "estimator": {"name": ESTIMATOR, "version": ESTIMATOR_VERSION,
                      "answers": answers,
                      "coverage": 0.9 if why_not is None else None, "unavailable": why_not},
    }


# ============================================================ slicing
def slice_table(table: "Table | str", *, noise_c: float | None = None, delta_t_c: float | None = None,
                contact=None, e_min: float | None = None, e_max: float | None = None,
                kind: str = "svm") -> Exported:
    """The part of ``table`` a deployment needs, interpolated exactly as :mod:`designkit.query` does.

    Parameters
    ----------
    table : Table or name or path
        The source table.
    noise_c, delta_t_c : float, optional
        Together: one scene, noise sigma per sample [degC] and sensor minus
        object temperature [degC]; the scene rows are combined with the
        query's weights (log-linear in sigma/dT). Neither: every scene.
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

    Raises
    ------
    InputError
        A request outside the table's grid, or a table whose header an export
        cannot carry safely (one line).

    Examples
    --------
    >>> exp = slice_table("ideal-paper", noise_c=0.05, delta_t_c=10.0, contact="1:2")
    >>> exp.shape, exp.contact.values
    ((1, 5, 500), (1.0, 1.25, 1.5, 1.75, 2.0))
    >>> exp.provenance["model"]
    {'name': 'semi-infinite'}
    """
    tab = table if isinstance(table, Table) else load_table(table)
    check_name("table name", tab.name)
    names = _array_names(tab, kind)
    up = np.asarray(tab.arrays[names[0]], dtype=np.float64)
    down = np.asarray(tab.arrays[names[1]], dtype=np.float64)
    if up.shape != down.shape:
        raise InputError(f"table {tab.name}: {names[0]} and {names[1]} differ in shape")
    scene_names, ax_meta, ax_values = _axes_of(tab, up.shape)
    sensor = _sensor_of(tab)

    from .estimator_data import MORE_ARRAYS, estimator_params, estimator_reason

    why_not = estimator_reason(tab, kind, contact is not None)
    arrays = {"delta_up": up, "delta_down": down,
              **({n: np.asarray(tab.arrays[n], dtype=np.float64) for n in MORE_ARRAYS} if why_not is None else {})}
    arrays, scene_axes, scene_info = _scene_cut(tab, scene_names, ax_meta, ax_values, noise_c, delta_t_c, arrays,
                                                why_not is None)
    contacts = ax_values["contact_s"]
    arrays, cols, adjacent, contact_info = _contact_cut(contacts, contact, arrays)
    centres = ax_values["e_ref"]
    e_lo, e_hi, inclusive, i0, i1, e_info = _effusivity_cut(tab, centres, e_min, e_max)
    arrays = {k: np.ascontiguousarray(a[..., i0:i1 + 1]) for k, a in arrays.items()}
    _check_deltas(tab, arrays)

    axes = tuple(scene_axes) + (
        Axis("contact_s", _units(ax_meta, "contact_s"), "linear", tuple(float(contacts[k]) for k in cols)),
        Axis("e_ref", E_UNITS, "linear", tuple(float(c) for c in centres[i0:i1 + 1])),
    )
    export_hash = content_hash({**arrays, **{f"axis_{a.name}": np.asarray(a.values) for a in axes}})
    params = estimator_params(tab) if why_not is None else None
    slice_info = {"scene": scene_info, "contact_s": contact_info, "effusivity": e_info}
    provenance = _provenance(tab, kind, names, sensor, axes, arrays["delta_up"].shape, (e_lo, e_hi, inclusive),
                             slice_info, export_hash, params, why_not)
    _plain_json(tab, provenance)
    # a table another with its name could shadow (a user's svm-paper) is named by its path in "Regenerate:" lines
    hdr = tab.header
    ref = tab.name if SHIPPED_TABLES.get(tab.name, (None,))[0] == hdr.get("content_hash") else str(tab.path)
    more = {n: a for n, a in arrays.items() if n not in ("delta_up", "delta_down")}
    return Exported(axes=axes, delta_up=arrays["delta_up"], delta_down=arrays["delta_down"],
                    contact_adjacent=adjacent, e_lo=float(e_lo), e_hi=float(e_hi), e_lo_inclusive=inclusive,
                    provenance=provenance, source_ref=ref, more=more, estimator=params)
