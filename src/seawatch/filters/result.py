"""Result of running a filter over a whole measurement sequence."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True)
class FilterResult:
    """Arrays produced by ``filter(zs)`` of any seawatch filter.

    Shapes use ``B...`` for the leading batch axes (none for a single track),
    ``T`` for time steps, ``n`` for the state and ``m`` for the measurement size.
    Units are those of the model (e.g. metres and metres per second for a CV model
    in metres). Steps whose measurement was missing (NaN) are predict-only: their
    innovation and NIS are NaN and their posterior equals the prediction.

    Attributes:
        states: posterior state estimates x_{k|k}, shape (B..., T, n).
        covariances: posterior covariances P_{k|k}, shape (B..., T, n, n).
        predicted_states: priors x_{k|k-1}, shape (B..., T, n).
        predicted_covariances: prior covariances P_{k|k-1}, shape (B..., T, n, n).
        innovations: z_k - h(x_{k|k-1}) (z_k - H x_{k|k-1} for linear models; angular
            components wrapped to (-pi, pi]), shape (B..., T, m).
        innovation_covariances: S_k = H P_{k|k-1} H^T + R, shape (B..., T, m, m).
        nis: normalised innovation squared y^T S^-1 y (dimensionless, chi-square with m
            degrees of freedom for a consistent filter), shape (B..., T).
    """

    states: NDArray[np.float64]
    covariances: NDArray[np.float64]
    predicted_states: NDArray[np.float64]
    predicted_covariances: NDArray[np.float64]
    innovations: NDArray[np.float64]
    innovation_covariances: NDArray[np.float64]
    nis: NDArray[np.float64]
