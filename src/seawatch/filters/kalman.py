"""Linear Kalman filter, batched over any number of independent tracks.

The textbook recursion (Kalman 1960; Bar-Shalom, Li & Kirubarajan 2001 §5.2), the
estimator used by seed 003 eqs. 4–10 and the base of every other filter here:

    predict:  x⁻ = F x,              P⁻ = F P Fᵀ + Q
    update:   y  = z − H x⁻,         S  = H P⁻ Hᵀ + R,      K = P⁻ Hᵀ S⁻¹
              x  = x⁻ + K y,         P  = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ   (Joseph form)
              NIS = yᵀ S⁻¹ y

Leading axes of ``x0`` (and of the measurements given to ``filter``) are batch axes:
the same filter runs many tracks or Monte-Carlo runs at once. Units are those of the
model (e.g. metres and m/s for a CV model in metres).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import FloatArray, as_float_array, covariance, finite, matrix
from seawatch.filters import _kalman_kernels as _generic
from seawatch.filters._kernel_cache import specialised
from seawatch.filters.result import FilterResult

PARALLEL_MIN_TRACKS = 64
"""Batches of at least this many tracks are filtered on all CPU cores."""


def raise_kernel_status(status: tuple[int, int], batch_shape: tuple[int, ...], where: str) -> None:
    """Turn a kernel's ``(code, flat track index)`` into the matching exception."""
    code, index = status
    if code == _generic.OK:
        return
    label = ""
    if batch_shape:
        track = tuple(int(i) for i in np.unravel_index(index, batch_shape))
        label = f" (track {track})"
    if code == _generic.S_NOT_PD:
        raise np.linalg.LinAlgError(
            f"{where}: innovation covariance S = H P Hᵀ + R is not positive definite{label}; "
            "check R (must be positive definite) and P"
        )
    if code == _generic.Z_INF:
        raise ValueError(f"z: contains inf{label} (use NaN for a missing measurement)")
    raise FloatingPointError(f"{where}: the state estimate became non-finite{label}")


class KalmanFilter:
    """Linear Kalman filter with Joseph-form update and batch axes.

    Args:
        F: state transition matrix, (n, n).
        H: measurement matrix, (m, n).
        Q: process noise covariance, (n, n), positive semi-definite (may be singular).
        R: measurement noise covariance, (m, m), positive definite.
        x0: initial state estimate, (n,) or (B..., n) for a batch of tracks.
        P0: initial covariance, (n, n) shared or (B..., n, n) per track.

    Attributes (textbook symbols): ``x`` (B..., n), ``P`` (B..., n, n), ``F``, ``H``,
    ``Q``, ``R``; after each ``update``: ``y`` innovation (B..., m), ``S`` its covariance
    (B..., m, m), ``nis`` normalised innovation squared (B...,), NaN where the
    measurement was missing.
    """

    def __init__(
        self,
        F: ArrayLike,
        H: ArrayLike,
        Q: ArrayLike,
        R: ArrayLike,
        x0: ArrayLike,
        P0: ArrayLike,
    ) -> None:
        F = matrix("F", F)
        n = F.shape[0]
        if F.shape != (n, n):
            raise ValueError(f"F: expected a square (n, n) matrix, got shape {F.shape}")
        H = matrix("H", H, (None, n))
        m = H.shape[0]
        self._n, self._m = n, m
        self.F = F
        self.H = H
        self.Q = Q
        self.R = R
        x0 = finite("x0", as_float_array("x0", x0))
        if x0.ndim == 0 or x0.shape[-1] != n:
            raise ValueError(f"x0: expected shape (..., {n}), got {x0.shape}")
        P0 = covariance("P0", P0, n, batch=True)
        batch = np.broadcast_shapes(x0.shape[:-1], P0.shape[:-2])
        self._set_state(
            np.broadcast_to(x0, (*batch, n)).reshape(-1, n),
            np.broadcast_to(P0, (*batch, n, n)).reshape(-1, n, n),
            batch,
        )
        self._k = specialised(_generic, n, m)
        self._y: FloatArray | None = None
        self._S: FloatArray | None = None
        self._nis: FloatArray | None = None

    # ------------------------------------------------------------ model matrices
    # Assignable like FilterPy's attributes; each assignment is validated and kept as a
    # contiguous (1, r, c) stack for the kernels, so a step does no conversion work.
    @property
    def F(self) -> FloatArray:
        """State transition matrix, (n, n)."""
        return self._F3[0]

    @F.setter
    def F(self, value: ArrayLike) -> None:
        self._F3 = np.ascontiguousarray(matrix("F", value, (self._n, self._n))[None])

    @property
    def H(self) -> FloatArray:
        """Measurement matrix, (m, n)."""
        return self._H3[0]

    @H.setter
    def H(self, value: ArrayLike) -> None:
        self._H3 = np.ascontiguousarray(matrix("H", value, (self._m, self._n))[None])

    @property
    def Q(self) -> FloatArray:
        """Process noise covariance, (n, n), positive semi-definite."""
        return self._Q3[0]

    @Q.setter
    def Q(self, value: ArrayLike) -> None:
        self._Q3 = np.ascontiguousarray(covariance("Q", value, self._n)[None])

    @property
    def R(self) -> FloatArray:
        """Measurement noise covariance, (m, m), positive definite."""
        return self._R3[0]

    @R.setter
    def R(self, value: ArrayLike) -> None:
        self._R3 = np.ascontiguousarray(
            covariance("R", value, self._m, positive_definite=True)[None]
        )

    # ------------------------------------------------------------------ state
    def _set_state(self, x: FloatArray, P: FloatArray, batch: tuple[int, ...]) -> None:
        self._x = np.ascontiguousarray(x, dtype=np.float64).copy()
        self._P = np.ascontiguousarray(P, dtype=np.float64).copy()
        self._batch = tuple(batch)

    @property
    def dim_x(self) -> int:
        """State size n."""
        return self._n

    @property
    def dim_z(self) -> int:
        """Measurement size m."""
        return self._m

    @property
    def batch_shape(self) -> tuple[int, ...]:
        """Leading batch axes of the state (``()`` for a single track)."""
        return self._batch

    @property
    def x(self) -> FloatArray:
        """Current state estimate, (B..., n)."""
        return self._x.reshape(*self._batch, self.dim_x)

    @x.setter
    def x(self, value: ArrayLike) -> None:
        v = finite("x", as_float_array("x", value))
        self._x = np.ascontiguousarray(np.broadcast_to(v, self.x.shape).reshape(-1, self.dim_x))

    @property
    def P(self) -> FloatArray:
        """Current state covariance, (B..., n, n)."""
        return self._P.reshape(*self._batch, self.dim_x, self.dim_x)

    @P.setter
    def P(self, value: ArrayLike) -> None:
        v = covariance("P", value, self.dim_x, batch=True)
        self._P = np.ascontiguousarray(
            np.broadcast_to(v, self.P.shape).reshape(-1, self.dim_x, self.dim_x)
        )

    # ------------------------------------------------------------ model args
    def _stack(
        self, name: str, value: ArrayLike | None, default: FloatArray, rows: int
    ) -> FloatArray:
        """A model matrix as (1 or B, rows, n-or-m) for the kernels (default: a cached stack)."""
        if value is None:
            return default
        cols = default.shape[2]
        if name in ("Q", "R"):
            arr = covariance(name, value, rows, batch=True, positive_definite=name == "R")
        else:
            arr = finite(name, as_float_array(name, value))
            if arr.ndim < 2 or arr.shape[-2:] != (rows, cols):
                raise ValueError(f"{name}: expected shape (..., {rows}, {cols}), got {arr.shape}")
        if arr.ndim == 2:
            return np.ascontiguousarray(arr[None])
        try:
            arr = np.broadcast_to(arr, (*self._batch, rows, cols))
        except ValueError:
            raise ValueError(
                f"{name}: batch axes {arr.shape[:-2]} do not match the filter's {self._batch}"
            ) from None
        return np.ascontiguousarray(arr.reshape(-1, rows, cols))

    # ----------------------------------------------------------- per step
    def predict(self, F: ArrayLike | None = None, Q: ArrayLike | None = None) -> None:
        """Time update x⁻ = F x, P⁻ = F P Fᵀ + Q.

        ``F`` and ``Q`` override the filter's matrices for this step only; either may
        carry the batch axes (one matrix per track).
        """
        F3 = self._F3 if F is None else self._stack("F", F, self._F3, self._n)
        Q3 = self._Q3 if Q is None else self._stack("Q", Q, self._Q3, self._n)
        status = self._k.predict_batch(F3, Q3, self._x, self._P)
        if status[0]:
            raise_kernel_status(status, self._batch, "KalmanFilter.predict")

    def update(
        self, z: ArrayLike | None, R: ArrayLike | None = None, H: ArrayLike | None = None
    ) -> None:
        """Measurement update with z of shape (m,) or (B..., m).

        ``None`` or a NaN anywhere in a track's z makes that track's step predict-only
        (posterior = prior, ``y`` and ``nis`` NaN). ``R``/``H`` override for this step.
        """
        m = self._m
        B = self._x.shape[0]
        if z is None:
            zz = np.full((B, m), np.nan)
        else:
            zz = z if isinstance(z, np.ndarray) else as_float_array("z", z)
            if zz.shape != (*self._batch, m):
                if zz.ndim == 0 or zz.shape[-1] != m:
                    raise ValueError(f"z: expected shape (..., {m}), got {zz.shape}")
                try:
                    zz = np.broadcast_to(zz, (*self._batch, m))
                except ValueError:
                    raise ValueError(
                        f"z: batch axes {zz.shape[:-1]} do not match the filter's {self._batch}"
                    ) from None
            zz = np.ascontiguousarray(zz, dtype=np.float64).reshape(B, m)
        H3 = self._H3 if H is None else self._stack("H", H, self._H3, m)
        R3 = self._R3 if R is None else self._stack("R", R, self._R3, m)
        y = np.empty((B, m))
        S = np.empty((B, m, m))
        nis = np.empty(B)
        status = self._k.update_batch(H3, R3, zz, self._x, self._P, y, S, nis)
        if status[0]:
            raise_kernel_status(status, self._batch, "KalmanFilter.update")
        self._y, self._S, self._nis = y, S, nis

    @property
    def y(self) -> FloatArray | None:
        """Innovation z − H x⁻ of the last update, (B..., m); NaN where z was missing."""
        return None if self._y is None else self._y.reshape(*self._batch, self._m)

    @property
    def S(self) -> FloatArray | None:
        """Innovation covariance H P⁻ Hᵀ + R of the last update, (B..., m, m)."""
        return None if self._S is None else self._S.reshape(*self._batch, self._m, self._m)

    @property
    def nis(self) -> FloatArray | None:
        """Normalised innovation squared yᵀ S⁻¹ y of the last update, (B...,)."""
        return None if self._nis is None else self._nis.reshape(self._batch)

    # ------------------------------------------------------ whole sequence
    def filter(self, zs: ArrayLike) -> FilterResult:
        """Run predict-then-update over a whole sequence (FilterPy ``batch_filter`` order).

        Args:
            zs: measurements (T, m) for one track, or (B..., T, m); rows with NaN are
                missed measurements (predict-only steps). The filter's batch axes and
                those of ``zs`` broadcast (one initial state can start many runs).

        Returns:
            FilterResult with arrays of shape (B..., T, ...). The filter is left at the
            final state, so ``filter`` can be called again on the next chunk of a stream.
        """
        n, m = self.dim_x, self.dim_z
        zs = as_float_array("zs", zs)
        if zs.ndim < 2 or zs.shape[-1] != m:
            raise ValueError(f"zs: expected shape (T, {m}) or (..., T, {m}), got {zs.shape}")
        T = zs.shape[-2]
        try:
            batch = np.broadcast_shapes(self._batch, zs.shape[:-2])
        except ValueError:
            raise ValueError(
                f"zs: batch axes {zs.shape[:-2]} do not match the filter's {self._batch}"
            ) from None
        B = math.prod(batch)
        z3 = np.ascontiguousarray(np.broadcast_to(zs, (*batch, T, m)).reshape(B, T, m))
        x0 = np.ascontiguousarray(np.broadcast_to(self.x, (*batch, n)).reshape(B, n))
        P0 = np.ascontiguousarray(np.broadcast_to(self.P, (*batch, n, n)).reshape(B, n, n))
        xs = np.empty((B, T, n))
        Ps = np.empty((B, T, n, n))
        xps = np.empty((B, T, n))
        Pps = np.empty((B, T, n, n))
        ys = np.empty((B, T, m))
        Ss = np.empty((B, T, m, m))
        nis = np.empty((B, T))
        kernel = self._k.filter_batch_parallel if B >= PARALLEL_MIN_TRACKS else self._k.filter_batch
        status = kernel(
            self._F3, self._H3, self._Q3, self._R3, x0, P0, z3, xs, Ps, xps, Pps, ys, Ss, nis,
        )  # fmt: skip
        raise_kernel_status(status, batch, "KalmanFilter.filter")
        if T > 0:
            self._set_state(xs[:, -1], Ps[:, -1], batch)
            self._y, self._S, self._nis = ys[:, -1], Ss[:, -1], nis[:, -1]
        return FilterResult(
            states=xs.reshape(*batch, T, n),
            covariances=Ps.reshape(*batch, T, n, n),
            predicted_states=xps.reshape(*batch, T, n),
            predicted_covariances=Pps.reshape(*batch, T, n, n),
            innovations=ys.reshape(*batch, T, m),
            innovation_covariances=Ss.reshape(*batch, T, m, m),
            nis=nis.reshape(*batch, T),
        )
