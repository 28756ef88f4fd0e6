"""1-D finite-volume heat conduction through a stack of layers (sensor, object, backing).

The numerical reference and fallback of :mod:`designkit.models.slab` (the scheme, its
grids and its checks: docs/thin_samples.md, "Numerical solver"). A heated sensor (left of
the contact plane ``z = 0``) touches a stack of homogeneous layers, each starting at a
uniform temperature; ``rho c dT/dt = d/dz (k dT/dz)`` with continuity of temperature and
flux at every interface, by cell-centred finite volumes with harmonic-mean conductances
and cell faces on every interface (Patankar, *Numerical Heat Transfer and Fluid Flow*,
1980, sec. 4.2). Semi-infinite layers are cut where the heat entered within
``time_max_s`` is negligible (:func:`truncation_depth_m`) and closed by an insulated face.

Units: ``z`` [m], ``t`` [s], effusivity ``e = k / sqrt(alpha)`` [J s^-1/2 K^-1 m^-2],
diffusivity ``alpha`` [m^2 s^-1]; conductivity ``k = e sqrt(alpha)`` and volumetric heat
capacity ``rho c = e / sqrt(alpha)``. Temperatures are normalized (sensor 0, object 1).

Two integrators of ``M du/dt = -A u``: :func:`integrate_crank_nicolson` (the default;
geometric time grid, Rannacher start-up, one banded solve per step) and
:func:`integrate_bdf` (:func:`scipy.integrate.solve_ivp`, BDF; a check, several times
slower). Explicit stepping would need nanosecond steps for micrometre cells in copper
(the lab's :mod:`designkit_lab.explicit_euler`). Both advance ``K`` property sets that
share one geometry together, as one block-diagonal system.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy import linalg, sparse, special

from .._validation import InputError, check_positive

__all__ = [
    "Grid",
    "Layer",
    "apply_conductances",
    "build_grid",
    "heat_content",
    "integrate_bdf",
    "integrate_crank_nicolson",
    "probe_reading",
    "time_levels_s",
    "truncation_depth_m",
]

#: Relative size of the heat wave reflected by an artificial insulated cut
#: (see :func:`truncation_depth_m`).
TRUNCATION_TOLERANCE = 1e-10


@dataclass(frozen=True)
class Layer:
    """One homogeneous layer of the stack.

    Parameters
    ----------
    effusivity : float or array_like, shape (K,)
        e [J s^-1/2 K^-1 m^-2] (> 0). An array gives ``K`` property sets on one
        geometry (several objects of the same diffusivity and thickness).
    diffusivity_m2_s : float
        alpha [m^2 s^-1] (> 0); it sets the geometry, so it is one number.
    thickness_m : float
        Thickness [m] (> 0); ``inf`` for a semi-infinite layer, which must be
        the first (sensor) or last one.
    initial : float
        Initial (normalized) temperature of the whole layer.
    """

    effusivity: object
    diffusivity_m2_s: float
    thickness_m: float
    initial: float = 0.0

    def __post_init__(self) -> None:
        e = np.atleast_1d(np.asarray(self.effusivity, dtype=np.float64))
        if e.ndim != 1 or e.size == 0 or not np.all(np.isfinite(e)) or np.any(e <= 0):
            raise InputError("layer effusivity must be positive and finite "
                             f"(finite-volume solver), got {np.asarray(self.effusivity)!r}")
        e.setflags(write=False)
        object.__setattr__(self, "effusivity", e)
        object.__setattr__(self, "diffusivity_m2_s",
                           check_positive("layer diffusivity [m^2/s]", self.diffusivity_m2_s))
        object.__setattr__(self, "thickness_m",
                           check_positive("layer thickness [m]", self.thickness_m, allow_inf=True))
        object.__setattr__(self, "initial", float(self.initial))


@dataclass(frozen=True)
class Grid:
    """A graded finite-volume grid of a layer stack, for ``K`` property sets.

    Attributes
    ----------
    faces_m : ndarray, shape (N + 1,)
        Cell faces [m]; the contact plane is ``z = 0``, the sensor lies at ``z < 0``.
    conductivity : ndarray, shape (K, N)
        k of each cell [W m^-1 K^-1].
    capacity : ndarray, shape (K, N)
        rho c of each cell [J m^-3 K^-1].
    diffusivity_m2_s : ndarray, shape (N,)
        alpha of each cell [m^2 s^-1].
    initial : ndarray, shape (N,)
        Initial temperature of each cell (normalized).
    layer_index : ndarray of int, shape (N,)
        Which layer each cell belongs to (0 = sensor).
    probe_m : float
        Position of the thermistor [m] (``-depth``).
    """

    faces_m: np.ndarray
    conductivity: np.ndarray
    capacity: np.ndarray
    diffusivity_m2_s: np.ndarray
    initial: np.ndarray
    layer_index: np.ndarray
    probe_m: float

    @property
    def n_cells(self) -> int:
        return int(self.faces_m.size - 1)

    @property
    def n_sets(self) -> int:
        """Number of property sets K advanced together."""
        return int(self.conductivity.shape[0])

    @property
    def widths_m(self) -> np.ndarray:
        return np.diff(self.faces_m)

    @property
    def centres_m(self) -> np.ndarray:
        return 0.5 * (self.faces_m[1:] + self.faces_m[:-1])

    def heat_capacities(self) -> np.ndarray:
        """Diagonal of M: heat capacity of each cell per unit area [J m^-2 K^-1], (K, N)."""
        return self.capacity * self.widths_m

    def conductances(self) -> np.ndarray:
        """Conductance of each interior face per unit area [W m^-2 K^-1], (K, N - 1).

        Series resistance of the two half cells, ``1 / (h_i / 2k_i + h_j / 2k_j)``:
        exact for piecewise-linear temperature in each cell, with the face on the
        material interface (Patankar 1980, eq. 4.9).
        """
        h = self.widths_m
        half = 0.5 * h / self.conductivity
        return 1.0 / (half[:, :-1] + half[:, 1:])

    def probe_weights(self) -> tuple[int, float]:
        """Cell ``i`` and weight ``w``: reading = ``(1 - w) u[i] + w u[i + 1]`` (linear)."""
        c = self.centres_m
        i = int(np.clip(np.searchsorted(c, self.probe_m) - 1, 0, c.size - 2))
        w = (self.probe_m - c[i]) / (c[i + 1] - c[i])
        return i, float(w)


# ----------------------------------------------------------------------------- grid
def truncation_depth_m(diffusivity_m2_s: float, time_max_s: float,
                       tolerance: float = TRUNCATION_TOLERANCE) -> float:
    """Depth at which an insulated cut of a semi-infinite layer is invisible.

    A cut at depth D reflects the incoming heat wave; its image lies at 2D, so
    the change it causes near the entry face is of order
    ``erfc(2D / (2 sqrt(alpha t)))`` (Carslaw & Jaeger, *Conduction of Heat in
    Solids*, 2nd ed., sec. 2.9). Setting that to ``tolerance`` gives
    ``D = sqrt(alpha t) erfcinv(tolerance)``: a few diffusion lengths (4.57 for
    the default 1e-10).

    Returns
    -------
    float
        D [m].

    Examples
    --------
    >>> round(truncation_depth_m(1.19e-9, 4.0) * 1e6)  # the paper's sensor after 4 s [um]
    315
    """
    return math.sqrt(diffusivity_m2_s * time_max_s) * float(special.erfcinv(tolerance))


def _one_sided_faces(depth_m: float, n: int, ratio: float) -> np.ndarray:
    """n cells on [0, depth], fine at 0, growing geometrically (smooth exponential map)."""
    xi = np.linspace(0.0, 1.0, n + 1)
    beta = math.log(max(ratio, 1.0 + 1e-12))
    return depth_m * np.expm1(beta * xi) / math.expm1(beta)


def _two_sided_faces(thickness_m: float, n: int, ratio: float) -> np.ndarray:
    """n cells on [0, L], fine at both faces (tanh map, centre/edge cell size ~ ``ratio``)."""
    xi = np.linspace(0.0, 1.0, n + 1)
    # centre/edge width ratio of the tanh map is cosh(beta)^2
    beta = math.acosh(math.sqrt(max(ratio, 1.0 + 1e-12)))
    if beta < 1e-6:
        return thickness_m * xi
    return 0.5 * thickness_m * (1.0 + np.tanh(beta * (2.0 * xi - 1.0)) / math.tanh(beta))


def build_grid(sensor: Layer, body: Sequence[Layer], probe_depth_m: float, time_max_s: float,
               cells_per_layer: int = 48, *, time_min_s: float | None = None,
               sensor_cells: int | None = None) -> Grid:
    """Grid the stack ``sensor | body[0] | body[1] | ...`` for a contact of ``time_max_s``.

    Parameters
    ----------
    sensor : Layer
        The sensor, left of the contact plane; ``thickness_m = inf`` for the
        semi-infinite sensor of the paper. Must hold the thermistor.
    body : sequence of Layer
        The object's layers and the backing, from the contact plane outward.
        Only the last may be semi-infinite (``thickness_m = inf``); if it is
        finite, its back face is insulated.
    probe_depth_m : float
        Thermistor depth below the contact surface [m] (> 0).
    time_max_s : float
        Longest time that will be asked for [s] (sets how deep the grid reaches).
    cells_per_layer : int
        Cells in every body layer (the resolution knob).
    time_min_s : float, optional
        Earliest time whose reading matters [s]; the cell-size ratio of each
        layer is its extent over ``sqrt(alpha t_min)`` (at most 400).
        Defaults to ``time_max_s / 100``.
    sensor_cells : int, optional
        Cells between the contact and the thermistor (default
        ``2 * cells_per_layer``); behind the thermistor the cells keep growing
        by the same factor until the truncation depth.

    Returns
    -------
    Grid
    """
    n = int(cells_per_layer)
    n_sensor = 2 * n if sensor_cells is None else int(sensor_cells)
    if min(n, n_sensor) < 4:
        raise InputError(f"cells per layer must be >= 4, got {min(n, n_sensor)}")
    depth = check_positive("thermistor depth [m] (finite-volume solver)", probe_depth_m)
    t_max = check_positive("time [s]", time_max_s)
    t_min = t_max / 100.0 if time_min_s is None else min(check_positive("time [s]", time_min_s), t_max)
    if not body:
        raise InputError("the stack needs at least one layer beyond the contact")
    if any(math.isinf(b.thickness_m) for b in body[:-1]):
        raise InputError("only the last layer of the stack may be semi-infinite")
    k_sets = {sensor.effusivity.size} | {b.effusivity.size for b in body}
    k_sets.discard(1)
    if len(k_sets) > 1:
        raise InputError(f"layers give different numbers of property sets: {sorted(k_sets)}")
    n_sets = k_sets.pop() if k_sets else 1

    def grading(alpha: float, extent: float) -> float:
        # largest/smallest cell ratio: the layer's extent over the diffusion
        # length at the earliest time that matters, within [1, 400]
        finest = math.sqrt(alpha * t_min)
        return float(np.clip(extent / finest, 1.0, 400.0))

    pieces: list[np.ndarray] = []
    layers: list[Layer] = []
    # Sensor: the thermistor sits on a cell face. Between the contact and the
    # thermistor, n_sensor cells graded from the contact (exponential map);
    # behind it, cells keep growing by the same factor until the depth the heat
    # reaches (semi-infinite sensor), or an exponential map to the back face.
    reach_s = truncation_depth_m(sensor.diffusivity_m2_s, t_max)
    finite_sensor = math.isfinite(sensor.thickness_m)
    d_need = sensor.thickness_m if finite_sensor else max(0.5 * depth + reach_s, 1.5 * depth)
    if depth >= d_need:
        raise InputError(f"thermistor depth {depth:g} m lies outside the sensor layer ({d_need:g} m)")
    front = _one_sided_faces(depth, n_sensor, grading(sensor.diffusivity_m2_s, depth))
    h_last = front[-1] - front[-2]
    growth = h_last / (front[-2] - front[-3])
    if finite_sensor:
        back = depth + _one_sided_faces(d_need - depth, n_sensor, grading(sensor.diffusivity_m2_s,
                                                                         d_need - depth))
    else:
        # geometric continuation: h_last * growth^k, k = 1.., until past d_need
        k = int(math.ceil(math.log1p((d_need - depth) * (growth - 1.0) / (h_last * growth))
                              / math.log(growth))) if growth > 1.0 else \
            int(math.ceil((d_need - depth) / h_last))
        steps = h_last * growth ** np.arange(1, k + 1)
        back = depth + np.concatenate([[0.0], np.cumsum(steps)])
    f = np.concatenate([front, back[1:]])
    pieces.append(-f[::-1])
    layers.append(sensor)
    z0 = 0.0
    for lay in body:
        reach = truncation_depth_m(lay.diffusivity_m2_s, t_max)
        if lay.thickness_m >= reach:
            # semi-infinite, or thicker than heat gets within t_max: cut (insulated)
            # at the reach and leave out everything behind it
            f = _one_sided_faces(reach, n, grading(lay.diffusivity_m2_s, reach))
            pieces.append(z0 + f[1:])
            layers.append(lay)
            break
        f = _two_sided_faces(lay.thickness_m, n, grading(lay.diffusivity_m2_s, 0.5 * lay.thickness_m))
        pieces.append(z0 + f[1:])
        layers.append(lay)
        z0 += lay.thickness_m
    faces = np.concatenate(pieces)
    counts = [pieces[0].size - 1] + [p.size for p in pieces[1:]]
    idx = np.repeat(np.arange(len(layers)), counts)
    e = np.stack([np.broadcast_to(lay.effusivity, (n_sets,)) for lay in layers], axis=1)  # (K, L)
    sq = np.sqrt(np.array([lay.diffusivity_m2_s for lay in layers]))
    cond = np.repeat(e * sq, counts, axis=1)
    cap = np.repeat(e / sq, counts, axis=1)
    alpha = np.repeat(sq * sq, counts)
    init = np.repeat(np.array([lay.initial for lay in layers]), counts)
    return Grid(faces, np.ascontiguousarray(cond), np.ascontiguousarray(cap), alpha, init, idx, -depth)


# ------------------------------------------------------------------ semi-discrete system
def apply_conductances(g: np.ndarray, u: np.ndarray) -> np.ndarray:
    """``A u`` for the conductance matrix ``A`` (insulated ends), row-wise over (K, N): ``g`` the face
    conductances (:meth:`Grid.conductances`), ``u`` the cell temperatures."""
    flux = g * (u[:, :-1] - u[:, 1:])  # heat flow left -> right through each interior face
    out = np.zeros_like(u)
    out[:, :-1] += flux
    out[:, 1:] -= flux
    return out


def _banded(m: np.ndarray, g: np.ndarray, theta_dt: float) -> np.ndarray:
    """Banded storage (3, K*N) of ``M + theta_dt * A`` for the stacked blocks."""
    k, n = m.shape
    gl = np.zeros((k, n))
    gr = np.zeros((k, n))
    gl[:, 1:] = g
    gr[:, :-1] = g
    ab = np.zeros((3, k * n))
    ab[1] = (m + theta_dt * (gl + gr)).ravel()
    up = np.zeros((k, n))
    up[:, 1:] = -theta_dt * g  # ab[0, j] = a[j - 1, j]
    lo = np.zeros((k, n))
    lo[:, :-1] = -theta_dt * g  # ab[2, j] = a[j + 1, j]
    ab[0] = up.ravel()
    ab[2] = lo.ravel()
    return ab


def probe_reading(grid: Grid, u: np.ndarray) -> np.ndarray:
    """Thermistor reading from cell values ``u`` (..., K, N): linear interpolation."""
    i, w = grid.probe_weights()
    return (1.0 - w) * u[..., i] + w * u[..., i + 1]


def heat_content(grid: Grid, u: np.ndarray) -> np.ndarray:
    """Heat per unit area ``sum_i rho_i c_i h_i u_i`` [J m^-2 per unit of u], shape (..., K)."""
    return np.sum(grid.heat_capacities() * u, axis=-1)


def time_levels_s(times_s: np.ndarray, step_ratio: float, start_fraction: float = 1e-3) -> np.ndarray:
    """Geometric time levels for graded stepping: ``dt <= step_ratio * t``.

    From ``start_fraction * t_first`` (``t_first``: the earliest positive output
    time) to the last output time, each step ``step_ratio`` times the time
    reached. Diffusion from a discontinuity changes on the time scale ``t``
    itself, so a constant ratio keeps the local error uniform (Eriksson &
    Johnson, SIAM J. Numer. Anal. 28 (1991) 43, graded steps for parabolic
    problems with non-smooth data).
    """
    t = np.asarray(times_s, dtype=np.float64)
    pos = t[t > 0]
    if pos.size == 0:
        return np.zeros(1)
    t0, t1 = float(pos.min()) * start_fraction, float(pos.max())
    n = max(1, int(math.ceil(math.log(t1 / t0) / math.log1p(step_ratio))))
    return np.concatenate([[0.0], np.geomspace(t0, t1, n + 1)])


def _interp_log_time(levels: np.ndarray, values: np.ndarray, times_s: np.ndarray) -> np.ndarray:
    """Cubic interpolation in log t of readings (K, n_levels) at the output times."""
    from scipy.interpolate import CubicSpline

    t = np.asarray(times_s, dtype=np.float64)
    out = np.empty((values.shape[0], t.size))
    pos = t > 0
    out[:, ~pos] = values[:, :1]  # t = 0: the initial reading
    if np.any(pos):
        spline = CubicSpline(np.log(levels[1:]), values[:, 1:], axis=1)
        tt = np.clip(t[pos], levels[1], levels[-1])
        out[:, pos] = spline(np.log(tt))
    return out


def integrate_crank_nicolson(grid: Grid, times_s, step_ratio: float = 0.05, *,
                             rannacher_steps: int = 4, return_state: bool = False):
    """Crank-Nicolson with Rannacher start-up on a geometric time grid.

    ``(M + dt/2 A) u_{n+1} = (M - dt/2 A) u_n`` (trapezoidal rule), solved
    for the increment ``u_{n+1} - u_n`` with ``A u`` from face fluxes, which
    conserves heat to rounding; one banded LU solve per step for all K
    property sets at once. The first
    ``rannacher_steps`` steps are backward Euler at a quarter of the step, which
    damps the stiff components of the initial discontinuity that Crank-Nicolson
    alone would keep ringing (Rannacher, Numer. Math. 43 (1984) 309; Luskin &
    Rannacher, SIAM J. Numer. Anal. 19 (1982) 93). Readings at the requested
    times come from a cubic spline in log t through the readings at the levels.

    Parameters
    ----------
    grid : Grid
    times_s : array_like, shape (m,)
        Output times [s] (>= 0).
    step_ratio : float
        Time step over time reached (the resolution knob in time).
    rannacher_steps : int
        Backward-Euler quarter steps at the start (0 for plain Crank-Nicolson).
    return_state : bool
        Also return the final cell values (K, N) (for energy checks).

    Returns
    -------
    ndarray, shape (K, m)
        Thermistor readings; with ``return_state``, ``(readings, u_final, levels)``.
    """
    r = check_positive("step ratio", step_ratio)
    t_out = np.asarray(times_s, dtype=np.float64)
    levels = time_levels_s(t_out, r)
    m = grid.heat_capacities()
    g = grid.conductances()
    shape = m.shape
    m_band = _banded(m, g, 0.0)  # M in banded storage
    a_band = _banded(np.zeros_like(m), g, 1.0)  # A in banded storage
    u = np.broadcast_to(grid.initial, shape).astype(np.float64).ravel()

    def probe(v):
        return probe_reading(grid, v.reshape(shape))

    readings = np.empty((shape[0], levels.size))
    readings[:, 0] = probe(u)
    n_be = int(rannacher_steps)
    # Increment form, (M + theta dt A) du = -dt A u, with A u from face fluxes:
    # the fluxes telescope, so the total heat changes only by rounding of the
    # (small) increments; the textbook form loses ~eps * |dt A| / |M| per step.
    for j in range(1, levels.size):
        dt = levels[j] - levels[j - 1]
        if j == 1 and n_be > 0:
            sub = dt / n_be
            ab = m_band + sub * a_band
            for _ in range(n_be):  # backward Euler quarter steps
                u = u + linalg.solve_banded((1, 1), ab, -sub * apply_conductances(g, u.reshape(shape)).ravel(),
                                            check_finite=False)
        else:
            ab = m_band + (0.5 * dt) * a_band
            u = u + linalg.solve_banded((1, 1), ab, -dt * apply_conductances(g, u.reshape(shape)).ravel(),
                                        overwrite_ab=True, overwrite_b=True, check_finite=False)
        readings[:, j] = probe(u)
    u = u.reshape(shape)
    out = _interp_log_time(levels, readings, t_out)
    if return_state:
        return out, u, levels
    return out


def integrate_bdf(grid: Grid, times_s, rtol: float = 1e-6, atol: float = 1e-9, *,
                  return_state: bool = False):
    """Variable-order BDF (:func:`scipy.integrate.solve_ivp`, ``method="BDF"``).

    The Jacobian ``-M^-1 A`` is constant and tridiagonal; it is handed over as
    a sparse matrix, so every Newton step is a sparse LU solve. scipy's BDF is
    the variable-order (1-5) NDF family of Shampine & Reichelt (SIAM J. Sci.
    Comput. 18 (1997) 1): A-stable at orders 1-2, A(alpha)-stable above.

    Parameters
    ----------
    grid : Grid
    times_s : array_like, shape (m,)
        Output times [s] (>= 0).
    rtol, atol : float
        solve_ivp tolerances (the resolution knob in time; ``atol`` in units of
        the normalized temperature).

    Returns
    -------
    ndarray, shape (K, m)
        Thermistor readings; with ``return_state``, ``(readings, u_final, n_rhs)``
        (``n_rhs``: right-hand-side evaluations).
    """
    from scipy.integrate import solve_ivp

    t_out = np.asarray(times_s, dtype=np.float64)
    m = grid.heat_capacities()
    g = grid.conductances()
    k, n = m.shape
    u0 = np.broadcast_to(grid.initial, m.shape).astype(np.float64).ravel()
    t_end = float(t_out.max())
    out = np.empty((k, t_out.size))
    if t_end <= 0:
        out[:] = probe_reading(grid, u0.reshape(k, n))[:, None]
        return (out, u0.reshape(k, n), 0) if return_state else out
    inv_m = 1.0 / m

    def rhs(_t, y):
        return (-apply_conductances(g, y.reshape(k, n)) * inv_m).ravel()

    # -M^-1 A: A from its banded storage (ab[0, j] = a[j - 1, j], ab[1, j] = a[j, j], ab[2, j] = a[j + 1, j])
    a = sparse.dia_matrix((_banded(np.zeros_like(m), g, 1.0), [1, 0, -1]), shape=(k * n, k * n))
    jac = (sparse.diags(-inv_m.ravel()) @ a).tocsc()
    t_eval = np.unique(np.clip(t_out, 0.0, t_end))
    sol = solve_ivp(rhs, (0.0, t_end), u0, method="BDF", t_eval=t_eval, jac=jac,
                    rtol=rtol, atol=atol, first_step=min(t_end, float(t_eval[t_eval > 0].min())) * 1e-6)
    if not sol.success:  # pragma: no cover - solve_ivp failure is a bug to report
        raise RuntimeError(f"BDF integration failed: {sol.message}")
    ys = sol.y.reshape(k, n, -1)
    vals = probe_reading(grid, np.moveaxis(ys, -1, 0))  # (n_eval, K)
    pos = np.searchsorted(t_eval, np.clip(t_out, 0.0, t_end))
    out = vals[pos].T
    if return_state:
        return out, ys[:, :, -1], int(sol.nfev)
    return out
