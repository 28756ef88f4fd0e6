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


def process_cost(cmd: Sequence[str], *, env: Mapping[str, str] | None = None, timeout: float = 600.0,
                 cwd: str | None = None) -> ProcessCost:
    """Run ``cmd`` as a child process: its wall time and peak resident set (``wait4`` rusage).

    The peak is the child's own (``ru_maxrss`` of exactly that process, not of
    every child this process ever had). A child still running after
    ``timeout`` seconds is killed.

    Examples
    --------
    >>> import sys
    >>> c = process_cost([sys.executable, "-c", "print('hi')"])
    >>> c.returncode, c.stdout.strip(), c.wall_s > 0
    (0, 'hi', True)
    """
    import subprocess
    import tempfile
    import threading

    run_env = {**os.environ, **(env or {})}
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        proc = subprocess.Popen(list(cmd), stdout=out, stderr=err, env=run_env, cwd=cwd)
        timer = threading.Timer(timeout, proc.kill)  # a hung child is killed, not waited for forever
        timer.start()
        try:
            _, status, usage = os.wait4(proc.pid, 0)
        finally:
            timer.cancel()
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        return ProcessCost(wall, usage.ru_maxrss / 1024.0, proc.returncode, out.read().decode(errors="replace"),
                           err.read().decode(errors="replace"))
