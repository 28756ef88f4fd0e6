"""One ``designkit bench`` run: the selected sections, in order, into a :class:`BenchReport`.

Every way designkit answers a question is measured against a high-fidelity
reference *in the same run*, so that errors and speed-ups are ratios on one
machine at one moment, not numbers copied from elsewhere. All draws are
seeded; the same seed gives the same errors (timings vary).
"""

from __future__ import annotations

import os
import platform
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Mapping

from designkit._validation import InputError
from .results import CostCurve, Row

__all__ = ["SECTIONS", "BenchReport", "check_sections", "environment", "run_bench"]

#: The report's sections, in the order they run and appear.
SECTIONS = ("physics", "recognition", "delta", "queries", "cost")


@dataclass(frozen=True)
class BenchReport:
    """Everything one ``designkit bench`` run measured.

    Attributes
    ----------
    rows : tuple of Row
        Every method's error and time, section by section.
    curves : tuple of CostCurve
        The sweep engine's cost curves (section ``cost``).
    facts : mapping
        Raw statistics the page quotes (``queries:<table>`` per table).
    quick, seed : bool, int
        How the run was asked for.
    wall_s : float
        Wall time of the whole run [s].
    environment : mapping
        Versions, CPUs and load (:func:`environment`).
    skipped : tuple of str
        What could not be measured, and why.
    section_wall_s : mapping
        Wall time of each section [s].
    """

    rows: tuple[Row, ...]
    curves: tuple[CostCurve, ...]
    facts: Mapping[str, Any]
    quick: bool
    seed: int
    wall_s: float
    environment: Mapping[str, Any]
    skipped: tuple[str, ...] = ()
    section_wall_s: Mapping[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The ``accuracy.json`` and ``designkit bench --json`` record."""
        return {"quick": self.quick, "seed": self.seed, "wall_s": self.wall_s,
                "section_wall_s": dict(self.section_wall_s), "environment": dict(self.environment),
                "skipped": list(self.skipped), "facts": dict(self.facts),
                "rows": [r.to_dict() for r in self.rows], "curves": [c.to_dict() for c in self.curves]}


def environment() -> dict[str, Any]:
    """Python, numpy, scipy, scikit-learn and designkit versions, CPUs and the load average now.

    Examples
    --------
    >>> sorted(environment())[:3]
    ['cpus', 'designkit', 'load_average_at_start']
    """
    import numpy
    import scipy

    env = {"python": platform.python_version(), "numpy": numpy.__version__, "scipy": scipy.__version__,
           "machine": platform.machine(), "cpus": os.cpu_count()}
    try:
        import sklearn

        env["scikit-learn"] = sklearn.__version__
    except ImportError:  # pragma: no cover
        pass
    try:
        env["load_average_at_start"] = [round(x, 2) for x in os.getloadavg()]
    except OSError:  # pragma: no cover
        pass
    from designkit import __version__

    env["designkit"] = __version__
    return env


@dataclass
class _Collected:
    rows: list = field(default_factory=list)
    curves: list = field(default_factory=list)
    facts: dict = field(default_factory=dict)
    skipped: list = field(default_factory=list)


def _physics(out: _Collected, quick, seed, say, **_) -> None:
    from .physics import physics_rows, slab_rows

    say("physics: eq. 2 against mpmath")
    out.rows += physics_rows(quick, seed)
    say("physics: thin-sample solvers")
    out.rows += slab_rows(quick)


def _recognition(out: _Collected, quick, seed, say, **_) -> None:
    from .recognition import ideal_mc_rows, recognition_rows

    say("recognition: ideal observer closed form vs Monte Carlo")
    out.rows += ideal_mc_rows(quick, seed)
    out.rows += recognition_rows(quick, seed, progress=say)


def _delta(out: _Collected, quick, seed, say, **_) -> None:
    from .delta import delta_rows

    out.rows += delta_rows(quick, seed, progress=say)


def _load_svm(svm_table, out: _Collected):
    """The SVM table, or None (and a line in ``skipped``) when it cannot be loaded."""
    from designkit.tables.store import load_table

    if not svm_table:
        return None
    try:
        return load_table(svm_table)
    except InputError as exc:
        out.skipped.append(f"queries against {svm_table}: {exc}")
        return None


def _queries(out: _Collected, quick, seed, say, *, svm_table, ideal_table, jobs) -> None:
    from designkit.tables.store import load_table
    from .queries import density_rows, query_rows, svm_query_rows

    say(f"queries: {ideal_table} against the exact ideal observer")
    itab = load_table(ideal_table)
    r, f = query_rows(itab, quick, seed)
    out.rows += r
    out.facts[f"queries:{itab.name}"] = f
    svm = _load_svm(svm_table, out)
    say("queries: table density")
    out.rows += density_rows(itab, quick, seed, svm_axes=None if svm is None else
                             {k: svm.axes[k] for k in ("noise_ratio", "contact_s")})
    if svm is not None:
        r, f = svm_query_rows(svm, quick, seed, jobs=jobs, progress=say)
        out.rows += r
        out.facts[f"queries:{svm.name}"] = f


def _cost(out: _Collected, quick, seed, say, **_) -> None:
    from .cost import cost_curves

    out.curves += cost_curves(quick, seed, progress=say)


_RUNNERS = {"physics": _physics, "recognition": _recognition, "delta": _delta, "queries": _queries, "cost": _cost}


def check_sections(sections: Iterable[str]) -> tuple[str, ...]:
    """The sections as a tuple, or an error naming the unknown ones and the valid names."""
    sections = tuple(sections)
    bad = [s for s in sections if s not in SECTIONS]
    if bad:
        raise InputError(f"unknown bench section(s) {', '.join(bad)} (choose from {', '.join(SECTIONS)})")
    return sections


def run_bench(*, quick: bool = True, seed: int = 0, sections: Iterable[str] = SECTIONS,
              svm_table: str | None = "svm-paper", ideal_table: str = "ideal-paper", jobs: int = 1,
              progress: Callable[[str], None] | None = None) -> BenchReport:
    """Run the selected sections and collect a :class:`BenchReport`.

    Parameters
    ----------
    quick : bool
        Fewer cases and smaller references (``designkit bench --quick``:
        a few minutes on 2 cores); the full run takes longer.
    seed : int
        Seed of every random draw.
    sections : iterable of str
        Any of :data:`SECTIONS`; they run in that order.
    svm_table, ideal_table : str
        Tables whose queries are measured; a missing SVM table is skipped
        (and listed in ``skipped``).
    jobs : int
        Processes for the exact SVM queries (1: sequential timing).
    progress : callable, optional
        Called with a short description before each step.

    Returns
    -------
    BenchReport

    Raises
    ------
    InputError
        For an unknown section.
    """
    sections = check_sections(sections)
    env = environment()
    t_start = time.perf_counter()
    out = _Collected()
    section_wall: dict[str, float] = {}
    say = progress or (lambda _msg: None)
    for sec in SECTIONS:
        if sec in sections:
            t0 = time.perf_counter()
            _RUNNERS[sec](out, quick, seed, say, svm_table=svm_table, ideal_table=ideal_table, jobs=jobs)
            section_wall[sec] = time.perf_counter() - t0
    return BenchReport(rows=tuple(out.rows), curves=tuple(out.curves), facts=out.facts, quick=quick, seed=seed,
                       wall_s=time.perf_counter() - t_start, environment=env, skipped=tuple(out.skipped),
                       section_wall_s=section_wall)
