"""Fresh-process start-up of the CLI against ``python -c "import numpy"``, measured in the same run (issue 16).

Run from the repository root::

    /work/main/.venv/bin/python benchmarks/bench_startup.py            # 15 runs each
    /work/main/.venv/bin/python benchmarks/bench_startup.py --runs 30 --json out.json

Like hyperfine: each command runs ``--runs`` times as a new process, round robin
(so a neighbour's load spreads over all of them), after one warm-up run each;
the figure is the median wall time. The CLI runs as ``python -m designkit`` with
this interpreter (the tree on ``PYTHONPATH`` if set), which costs the same as
the console script plus runpy's few milliseconds.

Byte-compile the tree first (``python -m compileall -q designkit``): an installed package has its
``.pyc`` files, and where ``PYTHONDONTWRITEBYTECODE`` is set a source tree compiles every module on
every run (it doubled designkit's own import time here).

Targets: ``designkit min-contact --e1 35000 --e2 20000`` at most 2x ``import
numpy``; ``designkit --version`` at most 1.5x.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

PY = sys.executable
COMMANDS = {
    "python -c pass": [PY, "-c", "pass"],
    "import numpy": [PY, "-c", "import numpy"],
    "designkit --version": [PY, "-m", "designkit", "--version"],
    "designkit min-contact": [PY, "-m", "designkit", "min-contact", "--e1", "35000", "--e2", "20000"],
    "designkit min-contact --json": [PY, "-m", "designkit", "min-contact", "--e1", "35000", "--e2", "20000",
                                     "--json"],
}
TARGETS = {"designkit --version": 1.5, "designkit min-contact": 2.0}


def _run(cmd: list[str], env: dict | None = None) -> tuple[float, float]:
    """Wall seconds and CPU seconds (user + system, from the child's rusage) of one run."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env or os.environ.copy())
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
    args = ap.parse_args(argv)
    commands = {name: (cmd, None) for name, cmd in COMMANDS.items()}
    if args.baseline is not None:
        env = {**os.environ, "PYTHONPATH": str(args.baseline)}
        commands["baseline min-contact"] = (COMMANDS["designkit min-contact"], env)
    for cmd, env in commands.values():  # warm-up: page cache, .pyc files
        _run(cmd, env)
    times: dict[str, list[float]] = {k: [] for k in commands}
    cpus: dict[str, list[float]] = {k: [] for k in commands}
    for _ in range(args.runs):
        for name, (cmd, env) in commands.items():
            wall, cpu = _run(cmd, env)
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
        print(f"  {name:<30} wall {med * 1e3:7.1f} ms {med / base:5.2f}x   CPU {cpu * 1e3:7.1f} ms "
              f"{cpu / base_cpu:5.2f}x  (x: of import numpy){target}")
    if args.json:
        args.json.write_text(json.dumps(out, indent=2))
    return out


if __name__ == "__main__":
    main()
