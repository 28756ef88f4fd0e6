"""Local worker processes that leave Ctrl-C to the program that started them, and a heap they reuse.

A terminal's Ctrl-C sends SIGINT to every process of the foreground group: the
program and its joblib (loky) workers alike. A worker that takes it dies printing
a traceback, and the user sees that under the program's quiet "Interrupted.":
caught between two tasks (in loky's own loop, seen in CI) or while it starts
(importing joblib). So:

- the workers are started with SIGINT blocked (the signal mask is inherited
  through fork and exec), so a Ctrl-C while they import stays pending in them;
- their initializer then ignores SIGINT, which also discards a pending one;
- the program blocks SIGINT only while the pool starts (a Ctrl-C meanwhile is
  delivered to it right after), gets its KeyboardInterrupt, and joblib stops the
  workers (it terminates the pool when the parent's call is interrupted);
- the resource trackers, which clean up after killed workers, do so without
  warning about it (:data:`_TRACKER_WARNINGS`).

:func:`steady_heap` keeps a worker's freed arrays for reuse while it computes
(a sweep chunk allocates and frees the same arrays of megabytes thousands of times).
"""

from __future__ import annotations

import ctypes
import functools
import os
import platform
import signal
import threading
from contextlib import contextmanager
from typing import Iterator


#: Most local worker processes per core a computation may start: each sweep worker takes up to 1 GB, and a
#: mistyped ``--jobs 100000`` would start processes until the machine stalls.
MAX_JOBS_PER_CORE = 4


def worker_count(jobs: int) -> int:
    """Local worker processes that ``jobs`` asks for on this machine, by joblib's convention.

    ``jobs > 0`` is that many, ``-1`` all cores, ``-2`` all but one, and so on (the cores
    this process may use: ``joblib.cpu_count()``). Raises :class:`~designkit.InputError`
    (one line) where that is no worker at all (0, or more cores left out than there are) or
    more than :data:`MAX_JOBS_PER_CORE` per core.

    >>> worker_count(1)
    1
    >>> import joblib
    >>> worker_count(-1) == joblib.cpu_count()
    True
    """
    from joblib import cpu_count

    from ._validation import InputError

    try:
        j = int(jobs)
    except (TypeError, ValueError, OverflowError):
        j = None
    if j is None or j != jobs:
        raise InputError(f"jobs must be a whole number of worker processes, got {jobs!r}")
    cores = cpu_count()
    if j == 0:
        raise InputError(f"jobs = 0 is no worker process: give how many (1 to {MAX_JOBS_PER_CORE * cores} here), "
                         "or -1 for all cores")
    n = j if j > 0 else cores + 1 + j
    if n < 1:
        raise InputError(f"jobs = {j} leaves out {-j - 1} of this machine's {cores} cores: none would work "
                         "(-1: all cores, -2: all but one)")
    if n > MAX_JOBS_PER_CORE * cores:
        raise InputError(f"jobs = {j} is more worker processes than {MAX_JOBS_PER_CORE} per core on this machine's "
                         f"{cores} cores (each may take up to 1 GB): give at most {MAX_JOBS_PER_CORE * cores}, "
                         "or -1 for all cores")
    return n


def ignore_ctrl_c(parent_pid: int | None = None) -> None:
    """Worker initializer: SIGINT ignored in this process (the parent handles it), and the worker exits when
    its parent, ``parent_pid`` (default: the parent it has now), dies (:func:`watch_parent`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    watch_parent(parent_pid)


#: How often a worker looks whether its parent still lives [s].
PARENT_WATCH_S = 0.5


def watch_parent(parent_pid: int | None = None, interval_s: float = PARENT_WATCH_S) -> threading.Thread | None:
    """Exit this process soon after its parent dies: a daemon thread compares the parent's pid every
    ``interval_s`` (a child whose parent died is adopted by another process).

    A ``kill -9`` of a sweep's main process left its loky workers (idle for loky's 300 s timeout) and, through
    them, the resource tracker alive for about 5 minutes; a worker's work belongs to its parent alone, so it
    exits at once (``os._exit``: nothing of the parent's to flush or clean). ``parent_pid`` is the pid that
    started the pool: a worker still starting when its parent was killed (its imports take seconds on a loaded
    machine) has been adopted already when this runs, and exits here.
    """
    parent = os.getppid() if parent_pid is None else int(parent_pid)
    if os.getppid() != parent:
        os._exit(1)

    def watch() -> None:
        import time

        while True:
            time.sleep(interval_s)
            if os.getppid() != parent:
                os._exit(1)

    t = threading.Thread(target=watch, name="designkit-parent-watch", daemon=True)
    t.start()
    return t


@contextmanager
def local_processes(n_jobs: int, *, start: bool = True) -> Iterator[None]:
    """``joblib.parallel_config`` for ``n_jobs`` local worker processes (loky) that leave Ctrl-C to this one.

    On entry the pool is started (or found running) with SIGINT blocked in this thread, so that workers
    begin life with it blocked; a Ctrl-C during those moments reaches this process when they are over.
    ``start=False`` skips that (one round trip to a running pool): for the calls after the first of a
    computation.

    >>> from joblib import Parallel, delayed
    >>> import os, signal
    >>> def disposition():
    ...     return signal.getsignal(signal.SIGINT) == signal.SIG_IGN, os.getpid()
    >>> with local_processes(2):
    ...     got = Parallel(n_jobs=2)(delayed(disposition)() for _ in range(2))
    >>> all(ignored and pid != os.getpid() for ignored, pid in got)
    True
    """
    from joblib import parallel_config

    with parallel_config(backend="loky", initializer=functools.partial(ignore_ctrl_c, os.getpid())):
        if start:
            _start_pool(n_jobs)
        yield


#: The resource trackers' own warnings, for the tracker processes' environment (PYTHONWARNINGS): joblib stops
#: interrupted workers with SIGKILL, so a worker can die holding a reference to the pool's semaphores, and
#: the tracker, which still unlinks them, then warns of "leaked semlock objects" under the program's
#: "Interrupted." (seen once in a CI-like run; loky's maintainers: killing a parallel job can leave these
#: warnings, and nothing can ensure it does not, joblib/loky#369).
_TRACKER_WARNINGS = ("ignore::UserWarning:joblib.externals.loky.backend.resource_tracker",
                     "ignore::UserWarning:multiprocessing.resource_tracker")


@contextmanager
def _quiet_about_leaks() -> Iterator[None]:
    """PYTHONWARNINGS extended with :data:`_TRACKER_WARNINGS` while the resource trackers start (they read
    it at their start; set back on exit)."""
    before = os.environ.get("PYTHONWARNINGS")
    os.environ["PYTHONWARNINGS"] = ",".join(([before] if before else []) + list(_TRACKER_WARNINGS))
    try:
        yield
    finally:
        if before is None:
            del os.environ["PYTHONWARNINGS"]
        else:
            os.environ["PYTHONWARNINGS"] = before


def _start_pool(n_jobs: int) -> None:
    """Run one trivial task per worker with SIGINT blocked in this thread: loky starts its workers at the
    first submission, from the submitting thread, so they inherit the blocked mask. Where the pool is
    already running this costs one round trip."""
    from joblib import Parallel, delayed

    can_block = hasattr(signal, "pthread_sigmask") and threading.current_thread() is threading.main_thread()
    if can_block:
        # the resource trackers first: the standard library's unblocks SIGINT (SIG_UNBLOCK, not the
        # previous mask) in the calling thread after starting its own, which loky does at its first launch
        from multiprocessing import resource_tracker

        from joblib.externals.loky.backend import resource_tracker as loky_tracker

        with _quiet_about_leaks():
            resource_tracker.ensure_running()
            loky_tracker.ensure_running()
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT}) if can_block else None
    try:
        Parallel(n_jobs=n_jobs)(delayed(os.getpid)() for _ in range(max(1, abs(int(n_jobs)))))
    finally:
        if old is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)


#: glibc's ``mallopt`` parameters (``malloc.h``) and their defaults.
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
_GLIBC_DEFAULT_THRESHOLD = 128 * 1024

#: The allocator's settings belong to the process, not to a chunk: where several chunks run at once
#: in one process (a dask worker with several threads), the first one in sets them and the last one
#: out sets them back (a chunk ending must not undo them under one still running).
_HEAP_LOCK = threading.Lock()
_HEAP_USERS = [0]
_HEAP_BEFORE: list = [None]


@contextmanager
def steady_heap() -> Iterator[None]:
    """Freed memory kept in the process for reuse, and no transparent huge pages for numpy, while inside.

    A sweep chunk allocates and frees the same few arrays of 1-10 MB (stacked features,
    scaled training touches, Gram matrices) thousands of times. By default glibc serves
    such an array from fresh pages of the kernel (``mmap``, or heap it gave back at the last
    ``free``), and numpy asks the kernel to back every array of 4 MiB or more with 2 MiB
    huge pages (``madvise``): each allocation then pays page faults and the kernel's
    zeroing of those pages. Nothing computed changes, only where memory comes from
    (the gain: docs/decisions-log.md).

    Inside: glibc's mmap threshold 32 MiB (arrays below it come from the heap) and its
    trim threshold 1 GiB (freed heap is kept), numpy's huge-page advice off. On exit the
    previous huge-page advice and glibc's default thresholds (128 KiB; glibc then no
    longer raises them by itself, as it does from the start of a process) are set back and
    the free heap is given back to the system (``malloc_trim``): an interactive process
    that ran a chunk does not keep its working set. Where several threads of one process
    are inside at once, the last one out sets them back. Where the C library is not glibc
    only numpy's advice changes.

    >>> import numpy as np
    >>> with steady_heap():
    ...     total = float(sum(np.ones(1_000_000).sum() for _ in range(3)))
    >>> total
    3000000.0
    """
    with _HEAP_LOCK:
        _HEAP_USERS[0] += 1
        if _HEAP_USERS[0] == 1:  # the first chunk in: set (later ones find it set)
            libc, advise = _glibc(), _numpy_hugepage_setter()
            _HEAP_BEFORE[0] = advise(False) if advise is not None else None
            if libc is not None:
                libc.mallopt(_M_MMAP_THRESHOLD, 32 * 2**20)
                libc.mallopt(_M_TRIM_THRESHOLD, 2**30)
    try:
        yield
    finally:
        with _HEAP_LOCK:
            _HEAP_USERS[0] -= 1
            if _HEAP_USERS[0] == 0:  # the last chunk out: set back
                libc, advise = _glibc(), _numpy_hugepage_setter()
                if libc is not None:
                    libc.mallopt(_M_MMAP_THRESHOLD, _GLIBC_DEFAULT_THRESHOLD)
                    libc.mallopt(_M_TRIM_THRESHOLD, _GLIBC_DEFAULT_THRESHOLD)
                    libc.malloc_trim(0)
                if advise is not None and _HEAP_BEFORE[0] is not None:
                    advise(_HEAP_BEFORE[0])


@functools.cache
def _glibc():
    """This process's C library where it is glibc (``mallopt``, ``malloc_trim``), else None (looked up once)."""
    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        return None
    try:
        libc = ctypes.CDLL(None)
        libc.mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
        libc.malloc_trim.argtypes = (ctypes.c_size_t,)
    except (OSError, AttributeError):
        return None
    return libc


@functools.cache
def _numpy_hugepage_setter():
    """numpy's runtime switch of its huge-page advice (returns the previous setting), or None (looked up once).

    numpy documents the switch as the environment variable ``NUMPY_MADVISE_HUGEPAGE``, read at
    import; this is the function behind it (``numpy._core.multiarray``, numpy >= 1.19).
    """
    try:
        from numpy._core import multiarray
    except ImportError:  # numpy < 2
        from numpy.core import multiarray
    return getattr(multiarray, "_set_madvise_hugepage", None)
