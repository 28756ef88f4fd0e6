"""`calibrate fit` with model selection on the 120 shared metal and wood touches: time, against the previous code.

Run from the repository root (about 20 s of CPU per variant; be nice on shared cores)::

    nice -n 10 python benchmarks/bench_fit_time.py [--data ../shared/data/robot-thermal-recordings]

Fits all nine candidates (``compare_models``, every touch fitted, as ``calibrate fit --model all
--fit-sets all``) twice in the same process: with the current code, and with the baseline, the
previous implementations put back in place: ``scipy.signal.savgol_filter`` for the host smoothing,
the 3m-long FFT convolution of the contact area, and the warm start from the last nested
candidate. Prints CPU and wall seconds of each, their ratio, the load average (timings on shared
cores vary with it; the CPU time much less), and checks that both select the same model with the
same residual.
"""

from __future__ import annotations

import argparse
import os
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from designkit.calibration import compare as cmpm
from designkit.calibration import identify as idm
from designkit.calibration.candidates import CANDIDATES, PARAMS
from designkit.calibration.fit import parse_ranges, resolve_ranges
from designkit.calibration.trials import load_index
from designkit.models import layered


def _default_data() -> Path:
    env = os.environ.get("DESIGNKIT_ROBOT_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "shared" / "data" / "robot-thermal-recordings"


# ------------------------------------------------------------ the baseline (the code before this change)
def _savgol_baseline(values, window, order, *, pad_before=None):
    from scipy.signal import savgol_filter

    v = np.asarray(values, dtype=np.float64)
    if window <= 1:
        return v.copy()
    pad = int(pad_before or 0)
    if pad:
        v = np.concatenate([np.zeros(v.shape[:-1] + (pad,)), v], axis=-1)
    return savgol_filter(v, window, order, axis=-1, mode="interp")[..., pad:]


def _area_weighted_baseline(step, time_s, area, offset_s):
    from scipy.signal import fftconvolve

    m = time_s.size
    dt = float(time_s[1] - time_s[0])
    lags = np.arange(-(m - 1), m) * dt - offset_s
    u1 = np.zeros(lags.size)
    pos = lags > 0
    if pos.any():
        u1[pos] = step(lags[pos])
    d_area = np.diff(area, axis=-1, prepend=0.0)
    return fftconvolve(d_area, u1[None, :], axes=-1)[:, m - 1:2 * m - 1]


def _warm_start_baseline(cand, done):
    for prev in reversed(done):
        if prev.candidate.model != cand.model and not (prev.candidate.model in ("semi-infinite", "contact")
                                                       and cand.model in ("contact", "layered")):
            continue
        if not set(prev.candidate.free) <= set(cand.free):
            continue
        n_prev = len(prev.candidate.free)
        x = [prev.x[prev.candidate.free.index(p)] if p in prev.candidate.free
             else PARAMS[p].to_x(PARAMS[p].start) for p in cand.free]
        return np.concatenate([x, prev.x[n_prev:]])
    return None


@contextmanager
def _baseline():
    saved = layered.savgol_smooth, idm.area_weighted, cmpm._warm_start
    layered.savgol_smooth, idm.area_weighted, cmpm._warm_start = (_savgol_baseline, _area_weighted_baseline,
                                                                  _warm_start_baseline)
    try:
        yield
    finally:
        layered.savgol_smooth, idm.area_weighted, cmpm._warm_start = saved


def _run(trials, ranges):
    c0, t0 = time.process_time(), time.perf_counter()
    cmp = cmpm.compare_models(trials, [], CANDIDATES, ranges=ranges)
    return time.process_time() - c0, time.perf_counter() - t0, cmp


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=_default_data(), help="folder of the recordings (index.csv)")
    args = ap.parse_args()
    trials = load_index(args.data / "index.csv", only=["metal", "wood"])
    ranges = resolve_ranges(["metal", "wood"], parse_ranges(["metal=aluminium"]))
    print(f"{len(trials)} touches, {len(CANDIDATES)} candidates; load average {os.getloadavg()[0]:.2f} "
          f"(on {os.cpu_count()} cores)")
    cpu, wall, cmp = _run(trials, ranges)
    print(f"current : {cpu:6.1f} s CPU, {wall:6.1f} s wall; selected {cmp.selected} "
          f"(fit RMS {cmp.results[-1].rms_c:.5f} degC); load {os.getloadavg()[0]:.2f}")
    with _baseline():
        bcpu, bwall, bcmp = _run(trials, ranges)
    print(f"baseline: {bcpu:6.1f} s CPU, {bwall:6.1f} s wall; selected {bcmp.selected} "
          f"(fit RMS {bcmp.results[-1].rms_c:.5f} degC); load {os.getloadavg()[0]:.2f}")
    print(f"baseline / current: {bcpu / cpu:.2f}x CPU, {bwall / wall:.2f}x wall")
    for a, b in zip(cmp.results, bcmp.results):
        print(f"  {a.candidate.label:34s} {a.fit_time_s:6.1f} s vs {b.fit_time_s:6.1f} s; "
              f"BIC {a.bic:.0f} vs {b.bic:.0f}")


if __name__ == "__main__":
    main()
