"""``designkit sweep`` end to end: tables written through the CLI, interrupted sweeps (kill -9 and
Ctrl-C) resumed without recomputing finished chunks, and the same sweep on a real dask
``LocalCluster`` on loopback giving the same table as local processes."""

from __future__ import annotations

import importlib.util
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from designkit.tables.store import load_table

# 2 scene points x 4 contact times = 8 chunks of about a second each (40 intervals, 50 trials)
CONFIG = """\
name: tiny
sensor: paper
fidelity: svm
effusivity: {min: 0, max: 40000, intervals: 40}
trials: 50
folds: 3
threshold: 0.9
seed: 3
max_repeats: 2
noise_ratio: [0.005, 0.01]
contact_s: [1, 2, 4, 8]
blocks: 1
"""
N_CHUNKS = 8
TIMING: set[str] = set()  # no array may differ between two runs of one sweep (timings are in the header)


def _sweep_cmd(cfg: Path, workdir: Path, out: Path, *extra: str) -> list[str]:
    return [sys.executable, "-m", "designkit", "sweep", "--config", str(cfg), "--workdir", str(workdir),
            "--out", str(out), *extra]


def _run(cmd, **kw) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, capture_output=True, text=True, timeout=600, **kw)


def _arrays(path: Path) -> dict[str, np.ndarray]:
    with np.load(path, allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


def _same_table(a: Path, b: Path) -> None:
    x, y = _arrays(a), _arrays(b)
    assert set(x) == set(y)
    for k in x:
        if k not in TIMING:
            np.testing.assert_array_equal(x[k], y[k], err_msg=k)


def _chunks(workdir: Path) -> dict[str, int]:
    return {p.name: p.stat().st_mtime_ns for p in (workdir / "chunks").glob("*.npz")}


def _wait_for_chunks(proc: subprocess.Popen, workdir: Path, n: int) -> dict[str, int]:
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline:
        if (workdir / "chunks").is_dir() and len(_chunks(workdir)) >= n:
            return _chunks(workdir)
        if proc.poll() is not None:
            pytest.fail(f"the sweep ended before it could be interrupted: {proc.stderr.read()}")
        time.sleep(0.02)
    pytest.fail("no chunk appeared")


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> tuple[Path, Path]:
    """The config, and its table from one uninterrupted run with local processes."""
    d = tmp_path_factory.mktemp("sweep-ref")
    cfg = d / "tiny.yaml"
    cfg.write_text(CONFIG)
    r = _run(_sweep_cmd(cfg, d / "work", d / "tiny.npz", "--jobs", "2", "--json"))
    assert r.returncode == 0, r.stderr
    summary = json.loads(r.stdout)
    assert summary["chunks_total"] == summary["chunks_computed"] == N_CHUNKS
    return cfg, d / "tiny.npz"


@pytest.mark.slow
def test_sweep_cli_writes_a_loadable_table_that_tables_show_describes(reference, cli):
    cfg, table = reference
    t = load_table(table)
    assert t.name == "tiny" and t.fidelity == "svm" and t.header["trials"] == 50
    assert t.arrays["delta_up"].shape == (2, 4, 40)
    a = t.arrays
    finite = np.isfinite(a["delta_up"])
    assert finite.any() and np.all(a["delta_up"][finite] % t.header["effusivity"]["width"] == 0)
    lo_ok = finite & np.isfinite(a["delta_up_lo"])
    assert np.all(a["delta_up_lo"][lo_ok] <= a["delta_up"][lo_ok])  # each interval holds its estimate
    assert a["fits"].shape == (2, 4) and np.all(a["fits"] > 0)
    r = cli("tables", "show", str(table), "--json")
    assert r.exit_code == 0, r.output
    shown = json.loads(r.stdout)
    assert shown["name"] == "tiny" and shown["content_hash"] == t.header["content_hash"]


@pytest.mark.slow
def test_a_finished_sweep_rewritten_uncompressed_is_the_same_content_stored_as_is(reference, tmp_path):
    import zipfile

    cfg, ref = reference
    out = tmp_path / "tiny.npz"
    r = _run(_sweep_cmd(cfg, ref.parent / "work", out, "--resume", "--uncompressed", "--json"))
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["chunks_computed"] == 0  # every chunk was there: only the table is written
    assert load_table(out).header["content_hash"] == load_table(ref).header["content_hash"]
    _same_table(out, ref)
    with zipfile.ZipFile(out) as z, zipfile.ZipFile(ref) as zr:
        assert {i.compress_type for i in z.infolist()} == {zipfile.ZIP_STORED}
        assert {i.compress_type for i in zr.infolist()} == {zipfile.ZIP_DEFLATED}


@pytest.mark.slow
def test_kill_9_then_resume_recomputes_nothing_finished_and_gives_the_same_table(reference, tmp_path):
    cfg, ref = reference
    work, out = tmp_path / "work", tmp_path / "tiny.npz"
    proc = subprocess.Popen(_sweep_cmd(cfg, work, out, "--jobs", "1"), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    before = _wait_for_chunks(proc, work, 2)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=60)
    proc.stdout.close()
    proc.stderr.close()
    assert proc.returncode == -signal.SIGKILL and not out.exists()
    before = _chunks(work)  # what the kill left: every chunk file complete (written atomically)
    assert 2 <= len(before) < N_CHUNKS
    for name in before:
        with np.load(work / "chunks" / name, allow_pickle=False) as z:
            assert "J" in z.files

    r = _run(_sweep_cmd(cfg, work, out, "--jobs", "2", "--resume", "--json"))
    assert r.returncode == 0, r.stderr
    summary = json.loads(r.stdout)
    assert summary["chunks_computed"] == N_CHUNKS - len(before)
    after = _chunks(work)
    assert all(after[name] == mtime for name, mtime in before.items())  # not rewritten
    _same_table(out, ref)


@pytest.mark.slow
def test_ctrl_c_keeps_finished_chunks_and_says_how_to_resume(reference, tmp_path, ctrl_c_able):
    cfg, ref = reference
    work, out = tmp_path / "work", tmp_path / "tiny.npz"
    proc = subprocess.Popen(_sweep_cmd(cfg, work, out, "--jobs", "1"), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **ctrl_c_able)
    _wait_for_chunks(proc, work, 1)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    lines = [ln for ln in err.strip().splitlines() if ln.startswith("Interrupted")]
    assert len(lines) == 1 and "--resume" in lines[0] and "Traceback" not in err
    kept = _chunks(work)
    assert 1 <= len(kept) < N_CHUNKS and f"{len(kept)} of {N_CHUNKS} chunks" in lines[0]

    # resuming with a config that would change the results is refused, and loses nothing
    r = _run(_sweep_cmd(cfg, work, out, "--jobs", "1", "--resume", "--seed", "4"))
    assert r.returncode == 2 and r.stderr.startswith("Error:") and len(r.stderr.strip().splitlines()) == 1
    assert _chunks(work) == kept

    r = _run(_sweep_cmd(cfg, work, out, "--jobs", "2", "--resume", "--json"))
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["chunks_computed"] == N_CHUNKS - len(kept)
    _same_table(out, ref)


@pytest.mark.slow
def test_the_same_sweep_on_a_dask_local_cluster_gives_the_same_table(reference, tmp_path):
    distributed = pytest.importorskip("distributed", reason="dask.distributed is in the test extra")
    cfg, ref = reference
    out = tmp_path / "tiny.npz"
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=":0") as cluster:
        address = cluster.scheduler_address
        assert address.startswith("tcp://127.0.0.1:")
        with distributed.Client(address) as client:
            r = _run(_sweep_cmd(cfg, tmp_path / "work", out, "--backend", "dask", "--scheduler", address,
                                "--json"), env={**os.environ, "PYTHONWARNINGS": "ignore"})
            assert r.returncode == 0, r.stderr
            # the chunks ran as tasks of this cluster's scheduler, not in the sweep's own process
            prefixes = client.run_on_scheduler(lambda dask_scheduler: list(dask_scheduler.task_prefixes))
            assert prefixes, "no task reached the cluster"
    assert json.loads(r.stdout)["chunks_computed"] == N_CHUNKS
    _same_table(out, ref)
    header = json.loads(out.with_suffix(".json").read_text())
    assert header["stats"]["run"]["backend"] == "dask"


def test_the_dask_cluster_a_sweep_starts_leaves_malloc_trimming_to_glibc(monkeypatch):
    """dask's nanny spawns workers with MALLOC_TRIM_THRESHOLD_=65536; the solver's arrays are then faulted in
    afresh at every allocation and a 500-interval scene's chunks ran 15-30 % slower than in local processes
    (benchmarks/bench_engine.py --dask). The cluster ``--backend dask`` starts itself (no --scheduler) leaves it
    unset in its real worker processes."""
    pytest.importorskip("distributed", reason="dask.distributed is in the test extra")
    from designkit.sweep.run import local_cluster

    monkeypatch.delenv("MALLOC_TRIM_THRESHOLD_", raising=False)
    with local_cluster(2) as client:
        envs = client.run(lambda: (os.getpid(), os.environ.get("MALLOC_TRIM_THRESHOLD_")))
    assert len(envs) == 2 and len({pid for pid, _ in envs.values()} | {os.getpid()}) == 3  # two worker processes
    assert {value for _, value in envs.values()} == {None}


def _mmapped_bytes() -> int:
    """glibc's count of bytes this process holds in mmap'd chunks (``mallinfo2().hblkhd``)."""
    import ctypes

    class Mallinfo2(ctypes.Structure):
        _fields_ = [(name, ctypes.c_size_t) for name in ("arena", "ordblks", "smblks", "hblks", "hblkhd",
                                                          "usmblks", "fsmblks", "uordblks", "fordblks", "keepcost")]

    libc = ctypes.CDLL(None)
    libc.mallinfo2.restype = Mallinfo2
    return int(libc.mallinfo2().hblkhd)


def test_a_chunk_takes_its_arrays_from_a_kept_heap_and_sets_everything_back_after():
    """Inside steady_heap (what run_chunk runs in) a 16 MB array comes from the heap, not fresh mmap'd pages,
    and numpy's huge-page advice is off, also after another chunk of the process has ended; after the last,
    glibc's default threshold and numpy's advice are back.

    Checked in a fresh process: the allocator's state is the process's, and an earlier test's chunk still
    running in a thread of this worker (a dask thread, a timed-out in-process command) would hold it."""
    import ctypes
    import platform

    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc" or not hasattr(ctypes.CDLL(None),
                                                                                       "mallinfo2"):
        pytest.skip("needs glibc 2.33 or later (mallopt, mallinfo2)")
    code = "import test_sweep; test_sweep.kept_heap_check(); print('ok')"
    r = subprocess.run([sys.executable, "-c", code], cwd=Path(__file__).parent, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0 and r.stdout.strip() == "ok", r.stderr


def kept_heap_check() -> None:
    """The body of the test above, run in a fresh process."""
    from designkit._workers import _numpy_hugepage_setter, steady_heap

    advise = _numpy_hugepage_setter()

    def advice():
        now = advise(True)
        advise(now)
        return now

    before = advice()
    with steady_heap():
        with steady_heap():  # a second chunk in the same process (dask worker threads) ends first
            pass
        assert advice() is False
        held = _mmapped_bytes()
        x = np.ones(2 * 2**20)  # 16 MiB
        assert _mmapped_bytes() == held
        del x
    assert advice() == before
    held = _mmapped_bytes()
    x = np.ones(2 * 2**20)
    assert _mmapped_bytes() >= held + x.nbytes
    del x


def _in_flight_plugin():
    """A scheduler plugin counting the most tasks assigned to workers at once (the ``processing`` state)."""
    from distributed.diagnostics.plugin import SchedulerPlugin

    class InFlight(SchedulerPlugin):
        name = "designkit-test-in-flight"

        def __init__(self):
            self.now = self.most = 0

        def transition(self, key, start, finish, *args, **kwargs):
            self.now += (finish == "processing") - (start == "processing")
            self.most = max(self.most, self.now)

    return InFlight()


@pytest.mark.slow
def test_a_dask_sweep_keeps_one_chunk_in_flight_per_worker_and_follows_a_growing_cluster(tmp_path):
    """dask assigns each submitted task to a worker at once, and a worker runs its own in order; with more
    chunks in flight than workers, a worker that finished early ran a small chunk while a costlier one waited
    behind the busy worker (benchmarks/bench_engine.py --dask). The sweep hands a chunk out only as a worker
    thread frees up, so the costliest-first order holds on dask as on local processes, and it counts the
    threads at each hand-out, so a worker that joins mid-sweep gets chunks."""
    distributed = pytest.importorskip("distributed", reason="dask.distributed is in the test extra")
    from designkit.sweep import SweepConfig
    from designkit.sweep.run import iter_sweep

    cfg = SweepConfig(name="inflight", intervals=24, trials=12, noise_ratio=(0.005,), contact_s=(0.5, 1.0),
                      blocks=4, max_repeats=1)
    plugin = _in_flight_plugin()
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=":0") as cluster, distributed.Client(cluster) as client:
        cluster.scheduler.add_plugin(plugin)
        sweep = iter_sweep(cfg, tmp_path, jobs=1, backend="dask", scheduler=cluster.scheduler_address)
        got = [next(sweep)]
        alone = plugin.most
        cluster.scale(2)
        client.wait_for_workers(2)
        got += list(sweep)
    assert len(got) == 8 and all(computed for _, computed in got)
    assert alone == 1, f"{alone} chunks were assigned to the one worker at once"
    assert plugin.most == 2, f"{plugin.most} chunks were assigned at once once a second worker joined"


# ------------------------------------------------------------------ forward models through the sweep
# One scene, one contact, 10 intervals: a second or two per sweep, in-process.
MODEL_CONFIG = """\
name: {name}
sensor: paper
fidelity: svm
effusivity: {{min: 0, max: 40000, intervals: 10}}
trials: 12
folds: 3
seed: 1
max_repeats: 1
noise_ratio: [0.005]
contact_s: [1.5]
{extra}"""


def _model_sweep(cli, tmp_path: Path, name: str, extra: str = "", *options: str):
    cfg = tmp_path / f"{name}.yaml"
    cfg.write_text(MODEL_CONFIG.format(name=name, extra=extra))
    r = cli("sweep", "--config", cfg, "--workdir", tmp_path / f"work-{name}", "--out", tmp_path / f"{name}.npz",
            "--jobs", "1", "--json", *options)
    return r, tmp_path / f"{name}.npz"


def test_a_contact_model_sweep_end_to_end(cli, tmp_path):
    r, path = _model_sweep(cli, tmp_path, "small", "model: {name: contact, conductance_w_m2k: 2000}\n")
    assert r.exit_code == 0, r.output
    summary = json.loads(r.stdout)
    assert summary["model"] == {"name": "contact", "conductance_w_m2k": 2000.0}
    t = load_table(path)
    assert t.header["model"] == {"name": "contact", "conductance_w_m2k": 2000.0}
    assert t.header["config"]["model"] == t.header["model"] and t.model.name == "contact"
    # no closed-form ideal observer for a lagging contact: no floor, and no ideal arrays in the table
    assert "delta_up_ideal" not in t.arrays and np.all(t.arrays["fits"] > 0)
    assert np.isfinite(t.arrays["delta_up"]).any()
    shown = cli("tables", "show", str(path))
    assert shown.exit_code == 0 and "model contact (conductance_w_m2k = 2000 W m^-2 K^-1)" in shown.stdout
    assert json.loads(cli("tables", "show", str(path), "--json").stdout)["model"]["name"] == "contact"


def test_a_near_perfect_contact_gives_the_semi_infinite_table(cli, tmp_path):
    """h_c -> inf is the paper's model: with the same seeds the readings differ by < 1e-9 degC, so every
    SVM decision, hence every array, is the semi-infinite sweep's (the model option overrides the file)."""
    r_semi, semi = _model_sweep(cli, tmp_path, "semi")
    r_contact, contact = _model_sweep(cli, tmp_path, "contact", "", "--conductance", "1e12")
    assert r_semi.exit_code == 0 and r_contact.exit_code == 0, (r_semi.output, r_contact.output)
    assert load_table(semi).model.name == "semi-infinite"
    assert load_table(contact).header["model"] == {"name": "contact", "conductance_w_m2k": 1e12}
    _same_table(contact, semi)


def test_a_changed_model_is_refused_on_resume_and_bad_models_are_one_line(cli, tmp_path):
    r, _ = _model_sweep(cli, tmp_path, "m", "model: contact\n")
    assert r.exit_code == 0, r.output
    again, _ = _model_sweep(cli, tmp_path, "m", "model: contact\n", "--resume", "--conductance", "3000")
    assert again.exit_code == 2 and "model changed" in again.stderr
    cases = [
        ("model: contcat\n", (), "model: unknown forward model 'contcat'"),
        ("model: {name: contact, conductance_w_m2k: -5}\n", (), "model: interface conductance"),
        ("model: slab\n", (), "needs the objects' diffusivity"),
        ("", ("--thickness", "0.003"), "needs the objects' diffusivity"),
        ("diffusivity_m2_s: 1.0e-7\n", (), "does not use the objects' diffusivity"),
        ("model: contact\nfidelity: ideal\n", (), "fidelity ideal needs the closed-form"),
    ]
    for k, (extra, options, needle) in enumerate(cases):
        if "fidelity:" in extra:  # a config gives each key once (a repeated key is refused on its own)
            options = (*options, "--fidelity", "ideal")
            extra = extra.replace("fidelity: ideal\n", "")
        bad, _ = _model_sweep(cli, tmp_path, f"bad{k}", extra, *options)
        err = bad.stderr.strip()
        assert bad.exit_code == 2 and len(err.splitlines()) == 1 and needle in err, (extra, options, err)
        if not options:
            assert f"bad{k}.yaml" in err  # the file is named


def test_a_slab_sweep_takes_one_diffusivity_for_every_interval(cli, tmp_path):
    r, path = _model_sweep(cli, tmp_path, "slab", "", "--thickness", "0.0005", "--diffusivity", "1e-7")
    assert r.exit_code == 0, r.output
    t = load_table(path)
    assert t.model.name == "slab" and t.header["model"]["thickness_m"] == 0.0005
    assert t.header["config"]["diffusivity_m2_s"] == 1e-7


def test_the_contact_model_through_a_table_query_and_an_export(cli, tmp_path):
    """The example model of the seam, used for real: a sweep makes its table, the table route answers
    from it (and refuses it for another model), and its stdlib export answers the same."""
    import importlib.util

    r, path = _model_sweep(cli, tmp_path, "contact2k", "model: {name: contact, conductance_w_m2k: 2000}\n")
    assert r.exit_code == 0, r.output
    t = load_table(path)
    e_lo, e_hi = float(t.axes["e_ref"][3]), float(t.axes["e_ref"][-4])
    contact = float(t.axes["contact_s"][0])
    noise = float(t.axes["noise_ratio"][0]) * 10.0
    ask = ["distinguishable", "--e1", e_lo, "--e2", e_hi, "--contact", contact, "--noise", noise,
           "--table", path, "--json"]
    q = cli(*ask, "--model", "contact:conductance_w_m2k=2000")
    assert q.exit_code == 0, q.output
    answer = json.loads(q.stdout)
    assert answer["route"] == "table" and answer["model"] == t.header["model"]
    assert answer["table"]["content_hash"] == t.header["content_hash"]
    wrong = cli(*ask)  # the same table asked for the paper's model: refused, both models named
    assert wrong.exit_code == 2 and "contact" in wrong.stderr and "semi-infinite" in wrong.stderr
    out = tmp_path / "contact_table.py"
    ex = cli("export", "--table", path, "--format", "python", "--out", out)
    assert ex.exit_code == 0, ex.output
    spec = importlib.util.spec_from_file_location("contact_table", out)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.MODEL["name"] == "contact"
    # the contact model has no closed-form ideal observer: the export answers by the library's rule for such a
    # table (tests/test_export_rig.py has the details); outside min-contact's interval, the library's verdict
    yes, sure = mod.distinguishable_verdict(e_lo, e_hi, noise, 10.0, contact)
    assert yes == mod.distinguishable(e_lo, e_hi, noise, 10.0, contact) and (not sure or yes == answer["value"])


def test_an_unknown_solver_or_a_batch_that_cannot_fit_is_one_line_before_any_work(cli, tmp_path):
    cases = [(("--solver", "libsvm"), "solver must be one of batched, sklearn, batched-cupy, batched-array-api"),
             (("--solver", "batched", "--contact", "2000"), "does not fit in the batched solver")]
    if importlib.util.find_spec("cupy") is None:  # a GPU library that is not installed: refused before work
        cases.append((("--solver", "batched-cupy"), "the cupy array library is not usable here"))
    for k, (options, needle) in enumerate(cases):
        bad, out = _model_sweep(cli, tmp_path, f"s{k}", "", *options)
        err = bad.stderr.strip()
        assert bad.exit_code == 2 and len(err.splitlines()) == 1 and needle in err, (options, err)
        assert not (tmp_path / f"work-s{k}").exists() and not out.exists()


def test_a_worker_count_that_means_none_or_too_many_is_one_line_before_any_work(cli, tmp_path):
    """--jobs 0 failed with joblib's "n_jobs == 0 in Parallel has no meaning" after the workdir was made;
    --jobs 100000 started processes until the machine stalled (seen: load average 43 on 2 cores); a
    negative count beyond the cores silently ran one worker. Each is one line naming the count now,
    before any work, for a sweep and for an exact question; later options (``-1``) keep joblib's sense."""
    import joblib

    cores = joblib.cpu_count()
    for k, jobs in enumerate(["0", str(10**5), str(-cores - 1)]):
        bad, out = _model_sweep(cli, tmp_path, f"j{k}", "", "--jobs", jobs)
        err = bad.stderr.strip()
        assert bad.exit_code == 2 and len(err.splitlines()) == 1 and f"jobs = {jobs}" in err, (jobs, err)
        assert not (tmp_path / f"work-j{k}").exists() and not out.exists()
    exact = cli("min-contact", "--e1", "35000", "--e2", "20000", "--exact", "--jobs", "0")
    assert exact.exit_code == 2 and "jobs = 0 is no worker process" in exact.stderr
    report = cli("reproduce", "--jobs", str(10**5), "--out", tmp_path / "report")  # before any section runs
    assert report.exit_code == 2 and f"jobs = {10**5} is more worker processes" in report.stderr
    assert not (tmp_path / "report").exists()
    from designkit.sweep.run import _workers_asked

    # the CLI's default (-1) on a dask cluster the sweep starts: one worker per core (it started one worker)
    assert _workers_asked(-1, "dask", None) == _workers_asked(-1, "loky", None) == cores
    if cores > 1:
        assert _workers_asked(-2, "loky", None) == cores - 1
    assert _workers_asked(-1, "dask", "tcp://127.0.0.1:8786") == -1  # a running cluster's own workers work


def test_a_seed_count_without_end_is_one_line_before_any_work(cli, tmp_path):
    """--max-repeats 1000000000 re-scored pairs at the threshold without end (seen: a one-scene sweep still
    running after a minute), and --exact --repeats 1000000000 the same; both are refused by name now."""
    bad, out = _model_sweep(cli, tmp_path, "r0", "", "--max-repeats", str(10**9))
    assert bad.exit_code == 2 and "max_repeats must be a whole number from 1 to 1000" in bad.stderr
    assert not (tmp_path / "work-r0").exists() and not out.exists()
    exact = cli("min-contact", "--e1", "35000", "--e2", "20000", "--exact", "--repeats", str(10**9))
    assert exact.exit_code == 2 and "repeats must be a whole number from 1 to 1000" in exact.stderr


def test_a_scheduler_that_cannot_be_used_is_one_line_before_any_work(cli, tmp_path):
    """A scheduler address without --backend dask was ignored (the sweep ran on local processes, not on
    the cluster asked for); a TCP port where nothing listens waited for dask's 30 s connect timeout; a
    malformed address failed inside dask with "invalid literal for int()". Each is one line naming the
    address now, before a chunk or the workdir is written."""
    pytest.importorskip("distributed", reason="dask.distributed is in the test extra")
    import socket

    with socket.socket() as s:  # a port nothing listens on once this closes
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    cases = [(("--scheduler", "tcp://127.0.0.1:8786"), "use it with --backend dask"),
             (("--backend", "dask", "--scheduler", f"tcp://127.0.0.1:{port}"), f"nothing listens on port {port}"),
             (("--backend", "dask", "--scheduler", "tcp:/nohost"), "'tcp:/nohost' is not a dask scheduler address"),
             (("--backend", "dask", "--scheduler", "localhost"), "missing port number"),
             (("--backend", "dask", "--scheduler", "tcp://no-such-host.invalid:8786"), "not found")]
    for k, (options, needle) in enumerate(cases):
        bad, out = _model_sweep(cli, tmp_path, f"d{k}", "", *options)
        err = bad.stderr.strip()
        assert bad.exit_code == 2 and len(err.splitlines()) == 1 and needle in err, (options, err)
        assert not (tmp_path / f"work-d{k}").exists() and not out.exists()


def test_the_batched_solver_through_the_cli(cli, tmp_path):
    r, out = _model_sweep(cli, tmp_path, "b", "", "--solver", "batched")
    assert r.exit_code == 0, r.output
    header = json.loads(out.with_suffix(".json").read_text())
    assert header["config"]["solver"] == "batched" and header["stats"]["run"]["solver"] == "batched"


def test_the_gpu_code_path_without_array_api_compat_is_one_line_before_any_work(tmp_path):
    """A base install (README command 1) has no array-api-compat: --solver batched-array-api is refused
    naming the package, before a chunk is written. The import is made to fail as Python lets a program
    do it (``sys.modules[name] = None``), in a process of its own."""
    cfg = tmp_path / "tiny.yaml"
    cfg.write_text(CONFIG)
    code = ("import sys; sys.modules['array_api_compat'] = None; from designkit.cli import main; "
            "sys.argv = ['designkit'] + sys.argv[1:]; main()")
    r = _run([sys.executable, "-c", code, "sweep", "--config", str(cfg), "--workdir", str(tmp_path / "w"),
              "--out", str(tmp_path / "t.npz"), "--solver", "batched-array-api"])
    err = r.stderr.strip()
    assert r.returncode == 2 and len(err.splitlines()) == 1, err
    assert "needs array-api-compat" in err and "pip install array-api-compat" in err
    assert not (tmp_path / "w").exists() and not (tmp_path / "t.npz").exists()


def test_the_table_records_its_engine_version_and_another_engines_chunks_are_not_resumed(tmp_path):
    """A table says which arithmetic built it (tables without the key are version 1, the shipped ones), and
    a working folder whose chunks another engine version computed is refused in one line, not mixed in."""
    from designkit import InputError
    from designkit.sweep import ENGINE_VERSION, SweepConfig, prepare_workdir, run_sweep
    from designkit.tables.store import load_table

    cfg = SweepConfig(name="ev", intervals=6, trials=10, noise_ratio=(0.02,), contact_s=(1.0,), fidelity="ideal")
    table = load_table(run_sweep(cfg, tmp_path / "w", backend="sequential"))
    assert table.header["engine_version"] == ENGINE_VERSION >= 2
    assert "engine_version" not in load_table("svm-paper").header  # built by version 1
    meta = tmp_path / "w" / "sweep.json"
    old = json.loads(meta.read_text())
    assert old["engine_version"] == ENGINE_VERSION
    old.pop("engine_version")  # a folder a version-1 designkit wrote
    meta.write_text(json.dumps(old))
    with pytest.raises(InputError, match="engine version 1.*--fresh"):
        prepare_workdir(cfg, tmp_path / "w", resume=True, fresh=False)
    prepare_workdir(cfg, tmp_path / "w", resume=True, fresh=True)  # --fresh discards them
    assert json.loads(meta.read_text())["engine_version"] == ENGINE_VERSION
