"""The command-line application runs BLAS on one thread unless the user chose (designkit.cli)."""

import os
import subprocess
import sys

import pytest

from designkit.cli import BLAS_THREAD_VARIABLES

PROBE = ("import designkit.cli, numpy; from threadpoolctl import threadpool_info; "
         "print(sorted({i['num_threads'] for i in threadpool_info() if i['user_api'] == 'blas'}))")


def _blas_threads(**extra: str) -> str:
    env = {k: v for k, v in os.environ.items() if k not in BLAS_THREAD_VARIABLES}
    env.update(extra)
    out = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, check=True)
    return out.stdout.strip()


def test_cli_process_runs_blas_on_one_thread_by_default():
    pytest.importorskip("threadpoolctl")
    assert _blas_threads() == "[1]"


def test_a_users_thread_setting_is_kept():
    pytest.importorskip("threadpoolctl")
    if (os.cpu_count() or 1) < 2:
        pytest.skip("one CPU: BLAS runs one thread whatever is asked")
    assert _blas_threads(OMP_NUM_THREADS="2") == "[2]"


def test_importing_the_library_leaves_the_environment_alone():
    env = {k: v for k, v in os.environ.items() if k not in BLAS_THREAD_VARIABLES}
    code = "import os, designkit, designkit.query; print(os.environ.get('OPENBLAS_NUM_THREADS'))"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "None"
