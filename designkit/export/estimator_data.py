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

import math

import numpy as np

from .._validation import InputError

__all__ = ["COVERAGE", "MORE_ARRAYS", "contact_frame", "estimator_of", "estimator_params", "estimator_reason",
           "lookup_of"]

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
    if contact_sliced:
        return "--contact keeps some contact columns; the estimator reads the efficiency on the whole contact axis"
    return None


def contact_frame(tab) -> dict:
    """What the export's contact times count from (plain JSON): the table's axis and the grid rule count from the
    model's time 0 (its first heat flow); for a calibrated rig's sensor ``onset_offset_s`` is that time 0 from
    the rig's detected onset, and the estimator's answers and asked contacts count from the onset, as
    ``designkit min-contact --sensor FILE`` does."""
    from ..rig import model_start_s

    start = model_start_s(tab.sensor)
    if start is None:
        return {"counted_from": "the model's first heat flow (t = 0)", "onset_offset_s": None}
    return {"counted_from": "the model's first heat flow (model time) on the contact_s axis and in the grid rule; "
                            "the rig's detected onset in the estimator's answers and asked contacts",
            "onset_offset_s": float(start),
            "from_onset": (f"contact after the rig's detected onset = contact_s + ({start:.6g}) s (at least 0), "
                           "as designkit answers a question about this sensor")}


def _sstar_grid(view, e_s: float, width: float, e_top: float):
    """The critical-noise grid the export carries: ``log(s* / (w(b) - w(a)))`` at its nodes, read off the query
    layer's (:meth:`designkit.query.table_arrays.TableView.critical_noise`, kept with the table: within 4.2e-7 in
    log of a fresh solve at every separable node of svm-fine's)."""
    u = np.linspace(math.log(_A0), math.log(e_top + 2 * width + _A0), _N)
    v = np.linspace(math.log(_D_MIN), math.log(e_top + 3 * width), _N)
    a, d = np.meshgrid(np.exp(u) - _A0, np.exp(v), indexing="ij")
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.log(view.critical_noise(a.ravel(), (a + d).ravel()).reshape(a.shape)) - np.log(
            1.0 / (1.0 + e_s / (a + d)) - np.where(a > 0, 1.0 / (1.0 + e_s / np.maximum(a, 1e-300)), 0.0))
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


def estimator_params(tab) -> dict:
    """The estimator's constants for table ``tab`` (plain JSON data: floats and lists of floats)."""
    from ..query.crossing import z_of_coverage
    from ..query.ideal_bound import shape_norm
    from ..query.table import CLOSED_FORM_MAX_CONTACT_S, open_table, table_spread, table_z
    from ..rig import model_start_s
    from ..sensor import last_sample_index

    sensor = tab.sensor
    op = open_table(tab, None, sensor_temp_spread_c=table_spread(tab))
    width = float(tab.header["effusivity"]["width"])
    e_lo, e_hi = float(tab.header["effusivity"]["min"]), float(tab.header["effusivity"]["max"])
    fs = float(sensor.sample_rate_hz)
    n_max = int(last_sample_index(CLOSED_FORM_MAX_CONTACT_S, fs))
    if op.closed:
        cum = shape_norm(sensor, np.arange(max(n_max, 1) + 1) / fs) ** 2  # sum_{k<=n} g(k/fs)^2 per sample n
        # one grid for every table up to 40,000 (the shipped range), read off the table's own memo
        u0, du, v0, dv, f = _sstar_grid(op.view, float(sensor.effusivity), width, max(e_hi, 40000.0))
    else:  # no closed form: no efficiency route (and no ideal observer) to carry
        cum, (u0, du, v0, dv, f) = [0.0], (0.0, 1.0, 0.0, 1.0, (0.0,))
    return {
        "e_s": float(sensor.effusivity), "fs": fs, "width": width, "threshold": float(tab.threshold),
        "z_table": table_z(tab), "coverage": COVERAGE, "zc": z_of_coverage(COVERAGE),
        "efficiency": bool(op.closed), "mc_factor": op.view.mc_calibration(), "e_lo": e_lo, "e_hi": e_hi,
        "max_contact_s": CLOSED_FORM_MAX_CONTACT_S, "cum": [float(x) for x in cum],
        "s_a0": _A0, "s_dmin": _D_MIN, "s_u0": u0, "s_du": du, "s_nu": _N if op.closed else 1, "s_v0": v0,
        "s_dv": dv, "s_nv": _N if op.closed else 1,
        "s_f": list(f), "onset_offset_s": float(model_start_s(sensor) or 0.0),
    }


def lookup_of(exp):
    """The grid rule over an export's arrays (:class:`designkit.tables.lookup.Lookup`: the module's ``TABLE``)."""
    from ..tables.lookup import Lookup
    from ._common import log_grid

    return Lookup([(a.name, a.scale, list(a.values), log_grid(a)) for a in exp.scene_axes], list(exp.contact.values),
                  list(exp.e_ref.values), exp.delta_up.ravel().tolist(), exp.delta_down.ravel().tolist(), exp.e_lo,
                  exp.e_hi, exp.e_lo_inclusive, exp.contact_adjacent, exp.provenance["source_table"])


def estimator_of(exp):
    """The documented reading rule of a data export (JSON, CSV, npz, or :class:`Exported`): the library's
    estimator over its arrays; an :class:`InputError` where the export carries none (its provenance says why)."""
    from .estimator import Estimator

    if exp.estimator is None:
        why = exp.provenance.get("estimator", {}).get("unavailable") or "it carries none"
        raise InputError(f"this export cannot answer as the library does: {why}")
    return Estimator(lookup_of(exp), *(exp.more[n].ravel().tolist() for n in MORE_ARRAYS), exp.estimator)
