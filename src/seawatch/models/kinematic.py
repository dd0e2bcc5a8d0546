"""Kinematic motion models: nearly constant velocity (NCV) and acceleration (NCA).

ALGORITHMS.md §5.2; seed 002 eqs. 9–11 (NCV) and 19–21 (NCA); Bar-Shalom, Li &
Kirubarajan (2001) §6.3. State ordering for ``dim`` spatial axes is positions first,
then velocities, then accelerations: ``[x, y, (z,) vx, vy, (vz,) (ax, ay, (az))]``,
i.e. ``F = kron(F_axis, I_dim)`` and ``Q = kron(Q_axis, I_dim)``.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import FloatArray, integer, positive

NoiseKind = Literal["discrete", "continuous"]


def _check(dim: int, dt: float, sigma: float, sigma_name: str) -> tuple[int, float, float]:
    dim = integer("dim", dim, 1, 3)
    return int(dim), positive("dt", dt), positive(sigma_name, sigma, allow_zero=True)


def axis_sigmas(dim: int, sigma: float | ArrayLike, name: str) -> float | FloatArray:
    """A noise level for every spatial axis: ``sigma`` itself if it is one number (>= 0),
    else an array of ``dim`` numbers (>= 0, finite), one per axis (e.g. an image track's
    horizontal and vertical acceleration noise)."""
    if np.ndim(sigma) == 0:
        return positive(name, float(sigma), allow_zero=True)  # type: ignore[arg-type]
    s = np.asarray(sigma, dtype=float)
    if s.shape != (dim,) or not np.all(np.isfinite(s)) or np.any(s < 0.0):
        raise ValueError(
            f"{name}: expected a number >= 0 or {dim} of them (one per axis), got {sigma!r}"
        )
    return s


def _noise(noise: str) -> str:
    if noise not in ("discrete", "continuous"):
        raise ValueError(f"noise: expected 'discrete' or 'continuous', got {noise!r}")
    return noise


def constant_velocity(
    dim: int, dt: float, sigma_a: float | ArrayLike, *, noise: NoiseKind = "discrete"
) -> tuple[FloatArray, FloatArray]:
    """Transition matrix F and process noise Q of the NCV model.

    Per axis ``x = [p, v]``, ``F = [[1, T], [0, 1]]`` (seed 002 eq. 9).

    * ``noise="discrete"`` — discrete white-noise acceleration (DWNA, seed 002 eqs.
      10–11): ``Q = sigma_a^2 Γ Γ^T``, ``Γ = [T^2/2, T]^T``; ``sigma_a`` [m/s^2] is the
      standard deviation of the acceleration, constant over one interval. Rank 1 per axis.
    * ``noise="continuous"`` — continuous white-noise acceleration (CWNA):
      ``Q = q [[T^3/3, T^2/2], [T^2/2, T]]`` with power spectral density
      ``q = sigma_a^2`` [m^2/s^3]. Full rank (needed where Q is inverted, e.g. the CRLB).

    Args:
        dim: number of spatial axes (1–3).
        dt: sampling interval T [s].
        sigma_a: acceleration noise level (see above), one for all axes or one per axis
            (``dim`` numbers: ``Q = kron(Q_unit, diag(sigma_a^2))``).
        noise: "discrete" (default) or "continuous".

    Returns:
        (F, Q), each of shape (2*dim, 2*dim).
    """
    per_axis = axis_sigmas(integer("dim", dim, 1, 3), sigma_a, "sigma_a")
    if np.ndim(per_axis):  # Q_unit's axes scaled: kron(Q1, I) has no cross-axis terms
        F, Q = constant_velocity(dim, dt, 1.0, noise=noise)
        t = np.tile(per_axis, 2)
        return F, Q * np.outer(t, t)
    dim, T, s = _check(dim, dt, sigma_a, "sigma_a")  # type: ignore[arg-type]
    F1 = np.array([[1.0, T], [0.0, 1.0]])
    if _noise(noise) == "discrete":
        g = np.array([T * T / 2.0, T])
        Q1 = s * s * np.outer(g, g)
    else:
        Q1 = s * s * np.array([[T**3 / 3.0, T**2 / 2.0], [T**2 / 2.0, T]])
    eye = np.eye(dim)
    return np.kron(F1, eye), np.kron(Q1, eye)


def constant_acceleration(
    dim: int, dt: float, sigma_j: float, *, noise: NoiseKind = "discrete"
) -> tuple[FloatArray, FloatArray]:
    """Transition matrix F and process noise Q of the NCA model.

    Per axis ``x = [p, v, a]``, ``F = [[1, T, T^2/2], [0, 1, T], [0, 0, 1]]`` (seed 002
    eq. 19).

    * ``noise="discrete"`` — discrete Wiener-process acceleration (DWPA, seed 002 eqs.
      20–21): ``Q = sigma_j^2 Γ Γ^T``, ``Γ = [T^2/2, T, 1]^T``; ``sigma_j`` [m/s^2] is the
      standard deviation of the acceleration *increment* over one interval (jerk × T).
    * ``noise="continuous"`` — continuous white-noise jerk (CWNJ):
      ``Q = q [[T^5/20, T^4/8, T^3/6], [T^4/8, T^3/3, T^2/2], [T^3/6, T^2/2, T]]`` with
      ``q = sigma_j^2`` [m^2/s^5].

    Args:
        dim: number of spatial axes (1–3).
        dt: sampling interval T [s].
        sigma_j: noise level (see above).
        noise: "discrete" (default) or "continuous".

    Returns:
        (F, Q), each of shape (3*dim, 3*dim).
    """
    dim, T, s = _check(dim, dt, sigma_j, "sigma_j")
    F1 = np.array([[1.0, T, T * T / 2.0], [0.0, 1.0, T], [0.0, 0.0, 1.0]])
    if _noise(noise) == "discrete":
        g = np.array([T * T / 2.0, T, 1.0])
        Q1 = s * s * np.outer(g, g)
    else:
        Q1 = (
            s
            * s
            * np.array(
                [
                    [T**5 / 20.0, T**4 / 8.0, T**3 / 6.0],
                    [T**4 / 8.0, T**3 / 3.0, T**2 / 2.0],
                    [T**3 / 6.0, T**2 / 2.0, T],
                ]
            )
        )
    eye = np.eye(dim)
    return np.kron(F1, eye), np.kron(Q1, eye)


def position_measurement(dim: int, order: int) -> FloatArray:
    """Measurement matrix H that picks the ``dim`` positions out of a kinematic state.

    ``order`` is the number of derivatives kept per axis (2 for NCV, 3 for NCA).
    Returns ``[I_dim, 0, ...]`` of shape (dim, order*dim).
    """
    if order not in (2, 3):
        raise ValueError(f"order: expected 2 (NCV) or 3 (NCA), got {order!r}")
    dim, _, _ = _check(dim, 1.0, 0.0, "sigma")
    H = np.zeros((dim, order * dim))
    H[:, :dim] = np.eye(dim)
    return H
