"""What keeps a fresh ``designkit`` process quick (issue 16): shipped tables are checked by their content
hash instead of pydantic schemas, typer's pydantic coercion is bypassed for plain numbers, and only the
command asked for is built. Timings are in benchmarks/bench_startup.py; these tests check behaviour."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from designkit._schemas import schemas, validate
from designkit.tables.store import SHIPPED_CONTENT_HASHES, list_tables, load_table

REPO = Path(__file__).resolve().parent.parent


def _py(*args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, env=env, timeout=120)


@pytest.mark.parametrize("name", list_tables())
def test_every_shipped_table_is_listed_by_hash_and_passes_its_schema(name):
    t = load_table(name)
    assert t.shipped, (f"shipped table {name} (content hash {t.header['content_hash']}) is not in "
                       "designkit.tables.store.SHIPPED_CONTENT_HASHES: add it there")
    validate(schemas()["table"], t.header, name)  # the step its hash stands for
    validate(schemas()["sensor"], dict(t.header["sensor"]), name)


def test_a_copied_table_is_schema_checked_and_an_edited_one_refused(tmp_path):
    src = load_table("ideal-paper").path
    for suffix in (".npz", ".json"):
        (tmp_path / f"t{suffix}").write_bytes(src.with_suffix(suffix).read_bytes())
    assert load_table(tmp_path / "t.npz").shipped  # same content, wherever it lies
    header = json.loads((tmp_path / "t.json").read_text())
    header["threshold"] = "0.9"  # a string: the schema refuses it, though the hash claims shipped
    (tmp_path / "t.json").write_text(json.dumps(header))
    with pytest.raises(ValueError, match="threshold"):
        load_table(tmp_path / "t.npz")
    header["threshold"], header["sensor"]["effusivity"] = 0.9, 900.0  # valid, but not the shipped content
    (tmp_path / "t.json").write_text(json.dumps(header))
    with pytest.raises(ValueError, match="content check"):
        load_table(tmp_path / "t.npz")
    assert "sha256:" + "0" * 64 not in SHIPPED_CONTENT_HASHES


def test_a_table_question_from_the_cli_imports_no_pydantic():
    r = _py("-X", "importtime", "-m", "designkit", "min-contact", "--e1", "35000", "--e2", "20000")
    assert r.returncode == 0, r.stderr
    imported = {line.split("|")[-1].strip() for line in r.stderr.splitlines() if line.startswith("import time")}
    assert "designkit.query" in imported and "numpy" in imported
    assert not {"pydantic", "typer._adapters", "sklearn", "scipy", "matplotlib", "numpy.ma"} \
        & imported


def test_the_lean_app_answers_as_the_whole_app(cli):
    args = ["min-contact", "--e1", "35000", "--e2", "2e4", "--noise", ".05", "--json"]
    r = _py("-m", "designkit", *args)
    whole = cli(*args)
    assert r.returncode == whole.exit_code == 0, r.stderr
    a, b = json.loads(r.stdout), json.loads(whole.stdout)
    assert a == b and a["objects"][1]["e_range"][0] == 20000.0


@pytest.mark.parametrize("value, message", [("abc", "Invalid value for '--e1'"), ("12abc", "Invalid value")])
def test_odd_numbers_go_to_typers_own_coercion_and_its_messages(cli, value, message):
    r = cli("min-contact", "--e1", value, "--e2", "20000")
    assert r.exit_code == 2 and message in r.output, r.output
    r = _py("-m", "designkit", "min-contact", "--e1", value, "--e2", "20000")
    assert r.returncode == 2 and message in r.stderr, r.stderr
