"""Fresh-process start-up of the CLI against ``python -c "import numpy"``, measured in the same run (issue 16).

Run from the repository root::

    /work/main/.venv/bin/python benchmarks/bench_startup.py            # 15 runs each
    /work/main/.venv/bin/python benchmarks/bench_startup.py --runs 30 --json out.json

Like hyperfine: each command runs ``--runs`` times as a new process, round robin
(so a neighbour's load spreads over all of them), after one warm-up run each;
the figure is the median wall time. The CLI runs as ``python -m designkit`` with
this interpreter (the tree on ``PYTHONPATH`` if set), which costs the same as
the console script plus runpy's few milliseconds. Its output goes to the null device, except for
``(terminal)`` rows: those run on a pseudo-terminal, as in a user's shell, where the answer is styled.

The script byte-compiles this tree's packages and a ``--baseline`` tree's first (what ``python -m
compileall -q designkit`` does; only stale or missing ``.pyc`` files are written): an installed package has
its ``.pyc`` files, and where ``PYTHONDONTWRITEBYTECODE`` is set a source tree edited since its last
compile compiles that module on every run (a stale ``store.pyc`` showed as 15 ms of "self" import time).
A ``--baseline`` tree is a checkout of the commit to compare (``git archive COMMIT designkit designkit_lab
tables | tar -x -C /tmp/base``)::

    python benchmarks/bench_startup.py --runs 11 --baseline /tmp/base --sensor tests/data/rig_sensor.yaml

``--python PY`` runs every command (``import numpy`` too) with another interpreter, e.g. a virtual
environment where designkit is installed as the README installs it (``pip install .``, not editable: an
editable install's import hook loads pathlib into every process, ``import numpy`` included, which flatters
the ratio by about 10 ms)::

    python -m venv /tmp/ne && /tmp/ne/bin/pip install .
    python benchmarks/bench_startup.py --python /tmp/ne/bin/python --baseline /tmp/base

Targets: ``designkit min-contact --e1 35000 --e2 20000`` at most 2x ``import
numpy``; ``designkit --version`` at most 1.5x (issue 33).

``--sensor FILE`` (e.g. ``tests/data/rig_sensor.yaml``) adds a calibrated sensor's question (issue 34: answered
from its table in at most 50 ms from a fresh shell; python with numpy alone takes longer, so the figure is
reported as is and above ``import numpy``): a tiny table for the sensor is built first (2 materials, 3 contact
times, 6 touches: seconds) and registered in a scratch data folder, then ``designkit min-contact --sensor FILE
--m1 wood --m2 glass`` answers from it; beside it, the sensor file read alone, and the sensor file read plus
the registry looked up where no table is registered (what every ``--sensor`` question pays first)::

    python benchmarks/bench_startup.py --runs 11 --sensor tests/data/rig_sensor.yaml

``--help-rows`` adds what reads the installed packages' entry points (the commands other packages add,
``designkit.commands``: the lab's ``bench``, ``reproduce``, ``emulate``): ``designkit --help``, ``designkit
reproduce --help``, and the entry points read alone (``python -c``); with ``--baseline`` the first two for
that tree too. ``designkit min-contact`` never reads them::

    python benchmarks/bench_startup.py --runs 11 --baseline /tmp/base --help-rows
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PY = sys.executable
REPO = Path(__file__).resolve().parents[1]
ARGS = {
    "python -c pass": ["-c", "pass"],
    "import numpy": ["-c", "import numpy"],
    "designkit --version": ["-m", "designkit", "--version"],
    "designkit min-contact": ["-m", "designkit", "min-contact", "--e1", "35000", "--e2", "20000"],
    "designkit min-contact --json": ["-m", "designkit", "min-contact", "--e1", "35000", "--e2", "20000", "--json"],
}
#: ``--help-rows``: the commands that read the installed entry points, and that read alone.
HELP_ARGS = {
    "designkit --help": ["-m", "designkit", "--help"],
    "designkit reproduce --help": ["-m", "designkit", "reproduce", "--help"],
    "entry points read alone": ["-c", "from importlib.metadata import entry_points; "
                                      "entry_points(group='designkit.commands')"],
}
#: A command's first item when it runs on a pseudo-terminal (:func:`_run`).
TERMINAL = "<terminal>"
ARGS["designkit min-contact (terminal)"] = [TERMINAL, *ARGS["designkit min-contact"]]
COMMANDS = {name: [PY, *args] for name, args in ARGS.items()}
TARGETS = {"designkit --version": 1.5, "designkit min-contact": 2.0, "designkit min-contact (terminal)": 2.0}


def _compile(trees: list[Path]) -> None:
    """Byte-compile the designkit packages of ``trees`` where their ``.pyc`` files are missing or stale."""
    import compileall

    for tree in trees:
        for package in ("designkit", "designkit_lab"):
            if (tree / package).is_dir():
                compileall.compile_dir(tree / package, quiet=1)


def _run(cmd: list[str], env: dict | None = None, cwd: Path | None = None) -> tuple[float, float]:
    """Wall seconds and CPU seconds (user + system, from the child's rusage) of one run. A command whose first
    item is :data:`TERMINAL` runs the rest with stdout and stderr on a pseudo-terminal (a user's shell:
    styled output), its output read as it comes; any other's output goes to the null device."""
    terminal = cmd[0] == TERMINAL
    if terminal:
        import pty

        cmd = cmd[1:]
        main, sub = pty.openpty()
        out = err = sub
    else:
        out = err = subprocess.DEVNULL
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=out, stderr=err, env=env or os.environ.copy(), cwd=cwd)
    if terminal:
        os.close(sub)
        while True:
            try:
                if not os.read(main, 65536):
                    break
            except OSError:  # the child closed the terminal
                break
        os.close(main)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} exited with {p.returncode}")
    return wall, usage.ru_utime + usage.ru_stime


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=15)
    ap.add_argument("--json", type=Path)
    ap.add_argument("--baseline", type=Path,
                    help="another designkit tree (e.g. /work/main): its min-contact runs in the same round robin, "
                         "with that tree first on PYTHONPATH (a before/after in one run)")
    ap.add_argument("--sensor", type=Path, help="a calibrated sensor file: also time its question from a fresh shell")
    ap.add_argument("--help-rows", action="store_true",
                    help="also time designkit --help, a lab command's --help and the entry points read alone")
    ap.add_argument("--python", type=Path, default=Path(PY),
                    help="the interpreter every command runs with (default: this one), e.g. a virtual environment "
                         "with designkit installed non-editable")
    args = ap.parse_args(argv)
    if args.baseline is not None:
        args.baseline = args.baseline.resolve()
    _compile([REPO] + ([args.baseline] if args.baseline is not None else []))
    scratch = tempfile.TemporaryDirectory(prefix="bench-startup-")
    # another interpreter runs from an empty folder: ``python -m`` puts the working folder first on sys.path,
    # which would put this tree before the installed package
    # (and without PYTHONPATH): its own installed designkit is measured
    home = None if args.python == Path(PY) else Path(scratch.name)
    own = None if home is None else {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    where = subprocess.run([str(args.python), "-c", "import designkit; print(designkit.__file__)"], cwd=home,
                           env=own, capture_output=True, text=True)
    print(f"{args.python}: designkit from {where.stdout.strip() or where.stderr.strip()}")
    rows = {**ARGS, **(HELP_ARGS if args.help_rows else {})}
    commands = {name: ([TERMINAL, str(args.python), *a[1:]] if a[0] == TERMINAL else [str(args.python), *a], own, home)
                for name, a in rows.items()}
    if args.sensor is not None:
        commands.update(_sensor_commands(args.sensor.resolve(), Path(scratch.name), str(args.python)))
        if args.baseline is not None:
            for name in ("sensor question (its table)", "sensor file read"):
                cmd, env, _ = commands[name]
                commands[f"baseline {name}"] = (cmd, {**env, "PYTHONPATH": str(args.baseline)}, args.baseline)
    if args.baseline is not None:
        env = {**os.environ, "PYTHONPATH": str(args.baseline)}
        # run from that tree too: ``python -m`` puts the working folder first on sys.path, before PYTHONPATH
        commands["baseline min-contact"] = (commands["designkit min-contact"][0], env, args.baseline)
        commands["baseline min-contact (terminal)"] = (commands["designkit min-contact (terminal)"][0], env,
                                                       args.baseline)
        if args.help_rows:
            for name in ("designkit --help", "designkit reproduce --help"):
                commands[f"baseline {name[len('designkit '):]}"] = (commands[name][0], env, args.baseline)
    for cmd, env, cwd in commands.values():  # warm-up: page cache, .pyc files
        _run(cmd, env, cwd)
    times: dict[str, list[float]] = {k: [] for k in commands}
    cpus: dict[str, list[float]] = {k: [] for k in commands}
    for _ in range(args.runs):
        for name, (cmd, env, cwd) in commands.items():
            wall, cpu = _run(cmd, env, cwd)
            times[name].append(wall)
            cpus[name].append(cpu)
    base = statistics.median(times["import numpy"])
    base_cpu = statistics.median(cpus["import numpy"])
    out = {"runs": args.runs, "load_average": os.getloadavg(), "median_s": {}, "ratio_to_import_numpy": {},
           "median_cpu_s": {}, "cpu_ratio_to_import_numpy": {}}
    print(f"median over {args.runs} runs (load average {os.getloadavg()[0]:.2f}); wall, and CPU (user + sys, "
          "less sensitive to a shared machine's load):")
    for name, ts in times.items():
        med, cpu = statistics.median(ts), statistics.median(cpus[name])
        out["median_s"][name], out["ratio_to_import_numpy"][name] = med, med / base
        out["median_cpu_s"][name], out["cpu_ratio_to_import_numpy"][name] = cpu, cpu / base_cpu
        target = f"   target <= {TARGETS[name]:g}x" if name in TARGETS else ""
        print(f"  {name:<38} wall {med * 1e3:7.1f} ms {med / base:5.2f}x   CPU {cpu * 1e3:7.1f} ms "
              f"{cpu / base_cpu:5.2f}x  (x: of import numpy){target}")
    if args.json:
        args.json.write_text(json.dumps(out, indent=2))
    if args.sensor is not None:
        above = {k: out["median_s"][k] - base for k in out["median_s"] if "sensor" in k}
        print("  above import numpy (wall): " + ", ".join(f"{k} +{v * 1e3:.0f} ms" for k, v in above.items()))
        out["sensor_above_import_numpy_s"] = above
    scratch.cleanup()
    return out


def _sensor_commands(sensor: Path, scratch: Path, py: str = PY) -> dict[str, tuple[list[str], dict, None]]:
    """The sensor question's commands, each with its data folder (a tiny table registered in one, none in the
    other), after building that table."""
    with_table, without = {**os.environ, "DESIGNKIT_DATA_DIR": str(scratch / "with")}, \
        {**os.environ, "DESIGNKIT_DATA_DIR": str(scratch / "without")}
    t0 = time.perf_counter()
    r = subprocess.run([py, "-m", "designkit", "tables", "build", "--sensor", str(sensor), "--m", "wood", "--m",
                        "glass", "--contact-points", "3", "--trials", "6", "--jobs", "1"], env=with_table,
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"building a table for {sensor} failed:\n{r.stderr}")
    print(f"(a tiny table for {sensor.name} built in {time.perf_counter() - t0:.1f} s)")
    read = f"from designkit.sensor import load_sensor; s = load_sensor({str(sensor)!r})"
    return {
        "sensor question (its table)": ([py, "-m", "designkit", "min-contact", "--sensor", str(sensor), "--m1", "wood",
                                         "--m2", "glass"], with_table, None),
        "sensor file read": ([py, "-c", read], without, None),
        "sensor file + registry (none)": ([py, "-c", read + "; from designkit.tables.registry import "
                                           "table_for_sensor; assert table_for_sensor(s) is None"], without, None),
    }


if __name__ == "__main__":
    main()
