"""Identify any registered sensor model from recorded touches: the one identification engine.

On real touches the paper's semi-infinite model's *shape* is wrong (issue 14): its residual is
30-40 times the noise and the materials ask for conflicting e_s. This module fits any forward
model of :mod:`designkit.models` (a :class:`~designkit.calibration.candidates.Candidate`) behind
one least-squares problem; :mod:`~designkit.calibration.compare` chooses between them on touches
the fit has not seen.

Trial ``i`` of material ``m`` is fitted as ``T_i(t) = Ts0_i (1 - v_m(t)) + To_i v_m(t)`` with
``v_m = S[u(t - t_off; e_o,m / e_s, theta)]``: the model's normalized reading ``u``, the host's smoothing
``S`` when the candidate includes it, each touch's own ``Ts0_i`` in closed form (variable projection) and
its ``To_i`` from the passive thermistor, a number or the fit; the nonlinear parameters (logs of positive
quantities) by :func:`scipy.optimize.least_squares` (trust-region reflective, bounded). The fit runs at
``e_s = 1`` (only ratios to e_s are identifiable; e_s comes from the materials' handbook ranges, or a
*conflict*). Intervals: the cluster-robust CR2 sandwich, touches as clusters, with each parameter's
Bell-McCaffrey degrees of freedom (:mod:`~designkit.calibration.robust`); a parameter is *not
identified* when the Jacobian (columns scaled to unit norm) is rank-deficient along it, its interval
spans more than a factor of 10, or it sits on a search bound. Why, and what it gives on the shared
recordings: docs/sensor-models.md ("The models", "What the data can identify").
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from .._validation import InputError
from .candidates import CHAIN_PARAMS, PARAMS, Candidate, candidate
from .force import FORCE_NOISE_BAND_SD, area_weighted, contact_area, force_noise, nominal_force_profile, relative_force
from .results import IdentifiedParameter, Identification
from .robust import cluster_sandwich, t_critical
from .trials import Trial

__all__ = ["identify", "residual_series", "rms_by_material", "score"]

_LOG_RATIO_LIMIT = 12.0
_LOG_TOUCH_HC = 4.0   # search range of a touch's ln(h_c,i / h_c)
_AFFINE_OFFSET_C, _AFFINE_SLOPE = 5.0, 2.0   # search range of a passive channel's offset [degC] and slope
#: Talbot nodes of the fitted readings (12: error < 1e-8 of the temperature difference).
FIT_TALBOT_NODES = 12


# ------------------------------------------------------------ data
@dataclass(frozen=True)
class _Group:
    """Trials of one material on one time grid: they share one predicted shape."""

    material: int
    time_s: np.ndarray     # (m,)
    y: np.ndarray          # (n, m) sensor [degC]
    to: np.ndarray         # (n,) object temperature [degC] (nan: fitted per touch)
    free_to: bool
    trials: tuple[int, ...]
    affine: bool = False   # To = passive + offset + slope (passive - reference): a rig calibration of the channel
    force: np.ndarray | None = None       # (n, m) force / its plateau, each touch (force-area candidates)
    force_band: np.ndarray | None = None  # (n,) the plateau's noise band of each touch's relative force


@dataclass(frozen=True)
class _Data:
    groups: tuple[_Group, ...]
    names: tuple[str, ...]
    modes: Mapping[str, "str | float"]
    noise_c: float
    sample_rate_hz: float
    refs: Mapping[str, float] = field(default_factory=dict)   # reference passive reading of affine materials
    noise_lag: int = 1     # first lag [samples] at which the pre-contact noise's autocorrelation falls below 0.5

    @property
    def n_samples(self) -> int:
        return int(sum(g.y.size for g in self.groups))


_OBJECT_MODES = ("passive", "passive-end", "free", "passive-affine", "passive-end-affine")


def _prepare(trials: Sequence[Trial], names: Sequence[str], object_temps: Mapping[str, Any],
             moving_passive_c: float = 1.0, refs: Mapping[str, float] | None = None,
             force_area: bool = False) -> _Data:
    """Group trials by material and time grid; decide each material's object temperature."""
    if not trials:
        raise InputError("no trials to fit")
    idx = {n: k for k, n in enumerate(names)}
    modes: dict[str, str] = {}
    info = []
    rates = []
    noise, lag = _pre_contact_noise(trials)
    for tr in trials:
        to = tr.before_contact()[1]
        post = tr.object_c[tr.time_s >= 0]
        moved = float(np.nanmax(np.abs(post - to))) if math.isfinite(to) and np.isfinite(post).any() else math.nan
        info.append((to, moved))
        rates.append(1.0 / float(np.median(np.diff(tr.time_s))))
    for n in names:
        mode = object_temps.get(n)
        if mode is None:
            moves = [mv for tr, (_, mv) in zip(trials, info) if tr.material == n and math.isfinite(mv)]
            if not moves:
                raise InputError(f"trials of {n} have no passive (object) channel: give its object temperature "
                                 f"({n}=DEGC, the ambient) or {n}=free")
            mode = "free" if float(np.median(moves)) > moving_passive_c else "passive"
        if isinstance(mode, str) and mode not in _OBJECT_MODES:
            try:
                mode = float(mode)
            except ValueError:
                raise InputError(f"object temperature of {n}: {', '.join(_OBJECT_MODES)} or DEGC, got {mode!r}") \
                    from None
        modes[n] = mode if isinstance(mode, str) else float(mode)
    groups: dict[tuple[int, bytes], list[int]] = {}
    for i, tr in enumerate(trials):
        if tr.material not in idx:
            raise InputError(f"trial {tr.source}: material {tr.material!r} not among {', '.join(names)}")
        ok = np.isfinite(tr.sensor_c)
        if not ok.all():
            raise InputError(f"trial {tr.source}: the sensor channel has missing values")
        groups.setdefault((idx[tr.material], np.round(tr.time_s, 6).tobytes()), []).append(i)
    out = []
    for (k, _), members in groups.items():
        n = names[k]
        mode = modes[n]
        tos = []
        for i in members:
            if mode in ("passive-end", "passive-end-affine"):
                tr = trials[i]
                last = (tr.time_s >= tr.time_s[-1] - 1.0) & np.isfinite(tr.object_c)
                if not last.any():
                    raise InputError(f"trial {tr.source} has no passive reading at its end for {n}={mode}")
                tos.append(float(np.mean(tr.object_c[last])))
            elif mode in ("passive", "passive-affine"):
                if not math.isfinite(info[i][0]):
                    raise InputError(f"trial {trials[i].source} has no passive reading before contact: give "
                                     f"{n}=DEGC")
                tos.append(info[i][0])
            elif mode == "free":
                tos.append(math.nan)
            else:
                tos.append(float(mode))
        out.append(_Group(k, trials[members[0]].time_s.copy(), np.array([trials[i].sensor_c for i in members]),
                          np.array(tos), mode == "free", tuple(members),
                          isinstance(mode, str) and mode.endswith("-affine"),
                          np.array([relative_force(trials[i]) for i in members]) if force_area else None,
                          np.array([FORCE_NOISE_BAND_SD * force_noise(trials[i]) for i in members])
                          if force_area else None))
    ref = dict(refs or {})
    for n in names:  # the reference reading of an affine channel: the fitted touches' mean (kept for scoring)
        if isinstance(modes[n], str) and modes[n].endswith("-affine") and n not in ref:
            ref[n] = float(np.mean(np.concatenate([g.to for g in out if names[g.material] == n])))
    return _Data(tuple(out), tuple(names), modes, noise, float(np.median(rates)), ref, lag)


def _pre_contact_noise(trials: Sequence[Trial]) -> tuple[float, int]:
    """The pre-contact noise [degC] (pooled scatter about each touch's straight line over the first half of its
    samples before contact) and the first lag [samples] at which its autocorrelation falls below 0.5."""
    ssr, dof = 0.0, 0
    acf = np.zeros(41)
    for tr in trials:
        pre = tr.time_s < 0
        if pre.sum() < 3:
            raise InputError(f"trial {tr.source}: fewer than 3 samples before contact (time_s < 0)")
        t, s = tr.time_s[pre], tr.sensor_c[pre]
        early = t < t[0] + 0.5 * (t[-1] - t[0]) if t.size >= 20 else np.ones(t.size, bool)
        coef = np.polyfit(t[early], s[early], 1)
        e = s[early] - np.polyval(coef, t[early])
        ssr += float(e @ e)
        lags = min(acf.size, e.size)
        acf[:lags] += [float(e[:e.size - k] @ e[k:]) for k in range(lags)]
        dof += int(early.sum()) - 2
    below = np.flatnonzero(acf < 0.5 * acf[0]) if acf[0] > 0 else np.array([1])
    lag = int(below[0]) if below.size else acf.size
    return (math.sqrt(ssr / dof) if dof > 0 else math.nan), max(lag, 1)


# ------------------------------------------------------------ the problem
def _reading(model, t: np.ndarray, e_object: float, sensor, interp_points: int | None) -> np.ndarray:
    """The model's unsmoothed normalized reading at times ``t > 0``.

    Models solved numerically (``solved_numerically``) are evaluated at
    ``interp_points`` log-spaced times and interpolated by a cubic spline in
    ``log t`` (error below 1e-6 of the temperature difference for smooth
    readings, tested), which makes a residual evaluation cheaper.
    The Talbot inversion uses :data:`FIT_TALBOT_NODES` nodes (error below
    1e-8 of the temperature difference against 32 nodes over the fitted
    parameter range, docs/sensor-models.md; the noise is about 1e-3 of it).
    """
    if not model.solved_numerically:
        return model.conduction(t, [e_object], sensor)[0]
    if not interp_points or t.size <= 2 * interp_points:
        return model.conduction(t, [e_object], sensor, nodes=FIT_TALBOT_NODES)[0]
    from scipy.interpolate import CubicSpline

    # the grid starts at half a sample, not at the smallest t: that moves by a whole sample when the
    # contact offset crosses one, and would make the residual kink there (the optimizer then sticks)
    lo = 0.5 / float(sensor.sample_rate_hz)
    hi = max(float(t.max()), 2.0 * lo)
    grid = np.geomspace(lo, hi, interp_points)
    u = model.conduction(grid, [e_object], sensor, nodes=FIT_TALBOT_NODES)[0]
    out = CubicSpline(np.log(grid), u)(np.log(np.maximum(t, lo)))
    early = t < lo
    if early.any():
        out[early] = model.conduction(t[early], [e_object], sensor, nodes=FIT_TALBOT_NODES)[0]
    return out


class _Problem:
    """Projected residuals of one candidate on prepared data; x = [model params, t_off, log rho_m]."""

    def __init__(self, cand: Candidate, data: _Data, depth_m: float, offset_bounds_s: tuple[float, float],
                 stride: int = 1, touch_conductance: Sequence[str] = ()):
        from ..models import get_model

        self.stride = max(int(stride), 1)   # residual rows: every stride-th sample (shapes on the full grid)

        self.cand = cand
        self.data = data
        self.depth_m = depth_m
        self.params = [PARAMS[p] for p in cand.free]
        self.n_model = len(self.params)
        self.n_mat = len(data.names)
        self._get_model = get_model
        self.interp_points: int | None = 80
        #: materials whose To is the passive reading through a fitted offset and slope: x gets both
        self.affine = [k for k, n in enumerate(data.names) if isinstance(data.modes[n], str)
                       and data.modes[n].endswith("-affine")]
        lo = [p.to_x(p.lo) for p in self.params] + [offset_bounds_s[0]] + [-_LOG_RATIO_LIMIT] * self.n_mat
        hi = [p.to_x(p.hi) for p in self.params] + [offset_bounds_s[1]] + [_LOG_RATIO_LIMIT] * self.n_mat
        lo += [-_AFFINE_OFFSET_C, -_AFFINE_SLOPE] * len(self.affine)
        hi += [_AFFINE_OFFSET_C, _AFFINE_SLOPE] * len(self.affine)
        self.lo, self.hi = np.array(lo), np.array(hi)
        # a material none of whose touches has a known object temperature: its ratio still shapes the
        # curve (not for shared-shape models, where it is not identified at all)
        self.names = [p.name for p in self.params] + ["time_offset_s"] + [f"log_ratio[{n}]" for n in data.names]
        for k in self.affine:
            self.names += [f"passive_offset_c[{data.names[k]}]", f"passive_slope[{data.names[k]}]"]
        # each touch of these materials its own contact conductance: h_c,i = h_c exp(x_i), x_i last in x
        unknown = sorted(set(touch_conductance) - set(data.names))
        if unknown:
            raise InputError(f"per-touch contact conductance for {', '.join(unknown)}: not among the fitted "
                             f"materials {', '.join(data.names)}")
        if touch_conductance and "conductance_w_m2k" not in cand.free:
            raise InputError(f"per-touch contact conductance needs a candidate that fits h_c, not {cand.label}")
        self.touch_cols: dict[int, int] = {}
        self.n_global = len(self.names)
        for gi, g in enumerate(data.groups):
            if data.names[g.material] in touch_conductance:
                self.touch_cols[gi] = len(self.names)
                self.names += [f"log_hc_touch[{data.names[g.material]}#{t}]" for t in g.trials]
        n_touch = len(self.names) - self.n_global
        self.lo = np.concatenate([self.lo, np.full(n_touch, -_LOG_TOUCH_HC)])
        self.hi = np.concatenate([self.hi, np.full(n_touch, _LOG_TOUCH_HC)])

    # -------------------------------------------------------- model
    def model_and_sensor(self, x: np.ndarray):
        from ..sensor import Sensor

        vals = {p.name: p.from_x(v) for p, v in zip(self.params, x[:self.n_model])}
        for k in CHAIN_PARAMS:
            vals.pop(k, None)
        alpha = vals.pop("diffusivity_m2_s", PARAMS["diffusivity_m2_s"].start)
        sensor = Sensor(effusivity=1.0, diffusivity_m2_s=alpha, depth_m=self.depth_m,
                        sample_rate_hz=self.data.sample_rate_hz, name="identify")
        return self._get_model(self.cand.model, **{**self.cand.fixed, **vals}), sensor

    def shapes_and_drift(self, x: np.ndarray) -> list[tuple[np.ndarray, np.ndarray | None]]:
        """Per group (v, b): the normalized reading and, with ``drift``, the drift's basis ``t (1 - u)``.

        Both smoothed by the host's filter when the candidate says (the filter is linear: the
        prediction ``Ts0 (1 - v) + s b + To v`` is the smoothed ``(Ts0 + s t)(1 - u) + To u``).
        """
        model, sensor = self.model_and_sensor(x)
        off = x[self.n_model]
        rho = np.exp(x[self.n_model + 1:self.n_model + 1 + self.n_mat])
        out = []
        cache: dict[tuple[int, bytes], tuple[np.ndarray, np.ndarray | None]] = {}
        for g in self.data.groups:
            gi = len(out)
            if gi in self.touch_cols:  # one shape per touch, each with its own h_c
                u = self._touch_shapes(g, model, sensor, off, rho[g.material],
                                       x[self.touch_cols[gi]:self.touch_cols[gi] + len(g.trials)], x)
                out.append(self.cand.chain(g.time_s, u))
                continue
            def step(tt, rho_m=rho[g.material]):
                return _reading(model, tt, rho_m, sensor, self.interp_points)

            if g.force is not None:  # one shape per touch: its contact area grows with its own force
                out.append(self.cand.chain(g.time_s, area_weighted(step, g.time_s, self.contact_area(g, x), off)))
                continue
            key = (g.material, g.time_s.tobytes())
            if key not in cache:
                cache[key] = self.cand.chain(g.time_s, area_weighted(step, g.time_s, None, off))
            out.append(cache[key])
        return out

    def contact_area(self, g: _Group, x: np.ndarray) -> np.ndarray | None:
        """Share of the final contact area (n, m) of a force-area group's touches (None: full contact)."""
        if g.force is None:
            return None
        band = 0.0 if g.force_band is None else g.force_band[:, None]
        free = self.cand.free
        c = PARAMS["contact_force_fraction"].from_x(x[free.index("contact_force_fraction")]) \
            if "contact_force_fraction" in free else 0.0
        return contact_area(g.force, c, band)

    def _touch_shapes(self, g: _Group, model, sensor, off: float, rho: float, log_dev: np.ndarray,
                      x: np.ndarray) -> np.ndarray:
        """Unsmoothed readings (n, m) of a group whose touches each have their own h_c."""
        import dataclasses

        out = np.zeros((log_dev.size, g.time_s.size))
        area = self.contact_area(g, x)
        for i, d in enumerate(log_dev):
            m = dataclasses.replace(model, conductance_w_m2k=model.conductance_w_m2k * math.exp(float(d)))
            out[i] = area_weighted(lambda t: _reading(m, t, rho, sensor, self.interp_points), g.time_s,
                                   None if area is None else area[i:i + 1], off)
        return out

    def jacobian(self, x: np.ndarray, touch_only: bool = False) -> np.ndarray:
        """Forward differences (step 1e-6 max(1, |x|)); all per-touch columns from one evaluation.

        A touch's residuals depend on its own h_c only (its Ts0 and To are its own), so perturbing
        every touch's h_c at once gives each touch's column on its own rows.
        """
        r0 = self.residuals(x)
        J = np.zeros((r0.size, x.size))
        steps = 1e-6 * np.maximum(1.0, np.abs(x))
        steps = np.where(x + steps > self.hi, -steps, steps)
        for j in range(0 if touch_only else self.n_global):
            xp = x.copy()
            xp[j] += steps[j]
            J[:, j] = (self.residuals(xp) - r0) / steps[j]
        if self.touch_cols:
            xp = x.copy()
            xp[self.n_global:] += steps[self.n_global:]
            d = self.residuals(xp) - r0
            pos = 0
            for gi, g in enumerate(self.data.groups):
                m = self.fitted_y(g).shape[1]
                if gi in self.touch_cols:
                    for i in range(len(g.trials)):
                        j = self.touch_cols[gi] + i
                        J[pos + i * m:pos + (i + 1) * m, j] = d[pos + i * m:pos + (i + 1) * m] / steps[j]
                pos += g.y.shape[0] * m
        return J

    def fitted_y(self, g: _Group) -> np.ndarray:
        """The samples of group ``g`` the residual uses (every ``stride``-th)."""
        return g.y[:, ::self.stride] if self.stride > 1 else g.y

    def project(self, x: np.ndarray):
        """(residuals, per-group linear coefficients): Ts0 (and To where free) in closed form.

        A group's shape is one curve (m,) or one per touch (n, m); the sums run over the last axis.
        """
        res, coefs = [], []
        for g, (v, b) in zip(self.data.groups, self.shapes_and_drift(x)):
            y = self.fitted_y(g)
            v = v[..., ::self.stride]
            a = 1.0 - v
            if b is not None:  # per touch: [Ts0, s] (and To where free) by least squares on its own basis
                b = b[..., ::self.stride]
                n = y.shape[0]
                cols = [np.broadcast_to(a, y.shape), np.broadcast_to(b, y.shape)]
                target = y
                if g.free_to:
                    cols.append(np.broadcast_to(v, y.shape))
                else:
                    to = self.object_temps(g, x)
                    target = y - to[:, None] * v
                B = np.stack(cols, axis=1)                       # (n, k, m)
                G = np.einsum("nkm,nlm->nkl", B, B)
                c = np.linalg.solve(G, np.einsum("nkm,nm->nk", B, target)[..., None])[..., 0]
                if g.free_to:
                    to = c[:, 2]
                pred = np.einsum("nk,nkm->nm", c, B) + (0.0 if g.free_to else to[:, None] * v)
                res.append((pred - y).ravel())
                coefs.append(np.vstack([c[:, 0], np.broadcast_to(to, (n,)), c[:, 1]]))
                continue
            saa = np.sum(a * a, axis=-1)
            if g.free_to:  # per touch: [Ts0, To] from the 2x2 normal equations (well scaled)
                sav, svv = np.sum(a * v, axis=-1), np.sum(v * v, axis=-1)
                ya, yv = np.sum(y * a, axis=-1), np.sum(y * v, axis=-1)
                det = saa * svv - sav * sav
                ts0 = (svv * ya - sav * yv) / det
                to = (saa * yv - sav * ya) / det
            else:
                to = self.object_temps(g, x)
                ts0 = np.sum((y - to[:, None] * v) * a, axis=-1) / saa
            pred = ts0[:, None] * a + to[:, None] * v
            res.append((pred - y).ravel())
            coefs.append(np.vstack([ts0, to]))
        return np.concatenate(res), coefs

    def residuals(self, x):
        return self.project(x)[0]

    def object_temps(self, g: _Group, x: np.ndarray) -> np.ndarray:
        """Each touch's object temperature [degC]: the group's, through the fitted offset and slope if affine."""
        if not g.affine:
            return g.to
        j = self.n_model + 1 + self.n_mat + 2 * self.affine.index(g.material)
        ref = self.data.refs[self.data.names[g.material]]
        return g.to + x[j] + x[j + 1] * (g.to - ref)

    def start(self) -> np.ndarray:
        x = [p.to_x(p.start) for p in self.params] + [0.3]
        return np.array(x + [0.0] * self.n_mat + [0.0, 0.0] * len(self.affine) + [0.0] * (self.lo.size - self.n_global))

    def row_touches(self) -> np.ndarray:
        """The touch (trial index) of each residual row: the clusters of the sandwich."""
        return np.concatenate([np.repeat(np.asarray(g.trials), self.fitted_y(g).shape[1]) for g in self.data.groups])

    def rows_of(self, k: int) -> np.ndarray:
        """Residual rows of material ``k``."""
        mask = [np.full(self.fitted_y(g).size, g.material == k) for g in self.data.groups]
        return np.concatenate(mask)

    def n_linear(self) -> int:
        per = (2 if self.cand.drift else 1)
        return int(sum(len(g.trials) * (per + (1 if g.free_to else 0)) for g in self.data.groups))


def _initial_ratios(prob: _Problem, x: np.ndarray) -> np.ndarray:
    """Log ratios e_o/e_s from a coarse 1-D search per material (the other parameters at their start)."""
    x = x.copy()
    for k in range(prob.n_mat):
        best = None
        for lr in np.linspace(-6.0, 6.0, 25):
            x[prob.n_model + 1 + k] = lr
            r = prob.residuals(x)
            sse = float(np.sum(r[prob.rows_of(k)] ** 2))
            if best is None or sse < best[0]:
                best = (sse, lr)
        x[prob.n_model + 1 + k] = best[1]
    return x


def _exp(v: float) -> float:
    """exp that saturates at the float range instead of raising."""
    return math.exp(min(max(float(v), -700.0), 700.0)) if math.isfinite(v) else (math.inf if v > 0 else 0.0)


def identify(trials: Sequence[Trial], model: "str | Candidate" = "layered+lag+smoothing", *,
             ranges: Mapping[str, Any] | None = None, object_temps: Mapping[str, Any] | None = None,
             depth_m: float = 80e-6, offset_bounds_s: tuple[float, float] = (-1.5, 1.5),
             start: Mapping[str, float] | None = None, x0: np.ndarray | None = None,
             max_nfev: int = 100, fit_rate_hz: "float | str | None" = "auto",
             touch_conductance: Sequence[str] = ()) -> Identification:
    """Fit one candidate model to touches.

    Parameters
    ----------
    trials : sequence of Trial
        Touches (time 0 = detected contact onset, samples before it).
    model : str or Candidate
        A label of :data:`~designkit.calibration.candidates.CANDIDATES` or a registered model name (its fullest candidate).
    ranges : mapping material -> MaterialRange (or (e_min, e_max)), optional
        Handbook effusivity ranges [J s^-1/2 K^-1 m^-2]; they set e_s's scale.
    object_temps : mapping, optional
        Per material ``"passive"``, ``"free"`` or a temperature [degC]; by
        default the passive channel, or ``"free"`` when it moves in contact.
    depth_m : float
        Thermistor depth [m], fixed (only x^2/alpha_s is identifiable).
    offset_bounds_s : (float, float)
        Search range of the contact-time offset [s].
    start : mapping, optional
        Starting values of free parameters (physical units; effusivities and
        h_c as ratios to e_s).
    x0 : ndarray, optional
        A transformed start vector (from another fit's ``x``).
    max_nfev : int
        Most residual evaluations of the optimizer.
    fit_rate_hz : float, "auto" or None
        The least-squares fit uses every k-th sample, ``k = round(fs /
        fit_rate_hz)`` (None: every sample; ``"auto"``: k = the lag at which
        the pre-contact noise's autocorrelation falls below 0.5, so white
        noise keeps every sample). The model's shapes (and the host
        smoothing) are still computed on the full grid, and the reported
        RMS, AIC and BIC are of the full grid. A host-smoothed recording gets
        a stride of several samples (docs/sensor-models.md). The
        cluster-robust covariance does not depend on the stride.
    touch_conductance : sequence of str
        Materials whose touches each get their own contact conductance
        ``h_c,i = h_c exp(d_i)`` (a per-touch nuisance: contact area and
        pressure differ from touch to touch); needs a candidate fitting h_c.
        Held-out touches of them get their own ``d_i`` fitted in :func:`score`.

    Returns
    -------
    Identification
    """
    from scipy.optimize import least_squares
    from threadpoolctl import threadpool_limits

    from ..rig import rig_conditions

    t0 = time.perf_counter()
    cand = model if isinstance(model, Candidate) else candidate(model)
    names = tuple(sorted({tr.material for tr in trials}))
    data = _prepare(trials, names, dict(object_temps or {}), force_area=cand.force_area)
    rng = {n: _as_range(ranges[n]) for n in names if ranges and n in ranges}
    if fit_rate_hz == "auto":
        stride = data.noise_lag
    else:
        stride = 1 if not fit_rate_hz else max(1, int(round(data.sample_rate_hz / float(fit_rate_hz))))
    prob = _Problem(cand, data, depth_m, offset_bounds_s, stride=stride,
                    touch_conductance=tuple(touch_conductance))
    if x0 is None:
        x = prob.start()
        for k, v in dict(start or {}).items():
            if k == "time_offset_s":
                x[prob.n_model] = float(v)
            elif k in cand.free:
                x[cand.free.index(k)] = PARAMS[k].to_x(float(v))
        x = _initial_ratios(prob, x)
    else:
        x = np.asarray(x0, dtype=np.float64)[:prob.n_global].copy()
    x = np.concatenate([x[:prob.n_global], np.zeros(prob.lo.size - prob.n_global)])
    x = np.clip(x, prob.lo + 1e-9, prob.hi - 1e-9)
    with threadpool_limits(1):  # tall, thin SVDs: threads only contend
        jac = dict(jac=prob.jacobian) if prob.touch_cols else dict(diff_step=1e-6)
        sol = least_squares(prob.residuals, x, bounds=(prob.lo, prob.hi), method="trf", x_scale="jac",
                            xtol=1e-8, ftol=1e-8, gtol=1e-8, max_nfev=max_nfev, **jac)
    est = _Estimate.of(prob, sol)
    r = sol.fun
    if prob.stride > 1:  # fit quality on every sample
        prob.stride = 1
        r = prob.residuals(est.x)
    x, rank, weak = est.x, est.rank, est.weak
    ratios, allowed, es_p, consistent, notes = _effusivity(est, prob, rng)
    params = _physical_parameters(est, prob, ratios, es_p, consistent)
    # ------------------------------------------------ fit quality
    rows = _touch_residuals(data, r)
    rms = rms_by_material([(n, row) for _, n, _, row in rows], total=False)
    rms_by = {n: rms[n] for n in names if n in rms}
    n_s = r.size
    k_par = x.size + prob.n_linear()
    ssr = float(r @ r)
    aic = n_s * math.log(ssr / n_s) + 2 * k_par
    bic = n_s * math.log(ssr / n_s) + k_par * math.log(n_s)
    if rank < x.size:
        notes.append(f"the Jacobian has rank {rank} of {x.size}: "
                     + ", ".join(prob.names[i] for i in sorted(weak)) + " not separately identified")
    if "diffusivity_m2_s" in cand.free:
        notes.append(f"alpha_s is identified at the fixed thermistor depth x = {depth_m * 1e6:g} um "
                     "(only x^2/alpha_s matters)")
    return Identification(cand, tuple(params), ratios, es_p, consistent, allowed, float(np.sqrt(np.mean(r ** 2))),
                          rms_by, n_s, k_par, aic, bic, rank, x.size, est.singular_values, time.perf_counter() - t0,
                          data.noise_c, x, names, depth_m, data.sample_rate_hz, dict(data.modes), tuple(notes),
                          dict(data.refs), tuple(touch_conductance),
                          nominal_force_profile(data) if cand.force_area else None,
                          rig_conditions(trials, pre_contact_noise_c=data.noise_c,
                                         residual_rms_c=float(np.sqrt(np.mean(r ** 2))),
                                         onset_offset_s=math.nan, residuals=[row for *_, row in rows],
                                         sample_rate_hz=data.sample_rate_hz).to_dict())


@dataclass(frozen=True)
class _Estimate:
    """The fitted transformed parameters with their 95 % half-widths and what the data leave unidentified."""

    x: np.ndarray
    sd: np.ndarray               # standard errors (cluster-robust sandwich)
    q: np.ndarray                # each parameter's t quantile (its Bell-McCaffrey degrees of freedom)
    weak: frozenset              # columns along which the scaled Jacobian is rank-deficient (or zero)
    at_bound: np.ndarray
    rank: int
    singular_values: np.ndarray

    @classmethod
    def of(cls, prob: "_Problem", sol) -> "_Estimate":
        """Identifiability (singular values of the column-scaled Jacobian) and the covariance of a solution."""
        x, J = sol.x, sol.jac
        norms = np.linalg.norm(J, axis=0)
        Js = J / np.where(norms > 0, norms, 1.0)
        sv = np.linalg.svd(Js, compute_uv=False)
        rank = int(np.sum(sv > sv[0] * 1e-6)) if sv.size else 0
        _, _, vt = np.linalg.svd(Js, full_matrices=False)
        weak = set()
        for j in range(rank, len(sv)):
            weak |= {int(i) for i in np.flatnonzero(np.abs(vt[j]) > 0.3)}
        weak |= {int(i) for i in np.flatnonzero(norms == 0)}
        cov, dof = cluster_sandwich(J, sol.fun, prob.row_touches(), df_columns=prob.n_global)
        at_bound = (np.abs(x - prob.lo) < 1e-6) | (np.abs(x - prob.hi) < 1e-6)
        return cls(x, np.sqrt(np.clip(np.diag(cov), 0.0, None)), t_critical(dof), frozenset(weak), at_bound, rank, sv)

    def interval(self, j: int) -> tuple[float, float]:
        """95 % interval of ``x[j]`` (transformed)."""
        h = self.q[j] * self.sd[j]
        return self.x[j] - h, self.x[j] + h

    def identified(self, j: int) -> bool:
        return j not in self.weak and not self.at_bound[j]


def _effusivity(est: _Estimate, prob: "_Problem", rng: Mapping[str, tuple[float, float]]):
    """e_s from the ranges of materials with a known object temperature: ``(ratios, allowed, e_s, consistent, notes)``."""
    x, names = est.x, prob.data.names
    ratios: dict[str, IdentifiedParameter] = {}
    allowed: dict[str, tuple[float, float]] = {}
    point_lo, point_hi, wide_lo, wide_hi = [], [], [], []
    for k, n in enumerate(names):
        j = prob.n_model + 1 + k
        lr, (r_lo, r_hi) = x[j], est.interval(j)   # its own touches inform it: its degrees of freedom say how many
        ident = est.identified(j) and 2 * est.q[j] * est.sd[j] < math.log(10.0)
        why = ("at the search limit: the touches ask for the full temperature difference (e_o/e_s -> inf)"
               if lr > 0 and est.at_bound[j] else "at the search limit (e_o/e_s -> 0)" if est.at_bound[j]
               else "95 % interval wider than a factor of 10" if not ident else "")
        ratios[n] = IdentifiedParameter(f"e_o/e_s[{n}]", _exp(lr), (_exp(r_lo), _exp(r_hi)), "", ident, why)
        if n in rng and prob.data.modes[n] != "free":
            e_lo, e_hi = rng[n]
            allowed[n] = (e_lo / _exp(r_hi), e_hi / _exp(r_lo))
            point_lo.append(math.log(e_lo) - lr)
            point_hi.append(math.log(e_hi) - lr)
            wide_lo.append(math.log(min(max(allowed[n][0], 1e-300), 1e300)))
            wide_hi.append(math.log(min(max(allowed[n][1], 1e-300), 1e300)))
    notes: list[str] = []
    if not point_lo:
        return ratios, allowed, None, None, notes
    a, b = max(point_lo), min(point_hi)
    wa, wb = max(wide_lo), min(wide_hi)
    consistent = bool(wa <= wb)
    if a <= b:
        les = 0.5 * (a + b)
        note = "set-identified: every e_s in the interval keeps all materials in range"
    elif consistent:
        les = 0.5 * (wa + wb)
        note = "the ranges touch only within the ratios' uncertainty"
    else:
        les = 0.5 * (a + b)
        note = "conflict: no e_s keeps every material in its range"
    ci = (_exp(wa), _exp(wb)) if consistent else (math.nan, math.nan)
    es_p = IdentifiedParameter("effusivity", _exp(les), ci, "J s^-1/2 K^-1 m^-2", consistent, note)
    if not consistent:
        notes.append("the materials' ranges conflict under this model: " + "; ".join(
            f"{n} allows e_s in [{lo:.4g}, {hi:.4g}]" for n, (lo, hi) in allowed.items()))
    return ratios, allowed, es_p, consistent, notes


def _physical_parameters(est: _Estimate, prob: "_Problem", ratios: Mapping[str, IdentifiedParameter],
                         es_p: IdentifiedParameter | None, consistent: bool | None) -> list[IdentifiedParameter]:
    """Every fitted parameter in physical units (effusivities and h_c scaled by e_s), with its 95 % interval."""
    x, data, names = est.x, prob.data, prob.data.names
    es = es_p.value if es_p is not None else 1.0
    es_ci = es_p.ci95 if es_p is not None and consistent else (es, es)
    params: list[IdentifiedParameter] = []
    for i, p in enumerate(prob.params):
        v = p.from_x(x[i])
        lo, hi = (p.from_x(e) for e in est.interval(i))
        if p.scale_with_es:
            v, lo, hi = v * es, lo * es_ci[0], hi * es_ci[1]
        why = []
        if i in est.weak:
            why.append("Jacobian rank-deficient along it")
        if est.at_bound[i]:
            why.append("at a search bound")
        if p.log and 2 * est.q[i] * est.sd[i] > math.log(10.0):
            why.append("95 % interval wider than a factor of 10")
        params.append(IdentifiedParameter(p.name, v, (lo, hi), p.unit, not why, "; ".join(why)))
    j = prob.n_model
    params.append(IdentifiedParameter("time_offset_s", float(x[j]), est.interval(j), "s", est.identified(j)))
    for n in names:
        rp = ratios[n]
        params.append(IdentifiedParameter(f"e_o[{n}]", rp.value * es, (rp.ci95[0] * es_ci[0], rp.ci95[1] * es_ci[1]),
                                          "J s^-1/2 K^-1 m^-2", rp.identifiable, rp.note))
    for gi, j0 in prob.touch_cols.items():
        g = data.groups[gi]
        d = x[j0:j0 + len(g.trials)]
        n = names[g.material]
        sdl = float(np.std(d, ddof=1)) if d.size > 1 else math.nan
        hc = PARAMS["conductance_w_m2k"].from_x(x[prob.params.index(PARAMS["conductance_w_m2k"])]) * es
        inside = bool(np.all(~est.at_bound[j0:j0 + d.size]))
        params.append(IdentifiedParameter(
            f"conductance_w_m2k[{n} touches]", hc * _exp(float(np.mean(d))),
            (hc * _exp(float(np.min(d))), hc * _exp(float(np.max(d)))), "W m^-2 K^-1", inside,
            "geometric mean of the touches' own h_c,i; interval: their smallest and largest (not a CI)"))
        params.append(IdentifiedParameter(
            f"conductance_spread[{n}]", _exp(sdl) if math.isfinite(sdl) else math.nan,
            (math.nan, math.nan), "factor", inside, "geometric standard deviation of the touches' h_c,i"))
    for i, k in enumerate(prob.affine):
        for j, name, unit in ((prob.n_model + 1 + prob.n_mat + 2 * i, "passive_offset_c", "degC"),
                              (prob.n_model + 2 + prob.n_mat + 2 * i, "passive_slope", "")):
            ok = est.identified(j)
            params.append(IdentifiedParameter(f"{name}[{names[k]}]", float(x[j]), est.interval(j), unit, ok,
                                              "" if ok else "at a search bound or rank-deficient"))
    return params


def _touch_residuals(data: "_Data", r: np.ndarray) -> list[tuple[int, str, np.ndarray, np.ndarray]]:
    """The residual ``r`` (groups one after the other, each touch a row) cut into one series per touch:
    ``(trial index, material, time_s, residual)`` in the groups' order."""
    rows, pos = [], 0
    for g in data.groups:
        block = r[pos:pos + g.y.size].reshape(g.y.shape)
        pos += g.y.size
        rows.extend((k, data.names[g.material], g.time_s, row) for k, row in zip(g.trials, block))
    return rows


def rms_by_material(rows: Sequence[tuple[str, np.ndarray]], total: bool = True) -> dict[str, float]:
    """Residual RMS [degC] per material of ``(material, residual)`` rows, and of all (``"all"``, when ``total``)."""
    per: dict[str, list[np.ndarray]] = {}
    for name, r in rows:
        per.setdefault(name, []).append(r)
    out = {n: float(np.sqrt(np.mean(np.concatenate(v) ** 2))) for n, v in per.items()}
    if total:
        out["all"] = float(np.sqrt(np.mean(np.concatenate([r for _, r in rows]) ** 2)))
    return out


def _as_range(r) -> tuple[float, float]:
    if hasattr(r, "e_min"):
        return float(r.e_min), float(r.e_max)
    lo, hi = r
    return float(lo), float(hi)


def score(result: Identification, trials: Sequence[Trial], *,
          object_temps: Mapping[str, Any] | None = None) -> dict[str, float]:
    """Residual RMS [degC] per material of an identified model on (held-out) touches.

    Nothing of the fit is changed but each touch's own initial temperatures:
    Ts0 fitted in closed form, To from its passive channel (or fitted where the
    material's object temperature is free). Materials the fit did not see are
    refused (their e_o is unknown).
    """
    return rms_by_material([(n, row) for _, n, _, row in _touch_residuals(*_held_out(result, trials, object_temps))])


def residual_series(result: Identification, trials: Sequence[Trial], *,
                    object_temps: Mapping[str, Any] | None = None) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """Each touch's residual (prediction - reading) [degC] on its own grid, as :func:`score` computes it.

    Returns
    -------
    list of (material, time_s, residual), in the order of ``trials``.
    """
    rows = sorted(_touch_residuals(*_held_out(result, trials, object_temps)), key=lambda row: row[0])
    return [row[1:] for row in rows]


def _held_out(result: Identification, trials: Sequence[Trial],
              object_temps: Mapping[str, Any] | None) -> tuple[_Data, np.ndarray]:
    """(prepared data, residuals) of an identified model on touches, each with its own nuisances."""
    names = result.names
    unknown = sorted({tr.material for tr in trials} - set(names))
    if unknown:
        raise InputError(f"cannot score {', '.join(unknown)}: not among the fitted materials {', '.join(names)}")
    modes = dict(result.object_modes)
    modes.update(dict(object_temps or {}))
    data = _prepare(trials, names, modes, refs=result.object_refs, force_area=result.candidate.force_area)
    prob = _Problem(result.candidate, data, result.depth_m, (-math.inf, math.inf), stride=1,
                    touch_conductance=result.touch_conductance)
    x = np.concatenate([result.x[:prob.n_global], np.zeros(prob.lo.size - prob.n_global)])
    if prob.touch_cols:  # each held-out touch's own h_c (the sensor's parameters stay as fitted)
        from scipy.optimize import least_squares
        from threadpoolctl import threadpool_limits

        glob = x[:prob.n_global]
        free = slice(prob.n_global, None)
        prob.stride = data.noise_lag
        with threadpool_limits(1):
            sol = least_squares(lambda d: prob.residuals(np.concatenate([glob, d])), x[free],
                                jac=lambda d: prob.jacobian(np.concatenate([glob, d]), touch_only=True)[:, free],
                                bounds=(prob.lo[free], prob.hi[free]), method="trf", x_scale="jac", max_nfev=50)
        x = np.concatenate([glob, sol.x])
        prob.stride = 1
    r, _ = prob.project(x)
    return data, r
