"""Project conventions: one version everywhere, `designkit --version`, and the files a
published package carries (LICENSE, CITATION.cff, CHANGELOG.md)."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

import designkit

REPO = Path(__file__).resolve().parent.parent


def _repo_file(name: str) -> Path:
    path = REPO / name
    if not (REPO / "pyproject.toml").is_file():
        pytest.skip("not running from a source checkout")
    assert path.is_file(), f"{name} is missing from the repository root"
    return path


def _designkit_cmd() -> list[str]:
    exe = Path(sys.executable).with_name("designkit")
    return [str(exe)] if exe.is_file() else [sys.executable, "-m", "designkit"]


# ----------------------------------------------------------------- version
def test_version_is_a_release_number():
    assert re.fullmatch(r"\d+\.\d+\.\d+", designkit.__version__), designkit.__version__


def test_cli_version_matches_package_and_installed_metadata():
    from importlib.metadata import PackageNotFoundError, version

    out = subprocess.run(_designkit_cmd() + ["--version"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout == f"designkit {designkit.__version__}\n"
    assert out.stderr == ""
    short = subprocess.run(_designkit_cmd() + ["-V"], capture_output=True, text=True, timeout=60)
    assert short.returncode == 0 and short.stdout == out.stdout
    try:
        installed = version("designkit")
    except PackageNotFoundError:
        pytest.skip("designkit is not installed (no distribution metadata to compare)")
    assert installed == designkit.__version__, (
        f"installed metadata says {installed}, designkit.__version__ says {designkit.__version__}: "
        "reinstall (pip install -e .) after changing the version")


def test_version_option_in_process(cli):
    res = cli("--version")
    assert res.exit_code == 0
    assert res.stdout == f"designkit {designkit.__version__}\n"


def test_version_loads_nothing_heavy():
    """--version answers before any command's library layer: no numpy, let alone scikit-learn."""
    code = ("import json, sys\nsys.argv = ['designkit', '--version']\nfrom designkit.cli import main\n"
            "code = None\ntry:\n    main()\nexcept SystemExit as exc:\n    code = exc.code\n"
            "heavy = [m for m in ('numpy', 'scipy', 'sklearn', 'matplotlib', 'dask') if m in sys.modules]\n"
            "print(json.dumps([code, heavy]), file=sys.stderr)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    assert out.stdout == f"designkit {designkit.__version__}\n"
    exit_code, heavy = json.loads(out.stderr)
    assert exit_code in (0, None) and heavy == [], out.stderr


def test_version_is_written_once():
    """pyproject reads the version from designkit/__init__.py instead of repeating it."""
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover
        tomllib = pytest.importorskip("tomli")
    cfg = tomllib.loads(_repo_file("pyproject.toml").read_text())
    assert "version" not in cfg["project"] and "version" in cfg["project"]["dynamic"]
    attr = cfg["tool"]["setuptools"]["dynamic"]["version"]["attr"]
    assert attr == "designkit.__version__"
    expand = pytest.importorskip("setuptools.config.expand")
    # setuptools' own reader, the one a build uses (it reads the literal without importing)
    assert expand.read_attr(attr, root_dir=REPO) == designkit.__version__
    assert "version" not in yaml.safe_load(_repo_file("CITATION.cff").read_text())


# ------------------------------------------------------ files of a release
def test_license_is_mit():
    text = _repo_file("LICENSE").read_text()
    assert text.startswith("MIT License")
    assert re.search(r"Copyright \(c\) \d{4} designkit developers", text)
    assert "WITHOUT WARRANTY OF ANY KIND" in text


def test_citation_cff_has_the_required_keys():
    cff = yaml.safe_load(_repo_file("CITATION.cff").read_text())
    # required by the Citation File Format 1.2.0 schema
    for key in ("cff-version", "message", "title", "authors"):
        assert cff.get(key), f"CITATION.cff lacks {key!r}"
    assert cff["cff-version"] == "1.2.0"
    assert cff["type"] == "software" and cff["license"] == "MIT"
    for person in cff["authors"]:
        assert person.get("name") or person.get("family-names"), person
    (paper,) = [r for r in cff["references"] if "Thermal Tactile Sensing" in r["title"]]
    for key in ("type", "title", "authors"):  # required of every reference
        assert paper.get(key), f"the reference lacks {key!r}"
    assert [a["family-names"] for a in paper["authors"]] == ["Bai", "Chen", "Healy", "Kemp", "Bhattacharjee"]


def test_changelog_names_the_current_version():
    text = _repo_file("CHANGELOG.md").read_text()
    assert "## [Unreleased]" in text
    headings = re.findall(r"^## \[(\d+\.\d+\.\d+)\] - \d{4}-\d{2}-\d{2}$", text, flags=re.M)
    assert designkit.__version__ in headings, f"CHANGELOG.md has no entry for {designkit.__version__}"
    assert f"[{designkit.__version__}]: http" in text


# ----------------------------------------------------------------- shell completion
def _run_module(args, env_extra=None):
    import os

    env = {**os.environ, **(env_extra or {})}
    env["PYTHONPATH"] = str(REPO) + os.pathsep + env.get("PYTHONPATH", "")
    return subprocess.run([sys.executable, "-m", "designkit", *args], capture_output=True, text=True, env=env,
                          timeout=120)


@pytest.mark.parametrize("how", ["flag", "env"])
def test_show_completion_prints_a_bash_script_for_the_designkit_command(how):
    # --show-completion detects the shell from the process tree (shellingham), which a CI runner may not
    # have; typer's own test switch makes it take the shell as its value, as the env protocol does.
    if how == "flag":
        r = _run_module(["--show-completion", "bash"], {"_TYPER_COMPLETE_TEST_DISABLE_SHELL_DETECTION": "1"})
    else:
        r = _run_module([], {"_DESIGNKIT_COMPLETE": "source_bash"})
    assert r.returncode == 0, r.stderr
    assert "_DESIGNKIT_COMPLETE=complete_bash" in r.stdout
    assert "complete -o default -F _designkit_completion designkit" in r.stdout


@pytest.mark.parametrize("words, cword, expected", [
    ("designkit min-co", 1, {"min-contact"}),
    ("designkit min-contact --e", 2, {"--e1", "--e2", "--exact"}),
    ("designkit tables ", 2, {"list", "show"}),
])
def test_completion_protocol_completes_commands_and_options(words, cword, expected):
    r = _run_module([], {"_DESIGNKIT_COMPLETE": "complete_bash", "COMP_WORDS": words, "COMP_CWORD": str(cword)})
    assert r.returncode == 0, r.stderr
    assert expected <= set(r.stdout.split()), r.stdout
