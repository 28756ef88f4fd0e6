"""What an export carries so that it answers as the library does, and the reading rule of the data exports.

:func:`estimator_params` computes, once per table, the constants of
:class:`designkit.export.estimator.Estimator`: the sensor's cumulative response
energy per sample, the ideal observer's critical noise on a grid (from
:func:`designkit.query.ideal_bound.critical_noise`), the table's Monte Carlo
calibration, z and coverage. :func:`estimator_of` is the documented reading rule
of a JSON, CSV or npz export: the :class:`~designkit.export.estimator.Estimator`
over the arrays and constants it holds (the Python module and the C header carry
the same steps).

Examples
--------
>>> from designkit.export import slice_table
>>> from designkit.export.estimator_data import estimator_of
>>> est = estimator_of(slice_table("svm-fine", noise_c=0.05, delta_t_c=10.0))
>>> round(est.min_contact_s(35000, 20000, 0.05, 10), 3)
1.225
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .._validation import InputError

__all__ = ["COVERAGE", "MORE_ARRAYS", "closed_form", "contact_frame", "estimator_of", "estimator_params", "estimator_reason"]

#: Coverage of the intervals an export states (the library's default).
COVERAGE = 0.9
#: The arrays an estimator export carries besides delta_up / delta_down (the ends of the Monte Carlo interval).
MORE_ARRAYS = ("delta_up_lo", "delta_down_lo", "delta_up_hi", "delta_down_hi")
#: The critical-noise grid: u = log(a + A0) for lower edges a in [0, 40,100], v = log(b - a) for distances in
#: [D_MIN, 40,200]; 60 x 60 points, bicubic in the estimator (within 2e-4 of the library's: docs/decisions-log.md).
_A0, _D_MIN, _N = 100.0, 60.0, 60


def estimator_reason(tab, kind: str, contact_sliced: bool) -> str | None:
    """Why an export of ``tab`` cannot carry the library's estimator (None: it can)."""
    if kind != "svm":
        return f"kind {kind} exports one delta array (the estimator reads the SVM's and its Monte Carlo ends)"
    if tab.fidelity != "svm":
        return f"a {tab.fidelity}-fidelity table (the estimator reads an SVM table's efficiency)"
    if "noise_ratio" not in tab.axes:
        return ("the table varies the initial conditions (its ideal observer has no closed form: the library "
                "estimates its answers from each scene slice and the bound by simulation)")
    if any(n not in tab.arrays for n in MORE_ARRAYS):
        return "the table holds no Monte Carlo interval (delta_*_lo / delta_*_hi)"
    if not closed_form(tab):
        return ("its sensor model has no closed-form ideal observer (a calibrated rig's table: the library "
                "averages both directions' needs, crosses the rounding-corrected need and counts contact from the "
                "rig's detected onset; the export's estimator does not carry that rule)")
    if contact_sliced:
        return "--contact keeps some contact columns; the estimator reads the efficiency on the whole contact axis"
    return None


def closed_form(tab) -> bool:
    """Whether the library computes ``tab``'s ideal bound in closed form (the efficiency route the estimator
    carries); a calibrated rig's table has none."""
    from ..query.table import open_table, table_spread

    return bool(open_table(tab, None, sensor_temp_spread_c=table_spread(tab)).closed)


def contact_frame(tab) -> dict:
    """What the export's contact times count from (plain JSON): the model's time 0 (its first heat flow), and,
    for a calibrated rig's sensor, the offset of that time 0 from the rig's detected onset (what
    ``designkit min-contact --sensor FILE`` counts from)."""
    from ..rig import model_start_s

    start = model_start_s(tab.sensor)
    if start is None:
        return {"counted_from": "the model's first heat flow (t = 0)", "onset_offset_s": None}
    return {"counted_from": "the model's first heat flow (model time), not the rig's detected onset",
            "onset_offset_s": float(start),
            "from_onset": (f"contact after the rig's detected onset = contact_s + ({start:.6g}) s (at least 0), "
                           "as designkit answers a question about this sensor")}


@functools.lru_cache(maxsize=4)
def _sstar_grid(e_s: float, width: float, threshold: float, e_top: float):
    """The critical-noise grid (a function of the sensor's effusivity, the class width and the threshold only:
    the scene enters through the projection noise alone). Computed once per process and key (3,600 critical
    noises)."""
    from ..query.ideal_bound import critical_noise

    sensor = _SensorLike(e_s)
    u = np.linspace(math.log(_A0), math.log(e_top + 2 * width + _A0), _N)
    v = np.linspace(math.log(_D_MIN), math.log(e_top + 3 * width), _N)
    a = np.exp(u)[:, None] - _A0 + 0.0 * v[None, :]
    d = np.exp(v)[None, :] + 0.0 * u[:, None]
    star = critical_noise(sensor, a.ravel(), (a + d).ravel(), width=width, threshold=threshold).reshape(a.shape)
    dw = 1.0 / (1.0 + e_s / (a + d)) - np.where(a > 0, 1.0 / (1.0 + e_s / np.maximum(a, 1e-300)), 0.0)
    f = np.log(star) - np.log(dw)
    # Classes that overlap too much never separate (the library's critical noise is NaN there): the bicubic
    # reading still needs a value at such nodes next to separable ones; extend each row linearly in log
    # distance from its first two finite nodes (docs/decisions-log.md, Exports)
    for row in f:
        ok = np.flatnonzero(np.isfinite(row))
        if 2 <= ok.size < row.size and ok[0] > 0 and np.all(np.diff(ok) == 1):
            k = np.arange(ok[0])
            row[k] = row[ok[0]] + (k - ok[0]) * (row[ok[0] + 1] - row[ok[0]])
    if not np.isfinite(f).all():
        raise InputError("the ideal observer's critical noise is not finite on the export's grid")
    return (float(u[0]), float(u[1] - u[0]), float(v[0]), float(v[1] - v[0]), tuple(f.ravel().tolist()))


class _SensorLike:
    """What :func:`critical_noise` reads of a sensor: its effusivity."""

    def __init__(self, e_s):
        self.effusivity = e_s


def estimator_params(tab) -> dict:
    """The estimator's constants for table ``tab`` (plain JSON data: floats and lists of floats)."""
    from ..query.crossing import z_of_coverage
    from ..query.ideal_bound import shape_norm
    from ..query.table import CLOSED_FORM_MAX_CONTACT_S, open_table, table_spread, table_z
    from ..sensor import last_sample_index

    sensor = tab.sensor
    op = open_table(tab, None, sensor_temp_spread_c=table_spread(tab))
    width = float(tab.header["effusivity"]["width"])
    e_lo, e_hi = float(tab.header["effusivity"]["min"]), float(tab.header["effusivity"]["max"])
    fs = float(sensor.sample_rate_hz)
    n_max = int(last_sample_index(CLOSED_FORM_MAX_CONTACT_S, fs))
    if op.closed:
        cum = shape_norm(sensor, np.arange(max(n_max, 1) + 1) / fs) ** 2  # sum_{k<=n} g(k/fs)^2 per sample n
        # one grid for every table up to 40,000 (the shipped range): computed once per process and sensor
        u0, du, v0, dv, f = _sstar_grid(float(sensor.effusivity), width, float(tab.threshold), max(e_hi, 40000.0))
    else:  # no closed form: no efficiency route (and no ideal observer) to carry
        cum, (u0, du, v0, dv, f) = [0.0], (0.0, 1.0, 0.0, 1.0, (0.0,))
    return {
        "e_s": float(sensor.effusivity), "fs": fs, "width": width, "threshold": float(tab.threshold),
        "z_table": table_z(tab), "coverage": COVERAGE, "zc": z_of_coverage(COVERAGE),
        "efficiency": bool(op.closed), "mc_factor": op.view.mc_calibration(), "e_lo": e_lo, "e_hi": e_hi,
        "max_contact_s": CLOSED_FORM_MAX_CONTACT_S, "cum": [float(x) for x in cum],
        "s_a0": _A0, "s_dmin": _D_MIN, "s_u0": u0, "s_du": du, "s_nu": _N if op.closed else 1, "s_v0": v0,
        "s_dv": dv, "s_nv": _N if op.closed else 1,
        "s_f": list(f),
    }


def estimator_of(exp):
    """The documented reading rule of a data export (JSON, CSV, npz, or :class:`Exported`): the library's
    estimator over its arrays; an :class:`InputError` where the export carries none (its provenance says why)."""
    from ..tables.lookup import Lookup
    from .estimator import Estimator

    if exp.estimator is None:
        why = exp.provenance.get("estimator", {}).get("unavailable") or "it carries none"
        raise InputError(f"this export cannot answer as the library does: {why}")
    scene = [(a.name, a.scale, list(a.values), np.log(np.asarray(a.values)).tolist() if a.scale == "log"
              else list(a.values)) for a in exp.scene_axes]
    lk = Lookup(scene, list(exp.contact.values), list(exp.e_ref.values), exp.delta_up.ravel().tolist(),
                exp.delta_down.ravel().tolist(), exp.e_lo, exp.e_hi, exp.e_lo_inclusive, exp.contact_adjacent,
                exp.provenance["source_table"])
    more = [exp.more[n].ravel().tolist() for n in MORE_ARRAYS]
    return Estimator(lk, more[0], more[1], more[2], more[3], exp.estimator)
