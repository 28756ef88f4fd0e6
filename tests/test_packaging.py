"""The explicit package list in pyproject.toml covers the tree (a forgotten subpackage
would be missing from a non-editable install)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    tomllib = pytest.importorskip("tomli")


def test_every_subpackage_is_listed():
    pyproject = REPO / "pyproject.toml"
    if not pyproject.is_file():
        pytest.skip("not running from a source checkout")
    cfg = tomllib.loads(pyproject.read_text())["tool"]["setuptools"]
    listed = set(cfg["packages"])
    found = {".".join(p.parent.relative_to(REPO).parts) for root in ("designkit", "designkit_lab")
             for p in (REPO / root).rglob("__init__.py") if "__pycache__" not in p.parts}
    assert found <= listed, f"add to pyproject.toml packages: {sorted(found - listed)}"
    for pkg, folder in cfg["package-dir"].items():
        assert pkg in listed and (REPO / folder).is_dir()


def test_cli_import_stays_light():
    """`designkit --help` and table queries must not pay for scikit-learn, matplotlib, dask or the lab."""
    import subprocess

    code = ("import sys, designkit.cli; bad = [m for m in ('sklearn', 'matplotlib', 'dask', 'scipy.optimize',"
            " 'designkit_lab')"
            " if m in sys.modules]; print(','.join(bad))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_every_named_package_data_file_exists():
    """A package-data file named without a wildcard that does not exist is silently left
    out of the wheel; tables/README.md was once such an entry."""
    pyproject = REPO / "pyproject.toml"
    if not pyproject.is_file():
        pytest.skip("not running from a source checkout")
    cfg = tomllib.loads(pyproject.read_text())["tool"]["setuptools"]
    folders = cfg.get("package-dir", {})
    for pkg, patterns in cfg["package-data"].items():
        folder = REPO / folders.get(pkg, pkg.replace(".", "/"))
        for name in patterns:
            if not any(c in name for c in "*?["):
                assert (folder / name).is_file(), f"package-data {pkg}: {name} does not exist in {folder}"


def test_every_data_file_in_a_package_folder_is_installed():
    """A template or data file added beside the code but not matched by package-data works in an
    editable checkout and is missing from the wheel (the sequential C template once was)."""
    import fnmatch

    pyproject = REPO / "pyproject.toml"
    if not pyproject.is_file():
        pytest.skip("not running from a source checkout")
    cfg = tomllib.loads(pyproject.read_text())["tool"]["setuptools"]
    folders = cfg.get("package-dir", {})
    data = cfg["package-data"]
    owners = {pkg: REPO / pkg.replace(".", "/") for pkg in cfg["packages"] if pkg not in folders}
    missing = []
    for p in [p for root in ("designkit", "designkit_lab") for p in (REPO / root).rglob("*")]:
        if not p.is_file() or "__pycache__" in p.parts or p.suffix in (".py", ".pyc") or p.name.startswith("."):
            continue
        pkg, folder = max(((k, f) for k, f in owners.items() if f in p.parents), key=lambda kf: len(kf[1].parts))
        rel = p.relative_to(folder).as_posix()
        if not any(fnmatch.fnmatch(rel, pat) for pat in data.get(pkg, [])):
            missing.append(f"{pkg}: {rel}")
    assert not missing, f"not in [tool.setuptools.package-data]: {missing}"


def test_the_lab_commands_come_through_the_entry_points():
    """``designkit bench``, ``reproduce`` and ``emulate`` are registered by the lab's modules that the installed
    ``designkit.commands`` entry points name, as pyproject.toml declares them (the core's CLI names no lab
    module: tests/test_architecture.py)."""
    from importlib.metadata import entry_points

    from designkit.cli import ENTRY_POINT_GROUP, app

    pyproject = REPO / "pyproject.toml"
    if not pyproject.is_file():
        pytest.skip("not running from a source checkout")
    declared = tomllib.loads(pyproject.read_text())["project"]["entry-points"][ENTRY_POINT_GROUP]
    assert declared == {"bench": "designkit_lab.cli.bench", "reproduce": "designkit_lab.cli.reproduce",
                        "emulate": "designkit_lab.cli.emulate"}
    installed = {ep.name: ep.value for ep in entry_points(group=ENTRY_POINT_GROUP)}
    assert installed == declared, ("the installed metadata's entry points are not pyproject.toml's: reinstall "
                                   "designkit (pip install --no-deps -e .)")
    where = {c.name or c.callback.__name__: c.callback.__module__ for c in app.registered_commands}
    assert {name: where.get(name) for name in declared} == declared


def test_a_lab_command_that_cannot_be_imported_is_one_line_naming_it():
    """The core runs without designkit_lab; a lab command whose entry point is installed but whose module
    cannot be imported says so in one line (exit 2, JSON too under --json), no traceback; ``designkit --help``
    still lists the core's commands."""
    import subprocess

    def run(*argv):
        code = (f"import sys; sys.modules['designkit_lab'] = None; sys.argv = ['designkit', *{argv!r}];"
                " from designkit.cli import main; main()")
        return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)

    out = run("bench", "--quick", "--json")
    assert out.returncode == 2, out.stderr
    assert out.stderr.count("\n") == 1 and "designkit_lab.cli.bench" in out.stderr and "Traceback" not in out.stderr
    assert '"exit_status": 2' in out.stdout
    helped = run("--help")
    assert helped.returncode == 0, helped.stderr
    assert "min-contact" in helped.stdout and "reproduce" not in helped.stdout and "Traceback" not in helped.stderr
