"""Live decisions during a touch: a multi-hypothesis sequential probability ratio test.

A robot feeds the samples of one touch as they arrive; after each sample the
test says "keep touching", names a material, or says that no contact time up to
the longest allowed one will separate the candidates at the requested error
rates. The derivation, the evidence on simulated touches and the bound on any
test are in docs/decisions.md; in short:

- **Statistic** (Gaussian white noise on the raw samples, shared-shape model
  ``y_k = Ts0 + A w(e) g_k + sigma z_k``): the log-likelihood of an amplitude
  ``w`` is ``-(w - v)^2 / (2 s^2)`` with ``v = S_rg / (A S_gg)`` and
  ``s = sigma / (|A| sqrt(S_gg))``, from two running sums
  ``S_rg = sum (y_k - Ts0) g_k`` and ``S_gg = sum g_k^2`` (the ideal observer's
  projection and its noise, :mod:`designkit.recognition.ideal`).
- **A class is a mixture, not a GLR**: the likelihood of a class (effusivity
  uniform in ``[a, b)``) is the integral over its range, so Wald's bounds hold.
  The prior of ``w`` is cut into pieces geometric in ``e_s + e`` (density
  within 10 % in a piece, each uniform in ``w`` with its exact mass), which
  makes the mixture a sum of normal-CDF differences, evaluated in log space
  (:func:`scipy.special.log_ndtr`); a piece narrower than 1e-3 ``s`` is a point.
- **Thresholds** (Wald 1945; Armitage 1950): class ``i`` is decided once
  ``l_i - l_j >= log((k - 1) (1 - eps_i) / eps_j)`` for every other ``j``.
- **Hopeless pairs**: no test that stops by ``T`` beats the best fixed test at
  ``T``, a threshold on ``v`` (:func:`min_fixed_contact_s`); where a pair cannot
  reach the rates by the longest contact, :attr:`SequentialTest.plan` says so
  before the first sample and every update answers ``"no decision possible"``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, special

from .._validation import InputError, check_positive
from ..models import get_model
from ..objects import ObjectClass
from ..sensor import Sensor, last_sample_index
from .ideal import class_survival, log_ndtr_diff

__all__ = [
    "KEEP_TOUCHING",
    "LOG_SQRT_2PI",
    "NO_DECISION",
    "NOT_SEPARABLE",
    "Candidate",
    "Decision",
    "SequentialTest",
    "BatchResult",
    "DecisionPlan",
    "CENTRAL",
    "FAR_PIECES",
    "candidate_pieces",
    "log_marginals",
    "min_fixed_contact_s",
    "run_batch",
]

KEEP_TOUCHING = "keep touching"
NO_DECISION = "no decision by the longest contact"
NOT_SEPARABLE = "no decision possible"

#: Largest ratio of the prior density of w within one piece (10 %).
PIECE_DENSITY_RATIO = 1.1
#: Most pieces per candidate (a range spanning e_s + e over a factor 1.1^32 / 2 ~ 4.5).
MAX_PIECES = 32
#: A piece narrower than this many projection noises is treated as a point.
POINT_PIECE = 1e-3
#: log(sqrt(2 pi)), the normal density's constant (shared with the C export).
LOG_SQRT_2PI = 0.5 * math.log(2.0 * math.pi)
_SQRT2 = math.sqrt(2.0)
_LOG2 = math.log(2.0)


@dataclass(frozen=True)
class Candidate:
    """One hypothesis of the test: a class of objects and its prior on the amplitude ``w``.

    Attributes
    ----------
    name : str
        What a decision calls it (a material name or an effusivity).
    e_range : (float, float)
        Effusivity range [J s^-1/2 K^-1 m^-2].
    w_edges : tuple of float
        Piece edges in ``w = e / (e_s + e)``, increasing (two equal edges: a point).
    log_mass : tuple of float
        Log prior mass of each piece (sums to 1).
    error_rate : float
        Requested probability of a wrong decision on a touch of this class.
    """

    name: str
    e_range: tuple[float, float]
    w_edges: tuple[float, ...]
    log_mass: tuple[float, ...]
    error_rate: float

    def to_dict(self) -> dict:
        return {"name": self.name, "effusivity_range": list(self.e_range), "pieces": len(self.log_mass),
                "error_rate": self.error_rate}


@dataclass(frozen=True)
class DecisionPlan:
    """What the test will do, fixed before the first sample.

    Attributes
    ----------
    candidates : tuple of Candidate
    thresholds : ndarray, shape (k, k)
        ``A_ij``: decide ``i`` once ``l_i - l_j >= A_ij`` for every ``j != i``.
    max_contact_s : float
        Longest contact [s]: no decision by then gives :data:`NO_DECISION`.
    separable : bool
        Whether the best fixed test at ``max_contact_s`` reaches the requested
        error rates for every pair (else no decision is possible).
    fixed_contact_s : float or None
        Shortest fixed contact [s] at which the ideal observer reaches the
        requested error rates for every pair (None when not by ``max_contact_s``).
    limiting_pair : (str, str) or None
        The pair that needs the longest fixed contact.
    reason : str
        One line for people.
    """

    candidates: tuple[Candidate, ...]
    thresholds: np.ndarray
    max_contact_s: float
    separable: bool
    fixed_contact_s: float | None
    limiting_pair: tuple[str, str] | None
    reason: str

    def to_dict(self) -> dict:
        return {"candidates": [c.to_dict() for c in self.candidates],
                "thresholds": self.thresholds.tolist(), "max_contact_s": self.max_contact_s,
                "separable": self.separable, "fixed_contact_s": self.fixed_contact_s,
                "limiting_pair": None if self.limiting_pair is None else list(self.limiting_pair),
                "reason": self.reason}


@dataclass(frozen=True)
class Decision:
    """The test's answer after one sample.

    Attributes
    ----------
    state : str
        :data:`KEEP_TOUCHING`, ``"decided"``, :data:`NO_DECISION` (the longest
        contact passed) or :data:`NOT_SEPARABLE`.
    material : str or None
        The decided candidate (``"decided"``), or the most likely one when the
        longest contact passed; None otherwise.
    time_s : float
        Time after contact of the sample [s].
    n_samples : int
        Samples used so far.
    log_likelihoods : tuple of float
        ``l_j`` of each candidate (up to a common constant).
    """

    state: str
    material: str | None
    time_s: float
    n_samples: int
    log_likelihoods: tuple[float, ...] = field(default=())

    @property
    def final(self) -> bool:
        """Whether the touch can end (anything but "keep touching")."""
        return self.state != KEEP_TOUCHING

    @property
    def label(self) -> str:
        """What to show: the material when decided, else the state."""
        return self.material if self.state == "decided" else self.state

    def to_dict(self) -> dict:
        return {"state": self.state, "material": self.material, "time_s": self.time_s,
                "n_samples": self.n_samples, "log_likelihoods": list(self.log_likelihoods)}


# ----------------------------------------------------------------- the pieces
def candidate_pieces(e_low: float, e_high: float, e_sensor: float) -> tuple[np.ndarray, np.ndarray]:
    """Piece edges in ``w`` and log masses of the uniform-in-``e`` prior on ``[e_low, e_high)``.

    Pieces are geometric in ``e_s + e`` so that the density of ``w`` varies by at
    most :data:`PIECE_DENSITY_RATIO` within each (at most :data:`MAX_PIECES`).

    Examples
    --------
    >>> edges, log_mass = candidate_pieces(331.0, 506.46, 1353.0)
    >>> len(log_mass), round(float(np.exp(log_mass).sum()), 12)
    (3, 1.0)
    """
    lo, hi, es = float(e_low), float(e_high), float(e_sensor)
    if hi <= lo:
        w = float(lo / (es + lo))
        return np.array([w, w]), np.array([0.0])
    ratio = (es + hi) / (es + lo)
    n = int(min(MAX_PIECES, max(1, math.ceil(math.log(ratio) / (0.5 * math.log(PIECE_DENSITY_RATIO)) - 1e-9))))
    e_edges = (es + lo) * ratio ** (np.arange(n + 1) / n) - es
    e_edges[0], e_edges[-1] = lo, hi
    w_edges = e_edges / (es + e_edges)
    return w_edges, np.log(np.diff(e_edges) / (hi - lo))


def log_marginals(v, s, candidates) -> np.ndarray:
    """Log marginal density ``l_j = log p(v | candidate j)`` of the projection, vectorized.

    Parameters
    ----------
    v : array_like
        Running projection ``S_rg / (A S_gg)`` (any shape).
    s : array_like
        Its noise ``sigma / (|A| sqrt(S_gg))``, > 0 and finite (same shape).
    candidates : sequence of Candidate

    Returns
    -------
    ndarray, shape ``v.shape + (k,)``
        Up to a constant common to all candidates.

    Examples
    --------
    >>> c = [Candidate("a", (1, 1), (0.2, 0.2), (0.0,), 0.05), Candidate("b", (2, 2), (0.3, 0.3), (0.0,), 0.05)]
    >>> l = log_marginals(0.21, 0.05, c)
    >>> round(float(l[0] - l[1]), 6)  # ((0.3-0.21)^2 - (0.21-0.2)^2) / (2 * 0.05^2)
    1.6
    """
    v = np.asarray(v, dtype=np.float64)
    s = np.asarray(s, dtype=np.float64)
    out = np.empty(v.shape + (len(candidates),))
    for j, c in enumerate(candidates):
        edges = np.asarray(c.w_edges)
        terms = []
        for m, lm in enumerate(c.log_mass):
            w0, w1 = edges[m], edges[m + 1]
            width = w1 - w0
            point = -0.5 * ((v - 0.5 * (w0 + w1)) / s) ** 2 - np.log(s) - LOG_SQRT_2PI
            if width > 0:
                with np.errstate(divide="ignore", invalid="ignore"):
                    spread = log_ndtr_diff((w0 - v) / s, (w1 - v) / s) - math.log(width)
                term = np.where(width < POINT_PIECE * s, point, spread)
            else:
                term = point
            terms.append(lm + term)
        out[..., j] = terms[0] if len(terms) == 1 else special.logsumexp(np.stack(terms), axis=0)
    return out


def _log_ndtr_1(x: float) -> float:
    """log Phi(x) for one number, the formula of the C export (erfc, log1p above 0; asymptotic series below -30).

    Agrees with :func:`scipy.special.log_ndtr` to a few ulp (tested); per sample it is 30x
    faster than numpy on a scalar, which is what a robot loop at 200 Hz or more needs.
    """
    if x > 0.0:
        return math.log1p(-0.5 * math.erfc(x / _SQRT2))
    if x > -30.0:
        return math.log(0.5 * math.erfc(-x / _SQRT2))
    x2 = x * x
    r = 1.0 / x2
    series = r * (-1.0 + r * (3.0 + r * (-15.0 + r * (105.0 - r * 945.0))))
    return -0.5 * x2 - math.log(-x) - LOG_SQRT_2PI + math.log1p(series)


#: Pieces farther than this many projection noises beyond the nearest one are skipped: their share
#: of the mixture is below exp(-0.5 * 12^2 + 7) = exp(-65) of the nearest's (masses and widths of
#: pieces differ by less than e^7), under 2^-60 each: nothing in double precision.
FAR_PIECES = 12.0
#: Pieces with both ends within this many projection noises of ``v`` take the CDF difference directly,
#: sharing each edge's erfc with the neighbouring piece (half the special functions): the CDF is
#: then above 2.9e-7 and the difference above 1e-3 x phi(5) = 1.5e-9 (a piece is at least 1e-3 s
#: wide, :data:`POINT_PIECE`), so its relative rounding error stays below 1e-7.
CENTRAL = 5.0


def _near_pieces(v: float, s: float, edges) -> float:
    """Distance from ``v`` in ``w`` beyond which a piece is skipped: the nearest piece's + FAR_PIECES s."""
    d = math.inf
    for m in range(len(edges) - 1):
        dm = max(edges[m] - v, v - edges[m + 1], 0.0)
        if dm < d:
            d = dm
    return d + FAR_PIECES * s


def _log_marginals_1(v: float, s: float, candidates) -> list[float]:
    """:func:`log_marginals` for one (v, s), in the C export's order of operations.

    Pieces more than :data:`FAR_PIECES` projection noises beyond the nearest piece are skipped
    (the C export skips the same ones), which makes a wide material cost a few pieces per sample
    once the evidence is sharp. Central pieces (both ends within :data:`CENTRAL` noises) are summed
    in linear space, density times probability, and enter the log-sum-exp as one term: one special
    function per piece instead of three (the C update's cost per sample for wide materials).
    """
    out = []
    for c in candidates:
        terms = []
        edges = c.w_edges
        near = _near_pieces(v, s, edges)
        cached_k, cached_phi = -1, 0.0  # Phi at the last edge used: shared by neighbouring pieces
        central = 0.0  # the central pieces' sum, in linear space (no log and exp per piece)
        for m, lm in enumerate(c.log_mass):
            w0, w1 = edges[m], edges[m + 1]
            if w0 - v > near or v - w1 > near:
                continue  # exp(term - max) < exp(-65): adds nothing to the sum in double precision
            width = w1 - w0
            if width < POINT_PIECE * s:
                z = (v - 0.5 * (w0 + w1)) / s
                term = -0.5 * (z * z) - math.log(s) - LOG_SQRT_2PI
                terms.append(lm + term)
                continue
            hi, lo = (w1 - v) / s, (w0 - v) / s
            if -CENTRAL < lo and hi < CENTRAL:
                # both ends central: the CDF difference directly (relative error < 1e-7, see CENTRAL)
                p_lo = cached_phi if cached_k == m else 0.5 * math.erfc(-lo / _SQRT2)
                p_hi = 0.5 * math.erfc(-hi / _SQRT2)
                cached_k, cached_phi = m + 1, p_hi
                central += math.exp(lm - math.log(width)) * (p_hi - p_lo)  # the piece's density x probability
                continue
            else:
                a, b = (-hi, -lo) if lo > 0.0 else (lo, hi)
                lb = _log_ndtr_1(b)
                d = _log_ndtr_1(a) - lb
                if d == -math.inf:
                    term = lb - math.log(width)
                else:
                    term = lb + (math.log(-math.expm1(d)) if d > -_LOG2 else math.log1p(-math.exp(d))) \
                        - math.log(width)
            terms.append(lm + term)
        if central > 0.0:
            terms.append(math.log(central))
        if len(terms) == 1:
            out.append(terms[0])
        else:
            mx = max(terms)
            out.append(mx if mx == -math.inf else mx + math.log(sum(math.exp(t - mx) for t in terms)))
    return out


# ----------------------------------------------------------------- fixed-time reference
def _shape(sensor: Sensor, model, n: int) -> np.ndarray:
    return np.asarray(model.shape(np.arange(n, dtype=np.float64) / sensor.sample_rate_hz, sensor), dtype=np.float64)


def _survival(t, e_range, e_sensor: float, s: float) -> float:
    """``P(v > t)`` for a class (a single effusivity where the range is one value)."""
    lo, hi = e_range
    if hi <= lo:
        return float(special.ndtr((lo / (e_sensor + lo) - t) / s))
    return float(class_survival(t, lo, hi, e_sensor, s))


def _fixed_ok(range_low, range_high, error_low: float, error_high: float, e_sensor: float, s: float) -> bool:
    """Whether the best fixed test with projection noise ``s`` reaches both error rates.

    The best test of two ordered effusivity classes on all samples up to a contact is a threshold on
    the projection ``v`` (Neyman-Pearson with a monotone likelihood ratio,
    :mod:`designkit.recognition.ideal`); the threshold with ``P(v > t | low) = error_low`` is taken
    and its error on the high class compared with ``error_high``.
    """
    if not np.isfinite(s):
        return False
    # threshold where the low class's false-positive rate equals error_low (Brent's method on w;
    # P(v > t | low) falls from 1 to 0 over [-1, 2] for any s that matters here)
    def excess(t):
        return _survival(t, range_low, e_sensor, s) - error_low
    lo_w, hi_w = -1.0 - 10.0 * s, 2.0 + 10.0 * s
    thr = optimize.brentq(excess, lo_w, hi_w, xtol=1e-14, rtol=4 * np.finfo(float).eps) \
        if excess(lo_w) > 0 > excess(hi_w) else hi_w
    return bool(1.0 - _survival(thr, range_high, e_sensor, s) <= error_high)


def min_fixed_contact_s(range_low, range_high, error_low: float, error_high: float, sensor: Sensor,
                        noise_ratio: float, max_contact_s: float, *, model=None) -> float | None:
    """Shortest fixed contact [s] (to one sample) at which the ideal observer reaches both error rates.

    None when not by ``max_contact_s``. Bisection over the sample count (monotone: more samples
    never hurt the ideal observer) of whether the best fixed test reaches both rates.

    Examples
    --------
    >>> from designkit import SENSORS
    >>> t = min_fixed_contact_s((20000, 20080), (35000, 35080), 0.1, 0.1, SENSORS["paper"], 0.005, 10.0)
    >>> 1.0 < t < 1.2
    True
    """
    fs = sensor.sample_rate_hz
    n_hi = int(last_sample_index(max_contact_s, fs))
    return _min_fixed_n(range_low, range_high, error_low, error_high, sensor.effusivity, noise_ratio,
                        _shape(sensor, get_model(model), n_hi + 1), fs)


def _min_fixed_n(range_low, range_high, error_low: float, error_high: float, e_sensor: float, noise_ratio: float,
                 g: np.ndarray, fs: float) -> float | None:
    """:func:`min_fixed_contact_s` on a shape table ``g`` (samples 0 .. the longest contact's last)."""
    with np.errstate(divide="ignore"):
        s_of_n = noise_ratio / np.sqrt(np.cumsum(g * g))

    def ok(n):
        return _fixed_ok(range_low, range_high, error_low, error_high, e_sensor, float(s_of_n[n]))
    n_hi = g.size - 1
    if n_hi < 1 or not ok(n_hi):
        return None
    lo = 0
    while n_hi - lo > 1:
        mid = (lo + n_hi) // 2
        if ok(mid):
            n_hi = mid
        else:
            lo = mid
    return n_hi / fs


# ----------------------------------------------------------------- the test
def _candidate(spec, e_sensor: float, error_rate: float) -> Candidate:
    if isinstance(spec, Candidate):
        return spec
    if isinstance(spec, ObjectClass):
        name, (lo, hi) = (spec.material or spec.label), spec.e_range
    elif isinstance(spec, str):
        from ..objects import object_class

        oc = object_class(material=spec)
        name, (lo, hi) = oc.material, oc.e_range
    else:
        try:
            name, rng = spec
            lo, hi = (float(rng), float(rng)) if np.isscalar(rng) else (float(rng[0]), float(rng[1]))
        except (TypeError, ValueError):
            raise InputError(f"a candidate is a material name, an ObjectClass or (name, (e_low, e_high)); "
                             f"got {spec!r}") from None
    edges, log_mass = candidate_pieces(lo, hi, e_sensor)
    return Candidate(str(name), (float(lo), float(hi)), tuple(float(x) for x in edges),
                     tuple(float(x) for x in log_mass), float(error_rate))


def _check_rate(name: str, x) -> float:
    x = float(x)
    if not 0.0 < x < 0.5:
        raise InputError(f"error rate of {name} must lie in (0, 0.5), got {x:g}")
    return x


class SequentialTest:
    """Sequential test between candidate materials on the samples of one touch.

    Parameters
    ----------
    candidates : sequence
        Two or more: material names (database), :class:`~designkit.objects.ObjectClass`
        objects, or ``(name, (e_low, e_high))`` / ``(name, e)`` pairs [J s^-1/2 K^-1 m^-2].
    sensor : Sensor
        e_s, tau and the sampling rate the samples must come at.
    noise_c : float
        White-noise standard deviation sigma of one sample [degC] (> 0).
    sensor_temp_c, ambient_temp_c : float
        Ts0 (sensor before contact) and Ta (object) [degC]; they must differ.
    error_rate : float or mapping
        Requested probability of a wrong decision on a touch of each candidate
        (one number for all, or name -> number); each in (0, 0.5).
    max_contact_s : float
        Longest contact [s]; by then the test gives :data:`NO_DECISION`.
    model : ForwardModel or name, optional
        A shared-shape forward model (default: the paper's semi-infinite one).

    Notes
    -----
    Feed every sample, the first at contact (t = 0), at the sensor's rate:
    :meth:`update` refuses a sample whose spacing from the previous one is not
    a whole number of sample periods (within a quarter period), naming the
    rate it saw. Sample ``k`` is read as taken at ``round(t_s * fs) / fs``.

    Examples
    --------
    >>> from designkit import SENSORS
    >>> from designkit.simulation import simulate_trials
    >>> from designkit.scene import Scene
    >>> test = SequentialTest([("35000", (35000, 35080)), ("20000", (20000, 20080))], SENSORS["paper"],
    ...                       noise_c=0.05, sensor_temp_c=35.0, ambient_temp_c=25.0, error_rate=0.01)
    >>> touch = simulate_trials(35040, SENSORS["paper"], Scene(contact_s=5), seed=3)
    >>> for t, y in zip(touch.time_s, touch.temperature_c[0]):
    ...     d = test.update(t, y)
    ...     if d.final:
    ...         break
    >>> d.state, d.material, d.time_s < 1.5
    ('decided', '35000', True)
    """

    def __init__(self, candidates, sensor: Sensor, *, noise_c: float, sensor_temp_c: float,
                 ambient_temp_c: float, error_rate=0.05, max_contact_s: float = 10.0, model=None):
        fm = get_model(model)
        if not fm.shared_shape:
            raise InputError(f"the sequential test needs a shared-shape model; {fm.name!r} has curves that differ "
                             "per object")
        self.model = fm
        self.sensor = sensor
        self.noise_c = check_positive("noise sigma [degC]", noise_c)
        self.sensor_temp_c = float(sensor_temp_c)
        self.ambient_temp_c = float(ambient_temp_c)
        self.amplitude_c = self.ambient_temp_c - self.sensor_temp_c
        if not math.isfinite(self.amplitude_c) or self.amplitude_c == 0.0:
            raise InputError("sensor and object temperatures must differ (no temperature difference, no signal)")
        self.max_contact_s = check_positive("longest contact [s]", max_contact_s)
        specs = list(candidates)
        if len(specs) < 2:
            raise InputError(f"a decision needs at least two candidate materials, got {len(specs)}")
        rates = error_rate if isinstance(error_rate, dict) else None
        cands = []
        for spec in specs:
            c = _candidate(spec, sensor.effusivity, 0.05)
            r = _check_rate(c.name, rates.get(c.name, 0.05) if rates is not None else error_rate)
            cands.append(Candidate(c.name, c.e_range, c.w_edges, c.log_mass, r))
        names = [c.name for c in cands]
        if len(set(names)) != len(names):
            raise InputError(f"candidate names must differ, got {names}")
        if rates is not None and set(rates) - set(names):
            raise InputError(f"error rates given for unknown candidates: {sorted(set(rates) - set(names))}")
        self._g = _shape(sensor, fm, int(last_sample_index(self.max_contact_s, sensor.sample_rate_hz)) + 1)
        self.plan = self._plan(tuple(cands))
        self._thr = self.plan.thresholds.tolist()
        self._fs = float(sensor.sample_rate_hz)
        self.reset()

    def _plan(self, cands: tuple[Candidate, ...]) -> DecisionPlan:
        k = len(cands)
        eps = np.array([c.error_rate for c in cands])
        thr = np.log((k - 1) * (1.0 - eps)[:, None] / eps[None, :])
        np.fill_diagonal(thr, 0.0)
        ratio = self.noise_c / abs(self.amplitude_c)
        worst, limiting, separable, bad = 0.0, None, True, None
        for i in range(k):
            for j in range(i + 1, k):
                a, b = sorted([cands[i], cands[j]], key=lambda c: (c.e_range[0] + c.e_range[1]))
                if a.e_range[1] > b.e_range[0]:
                    separable, bad = False, (a.name, b.name)
                    break
                t = _min_fixed_n(a.e_range, b.e_range, a.error_rate, b.error_rate, self.sensor.effusivity, ratio,
                                 self._g, float(self.sensor.sample_rate_hz))
                if t is None:
                    separable, bad = False, (a.name, b.name)
                    break
                if t > worst:
                    worst, limiting = t, (a.name, b.name)
            if not separable:
                break
        if separable:
            reason = (f"a fixed contact needs {worst:g} s for these error rates (pair {limiting[0]} / {limiting[1]}); "
                      "the sequential test stops as soon as the evidence suffices")
            return DecisionPlan(cands, thr, self.max_contact_s, True, worst, limiting, reason)
        reason = (f"no contact time up to {self.max_contact_s:g} s will separate {bad[0]} from {bad[1]} "
                  f"at the requested error rates (the ideal observer's bound)")
        return DecisionPlan(cands, thr, self.max_contact_s, False, None, bad, reason)

    @property
    def n_samples(self) -> int:
        """Samples fed since the touch began."""
        return self._n

    @property
    def shape_table(self) -> np.ndarray:
        """The response shape ``g_k = g(k / fs)`` up to the longest contact (a copy)."""
        return self._g.copy()

    @property
    def candidates(self) -> tuple[Candidate, ...]:
        return self.plan.candidates

    def projection(self, temps_c) -> tuple[np.ndarray, np.ndarray, int]:
        """:meth:`update`'s statistic after every sample of many touches: ``(v, s, first)``.

        ``temps_c`` (touch, sample) from contact at the sensor's rate, cut to the longest contact;
        ``v`` (touch, sample - first) the running projection, ``s`` (sample - first,) its noise, from
        ``first``, the first sample whose shape is not 0.
        """
        y = np.asarray(temps_c, dtype=np.float64)
        m = min(y.shape[1], self._g.size)
        g = self._g[:m]
        s_gg = np.cumsum(g * g)
        first = int(np.argmax(s_gg > 0))
        a = self.amplitude_c
        v = np.cumsum((y[:, :m] - self.sensor_temp_c) * g, axis=1)[:, first:] / (a * s_gg[first:])
        return v, self.noise_c / (abs(a) * np.sqrt(s_gg[first:])), first

    def reset(self) -> None:
        """Start a new touch (the next sample is at contact)."""
        self._s_rg = 0.0
        self._s_gg = 0.0
        self._n = 0
        self._last_k = -1
        self._decision: Decision | None = None

    def _index(self, t_s: float) -> int:
        fs = self.sensor.sample_rate_hz
        x = float(t_s) * fs
        if not math.isfinite(x) or x < -0.25:
            raise InputError(f"sample time must be a finite time after contact [s], got {t_s!r}")
        k = int(round(x))
        if abs(x - k) > 0.25 or k <= self._last_k:
            dt = float(t_s) - (self._last_k / fs if self._last_k >= 0 else 0.0)
            seen = f"{1.0 / dt:.4g} Hz" if dt > 0 else "a time that does not increase"
            raise InputError(f"stream sample rate does not match the sensor's {fs:g} Hz: sample at {float(t_s):.6g} s "
                             f"after the previous one gives {seen}")
        return k

    def update(self, t_s: float, temp_c: float) -> Decision:
        """Add one sample (time after contact [s], reading [degC]) and decide.

        Once the answer is final, further samples return the same decision.
        """
        if self._decision is not None:
            return self._decision
        if not self.plan.separable:
            self._decision = Decision(NOT_SEPARABLE, None, float(t_s), self._n)
            return self._decision
        y = float(temp_c)
        if not math.isfinite(y):
            raise InputError(f"sample reading must be a finite temperature [degC], got {temp_c!r}")
        k = self._index(t_s)
        self._last_k = k
        self._n += 1
        if k >= self._g.size:
            return self._finish(k, timed_out=True)
        g = float(self._g[k])
        self._s_rg += (y - self.sensor_temp_c) * g
        self._s_gg += g * g
        return self._finish(k, timed_out=k >= self._g.size - 1)

    def _finish(self, k: int, *, timed_out: bool) -> Decision:
        t = k / self._fs
        if self._s_gg > 0.0:
            v = self._s_rg / (self.amplitude_c * self._s_gg)
            s = self.noise_c / (abs(self.amplitude_c) * math.sqrt(self._s_gg))
            ll = _log_marginals_1(v, s, self.plan.candidates)
            state, idx = _decide_1(ll, self._thr)
        else:
            ll, state, idx = [0.0] * len(self.plan.candidates), KEEP_TOUCHING, -1
        lls = tuple(ll)
        if state == "decided":
            self._decision = Decision("decided", self.plan.candidates[idx].name, t, self._n, lls)
            return self._decision
        if timed_out:
            best = self.plan.candidates[max(range(len(ll)), key=ll.__getitem__)].name
            self._decision = Decision(NO_DECISION, best, t, self._n, lls)
            return self._decision
        return Decision(KEEP_TOUCHING, None, t, self._n, lls)


def _decide_1(ll, thr) -> tuple[str, int]:
    k = len(ll)
    for i in range(k):
        if all(j == i or ll[i] - ll[j] >= thr[i][j] for j in range(k)):
            return "decided", i
    return KEEP_TOUCHING, -1


# ----------------------------------------------------------------- many touches at once
@dataclass(frozen=True)
class BatchResult:
    """Decisions of the test on many touches.

    Attributes
    ----------
    decided : ndarray of int, shape (n,)
        Index of the decided candidate, -1 when none by the longest contact.
    time_s : ndarray, shape (n,)
        Time of the decision (the longest contact when none) [s].
    best : ndarray of int, shape (n,)
        Most likely candidate at the end (the decided one when decided).
    """

    decided: np.ndarray
    time_s: np.ndarray
    best: np.ndarray


def run_batch(test: SequentialTest, temps_c: np.ndarray, *, chunk: int = 2000) -> BatchResult:
    """The test on many touches at once (rows of ``temps_c``, samples from contact at the sensor's rate).

    Identical to feeding each row to :meth:`SequentialTest.update` (same
    statistic, same thresholds), vectorized over touches and samples.

    Examples
    --------
    >>> from designkit import SENSORS
    >>> from designkit.simulation import simulate_trials
    >>> from designkit.scene import Scene
    >>> test = SequentialTest([("35000", (35000, 35080)), ("20000", (20000, 20080))], SENSORS["paper"],
    ...                       noise_c=0.05, sensor_temp_c=35.0, ambient_temp_c=25.0, error_rate=0.01)
    >>> r = run_batch(test, simulate_trials(20040, SENSORS["paper"], Scene(contact_s=5), 50, seed=1).temperature_c)
    >>> bool((r.decided == 1).mean() > 0.95)
    True
    """
    y = np.asarray(temps_c, dtype=np.float64)
    if y.ndim != 2:
        raise InputError(f"touches must be a 2-D array (touch, sample), got shape {y.shape}")
    n = y.shape[0]
    k = len(test.plan.candidates)
    decided = np.full(n, -1)
    best = np.full(n, -1)
    time_s = np.full(n, np.nan)
    if not test.plan.separable:
        return BatchResult(decided, np.zeros(n), best)
    thr = test.plan.thresholds
    fs = test.sensor.sample_rate_hz
    for lo in range(0, n, chunk):
        v, s, first = test.projection(y[lo:lo + chunk])
        ll = log_marginals(v, np.broadcast_to(s, v.shape), test.plan.candidates)  # (c, m', k)
        diff = ll[..., :, None] - ll[..., None, :]
        ok = (diff >= thr) | np.eye(k, dtype=bool)
        win = ok.all(axis=-1)  # (c, m', k); at most one winner per sample (thresholds > 0)
        any_win = win.any(axis=-1)
        hit = any_win.any(axis=1)
        at = np.argmax(any_win, axis=1)
        who = np.argmax(win[np.arange(v.shape[0]), at], axis=-1)
        d = np.where(hit, who, -1)
        decided[lo:lo + chunk] = d
        time_s[lo:lo + chunk] = np.where(hit, at + first, v.shape[1] + first - 1) / fs
        best[lo:lo + chunk] = np.where(hit, d, np.argmax(ll[:, -1, :], axis=-1))
    return BatchResult(decided, time_s, best)
