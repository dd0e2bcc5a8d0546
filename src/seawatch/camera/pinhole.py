"""Calibrated pinhole camera with OpenCV lens distortion: pixels ↔ rays ↔ (azimuth, elevation).

Implements ALGORITHMS.md §4.3 ("Pixel to (azimuth, depression) for a calibrated pinhole
camera"): undistort a pixel with the OpenCV model, form the camera ray
``r_c = K^-1 [u', v', 1]^T``, rotate it into the local level NED frame with
``R_nc = R_z(psi) R_y(theta) R_x(phi) R_bc`` (`seawatch.camera.attitude`) and read

    azimuth   = atan2(r_E, r_N)                         clockwise from North [rad]
    elevation = atan2(-r_D, sqrt(r_N^2 + r_E^2))        positive ABOVE the true horizontal [rad]

The §4.3 depression is ``delta = -elevation``.

Pixel convention (OpenCV, INTERFACES.md): u right, v down, origin at the centre of the
top-left pixel, so the centre of a W×H image is ((W − 1)/2, (H − 1)/2) and the image
spans u ∈ [−0.5, W − 0.5].

Lens distortion is OpenCV's model with coefficients ``(k1, k2, p1, p2[, k3[, k4, k5, k6
[, s1, s2, s3, s4[, tau_x, tau_y]]]])``. The forward model (ideal → observed pixel) is
``cv2.projectPoints``; the inverse starts from ``cv2.undistortPoints`` and is polished by
Newton steps on the forward model, so that pixel → angle → pixel round trips hold to
~1e-12 px; pixels where the model cannot be inverted (outside its monotonic domain)
give NaN.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Literal

import cv2
import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import FloatArray, as_float_array, in_range, matrix, positive, vector
from seawatch.camera.attitude import rotation_nc

Frame = Literal["world", "platform"]
RayFrame = Literal["camera", "world", "platform"]

_DIST_SIZES = (4, 5, 8, 12, 14)
_TWO_PI = 2.0 * math.pi
_MAX_NEWTON_STEPS = 8
_NEWTON_TOL_PX = 1e-6


def _pixels(name: str, uv: ArrayLike) -> FloatArray:
    arr = as_float_array(name, uv)
    if arr.ndim == 0 or arr.shape[-1] != 2:
        raise ValueError(f"{name}: expected pixel coordinates of shape (..., 2), got {arr.shape}")
    return arr


def _wrap_pi(a: FloatArray) -> FloatArray:
    """Angles to (−π, π]."""
    return np.pi - np.mod(np.pi - a, _TWO_PI)


def _wrap_2pi(a: FloatArray) -> FloatArray:
    """Angles to [0, 2π)."""
    w = np.mod(a, _TWO_PI)
    return np.where(w >= _TWO_PI, 0.0, w)


@dataclass(frozen=True)
class PinholeCamera:
    """A calibrated pinhole camera with OpenCV distortion and a mounting attitude.

    ALGORITHMS.md §4.3. Intrinsics K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (no skew).

    Attributes:
        fx, fy: focal lengths [px], > 0.
        cx, cy: principal point [px] (origin at the centre of the top-left pixel).
        image_size: (width, height) [px].
        dist: OpenCV distortion coefficients (k1, k2, p1, p2[, k3, ...]); stored with
            5, 8, 12 or 14 entries (4 are padded with k3 = 0, an empty tuple means no
            distortion and is stored as five zeros).
        heading: azimuth of the optical axis, clockwise from North [rad].
        pitch: elevation of the optical axis, positive nose-up [rad] (a camera looking
            down at the sea has pitch < 0).
        roll: rotation about the optical axis, positive right-side-down [rad].
        height: height of the optical centre above the sea surface [m], or None when
            unknown.
        lat, lon: geodetic (WGS-84) position of the camera [degrees] — the one place in
            the class that uses degrees, as geodetic coordinates conventionally do —
            or None; both or neither.
        position: local position (x_north, y_east) [m] of the camera in the scene's
            tangent plane.

    Angles are radians. Use :meth:`from_fov` for a camera known only by its data sheet
    and :meth:`from_matrix` for an OpenCV calibration result.
    """

    fx: float
    fy: float
    cx: float
    cy: float
    image_size: tuple[int, int]
    dist: tuple[float, ...] = ()
    heading: float = 0.0
    pitch: float = 0.0
    roll: float = 0.0
    height: float | None = None
    lat: float | None = None
    lon: float | None = None
    position: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "fx", positive("fx", self.fx))
        set_(self, "fy", positive("fy", self.fy))
        for name in ("cx", "cy", "heading", "pitch", "roll"):
            set_(
                self,
                name,
                in_range(name, getattr(self, name), -np.inf, np.inf, lo_open=True, hi_open=True),
            )
        size = vector("image_size", self.image_size, 2)
        if np.any(size < 1) or np.any(size != np.round(size)):
            raise ValueError(
                f"image_size: expected two positive integers (width, height) [px], "
                f"got {self.image_size!r}"
            )
        set_(self, "image_size", (int(size[0]), int(size[1])))
        d = np.atleast_1d(as_float_array("dist", self.dist, ndim=(0, 1)))
        if d.size == 0:
            d = np.zeros(5)
        if d.size not in _DIST_SIZES:
            raise ValueError(
                f"dist: expected 4, 5, 8, 12 or 14 OpenCV distortion coefficients, got {d.size}"
            )
        if not np.all(np.isfinite(d)):
            raise ValueError("dist: contains NaN or inf")
        if d.size == 4:
            d = np.append(d, 0.0)
        set_(self, "dist", tuple(float(c) for c in d))
        if self.height is not None:
            set_(self, "height", positive("height", self.height))
        if (self.lat is None) != (self.lon is None):
            raise ValueError("lat, lon: give both the latitude and the longitude, or neither")
        if self.lat is not None:
            set_(self, "lat", in_range("lat", self.lat, -90.0, 90.0))
            set_(self, "lon", in_range("lon", self.lon, -180.0, 180.0))
        pos = vector("position", self.position, 2)
        set_(self, "position", (float(pos[0]), float(pos[1])))

    # ------------------------------------------------------------ constructors
    @classmethod
    def from_fov(
        cls,
        image_width: int,
        image_height: int,
        hfov_deg: float,
        /,
        *,
        vfov_deg: float | None = None,
        **kwargs: Any,
    ) -> PinholeCamera:
        """A distortion-free camera known by its image size and horizontal field of view.

        ``fx = (W/2) / tan(hfov/2)``; ``fy = fx`` (square pixels) unless ``vfov_deg`` is
        given (then ``fy = (H/2) / tan(vfov/2)``); principal point at the image centre
        ((W − 1)/2, (H − 1)/2). The fields of view span the whole image, edge to edge
        [degrees, in (0, 180)]. Seed 000's camera is ``from_fov(1920, 1080, 70.0)``.

        The image size is positional only, so that the keyword ``height`` keeps its
        meaning everywhere in this class: camera height above the sea [m]. Other
        keywords (``heading``, ``pitch``, ``roll`` [rad], ``height`` [m], ``lat``,
        ``lon`` [deg], ``position`` [m], ``dist``) go to the constructor.
        """
        w = positive("image_width", image_width)
        h = positive("image_height", image_height)
        hfov = in_range("hfov_deg", hfov_deg, 0.0, 180.0, lo_open=True, hi_open=True)
        fx = 0.5 * w / math.tan(math.radians(hfov) / 2.0)
        if vfov_deg is None:
            fy = fx
        else:
            vfov = in_range("vfov_deg", vfov_deg, 0.0, 180.0, lo_open=True, hi_open=True)
            fy = 0.5 * h / math.tan(math.radians(vfov) / 2.0)
        return cls(
            fx=fx, fy=fy, cx=(w - 1.0) / 2.0, cy=(h - 1.0) / 2.0, image_size=(w, h), **kwargs
        )

    @classmethod
    def from_matrix(
        cls, K: ArrayLike, dist: ArrayLike, image_size: tuple[int, int], **kwargs: Any
    ) -> PinholeCamera:
        """A camera from an OpenCV camera matrix K (3×3) and distortion vector.

        K must be ``[[fx, 0, cx], [0, fy, cy], [0, 0, 1]]``: a skew K[0, 1] ≠ 0 is not
        supported (OpenCV's calibration never estimates one). ``dist`` as in the class
        (any of OpenCV's shapes: (n,), (n, 1), (1, n)); ``image_size`` = (width, height)
        [px]. Further keywords (attitude, height, position) go to the constructor.
        """
        k = matrix("K", K, (3, 3))
        scale = max(abs(k[0, 0]), abs(k[1, 1]), 1.0)
        if abs(k[0, 1]) > 1e-9 * scale:
            raise ValueError(f"K: skew K[0, 1] = {k[0, 1]!r} is not supported (expected 0)")
        if abs(k[1, 0]) > 1e-9 * scale or np.any(np.abs(k[2] - [0.0, 0.0, 1.0]) > 1e-12):
            raise ValueError(f"K: expected [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], got {k.tolist()}")
        d = as_float_array("dist", dist)
        if d.ndim > 2 or (d.ndim == 2 and 1 not in d.shape):
            raise ValueError(f"dist: expected a vector of coefficients, got shape {d.shape}")
        return cls(
            fx=k[0, 0],
            fy=k[1, 1],
            cx=k[0, 2],
            cy=k[1, 2],
            image_size=image_size,
            dist=tuple(d.ravel()),
            **kwargs,
        )

    def resized(self, image_size: tuple[int, int]) -> PinholeCamera:
        """The same camera and view at another resolution (a stream scaled to
        ``image_size`` = (width, height) [px]): with ``s_x = width / W`` and
        ``s_y = height / H``, ``fx' = s_x fx``, ``cx' = s_x (cx + ½) − ½`` (pixel centres
        at integers: the edge of the image stays the edge) and likewise in y; the lens
        distortion acts on normalised coordinates and is unchanged, as are the attitude,
        height and position. A ray seen at pixel ``p`` is seen at ``s (p + ½) − ½``."""
        size = vector("image_size", image_size, 2)
        if np.any(size < 1) or np.any(size != np.round(size)):
            raise ValueError(
                f"image_size: expected two positive integers (width, height) [px], "
                f"got {image_size!r}"
            )
        sx = float(size[0]) / self.image_size[0]
        sy = float(size[1]) / self.image_size[1]
        return dataclasses.replace(
            self,
            fx=self.fx * sx,
            fy=self.fy * sy,
            cx=(self.cx + 0.5) * sx - 0.5,
            cy=(self.cy + 0.5) * sy - 0.5,
            image_size=(int(size[0]), int(size[1])),
        )

    def zoomed(self, scale: float, centre: tuple[float, float] | None = None) -> PinholeCamera:
        """The camera whose image is this one's magnified by ``scale`` about ``centre``
        (x, y) [px] (default: the principal point): a zoom lens's focal length times
        ``scale``, ``fx' = s fx``, ``fy' = s fy``, ``cx' = c_x + s (cx − c_x)`` and
        likewise in y, so that the ray seen at pixel ``p`` is seen at
        ``c + s (p − c)``; the distortion, on normalised coordinates, is unchanged (a
        zoom lens whose distortion changes with its focal length needs a calibration
        per focal length), as are the attitude, height and position.
        (:class:`~seawatch.vision.motion.CameraMotion` measures ``scale`` about the
        frame's centre.)"""
        s = positive("scale", scale)
        cx, cy = (self.cx, self.cy) if centre is None else vector("centre", centre, 2)
        return dataclasses.replace(
            self,
            fx=self.fx * s,
            fy=self.fy * s,
            cx=float(cx + s * (self.cx - cx)),
            cy=float(cy + s * (self.cy - cy)),
        )

    def with_attitude(
        self, heading: float | None = None, pitch: float | None = None, roll: float | None = None
    ) -> PinholeCamera:
        """The same camera with a new mounting attitude [rad]; None keeps the current angle."""
        changes = {
            name: value
            for name, value in (("heading", heading), ("pitch", pitch), ("roll", roll))
            if value is not None
        }
        return dataclasses.replace(self, **changes)

    # ------------------------------------------------------------ properties
    @cached_property
    def K(self) -> FloatArray:
        """Camera matrix K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] [px], read-only."""
        k = np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])
        k.setflags(write=False)
        return k

    @cached_property
    def dist_coeffs(self) -> FloatArray:
        """Distortion coefficients as a read-only float array (for OpenCV calls)."""
        d = np.array(self.dist, dtype=np.float64)
        d.setflags(write=False)
        return d

    @property
    def has_distortion(self) -> bool:
        """True if any distortion coefficient is non-zero."""
        return any(c != 0.0 for c in self.dist)

    @cached_property
    def R_nc(self) -> FloatArray:
        """Camera → world NED rotation R_z(heading) R_y(pitch) R_x(roll) R_bc (§4.3), read-only."""
        r = rotation_nc(self.heading, self.pitch, self.roll)
        r.setflags(write=False)
        return r

    @cached_property
    def R_pc(self) -> FloatArray:
        """Camera → platform rotation R_y(pitch) R_x(roll) R_bc (heading removed), read-only.

        The platform frame is the local level frame turned to the camera heading: x along
        the horizontal projection of the optical axis, y to its right, z down.
        """
        r = rotation_nc(0.0, self.pitch, self.roll)
        r.setflags(write=False)
        return r

    @property
    def hfov(self) -> float:
        """Horizontal field of view 2 atan(W / (2 fx)) [rad] (distortion ignored)."""
        return 2.0 * math.atan(0.5 * self.image_size[0] / self.fx)

    @property
    def vfov(self) -> float:
        """Vertical field of view 2 atan(H / (2 fy)) [rad] (distortion ignored)."""
        return 2.0 * math.atan(0.5 * self.image_size[1] / self.fy)

    def _rotation(self, frame: str) -> FloatArray:
        if frame == "world":
            return self.R_nc
        if frame == "platform":
            return self.R_pc
        if frame == "camera":
            return np.eye(3)
        raise ValueError(f"frame: expected 'camera', 'world' or 'platform', got {frame!r}")

    # ------------------------------------------------------------ distortion
    def _project_normalized(
        self, xy: FloatArray, jacobian: bool = False
    ) -> tuple[FloatArray, FloatArray | None]:
        """Ideal normalised coordinates (N, 2) → observed pixels (N, 2) [and d(u,v)/d(x,y)].

        The OpenCV forward model (``cv2.projectPoints`` of the point (x, y, 1) with an
        identity pose). The Jacobian (N, 2, 2) is OpenCV's derivative with respect to the
        translation's x and y, which equals d(u, v)/d(x, y) at depth 1.
        """
        n = xy.shape[0]
        if not self.has_distortion:
            uv = np.empty_like(xy)
            uv[:, 0] = self.fx * xy[:, 0] + self.cx
            uv[:, 1] = self.fy * xy[:, 1] + self.cy
            jac = np.broadcast_to(np.diag([self.fx, self.fy]), (n, 2, 2)) if jacobian else None
            return uv, jac
        if n == 0:
            return np.empty((0, 2)), (np.empty((0, 2, 2)) if jacobian else None)
        pts = np.ascontiguousarray(np.column_stack([xy, np.ones(n)]))
        zero = np.zeros(3)
        uv, jac = cv2.projectPoints(
            pts, zero, zero, np.asarray(self.K), np.asarray(self.dist_coeffs)
        )
        uv = uv.reshape(n, 2)
        if jacobian:
            return uv, jac[:, 3:5].reshape(n, 2, 2)
        return uv, None

    def _normalized(self, uv: FloatArray) -> FloatArray:
        """Observed pixels (..., 2) → undistorted normalised coordinates (x, y) (..., 2).

        ALGORITHMS.md §4.3 step 1: ``cv2.undistortPoints`` (OpenCV's default fixed-point
        iterations, good to ~1e-5) as the start, then Newton steps on the forward model
        ``cv2.projectPoints`` and its Jacobian until the residual before the last step is
        below 1e-6 px (at most 8 steps). NaN where the input is not finite, the inversion
        does not converge, or it meets a fold of the model (Jacobian determinant <= 0).
        """
        out = np.full(uv.shape, np.nan)
        ok = np.all(np.isfinite(uv), axis=-1)
        if not np.any(ok):
            return out
        pts = uv[ok]
        target = pts
        if not self.has_distortion:
            xy = np.column_stack([(pts[:, 0] - self.cx) / self.fx, (pts[:, 1] - self.cy) / self.fy])
            out[ok] = xy
            return out
        xy = cv2.undistortPoints(
            np.ascontiguousarray(pts.reshape(-1, 1, 2)),
            np.asarray(self.K),
            np.asarray(self.dist_coeffs),
        ).reshape(-1, 2)
        valid = np.all(np.isfinite(xy), axis=-1)
        resid = np.full(xy.shape[0], np.inf)
        for _ in range(_MAX_NEWTON_STEPS):
            proj, jac = self._project_normalized(np.where(valid[:, None], xy, 0.0), jacobian=True)
            res = proj - target
            resid = np.max(np.abs(res), axis=-1)
            det = jac[:, 0, 0] * jac[:, 1, 1] - jac[:, 0, 1] * jac[:, 1, 0]
            valid &= (det > 0.0) & np.isfinite(resid)
            det_s = np.where(valid, det, 1.0)
            dx = (jac[:, 1, 1] * res[:, 0] - jac[:, 0, 1] * res[:, 1]) / det_s
            dy = (-jac[:, 1, 0] * res[:, 0] + jac[:, 0, 0] * res[:, 1]) / det_s
            xy = np.where(valid[:, None], xy - np.column_stack([dx, dy]), np.nan)
            # Newton converges quadratically: a residual r [px] before this step leaves
            # about r^2 / (2 f) after it, so r <= 1e-6 px means machine precision now.
            if np.all(resid[valid] <= _NEWTON_TOL_PX):
                break
        xy[~valid | ~(resid <= _NEWTON_TOL_PX)] = np.nan
        out[ok] = xy
        return out

    def undistort(self, uv: ArrayLike) -> FloatArray:
        """Observed (distorted) pixels → ideal pinhole pixels, (..., 2) → (..., 2) [px].

        ALGORITHMS.md §4.3 step 1, ``cv2.undistortPoints(p, K, dist, P=K)`` refined by
        Newton steps (see the module docstring). NaN in, NaN out.
        """
        p = _pixels("uv", uv)
        xy = self._normalized(p)
        return np.stack([self.fx * xy[..., 0] + self.cx, self.fy * xy[..., 1] + self.cy], -1)

    def distort(self, uv_ideal: ArrayLike) -> FloatArray:
        """Ideal pinhole pixels → observed (distorted) pixels, (..., 2) → (..., 2) [px].

        The OpenCV forward model (``cv2.projectPoints`` of the ray through the ideal
        pixel); the inverse of :meth:`undistort`. NaN in, NaN out.
        """
        p = _pixels("uv_ideal", uv_ideal)
        xy = np.stack([(p[..., 0] - self.cx) / self.fx, (p[..., 1] - self.cy) / self.fy], -1)
        return self._distort_normalized(xy)

    def _distort_normalized(self, xy: FloatArray) -> FloatArray:
        out = np.full(xy.shape, np.nan)
        ok = np.all(np.isfinite(xy), axis=-1)
        if np.any(ok):
            out[ok] = self._project_normalized(xy[ok])[0]
        return out

    # ------------------------------------------------------------ pixels → rays/angles
    def pixel_to_ray(self, uv: ArrayLike, frame: RayFrame = "camera") -> FloatArray:
        """Unit ray through each pixel, (..., 2) → (..., 3).

        ALGORITHMS.md §4.3 step 2: ``r_c = K^-1 [u', v', 1]^T / ||.||`` with (u', v') the
        undistorted pixel; ``frame="world"`` rotates it to NED (``r_n = R_nc r_c``),
        ``frame="platform"`` to the heading-free level frame (:attr:`R_pc`). NaN pixels
        give NaN rays.
        """
        p = _pixels("uv", uv)
        rot = self._rotation(frame)
        xy = self._normalized(p)
        r = np.concatenate([xy, np.ones((*xy.shape[:-1], 1))], axis=-1)
        r = r / np.linalg.norm(r, axis=-1, keepdims=True)
        if frame != "camera":
            r = r @ rot.T
        return r

    def pixel_to_angles(
        self, uv: ArrayLike, frame: Frame = "world"
    ) -> tuple[FloatArray, FloatArray]:
        """(azimuth, elevation) [rad] of each pixel, (..., 2) → two (...,) arrays.

        ALGORITHMS.md §4.3: ``az = atan2(r_E, r_N)``, ``elevation = atan2(-r_D,
        sqrt(r_N^2 + r_E^2))`` — positive above the true horizontal (the §4.3 depression
        is −elevation). ``frame="world"``: azimuth clockwise from North in [0, 2π);
        ``frame="platform"``: azimuth clockwise from the camera heading in (−π, π]
        (world azimuth = heading + platform azimuth). NaN pixels → NaN angles.
        """
        if frame not in ("world", "platform"):
            raise ValueError(f"frame: expected 'world' or 'platform', got {frame!r}")
        r = self.pixel_to_ray(uv, frame=frame)
        az = np.arctan2(r[..., 1], r[..., 0])
        el = np.arctan2(-r[..., 2], np.hypot(r[..., 0], r[..., 1]))
        az = _wrap_2pi(az) if frame == "world" else _wrap_pi(az)
        return az, el

    # ------------------------------------------------------------ rays/angles → pixels
    def ray_to_pixel(self, ray: ArrayLike, frame: RayFrame = "world") -> FloatArray:
        """Observed pixel of a direction, (..., 3) → (..., 2) [px].

        Inverse of :meth:`pixel_to_ray`: rotate into the camera frame
        (``r_c = R_nc^T r_n`` for ``frame="world"``), project ``(x, y) = (r_x, r_y) / r_z``
        and apply the distortion. Rays with ``r_z <= 0`` (at or behind the camera plane)
        and NaN rays give NaN. Pixels outside the image are returned as they are.
        """
        r = as_float_array("ray", ray)
        if r.ndim == 0 or r.shape[-1] != 3:
            raise ValueError(f"ray: expected directions of shape (..., 3), got {r.shape}")
        rot = self._rotation(frame)
        rc = r @ rot if frame != "camera" else r
        z = rc[..., 2]
        front = z > 0.0
        z_s = np.where(front, z, 1.0)
        xy = np.stack([rc[..., 0] / z_s, rc[..., 1] / z_s], -1)
        xy[~front] = np.nan
        return self._distort_normalized(xy)

    def angles_to_pixel(
        self, azimuth: ArrayLike, elevation: ArrayLike, frame: Frame = "world"
    ) -> FloatArray:
        """Observed pixel of (azimuth, elevation) [rad], broadcast shape (...) → (..., 2) [px].

        Inverse of :meth:`pixel_to_angles` (same ``frame`` meanings; elevation positive
        above the horizontal): ``r_n = (cos el cos az, cos el sin az, -sin el)``, then
        :meth:`ray_to_pixel` (distortion applied). Directions behind the camera → NaN.
        """
        if frame not in ("world", "platform"):
            raise ValueError(f"frame: expected 'world' or 'platform', got {frame!r}")
        az = as_float_array("azimuth", azimuth)
        el = as_float_array("elevation", elevation)
        try:
            az, el = np.broadcast_arrays(az, el)
        except ValueError:
            raise ValueError(
                f"azimuth, elevation: shapes {az.shape} and {el.shape} do not broadcast"
            ) from None
        ce = np.cos(el)
        r = np.stack([ce * np.cos(az), ce * np.sin(az), -np.sin(el)], -1)
        return self.ray_to_pixel(r, frame=frame)

    # ------------------------------------------------------------ uncertainty
    def angle_jacobian(self, uv: ArrayLike) -> FloatArray:
        """d(azimuth, elevation)/d(u, v) at observed pixels, (..., 2) → (..., 2, 2) [rad/px].

        Rows (azimuth, elevation), columns (u, v); the same in the world and platform
        frames (they differ by a constant azimuth). Chain rule through §4.3:
        ``d(x, y)/d(u, v) = (d(u, v)/d(x, y))^-1`` (inverse of the distortion Jacobian),
        ``d r_n / d(x, y) = R_nc[:, :2]`` for the unnormalised ray ``r = R_nc (x, y, 1)``,
        and with ``rho = sqrt(r_N^2 + r_E^2)``:
        ``d az/d r = (-r_E, r_N, 0) / rho^2``,
        ``d el/d r = (r_D r_N / rho, r_D r_E / rho, -rho) / |r|^2``.
        NaN pixels (and rays straight up or down, where azimuth is undefined) give NaN.
        """
        p = _pixels("uv", uv)
        xy = self._normalized(p)
        shape = p.shape[:-1]
        flat = xy.reshape(-1, 2)
        ok = np.all(np.isfinite(flat), axis=-1)
        j_dist = np.full((flat.shape[0], 2, 2), np.nan)
        if np.any(ok):
            j_dist[ok] = self._project_normalized(flat[ok], jacobian=True)[1]
        j_dist = j_dist.reshape((*shape, 2, 2))
        d_xy_d_uv = np.linalg.inv(np.where(np.isfinite(j_dist), j_dist, np.eye(2)))
        d_xy_d_uv = np.where(np.isfinite(j_dist), d_xy_d_uv, np.nan)
        rot = self.R_nc
        r = np.concatenate([xy, np.ones((*shape, 1))], axis=-1) @ rot.T
        rn, re, rd = r[..., 0], r[..., 1], r[..., 2]
        rho2 = rn * rn + re * re
        rho = np.sqrt(rho2)
        norm2 = rho2 + rd * rd
        with np.errstate(divide="ignore", invalid="ignore"):
            d_az = np.stack([-re / rho2, rn / rho2, np.zeros_like(rn)], -1)
            d_el = np.stack([rd * rn / rho, rd * re / rho, -rho], -1) / norm2[..., None]
        d_angles_d_r = np.stack([d_az, d_el], -2)  # (..., 2, 3)
        return d_angles_d_r @ rot[:, :2] @ d_xy_d_uv

    def angle_covariance(self, uv: ArrayLike, sigma_px: ArrayLike) -> FloatArray:
        """Covariance of (azimuth, elevation) [rad²] from isotropic pixel noise, (..., 2, 2).

        First-order propagation ``C = sigma_px^2 J J^T`` with ``J`` = :meth:`angle_jacobian`.
        ``sigma_px`` [px] ≥ 0 is a scalar or an array that broadcasts against the pixel
        batch shape. For a distortion-free camera at the principal point of a level
        camera this is diag((sigma/fx)^2, (sigma/fy)^2); pixel quantisation alone is
        ``sigma_px = 1/sqrt(12)`` (§4.3 pitfalls).
        """
        jac = self.angle_jacobian(uv)
        s = as_float_array("sigma_px", sigma_px)
        if not np.all(np.isfinite(s)) or np.any(s < 0.0):
            raise ValueError("sigma_px: expected finite pixel standard deviations >= 0 [px]")
        try:
            s2 = np.broadcast_to(s * s, jac.shape[:-2])
        except ValueError:
            raise ValueError(
                f"sigma_px: shape {s.shape} does not broadcast against the pixels' batch "
                f"shape {jac.shape[:-2]}"
            ) from None
        return s2[..., None, None] * (jac @ np.swapaxes(jac, -1, -2))
