"""min-contact from an SVM table without a closed-form ideal observer is not late (issue 34).

A calibrated rig's table answered later than fresh-seed F1 curves put the crossing (6.9 % on 204 vs 535, 7.8 % on
2262 vs 5435 J s^-1/2 K^-1 m^-2: benchmarks/results/sensor_table_bias.txt): the grid rule's maximum of the two
directions' needs is the larger of two noisy readings of one distance, and the rounding correction was applied
only inside the uncorrected need's cell. Here a synthetic table whose staircases come from a known need
``d*(t)`` (the same at every reference, rounded up to the grid and read with Monte Carlo noise, as a sweep's
first passing partner is) answers random pairs; their true crossing is ``d*(t) = gap``.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from designkit.query import min_contact
from designkit.sweep import SweepConfig
from designkit.sweep.search import delta_from_staircase
from designkit.tables.store import load_table, table_header, write_table

CONTACTS = tuple(float(c) for c in np.round(np.geomspace(0.75, 6.0, 8), 3))  # the rig's grid: ratio 1.35
W, N, A, P = 80.0, 120, 1200.0, 1.5  # need d*(t) = A t^-P [J s^-1/2 K^-1 m^-2]
SD_LOG, Z = 0.12, 2.0  # Monte Carlo noise of a staircase's reading (log), the table's z


def _table(seed: int):
    """A fixed-condition SVM table of the contact model (no closed form), from noisy staircases of ``d*``."""
    rng = np.random.default_rng(seed)
    cfg = SweepConfig(name=f"bias-{seed}", e_min=0.0, e_max=N * W, intervals=N, noise_ratio=(0.004,),
                      contact_s=CONTACTS, model={"name": "contact", "conductance_w_m2k": 1500.0})
    arrays = {f"delta_{d}{t}": np.empty((1, len(CONTACTS), N)) for d in ("up", "down") for t in ("", "_lo", "_hi")}
    idx = np.arange(N)
    for k, t in enumerate(CONTACTS):
        d = A * t ** -P * np.exp(SD_LOG * rng.standard_normal(N))  # each reference's reading of the need
        for tag, z in (("", 0.0), ("_lo", -Z), ("_hi", Z)):  # the ends: the staircases at mean -+ z SE
            J = idx + np.maximum(np.ceil(d * np.exp(z * SD_LOG) / W), 1).astype(np.int64)  # first passing partner
            arrays[f"delta_up{tag}"][0, k], arrays[f"delta_down{tag}"][0, k] = delta_from_staircase(
                np.minimum(J, N), W)
    arrays["fits"] = np.zeros((1, len(CONTACTS)), dtype=np.int64)
    folder = Path(tempfile.mkdtemp(prefix="dk-bias-"))
    return load_table(write_table(folder / f"bias-{seed}.npz", table_header(cfg, arrays), arrays))


def test_min_contact_from_a_table_without_closed_form_is_not_late():
    rng = np.random.default_rng(34)
    gap = np.exp(rng.uniform(np.log(150.0), np.log(700.0), 60))  # crossings from 1.2 to 3.7 s
    lo = rng.uniform(1500.0, N * W - 2500.0, gap.size)
    truth = (A / gap) ** (1.0 / P)
    errors, held = [], []
    for seed in range(4):  # four tables: their Monte Carlo draws
        a = min_contact(lo, lo + gap, table=_table(seed), noise_c=0.004, delta_t_c=1.0, ideal_bound=False)
        assert np.all(a.value > 0)
        errors.append(np.log(a.value / truth))
        held.append((a.low <= truth) & (truth <= a.high))
    errors = np.concatenate(errors)
    # the old rule: 4 % late (median), 71 % of the answers late, 80 % of its 90 % intervals held, and no answer
    # on 8 of the 240; now within 2 % and not one-sided
    assert abs(np.median(errors)) < 0.02, np.median(errors)
    assert 0.3 < np.mean(errors > 0) < 0.7
    assert np.mean(np.concatenate(held)) > 0.85  # the stated 90 % intervals hold the true crossing
