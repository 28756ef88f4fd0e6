"""Local worker processes that leave Ctrl-C to the program that started them.

A terminal's Ctrl-C sends SIGINT to every process of the foreground group: the
program and its joblib (loky) workers alike. A worker caught between two tasks
(in loky's own loop, outside any task) then dies printing a traceback, and the
user sees it under the program's quiet "Interrupted.". So the workers ignore
SIGINT; the program gets its KeyboardInterrupt, and joblib stops the workers
(it terminates the pool when the parent's call is interrupted).
"""

from __future__ import annotations

import signal
from typing import Any


def ignore_ctrl_c() -> None:
    """Worker initializer: SIGINT ignored in this process (the parent handles it)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def local_processes() -> Any:
    """``joblib.parallel_config`` for local worker processes (loky) that ignore Ctrl-C.

    >>> from joblib import Parallel, delayed
    >>> import os, signal
    >>> def disposition():
    ...     return signal.getsignal(signal.SIGINT) == signal.SIG_IGN, os.getpid()
    >>> with local_processes():
    ...     got = Parallel(n_jobs=2)(delayed(disposition)() for _ in range(2))
    >>> all(ignored and pid != os.getpid() for ignored, pid in got)
    True
    """
    from joblib import parallel_config

    return parallel_config(backend="loky", initializer=ignore_ctrl_c)
