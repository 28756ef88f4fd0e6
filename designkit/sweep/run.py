"""Running a whole sweep: chunks in parallel (joblib processes or a dask cluster), resumable.

Work is cut into chunks, one per (scene point, block of references, contact
time), run on local processes (joblib) or a dask cluster and written
atomically as they finish; an interrupted sweep resumes without recomputing
finished chunks and gives bit-identical results. A working folder records its
sweep's :meth:`~designkit.sweep.config.SweepConfig.digest`: resuming it with
a config that would change the results (another seed, another forward model)
is refused, naming what changed.
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

from .._validation import InputError
from .chunk import ChunkResult, estimated_costs, run_chunk
from .config import SweepConfig
from .scorer import ENGINE_VERSION
from .search import assemble, chunk_wall_s

__all__ = ["BACKENDS", "SweepInterrupted", "check_batches", "check_scheduler", "iter_sweep", "local_cluster",
           "prepare_workdir", "run_sweep"]

#: Where chunks run: local processes, this process, or a dask cluster.
BACKENDS = ("loky", "sequential", "dask")


class SweepInterrupted(Exception):
    """Raised when a sweep is interrupted; finished chunks are on disk."""

    def __init__(self, done: int, total: int, workdir: Path):
        super().__init__(f"interrupted: {done} of {total} chunks saved in {workdir}; "
                         f"run the same command with --resume to continue")
        self.done, self.total, self.workdir = done, total, workdir


def _chunk_path(workdir: Path, point, block, k) -> Path:
    p = "-".join(f"{x:03d}" for x in point)
    return workdir / "chunks" / f"p{p}-b{block:03d}-c{k:03d}.npz"


def _save_chunk(path: Path, res: ChunkResult, cfg: SweepConfig) -> None:
    """Write a chunk atomically, stamped with the identity of its slot in this sweep."""
    import io

    from .._io import atomic_write_bytes
    from .config import stamp_chunk

    buf = io.BytesIO()
    np.savez(buf, **stamp_chunk(res.to_arrays(), cfg, res.point, res.block, res.contact_index))
    atomic_write_bytes(path, buf.getvalue())


def _load_chunk(path: Path, cfg: SweepConfig, point, block: int, contact_index: int) -> ChunkResult:
    """A finished chunk, refused unless it is this slot's (a chunk copied into another slot changed tables)."""
    from .config import check_chunk

    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except Exception as exc:  # a damaged chunk is recomputed, never trusted
        raise InputError(f"chunk {path.name} is unreadable ({exc}); delete it and resume") from None
    check_chunk(arrays, cfg, point, block, contact_index, path)
    try:
        return ChunkResult.from_arrays(arrays)
    except (KeyError, ValueError, TypeError) as exc:
        raise InputError(f"chunk {path.name} is unreadable ({exc}); delete it and resume") from None


def prepare_workdir(cfg: SweepConfig, workdir: Path, *, resume: bool, fresh: bool) -> None:
    """Create or check a sweep's working folder (its config and chunks)."""
    from .._io import atomic_write_text

    workdir = Path(workdir)
    meta = workdir / "sweep.json"
    chunks = workdir / "chunks"
    if meta.exists() and not fresh:
        try:
            old = json.loads(meta.read_text())
        except (OSError, ValueError):
            raise InputError(f"{meta} is unreadable; use --fresh to start over") from None
        if old.get("digest") != cfg.digest():
            changed = cfg.changes_from(old.get("config")) or ["sensor file"]
            raise InputError(f"{workdir} holds a different sweep ({', '.join(changed)} changed); "
                             "use another --workdir or --fresh")
        if old.get("engine_version", 1) != ENGINE_VERSION and any(chunks.glob("*.npz")):
            raise InputError(f"{workdir} holds chunks of engine version {old.get('engine_version', 1)}, this "
                             f"designkit computes version {ENGINE_VERSION} (it rounds differently); "
                             "use another --workdir or --fresh")
        if not resume and any(chunks.glob("*.npz")):
            raise InputError(f"{workdir} already has finished chunks; use --resume to continue or --fresh to discard them")
    if fresh and chunks.exists():
        for f in chunks.glob("*.npz"):
            f.unlink()
    chunks.mkdir(parents=True, exist_ok=True)
    atomic_write_text(meta, json.dumps({"digest": cfg.digest(), "engine_version": ENGINE_VERSION,
                                        "config": cfg.to_dict()}, indent=2))


#: Up to this many chunks per worker, the chunks are ordered by estimated cost (in the parent, before any chunk
#: starts); with more, handing them out as workers free up balances
#: them well enough.
_FEW_CHUNKS_PER_WORKER = 8


def iter_sweep(cfg: SweepConfig, workdir: Path, *, jobs: int = 1, backend: str = "loky",
               scheduler: str | None = None) -> Iterator[tuple[ChunkResult, bool]]:
    """Run the missing chunks, all at once (no waves: chunks do not depend on each other).

    Yields ``(chunk, computed)`` for every chunk of the sweep, reading the
    finished ones from ``workdir`` and computing the rest in parallel; each
    computed chunk is written atomically before it is yielded. Longest contact
    times are submitted first so that the slowest chunks do not start last; where
    there are few chunks per worker (a single scene's blocks), the costliest by
    :func:`~designkit.sweep.chunk.estimated_costs` go first, so that no worker
    starts a long one while the others run out of work.
    """
    check_scheduler(backend, scheduler)
    yield from _iter_sweep(cfg, Path(workdir), _workers_asked(jobs, backend, scheduler), backend, scheduler)


def _workers_asked(jobs: int, backend: str, scheduler: str | None) -> int:
    """The local worker processes ``jobs`` means (:func:`~designkit._workers.worker_count`: ``-1`` all cores),
    refused before any work where that is none or absurdly many; ``jobs`` as given on a running dask cluster
    (``scheduler``), whose own workers do the work."""
    from .._workers import worker_count

    return int(jobs) if backend == "dask" and scheduler else worker_count(jobs)


def _iter_sweep(cfg: SweepConfig, workdir: Path, jobs: int, backend: str, scheduler: str | None):
    """:func:`iter_sweep` once its backend, scheduler and worker count are checked (``run_sweep`` checks them
    before it prepares the workdir: the scheduler is probed once); ``jobs`` is a count of workers."""
    todo = []
    for k in range(len(cfg.contact_s)):
        for p in cfg.scene_points():
            for b in range(len(cfg.blocks_of())):
                path = _chunk_path(workdir, p, b, k)
                if path.exists():
                    yield _load_chunk(path, cfg, p, b, k), False
                else:
                    todo.append((p, b, k))
    if not todo:
        return
    if 1 < len(todo) <= _FEW_CHUNKS_PER_WORKER * max(1, jobs) and (jobs != 1 or backend == "dask"):
        cost = {}
        for p, k in {(p, k) for p, _, k in todo}:
            for b, c in enumerate(estimated_costs(cfg, p, k).tolist()):
                cost[(p, b, k)] = c
        todo.sort(key=lambda t: -cost[t])
    else:
        todo.sort(key=lambda t: -t[2])
    results = _on_dask(cfg, todo, jobs, scheduler) if backend == "dask" else _on_joblib(cfg, todo, backend, jobs)
    for res in results:
        _save_chunk(_chunk_path(workdir, res.point, res.block, res.contact_index), res, cfg)
        yield res, True


def _on_joblib(cfg: SweepConfig, todo, backend: str, jobs: int) -> Iterator[ChunkResult]:
    """The chunks ``todo`` on local processes (loky) or in this process, as they finish."""
    from joblib import Parallel, delayed, parallel_config

    from .._workers import local_processes

    with local_processes(jobs) if backend == "loky" and jobs != 1 else parallel_config(backend="sequential"):
        yield from Parallel(n_jobs=jobs, return_as="generator_unordered")(
            delayed(run_chunk)(cfg, p, b, k) for p, b, k in todo)


def _on_dask(cfg: SweepConfig, todo, jobs: int, scheduler: str | None) -> Iterator[ChunkResult]:
    """The chunks ``todo`` on a dask cluster, as they finish, each handed out when a worker thread frees up.

    dask assigns a submitted task to a worker at once and a worker runs its own in turn, so with more chunks
    submitted than threads a worker that finished early would run a small chunk while a costlier one waited
    behind a busy worker: one chunk per thread is in flight (docs/decisions-log.md). The number
    of threads is asked again at each hand-out, so the chunks follow a cluster that grows (an adaptive one
    sees the work of its running chunks; with no worker yet, one chunk waits for it).
    """
    try:
        from dask.distributed import Client, as_completed
    except ImportError:
        raise InputError("the dask backend needs dask.distributed: pip install 'designkit[distributed]'") from None
    client = Client(scheduler) if scheduler else local_cluster(jobs)
    try:
        running, waiting = as_completed(), list(reversed(todo))

        def hand_out():
            threads = max(1, sum(client.nthreads().values()))
            while waiting and running.count() < threads:
                running.add(client.submit(run_chunk, cfg, *waiting.pop(), pure=False))

        hand_out()
        for future in running:
            res = future.result()
            future.release()
            hand_out()
            yield res
    finally:
        client.close()


def local_cluster(jobs: int):
    """A dask client of a new ``LocalCluster`` of ``jobs`` worker processes, one thread each, as
    ``--backend dask`` without ``--scheduler`` starts it (close it when done)."""
    import dask
    from dask.distributed import Client

    # dask's nanny spawns workers with MALLOC_TRIM_THRESHOLD_=65536, and the solver's per-fold arrays are
    # then handed back and faulted in afresh (docs/decisions-log.md). The cluster designkit starts leaves it
    # unset; a worker's memory stays bounded by the chunk's own limits (scorer.BATCH_MB, the feature cache).
    with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}):
        return Client(processes=True, n_workers=max(jobs, 1), threads_per_worker=1)


def check_scheduler(backend: str, scheduler: str | None) -> None:
    """Refuse, before any work, a backend or a dask scheduler address that cannot be used.

    A scheduler address without ``backend="dask"`` would be ignored (the sweep would run on local
    processes, not on the cluster asked for), a malformed one fails deep inside dask, and a TCP
    address where nothing listens waits for dask's connect timeout (30 s) before failing: each is
    one clear error here instead. A TCP port that neither accepts nor refuses (a firewall, a slow
    network) is left to dask's own connection attempt, which waits and says why.

    Raises
    ------
    InputError
        Unknown backend; a scheduler with another backend; an address dask cannot parse; a host
        that does not resolve; a port that refuses the connection.

    Examples
    --------
    >>> check_scheduler("loky", None)
    >>> check_scheduler("loky", "tcp://10.0.0.5:8786")
    Traceback (most recent call last):
    ...
    designkit._validation.InputError: --scheduler is the address of a dask scheduler: use it with --backend dask
    """
    if backend not in BACKENDS:
        raise InputError(f"backend must be loky, sequential or dask, got {backend!r}")
    if scheduler is None:
        return
    if backend != "dask":
        raise InputError("--scheduler is the address of a dask scheduler: use it with --backend dask")
    try:
        from distributed.comm import parse_address
        from distributed.comm.addressing import parse_host_port
    except ImportError:
        raise InputError("the dask backend needs dask.distributed: pip install 'designkit[distributed]'") from None
    try:
        scheme, location = parse_address(scheduler)
        host, port = parse_host_port(location) if scheme in ("tcp", "tls") else (None, None)
    except (ValueError, TypeError) as exc:
        raise InputError(f"--scheduler {scheduler!r} is not a dask scheduler address (tcp://HOST:PORT): {exc}") from None
    if host is None:
        return  # another transport (inproc, ucx, ...): dask's to check
    import socket

    try:
        socket.create_connection((host, port), timeout=5).close()
    except ConnectionRefusedError:
        raise InputError(f"no dask scheduler at {scheduler}: nothing listens on port {port} of {host}") from None
    except socket.gaierror as exc:
        raise InputError(f"no dask scheduler at {scheduler}: host {host!r} not found ({exc.strerror})") from None
    except OSError:
        pass  # no answer within 5 s (a firewall, a slow network): dask's own attempt decides


def check_batches(cfg: SweepConfig) -> None:
    """Refuse, before any work, a batched-solver sweep that cannot run here.

    Raises
    ------
    InputError
        The solver's array library is not installed (``batched-cupy`` without CuPy),
        or one pair's batch at the longest contact time exceeds
        :data:`~designkit.sweep.scorer.BATCH_MB`.
    """
    from .scorer import BATCH_MB, array_namespace, batch_pairs

    if cfg.solver == "sklearn" or cfg.fidelity != "svm":
        return
    array_namespace(cfg.solver)
    longest = max(cfg.contact_s)
    n_samples = cfg.resolved_sensor().times_s(longest).size
    if batch_pairs(cfg.trials, n_samples, cfg.folds) < 1:
        raise InputError(f"one pair at {longest:g} s contact ({cfg.trials} trials x {n_samples} samples) does not "
                         f"fit in the batched solver's {BATCH_MB} MiB batch; use --solver sklearn or fewer trials")


def run_sweep(cfg: SweepConfig, workdir: str | Path, *, out: str | Path | None = None, jobs: int = 1,
              backend: str = "loky", scheduler: str | None = None, resume: bool = False,
              fresh: bool = False, on_chunk: Callable[[ChunkResult, bool, int, int], None] | None = None,
              compress: bool = True) -> Path:
    """Run (or resume) a sweep and write its table; returns the table's path.

    Parameters
    ----------
    cfg : SweepConfig
    workdir : path
        Folder for the sweep's chunks (resumable state).
    out : path, optional
        Table path (``.npz``; a ``.json`` header is written beside it).
        Default: ``workdir / f"{cfg.name}.npz"``.
    jobs : int
        Local worker processes (``-1``: all cores, ``-2``: all but one; the header's run stats record the
        count); unused on a running dask cluster (``scheduler``).
    backend : {"loky", "sequential", "dask"}
    scheduler : str, optional
        Address of a dask scheduler (with ``backend="dask"``).
    resume, fresh : bool
        Continue a previous run in ``workdir`` / discard its chunks.
    on_chunk : callable, optional
        Called as ``on_chunk(chunk, computed, done, total)`` after each chunk
        (progress display).
    compress : bool
        Deflate the table's arrays (default); ``False`` stores them as they are, so that a
        question maps only the slices it reads (:func:`designkit.tables.store.write_table`).
    """
    from ..tables.store import table_header, write_table

    workdir = Path(workdir)
    check_scheduler(backend, scheduler)
    jobs = _workers_asked(jobs, backend, scheduler)
    check_batches(cfg)
    prepare_workdir(cfg, workdir, resume=resume, fresh=fresh)
    total = len(cfg.scene_points()) * len(cfg.blocks_of()) * len(cfg.contact_s)
    chunks: list[ChunkResult] = []
    t0 = time.perf_counter()
    computed = 0
    try:
        for res, was_computed in _iter_sweep(cfg, workdir, jobs, backend, scheduler):
            chunks.append(res)
            computed += was_computed
            if on_chunk is not None:
                on_chunk(res, was_computed, len(chunks), total)
    except KeyboardInterrupt:
        raise SweepInterrupted(len(list((workdir / "chunks").glob("*.npz"))), total, workdir) from None
    arrays = assemble(cfg, chunks)
    elapsed = time.perf_counter() - t0
    wall = chunk_wall_s(cfg, chunks)  # timings: in the header's run stats, never in the hashed arrays
    header = table_header(cfg, arrays, run={"elapsed_s": elapsed, "chunks_computed": computed,
                                            "chunks_total": total, "jobs": jobs, "backend": backend,
                                            "solver": cfg.solver, "compute_s_total": float(wall.sum()),
                                            "chunk_wall_s": wall.tolist()})
    header["engine_version"] = ENGINE_VERSION  # hashed with the header; tables without it are version 1
    path = Path(out) if out is not None else workdir / f"{cfg.name}.npz"
    return write_table(path, header, arrays, compress=compress)
