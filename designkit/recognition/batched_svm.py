"""Batched cross-validated F1 of the paper's SVM: many pairs and folds as array operations.

Same classifier as :func:`designkit.recognition.svm.f1_from_features` (the reference):
stratified k-fold cross-validation with the same folds (scikit-learn's
``StratifiedKFold(shuffle=True)`` with the same ``random_state`` derivation, replicated
here and tested equal), standardization fitted on each training fold (mean and
population standard deviation, constant features as ``StandardScaler`` detects them),
and the linear-kernel C-SVM with an unregularized bias as libsvm poses it::

    min_a  1/2 a^T Q a - 1^T a    subject to  0 <= a_i <= C,  y^T a = 0,
    Q_ij = y_i y_j x_i . x_j,     C = 1,

with libsvm's bias rule (average of ``y_i G_i`` over the free support vectors, the
midpoint of the feasible interval when there are none) and libsvm's prediction
(``sum_j y_j a_j x_j . x - rho > 0`` gives the lower class, ties the higher one).

What differs is how the dual is solved: all problems of a batch together, by a **primal-dual
active-set (semismooth Newton) method** (:func:`solve_svc_duals`): guess which ``a_i`` are
free, at 0 or at C; solve the free ones' KKT system (one batched ``(n+1) x (n+1)`` solve);
move the variables that leave the box or whose gradient has the wrong sign; stop when the
sets no longer change, where the KKT conditions hold to rounding (libsvm stops at a gap of
1e-3). A tiny ridge keeps the systems nonsingular; problems where the active set does not
settle are re-solved by continuation, then from libsvm's own solution (scikit-learn's
``SVC`` on the precomputed kernel), and as a last resort libsvm's answer is kept (the
``solver`` code of each problem says which; evidence: ``benchmarks/results/rig-duals.txt``).

Cost: the Gram products dominate (``n_train^2 d / 2`` multiply-adds per fold). They are
formed in float32 from features centered in float64 (``K`` to about 1e-6 relative, far
below what moves a prediction; the solver runs in float64), with each fold's
standardization folded into them: features are centered once per pair (the SVM is
invariant to a common shift) and scaled by each fold's inverse standard deviation
(:func:`prepare_features`, :func:`_chunk_prepared`).

The code is written against the array API (``xp``: numpy by default, or the namespace
``array_api_compat`` finds for the inputs where it is installed); the fold assignment
(a few random shuffles per pair) stays in numpy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import InputError, as_generator
from .svm import F1Result, f1_standard_error

__all__ = [
    "ARRAY_LIBRARIES",
    "BatchedF1",
    "LIBSVM_EPS",
    "PreparedFeatures",
    "array_library",
    "batched_cv_f1",
    "prepare_features",
    "solve_svc_duals",
    "stratified_test_folds",
]

#: libsvm's default stopping tolerance on the KKT gap (scikit-learn's ``SVC(tol=1e-3)``).
LIBSVM_EPS = 1e-3
_RIDGE = 1e-9  # relative ridge of the active-set solves (times mean(diag K))
_CONTINUATION = (1e-3, 1e-9)
_SMO_EPS_START = 1e-2  # libsvm's eps before the polish (rig duals: exact after it on 90 of 90, after 1e-3 on 83)


def _namespace(xp, *arrays):
    if xp is not None:
        return xp
    if all(isinstance(a, np.ndarray) for a in arrays):
        return np  # numpy's own namespace: the fast paths below test for it
    try:
        from array_api_compat import array_namespace
    except ImportError:
        return np
    return array_namespace(*arrays)


#: Array libraries the batched solver runs on by name (``array_library``); numpy is the default.
ARRAY_LIBRARIES = ("numpy", "cupy", "array-api")


def array_library(name: str):
    """The array namespace of a library by name, or one clear error if it is not installed.

    ``"numpy"`` is numpy itself (the solver's numpy fast path); ``"cupy"`` is CuPy through
    ``array_api_compat`` (``pip install 'designkit[gpu]'``): the same solver code then runs
    on the GPU; ``"array-api"`` is numpy through ``array_api_compat``'s wrapper namespace,
    which runs the code the GPU runs (the generic array-API path, not the numpy fast path)
    on the CPU: what a GPU build should give, checked without a GPU.

    Raises
    ------
    InputError
        Unknown name, or the library (or ``array_api_compat``) is not installed.

    Examples
    --------
    >>> array_library("numpy").__name__
    'numpy'
    """
    if name not in ARRAY_LIBRARIES:
        raise InputError(f"array library must be one of {', '.join(ARRAY_LIBRARIES)}, got {name!r}")
    if name == "numpy":
        return np
    if name == "array-api":
        try:
            from array_api_compat import numpy as xp
        except ImportError as exc:
            raise InputError(f"the array-api solver needs array-api-compat ({exc}); install it with "
                             "pip install array-api-compat") from None
        return xp
    try:
        import cupy  # noqa: F401
        from array_api_compat import cupy as xp
    except ImportError as exc:
        raise InputError(f"the {name} array library is not usable here ({exc}); "
                         "install it with pip install 'designkit[gpu]' on a machine with a GPU") from None
    return xp


def _check_folds(folds: int, n_min: int) -> int:
    if int(folds) != folds or folds < 2:
        raise InputError(f"folds must be >= 2, got {folds}")
    if n_min < folds:
        raise InputError(f"trials per class ({n_min}) must be at least the number of folds ({folds})")
    return int(folds)


def _allocation(n_low: int, n_high: int, folds: int) -> np.ndarray:
    """Test-set size of each class in each fold, as StratifiedKFold allots them: shape (folds, 2)."""
    y_order = np.r_[np.zeros(n_low, dtype=np.intp), np.ones(n_high, dtype=np.intp)]
    return np.asarray([np.bincount(y_order[i::folds], minlength=2) for i in range(folds)])


def stratified_test_folds(n_low: int, n_high: int, seed, folds: int = 3, *,
                          _legacy: "np.random.RandomState | None" = None) -> np.ndarray:
    """Test-fold index of each touch, exactly as the reference's StratifiedKFold assigns it.

    The reference (:func:`~designkit.recognition.svm.f1_from_features`) stacks the
    lower class over the higher one, labels them 0 and 1 and splits with
    ``StratifiedKFold(n_splits=folds, shuffle=True, random_state=r)``,
    ``r = int(as_generator(seed).integers(0, 2**31 - 1))``. This replicates
    scikit-learn's ``_make_test_folds`` for that input (tests check equality).

    Parameters
    ----------
    n_low, n_high : int
        Touches of the lower (label 0) and higher (label 1) class.
    seed : int or sequence of int
        The reference's ``seed``.
    folds : int
        Number of folds.

    Returns
    -------
    ndarray of int, shape (n_low + n_high,)
        Fold in which each touch (lower class first) is a test touch.

    Examples
    --------
    >>> f = stratified_test_folds(4, 3, seed=0, folds=2)
    >>> f.shape, sorted(set(f.tolist()))
    ((7,), [0, 1])
    """
    folds = _check_folds(folds, min(n_low, n_high))
    state = int(as_generator(seed).integers(0, 2**31 - 1))
    if _legacy is None:
        rng = np.random.RandomState(state)
    else:  # re-seeding one RandomState gives the same stream (2 us instead of 150 us for a new one, measured)
        rng = _legacy
        rng.seed(state)
    alloc = _allocation(n_low, n_high, folds)
    out = np.empty(n_low + n_high, dtype=np.intp)
    for k, (start, stop) in enumerate(((0, n_low), (n_low, n_low + n_high))):
        folds_for_class = np.arange(folds).repeat(alloc[:, k])
        rng.shuffle(folds_for_class)
        out[start:stop] = folds_for_class
    return out


# ----------------------------------------------------------------------------- solver
def _bias_and_gap(K, y, a, C, xp):
    """libsvm's rho (Solver::calculate_rho) and KKT gap at ``a``; y in libsvm's +-1 convention."""
    beta = y * a
    G = y * (K @ beta[..., None])[..., 0] - 1.0  # gradient of the dual, Q a - 1
    yG = y * G
    at_up = a >= C
    at_low = a <= 0.0
    free = ~(at_up | at_low)
    inf = float("inf")
    # upper bound: y = -1 -> ub, y = +1 -> lb ; lower bound: y = +1 -> ub, y = -1 -> lb
    to_ub = (at_up & (y < 0)) | (at_low & (y > 0))
    to_lb = (at_up & (y > 0)) | (at_low & (y < 0))
    ub = xp.min(xp.where(to_ub, yG, inf), axis=-1)
    lb = xp.max(xp.where(to_lb, yG, -inf), axis=-1)
    n_free = xp.sum(xp.astype(free, yG.dtype), axis=-1)
    sum_free = xp.sum(xp.where(free, yG, 0.0), axis=-1)
    fin_ub, fin_lb = xp.isfinite(ub), xp.isfinite(lb)
    ub0, lb0 = xp.where(fin_ub, ub, 0.0), xp.where(fin_lb, lb, 0.0)
    mid = xp.where(fin_ub & fin_lb, (ub0 + lb0) / 2, ub0 + lb0)  # libsvm: (ub + lb) / 2 (one side empty: the other)
    rho = xp.where(n_free > 0, sum_free / xp.where(n_free > 0, n_free, 1.0), mid)
    v = -yG
    i_up = ((y > 0) & (a < C)) | ((y < 0) & (a > 0))
    i_low = ((y > 0) & (a > 0)) | ((y < 0) & (a < C))
    gap = xp.max(xp.where(i_up, v, -inf), axis=-1) - xp.min(xp.where(i_low, v, inf), axis=-1)
    return rho, gap


def _solve(M, rhs, xp):
    """Batched solve; a singular member gives NaN (numpy raises for the whole batch)."""
    try:
        return xp.linalg.solve(M, rhs)
    except Exception:  # numpy.linalg.LinAlgError, torch's, cupy's: isolate the singular members
        out = xp.full(rhs.shape, float("nan"), dtype=rhs.dtype)
        for k in range(M.shape[0]):
            try:
                out[k] = xp.linalg.solve(M[k], rhs[k])
            except Exception:
                pass
        return out


def _kkt_bordered(Ka, ya, fr, uu, C, ridge, eye, xp):
    """Equality-constrained KKT step of the active set (fr free, uu at C) as one bordered solve.

    Returns z, shape (p, n + 1): ``beta = y a`` of every variable, then the multiplier
    of ``y^T a = 0`` (libsvm's ``-rho``).
    """
    p, n = ya.shape
    dt = Ka.dtype
    fa = xp.astype(fr, dt)
    ua = xp.astype(uu, dt)
    beta_u = C * ya * ua
    M = xp.zeros((p, n + 1, n + 1), dtype=dt)
    M[:, :n, :n] = Ka * (fa[:, :, None] * fa[:, None, :]) + eye * ((1.0 - fa) + ridge[:, None] * fa)[:, None, :]
    M[:, :n, n] = fa
    M[:, n, :n] = fa
    M[:, n, n] = 1.0 - xp.astype(xp.any(fr, axis=-1), dt)  # no free variable: keep it solvable, flagged below
    rhs = xp.zeros((p, n + 1, 1), dtype=dt)
    if bool(xp.any(uu)):
        rhs[:, :n, 0] = fa * (ya - (Ka @ beta_u[..., None])[..., 0]) + (1.0 - fa) * beta_u
    else:  # no variable at C (the usual case here): skip a batched mat-vec
        rhs[:, :n, 0] = fa * ya
    rhs[:, n, 0] = -xp.sum(beta_u, axis=-1)
    return _solve(M, rhs, xp)[..., 0]


def _kkt_step(Ka, ya, fr, uu, C, ridge, eye, xp):
    """:func:`_kkt_bordered`'s answer; with numpy, by a Cholesky solve of the free block alone.

    The free block ``K_FF + ridge I`` is symmetric positive definite wherever the
    bordered system is well posed, so block elimination of the equality constraint
    (``K_FF [u v] = [r 1]``, ``b = (1.u - c) / 1.v``, ``beta_F = u - b v``) gives the
    same solution with one LAPACK ``dposv`` on ``|F|`` variables instead of an LU of
    ``n + 1`` (measured: 3-4x less solver time at n = 133, |F| ~ 114; numpy has no
    batched Cholesky solve, hence the loop over problems). A block that Cholesky
    refuses (numerically indefinite: rank-deficient Gram matrices, float32 rounding)
    is solved by the bordered LU as before.
    """
    if xp is not np:
        return _kkt_bordered(Ka, ya, fr, uu, C, ridge, eye, xp)
    from scipy.linalg.lapack import dposv

    p, n = ya.shape
    z = np.zeros((p, n + 1))
    retry = []
    any_up = uu.any(axis=1)
    for k in range(p):
        F = np.flatnonzero(fr[k])
        if F.size == 0:
            z[k] = np.nan
            continue
        yk = ya[k]
        rhs = np.empty((F.size, 2), order="F")
        rhs[:, 1] = 1.0
        c = 0.0
        if any_up[k]:
            U = np.flatnonzero(uu[k])
            bu = C * yk[U]
            rhs[:, 0] = yk[F] - Ka[k][np.ix_(F, U)] @ bu
            c = -float(bu.sum())
            z[k, U] = bu
        else:
            rhs[:, 0] = yk[F]
        # symmetric: its transpose is the Fortran-order view LAPACK wants; every variable free (each fold's
        # first step): a plain copy instead of two gathers
        A = Ka[k].copy() if F.size == n else Ka[k].take(F, axis=0).take(F, axis=1)
        A.flat[:: F.size + 1] += ridge[k]
        _, x, info = dposv(A.T, rhs, overwrite_a=1, overwrite_b=1)
        if info != 0:
            retry.append(k)
            continue
        u, v = x[:, 0], x[:, 1]
        b = (u.sum() - c) / v.sum()
        z[k, F] = u - b * v
        z[k, n] = b
    if retry:
        r = np.asarray(retry)
        z[r] = _kkt_bordered(Ka[r], ya[r], fr[r], uu[r], C, ridge[r], eye, xp)
    return z


def _active_set(K, y, C, ridge, free, up, max_iter, xp):
    """Batched primal-dual active-set method; returns (a, converged, iterations)."""
    P, n = y.shape
    dt = K.dtype
    eye = xp.eye(n, dtype=dt)
    a_out = xp.zeros((P, n), dtype=dt)
    done = xp.zeros(P, dtype=xp.bool)
    failed = xp.zeros(P, dtype=xp.bool)
    iters = xp.zeros(P, dtype=xp.int64)
    tol_g = 1e-9
    idx = xp.arange(P)
    for _ in range(max_iter):
        if idx.shape[0] == 0:
            break
        # every problem still open (always the first step): the arrays themselves, not gathered copies
        Ka, ya = (K, y) if idx.shape[0] == P else (K[idx], y[idx])
        z = _kkt_step(Ka, ya, free[idx], up[idx], C, ridge[idx], eye, xp)
        beta = z[:, :n]
        a = ya * beta
        g = ya * ((Ka @ beta[..., None])[..., 0] + z[:, n:]) - 1.0
        iters[idx] += 1
        fr, uu = free[idx], up[idx]
        low = ~fr & ~uu
        bad = ~xp.all(xp.isfinite(z), axis=-1) | ~xp.any(fr, axis=-1)
        new_free = (fr & (a >= 0) & (a <= C)) | (low & (g < -tol_g)) | (uu & (g > tol_g))
        new_up = (fr & (a > C)) | (uu & (g <= tol_g))
        same = xp.all(new_free == fr, axis=-1) & xp.all(new_up == uu, axis=-1)
        conv = same & ~bad
        a_out[idx] = xp.where(conv[:, None], xp.clip(a, 0.0, C), a_out[idx])
        done[idx] = conv
        failed[idx] = bad
        free[idx] = new_free
        up[idx] = new_up
        idx = idx[~(conv | bad)]
    return a_out, done, iters


def _restore_equality(a, y, ok, C, xp):
    """``(a, ok)`` with ``y.a = 0`` restored: numpy's block elimination leaves up to 1e-8 on near-degenerate
    optima (the bordered LU does not), spread evenly over the free ``a``; ``ok`` false where that leaves the box."""
    free = (a > 0.0) & (a < C)
    n_free = xp.sum(xp.astype(free, a.dtype), axis=-1)
    r = xp.sum(y * a, axis=-1) / xp.where(n_free > 0, n_free, 1.0)
    b = a - xp.where(free, r[:, None] * y, 0.0)
    inside = xp.all((b >= 0.0) & (b <= C), axis=-1) & (n_free > 0)
    ok = ok & inside
    return xp.where(ok[:, None], b, a), ok


def _libsvm_smo(K, y, C, eps, max_iter, xp):
    """libsvm's own SMO, problem by problem on the host: ``(a, done, iterations)``.

    scikit-learn's ``SVC`` on the precomputed kernel with the labels as the reference fits them (the
    class that is +1 here listed first), so the same path and optimum as the reference's fit; ``a`` is
    ``|dual_coef_|`` at the support vectors.
    """
    import warnings

    from sklearn.exceptions import ConvergenceWarning
    from sklearn.svm import SVC

    host = lambda v: v.get() if hasattr(v, "get") else np.asarray(v)  # noqa: E731  (CuPy: an explicit copy)
    Kh, yh = host(K), host(y)
    a = np.zeros(yh.shape, dtype=np.float64)
    iters = np.zeros(yh.shape[0], dtype=np.int64)
    for p in range(yh.shape[0]):
        with warnings.catch_warnings():  # at max_iter: silently (``done`` says so)
            warnings.simplefilter("ignore", ConvergenceWarning)
            m = SVC(kernel="precomputed", C=C, tol=eps, max_iter=max_iter).fit(Kh[p], (yh[p] < 0).astype(np.int64))
        a[p, m.support_] = np.abs(m.dual_coef_[0])
        iters[p] = int(np.sum(m.n_iter_))
    return xp.asarray(a, dtype=K.dtype), xp.asarray(iters < max_iter), xp.asarray(iters)


def _smo_polished(K, y, C, eps, max_iter, scale, max_active_set_iter, xp):
    """libsvm's SMO at ``eps``, then the active set from its free and bounded sets: ``(a, exact, SMO steps)``;
    ``a`` is the exact optimum where ``exact``, libsvm's answer elsewhere."""
    a_s, _, it_s = _libsvm_smo(K, y, C, eps, max_iter, xp)
    a_p, ok, _ = _active_set(K, y, C, _RIDGE * scale, (a_s > 0.0) & (a_s < C), a_s >= C, max_active_set_iter, xp)
    a_p, ok = _restore_equality(a_p, y, ok, C, xp)
    return xp.where(ok[:, None], a_p, a_s), ok, it_s


def solve_svc_duals(K, y, *, C: float = 1.0, xp=None, max_active_set_iter: int = 25,
                    smo_max_iter: int = 200_000, start=None):
    """Solve a batch of libsvm C-SVC duals with a precomputed kernel.

    Parameters
    ----------
    K : array, shape (P, n, n)
        Gram matrices (float64 recommended), one per problem.
    y : array, shape (n,) or (P, n)
        Labels +1 / -1 in libsvm's convention (+1 = the class libsvm lists first,
        which for scikit-learn's SVC is the smaller label).
    C : float
        Box bound.
    xp : array namespace, optional
    max_active_set_iter : int
        Active-set solves per problem before it is handed to the next stage.
    smo_max_iter : int
        Iteration cap of the SMO fallback.
    start : tuple of two bool arrays, shape (P, n), optional
        A guess of the active set: which ``a_i`` are free and which are at ``C``
        (the rest at 0). Only the path changes: the active-set method stops only
        where the KKT conditions hold, and the (ridged) dual has one optimum, so a
        good guess saves linear solves and a bad one costs a few. Problems whose
        guessed start does not converge are restarted from all-free.

    Returns
    -------
    a : array, shape (P, n)
        Dual coefficients (``0 <= a <= C``).
    rho : array, shape (P,)
        libsvm's ``rho``: the decision value of ``x`` is ``sum_j y_j a_j K(x_j, x) - rho``.
    info : dict
        ``kkt_gap`` (P,): libsvm's stopping quantity at the solution (libsvm stops at
        1e-3); ``solver`` (P,): 0 active set, 1 active set with continuation, 2 SMO then
        the exact optimum by the active set from SMO's sets (SMO at eps 1e-2, else 1e-3),
        3 SMO's own answer at eps 1e-3 (that last step did not converge);
        ``iterations`` (P,): linear solves (stages 0-1) or SMO steps, both runs (stages 2-3).

    Examples
    --------
    >>> import numpy as np
    >>> X = np.array([[0.0, 0.0], [0.0, 1.0], [2.0, 0.0], [2.0, 1.0]])
    >>> a, rho, info = solve_svc_duals((X @ X.T)[None], np.array([1.0, 1.0, -1.0, -1.0]))
    >>> np.round(a, 6).tolist(), round(float(rho[0]), 6)
    ([[0.25, 0.25, 0.25, 0.25]], -1.0)
    """
    xp = _namespace(xp, K)
    K = xp.asarray(K)
    P, n = K.shape[0], K.shape[-1]
    y = xp.asarray(y, dtype=K.dtype)
    if y.ndim == 1:
        y = xp.broadcast_to(y[None, :], (P, n))
    y = xp.asarray(y, copy=True)
    mean_diag = xp.mean(xp.linalg.diagonal(K) if hasattr(xp.linalg, "diagonal") else xp.diagonal(K, axis1=-2, axis2=-1), axis=-1)
    scale = xp.where(mean_diag > 0, mean_diag, 1.0)
    a = xp.zeros((P, n), dtype=K.dtype)
    solver = xp.zeros(P, dtype=xp.int64)
    iters = xp.zeros(P, dtype=xp.int64)

    if start is None:
        free = xp.ones((P, n), dtype=xp.bool)
        up = xp.zeros((P, n), dtype=xp.bool)
    else:
        free = xp.asarray(start[0], dtype=xp.bool, copy=True)
        up = xp.asarray(start[1], dtype=xp.bool, copy=True) & ~free
    a0, ok, it0 = _active_set(K, y, C, _RIDGE * scale, free, up, max_active_set_iter, xp)
    a = xp.where(ok[:, None], a0, a)
    iters = iters + it0
    if start is not None and not bool(xp.all(ok)):  # the guess led nowhere: from all-free, as without one
        redo = xp.nonzero(~ok)[0]
        free_r = xp.ones((redo.shape[0], n), dtype=xp.bool)
        up_r = xp.zeros((redo.shape[0], n), dtype=xp.bool)
        a_r, ok_r, it_r = _active_set(K[redo], y[redo], C, _RIDGE * scale[redo], free_r, up_r,
                                      max_active_set_iter, xp)
        a[redo] = xp.where(ok_r[:, None], a_r, a[redo])
        iters[redo] += it_r
        ok = xp.asarray(ok, copy=True)
        ok[redo] = ok_r
    todo = xp.nonzero(~ok)[0]
    if todo.shape[0]:
        Kt, yt = K[todo], y[todo]
        free = xp.ones(yt.shape, dtype=xp.bool)
        up = xp.zeros(yt.shape, dtype=xp.bool)
        ok_t = xp.ones(todo.shape[0], dtype=xp.bool)
        a_t = xp.zeros(yt.shape, dtype=K.dtype)
        for level in _CONTINUATION:
            a_t, ok_l, it_l = _active_set(Kt, yt, C, level * scale[todo], free, up, max_active_set_iter, xp)
            iters[todo] += it_l
            ok_t = ok_t & ok_l
            if level != _CONTINUATION[-1]:  # restart the failed ones from all-free at the next level
                free = xp.where(ok_l[:, None], free, True)
                up = xp.where(ok_l[:, None], up, False)
        a[todo] = xp.where(ok_t[:, None], a_t, a[todo])
        solver[todo] = 1
        rest = todo[~ok_t]
        if rest.shape[0]:
            # libsvm's own SMO (the reference's solver, in C) at eps 1e-2, then the exact optimum from its active
            # set (1-10 solves); where that does not converge, the same from libsvm at its own eps 1e-3; solver 3:
            # libsvm's own answer (benchmarks/results/rig-duals.txt)
            Kr, yr = K[rest], y[rest]
            a_r, ok_r, it_r = _smo_polished(Kr, yr, C, _SMO_EPS_START, smo_max_iter, scale[rest],
                                            max_active_set_iter, xp)
            again = xp.nonzero(~ok_r)[0]
            if again.shape[0] and _SMO_EPS_START != LIBSVM_EPS:
                a_g, ok_g, it_g = _smo_polished(Kr[again], yr[again], C, LIBSVM_EPS, smo_max_iter,
                                                scale[rest][again], max_active_set_iter, xp)
                a_r[again], ok_r[again], it_r[again] = a_g, ok_g, it_r[again] + it_g
            a[rest] = a_r
            solver[rest] = 3 - xp.astype(ok_r, xp.int64)
            iters[rest] = it_r
    rho, gap = _bias_and_gap(K, y, a, C, xp)
    return a, rho, {"kkt_gap": gap, "solver": solver, "iterations": iters}


# ----------------------------------------------------------------------------- CV driver
@dataclass(frozen=True)
class BatchedF1:
    """Cross-validated F1 of a batch of pairs (one row per pair).

    Attributes
    ----------
    f1 : ndarray, shape (B,)
        Mean of the fold F1 scores (as :class:`~designkit.recognition.svm.F1Result`).
    fold_f1 : ndarray, shape (B, folds)
    accuracy : ndarray, shape (B,)
    standard_error : ndarray, shape (B,)
    n_per_class : int
    predictions : ndarray of int8, shape (B, n_low + n_high)
        Cross-validated prediction of each touch (1 = higher class), lower class first,
        in the order of the inputs.
    decision : ndarray, shape (B, n_low + n_high)
        Decision value of each touch in scikit-learn's convention (>= 0 predicts the
        higher class), in units of the functional margin (support vectors sit at +-1).
    kkt_gap : ndarray, shape (B, folds)
        libsvm's stopping quantity at each fold's solution (libsvm stops below 1e-3).
    solver : ndarray of int, shape (B, folds)
        0 active set, 1 active set with continuation, 2 SMO polished to the exact
        optimum by the active set, 3 SMO alone (see :func:`solve_svc_duals`).
    iterations : ndarray of int, shape (B, folds)
    """

    f1: np.ndarray
    fold_f1: np.ndarray
    accuracy: np.ndarray
    standard_error: np.ndarray
    n_per_class: int
    predictions: np.ndarray
    decision: np.ndarray
    kkt_gap: np.ndarray
    solver: np.ndarray
    iterations: np.ndarray

    def __len__(self) -> int:
        return int(self.f1.shape[0])

    def result(self, i: int) -> F1Result:
        """Pair ``i`` as the reference's :class:`~designkit.recognition.svm.F1Result`."""
        return F1Result(f1=float(self.f1[i]), fold_f1=tuple(float(v) for v in self.fold_f1[i]),
                        standard_error=float(self.standard_error[i]), accuracy=float(self.accuracy[i]),
                        n_per_class=self.n_per_class)

    def results(self) -> list[F1Result]:
        return [self.result(i) for i in range(len(self))]


@dataclass(frozen=True)
class PreparedFeatures:
    """One class's feature matrix as the numpy path of :func:`batched_cv_f1` reads it.

    Attributes
    ----------
    dev : ndarray of float32, shape (n, d)
        Features minus their own mean (computed in float64, then rounded once).
    mean : ndarray of float64, shape (d,)
        The feature means.

    A pair's common center and each class's offset from it are then exact float64
    vectors, and the fold statistics block sums of ``dev`` and ``dev^2``. Built once per
    feature matrix (a sweep caches them per interval) by :func:`prepare_features`: half
    the bytes of the float64 matrix.
    """

    dev: np.ndarray
    mean: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        return self.dev.shape


def prepare_features(features) -> PreparedFeatures:
    """:class:`PreparedFeatures` of one ``(n, d)`` feature matrix (float64 in, one pass).

    Raises :class:`~designkit.InputError` if a value is NaN or infinite.

    Examples
    --------
    >>> import numpy as np
    >>> p = prepare_features(np.array([[1.0, 10.0], [3.0, 10.0]]))
    >>> p.mean.tolist(), p.dev.tolist(), p.dev.dtype.name
    ([2.0, 10.0], [[-1.0, 0.0], [1.0, 0.0]], 'float32')
    """
    if isinstance(features, PreparedFeatures):
        return features
    x = np.asarray(features, dtype=np.float64)
    if x.ndim != 2:
        raise InputError(f"a feature matrix must be 2-D (touches x features), got shape {x.shape}")
    mean = x.mean(axis=0)
    dev = np.empty(x.shape, dtype=np.float32)
    np.subtract(x, mean, out=dev, casting="same_kind")  # rounded once
    if not np.all(np.isfinite(mean)):  # NaN or infinity in a column; a value beyond float32 is caught per pair
        raise InputError("features contain NaN or infinite values")
    return PreparedFeatures(dev=dev, mean=mean)


class _Batch:
    """A batch of feature matrices, stacked one chunk at a time (a list is never stacked whole)."""

    def __init__(self, features, name):
        if isinstance(features, (list, tuple)):
            self.items = [f if isinstance(f, PreparedFeatures) else np.asarray(f, dtype=np.float64)
                          for f in features]
            shapes = {f.shape for f in self.items}
            if len(shapes) > 1:
                raise InputError(f"{name}: every feature matrix must have the same shape, got {sorted(shapes)}")
            if not self.items or len(self.items[0].shape) != 2:
                raise InputError(f"{name} must be shaped (B, n, d) or a non-empty list of (n, d) arrays")
            self.shape = (len(self.items),) + self.items[0].shape
            self.array = None
        else:
            x = np.asarray(features, dtype=np.float64)
            if x.ndim == 2:
                x = x[None]
            if x.ndim != 3:
                raise InputError(f"{name} must be shaped (B, n, d) or a list of (n, d) arrays, got shape {x.shape}")
            self.array, self.shape = x, x.shape

    def get(self, c0: int, c1: int, stack: bool = True):
        """Pairs c0:c1 as one (b, n, d) array, or (``stack=False``) a list as given: the numpy
        path gathers each pair's rows straight from it (a whole pass over the features saved)."""
        if self.array is not None:
            return self.array[c0:c1] if stack else list(self.array[c0:c1])
        if stack:
            return np.stack([f.dev.astype(np.float64) + f.mean if isinstance(f, PreparedFeatures) else f
                             for f in self.items[c0:c1]])
        return self.items[c0:c1]


def batched_cv_f1(features_low, features_high, *, seeds, folds: int = 3, gram_dtype="float32",
                  chunk_size: int = 8, xp=None, timings: "dict | None" = None) -> BatchedF1:
    """Stratified k-fold F1 of the paper's SVM for a batch of pairs at once.

    Pair ``b`` gives the same folds, standardization, classifier and F1 as
    ``f1_from_features(features_low[b], features_high[b], folds=folds, seed=seeds[b])``;
    predictions can differ only where the reference's own solution (libsvm, KKT gap
    1e-3) and this one (exact up to rounding) fall on either side of a near-tie.

    Parameters
    ----------
    features_low, features_high : array_like, shape (B, n_low, d) and (B, n_high, d)
        Feature matrices of the lower and higher class of each pair
        (:func:`~designkit.recognition.features.feature_matrix`), or lists of
        ``(n, d)`` arrays. The higher class is the positive one.
    seeds : sequence of length B
        Fold seed of each pair (the reference's ``seed``: int or list of int).
    folds : int
        Number of folds (3 in the paper).
    gram_dtype : {"float32", "float64"}
        Precision of the Gram products (the solver is float64 either way).
    chunk_size : int
        Pairs processed together; memory is about 3.5 MB per pair of 200 touches x
        802 features at float32, plus the inputs. Lists of feature matrices are
        stacked one chunk at a time, so a call may carry any number of pairs: its
        working memory is that of one chunk.
    xp : array namespace, optional
        Array library for the heavy work (numpy by default).
    timings : dict, optional
        If given, CPU seconds of this process are added under ``"folds"``,
        ``"standardize"``, ``"gram"``, ``"solve"`` and ``"predict"`` (for benchmarks;
        on a GPU the stages overlap and these are not meaningful).

    Returns
    -------
    BatchedF1

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> lo = rng.normal(0.0, 1.0, (2, 30, 8)); hi = rng.normal(0.7, 1.0, (2, 30, 8))
    >>> r = batched_cv_f1(lo, hi, seeds=[0, 1])
    >>> r.f1.shape, r.predictions.shape, bool(np.all(r.kkt_gap < 1e-3))
    ((2,), (2, 60), True)
    """
    lo = _Batch(features_low, "features_low")
    hi = _Batch(features_high, "features_high")
    if lo.shape[0] != hi.shape[0] or lo.shape[2] != hi.shape[2]:
        raise InputError(f"features_low {lo.shape} and features_high {hi.shape} must have the same batch "
                         "size and feature count")
    B, n_lo, d = lo.shape
    n_hi = hi.shape[1]
    seeds = list(seeds)
    if len(seeds) != B:
        raise InputError(f"need one seed per pair: {B} pairs, {len(seeds)} seeds")
    folds = _check_folds(folds, min(n_lo, n_hi))
    if gram_dtype not in ("float32", "float64"):
        raise InputError(f"gram_dtype must be 'float32' or 'float64', got {gram_dtype!r}")
    chunk_size = max(1, int(chunk_size))

    clock = _Clock(timings)
    n = n_lo + n_hi
    alloc = _allocation(n_lo, n_hi, folds)  # (folds, 2) test touches per class
    legacy = np.random.RandomState(0)  # re-seeded for each pair: this call's own, never shared
    test_folds = np.stack([stratified_test_folds(n_lo, n_hi, s, folds, _legacy=legacy) for s in seeds])  # (B, n)
    # Rows of each pair in fold-block order: block f = [low test touches of f, high test touches of f].
    order_lo = np.argsort(test_folds[:, :n_lo], axis=1, kind="stable")
    order_hi = np.argsort(test_folds[:, n_lo:], axis=1, kind="stable")
    blk_lo = np.r_[0, np.cumsum(alloc[:, 0])]
    blk_hi = np.r_[0, np.cumsum(alloc[:, 1])]
    blk_size = alloc.sum(axis=1)
    blk_start = np.r_[0, np.cumsum(blk_size)]
    clock.lap("folds")

    f1 = np.empty(B)
    fold_f1 = np.empty((B, folds))
    tp = np.zeros(B)
    fp = np.zeros(B)
    correct = np.zeros(B)
    predictions = np.empty((B, n), dtype=np.int8)
    decision = np.empty((B, n))
    kkt = np.empty((B, folds))
    solver = np.empty((B, folds), dtype=np.int64)
    iterations = np.empty((B, folds), dtype=np.int64)

    for c0 in range(0, B, chunk_size):
        c1 = min(B, c0 + chunk_size)
        ns = _namespace(xp, np.empty(0)) if xp is None or xp is np else xp
        fast = ns is np and gram_dtype == "float32"  # prepared features hold float32 deviations
        lo_c, hi_c = lo.get(c0, c1, stack=not fast), hi.get(c0, c1, stack=not fast)
        if fast:
            out = _chunk_prepared([prepare_features(x) for x in lo_c], [prepare_features(x) for x in hi_c],
                                  test_folds[c0:c1], order_lo[c0:c1], order_hi[c0:c1], alloc, blk_lo, blk_hi,
                                  folds, gram_dtype, clock)
        else:
            out = _chunk(lo_c, hi_c, order_lo[c0:c1], order_hi[c0:c1], alloc, blk_lo, blk_hi,
                         blk_start, folds, gram_dtype, ns, clock)
        del lo_c, hi_c
        dec_blocks, gaps, solv, its = out
        for f in range(folds):
            dec = dec_blocks[f]  # (b, blk_size[f]) libsvm convention, low rows then high rows
            pred_hi = dec <= 0.0  # libsvm: dec > 0 -> first (lower) label
            nl = alloc[f, 0]
            t_pos = np.sum(pred_hi[:, nl:], axis=1)  # true positives
            f_pos = np.sum(pred_hi[:, :nl], axis=1)
            f_neg = alloc[f, 1] - t_pos
            denom = 2 * t_pos + f_pos + f_neg
            fold_f1[c0:c1, f] = np.where(denom > 0, 2.0 * t_pos / np.where(denom > 0, denom, 1), 0.0)
            tp[c0:c1] += t_pos
            fp[c0:c1] += f_pos
            correct[c0:c1] += t_pos + (nl - f_pos)
            # back to input order
            r = np.arange(c1 - c0)[:, None]
            pos_lo = order_lo[c0:c1, blk_lo[f]:blk_lo[f + 1]]
            pos_hi = n_lo + order_hi[c0:c1, blk_hi[f]:blk_hi[f + 1]]
            predictions[c0 + r, pos_lo] = pred_hi[:, :nl]
            predictions[c0 + r, pos_hi] = pred_hi[:, nl:]
            decision[c0 + r, pos_lo] = -dec[:, :nl]
            decision[c0 + r, pos_hi] = -dec[:, nl:]
            kkt[c0:c1, f] = gaps[f]
            solver[c0:c1, f] = solv[f]
            iterations[c0:c1, f] = its[f]
    f1[:] = np.mean(fold_f1, axis=1)
    n_min = min(n_lo, n_hi)
    se = np.array([f1_standard_error(float(tp[b] / n_hi), float(fp[b] / n_lo), n_min) for b in range(B)])
    return BatchedF1(f1=f1, fold_f1=fold_f1, accuracy=correct / n, standard_error=se, n_per_class=n_min,
                     predictions=predictions, decision=decision, kkt_gap=kkt, solver=solver,
                     iterations=iterations)


def _to_numpy(x):
    return np.asarray(x.get() if hasattr(x, "get") else (x.cpu() if hasattr(x, "cpu") else x))


class _Clock:
    def __init__(self, timings):
        import time

        self.timings = timings
        self._now = time.process_time
        self.t = self._now() if timings is not None else 0.0

    def lap(self, name):
        if self.timings is not None:
            t = self._now()
            self.timings[name] = self.timings.get(name, 0.0) + t - self.t
            self.t = t


def _gather_centered(x, order, center, xp):
    """Rows of x (b, m, d) in the given order (b, m), minus center (b, d): a new (b, m, d) float64 array.

    With numpy, ``x`` may be a list of b (m, d) arrays (never stacked: one pass fewer).
    """
    if xp is np:  # one gather per pair into a contiguous buffer and an in-place subtraction
        b, (m, d) = len(x), x[0].shape
        out = np.empty((b, m, d))
        for k in range(b):
            np.take(x[k], order[k], axis=0, out=out[k], mode="clip")
        np.subtract(out, center[:, None, :], out=out)
        return out
    return xp.take_along_axis(x, order[:, :, None], axis=1) - center[:, None, :]


def _scaled(x, scale, dtype, out, xp):
    """out[...] = x * scale cast to dtype (in place for numpy)."""
    if xp is np:
        np.multiply(x, scale, out=out, casting="same_kind")
    else:
        out[...] = xp.astype(x * scale, dtype)


def _chunk(lo, hi, order_lo, order_hi, alloc, blk_lo, blk_hi, blk_start, folds, gram_dtype, xp, clock):
    """Decision values of every test touch of one chunk of pairs; see batched_cv_f1."""
    b, (n_lo, d), n_hi = len(lo), lo[0].shape, hi[0].shape[0]
    n = n_lo + n_hi
    f64 = xp.float64
    gdt = xp.float32 if gram_dtype == "float32" else f64
    if xp is np:  # lo, hi: (b, m, d) arrays or lists of b (m, d) arrays, gathered pair by pair
        center = (np.stack([x.sum(axis=0) for x in lo]) + np.stack([x.sum(axis=0) for x in hi])) / n
        D = (_gather_centered(lo, order_lo, center, xp), _gather_centered(hi, order_hi, center, xp))
    else:
        lo_x = xp.asarray(lo)
        hi_x = xp.asarray(hi)
        center = (xp.sum(lo_x, axis=1) + xp.sum(hi_x, axis=1)) / n  # (b, d): a shift common to all touches
        # Each class's touches in fold-block order (the test touches of fold 0 first, ...), centered.
        D = (_gather_centered(lo_x, xp.asarray(order_lo), center, xp),
             _gather_centered(hi_x, xp.asarray(order_hi), center, xp))
    blk = (blk_lo, blk_hi)

    def seg(c, g):  # class c's touches in block g
        return D[c][:, int(blk[c][g]):int(blk[c][g + 1]), :]

    # Block sums of x and x^2 (relative to the common center) give every fold's training mean and variance.
    S1 = S2 = 0.0
    for c in range(2):
        E = np.zeros((folds, D[c].shape[1]))
        for g in range(folds):
            E[g, int(blk[c][g]):int(blk[c][g + 1])] = 1.0
        E = xp.asarray(E, dtype=f64)
        S1 = S1 + E @ D[c]  # (b, folds, d)
        if xp is np:  # sums of squares per block without an (m, d) temporary: half the memory traffic
            S2 = S2 + np.stack([np.einsum("bmd,bmd->bd", seg(c, g), seg(c, g)) for g in range(folds)], axis=1)
        else:
            S2 = S2 + E @ (D[c] * D[c])
    # The Gram products read the centered touches in the Gram's precision: one cast here instead of a
    # float64 -> float32 cast in every fold's scaling (the scaled values
    # then carry two float32 roundings instead of one, relative 1e-7, far below what moves a prediction).
    D_g = D if gdt == f64 else tuple(xp.astype(x, gdt) for x in D)
    S1_all = xp.sum(S1, axis=1)
    S2_all = xp.sum(S2, axis=1)
    # a NaN or infinity anywhere in a pair's features reaches its sums (inf - inf is NaN): checked
    # here on (b, d) values instead of a pass over every feature
    if not bool(xp.all(xp.isfinite(S2_all)) and xp.all(xp.isfinite(center))):
        raise InputError("features contain NaN or infinite values")
    eps = float(np.finfo(np.float64).eps)
    clock.lap("standardize")

    dec_blocks, gaps, solv, its = [], [], [], []
    for f in range(folds):
        n_te = int(alloc[f, 0] + alloc[f, 1])
        n_tr = n - n_te
        mean_c = (S1_all - S1[:, f, :]) / n_tr  # training mean relative to the center
        var = (S2_all - S2[:, f, :]) / n_tr - mean_c * mean_c
        var = xp.where(var > 0, var, 0.0)
        mean_raw = mean_c + center
        constant = var <= n_tr * eps * var + (n_tr * mean_raw * eps) ** 2  # StandardScaler's rule
        inv_scale = xp.where(constant, 1.0, 1.0 / xp.sqrt(xp.where(constant, 1.0, var)))  # (b, d)
        inv_scale_g = xp.astype(inv_scale, gdt)[:, None, :]
        # training touches of fold f: the other blocks, each as [lower class, higher class]
        parts = [(c, g) for g in range(folds) if g != f for c in range(2)]
        Z = xp.empty((b, n_tr, d), dtype=gdt)
        y = []
        r = 0
        for c, g in parts:
            x = D_g[c][:, int(blk[c][g]):int(blk[c][g + 1]), :]
            m = x.shape[1]
            _scaled(x, inv_scale_g, gdt, Z[:, r:r + m, :], xp)
            r += m
            y += [1.0 if c == 0 else -1.0] * m  # libsvm: the lower class (label 0) is +1
        clock.lap("standardize")
        K = xp.astype(Z @ xp.permute_dims(Z, (0, 2, 1)), f64)
        del Z
        clock.lap("gram")
        yv = xp.asarray(y, dtype=f64)
        a, rho, info = solve_svc_duals(K, yv, xp=xp)
        clock.lap("solve")
        beta = a * yv[None, :]
        # w (in centered, scaled coordinates) = Z^T beta ; decision of a test touch x: (x * s) . w - rho
        v = xp.zeros((b, d), dtype=f64)
        r = 0
        for c, g in parts:
            x = seg(c, g)
            m = x.shape[1]
            v = v + (xp.permute_dims(x, (0, 2, 1)) @ beta[:, r:r + m, None])[..., 0]
            r += m
        u = (v * inv_scale * inv_scale)[:, :, None]
        dec = xp.concat([(seg(0, f) @ u)[..., 0], (seg(1, f) @ u)[..., 0]], axis=1) - rho[:, None]
        dec_blocks.append(_to_numpy(dec))
        gaps.append(_to_numpy(info["kkt_gap"]))
        solv.append(_to_numpy(info["solver"]))
        its.append(_to_numpy(info["iterations"]))
        clock.lap("predict")
    return dec_blocks, gaps, solv, its


def _chunk_prepared(lo, hi, test_folds, order_lo, order_hi, alloc, blk_lo, blk_hi, folds, gram_dtype, clock):
    """:func:`_chunk` on numpy from :class:`PreparedFeatures`: the same classifier, a fraction of the passes.

    Pair by pair, each class's ``dev`` rows are gathered once into one float32 array in
    fold-block order (block ``g`` = the lower class's test touches of fold ``g``, then the
    higher class's), so that every fold's training touches are one or two contiguous
    ranges in exactly the order the solver takes them, and its test touches one range.
    Then, while that array is still in the core's cache:

    - block sums of ``dev`` and ``dev^2`` (float32 sums of at most a fold of touches)
      give every fold's training mean and variance in float64, with the class offsets
      ``o_k = mean_k - c`` from the pair's center ``c`` entered exactly:
      ``sum (x - c)^2 = sum dev^2 + 2 o_k sum dev + m o_k^2``;
    - each fold's Gram matrix of ``x - c = dev + o_k`` scaled by the fold's inverse
      standard deviations ``s`` is ``(dev_a s).(dev_b s)`` (one float32 product of the
      fold's scaled training ``dev``, the only ``n x d`` array written per fold, reused
      from pair to pair so it stays in cache) plus rank-two terms of the offsets:
      ``H[a, l] = dev_a . (o_l s^2)`` (one float32 product for all folds at once) and
      ``(o_k s).(o_l s)`` exact in float64. Adding the offsets to ``dev`` in float32
      instead made the Gram matrices of well-separated classes ill-conditioned (the
      solver fell back to continuation and SMO: 25x its time at 10 s, measured);
    - after the batched solve, a test touch's decision is ``(dev + o_k) . (s^2 t) - rho`` with
      ``t = sum_a beta_a (dev_a + o_k(a))``, read from the same gathered rows.

    Engine version 2 (:data:`designkit.sweep.ENGINE_VERSION`): version 1 gathered the
    rows once more per pair, read ``dev^2`` from the prepared features and kept every
    pair's scaled training touches until the decisions.
    """
    b = len(lo)
    n_lo, d = lo[0].shape
    n_hi = hi[0].shape[0]
    n = n_lo + n_hi
    gdt = np.float32 if gram_dtype == "float32" else np.float64
    eps = float(np.finfo(np.float64).eps)
    # rows of the gathered array: block g holds [low test touches of g, high test touches of g]
    cnt = np.stack([alloc[:, 0], alloc[:, 1]], axis=1).reshape(-1)  # (2 folds,): class-0 block 0, class-1 block 0, ...
    seg_start = np.r_[0, np.cumsum(cnt)]
    blk_start = seg_start[::2]  # start of each fold block; blk_start[folds] = n
    cls_seg = np.tile([0, 1], folds)
    cnt_f = cnt.astype(np.float64)[:, None]
    X = np.empty((b, n, d), dtype=gdt)  # x - c of every touch of each pair, in fold-block order
    inv_scale = np.empty((b, folds, d))
    n_tr = [n - int(alloc[f].sum()) for f in range(folds)]
    K = [np.empty((b, m, m)) for m in n_tr]
    Z = np.empty((max(n_tr), d), dtype=gdt)  # one pair's scaled training touches, reused: stays in cache
    row_cls = np.repeat(cls_seg, cnt)  # class of each row in fold-block order
    Hs = np.empty((b, n, folds, 2))
    VVs = np.empty((b, folds, 2, 2))
    offs_pair = []  # (2, d) class offsets of each pair, float64
    for p in range(b):
        Xp = X[p]
        c = (n_lo * lo[p].mean + n_hi * hi[p].mean) / n
        offs = (lo[p].mean - c, hi[p].mean - c)
        for k, (src, order, blk) in enumerate(((lo[p], order_lo[p], blk_lo), (hi[p], order_hi[p], blk_hi))):
            for g in range(folds):
                r0 = seg_start[2 * g + k]
                np.take(src.dev, order[blk[g]:blk[g + 1]], axis=0, out=Xp[r0:r0 + cnt[2 * g + k]], mode="clip")
        # (2 folds, d): sums of dev and dev^2 per class and block, row by row in float32 (numpy's own loops:
        # 2.8x less time than an indicator product and a squared copy at 4,000 features, measured)
        segs_p = [Xp[seg_start[i]:seg_start[i + 1]] for i in range(2 * folds)]
        s1 = np.stack([x.sum(axis=0) for x in segs_p]).astype(np.float64)
        s2 = np.stack([np.einsum("ij,ij->j", x, x) for x in segs_p]).astype(np.float64)
        if not np.all(np.isfinite(s2)):  # an infinite deviation (beyond float32's range) reaches its block's sum
            raise InputError("features contain NaN or infinite values")
        o = np.stack(offs)[cls_seg]  # (2 folds, d)
        S1 = (s1 + cnt_f * o).reshape(folds, 2, d).sum(axis=1)  # (folds, d): each block's sum of x - c
        S2 = (s2 + 2.0 * o * s1 + cnt_f * o * o).reshape(folds, 2, d).sum(axis=1)
        n_f = np.asarray(n_tr, dtype=np.float64)[:, None]
        mean_c = (S1.sum(axis=0) - S1) / n_f  # (folds, d): training mean of each fold, relative to c
        var = np.maximum((S2.sum(axis=0) - S2) / n_f - mean_c * mean_c, 0.0)
        constant = var <= n_f * eps * var + (n_f * (mean_c + c) * eps) ** 2  # StandardScaler's rule
        inv_scale[p] = np.where(constant, 1.0, 1.0 / np.sqrt(np.where(constant, 1.0, var)))
        # the offsets' terms of every fold's Gram matrix, K_ab += H[a, k(b)] + H[b, k(a)] + VV[k(a), k(b)]:
        # H[a, (f, l)] = (dev_a s_f) . (o_l s_f), one product for all folds; VV exact in float64
        s_sq = inv_scale[p] * inv_scale[p]  # (folds, d)
        o2 = np.stack(offs)  # (2, d)
        W = (s_sq[:, None, :] * o2[None, :, :]).reshape(2 * folds, d)
        Hs[p] = (Xp @ W.astype(gdt).T).reshape(n, folds, 2)
        VVs[p] = np.einsum("fd,kd,ld->fkl", s_sq, o2, o2)
        offs_pair.append(o2)
        clock.lap("standardize")
        s_g = inv_scale[p].astype(gdt)
        for f in range(folds):
            Zf = Z[:n_tr[f]]
            r = 0
            for r0, r1 in _train_ranges(blk_start, f):
                np.multiply(Xp[r0:r1], s_g[f], out=Zf[r:r + r1 - r0])
                r += r1 - r0
            clock.lap("standardize")
            np.matmul(Zf, Zf.T, out=K[f][p], casting="same_kind")
            clock.lap("gram")
    # the offsets' terms, K_ab += H[a, k(b)] + H[b, k(a)] + VV[k(a), k(b)] = w_a M w_b with
    # w_a = (H[a, 0], H[a, 1], [k(a) = 0], [k(a) = 1]) and M = [[0, I], [I, VV]]: one small product per fold
    train_rows = [np.concatenate([np.arange(r0, r1) for r0, r1 in _train_ranges(blk_start, f)]) for f in range(folds)]
    for f, rows in enumerate(train_rows):
        w = np.empty((b, rows.size, 4))
        w[:, :, :2] = Hs[:, rows, f, :]
        w[:, :, 2:] = np.eye(2)[row_cls[rows]]
        M = np.zeros((b, 4, 4))
        M[:, :2, 2:] = M[:, 2:, :2] = np.eye(2)
        M[:, 2:, 2:] = VVs[:, f]
        K[f] += (w @ M) @ np.swapaxes(w, 1, 2)
    clock.lap("gram")

    # Each fold's duals from the all-free start. Guessing a fold's active set from the folds solved before
    # (its training touches' states, the margins of the touches it had tested) took more linear solves, not
    # fewer: 315 against 301 at 2 s of contact, 220 against 206 at 10 s (96 problems each, measured).
    dec_blocks, gaps, solv, its = [], [], [], []
    for f, rows in enumerate(train_rows):
        yv = np.where(row_cls[rows] == 0, 1.0, -1.0)  # libsvm: the lower class is +1
        a, rho, info = solve_svc_duals(K[f], yv, xp=np)
        clock.lap("solve")
        beta = a * yv[None, :]
        beta_g = beta.astype(gdt)
        Bk = np.stack([beta[:, yv > 0].sum(axis=1), beta[:, yv < 0].sum(axis=1)], axis=1)  # (b, 2)
        t0, t1 = int(blk_start[f]), int(blk_start[f + 1])
        test_cls = row_cls[t0:t1]
        dec = np.empty((b, t1 - t0))
        for p in range(b):
            # t = sum_a beta_a (dev_a + o_k(a)) in unscaled coordinates; the decision of x is (x - c) . (s^2 t)
            # (matrix-vector products over each range of rows: one product of a few columns for every fold
            # at once packs X first, 1.5x the predict stage's CPU at 10 s, measured)
            t = np.zeros(d, dtype=gdt)
            r = 0
            for r0, r1 in _train_ranges(blk_start, f):
                t += beta_g[p, r:r + r1 - r0] @ X[p, r0:r1]
                r += r1 - r0
            u64 = inv_scale[p, f] * inv_scale[p, f] * (t.astype(np.float64) + Bk[p] @ offs_pair[p])
            dec[p] = (X[p, t0:t1] @ u64.astype(gdt)).astype(np.float64) + (offs_pair[p] @ u64)[test_cls]
        dec_blocks.append(dec - rho[:, None])
        gaps.append(info["kkt_gap"])
        solv.append(info["solver"])
        its.append(info["iterations"])
        clock.lap("predict")
    return dec_blocks, gaps, solv, its


def _train_ranges(blk_start, f: int) -> list[tuple[int, int]]:
    """Row ranges of fold ``f``'s training touches in fold-block order: every block but ``f``, merged."""
    out = []
    for g in range(len(blk_start) - 1):
        if g == f:
            continue
        r0, r1 = int(blk_start[g]), int(blk_start[g + 1])
        if out and out[-1][1] == r0:
            out[-1] = (out[-1][0], r1)
        else:
            out.append((r0, r1))
    return out
