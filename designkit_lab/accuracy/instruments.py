"""The measuring instruments: wall time, peak memory, a child process's cost, power-law fits.

Every section of the accuracy report times its methods with :func:`timed`;
the cost section measures memory with :func:`measure`; the scripts in
``benchmarks/`` measure whole processes with :func:`process_cost`.
Peak memory uses Linux's resettable high-water mark (``/proc/self/clear_refs``
and ``VmHWM``); where the kernel does not offer it, memory is reported as
None and nothing else changes.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

import numpy as np

__all__ = ["ProcessCost", "fit_exponent", "measure", "process_cost", "reset_peak_memory", "resident_mb", "timed"]


def timed(fn: Callable[[], Any], repeat: int = 1) -> tuple[Any, float]:
    """``fn()`` and its best wall time over ``repeat`` calls [s].

    Examples
    --------
    >>> out, sec = timed(lambda: sum(range(1000)), repeat=3)
    >>> out, sec > 0
    (499500, True)
    """
    best, out = math.inf, None
    for _ in range(max(1, int(repeat))):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return out, best


def fit_exponent(x: Sequence[float], y: Sequence[float]) -> float:
    """Slope ``p`` of ``log y = p log x + c`` by least squares.

    Points with a non-positive or non-finite coordinate are dropped; NaN with
    fewer than two usable points or no spread in ``x``.

    Examples
    --------
    >>> round(fit_exponent([10, 20, 40], [3.0, 12.0, 48.0]), 6)
    2.0
    >>> fit_exponent([5.0, 5.0], [1.0, 2.0])
    nan
    """
    xa, ya = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    ok = (xa > 0) & (ya > 0) & np.isfinite(xa) & np.isfinite(ya)
    if np.count_nonzero(ok) < 2 or np.ptp(np.log(xa[ok])) == 0:
        return math.nan
    return float(np.polyfit(np.log(xa[ok]), np.log(ya[ok]), 1)[0])


def resident_mb(key: str = "VmRSS") -> float | None:
    """A memory figure of this process from ``/proc/self/status`` [MB] (None where unavailable).

    ``key`` is ``VmRSS`` (resident set now) or ``VmHWM`` (its high-water mark).
    """
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) / 1024.0  # kB
    except (OSError, ValueError):
        pass
    return None


def reset_peak_memory() -> float | None:
    """Reset this process's peak resident set (Linux ``clear_refs``); its current resident set [MB].

    None where the kernel does not offer it (then no memory is reported).
    """
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
    except OSError:
        return None
    return resident_mb("VmRSS")


def measure(fn: Callable[[], Any]) -> tuple[Any, float, float | None, float | None]:
    """``fn()``, its wall time [s], and the peak resident set during it [MB] and above its start [MB].

    Peak memory uses Linux's resettable high-water mark (``/proc/self/clear_refs``,
    ``VmHWM``), so it is this call's own peak, not the process's lifetime peak;
    both memory figures are None where that is unavailable.

    Examples
    --------
    >>> out, wall, peak, above = measure(lambda: 6 * 7)
    >>> out, wall > 0, above is None or above >= 0
    (42, True, True)
    """
    start = reset_peak_memory()
    t0 = time.perf_counter()
    out = fn()
    wall = time.perf_counter() - t0
    peak = resident_mb("VmHWM") if start is not None else None
    return out, wall, peak, (None if peak is None else max(peak - start, 0.0))


@dataclass(frozen=True)
class ProcessCost:
    """Wall time [s], peak resident memory [MB], exit status and output of one child process."""

    wall_s: float
    max_rss_mb: float
    returncode: int
    stdout: str
    stderr: str


#: Runs a command and reports its own peak resident set and wall time on a pipe. Linux carries a
#: process's peak RSS across fork and exec (``signal->maxrss``), so a child forked straight from a
#: large parent (a test runner, 300 MB) reports at least the parent's size; forked from this small
#: launcher instead, the child starts from the launcher's ~10 MB. (-S: no site packages, stdlib only.)
_LAUNCHER = """
import os, sys, time
fd = int(sys.argv[1])
t0 = time.perf_counter()
pid = os.fork()
if pid == 0:
    try:
        os.execvp(sys.argv[2], sys.argv[2:])
    finally:
        os._exit(127)
_, status, ru = os.wait4(pid, 0)
os.write(fd, ("%d %r" % (ru.ru_maxrss, time.perf_counter() - t0)).encode())
os._exit(os.waitstatus_to_exitcode(status) & 0xFF)
"""


def process_cost(cmd: Sequence[str], *, env: Mapping[str, str] | None = None, timeout: float = 600.0,
                 cwd: str | None = None) -> ProcessCost:
    """Run ``cmd`` as a child process: its wall time and peak resident set (``wait4`` rusage).

    The peak is the child's own: the command is started by a small launcher
    process (see ``_LAUNCHER``), so neither this process's size nor its other
    children's peaks leak into it. The wall time is measured by the launcher
    around the command alone. A child still running after ``timeout`` seconds
    is killed.

    Examples
    --------
    >>> import sys
    >>> c = process_cost([sys.executable, "-c", "print('hi')"])
    >>> c.returncode, c.stdout.strip(), c.wall_s > 0
    (0, 'hi', True)
    """
    import subprocess
    import sys
    import tempfile

    run_env = {**os.environ, **(env or {})}
    read_fd, write_fd = os.pipe()
    try:
        with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
            t0 = time.perf_counter()
            proc = subprocess.Popen([sys.executable, "-S", "-c", _LAUNCHER, str(write_fd), *map(str, cmd)],
                                    stdout=out, stderr=err, env=run_env, cwd=cwd, pass_fds=(write_fd,),
                                    start_new_session=True)
            os.close(write_fd)
            write_fd = -1
            try:
                returncode = proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:  # a hung child is killed with its launcher, not waited for forever
                os.killpg(proc.pid, 9)
                returncode = proc.wait()
            report = os.read(read_fd, 256).decode().split()
            wall = float(report[1]) if len(report) == 2 else time.perf_counter() - t0
            max_rss_mb = int(report[0]) / 1024.0 if len(report) == 2 else float("nan")
            out.seek(0)
            err.seek(0)
            return ProcessCost(wall, max_rss_mb, returncode, out.read().decode(errors="replace"),
                               err.read().decode(errors="replace"))
    finally:
        os.close(read_fd)
        if write_fd >= 0:
            os.close(write_fd)
