"""A sweep's main process killed with ``kill -9`` takes its workers with it (issue 36, class 12).

On c8fe4cc its two loky workers, and through them the resource tracker, lived on for about 5 minutes
(loky's idle timeout). Each worker now watches its parent (designkit._workers.watch_parent)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent

CONFIG = """\
name: orphans
sensor: paper
fidelity: svm
effusivity: {min: 0, max: 40000, intervals: 40}
trials: 50
folds: 3
seed: 3
max_repeats: 2
noise_ratio: [0.005, 0.01, 0.02, 0.04]
contact_s: [1, 2, 4, 8]
blocks: 1
"""


def _descendants(pid: int) -> set[int]:
    """Every live process below ``pid`` (from /proc)."""
    parents: dict[int, int] = {}
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                stat = (d / "stat").read_text()
            except OSError:
                continue
            parents[int(d.name)] = int(stat.rsplit(")", 1)[1].split()[1])
    out, todo = set(), [pid]
    while todo:
        p = todo.pop()
        kids = {c for c, pp in parents.items() if pp == p}
        todo += list(kids - out)
        out |= kids
    return out


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads /proc to find the workers")
def test_kill_9_of_a_sweep_leaves_no_worker_behind(tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(CONFIG)
    env = {**os.environ, "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    proc = subprocess.Popen([sys.executable, "-m", "designkit", "sweep", "--config", str(cfg), "--workdir",
                             str(tmp_path / "w"), "--out", str(tmp_path / "t.npz"), "--jobs", "2"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        kids: set[int] = set()
        while time.monotonic() < deadline:  # the pool is up: two workers (and the trackers) below it
            kids = _descendants(proc.pid)
            if len(kids) >= 4:  # two workers, two resource trackers
                break
            time.sleep(0.2)
        assert len(kids) >= 4, kids
        time.sleep(1.0)  # the workers' initializers have run
        kids = _descendants(proc.pid)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)
        deadline = time.monotonic() + 20  # c8fe4cc: about 300 s
        while time.monotonic() < deadline and any(_alive(k) for k in kids):
            time.sleep(0.2)
        left = [k for k in kids if _alive(k)]
        assert not left, [Path(f"/proc/{k}/cmdline").read_bytes()[:120] for k in left]
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)  # whatever this test started, whatever the outcome
        except ProcessLookupError:
            pass
