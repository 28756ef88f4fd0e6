"""The SVM's efficiency against the exact ideal observer, read from a table: min-contact's and max-noise's
*noise efficiency* k (:func:`noise_k_min_contact`, :func:`noise_k_max_ratio`), delta-e's ratio of needs
(:func:`delta_efficiency_estimate`), and the calibration of a table's Monte Carlo errors
(:func:`mc_calibration`). All elementwise over arrays.
"""

from __future__ import annotations

import math

import numpy as np

from ..models.semi_infinite import object_weight
from ..recognition.ideal import critical_noise, shape_norm
from ..tables.store import Table
from .ideal_bound import columns, exact_ideal_delta, noise_k_contact, pair_critical_noise


__all__ = [
    "CLOSED_FORM_MAX_CONTACT_S", "K_SLOPE_SPAN", "NOISE_GRID_NODES", "CriticalNoiseGrid",
    "delta_efficiency_estimate", "delta_entries", "interp_e_by", "k_baseline", "mc_calibration", "median", "noise_k_max_ratio",
    "noise_k_min_contact", "span_neighbours", "table_z"
]


#: Longest contact [s] the closed-form ideal bound examines (the exact route's default).
CLOSED_FORM_MAX_CONTACT_S = 10.0



def median(x: np.ndarray) -> float:
    """The median of a non-empty 1-D array (not ``np.median``, whose first call imports ``numpy.ma``:
    docs/decisions-log.md).

    >>> median(np.array([3.0, 1.0, 10.0, 2.0])), median(np.array([5.0, 1.0, 4.0]))
    (2.5, 4.0)
    """
    k = x.size // 2
    p = np.partition(x, [k - 1, k] if x.size > 1 else [0])
    return float(p[k]) if x.size % 2 else 0.5 * float(p[k - 1] + p[k])


def table_z(tab: Table) -> float:
    """The z (standard errors) of the table's Monte Carlo interval of delta(e) (its header; 2 if absent)."""
    return float(tab.header.get("z") or 2.0)


def interp_e_by(at, centres: np.ndarray, e: np.ndarray) -> np.ndarray:
    """:func:`designkit.tables.lookup.interp_e`'s rule over arrays: ``at(c)`` gives the tabulated values at
    centre indices ``c`` (an array shaped as ``e``), and the result is shaped as what ``at`` returns.

    >>> centres, vals = np.array([0.0, 1.0, 2.0]), np.array([10.0, 20.0, np.nan])
    >>> interp_e_by(lambda c: vals[c], centres, np.array([-1.0, 0.5, 1.0, 1.5, 3.0])).tolist()
    [10.0, 15.0, 20.0, nan, nan]
    """
    n = centres.size
    c = np.minimum(np.maximum(centres.searchsorted(e, side="right") - 1, 0), n - 2)
    c1 = c + 1
    a, b = at(c), at(c1)
    left = centres[c]
    w = (e - left) / (centres[c1] - left)
    # (NaN, a value beyond the grid, propagates through a + w (b - a); on a centre itself only a is read)
    out = np.where(w == 0.0, a, a + w * (b - a))
    if np.count_nonzero(top := e >= centres[-1]):
        out = np.where(top, at(np.full_like(c, n - 1)), out)
    if np.count_nonzero(bottom := e <= centres[0]):
        out = np.where(bottom, at(np.zeros_like(c)), out)
    return out


#: The shortest span in contact time [ratio] over which min-contact reads the slope of ``log k`` in ``log t``:
#: closer readings give a slope that is mostly the table's Monte Carlo noise (docs/decisions-log.md).
K_SLOPE_SPAN = 1.14


def span_neighbours(contacts_s, k):
    """The contacts at least :data:`K_SLOPE_SPAN` away from ``contacts_s[k]`` on each side: the index of the latest
    at or below ``contacts_s[k] / K_SLOPE_SPAN`` and of the first at or above ``contacts_s[k] * K_SLOPE_SPAN``
    (-1 where none), elementwise over the indices ``k``.

    >>> c = np.array([0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.5, 2.0])
    >>> [a.tolist() for a in span_neighbours(c, np.array([0, 1, 5, 7]))]
    [[-1, 0, 3, 6], [1, 2, 6, -1]]
    """
    c, k = np.asarray(contacts_s, dtype=np.float64), np.asarray(k, dtype=np.int64)
    back = np.searchsorted(c, c[k] / K_SLOPE_SPAN * (1 + 1e-12), side="right") - 1
    ahead = np.searchsorted(c, c[k] * K_SLOPE_SPAN * (1 - 1e-12), side="left")
    return back, np.where(ahead < c.size, ahead, -1)


def k_baseline(contacts_s, k_cross):
    """Index of the contact where min-contact reads ``k`` beside the crossing's contact ``k_cross``: the
    latest at or below ``contacts_s[k_cross] / K_SLOPE_SPAN`` (at least one step back, and the first contact
    where none lies that far back), or, where ``k_cross`` is the first, the first at or above
    ``contacts_s[0] * K_SLOPE_SPAN``; -1 where none.

    >>> c = np.array([0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.5, 2.0])
    >>> k_baseline(c, np.array([5, 6, 7, 0, 1])).tolist()
    [3, 5, 6, 1, 0]
    """
    kb = np.asarray(k_cross, dtype=np.int64)
    back, ahead = span_neighbours(contacts_s, kb)  # (where kb is the first contact, ahead is read from it)
    return np.where(kb > 0, np.maximum(back, 0), ahead)


def mc_calibration(table) -> float:
    """Factor on the table's Monte Carlo standard errors that matches the scatter of its own entries.

    Measured on the table itself (leave one contact out): every interior contact's log efficiency
    ``log((svm need - w/2) / (ideal need - w/2))`` (both directions, every noise-ratio slice and
    effusivity) is predicted from its two neighbours on the contact axis at least :data:`K_SLOPE_SPAN`
    away on each side (linear in log t); each residual
    is standardized by the SD its three entries' stated errors give: ``f`` times the table's Monte Carlo
    SE of each SVM need (``delta_lo`` / ``delta_hi``, ``z`` SEs each) and the rounding of both needs
    (``w/sqrt(12)`` each). The factor ``f`` is the one that makes the standardized residuals' robust SD
    (1.4826 x median |r|) 1. Entries whose ideal need is under four widths (rounding dominates there)
    are left out. The residuals also carry the need's curvature across two cells, so ``f`` errs high
    (on svm-paper 0.78: its Monte Carlo intervals are a quarter wider than its entries scatter; on
    svm-fine 0.72).
    1 where the table has no ideal needs or no Monte Carlo interval to calibrate (fewer than 20
    residuals). Computed once per table by its view (:meth:`~designkit.query.table_arrays.TableView.mc_calibration`).
    """
    arrays, h = table.arrays, 0.5 * float(table.header["effusivity"]["width"])
    rnd_sd, z = 2.0 * h / math.sqrt(12.0), table_z(table)
    lt = np.log(table.axes["contact_s"])
    res, vm, vr = [], [], []
    for d in ("up", "down"):
        if f"delta_{d}_ideal" not in arrays or f"delta_{d}_lo" not in arrays:
            continue
        svm, ideal = arrays[f"delta_{d}"], arrays[f"delta_{d}_ideal"]  # [slice, contact, e_ref]
        lo, hi = arrays[f"delta_{d}_lo"], arrays[f"delta_{d}_hi"]
        with np.errstate(invalid="ignore", divide="ignore"):
            le = np.log((svm - h) / (ideal - h))
            rnd2 = (rnd_sd / (svm - h)) ** 2 + (rnd_sd / (ideal - h)) ** 2
            mc = np.where(np.isfinite(hi) & (lo > h), np.log((hi - h) / (lo - h)) / (2.0 * z),
                          np.where(lo > h, np.log((svm - h) / (lo - h)) / z, np.nan))
        # the neighbours at least K_SLOPE_SPAN away: entries closer than that share most of their touches (a
        # shorter contact is a prefix of a longer one) and their Monte Carlo errors correlate, which shrinks the
        # residuals (on svm-fine f is 0.65 from neighbours 0.1 s apart, 0.71, 0.75, 0.77 from 0.2, 0.3, 0.4 s);
        # on svm-paper's axis these are the next contacts
        backs, aheads = span_neighbours(table.axes["contact_s"], np.arange(lt.size))
        for k, a, b in zip(range(lt.size), backs, aheads):
            if a < 0 or b < 0:
                continue
            w = (lt[k] - lt[a]) / (lt[b] - lt[a])
            # entries at or below half a width give infinite logs (inf - inf here): left out by `ok`
            with np.errstate(invalid="ignore", over="ignore"):
                r = le[:, k] - ((1.0 - w) * le[:, a] + w * le[:, b])
                v_mc = mc[:, k] ** 2 + ((1.0 - w) * mc[:, a]) ** 2 + (w * mc[:, b]) ** 2
                v_rnd = rnd2[:, k] + (1.0 - w) ** 2 * rnd2[:, a] + w ** 2 * rnd2[:, b]
                ok = (np.isfinite(r) & np.isfinite(v_mc) & (v_mc > 0) & np.isfinite(v_rnd)
                      & (np.fmin(np.fmin(ideal[:, a], ideal[:, k]), ideal[:, b]) >= 8.0 * h))
            res.append(r[ok]), vm.append(v_mc[ok]), vr.append(v_rnd[ok])
    r = np.abs(np.concatenate(res)) if res else np.zeros(0)
    value = 1.0
    if r.size >= 20:
        v_mc, v_rnd = np.concatenate(vm), np.concatenate(vr)
        a, b = math.log(0.05), math.log(20.0)  # bisection on log f: the robust SD falls as f grows
        for _ in range(30):
            f = math.exp(0.5 * (a + b))
            if 1.4826 * median(r / np.sqrt(f * f * v_mc + v_rnd)) > 1.0:
                a = math.log(f)
            else:
                b = math.log(f)
        value = math.exp(0.5 * (a + b))
    return value


# ============================================================ the ideal observer's critical noise, per table
#: :class:`CriticalNoiseGrid`'s nodes per axis, its offset A0 [J s^-1/2 K^-1 m^-2] in ``log(lo + A0)`` and its
#: smallest distance (in class widths): measured against :func:`~designkit.recognition.ideal.critical_noise` on
#: 8,000 random pairs of the paper sensor (lo in [0, 40,080], distances 160 to 40,160, width 80): relative error
#: at most 4.5e-7 (99th percentile 1.9e-7, median 2.9e-10).
NOISE_GRID_NODES, NOISE_GRID_A0, NOISE_GRID_MIN_WIDTHS = 128, 100.0, 2.0
#: The grid is solved in aligned blocks of this many nodes a side, each the first time a pair reads one of
#: its nodes (a solve's fixed cost is several node's: a process's first questions then fill the blocks later
#: ones read).
NOISE_GRID_BLOCK = 8


class CriticalNoiseGrid:
    """The ideal observer's critical noise ``s*(lo, hi)`` (:func:`~designkit.recognition.ideal.critical_noise`) of
    one sensor, class width and threshold, read off a grid instead of a Newton solve per pair: the table route's
    per-table memo of it (held by :class:`~designkit.query.table_arrays.TableView`).

    The grid is regular in ``u = log(lo + A0)`` (``lo`` in [0, ``e_top`` + 2 widths]) and ``v = log(hi - lo)``
    (2 widths to ``e_top`` + 3 widths) and holds ``log(s* / (w(hi) - w(lo)))``, ``w(e) = e / (e_s + e)`` the
    contact weight (that ratio is smooth and nearly constant); a pair reads it by tensor-product cubic Lagrange
    interpolation on the 4 x 4 nodes around it (one-sided at the grid's edges). A node is solved exactly the
    first time a pair needs it (the grid fills on demand: a node's value does not depend on which pairs asked
    for it), so an answer does not depend on what the process asked before. Pairs outside the grid (distances
    under two widths, where the classes nearly overlap and ``s*`` falls steeply to 0) get the exact solve.
    Accuracy: :data:`NOISE_GRID_NODES`.
    """

    def __init__(self, sensor, width: float, threshold: float, e_top: float):
        self.sensor, self.width, self.threshold = sensor, float(width), float(threshold)
        self.e_s = float(sensor.effusivity)
        n = NOISE_GRID_NODES
        self.u0 = math.log(NOISE_GRID_A0)
        self.du = (math.log(e_top + 2.0 * width + NOISE_GRID_A0) - self.u0) / (n - 1)
        self.v0 = math.log(NOISE_GRID_MIN_WIDTHS * width)
        self.dv = (math.log(e_top + 3.0 * width) - self.v0) / (n - 1)
        self._origin = np.array([[self.u0], [self.v0]])  # (u, v) of node (0, 0) and the steps, [2, 1] each
        self._step = np.array([[self.du], [self.dv]])
        self.values = np.full(n * n, np.nan)  # log(s* / dw) at node (i, j), flat i * n + j
        self.known = np.zeros(n * n, dtype=bool)

    def _fill(self, nodes: np.ndarray) -> None:
        """Solve the nodes ``nodes`` (flat indices) exactly, in one vectorized call."""
        n = NOISE_GRID_NODES
        lo = np.maximum(np.exp(self.u0 + self.du * (nodes // n)) - NOISE_GRID_A0, 0.0)
        hi = lo + np.exp(self.v0 + self.dv * (nodes % n))
        star = critical_noise(self.sensor, lo, hi, width=self.width, threshold=self.threshold)
        with np.errstate(divide="ignore", invalid="ignore"):
            self.values[nodes] = np.log(star) - np.log(object_weight(self.e_s, hi) - object_weight(self.e_s, lo))
        self.known[nodes] = True

    def __call__(self, lo, hi) -> np.ndarray:
        """``s*`` of the classes ``[lo, lo + w)``, ``[hi, hi + w)``, elementwise (NaN: not separable)."""
        lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
        if lo.shape != hi.shape or lo.ndim != 1:
            lo, hi = np.broadcast_arrays(lo, hi)
        shape, lo, hi = lo.shape, lo.ravel(), hi.ravel()
        n = NOISE_GRID_NODES
        with np.errstate(divide="ignore", invalid="ignore"):
            # the grid coordinates (u, v) of every pair, [2, pair]
            p = (np.log(np.array([lo + NOISE_GRID_A0, hi - lo])) - self._origin) / self._step
            inside = (lo >= 0) & (p[0] <= n - 1) & (p[1] >= 0) & (p[1] <= n - 1)
        i = inside.nonzero()[0]
        every = 0 < i.size == lo.size  # (every pair inside: the arrays themselves, the answer itself)
        if not every:
            out = np.empty(lo.size)
            out.fill(np.nan)
        if i.size:
            i, p, lo_i, hi_i = (slice(None), p, lo, hi) if every else (i, p[:, i], lo[i], hi[i])
            s = np.minimum(np.maximum(np.floor(p).astype(np.int64) - 1, 0), n - 4)  # the first of 4 nodes a side
            flat = (s[0] * n + s[1])[:, None, None] + _NODES4  # the 4 x 4 nodes around each pair
            if np.count_nonzero(known := self.known[flat]) < known.size:
                missing = flat[~self.known[flat]]  # the whole blocks of NOISE_GRID_BLOCK x NOISE_GRID_BLOCK nodes around them
                b = NOISE_GRID_BLOCK
                wanted = np.zeros((n // b) ** 2, dtype=bool)  # (not np.unique: its first call imports numpy.ma)
                wanted[(missing // n) // b * (n // b) + (missing % n) // b] = True
                blocks = np.flatnonzero(wanted)
                rows = (blocks // (n // b))[:, None, None] * b + np.arange(b)[None, :, None]
                cols = (blocks % (n // b))[:, None, None] * b + np.arange(b)[None, None, :]
                nodes = (rows * n + cols).ravel()
                self._fill(nodes[~self.known[nodes]])
            lu, lv = _lagrange4(p - s)
            g = np.einsum("pi,pj,pij->p", lu, lv, self.values[flat])
            w = object_weight(self.e_s, np.array([hi_i, lo_i]))
            if every:
                out = np.exp(g) * (w[0] - w[1])
            else:
                out[i] = np.exp(g) * (w[0] - w[1])
        # (every pair inside the grid has finite lo and hi)
        rest = (np.isnan(out) if every else
                np.isnan(out) & np.isfinite(lo) & np.isfinite(hi)).nonzero()[0]
        if rest.size:  # outside the grid (or next to a node that does not separate): the exact solve
            out[rest] = pair_critical_noise(self.sensor, lo[rest], hi[rest], width=self.width,
                                            threshold=self.threshold)
        return out.reshape(shape)


_FOUR = np.arange(4)
_FOUR.flags.writeable = False
#: The flat offsets of the 4 x 4 nodes from the first (row-major, :data:`NOISE_GRID_NODES` a row).
_NODES4 = _FOUR[:, None] * NOISE_GRID_NODES + _FOUR[None, :]
_NODES4.flags.writeable = False
#: Weight j of :func:`_lagrange4` is ``(x - A) S (x - B) (x - C) / D``: the other nodes A, B, C, sign S.
_LAGRANGE = np.array([[1.0, 0.0, 0.0, 0.0], [-1.0, 1.0, -1.0, 1.0], [2.0, 2.0, 1.0, 1.0], [3.0, 3.0, 3.0, 2.0],
                      [6.0, 2.0, 2.0, 6.0]])
_LAGRANGE.flags.writeable = False


def _lagrange4(x: np.ndarray) -> np.ndarray:
    """Cubic Lagrange weights of the nodes 0, 1, 2, 3 at positions ``x`` (in [0, 3]): shape ``x.shape + (4,)``
    (``-(x-1)(x-2)(x-3)/6``, ``x(x-2)(x-3)/2``, ``-x(x-1)(x-3)/2``, ``x(x-1)(x-2)/6``, in that order)."""
    first, sign, second, third, div = _LAGRANGE
    x = x[..., None]
    return (x - first) * sign * (x - second) * (x - third) / div


# ============================================================ the noise efficiency (min-contact)
def _entries(view, slices, ka, kb, lo, hi, readings=None):
    """The entries of a pair's noise efficiency (``delta_{up,down}{,_lo,_hi}`` upwards at ``lo``, downwards at
    ``hi``, at contacts ``ka`` / ``kb`` in the pair's slices ``slices`` (n, m)): (need / lo / hi 3, contact 2,
    slice m, direction 2, pair n), the clipped contacts (2, n) and whether each is the one asked. ``readings``:
    :meth:`~designkit.query.table_arrays.TableView.readings` of the first three kinds, read already."""
    kk = np.array([ka, kb])
    jj = np.minimum(np.maximum(kk, 0), view.contacts.size - 1)  # (2, n)
    if readings is not None:  # [direction, kind, slice, contact, pair] at jj -> [kind, contact, slice, direction, pair]
        return readings[:, :3, :, jj, np.arange(lo.size)].transpose(1, 3, 2, 0, 4), jj, jj == kk
    si = slices.T[None]  # (1, m, n)
    j = jj[:, None, :]  # (2, 1, n)
    sides = []
    for d, e in (("up", lo), ("down", hi)):  # the need and its two ends in one reading per direction
        arrays = [view.t.arrays[f"delta_{d}{suffix}"] for suffix in ("", "_lo", "_hi")]
        sides.append(interp_e_by(lambda c: np.stack([a[si, j, c] for a in arrays]), view.centres,
                                 np.broadcast_to(e, (2, si.shape[1], e.size))))
    return np.stack(sides, axis=3), jj, jj == kk  # [need / lo / hi, contact, slice, direction, pair]


def _k_readings(op, slices, sw, ka, kb, lo, hi, extra=None, readings=None):
    """The noise efficiency ``log k`` and its standard error at the tabulated contacts ``ka`` and ``kb`` (rows
    0 and 1 of the (2, n) arrays; NaN: no usable entry), per pair, from the pair's own entries (upwards at
    ``lo``, downwards at ``hi``) in the noise-ratio slices ``slices`` (n, m) weighted ``sw`` (n, m); see
    :func:`noise_k_min_contact`. The entries' critical noises are read off the table's
    :class:`CriticalNoiseGrid`; ``extra``: (lo, hi) of further pairs read in the same call, whose critical
    noises are returned third (None: not asked). Called inside its callers' ``np.errstate(divide="ignore",
    invalid="ignore")`` (one context for the whole computation)."""
    view, width = op.view, op.width
    z_table = table_z(op.tab)
    n = lo.size
    h, rnd_sd = 0.5 * width, width / math.sqrt(12.0)
    entries, jj, ok_j = _entries(view, slices, ka, kb, lo, hi, readings)  # (3, 2, m, 2, n); (2, n) twice
    d = entries[0]
    shape = d.shape
    ok = np.isfinite(d) & (d > width) & (sw.T[None, :, None, :] > 0) & ok_j[:, None, None, :]
    ok[:, :, 1] &= hi - (d[:, :, 1] - h) > 0  # downwards: the partner stays above 0
    # the entries in (contact, slice, direction, pair) order
    Cc, M4, S4, P = ok.nonzero()  # (C order: contact, slice, direction, pair)
    D, DL, DH = entries[:, ok]
    W = sw[P, M4]
    RS = view.t.axes["noise_ratio"][slices[P, M4]]
    s_t = RS / view.contact_norms()[jj[Cc, P]]
    # the entry's pairs of lower edges at its need and one width further, from its reference (upwards at lo,
    # downwards at hi): one reading of the grid for every entry, at both distances, and the extra pairs
    up = S4 == 0
    e_ref = np.array([lo, hi])[S4, P]
    dist = (D - h) + np.array([[0.0], [width]])  # (2, k)
    a = np.where(up, e_ref, e_ref - dist)
    b = np.where(up, e_ref + dist, e_ref)
    np.maximum(a[1], 0.0, out=a[1])
    k = P.size
    if extra is not None:
        a, b = np.concatenate([a.ravel(), extra[0]]), np.concatenate([b.ravel(), extra[1]])
    star = view.critical_noise(a.ravel(), b.ravel())
    s1, s2 = star[:k], star[k:2 * k]
    log_k = np.log(s1 / s_t)
    gamma = np.abs(np.log(s2 / s1) / np.log(dist[1] / dist[0]))
    low = np.isfinite(DL) & (DL > h)
    logs = np.log(np.array([DH - h, dist[0]]) / (DL - h))  # the interval's width, the low end's distance
    mc = np.where(np.isfinite(DH) & low, logs[0] / (2.0 * z_table), np.where(low, logs[1] / z_table, 0.0))
    rnd = gamma * rnd_sd / dist[0]
    mck = gamma * mc
    sd = np.maximum(np.hypot(rnd, mck), 1e-3)
    good = np.isfinite(log_k) & np.isfinite(sd)
    # the entries' Monte Carlo errors are combined as independent (measured on svm-paper, the residuals of
    # log k about each slice's trend correlate 0.14 between neighbouring noise-ratio slices and 0.07 between
    # neighbouring contact times, needs >= 5 widths); their rounding errors are not: the grid rounds the
    # similar needs of neighbouring entries the same way (at needs under 5 widths neighbouring readings of
    # log k are identical), so the rounding term is the entries' weighted mean, not reduced by averaging
    all_good = np.count_nonzero(good) == good.size
    om = W / sd ** 2 if all_good else np.where(good, W / sd ** 2, 0.0)
    # per (contact, pair): bin c * n + p, each bin's entries summed in their order; the four sums in one count
    parts = np.array([om * log_k, om, om ** 2 * mck ** 2, om * rnd])
    if not all_good:
        parts = np.where(good, parts, 0.0)
    num, den, var, rnd_mean = np.bincount(np.add.outer((2 * n) * _FOUR, Cc * n + P).ravel(), parts.ravel(),
                                          minlength=8 * n).reshape(4, 2, n)
    lk, se = np.where(den > 0, [num / den, np.hypot(np.sqrt(var) / den, rnd_mean / den)], np.nan)
    return (lk, se) if extra is None else (lk, se, star[2 * k:])


def _k_line(lk, se, t_a, t_b, log_ab=None):
    """``log k`` at ``t_a`` and ``t_b`` (one held at the other's where it has no reading; two that fall pooled:
    k never falls with contact time, on svm-paper the slice medians rise at every step in every slice), the
    weights and the readings' disagreement where they fell (``log_ab``: ``log(t_b / t_a)``, if computed; the
    weights and the disagreement None where none fell: :func:`_k_var` reads them only where one did)."""
    have = np.isfinite(lk)  # [a / b, n]
    lab = np.where(have, lk, lk[::-1])
    rise = lab[1] - lab[0]
    falls = have[0] & have[1] & (rise * np.sign(np.log(t_b / t_a) if log_ab is None else log_ab) < 0)
    if not np.count_nonzero(falls):  # (none fell: nothing pooled)
        return lab[0], lab[1], have[0], have[1], falls, None, None, None
    # (la_, lb_ are finite or NaN: a reading is a weighted mean of finite log k)
    w = np.where(have, 1.0 / se ** 2, 0.0)
    held = np.where(have, lab, 0.0) * w
    pooled = (held[0] + held[1]) / (w[0] + w[1])
    disagree = np.where(falls, np.abs(rise), 0.0)
    la_, lb_ = np.where(falls, pooled, lab)
    return la_, lb_, have[0], have[1], falls, w[0], w[1], disagree


def _k_var(u, se, la_, lb_, have_a, have_b, falls, wa, wb, disagree, far):
    """Variance of ``log k`` at fraction ``u`` of the way from ``t_a`` to ``t_b`` (``far()``: the log distance
    to the one reading where only one exists, computed where one does)."""
    dk = np.abs(lb_ - la_)
    w = 1 - u
    both = have_a & have_b
    v = (w * se[0]) ** 2 + (u * se[1]) ** 2 + (u * w * dk / 2) ** 2
    if np.count_nonzero(both) < both.size:  # (one reading only somewhere)
        v = np.where(both, v, np.where(have_a, se[0], se[1]) ** 2 + (0.5 * far()) ** 2)
    if np.count_nonzero(falls):
        v = np.where(falls, 1.0 / (wa + wb) + (disagree / 2) ** 2, v)
    return v


def _slices(combos, n):
    """Shared scene weights as per-pair slice arrays (n, m), read-only."""
    live = [(idx[0], w) for idx, w in combos if w]
    out = (np.array([[i for i, _ in live]], dtype=np.int64).repeat(n, axis=0),
           np.array([[w for _, w in live]], dtype=np.float64).repeat(n, axis=0))
    for a in out:
        a.flags.writeable = False
    return out


@np.errstate(divide="ignore", invalid="ignore")  # (one context for the whole computation)
def noise_k_min_contact(op, combos, k_cross, lo, hi, ratio, *, zc: float,
                        max_contact_s: float = CLOSED_FORM_MAX_CONTACT_S, readings=None) -> dict[str, np.ndarray]:
    """min-contact from the SVM's *noise efficiency* against the exact ideal observer, for pairs of one scene.

    The SVM separates a pair when the ideal observer would at a larger noise: ``k(t)`` times the projection
    noise ``s(t) = (sigma/dT) / |g(t)|`` (:mod:`designkit.query.ideal_bound`). Every tabulated need gives
    one reading of ``k``: the noise at which the ideal observer needs exactly that separation (less the
    grid's rounding, w/2: :func:`~designkit.recognition.ideal.critical_noise`) over ``s(t)`` of its slice.
    ``k`` is a property of the classifier and the contact time (on svm-paper it is the same for every
    sigma/dT, direction and effusivity to about 1 %, docs/accuracy.md), unlike the ratio of the needs in
    effusivity, which changes with the pair's width because the signal ``w(e) = e / (e_s + e)`` is concave
    (that ratio, read at pairs narrower and wider than the asked one, put the answers late). ``k`` is read at
    the crossing's tabulated contact ``t_b`` (index ``k_cross``) and one before, ``t_a`` (after, where
    ``t_b`` is the first), at least a factor :data:`K_SLOPE_SPAN` away (:func:`k_baseline`), from the pair's
    own entries (upwards at ``lo``, downwards at ``hi``) in every scene slice the question interpolates
    between; ``log k`` is linear in ``log t`` through them. The answer is the first sample time where ``k(t) s(t)`` reaches the pair's own critical noise
    (:func:`~designkit.query.ideal_bound.noise_k_contact`).

    Standard error of ``log k`` at a contact: the entries' inverse-variance mean (their Monte Carlo errors
    nearly independent, measured on the table; their rounding errors alike, so that term is not reduced by
    averaging), each entry's in log k the local slope
    ``gamma = dlog s*/dlog need`` (a second critical noise, one width further) times its need's relative
    error: the grid's rounding (w/sqrt(12)) and the table's Monte Carlo interval
    (``delta_lo`` / ``delta_hi``, ``z`` standard errors each). Between the two contacts: ``(1-u)`` and ``u``
    weights, plus ``u (1-u)`` times half the change of ``log k`` across the cell (interpolation; the
    measured curvature of log k in log t on the table is below this). In log t it is that over
    ``beta_g - beta_k``, the local log-log slopes of ``|g|`` and ``k``.

    Parameters
    ----------
    op : the opened table (:func:`open_table`)
    combos : scene weights (``view.scene_weights``)
    k_cross : array_like of int
        Index of the first tabulated contact whose need suffices, per pair (>= 0).
    lo, hi, ratio : array_like
        Pairs [J s^-1/2 K^-1 m^-2] and the asked sigma/dT.
    zc : float
        z of the asked coverage.
    readings : ndarray, optional
        The pairs' entries read already: ``delta_up{,_lo,_hi}`` at ``lo`` and ``delta_down{,_lo,_hi}`` at
        ``hi`` in each weighted slice of ``combos`` at every contact, [direction, kind, slice, contact, pair]
        (:meth:`~designkit.query.table_arrays.TableView.readings`); None: read here.

    Returns
    -------
    dict of ndarray
        ``value``, ``low``, ``high`` [s], ``k_a``, ``k_b`` (NaN: no reading there), ``t_a``, ``t_b``,
        ``se_log`` (of the answer, log); ``value`` NaN where the route does not apply.
    """
    view, sensor = op.view, op.tab.sensor
    lo, hi, ratio, kb = columns(lo, hi, ratio, k_cross, dtypes=(np.float64,) * 3 + (np.int64,))
    n = lo.size
    ka = view.baselines()[kb]  # (k_baseline of every tabulated contact, kept with the table)
    slices, sw = view.memo(("slices", tuple(combos), n), lambda: _slices(combos, n)) if n <= 64 else _slices(combos, n)
    lk, se, s_pair = _k_readings(  # (the pair's own critical noise read with its entries')
        op, slices, sw, ka, kb, lo, hi, extra=(lo, hi), readings=readings)
    t_a, t_b = view.contacts[np.where(ka >= 0, ka, kb)], view.contacts[kb]
    log_ab = np.log(t_b / t_a)
    la_, lb_, have_a, have_b, falls, wa, wb, disagree = _k_line(lk, se, t_a, t_b, log_ab)
    # (NaN where neither contact has a reading: its log k is NaN, no count is decided good)
    value = noise_k_contact(sensor, ratio, s_pair, t_a, t_b, la_, lb_, max_contact_s)
    ok = (have_a | have_b) & np.isfinite(value)
    lv = np.log(value / t_a)
    u = lv / log_ab
    var_k = _k_var(u, se, la_, lb_, have_a, have_b, falls, wa, wb, disagree,
                   lambda: np.log(value / np.where(have_a, t_a, t_b)))  # (the log distance to the one reading)
    slope_k = np.where(have_a & have_b & (t_a != t_b), (lb_ - la_) / log_ab, 0.0)
    v_ok = np.where(ok, value, 1.0)  # (shape_norm takes finite contact times only)
    g = shape_norm(sensor, np.concatenate([v_ok * 1.05, v_ok / 1.05]))
    beta_g = np.log(g[:n] / g[n:]) / (2 * math.log(1.05))
    se_t = np.sqrt(var_k) / np.maximum(beta_g - slope_k, 0.05)
    ends = value * np.exp(np.array([[-zc], [zc]]) * se_t)
    k_at = np.exp(np.maximum(la_ + slope_k * lv, 0.0))
    out = np.where(ok, [value, ends[0], ends[1], k_at, se_t], np.nan)
    k_ab = np.where([have_a & ok, have_b & ok], np.exp(lk), np.nan)
    return {"value": out[0], "low": out[1], "high": out[2], "k_a": k_ab[0], "k_b": k_ab[1], "t_a": t_a, "t_b": t_b,
            "k": out[3], "se_log": out[4], "s_pair": s_pair}


@np.errstate(divide="ignore", invalid="ignore")  # (one context for the whole computation)
def noise_k_max_ratio(op, contact_s, r_table, r_ideal, lo, hi, *, zc: float) -> dict[str, np.ndarray]:
    """max-noise / min-delta-t from the SVM's noise efficiency (:func:`noise_k_min_contact`): the SVM separates
    the pair up to ``sigma/dT = r_ideal / k(contact)``, ``r_ideal`` the ideal observer's exact largest
    sigma/dT, ``k`` read at the two tabulated contacts around ``contact_s`` (log-linear in log t) in the two
    noise-ratio slices around ``r_table`` (the table's own crossing), elementwise. Standard error in log:
    that of ``log k`` there (as min-contact's), no slope to divide by.

    Returns
    -------
    dict of ndarray
        ``value``, ``low``, ``high`` (sigma/dT), ``k``, ``se_log``; NaN where it does not apply.
    """
    view = op.view
    contact, r_table, r_ideal, lo, hi = (np.atleast_1d(a) for a in np.broadcast_arrays(*(
        np.asarray(x, dtype=np.float64) for x in (contact_s, r_table, r_ideal, lo, hi))))
    C = view.contacts
    kb = np.clip(np.searchsorted(C, contact, side="left"), 0, C.size - 1)  # the first contact >= the asked one
    ka = np.where(C[kb] == contact, kb, np.maximum(kb - 1, 0))
    lr, lrt = np.log(view.t.axes["noise_ratio"]), np.log(r_table)
    i0 = np.clip(np.searchsorted(lr, lrt, side="right") - 1, 0, lr.size - 2)
    w1 = np.clip((lrt - lr[i0]) / (lr[i0 + 1] - lr[i0]), 0.0, 1.0)
    slices, sw = np.stack([i0, i0 + 1], axis=1), np.stack([1.0 - w1, w1], axis=1)
    lk, se = _k_readings(op, slices, sw, ka, kb, lo, hi)
    t_a, t_b = C[ka], C[kb]
    la_, lb_, have_a, have_b, falls, wa, wb, disagree = _k_line(lk, se, t_a, t_b)
    u = np.where(t_a != t_b, np.log(contact / t_a) / np.log(t_b / t_a), 1.0)
    log_k = np.maximum((1 - u) * la_ + u * lb_, 0.0)
    var_k = _k_var(u, se, la_, lb_, have_a, have_b, falls, wa, wb, disagree,
                   lambda: np.log(contact / np.where(have_a, t_a, t_b)))
    sd = np.sqrt(var_k)
    ok = (have_a | have_b) & np.isfinite(r_ideal) & np.isfinite(sd)
    value = r_ideal * np.exp(-log_k)
    return {"value": np.where(ok, value, np.nan), "low": np.where(ok, value * np.exp(-zc * sd), np.nan),
            "high": np.where(ok, value * np.exp(zc * sd), np.nan), "k": np.where(ok, np.exp(log_k), np.nan),
            "se_log": np.where(ok, sd, np.nan)}



def delta_entries(view, combos, ends, direction: str, e) -> tuple[np.ndarray, ...]:
    """The tabulated SVM delta(e) towards ``direction`` (``"up"`` / ``"down"``) and its Monte Carlo ends at
    effusivities ``e`` (interpolated between centres as :func:`designkit.tables.lookup.interp_e`), at the
    contact indices ``ends`` (two) in each weighted noise-ratio slice of ``combos``: the slices' sigma/dT (m,),
    their weights (m,), and the delta, its low and its high end, each (2, m, n) (NaN: none within the grid);
    what :func:`delta_efficiency_estimate` takes."""
    live = [(idx[0], w) for idx, w in combos if w]
    e = np.atleast_1d(np.asarray(e, dtype=np.float64))
    si = np.array([i for i, _ in live], dtype=np.int64)
    shape = (2, si.size, e.size)
    sl, kk, ee = (np.broadcast_to(a, shape).ravel() for a in (
        si[None, :, None], np.asarray(ends, dtype=np.int64)[:, None, None], e[None, None, :]))
    out = [interp_e_by(lambda c, a=view.t.arrays[f"delta_{direction}{suffix}"]: a[sl, kk, c], view.centres,
                       ee).reshape(shape) for suffix in ("", "_lo", "_hi")]
    return (view.t.axes["noise_ratio"][si], np.array([w for _, w in live], dtype=np.float64), *out)


def delta_efficiency_estimate(sensor, e, contact_s, ratio, direction, t_a, t_b, slice_ratios, slice_weights, svm,
                              svm_lo, svm_hi, *, width: float, threshold: float, e_max: float, z_table: float,
                              zc: float, mc_factor: float = 1.0) -> dict[str, np.ndarray]:
    """delta-e's estimate of one direction from the SVM's efficiency against the exact ideal observer.

    The SVM's efficiency is its need over the ideal observer's for the asked reference class and direction,
    ``eff = s / i``. At every tabulated entry around the question (the contact times ``t_a``, ``t_b`` and the
    noise-ratio slices ``slice_ratios``) the ideal need ``i`` is computed exactly
    (:func:`designkit.query.ideal_bound.exact_ideal_delta`; the table's own ideal needs are rounded up to its
    grid, and at small needs that rounding dominated the ratio) and the SVM's ``s`` is the middle of what its
    tabulated need ``S`` allows: the first grid distance whose F1 reaches Phi, so the crossing lies in
    ``(S - w, S]``, and never below the ideal observer's, ``[max(i, S - w), S]`` (SD its length / sqrt(12)).
    ``log eff`` is interpolated linearly in log t between the two contacts and with ``slice_weights`` between
    the slices, floored at 1 (no classifier beats the ideal observer), and applied to the ideal observer's
    delta(e) computed exactly at the asked contact and sigma/dT: no interpolation of the steep need itself.

    Standard error in log, each term measured on the table (docs/accuracy.md): the entries' Monte Carlo
    errors (the table's ``delta_lo`` / ``delta_hi``, ``z_table`` SEs each, times ``mc_factor``, the table's
    own calibration :func:`mc_calibration`), combined as independent (the table's entries are
    separate simulations); their rounding errors combined as alike (neighbouring needs round the same way),
    the weighted mean, not reduced by averaging; and the interpolation across the cell, ``u (1 - u)`` times
    half the change of ``log eff`` across it (as min-contact's noise efficiency). Where one contact's
    entries cannot be read (a need beyond the grid) the other's stand alone.

    Parameters
    ----------
    e : array_like, shape (n,)
        Reference class's lower edge [J s^-1/2 K^-1 m^-2].
    contact_s, ratio, direction : array_like, shape (n,) or scalar
        Contact time [s], sigma/dT [-], and +1 (towards higher effusivity) or -1.
    t_a, t_b : array_like
        The tabulated contact times [s] around ``contact_s`` (equal where it is one).
    slice_ratios, slice_weights : array_like, shape (m,) or (m, n)
        The noise-ratio slices the question interpolates between and their weights.
    svm, svm_lo, svm_hi : array_like, shape (2, m, n)
        The tabulated SVM delta and its Monte Carlo ends at ``e`` (interpolated in effusivity) at ``t_a``
        (row 0) and ``t_b`` (row 1) in each slice [J s^-1/2 K^-1 m^-2].
    width, threshold, e_max, z_table, zc : float
        Grid width, F1 threshold, upper end of the effusivity range, the table's z and the asked coverage's.
    mc_factor : float
        Calibration of the table's Monte Carlo errors (:func:`mc_calibration`).

    Returns
    -------
    dict of ndarray
        ``value``, ``low``, ``high``, ``ideal`` [J s^-1/2 K^-1 m^-2], ``efficiency``, ``se_log`` (NaN where
        it does not apply).

    Examples
    --------
    >>> from designkit.sensor import load_sensor
    >>> S = [[[8760.0]], [[5000.0]]]
    >>> r = delta_efficiency_estimate(load_sensor("paper"), 20000.0, 1.75, 0.005, +1, 1.5, 2.0, [0.005], [1.0],
    ...                               S, [[[8300.0]], [[4750.0]]], [[[9200.0]], [[5300.0]]], width=80.0,
    ...                               threshold=0.9, e_max=40000.0, z_table=2.0, zc=1.645)
    >>> float(r["ideal"][0]) < float(r["low"][0]) < float(r["value"][0]) < float(r["high"][0])
    True
    """
    S, L, H = (np.asarray(a, dtype=np.float64) for a in (svm, svm_lo, svm_hi))
    m, n = S.shape[1], S.shape[2]
    e, contact, ratio, direction, t_a, t_b = (np.broadcast_to(np.asarray(a, dtype=np.float64), (n,)) for a in (
        e, contact_s, ratio, direction, t_a, t_b))
    rs = np.broadcast_to(np.asarray(slice_ratios, dtype=np.float64).reshape(m, -1), (m, n))
    ws = np.broadcast_to(np.asarray(slice_weights, dtype=np.float64).reshape(m, -1), (m, n))
    h = 0.5 * width
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.where(t_a != t_b, np.log(contact / t_a) / np.log(t_b / t_a), 0.0)
    wc = np.stack([1.0 - u, u])  # (2, n): the contacts' weights
    needed = (wc[:, None, :] > 0) & (ws[None, :, :] > 0)
    live = needed & np.isfinite(S) & (S > 0)
    # the ideal observer's delta at every live entry and at the asked point: one (cached) computation
    shape = (2, m, n)
    cols = [np.concatenate([np.broadcast_to(a, shape)[live], b]) for a, b in (
        (e, e), (np.stack([t_a, t_b])[:, None, :], contact), (rs[None], ratio), (direction, direction))]
    ideal_all = exact_ideal_delta(sensor, *cols[:3], direction=cols[3], width=width, threshold=threshold,
                                  e_max=e_max)
    k = int(live.sum())
    i_entry = np.full(shape, np.nan)
    i_entry[live] = ideal_all[:k]
    ideal = ideal_all[k:]
    usable = live & np.isfinite(i_entry) & (i_entry > 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        lower = np.minimum(np.maximum(i_entry, S - width), S)
        mid = 0.5 * (lower + S)
        rnd = (S - lower) / math.sqrt(12.0) / mid
        le = np.log(mid / i_entry)
        mc = np.where(np.isfinite(H) & (L > h), np.log((H - h) / (L - h)) / (2.0 * z_table),
                      np.where(L > h, np.log((S - h) / (L - h)) / z_table, 0.0))
        mc = np.where(np.isfinite(mc), mc, 0.0)
        # a contact counts where all its weighted slices are usable; where only one does, it stands alone
        ok_c = (wc > 0) & np.all(usable | ~needed, axis=1)
        wcn = np.where(ok_c, wc, 0.0)
        wcn = wcn / wcn.sum(axis=0)
        wsn = ws / ws.sum(axis=0)
        W = np.where(usable, wcn[:, None, :] * wsn[None, :, :], 0.0)
        log_eff = np.sum(W * np.where(usable, le, 0.0), axis=(0, 1))
        var_mc = np.sum((W * mc) ** 2, axis=(0, 1))
        rounding = np.sum(W * np.where(usable, rnd, 0.0), axis=(0, 1))
        per_c = np.sum(wsn[None] * np.where(usable, le, 0.0), axis=1)  # log eff at each contact
        both = ok_c.all(axis=0)
        interp = np.where(both, u * (1.0 - u) * np.abs(per_c[1] - per_c[0]) / 2.0, 0.0)
        se = np.sqrt(mc_factor ** 2 * var_mc + rounding ** 2 + interp ** 2)
        eff = np.maximum(np.exp(log_eff), 1.0)  # no classifier beats the ideal observer
    ok = ok_c.any(axis=0) & np.isfinite(log_eff) & np.isfinite(se) & np.isfinite(ideal)
    with np.errstate(invalid="ignore"):
        value = np.where(ok, eff * ideal, np.nan)
        low = np.where(ok, np.maximum(value * np.exp(-zc * se), ideal), np.nan)
        high = np.where(ok, value * np.exp(zc * se), np.nan)
    return {"value": value, "low": low, "high": high, "ideal": np.where(ok, ideal, np.nan),
            "efficiency": np.where(ok, eff, np.nan), "se_log": np.where(ok, se, np.nan)}


