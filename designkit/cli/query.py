"""Design questions: min-contact, max-noise, min-delta-t, delta-e, distinguishable.

Each command parses its options, makes one call of :mod:`designkit.query`
and renders the :class:`~designkit.query.Answer` (text, or ``--json``: the
answer's ``to_dict()``). Answered from the shipped tables in milliseconds
(this module and the table route import neither scikit-learn nor
matplotlib), or with ``--exact`` computed for the one pair and scene. A
forward model other than the tables' (``--thickness``, ``--conductance``,
``--model``) is computed like ``--exact`` unless a ``--table`` built for it is named.
"""

from __future__ import annotations

import sys
from contextlib import contextmanager
from typing import Annotated, Optional

import typer

from . import _app
from ._app import app, emit_json
from ._format import check_format, check_out, emit_rows, output_to
from ._options import (
    E1,
    E2,
    M1,
    Explain,
    M2,
    BackingOpt,
    Conductance,
    Diffusivity,
    Json,
    ModelOpt,
    PANEL_EXACT,
    PANEL_OUTPUT,
    PANEL_QUESTION,
    PANEL_SCENE,
    PANEL_SENSOR,
    SensorOpt,
    Thickness,
    Threshold,
    sensor_and_model,
)

Contact = Annotated[float, typer.Option("--contact", help="Contact time [s].",
    rich_help_panel=PANEL_SCENE)]
Exact = Annotated[bool, typer.Option(
    "--exact", help="Compute for this pair and scene (seconds) instead of reading a table.",
    rich_help_panel=PANEL_EXACT)]
TableOpt = Annotated[Optional[str], typer.Option(
    "--table", help="Lookup table (name or path) for the SVM answer (default: svm-fine).",
    rich_help_panel=PANEL_SENSOR)]
IdealTableOpt = Annotated[str, typer.Option("--ideal-table", help="Lookup table for the ideal-observer bound.",
    rich_help_panel=PANEL_SENSOR)]
TrialsQ = Annotated[int, typer.Option("--trials", help="--exact: simulated touches per class.",
    rich_help_panel=PANEL_EXACT)]
RepeatsQ = Annotated[int, typer.Option("--repeats", help="--exact: seeds per evaluation (Monte Carlo error).",
    rich_help_panel=PANEL_EXACT)]
SeedQ = Annotated[int, typer.Option("--seed", help="--exact: random seed.",
    rich_help_panel=PANEL_EXACT)]
WidthQ = Annotated[float, typer.Option(
    "--width", help="--exact: class width [J s^-1/2 K^-1 m^-2] of each object (and of the materials rule).",
    rich_help_panel=PANEL_EXACT)]
JobsQ = Annotated[int, typer.Option("--jobs", "-j", help="--exact: worker processes (-1: all cores).",
    rich_help_panel=PANEL_EXACT)]
NmcQ = Annotated[int, typer.Option(
    "--n-mc", help="--exact: touches per class of the Monte Carlo ideal observer (models without a shared shape).",
    rich_help_panel=PANEL_EXACT)]
MaxContact = Annotated[float, typer.Option("--max-contact", help="--exact: longest contact time to consider [s].",
    rich_help_panel=PANEL_EXACT)]
NoiseQ = Annotated[Optional[float], typer.Option(
    "--noise", help="Noise sigma per sample [°C] (default 0.05, or the rig's as calibrated in a --sensor file).",
    rich_help_panel=PANEL_SCENE)]
DeltaTQ = Annotated[Optional[float], typer.Option(
    "--delta-t", help="Sensor minus object temperature before contact [°C] (default 10, or the rig's as "
                      "calibrated in a --sensor file).", rich_help_panel=PANEL_SCENE)]
SpreadOpt = Annotated[Optional[float], typer.Option(
    "--sensor-temp-spread", help="Varied initial conditions: each touch's sensor temperature uniform within "
    "+-this [°C] of ambient + dT (the paper's robot: --delta-t 7.5 --sensor-temp-spread 2.5, answered from the "
    "shipped table svm-paper-varied for min-contact, delta-e and distinguishable); any other case is computed "
    "like --exact. Must stay below |dT|. Default 0, or the rig's touch-to-touch spread of dT as calibrated in a "
    "--sensor file.", rich_help_panel=PANEL_SCENE)]
CoverageOpt = Annotated[float, typer.Option(
    "--coverage", help="Coverage of the answer's interval, in (0, 1) (table and --exact).",
    rich_help_panel=PANEL_QUESTION)]

#: Exit status of a question without an answer, on either route: the table cannot answer it (outside
#: its grid along an axis, or nothing tabulated separates the pair), the materials' effusivity ranges
#: overlap (no scene separates them), or nothing up to the longest contact / noise searched does.
#: Distinct from bad input (2), so scripts can tell "no answer here" from an answer (0). The message
#: says why in the user's units.
EXIT_NO_ANSWER = 3

#: Questions whose exact route reports its progress evaluation by evaluation (a progress bar); the
#: others get a spinner with the elapsed time.
_STEPWISE = frozenset({"min-contact", "max-noise", "min-delta-t", "delta-e"})

#: Flag hints for library errors (the library speaks in its own terms).
_HINTS = {
    "diffusivity": "give --diffusivity, or name materials with --m1/--m2",
    "diffusivity-unused": "--diffusivity is for the slab model: give --thickness, or drop it",
}


@contextmanager
def _hints():
    """Library errors with the flags that fix them."""
    from ..query.inputs import NeedsInput, TableMismatch

    try:
        yield
    except TableMismatch as exc:
        raise TableMismatch(f"{exc} (use --exact, or a table built for it with designkit sweep)") from None
    except NeedsInput as exc:
        hint = _HINTS.get(exc.what)
        raise NeedsInput(f"{exc} ({hint})" if hint else str(exc), exc.what) from None


def _ask(question: str, *, exact: bool, table: Optional[str], ideal_table: str, threshold: float, sensor: str,
         model, conductance, thickness, backing, diffusivity, width: float, trials: int, repeats: int, seed: int,
         jobs: int, n_mc: int, objects: dict, scene: dict, exact_extra: Optional[dict] = None,
         progress: bool = False, coverage: float = 0.9, spread: Optional[float] = None):
    """The one library call of a command: the table route, or the exact one.

    The scene's values not given (None) come from the sensor file's rig conditions, else the defaults
    (:func:`designkit.rig.resolve_scene`); the answer says which and where each came from."""
    ans, rig, asked = _ask_scene(question, exact=exact, table=table, ideal_table=ideal_table, threshold=threshold,
                                 sensor=sensor, model=model, conductance=conductance, thickness=thickness,
                                 backing=backing, diffusivity=diffusivity, width=width, trials=trials,
                                 repeats=repeats, seed=seed, jobs=jobs, n_mc=n_mc, objects=objects, scene=scene,
                                 exact_extra=exact_extra, progress=progress, coverage=coverage, spread=spread)
    from ..rig import for_rig

    return for_rig(ans, rig, asked)


def _ask_scene(question: str, *, exact: bool, table: Optional[str], ideal_table: str, threshold: float, sensor: str,
               model, conductance, thickness, backing, diffusivity, width: float, trials: int, repeats: int,
               seed: int, jobs: int, n_mc: int, objects: dict, scene: dict, exact_extra: Optional[dict] = None,
               progress: bool = False, coverage: float = 0.9, spread: Optional[float] = None):
    from .. import query
    from ..query.crossing import check_coverage

    from ._options import refuse_together

    refuse_together(("--exact", exact), ("--table", table),
                    why="--exact computes the answer for the pair, --table reads it from a table")
    from .._validation import MAX_EFFUSIVITY, InputError, check_positive

    if check_positive("--width", width) > MAX_EFFUSIVITY:  # on either route (the table's is its own): 1e308 was taken
        raise InputError(f"--width must be at most {MAX_EFFUSIVITY:g} J s^-1/2 K^-1 m^-2, got {width:g}")
    extra = dict(exact_extra or {})
    extra["coverage"] = check_coverage(coverage)  # bad input before any work, on either route

    with _hints():
        from ..query.inputs import table_reroute

        if spread is not None and (spread < 0 or spread != spread):
            from .._validation import InputError

            raise InputError(f"sensor temperature spread must be >= 0 degC, got {spread:g}")
        sen, fm, source = sensor_and_model(sensor, model, conductance=conductance, thickness=thickness,
                                           backing=backing)
        if scene.get("contact_s") is not None:  # a touch the sensor can take, on either route (1e308 s was
            from ..sensor import check_samples_per_touch  # answered "outside the table")

            check_samples_per_touch(check_positive("--contact [s]", scene["contact_s"]), sen.sample_rate_hz,
                                    "--contact", "give a contact time a touch can last")
        from ..rig import resolve_scene

        asked = scene.get("contact_s")
        rig = resolve_scene(sen, {**scene, "sensor_temp_spread_c": spread})
        scene = {k: rig.values[k] for k in scene}
        spread = rig.values["sensor_temp_spread_c"]
        # the shipped tables are for the paper sensor and the semi-infinite model: another sensor or model is
        # computed unless a table is named (a named table built for another one is refused, never used);
        # varied initial conditions: no shipped table holds them, computed for the pair
        own = None  # the table built for this sensor file (designkit tables build), where one is registered
        if not exact and table is None and source == "sensor file" and not spread > 0:
            from ..tables.registry import table_for_sensor

            own = table_for_sensor(sen)
        reroute = None if exact or table is not None or own is not None else table_reroute(sen, fm)
        if reroute and source == "sensor file" and getattr(sen, "conditions", None):
            reroute += "; 'designkit tables build --sensor FILE' builds this sensor's table (then milliseconds)"
        # varied initial conditions: the shipped table for the paper's spread (2.5 degC) and dT, else computed
        varied = None
        if spread > 0 and not exact and table is None and reroute is None:
            from ..query.table import shipped_spread_table

            varied = shipped_spread_table(spread, question, scene.get("delta_t_c"))
        route = "exact" if exact or reroute or (spread > 0 and table is None and varied is None) else "table"
        if spread > 0:
            extra["sensor_temp_spread_c"] = spread
        if route == "table":
            if diffusivity is not None:
                from ..query.inputs import NeedsInput

                raise NeedsInput("a diffusivity was given but tables answer for effusivity alone",
                                 "diffusivity-unused")
            if own is not None:
                return _from_own_table(question, own, objects, scene, threshold, sen, fm, extra["coverage"]), rig, \
                    asked
            from ..query.table import DEFAULT_TABLE

            return query.ask(question, route="table", **objects, **scene, threshold=threshold,
                             table=table or varied or DEFAULT_TABLE, ideal_table=ideal_table,
                             sensor=None if sensor == "paper" else sen, model=fm, coverage=extra["coverage"],
                             sensor_temp_spread_c=spread), rig, asked
        kw = dict(threshold=threshold, sensor=sen, model=fm, diffusivity_m2_s=diffusivity, width=width,
                  trials=trials, repeats=repeats, seed=seed, jobs=jobs, n_mc=n_mc, **extra)
        with _exact_display(question, progress) as report:
            if report is not None:
                kw["progress"] = report
            return _noted(query.ask(question, route="exact", **objects, **scene, **kw), reroute, sen, fm,
                          source), rig, asked


#: Questions whose table route would estimate a missing closed-form ideal bound by Monte Carlo (seconds).
_MC_BOUND = frozenset({"min-contact", "delta-e"})


def _from_own_table(question: str, own, objects: dict, scene: dict, threshold, sen, fm, coverage: float):
    """A question about a sensor file answered from the table built for it (:func:`~designkit.tables.registry.
    table_for_sensor`). Its model has no closed-form ideal observer: the bound is not tabulated, and not
    estimated here (seconds; ``--exact`` does). A question outside the table's span is refused (one line,
    exit 2), never answered by extrapolation nor silently computed instead."""
    import dataclasses

    from .. import query
    from .._validation import InputError

    fn = query.QUESTIONS[question].table
    ans = fn(**objects, **scene, threshold=threshold, table=own, ideal_table=None, sensor=sen, model=fm,
             coverage=coverage, **({"ideal_bound": False} if question in _MC_BOUND else {}))
    if not all(ans.in_grid.values()):
        raise InputError("; ".join(ans.notes) + f" (the table built for sensor {sen.name}): ask with --exact "
                         "(computed, tens of seconds)" + ("" if ans.in_grid.get("effusivity", True) else
                                                          ", or build a table over a wider span with 'designkit "
                                                          "tables build --sensor FILE --e-range LO HI'"))
    notes = ans.notes
    if question == "min-contact" and (ans.value is None or ans.interval_kind == "table-cell"):
        from ..rig import from_model_contact, model_start_s  # the route's note counts as the model does: from the onset

        start = model_start_s(sen)
        at = [f"{max(from_model_contact(float(t), start), 0.0):.3g}" for t in
              ((own.axes["contact_s"][-1],) if ans.value is None else ans.interval)]
        notes = ((f"no tabulated contact time up to {at[0]} s after the rig's detected onset separates them (--exact "
                  "examines up to 10 s)",) if ans.value is None else
                 (f"the shortest contact lies in ({at[0]}, {at[1]}] s after the rig's detected onset, a cell of the "
                  "table's contact grid: no interval of stated coverage there (--exact estimates one)",))
    return dataclasses.replace(ans, notes=(*notes, f"from the table built for sensor {sen.name} (designkit "
                                           "tables build); its model has no closed-form ideal observer: --exact "
                                           "estimates the bound by Monte Carlo"))


@contextmanager
def _exact_display(question: str, progress: bool):
    """What the exact route shows while it runs: a bar of SVM evaluations for a question that reports its
    steps (yields the callback to pass as ``progress``), a spinner for one that does not, nothing when quiet
    or where stderr is no terminal (rich's bar then left a blank line before the answer's error, if any)."""
    if not progress or not (hasattr(sys.stderr, "isatty") and sys.stderr.isatty()):
        yield None
        return
    if question not in _STEPWISE:  # no step-by-step progress from this question's exact route: a spinner
        with _app.busy(f"{question}: simulating touches and fitting SVMs (exact route)"):
            yield None
        return
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                  TimeElapsedColumn(), console=Console(stderr=True), transient=True) as bar:
        task = bar.add_task("SVM evaluations", total=None)

        def report(done, total, message):
            bar.update(task, completed=done, total=total, description=f"SVM evaluations ({message})")

        yield report


def _noted(ans, reroute: Optional[str], sen, fm, source: str):
    """The answer with a note saying why it was computed rather than read, and where its model came from."""
    import dataclasses

    notes = list(ans.notes)
    if reroute:
        notes.append(reroute)
    if source == "sensor file":
        from ..models import sensor_model_notes

        notes.extend(sensor_model_notes(sen, fm))
    return dataclasses.replace(ans, notes=tuple(notes)) if notes != list(ans.notes) else ans


# ============================================================ rendering
# The answer first: the value with its interval and the ideal bound (lines 1-2), the scene, sensor and
# source (line 3), at most one warning that changes how far to trust it (line 4). The rest (the method, the
# hardest pair, the paper's remark, the notes, the materials rule) with --explain, and always in --json.
def _fmt(x, unit="") -> str:
    from .._numbers import sig

    return sig(x, unit.strip())


def _render(ans, json_: bool, explain: bool = False) -> None:
    d = ans.to_dict()
    if json_:
        emit_json(d)
    else:
        _render_text(d, explain)
    if d["value"] is None and (d["question"] != "delta-e" or not all(d["in_grid"].values())):
        raise typer.Exit(EXIT_NO_ANSWER)


def _render_text(d, explain: bool = False) -> None:
    con = _app.text_console()
    _VALUE_LINES[d["question"]](con, d)
    con.print(f"[dim]{_scene_line(d)}[/]")
    warning = _warning(d)
    if explain:
        _explain_lines(con, d)
    elif warning:
        con.print(f"[yellow]{warning}[/]")


def _scene_line(d) -> str:
    """Line 3: the objects, the scene, the sensor (and model) and where the answer came from."""
    from rich.markup import escape

    sc = d["scene"]
    scene = [f"{w} {_fmt(sc[k], u)}" for k, w, u in (("noise_c", "noise", "°C"), ("delta_t_c", "dT", "°C"),
                                                   ("contact_s", "contact", "s")) if sc.get(k) is not None]
    names = " vs ".join(o["material"] or f"{o['effusivity_range'][0]:g}" for o in d["objects"])
    if d["question"] == "delta-e":
        names = f"e {names}"
    model = "" if d["model"]["name"] == "semi-infinite" else f", model {d['model']['name']}"  # --explain: its parameters
    source = (f"table {d['table']['name']}" if d["route"] == "table"
              else f"computed in {d['computation']['wall_s']:.1f} s")
    return escape(f"{names}, {', '.join(scene)}, F1 ≥ {d['threshold']:g}, {d['sensor']['name']} sensor{model}; "
                  f"{source}")


def _warning(d) -> str | None:
    """Line 4, when the answer needs a caveat: why there is none, or where the table was left."""
    from rich.markup import escape

    if d["value"] is None and d["notes"]:
        return escape(d["notes"][0])
    if d["question"] == "delta-e" and any(d["details"][k][w] is None for k in ("lower", "upper")
                                          for w in ("value", "ideal")):
        return "— : no distinguishable effusivity in that direction within the range examined"
    if d["route"] == "table":
        words = {"noise_ratio": "sigma/dT", "contact_s": "contact time", "noise_c": "noise",
                 "delta_t_c": "temperature difference"}
        bad = [words.get(k, k) for k, ok in d["in_grid"].items() if not ok]
        if bad:
            return f"outside the table's grid along {', '.join(bad)}: --explain says more, --exact computes it"
        if d["computation"].get("below_grid"):
            return "below the table's shortest contact time: extrapolated (--explain says more)"
    chk = d["model_check"]
    if chk and chk.get("message") and not chk.get("holds"):
        return escape(chk["message"])
    return None


def _model_words(d: dict) -> str:
    from ..models import get_model

    return get_model(d["model"]).describe()


def _interval(d, unit):
    iv = d["interval"]
    if iv["low"] is None and iv["high"] is None:
        return "(no interval: --explain)"
    ends = f"{_fmt(iv['low'])} to {_fmt(iv['high'], unit)}"
    if iv.get("coverage"):
        return f"({iv['coverage']:.0%} interval {ends})"
    why = {"table-cell": "grid cell", "exact": "search bracket", "table-varied": "varied table"}
    return f"({why.get(iv.get('method'), 'interval')} {ends}, coverage not stated)"


def _answerer(d) -> str:
    """Whose answer line 1 gives: the paper's SVM, or the ideal observer where the table holds that."""
    if (d.get("computation") or {}).get("fidelity") == "ideal":
        from rich.markup import escape

        return f"ideal observer on table {escape(d['table']['name'])}'s grid"
    return "SVM"


def _scalar(words: str, unit: str):
    def line(con, d):
        if d["value"] is None:
            con.print(f"{words}: [red]no answer[/] ({_answerer(d)})")
        else:
            qual = {"at-most": "at most ", "at-least": "at least "}.get(d.get("bound") or "", "")  # Answer.bound
            iv = "(a bound: the table's grid ends there)" if qual else _interval(d, unit)
            con.print(f"{words}: {qual}[bold green]{_fmt(d['value'], unit)}[/] {iv}, {_answerer(d)}")
        ideal = d["ideal"]
        iv = ideal.get("interval")
        ends = f", {iv['coverage']:.0%} interval {_fmt(iv['low'])} to {_fmt(iv['high'], unit)}" if iv else ""
        con.print(f"ideal observer bound: {_fmt(ideal['value'], unit)}"
                  + (f" ({ideal['method']}{ends}; no classifier does better)" if ideal["value"] is not None else ""))
    return line


def _delta_lines(con, d):
    x = d["details"]
    who = _answerer(d)
    for words, side in (("delta(e) towards lower e ", "lower"), ("delta(e) towards higher e", "upper")):
        s = x[side]
        iv = s["interval"]
        cov = f"{iv['coverage']:.0%} interval" if iv.get("coverage") else "interval, coverage not stated"
        shown = s["value"] is not None and (iv["low"], iv["high"]) != (None, None)  # an ideal table's has no ends
        ivs = f" ({cov} {_fmt(iv['low'])} to {_fmt(iv['high'])})" if shown else ""
        con.print(f"{words}: [bold green]{_fmt(s['value'])}[/]{ivs} {who}, ideal bound {_fmt(s['ideal']['value'])}")


def _distinguishable_lines(con, d):
    x = d["details"]
    if x["distinguishable"] is None:
        con.print("distinguishable: [yellow]no answer[/]")
    else:
        yes = "[bold green]yes[/]" if x["distinguishable"] else "[bold red]no[/]"
        iv = d["interval"]
        f1 = (f", F1 {x['svm_f1']:.3f} ({iv['coverage']:.0%} interval {iv['low']:.3f} to {iv['high']:.3f})"
              if x["svm_f1"] is not None else "")
        verdict = f"; {x['verdict']}" if x.get("verdict") else ""
        con.print(f"distinguishable: {yes}{f1} ({_answerer(d)}{verdict})")
    if x["ideal_f1"] is not None:  # also where the table has no answer: the closed form needs no table
        con.print(f"ideal observer bound: F1 {x['ideal_f1']:.3f} ({d['ideal']['method']})"
                  + (", distinguishable" if x["ideal_distinguishable"] else ", not even in principle"))
    else:
        con.print("ideal observer bound: —")


_VALUE_LINES = {
    "min-contact": _scalar("shortest contact", " s"),
    "max-noise": _scalar("largest noise", " °C"),
    "min-delta-t": _scalar("smallest temperature difference", " °C"),
    "delta-e": _delta_lines,
    "distinguishable": _distinguishable_lines,
}


def _explain_lines(con, d):
    """--explain: the objects with their units, the hardest pair, the paper's remark, the method, every note."""
    con.print("objects [J s^-1/2 K^-1 m^-2]: " + " vs ".join(f"[bold]{o['label']}[/]" for o in d["objects"]))
    if d["model"]["name"] != "semi-infinite":
        from rich.markup import escape

        con.print(f"model: {escape(_model_words(d))}")
    if d["limiting_pair"] and any(o["material"] for o in d["objects"]) and d["question"] != "delta-e":
        con.print("answered for the hardest pair: " + " vs ".join(o["label"] for o in d["limiting_pair"]))
    if d["question"] == "delta-e":
        sides = [d["details"][k] for k in ("lower", "upper")]
        if any(s["value"] is None or s["ideal"] is None for s in sides):
            outside = d["route"] == "table" and not all(d["in_grid"].values())
            con.print("— : " + ("no answer from the table, or " if outside else "")
                      + "no distinguishable effusivity in that direction within the range examined")
    if d["question"] == "min-contact":
        from ..query.guideline import guideline_remark

        remark = guideline_remark(d)
        if remark:
            con.print(remark)
    if d["route"] == "table":
        words = {"noise_ratio": "sigma/dT", "contact_s": "contact time", "noise_c": "noise",
                 "delta_t_c": "temperature difference"}
        bad = [words.get(k, k) for k, ok in d["in_grid"].items() if not ok]
        where = "inside its grid" if not bad else "OUTSIDE its grid along " + ", ".join(bad)
        if not bad and d["computation"].get("below_grid"):
            where = "below its contact times: extrapolated"
        eff = "the SVM's tabulated efficiency applied to the exact ideal observer between grid points"
        how = {"table-efficiency": eff,
               "table-varied-estimate": "each noise slice's estimate around the question, interpolated in log time"
               }.get(d["interval"].get("method"), "interpolated")
        if d["question"] == "distinguishable":  # the verdict is the contact against min-contact's answer
            how = "the contact against min-contact's answer" + (
                f" ({eff})" if (d["computation"].get("min_contact_interval") or {}).get("method") == "table-efficiency" else "")
        con.print(f"method: from table {d['table']['name']} ({where}), {how}; --exact computes it for this pair")
    else:
        c = d["computation"]
        varied = (f", sensor temperature varied per touch by ±{c['sensor_temp_spread_c']:g} °C"
                  if c.get("sensor_temp_spread_c") else "")
        con.print(f"method: computed for this pair ({c['repeats']} seeds x {c['trials']} trials per class"
                  f"{varied}, {c['wall_s']:.1f} s)")
    for n in d["notes"]:
        con.print(f"note: {n}", markup=False)
    chk = d["model_check"]
    if chk and chk.get("message"):
        con.print(f"{'' if chk['holds'] else '[yellow]'}model check: {chk['message']}{'' if chk['holds'] else '[/]'}")
    if any(o["material"] for o in d["objects"]):
        con.print(d["materials_rule"], markup=False)


# ============================================================ the commands
@app.command("min-contact", rich_help_panel=_app.ASK)
def min_contact_cmd(
    e1: E1 = None, e2: E2 = None, m1: M1 = None, m2: M2 = None,
    noise: NoiseQ = None, delta_t: DeltaTQ = None, threshold: Threshold = 0.9, sensor: SensorOpt = "paper",
    model: ModelOpt = None, conductance: Conductance = None, thickness: Thickness = None,
    backing: BackingOpt = None, diffusivity: Diffusivity = None,
    exact: Exact = False, table: TableOpt = None, ideal_table: IdealTableOpt = "ideal-paper",
    trials: TrialsQ = 100, repeats: RepeatsQ = 4, seed: SeedQ = 0, width: WidthQ = 80.0, jobs: JobsQ = -1,
    n_mc: NmcQ = 1000, max_contact: MaxContact = 10.0, coverage: CoverageOpt = 0.9,
    sensor_temp_spread: SpreadOpt = None, json_: Json = False,
    explain: Explain = False,
) -> None:
    """Shortest contact time that separates two materials.

    Example: `designkit min-contact --e1 35000 --e2 20000`

    Example (materials by name, the method too): `designkit min-contact --m1 wood --m2 glass --explain`
    """
    ans = _ask("min-contact", exact=exact, table=table, ideal_table=ideal_table, threshold=threshold, sensor=sensor,
               model=model, conductance=conductance, thickness=thickness, backing=backing, diffusivity=diffusivity,
               width=width, trials=trials, repeats=repeats, seed=seed, jobs=jobs, n_mc=n_mc,
               objects=dict(e1=e1, e2=e2, m1=m1, m2=m2), scene=dict(noise_c=noise, delta_t_c=delta_t),
               exact_extra=dict(max_contact_s=max_contact), coverage=coverage, progress=not json_,
               spread=sensor_temp_spread)
    _render(ans, json_, explain)


@app.command("max-noise", rich_help_panel=_app.ASK)
def max_noise_cmd(
    e1: E1 = None, e2: E2 = None, m1: M1 = None, m2: M2 = None,
    contact: Contact = 2.0, delta_t: DeltaTQ = None, threshold: Threshold = 0.9, sensor: SensorOpt = "paper",
    model: ModelOpt = None, conductance: Conductance = None, thickness: Thickness = None,
    backing: BackingOpt = None, diffusivity: Diffusivity = None,
    exact: Exact = False, table: TableOpt = None, ideal_table: IdealTableOpt = "ideal-paper",
    trials: TrialsQ = 100, repeats: RepeatsQ = 4, seed: SeedQ = 0, width: WidthQ = 80.0, jobs: JobsQ = -1,
    n_mc: NmcQ = 1000, coverage: CoverageOpt = 0.9, sensor_temp_spread: SpreadOpt = None, json_: Json = False,
    explain: Explain = False,
) -> None:
    """Largest sensor noise at which a contact time still separates two materials.

    Example: `designkit max-noise --e1 35000 --e2 20000 --contact 2`
    """
    ans = _ask("max-noise", exact=exact, table=table, ideal_table=ideal_table, threshold=threshold, sensor=sensor,
               model=model, conductance=conductance, thickness=thickness, backing=backing, diffusivity=diffusivity,
               width=width, trials=trials, repeats=repeats, seed=seed, jobs=jobs, n_mc=n_mc,
               objects=dict(e1=e1, e2=e2, m1=m1, m2=m2),
               scene=dict(contact_s=contact, delta_t_c=delta_t), coverage=coverage, progress=not json_,
               spread=sensor_temp_spread)
    _render(ans, json_, explain)


@app.command("min-delta-t", rich_help_panel=_app.ASK)
def min_delta_t_cmd(
    e1: E1 = None, e2: E2 = None, m1: M1 = None, m2: M2 = None,
    contact: Contact = 2.0, noise: NoiseQ = None, threshold: Threshold = 0.9, sensor: SensorOpt = "paper",
    model: ModelOpt = None, conductance: Conductance = None, thickness: Thickness = None,
    backing: BackingOpt = None, diffusivity: Diffusivity = None,
    exact: Exact = False, table: TableOpt = None, ideal_table: IdealTableOpt = "ideal-paper",
    trials: TrialsQ = 100, repeats: RepeatsQ = 4, seed: SeedQ = 0, width: WidthQ = 80.0, jobs: JobsQ = -1,
    n_mc: NmcQ = 1000, coverage: CoverageOpt = 0.9, sensor_temp_spread: SpreadOpt = None, json_: Json = False,
    explain: Explain = False,
) -> None:
    """Smallest sensor-object temperature difference that separates two materials.

    Example: `designkit min-delta-t --e1 35000 --e2 20000 --contact 2 --noise 0.05`
    """
    ans = _ask("min-delta-t", exact=exact, table=table, ideal_table=ideal_table, threshold=threshold, sensor=sensor,
               model=model, conductance=conductance, thickness=thickness, backing=backing, diffusivity=diffusivity,
               width=width, trials=trials, repeats=repeats, seed=seed, jobs=jobs, n_mc=n_mc,
               objects=dict(e1=e1, e2=e2, m1=m1, m2=m2),
               scene=dict(contact_s=contact, noise_c=noise), coverage=coverage, progress=not json_,
               spread=sensor_temp_spread)
    _render(ans, json_, explain)


@app.command("delta-e", rich_help_panel=_app.ASK)
def delta_e_cmd(
    e: Annotated[Optional[float], typer.Option("--e", help="Reference effusivity [J s^-1/2 K^-1 m^-2].",
                                               rich_help_panel=PANEL_QUESTION)] = None,
    m: Annotated[Optional[str], typer.Option("--m", help="Reference material (its range's middle).",
                                             rich_help_panel=PANEL_QUESTION)] = None,
    contact: Contact = 2.0, noise: NoiseQ = None, delta_t: DeltaTQ = None, threshold: Threshold = 0.9,
    sensor: SensorOpt = "paper",
    model: ModelOpt = None, conductance: Conductance = None, thickness: Thickness = None,
    backing: BackingOpt = None, diffusivity: Diffusivity = None,
    exact: Exact = False, table: TableOpt = None, ideal_table: IdealTableOpt = "ideal-paper",
    trials: TrialsQ = 100, repeats: RepeatsQ = 4, seed: SeedQ = 0, width: WidthQ = 80.0, jobs: JobsQ = -1,
    n_mc: NmcQ = 1000, coverage: CoverageOpt = 0.9, sensor_temp_spread: SpreadOpt = None,
    format_: Annotated[Optional[str], typer.Option(
        "--format", "-f", help="Print the two directions as rows: table, json, csv or md (default: the answer "
                               "for people; --json: the whole answer).", rich_help_panel=PANEL_OUTPUT)] = None,
    out: Annotated[Optional[str], typer.Option("--out", "-o", help="Write the output to this file ('-' or none: "
                                               "stdout).", rich_help_panel=PANEL_OUTPUT)] = None,
    json_: Json = False, explain: Explain = False,
) -> None:
    """Smallest distinguishable effusivity difference delta(e), towards lower and higher effusivity.

    Example: `designkit delta-e --e 20000 --contact 2`

    Example (one row per direction): `designkit delta-e --e 20000 --contact 2 --format csv`
    """
    fmt = None if json_ or format_ is None else check_format(format_)
    if out not in (None, "-"):
        check_out(out)  # before the work: an --exact answer is not computed for a folder that does not exist
    ans = _ask("delta-e", exact=exact, table=table, ideal_table=ideal_table, threshold=threshold, sensor=sensor,
               model=model, conductance=conductance, thickness=thickness, backing=backing, diffusivity=diffusivity,
               width=width, trials=trials, repeats=repeats, seed=seed, jobs=jobs, n_mc=n_mc,
               objects=dict(e=e, m=m), scene=dict(contact_s=contact, noise_c=noise, delta_t_c=delta_t),
               coverage=coverage, progress=not json_, spread=sensor_temp_spread)
    if fmt is not None:
        d = ans.to_dict()  # rows: each direction as a record (docs/schema.md); json: the answer, as --json
        x = d["details"]
        rows = [{"direction": side, "effusivity": x["effusivity"], "delta_e": x[side]["value"],
                 "interval_low": x[side]["interval"]["low"], "interval_high": x[side]["interval"]["high"],
                 "ideal_value": x[side]["ideal"]["value"], "unit": d["unit"], "route": d["route"],
                 "table_name": (d["table"] or {}).get("name")}
                for side in ("lower", "upper")]
        emit_rows(rows, list(rows[0]), fmt=fmt, out=out, title=f"delta(e) at {x['effusivity']:g}", payload=d)
        return
    with output_to(out):
        _render(ans, json_, explain)


@app.command("distinguishable", rich_help_panel=_app.ASK)
def distinguishable_cmd(
    e1: E1 = None, e2: E2 = None, m1: M1 = None, m2: M2 = None,
    contact: Contact = 2.0, noise: NoiseQ = None, delta_t: DeltaTQ = None, threshold: Threshold = 0.9,
    sensor: SensorOpt = "paper",
    model: ModelOpt = None, conductance: Conductance = None, thickness: Thickness = None,
    backing: BackingOpt = None, diffusivity: Diffusivity = None,
    exact: Exact = False, table: TableOpt = None, ideal_table: IdealTableOpt = "ideal-paper",
    trials: TrialsQ = 100, repeats: RepeatsQ = 4, seed: SeedQ = 0, width: WidthQ = 80.0, jobs: JobsQ = -1,
    n_mc: NmcQ = 1000, coverage: CoverageOpt = 0.9, sensor_temp_spread: SpreadOpt = None, json_: Json = False,
    explain: Explain = False,
) -> None:
    """Whether a scene separates two materials, with the SVM's and the ideal observer's F1.

    Example: `designkit distinguishable --m1 wood --m2 glass --contact 2`
    """
    ans = _ask("distinguishable", exact=exact, table=table, ideal_table=ideal_table, threshold=threshold,
               sensor=sensor, model=model, conductance=conductance, thickness=thickness, backing=backing,
               diffusivity=diffusivity, width=width, trials=trials, repeats=repeats, seed=seed, jobs=jobs,
               n_mc=n_mc, objects=dict(e1=e1, e2=e2, m1=m1, m2=m2),
               scene=dict(contact_s=contact, noise_c=noise, delta_t_c=delta_t), coverage=coverage,
               progress=not json_, spread=sensor_temp_spread)
    _render(ans, json_, explain)
