"""Thin samples: the sensor touching an object slab of finite thickness on a backing.

The paper's model (:mod:`designkit.models.semi_infinite`, eqs. 1-2) treats sensor and object
as two semi-infinite solids; a real sample is a slab of thickness ``L`` on something (a
wooden table, a steel plate, air), and once heat has crossed it, what lies behind changes
the reading. This module gives the reading of a semi-infinite sensor (thermistor at depth
``x``) on an object slab (``e_o``, ``alpha_o``, ``L``) on a semi-infinite backing (``e_b``; or
an insulated back face, ``e_b = 0``), object and backing starting at ambient, perfect contact.

The closed form (method of images; derived in docs/thin_samples.md, after Carslaw & Jaeger,
*Conduction of Heat in Solids*, 2nd ed., 1959, sec. 12.8), with ``u = (T - Ts0) / (Ta - Ts0)``:

    u(t) = w [ erfc(sqrt(tau / t))
               - 2 (1 - w) sum_{n>=1} R_b^n R_s^(n-1) erfc((sqrt(tau) + 2 n sqrt(tau_L)) / sqrt(t)) ],

``w = e_o / (e_s + e_o)`` (eq. 1), reflection coefficients ``R_s = (e_o - e_s) / (e_o + e_s)``
and ``R_b = (e_o - e_b) / (e_o + e_b)`` (1 for an insulated back), ``tau = x^2 / (4 alpha_s)``
and ``tau_L = L^2 / (4 alpha_o)``. The series converges for every finite effusivity, faster
than geometrically once ``n >> sqrt(alpha_o t) / L``; the first term is the paper's eq. 2.

Which solver: :func:`slab_response` picks per scene (and says which): ``"semi-infinite"``
(eq. 2) when a bound on all reflected terms is below the tolerance (small Fourier number
``alpha_o t / L^2``); ``"image-series"``, truncated where its tail bound is below the
tolerance, when that takes a reasonable number of terms; ``"finite-volume"``
(:mod:`designkit.models.fv`) when the series would need too many terms, or on request.

Units: effusivity [J s^-1/2 K^-1 m^-2], diffusivity [m^2 s^-1], thickness and
depth [m], time [s], temperatures [degC].
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import special

from .._validation import InputError, check_effusivity, check_finite, check_positive
from .base import ForwardModel, ModelCheck
from .semi_infinite import SemiInfinite, object_weight, response_shape
from ..sensor import SENSORS, Sensor

__all__ = [
    "BACKINGS",
    "BACKING_ALIASES",
    "Backing",
    "FV_DEFAULTS",
    "SlabMaterial",
    "SlabResponse",
    "Validity",
    "MaterialValidity",
    "fourier_number",
    "image_series",
    "material_properties",
    "material_validity",
    "reflection_coefficients",
    "resolve_backing",
    "semi_infinite_deviation",
    "semi_infinite_error_bound",
    "semi_infinite_validity",
    "slab_response",
]

#: Methods :func:`slab_response` can use.
METHODS = ("auto", "semi-infinite", "image-series", "finite-volume")

#: Default finite-volume resolution: the cheapest setting of the error-versus-
#: run-time study (``benchmarks/bench_slab.py``, ``docs/thin_samples.md``)
#: whose worst-case error against the converged series is below 1e-3 degC at
#: a 10 degC sensor-object difference (1e-4 in normalized units).
FV_DEFAULTS: dict[str, Any] = {"integrator": "crank-nicolson", "cells_per_layer": 48, "step_ratio": 0.05}

_MAX_TERMS = 20000          # image terms the series may use before the FV solver takes over
_MAX_SERIES_WORK = 4e8      # terms x samples x objects per call (a few seconds of BLAS)


# ----------------------------------------------------------------------------- backings
@dataclass(frozen=True)
class Backing:
    """What lies behind the object slab.

    Parameters
    ----------
    name : str
    effusivity : float
        e_b [J s^-1/2 K^-1 m^-2]; 0 means an insulated back face (R_b = 1).
    diffusivity_m2_s : float
        alpha_b [m^2 s^-1]. The closed form does not need it; the
        finite-volume solver grids the backing with it. Ignored when insulated.
    source : str
        Where the numbers come from.
    """

    name: str
    effusivity: float
    diffusivity_m2_s: float = 1e-7
    source: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "effusivity",
                           check_effusivity(f"of backing {self.name!r}", self.effusivity, allow_zero=True))
        if self.effusivity > 0:
            object.__setattr__(self, "diffusivity_m2_s",
                               check_positive(f"diffusivity of backing {self.name!r} [m^2/s]",
                                              self.diffusivity_m2_s))

    @property
    def insulated(self) -> bool:
        return self.effusivity == 0.0


def _handbook(name: str, k: float, rho: float, c: float, source: str) -> Backing:
    return Backing(name, math.sqrt(k * rho * c), k / (rho * c), source)


#: Named backings that are not materials of the database. Any other name is
#: looked up in :mod:`designkit.materials` (at mid-range properties), after
#: :data:`BACKING_ALIASES`.
BACKINGS: dict[str, Backing] = {
    "insulated": Backing("insulated", 0.0, 0.0, "ideal: no heat crosses the back face"),
    "air": _handbook("air", 0.0263, 1.1614, 1007.0,
                     "Incropera, DeWitt, Bergman & Lavine, Fundamentals of Heat and Mass Transfer, "
                     "6th ed., Table A.4 (air at 300 K; still air, conduction only)"),
}

#: Backing names that stand for a database material.
BACKING_ALIASES: dict[str, str] = {"steel": "Low carbon steel", "table": "Hardwood, across grain"}


@dataclass(frozen=True)
class SlabMaterial:
    """Effusivity and diffusivity ranges of a named material (from the materials database)."""

    name: str
    e_min: float
    e_max: float
    diffusivity_min_m2_s: float
    diffusivity_max_m2_s: float

    @property
    def effusivity(self) -> float:
        """Mid-range effusivity [J s^-1/2 K^-1 m^-2]."""
        return 0.5 * (self.e_min + self.e_max)

    @property
    def diffusivity_m2_s(self) -> float:
        """Mid-range diffusivity [m^2 s^-1]."""
        return 0.5 * (self.diffusivity_min_m2_s + self.diffusivity_max_m2_s)


def material_properties(name: str) -> SlabMaterial:
    """Effusivity and diffusivity ranges of a material of :mod:`designkit.materials`.

    Raises
    ------
    InputError
        Unknown material, or a database without diffusivities.
    """
    try:
        from .. import materials
    except ImportError:  # pragma: no cover - the database ships with designkit
        raise InputError(f"no materials database available to look up {name!r}; "
                         "give the effusivity and diffusivity as numbers") from None
    mat = materials.get_material(name)
    try:
        return SlabMaterial(str(getattr(mat, "name", name)), float(mat.e_min), float(mat.e_max),
                            float(mat.diffusivity_min_m2_s), float(mat.diffusivity_max_m2_s))
    except AttributeError as exc:
        raise InputError(f"material {name!r} lacks a field the slab model needs ({exc.name})") from None


def resolve_backing(backing: "str | Backing | None") -> Backing:
    """A :class:`Backing` from a name or a Backing.

    ``insulated`` and ``air`` are built in (:data:`BACKINGS`); ``steel`` means
    low carbon steel and ``table`` a hardwood table top (:data:`BACKING_ALIASES`);
    any other name is a material of :mod:`designkit.materials` (``wood`` is the
    paper's wood), taken at the middle of its effusivity and diffusivity ranges.
    """
    if backing is None:
        return BACKINGS["insulated"]
    if isinstance(backing, Backing):
        return backing
    key = str(backing).strip().lower()
    if key in BACKINGS:
        return BACKINGS[key]
    name = BACKING_ALIASES.get(key, str(backing))
    try:
        mat = material_properties(name)
    except InputError as exc:
        raise InputError(f"unknown backing {backing!r} (use {', '.join([*BACKINGS, *BACKING_ALIASES])} "
                         f"or a material name): {exc}") from None
    return Backing(mat.name, mat.effusivity, mat.diffusivity_m2_s,
                   "designkit.materials, mid-range effusivity and diffusivity")


# ----------------------------------------------------------------------------- closed form
def fourier_number(diffusivity_m2_s, time_s, thickness_m):
    """Fourier number ``Fo = alpha t / L^2`` (dimensionless).

    Below about 0.05 the far face of the slab is invisible at the contact
    (the first image term is ``erfc(1 / sqrt(Fo))``, 2e-6 at 0.05).
    """
    a = np.asarray(diffusivity_m2_s, dtype=np.float64)
    t = np.asarray(time_s, dtype=np.float64)
    L = np.asarray(thickness_m, dtype=np.float64)
    return a * t / (L * L)


def reflection_coefficients(e_object, e_backing, e_sensor):
    """Contact weight and reflection coefficients ``(w, R_s, R_b)``.

    ``w = e_o / (e_s + e_o)`` (paper eq. 1), ``R_s = (e_o - e_s) / (e_o + e_s)
    = 2 w - 1``, ``R_b = (e_o - e_b) / (e_o + e_b)`` (1 for an insulated back,
    ``e_b = 0``). Exact at ``e_o = 0`` and ``e_o = inf``.
    """
    eo = np.asarray(e_object, dtype=np.float64)
    eb = np.asarray(e_backing, dtype=np.float64)
    w = object_weight(e_sensor, eo)
    # e_o / (e_b + e_o); 0/0 (no object on an insulated back) carries no heat
    # either way (w = 0): take R_b = 0 there instead of NaN
    both_zero = (eo == 0) & (eb == 0)
    wb = np.where(both_zero, 0.5, object_weight(np.where(both_zero, 1.0, eb), eo))
    return w, 2.0 * w - 1.0, 2.0 * wb - 1.0


def _reflected_bound(w, rs, rb, sqrt_tau, flight, time_s: float, n_terms):
    """Bound on the image terms after the first ``n_terms``, per object (K,), at times up to ``time_s``.

    Term n has magnitude ``A |r|^(n-1) erfc(a_n)`` with ``A = 2 w (1 - w) |R_b|``,
    ``r = R_b R_s``, ``a_n = (sqrt(tau) + n * flight) / sqrt(t)``; erfc(a_n)
    falls with n (and grows with t), so the tail after N terms is at most
    ``A |r|^N erfc(a_{N+1}) / (1 - |r|)``. ``n_terms = 0``: all reflected heat.
    """
    amp = 2.0 * w * (1.0 - w) * np.abs(rb)  # (K,)
    r = np.abs(rb * rs)
    # |r| < 1 whenever amp > 0 (finite, positive e_o); e_o = 0 or inf carry no reflections
    geo_tail = np.where(amp == 0.0, 0.0, amp / np.where(r < 1.0, 1.0 - r, 1.0))
    with np.errstate(under="ignore"):
        erfc_next = special.erfc((sqrt_tau + (n_terms + 1.0) * flight) / math.sqrt(time_s))
        return np.where(amp == 0.0, 0.0, geo_tail * r ** n_terms * erfc_next)


def _series_terms(w, rs, rb, sqrt_tau, flight, t_max, tolerance, max_terms):
    """Terms needed so that the tail bound (:func:`_reflected_bound`) is below ``tolerance``, and that bound."""
    if t_max <= 0:
        return 0, 0.0

    def tail(n_terms):  # bound after n_terms terms, per object (K,)
        return _reflected_bound(w, rs, rb, sqrt_tau, flight, t_max, n_terms)

    b_max = tail(np.full(w.shape, float(max_terms)))
    if np.any(b_max > tolerance):
        return None, float(b_max.max())
    # tail(N) falls with N: bisection for the smallest N meeting the tolerance, per object
    lo = np.full(w.shape, -1.0)  # tail(lo) > tol (or lo = -1)
    hi = np.full(w.shape, float(max_terms))  # tail(hi) <= tol
    while np.any(hi - lo > 1):
        mid = np.floor(0.5 * (lo + hi))
        good = tail(mid) <= tolerance
        hi = np.where(good, mid, hi)
        lo = np.where(good, lo, mid)
    n_terms = int(hi.max())
    return n_terms, float(tail(np.full(w.shape, float(n_terms))).max())


def image_series(time_s, e_object, alpha_object_m2_s, thickness_m, e_backing, e_sensor, tau_s, *,
                 n_terms: int):
    """Normalized reading ``u = (T - Ts0) / (Ta - Ts0)`` from the image series (module docstring).

    Parameters
    ----------
    time_s : array_like, shape (m,)
        Times after contact [s] (>= 0).
    e_object : array_like, shape (K,)
        Object effusivities [J s^-1/2 K^-1 m^-2] (0 and inf allowed).
    alpha_object_m2_s : float or array_like, shape (K,)
        Object diffusivity [m^2 s^-1].
    thickness_m : float
        Slab thickness L [m] (inf: semi-infinite).
    e_backing : float
        Backing effusivity [J s^-1/2 K^-1 m^-2]; 0 = insulated back.
    e_sensor : float
        Sensor effusivity e_s.
    tau_s : float
        Sensor time constant x^2 / (4 alpha_s) [s].
    n_terms : int
        Reflected terms to sum (0: the paper's eq. 2 alone).

    Returns
    -------
    ndarray, shape (K, m)
        u(t); the reading is ``Ts0 + (Ta - Ts0) * u``.
    """
    t = np.atleast_1d(np.asarray(time_s, dtype=np.float64))
    e = np.atleast_1d(np.asarray(e_object, dtype=np.float64))
    alpha = np.broadcast_to(np.asarray(alpha_object_m2_s, dtype=np.float64), e.shape)
    w, rs, rb = reflection_coefficients(e, e_backing, e_sensor)
    out = w[:, None] * response_shape(t, tau_s)[None, :]
    if n_terms <= 0 or not math.isfinite(thickness_m):
        return out
    sqrt_tau = math.sqrt(tau_s)
    n = np.arange(1, n_terms + 1, dtype=np.float64)
    # coefficient of term n: -2 w (1 - w) R_b^n R_s^(n-1)  (R_s^0 = 1 also when R_s = 0)
    coef = -2.0 * (w * (1.0 - w))[:, None] * rb[:, None] ** n[None, :] * rs[:, None] ** (n - 1.0)[None, :]
    pos = t > 0
    if not np.any(pos):
        return out
    sqt = np.sqrt(t[pos])
    # objects of one diffusivity share the erfc matrix: group them
    for a in np.unique(alpha):
        rows = np.nonzero(alpha == a)[0]
        flight = thickness_m / math.sqrt(a)  # 2 sqrt(tau_L)
        # chunk the (terms x times) matrix to bound memory (~16 MB per chunk)
        step = max(1, int(2_000_000 // max(n_terms, 1)))
        for j0 in range(0, sqt.size, step):
            st = sqt[j0:j0 + step]
            with np.errstate(under="ignore"):
                g = special.erfc((sqrt_tau + n[:, None] * flight) / st[None, :])  # (N, mc)
            idx = np.nonzero(pos)[0][j0:j0 + step]
            out[np.ix_(rows, idx)] += coef[rows] @ g
    return out


# ----------------------------------------------------------------------------- entry point
@dataclass(frozen=True)
class SlabResponse:
    """Sensor response for one slab scene and ``K`` object effusivities.

    Attributes
    ----------
    time_s : ndarray, shape (m,)
        Times after contact [s].
    e_object : ndarray, shape (K,)
        Object effusivities [J s^-1/2 K^-1 m^-2].
    response : ndarray, shape (K, m)
        Normalized reading ``u = (T - Ts0) / (Ta - Ts0)`` (0 before contact;
        the paper's semi-infinite value is ``w erfc(sqrt(tau / t))``).
        Use :meth:`temperature_c` for degrees.
    method : str
        ``"semi-infinite"``, ``"image-series"`` or ``"finite-volume"``.
    error_bound : float
        Estimated worst-case error of ``response`` (normalized; times
        ``|Ts0 - Ta|`` for degC). A rigorous bound for the closed forms (the
        omitted terms); for the finite-volume solver, a Richardson estimate
        from a second run at half resolution.
    fourier_number : float
        ``alpha_o t_max / L^2`` (largest over the objects); 0 for L = inf.
    n_terms : int
        Image terms summed (0 for the semi-infinite and finite-volume methods).
    details : dict
        Solver settings (grid cells, integrator, ...).
    """

    time_s: np.ndarray
    e_object: np.ndarray
    response: np.ndarray
    method: str
    error_bound: float
    fourier_number: float
    n_terms: int = 0
    details: dict = field(default_factory=dict, compare=False)

    def temperature_c(self, sensor_temp_c, ambient_temp_c) -> np.ndarray:
        """Noise-free readings ``Ts0 + (Ta - Ts0) u`` [degC], shape (K, m).

        ``sensor_temp_c`` and ``ambient_temp_c`` broadcast against (K, 1)
        (scalars, or one value per object).
        """
        ts = np.asarray(sensor_temp_c, dtype=np.float64)
        ta = np.asarray(ambient_temp_c, dtype=np.float64)
        if ts.ndim == 1:
            ts = ts[:, None]
        if ta.ndim == 1:
            ta = ta[:, None]
        return ts + (ta - ts) * self.response


def _check_times(time_s) -> np.ndarray:
    t = np.atleast_1d(np.asarray(time_s, dtype=np.float64))
    if t.ndim != 1 or t.size == 0:
        raise InputError("times must be a non-empty 1-D array [s]")
    if not np.all(np.isfinite(t)) or np.any(t < 0):
        raise InputError("times must be finite and >= 0 [s]")
    return t


def _check_objects(e_object, alpha_object_m2_s):
    e = np.atleast_1d(np.asarray(e_object, dtype=np.float64))
    if e.ndim != 1 or e.size == 0:
        raise InputError("object effusivities must be a number or a 1-D array")
    if np.any(np.isnan(e)) or np.any(e < 0):
        bad = e[np.isnan(e) | (e < 0)][0]
        raise InputError(f"object effusivity must be >= 0, got {bad:g}")
    a = np.asarray(alpha_object_m2_s, dtype=np.float64)
    if a.ndim > 1 or (a.ndim == 1 and a.size not in (1, e.size)):
        raise InputError(f"give one object diffusivity or one per effusivity ({e.size}), got {a.size}")
    a = np.broadcast_to(a.reshape(-1) if a.ndim else a, e.shape).astype(np.float64)
    if not np.all(np.isfinite(a)) or np.any(a <= 0):
        bad = a[~(np.isfinite(a) & (a > 0))][0]
        raise InputError(f"object diffusivity must be positive and finite [m^2/s], got {bad:g}")
    return e, a


def _scene(e_object, alpha_object_m2_s, thickness_m, backing, sensor):
    """Checked objects, thickness, backing and sensor of a slab scene: ``(e, alpha, L, backing, sensor)``."""
    e, alpha = _check_objects(e_object, alpha_object_m2_s)
    L = check_positive("object thickness [m]", thickness_m, allow_inf=True)
    return e, alpha, L, resolve_backing(backing), SENSORS["paper"] if sensor is None else sensor


def slab_response(time_s, e_object, alpha_object_m2_s, thickness_m, backing="insulated",
                  sensor: Sensor | None = None, *, tolerance: float = 1e-5, method: str = "auto",
                  max_terms: int = 20000, cells_per_layer: int | None = None,
                  step_ratio: float | None = None, integrator: str | None = None) -> SlabResponse:
    """Sensor response to an object slab on a backing: the solver is chosen per scene.

    Parameters
    ----------
    time_s : array_like, shape (m,)
        Times after contact [s] (>= 0), e.g. ``sensor.times_s(contact_s)``.
    e_object : float or array_like, shape (K,)
        Object effusivities [J s^-1/2 K^-1 m^-2] (0 and inf allowed on the
        closed-form paths), e.g. one per effusivity class.
    alpha_object_m2_s : float or array_like, shape (K,)
        Object diffusivity [m^2 s^-1].
    thickness_m : float
        Slab thickness L [m] (> 0; ``inf`` for the paper's semi-infinite object).
    backing : str or Backing
        ``"insulated"`` (default), ``"air"``, ``"wood"``, ``"steel"``, a
        material of the database, or a :class:`Backing`.
    sensor : Sensor, optional
        Defaults to the paper's sensor.
    tolerance : float
        Largest acceptable error of the normalized response (default 1e-5,
        i.e. 1e-4 degC at a 10 degC sensor-object difference). Decides the
        method and the number of image terms.
    method : {"auto", "semi-infinite", "image-series", "finite-volume"}
        ``auto`` takes the cheapest method that meets ``tolerance``:
        semi-infinite if all reflections together are below it, else the image
        series if it needs at most ``max_terms`` terms and a bounded amount of
        work (terms x samples x objects <= 4e8), else finite volumes.
        ``semi-infinite`` forces the paper's model (its ``error_bound`` then
        says how wrong it is).
    max_terms : int
        Most image terms the series may use (default 20,000).
    cells_per_layer, step_ratio, integrator : optional
        Finite-volume resolution (defaults: :data:`FV_DEFAULTS`); integrator
        ``"crank-nicolson"`` or ``"bdf"``.

    Returns
    -------
    SlabResponse
        ``response[k, j]`` for object ``k`` at time ``j``, with the method used
        and its error bound.

    Examples
    --------
    >>> import numpy as np
    >>> from designkit.models.slab import slab_response
    >>> r = slab_response(np.array([1.0, 4.0]), 583.0, 1.18e-7, 0.003, "steel")
    >>> r.method  # 3 mm of acrylic: no reflection reaches the thermistor within 4 s
    'semi-infinite'
    >>> r = slab_response(np.array([1.0, 10.0]), 583.0, 1.18e-7, 0.001, "steel")
    >>> r.method, r.n_terms, r.response.shape  # 1 mm, 10 s: it does
    ('image-series', 2, (1, 2))
    """
    t = _check_times(time_s)
    e, alpha, L, back, sen = _scene(e_object, alpha_object_m2_s, thickness_m, backing, sensor)
    tol = check_positive("tolerance", tolerance)
    if method not in METHODS:
        raise InputError(f"unknown method {method!r}: use one of {', '.join(METHODS)}")
    t_max = float(t.max())
    fo = float(fourier_number(alpha.max(), t_max, L)) if math.isfinite(L) else 0.0
    tau = sen.tau_s
    w, rs, rb = reflection_coefficients(e, back.effusivity, sen.effusivity)
    flight = (L / np.sqrt(alpha)) if math.isfinite(L) else np.full(e.shape, np.inf)
    sqrt_tau = math.sqrt(tau)
    base = dict(time_s=t, e_object=e, fourier_number=fo)

    # bound on everything the semi-infinite model leaves out (all reflected terms)
    if math.isfinite(L) and t_max > 0:
        _, bound0 = _series_terms(w, rs, rb, sqrt_tau, flight, t_max, np.inf, 0)
    else:
        bound0 = 0.0
    if method == "semi-infinite" or (method == "auto" and bound0 <= tol):
        u = image_series(t, e, alpha, L, back.effusivity, sen.effusivity, tau, n_terms=0)
        return SlabResponse(response=u, method="semi-infinite", error_bound=bound0, **base)

    if method in ("auto", "image-series"):
        cap = int(max_terms)
        if cap < 1:
            raise InputError(f"max_terms must be >= 1, got {max_terms}")
        n_terms, bound = _series_terms(w, rs, rb, sqrt_tau, flight, t_max, tol, cap)
        affordable = n_terms is not None and n_terms * t.size * e.size <= _MAX_SERIES_WORK
        if method == "image-series" and n_terms is None:
            raise InputError(f"the image series needs more than {cap} terms for tolerance {tol:g} "
                             "here; use the finite-volume method")
        if method == "image-series" or affordable:
            u = image_series(t, e, alpha, L, back.effusivity, sen.effusivity, tau, n_terms=n_terms)
            return SlabResponse(response=u, method="image-series", error_bound=bound, n_terms=n_terms,
                                **base)

    return _finite_volume(t, e, alpha, L, back, sen, base, cells_per_layer, step_ratio, integrator)


def _fv_solve(t, e, alpha, L, back, sen, cells, ratio, integrator):
    from . import fv

    if sen.depth_m <= 0:
        raise InputError("the finite-volume solver needs a buried thermistor (depth > 0)")
    if np.any(e <= 0) or np.any(~np.isfinite(e)):
        raise InputError("the finite-volume solver needs positive, finite object effusivities")
    t_pos = t[t > 0]
    if t_pos.size == 0:
        return np.zeros((e.size, t.size)), {}
    # earliest time whose reading can exceed ~1e-9: erfc(sqrt(tau/t)) = 1e-9
    t_min = max(sen.tau_s / float(special.erfcinv(1e-9)) ** 2, float(t_pos.min()))
    sensor_layer = fv.Layer(sen.effusivity, sen.diffusivity_m2_s, math.inf, 0.0)
    out = np.empty((e.size, t.size))
    cells_used = 0
    for a in np.unique(alpha):
        rows = np.nonzero(alpha == a)[0]
        body = [fv.Layer(e[rows], float(a), L, 1.0)]
        if not back.insulated and math.isfinite(L):
            body.append(fv.Layer(back.effusivity, back.diffusivity_m2_s, math.inf, 1.0))
        grid = fv.build_grid(sensor_layer, body, sen.depth_m, float(t.max()), cells,
                             time_min_s=min(t_min, float(t.max())))
        cells_used = max(cells_used, grid.n_cells)
        if integrator == "bdf":
            out[rows] = fv.integrate_bdf(grid, t, rtol=ratio, atol=ratio * 1e-3)
        else:
            out[rows] = fv.integrate_crank_nicolson(grid, t, step_ratio=ratio)
    return out, {"cells": cells_used}


def _finite_volume(t, e, alpha, L, back, sen, base, cells, ratio, integrator) -> SlabResponse:
    integ = FV_DEFAULTS["integrator"] if integrator is None else integrator
    if integ not in ("crank-nicolson", "bdf"):
        raise InputError(f"unknown integrator {integ!r}: use crank-nicolson or bdf")
    n = int(FV_DEFAULTS["cells_per_layer"] if cells is None else cells)
    if integ == "bdf":
        r = 1e-6 if ratio is None else check_positive("rtol", ratio)
    else:
        r = float(FV_DEFAULTS["step_ratio"] if ratio is None else check_positive("step ratio", ratio))
    fine, info = _fv_solve(t, e, alpha, L, back, sen, n, r, integ)
    # Richardson: the scheme is second order in space and time, so halving
    # both resolutions quadruples the error; |fine - coarse| / 3 estimates it.
    coarse, _ = _fv_solve(t, e, alpha, L, back, sen, max(4, n // 2), r * (2.0 if integ != "bdf" else 4.0),
                          integ)
    err = float(np.max(np.abs(fine - coarse))) / 3.0 if fine.size else 0.0
    details = {"integrator": integ, "cells_per_layer": n, "step_ratio" if integ != "bdf" else "rtol": r}
    details.update(info)
    return SlabResponse(response=fine, method="finite-volume", error_bound=err, details=details, **base)


# ----------------------------------------------------------------------------- validity
def semi_infinite_deviation(time_s, e_object, alpha_object_m2_s, thickness_m, backing="insulated",
                            sensor: Sensor | None = None, *, tolerance: float = 1e-9) -> np.ndarray:
    """Slab reading minus the semi-infinite reading, normalized: shape (K, m).

    ``u_slab - u_semi`` (times ``Ta - Ts0`` for degC): the sum of all
    reflected image terms.
    """
    t = _check_times(time_s)
    e, alpha, L, back, sen = _scene(e_object, alpha_object_m2_s, thickness_m, backing, sensor)
    if not math.isfinite(L):
        return np.zeros((e.size, t.size))
    w, rs, rb = reflection_coefficients(e, back.effusivity, sen.effusivity)
    n_terms, _ = _series_terms(w, rs, rb, math.sqrt(sen.tau_s), L / np.sqrt(alpha), float(t.max()),
                               tolerance, _MAX_TERMS)
    if n_terms is None:
        n_terms = _MAX_TERMS
    full = image_series(t, e, alpha, L, back.effusivity, sen.effusivity, sen.tau_s, n_terms=n_terms)
    return full - image_series(t, e, alpha, L, back.effusivity, sen.effusivity, sen.tau_s, n_terms=0)


def semi_infinite_error_bound(contact_s, e_object, alpha_object_m2_s, thickness_m, backing="insulated",
                              sensor: Sensor | None = None) -> np.ndarray:
    """Rigorous bound on ``|u_slab - u_semi|`` over ``[0, contact_s]``, per object (cheap).

    ``2 w (1 - w) |R_b| erfc((sqrt(tau) + L / sqrt(alpha_o)) / sqrt(t)) / (1 - |R_b R_s|)``
    at ``t = contact_s`` (it grows with t): all reflected image terms together
    (module docstring). Times ``|Ts0 - Ta|`` for degC. A quick, conservative
    test of whether a semi-infinite table answers a thin-sample scene, e.g. for
    a warning; :func:`semi_infinite_validity` gives the exact time instead.

    Returns
    -------
    ndarray, shape (K,)
        Normalized bound; 0 for ``L = inf``.
    """
    t = check_positive("contact time [s]", contact_s)
    e, alpha, L, back, sen = _scene(e_object, alpha_object_m2_s, thickness_m, backing, sensor)
    if not math.isfinite(L):
        return np.zeros(e.shape)
    w, rs, rb = reflection_coefficients(e, back.effusivity, sen.effusivity)
    return _reflected_bound(w, rs, rb, math.sqrt(sen.tau_s), L / np.sqrt(alpha), t, 0)


@dataclass(frozen=True)
class Validity:
    """How long the semi-infinite model holds for a slab scene.

    Attributes
    ----------
    time_s : float
        Longest contact time [s] up to which ``|T_slab - T_semi| <= tolerance_c``
        at every instant, for every object considered (inf if beyond ``horizon_s``).
    tolerance_c, delta_t_c : float
        Tolerance [degC] and sensor-object temperature difference [degC] used.
    fourier_number : float
        ``alpha_o time_s / L^2`` at the limiting object (inf if time_s is).
    e_object, alpha_object_m2_s : float
        The limiting (worst-case) object's effusivity and diffusivity.
    thickness_m : float
    backing : str
    horizon_s : float
        Longest time examined [s].
    """

    time_s: float
    tolerance_c: float
    delta_t_c: float
    fourier_number: float
    e_object: float
    alpha_object_m2_s: float
    thickness_m: float
    backing: str
    horizon_s: float

    def to_dict(self) -> dict[str, Any]:
        from dataclasses import asdict

        return asdict(self)


def semi_infinite_validity(e_object, alpha_object_m2_s, thickness_m, backing="insulated",
                           sensor: Sensor | None = None, *, delta_t_c: float = 10.0,
                           tolerance_c: float = 0.01, horizon_s: float = 3600.0) -> Validity:
    """The contact time up to which the paper's semi-infinite answer is within a tolerance.

    The semi-infinite model is exact until heat reflected from the slab's far
    face reaches the thermistor; the difference is the sum of image terms
    (:func:`semi_infinite_deviation`) times ``|Ts0 - Ta|``. This returns the
    first time it exceeds ``tolerance_c`` (found on a log-time grid, refined by
    :func:`scipy.optimize.brentq`), the worst case over all object
    properties given (e.g. the corners of a material's ranges).

    Parameters
    ----------
    e_object, alpha_object_m2_s : float or array_like
        Object effusivities and diffusivities; every pair of the two (outer
        product) is examined.
    thickness_m : float
        Slab thickness [m].
    backing : str or Backing
    sensor : Sensor, optional
    delta_t_c : float
        Sensor-object temperature difference [degC] (the deviation scales with it).
    tolerance_c : float
        Acceptable deviation [degC] (default 0.01 degC, the smallest noise level
        of the paper's experiments: a bias below one noise standard deviation of
        the quietest sensor considered).
    horizon_s : float
        Longest time examined [s].
    """
    from scipy.optimize import brentq

    L = check_positive("object thickness [m]", thickness_m, allow_inf=True)
    dt = abs(check_finite("temperature difference [degC]", delta_t_c))
    tol = check_positive("tolerance [degC]", tolerance_c)
    horizon = check_positive("horizon [s]", horizon_s)
    if horizon > 1e9:  # about 30 years of contact; beyond it the root finder cannot converge (1e300 did not)
        raise InputError(f"horizon must be at most 1e9 s, got {horizon:g}")
    if math.isfinite(L) and L > 1e6:  # 1e308 overflowed; a slab this thick is semi-infinite for any contact
        raise InputError(f"object thickness must be at most 1e6 m (or inf), got {L:g} m")
    back = resolve_backing(backing)
    sen = SENSORS["paper"] if sensor is None else sensor
    e = np.atleast_1d(np.asarray(e_object, dtype=np.float64)).ravel()
    a = np.atleast_1d(np.asarray(alpha_object_m2_s, dtype=np.float64)).ravel()
    ee, aa = (v.ravel() for v in np.meshgrid(e, a, indexing="ij"))
    _check_objects(ee, aa)
    if dt == 0 or not math.isfinite(L):  # nothing to deviate, or nothing to reflect from
        return Validity(math.inf, tol, dt, math.inf, float(ee[0]), float(aa[0]), L, back.name, horizon)
    # log-time grid from well before the first reflection can matter to the horizon
    t_first = max(min(1e-3, horizon), horizon * 1e-9)
    grid = np.geomspace(t_first, horizon, 600)
    best = (math.inf, 0)
    for k in range(ee.size):
        dev = dt * np.abs(semi_infinite_deviation(grid, ee[k], aa[k], L, back, sen)[0])
        over = np.nonzero(dev > tol)[0]
        if over.size == 0:
            continue
        j = int(over[0])

        def f(tt, k=k):
            return dt * abs(float(semi_infinite_deviation(np.array([tt]), ee[k], aa[k], L, back,
                                                          sen)[0, 0])) - tol
        # the deviation is 0 at t = 0, so [0, grid[0]] brackets a first crossing there
        lo = float(grid[j - 1]) if j > 0 else 0.0
        t_cross = brentq(f, lo, float(grid[j]), xtol=1e-12, rtol=1e-10)
        if t_cross < best[0]:
            best = (t_cross, k)
    t_valid, k = best
    fo = float(fourier_number(aa[k], t_valid, L)) if math.isfinite(t_valid) else math.inf
    return Validity(t_valid, tol, dt, fo, float(ee[k]), float(aa[k]), L, back.name, horizon)


@dataclass(frozen=True)
class MaterialValidity:
    """Validity of the semi-infinite model for a named material (see :func:`material_validity`).

    Attributes
    ----------
    material : SlabMaterial
    nominal : Validity
        At the middle of the material's effusivity and diffusivity ranges.
    worst : Validity
        The shortest validity over the corners of the ranges (and the middle).
    """

    material: SlabMaterial
    nominal: Validity
    worst: Validity


def material_validity(name: str, thickness_m: float, backing="insulated", sensor: Sensor | None = None,
                      *, delta_t_c: float = 10.0, tolerance_c: float = 0.01,
                      horizon_s: float = 3600.0) -> MaterialValidity:
    """:func:`semi_infinite_validity` for a material of :mod:`designkit.materials`.

    Reports the mid-range value and the worst case over the corners of the
    material's effusivity and diffusivity ranges (a thinner validity for the
    most diffusive grade).
    """
    mat = material_properties(name)
    kw = dict(delta_t_c=delta_t_c, tolerance_c=tolerance_c, horizon_s=horizon_s)
    nominal = semi_infinite_validity(mat.effusivity, mat.diffusivity_m2_s, thickness_m, backing, sensor, **kw)
    worst = semi_infinite_validity([mat.e_min, mat.effusivity, mat.e_max],
                                   [mat.diffusivity_min_m2_s, mat.diffusivity_m2_s, mat.diffusivity_max_m2_s],
                                   thickness_m, backing, sensor, **kw)
    return MaterialValidity(mat, nominal, worst)


# ----------------------------------------------------------------------------- the forward model
@dataclass(frozen=True)
class Slab(ForwardModel):
    """An object of finite thickness on a backing: the thin-sample forward model.

    The reading is :func:`slab_response` (image series while it converges
    cheaply, finite volumes otherwise, each to the requested tolerance); it
    needs each object's diffusivity as well as its effusivity. With
    ``thickness_m = inf`` it is the paper's semi-infinite model.

    Parameters
    ----------
    thickness_m : float
        Slab thickness L [m] (> 0, ``inf`` allowed).
    backing : str or Backing
        What lies behind the slab (:func:`resolve_backing`; default a hardwood
        table top, ``"table"``).

    Examples
    --------
    >>> from designkit import SENSORS
    >>> m = Slab(0.003, "table")
    >>> u = m.response([0.5, 8.0], [600.0], SENSORS["paper"], diffusivity_m2_s=[1.1e-7])
    >>> u.shape
    (1, 2)
    """

    thickness_m: float = 0.003
    backing: Any = "table"

    name = "slab"
    shared_shape = False
    object_properties = ("effusivity", "diffusivity_m2_s")
    units = {"thickness_m": "m"}

    def __post_init__(self) -> None:
        if self.thickness_m is None:  # what to_dict() writes for inf (JSON has no infinity)
            object.__setattr__(self, "thickness_m", math.inf)
        object.__setattr__(self, "thickness_m",
                           check_positive("object thickness [m]", self.thickness_m, allow_inf=True))
        b = self.backing
        if isinstance(b, dict):
            b = Backing(**{k: v for k, v in b.items() if k in ("name", "effusivity", "diffusivity_m2_s", "source")})
        object.__setattr__(self, "backing", resolve_backing(b))

    def solve(self, time_s, e_object, sensor, *, diffusivity_m2_s, tolerance: float = 1e-5) -> SlabResponse:
        """The full :class:`SlabResponse` (method used, error bound, Fourier number)."""
        return slab_response(time_s, e_object, diffusivity_m2_s, self.thickness_m, self.backing, sensor,
                             tolerance=tolerance)

    def response(self, time_s, e_object, sensor, *, diffusivity_m2_s=None, tolerance: float = 1e-5) -> np.ndarray:
        if diffusivity_m2_s is None:
            raise InputError("the slab model needs each object's diffusivity [m^2/s]: "
                             "effusivity alone does not fix a thin sample's reading")
        return self.solve(time_s, e_object, sensor, diffusivity_m2_s=diffusivity_m2_s,
                          tolerance=max(float(tolerance), 1e-12)).response

    def parameters(self) -> dict[str, Any]:
        b = self.backing
        return {"thickness_m": None if math.isinf(self.thickness_m) else self.thickness_m,
                "backing": {"name": b.name, "effusivity": b.effusivity,
                            "diffusivity_m2_s": None if b.insulated else b.diffusivity_m2_s}}

    def describe(self) -> str:
        if math.isinf(self.thickness_m):
            return "slab (semi-infinite object)"
        return f"slab ({self.thickness_m * 1e3:g} mm on {self.backing.name})"

    def deviation_bound(self, objects, sensor, contact_s: float) -> float:
        """Rigorous bound on ``max_t |u_slab - u_semi|`` up to ``contact_s`` for any object of the classes.

        :func:`semi_infinite_error_bound` at each class's highest diffusivity,
        on 65 effusivities across its range (normalized units).
        """
        if math.isinf(self.thickness_m):
            return 0.0
        worst = 0.0
        for obj in objects:
            e = np.linspace(obj.e_range[0], obj.e_range[1], 65)
            b = semi_infinite_error_bound(contact_s, e, obj.diffusivity_range_m2_s[1], self.thickness_m,
                                          self.backing, sensor)
            worst = max(worst, float(b.max()))
        return worst

    def equivalent_shared_shape(self, objects, sensor, *, contact_s: float, tolerance: float):
        """The semi-infinite model where all reflected heat stays below ``tolerance``."""
        return SemiInfinite() if self.deviation_bound(objects, sensor, contact_s) <= tolerance else None

    def check(self, objects, sensor, *, contact_s: float, noise_c: float, delta_t_c: float) -> ModelCheck:
        """The slab model holds for any thickness; says when the semi-infinite one would too."""
        dev_c = self.deviation_bound(objects, sensor, contact_s) * abs(delta_t_c)
        frac = math.inf if noise_c == 0 and dev_c > 0 else (dev_c / noise_c if noise_c > 0 else 0.0)
        msg = (f"the far face is invisible within {contact_s:g} s (reflected heat <= {dev_c:.2g} degC): "
               "the semi-infinite model and its tables hold" if frac <= 0.1 else
               f"the far face changes the reading by up to {dev_c:.2g} degC within {contact_s:g} s: "
               "semi-infinite answers would not hold")
        return ModelCheck(self.name, True, msg, {"deviation_bound_c": dev_c, "noise_fraction": frac,
                                                 "semi_infinite_holds": frac <= 0.1})
