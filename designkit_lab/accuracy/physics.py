"""Section ``physics``: the forward models against high-precision references.

eq. 2 of the paper (numpy/scipy erfc, and the log form for the deep tail)
against mpmath at 40 digits; the thin-sample solvers (image series at its
default tolerance, finite volumes at their default resolution) against the
image series summed to a 1e-13 tail bound (itself checked against mpmath's
Laplace inversion in ``tests/test_slab.py``).

mpmath is a declared dependency of designkit (small, pure Python): the
reference of this section must be there wherever ``designkit bench`` is.
"""

from __future__ import annotations

import math

import numpy as np

from designkit._validation import as_generator
from .instruments import timed
from .results import Row, paper_sensor, p95, worst

__all__ = ["physics_rows", "slab_rows"]

_TAU_S = 1.3445378151260505  # the paper sensor's tau = x^2 / (4 alpha_s) [s]
_MP_REF = "mpmath, 40 digits"


def _mp_shape(mpmath, ratio):
    """erfc(sqrt(tau/t)) in mpmath, for ``ratio`` = tau/t."""
    return mpmath.erfc(mpmath.sqrt(mpmath.mpf(ratio)))


def _mp_ratio(mpmath, t):
    return mpmath.mpf(_TAU_S) / mpmath.mpf(float(t))


def _shape_row(mpmath, rng, n) -> Row:
    from designkit.models.semi_infinite import response_shape

    t = _TAU_S / 10.0 ** rng.uniform(-3.0, math.log10(700.0), n)
    got, sec = timed(lambda: response_shape(t, _TAU_S), 3)
    ref, ref_sec = timed(lambda: [_mp_shape(mpmath, _mp_ratio(mpmath, ti)) for ti in t])
    err = np.array([float(abs((mpmath.mpf(float(g)) - r) / r)) for g, r in zip(got, ref)])
    return Row("physics: eq. 2", "response_shape (scipy erfc)", "tau/t 1e-3..700", "relative error",
               p95(err), worst(err), sec / n, _MP_REF, ref_sec / n, n)


def _log_shape_row(mpmath, rng, n) -> Row:
    from designkit.models.semi_infinite import log_response_shape

    t = _TAU_S / 10.0 ** rng.uniform(-6.0, 6.0, n)
    got, sec = timed(lambda: log_response_shape(t, _TAU_S), 3)
    ref, ref_sec = timed(lambda: [mpmath.log(_mp_shape(mpmath, _mp_ratio(mpmath, ti))) for ti in t])
    err = np.array([float(abs(mpmath.mpf(float(g)) - r)) for g, r in zip(got, ref)])
    return Row("physics: eq. 2", "log_response_shape (log_ndtr)", "tau/t 1e-6..1e6",
               "relative error (abs. error of log)", p95(err), worst(err), sec / n, _MP_REF, ref_sec / n, n)


def _change_row(mpmath, rng, n) -> Row:
    from designkit.models.semi_infinite import temperature_change

    e = 10.0 ** rng.uniform(-3.0, 6.0, n)
    t = _TAU_S / 10.0 ** rng.uniform(-3.0, math.log10(700.0), n)
    dt = rng.uniform(0.1, 100.0, n)
    es = 892.0
    got, sec = timed(lambda: temperature_change(t, e, 25.0 + dt, 25.0, es, _TAU_S), 3)

    def mp_change():
        out = []
        for ti, ei, di in zip(t, e, dt):
            ei_, di_ = mpmath.mpf(float(ei)), mpmath.mpf(float(di))
            out.append(-di_ * ei_ / (es + ei_) * _mp_shape(mpmath, _mp_ratio(mpmath, ti)))
        return out

    ref, ref_sec = timed(mp_change)
    err = np.array([float(abs((mpmath.mpf(float(g)) - r) / r)) for g, r in zip(got, ref)])
    return Row("physics: eq. 1-2", "temperature_change", "e 1e-3..1e6, dT 0.1..100 °C", "relative error",
               p95(err), worst(err), sec / n, _MP_REF, ref_sec / n, n)


def physics_rows(quick: bool = True, seed: int = 0) -> list[Row]:
    """eq. 2 in double precision against mpmath at 40 significant digits.

    Three rows: the response shape ``erfc(sqrt(tau/t))`` where it is
    representable (``tau/t`` from 1e-3 to 700), its log form deep in the tail
    (``tau/t`` up to 1e6, where erfc itself underflows), and the temperature
    change ``(To - Ts0) w(e) g(t)`` for effusivities from 1e-3 to 1e6.
    Errors are relative (the log form: absolute error of the log, i.e.
    relative error of the value). Times are for the same points: one
    vectorized numpy call against an mpmath loop.

    Parameters
    ----------
    quick : bool
        300 random points per row (else 3000).
    seed : int
        Seed of the random points.

    Returns
    -------
    list of Row

    Examples
    --------
    >>> rows = physics_rows(quick=True)
    >>> [r.method for r in rows][0], all(r.worst < 1e-8 for r in rows)
    ('response_shape (scipy erfc)', True)
    """
    import mpmath

    rng = as_generator([seed, 801])
    n = 300 if quick else 3000
    with mpmath.workdps(40):
        return [_shape_row(mpmath, rng, n), _log_shape_row(mpmath, rng, n), _change_row(mpmath, rng, n)]


def _slab_scenes(slab):
    """(object (e, alpha), thickness [m], backing, contact [s]) of the three thin-sample scenes."""
    copper, foam, acrylic = (36800.0, 1.17e-4), (30.5, 6.0e-7), (583.25, 1.18e-7)
    return [(acrylic, 1e-3, "wood", 10.0),
            (copper, 1e-3, slab.Backing("rigid foam", *foam), 4.0),
            (foam, 1e-3, slab.Backing("copper", *copper), 10.0)]


def _slab_methods(slab, quick: bool):
    methods = [("image series", "tail bound 1e-5 (default)", dict(method="image-series", tolerance=1e-5)),
               ("image series", "tail bound 1e-3", dict(method="image-series", tolerance=1e-3)),
               ("finite volumes", "default: " + ", ".join(f"{k} {v}" for k, v in slab.FV_DEFAULTS.items()),
                dict(method="finite-volume")),
               ("semi-infinite (paper eq. 2)", "no reflections", dict(method="semi-infinite"))]
    if not quick:
        methods.insert(2, ("image series", "tail bound 1e-8", dict(method="image-series", tolerance=1e-8)))
    return methods


def slab_rows(quick: bool = True) -> list[Row]:
    """Thin-sample solvers against the image series summed to a 1e-13 tail bound.

    Scenes (paper sensor, 200 Hz, errors in degC at a 10 degC difference):
    1 mm acrylic on wood for 10 s, 1 mm copper on rigid foam for 4 s, 1 mm
    foam on copper for 10 s. ``benchmarks/bench_slab.py`` has the full study
    (every resolution, orders of convergence, stability).

    Parameters
    ----------
    quick : bool
        Best of 2 timings and four methods (else best of 3 and five).

    Returns
    -------
    list of Row
    """
    from designkit.models import slab

    sensor = paper_sensor()
    scenes = _slab_scenes(slab)
    refs, ref_total = [], 0.0
    for (e, a), L, back, contact in scenes:
        t = sensor.times_s(contact)
        r, sec = timed(lambda: slab.slab_response(t, e, a, L, back, tolerance=1e-13, method="image-series"))
        refs.append(r.response[0])
        ref_total += sec
    rows = []
    repeat = 2 if quick else 3
    for label, setting, kw in _slab_methods(slab, quick):
        errs, total = [], 0.0
        for ((e, a), L, back, contact), ref in zip(scenes, refs):
            t = sensor.times_s(contact)
            r, sec = timed(lambda: slab.slab_response(t, e, a, L, back, **kw), repeat)
            errs.append(float(np.max(np.abs(r.response[0] - ref))) * 10.0)  # dT 10 degC
            total += sec
        rows.append(Row("physics: thin samples", label, setting, "max |error| over samples [°C] (dT 10 °C)",
                        worst(errs), worst(errs), total / len(scenes), "image series, tail bound 1e-13",
                        ref_total / len(scenes), len(scenes),
                        "3 scenes: 1 mm acrylic on wood 10 s, copper on foam 4 s, foam on copper 10 s"))
    return rows
