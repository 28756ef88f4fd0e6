"""``designkit tables list|show``: what lookup tables are shipped and what they hold."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from . import _app
from ._app import console, sub_app
from ._format import FormatOpt, OutOpt, emit, emit_rows, output_format, write_output
from ._options import Json

tables_app = sub_app("tables", "Shipped lookup tables: list them, or show one's grid and provenance.",
                     panel=_app.TABLES)


@tables_app.command("list")
def tables_list(
    folder: Annotated[Optional[Path], typer.Option("--folder", help="List tables in this folder instead.")] = None,
    format_: FormatOpt = None,
    out: OutOpt = None,
    json_: Json = False,
) -> None:
    """List the lookup tables (shipped, or in --folder).

    Example: `designkit tables list --format csv`
    """
    from ..tables.store import list_tables, load_table

    from .._validation import InputError

    fmt = output_format(format_, json_, default="table")
    rows = []
    for name in list_tables(folder):
        try:
            t = load_table(name if folder is None else folder / f"{name}.npz")
        except InputError as exc:  # one damaged file in a folder of tables: said, and the others listed
            if folder is None:
                raise
            console(stderr=True).print(f"skipped: {_visible(exc)}")
            continue
        s = t.summary()
        # the keys and shapes of `tables show` (docs/schema.md): the sensor and the axes as there
        rows.append({"name": name, "fidelity": s["fidelity"], "sensor": s["sensor"], "model": s["model"],
                     "axes": s["axes"], "content_hash": s.get("content_hash"), "size_bytes": s["size_bytes"],
                     "path": s["path"]})
    if fmt == "json":
        emit_rows(rows, fmt="json", out=out, payload=rows)
        return
    flat = []
    for r in rows:  # one plain value per column (csv: full precision; table/md: ranges for people)
        ax = {a["name"]: [a["min"], a["max"], a["points"]] for a in r["axes"]}
        noise_axis = "noise_ratio" if "noise_ratio" in ax else "noise_c"
        noise, contact = ax[noise_axis], ax["contact_s"]
        flat.append({"name": r["name"], "fidelity": r["fidelity"], "sensor": r["sensor"]["name"],
                     "model": r["model"]["name"],
                     "noise_axis": noise_axis, "noise_min": noise[0], "noise_max": noise[1], "noise_points": noise[2],
                     "contact_min_s": contact[0], "contact_max_s": contact[1], "contact_points": contact[2],
                     "intervals": ax["e_ref"][2], "size_bytes": r["size_bytes"], "path": r["path"]})
    if fmt in ("csv", "ndjson"):
        emit_rows(flat, fmt=fmt, out=out)
        return
    if not flat and fmt == "table":
        write_output(f"no designkit tables in {folder if folder is not None else 'the shipped folder'}\n", out)
        return
    people = [{"name": f["name"], "fidelity": f["fidelity"], "sensor": f["sensor"], "model": f["model"],
               "sigma/dT" if f["noise_axis"] == "noise_ratio" else "noise [degC]":
                   f"{f['noise_min']:g}–{f['noise_max']:g} ({f['noise_points']})",
               "contact [s]": f"{f['contact_min_s']:g}–{f['contact_max_s']:g} ({f['contact_points']})",
               "intervals": f["intervals"], "size": f"{f['size_bytes'] / 1024:.0f} KiB"} for f in flat]
    cols = list(dict.fromkeys(k for p in people for k in p))
    emit_rows(people, cols, fmt=fmt, out=out, title="designkit lookup tables",
              justify={c: ("right" if c in ("intervals", "size") else "left") for c in cols})


@tables_app.command("show")
def tables_show(
    name: Annotated[str, typer.Argument(help="Table name (see 'designkit tables list') or path.")],
    format_: FormatOpt = None,
    out: OutOpt = None,
    json_: Json = False,
) -> None:
    """Describe one table: grid, units, sensor, forward model, fidelity, provenance, content hash
    (checked in full: every array read and hashed, a shipped table's too).

    Example: `designkit tables show svm-paper`

    Example (its axes, one row each): `designkit tables show svm-paper --format csv`
    """
    from ..tables.store import load_table

    fmt = output_format(format_, json_, out=out)
    table = load_table(name, thorough=True)
    s = table.summary()
    rows = [{"axis": a["name"], "unit": a.get("unit"), "scale": a.get("scale"), "points": a.get("points"),
             "min": a.get("min"), "max": a.get("max"),
             "values": " ".join(f"{v:g}" for v in a.get("values", []))} for a in s["axes"]]
    emit(fmt, out, payload=s, records=rows, text=lambda: _print_table(table, s), title=f"{s['name']}: axes",
         columns=["axis", "unit", "scale", "points", "min", "max", "values"])


def _visible(x) -> str:
    """``str(x)`` with rich markup escaped and control characters (escape sequences, newlines) shown as escapes."""
    from ._app import escape

    return escape("".join(ch if ch.isprintable() else repr(ch)[1:-1] for ch in str(x)))


def _print_table(table, s: dict) -> None:
    """``tables show``'s description for people (every text from the file made visible: it may hold markup)."""
    v = _visible
    con = console()
    con.print(f"[bold]{v(s['name'])}[/]  ({v(s['fidelity'])} fidelity, {v(s['path'])})")
    con.print(f"  model {v(table.model.describe())}")
    sen = s["sensor"]
    con.print(f"  sensor {v(sen['name'])}: e_s = {sen['effusivity']:g} J s^-1/2 K^-1 m^-2, alpha_s = "
              f"{sen['diffusivity_m2_s']:.3g} m^2/s, depth {sen['depth_m'] * 1e6:g} um, tau = {sen['tau_s']:.4g} s, "
              f"{sen['sample_rate_hz']:g} Hz")
    eff = s["effusivity_grid"]
    con.print(f"  effusivity ({eff['min']:g}, {eff['max']:g}] in {eff['intervals']} intervals of {eff['width']:g}")
    for a in s["axes"]:
        if a["name"] == "e_ref":
            continue
        vals = ", ".join(f"{x:g}" for x in a.get("values", [])) or f"{a['min']:g} .. {a['max']:g}"
        con.print(v(f"  axis {a['name']} [{a['unit']}, {a['scale']}]: {vals}"))
    ic = s["initial_conditions"]
    if ic["fixed"]:
        con.print("  initial conditions fixed (every touch starts at Ta + dT)")
    else:
        amb = (f", ambient within +-{ic['ambient_temp_spread_c']:g} degC" if ic["ambient_temp_spread_c"] else "")
        con.print(f"  initial conditions varied per touch: sensor temperature within +-{ic['sensor_temp_spread_c']:g} "
                  f"degC of Ta + dT{amb} (questions must give the same --sensor-temp-spread)")
    con.print(f"  threshold F1 >= {s['threshold']:g}; {s['trials']} trials per interval, {s['folds']} folds, seed {s['seed']}")
    st = s.get("stats", {})
    if st.get("svm_fits_total"):
        # compute_s is each chunk's wall time in its worker, summed: worker time, CPU time when the cores were free
        con.print(f"  built with {st['svm_fits_total']} SVM fits, {st['compute_s_total'] / 3600:.2f} worker-hours "
                  f"({st['svm_fits_per_scene_mean']:.0f} fits and {st['compute_s_per_scene_mean']:.0f} s per scene)")
    con.print(f"  designkit {v(s['designkit_version'])}, created {v(s['created'])}")
    con.print(f"  arrays: {v(', '.join(s['arrays']))}")
    con.print(f"  {v(s['content_hash'])}  ({s['size_bytes'] / 1024:.0f} KiB)")


from .tables_build import tables_build  # noqa: E402  (its own module: the command is long)

tables_app.command("build")(tables_build)
