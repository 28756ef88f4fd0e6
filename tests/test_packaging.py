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


def test_bench_without_the_lab_is_one_line_naming_what_to_install():
    """The core runs without designkit_lab; `designkit bench` then says what is missing (exit 2), no traceback."""
    import subprocess

    code = ("import sys; sys.modules['designkit_lab'] = None; sys.argv = ['designkit', 'bench', '--quick', '--json'];"
            " from designkit.cli import main; main()")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 2, out.stderr
    assert out.stderr.count("\n") == 1 and "designkit_lab" in out.stderr and "Traceback" not in out.stderr
    assert '"exit_status": 2' in out.stdout
