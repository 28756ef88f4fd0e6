"""What every section of the accuracy report returns, and the summaries they share.

A section measures methods against a reference and returns :class:`Row`
objects (the cost section returns :class:`CostCurve` objects). The error
summaries (:func:`p95`, :func:`worst`) and the paper's scene
(:data:`PAPER_RATIO`, :func:`paper_sensor`) are shared here so that every
section summarizes the same way.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

__all__ = ["PAPER_RATIO", "CostCurve", "Row", "p95", "paper_sensor", "worst"]

#: sigma 0.05 degC over dT 10 degC: the paper's guideline scene [-].
PAPER_RATIO = 0.005


@dataclass(frozen=True)
class Row:
    """One method at one setting: its error against a reference and its run time.

    Attributes
    ----------
    question : str
        What is answered (``"SVM F1"``, ``"min-contact"``, ``"delta(e)"``, ...).
    method : str
        How designkit answers it.
    setting : str
        The method's knob(s) (trials, grid, tolerance, ...).
    metric : str
        What ``error`` measures, with units.
    error : float
        The typical error: the 95th percentile when the row summarizes many
        cases (``n > 1``), else the single value.
    worst : float
        The worst case over the cases.
    wall_s : float
        Wall time of the method per answer [s].
    reference : str
        The high-fidelity reference the error is measured against.
    reference_wall_s : float
        Wall time of the reference per answer [s] (NaN when not timed).
    n : int
        Number of cases summarized.
    note : str
        Anything needed to read the row right.

    Examples
    --------
    >>> r = Row("q", "fast", "s", "err", 0.1, 0.2, 0.001, "ref", 0.1)
    >>> round(r.speedup)
    100
    >>> sorted(r.to_dict())[:3]
    ['error', 'method', 'metric']
    """

    question: str
    method: str
    setting: str
    metric: str
    error: float
    worst: float
    wall_s: float
    reference: str
    reference_wall_s: float
    n: int = 1
    note: str = ""

    @property
    def speedup(self) -> float:
        """Reference time over method time (>1: the method is faster)."""
        if not (self.wall_s > 0) or not math.isfinite(self.reference_wall_s):
            return math.nan
        return self.reference_wall_s / self.wall_s

    def to_dict(self) -> dict[str, Any]:
        """The row's fields and its speed-up (the ``accuracy.json`` schema of a row)."""
        d = asdict(self)
        d["speedup"] = self.speedup
        return d


@dataclass(frozen=True)
class CostCurve:
    """Cost of the sweep engine as one quantity grows, with fitted exponents.

    ``cost ~ x^p`` with ``p`` from a least-squares line through
    ``(log x, log cost)``. ``peak_mb`` is each point's peak resident set above
    the resident set of its process after imports (Linux's resettable
    high-water mark; NaN where unavailable); ``base_mb`` that baseline.
    """

    name: str
    variable: str
    fidelity: str
    x: tuple[float, ...]
    wall_s: tuple[float, ...]
    fits: tuple[int, ...]
    peak_mb: tuple[float, ...]
    base_mb: float
    time_exponent: float
    fits_exponent: float | None
    memory_exponent: float | None
    setting: str = ""
    note: str = ""

    def to_dict(self) -> dict[str, Any]:
        """The curve's fields (the ``accuracy.json`` schema of a curve)."""
        return asdict(self)


def _finite(x) -> np.ndarray:
    a = np.asarray(x, dtype=np.float64)
    return a[np.isfinite(a)]


def p95(x) -> float:
    """95th percentile of the finite values (NaN when there are none).

    Examples
    --------
    >>> p95([0.0, 1.0, float("nan")])
    0.95
    >>> p95([])
    nan
    """
    a = _finite(x)
    return float(np.percentile(a, 95)) if a.size else math.nan


def worst(x) -> float:
    """Largest finite value (NaN when there is none).

    Examples
    --------
    >>> worst([0.5, float("inf"), 2.0])
    2.0
    """
    a = _finite(x)
    return float(a.max()) if a.size else math.nan


def paper_sensor():
    """The paper's sensor (:data:`designkit.sensor.SENSORS` ``["paper"]``)."""
    from designkit.sensor import SENSORS

    return SENSORS["paper"]
