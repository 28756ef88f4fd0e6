"""Issue 36, the audit of c8fe4cc: names that escape their folder, unbounded touches, internal errors,
results lost, inputs accepted that should be refused, unclear messages. Each test failed on c8fe4cc."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from designkit._validation import InputError, check_file_name
from refusals import REFUSED_IN_ONE_LINE


def _one_line_refusal(r, *needles: str) -> str:
    assert r.exit_code == 2, (r.exit_code, r.output)
    out = r.output.strip()
    assert out.startswith("Error: ") and "\n" not in out and "Traceback" not in out, out
    for n in needles:
        assert n in out, out
    return out


# ------------------------------------------------------------------ class 3: one rule for names that become files
@pytest.mark.parametrize("name", ["../../../escaped", "/tmp/abs", "a/b", "a\\b", "", " ", ".", "..", "a\nb",
                                  "a\0b", "tab\there", "x" * 101, "é" * 101])
def test_a_name_that_becomes_a_file_is_one_file_name(name):
    with pytest.raises(InputError) as info:
        check_file_name("name", name)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("name", ["svm-fine", "my table 2", "é" * 100, "a.b", "-x"])
def test_ordinary_names_pass(name):
    assert check_file_name("name", name) == name


@pytest.mark.parametrize("name", ["../../../escaped", "a/b", "", "a\nb", "/abs/t"])
def test_a_sweep_name_is_refused_before_any_work(cli, tmp_path, monkeypatch, name):
    monkeypatch.chdir(tmp_path)
    r = cli("sweep", "--name", name, "--intervals", "4", "--contact", "1", "--noise-ratio", "0.01",
            "--trials", "6", "--folds", "2", "--out", str(tmp_path / "out"))
    _one_line_refusal(r, "name")
    assert not any(tmp_path.rglob("*")), list(tmp_path.rglob("*"))  # nothing written anywhere under it
    assert not (tmp_path.parent.parent / "escaped.npz").exists()


def test_a_config_name_with_an_absolute_path_is_refused(cli, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    cfg = tmp_path / "c.yaml"
    cfg.write_text(f"name: {tmp_path / 'elsewhere' / 'victim'}\nintervals: 4\ncontact_s: [1]\n"
                   "noise_ratio: [0.01]\ntrials: 6\nfolds: 2\n")
    r = cli("sweep", "--config", str(cfg))
    _one_line_refusal(r, "name")
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["c.yaml"]


def test_a_sensor_name_with_a_newline_is_refused(cli, tmp_path):
    from designkit.sensor import SENSORS

    p = SENSORS["paper"].replace(name="two").to_yaml(tmp_path / "s.yaml")
    p.write_text(p.read_text().replace("name: two", 'name: "two\\nlines"'))
    r = cli("simulate", "--e", "400", "--sensor", str(p))
    _one_line_refusal(r, "sensor name")


# ------------------------------------------------------------------ class 5: the per-touch budget
def test_a_sensor_at_1e12_hz_is_refused_before_any_allocation(cli, tmp_path):
    import resource

    from designkit.sensor import SENSORS

    p = SENSORS["paper"].replace(sample_rate_hz=1e12, name="fast").to_yaml(tmp_path / "fast.yaml")
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    for args in (["min-contact", "--m1", "copper", "--m2", "glass"], ["simulate", "--e", "400"],
                 ["f1", "--e1", "400", "--e2", "20000"], ["distinguishable", "--m1", "copper", "--m2", "glass",
                                                        "--contact", "2"]):
        r = cli(*args, "--sensor", str(p))
        _one_line_refusal(r, "samples per touch")
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 500_000  # KiB: no GB grown


def test_the_library_enforces_the_budget_in_draw_trials():
    from designkit.simulation import draw_trials

    with pytest.raises(InputError, match="samples per touch"):
        draw_trials(400.0, 480.0, 2, 10**7, 0)
    with pytest.raises(InputError, match="memory"):
        draw_trials(400.0, 480.0, 10**9, 10**5, 0)


# ------------------------------------------------------------------ class 8: internal errors
@pytest.mark.parametrize("args", [
    ["min-contact", "--m1", "copper", "--m2", "glass", "--exact", "--max-contact", "1e308"],
    ["min-contact", "--m1", "copper", "--m2", "glass", "--exact", "--max-contact", "1e9"],
])
def test_an_absurd_longest_contact_is_refused_not_an_index_error(cli, args):
    _one_line_refusal(cli(*args), "samples per touch")


def test_matrix_at_an_absurd_contact_is_no_internal_error(cli):
    r = cli("matrix", "--m", "copper", "--m", "glass", "--m", "granite", "-q", "max-noise", "--contact", "1e308")
    assert r.exit_code in (0, 2, 3) and "internal error" not in r.output, r.output


def test_a_profile_with_an_endless_trial_window_is_refused(cli, tmp_path):
    from designkit.calibration.profiles import list_profiles

    text = list_profiles()["designkit"].read_text()
    import re

    p = tmp_path / "big.yaml"
    p.write_text(re.sub(r"post_s: .*", "post_s: 1e308", text))
    r = cli("calibrate", "record", "--port", "/dev/null", "--profile", str(p), "--out", str(tmp_path / "rec"),
            "--material", "wood")
    _one_line_refusal(r, "post_s")
    p.write_text(re.sub(r"sample_rate_hz: .*", "sample_rate_hz: 1e9", text))
    r = cli("calibrate", "record", "--port", "/dev/null", "--profile", str(p), "--out", str(tmp_path / "rec"),
            "--material", "wood")
    _one_line_refusal(r, "samples per touch")
    assert not (tmp_path / "rec").exists()


# ------------------------------------------------------------------ class 9: results lost or broken
def test_bench_out_on_a_file_is_refused_before_the_work(cli, tmp_path):
    f = tmp_path / "existing"
    f.write_text("keep me")
    _one_line_refusal(cli("bench", "--quick", "--out", str(f)), "--out", "not a folder")
    assert f.read_text() == "keep me"
    _one_line_refusal(cli("bench", "--quick", "--jobs", "0"), "jobs")


def test_csv_cells_of_numpy_scalars_are_plain_numbers():
    import numpy as np

    from designkit.cli._format import render_rows

    text = render_rows([{"a": np.float64(1.88e-12), "b": np.int64(3), "c": [np.int64(1)], "d": np.float64("nan")}],
                       fmt="csv")
    assert text.splitlines()[1] == "1.88e-12,3,[1],", text


# ------------------------------------------------------------------ class 10: accepted where it should be refused
@pytest.mark.parametrize("args, needle", [c for c in REFUSED_IN_ONE_LINE if not any(a.startswith("@") for a in c[0])],
                         ids=lambda v: " ".join(v)[:60] if isinstance(v, list) else None)
def test_refused_in_one_line(cli, tmp_path, monkeypatch, args, needle):
    monkeypatch.chdir(tmp_path)
    _one_line_refusal(cli(*args), needle)
    assert not any(tmp_path.iterdir()), list(tmp_path.iterdir())  # nothing written


def _sensor_text() -> str:
    from designkit.sensor import SENSORS

    return "\n".join(f"{k}: {v}" for k, v in SENSORS["paper"].to_dict().items() if not isinstance(v, dict)) + "\n"


@pytest.mark.parametrize("edit, needle", [
    (lambda t: re.sub(r"^designkit_sensor: \d+\n", "", t, flags=re.M), "designkit_sensor"),
    (lambda t: t + "effusivity: 900\n", "twice"),
    (lambda t: t.replace("effusivity: 892.0", "effusivity: 1e308"), "at most"),
    (lambda t: t.replace("depth_m: 8e-05", "depth_m: 1e308"), "depth"),
])
def test_a_bad_sensor_file_is_refused(cli, tmp_path, edit, needle):
    p = tmp_path / "s.yaml"
    text = _sensor_text()
    assert re.search(r"^designkit_sensor: \d+$", text, re.M) and "effusivity: 892.0" in text and "depth_m: 8e-05" in text, text
    p.write_text(edit(text))
    _one_line_refusal(cli("simulate", "--e", "400", "--sensor", str(p)), needle)


def test_the_unedited_sensor_file_answers(cli, tmp_path):
    p = tmp_path / "s.yaml"
    p.write_text(_sensor_text())
    assert cli("simulate", "--e", "400", "--sensor", str(p)).exit_code == 0


@pytest.mark.parametrize("opt, cmd", [
    ("--plot", ["simulate", "--e", "400"]), ("--out", ["simulate", "--e", "400"]),
    ("--plot", ["matrix", "--m", "copper", "--m", "glass"]),
    ("--plot", ["validity", "--m", "acrylic", "--thickness", "0.003"]),
    ("--plot", ["design", "--set", "paper12"]),
    ("--export-c", ["classify", "--m", "wood", "--m", "copper"]),
    ("--out", ["export", "--table", "svm-paper"]),
])
def test_an_output_in_a_missing_folder_is_refused_by_every_command(cli, tmp_path, opt, cmd):
    target = tmp_path / "missing" / "deeper" / "x.png"
    _one_line_refusal(cli(*cmd, opt, str(target)), opt, "does not exist")
    assert not (tmp_path / "missing").exists()


def test_output_folders_follow_one_rule(cli, tmp_path):
    f = tmp_path / "file"
    f.write_text("")
    _one_line_refusal(cli("sweep", "--name", "t", "--workdir", str(f), "--intervals", "4", "--contact", "1",
                          "--noise-ratio", "0.01"), "--workdir", "not a folder")
    _one_line_refusal(cli("sweep", "--name", "t", "--out", str(tmp_path / "a" / "b" / "t.npz"), "--intervals", "4",
                          "--contact", "1", "--noise-ratio", "0.01"), "--out", "does not exist")


# ------------------------------------------------------------------ class 11: messages
def test_a_folder_as_an_output_file_says_so_plainly(tmp_path):
    from designkit._io import atomic_write_bytes

    with pytest.raises(IsADirectoryError) as info:
        atomic_write_bytes(tmp_path, b"")
    assert str(info.value) == f"cannot write {tmp_path}: it is a folder; give a file name"


def test_an_empty_profile_says_empty(cli, tmp_path):
    p = tmp_path / "p.yaml"
    p.write_text("")
    _one_line_refusal(cli("classify", "--m", "wood", "--m", "copper", "--port", "/dev/null", "--profile", str(p)),
                      "is empty")


def test_a_refusal_after_a_warning_is_its_one_line_alone(cli, tmp_path):
    """A warning raised on the way (numpy's, loadtxt's) is held back: a refusal prints one line."""
    import subprocess
    import sys

    code = ("import warnings, sys\nfrom designkit.cli import _app\n"
            "@_app.app.command('warn-then-refuse')\n"
            "def _w():\n    warnings.warn('numpy said something', RuntimeWarning)\n"
            "    raise ValueError('the one line')\n"
            "sys.argv = ['designkit', 'warn-then-refuse']\n_app.main()\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                       env={**__import__("os").environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])})
    assert r.returncode == 2 and r.stderr.strip() == "Error: the one line", r.stderr


def test_the_one_path_rule_is_checked_by_every_table_question_before_work(cli):
    r = cli("min-contact", "--e1", "35000", "--e2", "20000", "--table", "\n")
    _one_line_refusal(r, "empty")
