"""What keeps a fresh ``designkit`` process quick (issue 16): shipped tables are checked by their content
hash instead of pydantic schemas, typer is the last release without pydantic coercion (pyproject.toml), and
only the command asked for is built. Timings are in benchmarks/bench_startup.py; these tests check behaviour."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import read_until_closed
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
                       "designkit.tables.store.SHIPPED_CONTENT_HASHES: add it to SHIPPED_TABLES")
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


def _imported(r: subprocess.CompletedProcess) -> set[str]:
    """The modules a ``python -X importtime`` run imported."""
    assert r.returncode == 0, r.stderr
    return {line.split("|")[-1].strip() for line in r.stderr.splitlines() if line.startswith("import time")}


#: What a table question never needs: the exact route (simulation, SVM, its Monte Carlo bound), pydantic (the
#: schemas of files it does not read, typer's adapters), scipy, scikit-learn, joblib, matplotlib, and rich when
#: its answer is piped (plain lines: designkit.cli._app.text_console).
_NOT_FOR_A_TABLE_QUESTION = {"pydantic", "typer._adapters", "rich", "sklearn", "scipy", "scipy.optimize", "joblib",
                             "matplotlib", "numpy.ma", "designkit.query.exact", "designkit.query.ideal_mc_bound",
                             "designkit.simulation", "designkit.recognition.svm", "designkit.recognition.features"}


def test_a_table_question_from_the_cli_imports_no_pydantic_and_not_the_exact_route():
    imported = _imported(_py("-X", "importtime", "-m", "designkit", "min-contact", "--e1", "35000", "--e2", "20000"))
    assert "designkit.query" in imported and "numpy" in imported and "designkit.query.table" in imported
    assert not _NOT_FOR_A_TABLE_QUESTION & imported


def _on_a_terminal(*args: str, env: dict | None = None) -> str:
    """What ``python ARGS`` prints with stdin, stdout and stderr on a pseudo-terminal (NO_COLOR unset unless
    ``env`` sets it)."""
    import pty

    env = {**{k: v for k, v in os.environ.items() if k != "NO_COLOR"},
           "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""), **(env or {})}
    main, sub = pty.openpty()
    p = subprocess.Popen([sys.executable, *args], stdin=sub, stdout=sub, stderr=sub, env=env)
    os.close(sub)
    out = read_until_closed(main)
    p.wait(timeout=120)
    os.close(main)
    assert p.returncode == 0, out
    return out.decode("utf-8", "replace")


def test_a_question_on_a_terminal_is_styled_without_rich():
    """On a terminal the answer's parts get typer's ANSI styles (rich's console cost a fresh question about
    25 ms); NO_COLOR prints the plain text."""
    code = ("import sys, runpy; sys.argv = ['designkit', 'min-contact', '--e1', '35000', '--e2', '20000']\n"
            "try:\n    runpy.run_module('designkit', run_name='__main__')\nexcept SystemExit:\n    pass\n"
            "print('rich imported:', 'rich' in sys.modules)")
    out = _on_a_terminal("-c", code)
    assert "shortest contact: \x1b[" in out and "rich imported: False" in out, out
    plain = _on_a_terminal("-c", code, env={"NO_COLOR": "1"})
    assert "\x1b[" not in plain and "shortest contact: 1.23 s" in plain, plain


def test_the_library_loads_a_question_route_on_first_use():
    code = ("import sys, designkit.query as q\n"
            "assert 'numpy' not in sys.modules, 'import designkit.query loaded numpy'\n"
            "a = q.min_contact(35000, 20000)\n"
            "print(a.route, a.value)")
    r = _py("-X", "importtime", "-c", code)
    imported = _imported(r)
    assert r.stdout.split()[0] == "table" and float(r.stdout.split()[1]) > 0
    assert not _NOT_FOR_A_TABLE_QUESTION & imported
    # the exact route is there when asked for, by name or through the registry
    from designkit import query
    from designkit.query import exact

    assert query.QUESTIONS["min-contact"].route("exact") is exact.exact_min_contact is query.exact_min_contact
    assert set(query.__all__) <= set(dir(query))
    with pytest.raises(AttributeError, match="no_such_name"):
        query.no_such_name  # noqa: B018


def test_the_lean_app_answers_as_the_whole_app(cli):
    args = ["min-contact", "--e1", "35000", "--e2", "2e4", "--noise", ".05", "--json"]
    r = _py("-m", "designkit", *args)
    whole = cli(*args)
    assert r.returncode == whole.exit_code == 0, r.stderr
    a, b = json.loads(r.stdout), json.loads(whole.stdout)
    assert a == b and a["objects"][1]["effusivity_range"][0] == 20000.0


@pytest.mark.parametrize("value, message", [("abc", "Invalid value for '--e1'"), ("12abc", "Invalid value")])
def test_odd_numbers_get_typers_own_messages(cli, value, message):
    r = cli("min-contact", "--e1", value, "--e2", "20000")
    assert r.exit_code == 2 and message in r.output, r.output
    r = _py("-m", "designkit", "min-contact", "--e1", value, "--e2", "20000")
    assert r.returncode == 2 and message in r.stderr, r.stderr


@pytest.mark.parametrize("name", list_tables())
def test_every_shipped_table_is_listed_by_file_digest_and_its_arrays_pass_the_long_check(name):
    import zipfile

    from designkit.tables.store import SHIPPED_FILE_DIGESTS, _zip_members, content_hash, file_digest

    t = load_table(name)
    with zipfile.ZipFile(t.path) as z:
        digest = file_digest(t.path.with_suffix(".json").read_bytes(), _zip_members(z))
    assert digest in SHIPPED_FILE_DIGESTS, (f"shipped table {name} (files {digest}) is not in "
                                            "designkit.tables.store.SHIPPED_FILE_DIGESTS: add it to SHIPPED_TABLES")
    assert type(t.arrays).__name__ == "_NpzArrays", (f"shipped table {name} has no array digests in "
                                                     "designkit/data/shipped_members.json: run python "
                                                     "benchmarks/rehash_tables.py --members")
    assert content_hash(dict(t.arrays), t.header) == t.header["content_hash"]  # what the digest stands for
    assert not load_table(name, thorough=True).arrays.__class__.__name__.startswith("_")  # the long way


def test_a_shipped_table_decompresses_only_the_arrays_a_question_reads():
    # a fresh process: within this one, another test's question may have cached the table's view
    code = """
import numpy as np
from designkit.query import min_contact
from designkit.tables.store import _NpzArrays, load_table
t = load_table("svm-paper")
assert isinstance(t.arrays, _NpzArrays) and not t.arrays._loaded
assert set(t.arrays) == set(t.header["arrays"]) and "fits" in t.arrays
assert min_contact(35000, 20000, noise_c=0.05, delta_t_c=10, table=t).value > 0
read = set(t.arrays._loaded)
assert read and "fits" not in read, read
full = load_table(t.path, verify=False)  # the long way: every array from the file
for k in read:
    np.testing.assert_array_equal(t.arrays[k], full.arrays[k])
print(sorted(read))
"""
    r = _py("-c", code)
    assert r.returncode == 0, r.stderr
    assert "delta_up" in r.stdout


def test_one_changed_byte_in_a_shipped_npz_is_refused_in_one_line(tmp_path):
    src = load_table("svm-paper").path
    (tmp_path / "t.json").write_bytes(src.with_suffix(".json").read_bytes())
    blob = bytearray(src.read_bytes())
    (tmp_path / "t.npz").write_bytes(bytes(blob))
    assert load_table(tmp_path / "t.npz").shipped  # the same bytes elsewhere: the shipped content
    blob[len(blob) // 2] ^= 0x01  # inside some array's compressed stream: its CRC no longer matches
    (tmp_path / "t.npz").write_bytes(bytes(blob))
    t = load_table(tmp_path / "t.npz")  # the directory is unchanged: the array is checked when read
    with pytest.raises(ValueError, match=r"t.npz: array \w+ is corrupted or truncated \(BadZipFile\)"):
        for name in t.arrays:
            t.arrays[name]
    with pytest.raises(ValueError, match="corrupted|content check"):  # and the long way refuses the file
        load_table(tmp_path / "t.npz", thorough=True)


def test_an_uncompressed_table_is_mapped_and_reads_the_same_arrays(tmp_path, monkeypatch):
    """write_table(compress=False): same content hash; a shipped one's arrays are mapped from the file, read-only."""
    import zipfile

    import numpy as np

    from designkit.tables import store

    src = load_table("svm-paper", thorough=True)
    header = {k: v for k, v in src.header.items() if k not in ("content_hash", "schema_version")}
    path = store.write_table(tmp_path / "svm-paper.npz", header, dict(src.arrays), compress=False)
    assert not isinstance(load_table(path).arrays, store._NpzArrays)  # not a shipped file: the long way
    with zipfile.ZipFile(path) as z:  # ship it, as a rebuilt table is shipped
        digest = store.file_digest(path.with_suffix(".json").read_bytes(), store._zip_members(z))
    monkeypatch.setattr(store, "SHIPPED_FILE_DIGESTS", store.SHIPPED_FILE_DIGESTS | {digest})
    assert not isinstance(load_table(path).arrays, store._NpzArrays)  # no member digests listed: the long way
    monkeypatch.setitem(store.SHIPPED_TABLES, "svm-paper-stored", (src.header["content_hash"], digest))
    monkeypatch.setitem(store.shipped_member_digests(), "svm-paper-stored", store.member_digests(path))
    t = load_table(path)
    assert isinstance(t.arrays, store._NpzArrays) and t.shipped
    assert t.header["content_hash"] == src.header["content_hash"]
    assert path.stat().st_size > 4 * src.path.stat().st_size  # stored, not deflated
    for name in src.arrays:
        a = t.arrays[name]
        np.testing.assert_array_equal(a, src.arrays[name])
        assert a.dtype == src.arrays[name].dtype and not a.flags.writeable
    import pickle

    again = pickle.loads(pickle.dumps(t))  # a worker maps its own copy
    np.testing.assert_array_equal(again.arrays["delta_up"], src.arrays["delta_up"])


def test_reading_a_sensor_file_builds_the_sensor_files_schema_only():
    code = ("from designkit import _schemas\n"
            "from designkit.sensor import load_sensor\n"
            f"s = load_sensor({str(REPO / 'tests' / 'data' / 'rig_sensor.yaml')!r})\n"
            "print(s.name, *sorted(_schemas.schemas()))")
    r = _py("-c", code)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ["rig", "sensor"]  # the sweep, table and sidecar schemas not built
    assert {k: schemas()[k].__name__ for k in ("sensor", "sweep", "table", "sidecar")} == {
        "sensor": "SensorFile", "sweep": "SweepFile", "table": "TableHeader", "sidecar": "TrialSidecar"}
    assert schemas()["sensor"] is schemas()["sensor"]  # built once per process
    with pytest.raises(KeyError):
        schemas()["nope"]


def test_the_cli_uses_typer_through_its_public_names_only():
    # typer 0.29's pydantic coercion was once bypassed through typer._coercion; pyproject.toml pins typer
    # below it instead, and the error handling reads click's errors as the public typer.TyperException
    import ast

    for path in sorted((REPO / "designkit").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = ([node.module or ""] if isinstance(node, ast.ImportFrom)
                     else [a.name for a in node.names] if isinstance(node, ast.Import) else [])
            assert not any(n.startswith(("typer._", "click")) for n in names), f"{path}: imports {names}"


@pytest.mark.parametrize("text", ["svm-fine", "", "a [b] c", "[bold]x[/]", "x\\", "x\\\\", "\\[red]", "e [J s^-1/2]",
                                  "50% [", "]", "C:\\tables\\"])
def test_the_clis_escape_is_richs(text):
    from rich.markup import escape as rich_escape

    from designkit.cli._app import escape

    assert escape(text) == rich_escape(text)
