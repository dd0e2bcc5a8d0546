"""Scenario ``air-range``: range of an air target from its image size (seed 002, Ugarak).

SCENARIOS.md ``air-range``; ALGORITHMS.md §5. A jet trainer of known size L = 10 m is
filmed by a TV camera with focal length f = 40 000 px (750 mm lens) at 25 frames/s. In
every frame its image size is measured, ``l = f L / d + ε``, ``ε ~ N(0, σ_l²)``,
``σ_l = 1 px``, and turned into a raw range ``d = f L / l`` whose standard deviation is
``σ_d = d² σ_l / (f L)`` (62.5 m at 5 km, 15.6 m at 2.5 km; seed 002 eqs. 14–15). The
raw ranges are filtered by the paper's fixed-noise NCV (σ_v = 1, 5, 10 m/s²) and NCA
(Δa = 0.001, 0.01, 0.1 m/s²) and by the adaptive ANCV and ANCA
(:class:`seawatch.filters.adaptive_range.AdaptiveRangeFilter`).

Truth (**resolved** in SCENARIOS.md; coordinates with the camera at the origin, x along
the flight direction, y across it, z up):

* straight, level flight at 200 m/s along the line y = 1000 m (horizontal miss
  distance), z = 300 m (height), starting where the slant range is 5000 m
  (x = −4889.8 m);
* from the point where the range has fallen to 2500 m (x = −2271.6 m, t = 13.09 s) a
  pull-up in the vertical plane of the flight path: constant speed, acceleration of
  magnitude 3 g = 29.42 m/s² perpendicular to the velocity (a circular arc of radius
  v²/(3 g) = 1359.6 m). "3 g" is read as the kinematic acceleration, not the load
  factor;
* **end of the run** (resolved here): the last frame before the range stops
  decreasing. On the arc the range reaches its minimum, 1764.4 m, at t = 19.48 s
  (53.8° of climb); frames are ``t_k = k T``, ``T = 0.04 s``, k = 0 … 487 (488 frames;
  327 of them level flight).

Filter set-up (**resolved** here; the paper gives no initialisation): every filter
starts from the first raw range with no knowledge of the range rate,
``x0 = [z_0, 0(, 0)]``, ``P0 = diag(σ_d(z_0)², (300 m/s)²(, (10 m/s²)²))`` (a diffuse
prior covering any subsonic aircraft and ~1 g of range acceleration), and filters the
frames 1 … N−1; its estimate at frame 0 is ``z_0``. R_k is evaluated at the predicted
range. ANCV starts at σ_v² = 1, ANCA at σ_v² = 10⁻⁴, both with a window of W = 50
frames (seed 002), floors σ_start/10 and caps 10 g (ANCV) and 10 g/s · T (ANCA).

Metrics (INTERFACES.md): per run, the RMS range error over all frames
(``rmse_range``), over the frames with true range > 2.5 km (``rmse_range_far``, the
level flight) and over the rest (``rmse_range_near``, the pull-up); reported as the
mean over runs and its standard error. ``crlb`` (the bound below): the RMS of √PCRB
over the same frames (no standard error: it is computed, not sampled).
``rmse_range_over_crlb``, ``rmse_range_far_over_crlb``, ``rmse_range_near_over_crlb``
(unit 1, every estimator): the RMS error pooled over runs and frames of the segment,
√(mean e²), divided by that RMS bound, with the delta-method standard error from the
per-run mean squared errors. Pooled, not the mean of per-run ratios: a lower bound
limits the mean *square* error, and the mean of per-run RMS values is lower by
Jensen's inequality (≈ 2 % here, where the far segment's per-run RMS is dominated by
the few first frames).

The bound (``crlb``)
--------------------
:func:`pcrb`: the posterior Cramér–Rao bound of the range (ALGORITHMS.md §7, Tichavský
recursion in the singular-Q form; :func:`seawatch.metrics.crlb.air_range_pcrb` with one
process-noise level per frame) with the state ``[d, ḋ, d̈]`` and the NCA (DWPA) dynamics
of §5.2, whose process noise is the **truth's own motion**: the acceleration increment
of frame k → k+1 has standard deviation ``Δa_k = |d̈(t_{k+1}) − d̈(t_k)|`` (0.002–0.024
m/s² per frame in the level flight, 3.7 m/s² at the onset of the pull-up, up to 0.34
m/s² on the arc). Prior at the first frame: nothing about the range (the first image
size initialises it, as in the filters), rate N(0, ḋ(0)²) = N(0, (195.6 m/s)²) and
acceleration N(0, d̈(0)²) = N(0, (0.35 m/s²)²): zero-mean like the filters' start, with
the truth's values as one standard deviation. The measurement information is ``(f L /
d²)² / σ_l² = 1/σ_d(d_k)²`` along the true range (exact, ALGORITHMS.md §5.1). Why this
one: the truth is one deterministic path, so a Bayesian bound needs a prior process that
the path is a typical draw of; treating its every random element (initial rate, initial
acceleration, each acceleration increment) as a one-σ draw of a zero-mean NCA process
gives the least prior information that still covers the truth. The bound of a *filter's*
model (``air_range_pcrb`` with ncv-1's σ_v, say) would only describe that filter; an
information-only bound on the deterministic path (Q = 0) is not a bound here, since no
polynomial model contains the path. Checks (``tests/scenarios/test_air_range.py``): it
equals the covariance of a Kalman filter with the same Q_k, R_k and prior (FilterPy,
1e-7), and the *exact* mean square error of every fixed-noise filter on this truth (its
bias from the unmodelled motion plus its noise covariance, R at the true range) is never
below it (ncv-1 touches it to 1e-4 at 3.1 s; far-segment ratios 1.02–1.06). A DWNA (NCV)
process with σ_k = |d̈_k| gives nearly the same numbers (RMS 10.15 / 12.23 / 2.69 m, all
/ far / near, against 9.96 / 11.99 / 2.77 m) but treats the persistent acceleration as
white noise.

Figures (:func:`run_demo`, ``merge`` with ``out_dir``): ``range_error.png`` (every
filter, σ_v of the adaptive ones) and the paper's Figs. 3–6 (:data:`FIGURES`):
Fig. 3 NCV σ_v = 1, 5, 10 with the true range acceleration and each filter's windowed
mean acceleration ``asr`` (seed 002 eq. 16, the signed mean of (v̂_k − v̂_{k−1})/T over
W = 50 frames, median over runs); Fig. 4 NCA Δa = 0.001, 0.01, 0.1 with the true and
estimated change of acceleration per frame ``Δasr`` (eq. 23); Fig. 5 ANCV against
NCV (ncv-1 is its start value) with ANCV's σ_v (median, 10–90 %) and the true |d̈|;
Fig. 6 ANCA against NCA (nca-0.01 is its start) with ANCA's σ_v and the true
|Δa_k|. Each shows the RMS range error over the runs against the true range (range
decreasing left to right), σ_d and √PCRB. The paper plots one flight's signed error;
the RMS over runs is what a simulation can compare.

Outcome (100 runs, seed 0; ``tests/scenarios/test_air_range.py`` checks it):

==========  ==========  ===========  ==========  =====================
estimator   whole run   far (level)  near        RMSE / √CRLB (whole)
==========  ==========  ===========  ==========  =====================
raw         32.09 m     38.42 m      10.72 m     3.22
ncv-1       40.55       11.82        68.69       4.07
ncv-5       20.29       11.54        31.20       2.04
ncv-10      14.37       11.43        18.84       1.45
nca-0.001   24.95       12.04        39.89       2.51
nca-0.01    24.04       12.04        38.16       2.42
nca-0.1     13.43       12.04        15.72       1.36
ancv        10.50       12.39         4.55       1.07
anca        10.36       12.33         3.77       1.06
crlb         9.96       11.99         2.77
==========  ==========  ===========  ==========  =====================

(standard errors 0.06–0.24 m, ratios ± 0.01–0.02.) Every filter beats the raw range
in the level flight, where all are at the bound (far ratios 0.97–1.05 ± 0.02: the
start transient dominates that segment); on the pull-up the fixed filters are 5.7–25
times the bound and the adaptive ones 1.66 (ANCV) and 1.38 (ANCA). ANCV and ANCA beat
every fixed-noise filter over the whole run and estimate the range about equally well
(10.5 / 10.4 m; paper: "equally well", "about ±10 m"). The paper's "large σ_v better
late" holds. Two claims do not:

* "small σ_v better early" (Figs. 3–4). Read as the paper means it — the approach once
  the filters have left their start — there is no such phase for the small σ_v: a
  fixed filter has "converged" when its own range variance is within 1.25² of the
  steady state at the current R (:func:`convergence_frame`): ncv-10 at 4.64 s
  (4.10 km), nca-0.1 at 8.44 s (3.37 km), but ncv-1 only at 15.0 s (on the arc) and
  nca-0.001 never. From the larger σ_v's convergence to the pull-up, ncv-1 is 22 %
  worse than ncv-10 (6.33 vs 5.17 m, paired −1.17 ± 0.08 m: at σ_d = 30–60 m a
  1 m/s² model lags the miss distance's 0.35 → 2.8 m/s² of range acceleration by up to
  9 m) and nca-0.001 equals nca-0.1 (4.56 vs 4.58 m). Before that, in the start
  transient, every σ_v gives the same estimate to 0.2 % (the memory is set by the time
  since the start, not by σ_v).
* "ANCA substantially better, especially in the initial part" (Fig. 6). From the
  first adapted frame (51, 2.04 s) to the pull-up ANCA is 6.6 % *worse* than nca-0.01
  (8.36 vs 7.84 m, paired −0.52 ± 0.05 m; ANCV likewise 13 % worse than ncv-1): the
  first full window holds the diffuse start's convergence and lifts σ_v to ~1 m/s²
  (ANCV to ~90 m/s², near its 10 g cap), where it stays (the statistic's fixed point
  is only weakly attracting, see :mod:`seawatch.filters.adaptive_range`): a hundred
  times the truth's 0.002–0.024 m/s² per frame. The adaptation pays off only on the
  pull-up.

Randomness: run i draws from ``numpy.random.default_rng(SeedSequence(seed,
spawn_key=(i,)))``, so its numbers do not depend on how the runs are split into chunks
or Dask workers (:func:`chunk` / :func:`merge`, the protocol of
:mod:`seawatch.scenarios.parallel`).
"""

from __future__ import annotations

import csv
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

from seawatch._validation import FloatArray, as_float_array, covariance, integer, matrix, positive
from seawatch.filters.adaptive_range import (
    STANDARD_GRAVITY,
    AdaptiveRangeFilter,
    size_range_std,
)
from seawatch.metrics.crlb import PCRBResult, air_range_pcrb
from seawatch.models.kinematic import constant_acceleration, constant_velocity
from seawatch.scenarios.base import ExperimentResult, record

SCENARIO = "air-range"
FOCAL_PX = 40_000.0
"""Focal length f [px] (750 mm lens)."""
SIZE_M = 10.0
"""Target extent L [m] (G-2 jet trainer)."""
SIGMA_L_PX = 1.0
"""Image-size measurement error σ_l [px]."""
DT_S = 0.04
"""Frame period T [s] (25 frames/s)."""
SPEED_MPS = 200.0
MISS_DISTANCE_M = 1000.0
HEIGHT_M = 300.0
START_RANGE_M = 5000.0
PULLUP_RANGE_M = 2500.0
PULLUP_G = 3.0
FAR_RANGE_M = 2500.0
"""Frames with true range above this are "far" (``rmse_range_far``), the rest "near"."""
INITIAL_SPEED_STD_MPS = 300.0
INITIAL_ACCEL_STD_MPS2 = 10.0
WINDOW = 50

ProgressCallback = Callable[[int, int], None]

CHUNK_MIN = 500
"""Smallest chunk of the parallel runner's default plan (a chunk costs ~0.5 s + 6 ms/run)."""
PARALLEL_MIN_COST = 2000
"""Below this many runs the default (no ``--workers``) runs in one process."""


@dataclass(frozen=True)
class EstimatorSpec:
    """One filter of the comparison: INTERFACES.md name, model, adaptation and σ_v [m/s²]."""

    name: str
    model: str
    adaptive: bool
    sigma: float


ESTIMATORS: tuple[EstimatorSpec, ...] = (
    EstimatorSpec("ncv-1", "ncv", False, 1.0),
    EstimatorSpec("ncv-5", "ncv", False, 5.0),
    EstimatorSpec("ncv-10", "ncv", False, 10.0),
    EstimatorSpec("nca-0.001", "nca", False, 0.001),
    EstimatorSpec("nca-0.01", "nca", False, 0.01),
    EstimatorSpec("nca-0.1", "nca", False, 0.1),
    EstimatorSpec("ancv", "ncv", True, 1.0),
    EstimatorSpec("anca", "nca", True, 0.01),
)
"""The filters compared, in INTERFACES.md order (``raw`` is the unfiltered range)."""

METRICS = ("rmse_range", "rmse_range_far", "rmse_range_near")


@dataclass(frozen=True)
class AirRangeTrajectory:
    """Sampled truth of the ``air-range`` scenario (camera at the origin).

    Attributes:
        time: frame times t_k = k T [s], (N,).
        position: target position [m], (N, 3): x along the flight path, y across, z up.
        velocity: [m/s], (N, 3).
        acceleration: [m/s²], (N, 3) (zero in level flight, 3 g on the pull-up).
        range: slant range d = |p| [m], (N,).
        range_rate: ḋ = p·v / d [m/s], (N,).
        range_acceleration: d̈ = (|v|² + p·a − ḋ²) / d [m/s²], (N,).
        pullup_time: time the pull-up starts [s].
        end_time: time of the range minimum on the pull-up [s] (the run's end).
        dt: frame period T [s].
    """

    time: FloatArray
    position: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    range: FloatArray
    range_rate: FloatArray
    range_acceleration: FloatArray
    pullup_time: float
    end_time: float
    dt: float


def _state_at(
    t: FloatArray,
    x_start: float,
    x_pull: float,
    t_pull: float,
    v: float,
    a: float,
    y: float,
    h: float,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Position, velocity, acceleration (..., 3) of the level-flight-then-arc path."""
    t = np.asarray(t, dtype=np.float64)
    rho = v * v / a
    w = a / v
    th = w * np.clip(t - t_pull, 0.0, None)
    level = t < t_pull
    px = np.where(level, x_start + v * t, x_pull + rho * np.sin(th))
    pz = np.where(level, h, h + rho * (1.0 - np.cos(th)))
    vx = np.where(level, v, v * np.cos(th))
    vz = np.where(level, 0.0, v * np.sin(th))
    ax = np.where(level, 0.0, -a * np.sin(th))
    az = np.where(level, 0.0, a * np.cos(th))
    py = np.full(t.shape, y)
    zero = np.zeros(t.shape)
    return (
        np.stack([px, py, pz], axis=-1),
        np.stack([vx, zero, vz], axis=-1),
        np.stack([ax, zero, az], axis=-1),
    )


def trajectory(
    *,
    dt: float = DT_S,
    speed: float = SPEED_MPS,
    miss_distance: float = MISS_DISTANCE_M,
    height: float = HEIGHT_M,
    start_range: float = START_RANGE_M,
    pullup_range: float = PULLUP_RANGE_M,
    pullup_g: float = PULLUP_G,
) -> AirRangeTrajectory:
    """The resolved ``air-range`` truth: level pass, then a pull-up (SCENARIOS.md).

    Straight, level flight at ``speed`` [m/s] along y = ``miss_distance``, z = ``height``
    [m], starting at slant range ``start_range`` [m]; from slant range ``pullup_range``
    a circular pull-up in the vertical plane with acceleration ``pullup_g`` · g. Sampled
    every ``dt`` [s] until the range reaches its minimum on the arc (the last frame at
    or before that instant).
    """
    T = positive("dt", dt)
    v = positive("speed", speed)
    y = positive("miss_distance", miss_distance, allow_zero=True)
    h = positive("height", height, allow_zero=True)
    a = positive("pullup_g", pullup_g) * STANDARD_GRAVITY
    closest = math.hypot(y, h)
    r_pull = positive("pullup_range", pullup_range)
    r_start = positive("start_range", start_range)
    if not closest < r_pull < r_start:
        raise ValueError(
            f"pullup_range: expected {closest:.1f} m (closest approach) < pullup_range "
            f"< start_range = {r_start} m, got {r_pull}"
        )
    x_start = -math.sqrt(r_start**2 - closest**2)
    x_pull = -math.sqrt(r_pull**2 - closest**2)
    t_pull = (x_pull - x_start) / v
    w = a / v

    def closing(theta: float) -> float:  # p · v on the arc, zero at the range minimum
        p, vel, _ = _state_at(np.array(t_pull + theta / w), x_start, x_pull, t_pull, v, a, y, h)
        return float(p @ vel)

    # p·v < 0 at the start of the arc and = (h + ρ) v > 0 at the vertical: one root between
    theta_end = brentq(closing, 0.0, math.pi / 2.0, xtol=1e-13)
    t_end = t_pull + theta_end / w
    n = math.floor(t_end / T + 1e-9) + 1
    time = np.arange(n) * T
    p, vel, acc = _state_at(time, x_start, x_pull, t_pull, v, a, y, h)
    rng = np.linalg.norm(p, axis=-1)
    rdot = np.einsum("ij,ij->i", p, vel) / rng
    rddot = (np.einsum("ij,ij->i", vel, vel) + np.einsum("ij,ij->i", p, acc) - rdot**2) / rng
    return AirRangeTrajectory(
        time=time,
        position=p,
        velocity=vel,
        acceleration=acc,
        range=rng,
        range_rate=rdot,
        range_acceleration=rddot,
        pullup_time=t_pull,
        end_time=t_end,
        dt=T,
    )


@dataclass(frozen=True)
class AirRangeMeasurements:
    """Simulated image sizes and the raw ranges computed from them.

    Attributes:
        image_size: measured image size l [px], (runs, N).
        range: raw range f L / l [m], (runs, N).
        truth: the trajectory measured.
        seed: seed of ``numpy.random.default_rng`` that drew the noise.
    """

    image_size: FloatArray
    range: FloatArray
    truth: AirRangeTrajectory
    seed: int


def _run_noise(indices: Sequence[int], seed: int, frames: int) -> FloatArray:
    """Standard normals (B, frames); run i from ``SeedSequence(seed, spawn_key=(i,))``."""
    seed = integer("seed", seed, 0)
    out = np.empty((len(indices), frames))
    for b, i in enumerate(indices):
        ss = np.random.SeedSequence(int(seed), spawn_key=(int(i),))
        out[b] = np.random.default_rng(ss).standard_normal(frames)
    return out


def simulate(
    runs: int = 100,
    seed: int = 0,
    *,
    start: int = 0,
    truth: AirRangeTrajectory | None = None,
    sigma_l: float = SIGMA_L_PX,
    focal: float = FOCAL_PX,
    size: float = SIZE_M,
) -> AirRangeMeasurements:
    """Monte-Carlo image-size measurements ``l = f L / d + N(0, σ_l²)`` and ``d = f L / l``.

    ALGORITHMS.md §5.1, seed 002 eq. 14. Runs ``start … start + runs − 1``; run i draws
    its noise from ``numpy.random.default_rng(SeedSequence(seed, spawn_key=(i,)))``, so a
    run's numbers do not depend on how the runs are split into blocks or workers.
    """
    runs = _check_runs(runs)
    start = integer("start", start, 0)
    return _simulate_runs(range(int(start), int(start) + runs), seed, truth, sigma_l, focal, size)


def _simulate_runs(
    indices: Sequence[int],
    seed: int,
    truth: AirRangeTrajectory | None = None,
    sigma_l: float = SIGMA_L_PX,
    focal: float = FOCAL_PX,
    size: float = SIZE_M,
) -> AirRangeMeasurements:
    truth = trajectory() if truth is None else truth
    fL = positive("focal", focal) * positive("size", size)
    sl = positive("sigma_l", sigma_l, allow_zero=True)
    l = fL / truth.range + sl * _run_noise(indices, seed, truth.range.shape[0])
    if np.any(l <= 0.0):
        raise ValueError("sigma_l: noise this large makes image sizes non-positive")
    return AirRangeMeasurements(image_size=l, range=fL / l, truth=truth, seed=int(seed))


def initial_state(z0: ArrayLike, model: str) -> tuple[FloatArray, FloatArray]:
    """Diffuse start from the first raw range: ``x0 = [z0, 0(, 0)]``, see the module docstring.

    Args:
        z0: first raw range(s) [m], scalar or (B,).
        model: "ncv" or "nca".

    Returns:
        x0 (B..., n) and P0 (B..., n, n).
    """
    z = as_float_array("z0", z0)
    n = 2 if model == "ncv" else 3
    x0 = np.zeros((*z.shape, n))
    x0[..., 0] = z
    P0 = np.zeros((*z.shape, n, n))
    P0[..., 0, 0] = size_range_std(z, SIGMA_L_PX, SIZE_M, FOCAL_PX) ** 2
    P0[..., 1, 1] = INITIAL_SPEED_STD_MPS**2
    if n == 3:
        P0[..., 2, 2] = INITIAL_ACCEL_STD_MPS2**2
    return x0, P0


def make_filter(spec: EstimatorSpec, z0: ArrayLike, *, window: int = WINDOW) -> AdaptiveRangeFilter:
    """The scenario's filter for one estimator, started from the first raw range(s)."""
    x0, P0 = initial_state(z0, spec.model)
    return AdaptiveRangeFilter(
        spec.model,  # type: ignore[arg-type]
        DT_S,
        x0,
        P0,
        sigma_l=SIGMA_L_PX,
        size=SIZE_M,
        focal=FOCAL_PX,
        adaptive=spec.adaptive,
        sigma=spec.sigma,
        window=window,
    )


def _params(spec: EstimatorSpec, flt: AdaptiveRangeFilter) -> dict[str, Any]:
    if not spec.adaptive:
        return {"model": spec.model, "sigma_v": spec.sigma}
    params: dict[str, Any] = {
        "model": spec.model,
        "window": flt.window,
        "sigma_start": spec.sigma,
        "sigma_min": flt.sigma_min,
        "sigma_max": flt.sigma_max,
    }
    if spec.model == "nca":
        params["source"] = flt.source
    return params


# ==========================================================================================
# the bound (crlb) and the convergence of the fixed-noise filters
# ==========================================================================================

PRIOR_FLOOR = 1e-3
"""Smallest prior standard deviation of the range rate [m/s] and acceleration [m/s²] of
the bound's prior (a head-on path has d̈(0) = 0; the floor keeps J₀ finite)."""

CRLB_PARAMS: dict[str, Any] = {
    "model": "nca",
    "process": "truth",
    "prior": "diffuse range, |rate(0)|, |acceleration(0)|",
}
"""``params`` of the ``crlb`` records (module docstring, "The bound")."""


def pcrb(
    truth: AirRangeTrajectory | None = None,
    *,
    sigma_l: float = SIGMA_L_PX,
    focal: float = FOCAL_PX,
    size: float = SIZE_M,
) -> PCRBResult:
    """Posterior Cramér–Rao bound of the range along the truth (module docstring, ``crlb``).

    ALGORITHMS.md §7 (Tichavský et al. 1998; singular-Q form), seed 002 eqs. 14, 17–21.
    State ``[d, ḋ, d̈]`` [m, m/s, m/s²] with the DWPA (NCA) dynamics of §5.2 and a
    **time-varying** process noise taken from the truth itself: the acceleration
    increment of frame k → k+1 has standard deviation ``Δa_k = |d̈(t_{k+1}) − d̈(t_k)|``
    [m/s²], i.e. ``Q_k = Δa_k² Γ Γᵀ``, ``Γ = [T²/2, T, 1]ᵀ``. Prior at the first frame
    (no prediction before it): nothing about the range, rate N(0, ḋ(0)²) and
    acceleration N(0, d̈(0)²) — zero-mean like the filters' start, with the truth's
    values as one standard deviation (floored at :data:`PRIOR_FLOOR`). Measurement
    information ``(f L / d²)² / σ_l² = 1/σ_d(d_k)²`` per frame along the true range (exact:
    the image size is linear in 1/d with noise independent of d, ALGORITHMS.md §5.1).

    Args:
        truth: the trajectory (default :func:`trajectory`).
        sigma_l: image-size noise σ_l [px]; focal: f [px]; size: L [m].

    Returns:
        PCRBResult over the N frames; ``rmse_bound(0)`` is the least RMS range error [m].
    """
    truth = trajectory() if truth is None else truth
    # Δa_k drives the prediction into frame k (frame 0 has none)
    steps = np.concatenate([[0.0], np.abs(np.diff(truth.range_acceleration))])
    s_rate = max(abs(float(truth.range_rate[0])), PRIOR_FLOOR)
    s_acc = max(abs(float(truth.range_acceleration[0])), PRIOR_FLOOR)
    J0 = np.diag([0.0, 1.0 / s_rate**2, 1.0 / s_acc**2])
    return air_range_pcrb(
        truth.range, truth.dt, "nca", steps, sigma_l=sigma_l, focal=focal, size=size,
        J0=J0, predict_first=False,
    )  # fmt: skip


def steady_state_variance(F: ArrayLike, Q: ArrayLike, R: ArrayLike) -> FloatArray:
    """Steady-state *filtered* position variance of a Kalman filter, one per R [m²].

    Solves the discrete algebraic Riccati equation of the predicted covariance,
    ``P = F P (I + G P)⁻¹ Fᵀ + Q`` with ``G = h hᵀ / R`` (h = the position row), by the
    structured doubling algorithm (Chu, Fan & Lin 2005; quadratic convergence, batched
    over R), then applies one update: ``P_ss = P₀₀ − P₀₀² / (P₀₀ + R)``.

    Args:
        F: transition (n, n); Q: process noise (n, n), PSD (rank 1 is fine).
        R: measurement variances [m²], (K,), > 0.

    Returns:
        (K,) steady-state variances of the first state [m²].
    """
    Fm = matrix("F", F)
    n = Fm.shape[0]
    if Fm.shape != (n, n):
        raise ValueError(f"F: expected a square (n, n) matrix, got shape {Fm.shape}")
    Qm = covariance("Q", Q, n)
    r = as_float_array("R", R).reshape(-1)
    if np.any(~(r > 0.0)):
        raise ValueError("R: expected measurement variances > 0")
    eye = np.eye(n)
    A = np.broadcast_to(Fm.T, (r.size, n, n)).copy()
    G = np.zeros((r.size, n, n))
    G[:, 0, 0] = 1.0 / r
    X = np.broadcast_to(Qm, (r.size, n, n)).copy()
    for _ in range(64):
        Winv = np.linalg.inv(eye + G @ X)
        At = np.swapaxes(A, -1, -2)
        A, G, X_new = A @ Winv @ A, G + A @ Winv @ G @ At, X + At @ X @ Winv @ A
        done = np.all(np.abs(X_new - X) <= 1e-14 * np.abs(X_new))
        X = X_new
        if done:
            break
    p = X[:, 0, 0]
    return p - p * p / (p + r)


def convergence_frame(
    spec: EstimatorSpec, truth: AirRangeTrajectory | None = None, *, tolerance: float = 1.25
) -> int:
    """First frame at which a fixed-noise filter has forgotten its start (module docstring).

    The filter's own range variance P_k (Riccati recursion from the scenario's start
    :func:`initial_state`, with R at the true range) is compared with the steady state
    P_ss,k it would reach if the range stayed at d_k (:func:`steady_state_variance` at
    R_k): the first k with ``√(P_k / P_ss,k) ≤ tolerance``.

    Args:
        spec: a fixed-noise estimator (``adaptive=False``).
        truth: the trajectory (default :func:`trajectory`).
        tolerance: accepted ratio of standard deviations (> 1).

    Returns:
        the frame index, or N (the number of frames) if the filter never converges.
    """
    if spec.adaptive:
        raise ValueError(f"spec: expected a fixed-noise filter, got the adaptive {spec.name!r}")
    tol = positive("tolerance", tolerance)
    if tol <= 1.0:
        raise ValueError(f"tolerance: expected a ratio > 1, got {tolerance!r}")
    truth = trajectory() if truth is None else truth
    make = constant_velocity if spec.model == "ncv" else constant_acceleration
    F, Q = make(1, truth.dt, spec.sigma)
    R = size_range_std(truth.range, SIGMA_L_PX, SIZE_M, FOCAL_PX) ** 2
    p_ss = steady_state_variance(F, Q, R)
    _, P = initial_state(truth.range[0], spec.model)
    for k in range(truth.range.size):
        if k:
            P = F @ P @ F.T + Q
            P = P - np.outer(P[:, 0], P[0]) / (P[0, 0] + R[k])
        if P[0, 0] <= tol * tol * p_ss[k]:
            return k
    return int(truth.range.size)


def _paper_window_mean(states: FloatArray, model: str, dt: float, window: int) -> FloatArray:
    """Seed 002 eqs. 16 and 23 on a filter's own estimates, (B, N) (NaN for k < W).

    NCV: ``asr_k = (1/W) Σ (v̂_i − v̂_{i−1})/T = (v̂_k − v̂_{k−W}) / (W T)`` [m/s²];
    NCA: ``Δasr_k = (1/W) Σ (â_i − â_{i−1}) = (â_k − â_{k−W}) / W`` [m/s² per frame].
    """
    u = states[..., 1] / dt if model == "ncv" else states[..., 2]
    out = np.full(u.shape, np.nan)
    out[..., window:] = (u[..., window:] - u[..., :-window]) / window
    return out


# ==========================================================================================
# results
# ==========================================================================================


@dataclass(frozen=True)
class AirRangeResult:
    """Outcome of :func:`run`.

    Attributes:
        runs: number of Monte-Carlo runs.
        seed: the noise seed.
        truth: the trajectory.
        records: experiment-JSON records (INTERFACES.md): ``estimator``, ``metric``,
            ``unit``, ``mean``, ``stderr``, ``paper`` (None: the paper gives figures
            only), ``params``; the bound as estimator ``crlb`` and the ratios
            ``*_over_crlb``.
        errors: per estimator, range error estimate − truth [m], (runs, N).
        sigma_v: per filter, σ_v used at each frame [m/s²], (runs, N) (NaN at frame 0).
        window_mean: per fixed-noise filter, the paper's windowed mean of its own
            estimates (seed 002 eq. 16 ``asr`` [m/s²] for NCV, eq. 23 ``Δasr`` [m/s² per
            frame] for NCA), (runs, N) (NaN for the first W frames).
        bound: √PCRB of the range per frame [m], (N,) (:func:`pcrb`).
    """

    runs: int
    seed: int
    truth: AirRangeTrajectory
    records: list[dict[str, Any]]
    errors: dict[str, FloatArray]
    sigma_v: dict[str, FloatArray] = field(default_factory=dict)
    window_mean: dict[str, FloatArray] = field(default_factory=dict)
    bound: FloatArray = field(default_factory=lambda: np.empty(0))

    @property
    def estimators(self) -> list[str]:
        """Estimator names in table order (without ``crlb``)."""
        return list(self.errors)

    def rms_error(self, estimator: str) -> FloatArray:
        """RMS over runs of the range error of one estimator per frame [m], (N,)."""
        return np.sqrt(np.mean(self.errors[estimator] ** 2, axis=0))

    def record(self, estimator: str, metric: str) -> dict[str, Any]:
        """The record of one estimator and metric."""
        for r in self.records:
            if r["estimator"] == estimator and r["metric"] == metric:
                return r
        raise KeyError(f"no record for estimator {estimator!r}, metric {metric!r}")

    def table_rows(self) -> list[dict[str, Any]]:
        """One row per estimator and one for ``crlb``: mean and standard error of each
        metric [m] and the ratio to the bound (mean and standard error over runs)."""
        rows = []
        for name in (*self.errors, "crlb"):
            row: dict[str, Any] = {"estimator": name}
            for metric in METRICS:
                rec = self.record(name, metric)
                row[f"{metric}_m"] = rec["mean"]
                row[f"{metric}_stderr_m"] = rec["stderr"]
                ratio = None if name == "crlb" else self.record(name, f"{metric}_over_crlb")
                row[f"{metric}_over_crlb"] = None if ratio is None else ratio["mean"]
                row[f"{metric}_over_crlb_stderr"] = None if ratio is None else ratio["stderr"]
            rows.append(row)
        return rows


def _segments(truth: AirRangeTrajectory) -> dict[str, NDArray[np.bool_]]:
    """Frames of each metric: all, true range > 2.5 km (far), the rest (near)."""
    far = truth.range > FAR_RANGE_M
    return {"rmse_range": np.ones_like(far), "rmse_range_far": far, "rmse_range_near": ~far}


def _records(
    errors: dict[str, FloatArray],
    params: dict[str, dict[str, Any]],
    truth: AirRangeTrajectory,
    bound: FloatArray,
) -> list[dict[str, Any]]:
    """Per estimator × metric, then ``crlb`` × metric, then the ``*_over_crlb`` ratios."""
    segments = _segments(truth)
    per_run = {
        n: {m: np.sqrt(np.mean(e[:, mask] ** 2, axis=-1)) for m, mask in segments.items()}
        for n, e in errors.items()
    }
    crlb = {m: math.sqrt(float(np.mean(bound[mask] ** 2))) for m, mask in segments.items()}
    recs = [record(n, m, "m", per_run[n][m], params=params[n]) for n in errors for m in METRICS]
    recs += [record("crlb", m, "m", crlb[m], params=CRLB_PARAMS) for m in METRICS]
    for n, e in errors.items():
        for m, mask in segments.items():
            recs.append(_ratio_record(n, m, np.mean(e[:, mask] ** 2, axis=-1), crlb[m], params[n]))
    return recs


def _ratio_record(
    name: str, metric: str, mse: FloatArray, bound_rms: float, params: dict[str, Any]
) -> dict[str, Any]:
    """``{metric}_over_crlb``: √(MSE pooled over runs and frames) / RMS √bound, with the
    delta-method standard error from the per-run mean squared errors ``mse`` [m²]."""
    pooled = float(np.mean(mse))
    rec = record(name, f"{metric}_over_crlb", "1", math.sqrt(pooled) / bound_rms, params=params)
    if mse.size > 1:
        se_mse = float(np.std(mse, ddof=1)) / math.sqrt(mse.size)
        rec["stderr"] = se_mse / (2.0 * math.sqrt(pooled) * bound_rms)
    return rec


@dataclass(frozen=True)
class AirRangeChunk:
    """Per-run output of :func:`chunk` (what a Dask task returns).

    Attributes:
        runs: global run indices, (B,).
        errors: per estimator, range error estimate − truth [m], (B, N).
        sigma_v: per filter, σ_v at each frame [m/s²], (B, N).
        params: per estimator, the record ``params``.
        window_mean: per fixed-noise filter, seed 002 eq. 16 / 23 on its estimates, (B, N).
    """

    runs: NDArray[np.int64]
    errors: dict[str, FloatArray]
    sigma_v: dict[str, FloatArray]
    params: dict[str, dict[str, Any]]
    window_mean: dict[str, FloatArray] = field(default_factory=dict)


def chunk(
    indices: Sequence[int],
    runs: int | None = None,
    seed: int = 0,
    *,
    progress: ProgressCallback | None = None,
) -> AirRangeChunk:
    """Runs ``indices`` of the comparison (the parallel protocol of
    :mod:`seawatch.scenarios.parallel`): per-run errors of raw, NCV ×3, NCA ×3, ANCV, ANCA.

    Run i draws from its own stream (:func:`simulate`) and the filters treat the runs of
    a batch independently, so run i's errors are the same whatever chunk it is in.

    Args:
        indices: global run indices.
        runs: total number of runs (unused: a run does not depend on it).
        seed: seed of the measurement noise.
        progress: ``progress(done, total)`` after each estimator (total 9).
    """
    idx = np.asarray(list(indices), dtype=np.int64)
    if idx.size == 0 or np.any(idx < 0):
        raise ValueError(f"indices: expected non-negative run indices, got {indices!r}")
    meas = _simulate_runs(idx.tolist(), seed)
    truth = meas.truth
    total = len(ESTIMATORS) + 1
    errors: dict[str, FloatArray] = {"raw": meas.range - truth.range}
    params: dict[str, dict[str, Any]] = {"raw": {}}
    sigma_v: dict[str, FloatArray] = {}
    window_mean: dict[str, FloatArray] = {}
    if progress is not None:
        progress(1, total)
    z = meas.range
    for i, spec in enumerate(ESTIMATORS, start=2):
        flt = make_filter(spec, z[:, 0])
        res = flt.filter(z[:, 1:])
        x0, _ = initial_state(z[:, 0], spec.model)
        states = np.concatenate([x0[:, None, :], res.states], axis=1)  # (B, N, n)
        errors[spec.name] = states[..., 0] - truth.range
        sig = np.full(z.shape, np.nan)
        sig[:, 1:] = res.sigma_v
        sigma_v[spec.name] = sig
        if not spec.adaptive:
            window_mean[spec.name] = _paper_window_mean(states, spec.model, DT_S, WINDOW)
        params[spec.name] = _params(spec, flt)
        if progress is not None:
            progress(i, total)
    return AirRangeChunk(
        runs=idx, errors=errors, sigma_v=sigma_v, params=params, window_mean=window_mean
    )


def _combine(payloads: Sequence[AirRangeChunk], seed: int) -> AirRangeResult:
    """Concatenate chunks (in run order) and compute the records over all runs."""
    if not payloads:
        raise ValueError("payloads: expected at least one chunk")
    order = sorted(payloads, key=lambda p: int(p.runs[0]))
    truth = trajectory()
    names = list(order[0].errors)
    errors = {n: np.concatenate([p.errors[n] for p in order]) for n in names}
    sigma_v = {n: np.concatenate([p.sigma_v[n] for p in order]) for n in order[0].sigma_v}
    window_mean = {
        n: np.concatenate([p.window_mean[n] for p in order]) for n in order[0].window_mean
    }
    bound = pcrb(truth).rmse_bound(0)
    return AirRangeResult(
        runs=int(errors["raw"].shape[0]),
        seed=int(seed),
        truth=truth,
        records=_records(errors, order[0].params, truth, bound),
        errors=errors,
        sigma_v=sigma_v,
        window_mean=window_mean,
        bound=bound,
    )


def run(runs: int = 100, seed: int = 0, progress: ProgressCallback | None = None) -> AirRangeResult:
    """Run the ``air-range`` comparison: raw, NCV ×3, NCA ×3, ANCV, ANCA, and the bound.

    ``chunk(range(runs))`` then the records over the runs (the same code as the
    parallel runner's :func:`chunk` + :func:`merge`).

    Args:
        runs: Monte-Carlo runs (all filters see the same noise draws).
        seed: seed of the measurement noise (run i: ``SeedSequence(seed, spawn_key=(i,))``).
        progress: optional ``callable(done, total)`` called after each estimator.

    Returns:
        AirRangeResult with the records of every estimator × metric, the bound and the
        ratios, the per-frame errors, the σ_v histories and the paper's window means.
    """
    n = _check_runs(runs)
    return _combine([chunk(range(n), n, seed, progress=progress)], seed)


# ==========================================================================================
# outputs
# ==========================================================================================


@dataclass(frozen=True)
class DemoResult:
    """What :func:`run_demo` wrote.

    Attributes:
        rows: the table (one dict per estimator and ``crlb``, see
            :meth:`AirRangeResult.table_rows`).
        records: the experiment-JSON records.
        table_path: ``errors.csv``.
        plot_path: ``range_error.png`` (every filter).
        figure_paths: the paper's Figs. 3–6 (:data:`FIGURES`), in that order.
        result: the full :class:`AirRangeResult`.
    """

    rows: list[dict[str, Any]]
    records: list[dict[str, Any]]
    table_path: Path
    plot_path: Path
    result: AirRangeResult
    figure_paths: list[Path] = field(default_factory=list)


FIGURES = (
    "range_error_fig3_ncv.png",
    "range_error_fig4_nca.png",
    "range_error_fig5_ancv.png",
    "range_error_fig6_anca.png",
)
"""File names of the paper's Figs. 3–6 (module docstring, "Figures")."""


def write_table(rows: list[dict[str, Any]], path: Path) -> Path:
    """Write the per-estimator table as CSV (metres and ratios, 4 decimals)."""
    path = Path(path)
    cols = list(rows[0])
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for row in rows:
            w.writerow(
                [
                    ""
                    if row[c] is None
                    else (f"{row[c]:.4f}" if isinstance(row[c], float) else row[c])
                    for c in cols
                ]
            )
    return path


def run_demo(
    out_dir: Path, runs: int = 50, seed: int = 0, progress: ProgressCallback | None = None
) -> DemoResult:
    """Run the scenario and write ``errors.csv``, ``range_error.png`` and the paper's
    Figs. 3–6 (:data:`FIGURES`) into ``out_dir``.

    Every plot shows the RMS range error against the true range (range decreasing left
    to right, like the approach), the raw measurement's σ_d and the bound √PCRB.
    """
    return _write_demo(run(runs, seed, progress), out_dir)


_STYLE: dict[str, dict[str, Any]] = {
    "raw": {"color": "0.6", "lw": 0.9},
    "ncv-1": {"color": "#9ecae1", "lw": 1.3},
    "ncv-5": {"color": "#4292c6", "lw": 1.3},
    "ncv-10": {"color": "#08519c", "lw": 1.3},
    "nca-0.001": {"color": "#fdae6b", "lw": 1.3},
    "nca-0.01": {"color": "#f16913", "lw": 1.3},
    "nca-0.1": {"color": "#a63603", "lw": 1.3},
    "ancv": {"color": "#238b45", "lw": 2.2},
    "anca": {"color": "#cb181d", "lw": 2.2},
}


def _plot(
    path: Path,
    result: AirRangeResult,
    names: Sequence[str],
    title: str,
    lower: Sequence[tuple[str, FloatArray, dict[str, Any]]],
    lower_label: str,
    *,
    lower_linthresh: float | None = None,
    bands: Sequence[tuple[FloatArray, FloatArray, dict[str, Any]]] = (),
    thin: Sequence[str] = (),
) -> Path:
    """Error-vs-range figure: RMS range error of ``names`` (``thin``: drawn faint), σ_d
    and √PCRB on top (log scale); ``lower`` curves (and shaded ``bands``) below."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    truth = result.truth
    d = truth.range
    fig = Figure(figsize=(9.0, 6.8))
    FigureCanvasAgg(fig)
    ax, ax2 = fig.subplots(2, 1, sharex=True, height_ratios=[3, 1.4])
    fig.subplots_adjust(left=0.1, right=0.98, top=0.94, bottom=0.08, hspace=0.06)
    for name in names:
        style = dict(_STYLE.get(name, {"lw": 1.2}))
        if name in thin:
            style.update(lw=0.9, alpha=0.55)
        ax.plot(d, result.rms_error(name), label=name, **style)
    sigma_d = size_range_std(d, SIGMA_L_PX, SIZE_M, FOCAL_PX)
    ax.plot(d, sigma_d, "k--", lw=1.0, label="raw σ_d = d²σ_l/(fL)")
    ax.plot(d, result.bound, "k-", lw=2.0, label="√PCRB (crlb)")
    ax.set_yscale("log")
    ax.set_ylabel(f"RMS range error over {result.runs} runs [m]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(ncol=3, fontsize=8, loc="upper center")
    for lo, hi, style in bands:
        ax2.fill_between(d, lo, hi, **style)
    for label, y, style in lower:
        ax2.plot(d, y, label=label, **style)
    if lower_linthresh is not None:
        ax2.set_yscale("symlog", linthresh=lower_linthresh)
    else:
        ax2.set_yscale("log")
    ax2.set_ylabel(lower_label)
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(ncol=2, fontsize=7, loc="upper left")
    for a in (ax, ax2):
        a.axvline(PULLUP_RANGE_M, color="0.3", lw=0.8, ls=":")
    ax.annotate(
        "pull-up", (PULLUP_RANGE_M, 1.0), xycoords=("data", "axes fraction"),
        xytext=(3, -12), textcoords="offset points", fontsize=8,
    )  # fmt: skip
    ax2.set_xlim(float(d.max()), float(d.min()))  # range decreasing left to right
    ax2.set_xlabel("true range [m]")
    fig.suptitle(title, fontsize=11)
    fig.savefig(path, dpi=110)
    return path


def _median(x: FloatArray) -> FloatArray:
    out = np.full(x.shape[-1], np.nan)
    have = np.any(np.isfinite(x), axis=0)
    out[have] = np.nanmedian(x[:, have], axis=0)
    return out


def _write_figures(result: AirRangeResult, out: Path) -> tuple[Path, list[Path]]:
    """``range_error.png`` and the paper's Figs. 3–6 (module docstring, "Figures")."""
    truth = result.truth
    tail = f"{result.runs} runs, seed {result.seed}"
    acc = truth.range_acceleration
    jump = np.concatenate([[np.nan], np.diff(acc)])  # d̈_k − d̈_{k−1} [m/s² per frame]
    black = {"color": "k", "lw": 1.6}
    level = {"lw": 0.8, "ls": ":"}
    sig = {s.name: _median(result.sigma_v[s.name]) for s in ESTIMATORS if s.adaptive}
    band = {
        s.name: np.nanpercentile(result.sigma_v[s.name][:, 1:], [10, 90], axis=0)
        for s in ESTIMATORS
        if s.adaptive
    }
    pad = np.full((2, 1), np.nan)
    main = _plot(
        out / "range_error.png",
        result,
        result.estimators,
        f"air-range: RMS range error, every filter ({tail})",
        [(f"{n} σ_v (median)", sig[n], dict(_STYLE[n])) for n in sig],
        "σ_v [m/s²]",
    )
    figs = []
    ncv = [s.name for s in ESTIMATORS if s.model == "ncv" and not s.adaptive]
    nca = [s.name for s in ESTIMATORS if s.model == "nca" and not s.adaptive]
    figs.append(
        _plot(
            out / FIGURES[0],
            result,
            ["raw", *ncv],
            f"seed 002 Fig. 3 — NCV, σ_v = 1, 5, 10 m/s² ({tail})",
            [("true d̈", acc, black)]
            + [
                (f"{n}: asr (eq. 16, median)", _median(result.window_mean[n]), _STYLE[n])
                for n in ncv
            ],
            "range acceleration [m/s²]",
            lower_linthresh=0.1,
        )
    )
    figs.append(
        _plot(
            out / FIGURES[1],
            result,
            ["raw", *nca],
            f"seed 002 Fig. 4 — NCA, Δa = 0.001, 0.01, 0.1 m/s² ({tail})",
            [("true d̈_k − d̈_{k−1}", jump, black)]
            + [
                (f"{n}: Δasr (eq. 23, median)", _median(result.window_mean[n]), _STYLE[n])
                for n in nca
            ],
            "change of d̈ per\nframe [m/s²]",
            lower_linthresh=1e-3,
        )
    )
    for fig_name, adaptive, fixed, truth_curve, truth_label, unit in (
        (FIGURES[2], "ancv", ncv, np.abs(acc), "true |d̈|", "σ_v [m/s²]"),
        (FIGURES[3], "anca", nca, np.abs(jump), "true |d̈_k − d̈_{k−1}|", "σ_v (Δa) [m/s²]"),
    ):
        spec = next(s for s in ESTIMATORS if s.name == adaptive)
        fixed_levels = [
            (f"{n} σ_v", np.full(truth.range.size, s.sigma), {**_STYLE[n], **level})
            for n in fixed
            for s in ESTIMATORS
            if s.name == n
        ]
        lo, hi = np.concatenate([pad, band[adaptive]], axis=1)
        shade = {
            "color": _STYLE[adaptive]["color"],
            "alpha": 0.2,
            "label": f"{adaptive} σ_v 10–90 %",
        }
        figs.append(
            _plot(
                out / fig_name,
                result,
                ["raw", *fixed, adaptive],
                f"seed 002 Fig. {5 if adaptive == 'ancv' else 6} — {adaptive.upper()} "
                f"(start σ_v = {spec.sigma:g} m/s², W = {WINDOW}) and "
                f"{spec.model.upper()} ({tail})",
                [
                    (f"{adaptive} σ_v (median)", sig[adaptive], dict(_STYLE[adaptive])),
                    (truth_label, truth_curve, black),
                    *fixed_levels,
                ],
                unit,
                bands=[(lo, hi, shade)],
                thin=[n for n in fixed if n != ("ncv-1" if adaptive == "ancv" else "nca-0.01")],
            )
        )
    return main, figs


def _write_demo(result: AirRangeResult, out_dir: Path | str) -> DemoResult:
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows = result.table_rows()
    table_path = write_table(rows, out / "errors.csv")
    plot_path, figures = _write_figures(result, out)
    return DemoResult(
        rows=rows,
        records=result.records,
        table_path=table_path,
        plot_path=plot_path,
        result=result,
        figure_paths=figures,
    )


def _check_runs(runs: int) -> int:
    return integer("runs", runs, 1)


def merge(
    payloads: Sequence[AirRangeChunk],
    runs: int | None = None,
    seed: int = 0,
    out_dir: Path | str | None = None,
) -> ExperimentResult:
    """The experiment JSON from the chunks of :func:`chunk` (in run order; the parallel
    protocol of :mod:`seawatch.scenarios.parallel`), plus ``errors.csv``,
    ``range_error.png`` and the paper's Figs. 3–6 in ``out_dir`` when one is given."""
    result = _combine(payloads, seed)
    if runs is not None and result.runs != runs:
        raise ValueError(f"payloads: expected {runs} runs in all, got {result.runs}")
    if out_dir is None:
        return ExperimentResult(SCENARIO, result.runs, int(seed), result.records)
    demo = _write_demo(result, out_dir)
    return ExperimentResult(
        SCENARIO,
        result.runs,
        int(seed),
        demo.records,
        outputs=[demo.table_path, demo.plot_path, *demo.figure_paths],
    )


def experiment(
    runs: int = 100,
    seed: int = 0,
    out_dir: Path | None = None,
    progress: ProgressCallback | None = None,
) -> ExperimentResult:
    """``seawatch experiment air-range``: ``merge([chunk(range(runs))])`` — :func:`run`,
    plus ``errors.csv``, ``range_error.png`` and Figs. 3–6 in ``out_dir`` when one is given."""
    n = _check_runs(runs)
    return merge([chunk(range(n), n, seed, progress=progress)], n, seed, out_dir)
