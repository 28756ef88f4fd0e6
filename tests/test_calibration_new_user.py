"""Rough edges a new user hit with the calibration commands (issue 14's walkthrough): each through the CLI."""

from __future__ import annotations

import json
import shlex

import pytest
from test_calibration_cli import METER_RANGES, _synthetic_index

RANGES = sum((["--range", x] for x in METER_RANGES), [])


def _png_size(path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


# ------------------------------------------------ calibrate fit --model --plot
@pytest.mark.parametrize("model", ["semi-infinite", "contact"])
def test_fit_with_a_model_writes_the_plot(cli, tmp_path, model):
    index = _synthetic_index(tmp_path / "trials", n=3)
    plot = tmp_path / "fig" / "fit.png"
    r = cli("calibrate", "fit", index, *RANGES, "--model", model, "--plot", plot)
    assert r.exit_code == 0, r.output
    assert f"wrote {plot}" in r.stdout
    w, h = _png_size(plot)
    assert w > 1000 and h > 300
    r = cli("calibrate", "fit", index, *RANGES, "--model", model, "--plot", tmp_path / "j.png", "--json")
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["plot"] == str(tmp_path / "j.png") and (tmp_path / "j.png").exists()


def test_a_refused_model_fit_still_writes_its_plot(cli, tmp_path):
    """As without --model: the figure shows why the sensor file was refused."""
    index = _synthetic_index(tmp_path / "trials", n=3)
    plot, out = tmp_path / "refused.png", tmp_path / "s.yaml"
    r = cli("calibrate", "fit", index, "--range", "metal=100:200", "--range", "wood=331:506",
            "--model", "semi-infinite", "--out", out, "--plot", plot)
    assert r.exit_code == 2 and "not written" in r.stderr
    assert not out.exists()
    _png_size(plot)
