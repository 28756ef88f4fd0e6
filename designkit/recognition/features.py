"""Feature vectors of a touch: raw samples plus their estimated local slope.

The paper concatenates "raw temperature and estimated local slope" (section
III) without saying how the slope is estimated. A two-point difference
(``np.gradient``) of noisy 200 Hz samples has noise of order
``sigma * fs / sqrt(2)``, hundreds of times the signal's slope, and drowns the
features (docs/physics.md section 2). designkit uses the Savitzky-Golay derivative
(:func:`scipy.signal.savgol_filter` with ``deriv=1``, ``mode="interp"``): the slope of a local
least-squares quadratic over a window of ``window_s`` seconds (0.25 s, 51
samples at 200 Hz, by default). Its noise falls as ``window^-3/2``.

It is computed here in its cumulative-sum form, not by ``savgol_filter`` (why:
docs/decisions-log.md, "Recognition"). In a symmetric window the quadratic
term is orthogonal to the linear one, so the derivative at the window's centre is the
least-squares line's slope, ``sum_k k x_(i+k) / sum_k k^2`` (``k = -M..M``): two
running sums give it at every interior sample in O(1) each. The first and last ``M``
samples take the derivative of the quadratic fitted to the first / last window, as
``mode="interp"`` does, as one small matrix product. Same values as
``savgol_filter`` to rounding (about 1e-12 of the slope's scale; tests check it); the
rounding differs, which is why the sweep's engine version changed with it
(:data:`designkit.sweep.ENGINE_VERSION`).

The slope is a linear function of the samples, so it adds no information a
linear classifier could not extract from the raw samples; what it changes is
the geometry that standardization and the SVM's margin see.
"""

from __future__ import annotations

import numpy as np

from .._validation import check_positive

__all__ = ["DEFAULT_SLOPE_WINDOW_S", "feature_matrix", "local_slope"]

DEFAULT_SLOPE_WINDOW_S = 0.25
_POLYORDER = 2


def local_slope(temperature_c, sample_rate_hz: float,
                window_s: float = DEFAULT_SLOPE_WINDOW_S) -> np.ndarray:
    """Savitzky-Golay estimate of dT/dt along the last axis [K s^-1].

    Parameters
    ----------
    temperature_c : array_like, shape (..., m)
        Readings [degC], samples along the last axis.
    sample_rate_hz : float
        Sampling rate [Hz].
    window_s : float
        Window length [s]; rounded to an odd number of samples and cut to the
        number of samples available.

    Returns
    -------
    ndarray, shape (..., m)
        Local slope [K s^-1]. With fewer samples than a quadratic needs
        (m < 3) the two-point difference is used; with one sample, 0.
    """
    x = np.asarray(temperature_c, dtype=np.float64)
    fs = check_positive("sample rate [Hz]", sample_rate_hz)
    check_positive("slope window [s]", window_s)
    m = x.shape[-1]
    if m == 1:
        return np.zeros_like(x)
    if m < _POLYORDER + 1:
        return np.gradient(x, 1.0 / fs, axis=-1)
    out = np.empty_like(x)
    _slope_into(x, _window(window_s, fs, m), fs, out)
    return out


def _window(window_s: float, fs: float, m: int) -> int:
    """The window in samples: odd, more than the polynomial order, at most ``m``."""
    win = int(round(window_s * fs)) | 1
    return max(_POLYORDER + 1, min(win, m if m % 2 else m - 1))


def _slope_into(x: np.ndarray, win: int, fs: float, out: np.ndarray) -> None:
    """Write the Savitzky-Golay slope of ``x`` (odd window ``win`` <= m, quadratic, ``mode="interp"``)
    into ``out`` [K s^-1]; see the module docstring."""
    m = x.shape[-1]
    h = win // 2
    # interior: the least-squares line's slope over i-h..i+h, from running sums of x and j x (j counted
    # from the row's middle, to keep the sums small); written in place, a few passes over the samples
    j = np.arange(m, dtype=np.float64) - 0.5 * (m - 1)
    s0 = np.empty(x.shape[:-1] + (m + 1,))
    s1 = np.empty_like(s0)
    s0[..., 0] = s1[..., 0] = 0.0
    np.cumsum(x, axis=-1, out=s0[..., 1:])
    np.multiply(x, j, out=s1[..., 1:])
    np.cumsum(s1[..., 1:], axis=-1, out=s1[..., 1:])
    lo, hi = slice(0, m - 2 * h), slice(2 * h + 1, m + 1)
    mid = out[..., h:m - h]
    np.subtract(s1[..., hi], s1[..., lo], out=mid)
    win_sum = np.subtract(s0[..., hi], s0[..., lo], out=s0[..., :m - 2 * h])  # in place: read ahead of written
    win_sum *= j[h:m - h]
    mid -= win_sum
    mid *= fs / (h * (h + 1) * (2 * h + 1) / 3.0)  # 1 / (sum_k k^2 * dt)
    if h:  # edges: the derivative of the quadratic fitted to the first / last window, at each edge sample
        t = np.arange(win, dtype=np.float64)
        vander = np.vander(t, _POLYORDER + 1, increasing=True)  # (win, 3): 1, t, t^2
        deriv = np.stack([np.zeros(h), np.ones(h), 2.0 * t[:h]], axis=1)  # d/dt at t = 0..h-1
        head = (deriv @ np.linalg.pinv(vander)) * fs  # (h, win)
        tail = -head[::-1, ::-1]  # the mirror image: the last window read backwards
        # einsum's own loops (no BLAS): a touch's edge slopes round the same however many touches come with it
        out[..., :h] = np.einsum("...k,pk->...p", x[..., :win], head)
        out[..., m - h:] = np.einsum("...k,pk->...p", x[..., m - win:], tail)


def feature_matrix(temperature_c, sample_rate_hz: float,
                   window_s: float = DEFAULT_SLOPE_WINDOW_S) -> np.ndarray:
    """Paper features: raw samples concatenated with their local slope.

    Parameters
    ----------
    temperature_c : array_like, shape (n, m)
        One touch per row [degC].
    sample_rate_hz : float
        Sampling rate [Hz].
    window_s : float
        Slope window [s] (see :func:`local_slope`).

    Returns
    -------
    ndarray, shape (n, 2 m)
        Unscaled features; standardize them inside each training fold
        (:func:`designkit.recognition.svm.make_classifier` does).
    """
    x = np.atleast_2d(np.asarray(temperature_c, dtype=np.float64))
    m = x.shape[-1]
    out = np.empty(x.shape[:-1] + (2 * m,))
    out[..., :m] = x
    fs = check_positive("sample rate [Hz]", sample_rate_hz)
    check_positive("slope window [s]", window_s)
    if m < _POLYORDER + 1:
        out[..., m:] = local_slope(x, fs, window_s)
    else:
        _slope_into(x, _window(window_s, fs, m), fs, out[..., m:])
    return out
