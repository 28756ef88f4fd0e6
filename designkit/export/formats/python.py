"""Python export: one module that needs only the standard library.

The module is the template ``designkit/export/templates/lookup_module.py.in``
filled in one pass: a docstring (what the table is, how to regenerate it), the
text of :mod:`designkit.tables.lookup` *verbatim* between the markers
:data:`LOOKUP_BEGIN` and :data:`LOOKUP_END` (so the export answers with the
very code designkit tests), then the data (base85 of zlib of float64, checked
with SHA-256 on import) and the functions ``delta_e``, ``delta_e_lower``,
``delta_e_upper``, ``min_contact_s`` and ``distinguishable``.

==================  ===============================
meaning             generated Python module
==================  ===============================
answer              float / ``True`` or ``False``
nothing suffices    ``None``
outside the grid    raises ``OutsideTable``
invalid input       raises ``ValueError``
==================  ===============================

Strings from the table reach the module only as :func:`repr`-escaped literals
(``PROVENANCE``) or through :func:`~designkit.export._common.py_docstring`;
nothing from the table is ever code.
"""

from __future__ import annotations

import base64
import hashlib
import zlib
from importlib import resources

import numpy as np

from .._common import fill_template, log_grid, printable, py_docstring, py_literal, read_template, \
    regenerate_command, slice_lines
from ..slicing import Exported

__all__ = ["ESTIMATOR_BEGIN", "ESTIMATOR_END", "LOOKUP_BEGIN", "LOOKUP_END", "TEMPLATE", "estimator_source",
           "example_answer", "example_question", "lookup_source", "write"]

#: The module template, a file in the package.
TEMPLATE = "lookup_module.py.in"
#: The lines around the verbatim copy of designkit/tables/lookup.py in a generated module.
LOOKUP_BEGIN = "# ---- designkit/tables/lookup.py, verbatim (the lookup designkit tests) ----"
LOOKUP_END = "# ---- end of designkit/tables/lookup.py ----"


def lookup_source() -> str:
    """The text of :mod:`designkit.tables.lookup`, read from the installed package."""
    return resources.files("designkit.tables").joinpath("lookup.py").read_text(encoding="utf-8")


#: The lines around the verbatim copy of designkit/export/estimator.py (its package import left out).
ESTIMATOR_BEGIN = "# ---- designkit/export/estimator.py, verbatim but its package import ----"
ESTIMATOR_END = "# ---- end of designkit/export/estimator.py ----"


def estimator_source() -> str:
    """The text of :mod:`designkit.export.estimator` without the block that imports the lookup from designkit
    (the generated module carries :mod:`designkit.tables.lookup` above it)."""
    text = resources.files("designkit.export").joinpath("estimator.py").read_text(encoding="utf-8")
    head, rest = text.split("# <package-import>", 1)
    _, tail = rest.split("# </package-import>\n", 1)
    return head + tail


def example_question(exp: Exported):
    """A question the export answers, for the examples in its opening comment: ``(e1, e2, noise_c, delta_t_c)``
    inside its grid (the README's main job, 35000 vs 20000 at 0.05 degC and 10 degC, where it lies inside)."""
    lo, hi = exp.e_lo, exp.e_hi
    e1 = 35000.0 if lo < 35000.0 <= hi else hi
    e2 = 20000.0 if lo < 20000.0 <= hi and e1 != 20000.0 else 0.5 * (max(lo, 0.0) + hi)
    sc = exp.provenance["slice"]["scene"]
    if sc:
        return e1, e2, float(sc["noise_c"]), float(sc["delta_t_c"])
    names = [a.name for a in exp.scene_axes]
    if names == ["noise_ratio"]:
        r = exp.scene_axes[0].values
        ratio = 0.005 if r[0] <= 0.005 <= r[-1] else r[len(r) // 2]
        return e1, e2, ratio * 10.0, 10.0
    return e1, e2, exp.scene_axes[0].values[0], exp.scene_axes[1].values[0]


def example_answer(exp: Exported):
    """``(question, answer)`` of :func:`example_question`: the library's estimate where the export carries it,
    else the grid's (None: none)."""
    q = example_question(exp)
    if exp.estimator is not None:
        from ..estimator_data import estimator_of

        return q, estimator_of(exp).min_contact_s(*q)
    from ...tables.lookup import Lookup

    scene = [(a.name, a.scale, list(a.values), log_grid(a)) for a in exp.scene_axes]
    lk = Lookup(scene, list(exp.contact.values), list(exp.e_ref.values), exp.delta_up.ravel().tolist(),
                exp.delta_down.ravel().tolist(), exp.e_lo, exp.e_hi, exp.e_lo_inclusive, exp.contact_adjacent)
    try:
        return q, lk.min_contact_s(*q)
    except ValueError:
        return q, None


def _py_list(vals) -> str:
    return "[" + ", ".join(repr(float(v)) for v in vals) + "]"


def _docstring(exp: Exported) -> str:
    p = exp.provenance
    model = p["model"]
    params = ", ".join(f"{k} = {v!r}" for k, v in model.items() if k != "name")
    q, ans = example_answer(exp)
    call = f"min_contact_s({q[0]!r}, {q[1]!r}, {q[2]!r}, {q[3]!r})"
    est = exp.estimator is not None
    lines = [
        f"designkit lookup table {p['source_table']} ({p['fidelity']}, kind {p['kind']}, "
        f"F1 >= {p['threshold']:g}, sensor {p['sensor'].get('name')})",
        "",
        f"Generated by designkit {p['designkit_version']} (do not edit); needs only the Python standard library.",
        f"Regenerate:  {regenerate_command(exp, 'python', None)}",
        "",
        f"Source: {p['source_table']} {p['source_content_hash']} (created {p['source_created']})",
        f"Forward model: {model.get('name')}" + (f" ({params})" if params else ""),
        f"Export hash: {p['export_hash']}",
        *slice_lines(exp),
        "",
        "Example (save this file as designkit_table.py next to your script):",
        "",
        "    >>> import designkit_table as t",
        f"    >>> round(t.{call}, 3)" if ans is not None else f"    >>> t.{call} is None",
        f"    {round(ans, 3)!r}" if ans is not None else "    True",
        "",
        *((f"Estimator: {p['estimator']['name']}, version {p['estimator']['version']} ({p['estimator']['answers']}):",
           "these functions answer",
           "as designkit min-contact / delta-e / distinguishable do (same value, same 90 % interval),",
           "in the code of designkit/export/estimator.py carried below. A question only the library can",
           "answer (max-noise, min-delta-t) is not here: ask designkit.",
           "") if est else (
           f"Estimator: none (answers by the grid rule): {p['estimator']['unavailable']}.",
           "For an SVM table these are NOT designkit's estimates: the functions raise NeedsDesignkit.",
           "The grid rule's lookups stay available as TABLE.min_contact_s etc.", "")),
        "Functions:",
        "",
        "    min_contact_s(e1, e2, noise_c, delta_t_c)        -> float or None",
        "    min_contact_interval(e1, e2, noise_c, delta_t_c) -> (value, low, high) [s]",
        "    delta_e(e, noise_c, delta_t_c, contact_s)        -> float or None",
        "    delta_e_interval(e, noise_c, delta_t_c, contact_s) -> (value, low, high)",
        "    delta_e_lower(...), delta_e_upper(...)          -> float or None",
        "    distinguishable(e1, e2, noise_c, delta_t_c, contact_s) -> bool",
        "    distinguishable_verdict(...) -> (yes, sure): sure when the contact lies outside",
        "        min_contact_interval (inside it the library may decide by max-noise or delta-e)",
        "",
        "Units: effusivity [J s^-1/2 K^-1 m^-2], noise sigma per sample [degC],",
        "delta_t_c = sensor minus object temperature before contact [degC], contact [s].",
        "delta_e is the smaller of the two directions (designkit delta-e's value). None means",
        "nothing in the table suffices (no tabulated contact time separates the pair; no",
        "distinguishable effusivity within the grid in either direction); an interval end None",
        "is open. An input outside the table's grid raises OutsideTable (a ValueError; nothing",
        "is extrapolated); invalid input (NaN, infinite, e <= 0, noise < 0, dT == 0,",
        "contact <= 0, e1 == e2) raises ValueError. distinguishable is the contact against",
        "min_contact_s for the pair (designkit distinguishable's value outside its interval).",
        "TABLE answers by the grid rule alone: lo < hi are distinguishable when",
        "hi - lo >= max(delta_up(lo), delta_down(hi)), delta interpolated on the grid.",
    ]
    return py_docstring("\n".join(printable(line) for line in lines))


def write(exp: Exported) -> bytes:
    """The module's text (ASCII except where designkit/tables/lookup.py itself is not)."""
    est = dict(exp.estimator) if exp.estimator is not None else None
    parts = [exp.delta_up.ravel(), exp.delta_down.ravel(), *(a.ravel() for a in exp.more.values())]
    if est is not None:
        parts += [np.asarray(est.pop("cum")), np.asarray(est.pop("s_f"))]
    sizes = [int(a.size) for a in parts]
    raw = np.concatenate(parts).astype("<f8").tobytes()
    b85 = base64.b85encode(zlib.compress(raw, 9)).decode("ascii")
    data = "\n".join(f'    "{b85[i:i + 96]}",' for i in range(0, len(b85), 96))
    scene = "[\n" + "".join(f"    ({a.name!r}, {a.scale!r}, {_py_list(a.values)}, {_py_list(log_grid(a))}),\n"
                            for a in exp.scene_axes) + "]"
    source = lookup_source()
    text = fill_template(read_template(TEMPLATE), {
        "DOCSTRING": _docstring(exp),
        "LOOKUP_BEGIN": LOOKUP_BEGIN, "LOOKUP_SOURCE": source if source.endswith("\n") else source + "\n",
        "LOOKUP_END": LOOKUP_END,
        "PROVENANCE": py_literal(exp.provenance),
        "SCENE": scene, "CONTACTS": _py_list(exp.contact.values),
        "ADJACENT": repr([bool(x) for x in exp.contact_adjacent]), "CENTRES": _py_list(exp.e_ref.values),
        "E_MIN": repr(float(exp.e_lo)), "E_INCL": repr(bool(exp.e_lo_inclusive)), "E_MAX": repr(float(exp.e_hi)),
        "DATA": data, "DATA_SHA": hashlib.sha256(raw).hexdigest(), "SIZES": repr(sizes),
        "ESTIMATOR_BEGIN": ESTIMATOR_BEGIN, "ESTIMATOR_SOURCE": estimator_source(), "ESTIMATOR_END": ESTIMATOR_END,
        "PARAMS": py_literal(est) if est is not None else "None",
    })
    return text.encode("utf-8")
