"""The optimal sequential test of two candidates: the bound on :mod:`designkit.recognition.sequential`.

Wald's thresholds (:class:`~designkit.recognition.sequential.SequentialTest`) are optimal when
every sample carries the same information; here the information per sample
``(A dw g_k / sigma)^2`` grows steeply with time. :func:`optimal_test` computes the Bayes-optimal
stopping rule for two candidates by backward induction (time-varying boundaries) and the bound on
the mean time to decision that no test reaching the same error rate beats (:func:`optimal_stopping`
on any information curve; :func:`run_boundaries` applies its rule to touches). On the paper's
guideline pair it is within 1-2 % of the SPRT at eps <= 0.01 (docs/decisions.md), so the core's
test keeps Wald's thresholds. A measurement of the core (``benchmarks/bench_sequential*.py``), not
part of it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import special

from designkit._validation import InputError, check_positive
from designkit.recognition.sequential import BatchResult, SequentialTest, log_marginals

__all__ = ["OptimalTest", "optimal_stopping", "optimal_test", "run_boundaries"]


@dataclass(frozen=True)
class OptimalTest:
    """The Bayes-optimal sequential test of two candidates at one error rate (:func:`optimal_test`).

    Attributes
    ----------
    error_rate : float
        The requested error rate (mean of the two classes' error rates, prior 1/2 each).
    bound_s : float
        Lower bound [s] on the mean time to decision (mean over the two classes) of *any* test,
        sequential or not, randomized or not, whose mean error rate is at most ``error_rate``:
        ``max over lambda of R(lambda) - lambda * error_rate`` (weak Lagrangian duality, ``R`` the
        Bayes risk ``E[tau] + lambda P(error)`` of the optimal stopping rule at sampling cost 1 s/s).
    expected_time_s : float
        Mean time to decision [s] of the deterministic optimal rule with the smallest cost of an error
        whose error rate is at most ``error_rate`` (equal to ``bound_s`` unless the error rate jumps
        with the cost, when a randomized mixture of two rules fills the gap).
    error : float
        That rule's mean error rate.
    cost_s : float
        Its cost of an error ``lambda`` [s].
    upper, lower : ndarray, shape (n,)
        Its boundaries on the log posterior odds ``l_1 - l_0`` after each sample ``k = 0 .. n - 1``:
        decide candidate 1 when ``l_1 - l_0 >= upper[k]``, candidate 0 when ``<= lower[k]``
        (``inf`` / ``-inf``: no decision at that sample; the last sample decides the likelier).
    sprt_time_s, sprt_error : float
        Mean time to decision and mean error rate of the :class:`SequentialTest`'s own constant
        thresholds, evaluated by the same recursion (a check against simulated touches).
    """

    error_rate: float
    bound_s: float
    expected_time_s: float
    error: float
    cost_s: float
    upper: np.ndarray
    lower: np.ndarray
    sprt_time_s: float
    sprt_error: float

    def to_dict(self) -> dict:
        return {"error_rate": self.error_rate, "bound_s": self.bound_s, "expected_time_s": self.expected_time_s,
                "error": self.error, "cost_s": self.cost_s, "sprt_time_s": self.sprt_time_s,
                "sprt_error": self.sprt_error}


def _hermite(nodes: int) -> tuple[np.ndarray, np.ndarray]:
    z, w = np.polynomial.hermite_e.hermegauss(int(nodes))
    return z, w / w.sum()


class _Stopping:
    """Backward induction for the two-class stopping problem on a uniform grid of the score ``x``.

    ``x = dw (v - w_mid) / s^2`` is the log-likelihood ratio of the two class centres (``dw`` apart,
    midpoint ``w_mid``); after ``n`` samples a point hypothesis at offset ``r`` (in units of ``dw``
    from ``w_mid``) has log-likelihood ``r x - r^2 I_n / 2`` (``I_n`` the information of the centres,
    :func:`optimal_stopping`), and the next sample adds ``N(r iota, iota)`` to ``x``.
    """

    def __init__(self, iota, offsets, log_prior, classes, step: float, half_width: float, nodes: int):
        self.iota = np.asarray(iota, dtype=np.float64)
        self.info = np.cumsum(self.iota)
        self.r = np.asarray(offsets, dtype=np.float64)
        self.lp = np.asarray(log_prior, dtype=np.float64)
        self.cls = np.asarray(classes, dtype=bool)
        self.dx = float(step)
        m = int(math.ceil(half_width / step))
        self.x = np.arange(-m, m + 1) * self.dx
        self.z, self.wz = _hermite(nodes)

    def log_weights(self, x, n):
        """Log posterior weight (unnormalized) of each point hypothesis, shape (points,) + x.shape."""
        x = np.asarray(x, dtype=np.float64)
        r = self.r.reshape((-1,) + (1,) * x.ndim)
        return self.lp.reshape(r.shape) + r * x - 0.5 * r * r * self.info[n]

    @staticmethod
    def _lse(a):
        """log-sum-exp over the first axis (scipy's costs more in overhead than the sum on these sizes)."""
        if a.shape[0] == 1:
            return a[0]
        mx = a.max(axis=0)
        return mx + np.log(np.exp(a - mx).sum(axis=0))

    def log_odds(self, x, n):
        """``log P(class 1 | x) - log P(class 0 | x)`` after samples 0 .. n (prior 1/2 per class)."""
        lw = self.log_weights(x, n)
        return self._lse(lw[self.cls]) - self._lse(lw[~self.cls])

    def _expect(self, tables, n1, post, out_err, band: slice):
        """E[f(x')] for f in ``tables`` (T, E), x' = x + the increment of sample n1, under the predictive,
        for the grid points ``x[band]``."""
        io = self.iota[n1]
        if io <= 0.0:
            return tables[:, band].copy()
        x0, dx, m = self.x[0], self.dx, self.x.size
        xs = self.x[band]
        acc = np.zeros((2, xs.size))
        sd = math.sqrt(io)
        for i, ri in enumerate(self.r):
            xx = xs[:, None] + (ri * io + sd * self.z)[None, :]
            f = (xx - x0) / dx
            j = np.floor(f).astype(np.int64)
            inside = (j >= 0) & (j < m - 1)
            jj = np.clip(j, 0, m - 2)
            fr = f - jj
            vals = tables[:, jj] * (1.0 - fr) + tables[:, jj + 1] * fr
            if not inside.all():
                # beyond the grid the rule stops at once: no more time, the stopping error there
                vals[0] = np.where(inside, vals[0], 0.0)
                vals[1][~inside] = out_err(xx[~inside], n1)
            acc += post[i, band] * (vals @ self.wz)
        return acc

    def stop_error(self, x, n):
        lo = self.log_odds(x, n)
        return special.expit(-np.abs(lo))

    def solve(self, dt: float, cost: float | None = None, threshold: float | None = None):
        """(E[tau], P(error), upper, lower) from x = 0 before the first sample.

        ``cost``: the optimal rule at that cost of an error [s]; ``threshold``: the rule that stops
        once ``|l_1 - l_0| >= threshold`` (the SPRT), evaluated.
        """
        n_s, x = self.iota.size, self.x
        tab = np.stack([np.zeros_like(x), self.stop_error(x, n_s - 1)])
        upper = np.full(n_s, -np.inf)
        lower = np.full(n_s, np.inf)
        for n in range(n_s - 2, -1, -1):
            lw = self.log_weights(x, n)
            post = np.exp(lw - self._lse(lw))
            lo = self._lse(lw[self.cls]) - self._lse(lw[~self.cls])
            serr = special.expit(-np.abs(lo))
            # only where continuing can pay (the optimal rule stops once cost * P(error) <= dt, the least a
            # further sample costs; the SPRT beyond its threshold) is the expectation computed
            maybe = cost * serr > dt if threshold is None else np.abs(lo) < threshold
            stop = np.ones(x.size, dtype=bool)
            new = np.stack([np.zeros_like(x), serr])
            if maybe.any():
                idx = np.flatnonzero(maybe)  # an interval: the log-odds increase with x
                band = slice(int(idx[0]), int(idx[-1]) + 1)
                cont = self._expect(tab, n + 1, post, self.stop_error, band)
                cont[0] += dt
                if threshold is None:
                    stop[band] = cost * serr[band] <= cont[0] + cost * cont[1]
                else:
                    stop[band] = False
                new[:, band] = np.where(stop[band], new[:, band], cont)
            tab = new
            up, dn = stop & (lo > 0), stop & (lo <= 0)
            upper[n] = lo[up].min() if up.any() else np.inf
            lower[n] = lo[dn].max() if dn.any() else -np.inf
        upper[-1], lower[-1] = 0.0, 0.0
        i0 = int(np.argmin(np.abs(x)))
        return float(tab[0, i0]), float(tab[1, i0]), upper, lower


def optimal_stopping(iota, offsets, log_prior, classes, sample_period_s: float, error_rate: float, *,
                     sprt_threshold: float | None = None, step: float = 0.02, nodes: int = 16,
                     iterations: int = 18) -> OptimalTest:
    """The Bayes-optimal sequential test of two classes of Gaussian shifts with time-varying information.

    The classes are mixtures of point hypotheses; after samples ``0 .. n`` the log-likelihood of the
    point at offset ``r`` is ``r x_n - r^2 I_n / 2``, where ``x_n`` is a Gaussian process with
    independent increments ``N(r iota_n, iota_n)`` under that point and ``I_n = sum iota``: the
    model of :class:`SequentialTest` (white noise, known initial conditions) with ``iota_n`` the
    information the sample adds about the class centres (``(A dw g_n / sigma)^2``) and ``r`` the
    point's amplitude offset from their midpoint in units of their distance ``dw``.

    For a cost ``lambda`` [s] of an error and 1 s per second of contact, the optimal stopping rule
    minimizes the Bayes risk ``R = E[tau] + lambda P(error)`` (prior 1/2 per class); it is found by
    backward induction from the last sample (Wald and Wolfowitz 1948; Chernoff 1972, ch. 9):
    ``V_n(x) = min(lambda P(error | stop), dt + E[V_{n+1}(x + dx) | x])``, on a grid of ``x``
    (``step`` wide, linear interpolation; expectations by ``nodes``-point Gauss-Hermite quadrature
    over the predictive). ``lambda`` is bisected (in log) until the rule's error rate reaches
    ``error_rate``. By weak duality, ``E[tau] >= R(lambda) - lambda error_rate`` for every ``lambda``
    and every test with mean error at most ``error_rate``: the largest such value is the bound.

    Parameters
    ----------
    iota : array_like, shape (n,)
        Information of each sample about the class centres (0 for the sample at contact).
    offsets : array_like, shape (p,)
        Point hypotheses' offsets ``r`` (class 0's centre at -1/2, class 1's at +1/2).
    log_prior : array_like, shape (p,)
        Log prior mass of each point within its class (each class's masses sum to 1).
    classes : array_like of bool, shape (p,)
        True for the points of class 1.
    sample_period_s : float
        Time between samples [s].
    error_rate : float
        Mean error rate to reach, in (0, 0.5).
    sprt_threshold : float, optional
        Also evaluate the rule ``|l_1 - l_0| >= sprt_threshold`` (Wald's SPRT).
    step : float
        Grid step of the score ``x`` (log-likelihood ratio units).
    nodes : int
        Gauss-Hermite nodes per expectation.
    iterations : int
        Bisections of ``log lambda`` (over ``[log dt, log(1e9 dt n)]``).

    Returns
    -------
    OptimalTest

    Examples
    --------
    Constant information: the optimal test is Wald's SPRT (Wald and Wolfowitz 1948), whose mean
    information at the decision is ``2 (1 - 2 eps) log((1 - eps) / eps)`` (9.01 at eps = 0.01)
    up to the overshoot of discrete steps:

    >>> o = optimal_stopping(np.full(400, 0.1), [-0.5, 0.5], [0.0, 0.0], [False, True], 1.0, 0.01,
    ...                      step=0.1, nodes=8, iterations=10)
    >>> 8.8 < 0.1 * o.bound_s < 9.3, abs(o.error - 0.01) < 1e-3
    (True, True)
    """
    iota = np.asarray(iota, dtype=np.float64)
    if iota.ndim != 1 or iota.size < 2 or not np.all(np.isfinite(iota)) or np.any(iota < 0):
        raise InputError("the information per sample must be a 1-D array of at least two finite numbers >= 0")
    eps = float(error_rate)
    if not 0.0 < eps < 0.5:
        raise InputError(f"error rate of the optimal test must lie in (0, 0.5), got {eps:g}")
    dt = check_positive("sample period [s]", sample_period_s)
    r = np.asarray(offsets, dtype=np.float64)
    # the score's range: the rule stops by |l_1 - l_0| ~ log(1/eps) + a few, and the increments of the
    # last samples reach a few sqrt(iota) beyond
    half = (abs(math.log(eps)) + 8.0) * max(1.0, 2.0 * float(np.abs(r).max())) + 6.0 * math.sqrt(iota.max())
    dp = _Stopping(iota, r, log_prior, classes, step, half, nodes)
    lo_c, hi_c = math.log(dt), math.log(1e9 * dt * iota.size)
    best = -math.inf
    kept = None
    for _ in range(int(iterations)):
        mid = 0.5 * (lo_c + hi_c)
        t, e, up, dn = dp.solve(dt, cost=math.exp(mid))
        best = max(best, t + math.exp(mid) * (e - eps))
        if e > eps:
            lo_c = mid
        else:
            hi_c, kept = mid, (t, e, up, dn, math.exp(mid))
    if kept is None:
        t, e, up, dn = dp.solve(dt, cost=math.exp(hi_c))
        kept = (t, e, up, dn, math.exp(hi_c))
        best = max(best, t + kept[4] * (e - eps))
    st, se = (math.nan, math.nan) if sprt_threshold is None else dp.solve(dt, threshold=sprt_threshold)[:2]
    t, e, up, dn, lam = kept
    return OptimalTest(eps, float(best), t, e, lam, up, dn, st, se)


def optimal_test(test: SequentialTest, error_rate: float | None = None, *, points: int = 3,
                 step: float = 0.02, nodes: int = 16, iterations: int = 18) -> OptimalTest:
    """The optimal sequential test for a two-candidate :class:`SequentialTest`'s scene: the bound.

    No test on the same samples (sequential, fixed or randomized, up to ``test.max_contact_s``)
    reaches the same mean error rate with a shorter mean time to decision than
    :attr:`OptimalTest.bound_s`. Each candidate's effusivity range enters as its prior pieces
    (:func:`~designkit.recognition.sequential.candidate_pieces`), each cut into ``points`` equal-width points in ``w`` carrying the
    piece's mass; the information of the samples comes from the model's response shape, the noise
    and the temperature difference (:func:`optimal_stopping` for the recursion). Also evaluates
    the test's own (Wald) thresholds by the same recursion.

    Parameters
    ----------
    test : SequentialTest
        Two candidates.
    error_rate : float, optional
        Mean error rate to reach (default: the mean of the candidates' requested rates).
    points : int
        Points per prior piece.
    step, nodes, iterations : optional
        Grid step of the score, Gauss-Hermite nodes, bisections of the cost (see :func:`optimal_stopping`).

    Examples
    --------
    >>> from designkit import SENSORS
    >>> t = SequentialTest([("20000", (20000, 20080)), ("35000", (35000, 35080))], SENSORS["paper"],
    ...                    noise_c=0.05, sensor_temp_c=35, ambient_temp_c=25, error_rate=0.05, max_contact_s=2)
    >>> o = optimal_test(t, points=1, step=0.05, nodes=8, iterations=10)
    >>> 0.85 < o.bound_s <= o.expected_time_s < o.sprt_time_s < t.plan.fixed_contact_s
    True
    """
    cands = test.plan.candidates
    if len(cands) != 2:
        raise InputError(f"the optimal test is computed for two candidates, got {len(cands)}")
    if not test.plan.separable:
        raise InputError(test.plan.reason)
    eps = float(np.mean([c.error_rate for c in cands])) if error_rate is None else float(error_rate)
    n_pts = int(points)
    if n_pts < 1:
        raise InputError(f"points per piece must be at least 1, got {points}")
    w_pts, lp, cls = [], [], []
    centres = []
    for ci, c in enumerate(cands):
        edges = np.asarray(c.w_edges)
        mass = np.exp(np.asarray(c.log_mass))
        centres.append(float(np.sum(mass * 0.5 * (edges[:-1] + edges[1:]))))
        for m in range(mass.size):
            q = (np.arange(n_pts) + 0.5) / n_pts
            w_pts.extend(edges[m] + q * (edges[m + 1] - edges[m]))
            lp.extend([math.log(mass[m] / n_pts)] * n_pts)
            cls.extend([ci == 1] * n_pts)
    w_mid, dw = 0.5 * (centres[0] + centres[1]), centres[1] - centres[0]
    offsets = (np.asarray(w_pts) - w_mid) / dw
    iota = (test.amplitude_c * dw * test.shape_table / test.noise_c) ** 2
    thr = float(test.plan.thresholds[0, 1]) if cands[0].error_rate == cands[1].error_rate else None
    return optimal_stopping(iota, offsets, lp, cls, 1.0 / test.sensor.sample_rate_hz, eps, sprt_threshold=thr,
                            step=step, nodes=nodes, iterations=iterations)


def run_boundaries(test: SequentialTest, temps_c: np.ndarray, upper, lower) -> BatchResult:
    """A two-candidate rule with time-varying boundaries (the optimal test's) on many touches.

    Candidate 1 is decided at the first sample ``k`` with ``l_1 - l_0 >= upper[k]``, candidate 0 at
    the first with ``l_1 - l_0 <= lower[k]``, the statistic as in
    :func:`~designkit.recognition.sequential.run_batch`; at the last boundary sample the likelier is
    decided. The touches are cut to ``len(upper)`` samples.

    Examples
    --------
    >>> from designkit import SENSORS
    >>> from designkit.simulation import simulate_trials
    >>> from designkit.scene import Scene
    >>> from designkit.recognition.sequential import run_batch
    >>> test = SequentialTest([("20000", (20000, 20080)), ("35000", (35000, 35080))], SENSORS["paper"],
    ...                       noise_c=0.05, sensor_temp_c=35.0, ambient_temp_c=25.0, error_rate=0.01)
    >>> y = simulate_trials(35040, SENSORS["paper"], Scene(contact_s=5), 20, seed=1).temperature_c
    >>> thr = test.plan.thresholds[1, 0]  # constant boundaries: the SPRT, as run_batch runs it
    >>> r, b = run_boundaries(test, y, np.full(1001, thr), np.full(1001, -thr)), run_batch(test, y)
    >>> bool(np.all(r.decided == b.decided) and np.all(r.time_s == b.time_s))
    True
    """
    if len(test.plan.candidates) != 2:
        raise InputError(f"boundaries on l_1 - l_0 need two candidates, got {len(test.plan.candidates)}")
    upper = np.asarray(upper, dtype=np.float64)
    lower = np.asarray(lower, dtype=np.float64)
    y = np.asarray(temps_c, dtype=np.float64)
    if y.ndim != 2 or upper.shape != lower.shape or upper.ndim != 1:
        raise InputError(f"touches must be (touch, sample) and the boundaries two 1-D arrays of one length; got "
                         f"{y.shape}, {upper.shape}, {lower.shape}")
    v, s, first = test.projection(y[:, :upper.size])
    m = v.shape[1] + first
    s = np.broadcast_to(s, v.shape)
    ll = log_marginals(v, s, test.plan.candidates)
    d = ll[..., 1] - ll[..., 0]
    up, dn = d >= upper[first:m], d <= lower[first:m]
    stop = up | dn
    hit = stop.any(axis=1)
    at = np.where(hit, np.argmax(stop, axis=1), d.shape[1] - 1)
    rows = np.arange(d.shape[0])
    decided = np.where(hit, np.where(up[rows, at], 1, 0), -1)
    best = np.where(hit, decided, (d[:, -1] > 0).astype(int))
    return BatchResult(decided, (at + first) / test.sensor.sample_rate_hz, best)
