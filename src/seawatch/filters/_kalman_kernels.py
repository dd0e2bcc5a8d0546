"""Compiled inner loops of the linear Kalman filter (ALGORITHMS.md §2 without fading).

Written by hand with numba because no library runs a small-matrix Kalman recursion
fast: calling LAPACK (numpy/scipy) for a 4×4 problem costs microseconds of overhead per
call, which caps a Python loop at ~20,000 steps/s (FilterPy), while these loops run a
few hundred nanoseconds per step. Every kernel works on a flat batch axis ``B``; model
matrices carry a leading axis of length 1 (shared) or ``B`` (one per track).

Kernels return ``(code, b)``: code 0 ok; ``S_NOT_PD`` the innovation covariance of
batch element ``b`` is not positive definite; ``NONFINITE`` its state became
non-finite; ``Z_INF`` its measurement holds an infinity.

Specialisation: the sizes n (state) and m (measurement) are read from the module
constants ``N_STATE``/``N_MEAS`` when they are positive. numba freezes module globals
as compile-time constants, so a copy of this module with those two lines set (made by
``seawatch.filters._kernel_cache``) compiles to fully unrolled straight-line code,
~1.5× faster than the generic loops for n = 4, m = 2. Here they are 0: generic sizes.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

N_STATE = 0  # specialised copies set this line to the state size
N_MEAS = 0  # specialised copies set this line to the measurement size

OK = 0
S_NOT_PD = 1
NONFINITE = 2
Z_INF = 3


@njit(cache=True, inline="always")
def _sel(i: int, count: int) -> int:
    return i if count > 1 else 0


@njit(cache=True, inline="always")
def _predict_one(F, Q, x, P, xp, Pp, FP):
    """x_{k|k-1} = F x, P_{k|k-1} = F P F^T + Q (symmetrised)."""
    n = N_STATE if N_STATE > 0 else x.shape[0]
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += F[i, j] * x[j]
        xp[i] = acc
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for k in range(n):
                acc += F[i, k] * P[k, j]
            FP[i, j] = acc
    for i in range(n):
        for j in range(i, n):
            acc = 0.0
            for k in range(n):
                acc += FP[i, k] * F[j, k]
            v = acc + 0.5 * (Q[i, j] + Q[j, i])
            Pp[i, j] = v
            Pp[j, i] = v


@njit(cache=True, inline="always")
def _update_one(H, R, z, x, P, xo, Po, y, S, PHt, L, K, A, AP, w):
    """Kalman update with the Joseph-form covariance; returns (code, nis).

    ``x``/``P`` are the prior, ``xo``/``Po`` receive the posterior (may alias the prior
    only for ``xo is x``; ``Po`` must differ from ``P``). A NaN in ``z`` makes the step
    predict-only (posterior = prior, y = NaN, nis = NaN); S is still computed.
    """
    n = N_STATE if N_STATE > 0 else x.shape[0]
    m = N_MEAS if N_MEAS > 0 else z.shape[0]
    # PHt = P H^T (n x m); S = H P H^T + R (m x m)
    for i in range(n):
        for j in range(m):
            acc = 0.0
            for k in range(n):
                acc += P[i, k] * H[j, k]
            PHt[i, j] = acc
    for i in range(m):
        for j in range(i, m):
            acc = 0.0
            for k in range(n):
                acc += H[i, k] * PHt[k, j]
            v = acc + 0.5 * (R[i, j] + R[j, i])
            S[i, j] = v
            S[j, i] = v
    # Cholesky S = L L^T
    for j in range(m):
        d = S[j, j]
        for k in range(j):
            d -= L[j, k] * L[j, k]
        if not d > 0.0:
            return S_NOT_PD, np.nan
        ljj = np.sqrt(d)
        L[j, j] = ljj
        for i in range(j + 1, m):
            acc = S[i, j]
            for k in range(j):
                acc -= L[i, k] * L[j, k]
            L[i, j] = acc / ljj
        for i in range(j):
            L[i, j] = 0.0
    missing = False
    for i in range(m):
        if np.isnan(z[i]):
            missing = True
        elif np.isinf(z[i]):
            return Z_INF, np.nan
    if missing:
        for i in range(m):
            y[i] = np.nan
        for i in range(n):
            xo[i] = x[i]
            for j in range(n):
                Po[i, j] = P[i, j]
        return OK, np.nan
    # innovation y = z - H x
    for i in range(m):
        acc = z[i]
        for k in range(n):
            acc -= H[i, k] * x[k]
        y[i] = acc
    # K = PHt S^-1: solve L L^T K_i^T = PHt_i^T for each row i (w: 1 / diag L)
    for i in range(m):
        w[i] = 1.0 / L[i, i]
    for r in range(n):
        for i in range(m):  # forward substitution
            acc = PHt[r, i]
            for k in range(i):
                acc -= L[i, k] * K[r, k]
            K[r, i] = acc * w[i]
        for i in range(m - 1, -1, -1):  # back substitution
            acc = K[r, i]
            for k in range(i + 1, m):
                acc -= L[k, i] * K[r, k]
            K[r, i] = acc * w[i]
    # nis = |L^-1 y|^2 (y^T S^-1 y); the forward substitution overwrites w in place
    nis = 0.0
    for i in range(m):
        acc = y[i]
        for k in range(i):
            acc -= L[i, k] * w[k]
        w[i] = acc * w[i]
        nis += w[i] * w[i]
    # state update
    for i in range(n):
        acc = x[i]
        for j in range(m):
            acc += K[i, j] * y[j]
        xo[i] = acc
    # Joseph form Po = (I - K H) P (I - K H)^T + K R K^T, evaluated as the same product
    # with A = I - K H applied by associativity: M = A P = P - K (P H^T)^T,
    # M A^T = M - (M H^T) K^T. AP holds M, A[:, :m] holds M H^T, PHt is reused for K R.
    for i in range(n):
        for j in range(n):
            acc = P[i, j]
            for k in range(m):
                acc -= K[i, k] * PHt[j, k]
            AP[i, j] = acc
    for i in range(n):
        for j in range(m):
            acc = 0.0
            for k in range(n):
                acc += AP[i, k] * H[j, k]
            A[i, j] = acc
            kr = 0.0
            for k in range(m):
                kr += K[i, k] * R[k, j]
            PHt[i, j] = kr
    for i in range(n):
        for j in range(i, n):
            acc = AP[i, j]
            for a in range(m):
                acc += (PHt[i, a] - A[i, a]) * K[j, a]
            Po[i, j] = acc
            Po[j, i] = acc
    for i in range(n):
        if not np.isfinite(xo[i]):
            return NONFINITE, np.nan
    return OK, nis


@njit(cache=True)
def predict_batch(F, Q, x, P):
    """In-place prediction of every track: x (B, n), P (B, n, n); F, Q (1 or B, n, n)."""
    B = x.shape[0]
    n = N_STATE if N_STATE > 0 else x.shape[1]
    xp = np.empty(n)
    Pp = np.empty((n, n))
    FP = np.empty((n, n))
    for b in range(B):
        _predict_one(F[_sel(b, F.shape[0])], Q[_sel(b, Q.shape[0])], x[b], P[b], xp, Pp, FP)
        x[b, :] = xp
        P[b, :, :] = Pp
        for i in range(n):
            if not np.isfinite(xp[i]):
                return NONFINITE, b
    return OK, 0


@njit(cache=True)
def update_batch(H, R, z, x, P, y, S, nis):
    """In-place update of every track: z (B, m) with NaN rows for missed measurements.

    Writes the innovation y (B, m), its covariance S (B, m, m) and the NIS (B,).
    """
    B = x.shape[0]
    n = N_STATE if N_STATE > 0 else x.shape[1]
    m = N_MEAS if N_MEAS > 0 else z.shape[1]
    PHt = np.empty((n, m))
    L = np.empty((m, m))
    K = np.empty((n, m))
    A = np.empty((n, n))
    AP = np.empty((n, n))
    Po = np.empty((n, n))
    w = np.empty(m)
    for b in range(B):
        code, v = _update_one(
            H[_sel(b, H.shape[0])], R[_sel(b, R.shape[0])], z[b], x[b], P[b], x[b], Po,
            y[b], S[b], PHt, L, K, A, AP, w,
        )  # fmt: skip
        if code != OK:
            return code, b
        P[b, :, :] = Po
        nis[b] = v
    return OK, 0


@njit(cache=True)
def _filter_track(F, H, Q, R, x0, P0, zs, xs, Ps, xps, Pps, ys, Ss, nis):
    """One track's whole sequence: predict then update at each step; returns a code."""
    T = zs.shape[0]
    n = N_STATE if N_STATE > 0 else x0.shape[0]
    m = N_MEAS if N_MEAS > 0 else zs.shape[1]
    PHt = np.empty((n, m))
    L = np.empty((m, m))
    K = np.empty((n, m))
    A = np.empty((n, n))
    AP = np.empty((n, n))
    FP = np.empty((n, n))
    w = np.empty(m)
    x = x0
    P = P0
    for t in range(T):
        _predict_one(F, Q, x, P, xps[t], Pps[t], FP)
        code, v = _update_one(
            H, R, zs[t], xps[t], Pps[t], xs[t], Ps[t], ys[t], Ss[t], PHt, L, K, A, AP, w
        )
        if code != OK:
            return code
        nis[t] = v
        x = xs[t]
        P = Ps[t]
    return OK


@njit(cache=True)
def filter_batch(F, H, Q, R, x0, P0, zs, xs, Ps, xps, Pps, ys, Ss, nis):
    """Whole sequences: for every track b and step t, predict then update.

    zs (B, T, m); outputs xs/xps (B, T, n), Ps/Pps (B, T, n, n), ys (B, T, m),
    Ss (B, T, m, m), nis (B, T). Starts from x0 (B, n), P0 (B, n, n).
    """
    for b in range(zs.shape[0]):
        code = _filter_track(
            F[_sel(b, F.shape[0])], H[_sel(b, H.shape[0])], Q[_sel(b, Q.shape[0])],
            R[_sel(b, R.shape[0])], x0[b], P0[b], zs[b], xs[b], Ps[b], xps[b], Pps[b],
            ys[b], Ss[b], nis[b],
        )  # fmt: skip
        if code != OK:
            return code, b
    return OK, 0


@njit(cache=True, parallel=True)
def filter_batch_parallel(F, H, Q, R, x0, P0, zs, xs, Ps, xps, Pps, ys, Ss, nis):
    """``filter_batch`` with the tracks spread over the CPU cores (numba prange)."""
    B = zs.shape[0]
    codes = np.zeros(B, dtype=np.int64)
    for bp in prange(B):
        b = np.int64(bp)  # prange yields unsigned indices; keep _sel's branches int64
        codes[b] = _filter_track(
            F[_sel(b, F.shape[0])], H[_sel(b, H.shape[0])], Q[_sel(b, Q.shape[0])],
            R[_sel(b, R.shape[0])], x0[b], P0[b], zs[b], xs[b], Ps[b], xps[b], Pps[b],
            ys[b], Ss[b], nis[b],
        )  # fmt: skip
    for b in range(B):
        if codes[b] != OK:
            return codes[b], b
    return OK, 0
