"""Option types shared by commands, so that names, units and help agree everywhere."""

from __future__ import annotations

from typing import Annotated, Optional

import typer

#: Help panels of a command's options (typer's rich_help_panel), in the order a user reads them.
PANEL_QUESTION = "The question"
PANEL_SCENE = "The scene"
PANEL_SENSOR = "The sensor and model"
PANEL_EXACT = "--exact only"
PANEL_OUTPUT = "Output"

Json = Annotated[bool, typer.Option("--json", help="Print the result as JSON on stdout.",
                                    rich_help_panel=PANEL_OUTPUT)]
Explain = Annotated[bool, typer.Option(
    "--explain", "-v", help="Also print how the answer was found: the method, the hardest pair of two materials, "
                            "the paper's remark and every note (--json always has them).",
    rich_help_panel=PANEL_OUTPUT)]
SensorOpt = Annotated[str, typer.Option(
    "--sensor", help="Sensor preset name ('paper') or a sensor YAML file written by calibration; a file's "
                     "recorded model answers unless --model (or --thickness, --conductance) is given.",
    rich_help_panel=PANEL_SENSOR)]
Noise = Annotated[float, typer.Option("--noise", help="Noise sigma per sample [°C].", rich_help_panel=PANEL_SCENE)]
DeltaT = Annotated[float, typer.Option(
    "--delta-t", help="Sensor minus object temperature before contact [°C].", rich_help_panel=PANEL_SCENE)]
Ambient = Annotated[float, typer.Option("--ambient", help="Ambient (object) temperature [°C].",
    rich_help_panel=PANEL_SCENE)]
Contact = Annotated[float, typer.Option("--contact", help="Contact time [s].", rich_help_panel=PANEL_SCENE)]
Seed = Annotated[int, typer.Option("--seed", help="Random seed (same seed, same trials).")]
Threshold = Annotated[float, typer.Option(
    "--threshold", help="F1 at or above which a pair counts as distinguishable (the paper's Phi).",
    rich_help_panel=PANEL_QUESTION)]
E1 = Annotated[Optional[float], typer.Option("--e1", help="Effusivity of the first object [J s^-1/2 K^-1 m^-2].",
    rich_help_panel=PANEL_QUESTION)]
E2 = Annotated[Optional[float], typer.Option("--e2", help="Effusivity of the second object [J s^-1/2 K^-1 m^-2].",
    rich_help_panel=PANEL_QUESTION)]
Width = Annotated[float, typer.Option(
    "--width", help="Width of each effusivity class [e, e+width) [J s^-1/2 K^-1 m^-2] (paper: 80).")]
Trials = Annotated[int, typer.Option("--trials", help="Simulated touches per class.")]
Folds = Annotated[int, typer.Option("--folds", help="Cross-validation folds.")]

# ---------------------------------------------------------------- the questions' options (cli/query.py)
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

BatchOpt = Annotated[Optional[str], typer.Option(
    "--batch", help="Answer every row of this CSV file ('-': stdin) in one call: columns named as the options "
                    "(e1,e2 or m1,m2; e or m for delta-e; noise, delta_t, contact); a column left out, or an empty "
                    "scene cell, takes the option's value. One record per row out (--format csv, ndjson, json, "
                    "table, md; text is the table).", rich_help_panel=PANEL_QUESTION)]

# ---------------------------------------------------------------- objects and forward models (one vocabulary)
M1 = Annotated[Optional[str], typer.Option(
    "--m1", help="First material by name (instead of --e1); see 'designkit materials list'.",
    rich_help_panel=PANEL_QUESTION)]
M2 = Annotated[Optional[str], typer.Option("--m2", help="Second material by name (instead of --e2).",
    rich_help_panel=PANEL_QUESTION)]
ModelOpt = Annotated[Optional[str], typer.Option(
    "--model", help="Forward model: semi-infinite (the paper's, default), slab (a thin object: give --thickness) "
                    "or contact (finite interface conductance: give --conductance), or any registered model with "
                    "its parameters as NAME:KEY=VALUE,... (e.g. contact:conductance_w_m2k=2000); see docs/models.md.",
    rich_help_panel=PANEL_SENSOR)]
Conductance = Annotated[Optional[float], typer.Option(
    "--conductance", help="Sensor-object interface conductance h_c \\[W m^-2 K^-1] (contact model; implies "
                          "--model contact).", rich_help_panel=PANEL_SENSOR)]
Thickness = Annotated[Optional[float], typer.Option(
    "--thickness", help="Object thickness \\[m] (e.g. 0.003 for a 3 mm sheet; slab model; implies --model slab).",
    rich_help_panel=PANEL_SENSOR)]
BackingOpt = Annotated[Optional[str], typer.Option(
    "--backing", help="Slab model: what the object lies on: table (default: a hardwood table top), insulated, "
                      "air, steel, or a material name.", rich_help_panel=PANEL_SENSOR)]
Diffusivity = Annotated[Optional[float], typer.Option(
    "--diffusivity", help="Diffusivity \\[m^2/s] of objects given as numbers (--e1/--e2/--e), for models that "
                          "need it (slab).", rich_help_panel=PANEL_SENSOR)]


def refuse_together(*groups: tuple[str, object], why: str) -> None:
    """The one rule for options that contradict each other: of the ``(flag, value)`` pairs, at most one may be
    given (a value other than None, False or empty); else a one-line InputError naming them and ``why``.

    >>> refuse_together(("--exact", True), ("--table", None), why="x")
    >>> refuse_together(("--exact", True), ("--table", "svm-paper"), why="--exact computes, a table is read")
    Traceback (most recent call last):
    ...
    designkit._validation.InputError: --exact and --table contradict each other: --exact computes, a table is read; give one
    """
    from .._validation import InputError

    given = [flag for flag, value in groups if value is not None and value is not False and value != [] and value != ()]
    if len(given) > 1:
        raise InputError(f"{' and '.join(given)} contradict each other: {why}; give one")


def model_from_options(model: Optional[str], *, conductance: Optional[float] = None,
                       thickness: Optional[float] = None, backing: Optional[str] = None):
    """The forward model the options name (None, None, ... is the paper's semi-infinite model).

    ``--thickness`` implies ``--model slab`` and ``--conductance`` implies
    ``--model contact``; a parameter given with another model is refused.
    """
    from .._validation import InputError
    from ..models import get_model

    from ..models import parse_model_spec

    if model is not None and ":" in model:  # NAME:KEY=VALUE,...: the parameters come with the name
        if conductance is not None or thickness is not None or backing is not None:
            raise InputError("give a model's parameters either in --model NAME:KEY=VALUE or as options, not both")
        return get_model(model)
    implied = {"slab": thickness is not None or backing is not None, "contact": conductance is not None}
    wanted = [name for name, yes in implied.items() if yes]
    if len(wanted) > 1:
        raise InputError("--thickness/--backing (slab model) and --conductance (contact model) "
                         "describe different models: give one")
    name = parse_model_spec(model)[0] if model else (wanted[0] if wanted else "semi-infinite")
    if wanted and wanted[0] != get_model_name(name):
        flag = "--conductance" if wanted[0] == "contact" else "--thickness/--backing"
        raise InputError(f"{flag} belongs to the {wanted[0]} model, not --model {name}")
    params = {}
    if thickness is not None:
        params["thickness_m"] = thickness
    if backing is not None:
        params["backing"] = backing
    if conductance is not None:
        params["conductance_w_m2k"] = conductance
    if get_model_name(name) == "slab" and thickness is None:
        raise InputError("the slab model needs the object's --thickness [m]")
    if get_model_name(name) == "contact" and conductance is None:
        raise InputError("the contact model needs the interface --conductance [W m^-2 K^-1]")
    return get_model(name, **params)


def sensor_and_model(sensor, model: Optional[str] = None, *, conductance: Optional[float] = None,
                     thickness: Optional[float] = None, backing: Optional[str] = None, warn: bool = True):
    """The sensor (preset or file) and the forward model that answers for it, and where the model came from.

    Model options given on the command line (``--model``, ``--thickness``, ``--conductance``) override the
    model a sensor file records; without them the file's model answers (semi-infinite for presets and old
    files). A sensor file that calibration wrote despite problems (``--force``) is named on stderr each time
    it is used (``warn``).

    Returns
    -------
    (Sensor, ForwardModel, str)
        The last item says where the model came from: ``"sensor file"``, ``"options"`` or ``"default"``.
    """
    from ..models import sensor_model
    from ..sensor import load_sensor

    sen = load_sensor(sensor if sensor is not None else "paper")
    given = any(x is not None for x in (model, conductance, thickness, backing))
    if given:
        fm, source = model_from_options(model, conductance=conductance, thickness=thickness, backing=backing), \
            "options"
    else:
        fm, source = sensor_model(sen), ("sensor file" if sen.model is not None else "default")
    if warn and sen.problems:
        from ._app import escape

        from ._app import console

        con = console(stderr=True)
        for text in sen.problems:
            con.print(f"[bold yellow]warning:[/] sensor {escape(sen.name)}: its calibration reported: "
                      f"{escape(text)}")
    return sen, fm, source


def model_words(sen, fm, source: str) -> str:
    """One line saying which model answers, and why (for text output)."""
    if source == "sensor file":
        from ..models import sensor_model_notes

        extra = sensor_model_notes(sen, fm)[1:]   # the contact area and drift lines (the first names the model)
        return f"model {fm.describe()} (recorded in sensor file {sen.name})" + "".join(f"; {x}" for x in extra)
    if source == "options" and sen.model is not None and sen.model_name != fm.name:
        return f"model {fm.describe()} (from the options; sensor {sen.name} was identified with {sen.model_name})"
    return f"model {fm.describe()}"


def get_model_name(name: str) -> str:
    from ..models import model_class

    return model_class(name).name
