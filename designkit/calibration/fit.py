"""Identify a sensor's e_s and alpha_s from recorded touches (paper appendix).

Model (paper eqs. 1-2, appendix): trial ``i`` of material ``m``, detected
contact onset at ``t = 0``, heat flow from ``t = t_off`` (the contact-time
offset, shared by all trials)::

    T_i(t) = Ts0_i + (To_i - Ts0_i) * w_m * erfc(sqrt(tau / (t - t_off))),  t > t_off
    w_m = e_o,m / (e_s + e_o,m),     tau = x^2 / (4 alpha_s)

``Ts0_i`` and ``To_i`` come from the samples before contact (the object's from
the passive channel). The paper fitted e_s, alpha_s, each material's e_o
inside its database range and the offset by L-BFGS-B on the sum of squared
errors; here the same least-squares problem is solved with
:func:`scipy.optimize.least_squares` (trust-region reflective, analytic
Jacobian) in log parameters, from several starts.

What the data can and cannot tell
---------------------------------
* Only ``tau`` is identified by the curve shape; ``alpha_s = x^2 / (4 tau)``
  follows from the fixed depth ``x`` (80 um by default). Another depth gives
  another alpha_s with the same fit.
* The amplitudes fix only the ratios ``rho_m = e_o,m / e_s`` (``w_m`` depends
  on nothing else). The model is unchanged when e_s and every e_o are scaled
  together, so **e_s is identified only through the effusivity ranges**:
  each material allows ``e_s`` in ``[e_min,m / rho_m, e_max,m / rho_m]``. If
  these intervals overlap, every e_s in the overlap fits equally well (the
  reported value is its geometric centre and its interval is the overlap);
  if they do not, no e_s keeps every material in range and the bounded fit
  compromises with some materials at their bounds (flagged).

So the fit runs in two steps: (1) the identified quantities (tau, t_off,
log rho_m) by unbounded least squares; (2) e_s from the ranges, by the
overlap or, when the ranges conflict, by the paper's bounded joint fit.
Uncertainty: a bootstrap over trials (trials resampled within each
material, the whole two-step estimator repeated) or, with no bootstrap, a
cluster-robust (trials as clusters) sandwich covariance from the Jacobian.
A profile of the residual over e_s shows the flat region or the minimum.

Materials whose object temperature is not known (an object cooled or warmed
away from room temperature, detected from a passive channel that moves
during contact) get a free amplitude per trial; they inform tau and t_off
only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np
from scipy import special

from .._validation import InputError, as_generator, check_positive, check_temperature
from .trials import Trial

__all__ = [
    "CalibrationProblem",
    "CalibrationResult",
    "FitSettings",
    "MaterialRange",
    "Parameter",
    "check_calibration",
    "fit_sensor",
    "parse_object_temps",
    "parse_ranges",
    "resolve_ranges",
]

PAPER_E_S = 892.0
PAPER_ALPHA_S = 1.19e-9
_SQRT_PI = math.sqrt(math.pi)
_LOG_RHO_LIMIT = 25.0  # |log(e_o / e_s)| beyond this is "no information"


# ----------------------------------------------------------------- ranges
@dataclass(frozen=True)
class MaterialRange:
    """Effusivity range of one material [J s^-1/2 K^-1 m^-2] and where it came from."""

    name: str
    e_min: float
    e_max: float
    source: str

    def __post_init__(self) -> None:
        lo = check_positive(f"{self.name} effusivity minimum", self.e_min)
        hi = check_positive(f"{self.name} effusivity maximum", self.e_max)
        if hi < lo:
            raise InputError(f"effusivity range of {self.name} has min > max: {lo:g}:{hi:g}")


def parse_ranges(specs: Sequence[str]) -> dict[str, str]:
    """``["metal=12767:25972", "cold_wood=wood"]`` -> {name: spec}."""
    out: dict[str, str] = {}
    for spec in specs:
        name, sep, value = str(spec).partition("=")
        name, value = name.strip(), value.strip()
        if not sep or not name or not value:
            raise InputError(f"--range must look like NAME=MIN:MAX or NAME=DATABASE_NAME, got {spec!r}")
        if name in out:
            raise InputError(f"--range given twice for {name!r}")
        out[name] = value
    return out


def _range_from_spec(name: str, spec: str) -> MaterialRange:
    lo_text, sep, hi_text = spec.partition(":")
    if sep:
        try:
            lo, hi = float(lo_text), float(hi_text)
        except ValueError:
            raise InputError(f"--range {name}={spec}: MIN and MAX must be numbers") from None
        return MaterialRange(name, lo, hi, "--range")
    from ..materials import get_material

    try:
        m = get_material(spec)
    except InputError as exc:
        raise InputError(f"--range {name}={spec}: not MIN:MAX and {exc}") from None
    return MaterialRange(name, m.e_min, m.e_max, f"materials database: {m.name}")


def resolve_ranges(materials: Sequence[str], overrides: Mapping[str, str]) -> dict[str, MaterialRange]:
    """A range for every material: ``--range`` first, then the materials database.

    Raises one InputError naming every material left without a range.
    """
    unknown = sorted(set(overrides) - set(materials))
    if unknown:
        raise InputError(f"--range names material(s) not in the index: {', '.join(unknown)} "
                         f"(it has {', '.join(materials)})")
    out: dict[str, MaterialRange] = {}
    missing: list[str] = []
    for name in materials:
        if name in overrides:
            out[name] = _range_from_spec(name, overrides[name])
            continue
        try:
            from ..materials import get_material
        except ImportError:  # pragma: no cover - the materials layer is part of designkit
            missing.append(name)
            continue
        try:
            m = get_material(name)
        except InputError:
            missing.append(name)
            continue
        out[name] = MaterialRange(name, m.e_min, m.e_max, f"materials database: {m.name}")
    if missing:
        raise InputError(f"no effusivity range for {', '.join(missing)} (not a materials database name): "
                         f"give --range NAME=MIN:MAX or NAME=DATABASE_NAME, or leave them out with --only")
    return out


def parse_object_temps(specs: Sequence[str]) -> dict[str, str | float]:
    """``["cold_wood=free", "block=18.5"]`` -> {name: "passive" | "passive-end" | "free" | degC}."""
    out: dict[str, str | float] = {}
    for spec in specs:
        name, sep, value = str(spec).partition("=")
        name, value = name.strip(), value.strip().lower()
        if not sep or not name or not value:
            raise InputError(f"--object-temp must look like NAME=passive|passive-end|free|DEGC, got {spec!r}")
        if value in ("passive", "passive-end", "free"):
            out[name] = value
        else:
            try:
                out[name] = float(value)
            except ValueError:
                raise InputError(f"--object-temp {spec!r}: use passive, passive-end, free or a temperature "
                                 "in °C") from None
            check_temperature(f"--object-temp {name}", out[name])  # NaN was taken, and fitted
    return out


# --------------------------------------------------------------- settings
@dataclass(frozen=True)
class FitSettings:
    """Knobs of :func:`fit_sensor`.

    Parameters
    ----------
    depth_m : float
        Thermistor depth x [m] (fixed; 80 um as the paper's lab).
    offset_bounds_s : (float, float)
        Bounds of the contact-time offset t_off [s].
    fit_from_s, fit_to_s : float or None
        Samples used: ``fit_from_s <= t <= fit_to_s`` (None: to the end of
        each trial, or to its release when the sidecar records one).
    baseline : {"mean", "trend"}
        Ts0 from the mean of the pre-contact samples, or from a straight line
        through them evaluated at the onset (rigs whose heater drifts).
    moving_passive_c : float
        A material whose passive channel moves more than this [degC] during
        contact (median over its trials) is not at room temperature: its
        object temperature becomes free per trial unless told otherwise.
    bootstrap : int
        Bootstrap replicates (0: Jacobian sandwich instead).
    profile_points : int
        Most steps (of 5 % in e_s) the residual profile walks out on each side
        of the estimate (0: no profile).
    seed : int
        Bootstrap seed.
    """

    depth_m: float = 80e-6
    offset_bounds_s: tuple[float, float] = (-1.5, 1.5)
    fit_from_s: float = 0.0
    fit_to_s: float | None = None
    baseline: str = "mean"
    moving_passive_c: float = 1.0
    bootstrap: int = 100
    profile_points: int = 40
    seed: int = 0
    es_bounds: tuple[float, float] = (1.0, 1e6)
    tau_bounds_s: tuple[float, float] = (1e-3, 1e3)

    def __post_init__(self) -> None:
        check_positive("thermistor depth [m]", self.depth_m)
        lo, hi = self.offset_bounds_s
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise InputError(f"offset bounds must be finite with min < max, got {lo:g}:{hi:g}")
        if self.baseline not in ("mean", "trend"):
            raise InputError(f"baseline must be 'mean' or 'trend', got {self.baseline!r}")
        if self.bootstrap < 0 or self.profile_points < 0:
            raise InputError("bootstrap and profile points must be >= 0")
        if self.bootstrap == 1:
            raise InputError("a bootstrap needs at least 2 replicates (or 0 for none)")


# ------------------------------------------------------------ prepared data
@dataclass(frozen=True)
class _Data:
    t: np.ndarray          # (N,) time since detected onset [s]
    y: np.ndarray          # (N,) sensor [degC]
    trial: np.ndarray      # (N,) trial id
    starts: np.ndarray     # (n+1,) sample offsets of each trial
    mat: np.ndarray        # (n,) material id per trial
    ts0: np.ndarray        # (n,) initial sensor temperature
    to: np.ndarray         # (n,) object temperature (nan where free)
    free: np.ndarray       # (n,) bool, amplitude free per trial
    names: tuple[str, ...]

    @property
    def n_trials(self) -> int:
        return int(self.mat.size)


@dataclass(frozen=True)
class _Rows:
    """Residual rows ``r = c * amp * g(t) - target`` of a least-squares problem.

    Known object temperature: ``amp = w_m`` (the material's weight), and the
    trials of a material are summed exactly per time point: for the trials
    ``i`` with a sample at ``t`` (multiplicity ``k_i``),
    ``sum_i k_i (Ts0_i + D_i w g - y_i)^2 = (sqrt(S2) w g - S1/sqrt(S2))^2 + const``
    with ``D_i = To_i - Ts0_i``, ``S2 = sum k_i D_i^2`` and
    ``S1 = sum k_i D_i (y_i - Ts0_i)``. The fit then has one row per material
    and time point instead of one per sample, with the same minimum.
    Free object temperature: one row per sample, ``amp`` the trial's own
    amplitude (solved in closed form, variable projection).
    """

    t: np.ndarray
    mat: np.ndarray
    c: np.ndarray
    target: np.ndarray
    group: np.ndarray      # free-amplitude group per row, -1 for known-amplitude rows
    n_groups: int
    trial: np.ndarray      # trial per row (-1 when rows are sums over trials)
    const: float           # sum of squares the compression took out
    n_samples: float       # samples represented (with multiplicity)
    t_unique: np.ndarray   # distinct times (trials share a time grid: the shape is computed once per time)
    t_index: np.ndarray    # row -> index into t_unique


def _rows(data: _Data, weights: np.ndarray | None = None, *, compress: bool = True) -> _Rows:
    k = np.ones(data.n_trials) if weights is None else np.asarray(weights, dtype=np.float64)
    ks = k[data.trial]
    keep = ks > 0
    free_s = data.free[data.trial]
    dev = data.y - data.ts0[data.trial]             # y - Ts0
    D = np.nan_to_num((data.to - data.ts0)[data.trial])
    parts = []
    const = 0.0
    known = keep & ~free_s
    if compress and known.any():
        key = data.mat[data.trial][known].astype(np.int64) * (1 << 40) + np.rint(data.t[known] * 1e6).astype(np.int64)
        uniq, inv = np.unique(key, return_inverse=True)
        kk, dd, vv = ks[known], D[known], dev[known]
        s2 = np.bincount(inv, weights=kk * dd * dd)
        s1 = np.bincount(inv, weights=kk * dd * vv)
        q = np.bincount(inv, weights=kk * vv * vv)
        t_u = np.bincount(inv, weights=data.t[known]) / np.bincount(inv)
        ok = s2 > 0
        const += float(np.sum(q[~ok]) + np.sum(q[ok] - s1[ok] ** 2 / s2[ok]))
        root = np.sqrt(s2[ok])
        m_u = (uniq[ok] >> 40).astype(np.int64)
        parts.append((t_u[ok], m_u, root, s1[ok] / root, np.full(root.size, -1), np.full(root.size, -1)))
    elif known.any():
        sw = np.sqrt(ks[known])
        parts.append((data.t[known], data.mat[data.trial][known], sw * D[known], sw * dev[known],
                      np.full(int(known.sum()), -1), data.trial[known]))
    fr = keep & free_s
    n_groups = 0
    if fr.any():
        groups, ginv = np.unique(data.trial[fr], return_inverse=True)
        n_groups = groups.size
        sw = np.sqrt(ks[fr])
        parts.append((data.t[fr], data.mat[data.trial][fr], sw, sw * dev[fr], ginv, data.trial[fr]))
    cols = [np.concatenate([p[j] for p in parts]) for j in range(6)]
    t_u, t_inv = np.unique(cols[0], return_inverse=True)
    return _Rows(cols[0], cols[1].astype(np.int64), cols[2], cols[3], cols[4].astype(np.int64), n_groups,
                 cols[5].astype(np.int64), const, float(np.sum(ks[keep])), t_u, t_inv.astype(np.int64))


def _pre_stats(trial: Trial, baseline: str, until_s: float = 0.0) -> tuple[float, float, float, int]:
    """(Ts0, To, residual sum of squares about a line, dof) from samples before ``until_s``.

    ``until_s`` is 0 (the detected onset) or, when heat is found to flow
    earlier, the fitted contact time: samples after it are already cooling.
    Falls back to all samples before the onset when fewer than 10 are left.
    """
    pre = trial.time_s < until_s
    if pre.sum() < 10:
        pre = trial.time_s < 0
    t, s = trial.time_s[pre], trial.sensor_c[pre]
    if t.size < 3:
        raise InputError(f"trial {trial.source}: fewer than 3 samples before contact (time_s < 0)")
    coef = np.polyfit(t, s, 1)
    ssr = float(np.sum((s - np.polyval(coef, t)) ** 2))
    ts0 = float(np.mean(s)) if baseline == "mean" else float(np.polyval(coef, min(until_s, 0.0)))
    obj = trial.object_c[pre]
    to = float(np.mean(obj[np.isfinite(obj)])) if np.isfinite(obj).any() else math.nan
    return ts0, to, ssr, t.size - 2


# --------------------------------------------------------------- the model
def _shape(t: np.ndarray, tau: float, off: float):
    """g = erfc(sqrt(tau / (t - off))) and its derivatives in log tau and off."""
    tt = t - off
    pos = tt > 0
    z = np.zeros_like(tt)
    np.divide(tau, tt, out=z, where=pos)
    np.sqrt(z, out=z)
    g = np.where(pos, special.erfc(z), 0.0)
    ez = np.where(pos, z * np.exp(-z * z) / _SQRT_PI, 0.0)
    dg_dlogtau = -ez
    dg_doff = np.zeros_like(tt)
    np.divide(-ez, tt, out=dg_doff, where=pos)
    return g, dg_dlogtau, dg_doff


class _Problem:
    """Least squares in x = [log tau, off, log e_o (or log rho) per material, (log e_s)].

    With ``log_es`` fixed at 0 the material parameters are log(e_o/e_s), the
    identified ratios; with ``log_es=None`` e_s is the last parameter.
    """

    def __init__(self, rows: _Rows, n_mat: int, *, log_es: float | None,
                 eo_bounds: np.ndarray | None, settings: FitSettings) -> None:
        self.rows = rows
        self.m = n_mat
        self.log_es = log_es          # None: e_s is a parameter (last)
        lo = [math.log(settings.tau_bounds_s[0]), settings.offset_bounds_s[0]]
        hi = [math.log(settings.tau_bounds_s[1]), settings.offset_bounds_s[1]]
        if eo_bounds is None:
            lo += [-_LOG_RHO_LIMIT] * n_mat
            hi += [_LOG_RHO_LIMIT] * n_mat
        else:
            lo += list(eo_bounds[:, 0])
            hi += list(eo_bounds[:, 1])
        if log_es is None:
            lo.append(math.log(settings.es_bounds[0]))
            hi.append(math.log(settings.es_bounds[1]))
        self.lo = np.array(lo)
        self.hi = np.array(hi)
        self.fixed = self.hi - self.lo <= 1e-12 * np.maximum(1.0, np.abs(self.hi))
        self.free_rows = rows.group >= 0
        # a material whose rows all have free amplitudes has no say in its e_o: hold it
        known = np.bincount(rows.mat[~self.free_rows], minlength=n_mat) if (~self.free_rows).any() \
            else np.zeros(n_mat, dtype=np.int64)
        self.fixed[2:2 + n_mat] |= known[:n_mat] == 0
        self._cache: tuple[bytes, Any] | None = None

    def _les(self, x):
        return x[-1] if self.log_es is None else self.log_es

    def _eval(self, x):
        key = x.tobytes()
        if self._cache is not None and self._cache[0] == key:
            return self._cache[1]
        rw = self.rows
        g, g_lt, g_off = (a[rw.t_index] for a in _shape(rw.t_unique, math.exp(x[0]), x[1]))
        w_m = special.expit(x[2:2 + self.m] - self._les(x))           # e_o / (e_s + e_o)
        w = w_m[rw.mat]
        amp = rw.c * w
        if rw.n_groups:  # free amplitude per trial: least squares in closed form
            fr = self.free_rows
            cg = rw.c[fr] * g[fr]
            num = np.bincount(rw.group[fr], weights=cg * rw.target[fr], minlength=rw.n_groups)
            den = np.bincount(rw.group[fr], weights=cg * cg, minlength=rw.n_groups)
            a = np.divide(num, den, out=np.zeros_like(num), where=den > 0)
            amp = amp.copy()
            amp[fr] = rw.c[fr] * a[rw.group[fr]]
        r = amp * g - rw.target
        out = (r, g, g_lt, g_off, w, amp)
        self._cache = (key, out)
        return out

    def residuals(self, x):
        return self._eval(x)[0]

    def jac(self, x):
        r, g, g_lt, g_off, w, amp = self._eval(x)
        rw = self.rows
        cols = 2 + self.m + (1 if self.log_es is None else 0)
        J = np.zeros((r.size, cols))
        J[:, 0] = amp * g_lt
        J[:, 1] = amp * g_off
        if rw.n_groups:  # variable projection (Kaufman): project out each free trial's own amplitude
            fr = self.free_rows
            grp = rw.group[fr]
            c2g = rw.c[fr] ** 2 * g[fr]
            den = np.bincount(grp, weights=c2g * g[fr], minlength=rw.n_groups)
            for col, dg in ((0, g_lt), (1, g_off)):
                num = np.bincount(grp, weights=c2g * dg[fr], minlength=rw.n_groups)
                proj = np.divide(num, den, out=np.zeros_like(num), where=den > 0)
                J[fr, col] = amp[fr] * (dg[fr] - g[fr] * proj[grp])
        dw = np.where(self.free_rows, 0.0, amp * (1.0 - w) * g)
        J[np.arange(r.size), 2 + rw.mat] = dw
        if self.log_es is None:
            J[:, -1] = -dw
        J[:, self.fixed] = 0.0
        return J

    def solve(self, x0):
        """Bounded least squares from ``x0`` over the parameters that are not held."""
        from scipy.optimize import OptimizeResult, least_squares

        x0 = np.clip(np.asarray(x0, dtype=np.float64), self.lo, self.hi)
        free = ~self.fixed
        full = x0.copy()

        def expand(z):
            full[free] = z
            return full

        sol = least_squares(lambda z: self.residuals(expand(z)), x0[free],
                            jac=lambda z: self.jac(expand(z))[:, free], bounds=(self.lo[free], self.hi[free]),
                            method="trf", x_scale="jac", xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=500)
        x = x0.copy()
        x[free] = sol.x
        active = np.zeros(x.size, dtype=int)
        active[free] = sol.active_mask
        return OptimizeResult(x=x, cost=float(sol.cost), fun=sol.fun, status=sol.status, nfev=sol.nfev,
                              active_mask=active)


def _initial_log_rho(rows: _Rows, n_mat: int, tau: float, off: float) -> np.ndarray:
    """Closed-form amplitude fit of each material for a given shape -> log(e_o/e_s)."""
    g = _shape(rows.t_unique, tau, off)[0][rows.t_index]
    out = np.zeros(n_mat)
    for k in range(n_mat):
        sel = (rows.mat == k) & (rows.group < 0)
        cg = rows.c[sel] * g[sel]
        den = np.sum(cg * cg)
        w = np.sum(cg * rows.target[sel]) / den if den > 0 else 0.5
        w = float(np.clip(w, 1e-4, 1 - 1e-4))
        out[k] = math.log(w / (1 - w))
    return out


def _ratio_fit(rows: _Rows, n_mat: int, settings: FitSettings, x0=None):
    """Step 1: tau, t_off, log rho (unbounded); several starts unless x0 is given."""
    prob = _Problem(rows, n_mat, log_es=0.0, eo_bounds=None, settings=settings)
    if x0 is not None:
        return prob.solve(x0), prob
    lo, hi = settings.offset_bounds_s
    best = None
    for tau in (0.2, 0.8, 3.0, 10.0):
        for off in (lo + 0.25 * (hi - lo), 0.5 * (lo + hi), lo + 0.75 * (hi - lo)):
            start = np.concatenate([[math.log(tau), off], _initial_log_rho(rows, n_mat, tau, off)])
            sol = prob.solve(start)
            if best is None or sol.cost < best.cost:
                best = sol
    return best, prob


def _es_interval(log_rho: np.ndarray, log_bounds: np.ndarray, constrained: np.ndarray):
    """Per material [log e_min - log rho, log e_max - log rho] and their overlap (log e_s)."""
    per = np.column_stack([log_bounds[:, 0] - log_rho, log_bounds[:, 1] - log_rho])
    per = per[constrained]
    if per.size == 0:
        return per, (math.nan, math.nan)
    return per, (float(per[:, 0].max()), float(per[:, 1].min()))


def _joint_fit(rows: _Rows, n_mat: int, log_bounds: np.ndarray, settings: FitSettings, ratio_x,
               starts_log_es: Sequence[float]):
    """Step 2 when the ranges conflict: the paper's bounded joint fit, several e_s starts."""
    prob = _Problem(rows, n_mat, log_es=None, eo_bounds=log_bounds, settings=settings)
    best = None
    for les in starts_log_es:
        les = float(np.clip(les, math.log(settings.es_bounds[0]), math.log(settings.es_bounds[1])))
        leo = np.clip(ratio_x[2:] + les, log_bounds[:, 0], log_bounds[:, 1])
        sol = prob.solve(np.concatenate([ratio_x[:2], leo, [les]]))
        if best is None or sol.cost < best.cost:
            best = sol
    return best, prob


@dataclass(frozen=True)
class _Estimate:
    log_es: float
    tau: float
    off: float
    log_eo: np.ndarray
    log_rho: np.ndarray                # e_o / e_s of the reported fit
    log_rho_free: np.ndarray           # e_o / e_s the data alone prefer (step 1)
    interval: tuple[float, float]      # overlap of the allowed log e_s intervals (a > b: conflict)
    conflict: bool
    cost: float
    x_ratio: np.ndarray
    x_joint: np.ndarray | None


def _estimate(rows: _Rows, n_mat: int, log_bounds: np.ndarray, constrained: np.ndarray,
              settings: FitSettings, warm: _Estimate | None = None) -> _Estimate:
    sol, _ = _ratio_fit(rows, n_mat, settings, None if warm is None else warm.x_ratio)
    x = sol.x
    log_rho = x[2:]
    per, (a, b) = _es_interval(log_rho, log_bounds, constrained)
    if a <= b + 1e-9:
        les = 0.5 * (a + b)
        log_eo = np.where(constrained, log_rho + les, 0.5 * (log_bounds[:, 0] + log_bounds[:, 1]))
        return _Estimate(les, math.exp(x[0]), x[1], log_eo, log_rho, log_rho, (a, b), False, float(sol.cost),
                         x, None)
    # the ranges conflict: the paper's bounded joint fit (e_o inside ranges, e_s free)
    if warm is not None and warm.x_joint is not None:
        starts = [warm.x_joint[-1]]
    else:
        starts = sorted({*per.ravel().tolist(), float(per.mean())})
    jsol, _ = _joint_fit(rows, n_mat, log_bounds, settings, x, starts)
    jx = jsol.x
    les = jx[-1]
    return _Estimate(les, math.exp(jx[0]), jx[1], jx[2:2 + n_mat], jx[2:2 + n_mat] - les, log_rho, (a, b), True,
                     float(jsol.cost), x, jx)


# ------------------------------------------------------------------ result
@dataclass(frozen=True)
class Parameter:
    """An estimate with its uncertainty.

    ``std_error`` and the 95 % interval ``ci95`` come from the bootstrap (or
    the Jacobian); for a set-identified e_s the interval also spans every
    value that fits equally well. ``at_bound``: ``"lower"``/``"upper"`` when
    the estimate sits on a bound of its search range.
    """

    value: float
    std_error: float
    ci95: tuple[float, float]
    unit: str = ""
    at_bound: str | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"value": self.value, "std_error": self.std_error, "ci95": list(self.ci95), "unit": self.unit,
                "at_bound": self.at_bound}


@dataclass(frozen=True)
class MaterialFit:
    """What the fit says about one material."""

    name: str
    range: MaterialRange
    n_trials: int
    object_temp: str
    effusivity: Parameter | None
    ratio: Parameter | None
    es_interval: tuple[float, float] | None
    rms_c: float

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name, "range": [self.range.e_min, self.range.e_max], "range_source": self.range.source,
            "n_trials": self.n_trials, "object_temp": self.object_temp,
            "effusivity": None if self.effusivity is None else self.effusivity.to_dict(),
            "ratio_eo_over_es": None if self.ratio is None else self.ratio.to_dict(),
            "es_interval": None if self.es_interval is None else list(self.es_interval),
            "rms_c": self.rms_c,
        }


@dataclass(frozen=True)
class CalibrationResult:
    """Everything :func:`fit_sensor` found (see :meth:`to_dict` for the JSON form)."""

    effusivity: Parameter
    diffusivity_m2_s: Parameter
    tau_s: Parameter
    time_offset_s: Parameter
    materials: tuple[MaterialFit, ...]
    depth_m: float
    sample_rate_hz: float
    noise_c: float
    rms_c: float
    n_trials: int
    n_samples: int
    identification: str           # "interval" (set-identified) or "conflict"
    es_interval: tuple[float, float] | None
    notes: tuple[str, ...]
    settings: FitSettings
    uncertainty_method: str
    profile_es: np.ndarray = field(default_factory=lambda: np.zeros(0))
    profile_rms_c: np.ndarray = field(default_factory=lambda: np.zeros(0))
    es_profile_interval: tuple[float, float] | None = None
    design_effect: float = 1.0
    curves: Mapping[str, Any] = field(default_factory=dict, repr=False)

    def sensor(self, name: str = "calibrated", provenance: Mapping[str, Any] | None = None):
        """The calibrated :class:`~designkit.sensor.Sensor` (what ``--sensor FILE`` reads)."""
        from ..sensor import Sensor

        prov = {
            "method": "designkit calibrate fit: paper appendix model, least squares in log parameters",
            "time_offset_s": self.time_offset_s.value,
            "effusivity_std_error": self.effusivity.std_error,
            "effusivity_ci95": [float(v) for v in self.effusivity.ci95],
            "diffusivity_ci95_m2_s": [float(v) for v in self.diffusivity_m2_s.ci95],
            "tau_std_error_s": self.tau_s.std_error,
            "identification": self.identification,
            "uncertainty": self.uncertainty_method,
            "rms_c": self.rms_c,
            "materials": {m.name: {"range": [m.range.e_min, m.range.e_max],
                                   "effusivity": None if m.effusivity is None else m.effusivity.value,
                                   "n_trials": m.n_trials, "rms_c": m.rms_c} for m in self.materials},
            "notes": list(self.notes),
        }
        prov.update(dict(provenance or {}))
        record = {"name": "semi-infinite", "params": {}, "time_offset_s": float(self.time_offset_s.value),
                  "contact_spread": None,
                  "object_temperature": {m.name: str(m.object_temp) for m in self.materials},
                  "candidate": "semi-infinite (paper appendix fit)"}
        return Sensor(effusivity=self.effusivity.value, diffusivity_m2_s=self.diffusivity_m2_s.value,
                      depth_m=self.depth_m, sample_rate_hz=self.sample_rate_hz, name=name,
                      noise_c=self.noise_c, provenance=_plain(prov), model=record)

    def to_dict(self) -> dict[str, Any]:
        return {
            "effusivity": self.effusivity.to_dict(),
            "diffusivity_m2_s": self.diffusivity_m2_s.to_dict(),
            "tau_s": self.tau_s.to_dict(),
            "time_offset_s": self.time_offset_s.to_dict(),
            "depth_m": self.depth_m,
            "sample_rate_hz": self.sample_rate_hz,
            "noise_c": self.noise_c,
            "rms_c": self.rms_c,
            "n_trials": self.n_trials,
            "n_samples": self.n_samples,
            "identification": self.identification,
            "es_interval": None if self.es_interval is None else list(self.es_interval),
            "materials": [m.to_dict() for m in self.materials],
            "notes": list(self.notes),
            "uncertainty_method": self.uncertainty_method,
            "profile": {"effusivity": self.profile_es, "rms_c": self.profile_rms_c,
                        "interval": None if self.es_profile_interval is None else list(self.es_profile_interval),
                        "design_effect": self.design_effect},
            "paper": {"effusivity": PAPER_E_S, "diffusivity_m2_s": PAPER_ALPHA_S},
        }


def _plain(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def _param(value, boot: np.ndarray | None, *, unit: str, se_fallback: float = math.nan,
           ci: tuple[float, float] | None = None, at_bound: str | None = None) -> Parameter:
    if boot is not None and boot.size >= 2:
        se = float(np.std(boot, ddof=1))
        lo, hi = (float(v) for v in np.percentile(boot, [2.5, 97.5]))
    else:
        se = se_fallback
        lo, hi = (value - 1.96 * se, value + 1.96 * se) if math.isfinite(se) else (math.nan, math.nan)
    if ci is not None:
        lo, hi = min(lo, ci[0]) if math.isfinite(lo) else ci[0], max(hi, ci[1]) if math.isfinite(hi) else ci[1]
    return Parameter(float(value), se, (lo, hi), unit, at_bound)


def _sandwich(J: np.ndarray, r: np.ndarray, clusters: np.ndarray, free: np.ndarray) -> np.ndarray:
    """Cluster-robust covariance (trials as clusters) of the free parameters."""
    Jf = J[:, free]
    bread = np.linalg.pinv(Jf.T @ Jf)
    scores = np.zeros((int(clusters.max()) + 1, Jf.shape[1]))
    np.add.at(scores, clusters, Jf * r[:, None])
    meat = scores.T @ scores
    cov = np.full((J.shape[1], J.shape[1]), np.nan)
    cov[np.ix_(free, free)] = bread @ meat @ bread
    return cov


# --------------------------------------------------------------------- fit
def _prepare(trials: Sequence[Trial], names: Sequence[str], object_temps: Mapping[str, str | float],
             settings: FitSettings, pre_until_s: float = 0.0) -> tuple[_Data, dict[str, str], list[str], float, float]:
    """Cut the fit windows, take initial temperatures, decide each material's object temperature."""
    idx = {n: k for k, n in enumerate(names)}
    ts, ys, ids, mats, ts0s, tos, frees = [], [], [], [], [], [], []
    modes: dict[str, str] = {}
    ssr_total, dof_total = 0.0, 0
    rates = []
    moved: dict[str, list[float]] = {n: [] for n in names}
    pre_stats = [_pre_stats(tr, settings.baseline, pre_until_s) for tr in trials]
    for tr, (_, to, _, _) in zip(trials, pre_stats):
        post = tr.time_s >= 0
        obj = tr.object_c[post]
        if np.isfinite(to) and np.isfinite(obj).any():
            moved[tr.material].append(float(np.nanmax(np.abs(obj - to))))
    notes = []
    for n in names:
        mode = object_temps.get(n)
        if mode is None:
            if not moved[n]:
                raise InputError(f"trials of {n} have no passive (object) channel: give --object-temp "
                                 f"{n}=DEGC (the object's temperature) or {n}=free")
            shift = float(np.median(moved[n]))
            if shift > settings.moving_passive_c:
                mode = "free"
                notes.append(f"{n}: the passive channel moves {shift:.1f} °C during contact, so the object is "
                             f"not at room temperature and its temperature is unknown: fitted free per trial "
                             f"({n} informs tau and the time offset only; --object-temp {n}=passive-end uses the "
                             f"passive reading at the end instead)")
            else:
                mode = "passive"
        modes[n] = mode if isinstance(mode, str) else f"{mode:g} °C"
        object_temps = {**object_temps, n: mode}
    for i, (tr, (ts0, to, ssr, dof)) in enumerate(zip(trials, pre_stats)):
        mode = object_temps[tr.material]
        lo = settings.fit_from_s
        hi = settings.fit_to_s if settings.fit_to_s is not None else math.inf
        rel = tr.meta.get("release_s") if isinstance(tr.meta, Mapping) else None
        if rel is not None and settings.fit_to_s is None:
            hi = min(hi, float(rel))
        sel = (tr.time_s >= lo) & (tr.time_s <= hi) & np.isfinite(tr.sensor_c)
        if sel.sum() < 10:
            raise InputError(f"trial {tr.source}: fewer than 10 samples in the fit window [{lo:g}, {hi:g}] s")
        if mode == "passive":
            if not math.isfinite(to):
                raise InputError(f"trial {tr.source} has no passive reading before contact: give --object-temp "
                                 f"{tr.material}=DEGC")
            obj = to
        elif mode == "passive-end":
            o = tr.object_c[sel & np.isfinite(tr.object_c)]
            if o.size == 0:
                raise InputError(f"trial {tr.source} has no passive reading in contact for passive-end")
            obj = float(np.mean(o[-max(1, o.size // 50):]))
        elif mode == "free":
            obj = math.nan
        else:
            obj = float(mode)
        ts.append(tr.time_s[sel])
        ys.append(tr.sensor_c[sel])
        ids.append(np.full(int(sel.sum()), i))
        mats.append(idx[tr.material])
        ts0s.append(ts0)
        tos.append(obj)
        frees.append(mode == "free")
        ssr_total += ssr
        dof_total += dof
        rates.append(1.0 / float(np.median(np.diff(tr.time_s))))
    lens = np.array([a.size for a in ts])
    data = _Data(np.concatenate(ts), np.concatenate(ys), np.concatenate(ids),
                 np.concatenate([[0], np.cumsum(lens)]), np.array(mats), np.array(ts0s), np.array(tos),
                 np.array(frees), tuple(names))
    noise = math.sqrt(ssr_total / dof_total) if dof_total > 0 else math.nan
    return data, modes, notes, noise, float(np.median(rates))


def _design_effect(prob: "_Problem", x: np.ndarray, clusters: np.ndarray) -> float:
    """How much trial-correlated residuals inflate variances: max over parameters of
    (cluster-robust variance) / (independent-noise variance), at least 1."""
    J = prob.jac(x)
    r = prob.residuals(x)
    free = ~prob.fixed & (np.abs(x - prob.lo) > 1e-6) & (np.abs(x - prob.hi) > 1e-6)
    if not free.any():
        return 1.0
    s2 = float(r @ r) / max(r.size - int(free.sum()), 1)
    naive = s2 * np.diag(np.linalg.pinv(J[:, free].T @ J[:, free]))
    robust = np.diag(_sandwich(J, r, clusters, free))[free]
    ok = naive > 0
    return float(max(1.0, np.max(robust[ok] / naive[ok]))) if ok.any() else 1.0


@dataclass(frozen=True)
class _ProfilePoint:
    log_es: float
    ssr: float
    log_eo: np.ndarray


def _profile(rows: _Rows, n_mat: int, log_bounds: np.ndarray, settings: FitSettings, best: _Estimate,
             threshold: float, progress) -> tuple[list[_ProfilePoint], tuple[float, float], tuple[bool, bool]]:
    """Residual profile over log e_s, walking out from the estimate until the sum of squares
    exceeds its minimum by ``threshold`` on each side (or the walk ends).

    Returns the points, the interval where the profile stays under the threshold
    (interpolated), and whether each end was reached (False: open-ended).
    """
    step = 0.05
    max_steps = max(1, settings.profile_points)
    les_lo, les_hi = math.log(settings.es_bounds[0]), math.log(settings.es_bounds[1])

    def at(les, x_start):
        pp = _Problem(rows, n_mat, log_es=les, eo_bounds=log_bounds, settings=settings)
        sol = pp.solve(x_start)
        return 2.0 * sol.cost + rows.const, sol.x

    def start_for(les):
        return np.concatenate([best.x_ratio[:2], np.clip(best.log_rho_free + les, log_bounds[:, 0],
                                                         log_bounds[:, 1])])

    ssr0, x0 = at(best.log_es, start_for(best.log_es))
    points = [_ProfilePoint(best.log_es, ssr0, x0[2:])]
    ends = []
    reached = []
    for direction in (-1.0, 1.0):
        les, x_prev, prev = best.log_es, x0, points[0]
        end, hit = None, False
        for _ in range(max_steps):
            les_next = les + direction * step
            if not les_lo <= les_next <= les_hi:
                break
            cand = [start_for(les_next), np.concatenate([x_prev[:2], np.clip(x_prev[2:] + direction * step,
                                                                              log_bounds[:, 0], log_bounds[:, 1])])]
            ssr, x = min((at(les_next, c) for c in cand), key=lambda v: v[0])
            pt = _ProfilePoint(les_next, ssr, x[2:])
            points.append(pt)
            if progress:
                progress()
            if ssr > ssr0 + threshold:  # bisect for the crossing
                inside, outside = prev.log_es, les_next
                x_in = x_prev
                for _ in range(6):
                    mid = 0.5 * (inside + outside)
                    ssr_mid, x_mid = min((at(mid, c) for c in (start_for(mid), x_in)), key=lambda v: v[0])
                    if ssr_mid > ssr0 + threshold:
                        outside = mid
                    else:
                        inside, x_in = mid, x_mid
                        points.append(_ProfilePoint(mid, ssr_mid, x_mid[2:]))
                end, hit = 0.5 * (inside + outside), True
                break
            les, x_prev, prev = les_next, x, pt
        ends.append(end if end is not None else les)
        reached.append(hit)
    points.sort(key=lambda p: p.log_es)
    return points, (ends[0], ends[1]), (reached[0], reached[1])


def fit_sensor(trials: Sequence[Trial], ranges: Mapping[str, MaterialRange], *,
               object_temps: Mapping[str, str | float] | None = None,
               settings: FitSettings = FitSettings(), progress=None) -> CalibrationResult:
    """Identify e_s, alpha_s (through tau at fixed depth), each e_o and the time offset.

    Parameters
    ----------
    trials : sequence of Trial
        Recorded touches (time 0 = detected contact onset, samples before it).
    ranges : mapping of material name -> MaterialRange
        Effusivity range of every material in ``trials``.
    object_temps : mapping, optional
        Per material: ``"passive"`` (pre-contact passive channel; the default
        when the passive channel stays put), ``"passive-end"``, ``"free"``, or
        a temperature [degC].
    settings : FitSettings
    progress : callable(int, int), optional
        Called with (done, total) during the bootstrap and the profile.

    Returns
    -------
    CalibrationResult

    Notes
    -----
    Uncertainties. tau, alpha_s, the offset and the ratios e_o/e_s: bootstrap
    percentiles over trials (or the cluster-robust Jacobian). e_s (and each
    e_o): the 95 % interval spans the bootstrap spread, the values that fit
    equally well (set-identified case) and the profile interval, where the
    residual sum of squares stays within ``3.84 s^2 k`` of its minimum
    (``s^2`` the residual variance, ``k >= 1`` the design effect of
    trial-correlated residuals, so the interval widens when the model misfits
    whole trials); its standard error is a quarter of that interval's width.
    """
    if not trials:
        raise InputError("no trials to fit")
    names = sorted({tr.material for tr in trials})
    missing = [n for n in names if n not in ranges]
    if missing:
        raise InputError(f"no effusivity range for {', '.join(missing)}")
    counts = {n: sum(tr.material == n for tr in trials) for n in names}
    data, modes, notes, noise, fs = _prepare(trials, names, dict(object_temps or {}), settings)
    n_mat = len(names)
    log_bounds = np.log(np.array([[ranges[n].e_min, ranges[n].e_max] for n in names]))
    constrained = np.array([modes[n] != "free" for n in names])
    if not constrained.any():
        raise InputError("no material constrains e_s: every material has a free object temperature "
                         "(give --object-temp NAME=passive or a temperature for at least one)")

    rows = _rows(data)
    best = _estimate(rows, n_mat, log_bounds, constrained, settings)
    if best.off < -0.5 / fs:
        # heat flows before the detected onset: take the initial temperatures from before it and refit
        data, modes, notes, noise, fs = _prepare(trials, names, dict(object_temps or {}), settings, best.off)
        rows = _rows(data)
        best = _estimate(rows, n_mat, log_bounds, constrained, settings, warm=best)
        notes.append(f"heat starts to flow {-best.off:.3f} s before the detected onset: initial temperatures "
                     "are taken from the samples before that")
    full = _rows(data, compress=False)
    total = settings.bootstrap + 2 * settings.profile_points
    done = [0]

    def tick():
        done[0] += 1
        if progress:
            progress(min(done[0], total), total)

    # ------------------------------------------------------ bootstrap
    boot: list[_Estimate] = []
    if settings.bootstrap:
        rng = as_generator(settings.seed)
        groups = [np.flatnonzero(data.mat == k) for k in range(n_mat)]
        for _ in range(settings.bootstrap):
            idx = np.concatenate([rng.choice(g, size=g.size, replace=True) for g in groups])
            mult = np.bincount(idx, minlength=data.n_trials).astype(np.float64)
            try:
                boot.append(_estimate(_rows(data, mult), n_mat, log_bounds, constrained, settings, warm=best))
            except (InputError, np.linalg.LinAlgError):  # pragma: no cover - degenerate resample
                pass
            tick()
        method = f"bootstrap over trials ({len(boot)} replicates, resampled within each material)"
    else:
        method = "Jacobian (cluster-robust sandwich, trials as clusters)"

    def arr(f):
        return np.array([f(b) for b in boot]) if boot else None

    ratio_full = _Problem(full, n_mat, log_es=0.0, eo_bounds=None, settings=settings)
    cov = _sandwich(ratio_full.jac(best.x_ratio), ratio_full.residuals(best.x_ratio), full.trial,
                    ~ratio_full.fixed)
    sd = np.sqrt(np.clip(np.diag(cov), 0, None))
    if best.x_joint is None:
        r = ratio_full.residuals(best.x_ratio)
    else:
        r = _Problem(full, n_mat, log_es=None, eo_bounds=log_bounds, settings=settings).residuals(best.x_joint)

    # ------------------------------------------------------ profile over e_s
    ssr_min = float(r @ r)
    n_par = 2 + n_mat + 1
    s2 = ssr_min / max(full.t.size - n_par, 1)
    k_design = _design_effect(ratio_full, best.x_ratio, full.trial)
    threshold = 3.84 * s2 * k_design
    points: list[_ProfilePoint] = []
    prof_iv: tuple[float, float] | None = None
    reached = (True, True)
    if settings.profile_points:
        points, (plo, phi), reached = _profile(rows, n_mat, log_bounds, settings, best, threshold, tick)
        prof_iv = (math.exp(plo), math.exp(phi))

    # ------------------------------------------------------ parameters
    lo_tau, hi_tau = settings.tau_bounds_s
    at_tau = "lower" if best.tau <= lo_tau * (1 + 1e-6) else "upper" if best.tau >= hi_tau * (1 - 1e-6) else None
    tau_p = _param(best.tau, arr(lambda b: b.tau), unit="s", se_fallback=best.tau * sd[0], at_bound=at_tau)
    x2 = settings.depth_m ** 2 / 4.0
    alpha_p = _param(x2 / best.tau, arr(lambda b: x2 / b.tau), unit="m^2/s", se_fallback=x2 / best.tau * sd[0],
                     at_bound={"lower": "upper", "upper": "lower"}.get(at_tau or "", None))
    olo, ohi = settings.offset_bounds_s
    at_off = "lower" if best.off <= olo + 1e-6 else "upper" if best.off >= ohi - 1e-6 else None
    off_p = _param(best.off, arr(lambda b: b.off), unit="s", se_fallback=sd[1], at_bound=at_off)

    es = math.exp(best.log_es)
    es_lo_b, es_hi_b = settings.es_bounds
    at_es = "lower" if es <= es_lo_b * (1 + 1e-6) else "upper" if es >= es_hi_b * (1 - 1e-6) else None
    lo_parts, hi_parts = [es], [es]
    if boot:
        lo_parts.append(float(np.percentile(np.exp([b.interval[0] if not b.conflict else b.log_es
                                                    for b in boot]), 2.5)))
        hi_parts.append(float(np.percentile(np.exp([b.interval[1] if not b.conflict else b.log_es
                                                    for b in boot]), 97.5)))
    elif best.conflict:
        jprob = _Problem(full, n_mat, log_es=None, eo_bounds=log_bounds, settings=settings)
        held = np.zeros(2 + n_mat + 1, dtype=bool)
        held[2:2 + n_mat] = (np.abs(best.x_joint[2:2 + n_mat] - log_bounds[:, 0]) < 1e-7) | \
                            (np.abs(best.x_joint[2:2 + n_mat] - log_bounds[:, 1]) < 1e-7)
        jcov = _sandwich(jprob.jac(best.x_joint), jprob.residuals(best.x_joint), full.trial, ~(held | jprob.fixed))
        if np.isfinite(jcov[-1, -1]):
            half = 1.96 * math.sqrt(max(jcov[-1, -1], 0.0))
            lo_parts.append(es * math.exp(-half))
            hi_parts.append(es * math.exp(half))
    if not best.conflict:
        lo_parts.append(math.exp(best.interval[0]))
        hi_parts.append(math.exp(best.interval[1]))
    if prof_iv is not None:
        lo_parts.append(prof_iv[0])
        hi_parts.append(prof_iv[1])
    es_ci = (min(lo_parts), max(hi_parts))
    es_p = Parameter(es, (es_ci[1] - es_ci[0]) / (2 * 1.96), es_ci, "J s^-1/2 K^-1 m^-2", at_es)

    if not best.conflict:
        ident = "interval"
        es_interval: tuple[float, float] | None = (math.exp(best.interval[0]), math.exp(best.interval[1]))
        notes.insert(0, f"e_s is set-identified: every value in [{es_interval[0]:.4g}, {es_interval[1]:.4g}] "
                        "fits the data equally well (the amplitudes fix only e_o/e_s; e_s comes from where the "
                        "materials' ranges overlap); reported: the geometric centre")
    else:
        ident = "conflict"
        es_interval = None
        per, _ = _es_interval(best.log_rho_free, log_bounds, constrained)
        hit = []
        for k, n in enumerate(names):
            if constrained[k] and abs(best.log_eo[k] - log_bounds[k, 0]) < 1e-6:
                hit.append(f"{n} at its lower bound")
            elif constrained[k] and abs(best.log_eo[k] - log_bounds[k, 1]) < 1e-6:
                hit.append(f"{n} at its upper bound")
        allowed = []
        for n, k, (lo, hi) in zip([n for k, n in enumerate(names) if constrained[k]],
                                  np.flatnonzero(constrained), per):
            if best.log_rho_free[k] >= _LOG_RHO_LIMIT - 1e-6:
                allowed.append(f"{n} asks for the full temperature difference (e_o/e_s -> infinity)")
            else:
                allowed.append(f"{n} alone allows e_s in [{math.exp(lo):.4g}, {math.exp(hi):.4g}]")
        notes.insert(0, "the ranges conflict with the data under this model, no e_s keeps every material in range ("
                        + "; ".join(allowed) + f"): the bounded fit compromises with {', '.join(hit) or 'no bound hit'}"
                        ", so e_s reflects the ranges and the model's misfit more than the noise")
    if prof_iv is not None:
        open_ends = [side for side, ok in zip(("low", "high"), reached) if not ok]
        notes.append(f"residual profile over e_s: within the noise (k = {k_design:.3g} design effect of "
                     f"trial-correlated residuals) for e_s in [{prof_iv[0]:.4g}, {prof_iv[1]:.4g}]"
                     + (f" (open at the {' and '.join(open_ends)} end: the walk stopped)" if open_ends else ""))
    notes.insert(0, f"only tau = x^2/(4 alpha_s) is identified by the curve shape; alpha_s = "
                    f"{x2 / best.tau:.4g} m^2/s follows from the fixed depth x = {settings.depth_m * 1e6:g} um "
                    "(another depth x' gives alpha_s (x'/x)^2 times this, with the same fit)")

    # ------------------------------------------------------ per material
    within: list[_ProfilePoint] = []
    if points:
        ssr_floor = min(p.ssr for p in points)
        within = [p for p in points if p.ssr <= ssr_floor + threshold]
    mats: list[MaterialFit] = []
    for k, n in enumerate(names):
        sel = full.mat == k
        rms = float(np.sqrt(np.mean(r[sel] ** 2)))
        if not constrained[k]:
            mats.append(MaterialFit(n, ranges[n], counts[n], modes[n], None, None, None, rms))
            continue
        lr = best.log_rho_free[k]
        at_limit = abs(lr) >= _LOG_RHO_LIMIT - 1e-6
        rho_boot = arr(lambda bb: bb.log_rho_free[k])
        if rho_boot is not None:
            lo_r, hi_r = np.exp(np.percentile(rho_boot, [2.5, 97.5]))
            se_r = math.exp(lr) * float(np.std(rho_boot, ddof=1))
        else:
            se_r = math.exp(lr) * sd[2 + k]
            lo_r, hi_r = math.exp(lr - 1.96 * sd[2 + k]), math.exp(lr + 1.96 * sd[2 + k])
        rho_p = Parameter(math.exp(lr), se_r, (float(lo_r), float(hi_r)), "",
                          ("upper" if lr > 0 else "lower") if at_limit else None)
        eo = math.exp(best.log_eo[k])
        at = "lower" if abs(best.log_eo[k] - log_bounds[k, 0]) < 1e-6 else \
            "upper" if abs(best.log_eo[k] - log_bounds[k, 1]) < 1e-6 else None
        lo_e, hi_e = [eo], [eo]
        eo_boot = arr(lambda bb: math.exp(bb.log_eo[k]))
        if eo_boot is not None:
            lo_e.append(float(np.percentile(eo_boot, 2.5)))
            hi_e.append(float(np.percentile(eo_boot, 97.5)))
        if not best.conflict:  # every e_o = rho * e_s with e_s in its interval
            lo_e.append(max(ranges[n].e_min, es_ci[0] * math.exp(lr)))
            hi_e.append(min(ranges[n].e_max, es_ci[1] * math.exp(lr)))
        for p in within:
            lo_e.append(math.exp(p.log_eo[k]))
            hi_e.append(math.exp(p.log_eo[k]))
        eo_ci = (min(lo_e), max(hi_e))
        eo_p = Parameter(eo, (eo_ci[1] - eo_ci[0]) / (2 * 1.96), eo_ci, "J s^-1/2 K^-1 m^-2", at)
        per_k = (ranges[n].e_min / math.exp(lr), ranges[n].e_max / math.exp(lr))
        mats.append(MaterialFit(n, ranges[n], counts[n], modes[n], eo_p, rho_p, per_k, rms))

    prof_es = np.exp([p.log_es for p in points]) if points else np.zeros(0)
    prof_rms = np.sqrt(np.maximum([p.ssr for p in points], 0.0) / rows.n_samples) if points else np.zeros(0)
    curves = {"rows": full, "residuals": r, "names": names,
              "profile_threshold_rms_c": math.sqrt((ssr_min + threshold) / rows.n_samples)}
    return CalibrationResult(
        effusivity=es_p, diffusivity_m2_s=alpha_p, tau_s=tau_p, time_offset_s=off_p, materials=tuple(mats),
        depth_m=settings.depth_m, sample_rate_hz=fs, noise_c=noise,
        rms_c=float(np.sqrt(np.mean(r ** 2))), n_trials=data.n_trials, n_samples=int(full.t.size),
        identification=ident, es_interval=es_interval, notes=tuple(notes), settings=settings,
        uncertainty_method=method, profile_es=prof_es, profile_rms_c=prof_rms,
        es_profile_interval=prof_iv, design_effect=k_design, curves=curves)


def model_curves(result: CalibrationResult) -> dict[str, Any]:
    """Per material: time grid, mean data, mean model (for plots)."""
    rows: _Rows = result.curves["rows"]
    r = result.curves["residuals"]
    out = {}
    for k, n in enumerate(result.curves["names"]):
        sel = rows.mat == k
        t = np.round(rows.t[sel], 6)
        grid, inv = np.unique(t, return_inverse=True)
        # rows are c*amp*g - target; known amplitude: c = To - Ts0, target = T - Ts0, so target/c is the
        # fraction of the way to the object's temperature (model: w g); free amplitude: c = 1 (degC)
        c = rows.c[sel]
        ok = np.abs(c) > 0
        c = np.where(ok, c, 1.0)
        y = np.bincount(inv, weights=np.where(ok, rows.target[sel] / c, 0.0)) / np.bincount(inv)
        fitted = np.bincount(inv, weights=np.where(ok, (r + rows.target)[sel] / c, 0.0)) / np.bincount(inv)
        res = np.bincount(inv, weights=r[sel]) / np.bincount(inv)  # [degC]
        cnt = np.bincount(inv)
        keep = cnt >= max(1, cnt.max() // 2)
        out[n] = {"time_s": grid[keep], "data_c": y[keep], "model_c": fitted[keep], "residual_c": res[keep]}
    return out


def plot_fit(result: CalibrationResult, path: Path) -> Path:
    """Figure: mean data and model per material, mean residuals, residual profile over e_s."""
    from ..figures import pyplot

    plt = pyplot()
    curves = model_curves(result)
    fig, axes = plt.subplots(1, 3, figsize=(13.5, 4.0), constrained_layout=True)
    for k, (n, c) in enumerate(curves.items()):
        # the data light and wide, the model dark and dashed on top: the model stays visible where it fits
        axes[0].plot(c["time_s"], c["data_c"], color=f"C{k}", lw=3.0, alpha=0.45, label=f"{n} (mean of trials)")
        axes[0].plot(c["time_s"], c["model_c"], color="k", lw=1.2, ls=(0, (4, 2)), zorder=4,
                     label="fitted model" if k == 0 else None)
        axes[1].plot(c["time_s"], c["residual_c"], color=f"C{k}", lw=1.0, label=n)
    axes[0].set_xlabel("time after detected onset [s]")
    axes[0].set_ylabel("(T - Ts0) / (To - Ts0)\n(free-To materials: T - Ts0 [°C])")
    axes[0].set_title("data (wide) and fitted model (dashed)")
    axes[0].legend(fontsize=7)
    axes[1].axhline(0, color="k", lw=0.5)
    axes[1].set_xlabel("time after detected onset [s]")
    axes[1].set_ylabel("mean residual (model - data) [°C]")
    axes[1].legend(fontsize=7)
    ax = axes[2]
    if result.profile_es.size:
        ax.semilogx(result.profile_es, result.profile_rms_c, "o-", ms=3)
        if result.es_interval is not None:
            ax.axvspan(*result.es_interval, color="C2", alpha=0.2, label="equally good e_s")
        if "profile_threshold_rms_c" in result.curves:
            ax.axhline(result.curves["profile_threshold_rms_c"], color="C1", lw=0.8, ls="--",
                       label="within the noise below this")
        from .._numbers import sig

        ax.axvline(result.effusivity.value, color="C3", lw=1, label=f"e_s = {sig(result.effusivity.value)}")
        ax.axvline(PAPER_E_S, color="k", lw=0.8, ls=":", label=f"paper {PAPER_E_S:g}")
        ax.legend(fontsize=7)
    ax.set_xlabel("sensor effusivity e_s [J s^-1/2 K^-1 m^-2]")
    ax.set_ylabel("best residual RMS at this e_s [°C]")
    ax.set_title("profile over e_s (other parameters refitted)", fontsize=9)
    for a in axes:
        a.grid(alpha=0.3)
    from ..figures import save_figure

    return save_figure(fig, path, dpi=110)


# --------------------------------------------------------------- checks
@dataclass(frozen=True)
class CalibrationProblem:
    """Something about a calibration a user must hear before trusting (or writing) its sensor file.

    Attributes
    ----------
    kind : str
        ``"conflict"``, ``"mislabelled"``, ``"wiring"``.
    message : str
        What is wrong, with the numbers that show it.
    suggestion : str
        What to do about it.
    fatal : bool
        The result is unusable: no sensor file is written (unless forced) and the exit is non-zero.
    """

    kind: str
    message: str
    suggestion: str
    fatal: bool = True

    def text(self) -> str:
        return f"{self.message}. {self.suggestion}"


def _normalized_drop(tr: Trial, at_s: float = 2.0) -> float:
    """(Ts0 - T(at_s)) / (Ts0 - To) of one touch (raw drop [degC] without a passive channel); NaN if too short."""
    pre = tr.time_s < 0
    late = np.abs(tr.time_s - at_s) <= 0.25
    if pre.sum() < 3 or not late.any():
        return math.nan
    ts0 = float(np.mean(tr.sensor_c[pre]))
    drop = ts0 - float(np.mean(tr.sensor_c[late]))
    obj = tr.object_c[pre]
    if np.isfinite(obj).any():
        diff = ts0 - float(np.nanmean(obj))
        return drop / diff if abs(diff) > 0.5 else math.nan
    return drop


def check_calibration(result: "CalibrationResult | None", trials: Sequence[Trial]) -> list[CalibrationProblem]:
    """What makes a calibration unusable or suspect, each with a suggestion.

    * **wiring**: the heated sensor reads colder than the object before contact in most touches (a
      thermistor on the wrong side of its divider reads a plausible temperature mirrored about the
      divider's midpoint);
    * **mislabelled**: a touch whose normalized response at 2 s (``(Ts0 - T) / (Ts0 - To)``) lies
      within 2 robust SDs of another material's median and beyond 5 of its own's (touches recorded
      while another sample was under the sensor);
    * **conflict**: no e_s keeps every material inside its effusivity range (``result``);
    * **no-response**: in most touches the sensor's reading moves by less than 5 pre-contact noise SDs
      (and 0.05 °C) over the contact: no heat flowed (the heater off, sensor and object at one
      temperature, a disconnected channel), so the touches hold nothing about e_s, whatever a fit says.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(-200, 801) / 200.0
    >>> warming = np.where(t < 0, 20.0, 20.0 + 2.0 * (1.0 - np.exp(-np.maximum(t, 0.0))))
    >>> cold = Trial(t, warming, np.full(t.size, 25.0), np.zeros(t.size), "wood")
    >>> [p.kind for p in check_calibration(None, [cold, cold])]
    ['wiring']
    >>> flat = Trial(t, np.full(t.size, 35.0), np.full(t.size, 25.0), np.zeros(t.size), "wood")
    >>> [p.kind for p in check_calibration(None, [flat, flat])]
    ['no-response']
    """
    out: list[CalibrationProblem] = []
    moved = []  # (largest move over the contact, pre-contact noise SD, sensor - object before contact) [degC]
    for tr in trials:
        pre, post = tr.time_s < 0, tr.time_s >= 0
        if pre.sum() >= 3 and post.sum() >= 3:
            ts0 = float(np.mean(tr.sensor_c[pre]))
            obj = tr.object_c[pre]
            diff = ts0 - float(np.nanmean(obj)) if np.isfinite(obj).any() else math.nan
            moved.append((float(np.max(np.abs(tr.sensor_c[post] - ts0))), float(np.std(tr.sensor_c[pre])), diff))
    still = [m for m in moved if m[0] < max(5.0 * m[1], 0.05)]
    if moved and len(still) > len(moved) / 2:
        diffs = [m[2] for m in still if math.isfinite(m[2])]
        why = (f"; sensor minus object before contact {np.mean(diffs):+.2f} °C on average" if diffs else "")
        out.append(CalibrationProblem(
            "no-response", f"the sensor's reading does not respond to contact in {len(still)} of {len(moved)} "
                           f"touches (it moves by at most {max(m[0] for m in still):.3g} °C, against a pre-contact "
                           f"noise of {np.mean([m[1] for m in still]):.2g} °C{why}): no heat flowed, so these "
                           "touches say nothing about the sensor",
            "Heat the sensor above the object (its set point), check that the thermistor channel is "
            "connected and that the object is under the sensor when a touch is recorded, then record again"))
    cold = []
    for tr in trials:
        pre = tr.time_s < 0
        obj = tr.object_c[pre]
        if pre.any() and np.isfinite(obj).any():
            cold.append((float(np.mean(tr.sensor_c[pre])), float(np.nanmean(obj))))
    below = [(s, o) for s, o in cold if s < o - 0.2]
    if cold and len(below) > len(cold) / 2:
        s, o = np.mean([b[0] for b in below]), np.mean([b[1] for b in below])
        out.append(CalibrationProblem(
            "wiring", f"the heated sensor reads colder than the object before contact in {len(below)} of "
                      f"{len(cold)} touches (sensor {s:.2f} °C, object {o:.2f} °C on average)",
            "A heated sensor should be the warmer one: check that each thermistor sits on the side of its "
            "divider that the profile's channel says (wired the other way, a thermistor reads a plausible "
            "but wrong temperature), and the heater's set point"))
    names = sorted({tr.material for tr in trials})
    drops = {n: [(i, _normalized_drop(tr)) for i, tr in enumerate(trials) if tr.material == n] for n in names}
    med = {n: float(np.nanmedian([d for _, d in v])) for n, v in drops.items()
           if sum(math.isfinite(d) for _, d in v) >= 2}
    # robust spread of each material's responses (1.4826 MAD, at least 0.005): materials made to look
    # alike (cold wood and metal) are not "mislabelled" just because their medians are close
    spread = {n: max(0.005, 1.4826 * float(np.nanmedian([abs(d - med[n]) for _, d in drops[n]]))) for n in med}
    if len(med) >= 2:
        odd = []
        for n, v in drops.items():
            if n not in med:
                continue
            for i, d in v:
                if not math.isfinite(d):
                    continue
                near = min(med, key=lambda m: abs(d - med[m]))
                if near != n and abs(d - med[near]) < 2.0 * spread[near] and abs(d - med[n]) > 5.0 * spread[n]:
                    odd.append(f"{Path(trials[i].source).name or f'touch {i + 1}'} ({n}, looks like {near}: "
                               f"response {d:.3g} against {med[n]:.3g} for {n} and {med[near]:.3g} for {near})")
        if odd:
            out.append(CalibrationProblem(
                "mislabelled", f"{len(odd)} touch(es) look like another material: " + "; ".join(odd[:6])
                + (" ..." if len(odd) > 6 else ""),
                "Touches recorded while another sample was under the sensor get the wrong label; record "
                "those materials again (press Enter only once the sample is in place), or delete the odd "
                "trials from the index and run 'calibrate fit' on it"))
    if result is not None and result.identification == "conflict":
        allowed = "; ".join(f"{m.name} allows e_s in [{m.es_interval[0]:.4g}, {m.es_interval[1]:.4g}]"
                            for m in result.materials if m.es_interval is not None)
        out.append(CalibrationProblem(
            "conflict", f"the materials' effusivity ranges conflict under the paper's model ({allowed}): "
                        f"e_s = {result.effusivity.value:.4g} is a compromise at the ranges' bounds, at "
                        f"{result.rms_c / result.noise_c:.0f}x the pre-contact noise",
            "Check each material's label, range (--range NAME=MIN:MAX) and object temperature "
            "(--object-temp NAME=free for an object not at room temperature); compare sensor models "
            "with 'calibrate fit --model all'; or write the file anyway with --force"))
    return out
