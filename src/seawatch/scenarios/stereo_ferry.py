"""Scenario ``stereo-ferry``: binocular ranging and strong tracking of a ferry (seed 003).

SCENARIOS.md ``stereo-ferry``; ALGORITHMS.md §2 (STKF) and §6 (stereo). Huang et al.
film two Yangtze ferries with a 640×480 stereo pair at 25 frames/s (calibration: seed
Tables 1–2, :data:`seawatch.camera.SEED003_CALIBRATION`), triangulate two feature points
over 400 frames (16 s) with the inhomogeneous least squares of their eq. 3, take the
average speed of the two points as the ship's "partial trajectory" (exp. 1: 1.5683 m/s,
exp. 2: 2.2509 m/s), and then track the ship over 300 m with a conventional KF, an STKF
(β = 4.5, ρ = 0.95) and the STKF started from the stereo-measured speed. Table 3 gives
the RMSE of the one-step *prediction error*, "the observation Z at that time minus the
prediction", for position and speed.

Synthetic runs (**resolved** here; SCENARIOS.md fixes Δt, R, the speeds and the
durations, the rest is ours):

* **Geometry.** World frame = left camera (x right, y down, z forward), metres. The
  ship starts at the first stereo fix of the paper's experiment 1, feature point 2
  (the seed's inhomogeneous triangulation of left (416.587, 110.500), right
  (448.761, 108.761)): ``X0 = (1.857, −1.566, 17.766) m``, range 17.93 m, and recedes
  **radially** (along the line of sight through X0, a constant bearing), so that it
  stays in both images for the whole run. (The direction of the paper's 16-s track,
  mostly away but 24° to the left, leaves the left image after about 43 m; no straight
  300 m path stays at "tens of metres", and none but a near-radial one stays in view.)
  Experiment 2's pixel coordinates are garbled in the extracted text (they give negative
  depth), so it uses the same start and direction at its own speed.
* **Truth.** Along-track distance ``s(t)`` from X0 and speed ``v(t) = v̄ + δv(t)``
  with ``v̄`` the paper's stereo-measured average speed and ``δv`` small fluctuations:
  an Ornstein–Uhlenbeck process with standard deviation **0.05 m/s** (about 3 % / 2 %
  of the speed) and correlation time **20 s**, with its run mean removed so that every
  run covers exactly ``v̄ T``: exp. 1 1.5683 m/s × 200 s = 313.7 m (range 17.9 → 331.6 m,
  5000 frames), exp. 2 2.2509 m/s × 137 s = 308.4 m (range 17.9 → 326.3 m, 3425 frames;
  the paper's "300 m (200 s)" and "300 m (137 s)"). ``s`` integrates ``v`` with the
  trapezoidal rule.
* **Measurement.** The true point ``X0 + s u`` is projected into both cameras, every
  pixel coordinate gets independent N(0, 0.5²) px matching noise, the pair is
  triangulated with the seed's inhomogeneous least squares (ALGORITHMS.md §6.1,
  :func:`seawatch.camera.triangulate` ``method="inhomogeneous"``, computed here by the
  equivalent normal equations for speed; a test checks the two agree), and the
  along-track position measurement is ``z = u · (X̂ − X0)`` [m].
* **Filters** (seed eqs. 4–16): state ``[s, v]``, ``F = [[1, Δt], [0, 1]]``,
  ``H = [1, 0]``, Δt = 0.04 s. One **Q** for all three: the discrete white-noise
  acceleration of the paper's Γ = [Δt²/2, Δt], ``Q = σ_a² Γ Γᵀ`` with
  ``σ_a² = q / Δt``, ``q = 2 σ_δv² / τ = 2.5·10⁻⁴ m²/s³`` (the driving intensity of the
  truth's fluctuation; σ_a = 0.079 m/s²). **R** at frame k: the first-order variance of
  the along-track triangulation at the current (true) point for 0.5 px per coordinate,
  ``R_k = uᵀ Σ(X_k) u`` (:func:`seawatch.camera.triangulation_covariance`), the §6.3
  depth error ``Z² σ_d / (f B)`` of this unrectified rig: 0.91 m (1σ) at 17.9 m,
  5.2 m at 43 m, 39 m at 118 m, 285 m at 318 m. One **P0**, ``diag(R_0, σ_v0²)``, in
  two readings (``variant=``, :data:`VARIANTS`, ``seawatch experiment stereo-ferry
  --variant stereo-prior``): ``"matched"`` (default) σ_v0 = 0.1 m/s, covering what the
  initial speeds are actually off by (the guesses 0.068 / 0.051 m/s, the truth's
  frame-0 fluctuation 0.05 m/s); ``"stereo-prior"`` σ_v0 = :func:`stereo_speed_std`,
  the accuracy of the speed the 16-s stereo video measures — the Cramér–Rao bound of a
  constant-speed fit through its 400 fixes with the R above, 0.0265 / 0.0355 m/s
  (brute-force tested) — i.e. the paper's initial speed used as if known to stereo
  accuracy, also by the KF and STKF whose guess is 2.6 / 1.4 σ_v0 off. Every filter
  starts at frame 0 from ``x0 = [z_0, v_0]`` and filters frames 1…N−1; KF and STKF take
  the paper's speed guess ``v_0`` = 1.5 / 2.2 m/s, stereo + STKF the stereo-measured
  1.5683 / 2.2509 m/s — the only difference between the last two. STKF: β = 4.5,
  ρ = 0.95, Zhou's order (fading factor from the current innovation, ALGORITHMS.md §2);
  ``late_fading=True`` adds the seed-literal one-step-late order as an ablation
  (estimators ``stkf-late``, ``stereo-stkf-late``).

Randomness: run i of experiment e draws from ``SeedSequence(seed, spawn_key=(e − 1,
i))`` and every step treats the runs of a batch independently, so a run's numbers do
not depend on the chunk or Dask worker it runs in (:func:`chunk` / :func:`merge`, the
protocol of :mod:`seawatch.scenarios.parallel`; :func:`run` is
``merge([chunk(range(runs))])``).

Metrics (per run: RMS over frames 1…N−1 of the run; records: mean ± standard error over
runs; all filters see the same noise):

* ``rmse_position_pred`` [m] — the paper's metric: one-step innovation
  ``z_k − ŝ_k⁻`` (observation minus prediction).
* ``rmse_speed_pred`` [m/s] — the paper's speed prediction error with the speed
  "observation" taken as the finite difference of consecutive position observations,
  ``(z_k − z_{k−1}) / Δt − v̂_k⁻`` (the paper observes position only, H = [1, 0], and
  does not say what its speed observation is).
* ``rmse_position_pred_truth`` [m], ``rmse_speed_pred_truth`` [m/s] — the same
  prediction against the truth, ``s_k − ŝ_k⁻`` and ``v_k − v̂_k⁻``.

Each comes for the whole run (params ``{"experiment": e}``, with the paper's Table 3
value for the first two) and for the first 16 s, the length of the paper's video
(params ``{"experiment": e, "window_s": [0.0, 16.0]}``). The triangulation comparison
(estimators ``triangulation-inhomogeneous`` — the seed's, used above —,
``triangulation-homogeneous`` — the DLT of ``cv2.triangulatePoints`` — and
``triangulation-optimal`` — ``cv2.correctMatches`` then triangulation, the
reprojection-optimal point under Gaussian pixel noise) reports ``bias_range``,
``rmse_range`` and ``median_error_range`` [m] of the range from the left camera, per
true-range band (params ``{"experiment": e, "range_m": [lo, hi]}``). The homogeneous
DLT is computed in the rig's native millimetres (the unit of the seed's tables; it is
not invariant to the world unit).

Outcome (1000 runs, seed 0; position [m] / speed [m/s], paper's metric, whole run; both
variants give these to four figures):

=============  ===============  ===============  ===============  ===============
filter         exp. 1 ours      exp. 1 paper     exp. 2 ours      exp. 2 paper
=============  ===============  ===============  ===============  ===============
KF             251.9 / 8862     1.3901 / 0.1329  247.0 / 8607     1.0992 / 0.2645
STKF           353.6 / 9447     0.3706 / 0.1054  340.7 / 9119     0.8218 / 0.1606
stereo + STKF  353.6 / 9447     0.3373 / 0.0911  340.7 / 9119     0.5579 / 0.1258
=============  ===============  ===============  ===============  ===============

(standard errors 4–11 m and 140–280 m/s). First 16 s (the video; range 18–43 / 18–54 m),
``stereo-prior``, against the observation (the paper's metric) and against the truth:

=============  ===============  ===============  ===============  ===============
filter         exp. 1 obs.      exp. 1 truth     exp. 2 obs.      exp. 2 truth
=============  ===============  ===============  ===============  ===============
KF             3.117 / 109.4    0.280 / 0.058    4.650 / 163.7    0.293 / 0.050
STKF           3.291 / 109.7    1.042 / 1.072    4.993 / 164.3    1.759 / 2.382
stereo + STKF  3.287 / 109.7    1.027 / 1.050    4.991 / 164.3    1.748 / 2.364
=============  ===============  ===============  ===============  ===============

(``matched``: within 0.003 m of these against the observation, 0.025 m and 0.025 m/s
against the truth; standard errors 0.006–0.017 m, 0.25–0.44 m/s, 0.004–0.024 m and
0.0007–0.11 m/s.) The paper's ordering KF > STKF > stereo + STKF does **not** hold in
either variant, so the filters' exact model (``matched``) stays the default:

* The magnitudes are set by the stereo range error, not by the filters: σ grows as Z²
  from 0.9 m at 18 m to 285 m at 318 m (a 0.2 m baseline with 0.5 px cannot range a
  ship 300 m away: the disparity there is 0.7 px). The paper's 0.34–1.39 m need a
  measurement noise of a few tenths of a metre, about 10 m range for this rig. The
  speed "observation" Δz/Δt carries √2 σ / Δt of noise (35 σ: the 109 / 164 m/s above).
* STKF > stereo + STKF holds in the first 16 s, in every column, by a little: the
  initial speed (0.068 / 0.051 m/s closer to the truth) is the only difference between
  them (paired difference > 3 s.e. in the first 4 s, tested); over the whole run the
  two coincide to four figures.
* KF > STKF holds nowhere — both columns, both experiments, the video and the whole
  run, against the observation and the truth, with either P0. Issue 8's reading was
  that a KF trusting its initial speed stays stuck with the guess's 0.07 m/s error while
  the STKF's fading factor detects it. Neither happens:

  - The fading test (ALGORITHMS.md §2) passes when the innovation power exceeds about
    β R, so an innovation bias b shows only if b² ≳ (β − 1) R, b ≳ 1.9 σ_z: 1.7 m at
    18 m, 9.7 m at 43 m (the end of the video). The guess gives b ≤ 0.068 t ≤ 1.1 m
    (tested). The factor does not see it: with ``stereo-prior`` it fires on 1.71 % of
    the frames of the first 2 s with the guess and 1.66 % with the stereo speed
    (exp. 2: 1.68 / 1.64 %), on 1.9–2.3 % over 2–16 s and on 10 % beyond 16 s
    (``diagnostics.fading_fraction_by_period``) — chance firings (white unit
    innovations pass the test on 0.6 % of frames, and each firing disturbs the state
    and makes the next likelier) and, far out, the heavy tails of the seed's
    triangulation (KF mean NIS over the run 4.0 / 4.6; 1.01 in the first 16 s).
  - A false firing is costly: with R much larger than the converged prior
    ``H F P Fᵀ Hᵀ``, ``λ = tr N / tr M`` is large (median 7, up to the clamp of 100)
    and multiplies the speed variance too, so the update turns into a two-point
    differentiator with a speed error of order √2 σ_z / Δt; the long memory of a
    low-Q filter keeps it and it re-triggers the test. The seed-literal one-step-late
    fading is less harmful (274 / 265 m, whole run) but still behind the KF.
  - The KF is not stuck: Q (the truth's own fluctuation) adds (0.068 m/s)² of speed
    variance in 18 s and the measurements take it from there; its speed error against
    the truth over the video is 0.058 / 0.050 m/s, below the guess's error.

* Where the ordering would appear: with ``stereo-prior`` and a larger guess error
  (400 runs, first 16 s, position column), KF > STKF once the guess is 0.5 m/s off
  (exp. 1; at 0.4 m/s the KF is still 0.02 m ahead) or 0.7 m/s (exp. 2; at 0.5 m/s
  0.10 m ahead) — 7–14 × the paper's error; at 1 m/s the factor fires on the mismatch
  and KF > STKF > stereo + STKF holds in the position column (tested). The speed column
  is the wrong way at every guess error: its differentiation noise hides the filters'
  speed errors, and the STKF's false firings add 0.3 / 0.7 m/s to it. If the paper's
  speed observation is such a difference, its 0.09–0.26 m/s imply σ_z ≤ 2.6–7.5 mm:
  nearly noise-free observations (its pixel coordinates are interpolated linearly
  between frames 1 and 400), the one regime where the innovations show a 0.07 m/s
  speed error and nothing else.

Triangulation (same runs, every 10th frame, median range error; ALGORITHMS.md §6.1):
the seed's inhomogeneous least squares understates the range by 0.25 m below 50 m,
2.9 m at 50–100 m, 23 m at 100–200 m and 99 m beyond 200 m, while the
reprojection-optimal point (and the homogeneous DLT, within 0.01 m of it) is
median-unbiased (|median| < 1.5 m); the seed's form has the smaller RMSE at long range
only because it never puts a point near infinity, where the optimal/homogeneous ones
have heavy tails (mean and RMSE in the thousands of metres beyond 100 m).
"""

from __future__ import annotations

import csv
import itertools
import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from seawatch._validation import FloatArray, as_float_array, integer, positive
from seawatch.camera import SEED003_CALIBRATION, triangulate, triangulation_covariance
from seawatch.filters import KalmanFilter, StrongTrackingKalmanFilter
from seawatch.models.kinematic import constant_velocity, position_measurement
from seawatch.scenarios.base import ExperimentResult, ProgressCallback, record

SCENARIO = "stereo-ferry"
DT_S = 0.04
"""Frame period Δt [s] (25 frames/s)."""
MATCH_SIGMA_PX = 0.5
"""Pixel matching noise per image coordinate [px] (σ_d = √2 · 0.5 px on the disparity)."""
BETA = 4.5
"""STKF weakening factor β (seed 003)."""
RHO = 0.95
"""STKF forgetting factor ρ (seed 003)."""
SPEED_FLUCTUATION_MPS = 0.05
"""Standard deviation of the truth's speed fluctuation δv [m/s]."""
SPEED_CORRELATION_S = 20.0
"""Correlation time τ of the truth's speed fluctuation (Ornstein–Uhlenbeck) [s]."""
INITIAL_SPEED_STD_MPS = 0.1
"""Speed standard deviation of the shared P0 in the ``matched`` variant [m/s] (covers the
guesses' 0.07 / 0.05 m/s error and the truth's 0.05 m/s fluctuation at frame 0)."""
VARIANTS: dict[str, str] = {
    "matched": "P0 speed sigma 0.1 m/s, covering the initial-speed errors (default)",
    "stereo-prior": "P0 speed sigma = the stereo speed accuracy of the 16-s video "
    "(stereo_speed_std: 0.027 / 0.035 m/s), trusted by all three filters",
}
"""Readings of the shared P0 (``variant=``); Q and R are the same in both."""
DEFAULT_VARIANT = "matched"
VIDEO_WINDOW_S = 16.0
"""Length of the paper's stereo video (400 frames) [s]: the early window reported."""
RANGE_BANDS_M: tuple[tuple[float, float], ...] = (
    (0.0, 50.0),
    (50.0, 100.0),
    (100.0, 200.0),
    (200.0, math.inf),
)
"""True-range bands [m] of the triangulation comparison."""
CHUNK_RUNS = 250
"""Monte-Carlo runs processed together (bounds memory; results do not depend on it)."""
CHUNK_MAX = CHUNK_RUNS
"""Largest chunk the parallel runner sends to one task (:mod:`seawatch.scenarios.parallel`)."""
CHUNK_MIN = 50
"""Smallest chunk of the parallel runner's default plan."""
PARALLEL_MIN_COST = 200
"""Below this many runs the default (no ``--workers``) runs in one process (a run costs
about 0.07 s, a local cluster 5–10 s to start)."""
CHUNK_ALIGN = 50
"""The per-frame sums of the plots are taken over aligned blocks of this many runs and
added in block order, so chunks starting on multiples of 50 give bit-identical outputs
(the records are per-run values and never depend on the chunking)."""
COMPARE_EVERY = 10
"""The triangulation comparison uses every 10th frame of every run."""
FADING_PERIODS_S: tuple[tuple[str, float, float], ...] = (
    ("0-2s", 0.0, 2.0),
    ("2-16s", 2.0, VIDEO_WINDOW_S),
    ("16s-end", VIDEO_WINDOW_S, math.inf),
)
"""Time periods (name, from, to) [s] of the fading-factor diagnostics: the start-up,
where a wrong initial speed would show, the rest of the 16-s video and the far range."""

ESTIMATORS = ("kf", "stkf", "stereo-stkf")
"""The paper's three filters, INTERFACES.md names."""
LATE_ESTIMATORS = ("stkf-late", "stereo-stkf-late")
"""Ablation: the STKFs with the seed-literal one-step-late fading factor."""
TRIANGULATIONS = ("inhomogeneous", "homogeneous", "optimal")
PRED_METRICS = (
    ("rmse_position_pred", "m"),
    ("rmse_speed_pred", "m/s"),
    ("rmse_position_pred_truth", "m"),
    ("rmse_speed_pred_truth", "m/s"),
)
RANGE_METRICS = ("bias_range", "rmse_range", "median_error_range")

SEED_EXP1_POINT2_LEFT = ((416.587, 110.500), (67.891, 111.370))
"""Seed 003 experiment 1, feature point 2: left-image pixels in frames 1 and 400 [px]."""
SEED_EXP1_POINT2_RIGHT = ((448.761, 108.761), (53.978, 111.370))
"""Seed 003 experiment 1, feature point 2: right-image pixels in frames 1 and 400 [px]."""
SEED_VIDEO_FRAMES = 400


@dataclass(frozen=True)
class FerryExperiment:
    """One of the paper's two experiments.

    Attributes:
        number: 1 or 2.
        speed: stereo-measured average speed v̄ of the paper [m/s] (the truth's mean and
            stereo + STKF's initial speed).
        duration: tracking time of the paper [s] (300 m in 200 s / 137 s).
        speed_guess: the paper's assumed initial speed for KF and STKF [m/s].
        paper: Table 3, ``{estimator: (position RMSE [m], speed RMSE [m/s])}``.
    """

    number: int
    speed: float
    duration: float
    speed_guess: float
    paper: dict[str, tuple[float, float]]

    @property
    def frames(self) -> int:
        """Number of frames N = duration / Δt + 1 (frame 0 initialises the filters)."""
        return round(self.duration / DT_S) + 1

    def initial_speed(self, estimator: str) -> float:
        """Initial speed of a filter [m/s]: the stereo-measured one for ``stereo-*``."""
        return self.speed if estimator.startswith("stereo") else self.speed_guess


EXPERIMENTS: dict[int, FerryExperiment] = {
    1: FerryExperiment(
        1,
        speed=1.5683,
        duration=200.0,
        speed_guess=1.5,
        paper={"kf": (1.3901, 0.1329), "stkf": (0.3706, 0.1054), "stereo-stkf": (0.3373, 0.0911)},
    ),
    2: FerryExperiment(
        2,
        speed=2.2509,
        duration=137.0,
        speed_guess=2.2,
        paper={"kf": (1.0992, 0.2645), "stkf": (0.8218, 0.1606), "stereo-stkf": (0.5579, 0.1258)},
    ),
}
"""The paper's experiments (SCENARIOS.md ``stereo-ferry``; seed 003 §5.3, Table 3)."""


# ----------------------------------------------------------------------------- geometry
def projection_matrices_mm() -> tuple[FloatArray, FloatArray]:
    """``(P1, P2)`` of the seed 003 rig in its native unit (mm): ``K1 [I|0]``, ``K2 [R|T]``."""
    return SEED003_CALIBRATION.projection_matrices()


def seed_pixel_track(frames: int = SEED_VIDEO_FRAMES) -> tuple[FloatArray, FloatArray]:
    """Experiment 1, feature point 2, linearly interpolated over ``frames`` frames.

    Seed 003 §5.3 assumes the pixel coordinates vary linearly between frames 1 and 400.

    Returns:
        (left, right) pixel tracks [px], each (frames, 2).
    """
    t = np.linspace(0.0, 1.0, frames)[:, None]
    (l0, l1), (r0, r1) = np.array(SEED_EXP1_POINT2_LEFT), np.array(SEED_EXP1_POINT2_RIGHT)
    return l0 + t * (l1 - l0), r0 + t * (r1 - r0)


def seed_path_length(method: str = "inhomogeneous") -> float:
    """Length of the triangulated experiment 1, feature point 2 path [m] (seed: 26.4507 m).

    ALGORITHMS.md §6.1: the polyline through the 400 triangulated points of
    :func:`seed_pixel_track` (``triangulate(..., method)``, tables in mm).
    """
    left, right = seed_pixel_track()
    X = triangulate(projection_matrices_mm(), [left, right], method) / 1000.0  # type: ignore[arg-type]
    return float(np.sum(np.linalg.norm(np.diff(X, axis=0), axis=1)))


@dataclass(frozen=True)
class FerryGeometry:
    """Straight receding path in the left-camera frame [m].

    Attributes:
        start: X0 (3,), the first stereo fix of experiment 1, feature point 2 [m].
        direction: unit vector u (3,) of travel (radial: ``X0 / |X0|``).
    """

    start: FloatArray
    direction: FloatArray

    def points(self, along: ArrayLike) -> FloatArray:
        """``X0 + s u`` for along-track distances s [m]: shape (..., 3) [m]."""
        s = np.asarray(along, dtype=np.float64)
        return self.start + s[..., None] * self.direction

    def ranges(self, along: ArrayLike) -> FloatArray:
        """Distance of ``X0 + s u`` from the left camera centre [m]."""
        return np.linalg.norm(self.points(along), axis=-1)


def ferry_geometry() -> FerryGeometry:
    """The resolved geometry (module docstring): start at the seed's first fix, radial."""
    left, right = seed_pixel_track()
    X0 = triangulate(projection_matrices_mm(), [left[:1], right[:1]], "inhomogeneous")[0] / 1000.0
    return FerryGeometry(start=X0, direction=X0 / np.linalg.norm(X0))


def project(P: FloatArray, X_m: FloatArray) -> FloatArray:
    """Pixel coordinates (..., 2) [px] of points X (..., 3) [m] under a mm-unit camera P."""
    Xh = np.concatenate([X_m * 1000.0, np.ones((*X_m.shape[:-1], 1))], axis=-1)
    p = Xh @ P.T
    return p[..., :2] / p[..., 2:3]


def triangulate_inhomogeneous(
    P1: FloatArray, P2: FloatArray, left: FloatArray, right: FloatArray
) -> FloatArray:
    """Seed 003 eq. 3: two-view inhomogeneous least squares, vectorised [units of P].

    The same solution as ``triangulate([P1, P2], [left, right], "inhomogeneous")``
    (ALGORITHMS.md §6.1: ``X_4 = 1``, the 4 × 3 system ``A X = b`` with rows
    ``u p³ − p¹``, ``v p³ − p²`` per view) through the normal equations
    ``(AᵀA) X = Aᵀ b``, solved for all points at once; about 20× faster, which matters
    for 10⁷ triangulations.

    Args:
        P1, P2: (3, 4) camera matrices.
        left, right: pixel coordinates (..., 2) [px].

    Returns:
        (..., 3) points in the world unit of the P's.
    """
    AtA = np.zeros((*left.shape[:-1], 3, 3))
    Atb = np.zeros((*left.shape[:-1], 3))
    for P, x in ((P1, left), (P2, right)):
        for i in (0, 1):
            row = x[..., i : i + 1] * P[2] - P[i]  # (..., 4): u p³ − p¹ or v p³ − p²
            a, b = row[..., :3], -row[..., 3:]
            AtA += a[..., :, None] * a[..., None, :]
            Atb += a * b
    return np.linalg.solve(AtA, Atb[..., None])[..., 0]


def _fundamental_matrix() -> FloatArray:
    """F with ``x_Rᵀ F x_L = 0``: ``K_R^{-T} [T]_× R K_L^{-1}`` (seed 003 rig)."""
    rig = SEED003_CALIBRATION
    t = rig.T
    tx = np.array([[0.0, -t[2], t[1]], [t[2], 0.0, -t[0]], [-t[1], t[0], 0.0]])
    return np.linalg.inv(rig.K_right).T @ tx @ rig.R @ np.linalg.inv(rig.K_left)


def optimal_correction(
    F: FloatArray, left: FloatArray, right: FloatArray, iterations: int = 3
) -> tuple[FloatArray, FloatArray]:
    """Reprojection-optimal correction of pixel pairs onto the epipolar constraint.

    The pair ``(x̂_L, x̂_R)`` closest to the measured ``(x_L, x_R)`` (sum of squared pixel
    distances) with ``x̂_Rᵀ F x̂_L = 0`` — what ``cv2.correctMatches`` (Hartley–Sturm)
    computes, the maximum-likelihood pair for i.i.d. Gaussian pixel noise — by
    Gauss–Newton on the constraint: linearise ``g = x_Rᵀ F x_L`` at the current pair and
    take the minimum-distance point of the linearised constraint from the *measured*
    pair; three iterations agree with ``cv2.correctMatches`` to 1e-13 px on this rig
    (tested) at ~1/50 of its cost.

    Args:
        F: fundamental matrix (3, 3) with ``x_Rᵀ F x_L = 0``.
        left, right: pixel coordinates (..., 2) [px].
        iterations: Gauss–Newton iterations.

    Returns:
        Corrected (left, right), each (..., 2) [px].
    """
    L0, R0 = np.asarray(left, dtype=np.float64), np.asarray(right, dtype=np.float64)
    Lh, Rh = L0.copy(), R0.copy()
    one = np.ones((*L0.shape[:-1], 1))
    for _ in range(iterations):
        Fxl = np.concatenate([Lh, one], axis=-1) @ F.T  # F x_L
        Ftxr = np.concatenate([Rh, one], axis=-1) @ F  # Fᵀ x_R
        g = np.sum(Rh * Fxl[..., :2], axis=-1) + Fxl[..., 2]
        gl, gr = Ftxr[..., :2], Fxl[..., :2]  # ∂g/∂x_L, ∂g/∂x_R
        num = g + np.sum(gl * (L0 - Lh), axis=-1) + np.sum(gr * (R0 - Rh), axis=-1)
        k = num / (np.sum(gl * gl, axis=-1) + np.sum(gr * gr, axis=-1))
        Lh = L0 - k[..., None] * gl
        Rh = R0 - k[..., None] * gr
    return Lh, Rh


def triangulate_reference(
    method: str, P1: FloatArray, P2: FloatArray, left: FloatArray, right: FloatArray
) -> FloatArray:
    """Homogeneous DLT or reprojection-optimal triangulation of (N, 2) pixel pairs [mm].

    ``"homogeneous"``: ``cv2.triangulatePoints`` (the SVD of ALGORITHMS.md §6.1).
    ``"optimal"``: :func:`optimal_correction` (``cv2.correctMatches``), then the DLT,
    exact on the corrected (consistent) pairs: the maximum-likelihood point for Gaussian
    pixel noise. Points at infinity come out huge or inf.
    """
    if method == "optimal":
        left, right = optimal_correction(_fundamental_matrix(), left, right)
    elif method != "homogeneous":
        raise ValueError(f"method: expected 'homogeneous' or 'optimal', got {method!r}")
    Xh = cv2.triangulatePoints(P1, P2, np.ascontiguousarray(left.T), np.ascontiguousarray(right.T))
    with np.errstate(divide="ignore", invalid="ignore"):
        return (Xh[:3] / Xh[3]).T


def along_track_variance(
    geometry: FerryGeometry, along: ArrayLike, sigma_px: float = MATCH_SIGMA_PX
) -> FloatArray:
    """R: first-order variance of the along-track measurement ``u·(X̂ − X0)`` [m²].

    ``uᵀ Σ(X) u`` with Σ the triangulation covariance for ``sigma_px`` per pixel
    coordinate (:func:`seawatch.camera.triangulation_covariance`); for the radial path
    this is the squared stereo depth error of ALGORITHMS.md §6.3,
    ``(Z² σ_d / (f B))²`` with ``σ_d = √2 σ`` (for this unrectified rig, f between the
    two cameras' 1113 and 1285 px).

    Args:
        geometry: the path.
        along: along-track distances s [m], any shape.
        sigma_px: matching noise per coordinate [px].

    Returns:
        R [m²], the shape of ``along``.
    """
    s = as_float_array("along", along)
    sig = positive("sigma_px", sigma_px)
    X = geometry.points(s.reshape(-1)) * 1000.0
    cov = triangulation_covariance(projection_matrices_mm(), X, sig)  # mm²
    u = geometry.direction
    return (np.einsum("i,nij,j->n", u, cov, u) / 1e6).reshape(s.shape)


def _interpolated_variance(
    geometry: FerryGeometry, along: FloatArray, sigma_px: float
) -> FloatArray:
    """:func:`along_track_variance` through log-linear interpolation on a 0.05 m grid.

    R varies smoothly (≈ Z⁴); the interpolation error is below 2e-5 relative (tested),
    and it avoids an eigendecomposition per frame and run.
    """
    lo = math.floor(float(np.min(along))) - 1.0
    hi = math.ceil(float(np.max(along))) + 1.0
    grid = np.arange(lo, hi + 0.05, 0.05)
    logR = np.log(along_track_variance(geometry, grid, sigma_px))
    return np.exp(np.interp(along, grid, logR))


# ----------------------------------------------------------------------------- truth
@dataclass(frozen=True)
class FerryTruth:
    """Sampled truth of a batch of runs.

    Attributes:
        time: t_k = k Δt [s], (N,).
        along: along-track distance s from X0 [m], (runs, N) (s_0 = 0).
        speed: v [m/s], (runs, N).
    """

    time: FloatArray
    along: FloatArray
    speed: FloatArray


def simulate_truth(
    experiment: FerryExperiment,
    gens: Sequence[np.random.Generator],
    *,
    fluctuation: float = SPEED_FLUCTUATION_MPS,
    correlation_time: float = SPEED_CORRELATION_S,
) -> FerryTruth:
    """Truth of one run per generator: v̄ plus a zero-run-mean OU fluctuation.

    ``δv_{k+1} = a δv_k + σ √(1 − a²) ε_k``, ``a = exp(−Δt/τ)``, ``δv_0 ~ N(0, σ²)``
    (stationary Ornstein–Uhlenbeck with std σ = ``fluctuation`` [m/s] and correlation
    time τ = ``correlation_time`` [s]); the run mean of δv (trapezoid-weighted) is
    subtracted so that the run covers exactly ``v̄ T``; ``s`` is the trapezoidal
    integral of ``v``.
    """
    sig = positive("fluctuation", fluctuation, allow_zero=True)
    tau = positive("correlation_time", correlation_time)
    N = experiment.frames
    a = math.exp(-DT_S / tau)
    eps = np.stack([g.standard_normal(N) for g in gens]) if gens else np.zeros((0, N))
    dv = np.empty_like(eps)
    if eps.size:
        dv[:, 0] = sig * eps[:, 0]
        b = sig * math.sqrt(1.0 - a * a)
        for k in range(1, N):
            dv[:, k] = a * dv[:, k - 1] + b * eps[:, k]
    if eps.size and N > 1:  # remove the trapezoid-weighted run mean: s_N = v̄ T exactly
        w = np.ones(N)
        w[[0, -1]] = 0.5
        # (dv * w).sum(1), not dv @ w: BLAS gemv rounds a lone row differently from a
        # batch, and a run must not depend on the batch it is simulated in
        dv -= (dv * w).sum(axis=1)[:, None] / np.sum(w)
    v = experiment.speed + dv
    s = np.zeros_like(v)
    s[:, 1:] = np.cumsum(0.5 * DT_S * (v[:, 1:] + v[:, :-1]), axis=1)
    return FerryTruth(time=np.arange(N) * DT_S, along=s, speed=v)


# ----------------------------------------------------------------------------- filters
def process_noise(
    fluctuation: float = SPEED_FLUCTUATION_MPS, correlation_time: float = SPEED_CORRELATION_S
) -> tuple[FloatArray, FloatArray]:
    """(F, Q) of the shared CV model: DWNA with ``σ_a² = (2 σ_δv² / τ) / Δt`` (seed eq. 5)."""
    q = 2.0 * fluctuation**2 / correlation_time  # m²/s³, OU driving intensity
    return constant_velocity(1, DT_S, math.sqrt(q / DT_S))


def stereo_speed_std(
    experiment: FerryExperiment,
    sigma_px: float = MATCH_SIGMA_PX,
    frames: int = SEED_VIDEO_FRAMES,
    geometry: FerryGeometry | None = None,
) -> float:
    """Accuracy [m/s] of the speed the stereo video measures: the ``stereo-prior`` P0.

    The Cramér–Rao bound of the speed of a constant-speed path from ``frames`` stereo
    fixes (the paper's 400 frames, 16 s) with independent along-track errors of
    variance ``R(s_k)`` (:func:`along_track_variance`, ``sigma_px`` per pixel
    coordinate; ALGORITHMS.md §6.3): the speed entry of ``(Aᵀ W A)⁻¹`` with rows
    ``A_k = [1, t_k]``, ``t_k = k Δt``, ``W = diag(1 / R(v̄ t_k))`` — the standard
    deviation of the weighted least-squares slope through the partial trajectory.
    Seed 003's own estimate, the distance between the first and last fixes over 16 s,
    is far worse (``√(R_0 + R_399) / 16 s`` = 0.33 / 0.52 m/s).

    Args:
        experiment: the experiment (its v̄ sets the ranges).
        sigma_px: matching noise per coordinate [px].
        frames: number of video frames.
        geometry: the path (default :func:`ferry_geometry`).

    Returns:
        σ_v [m/s] (0.0265 for experiment 1, 0.0355 for experiment 2 at 0.5 px).
    """
    frames = integer("frames", frames, 2)
    geo = ferry_geometry() if geometry is None else geometry
    t = np.arange(int(frames)) * DT_S
    w = 1.0 / along_track_variance(geo, experiment.speed * t, sigma_px)
    info = np.array([[np.sum(w), np.sum(w * t)], [np.sum(w * t), np.sum(w * t * t)]])
    return float(math.sqrt(np.linalg.inv(info)[1, 1]))


def _check_variant(variant: str) -> str:
    if not isinstance(variant, str) or variant not in VARIANTS:
        raise ValueError(f"variant: expected one of {', '.join(VARIANTS)}, got {variant!r}")
    return variant


def initial_speed_std(experiment: FerryExperiment, variant: str = DEFAULT_VARIANT) -> float:
    """Speed standard deviation of the shared P0 [m/s] in a variant (:data:`VARIANTS`).

    ``"matched"``: :data:`INITIAL_SPEED_STD_MPS`; ``"stereo-prior"``:
    :func:`stereo_speed_std` of the experiment.
    """
    if _check_variant(variant) == "stereo-prior":
        return stereo_speed_std(experiment)
    return INITIAL_SPEED_STD_MPS


def initial_state(
    z0: ArrayLike, R0: ArrayLike, speed: float, speed_std: float = INITIAL_SPEED_STD_MPS
) -> tuple[FloatArray, FloatArray]:
    """Shared start: ``x0 = [z_0, v_0]``, ``P0 = diag(R_0, speed_std²)`` per run.

    Args:
        z0: first measurement(s) [m], (B,).
        R0: their variance [m²], (B,).
        speed: v_0 [m/s].
        speed_std: standard deviation of v_0 [m/s] (:func:`initial_speed_std`).

    Returns:
        x0 (B, 2), P0 (B, 2, 2).
    """
    z = np.atleast_1d(as_float_array("z0", z0))
    r = np.broadcast_to(as_float_array("R0", R0), z.shape)
    sv = positive("speed_std", speed_std)
    x0 = np.stack([z, np.full(z.shape, float(speed))], axis=-1)
    P0 = np.zeros((*z.shape, 2, 2))
    P0[..., 0, 0] = r
    P0[..., 1, 1] = sv**2
    return x0, P0


@dataclass(frozen=True)
class Predictions:
    """One filter's one-step predictions and innovations over frames 1…N−1.

    Attributes:
        states: predicted ``[ŝ⁻, v̂⁻]`` (B, N−1, 2) [m, m/s].
        innovations: ``z_k − ŝ_k⁻`` (B, N−1) [m].
        nis: normalised innovation squared (B, N−1).
        fading: STKF fading factor applied (B, N−1) (ones for the KF).
    """

    states: FloatArray
    innovations: FloatArray
    nis: FloatArray
    fading: FloatArray


def run_filter(
    estimator: str,
    experiment: FerryExperiment,
    z: FloatArray,
    R: FloatArray,
    *,
    Q: FloatArray | None = None,
    variant: str = DEFAULT_VARIANT,
) -> Predictions:
    """Run one of the scenario's filters on measurements z (B, N) with variances R (B, N).

    ``kf``: :class:`seawatch.filters.KalmanFilter` stepped frame by frame (per-frame R);
    ``stkf`` / ``stereo-stkf`` (and ``*-late``, one-step-late fading):
    :class:`seawatch.filters.StrongTrackingKalmanFilter` with β = 4.5, ρ = 0.95.
    All start from :func:`initial_state` at frame 0 (speed per
    :meth:`FerryExperiment.initial_speed`, the variant's P0 speed σ per
    :func:`initial_speed_std`) and share Q (default :func:`process_noise`).
    """
    F, Q_default = process_noise()
    Qm = Q_default if Q is None else Q
    H = position_measurement(1, 2)
    x0, P0 = initial_state(
        z[:, 0],
        R[:, 0],
        experiment.initial_speed(estimator),
        initial_speed_std(experiment, variant),
    )
    B, N = z.shape
    if estimator == "kf":
        kf = KalmanFilter(F, H, Qm, R[0, 0], x0, P0)
        states = np.empty((B, N - 1, 2))
        innov = np.empty((B, N - 1))
        nis = np.empty((B, N - 1))
        for k in range(1, N):
            kf.predict()
            states[:, k - 1] = kf.x
            kf.update(z[:, k, None], R=R[:, k, None, None])
            innov[:, k - 1] = kf.y[:, 0]  # type: ignore[index]
            nis[:, k - 1] = kf.nis  # type: ignore[index]
        return Predictions(states, innov, nis, np.ones((B, N - 1)))
    if estimator not in ESTIMATORS + LATE_ESTIMATORS:
        raise ValueError(
            f"estimator: expected one of {ESTIMATORS + LATE_ESTIMATORS}, got {estimator!r}"
        )
    stkf = StrongTrackingKalmanFilter(
        F, H, Qm, R[0, 0], x0, P0, beta=BETA, rho=RHO, late_fading=estimator.endswith("-late")
    )
    res = stkf.filter(z[:, 1:, None], R=R[:, 1:, None, None])
    return Predictions(res.predicted_states, res.innovations[..., 0], res.nis, res.fading_factors)


# ----------------------------------------------------------------------------- simulation
@dataclass(frozen=True)
class FerryBatch:
    """Truth and measurements of a batch of runs.

    Attributes:
        truth: :class:`FerryTruth`.
        z: along-track measurements ``u·(X̂ − X0)`` from the seed's triangulation [m], (B, N).
        R: their nominal variance at the true point [m²], (B, N).
        range_error: per triangulation method, estimated minus true range from the left
            camera [m], (B, ⌈N / compare_every⌉) (only when requested).
    """

    truth: FerryTruth
    z: FloatArray
    R: FloatArray
    range_error: dict[str, FloatArray]


def simulate_batch(
    experiment: FerryExperiment,
    gens: Sequence[np.random.Generator],
    geometry: FerryGeometry | None = None,
    *,
    compare: bool = False,
    compare_every: int = 1,
    sigma_px: float = MATCH_SIGMA_PX,
) -> FerryBatch:
    """Truth, noisy pixel pairs and triangulated along-track measurements, one run per generator.

    Each generator draws, in order, the truth's N fluctuation normals and the (N, 4) pixel
    noise (left u, v, right u, v), so a run's draws do not depend on the batch.
    """
    geo = ferry_geometry() if geometry is None else geometry
    truth = simulate_truth(experiment, gens)
    B, N = truth.along.shape
    P1, P2 = projection_matrices_mm()
    X = geo.points(truth.along)  # (B, N, 3) m
    noise = sigma_px * np.stack([g.standard_normal((N, 4)) for g in gens])
    left = project(P1, X) + noise[..., 0:2]
    right = project(P2, X) + noise[..., 2:4]
    Xi = triangulate_inhomogeneous(P1, P2, left, right) / 1000.0
    z = (Xi - geo.start) @ geo.direction
    R = _interpolated_variance(geo, truth.along, sigma_px)
    errors: dict[str, FloatArray] = {}
    if compare:
        sub = slice(None, None, compare_every)
        true_range = np.linalg.norm(X[:, sub], axis=-1)
        errors["inhomogeneous"] = np.linalg.norm(Xi[:, sub], axis=-1) - true_range
        ls, rs = left[:, sub].reshape(-1, 2), right[:, sub].reshape(-1, 2)
        for method in TRIANGULATIONS[1:]:
            Xm = triangulate_reference(method, P1, P2, ls, rs)
            errors[method] = np.linalg.norm(Xm, axis=-1).reshape(B, -1) / 1000.0 - true_range
    return FerryBatch(truth=truth, z=z, R=R, range_error=errors)


def prediction_errors(batch: FerryBatch, pred: Predictions) -> dict[str, FloatArray]:
    """The four prediction errors (B, N−1) of :data:`PRED_METRICS` [m or m/s]."""
    z, tr = batch.z, batch.truth
    return {
        "rmse_position_pred": z[:, 1:] - pred.states[..., 0],
        "rmse_speed_pred": np.diff(z, axis=1) / DT_S - pred.states[..., 1],
        "rmse_position_pred_truth": tr.along[:, 1:] - pred.states[..., 0],
        "rmse_speed_pred_truth": tr.speed[:, 1:] - pred.states[..., 1],
    }


def _run_generators(seed: int, experiment: int, runs: int) -> list[np.random.Generator]:
    """Independent per-run generators: run i's draws do not depend on ``runs``."""
    return _generators(seed, experiment, range(runs))


def _generators(seed: int, experiment: int, indices: Sequence[int]) -> list[np.random.Generator]:
    """Run i of experiment e: ``default_rng(SeedSequence(seed, spawn_key=(e − 1, i)))``.

    The same streams as ``SeedSequence(seed).spawn(2)[e − 1].spawn(runs)[i]``.
    """
    seed = integer("seed", seed, 0)
    return [
        np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(experiment - 1, int(i))))
        for i in indices
    ]


# ----------------------------------------------------------------------------- experiment
def _window_mask(N: int) -> NDArray[np.bool_]:
    t = np.arange(1, N) * DT_S
    return t <= VIDEO_WINDOW_S + 1e-9


def _period_slices(N: int) -> list[slice]:
    """Slices of the filtered frames 1…N−1 in each of :data:`FADING_PERIODS_S`."""
    t = np.arange(1, N) * DT_S
    return [
        slice(int(np.searchsorted(t, a + 1e-9)), int(np.searchsorted(t, b + 1e-9)))
        for _, a, b in FADING_PERIODS_S
    ]


@dataclass
class FerryChunk:
    """What :func:`chunk` computes for one experiment and a chunk of runs.

    Attributes:
        runs: global run indices, (B,).
        per_run: per (estimator, metric, "run" | "window"), the per-run RMS (B,).
        tri: per (metric, method, band index), the per-run value (B,) (NaN where the run
            has no frame in the band) and the run's frame count in the band (B,).
        sumsq: per (estimator, metric), sums over runs of the squared error per frame,
            one (N−1,) array per aligned block of :data:`CHUNK_ALIGN` runs, in order.
        nis_sum, nis_n, fading_sum, faded: per estimator, per-run sums over frames of
            the NIS and of the fading factor, frame counts and frames with fading > 1,
            each (B,).
        faded_periods: per estimator, frames with fading > 1 in each of
            :data:`FADING_PERIODS_S`, (B, 3).
    """

    runs: NDArray[np.int64]
    per_run: dict[tuple[str, str, str], FloatArray]
    tri: dict[tuple[str, str, int], tuple[FloatArray, NDArray[np.int64]]]
    sumsq: dict[tuple[str, str], list[FloatArray]]
    nis_sum: dict[str, FloatArray]
    nis_n: dict[str, NDArray[np.int64]]
    fading_sum: dict[str, FloatArray]
    faded: dict[str, NDArray[np.int64]]
    faded_periods: dict[str, NDArray[np.int64]]


def _chunk_experiment(
    experiment: FerryExperiment,
    indices: NDArray[np.int64],
    seed: int,
    late_fading: bool,
    progress: Callable[[int], None] | None = None,
    block: int = CHUNK_RUNS,
    variant: str = DEFAULT_VARIANT,
) -> FerryChunk:
    """Runs ``indices`` of one experiment, vectorised over blocks of ``block`` runs."""
    estimators = ESTIMATORS + (LATE_ESTIMATORS if late_fading else ())
    geo = ferry_geometry()
    N = experiment.frames
    # the window is a prefix of the frames: a slice keeps each row's reduction the same
    # whatever the batch (a boolean mask gives a Fortran-ordered copy)
    n_window = int(np.count_nonzero(_window_mask(N)))
    per_run: dict[tuple[str, str, str], list[FloatArray]] = {}
    tri: dict[tuple[str, str, int], list[tuple[FloatArray, NDArray[np.int64]]]] = {}
    sumsq: dict[tuple[str, str], list[FloatArray]] = {}
    diag: dict[str, dict[str, list[FloatArray]]] = {
        k: {} for k in ("nis_sum", "nis_n", "fading_sum", "faded", "faded_periods")
    }
    periods = _period_slices(N)
    for lo in range(0, indices.size, block):
        runs = indices[lo : lo + block]
        gens = _generators(seed, experiment.number, runs.tolist())
        batch = simulate_batch(experiment, gens, geo, compare=True, compare_every=COMPARE_EVERY)
        key = runs // CHUNK_ALIGN
        cuts = [0, *(np.nonzero(np.diff(key))[0] + 1).tolist(), runs.size]
        blocks = [slice(a, b) for a, b in itertools.pairwise(cuts)]
        true_range = geo.ranges(batch.truth.along[:, ::COMPARE_EVERY])
        for method, err in batch.range_error.items():
            for i, (r0, r1) in enumerate(RANGE_BANDS_M):
                sel = (true_range >= r0) & (true_range < r1)
                cnt = np.sum(sel, axis=1)
                e = np.where(sel, err, np.nan)
                with warnings.catch_warnings(action="ignore", category=RuntimeWarning):
                    values = {
                        "bias_range": np.nanmean(e, axis=1),
                        "rmse_range": np.sqrt(np.nanmean(e * e, axis=1)),
                        "median_error_range": np.nanmedian(e, axis=1),
                    }
                for metric, v in values.items():
                    tri.setdefault((metric, method, i), []).append((v, cnt))
        for est in estimators:
            pred = run_filter(est, experiment, batch.z, batch.R, variant=variant)
            errs = prediction_errors(batch, pred)
            for metric, e in errs.items():
                e2 = e * e
                per_run.setdefault((est, metric, "run"), []).append(np.sqrt(np.mean(e2, axis=1)))
                per_run.setdefault((est, metric, "window"), []).append(
                    np.sqrt(np.mean(e2[:, :n_window], axis=1))
                )
                sumsq.setdefault((est, metric), []).extend(e2[b].sum(axis=0) for b in blocks)
            diag["nis_sum"].setdefault(est, []).append(np.sum(pred.nis, axis=1))
            diag["nis_n"].setdefault(est, []).append(np.full(runs.size, pred.nis.shape[1]))
            diag["fading_sum"].setdefault(est, []).append(np.sum(pred.fading, axis=1))
            diag["faded"].setdefault(est, []).append(np.count_nonzero(pred.fading > 1.0, axis=1))
            diag["faded_periods"].setdefault(est, []).append(
                np.stack(
                    [np.count_nonzero(pred.fading[:, sl] > 1.0, axis=1) for sl in periods], axis=1
                )
            )
        if progress is not None:
            progress(runs.size)
    return FerryChunk(
        runs=indices,
        per_run={k: np.concatenate(v) for k, v in per_run.items()},
        tri={
            k: (np.concatenate([a for a, _ in v]), np.concatenate([c for _, c in v]))
            for k, v in tri.items()
        },
        sumsq=sumsq,
        **{name: {k: np.concatenate(v) for k, v in d.items()} for name, d in diag.items()},
    )


def _merge_experiment(
    experiment: FerryExperiment, payloads: Sequence[FerryChunk], late_fading: bool
) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """Records and plot series of one experiment from its chunks (in run order)."""
    estimators = ESTIMATORS + (LATE_ESTIMATORS if late_fading else ())
    runs = int(sum(p.runs.size for p in payloads))
    N = experiment.frames
    geo = ferry_geometry()

    def cat(get: Callable[[FerryChunk], Any]) -> Any:
        return np.concatenate([get(p) for p in payloads])

    e_no = experiment.number
    records: list[dict[str, Any]] = []
    for window_key, params in (
        ("run", {"experiment": e_no}),
        ("window", {"experiment": e_no, "window_s": [0.0, VIDEO_WINDOW_S]}),
    ):
        for est in estimators:
            for i, (metric, unit) in enumerate(PRED_METRICS):
                paper = None
                if window_key == "run" and i < 2 and est in experiment.paper:
                    paper = experiment.paper[est][i]
                vals = cat(lambda p, k=(est, metric, window_key): p.per_run[k])
                records.append(record(est, metric, unit, vals, paper=paper, params=params))
    for metric in RANGE_METRICS:
        for method in TRIANGULATIONS:
            for i, band in enumerate(RANGE_BANDS_M):
                key = (metric, method, i)
                if not any(np.any(p.tri[key][1]) for p in payloads):
                    continue  # no run has a frame in this band
                vals = cat(lambda p, k=key: p.tri[k][0][p.tri[k][1] > 0])
                hi = band[1] if math.isfinite(band[1]) else None
                records.append(
                    record(
                        f"triangulation-{method}",
                        metric,
                        "m",
                        vals,
                        params={"experiment": e_no, "range_m": [band[0], hi]},
                    )
                )
    rms: dict[tuple[str, str], FloatArray] = {}
    for k in payloads[0].sumsq:
        parts = [part for p in payloads for part in p.sumsq[k]]
        total = parts[0].copy()
        for part in parts[1:]:
            total += part
        rms[k] = np.sqrt(total / runs)
    n = {k: int(np.sum(cat(lambda p, k=k: p.nis_n[k]))) for k in estimators}
    series: dict[str, Any] = {
        "time": np.arange(1, N) * DT_S,
        "sqrt_R": np.sqrt(along_track_variance(geo, experiment.speed * np.arange(1, N) * DT_S)),
        "range": geo.ranges(experiment.speed * np.arange(N) * DT_S)[1:],
        "rms": rms,
        "diagnostics": {
            "mean_nis": {
                k: float(np.sum(cat(lambda p, k=k: p.nis_sum[k]))) / max(n[k], 1)
                for k in estimators
            },
            "mean_fading_factor": {
                k: float(np.sum(cat(lambda p, k=k: p.fading_sum[k]))) / max(n[k], 1)
                for k in estimators
            },
            "fading_fraction": {
                k: int(np.sum(cat(lambda p, k=k: p.faded[k]))) / max(n[k], 1) for k in estimators
            },
            "fading_fraction_by_period": {
                k: {
                    name: (
                        int(np.sum(cat(lambda p, k=k: p.faded_periods[k])[:, i]))
                        / max(runs * (sl.stop - sl.start), 1)
                    )
                    for i, ((name, _, _), sl) in enumerate(
                        zip(FADING_PERIODS_S, _period_slices(N), strict=True)
                    )
                }
                for k in estimators
            },
        },
    }
    return records, series


def run_experiment(
    experiment: FerryExperiment,
    runs: int,
    seed: int,
    *,
    late_fading: bool = False,
    progress: ProgressCallback | None = None,
    progress_offset: int = 0,
    progress_total: int | None = None,
    chunk: int = CHUNK_RUNS,
    variant: str = DEFAULT_VARIANT,
) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """Monte-Carlo runs of one experiment, in blocks of ``chunk`` runs.

    Returns:
        (records, series): the experiment-JSON records and, for the plots, the RMS over
        runs of each prediction error per frame (``series[(estimator, metric)]``, (N−1,)),
        the truth's time axis and the nominal √R.
    """
    total = progress_total if progress_total is not None else runs
    done = [progress_offset]

    def step(n: int) -> None:
        done[0] += n
        if progress is not None:
            progress(done[0], total)

    payload = _chunk_experiment(
        experiment,
        np.arange(runs),
        seed,
        late_fading,
        step,
        block=max(1, int(chunk)),
        variant=_check_variant(variant),
    )
    return _merge_experiment(experiment, [payload], late_fading)


def ordering(
    records: list[dict[str, Any]], experiment: int, window: bool = False
) -> dict[str, Any]:
    """Does KF > STKF > stereo + STKF hold for both paper metrics (and against the truth)?

    Returns ``{metric: {"values": [kf, stkf, stereo-stkf], "holds": bool}}`` (means).
    """
    out: dict[str, Any] = {}
    for metric, _ in PRED_METRICS:
        vals = []
        for est in ESTIMATORS:
            for rec in records:
                p = rec["params"]
                if (
                    rec["estimator"] == est
                    and rec["metric"] == metric
                    and p.get("experiment") == experiment
                    and ("window_s" in p) == window
                ):
                    vals.append(rec["mean"])
                    break
        if len(vals) == 3:
            out[metric] = {"values": vals, "holds": bool(vals[0] > vals[1] > vals[2])}
    return out


def _check_runs(runs: int) -> int:
    return integer("runs", runs, 1)


def _numbers(experiment: int | None) -> list[int]:
    if experiment is None:
        return [1, 2]
    if experiment in EXPERIMENTS and not isinstance(experiment, bool):
        return [int(experiment)]
    raise ValueError(f"experiment: expected 1, 2 or None (both), got {experiment!r}")


def chunk(
    indices: Sequence[int],
    runs: int | None = None,
    seed: int = 0,
    *,
    progress: ProgressCallback | None = None,
    experiment: int | None = None,
    late_fading: bool = False,
    variant: str = DEFAULT_VARIANT,
) -> dict[int, FerryChunk]:
    """Runs ``indices`` of each experiment (the parallel protocol of
    :mod:`seawatch.scenarios.parallel`; :func:`run` is ``merge([chunk(range(runs))])``).

    Run i of experiment e draws from ``SeedSequence(seed, spawn_key=(e − 1, i))`` and
    the filters treat runs independently, so a run's values do not depend on its chunk.

    Args:
        indices: global run indices, increasing.
        runs: total number of runs (unused: a run does not depend on it).
        seed: seed of the per-run streams.
        progress: ``progress(done, total)`` after each block of runs (total = the
            chunk's runs × the number of experiments).
        experiment, late_fading, variant: as in :func:`run`.

    Returns:
        ``{experiment number: FerryChunk}``.
    """
    numbers = _numbers(experiment)
    _check_variant(variant)
    idx = np.asarray(list(indices), dtype=np.int64)
    if idx.ndim != 1 or idx.size == 0 or idx[0] < 0 or np.any(np.diff(idx) <= 0):
        raise ValueError(f"indices: expected increasing non-negative run indices, got {indices!r}")
    total = idx.size * len(numbers)
    done = [0]

    def step(n: int) -> None:
        done[0] += n
        if progress is not None:
            progress(done[0], total)

    return {
        e: _chunk_experiment(EXPERIMENTS[e], idx, int(seed), late_fading, step, variant=variant)
        for e in numbers
    }


def merge(
    payloads: Sequence[dict[int, FerryChunk]],
    runs: int | None = None,
    seed: int = 0,
    out_dir: str | Path | None = None,
    *,
    experiment: int | None = None,
    late_fading: bool = False,
    variant: str = DEFAULT_VARIANT,
) -> ExperimentResult:
    """The experiment JSON (and outputs) of :func:`run` from the chunks of :func:`chunk`.

    Args:
        payloads: the chunks, in run order, covering runs 0 … runs − 1.
        runs: the number of runs (checked against the chunks).
        seed: the seed the chunks were made with.
        out_dir: where ``table3.csv``, ``triangulation.csv`` and the plots go.
        experiment, late_fading, variant: the options the chunks were made with.
    """
    numbers = _numbers(experiment)
    _check_variant(variant)
    if not payloads:
        raise ValueError("payloads: expected at least one chunk")
    order = sorted(payloads, key=lambda p: int(p[numbers[0]].runs[0]))
    n_runs = int(sum(p[numbers[0]].runs.size for p in order))
    if runs is not None and n_runs != runs:
        raise ValueError(f"payloads: expected {runs} runs in all, got {n_runs}")
    out = Path(out_dir) if out_dir is not None else None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    records: list[dict[str, Any]] = []
    outputs: list[Path] = []
    order_ok: dict[str, Any] = {}
    diagnostics: dict[str, Any] = {}
    for e in numbers:
        exp = EXPERIMENTS[e]
        recs, series = _merge_experiment(exp, [p[e] for p in order], late_fading)
        records += recs
        order_ok[str(e)] = {
            "run": ordering(recs, e),
            "window_16s": ordering(recs, e, window=True),
        }
        diagnostics[str(e)] = series["diagnostics"]
        if out is not None:
            for path in (
                write_table3(records, out / "table3.csv"),
                write_triangulation(records, out / "triangulation.csv"),
                plot_prediction_errors(
                    series, exp, out / f"prediction_error_exp{e}.png", n_runs, variant
                ),
            ):
                if path not in outputs:
                    outputs.append(path)
    return ExperimentResult(
        SCENARIO,
        n_runs,
        int(seed),
        records,
        outputs=outputs,
        extra={
            "variant": variant,
            "initial_speed_std_mps": {
                str(e): initial_speed_std(EXPERIMENTS[e], variant) for e in numbers
            },
            "ordering": order_ok,
            "diagnostics": diagnostics,
        },
    )


def run(
    runs: int = 1000,
    seed: int = 0,
    out_dir: str | Path | None = None,
    progress: ProgressCallback | None = None,
    experiment: int | None = None,
    late_fading: bool = False,
    variant: str = DEFAULT_VARIANT,
) -> ExperimentResult:
    """Run ``seawatch experiment stereo-ferry`` (SCENARIOS.md; seed 003 Table 3).

    ``merge([chunk(range(runs))])``: the code the parallel runner uses too.

    Args:
        runs: Monte-Carlo runs per experiment (the paper: 1000).
        seed: seed of the per-run ``numpy.random.SeedSequence`` streams (run i draws the
            same noise whatever ``runs`` is).
        out_dir: if given, ``table3.csv`` (ours beside the paper's),
            ``triangulation.csv`` and ``prediction_error_exp{1,2}.png`` are written there
            as each experiment completes.
        progress: ``progress(done, total)`` after each chunk of runs (total = runs × the
            number of experiments).
        experiment: 1 or 2 to run one experiment only (default: both).
        late_fading: also run the STKFs with the seed-literal one-step-late fading
            factor (estimators ``stkf-late``, ``stereo-stkf-late``; ablation).
        variant: the shared P0 (:data:`VARIANTS`): ``"matched"`` (default, speed σ
            0.1 m/s) or ``"stereo-prior"`` (speed σ = :func:`stereo_speed_std`, the
            accuracy of the stereo-measured speed, trusted by all three filters);
            ``seawatch experiment stereo-ferry --variant stereo-prior``.

    Returns:
        The experiment JSON (INTERFACES.md); ``extra`` holds ``"ordering"`` (for each
        experiment, over the whole run and the first 16 s: the three filters' means per
        metric and whether KF > STKF > stereo + STKF holds), ``"diagnostics"`` (per
        experiment and filter: mean NIS, mean fading factor, the fraction of frames
        with a fading factor > 1, overall and per period of :data:`FADING_PERIODS_S`),
        ``"variant"`` and ``"initial_speed_std_mps"`` (the P0 speed σ per experiment).
    """
    n_runs = _check_runs(runs)
    opts = {"experiment": experiment, "late_fading": late_fading, "variant": variant}
    _numbers(experiment)
    _check_variant(variant)
    payload = chunk(range(n_runs), n_runs, seed, progress=progress, **opts)
    return merge([payload], n_runs, seed, out_dir, **opts)


# ----------------------------------------------------------------------------- outputs
def _fmt(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return f"{v:.4f}" if abs(v) < 1e6 else f"{v:.4e}"
    return str(v)


def write_table3(records: list[dict[str, Any]], path: Path) -> Path:
    """``table3.csv``: per experiment and filter, ours (mean, stderr) beside the paper's.

    Columns: the paper's two metrics over the whole run with Table 3's values, the same
    against the truth, and all four over the first 16 s.
    """
    cols = ["experiment", "estimator"]
    for suffix in ("", "_16s"):
        for metric, unit in PRED_METRICS:
            u = "m" if unit == "m" else "mps"
            cols += [f"{metric}{suffix}_{u}", f"{metric}{suffix}_stderr_{u}"]
            if not suffix and metric in ("rmse_position_pred", "rmse_speed_pred"):
                cols.append(f"{metric}_paper_{u}")
    rows: dict[tuple[int, str], dict[str, Any]] = {}
    for rec in records:
        metric = rec["metric"]
        if metric not in dict(PRED_METRICS):
            continue
        e = rec["params"]["experiment"]
        row = rows.setdefault(
            (e, rec["estimator"]), {"experiment": e, "estimator": rec["estimator"]}
        )
        u = "m" if rec["unit"] == "m" else "mps"
        suffix = "_16s" if "window_s" in rec["params"] else ""
        row[f"{metric}{suffix}_{u}"] = rec["mean"]
        row[f"{metric}{suffix}_stderr_{u}"] = rec["stderr"]
        if not suffix and metric in ("rmse_position_pred", "rmse_speed_pred"):
            row[f"{metric}_paper_{u}"] = rec["paper"]
    with Path(path).open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for row in rows.values():
            w.writerow([_fmt(row.get(c)) for c in cols])
    return Path(path)


def write_triangulation(records: list[dict[str, Any]], path: Path) -> Path:
    """``triangulation.csv``: range bias / RMSE / median error per method and range band."""
    cols = ["experiment", "range_lo_m", "range_hi_m", "method"]
    cols += [f"{m}_m" for m in RANGE_METRICS] + [f"{m}_stderr_m" for m in RANGE_METRICS]
    rows: dict[tuple[int, float, str], dict[str, Any]] = {}
    for rec in records:
        if not rec["estimator"].startswith("triangulation-"):
            continue
        p = rec["params"]
        lo, hi = p["range_m"]
        key = (p["experiment"], lo, rec["estimator"])
        row = rows.setdefault(
            key,
            {
                "experiment": p["experiment"],
                "range_lo_m": lo,
                "range_hi_m": hi,
                "method": rec["estimator"].removeprefix("triangulation-"),
            },
        )
        row[f"{rec['metric']}_m"] = rec["mean"]
        row[f"{rec['metric']}_stderr_m"] = rec["stderr"]
    with Path(path).open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for row in rows.values():
            w.writerow([_fmt(row.get(c)) for c in cols])
    return Path(path)


_STYLE = {
    "kf": {"color": "#4d4d4d", "lw": 1.2},
    "stkf": {"color": "#2166ac", "lw": 1.2},
    "stereo-stkf": {"color": "#b2182b", "lw": 1.2},
    "stkf-late": {"color": "#92c5de", "lw": 1.0, "ls": "--"},
    "stereo-stkf-late": {"color": "#f4a582", "lw": 1.0, "ls": "--"},
}


def plot_prediction_errors(
    series: dict[str, Any],
    experiment: FerryExperiment,
    path: Path,
    runs: int,
    variant: str = DEFAULT_VARIANT,
) -> Path:
    """PNG: RMS over runs of each filter's one-step prediction error against time.

    Four panels: position and speed, against the observation (the paper's metric) and
    against the truth; log-log axes so the start-up transient and the far end are both
    visible; the nominal measurement σ = √R is drawn on the position panels.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 7.5))
    FigureCanvasAgg(fig)
    axes = fig.subplots(2, 2, sharex=True)
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.08, top=0.92, wspace=0.22, hspace=0.08)
    t = series["time"]
    # mean squares averaged in ~200 log-spaced time bins (smooth curves, light PNG)
    edges = np.unique(np.geomspace(1, t.size, 200).astype(int)) - 1
    edges = np.append(edges, t.size)
    t_bin = np.array([t[a:b].mean() for a, b in itertools.pairwise(edges)])

    def binned(rms: FloatArray) -> FloatArray:
        ms = rms**2
        return np.sqrt([ms[a:b].mean() for a, b in itertools.pairwise(edges)])

    panels = (
        ("rmse_position_pred", "position: observation − prediction [m]"),
        ("rmse_position_pred_truth", "position: truth − prediction [m]"),
        ("rmse_speed_pred", "speed: Δz/Δt − prediction [m/s]"),
        ("rmse_speed_pred_truth", "speed: truth − prediction [m/s]"),
    )
    for ax, (metric, label) in zip(axes.flat, panels, strict=True):
        for (est, m), rms in series["rms"].items():
            if m == metric:
                ax.plot(t_bin, binned(rms), label=est, **_STYLE.get(est, {}))
        if metric.startswith("rmse_position"):
            ax.plot(t_bin, binned(series["sqrt_R"]), color="0.6", lw=0.8, ls=":", label="√R")
        ax.axvline(VIDEO_WINDOW_S, color="0.8", lw=0.8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.minorticks_off()
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time [s] (range 17.9 m → {:.0f} m)".format(series["range"][-1]))
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(
        f"stereo-ferry ({variant}), experiment {experiment.number}: RMS one-step prediction "
        f"error, {runs} runs (grey line: end of the 16-s video window)"
    )
    fig.savefig(path, dpi=100)
    return Path(path)
