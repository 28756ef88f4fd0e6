"""``designkit tables list|show``: what lookup tables are shipped and what they hold."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from . import _app
from ._app import console, emit_json, sub_app
from ._options import Json

tables_app = sub_app("tables", "Shipped lookup tables: list them, or show one's grid and provenance.",
                     panel=_app.TABLES)


@tables_app.command("list")
def tables_list(
    folder: Annotated[Optional[Path], typer.Option("--folder", help="List tables in this folder instead.")] = None,
    json_: Json = False,
) -> None:
    """List the lookup tables (shipped, or in --folder).

    Example: `designkit tables list --json`
    """
    from ..tables.store import list_tables, load_table

    rows = []
    for name in list_tables(folder):
        t = load_table(name if folder is None else folder / f"{name}.npz")
        s = t.summary()
        rows.append({"name": name, "fidelity": s["fidelity"], "sensor": s["sensor"]["name"], "model": s["model"],
                     "axes": {a["name"]: [a["min"], a["max"], a["points"]] for a in s["axes"]},
                     "size_bytes": s["size_bytes"], "path": s["path"]})
    if json_:
        emit_json(rows)
        return
    from rich.table import Table as RichTable

    tab = RichTable(title="designkit lookup tables")
    for col in ("name", "fidelity", "sensor", "model", "sigma/dT", "contact [s]", "intervals", "size"):
        tab.add_column(col)
    for r in rows:
        ax = r["axes"]
        noise = ax.get("noise_ratio") or ax.get("noise_c")
        tab.add_row(r["name"], r["fidelity"], r["sensor"], r["model"]["name"],
                    f"{noise[0]:g}–{noise[1]:g} ({noise[2]})",
                    f"{ax['contact_s'][0]:g}–{ax['contact_s'][1]:g} ({ax['contact_s'][2]})",
                    str(ax["e_ref"][2]), f"{r['size_bytes'] / 1024:.0f} KiB")
    console().print(tab)


@tables_app.command("show")
def tables_show(
    name: Annotated[str, typer.Argument(help="Table name (see 'designkit tables list') or path.")],
    json_: Json = False,
) -> None:
    """Describe one table: grid, units, sensor, forward model, fidelity, provenance, content hash.

    Example: `designkit tables show svm-paper`
    """
    from ..tables.store import load_table

    from rich.markup import escape

    table = load_table(name)
    s = table.summary()
    if json_:
        emit_json(s)
        return
    con = console()
    con.print(f"[bold]{s['name']}[/]  ({s['fidelity']} fidelity, {s['path']})")
    con.print(escape(f"  model {table.model.describe()}"))
    sen = s["sensor"]
    con.print(f"  sensor {sen['name']}: e_s = {sen['effusivity']:g} J s^-1/2 K^-1 m^-2, alpha_s = "
              f"{sen['diffusivity_m2_s']:.3g} m^2/s, depth {sen['depth_m'] * 1e6:g} um, tau = {sen['tau_s']:.4g} s, "
              f"{sen['sample_rate_hz']:g} Hz")
    eff = s["effusivity"]
    con.print(f"  effusivity ({eff['min']:g}, {eff['max']:g}] in {eff['intervals']} intervals of {eff['width']:g}")
    for a in s["axes"]:
        if a["name"] == "e_ref":
            continue
        vals = ", ".join(f"{v:g}" for v in a.get("values", [])) or f"{a['min']:g} .. {a['max']:g}"
        con.print(escape(f"  axis {a['name']} [{a['units']}, {a['scale']}]: {vals}"))
    con.print(f"  threshold F1 >= {s['threshold']:g}; {s['trials']} trials per interval, {s['folds']} folds, seed {s['seed']}")
    st = s.get("stats", {})
    if st.get("svm_fits_total"):
        con.print(f"  built with {st['svm_fits_total']} SVM fits, {st['compute_s_total'] / 3600:.2f} CPU-hours "
                  f"({st['svm_fits_per_scene_mean']:.0f} fits and {st['compute_s_per_scene_mean']:.0f} s per scene)")
    con.print(f"  designkit {s['designkit_version']}, created {s['created']}")
    con.print(f"  arrays: {', '.join(s['arrays'])}")
    con.print(f"  {s['content_hash']}  ({s['size_bytes'] / 1024:.0f} KiB)")
