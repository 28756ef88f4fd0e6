"""designkit reproduce: the report is produced, its numbers agree with the tables and queries
they come from (recomputed here independently), figures are real PNGs, the real-robot part
skips cleanly without the data, and the CLI has --json."""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designkit._validation import InputError
from designkit_lab.reproduce import SECTIONS, ReproduceSettings, parse_only, reproduce
from designkit_lab.reproduce.matrices import (covering_intervals, matrix_delta_up, matrix_stats,
                                          staircase_percent)
from designkit_lab.reproduce.multiclass import bayes_accuracy
from designkit.tables.store import Table

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


# ------------------------------------------------------------------ helpers
def _brute_percent(delta_up: np.ndarray, width: float) -> float:
    """% indistinguishable pairs by looking at every pair (i < j): distinguishable iff j - i >= steps(i)."""
    n = delta_up.size
    indist = 0
    for i in range(n):
        for j in range(i + 1, n):
            d = delta_up[i]
            if not (np.isfinite(d) and (j - i) * width >= d - 1e-9):
                indist += 1
    return 100.0 * indist / (n * (n - 1) / 2)


def _fake_table(arrays: dict, *, n: int, width: float, ratios, contacts, threshold=0.9) -> Table:
    header = {
        "effusivity": {"min": 0.0, "max": n * width, "intervals": n, "width": width},
        "axes": [{"name": "noise_ratio", "values": list(ratios), "scale": "log"},
                 {"name": "contact_s", "values": list(contacts), "scale": "linear"},
                 {"name": "e_ref", "values": list(width * (np.arange(n) + 0.5)), "scale": "linear"}],
        "threshold": threshold, "fidelity": "svm",
    }
    return Table(name="fake", path=Path("fake.npz"), header=header, arrays=arrays)


def _check_png(path: Path) -> None:
    import matplotlib.image as mpimg

    data = path.read_bytes()
    assert data[:8] == PNG_MAGIC, path
    assert len(data) > 8000, f"{path} is suspiciously small ({len(data)} bytes)"
    img = mpimg.imread(path)
    assert img.ndim == 3 and img.shape[0] > 200 and img.shape[1] > 200
    # not blank: many distinct colours and real contrast
    flat = img[..., :3].reshape(-1, 3)
    assert float(flat.std()) > 0.05
    rgb = (flat * 255).astype(np.uint32)
    assert np.unique((rgb[:, 0] << 16) | (rgb[:, 1] << 8) | rgb[:, 2]).size > 20


# ------------------------------------------------------------------ pure parts
def test_parse_only_accepts_repeats_and_commas_and_rejects_unknown():
    assert parse_only(None) == SECTIONS
    assert parse_only(["table1,effusivity", "guideline"]) == ("effusivity", "table1", "guideline")
    with pytest.raises(InputError, match="unknown section"):
        parse_only(["table2"])


def test_staircase_percent_matches_counting_every_pair():
    rng = np.random.default_rng(3)
    n, width = 40, 80.0
    J = np.maximum.accumulate(np.arange(n) + rng.integers(1, 12, n))  # a staircase: non-decreasing
    d = np.where(J < n, (J - np.arange(n)) * width, np.nan)
    arrays = {"delta_up": d.reshape(1, 1, n)}
    tab = _fake_table(arrays, n=n, width=width, ratios=[0.005], contacts=[2.0])
    assert staircase_percent(tab, 0.005, 2.0) == pytest.approx(_brute_percent(d, width), abs=1e-9)
    assert staircase_percent(tab, 0.01, 2.0) is None  # not a grid point: no silent interpolation


def test_matrix_stats_and_delta_read_off_every_pair():
    rng = np.random.default_rng(5)
    n = 25
    m = rng.uniform(0.3, 1.0, (n, n))
    m = np.triu(m, 1) + np.triu(m, 1).T
    np.fill_diagonal(m, np.nan)
    st_ = matrix_stats(m, 0.9)
    pairs = [m[i, j] for i in range(n) for j in range(i + 1, n)]
    assert st_.pairs == len(pairs)
    assert st_.mean_f1 == pytest.approx(np.mean(pairs))
    assert st_.percent_indistinguishable == pytest.approx(100 * np.mean(np.array(pairs) < 0.9))
    d = matrix_delta_up(m, 400.0, 0.9)
    for i in range(n):
        first = next((j for j in range(i + 1, n) if m[i, j] >= 0.9), None)
        assert (math.isnan(d[i]) if first is None else d[i] == (first - i) * 400.0)


@settings(max_examples=60, deadline=None)
@given(lo=st.floats(0, 39000), span=st.floats(0, 20000), width=st.sampled_from([80.0, 400.0]))
def test_covering_intervals_cover_the_range_and_only_it(lo, span, width):
    n = int(40000 / width)
    hi = min(lo + span, 40000.0)
    k = covering_intervals(lo, hi, 0.0, width, n)
    assert k.size >= 1 and np.all(np.diff(k) == 1)
    edges_lo, edges_hi = k * width, (k + 1) * width
    assert edges_lo[0] <= lo + 1e-9 and edges_hi[-1] >= hi - 1e-9  # the range is covered
    assert np.all(edges_hi >= lo - 1e-9) and np.all(edges_lo <= hi + 1e-9)  # every interval meets it


def test_bayes_accuracy_two_classes_equals_the_ideal_observer(paper_sensor):
    """Two ordered classes: the Bayes rule between the density crossings reaches the closed-form optimum of
    designkit.recognition.ideal (the bins of s/8 it replaced were within 2e-3)."""
    from designkit import Scene
    from designkit.recognition.ideal import ideal_pair

    for contact, ranges in ((1.0, [(20000, 20080), (35000, 35080)]), (2.0, [(400, 600), (550, 900)])):
        scene = Scene.from_delta_t(contact_s=contact, noise_c=0.05, delta_t_c=10.0)
        ref = ideal_pair(ranges[0], ranges[1], paper_sensor, scene).accuracy
        assert bayes_accuracy(ranges, paper_sensor, scene) == pytest.approx(ref, abs=1e-9)


def test_bayes_accuracy_limits(paper_sensor):
    from designkit import Scene

    ranges = [(100, 200), (1000, 1100), (20000, 21000)]
    quiet = Scene.from_delta_t(contact_s=4.0, noise_c=1e-6, delta_t_c=10.0)
    assert bayes_accuracy(ranges, paper_sensor, quiet) == pytest.approx(1.0, abs=1e-6)
    no_signal = Scene(contact_s=2.0, noise_c=0.05, sensor_temp_c=25.0, ambient_temp_c=25.0)
    assert bayes_accuracy(ranges, paper_sensor, no_signal) == pytest.approx(1 / 3)


# ------------------------------------------------------------------ the report, end to end
@pytest.fixture(scope="session")
def small_tables(tmp_path_factory) -> Path:
    """Tiny versions of the shipped tables the report reads (same names, real sweeps)."""
    from designkit.sweep import SweepConfig, run_sweep

    out = tmp_path_factory.mktemp("tables")
    common = dict(trials=6, folds=3, max_repeats=1, seed=0)
    ratios = (0.001, 0.002, 0.005, 0.01, 0.02)
    for cfg in (
        SweepConfig(name="svm-paper", intervals=4, noise_ratio=ratios, contact_s=(1, 2, 4), **common),
        SweepConfig(name="f1-matrix-paper", intervals=5, noise_ratio=(0.005,), contact_s=(1, 4),
                    full_matrix=True, **common),
        SweepConfig(name="f1-matrix-2s", intervals=5, noise_ratio=ratios, contact_s=(2,), full_matrix=True,
                    **common),
        SweepConfig(name="f1-matrix-fine-low", e_max=4000, intervals=4, noise_ratio=ratios, contact_s=(2,),
                    full_matrix=True, **common),
    ):
        run_sweep(cfg, out / "work" / cfg.name, out=out / f"{cfg.name}.npz")
    return out


@pytest.fixture(scope="session")
def small_report(small_tables, tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    no_data = tmp_path_factory.mktemp("no-robot-data")
    res = reproduce(out, ["f1-matrices", "delta-curves", "effusivity", "node-graphs", "table1", "real-robot",
                          "sim-to-real", "real-prediction"],
                    ReproduceSettings(tables_dir=small_tables, robot_data=no_data, quick=True))
    return res


@pytest.mark.slow
def test_report_is_written_with_every_section_and_real_figures(small_report):
    text = small_report.report.read_text()
    for s in small_report.sections:
        assert f"## {s.title}" in text
    assert len(small_report.figures) >= 5
    for f in small_report.figures:
        _check_png(f)
        assert f"]({f.relative_to(small_report.out_dir)})" in text  # linked from the report
    data = json.loads(small_report.report_json.read_text())
    assert set(data["sections"]) == {s.name for s in small_report.sections}


@pytest.mark.slow
def test_table1_numbers_agree_with_the_tables(small_report, small_tables):
    from designkit.tables.store import load_table

    rows = small_report.section("table1").numbers["rows"]
    svm = load_table(small_tables / "svm-paper.npz")
    coarse = load_table(small_tables / "f1-matrix-2s.npz")
    width = svm.header["effusivity"]["width"]
    for r in rows:
        ri = list(svm.axes["noise_ratio"]).index(r["noise_ratio"])
        ci = list(svm.axes["contact_s"]).index(2.0)
        assert r["intervals"]["percent"] == pytest.approx(_brute_percent(svm.arrays["delta_up"][ri, ci], width))
        m = coarse.arrays["f1_matrix"][list(coarse.axes["noise_ratio"]).index(r["noise_ratio"]), 0]
        pairs = [m[i, j] for i in range(m.shape[0]) for j in range(i + 1, m.shape[0])]
        assert r["intervals"]["coarse"]["mean_f1"] == pytest.approx(float(np.mean(pairs)), rel=1e-6)
        assert 0 <= r["materials"]["percent_indistinguishable"] <= 100
        assert r["paper"]["intervals_percent"] > 0
    # same sigma/dT, same numbers (the invariance the paper's own table shows up to noise)
    by_ratio = {}
    for r in rows:
        by_ratio.setdefault(r["noise_ratio"], []).append(r["intervals"]["percent"])
    assert any(len(v) == 2 and v[0] == v[1] for v in by_ratio.values())
    comps = small_report.section("table1").comparisons
    assert len(comps) == 24
    assert all(c.explanation for c in comps if c.beyond_tolerance)


@pytest.mark.slow
def test_delta_numbers_are_the_query_answers(small_report, small_tables):
    from designkit.query.table import delta_e
    from designkit.tables.store import load_table

    svm = load_table(small_tables / "svm-paper.npz")
    rows = small_report.section("delta-curves").numbers["ts0_35_sigma_0.05"]
    for r in rows[::5]:
        a = delta_e(r["e"], contact_s=r["contact_s"], noise_c=0.05, delta_t_c=10.0, table=svm)
        assert r["delta_up"] == a.extra["delta_e_upper"]
        assert r["delta_up_ideal"] == a.extra["delta_e_upper_ideal"]


@pytest.mark.slow
def test_material_pairs_use_the_papers_mean_over_covering_intervals(small_report, small_tables):
    """Recompute one graph edge's F1 from the table: mean over the covering interval pairs."""
    from designkit.materials import get_material
    from designkit.tables.store import load_table

    edges_csv = small_report.out_dir / small_report.section("node-graphs").numbers["ts0_35"]["edges_csv"]
    lines = edges_csv.read_text().splitlines()[1:]
    coarse = load_table(small_tables / "f1-matrix-2s.npz")
    m = np.array(coarse.arrays["f1_matrix"][list(coarse.axes["noise_ratio"]).index(0.005), 0], dtype=float)
    checked = 0
    for a, b, f1, grid in csv.reader(lines):
        if grid != "width 400":
            continue
        ma, mb = get_material(a), get_material(b)
        w = coarse.header["effusivity"]["width"]
        ka = covering_intervals(*ma.effusivity_range, 0.0, w, m.shape[0])
        kb = covering_intervals(*mb.effusivity_range, 0.0, w, m.shape[0])
        if np.intersect1d(ka, kb).size:
            continue  # involves chance cells; checked through the no-overlap pairs
        assert float(f1) == pytest.approx(float(np.mean(m[np.ix_(ka, kb)])), rel=1e-5)
        checked += 1
    assert checked >= 1


@pytest.mark.slow
def test_real_robot_sections_skip_cleanly_without_data(small_report):
    for name in ("real-robot", "sim-to-real", "real-prediction"):
        s = small_report.section(name)
        assert s.skipped and "not available" in s.skipped
        assert s.figures == ()
    assert "real robot recordings are not available" in small_report.report.read_text()


@pytest.mark.slow
def test_real_robot_on_the_shared_recordings(robot_data_dir, tmp_path):
    """Train real / test real on the recordings: numbers equal a direct cross-validation."""
    from designkit.recognition.svm import cross_validated_f1
    from designkit_lab.reproduce.robot import load_real

    res = reproduce(tmp_path / "r", ["real-robot"], ReproduceSettings(robot_data=robot_data_dir, quick=True))
    s = res.section("real-robot")
    assert not s.skipped
    pairs = {tuple(p["pair"]): p for p in s.numbers["pairs"]}
    touches = load_real(robot_data_dir)
    assert touches.sensor_c.shape == (180, 801)
    direct = np.mean([cross_validated_f1(touches.of("wood"), touches.of("metal"), 200.0, folds=3,
                                         seed=[0, 211, r]).f1 for r in range(2)])
    assert pairs[("wood", "metal")]["f1"] == pytest.approx(direct)
    assert pairs[("wood", "metal")]["f1"] > 0.95  # aluminium and wood are easy for a real heated sensor
    cm = np.array(s.numbers["multiclass"]["confusion"])
    assert cm.sum() == 180 * s.numbers["multiclass"]["repeats"]
    for f in res.figures:
        _check_png(f)


# ------------------------------------------------------------------ CLI
def test_cli_json_and_errors(cli, tmp_path):
    r = cli("reproduce", "--out", tmp_path / "rep", "--only", "effusivity", "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    eff = d["sections"]["effusivity"]
    assert eff["numbers"]["materials"] >= 69
    assert (tmp_path / "rep" / "report.md").is_file()
    _check_png(tmp_path / "rep" / eff["figures"][0])
    bad = cli("reproduce", "--out", tmp_path / "rep", "--only", "fig99")
    assert bad.exit_code == 2
    assert "unknown section" in bad.output and "Traceback" not in bad.output


def test_console_script_runs(tmp_path):
    exe = Path(sys.executable).with_name("designkit")
    if not exe.exists():
        pytest.skip("designkit console script not installed next to this Python")
    out = subprocess.run([str(exe), "reproduce", "--out", str(tmp_path / "rep"), "--only", "effusivity"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "Wrote" in out.stdout and (tmp_path / "rep" / "report.md").is_file()


# ------------------------------------------------------------------ Table I at the paper's resolution (issue 35)
TABLES_DIR = Path(__file__).resolve().parents[1] / "tables"


def test_every_table1_setting_has_a_500_interval_full_matrix_config():
    """Each sigma/dT of Table I names its own 500-interval full-matrix config, the 100-interval
    matrices' sweep on the paper's grid (same trials, folds, repeats, seed, threshold, contact)."""
    import yaml

    from designkit_lab.reproduce.matrices import paper_grid_table
    from designkit_lab.reproduce.paper import TABLE1

    base = yaml.safe_load((TABLES_DIR / "f1-matrix-2s.yaml").read_text())
    for row in TABLE1:
        name = paper_grid_table(row.noise_ratio)
        cfg = yaml.safe_load((TABLES_DIR / f"{name}.yaml").read_text())
        assert cfg["name"] == name and cfg["full_matrix"] is True
        assert cfg["effusivity"] == {"min": 0, "max": 40000, "intervals": 500}
        assert cfg["noise_ratio"] == [pytest.approx(row.noise_ratio)]
        for key in ("trials", "folds", "seed", "max_repeats", "threshold", "z", "contact_s", "sensor", "fidelity"):
            assert cfg[key] == base[key], key


def test_table1_section_labels_each_resolution_and_names_missing_tables():
    from designkit_lab.reproduce.table1 import _paper_grid_lines

    def row(ratio, grid):
        return {"noise_c": 0.05, "delta_t_c": 0.05 / ratio, "noise_ratio": ratio,
                "paper": {"intervals_percent": 15.0, "intervals_f1": 0.93, "materials_percent": 18.0,
                          "materials_f1": 0.95},
                "intervals": {"percent": 19.8, "coarse": {"mean_f1": 0.931, "percent_indistinguishable": 19.5}},
                "materials": {"mean_f1": 0.978, "percent_indistinguishable": 8.9}, "paper_grid": grid}

    def pct(x):
        return "—" if x is None else f"{x:.4g} %"

    assert "Not built: `f1-matrix-500-r0p005`" in "\n".join(_paper_grid_lines([row(0.005, None)], pct))
    grid = {"table": "f1-matrix-500-r0p005", "grid": {"e_min": 0.0, "width": 80.0, "intervals": 500},
            "intervals": {"mean_f1": 0.9123, "percent_indistinguishable": 17.25, "pairs": 124750},
            "materials": {"mean_f1": 0.9456, "percent_indistinguishable": 12.5, "pairs": 2346},
            "build": {"compute_s": 412.0, "fits": 130000, "elapsed_s": 900.0, "jobs": 2, "whole_build": True}}
    text = "\n".join(_paper_grid_lines([row(0.005, grid), row(0.01, None)], pct))
    assert "124,750 interval pairs" in text and "Not built: `f1-matrix-500-r0p01`" in text
    assert "% indist. 500 (every pair)" in text and "mean F1 100" in text and "% indist. 500 (staircase)" in text
    line = next(ln for ln in text.splitlines() if ln.startswith("| 0.05 | 10 |"))
    assert "17.25 %" in line and "0.912" in line and "0.931" in line and "19.8 %" in line
    assert "412 worker-s of chunk wall" in text and "one run of 15.0 min wall on 2 worker(s)" in text


def test_paper_grid_row_counts_every_pair_of_the_shipped_500_interval_matrices(tmp_path):
    from designkit.tables.store import load_table
    from designkit_lab.reproduce._report import Context
    from designkit_lab.reproduce.matrices import paper_grid_row, paper_grid_table
    from designkit_lab.reproduce.paper import TABLE1

    shipped = [r.noise_ratio for r in TABLE1 if (TABLES_DIR / f"{paper_grid_table(r.noise_ratio)}.npz").is_file()]
    if not shipped:
        pytest.skip("no 500-interval full matrix is shipped in tables/ (build: tables/f1-matrix-500-r*.yaml)")
    ctx = Context(ReproduceSettings(tables_dir=TABLES_DIR), tmp_path)
    for ratio in sorted(set(shipped)):
        got = paper_grid_row(ctx, ratio, material_cover=False)
        m = np.asarray(load_table(TABLES_DIR / f"{paper_grid_table(ratio)}.npz").arrays["f1_matrix"][0, 0],
                       dtype=np.float64)
        upper = m[np.triu(np.ones(m.shape, dtype=bool), 1)]
        assert m.shape == (500, 500) and got["intervals"]["pairs"] == 124_750 == upper.size
        assert np.isfinite(upper).all()
        assert got["intervals"]["mean_f1"] == pytest.approx(upper.sum() / upper.size, rel=1e-12)
        assert got["intervals"]["percent_indistinguishable"] == pytest.approx(100.0 * np.count_nonzero(upper < 0.9)
                                                                              / upper.size)
        assert got["build"]["fits"] >= 124_750


@pytest.mark.slow
def test_real_prediction_counts_contact_from_the_onset_as_the_library_does(robot_data_dir):
    """The prediction against the real rig asks the library, which counts a calibrated sensor's contact from its
    detected onset: converting again (as this section did after the library took the onset over) asked F1 at
    0.25 + 0.64 s and gave a min-contact of -0.04 s against the real 0.59 s. Issue 34's targets: F1 within 0.05 of
    the real at every contact 0.25-1.5 s, min-contact inside its interval or within 25 %."""
    from designkit_lab.reproduce.prediction import predict_against_real
    from designkit_lab.reproduce.robot import load_real

    res = predict_against_real(robot_data_dir, load_real(robot_data_dir), repeats=3, parts=False, log=lambda *_: None)
    pred, real = res["predicted_min_contact"], res["real_min_contact_s"]
    assert pred["value"] > 0 and pred["interval"][0] > 0 and real > 0
    assert res["min_contact_met"], (pred, real)
    assert res["worst_error"] <= 0.05, [(r["contact_s"], r["predicted_f1"], r["real_f1"]) for r in res["rows"]]
