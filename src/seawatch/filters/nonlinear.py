"""Extended and unscented Kalman filters for nonlinear measurement models.

Built for angle-only tracking of a vessel on the sea surface (SCENARIOS.md ``uav-sea``,
seed 000 eqs. 1–2; ALGORITHMS.md §4.1 and §7(a)): the state follows a linear NCV/NCA
model (``seawatch.models.constant_velocity`` etc.) and is observed through a nonlinear
model such as :class:`seawatch.models.angles.SeaSurfaceAngles` (azimuth, depression).

Both filters share the API of :class:`seawatch.filters.kalman.KalmanFilter`: the
textbook attributes ``x``, ``P``, ``F``, ``Q``, ``R``; ``predict(F=None, Q=None)``;
``update(z, R=None, measurement=None)``; ``y``, ``S``, ``nis`` after each update;
``filter(zs)`` returning a :class:`~seawatch.filters.result.FilterResult`. Leading axes
of ``x0`` are batch axes (independent tracks / Monte-Carlo runs); all maths is
vectorised over them with numpy. A NaN (or None) measurement makes that track's step
predict-only. Measurement components the model marks ``angular`` have their residuals
wrapped to (−π, π], so an azimuth near ±180° gives a small innovation.

Units are those of the models: metres, metres per second and radians for the sea
angles.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seawatch._validation import FloatArray, as_float_array, covariance, finite, matrix
from seawatch.filters.result import FilterResult
from seawatch.models.angles import wrap_angle

Transition = Callable[[FloatArray], FloatArray]
"""x_{k+1} = f(x_k), vectorised over leading axes: (..., n) -> (..., n)."""

MeasurementLike = Any
"""A model with ``__call__(x)`` (and ``.jacobian(x)`` for the EKF, ``.angular`` and
``.dim_z`` optional), or a pair ``(h, H_jacobian)``, or ``(h, H_jacobian, angular)``."""


def _sym(P: FloatArray) -> FloatArray:
    return 0.5 * (P + np.swapaxes(P, -1, -2))


def _mT(A: FloatArray) -> FloatArray:
    return np.swapaxes(A, -1, -2)


class _Measurement:
    """Internal adapter: h, its Jacobian (or None) and the angular mask."""

    __slots__ = ("angular", "h", "jac", "m")

    def __init__(
        self,
        h: Callable[[FloatArray], FloatArray],
        jac: Callable[[FloatArray], FloatArray] | None,
        angular: NDArray[np.bool_],
        m: int,
    ) -> None:
        self.h = h
        self.jac = jac
        self.angular = angular
        self.m = m


def _adapt_measurement(
    name: str, value: MeasurementLike, m_hint: int | None, need_jacobian: bool
) -> _Measurement:
    if isinstance(value, tuple | list):
        if len(value) not in (2, 3) or not callable(value[0]):
            raise ValueError(
                f"{name}: expected a model or a pair (h, H_jacobian[, angular]), got {value!r}"
            )
        h, jac = value[0], value[1]
        angular = value[2] if len(value) == 3 else ()
        m = None
    elif callable(value):
        h = value
        jac = getattr(value, "jacobian", None)
        angular = getattr(value, "angular", ())
        m = getattr(value, "dim_z", None)
    else:
        raise ValueError(f"{name}: expected a callable measurement model, got {value!r}")
    if jac is not None and not callable(jac):
        raise ValueError(f"{name}: the Jacobian must be callable, got {jac!r}")
    if need_jacobian and jac is None:
        raise ValueError(
            f"{name}: the EKF needs a Jacobian: pass a model with .jacobian(x) "
            "or a pair (h, H_jacobian)"
        )
    m = int(m) if m is not None else m_hint
    if m is None:
        raise ValueError(
            f"{name}: cannot tell the measurement size; give R as an (m, m) matrix "
            "or a model with a dim_z attribute"
        )
    ang = np.asarray(tuple(angular), dtype=bool)
    if ang.size == 0:
        ang = np.zeros(m, dtype=bool)
    if ang.shape != (m,):
        raise ValueError(f"{name}: 'angular' must hold {m} flags, got {ang.shape}")
    return _Measurement(h, jac, ang, m)


def _size_from(R: ArrayLike) -> int | None:
    shape = np.shape(R)
    return int(shape[-1]) if len(shape) >= 1 else None


class _NonlinearKalmanFilter:
    """Shared state handling, validation, masking and ``filter`` loop of EKF and UKF."""

    _need_jacobian = False
    _name = "filter"

    def __init__(
        self,
        F: ArrayLike | None,
        Q: ArrayLike,
        measurement: MeasurementLike,
        R: ArrayLike,
        x0: ArrayLike,
        P0: ArrayLike,
        transition: Transition | None,
        transition_jacobian: Transition | None,
    ) -> None:
        x0 = finite("x0", as_float_array("x0", x0))
        if x0.ndim == 0:
            raise ValueError(f"x0: expected shape (n,) or (..., n), got {x0.shape}")
        if transition is None:
            if F is None:
                raise ValueError("F: a transition matrix (n, n) or a transition function is needed")
            F = matrix("F", F)
            if F.shape[0] != F.shape[1]:
                raise ValueError(f"F: expected a square (n, n) matrix, got shape {F.shape}")
            n = F.shape[0]
        else:
            if not callable(transition):
                raise ValueError(f"transition: expected a callable f(x), got {transition!r}")
            if F is not None:
                raise ValueError("F: give either a transition matrix F or a transition function")
            n = x0.shape[-1]
        if x0.shape[-1] != n:
            raise ValueError(f"x0: expected shape (..., {n}), got {x0.shape}")
        self.F: FloatArray | None = F
        self.transition = transition
        self.transition_jacobian = transition_jacobian
        self.Q = covariance("Q", Q, n, batch=True)
        self._model = _adapt_measurement(
            "measurement", measurement, _size_from(R), self._need_jacobian
        )
        m = self._model.m
        self.measurement = measurement
        self.R = covariance("R", R, m, positive_definite=True, batch=True)
        P0 = covariance("P0", P0, n, batch=True)
        try:
            batch = np.broadcast_shapes(x0.shape[:-1], P0.shape[:-2])
        except ValueError:
            raise ValueError(
                f"P0: batch axes {P0.shape[:-2]} do not match those of x0 {x0.shape[:-1]}"
            ) from None
        self._x = np.broadcast_to(x0, (*batch, n)).copy()
        self._P = np.broadcast_to(P0, (*batch, n, n)).copy()
        self._fit("Q", self.Q, (n, n))
        self._fit("R", self.R, (m, m))
        self.y: FloatArray | None = None
        self.S: FloatArray | None = None
        self.nis: FloatArray | None = None

    # ------------------------------------------------------------------ state
    @property
    def dim_x(self) -> int:
        """State size n."""
        return self._x.shape[-1]

    @property
    def dim_z(self) -> int:
        """Measurement size m of the default measurement model."""
        return self._model.m

    @property
    def batch_shape(self) -> tuple[int, ...]:
        """Leading batch axes of the state (``()`` for a single track)."""
        return self._x.shape[:-1]

    @property
    def x(self) -> FloatArray:
        """Current state estimate, (B..., n)."""
        return self._x

    @x.setter
    def x(self, value: ArrayLike) -> None:
        v = finite("x", as_float_array("x", value))
        self._x = self._fit("x", v, (self.dim_x,)).copy()

    @property
    def P(self) -> FloatArray:
        """Current state covariance, (B..., n, n)."""
        return self._P

    @P.setter
    def P(self, value: ArrayLike) -> None:
        v = covariance("P", value, self.dim_x, batch=True)
        self._P = self._fit("P", v, (self.dim_x, self.dim_x)).copy()

    def _fit(self, name: str, arr: FloatArray, tail: tuple[int, ...]) -> FloatArray:
        """Broadcast *arr* to (B..., *tail) or raise ValueError naming it."""
        try:
            return np.broadcast_to(arr, (*self.batch_shape, *tail))
        except ValueError:
            raise ValueError(
                f"{name}: shape {np.shape(arr)} does not broadcast to the filter's "
                f"{(*self.batch_shape, *tail)}"
            ) from None

    # ---------------------------------------------------------------- predict
    def predict(self, F: ArrayLike | None = None, Q: ArrayLike | None = None) -> None:
        """Time update; ``F`` and ``Q`` override the filter's for this step only.

        Linear (given ``F`` or built with one): ``x⁻ = F x``, ``P⁻ = F P Fᵀ + Q``. With
        a transition function see the subclass. F may be (n, n) or (B..., n, n), Q
        (n, n) or (B..., n, n).
        """
        n = self.dim_x
        Qm = self.Q if Q is None else covariance("Q", Q, n, batch=True)
        Qm = self._fit("Q", Qm, (n, n))
        if F is not None:
            Fm = finite("F", as_float_array("F", F))
            if Fm.ndim < 2 or Fm.shape[-2:] != (n, n):
                raise ValueError(f"F: expected shape (..., {n}, {n}), got {Fm.shape}")
            self._predict_linear(self._fit("F", Fm, (n, n)), Qm)
        elif self.transition is None:
            assert self.F is not None
            self._predict_linear(self.F, Qm)
        else:
            self._predict_nonlinear(Qm)

    def _predict_linear(self, F: FloatArray, Q: FloatArray) -> None:
        self._x = np.einsum("...ij,...j->...i", F, self._x)
        self._P = _sym(F @ self._P @ _mT(F) + Q)
        self._check_finite("predict")

    def _predict_nonlinear(self, Q: FloatArray) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    def _transition_output(self, name: str, value: ArrayLike, shape: tuple[int, ...]) -> FloatArray:
        arr = as_float_array(name, value)
        try:
            return np.broadcast_to(arr, shape)
        except ValueError:
            raise ValueError(f"{name}: returned shape {arr.shape}, expected {shape}") from None

    # ----------------------------------------------------------------- update
    def update(
        self,
        z: ArrayLike | None,
        R: ArrayLike | None = None,
        measurement: MeasurementLike | None = None,
    ) -> None:
        """Measurement update with z of shape (m,) or (B..., m).

        ``None`` or a NaN anywhere in a track's z makes that track's step predict-only
        (posterior = prior, ``y`` and ``nis`` NaN, ``S`` still computed). ``R`` and
        ``measurement`` override the filter's for this step (e.g. a model seen from
        this step's observer position).
        """
        if measurement is None:
            model = self._model
        else:
            hint = _size_from(R) if R is not None else self._model.m
            model = _adapt_measurement("measurement", measurement, hint, self._need_jacobian)
        m = model.m
        if R is None:
            if m != self._model.m:
                raise ValueError(f"R: the measurement has size {m}; give a matching R ({m}, {m})")
            Rm = self.R
        else:
            Rm = covariance("R", R, m, positive_definite=True, batch=True)
        Rm = self._fit("R", Rm, (m, m))
        batch = self.batch_shape
        if z is None:
            zz = np.full((*batch, m), np.nan)
        else:
            zz = as_float_array("z", z)
            if np.any(np.isinf(zz)):
                raise ValueError("z: contains inf (use NaN for a missing measurement)")
            if zz.ndim == 0 or zz.shape[-1] != m:
                raise ValueError(f"z: expected shape (..., {m}), got {zz.shape}")
            zz = self._fit("z", zz, (m,))
        missing = np.any(np.isnan(zz), axis=-1)
        zf = np.where(missing[..., None], 0.0, zz)
        x_prior, P_prior = self._x, self._P
        x, P, y, S = self._correct(zf, model, Rm)
        nis = np.einsum("...i,...i->...", y, np.linalg.solve(S, y[..., None])[..., 0])
        if np.any(missing):
            x = np.where(missing[..., None], x_prior, x)
            P = np.where(missing[..., None, None], P_prior, P)
            y = np.where(missing[..., None], np.nan, y)
            nis = np.where(missing, np.nan, nis)
        self._x, self._P = x, P
        self.y, self.S, self.nis = y, S, np.asarray(nis, dtype=np.float64)
        self._check_finite("update")

    def _correct(
        self, z: FloatArray, model: _Measurement, R: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:  # pragma: no cover - abstract
        raise NotImplementedError

    def _measure(self, model: _Measurement, x: FloatArray, batch: tuple[int, ...]) -> FloatArray:
        """h(x) checked to have shape (*batch, m)."""
        z = as_float_array("measurement", model.h(x))
        shape = (*batch, model.m)
        try:
            return np.broadcast_to(z, shape)
        except ValueError:
            raise ValueError(
                f"measurement: h(x) returned shape {z.shape}, expected {shape}"
            ) from None

    def _wrap(self, r: FloatArray, angular: NDArray[np.bool_]) -> FloatArray:
        """Residuals with angular components wrapped to (−π, π]."""
        if not np.any(angular):
            return r
        return np.where(angular, wrap_angle(r), r)

    def _gain(self, C: FloatArray, S: FloatArray) -> FloatArray:
        """K = C S⁻¹ (C = P Hᵀ or P_xz), after checking S is positive definite."""
        try:
            np.linalg.cholesky(S)
        except np.linalg.LinAlgError:
            bad = np.argwhere(np.linalg.eigvalsh(S)[..., 0] <= 0.0)
            where = f" (track {tuple(int(i) for i in bad[0])})" if S.ndim > 2 and bad.size else ""
            raise np.linalg.LinAlgError(
                f"{type(self).__name__}.update: innovation covariance S is not positive "
                f"definite{where}; check R (must be positive definite) and P"
            ) from None
        return _mT(np.linalg.solve(S, _mT(C)))

    def _check_finite(self, where: str) -> None:
        if not (np.all(np.isfinite(self._x)) and np.all(np.isfinite(self._P))):
            raise FloatingPointError(
                f"{type(self).__name__}.{where}: the state estimate became non-finite"
            )

    # --------------------------------------------------------- whole sequence
    def filter(
        self,
        zs: ArrayLike,
        measurements: Sequence[MeasurementLike | None] | None = None,
        Rs: Sequence[ArrayLike | None] | None = None,
    ) -> FilterResult:
        """Run predict-then-update over a whole sequence (FilterPy ``batch_filter`` order).

        Args:
            zs: measurements (T, m) for one track, or (B..., T, m); rows with NaN are
                missed measurements (predict-only steps). The filter's batch axes and
                those of ``zs`` broadcast (one initial state can start many runs).
            measurements: optional length-T sequence of per-step measurement models
                (e.g. ``SeaSurfaceAngles.at(observer_k, heading_k)`` for a moving
                platform); None entries use the filter's model.
            Rs: optional length-T sequence of per-step measurement noise covariances.

        Returns:
            FilterResult with arrays of shape (B..., T, ...). The filter is left at the
            final state, so ``filter`` can be called again on the next chunk of a stream.
        """
        m = self.dim_z
        zs = as_float_array("zs", zs)
        if zs.ndim < 2 or zs.shape[-1] != m:
            raise ValueError(f"zs: expected shape (T, {m}) or (..., T, {m}), got {zs.shape}")
        if np.any(np.isinf(zs)):
            raise ValueError("zs: contains inf (use NaN for a missing measurement)")
        T = zs.shape[-2]
        for name, seq in (("measurements", measurements), ("Rs", Rs)):
            if seq is not None and len(seq) != T:
                raise ValueError(f"{name}: expected {T} entries (one per step), got {len(seq)}")
        try:
            batch = np.broadcast_shapes(self.batch_shape, zs.shape[:-2])
        except ValueError:
            raise ValueError(
                f"zs: batch axes {zs.shape[:-2]} do not match the filter's {self.batch_shape}"
            ) from None
        n = self.dim_x
        self._x = np.broadcast_to(self._x, (*batch, n)).copy()
        self._P = np.broadcast_to(self._P, (*batch, n, n)).copy()
        zs = np.broadcast_to(zs, (*batch, T, m))
        xs, Ps, xps, Pps, ys, Ss, niss = [], [], [], [], [], [], []
        for k in range(T):
            self.predict()
            xps.append(self._x)
            Pps.append(self._P)
            self.update(
                zs[..., k, :],
                R=None if Rs is None else Rs[k],
                measurement=None if measurements is None else measurements[k],
            )
            assert self.y is not None and self.S is not None and self.nis is not None
            xs.append(self._x)
            Ps.append(self._P)
            ys.append(self.y)
            Ss.append(self.S)
            niss.append(self.nis)

        def stack(seq: list[FloatArray], tail: tuple[int, ...]) -> FloatArray:
            if not seq:
                return np.empty((*batch, 0, *tail))
            return np.stack(seq, axis=len(batch))

        return FilterResult(
            states=stack(xs, (n,)),
            covariances=stack(Ps, (n, n)),
            predicted_states=stack(xps, (n,)),
            predicted_covariances=stack(Pps, (n, n)),
            innovations=stack(ys, (m,)),
            innovation_covariances=stack(Ss, (m, m)),
            nis=stack(niss, ()),
        )


class ExtendedKalmanFilter(_NonlinearKalmanFilter):
    """Extended Kalman filter with Joseph-form update and batch axes.

    Bar-Shalom, Li & Kirubarajan (2001) §10.3; measurement Jacobian of ALGORITHMS.md
    §7(a) when used with :class:`~seawatch.models.angles.SeaSurfaceAngles`:

        predict:  x⁻ = F x,  P⁻ = F P Fᵀ + Q     (or x⁻ = f(x), P⁻ = J P Jᵀ + Q with
                                                   J = df/dx at the posterior x)
        update:   H = dh/dx at x⁻,  y = wrap(z − h(x⁻)),  S = H P⁻ Hᵀ + R,
                  K = P⁻ Hᵀ S⁻¹,  x = x⁻ + K y,
                  P = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ   (Joseph form, symmetrised),
                  NIS = yᵀ S⁻¹ y

    ``wrap`` maps the components the model marks ``angular`` to (−π, π].

    Args:
        F: state transition matrix (n, n), e.g. from ``constant_velocity``; None when
            ``transition`` is given.
        Q: process noise covariance (n, n) or (B..., n, n), positive semi-definite.
        measurement: a model with ``__call__(x)`` and ``jacobian(x)`` (vectorised over
            leading axes; ``angular`` and ``dim_z`` read when present), or a pair
            ``(h, H_jacobian)`` / triple ``(h, H_jacobian, angular)``.
        R: measurement noise covariance (m, m) or (B..., m, m), positive definite
            [rad² for angles].
        x0: initial state (n,) or (B..., n).
        P0: initial covariance (n, n) or (B..., n, n).
        transition: optional nonlinear transition f(x), (..., n) -> (..., n).
        transition_jacobian: its Jacobian df/dx, (..., n) -> (..., n, n); required with
            ``transition``.

    Attributes: ``x`` (B..., n), ``P`` (B..., n, n), ``F``, ``Q``, ``R``,
    ``measurement``; after ``update``: ``y`` (B..., m), ``S`` (B..., m, m), ``nis``
    (B...), NaN where the measurement was missing.
    """

    _need_jacobian = True

    def __init__(
        self,
        F: ArrayLike | None,
        Q: ArrayLike,
        measurement: MeasurementLike,
        R: ArrayLike,
        x0: ArrayLike,
        P0: ArrayLike,
        *,
        transition: Transition | None = None,
        transition_jacobian: Transition | None = None,
    ) -> None:
        if transition is not None and not callable(transition_jacobian):
            raise ValueError(
                "transition_jacobian: the EKF needs the Jacobian df/dx of the transition"
            )
        super().__init__(F, Q, measurement, R, x0, P0, transition, transition_jacobian)

    def _predict_nonlinear(self, Q: FloatArray) -> None:
        assert self.transition is not None and self.transition_jacobian is not None
        n = self.dim_x
        batch = self.batch_shape
        J = self._transition_output(
            "transition_jacobian", self.transition_jacobian(self._x), (*batch, n, n)
        )
        x = self._transition_output("transition", self.transition(self._x), (*batch, n))
        self._x = np.array(x)
        self._P = _sym(J @ self._P @ _mT(J) + Q)
        self._check_finite("predict")

    def _correct(
        self, z: FloatArray, model: _Measurement, R: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        x, P = self._x, self._P
        batch = self.batch_shape
        assert model.jac is not None
        H = as_float_array("measurement jacobian", model.jac(x))
        try:
            H = np.broadcast_to(H, (*batch, model.m, self.dim_x))
        except ValueError:
            raise ValueError(
                f"measurement: jacobian(x) returned shape {H.shape}, "
                f"expected {(*batch, model.m, self.dim_x)}"
            ) from None
        zhat = self._measure(model, x, batch)
        PHt = P @ _mT(H)
        S = _sym(H @ PHt + R)
        K = self._gain(PHt, S)
        y = self._wrap(z - zhat, model.angular)
        x_new = x + np.einsum("...ij,...j->...i", K, y)
        A = np.eye(self.dim_x) - K @ H
        P_new = _sym(A @ P @ _mT(A) + K @ R @ _mT(K))
        return x_new, P_new, y, S


class UnscentedKalmanFilter(_NonlinearKalmanFilter):
    """Unscented Kalman filter with Van der Merwe's scaled sigma points and batch axes.

    Wan & van der Merwe (2000), additive-noise UKF; Julier (2002) scaled unscented
    transform. With n states, ``λ = α² (n + κ) − n``:

        sigma points  χ₀ = x,  χ_i = x ± [√((n + λ) P)]_i   (Cholesky columns, i = 1..n)
        weights       W₀ᵐ = λ/(n+λ),  W₀ᶜ = W₀ᵐ + 1 − α² + β,  Wᵢᵐ = Wᵢᶜ = 1/(2(n+λ))
        predict       linear F: x⁻ = F x, P⁻ = F P Fᵀ + Q (what the unscented transform
                      of a linear map gives exactly); transition f: x⁻ = Σ Wᵐ f(χ),
                      P⁻ = Σ Wᶜ (f(χ) − x⁻)(f(χ) − x⁻)ᵀ + Q
        update        sigma points redrawn from (x⁻, P⁻) (so that they carry Q; FilterPy
                      does the same), Z = h(χ),
                      ẑ = Σ Wᵐ Z  — for angular components the circular mean
                           atan2(Σ Wᵐ sin Z, Σ Wᵐ cos Z),
                      S = Σ Wᶜ wrap(Z − ẑ) wrap(Z − ẑ)ᵀ + R,
                      P_xz = Σ Wᶜ (χ − x⁻) wrap(Z − ẑ)ᵀ,  K = P_xz S⁻¹,
                      x = x⁻ + K wrap(z − ẑ),  P = P⁻ − K S Kᵀ (symmetrised),
                      NIS = yᵀ S⁻¹ y

    Defaults α = 1, β = 2, κ = 0 (not the α = 10⁻³ often quoted): then λ = 0 and all
    weights are non-negative (W₀ᵐ = 0, W₀ᶜ = 2, Wᵢ = 1/(2n)), so S and P⁻ are sums of
    positive semi-definite terms plus R or Q and stay positive definite, and the sigma
    points sit √n standard deviations out, probing the depression-to-range
    nonlinearity over the actual uncertainty (at 1 km from a 10 m camera, the range σ
    is ~5 % of the range). With α = 10⁻³, W₀ᵐ ≈ W₀ᶜ ≈ −10⁶: the mean and covariances
    are differences of numbers a million times larger than the result, which loses
    about six digits and can make S indefinite once angles wrap or P becomes small.

    Args:
        F_or_transition: transition matrix (n, n) (linear predict, e.g. from
            ``constant_velocity``) or a function f(x) vectorised over leading axes,
            (..., n) -> (..., n) (it receives sigma points of shape (2n+1, B..., n)).
        Q: process noise covariance (n, n) or (B..., n, n).
        measurement: a model with ``__call__(x)`` vectorised over leading axes
            (``angular`` and ``dim_z`` read when present; ``jacobian`` unused), or a
            pair ``(h, H_jacobian)`` / triple ``(h, H_jacobian, angular)``. Array-valued
            model settings (e.g. per-run observer positions (B..., 2)) broadcast against
            the sigma points (2n+1, B..., n).
        R: measurement noise covariance (m, m) or (B..., m, m), positive definite.
        x0: initial state (n,) or (B..., n).
        P0: initial covariance (n, n) or (B..., n, n), positive definite.
        alpha: spread of the sigma points α > 0.
        beta: prior-knowledge parameter β (2 is optimal for Gaussians).
        kappa: secondary scaling κ, with n + κ > 0.

    Attributes as :class:`ExtendedKalmanFilter`, plus ``Wm``, ``Wc`` (2n+1,) weights.
    Raises ``numpy.linalg.LinAlgError`` naming the track if P is not positive definite
    when sigma points are drawn.
    """

    def __init__(
        self,
        F_or_transition: ArrayLike | Transition,
        Q: ArrayLike,
        measurement: MeasurementLike,
        R: ArrayLike,
        x0: ArrayLike,
        P0: ArrayLike,
        *,
        alpha: float = 1.0,
        beta: float = 2.0,
        kappa: float = 0.0,
    ) -> None:
        if callable(F_or_transition):
            super().__init__(None, Q, measurement, R, x0, P0, F_or_transition, None)
        else:
            super().__init__(F_or_transition, Q, measurement, R, x0, P0, None, None)
        n = self.dim_x
        for name, v in (("alpha", alpha), ("beta", beta), ("kappa", kappa)):
            try:
                ok = np.isfinite(float(v))
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise ValueError(f"{name}: expected a finite number, got {v!r}")
        if not float(alpha) > 0.0:
            raise ValueError(f"alpha: expected alpha > 0, got {alpha!r}")
        if not n + float(kappa) > 0.0:
            raise ValueError(f"kappa: expected n + kappa > 0 (n = {n}), got {kappa!r}")
        self.alpha, self.beta, self.kappa = float(alpha), float(beta), float(kappa)
        lam = self.alpha**2 * (n + self.kappa) - n
        self._c = n + lam
        self.Wm = np.full(2 * n + 1, 0.5 / self._c)
        self.Wc = self.Wm.copy()
        self.Wm[0] = lam / self._c
        self.Wc[0] = lam / self._c + 1.0 - self.alpha**2 + self.beta

    def sigma_points(self, x: ArrayLike | None = None, P: ArrayLike | None = None) -> FloatArray:
        """Scaled sigma points of (x, P) (default: the current estimate), (2n+1, B..., n)."""
        x = self._x if x is None else np.asarray(x, dtype=np.float64)
        P = self._P if P is None else np.asarray(P, dtype=np.float64)
        try:
            L = np.linalg.cholesky(self._c * P)
        except np.linalg.LinAlgError:
            eig = np.linalg.eigvalsh(P)[..., 0]
            bad = np.argwhere(~(eig > 0.0))
            where = f" (track {tuple(int(i) for i in bad[0])})" if P.ndim > 2 and bad.size else ""
            raise np.linalg.LinAlgError(
                f"{type(self).__name__}: state covariance P is not positive definite{where} "
                f"(smallest eigenvalue {float(np.min(eig)):.3g}); the Cholesky factor for the "
                "sigma points does not exist"
            ) from None
        cols = np.moveaxis(L, -1, 0)  # cols[i] = i-th column of L, (n, B..., n)
        return np.concatenate([x[None], x + cols, x - cols], axis=0)

    def _predict_nonlinear(self, Q: FloatArray) -> None:
        assert self.transition is not None
        chi = self.sigma_points()
        shape = chi.shape
        chi_f = self._transition_output("transition", self.transition(chi), shape)
        x = np.einsum("k,k...i->...i", self.Wm, chi_f)
        d = chi_f - x
        P = np.einsum("k,k...i,k...j->...ij", self.Wc, d, d) + Q
        self._x = x
        self._P = _sym(P)
        self._check_finite("predict")

    def _correct(
        self, z: FloatArray, model: _Measurement, R: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        x, P = self._x, self._P
        chi = self.sigma_points()
        Z = self._measure(model, chi, chi.shape[:-1])
        zhat = np.einsum("k,k...i->...i", self.Wm, Z)
        if np.any(model.angular):
            s = np.einsum("k,k...i->...i", self.Wm, np.sin(Z))
            c = np.einsum("k,k...i->...i", self.Wm, np.cos(Z))
            zhat = np.where(model.angular, np.arctan2(s, c), zhat)
        dZ = self._wrap(Z - zhat, model.angular)
        dX = chi - x
        S = _sym(np.einsum("k,k...i,k...j->...ij", self.Wc, dZ, dZ) + R)
        Pxz = np.einsum("k,k...i,k...j->...ij", self.Wc, dX, dZ)
        K = self._gain(Pxz, S)
        y = self._wrap(z - zhat, model.angular)
        x_new = x + np.einsum("...ij,...j->...i", K, y)
        P_new = _sym(P - K @ S @ _mT(K))
        return x_new, P_new, y, S
