"""Shared fixtures. Tests run against whatever `designkit` is importable (the
installed package in CI), never against a copy of the shared recordings."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent


def pytest_configure(config):
    """Stop at once, with the remedy, where designkit's installed metadata predates pyproject.toml's command
    entry points (an editable install made before they changed): the lab's commands would be missing."""
    try:
        import tomllib
    except ImportError:  # pragma: no cover - Python 3.10
        return
    from importlib.metadata import entry_points

    pyproject = REPO / "pyproject.toml"
    if not pyproject.is_file():
        return
    declared = tomllib.loads(pyproject.read_text())["project"].get("entry-points", {}).get("designkit.commands", {})
    installed = {ep.name: ep.value for ep in entry_points(group="designkit.commands")}
    if installed != declared:
        raise pytest.UsageError(f"designkit's installed entry points {installed} are not pyproject.toml's {declared}: "
                                "reinstall it (pip install --no-deps -e .) and run the tests again")


@pytest.fixture(scope="session")
def paper_sensor():
    from designkit import SENSORS

    return SENSORS["paper"]


@pytest.fixture(scope="session")
def robot_data_dir() -> Path:
    """The shared real robot recordings, or a skip with the reason."""
    env = os.environ.get("DESIGNKIT_ROBOT_DATA")
    path = Path(env) if env else REPO.parent / "shared" / "data" / "robot-thermal-recordings"
    if not (path / "index.csv").is_file():
        pytest.skip(f"robot recordings not found at {path} (set DESIGNKIT_ROBOT_DATA to their folder)")
    return path


@pytest.fixture
def cli():
    """Invoke the designkit CLI in-process; returns typer's Result."""
    from typer.testing import CliRunner

    from designkit.cli import app

    runner = CliRunner()

    def invoke(*args: str, input: str | None = None):
        return runner.invoke(app, [str(a) for a in args], input=input)

    return invoke


def _default_sigint() -> None:
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.fixture
def ctrl_c_able() -> dict:
    """``subprocess.Popen`` keywords for a child that a test interrupts with SIGINT (Ctrl-C).

    A shell starts background jobs with SIGINT ignored and children inherit that; Python then
    never raises KeyboardInterrupt. The child gets the default disposition back, so that the
    test checks designkit's Ctrl-C handling wherever the suite runs."""
    return {"preexec_fn": _default_sigint}


def pytest_collection_modifyitems(config, items):
    """Files holding a test marked ``slow`` first, the most slow tests first, then the others by their number of
    tests (most first), each file's tests in their own order.

    pyproject's addopts hand xdist whole files in this order (``--dist loadfile --no-loadscope-reorder``): a slow
    file started last kept one worker busy while the others had finished (xdist's own order, by number of tests,
    put the tutorial's calibration, three tests, near the end)."""
    slow: dict[str, int] = {}
    count: dict[str, int] = {}
    for item in items:
        f = item.nodeid.split("::", 1)[0]
        count[f] = count.get(f, 0) + 1
        slow[f] = slow.get(f, 0) + (item.get_closest_marker("slow") is not None)
    first = {f: i for i, f in enumerate(dict.fromkeys(item.nodeid.split("::", 1)[0] for item in items))}
    items.sort(key=lambda item: (lambda f: (-slow[f], -count[f], first[f]))(item.nodeid.split("::", 1)[0]))


def read_until_closed(fd: int) -> bytes:
    """Everything a pseudo-terminal's main side ``fd`` receives until the child closes the terminal."""
    chunks = []
    while True:
        try:
            b = os.read(fd, 65536)
        except OSError:  # the child closed the terminal
            break
        if not b:
            break
        chunks.append(b)
    return b"".join(chunks)


@pytest.fixture
def load_python_export(tmp_path):
    """Import a Python export (its bytes, or an :class:`~designkit.export.Exported` rendered as Python) from a
    file in ``tmp_path``; returns the module."""
    import importlib.util

    def load(data, name: str = "dk_module"):
        if not isinstance(data, (bytes, bytearray)):
            from designkit.export import render

            data = render(data, "python")
        path = tmp_path / f"{name}.py"
        path.write_bytes(data)
        spec = importlib.util.spec_from_file_location(name, path)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        return mod

    return load

