"""Cluster-robust covariance of a least-squares fit, with touches as clusters.

Residuals of a smoothed, imperfect model are correlated along a touch, so the covariance of
an identification (:func:`~designkit.calibration.identify.identify`) is the cluster-robust
sandwich with touches as clusters, bias-reduced for few touches (CR2), and each interval takes
Student's t with that parameter's Bell-McCaffrey degrees of freedom (:func:`t_critical`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["cluster_sandwich", "t_critical"]


def cluster_sandwich(J: np.ndarray, r: np.ndarray, clusters: np.ndarray,
              df_columns: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Cluster-robust covariance (touches as clusters), bias-reduced (CR2), and each parameter's t degrees of freedom.

    ``V = B (sum_g J_g' A_g r_g r_g' A_g J_g) B`` with ``B = (J'J)^+`` and
    ``A_g = (I - H_gg)^(-1/2)``, ``H_gg = J_g B J_g'`` the touch's block of the
    hat matrix (Bell & McCaffrey, Survey Methodology 28 (2002) 169; Imbens &
    Kolesar, Rev. Econ. Stat. 98 (2016) 701): the residuals of a touch that
    weighs much in a parameter are shrunk by the fit, and ``A_g`` undoes it
    (CR2); the plain sandwich, even with the CR1 factor
    ``G/(G-1) (N-1)/(N-K)`` used before, is biased low then. Directions a touch
    determines alone (its own contact conductance, ``H_gg`` eigenvalue 1) take
    the Moore-Penrose inverse (their residual is orthogonal to them anyway).

    The degrees of freedom of parameter k's t quantile are Bell and McCaffrey's
    Satterthwaite approximation ``(sum lambda)^2 / sum lambda^2``, lambda the
    eigenvalues of ``G' G``, whose column g is ``(I - H) E_g A_g J_g B e_k``
    (``E_g`` puts touch g's rows in place; working model: white residuals). A
    parameter that a few touches carry gets few degrees of freedom, not
    touches - 1: the force-area threshold c is carried by the granite touches,
    and among them by those of extreme press speed (df about 7 of 19 in the pty
    round trips, docs/sensor-models.md). scipy and statsmodels offer only the
    CR0/CR1 sandwich; this is written out (low-rank ``H_gg``: a thin QR per
    touch, no m x m matrix).

    Parameters
    ----------
    J : ndarray, shape (N, K)
        Jacobian of the residuals at the estimate.
    r : ndarray, shape (N,)
        Residuals.
    clusters : ndarray of int, shape (N,)
        Each residual's touch.
    df_columns : int, optional
        Degrees of freedom are computed for the first ``df_columns`` parameters
        (default all); the others get ``G - 1``.

    Returns
    -------
    cov : ndarray, shape (K, K)
    df : ndarray, shape (K,)
        In ``[1, G - 1]``.

    Examples
    --------
    A mean (one column of ones) on 6 touches of 20 samples: every touch has
    leverage 1/6, so CR2 is the sum of squared touch scores times G/(G-1)
    and the degrees of freedom are G - 1 = 5 exactly.

    >>> rng = np.random.default_rng(0)
    >>> cl, r = np.repeat(np.arange(6), 20), rng.normal(size=120)
    >>> cov, df = cluster_sandwich(np.ones((120, 1)), r, cl)
    >>> sums = np.bincount(cl, weights=r)
    >>> bool(np.isclose(cov[0, 0], 6 / 5 * np.sum(sums ** 2) / 120 ** 2)), round(float(df[0]), 6)
    (True, 5.0)
    """
    n, k = J.shape
    groups, idx = np.unique(clusters, return_inverse=True)
    g_n = groups.size
    B = np.linalg.pinv(J.T @ J)
    order = np.argsort(idx, kind="stable")
    bounds = np.searchsorted(idx[order], np.arange(g_n + 1))
    scores = np.zeros((g_n, k))
    blocks = []
    for g in range(g_n):
        rows = order[bounds[g]:bounds[g + 1]]
        Jg = J[rows]
        Q, R = np.linalg.qr(Jg)                      # H_gg = Q (R B R') Q'
        lam, V = np.linalg.eigh(R @ B @ R.T)
        U = Q @ V
        one = lam > 1.0 - 1e-8
        adj = np.where(one, -1.0, 1.0 / np.sqrt(np.clip(1.0 - lam, 1e-300, None)) - 1.0)
        rg = r[rows]
        scores[g] = Jg.T @ (rg + U @ (adj * (U.T @ rg)))
        blocks.append((rows, Jg, U, adj))
    cov = B @ (scores.T @ scores) @ B
    df = np.full(k, float(max(g_n - 1, 1)))
    for j in range(k if df_columns is None else min(int(df_columns), k)):
        l = B[:, j]
        if not np.any(l):
            continue
        # G'G = W'(I - H)W = diag(w_g'w_g) - (W'J) B (J'W), column g of W being E_g A_g J_g B e_j
        diag = np.zeros(g_n)
        wj = np.zeros((g_n, k))
        for g, (rows, Jg, U, adj) in enumerate(blocks):
            w = Jg @ l
            w = w + U @ (adj * (U.T @ w))
            diag[g] = w @ w
            wj[g] = w @ Jg
        lam = np.linalg.eigvalsh(np.diag(diag) - wj @ B @ wj.T)
        lam = np.clip(lam, 0.0, None)
        if lam.sum() > 0:
            df[j] = float(np.clip(lam.sum() ** 2 / np.sum(lam ** 2), 1.0, max(g_n - 1, 1)))
    return cov, df


def t_critical(df) -> "float | np.ndarray":
    """Two-sided 95 % quantile of Student's t with ``df`` degrees of freedom (from :func:`cluster_sandwich`):
    2.36 for 7, 2.09 for 19, 1.96 in the limit.

    >>> round(float(t_critical(7)), 2)
    2.36
    """
    from scipy.stats import t

    return t.ppf(0.975, np.maximum(df, 1.0))
