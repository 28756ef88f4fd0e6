"""``designkit materials list|show``: the shipped materials table (designkit.materials)."""

from __future__ import annotations

from typing import Annotated, Optional

import typer

from . import _app
from ._app import console, sub_app
from ._format import FormatOpt, OutOpt, emit, emit_rows, output_format
from ._options import Json

materials_app = sub_app(
    "materials",
    "Materials: effusivity and diffusivity ranges of engineering material families "
    "(public handbook table) and of the paper's 12 experiment materials.",
    panel=_app.ASK,
)

SetOpt = Annotated[str, typer.Option(
    "--set", help="Named set: 'database' (handbook families) or 'paper12' (the paper's robot materials).")]
_SORTS = ("file", "name", "effusivity")


def _range(lo: float, hi: float, fmt: str, sep: str = " – ") -> str:
    return f"{lo:{fmt}}{sep}{hi:{fmt}}"


@materials_app.command("list")
def list_(
    family: Annotated[Optional[str], typer.Option(
        "--family", help="Only one family: metals, ceramics, polymers or composites.")] = None,
    set_: SetOpt = "database",
    sort: Annotated[str, typer.Option(
        "--sort", help="Order: 'file' (grouped by family), 'name' or 'effusivity' (by e_min).")] = "file",
    format_: FormatOpt = None,
    out: OutOpt = None,
    json_: Json = False,
) -> None:
    """List materials with their effusivity and diffusivity ranges.

    Example: `designkit materials list --family metals --sort effusivity`

    Example: `designkit materials list --set paper12 --format csv --out materials.csv`
    """
    from .._validation import InputError
    from ..materials import FAMILY_LABELS, list_materials

    fmt = output_format(format_, json_, default="table")
    if sort not in _SORTS:
        raise InputError(f"unknown sort {sort!r}; choose one of: {', '.join(_SORTS)}")
    mats = list_materials(family=family, set=set_)
    if sort == "name":
        mats = tuple(sorted(mats, key=lambda m: m.name.lower()))
    elif sort == "effusivity":
        mats = tuple(sorted(mats, key=lambda m: (m.e_min, m.e_max)))
    paper = set_.strip().lower() == "paper12"
    payload = {"set": set_.strip().lower(), "family": family, "count": len(mats),
               "materials": [m.to_dict() for m in mats]}
    if fmt in ("csv", "ndjson", "json"):  # plain values, full precision; a name column that 'designkit matrix --from' reads
        cols = ["name", "family", "set", *(["identified"] if paper else []), "e_min", "e_max",
                "diffusivity_min_m2_s", "diffusivity_max_m2_s", "flags"]
        rows = [{"name": m.name, "family": m.family, "set": m.set, "identified": m.identified, "e_min": m.e_min,
                 "e_max": m.e_max, "diffusivity_min_m2_s": m.diffusivity_min_m2_s,
                 "diffusivity_max_m2_s": m.diffusivity_max_m2_s, "flags": ";".join(m.flags)} for m in mats]
        emit_rows(rows, cols, fmt=fmt, out=out, payload=payload)
        return
    e_fmt = ".2f" if paper else ".0f"
    cols = ["name", "family", *(["identified"] if paper else []), "e min–max", "α min–max"]
    rows = []
    for m in mats:
        row = {"name": m.name + (" [!]" if m.flags else ""), "family": m.family}
        if paper:
            row["identified"] = "–" if m.identified is None else f"{m.identified:.2f}"
        row["e min–max"] = _range(m.e_min, m.e_max, e_fmt, "–")
        row["α min–max"] = _range(m.diffusivity_min_m2_s * 1e6, m.diffusivity_max_m2_s * 1e6, ".3g", "–")
        rows.append(row)
    counts = ", ".join(f"{f} {sum(m.family == f for m in mats)}" for f in FAMILY_LABELS
                       if any(m.family == f for m in mats))
    rule = ("as printed in the paper; α from the database family named by 'show'" if paper else
            "sqrt(k rho c) and k/(rho c) at the corners of the k, rho, c ranges")
    flagged = "; [!] = flagged, see 'show'" if any(m.flags for m in mats) else ""
    emit_rows(rows, cols, fmt=fmt, out=out, title=f"{len(mats)} materials ({set_.strip().lower()} set)",
              notes=[f"{counts}. e in J s^-1/2 K^-1 m^-2, α in mm²/s: {rule}{flagged}."],
              justify={"name": "left", "family": "left", "identified": "right", "e min–max": "right",
                       "α min–max": "right"})


@materials_app.command("show")
def show(
    name: Annotated[str, typer.Argument(help="Material name or alias (case, punctuation and word order ignored); "
                                             "prefix 'paper12:' for the paper's set.")],
    set_: Annotated[Optional[str], typer.Option(
        "--set", help="Look only in this set (default: database, then paper12).")] = None,
    format_: FormatOpt = None,
    out: OutOpt = None,
    json_: Json = False,
) -> None:
    """Show one material: property ranges, effusivity, diffusivity and source.

    Example: `designkit materials show "stainless steel"`

    Example (one row per property): `designkit materials show "stainless steel" --format csv`
    """
    from ..materials import get_material

    fmt = output_format(format_, json_, out=out)
    m = get_material(name, set=set_)

    def rows() -> list[dict]:
        """One row per property (table, csv, ndjson, md)."""
        props = [("conductivity", m.conductivity_min_w_mk, m.conductivity_max_w_mk, "W m^-1 K^-1"),
                 ("density", m.density_min_kg_m3, m.density_max_kg_m3, "kg m^-3"),
                 ("specific_heat", m.specific_heat_min_j_kgk, m.specific_heat_max_j_kgk, "J kg^-1 K^-1"),
                 ("effusivity", m.e_min, m.e_max, "J s^-1/2 K^-1 m^-2"),
                 ("diffusivity", m.diffusivity_min_m2_s, m.diffusivity_max_m2_s, "m^2 s^-1")]
        out_rows = [{"material": m.name, "property": p, "min": lo, "max": hi, "unit": u}
                    for p, lo, hi, u in props if lo is not None or hi is not None]
        if m.identified is not None:
            out_rows.append({"material": m.name, "property": "identified_effusivity", "min": m.identified,
                             "max": m.identified, "unit": "J s^-1/2 K^-1 m^-2"})
        return out_rows

    emit(fmt, out, payload=m.to_dict(), records=rows, text=lambda: _print_material(m),
         columns=["material", "property", "min", "max", "unit"], title=f"{m.name} ({m.family_label}; {m.set} set)",
         notes=[f"source: {m.source}"])


def _print_material(m) -> None:
    """``materials show``'s description for people."""
    con = console()
    con.print(f"[bold]{m.name}[/]  ({m.family_label}; {m.set} set)")
    if m.aliases:
        con.print(f"  aliases          {', '.join(m.aliases)}")
    if m.conductivity_min_w_mk is not None:
        con.print(f"  conductivity k   {_range(m.conductivity_min_w_mk, m.conductivity_max_w_mk, 'g')} W m^-1 K^-1")
        con.print(f"  density rho      {_range(m.density_min_kg_m3, m.density_max_kg_m3, 'g')} kg m^-3")
        con.print(f"  specific heat c  {_range(m.specific_heat_min_j_kgk, m.specific_heat_max_j_kgk, 'g')} J kg^-1 K^-1")
    con.print(f"  effusivity e     {_range(m.e_min, m.e_max, ',.2f')} J s^-1/2 K^-1 m^-2"
              + ("  (sqrt(k rho c) at the range corners)" if m.set == "database" else "  (as printed in the paper)"))
    if m.identified is not None:
        con.print(f"  identified e     {m.identified:,.2f} J s^-1/2 K^-1 m^-2 (paper's sensor calibration)")
    con.print(f"  diffusivity α    {_range(m.diffusivity_min_m2_s, m.diffusivity_max_m2_s, '.3g')} m^2 s^-1"
              + (f"  (from database '{m.diffusivity_from}')" if m.diffusivity_from else ""))
    for flag in m.flags:
        if flag == "identified_outside_range":
            con.print("  [yellow]note[/]             the paper's identified value lies outside its printed range "
                      "(kept as printed)")
        else:
            con.print(f"  [yellow]flag[/]             {flag}")
    con.print(f"  source           {m.source}")
