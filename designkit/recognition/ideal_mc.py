"""The ideal observer for forward models whose curves differ in shape per object.

The closed form of :mod:`designkit.recognition.ideal` needs every curve of a
scene to share one shape ``g(t)``; a slab (heat reflected from its far face)
or an imperfect contact (a lag that depends on the object) breaks that. Here
each class's likelihood ``p(y | class)`` is the Gaussian likelihood of the
whole touch averaged over a midpoint grid of the class's effusivity (and, where
the model needs it, diffusivity) range, fine enough that neighbouring grid
curves differ by at most half the noise (arc length of the curve family in
noise units: sampled at spacing h, a unit Gaussian sums to its integral within
``2 exp(-2 pi^2 / h^2)`` by Poisson summation, so what is left is the class
edges). Test touches are simulated with the same model, classified by the
log-likelihood ratio and scored (:func:`designkit.recognition.ideal.score_llr`);
the result carries its Monte Carlo standard error.

For speed the curves and touches are projected on an orthonormal basis of
the curve family (SVD), truncated only where every grid curve is reproduced
to 1 % of the noise; the part of a touch outside the basis is common to all
hypotheses and cancels from the ratio.

Fixed initial conditions only (the varied-condition likelihood is integrated
in closed form for shared-shape models only).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validation import InputError
from ..models import ForwardModel, get_model
from ..objects import ObjectClass, ordered_pair
from ..scene import Scene
from ..sensor import Sensor
from ..simulation import response_tolerance, seed_key, simulate_class, window_times_s
from .scores import IdealResult, score_llr

__all__ = ["ideal_pair_mc"]

_BASIS_EPS = 0.01              # basis reproduces every grid curve to this fraction of the noise
_GRID_PER_NOISE = 2.0          # likelihood grid points per noise unit of curve arc length
_MAX_GRID = 4096               # most grid points per class along effusivity
_MAX_GRID_D = 64               # ... along diffusivity
_BLOCK = 2_000_000             # floats per block of curves (16 MB)
_TEST_STREAMS = (10, 11)       # seed-key suffixes of the two classes' test touches


def _curves(model: ForwardModel, t, e, d, sensor, tol) -> np.ndarray:
    """Normalized curves for effusivities ``e`` at one diffusivity ``d`` (None: the model needs none)."""
    e = np.atleast_1d(np.asarray(e, dtype=np.float64))
    dd = None if d is None else np.full(e.size, float(d)) if np.ndim(d) == 0 else np.asarray(d, dtype=np.float64)
    return model.response(t, e, sensor, diffusivity_m2_s=dd, tolerance=tol)


def _arc_length(curves: np.ndarray) -> float:
    """Length of a polyline of curves (rows), Euclidean."""
    if curves.shape[0] < 2:
        return 0.0
    return float(np.sum(np.linalg.norm(np.diff(curves, axis=0), axis=1)))


@dataclass(frozen=True)
class _ClassGrid:
    e_nodes: np.ndarray      # (n_e,)
    d_nodes: tuple           # diffusivity nodes, or (None,)
    arc_e: float             # curve-family arc length along e, noise units
    arc_d: float
    capped: bool

    @property
    def size(self) -> int:
        return self.e_nodes.size * len(self.d_nodes)


def _class_grid(model, obj: ObjectClass, t, sensor, s_n, tol, pilot: list) -> _ClassGrid:
    """Midpoint grid over the class's effusivity (x diffusivity) box: 2 points per noise unit of arc."""
    e_lo, e_hi = obj.e_range
    needs_d = "diffusivity_m2_s" in model.object_properties
    d_lo, d_hi = obj.diffusivity_range_m2_s if needs_d else (None, None)
    d_lines = [d_lo] if d_hi == d_lo else [d_lo, 0.5 * (d_lo + d_hi), d_hi]
    e_pilot = np.linspace(e_lo, e_hi, 33)
    arc_e = 0.0
    for d in d_lines:
        c = _curves(model, t, e_pilot, d, sensor, tol)
        pilot.append(c)
        arc_e = max(arc_e, _arc_length(c) / s_n)
    arc_d = 0.0
    if needs_d and d_hi > d_lo:
        d_pilot = np.linspace(d_lo, d_hi, 9)
        for e in (e_lo, 0.5 * (e_lo + e_hi), e_hi):
            c = _curves(model, t, np.full(d_pilot.size, e), d_pilot, sensor, tol)
            pilot.append(c)
            arc_d = max(arc_d, _arc_length(c) / s_n)
    n_e = int(np.clip(math.ceil(_GRID_PER_NOISE * arc_e), 16, _MAX_GRID))
    varied_d = needs_d and d_hi > d_lo
    n_d = int(np.clip(math.ceil(_GRID_PER_NOISE * arc_d), 1, _MAX_GRID_D)) if varied_d else 1
    capped = _GRID_PER_NOISE * arc_e > _MAX_GRID or (varied_d and _GRID_PER_NOISE * arc_d > _MAX_GRID_D)
    if n_e * n_d > 4 * _MAX_GRID:  # keep the 2-D grid affordable: shrink both alike
        f = math.sqrt(4 * _MAX_GRID / (n_e * n_d))
        n_e, n_d, capped = max(16, int(n_e * f)), max(1, int(n_d * f)), True
    e_nodes = e_lo + (np.arange(n_e) + 0.5) * (e_hi - e_lo) / n_e
    if not needs_d:
        d_nodes: tuple = (None,)
    elif not varied_d:
        d_nodes = (d_lo,)
    else:
        d_nodes = tuple(d_lo + (np.arange(n_d) + 0.5) * (d_hi - d_lo) / n_d)
    return _ClassGrid(e_nodes, d_nodes, arc_e, arc_d, capped)


def _basis_from(curves: np.ndarray, tol_abs: float, basis: np.ndarray | None = None) -> np.ndarray:
    """Orthonormal rows spanning ``curves`` (after removing ``basis``) to ``tol_abs`` per curve."""
    resid = curves if basis is None else curves - (curves @ basis.T) @ basis
    # SVD through a QR of the (few) curves: resid = r^T q^T, so resid's right singular vectors are q w
    q, r = np.linalg.qr(resid.T)
    _, _, wt = np.linalg.svd(r.T, full_matrices=False)
    vt = wt @ q.T
    # residual of each curve after r components; keep r so that all are <= tol
    coef = resid @ vt.T  # (K, k)
    tail = np.sqrt(np.maximum(np.cumsum((coef ** 2)[:, ::-1], axis=1)[:, ::-1], 0.0))  # tail[:, j]: from j on
    need = [j for j in range(vt.shape[0] + 1) if j == vt.shape[0] or np.all(tail[:, j] <= tol_abs)]
    new = vt[:need[0]]
    return new if basis is None else np.vstack([basis, new])


def _grid_coefficients(model, grid: _ClassGrid, basis, t, sensor, tol):
    """Basis coefficients of every grid curve, the largest residual norm, and the largest residual rows.

    The residual rows (up to 8 per block, those within a factor 2 of the block's largest) are what
    :func:`_basis_from` adds to the basis when the largest residual exceeds the tolerance.
    """
    coefs, worst, worst_rows = [], 0.0, []
    step = max(1, _BLOCK // max(t.size, 1))
    for d in grid.d_nodes:
        for j in range(0, grid.e_nodes.size, step):
            c = _curves(model, t, grid.e_nodes[j:j + step], d, sensor, tol)
            k = c @ basis.T
            res = c - k @ basis
            norms = np.linalg.norm(res, axis=1)
            worst = max(worst, float(norms.max()))
            worst_rows.append(res[norms >= 0.5 * norms.max()][:8])
            coefs.append(k)
    return np.vstack(coefs), worst, np.vstack(worst_rows)


def ideal_pair_mc(obj_a: ObjectClass, obj_b: ObjectClass, sensor: Sensor, scene: Scene, *,
                  model: "ForwardModel | str | None" = None, n_mc: int = 1000, seed=0) -> IdealResult:
    """Best achievable F1 and accuracy for two object classes, by Monte Carlo on the exact likelihood.

    Parameters
    ----------
    obj_a, obj_b : ObjectClass
        Order does not matter; the positive class has the higher effusivity.
    sensor : Sensor
    scene : Scene
        Fixed initial conditions.
    model : ForwardModel or name
        Any forward model (used where curves differ in shape per object).
    n_mc : int
        Simulated test touches per class (>= 10).
    seed : int or list of int
        Test touches use streams ``seed + [10]`` and ``seed + [11]``.

    Returns
    -------
    IdealResult
        ``method="monte-carlo"``, with standard errors and ``details``: grid
        sizes, arc lengths (noise units), basis rank and its largest residual.

    Examples
    --------
    >>> from designkit import SENSORS, Scene
    >>> from designkit.objects import object_class
    >>> r = ideal_pair_mc(object_class(35000), object_class(20000), SENSORS["paper"],
    ...                   Scene(contact_s=1), model="contact", n_mc=200)
    >>> 0.66 < r.f1 <= 1.0 and r.method
    'monte-carlo'
    """
    fm = get_model(model)
    if getattr(fm, "touch_ramps", ()):
        # every touch pressing as the nominal one: a nuisance less, so still a bound on any classifier
        fm = fm.nominal()
    n_mc = int(n_mc)
    if n_mc < 10:
        raise InputError(f"the Monte Carlo ideal observer needs at least 10 touches per class, got {n_mc}")
    if not scene.fixed_initial_conditions:
        raise InputError(f"the ideal observer for the {fm.name} model supports fixed initial conditions only")
    if scene.delta_t_c == 0:
        raise InputError("temperature difference is 0: an unheated sensor sees no contrast between materials")
    low, high = ordered_pair(obj_a.require(fm.object_properties), obj_b.require(fm.object_properties))
    key = seed_key(seed)
    # a noise-free scene is handled as the limit of a tiny noise (as the closed form does)
    sc = scene.replace(noise_c=max(scene.noise_c, 1e-6 * abs(scene.delta_t_c)))
    s_n = sc.noise_ratio
    t = window_times_s(sensor, sc)   # the recorder's window
    sim_model = fm
    fm, whiten = _whitened(fm, t.size, sensor.sample_rate_hz, sc.noise_correlation_s)
    tol = response_tolerance(s_n, t.size)
    pilot: list[np.ndarray] = []
    grids = [_class_grid(fm, obj, t, sensor, s_n, tol, pilot) for obj in (low, high)]
    eps = _BASIS_EPS * s_n
    basis = _basis_from(np.vstack(pilot), eps)
    for _ in range(6):  # grow the basis until it reproduces every grid curve
        out = [_grid_coefficients(fm, g, basis, t, sensor, tol) for g in grids]
        worst = max(o[1] for o in out)
        if worst <= eps:
            break
        basis = _basis_from(np.vstack([o[2] for o in out]), eps, basis)
    coefs = [o[0] for o in out]
    # test touches, normalized: u_obs = (y - Ts0) / (Ta - Ts0) = u + (sigma / (Ta - Ts0)) z
    dt = sc.ambient_temp_c - sc.sensor_temp_c
    obs = []
    for obj, k in zip((low, high), _TEST_STREAMS):
        tr = simulate_class(obj, n_mc, sensor, sc, key + [k], sim_model)
        obs.append(whiten((tr.temperature_c - sc.sensor_temp_c) / dt) @ basis.T)
    labels = np.r_[np.zeros(n_mc, dtype=int), np.ones(n_mc, dtype=int)]
    llr = _log_likelihood_ratio(np.vstack(obs), coefs, s_n)
    f1, se, acc, acc_se = score_llr(llr, labels, n_mc)
    details = {"grid": [[g.e_nodes.size, len(g.d_nodes)] for g in grids],
               "arc_length_noise_units": [[g.arc_e, g.arc_d] for g in grids],
               "grid_capped": any(g.capped for g in grids), "basis_rank": int(basis.shape[0]),
               "basis_residual_noise_units": worst / s_n, "model": sim_model.name}
    return IdealResult(f1=f1, accuracy=acc, method="monte-carlo", standard_error=se,
                       accuracy_standard_error=acc_se, projection_noise=None, n_mc=n_mc, details=details)


@dataclass(frozen=True)
class _Whitened:
    """A model whose curves are read through the whitening ``L^-1`` of correlated noise (a rig's scene):
    in whitened coordinates the noise is white again and the likelihood below holds as it is."""

    base: ForwardModel
    chol: np.ndarray

    def __getattr__(self, name):
        return getattr(self.base, name)

    def whiten(self, curves) -> np.ndarray:
        from scipy.linalg import solve_triangular

        y = np.atleast_2d(np.asarray(curves, dtype=np.float64))
        return solve_triangular(self.chol, y.T, lower=True).T

    def response(self, *args, **kwargs) -> np.ndarray:
        return self.whiten(self.base.response(*args, **kwargs))


def _whitened(fm: ForwardModel, n_samples: int, sample_rate_hz: float, correlation_s: float):
    """(model, whiten): the model and observations read in whitened coordinates when the noise is correlated
    (:func:`designkit.simulation.noise_cholesky`), else unchanged."""
    if not correlation_s or n_samples < 2:
        return fm, lambda y: y
    from ..simulation import noise_cholesky

    w = _Whitened(fm, noise_cholesky(n_samples, sample_rate_hz, correlation_s))
    return w, w.whiten


def _log_likelihood_ratio(y: np.ndarray, coefs: list[np.ndarray], s_n: float) -> np.ndarray:
    """log p(y | high) - log p(y | low), each a mean of Gaussians centred on the class's grid curves."""
    from scipy import special

    centre = np.vstack(coefs).mean(axis=0)  # centring keeps the expanded squares well conditioned
    y = y - centre
    cs = [c - centre for c in coefs]
    half_sq = [0.5 * np.einsum("ij,ij->i", c, c) for c in cs]
    llr = np.empty(y.shape[0])
    for i in range(0, y.shape[0], 512):
        yc = y[i:i + 512]
        ll = [special.logsumexp((yc @ c.T - h[None, :]) / (s_n * s_n), axis=1) - math.log(c.shape[0])
              for c, h in zip(cs, half_sq)]
        llr[i:i + 512] = ll[1] - ll[0]
    return llr
