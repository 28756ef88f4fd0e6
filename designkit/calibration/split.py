"""Disjoint fitted and held-out touches: the trial sets of a recording, and the split between them.

A model is chosen by how it predicts touches it was not fitted on
(:func:`~designkit.calibration.compare.compare_models`); :func:`choose_split` picks those touches
from the trial sets present (or, without trial sets, from the touches' order).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

from .._validation import InputError
from .trials import Trial

__all__ = ["FIT_SHARE", "FIT_SHARE_TOUCH_ORDER", "MIN_TOUCHES_TO_HOLD_OUT", "Split", "choose_split",
           "split_by_trial_set", "trial_sets"]


def trial_sets(trials: Sequence[Trial], index_csv: Path | str | None = None) -> list[int | None]:
    """Trial set of each trial: the index's ``trial_set`` column, else from ``setNN_`` file names."""
    import re

    by_file: dict[str, int] = {}
    if index_csv is not None:
        from .trials import read_index_rows

        for r in read_index_rows(Path(index_csv)):
            v = (r.get("trial_set") or "").strip()
            if r.get("file") and v.isdigit():
                by_file[r["file"]] = int(v)
    out: list[int | None] = []
    for tr in trials:
        name = Path(tr.source).name
        if name in by_file:
            out.append(by_file[name])
            continue
        m = re.match(r"set(\d+)_", name)
        out.append(int(m.group(1)) if m else None)
    return out


def split_by_trial_set(trials: Sequence[Trial], fit_sets: Sequence[int],
                       index_csv: Path | str | None = None) -> tuple[list[Trial], list[Trial]]:
    """(trials of ``fit_sets``, the others): :func:`choose_split` with the fit sets given."""
    sp = choose_split(trials, index_csv, fit_sets=fit_sets)
    return list(sp.fit), list(sp.held_out)


#: Share of the trial sets present that :func:`choose_split` fits by default (the first ones, at least one):
#: 4 of the shared recordings' 20 sets. A recording without trial
#: sets (one session, touches in order) fits the first half of each material's touches.
FIT_SHARE = 0.2
FIT_SHARE_TOUCH_ORDER = 0.5
#: Touches of each material a recording without trial sets needs before some are held out.
MIN_TOUCHES_TO_HOLD_OUT = 4


@dataclass(frozen=True)
class Split:
    """Disjoint calibration (fitted) and test (held-out) touches, and how they were chosen.

    Attributes
    ----------
    fit, held_out : tuple of Trial
    fit_sets, held_sets : tuple of int
        The trial sets on each side; where the recording has none, the touches' places in their
        material's order (touch k of every material counted as set k).
    by : str
        ``"trial set"`` or ``"touch order"``.
    reason : str
        How the sides were chosen, or why nothing is held out (then ``held_out`` is empty).
    """

    fit: tuple[Trial, ...]
    held_out: tuple[Trial, ...]
    fit_sets: tuple[int, ...]
    held_sets: tuple[int, ...]
    by: str
    reason: str

    def describe(self) -> str:
        """One phrase: 'fitted on trial sets 1-4 (24 touches), scored on sets 5-20 (96)'."""
        what = "trial sets" if self.by == "trial set" else "touch numbers"
        if not self.held_out:
            return f"fitted on all {len(self.fit)} touches, none held out ({self.reason})"
        return (f"fitted on {what} {_ranges_text(self.fit_sets)} ({len(self.fit)} touches), scored on "
                f"{what} {_ranges_text(self.held_sets)} ({len(self.held_out)} touches)")

    def to_dict(self) -> dict[str, Any]:
        return {"by": self.by, "fit_sets": list(self.fit_sets), "held_out_sets": list(self.held_sets),
                "n_fit": len(self.fit), "n_held_out": len(self.held_out), "reason": self.reason}


def _ranges_text(values: Sequence[int]) -> str:
    """``[1, 2, 3, 5]`` -> ``'1-3, 5'``."""
    vals = sorted(set(int(v) for v in values))
    out, i = [], 0
    while i < len(vals):
        j = i
        while j + 1 < len(vals) and vals[j + 1] == vals[j] + 1:
            j += 1
        out.append(f"{vals[i]}" if i == j else f"{vals[i]}-{vals[j]}")
        i = j + 1
    return ", ".join(out)


def choose_split(trials: Sequence[Trial], index_csv: Path | str | None = None,
                 fit_sets: Sequence[int] | None = None, *, require: bool = False,
                 fit_share: float | None = None, sets: Sequence[int | None] | None = None) -> Split:
    """Choose disjoint fitted and held-out touches from the trial sets present.

    Trial sets come from ``sets`` (one per touch, None where unknown) or :func:`trial_sets` (the
    index's ``trial_set`` column or ``setNN_`` file names); a recording without them is split in
    touch order (touch k of each material counts as set k, so sessions recorded one after another
    stay apart). ``fit_sets`` given: those sets are
    fitted and every other set present is held out; otherwise the first ``ceil(fit_share * n)``
    sets of the ``n`` present (at least one; ``fit_share`` by default :data:`FIT_SHARE`, or
    :data:`FIT_SHARE_TOUCH_ORDER` in touch order). Every material must have touches on both sides.

    Where no split exists (one trial set; fewer than :data:`MIN_TOUCHES_TO_HOLD_OUT` touches of a
    material without trial sets; a material only on one side) nothing is held out and ``reason``
    says why, unless ``fit_sets`` is given or ``require`` is set: then a one-line InputError.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(-200, 400) / 200.0
    >>> trs = [Trial(t, t, t, t, m, f"set{s:02d}_{m}_0.csv") for s in (3, 4, 7, 9, 11) for m in ("a", "b")]
    >>> sp = choose_split(trs)
    >>> sp.fit_sets, sp.held_sets, sp.describe()
    ((3,), (4, 7, 9, 11), 'fitted on trial sets 3 (2 touches), scored on trial sets 4, 7, 9, 11 (8 touches)')
    """
    sets = trial_sets(trials, index_csv) if sets is None else list(sets)
    names = sorted({tr.material for tr in trials})
    if not trials:
        raise InputError("no touches to split")
    if all(s is not None for s in sets):
        by, labels = "trial set", [int(s) for s in sets]
    else:
        by, seen, labels = "touch order", {}, []
        for tr in trials:
            seen[tr.material] = seen.get(tr.material, 0) + 1
            labels.append(seen[tr.material])
    present = sorted(set(labels))
    word = "trial sets" if by == "trial set" else "touch numbers"
    aside = "" if by == "trial set" else " (no trial sets: touch k of each material counts as set k)"

    def refuse(why: str) -> Split:
        if fit_sets is not None or require:
            raise InputError(why)
        return Split(tuple(trials), (), tuple(present), (), by, why)

    if fit_sets is not None:
        keep = sorted(set(int(s) for s in fit_sets))
        unknown = [s for s in keep if s not in present]
        if unknown:
            return refuse(f"--fit-sets names {word} {_ranges_text(unknown)} that the recording does not have "
                          f"(it has {_ranges_text(present)}){aside}")
        held = [s for s in present if s not in keep]
        if not held:
            return refuse(f"fit sets {_ranges_text(keep)} leave no touches to score: the recording has only "
                          f"{word} {_ranges_text(present)}{aside} (leave out --fit-sets, or give 'all' to fit every "
                          "touch)")
        how = f"{word} {_ranges_text(keep)} fitted as asked{aside}, the others held out"
    else:
        if len(names) < 2 and require:
            raise InputError(f"the recording has one material ({names[0]}): a test of recognition needs two")
        if len(present) < 2:
            return refuse(f"the recording has one trial set ({present[0]}): no touches to hold out"
                          if by == "trial set" else "one touch per material: no touches to hold out")
        if by == "touch order":
            few = {n: sum(tr.material == n for tr in trials) for n in names}
            short = [f"{n} ({k})" for n, k in few.items() if k < MIN_TOUCHES_TO_HOLD_OUT]
            if short:
                return refuse(f"no trial sets and fewer than {MIN_TOUCHES_TO_HOLD_OUT} touches of "
                              f"{', '.join(short)}: too few to hold some out")
        if fit_share is None:
            fit_share = FIT_SHARE if by == "trial set" else FIT_SHARE_TOUCH_ORDER
        n_fit = min(len(present) - 1, max(1, math.ceil(fit_share * len(present) - 1e-9)))
        keep, held = present[:n_fit], present[n_fit:]
        how = (f"the first {n_fit} of the {len(present)} {word} present fitted{aside} "
               f"(a share of {fit_share:g}, at least one), the others held out")
    fit = [tr for tr, s in zip(trials, labels) if s in set(keep)]
    out = [tr for tr, s in zip(trials, labels) if s not in set(keep)]
    for side, group in (("fitted", fit), ("held-out", out)):
        missing = [n for n in names if not any(tr.material == n for tr in group)]
        if missing:
            return refuse(f"the {side} {word} {_ranges_text(keep if side == 'fitted' else held)}{aside} "
                          f"have no touches of {', '.join(missing)}")
    return Split(tuple(fit), tuple(out), tuple(keep), tuple(held), by, how)
