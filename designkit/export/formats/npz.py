"""NumPy ``.npz`` export (compressed, no pickles).

Arrays: ``delta_up``, ``delta_down`` (``[scene..., contact, e_ref]``, NaN: none
within the grid), ``axis_<name>`` for every axis, ``contact_adjacent``,
``array_order``, ``axis_scales``, and ``provenance`` (a JSON string).
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
    """The export as ``.npz`` bytes (read with ``numpy.load(path, allow_pickle=False)``)."""
    arrays = {"delta_up": exp.delta_up, "delta_down": exp.delta_down,
              "contact_adjacent": np.asarray(exp.contact_adjacent, dtype=bool),
              "array_order": np.asarray([a.name for a in exp.axes]),
              "axis_scales": np.asarray([a.scale for a in exp.axes]),
              "provenance": np.asarray(json.dumps(exp.provenance, allow_nan=False)), **exp.more}
    if exp.estimator is not None:  # the estimator's constants: scalars as JSON, the two long lists as arrays
        est = dict(exp.estimator)
        arrays["estimator_cum"] = np.asarray(est.pop("cum"), dtype=np.float64)
        arrays["estimator_s_f"] = np.asarray(est.pop("s_f"), dtype=np.float64)
        arrays["estimator"] = np.asarray(json.dumps(est, allow_nan=False))
    for a in exp.axes:
        arrays[f"axis_{a.name}"] = np.asarray(a.values, dtype=np.float64)
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    return buf.getvalue()


def read(path: Path) -> Exported:
    """Read an ``.npz`` export back."""
    with np.load(path, allow_pickle=False) as z:
        prov = json.loads(str(z["provenance"]))
        scales = [str(s) for s in z["axis_scales"]]
        names = [str(s) for s in z["array_order"]]
        units = {a["name"]: a["units"] for a in prov["axes"]}
        axes = tuple(Axis(n, units[n], s, tuple(z[f"axis_{n}"].tolist())) for n, s in zip(names, scales))
        up, down = z["delta_up"], z["delta_down"]
        adjacent = z["contact_adjacent"].tolist()
        more = {k: np.asarray(z[k], dtype=np.float64) for k in MORE_ARRAYS if k in z.files}
        est = None
        if "estimator" in z.files:
            est = json.loads(str(z["estimator"]))
            est["cum"], est["s_f"] = z["estimator_cum"].tolist(), z["estimator_s_f"].tolist()
    ea = prov["effusivity_answered"]
    return Exported(axes=axes, delta_up=np.asarray(up, dtype=np.float64), delta_down=np.asarray(down, dtype=np.float64),
                    contact_adjacent=tuple(bool(x) for x in adjacent), e_lo=float(ea["min"]), e_hi=float(ea["max"]),
                    e_lo_inclusive=bool(ea["min_inclusive"]), provenance=prov, more=more, estimator=est)
