"""Table format: round trip, integrity checks, and the shipped tables' grids."""

from __future__ import annotations

import json

import numpy as np
import pytest

from designkit import InputError
from designkit.sweep import SweepConfig
from designkit.query import table as q
from designkit.query.table import DEFAULT_TABLE
from designkit.tables.store import SCHEMA_VERSION, content_hash, list_tables, load_table, table_header, write_table


def _small(tmp_path, name="t"):
    cfg = SweepConfig(name=name, intervals=10, noise_ratio=(0.001, 0.01), contact_s=(1.0, 2.0), fidelity="ideal")
    rng = np.random.default_rng(0)
    arrays = {"delta_up": rng.uniform(100, 1000, (2, 2, 10)), "delta_down": rng.uniform(100, 1000, (2, 2, 10)),
              "fits": np.zeros((2, 2), dtype=np.int64), "chunk_wall_s": np.zeros((2, 2))}
    return write_table(tmp_path / f"{name}.npz", table_header(cfg, arrays), arrays), arrays


def test_round_trip_and_header(tmp_path):
    path, arrays = _small(tmp_path)
    t = load_table(path)
    for k, v in arrays.items():
        np.testing.assert_array_equal(t.arrays[k], v)
    h = t.header
    assert h["schema_version"] == SCHEMA_VERSION and h["format"] == "designkit-table"
    assert [a["name"] for a in h["axes"]] == ["noise_ratio", "contact_s", "e_ref"]
    assert h["axes"][1]["units"] == "s" and "J s^-1/2" in h["axes"][2]["units"]
    assert h["content_hash"] == content_hash(arrays, h) != content_hash(arrays)  # header and arrays
    assert h["sensor"]["effusivity"] == 892.0 and h["designkit_version"]
    assert t.sensor.name == "paper"
    # loaded without pickle: the npz holds plain numeric arrays only
    with np.load(path, allow_pickle=False) as z:
        assert all(z[k].dtype != object for k in z.files)


def test_corrupted_truncated_or_edited_tables_are_refused(tmp_path):
    path, _ = _small(tmp_path)
    data = bytearray(path.read_bytes())
    # flip one byte inside the compressed payload
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(InputError, match="corrupted|content check"):
        load_table(path)
    path, _ = _small(tmp_path)
    path.write_bytes(path.read_bytes()[:200])  # truncated
    with pytest.raises(InputError, match="corrupted or truncated"):
        load_table(path)
    path, arrays = _small(tmp_path)
    # valid npz, different numbers: the hash catches it
    edited = dict(arrays, delta_up=arrays["delta_up"] + 1)
    np.savez_compressed(path, **edited)
    with pytest.raises(InputError, match="content check"):
        load_table(path)
    path, _ = _small(tmp_path)
    header = json.loads(path.with_suffix(".json").read_text())
    header["schema_version"] = 99
    path.with_suffix(".json").write_text(json.dumps(header))
    with pytest.raises(InputError, match="schema version 99"):
        load_table(path)
    path.with_suffix(".json").write_text("{ not json")
    with pytest.raises(InputError, match="not valid JSON"):
        load_table(path)
    with pytest.raises(InputError, match="no table"):
        load_table(tmp_path / "missing")


def test_object_arrays_are_refused(tmp_path):
    cfg = SweepConfig(name="x", intervals=2, fidelity="ideal", contact_s=(1.0,))
    with pytest.raises(InputError, match="object"):
        write_table(tmp_path / "x.npz", table_header(cfg, {}), {"bad": np.array([{"a": 1}], dtype=object)})


def test_shipped_ideal_table_grid():
    assert "ideal-paper" in list_tables()
    t = load_table("ideal-paper")
    ax = t.axes
    assert t.fidelity == "ideal" and t.threshold == 0.9 and t.sensor.name == "paper"
    assert ax["noise_ratio"].min() == pytest.approx(0.0005) and ax["noise_ratio"].max() == pytest.approx(0.02)
    for r in (0.001, 0.002, 0.005, 0.01, 0.02):
        assert np.isclose(ax["noise_ratio"], r).any()
    assert ax["contact_s"].min() == 0.5 and ax["contact_s"].max() == 10
    assert ax["e_ref"].size == 500 and t.header["effusivity"]["max"] == 40000
    assert np.all(np.diff(np.log(ax["noise_ratio"])) > 0)


def test_shipped_svm_table_grid():
    t = load_table("svm-paper")
    ax = t.axes
    ideal = load_table("ideal-paper").axes
    assert t.fidelity == "svm" and t.header["trials"] == 100 and t.header["folds"] == 3
    assert ax["noise_ratio"].size >= 8 and ax["contact_s"].size >= 12 and ax["e_ref"].size == 500
    for r in (0.001, 0.002, 0.005, 0.01, 0.02):
        assert np.isclose(ax["noise_ratio"], r).any()
    for c in (1, 2, 3, 4):
        assert np.isclose(ax["contact_s"], c).any()
    assert ax["contact_s"].min() == 0.5 and ax["contact_s"].max() == 10
    # the ideal table is the denser grid of the same axes
    assert ideal["noise_ratio"].size > ax["noise_ratio"].size and ideal["contact_s"].size > ax["contact_s"].size
    # its Monte Carlo interval brackets delta, and the ideal bound is never above the SVM's delta
    a = t.arrays
    ok = ~np.isnan(a["delta_up"]) & ~np.isnan(a["delta_up_lo"])
    assert np.all(a["delta_up_lo"][ok] <= a["delta_up"][ok])
    both = ~np.isnan(a["delta_up"]) & ~np.isnan(a["delta_up_ideal"])
    assert np.all(a["delta_up_ideal"][both] <= a["delta_up"][both])


def test_tables_cli(cli, tmp_path):
    r = cli("tables", "list", "--json")
    assert r.exit_code == 0
    names = [row["name"] for row in json.loads(r.stdout)]
    assert "ideal-paper" in names
    r = cli("tables", "show", "ideal-paper", "--json")
    s = json.loads(r.stdout)
    assert s["fidelity"] == "ideal" and s["content_hash"].startswith("sha256:")
    r = cli("tables", "show", "ideal-paper")
    assert r.exit_code == 0 and "noise_ratio" in r.stdout and "[s, linear]" in r.stdout
    r = cli("tables", "show", "nope")
    assert r.exit_code == 2 and r.stderr.startswith("Error: no table")


def test_shipped_svm_table_reproduces_the_papers_guideline():
    """The paper (DOMAIN.md): 35,000 vs 20,000 at sigma 0.05 °C, dT 10 °C needs at least 2 s of
    contact on its 1 s grid of contact times, i.e. more than 1 s and at most 2 s. The shipped SVM
    table must say the same, bracket its answer by its Monte Carlo interval, and never need less
    contact than the ideal observer (a bound no classifier beats)."""
    ans = q.min_contact(35000, 20000, noise_c=0.05, delta_t_c=10.0)
    assert ans.table == DEFAULT_TABLE and ans.source == "table" and all(ans.in_grid.values())
    assert 1.0 < ans.value <= 2.0
    lo, hi = ans.interval
    assert lo <= ans.value and (hi is None or ans.value <= hi)
    assert ans.ideal is not None and ans.ideal <= ans.value


def test_the_header_records_the_model_and_tables_show_prints_it(tmp_path, cli):
    cfg = SweepConfig(name="c", intervals=4, noise_ratio=(0.005,), contact_s=(1.0,),
                      model={"name": "contact", "conductance_w_m2k": 1500})
    arrays = {"delta_up": np.full((1, 1, 4), 80.0), "delta_down": np.full((1, 1, 4), 80.0)}
    path = write_table(tmp_path / "c.npz", table_header(cfg, arrays), arrays)
    t = load_table(path)
    assert t.header["model"] == t.header["config"]["model"] == {"name": "contact", "conductance_w_m2k": 1500.0}
    assert t.model == cfg.model and SweepConfig.from_mapping(t.header["config"]) == cfg
    r = cli("tables", "show", str(path))
    assert r.exit_code == 0 and "model contact (conductance_w_m2k = 1500 W m^-2 K^-1)" in r.stdout
    assert json.loads(cli("tables", "show", str(path), "--json").stdout)["model"]["conductance_w_m2k"] == 1500
    rows = json.loads(cli("tables", "list", "--folder", str(tmp_path), "--json").stdout)
    assert [row["model"]["name"] for row in rows] == ["contact"]


def test_tables_from_before_the_seam_are_semi_infinite(cli):
    t = load_table("ideal-paper")
    assert "model" not in t.header["config"]  # built before the header recorded a model
    assert t.model.name == "semi-infinite" and SweepConfig.from_mapping(t.header["config"]).model.name == "semi-infinite"
    r = cli("tables", "show", "ideal-paper")
    assert r.exit_code == 0 and "model semi-infinite" in r.stdout


def test_every_shipped_table_loads_under_the_header_and_arrays_hash():
    for name in list_tables():
        t = load_table(name)
        assert t.header["schema_version"] == SCHEMA_VERSION == 2
        assert t.header["content_hash"] == content_hash(t.arrays, t.header) != content_hash(t.arrays)


def test_a_version_1_table_is_refused_with_the_remedy(tmp_path):
    path, arrays = _small(tmp_path)
    header = json.loads(path.with_suffix(".json").read_text())
    header["schema_version"] = 1
    header["content_hash"] = content_hash(arrays)  # the old, arrays-only hash
    path.with_suffix(".json").write_text(json.dumps(header))
    with pytest.raises(InputError, match="schema version 1.*rehash_tables.py"):
        load_table(path)


def test_table_listing_and_names_refuse_what_is_not_there(cli, tmp_path):
    for args, needle in ((["tables", "list", "--folder", str(tmp_path / "none")], "does not exist"),
                         (["tables", "list", "--folder", __file__], "not a folder"),
                         (["tables", "show", ""], "empty"), (["tables", "show", " "], "empty")):
        r = cli(*args)
        assert r.exit_code == 2 and needle in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.output


def test_a_chunk_is_checked_against_its_slot_and_sweep():
    from designkit.sweep.config import check_chunk, stamp_chunk

    cfg = SweepConfig(name="c", intervals=4, contact_s=(1.0, 2.0), fidelity="ideal")
    own = {"point": np.array([0]), "block": np.array(0), "contact_index": np.array(1)}
    stamped = stamp_chunk(own, cfg, (0,), 0, 1)
    check_chunk(stamped, cfg, (0,), 0, 1)
    check_chunk(own, cfg, (0,), 0, 1)  # written before chunks carried an identity: its indices decide
    with pytest.raises(InputError, match="sits in the slot"):
        check_chunk(stamped, cfg, (0,), 0, 0, "p000-b000-c000.npz")  # copied into another slot
    with pytest.raises(InputError, match="another sweep"):
        check_chunk(stamped, SweepConfig(name="c", intervals=5, contact_s=(1.0, 2.0), fidelity="ideal"), (0,), 0, 1)


def test_tables_list_of_a_folder_skips_a_damaged_table_and_says_when_there_are_none(cli, tmp_path):
    """One damaged table in a folder is said on stderr (one line) and the others are listed (the whole listing
    was refused); a folder without tables says so (it printed an empty line)."""
    import shutil

    from designkit._resources import shipped_tables_dir

    src = shipped_tables_dir()
    for suffix in (".npz", ".json"):
        shutil.copy(src / f"ideal-paper{suffix}", tmp_path / f"good{suffix}")
    shutil.copy(src / "svm-paper.json", tmp_path / "bad.json")
    (tmp_path / "bad.npz").write_bytes((src / "svm-paper.npz").read_bytes()[:1000])
    r = cli("tables", "list", "--folder", tmp_path, "--format", "csv")
    assert r.exit_code == 0, r.output
    assert [line.split(",")[0] for line in r.stdout.splitlines()] == ["name", "good"]
    assert r.stderr.startswith("skipped: table bad.npz is corrupted") and r.stderr.count("\n") == 1
    empty = tmp_path / "empty"
    empty.mkdir()
    r = cli("tables", "list", "--folder", empty)
    assert r.exit_code == 0 and r.stdout == f"no designkit tables in {empty}\n"


def test_a_sweep_config_given_as_a_table_is_named_for_what_it_is(cli):
    """It was read as a zip: "table svm-paper.yaml is corrupted or truncated (ValueError)"."""
    from designkit._resources import shipped_tables_dir

    cfg = shipped_tables_dir() / "svm-paper.yaml"
    r = cli("tables", "show", cfg)
    assert r.exit_code == 2 and r.stderr.count("\n") == 1
    assert "is a sweep config, not a table: build its table with 'designkit sweep --config" in r.stderr
