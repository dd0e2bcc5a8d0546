"""Binocular (and multi-view) stereo: DLT triangulation, its covariance, rectified depth.

Implements ALGORITHMS.md §6 (seed 003 eqs. 1–3): linear triangulation from any number of
3×4 projection matrices (§6.1, homogeneous SVD as in ``cv2.triangulatePoints`` or the
seed's inhomogeneous least squares), first-order covariance from pixel noise, rectified
disparity → depth (§6.2) with its error (§6.3), and stereo-rig projection matrices from
calibration tables (``P1 = K1 [I | 0]``, ``P2 = K2 [R | T]``; the left camera is the
world frame and ``X_R = R X_L + T``), including the seed 003 tables
(:data:`SEED003_CALIBRATION`).

Pixel coordinates (u right, v down) must be **undistorted** when ``P = K [R | t]``
(``cv2.undistortPoints(..., P=K)``; :meth:`StereoRig.triangulate` does it). World units
are those of the translation in the projection matrices (mm for the seed 003 tables).

Bad data never raises inside a batch: NaN pixels give NaN rows with flag
:attr:`TriangulationFlag.INVALID`; parallel rays (a point at infinity, X[3] ≈ 0) are
flagged AT_INFINITY; a point behind a camera is flagged BEHIND_CAMERA.
"""

from __future__ import annotations

import enum
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from seawatch._validation import FloatArray, as_float_array, matrix, positive, vector

__all__ = [
    "SEED003_CALIBRATION",
    "StereoRig",
    "Triangulation",
    "TriangulationFlag",
    "depth_bias",
    "depth_sigma",
    "disparity_to_depth",
    "projection_matrices_from_calibration",
    "rectified_point",
    "triangulate",
    "triangulate_points",
    "triangulation_covariance",
]

Method = Literal["homogeneous", "inhomogeneous"]


class TriangulationFlag(enum.IntFlag):
    """Per-point status of a triangulation (bit flags, stored as uint8)."""

    OK = 0
    AT_INFINITY = 1
    """The rays are (nearly) parallel: parallax below ``min_parallax``, X[3] ≈ 0."""
    BEHIND_CAMERA = 2
    """Cheirality failed: the point has depth <= 0 in at least one camera."""
    INVALID = 4
    """NaN/inf pixel coordinates: the row is NaN."""


@dataclass(frozen=True, eq=False)
class Triangulation:
    """Result of :func:`triangulate_points` for N points seen in V views.

    Attributes:
        points: (N, 3) Euclidean points [world units, e.g. m or mm]; NaN for INVALID rows.
            AT_INFINITY rows hold whatever the solver gave (possibly huge): check the flags.
        homogeneous: (N, 4) unit-norm homogeneous points, sign chosen so that X[3] >= 0
            (for the inhomogeneous method, ``(X, 1)`` normalised).
        depths: (V, N) depth of each point in each camera [world units] (positive in
            front; for P = K[R|t] with K[2] = (0, 0, 1) it is the camera-frame Z).
        parallax: (N,) largest angle between the viewing rays of any two views [rad]
            (≈ baseline / range for a point in front of both cameras).
        reprojection_error: (N,) RMS over views of the pixel reprojection error [px].
        flags: (N,) :class:`TriangulationFlag` bits, uint8.
    """

    points: FloatArray
    homogeneous: FloatArray
    depths: FloatArray
    parallax: FloatArray
    reprojection_error: FloatArray
    flags: NDArray[np.uint8]

    @property
    def ok(self) -> NDArray[np.bool_]:
        """True where no flag is set."""
        return self.flags == 0


# ----------------------------------------------------------------------------- inputs
def _projections(projections: Sequence[ArrayLike] | ArrayLike) -> FloatArray:
    if isinstance(projections, np.ndarray) and projections.ndim == 3:
        items = list(projections)
    else:
        try:
            items = list(projections)  # type: ignore[arg-type]
        except TypeError:
            raise ValueError("projections: expected a sequence of 3×4 matrices") from None
    if len(items) < 2:
        raise ValueError(f"projections: expected at least 2 views, got {len(items)}")
    Ps = np.stack([matrix(f"projections[{i}]", P, (3, 4)) for i, P in enumerate(items)])
    for i, P in enumerate(Ps):
        if np.linalg.matrix_rank(P) < 3:
            raise ValueError(f"projections[{i}]: rank < 3, not a camera matrix")
    return Ps


def _points(points: Sequence[ArrayLike] | ArrayLike, n_views: int) -> FloatArray:
    try:
        items = list(points)  # type: ignore[arg-type]
    except TypeError:
        raise ValueError("points: expected a sequence of (N, 2) pixel arrays") from None
    if len(items) != n_views:
        raise ValueError(f"points: expected {n_views} arrays (one per view), got {len(items)}")
    arrs = []
    for i, p in enumerate(items):
        a = as_float_array(f"points[{i}]", p)
        if a.ndim == 1 and a.shape[0] == 2:
            a = a[None, :]
        if a.ndim != 2 or a.shape[1] != 2:
            raise ValueError(f"points[{i}]: expected pixel coordinates (N, 2), got {a.shape}")
        arrs.append(a)
    n = arrs[0].shape[0]
    for i, a in enumerate(arrs):
        if a.shape[0] != n:
            raise ValueError(f"points[{i}]: expected {n} points like points[0], got {a.shape[0]}")
    return np.stack(arrs)  # (V, N, 2)


def _forward_sign(Ps: FloatArray) -> FloatArray:
    """sign(det M) per view (M = P[:, :3]): +1 when depth = (P X)[2] / ||m3|| is forward."""
    return np.sign(np.linalg.det(Ps[:, :, :3]))


# ----------------------------------------------------------------------------- DLT
def triangulate_points(
    projections: Sequence[ArrayLike] | ArrayLike,
    points: Sequence[ArrayLike] | ArrayLike,
    method: Method = "homogeneous",
    min_parallax: float = 1e-5,
) -> Triangulation:
    """Linear (DLT) triangulation from V >= 2 views (ALGORITHMS.md §6.1, seed 003 eqs. 1–3).

    For each point, with ``p_v^{iT}`` the rows of P_v and (u_v, v_v) its undistorted pixel
    coordinates in view v, the 2V × 4 system

        [ u_v p_v^{3T} - p_v^{1T} ]
        [ v_v p_v^{3T} - p_v^{2T} ]  X = 0          (v = 1..V)

    is solved either

    - ``"homogeneous"`` (default, the accurate one): ``X = V[:, -1]`` of the SVD
      ``A = U S V^T`` (min ||A X|| s.t. ||X|| = 1), ``X_e = X[:3] / X[3]``. This is exactly
      what ``cv2.triangulatePoints`` computes for two views (no coordinate normalisation);
    - ``"inhomogeneous"`` (seed 003 eq. 3): ``X_4 = 1``, the fourth column moved to the
      right-hand side and the 2V × 3 system solved by least squares (via the SVD).

    The two differ when the views' projective depths differ (seed 003's experiment 1
    gives a path 14 % shorter with the inhomogeneous form; ALGORITHMS.md §6.1).

    Flags: AT_INFINITY when the largest angle between two viewing rays is below
    ``min_parallax`` (parallel rays; the homogeneous X[3] ≈ 0); BEHIND_CAMERA when a
    finite point has depth <= 0 in some view (cheirality, not checked at infinity);
    INVALID for NaN pixels.

    Args:
        projections: V camera matrices P_v (3, 4) [px per world unit].
        points: V arrays of undistorted pixel coordinates (N, 2) [px] (one per view,
            same N; a single point may be given as (2,)).
        method: ``"homogeneous"`` or ``"inhomogeneous"``.
        min_parallax: ray angle below which a point counts as at infinity [rad], >= 0
            (1e-5 rad: range/baseline > 1e5).

    Returns:
        :class:`Triangulation` (points (N, 3) in the world units of the P_v).
    """
    if method not in ("homogeneous", "inhomogeneous"):
        raise ValueError(f"method: expected 'homogeneous' or 'inhomogeneous', got {method!r}")
    min_par = positive("min_parallax", min_parallax, allow_zero=True)
    Ps = _projections(projections)
    x = _points(points, len(Ps))  # (V, N, 2)
    V, N = x.shape[0], x.shape[1]
    invalid = ~np.all(np.isfinite(x), axis=(0, 2))  # (N,)
    xs = np.where(invalid[None, :, None], 0.0, x)

    # A: (N, 2V, 4); rows u p3 - p1, v p3 - p2 per view.
    A = np.empty((N, 2 * V, 4))
    for v in range(V):
        P = Ps[v]
        A[:, 2 * v, :] = xs[v, :, 0:1] * P[2] - P[0]
        A[:, 2 * v + 1, :] = xs[v, :, 1:2] * P[2] - P[1]

    if method == "homogeneous":
        _, _, vh = np.linalg.svd(A)
        Xh = vh[:, -1, :]
    else:
        A3, b = A[:, :, :3], -A[:, :, 3]
        U, S, vh = np.linalg.svd(A3, full_matrices=False)
        with np.errstate(divide="ignore", invalid="ignore"):
            coef = np.einsum("nij,ni->nj", U, b) / S
        coef = np.where(S > S[:, :1] * 1e-15, coef, 0.0)  # rank-deficient: minimum norm
        Xe = np.einsum("nji,nj->ni", vh, coef)
        Xh = np.concatenate([Xe, np.ones((N, 1))], axis=1)
        Xh = Xh / np.linalg.norm(Xh, axis=1, keepdims=True)
    Xh = Xh * np.where(Xh[:, 3:4] < 0.0, -1.0, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        Xe = Xh[:, :3] / Xh[:, 3:4]

    # Viewing rays (forward directions in the world frame): d_v = sign(det M) M^-1 x_v.
    sgn = _forward_sign(Ps)
    homog = np.concatenate([xs, np.ones((V, N, 1))], axis=2)  # (V, N, 3)
    rays = np.stack([np.linalg.solve(Ps[v, :, :3], homog[v].T).T * sgn[v] for v in range(V)])
    rays = rays / np.linalg.norm(rays, axis=2, keepdims=True)
    parallax = np.zeros(N)
    for i in range(V):
        for j in range(i + 1, V):
            c = np.linalg.norm(np.cross(rays[i], rays[j]), axis=1)
            d = np.sum(rays[i] * rays[j], axis=1)
            parallax = np.maximum(parallax, np.arctan2(c, d))

    # Depths and reprojection errors from the homogeneous point (valid at infinity too).
    proj = np.einsum("vij,nj->vni", Ps, Xh)  # (V, N, 3)
    m3 = np.linalg.norm(Ps[:, 2, :3], axis=1)  # (V,)
    with np.errstate(divide="ignore", invalid="ignore"):
        depths = sgn[:, None] * proj[:, :, 2] / (Xh[None, :, 3] * m3[:, None])
        reproj = proj[:, :, :2] / proj[:, :, 2:3]
        err = np.sqrt(np.mean(np.sum((reproj - xs) ** 2, axis=2), axis=0))

    at_inf = (parallax < min_par) | ~np.all(np.isfinite(Xe), axis=1)
    behind = ~at_inf & np.any(~(depths > 0.0), axis=0)
    flags = np.zeros(N, dtype=np.uint8)
    flags[at_inf] |= np.uint8(TriangulationFlag.AT_INFINITY)
    flags[behind] |= np.uint8(TriangulationFlag.BEHIND_CAMERA)
    flags[invalid] = TriangulationFlag.INVALID
    nan = invalid
    Xe[nan] = np.nan
    Xh[nan] = np.nan
    depths[:, nan] = np.nan
    parallax[nan] = np.nan
    err[nan] = np.nan
    return Triangulation(
        points=Xe,
        homogeneous=Xh,
        depths=depths,
        parallax=parallax,
        reprojection_error=err,
        flags=flags,
    )


def triangulate(
    projections: Sequence[ArrayLike] | ArrayLike,
    points: Sequence[ArrayLike] | ArrayLike,
    method: Method = "homogeneous",
) -> FloatArray:
    """Triangulated points (N, 3) [world units]; :func:`triangulate_points` without the flags.

    ALGORITHMS.md §6.1, seed 003 eqs. 1–3. Args as in :func:`triangulate_points`. NaN
    pixels give NaN rows; use :func:`triangulate_points` to see which points are at
    infinity or behind a camera.
    """
    return triangulate_points(projections, points, method).points


def triangulation_covariance(
    projections: Sequence[ArrayLike] | ArrayLike,
    X: ArrayLike,
    sigma_px: ArrayLike,
) -> FloatArray:
    """First-order covariance of triangulated points from pixel noise [world units^2].

    With J the (2V × 3) Jacobian of the stacked projections ``u_v = (p_v^1 X)/(p_v^3 X)``,
    ``v_v = (p_v^2 X)/(p_v^3 X)`` at the point,

        du_v/dX = (p_v^{1} - u_v p_v^{3})[:3] / (p_v^3 X),   likewise for v_v,
        Cov = ( J^T W J )^-1,    W = diag(1 / sigma^2)

    the Gauss–Newton (Cramér–Rao) covariance of a reprojection-optimal triangulation; the
    homogeneous DLT attains it to first order when the views' depths are similar (test:
    Monte Carlo). It grows as ``Z^2 sigma / (f B)`` along the line of sight (§6.3).

    Args:
        projections: V matrices (3, 4).
        X: (N, 3) or (3,) points [world units]; NaN rows give NaN.
        sigma_px: pixel noise 1-sigma [px], >= 0: a scalar, (V,) per view, (V, 2) per view
            and axis, or (N, V, 2).

    Returns:
        (N, 3, 3) (or (3, 3) for a single point); +inf where J^T W J is singular (a point
        at infinity or on a camera centre).
    """
    Ps = _projections(projections)
    V = len(Ps)
    pts = as_float_array("X", X)
    single = pts.ndim == 1
    pts = np.atleast_2d(pts)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"X: expected points of shape (N, 3) or (3,), got {pts.shape}")
    N = pts.shape[0]
    s = as_float_array("sigma_px", sigma_px)
    if s.ndim == 1 and s.shape[0] == V:
        s = s[:, None]
    try:
        s = np.broadcast_to(s, (N, V, 2))
    except ValueError:
        raise ValueError(
            f"sigma_px: expected a scalar, (V,), (V, 2) or (N, V, 2) with V = {V}, got {s.shape}"
        ) from None
    if not np.all(np.isfinite(s)) or np.any(s <= 0.0):
        raise ValueError("sigma_px: expected finite pixel standard deviations > 0")
    bad = ~np.all(np.isfinite(pts), axis=1)
    Xh = np.concatenate([np.where(bad[:, None], 0.0, pts), np.ones((N, 1))], axis=1)
    proj = np.einsum("vij,nj->nvi", Ps, Xh)  # (N, V, 3)
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = proj[:, :, :2] / proj[:, :, 2:3]
        # J[n, v, a, :] = (P[v, a, :3] - uv[n, v, a] P[v, 2, :3]) / proj[n, v, 2]
        J = (Ps[None, :, :2, :3] - uv[..., None] * Ps[None, :, None, 2, :3]) / proj[
            :, :, 2, None, None
        ]
        Jw = J / s[..., None]
        Jw = Jw.reshape(N, 2 * V, 3)
        info = np.einsum("nki,nkj->nij", Jw, Jw)
    finite_info = np.all(np.isfinite(info), axis=(1, 2))
    info = np.where(finite_info[:, None, None], info, 0.0)
    vals, vecs = np.linalg.eigh(info)
    singular = ~finite_info | (vals[:, 0] <= 1e-12 * np.maximum(vals[:, -1], 1e-300))
    with np.errstate(divide="ignore"):
        inv_vals = np.where(singular[:, None], 0.0, 1.0 / np.where(vals > 0, vals, 1.0))
    cov = np.einsum("nij,nj,nkj->nik", vecs, inv_vals, vecs)
    cov[singular & ~bad] = np.inf
    cov[bad] = np.nan
    return cov[0] if single else cov


# ----------------------------------------------------------------------------- rectified
def disparity_to_depth(disparity: ArrayLike, focal_px: float, baseline: float) -> FloatArray:
    """Depth of a rectified pair ``Z = f B / d`` (ALGORITHMS.md §6.2).

    Args:
        disparity: d = u_L - u_R [px] (any shape; StereoBM/SGBM output must first be
            divided by 16). d = 0 gives +inf, d < 0 or NaN gives NaN.
        focal_px: f [px], > 0.
        baseline: B [m or any unit; Z has the same], > 0.
    """
    f = positive("focal_px", focal_px)
    B = positive("baseline", baseline)
    d = as_float_array("disparity", disparity)
    with np.errstate(divide="ignore", invalid="ignore"):
        Z = f * B / d
    Z = np.where(d < 0.0, np.nan, Z)
    return Z[()] if Z.ndim == 0 else Z


def rectified_point(
    u_left: ArrayLike,
    v: ArrayLike,
    disparity: ArrayLike,
    focal_px: float,
    baseline: float,
    cx: float,
    cy: float,
) -> FloatArray:
    """3-D point of a rectified pair in the left camera frame (ALGORITHMS.md §6.2).

        Z = f B / d,   X = (u_L - c_x) Z / f,   Y = (v - c_y) Z / f

    Args:
        u_left, v: left-image pixel [px] (arrays, broadcast with disparity).
        disparity: d = u_L - u_R [px] (d = 0 → inf, d < 0 → NaN).
        focal_px: f [px]; baseline: B (unit of the result); cx, cy: principal point [px].

    Returns:
        (..., 3) points (X right, Y down, Z forward) [unit of B].
    """
    f = positive("focal_px", focal_px)
    cx_ = float(vector("cx", cx, 1)[0])
    cy_ = float(vector("cy", cy, 1)[0])
    Z = np.asarray(disparity_to_depth(disparity, f, baseline))
    u = as_float_array("u_left", u_left)
    vv = as_float_array("v", v)
    u, vv, Z = np.broadcast_arrays(u, vv, Z)
    with np.errstate(invalid="ignore"):
        return np.stack([(u - cx_) * Z / f, (vv - cy_) * Z / f, Z], axis=-1)


def depth_sigma(
    disparity: ArrayLike, focal_px: float, baseline: float, sigma_disparity: ArrayLike
) -> FloatArray:
    """1-sigma depth error of a rectified pair (ALGORITHMS.md §6.3).

        sigma_Z ≈ |dZ/dd| sigma_d = Z^2 sigma_d / (f B) = f B sigma_d / d^2

    with ``sigma_d ≈ sqrt(2) sigma_match`` for independent localisations in both images.

    Args:
        disparity: d [px] (d = 0 → inf, d < 0 → NaN). focal_px: f [px]. baseline: B.
        sigma_disparity: 1-sigma of d [px], >= 0.
    """
    s = as_float_array("sigma_disparity", sigma_disparity)
    if not np.all(np.isfinite(s)) or np.any(s < 0.0):
        raise ValueError("sigma_disparity: expected finite values >= 0 [px]")
    Z = np.asarray(disparity_to_depth(disparity, focal_px, baseline))
    sig = Z * Z * s / (float(focal_px) * float(baseline))
    return sig[()] if sig.ndim == 0 else sig


def depth_bias(
    disparity: ArrayLike, focal_px: float, baseline: float, sigma_disparity: ArrayLike
) -> FloatArray:
    """Second-order bias of the rectified depth, ``E[Z] - Z ≈ (f B / d) sigma_d^2 / d^2`` (§6.3).

    Positive: the range is over-estimated at long range. Args as in :func:`depth_sigma`.
    """
    Z = np.asarray(disparity_to_depth(disparity, focal_px, baseline))
    d = as_float_array("disparity", disparity)
    s = as_float_array("sigma_disparity", sigma_disparity)
    with np.errstate(divide="ignore", invalid="ignore"):
        b = Z * s * s / (d * d)
    return b[()] if b.ndim == 0 else b


# ----------------------------------------------------------------------------- rigs
def _rotation(rotation: ArrayLike) -> FloatArray:
    r = as_float_array("rotation", rotation)
    if r.shape == (3,) or r.shape == (3, 1) or r.shape == (1, 3):
        rv = vector("rotation", r.reshape(3), 3)
        R, _ = cv2.Rodrigues(rv)
        return np.asarray(R, dtype=np.float64)
    R = matrix("rotation", r, (3, 3))
    if not np.allclose(R @ R.T, np.eye(3), atol=1e-6) or np.linalg.det(R) <= 0:
        raise ValueError("rotation: expected a rotation matrix (orthonormal, det +1)")
    return R


def _intrinsics(name: str, K: ArrayLike) -> FloatArray:
    K_ = matrix(name, K, (3, 3))
    if K_[0, 0] <= 0 or K_[1, 1] <= 0 or not np.allclose(K_[2], [0.0, 0.0, 1.0]):
        raise ValueError(f"{name}: expected an intrinsic matrix [[fx,s,cx],[0,fy,cy],[0,0,1]]")
    return K_


def projection_matrices_from_calibration(
    K1: ArrayLike, K2: ArrayLike, rotation: ArrayLike, T: ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """Projection matrices ``P1 = K1 [I | 0]``, ``P2 = K2 [R | T]`` of a stereo rig (§6.1).

    The left camera is the world frame; a point maps into the right camera frame as
    ``X_R = R X_L + T`` (OpenCV ``stereoCalibrate``, MATLAB toolbox ``om``/``T``).

    Args:
        K1, K2: intrinsic matrices (3, 3) [px] of the left and right cameras.
        rotation: rotation vector ``om`` (3,) [rad] (``cv2.Rodrigues``) or a matrix R (3, 3).
        T: translation (3,) [world units: m, or mm for the seed 003 tables].

    Returns:
        (P1, P2), each (3, 4).
    """
    K1_ = _intrinsics("K1", K1)
    K2_ = _intrinsics("K2", K2)
    R = _rotation(rotation)
    t = vector("T", np.asarray(T, dtype=np.float64).reshape(-1), 3)
    P1 = K1_ @ np.hstack([np.eye(3), np.zeros((3, 1))])
    P2 = K2_ @ np.hstack([R, t[:, None]])
    return P1, P2


@dataclass(frozen=True, eq=False)
class StereoRig:
    """A calibrated stereo pair: intrinsics, distortion and right-from-left pose (§6.1).

    Attributes:
        K_left, K_right: (3, 3) intrinsic matrices [px].
        R: (3, 3) rotation and T: (3,) translation of the right camera relative to the
            left (``X_R = R X_L + T``) [T in ``unit``].
        dist_left, dist_right: OpenCV distortion coefficients (k1, k2, p1, p2[, k3...]);
            zeros when the pixels are already undistorted.
        unit: unit of T and of triangulated points (``"m"`` or ``"mm"``).
    """

    K_left: FloatArray
    K_right: FloatArray
    R: FloatArray
    T: FloatArray
    dist_left: FloatArray = field(default_factory=lambda: np.zeros(5))
    dist_right: FloatArray = field(default_factory=lambda: np.zeros(5))
    unit: str = "m"

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "K_left", _intrinsics("K_left", self.K_left))
        set_(self, "K_right", _intrinsics("K_right", self.K_right))
        set_(self, "R", _rotation(self.R))
        set_(self, "T", vector("T", np.asarray(self.T, dtype=np.float64).reshape(-1), 3))
        set_(self, "dist_left", vector("dist_left", np.ravel(self.dist_left)))
        set_(self, "dist_right", vector("dist_right", np.ravel(self.dist_right)))
        if self.unit not in ("m", "mm"):
            raise ValueError(f"unit: expected 'm' or 'mm', got {self.unit!r}")

    @classmethod
    def from_rotation_vector(
        cls,
        K_left: ArrayLike,
        K_right: ArrayLike,
        rvec: ArrayLike,
        T: ArrayLike,
        unit: str = "m",
        dist_left: ArrayLike | None = None,
        dist_right: ArrayLike | None = None,
    ) -> StereoRig:
        """Build from a rotation vector ``om`` [rad] (``cv2.Rodrigues``), as in seed 003 Table 2."""
        return cls(
            K_left=np.asarray(K_left, dtype=np.float64),
            K_right=np.asarray(K_right, dtype=np.float64),
            R=_rotation(vector("rvec", np.ravel(rvec), 3)),
            T=np.asarray(T, dtype=np.float64),
            dist_left=np.zeros(5) if dist_left is None else np.asarray(dist_left, dtype=float),
            dist_right=np.zeros(5) if dist_right is None else np.asarray(dist_right, dtype=float),
            unit=unit,
        )

    @property
    def rvec(self) -> FloatArray:
        """Rotation vector of R [rad] (3,)."""
        r, _ = cv2.Rodrigues(self.R)
        return np.asarray(r, dtype=np.float64).reshape(3)

    @property
    def baseline(self) -> float:
        """Baseline |T| [unit]: the distance between the camera centres."""
        return float(np.linalg.norm(self.T))

    def projection_matrices(self) -> tuple[FloatArray, FloatArray]:
        """(P1, P2) = (K_left [I | 0], K_right [R | T]): the rig's projection matrices."""
        return projection_matrices_from_calibration(self.K_left, self.K_right, self.R, self.T)

    def undistort(self, left_uv: ArrayLike, right_uv: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Undistorted pixel coordinates (N, 2) of raw left/right pixels (N, 2) [px]."""
        return (
            _undistort_pixels(left_uv, self.K_left, self.dist_left, "left_uv"),
            _undistort_pixels(right_uv, self.K_right, self.dist_right, "right_uv"),
        )

    def triangulate(
        self,
        left_uv: ArrayLike,
        right_uv: ArrayLike,
        method: Method = "homogeneous",
        undistort: bool = True,
        min_parallax: float = 1e-5,
    ) -> Triangulation:
        """Triangulate raw pixel pairs (undistorted first unless ``undistort=False``).

        Points are in the left camera frame [unit]. See :func:`triangulate_points`.
        """
        if undistort:
            left, right = self.undistort(left_uv, right_uv)
        else:
            left, right = left_uv, right_uv
        return triangulate_points(self.projection_matrices(), [left, right], method, min_parallax)


def _undistort_pixels(uv: ArrayLike, K: FloatArray, dist: FloatArray, name: str) -> FloatArray:
    p = as_float_array(name, uv)
    if p.ndim == 1 and p.shape[0] == 2:
        p = p[None, :]
    if p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f"{name}: expected pixel coordinates (N, 2), got {p.shape}")
    if not np.any(dist):
        return p.copy()
    out = np.full(p.shape, np.nan)
    good = np.all(np.isfinite(p), axis=1)
    if np.any(good):
        out[good] = cv2.undistortPoints(p[good].reshape(-1, 1, 2), K, dist, P=K).reshape(-1, 2)
    return out


SEED003_CALIBRATION = StereoRig.from_rotation_vector(
    K_left=[[1113.20069, 0.0, 300.32161], [0.0, 1087.09209, 205.54074], [0.0, 0.0, 1.0]],
    K_right=[[1285.04761, 0.0, 335.23679], [0.0, 1254.65578, 261.96101], [0.0, 0.0, 1.0]],
    rvec=[0.03266, -0.00424, -0.00525],
    T=[-206.29240, 0.20595, 19.50555],
    unit="mm",
)
"""Seed 003 Tables 1–2 (SCENARIOS.md ``stereo-ferry``): focal lengths and principal points
of the 640×480 left/right cameras [px], the right camera's rotation vector ``om`` [rad]
and translation T [mm] relative to the left. No distortion is given. Baseline 207.2 mm."""
