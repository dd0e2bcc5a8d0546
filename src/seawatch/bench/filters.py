"""``seawatch bench filters``: the linear Kalman filter against FilterPy and plain numpy.

One 2-D constant-velocity problem (4 states, 2 position measurements, 100,000 steps by
default) runs through, in the same process and run:

* ``seawatch.filter``       — ``KalmanFilter.filter(zs)`` (whole sequence, compiled);
* ``seawatch.step``         — ``KalmanFilter.predict(); update(z)`` per step from Python;
* ``filterpy.KalmanFilter`` — FilterPy's ``predict(); update(z)`` (the reference);
* ``numpy.loop``            — the textbook equations as a plain numpy loop;
* ``seawatch.batch``        — 10,000 independent tracks filtered at once (track-steps/s).

Speeds are reported with their ratios to FilterPy and numpy measured in the same run, so
the figures do not depend on how fast the machine is. The states of every variant must
agree with FilterPy's to 1e-9 relative; the benchmark reports the worst difference and
fails (``agreement.ok = false``, exit 1 on the CLI) if not.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from seawatch.filters.kalman import KalmanFilter
from seawatch.models import constant_velocity, position_measurement

TARGETS = {
    "seawatch.filter/filterpy.KalmanFilter": 50.0,
    "seawatch.step/filterpy.KalmanFilter": 2.0,
}
"""Speed targets of issue 2 (ratios measured in the same run)."""
BATCH_TARGET = 1.0e6
"""Batched filtering target, track-steps per second."""
AGREEMENT_TOL = 1e-9

Progress = Callable[[str], None]


def problem(steps: int, seed: int = 0) -> dict[str, np.ndarray]:
    """The benchmark's 2-D CV problem: T = 0.1 s, σ_a = 0.5 m/s², σ_z = 2 m."""
    F, Q = constant_velocity(2, 0.1, 0.5)
    H = position_measurement(2, 2)
    R = np.eye(2) * 4.0
    rng = np.random.default_rng(seed)
    x = np.array([0.0, 0.0, 3.0, -1.0])
    noise = rng.multivariate_normal(np.zeros(4), Q, size=steps)
    truth = np.empty((steps, 4))
    for k in range(steps):
        x = F @ x + noise[k]
        truth[k] = x
    zs = truth[:, :2] + rng.normal(scale=2.0, size=(steps, 2))
    return {"F": F, "H": H, "Q": Q, "R": R, "x0": np.zeros(4), "P0": np.eye(4) * 100.0, "zs": zs}


def _filterpy(p: dict[str, np.ndarray]) -> np.ndarray:
    from filterpy.kalman import KalmanFilter as FilterPyKF

    kf = FilterPyKF(dim_x=4, dim_z=2)
    kf.F, kf.H, kf.Q, kf.R = p["F"], p["H"], p["Q"], p["R"]
    kf.x, kf.P = p["x0"].copy(), p["P0"].copy()
    out = np.empty((len(p["zs"]), 4))
    for k, z in enumerate(p["zs"]):
        kf.predict()
        kf.update(z)
        out[k] = kf.x
    return out


def _numpy_loop(p: dict[str, np.ndarray]) -> np.ndarray:
    F, H, Q, R = p["F"], p["H"], p["Q"], p["R"]
    x, P = p["x0"].copy(), p["P0"].copy()
    eye = np.eye(4)
    out = np.empty((len(p["zs"]), 4))
    for k, z in enumerate(p["zs"]):
        x = F @ x
        P = F @ P @ F.T + Q
        S = H @ P @ H.T + R
        K = P @ H.T @ np.linalg.inv(S)
        x = x + K @ (z - H @ x)
        A = eye - K @ H
        P = A @ P @ A.T + K @ R @ K.T
        out[k] = x
    return out


def _seawatch_step(p: dict[str, np.ndarray]) -> np.ndarray:
    kf = KalmanFilter(p["F"], p["H"], p["Q"], p["R"], p["x0"], p["P0"])
    out = np.empty((len(p["zs"]), 4))
    for k, z in enumerate(p["zs"]):
        kf.predict()
        kf.update(z)
        out[k] = kf.x
    return out


def _seawatch_filter(p: dict[str, np.ndarray]) -> np.ndarray:
    return KalmanFilter(p["F"], p["H"], p["Q"], p["R"], p["x0"], p["P0"]).filter(p["zs"]).states


def _timed(fn: Callable[[], Any], repeats: int) -> tuple[float, Any]:
    best, result = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - t0)
    return best, result


def _rel_diff(a: np.ndarray, ref: np.ndarray) -> float:
    return float(np.max(np.abs(a - ref)) / max(np.max(np.abs(ref)), 1e-300))


def run(
    steps: int = 100_000,
    tracks: int = 10_000,
    track_steps: int = 100,
    repeats: int = 3,
    progress: Progress | None = None,
) -> dict[str, Any]:
    """Run the benchmark; returns the benchmark JSON of INTERFACES.md (plus targets).

    Every variant is timed best-of-``repeats`` (interleaved). Compilation happens in a
    warm-up before any timing.
    """
    say = progress or (lambda _msg: None)
    p = problem(steps)
    warm = problem(50, seed=1)
    _seawatch_filter(warm)
    _seawatch_step(warm)

    # Interleaved repeats, best of each: load from other processes hits every variant
    # alike instead of whichever happened to run at a busy moment.
    variants = {
        "seawatch.filter": lambda: _seawatch_filter(p),
        "seawatch.step": lambda: _seawatch_step(p),
        "filterpy.KalmanFilter": lambda: _filterpy(p),
        "numpy.loop": lambda: _numpy_loop(p),
    }
    best = dict.fromkeys(variants, np.inf)
    states: dict[str, np.ndarray] = {}
    for r in range(repeats):
        for name, fn in variants.items():
            say(f"{name} ({r + 1}/{repeats})")
            t, states[name] = _timed(fn, 1)
            best[name] = min(best[name], t)
    t_filter, t_step, t_fp, t_np = (best[k] for k in variants)
    x_filter, x_step, x_fp, x_np = (states[k] for k in variants)

    say("seawatch.batch")
    rng = np.random.default_rng(2)
    zb = p["zs"][:track_steps][None] + rng.normal(scale=2.0, size=(tracks, track_steps, 2))
    warm_tracks = min(tracks, 64)  # compile the multi-core kernel before timing
    KalmanFilter(p["F"], p["H"], p["Q"], p["R"], np.zeros((warm_tracks, 4)), p["P0"]).filter(
        zb[:warm_tracks, :2]
    )

    def batch() -> np.ndarray:
        return (
            KalmanFilter(p["F"], p["H"], p["Q"], p["R"], np.zeros((tracks, 4)), p["P0"])
            .filter(zb)
            .states
        )

    t_batch, x_batch = _timed(batch, repeats)
    single = (
        KalmanFilter(p["F"], p["H"], p["Q"], p["R"], np.zeros(4), p["P0"]).filter(zb[-1]).states
    )

    speeds = {
        "seawatch.filter": steps / t_filter,
        "seawatch.step": steps / t_step,
        "filterpy.KalmanFilter": steps / t_fp,
        "numpy.loop": steps / t_np,
        "seawatch.batch": tracks * track_steps / t_batch,
    }
    results = [
        {"name": k, "value": v, "unit": "track-steps/s" if k == "seawatch.batch" else "steps/s"}
        for k, v in speeds.items()
    ]
    ratios = {}
    for fast in ("seawatch.filter", "seawatch.step"):
        for ref in ("filterpy.KalmanFilter", "numpy.loop"):
            ratios[f"{fast}/{ref}"] = speeds[fast] / speeds[ref]
    diffs = {
        "seawatch.filter": _rel_diff(x_filter, x_fp),
        "seawatch.step": _rel_diff(x_step, x_fp),
        "numpy.loop": _rel_diff(x_np, x_fp),
        "seawatch.batch_vs_single": _rel_diff(x_batch[-1], single),
    }
    max_diff = max(diffs.values())
    targets = {
        k: {"target": v, "measured": ratios[k], "met": ratios[k] >= v} for k, v in TARGETS.items()
    }
    targets["seawatch.batch"] = {
        "target": BATCH_TARGET,
        "measured": speeds["seawatch.batch"],
        "met": speeds["seawatch.batch"] >= BATCH_TARGET,
    }
    return {
        "benchmark": "filters",
        "problem": {
            "states": 4,
            "measurements": 2,
            "steps": steps,
            "batch_tracks": tracks,
            "batch_steps": track_steps,
        },
        "results": results,
        "ratios": ratios,
        "agreement": {
            "max_rel_diff": max_diff,
            "per_variant": diffs,
            "tolerance": AGREEMENT_TOL,
            "ok": max_diff <= AGREEMENT_TOL,
        },
        "targets": targets,
    }
