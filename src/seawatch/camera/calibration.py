"""Chessboard calibration of one camera or a stereo pair, built on OpenCV.

Zhang's method as implemented by OpenCV: ``cv2.findChessboardCorners`` (adaptive
threshold, normalised image) refined by ``cv2.cornerSubPix``, then ``cv2.calibrateCamera``
(pinhole + distortion k1, k2, p1, p2, k3) and, for a pair, ``cv2.stereoCalibrate`` with
the intrinsics of the single-camera calibrations held fixed. Seed 003 calibrated its
rig with the MATLAB toolbox (same model); its tables are
:data:`seawatch.camera.stereo.SEED003_CALIBRATION`.

Images where the pattern is not found are listed in ``images_rejected`` with the
reason (not an error), as are unreadable image files and images of a different size
than the first usable one. Too few usable images (< ``min_images``) raise ValueError
naming ``images`` and listing the rejections.

Units: the square size and hence T and the board poses are in metres (any unit works,
the results carry it); pixels with the OpenCV convention (origin at the centre of the
top-left pixel, u right, v down).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import cv2
import numpy as np
from numpy.typing import NDArray

from seawatch._validation import FloatArray, positive
from seawatch.camera.stereo import StereoRig

if TYPE_CHECKING:
    from seawatch.camera.pinhole import PinholeCamera

__all__ = [
    "CameraCalibration",
    "StereoCalibration",
    "board_points",
    "calibrate_camera",
    "calibrate_stereo",
    "find_corners",
]

ImageLike = str | Path | NDArray[Any]
Progress = Callable[[int, int], None]

_SUBPIX_CRITERIA = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 30, 1e-3)
_FIND_FLAGS = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
_CALIB_CRITERIA = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 100, 1e-12)


# ----------------------------------------------------------------------------- results
@dataclass(frozen=True, eq=False)
class CameraCalibration:
    """Result of :func:`calibrate_camera`.

    Attributes:
        K: (3, 3) camera matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] [px].
        dist: (5,) OpenCV distortion coefficients (k1, k2, p1, p2, k3).
        image_size: (width, height) [px].
        rms_px: overall RMS reprojection error [px] (OpenCV's ``calibrateCamera`` value:
            sqrt of the mean squared corner error over all corners).
        per_image_rms_px: (M,) RMS reprojection error of each used image [px].
        images_used: names of the M images used (paths as given, or ``<image i>``).
        images_rejected: (name, reason) of the images left out.
        pattern: inner corners (columns, rows) of the chessboard.
        square: side of a square [m].
        object_points: (P, 3) board corners in the board frame [m] (z = 0).
        image_points: M arrays (P, 2) of the detected sub-pixel corners [px].
        rvecs, tvecs: (M, 3) board poses (rotation vector [rad], translation [m]) in the
            camera frame.
    """

    K: FloatArray
    dist: FloatArray
    image_size: tuple[int, int]
    rms_px: float
    per_image_rms_px: FloatArray
    images_used: tuple[str, ...]
    images_rejected: tuple[tuple[str, str], ...]
    pattern: tuple[int, int]
    square: float
    object_points: FloatArray
    image_points: tuple[FloatArray, ...]
    rvecs: FloatArray
    tvecs: FloatArray

    @property
    def fx(self) -> float:
        """Focal length along u [px]."""
        return float(self.K[0, 0])

    @property
    def fy(self) -> float:
        """Focal length along v [px]."""
        return float(self.K[1, 1])

    @property
    def cx(self) -> float:
        """Principal point u [px]."""
        return float(self.K[0, 2])

    @property
    def cy(self) -> float:
        """Principal point v [px]."""
        return float(self.K[1, 2])

    def to_camera(self, **kwargs: Any) -> PinholeCamera:
        """A :class:`seawatch.camera.PinholeCamera` with these intrinsics.

        Keywords (heading, pitch, roll [rad], height [m], lat, lon, position) go to
        ``PinholeCamera.from_matrix``.
        """
        from seawatch.camera.pinhole import PinholeCamera

        return PinholeCamera.from_matrix(self.K, self.dist, self.image_size, **kwargs)

    def to_dict(self) -> dict[str, Any]:
        """The Calibration JSON of INTERFACES.md (``seawatch calibrate --json``), as a dict.

        Keys: ``rms_px``, ``fx``, ``fy``, ``cx``, ``cy``, ``dist`` (k1, k2, p1, p2, k3),
        ``image_size`` [w, h], ``images_used``, ``images_rejected`` (a list of
        ``{"image", "reason"}``), plus ``per_image_rms_px``, ``pattern``, ``square_m``.
        The command line adds ``output``.
        """
        return {
            "rms_px": float(self.rms_px),
            "fx": self.fx,
            "fy": self.fy,
            "cx": self.cx,
            "cy": self.cy,
            "dist": [float(c) for c in self.dist],
            "image_size": [int(self.image_size[0]), int(self.image_size[1])],
            "images_used": list(self.images_used),
            "images_rejected": [{"image": n, "reason": r} for n, r in self.images_rejected],
            "per_image_rms_px": [float(e) for e in self.per_image_rms_px],
            "pattern": [int(self.pattern[0]), int(self.pattern[1])],
            "square_m": float(self.square),
        }

    def to_json(self, indent: int | None = 2) -> str:
        """:meth:`to_dict` serialised as a JSON string."""
        return json.dumps(self.to_dict(), indent=indent)


@dataclass(frozen=True, eq=False)
class StereoCalibration:
    """Result of :func:`calibrate_stereo`.

    Attributes:
        left, right: the single-camera calibrations (each on all its own images).
        R: (3, 3) rotation and T: (3,) translation [m] of the right camera relative to
            the left: ``X_R = R X_L + T`` (OpenCV ``stereoCalibrate``).
        E, F: essential and fundamental matrices (3, 3).
        baseline_m: |T| [m].
        stereo_rms_px: RMS reprojection error of ``stereoCalibrate`` over both views [px].
        per_pair_rms_px: (M, 2) RMS error of each used pair, left and right [px].
        pairs_used: (left, right) names of the M pairs used (pattern found in both).
        pairs_rejected: ((left, right), reason) of the pairs left out.
        image_points_left, image_points_right: M arrays (P, 2) of the pairs' corners [px].
    """

    left: CameraCalibration
    right: CameraCalibration
    R: FloatArray
    T: FloatArray
    E: FloatArray
    F: FloatArray
    baseline_m: float
    stereo_rms_px: float
    per_pair_rms_px: FloatArray
    pairs_used: tuple[tuple[str, str], ...]
    pairs_rejected: tuple[tuple[tuple[str, str], str], ...]
    image_points_left: tuple[FloatArray, ...]
    image_points_right: tuple[FloatArray, ...]

    def rig(self) -> StereoRig:
        """The calibrated pair as a :class:`seawatch.camera.stereo.StereoRig` (unit m)."""
        return StereoRig(
            K_left=self.left.K,
            K_right=self.right.K,
            R=self.R,
            T=self.T,
            dist_left=self.left.dist,
            dist_right=self.right.dist,
            unit="m",
        )

    def to_dict(self) -> dict[str, Any]:
        """Calibration JSON of INTERFACES.md for ``--stereo``, as a dict.

        The left camera's keys (see :meth:`CameraCalibration.to_dict`) plus
        ``baseline_m``, ``R`` (3×3 nested list), ``T`` [m], ``stereo_rms_px``,
        ``per_pair_rms_px``, ``pairs_used``, ``pairs_rejected`` and ``right`` (the right
        camera's own keys).
        """
        doc = self.left.to_dict()
        doc.update(
            {
                "baseline_m": float(self.baseline_m),
                "R": self.R.tolist(),
                "T": [float(t) for t in self.T],
                "stereo_rms_px": float(self.stereo_rms_px),
                "per_pair_rms_px": self.per_pair_rms_px.tolist(),
                "pairs_used": [list(p) for p in self.pairs_used],
                "pairs_rejected": [
                    {"left": p[0], "right": p[1], "reason": r} for p, r in self.pairs_rejected
                ],
                "right": self.right.to_dict(),
            }
        )
        return doc

    def to_json(self, indent: int | None = 2) -> str:
        """:meth:`to_dict` serialised as a JSON string."""
        return json.dumps(self.to_dict(), indent=indent)


# ----------------------------------------------------------------------------- helpers
def _pattern(pattern: Sequence[int]) -> tuple[int, int]:
    try:
        cols, rows = (int(p) for p in pattern)
    except (TypeError, ValueError):
        raise ValueError(
            f"pattern: expected (columns, rows) of inner corners, got {pattern!r}"
        ) from None
    if cols < 2 or rows < 2 or (cols, rows) != tuple(pattern):
        raise ValueError(f"pattern: expected two integers >= 2 (inner corners), got {pattern!r}")
    return cols, rows


def board_points(pattern: Sequence[int], square: float) -> FloatArray:
    """Chessboard inner corners in the board frame (P, 3) [m], in OpenCV's detection order.

    Row by row: point ``j * columns + i`` is at ``(i * square, j * square, 0)``.
    """
    cols, rows = _pattern(pattern)
    s = positive("square", square)
    grid = np.mgrid[0:cols, 0:rows].T.reshape(-1, 2) * s
    return np.hstack([grid, np.zeros((cols * rows, 1))])


def _name(image: ImageLike, index: int) -> str:
    return str(image) if isinstance(image, str | Path) else f"<image {index}>"


def _read_gray(image: ImageLike) -> tuple[NDArray[np.uint8] | None, str]:
    """(grayscale image or None, reason when None)."""
    if isinstance(image, str | Path):
        p = Path(image)
        if not p.is_file():
            return None, "file not found"
        img = cv2.imread(str(p), cv2.IMREAD_GRAYSCALE)
        if img is None:
            return None, "unreadable image file (OpenCV cannot decode it)"
        return img, ""
    arr = np.asarray(image)
    if arr.ndim == 3 and arr.shape[2] in (3, 4):
        code = cv2.COLOR_BGR2GRAY if arr.shape[2] == 3 else cv2.COLOR_BGRA2GRAY
        arr = cv2.cvtColor(arr, code)
    if arr.ndim != 2 or arr.size == 0:
        return None, f"not an image array (shape {arr.shape})"
    if arr.dtype != np.uint8:
        arr = cv2.normalize(arr, None, 0, 255, cv2.NORM_MINMAX).astype(np.uint8)
    return arr, ""


def find_corners(image: ImageLike, pattern: Sequence[int] = (9, 6)) -> FloatArray | None:
    """Sub-pixel chessboard corners (P, 2) [px] of one image, or None if not found.

    ``cv2.findChessboardCorners`` (adaptive threshold, normalised image) then
    ``cv2.cornerSubPix`` (11×11 window). Raises ValueError if the image cannot be read.
    """
    gray, reason = _read_gray(image)
    if gray is None:
        raise ValueError(f"image: {reason}")
    return _corners(gray, _pattern(pattern))


def _corners(gray: NDArray[np.uint8], pattern: tuple[int, int]) -> FloatArray | None:
    found, corners = cv2.findChessboardCorners(gray, pattern, flags=_FIND_FLAGS)
    if not found or corners is None:
        return None
    corners = cv2.cornerSubPix(gray, corners, (11, 11), (-1, -1), _SUBPIX_CRITERIA)
    return np.asarray(corners, dtype=np.float64).reshape(-1, 2)


def _detect(
    images: Sequence[ImageLike],
    pattern: tuple[int, int],
    progress: Progress | None,
    offset: int = 0,
    total: int | None = None,
) -> tuple[list[FloatArray | None], list[str], list[tuple[int, int] | None]]:
    """Corners (or None), rejection reason ('' if found) and size per image."""
    corners: list[FloatArray | None] = []
    reasons: list[str] = []
    sizes: list[tuple[int, int] | None] = []
    total = len(images) if total is None else total
    for i, image in enumerate(images):
        gray, reason = _read_gray(image)
        if gray is None:
            corners.append(None)
            reasons.append(reason)
            sizes.append(None)
        else:
            c = _corners(gray, pattern)
            corners.append(c)
            sizes.append((int(gray.shape[1]), int(gray.shape[0])))
            reasons.append(
                "" if c is not None else f"chessboard {pattern[0]}x{pattern[1]} not found"
            )
        if progress is not None:
            progress(offset + i + 1, total)
    return corners, reasons, sizes


def _reference_size(
    sizes: list[tuple[int, int] | None], corners: list[FloatArray | None]
) -> tuple[int, int] | None:
    for s, c in zip(sizes, corners, strict=True):
        if s is not None and c is not None:
            return s
    return None


def _calibrate(
    names: list[str],
    corners: list[FloatArray | None],
    reasons: list[str],
    sizes: list[tuple[int, int] | None],
    pattern: tuple[int, int],
    square: float,
    min_images: int,
    flags: int,
    arg: str,
) -> CameraCalibration:
    size = _reference_size(sizes, corners)
    used: list[int] = []
    rejected: list[tuple[str, str]] = []
    for i, name in enumerate(names):
        if corners[i] is None:
            rejected.append((name, reasons[i]))
        elif sizes[i] != size:
            rejected.append((name, f"image size {sizes[i]} differs from {size}"))
        else:
            used.append(i)
    if len(used) < min_images:
        detail = "; ".join(f"{n}: {r}" for n, r in rejected) or "none rejected"
        raise ValueError(
            f"{arg}: the chessboard was found in {len(used)} of {len(names)} images, "
            f"need at least {min_images} ({detail})"
        )
    obj = board_points(pattern, square)
    obj32 = [obj.astype(np.float32)] * len(used)
    img32 = [corners[i].astype(np.float32).reshape(-1, 1, 2) for i in used]  # type: ignore[union-attr]
    rms, K, dist, rvecs, tvecs = cv2.calibrateCamera(
        obj32, img32, size, None, None, flags=flags, criteria=_CALIB_CRITERIA
    )
    rv = np.asarray(rvecs, dtype=np.float64).reshape(-1, 3)
    tv = np.asarray(tvecs, dtype=np.float64).reshape(-1, 3)
    dist = np.asarray(dist, dtype=np.float64).ravel()
    per_image = np.empty(len(used))
    for k, i in enumerate(used):
        proj, _ = cv2.projectPoints(obj, rv[k], tv[k], K, dist)
        per_image[k] = np.sqrt(np.mean(np.sum((proj.reshape(-1, 2) - corners[i]) ** 2, axis=1)))
    return CameraCalibration(
        K=np.asarray(K, dtype=np.float64),
        dist=dist,
        image_size=size,  # type: ignore[arg-type]
        rms_px=float(rms),
        per_image_rms_px=per_image,
        images_used=tuple(names[i] for i in used),
        images_rejected=tuple(rejected),
        pattern=pattern,
        square=float(square),
        object_points=obj,
        image_points=tuple(corners[i] for i in used),  # type: ignore[misc]
        rvecs=rv,
        tvecs=tv,
    )


def _image_list(name: str, images: Sequence[ImageLike]) -> list[ImageLike]:
    if isinstance(images, str | Path | np.ndarray):
        raise ValueError(f"{name}: expected a sequence of image paths or arrays, got one item")
    items = list(images)
    if not items:
        raise ValueError(f"{name}: no images given")
    return items


# ----------------------------------------------------------------------------- API
def calibrate_camera(
    images: Sequence[ImageLike],
    pattern: Sequence[int] = (9, 6),
    square: float = 0.025,
    *,
    min_images: int = 3,
    flags: int = 0,
    progress: Progress | None = None,
) -> CameraCalibration:
    """Calibrate one camera from chessboard images (OpenCV; Zhang's method).

    Args:
        images: image file paths or arrays (grayscale or BGR).
        pattern: inner corners (columns, rows), e.g. (9, 6) for OpenCV's sample board.
        square: side of a chessboard square [m], > 0.
        min_images: fewest usable images (pattern found) to calibrate, >= 1.
        flags: ``cv2.calibrateCamera`` flags (default 0: fx, fy, cx, cy, k1, k2, p1, p2, k3).
        progress: optional callback ``progress(done, total)`` per image.

    Returns:
        :class:`CameraCalibration`. Rejected images (pattern not found, unreadable,
        wrong size) are listed, not fatal.

    Raises:
        ValueError: bad arguments, or fewer than ``min_images`` usable images (the
            message names ``images`` and lists the rejections).
    """
    items = _image_list("images", images)
    pat = _pattern(pattern)
    sq = positive("square", square)
    if int(min_images) < 1:
        raise ValueError(f"min_images: expected >= 1, got {min_images!r}")
    names = [_name(im, i) for i, im in enumerate(items)]
    corners, reasons, sizes = _detect(items, pat, progress)
    return _calibrate(names, corners, reasons, sizes, pat, sq, int(min_images), flags, "images")


def calibrate_stereo(
    left_images: Sequence[ImageLike],
    right_images: Sequence[ImageLike],
    pattern: Sequence[int] = (9, 6),
    square: float = 0.025,
    *,
    min_images: int = 3,
    flags: int = 0,
    progress: Progress | None = None,
) -> StereoCalibration:
    """Calibrate a stereo pair from simultaneous chessboard images (OpenCV).

    Each camera is first calibrated on all of its own images where the pattern is found
    (:func:`calibrate_camera`); then ``cv2.stereoCalibrate`` with ``CALIB_FIX_INTRINSIC``
    estimates the right camera's pose relative to the left (``X_R = R X_L + T``) from
    the pairs where the pattern is found in both images.

    Args:
        left_images, right_images: the pairs, in the same order (same length).
        pattern, square, min_images, flags: as in :func:`calibrate_camera` (``min_images``
            also applies to the pairs).
        progress: optional callback ``progress(done, total)`` over all 2M images.

    Returns:
        :class:`StereoCalibration` with R, T [m], baseline_m, stereo_rms_px.
    """
    left = _image_list("left_images", left_images)
    right = _image_list("right_images", right_images)
    if len(left) != len(right):
        raise ValueError(
            f"right_images: expected {len(left)} images (one per left image), got {len(right)}"
        )
    pat = _pattern(pattern)
    sq = positive("square", square)
    if int(min_images) < 1:
        raise ValueError(f"min_images: expected >= 1, got {min_images!r}")
    n = len(left)
    names_l = [_name(im, i) for i, im in enumerate(left)]
    names_r = [_name(im, i) for i, im in enumerate(right)]
    c_l, why_l, s_l = _detect(left, pat, progress, 0, 2 * n)
    c_r, why_r, s_r = _detect(right, pat, progress, n, 2 * n)
    cal_l = _calibrate(names_l, c_l, why_l, s_l, pat, sq, int(min_images), flags, "left_images")
    cal_r = _calibrate(names_r, c_r, why_r, s_r, pat, sq, int(min_images), flags, "right_images")

    used: list[int] = []
    rejected: list[tuple[tuple[str, str], str]] = []
    for i in range(n):
        pair = (names_l[i], names_r[i])
        reasons = []
        if c_l[i] is None or s_l[i] != cal_l.image_size:
            reasons.append(f"left: {why_l[i] or 'image size differs'}")
        if c_r[i] is None or s_r[i] != cal_r.image_size:
            reasons.append(f"right: {why_r[i] or 'image size differs'}")
        if reasons:
            rejected.append((pair, "; ".join(reasons)))
        else:
            used.append(i)
    if len(used) < min_images:
        detail = "; ".join(f"{p[0]} / {p[1]}: {r}" for p, r in rejected)
        raise ValueError(
            f"left_images, right_images: the chessboard was found in both images of "
            f"{len(used)} of {n} pairs, need at least {min_images} ({detail})"
        )
    obj = board_points(pat, sq).astype(np.float32)
    objs = [obj] * len(used)
    pts_l = [c_l[i].astype(np.float32).reshape(-1, 1, 2) for i in used]  # type: ignore[union-attr]
    pts_r = [c_r[i].astype(np.float32).reshape(-1, 1, 2) for i in used]  # type: ignore[union-attr]
    out = cv2.stereoCalibrateExtended(
        objs,
        pts_l,
        pts_r,
        cal_l.K.copy(),
        cal_l.dist.copy(),
        cal_r.K.copy(),
        cal_r.dist.copy(),
        cal_l.image_size,
        np.eye(3),
        np.zeros((3, 1)),
        flags=cv2.CALIB_FIX_INTRINSIC | flags,
        criteria=_CALIB_CRITERIA,
    )
    rms, _, _, _, _, R, T, E, F, _, _, per_view = out
    T = np.asarray(T, dtype=np.float64).ravel()
    return StereoCalibration(
        left=cal_l,
        right=cal_r,
        R=np.asarray(R, dtype=np.float64),
        T=T,
        E=np.asarray(E, dtype=np.float64),
        F=np.asarray(F, dtype=np.float64),
        baseline_m=float(np.linalg.norm(T)),
        stereo_rms_px=float(rms),
        per_pair_rms_px=np.asarray(per_view, dtype=np.float64).reshape(-1, 2),
        pairs_used=tuple((names_l[i], names_r[i]) for i in used),
        pairs_rejected=tuple(rejected),
        image_points_left=tuple(c_l[i] for i in used),  # type: ignore[misc]
        image_points_right=tuple(c_r[i] for i in used),  # type: ignore[misc]
    )
