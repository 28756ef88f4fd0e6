"""Rough edges a new user hit, each as the user met it: error lines that name what the user typed (not a
temporary file, not numpy's advice, not a bare errno), no folders made from a typo, absurd effusivities
refused by name, the delta-e legend only when it explains something, and the robot recordings found from
where the user runs ``reproduce``."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

SHARED_TRIAL = "set01_cold_wood_2.csv"


def _one_error_line(r) -> str:
    assert r.exit_code == 2, r.output
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: "), r.output
    assert "Traceback" not in r.output and "[Errno" not in r.output
    return lines[0]


# ------------------------------------------------------------------ write errors
def test_unwritable_out_names_the_users_file_not_a_temporary_one(cli, tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    line = _one_error_line(cli("simulate", "--e", "20000", "--contact", "1", "--trials", "2",
                               "--out", str(blocker / "x.csv")))
    # refused before the work (issue 36: the output folder checked as export checks it)
    assert f"--out {blocker / 'x.csv'}" in line and "is not a folder" in line and ".tmp" not in line


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc (a folder no file can be made in)")
def test_export_into_a_folder_that_refuses_files_names_the_out_path(cli):
    line = _one_error_line(cli("export", "--format", "c", "--noise", "0.05", "--delta-t", "10",
                               "--out", "/proc/designkit-x.h"))
    assert "cannot write /proc/designkit-x.h" in line and ".tmp" not in line


def test_export_refuses_a_missing_folder_and_creates_none(cli, tmp_path):
    out = tmp_path / "no" / "such" / "x.h"
    line = _one_error_line(cli("export", "--format", "c", "--out", str(out)))
    assert f"--out {out}" in line and "does not exist" in line
    assert not (tmp_path / "no").exists()
    r = cli("export", "--format", "c", "--out", str(out), "--json")
    assert r.exit_code == 2 and "does not exist" in json.loads(r.stdout)["error"]["message"]
    ok = cli("export", "--format", "c", "--noise", "0.05", "--delta-t", "10", "--out", str(tmp_path / "x.h"))
    assert ok.exit_code == 0 and (tmp_path / "x.h").is_file()


# ------------------------------------------------------------------ read errors
def test_matrix_from_a_missing_file_names_the_option(cli, tmp_path):
    line = _one_error_line(cli("matrix", "--from", str(tmp_path / "none.csv")))
    assert line == f"Error: --from {tmp_path / 'none.csv'}: cannot read it (No such file or directory)"
    assert "--from" in _one_error_line(cli("matrix", "--from", str(tmp_path)))


@pytest.fixture
def trial_dir(tmp_path, robot_data_dir):
    src = (robot_data_dir / SHARED_TRIAL).read_text()
    lines = src.splitlines(keepends=True)
    (tmp_path / "whole.csv").write_text(src)
    cut = "".join(lines[:80]) + lines[80][:12]  # a recording cut off in the middle of a row
    (tmp_path / "cut.csv").write_text(cut)
    (tmp_path / "index.csv").write_text("file,material,trial_set,trial_index\ncut.csv,wood,1,1\nwhole.csv,wood,1,2\n")
    return tmp_path


def test_truncated_trial_file_says_which_line_in_the_files_terms(cli, trial_dir):
    line = _one_error_line(cli("calibrate", "fit", str(trial_dir / "index.csv"), "--range", "wood=331:506",
                               "--out", str(trial_dir / "s.yaml")))
    assert "cut.csv: line 81 has 2 of the header's 5 columns" in line and "truncated" in line
    assert "usecols" not in line
    assert not (trial_dir / "s.yaml").exists()


def test_trial_value_that_is_not_a_number_is_located(trial_dir):
    from designkit.calibration.trials import read_trial_csv

    lines = (trial_dir / "whole.csv").read_text().splitlines(keepends=True)
    lines[9] = lines[9].replace(",", ",x", 1)
    (trial_dir / "bad.csv").write_text("".join(lines))
    with pytest.raises(ValueError, match=r"line 10, column 2: 'x.*' is not a number"):
        read_trial_csv(trial_dir / "bad.csv")


# ------------------------------------------------------------------ effusivities
@pytest.mark.parametrize("args, name", [
    (("min-contact", "--e1", "1e30", "--e2", "20000"), "e1"),
    (("distinguishable", "--e1", "35000", "--e2", "2e7", "--contact", "1"), "e2"),
    (("delta-e", "--e", "1e30", "--contact", "1"), "e"),
])
def test_absurd_effusivity_is_refused_by_name_and_range(cli, args, name):
    line = _one_error_line(cli(*args))
    assert line.startswith(f"Error: effusivity {name} must be at most 1e+07 J s^-1/2 K^-1 m^-2")
    assert "width" not in line


def test_largest_accepted_effusivity_still_answers(cli):
    from designkit._validation import MAX_EFFUSIVITY, check_effusivity

    assert check_effusivity("e", MAX_EFFUSIVITY) == MAX_EFFUSIVITY
    assert check_effusivity("e", float("inf"), allow_inf=True) == float("inf")  # the physics layer's limit
    assert cli("min-contact", "--e1", "35000", "--e2", "20000").exit_code == 0


# ------------------------------------------------------------------ delta-e legend
def test_delta_e_legend_only_when_a_dash_is_shown(cli):
    both = cli("delta-e", "--e", "20000", "--contact", "2")
    assert both.exit_code == 0, both.output
    assert "—" not in both.output and "no distinguishable effusivity" not in both.output
    edge = cli("delta-e", "--e", "39000", "--contact", "0.5")
    assert edge.exit_code == 0, edge.output
    assert ": — SVM" in edge.output and "— : no distinguishable effusivity" in edge.output


# ------------------------------------------------------------------ reproduce's robot data
def test_robot_data_found_from_the_folder_the_user_runs_in(tmp_path, monkeypatch):
    from designkit_lab.reproduce import default_robot_data_dir

    monkeypatch.delenv("DESIGNKIT_ROBOT_DATA", raising=False)
    data = tmp_path / "shared" / "data" / "robot-thermal-recordings"
    data.mkdir(parents=True)
    (data / "index.csv").write_text("file,material\n")
    work = tmp_path / "my-repo" / "scripts"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)
    assert default_robot_data_dir() == data.resolve()
    assert "site-packages" not in str(default_robot_data_dir(tmp_path / "my-repo"))
    monkeypatch.setenv("DESIGNKIT_ROBOT_DATA", str(tmp_path / "elsewhere"))
    assert default_robot_data_dir() == tmp_path / "elsewhere"


def test_reproduce_says_where_it_looked_and_keeps_robot_data(cli, tmp_path, monkeypatch):
    monkeypatch.delenv("DESIGNKIT_ROBOT_DATA", raising=False)
    r = cli("reproduce", "--help")
    assert "--robot-data" in r.output and "current folder" in " ".join(r.output.split())
    from designkit_lab.reproduce import ReproduceSettings

    assert ReproduceSettings(robot_data=tmp_path).robot_data_dir == tmp_path
