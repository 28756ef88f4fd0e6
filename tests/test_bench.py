"""designkit_lab.accuracy and `designkit bench`: the measuring instruments themselves.

The exact references the benchmark compares tables against are checked here against
their definitions (the ideal observer's F1 just above and just below each answer), so
that a table error in docs/accuracy.md is the table's, not the reference's.

No test asserts on a measured time: timings are checked to be positive and reported,
and scaling claims are printed by benchmarks/bench_cost.py, not asserted here.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from designkit import Scene
from designkit_lab import accuracy as bench
from designkit.query import ideal_bound
from designkit.recognition.ideal import ideal_pair
from designkit.sensor import SENSORS

PAPER = SENSORS["paper"]
W = 80.0


#: The critical noise is a root of F1(sigma) = 0.9 in floating point: the F1 read back at it lies within
#: this of 0.9 (8e-13 apart between ideal_pair's F1 maximizer and critical_noise's own), not above it.
ROOT_F1 = 1e-9


def _f1(lo, hi, contact, ratio, width=W):
    return ideal_pair((lo, lo + width), (hi, hi + width), PAPER,
                      Scene(contact_s=contact, noise_c=ratio, sensor_temp_c=26.0, ambient_temp_c=25.0)).f1


# ------------------------------------------------------------------ helpers
def test_fit_exponent_recovers_power_laws_and_ignores_unusable_points():
    x = np.array([10.0, 20.0, 40.0, 80.0])
    assert bench.fit_exponent(x, 3.0 * x ** 1.5) == pytest.approx(1.5)
    assert bench.fit_exponent(x, 7.0 * x ** -0.5) == pytest.approx(-0.5)
    assert bench.fit_exponent(x, [0.0, 2.0, 4.0, np.nan]) == pytest.approx(1.0)  # zeros and NaN dropped
    assert math.isnan(bench.fit_exponent([5.0, 5.0], [1.0, 2.0]))  # no spread in x: no slope


def test_process_cost_reports_the_childs_own_peak_memory_and_exit_status():
    big = bench.process_cost([sys.executable, "-c", "import numpy; a = numpy.ones(40_000_000); a += 1"])
    small = bench.process_cost([sys.executable, "-c", "import numpy"])
    assert big.returncode == 0 and small.returncode == 0
    # 40e6 float64 = 305 MiB on top of the interpreter and numpy. Resident memory is the
    # kernel's to reclaim (CI saw 193 of the 305 MiB resident at the peak), so this checks
    # the property that matters: the small child's peak is its own, not the big one's
    # carried over (as RUSAGE_CHILDREN would report), and the big one's is visibly larger.
    assert big.max_rss_mb - small.max_rss_mb > 100
    # and the small one's is its own even though this test process is large (hundreds of MB after the
    # suite has run): Linux carries peak RSS across fork and exec, which the launcher sidesteps
    assert small.max_rss_mb < 150
    assert big.wall_s > 0
    bad = bench.process_cost([sys.executable, "-c", "import sys; print('x'); sys.exit(3)"])
    assert bad.returncode == 3 and bad.stdout.strip() == "x"


@pytest.mark.skipif(bench.reset_peak_memory() is None, reason="needs Linux /proc/self/clear_refs")
def test_measure_reports_each_calls_own_peak():
    def alloc(mb):
        a = np.ones(int(mb * 2**20 / 8))
        a += 1.0
        return float(a[0])

    _, _, _, first = bench.measure(lambda: alloc(300))
    _, _, _, second = bench.measure(lambda: alloc(10))
    assert 120 < first < 360  # at most 300 MiB, most of it resident at the peak
    assert second < 60  # the earlier, larger peak is not carried over


# ------------------------------------------------------------------ exact ideal references
def test_exact_ideal_min_contact_is_the_first_sample_time_that_separates():
    lo = np.array([20000.0, 5000.0, 1000.0])
    hi = np.array([35000.0, 5400.0, 1100.0])
    ratio = np.array([0.005, 0.002, 0.01])
    t = ideal_bound.exact_ideal_min_contact(PAPER, lo, hi, ratio)
    dt = 1.0 / PAPER.sample_rate_hz
    for a, b, r, c in zip(lo, hi, ratio, t):
        assert _f1(a, b, c, r) >= 0.9 > _f1(a, b, c - dt, r)
    # the paper's guideline pair: about 1 s for the ideal observer (DOMAIN.md: accuracy 0.87 at 1 s)
    assert 0.9 < t[0] < 1.3


def test_exact_ideal_min_contact_is_nan_when_nothing_up_to_the_limit_separates():
    t = ideal_bound.exact_ideal_min_contact(PAPER, 20000.0, 20050.0, 0.02, max_contact_s=2.0)
    assert np.isnan(t)


def test_exact_ideal_max_ratio_brackets_the_threshold():
    lo, hi, c = np.array([20000.0, 3000.0]), np.array([35000.0, 3400.0]), np.array([2.0, 1.5])
    r = ideal_bound.exact_ideal_max_ratio(PAPER, lo, hi, c)
    for a, b, ci, ri in zip(lo, hi, c, r):
        assert _f1(a, b, ci, ri) >= 0.9 - ROOT_F1 and 0.9 > _f1(a, b, ci, ri * 1.001)


def test_exact_ideal_max_ratio_searches_above_its_bracket():
    """The bracket's top is not a bound: where the ideal observer still separates there, the search goes on
    upwards (at 10 s it separates 500 from 39,000 up to sigma/dT 4.6; clipped at 1, a max-noise bound of
    10 degC at dT 10 would have claimed what the ideal observer beats)."""
    lo, hi, c = np.array([500.0, 20000.0, 20000.0]), np.array([39000.0, 35000.0, 35000.0]), np.array([10.0, 10.0, 2.0])
    r = ideal_bound.exact_ideal_max_ratio(PAPER, lo, hi, c, bracket=(1e-5, 1.0))
    assert r[0] > 1.0 and r[1] < 1.0
    for a, b, ci, ri in zip(lo, hi, c, r):
        assert _f1(a, b, ci, ri) >= 0.9 - ROOT_F1 and 0.9 > _f1(a, b, ci, ri * 1.001)
    # the elements inside the bracket answer as they would alone (each element's bisection is its own)
    alone = ideal_bound.exact_ideal_max_ratio(PAPER, lo[1:], hi[1:], c[1:], bracket=(1e-5, 1.0))
    np.testing.assert_array_equal(r[1:], alone)


def test_exact_ideal_delta_brackets_the_threshold_in_both_directions():
    e = np.array([20000.0, 2000.0])
    for direction in (+1, -1):
        d = ideal_bound.exact_ideal_delta(PAPER, e, 2.0, 0.005, direction=direction)
        for ei, di in zip(e, d):
            near, far = sorted([ei + direction * (di - 1.0), ei + direction * di])
            p = ei + direction * di
            assert _f1(min(ei, p), max(ei, p), 2.0, 0.005) >= 0.9
            q = ei + direction * (di - 1.0)
            assert _f1(min(ei, q), max(ei, q), 2.0, 0.005) < 0.9


# ------------------------------------------------------------------ tables
@pytest.fixture(scope="module")
def ideal_table():
    from designkit.tables.store import load_table

    return load_table("ideal-paper")


def test_subsampled_table_answers_like_the_full_table_at_kept_points(ideal_table):
    from designkit.query import table as query

    ax = ideal_table.axes
    keep = {"noise_ratio": [0, 6, 10, 16], "contact_s": list(range(0, len(ax["contact_s"]), 4))}
    sub = bench.subsample_table(ideal_table, keep)
    assert list(sub.axes["noise_ratio"]) == [ax["noise_ratio"][i] for i in keep["noise_ratio"]]
    for r_i in keep["noise_ratio"]:
        for c_i in keep["contact_s"]:
            kw = dict(contact_s=float(ax["contact_s"][c_i]), noise_c=float(ax["noise_ratio"][r_i]) * 10,
                      delta_t_c=10.0)
            a = query.delta_e(12345.0, table=ideal_table, ideal_table=ideal_table, **kw)
            b = query.delta_e(12345.0, table=sub, ideal_table=sub, **kw)
            assert a.extra["delta_e_upper"] == b.extra["delta_e_upper"]
            assert a.extra["delta_e_lower"] == b.extra["delta_e_lower"]
    with pytest.raises(ValueError):
        bench.subsample_table(ideal_table, {"contact_s": [3, 1]})


def test_query_rows_measure_a_conservative_ideal_table(ideal_table):
    rows, facts = bench.query_rows(ideal_table, quick=True, n=16, questions=("min-contact", "delta-e"))
    assert [r.question for r in rows] == ["min-contact", "delta-e"]
    for r in rows:
        assert math.isfinite(r.error) and r.worst >= r.error >= 0 and r.wall_s > 0 and r.n > 0
    # the table's delta is a whole number of intervals at or above the exact one, and linear
    # interpolation of a convex need overestimates it: table answers never claim too short a contact
    assert facts["min-contact"]["conservative_fraction"] == 1.0
    assert facts["delta-e"]["worst"] >= 0


def test_staircase_and_full_matrix_agree_on_a_tiny_grid():
    r = bench.staircase_vs_full(6, contact_s=0.5, trials=12, max_repeats=2)
    assert r["pairs_full"] == 15
    assert r["fits_full"] >= 15 and r["fits_staircase"] <= r["fits_full"]
    assert r["max_diff_intervals"] <= 1


def test_cost_curve_of_the_ideal_engine_reports_every_point_and_its_exponents():
    c = bench.cost_curve("ideal: intervals", "intervals", (100, 400),
                         dict(name="t", fidelity="ideal", noise_ratio=(0.005,), contact_s=(1.0,)))
    assert c.x == (100.0, 400.0) and c.fits == (0, 0)  # the ideal engine fits no SVM
    assert len(c.wall_s) == len(c.peak_mb) == 2 and all(w > 0 for w in c.wall_s)
    assert math.isfinite(c.time_exponent)  # reported; its size is benchmarks/bench_cost.py's to print
    assert c.fits_exponent is None and c.note == ""


def test_cost_curve_of_the_svm_engine_counts_its_fits():
    base = dict(name="t", fidelity="svm", noise_ratio=(0.005,), contact_s=(0.5,), intervals=4, trials=8,
                max_repeats=1)
    c = bench.cost_curve("SVM: intervals", "intervals", (8, 16), base)
    a = bench.cost_curve("SVM: intervals", "intervals", (8, 16), base)
    assert c.fits == a.fits and all(f > 0 for f in c.fits)  # seeded: the same work twice
    assert c.fits_exponent == pytest.approx(bench.fit_exponent(c.x, c.fits))
    assert c.note.startswith("time per SVM fit")


def test_cost_curves_follow_their_specs_and_only_selects():
    names = [s[0] for s in bench.cost_curve_specs(quick=True)]
    assert names == ["ideal: intervals", "ideal: contact times per table", "SVM: intervals",
                     "SVM: trials per interval", "SVM: contact time"]
    assert bench.cost_curves(quick=True, isolated=False, only=()) == []


# ------------------------------------------------------------------ report and CLI
@pytest.fixture(scope="module")
def physics_report():
    return bench.run_bench(quick=True, sections=("physics",))


def test_physics_rows_are_accurate_and_faster_than_mpmath(physics_report):
    rows = {r.method: r for r in physics_report.rows}
    for name in ("response_shape (scipy erfc)", "temperature_change"):
        assert rows[name].worst < 1e-12
    for r in physics_report.rows:  # timed and reported (how much faster is the page's to say, not a test's)
        assert r.wall_s > 0 and r.reference_wall_s > 0 and r.speedup > 0
    assert rows["log_response_shape (log_ndtr)"].worst < 1e-8
    fv = rows["finite volumes"]
    assert fv.worst < 1e-2  # degC at a 10 degC difference (bench_slab's default resolution study)
    assert rows["semi-infinite (paper eq. 2)"].worst > 0.1  # the thin samples are really not semi-infinite


def test_report_renders_markdown_json_and_figures(physics_report, tmp_path):
    paths = bench.write_report(physics_report, tmp_path)
    md = paths["markdown"].read_text()
    assert md.startswith("# Accuracy against run time") and "GENERATED" in md
    assert "response_shape (scipy erfc)" in md and "How to buy more accuracy with time" in md
    assert (tmp_path / "accuracy_pareto.png").stat().st_size > 10_000
    data = json.loads(paths["json"].read_text())
    assert len(data["rows"]) == len(physics_report.rows)


def test_cli_bench_json_and_out(cli, tmp_path):
    r = cli("bench", "--quick", "--section", "physics", "--json", "--out", str(tmp_path))
    assert r.exit_code == 0, r.output
    data = json.loads(r.output)
    assert data["quick"] is True and {row["question"] for row in data["rows"]} >= {"physics: eq. 2"}
    assert (tmp_path / "accuracy.md").is_file()


def test_cli_bench_rejects_an_unknown_section(cli):
    r = cli("bench", "--section", "nonsense")
    assert r.exit_code == 2 and r.output.strip().startswith("Error:") and "nonsense" in r.output


@pytest.mark.slow
def test_console_script_bench_prints_the_table(tmp_path):
    exe = Path(sys.executable).with_name("designkit")
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "designkit"]
    p = subprocess.run(cmd + ["bench", "--quick", "-s", "physics", "--out", str(tmp_path)], capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert "error against run time" in p.stdout and "response_shape" in p.stdout
    assert (tmp_path / "accuracy.md").is_file()


@pytest.mark.slow
def test_svm_query_rows_against_exact_on_a_tiny_svm_table(tmp_path):
    from designkit.sweep import SweepConfig, run_sweep
    from designkit.tables.store import load_table

    cfg = SweepConfig(name="tiny-svm", fidelity="svm", intervals=8, e_max=40000.0, trials=24, max_repeats=1,
                      noise_ratio=(0.002, 0.005), contact_s=(0.5, 1.0, 2.0))
    tab = load_table(run_sweep(cfg, tmp_path / "w", out=tmp_path / "tiny-svm.npz", backend="sequential"))
    rows, facts = bench.svm_query_rows(tab, quick=True, n=1, repeats=1)
    assert [r.question for r in rows] == ["min-contact", "distinguishable"]
    case = facts["min-contact"][0]
    assert case["exact_wall_s"] > 0 and case["table_wall_s"] > 0
    assert 0.0 <= rows[1].error <= 1.0


def test_pareto_figure_has_one_visible_panel_with_points_per_question():
    """Every question gets its own panel with its methods and its reference (a reused loop variable
    once hid all panels but the first)."""
    rows = tuple(bench.Row(question=q, method=m, setting="s", metric="err", error=e, worst=e, wall_s=t,
                           reference="ref", reference_wall_s=1.0, n=1, note="")
                 for q in ("A", "B", "C", "D") for m, e, t in (("fast", 0.1, 1e-3), ("slow", 0.0, 1e-1)))
    report = bench.BenchReport(rows=rows, curves=(), facts={}, quick=True, seed=0, wall_s=0.0, environment={})
    fig = bench.pareto_figure(report)
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert sorted(ax.get_title() for ax in visible) == ["A", "B", "C", "D"]
    for ax in visible:  # two methods and the reference star
        assert len(ax.collections) == 3
    assert bench.pareto_figure(bench.BenchReport((), (), {}, True, 0, 0.0, {})) is None


def test_query_rows_check_distinguishable_verdicts_against_the_closed_form(ideal_table):
    rows, facts = bench.query_rows(ideal_table, quick=True, n=12, questions=("distinguishable",))
    assert [r.question for r in rows] == ["distinguishable"]
    d = facts["distinguishable"]
    assert d["n"] == 12 and 0.0 <= d["wrong_fraction"] <= 1.0 and rows[0].error == d["wrong_fraction"]
    assert rows[0].wall_s > 0 and rows[0].reference_wall_s > 0


# ------------------------------------------------------------------ the page, and what the package promises
REPO = Path(__file__).resolve().parent.parent


def _report_from_json(path: Path) -> bench.BenchReport:
    """A report read back from accuracy.json (null: NaN, except an open gap bin's upper end: inf)."""
    def back(obj, key=""):
        if isinstance(obj, dict):
            return {k: back(v, k) for k, v in obj.items()}
        if isinstance(obj, list):
            return [back(v, key) for v in obj]
        return (math.inf if key == "gap_intervals" else math.nan) if obj is None else obj

    d = back(json.loads(path.read_text()))
    rows = tuple(bench.Row(**{k: v for k, v in r.items() if k != "speedup"}) for r in d["rows"])
    curves = tuple(bench.CostCurve(**{k: tuple(v) if isinstance(v, list) else v for k, v in c.items()})
                   for c in d["curves"])
    return bench.BenchReport(rows, curves, d["facts"], d["quick"], d["seed"], d["wall_s"], d["environment"],
                             tuple(d["skipped"]), d["section_wall_s"])


@pytest.mark.skipif(not (REPO / "docs" / "accuracy.json").is_file(), reason="needs the repository's docs/")
def test_the_shipped_page_renders_from_its_own_json():
    """docs/accuracy.md is exactly what the renderer makes of docs/accuracy.json (same rows, same markdown)."""
    report = _report_from_json(REPO / "docs" / "accuracy.json")
    md = bench.render_markdown(report, {"pareto": "accuracy_pareto.png", "cost": "accuracy_cost.png"})
    cov = REPO / "docs" / "accuracy_coverage.json"
    if cov.is_file():  # the coverage benchmark's section (benchmarks/bench_coverage.py --docs) from its record
        from designkit_lab.accuracy.render import coverage_markdown, insert_coverage

        md = insert_coverage(md, coverage_markdown(json.loads(cov.read_text()), "accuracy_coverage.png"))
    varied = REPO / "docs" / "accuracy_coverage_varied.json"
    if varied.is_file():  # and the varied-conditions one (benchmarks/bench_coverage_varied.py --docs)
        from designkit_lab.accuracy.render import insert_varied_coverage, varied_coverage_markdown

        fig = "accuracy_coverage_varied.png"
        md = insert_varied_coverage(md, varied_coverage_markdown(json.loads(varied.read_text()),
                                                                 fig if (REPO / "docs" / fig).is_file() else None))
    assert md == (REPO / "docs" / "accuracy.md").read_text()


def test_a_varied_coverage_run_replaces_its_own_earlier_run_and_keeps_the_others(tmp_path):
    from designkit_lab.accuracy.render import VARIED_COVERAGE_FILE, write_varied_coverage

    (tmp_path / "accuracy.md").write_text("# Accuracy\n\n<!-- COVERAGE START -->\nc\n<!-- COVERAGE END -->\n## Next\n")
    s = {"n": 100, "n_compared": 50, "n_stated": 40, "coverage": 0.9, "n_unstated": 2, "unstated_contains": 0.5,
         "n_no_answer": 10, "median_rel": 0.03, "p95_rel": 0.2, "violations": 0}
    run = {"question": "min-contact", "seed": 1, "wall_s": 500.0, "cpus": 2, "spread_c": 2.5, "delta_t_c": 7.5,
           "routes": {"table": s, "exact": s}, "sharp": None,
           "regions": [{"noise_band": [0.01, 0.02], "e_band": [0, 2000], "n": 4, "median_rel": 0.1, "max_rel": 0.2,
                        "coverage": 0.75}]}
    write_varied_coverage(run, tmp_path)
    write_varied_coverage({**run, "seed": 2}, tmp_path)
    page = write_varied_coverage({**run, "routes": {"table": {**s, "coverage": 0.5}}}, tmp_path).read_text()
    doc = json.loads((tmp_path / VARIED_COVERAGE_FILE).read_text())
    assert sorted((r["question"], r["seed"]) for r in doc["runs"]) == [("min-contact", 1), ("min-contact", 2)]
    rows = [ln for ln in page.splitlines() if ln.startswith("| `min-contact`")]
    assert [r.split(" | ")[1:3] + [r.split(" | ")[6]] for r in rows] == [
        ["1", "table", "50 %"], ["2", "table", "90 %"], ["2", "exact", "90 %"]]
    # one section, after the coverage section and before the next heading
    assert page.count("VARIED COVERAGE START") == 1
    assert page.index("COVERAGE END") < page.index("VARIED COVERAGE START") < page.index("## Next")
    assert "noise 0.01-0.02 degC, e 0-2000: 10 % (4 cases, coverage 75 %)" in page
    assert "accuracy_coverage_varied.png" not in page and not (tmp_path / "accuracy_coverage_varied.png").exists()


def test_a_varied_run_with_its_cases_gets_a_figure_linked_from_its_section(tmp_path):
    pytest.importorskip("matplotlib")
    from designkit_lab.accuracy.render import VARIED_COVERAGE_FIGURE, varied_coverage_cases, write_varied_coverage

    def reading(v, lo=None, hi=None, cov=None):
        return {"value": v, "low": lo, "high": hi, "coverage": cov, "method": "m", "ideal": None}

    ref = reading(1.0, 0.9, 1.1, 0.9)
    results = [{"noise_c": 0.02, "table": reading(1.05, 0.95, 1.2, 0.9), "exact": reading(1.0, 0.9, 1.1, 0.9),
                "reference": ref},  # held
               {"noise_c": 0.05, "table": reading(1.5, 1.3, 1.7, 0.9), "exact": reading(None), "reference": ref},
               {"noise_c": 0.05, "table": reading(1.5, 1.0, 1.5), "exact": reading(None), "reference": ref}]
    cases = varied_coverage_cases(results)
    assert cases[1] == {"noise_c": 0.05, "table": {"value": 1.5, "low": 1.3, "high": 1.7, "coverage": 0.9,
                                                   "method": "m"},
                        "exact": {"value": None, "low": None, "high": None, "coverage": None, "method": "m"},
                        "reference": {"value": 1.0, "low": 0.9, "high": 1.1, "coverage": 0.9, "method": "m"}}
    s = {"n": 3, "n_compared": 3, "n_stated": 2, "coverage": 0.5, "n_unstated": 1, "unstated_contains": 1.0,
         "n_no_answer": 0, "median_rel": 0.05, "p95_rel": 0.5, "violations": 0}
    run = {"question": "min-contact", "seed": 1, "wall_s": 5.0, "cpus": 2, "spread_c": 2.5, "delta_t_c": 7.5,
           "routes": {"table": s, "exact": s}, "sharp": None, "regions": [], "cases": cases}
    page = write_varied_coverage(run, tmp_path).read_text()
    png = tmp_path / VARIED_COVERAGE_FIGURE
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert f"]({VARIED_COVERAGE_FIGURE})" in page


def test_every_accuracy_module_declares_its_public_names_and_imports_no_private_ones():
    import ast
    import importlib
    import pkgutil

    import designkit_lab.accuracy as pkg

    modules = [pkg] + [importlib.import_module(f"designkit_lab.accuracy.{m.name}") for m in pkgutil.iter_modules(pkg.__path__)]
    for mod in modules:
        assert all(hasattr(mod, n) for n in mod.__all__), mod.__name__
        tree = ast.parse(Path(mod.__file__).read_text())
        private = [f"{n.module}.{a.name}" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)
                   for a in n.names if a.name.startswith("_") and a.name != "__version__"]
        assert private == [], mod.__name__
    public = {n for mod in modules[1:] for n in mod.__all__}
    assert public == set(pkg.__all__)  # the package exports every module's public names


def test_mpmath_is_a_declared_dependency():
    """`designkit bench` (section physics) needs mpmath: a plain install must have it, not only the test extra."""
    text = (REPO / "pyproject.toml").read_text()
    deps = text.split("dependencies = [", 1)[1].split("]", 1)[0]
    assert '"mpmath' in deps


@pytest.fixture
def no_matplotlib(monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "matplotlib" else real(name, *a))


def test_figures_refuse_in_one_line_naming_the_extra(no_matplotlib, tmp_path):
    with pytest.raises(ValueError, match=r"pip install 'designkit\[figures\]'"):
        bench.require_figures()
    report = bench.BenchReport((), (), {}, True, 0, 0.0, {})
    with pytest.raises(ValueError):
        bench.write_report(report, tmp_path / "out")
    assert not (tmp_path / "out").exists()  # refused before writing anything


def test_cli_bench_out_refuses_before_measuring_without_matplotlib(cli, no_matplotlib, monkeypatch, tmp_path):
    def must_not_run(**_):
        raise AssertionError("measured before refusing")

    monkeypatch.setattr(bench, "run_bench", must_not_run)
    r = cli("bench", "--quick", "-s", "physics", "--out", str(tmp_path))
    assert r.exit_code == 2
    assert r.output.strip() == "Error: figures need matplotlib: pip install 'designkit[figures]'"
