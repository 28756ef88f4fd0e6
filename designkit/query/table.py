"""Design questions answered: contact time, noise, temperature difference, delta(e).

Every question has two routes:

* **from a table** (milliseconds, no scikit-learn): delta(e) is interpolated
  linearly in effusivity and contact time and log-linearly in sigma/dT between
  the table's grid points. An answer outside the grid is refused (``in_grid``
  says which axis), never extrapolated.
* **exact** (seconds): the question is computed for this one pair and scene:
  the SVM's F1 by simulation with repeated seeds and bisection on the asked
  quantity, the ideal observer in closed form.

Both report the SVM answer and the ideal-observer bound.

Decision rule for a pair ``e1 < e2``: distinguishable when the distance
``e2 - e1`` reaches both ``delta_up(e1)`` (seen from the lower effusivity) and
``delta_down(e2)`` (seen from the higher one); the two agree up to Monte Carlo
noise, and requiring both is the conservative choice.

Materials (a range of effusivities each) are answered for the worst case: the
pair of effusivities, on a 9 x 9 grid over the two ranges, that needs the most.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from typing import Any, Sequence

import numpy as np

from .._validation import InputError, check_effusivity, check_finite, check_nonnegative, check_positive
from ..tables.store import Table, load_table

__all__ = [
    "DEFAULT_IDEAL_TABLE",
    "DEFAULT_TABLE",
    "Answer",
    "delta_e",
    "distinguishable",
    "exact_delta_e",
    "exact_distinguishable",
    "exact_max_noise",
    "exact_min_contact",
    "exact_min_delta_t",
    "max_noise",
    "min_contact",
    "min_delta_t",
]

DEFAULT_TABLE = "svm-paper"
DEFAULT_IDEAL_TABLE = "ideal-paper"
_GRID = 9  # worst case over material ranges: a 9 x 9 grid of effusivity pairs


@dataclass(frozen=True)
class Answer:
    """A query's answer: the asked quantity, its interval, the ideal bound, and provenance."""

    question: str
    value: float | None
    interval: tuple[float | None, float | None]
    ideal: float | None
    source: str
    table: str | None
    ideal_table: str | None
    inputs: dict[str, Any]
    in_grid: dict[str, bool] = field(default_factory=dict)
    extra: dict[str, Any] = field(default_factory=dict)
    note: str = ""

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["interval"] = list(self.interval)
        return d


# ============================================================ input checks
def _pair(e1: float, e2: float) -> tuple[float, float]:
    a = check_effusivity("e1", e1)
    b = check_effusivity("e2", e2)
    if a == b:
        raise InputError(f"e1 and e2 are equal ({a:g}): nothing to separate")
    return (a, b) if a < b else (b, a)


def _scene_inputs(noise_c: float, delta_t_c: float) -> tuple[float, float]:
    noise = check_nonnegative("noise sigma [degC]", noise_c)
    dt = check_finite("temperature difference [degC]", delta_t_c)
    if dt == 0:
        raise InputError("temperature difference is 0: an unheated sensor sees no contrast between materials")
    return noise, dt


def _as_table(table: "Table | str") -> Table:
    return table if isinstance(table, Table) else load_table(table)


# ============================================================ interpolation
class _View:
    """Interpolation on one table."""

    def __init__(self, table: Table):
        self.t = table
        ax = table.axes
        self.centres = ax["e_ref"]
        self.contacts = ax["contact_s"]
        self.scene_axes = [n for n in table.axis_names if n not in ("contact_s", "e_ref")]
        self.e_lo = float(table.header["effusivity"]["min"])
        self.e_hi = float(table.header["effusivity"]["max"])

    # ---- scene axes -> weights
    def scene_weights(self, noise_c: float, delta_t_c: float) -> tuple[list[tuple[tuple[int, ...], float]], dict[str, bool]]:
        """Multilinear weights over the scene axes; in-grid flags per axis."""
        ax = self.t.axes
        coords: list[list[tuple[int, float]]] = []
        flags: dict[str, bool] = {}
        if self.scene_axes == ["noise_ratio"]:
            wanted = {"noise_ratio": noise_c / abs(delta_t_c)}
        else:
            wanted = {"noise_c": noise_c, "delta_t_c": delta_t_c}
        for name in self.scene_axes:
            vals = ax[name]
            scale = next(a["scale"] for a in self.t.header["axes"] if a["name"] == name)
            pts, ok = _axis_weights(vals, wanted[name], log=scale == "log")
            coords.append(pts)
            flags[name] = ok
        combos = [((), 1.0)]
        for pts in coords:
            combos = [(idx + (k,), w * wk) for idx, w in combos for k, wk in pts]
        return combos, flags

    def delta_at(self, name: str, combos, k: int, e: float) -> float:
        """delta array ``name`` at scene weights, contact index ``k``, effusivity ``e`` (NaN = none)."""
        arr = self.t.arrays[name]
        total = 0.0
        for idx, w in combos:
            if w == 0:
                continue
            v = _interp_e(arr[idx + (k,)], self.centres, e)
            if math.isnan(v):
                return math.nan
            total += w * v
        return total

    def need(self, kind: str, combos, k: int, lo: float, hi: float) -> float:
        """Distance needed to separate lo < hi at contact index k (NaN: not within the grid)."""
        suffix = {"svm": "", "lo": "_lo", "hi": "_hi", "ideal": "_ideal"}[kind]
        up_name, down_name = f"delta_up{suffix}", f"delta_down{suffix}"
        if up_name not in self.t.arrays:  # ideal tables carry only delta_up / delta_down
            up_name, down_name = "delta_up", "delta_down"
        up = self.delta_at(up_name, combos, k, lo)
        down = self.delta_at(down_name, combos, k, hi)
        if math.isnan(up) or math.isnan(down):
            return math.nan
        return max(up, down)

    def e_in_grid(self, *es: float) -> bool:
        return all(self.e_lo < e <= self.e_hi for e in es)


#: A value within this relative distance of a grid value is that grid value. A float32
#: argument (0.05f / 10.0f, as on a microcontroller) cannot hit 0.005 exactly, and the
#: exported C and Python lookups use the same rule, so all three answer alike.
GRID_RTOL = 1e-6


def _axis_weights(vals: np.ndarray, x: float, *, log: bool) -> tuple[list[tuple[int, float]], bool]:
    """Linear (or log-linear) weights of ``x`` between grid values; clamps outside, flagged.

    Within :data:`GRID_RTOL` of a grid value, ``x`` is that value (weight 1).
    """
    n = vals.size
    near = np.abs(x - vals) <= GRID_RTOL * np.abs(vals)
    if near.any():
        return [(int(np.argmax(near)), 1.0)], True
    if n == 1 or x < vals[0] or x > vals[-1]:
        return [(0 if x < vals[0] else n - 1, 1.0)], False
    if log:
        if x <= 0 or vals[0] <= 0:
            return [(0, 1.0)], False
        u, grid = math.log(x), np.log(vals)
    else:
        u, grid = x, vals
    j = int(np.clip(np.searchsorted(grid, u) - 1, 0, n - 2))
    w = float(np.clip((u - grid[j]) / (grid[j + 1] - grid[j]), 0.0, 1.0))
    return [(j, 1.0 - w), (j + 1, w)], True


def _interp_e(row: np.ndarray, centres: np.ndarray, e: float) -> float:
    """delta at effusivity e from values at interval centres; NaN if a neighbour is NaN."""
    if e <= centres[0]:
        return float(row[0])
    if e >= centres[-1]:
        return float(row[-1])
    j = int(np.searchsorted(centres, e, side="right") - 1)  # centres[j] <= e < centres[j + 1]
    a, b = row[j], row[j + 1]
    w = (e - centres[j]) / (centres[j + 1] - centres[j])
    if w == 0.0:  # on a grid point: its own value, whatever the neighbour holds
        return float(a)
    if math.isnan(a) or math.isnan(b):
        return math.nan
    return float(a + w * (b - a))


def _crossing(xs: Sequence[float], needs: Sequence[float], gap: float) -> tuple[float | None, int | None]:
    """First x where need(x) <= gap, linearly interpolated between grid points.

    ``needs`` decreases along ``xs`` (more contact, less noise); NaN means the
    need is beyond the grid. Returns (x, index of the first grid point that
    suffices) or (None, None).
    """
    for k, nd in enumerate(needs):
        if not math.isnan(nd) and nd <= gap:
            if k == 0:
                return float(xs[0]), 0
            prev = needs[k - 1]
            if math.isnan(prev):
                return float(xs[k]), k  # cannot interpolate into "beyond the grid": conservative
            w = (prev - gap) / (prev - nd) if prev != nd else 1.0
            return float(xs[k - 1] + w * (xs[k] - xs[k - 1])), k
    return None, None


# ============================================================ table answers
def _ideal_view(svm: _View, ideal_table: "Table | str | None") -> tuple[_View, str, str | None]:
    """The view answering the ideal bound: a dedicated ideal table, else the SVM table's ideal arrays."""
    if ideal_table is not None:
        try:
            t = _as_table(ideal_table)
        except InputError:
            t = None
        if t is not None and t.sensor == svm.t.sensor and t.fidelity == "ideal" and t.threshold == svm.t.threshold:
            return _View(t), "svm", t.name
    if "delta_up_ideal" in svm.t.arrays:
        return svm, "ideal", svm.t.name
    return svm, "svm", svm.t.name if svm.t.fidelity == "ideal" else None


def _check_threshold(table: Table, threshold: float | None) -> float:
    if threshold is None or math.isclose(threshold, table.threshold, rel_tol=1e-9):
        return table.threshold
    raise InputError(f"table {table.name} was built for threshold {table.threshold:g}, not {threshold:g}: "
                     f"use --exact, or build a table with designkit sweep --threshold {threshold:g}")


def _check_sensor(table: Table, sensor) -> None:
    if sensor is None:
        return
    from ..sensor import load_sensor

    s = load_sensor(sensor)
    if s != table.sensor:
        raise InputError(f"table {table.name} was built for sensor {table.sensor.name!r}, not {s.name!r}: "
                         f"use --exact, or build a table for it with designkit sweep --sensor")


def _pairs_for(e1, e2, ranges) -> list[tuple[float, float]]:
    """The effusivity pairs a question covers: one pair, or a grid over two material ranges."""
    if ranges is None:
        return [_pair(e1, e2)]
    (a0, a1), (b0, b1) = ranges
    ga, gb = np.linspace(a0, a1, _GRID), np.linspace(b0, b1, _GRID)
    return [(min(x, y), max(x, y)) for x in ga for y in gb]


def _ranges_overlap(ranges) -> bool:
    (a0, a1), (b0, b1) = ranges
    return max(a0, b0) <= min(a1, b1)


def min_contact(e1: float | None = None, e2: float | None = None, *, noise_c: float = 0.05,
                delta_t_c: float = 10.0, threshold: float | None = None,
                table: "Table | str" = DEFAULT_TABLE, ideal_table: "Table | str | None" = DEFAULT_IDEAL_TABLE,
                sensor=None, ranges=None) -> Answer:
    """Shortest contact time [s] that separates e1 from e2, from a table.

    Parameters
    ----------
    e1, e2 : float
        Effusivities [J s^-1/2 K^-1 m^-2] (or ``ranges``: two (min, max)
        material ranges, answered for their worst-case pair).
    noise_c : float
        Noise sigma per sample [degC].
    delta_t_c : float
        Sensor minus object temperature before contact [degC].
    threshold : float, optional
        F1 threshold Phi; must be the table's (0.9 for the shipped tables).
    table, ideal_table : Table or name or path
        SVM table, and the table for the ideal bound.
    sensor : name, path or Sensor, optional
        Checked against the table's sensor.

    Returns
    -------
    Answer
        ``value``: contact time [s] or None when no tabulated contact time up
        to the table's longest suffices; ``interval``: Monte Carlo interval;
        ``ideal``: the ideal observer's contact time.
    """
    noise, dt = _scene_inputs(noise_c, delta_t_c)
    pairs = _pairs_for(e1, e2, ranges)
    tab = _as_table(table)
    phi = _check_threshold(tab, threshold)
    _check_sensor(tab, sensor)
    view = _View(tab)
    combos, flags = view.scene_weights(noise, dt)
    flags["effusivity"] = all(view.e_in_grid(lo, hi) for lo, hi in pairs)
    inputs = _inputs(e1, e2, noise, dt, phi, tab, ranges)
    if not all(flags.values()):
        return _outside(inputs, flags, "min-contact", tab)
    if ranges is not None and _ranges_overlap(ranges):
        return Answer("min-contact", None, (None, None), None, "table", tab.name, None, inputs, flags,
                      {"fidelity": tab.fidelity},
                      note="the two effusivity ranges overlap: some objects of the two materials are identical "
                           "to the sensor, so no contact time separates them in the worst case")
    iview, ikind, iname = _ideal_view(view, ideal_table)
    icombos, iflags = iview.scene_weights(noise, dt)

    def contact_for(v: _View, kind: str, cmb) -> float | None:
        worst = 0.0
        for lo, hi in pairs:
            needs = [v.need(kind, cmb, k, lo, hi) for k in range(v.contacts.size)]
            x, _ = _crossing(v.contacts, needs, hi - lo)
            if x is None:
                return None
            worst = max(worst, x)
        return worst

    value = contact_for(view, "svm", combos)
    if tab.fidelity == "svm":
        lo_t = contact_for(view, "lo", combos)
        hi_t = contact_for(view, "hi", combos)
    else:
        lo_t = hi_t = value
    ideal = contact_for(iview, ikind, icombos) if all(iflags.values()) else None
    note = "" if value is not None else (
        f"no tabulated contact time up to {view.contacts[-1]:g} s separates them; "
        f"try --exact for longer contacts")
    return Answer("min-contact", value, (lo_t, hi_t), ideal, "table", tab.name, iname, inputs, flags,
                  {"fidelity": tab.fidelity, "table_contacts_s": view.contacts.tolist()}, note)


def _inputs(e1, e2, noise, dt, phi, tab, ranges, **more) -> dict[str, Any]:
    d = {"e1": e1, "e2": e2, "noise_c": noise, "delta_t_c": dt, "threshold": phi,
         "sensor": tab.header["sensor"]["name"]}
    if noise is not None and dt is not None:
        d["noise_ratio"] = noise / abs(dt)
    if ranges is not None:
        d["e1_range"], d["e2_range"] = list(ranges[0]), list(ranges[1])
        d["rule"] = "worst case over the two ranges (9 x 9 grid of effusivity pairs)"
    d.update(more)
    return d


def _outside(inputs, flags, question, tab) -> Answer:
    bad = [k for k, ok in flags.items() if not ok]
    return Answer(question, None, (None, None), None, "table", tab.name, None, inputs, flags,
                  {"fidelity": tab.fidelity},
                  note=f"outside table {tab.name} along {', '.join(bad)} (no extrapolation): use --exact")


def _contact_index_weights(view: _View, contact_s: float) -> tuple[list[tuple[int, float]], bool]:
    return _axis_weights(view.contacts, contact_s, log=False)


def _need_at_contact(view: _View, kind: str, combos, cw, lo: float, hi: float) -> float:
    total = 0.0
    for k, w in cw:
        if w == 0:
            continue
        nd = view.need(kind, combos, k, lo, hi)
        if math.isnan(nd):
            return math.nan
        total += w * nd
    return total


def _max_ratio(view: _View, kind: str, contact_s: float, pairs, dt: float) -> tuple[float | None, str]:
    """Largest sigma/dT (fixed-condition table) at which all pairs separate."""
    ratios = view.t.axes["noise_ratio"]
    cw, _ = _contact_index_weights(view, contact_s)
    ok_rows = []
    for r_idx in range(ratios.size):
        combos = [((r_idx,), 1.0)]
        ok_rows.append(all(not math.isnan(nd := _need_at_contact(view, kind, combos, cw, lo, hi))
                           and nd <= hi - lo for lo, hi in pairs))
    if not ok_rows[0]:
        return None, "below"
    last = max(i for i, ok in enumerate(ok_rows) if ok)
    if last == ratios.size - 1:
        return float(ratios[-1]), "above"
    # interpolate the crossing in log(ratio) on the worst pair's margin
    def margin(r_idx):
        combos = [((r_idx,), 1.0)]
        vals = []
        for lo, hi in pairs:
            nd = _need_at_contact(view, kind, combos, cw, lo, hi)
            vals.append(-math.inf if math.isnan(nd) else (hi - lo) - nd)
        return min(vals)

    m0, m1 = margin(last), margin(last + 1)
    if not math.isfinite(m1):
        return float(ratios[last]), "inside"
    w = m0 / (m0 - m1) if m0 != m1 else 0.0
    lr = math.log(ratios[last]) + w * (math.log(ratios[last + 1]) - math.log(ratios[last]))
    return math.exp(lr), "inside"


def _ratio_question(question: str, e1, e2, contact_s, noise_c, delta_t_c, threshold, table, ideal_table,
                    sensor, ranges) -> Answer:
    contact = check_positive("contact time [s]", contact_s)
    pairs = _pairs_for(e1, e2, ranges)
    if question == "max-noise":
        dt = check_finite("temperature difference [degC]", delta_t_c)
        if dt == 0:
            raise InputError("temperature difference is 0: no noise level is small enough")
    else:
        noise = check_positive("noise sigma [degC]", noise_c)
    tab = _as_table(table)
    phi = _check_threshold(tab, threshold)
    _check_sensor(tab, sensor)
    if "noise_ratio" not in tab.axes:
        raise InputError(f"table {tab.name} has separate noise and temperature axes (varied initial "
                         f"conditions); use --exact for {question}")
    view = _View(tab)
    _, c_ok = _contact_index_weights(view, contact)
    flags = {"contact_s": c_ok, "effusivity": all(view.e_in_grid(lo, hi) for lo, hi in pairs)}
    if question == "max-noise":
        inputs = _inputs(e1, e2, None, dt, phi, tab, ranges, contact_s=contact)
    else:
        inputs = _inputs(e1, e2, noise, None, phi, tab, ranges, contact_s=contact)
    inputs.pop("noise_ratio", None)
    if not all(flags.values()):
        return _outside(inputs, flags, question, tab)
    iview, ikind, iname = _ideal_view(view, ideal_table)

    def to_answer(r):
        if r is None:
            return None
        return r * abs(dt) if question == "max-noise" else noise / r

    out = {}
    for kind, v in (("svm", view), ("lo", view), ("hi", view), ("ideal", iview)):
        if tab.fidelity == "ideal" and kind in ("lo", "hi"):
            out[kind] = out["svm"]
            continue
        out[kind] = _max_ratio(v, ikind if kind == "ideal" else kind, contact, pairs, 1.0)
    r, where = out["svm"]
    note = ""
    value = to_answer(r)
    if where == "below":
        value = None
        note = (f"not separable even at the table's smallest noise ratio sigma/dT = "
                f"{view.t.axes['noise_ratio'][0]:g}: use --exact")
    elif where == "above":
        note = (f"separable even at the table's largest noise ratio sigma/dT = "
                f"{view.t.axes['noise_ratio'][-1]:g}: the answer is at least this (use --exact for more)")
        flags["noise_ratio"] = False
    # with more noise allowed at the optimistic end: 'lo' (possibly) ratio >= 'svm' ratio
    ends = [to_answer(out[k][0]) if out[k][1] != "below" else None for k in ("hi", "lo")]
    interval = tuple(sorted(ends, key=lambda x: (x is None, x))) if all(e is not None for e in ends) else tuple(ends)
    ideal = to_answer(out["ideal"][0]) if out["ideal"][1] != "below" else None
    return Answer(question, value, interval, ideal, "table", tab.name, iname, inputs, flags,
                  {"fidelity": tab.fidelity}, note)


def max_noise(e1=None, e2=None, *, contact_s: float, delta_t_c: float = 10.0, threshold=None,
              table="svm-paper", ideal_table=DEFAULT_IDEAL_TABLE, sensor=None, ranges=None) -> Answer:
    """Largest noise sigma [degC] at which ``contact_s`` still separates e1 from e2 (table)."""
    return _ratio_question("max-noise", e1, e2, contact_s, None, delta_t_c, threshold, table, ideal_table,
                           sensor, ranges)


def min_delta_t(e1=None, e2=None, *, contact_s: float, noise_c: float = 0.05, threshold=None,
                table="svm-paper", ideal_table=DEFAULT_IDEAL_TABLE, sensor=None, ranges=None) -> Answer:
    """Smallest sensor-object temperature difference [degC] that separates e1 from e2 (table)."""
    return _ratio_question("min-delta-t", e1, e2, contact_s, noise_c, None, threshold, table, ideal_table,
                           sensor, ranges)


def delta_e(e: float, *, contact_s: float, noise_c: float = 0.05, delta_t_c: float = 10.0,
            threshold=None, table="svm-paper", ideal_table=DEFAULT_IDEAL_TABLE, sensor=None) -> Answer:
    """delta(e) towards lower and higher effusivity [J s^-1/2 K^-1 m^-2] (table).

    ``value`` is the smaller of the two; ``extra`` holds ``delta_e_lower``,
    ``delta_e_upper`` and their intervals (None: nothing distinguishable in the
    grid in that direction).
    """
    e = check_effusivity("e", e)
    contact = check_positive("contact time [s]", contact_s)
    noise, dt = _scene_inputs(noise_c, delta_t_c)
    tab = _as_table(table)
    phi = _check_threshold(tab, threshold)
    _check_sensor(tab, sensor)
    view = _View(tab)
    combos, flags = view.scene_weights(noise, dt)
    cw, flags["contact_s"] = _contact_index_weights(view, contact)
    flags["effusivity"] = view.e_in_grid(e)
    inputs = {"e": e, "noise_c": noise, "delta_t_c": dt, "contact_s": contact, "threshold": phi,
              "sensor": tab.header["sensor"]["name"]}
    if not all(flags.values()):
        return _outside(inputs, flags, "delta-e", tab)
    iview, ikind, iname = _ideal_view(view, ideal_table)
    icombos, _ = iview.scene_weights(noise, dt)
    icw, _ = _contact_index_weights(iview, contact)

    def at(v, cmb, cws, name):
        if name not in v.t.arrays:
            return None
        total = 0.0
        for k, w in cws:
            if w == 0:
                continue
            x = v.delta_at(name, cmb, k, e)
            if math.isnan(x):
                return None
            total += w * x
        return total

    res = {}
    for direction, key in (("down", "delta_e_lower"), ("up", "delta_e_upper")):
        res[key] = at(view, combos, cw, f"delta_{direction}")
        res[key + "_interval"] = [at(view, combos, cw, f"delta_{direction}_lo"),
                                  at(view, combos, cw, f"delta_{direction}_hi")] if tab.fidelity == "svm" \
            else [res[key], res[key]]
        iname_arr = f"delta_{direction}_ideal" if ikind == "ideal" else f"delta_{direction}"
        res[key + "_ideal"] = at(iview, icombos, icw, iname_arr)
    finite = [v for v in (res["delta_e_lower"], res["delta_e_upper"]) if v is not None]
    value = min(finite) if finite else None
    ifinite = [v for v in (res["delta_e_lower_ideal"], res["delta_e_upper_ideal"]) if v is not None]
    return Answer("delta-e", value, (None, None), min(ifinite) if ifinite else None, "table", tab.name, iname,
                  inputs, flags, {"fidelity": tab.fidelity, **res})


def distinguishable(e1=None, e2=None, *, contact_s: float, noise_c: float = 0.05, delta_t_c: float = 10.0,
                    threshold=None, table="svm-paper", ideal_table=DEFAULT_IDEAL_TABLE, sensor=None,
                    ranges=None) -> Answer:
    """Whether ``contact_s`` separates e1 from e2 (table), with the ideal observer's F1 (closed form).

    ``value`` is 1.0 (yes) or 0.0 (no); the SVM's F1 of the pair itself is not
    in a table (``svm_f1`` None): use :func:`exact_distinguishable`.
    """
    contact = check_positive("contact time [s]", contact_s)
    noise, dt = _scene_inputs(noise_c, delta_t_c)
    pairs = _pairs_for(e1, e2, ranges)
    tab = _as_table(table)
    phi = _check_threshold(tab, threshold)
    _check_sensor(tab, sensor)
    view = _View(tab)
    combos, flags = view.scene_weights(noise, dt)
    cw, flags["contact_s"] = _contact_index_weights(view, contact)
    flags["effusivity"] = all(view.e_in_grid(lo, hi) for lo, hi in pairs)
    inputs = _inputs(e1, e2, noise, dt, phi, tab, ranges, contact_s=contact)
    if not all(flags.values()):
        return _outside(inputs, flags, "distinguishable", tab)

    def verdict(kind):
        for lo, hi in pairs:
            nd = _need_at_contact(view, kind, combos, cw, lo, hi)
            if math.isnan(nd) or nd > hi - lo:
                return False
        return True

    yes = verdict("svm")
    interval = (float(verdict("hi")), float(verdict("lo"))) if tab.fidelity == "svm" else (float(yes), float(yes))
    ideal_f1 = _ideal_f1_pairs(pairs, tab, contact, noise, dt, ranges)
    return Answer("distinguishable", float(yes), interval, ideal_f1, "table", tab.name, None, inputs, flags,
                  {"fidelity": tab.fidelity, "distinguishable": yes, "svm_f1": None,
                   "ideal_f1": ideal_f1, "ideal_distinguishable": ideal_f1 >= phi})


def _ideal_f1_pairs(pairs, tab: Table, contact, noise, dt, ranges) -> float:
    """Worst (smallest) ideal-observer F1 over the pairs, classes one table interval wide."""
    from ..recognition.ideal import ideal_scores, projection_noise
    from ..scene import Scene

    sensor = tab.sensor
    width = float(tab.header["effusivity"]["width"])
    s = projection_noise(sensor, Scene.from_delta_t(contact_s=contact, noise_c=noise, delta_t_c=dt))
    lo = np.array([p[0] for p in pairs])
    hi = np.array([p[1] for p in pairs])
    f1, _ = ideal_scores(lo, lo + width, hi, hi + width, sensor.effusivity, s, accuracy=False)
    return float(np.min(f1))


# ============================================================ exact answers
@dataclass(frozen=True)
class _Exact:
    sensor: Any
    width: float
    trials: int
    folds: int
    seed: int
    repeats: int
    z: float
    jobs: int


def _exact_setup(sensor, width, trials, folds, seed, repeats, z, jobs) -> _Exact:
    from ..sensor import load_sensor

    if int(folds) < 2:
        raise InputError(f"folds must be >= 2, got {folds}")
    if int(trials) < int(folds):
        raise InputError(f"trials per class ({trials}) must be at least the number of folds ({folds})")
    if int(repeats) < 1:
        raise InputError(f"repeats must be >= 1, got {repeats}")
    return _Exact(load_sensor(sensor if sensor is not None else "paper"), check_positive("class width", width),
                  int(trials), int(folds), int(seed), int(repeats), check_positive("z", z), int(jobs))


def _svm_f1(ex: _Exact, ranges, scene_for) -> tuple[float, float]:
    """Mean SVM F1 over ex.repeats seeds and its standard error, for the pair's classes."""
    from joblib import Parallel, delayed

    from ..recognition.svm import interval_pair_f1

    (a, b) = ranges
    jobs = ex.jobs if ex.repeats > 1 else 1
    results = Parallel(n_jobs=jobs, prefer="processes" if jobs != 1 else None)(
        delayed(interval_pair_f1)(a, b, ex.sensor, scene_for, trials=ex.trials, folds=ex.folds,
                                  seed=[ex.seed, r]) for r in range(ex.repeats))
    f1 = np.array([r.f1 for r in results])
    se_fold = math.sqrt(float(np.mean([r.standard_error ** 2 for r in results])))
    se_rep = float(np.std(f1, ddof=1)) if f1.size > 1 else 0.0
    return float(f1.mean()), max(se_fold, se_rep) / math.sqrt(f1.size)


def _ideal_f1(ex: _Exact, ranges, scene) -> float:
    from ..recognition.ideal import ideal_pair

    return ideal_pair(ranges[0], ranges[1], ex.sensor, scene, seed=ex.seed).f1


def _bisect(f_ok, lo: float, hi: float, tol: float, *, log: bool = False) -> float:
    """Smallest x in (lo, hi] with f_ok(x) (monotone), to tolerance tol (relative if log)."""
    for _ in range(60):
        if (math.log(hi / lo) if log else hi - lo) <= tol:
            break
        mid = math.sqrt(lo * hi) if log else 0.5 * (lo + hi)
        if f_ok(mid):
            hi = mid
        else:
            lo = mid
    return hi


def _class_ranges(ex: _Exact, e1, e2, ranges):
    if ranges is not None:
        return tuple(tuple(float(x) for x in r) for r in ranges)
    lo, hi = _pair(e1, e2)
    return ((lo, lo + ex.width), (hi, hi + ex.width))


def exact_min_contact(e1=None, e2=None, *, noise_c: float = 0.05, delta_t_c: float = 10.0,
                      threshold: float = 0.9, sensor=None, width: float = 80.0, trials: int = 100,
                      folds: int = 3, seed: int = 0, repeats: int = 4, z: float = 2.0, jobs: int = -1,
                      max_contact_s: float = 10.0, tolerance_s: float = 0.05, ranges=None) -> Answer:
    """Shortest contact time [s] computed for this pair: bisection on the SVM's F1.

    Classes are ``[e, e + width)`` (or the material ranges, with the paper's
    rule: the classes are the whole ranges). Each contact time is scored with
    ``repeats`` seeds; the interval collects the contact times whose mean F1 is
    within ``z`` standard errors of ``threshold``.
    """
    from ..scene import Scene

    noise, dt = _scene_inputs(noise_c, delta_t_c)
    phi = _threshold(threshold)
    ex = _exact_setup(sensor, width, trials, folds, seed, repeats, z, jobs)
    cls = _class_ranges(ex, e1, e2, ranges)
    tmax = check_positive("maximum contact time [s]", max_contact_s)
    t0 = time.perf_counter()

    def scene(c):
        return Scene.from_delta_t(contact_s=c, noise_c=noise, delta_t_c=dt)

    floor = 1.0 / ex.sensor.sample_rate_hz
    value, interval, evaluations = _contact_search(lambda c: _svm_f1(ex, cls, scene(c)), phi, floor, tmax,
                                                   tolerance_s, z)
    ideal_ok = lambda c: _ideal_f1(ex, cls, scene(c)) >= phi  # noqa: E731
    ideal = _bisect(ideal_ok, floor, tmax, 1e-3) if ideal_ok(tmax) else None
    inputs = {"e1": e1, "e2": e2, "noise_c": noise, "delta_t_c": dt, "threshold": phi, "classes": [list(c) for c in cls],
              "trials": ex.trials, "folds": ex.folds, "seed": ex.seed, "repeats": ex.repeats,
              "sensor": ex.sensor.name}
    note = "" if value is not None else f"not separable by any contact time up to {tmax:g} s"
    return Answer("min-contact", value, interval, ideal, "computed", None, None, inputs, {},
                  {"fidelity": "svm", "evaluations": evaluations, "wall_s": time.perf_counter() - t0}, note)


def _contact_search(svm_f1, phi: float, floor_s: float, max_contact_s: float, tolerance_s: float, z: float):
    """Shortest contact time whose mean SVM F1 reaches ``phi``, by bisection, with its Monte Carlo interval.

    ``svm_f1(contact_s)`` returns ``(mean F1, standard error)``. The interval runs
    from the longest evaluated contact clearly below ``phi`` (mean + z SE < phi)
    to the shortest clearly above (mean - z SE >= phi; None when none is).

    Returns ``(value or None, (lo, hi), evaluations)``.
    """
    evaluated: dict[float, tuple[float, float]] = {}

    def ok(c):
        evaluated[c] = svm_f1(c)
        return evaluated[c][0] >= phi

    value = _bisect(ok, floor_s, max_contact_s, tolerance_s) if ok(max_contact_s) else None
    below = [c for c, (m, s) in evaluated.items() if m + z * s < phi]
    above = [c for c, (m, s) in evaluated.items() if m - z * s >= phi]
    interval = (max(below) if below else floor_s, min(above) if above else None)
    evaluations = [{"contact_s": c, "svm_f1": m, "standard_error": s} for c, (m, s) in sorted(evaluated.items())]
    return value, interval, evaluations


def _ratio_search(svm_f1, phi: float, lo_r: float, hi_r: float, z: float):
    """Largest sigma/dT at which the mean SVM F1 still reaches ``phi``, by bisection in log sigma/dT.

    ``svm_f1(ratio)`` returns ``(mean F1, standard error)``. The Monte Carlo interval
    runs from the largest evaluated ratio clearly separable (mean - z SE >= phi) to the
    smallest clearly not (mean + z SE < phi); None where no evaluation is clear.

    Returns ``(ratio or None, (lo, hi), evaluations)``; ``hi_r`` itself when even it
    separates, None when not even ``lo_r`` does.
    """
    evaluated: dict[float, tuple[float, float]] = {}

    def ok(r):  # still separable at this noise ratio
        evaluated[r] = svm_f1(r)
        return evaluated[r][0] >= phi

    if not ok(lo_r):
        r = None
    elif ok(hi_r):
        r = hi_r
    else:  # largest ratio that is ok == bisection on "not ok" from above
        r = _bisect(lambda x: not ok(x), lo_r, hi_r, 0.02, log=True)
    ok_conf = [x for x, (m, s) in evaluated.items() if m - z * s >= phi]
    bad_conf = [x for x, (m, s) in evaluated.items() if m + z * s < phi]
    interval = (max(ok_conf) if ok_conf else None, min(bad_conf) if bad_conf else None)
    evaluations = [{"noise_ratio": x, "svm_f1": m, "standard_error": s} for x, (m, s) in sorted(evaluated.items())]
    return r, interval, evaluations


def _threshold(threshold: float) -> float:
    phi = check_finite("threshold", threshold)
    if not 2 / 3 < phi < 1:
        raise InputError(f"threshold must be in (2/3, 1), got {phi:g}")
    return phi


def _exact_ratio(question: str, e1, e2, contact_s, noise_c, delta_t_c, threshold, sensor, width, trials,
                 folds, seed, repeats, z, jobs, ranges) -> Answer:
    from ..scene import Scene

    phi = _threshold(threshold)
    contact = check_positive("contact time [s]", contact_s)
    ex = _exact_setup(sensor, width, trials, folds, seed, repeats, z, jobs)
    cls = _class_ranges(ex, e1, e2, ranges)
    t0 = time.perf_counter()
    lo_r, hi_r = 1e-5, 1.0  # sigma/dT bracket: 10 uK per K to noise as large as the contrast

    def scene(r):
        return Scene.from_delta_t(contact_s=contact, noise_c=r, delta_t_c=1.0)

    r, (r_lo, r_hi), evaluations = _ratio_search(lambda x: _svm_f1(ex, cls, scene(x)), phi, lo_r, hi_r, z)
    ideal_r = None
    if _ideal_f1(ex, cls, scene(lo_r)) >= phi:
        ideal_r = _bisect(lambda x: _ideal_f1(ex, cls, scene(x)) < phi, lo_r, hi_r, 1e-3, log=True)
    if question == "max-noise":
        dt = check_finite("temperature difference [degC]", delta_t_c)
        conv = lambda x: None if x is None else x * abs(dt)  # noqa: E731
        interval = (conv(r_lo), conv(r_hi))
        inputs = {"delta_t_c": dt}
    else:
        noise = check_positive("noise sigma [degC]", noise_c)
        conv = lambda x: None if x is None else noise / x  # noqa: E731
        interval = (conv(r_hi), conv(r_lo))
        inputs = {"noise_c": noise}
    inputs.update({"e1": e1, "e2": e2, "contact_s": contact, "threshold": phi,
                   "classes": [list(c) for c in cls], "trials": ex.trials, "repeats": ex.repeats,
                   "seed": ex.seed, "sensor": ex.sensor.name})
    note = "" if r is not None else "not separable even at sigma/dT = 1e-5"
    return Answer(question, conv(r), interval, conv(ideal_r), "computed", None, None, inputs, {},
                  {"fidelity": "svm", "wall_s": time.perf_counter() - t0, "evaluations": evaluations}, note)


def exact_max_noise(e1=None, e2=None, *, contact_s: float, delta_t_c: float = 10.0, threshold: float = 0.9,
                    sensor=None, width: float = 80.0, trials: int = 100, folds: int = 3, seed: int = 0,
                    repeats: int = 4, z: float = 2.0, jobs: int = -1, ranges=None) -> Answer:
    """Largest noise sigma [degC] that still separates the pair, computed (bisection in log sigma/dT)."""
    return _exact_ratio("max-noise", e1, e2, contact_s, None, delta_t_c, threshold, sensor, width, trials,
                        folds, seed, repeats, z, jobs, ranges)


def exact_min_delta_t(e1=None, e2=None, *, contact_s: float, noise_c: float = 0.05, threshold: float = 0.9,
                      sensor=None, width: float = 80.0, trials: int = 100, folds: int = 3, seed: int = 0,
                      repeats: int = 4, z: float = 2.0, jobs: int = -1, ranges=None) -> Answer:
    """Smallest temperature difference [degC] that separates the pair, computed."""
    return _exact_ratio("min-delta-t", e1, e2, contact_s, noise_c, None, threshold, sensor, width, trials,
                        folds, seed, repeats, z, jobs, ranges)


def exact_distinguishable(e1=None, e2=None, *, contact_s: float, noise_c: float = 0.05, delta_t_c: float = 10.0,
                          threshold: float = 0.9, sensor=None, width: float = 80.0, trials: int = 100,
                          folds: int = 3, seed: int = 0, repeats: int = 4, z: float = 2.0, jobs: int = -1,
                          ranges=None) -> Answer:
    """SVM F1 (mean of ``repeats`` seeds) and ideal F1 of the pair's classes at this scene."""
    from ..scene import Scene

    phi = _threshold(threshold)
    noise, dt = _scene_inputs(noise_c, delta_t_c)
    ex = _exact_setup(sensor, width, trials, folds, seed, repeats, z, jobs)
    cls = _class_ranges(ex, e1, e2, ranges)
    scene = Scene.from_delta_t(contact_s=check_positive("contact time [s]", contact_s), noise_c=noise, delta_t_c=dt)
    t0 = time.perf_counter()
    f1, se = _svm_f1(ex, cls, scene)
    ideal = _ideal_f1(ex, cls, scene)
    yes = f1 >= phi
    conf = "confident" if abs(f1 - phi) >= z * se else "uncertain"
    inputs = {"e1": e1, "e2": e2, "noise_c": noise, "delta_t_c": dt, "contact_s": scene.contact_s,
              "threshold": phi, "classes": [list(c) for c in cls], "trials": ex.trials, "repeats": ex.repeats,
              "seed": ex.seed, "sensor": ex.sensor.name}
    return Answer("distinguishable", float(yes), (f1 - z * se, f1 + z * se), ideal, "computed", None, None,
                  inputs, {}, {"fidelity": "svm", "distinguishable": yes, "svm_f1": f1, "svm_standard_error": se,
                               "verdict": conf, "ideal_f1": ideal, "ideal_distinguishable": ideal >= phi,
                               "wall_s": time.perf_counter() - t0})


def exact_delta_e(e: float, *, contact_s: float, noise_c: float = 0.05, delta_t_c: float = 10.0,
                  threshold: float = 0.9, sensor=None, width: float = 80.0, trials: int = 100, folds: int = 3,
                  seed: int = 0, repeats: int = 4, z: float = 2.0, jobs: int = -1,
                  e_max: float = 40000.0) -> Answer:
    """delta(e) computed for this reference: bisection on the partner's distance, both directions."""
    from ..scene import Scene

    phi = _threshold(threshold)
    e = check_effusivity("e", e)
    noise, dt = _scene_inputs(noise_c, delta_t_c)
    ex = _exact_setup(sensor, width, trials, folds, seed, repeats, z, jobs)
    scene = Scene.from_delta_t(contact_s=check_positive("contact time [s]", contact_s), noise_c=noise, delta_t_c=dt)
    ref = (e, e + ex.width)
    t0 = time.perf_counter()
    res: dict[str, Any] = {}
    for key, sign, limit in (("delta_e_upper", +1, e_max - e - ex.width), ("delta_e_lower", -1, e - ex.width)):
        if limit < ex.width:
            res[key] = res[key + "_ideal"] = None
            continue
        part = lambda d: (e + sign * d, e + sign * d + ex.width)  # noqa: E731
        ok = lambda d: _svm_f1(ex, (ref, part(d)), scene)[0] >= phi  # noqa: E731
        res[key] = _bisect(ok, 0.0, limit, ex.width / 2) if ok(limit) else None
        iok = lambda d: _ideal_f1(ex, (ref, part(d)), scene) >= phi  # noqa: E731
        res[key + "_ideal"] = _bisect(iok, 0.0, limit, 1.0) if iok(limit) else None
    finite = [v for v in (res["delta_e_lower"], res["delta_e_upper"]) if v is not None]
    ifinite = [v for v in (res["delta_e_lower_ideal"], res["delta_e_upper_ideal"]) if v is not None]
    inputs = {"e": e, "noise_c": noise, "delta_t_c": dt, "contact_s": scene.contact_s, "threshold": phi,
              "width": ex.width, "trials": ex.trials, "repeats": ex.repeats, "seed": ex.seed,
              "sensor": ex.sensor.name}
    return Answer("delta-e", min(finite) if finite else None, (None, None), min(ifinite) if ifinite else None,
                  "computed", None, None, inputs, {}, {"fidelity": "svm", **res, "wall_s": time.perf_counter() - t0})
