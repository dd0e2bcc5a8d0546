"""Strong Tracking Kalman Filter (STKF) with a single suboptimal fading factor.

ALGORITHMS.md §2; Zhou & Frank, Int. J. Control 65(2), 1996; seed 003 eqs. 11–16.

The STKF is a linear Kalman filter whose predicted covariance is inflated by a scalar
fading factor ``lambda_k >= 1`` whenever the recent innovations are larger than the
filter expects (a manoeuvre or a model error). Per step k (the order matters):

1. ``x_minus = F x_{k-1}``, pre-fit innovation ``nu_k = z_k - H x_minus``;
2. ``V_k = nu nu^T`` at the first measured step, else ``(rho V_{k-1} + nu nu^T) / (1 + rho)``;
3. ``N_k = V_k - H Q H^T - beta R_k``, ``M_k = H F P_{k-1} F^T H^T``;
4. ``lambda_k = min(lambda_max, max(1, tr N_k / tr M_k))`` (``lambda_k = 1`` if
   ``tr M_k`` is not > 1e-300);
5. ``P_minus = lambda_k F P_{k-1} F^T + Q`` (the factor multiplies only ``F P F^T``);
6. gain, state update and the Joseph-form covariance update.

``late_fading=True`` is the seed-literal variant (seed 003 eq. 11,
``P = lambda_{t-1} F P F^T + Q``): the factor computed from the innovation of step k is
applied in the prediction of step k+1 (``lambda = 1`` at the first step).

All per-track arithmetic runs in ``numba`` kernels; leading batch axes (many tracks or
Monte-Carlo runs) are looped inside the kernels. Units are those of the model (for the
seed 003 ferry: metres and metres per second, ``dt`` in seconds).

The Joseph-form measurement update is the linear Kalman filter's own compiled kernel
(``seawatch.filters._kalman_kernels._update_one``); the small wrappers and batch-shape
helpers of this module are shared with :mod:`seawatch.filters.fractional`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from seawatch._validation import (
    FloatArray,
    as_float_array,
    covariance,
    finite,
    in_range,
    linear_model,
)
from seawatch.filters import _kalman_kernels as _kk
from seawatch.filters.kalman import PARALLEL_MIN_TRACKS, raise_kernel_status
from seawatch.filters.result import FilterResult

__all__ = ["StrongTrackingKalmanFilter", "StrongTrackingResult"]

_TINY_TRACE = 1e-300  # guard for tr(M_k) (ALGORITHMS.md §2 pitfalls)


# --------------------------------------------------------------------------------------
# numba building blocks shared with the fractional Kalman filters
# --------------------------------------------------------------------------------------


@njit(cache=True)
def _workspace(n: int, m: int):
    """Scratch arrays of ``_kalman_kernels._update_one``: PHt, L, K, A, AP, w, Po."""
    return (
        np.empty((n, m)),
        np.zeros((m, m)),
        np.empty((n, m)),
        np.empty((n, n)),
        np.empty((n, n)),
        np.empty(m),
        np.empty((n, n)),
    )


@njit(cache=True, inline="always")
def _joseph_update(H, R, z, x, P, y, S, ws):
    """Kalman measurement update of (x, P) in place, Joseph form, via the linear KF's kernel.

    ``K = P H^T S^-1``, ``x += K (z - H x)``, ``P = (I - K H) P (I - K H)^T + K R K^T``
    (ALGORITHMS.md §1.4 (16)–(18), §2 step 6). A NaN in z: predict-only, y and NIS NaN,
    S still computed. Returns ``(code, nis)`` with the codes of ``_kalman_kernels``.
    """
    PHt, L, K, A, AP, w, Po = ws
    code, nis = _kk._update_one(H, R, z, x, P, x, Po, y, S, PHt, L, K, A, AP, w)
    if code == _kk.OK:
        n = x.shape[0]
        for a in range(n):
            for b in range(n):
                P[a, b] = Po[a, b]
    return code, nis


@njit(cache=True, inline="always")
def _any_nan(z):
    for i in range(z.shape[0]):
        if math.isnan(z[i]):
            return True
    return False


# --------------------------------------------------------------------------------------
# STKF kernels (ALGORITHMS.md §2)
# --------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _stkf_predict_track(F, Q, lam, x, P, FPF, tmp_n, tmp_nn):
    """``x = F x``, ``FPF = F P F^T``, ``P = lam FPF + Q`` (lam = 1 or the late factor)."""
    n = x.shape[0]
    for a in range(n):
        s = 0.0
        for b in range(n):
            s += F[a, b] * x[b]
        tmp_n[a] = s
    for a in range(n):
        x[a] = tmp_n[a]
    for a in range(n):
        for b in range(n):
            s = 0.0
            for c in range(n):
                s += F[a, c] * P[c, b]
            tmp_nn[a, b] = s
    for a in range(n):
        for b in range(a + 1):
            s = 0.0
            for c in range(n):
                s += tmp_nn[a, c] * F[b, c]
            FPF[a, b] = s
            FPF[b, a] = s
    for a in range(n):
        for b in range(n):
            P[a, b] = lam * FPF[a, b] + Q[a, b]


@njit(cache=True, inline="always")
def _stkf_update_track(
    H, trHQH, Q, R, z, beta, rho, lam_max, late, vinit, lam_pending,
    x, P, FPF, V, y, S, x_prior, P_prior, ws,
):  # fmt: skip
    """Steps 1–6 of ALGORITHMS.md §2 for one track after ``_stkf_predict_track``.

    A measurement with NaN is missing: plain prediction (lambda = 1), V unchanged.
    Returns ``(code, lam_applied, lam_pending_new, vinit_new, nis)``.
    """
    n = x.shape[0]
    m = H.shape[0]
    lam_applied = 1.0
    lam_next = 1.0
    if not _any_nan(z):
        # 1. pre-fit innovation nu_k = z_k - H x_minus (does not depend on lambda)
        for i in range(m):
            s = z[i]
            for c in range(n):
                s -= H[i, c] * x[c]
            y[i] = s
        # 2. V_k = nu nu^T (first measured step) or (rho V + nu nu^T) / (1 + rho)
        for i in range(m):
            for j in range(m):
                if vinit:
                    V[i, j] = (rho * V[i, j] + y[i] * y[j]) / (1.0 + rho)
                else:
                    V[i, j] = y[i] * y[j]
        vinit = True
        # 3.–4. c_k = tr N_k / tr M_k; N_k = V_k - H Q H^T - beta R_k, M_k = H F P F^T H^T
        trN = -trHQH
        for i in range(m):
            trN += V[i, i] - beta * R[i, i]
        trM = 0.0
        for i in range(m):
            for a in range(n):
                for b in range(n):
                    trM += H[i, a] * FPF[a, b] * H[i, b]
        lam = 1.0
        if trM > _TINY_TRACE:
            lam = max(1.0, trN / trM)
        lam = min(lam, lam_max)
        if late:
            lam_applied = lam_pending
            lam_next = lam
        else:
            lam_applied = lam
    # 5. P_minus = lambda F P F^T + Q (the factor multiplies only F P F^T)
    for a in range(n):
        for b in range(n):
            P[a, b] = lam_applied * FPF[a, b] + Q[a, b]
            P_prior[a, b] = P[a, b]
        x_prior[a] = x[a]
    # 6. gain, state and Joseph covariance update
    code, nis = _joseph_update(H, R, z, x, P, y, S, ws)
    return code, lam_applied, lam_next, vinit, nis


@njit(cache=True)
def _stkf_predict_batch(F, Q, late, lam_pending, x, P, FPF):
    n = x.shape[1]
    tmp_n = np.empty(n)
    tmp_nn = np.empty((n, n))
    for b in range(x.shape[0]):
        lam = lam_pending[b] if late else 1.0
        _stkf_predict_track(F, Q, lam, x[b], P[b], FPF[b], tmp_n, tmp_nn)


@njit(cache=True)
def _stkf_update_batch(
    H, trHQH, Q, R, z, beta, rho, lam_max, late, vinit, lam_pending, lam_applied,
    x, P, FPF, V, y, S, nis, x_prior, P_prior,
):  # fmt: skip
    """One update of every track; ``R`` is (1 or B, m, m). Returns ``(code, b)``."""
    ws = _workspace(x.shape[1], H.shape[0])
    for b in range(x.shape[0]):
        rb = b if R.shape[0] > 1 else 0
        code, lam_a, lam_n, vi, e = _stkf_update_track(
            H, trHQH, Q, R[rb], z[b], beta, rho, lam_max, late, vinit[b], lam_pending[b],
            x[b], P[b], FPF[b], V[b], y[b], S[b], x_prior[b], P_prior[b], ws,
        )  # fmt: skip
        if code != _kk.OK:
            return code, b
        lam_applied[b] = lam_a
        lam_pending[b] = lam_n
        vinit[b] = vi
        nis[b] = e
    return _kk.OK, 0


@njit(cache=True)
def _stkf_filter_track(
    F, H, trHQH, Q, R, zs, beta, rho, lam_max, late, vinit, lam_pending,
    x, P, FPF, V, out_x, out_P, out_xp, out_Pp, out_y, out_S, out_nis, out_lam,
):  # fmt: skip
    """One track's whole sequence, predict then update at each step; ``R`` (1 or T, m, m).

    Returns ``(code, t, vinit, lam_pending)`` (t: the failing step if code is not OK).
    """
    n = x.shape[0]
    ws = _workspace(n, H.shape[0])
    tmp_n = np.empty(n)
    tmp_nn = np.empty((n, n))
    for t in range(zs.shape[0]):
        rt = t if R.shape[0] > 1 else 0
        _stkf_predict_track(F, Q, lam_pending if late else 1.0, x, P, FPF, tmp_n, tmp_nn)
        code, lam_a, lam_pending, vinit, e = _stkf_update_track(
            H, trHQH, Q, R[rt], zs[t], beta, rho, lam_max, late, vinit, lam_pending,
            x, P, FPF, V, out_y[t], out_S[t], out_xp[t], out_Pp[t], ws,
        )  # fmt: skip
        if code != _kk.OK:
            return code, t, vinit, lam_pending
        out_lam[t] = lam_a
        out_nis[t] = e
        out_x[t] = x
        out_P[t] = P
    return _kk.OK, 0, vinit, lam_pending


@njit(cache=True)
def _stkf_filter(
    F, H, trHQH, Q, R, zs, beta, rho, lam_max, late, vinit, lam_pending,
    x, P, FPF, V, out_x, out_P, out_xp, out_Pp, out_y, out_S, out_nis, out_lam,
):  # fmt: skip
    """Every track's sequence; ``R`` (1 or B, 1 or T, m, m). Returns ``(code, b, t)``."""
    for b in range(zs.shape[0]):
        code, t, vinit[b], lam_pending[b] = _stkf_filter_track(
            F, H, trHQH, Q, R[b if R.shape[0] > 1 else 0], zs[b], beta, rho, lam_max, late,
            vinit[b], lam_pending[b], x[b], P[b], FPF[b], V[b], out_x[b], out_P[b],
            out_xp[b], out_Pp[b], out_y[b], out_S[b], out_nis[b], out_lam[b],
        )  # fmt: skip
        if code != _kk.OK:
            return code, b, t
    return _kk.OK, 0, 0


@njit(cache=True, parallel=True)
def _stkf_filter_parallel(
    F, H, trHQH, Q, R, zs, beta, rho, lam_max, late, vinit, lam_pending,
    x, P, FPF, V, out_x, out_P, out_xp, out_Pp, out_y, out_S, out_nis, out_lam,
):  # fmt: skip
    """``_stkf_filter`` with the tracks spread over the CPU cores (numba prange)."""
    B = zs.shape[0]
    codes = np.zeros(B, dtype=np.int64)
    steps = np.zeros(B, dtype=np.int64)
    for bp in prange(B):
        b = np.int64(bp)
        code, t, vi, lp = _stkf_filter_track(
            F, H, trHQH, Q, R[b if R.shape[0] > 1 else 0], zs[b], beta, rho, lam_max, late,
            vinit[b], lam_pending[b], x[b], P[b], FPF[b], V[b], out_x[b], out_P[b],
            out_xp[b], out_Pp[b], out_y[b], out_S[b], out_nis[b], out_lam[b],
        )  # fmt: skip
        codes[b] = code
        steps[b] = t
        vinit[b] = vi
        lam_pending[b] = lp
    for b in range(B):
        if codes[b] != _kk.OK:
            return codes[b], b, steps[b]
    return _kk.OK, 0, 0


# --------------------------------------------------------------------------------------
# batch-shape helpers (shared with the fractional filters)
# --------------------------------------------------------------------------------------


def _broadcast_shapes(*named: tuple[str, tuple[int, ...]]) -> tuple[int, ...]:
    """Common batch shape of several arrays; ValueError naming them if they do not broadcast."""
    try:
        return tuple(np.broadcast_shapes(*(shape for _, shape in named)))
    except ValueError:
        desc = ", ".join(f"{name} {shape}" for name, shape in named)
        raise ValueError(f"batch shapes do not broadcast: {desc}") from None


def _flat(arr: np.ndarray, batch: tuple[int, ...], tail: tuple[int, ...]) -> FloatArray:
    """``arr`` broadcast to ``batch + tail`` and reshaped to a C-contiguous ``(B, *tail)``."""
    size = math.prod(batch)
    return np.array(np.broadcast_to(arr, batch + tail).reshape((size, *tail)), order="C")


def _measurements(name: str, z: ArrayLike | None, m: int, min_ndim: int) -> FloatArray:
    """Measurement array with last axis m; NaN marks a missing value, inf is an error."""
    arr = as_float_array(name, z)
    if arr.ndim < min_ndim or arr.shape[-1] != m:
        want = "(..., m)" if min_ndim == 1 else "(..., T, m)"
        raise ValueError(f"{name}: expected shape {want} with m = {m}, got {arr.shape}")
    if np.any(np.isinf(arr)):
        raise ValueError(f"{name}: contains inf (use NaN for a missing measurement)")
    return arr


# --------------------------------------------------------------------------------------
# public API
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class StrongTrackingResult(FilterResult):
    """:class:`FilterResult` of the STKF plus the fading factors.

    Attributes:
        fading_factors: the factor ``lambda`` (dimensionless, >= 1) that multiplied
            ``F P F^T`` in the prediction of each step, shape (B..., T). With
            ``late_fading=True`` this is the factor computed at the previous step.
            ``predicted_covariances`` are the faded priors actually used by the update.
    """

    fading_factors: NDArray[np.float64]


class StrongTrackingKalmanFilter:
    """Strong Tracking Kalman Filter, single suboptimal fading factor.

    ALGORITHMS.md §2 (Zhou's order: the fading factor of step k comes from the pre-fit
    innovation of step k), seed 003 eqs. 11–16; Joseph-form covariance update.

    Model ``x_k = F x_{k-1} + w``, ``w ~ N(0, Q)``; ``z_k = H x_k + v``, ``v ~ N(0, R)``.
    State and measurement units are those of the model (seed 003: position [m] and
    speed [m/s] with ``F = [[1, dt], [0, 1]]``, ``dt`` [s]); ``beta``, ``rho`` and
    ``lambda`` are dimensionless.

    Args:
        F: transition matrix (n, n).
        H: measurement matrix (m, n).
        Q: process-noise covariance (n, n), PSD.
        R: measurement-noise covariance (m, m), positive definite (the default of
            ``update``/``filter``; both accept a per-step R).
        x0: initial state (n,) or a batch (B..., n), e.g. 1000 Monte-Carlo runs.
        P0: initial covariance (n, n) or (B..., n, n).
        beta: weakening (softening) factor ``beta >= 1`` (source default 4.5).
        rho: forgetting factor ``0 < rho <= 1`` of the innovation covariance estimate V
            (default 0.95; note the effective memory is only ~2 samples, §2).
        lambda_max: upper clamp of the fading factor (>= 1), so that one outlier
            cannot blow up P.
        late_fading: apply the factor one step late, ``P = lambda_{k-1} F P F^T + Q``
            (seed 003 eq. 11 read literally; ``lambda_{-1} = 1``; a missing measurement
            applies 1 and passes 1 on to the next step).

    Per-step use: ``predict()`` propagates the state and stores ``F P F^T``;
    ``update(z)`` computes the fading factor from the pre-fit innovation, forms the
    faded prior ``P_prior = lambda F P F^T + Q`` and corrects. ``step(z)`` does both.
    After ``predict()`` alone, ``P`` is the prior with the factor not yet known (the
    unfaded ``F P F^T + Q``; with ``late_fading`` the late factor is already applied).
    A measurement containing NaN (or ``None``) is missing: plain prediction with
    ``lambda = 1`` and V unchanged. Calling ``predict()`` twice treats the skipped
    update as missing.

    Attributes (arrays with the filter's batch shape ``B...`` in front):
        x, P: current estimate and covariance.
        x_prior, P_prior: the prediction used by the last update (faded).
        y, S, nis: innovation, its covariance and the NIS of the last update
            (y and nis NaN for a missing measurement).
        fading_factor: the factor applied in the last step's prediction.
    """

    def __init__(
        self,
        F: ArrayLike,
        H: ArrayLike,
        Q: ArrayLike,
        R: ArrayLike,
        x0: ArrayLike,
        P0: ArrayLike,
        *,
        beta: float = 4.5,
        rho: float = 0.95,
        lambda_max: float = 100.0,
        late_fading: bool = False,
    ) -> None:
        self.F, self.H, self.Q, self.R = linear_model(F, H, Q, R)
        n, m = self.H.shape[1], self.H.shape[0]
        x0a = finite("x0", as_float_array("x0", x0))
        if x0a.ndim < 1 or x0a.shape[-1] != n:
            raise ValueError(f"x0: expected shape (..., {n}), got {x0a.shape}")
        P0a = covariance("P0", P0, n, batch=True)
        self.beta = in_range("beta", beta, 1.0, np.inf)
        self.rho = in_range("rho", rho, 0.0, 1.0, lo_open=True)
        self.lambda_max = in_range("lambda_max", lambda_max, 1.0, np.inf)
        self.late_fading = bool(late_fading)
        self.dim_x = n
        self.dim_z = m
        self._trHQH = float(np.trace(self.H @ self.Q @ self.H.T))
        self._batch = _broadcast_shapes(("x0", x0a.shape[:-1]), ("P0", P0a.shape[:-2]))
        B = math.prod(self._batch)
        self._x = _flat(x0a, self._batch, (n,))
        self._P = _flat(P0a, self._batch, (n, n))
        self._FPF = np.zeros((B, n, n))
        self._V = np.zeros((B, m, m))
        self._vinit = np.zeros(B, dtype=np.bool_)
        self._lam_pending = np.ones(B)
        self._lam = np.ones(B)
        self._x_prior = self._x.copy()
        self._P_prior = self._P.copy()
        self._y = np.full((B, m), np.nan)
        self._S = np.full((B, m, m), np.nan)
        self._nis = np.full(B, np.nan)
        self._predicted = False

    # ---- state access ---------------------------------------------------------------

    @property
    def batch_shape(self) -> tuple[int, ...]:
        """Leading batch axes of the filter state (``()`` for a single track)."""
        return self._batch

    def _out(self, arr: np.ndarray, tail: tuple[int, ...]) -> FloatArray:
        return arr.reshape(self._batch + tail).copy()

    @property
    def x(self) -> FloatArray:
        """Current state estimate, shape (B..., n), model units."""
        return self._out(self._x, (self.dim_x,))

    @property
    def P(self) -> FloatArray:
        """Current state covariance, shape (B..., n, n)."""
        return self._out(self._P, (self.dim_x, self.dim_x))

    @property
    def x_prior(self) -> FloatArray:
        """Predicted state of the last update, shape (B..., n)."""
        return self._out(self._x_prior, (self.dim_x,))

    @property
    def P_prior(self) -> FloatArray:
        """Faded predicted covariance ``lambda F P F^T + Q`` of the last update, (B..., n, n)."""
        return self._out(self._P_prior, (self.dim_x, self.dim_x))

    @property
    def y(self) -> FloatArray:
        """Last pre-fit innovation ``z - H x_minus``, shape (B..., m); NaN if missing."""
        return self._out(self._y, (self.dim_z,))

    @property
    def S(self) -> FloatArray:
        """Last innovation covariance ``H P_prior H^T + R``, shape (B..., m, m)."""
        return self._out(self._S, (self.dim_z, self.dim_z))

    @property
    def nis(self) -> FloatArray:
        """Last normalised innovation squared ``y^T S^-1 y`` (dimensionless), shape (B...)."""
        return self._out(self._nis, ())

    @property
    def fading_factor(self) -> FloatArray:
        """Fading factor applied in the last step's prediction (>= 1), shape (B...)."""
        return self._out(self._lam, ())

    # ---- batch handling -------------------------------------------------------------

    def _expand(self, batch: tuple[int, ...]) -> None:
        """Broadcast the per-track state to a larger batch shape (e.g. one x0, many runs)."""
        if batch == self._batch:
            return
        old = self._batch
        n, m = self.dim_x, self.dim_z

        def grow(arr: np.ndarray, tail: tuple[int, ...]) -> np.ndarray:
            return _flat(arr.reshape(old + tail), batch, tail)

        self._x = grow(self._x, (n,))
        self._P = grow(self._P, (n, n))
        self._FPF = grow(self._FPF, (n, n))
        self._V = grow(self._V, (m, m))
        self._vinit = np.ascontiguousarray(
            np.broadcast_to(self._vinit.reshape(old), batch).reshape(-1)
        )
        self._lam_pending = grow(self._lam_pending, ())
        self._lam = grow(self._lam, ())
        self._x_prior = grow(self._x_prior, (n,))
        self._P_prior = grow(self._P_prior, (n, n))
        self._y = grow(self._y, (m,))
        self._S = grow(self._S, (m, m))
        self._nis = grow(self._nis, ())
        self._batch = batch

    def _noise(self, R: ArrayLike | None, batch_axes: int) -> tuple[FloatArray, tuple[int, ...]]:
        """Validated R with ``batch_axes`` trailing non-batch axes before (m, m)."""
        m = self.dim_z
        if R is None:
            return self.R.reshape((1,) * batch_axes + (m, m)), ()
        Ra = covariance("R", R, m, positive_definite=True, batch=True)
        if Ra.ndim == 2:
            Ra = Ra.reshape((1,) * batch_axes + (m, m))
        if Ra.ndim < 2 + batch_axes:
            raise ValueError(f"R: expected shape (..., T, {m}, {m}), got {Ra.shape}")
        return Ra, Ra.shape[: Ra.ndim - 2 - batch_axes]

    # ---- per-step API ---------------------------------------------------------------

    def predict(self) -> None:
        """Propagate ``x = F x`` and store ``F P F^T`` (ALGORITHMS.md §2 step 1).

        ``P`` becomes ``F P F^T + Q`` (``lambda_{k-1} F P F^T + Q`` with late fading); the
        fading factor of Zhou's order is only known in :meth:`update`.
        """
        if self._predicted:  # the previous prediction got no update: a missing measurement
            self.update(None)
        _stkf_predict_batch(
            self.F, self.Q, self.late_fading, self._lam_pending, self._x, self._P, self._FPF
        )
        self._predicted = True

    def update(self, z: ArrayLike | None, R: ArrayLike | None = None) -> None:
        """Fading factor, faded prior and Joseph update (ALGORITHMS.md §2 steps 1–6).

        Args:
            z: measurement (m,) or (B..., m) in model units; a row with NaN (or ``None``
                for all tracks) is a missing measurement: predict-only, lambda = 1.
            R: optional measurement-noise covariance for this step, (m, m) or
                (B..., m, m); default the constructor's R.

        Raises:
            RuntimeError: without a preceding :meth:`predict`.
            numpy.linalg.LinAlgError: singular innovation covariance (state unchanged).
        """
        if not self._predicted:
            raise RuntimeError("update(): call predict() first (the STKF needs F P F^T)")
        m = self.dim_z
        za = np.full(m, np.nan) if z is None else _measurements("z", z, m, 1)
        Ra, Rbatch = self._noise(R, 0)
        batch = _broadcast_shapes(
            ("filter state", self._batch), ("z", za.shape[:-1]), ("R", Rbatch)
        )
        self._expand(batch)
        zf = _flat(za, batch, (m,))
        Rf = Ra.reshape(1, m, m) if Rbatch == () else _flat(Ra, batch, (m, m))
        Rf = np.ascontiguousarray(Rf)
        state = [self._x.copy(), self._P.copy(), self._V.copy(), self._vinit.copy()]
        lam_pending = self._lam_pending.copy()
        lam = self._lam.copy()
        y, S, nis = self._y.copy(), self._S.copy(), self._nis.copy()
        xp, Pp = self._x_prior.copy(), self._P_prior.copy()
        x, P, V, vinit = state
        status = _stkf_update_batch(
            self.H, self._trHQH, self.Q, Rf, zf, self.beta, self.rho, self.lambda_max,
            self.late_fading, vinit, lam_pending, lam, x, P, self._FPF, V, y, S, nis, xp, Pp,
        )  # fmt: skip
        raise_kernel_status(status, batch, "StrongTrackingKalmanFilter.update")
        self._x, self._P, self._V, self._vinit = x, P, V, vinit
        self._lam_pending, self._lam = lam_pending, lam
        self._y, self._S, self._nis, self._x_prior, self._P_prior = y, S, nis, xp, Pp
        self._predicted = False

    def step(self, z: ArrayLike | None, R: ArrayLike | None = None) -> None:
        """One STKF cycle: :meth:`predict` then :meth:`update`."""
        self.predict()
        self.update(z, R)

    # ---- whole sequences ------------------------------------------------------------

    def filter(self, zs: ArrayLike, R: ArrayLike | None = None) -> StrongTrackingResult:
        """Run predict-then-update over a measurement sequence (FilterPy batch convention).

        Starts from the current state and leaves the filter at the last step (the same
        as calling :meth:`step` for each ``z``). A state without batch axes is broadcast
        to the batch of ``zs`` (one x0 for many Monte-Carlo runs).

        Args:
            zs: measurements (T, m) or (B..., T, m); rows containing NaN are missing.
            R: optional measurement noise: (m, m), or per step (..., T, m, m) with the
                leading axes broadcasting against the batch (e.g. a range-dependent R).

        Returns:
            :class:`StrongTrackingResult` with shapes (B..., T, ...) and the per-step
            fading factors. Batches of at least ``kalman.PARALLEL_MIN_TRACKS`` tracks run
            on all CPU cores.
        """
        if self._predicted:
            self.update(None)
        n, m = self.dim_x, self.dim_z
        za = _measurements("zs", zs, m, 2)
        T = za.shape[-2]
        Ra, Rbatch = self._noise(R, 1)
        if R is not None and Ra.shape[-3] not in (1, T):
            raise ValueError(f"R: time axis has length {Ra.shape[-3]}, expected 1 or T = {T}")
        batch = _broadcast_shapes(
            ("filter state", self._batch), ("zs", za.shape[:-2]), ("R", Rbatch)
        )
        self._expand(batch)
        B = math.prod(batch)
        zf = _flat(za, batch, (T, m))
        TR = Ra.shape[-3]
        if Rbatch == ():
            Rf = np.ascontiguousarray(Ra.reshape(1, TR, m, m))
        else:
            Rf = _flat(Ra, batch, (TR, m, m))
        x, P, V, vinit = self._x.copy(), self._P.copy(), self._V.copy(), self._vinit.copy()
        FPF, lam_pending = self._FPF.copy(), self._lam_pending.copy()
        out_x = np.empty((B, T, n))
        out_P = np.empty((B, T, n, n))
        out_xp = np.empty((B, T, n))
        out_Pp = np.empty((B, T, n, n))
        out_y = np.empty((B, T, m))
        out_S = np.empty((B, T, m, m))
        out_nis = np.empty((B, T))
        out_lam = np.empty((B, T))
        kernel = _stkf_filter_parallel if B >= PARALLEL_MIN_TRACKS else _stkf_filter
        code, bad_b, bad_t = kernel(
            self.F, self.H, self._trHQH, self.Q, Rf, zf, self.beta, self.rho, self.lambda_max,
            self.late_fading, vinit, lam_pending, x, P, FPF, V,
            out_x, out_P, out_xp, out_Pp, out_y, out_S, out_nis, out_lam,
        )  # fmt: skip
        raise_kernel_status(
            (code, bad_b), batch, f"StrongTrackingKalmanFilter.filter (step {bad_t})"
        )
        if T > 0:
            self._x, self._P, self._V, self._vinit = x, P, V, vinit
            self._FPF, self._lam_pending = FPF, lam_pending
            self._lam = out_lam[:, -1].copy()
            self._x_prior, self._P_prior = out_xp[:, -1].copy(), out_Pp[:, -1].copy()
            self._y, self._S = out_y[:, -1].copy(), out_S[:, -1].copy()
            self._nis = out_nis[:, -1].copy()

        def shape(arr: np.ndarray, tail: tuple[int, ...]) -> FloatArray:
            return arr.reshape((*batch, T, *tail))

        return StrongTrackingResult(
            states=shape(out_x, (n,)),
            covariances=shape(out_P, (n, n)),
            predicted_states=shape(out_xp, (n,)),
            predicted_covariances=shape(out_Pp, (n, n)),
            innovations=shape(out_y, (m,)),
            innovation_covariances=shape(out_S, (m, m)),
            nis=shape(out_nis, ()),
            fading_factors=shape(out_lam, ()),
        )
