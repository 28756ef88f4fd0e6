"""A rebuilt svm-paper table (or a slice of it) against the shipped one, delta by delta (issue 12).

Run from the repository root::

    python benchmarks/compare_svm_paper.py NEW.npz                  # against tables/svm-paper
    python benchmarks/compare_svm_paper.py NEW.npz --old OTHER.npz
    python benchmarks/compare_svm_paper.py --workdir build/svm-paper   # the chunks finished so far

With ``--workdir`` the finished chunks of a rebuild still running (or stopped)
are compared: ``delta_up`` of each chunk's references, from its own staircase
(``delta_down`` needs every reference of the scene and is left out), against
the old ``[delta_up_lo, delta_up_hi]``; "explained" then uses the chunk's own
``[J_lo, J_hi]``.

The new table may cover a subset of the old one's sigma/dT and contact axes (a
rebuild of one scene, say); only the points both hold are compared. For every
reference, both directions (``delta_up``, ``delta_down``):

* **inside**: the new delta lies in the old table's Monte Carlo interval
  ``[delta_*_lo, delta_*_hi]`` (NaN, "no distinguishable partner in the grid",
  counts as +inf at the upper end);
* **outside, explained**: it does not, but the two Monte Carlo intervals
  overlap: both are estimates of one noisy crossing, and the new search (each
  reference from its own ideal floor, no warm start from the previous contact
  time) walked to another point of the overlap;
* **outside, unexplained**: the intervals do not overlap (listed).

Also printed: the SVM fits of both builds on the compared points, and the
largest difference in intervals.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from designkit.tables.store import load_table


def _axis(t, name):
    for a in t.header["axes"]:
        if a["name"] == name:
            return [float(v) for v in a["values"]]
    raise SystemExit(f"table {t.header['name']} has no {name} axis")


def _upper(x):
    return np.where(np.isnan(x), np.inf, x)


def compare(new, old) -> dict:
    width = float(old.header["effusivity"]["width"])
    noise_new, noise_old = _axis(new, "noise_ratio"), _axis(old, "noise_ratio")
    c_new, c_old = _axis(new, "contact_s"), _axis(old, "contact_s")
    points = [(a, noise_old.index(x), b, c_old.index(c)) for a, x in enumerate(noise_new) if x in noise_old
              for b, c in enumerate(c_new) if c in c_old]
    counts = {"compared": 0, "inside": 0, "explained": 0, "unexplained": 0, "equal": 0}
    worst, listed = 0.0, []
    fits_new = fits_old = 0
    for a, a_old, b, b_old in points:
        fits_new += int(new.arrays["fits"][a, b])
        fits_old += int(old.arrays["fits"][a_old, b_old])
        for d in ("up", "down"):
            v = _upper(new.arrays[f"delta_{d}"][a, b])
            lo = _upper(old.arrays[f"delta_{d}_lo"][a_old, b_old])
            hi = _upper(old.arrays[f"delta_{d}_hi"][a_old, b_old])
            v_old = _upper(old.arrays[f"delta_{d}"][a_old, b_old])
            n_lo = _upper(new.arrays[f"delta_{d}_lo"][a, b])
            n_hi = _upper(new.arrays[f"delta_{d}_hi"][a, b])
            bad, w = _tally(counts, v, v_old, lo, hi, n_lo, n_hi, width)
            worst = max(worst, w)
            for i in bad[:20]:
                listed.append((noise_new[a], c_new[b], d, int(i), float(v[i]), float(lo[i]), float(hi[i]),
                               float(n_lo[i]), float(n_hi[i])))
    return {"points": len(points), "counts": counts, "worst_intervals": worst, "unexplained": listed,
            "fits_new": fits_new, "fits_old": fits_old}


def _tally(counts: dict, v, v_old, lo, hi, n_lo, n_hi, width: float):
    """Add one block of deltas to ``counts``: inside the old MC interval [lo, hi], outside but with the
    new interval [n_lo, n_hi] overlapping it (explained), or neither. Returns the unexplained indices and
    the largest finite difference from the old delta, in intervals."""
    inside = (v >= lo) & (v <= hi)
    overlap = (n_lo <= hi) & (lo <= n_hi)
    counts["compared"] += v.size
    counts["equal"] += int(np.sum(v == v_old))
    counts["inside"] += int(inside.sum())
    counts["explained"] += int(np.sum(~inside & overlap))
    bad = np.flatnonzero(~inside & ~overlap)
    counts["unexplained"] += bad.size
    finite = np.isfinite(v) & np.isfinite(v_old)
    worst = float(np.max(np.abs(v[finite] - v_old[finite]))) / width if finite.any() else 0.0
    return bad, worst


def compare_chunks(workdir: Path, old) -> dict:
    """:func:`compare` for the finished chunks of a sweep's working folder (delta_up only)."""
    import json

    from designkit.sweep.chunk import ChunkResult

    cfg = json.loads((workdir / "sweep.json").read_text())["config"]
    width = float(old.header["effusivity"]["width"])
    noise_old, c_old = _axis(old, "noise_ratio"), _axis(old, "contact_s")
    counts = {"compared": 0, "inside": 0, "explained": 0, "unexplained": 0, "equal": 0}
    worst, listed, fits_new, points = 0.0, [], 0, set()
    for path in sorted((workdir / "chunks").glob("*.npz")):
        with np.load(path) as z:
            ch = ChunkResult.from_arrays({k: z[k] for k in z.files})
        noise = float(cfg["noise_ratio"][ch.point[0]])
        contact = float(cfg["contact_s"][ch.contact_index])
        if noise not in noise_old or contact not in c_old:
            continue
        a, b = noise_old.index(noise), c_old.index(contact)
        points.add((a, b))
        rows = ch.rows
        n = int(cfg["intervals"])

        def up(J):
            return np.where(J < n, (J - rows) * width, np.inf)

        v, n_lo, n_hi = up(ch.J), up(ch.J_lo), up(ch.J_hi)
        v_old = _upper(old.arrays["delta_up"][a, b][rows])
        lo = _upper(old.arrays["delta_up_lo"][a, b][rows])
        hi = _upper(old.arrays["delta_up_hi"][a, b][rows])
        fits_new += ch.fits
        bad, w = _tally(counts, v, v_old, lo, hi, np.minimum(n_lo, v), np.maximum(n_hi, v), width)
        worst = max(worst, w)
        for i in bad[:20]:
            listed.append((noise, contact, "up", int(rows[i]), float(v[i]), float(lo[i]), float(hi[i]),
                           float(n_lo[i]), float(n_hi[i])))
    fits_old = sum(int(old.arrays["fits"][a, b]) for a, b in points)
    return {"points": len(points), "counts": counts, "worst_intervals": worst, "unexplained": listed,
            "fits_new": fits_new, "fits_old": fits_old}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("new", type=Path, nargs="?", help="the rebuilt table (.npz)")
    p.add_argument("--workdir", type=Path, default=None, help="compare a sweep's finished chunks instead")
    p.add_argument("--old", default="svm-paper", help="table name or path (default: the shipped svm-paper)")
    args = p.parse_args(argv)
    old = load_table(args.old)
    if args.workdir is not None:
        r = compare_chunks(args.workdir, old)
        args.new = f"{args.workdir} (finished chunks; delta_up only; fits counted for whole old points)"
    else:
        r = compare(load_table(args.new), old)
    c = r["counts"]
    n = max(c["compared"], 1)
    print(f"{args.new} against {args.old}: {r['points']} (sigma/dT, contact) points in common, "
          f"{c['compared']} deltas compared")
    print(f"  equal to the old delta:                      {c['equal']} ({100 * c['equal'] / n:.1f} %)")
    print(f"  inside the old Monte Carlo interval:         {c['inside']} ({100 * c['inside'] / n:.2f} %)")
    print(f"  outside, Monte Carlo intervals overlap:      {c['explained']} ({100 * c['explained'] / n:.2f} %)")
    print(f"  outside, intervals disjoint (unexplained):   {c['unexplained']} ({100 * c['unexplained'] / n:.2f} %)")
    print(f"  largest |new - old| delta: {r['worst_intervals']:.0f} intervals")
    print(f"  SVM fits on these points: new {r['fits_new']}, old {r['fits_old']}")
    for row in r["unexplained"]:
        print("    sigma/dT {:g}, contact {:g} s, delta_{}[{}] = {:g}; old interval [{:g}, {:g}], new [{:g}, {:g}]"
              .format(*row))
    return 0 if c["unexplained"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
