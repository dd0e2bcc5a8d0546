"""The sea horizon in the image ↔ camera pitch and roll.

Implements ALGORITHMS.md §4.3 "With roll and pitch from the detected horizon line" and
the horizon dip of §4.2.

The visible sea horizon lies ``dip`` below the true horizontal (§4.2):

    R_e = R / (1 - k)                 effective earth radius, R = 6 371 000 m, k = refraction
    dip = arccos(R_e / (R_e + h))     = atan(sqrt(2 R_e h + h^2) / R_e)     [rad]

It is a small circle, not a great circle; as in §4.3 it is modelled as the image line in
which the plane with normal

    n = cos(dip) up + sin(dip) f

cuts the image, where ``up`` is the local vertical and ``f`` the horizontal unit vector
towards the azimuth of the optical axis. This plane holds the horizontal direction
perpendicular to ``f`` and the ray at depression ``dip`` towards ``f``: the line is exact
at the boresight azimuth, and off-axis by an angle alpha the true horizon is lower by about
``dip (1 - cos alpha)`` (the §4.3 pitfall). For a camera matrix K the line is
``l = K^-T n_c`` (``l · (u, v, 1) = 0``), with ``n_c = R_nc^T n`` in the camera frame.

:func:`horizon_line` draws the line of a camera with known attitude;
:func:`attitude_from_horizon` inverts it exactly: with ``n_c ∝ K^T l`` (sign chosen so
that ``n_c`` points up, ``n_y < 0`` in the y-down camera frame, which selects
|roll| < 90°) and ``n_b = R_bc n_c`` in the body FRD frame,

    roll  phi   = atan2(-n_by, -n_bz)
    pitch theta = atan2(m_z, n_bx) + pi/2 - dip,     m_z = -sqrt(n_by^2 + n_bz^2)

which solves ``R_y(theta) R_x(phi) n_b = (sin dip, 0, -cos dip)`` (heading-free level
frame). Sign conventions as in `seawatch.camera.attitude`: pitch positive nose-up, roll
positive right-side-down (the horizon's right end rises in the image).

Pixel coordinates given as points or (rho, theta) are *observed* pixels and are
undistorted with the camera's lens model first; a :class:`HorizonLine` is always in
ideal (undistorted) pixel coordinates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import FloatArray, as_float_array, positive
from seawatch.camera.attitude import R_BC
from seawatch.camera.pinhole import PinholeCamera
from seawatch.geometry.sea import horizon_dip
from seawatch.models.angles import wrap_angle

LineForm = Literal["auto", "points", "rho_theta"]


@dataclass(frozen=True, eq=False)
class HorizonLine:
    """An image line ``a u + b v + c = 0`` in ideal (undistorted) pixel coordinates.

    ``coefficients`` (..., 3) are normalised to ``a^2 + b^2 = 1`` with the normal angle
    ``theta = atan2(b, a)`` in [0, π), i.e. OpenCV's Hough convention
    ``u cos(theta) + v sin(theta) = rho`` with ``rho = -c`` [px]. Pixels: u right,
    v down, origin at the centre of the top-left pixel.
    """

    coefficients: FloatArray

    def __post_init__(self) -> None:
        l_ = as_float_array("coefficients", self.coefficients)
        if l_.ndim == 0 or l_.shape[-1] != 3:
            raise ValueError(f"coefficients: expected shape (..., 3), got {l_.shape}")
        norm = np.hypot(l_[..., 0], l_[..., 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            l_ = l_ / np.where(norm > 0.0, norm, np.nan)[..., None]
        flip = (l_[..., 1] < 0.0) | ((l_[..., 1] == 0.0) & (l_[..., 0] < 0.0))
        l_ = np.where(flip[..., None], -l_, l_)
        l_.setflags(write=False)
        object.__setattr__(self, "coefficients", l_)

    @classmethod
    def from_points(cls, p0: ArrayLike, p1: ArrayLike) -> HorizonLine:
        """The line through two ideal pixels p0, p1 (..., 2): ``l = (p0, 1) × (p1, 1)``."""
        a = as_float_array("p0", p0)
        b = as_float_array("p1", p1)
        if a.ndim == 0 or a.shape[-1] != 2 or b.ndim == 0 or b.shape[-1] != 2:
            raise ValueError(f"p0, p1: expected pixels of shape (..., 2), got {a.shape}, {b.shape}")
        one = np.ones((*np.broadcast_shapes(a.shape, b.shape)[:-1], 1))
        ha = np.concatenate([np.broadcast_to(a, (*one.shape[:-1], 2)), one], -1)
        hb = np.concatenate([np.broadcast_to(b, (*one.shape[:-1], 2)), one], -1)
        return cls(np.cross(ha, hb))

    @classmethod
    def from_rho_theta(cls, rho: ArrayLike, theta: ArrayLike) -> HorizonLine:
        """The line ``u cos(theta) + v sin(theta) = rho`` (OpenCV Hough; rho [px], theta [rad])."""
        r = as_float_array("rho", rho)
        t = as_float_array("theta", theta)
        r, t = np.broadcast_arrays(r, t)
        return cls(np.stack([np.cos(t), np.sin(t), -r], -1))

    @property
    def rho(self) -> FloatArray:
        """Signed distance of the line from the pixel origin [px] (Hough rho)."""
        return -self.coefficients[..., 2]

    @property
    def theta(self) -> FloatArray:
        """Angle of the line's normal from the u axis, in [0, π) [rad] (Hough theta)."""
        return np.arctan2(self.coefficients[..., 1], self.coefficients[..., 0])

    def v_at(self, u: ArrayLike) -> FloatArray:
        """Row v [px] of the line at column(s) u [px], broadcast against the line batch."""
        a, b, c = np.moveaxis(self.coefficients, -1, 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            return -(a * np.asarray(u, dtype=np.float64) + c) / b

    def endpoints(self, width: int) -> FloatArray:
        """Points (..., 2, 2) at the left and right image borders, u = 0 and u = width − 1.

        The (x0, y0), (x1, y1) of the horizon JSON (INTERFACES.md); rows are NaN/inf for
        a vertical line.
        """
        w = positive("width", width)
        u = np.array([0.0, w - 1.0])
        a, b, c = (x[..., None] for x in np.moveaxis(self.coefficients, -1, 0))
        with np.errstate(divide="ignore", invalid="ignore"):
            v = -(a * u + c) / b
        return np.stack([np.broadcast_to(u, v.shape), v], -1)


@dataclass(frozen=True, eq=False)
class HorizonAttitude:
    """Camera attitude recovered from the horizon (ALGORITHMS.md §4.3).

    Attributes:
        pitch: elevation of the optical axis, positive nose-up [rad], (...).
        roll: rotation about the optical axis, positive right-side-down [rad], (...).
        dip: horizon dip used for the camera height [rad] (§4.2).
    """

    pitch: FloatArray
    roll: FloatArray
    dip: float


def _height(camera: PinholeCamera, height: float | None) -> float:
    if height is None:
        if camera.height is None:
            raise ValueError("height: the camera has no height; pass the height above the sea [m]")
        return camera.height
    return positive("height", height, allow_zero=True)


def horizon_line(
    camera: PinholeCamera, height: float | None = None, refraction: float = 0.14
) -> HorizonLine:
    """Image line of the visible sea horizon for a camera of known attitude (§4.2, §4.3).

    ``l = K^-T R_nc^T (cos(dip) up + sin(dip) f)`` (module docstring), in ideal pixel
    coordinates; ``height`` [m] defaults to ``camera.height``, ``refraction`` is k. For a
    level camera this is the row ``v = cy + fy tan(dip)``. The inverse of
    :func:`attitude_from_horizon`. Raises ValueError for a camera looking straight up
    or down (no horizontal boresight azimuth).
    """
    h = _height(camera, height)
    dip = float(horizon_dip(h, refraction))
    r_nc = camera.R_nc
    axis = r_nc[:, 2]
    horiz = math.hypot(axis[0], axis[1])
    if horiz < 1e-12:
        raise ValueError("camera: optical axis is vertical; the horizon line is undefined")
    f = np.array([axis[0] / horiz, axis[1] / horiz, 0.0])
    up = np.array([0.0, 0.0, -1.0])
    n_c = r_nc.T @ (math.cos(dip) * up + math.sin(dip) * f)
    return HorizonLine(np.linalg.solve(camera.K.T, n_c))


def _line_from_input(camera: PinholeCamera, line: object, form: LineForm) -> FloatArray:
    """Homogeneous line (..., 3) in ideal pixel coordinates from the accepted inputs."""
    if isinstance(line, HorizonLine):
        return line.coefficients
    arr = as_float_array("line", line)
    if form == "auto":
        if arr.ndim >= 2 and arr.shape[-2:] == (2, 2):
            form = "points"
        elif arr.ndim >= 1 and arr.shape[-1] == 2:
            form = "rho_theta"
        else:
            raise ValueError(
                f"line: expected two points (..., 2, 2) or (rho, theta) (..., 2), got {arr.shape}"
            )
    if form == "points":
        if arr.ndim < 2 or arr.shape[-2:] != (2, 2):
            raise ValueError(f"line: expected two points of shape (..., 2, 2), got {arr.shape}")
        pts = arr
    elif form == "rho_theta":
        if arr.ndim < 1 or arr.shape[-1] != 2:
            raise ValueError(f"line: expected (rho, theta) of shape (..., 2), got {arr.shape}")
        if not camera.has_distortion:
            return HorizonLine.from_rho_theta(arr[..., 0], arr[..., 1]).coefficients
        # Two observed pixels on the line, half an image width either side of the point
        # nearest the image centre; undistorted below like any two points.
        rho, theta = arr[..., 0], arr[..., 1]
        normal = np.stack([np.cos(theta), np.sin(theta)], -1)
        direction = np.stack([-np.sin(theta), np.cos(theta)], -1)
        centre = np.array([camera.cx, camera.cy])
        foot = rho[..., None] * normal
        mid = foot + np.sum((centre - foot) * direction, -1)[..., None] * direction
        half = 0.5 * camera.image_size[0]
        pts = np.stack([mid - half * direction, mid + half * direction], -2)
    else:
        raise ValueError(f"form: expected 'auto', 'points' or 'rho_theta', got {form!r}")
    ideal = camera.undistort(pts)
    return HorizonLine.from_points(ideal[..., 0, :], ideal[..., 1, :]).coefficients


def attitude_from_horizon(
    camera: PinholeCamera,
    line: HorizonLine | ArrayLike,
    height: float | None = None,
    refraction: float = 0.14,
    *,
    form: LineForm = "auto",
) -> HorizonAttitude:
    """Camera pitch and roll from the horizon line in the image (ALGORITHMS.md §4.3).

    ``line`` is a :class:`HorizonLine` (ideal pixels), two observed pixels
    ``((u0, v0), (u1, v1))`` of shape (..., 2, 2), or an OpenCV Hough ``(rho, theta)``
    [px, rad] of shape (..., 2) in observed pixels; ``form`` forces the reading (a
    batch of exactly two (rho, theta) pairs has shape (2, 2) and needs
    ``form="rho_theta"``). ``height`` [m] (default ``camera.height``) and ``refraction``
    k give the dip (§4.2). Returns pitch (nose-up positive) and roll (right-side-down
    positive) in radians, |roll| < π/2, from the exact inversion in the module
    docstring; the camera's own attitude is not used, its intrinsics and distortion are.
    Degenerate or NaN lines give NaN.
    """
    h = _height(camera, height)
    dip = float(horizon_dip(h, refraction))
    l_ = _line_from_input(camera, line, form)
    n_c = l_ @ camera.K  # (K^T l) for each line, as rows
    norm = np.linalg.norm(n_c, axis=-1, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        n_c = n_c / np.where(norm > 0.0, norm, np.nan)
    n_c = np.where(n_c[..., 1:2] > 0.0, -n_c, n_c)
    n_b = n_c @ R_BC.T
    roll = np.arctan2(-n_b[..., 1], -n_b[..., 2])
    m_z = -np.hypot(n_b[..., 1], n_b[..., 2])
    pitch = wrap_angle(np.arctan2(m_z, n_b[..., 0]) + 0.5 * np.pi - dip)
    return HorizonAttitude(pitch=pitch, roll=roll, dip=dip)
