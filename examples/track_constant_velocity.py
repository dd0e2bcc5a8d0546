"""Track a ship on a 2-D constant-velocity course from noisy positions.

Run: ``python examples/track_constant_velocity.py`` — prints the RMS position error of
the raw measurements and of the Kalman filter, and the filter's mean NIS (≈ 2 when the
filter is consistent: chi-square with 2 degrees of freedom).
"""

from __future__ import annotations

import numpy as np

from seawatch.filters import KalmanFilter
from seawatch.models import constant_velocity, position_measurement


def main(steps: int = 2000, seed: int = 0) -> dict[str, float]:
    dt, sigma_a, sigma_z = 1.0, 0.05, 15.0  # s, m/s², m
    F, Q = constant_velocity(2, dt, sigma_a)
    H = position_measurement(2, 2)
    rng = np.random.default_rng(seed)
    x = np.array([0.0, 0.0, 4.0, 2.5])  # north, east [m]; velocity [m/s]
    truth = np.empty((steps, 4))
    for k in range(steps):
        x = F @ x + rng.multivariate_normal(np.zeros(4), Q)
        truth[k] = x
    zs = truth[:, :2] + rng.normal(scale=sigma_z, size=(steps, 2))
    kf = KalmanFilter(
        F, H, Q, sigma_z**2 * np.eye(2), x0=[*zs[0], 0.0, 0.0], P0=np.diag([225, 225, 100, 100])
    )
    result = kf.filter(zs)
    rms = lambda e: float(np.sqrt(np.mean(np.sum(e**2, axis=-1))))  # noqa: E731
    out = {
        "rms_raw_m": rms(zs - truth[:, :2]),
        "rms_filtered_m": rms(result.states[100:, :2] - truth[100:, :2]),
        "mean_nis": float(np.mean(result.nis[100:])),
    }
    for key, value in out.items():
        print(f"{key}: {value:.2f}")
    return out


if __name__ == "__main__":
    main()
