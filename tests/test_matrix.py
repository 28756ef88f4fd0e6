"""``designkit matrix`` and designkit.query.matrix: each cell is the public query's answer, the limiting
pair is the hardest answered pair, the multi-class view agrees with the reproduce section, and the
12-material matrix is fast."""

from __future__ import annotations

import csv
import io
import json
import math

import numpy as np
import pytest

from designkit import query
from designkit.query.matrix import material_matrix, multiclass_ideal_accuracy, resolve_materials
from designkit.query.table import DEFAULT_TABLE
from designkit.tables.store import load_table

THREE = ["paper12:glass", "paper12:stainless steel", "paper12:copper"]


@pytest.fixture(scope="module")
def paper12():
    return material_matrix(set="paper12")


def test_each_cell_is_the_public_query_answer(paper12):
    names = [m.qualified_name for m in paper12.materials]
    vals = paper12.values()
    for i, j in [(0, 2), (7, 9), (9, 10), (3, 6)]:
        a = query.min_contact(m1=names[i], m2=names[j])
        want = math.nan if a.value is None else a.value
        assert vals[i, j] == pytest.approx(want, nan_ok=True)
        assert vals[j, i] == vals[i, j] or (math.isnan(vals[j, i]) and math.isnan(vals[i, j]))


def test_overlapping_materials_are_marked_and_never_limiting(paper12):
    st = paper12.status()
    by = dict(zip(paper12.names, range(len(paper12.names))))
    assert st[by["Aluminum"], by["Copper"]] == "overlap"  # 12768-25972 vs 23049-36761
    assert st[by["Glass"], by["Copper"]] == "answered"
    lim = paper12.limiting
    assert lim.status == "answered" and len(lim.names) == 2
    i, j = by[lim.names[0]], by[lim.names[1]]
    answered = paper12.values()[paper12.status() == "answered"]
    assert paper12.values()[i, j] == pytest.approx(np.nanmax(answered))  # min-contact: the longest wins
    assert "overlap" in lim.why


def test_max_noise_limiting_pair_is_the_smallest_noise():
    r = material_matrix(THREE, "max-noise", contact_s=1.0)
    vals = r.values()
    assert r.limiting.value == pytest.approx(np.nanmin(vals))
    assert r.scene["contact_s"] == 1.0 and r.scene["noise_c"] is None


def test_bounds_are_the_answers_own():
    """A cell says "at most" / "at least" exactly where the single answer does (its interval open at one
    end): below the table's first contact the answer is an estimate with an interval, not a bound."""
    r = material_matrix(THREE, "min-contact")
    glass_copper = next(c for c in r.cells if (c.i, c.j) == (0, 2))
    assert glass_copper.value < 0.5 and glass_copper.bound == "" == glass_copper.answer.bound
    r = material_matrix(THREE, "max-noise", contact_s=2.0)
    bounds = {c.bound for c in r.cells}
    assert "at-least" in bounds and all(c.bound == c.answer.bound for c in r.cells)


def test_multiclass_ideal_equals_the_reproduce_section_formula(paper12):
    from designkit_lab.reproduce.multiclass import bayes_accuracy
    from designkit.scene import Scene
    from designkit.sensor import SENSORS

    mc = paper12.multiclass
    assert mc.svm_accuracy is None and "not computed" in mc.note
    ranges = [m.effusivity_range for m in paper12.materials]
    k = int(np.flatnonzero(mc.contact_s == 2.0)[0])
    sc = Scene.from_delta_t(contact_s=2.0, noise_c=0.05, delta_t_c=10.0)
    assert mc.ideal_accuracy[k] == pytest.approx(bayes_accuracy(ranges, SENSORS["paper"], sc), abs=1e-12)
    assert np.all(np.diff(mc.ideal_accuracy) >= -1e-9)  # longer contact never hurts the ideal observer
    assert mc.chance < mc.ideal_accuracy[0] < mc.ideal_accuracy[-1] < 1.0  # overlaps cap it below 1


def test_separated_classes_are_told_apart_perfectly(paper_sensor):
    from designkit.scene import Scene

    assert multiclass_ideal_accuracy([(400, 500), (20000, 30000)], paper_sensor,
                                     Scene.from_delta_t(contact_s=2.0)) == pytest.approx(1.0)
    assert multiclass_ideal_accuracy([(400, 500), (400, 500)], paper_sensor,
                                     Scene.from_delta_t(contact_s=2.0)) == pytest.approx(0.5, abs=1e-6)


def test_multiclass_accuracy_matches_scipys_quadrature(paper_sensor):
    # an independent reference: (1/K) * integral of the highest class density, each density itself a quadrature
    # over the class's effusivities, by scipy's adaptive quad; three overlapping classes (wood, rubber,
    # acrylic), a short contact where the highest class changes three times
    from scipy import integrate

    from designkit.recognition.ideal import projection_noise
    from designkit.scene import Scene

    ranges = [(331.0, 506.46), (407.0, 570.81), (380.35, 702.15)]
    scene = Scene.from_delta_t(contact_s=0.6, noise_c=0.05, delta_t_c=10.0)
    s, e_s = projection_noise(paper_sensor, scene), paper_sensor.effusivity

    def density(v, a, b):
        f = lambda e: math.exp(-0.5 * ((v - e / (e_s + e)) / s) ** 2)  # noqa: E731
        return integrate.quad(f, a, b, epsabs=1e-14, epsrel=1e-12)[0] / ((b - a) * s * math.sqrt(2 * math.pi))

    lo, hi = 331.0 / (e_s + 331.0) - 9 * s, 702.15 / (e_s + 702.15) + 9 * s
    top = integrate.quad(lambda v: max(density(v, a, b) for a, b in ranges), lo, hi, limit=200,
                         epsabs=1e-11, epsrel=1e-10)[0]
    assert multiclass_ideal_accuracy(ranges, paper_sensor, scene) == pytest.approx(top / 3, abs=1e-8)


def test_noise_free_multiclass_accuracy_is_the_narrowest_class_wherever_classes_overlap(paper_sensor):
    from designkit.scene import Scene

    # [400, 450): the first class alone; [450, 500): both, the narrower (first) wins; [500, 600): the second
    acc = multiclass_ideal_accuracy([(400, 500), (450, 600)], paper_sensor,
                                    Scene.from_delta_t(contact_s=2.0, noise_c=0.0))
    assert acc == pytest.approx(0.5 * (50 / 100 + 50 / 100 + 100 / 150), abs=1e-15)


def test_to_dict_is_json_and_symmetric(paper12):
    d = json.loads(json.dumps(paper12.to_dict(), allow_nan=False))
    n = len(d["materials"])
    assert n == 12 and len(d["cells"]) == 66 and d["computation"]["queries"] == 66
    m = d["matrix"]["value"]
    assert all(m[i][i] is None for i in range(n))
    assert all(m[i][j] == m[j][i] for i in range(n) for j in range(n))


def test_resolve_materials_needs_two_distinct():
    from designkit._validation import InputError

    with pytest.raises(InputError, match="two distinct"):
        resolve_materials(["paper12:copper", "paper12:Copper"])
    assert len(resolve_materials(["copper"], set="paper12")) == 13  # database copper alloys + the 12


def test_a_question_without_a_matrix_is_refused():
    from designkit._validation import InputError

    with pytest.raises(InputError, match="a matrix asks one of"):
        material_matrix(THREE, "delta-e")


def test_twelve_materials_load_each_table_once():
    """The speed of a 12-material plan is measured in benchmarks/bench_library.py (no timed assertion
    here); what makes it fast is checked: each table is loaded once for all 66 pairs."""
    import designkit.query.matrix as qm
    from designkit.query import table as qt
    from designkit.query import table_open as qo
    from designkit.tables import store

    calls = []
    real = store.load_table

    def counting(*a, **k):
        calls.append(str(a[0]) if a else str(k))
        return real(*a, **k)

    patched = [(mod, "load_table") for mod in (store, qt, qo, qm) if hasattr(mod, "load_table")]
    saved = [getattr(mod, name) for mod, name in patched]
    for mod, name in patched:
        setattr(mod, name, counting)
    try:
        qt.clear_table_cache()
        m = material_matrix(set="paper12")
    finally:
        for (mod, name), old in zip(patched, saved):
            setattr(mod, name, old)
        qt.clear_table_cache()
    assert len(m.to_dict()["materials"]) == 12
    assert 1 <= len(calls) <= 2, calls  # the SVM table (and at most the ideal one), not 66 of each


# ---------------------------------------------------------------- the command
def test_cli_table_names_every_material_uncut(cli):
    r = cli("matrix", "--set", "paper12")
    assert r.exit_code == 0, r.output
    for name in ("Stainless Steel", "Cardboard", "Porcelain"):
        assert name in r.output
    assert "…" not in r.output
    assert "min-contact [s]" in r.output and "Limiting pair" in r.output and "overlap" in r.output


def test_cli_csv_is_a_header_and_rows_only(cli):
    r = cli("matrix", "--m", "copper", "--m", "stainless steel", "--m", "glass", "--format", "csv")
    assert r.exit_code == 0, r.output
    rows = list(csv.reader(io.StringIO(r.output)))
    assert rows[0] == ["material", "Copper alloys", "Stainless steel", "Glass"]
    assert len(rows) == 4 and rows[1][1] == "" and float(rows[1][2]) > 0
    assert not any(line.startswith("#") for line in r.output.splitlines())


def test_cli_csv_reads_with_pandas_defaults(cli):  # (cells are the table's text: "≥0.2" stays a string)
    pd = pytest.importorskip("pandas")
    r = cli("matrix", "--m", "copper", "--m", "stainless steel", "--m", "glass", "--format", "csv")
    assert r.exit_code == 0, r.output
    df = pd.read_csv(io.StringIO(r.output), index_col=0)
    assert list(df.index) == list(df.columns)
    assert df.shape == (3, 3) and np.isnan(df.values[0, 0])


FOUR = ["--m", "copper", "--m", "stainless steel", "--m", "glass", "--m", "granite"]
OVERLAPPING = ["--m", "Soda-lime glass", "--m", "Borosilicate glass", "--m", "porcelain", "--m", "granite"]


def _table_cells(output: str) -> dict:
    """{(row, column): text} of the rich table the command prints by default."""
    rows = [[c.strip() for c in ln.strip("│").split("│")] for ln in output.splitlines() if ln.startswith("│")]
    head = next(ln for ln in output.splitlines() if ln.startswith("┃"))
    cols = [c.strip() for c in head.strip("┃").split("┃")]
    return {(r[0], cols[k]): r[k] for r in rows for k in range(1, len(cols))}


def test_cli_csv_keeps_the_bounds_the_table_shows(cli):
    r = cli("matrix", *FOUR, "-q", "max-noise", "--contact", "2", "--format", "csv", "--no-multiclass")
    assert r.exit_code == 0, r.output
    lib = material_matrix(["copper", "stainless steel", "glass", "granite"], "max-noise", contact_s=2.0,
                          multiclass=False)
    bounded = [c for c in lib.cells if c.bound == "at-least"]
    assert bounded, "the scene was chosen so that some answers lie beyond the table's noise grid"
    rows = list(csv.DictReader(io.StringIO(r.output)))
    names = lib.names
    for c in bounded:
        assert rows[c.i][names[c.j]] == f"≥{c.value:.3g}"
    table = _table_cells(cli("matrix", *FOUR, "-q", "max-noise", "--contact", "2", "--no-multiclass").output)
    for row in rows:
        for name in names:
            want = table[row["material"], name]
            assert row[name] == ("" if want == "·" else want)


def test_cli_csv_tells_overlap_from_the_diagonal(cli):
    r = cli("matrix", *OVERLAPPING, "--format", "csv", "--no-multiclass")
    assert r.exit_code == 0, r.output
    rows = list(csv.reader(io.StringIO(r.output)))
    lib = material_matrix(["Soda-lime glass", "Borosilicate glass", "porcelain", "granite"], multiclass=False)
    st = lib.status()
    assert (st == "overlap").any() and (st == "answered").any()
    for i in range(4):
        assert rows[i + 1][i + 1] == ""
        for j in range(4):
            if i != j:
                assert (rows[i + 1][j + 1] == "overlap") == (st[i, j] == "overlap")
    assert "overlap" in cli("matrix", "--help").output


def test_the_summary_under_the_matrix_is_short_and_rounded_as_its_cells(cli):
    """At most 3 lines under the table (the limiting pair with its interval and ideal bound first); its value is
    the cell's text (one rounding rule: "1.32" in the cell was "1.325 s" in the summary)."""
    r = cli("matrix", "--set", "paper12", "--format", "md")
    assert r.exit_code == 0, r.output
    summary = r.output.split("\n\n", 2)[-1].strip().splitlines()
    summary = [x for x in summary if x.strip()]
    assert len(summary) <= 3 and summary[0].startswith("Limiting pair: Stainless Steel / Aluminum, 1.32 s ("), summary
    assert "ideal bound" in summary[0] and "| 1.32 |" in r.output and "1.325" not in r.output


def test_cli_speaks_the_users_words(cli):
    r = cli("matrix", *FOUR, "-q", "max-noise", "--contact", "2", "--explain")
    assert r.exit_code == 0, r.output
    first = r.output.splitlines()[0]
    assert first.startswith("max-noise [°C] for 4 materials (contact 2 s, dT 10 °C;"), first
    assert "the smallest noise of all" in r.output and "--svm-trials N" in r.output
    for internal in ("noise_c", "delta_t_c", "contact_s", "svm_trials", "degC"):
        assert internal not in r.output
    r = cli("matrix", *FOUR, "--noise", "0.05")
    assert "(noise 0.05 °C, dT 10 °C;" in r.output.splitlines()[0] and "noise_c" not in r.output
    j = json.loads(cli("matrix", *FOUR, "-q", "max-noise", "--contact", "2", "--json").output)
    assert j["quantity"] == "noise_c" and "contact_s" in j["scene"]  # --json keeps the library's keys


def test_matrix_figure_labels_the_colorbar_in_the_users_words(tmp_path):
    mpl = pytest.importorskip("matplotlib")
    from designkit.figures import plot_matrix

    with mpl.rc_context({"svg.fonttype": "none"}):  # text as text, so the test can read it
        svg = plot_matrix(material_matrix(THREE, multiclass=False), tmp_path / "m.svg").read_text()
    assert "contact [s]" in svg and "contact_s" not in svg


def test_cli_json_is_the_library_dict(cli):
    r = cli("matrix", *sum((["--m", m] for m in THREE), []), "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    lib = material_matrix(THREE).to_dict()
    d["computation"].pop("wall_s"), lib["computation"].pop("wall_s")
    assert d == json.loads(json.dumps(lib))


def test_cli_md_and_out_file(cli, tmp_path):
    out = tmp_path / "m.md"
    r = cli("matrix", *sum((["--m", m] for m in THREE), []), "-q", "distinguishable", "--contact", "1",
            "--format", "md", "--out", str(out))
    assert r.exit_code == 0, r.output
    text = out.read_text()
    assert text.startswith("**distinguishable") and "| Glass | · | yes | yes |" in text


def test_cli_needs_contact_for_max_noise(cli):
    r = cli("matrix", "--set", "paper12", "-q", "max-noise", "--json")
    assert r.exit_code == 2
    assert "--contact" in json.loads(r.stdout)["error"]["message"]


def test_cli_plot_writes_a_vector_figure(cli, tmp_path):
    pytest.importorskip("matplotlib")
    r = cli("matrix", *sum((["--m", m] for m in THREE), []), "--plot", str(tmp_path / "m.svg"))
    assert r.exit_code == 0, r.output
    assert (tmp_path / "m.svg").read_text().lstrip().startswith("<?xml")


def test_svm_multiclass_on_request_equals_the_reproduce_pipeline(paper_sensor):
    pytest.importorskip("sklearn")
    from designkit_lab.reproduce.multiclass import svm_multiclass
    from designkit.scene import Scene

    r = material_matrix(THREE, svm_trials=6, seed=3)
    mc = r.multiclass
    assert mc.svm_accuracy is not None and mc.svm_accuracy.shape == mc.contact_s.shape
    assert np.all((0 <= mc.svm_accuracy) & (mc.svm_accuracy <= 1)) and "SVM: the paper's pipeline" in mc.note
    sc = Scene.from_delta_t(contact_s=float(mc.contact_s[2]), noise_c=0.05, delta_t_c=10.0)
    want = svm_multiclass([m.effusivity_range for m in r.materials], 6, paper_sensor, sc, [3, 16, 2])["accuracy"]
    assert mc.svm_accuracy[2] == want


def test_progress_counts_pairs_then_svm_contacts():
    pytest.importorskip("sklearn")
    seen = []
    material_matrix(THREE, svm_trials=3, progress=lambda d, t: seen.append((d, t)))
    n = 3 + load_table(DEFAULT_TABLE).axes["contact_s"].size  # 3 pairs, then the table's contact times
    assert seen[0] == (1, n) and seen[-1] == (n, n) and [d for d, _ in seen] == list(range(1, n + 1))
