"""Sweep engine: each shortcut against the brute-force answer it replaces."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designkit import InputError
from designkit.sweep import (
    ChunkResult,
    SweepConfig,
    assemble,
    delta_from_staircase,
    ideal_staircase,
    run_chunk,
    run_scene,
    staircase_search,
)
from designkit.recognition.ideal import ideal_scores, projection_noise


@st.composite
def monotone_staircases(draw):
    n = draw(st.integers(2, 60))
    steps = draw(st.lists(st.integers(0, 3), min_size=n, max_size=n))
    start = draw(st.integers(1, 5))
    J = np.minimum(np.maximum(np.cumsum(steps) + start, np.arange(n) + 1), n)
    J = np.maximum.accumulate(J)
    return n, J


@settings(max_examples=200, deadline=None)
@given(monotone_staircases(), st.integers(0, 2**16))
def test_staircase_finds_every_monotone_boundary(case, seed):
    n, J_true = case
    rng = np.random.default_rng(seed)
    calls = []

    def decide(i, j):
        calls.append((i, j))
        return j >= J_true[i]

    # floors at or below the truth must not change the answer, nor asking in batches
    floor = np.maximum(J_true - rng.integers(0, 4, n), 0)
    for kw in ({}, {"floor": floor}, {"anchor_every": 3}, {"floor": floor, "anchor_every": 8}):
        calls.clear()
        got = staircase_search(decide, range(n), n, **kw)
        np.testing.assert_array_equal(got, J_true)
        # never asks twice, and far fewer questions than the n^2/2 full matrix
        assert len(calls) == len(set(calls))
        assert len(calls) <= n + 2 * n * np.log2(n + 1)
        batched = staircase_search(None, range(n), n, decide_many=lambda pairs: [decide(i, j) for i, j in pairs], **kw)
        np.testing.assert_array_equal(batched, J_true)


@settings(max_examples=100, deadline=None)
@given(st.integers(2, 40), st.integers(0, 2**16), st.integers(1, 6), st.sampled_from([None, 2, 3, 8]))
def test_a_row_answer_does_not_depend_on_the_other_rows_searched(n, seed, parts, anchor_every):
    """Noisy (not monotone) decisions: any split of the rows gives the same J (a table is a function
    of its config, whatever --blocks), also when rows start from guesses of their anchors' answers."""
    noisy = np.random.default_rng(seed).random((n, n)) < 0.5
    rows = np.arange(n)
    whole = staircase_search(lambda i, j: bool(noisy[i, j]), rows, n, anchor_every=anchor_every)
    split = np.concatenate([staircase_search(lambda i, j: bool(noisy[i, j]), part, n, anchor_every=anchor_every)
                            for part in np.array_split(rows, parts) if part.size])
    np.testing.assert_array_equal(split, whole)
    # a crossing: false below J (or J at its floor), true at J
    for i, J in enumerate(whole):
        assert J == n or noisy[i, J]
        assert J == i + 1 or J == n or not noisy[i, J - 1]


def test_guided_rows_ask_fewer_questions_where_the_staircase_is_smooth():
    """Rows starting from their anchors' interpolated answers need a few probes each, not a gallop
    from the floor; the answers are the same (exactly monotone decisions)."""
    n = 300
    J_true = np.minimum(np.arange(n) + 25 + np.arange(n) // 7, n)
    asked = {}
    for every in (None, 8):
        calls = []
        got = staircase_search(lambda i, j: calls.append((i, j)) or j >= J_true[i], range(n), n, anchor_every=every)
        np.testing.assert_array_equal(got, J_true)
        asked[every] = len(calls)
    assert asked[8] < 0.6 * asked[None], asked


def test_delta_from_staircase_matches_the_decision_matrix():
    rng = np.random.default_rng(0)
    n, width = 30, 80.0
    J = np.maximum.accumulate(np.minimum(np.arange(n) + 1 + rng.integers(0, 4, n).cumsum() // 3, n))
    D = np.array([[j > i and j >= J[i] for j in range(n)] for i in range(n)])  # distinguishable (i < j)
    up, down = delta_from_staircase(J, width)
    for i in range(n):
        partners = [j for j in range(i + 1, n) if D[i, j]]
        assert (np.isnan(up[i]) and not partners) or up[i] == (partners[0] - i) * width
        lower = [k for k in range(i) if D[k, i]]
        assert (np.isnan(down[i]) and not lower) or down[i] == (i - max(lower)) * width


def test_ideal_staircase_equals_the_full_closed_form_matrix(paper_sensor):
    cfg = SweepConfig(intervals=60, fidelity="ideal", contact_s=(1.5,))
    scene = cfg.scene((0,), 1.5)
    s = projection_noise(paper_sensor, scene)
    e = cfg.edges
    n = cfg.intervals
    ii, jj = np.triu_indices(n, 1)
    f1, _ = ideal_scores(e[ii], e[ii + 1], e[jj], e[jj + 1], paper_sensor.effusivity, s, accuracy=False)
    M = np.zeros((n, n), bool)
    M[ii, jj] = f1 >= cfg.threshold
    brute = np.array([next((j for j in range(i + 1, n) if M[i, j]), n) for i in range(n)])
    np.testing.assert_array_equal(ideal_staircase(cfg, paper_sensor, s, np.arange(n)), brute)


@pytest.mark.slow
def test_staircase_agrees_with_the_full_matrix(paper_sensor):
    """Same delta(e) to within one interval; the full matrix's answer inside the Monte Carlo interval."""
    kw = dict(intervals=24, trials=40, noise_ratio=(0.005,), contact_s=(1.0,), max_repeats=3)
    fast = run_scene(SweepConfig(**kw))[0]
    full = run_scene(SweepConfig(full_matrix=True, **kw))[0]
    assert full.fits > 2.5 * fast.fits
    within_one = np.abs(fast.J - full.J) <= 1
    assert within_one.mean() >= 0.9, (fast.J, full.J)
    inside = (full.J >= fast.J_lo - 1) & (full.J <= fast.J_hi + 1)
    assert inside.mean() >= 0.9
    assert np.all(fast.J_lo <= fast.J) and np.all(fast.J <= fast.J_hi)
    # no SVM fit below the ideal observer's staircase
    cells = fast.cells
    assert np.all(cells[:, 1] >= fast.J_ideal[cells[:, 0].astype(int)])


@pytest.mark.slow
def test_noise_ratio_shortcut_equals_sweeping_noise_and_delta_t(paper_sensor):
    """The sigma/dT invariance used to collapse two axes into one gives the same staircase."""
    common = dict(intervals=20, trials=30, contact_s=(1.5,), max_repeats=2)
    by_ratio = run_chunk(SweepConfig(noise_ratio=(0.005,), **common), (0,), 0, 0)
    by_pair = run_chunk(SweepConfig(noise_ratio=None, noise_c=(0.05,), delta_t_c=(10.0,), **common), (0, 0), 0, 0)
    np.testing.assert_array_equal(by_ratio.J, by_pair.J)
    np.testing.assert_array_equal(by_ratio.J_hi, by_pair.J_hi)
    np.testing.assert_allclose(by_ratio.cells, by_pair.cells, atol=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("solver", ["sklearn", "batched"])
def test_a_table_is_a_function_of_its_config_whatever_the_split(solver, tmp_path):
    """Same arrays for several --blocks, --jobs and backends, and a contact time swept alone gives
    that contact's rows of the full table (no warm start reaches across chunks)."""
    from designkit.sweep import run_sweep
    from designkit.tables.store import content_hash, load_table

    base = dict(intervals=12, trials=15, noise_ratio=(0.005,), contact_s=(1.0, 2.0), max_repeats=2, solver=solver)
    tables = {}
    for blocks, jobs, backend in ((1, 1, "sequential"), (3, 1, "sequential"), (5, 2, "loky")):
        cfg = SweepConfig(name=f"t{blocks}", blocks=blocks, **base)
        path = run_sweep(cfg, tmp_path / f"w{blocks}", jobs=jobs, backend=backend)
        tables[(blocks, jobs, backend)] = load_table(path)
    ref = tables[(1, 1, "sequential")]
    for key, t in tables.items():
        assert sorted(t.arrays) == sorted(ref.arrays), key
        for name in ref.arrays:
            np.testing.assert_array_equal(t.arrays[name], ref.arrays[name], err_msg=f"{key} {name}")
    assert "chunk_wall_s" not in ref.arrays  # timings are in the header's run stats
    assert len({content_hash(t.arrays) for t in tables.values()}) == 1
    assert len(ref.header["stats"]["run"]["chunk_wall_s"]) == 1
    alone = run_chunk(SweepConfig(contact_s=(2.0,), **{k: v for k, v in base.items() if k != "contact_s"}), (0,), 0, 0)
    both = run_scene(SweepConfig(**base))[1]
    for name in ("J", "J_lo", "J_hi"):
        np.testing.assert_array_equal(getattr(alone, name), getattr(both, name), err_msg=name)


def test_the_gpu_code_path_run_on_numpy_gives_the_numpy_table(tmp_path):
    """``--solver batched-array-api`` runs the batched solver's generic array-API code, the code
    ``batched-cupy`` runs on a GPU, on numpy instead of the numpy fast path (which folds the
    standardization into float32 products of prepared deviations). The arithmetic differs, the table
    must not: what a GPU build should give, checked without a GPU."""
    pytest.importorskip("array_api_compat", reason="array-api-compat is in the test and gpu extras")
    from designkit.sweep import run_sweep
    from designkit.tables.store import load_table

    base = dict(intervals=40, trials=30, noise_ratio=(0.005, 0.02), contact_s=(0.5, 2.0), seed=2, max_repeats=2)
    fast = load_table(run_sweep(SweepConfig(name="fast", **base), tmp_path / "fast", backend="sequential"))
    generic = load_table(run_sweep(SweepConfig(name="generic", solver="batched-array-api", **base),
                                   tmp_path / "generic", backend="sequential"))
    assert generic.header["stats"]["run"]["solver"] == "batched-array-api"
    assert sorted(generic.arrays) == sorted(fast.arrays)
    for name in fast.arrays:
        np.testing.assert_array_equal(generic.arrays[name], fast.arrays[name], err_msg=name)
    assert fast.arrays["fits"].sum() > 100  # the SVM was fitted, not only the ideal floor


#: An older x86-64 CPU as one machine can emulate it: OpenBLAS's Nehalem kernels (numpy's wheels are built
#: with DYNAMIC_ARCH) and numpy's loops without AVX, AVX2 or AVX-512 (its SSE4.2 baseline only).
OLDER_CPU = {"OPENBLAS_CORETYPE": "Nehalem", "NPY_DISABLE_CPU_FEATURES": "X86_V3 X86_V4 AVX512_ICL AVX512_SPR"}
#: One chunk of a small scene and the decision values of a few of its pairs, as JSON (run on each CPU).
_CHUNK_AND_DECISIONS = """
import json, sys, numpy as np, threadpoolctl
from designkit.sweep import SweepConfig, run_chunk
from designkit.sweep.scorer import PairScorer
cfg = SweepConfig(**json.loads(sys.argv[1]))
r = run_chunk(cfg, (0,), 0, 0)
sc = PairScorer(cfg, cfg.resolved_sensor(), cfg.scene((0,), cfg.contact_s[0]))
dec = sc.decisions([(i, i + 3, 0) for i in range(0, 30, 5)])
print(json.dumps({"blas": sorted({i.get("architecture") for i in threadpoolctl.threadpool_info()}),
                  "J": [r.J.tolist(), r.J_lo.tolist(), r.J_hi.tolist()], "fits": int(r.fits),
                  "cells": np.asarray(r.cells).tolist(), "decision": dec.tolist()}))
"""


@pytest.mark.skipif(__import__("platform").machine() not in ("x86_64", "AMD64"),
                    reason="emulates an older x86-64 CPU (OpenBLAS core types, numpy's x86 dispatch)")
def test_a_table_is_the_same_on_an_older_cpu_whose_arithmetic_rounds_differently():
    """Another machine runs other SIMD code in numpy and other BLAS kernels (the solver's float32 Gram
    products), so its decision values differ in their last bits; the table must not. Both halves are
    asserted: the emulated CPU's decisions differ from this one's (else the test proves nothing), its
    staircases, fits and F1 cells do not. benchmarks/bench_machines.py does the same on svm-paper scenes."""
    import json
    import os

    base = json.dumps(dict(intervals=40, trials=30, noise_ratio=(0.005,), contact_s=(1.0,), seed=2, max_repeats=2))
    env = {k: v for k, v in os.environ.items() if k not in OLDER_CPU}
    runs = {}
    for name, extra in (("here", {}), ("older", OLDER_CPU)):
        r = subprocess.run([sys.executable, "-c", _CHUNK_AND_DECISIONS, base], capture_output=True, text=True,
                           timeout=300, env={**env, **extra})
        assert r.returncode == 0, r.stderr
        runs[name] = json.loads(r.stdout)
    here, older = runs["here"], runs["older"]
    if older["blas"] != ["Nehalem"]:
        pytest.skip(f"this BLAS does not take OPENBLAS_CORETYPE (it runs {older['blas']}): nothing emulated")
    moved = np.abs(np.asarray(older["decision"]) - np.asarray(here["decision"]))
    assert moved.max() > 0, "the emulated CPU computed bit-identical decisions: the emulation did not take"
    assert moved.max() < 1e-4  # rounding, not another classifier
    assert older["J"] == here["J"]
    assert older["fits"] == here["fits"]
    np.testing.assert_array_equal(np.asarray(older["cells"]), np.asarray(here["cells"]))


def _staircases_by_row(cfg: SweepConfig) -> dict[int, tuple[int, int, int]]:
    out = {}
    for b in range(len(cfg.blocks_of())):
        r = run_chunk(cfg, (0,), b, 0)
        out.update({row: (int(r.J[i]), int(r.J_lo[i]), int(r.J_hi[i])) for i, row in enumerate(r.rows.tolist())})
    return out


def test_rows_beside_a_block_boundary_do_not_depend_on_the_split():
    """A guided search starts each row from its anchors' answers (every 8th row). An anchor in another
    block was searched from floor 0 instead of the ideal observer's floor, found another crossing of the
    noisy decisions, and the rows guessed from it moved: in this scene (chosen because it showed it, among
    seeds 0-5) rows 17-22 with --blocks 3 and 5 differed from --blocks 1. A 500-interval scene of svm-paper
    moved likewise with --blocks 3."""
    base = dict(intervals=60, trials=20, noise_ratio=(0.005,), contact_s=(1.0,), seed=5, max_repeats=2)
    ref = _staircases_by_row(SweepConfig(blocks=1, **base))
    for blocks in (3, 5):
        split = _staircases_by_row(SweepConfig(blocks=blocks, **base))
        assert split == ref, [r for r in ref if split[r] != ref[r]]


@pytest.mark.slow
def test_the_boundary_recomputation_script_restores_exactly_the_rows_it_names(tmp_path):
    """benchmarks/recompute_boundary_rows.py (how the shipped svm-fine was brought up to the fix above)
    recomputes the rows whose anchors lie in another block, and only those: a chunk whose boundary rows
    hold stale staircases and cells gets the fresh build's values back, and a stale row elsewhere is left."""
    from designkit.sweep import run_sweep
    from designkit.sweep.chunk import ChunkResult
    from designkit.sweep.config import stamp_chunk

    cfg = SweepConfig(name="b", blocks=3, intervals=60, trials=20, noise_ratio=(0.005,), contact_s=(1.0,), seed=5,
                      max_repeats=2)
    work = tmp_path / "work"
    run_sweep(cfg, work, jobs=1, backend="sequential")
    chunk = work / "chunks" / "p000-b001-c000.npz"  # rows 20-39; rows 20-23 need anchor 16, 33-39 anchor 40
    with np.load(chunk, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    good = ChunkResult.from_arrays(arrays)
    stale = {k: v.copy() for k, v in arrays.items() if k != "identity"}
    for name in ("J", "J_lo", "J_hi"):
        stale[name][[0, 1, 19]] += 1  # rows 20, 21 (anchor 16 outside) and 39 (anchor 40 outside)
    stale["J_lo"][8] += 1  # row 28: anchors 24 and 32, both inside the block
    stale["cells"] = stale["cells"][~np.isin(stale["cells"][:, 0], [20, 21, 39])]
    np.savez(chunk, **stamp_chunk(stale, cfg, (0,), 1, 0))
    root = Path(__file__).resolve().parents[1]
    r = subprocess.run([sys.executable, str(root / "benchmarks" / "recompute_boundary_rows.py"), str(work)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "3 chunks: 2 with rows beside a block boundary (14 rows recomputed), 1 changed" in r.stdout  # 17-23, 33-39
    with np.load(chunk, allow_pickle=False) as z:
        fixed = ChunkResult.from_arrays({k: z[k] for k in z.files})
    for name in ("J", "J_hi"):
        np.testing.assert_array_equal(getattr(fixed, name), getattr(good, name), err_msg=name)
    assert fixed.J_lo[8] == good.J_lo[8] + 1 and np.array_equal(np.delete(fixed.J_lo, 8), np.delete(good.J_lo, 8))
    np.testing.assert_array_equal(fixed.cells, good.cells)
    assert fixed.fits == good.fits


def test_crossing_fits_are_the_repeats_of_j_minus_one_and_j_of_each_staircase():
    """A hand-worked chunk: only the pairs J - 1 and J of J, J_lo and J_hi count (shared pairs once, none at or
    below the reference itself), each with its repeats; the probes elsewhere are what the search spent."""
    import importlib.util
    from types import SimpleNamespace

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "profile_chunk.py"
    spec = importlib.util.spec_from_file_location("profile_chunk", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    cells = np.array([(0, 1, 0.5, 0.1, 1), (0, 2, 0.8, 0.1, 2), (0, 3, 0.9, 0.1, 2), (0, 4, 0.95, 0.1, 1),
                      (0, 6, 1.0, 0.0, 1),  # a galloping probe beyond J_hi: spent, not certifying
                      (1, 4, 0.85, 0.1, 2), (1, 5, 0.92, 0.1, 1), (1, 7, 0.96, 0.1, 1), (1, 8, 0.97, 0.1, 1),
                      (1, 9, 0.99, 0.1, 2)], dtype=float)
    res = SimpleNamespace(rows=np.array([0, 1]), J=np.array([3, 5]), J_lo=np.array([2, 5]), J_hi=np.array([4, 9]),
                          cells=cells)
    # row 0: pairs 1-4 (2+3, 1+2, 3+4) = 1 + 2 + 2 + 1; row 1: pairs 4, 5, 8, 9 = 2 + 1 + 1 + 2
    assert mod.crossing_fits(res, 10) == 12
    res.J_lo = np.array([3, 5])  # row 0's J_lo at J: pair 1 no longer certifies anything
    assert mod.crossing_fits(res, 10) == 11
    # right above row 0: pair (0, 0) is none
    res.J, res.J_lo, res.J_hi = np.array([1, 5]), np.array([1, 5]), np.array([1, 9])
    assert mod.crossing_fits(res, 10) == 1 + 6


def test_profile_chunk_counts_a_finished_builds_fits_and_its_crossing_fits(tmp_path):
    """benchmarks/profile_chunk.py --workdir (docs/engine.md: the search against a search told the answers):
    every J inside the grid was scored (a row's search ends only on a passing probe at J), so the crossing
    fits are at least one per such staircase answer, never more than the fits, and the totals are the chunks'."""
    from designkit.sweep import run_sweep
    from designkit.sweep.chunk import ChunkResult

    cfg = SweepConfig(name="oc", blocks=2, intervals=40, trials=20, noise_ratio=(0.005,), contact_s=(1.0, 2.0), seed=3,
                      max_repeats=2)
    work = tmp_path / "work"
    run_sweep(cfg, work, jobs=1, backend="sequential")
    fits = answers = 0
    for path in sorted((work / "chunks").glob("*.npz")):
        with np.load(path, allow_pickle=False) as z:
            res = ChunkResult.from_arrays({k: z[k] for k in z.files})
        scored = {(int(i), int(j)) for i, j in res.cells[:, :2]}
        inside = {(int(i), int(J)) for name in ("J", "J_lo", "J_hi")
                  for i, J in zip(res.rows, getattr(res, name)) if J < cfg.intervals}
        assert inside <= scored
        answers += len(inside)
        fits += res.fits
    root = Path(__file__).resolve().parents[1]
    r = subprocess.run([sys.executable, str(root / "benchmarks" / "profile_chunk.py"), "--workdir", str(work)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    m = re.search(r"oc \(.*\): ([\d,]+) fits, ([\d,]+) on crossing pairs", r.stdout)
    assert m, r.stdout
    total, crossing = (int(g.replace(",", "")) for g in m.groups())
    assert total == fits > 0
    assert 0 < crossing <= total
    assert crossing >= answers > 0  # each answer's pair, with at least one fit
    assert len(re.findall(r"^\s+[12]\s+[\d,]+\s+[\d,]+\s+\d", r.stdout, flags=re.M)) == 2  # one line per contact
    (work / "chunks" / "p000-b000-c000.npz").write_bytes(b"not a chunk")
    for folder, says in ((work, "p000-b000-c000.npz is unreadable"), (tmp_path, "is no sweep's working folder")):
        r = subprocess.run([sys.executable, str(root / "benchmarks" / "profile_chunk.py"), "--workdir", str(folder)],
                           capture_output=True, text=True, timeout=120)
        assert r.returncode == 2 and says in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr


def test_the_batched_solver_decides_as_the_reference_except_near_ties():
    """Same staircases with both solvers on a small scene; any cell they score differently is close."""
    kw = dict(intervals=16, trials=24, noise_ratio=(0.005,), contact_s=(1.0,), max_repeats=2)
    ref = run_chunk(SweepConfig(**kw), (0,), 0, 0)
    bat = run_chunk(SweepConfig(solver="batched", **kw), (0,), 0, 0)
    for name in ("J", "J_lo", "J_hi"):
        assert np.abs(getattr(ref, name) - getattr(bat, name)).max() <= 1, name
    assert np.mean(ref.J == bat.J) >= 0.9


def test_an_unknown_solver_is_refused():
    with pytest.raises(InputError, match="solver must be one of batched, sklearn, batched-cupy, batched-array-api"):
        SweepConfig(solver="libsvm")


def test_a_batch_that_would_not_fit_is_refused_before_work():
    from designkit.sweep.scorer import batch_pairs

    from designkit.sweep.run import check_batches

    assert batch_pairs(100, 400) >= 1
    assert batch_pairs(100, 10**6) == 0
    check_batches(SweepConfig(solver="batched", contact_s=(2.0,)))
    with pytest.raises(InputError, match="does not fit in the batched solver"):
        check_batches(SweepConfig(solver="batched", contact_s=(2000.0,)))


def test_delta_shrinks_with_contact_time_and_grows_with_noise(paper_sensor):
    cfg = SweepConfig(intervals=80, fidelity="ideal", noise_ratio=(0.002, 0.01), contact_s=(0.5, 1.0, 4.0))
    J = {(p, k): run_chunk(cfg, (p,), 0, k).J for p in range(2) for k in range(3)}
    for p in range(2):
        assert np.all(J[(p, 0)] >= J[(p, 1)]) and np.all(J[(p, 1)] >= J[(p, 2)])
    for k in range(3):
        assert np.all(J[(1, k)] >= J[(0, k)])


@pytest.mark.parametrize("kwargs,match", [
    ({"fidelity": "best"}, "fidelity"),
    ({"intervals": 1}, "intervals"),
    ({"trials": 2}, "trials"),
    ({"folds": 1}, "folds"),
    ({"threshold": 0.5}, "threshold"),
    ({"contact_s": (2.0, 1.0)}, "contact"),
    ({"contact_s": (0.0,)}, "contact"),
    ({"noise_ratio": (-1.0,)}, "noise_ratio"),
    ({"sensor_temp_spread_c": 2.0}, "varied"),
    ({"noise_ratio": None}, "noise axis"),
    ({"e_min": 100.0, "e_max": 50.0}, "effusivity range"),
])
def test_config_rejects_bad_values(kwargs, match):
    with pytest.raises(InputError, match=match):
        SweepConfig(**kwargs)


def test_config_from_yaml_with_overrides(tmp_path):
    p = tmp_path / "c.yaml"
    p.write_text("name: t\nfidelity: ideal\neffusivity: {min: 0, max: 4000, intervals: 50}\n"
                 "noise_ratio: [0.001, 0.01]\ncontact_s: [1, 2]\n")
    cfg = SweepConfig.from_yaml(p, intervals=25, seed=None)
    assert (cfg.name, cfg.fidelity, cfg.e_max, cfg.intervals, cfg.noise_ratio) == ("t", "ideal", 4000, 25, (0.001, 0.01))
    p.write_text("name: t\nbogus: 1\n")
    with pytest.raises(InputError, match="unknown key"):
        SweepConfig.from_yaml(p)
    p.write_text("name: [unclosed\n")
    with pytest.raises(InputError, match="not valid YAML"):
        SweepConfig.from_yaml(p)
    with pytest.raises(InputError, match="cannot read"):
        SweepConfig.from_yaml(tmp_path / "missing.yaml")
    # the digest (what --resume checks) follows every result-changing key and only those
    assert cfg.digest() == SweepConfig(**{**cfg.to_dict(), "noise_ratio": (0.001, 0.01)}).digest()
    assert cfg.digest() != SweepConfig(**{**cfg.to_dict(), "seed": 1}).digest()


def test_assembled_monte_carlo_interval_always_holds_its_estimate():
    """Separate staircase walks over noisy F1 may put J_lo above J (seen in 21 of 33,669 entries of the
    first svm-paper build): the assembled table's interval must still contain delta, both ways."""
    cfg = SweepConfig(intervals=6, noise_ratio=(0.005,), contact_s=(1.0,), trials=10)
    rows = np.arange(6)
    J = np.array([2, 3, 4, 5, 6, 6])
    J_lo = np.array([1, 4, 4, 4, 6, 6])  # row 1 walked above J; row 3 below it
    J_hi = np.array([3, 3, 5, 6, 6, 6])  # row 1 below J
    chunk = ChunkResult((0,), 0, 0, rows, J, J_lo, J_hi, J.copy(), 0, np.zeros((0, 5)), 0.0)
    out = assemble(cfg, [chunk])
    for d in ("up", "down"):
        est, lo, hi = (out[f"delta_{d}{t}"][0, 0] for t in ("", "_lo", "_hi"))
        both = ~np.isnan(est)
        assert np.all(lo[both] <= est[both]) and np.all(np.isnan(hi[both]) | (hi[both] >= est[both]))
    # row 3's lower end stays where its own walk put it (below the estimate)
    assert out["delta_up_lo"][0, 0, 3] == 1 * cfg.width < out["delta_up"][0, 0, 3]


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(min_value=0, max_value=40), min_size=1, max_size=40), st.floats(1.0, 500.0))
def test_delta_from_staircase_matches_its_definition(raw, width):
    """delta_up[i] = (J(i) - i) w; delta_down[j] = (j - I(j)) w with I(j) = max{i < j : J(i) <= j};
    for any J, monotone or not (full-matrix rows need not be), checked by brute force."""
    n = len(raw)
    J = np.minimum(np.asarray(raw), n)
    up, down = delta_from_staircase(J, width)
    for i in range(n):
        assert (np.isnan(up[i]) if J[i] >= n else up[i] == (J[i] - i) * width)
    for j in range(n):
        cands = [i for i in range(j) if J[i] <= j]
        assert (np.isnan(down[j]) if not cands else down[j] == (j - max(cands)) * width)


def test_bounded_feature_cache_changes_no_result(monkeypatch):
    """A chunk's feature cache is bounded (a worker's memory whatever the grid); features are a
    function of (interval, seed), so a cache that must evict and regenerate gives the same table."""
    import designkit.sweep.scorer as scorer

    cfg = SweepConfig(intervals=24, trials=30, noise_ratio=(0.005,), contact_s=(1.0,), max_repeats=2, seed=5)
    full = run_chunk(cfg, (0,), 0, 0)
    monkeypatch.setattr(scorer, "FEATURE_CACHE_MB", 0)  # the floor: 8 entries for 24 intervals x 2 seeds
    small = run_chunk(cfg, (0,), 0, 0)
    for name in ("J", "J_lo", "J_hi", "J_ideal"):
        np.testing.assert_array_equal(getattr(small, name), getattr(full, name), err_msg=name)
    np.testing.assert_array_equal(small.cells, full.cells)
    assert small.fits == full.fits


# ------------------------------------------------------------------ the forward model of a sweep
def test_config_model_from_name_mapping_or_model_and_in_the_identity(tmp_path):
    from designkit.models import get_model

    contact = {"name": "contact", "conductance_w_m2k": 2000.0}
    by_map = SweepConfig(model=contact)
    assert SweepConfig(model=get_model(contact)) == by_map == SweepConfig(model="contact")
    assert by_map.to_dict()["model"] == contact
    assert SweepConfig.from_mapping(by_map.to_dict()) == by_map  # round trip through a header's config
    default = SweepConfig()
    assert default.model.name == "semi-infinite" and default.to_dict()["model"] == {"name": "semi-infinite"}
    # a config recorded before the seam (no model key) is the semi-infinite sweep, with the same digest,
    # so its working folder still resumes; another model is another sweep
    old = {k: v for k, v in default.to_dict().items() if k not in ("model", "diffusivity_m2_s")}
    assert SweepConfig.from_mapping(old).digest() == default.digest() == SweepConfig(model="semi-infinite").digest()
    assert by_map.digest() != default.digest() != SweepConfig(model={**contact, "conductance_w_m2k": 3000}).digest()
    slab = SweepConfig(model={"name": "slab", "thickness_m": 0.003}, diffusivity_m2_s=1e-7)
    assert slab.digest() != SweepConfig(model=slab.model, diffusivity_m2_s=2e-7).digest()
    p = tmp_path / "m.yaml"
    p.write_text("model: {name: contact, conductance_w_m2k: 1500}\n")
    assert SweepConfig.from_yaml(p).model == get_model("contact", conductance_w_m2k=1500)
    assert SweepConfig.from_yaml(p, model="semi-infinite").model.name == "semi-infinite"  # overrides win
    p.write_text("model: {name: contact, bogus: 1}\n")
    with pytest.raises(InputError, match=r"m\.yaml: model: model 'contact' has no parameter bogus"):
        SweepConfig.from_yaml(p)


@pytest.mark.parametrize("kwargs,match", [
    ({"model": "nope"}, "model: unknown forward model"),
    ({"model": {"conductance_w_m2k": 5}}, "model: a model needs a name"),
    ({"model": "slab"}, "needs the objects' diffusivity"),
    ({"model": "slab", "diffusivity_m2_s": -1.0}, "diffusivity_m2_s"),
    ({"diffusivity_m2_s": 1e-7}, "does not use the objects' diffusivity"),
    ({"model": "contact", "fidelity": "ideal"}, "fidelity ideal needs the closed-form ideal observer"),
])
def test_config_rejects_bad_models(kwargs, match):
    with pytest.raises(InputError, match=match) as err:
        SweepConfig(**kwargs)
    assert "\n" not in str(err.value)


def test_the_ideal_floor_only_where_a_closed_form_holds(paper_sensor):
    from designkit.sweep import closed_form_model
    from designkit.sweep.search import IDEAL_UNKNOWN

    kw = dict(intervals=10, trials=12, noise_ratio=(0.005,), contact_s=(1.5,), max_repeats=1, seed=1)
    scene = SweepConfig(**kw).scene((0,), 1.5)
    assert closed_form_model(SweepConfig(**kw), paper_sensor, scene).name == "semi-infinite"
    assert closed_form_model(SweepConfig(model={"name": "contact", "conductance_w_m2k": 1e12}, **kw),
                             paper_sensor, scene).name == "semi-infinite"  # a contact too good to lag
    lagging = SweepConfig(model={"name": "contact", "conductance_w_m2k": 2000}, **kw)
    assert closed_form_model(lagging, paper_sensor, scene) is None
    res = run_chunk(lagging, (0,), 0, 0)
    assert np.all(res.J_ideal == IDEAL_UNKNOWN) and res.fits > 0
    assert np.all(res.J_lo <= res.J) and np.all(res.J <= res.J_hi)
    out = assemble(lagging, [res])
    assert "delta_up_ideal" not in out and "delta_down_ideal" not in out and "delta_up" in out


def test_the_package_exports_the_engine_from_its_modules():
    import importlib

    import designkit.sweep as sweep

    assert sweep.__all__ and all(hasattr(sweep, name) for name in sweep.__all__)
    for mod in ("config", "scorer", "search", "chunk", "run"):
        m = importlib.import_module(f"designkit.sweep.{mod}")
        assert m.__all__ and all(hasattr(m, name) for name in m.__all__), mod


def test_estimated_costs_order_a_scenes_blocks_as_measured():
    """The blocks of one 500-interval scene (2 s, sigma/dT 0.005) took 6.2, 14.3, 20.0 and 0.6 s of CPU
    (benchmarks/bench_engine.py's scene): the estimate hands them out in that order of cost, and a block
    whose references have no partner in the grid costs next to nothing."""
    from designkit.sweep.chunk import estimated_costs

    cfg = SweepConfig(name="c", solver="batched", blocks=4, intervals=500, trials=100, noise_ratio=(0.005,),
                      contact_s=(2.0,))
    cost = estimated_costs(cfg, (0,), 0)
    assert list(np.argsort(-cost)) == [2, 1, 0, 3]
    assert cost[3] < 0.05 * cost[2]
    longer = SweepConfig(name="c", solver="batched", blocks=4, intervals=500, trials=100, noise_ratio=(0.005,),
                         contact_s=(2.0, 4.0))
    assert estimated_costs(longer, (0,), 1).sum() > estimated_costs(longer, (0,), 0).sum()  # longer fits
