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
from ._app import app
from ._format import FormatOpt, OutOpt, emit, output_format
from ._options import (
    E1,
    E2,
    M1,
    M2,
    PANEL_QUESTION,
    BackingOpt,
    BatchOpt,
    Conductance,
    Contact,
    CoverageOpt,
    DeltaTQ,
    Diffusivity,
    Exact,
    Explain,
    IdealTableOpt,
    JobsQ,
    Json,
    MaxContact,
    ModelOpt,
    NmcQ,
    NoiseQ,
    RepeatsQ,
    SeedQ,
    SensorOpt,
    SpreadOpt,
    TableOpt,
    Thickness,
    Threshold,
    TrialsQ,
    WidthQ,
    sensor_and_model,
)

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
    from .._validation import InputError
    from ..query.inputs import NeedsInput, TableMismatch
    from ..query.policy import OutsideSensorTable

    try:
        yield
    except OutsideSensorTable as exc:
        raise InputError(f"{exc.where}: ask with --exact (computed, tens of seconds)" + (
            ", or build a table over a wider span with 'designkit tables build --sensor FILE --e-range LO HI'"
            if exc.wider else "")) from None
    except TableMismatch as exc:
        raise TableMismatch(f"{exc} (use --exact, or a table built for it with designkit sweep)") from None
    except NeedsInput as exc:
        hint = _HINTS.get(exc.what)
        raise NeedsInput(f"{exc} ({hint})" if hint else str(exc), exc.what) from None


def _ask(question: str, *, exact: bool, table: Optional[str], ideal_table: str, threshold: float, sensor: str,
         model, conductance, thickness, backing, diffusivity, width: float, trials: int, repeats: int, seed: int,
         jobs: int, n_mc: int, objects: dict, scene: dict, exact_extra: Optional[dict] = None,
         progress: bool = False, coverage: float = 0.9, spread: Optional[float] = None):
    """The one library call of a command: the options parsed, passed as given (a scene value not given is None:
    the library takes the sensor file's rig conditions, else the defaults, and says where each came from)."""
    from .. import query
    from ..query.crossing import check_coverage

    from .._validation import MAX_EFFUSIVITY, InputError, check_positive

    if check_positive("--width", width) > MAX_EFFUSIVITY:  # on either route (the table's is its own): 1e308 was taken
        raise InputError(f"--width must be at most {MAX_EFFUSIVITY:g} J s^-1/2 K^-1 m^-2, got {width:g}")
    extra = dict(exact_extra or {})
    extra["coverage"] = check_coverage(coverage)  # bad input before any work, on either route

    with _hints():
        if spread is not None and (spread < 0 or spread != spread):
            raise InputError(f"sensor temperature spread must be >= 0 degC, got {spread:g}")
        sen, fm, source = sensor_and_model(sensor, model, conductance=conductance, thickness=thickness,
                                           backing=backing)
        if scene.get("contact_s") is not None:  # a touch the sensor can take, on either route (1e308 s was
            from ..sensor import check_samples_per_touch  # answered "outside the table")

            check_samples_per_touch(check_positive("--contact [s]", scene["contact_s"]), sen.sample_rate_hz,
                                    "--contact", "give a contact time a touch can last")
        # the library chooses the route (designkit.query.policy): a table built for this sensor, model and
        # scene, or named, else computed for the pair; the answer's route_reason says why
        kw = dict(objects, **scene, threshold=threshold, sensor=sen, model=fm, table=table, ideal_table=ideal_table,
                  diffusivity_m2_s=diffusivity, width=width, trials=trials, repeats=repeats, seed=seed, jobs=jobs,
                  n_mc=n_mc, sensor_temp_spread_c=spread, **extra)
        route = "exact" if exact else "auto"
        from ..query.policy import choose_route

        with _exact_display(question, progress and choose_route(question, route, kw)[0] == "exact") as report:
            if report is not None:
                kw["progress"] = report
            return _noted(query.ask(question, route=route, **kw), sen, fm, source)


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


def _noted(ans, sen, fm, source: str):
    """A computed answer with a note saying where its model came from (a sensor file's own)."""
    import dataclasses

    notes = list(ans.notes)
    if source == "sensor file" and ans.route == "exact":
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


def _render(ans, fmt: str = "text", out: Optional[str] = None, explain: bool = False) -> None:
    """Print the answer in ``fmt``: the text for people, ``to_dict()`` (json), or its record (csv, ndjson,
    table, md: one row, docs/schema.md "Records"; delta-e: one row per direction). Exit 3 if there is none."""
    d = ans.to_dict()
    emit(fmt, out, payload=d, records=lambda: _records(d), text=lambda: _render_text(d, explain),
         title=f"{d['question']}")
    if d["value"] is None and (d["question"] != "delta-e" or not all(d["in_grid"].values())):
        raise typer.Exit(EXIT_NO_ANSWER)


def _records(d: dict) -> list[dict]:
    """An answer's rows: its record (:func:`designkit.query.answer.to_record`); delta-e's, one per direction."""
    if d["question"] != "delta-e":
        from ..query.answer import to_record

        return [to_record(d)]
    x = d["details"]
    return [{"direction": side, "effusivity": x["effusivity"], "delta_e": x[side]["value"],
             "interval_low": x[side]["interval"]["low"], "interval_high": x[side]["interval"]["high"],
             "ideal_value": x[side]["ideal"]["value"], "unit": d["unit"], "route": d["route"],
             "table_name": (d["table"] or {}).get("name")} for side in ("lower", "upper")]


def _batch(question: str, path: str, fmt: str, out: Optional[str], *, objects: dict, scene: dict, exact: bool,
           table, ideal_table, threshold, coverage, sensor, spread, exact_options: dict) -> None:
    """``--batch FILE``: every row answered by one array call of the library (:mod:`designkit.io_batch`), one
    record per row out; the options give the columns the file leaves out."""
    from ..io_batch import MAX_BATCH_ROWS, MAX_BATCH_ROWS_EXACT, answer_batch, read_batch
    from ..query.crossing import check_coverage

    with _hints():
        sen, fm, _ = sensor_and_model(sensor, exact_options["model"], conductance=exact_options["conductance"],
                                      thickness=exact_options["thickness"], backing=exact_options["backing"])
    batch = read_batch(path, question, max_rows=MAX_BATCH_ROWS_EXACT if exact else MAX_BATCH_ROWS)
    # a scene value neither in the file nor given: the library's (the sensor file's rig conditions, else the
    # defaults, each with its source); an empty cell of a column the file has: the same value
    from ..query import QUESTIONS
    from ..rig import DEFAULTS, rig_arguments

    empty = [k for k, v in scene.items() if v is None and k in batch.columns]
    resolved = rig_arguments(QUESTIONS[question].scene, {**scene, "sensor": sen})[0] if empty else {}
    defaults = {**{k: v for k, v in objects.items() if v is not None}, **scene,
                **{k: resolved.get(k, DEFAULTS.get(k)) for k in empty}}
    options = dict(threshold=threshold, coverage=check_coverage(coverage), sensor=sen, model=fm,
                   **{k: v for k, v in exact_options.items() if k not in _MODEL_KEYS})
    if spread:
        options["sensor_temp_spread_c"] = spread
    if exact_options["diffusivity"] is not None:
        options["diffusivity_m2_s"] = exact_options["diffusivity"]
    if not exact:
        options.update(ideal_table=ideal_table, **({"table": table} if table else {}))
    with _hints():
        records = answer_batch(batch, defaults, route="exact" if exact else "auto", **options)
    payload = records  # json: the records (an array answer's to_dict, with each row's inputs)
    emit(fmt, out, payload=payload, records=records, title=f"{question}: {len(records)} rows")


#: Options of the sensor's forward model (--batch: sensor_and_model reads them).
_MODEL_KEYS = ("model", "conductance", "thickness", "backing", "diffusivity")


def _render_text(d, explain: bool = False) -> None:
    con = _app.text_console()
    _VALUE_LINES[d["question"]](con, d)
    con.print((_scene_line(d), "dim"))
    warning = _warning(d)
    if explain:
        _explain_lines(con, d)
    elif warning:
        con.print((warning, "yellow"))


def _scene_line(d) -> str:
    """Line 3: the objects, the scene, the sensor (and model) and where the answer came from."""
    sc = d["scene"]
    scene = [f"{w} {_fmt(sc[k], u)}" for k, w, u in (("noise_c", "noise", "°C"), ("delta_t_c", "dT", "°C"),
                                                   ("contact_s", "contact", "s")) if sc.get(k) is not None]
    names = " vs ".join(o["material"] or f"{o['effusivity_range'][0]:g}" for o in d["objects"])
    if d["question"] == "delta-e":
        names = f"e {names}"
    model = "" if d["model"]["name"] == "semi-infinite" else f", model {d['model']['name']}"  # --explain: its parameters
    source = (f"table {d['table']['name']}" if d["route"] == "table"
              else f"computed in {d['computation']['wall_s']:.1f} s")
    return f"{names}, {', '.join(scene)}, F1 ≥ {d['threshold']:g}, {d['sensor']['name']} sensor{model}; {source}"


def _warning(d) -> str | None:
    """Line 4, when the answer needs a caveat: why there is none, or where the table was left."""
    if d["value"] is None and d["notes"]:
        return d["notes"][0]
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
        return chk["message"]
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
        return f"ideal observer on table {d['table']['name']}'s grid"
    return "SVM"


def _scalar(words: str, unit: str):
    def line(con, d):
        if d["value"] is None:
            con.print(f"{words}: ", ("no answer", "red"), f" ({_answerer(d)})")
        else:
            qual = {"at-most": "at most ", "at-least": "at least "}.get(d.get("bound") or "", "")  # Answer.bound
            iv = "(a bound: the table's grid ends there)" if qual else _interval(d, unit)
            con.print(f"{words}: {qual}", (_fmt(d["value"], unit), "bold green"), f" {iv}, {_answerer(d)}")
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
        con.print(f"{words}: ", (_fmt(s["value"]), "bold green"), f"{ivs} {who}, ideal bound {_fmt(s['ideal']['value'])}")


def _distinguishable_lines(con, d):
    x = d["details"]
    if x["distinguishable"] is None:
        con.print("distinguishable: ", ("no answer", "yellow"))
    else:
        yes = ("yes", "bold green") if x["distinguishable"] else ("no", "bold red")
        iv = d["interval"]
        f1 = (f", F1 {x['svm_f1']:.3f} ({iv['coverage']:.0%} interval {iv['low']:.3f} to {iv['high']:.3f})"
              if x["svm_f1"] is not None else "")
        verdict = f"; {x['verdict']}" if x.get("verdict") else ""
        con.print("distinguishable: ", yes, f"{f1} ({_answerer(d)}{verdict})")
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
    labels = [part for o in d["objects"] for part in (" vs ", (o["label"], "bold"))][1:]
    con.print("objects [J s^-1/2 K^-1 m^-2]: ", *labels)
    if d["model"]["name"] != "semi-infinite":
        con.print(f"model: {_model_words(d)}")
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
    if d.get("route_reason") and d["route_reason"] not in d["notes"]:
        con.print(f"route ({d['route']}): {d['route_reason']}")
    for n in d["notes"]:
        con.print(f"note: {n}")
    chk = d["model_check"]
    if chk and chk.get("message"):
        con.print((f"model check: {chk['message']}", "" if chk["holds"] else "yellow"))
    if any(o["material"] for o in d["objects"]):
        con.print(d["materials_rule"])


# ============================================================ the commands
# One command per question, built from one list of options: the objects and scene of its question (the
# library's registry, designkit.query.QUESTIONS, names the same scene), then the options every question
# shares. Each command: one library call (_ask, or --batch: one array call), the answer rendered in
# --format (text for people by default; --json is --format json).
E = Annotated[Optional[float], typer.Option("--e", help="Reference effusivity [J s^-1/2 K^-1 m^-2].",
                                            rich_help_panel=PANEL_QUESTION)]
M = Annotated[Optional[str], typer.Option("--m", help="Reference material (its range's middle).",
                                          rich_help_panel=PANEL_QUESTION)]
#: A question's objects and scene quantities as (argument, option type, default); the scene is keyed by
#: the library's name (QUESTIONS[q].scene) of the quantity.
_OBJECT_OPTIONS = {"e1": (E1, None), "e2": (E2, None), "m1": (M1, None), "m2": (M2, None), "e": (E, None),
                   "m": (M, None)}
_SCENE_OPTIONS = {"contact_s": ("contact", Contact, 2.0), "noise_c": ("noise", NoiseQ, None),
                  "delta_t_c": ("delta_t", DeltaTQ, None)}
_SHARED_OPTIONS = (
    ("threshold", Threshold, 0.9), ("sensor", SensorOpt, "paper"), ("model", ModelOpt, None),
    ("conductance", Conductance, None), ("thickness", Thickness, None), ("backing", BackingOpt, None),
    ("diffusivity", Diffusivity, None), ("exact", Exact, False), ("table", TableOpt, None),
    ("ideal_table", IdealTableOpt, "ideal-paper"), ("trials", TrialsQ, 100), ("repeats", RepeatsQ, 4),
    ("seed", SeedQ, 0), ("width", WidthQ, 80.0), ("jobs", JobsQ, -1), ("n_mc", NmcQ, 1000))
_OUTPUT_OPTIONS = (
    ("coverage", CoverageOpt, 0.9), ("sensor_temp_spread", SpreadOpt, None), ("batch", BatchOpt, None),
    ("format_", FormatOpt, None), ("out", OutOpt, None), ("json_", Json, False), ("explain", Explain, False))
#: question -> (its objects, its scene: as QUESTIONS[question].scene, its --exact-only options, its help).
_COMMANDS = {
    "min-contact": (("e1", "e2", "m1", "m2"), ("noise_c", "delta_t_c"), (("max_contact", MaxContact, 10.0),),
                    """Shortest contact time that separates two materials.

    Example: `designkit min-contact --e1 35000 --e2 20000`

    Example (materials by name, the method too): `designkit min-contact --m1 wood --m2 glass --explain`

    Example (one record, pandas-ready): `designkit min-contact --e1 35000 --e2 20000 --format csv`
    """),
    "max-noise": (("e1", "e2", "m1", "m2"), ("contact_s", "delta_t_c"), (),
                  """Largest sensor noise at which a contact time still separates two materials.

    Example: `designkit max-noise --e1 35000 --e2 20000 --contact 2`
    """),
    "min-delta-t": (("e1", "e2", "m1", "m2"), ("contact_s", "noise_c"), (),
                    """Smallest sensor-object temperature difference that separates two materials.

    Example: `designkit min-delta-t --e1 35000 --e2 20000 --contact 2 --noise 0.05`
    """),
    "delta-e": (("e", "m"), ("contact_s", "noise_c", "delta_t_c"), (),
                """Smallest distinguishable effusivity difference delta(e), towards lower and higher effusivity.

    Example: `designkit delta-e --e 20000 --contact 2`

    Example (one row per direction): `designkit delta-e --e 20000 --contact 2 --format csv`
    """),
    "distinguishable": (("e1", "e2", "m1", "m2"), ("contact_s", "noise_c", "delta_t_c"), (),
                        """Whether a scene separates two materials, with the SVM's and the ideal observer's F1.

    Example: `designkit distinguishable --m1 wood --m2 glass --contact 2`
    """),
}


def _question_command(question: str, objects: tuple, scene: tuple, exact_only: tuple, doc: str) -> None:
    """Register ``designkit QUESTION``: its options in help order (objects, scene, shared, its own --exact
    ones, output), its one call."""
    import inspect

    options = ([(name, *_OBJECT_OPTIONS[name]) for name in objects] + [_SCENE_OPTIONS[k] for k in scene]
               + list(_SHARED_OPTIONS) + list(exact_only) + list(_OUTPUT_OPTIONS))

    def command(**args) -> None:
        fmt = output_format(args["format_"], args["json_"], out=args["out"])  # before the work: --exact is
        opts = dict({k: args[k] for k, _, _ in _SHARED_OPTIONS}, coverage=args["coverage"],  # not computed
                    spread=args["sensor_temp_spread"], objects={k: args[k] for k in objects},  # for nowhere
                    scene={k: args[_SCENE_OPTIONS[k][0]] for k in scene},
                    exact_extra={"max_contact_s": args["max_contact"]} if exact_only else None)
        _answer(question, opts, args["batch"], fmt, args["out"], args["explain"])

    command.__name__ = command.__qualname__ = f"{question.replace('-', '_')}_cmd"
    command.__doc__ = doc
    command.__signature__ = inspect.Signature(
        [inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=default, annotation=kind)
         for name, kind, default in options], return_annotation=None)
    app.command(question, rich_help_panel=_app.ASK)(command)


for _question, _spec in _COMMANDS.items():
    _question_command(_question, *_spec)


def _answer(question: str, kw: dict, batch: Optional[str], fmt: str, out: Optional[str], explain: bool) -> None:
    """One question command's work: ``--batch`` (every row of a file, one array call) or one answer (_ask)."""
    from ._options import refuse_together

    refuse_together(("--exact", kw["exact"]), ("--table", kw["table"]),
                    why="--exact computes the answer for the pair, --table reads it from a table")
    if batch is not None:
        exact_options = {k: kw[k] for k in ("model", "conductance", "thickness", "backing", "diffusivity", "width",
                                            "trials", "repeats", "seed", "jobs", "n_mc")}
        exact_options.update(kw.get("exact_extra") or {})
        _batch(question, batch, fmt, out, objects=kw["objects"], scene=kw["scene"], exact=kw["exact"],
               table=kw["table"], ideal_table=kw["ideal_table"], threshold=kw["threshold"], coverage=kw["coverage"],
               sensor=kw["sensor"], spread=kw["spread"], exact_options=exact_options)
        return
    _render(_ask(question, **kw, progress=fmt != "json"), fmt, out, explain)
