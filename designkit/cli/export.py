"""``designkit export``: a lookup table, or the slice a deployment needs, in any format of the export registry.

The C header and the Python module answer the same questions as ``designkit
min-contact / delta-e / distinguishable`` (from a table) on a robot or a
microcontroller where designkit does not run. One library call
(:func:`designkit.export.export_table`, or :func:`~designkit.export.export_bytes`
for ``--out -``), then its result rendered. Imports nothing heavy: the export
path needs numpy only (and scipy for ``.mat``).
"""

from __future__ import annotations

import sys
from typing import Annotated, List, Optional

import typer

from ._app import app, console, emit_json
from . import _app
from ._options import Json

__all__ = ["export_cmd"]

_FORMATS = ("json, csv (provenance in FILE.csv.json), npz, mat (MATLAB), c (a C99 header) or python "
            "(a module needing only the standard library)")
_WHAT = {"json": "JSON", "csv": "CSV", "npz": "NumPy npz", "mat": "MATLAB .mat", "c": "C99 header",
         "python": "Python module (stdlib only)"}


@app.command("export", rich_help_panel=_app.TABLES)
def export_cmd(
    out: Annotated[str, typer.Option("--out", "-o", help="File to write (.json, .csv, .npz, .mat, .h or .py); - for standard output (give --format; a CSV then goes without its provenance sidecar).")],
    table: Annotated[Optional[str], typer.Option("--table", help="Lookup table (name or path); default the one every question reads (with --sensor FILE: the table built for that sensor, if one is).")] = None,
    fmt: Annotated[Optional[str], typer.Option("--format", "-f", help=f"Format: {_FORMATS}. Default: from --out's suffix.")] = None,
    noise: Annotated[Optional[float], typer.Option("--noise", help="Keep one scene: noise sigma per sample [°C] (with --delta-t).")] = None,
    delta_t: Annotated[Optional[float], typer.Option("--delta-t", help="Keep one scene: sensor minus object temperature [°C] (with --noise).")] = None,
    contact: Annotated[Optional[List[str]], typer.Option("--contact", help="Keep the contact times a robot uses [s]: a value, a range 1:4, or a comma list; repeatable.")] = None,
    e_min: Annotated[Optional[float], typer.Option("--e-min", help="Keep effusivities from this value [J s^-1/2 K^-1 m^-2] (plus one interval of margin).")] = None,
    e_max: Annotated[Optional[float], typer.Option("--e-max", help="Keep effusivities up to this value (plus one interval of margin).")] = None,
    prefix: Annotated[str, typer.Option("--prefix", help="C: prefix of every function, constant and macro (macros take it upper-cased: two headers in one program need prefixes that differ in more than case).")] = "designkit",
    kind: Annotated[str, typer.Option("--kind", help="Which delta: svm (the table's classifier), lo / hi (ends of its Monte Carlo interval; hi is the conservative one) or ideal.")] = "svm",
    sensor: Annotated[Optional[str], typer.Option("--sensor", help="Check that the table was built for this sensor (preset or sensor YAML) and the model its file records; refused otherwise.")] = None,
    json_: Json = False,
) -> None:
    """Export a table, or only the slice a deployment needs, for software where designkit does not run.

    Example: `designkit export --format c --noise 0.05 --delta-t 10 --out designkit_table.h`
    writes a C99 header whose `designkit_min_contact_interval`, `designkit_delta_e_interval` and
    `designkit_distinguishable` answer as `designkit min-contact / delta-e / distinguishable` do (value and
    90% interval) for one sensor noise and temperature difference.

    The folder of --out must exist (it is not created).
    """
    from ..export import export_bytes, export_table

    if table is None:  # the table the questions read (the route policy's one answer): a calibrated sensor's own
        from ..query.policy import table_for
        from ..query.table_open import DEFAULT_TABLE

        # (a sensor with none: the default table, which _check_sensor then refuses as another sensor's)
        table = table_for("min-contact", sensor=sensor).table or DEFAULT_TABLE
    if sensor is not None:
        _check_sensor(table, sensor)
    slice_opts = dict(prefix=prefix, noise_c=noise, delta_t_c=delta_t, contact=contact, e_min=e_min, e_max=e_max,
                      kind=kind)
    if out == "-":
        _to_stdout(export_bytes, table, fmt, json_, slice_opts)
        return
    from ._format import check_out

    res = export_table(table, check_out(out, "--out"), fmt, **slice_opts)
    if json_:
        emit_json(res.to_dict())
        return
    from ._app import escape

    p = res.provenance
    con = console()
    con.print(f"wrote [bold]{escape(str(res.path))}[/] ({_WHAT[res.format]}, {_size(res.size_bytes)})"
              + (f" and its provenance {escape(str(res.sidecar))}" if res.sidecar else ""))
    con.print(f"  from table {escape(p['source_table'])} ({escape(str(p['fidelity']))} fidelity, kind {p['kind']}, "
              f"F1 >= {p['threshold']:g}, sensor {escape(str(p['sensor'].get('name')))}, "
              f"model {escape(str(p['model'].get('name')))}), {escape(str(p['source_content_hash']))}")
    shape = " x ".join(f"{a['points']} {a['name']}" for a in p["axes"])
    con.print(f"  grid {shape}")
    for line in _lines_from(p):
        con.print("  " + escape(line))
    if res.format == "c":
        con.print(f"  [dim]#include it; call {prefix}_min_contact_interval, {prefix}_delta_e_interval, "
                  f"{prefix}_distinguishable (sentinels: -1 none suffices, -2 outside the grid, -3 invalid input, "
                  f"-4 only designkit answers this table)[/]")
    elif res.format == "python":
        con.print("  [dim]import it; call min_contact_interval, delta_e_interval, distinguishable (None: none "
                  "suffices; OutsideTable / ValueError otherwise)[/]")
    est = p.get("estimator", {})
    con.print(f"  answers as designkit does: {est.get('name')} v{est.get('version')} (90% intervals)"
              if est.get("answers") == "library" else
              f"  answers as designkit does: {escape(str(est.get('answers')))}" if est.get("answers", "").startswith(
                  "library") else
              f"  [yellow]answers by the grid rule only[/]: {escape(str(est.get('unavailable')))}")


def _check_sensor(table: str, sensor: str) -> None:
    """Refuse (one line, exit 2) a table built for another sensor or forward model than ``--sensor``'s."""
    from .._validation import InputError
    from ..query.inputs import table_reroute
    from ..tables.store import load_table
    from ._options import sensor_and_model

    sen, fm, source = sensor_and_model(sensor)
    tab = load_table(table)
    why = table_reroute(sen, fm, table_sensor=tab.sensor, table_model=tab.model)
    if why:
        raise InputError(f"table {tab.name} was built for sensor {tab.sensor.name!r} and the {tab.model.name} model, "
                         f"not sensor {sen.name!r} with the {fm.name} model ({source}): its answers would be "
                         f"another sensor's; build one with 'designkit sweep --sensor {sensor} ...'")


def _to_stdout(export_bytes, table: str, fmt: str | None, json_: bool, slice_opts: dict) -> None:
    """``--out -``: the export's bytes on standard output, nothing else there."""
    if fmt is None:
        raise ValueError("--out - needs --format (there is no file suffix to tell it from)")
    if json_:
        raise ValueError("--json and --out - both write to standard output; give --out FILE for --json")
    res = export_bytes(table, fmt, **slice_opts)
    if res.format in ("npz", "mat") and sys.stdout.isatty():
        raise ValueError(f"{res.format} is binary: redirect standard output to a file or give --out FILE")
    sys.stdout.buffer.write(res.data)
    sys.stdout.flush()


def _lines_from(p: dict) -> list[str]:
    s = p["slice"]
    out = []
    if s["scene"]:
        sc = s["scene"]
        out.append(f"one scene: noise {sc['noise_c']:g} °C, dT {sc['delta_t_c']:g} °C")
    if s["contact_s"]:
        out.append(f"contact columns {s['contact_s']['source_columns']} of the table")
    one = [a for a in p["axes"] if a["name"] == "noise_ratio" and a["points"] == 1]
    if one and not s["scene"]:  # a sensor's own table: one row, read to 1e-6 (no extrapolation)
        from ..rig import resolve_scene
        from ..sensor import Sensor

        # the scene a question about this sensor takes by default (designkit.rig: the one place that resolves it)
        sc = resolve_scene(Sensor.from_dict(p["sensor"], source="the export's provenance"),
                           {"noise_c": None, "delta_t_c": None})
        noise, dt = sc.values["noise_c"], sc.values["delta_t_c"]
        rig = (f" (the sensor file's noise {noise:.9g} °C at dT {dt:.9g} °C)" if sc.sources["noise_c"] == "sensor file"
               and abs(noise / dt / one[0]["min"] - 1.0) <= 1e-6 else "")
        out.append(f"one sigma/dT row, {one[0]['min']:.9g}{rig}: ask at that ratio (to 1e-6)")
    if (start := (p.get("contact_frame") or {}).get("onset_offset_s")) is not None:
        out.append(f"contact counted from the rig's detected onset (the model's time 0 at {start:+.3g} s)")
    ea = p["effusivity_answered"]
    out.append(f"effusivities answered {ea['min']:g} {'<=' if ea['min_inclusive'] else '<'} e <= {ea['max']:g}")
    return out


def _size(n: int) -> str:
    return f"{n} bytes" if n < 10240 else f"{n / 1024:.0f} KiB" if n < 10 * 1024 ** 2 else f"{n / 1024 ** 2:.1f} MiB"
