"""Design questions: min-contact, max-noise, min-delta-t, delta-e, distinguishable.

Answered from the shipped tables in milliseconds (this module and the table
path import neither scikit-learn nor matplotlib), or with ``--exact`` computed
for the one pair and scene. With ``--thickness`` the object is a slab on a
``--backing`` and the question is computed for that scene
(:mod:`designkit.thin_query`).
"""

from __future__ import annotations

from typing import Annotated, Any, Optional

import typer

from ._app import app, console, emit_json
from . import _app
from ._options import E1, E2, Json, SensorOpt, Threshold

M1 = Annotated[Optional[str], typer.Option("--m1", help="First material by name (instead of --e1); see 'designkit materials list'.")]
M2 = Annotated[Optional[str], typer.Option("--m2", help="Second material by name (instead of --e2).")]
NoiseQ = Annotated[float, typer.Option("--noise", help="Noise sigma per sample [°C].")]
DeltaTQ = Annotated[float, typer.Option("--delta-t", help="Sensor minus object temperature before contact [°C].")]
ContactQ = Annotated[float, typer.Option("--contact", help="Contact time [s].")]
Exact = Annotated[bool, typer.Option("--exact", help="Compute for this pair and scene (seconds) instead of reading a table.")]
TableOpt = Annotated[str, typer.Option("--table", help="Lookup table (name or path) for the SVM answer.")]
IdealTableOpt = Annotated[str, typer.Option("--ideal-table", help="Lookup table for the ideal-observer bound.")]
TrialsQ = Annotated[int, typer.Option("--trials", help="--exact: simulated touches per class.")]
RepeatsQ = Annotated[int, typer.Option("--repeats", help="--exact: seeds per evaluation (Monte Carlo error).")]
SeedQ = Annotated[int, typer.Option("--seed", help="--exact: random seed.")]
WidthQ = Annotated[float, typer.Option("--width", help="--exact: class width [J s^-1/2 K^-1 m^-2] around each effusivity.")]
JobsQ = Annotated[int, typer.Option("--jobs", "-j", help="--exact: worker processes (-1: all cores).")]
ThicknessQ = Annotated[Optional[float], typer.Option(
    "--thickness", help="Object thickness \\[m] (e.g. 0.003 for a 3 mm sheet): answer for a slab of this thickness "
                        "lying on --backing, computed on demand like --exact (the tables assume semi-infinite "
                        "objects); says whether a semi-infinite table would have held.")]
BackingQ = Annotated[Optional[str], typer.Option(
    "--backing", help="With --thickness: what the slab lies on: table (default: a hardwood table top), insulated "
                      "(nothing), air, steel, wood, or a material name.")]
DiffusivityQ = Annotated[Optional[float], typer.Option(
    "--diffusivity", help="With --thickness: diffusivity \\[m^2/s] of the objects given as numbers (--e1/--e2/--e); "
                          "materials take theirs from the database.")]


def _thin(question: str, thickness, backing, diffusivity, e1, e2, m1, m2, width, **kw):
    """A question with --thickness: computed for the slab scene by designkit.thin_query."""
    from ..query import thin as thin_query

    o1, o2 = thin_query.slab_objects(e1, e2, m1, m2, diffusivity_m2_s=diffusivity, width=width)
    fn = {"min-contact": thin_query.thin_min_contact, "max-noise": thin_query.thin_max_noise,
          "min-delta-t": thin_query.thin_min_delta_t, "distinguishable": thin_query.thin_distinguishable}[question]
    return fn(o1, o2, thickness_m=thickness, backing=backing, **kw), {"e1": o1.label, "e2": o2.label}


def _slab_options(thickness, backing, diffusivity) -> None:
    from .._validation import InputError

    if thickness is None and (backing is not None or diffusivity is not None):
        raise InputError("--backing and --diffusivity describe a thin sample: give its --thickness too")


def _pair_answer(question: str, e1, e2, m1, m2, scene: dict, *, thickness, backing, diffusivity, exact: bool,
                 table: str, ideal_table: str, threshold: float, sensor: str, width: float, trials: int, seed: int,
                 repeats: int, jobs: int, exact_extra: Optional[dict] = None):
    """Answer a two-object question (``scene``: its scene keywords) from the thin-sample model
    (--thickness), by computing it for this pair (--exact), or from the tables; with the labels."""
    from ..query import table as query

    _slab_options(thickness, backing, diffusivity)
    common = dict(threshold=threshold, sensor=sensor, trials=trials, seed=seed, repeats=repeats, jobs=jobs)
    if thickness is not None:
        return _thin(question, thickness, backing, diffusivity, e1, e2, m1, m2, width, **scene, **common,
                     **(exact_extra or {}))
    v1, v2, ranges, labels = _sides(e1, e2, m1, m2, exact=exact, width=width)
    name = question.replace("-", "_")
    if exact:
        ans = getattr(query, f"exact_{name}")(v1, v2, **scene, **common, width=width, ranges=ranges,
                                                **(exact_extra or {}))
    else:
        ans = getattr(query, name)(v1, v2, **scene, threshold=threshold, table=table, ideal_table=ideal_table,
                                   sensor=None if sensor == "paper" else sensor, ranges=ranges)
    return ans, labels


def _sides(e1, e2, m1, m2, *, exact: bool, width: float) -> tuple[Optional[float], Optional[float], Any, dict]:
    """Resolve numbers or material names to (e1, e2, ranges, labels)."""
    from .._validation import InputError, check_effusivity

    if (e1 is None and m1 is None) or (e2 is None and m2 is None):
        raise InputError("give two objects: --e1/--m1 and --e2/--m2")
    if e1 is not None and m1 is not None or e2 is not None and m2 is not None:
        raise InputError("give each object once: either --e1 or --m1, either --e2 or --m2")
    if m1 is None and m2 is None:
        return e1, e2, None, {"e1": f"{e1:g}", "e2": f"{e2:g}"}
    from ..materials import get_material

    ranges, labels = [], {}
    for key, e, m in (("e1", e1, m1), ("e2", e2, m2)):
        if m is not None:
            mat = get_material(m)
            ranges.append(tuple(mat.effusivity_range))
            labels[key] = f"{mat.name} ({mat.effusivity_range[0]:.0f}–{mat.effusivity_range[1]:.0f})"
        else:
            v = check_effusivity(key, e)
            ranges.append((v, v + width) if exact else (v, v))
            labels[key] = f"{v:g}"
    return None, None, tuple(ranges), labels


def _emit(ans, labels: dict, json_: bool, render) -> None:
    d = ans.to_dict()
    if json_:
        emit_json(render(d, json_=True))
        return
    render(d, json_=False, labels=labels)


def _fmt(x, unit="", digits=3) -> str:
    return "—" if x is None else f"{x:.{digits}g}{unit}"


def _header_line(con, d, labels, extra=""):
    inp = d["inputs"]
    scene = []
    if inp.get("noise_c") is not None:
        scene.append(f"noise {inp['noise_c']:g} °C")
    if inp.get("delta_t_c") is not None:
        scene.append(f"dT {inp['delta_t_c']:g} °C")
    if inp.get("contact_s") is not None:
        scene.append(f"contact {inp['contact_s']:g} s")
    con.print(f"[bold]{labels.get('e1', '')}[/] vs [bold]{labels.get('e2', '')}[/] J s^-1/2 K^-1 m^-2, "
              f"{', '.join(scene)}, {inp.get('sensor', 'paper')} sensor, F1 >= {inp['threshold']:g}{extra}")
    if inp.get("rule"):
        con.print(f"  [dim]materials: {inp['rule']}[/]")


def _source_line(con, d):
    if d["source"] == "table":
        where = "inside its grid" if all(d["in_grid"].values()) else \
            "OUTSIDE its grid along " + ", ".join(k for k, v in d["in_grid"].items() if not v)
        con.print(f"  [dim]from table {d['table']} ({where}), interpolated; --exact computes it for this pair[/]")
    else:
        wall = d["extra"].get("wall_s")
        con.print(f"  [dim]computed for this pair ({d['inputs'].get('repeats')} seeds x "
                  f"{d['inputs'].get('trials')} trials per class{f', {wall:.1f} s' if wall else ''})[/]")
    if d.get("note"):
        con.print(f"  [yellow]{d['note']}[/]")
    slab = d["extra"].get("slab")
    if slab:
        con.print(f"  {'[dim]' if slab['holds'] else '[yellow]'}{slab['message']}[/]")


def _common(d: dict) -> dict:
    inp = d["inputs"]
    return {"source": d["source"], "table": d["table"], "ideal_table": d["ideal_table"],
            "e1": inp.get("e1"), "e2": inp.get("e2"), "e1_range": inp.get("e1_range"),
            "e2_range": inp.get("e2_range"), "rule": inp.get("rule"),
            "noise_c": inp.get("noise_c"), "delta_t_c": inp.get("delta_t_c"),
            "contact_s": inp.get("contact_s"), "threshold": inp["threshold"],
            "fidelity": d["extra"].get("fidelity", "svm"), "sensor": inp.get("sensor"),
            "in_grid": d["in_grid"], "note": d["note"], "slab": d["extra"].get("slab"), "inputs": inp,
            "details": d["extra"]}


# ============================================================ min-contact
@app.command("min-contact", rich_help_panel=_app.ASK)
def min_contact_cmd(
    e1: E1 = None, e2: E2 = None, m1: M1 = None, m2: M2 = None,
    noise: NoiseQ = 0.05, delta_t: DeltaTQ = 10.0, threshold: Threshold = 0.9, sensor: SensorOpt = "paper",
    exact: Exact = False, table: TableOpt = "svm-paper", ideal_table: IdealTableOpt = "ideal-paper",
    trials: TrialsQ = 100, repeats: RepeatsQ = 4, seed: SeedQ = 0, width: WidthQ = 80.0, jobs: JobsQ = -1,
    max_contact: Annotated[float, typer.Option("--max-contact", help="--exact: longest contact time to consider [s].")] = 10.0,
    thickness: ThicknessQ = None, backing: BackingQ = None, diffusivity: DiffusivityQ = None,
    json_: Json = False,
) -> None:
    """Shortest contact time that separates two materials (e.g. --e1 35000 --e2 20000)."""
    ans, labels = _pair_answer("min-contact", e1, e2, m1, m2, dict(noise_c=noise, delta_t_c=delta_t),
                               thickness=thickness, backing=backing, diffusivity=diffusivity, exact=exact,
                               table=table, ideal_table=ideal_table, threshold=threshold, sensor=sensor, width=width,
                               trials=trials, seed=seed, repeats=repeats, jobs=jobs,
                               exact_extra=dict(max_contact_s=max_contact))

    def render(d, json_, labels=None):
        if json_:
            return {"contact_time_s": d["value"], "contact_time_interval_s": d["interval"],
                    "ideal_contact_time_s": d["ideal"], **_common(d)}
        con = console()
        _header_line(con, d, labels)
        lo, hi = d["interval"]
        if not all(d["in_grid"].values()):
            con.print("  [yellow]no answer from the table[/] (the question lies outside its grid)")
        elif d["value"] is None:
            con.print("  SVM (the paper's classifier): [red]no contact time in range separates them[/]")
        else:
            con.print(f"  SVM (the paper's classifier): [bold green]{d['value']:.2f} s[/] of contact at least "
                      f"(Monte Carlo interval {_fmt(lo, ' s')} to {_fmt(hi, ' s')})")
            grid = d["extra"].get("table_contacts_s") or []
            if d["value"] in grid and grid.index(d["value"]) > 0:
                prev = grid[grid.index(d["value"]) - 1]
                con.print(f"  [dim]{d['value']:g} s is the table's next contact time after {prev:g} s, where they are "
                          f"not separable: the shortest time lies in ({prev:g}, {d['value']:g}] s; --exact resolves "
                          f"it[/]")
        ideal = d["ideal"]
        con.print(f"  ideal observer bound:         {_fmt(ideal, ' s')}"
                  + ("  (no classifier can do with less)" if ideal is not None else ""))
        _source_line(con, d)

    _emit(ans, labels, json_, render)


# ============================================================ max-noise / min-delta-t
@app.command("max-noise", rich_help_panel=_app.ASK)
def max_noise_cmd(
    e1: E1 = None, e2: E2 = None, m1: M1 = None, m2: M2 = None,
    contact: ContactQ = 2.0, delta_t: DeltaTQ = 10.0, threshold: Threshold = 0.9, sensor: SensorOpt = "paper",
    exact: Exact = False, table: TableOpt = "svm-paper", ideal_table: IdealTableOpt = "ideal-paper",
    trials: TrialsQ = 100, repeats: RepeatsQ = 4, seed: SeedQ = 0, width: WidthQ = 80.0, jobs: JobsQ = -1,
    thickness: ThicknessQ = None, backing: BackingQ = None, diffusivity: DiffusivityQ = None,
    json_: Json = False,
) -> None:
    """Largest sensor noise at which a contact time still separates two materials."""
    ans, labels = _pair_answer("max-noise", e1, e2, m1, m2, dict(contact_s=contact, delta_t_c=delta_t),
                               thickness=thickness, backing=backing, diffusivity=diffusivity, exact=exact,
                               table=table, ideal_table=ideal_table, threshold=threshold, sensor=sensor, width=width,
                               trials=trials, seed=seed, repeats=repeats, jobs=jobs)
    _emit(ans, labels, json_, _render_scalar("max_noise_c", "largest noise", " °C"))


@app.command("min-delta-t", rich_help_panel=_app.ASK)
def min_delta_t_cmd(
    e1: E1 = None, e2: E2 = None, m1: M1 = None, m2: M2 = None,
    contact: ContactQ = 2.0, noise: NoiseQ = 0.05, threshold: Threshold = 0.9, sensor: SensorOpt = "paper",
    exact: Exact = False, table: TableOpt = "svm-paper", ideal_table: IdealTableOpt = "ideal-paper",
    trials: TrialsQ = 100, repeats: RepeatsQ = 4, seed: SeedQ = 0, width: WidthQ = 80.0, jobs: JobsQ = -1,
    thickness: ThicknessQ = None, backing: BackingQ = None, diffusivity: DiffusivityQ = None,
    json_: Json = False,
) -> None:
    """Smallest sensor-object temperature difference that separates two materials."""
    ans, labels = _pair_answer("min-delta-t", e1, e2, m1, m2, dict(contact_s=contact, noise_c=noise),
                               thickness=thickness, backing=backing, diffusivity=diffusivity, exact=exact,
                               table=table, ideal_table=ideal_table, threshold=threshold, sensor=sensor, width=width,
                               trials=trials, seed=seed, repeats=repeats, jobs=jobs)
    _emit(ans, labels, json_, _render_scalar("min_delta_t_c", "smallest temperature difference", " °C"))


def _render_scalar(key: str, words: str, unit: str):
    def render(d, json_, labels=None):
        if json_:
            return {key: d["value"], key.replace("_c", "_interval_c"): d["interval"],
                    f"ideal_{key}": d["ideal"], **_common(d)}
        con = console()
        _header_line(con, d, labels)
        lo, hi = d["interval"]
        if d["source"] == "table" and d["value"] is None and d["note"].startswith("outside"):
            con.print("  [yellow]no answer from the table[/] (the question lies outside its grid)")
        else:
            con.print(f"  SVM (the paper's classifier): {words} [bold green]{_fmt(d['value'], unit)}[/] "
                      f"(Monte Carlo interval {_fmt(lo, unit)} to {_fmt(hi, unit)})")
            con.print(f"  ideal observer bound:         {_fmt(d['ideal'], unit)}")
        _source_line(con, d)

    return render


# ============================================================ delta-e
@app.command("delta-e", rich_help_panel=_app.ASK)
def delta_e_cmd(
    e: Annotated[Optional[float], typer.Option("--e", help="Reference effusivity [J s^-1/2 K^-1 m^-2].")] = None,
    m: Annotated[Optional[str], typer.Option("--m", help="Reference material (its range's midpoint).")] = None,
    contact: ContactQ = 2.0, noise: NoiseQ = 0.05, delta_t: DeltaTQ = 10.0, threshold: Threshold = 0.9,
    sensor: SensorOpt = "paper", exact: Exact = False, table: TableOpt = "svm-paper",
    ideal_table: IdealTableOpt = "ideal-paper", trials: TrialsQ = 100, repeats: RepeatsQ = 4, seed: SeedQ = 0,
    width: WidthQ = 80.0, jobs: JobsQ = -1,
    thickness: ThicknessQ = None, backing: BackingQ = None, diffusivity: DiffusivityQ = None, json_: Json = False,
) -> None:
    """Smallest distinguishable effusivity difference delta(e), towards lower and higher effusivity."""
    from ..query import table as query
    from .._validation import InputError

    _slab_options(thickness, backing, diffusivity)
    if (e is None) == (m is None):
        raise InputError("give the reference as --e NUMBER or --m MATERIAL")
    label = f"{e:g}" if e is not None else m
    if m is not None:
        from ..materials import get_material

        mat = get_material(m)
        e = 0.5 * (mat.effusivity_range[0] + mat.effusivity_range[1])
        label = f"{mat.name} (midpoint {e:.0f})"
    if thickness is not None:
        from ..query import thin as thin_query

        ans = thin_query.thin_delta_e(e, thickness_m=thickness, diffusivity_m2_s=diffusivity, material=m,
                                      backing=backing, contact_s=contact, noise_c=noise, delta_t_c=delta_t,
                                      threshold=threshold, sensor=sensor, width=width, trials=trials, seed=seed,
                                      repeats=repeats, jobs=jobs, label=label)
    elif exact:
        ans = query.exact_delta_e(e, contact_s=contact, noise_c=noise, delta_t_c=delta_t, threshold=threshold,
                                  sensor=sensor, width=width, trials=trials, seed=seed, repeats=repeats, jobs=jobs)
    else:
        ans = query.delta_e(e, contact_s=contact, noise_c=noise, delta_t_c=delta_t, threshold=threshold, table=table,
                            ideal_table=ideal_table, sensor=None if sensor == "paper" else sensor)

    def render(d, json_, labels=None):
        x = d["extra"]
        if json_:
            return {"delta_e_lower": x.get("delta_e_lower"), "delta_e_upper": x.get("delta_e_upper"),
                    "delta_e_lower_interval": x.get("delta_e_lower_interval"),
                    "delta_e_upper_interval": x.get("delta_e_upper_interval"),
                    "ideal_delta_e_lower": x.get("delta_e_lower_ideal"),
                    "ideal_delta_e_upper": x.get("delta_e_upper_ideal"), "e": d["inputs"]["e"], **_common(d)}
        con = console()
        inp = d["inputs"]
        con.print(f"delta(e) at [bold]{label}[/] J s^-1/2 K^-1 m^-2: contact {inp['contact_s']:g} s, noise "
                  f"{inp['noise_c']:g} °C, dT {inp['delta_t_c']:g} °C, F1 >= {inp['threshold']:g}")
        for side, key in (("towards lower e ", "delta_e_lower"), ("towards higher e", "delta_e_upper")):
            iv = x.get(key + "_interval") or [None, None]
            con.print(f"  {side}: SVM [bold green]{_fmt(x.get(key), '', 4)}[/] "
                      f"(interval {_fmt(iv[0], '', 4)} to {_fmt(iv[1], '', 4)}), ideal {_fmt(x.get(key + '_ideal'), '', 4)}")
        con.print("  [dim]— : no distinguishable effusivity in that direction within the grid[/]")
        _source_line(con, d)

    _emit(ans, {}, json_, render)


# ============================================================ distinguishable
@app.command("distinguishable", rich_help_panel=_app.ASK)
def distinguishable_cmd(
    e1: E1 = None, e2: E2 = None, m1: M1 = None, m2: M2 = None,
    contact: ContactQ = 2.0, noise: NoiseQ = 0.05, delta_t: DeltaTQ = 10.0, threshold: Threshold = 0.9,
    sensor: SensorOpt = "paper", exact: Exact = False, table: TableOpt = "svm-paper",
    ideal_table: IdealTableOpt = "ideal-paper", trials: TrialsQ = 100, repeats: RepeatsQ = 4, seed: SeedQ = 0,
    width: WidthQ = 80.0, jobs: JobsQ = -1,
    thickness: ThicknessQ = None, backing: BackingQ = None, diffusivity: DiffusivityQ = None, json_: Json = False,
) -> None:
    """Whether a scene separates two materials, with the SVM's and the ideal observer's F1."""
    ans, labels = _pair_answer("distinguishable", e1, e2, m1, m2, dict(contact_s=contact, noise_c=noise, delta_t_c=delta_t),
                               thickness=thickness, backing=backing, diffusivity=diffusivity, exact=exact,
                               table=table, ideal_table=ideal_table, threshold=threshold, sensor=sensor, width=width,
                               trials=trials, seed=seed, repeats=repeats, jobs=jobs)

    def render(d, json_, labels=None):
        x = d["extra"]
        if json_:
            return {"distinguishable": x.get("distinguishable"), "svm_f1": x.get("svm_f1"),
                    "svm_standard_error": x.get("svm_standard_error"), "ideal_f1": x.get("ideal_f1"),
                    "ideal_distinguishable": x.get("ideal_distinguishable"), **_common(d)}
        con = console()
        _header_line(con, d, labels)
        if x.get("distinguishable") is None:
            con.print("  [yellow]no answer[/]")
        else:
            yes = "[bold green]yes[/]" if x["distinguishable"] else "[bold red]no[/]"
            f1 = f", F1 {x['svm_f1']:.3f} ± {x['svm_standard_error']:.3f}" if x.get("svm_f1") is not None else ""
            con.print(f"  SVM (the paper's classifier): {yes}{f1}")
            con.print(f"  ideal observer: F1 {x['ideal_f1']:.3f}"
                      + (" (distinguishable)" if x["ideal_distinguishable"] else " (not even in principle)"))
        _source_line(con, d)

    _emit(ans, labels, json_, render)
