"""Range filters with adaptive process noise: ANCV and ANCA (ALGORITHMS.md §5, seed 002).

A scalar range ``d`` measured from the image size of a target of known extent (§5.1,
seed 002 eq. 14) is filtered with a nearly-constant-velocity (NCV, state ``[d, ḋ]``,
seed 002 eqs. 7–11) or nearly-constant-acceleration (NCA, state ``[d, ḋ, d̈]``, seed 002
eqs. 17–21) model. The measurement noise depends on the range itself,

    σ_d = d² σ_l / (f L),        R_k = σ_d(d_k)²                     (§5.1, seed 002 eqs. 14–15)

and the process noise level σ_v is either fixed (the paper's NCV/NCA) or re-estimated
every step from a sliding window of the filter's own estimates (the paper's ANCV/ANCA,
seed 002 eqs. 16, 23–25, in the dimensionally sound form of ALGORITHMS.md §5.3):

    ANCV:  σ_v² = clip( (1/W) Σ_{i=k-W+1..k} ((v̂_i − v̂_{i-1}) / T)²,  σ_min², σ_max² )
    ANCA:  σ_v² = clip( (1/W) Σ_{i=k-W+1..k} (â_i − â_{i-1})²,        σ_min², σ_max² )

Until the window holds W increments the filter runs with the starting value (seed 002:
σ_v² = 1 for ANCV, 10⁻⁴ for ANCA, "after the first value of asr is computed a new
variance is introduced"). The recursion itself is :class:`seawatch.filters.kalman.
KalmanFilter`, driven step by step with per-track ``Q`` and ``R`` overrides, so leading
batch axes (many tracks or Monte-Carlo runs) are supported throughout.

Choices made here (documented because the spec leaves them open):

* **R at the predicted range** (default ``noise_range="predicted"``). Evaluating
  ``R_k`` at the *measured* range correlates the weight with the noise: a measurement
  that happens to be short gets a smaller R and a larger gain, which biases the estimate
  towards short ranges (measured in the ``air-range`` scenario, 400 runs, NCV σ_v =
  10 m/s², level flight: mean error −1.9 m with the measured range against −0.5 m with
  the predicted one). The prediction ``d_{k|k-1}`` does not depend on the current
  noise. ``"measured"`` is kept as an option.
* **ANCA statistic from the filtered acceleration** (default ``source="state"``): the
  NCA state holds â, and seed 002 eq. 23 averages ``a_kal(k) − a_kal(k−1)``. For a
  consistent filter in steady state ``E[(â_k − â_{k-1})²] = (P⁻ − P)_aa = σ_v²``, so the
  statistic has the true σ_v as its fixed point (covariance matching). ALGORITHMS.md
  §5.3 writes â from velocity differences, ``â_i = (v̂_i − v̂_{i-1})/T``; that form is
  available as ``source="velocity"``. Differencing velocity updates adds their noise
  twice and in the ``air-range`` scenario pins σ_v at its cap. For ANCV both sources
  are the same (velocity is the state's highest derivative).
* **Floors and caps** (defaults, [NEW] guards): ``σ_min = σ_start / 10``;
  ``σ_max = 10 g`` for NCV (range acceleration of a hard-manoeuvring aircraft) and
  ``σ_max = 10 g/s · T`` for NCA (acceleration change per frame at a 10 g/s onset).

Behaviour to know: when the measurement noise dominates the innovations (far targets),
the window statistic hardly tells one σ_v from another (its fixed point is only weakly
attracting), so σ_v stays near wherever the first full window put it. After a diffuse
start that first window contains the convergence of the velocity estimate and lifts
σ_v high (ANCV to its cap); it then follows large manoeuvres but does not come back
down for gentle ones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seawatch._validation import FloatArray, as_float_array, integer, positive
from seawatch.filters.kalman import KalmanFilter
from seawatch.filters.result import FilterResult
from seawatch.models.kinematic import (
    constant_acceleration,
    constant_velocity,
    position_measurement,
)

RangeModel = Literal["ncv", "nca"]
StatisticSource = Literal["state", "velocity"]
NoiseRange = Literal["predicted", "measured"]

STANDARD_GRAVITY = 9.80665
"""g [m/s²]; the default caps of σ_v are expressed in g."""

DEFAULT_SIGMA = {"ncv": 1.0, "nca": 0.01}
"""Starting σ_v [m/s²] of ANCV (σ_v² = 1) and ANCA (σ_v² = 10⁻⁴), seed 002 / SCENARIOS.md."""

_MIN_R = 1e-12  # [m²] keeps R positive definite if a predicted range collapses to 0


def size_range_std(range_m: ArrayLike, sigma_l: float, size: float, focal: float) -> FloatArray:
    """Standard deviation of a range measured from an image size (ALGORITHMS.md §5.1).

    ``σ_d = d² σ_l / (f L)`` (seed 002 eq. 14), the first-order propagation of the size
    error σ_l through ``d = f L / l``.

    Args:
        range_m: range d [m], any shape.
        sigma_l: image-size measurement error σ_l [px].
        size: true target extent L perpendicular to the line of sight [m].
        focal: focal length f [px].

    Returns:
        σ_d [m], same shape as ``range_m``.
    """
    d = as_float_array("range_m", range_m)
    return d * d * (float(sigma_l) / (float(focal) * float(size)))


def adaptation_statistic(
    samples: ArrayLike,
    dt: float,
    *,
    model: RangeModel = "ncv",
    window: int = 50,
    source: StatisticSource = "state",
) -> FloatArray:
    """Windowed mean squared increment that sets σ_v² (ALGORITHMS.md §5.3, seed 002 eqs. 16, 23).

    * ``model="ncv"``: ``samples`` are filtered velocities v̂ [m/s];
      returns ``(1/W) Σ ((v̂_i − v̂_{i-1})/T)²`` [m²/s⁴] (mean squared acceleration).
    * ``model="nca", source="state"``: ``samples`` are filtered accelerations â [m/s²];
      returns ``(1/W) Σ (â_i − â_{i-1})²`` [m²/s⁴] (mean squared change of acceleration
      per interval, ``= (jerk_rms · T)²``).
    * ``model="nca", source="velocity"``: ``samples`` are filtered velocities;
      ``â_i = (v̂_i − v̂_{i-1})/T`` first, then as above.

    Entry k averages the W increments ending at sample k; it is NaN where fewer than W
    increments exist (k < W, or k < W + 1 for the velocity form of NCA).

    Args:
        samples: (..., T) series, time on the last axis.
        dt: sampling interval T [s].
        model: "ncv" or "nca".
        window: W, number of increments averaged (≥ 1).
        source: "state" or "velocity" (see above; irrelevant for NCV).

    Returns:
        (..., T) array of the statistic.
    """
    model = _check_model(model)
    source = _check_source(source)
    T = positive("dt", dt)
    W = _check_window(window)
    s = as_float_array("samples", samples)
    if s.ndim == 0:
        raise ValueError("samples: expected an array with time on the last axis, got a scalar")
    if model == "ncv":
        u = s / T
    elif source == "state":
        u = s
    else:
        u = np.diff(s, axis=-1) / T
    inc2 = np.diff(u, axis=-1) ** 2
    lead = s.shape[-1] - inc2.shape[-1]  # samples before the first increment
    out = np.full(s.shape, np.nan)
    if inc2.shape[-1] >= W:
        c = np.cumsum(inc2, axis=-1)
        c = np.concatenate([np.zeros((*c.shape[:-1], 1)), c], axis=-1)
        out[..., lead + W - 1 :] = (c[..., W:] - c[..., :-W]) / W
    return out


@dataclass(frozen=True)
class AdaptiveRangeResult(FilterResult):
    """:class:`FilterResult` of a range filter plus its noise histories.

    The state is ``[d, ḋ]`` [m, m/s] (NCV) or ``[d, ḋ, d̈]`` [m, m/s, m/s²] (NCA);
    the measurement is the range d [m] (m = 1).

    Attributes:
        sigma_v: σ_v used in the prediction of each step [m/s²], shape (B..., T).
        statistic: the windowed adaptation statistic after each step's update
            (:func:`adaptation_statistic`, unclipped) [m²/s⁴], NaN until the window is
            full; computed for fixed-noise filters too (the paper's "asr" plots).
        measurement_variances: R_k used in each update [m²], shape (B..., T).
    """

    sigma_v: NDArray[np.float64]
    statistic: NDArray[np.float64]
    measurement_variances: NDArray[np.float64]


class AdaptiveRangeFilter:
    """NCV/NCA range filter with fixed or windowed-adaptive process noise (ANCV/ANCA).

    ALGORITHMS.md §5.1–§5.3; seed 002 eqs. 9–11 (NCV), 19–21 (NCA), 14–15 (R), 16 and
    23–25 (adaptation). Fixed-noise NCV/NCA are the same code with ``adaptive=False``,
    so comparisons are like for like.

    Args:
        model: "ncv" (state [d, ḋ]) or "nca" (state [d, ḋ, d̈]).
        dt: frame period T [s].
        x0: initial state, (n,) or (B..., n) for a batch of tracks [m, m/s(, m/s²)].
        P0: initial covariance, (n, n) or (B..., n, n).
        R: fixed measurement variance [m²] — or give ``sigma_l``, ``size`` and ``focal``
            for the range-dependent ``R_k = (d² σ_l/(f L))²``.
        sigma_l: image-size error σ_l [px].
        size: target extent L [m].
        focal: focal length f [px].
        noise_range: range at which R_k is evaluated: "predicted" (``d_{k|k-1}``,
            default) or "measured" (``z_k``).
        adaptive: adapt σ_v (ANCV/ANCA) or keep it fixed (NCV/NCA).
        sigma: starting σ_v when adaptive, the fixed σ_v otherwise [m/s²]; NCV: std of
            the acceleration over one interval; NCA: std of the acceleration change over
            one interval. Default 1.0 (NCV) / 0.01 (NCA).
        window: W, number of increments averaged by the adaptation (default 50).
        sigma_min: floor of σ_v [m/s²] (default ``sigma / 10``).
        sigma_max: cap of σ_v [m/s²] (default 10 g for NCV, 10 g/s · T for NCA, or
            ``sigma`` if that is larger).
        source: "state" or "velocity", the series the ANCA statistic differences (see
            the module docstring); ignored for NCV.

    Attributes: ``x`` (B..., n), ``P`` (B..., n, n), ``sigma_v`` (B...,) the σ_v the
    next prediction uses, ``R`` (B...,) the last measurement variance, ``y``, ``S``,
    ``nis`` of the last update, ``F``, ``H``, ``kf`` the underlying
    :class:`KalmanFilter`.
    """

    def __init__(
        self,
        model: RangeModel,
        dt: float,
        x0: ArrayLike,
        P0: ArrayLike,
        *,
        R: float | None = None,
        sigma_l: float | None = None,
        size: float | None = None,
        focal: float | None = None,
        noise_range: NoiseRange = "predicted",
        adaptive: bool = True,
        sigma: float | None = None,
        window: int = 50,
        sigma_min: float | None = None,
        sigma_max: float | None = None,
        source: StatisticSource = "state",
    ) -> None:
        self.model: RangeModel = _check_model(model)
        self.dt = positive("dt", dt)
        self.adaptive = bool(adaptive)
        self.window = _check_window(window)
        self.source: StatisticSource = _check_source(source)
        if noise_range not in ("predicted", "measured"):
            raise ValueError(
                f"noise_range: expected 'predicted' or 'measured', got {noise_range!r}"
            )
        self.noise_range: NoiseRange = noise_range

        # measurement noise: fixed R or the size-based range-dependent one (§5.1)
        size_args = {"sigma_l": sigma_l, "size": size, "focal": focal}
        if R is not None:
            given = [k for k, v in size_args.items() if v is not None]
            if given:
                raise ValueError(f"R: give either R or sigma_l/size/focal, not both (got {given})")
            self.fixed_R: float | None = positive("R", R)
            self._r_scale = 0.0
        else:
            for name, value in size_args.items():
                if value is None:
                    raise ValueError(
                        f"{name}: required when R is not given (R_k = (d² σ_l/(f L))²)"
                    )
            self.fixed_R = None
            self.sigma_l = positive("sigma_l", sigma_l)  # type: ignore[arg-type]
            self.size = positive("size", size)  # type: ignore[arg-type]
            self.focal = positive("focal", focal)  # type: ignore[arg-type]
            self._r_scale = self.sigma_l / (self.focal * self.size)  # σ_d = d² · scale

        # process noise level and its guards
        s0 = (
            DEFAULT_SIGMA[self.model]
            if sigma is None
            else positive("sigma", sigma, allow_zero=True)
        )
        if self.adaptive:
            cap = 10.0 * STANDARD_GRAVITY * (1.0 if self.model == "ncv" else self.dt)
            lo = s0 / 10.0 if sigma_min is None else positive("sigma_min", sigma_min)
            hi = max(cap, s0) if sigma_max is None else positive("sigma_max", sigma_max)
            if lo > hi:
                raise ValueError(f"sigma_min: {lo} exceeds sigma_max {hi}")
            if not lo <= s0 <= hi:
                raise ValueError(
                    f"sigma: starting value {s0} outside [sigma_min, sigma_max] = [{lo}, {hi}]"
                )
            self.sigma_min, self.sigma_max = lo, hi
        else:
            self.sigma_min = self.sigma_max = s0
        self.sigma = s0

        if self.model == "ncv":
            self.F, self._Qu = constant_velocity(1, self.dt, 1.0)
            self.H = position_measurement(1, 2)
        else:
            self.F, self._Qu = constant_acceleration(1, self.dt, 1.0)
            self.H = position_measurement(1, 3)
        self.kf = KalmanFilter(self.F, self.H, s0 * s0 * self._Qu, 1.0, x0, P0)
        self._init_tracks()

    # ------------------------------------------------------------------ state
    def _init_tracks(self) -> None:
        B = math.prod(self.kf.batch_shape)
        self._s2 = np.full(B, self.sigma * self.sigma)
        self._buf = np.zeros((B, self.window))  # ring buffer of squared increments
        self._count = np.zeros(B, dtype=np.int64)  # increments collected
        self._seen = np.zeros(B, dtype=np.int64)  # measured samples seen
        self._prev_v = np.zeros(B)
        self._prev_u = np.zeros(B)
        self._R = np.full(B, np.nan)
        self._stat = np.full(B, np.nan)
        self._prior: tuple[FloatArray, FloatArray] | None = None

    def _broadcast_to(self, batch: tuple[int, ...]) -> None:
        """Grow a filter that has not run yet to more batch axes (one x0 for many runs)."""
        if batch == self.kf.batch_shape:
            return
        n = self.F.shape[0]
        x = np.broadcast_to(self.kf.x, (*batch, n))
        P = np.broadcast_to(self.kf.P, (*batch, n, n))
        if np.any(self._seen) or not np.all(self._s2 == self._s2[0]):
            raise ValueError(
                f"zs: batch axes {batch} do not match the filter's {self.kf.batch_shape}"
            )
        self.kf = KalmanFilter(self.F, self.H, self.kf.Q, 1.0, x, P)
        self._init_tracks()

    @property
    def batch_shape(self) -> tuple[int, ...]:
        """Leading batch axes of the state (``()`` for one track)."""
        return self.kf.batch_shape

    @property
    def x(self) -> FloatArray:
        """Current state estimate (B..., n) [m, m/s(, m/s²)]."""
        return self.kf.x

    @property
    def P(self) -> FloatArray:
        """Current state covariance (B..., n, n)."""
        return self.kf.P

    @property
    def sigma_v(self) -> FloatArray:
        """σ_v [m/s²] the next prediction will use, shape (B...,)."""
        return np.sqrt(self._s2).reshape(self.batch_shape)

    @property
    def R(self) -> FloatArray:
        """Measurement variance [m²] of the last update, shape (B...,)."""
        return self._R.reshape(self.batch_shape)

    @property
    def statistic(self) -> FloatArray:
        """Windowed adaptation statistic after the last update [m²/s⁴] (NaN until full)."""
        return self._stat.reshape(self.batch_shape)

    @property
    def y(self) -> FloatArray | None:
        """Innovation of the last update (B..., 1) [m]."""
        return self.kf.y

    @property
    def S(self) -> FloatArray | None:
        """Innovation covariance of the last update (B..., 1, 1) [m²]."""
        return self.kf.S

    @property
    def nis(self) -> FloatArray | None:
        """Normalised innovation squared of the last update (B...,)."""
        return self.kf.nis

    # ------------------------------------------------------------ per step
    def measurement_variance(self, range_m: ArrayLike) -> FloatArray:
        """R = σ_d(d)² [m²] at the given range (§5.1, seed 002 eq. 15), or the fixed R."""
        d = as_float_array("range_m", range_m)
        if self.fixed_R is not None:
            return np.full(d.shape, self.fixed_R)
        sd = d * d * self._r_scale
        return np.maximum(sd * sd, _MIN_R)

    def step(self, z: ArrayLike | None) -> None:
        """One frame: predict with the current σ_v, update with range z, adapt σ_v.

        Args:
            z: measured range [m], scalar or (B...,); NaN or None → predict-only step
                (no update, no adaptation for that track).
        """
        B = self._s2.shape[0]
        batch = self.batch_shape
        if z is None:
            zf = np.full(B, np.nan)
        else:
            za = as_float_array("z", z)
            try:
                zf = np.broadcast_to(za, batch).reshape(B)
            except ValueError:
                raise ValueError(
                    f"z: expected a scalar or shape {batch} (one range per track), got {za.shape}"
                ) from None
            if np.any(np.isinf(zf)):
                raise ValueError("z: contains inf (use NaN for a missing measurement)")
        self._step(zf)

    def _step(self, zf: FloatArray) -> None:
        """:meth:`step` on a flat (B,) measurement vector (NaN = missing)."""
        B = self._s2.shape[0]
        batch = self.batch_shape
        n = self.F.shape[0]
        Q = self._s2[:, None, None] * self._Qu
        self.kf.predict(Q=Q.reshape(*batch, n, n))
        self._prior = (self.kf.x.reshape(B, n).copy(), self.kf.P.reshape(B, n, n).copy())
        measured = np.isfinite(zf)
        d_pred = self.kf.x.reshape(B, n)[:, 0]
        d_ref = np.where(measured, zf, d_pred) if self.noise_range == "measured" else d_pred
        R = self.measurement_variance(d_ref)
        self.kf.update(zf.reshape(*batch, 1), R=R.reshape(*batch, 1, 1))
        self._R = R
        self._adapt(measured)

    def _adapt(self, measured: NDArray[np.bool_]) -> None:
        """Push the new increment of each measured track and re-estimate σ_v² (§5.3)."""
        n = self.F.shape[0]
        x = self.kf.x.reshape(-1, n)
        idx = np.flatnonzero(measured)
        if idx.size == 0:
            return
        v = x[idx, 1]
        seen = self._seen[idx]
        # u: the series whose squared increments are averaged (§5.3); the velocity form
        # of NCA needs one earlier sample to form u and two to form an increment
        if self.model == "ncv":
            u, lag = v / self.dt, 0
        elif self.source == "state":
            u, lag = x[idx, 2], 0
        else:
            u, lag = (v - self._prev_v[idx]) / self.dt, 1
        have_u = seen >= lag
        have_inc = seen >= lag + 1
        inc2 = (u - self._prev_u[idx]) ** 2
        j = idx[have_inc]
        self._buf[j, self._count[j] % self.window] = inc2[have_inc]
        self._count[j] += 1
        self._prev_v[idx] = v
        self._prev_u[idx] = np.where(have_u, u, self._prev_u[idx])
        self._seen[idx] += 1
        full = idx[self._count[idx] >= self.window]
        if full.size:
            stat = self._buf[full].mean(axis=1)
            self._stat[full] = stat
            if self.adaptive:
                self._s2[full] = np.clip(stat, self.sigma_min**2, self.sigma_max**2)

    # ------------------------------------------------------ whole sequence
    def filter(self, zs: ArrayLike) -> AdaptiveRangeResult:
        """Run :meth:`step` over a sequence of ranges.

        Args:
            zs: measured ranges [m], (T,) for the filter's batch or (B..., T); NaN
                entries are missed measurements (predict-only steps). A filter that has
                not run yet and holds one track broadcasts to the batch axes of ``zs``.

        Returns:
            AdaptiveRangeResult with arrays (B..., T, ...). The filter is left at the
            final state, so ``filter`` can be called again on the next chunk.
        """
        zs = as_float_array("zs", zs)
        if zs.ndim == 0:
            raise ValueError("zs: expected shape (T,) or (..., T), got a scalar")
        if np.any(np.isinf(zs)):
            raise ValueError("zs: contains inf (use NaN for a missing measurement)")
        T = zs.shape[-1]
        try:
            batch = np.broadcast_shapes(self.batch_shape, zs.shape[:-1])
        except ValueError:
            raise ValueError(
                f"zs: batch axes {zs.shape[:-1]} do not match the filter's {self.batch_shape}"
            ) from None
        self._broadcast_to(batch)
        B = self._s2.shape[0]
        n = self.F.shape[0]
        z2 = np.broadcast_to(zs, (*batch, T)).reshape(B, T)
        xs = np.empty((B, T, n))
        Ps = np.empty((B, T, n, n))
        xps = np.empty((B, T, n))
        Pps = np.empty((B, T, n, n))
        ys = np.empty((B, T, 1))
        Ss = np.empty((B, T, 1, 1))
        nis = np.empty((B, T))
        sig = np.empty((B, T))
        stat = np.empty((B, T))
        Rs = np.empty((B, T))
        for k in range(T):
            sig[:, k] = np.sqrt(self._s2)
            self._step(np.ascontiguousarray(z2[:, k]))
            xps[:, k], Pps[:, k] = self._prior
            xs[:, k] = self.kf.x.reshape(B, n)
            Ps[:, k] = self.kf.P.reshape(B, n, n)
            ys[:, k] = self.kf.y.reshape(B, 1)  # type: ignore[union-attr]
            Ss[:, k] = self.kf.S.reshape(B, 1, 1)  # type: ignore[union-attr]
            nis[:, k] = self.kf.nis.reshape(B)  # type: ignore[union-attr]
            stat[:, k] = self._stat
            Rs[:, k] = self._R

        def shape(a: FloatArray, *tail: int) -> FloatArray:
            return a.reshape(*batch, T, *tail)

        return AdaptiveRangeResult(
            states=shape(xs, n),
            covariances=shape(Ps, n, n),
            predicted_states=shape(xps, n),
            predicted_covariances=shape(Pps, n, n),
            innovations=shape(ys, 1),
            innovation_covariances=shape(Ss, 1, 1),
            nis=shape(nis),
            sigma_v=shape(sig),
            statistic=shape(stat),
            measurement_variances=shape(Rs),
        )


# ---------------------------------------------------------------- checks
def _check_model(model: str) -> RangeModel:
    if model not in ("ncv", "nca"):
        raise ValueError(f"model: expected 'ncv' or 'nca', got {model!r}")
    return model  # type: ignore[return-value]


def _check_source(source: str) -> StatisticSource:
    if source not in ("state", "velocity"):
        raise ValueError(f"source: expected 'state' or 'velocity', got {source!r}")
    return source  # type: ignore[return-value]


def _check_window(window: int) -> int:
    return integer("window", window, 1)
