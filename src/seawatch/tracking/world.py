"""World-frame estimation of many ship tracks from camera angles, online (issue 7).

A bank of estimators, fed frame by frame with each visual track's measured **azimuth**
(clockwise from North, world frame) and **depression** (below the true horizontal) of
its water-line point, that turns them into North/East positions [m] in the camera's
local tangent plane, a 2×2 position covariance [m²], speed [m/s], course [rad clockwise
from North, in [0, 2π)], range [m] and its 1-σ [m], and forecast positions at fixed
horizons (default +10 s and +30 s). Four estimators (INTERFACES.md names), all run on
the same measurements:

``geometry`` — seed 000 algorithm 1: point-wise position from each frame's angles,
    seed 000 eqs. 3–5 with the exact curved-sea range of ALGORITHMS.md §4.2 (flat §4.1
    with ``curved=False``): ``p = p_o + D(β) (cos α, sin α)``. Covariance to first
    order, ``G Σ_angles Gᵀ + σ_p² I`` with ``G = ∂p/∂(α, β) = [D (−sin α, cos α),
    D'(β) (cos α, sin α)]`` (the same as :func:`seawatch.geometry.sea_position_covariance`
    for a diagonal Σ) and σ_p the platform's position error. Velocity: least-squares
    slope of the track's point-wise positions over the last ``velocity_window`` seconds
    (the straight-line fit; exact for a straight track); forecast ``p + v τ``.
``diffuse-rls`` — seed 000 algorithm 2 (ALGORITHMS.md §3): each track's azimuth and
    depression series is smoothed by the diffuse RLS of :class:`seawatch.filters.
    DiffuseRLS` (AR(5), λ = 1, diffuse start, ``filtered="fitted"``; see "AR model"
    below), and the smoothed angles go through the geometry above. Forecasts are the AR
    model's multi-step prediction of both angles (seed eq. 20, ``DiffuseRLS.forecast``)
    turned into positions from the platform's extrapolated position ``p_o + v_o τ``
    (:class:`PlatformPose` velocity; zero for a shore camera); while the AR model is
    not yet of full rank, or if either AR forecast is unstable (where ``DiffuseRLS``
    would fall back to a noisy constant-rate extrapolation of the angles), the
    straight-line extrapolation ``p + v τ`` of the smoothed positions is used instead.
    Velocity: the least-squares slope of the smoothed positions over
    ``velocity_window``. The covariance is the geometry's first-order covariance at the
    smoothed angles with the *measurement* angle covariance: an upper bound (the
    smoothing reduces the angle noise by an amount the AR model does not quantify). No
    forecast covariance (NaN). The per-track AR states live in arrays of the bank and
    are advanced, all tracks in one compiled call, by ``DiffuseRLS``'s own compiled
    step and forecast kernels (20 ``DiffuseRLS.update``/``forecast`` calls per frame
    cost ~1 ms for 10 tracks); the tests check the result against ``DiffuseRLS``
    objects fed the same series.
``ekf`` / ``ukf`` — extended / unscented Kalman filters with the world-frame state
    ``x = [north, east, v_north, v_east]`` [m, m/s], nearly-constant-velocity model with
    continuous white-noise acceleration (ALGORITHMS.md §5.2, ``constant_velocity(2, dt,
    sigma_a, noise="continuous")``) over each track's own, variable, ``dt`` since its
    last update, and the measurement model
    :class:`seawatch.models.SeaSurfaceAngles` (seed 000 eqs. 1–2, curved sea §4.2) seen
    from the platform's position: ``z = h(x − p_o)``. The equations are those of
    :class:`seawatch.filters.ExtendedKalmanFilter` (Joseph form) and
    :class:`seawatch.filters.UnscentedKalmanFilter` (α = 1, β = 2, κ = 0; circular mean
    of the angles), compiled with numba over all the tracks of a frame: the same maths
    batched in numpy costs 0.8–1.1 ms of CPU per frame and filter for 10 tracks, the
    classes themselves more (their per-call argument checks). The tests check both
    kernels against the classes step by step. Forecast at +τ: ``x(τ) = F(τ) x``,
    ``P(τ) = F(τ) P F(τ)ᵀ + Q(τ)``.

AR model (``ar_increments``): seed 000 fits AR(5) models of the angle *levels* without
intercept. At 25 fps that model forecasts badly: a smooth angle series makes the lagged
levels nearly collinear, about half of the azimuth forecasts are unstable, and 250 AR
steps (10 s) miss the true azimuth by ~29 mrad RMS. Modelling the *increments* with an
intercept (ALGORITHMS.md §3.1 [NEW] variant; the intercept is the mean angle rate) keeps
every forecast stable, cuts the 10-s azimuth/depression forecast errors to 6.1/0.49 mrad
(from 29/10.5) and smooths the angles as well (RMS error 0.44σ/0.42σ against
0.49σ/0.46σ for the levels). Default ``ar_increments=True``; ``False`` is the seed's
exact form. (40 straight ships at 0.5–3 km, 40 s at 25 fps, 1-px noise, seed 2.)

Why CWNA and not the DWNA of ``solent-ais``: the interval between updates varies
(missed frames), and only the continuous model composes over arbitrary intervals
(``Q(2T) = F(T) Q(T) F(T)ᵀ + Q(T)``) — it is also independent of the frame rate. Its
``sigma_a`` [m/s^1.5] = √q is the velocity random walk (velocity σ grows by sigma_a per
√s); at 1 Hz it matches the DWNA σ_a = 0.1 m/s² of ``solent-ais`` to first order.

Platform (moving camera): a :class:`PlatformPose` per frame gives the camera's position
(North, East) in the reference tangent plane, its height and the 1-σ horizontal error of
that position. All estimators compute from the given position; the EKF/UKF add its
error to the measurement noise through the Jacobian, ``R + J σ_p² I Jᵀ`` with ``J =
∂h/∂(north, east)`` (exact to first order for an error independent from frame to frame).
Shore camera: ``platform=None`` (position 0, the tracker's height, no error).

Horizon: a depression at or above the horizon dip (:func:`seawatch.geometry.horizon_dip`,
0 on a flat sea) has no point-wise range: ``geometry`` (and ``diffuse-rls`` when the
*smoothed* depression is above it) gives NaN position, covariance, range and forecast
there (its velocity still comes from the earlier positions in the window) — never an
exception. The EKF/UKF of a track start only from
a measurement at least ``init_margin`` σ_β below the horizon (and at a point-wise range
≤ ``max_range``): position from the geometry with its first-order covariance, velocity
0 ± ``sigma_velocity`` per axis. Until then their outputs are NaN. Once started, a frame
whose measured depression is at or above the dip is used as an **azimuth-only** update
(the exact scalar EKF/UKF update with the azimuth row); any other frame is a full update.

Robust update (``robust_gate``, off by default): detectors make gross errors a Gaussian
model does not foresee — two ships merged into one box, a box on the superstructure —
and one such water line moves a range by tens of percent. With a gate probability p,
an EKF/UKF innovation whose NIS ν exceeds the χ² quantile g(p) (1 degree of freedom for
an azimuth-only update, 2 otherwise) is used with the measurement noise inflated to
``R + (ν/g − 1) S`` (so ``S' = (ν/g) S``): its correction is scaled by g/ν, a gross
error is all but ignored, and the covariance update stays the exact one for the
inflated noise (the state's σ still grows by the process noise, so a real manoeuvre
is followed once the prediction's uncertainty covers it). The NIS reported is the raw ν.

Missing measurements: a track id absent from a frame is not touched (its next update
predicts over the longer interval). NaN in either angle of a listed track is a
predict-only step for the EKF/UKF (its outputs are the prediction), a missing sample
for the diffuse RLS, and NaN for ``geometry``.

Gaps in the diffuse RLS: the AR model assumes uniformly spaced samples at the frame
interval T (``frame_interval``, or else the shortest interval seen between two
``update`` calls). A track updated after ``dt`` gets ``round(dt / T) − 1`` missing
samples (NaN: the RLS's predict-only step, see ``DiffuseRLS.update``) before the new
one; a gap longer than ``max_gap`` seconds restarts both AR models from the diffuse start
instead. Missing samples count as a gap too: the first measurement after more than
``max_gap`` seconds of NaN angles restarts the AR models (a track that coasts through an
occlusion would otherwise carry a long run of AR predictions — from a model that may
have seen only a few samples — in its regressors for ever: on the demo clip the large
vessel's diffuse-RLS positions were NaN for 244 of its 283 frames after a 2.7-s
occlusion). A shorter run of missing samples can do the same when the model has not
yet reached full rank: its predictions run off (tens of degrees), and λ = 1 keeps them
in the fit. So a track whose smoothed angle lies more than :data:`RLS_RESTART_SIGMA`
(10) measurement σ from the measured one restarts its AR models on that sample (on the
demo clip, session 22's host: the far vessel coasted 0.9 s from its 13th frame, and
its diffuse-RLS positions were NaN in 262 of its 297 frames; now 7 of the clip's 755
matched track-frames have none). Forecast steps: ``round(τ / T)`` AR steps for a
horizon τ [s].

Units: SI and radians throughout; the tangent plane is that of the camera's reference
point (x North, y East), on which distances are read as arc distances along the sea
(ALGORITHMS.md §4.2, exact to far below the measurement error for D ≪ R).

Measurements (``tests/tracking/test_world.py``; 40 straight ships at 0.5–3 km, 3–10 m/s,
30 s at 25 fps, 10 m camera, 1-px angle noise σ = 0.0305°, errors after 5 s). Position
RMSE [m] by true range, and as a fraction of ``geometry``'s:

==============  ======  ======  =========  =========  =========  =======
shore camera    all     < 1 km  1–1.5 km   1.5–2 km   2–2.5 km   > 2.5 km
==============  ======  ======  =========  =========  =========  =======
geometry        325.5   37.4    83.1       186.3      291.8      553.5
diffuse-rls     0.38    0.42    0.42       0.41       0.39       0.37
ekf             0.06    0.09    0.08       0.08       0.07       0.06
ukf             0.06    0.09    0.08       0.08       0.07       0.06
==============  ======  ======  =========  =========  =========  =======

Range error at 1 km (RMS): geometry 5.5 %, diffuse-rls 2.3 %, EKF/UKF 0.46 %. Speed
RMSE: geometry 16.9 m/s, diffuse-rls 14.4 m/s, EKF/UKF 1.7 m/s. From a boat at 5 m/s
with a 1-m NAV error the ratios are 0.37 (diffuse-rls) and 0.09 (EKF/UKF) overall, at
most 0.43 and 0.12 in any range bin, and the EKF range error at 1 km is 0.50 %. The
EKF's position NEES is χ²-consistent over 100 Monte-Carlo runs (straight ships with
``sigma_a = 0`` and ships that accelerate as the CWNA model says), and so are its
+10 s/+30 s forecasts; 40 s runs give forecast RMSEs of 45/115 m (EKF), 279/989 m
(diffuse-rls) and 409/660 m (geometry). Per frame, 10 tracks, CPU time on this
project's 2-core machine: EKF 0.17 ms, UKF 0.18 ms, geometry 0.08 ms, diffuse-rls
0.46 ms (its 750-step AR forecasts), all four 0.5–1.0 ms; the first call compiles
the kernels (~10 s, cached on disk by numba).

``best`` defaults to ``"ekf"``: the EKF and UKF are equally accurate (position RMSE
within 1 % of each other in every range bin, the same NEES), 8–16 times more accurate
than point-wise geometry and 3–6 times more than the diffuse RLS in every range bin,
and the EKF is the cheaper and simpler of the two.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray
from scipy.stats import chi2

from seawatch._validation import FloatArray, as_float_array, covariance, in_range, integer, positive
from seawatch.filters.diffuse_rls import DiffuseRLS, DiffuseRLSBank
from seawatch.geometry.sea import DEFAULT_REFRACTION, EARTH_RADIUS
from seawatch.models.angles import wrap_angle

__all__ = [
    "ESTIMATORS",
    "PlatformPose",
    "WorldEstimates",
    "WorldTracker",
]

ESTIMATORS = ("geometry", "diffuse-rls", "ekf", "ukf")
"""INTERFACES.md estimator names, in table order."""

SIGMA_ANGLE = math.radians(0.0305)
"""Default 1-σ angle noise per axis [rad]: about one pixel of a 1920-px image over a 60°
horizontal field of view (60°/1920 px = 0.031°)."""

SIGMA_A = 0.1
"""Default CWNA process noise √q of the EKF/UKF [m/s^1.5] (see module docstring)."""

SIGMA_VELOCITY = 10.0
"""Default initial velocity 1-σ of the EKF/UKF per axis [m/s]."""

RLS_RESTART_SIGMA = 10.0
"""The diffuse RLS restarts a track's AR models where a smoothed angle is further than
this many measurement σ from the measured one (module docstring, "Gaps in the diffuse
RLS")."""

AR_ORDER = 5
"""Default AR order of the diffuse RLS (seed 000's scenario: n = m = 5)."""

VELOCITY_CAPACITY = 256
"""Most samples per track kept for the velocity slope of ``geometry``/``diffuse-rls``."""

_TWO_PI = 2.0 * math.pi


# ==========================================================================================
# public data types
# ==========================================================================================


@dataclass(frozen=True)
class PlatformPose:
    """Where the camera is at one frame (moving platform; ALGORITHMS.md §4.1 observer).

    Attributes:
        north, east: camera position in the reference tangent plane [m].
        height: camera height above the sea [m], > 0; None: the tracker's height.
        sigma_position: 1-σ horizontal error of (north, east) per axis [m], >= 0 (NAV
            error, independent from frame to frame).
        velocity_north, velocity_east: platform velocity [m/s]; used only to place the
            ``diffuse-rls`` forecasts (the platform's position at +τ).
    """

    north: float = 0.0
    east: float = 0.0
    height: float | None = None
    sigma_position: float = 0.0
    velocity_north: float = 0.0
    velocity_east: float = 0.0

    def __post_init__(self) -> None:
        for name in ("north", "east", "velocity_north", "velocity_east"):
            v = getattr(self, name)
            try:
                ok = math.isfinite(float(v))
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise ValueError(f"{name}: expected a finite number [m or m/s], got {v!r}")
            object.__setattr__(self, name, float(v))
        if self.height is not None:
            object.__setattr__(self, "height", positive("height", self.height))
        sp = positive("sigma_position", self.sigma_position, allow_zero=True)
        object.__setattr__(self, "sigma_position", sp)


@dataclass(frozen=True)
class WorldEstimates:
    """The k tracks updated at one time by one estimator (module docstring).

    NaN where the estimator has no value (above the horizon, before a filter starts,
    too few samples for a velocity, no model for a forecast covariance).

    Attributes:
        time: the frame time [s].
        track_id: (k,) int64, in the order given to :meth:`WorldTracker.update`.
        north, east: (k,) position in the tangent plane [m].
        covariance: (k, 2, 2) covariance of (north, east) [m²].
        speed: (k,) speed over ground [m/s].
        course: (k,) course over ground, clockwise from North, in [0, 2π) [rad].
        range: (k,) horizontal distance from the camera [m].
        sigma_range: (k,) 1-σ of the range [m].
        forecasts: {τ: (k, 2)} forecast (north, east) at time + τ [m], τ in seconds.
        forecast_covariances: {τ: (k, 2, 2)} their covariance [m²] (EKF/UKF; NaN for the
            other estimators).
        nis: (k,) normalised innovation squared of this frame's update (EKF/UKF; NaN
            for a predict-only or starting step and for the other estimators).
    """

    time: float
    track_id: NDArray[np.int64]
    north: FloatArray
    east: FloatArray
    covariance: FloatArray
    speed: FloatArray
    course: FloatArray
    range: FloatArray
    sigma_range: FloatArray
    forecasts: dict[float, FloatArray]
    forecast_covariances: dict[float, FloatArray]
    nis: FloatArray

    @property
    def position(self) -> FloatArray:
        """(k, 2) (north, east) [m]."""
        return np.stack([self.north, self.east], axis=-1)


# ==========================================================================================
# compiled kernels
# ==========================================================================================


@njit(cache=True)
def _wrap(a: float) -> float:
    """Wrap an angle [rad] to (−π, π]."""
    return math.pi - ((math.pi - a) % _TWO_PI)


@njit(cache=True)
def _depression(rho: float, h: float, Re: float, curved: bool) -> tuple[float, float]:
    """Depression β(ρ) [rad] and dβ/dρ [rad/m] (``SeaSurfaceAngles``, ALGORITHMS.md §4.2)."""
    if not curved:
        return math.atan2(h, rho), -h / (rho * rho + h * h)
    phi = rho / Re
    u = Re * math.sin(phi)
    s = math.sin(0.5 * phi)
    v = h + 2.0 * Re * s * s
    return math.atan2(v, u), (u * math.sin(phi) - v * math.cos(phi)) / (u * u + v * v)


@njit(cache=True)
def _range(b: float, h: float, Re: float, curved: bool) -> tuple[float, float]:
    """Point-wise range D(β) [m] and dD/dβ [m/rad] (ALGORITHMS.md §4.1/§4.2, the ray–sphere
    range of :func:`seawatch.geometry.curved_sea_range`); NaN at or above the horizon, for
    NaN input or beyond the nadir."""
    if not (b > 0.0) or b > 0.5 * math.pi:
        return np.nan, np.nan
    if not curved:
        d = h / math.tan(b)
        return d, -(d * d + h * h) / h
    C = Re + h
    c = 2.0 * Re * h + h * h
    if b <= math.atan(math.sqrt(c) / Re):  # at or above the horizon dip
        return np.nan, np.nan
    sb = math.sin(b)
    disc = (C * sb) ** 2 - c
    if disc <= 0.0:
        return np.nan, np.nan
    s = c / (C * sb + math.sqrt(disc))  # slant range, without cancellation
    d = Re * math.atan2(s * math.cos(b), C - s * sb)
    _, db = _depression(d, h, Re, True)
    if db == 0.0:
        return np.nan, np.nan
    return d, 1.0 / db


@njit(cache=True)
def _pointwise(
    az: FloatArray,
    dep: FloatArray,
    Sigma: FloatArray,
    h: float,
    on: float,
    oe: float,
    sp2: float,
    Re: float,
    curved: bool,
    pos: FloatArray,
    cov: FloatArray,
    D: FloatArray,
    sig_r: FloatArray,
) -> None:
    """Point-wise positions, first-order covariances, ranges and range σ of k measurements.

    Seed 000 eqs. 3–5 / ALGORITHMS.md §4.2: ``p = p_o + D(β) (cos α, sin α)``;
    ``Cov = G Σ Gᵀ + σ_p² I`` with ``G = [D (−sin α, cos α), D'(β) (cos α, sin α)]``
    (columns: azimuth, depression); ``σ_D = |D'(β)| σ_β``. NaN rows where D is NaN.
    """
    for i in range(az.shape[0]):
        d, dd = _range(dep[i], h, Re, curved)
        a = az[i]
        if not math.isfinite(a):
            d = np.nan
            dd = np.nan
        c = math.cos(a)
        s = math.sin(a)
        pos[i, 0] = on + d * c
        pos[i, 1] = oe + d * s
        g00 = -d * s
        g10 = d * c
        g01 = dd * c
        g11 = dd * s
        S = Sigma[i]
        # G Σ Gᵀ
        t00 = g00 * S[0, 0] + g01 * S[1, 0]
        t01 = g00 * S[0, 1] + g01 * S[1, 1]
        t10 = g10 * S[0, 0] + g11 * S[1, 0]
        t11 = g10 * S[0, 1] + g11 * S[1, 1]
        cov[i, 0, 0] = t00 * g00 + t01 * g01 + sp2
        cov[i, 0, 1] = t00 * g10 + t01 * g11
        cov[i, 1, 0] = t10 * g00 + t11 * g01
        cov[i, 1, 1] = t10 * g10 + t11 * g11 + sp2
        D[i] = d
        sig_r[i] = abs(dd) * math.sqrt(S[1, 1])


@njit(cache=True)
def _push_and_slope(
    slots: NDArray[np.int64],
    t: float,
    pos: FloatArray,
    Tb: FloatArray,
    Pb: FloatArray,
    count: NDArray[np.int64],
    head: NDArray[np.int64],
    window: float,
    vel: FloatArray,
) -> None:
    """Append each finite position to its track's ring buffer; velocity = least-squares
    slope of the positions within ``window`` seconds of t (NaN with < 2 samples)."""
    C = Tb.shape[1]
    for i in range(slots.shape[0]):
        s = slots[i]
        if math.isfinite(pos[i, 0]) and math.isfinite(pos[i, 1]):
            hd = head[s]
            Tb[s, hd] = t
            Pb[s, hd, 0] = pos[i, 0]
            Pb[s, hd, 1] = pos[i, 1]
            head[s] = (hd + 1) % C
            count[s] = min(count[s] + 1, C)
        vel[i, 0] = np.nan
        vel[i, 1] = np.nan
        n = 0
        st = 0.0
        s0 = 0.0
        s1 = 0.0
        for j in range(count[s]):
            k = (head[s] - 1 - j) % C
            tj = Tb[s, k] - t
            if tj < -window - 1e-9:  # inclusive, whatever the rounding of the times
                break
            n += 1
            st += tj
            s0 += Pb[s, k, 0]
            s1 += Pb[s, k, 1]
        if n < 2:
            continue
        tm = st / n
        m0 = s0 / n
        m1 = s1 / n
        stt = 0.0
        c0 = 0.0
        c1 = 0.0
        for j in range(n):
            k = (head[s] - 1 - j) % C
            d = Tb[s, k] - t - tm
            stt += d * d
            c0 += d * (Pb[s, k, 0] - m0)
            c1 += d * (Pb[s, k, 1] - m1)
        if stt > 0.0:
            vel[i, 0] = c0 / stt
            vel[i, 1] = c1 / stt


# ==========================================================================================
# EKF / UKF kernels (compiled; the maths of seawatch.filters.nonlinear, state size 4)
# ==========================================================================================


@njit(cache=True)
def _predict(x: FloatArray, P: FloatArray, dt: float, q: float) -> None:
    """``x = F x``, ``P = F P Fᵀ + Q`` of the 2-D NCV model with CWNA, in place
    (``constant_velocity(2, dt, √q, noise="continuous")``, ALGORITHMS.md §5.2)."""
    x[0] += dt * x[2]
    x[1] += dt * x[3]
    for j in range(4):  # F P: rows 0, 1 gain dt × rows 2, 3
        P[0, j] += dt * P[2, j]
        P[1, j] += dt * P[3, j]
    for i in range(4):  # (F P) Fᵀ: columns 0, 1 gain dt × columns 2, 3
        P[i, 0] += dt * P[i, 2]
        P[i, 1] += dt * P[i, 3]
    q3 = q * dt**3 / 3.0
    q2 = q * dt**2 / 2.0
    P[0, 0] += q3
    P[1, 1] += q3
    P[0, 2] += q2
    P[2, 0] += q2
    P[1, 3] += q2
    P[3, 1] += q2
    P[2, 2] += q * dt
    P[3, 3] += q * dt


@njit(cache=True)
def _measure(
    x: FloatArray, on: float, oe: float, h: float, Re: float, curved: bool, H: FloatArray
) -> tuple[float, float]:
    """(azimuth, depression) [rad] of state x seen from (on, oe), and H = ∂z/∂x (2, 4)
    into ``H``: ``SeaSurfaceAngles`` with heading 0 (seed 000 eqs. 1–2, §7(a))."""
    dn = x[0] - on
    de = x[1] - oe
    rho = max(math.hypot(dn, de), 1e-9)
    beta, db = _depression(rho, h, Re, curved)
    H[0, 0] = -de / (rho * rho)
    H[0, 1] = dn / (rho * rho)
    H[1, 0] = db * dn / rho
    H[1, 1] = db * de / rho
    H[0, 2] = H[0, 3] = H[1, 2] = H[1, 3] = 0.0
    return _wrap(math.atan2(de, dn)), beta


@njit(cache=True)
def _noise(Sigma: FloatArray, H: FloatArray, sp2: float, az_only: bool, R: FloatArray) -> None:
    """``R = Σ + σ_p² J Jᵀ`` with J = H[:, :2] (platform position error). Azimuth-only:
    depression row/column of the identity (with a zero depression innovation and
    Jacobian row, the 2-D update is then exactly the scalar azimuth update)."""
    for a in range(2):
        for b in range(2):
            R[a, b] = Sigma[a, b] + sp2 * (H[a, 0] * H[b, 0] + H[a, 1] * H[b, 1])
    if az_only:
        R[0, 1] = R[1, 0] = 0.0
        R[1, 1] = 1.0


@njit(cache=True)
def _correct(
    x: FloatArray,
    P: FloatArray,
    C: FloatArray,
    S: FloatArray,
    y: FloatArray,
    joseph: bool,
    H: FloatArray,
    R: FloatArray,
    K: FloatArray,
    A: FloatArray,
    gate: float,
) -> float:
    """``K = C S⁻¹``, ``x += K y`` and the covariance update: Joseph form ``A P Aᵀ + K R Kᵀ``
    (A = I − K H, EKF) or ``P − K S Kᵀ`` (UKF); returns NIS ``ν = yᵀ S⁻¹ y``, NaN (state
    unchanged) if S is not positive definite.

    Robust update (``gate`` finite; module docstring): an innovation with ``ν > gate``
    is used with the measurement noise inflated to ``R' = R + (α − 1) S``, ``α = ν /
    gate``, so that ``S' = α S`` (the update's own NIS equals the gate) and the
    correction is scaled by 1/α. R and S are modified in place; the NIS returned is the
    raw ``ν``."""
    s01 = 0.5 * (S[0, 1] + S[1, 0])
    det = S[0, 0] * S[1, 1] - s01 * s01
    if not (S[0, 0] > 0.0 and det > 0.0):
        return np.nan
    i00 = S[1, 1] / det
    i11 = S[0, 0] / det
    i01 = -s01 / det
    nis = y[0] * (i00 * y[0] + i01 * y[1]) + y[1] * (i01 * y[0] + i11 * y[1])
    if nis > gate:
        alpha = nis / gate
        for a in range(2):
            for b in range(2):
                R[a, b] += (alpha - 1.0) * S[a, b]
                S[a, b] *= alpha
        i00 /= alpha
        i11 /= alpha
        i01 /= alpha
    for i in range(4):
        K[i, 0] = C[i, 0] * i00 + C[i, 1] * i01
        K[i, 1] = C[i, 0] * i01 + C[i, 1] * i11
        x[i] += K[i, 0] * y[0] + K[i, 1] * y[1]
    if joseph:
        for i in range(4):
            for j in range(4):
                A[i, j] = (1.0 if i == j else 0.0) - K[i, 0] * H[0, j] - K[i, 1] * H[1, j]
        AP = np.zeros((4, 4))
        for i in range(4):
            for j in range(4):
                for m in range(4):
                    AP[i, j] += A[i, m] * P[m, j]
        for i in range(4):
            for j in range(4):
                acc = 0.0
                for m in range(4):
                    acc += AP[i, m] * A[j, m]
                for a in range(2):
                    for b in range(2):
                        acc += K[i, a] * R[a, b] * K[j, b]
                P[i, j] = acc
    else:
        for i in range(4):
            for j in range(4):
                acc = 0.0
                for a in range(2):
                    for b in range(2):
                        acc += K[i, a] * S[a, b] * K[j, b]
                P[i, j] -= acc
    for i in range(4):
        for j in range(i + 1, 4):
            v = 0.5 * (P[i, j] + P[j, i])
            P[i, j] = v
            P[j, i] = v
    return nis


@njit(cache=True)
def _ekf_bank(
    slots: NDArray[np.int64],
    X: FloatArray,
    P: FloatArray,
    dt: FloatArray,
    q: float,
    z: FloatArray,
    Sigma: FloatArray,
    on: float,
    oe: float,
    h: float,
    sp2: float,
    Re: float,
    curved: bool,
    dip: float,
    nis: FloatArray,
    gate1: float,
    gate2: float,
) -> int:
    """Predict over dt[i], then EKF-update (``ExtendedKalmanFilter``: y = wrap(z − h(x⁻)),
    S = H P Hᵀ + R, Joseph form) each listed track's slot in place. NaN z: predict only.
    Returns the index of the first track whose S is not positive definite, else −1."""
    H = np.zeros((2, 4))
    R = np.zeros((2, 2))
    C = np.zeros((4, 2))
    S = np.zeros((2, 2))
    K = np.zeros((4, 2))
    A = np.zeros((4, 4))
    y = np.zeros(2)
    for i in range(slots.shape[0]):
        x = X[slots[i]]
        Pi = P[slots[i]]
        if dt[i] > 0.0:
            _predict(x, Pi, dt[i], q)
        nis[i] = np.nan
        if not (math.isfinite(z[i, 0]) and math.isfinite(z[i, 1])):
            continue
        az_only = not z[i, 1] > dip
        zh0, zh1 = _measure(x, on, oe, h, Re, curved, H)
        _noise(Sigma[i], H, sp2, az_only, R)
        y[0] = _wrap(z[i, 0] - zh0)
        y[1] = _wrap(z[i, 1] - zh1)
        if az_only:
            y[1] = 0.0
            H[1, :] = 0.0
        for r in range(4):
            for a in range(2):
                C[r, a] = Pi[r, 0] * H[a, 0] + Pi[r, 1] * H[a, 1]
        for a in range(2):
            for b in range(2):
                S[a, b] = R[a, b] + H[a, 0] * C[0, b] + H[a, 1] * C[1, b]
        v = _correct(x, Pi, C, S, y, True, H, R, K, A, gate1 if az_only else gate2)
        if not math.isfinite(v):
            return i
        nis[i] = v
    return -1


@njit(cache=True)
def _ukf_bank(
    slots: NDArray[np.int64],
    X: FloatArray,
    P: FloatArray,
    dt: FloatArray,
    q: float,
    z: FloatArray,
    Sigma: FloatArray,
    on: float,
    oe: float,
    h: float,
    sp2: float,
    Re: float,
    curved: bool,
    dip: float,
    nis: FloatArray,
    gate1: float,
    gate2: float,
) -> int:
    """Predict over dt[i], then UKF-update (``UnscentedKalmanFilter`` with α = 1, β = 2,
    κ = 0 for n = 4: χ = x, x ± columns of chol(4 P⁻); weights Wᵐ = (0, 1/8, …),
    Wᶜ = (2, 1/8, …); circular mean of the angles; P = P⁻ − K S Kᵀ) in place. NaN z:
    predict only. Returns the index of the first track whose P⁻ or S is not positive
    definite, else −1."""
    H = np.zeros((2, 4))
    Hs = np.zeros((2, 4))
    R = np.zeros((2, 2))
    C = np.zeros((4, 2))
    S = np.zeros((2, 2))
    K = np.zeros((4, 2))
    A = np.zeros((4, 4))
    L = np.zeros((4, 4))
    chi = np.zeros((9, 4))
    Z = np.zeros((9, 2))
    y = np.zeros(2)
    wi = 1.0 / 8.0
    for i in range(slots.shape[0]):
        x = X[slots[i]]
        Pi = P[slots[i]]
        if dt[i] > 0.0:
            _predict(x, Pi, dt[i], q)
        nis[i] = np.nan
        if not (math.isfinite(z[i, 0]) and math.isfinite(z[i, 1])):
            continue
        az_only = not z[i, 1] > dip
        _measure(x, on, oe, h, Re, curved, H)
        _noise(Sigma[i], H, sp2, az_only, R)
        for j in range(4):  # Cholesky factor of 4 P⁻
            acc = 4.0 * Pi[j, j]
            for m in range(j):
                acc -= L[j, m] * L[j, m]
            if not acc > 0.0:
                return i
            L[j, j] = math.sqrt(acc)
            for r in range(j + 1, 4):
                t = 4.0 * Pi[r, j]
                for m in range(j):
                    t -= L[r, m] * L[j, m]
                L[r, j] = t / L[j, j]
        for r in range(4):
            chi[0, r] = x[r]
            for j in range(4):
                lv = L[r, j] if r >= j else 0.0
                chi[1 + j, r] = x[r] + lv
                chi[5 + j, r] = x[r] - lv
        for k in range(9):
            Z[k, 0], Z[k, 1] = _measure(chi[k], on, oe, h, Re, curved, Hs)
        zh = np.zeros(2)
        for a in range(2):  # circular mean (W₀ᵐ = 0)
            sn = 0.0
            cs = 0.0
            for k in range(1, 9):
                sn += wi * math.sin(Z[k, a])
                cs += wi * math.cos(Z[k, a])
            zh[a] = math.atan2(sn, cs)
        S[:] = 0.0
        C[:] = 0.0
        for k in range(9):
            wk = 2.0 if k == 0 else wi
            d0 = _wrap(Z[k, 0] - zh[0])
            d1 = 0.0 if az_only else _wrap(Z[k, 1] - zh[1])
            S[0, 0] += wk * d0 * d0
            S[0, 1] += wk * d0 * d1
            S[1, 1] += wk * d1 * d1
            for r in range(4):
                dx = chi[k, r] - x[r]
                C[r, 0] += wk * dx * d0
                C[r, 1] += wk * dx * d1
        S[1, 0] = S[0, 1]
        for a in range(2):
            for b in range(2):
                S[a, b] += R[a, b]
        y[0] = _wrap(z[i, 0] - zh[0])
        y[1] = 0.0 if az_only else _wrap(z[i, 1] - zh[1])
        v = _correct(x, Pi, C, S, y, False, H, R, K, A, gate1 if az_only else gate2)
        if not math.isfinite(v):
            return i
        nis[i] = v
    return -1


@njit(cache=True)
def _outputs(
    slots: NDArray[np.int64],
    ready: NDArray[np.bool_],
    X: FloatArray,
    P: FloatArray,
    on: float,
    oe: float,
    q: float,
    horizons: FloatArray,
    pos: FloatArray,
    cov: FloatArray,
    vel: FloatArray,
    rng: FloatArray,
    sig_r: FloatArray,
    fc: FloatArray,
    fcov: FloatArray,
) -> None:
    """EKF/UKF outputs of k tracks: position, its covariance, velocity, range from the
    camera and its σ along the line of sight u (``√(uᵀ P_pp u)``), and the forecasts
    ``F(τ) x`` with position covariance ``P_pp + τ (P_pv + P_vp) + τ² P_vv + q τ³/3 I``
    (the position block of ``F(τ) P F(τ)ᵀ + Q(τ)``). NaN rows where not started."""
    for i in range(slots.shape[0]):
        if not ready[i]:
            pos[i] = np.nan
            cov[i] = np.nan
            vel[i] = np.nan
            rng[i] = np.nan
            sig_r[i] = np.nan
            fc[i] = np.nan
            fcov[i] = np.nan
            continue
        x = X[slots[i]]
        Pm = P[slots[i]]
        for a in range(2):
            pos[i, a] = x[a]
            vel[i, a] = x[2 + a]
            for b in range(2):
                cov[i, a, b] = Pm[a, b]
        dn = x[0] - on
        de = x[1] - oe
        r = math.hypot(dn, de)
        rng[i] = r
        if r > 0.0:
            un = dn / r
            ue = de / r
            var = un * un * Pm[0, 0] + 2.0 * un * ue * Pm[0, 1] + ue * ue * Pm[1, 1]
            sig_r[i] = math.sqrt(max(var, 0.0))
        else:
            sig_r[i] = math.sqrt(max(Pm[0, 0], Pm[1, 1]))
        for j in range(horizons.shape[0]):
            tau = horizons[j]
            for a in range(2):
                fc[i, j, a] = x[a] + tau * x[2 + a]
                for b in range(2):
                    fcov[i, j, a, b] = (
                        Pm[a, b]
                        + tau * (Pm[2 + a, b] + Pm[a, 2 + b])
                        + tau * tau * Pm[2 + a, 2 + b]
                    )
                fcov[i, j, a, a] += q * tau**3 / 3.0


# ==========================================================================================
# helpers
# ==========================================================================================


def _course(vn: FloatArray, ve: FloatArray) -> FloatArray:
    """Course clockwise from North in [0, 2π) [rad] (NaN where the velocity is NaN)."""
    return np.mod(np.arctan2(ve, vn), _TWO_PI)


def _flag(name: str, value: object) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise ValueError(f"{name}: expected True or False, got {value!r}")
    return bool(value)


@dataclass(frozen=True)
class _Fix:
    """Point-wise positions of k measurements (``_pointwise``)."""

    pos: FloatArray  # (k, 2) [m]
    cov: FloatArray  # (k, 2, 2) [m²]
    D: FloatArray  # (k,) range [m]
    sigma_range: FloatArray  # (k,) [m]


# ==========================================================================================
# the tracker
# ==========================================================================================


class WorldTracker:
    """Online bank of world-frame estimators for many ship tracks (module docstring).

    ALGORITHMS.md §3 (diffuse RLS, seed 000 eqs. 14–16, 20), §4.1–§4.2 (sea geometry,
    seed 000 eqs. 3–5), §5.2 (CWNA model) and seed 000 eqs. 1–2 (angle measurement model
    of the EKF/UKF).

    Args:
        height: camera height above the sea [m], > 0 (a :class:`PlatformPose` may
            override it per frame).
        sigma_angle: default 1-σ noise of each angle [rad], > 0, used when ``update`` gets
            no ``angle_covariance``.
        sigma_a: CWNA process noise √q of the EKF/UKF [m/s^1.5], >= 0.
        sigma_velocity: initial velocity 1-σ of the EKF/UKF per axis [m/s], > 0.
        curved: curved sea with refraction (ALGORITHMS.md §4.2) instead of flat (§4.1).
        refraction: terrestrial refraction coefficient k in [0, 1).
        horizons: forecast horizons τ [s], each > 0.
        estimators: which estimators to run, a non-empty subset of :data:`ESTIMATORS`.
        best: the estimator the pipeline should report (:attr:`best`); default ``"ekf"``
            (module docstring, "Measurements", for why).
        max_range: farthest point-wise range [m] from which an EKF/UKF may start (None:
            no limit beyond ``init_margin``).
        init_margin: an EKF/UKF starts only from a depression at least this many σ_β
            below the horizon dip (>= 0).
        velocity_window: window of the least-squares velocity of ``geometry`` and
            ``diffuse-rls`` [s], > 0 (at most :data:`VELOCITY_CAPACITY` samples).
        ar_order: AR order p of the diffuse RLS (seed 000: 5).
        ar_increments: model the angle increments with an intercept (ALGORITHMS.md §3.1
            [NEW] variant, default) instead of the levels without intercept (seed 000's
            exact form): see "AR model" in the module docstring.
        forgetting: forgetting factor λ of the diffuse RLS, in (0, 1] (seed 000: 1).
        frame_interval: sampling interval T of the angle series [s] for the diffuse RLS;
            None: the shortest interval seen between two ``update`` calls.
        max_gap: longest gap [s] bridged by missing samples in the diffuse RLS; a longer
            one restarts its AR models.
        earth_radius: earth radius R [m].
        robust_gate: EKF/UKF robust update: the probability p in (0, 1) of the χ² gate
            (1 degree of freedom for an azimuth-only update, 2 for a full one) above
            which an innovation is down-weighted (``_correct``; module docstring,
            "Robust update"); None: the plain update.

    Raises:
        ValueError: naming the argument, for any bad configuration.
    """

    def __init__(
        self,
        height: float,
        *,
        sigma_angle: float = SIGMA_ANGLE,
        sigma_a: float = SIGMA_A,
        sigma_velocity: float = SIGMA_VELOCITY,
        curved: bool = True,
        refraction: float = DEFAULT_REFRACTION,
        horizons: Sequence[float] = (10.0, 30.0),
        estimators: Sequence[str] = ESTIMATORS,
        best: str = "ekf",
        max_range: float | None = None,
        init_margin: float = 3.0,
        velocity_window: float = 5.0,
        ar_order: int = AR_ORDER,
        ar_increments: bool = True,
        forgetting: float = 1.0,
        frame_interval: float | None = None,
        max_gap: float = 2.0,
        earth_radius: float = EARTH_RADIUS,
        robust_gate: float | None = None,
    ) -> None:
        self.height = positive("height", height)
        self.sigma_angle = positive("sigma_angle", sigma_angle)
        self.sigma_a = positive("sigma_a", sigma_a, allow_zero=True)
        self.sigma_velocity = positive("sigma_velocity", sigma_velocity)
        self.curved = _flag("curved", curved)
        self.refraction = in_range("refraction", refraction, 0.0, 1.0, hi_open=True)
        self.earth_radius = in_range(
            "earth_radius", earth_radius, 0.0, np.inf, lo_open=True, hi_open=True
        )
        if isinstance(horizons, str) or not isinstance(horizons, Sequence | np.ndarray):
            raise ValueError(f"horizons: expected a sequence of times > 0 [s], got {horizons!r}")
        hs = tuple(positive("horizons", v) for v in horizons)
        if len(set(hs)) != len(hs):
            raise ValueError(f"horizons: expected distinct times, got {horizons!r}")
        self.horizons: tuple[float, ...] = hs
        if isinstance(estimators, str) or not isinstance(estimators, Sequence):
            raise ValueError(
                f"estimators: expected a sequence of names from {ESTIMATORS}, got {estimators!r}"
            )
        ests = tuple(estimators)
        if not ests or len(set(ests)) != len(ests) or any(e not in ESTIMATORS for e in ests):
            raise ValueError(
                f"estimators: expected distinct names from {', '.join(ESTIMATORS)}, "
                f"got {estimators!r}"
            )
        self.estimators: tuple[str, ...] = tuple(e for e in ESTIMATORS if e in ests)
        if best not in self.estimators:
            raise ValueError(
                f"best: expected one of the estimators {self.estimators}, got {best!r}"
            )
        self.best = best
        self.max_range = None if max_range is None else positive("max_range", max_range)
        self.init_margin = positive("init_margin", init_margin, allow_zero=True)
        self.velocity_window = positive("velocity_window", velocity_window)
        self.ar_order = integer("ar_order", ar_order, 1)
        self.ar_increments = _flag("ar_increments", ar_increments)
        self.forgetting = in_range("forgetting", forgetting, 0.0, 1.0, lo_open=True)
        self.frame_interval = (
            None if frame_interval is None else positive("frame_interval", frame_interval)
        )
        self.max_gap = positive("max_gap", max_gap)
        self.robust_gate = (
            None
            if robust_gate is None
            else in_range("robust_gate", robust_gate, 0.0, 1.0, lo_open=True, hi_open=True)
        )
        self._gate = (
            (math.inf, math.inf)
            if self.robust_gate is None
            else (float(chi2.ppf(self.robust_gate, 1)), float(chi2.ppf(self.robust_gate, 2)))
        )
        self._Re = self.earth_radius / (1.0 - self.refraction)
        self._q = self.sigma_a**2
        self._horizons = np.array(self.horizons, dtype=np.float64)
        # the diffuse RLS configuration of DiffuseRLS itself (one template per angle)
        opts = {"increments": self.ar_increments, "intercept": self.ar_increments}
        rls = (
            DiffuseRLS(self.ar_order, self.forgetting, angle=True, **opts),
            DiffuseRLS(self.ar_order, self.forgetting, angle=False, **opts),
        )
        self._rls = DiffuseRLSBank(rls, 16)
        self._T = self.frame_interval
        self._time: float | None = None
        self._slot_of: dict[int, int] = {}
        self._free: list[int] = []
        self._n = 0
        self._alloc(16)

    # ------------------------------------------------------------------ storage
    def _alloc(self, size: int) -> None:
        """Grow the per-track storage to ``size`` slots (keeping the existing ones)."""
        C = VELOCITY_CAPACITY
        old = self._n
        shapes: dict[str, tuple[tuple[int, ...], float, type]] = {
            "_last": ((size,), np.nan, np.float64),
            "_seen": ((size,), np.nan, np.float64),
            "_ready": ((size,), False, np.bool_),
            "_Xe": ((size, 4), 0.0, np.float64),
            "_Pe": ((size, 4, 4), 0.0, np.float64),
            "_Xu": ((size, 4), 0.0, np.float64),
            "_Pu": ((size, 4, 4), 0.0, np.float64),
        }
        for pre in ("_g", "_d"):  # velocity ring buffers of geometry / diffuse-rls
            shapes[pre + "T"] = ((size, C), 0.0, np.float64)
            shapes[pre + "P"] = ((size, C, 2), 0.0, np.float64)
            shapes[pre + "count"] = ((size,), 0, np.int64)
            shapes[pre + "head"] = ((size,), 0, np.int64)
        for name, (shape, fill, dtype) in shapes.items():
            arr = np.full(shape, fill, dtype=dtype)
            if old:
                arr[:old] = getattr(self, name)
            setattr(self, name, arr)
        self._rls.grow(size)
        self._free.extend(range(size - 1, old - 1, -1))
        self._n = size

    def _new_slot(self) -> int:
        if not self._free:
            self._alloc(2 * self._n)
        s = self._free.pop()
        self._last[s] = np.nan
        self._seen[s] = np.nan
        self._ready[s] = False
        for pre in ("_g", "_d"):
            getattr(self, pre + "count")[s] = 0
            getattr(self, pre + "head")[s] = 0
        self._rls.clear(s)  # the diffuse start (DiffuseRLS.reset)
        return s

    # ------------------------------------------------------------------ queries
    @property
    def track_ids(self) -> NDArray[np.int64]:
        """Ids of the tracks the bank holds (sorted)."""
        return np.array(sorted(self._slot_of), dtype=np.int64)

    @property
    def time(self) -> float | None:
        """Time of the last ``update`` [s] (None before the first)."""
        return self._time

    @property
    def sampling_interval(self) -> float | None:
        """Sampling interval T of the diffuse RLS [s] (given or estimated; None yet)."""
        return self._T

    def horizon_dip(self, height: float | None = None) -> float:
        """Dip of the visible horizon below the true horizontal [rad] (ALGORITHMS.md §4.2)
        at ``height`` [m] (default: the tracker's); 0 on a flat sea."""
        return self._dip(self.height if height is None else positive("height", height))

    def _dip(self, h: float) -> float:
        if not self.curved:
            return 0.0
        Re = self._Re
        return math.atan(math.sqrt(2.0 * Re * h + h * h) / Re)

    # ------------------------------------------------------------------ API
    def drop(self, track_ids: ArrayLike) -> None:
        """Forget the given tracks (ids not held are ignored); their ids may start anew."""
        ids = np.atleast_1d(np.asarray(track_ids))
        if ids.ndim != 1 or (ids.size and not np.issubdtype(ids.dtype, np.integer)):
            raise ValueError(f"track_ids: expected a 1-D array of integer ids, got {track_ids!r}")
        for i in ids.tolist():
            s = self._slot_of.pop(int(i), None)
            if s is not None:
                self._free.append(s)

    def update(
        self,
        time: float,
        track_ids: ArrayLike,
        azimuth: ArrayLike,
        depression: ArrayLike,
        *,
        angle_covariance: ArrayLike | None = None,
        platform: PlatformPose | None = None,
    ) -> dict[str, WorldEstimates]:
        """Take one frame's angles of k tracks and return every estimator's estimates.

        Args:
            time: frame time [s], finite, later than the previous ``update``.
            track_ids: (k,) distinct integer ids; a new id starts new estimators.
            azimuth: (k,) measured azimuth, clockwise from North (world frame) [rad].
            depression: (k,) measured depression below the true horizontal [rad].
                NaN in either angle: a missing measurement (module docstring).
            angle_covariance: covariance of (azimuth, depression) [rad²], (2, 2) or
                (k, 2, 2), positive definite; default ``sigma_angle² I``.
            platform: the camera's pose at this frame; None: a fixed camera at the
                origin at the tracker's height.

        Returns:
            {estimator name: :class:`WorldEstimates`} for the k tracks, in the order of
            ``track_ids``, for each configured estimator (in :data:`ESTIMATORS` order).

        Raises:
            ValueError: naming the argument for bad shapes, inf angles, duplicate ids, a
                time that does not increase, or a bad covariance or platform.
            numpy.linalg.LinAlgError: if a filter's covariance stops being positive
                definite (names the track).
        """
        t = self._check_time(time)
        ids, az, dep, Sigma = self._check_data(track_ids, azimuth, depression, angle_covariance)
        if platform is None:
            platform = PlatformPose()
        elif not isinstance(platform, PlatformPose):
            raise ValueError(f"platform: expected a PlatformPose or None, got {platform!r}")
        h = self.height if platform.height is None else platform.height
        sp2 = platform.sigma_position**2
        if self._time is not None and self.frame_interval is None:
            step = t - self._time
            if self._T is None or step < self._T:
                self._T = step
        self._time = t

        k = ids.shape[0]
        slots = np.empty(k, dtype=np.int64)
        for i, tid in enumerate(ids.tolist()):
            s = self._slot_of.get(tid)
            if s is None:
                s = self._new_slot()
                self._slot_of[tid] = s
            slots[i] = s
        last = self._last[slots]
        dt = np.where(np.isnan(last), 0.0, t - last)
        self._last[slots] = t
        # time since each track's last measured angles [s] (inf: none yet): the diffuse
        # RLS restarts after a gap of missing samples as after a gap between updates
        measured = np.isfinite(az) & np.isfinite(dep)
        seen = self._seen[slots]
        unseen = np.where(np.isnan(seen), np.inf, t - seen)
        self._seen[slots[measured]] = t

        fix = self._fix(az, dep, Sigma, h, platform.north, platform.east, sp2)
        out: dict[str, WorldEstimates] = {}
        if "geometry" in self.estimators:
            out["geometry"] = self._geometry(t, ids, slots, fix)
        if "diffuse-rls" in self.estimators:
            stale = measured & np.isfinite(unseen) & (unseen > self.max_gap)
            out["diffuse-rls"] = self._diffuse(
                t, ids, slots, dt, stale, az, dep, Sigma, h, sp2, platform
            )
        if "ekf" in self.estimators or "ukf" in self.estimators:
            starting = self._start_filters(slots, dep, Sigma, h, fix)
            z = np.stack([az, dep], axis=-1)
            for name, X, P in (("ekf", self._Xe, self._Pe), ("ukf", self._Xu, self._Pu)):
                if name in self.estimators:
                    out[name] = self._filter(
                        name, t, ids, slots, dt, z, Sigma, X, P, h, platform, sp2, starting
                    )
        return {name: out[name] for name in self.estimators}

    # ------------------------------------------------------------------ input checks
    def _check_time(self, time: float) -> float:
        try:
            t = float(time)
        except (TypeError, ValueError):
            raise ValueError(f"time: expected a finite number [s], got {time!r}") from None
        if not math.isfinite(t):
            raise ValueError(f"time: expected a finite number [s], got {time!r}")
        if self._time is not None and not t > self._time:
            raise ValueError(
                f"time: expected a time later than the previous update ({self._time} s), got {t}"
            )
        return t

    def _check_data(
        self,
        track_ids: ArrayLike,
        azimuth: ArrayLike,
        depression: ArrayLike,
        angle_covariance: ArrayLike | None,
    ) -> tuple[NDArray[np.int64], FloatArray, FloatArray, FloatArray]:
        raw = np.asarray(track_ids)
        if raw.ndim != 1 or (raw.size and not np.issubdtype(raw.dtype, np.integer)):
            raise ValueError(f"track_ids: expected a 1-D array of integer ids, got {track_ids!r}")
        ids = raw.astype(np.int64)
        k = ids.shape[0]
        if k > 1 and len(set(ids.tolist())) != k:
            raise ValueError("track_ids: duplicate ids in one frame")
        az = as_float_array("azimuth", azimuth, ndim=1)
        dep = as_float_array("depression", depression, ndim=1)
        for name, arr in (("azimuth", az), ("depression", dep)):
            if arr.shape != (k,):
                raise ValueError(f"{name}: expected shape ({k},) like track_ids, got {arr.shape}")
            if np.any(np.isinf(arr)):
                raise ValueError(f"{name}: contains inf (use NaN for a missing measurement)")
        if angle_covariance is None:
            Sigma = np.zeros((k, 2, 2))
            Sigma[:, 0, 0] = Sigma[:, 1, 1] = self.sigma_angle**2
        else:
            cov = covariance(
                "angle_covariance", angle_covariance, 2, positive_definite=True, batch=True
            )
            if cov.shape not in ((2, 2), (k, 2, 2)):
                raise ValueError(
                    f"angle_covariance: expected shape (2, 2) or ({k}, 2, 2), got {cov.shape}"
                )
            Sigma = np.ascontiguousarray(np.broadcast_to(cov, (k, 2, 2)))
        return ids, np.ascontiguousarray(az), np.ascontiguousarray(dep), Sigma

    # ------------------------------------------------------------------ estimators
    def _fix(
        self,
        az: FloatArray,
        dep: FloatArray,
        Sigma: FloatArray,
        h: float,
        on: float,
        oe: float,
        sp2: float,
    ) -> _Fix:
        k = az.shape[0]
        pos = np.empty((k, 2))
        cov = np.empty((k, 2, 2))
        D = np.empty(k)
        sig = np.empty(k)
        _pointwise(az, dep, Sigma, h, on, oe, sp2, self._Re, self.curved, pos, cov, D, sig)
        return _Fix(pos, cov, D, sig)

    def _geometry(
        self, t: float, ids: NDArray[np.int64], slots: NDArray[np.int64], fix: _Fix
    ) -> WorldEstimates:
        vel = np.empty((ids.shape[0], 2))
        _push_and_slope(
            slots, t, fix.pos, self._gT, self._gP, self._gcount, self._ghead,
            self.velocity_window, vel,
        )  # fmt: skip
        fc = {tau: fix.pos + tau * vel for tau in self.horizons}
        return self._estimates(t, ids, fix.pos, fix.cov, vel, fix.D, fix.sigma_range, fc)

    def _diffuse(
        self,
        t: float,
        ids: NDArray[np.int64],
        slots: NDArray[np.int64],
        dt: FloatArray,
        stale: NDArray[np.bool_],
        az: FloatArray,
        dep: FloatArray,
        Sigma: FloatArray,
        h: float,
        sp2: float,
        platform: PlatformPose,
    ) -> WorldEstimates:
        k = ids.shape[0]
        T = self._T
        reset = (dt > self.max_gap) | stale
        if T is None:
            missing = np.zeros(k, dtype=np.int64)
            steps = np.zeros(0, dtype=np.int64)
        else:
            missing = np.maximum(np.rint(dt / T).astype(np.int64) - 1, 0)
            steps = np.maximum(np.rint(self._horizons / T).astype(np.int64), 1)
        missing[reset | (dt <= 0.0)] = 0
        y = np.stack([az, dep], axis=-1)
        filt, fca, ar_ok = self._rls.step(slots, y, missing=missing, reset=reset, steps=steps)
        # a smoothed angle that has lost the measured one (AR predictions over missing
        # samples from a model not yet of full rank, kept in its regressors by λ = 1):
        # restart those tracks' AR models on this sample
        sd = np.sqrt(np.diagonal(Sigma, axis1=1, axis2=2))
        off = np.abs(np.stack([wrap_angle(filt[:, 0] - az), filt[:, 1] - dep], axis=-1))
        lost = np.any(off > RLS_RESTART_SIGMA * sd, axis=1)  # False where y is NaN
        if np.any(lost):
            again = self._rls.step(
                slots[lost], y[lost], reset=np.ones(int(lost.sum()), np.bool_), steps=steps
            )
            filt[lost], fca[lost], ar_ok[lost] = again
        on, oe = platform.north, platform.east
        fix = self._fix(filt[:, 0], filt[:, 1], Sigma, h, on, oe, sp2)
        vel = np.empty((k, 2))
        _push_and_slope(
            slots, t, fix.pos, self._dT, self._dP, self._dcount, self._dhead,
            self.velocity_window, vel,
        )  # fmt: skip
        fc = {}
        any_ar = bool(np.any(ar_ok))
        for j, tau in enumerate(self.horizons):
            line = fix.pos + tau * vel
            if any_ar:
                on_t = on + tau * platform.velocity_north
                oe_t = oe + tau * platform.velocity_east
                ahead = self._fix(
                    np.ascontiguousarray(fca[:, j, 0]), np.ascontiguousarray(fca[:, j, 1]),
                    Sigma, h, on_t, oe_t, sp2,
                )  # fmt: skip
                line = np.where(ar_ok[:, None], ahead.pos, line)
            fc[tau] = line
        return self._estimates(t, ids, fix.pos, fix.cov, vel, fix.D, fix.sigma_range, fc)

    def _start_filters(
        self,
        slots: NDArray[np.int64],
        dep: FloatArray,
        Sigma: FloatArray,
        h: float,
        fix: _Fix,
    ) -> NDArray[np.bool_]:
        """Start the EKF/UKF of tracks whose measurement is far enough below the horizon."""
        if np.all(self._ready[slots]):
            return np.zeros(slots.shape[0], dtype=np.bool_)
        dip = self._dip(h)
        with np.errstate(invalid="ignore"):
            ok = dep - dip >= self.init_margin * np.sqrt(Sigma[:, 1, 1])
            ok &= np.isfinite(fix.D)
            if self.max_range is not None:
                ok &= fix.D <= self.max_range
        starting = ok & ~self._ready[slots]
        if np.any(starting):
            s = slots[starting]
            x0 = np.zeros((s.size, 4))
            x0[:, :2] = fix.pos[starting]
            P0 = np.zeros((s.size, 4, 4))
            P0[:, :2, :2] = fix.cov[starting]
            P0[:, 2, 2] = P0[:, 3, 3] = self.sigma_velocity**2
            for X, P in ((self._Xe, self._Pe), (self._Xu, self._Pu)):
                X[s] = x0
                P[s] = P0
            self._ready[s] = True
        return starting

    def _filter(
        self,
        name: str,
        t: float,
        ids: NDArray[np.int64],
        slots: NDArray[np.int64],
        dt: FloatArray,
        z: FloatArray,
        Sigma: FloatArray,
        X: FloatArray,
        P: FloatArray,
        h: float,
        platform: PlatformPose,
        sp2: float,
        starting: NDArray[np.bool_],
    ) -> WorldEstimates:
        k = ids.shape[0]
        on, oe = platform.north, platform.east
        ready = self._ready[slots]
        nis = np.full(k, np.nan)
        run = np.flatnonzero(ready & ~starting)  # a starting measurement is in x0 already
        if run.size:
            nis_run = np.empty(run.size)
            bank = _ukf_bank if name == "ukf" else _ekf_bank
            bad = bank(
                slots[run], X, P, dt[run], self._q, z[run], Sigma[run], on, oe, h, sp2,
                self._Re, self.curved, self._dip(h), nis_run, self._gate[0], self._gate[1],
            )  # fmt: skip
            if bad >= 0:
                raise np.linalg.LinAlgError(
                    f"WorldTracker.update ({name}): the covariance of track "
                    f"{int(ids[run[bad]])} is not positive definite; check angle_covariance"
                )
            nis[run] = nis_run
        H = self._horizons.shape[0]
        pos = np.empty((k, 2))
        cov = np.empty((k, 2, 2))
        vel = np.empty((k, 2))
        rng = np.empty(k)
        sig = np.empty(k)
        fc = np.empty((k, H, 2))
        fcov = np.empty((k, H, 2, 2))
        _outputs(
            slots, ready, X, P, on, oe, self._q, self._horizons, pos, cov, vel, rng, sig, fc,
            fcov,
        )  # fmt: skip
        fcd = {tau: fc[:, j] for j, tau in enumerate(self.horizons)}
        fcovd = {tau: fcov[:, j] for j, tau in enumerate(self.horizons)}
        return self._estimates(t, ids, pos, cov, vel, rng, sig, fcd, fcovd, nis)

    def _estimates(
        self,
        t: float,
        ids: NDArray[np.int64],
        pos: FloatArray,
        cov: FloatArray,
        vel: FloatArray,
        rng: FloatArray,
        sig_r: FloatArray,
        fc: dict[float, FloatArray],
        fcov: dict[float, FloatArray] | None = None,
        nis: FloatArray | None = None,
    ) -> WorldEstimates:
        k = ids.shape[0]
        if fcov is None:
            nan = np.full((k, 2, 2), np.nan)
            fcov = dict.fromkeys(self.horizons, nan)
        return WorldEstimates(
            time=t,
            track_id=ids,
            north=pos[:, 0].copy(),
            east=pos[:, 1].copy(),
            covariance=cov,
            speed=np.hypot(vel[:, 0], vel[:, 1]),
            course=_course(vel[:, 0], vel[:, 1]),
            range=rng,
            sigma_range=sig_r,
            forecasts=fc,
            forecast_covariances=fcov,
            nis=np.full(k, np.nan) if nis is None else nis,
        )
