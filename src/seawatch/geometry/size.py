"""Range from the image size of a target of known size (ALGORITHMS.md §5.1, seed 002 eqs. 14–15).

Pinhole relation ``d = f L / l`` with f the focal length in pixels, L the true extent
perpendicular to the line of sight [m] and l its image extent [px], its first-order error,
and the subtended-angle form for off-axis targets (§5.1 pitfall).

Bad data never raises inside a batch: an image size of 0 gives +inf, a negative or NaN
size gives NaN. Configuration errors (a focal length or true size <= 0, negative sigmas)
raise ValueError naming the argument.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import FloatArray, as_float_array, matrix

__all__ = [
    "size_range",
    "size_range_sigma",
    "subtended_angle",
    "subtended_range",
    "subtended_range_sigma",
]


def _positive_array(name: str, value: ArrayLike, unit: str) -> FloatArray:
    a = as_float_array(name, value)
    if not np.all(np.isfinite(a)) or np.any(a <= 0.0):
        raise ValueError(f"{name}: expected finite values > 0 {unit}, got {value!r}")
    return a


def _nonneg_array(name: str, value: ArrayLike, unit: str) -> FloatArray:
    a = as_float_array(name, value)
    if not np.all(np.isfinite(a)) or np.any(a < 0.0):
        raise ValueError(f"{name}: expected finite values >= 0 {unit}, got {value!r}")
    return a


def _out(a: FloatArray) -> FloatArray:
    return a[()] if a.ndim == 0 else a


def size_range(size_px: ArrayLike, true_size: ArrayLike, focal_px: ArrayLike) -> FloatArray:
    """Range from image size ``d = f L / l`` [m] (ALGORITHMS.md §5.1, seed 002).

    Valid for an extent perpendicular to the line of sight near the optical axis; for
    off-axis targets use :func:`subtended_range` (a radial extent at off-axis angle
    theta images as ``f L / (d cos^2 theta)``: 13 % error at 20°).

    Args:
        size_px: image extent l [px] (any shape; 0 gives +inf, < 0 or NaN gives NaN).
        true_size: true extent L [m], > 0 (broadcasts).
        focal_px: focal length f [px] (= f_mm / pixel pitch_mm), > 0 (broadcasts).

    Returns:
        d [m] (in the unit of ``true_size``), broadcast shape.
    """
    l_px = as_float_array("size_px", size_px)
    L = _positive_array("true_size", true_size, "[m]")
    f = _positive_array("focal_px", focal_px, "[px]")
    with np.errstate(divide="ignore", invalid="ignore"):
        d = f * L / l_px
    d = np.where(l_px < 0.0, np.nan, d)
    return _out(d)


def size_range_sigma(
    size_px: ArrayLike,
    true_size: ArrayLike,
    focal_px: ArrayLike,
    sigma_px: ArrayLike,
    sigma_size: ArrayLike = 0.0,
) -> FloatArray:
    """1-sigma error of :func:`size_range` [m] (ALGORITHMS.md §5.1, seed 002 eqs. 14–15).

        sigma_d = d^2 sigma_l / (f L)                      (seed 002 eq. 14)
        (sigma_d / d)^2 = (sigma_l / l)^2 + (sigma_L / L)^2   (uncertain true size)

    The measurement variance of seed 002 eq. 15 is ``R = sigma_d^2``. §5.1 advises a
    sigma_l that includes about 1 px of edge uncertainty on each side.

    Args:
        size_px: image extent l [px].
        true_size: true extent L [m], > 0.
        focal_px: focal length f [px], > 0.
        sigma_px: 1-sigma of l [px], >= 0.
        sigma_size: 1-sigma of L [m], >= 0.

    Returns:
        sigma_d [m]: +inf for l = 0, NaN for l < 0 or NaN.
    """
    l_px = as_float_array("size_px", size_px)
    L = _positive_array("true_size", true_size, "[m]")
    s_l = _nonneg_array("sigma_px", sigma_px, "[px]")
    s_L = _nonneg_array("sigma_size", sigma_size, "[m]")
    d = np.asarray(size_range(l_px, L, focal_px))
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.sqrt((s_l / l_px) ** 2 + (s_L / L) ** 2)
        sig = d * rel
    sig = np.where(l_px == 0.0, np.inf, sig)
    return _out(np.where(np.isnan(d), np.nan, sig))


def _rays(uv: ArrayLike, K: FloatArray, name: str) -> FloatArray:
    p = as_float_array(name, uv)
    if p.ndim == 0 or p.shape[-1] != 2:
        raise ValueError(f"{name}: expected pixel coordinates of shape (..., 2), got {p.shape}")
    homog = np.concatenate([p, np.ones((*p.shape[:-1], 1))], axis=-1)
    return homog @ np.linalg.inv(K).T


def _undistort(uv: ArrayLike, K: FloatArray, dist: ArrayLike | None, name: str) -> FloatArray:
    p = as_float_array(name, uv)
    if dist is None:
        return p
    import cv2  # local: only needed with distortion

    if p.ndim == 0 or p.shape[-1] != 2:
        raise ValueError(f"{name}: expected pixel coordinates of shape (..., 2), got {p.shape}")
    d = as_float_array("dist", dist, ndim=1)
    flat = p.reshape(-1, 1, 2)
    good = np.all(np.isfinite(flat[:, 0, :]), axis=-1)
    out = np.full(flat.shape, np.nan)
    if np.any(good):
        out[good] = cv2.undistortPoints(flat[good], K, d, P=K)
    return out.reshape(p.shape)


def _camera_matrix(camera_matrix: ArrayLike) -> FloatArray:
    K = matrix("camera_matrix", camera_matrix, (3, 3))
    if abs(np.linalg.det(K)) < 1e-300:
        raise ValueError("camera_matrix: singular intrinsic matrix")
    return K


def subtended_angle(
    end_a: ArrayLike,
    end_b: ArrayLike,
    camera_matrix: ArrayLike,
    dist: ArrayLike | None = None,
) -> FloatArray:
    """Angle between the rays through two pixels [rad] (ALGORITHMS.md §5.1 pitfall).

    Rays ``r = K^-1 [u, v, 1]^T`` (after undistortion with OpenCV when ``dist`` is given);
    ``phi = atan2(|r_a x r_b|, r_a . r_b)`` (accurate for small angles).

    Args:
        end_a, end_b: pixel coordinates (u, v) of the two ends [px], shape (..., 2).
        camera_matrix: K (3, 3) [px].
        dist: optional OpenCV distortion coefficients (k1, k2, p1, p2[, k3, ...]).
    """
    K = _camera_matrix(camera_matrix)
    ra = _rays(_undistort(end_a, K, dist, "end_a"), K, "end_a")
    rb = _rays(_undistort(end_b, K, dist, "end_b"), K, "end_b")
    cross = np.linalg.norm(np.cross(ra, rb), axis=-1)
    return _out(np.arctan2(cross, np.sum(ra * rb, axis=-1)))


def subtended_range(
    end_a: ArrayLike,
    end_b: ArrayLike,
    true_size: ArrayLike,
    camera_matrix: ArrayLike,
    dist: ArrayLike | None = None,
) -> FloatArray:
    """Off-axis size ranging from the subtended angle [m] (ALGORITHMS.md §5.1 pitfall).

        d = L / (2 tan(phi / 2))

    with phi the :func:`subtended_angle` of the two ends. Exact for an extent L that is
    perpendicular to the line of sight to its midpoint and bisected by it, at any
    off-axis angle; it reduces to ``f L / l`` on the optical axis.

    Args:
        end_a, end_b: pixel coordinates of the two ends [px], (..., 2).
        true_size: L [m], > 0.
        camera_matrix: K (3, 3) [px].
        dist: optional OpenCV distortion coefficients.

    Returns:
        Range to the target's midpoint [m]; +inf when the ends coincide, NaN for NaN pixels.
    """
    L = _positive_array("true_size", true_size, "[m]")
    phi = np.asarray(subtended_angle(end_a, end_b, camera_matrix, dist))
    with np.errstate(divide="ignore"):
        return _out(L / (2.0 * np.tan(0.5 * phi)))


def subtended_range_sigma(
    end_a: ArrayLike,
    end_b: ArrayLike,
    true_size: ArrayLike,
    camera_matrix: ArrayLike,
    sigma_px: ArrayLike,
    sigma_size: ArrayLike = 0.0,
    dist: ArrayLike | None = None,
) -> FloatArray:
    """1-sigma error of :func:`subtended_range` [m] (first order, §5.1).

        sigma_d^2 = (dd/dphi)^2 sum_i (dphi/dp_i)^2 sigma_px^2 + (d/L)^2 sigma_L^2,
        dd/dphi = -L / (4 sin^2(phi/2))

    where the p_i are the four pixel coordinates of the two ends (independent, each with
    sigma_px); dphi/dp_i by central differences (step 1e-3 px). On the axis it equals
    :func:`size_range_sigma` with ``sigma_l = sqrt(2) sigma_px``.

    Args:
        end_a, end_b, true_size, camera_matrix, dist: as in :func:`subtended_range`.
        sigma_px: 1-sigma of each pixel coordinate [px], >= 0.
        sigma_size: 1-sigma of L [m], >= 0.
    """
    L = _positive_array("true_size", true_size, "[m]")
    s_p = _nonneg_array("sigma_px", sigma_px, "[px]")
    s_L = _nonneg_array("sigma_size", sigma_size, "[m]")
    a = as_float_array("end_a", end_a)
    b = as_float_array("end_b", end_b)
    a, b = np.broadcast_arrays(a, b)
    phi = np.asarray(subtended_angle(a, b, camera_matrix, dist))
    step = 1e-3
    grad2 = np.zeros(phi.shape)
    for which in (0, 1):
        for axis in (0, 1):
            e = np.zeros(2)
            e[axis] = step
            pa, pb = (a + e, b) if which == 0 else (a, b + e)
            ma, mb = (a - e, b) if which == 0 else (a, b - e)
            plus = np.asarray(subtended_angle(pa, pb, camera_matrix, dist))
            minus = np.asarray(subtended_angle(ma, mb, camera_matrix, dist))
            grad2 = grad2 + ((plus - minus) / (2.0 * step)) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        d = L / (2.0 * np.tan(0.5 * phi))
        dd_dphi = -L / (4.0 * np.sin(0.5 * phi) ** 2)
        sig = np.sqrt(dd_dphi**2 * grad2 * s_p**2 + (d / L * s_L) ** 2)
    return _out(sig)
