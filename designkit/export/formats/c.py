"""C99 export: one self-contained header, ``static const`` arrays and the lookup functions.

The header is the template ``designkit/export/templates/designkit_lookup.h.in``
(shipped in the package) with its ``@NAME@`` placeholders filled in one pass
(:func:`designkit.export._common.fill_template`): the data as initializers,
the provenance as macros and comments. It needs only ``<math.h>`` and ``<float.h>``, allocates
nothing, and answers like :mod:`designkit.tables.lookup`:

``PREFIX_min_contact_s``, ``PREFIX_min_contact_interval``, ``PREFIX_delta_e``,
``PREFIX_delta_e_interval``, ``PREFIX_delta_e_lower`` / ``_upper``, ``PREFIX_delta_e_sides``,
``PREFIX_distinguishable`` and ``PREFIX_distinguishable_verdict``: the library's estimator
(:mod:`designkit.export.estimator`, in C, double precision) where the export carries it
(``PREFIX_HAS_ESTIMATOR``), the grid rule for an ideal-observer table (which the library answers by it),
else ``PREFIX_NEEDS_DESIGNKIT`` (-4). ``PREFIX_grid_*`` answer by the grid rule alone.

==================  ============================================
meaning             C (float / int functions)
==================  ============================================
answer              ``>= 0`` / ``PREFIX_YES`` (1) or ``PREFIX_NO`` (0)
nothing suffices    ``PREFIX_NONE`` (-1)
outside the grid    ``PREFIX_OUTSIDE`` (-2) / ``PREFIX_OUTSIDE_I``
invalid input       ``PREFIX_INVALID`` (-3) / ``PREFIX_INVALID_I``
needs designkit     ``PREFIX_NEEDS_DESIGNKIT`` (-4) / ``_I``
==================  ============================================

Every string from the table (names, creation time, units, hash, the forward
model) reaches the header through :func:`~designkit.export._common.c_string`
or :func:`~designkit.export._common.c_comment`; identifiers come only from the
validated prefix and the fixed axis names.
"""

from __future__ import annotations

import json
import math

import numpy as np

from ...tables.lookup import GRID_RTOL
from .._common import (c_comment, c_double, c_string, check_prefix, fill_template, log_grid, read_template,
                       regenerate_command, slice_lines)
from ..slicing import Exported
from .python import example_answer

__all__ = ["TEMPLATE", "describe_model", "write"]

#: The header template, a file in the package.
TEMPLATE = "designkit_lookup.h.in"


def _c_doubles(vals) -> str:
    return ", ".join(c_double(v) for v in vals)


def _c_float_rows(arr: np.ndarray, exp: Exported, per_line: int = 16) -> str:
    """Float initializer text: one commented block per (scene, contact) row; NaN -> -1 (none)."""
    a32 = arr.astype(np.float32)
    flat = a32.ravel()
    u, inv = np.unique(flat, return_inverse=True)
    words = []
    for x in u.tolist():
        if math.isnan(x):
            words.append("-1")
        elif x.is_integer() and abs(x) < 2 ** 24:
            words.append(str(int(x)))
        else:
            words.append(np.format_float_positional(np.float32(x), unique=True) + "f")
    text = np.array(words, dtype=object)[inv.ravel()].reshape(a32.shape)
    ne = a32.shape[-1]
    blocks = []
    for idx in np.ndindex(*a32.shape[:-1]):
        label = c_comment(", ".join(f"{ax.name} {ax.values[i]:g}" for ax, i in zip(exp.axes, idx)))
        row = text[idx].tolist()
        lines = [", ".join(row[i:i + per_line]) for i in range(0, ne, per_line)]
        blocks.append(f"    /* {label} */\n    " + ",\n    ".join(lines))
    return ",\n".join(blocks)


def describe_model(model: dict) -> str:
    """One line naming a forward model and its parameters (``semi-infinite``, ``contact (conductance_w_m2k = 1500)``)."""
    params = {k: v for k, v in model.items() if k != "name"}
    inner = ", ".join(f"{k} = {json.dumps(v, sort_keys=True)}" for k, v in params.items())
    return str(model.get("name")) + (f" ({inner})" if inner else "")


def _num(sensor: dict, key: str) -> float:
    """A sensor number from the provenance (NaN where it is not one)."""
    v = sensor.get(key)
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else math.nan


def _scene_parts(exp: Exported, prefix: str) -> tuple[list[str], list[str], list[str]]:
    """Per scene axis: its macros, its value and grid arrays, and the #undef of its private macro."""
    P = prefix.upper()
    defines, arrays, undefs = [], [], []
    for a in exp.scene_axes:  # a.name is one of the fixed axis names (checked by slice_table)
        big = a.name.upper()
        defines.append(f"#define {P}_N_{big} {len(a.values)}")
        defines.append(f"#define {P}_{big}_MIN {c_double(min(a.values))}")
        defines.append(f"#define {P}_{big}_MAX {c_double(max(a.values))}")
        defines.append(f"#define {P}_{big}_LOG_ {1 if a.scale == 'log' else 0}")
        undefs.append(f"#undef {P}_{big}_LOG_")
        arrays.append(f"/* {a.name} [{c_comment(a.units)}], {a.scale} */")
        arrays.append(f"static const {prefix}_real_ {prefix}_{a.name}_[{len(a.values)}] = {{{_c_doubles(a.values)}}};")
        arrays.append(f"static const {prefix}_real_ {prefix}_{a.name}_g_[{len(a.values)}] = "
                      f"{{{_c_doubles(log_grid(a))}}};")
    return defines, arrays, undefs


def _estimator_values(exp: Exported, grid_is_library: bool) -> dict[str, str]:
    """The estimator's placeholders: its arrays and constants ("0" inside "#if 0" where the export has none)."""
    est = exp.estimator
    ev = {"HAS_EST": "1" if est is not None else "0", "GRID_IS_LIBRARY": "1" if grid_is_library else "0",
          "S_ESTIMATOR": c_string(exp.provenance["estimator"]["name"]),
          "EST_VERSION": str(exp.provenance["estimator"]["version"]), "EST_COVERAGE": c_double(0.9)}
    ev.update({k: "0" for k in ("UP_LO", "DOWN_LO", "UP_HI", "DOWN_HI", "CUM", "NCUM", "SF", "NSF", "RATIOS", "NR",
                                "E_S", "FS", "WIDTH", "ZT", "ZC", "MCF", "ELO", "EHI", "NMAX", "SA0", "SDMIN", "SU0",
                                "SDU", "SNU", "SV0", "SDV", "SNV", "EFFICIENCY")})  # inside "#if 0" when absent
    if est is None:
        return ev
    scene_vals = exp.scene_axes[0].values
    ev.update({
        "UP_LO": _c_float_rows(exp.more["delta_up_lo"], exp), "DOWN_LO": _c_float_rows(exp.more["delta_down_lo"], exp),
        "UP_HI": _c_float_rows(exp.more["delta_up_hi"], exp), "DOWN_HI": _c_float_rows(exp.more["delta_down_hi"], exp),
        "CUM": _c_doubles(est["cum"]), "NCUM": str(len(est["cum"])), "SF": _c_doubles(est["s_f"]),
        "NSF": str(len(est["s_f"])), "RATIOS": _c_doubles(scene_vals), "NR": str(len(scene_vals)),
        "E_S": c_double(est["e_s"]), "FS": c_double(est["fs"]), "WIDTH": c_double(est["width"]),
        "ZT": c_double(est["z_table"]), "ZC": c_double(est["zc"]), "MCF": c_double(est["mc_factor"]),
        "ELO": c_double(est["e_lo"]), "EHI": c_double(est["e_hi"]),
        "NMAX": str(int(math.floor(est["max_contact_s"] * est["fs"] + 1e-9))),
        "SA0": c_double(est["s_a0"]), "SDMIN": c_double(est["s_dmin"]), "SU0": c_double(est["s_u0"]),
        "SDU": c_double(est["s_du"]), "SNU": str(est["s_nu"]), "SV0": c_double(est["s_v0"]),
        "SDV": c_double(est["s_dv"]), "SNV": str(est["s_nv"]),
        "EFFICIENCY": "1" if est.get("efficiency", True) else "0"})
    return ev


def _how_lines(exp: Exported, prefix: str, grid_is_library: bool) -> list[str]:
    """The opening comment's lines on how the functions answer (the estimator, or why not)."""
    p, est, P = exp.provenance, exp.estimator, prefix.upper()
    named = "Estimator: " + p["estimator"]["name"] + ", version " + str(p["estimator"]["version"])
    if est is not None and not est.get("efficiency", True):
        return [named + ": no closed-form ideal observer; the functions below answer as designkit",
                "min-contact / delta-e / distinguishable --sensor FILE do from the sensor's own table (the same",
                "value and 90 % interval, contact from the rig's detected onset), double precision, libm only.",
                "max-noise and min-delta-t are not here."]
    if est is not None:
        return [named + ": the",
                "functions below answer as designkit min-contact / delta-e / distinguishable do (the same value",
                "and 90 % interval), in double precision, libm only. max-noise and min-delta-t are not here."]
    if grid_is_library:
        return ["An ideal-observer table: designkit answers it by the grid rule, which the functions below run."]
    return ["Estimator: none (" + str(p["estimator"]["unavailable"]) + ").",
            "The functions below return " + P + "_NEEDS_DESIGNKIT (-4): only designkit answers this table as",
            "designkit does; " + prefix + "_grid_* answer by the grid rule (not designkit's estimates)."]


def _example_lines(exp: Exported, prefix: str) -> list[str]:
    """The opening comment's runnable example: the README's main job, and what it prints."""
    q, ans = example_answer(exp)
    return ["    #include <stdio.h>", f'    #include "{prefix}_table.h"',
            "    int main(void) {", "        double iv[3];",
            f"        if ({prefix}_min_contact_interval({q[0]!r}, {q[1]!r}, {q[2]!r}, {q[3]!r}, iv) == 0)",
            '            printf("%.3f s (%.3f to %.3f)\\n", iv[0], iv[1], iv[2]);',
            "        return 0;", "    }",
            f"    prints {ans:.3f} s ...  (cc -std=c99 main.c -lm)" if ans is not None else "    prints nothing (none)"]


def _provenance_values(exp: Exported, prefix: str) -> dict[str, str]:
    """The provenance's placeholders: comment text (c_comment) and string macros (c_string)."""
    p = exp.provenance
    sensor, model = p["sensor"], p["model"]
    return {
        "SLICE": "\n".join(" * " + c_comment(line) for line in slice_lines(exp)),
        "COMMAND": c_comment(regenerate_command(exp, "c", prefix)),
        "VERSION": c_comment(p["designkit_version"]), "TABLE": c_comment(p["source_table"]),
        "HASH": c_comment(p["source_content_hash"]), "CREATED": c_comment(p["source_created"]),
        "SENSOR": c_comment(sensor.get("name")),
        "SENSOR_LINE": c_comment(f"e_s {_num(sensor, 'effusivity')!r} J s^-1/2 K^-1 m^-2, alpha_s "
                                 f"{_num(sensor, 'diffusivity_m2_s')!r} m^2/s, depth {_num(sensor, 'depth_m')!r} m, "
                                 f"{_num(sensor, 'sample_rate_hz')!r} Hz"),
        "MODEL": c_comment(describe_model(model)),
        "ONSET": c_double((p.get("contact_frame") or {}).get("onset_offset_s") or 0.0),
        "FIDELITY": c_comment(p["fidelity"]), "KIND": c_comment(p["kind"]),
        "KIND_MEANING": c_comment(p["kind_meaning"]),
        "THRESHOLD": c_comment(f"{p['threshold']:g}"), "EXPORT_HASH": c_comment(p["export_hash"]),
        "S_TABLE": c_string(p["source_table"]), "S_HASH": c_string(p["source_content_hash"]),
        "S_CREATED": c_string(p["source_created"]), "S_EXPORT_HASH": c_string(p["export_hash"]),
        "S_VERSION": c_string(p["designkit_version"]), "S_FIDELITY": c_string(p["fidelity"]),
        "S_KIND": c_string(p["kind"]), "THRESHOLD_D": c_double(p["threshold"]),
        "S_SENSOR": c_string(sensor.get("name")),
        "S_MODEL": c_string(model.get("name")),
        "S_MODEL_PARAMETERS": c_string(json.dumps({k: v for k, v in model.items() if k != "name"},
                                                  sort_keys=True, allow_nan=False)),
        "SENSOR_E": c_double(_num(sensor, "effusivity")), "SENSOR_A": c_double(_num(sensor, "diffusivity_m2_s")),
        "SENSOR_D": c_double(_num(sensor, "depth_m")), "SENSOR_F": c_double(_num(sensor, "sample_rate_hz")),
        "S_SLICE": c_string("; ".join(slice_lines(exp))),
    }


def write(exp: Exported, prefix: str = "designkit") -> bytes:
    """The C99 header text of ``exp``; every function, macro and constant starts with ``prefix``."""
    prefix = check_prefix(prefix)
    p = exp.provenance
    scene = exp.scene_axes
    nc, ne = len(exp.contact.values), len(exp.e_ref.values)
    ndata = int(exp.delta_up.size)
    defines, arrays, undefs = _scene_parts(exp, prefix)
    varied = [a.name for a in scene] != ["noise_ratio"]
    nbytes = 8 * ndata + 8 * (nc + ne + 2 * sum(len(a.values) for a in scene)) + nc
    grid_is_library = exp.estimator is None and p["fidelity"] != "svm" and p["kind"] == "svm"
    text = fill_template(read_template(TEMPLATE), {
        **_estimator_values(exp, grid_is_library), **_provenance_values(exp, prefix),
        "HOW": "\n".join(" * " + c_comment(x) for x in _how_lines(exp, prefix, grid_is_library)),
        "EXAMPLE": "\n".join(" * " + c_comment(x).replace("\\\\", "\\") for x in _example_lines(exp, prefix)),
        "P": prefix.upper(), "p": prefix,
        "SCENE_VARIED": "1" if varied else "0",
        "SCENE_DEFINES": "\n".join(defines),
        "SCENE_ARRAYS": "\n".join(arrays),
        "SCENE_UNDEFS": "\n".join(undefs),
        "SCENE_WORDS": "sigma and linearly in dT" if varied else "sigma/dT",
        "BYTES": str(nbytes),
        "E_MIN": c_double(exp.e_lo), "E_MAX": c_double(exp.e_hi), "E_INCL": "1" if exp.e_lo_inclusive else "0",
        "C_MIN": c_double(exp.contact.values[0]), "C_MAX": c_double(exp.contact.values[-1]),
        "NC": str(nc), "NE": str(ne), "NDATA": str(ndata), "RTOL": c_double(GRID_RTOL),
        "CONTACTS": _c_doubles(exp.contact.values),
        "ADJACENT": ", ".join(["1" if x else "0" for x in exp.contact_adjacent] + ["0"]),
        "CENTRES": _c_doubles(exp.e_ref.values),
        "DELTA_UP": _c_float_rows(exp.delta_up, exp), "DELTA_DOWN": _c_float_rows(exp.delta_down, exp),
    })
    return text.encode("ascii")
