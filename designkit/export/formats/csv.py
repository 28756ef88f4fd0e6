"""CSV export: one row per grid point, readable by ``pandas.read_csv(path)`` with its defaults.

The first line names the columns, every other line is one grid point with the
same number of fields: the scene axes (``noise_ratio``, or ``noise_c`` and
``delta_t_c``), ``contact_s``, ``e_ref``, then ``delta_up`` and ``delta_down``
[J s^-1/2 K^-1 m^-2] (``nan``: no distinguishable partner within the grid,
which pandas and ``numpy.genfromtxt`` read as NaN). Nothing else is in the
file: no comment lines, no quoted text, only numbers after the header.

The provenance (source table, content hash, forward model, sensor, units of
every column, contact adjacency, the slice taken) is written next to it, by
``designkit export``, as a JSON *sidecar* named after the CSV file plus
``.json`` (``table.csv`` -> ``table.csv.json``; :func:`sidecar`). Written to
standard output (``--out -``), the CSV goes without its provenance.
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np

from ...tables.store import E_UNITS
from ..slicing import EXPORT_FORMAT, EXPORT_SCHEMA, Axis, Exported

__all__ = ["SIDECAR_SUFFIX", "read", "sidecar", "sidecar_path", "write"]

#: Added to the CSV file's name to name its provenance sidecar.
SIDECAR_SUFFIX = ".json"


def _num_strings(a: np.ndarray, nan: str) -> np.ndarray:
    """Shortest round-trip text of every float64 value (formatted once per distinct value)."""
    flat = a.ravel()
    u, inv = np.unique(flat, return_inverse=True)
    text = np.array([nan if math.isnan(x) else repr(float(x)) for x in u.tolist()] or [""], dtype=object)
    return text[inv.ravel()] if flat.size else np.array([], dtype=object)


def _columns(exp: Exported) -> list[str]:
    return [a.name for a in exp.axes] + ["delta_up", "delta_down"] + list(exp.more)


def write(exp: Exported) -> bytes:
    """The CSV bytes: a header line, then one line of numbers per grid point (no provenance)."""
    grids = np.meshgrid(*[np.asarray(a.values) for a in exp.axes], indexing="ij")
    cols = [_num_strings(g, "nan") for g in grids] + [_num_strings(a, "nan") for a in (
        exp.delta_up, exp.delta_down, *exp.more.values())]
    head = io.StringIO()
    csv.writer(head, lineterminator="\n").writerow(_columns(exp))  # quoted by the csv rules, were it ever needed
    rows = map(",".join, zip(*[c.tolist() for c in cols]))
    return (head.getvalue() + "\n".join(rows) + "\n").encode()


def sidecar_path(path: str | Path) -> Path:
    """Where the provenance of the CSV export ``path`` goes: ``path`` + ``.json``."""
    path = Path(path)
    return path.with_name(path.name + SIDECAR_SUFFIX)


def sidecar(exp: Exported, csv_name: str) -> bytes:
    """The JSON provenance sidecar of the CSV export named ``csv_name``."""
    meaning = {"delta_up": "smallest distinguishable difference towards higher effusivity (nan: none in the grid)",
               "delta_down": "smallest distinguishable difference towards lower effusivity (nan: none in the grid)"}
    columns = [{"name": a.name, "units": a.units, "scale": a.scale} for a in exp.axes]
    columns += [{"name": n, "units": E_UNITS, "meaning": meaning[n]} for n in ("delta_up", "delta_down")]
    columns += [{"name": n, "units": E_UNITS, "meaning": "an end of the table's Monte Carlo interval of delta"}
                for n in exp.more]
    doc = {"format": EXPORT_FORMAT, "schema_version": EXPORT_SCHEMA, "sidecar_of": csv_name,
           "columns": columns, "axes": [a.to_dict() for a in exp.axes],
           "contact_adjacent": list(exp.contact_adjacent), "provenance": exp.provenance,
           "estimator": exp.estimator}
    return (json.dumps(doc, indent=1, allow_nan=False) + "\n").encode()


def read(path: Path) -> Exported:
    """Read a CSV export and its sidecar back (ValueError when the sidecar is missing)."""
    path = Path(path)
    side = sidecar_path(path)
    if not side.is_file():
        raise ValueError(f"its provenance sidecar {side.name} is missing (written next to it by designkit export)")
    doc = json.loads(side.read_text(encoding="utf-8"))
    prov = doc["provenance"]
    axes = tuple(Axis(a["name"], a["units"], a["scale"], tuple(a["values"])) for a in doc["axes"])
    shape = tuple(len(a.values) for a in axes)
    data = np.genfromtxt(path, delimiter=",", names=True, dtype=np.float64)
    names = [a.name for a in axes]
    more = [c["name"] for c in doc["columns"][len(names) + 2:]]
    if list(data.dtype.names) != names + ["delta_up", "delta_down"] + more or data.size != math.prod(shape):
        raise ValueError(f"its columns or row count do not match its sidecar {side.name}")
    order = np.lexsort([np.atleast_1d(data[n]) for n in reversed(names)])
    for a in axes:
        got = np.unique(np.atleast_1d(data[a.name]))
        if got.size != len(a.values) or not np.array_equal(got, np.asarray(a.values)):
            raise ValueError(f"its {a.name} column does not hold the grid of its sidecar {side.name}")
    arr = {k: np.atleast_1d(data[k])[order].reshape(shape) for k in ("delta_up", "delta_down", *more)}
    ea = prov["effusivity_answered"]
    return Exported(axes=axes, delta_up=arr["delta_up"], delta_down=arr["delta_down"],
                    contact_adjacent=tuple(bool(x) for x in doc["contact_adjacent"]), e_lo=float(ea["min"]),
                    e_hi=float(ea["max"]), e_lo_inclusive=bool(ea["min_inclusive"]), provenance=prov,
                    more={k: arr[k] for k in more}, estimator=doc.get("estimator"))
