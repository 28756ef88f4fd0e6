"""Table lookup in pure Python: the one implementation of designkit's interpolation rule.

This module imports only the standard library, so that designkit's Python
export can carry it verbatim: ``designkit export --format python`` writes this
file's text, unchanged, followed by the table's data (a test checks that the
two texts are equal). It works on any indexable sequence of floats: numpy
arrays, ``array.array("d")`` or lists.

The rule (the same as :mod:`designkit.query.table` and the C export)
--------------------------------------------------------------------
* An axis value within a relative :data:`GRID_RTOL` of a grid value *is* that
  grid value; otherwise it is interpolated linearly (``scale == "linear"``) or
  linearly in its logarithm (``"log"``) between its two neighbours; nothing is
  extrapolated (:func:`axis_weights`).
* delta(e) is tabulated at reference-interval centres and interpolated
  linearly in effusivity between the two centres around ``e``; a NaN
  neighbour (no distinguishable partner within the grid) gives NaN, except on
  a centre itself (:func:`interp_e`).
* Two effusivities ``lo < hi`` are distinguishable when

  .. math:: hi - lo \\ge \\max(\\delta_{up}(lo), \\delta_{down}(hi))

  (the *need*; NaN: not within the grid, so not separable).
* The shortest contact time is the first contact column whose need is at most
  ``hi - lo``, interpolated linearly towards the previous column
  (:func:`crossing`).

Units: effusivity and delta [J s^-1/2 K^-1 m^-2], noise sigma per sample
[degC], ``delta_t_c`` = sensor minus object temperature before contact
[degC], contact time [s].

Examples
--------
One scene row, two contact columns (1 s and 2 s), three reference intervals
centred at 100, 200 and 300:

>>> t = Lookup(scene=[("noise_ratio", "log", [0.005])], contact_s=[1.0, 2.0],
...            e_ref=[100.0, 200.0, 300.0],
...            delta_up=[150.0, 120.0, 90.0, 50.0, 45.0, 40.0],
...            delta_down=[90.0, 120.0, 150.0, 40.0, 50.0, 60.0],
...            e_min=50.0, e_max=350.0, name="demo")
>>> t.min_contact_s(100.0, 200.0, 0.05, 10.0)
1.5
>>> t.distinguishable(100.0, 200.0, 0.05, 10.0, 2.0)
True
>>> t.delta_e(200.0, 0.05, 10.0, 2.0)
45.0
>>> t.min_contact_s(100.0, 200.0, 0.5, 10.0)
Traceback (most recent call last):
...
designkit.tables.lookup.OutsideTable: noise_ratio 0.05 is outside table demo's grid [0.005, 0.005] (no extrapolation)
"""

import bisect
import math

__all__ = ["GRID_RTOL", "Lookup", "OutsideTable", "axis_weights", "contact_input", "crossing", "effusivity_input",
           "interp_e", "pair_input", "scene_inputs"]

#: A value within this relative distance of a grid value is that grid value. A float32
#: argument (0.05f / 10.0f, as on a microcontroller) cannot hit 0.005 exactly; the query,
#: the C export and this module use the same rule, so all three answer alike.
GRID_RTOL = 1e-6


class OutsideTable(ValueError):
    """An input lies outside the table's grid (nothing is extrapolated): ask designkit (``--exact``)."""


def axis_weights(values, x, log=False, grid=None):
    """Interpolation weights of ``x`` on one axis, or None outside it.

    Parameters
    ----------
    values : sequence of float
        Grid values, increasing [the axis' unit].
    x : float
        The value to place [the axis' unit].
    log : bool
        Interpolate linearly in ``log(x)`` (a ``"log"`` axis) instead of ``x``.
    grid : sequence of float, optional
        The grid interpolated on: ``log(values)`` for a log axis (pass numpy's
        values to agree with numpy to the last bit), ``values`` otherwise.
        Default: computed here with :func:`math.log`.

    Returns
    -------
    list of (int, float) or None
        ``[(k, 1.0)]`` when ``x`` is within :data:`GRID_RTOL` of ``values[k]``;
        ``[(j, 1 - w), (j + 1, w)]`` between two grid values; None when ``x`` is
        outside the grid (or the grid has one value that ``x`` is not).

    Examples
    --------
    >>> axis_weights([1.0, 2.0, 4.0], 3.0)
    [(1, 0.5), (2, 0.5)]
    >>> axis_weights([1.0, 2.0, 4.0], 2.0 * (1 + 1e-9))
    [(1, 1.0)]
    >>> axis_weights([1.0, 4.0], 2.0, log=True)
    [(0, 0.5), (1, 0.5)]
    >>> axis_weights([1.0, 2.0], 2.5) is None
    True
    """
    n = len(values)
    for k in range(n):
        v = values[k]
        if abs(x - v) <= GRID_RTOL * abs(v):
            return [(k, 1.0)]
    if n == 1 or x < values[0] or x > values[n - 1]:
        return None
    if log:
        if x <= 0 or values[0] <= 0:
            return None
        u = math.log(x)
        if grid is None:
            grid = [math.log(v) for v in values]
    else:
        u = x
        if grid is None:
            grid = values
    j = min(max(bisect.bisect_left(grid, u) - 1, 0), n - 2)
    w = min(max(float((u - grid[j]) / (grid[j + 1] - grid[j])), 0.0), 1.0)
    return [(j, 1.0 - w), (j + 1, w)]


def interp_e(row, centres, e, start=0):
    """delta at effusivity ``e`` from its values at the reference-interval centres.

    Parameters
    ----------
    row : sequence of float
        delta [J s^-1/2 K^-1 m^-2] at each centre, from index ``start`` on; NaN:
        no distinguishable partner within the grid.
    centres : sequence of float
        Reference-interval centres, increasing [J s^-1/2 K^-1 m^-2].
    e : float
        Effusivity [J s^-1/2 K^-1 m^-2]; below the first centre (above the
        last) the first (last) value holds.
    start : int
        Offset of the row in ``row`` (a flat array of many rows).

    Returns
    -------
    float
        Linear interpolation between the centres around ``e``; a centre's own
        value on a centre; NaN when a neighbour is NaN.

    Examples
    --------
    >>> interp_e([10.0, 20.0, 40.0], [100.0, 200.0, 300.0], 250.0)
    30.0
    >>> interp_e([10.0, float("nan"), 40.0], [100.0, 200.0, 300.0], 250.0)
    nan
    >>> interp_e([10.0, float("nan"), 40.0], [100.0, 200.0, 300.0], 300.0)
    40.0
    """
    n = len(centres)
    if e <= centres[0]:
        return row[start]
    if e >= centres[n - 1]:
        return row[start + n - 1]
    j = bisect.bisect_right(centres, e) - 1  # centres[j] <= e < centres[j + 1]
    a, b = row[start + j], row[start + j + 1]
    w = (e - centres[j]) / (centres[j + 1] - centres[j])
    if w == 0.0:  # on a centre: its own value, whatever the neighbour holds
        return a
    if math.isnan(a) or math.isnan(b):
        return math.nan
    return a + w * (b - a)


def crossing(xs, needs, gap, adjacent=None):
    """First ``x`` at which the need falls to ``gap``, interpolated linearly between grid points.

    Parameters
    ----------
    xs : sequence of float
        Grid points, increasing (contact times [s]).
    needs : iterable of float
        The need at each grid point (NaN: beyond the grid); read lazily, up to
        the first point that suffices.
    gap : float
        The distance available (``hi - lo``).
    adjacent : sequence of bool, optional
        ``adjacent[k]``: points ``k`` and ``k + 1`` are neighbours in the source
        grid; when not, the answer is the later point (no interpolation across
        a gap). Default: all neighbours.

    Returns
    -------
    (float, int) or (None, None)
        The crossing and the index of the first point that suffices, or
        ``(None, None)`` when none does. After a NaN need the answer is the
        point itself (no interpolation into "beyond the grid").

    Examples
    --------
    >>> crossing([1.0, 2.0, 3.0], [300.0, 150.0, 50.0], 100.0)
    (2.5, 2)
    >>> crossing([1.0, 2.0, 3.0], [300.0, 150.0, 50.0], 100.0, adjacent=[True, False])
    (3.0, 2)
    >>> crossing([1.0, 2.0], [300.0, 150.0], 100.0)
    (None, None)
    """
    prev = math.nan
    for k, nd in enumerate(needs):
        if not math.isnan(nd) and nd <= gap:
            if k == 0:
                return float(xs[0]), 0
            if math.isnan(prev) or (adjacent is not None and not adjacent[k - 1]):
                return float(xs[k]), k
            w = (prev - gap) / (prev - nd) if prev != nd else 1.0
            return float(xs[k - 1] + w * (xs[k] - xs[k - 1])), k
        prev = nd
    return None, None


# ------------------------------------------------------------ input checks (designkit.query's rules; also the
# exported estimator's, designkit/export/estimator.py)
def _number(name, x):
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise ValueError(name + " must be a number, got " + repr(x)) from None
    if not math.isfinite(v):
        raise ValueError(name + " must be finite, got " + repr(v))
    return v


def effusivity_input(name, x):
    """Effusivity ``name`` as a positive finite float [J s^-1/2 K^-1 m^-2] (ValueError otherwise)."""
    v = _number("effusivity " + name, x)
    if v <= 0:
        raise ValueError("effusivity " + name + " must be positive, got " + repr(v))
    return v


def scene_inputs(noise_c, delta_t_c):
    """``(noise, dT)`` [degC]: noise >= 0 and dT != 0, both finite (ValueError otherwise)."""
    noise = _number("noise sigma [degC]", noise_c)
    if noise < 0:
        raise ValueError("noise sigma [degC] must be >= 0, got " + repr(noise))
    dt = _number("temperature difference [degC]", delta_t_c)
    if dt == 0:
        raise ValueError("temperature difference is 0: an unheated sensor sees no contrast between materials")
    return noise, dt


def contact_input(contact_s):
    """Contact time [s] as a positive finite float (ValueError otherwise)."""
    c = _number("contact time [s]", contact_s)
    if c <= 0:
        raise ValueError("contact time [s] must be positive, got " + repr(c))
    return c


def pair_input(e1, e2):
    """Two different effusivities as ``(lo, hi)`` [J s^-1/2 K^-1 m^-2] (ValueError otherwise)."""
    a, b = effusivity_input("e1", e1), effusivity_input("e2", e2)
    if a == b:
        raise ValueError("e1 and e2 are equal (" + repr(a) + "): nothing to separate")
    return (a, b) if a < b else (b, a)


class Lookup:
    """The design questions answered from one table's arrays.

    Parameters
    ----------
    scene : sequence of tuple
        Scene axes in array order, each ``(name, scale, values)`` or ``(name,
        scale, values, grid)`` (see :func:`axis_weights`): either one
        ``"noise_ratio"`` axis (sigma/dT [1]) or ``"noise_c"`` [degC] and
        ``"delta_t_c"`` [degC].
    contact_s : sequence of float
        Contact-time columns [s], increasing.
    e_ref : sequence of float
        Reference-interval centres [J s^-1/2 K^-1 m^-2], increasing.
    delta_up, delta_down : sequence of float
        delta(e) towards higher / lower effusivity [J s^-1/2 K^-1 m^-2], flat
        in row-major order ``[scene..., contact, e_ref]`` (``numpy.ravel``);
        NaN: no distinguishable partner within the grid.
    e_min, e_max : float
        Effusivities answered: ``e_min < e <= e_max`` [J s^-1/2 K^-1 m^-2].
    e_min_inclusive : bool
        Answer ``e == e_min`` too (a slice's lower end).
    contact_adjacent : sequence of bool, optional
        ``contact_adjacent[k]``: columns ``k`` and ``k + 1`` are neighbours in
        the source table (default: all are). Between two that are not, a
        contact time is refused and ``min_contact_s`` answers the later column.
    name : str
        The table's name, for messages.

    Notes
    -----
    Answers: a float or bool; None where nothing in the table suffices;
    :class:`OutsideTable` (a ValueError) for an input outside the grid;
    ValueError for invalid input (NaN or infinite, ``e <= 0``, noise < 0,
    dT == 0, contact <= 0, ``e1 == e2``).
    """

    def __init__(self, scene, contact_s, e_ref, delta_up, delta_down, e_min, e_max, e_min_inclusive=False,
                 contact_adjacent=None, name="table"):
        self.scene = [(ax[0], ax[1], ax[2], ax[3] if len(ax) > 3 else None) for ax in scene]
        self.contact_s = contact_s
        self.e_ref = e_ref
        self.delta_up = delta_up
        self.delta_down = delta_down
        self.e_min, self.e_max, self.e_min_inclusive = e_min, e_max, bool(e_min_inclusive)
        self.contact_adjacent = contact_adjacent
        self.name = name
        names = [ax[0] for ax in self.scene]
        if names not in (["noise_ratio"], ["noise_c", "delta_t_c"]):
            raise ValueError("scene axes must be [noise_ratio] or [noise_c, delta_t_c], got " + repr(names))
        self._ratio = names == ["noise_ratio"]
        self._nc, self._ne = len(contact_s), len(e_ref)
        rows = 1
        for ax in self.scene:
            rows *= len(ax[2])
        size = rows * self._nc * self._ne
        if len(delta_up) != size or len(delta_down) != size:
            raise ValueError("delta arrays hold %d and %d values; the axes need %d"
                             % (len(delta_up), len(delta_down), size))

    # ---- grid coordinates
    def _outside(self, name, x, vals):
        return OutsideTable("%s %g is outside table %s's grid [%g, %g] (no extrapolation)"
                            % (name, x, self.name, min(vals), max(vals)))

    def scene_weights(self, noise, dt):
        """Flat scene-row indices and weights ``[(row, w)]`` for noise sigma [degC] and dT [degC]."""
        wanted = {"noise_ratio": noise / abs(dt)} if self._ratio else {"noise_c": noise, "delta_t_c": dt}
        combos = [(0, 1.0)]
        for name, scale, vals, grid in self.scene:
            pts = axis_weights(vals, wanted[name], scale == "log", grid)
            if pts is None:
                raise self._outside(name, wanted[name], vals)
            n = len(vals)
            combos = [(idx * n + k, w * wk) for idx, w in combos for k, wk in pts]
        return combos

    def contact_weights(self, contact):
        """Contact columns and weights ``[(k, w)]`` for a contact time [s]."""
        pts = axis_weights(self.contact_s, contact)
        if pts is None:
            raise self._outside("contact_s", contact, self.contact_s)
        adj = self.contact_adjacent
        if len(pts) == 2 and adj is not None and not adj[pts[0][0]] and 0 < pts[1][1] < 1:
            raise OutsideTable("contact time %g s falls between exported columns %g and %g s, which are not "
                               "neighbours in table %s" % (contact, self.contact_s[pts[0][0]],
                                                           self.contact_s[pts[1][0]], self.name))
        return pts

    def _check_e(self, *es):
        for e in es:
            if not ((e >= self.e_min if self.e_min_inclusive else e > self.e_min) and e <= self.e_max):
                raise OutsideTable("effusivity %g is outside the range %s%g, %g] answered by table %s "
                                   "(no extrapolation)" % (e, "[" if self.e_min_inclusive else "(", self.e_min,
                                                           self.e_max, self.name))

    # ---- delta and the need
    def delta_at(self, arr, combos, k, e):
        """``arr`` (delta_up or delta_down) at scene weights, contact column ``k``, effusivity ``e`` (NaN: none)."""
        total = 0.0
        nc, ne, centres = self._nc, self._ne, self.e_ref
        for row, w in combos:
            if w == 0:
                continue
            v = interp_e(arr, centres, e, (row * nc + k) * ne)
            if math.isnan(v):
                return math.nan
            total += w * v
        return total

    def need(self, combos, k, lo, hi):
        """Distance needed to separate ``lo < hi`` at contact column ``k`` (NaN: not within the grid)."""
        up = self.delta_at(self.delta_up, combos, k, lo)
        down = self.delta_at(self.delta_down, combos, k, hi)
        if math.isnan(up) or math.isnan(down):
            return math.nan
        return max(up, down)

    @staticmethod
    def _over_contact(cw, value_at):
        """Contact-weighted sum of ``value_at(k)``; None when a needed grid point has no value."""
        total = 0.0
        for k, w in cw:
            if w == 0:
                continue
            x = value_at(k)
            if math.isnan(x):
                return None
            total += w * x
        return float(total)

    # ---- the questions
    def _deltas(self, e, noise_c, delta_t_c, contact_s):
        e = effusivity_input("e", e)
        contact = contact_input(contact_s)
        noise, dt = scene_inputs(noise_c, delta_t_c)
        combos = self.scene_weights(noise, dt)
        cw = self.contact_weights(contact)
        self._check_e(e)
        return [self._over_contact(cw, lambda k, arr=arr: self.delta_at(arr, combos, k, e))
                for arr in (self.delta_down, self.delta_up)]

    def delta_e_lower(self, e, noise_c, delta_t_c, contact_s):
        """delta(e) towards lower effusivity [J s^-1/2 K^-1 m^-2]; None: none within the grid."""
        return self._deltas(e, noise_c, delta_t_c, contact_s)[0]

    def delta_e_upper(self, e, noise_c, delta_t_c, contact_s):
        """delta(e) towards higher effusivity [J s^-1/2 K^-1 m^-2]; None: none within the grid."""
        return self._deltas(e, noise_c, delta_t_c, contact_s)[1]

    def delta_e(self, e, noise_c, delta_t_c, contact_s):
        """Smallest distinguishable effusivity difference from ``e``, the smaller direction
        [J s^-1/2 K^-1 m^-2]; None: none within the grid in either direction."""
        finite = [v for v in self._deltas(e, noise_c, delta_t_c, contact_s) if v is not None]
        return min(finite) if finite else None

    def min_contact_s(self, e1, e2, noise_c, delta_t_c):
        """Shortest contact time [s] that separates ``e1`` from ``e2``; None: no tabulated contact time suffices."""
        noise, dt = scene_inputs(noise_c, delta_t_c)
        lo, hi = pair_input(e1, e2)
        combos = self.scene_weights(noise, dt)
        self._check_e(lo, hi)
        needs = (self.need(combos, k, lo, hi) for k in range(self._nc))
        return crossing(self.contact_s, needs, hi - lo, self.contact_adjacent)[0]

    def distinguishable(self, e1, e2, noise_c, delta_t_c, contact_s):
        """Whether ``contact_s`` [s] separates ``e1`` from ``e2`` (need <= distance)."""
        contact = contact_input(contact_s)
        noise, dt = scene_inputs(noise_c, delta_t_c)
        lo, hi = pair_input(e1, e2)
        combos = self.scene_weights(noise, dt)
        cw = self.contact_weights(contact)
        self._check_e(lo, hi)
        total = self._over_contact(cw, lambda k: self.need(combos, k, lo, hi))
        return total is not None and bool(total <= hi - lo)
