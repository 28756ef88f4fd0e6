"""Identification of e_s and alpha_s with the paper's semi-infinite model (paper appendix), the engine's
semi-infinite candidate, and the checks of a calibration. Synthetic trials are made here from
the closed-form model with numpy (not through the emulator or the fitter's own code), and
the identifiable set of e_s is checked against its closed form: the model depends on e_o/e_s
only, so with ratios rho_m the data allow exactly e_s in the intersection of
[e_min,m / rho_m, e_max,m / rho_m]."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import erfc

from designkit._validation import InputError
from designkit.calibration.fit import MaterialRange, check_calibration, parse_object_temps, parse_ranges, resolve_ranges
from designkit.calibration.identify import identify
from designkit.calibration.trials import Trial
from designkit.sensor import load_sensor

E_S, TAU, OFFSET = 892.0, 80e-6 ** 2 / (4 * 1.19e-9), -0.25
TRUE = {"metal": 17530.0, "wood": 400.0}
FS = 200.0


def make_trials(materials=TRUE, n=10, sigma=0.05, seed=0, e_s=E_S, tau=TAU, offset=OFFSET, ts0=35.0, to=25.0,
                cold: dict | None = None, passive=True, drop=0.0):
    """Touches from the closed-form model: T = Ts0 + (To - Ts0) e_o/(e_s+e_o) erfc(sqrt(tau/(t-offset)))."""
    rng = np.random.default_rng(seed)
    t = np.arange(-1.0 * FS, 7.0 * FS + 1) / FS
    out = []
    for name, e_o in materials.items():
        obj_t = (cold or {}).get(name, to)
        for _ in range(n):
            tt = t - offset
            g = np.zeros_like(t)
            g[tt > 0] = erfc(np.sqrt(tau / tt[tt > 0]))
            w = e_o / (e_s + e_o)
            sensor = ts0 + (obj_t - ts0) * w * g + sigma * rng.standard_normal(t.size)
            # the passive thermistor starts at room temperature and follows the object in contact
            passive_c = to + (obj_t - to) * w * g + sigma * rng.standard_normal(t.size)
            keep = rng.random(t.size) >= drop
            obj = passive_c if passive else np.full(t.size, np.nan)
            out.append(Trial(t[keep], sensor[keep], obj[keep], np.full(keep.sum(), np.nan), name))
    return out


def ranges(metal=(0.97, 1.08), wood=(0.93, 1.02), truth=TRUE):
    return {"metal": MaterialRange("metal", truth["metal"] * metal[0], truth["metal"] * metal[1], "test"),
            "wood": MaterialRange("wood", truth["wood"] * wood[0], truth["wood"] * wood[1], "test")}


def _fit(trials, rg, **kw):
    """The paper's semi-infinite fit: the engine's semi-infinite candidate, every sample (white noise)."""
    return identify(trials, "semi-infinite", ranges=rg, fit_rate_hz=None, **kw)


# ------------------------------------------------------------------ exactness
def test_noise_free_trials_give_back_the_model_and_the_closed_form_interval():
    rg = ranges()
    res = _fit(make_trials(sigma=0.0, n=3), rg)
    p = {q.name: q for q in res.parameters}
    assert p["diffusivity_m2_s"].value == pytest.approx(1.19e-9, rel=1e-5)
    assert p["time_offset_s"].value == pytest.approx(OFFSET, abs=1e-5)
    assert res.rms_c < 1e-5
    # closed form of the identified set: e_s in the intersection of [e_min / rho, e_max / rho]
    lo = max(rg[m].e_min * E_S / TRUE[m] for m in TRUE)
    hi = min(rg[m].e_max * E_S / TRUE[m] for m in TRUE)
    assert res.consistent and "set-identified" in res.effusivity.note
    assert res.effusivity.value == pytest.approx(math.sqrt(lo * hi), rel=1e-4)
    for m, ratio in res.ratios.items():
        assert ratio.value == pytest.approx(TRUE[m] / E_S, rel=1e-4)
        assert p[f"e_o[{m}]"].value == pytest.approx(ratio.value * res.effusivity.value, rel=1e-9)


def test_scaling_every_effusivity_together_changes_nothing():
    """The reason e_s is identified only through the ranges."""
    base = make_trials(sigma=0.0, n=2)
    scaled = make_trials({k: 3 * v for k, v in TRUE.items()}, sigma=0.0, n=2, e_s=3 * E_S)
    for a, b in zip(base, scaled):
        assert np.allclose(a.sensor_c, b.sensor_c, atol=1e-12)


# ------------------------------------------------------------ noisy recovery
def test_recovers_the_sensor_within_its_uncertainty_and_5_percent():
    res = _fit(make_trials(sigma=0.05, seed=7), ranges())
    p = {q.name: q for q in res.parameters}
    for q, truth in ((res.effusivity, E_S), (p["diffusivity_m2_s"], 1.19e-9), (p["time_offset_s"], OFFSET)):
        assert q.ci95[0] <= truth <= q.ci95[1], (q, truth)
    assert res.effusivity.value == pytest.approx(E_S, rel=0.05)
    assert p["diffusivity_m2_s"].value == pytest.approx(1.19e-9, rel=0.05)
    assert res.noise_c == pytest.approx(0.05, rel=0.1)
    for m in TRUE:
        assert res.rms_by_material_c[m] == pytest.approx(0.05, rel=0.1)
        assert p[f"e_o[{m}]"].ci95[0] <= TRUE[m] <= p[f"e_o[{m}]"].ci95[1]
    assert any("alpha_s is identified at the fixed thermistor depth" in n for n in res.notes)


# ----------------------------------------------------------------- conflicts
def test_conflicting_ranges_are_reported_with_each_materials_allowed_interval():
    # metal's range only allows e_s in [1.3, 1.5] x truth, wood's only [0.5, 0.6] x truth
    rg = ranges(metal=(1.3, 1.5), wood=(0.5, 0.6))
    res = _fit(make_trials(sigma=0.02, n=4), rg)
    assert res.consistent is False and "conflict" in res.effusivity.note
    # (metal's e_o/e_s is loosely determined: its amplitude is near the full temperature difference)
    assert res.es_allowed["wood"] == pytest.approx((0.5 * E_S, 0.6 * E_S), rel=0.02)
    assert res.es_allowed["metal"][0] <= 1.3 * E_S * 1.05 and res.es_allowed["metal"][1] >= 1.5 * E_S * 0.95
    problems = check_calibration(res, make_trials(sigma=0.02, n=4))
    assert [q.kind for q in problems] == ["conflict"] and "wood allows e_s in" in problems[0].message


# --------------------------------------------------------- object temperature
def test_object_away_from_room_temperature_gets_a_free_object_temperature():
    trials = make_trials({"metal": 17530.0, "wood": 400.0, "cold_wood": 400.0}, sigma=0.03, n=5,
                         cold={"cold_wood": 12.0})
    rg = {**ranges(), "cold_wood": MaterialRange("cold_wood", 331, 506, "test")}
    res = _fit(trials, rg)
    assert res.object_modes == {"cold_wood": "free", "metal": "passive", "wood": "passive"}
    assert "cold_wood" not in res.es_allowed          # a free object temperature says nothing of e_s
    assert res.parameter("diffusivity_m2_s").value == pytest.approx(1.19e-9, rel=0.02)
    # told the object's temperature, the amplitude is known again and the ratio comes back
    told = _fit(trials, rg, object_temps={"cold_wood": 12.0})
    assert told.object_modes["cold_wood"] == 12.0
    assert told.ratios["cold_wood"].value == pytest.approx(400 / E_S, rel=0.02)


def test_no_passive_channel_needs_the_object_temperature():
    trials = make_trials(passive=False, n=3)
    with pytest.raises(InputError, match="no passive .* give its object temperature"):
        _fit(trials, ranges())
    res = _fit(trials, ranges(), object_temps={"metal": 25.0, "wood": 25.0})
    assert res.parameter("diffusivity_m2_s").value == pytest.approx(1.19e-9, rel=0.02)


# ------------------------------------------------------------------- ranges
def test_range_resolution_and_errors():
    from designkit.materials import get_material

    got = resolve_ranges(["metal", "wood"], parse_ranges(["metal=12767:25972"]))
    assert (got["metal"].e_min, got["metal"].e_max) == (12767.0, 25972.0)
    wood = get_material("wood")
    assert (got["wood"].e_min, got["wood"].e_max) == (wood.e_min, wood.e_max)
    assert "materials database" in got["wood"].source
    alias = resolve_ranges(["cold_wood"], parse_ranges(["cold_wood=wood"]))
    assert alias["cold_wood"].e_max == wood.e_max
    with pytest.raises(InputError) as exc:
        resolve_ranges(["cold_wood", "metal", "wood"], {})
    assert "cold_wood, metal" in str(exc.value) and "\n" not in str(exc.value)
    for bad in (["metal"], ["metal=1:x"], ["=1:2"], ["metal=1:2", "metal=3:4"]):
        with pytest.raises(InputError):
            parse_ranges(bad) and resolve_ranges(["metal"], parse_ranges(bad))
    with pytest.raises(InputError, match="min > max"):
        resolve_ranges(["metal"], {"metal": "5:1"})
    with pytest.raises(InputError, match="not in the index"):
        resolve_ranges(["metal"], {"glass": "1:2"})
    assert parse_object_temps(["a=free", "b=12.5", "c=passive-end"]) == {"a": "free", "b": 12.5, "c": "passive-end"}
    with pytest.raises(InputError):
        parse_object_temps(["a=lukewarm"])


# ------------------------------------------------------------------ output
def test_sensor_file_round_trips_through_load_sensor(tmp_path):
    res = _fit(make_trials(sigma=0.05, n=4), ranges())
    path = res.sensor(name="mine").to_yaml(tmp_path / "mine.yaml")
    sen = load_sensor(path)
    assert sen.effusivity == pytest.approx(res.effusivity.value)
    assert sen.diffusivity_m2_s == pytest.approx(res.parameter("diffusivity_m2_s").value)
    assert sen.noise_c == pytest.approx(res.noise_c) and sen.sample_rate_hz == pytest.approx(200.0)
    assert sen.model["name"] == "semi-infinite"
    assert sen.model["time_offset_s"] == pytest.approx(res.parameter("time_offset_s").value)


def test_guided_run_against_the_emulator_records_its_first_touch_and_labels_every_touch(cli, tmp_path):
    """Over a real pty: the emulator touches wood 3x then metal 3x; the guided run must see touch 1."""
    import json

    from designkit import SENSORS
    from designkit_lab.emulator import EmulatedMaterial, Emulator, TouchPlan
    from designkit.calibration.profiles import load_profile

    paper = SENSORS["paper"]
    mats = [EmulatedMaterial("wood", 400.0), EmulatedMaterial("metal", 17530.0)]
    out = tmp_path / "run"
    with Emulator(load_profile("designkit"), paper, mats, noise_c=0.05, speed=100.0, seed=4,
                  plan=TouchPlan(touch_every_s=13.0, touches_per_material=3)) as emu:
        r = cli("calibrate", "--port", emu.port, "--profile", "designkit", "--material", "wood", "--material",
                "metal", "--trials", "3", "--range", "wood=380:420", "--range", "metal=16700:18400", "--out", out,
                "--model", "semi-infinite", "--yes", "--json")
    assert r.exit_code == 0, r.output
    onsets = {}
    for side in sorted(out.glob("*.json")):
        onsets[side.stem] = json.loads(side.read_text())["onset_device_time_s"]
    first = min(onsets.values())
    assert first < 13.0, onsets                       # touch 1 (heat from 2 s) is recorded
    for name, t in onsets.items():                    # touches 1-3 are wood, 4-6 metal
        touch = int(round((t - first) / 13.0))
        assert name.startswith("wood" if touch < 3 else "metal"), onsets
    res = json.loads(r.stdout)["fit"]["results"][0]
    assert res["consistent"]
    assert res["effusivity"]["interval"]["low"] <= paper.effusivity <= res["effusivity"]["interval"]["high"]


def _write(folder, trials):
    from designkit.calibration.trials import write_trial

    for tr in trials:
        write_trial(folder, tr.material, tr.time_s, tr.sensor_c, tr.object_c, tr.force_n, {"profile": "test"})
    return folder / "index.csv"


def test_mislabelled_touches_stop_the_fit_from_writing_a_sensor_file(cli, tmp_path):
    trials = make_trials(n=4, seed=3)
    wood = [tr for tr in trials if tr.material == "wood"]
    metal = [tr for tr in trials if tr.material == "metal"]
    swapped = wood[:3] + metal[:1]                     # a metal touch recorded as wood, and vice versa
    swapped = [Trial(tr.time_s, tr.sensor_c, tr.object_c, tr.force_n, "wood") for tr in swapped]
    swapped += [Trial(tr.time_s, tr.sensor_c, tr.object_c, tr.force_n, "metal") for tr in metal[1:] + wood[3:]]
    index = _write(tmp_path / "t", swapped)
    out = tmp_path / "s.yaml"
    r = cli("calibrate", "fit", index, "--range", "metal=aluminium", "--out", out, "--model", "semi-infinite")
    assert r.exit_code == 2 and not out.exists(), r.output
    assert "look like another material" in r.output and "looks like metal" in r.output
    assert "record those materials again" in r.output and "not written" in r.output
    r = cli("calibrate", "fit", index, "--range", "metal=aluminium", "--out", out, "--model", "semi-infinite", "--force")
    assert r.exit_code == 0 and out.exists() and "warning:" in r.output


def test_conflicting_ranges_stop_the_fit_unless_forced(cli, tmp_path):
    index = _write(tmp_path / "t", make_trials(n=3, seed=5))
    out = tmp_path / "s.yaml"
    # wood's range put where no e_s agrees with metal's
    args = ("calibrate", "fit", index, "--range", "wood=40:50", "--range", "metal=aluminium", "--out", out,
            "--model", "semi-infinite")
    r = cli(*args)
    assert r.exit_code == 2 and not out.exists(), r.output
    assert "ranges conflict" in r.output and "--force" in r.output and "calibrate fit --model all" in r.output
    r = cli(*args, "--force")
    assert r.exit_code == 0 and out.exists()
    assert "conflict" in " ".join(load_sensor(out).provenance["problems"])


def test_a_sensor_colder_than_the_object_is_a_wiring_error(cli, tmp_path):
    mirrored = [Trial(tr.time_s, 50.0 - tr.sensor_c, tr.object_c, tr.force_n, tr.material)
                for tr in make_trials(n=3, seed=6)]     # 35 degC read as 15, as from the wrong side of a divider
    index = _write(tmp_path / "t", mirrored)
    r = cli("calibrate", "fit", index, "--range", "metal=aluminium", "--out", tmp_path / "s.yaml", "--model", "semi-infinite")
    assert r.exit_code == 2, r.output
    assert "reads colder than the object" in r.output and "side of its divider" in r.output


@pytest.mark.parametrize("how", ["heater off", "flat"])
def test_touches_in_which_no_heat_flows_are_refused_not_fitted(cli, tmp_path, how):
    """The heater off (the sensor at the object's temperature, only noise), or a sensor channel stuck at one
    value: a fit gave e_s 132 (true 892) or 3.6e9 "at upper bound", called it set-identified and wrote the
    file with exit 0. Now: one problem that says no heat flowed, exit 2, no file (--force still writes)."""
    rng = np.random.default_rng(8)
    trials = make_trials(n=3, seed=7)
    if how == "heater off":
        cold = [Trial(tr.time_s, tr.object_c + rng.normal(0.0, 0.05, tr.time_s.size), tr.object_c, tr.force_n,
                      tr.material) for tr in trials]
    else:
        cold = [Trial(tr.time_s, np.full(tr.time_s.size, 35.0), tr.object_c, tr.force_n, tr.material)
                for tr in trials]
    index = _write(tmp_path / "t", cold)
    out = tmp_path / "s.yaml"
    args = ("calibrate", "fit", index, "--range", "metal=aluminium", "--out", out, "--model", "semi-infinite")
    r = cli(*args)
    assert r.exit_code == 2 and not out.exists(), r.output
    assert "does not respond to contact in 6 of 6 touches" in r.output and "no heat flowed" in r.output
    # --force writes past a problem, not past physics: what these touches identify (e_s of 1e7 and more)
    # is no sensor designkit can load, so the file is refused in one line naming the value
    forced = cli(*args, "--force")
    assert forced.exit_code == 2 and not out.exists(), forced.output
    assert [ln for ln in forced.output.splitlines() if ln.startswith("Error:")] == [
        next(ln for ln in forced.output.splitlines() if ln.startswith("Error: effusivity sensor e_s must be at most"))]
    good = _write(tmp_path / "good", trials)  # the same touches with the heater on: no such problem
    r = cli("calibrate", "fit", good, "--range", "metal=aluminium", "--out", tmp_path / "g.yaml", "--model", "semi-infinite")
    assert "does not respond" not in r.output


def test_touches_below_the_contact_threshold_get_a_hint_with_their_peak_force(cli, tmp_path):
    """The emulated rig presses with 4.2 N; the profile's threshold is 5 N: no touch would ever be recorded."""
    from designkit import SENSORS
    from designkit_lab.emulator import EmulatedMaterial, Emulator, TouchPlan
    from designkit.calibration.profiles import load_profile

    prof = load_profile("designkit")
    assert prof.contact.force_threshold_n == 5.0
    import dataclasses

    rig = dataclasses.replace(prof, contact=dataclasses.replace(prof.contact, force_threshold_n=3.0, release_n=1.5))
    with Emulator(rig, SENSORS["paper"], [EmulatedMaterial("wood", 400.0)], noise_c=0.05, speed=20.0, seed=1,
                  plan=TouchPlan(touch_every_s=13.0, press_force_n=4.2)) as emu:
        r = cli("calibrate", "--port", emu.port, "--profile", "designkit", "--material", "wood", "--trials", "2",
                "--range", "wood=380:420", "--out", tmp_path / "run", "--model", "semi-infinite", "--yes", "--timeout", "30")
    assert r.exit_code == 2, r.output
    assert "touches were not recorded" in r.output and "threshold of 5 N" in r.output
    # the peaks are the highest live force readings, 4.2 N plus the emulator's 0.02 N force noise: "4.2 N" or,
    # when one touch's noisiest reading rounds up, a range such as "4.2-4.3 N" (CI stop 45 printed the latter)
    import re

    peaks = re.search(r"peaked at ([0-9.]+)(?:-([0-9.]+))? N", " ".join(r.output.split()))
    assert peaks, r.output
    assert all(4.0 <= float(v) <= 4.4 for v in peaks.groups() if v is not None), peaks.group(0)
    assert "force_threshold_n" in r.output


def test_data_lines_that_start_with_the_comment_prefix_are_named(cli, tmp_path):
    """A rig writing '#T,...' data lines under a profile with comment '#': every sample would be a message."""
    import os
    import threading
    import tty

    master, slave = os.openpty()
    tty.setraw(slave)
    port = os.ttyname(slave)
    stop = threading.Event()

    def rig():
        k = 0
        while not stop.is_set():
            lines = "".join(f"#T,{(k + i) / 200:.3f},35.00,25.00,0.0\n" for i in range(50))
            try:
                os.write(master, lines.encode())
            except OSError:
                return
            k += 50
            stop.wait(0.01)

    th = threading.Thread(target=rig, daemon=True)
    th.start()
    try:
        r = cli("calibrate", "--port", port, "--profile", "designkit", "--material", "wood", "--trials", "1",
                "--range", "wood=380:420", "--out", tmp_path / "run", "--model", "semi-infinite", "--yes", "--timeout", "20")
    finally:
        stop.set()
        th.join(2)
        os.close(master)
        os.close(slave)
    assert r.exit_code == 2, r.output
    assert "start with the profile's comment prefix '#'" in r.output and "look like data lines" in r.output
    assert "Set the profile's comment" in r.output


def test_an_index_listing_a_trial_twice_is_refused_naming_its_lines(cli, tmp_path):
    """The same touch listed twice was fitted as two touches, without a word (overstated confidence)."""
    index = _write(tmp_path / "t", make_trials(n=2, seed=9))
    lines = index.read_text().splitlines()
    index.write_text("\n".join(lines + [lines[1]]) + "\n")
    r = cli("calibrate", "fit", index, "--range", "metal=aluminium", "--model", "semi-infinite", "--force")
    name = lines[1].split(",")[0]
    assert r.exit_code == 2 and r.stderr.count("\n") == 1, r.output
    assert f"lists {name} twice (lines 2 and {len(lines) + 1})" in r.stderr
