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
mean over runs and its standard error.

Outcome (100 runs, seed 0; ``tests/scenarios/test_air_range.py`` checks it): every
filter beats the raw range in the level flight; the paper's "large σ_v better late"
holds; its "small σ_v better early" does not (the first seconds are limited by the
diffuse start and all σ_v agree there; later the range acceleration of the 1000 m miss
distance, 0.35 → 2.6 m/s², already favours σ_v = 10 over 1); ncv-1 cannot follow the
pull-up and is worse than raw over the whole run (40.6 m against 32.1 m); ANCV
(10.5 m) and ANCA (10.4 m) beat every fixed-noise filter over the whole run (best
fixed: nca-0.1, 13.4 m) thanks to the pull-up, while in the level flight they are
slightly worse than the fixed filters (12.4/12.3 m against 11.4–12.0 m).

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

from seawatch._validation import FloatArray, as_float_array, positive
from seawatch.filters.adaptive_range import (
    STANDARD_GRAVITY,
    AdaptiveRangeFilter,
    size_range_std,
)
from seawatch.scenarios.base import ExperimentResult

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
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ValueError(f"seed: expected a non-negative integer, got {seed!r}")
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
    if isinstance(start, bool) or not isinstance(start, int | np.integer) or start < 0:
        raise ValueError(f"start: expected a non-negative integer, got {start!r}")
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


@dataclass(frozen=True)
class AirRangeResult:
    """Outcome of :func:`run`.

    Attributes:
        runs: number of Monte-Carlo runs.
        seed: the noise seed.
        truth: the trajectory.
        records: experiment-JSON records (INTERFACES.md): ``estimator``, ``metric``,
            ``unit``, ``mean``, ``stderr``, ``paper`` (None: the paper gives figures
            only), ``params``.
        errors: per estimator, range error estimate − truth [m], (runs, N).
        sigma_v: per filter, σ_v used at each frame [m/s²], (runs, N) (NaN at frame 0).
    """

    runs: int
    seed: int
    truth: AirRangeTrajectory
    records: list[dict[str, Any]]
    errors: dict[str, FloatArray]
    sigma_v: dict[str, FloatArray] = field(default_factory=dict)

    @property
    def estimators(self) -> list[str]:
        """Estimator names in table order."""
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
        """One row per estimator: mean and standard error of each metric [m]."""
        rows = []
        for name in self.errors:
            row: dict[str, Any] = {"estimator": name}
            for metric in METRICS:
                rec = self.record(name, metric)
                row[f"{metric}_m"] = rec["mean"]
                row[f"{metric}_stderr_m"] = rec["stderr"]
            rows.append(row)
        return rows


def _metric_records(
    name: str, err: NDArray[np.float64], far: NDArray[np.bool_], params: dict[str, Any]
) -> list[dict[str, Any]]:
    per_run = {
        "rmse_range": np.sqrt(np.mean(err**2, axis=-1)),
        "rmse_range_far": np.sqrt(np.mean(err[:, far] ** 2, axis=-1)),
        "rmse_range_near": np.sqrt(np.mean(err[:, ~far] ** 2, axis=-1)),
    }
    out = []
    for metric in METRICS:
        vals = per_run[metric]
        stderr = float(np.std(vals, ddof=1) / math.sqrt(vals.size)) if vals.size > 1 else None
        out.append(
            {
                "estimator": name,
                "metric": metric,
                "unit": "m",
                "mean": float(np.mean(vals)),
                "stderr": stderr,
                "paper": None,
                "params": dict(params),
            }
        )
    return out


@dataclass(frozen=True)
class AirRangeChunk:
    """Per-run output of :func:`chunk` (what a Dask task returns).

    Attributes:
        runs: global run indices, (B,).
        errors: per estimator, range error estimate − truth [m], (B, N).
        sigma_v: per adaptive filter, σ_v at each frame [m/s²], (B, N).
        params: per estimator, the record ``params``.
    """

    runs: NDArray[np.int64]
    errors: dict[str, FloatArray]
    sigma_v: dict[str, FloatArray]
    params: dict[str, dict[str, Any]]


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
    if progress is not None:
        progress(1, total)
    z = meas.range
    for i, spec in enumerate(ESTIMATORS, start=2):
        flt = make_filter(spec, z[:, 0])
        res = flt.filter(z[:, 1:])
        est = np.concatenate([z[:, :1], res.states[..., 0]], axis=1)
        errors[spec.name] = est - truth.range
        sig = np.full(z.shape, np.nan)
        sig[:, 1:] = res.sigma_v
        sigma_v[spec.name] = sig
        params[spec.name] = _params(spec, flt)
        if progress is not None:
            progress(i, total)
    return AirRangeChunk(runs=idx, errors=errors, sigma_v=sigma_v, params=params)


def _combine(payloads: Sequence[AirRangeChunk], seed: int) -> AirRangeResult:
    """Concatenate chunks (in run order) and compute the records over all runs."""
    if not payloads:
        raise ValueError("payloads: expected at least one chunk")
    order = sorted(payloads, key=lambda p: int(p.runs[0]))
    truth = trajectory()
    far = truth.range > FAR_RANGE_M
    names = list(order[0].errors)
    errors = {n: np.concatenate([p.errors[n] for p in order]) for n in names}
    sigma_v = {n: np.concatenate([p.sigma_v[n] for p in order]) for n in order[0].sigma_v}
    records: list[dict[str, Any]] = []
    for n in names:
        records += _metric_records(n, errors[n], far, order[0].params[n])
    return AirRangeResult(
        runs=int(errors["raw"].shape[0]),
        seed=int(seed),
        truth=truth,
        records=records,
        errors=errors,
        sigma_v=sigma_v,
    )


def run(runs: int = 100, seed: int = 0, progress: ProgressCallback | None = None) -> AirRangeResult:
    """Run the ``air-range`` comparison: raw, NCV ×3, NCA ×3, ANCV, ANCA.

    ``chunk(range(runs))`` then the records over the runs (the same code as the
    parallel runner's :func:`chunk` + :func:`merge`).

    Args:
        runs: Monte-Carlo runs (all filters see the same noise draws).
        seed: seed of the measurement noise (run i: ``SeedSequence(seed, spawn_key=(i,))``).
        progress: optional ``callable(done, total)`` called after each estimator.

    Returns:
        AirRangeResult with the records of every estimator × metric, the per-frame
        errors and the σ_v histories.
    """
    n = _check_runs(runs)
    return _combine([chunk(range(n), n, seed, progress=progress)], seed)


@dataclass(frozen=True)
class DemoResult:
    """What :func:`run_demo` wrote.

    Attributes:
        rows: the table (one dict per estimator, see :meth:`AirRangeResult.table_rows`).
        records: the experiment-JSON records.
        table_path: ``errors.csv``.
        plot_path: ``range_error.png``.
        result: the full :class:`AirRangeResult`.
    """

    rows: list[dict[str, Any]]
    records: list[dict[str, Any]]
    table_path: Path
    plot_path: Path
    result: AirRangeResult


def write_table(rows: list[dict[str, Any]], path: Path) -> Path:
    """Write the per-estimator table as CSV (metres, 4 decimals)."""
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
    """Run the scenario and write ``errors.csv`` and ``range_error.png`` into ``out_dir``.

    The plot shows the RMS range error of every filter against the true range (range
    decreasing left to right, like the approach), the raw measurement's σ_d for
    reference, and the σ_v the adaptive filters chose.
    """
    return _write_demo(run(runs, seed, progress), out_dir)


def _write_demo(result: AirRangeResult, out_dir: Path | str) -> DemoResult:
    from seawatch.report.air_range_plot import plot_range_errors

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows = result.table_rows()
    table_path = write_table(rows, out / "errors.csv")
    truth = result.truth
    rms = {name: result.rms_error(name) for name in result.estimators}
    adaptive = {
        s.name: np.nanmedian(result.sigma_v[s.name][:, 1:], axis=0)
        for s in ESTIMATORS
        if s.adaptive
    }
    plot_path = plot_range_errors(
        truth.range,
        rms,
        size_range_std(truth.range, SIGMA_L_PX, SIZE_M, FOCAL_PX),
        out / "range_error.png",
        sigma_v={k: np.concatenate([[np.nan], v]) for k, v in adaptive.items()},
        pullup_range=PULLUP_RANGE_M,
        title=f"air-range: RMS range error over {result.runs} runs (seed {result.seed})",
    )
    return DemoResult(
        rows=rows, records=result.records, table_path=table_path, plot_path=plot_path, result=result
    )


def _check_runs(runs: int) -> int:
    if isinstance(runs, bool) or not isinstance(runs, int | np.integer) or runs < 1:
        raise ValueError(f"runs: expected an integer >= 1, got {runs!r}")
    return int(runs)


def merge(
    payloads: Sequence[AirRangeChunk],
    runs: int | None = None,
    seed: int = 0,
    out_dir: Path | str | None = None,
) -> ExperimentResult:
    """The experiment JSON from the chunks of :func:`chunk` (in run order; the parallel
    protocol of :mod:`seawatch.scenarios.parallel`), plus ``errors.csv`` and
    ``range_error.png`` in ``out_dir`` when one is given."""
    result = _combine(payloads, seed)
    if runs is not None and result.runs != runs:
        raise ValueError(f"payloads: expected {runs} runs in all, got {result.runs}")
    if out_dir is None:
        return ExperimentResult(SCENARIO, result.runs, int(seed), result.records)
    demo = _write_demo(result, out_dir)
    return ExperimentResult(
        SCENARIO, result.runs, int(seed), demo.records, outputs=[demo.table_path, demo.plot_path]
    )


def experiment(
    runs: int = 100,
    seed: int = 0,
    out_dir: Path | None = None,
    progress: ProgressCallback | None = None,
) -> ExperimentResult:
    """``seawatch experiment air-range``: ``merge([chunk(range(runs))])`` — :func:`run`,
    plus ``errors.csv`` and ``range_error.png`` in ``out_dir`` when one is given."""
    n = _check_runs(runs)
    return merge([chunk(range(n), n, seed, progress=progress)], n, seed, out_dir)
