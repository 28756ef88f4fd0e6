"""MATLAB ``.mat`` export (level 5, compressed; written with :func:`scipy.io.savemat`).

Variables, for ``S = load("table.mat")`` in MATLAB or Octave:

``delta_up``, ``delta_down``
    double, size ``[scene..., contact, e_ref]`` (index ``(i, k, j)`` in MATLAB is
    ``[i-1, k-1, j-1]`` in numpy), J s^-1/2 K^-1 m^-2; NaN: no distinguishable
    partner within the grid.
``axis_<name>``
    one column vector per axis (``axis_noise_ratio`` or ``axis_noise_c`` and
    ``axis_delta_t_c``, ``axis_contact_s``, ``axis_e_ref``).
``array_order``, ``axis_scales``
    cell arrays of the axis names and scales, in array order.
``contact_adjacent``
    logical column: columns ``k`` and ``k + 1`` are neighbours in the source table.
``delta_up_lo``, ``delta_down_lo``, ``delta_up_hi``, ``delta_down_hi``
    where the export carries the library's estimator: the ends of the table's
    Monte Carlo interval, the same axes as ``delta_up``; ``estimator`` (JSON text),
    ``estimator_cum`` and ``estimator_s_f`` its constants
    (:mod:`designkit.export.estimator`).
``provenance``
    the provenance as JSON text (``jsondecode(S.provenance)``): source table,
    content hash, forward model, sensor, the slice taken, units.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np

from ..estimator_data import MORE_ARRAYS
from ..slicing import Axis, Exported

__all__ = ["read", "write"]


def write(exp: Exported) -> bytes:
    """The export as ``.mat`` bytes (needs scipy, a designkit dependency)."""
    from scipy.io import savemat

    data = {"delta_up": exp.delta_up, "delta_down": exp.delta_down,
            "contact_adjacent": np.asarray(exp.contact_adjacent, dtype=bool).reshape(-1, 1),
            "array_order": np.array([a.name for a in exp.axes], dtype=object).reshape(-1, 1),
            "axis_scales": np.array([a.scale for a in exp.axes], dtype=object).reshape(-1, 1),
            "provenance": json.dumps(exp.provenance, allow_nan=False), **exp.more}
    if exp.estimator is not None:  # the estimator's constants (same axes as delta_up for the arrays above)
        est = dict(exp.estimator)
        data["estimator_cum"] = np.asarray(est.pop("cum"), dtype=np.float64).reshape(-1, 1)
        data["estimator_s_f"] = np.asarray(est.pop("s_f"), dtype=np.float64).reshape(-1, 1)
        data["estimator"] = json.dumps(est, allow_nan=False)
    for a in exp.axes:
        data[f"axis_{a.name}"] = np.asarray(a.values, dtype=np.float64).reshape(-1, 1)
    buf = io.BytesIO()
    savemat(buf, data, do_compression=True, oned_as="column")
    return buf.getvalue()


def read(path: Path) -> Exported:
    """Read a ``.mat`` export back."""
    from scipy.io import loadmat

    z = loadmat(str(path), squeeze_me=False, chars_as_strings=True)
    prov = json.loads(str(np.asarray(z["provenance"]).ravel()[0]))
    names = [str(np.asarray(x).ravel()[0]) for x in z["array_order"].ravel()]
    scales = [str(np.asarray(x).ravel()[0]) for x in z["axis_scales"].ravel()]
    units = {a["name"]: a["units"] for a in prov["axes"]}
    axes = tuple(Axis(n, units[n], s, tuple(np.asarray(z[f"axis_{n}"], dtype=np.float64).ravel().tolist()))
                 for n, s in zip(names, scales))
    shape = tuple(len(a.values) for a in axes)
    ea = prov["effusivity_answered"]
    adjacent = np.asarray(z["contact_adjacent"]).ravel() if "contact_adjacent" in z else []
    more = {k: np.asarray(z[k], dtype=np.float64).reshape(shape) for k in MORE_ARRAYS if k in z}
    est = None
    if "estimator" in z:
        est = json.loads(str(np.asarray(z["estimator"]).ravel()[0]))
        est["cum"] = np.asarray(z["estimator_cum"], dtype=np.float64).ravel().tolist()
        est["s_f"] = np.asarray(z["estimator_s_f"], dtype=np.float64).ravel().tolist()
    return Exported(axes=axes, delta_up=np.asarray(z["delta_up"], dtype=np.float64).reshape(shape),
                    delta_down=np.asarray(z["delta_down"], dtype=np.float64).reshape(shape),
                    contact_adjacent=tuple(bool(x) for x in adjacent), e_lo=float(ea["min"]), e_hi=float(ea["max"]),
                    e_lo_inclusive=bool(ea["min_inclusive"]), provenance=prov, more=more, estimator=est)
