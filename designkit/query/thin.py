"""Design questions for thin samples: a slab of thickness L on a backing.

The shipped tables (and :mod:`designkit.query`) answer for the paper's
semi-infinite objects. A sheet lying on a table is one only until heat
reflected at its back face reaches the thermistor (:mod:`designkit.slab`);
after that the curve's *shape* depends on the object (effusivity and
diffusivity) and on what lies behind it, so a thin-sample scene is computed on
demand here:

* **simulated touches** follow the draw protocol of
  :mod:`designkit.simulation` (effusivity uniform in the class, optional
  temperature offsets, time-major standard normal noise, so that truncating a
  touch equals touching for less time) plus, from an independent stream, a
  diffusivity uniform in the class's diffusivity range (the materials database
  gives independent ranges, not correlations). The noise-free reading is
  :func:`designkit.slab.slab_response`, vectorized over the trials. With the
  same seed and a slab too thick to matter, the readings are those of
  :func:`designkit.simulation.simulate_interval`;
* **the SVM** is the paper's pipeline (:func:`designkit.recognition.cross_validated_f1`),
  with repeated seeds as in :func:`designkit.query.exact_min_contact`;
* **the ideal observer** is the Bayes classifier on the full curve. The
  one-shape closed form of :mod:`designkit.ideal` needs every curve of a scene
  to share ``g(t) = erfc(sqrt(tau/t))``, which a slab breaks, so each class's
  likelihood ``p(y | class)`` is the Gaussian likelihood of the whole touch
  averaged over a midpoint grid of the class's effusivity (and diffusivity)
  range, fine enough that neighbouring grid curves differ by at most half
  the noise (arc length of the curve family in noise units; sampled at
  spacing h, a unit Gaussian sums to its integral within 2 exp(-2 pi^2 / h^2)
  by Poisson summation, so what is left is the class edges; the tests check
  the result against the closed form and against two known curves). Test touches
  are simulated, classified by the log-likelihood ratio and scored; the result
  carries its Monte Carlo standard error. For speed the curves and touches are
  projected on an orthonormal basis of the curve family (SVD), truncated only
  where every grid curve is reproduced to 1 % of the noise; the part of a
  touch outside the basis is common to all hypotheses and cancels from the
  ratio. When the slab is invisible within the contact (all reflected heat
  together changes the curve by less than 1 % of the noise, in norm, by the
  rigorous bound :func:`designkit.slab.semi_infinite_error_bound`), the exact
  closed form of :mod:`designkit.ideal` answers instead, and says so.

Every answer also says whether a semi-infinite table would have held
(:func:`semi_infinite_check`): the first contact time at which the slab
changes the reading by more than a fraction (default 0.1) of the noise sigma,
by :func:`designkit.slab.semi_infinite_validity`, against the contact times
the question needs.

Only fixed initial conditions are supported by the ideal observer here (the
query layer asks nothing else).

Units: effusivity [J s^-1/2 K^-1 m^-2], diffusivity [m^2 s^-1], thickness
[m], time [s], temperatures and noise [degC].
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from scipy import special

from .._validation import (
    InputError,
    as_generator,
    check_effusivity,
    check_effusivity_range,
    check_finite,
    check_positive,
)
from ..recognition.ideal import IdealResult, ideal_pair, score_llr
from ..scene import Scene
from ..sensor import Sensor
from ..simulation import draw_trials
from ..models.slab import Backing, resolve_backing, semi_infinite_error_bound, semi_infinite_validity, slab_response

__all__ = [
    "DEFAULT_BACKING",
    "NOISE_FRACTION",
    "SemiInfiniteCheck",
    "SlabIdeal",
    "SlabObject",
    "SlabScene",
    "SlabTrials",
    "semi_infinite_check",
    "simulate_slab_class",
    "slab_deviation_norm",
    "slab_ideal_pair",
    "slab_object",
    "slab_objects",
    "slab_pair_f1",
    "thin_delta_e",
    "thin_distinguishable",
    "thin_max_noise",
    "thin_min_contact",
    "thin_min_delta_t",
]

#: Backing of a thin sample when none is named: a sample lying on a (hardwood) table.
DEFAULT_BACKING = "table"
#: A semi-infinite table holds while the slab changes the reading by less than this fraction of sigma.
NOISE_FRACTION = 0.1

_ALPHA_STREAM = 7              # seed-key suffix of the diffusivity draws (independent of the noise)
_INVISIBLE = 0.01              # slab deviation (curve norm, noise units) below which eq. 2 is used
_BASIS_EPS = 0.01              # basis reproduces every grid curve to this fraction of the noise
_GRID_PER_NOISE = 2.0          # likelihood grid points per noise unit of curve arc length
_MAX_GRID = 4096               # most grid points per class
_BLOCK = 2_000_000             # floats per block of curves (16 MB)
_TRIVIAL_F1 = 2.0 / 3.0        # F1 of "everything positive" with balanced classes (as designkit.ideal)


# ============================================================ objects and scene
@dataclass(frozen=True)
class SlabObject:
    """One object class of a thin-sample question.

    Attributes
    ----------
    label : str
        Name shown in reports.
    e_range : (float, float)
        Effusivity class ``[low, high)`` [J s^-1/2 K^-1 m^-2], low < high.
    alpha_range_m2_s : (float, float)
        Diffusivity range ``[low, high]`` [m^2 s^-1]; ``low == high`` is one value.
    material : str or None
        Database name, when the object is a material.
    """

    label: str
    e_range: tuple[float, float]
    alpha_range_m2_s: tuple[float, float]
    material: str | None = None

    def __post_init__(self) -> None:
        lo, hi = check_effusivity_range(self.label, *self.e_range)
        a_lo = check_positive(f"diffusivity of {self.label} [m^2/s]", self.alpha_range_m2_s[0])
        a_hi = check_positive(f"diffusivity of {self.label} [m^2/s]", self.alpha_range_m2_s[1])
        if a_hi < a_lo:
            raise InputError(f"diffusivity range of {self.label} must have low <= high, got [{a_lo:g}, {a_hi:g}]")
        object.__setattr__(self, "e_range", (lo, hi))
        object.__setattr__(self, "alpha_range_m2_s", (a_lo, a_hi))

    @property
    def key(self) -> tuple[float, float, float, float]:
        """Ordering key: effusivity midpoint first (the higher one is the positive class)."""
        return (0.5 * sum(self.e_range), 0.5 * sum(self.alpha_range_m2_s), *self.e_range)

    def sample_points(self, n_e: int = 5) -> tuple[np.ndarray, np.ndarray]:
        """Effusivities (``n_e`` across the range) and diffusivities (low, middle, high) to examine."""
        e = np.linspace(self.e_range[0], self.e_range[1], n_e)
        a_lo, a_hi = self.alpha_range_m2_s
        a = np.array([a_lo]) if a_hi == a_lo else np.array([a_lo, 0.5 * (a_lo + a_hi), a_hi])
        return e, a

    def to_dict(self) -> dict[str, Any]:
        return {"label": self.label, "material": self.material, "e_range": list(self.e_range),
                "alpha_range_m2_s": list(self.alpha_range_m2_s)}


def slab_object(e: float | None = None, material: str | None = None, *, diffusivity_m2_s: float | None = None,
                width: float = 80.0) -> SlabObject:
    """An object class from an effusivity and a diffusivity, or from a material name.

    Parameters
    ----------
    e : float, optional
        Effusivity [J s^-1/2 K^-1 m^-2]; the class is ``[e, e + width)``.
    material : str, optional
        Material of :mod:`designkit.materials` (instead of ``e``): its
        effusivity and diffusivity ranges are the class.
    diffusivity_m2_s : float, optional
        Diffusivity [m^2 s^-1] of an object given by ``e`` (required then:
        effusivity alone no longer fixes a thin sample's reading). Refused with
        ``material``, whose diffusivity comes from the database.
    width : float
        Class width for ``e`` [J s^-1/2 K^-1 m^-2].
    """
    if (e is None) == (material is None):
        raise InputError("give an object either as an effusivity or as a material name")
    if material is not None:
        if diffusivity_m2_s is not None:
            raise InputError(f"the diffusivity of {material!r} comes from the materials database; "
                             "--diffusivity is for objects given as an effusivity")
        from ..models.slab import material_properties

        mat = material_properties(material)
        return SlabObject(f"{mat.name} ({mat.e_min:.0f}–{mat.e_max:.0f})", (mat.e_min, mat.e_max),
                          (mat.diffusivity_min_m2_s, mat.diffusivity_max_m2_s), mat.name)
    v = check_effusivity("e", e)
    if diffusivity_m2_s is None:
        raise InputError(f"an object given as an effusivity ({v:g}) needs --diffusivity [m^2/s] when a thickness "
                         "is given: effusivity alone no longer fixes a thin sample's reading")
    a = check_positive("diffusivity [m^2/s]", diffusivity_m2_s)
    w = check_positive("class width", width)
    return SlabObject(f"{v:g}", (v, v + w), (a, a))


def slab_objects(e1=None, e2=None, m1=None, m2=None, *, diffusivity_m2_s: float | None = None,
                 width: float = 80.0) -> tuple[SlabObject, SlabObject]:
    """The two objects of a pair question (numbers or material names; see :func:`slab_object`).

    ``diffusivity_m2_s`` applies to the objects given as numbers; it is
    refused when both are materials (it would be silently unused).
    """
    if (e1 is None and m1 is None) or (e2 is None and m2 is None):
        raise InputError("give two objects: --e1/--m1 and --e2/--m2")
    if e1 is not None and m1 is not None or e2 is not None and m2 is not None:
        raise InputError("give each object once: either --e1 or --m1, either --e2 or --m2")
    if m1 is not None and m2 is not None and diffusivity_m2_s is not None:
        raise InputError("--diffusivity is for objects given as an effusivity; both materials "
                         "take their diffusivity ranges from the database")
    return (slab_object(e1, m1, diffusivity_m2_s=None if m1 else diffusivity_m2_s, width=width),
            slab_object(e2, m2, diffusivity_m2_s=None if m2 else diffusivity_m2_s, width=width))


@dataclass(frozen=True)
class SlabScene:
    """The thin-sample part of a scene: slab thickness and what lies behind it.

    Attributes
    ----------
    thickness_m : float
        Object thickness L [m] (> 0; ``inf``: the paper's semi-infinite object).
    backing : Backing
        Resolved backing (:func:`designkit.slab.resolve_backing`).
    """

    thickness_m: float
    backing: Backing

    @classmethod
    def make(cls, thickness_m: float, backing: "str | Backing | None" = DEFAULT_BACKING) -> "SlabScene":
        """Validate the thickness and resolve the backing by name (default: a hardwood table)."""
        L = check_positive("object thickness [m]", thickness_m, allow_inf=True)
        return cls(L, resolve_backing(DEFAULT_BACKING if backing is None else backing))

    def describe(self) -> str:
        if not math.isfinite(self.thickness_m):
            return "semi-infinite object"
        return f"{self.thickness_m * 1e3:g} mm slab on {self.backing.name}"

    def to_dict(self) -> dict[str, Any]:
        b = self.backing
        return {"thickness_m": self.thickness_m,
                "backing": {"name": b.name, "effusivity": b.effusivity,
                            "diffusivity_m2_s": None if b.insulated else b.diffusivity_m2_s, "source": b.source}}


# ============================================================ simulated touches
@dataclass(frozen=True)
class SlabTrials:
    """Simulated touches of a thin sample (as :class:`designkit.simulation.Trials`, plus diffusivity).

    Attributes
    ----------
    time_s : ndarray, shape (m,)
    temperature_c : ndarray, shape (n, m)
        Readings [degC].
    effusivity, diffusivity_m2_s : ndarray, shape (n,)
        Each trial's object properties.
    sensor_temp_c, ambient_temp_c : ndarray, shape (n,)
    method : str
        Solver :func:`designkit.slab.slab_response` used.
    error_bound : float
        Its bound on the normalized reading's error.
    """

    time_s: np.ndarray
    temperature_c: np.ndarray
    effusivity: np.ndarray
    diffusivity_m2_s: np.ndarray
    sensor_temp_c: np.ndarray
    ambient_temp_c: np.ndarray
    method: str
    error_bound: float


def _seed_key(seed) -> list[int]:
    if isinstance(seed, (list, tuple)):
        key = [int(s) for s in seed]
        as_generator(key)  # validates
        return key
    as_generator(seed)  # validates (refuses None, negatives, Generators are not keys)
    if isinstance(seed, (np.random.Generator, np.random.SeedSequence)):
        raise InputError("thin-sample simulations need an integer seed or a list of integers "
                         "(the diffusivity stream is derived from it)")
    return [int(seed)]


def _response_tolerance(noise_ratio: float, n_samples: int) -> float:
    """Tolerance of the normalized reading: 1 % of the noise over the whole curve, at most 1e-5."""
    if not math.isfinite(noise_ratio):
        return 1e-5
    return float(np.clip(0.01 * noise_ratio / math.sqrt(max(n_samples, 1)), 1e-10, 1e-5))


def _u(time_s, e, alpha, slab: SlabScene, sensor: Sensor, tol: float):
    r = slab_response(time_s, e, alpha, slab.thickness_m, slab.backing, sensor, tolerance=tol)
    return r.response, r.method, r.error_bound


def simulate_slab_class(obj: SlabObject, n_trials: int, sensor: Sensor, scene: Scene, slab: SlabScene,
                        seed) -> SlabTrials:
    """``n_trials`` touches of one object class lying as a slab on a backing.

    Draws follow :mod:`designkit.simulation` (:func:`~designkit.simulation.draw_trials`
    with ``seed``: effusivity, offsets, time-major noise); the diffusivity of
    each trial is uniform in the class's range, from the stream
    ``seed + [7]``. Readings ``Ts0 + (Ta - Ts0) u + sigma z`` with ``u`` from
    :func:`designkit.slab.slab_response` (tolerance 1 % of the noise over the
    curve, at most 1e-5).

    Parameters
    ----------
    obj : SlabObject
    n_trials : int
    sensor : Sensor
    scene : Scene
    slab : SlabScene
    seed : int or list of int
    """
    key = _seed_key(seed)
    t = sensor.times_s(scene.contact_s)
    draws = draw_trials(*obj.e_range, n_trials, t.size, key, vary_sensor=scene.sensor_temp_spread_c > 0,
                        vary_ambient=scene.ambient_temp_spread_c > 0)
    a_lo, a_hi = obj.alpha_range_m2_s
    if a_hi > a_lo:
        alpha = as_generator(key + [_ALPHA_STREAM]).uniform(a_lo, a_hi, draws.n_trials)
    else:
        alpha = np.full(draws.n_trials, a_lo)
    u, method, bound = _u(t, draws.effusivity, alpha, slab, sensor,
                          _response_tolerance(scene.noise_ratio, t.size))
    ts = scene.sensor_temp_c + scene.sensor_temp_spread_c * draws.sensor_offset
    ta = scene.ambient_temp_c + scene.ambient_temp_spread_c * draws.ambient_offset
    temps = ts[:, None] + (ta - ts)[:, None] * u
    if scene.noise_c > 0:
        temps = temps + scene.noise_c * draws.noise
    return SlabTrials(t, temps, draws.effusivity, alpha, ts, ta, method, bound)


def _ordered(obj_a: SlabObject, obj_b: SlabObject) -> tuple[SlabObject, SlabObject]:
    if obj_a.e_range == obj_b.e_range and obj_a.alpha_range_m2_s == obj_b.alpha_range_m2_s:
        raise InputError(f"the two objects are identical ({obj_a.label}): nothing to separate")
    return (obj_a, obj_b) if obj_a.key <= obj_b.key else (obj_b, obj_a)


def slab_pair_f1(obj_a: SlabObject, obj_b: SlabObject, sensor: Sensor, scene: Scene, slab: SlabScene, *,
                 trials: int = 100, folds: int = 3, seed=0):
    """The paper's SVM F1 for two thin-sample classes (as :func:`designkit.recognition.interval_pair_f1`).

    Trials of the lower class use stream ``[seed, 0]``, of the higher
    ``[seed, 1]``, the fold shuffle ``[seed, 2]``: for a slab too thick to
    matter, the same touches and F1 as ``interval_pair_f1`` with that seed.

    Returns
    -------
    designkit.recognition.F1Result
    """
    from ..recognition.svm import cross_validated_f1

    low, high = _ordered(obj_a, obj_b)
    base = _seed_key(seed)
    t_low = simulate_slab_class(low, trials, sensor, scene, slab, base + [0])
    t_high = simulate_slab_class(high, trials, sensor, scene, slab, base + [1])
    return cross_validated_f1(t_low.temperature_c, t_high.temperature_c, sensor.sample_rate_hz,
                              folds=folds, seed=base + [2])


# ============================================================ ideal observer
def slab_deviation_norm(objs, slab: SlabScene, sensor: Sensor, contact_s: float, noise_ratio: float) -> float:
    """Upper bound on ``||u_slab - u_semi||`` over a touch, in noise units, for any object of the classes.

    ``max_t |u_slab - u_semi| * sqrt(m) / (sigma / |dT|)`` with the rigorous
    per-time bound :func:`designkit.slab.semi_infinite_error_bound` (largest
    at the class's highest diffusivity, examined on 65 effusivities per class).
    """
    if not math.isfinite(slab.thickness_m):
        return 0.0
    m = sensor.times_s(contact_s).size
    worst = 0.0
    for obj in objs:
        e = np.linspace(obj.e_range[0], obj.e_range[1], 65)
        b = semi_infinite_error_bound(contact_s, e, obj.alpha_range_m2_s[1], slab.thickness_m, slab.backing,
                                      sensor)
        worst = max(worst, float(b.max()))
    if worst == 0.0:
        return 0.0
    return math.inf if noise_ratio == 0 else worst * math.sqrt(m) / noise_ratio


def _arc_length(curves: np.ndarray) -> float:
    """Length of a polyline of curves (rows), Euclidean."""
    if curves.shape[0] < 2:
        return 0.0
    return float(np.sum(np.linalg.norm(np.diff(curves, axis=0), axis=1)))


@dataclass(frozen=True)
class _ClassGrid:
    e_nodes: np.ndarray      # (n_e,)
    alpha_nodes: np.ndarray  # (n_a,)
    arc_e: float             # curve-family arc length along e, noise units
    arc_alpha: float
    capped: bool

    @property
    def size(self) -> int:
        return self.e_nodes.size * self.alpha_nodes.size


def _class_grid(obj: SlabObject, t, slab, sensor, s_n, tol, pilot: list) -> _ClassGrid:
    """Midpoint grid over the class's effusivity x diffusivity box (4 points per noise unit of arc)."""
    e_lo, e_hi = obj.e_range
    a_lo, a_hi = obj.alpha_range_m2_s
    a_lines = [a_lo] if a_hi == a_lo else [a_lo, 0.5 * (a_lo + a_hi), a_hi]
    e_pilot = np.linspace(e_lo, e_hi, 33)
    arc_e = 0.0
    for a in a_lines:
        c, _, _ = _u(t, e_pilot, a, slab, sensor, tol)
        pilot.append(c)
        arc_e = max(arc_e, _arc_length(c) / s_n)
    arc_a = 0.0
    if a_hi > a_lo:
        a_pilot = np.linspace(a_lo, a_hi, 9)
        for e in (e_lo, 0.5 * (e_lo + e_hi), e_hi):
            c, _, _ = _u(t, np.full(a_pilot.size, e), a_pilot, slab, sensor, tol)
            pilot.append(c)
            arc_a = max(arc_a, _arc_length(c) / s_n)
    n_e = int(np.clip(math.ceil(_GRID_PER_NOISE * arc_e), 16, _MAX_GRID))
    n_a = 1 if a_hi == a_lo else int(np.clip(math.ceil(_GRID_PER_NOISE * arc_a), 1, 64))
    capped = _GRID_PER_NOISE * arc_e > _MAX_GRID or (a_hi > a_lo and _GRID_PER_NOISE * arc_a > 64)
    if n_e * n_a > 4 * _MAX_GRID:  # keep the 2-D grid affordable: shrink both alike
        f = math.sqrt(4 * _MAX_GRID / (n_e * n_a))
        n_e, n_a, capped = max(16, int(n_e * f)), max(1, int(n_a * f)), True
    e_nodes = e_lo + (np.arange(n_e) + 0.5) * (e_hi - e_lo) / n_e
    a_nodes = np.array([a_lo]) if a_hi == a_lo else a_lo + (np.arange(n_a) + 0.5) * (a_hi - a_lo) / n_a
    return _ClassGrid(e_nodes, a_nodes, arc_e, arc_a, capped)


def _basis_from(curves: np.ndarray, tol_abs: float, basis: np.ndarray | None = None) -> np.ndarray:
    """Orthonormal rows spanning ``curves`` (after removing ``basis``) to ``tol_abs`` per curve."""
    resid = curves if basis is None else curves - (curves @ basis.T) @ basis
    # SVD through a QR of the (few) curves: resid = r^T q^T, so resid's right singular vectors are q w
    q, r = np.linalg.qr(resid.T)
    _, _, wt = np.linalg.svd(r.T, full_matrices=False)
    vt = wt @ q.T
    # residual of each curve after r components: ||rows of U S beyond r||; keep r so that all are <= tol
    coef = resid @ vt.T  # (K, k)
    tail = np.sqrt(np.maximum(np.cumsum((coef ** 2)[:, ::-1], axis=1)[:, ::-1], 0.0))  # tail[:, j]: from j on
    need = [j for j in range(vt.shape[0] + 1) if j == vt.shape[0] or np.all(tail[:, j] <= tol_abs)]
    r = need[0]
    new = vt[:r]
    return new if basis is None else np.vstack([basis, new])


def _grid_coefficients(grid: _ClassGrid, basis, t, slab, sensor, tol):
    """Basis coefficients of every grid curve, the largest residual norm, and the largest residual rows.

    The residual rows (up to 8 per block, those within a factor 2 of the block's largest) are what
    :func:`_basis_from` adds to the basis when the largest residual exceeds the tolerance.
    """
    coefs, worst, worst_rows = [], 0.0, []
    step = max(1, _BLOCK // max(t.size, 1))
    for a in grid.alpha_nodes:
        for j in range(0, grid.e_nodes.size, step):
            c, _, _ = _u(t, grid.e_nodes[j:j + step], a, slab, sensor, tol)
            k = c @ basis.T
            res = c - k @ basis
            norms = np.linalg.norm(res, axis=1)
            i = int(np.argmax(norms))
            if norms[i] > worst:
                worst = float(norms[i])
            worst_rows.append(res[norms >= 0.5 * norms.max()][:8])
            coefs.append(k)
    return np.vstack(coefs), worst, np.vstack(worst_rows)


@dataclass(frozen=True)
class SlabIdeal:
    """Ideal-observer result for a thin-sample pair, with how it was computed.

    Attributes
    ----------
    result : IdealResult
        F1, accuracy, method (``"closed-form"`` when the slab is invisible
        within the contact, else ``"monte-carlo"``) and standard errors.
    deviation_norm : float
        Bound on the slab's change of the curve, noise units (see :func:`slab_deviation_norm`).
    details : dict
        Grid sizes, basis rank, largest basis residual (noise units) for Monte Carlo.
    """

    result: IdealResult
    deviation_norm: float
    details: dict = field(default_factory=dict, compare=False)


def slab_ideal_pair(obj_a: SlabObject, obj_b: SlabObject, sensor: Sensor, scene: Scene, slab: SlabScene, *,
                    n_mc: int = 1000, seed=0, method: str = "auto") -> SlabIdeal:
    """Best achievable F1 and accuracy for two thin-sample classes (fixed initial conditions).

    Parameters
    ----------
    obj_a, obj_b : SlabObject
        Order does not matter; the positive class has the higher effusivity.
    sensor, scene, slab
        Scene must have fixed initial conditions.
    n_mc : int
        Simulated test touches per class (Monte Carlo path).
    seed : int or list of int
        Test touches use streams ``seed + [10]`` and ``seed + [11]``.
    method : {"auto", "closed-form", "monte-carlo"}
        ``auto``: the closed form of :mod:`designkit.ideal` when the slab
        changes no curve by more than 1 % of the noise (in norm), else Monte
        Carlo on the full-curve likelihood (module docstring).

    Returns
    -------
    SlabIdeal
    """
    if method not in ("auto", "closed-form", "monte-carlo"):
        raise InputError(f"unknown ideal-observer method {method!r}: use auto, closed-form or monte-carlo")
    if not scene.fixed_initial_conditions:
        raise InputError("the thin-sample ideal observer supports fixed initial conditions only")
    if scene.delta_t_c == 0:
        raise InputError("temperature difference is 0: an unheated sensor sees no contrast between materials")
    low, high = _ordered(obj_a, obj_b)
    s_n = scene.noise_ratio
    dev = slab_deviation_norm((low, high), slab, sensor, scene.contact_s, s_n)
    if method == "closed-form" or (method == "auto" and dev <= _INVISIBLE):
        if low.e_range == high.e_range:  # same effusivities, only diffusivity differs: invisible without a slab
            res = IdealResult(_TRIVIAL_F1, 0.5, "closed-form")
        else:
            res = ideal_pair(low.e_range, high.e_range, sensor, scene)
        return SlabIdeal(res, dev, {"why": "slab invisible within the contact" if method == "auto" else "asked"})
    return _slab_ideal_mc(low, high, sensor, scene, slab, int(n_mc), seed, dev)


def _slab_ideal_mc(low, high, sensor, scene, slab, n_mc, seed, dev) -> SlabIdeal:
    if n_mc < 10:
        raise InputError(f"Monte Carlo ideal observer needs at least 10 touches per class, got {n_mc}")
    key = _seed_key(seed)
    # a noise-free scene is handled as the limit of a tiny noise (as designkit.ideal does)
    sigma = max(scene.noise_c, 1e-6 * abs(scene.delta_t_c))
    sc = scene.replace(noise_c=sigma)
    s_n = sc.noise_ratio
    t = sensor.times_s(sc.contact_s)
    tol = _response_tolerance(s_n, t.size)
    pilot: list[np.ndarray] = []
    grids = [_class_grid(obj, t, slab, sensor, s_n, tol, pilot) for obj in (low, high)]
    eps = _BASIS_EPS * s_n
    basis = _basis_from(np.vstack(pilot), eps)
    for _ in range(6):  # grow the basis until it reproduces every grid curve
        out = [_grid_coefficients(g, basis, t, slab, sensor, tol) for g in grids]
        worst = max(o[1] for o in out)
        if worst <= eps:
            break
        basis = _basis_from(np.vstack([o[2] for o in out]), eps, basis)
    coefs = [o[0] for o in out]
    # test touches, normalized: u_obs = (y - Ts0) / (Ta - Ts0) = u + (sigma / (Ta - Ts0)) z
    dt = sc.ambient_temp_c - sc.sensor_temp_c
    obs = []
    for obj, k in ((low, 10), (high, 11)):
        tr = simulate_slab_class(obj, n_mc, sensor, sc, slab, key + [k])
        obs.append(((tr.temperature_c - sc.sensor_temp_c) / dt) @ basis.T)
    y = np.vstack(obs)
    labels = np.r_[np.zeros(n_mc, dtype=int), np.ones(n_mc, dtype=int)]
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
    f1, se, acc, acc_se = score_llr(llr, labels, n_mc)
    res = IdealResult(f1=f1, accuracy=acc, method="monte-carlo", standard_error=se, accuracy_standard_error=acc_se,
                      projection_noise=None, n_mc=n_mc)
    details = {"grid": [[g.e_nodes.size, g.alpha_nodes.size] for g in grids],
               "arc_length_noise_units": [[g.arc_e, g.arc_alpha] for g in grids],
               "grid_capped": any(g.capped for g in grids), "basis_rank": int(basis.shape[0]),
               "basis_residual_noise_units": worst / s_n}
    return SlabIdeal(res, dev, details)


# ============================================================ semi-infinite check
@dataclass(frozen=True)
class SemiInfiniteCheck:
    """Would a semi-infinite table (the paper's model) answer this thin-sample question?

    Attributes
    ----------
    holds : bool
        True when the slab changes no reading by more than ``fraction`` of
        sigma within the contact times the question needs (up to ``needed_s``).
    valid_up_to_s : float or None
        First contact time [s] at which the slab changes the reading by more
        than ``tolerance_c`` (any object of the classes; None: not within
        ``examined_s``).
    needed_s : float
        Longest contact time the question needs [s].
    examined_s : float
        Longest contact time examined [s].
    tolerance_c : float
        ``fraction * sigma`` [degC] (at the answer's noise and temperature difference).
    fraction : float
    limiting_object : dict or None
        Effusivity and diffusivity that limit ``valid_up_to_s``.
    message : str
        One sentence for people.
    """

    holds: bool
    valid_up_to_s: float | None
    needed_s: float
    examined_s: float
    tolerance_c: float
    fraction: float
    limiting_object: dict | None
    message: str

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def semi_infinite_check(objs, slab: SlabScene, sensor: Sensor, *, needed_s: float, noise_c: float,
                        delta_t_c: float, fraction: float = NOISE_FRACTION) -> SemiInfiniteCheck:
    """Whether the slab changes the reading by more than ``fraction * noise_c`` within ``needed_s``.

    A quick rigorous bound (:func:`designkit.slab.semi_infinite_error_bound`)
    settles most cases; otherwise :func:`designkit.slab.semi_infinite_validity`
    finds the first contact time the deviation exceeds the tolerance, worst
    case over 5 effusivities and 3 diffusivities of each class, examined up to
    ``max(10 needed_s, 60 s)`` so that the message can say when it stops
    holding even beyond the question.

    Parameters
    ----------
    objs : sequence of SlabObject
    slab : SlabScene
    sensor : Sensor
    needed_s : float
        Longest contact time the question depends on [s].
    noise_c, delta_t_c : float
        Noise sigma and sensor-object temperature difference [degC] (sigma may be 0).
    fraction : float
        Tolerated deviation as a fraction of sigma.
    """
    need = check_positive("contact time [s]", needed_s)
    frac = check_positive("noise fraction", fraction)
    sigma = abs(check_finite("noise sigma [degC]", noise_c))
    dt = abs(check_finite("temperature difference [degC]", delta_t_c))
    tol_c = max(frac * sigma, 1e-9 * max(dt, 1.0))  # noise-free: any visible deviation counts
    examined = min(max(10.0 * need, 60.0), 3600.0)
    what = slab.describe()
    if dt == 0 or not math.isfinite(slab.thickness_m):
        valid, limit = None, None
    else:
        tol_n = tol_c / dt
        candidates = []
        for obj in objs:
            e, a = obj.sample_points()
            if float(semi_infinite_error_bound(examined, e, a.max(), slab.thickness_m, slab.backing,
                                               sensor).max()) > tol_n:
                candidates.append((e, a))
        valid, limit = None, None
        for e, a in candidates:
            v = semi_infinite_validity(e, a, slab.thickness_m, slab.backing, sensor, delta_t_c=dt,
                                       tolerance_c=tol_c, horizon_s=examined)
            if math.isfinite(v.time_s) and (valid is None or v.time_s < valid):
                valid = v.time_s
                limit = {"effusivity": v.e_object, "diffusivity_m2_s": v.alpha_object_m2_s}
    holds = valid is None or valid >= need
    crit = f"{frac:g} sigma ({tol_c:.2g} °C)"
    if valid is None:
        msg = (f"the semi-infinite tables hold for this scene: the {what} changes the reading by less than "
               f"{crit} for any contact up to {examined:g} s")
    elif holds:
        msg = (f"the semi-infinite tables hold for this scene: the {what} changes the reading by less than "
               f"{crit} up to {valid:.3g} s of contact, beyond the {need:.3g} s this question needs")
    else:
        msg = (f"a semi-infinite table does NOT hold for this scene: the {what} changes the reading by more "
               f"than {crit} from {valid:.3g} s of contact on, within the {need:.3g} s this question needs; "
               f"answered for the slab")
    return SemiInfiniteCheck(holds, valid, need, examined, tol_c, frac, limit, msg)


# ============================================================ queries
def _svm_f1(ex, objs, scene, slab) -> tuple[float, float]:
    """Mean SVM F1 over ``ex.repeats`` seeds and its standard error (as designkit.query)."""
    from joblib import Parallel, delayed

    jobs = ex.jobs if ex.repeats > 1 else 1
    results = Parallel(n_jobs=jobs, prefer="processes" if jobs != 1 else None)(
        delayed(slab_pair_f1)(objs[0], objs[1], ex.sensor, scene, slab, trials=ex.trials, folds=ex.folds,
                              seed=[ex.seed, r]) for r in range(ex.repeats))
    f1 = np.array([r.f1 for r in results])
    se_fold = math.sqrt(float(np.mean([r.standard_error ** 2 for r in results])))
    se_rep = float(np.std(f1, ddof=1)) if f1.size > 1 else 0.0
    return float(f1.mean()), max(se_fold, se_rep) / math.sqrt(f1.size)


class _IdealLog:
    """Ideal-observer evaluations of one question (methods used, largest deviation)."""

    def __init__(self, ex, objs, slab, n_mc):
        self.ex, self.objs, self.slab, self.n_mc = ex, objs, slab, int(n_mc)
        self.calls: list[dict[str, Any]] = []

    def f1(self, scene: Scene) -> float:
        r = slab_ideal_pair(self.objs[0], self.objs[1], self.ex.sensor, scene, self.slab, n_mc=self.n_mc,
                            seed=self.ex.seed)
        self.calls.append({"contact_s": scene.contact_s, "noise_ratio": scene.noise_ratio, "f1": r.result.f1,
                           "standard_error": r.result.standard_error, "method": r.result.method,
                           "slab_deviation_noise_units": r.deviation_norm})
        return r.result.f1

    def summary(self) -> dict[str, Any]:
        methods = sorted({c["method"] for c in self.calls})
        return {"ideal_methods": methods, "ideal_evaluations": self.calls}


def _setup(objs, thickness_m, backing, sensor, trials, folds, seed, repeats, z, jobs, width=80.0):
    from .table import _exact_setup

    ex = _exact_setup(sensor, width, trials, folds, seed, repeats, z, jobs)
    slab = SlabScene.make(thickness_m, backing)
    o1, o2 = objs
    if not isinstance(o1, SlabObject) or not isinstance(o2, SlabObject):
        raise InputError("thin-sample queries take two SlabObject (see designkit.thin_query.slab_objects)")
    return ex, slab, _ordered(o1, o2)


def _thin_inputs(objs, slab, ex, **scene) -> dict[str, Any]:
    low, high = objs
    d = dict(scene)
    d.update({"e1": None, "e2": None, "objects": [low.to_dict(), high.to_dict()],
              "classes": [list(low.e_range), list(high.e_range)], "slab": slab.to_dict(),
              "thickness_m": slab.thickness_m, "backing": slab.backing.name,
              "trials": ex.trials, "folds": ex.folds, "seed": ex.seed, "repeats": ex.repeats,
              "sensor": ex.sensor.name})
    if low.material or high.material:
        d["rule"] = "each material's whole effusivity and diffusivity range is one class"
    return d


def _extra(check: SemiInfiniteCheck, slab: SlabScene, ideal: _IdealLog, t0: float, **more) -> dict[str, Any]:
    d = {"fidelity": "svm", "slab": {**slab.to_dict(), "semi_infinite": check.to_dict(),
                                     "message": check.message, "holds": check.holds},
         **ideal.summary(), "wall_s": time.perf_counter() - t0}
    d.update(more)
    return d


def thin_min_contact(obj1: SlabObject, obj2: SlabObject, *, thickness_m: float, backing=DEFAULT_BACKING,
                     noise_c: float = 0.05, delta_t_c: float = 10.0, threshold: float = 0.9, sensor=None,
                     trials: int = 100, folds: int = 3, seed: int = 0, repeats: int = 4, z: float = 2.0,
                     jobs: int = -1, max_contact_s: float = 10.0, tolerance_s: float = 0.05, n_mc: int = 1000,
                     fraction: float = NOISE_FRACTION):
    """Shortest contact time [s] that separates two thin-sample objects, computed for this scene.

    Bisection on the contact time of the SVM's mean F1 over ``repeats`` seeds
    (as :func:`designkit.query.exact_min_contact`), and of the ideal observer
    (:func:`slab_ideal_pair`, common random numbers at every contact time).
    ``extra["slab"]`` says whether a semi-infinite table holds up to the
    contact times the answer needs (:func:`semi_infinite_check`).

    Returns
    -------
    designkit.query.Answer
    """
    from .table import Answer, _bisect, _contact_search, _scene_inputs, _threshold

    noise, dt = _scene_inputs(noise_c, delta_t_c)
    phi = _threshold(threshold)
    ex, slab, objs = _setup((obj1, obj2), thickness_m, backing, sensor, trials, folds, seed, repeats, z, jobs)
    tmax = check_positive("maximum contact time [s]", max_contact_s)
    t0 = time.perf_counter()

    def scene(c):
        return Scene.from_delta_t(contact_s=c, noise_c=noise, delta_t_c=dt)

    floor = 1.0 / ex.sensor.sample_rate_hz
    value, interval, evaluations = _contact_search(lambda c: _svm_f1(ex, objs, scene(c), slab), phi, floor, tmax,
                                                   tolerance_s, z)
    ilog = _IdealLog(ex, objs, slab, n_mc)
    ideal_ok = lambda c: ilog.f1(scene(c)) >= phi  # noqa: E731
    # the ideal observer needs no more contact than the SVM: bracket with the SVM's answer first (long
    # contacts are the costly ones for the Monte Carlo likelihood), widen to tmax only if that fails
    itol = min(0.01, tolerance_s)
    if value is not None and ideal_ok(value):
        ideal = _bisect(ideal_ok, floor, value, itol)
    elif ideal_ok(tmax):
        ideal = _bisect(ideal_ok, value if value is not None else floor, tmax, itol)
    else:
        ideal = None
    # the answer depends on the readings up to the contact times it names (up to tmax when there is none)
    needed = tmax if value is None else max(x for x in (value, ideal, interval[1]) if x is not None)
    check = semi_infinite_check(objs, slab, ex.sensor, needed_s=needed, noise_c=noise, delta_t_c=dt,
                                fraction=fraction)
    inputs = _thin_inputs(objs, slab, ex, noise_c=noise, delta_t_c=dt, threshold=phi, max_contact_s=tmax)
    note = "" if value is not None else f"not separable by any contact time up to {tmax:g} s"
    extra = _extra(check, slab, ilog, t0, evaluations=evaluations)
    return Answer("min-contact", value, interval, ideal, "computed", None, None, inputs, {}, extra, note)


def _thin_ratio(question, obj1, obj2, thickness_m, backing, contact_s, noise_c, delta_t_c, threshold, sensor,
                trials, folds, seed, repeats, z, jobs, n_mc, fraction):
    from .table import Answer, _bisect, _ratio_search, _threshold

    phi = _threshold(threshold)
    contact = check_positive("contact time [s]", contact_s)
    ex, slab, objs = _setup((obj1, obj2), thickness_m, backing, sensor, trials, folds, seed, repeats, z, jobs)
    if question == "max-noise":
        dt = check_finite("temperature difference [degC]", delta_t_c)
        if dt == 0:
            raise InputError("temperature difference is 0: no noise level is small enough")
    else:
        noise = check_positive("noise sigma [degC]", noise_c)
    t0 = time.perf_counter()
    lo_r, hi_r = 1e-5, 1.0  # sigma/dT bracket, as designkit.query

    def scene(r):  # readings depend on sigma and dT only through r (standardized features, fixed conditions)
        return Scene.from_delta_t(contact_s=contact, noise_c=r, delta_t_c=1.0)

    r, (r_lo, r_hi), evaluations = _ratio_search(lambda x: _svm_f1(ex, objs, scene(x), slab), phi, lo_r, hi_r, z)
    ilog = _IdealLog(ex, objs, slab, n_mc)
    ideal_r = None
    if ilog.f1(scene(lo_r)) >= phi:
        ideal_r = hi_r if ilog.f1(scene(hi_r)) >= phi else \
            _bisect(lambda x: ilog.f1(scene(x)) < phi, lo_r, hi_r, 2e-3, log=True)
    if question == "max-noise":
        conv = lambda x: None if x is None else x * abs(dt)  # noqa: E731
        interval = (conv(r_lo), conv(r_hi))
        scene_in = {"delta_t_c": dt}
    else:
        conv = lambda x: None if x is None else noise / x  # noqa: E731
        interval = (conv(r_hi), conv(r_lo))
        scene_in = {"noise_c": noise}
    # the semi-infinite check at the answer (the slab's deviation scales with dT, the tolerance with sigma):
    # the smaller sigma/dT of the SVM's and the ideal observer's answers is the stricter one
    r_check = min([x for x in (r, ideal_r) if x is not None], default=lo_r)
    sigma_c, dt_c = (r_check * abs(dt), dt) if question == "max-noise" else (noise, noise / r_check)
    check = semi_infinite_check(objs, slab, ex.sensor, needed_s=contact, noise_c=sigma_c, delta_t_c=dt_c,
                                fraction=fraction)
    inputs = _thin_inputs(objs, slab, ex, contact_s=contact, threshold=phi, **scene_in)
    note = "" if r is not None else "not separable even at sigma/dT = 1e-5"
    extra = _extra(check, slab, ilog, t0, evaluations=evaluations)
    return Answer(question, conv(r), interval, conv(ideal_r), "computed", None, None, inputs, {}, extra, note)


def thin_max_noise(obj1: SlabObject, obj2: SlabObject, *, thickness_m: float, backing=DEFAULT_BACKING,
                   contact_s: float, delta_t_c: float = 10.0, threshold: float = 0.9, sensor=None,
                   trials: int = 100, folds: int = 3, seed: int = 0, repeats: int = 4, z: float = 2.0,
                   jobs: int = -1, n_mc: int = 1000, fraction: float = NOISE_FRACTION):
    """Largest noise sigma [degC] at which ``contact_s`` separates two thin-sample objects (computed)."""
    return _thin_ratio("max-noise", obj1, obj2, thickness_m, backing, contact_s, None, delta_t_c, threshold,
                       sensor, trials, folds, seed, repeats, z, jobs, n_mc, fraction)


def thin_min_delta_t(obj1: SlabObject, obj2: SlabObject, *, thickness_m: float, backing=DEFAULT_BACKING,
                     contact_s: float, noise_c: float = 0.05, threshold: float = 0.9, sensor=None,
                     trials: int = 100, folds: int = 3, seed: int = 0, repeats: int = 4, z: float = 2.0,
                     jobs: int = -1, n_mc: int = 1000, fraction: float = NOISE_FRACTION):
    """Smallest sensor-object temperature difference [degC] that separates two thin-sample objects (computed)."""
    return _thin_ratio("min-delta-t", obj1, obj2, thickness_m, backing, contact_s, noise_c, None, threshold,
                       sensor, trials, folds, seed, repeats, z, jobs, n_mc, fraction)


def thin_distinguishable(obj1: SlabObject, obj2: SlabObject, *, thickness_m: float, backing=DEFAULT_BACKING,
                         contact_s: float, noise_c: float = 0.05, delta_t_c: float = 10.0,
                         threshold: float = 0.9, sensor=None, trials: int = 100, folds: int = 3, seed: int = 0,
                         repeats: int = 4, z: float = 2.0, jobs: int = -1, n_mc: int = 1000,
                         fraction: float = NOISE_FRACTION):
    """SVM F1 (mean of ``repeats`` seeds) and ideal F1 of two thin-sample objects at this scene."""
    from .table import Answer, _scene_inputs, _threshold

    phi = _threshold(threshold)
    noise, dt = _scene_inputs(noise_c, delta_t_c)
    ex, slab, objs = _setup((obj1, obj2), thickness_m, backing, sensor, trials, folds, seed, repeats, z, jobs)
    scene = Scene.from_delta_t(contact_s=check_positive("contact time [s]", contact_s), noise_c=noise,
                               delta_t_c=dt)
    t0 = time.perf_counter()
    f1, se = _svm_f1(ex, objs, scene, slab)
    ilog = _IdealLog(ex, objs, slab, n_mc)
    ideal = ilog.f1(scene)
    yes = f1 >= phi
    check = semi_infinite_check(objs, slab, ex.sensor, needed_s=scene.contact_s, noise_c=noise, delta_t_c=dt,
                                fraction=fraction)
    inputs = _thin_inputs(objs, slab, ex, noise_c=noise, delta_t_c=dt, contact_s=scene.contact_s, threshold=phi)
    extra = _extra(check, slab, ilog, t0, distinguishable=yes, svm_f1=f1, svm_standard_error=se,
                   verdict="confident" if abs(f1 - phi) >= z * se else "uncertain", ideal_f1=ideal,
                   ideal_distinguishable=ideal >= phi)
    return Answer("distinguishable", float(yes), (f1 - z * se, f1 + z * se), ideal, "computed", None, None,
                  inputs, {}, extra)


def thin_delta_e(e: float | None = None, *, thickness_m: float, diffusivity_m2_s=None, material: str | None = None,
                 backing=DEFAULT_BACKING, contact_s: float,
                 noise_c: float = 0.05, delta_t_c: float = 10.0, threshold: float = 0.9, sensor=None,
                 width: float = 80.0, trials: int = 100, folds: int = 3, seed: int = 0, repeats: int = 4,
                 z: float = 2.0, jobs: int = -1, e_max: float = 40000.0, n_mc: int = 1000,
                 fraction: float = NOISE_FRACTION, label: str | None = None):
    """delta(e) of a thin sample: the smallest effusivity difference separable from ``e``, both directions.

    The reference is the class ``[e, e + width)`` with diffusivity
    ``diffusivity_m2_s`` (a value or a ``(low, high)`` range) or, with
    ``material``, that material's diffusivity range (``e`` then defaults to
    the middle of its effusivity range); the partners ``[e +- d, e +- d + width)`` are hypothetical
    objects that differ **only in effusivity**: they share the reference's
    diffusivity, thickness and backing (nothing gives a diffusivity to a bare
    effusivity). Bisection on ``d`` as :func:`designkit.query.exact_delta_e`.
    """
    from .table import Answer, _bisect, _exact_setup, _scene_inputs, _threshold

    phi = _threshold(threshold)
    noise, dt = _scene_inputs(noise_c, delta_t_c)
    ex = _exact_setup(sensor, width, trials, folds, seed, repeats, z, jobs)
    slab = SlabScene.make(thickness_m, backing)
    if material is not None:
        if diffusivity_m2_s is not None:
            raise InputError(f"the diffusivity of {material!r} comes from the materials database; "
                             "--diffusivity is for a reference given as an effusivity")
        from ..models.slab import material_properties

        mat = material_properties(material)
        diffusivity_m2_s = (mat.diffusivity_min_m2_s, mat.diffusivity_max_m2_s)
        e = mat.effusivity if e is None else e
        label = label or mat.name
    if e is None:
        raise InputError("give the reference as an effusivity or a material")
    e = check_effusivity("e", e)
    if diffusivity_m2_s is None:
        raise InputError("delta-e with a thickness needs the reference's diffusivity (--diffusivity, "
                         "or a material with --m)")
    a = np.atleast_1d(np.asarray(diffusivity_m2_s, dtype=np.float64)).ravel()
    if a.size not in (1, 2):
        raise InputError("give the reference's diffusivity as one value or a (low, high) range [m^2/s]")
    alpha = (float(a[0]), float(a[-1]))
    scene = Scene.from_delta_t(contact_s=check_positive("contact time [s]", contact_s), noise_c=noise,
                               delta_t_c=dt)
    ref_obj = SlabObject(label or f"{e:g}", (e, e + ex.width), alpha)
    t0 = time.perf_counter()
    res: dict[str, Any] = {}
    ilog = _IdealLog(ex, None, slab, n_mc)
    checked = [ref_obj]
    for key, sign, limit in (("delta_e_upper", +1, e_max - e - ex.width), ("delta_e_lower", -1, e - ex.width)):
        if limit < ex.width:
            res[key] = res[key + "_ideal"] = None
            continue

        def part(d, sign=sign):
            return SlabObject(f"{e + sign * d:g}", (e + sign * d, e + sign * d + ex.width), alpha)

        def ok(d, part=part):
            return _svm_f1(ex, (ref_obj, part(d)), scene, slab)[0] >= phi

        def iok(d, part=part):
            ilog.objs = _ordered(ref_obj, part(d))
            return ilog.f1(scene) >= phi

        res[key] = _bisect(ok, 0.0, limit, ex.width / 2) if ok(limit) else None
        res[key + "_ideal"] = _bisect(iok, 0.0, limit, 1.0) if iok(limit) else None
        found = [v for v in (res[key], res[key + "_ideal"]) if v is not None]
        if found:
            checked.append(part(max(found)))
    finite = [v for v in (res["delta_e_lower"], res["delta_e_upper"]) if v is not None]
    ifinite = [v for v in (res["delta_e_lower_ideal"], res["delta_e_upper_ideal"]) if v is not None]
    check = semi_infinite_check(checked, slab, ex.sensor, needed_s=scene.contact_s, noise_c=noise, delta_t_c=dt,
                                fraction=fraction)
    inputs = {"e": e, "noise_c": noise, "delta_t_c": dt, "contact_s": scene.contact_s, "threshold": phi,
              "width": ex.width, "trials": ex.trials, "repeats": ex.repeats, "seed": ex.seed,
              "sensor": ex.sensor.name, "reference": ref_obj.to_dict(), "slab": slab.to_dict(),
              "thickness_m": slab.thickness_m, "backing": slab.backing.name,
              "rule": "partners differ from the reference only in effusivity (same diffusivity range)"}
    for k in ("delta_e_lower", "delta_e_upper"):
        res[k + "_interval"] = [None, None]
    return Answer("delta-e", min(finite) if finite else None, (None, None), min(ifinite) if ifinite else None,
                  "computed", None, None, inputs, {}, _extra(check, slab, ilog, t0, **res))
