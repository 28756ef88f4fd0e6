"""How an emulated rig announces what it touches and when, on the wire.

The emulator's (:class:`designkit_lab.emulator.Emulator`, ``designkit emulate``) first line
(:func:`greeting_text`) and a device message at each touch (:func:`announcement_text`) name its touch
plan; a recorder reads them back (:func:`parse_greeting`, :func:`parse_announcement`) to refuse a run that
would label the touches wrongly. Writer and reader live here together, so that the two agree.
"""

from __future__ import annotations

import itertools
import json
import re
from dataclasses import dataclass
from typing import Sequence


__all__ = ["AnnouncedPlan", "announcement_text", "greeting_text", "parse_announcement", "parse_greeting"]


_GREETING = re.compile(r"designkit emulator, profile .*?; touches \d+ of each of \[.*\] in turn")
_PLAN = re.compile(r"touches (?P<n>\d+) of each of (?P<labels>\[.*\]) in turn")


@dataclass(frozen=True)
class AnnouncedPlan:
    """The touch sequence an emulator announces in its first line (a device message).

    Parameters
    ----------
    labels : tuple of str
        Materials, touched in this order.
    touches_per_material : int
        Touches of each before the next one (then the first again).

    Examples
    --------
    >>> plan = parse_greeting('# designkit emulator, profile designkit; touches 2 of each of ["wood", "metal"] in turn')
    >>> plan.sequence(5)
    ['wood', 'wood', 'metal', 'metal', 'wood']
    >>> plan.mislabels(["metal", "wood"], 2)   # doctest: +ELLIPSIS
    'the emulator touches wood, wood, metal, metal in turn, but this run labels its first 4 touches metal, ...'
    >>> plan.mislabels(["block", "slab"], 2) is None   # any names, as long as each stands for one material
    True
    """

    labels: tuple[str, ...]
    touches_per_material: int

    def sequence(self, n: int) -> list[str]:
        """Labels of the first ``n`` touches."""
        k = self.touches_per_material
        return [self.labels[(j // k) % len(self.labels)] for j in range(n)]

    def mislabels(self, materials: Sequence[str], trials: int) -> str | None:
        """Why a recording of ``trials`` touches of each of ``materials`` in turn would mislabel them (None: it
        would not).

        A recording may name the materials as it likes, but each of its names must stand for one of the
        emulator's materials and no two for the same; a name that is one of the emulator's labels (any case)
        must stand for that one.
        """
        ours = [m for m in materials for _ in range(trials)]
        theirs = self.sequence(len(ours))
        pairs = set(zip(ours, theirs))
        known = {lab.lower() for lab in self.labels}
        ok = (len(pairs) == len({a for a, _ in pairs}) == len({b for _, b in pairs})
              and all(a.lower() == b.lower() for a, b in pairs if a.lower() in known))
        if ok:
            return None

        def runs(seq: list[str]) -> str:
            return ", ".join(seq) if len(seq) <= 6 else ", ".join(
                f"{sum(1 for _ in g)} x {lab}" for lab, g in itertools.groupby(seq))
        return (f"the emulator touches {runs(theirs)} in turn, but this run labels its first {len(ours)} touches "
                f"{runs(ours)}")


_ANNOUNCEMENT = re.compile(r'designkit emulator: touch (?P<j>\d+) of (?P<label>"(?:[^"\\]|\\.)*") starts')


def parse_announcement(message: str) -> tuple[int, str, AnnouncedPlan | None] | None:
    """(touch number from 1, material label, the plan it repeats) of an emulator's touch announcement;
    None for other messages.

    >>> j, label, plan = parse_announcement(
    ...     '# designkit emulator: touch 3 of "Aluminium alloys" starts; touches 2 of each of ["Aluminium alloys", '
    ...     '"wood"] in turn')
    >>> j, label, plan.labels
    (3, 'Aluminium alloys', ('Aluminium alloys', 'wood'))
    """
    m = _ANNOUNCEMENT.search(message)
    if not m:
        return None
    try:
        label = json.loads(m.group("label"))
    except ValueError:
        return None
    if not isinstance(label, str):
        return None
    plan = _plan(message[m.end():])
    return int(m.group("j")), label, plan


def parse_greeting(message: str) -> AnnouncedPlan | None:
    """The plan an emulator's first line announces (None: ``message`` is no such line)."""
    return _plan(message) if _GREETING.search(message) else None


def _plan(text: str) -> AnnouncedPlan | None:
    m = _PLAN.search(text)
    if not m:
        return None
    try:
        labels = json.loads(m.group("labels"))
    except ValueError:
        return None
    if not labels or not all(isinstance(x, str) for x in labels) or int(m.group("n")) < 1:
        return None
    return AnnouncedPlan(tuple(labels), int(m.group("n")))


def greeting_text(prefix: str, profile_name: str, labels: Sequence[str], plan) -> str:
    """The emulator's first line (a device message after ``prefix``): the touch plan (its
    ``touches_per_material`` and ``touch_every_s`` [s])."""
    names = json.dumps(list(labels), ensure_ascii=False)
    return (f"{prefix} designkit emulator, profile {profile_name}; touches "
            f"{plan.touches_per_material} of each of {names} in turn, every {plan.touch_every_s:g} s")


def announcement_text(prefix: str, j: int, labels: Sequence[str], plan) -> str:
    """The device message sent as touch ``j`` (0-based) starts, with the plan."""
    k = plan.touches_per_material
    label = json.dumps(labels[(j // k) % len(labels)], ensure_ascii=False)
    names = json.dumps(list(labels), ensure_ascii=False)
    return f"{prefix} designkit emulator: touch {j + 1} of {label} starts; touches {k} of each of {names} in turn"
