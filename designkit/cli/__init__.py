"""Command-line interface: a thin skin over the library (see ``designkit --help``)."""

import os

#: The BLAS thread variables a user can set; where none is set, the command-line application runs its
#: BLAS on one thread per process (its matrices are small; parallelism comes from worker processes; why:
#: docs/decisions-log.md). Set in the application's entry only (before numpy is imported), never by
#: ``import designkit``.
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")
if not any(v in os.environ for v in BLAS_THREAD_VARIABLES):
    os.environ["OPENBLAS_NUM_THREADS"] = "1"

import importlib  # noqa: E402
import sys  # noqa: E402

from . import _app  # noqa: E402

#: The modules that register commands on ``app``, in the order of ``designkit --help`` within each panel
#: (questions first). Each keeps its imports cheap (no numpy work, no scikit-learn) at module level.
COMMAND_MODULES = ("query", "matrix", "thin", "materials", "tables", "export", "calibrate", "classify",
                   "design", "core", "sweep")

#: Which module registers each top-level command or command group. The console script imports only the
#: module of the command it runs; anything else (help, an unknown name, shell completion) imports them all.
#: tests/test_help.py checks that this map names every registered command and nothing else.
COMMAND_MODULE = {
    "min-contact": "query", "max-noise": "query", "min-delta-t": "query", "delta-e": "query",
    "distinguishable": "query", "matrix": "matrix", "validity": "thin", "materials": "materials",
    "tables": "tables", "export": "export", "calibrate": "calibrate", "classify": "classify",
    "design": "design", "simulate": "core", "f1": "core", "sweep": "sweep",
}

#: The entry-point group through which other installed packages add commands (pyproject.toml's
#: ``[project.entry-points."designkit.commands"]``): each entry point is named after its command and names
#: the module that registers it on ``app`` when imported. The installed packages' metadata is read only for
#: a command outside :data:`COMMAND_MODULE`, help and completion (benchmarks/bench_startup.py times it).
ENTRY_POINT_GROUP = "designkit.commands"


def _register(modules) -> None:
    for name in modules:
        importlib.import_module(f"{__name__}.{name}")


def _entry_points(name: str | None = None) -> list:
    """The installed ``designkit.commands`` entry points (only ``name``'s, if given)."""
    from importlib.metadata import entry_points

    return [ep for ep in entry_points(group=ENTRY_POINT_GROUP) if name is None or ep.name == name]


def _register_all() -> "_app.typer.Typer":
    """Every command on ``app``, in help order whatever was imported first (an entry point's after the core's;
    one whose module cannot be imported is left out: ``designkit NAME`` says why)."""
    _register(COMMAND_MODULES)
    for ep in _entry_points():
        try:
            ep.load()
        except ImportError:
            pass
    rank = {f"{__name__}.{m}": i for i, m in enumerate(COMMAND_MODULES)}

    def module_rank(callback) -> int:
        return rank.get(getattr(callback, "__module__", ""), len(rank))

    app = _app.app
    app.registered_commands.sort(key=lambda c: module_rank(c.callback))
    app.registered_groups.sort(key=lambda g: min((module_rank(c.callback) for c in g.typer_instance.registered_commands),
                                                 default=len(rank)))
    return app


def _register_entry_point(argv: list[str]) -> bool:
    """Register the command ``argv[0]`` names if an entry point adds it; False if none does. One whose module
    cannot be imported is one line naming it (exit 2, JSON too under ``--json``), not a traceback."""
    eps = _entry_points(argv[0])
    for ep in eps:
        try:
            ep.load()
        except ImportError as exc:
            _app.report_error("bad-input", f"`designkit {ep.name}` comes from {ep.value}, which cannot be imported "
                              f"here ({exc}): reinstall the package that provides it", _app.EXIT_BAD_INPUT,
                              _app.wants_json(argv))
            sys.exit(_app.EXIT_BAD_INPUT)
    return bool(eps)


def main() -> None:
    """Console-script entry point: registers the command asked for (or all), then runs it."""
    argv = sys.argv[1:]
    module = COMMAND_MODULE.get(argv[0]) if argv else None
    if any(k.endswith("_COMPLETE") for k in os.environ):
        _register_all()
    elif module is not None:
        _register((module,))
    elif argv and argv[0] in ("--version", "-V"):  # answered while parsing the top-level options
        pass
    elif not (argv and not argv[0].startswith("-") and _register_entry_point(argv)):
        _register_all()
    _app.main()


def __getattr__(name: str):
    # ``designkit.cli.app``: the application with every command registered (tests, docs, typer's tools)
    if name == "app":
        return _register_all()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["BLAS_THREAD_VARIABLES", "COMMAND_MODULE", "COMMAND_MODULES", "ENTRY_POINT_GROUP", "app", "main"]
