"""Diffuse recursive least squares for non-stationary autoregressive angle models.

ALGORITHMS.md §3 (Skorohod 2017, *Diffuse Algorithms for Neural and Neuro-Fuzzy
Networks*), seed 000 eqs. 14–20. An angle series ``y_t`` (radians; azimuth unwrapped)
is modelled as an AR(p) process with slowly varying parameters (§3.1):

    y_t = H_t θ + e_t,    H_t = [y_{t-1}, …, y_{t-p}, (1)],   θ = [a_1, …, a_p, (c)]

θ is estimated by the diffuse recursion (seed eqs. 14–16, §3.2):

    W_0 = 0,  θ_0 = 0
    W_t = λ W_{t-1} + H_tᵀ H_t
    K_t = W_t⁺ H_tᵀ
    θ_t = θ_{t-1} + K_t (y_t − H_t θ_{t-1})

or by its sliding-window form (seed eqs. 17–19, §3.3), and the filtered angle and the
multi-step forecast come from running the AR model (seed eq. 20, §3.4).

Implementation (the choice §3.3 asks for, and why)
--------------------------------------------------
With θ_0 = 0 the recursion's θ_t is exactly the minimum-norm weighted least-squares
solution ``argmin ‖θ‖ over argmin Σ_s λ^(t-s) (y_s − H_s θ)²`` (§3.2), including the
rank-deficient start. Neither the Meyer rank-one pseudo-inverse update nor
``pinv(W_t)`` is used here. Both work on W = AᵀA (A the weighted stacked regressor
matrix), whose condition number is the *square* of A's, and a relative threshold on
W's eigenvalues is not the threshold that ``lstsq`` applies to A's singular values.
Instead we keep the **square-root information form**: an upper-triangular R_t and a
vector z_t with

    R_tᵀ R_t = W_t,      R_tᵀ z_t = b_t = Σ_s λ^(t-s) H_sᵀ y_s,

updated per sample by ``R ← √λ R`` plus one sweep of Givens rotations that takes in the
row (H_t, y_t): O(n²), no loss of symmetry or definiteness. R_t = Q_tᵀ A_t, so R_t has
exactly the singular values of A_t. The min-norm solution of ``R_t θ = z_t`` with a
relative cut-off ``rcond`` is therefore ``np.linalg.lstsq(A_t, y_t, rcond)`` up to
rounding, with the *same* rank decision, and it is θ_t of eqs. 14–16 (the tests check
both references to 1e-9). On a near-constant angle series (§3.5) with cond(A) ≈ 1e5
it stays within 1e-11 of ``lstsq``. There the literal pinv(W) recursion, with
cond(W) ≈ 1e10, loses a direction and is off by ~40 %. Per step: if the cheap bound
``‖R‖_F ‖R⁻¹‖_F ≥ cond(R)`` certifies that no singular value falls below
``rcond·σ_max``, θ comes from back substitution (O(n²)). Otherwise (the diffuse start
or a poorly excited stretch) a small n×n one-sided Jacobi SVD gives the truncated
min-norm solution. That makes the two phases of §3.3, chosen by the numerical rank,
with none of the gain-form round-off. The sliding window (§3.3) assembles the
window's exact factor from two stacks of such factors (see ``_window_update``), in
O(n³) per step and without down-dating, and uses the same solver.

Wind-up guard (§3.5): with λ < 1 and poor excitation, the information in unexcited
directions decays like λ^t. ``DiffuseRLS`` with ``floor > 0`` and λ < 1 solves, once W
has reached full rank, the Tikhonov-floored system ``(W_t + δ_t I) θ = b_t`` with
``δ_t = floor · tr(W_t) / n`` (§3.5). This keeps every direction's information at or
above δ_t, so a few poorly excited samples cannot throw θ far away. It changes θ
noticeably only along directions whose information is below ~``floor`` times the
mean. ``floor = 0`` gives the exact min-norm estimate.

Numba kernels run both the per-sample ``update`` (a few µs per call) and the whole-series
``filter``, which loops over any number of leading batch axes (Monte-Carlo runs) in
compiled code.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from seawatch._validation import FloatArray, as_float_array, in_range, positive
from seawatch.models.angles import wrap_angle

__all__ = [
    "DiffuseRLS",
    "DiffuseRLSBank",
    "DiffuseRLSResult",
    "SlidingWindowDiffuseRLS",
    "ar_is_stable",
    "unwrap_step",
    "wrap_angle",
]

_PI = math.pi
_TWO_PI = 2.0 * math.pi

# --- layout of the configuration vector ``cfg`` -------------------------------------------
_C_P = 0  # AR order p
_C_N = 1  # number of parameters n = p + intercept
_C_INTERCEPT = 2
_C_INCR = 3  # model increments dy_t instead of y_t
_C_MODEL = 4  # filtered="model" (seed eq. 20, first line) instead of "fitted"
_C_LAM = 5  # forgetting factor λ
_C_RCOND = 6  # relative singular-value cut-off
_C_FLOOR = 7  # relative Tikhonov floor against wind-up (growing memory only)
_C_WINDOW = 8  # sliding-window length M in samples; 0 = growing memory
_C_ANGLE = 9  # unwrap the input, wrap outputs to (-π, π]
_C_MARGIN = 10  # AR root modulus allowed above 1 before a forecast counts as unstable
_C_SIZE = 11

# --- layout of the scalar state vector ``st`` ---------------------------------------------
_S_NS = 0  # samples processed
_S_NX = 1  # valid entries in the history buffers
_S_YEFF = 2  # last effective level (measured, or predicted when missing), unwrapped
_S_STARTED = 3  # a finite sample has been seen
_S_FILT = 4  # last filtered level, unwrapped
_S_MLEVEL = 5  # level of the model form (filtered="model")
_S_RANK = 6  # numerical rank of the information matrix
_S_EVER = 7  # full rank reached at least once
_S_NPUSH = 8  # modelled values pushed so far (buffer time of the newest is NPUSH − 1)
_S_F0 = 9  # sliding window: first buffer time of the front (suffix) stack
_S_B0 = 10  # sliding window: first buffer time of the back (prefix) stack
_S_SIZE = 11


# ==========================================================================================
# compiled kernels
# ==========================================================================================


@njit(cache=True)
def _wrap(v: float) -> float:
    """Wrap an angle to (-π, π]."""
    return _PI - ((_PI - v) % _TWO_PI)


@njit(cache=True)
def _wrap_all(values: FloatArray) -> None:
    """Wrap every entry of a 1-D array to (-π, π], in place."""
    for i in range(values.shape[0]):
        values[i] = _wrap(values[i])


@njit(cache=True)
def _push(buf: FloatArray, v: float) -> None:
    """Shift the history buffer left by one and append ``v`` (newest last)."""
    m = buf.shape[0]
    for i in range(m - 1):
        buf[i] = buf[i + 1]
    buf[m - 1] = v


@njit(cache=True)
def _add_row(R: FloatArray, z: FloatArray, h: FloatArray, y: float) -> None:
    """Take the row (h, y) into the square-root information pair (R, z): Givens sweep.

    Afterwards R_newᵀ R_new = Rᵀ R + hᵀ h and R_newᵀ z_new = Rᵀ z + hᵀ y; ``h`` is
    overwritten.
    """
    n = R.shape[0]
    for k in range(n):
        hk = h[k]
        if hk == 0.0:
            continue
        rkk = R[k, k]
        r = math.hypot(rkk, hk)
        c = rkk / r
        s = hk / r
        R[k, k] = r
        for j in range(k + 1, n):
            rkj = R[k, j]
            hj = h[j]
            R[k, j] = c * rkj + s * hj
            h[j] = c * hj - s * rkj
        zk = z[k]
        z[k] = c * zk + s * y
        y = c * y - s * zk


@njit(cache=True)
def _back_substitute(R: FloatArray, z: FloatArray, theta: FloatArray) -> None:
    n = R.shape[0]
    for i in range(n - 1, -1, -1):
        acc = z[i]
        for k in range(i + 1, n):
            acc -= R[i, k] * theta[k]
        theta[i] = acc / R[i, i]


@njit(cache=True)
def _min_norm_solve(
    R: FloatArray, z: FloatArray, theta: FloatArray, rcond: float, Rinv: FloatArray
) -> int:
    """Minimum-norm solution of R θ = z with singular values ≤ rcond·σ_max cut; returns rank.

    Equal to ``np.linalg.lstsq(R, z, rcond=rcond)`` (fast path: back substitution when
    ``‖R‖_F ‖R⁻¹‖_F < 1/rcond`` proves that every singular value exceeds the cut-off).
    """
    n = R.shape[0]
    fro2 = 0.0
    for i in range(n):
        for j in range(i, n):
            fro2 += R[i, j] * R[i, j]
    if fro2 == 0.0:
        theta.fill(0.0)
        return 0
    nonsingular = True
    for i in range(n):
        if R[i, i] == 0.0:
            nonsingular = False
    if nonsingular:
        # inverse of the upper-triangular R, column by column
        inv2 = 0.0
        for j in range(n):
            Rinv[j, j] = 1.0 / R[j, j]
            inv2 += Rinv[j, j] * Rinv[j, j]
            for i in range(j - 1, -1, -1):
                acc = 0.0
                for k in range(i + 1, j + 1):
                    acc += R[i, k] * Rinv[k, j]
                Rinv[i, j] = -acc / R[i, i]
                inv2 += Rinv[i, j] * Rinv[i, j]
        if math.sqrt(fro2 * inv2) * rcond < 1.0:
            _back_substitute(R, z, theta)
            return n
    # truncated SVD solve; one-sided Jacobi on a copy (Rinv is free here): R V = A, with
    # columns A_i = σ_i u_i, so θ = Σ_{σ_i > cut} v_i (A_iᵀ z) / σ_i²
    A = Rinv
    for i in range(n):
        for j in range(n):
            A[i, j] = R[i, j]
    V = np.zeros((n, n))
    for i in range(n):
        V[i, i] = 1.0
    sig2 = _jacobi_svd(A, V)
    smax2 = 0.0
    for i in range(n):
        smax2 = max(smax2, sig2[i])
    cut2 = rcond * rcond * smax2
    theta.fill(0.0)
    rank = 0
    for i in range(n):
        if sig2[i] > cut2:
            rank += 1
            coef = 0.0
            for k in range(n):
                coef += A[k, i] * z[k]
            coef /= sig2[i]
            for k in range(n):
                theta[k] += coef * V[k, i]
    return rank


@njit(cache=True)
def _jacobi_svd(A: FloatArray, V: FloatArray) -> FloatArray:
    """One-sided (Hestenes) Jacobi SVD of a small square A, in place; returns σ_i².

    On return the columns of A are orthogonal, A_new = A_old V with V orthogonal, and
    σ_i² = ‖A_new[:, i]‖². Accurate to ~eps·σ_max for every singular value; a handful of
    sweeps for n ≤ 11. (Written out so the kernels need no LAPACK, which also cuts the
    numba compile time.)
    """
    n = A.shape[0]
    tol = n * 2.220446049250313e-16
    for _sweep in range(100):
        rotated = False
        for i in range(n - 1):
            for j in range(i + 1, n):
                alpha = 0.0
                beta = 0.0
                gamma = 0.0
                for k in range(n):
                    alpha += A[k, i] * A[k, i]
                    beta += A[k, j] * A[k, j]
                    gamma += A[k, i] * A[k, j]
                if gamma == 0.0 or abs(gamma) <= tol * math.sqrt(alpha * beta):
                    continue
                rotated = True
                zeta = (beta - alpha) / (2.0 * gamma)
                t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                c = 1.0 / math.sqrt(1.0 + t * t)
                s = c * t
                for k in range(n):
                    ai = A[k, i]
                    aj = A[k, j]
                    A[k, i] = c * ai - s * aj
                    A[k, j] = s * ai + c * aj
                    vi = V[k, i]
                    vj = V[k, j]
                    V[k, i] = c * vi - s * vj
                    V[k, j] = s * vi + c * vj
        if not rotated:
            break
    sig2 = np.zeros(n)
    for i in range(n):
        acc = 0.0
        for k in range(n):
            acc += A[k, i] * A[k, i]
        sig2[i] = acc
    return sig2


@njit(cache=True)
def _ridge_solve(
    R: FloatArray,
    z: FloatArray,
    delta: float,
    theta: FloatArray,
    Ra: FloatArray,
    za: FloatArray,
    h: FloatArray,
) -> None:
    """θ = (RᵀR + δ I)⁻¹ Rᵀ z via the stacked system [R; √δ I] θ ≈ [z; 0] (QR, no squaring)."""
    n = R.shape[0]
    for i in range(n):
        za[i] = z[i]
        for j in range(n):
            Ra[i, j] = R[i, j]
    sd = math.sqrt(delta)
    for i in range(n):
        h.fill(0.0)
        h[i] = sd
        _add_row(Ra, za, h, 0.0)
    _back_substitute(Ra, za, theta)


@njit(cache=True)
def _ar_stable(theta: FloatArray, p: int, margin: float, alpha: FloatArray) -> bool:
    """All roots of z^p − a_1 z^(p−1) − … − a_p have modulus < 1 + margin (Schur–Cohn).

    Step-down (reverse Levinson) recursion on A(z) = 1 − Σ (a_i / ρ^i) z^(−i), ρ = 1 +
    margin: stable iff every reflection coefficient has modulus < 1. O(p²), no LAPACK.
    """
    rho = 1.0 + margin
    scale = 1.0
    for i in range(p):
        scale /= rho
        alpha[i] = -theta[i] * scale
    for m in range(p, 0, -1):
        k = alpha[m - 1]
        if not (abs(k) < 1.0):
            return False
        if m > 1:
            d = 1.0 - k * k
            # α_i ← (α_i − k α_{m−i}) / (1 − k²), i = 1..m−1, done pairwise in place
            for i in range((m - 1 + 1) // 2):
                lo = alpha[i]
                hi = alpha[m - 2 - i]
                alpha[i] = (lo - k * hi) / d
                if m - 2 - i != i:
                    alpha[m - 2 - i] = (hi - k * lo) / d
    return True


@njit(cache=True)
def _window_update(
    cfg: FloatArray,
    row: bool,
    h: FloatArray,
    x: float,
    xbuf: FloatArray,
    rbuf: FloatArray,
    st: FloatArray,
    R: FloatArray,
    z: FloatArray,
    theta: FloatArray,
    sr: FloatArray,
    sz: FloatArray,
    hc: FloatArray,
    Rinv: FloatArray,
) -> int:
    """Sliding window, seed eqs. 17–19: θ_t from the rows of buffer times t−M+1..t only.

    The window's square-root information factor is assembled without down-dating
    (which loses definiteness, §3.3) by the two-stack method. The rows are split at a
    boundary B0 into a *back* factor (rows B0..t, kept by adding each new row, weights
    λ^(t−s)) and a *front* of suffix factors ``sr[k]`` (rows F0+k..B0−1, built once,
    backwards, when the window start reaches B0, i.e. every M samples). The window
    factor is the back factor merged with one scaled suffix factor by Givens rotations:
    O(n³) per sample plus O(n²) amortised, instead of O(M n²) for a rebuild. It equals
    the QR factor of the window's weighted stacked rows, so θ is
    ``lstsq(window rows, rcond)``. Returns the rank, or −1 when ``row`` is False (θ
    held).
    """
    p = int(cfg[_C_P])
    n = int(cfg[_C_N])
    intercept = cfg[_C_INTERCEPT] > 0.0
    lam = cfg[_C_LAM]
    window = int(cfg[_C_WINDOW])
    t = int(st[_S_NPUSH]) - 1
    PR = sr[window]
    Pz = sz[window]
    sl = math.sqrt(lam)
    if lam < 1.0:
        for i in range(n):
            Pz[i] *= sl
            for j in range(i, n):
                PR[i, j] *= sl
    if row:
        for i in range(n):
            hc[i] = h[i]
        _add_row(PR, Pz, hc, x)
    F0 = int(st[_S_F0])
    B0 = int(st[_S_B0])
    w0 = t - window + 1  # buffer time of the oldest row in the window
    if w0 == B0:
        # the window is exactly the back stack: turn it into the front's suffix factors
        m = xbuf.shape[0]
        w = 1.0
        for s in range(t, B0 - 1, -1):
            k = s - B0
            for i in range(n):
                sz[k, i] = 0.0 if s == t else sz[k + 1, i]
                for c in range(n):
                    sr[k, i, c] = 0.0 if s == t else sr[k + 1, i, c]
            j = m - 1 - (t - s)
            if rbuf[j] > 0.0:
                for i in range(p):
                    hc[i] = w * xbuf[j - 1 - i]
                if intercept:
                    hc[p] = w
                _add_row(sr[k], sz[k], hc, w * xbuf[j])
            w *= sl
        F0 = B0
        B0 = t + 1
        for i in range(n):
            Pz[i] = 0.0
            for c in range(n):
                PR[i, c] = 0.0
        st[_S_F0] = F0
        st[_S_B0] = B0
    if not row:
        return -1
    for i in range(n):
        z[i] = Pz[i]
        for j in range(n):
            R[i, j] = PR[i, j]
    if B0 > F0:
        k = w0 - F0
        sc = sl ** (t - B0 + 1)  # front weights are relative to time B0 − 1
        for i in range(n):
            for c in range(i):
                hc[c] = 0.0
            for c in range(i, n):
                hc[c] = sc * sr[k, i, c]
            _add_row(R, z, hc, sc * sz[k, i])
    return _min_norm_solve(R, z, theta, cfg[_C_RCOND], Rinv)


@njit(cache=True)
def _step(
    y: float,
    cfg: FloatArray,
    R: FloatArray,
    z: FloatArray,
    theta: FloatArray,
    xbuf: FloatArray,
    rbuf: FloatArray,
    mbuf: FloatArray,
    st: FloatArray,
    wv: FloatArray,
    wm: FloatArray,
    sr: FloatArray,
    sz: FloatArray,
) -> float:
    """Process one sample; returns the filtered level (unwrapped). NaN y = missing."""
    p = int(cfg[_C_P])
    n = int(cfg[_C_N])
    intercept = cfg[_C_INTERCEPT] > 0.0
    incr = cfg[_C_INCR] > 0.0
    model = cfg[_C_MODEL] > 0.0
    lam = cfg[_C_LAM]
    rcond = cfg[_C_RCOND]
    floor = cfg[_C_FLOOR]
    window = int(cfg[_C_WINDOW])
    angle = cfg[_C_ANGLE] > 0.0
    m = xbuf.shape[0]
    h = wv[0:n]
    hc = wv[n : 2 * n]
    za = wv[2 * n : 3 * n]
    Rinv = wm[0]
    Ra = wm[1]

    st[_S_NS] += 1.0
    measured = math.isfinite(y)
    if st[_S_STARTED] == 0.0:
        if not measured:
            return np.nan  # nothing has been observed yet: no estimate exists
        st[_S_STARTED] = 1.0
        st[_S_YEFF] = y
        st[_S_MLEVEL] = y
        st[_S_FILT] = y
        if not incr:
            _push(xbuf, y)
            _push(rbuf, 0.0)
            _push(mbuf, y)
            st[_S_NX] = 1.0
            st[_S_NPUSH] = 1.0
        return y

    yeff_old = st[_S_YEFF]
    if measured and angle:
        # incremental unwrapping: the branch closest to the last effective level
        d = y - yeff_old
        y = yeff_old + d - _TWO_PI * math.floor((d + _PI) / _TWO_PI)
    nx = int(st[_S_NX])
    have_reg = nx >= p
    if have_reg:
        for i in range(p):
            h[i] = xbuf[m - 1 - i]
        if intercept:
            h[p] = 1.0
    rank = int(st[_S_RANK])

    # forgetting is per time step (weights λ^(t−s)); θ is invariant to a common scale
    if window == 0 and lam < 1.0:
        sl = math.sqrt(lam)
        for i in range(n):
            z[i] *= sl
            for j in range(i, n):
                R[i, j] *= sl

    # modelled value x_t: measured, or the one-step prediction when missing
    if measured:
        x = y - yeff_old if incr else y
    elif have_reg and rank > 0:
        x = 0.0
        for i in range(n):
            x += h[i] * theta[i]
    elif nx > 0:
        x = xbuf[m - 1]  # persistence before any parameter exists
    else:
        x = 0.0  # increments, none seen yet: hold the level

    row = measured and have_reg
    if row and window == 0:
        for i in range(n):
            hc[i] = h[i]
        _add_row(R, z, hc, x)
        rank = _min_norm_solve(R, z, theta, rcond, Rinv)
        if rank == n:
            st[_S_EVER] = 1.0
        if floor > 0.0 and lam < 1.0 and st[_S_EVER] > 0.0:
            tr = 0.0
            for i in range(n):
                for j in range(i, n):
                    tr += R[i, j] * R[i, j]
            _ridge_solve(R, z, floor * tr / n, theta, Ra, za, hc)
    _push(xbuf, x)
    _push(rbuf, 1.0 if row else 0.0)
    st[_S_NPUSH] += 1.0
    if window > 0:
        r = _window_update(cfg, row, h, x, xbuf, rbuf, st, R, z, theta, sr, sz, hc, Rinv)
        if r >= 0:
            rank = r
            if rank == n:
                st[_S_EVER] = 1.0

    ever = st[_S_EVER] > 0.0
    if model:
        # seed eq. 20 (first line): the fitted model run on its own past estimates
        if ever and have_reg:
            xm = theta[p] if intercept else 0.0
            for i in range(p):
                xm += theta[i] * mbuf[m - 1 - i]
        else:
            xm = x
        _push(mbuf, xm)
        if incr:
            level = st[_S_MLEVEL] + xm if ever else yeff_old + x
        else:
            level = xm
        st[_S_MLEVEL] = level
    else:
        if have_reg and rank > 0:
            xf = 0.0
            for i in range(n):
                xf += h[i] * theta[i]
        else:
            xf = x
        level = yeff_old + xf if incr else xf
    st[_S_YEFF] = yeff_old + x if incr else x
    st[_S_NX] = min(nx + 1, m)
    st[_S_RANK] = rank
    st[_S_FILT] = level
    return level


@njit(cache=True)
def _forecast(
    cfg: FloatArray,
    theta: FloatArray,
    xbuf: FloatArray,
    mbuf: FloatArray,
    st: FloatArray,
    out: FloatArray,
    wv: FloatArray,
) -> bool:
    """Seed eq. 20: iterate the AR model ``len(out)`` steps ahead; returns AR stability.

    Unstable (a root of modulus ≥ 1 + margin), or no parameters yet: constant-rate
    extrapolation with the mean increment of the last p samples. Outputs are levels,
    unwrapped.
    """
    steps = out.shape[0]
    if st[_S_STARTED] == 0.0:
        out.fill(np.nan)
        return False
    p = int(cfg[_C_P])
    intercept = cfg[_C_INTERCEPT] > 0.0
    incr = cfg[_C_INCR] > 0.0
    model = cfg[_C_MODEL] > 0.0
    margin = cfg[_C_MARGIN]
    buf = mbuf if model else xbuf
    level = st[_S_MLEVEL] if model else st[_S_YEFF]
    m = buf.shape[0]
    nx = int(st[_S_NX])
    lags = wv[0:p]
    alpha = wv[p : 2 * p]
    stable = int(st[_S_RANK]) > 0 and nx >= p and _ar_stable(theta, p, margin, alpha)
    if stable:
        c = theta[p] if intercept else 0.0
        for i in range(p):
            lags[i] = buf[m - 1 - i]
        for j in range(steps):
            v = c
            for i in range(p):
                v += theta[i] * lags[i]
            for i in range(p - 1, 0, -1):
                lags[i] = lags[i - 1]
            lags[0] = v
            if incr:
                level += v
                out[j] = level
            else:
                out[j] = v
        return True
    rate = 0.0
    if incr:
        k = min(p, nx)
        for i in range(k):
            rate += buf[m - 1 - i]
        if k > 0:
            rate /= k
    else:
        k = min(p, nx - 1)
        if k > 0:
            rate = (buf[m - 1] - buf[m - 1 - k]) / k
    for j in range(steps):
        out[j] = level + (j + 1) * rate
    return False


@njit(cache=True)
def _filter_kernel(
    ys: FloatArray,
    cfg: FloatArray,
    buf_len: int,
    filt: FloatArray,
    params: FloatArray,
    ready: NDArray[np.bool_],
    ranks: NDArray[np.int64],
    fc: FloatArray,
    fstab: NDArray[np.bool_],
) -> None:
    """Run ``_step`` (and ``_forecast`` when ``fc`` has a non-empty last axis) per batch row."""
    n_batch, n_time = ys.shape
    n = int(cfg[_C_N])
    p = int(cfg[_C_P])
    angle = cfg[_C_ANGLE] > 0.0
    horizon = fc.shape[2]
    R = np.zeros((n, n))
    z = np.zeros(n)
    theta = np.zeros(n)
    xbuf = np.zeros(buf_len)
    rbuf = np.zeros(buf_len)
    mbuf = np.zeros(buf_len)
    st = np.zeros(_S_SIZE)
    wv = np.zeros(3 * n + 2 * p)
    wm = np.zeros((2, n, n))
    sr = np.zeros((int(cfg[_C_WINDOW]) + 1, n, n))
    sz = np.zeros((int(cfg[_C_WINDOW]) + 1, n))
    for b in range(n_batch):
        R.fill(0.0)
        z.fill(0.0)
        theta.fill(0.0)
        xbuf.fill(0.0)
        rbuf.fill(0.0)
        mbuf.fill(0.0)
        st.fill(0.0)
        sr.fill(0.0)
        sz.fill(0.0)
        for t in range(n_time):
            v = _step(ys[b, t], cfg, R, z, theta, xbuf, rbuf, mbuf, st, wv, wm, sr, sz)
            filt[b, t] = _wrap(v) if angle else v
            for i in range(n):
                params[b, t, i] = theta[i]
            rk = int(st[_S_RANK])
            ranks[b, t] = rk
            ready[b, t] = rk == n
            if horizon > 0:
                fstab[b, t] = _forecast(cfg, theta, xbuf, mbuf, st, fc[b, t], wv)
                if angle:
                    _wrap_all(fc[b, t])


# ==========================================================================================
# small public helpers
# ==========================================================================================


def unwrap_step(previous: float, angle: float) -> float:
    """Incremental ``np.unwrap``: the branch of ``angle`` nearest to the unwrapped ``previous``.

    Both in radians; returns ``angle + 2πk`` with ``|result − previous| ≤ π``
    (ALGORITHMS.md §3.5, angle wrap).
    """
    d = angle - previous
    return previous + d - 2.0 * np.pi * np.floor((d + np.pi) / (2.0 * np.pi))


def ar_is_stable(coefficients: ArrayLike, margin: float = 1e-6) -> bool:
    """True if every root of z^p − a_1 z^(p−1) − … − a_p has modulus < 1 + ``margin``.

    ``coefficients`` = [a_1, …, a_p] of y_t = Σ a_i y_{t−i} (+ c). Schur–Cohn step-down
    test (ALGORITHMS.md §3.5: check AR stability before iterating a forecast).
    """
    a = as_float_array("coefficients", coefficients, ndim=1)
    if a.size == 0:
        return True
    margin = positive("margin", margin, allow_zero=True)
    return bool(_ar_stable(a, a.size, margin, np.zeros(a.size)))


# ==========================================================================================
# public classes
# ==========================================================================================


@dataclass(frozen=True)
class DiffuseRLSResult:
    """Output of ``DiffuseRLS.filter`` / ``SlidingWindowDiffuseRLS.filter``.

    ``B...`` are the leading batch axes of the input (none for one series), ``T`` the
    samples, ``n = order + intercept`` the parameters, ``J`` the forecast horizon.
    Angles are in radians (wrapped to (−π, π] when ``angle=True``), otherwise in the
    units of the input.

    Attributes:
        filtered: filtered value at each step, (B..., T); NaN only before the first
            finite sample.
        parameters: θ_t after each step, (B..., T, n), ordered [a_1, …, a_p, (c)]
            (AR coefficients dimensionless; intercept c in the units of y, or of its
            increments with ``increments=True``; unwrapped space for angles).
        ready: the information matrix has full rank n at this step, (B..., T) bool;
            False at least during the first ``order + n − 1`` samples (one more with
            ``increments=True``), when θ is a min-norm interpolant and forecasts are
            unreliable (§3.5).
        rank: numerical rank of the information matrix, (B..., T) int.
        forecasts: with ``horizon=J``: y_hat_{t+j|t}, j = 1..J, made after each step,
            (B..., T, J); else None.
        forecast_stable: with ``horizon``: the AR forecast was stable (False: the
            constant-rate fallback was used), (B..., T) bool; else None.
    """

    filtered: FloatArray
    parameters: FloatArray
    ready: NDArray[np.bool_]
    rank: NDArray[np.int64]
    forecasts: FloatArray | None = None
    forecast_stable: NDArray[np.bool_] | None = None


def _int_at_least(name: str, value: object, lo: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{name}: expected an integer >= {lo}, got {value!r}")
    v = int(value)
    if v < lo:
        raise ValueError(f"{name}: expected an integer >= {lo}, got {v}")
    return v


def _steps(name: str, value: object) -> int:
    """A positive whole number of steps; finite integral floats are accepted."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name}: expected a positive integer, got {value!r}")
    if isinstance(value, numbers.Integral):
        v = int(value)
    else:
        f = float(value)
        if not math.isfinite(f) or f != math.floor(f):
            raise ValueError(f"{name}: expected a finite positive integer, got {value!r}")
        v = int(f)
    if v < 1:
        raise ValueError(f"{name}: expected a positive integer, got {value!r}")
    return v


class _ARFilterBase:
    """Shared machinery: configuration vector, streaming state, update/forecast/filter."""

    def __init__(
        self,
        order: int,
        forgetting: float,
        intercept: bool,
        increments: bool,
        filtered: str,
        rcond: float,
        floor: float,
        window: int,
        angle: bool,
        stability_margin: float,
    ) -> None:
        self.order = _int_at_least("order", order, 1)
        self.forgetting = in_range("forgetting", forgetting, 0.0, 1.0, lo_open=True)
        if filtered not in ("fitted", "model"):
            raise ValueError(f"filtered: expected 'fitted' or 'model', got {filtered!r}")
        self.filtered_form: Literal["fitted", "model"] = filtered  # type: ignore[assignment]
        self.rcond = in_range("rcond", rcond, 0.0, 1.0, lo_open=True, hi_open=True)
        self.intercept = bool(intercept)
        self.increments = bool(increments)
        self.angle = bool(angle)
        self.stability_margin = positive("stability_margin", stability_margin, allow_zero=True)
        self.n_params = self.order + int(self.intercept)
        cfg = np.zeros(_C_SIZE)
        cfg[_C_P] = self.order
        cfg[_C_N] = self.n_params
        cfg[_C_INTERCEPT] = float(self.intercept)
        cfg[_C_INCR] = float(self.increments)
        cfg[_C_MODEL] = float(filtered == "model")
        cfg[_C_LAM] = self.forgetting
        cfg[_C_RCOND] = self.rcond
        cfg[_C_FLOOR] = floor
        cfg[_C_WINDOW] = window
        cfg[_C_ANGLE] = float(self.angle)
        cfg[_C_MARGIN] = self.stability_margin
        self._cfg = cfg
        # history: p lags (+1 for the constant-rate fallback), plus the window
        self._buf_len = window + self.order + 1
        self.last_forecast_stable: bool | None = None
        self.reset()

    def reset(self) -> None:
        """Return to the diffuse start W = 0, θ = 0 with no samples seen."""
        n = self.n_params
        self._R = np.zeros((n, n))
        self._z = np.zeros(n)
        self._theta = np.zeros(n)
        self._xbuf = np.zeros(self._buf_len)
        self._rbuf = np.zeros(self._buf_len)
        self._mbuf = np.zeros(self._buf_len)
        self._st = np.zeros(_S_SIZE)
        self._wv = np.zeros(3 * n + 2 * self.order)
        self._wm = np.zeros((2, n, n))
        window = int(self._cfg[_C_WINDOW])
        self._sr = np.zeros((window + 1, n, n))
        self._sz = np.zeros((window + 1, n))
        self._filtered = np.nan
        self.last_forecast_stable = None

    # --- streaming -----------------------------------------------------------------------
    def update(self, y: float | None) -> float:
        """Take one sample y_t (radians for angles; NaN/None = missing); return the filtered value.

        A missing sample makes no parameter update: the filtered value is the model's
        one-step prediction, and later regressors use that prediction. Before the first
        finite sample there is nothing to estimate and NaN is returned.
        """
        if y is None:
            v = np.nan
        else:
            try:
                v = float(y)  # type: ignore[arg-type]
            except (TypeError, ValueError):
                raise ValueError(
                    f"y: expected a number (or NaN/None if missing), got {y!r}"
                ) from None
            if math.isinf(v):
                raise ValueError("y: is infinite (use NaN or None for a missing sample)")
        out = _step(
            v,
            self._cfg,
            self._R,
            self._z,
            self._theta,
            self._xbuf,
            self._rbuf,
            self._mbuf,
            self._st,
            self._wv,
            self._wm,
            self._sr,
            self._sz,
        )
        self._filtered = float(_wrap(out)) if self.angle and math.isfinite(out) else float(out)
        return self._filtered

    @property
    def theta(self) -> FloatArray:
        """Current parameters θ_t = [a_1, …, a_p, (c)] (copy); see ``DiffuseRLSResult``."""
        return self._theta.copy()

    @property
    def filtered(self) -> float:
        """Last filtered value (wrapped to (−π, π] with ``angle=True``); NaN before any data."""
        return self._filtered

    @property
    def n_samples(self) -> int:
        """Samples given to ``update`` so far, missing ones included."""
        return int(self._st[_S_NS])

    @property
    def rank(self) -> int:
        """Numerical rank of the information matrix W_t (relative cut-off ``rcond``)."""
        return int(self._st[_S_RANK])

    @property
    def ready(self) -> bool:
        """W_t has full rank: θ is determined by the data, forecasts are meaningful (§3.5)."""
        return self.rank == self.n_params

    def forecast(self, steps: int) -> FloatArray:
        """Forecast y_{t+1..t+steps} from the current state (seed eq. 20, ALGORITHMS.md §3.4).

        The AR recursion is iterated with the latest θ from the past values: measured
        (effective) for ``filtered="fitted"``, the model's own estimates for
        ``filtered="model"``. With ``increments=True`` increments are forecast and summed
        onto y_t. If an AR root has modulus ≥ 1 + ``stability_margin`` (or no parameter
        exists yet), a constant-rate extrapolation with the mean increment of the last
        ``order`` samples is returned instead, and ``last_forecast_stable`` is False.
        Shape (steps,), radians for angles (wrapped to (−π, π] with ``angle=True``);
        NaN before the first finite sample.
        """
        steps = _steps("steps", steps)
        out = np.empty(steps)
        stable = _forecast(self._cfg, self._theta, self._xbuf, self._mbuf, self._st, out, self._wv)
        self.last_forecast_stable = bool(stable)
        if self.angle:
            _wrap_all(out)
        return out

    # --- whole series --------------------------------------------------------------------
    def filter(self, ys: ArrayLike, horizon: int | None = None) -> DiffuseRLSResult:
        """Filter whole series ys (B..., T) from the diffuse start; see ``DiffuseRLSResult``.

        Every series along the leading batch axes is run independently in compiled code
        (one loop over the flattened batch, no Python per step). The streaming state of
        ``update`` is neither read nor changed. NaN samples are missing; inf is an error.
        ``horizon=J`` also stores the J-step forecast made after every step.
        """
        arr = as_float_array("ys", ys)
        if arr.ndim < 1 or arr.shape[-1] == 0:
            raise ValueError(f"ys: expected shape (T,) or (B..., T) with T >= 1, got {arr.shape}")
        if np.any(np.isinf(arr)):
            raise ValueError("ys: contains inf (use NaN for a missing sample)")
        J = 0 if horizon is None else _steps("horizon", horizon)
        batch_shape = arr.shape[:-1]
        T = arr.shape[-1]
        flat = np.ascontiguousarray(arr.reshape(-1, T))
        B = flat.shape[0]
        n = self.n_params
        filt = np.empty((B, T))
        params = np.empty((B, T, n))
        ready = np.empty((B, T), dtype=np.bool_)
        ranks = np.empty((B, T), dtype=np.int64)
        fc = np.empty((B, T, J))
        fstab = np.zeros((B, T), dtype=np.bool_)
        _filter_kernel(flat, self._cfg, self._buf_len, filt, params, ready, ranks, fc, fstab)
        return DiffuseRLSResult(
            filtered=filt.reshape(*batch_shape, T),
            parameters=params.reshape(*batch_shape, T, n),
            ready=ready.reshape(*batch_shape, T),
            rank=ranks.reshape(*batch_shape, T),
            forecasts=fc.reshape(*batch_shape, T, J) if J else None,
            forecast_stable=fstab.reshape(*batch_shape, T) if J else None,
        )


class DiffuseRLS(_ARFilterBase):
    """Diffuse RLS on an AR(p) model of a (possibly angular) series, growing memory.

    ALGORITHMS.md §3.1–3.5, seed 000 eqs. 14–16 (estimation) and eq. 20 (filtering and
    forecast). θ_t is the min-norm weighted least-squares solution over all samples so
    far with weights λ^(t−s) (exactly what eqs. 14–16 produce from W_0 = 0, θ_0 = 0);
    see the module docstring for the square-root information implementation.

    Regressors: H_t = [x_{t−1}, …, x_{t−p}, (1)] from the *measured* series x (x = y, or
    x_t = y_t − y_{t−1} with ``increments=True``); the first p values of x only fill the
    lags, so the first parameter update happens at sample p + 1 (p + 2 with increments).

    Exact recovery (the seed's claim after eq. 16): without noise, θ_t equals the true
    parameters from sample t = 2p (1-based; p = order) on, i.e. after p lag samples and
    n = p linearly independent regressor rows; with ``intercept`` n = p + 1 rows are
    needed (t = 2p + 1), with ``increments`` one sample more. This is "order + 1
    samples" only for p = 1. Before that, W is rank-deficient, θ is the min-norm
    interpolant, and ``ready`` is False.

    Args:
        order: AR order p ≥ 1 (the seed's scenario uses 5).
        forgetting: λ ∈ (0, 1], per sample (1 = no forgetting, as in the seed's
            simulation; ALGORITHMS.md suggests 0.98 for tracking).
        intercept: add the constant term c (the seed's c_0; its scenario has c_0 = 0).
        increments: model dy_t = y_t − y_{t−1} instead of y_t (better conditioned; [NEW]).
        filtered: ``"fitted"`` (default): x_hat_t = H_t θ_t with measured regressors;
            ``"model"``: seed eq. 20 first line, x_hat_t = Σ a_i x_hat_{t−i} + c, the
            fitted model run on its own past estimates (measured values until W first
            reaches full rank; with increments the model increments are summed).
            "fitted" is the default because, of the two, it is the one closer to the
            seed's Table 2. In a quick simulation of the uav-sea geometry (order 5,
            λ = 1, 100 runs of 712 steps), "fitted" gave RMS errors of 0.94′ (α) and
            0.89′ (β) for noise of 0.88′ and 1.56′; the paper has 0.57′ and 1.14′. The
            model form is a free-running simulation of a near-unit-root AR, and it
            drifted by hundreds of arc-minutes.
        rcond: relative singular-value cut-off of the weighted regressor matrix, as in
            ``np.linalg.lstsq`` (decides the rank during the diffuse phase).
        floor: relative Tikhonov floor against estimator wind-up (§3.5), used only when
            λ < 1 and once W has reached full rank: θ = (W + δ I)⁻¹ b with δ = floor ·
            tr W / n. 0 disables it (exact min-norm least squares).
        angle: the series is an angle in radians: unwrap it on input (incrementally, to
            the branch nearest the last value) and wrap outputs to (−π, π].
        stability_margin: a forecast is iterated only if every AR root has modulus
            < 1 + stability_margin; otherwise the constant-rate fallback is used.

    Units: y in radians (angles) or any unit; θ's AR part dimensionless, c in y's unit.
    """

    def __init__(
        self,
        order: int,
        forgetting: float = 1.0,
        *,
        intercept: bool = False,
        increments: bool = False,
        filtered: Literal["fitted", "model"] = "fitted",
        rcond: float = 1e-10,
        floor: float = 1e-8,
        angle: bool = False,
        stability_margin: float = 1e-6,
    ) -> None:
        floor = positive("floor", floor, allow_zero=True)
        super().__init__(
            order,
            forgetting,
            intercept,
            increments,
            filtered,
            rcond,
            floor,
            0,
            angle,
            stability_margin,
        )
        self.floor = floor


class SlidingWindowDiffuseRLS(_ARFilterBase):
    """Sliding-window diffuse RLS: the diffuse estimate restarted on the last ``window`` samples.

    ALGORITHMS.md §3.3 (sliding-window variant), seed 000 eqs. 17–19, filtering and
    forecast by eq. 20 as in ``DiffuseRLS``. At each sample t with a measurement, θ_t is
    the min-norm weighted least-squares solution (weights λ^(t−s)) over the regressor
    rows of samples s = t − window + 1 … t. That is what eqs. 17–19 give when restarted
    from W = 0, θ = 0 at the window's start. Lags may reach before the window. Missing
    samples give no row and no update (θ is held). Memory is constant: a buffer of the
    last window + order + 1 values and window + 1 triangular n×n factors. Cost per
    sample O(n³), plus O(window · n²) once every ``window`` samples.

    Args:
        order, forgetting, intercept, increments, filtered, rcond, angle,
        stability_margin: as in ``DiffuseRLS``.
        window: window length M in samples, ≥ order + 1 (the seed uses 120; §3.3
            suggests 20–50, at least 3n).

    There is no wind-up floor: the window bounds the memory.
    """

    def __init__(
        self,
        order: int,
        window: int = 120,
        forgetting: float = 1.0,
        *,
        intercept: bool = False,
        increments: bool = False,
        filtered: Literal["fitted", "model"] = "fitted",
        rcond: float = 1e-10,
        angle: bool = False,
        stability_margin: float = 1e-6,
    ) -> None:
        order = _int_at_least("order", order, 1)
        window = _int_at_least("window", window, order + 1)
        super().__init__(
            order,
            forgetting,
            intercept,
            increments,
            filtered,
            rcond,
            0.0,
            window,
            angle,
            stability_margin,
        )
        self.window = window


# ==========================================================================================
# many streams at once
# ==========================================================================================


@njit(cache=True)
def _bank_kernel(
    slots: NDArray[np.int64],
    y: FloatArray,
    missing: NDArray[np.int64],
    reset: NDArray[np.bool_],
    cfg: FloatArray,
    R: FloatArray,
    z: FloatArray,
    theta: FloatArray,
    xbuf: FloatArray,
    rbuf: FloatArray,
    mbuf: FloatArray,
    st: FloatArray,
    sr: FloatArray,
    sz: FloatArray,
    wv: FloatArray,
    wm: FloatArray,
    steps: NDArray[np.int64],
    filt: FloatArray,
    fc: FloatArray,
    fc_ok: NDArray[np.bool_],
) -> None:  # pragma: no cover - compiled
    """``DiffuseRLSBank.step``: per listed slot and channel, an optional restart, the
    missing samples, the sample, and (full rank) the forecast read at ``steps``."""
    J = 0
    for j in range(steps.shape[0]):
        J = max(J, steps[j])
    buf = np.empty(J)
    channels = cfg.shape[0]
    for i in range(slots.shape[0]):
        s = slots[i]
        ok = J > 0
        for a in range(channels):
            if reset[i]:
                R[a, s] = 0.0
                z[a, s] = 0.0
                theta[a, s] = 0.0
                xbuf[a, s] = 0.0
                rbuf[a, s] = 0.0
                mbuf[a, s] = 0.0
                st[a, s] = 0.0
                sr[a, s] = 0.0
                sz[a, s] = 0.0
            c = cfg[a]
            angle = c[_C_ANGLE] > 0.0
            for _ in range(missing[i]):
                _step(
                    np.nan, c, R[a, s], z[a, s], theta[a, s], xbuf[a, s], rbuf[a, s],
                    mbuf[a, s], st[a, s], wv, wm, sr[a, s], sz[a, s],
                )  # fmt: skip
            v = _step(
                y[i, a], c, R[a, s], z[a, s], theta[a, s], xbuf[a, s], rbuf[a, s],
                mbuf[a, s], st[a, s], wv, wm, sr[a, s], sz[a, s],
            )  # fmt: skip
            filt[i, a] = _wrap(v) if angle and math.isfinite(v) else v
            if J > 0 and int(st[a, s, _S_RANK]) == int(c[_C_N]):
                stable = _forecast(c, theta[a, s], xbuf[a, s], mbuf[a, s], st[a, s], buf, wv)
                for j in range(steps.shape[0]):
                    v = buf[steps[j] - 1]
                    fc[i, j, a] = _wrap(v) if angle else v
                ok = ok and stable
            else:
                ok = False
        fc_ok[i] = ok


_BANK_ARRAYS = ("_R", "_z", "_theta", "_xbuf", "_rbuf", "_mbuf", "_st", "_sr", "_sz")


class DiffuseRLSBank:
    """Many independent streams of diffuse-RLS AR filters, advanced by one compiled call.

    The bank has ``channels`` filter configurations, given as template filters (for
    example a track's azimuth, ``DiffuseRLS(5, angle=True)``, and its depression,
    ``DiffuseRLS(5)``), and ``slots`` streams of each. Slot s of channel c behaves
    exactly as its own copy of ``templates[c]`` fed the same samples with
    :meth:`DiffuseRLS.update` and read with :meth:`DiffuseRLS.forecast` (seed 000
    eqs. 14–16 and 20; ALGORITHMS.md §3) — the tests check it sample by sample — so a
    tracker can run one filter pair per track without a Python loop over tracks (the
    track job's world estimators do: ``seawatch.tracking.world``).

    Args:
        templates: one filter per channel; all must have the same order, intercept and
            window (the state arrays are stacked).
        slots: initial number of streams (see :meth:`grow`).
    """

    def __init__(
        self, templates: Sequence[DiffuseRLS | SlidingWindowDiffuseRLS], slots: int = 16
    ) -> None:
        if isinstance(templates, _ARFilterBase) or len(templates) == 0:
            raise ValueError("templates: expected a non-empty sequence of DiffuseRLS filters")
        for t in templates:
            if not isinstance(t, _ARFilterBase):
                raise ValueError(f"templates: expected DiffuseRLS filters, got {type(t).__name__}")
        first = templates[0]
        for t in templates[1:]:
            if (t.n_params, t._buf_len, t._cfg[_C_WINDOW]) != (
                first.n_params,
                first._buf_len,
                first._cfg[_C_WINDOW],
            ):
                raise ValueError("templates: expected the same order, intercept and window")
        self.channels = len(templates)
        self.n_params = first.n_params
        self._cfg = np.stack([t._cfg for t in templates])
        self._len = first._buf_len
        self._window = int(first._cfg[_C_WINDOW])
        n, p = self.n_params, first.order
        self._wv = np.zeros(3 * n + 2 * p)
        self._wm = np.zeros((2, n, n))
        self.slots = 0
        self.grow(_int_at_least("slots", slots, 1))

    def grow(self, slots: int) -> None:
        """Hold ``slots`` streams, keeping the existing ones (new ones at the diffuse start)."""
        size = _int_at_least("slots", slots, self.slots)
        C, n, L, w = self.channels, self.n_params, self._len, self._window + 1
        shapes = {
            "_R": (n, n),
            "_z": (n,),
            "_theta": (n,),
            "_xbuf": (L,),
            "_rbuf": (L,),
            "_mbuf": (L,),
            "_st": (_S_SIZE,),
            "_sr": (w, n, n),
            "_sz": (w, n),
        }
        for name, tail in shapes.items():
            arr = np.zeros((C, size, *tail))
            if self.slots:
                arr[:, : self.slots] = getattr(self, name)
            setattr(self, name, arr)
        self.slots = size

    def clear(self, slots: ArrayLike) -> None:
        """Return these streams to the diffuse start (:meth:`DiffuseRLS.reset`)."""
        idx = self._slots(slots)
        for name in _BANK_ARRAYS:
            getattr(self, name)[:, idx] = 0.0

    def _slots(self, slots: ArrayLike) -> NDArray[np.int64]:
        idx = np.atleast_1d(np.asarray(slots))
        if idx.ndim != 1 or (idx.size and not np.issubdtype(idx.dtype, np.integer)):
            raise ValueError(f"slots: expected a 1-D array of integer slot numbers, got {slots!r}")
        idx = idx.astype(np.int64)
        if idx.size and (idx.min() < 0 or idx.max() >= self.slots):
            raise ValueError(f"slots: expected slot numbers in 0 … {self.slots - 1}")
        if np.unique(idx).size != idx.size:
            raise ValueError("slots: expected each slot at most once per step")
        return idx

    def step(
        self,
        slots: ArrayLike,
        samples: ArrayLike,
        *,
        missing: ArrayLike | None = None,
        reset: ArrayLike | None = None,
        steps: ArrayLike = (),
    ) -> tuple[FloatArray, FloatArray, NDArray[np.bool_]]:
        """Advance the listed streams by one sample each.

        Per listed slot: restart first where ``reset`` (the diffuse start), then
        ``missing`` missing samples (each a :meth:`DiffuseRLS.update` with NaN), then the
        sample, then — where the information matrix has full rank — the AR forecast
        (seed eq. 20) read ``steps`` samples ahead.

        Args:
            slots: (k,) distinct slot numbers.
            samples: (k, channels) samples (radians for angle channels; NaN = missing).
            missing: (k,) missing samples before each sample (default 0).
            reset: (k,) restart flags (default none).
            steps: (J,) forecast lead times in samples, each ≥ 1 (default none).

        Returns:
            filtered (k, channels) levels (wrapped to (−π, π] for angle channels),
            forecasts (k, J, channels) (NaN before full rank), and (k,) flags: every
            channel's forecast exists and its AR model is stable.
        """
        idx = self._slots(slots)
        k = idx.size
        y = np.asarray(samples, dtype=np.float64)
        if y.shape != (k, self.channels):
            raise ValueError(f"samples: expected shape ({k}, {self.channels}), got {y.shape}")
        miss = np.zeros(k, np.int64) if missing is None else np.asarray(missing, np.int64)
        if miss.shape != (k,) or (k and miss.min() < 0):
            raise ValueError(f"missing: expected ({k},) counts >= 0")
        rst = np.zeros(k, np.bool_) if reset is None else np.asarray(reset, np.bool_)
        if rst.shape != (k,):
            raise ValueError(f"reset: expected ({k},) flags, got shape {rst.shape}")
        lead = np.asarray(steps, dtype=np.int64).reshape(-1)
        if lead.size and lead.min() < 1:
            raise ValueError(f"steps: expected lead times >= 1, got {steps!r}")
        filt = np.empty((k, self.channels))
        fc = np.full((k, lead.size, self.channels), np.nan)
        ok = np.zeros(k, dtype=np.bool_)
        _bank_kernel(
            idx, np.ascontiguousarray(y), miss, rst, self._cfg, self._R, self._z, self._theta,
            self._xbuf, self._rbuf, self._mbuf, self._st, self._sr, self._sz, self._wv,
            self._wm, lead, filt, fc, ok,
        )  # fmt: skip
        return filt, fc, ok
