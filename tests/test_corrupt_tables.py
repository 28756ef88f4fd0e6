"""The corrupted-table matrix: every edit of a table's header or arrays, in every command that
reads tables, is refused with exit status 2 and one line naming what is wrong (issue 15).

A table's content hash covers its header and arrays (schema version 2), so a plain edit fails the
hash; the re-hashed variants stand for an editor who recomputes it, and are caught by the header's
schema and its consistency with the arrays. The base table answers every command (exit 0), so a
refusal is the corruption's doing.
"""

from __future__ import annotations

import json
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

from designkit.sweep.config import SweepConfig
from designkit.tables.store import content_hash, load_table, table_header, write_table

N = 10  # intervals of the small table


def _arrays() -> dict[str, np.ndarray]:
    contact = np.array([1.0, 2.0, 4.0])
    ratio = np.array([0.001, 0.01])
    base = 2000.0 * ratio[:, None, None] / 0.005 / np.sqrt(contact)[None, :, None] * np.ones((1, 1, N))
    out = {"delta_up": base, "delta_down": base * 0.9}
    for k in ("delta_up", "delta_down"):
        out[f"{k}_lo"] = out[k] * 0.9
        out[f"{k}_hi"] = out[k] * 1.1
        out[f"{k}_ideal"] = out[k] * 0.5
    out["fits"] = np.ones((2, 3), dtype=np.int64)
    out["chunk_wall_s"] = np.zeros((2, 3))
    return out


@pytest.fixture(scope="module")
def base(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("base")
    cfg = SweepConfig(name="small", intervals=N, noise_ratio=(0.001, 0.01), contact_s=(1.0, 2.0, 4.0))
    arrays = _arrays()
    return write_table(folder / "small.npz", table_header(cfg, arrays), arrays)


def _commands(p: str, out: Path) -> dict[str, list[str]]:
    pair = ["--e1", "35000", "--e2", "20000"]
    return {
        "tables show": ["tables", "show", p],
        "min-contact": ["min-contact", *pair, "--noise", "0.05", "--delta-t", "10", "--table", p],
        "max-noise": ["max-noise", *pair, "--contact", "2", "--delta-t", "10", "--table", p],
        "min-delta-t": ["min-delta-t", *pair, "--contact", "2", "--noise", "0.05", "--table", p],
        "delta-e": ["delta-e", "--e", "20000", "--contact", "2", "--noise", "0.05", "--delta-t", "10", "--table", p],
        "distinguishable": ["distinguishable", *pair, "--contact", "2", "--noise", "0.05", "--delta-t", "10",
                            "--table", p],
        "export": ["export", "--table", p, "--format", "json", "--out", str(out / "x.json")],
    }


# ----------------------------------------------------------------- corruptions
def _header(p: Path) -> dict:
    return json.loads(p.with_suffix(".json").read_text())


def _put(p: Path, h, rehash: bool = False) -> None:
    if rehash:
        with np.load(p, allow_pickle=False) as z:
            h["content_hash"] = content_hash({k: z[k] for k in z.files}, h)
    p.with_suffix(".json").write_text(json.dumps(h))


def _edit(fn, rehash=False):
    def apply(p: Path) -> None:
        h = _header(p)
        fn(h)
        _put(p, h, rehash)
    return apply


def _arrays_edit(fn):
    def apply(p: Path) -> None:
        with np.load(p, allow_pickle=False) as z:
            a = {k: z[k] for k in z.files}
        fn(a)
        np.savez_compressed(p, **a)
    return apply


def _axis(h, name):
    return next(a for a in h["axes"] if a["name"] == name)


def _drop(key):
    return lambda h: h.pop(key)


def _set(path, value):
    def fn(h):
        d = h
        for k in path[:-1]:
            d = d[k]
        d[path[-1]] = value
    return fn


def _swap(a):
    a["delta_up"], a["delta_down"] = a["delta_down"], a["delta_up"]


def _bytes(fn):
    def apply(p: Path) -> None:
        p.write_bytes(fn(p.read_bytes()))
    return apply


def _flip(b: bytes) -> bytes:
    d = bytearray(b)
    d[len(d) // 2] ^= 0xFF
    return bytes(d)


def _header_bytes(fn):
    def apply(p: Path) -> None:
        j = p.with_suffix(".json")
        j.write_text(fn(j.read_text()))
    return apply


CORRUPTIONS = {
    # header edits (the hash over header and arrays catches them)
    "contact axis value 2.0 -> 2.2": _edit(lambda h: _axis(h, "contact_s")["values"].__setitem__(1, 2.2)),
    "noise axis value": _edit(lambda h: _axis(h, "noise_ratio")["values"].__setitem__(0, 0.002)),
    "e_ref value": _edit(lambda h: _axis(h, "e_ref")["values"].__setitem__(0, 1.0)),
    "effusivity range max": _edit(_set(["effusivity", "max"], 44000.0)),
    "effusivity range min": _edit(_set(["effusivity", "min"], 100.0)),
    "fidelity svm -> ideal": _edit(_set(["fidelity"], "ideal")),
    "sensor effusivity": _edit(_set(["sensor", "effusivity"], 900.0)),
    "sensor name": _edit(_set(["sensor", "name"], "other")),
    "threshold": _edit(_set(["threshold"], 0.8)),
    "model added": _edit(_set(["model"], {"name": "contact", "conductance_w_m2k": 1000.0})),
    "table name": _edit(_set(["name"], "renamed")),
    "drop one contact value": _edit(lambda h: _axis(h, "contact_s")["values"].pop()),
    "old schema version 1": _edit(_set(["schema_version"], 1)),
    "unknown schema version": _edit(_set(["schema_version"], 99)),
    "hash removed": _edit(_drop("content_hash")),
    "hash garbage": _edit(_set(["content_hash"], "sha256:" + "0" * 64)),
    "key axes dropped": _edit(_drop("axes")),
    "key effusivity dropped": _edit(_drop("effusivity")),
    "key sensor dropped": _edit(_drop("sensor")),
    "key fidelity dropped": _edit(_drop("fidelity")),
    "key arrays dropped": _edit(_drop("arrays")),
    "key format dropped": _edit(_drop("format")),
    "threshold as a string": _edit(_set(["threshold"], "0.9")),
    "header truncated": _header_bytes(lambda t: t[: len(t) // 2]),
    "header is a list": _header_bytes(lambda t: "[1, 2]"),
    "header empty": _header_bytes(lambda t: ""),
    "header not UTF-8": _bytes(lambda b: b) if False else (lambda p: p.with_suffix(".json").write_bytes(b"\xff\xfe{")),
    # array edits
    "npz truncated": _bytes(lambda b: b[:200]),
    "npz byte flipped": _bytes(_flip),
    "npz empty": _bytes(lambda b: b""),
    "arrays swapped": _arrays_edit(_swap),
    "array values edited": _arrays_edit(lambda a: a.__setitem__("delta_up", a["delta_up"] + 1)),
    "array dropped": _arrays_edit(lambda a: a.pop("delta_up_lo")),
    "array added": _arrays_edit(lambda a: a.__setitem__("extra", np.zeros(3))),
    "array dtype float32": _arrays_edit(lambda a: a.__setitem__("delta_up", a["delta_up"].astype(np.float32))),
    "array reshaped": _arrays_edit(lambda a: a.__setitem__("delta_up", a["delta_up"][:, :2])),
    # re-hashed edits: the schema and consistency checks catch them
    "rehashed: drop one contact value": _edit(lambda h: _axis(h, "contact_s")["values"].pop(), rehash=True),
    "rehashed: drop one e_ref value": _edit(lambda h: _axis(h, "e_ref")["values"].pop(), rehash=True),
    "rehashed: axis units": _edit(lambda h: _axis(h, "contact_s").__setitem__("units", "ms"), rehash=True),
    "rehashed: unknown fidelity": _edit(_set(["fidelity"], "bogus"), rehash=True),
    "rehashed: unknown model": _edit(_set(["model"], {"name": "nosuch"}), rehash=True),
    "rehashed: effusivity width": _edit(_set(["effusivity", "width"], 1000.0), rehash=True),
    "rehashed: effusivity max": _edit(_set(["effusivity", "max"], 44000.0), rehash=True),
    "rehashed: effusivity units": _edit(_set(["effusivity", "units"], "W"), rehash=True),
    "rehashed: missing threshold": _edit(_drop("threshold"), rehash=True),
    "rehashed: contact axis decreasing": _edit(lambda h: _axis(h, "contact_s")["values"].reverse(), rehash=True),
    "rehashed: negative sensor effusivity": _edit(_set(["sensor", "effusivity"], -1.0), rehash=True),
    "rehashed: sensor field a list": _edit(_set(["sensor", "tau_s"], [1, 2]), rehash=True),
    "rehashed: array shape in header": _edit(_set(["arrays", "fits", "shape"], [2, 2]), rehash=True),
    "rehashed: config disagrees": _edit(_set(["config", "e_max"], 44000.0), rehash=True),
    "rehashed: ideal with interval arrays": _edit(_set(["fidelity"], "ideal"), rehash=True),
    "rehashed: threshold out of range": _edit(_set(["threshold"], 2.0), rehash=True),
    "rehashed: axis name unknown": _edit(lambda h: _axis(h, "noise_ratio").__setitem__("name", "bogus"), rehash=True),
}


def _copy(base: Path, folder: Path) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for suffix in (".npz", ".json"):
        shutil.copy(base.with_suffix(suffix), folder / f"small{suffix}")
    return folder / "small.npz"


@pytest.fixture(scope="module")
def cli():
    """The CLI in-process, its click command built once (typer rebuilds it per invoke: ~0.1 s)."""
    import typer.testing

    from designkit.cli import app

    # typer's runner rebuilds the click command on every invoke (~0.1 s): build it once
    build = typer.testing._get_command
    command = build(app)
    typer.testing._get_command = lambda a: command if a is app else build(a)
    runner = typer.testing.CliRunner()

    def invoke(*args: str):
        return runner.invoke(app, [str(a) for a in args])

    yield invoke
    typer.testing._get_command = build


def test_the_base_table_answers_every_command(base, cli, tmp_path):
    load_table(base)
    for name, args in _commands(str(base), tmp_path).items():
        r = cli(*args)
        assert r.exit_code == 0, (name, r.output)


def test_every_corruption_is_refused_by_every_command(base, cli, tmp_path):
    t0 = time.perf_counter()
    refused, failures = 0, []
    for i, (what, corrupt) in enumerate(CORRUPTIONS.items()):
        p = _copy(base, tmp_path / f"c{i}")
        corrupt(p)
        for cmd, args in _commands(str(p), tmp_path / f"c{i}").items():
            r = cli(*args)
            err = [line for line in r.stderr.splitlines() if line.strip()]
            ok = (r.exit_code == 2 and len(err) == 1 and err[0].startswith("Error: ")
                  and "Traceback" not in r.output and not isinstance(r.exception, Exception)
                  or r.exit_code == 2 and isinstance(r.exception, SystemExit) and len(err) == 1)
            if ok:
                refused += 1
            else:
                failures.append(f"{what} / {cmd}: exit {r.exit_code}: {r.output.strip()[-300:]}")
    total = len(CORRUPTIONS) * 7
    print(f"\ncorrupted tables: {refused}/{total} refused ({len(CORRUPTIONS)} corruptions x 7 commands) "
          f"in {time.perf_counter() - t0:.1f} s")
    assert not failures, "\n".join(failures)
    assert len(CORRUPTIONS) >= 27 and refused == total
