"""A layered sensor: a heater film on a backing, touching an object through a contact conductance.

The reading of a semi-infinite object (e_o, at Ta) touching, through an interface conductance h_c, a
film (the sensor's e_s and alpha_s, thickness L, thermistor at depth x) on a backing (e_b, alpha_b;
semi-infinite, or of thickness L_b with its far face held at Ts0), film and backing initially at Ts0;
then a first-order thermistor lag (``lag_s``) and, optionally, a Savitzky-Golay smoothing of the sampled
reading like the host's of the shared robot recordings (window 99, order 3 at 200 Hz). The exact solution
in the Laplace domain (the film's admittance in reflection form, object, interface and sensor in series)
is inverted with the fixed Talbot method (Abate and Valko, 2004; about 1e-11), vectorized over times and
objects. Limits (tested): ``L -> 0`` or ``e_b = e_s`` is the
:class:`~designkit.models.contact.Contact` model, and with ``h_c = inf`` the paper's semi-infinite model.
Only the ratios of effusivities (and ``h_c``) to ``e_s`` matter. The derivation, its limits and its
references: docs/sensor-models.md, "The layered model's exact solution".
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import InputError, check_nonnegative, check_positive
from .base import ForwardModel

__all__ = ["Layered", "laplace_parts", "laplace_reading", "savgol_smooth", "smooth_cut", "smoothing_grid",
           "talbot_invert", "talbot_points"]

#: Fixed-Talbot nodes: 24 gives about 1e-11 absolute error in double precision.
TALBOT_NODES = 24


def _talbot_contour(nodes: int):
    """Node angles' contour factors: ``s_k = r * z_k`` and the weights ``(1 + i sigma_k)``."""
    k = np.arange(1, nodes)
    theta = k * math.pi / nodes
    cot = 1.0 / np.tan(theta)
    z = theta * (cot + 1j)                        # s(theta) / r
    sigma = theta + (theta * cot - 1.0) * cot
    return z, 1.0 + 1j * sigma


def talbot_points(time_s, nodes: int = TALBOT_NODES) -> tuple[np.ndarray, np.ndarray]:
    """The fixed-Talbot contour points and weights of times ``time_s``: ``f(t_i) = Re sum_k W_ik F(p_ik)``.

    Parameters
    ----------
    time_s : array_like, shape (m,)
        Times [s], all > 0.
    nodes : int
        Contour points per time.

    Returns
    -------
    p : complex ndarray, shape (m, nodes)
        Where to evaluate the transform [s^-1].
    weights : complex ndarray, shape (m, nodes)
        ``W``: the inverse at ``t_i`` is ``Re(sum_k W_ik F(p_ik))``.
    """
    t = np.asarray(time_s, dtype=np.float64)
    if np.any(~(t > 0)):
        raise InputError("talbot_invert needs times > 0")
    r = 2.0 * nodes / (5.0 * t)                   # (m,)
    z, wk = _talbot_contour(nodes)
    p = np.concatenate([r[:, None] + 0j, r[:, None] * z[None, :]], axis=1)   # (m, nodes)
    rt = 2.0 * nodes / 5.0                        # r t, the same for every t
    ez = np.exp(rt * z)                           # exp(t s_k) = exp(r t z_k)
    k = np.concatenate([[0.5 * math.exp(rt) + 0j], ez * wk])                  # (nodes,)
    return p, (r / nodes)[:, None] * k[None, :]


def talbot_invert(transform, time_s, *, nodes: int = TALBOT_NODES) -> np.ndarray:
    """Inverse Laplace transform by the fixed Talbot method (Abate & Valko 2004).

    Parameters
    ----------
    transform : callable
        ``F(p)`` for a complex array ``p`` of shape ``(m, nodes)``; returns an
        array broadcastable to ``(..., m, nodes)`` (leading axes: objects).
    time_s : array_like, shape (m,)
        Times [s], all > 0.
    nodes : int
        Contour points per time (accuracy about ``10^(-0.6 nodes)`` until
        double-precision rounding, about 1e-11, dominates).

    Returns
    -------
    ndarray, shape (..., m)
        ``f(t)``, real.

    Examples
    --------
    >>> import numpy as np
    >>> f = talbot_invert(lambda p: 1.0 / (p + 1.0), np.array([0.5, 2.0]))
    >>> bool(np.allclose(f, np.exp([-0.5, -2.0]), rtol=1e-10, atol=0))
    True
    """
    p, weights = talbot_points(time_s, nodes)
    F = np.asarray(transform(p))
    return _talbot_sum(F, weights)


def _talbot_sum(F: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """``Re sum_k W_ik F_..ik`` over the last axis, term by term in a fixed order (elementwise operations
    only: no reduction whose rounding could depend on memory alignment, so every run gives the same bits)."""
    F = np.broadcast_to(F, np.broadcast_shapes(F.shape, weights.shape))
    Fr, Fi, Wr, Wi = F.real, F.imag, weights.real, weights.imag
    out = Fr[..., 0] * Wr[:, 0] - Fi[..., 0] * Wi[:, 0]
    for k in range(1, weights.shape[1]):
        out += Fr[..., k] * Wr[:, k]
        out -= Fi[..., k] * Wi[:, k]
    return out


def savgol_smooth(values, window: int, order: int, *, pad_before: int | None = None) -> np.ndarray:
    """The host's Savitzky-Golay smoothing (``scipy.signal.savgol_filter``, mode ``"interp"``).

    Parameters
    ----------
    values : array_like, shape (..., m)
        Uniformly sampled series (last axis).
    window, order : int
        Window length (odd, samples) and polynomial order; ``window <= 1``
        returns ``values`` unchanged.
    pad_before : int, optional
        Zeros to put before the series first (a touch's reading before
        contact), removed again afterwards: the smoothing then sees the
        contact onset as the host did. Default: none.

    Returns
    -------
    ndarray, same shape as ``values``.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.arange(200.0) ** 2
    >>> bool(np.allclose(savgol_smooth(x, 99, 3), x))   # a polynomial of degree <= 3 passes unchanged
    True
    """
    from scipy.signal import fftconvolve

    v = np.asarray(values, dtype=np.float64)
    if window <= 1:
        return v.copy()
    pad = int(pad_before or 0)
    if pad:
        v = np.concatenate([np.zeros(v.shape[:-1] + (pad,)), v], axis=-1)
    if v.shape[-1] < window:
        raise InputError(f"smoothing window {window} is longer than the series ({v.shape[-1]} samples)")
    # scipy.signal.savgol_filter(v, window, order, mode="interp") as two linear operators: the filter's
    # coefficients by FFT convolution inside, and at each end the projection onto the polynomial fitted to
    # the first / last window (what savgol_filter's polyfit does per row). Same values to 1e-14 relative
    # (why: docs/decisions-log.md).
    coeffs, head, tail = _savgol_operators(int(window), int(order))
    half = window // 2
    out = np.empty(v.shape)
    out[..., half:v.shape[-1] - half] = fftconvolve(v, coeffs.reshape((1,) * (v.ndim - 1) + (-1,)), mode="valid",
                                                    axes=-1)
    out[..., :half] = v[..., :window] @ head.T
    out[..., v.shape[-1] - half:] = v[..., -window:] @ tail.T
    return out[..., pad:]


@functools.lru_cache(maxsize=8)
def _savgol_operators(window: int, order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Savitzky-Golay convolution coefficients and the (half, window) end projections of mode "interp"."""
    from scipy.signal import savgol_coeffs

    half = window // 2
    x = np.arange(window, dtype=np.float64) - half
    vander = np.vander(x, order + 1, increasing=True)
    proj = vander @ np.linalg.pinv(vander)         # fitted values of the window's least-squares polynomial
    return savgol_coeffs(window, order), proj[:half].copy(), proj[window - half:].copy()


def laplace_reading(p, e_object, *, e_film: float, diffusivity_film_m2_s: float, depth_m: float,
                    thickness_m: float, e_backing: float, diffusivity_backing_m2_s: float,
                    conductance_w_m2k: float, lag_s: float, backing_thickness_m: float = math.inf) -> np.ndarray:
    """Laplace transform ``U(p)`` of the normalized reading (module docstring).

    Parameters
    ----------
    p : complex ndarray, shape (m, n)
        Transform variable [s^-1] (``Re`` sqrt(p) > 0 on the Talbot contour).
    e_object : ndarray, shape (K,)
        Object effusivities [J s^-1/2 K^-1 m^-2], > 0 and finite, or inf.
    e_film, e_backing : float
        Film (sensor) and backing effusivities [J s^-1/2 K^-1 m^-2].
    diffusivity_film_m2_s, diffusivity_backing_m2_s : float
        [m^2 s^-1].
    depth_m, thickness_m : float
        Thermistor depth and film thickness [m].
    conductance_w_m2k : float
        Interface conductance h_c [W m^-2 K^-1] (inf: perfect contact).
    lag_s : float
        Thermistor time constant [s] (0: none).

    Returns
    -------
    complex ndarray, shape (K, m, n)
    """
    parts = laplace_parts(p, e_film=e_film, diffusivity_film_m2_s=diffusivity_film_m2_s, depth_m=depth_m,
                          thickness_m=thickness_m, e_backing=e_backing,
                          diffusivity_backing_m2_s=diffusivity_backing_m2_s, conductance_w_m2k=conductance_w_m2k,
                          lag_s=lag_s, backing_thickness_m=backing_thickness_m)
    A, B, C = parts
    eo = np.asarray(e_object, dtype=np.float64)[:, None, None]
    return C / (A + B * np.where(np.isinf(eo), 0.0, 1.0 / np.where(np.isinf(eo), 1.0, eo)))   # e_o = inf: C / A


def laplace_parts(p, *, e_film: float, diffusivity_film_m2_s: float, depth_m: float, thickness_m: float,
                  e_backing: float, diffusivity_backing_m2_s: float, conductance_w_m2k: float, lag_s: float,
                  backing_thickness_m: float = math.inf) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The object-independent parts of ``U(p)``: ``U = C / (A + B / e_o)`` (parameters: :func:`laplace_reading`).

    Object, interface and sensor are heat resistances in series, so the object
    enters ``U`` only through ``1 / e_o``: with the sensor's admittance ``Y``,
    ``A = 1 + Y / h_c``, ``B = Y / sqrt(p)`` and ``C`` the depth profile over
    ``p`` and the lag. Computed once for a scene's time grid, they give every
    object's transform at the cost of one complex division per point.

    Returns
    -------
    (A, B, C) : complex ndarrays, shape (m, n)
    """
    p = np.asarray(p, dtype=np.complex128)
    sp = np.sqrt(p)
    q = sp / math.sqrt(diffusivity_film_m2_s)
    qb = sp / math.sqrt(diffusivity_backing_m2_s)
    if math.isinf(backing_thickness_m):
        Eb = np.zeros_like(p)
        R = (e_film - e_backing) / (e_film + e_backing) + 0j * p
    else:  # far face held at Ts0: backing admittance e_b sqrt(p) coth(q_b L_b)
        Eb = np.exp(-2.0 * qb * backing_thickness_m)
        coth = (1.0 + Eb) / (1.0 - Eb)
        R = (e_film - e_backing * coth) / (e_film + e_backing * coth)
    E = np.exp(-2.0 * q * thickness_m)
    Y = e_film * sp * (1.0 - R * E) / (1.0 + R * E)                    # film + backing admittance
    A = 1.0 + (0.0 if math.isinf(conductance_w_m2k) else Y / conductance_w_m2k)
    B = Y / sp
    if depth_m <= thickness_m:
        profile = (np.exp(-q * depth_m) + R * np.exp(-q * (2.0 * thickness_m - depth_m))) / (1.0 + R * E)
    else:
        zb = min(depth_m - thickness_m, backing_thickness_m)
        decay = np.exp(-qb * zb)
        if not math.isinf(backing_thickness_m):
            decay = (decay - np.exp(-qb * (2.0 * backing_thickness_m - zb))) / (1.0 - Eb)
        profile = (1.0 + R) * np.exp(-q * thickness_m) * decay / (1.0 + R * E)
    C = profile / p                                                     # U_0 p times the profile
    if lag_s > 0:
        C = C / (1.0 + lag_s * p)
    return np.broadcast_to(A, p.shape), B, C


@functools.lru_cache(maxsize=64)
def _scene_parts(kwargs: tuple, time_bytes: bytes, nodes: int) -> tuple[np.ndarray, ...]:
    """``(d_re, d_im^2, g_re, g_im d_im)`` on a time grid (m,), each (nodes, m), read-only: ``d = A / B`` and
    ``g = W C / B`` (``W`` the Talbot weights), once per scene and grid (a memo of a pure function; the last 64
    kept: a calibrated rig's 24 touch ramps read lag grids of their own). Never sliced from a longer grid: numpy's
    complex products round an element by where it lies in the array, and a reading must not depend on what was
    read before."""
    t = np.frombuffer(time_bytes, dtype=np.float64)
    p, weights = talbot_points(t, nodes)
    A, B, C = laplace_parts(p, **dict(kwargs))
    d, g = A / B, weights * (C / B)
    parts = tuple(np.ascontiguousarray(a.T) for a in (d.real, d.imag ** 2, g.real, g.imag * d.imag))
    for a in parts:
        a.setflags(write=False)
    return parts


def _talbot_readings(parts, inv_e: np.ndarray) -> np.ndarray:
    """The inverse at a grid's times of objects of ``1 / e_o`` = ``inv_e`` (K,), shape (K, m), from
    :func:`_scene_parts`: the Talbot terms ``Re(g / (d + v)) = (g_re x + g_im d_im) / (x^2 + d_im^2)``,
    ``x = d_re + v``, in real arithmetic, summed node by node in a fixed order (elementwise only: the same bits
    on every run)."""
    d_re, d_im2, g_re, g_dim = parts
    x = d_re + inv_e[:, None, None]                      # (K, nodes, m)
    terms = g_re * x
    terms += g_dim
    x *= x
    x += d_im2
    terms /= x
    out = terms[:, 0].copy()
    for k in range(1, terms.shape[1]):
        out += terms[:, k]
    return out


@dataclass(frozen=True)
class Layered(ForwardModel):
    """A heater film on a backing, an interface conductance, and the measurement chain.

    The sensor's effusivity e_s and diffusivity alpha_s are the film's
    (:class:`~designkit.sensor.Sensor`), the thermistor sits at the sensor's
    ``depth_m`` (in the film when ``depth_m <= film_thickness_m``).

    Parameters
    ----------
    film_thickness_m : float
        Film thickness L [m] (> 0; ``inf``: a semi-infinite sensor).
    backing_effusivity_ws05_m2k : float
        Backing effusivity e_b [W s^1/2 m^-2 K^-1 = J s^-1/2 K^-1 m^-2] (> 0).
    backing_diffusivity_m2_s : float or None
        Backing diffusivity [m^2 s^-1]; matters only for a thermistor below
        the film or a backing of finite thickness (None: the film's).
    backing_thickness_m : float
        Backing thickness L_b [m] (``inf``: semi-infinite). A finite backing's
        far face is held at the sensor's initial temperature: then the
        reading settles at a steady state between Ts0 and the object's
        temperature instead of reaching the object's.
    conductance_w_m2k : float
        Sensor-object interface conductance h_c [W m^-2 K^-1] (``inf``:
        perfect contact).
    lag_s : float
        First-order time constant of the thermistor (and the host's low-pass
        filter) [s] (0: none).
    smoothing_window : int
        Savitzky-Golay window [samples] applied to the sampled reading (0:
        none; the shared recordings': 99); needs uniformly sampled times.
    smoothing_order : int
        Savitzky-Golay polynomial order (the shared recordings': 3).

    Examples
    --------
    >>> from designkit import SENSORS
    >>> from designkit.models.semi_infinite import SemiInfinite
    >>> s = SENSORS["paper"]
    >>> same = Layered(film_thickness_m=1e-3, backing_effusivity_ws05_m2k=s.effusivity)
    >>> t = [0.5, 2.0]
    >>> bool(np.allclose(same.response(t, [20000.0], s), SemiInfinite().response(t, [20000.0], s),
    ...                  rtol=0, atol=1e-9))
    True
    >>> finger = Layered(film_thickness_m=100e-6, backing_effusivity_ws05_m2k=300.0,
    ...                  conductance_w_m2k=3000.0, lag_s=0.2)
    >>> u = finger.response(t, [400.0, 20000.0], s)
    >>> bool(u[1, 1] > u[0, 1] > 0)                 # metal pulls harder than wood
    True
    """

    film_thickness_m: float = 125e-6
    backing_effusivity_ws05_m2k: float = 500.0
    backing_diffusivity_m2_s: float | None = None
    conductance_w_m2k: float = math.inf
    lag_s: float = 0.0
    backing_thickness_m: float = math.inf
    smoothing_window: int = 0
    smoothing_order: int = 3

    name = "layered"
    shared_shape = False
    solved_numerically = True
    shared_response = True
    units = {"film_thickness_m": "m", "backing_effusivity_ws05_m2k": "J s^-1/2 K^-1 m^-2",
             "backing_diffusivity_m2_s": "m^2 s^-1", "conductance_w_m2k": "W m^-2 K^-1", "lag_s": "s", "backing_thickness_m": "m",
             "smoothing_window": "samples", "smoothing_order": ""}

    def __post_init__(self) -> None:
        for name in ("film_thickness_m", "conductance_w_m2k", "backing_thickness_m"):
            if getattr(self, name) is None:  # what to_dict writes for inf (JSON has no infinity)
                object.__setattr__(self, name, math.inf)
        object.__setattr__(self, "film_thickness_m",
                           check_positive("film thickness [m]", self.film_thickness_m, allow_inf=True))
        object.__setattr__(self, "backing_effusivity_ws05_m2k",
                           check_positive("backing effusivity [J s^-1/2 K^-1 m^-2]",
                                          self.backing_effusivity_ws05_m2k))
        if self.backing_diffusivity_m2_s is not None:
            object.__setattr__(self, "backing_diffusivity_m2_s",
                               check_positive("backing diffusivity [m^2/s]", self.backing_diffusivity_m2_s))
        object.__setattr__(self, "conductance_w_m2k",
                           check_positive("interface conductance h_c [W m^-2 K^-1]", self.conductance_w_m2k,
                                          allow_inf=True))
        object.__setattr__(self, "lag_s", check_nonnegative("thermistor lag [s]", self.lag_s))
        object.__setattr__(self, "backing_thickness_m",
                           check_positive("backing thickness [m]", self.backing_thickness_m, allow_inf=True))
        window, order = self.smoothing_window, self.smoothing_order
        if isinstance(window, bool) or not isinstance(window, (int, np.integer)) or window < 0:
            raise InputError(f"smoothing window must be a whole number of samples >= 0, got {window!r}")
        if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 0:
            raise InputError(f"smoothing order must be a whole number >= 0, got {order!r}")
        if window > 1 and (window % 2 == 0 or order >= window):
            raise InputError(f"smoothing window must be odd and longer than the order, got window {window}, "
                             f"order {order}")
        object.__setattr__(self, "smoothing_window", int(window))
        object.__setattr__(self, "smoothing_order", int(order))

    # ------------------------------------------------------------ physics
    def _laplace_kwargs(self, sensor) -> dict[str, Any]:
        thick = self.film_thickness_m
        depth = float(sensor.depth_m)
        if math.isinf(thick):
            thick = 1e3  # exp(-2 q L) underflows to 0 for every contour point: a semi-infinite film
        alpha_b = float(self.backing_diffusivity_m2_s or sensor.diffusivity_m2_s)
        return dict(e_film=float(sensor.effusivity), diffusivity_film_m2_s=float(sensor.diffusivity_m2_s),
                    depth_m=depth, thickness_m=thick, e_backing=self.backing_effusivity_ws05_m2k,
                    diffusivity_backing_m2_s=alpha_b, conductance_w_m2k=self.conductance_w_m2k, lag_s=self.lag_s,
                    backing_thickness_m=self.backing_thickness_m)

    def initial_value(self, e_object, sensor) -> np.ndarray:
        """``u(0+)``: nonzero only for a surface thermistor, perfect contact and no lag."""
        eo = np.atleast_1d(np.asarray(e_object, dtype=np.float64))
        if sensor.depth_m > 0 or not math.isinf(self.conductance_w_m2k) or self.lag_s > 0:
            return np.zeros(eo.shape)
        with np.errstate(divide="ignore", over="ignore"):
            return 1.0 / (1.0 + sensor.effusivity / eo)

    def conduction(self, time_s, e_object, sensor, *, nodes: int = TALBOT_NODES) -> np.ndarray:
        """Reading after conduction and the thermistor lag, before any smoothing: shape (K, m).

        ``u = 0`` for ``t <= 0`` except the surface-thermistor limit
        (:meth:`initial_value`) at ``t = 0``.
        """
        t = np.atleast_1d(np.asarray(time_s, dtype=np.float64))
        eo = np.atleast_1d(np.asarray(e_object, dtype=np.float64))
        if np.any(np.isnan(eo)) or np.any(eo < 0):
            raise InputError("object effusivities must be >= 0 (inf allowed)")
        out = np.zeros((eo.size, t.size))
        pos = t > 0
        live = eo > 0
        if pos.any() and live.any():
            kw = tuple(sorted(self._laplace_kwargs(sensor).items()))
            tp = np.ascontiguousarray(t[pos])
            x = eo[live]
            inv = np.where(np.isinf(x), 0.0, 1.0 / np.where(np.isinf(x), 1.0, x))
            out[np.ix_(live, pos)] = _talbot_readings(_scene_parts(kw, tp.tobytes(), int(nodes)), inv)
        zero = t == 0
        if zero.any():
            out[:, zero] = self.initial_value(eo, sensor)[:, None]
        return np.clip(out, 0.0, 1.0)

    def response(self, time_s, e_object, sensor, *, diffusivity_m2_s=None, tolerance: float = 1e-9) -> np.ndarray:
        """Normalized reading (K, m); with smoothing, the times must be uniform (1/fs apart).

        With smoothing the reading is smoothed as the host smoothed a
        recording: zeros before contact (``window // 2`` samples of them
        before the first time), the series after; the last ``window // 2``
        samples use the filter's polynomial fit at the end (``mode="interp"``).
        """
        t = np.atleast_1d(np.asarray(time_s, dtype=np.float64))
        if self.smoothing_window <= 1:
            return self.conduction(t, e_object, sensor)
        grid = smoothing_grid(t, sensor.sample_rate_hz, self.smoothing_window, what="the smoothed layered model")
        return smooth_cut(self.conduction(grid, e_object, sensor), t.size, self.smoothing_window, self.smoothing_order)


def smoothing_grid(time_s, sample_rate_hz: float, window: int, *, what: str = "a smoothed model") -> np.ndarray:
    """Where a reading smoothed as the host smoothed a recording (Savitzky-Golay, ``mode="interp"``) reads the
    model: ``window // 2`` samples before the first of the uniformly spaced ``time_s`` (zeros before contact, as
    the host saw them; one time: ``1 / sample_rate_hz`` apart), the times, and past the last where the series is
    shorter than the window; :func:`smooth_cut` smooths the reading and cuts it back.

    >>> t = np.arange(300) / 200.0
    >>> u = smooth_cut(np.clip(smoothing_grid(t, 200.0, 99), 0.0, None)[None, :] * 0.1, t.size, 99, 3)
    >>> bool(np.allclose(u[0, 60:240], 0.1 * t[60:240]))   # a line away from the kink at 0 passes unchanged
    True
    """
    t = np.atleast_1d(np.asarray(time_s, dtype=np.float64))
    if t.size > 1:
        dt = np.diff(t)
        if np.any(np.abs(dt - dt[0]) > 1e-6 * dt[0]) or dt[0] <= 0:
            raise InputError(f"{what} needs uniformly sampled times")
        step = float(dt[0])
    else:
        step = 1.0 / float(sample_rate_hz)
    half = window // 2
    grid = [t[0] - step * np.arange(half, 0, -1), t]
    if half + t.size < window:  # short series: extend past the end, smooth, cut
        grid.append(t[-1] + step * np.arange(1, window - half - t.size + 1))
    return np.concatenate(grid)


def smooth_cut(u, n_times: int, window: int, order: int) -> np.ndarray:
    """Readings (K, len(grid)) on a :func:`smoothing_grid` smoothed, cut back to its ``n_times`` times and
    clipped to [0, 1]."""
    half = window // 2
    return np.clip(savgol_smooth(u, window, order)[:, half:half + n_times], 0.0, 1.0)
