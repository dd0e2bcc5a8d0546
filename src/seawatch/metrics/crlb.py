"""Posterior Cramér–Rao bounds (PCRB): the physical limit every error plot is drawn against.

ALGORITHMS.md §7 (Tichavský, Muravchik & Nehorai, IEEE TSP 46(5), 1998). For a state
``x_{k+1} = F x_k + w_k`` (``w ~ N(0, Q)``) observed as ``z_k = h_k(x_k) + v_k``
(``v ~ N(0, R_k)``) every estimator's mean-square error obeys
``E[(x̂_k − x_k)(x̂_k − x_k)ᵀ] ≥ J_k⁻¹`` with the Fisher information recursion

    J_{k+1} = (Q + F J_k⁻¹ Fᵀ)⁻¹ + E[H_{k+1}ᵀ R_{k+1}⁻¹ H_{k+1}],     J_0 = P_0⁻¹

(the singular-Q form of §7: the DWNA Q of §5.2 has rank one per axis, so the D-form
with Q⁻¹ cannot be used). ``H`` is the measurement Jacobian at the **true** state and
the expectation is an average over sampled true trajectories.

Implementation of the prediction term
-------------------------------------
``(Q + F J⁻¹ Fᵀ)⁻¹`` needs J invertible, which it is not while the prior is diffuse
(e.g. J_0 = 0: nothing known about the position before the first measurement) or
while a sensor has seen only part of the state. With M = F⁻¹ Q F⁻ᵀ (F is invertible
for every kinematic model) the same matrix is

    (Q + F J⁻¹ Fᵀ)⁻¹ = F⁻ᵀ J (I + M J)⁻¹ F⁻¹

(because F (M + J⁻¹) Fᵀ = Q + F J⁻¹ Fᵀ and (M + J⁻¹)⁻¹ = J (I + M J)⁻¹). The right
side needs neither J⁻¹ nor Q⁻¹, I + M J is always invertible (M and J are positive
semi-definite, so M J has non-negative eigenvalues), and it is continuous in J, so a
singular or zero J_0 is the exact diffuse limit. With Q = 0 it is F⁻ᵀ J F⁻¹, the
deterministic form of §7. The recursion is run on the information matrix throughout;
bounds (J⁻¹ and its blocks) are taken at the end, with ``inf`` where the information
is singular (an unobserved direction has an unbounded error).

Two timing conventions (``predict_first``):

* ``True`` (default, the FilterPy ``batch_filter`` order of every seawatch filter):
  J_0 = P_0⁻¹ is the prior one step *before* the first measurement; step k is a
  prediction then a measurement, and the bound at step k matches ``covariances[k]`` of
  ``KalmanFilter(F, H, Q, R, x0, P0).filter(zs)``. For a linear-Gaussian model the
  bound *equals* that Kalman covariance P_{k|k} (§7(b); tested to 1e-10).
* ``False``: J_0 is the prior *at* the first measurement (no prediction before it),
  the natural choice for a diffuse prior where the first measurement initialises the
  estimate.

Scenario helpers: :func:`sea_surface_angles_pcrb` (azimuth and depression of a
sea-surface target from a moving platform whose own position is measured with noise;
used by ``uav-sea`` and, later, ``solent-ais``), :func:`uav_sea_pcrb` (its
SCENARIOS.md parameters), :func:`air_range_pcrb` (scalar range from image size, NCV or
NCA) and the static flat-sea range bound :func:`flat_sea_range_bound` (§7(a)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import (
    FloatArray,
    as_float_array,
    covariance,
    finite,
    integer,
    matrix,
    positive,
)
from seawatch.geometry.sea import EARTH_RADIUS
from seawatch.models.angles import SeaSurfaceAngles
from seawatch.models.kinematic import constant_acceleration, constant_velocity

__all__ = [
    "ARCMIN",
    "PCRBResult",
    "air_range_pcrb",
    "curved_sea_range_bound",
    "flat_sea_range_bound",
    "information_predict",
    "measurement_information",
    "pcrb_information",
    "pcrb_linear",
    "pcrb_nonlinear_measurement",
    "sea_surface_angles_information",
    "sea_surface_angles_pcrb",
    "uav_sea_pcrb",
]

ARCMIN = math.pi / (180.0 * 60.0)
"""One arc-minute [rad]."""


def _sym(A: FloatArray) -> FloatArray:
    return 0.5 * (A + np.swapaxes(A, -1, -2))


@dataclass(frozen=True)
class PCRBResult:
    """Fisher information sequence of a PCRB recursion and the bounds it implies.

    Attributes:
        information: J_k, shape (T, n, n), in the inverse square units of the state
            (1/m², s²/m², … for a kinematic state in metres).
        bound: J_k⁻¹, the lower bound on the estimation error covariance, (T, n, n),
            in the state's squared units; where J_k is singular, the directions it does
            not see have ``inf`` variance (rows/columns of those states are ``inf``,
            see :meth:`marginal`).
    """

    information: FloatArray
    bound: FloatArray

    @property
    def steps(self) -> int:
        """Number of steps T."""
        return int(self.information.shape[0])

    def marginal(self, indices: ArrayLike) -> FloatArray:
        """Bound on the covariance of the states ``indices`` alone, (T, k, k).

        The Schur complement of the other states' block in J (the nuisance states are
        unknown), inverted: ``(J_aa − J_ab J_bb⁺ J_ba)⁻¹``. Where that block is still
        singular the result is ``inf`` on its diagonal.
        """
        idx = np.atleast_1d(np.asarray(indices, dtype=np.int64))
        n = self.information.shape[-1]
        if idx.ndim != 1 or idx.size == 0 or np.any(idx < 0) or np.any(idx >= n):
            raise ValueError(f"indices: expected state indices in [0, {n}), got {indices!r}")
        rest = np.setdiff1d(np.arange(n), idx)
        J = self.information
        Jaa = J[:, idx[:, None], idx[None, :]]
        if rest.size:
            Jab = J[:, idx[:, None], rest[None, :]]
            Jbb = J[:, rest[:, None], rest[None, :]]
            Jaa = Jaa - Jab @ np.linalg.pinv(Jbb, rcond=1e-12, hermitian=True) @ np.swapaxes(
                Jab, -1, -2
            )
        return _inverse_or_inf(_sym(Jaa))

    def rmse_bound(self, indices: ArrayLike) -> FloatArray:
        """√(trace of the bound on ``indices``) per step, (T,): the least achievable RMS
        error of those states together (e.g. ``indices=(0, 1)``: position error [m])."""
        B = self.marginal(indices)
        return np.sqrt(np.trace(B, axis1=-2, axis2=-1))


def _inverse_or_inf(J: FloatArray) -> FloatArray:
    """J⁻¹ for each (n, n) block; singular blocks get ``inf`` on the unseen directions."""
    w, V = np.linalg.eigh(J)
    wmax = np.max(np.abs(w), axis=-1, keepdims=True)
    tiny = w <= 1e-13 * np.maximum(wmax, 1e-300)
    singular = np.any(tiny, axis=-1)
    out = np.empty_like(J)
    if not np.all(singular):
        out[~singular] = _sym(np.linalg.inv(J[~singular]))
    for k in zip(*np.nonzero(singular), strict=True):
        good = ~tiny[k]
        Vg = V[k][:, good]
        inv = (Vg / w[k][good]) @ Vg.T
        # any state with a component along an unseen direction is unbounded
        unseen = np.any(np.abs(V[k][:, tiny[k]]) > 1e-9, axis=1)
        inv[unseen, :] = np.inf
        inv[:, unseen] = np.inf
        out[k] = inv
    return out


def information_predict(J: ArrayLike, F: ArrayLike, Q: ArrayLike) -> FloatArray:
    """Fisher information after one prediction: ``(Q + F J⁻¹ Fᵀ)⁻¹`` [ALGORITHMS.md §7].

    Computed as ``F⁻ᵀ J (I + M J)⁻¹ F⁻¹`` with ``M = F⁻¹ Q F⁻ᵀ`` (module docstring), so
    J may be singular (a diffuse prior, J = 0 gives 0) and Q may be singular (DWNA)
    or zero. Works on batches: J (..., n, n).

    Args:
        J: information matrix (n, n) or (..., n, n), symmetric PSD [1/state²].
        F: transition matrix (n, n), invertible.
        Q: process noise covariance (n, n), symmetric PSD [state²].

    Returns:
        the predicted information, same shape as J.
    """
    Jm = finite("J", as_float_array("J", J))
    F = _transition("F", F)
    n = F.shape[0]
    Q = covariance("Q", Q, n)
    if Jm.ndim < 2 or Jm.shape[-2:] != (n, n):
        raise ValueError(f"J: expected shape (..., {n}, {n}), got {Jm.shape}")
    Finv = np.linalg.inv(F)
    return _predict(Jm, Finv, Finv @ Q @ Finv.T)


def _predict(J: FloatArray, Finv: FloatArray, M: FloatArray) -> FloatArray:
    n = Finv.shape[0]
    A = np.eye(n) + M @ J  # (I + M J), eigenvalues >= 1
    # J (I + M J)^-1 = ((I + M J)^-T J)^T = solve((I + J M), J)^T, J and M symmetric
    X = np.swapaxes(np.linalg.solve(np.swapaxes(A, -1, -2), J), -1, -2)
    return _sym(Finv.T @ X @ Finv)


def _transition(name: str, F: ArrayLike) -> FloatArray:
    Fm = matrix(name, F)
    if Fm.shape[0] != Fm.shape[1]:
        raise ValueError(f"{name}: expected a square (n, n) matrix, got shape {Fm.shape}")
    if np.linalg.cond(Fm) > 1e12:
        raise ValueError(f"{name}: the transition matrix must be invertible")
    return Fm


def _initial_information(P0: ArrayLike | None, J0: ArrayLike | None, n: int) -> FloatArray:
    if (P0 is None) == (J0 is None):
        raise ValueError("P0: give exactly one of P0 (prior covariance) or J0 (prior information)")
    if J0 is not None:
        return covariance("J0", J0, n)
    P = covariance("P0", P0, n, positive_definite=True)
    return _sym(np.linalg.inv(P))


def pcrb_information(
    F: ArrayLike,
    Q: ArrayLike,
    measurement_info: ArrayLike,
    P0: ArrayLike | None = None,
    *,
    J0: ArrayLike | None = None,
    predict_first: bool = True,
) -> PCRBResult:
    """The §7 recursion given the per-step measurement information E[Hᵀ R⁻¹ H].

    ``J_k = pred(J_{k−1}) + I_k`` with ``pred`` of :func:`information_predict`; with
    ``predict_first=False`` the first step is ``J_0' = J_0 + I_0`` (no prediction).

    Args:
        F: transition matrix (n, n), invertible.
        Q: process noise covariance (n, n), PSD (may be singular or zero); or (T, n, n),
            one per step: ``Q[k]`` drives the prediction into step k (``Q[0]`` is unused
            with ``predict_first=False``).
        measurement_info: I_k = E[H_kᵀ R_k⁻¹ H_k], (T, n, n), PSD; a zero block is a step
            without a measurement.
        P0: prior covariance (n, n), positive definite; or
        J0: prior information (n, n), PSD (zero = diffuse prior). Exactly one of them.
        predict_first: see the module docstring.

    Returns:
        PCRBResult with T steps.
    """
    F = _transition("F", F)
    n = F.shape[0]
    varying = np.ndim(Q) == 3
    Q = covariance("Q", Q, n, batch=varying)
    info = finite("measurement_info", as_float_array("measurement_info", measurement_info))
    if info.ndim != 3 or info.shape[1:] != (n, n):
        raise ValueError(f"measurement_info: expected shape (T, {n}, {n}), got {info.shape}")
    T = info.shape[0]
    if varying and Q.shape[0] != T:
        raise ValueError(f"Q: expected one covariance per step, ({T}, {n}, {n}), got {Q.shape}")
    J = _initial_information(P0, J0, n)
    Finv = np.linalg.inv(F)
    M = _sym(Finv @ Q @ Finv.T)  # (n, n) or (T, n, n)
    out = np.empty((T, n, n))
    for k in range(T):
        if predict_first or k > 0:
            J = _predict(J, Finv, M[k] if varying else M)
        J = _sym(J + info[k])
        out[k] = J
    return PCRBResult(information=out, bound=_inverse_or_inf(out))


def measurement_information(H: ArrayLike, R: ArrayLike) -> FloatArray:
    """``Hᵀ R⁻¹ H`` for stacks of Jacobians and noise covariances, averaged over samples.

    Args:
        H: Jacobians (m, n), (T, m, n) or (S, T, m, n) [measurement unit / state unit].
        R: noise covariances (m, m), (T, m, m) or (S, T, m, m), positive definite,
            broadcasting against H's leading axes.

    Returns:
        E[Hᵀ R⁻¹ H] per step, (T, n, n) (the mean over the S samples when H or R has
        four axes; (1, n, n) for a single H).
    """
    Hm = finite("H", as_float_array("H", H))
    Rm = finite("R", as_float_array("R", R))
    if Hm.ndim < 2 or Hm.ndim > 4:
        raise ValueError(f"H: expected shape (m, n), (T, m, n) or (S, T, m, n), got {Hm.shape}")
    m = Hm.shape[-2]
    if Rm.ndim < 2 or Rm.ndim > 4 or Rm.shape[-2:] != (m, m):
        raise ValueError(f"R: expected shape (..., {m}, {m}) matching H, got {Rm.shape}")
    try:
        L = np.linalg.cholesky(_sym(Rm))
    except np.linalg.LinAlgError:
        raise ValueError("R: covariance must be positive definite") from None
    try:
        np.broadcast_shapes(Hm.shape[:-2], Rm.shape[:-2])
    except ValueError:
        raise ValueError(
            f"R: leading axes {Rm.shape[:-2]} do not match H's {Hm.shape[:-2]}"
        ) from None
    Ht = np.linalg.inv(L) @ Hm  # L⁻¹ H, so (L⁻¹H)ᵀ(L⁻¹H) = Hᵀ R⁻¹ H
    if Ht.ndim == 4:  # the mean over samples, without forming every (n, n) product
        info = np.einsum("sthi,sthj->tij", Ht, Ht) / Ht.shape[0]
    else:
        info = np.swapaxes(Ht, -1, -2) @ Ht
        if info.ndim == 2:
            info = info[None]
    return _sym(info)


def pcrb_linear(
    F: ArrayLike,
    Q: ArrayLike,
    H: ArrayLike,
    R: ArrayLike,
    P0: ArrayLike | None = None,
    steps: int | None = None,
    *,
    J0: ArrayLike | None = None,
    predict_first: bool = True,
) -> PCRBResult:
    """PCRB of a linear-Gaussian model: ALGORITHMS.md §7, singular-Q form, §7(b).

    ``J_k = (Q + F J_{k−1}⁻¹ Fᵀ)⁻¹ + H_kᵀ R_k⁻¹ H_k``. For a linear-Gaussian model with
    the same P0, Q and R the bound is exactly the Kalman filter covariance P_{k|k}
    (with ``predict_first=True`` that of ``KalmanFilter.filter``).

    Args:
        F: transition (n, n), invertible; Q: process noise (n, n), PSD.
        H: measurement matrix (m, n), or one per step (T, m, n).
        R: measurement noise (m, m) or (T, m, m), positive definite.
        P0: prior covariance (n, n); or ``J0`` prior information (PSD, zero = diffuse).
        steps: number of steps T (needed when H and R are constant; must match T
            otherwise).
        predict_first: timing convention (module docstring).

    Returns:
        PCRBResult with T steps.
    """
    Fm = _transition("F", F)
    Hm = finite("H", as_float_array("H", H))
    Rm = finite("R", as_float_array("R", R))
    T = None
    for name, arr in (("H", Hm), ("R", Rm)):
        if arr.ndim == 3:
            if T is not None and arr.shape[0] != T:
                raise ValueError(f"{name}: expected {T} steps, got {arr.shape[0]}")
            T = arr.shape[0]
        elif arr.ndim != 2:
            raise ValueError(f"{name}: expected a matrix or one matrix per step, got {arr.shape}")
    if steps is not None:
        steps = integer("steps", steps, 1)
        if T is not None and int(steps) != T:
            raise ValueError(f"steps: {steps} does not match the {T} per-step matrices")
        T = int(steps)
    if T is None:
        raise ValueError("steps: needed when H and R are constant matrices")
    n = Fm.shape[0]
    if Hm.shape[-1] != n:
        raise ValueError(f"H: expected {n} columns (the state size), got shape {Hm.shape}")
    info = measurement_information(np.broadcast_to(Hm, (T, *Hm.shape[-2:])), Rm)
    info = np.broadcast_to(info, (T, *info.shape[-2:]))
    return pcrb_information(Fm, Q, info, P0, J0=J0, predict_first=predict_first)


def pcrb_nonlinear_measurement(
    F: ArrayLike,
    Q: ArrayLike,
    jacobians: ArrayLike,
    R: ArrayLike,
    P0: ArrayLike | None = None,
    *,
    J0: ArrayLike | None = None,
    predict_first: bool = True,
) -> PCRBResult:
    """PCRB for linear dynamics and a nonlinear measurement (ALGORITHMS.md §7).

    ``J_k = (Q + F J_{k−1}⁻¹ Fᵀ)⁻¹ + E[H(x_k)ᵀ R_k⁻¹ H(x_k)]`` with the Jacobians at the
    **true** states, averaged over S sampled true trajectories.

    Args:
        F, Q: linear dynamics (n, n).
        jacobians: H(x_true) per sample and step, (S, T, m, n) (or (T, m, n) for a
            single, e.g. deterministic, trajectory).
        R: noise covariance (m, m), (T, m, m) or (S, T, m, m) (a state-dependent R,
            such as the effective covariance of :func:`sea_surface_angles_pcrb`, per
            sample), positive definite.
        P0 / J0, predict_first: as in :func:`pcrb_linear`.
    """
    Hm = as_float_array("jacobians", jacobians)
    if Hm.ndim not in (3, 4):
        raise ValueError(f"jacobians: expected shape (S, T, m, n) or (T, m, n), got {Hm.shape}")
    info = measurement_information(Hm, R)
    T = Hm.shape[-3]
    info = np.broadcast_to(info, (T, *info.shape[-2:]))
    return pcrb_information(F, Q, info, P0, J0=J0, predict_first=predict_first)


def sea_surface_angles_pcrb(
    F: ArrayLike,
    Q: ArrayLike,
    states: ArrayLike,
    observer: ArrayLike,
    heading: ArrayLike,
    height: float,
    sigma_azimuth: float,
    sigma_elevation: float,
    *,
    observer_cov: ArrayLike | None = None,
    P0: ArrayLike | None = None,
    J0: ArrayLike | None = None,
    predict_first: bool = False,
    curved: bool = False,
    refraction: float = 0.14,
) -> PCRBResult:
    """PCRB of a sea-surface target seen in azimuth and depression from a moving camera.

    ALGORITHMS.md §7 with the Jacobian of §7(a) ("tracking version"), seed 000 eqs. 1–2:
    ``z = [α, β]``, α the azimuth relative to the heading, β the depression of the
    water-line point (flat sea, or curved with ``curved=True``), measured with
    ``R = diag(σ_α², σ_β²)``.

    **Platform-position noise.** The camera position is not known but *measured*:
    p̃_k = p_k + n_k, n_k ~ N(0, Σ_p). The angles depend on the offset target − platform,
    so ``∂h/∂p = −∂h/∂(x, y)`` = −H_pos, and the per-step platform error enters like an
    angle error. With p_k treated as an unknown per-step nuisance whose only information
    is its measurement (the estimators use the measured p̃_k, with no model of the
    platform's motion), marginalising it from the linearised model gives the effective
    measurement covariance

        R_eff,k = R + G_k Σ_p G_kᵀ,    G_k = ∂h/∂p at the true state,

    and the Fisher information H_kᵀ R_eff,k⁻¹ H_k. This is the bound of any estimator
    that uses the measured platform positions step by step (the paper's algorithms and
    our EKF/UKF). It is chosen over augmenting the state with the platform position
    because it is the exact linearised-Gaussian answer for that estimator class, keeps
    the state of the scenario's filters, and needs no platform motion model. (A bound
    that also assumes the platform's straight course known — augmented state, platform
    dynamics without noise — is lower still, and close to the ``observer_cov=None``
    bound, since hundreds of position fixes pin down a known-velocity course.) With
    ``observer_cov=None`` the platform is treated as known: a looser (lower) bound.

    Args:
        F, Q: target dynamics, e.g. ``constant_velocity(2, dt, sigma_a)`` (DWNA).
        states: true target states [x_north, y_east, ...] [m, m/s], (S, T, n) sampled
            trajectories (or (T, n) for one).
        observer: true camera positions (x_o, y_o) [m], (T, 2) or (S, T, 2).
        heading: camera heading ψ [rad]: scalar, (T,) or (S, T) (the bound does not
            depend on it: it only shifts the azimuth).
        height: camera height h [m].
        sigma_azimuth, sigma_elevation: angle noise standard deviations [rad].
        observer_cov: Σ_p, the platform-position noise covariance (2, 2) [m²]; None =
            platform position known exactly (looser bound).
        P0 / J0: prior (exactly one). For a diffuse position prior give J0 with zero
            position block.
        predict_first: False (default): the prior is at the first measurement.
        curved, refraction: curved-sea depression (§4.2) instead of flat.

    Returns:
        PCRBResult over the T steps (state order of ``states``).
    """
    info = sea_surface_angles_information(
        states,
        observer,
        heading,
        height,
        sigma_azimuth,
        sigma_elevation,
        observer_cov=observer_cov,
        curved=curved,
        refraction=refraction,
    )
    return pcrb_information(F, Q, info, P0, J0=J0, predict_first=predict_first)


def sea_surface_angles_information(
    states: ArrayLike,
    observer: ArrayLike,
    heading: ArrayLike,
    height: float,
    sigma_azimuth: float,
    sigma_elevation: float,
    *,
    observer_cov: ArrayLike | None = None,
    curved: bool = False,
    refraction: float = 0.14,
) -> FloatArray:
    """Per-step measurement information E[Hᵀ R_eff⁻¹ H] of :func:`sea_surface_angles_pcrb`.

    The mean over the S sampled trajectories, (T, n, n) [1/m², state order of
    ``states``]. Split out so that Monte-Carlo runs processed in chunks can accumulate
    it (weight each chunk's mean by its number of samples) before one
    :func:`pcrb_information` call. Arguments as in :func:`sea_surface_angles_pcrb`.

    Note on the average (§7 asks for it): the azimuth gives much more information
    across the line of sight than the depression gives along it, and samples whose
    lines of sight differ slightly mix the strong direction into the weak one. The
    averaged bound is valid but can be far below what any estimator reaches when the
    angle information is strong: in ``uav-sea`` with the platform *known*, at 70 m,
    0.04 m averaged over the runs against 0.20 m along the nominal path. With the
    1 m platform noise the cross-range information is weak and the two agree (0.35 m).
    """
    X = finite("states", as_float_array("states", states))
    if X.ndim == 2:
        X = X[None]
    if X.ndim != 3 or X.shape[-1] < 2:
        raise ValueError(f"states: expected shape (S, T, n) or (T, n) with n >= 2, got {X.shape}")
    S, T, _ = X.shape
    obs = finite("observer", as_float_array("observer", observer))
    if obs.ndim not in (2, 3) or obs.shape[-2:] != (T, 2):
        raise ValueError(
            f"observer: expected shape (T, 2) or (S, T, 2) with T = {T}, got {obs.shape}"
        )
    obs = np.broadcast_to(obs, (S, T, 2))
    sa = positive("sigma_azimuth", sigma_azimuth)
    se = positive("sigma_elevation", sigma_elevation)
    model = SeaSurfaceAngles(
        height=positive("height", height),
        observer=obs,
        heading=np.broadcast_to(np.asarray(heading, dtype=np.float64), (S, T)),
        curved=curved,
        refraction=refraction,
    )
    H = model.jacobian(X)  # (S, T, 2, n)
    R = np.diag([sa * sa, se * se])
    if observer_cov is not None:
        Sp = covariance("observer_cov", observer_cov, 2)
        G = -H[..., :2]
        R = R + G @ Sp @ np.swapaxes(G, -1, -2)
    return measurement_information(H, R)


def uav_sea_pcrb(
    states: ArrayLike,
    observer: ArrayLike,
    *,
    heading: float = math.radians(50.0),
    height: float = 3.0,
    sigma_azimuth: float = 0.88 * ARCMIN,
    sigma_elevation: float = 1.56 * ARCMIN,
    sigma_platform: float | None = 1.0,
    dt: float = 0.1,
    sigma_a: float = 0.1,
    velocity_prior_std: float = 10.0,
) -> PCRBResult:
    """PCRB of the ``uav-sea`` scenario (SCENARIOS.md, seed 000 Table 1).

    Target state [x, y, vx, vy] (NCV, DWNA with σ_a [m/s²], step ``dt`` [s]); azimuth
    and depression from the camera at ``height`` [m] with noise σ_α, σ_β [rad]; the
    platform position measured with σ = ``sigma_platform`` [m] per axis, included as
    the effective covariance of :func:`sea_surface_angles_pcrb` (``None``: platform
    known, the looser bound). Prior, at the first measurement: nothing known about the
    position (diffuse), velocity N(·, velocity_prior_std² I) [m/s] (a sea-going vessel;
    the scenario's filters start with the same velocity uncertainty).

    Args:
        states: true target states (S, T, 4) or (T, 4) [m, m/s].
        observer: true platform positions (T, 2) or (S, T, 2) [m].

    Returns:
        PCRBResult; ``rmse_bound((0, 1))`` is the position bound [m] per step.
    """
    F, Q = constant_velocity(2, dt, sigma_a)
    vp = positive("velocity_prior_std", velocity_prior_std)
    J0 = np.diag([0.0, 0.0, 1.0 / vp**2, 1.0 / vp**2])
    cov = (
        None
        if sigma_platform is None
        else positive("sigma_platform", sigma_platform) ** 2 * np.eye(2)
    )
    return sea_surface_angles_pcrb(
        F,
        Q,
        states,
        observer,
        heading,
        height,
        sigma_azimuth,
        sigma_elevation,
        observer_cov=cov,
        J0=J0,
        predict_first=False,
    )


def air_range_pcrb(
    true_range: ArrayLike,
    dt: float,
    model: Literal["ncv", "nca"] = "ncv",
    sigma: float = 1.0,
    *,
    sigma_l: float = 1.0,
    focal: float = 40_000.0,
    size: float = 10.0,
    noise: Literal["discrete", "continuous"] = "discrete",
    P0: ArrayLike | None = None,
    J0: ArrayLike | None = None,
    predict_first: bool = False,
) -> PCRBResult:
    """PCRB of the scalar range filtered with an NCV or NCA model (``air-range``, seed 002).

    The image size ``l = f L / d + ε`` (ε ~ N(0, σ_l²), ALGORITHMS.md §5.1) carries the
    Fisher information ``(∂l/∂d)² / σ_l² = (f L / d²)² / σ_l² = 1 / σ_d(d)²`` about the
    range, with ``σ_d = d² σ_l / (f L)``: exactly the range-dependent R of the scenario
    evaluated along the **true** range (no linearisation error: l is linear in 1/d and
    its noise does not depend on d). The dynamics are the filter's model (§5.2): NCV
    ``[d, ḋ]`` with σ = σ_v [m/s²] or NCA ``[d, ḋ, d̈]`` with σ = Δa [m/s²], ``noise``
    as in :func:`seawatch.models.constant_velocity`. This is the bound *for that model*
    of the truth; σ = 0 gives the deterministic-trajectory bound (Q = 0).

    Args:
        true_range: true range per frame [m], (T,) or (S, T) (averaged over samples).
        dt: frame period [s].
        model: "ncv" or "nca".
        sigma: process-noise level of the model [m/s²]; or (T,) levels, one per frame
            (``sigma[k]`` drives the prediction into frame k, as ``Q`` of
            :func:`pcrb_information`).
        sigma_l, focal, size: image-size noise [px], focal length [px], target size [m].
        P0 / J0: prior (exactly one; default J0 = 0, diffuse).
        predict_first: timing convention (module docstring).

    Returns:
        PCRBResult; ``rmse_bound(0)`` is the range bound [m] per frame.
    """
    d = finite("true_range", as_float_array("true_range", true_range))
    if d.ndim not in (1, 2) or d.shape[-1] < 1 or np.any(d <= 0.0):
        raise ValueError(
            f"true_range: expected positive ranges, shape (T,) or (S, T), got {d.shape}"
        )
    if model == "ncv":
        F, Q = constant_velocity(1, dt, 1.0, noise=noise)
    elif model == "nca":
        F, Q = constant_acceleration(1, dt, 1.0, noise=noise)
    else:
        raise ValueError(f"model: expected 'ncv' or 'nca', got {model!r}")
    s = finite("sigma", as_float_array("sigma", sigma))
    if s.ndim > 1 or np.any(s < 0.0) or (s.ndim == 1 and s.shape[0] != d.shape[-1]):
        raise ValueError(f"sigma: expected a level >= 0 or one per frame ({d.shape[-1]},)")
    Q = s[..., None, None] ** 2 * Q  # Q scales with σ² (§5.2)
    n = F.shape[0]
    fL = positive("focal", focal) * positive("size", size)
    sl = positive("sigma_l", sigma_l)
    info_d = np.mean(np.atleast_2d((fL / (d * d)) ** 2 / sl**2), axis=0)  # 1/σ_d², (T,)
    info = np.zeros((info_d.shape[0], n, n))
    info[:, 0, 0] = info_d
    if P0 is None and J0 is None:
        J0 = np.zeros((n, n))
    return pcrb_information(F, Q, info, P0, J0=J0, predict_first=predict_first)


def flat_sea_range_bound(
    distance: ArrayLike, height: ArrayLike, sigma_beta: ArrayLike
) -> FloatArray:
    """Static range bound from one flat-sea depression angle, ALGORITHMS.md §7(a).

    With ``β = atan(h/d) + n``, ``n ~ N(0, σ_β²)``, the Fisher information about d is
    ``J(d) = h² / ((d² + h²)² σ_β²)``, so ``σ_d ≥ σ_β (d² + h²) / h ≈ d² σ_β / h``.
    (e.g. h = 10 m, σ_β = 2.5e-4 rad: 0.25 m at 100 m, 25 m at 1 km, 225 m at 3 km.)

    Args:
        distance: horizontal range d [m]; height: camera height h [m] (> 0);
        sigma_beta: depression noise σ_β [rad].

    Returns:
        the least achievable standard deviation of d [m] (broadcast shape).
    """
    d = as_float_array("distance", distance)
    h = as_float_array("height", height)
    s = as_float_array("sigma_beta", sigma_beta)
    if np.any(~(h > 0.0)):
        raise ValueError(f"height: expected a camera height > 0 m, got {height!r}")
    if np.any(~(s >= 0.0)):
        raise ValueError(f"sigma_beta: expected a standard deviation >= 0 rad, got {sigma_beta!r}")
    return s * (d * d + h * h) / h


def curved_sea_range_bound(
    distance: ArrayLike,
    height: ArrayLike,
    sigma_beta: ArrayLike,
    *,
    refraction: float = 0.14,
    earth_radius: float = EARTH_RADIUS,
) -> FloatArray:
    """Spherical-earth version of :func:`flat_sea_range_bound` (ALGORITHMS.md §7(a)).

    ``β(D) ≈ h/D + D/(2 R_e)``, ``σ_D ≥ σ_β / |h/D² − 1/(2 R_e)|`` with ``R_e = R/(1−k)``
    [m]; infinite at the horizon distance √(2 R_e h).
    """
    D = as_float_array("distance", distance)
    h = as_float_array("height", height)
    s = as_float_array("sigma_beta", sigma_beta)
    if np.any(~(h > 0.0)):
        raise ValueError(f"height: expected a camera height > 0 m, got {height!r}")
    k = float(refraction)
    if not 0.0 <= k < 1.0:
        raise ValueError(f"refraction: expected a value in [0, 1), got {refraction!r}")
    Re = positive("earth_radius", earth_radius) / (1.0 - k)
    slope = np.abs(h / (D * D) - 1.0 / (2.0 * Re))
    with np.errstate(divide="ignore"):
        return np.where(slope > 0.0, s / slope, np.inf)
