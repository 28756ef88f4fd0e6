"""JSON export: provenance, axes, and the two delta arrays as nested lists (``null``: none within the grid).

Strict JSON (no NaN), readable by any JSON parser::

    {"format": "designkit-export", "schema_version": 1, "provenance": {...},
     "axes": [{"name", "units", "scale", "values"}, ...], "contact_adjacent": [...],
     "effusivity_answered": {...}, "array_order": [...],
     "delta_up": [[[...]]], "delta_down": [[[...]]]}
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from ..estimator_data import MORE_ARRAYS
from ..slicing import EXPORT_FORMAT, EXPORT_SCHEMA, Axis, Exported

__all__ = ["read", "structure", "write"]


def _nan_to_none(a: np.ndarray) -> list:
    return np.where(np.isnan(a), None, a).tolist() if a.size else []


def structure(exp: Exported) -> dict[str, Any]:
    """The axes, contact adjacency and effusivities answered: what a reader needs besides the arrays."""
    return {"axes": [a.to_dict() for a in exp.axes], "contact_adjacent": list(exp.contact_adjacent),
            "effusivity_answered": exp.provenance["effusivity_answered"]}


def write(exp: Exported) -> bytes:
    """The export as JSON bytes (UTF-8; every string escaped by :func:`json.dumps`, ASCII only)."""
    doc = {"format": EXPORT_FORMAT, "schema_version": EXPORT_SCHEMA, "provenance": exp.provenance,
           **structure(exp), "array_order": [a.name for a in exp.axes], "estimator": exp.estimator}
    head = json.dumps(doc, indent=1, allow_nan=False)
    body = ",\n".join(f' "{name}": ' + json.dumps(_nan_to_none(arr), separators=(",", ":"), allow_nan=False)
                      for name, arr in (("delta_up", exp.delta_up), ("delta_down", exp.delta_down),
                                        *exp.more.items()))
    return (head[:-2] + ",\n" + body + "\n}\n").encode()


def read(path: Path) -> Exported:
    """Read a JSON export back (KeyError / ValueError / TypeError on a file that is not one)."""
    doc = json.loads(Path(path).read_text(encoding="utf-8"))
    if isinstance(doc, dict) and doc.get("sidecar_of"):
        raise ValueError(f"this is the provenance sidecar of the CSV export {doc['sidecar_of']!r}; read that")
    axes = tuple(Axis(a["name"], a["units"], a["scale"], tuple(a["values"])) for a in doc["axes"])
    prov, ea = doc["provenance"], doc["provenance"]["effusivity_answered"]
    return Exported(axes=axes, delta_up=np.array(doc["delta_up"], dtype=np.float64),  # null -> nan
                    delta_down=np.array(doc["delta_down"], dtype=np.float64),
                    contact_adjacent=tuple(bool(x) for x in doc["contact_adjacent"]), e_lo=float(ea["min"]),
                    e_hi=float(ea["max"]), e_lo_inclusive=bool(ea["min_inclusive"]), provenance=prov,
                    more={k: np.array(doc[k], dtype=np.float64) for k in MORE_ARRAYS if k in doc},
                    estimator=doc.get("estimator"))
