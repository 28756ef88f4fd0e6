"""Scores shared by the ideal observers: the result type and the scoring of a log-likelihood ratio."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["TRIVIAL_F1", "IdealResult", "score_llr"]

#: F1 of "everything positive" with balanced classes: the least any observer scores.
TRIVIAL_F1 = 2.0 / 3.0


@dataclass(frozen=True)
class IdealResult:
    """Best achievable recognition of one pair of classes.

    Attributes
    ----------
    f1 : float
        Best F1 over all classifiers (a likelihood-ratio threshold), positive
        class = higher effusivity. At least 2/3.
    accuracy : float
        Bayes accuracy with equal priors.
    method : str
        ``"closed-form"`` (fixed initial conditions) or ``"monte-carlo"``.
    standard_error : float
        Monte Carlo standard error of ``f1`` (0 for the closed form).
    accuracy_standard_error : float
        Monte Carlo standard error of ``accuracy`` (0 for the closed form).
    projection_noise : float or None
        ``s``: noise of the projected statistic in units of ``w`` (closed form).
    n_mc : int or None
        Simulated test touches per class (Monte Carlo).
    details : dict
        How a Monte Carlo answer was computed (grid sizes, basis rank ...).
    """

    f1: float
    accuracy: float
    method: str
    standard_error: float = 0.0
    accuracy_standard_error: float = 0.0
    projection_noise: float | None = None
    n_mc: int | None = None
    details: dict = field(default_factory=dict, compare=False)

    def to_dict(self) -> dict:
        return {
            "f1": self.f1,
            "accuracy": self.accuracy,
            "method": self.method,
            "standard_error": self.standard_error,
            "accuracy_standard_error": self.accuracy_standard_error,
            "projection_noise": self.projection_noise,
            "n_mc": self.n_mc,
            "details": dict(self.details),
        }


def score_llr(llr: np.ndarray, labels: np.ndarray, n_mc: int) -> tuple[float, float, float, float]:
    """Best F1 over thresholds on a log-likelihood ratio, with Bayes accuracy, and their standard errors.

    ``llr`` of ``n_mc`` simulated touches per class (``labels`` 1 for the positive
    class). The F1 is the best over all thresholds (never below the trivial
    2/3 of calling everything positive); the accuracy is the Bayes rule's
    (threshold 0, equal priors). Returns ``(f1, f1 standard error, accuracy,
    accuracy standard error)``.

    Examples
    --------
    >>> f1, _, acc, _ = score_llr(np.array([-2.0, -1.0, 1.0, 2.0]), np.array([0, 0, 1, 1]), 2)
    >>> f1, acc
    (1.0, 1.0)
    """
    from sklearn.metrics import precision_recall_curve

    from .svm import f1_standard_error

    acc = float(np.mean((llr > 0) == labels))
    precision, recall, _ = precision_recall_curve(labels, llr)
    with np.errstate(invalid="ignore", divide="ignore"):
        f1s = np.where(precision + recall > 0, 2 * precision * recall / (precision + recall), 0.0)
    best = int(np.argmax(f1s))
    f1 = max(float(f1s[best]), TRIVIAL_F1)
    tpr = float(recall[best])
    # false-positive rate at that operating point: from precision and recall
    fpr = tpr * (1.0 / precision[best] - 1.0) if precision[best] > 0 else 1.0
    se = f1_standard_error(tpr, min(max(fpr, 0.0), 1.0), n_mc)
    acc_se = math.sqrt(max(acc * (1 - acc), 0.25 / n_mc) / (2 * n_mc))
    return f1, se, acc, acc_se
