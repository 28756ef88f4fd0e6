"""designkit's table estimator in pure Python: what an export answers, as the library answers it.

This module imports only the standard library, so that designkit's Python
export carries it verbatim (after :mod:`designkit.tables.lookup`), and the
JSON / CSV / npz exports are read with it (:func:`designkit.export.reading.estimator_of`).
The C header carries the same steps in C (``designkit/export/templates/designkit_lookup.h.in``);
``tests/test_export_conformance.py`` asks the library, the header, the module and
the data exports the same random questions.

What it computes (:mod:`designkit.query.table`'s efficiency route, step by step)
-------------------------------------------------------------------------------
* ``min_contact``: the grid's crossing of the need ``max(delta_up(lo),
  delta_down(hi))`` gives the tabulated contact ``t_b`` where the pair first
  separates; the SVM's *noise efficiency* ``k`` is read there and at ``t_a``
  (a factor 1.14 away) from the table's entries of the pair, each against the
  ideal observer's critical noise of its entry; ``log k`` is linear in
  ``log t``, and the answer is the first sample time where
  ``k(t) (sigma/dT) / |g(t)|`` reaches the pair's own critical noise
  (:func:`designkit.query.table.noise_k_min_contact`), with its 90 % interval.
  Where no reading exists, the log-log crossing
  (:func:`designkit.query.table.contact_estimate`) or the grid cell.
  Without a closed-form ideal observer (a calibrated rig's table): both
  directions' needs averaged (:meth:`Estimator._both_estimate`), no ideal floor.
* Contact times count from a calibrated rig's detected onset (``onset_offset_s``)
  as ``designkit ... --sensor FILE`` counts them; the table's axis: model time.
* ``delta_e``: each direction's SVM efficiency (tabulated need over the ideal
  observer's, computed at every entry around the question) applied to the ideal
  observer's delta(e) at the asked contact and sigma/dT
  (:func:`designkit.query.table.delta_efficiency_estimate`); the smaller side.
* ``distinguishable``: the contact against ``min_contact`` for the pair (sure
  outside its interval, as the library's verdict).

The ideal observer's critical noise ``s*(a, b)`` (the projection noise at which
its F1 of the classes ``[a, a+w)``, ``[b, b+w)`` is the threshold) is computed
at export time by :func:`designkit.query.ideal_bound.critical_noise` on a grid
in ``(log(a + A0), log(b - a))`` and read here by bicubic (Catmull-Rom)
interpolation of ``log(s* / (w(b) - w(a)))``, ``w(e) = e / (e_s + e)``
(within 2e-4 of the library's, which is itself exact to about 1e-4). The
response shape's cumulative energy ``sum g(k/fs)^2`` is carried per sample.
"""

import bisect
import math

# <package-import> (a generated module carries designkit/tables/lookup.py above this text instead)
from designkit.tables.lookup import (axis_weights, contact_input, crossing, effusivity_input, interp_e, pair_input,
                                     scene_inputs)
# </package-import>

__all__ = ["ESTIMATOR", "ESTIMATOR_VERSION", "Estimator"]

#: Name and version of the estimator every export records (bump the version when an answer changes).
ESTIMATOR = "designkit.query.table route (noise_k_min_contact, delta_efficiency_estimate; varied_contact_estimate)"
ESTIMATOR_VERSION = 2  # 2: tables without a closed-form ideal observer, contact from a rig's detected onset

_K_SLOPE_SPAN = 1.14       # designkit.query.table.K_SLOPE_SPAN
_SAMPLE_TOLERANCE = 1e-9   # designkit.sensor._SAMPLE_TOLERANCE
_SQRT12 = math.sqrt(12.0)


def _isnan(x):
    return x != x


def _finite(x):
    return not (x != x) and x not in (math.inf, -math.inf)


class Estimator:
    """The library's answers from one table's arrays (see the module docstring).

    Parameters
    ----------
    lookup : designkit.tables.lookup.Lookup
        The table's svm arrays (delta_up / delta_down) with its axes; its scene axis must be ``noise_ratio``.
    up_lo, down_lo, up_hi, down_hi : sequence of float
        The ends of the table's Monte Carlo interval of delta, flat like ``lookup``'s arrays.
    p : dict
        The constants: ``e_s`` [J s^-1/2 K^-1 m^-2], ``fs`` [Hz], ``width``, ``threshold``, ``z_table``,
        ``zc`` (the interval's z), ``mc_factor``, ``e_lo`` / ``e_hi`` (the source table's effusivity range),
        ``max_contact_s``, ``cum`` (cumulative g^2 per sample), and the critical-noise grid ``s_a0``,
        ``s_u0``, ``s_du``, ``s_nu``, ``s_v0``, ``s_dv``, ``s_nv``, ``s_f`` (flat, [u][v]); ``efficiency``
        (False: no closed-form ideal observer, none of the above ideal-observer constants is read),
        ``onset_offset_s`` (the model's time 0 from a rig's detected onset [s]; 0 or absent: none).
    """

    def __init__(self, lookup, up_lo, down_lo, up_hi, down_hi, p):
        if [ax[0] for ax in lookup.scene] != ["noise_ratio"]:
            raise ValueError("the estimator needs a table with a noise_ratio axis (fixed initial conditions)")
        self.t = lookup
        self.arr = {("up", ""): lookup.delta_up, ("down", ""): lookup.delta_down, ("up", "_lo"): up_lo,
                    ("down", "_lo"): down_lo, ("up", "_hi"): up_hi, ("down", "_hi"): down_hi}
        self.ratios = lookup.scene[0][2]
        self.p = p
        self.cum = p["cum"]
        self.fs = float(p["fs"])
        self.w = float(p["width"])
        self.h = 0.5 * self.w
        self.n_max = int(math.floor(float(p["max_contact_s"]) * self.fs + _SAMPLE_TOLERANCE))
        self.contacts = list(lookup.contact_s)
        # False: the table's ideal observer has no closed form: both directions' needs averaged, no efficiency
        # route and no ideal floor under the intervals (designkit's answer from a sensor's own table)
        self.efficiency = bool(p.get("efficiency", True))
        self.onset = float(p.get("onset_offset_s") or 0.0)  # contact from the rig's detected onset = model's + it
        # per sample n: log(n / fs) and log |g| (n = 0: no signal)
        self._log_t = [-math.inf] + [math.log(n / self.fs) for n in range(1, len(self.cum))]
        self._log_norm = [0.5 * math.log(c) if c > 0 else -math.inf for c in self.cum]
        # the critical-noise grid's constants as attributes (read on every critical noise)
        self._es, self._e_hi = float(p["e_s"]), float(p["e_hi"])
        nu, nv, f = int(p["s_nu"]), int(p["s_nv"]), p["s_f"]
        self._grid = (float(p["s_a0"]), float(p["s_dmin"]), float(p["s_u0"]), float(p["s_du"]), nu,
                      float(p["s_v0"]), float(p["s_dv"]), nv)
        # each grid cell's 4 x 4 neighbourhood of nodes in one tuple ([i - 1][j - 1]: nodes i-1..i+2, j-1..j+2)
        rows = [list(f[i * nv:(i + 1) * nv]) for i in range(nu)]
        self._cells = [[tuple(rows[i - 1][j - 1:j + 3] + rows[i][j - 1:j + 3] + rows[i + 1][j - 1:j + 3]
                              + rows[i + 2][j - 1:j + 3]) for j in range(1, nv - 2)] for i in range(1, nu - 2)]

    # ---------------------------------------------------------------- the ideal observer
    def shape_norm(self, t):
        """|g| over the samples of a touch of ``t`` [s]."""
        n = int(math.floor(t * self.fs + _SAMPLE_TOLERANCE))
        n = min(max(n, 0), len(self.cum) - 1)
        return math.sqrt(self.cum[n])

    def sstar(self, a, b):
        """The ideal observer's critical projection noise of classes [a, a+w), [b, b+w) (0: not separable)."""
        g = self._log_shape(a, b)
        if g is None:
            return 0.0
        e_s = self._es
        return math.exp(g) * (1.0 / (1.0 + e_s / b) - (1.0 / (1.0 + e_s / a) if a > 0 else 0.0))

    def _log_shape(self, a, b):
        """``log(s*(a, b) / (w(b) - w(a)))`` read bicubically (Catmull-Rom) off the grid; None: not separable."""
        a0, dmin, u0, du, nu, v0, dv, nv = self._grid
        d = b - a
        if not (d >= dmin) or a < 0:
            return None
        u = (math.log(a + a0) - u0) / du
        v = (math.log(d) - v0) / dv
        i = int(u)
        i = 1 if i < 1 else (nu - 3 if i > nu - 3 else i)
        j = int(v)
        j = 1 if j < 1 else (nv - 3 if j > nv - 3 else j)
        p0, p1, p2, p3, q0, q1, q2, q3, r0, r1, r2, r3, s0, s1, s2, s3 = self._cells[i - 1][j - 1]
        # Catmull-Rom in both directions: its four basis weights at the fractions
        t = v - j
        t2 = t * t
        t3 = t2 * t
        w0, w1, w2, w3 = (0.5 * (-t + 2.0 * t2 - t3), 0.5 * (2.0 - 5.0 * t2 + 3.0 * t3),
                          0.5 * (t + 4.0 * t2 - 3.0 * t3), 0.5 * (t3 - t2))
        t = u - i
        t2 = t * t
        t3 = t2 * t
        return (0.5 * (-t + 2.0 * t2 - t3) * (w0 * p0 + w1 * p1 + w2 * p2 + w3 * p3)
                + 0.5 * (2.0 - 5.0 * t2 + 3.0 * t3) * (w0 * q0 + w1 * q1 + w2 * q2 + w3 * q3)
                + 0.5 * (t + 4.0 * t2 - 3.0 * t3) * (w0 * r0 + w1 * r1 + w2 * r2 + w3 * r3)
                + 0.5 * (t3 - t2) * (w0 * s0 + w1 * s1 + w2 * s2 + w3 * s3))

    def ideal_delta(self, e, t, ratio, direction, guess=None):
        """Ideal observer's delta(e) [J s^-1/2 K^-1 m^-2] towards ``direction`` (+1 / -1) at contact ``t`` [s]
        (designkit.query.ideal_bound.exact_ideal_delta: bisection on the distance to 0.5); NaN: none.

        ``guess`` (a distance near the answer, optional) only makes it faster: see :meth:`_delta_root`."""
        norm = self.shape_norm(t)
        return self._delta_root(e, ratio / norm if norm > 0 else math.inf, direction, guess)[0]

    def _delta_root(self, e, s, direction, guess=None, slope=math.nan):
        """``(delta, slope)``: the library's bisection on the distance ``d`` to 0.5 for ``s <= s*(e, e +- d)``,
        at projection noise ``s``; ``slope`` is d log s* / d log d near the answer (NaN: unknown).

        The bisection's last step is a cell ``((k - 1) h, k h]`` of the grid ``h = limit / 2^n`` (n the
        bisection's steps) that holds the crossing; where s* grows with ``d`` (the ideal observer's does), the
        answer is that cell's upper end. The cell is found by probing grid nodes: each probe's end nearest the
        estimate of a secant in ``(log d, log s*)`` that starts at ``guess`` (a distance near the answer;
        ``slope`` where known), until a node that separates lies next to one that does not: 2 to 4 probes
        instead of the bisection's 17, and the same answer (the bisection's steps are then replayed on the two
        nodes, so that it is the same float: its nodes may lie an ulp from ``k h``)."""
        w = self.w
        limit = (self._e_hi - e - w) if direction > 0 else (e - w)
        if not (limit >= w and s < math.inf):  # s infinite (no signal yet): nothing separates
            return math.nan, math.nan
        es, log_shape, log, exp, inf = self._es, self._log_shape, math.log, math.exp, math.inf
        ls = log(s) if s > 0.0 else None
        m, n = math.frexp(2.0 * limit)  # the bisection's steps: limit / 2^n <= 0.5
        n = max(n if m > 0.5 else n - 1, 0)
        h, top = math.ldexp(limit, -n), 1 << n
        # grid nodes: lo does not separate (closer than the grid's least distance never does), hi separates
        # (top + 1: none yet)
        lo, hi = (min(max(math.ceil(self._grid[1] / h) - 1, 0), top) if s > 0.0 else 0), top + 1
        if lo * h >= self._grid[1]:
            lo -= 1
        r = guess if ls is not None and guess and guess < limit else 0.5 * limit
        x0 = f0 = None
        probes = 0
        while hi - lo > 1:
            k = math.ceil(r / h) if r < limit else top
            k = lo + 1 if k <= lo else (hi - 1 if k >= hi else k)  # r's cell: ((k - 1) h, k h]
            if probes >= 7 and hi - lo > 2:  # the secant stalls: halve the bracket
                k = (lo + min(hi, top)) // 2
            elif k - 1 > lo and (k >= hi or r - (k - 1) * h < k * h - r):
                k -= 1  # its end nearer the estimate
            d = k * h
            q = e + direction * d
            a, b = (e, q) if q > e else (q, e)
            g = log_shape(a, b)
            probes += 1
            if g is None:
                ok, f = s <= 0.0, -inf
            else:
                dw = 1.0 / (1.0 + es / b) - (1.0 / (1.0 + es / a) if a > 0 else 0.0)
                ok, f = s <= exp(g) * dw, (g + log(dw) - ls if ls is not None and dw > 0.0 else math.nan)
            if ok:
                hi = k
            else:
                lo = k
            if not -inf < f < inf:
                r = 0.5 * (lo + min(hi, top)) * h
                continue
            x = log(d)
            if x0 is not None and x != x0 and f != f0 and -inf < f0 < inf:
                slope = (f - f0) / (x - x0)
            r = exp(x - f / (slope if -inf < slope < inf and slope > 0.0 else 1.0))
            x0, f0 = x, f
        if hi > top:
            return math.nan, slope
        lo_d, hi_d = lo * h, hi * h
        a, b = 0.0, limit  # the bisection's steps, to return its very float
        while b - a > 0.5:
            mid = 0.5 * (a + b)
            if mid >= hi_d or (mid > lo_d and hi_d - mid < mid - lo_d):
                b = mid
            else:
                a = mid
        return b, slope

    def k_contact(self, ratio, s_star, t_a, t_b, ka, kb):
        """First sample time [s] where k(t) ratio / |g(t)| <= s_star, log k linear in log t (floored at 0)
        (designkit.query.ideal_bound.noise_k_contact); NaN: none up to max_contact_s."""
        fs, cum = self.fs, self.cum
        if not s_star > 0:
            return math.nan
        slope = (kb - ka) / math.log(t_b / t_a) if t_a != t_b else 0.0
        lta, lr, ls = math.log(t_a), math.log(ratio), math.log(s_star)
        log_t, log_norm = self._log_t, self._log_norm

        def ok(n):
            if cum[n] <= 0:
                return False
            lk = ka + slope * (log_t[n] - lta)
            return (lk if lk > 0.0 else 0.0) + lr - log_norm[n] <= ls

        n_max = max(self.n_max, 1)
        if not slope <= 0.5:  # not monotone in n: every sample
            for n in range(1, n_max + 1):
                if ok(n):
                    return n / fs
            return math.nan
        if not ok(n_max):
            return math.nan
        a, b = 0, n_max
        while b - a > 1:
            mid = (a + b) // 2
            if ok(mid):
                b = mid
            else:
                a = mid
        return b / fs

    # ---------------------------------------------------------------- table readings
    def _ew(self, e):
        """Where ``e`` lies among the centres: ``(j, w)`` as :func:`interp_e` reads it (w None: centre j alone)."""
        c = self.t.e_ref
        n = len(c)
        if e <= c[0]:
            return 0, None
        if e >= c[n - 1]:
            return n - 1, None
        j = bisect.bisect_right(c, e) - 1
        w = (e - c[j]) / (c[j + 1] - c[j])
        return j, (None if w == 0.0 else w)

    def _val(self, arr, start, ew):
        """:func:`interp_e` of the row at ``start`` with a precomputed :meth:`_ew`."""
        j, w = ew
        a = arr[start + j]
        if w is None:
            return a
        b = arr[start + j + 1]
        if a != a or b != b:
            return math.nan
        return a + w * (b - a)

    def _k_readings(self, slices, ka, kb, lo, hi):
        """log k and its standard error at contacts ka (0) and kb (1) (designkit.query.table._k_readings_computed)."""
        p, w, h = self.p, self.w, self.h
        z = p["z_table"]
        rnd_sd = w / _SQRT12
        nc = len(self.contacts)
        lk, se = [math.nan, math.nan], [math.nan, math.nan]
        ews = {1: self._ew(lo), -1: self._ew(hi)}
        tt = self.t
        for c, j in ((0, ka), (1, kb)):
            if not 0 <= j < nc:
                continue
            t = self.contacts[j]
            norm = self.shape_norm(t)
            num = den = var = rnd_mean = 0.0
            for si, ws in slices:
                if not ws > 0:
                    continue
                for sign, e, name in ((1, lo, "up"), (-1, hi, "down")):
                    start, ew = (si * tt._nc + j) * tt._ne, ews[sign]
                    d = self._val(self.arr[(name, "")], start, ew)
                    if not (_finite(d) and d > w):
                        continue
                    if sign < 0 and not e - (d - h) > 0:
                        continue
                    dl = self._val(self.arr[(name, "_lo")], start, ew)
                    dh = self._val(self.arr[(name, "_hi")], start, ew)
                    s_t = self.ratios[si] / norm
                    if sign > 0:
                        a1, b1, a2, b2 = e, e + (d - h), e, e + (d - h + w)
                    else:
                        a1, b1, a2, b2 = e - (d - h), e, max(e - (d - h + w), 0.0), e
                    s1, s2 = self.sstar(a1, b1), self.sstar(a2, b2)
                    try:
                        log_k = math.log(s1 / s_t)
                        gamma = math.log(s2 / s1) / math.log((d - h + w) / (d - h))
                    except (ValueError, ZeroDivisionError):
                        continue
                    if _finite(dh) and _finite(dl) and dl > h:
                        mc = math.log((dh - h) / (dl - h)) / (2.0 * z)
                    elif _finite(dl) and dl > h:
                        mc = math.log((d - h) / (dl - h)) / z
                    else:
                        mc = 0.0
                    rnd = abs(gamma) * rnd_sd / (d - h)
                    mck = abs(gamma) * mc
                    sd = max(math.hypot(rnd, mck), 1e-3)
                    if not (_finite(log_k) and _finite(sd)):
                        continue
                    om = ws / sd ** 2
                    num += om * log_k
                    den += om
                    var += om * om * mck * mck
                    rnd_mean += om * rnd
            if den > 0:
                lk[c] = num / den
                se[c] = math.hypot(math.sqrt(var) / den, rnd_mean / den)
        return lk, se

    def _baseline(self, kb):
        """designkit.query.table.k_baseline."""
        c = self.contacts
        if kb > 0:
            back = bisect.bisect_right(c, c[kb] / _K_SLOPE_SPAN * (1 + 1e-12)) - 1
            return max(back, 0)
        ahead = bisect.bisect_left(c, c[kb] * _K_SLOPE_SPAN * (1 - 1e-12))
        return ahead if ahead < len(c) else -1

    def _cross(self, kind, combos, lo, hi):
        """The grid's crossing of the need of ``kind`` ("", "_lo", "_hi"), read lazily up to it
        (:func:`crossing`): ``(crossing or None, index or None, the needs read)``."""
        up, down = self.arr[("up", kind)], self.arr[("down", kind)]
        ew_lo, ew_hi = self._ew(lo), self._ew(hi)
        read = []

        def needs():
            for k in range(len(self.contacts)):
                a = self._delta_at(up, combos, k, ew_lo)
                b = self._delta_at(down, combos, k, ew_hi)
                read.append(math.nan if a != a or b != b else max(a, b))
                yield read[-1]
        x, kb = crossing(self.contacts, needs(), hi - lo)
        return x, kb, read

    def _delta_at(self, arr, combos, k, ew):
        t = self.t
        total = 0.0
        for row, wt in combos:
            if wt == 0:
                continue
            v = self._val(arr, (row * t._nc + k) * t._ne, ew)
            if v != v:
                return math.nan
            total += wt * v
        return total

    # ---------------------------------------------------------------- min-contact
    def min_contact_interval(self, e1, e2, noise_c, delta_t_c):
        """``(value, low, high)`` [s] of designkit.query.min_contact (None for none / an open end).

        Raises OutsideTable (a ValueError) outside the grid, ValueError for invalid input."""
        noise, dt = scene_inputs(noise_c, delta_t_c)
        lo, hi = pair_input(e1, e2)
        t = self.t
        combos = t.scene_weights(noise, dt)
        t._check_e(lo, hi)
        # counted from the rig's detected onset, at least 0 (designkit.rig.for_rig)
        return tuple(None if v is None else max(v + self.onset, 0.0)
                     for v in self._min_contact(lo, hi, combos, noise / abs(dt)))

    def _model_contact(self, contact):
        """An asked contact [s] (from the rig's detected onset) in the table's time (designkit.rig.resolve_scene)."""
        c = contact - self.onset
        if not c > 0:
            raise ValueError(f"contact {contact:g} s after the rig's detected onset ends before the model's first "
                             f"heat flow ({self.onset:+.3g} s from the onset): give a longer contact")
        return c

    def _min_contact(self, lo, hi, combos, ratio):
        """min-contact in the table's time: the first of designkit.query.estimates.CONTACT_ESTIMATORS that answers."""
        C = self.contacts
        if not self.efficiency and (both := self._both_estimate(lo, hi, combos)) is not None:
            return both
        gap = hi - lo
        value, kb, needs = self._cross("", combos, lo, hi)
        if value is None:
            return None, None, None
        # the ideal observer's (NaN: none), and the SVM's efficiency against it
        ideal = self.k_contact(ratio, self.sstar(lo, hi), 1.0, 1.0, 0.0, 0.0) if self.efficiency else math.nan
        if self.efficiency and (est := self._efficiency_estimate(lo, hi, combos, ratio, kb, ideal)) is not None:
            return est
        # no efficiency reading: the log-log crossing between the two tabulated needs, or the grid cell
        prev = needs[kb - 1] if kb > 0 else math.nan
        if kb > 0 and not _isnan(prev):
            mc_lo = self._cross("_lo", combos, lo, hi)[0]
            mc_hi = self._cross("_hi", combos, lo, hi)[0]
            return self._contact_estimate(C[kb - 1], C[kb], prev, needs[kb], gap, value, mc_lo, mc_hi, ideal)
        start = C[kb - 1] if kb > 0 else 0.0
        return value, (max(start, ideal) if _finite(ideal) else start), value

    def _both_estimate(self, lo, hi, combos):
        """designkit.query.estimates.varied_contact_estimate, fixed conditions: per row :meth:`_rounded_crossing`
        and its Monte Carlo ends' (z sqrt 2: two readings averaged), log t across rows; None where a row has none."""
        zt, zc = self.p["z_table"] * math.sqrt(2.0), self.p["zc"]
        ews, rows = (self._ew(lo), self._ew(hi)), []
        for row, wt in ((row, wt) for row, wt in combos if wt != 0):
            v, interp, rnd = self._rounded_crossing("", row, lo, hi, ews)
            if _isnan(v):
                return None
            ends = (self._rounded_crossing(k, row, lo, hi, ews)[0] for k in ("_lo", "_hi"))
            rows.append((wt, math.log(v), *map(math.log, _stated_log(v, *ends, math.hypot(interp, rnd), zt, zc))))
        log_v, log_lo, log_hi = (sum(r[0] * r[i] for r in rows) for i in (1, 2, 3))
        interp = 0.25 * sum(wt * abs(lv - log_v) for wt, lv, _, _ in rows)
        low = math.exp(log_v - math.hypot(log_v - log_lo, zc * interp))
        high = math.exp(log_v + math.hypot(log_hi - log_v, zc * interp))
        return math.exp(log_v), (None if _isnan(low) else low), (None if _isnan(high) else high)

    def _rounded_crossing(self, kind, row, lo, hi, ews):
        """designkit.query.estimates.rounded_crossing of row ``row``'s need of ``kind`` ("", "_lo", "_hi") with both
        directions averaged (pair_need_both): ``(value, interp, rounding)``, NaN at the first contact or none."""
        w, t, C = self.w, self.t, self.contacts
        up, down = self.arr[("up", kind)], self.arr[("down", kind)]
        gap, nan = hi - lo, math.nan
        c0 = c1 = nan
        for k in range(len(C)):
            start = (row * t._nc + k) * t._ne
            a, b = self._val(up, start, ews[0]), self._val(down, start, ews[1])
            c0, c1 = c1, nan if _isnan(a) and _isnan(b) else math.sqrt(
                (self.p["e_hi"] - lo + w if _isnan(a) else a) * (hi - self.p["e_lo"] + w if _isnan(b) else b)) - 0.5 * w
            if not _isnan(c1) and c1 <= gap:
                break
        else:
            return nan, nan, nan
        return (nan, nan, nan) if k == 0 else _loglog_cell(C[k - 1], C[k], c0, c1, gap, w)

    def _efficiency_estimate(self, lo, hi, combos, ratio, kb, ideal):
        """designkit.query.estimates.efficiency_estimate: (value, low, high), or None where it reads nothing."""
        C, zc = self.contacts, self.p["zc"]
        ka = self._baseline(kb)
        lk, se = self._k_readings([(row, wt) for row, wt in combos if wt], ka, kb, lo, hi)
        t_a, t_b = C[ka if ka >= 0 else kb], C[kb]
        have_a, have_b = not _isnan(lk[0]), not _isnan(lk[1])
        if have_a or have_b:
            la = lk[0] if have_a else lk[1]
            lb = lk[1] if have_b else lk[0]
            wa = 1.0 / se[0] ** 2 if have_a else 0.0
            wb = 1.0 / se[1] ** 2 if have_b else 0.0
            falls = have_a and have_b and (lb - la) * math.copysign(1.0, math.log(t_b / t_a)) < 0 \
                and math.log(t_b / t_a) != 0
            disagree = 0.0
            if falls:
                pooled = (la * wa + lb * wb) / (wa + wb)
                disagree = abs(lb - la)
                la = lb = pooled
            value_k = self.k_contact(ratio, self.sstar(lo, hi), t_a, t_b, la, lb)
            if _finite(value_k):
                u = math.log(value_k / t_a) / math.log(t_b / t_a) if t_a != t_b else math.nan
                far = math.log(value_k / (t_a if have_a else t_b))
                if falls:
                    var_k = 1.0 / (wa + wb) + (disagree / 2) ** 2
                elif have_a and have_b:
                    dk = abs(lb - la)
                    var_k = ((1 - u) * se[0]) ** 2 + (u * se[1]) ** 2 + (u * (1 - u) * dk / 2) ** 2
                else:
                    var_k = (se[0] if have_a else se[1]) ** 2 + (0.5 * far) ** 2
                slope_k = (lb - la) / math.log(t_b / t_a) if have_a and have_b and t_a != t_b else 0.0
                beta_g = math.log(self.shape_norm(value_k * 1.05) / self.shape_norm(value_k / 1.05)) / (
                    2 * math.log(1.05))
                se_t = math.sqrt(var_k) / max(beta_g - slope_k, 0.05)
                if _finite(se_t):
                    low, high = value_k * math.exp(-zc * se_t), value_k * math.exp(zc * se_t)
                    if _finite(ideal):
                        low = min(max(low, ideal), value_k)
                    return value_k, low, high
        return None

    def _contact_estimate(self, x0, x1, n0, n1, gap, raw, mc_lo, mc_hi, ideal):
        """designkit.query.table.contact_estimate for an SVM table (one element)."""
        w, p = self.w, self.p
        lx0, lx1, lg = math.log(x0), math.log(x1), math.log(gap)
        raw_ll = _cross2(lx0, lx1, _log(n0), _log(n1), lg)
        raw_interp = 0.0 if _isnan(raw_ll) else abs(math.log(raw) - raw_ll)
        value, interp, rounding = _loglog_cell(x0, x1, n0 - 0.5 * w, n1 - 0.5 * w, gap, w)
        if _isnan(interp) or not x0 < value <= x1:  # (NaN: not crossed in the cell)
            value, interp, rounding = raw, raw_interp, 0.0
        shift = math.log(value) - math.log(raw)
        ends = [math.nan if m is None else math.exp(math.log(m) + shift) for m in (mc_lo, mc_hi)]
        low, high = _stated_log(value, ends[0], ends[1], math.hypot(interp, rounding), p["z_table"], p["zc"])
        if not _isnan(low) and _finite(ideal):
            low = min(max(low, ideal), value)
        return value, (None if _isnan(low) else low), (None if _isnan(high) else high)

    def min_contact_s(self, e1, e2, noise_c, delta_t_c):
        """Shortest contact time [s] that separates e1 from e2 (designkit min-contact's value); None: none
        within the table's contact times."""
        return self.min_contact_interval(e1, e2, noise_c, delta_t_c)[0]

    # ---------------------------------------------------------------- distinguishable
    def distinguishable_verdict(self, e1, e2, noise_c, delta_t_c, contact_s):
        """``(yes, sure)``: whether ``contact_s`` [s] reaches min-contact's answer for the pair, and whether
        it lies outside min-contact's interval (the library's "confident"; inside it, the library may decide
        by max-noise or delta-e instead)."""
        contact = self._model_contact(contact_input(contact_s))
        noise, dt = scene_inputs(noise_c, delta_t_c)
        lo, hi = pair_input(e1, e2)
        t = self.t
        combos = t.scene_weights(noise, dt)
        t.contact_weights(contact)
        t._check_e(lo, hi)
        value, low, high = self._min_contact(lo, hi, combos, noise / abs(dt))
        if value is None:
            return False, False
        yes = contact >= value
        sure = low is not None and not (low <= contact <= (high if high is not None else math.inf))
        return yes, sure

    def distinguishable(self, e1, e2, noise_c, delta_t_c, contact_s):
        """Whether ``contact_s`` [s] separates e1 from e2 (designkit distinguishable's value outside
        min-contact's interval)."""
        return self.distinguishable_verdict(e1, e2, noise_c, delta_t_c, contact_s)[0]

    # ---------------------------------------------------------------- delta-e
    def delta_e_sides(self, e, noise_c, delta_t_c, contact_s):
        """``{"lower": (value, low, high), "upper": (...)}`` [J s^-1/2 K^-1 m^-2] of designkit delta-e (None:
        none within the grid that way / an open end)."""
        x = effusivity_input("e", e)
        contact = self._model_contact(contact_input(contact_s))
        noise, dt = scene_inputs(noise_c, delta_t_c)
        t = self.t
        combos = t.scene_weights(noise, dt)
        cw = t.contact_weights(contact)
        t._check_e(x)
        ratio = noise / abs(dt)
        ends = (cw[0][0], cw[-1][0])
        slices = [(row, wt) for row, wt in combos if wt]
        ew = self._ew(x)
        out = {}
        for direction, side, sign in (("down", "lower", -1), ("up", "upper", 1)):
            val = self._at_contacts(direction, "", combos, cw, ew)
            eff = self._delta_efficiency(x, contact, ratio, sign, ends, slices, direction, ew) \
                if self.efficiency else None
            if eff is not None and val is None:
                d = eff[0]
                inside = x + d <= self.p["e_hi"] if sign > 0 else x - d > self.p["e_lo"]
                if not inside:
                    eff = None
            if eff is not None:
                out[side] = eff
            elif val is not None:
                out[side] = self._delta_estimate(direction, combos, cw, contact, x, val, ratio, sign, ew)
            else:
                out[side] = (None, None, None)
        return out

    def _at_contacts(self, direction, suffix, combos, cw, ew):
        total = 0.0
        for k, wk in cw:
            if wk == 0:
                continue
            y = self._delta_at(self.arr[(direction, suffix)], combos, k, ew)
            if _isnan(y):
                return None
            total += wk * y
        return total

    def _delta_efficiency(self, x, contact, ratio, sign, ends, slices, direction, ew):
        """designkit.query.table.delta_efficiency_estimate for one direction: (value, low, high) or None."""
        p, w, h, C, inf = self.p, self.w, self.h, self.contacts, math.inf
        z = p["z_table"]
        t_a, t_b = C[ends[0]], C[ends[1]]
        u = math.log(contact / t_a) / math.log(t_b / t_a) if t_a != t_b else 0.0
        wc = (1.0 - u, u)
        wsum = sum(ws for _, ws in slices)
        S_, L_, H_ = self.arr[(direction, "")], self.arr[(direction, "_lo")], self.arr[(direction, "_hi")]
        nc, ne, val = self.t._nc, self.t._ne, self._val
        ent = []  # (c, slice, (log efficiency, its Monte Carlo sd, rounding) or None), in reading order
        ok_c = [wc[0] > 0, wc[1] > 0]
        solved = []  # (log s, log delta, slope) of the ideal observer's answers so far: the next one's guess
        for c in (0, 1):
            if not wc[c] > 0:
                continue
            k = ends[c]
            norm = self.shape_norm(C[k])
            for s_i, (row, ws) in enumerate(slices):
                if not ws > 0:
                    continue
                start = (row * nc + k) * ne
                S = val(S_, start, ew)
                if not 0 < S < inf:
                    ent.append((c, s_i, None))
                    ok_c[c] = False
                    continue
                i_e = self._ideal_of(x, self.ratios[row] / norm if norm > 0 else inf, sign, solved, S)
                if not 0 < i_e < inf:
                    ent.append((c, s_i, None))
                    ok_c[c] = False
                    continue
                L = val(L_, start, ew)
                H = val(H_, start, ew)
                lower = min(max(i_e, S - w), S)
                mid = 0.5 * (lower + S)
                rnd = (S - lower) / _SQRT12 / mid
                le = math.log(mid / i_e)
                if -inf < H < inf and L > h:
                    mc = math.log((H - h) / (L - h)) / (2.0 * z)
                elif L > h:
                    mc = math.log((S - h) / (L - h)) / z
                else:
                    mc = 0.0
                ent.append((c, s_i, (le, mc if -inf < mc < inf else 0.0, rnd)))
        if not (ok_c[0] or ok_c[1]):
            return None
        norm = self.shape_norm(contact)
        ideal = self._ideal_of(x, ratio / norm if norm > 0 else inf, sign, solved, None)
        if not -inf < ideal < inf:
            return None
        wcn = [wc[c] if ok_c[c] else 0.0 for c in (0, 1)]
        tot = wcn[0] + wcn[1]
        wcn = [v / tot for v in wcn]
        log_eff = var_mc = rounding = 0.0
        per_c = [0.0, 0.0]
        for c, s_i, v in ent:
            if v is None:
                continue
            ws = slices[s_i][1] / wsum
            W = wcn[c] * ws
            log_eff += W * v[0]
            var_mc += (W * v[1]) ** 2
            rounding += W * v[2]
            per_c[c] += ws * v[0]
        interp = u * (1.0 - u) * abs(per_c[1] - per_c[0]) / 2.0 if ok_c[0] and ok_c[1] else 0.0
        se = math.sqrt(p["mc_factor"] ** 2 * var_mc + rounding ** 2 + interp ** 2)
        if not (-inf < log_eff < inf and -inf < se < inf):
            return None
        value = max(math.exp(log_eff), 1.0) * ideal
        return value, max(value * math.exp(-p["zc"] * se), ideal), value * math.exp(p["zc"] * se)

    def _ideal_of(self, x, s, sign, solved, default):
        """The ideal observer's delta at projection noise ``s`` (:meth:`_delta_root`), guessed from ``solved``
        (the answers for the same effusivity and direction so far, which it extends) or ``default``."""
        d, slope = self._delta_root(x, s, sign, *_guess(solved, s, default))
        if 0.0 < d < math.inf and 0.0 < s < math.inf:
            solved.append((math.log(s), math.log(d), slope))
        return d

    def _delta_estimate(self, direction, combos, cw, contact, x, val, ratio, sign, ew):
        """designkit.query.table.delta_estimate (no efficiency reading): the grid's value, its interval."""
        p, t = self.p, self.t
        lo_end = self._at_contacts(direction, "_lo", combos, cw, ew)
        hi_end = self._at_contacts(direction, "_hi", combos, cw, ew)
        gcw = axis_weights(self.contacts, contact, True, [math.log(c) for c in self.contacts])
        geo = 0.0
        for k, wk in gcw:
            if wk == 0:
                continue
            for row, wi in combos:
                y = interp_e(self.arr[(direction, "")], t.e_ref, x, (row * t._nc + k) * t._ne) if wi else 1.0
                if _isnan(y) or y <= 0:
                    geo = None
                    break
                geo += wk * wi * math.log(y)
            if geo is None:
                break
        geometric = math.nan if geo is None else math.exp(geo)
        interp = 0.0 if _isnan(geometric) else abs(math.log(val) - math.log(geometric))
        rounding = (self.w / _SQRT12) / val
        low, high = _stated_log(val, math.nan if lo_end is None else lo_end, math.nan if hi_end is None else hi_end,
                                math.hypot(interp, rounding), p["z_table"], p["zc"])
        floor = self.ideal_delta(x, contact, ratio, sign) if self.efficiency else math.nan
        if not _isnan(low) and _finite(floor):
            low = min(max(low, floor), val)
        return val, (None if _isnan(low) else low), (None if _isnan(high) else high)

    def delta_e_interval(self, e, noise_c, delta_t_c, contact_s):
        """``(value, low, high)`` of designkit delta-e: the smaller direction and its interval (None: none)."""
        sides = self.delta_e_sides(e, noise_c, delta_t_c, contact_s)
        best = None
        for side in ("lower", "upper"):
            v = sides[side]
            if v[0] is not None and (best is None or v[0] < best[0]):
                best = v
        return best if best is not None else (None, None, None)

    def delta_e(self, e, noise_c, delta_t_c, contact_s):
        """Smallest distinguishable effusivity difference from ``e`` [J s^-1/2 K^-1 m^-2] (designkit delta-e's
        value); None: none within the grid in either direction."""
        return self.delta_e_interval(e, noise_c, delta_t_c, contact_s)[0]


def _guess(solved, s, default):
    """``(distance, slope)`` near the ideal observer's answer at projection noise ``s`` from its answers at other
    noises for the same effusivity and direction (``solved``: (log s, log delta, slope)): log delta is smooth
    in log s, read linearly between (or beyond) the two nearest; ``default`` where none is known."""
    if not solved or not 0.0 < s < math.inf:
        return default, math.nan
    ls = math.log(s)
    a, da = None, math.inf
    for p in solved:  # the nearest (the first of equals)
        d = abs(p[0] - ls)
        if d < da:
            a, da = p, d
    b, db = None, math.inf
    for p in solved:  # the nearest at another noise
        d = abs(p[0] - ls)
        if d < db and abs(p[0] - a[0]) > 1e-9:
            b, db = p, d
    if b is not None:
        return math.exp(a[1] + (ls - a[0]) * (b[1] - a[1]) / (b[0] - a[0])), a[2]
    gamma = a[2] if _finite(a[2]) and a[2] > 0.1 else 1.0
    return math.exp(a[1] + (ls - a[0]) / gamma), a[2]


def _log(x):
    return math.log(x) if x > 0 else (math.nan if _isnan(x) or x < 0 else -math.inf)


def _cross2(x0, x1, n0, n1, gap):
    """designkit.query.table.cross2 for one element (NaN: none)."""
    if not _isnan(n0) and n0 <= gap:
        return x0
    if not _isnan(n1) and n1 <= gap:
        if _isnan(n0):
            return x1
        w = (n0 - gap) / (n0 - n1) if n0 != n1 else 1.0
        return x0 + w * (x1 - x0)
    return math.nan


def _loglog_cell(x0, x1, c0, c1, gap, w):
    """The rounding-corrected needs ``c0 > gap >= c1`` at contacts ``x0 < x1`` crossed log-log (designkit.query.
    estimates.rounded_crossing's cell): ``(value, interp, rounding)``; NaN where a need is not positive."""
    if not (c0 > 0 and c1 > 0):
        return math.nan, math.nan, math.nan
    lx0, lx1, l0, l1 = math.log(x0), math.log(x1), math.log(c0), math.log(c1)
    loglog = _cross2(lx0, lx1, l0, l1, math.log(gap))
    slope = abs((lx1 - lx0) / (l1 - l0)) if l1 != l0 else 0.0
    return math.exp(loglog), abs(loglog - math.log(_cross2(x0, x1, c0, c1, gap))), slope * (w / _SQRT12) / gap


def _stated_log(value, lo_end, hi_end, interp, z_table, zc):
    """designkit.query.table.stated_log for one element."""
    v = math.log(value)
    out = []
    for end, sign in ((lo_end, -1.0), (hi_end, 1.0)):
        if _isnan(end) or end <= 0:
            out.append(math.nan)
            continue
        mc = abs(math.log(end) - v) / z_table
        out.append(math.exp(v + sign * zc * math.hypot(mc, interp)))
    return out[0], out[1]
