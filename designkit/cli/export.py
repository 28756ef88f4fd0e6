"""``designkit export``: a lookup table, or the slice a deployment needs, as JSON, CSV, NumPy, C or Python.

The C header and the Python module answer the same questions as ``designkit
min-contact / delta-e / distinguishable`` (from a table) on a robot or a
microcontroller where designkit does not run. Imports nothing heavy: the
export path needs numpy only.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, List, Optional

import typer

from ._app import app, console, emit_json
from . import _app
from ._options import Json

_FORMATS = "json, csv, npz, c (a C99 header) or python (a module needing only the standard library)"


@app.command("export", rich_help_panel=_app.TABLES)
def export_cmd(
    out: Annotated[Path, typer.Option("--out", "-o", help="File to write (.json, .csv, .npz, .h or .py).")],
    table: Annotated[str, typer.Option("--table", help="Lookup table (name or path).")] = "svm-paper",
    fmt: Annotated[Optional[str], typer.Option("--format", "-f", help=f"Format: {_FORMATS}. Default: from --out's suffix.")] = None,
    noise: Annotated[Optional[float], typer.Option("--noise", help="Keep one scene: noise sigma per sample [°C] (with --delta-t).")] = None,
    delta_t: Annotated[Optional[float], typer.Option("--delta-t", help="Keep one scene: sensor minus object temperature [°C] (with --noise).")] = None,
    contact: Annotated[Optional[List[str]], typer.Option("--contact", help="Keep the contact times a robot uses [s]: a value, a range 1:4, or a comma list; repeatable.")] = None,
    e_min: Annotated[Optional[float], typer.Option("--e-min", help="Keep effusivities from this value [J s^-1/2 K^-1 m^-2] (plus one interval of margin).")] = None,
    e_max: Annotated[Optional[float], typer.Option("--e-max", help="Keep effusivities up to this value (plus one interval of margin).")] = None,
    prefix: Annotated[str, typer.Option("--prefix", help="C: prefix of every function, constant and macro.")] = "designkit",
    kind: Annotated[str, typer.Option("--kind", help="Which delta: svm (the table's classifier), lo / hi (ends of its Monte Carlo interval; hi is the conservative one) or ideal.")] = "svm",
    json_: Json = False,
) -> None:
    """Export a table, or only the slice a deployment needs, for software where designkit does not run.

    Example: `designkit export --table svm-paper --format c --noise 0.05 --delta-t 10 --out designkit_table.h`
    writes a C99 header with `designkit_min_contact_s`, `designkit_delta_e` and
    `designkit_distinguishable` for one sensor noise and temperature difference.
    """
    from ..export.core import export_table

    res = export_table(table, out, fmt, prefix=prefix, noise_c=noise, delta_t_c=delta_t, contact=contact,
                       e_min=e_min, e_max=e_max, kind=kind)
    if json_:
        emit_json(res.to_dict())
        return
    from rich.markup import escape

    p = res.provenance
    what = {"json": "JSON", "csv": "CSV", "npz": "NumPy npz", "c": "C99 header", "python": "Python module (stdlib only)"}
    con = console()
    con.print(f"wrote [bold]{escape(str(res.path))}[/] ({what[res.format]}, {_size(res.size_bytes)})")
    con.print(f"  from table {escape(p['source_table'])} ({p['fidelity']} fidelity, kind {p['kind']}, "
              f"F1 >= {p['threshold']:g}, sensor {escape(str(p['sensor'].get('name')))}), {p['source_content_hash']}")
    shape = " x ".join(f"{a['points']} {a['name']}" for a in p["axes"])
    con.print(f"  grid {shape}")
    for line in _lines_from(p):
        con.print("  " + escape(line))
    if res.format == "c":
        pre = prefix
        con.print(f"  [dim]#include it; call {pre}_min_contact_s, {pre}_delta_e, {pre}_distinguishable "
                  f"(sentinels: -1 none suffices, -2 outside the grid, -3 invalid input)[/]")
    elif res.format == "python":
        con.print("  [dim]import it; call min_contact_s, delta_e, distinguishable (None: none suffices; "
                  "OutsideTable / ValueError otherwise)[/]")


def _lines_from(p: dict) -> list[str]:
    s = p["slice"]
    out = []
    if s["scene"]:
        sc = s["scene"]
        out.append(f"one scene: noise {sc['noise_c']:g} °C, dT {sc['delta_t_c']:g} °C")
    if s["contact_s"]:
        out.append(f"contact columns {s['contact_s']['source_columns']} of the table")
    ea = p["effusivity_answered"]
    out.append(f"effusivities answered {ea['min']:g} {'<=' if ea['min_inclusive'] else '<'} e <= {ea['max']:g}")
    return out


def _size(n: int) -> str:
    return f"{n} bytes" if n < 10240 else f"{n / 1024:.0f} KiB" if n < 10 * 1024 ** 2 else f"{n / 1024 ** 2:.1f} MiB"
