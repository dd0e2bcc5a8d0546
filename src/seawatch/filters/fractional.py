"""Fractional-order Kalman filters: FKF and the adaptive AFKF of seed 001.

ALGORITHMS.md §1; Sierociuk & Dzieliński, Int. J. Appl. Math. Comput. Sci. 16(1),
129–140 (2006); seed 001 (Fang & Guo).

Model (§1.2), with the signed Grünwald–Letnikov (GL) coefficients ``c_j`` of §1.1 and
``Y_j = diag(c_j(alpha_1), ..., c_j(alpha_n))``::

    x_{k+1} = A x_k - sum_{j=1..k+1} Y_j x_{k+1-j} + w_k,     w_k ~ N(0, Q_k)
    z_k     = H x_k + e_k,                                   e_k ~ N(0, R)

Filter (§1.4, short memory L, ``J = min(k+1, L)``)::

    x~_{k+1} = A x^_k - sum_{j=1..J} Y_j x^_{k+1-j}
    P~_{k+1} = (A - Y_1) P_k (A - Y_1)^T + Q_k + sum_{j=2..J} Y_j P_{k+1-j} Y_j^T
    K        = P~ H^T (H P~ H^T + R)^-1
    x^_{k+1} = x~ + K (z_{k+1} - H x~),   P_{k+1} = Joseph form of (I - K H) P~

The first line of each pair is the plain Kalman prediction with ``F = A - Y_1`` (the
linear filter's own kernel computes it) plus the memory terms; the update is the linear
filter's Joseph-form kernel. The last ``L - 1`` past estimates and covariances live in a
fixed-size ring buffer, so memory is constant for a stream of any length.

Pitfall (§1.2): with ``alpha < 1`` the memory weights sum to less than one, so the model
pulls the state toward the origin. ``relative=True`` (default) runs the filter in
coordinates relative to the first measurement and adds the offset back on output.

Image-plane use (§1.3, seed 001): state ``[u, v, u_dot, v_dot]`` in px and px per frame
period, measurement ``[u, v]`` in px (box centre); see
:meth:`FractionalKalmanFilter.for_image_tracking`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal, Self, cast

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray
from scipy.stats import chi2

from seawatch._validation import (
    FloatArray,
    as_float_array,
    covariance,
    finite,
    in_range,
    integer,
    linear_model,
    positive,
)
from seawatch.filters import _kalman_kernels as _kk
from seawatch.filters.kalman import raise_kernel_status
from seawatch.filters.result import FilterResult
from seawatch.filters.strong_tracking import (
    _broadcast_shapes,
    _flat,
    _joseph_update,
    _measurements,
    _workspace,
)
from seawatch.models.kinematic import constant_velocity, position_measurement

__all__ = [
    "AdaptiveFractionalKalmanFilter",
    "AdaptiveFractionalResult",
    "FractionalKalmanFilter",
    "fractional_cv_matrix",
    "gl_coefficients",
]

_RULES = {"none": 0, "R1": 1, "R2": 2}


# --------------------------------------------------------------------------------------
# Grünwald–Letnikov coefficients and the image-plane model
# --------------------------------------------------------------------------------------


def _orders(value: ArrayLike, n: int | None) -> FloatArray:
    """Validated fractional order(s): a finite scalar or vector, every entry > 0."""
    arr = finite("order", as_float_array("order", value, ndim=(0, 1)))
    if np.any(arr <= 0.0):
        raise ValueError(f"order: every fractional order must be > 0, got {arr.tolist()}")
    if arr.ndim == 1 and n is not None and arr.shape[0] != n:
        raise ValueError(f"order: expected a scalar or {n} per-state orders, got {arr.shape[0]}")
    return arr


def gl_coefficients(order: ArrayLike, count: int) -> FloatArray:
    """Signed Grünwald–Letnikov coefficients ``c_j = (-1)^j binom(alpha, j)``, j = 0..count-1.

    ALGORITHMS.md §1.1, by the stable recursion ``c_0 = 1``,
    ``c_j = c_{j-1} (1 - (alpha + 1) / j)``. For ``0 < alpha < 1`` every ``c_j`` (j >= 1)
    is negative and ``sum_{j>=1} -c_j -> 1`` as the memory grows. Example:
    ``gl_coefficients(0.8, 5) = [1, -0.8, -0.08, -0.032, -0.0176]``.

    Args:
        order: fractional order alpha > 0 (dimensionless), scalar or per state (n,).
        count: number of coefficients (>= 1).

    Returns:
        shape (count,) for a scalar order, (count, n) for a vector of orders; the rows
        are the diagonals of ``Y_j`` (``Y_0 = I``).
    """
    alpha = _orders(order, None)
    count = integer("count", count, 1)
    c = np.empty((count, *alpha.shape))
    c[0] = 1.0
    for j in range(1, count):
        c[j] = c[j - 1] * (1.0 - (alpha + 1.0) / j)
    return c


def fractional_cv_matrix(dim: int, dt: float) -> FloatArray:
    """System matrix A of the fractional constant-velocity model, ALGORITHMS.md §1.3.

    ``A = kron([[0, dt], [0, 0]], I_dim)`` with positions first (``[u, v, u_dot, v_dot]``
    for ``dim = 2``), so that order 1 gives exactly ``A - Y_1 = A + I = F_CV``. ``dt`` is
    the frame period in the time unit of the velocities (1.0: velocities in px/frame).
    """
    dim = integer("dim", dim, 1, 3)
    T = positive("dt", dt)
    return np.kron(np.array([[0.0, T], [0.0, 0.0]]), np.eye(int(dim)))


# --------------------------------------------------------------------------------------
# numba kernels
# --------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _fkf_predict_track(AY1, c, Q, q_scale, head, count, x, P, hx, hP, xt, Pt, Qk, FP):
    """ALGORITHMS.md §1.4 (14)–(15) for one track into ``xt``, ``Pt`` (then pushed by caller).

    ``hx``/``hP`` hold ``count`` past estimates, the newest (k-1) at ``head``.
    """
    n = x.shape[0]
    cap = hx.shape[0]
    for a in range(n):
        for b in range(n):
            Qk[a, b] = q_scale * Q[a, b]
    # integer-order part: (A - Y_1) x_k and (A - Y_1) P_k (A - Y_1)^T + Q_k
    _kk._predict_one(AY1, Qk, x, P, xt, Pt, FP)
    # memory part: - sum_{j>=2} Y_j x_{k+1-j} and + sum_{j>=2} Y_j P_{k+1-j} Y_j^T
    for j in range(2, count + 2):
        idx = head - (j - 2)
        if idx < 0:
            idx += cap
        for a in range(n):
            xt[a] -= c[j, a] * hx[idx, a]
            for b in range(n):
                Pt[a, b] += c[j, a] * c[j, b] * hP[idx, a, b]


@njit(cache=True, inline="always")
def _push(head, count, cap):
    """Ring-buffer slot of the next push and the new fill count."""
    if cap == 0:
        return head, 0
    return (head + 1) % cap, min(count + 1, cap)


@njit(cache=True)
def _fkf_predict_batch(AY1, c, Q, q_scale, head, count, x, P, hx, hP):
    """Predict every track in place and push the old estimates; returns (head, count)."""
    n = x.shape[1]
    cap = hx.shape[1]
    xt = np.empty(n)
    Pt = np.empty((n, n))
    Qk = np.empty((n, n))
    FP = np.empty((n, n))
    new_head, new_count = _push(head, count, cap)
    for b in range(x.shape[0]):
        _fkf_predict_track(
            AY1, c, Q, q_scale[b], head, count, x[b], P[b], hx[b], hP[b], xt, Pt, Qk, FP
        )
        if cap > 0:
            hx[b, new_head] = x[b]
            hP[b, new_head] = P[b]
        x[b] = xt
        P[b] = Pt
    return new_head, new_count


@njit(cache=True, inline="always")
def _adapt_track(rule, gain, g_max, delta, bounds, m, nis, P, etas, state):
    """Adaptive state-noise factor g_k (Q_k = g_k Q_0), ALGORITHMS.md §1.5.

    ``state`` = [eta_head, eta_count, tr P_{k-1}, calm steps, eta_bar, steady] (floats,
    updated in place); returns g for the next prediction (causal: Q of step k is used at
    k+1). R1: ``g = min(g_max, 1 + gain max(0, eta_bar - 1))``. R2: ``g = 1`` at steady
    state, else ``1 + gain``; steady state is entered when the relative change of tr P
    stayed below delta for W consecutive steps and eta_bar is within the chi-square bound
    ``bounds[count]``, and left only when eta_bar exceeds that bound.
    """
    W = etas.shape[0]
    head = (int(state[0]) + 1) % W
    cnt = min(int(state[1]) + 1, W)
    etas[head] = nis / m
    total = 0.0
    for i in range(cnt):
        idx = head - i
        if idx < 0:
            idx += W
        total += etas[idx]
    eta_bar = total / cnt
    state[0] = head
    state[1] = cnt
    state[4] = eta_bar
    if rule == 1:
        return min(g_max, 1.0 + gain * max(0.0, eta_bar - 1.0))
    trP = 0.0
    for a in range(P.shape[0]):
        trP += P[a, a]
    if abs(trP - state[2]) < delta * trP:  # False while tr P_{k-1} is unknown (NaN)
        state[3] += 1.0
    else:
        state[3] = 0.0
    state[2] = trP
    if state[5] > 0.5:  # steady: stays so until the NIS exceeds the chi-square bound
        steady = eta_bar <= bounds[cnt]
    else:  # transient: enters steady state once tr P has settled and the NIS is in bounds
        steady = state[3] >= W and eta_bar <= bounds[cnt]
    state[5] = 1.0 if steady else 0.0
    return 1.0 if steady else 1.0 + gain


@njit(cache=True, inline="always")
def _fkf_update_track(H, R, z, x, P, y, S, ws, rule, gain, g_max, delta, bounds, etas, state, g):
    """(16)–(18) Joseph update, then the Q rule; returns (code, nis, g_next)."""
    code, nis = _joseph_update(H, R, z, x, P, y, S, ws)
    if code == _kk.OK and rule != 0 and not math.isnan(nis):
        g = _adapt_track(rule, gain, g_max, delta, bounds, H.shape[0], nis, P, etas, state)
    return code, nis, g


@njit(cache=True)
def _fkf_update_batch(
    H, R, z, x, P, y, S, nis, rule, gain, g_max, delta, bounds, etas, astate, q_scale
):
    """Update every track in place; returns (code, b)."""
    ws = _workspace(x.shape[1], H.shape[0])
    for b in range(x.shape[0]):
        code, e, g = _fkf_update_track(
            H, R, z[b], x[b], P[b], y[b], S[b], ws,
            rule, gain, g_max, delta, bounds, etas[b], astate[b], q_scale[b],
        )  # fmt: skip
        if code != _kk.OK:
            return code, b
        nis[b] = e
        q_scale[b] = g
    return _kk.OK, 0


@njit(cache=True)
def _fkf_filter(
    AY1, c, H, Q, R, zs, head0, count0, x, P, hx, hP,
    rule, gain, g_max, delta, bounds, etas, astate, q_scale,
    out_x, out_P, out_xp, out_Pp, out_y, out_S, out_nis, out_q,
):  # fmt: skip
    """Predict then update at every step of every track; returns (code, b, t, head, count)."""
    n = x.shape[1]
    cap = hx.shape[1]
    ws = _workspace(n, H.shape[0])
    Qk = np.empty((n, n))
    FP = np.empty((n, n))
    head = head0
    count = count0
    for b in range(zs.shape[0]):
        head = head0
        count = count0
        xb = x[b]
        Pb = P[b]
        for t in range(zs.shape[1]):
            out_q[b, t] = q_scale[b]
            _fkf_predict_track(
                AY1, c, Q, q_scale[b], head, count, xb, Pb, hx[b], hP[b],
                out_xp[b, t], out_Pp[b, t], Qk, FP,
            )  # fmt: skip
            head, count = _push(head, count, cap)
            if cap > 0:
                hx[b, head] = xb
                hP[b, head] = Pb
            xb[:] = out_xp[b, t]
            Pb[:, :] = out_Pp[b, t]
            code, e, g = _fkf_update_track(
                H, R, zs[b, t], xb, Pb, out_y[b, t], out_S[b, t], ws,
                rule, gain, g_max, delta, bounds, etas[b], astate[b], q_scale[b],
            )  # fmt: skip
            if code != _kk.OK:
                return code, b, t, head, count
            q_scale[b] = g
            out_nis[b, t] = e
            out_x[b, t] = xb
            out_P[b, t] = Pb
    return _kk.OK, 0, 0, head, count


# --------------------------------------------------------------------------------------
# public API
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class AdaptiveFractionalResult(FilterResult):
    """:class:`FilterResult` of the AFKF plus the state-noise gain factors.

    Attributes:
        q_scales: ``g_k`` (dimensionless, >= 1) with ``Q = g_k Q_0`` used in the
            prediction of each step, shape (B..., T).
    """

    q_scales: NDArray[np.float64]


class FractionalKalmanFilter:
    """Fractional-order Kalman filter (FKF) with short memory, ALGORITHMS.md §1.1–1.4.

    Sierociuk & Dzieliński (2006) recursion (14)–(18) with GL coefficients, Joseph-form
    covariance update, histories of the last ``memory`` estimates in a ring buffer.

    Args:
        A: system matrix (n, n) of ``Delta^alpha x_{k+1} = A x_k + w_k`` with the
            sampling factor absorbed (§1.2; see :func:`fractional_cv_matrix`).
        H: measurement matrix (m, n) (``G`` in §1).
        Q: state-noise covariance (n, n), PSD, units of x squared.
        R: measurement-noise covariance (m, m), positive definite, units of z squared.
        x0: initial estimate (n,) or (B..., n) in absolute coordinates, or ``None``: the
            first measurement initialises the track(s) with ``x0 = H^+ z_0`` (for the
            image model: ``[u_0, v_0, 0, 0]``) and ``P0``.
        P0: initial covariance (n, n) or (B..., n, n).
        order: fractional order alpha > 0, scalar or per state (n,); 1 gives the
            integer-order Kalman filter with ``F = A + I``.
        memory: history length L >= 1 (number of GL terms j = 1..L).
        relative: run in coordinates relative to the first measurement: the offset
            ``o = H^+ H x0`` (``= H^+ z_0`` when x0 comes from z_0; positions of x0 for
            the image model) is subtracted from the state and ``H o`` from every z;
            estimates are reported in absolute coordinates (§1.2 pitfall).

    Per step: ``predict()`` ((14)–(15); pushes the current estimate into the history),
    ``update(z)`` ((16)–(18); NaN or ``None``: predict-only, the history still advances
    at the next predict), ``step(z)`` = both. ``update`` without a ``predict`` corrects
    the current estimate. Attributes ``x``, ``P`` (current, absolute), ``y``, ``S``,
    ``nis`` (last update), ``x_prior``, ``P_prior`` (last prediction), leading batch axes.
    """

    _rule = "none"

    def __init__(
        self,
        A: ArrayLike,
        H: ArrayLike,
        Q: ArrayLike,
        R: ArrayLike,
        x0: ArrayLike | None,
        P0: ArrayLike,
        *,
        order: ArrayLike = 0.95,
        memory: int = 30,
        relative: bool = True,
    ) -> None:
        self.A, self.H, self.Q, self.R = linear_model(A, H, Q, R, transition="A")
        n, m = self.H.shape[1], self.H.shape[0]
        self.P0: FloatArray = covariance("P0", P0, n, batch=True)
        alpha = _orders(order, n)
        self.order: FloatArray = np.broadcast_to(alpha, (n,)).copy()
        self.memory = integer("memory", memory, 1)
        self.relative = bool(relative)
        self.dim_x, self.dim_z = n, m
        # c[j, i] = c_j(alpha_i), j = 0..L; Y_1 = diag(c[1])
        self._c = np.ascontiguousarray(gl_coefficients(self.order, self.memory + 1))
        self._AY1 = np.ascontiguousarray(self.A - np.diag(self._c[1]))
        self._Hpinv = np.linalg.pinv(self.H)
        self._head = 0
        self._count = 0
        self._s: dict[str, np.ndarray] = {}
        self._batch: tuple[int, ...] = ()
        if x0 is not None:
            x0a = finite("x0", as_float_array("x0", x0))
            if x0a.ndim < 1 or x0a.shape[-1] != n:
                raise ValueError(f"x0: expected shape (..., {n}) or None, got {x0a.shape}")
            self._start(x0a)

    # ---- adaptive hooks (overridden by the AFKF) -------------------------------------

    def _adapt_args(self) -> tuple[int, float, float, float, FloatArray]:
        """(rule code, gain, g_max, delta, chi-square bounds) for the kernels."""
        return 0, 0.0, 1.0, 0.0, np.zeros(2)

    def _window(self) -> int:
        return 1

    def _initial_q_scale(self) -> float:
        return 1.0

    # ---- state -----------------------------------------------------------------------

    def _start(self, x0: FloatArray) -> None:
        """Set up the per-track arrays from an absolute initial estimate x0 (B..., n)."""
        n, m = self.dim_x, self.dim_z
        batch = _broadcast_shapes(("x0", x0.shape[:-1]), ("P0", self.P0.shape[:-2]))
        B = math.prod(batch)
        x = _flat(x0, batch, (n,))
        offset = x @ (self._Hpinv @ self.H).T if self.relative else np.zeros((B, n))
        cap = self.memory - 1
        W = self._window()
        astate = np.zeros((B, 6))
        astate[:, 0] = -1.0  # eta ring head: first push goes to slot 0
        astate[:, 2] = np.nan  # tr P_{k-1} unknown
        astate[:, 4] = np.nan  # eta_bar unknown
        self._s = {
            "x": np.ascontiguousarray(x - offset),
            "P": _flat(self.P0, batch, (n, n)),
            "offset": np.ascontiguousarray(offset),
            "hx": np.zeros((B, cap, n)),
            "hP": np.zeros((B, cap, n, n)),
            "y": np.full((B, m), np.nan),
            "S": np.full((B, m, m), np.nan),
            "nis": np.full(B, np.nan),
            "etas": np.zeros((B, W)),
            "astate": astate,
            "q_scale": np.full(B, self._initial_q_scale()),
        }
        self._s["x_prior"] = self._s["x"].copy()
        self._s["P_prior"] = self._s["P"].copy()
        self._batch = batch
        self._head, self._count = 0, 0

    @property
    def initialised(self) -> bool:
        """False until x0 was given or the first measurement arrived."""
        return bool(self._s)

    def _need_state(self, what: str) -> None:
        if not self._s:
            raise RuntimeError(
                f"{what}: the filter has no state yet; pass x0 or call update(z0)/step(z0) "
                "with the first measurement"
            )

    def _initialise_from(self, z: FloatArray) -> None:
        """x0 = H^+ z_0 (image model: [u_0, v_0, 0, 0]), P = P0 (ALGORITHMS.md §1.4)."""
        if np.any(np.isnan(z)):
            raise ValueError(
                "z: the first measurement initialises the filter (x0=None) and must not be "
                "missing (NaN)"
            )
        self._start(z @ self._Hpinv.T)
        self._s["S"] = _flat(self.H @ self.P0 @ self.H.T + self.R, self._batch, (self.dim_z,) * 2)

    def _get(self, key: str, tail: tuple[int, ...], absolute: bool = False) -> FloatArray:
        self._need_state(key)
        arr = self._s[key] + self._s["offset"] if absolute else self._s[key]
        return arr.reshape(self._batch + tail).copy()

    @property
    def batch_shape(self) -> tuple[int, ...]:
        """Leading batch axes of the state (``()`` for one track or before initialisation)."""
        return self._batch

    @property
    def x(self) -> FloatArray:
        """Current estimate in absolute coordinates, (B..., n), units of the model."""
        return self._get("x", (self.dim_x,), absolute=True)

    @property
    def P(self) -> FloatArray:
        """Current covariance (B..., n, n) (Sierociuk's approximation, §1.4 notes)."""
        return self._get("P", (self.dim_x, self.dim_x))

    @property
    def x_prior(self) -> FloatArray:
        """Last prediction x~ (14), absolute coordinates, (B..., n)."""
        return self._get("x_prior", (self.dim_x,), absolute=True)

    @property
    def P_prior(self) -> FloatArray:
        """Last predicted covariance P~ (15), (B..., n, n)."""
        return self._get("P_prior", (self.dim_x, self.dim_x))

    @property
    def y(self) -> FloatArray:
        """Last innovation ``z - H x~``, (B..., m); NaN for a missing measurement."""
        return self._get("y", (self.dim_z,))

    @property
    def S(self) -> FloatArray:
        """Last innovation covariance ``H P~ H^T + R``, (B..., m, m)."""
        return self._get("S", (self.dim_z, self.dim_z))

    @property
    def nis(self) -> FloatArray:
        """Last normalised innovation squared (dimensionless), (B...)."""
        return self._get("nis", ())

    @property
    def history_length(self) -> int:
        """Number of past estimates currently held (at most ``memory - 1``)."""
        return self._count

    @property
    def history_nbytes(self) -> int:
        """Bytes held by the history ring buffers (constant over a stream)."""
        return int(self._s["hx"].nbytes + self._s["hP"].nbytes) if self._s else 0

    def _expand(self, batch: tuple[int, ...]) -> None:
        if batch == self._batch:
            return
        old = self._batch
        for key, arr in self._s.items():
            tail = arr.shape[1:]
            self._s[key] = _flat(arr.reshape(old + tail), batch, tail)
        self._batch = batch

    # ---- per-step API ----------------------------------------------------------------

    def predict(self) -> None:
        """Prediction (14)–(15) with ``Q_k``; the current estimate enters the history."""
        self._need_state("predict()")
        s = self._s
        self._head, self._count = _fkf_predict_batch(
            self._AY1, self._c, self.Q, s["q_scale"], self._head, self._count,
            s["x"], s["P"], s["hx"], s["hP"],
        )  # fmt: skip
        s["x_prior"] = s["x"].copy()
        s["P_prior"] = s["P"].copy()

    def update(self, z: ArrayLike | None, R: ArrayLike | None = None) -> None:
        """Measurement update (16)–(18), Joseph form (and the Q rule of the AFKF).

        Args:
            z: measurement (m,) or (B..., m), absolute coordinates (px for the image
                model); NaN in a row or ``None``: predict-only for that track. Before any
                state exists (``x0=None``) the first z initialises the filter.
            R: measurement covariance for this update only (default ``self.R``), as the
                constructor's R: (m, m), a diagonal (m,) or a scalar, positive definite
                (e.g. a very large variance on a coordinate the measurement does not
                tell: the update then leaves it to the prediction).

        Raises:
            numpy.linalg.LinAlgError: singular innovation covariance.
            ValueError: ``R`` not a finite positive-definite (m, m) covariance.
        """
        m = self.dim_z
        Rk = self.R if R is None else covariance("R", R, m, positive_definite=True)
        if z is None:
            self._need_state("update(None)")
            za = np.full(m, np.nan)
        else:
            za = _measurements("z", z, m, 1)
        if not self._s:
            self._initialise_from(za)
            return
        batch = _broadcast_shapes(("filter state", self._batch), ("z", za.shape[:-1]))
        self._expand(batch)
        s = self._s
        zf = _flat(za, batch, (m,)) - s["offset"] @ self.H.T
        keys = ("x", "P", "y", "S", "nis", "etas", "astate", "q_scale")
        work = {k: s[k].copy() for k in keys}
        rule, gain, g_max, delta, bounds = self._adapt_args()
        status = _fkf_update_batch(
            self.H, Rk, zf, work["x"], work["P"], work["y"], work["S"], work["nis"],
            rule, gain, g_max, delta, bounds, work["etas"], work["astate"], work["q_scale"],
        )  # fmt: skip
        raise_kernel_status(status, batch, f"{type(self).__name__}.update")
        s.update(work)

    def step(self, z: ArrayLike | None) -> None:
        """One cycle: :meth:`predict` then :meth:`update` (initialises if no state yet)."""
        if not self._s:
            self.update(z)
            return
        self.predict()
        self.update(z)

    # ---- whole sequences -------------------------------------------------------------

    def filter(self, zs: ArrayLike) -> FilterResult:
        """Predict then update over a measurement sequence; the filter keeps the final state.

        Args:
            zs: (T, m) or (B..., T, m) in absolute coordinates; rows with NaN are missing
                (predict-only; the history still advances). With ``x0=None`` and no state
                yet, the first row initialises the filter: that step's estimate is
                ``H^+ z_0`` with covariance ``P0`` and NaN innovation and NIS.

        Returns:
            :class:`FilterResult` (the AFKF returns :class:`AdaptiveFractionalResult`),
            shapes (B..., T, ...), absolute coordinates.
        """
        n, m = self.dim_x, self.dim_z
        za = _measurements("zs", zs, m, 2)
        first: dict[str, np.ndarray] | None = None
        if not self._s and za.shape[-2] > 0:
            self._initialise_from(za[..., 0, :])
            za = za[..., 1:, :]
            first = self._record()
        self._need_state("filter()")
        T = za.shape[-2]
        batch = _broadcast_shapes(("filter state", self._batch), ("zs", za.shape[:-2]))
        self._expand(batch)
        B = math.prod(batch)
        s = self._s
        zf = _flat(za, batch, (T, m)) - (s["offset"] @ self.H.T)[:, None, :]
        keys = ("x", "P", "hx", "hP", "etas", "astate", "q_scale")
        work = {k: s[k].copy() for k in keys}
        out = {
            "x": np.empty((B, T, n)),
            "P": np.empty((B, T, n, n)),
            "xp": np.empty((B, T, n)),
            "Pp": np.empty((B, T, n, n)),
            "y": np.empty((B, T, m)),
            "S": np.empty((B, T, m, m)),
            "nis": np.empty((B, T)),
            "q": np.empty((B, T)),
        }
        rule, gain, g_max, delta, bounds = self._adapt_args()
        code, bad_b, bad_t, head, count = _fkf_filter(
            self._AY1, self._c, self.H, self.Q, self.R, zf, self._head, self._count,
            work["x"], work["P"], work["hx"], work["hP"],
            rule, gain, g_max, delta, bounds, work["etas"], work["astate"], work["q_scale"],
            out["x"], out["P"], out["xp"], out["Pp"], out["y"], out["S"], out["nis"], out["q"],
        )  # fmt: skip
        raise_kernel_status((code, bad_b), batch, f"{type(self).__name__}.filter (step {bad_t})")
        offset = s["offset"][:, None, :]
        out["x"] += offset
        out["xp"] += offset
        if T > 0:
            s.update(work)
            self._head, self._count = head, count
            s["x_prior"] = out["xp"][:, -1] - s["offset"]
            s["P_prior"] = out["Pp"][:, -1].copy()
            s["y"], s["S"] = out["y"][:, -1].copy(), out["S"][:, -1].copy()
            s["nis"] = out["nis"][:, -1].copy()
        if first is not None:
            for key, arr in out.items():
                out[key] = np.concatenate([first[key], arr], axis=1)
            T += 1
        fields = {
            "states": out["x"].reshape((*batch, T, n)),
            "covariances": out["P"].reshape((*batch, T, n, n)),
            "predicted_states": out["xp"].reshape((*batch, T, n)),
            "predicted_covariances": out["Pp"].reshape((*batch, T, n, n)),
            "innovations": out["y"].reshape((*batch, T, m)),
            "innovation_covariances": out["S"].reshape((*batch, T, m, m)),
            "nis": out["nis"].reshape((*batch, T)),
        }
        return self._result(fields, out["q"].reshape((*batch, T)))

    def _record(self) -> dict[str, np.ndarray]:
        """The initialisation step as a one-step block of filter outputs (absolute)."""
        s = self._s
        x = (s["x"] + s["offset"])[:, None]
        P = s["P"][:, None]
        return {
            "x": x,
            "P": P,
            "xp": x.copy(),
            "Pp": P.copy(),
            "y": s["y"][:, None].copy(),
            "S": s["S"][:, None].copy(),
            "nis": s["nis"][:, None].copy(),
            "q": s["q_scale"][:, None].copy(),
        }

    def _result(self, fields: dict[str, np.ndarray], q_scales: np.ndarray) -> FilterResult:
        return FilterResult(**fields)

    # ---- model helper ----------------------------------------------------------------

    @classmethod
    def for_image_tracking(
        cls,
        *,
        dt: float = 1.0,
        sigma_a: float | ArrayLike = 1.0,
        sigma_z: float = 2.0,
        sigma_v0: float = 5.0,
        order: ArrayLike = 0.95,
        memory: int = 30,
        x0: ArrayLike | None = None,
        **options: Any,
    ) -> Self:
        """Filter for box-centre tracking in the image plane, ALGORITHMS.md §1.3–1.4.

        State ``[u, v, u_dot, v_dot]``, measurement ``[u, v]`` (px, OpenCV axes).
        ``A = fractional_cv_matrix(2, dt)``, ``H = [I_2, 0]``, ``Q0`` = discrete
        white-noise acceleration (§5.2), ``R = sigma_z^2 I_2``,
        ``P0 = diag(sigma_z^2, sigma_z^2, sigma_v0^2, sigma_v0^2)``; with ``x0=None`` the
        first measurement sets ``x0 = [u_0, v_0, 0, 0]``.

        Args:
            dt: frame period in the velocity time unit (1.0: velocities in px/frame;
                1/25 s: px/s at 25 fps).
            sigma_a: acceleration noise std [px/frame^2 with dt = 1] (seed 001 ships at
                25 fps: 0.5–2), one for both axes or ``(u, v)``.
            sigma_z: box-centre jitter of the detector/tracker [px].
            sigma_v0: initial velocity std ≈ expected maximum speed [px/frame].
            order, memory: fractional order(s) and history length L.
            x0: optional initial state (B..., 4) [px, px/frame]; default: first z.
            **options: further keyword arguments of the class (``relative``; the AFKF's
                ``rule``, ``gain``, ``window``, ``g_max``, ``delta``).
        """
        A = fractional_cv_matrix(2, dt)
        _, Q0 = constant_velocity(2, dt, sigma_a)
        H = position_measurement(2, 2)
        sz = positive("sigma_z", sigma_z)
        sv = positive("sigma_v0", sigma_v0)
        R = sz * sz * np.eye(2)
        P0 = np.diag([sz * sz, sz * sz, sv * sv, sv * sv])
        return cls(A, H, Q0, R, x0, P0, order=order, memory=memory, **options)


class AdaptiveFractionalKalmanFilter(FractionalKalmanFilter):
    """Adaptive fractional-order Kalman filter (AFKF, seed 001), ALGORITHMS.md §1.5.

    The FKF of §1.4 with the state-noise covariance ``Q_k = g_k Q0`` chosen from the
    normalised innovations ``eta_k = y^T S^-1 y / m`` averaged over the last ``window``
    measured steps (``eta_bar``). ``g`` computed at step k is used in the prediction of
    step k+1 (causal); missing measurements leave it unchanged.

    * ``rule="R1"`` (default, continuous): ``g = min(g_max, 1 + gain max(0, eta_bar - 1))``.
    * ``rule="R2"`` (steady-state switch): ``g = 1`` at steady state, else
      ``g = 1 + gain``. Starts transient; becomes steady when the relative change of
      ``tr P`` stayed below ``delta`` for ``window`` consecutive steps and
      ``eta_bar <= chi2_{m c, 0.99} / (m c)`` (c = number of averaged innovations, up to
      ``window``); returns to transient when ``eta_bar`` exceeds that bound. The
      hysteresis (the tr P test only to *enter* steady state) reads §1.5's "if NIS
      exceeds the chi-square bound later, the rule returns to the transient state":
      applied memorylessly the tr P test fails at every switch to the smaller Q (P
      shrinks by more than ``delta`` per step), so the filter would chatter between the
      two states.

    Args:
        A, H, Q0, R, x0, P0, order, memory, relative: as :class:`FractionalKalmanFilter`
            (``Q0`` is the base state-noise covariance, calibrate it at order 1 where
            ``eta_bar ≈ 1`` must hold, §1.5 pitfall).
        rule: "R1" or "R2".
        gain: the gain lambda > 0 (default 1.0 for R1, 4.0 for R2, §1.5).
        window: W >= 1 innovations averaged.
        g_max: upper clamp of g for R1 (>= 1).
        delta: relative tr P change threshold of R2 (> 0).

    Attributes: those of the FKF plus ``q_scale`` (g for the next prediction, (B...)),
    ``eta_bar`` (B...) and, for R2, ``steady`` (bool, (B...)).
    """

    def __init__(
        self,
        A: ArrayLike,
        H: ArrayLike,
        Q0: ArrayLike,
        R: ArrayLike,
        x0: ArrayLike | None,
        P0: ArrayLike,
        *,
        order: ArrayLike = 0.95,
        memory: int = 30,
        rule: Literal["R1", "R2"] = "R1",
        gain: float | None = None,
        window: int = 5,
        g_max: float = 100.0,
        delta: float = 0.01,
        relative: bool = True,
    ) -> None:
        if rule not in ("R1", "R2"):
            raise ValueError(f"rule: expected 'R1' or 'R2', got {rule!r}")
        self.rule = rule
        self.gain = positive("gain", (1.0 if rule == "R1" else 4.0) if gain is None else gain)
        self.window = integer("window", window, 1)
        self.g_max = in_range("g_max", g_max, 1.0, np.inf)
        self.delta = positive("delta", delta)
        super().__init__(A, H, Q0, R, x0, P0, order=order, memory=memory, relative=relative)
        self.Q0 = self.Q
        c = np.arange(1, self.window + 1)
        m = self.dim_z
        self._bounds = np.concatenate([[np.inf], chi2.ppf(0.99, m * c) / (m * c)])

    def _adapt_args(self) -> tuple[int, float, float, float, FloatArray]:
        return _RULES[self.rule], self.gain, self.g_max, self.delta, self._bounds

    def _window(self) -> int:
        return self.window

    def _initial_q_scale(self) -> float:
        return 1.0 if self.rule == "R1" else 1.0 + self.gain

    @property
    def q_scale(self) -> FloatArray:
        """g for the next prediction, ``Q = g Q0`` (dimensionless, >= 1), (B...)."""
        return self._get("q_scale", ())

    @property
    def eta_bar(self) -> FloatArray:
        """Windowed mean NIS per degree of freedom (NaN before the first update), (B...)."""
        self._need_state("eta_bar")
        return self._s["astate"][:, 4].reshape(self._batch).copy()

    @property
    def steady(self) -> NDArray[np.bool_]:
        """R2 steady-state flag after the last update, (B...) (always False for R1)."""
        self._need_state("steady")
        return (self._s["astate"][:, 5] > 0.5).reshape(self._batch)

    def _result(self, fields: dict[str, np.ndarray], q_scales: np.ndarray) -> FilterResult:
        return AdaptiveFractionalResult(**fields, q_scales=q_scales)

    def filter(self, zs: ArrayLike) -> AdaptiveFractionalResult:  # type: ignore[override]
        """As :meth:`FractionalKalmanFilter.filter`, plus the per-step ``q_scales``."""
        return cast(AdaptiveFractionalResult, super().filter(zs))
