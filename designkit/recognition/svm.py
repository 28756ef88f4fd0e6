"""Binary material recognition with the paper's pipeline (section III).

Features: raw samples + local slope (:mod:`designkit.recognition.features`), standardized
inside each training fold; classifier: scikit-learn's binary SVM with a linear
kernel; score: stratified k-fold cross-validated F1 (k = 3 in the paper).

The positive class is always the range with the higher effusivity, so a pair's
F1 does not depend on the order its ranges are given in.

scikit-learn is imported here and nowhere on the table-query path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validation import InputError, as_generator, check_effusivity_range
from .features import DEFAULT_SLOPE_WINDOW_S, feature_matrix
from ..models import ForwardModel, get_model
from ..objects import ObjectClass, ordered_pair
from ..scene import Scene
from ..sensor import Sensor
from ..simulation import seed_key, simulate_class

__all__ = [
    "F1Result",
    "cross_validated_f1",
    "binary_f1",
    "f1_from_features",
    "f1_standard_error",
    "interval_pair_f1",
    "make_classifier",
    "pair_f1",
]


@dataclass(frozen=True)
class F1Result:
    """Cross-validated F1 of one pair of classes.

    Attributes
    ----------
    f1 : float
        Mean of the fold F1 scores (as the paper reports).
    fold_f1 : tuple of float
        F1 of each test fold.
    standard_error : float
        Monte Carlo standard error of ``f1`` from the pooled confusion counts
        (delta method on the binomial true- and false-positive rates). It
        covers the test-set sampling, not the training-set variation; repeat
        with other seeds for the full spread.
    accuracy : float
        Pooled cross-validated accuracy.
    n_per_class : int
        Trials per class.
    """

    f1: float
    fold_f1: tuple[float, ...]
    standard_error: float
    accuracy: float
    n_per_class: int

    def to_dict(self) -> dict:
        return {"f1": self.f1, "fold_f1": list(self.fold_f1), "standard_error": self.standard_error,
                "accuracy": self.accuracy, "n_per_class": self.n_per_class}


def _linear_gram_svc_class():
    """scikit-learn's SVC solving the linear-kernel problem from a BLAS Gram matrix.

    ``SVC(kernel="linear")`` evaluates the kernel inside libsvm one pair at a
    time; with a few hundred touches and thousands of features it is faster to
    hand libsvm the Gram matrix ``X X^T`` (one matrix product) and the same
    solver (``kernel="precomputed"``). The optimization problem, solver and
    predictions are identical (tests/test_recognition.py checks this).
    """
    from sklearn.base import BaseEstimator, ClassifierMixin
    from sklearn.svm import SVC

    class LinearGramSVC(ClassifierMixin, BaseEstimator):
        def __init__(self, C: float = 1.0):
            self.C = C

        def fit(self, X, y):
            X = np.asarray(X, dtype=np.float64)
            self.X_fit_ = X
            self.svc_ = SVC(kernel="precomputed", C=self.C).fit(X @ X.T, y)
            self.classes_ = self.svc_.classes_
            return self

        def decision_function(self, X):
            return self.svc_.decision_function(np.asarray(X, dtype=np.float64) @ self.X_fit_.T)

        def predict(self, X):
            return self.svc_.predict(np.asarray(X, dtype=np.float64) @ self.X_fit_.T)

    return LinearGramSVC


def make_classifier():
    """The paper's classifier: standardization then a linear-kernel SVM (C = 1).

    Same model and solver as ``make_pipeline(StandardScaler(), SVC(kernel="linear"))``,
    about twice as fast here (see :func:`_linear_gram_svc_class`).
    """
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    return make_pipeline(StandardScaler(), _linear_gram_svc_class()())


def f1_standard_error(tpr: float, fpr: float, n_per_class: int) -> float:
    """Delta-method standard error of ``F1 = 2 TPR / (1 + TPR + FPR)`` (balanced classes).

    TPR and FPR are treated as independent binomial proportions over
    ``n_per_class`` test cases each, with a half-count continuity correction so
    that a perfect score does not claim zero uncertainty.
    """
    n = float(n_per_class)
    t = (tpr * n + 0.5) / (n + 1.0)
    f = (fpr * n + 0.5) / (n + 1.0)
    d = (1.0 + t + f) ** 2
    dt = 2.0 * (1.0 + f) / d
    df = -2.0 * t / d
    return math.sqrt(dt * dt * t * (1 - t) / n + df * df * f * (1 - f) / n)


def cross_validated_f1(temps_low, temps_high, sample_rate_hz: float, *, folds: int = 3,
                       seed=0, slope_window_s: float = DEFAULT_SLOPE_WINDOW_S) -> F1Result:
    """Stratified k-fold F1 of the paper's SVM on two sets of touches.

    Parameters
    ----------
    temps_low, temps_high : array_like, shape (n, m)
        Readings [degC] of the lower- and higher-effusivity class (the latter is
        the positive class). Equal numbers of trials are not required.
    sample_rate_hz : float
        Sampling rate [Hz] (for the slope feature).
    folds : int
        Number of folds (>= 2, at most the smaller class size).
    seed : int or sequence of int
        Seed of the fold shuffling.
    slope_window_s : float
        Savitzky-Golay slope window [s].
    """
    lo = np.atleast_2d(np.asarray(temps_low, dtype=np.float64))
    hi = np.atleast_2d(np.asarray(temps_high, dtype=np.float64))
    if lo.shape[1] != hi.shape[1]:
        raise InputError(f"both classes need the same number of samples, got {lo.shape[1]} and {hi.shape[1]}")
    _check_folds(folds, min(lo.shape[0], hi.shape[0]))
    return f1_from_features(feature_matrix(lo, sample_rate_hz, slope_window_s),
                            feature_matrix(hi, sample_rate_hz, slope_window_s), folds=folds, seed=seed)


def _check_folds(folds: int, n_min: int) -> None:
    if int(folds) != folds or folds < 2:
        raise InputError(f"folds must be >= 2, got {folds}")
    if n_min < folds:
        raise InputError(f"trials per class ({n_min}) must be at least the number of folds ({folds})")


def f1_from_features(features_low, features_high, *, folds: int = 3, seed=0) -> F1Result:
    """Cross-validated F1 of the paper's SVM on ready-made feature matrices.

    The sweep engine computes each class's features once and pairs them many
    times; :func:`cross_validated_f1` is the same on raw readings. Inputs are
    finite by construction, so scikit-learn's per-call input validation is
    switched off here (``config_context``), which removes about a third of the
    cost of a fit without changing any prediction.
    """
    import sklearn
    from sklearn.model_selection import StratifiedKFold, cross_val_predict

    lo = np.asarray(features_low, dtype=np.float64)
    hi = np.asarray(features_high, dtype=np.float64)
    n_min = min(lo.shape[0], hi.shape[0])
    _check_folds(folds, n_min)
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise InputError("features contain NaN or infinite values")
    X = np.vstack([lo, hi])
    y = np.r_[np.zeros(lo.shape[0], dtype=int), np.ones(hi.shape[0], dtype=int)]
    cv_state = int(as_generator(seed).integers(0, 2**31 - 1))
    cv = StratifiedKFold(n_splits=int(folds), shuffle=True, random_state=cv_state)
    with sklearn.config_context(assume_finite=True, skip_parameter_validation=True):
        pred = cross_val_predict(make_classifier(), X, y, cv=cv)
    fold_f1 = tuple(binary_f1(y[test], pred[test]) for _, test in cv.split(X, y))
    tpr = float(np.mean(pred[y == 1] == 1))
    fpr = float(np.mean(pred[y == 0] == 1))
    return F1Result(
        f1=float(np.mean(fold_f1)),
        fold_f1=fold_f1,
        standard_error=f1_standard_error(tpr, fpr, n_min),
        accuracy=float(np.mean(pred == y)),
        n_per_class=n_min,
    )


def binary_f1(y_true, y_pred) -> float:
    """F1 of the positive class (label 1): ``2 TP / (2 TP + FP + FN)``, 0 when undefined.

    Same value as ``sklearn.metrics.f1_score(y_true, y_pred, zero_division=0)``
    (tested), without its per-call validation, which costs more than the
    arithmetic in the engine's inner loop.
    """
    t = np.asarray(y_true) == 1
    p = np.asarray(y_pred) == 1
    tp = int(np.sum(t & p))
    denom = 2 * tp + int(np.sum(~t & p)) + int(np.sum(t & ~p))
    return 2.0 * tp / denom if denom else 0.0


def pair_f1(obj_a: ObjectClass, obj_b: ObjectClass, sensor: Sensor, scene: Scene, *,
            model: "ForwardModel | str | None" = None, trials: int = 100, folds: int = 3, seed=0,
            slope_window_s: float = DEFAULT_SLOPE_WINDOW_S) -> F1Result:
    """The paper's SVM F1 for two object classes under any forward model (paper section IV).

    Parameters
    ----------
    obj_a, obj_b : ObjectClass
        The classes; order does not matter (the higher effusivity is positive).
    sensor : Sensor
    scene : Scene
    model : ForwardModel or name, optional
        Forward model of the touches (default: the paper's semi-infinite model).
    trials : int
        Trials per class (100 in the paper).
    folds : int
        Cross-validation folds (3 in the paper).
    seed : int or list of int
        Trials of the lower class use stream ``[seed, 0]``, of the higher
        ``[seed, 1]``, the fold shuffle ``[seed, 2]``.

    Examples
    --------
    >>> from designkit import SENSORS, Scene
    >>> from designkit.objects import object_class
    >>> r = pair_f1(object_class(35000), object_class(20000), SENSORS["paper"], Scene(contact_s=2),
    ...             model="contact")
    >>> r.f1 > 0.9
    True
    """
    fm = get_model(model)
    low, high = ordered_pair(obj_a, obj_b)
    trials = int(trials)
    _check_folds(folds, trials)
    base = seed_key(seed)
    t_low = simulate_class(low, trials, sensor, scene, base + [0], fm)
    t_high = simulate_class(high, trials, sensor, scene, base + [1], fm)
    return cross_validated_f1(t_low.temperature_c, t_high.temperature_c, sensor.sample_rate_hz,
                              folds=folds, seed=base + [2], slope_window_s=slope_window_s)


def interval_pair_f1(range_a: tuple[float, float], range_b: tuple[float, float], sensor: Sensor,
                     scene: Scene, *, trials: int = 100, folds: int = 3, seed=0,
                     slope_window_s: float = DEFAULT_SLOPE_WINDOW_S) -> F1Result:
    """SVM F1 for two effusivity classes, each uniform in its range (paper section IV).

    Parameters
    ----------
    range_a, range_b : (float, float)
        Class ranges ``[low, high)`` [J s^-1/2 K^-1 m^-2]; order does not matter.
    sensor : Sensor
    scene : Scene
    trials : int
        Trials per class (100 in the paper).
    folds : int
        Cross-validation folds (3 in the paper).
    seed : int
        Trials of the lower class use stream ``[seed, 0]``, of the higher
        ``[seed, 1]``, the fold shuffle ``[seed, 2]``.

    Examples
    --------
    >>> from designkit import SENSORS, Scene
    >>> r = interval_pair_f1((35000, 35080), (20000, 20080), SENSORS["paper"], Scene(contact_s=2))
    >>> r.f1 > 0.9
    True
    """
    a = check_effusivity_range("e1", *range_a)
    b = check_effusivity_range("e2", *range_b)
    if a == b:
        raise InputError(f"the two effusivity ranges are identical ([{a[0]:g}, {a[1]:g})): nothing to separate")
    low, high = sorted([a, b])
    return pair_f1(ObjectClass("low", low), ObjectClass("high", high), sensor, scene, trials=trials,
                   folds=folds, seed=seed, slope_window_s=slope_window_s)
