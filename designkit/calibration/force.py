"""A touch's force and the contact area it puts down.

A finger presses in over a few tenths of a second, and the contact area grows with the force.
:func:`relative_force` is a touch's force over its plateau (averaged over
:data:`FORCE_SMOOTHING_S`), :func:`force_noise` the noise on it, :func:`contact_area` the share of
the final area in contact (the forward model's rule, :func:`designkit.models.ramp.area_share`, with
the cap beyond the noise band), :func:`area_weighted` the reading of a touch whose area grows
(the area-weighted sum of step responses), and :func:`nominal_force_profile` the median press a
sensor file records for questions to play.
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from .._validation import InputError
from ..models.ramp import area_share
from .trials import Trial

__all__ = ["FORCE_NOISE_BAND_SD", "FORCE_PROFILE_S", "FORCE_SMOOTHING_S", "area_weighted", "contact_area",
           "force_noise", "nominal_force_profile", "relative_force"]


#: The force is averaged over this window [s] (centred) before it sets the contact area: the force sensor's
#: white noise, clipped where the area is whole, reads the plateau's area low (errors in variables;
#: :data:`FORCE_NOISE_BAND_SD` removes the rest; docs/sensor-models.md). A finger presses over 0.3 s or more:
#: 25 ms rounds only the ramp's corners.
FORCE_SMOOTHING_S = 0.025


def relative_force(trial: Trial) -> np.ndarray:
    """The touch's force divided by its plateau (median from 1 s after the onset), on its grid.

    The force is first averaged over :data:`FORCE_SMOOTHING_S` (a centred moving
    average, :func:`scipy.ndimage.uniform_filter1d`, ends held): a linear ramp
    is unchanged but for its corners.

    Examples
    --------
    >>> t = np.arange(-200, 1000) / 200.0
    >>> tr = Trial(t, np.zeros(t.size), np.zeros(t.size), np.clip(t, 0.0, 1.0) * 4.0, "wood")
    >>> relative_force(tr)[[0, 300, 398, 400, 402]].round(4).tolist()
    [0.0, 0.5, 0.99, 0.997, 1.0]
    """
    t, f = np.asarray(trial.time_s), np.asarray(trial.force_n, dtype=np.float64)
    late = (t >= 1.0) & np.isfinite(f)
    if not late.any() or not np.isfinite(f).all():
        raise InputError(f"trial {trial.source}: a force-driven contact area needs the force channel on every "
                         "sample, to 1 s after the onset or later")
    f = _averaged_force(f, _force_window(trial))
    plateau = float(np.median(f[late]))
    if plateau <= 0:
        raise InputError(f"trial {trial.source}: the force's plateau is {plateau:.3g} N (no contact?)")
    return f / plateau


def _force_window(trial: Trial) -> int:
    """Samples of the :data:`FORCE_SMOOTHING_S` average (odd); InputError on a non-uniform grid."""
    dt = np.diff(np.asarray(trial.time_s))
    if dt.size == 0 or not np.allclose(dt, dt[0], rtol=1e-6, atol=1e-9):
        raise InputError(f"trial {trial.source}: a force-driven contact area needs a uniform time grid")
    return 2 * int(round(0.5 * FORCE_SMOOTHING_S / float(dt[0]))) + 1


def _averaged_force(f: np.ndarray, width: int) -> np.ndarray:
    from scipy.ndimage import uniform_filter1d

    return uniform_filter1d(f, width, mode="nearest") if width > 1 else f


#: The contact area is capped at its whole only where the measured force exceeds its plateau by more than this
#: many SDs of its own noise (:func:`force_noise`). On the plateau the true force *is* the plateau, so half the
#: noisy samples lie above it; capping those at once reads the area low by ``0.4 sigma / (1 - c)`` on average
#: (errors in variables: granite's e_o/e_s +0.20 % in the pty round trips, interval coverage 0.74), a bias that
#: does not shrink with more touches. Within the band the map stays linear, so the noise averages out; beyond
#: it (an overshoot of the press, larger than noise) the cap holds. The bias left is ``sigma psi(-3) / (1 - c)``,
#: a thousandth of the capped map's (``psi(z) = z Phi(z) + phi(z)``); an overshoot reads at most ``3 sigma /
#: (1 - c)`` too much area. Not tuned: three SDs, the usual band of a Gaussian noise. A noise-free force (a
#: smoothed recording) keeps today's map.
FORCE_NOISE_BAND_SD = 3.0


def force_noise(trial: Trial) -> float:
    """SD of the white noise on :func:`relative_force`'s plateau (a share of the plateau force).

    From the force's own residuals: the second differences of the raw force from 1 s
    after the onset (where the plateau is taken), whose spread is ``sqrt(6) sigma``
    for white noise of SD ``sigma`` and hardly feels a slow drift or a ramp's corner
    (median absolute deviation, 1.4826 MAD for a Gaussian), divided by the square
    root of the :data:`FORCE_SMOOTHING_S` average's width and by the plateau. A
    smoothed recording's force reads nearly 0.

    Examples
    --------
    >>> t = np.arange(-200, 1400) / 200.0
    >>> f = np.clip(t, 0.0, 1.0) * 10.0 + 0.02 * np.random.default_rng(0).standard_normal(t.size)
    >>> tr = Trial(t, np.zeros(t.size), np.zeros(t.size), f, "wood")
    >>> round(force_noise(tr) / (0.02 / 10 / 5 ** 0.5), 1)     # 0.02 N on 10 N, averaged over 5 samples
    1.0
    """
    t, f = np.asarray(trial.time_s), np.asarray(trial.force_n, dtype=np.float64)
    late = t >= 1.0
    width = _force_window(trial)
    d2 = np.diff(f[late], 2)
    if d2.size < 10:
        return 0.0
    sigma = 1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / math.sqrt(6.0)
    plateau = float(np.median(_averaged_force(f, width)[late]))
    return sigma / math.sqrt(width) / plateau if plateau > 0 else 0.0


def contact_area(force_rel, fraction: float, band=0.0) -> np.ndarray:
    """Share of the final contact area in contact, ``clip((F / F_p - c) / (1 - c), 0, (1 + b - c) / (1 - c))``.

    The forward model's rule (:func:`designkit.models.ramp.area_share`, ``b = 0``) on a
    measured force: the cap applies only beyond the plateau's noise band ``b``
    (:data:`FORCE_NOISE_BAND_SD` times :func:`force_noise`; broadcast against
    ``force_rel``), so the force's noise does not read the plateau's area low.

    Examples
    --------
    >>> contact_area([0.1, 0.3, 0.65, 1.0, 1.002, 1.2], 0.3).round(4).tolist()
    [0.0, 0.0, 0.5, 1.0, 1.0, 1.0]
    >>> contact_area([0.1, 0.3, 0.65, 1.0, 1.002, 1.2], 0.3, band=0.003).round(4).tolist()
    [0.0, 0.0, 0.5, 1.0, 1.0029, 1.0043]
    """
    if np.all(np.asarray(band) == 0):
        return area_share(force_rel, fraction)
    c = float(fraction)
    area_share(0.0, c)  # validates c
    b = np.asarray(band, dtype=np.float64)
    return np.clip((np.asarray(force_rel, dtype=np.float64) - c) / (1.0 - c), 0.0, (1.0 + b - c) / (1.0 - c))


def area_weighted(step, time_s: np.ndarray, area: "np.ndarray | None", offset_s: float) -> np.ndarray:
    """Readings of touches whose contact area grows: ``u_i(t_k) = sum_j dA_ij u(t_k - t_j - offset)``.

    ``step(t)`` is the full-contact reading at times ``t > 0``; ``area`` (n, m)
    the share of the final area in contact at each sample of the uniform grid
    ``time_s`` (what is in contact at the first sample counts from there). A
    discrete convolution (:func:`scipy.signal.fftconvolve`) of the area's
    increments with the step response on the lags of the grid. ``area`` None:
    full contact from the offset on, ``step(t - offset)`` where positive and 0
    before, shape (m,) (any grid).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(-5, 20) * 0.1
    >>> full = area_weighted(lambda tt: 1.0 - np.exp(-tt), t, np.ones((1, t.size)) * (t >= 0), 0.0)
    >>> bool(np.allclose(full[0], np.where(t > 0, 1.0 - np.exp(-np.maximum(t, 0.0)), 0.0)))
    True
    """
    if area is None:
        tt = time_s - offset_s
        u = np.zeros(tt.size)
        pos = tt > 0
        if pos.any():
            u[pos] = step(tt[pos])
        return u
    from scipy.signal import fftconvolve

    m = time_s.size
    dt = float(time_s[1] - time_s[0])
    # out[k] = sum_j dA_j u(k dt - j dt - offset): only lags k - j in [-(m-1), m-1] with a positive argument
    # matter, so the kernel starts at the first positive one (index i0 on that lag grid) and the convolution
    # is of length about 2m rather than 3m (a third of a fit's time went to this FFT)
    lags = np.arange(-(m - 1), m) * dt - offset_s
    pos = np.flatnonzero(lags > 0)
    if pos.size == 0:
        return np.zeros(area.shape)
    i0 = int(pos[0])
    u1 = step(lags[i0:])
    d_area = np.diff(area, axis=-1, prepend=0.0)
    shift = i0 - (m - 1)                      # out[k] = full[k - shift] of the convolution with u1
    if shift >= m:
        return np.zeros(area.shape)
    u1 = u1[:m - shift]                        # kernel entries needed: k - j - shift <= m - 1 - shift
    full = fftconvolve(d_area, u1[None, :], axes=-1)
    out = np.zeros(area.shape)
    k = np.arange(m)
    src = k - shift
    ok = (src >= 0) & (src < full.shape[-1])
    out[:, ok] = full[:, src[ok]]
    return out


#: The nominal force ramp a sensor file records: F / F_p from 1 s before the onset to 1.5 s after, every 20 ms.
FORCE_PROFILE_S = (-1.0, 1.5, 0.02)


def nominal_force_profile(data: "Sequence[Trial] | Any") -> dict[str, Any]:
    """The median over touches of the force over its plateau (:func:`relative_force`), after the onset.

    What a question plays for a ``force_area`` model (it has no force trace of its
    own): ``{"time_s": [...], "force_share": [...], "n_touches": n, "touch_force_share": [[...], ...]}`` (the
    median, and each touch's own, from which a simulated touch draws its press) on
    :data:`FORCE_PROFILE_S`. The median of the area shares is the area share of
    the median force (the share is a non-decreasing function of the force). The share is 0.006, not 0, at the
    onset below: the force is averaged over :data:`FORCE_SMOOTHING_S`, which rounds the foot of the ramp.

    Examples
    --------
    >>> t = np.arange(-200, 1000) / 200.0
    >>> trs = [Trial(t, np.zeros(t.size), np.zeros(t.size), np.clip(t / r, 0.0, 1.0) * 4.0, "wood")
    ...        for r in (0.4, 0.5, 0.6)]
    >>> p = nominal_force_profile(trs)
    >>> p["n_touches"], p["time_s"][50:53], p["force_share"][50:53]
    (3, [0.0, 0.02, 0.04], [0.006, 0.04, 0.08])
    """
    lo, hi, step = FORCE_PROFILE_S
    grid = np.round(np.arange(round((hi - lo) / step) + 1) * step + lo, 9)
    if hasattr(data, "groups"):   # a fit's prepared touches: their relative forces, computed once
        rows = [np.interp(grid, g.time_s, f) for g in data.groups if g.force is not None for f in g.force]
    else:
        rows = [np.interp(grid, tr.time_s, relative_force(tr)) for tr in data]
    if not rows:
        raise InputError("a nominal force profile needs touches with a force channel")
    med = np.median(np.array(rows), axis=0)
    return {"time_s": [float(v) for v in grid], "force_share": [round(float(v), 4) for v in med],
            "n_touches": len(rows), "touch_force_share": [[round(float(v), 3) for v in r] for r in rows]}
