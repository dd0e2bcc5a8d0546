"""Camera files: read and write `seawatch.camera.PinholeCamera` (ALGORITHMS.md §4.3).

Two formats are read and written; :func:`load_camera` tells them apart by content.

1. seawatch camera file (YAML, or JSON for a ``.json`` name) — ``format: seawatch-camera/1``
-------------------------------------------------------------------------------------

A mapping with exactly these keys (angles in **degrees**, lengths in **metres**, pixels
with the origin at the centre of the top-left pixel, u right, v down)::

    format: seawatch-camera/1      # required, exactly this string
    description: "mast camera"     # optional free text
    image_size: [1920, 1080]       # required: [width, height] in pixels
    intrinsics:                    # required, all four keys
      fx: 1371.02                  #   focal length along u [px], > 0
      fy: 1371.02                  #   focal length along v [px], > 0
      cx: 959.5                    #   principal point u [px]
      cy: 539.5                    #   principal point v [px]
    distortion: [k1, k2, p1, p2, k3]   # optional: OpenCV coefficients, 4, 5, 8, 12 or 14
                                       # numbers (OpenCV order); omitted or [] = none
    mounting:                      # optional; each key optional (default 0 / unknown)
      heading_deg: 90.0            #   azimuth of the optical axis, clockwise from North
      pitch_deg: -2.0              #   elevation of the optical axis, + nose-up
                                   #   (a camera looking down at the sea has pitch < 0)
      roll_deg: 0.0                #   rotation about the optical axis, + right side down
      height_m: 12.0               #   optical centre above the sea surface [m], > 0, or null
    position:                      # optional; each key optional
      lat_deg: 50.80               #   WGS-84 latitude [deg] (lat and lon both or neither)
      lon_deg: -1.30               #   WGS-84 longitude [deg]
      north_m: 0.0                 #   local position in the scene's tangent plane [m]
      east_m: 0.0

Any other key, at any level, is an error (ValueError naming the file and the key), as
is a missing required key or a value of the wrong type.

2. OpenCV ``cv2.FileStorage`` files (YAML ``%YAML:1.0``, XML, or OpenCV JSON)
-------------------------------------------------------------------------

As written by OpenCV's calibration samples (e.g. ``../shared/data/opencv/
left_intrinsics.yml``). Read keys:

- camera matrix: ``camera_matrix`` (or ``cameraMatrix``, ``K``), 3×3, required;
- distortion: ``distortion_coefficients`` (or ``dist_coeffs``, ``distCoeffs``, ``D``),
  optional (none = no distortion);
- image size: ``image_width`` and ``image_height`` (or ``image_size``/``imageSize`` =
  [width, height]), required;
- seawatch additions (optional, written by :func:`save_camera`): ``mount_heading_deg``,
  ``mount_pitch_deg``, ``mount_roll_deg``, ``height_m``, ``lat_deg``, ``lon_deg``,
  ``north_m``, ``east_m`` (meanings as above);
- ignored (calibration by-products of OpenCV's samples): ``calibration_time``,
  ``nframes``, ``nr_of_frames``, ``board_width``, ``board_height``, ``square_size``,
  ``aspectRatio``, ``fix_aspect_ratio``, ``flags``, ``fisheye_model``,
  ``avg_reprojection_error``, ``per_view_reprojection_errors``,
  ``extrinsic_parameters``, ``image_points``, ``grid_points``.

Any other key is an error unless ``strict=False``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Literal

import cv2
import numpy as np
import yaml

from seawatch.camera.pinhole import PinholeCamera

FORMAT_TAG = "seawatch-camera/1"
"""Value of the ``format`` key of a seawatch camera file."""

_SW_TOP = {
    "format": True,
    "description": False,
    "image_size": True,
    "intrinsics": True,
    "distortion": False,
    "mounting": False,
    "position": False,
}
_SW_INTRINSICS = ("fx", "fy", "cx", "cy")
_SW_MOUNTING = ("heading_deg", "pitch_deg", "roll_deg", "height_m")
_SW_POSITION = ("lat_deg", "lon_deg", "north_m", "east_m")

_CV_MATRIX = ("camera_matrix", "cameraMatrix", "K")
_CV_DIST = ("distortion_coefficients", "dist_coeffs", "distCoeffs", "D")
_CV_SIZE = ("image_size", "imageSize")
_CV_WH = ("image_width", "image_height")
_CV_EXTRA = (
    "mount_heading_deg",
    "mount_pitch_deg",
    "mount_roll_deg",
    "height_m",
    "lat_deg",
    "lon_deg",
    "north_m",
    "east_m",
)
_CV_IGNORED = (
    "calibration_time",
    "nframes",
    "nr_of_frames",
    "board_width",
    "board_height",
    "square_size",
    "aspectRatio",
    "fix_aspect_ratio",
    "flags",
    "fisheye_model",
    "avg_reprojection_error",
    "per_view_reprojection_errors",
    "extrinsic_parameters",
    "image_points",
    "grid_points",
)
_CV_KNOWN = frozenset(_CV_MATRIX + _CV_DIST + _CV_SIZE + _CV_WH + _CV_EXTRA + _CV_IGNORED)
_CV_SUFFIXES = (".yml", ".yaml", ".xml", ".json")


# ---------------------------------------------------------------------- reading
def load_camera(path: str | Path, *, strict: bool = True) -> PinholeCamera:
    """Read a camera file (seawatch or OpenCV FileStorage format, see the module docstring).

    The format is told by content: an XML file, a ``%YAML:1.0`` header, an
    ``opencv-matrix`` node, or a mapping without a ``format`` key but with an OpenCV
    camera matrix, distortion or image width key is read with ``cv2.FileStorage``; else the file
    must be a seawatch camera file. Degrees and metres at the edge become radians and
    metres in the returned camera.

    Raises:
        FileNotFoundError: the file does not exist.
        ValueError: unreadable file, unknown key (unless ``strict=False``), missing key,
            or invalid value — the message names the file and the key.
    """
    p = Path(path)
    text = p.read_text(encoding="utf-8", errors="replace")
    head = text.lstrip()[:16]
    if (
        head.startswith(("%YAML:", "<?xml"))
        or p.suffix.lower() == ".xml"
        or "opencv-matrix" in text
    ):
        return _load_opencv(p, strict)
    try:
        data = json.loads(text) if p.suffix.lower() == ".json" else yaml.safe_load(text)
    except (json.JSONDecodeError, yaml.YAMLError) as exc:
        raise ValueError(f"{p}: not a readable YAML/JSON camera file ({exc})") from None
    if not isinstance(data, Mapping):
        raise ValueError(f"{p}: expected a mapping of camera keys, got {type(data).__name__}")
    if "format" not in data and any(k in _CV_MATRIX + _CV_DIST + _CV_WH for k in data):
        return _load_opencv(p, strict)
    return _camera_from_seawatch(data, p, strict)


def _err(path: Path, key: str, problem: str) -> ValueError:
    return ValueError(f"{path}: key '{key}': {problem}")


def _number(value: Any, path: Path, key: str, *, allow_none: bool = False) -> float | None:
    if value is None and allow_none:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _err(path, key, f"expected a number, got {value!r}")
    return float(value)


def _check_keys(
    data: Mapping[str, Any], allowed: tuple[str, ...], path: Path, prefix: str, strict: bool
) -> None:
    if not strict:
        return
    for key in data:
        if key not in allowed:
            raise ValueError(
                f"{path}: unknown key '{prefix}{key}' (expected one of: {', '.join(allowed)})"
            )


def _section(data: Mapping[str, Any], key: str, path: Path) -> Mapping[str, Any]:
    value = data.get(key)
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise _err(path, key, f"expected a mapping, got {value!r}")
    return value


def _camera_from_seawatch(data: Mapping[str, Any], path: Path, strict: bool) -> PinholeCamera:
    _check_keys(data, tuple(_SW_TOP), path, "", strict)
    for key, required in _SW_TOP.items():
        if required and key not in data:
            raise ValueError(f"{path}: missing key '{key}'")
    if data["format"] != FORMAT_TAG:
        raise _err(path, "format", f"expected '{FORMAT_TAG}', got {data['format']!r}")
    if "description" in data and not isinstance(data["description"], str | type(None)):
        raise _err(path, "description", "expected a string")

    size = data["image_size"]
    if (
        not isinstance(size, list | tuple)
        or len(size) != 2
        or not all(isinstance(s, int) and not isinstance(s, bool) for s in size)
    ):
        raise _err(path, "image_size", f"expected [width, height] as two integers, got {size!r}")

    intr = _section(data, "intrinsics", path)
    _check_keys(intr, _SW_INTRINSICS, path, "intrinsics.", strict)
    values: dict[str, float] = {}
    for key in _SW_INTRINSICS:
        if key not in intr:
            raise ValueError(f"{path}: missing key 'intrinsics.{key}'")
        values[key] = _number(intr[key], path, f"intrinsics.{key}")  # type: ignore[assignment]

    dist = data.get("distortion") or []
    if not isinstance(dist, list | tuple):
        raise _err(path, "distortion", f"expected a list of numbers, got {dist!r}")
    coeffs = tuple(_number(c, path, f"distortion[{i}]") for i, c in enumerate(dist))

    mount = _section(data, "mounting", path)
    _check_keys(mount, _SW_MOUNTING, path, "mounting.", strict)
    angles = {
        name: math.radians(_number(mount.get(f"{name}_deg", 0.0), path, f"mounting.{name}_deg"))  # type: ignore[arg-type]
        for name in ("heading", "pitch", "roll")
    }
    height = _number(mount.get("height_m"), path, "mounting.height_m", allow_none=True)

    pos = _section(data, "position", path)
    _check_keys(pos, _SW_POSITION, path, "position.", strict)
    lat = _number(pos.get("lat_deg"), path, "position.lat_deg", allow_none=True)
    lon = _number(pos.get("lon_deg"), path, "position.lon_deg", allow_none=True)
    north = _number(pos.get("north_m", 0.0), path, "position.north_m")
    east = _number(pos.get("east_m", 0.0), path, "position.east_m")

    try:
        return PinholeCamera(
            **values,
            image_size=(size[0], size[1]),
            dist=coeffs,  # type: ignore[arg-type]
            **angles,
            height=height,
            lat=lat,
            lon=lon,
            position=(north, east),  # type: ignore[arg-type]
        )
    except ValueError as exc:
        raise ValueError(f"{path}: invalid camera: {exc}") from None


def _load_opencv(path: Path, strict: bool) -> PinholeCamera:
    try:
        fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
    except cv2.error as exc:
        raise ValueError(f"{path}: not a readable OpenCV FileStorage file ({exc})") from None
    if not fs.isOpened():
        raise ValueError(f"{path}: not a readable OpenCV FileStorage file")
    try:
        root = fs.root()
        keys = tuple(root.keys())
        if strict:
            for key in keys:
                if key not in _CV_KNOWN:
                    raise ValueError(
                        f"{path}: unknown key '{key}' in an OpenCV camera file "
                        "(pass strict=False to ignore unknown keys)"
                    )

        def one_of(names: tuple[str, ...], required: bool) -> str | None:
            present = [n for n in names if n in keys]
            if len(present) > 1:
                raise ValueError(f"{path}: keys {present} both give the same quantity; keep one")
            if not present and required:
                raise ValueError(f"{path}: missing key '{names[0]}' (or {', '.join(names[1:])})")
            return present[0] if present else None

        def mat(key: str) -> np.ndarray:
            node = root.getNode(key)
            m = node.mat() if node.isMap() else None
            if m is None and node.isSeq():
                m = np.array([node.at(i).real() for i in range(node.size())])
            if m is None:
                raise _err(path, key, "expected an OpenCV matrix or a sequence of numbers")
            return np.asarray(m, dtype=np.float64)

        def num(key: str) -> float | None:
            if key not in keys:
                return None
            node = root.getNode(key)
            if not (node.isInt() or node.isReal()):
                raise _err(path, key, "expected a number")
            return float(node.real())

        k_key = one_of(_CV_MATRIX, required=True)
        K = mat(k_key)  # type: ignore[arg-type]
        if K.shape != (3, 3):
            raise _err(path, k_key, f"expected a 3x3 camera matrix, got shape {K.shape}")  # type: ignore[arg-type]
        d_key = one_of(_CV_DIST, required=False)
        dist = mat(d_key).ravel() if d_key is not None else np.zeros(5)
        s_key = one_of(_CV_SIZE, required=False)
        if s_key is not None:
            size = mat(s_key).ravel()
            if size.size != 2:
                raise _err(path, s_key, f"expected [width, height], got {size.tolist()}")
            w, h = size
        else:
            for key in _CV_WH:
                if key not in keys:
                    raise ValueError(f"{path}: missing key '{key}'")
            w, h = num("image_width"), num("image_height")
        lat, lon = num("lat_deg"), num("lon_deg")
        extras: dict[str, Any] = {
            "heading": math.radians(num("mount_heading_deg") or 0.0),
            "pitch": math.radians(num("mount_pitch_deg") or 0.0),
            "roll": math.radians(num("mount_roll_deg") or 0.0),
            "height": num("height_m"),
            "lat": lat,
            "lon": lon,
            "position": (num("north_m") or 0.0, num("east_m") or 0.0),
        }
    finally:
        fs.release()
    try:
        return PinholeCamera.from_matrix(K, dist, (w, h), **extras)  # type: ignore[arg-type]
    except ValueError as exc:
        raise ValueError(f"{path}: invalid camera: {exc}") from None


# ---------------------------------------------------------------------- writing
def camera_to_dict(camera: PinholeCamera, description: str | None = None) -> dict[str, Any]:
    """The seawatch camera file mapping of a camera (degrees and metres at the edge)."""
    data: dict[str, Any] = {"format": FORMAT_TAG}
    if description is not None:
        data["description"] = str(description)
    data["image_size"] = [int(camera.image_size[0]), int(camera.image_size[1])]
    data["intrinsics"] = {"fx": camera.fx, "fy": camera.fy, "cx": camera.cx, "cy": camera.cy}
    data["distortion"] = [float(c) for c in camera.dist]
    data["mounting"] = {
        "heading_deg": math.degrees(camera.heading),
        "pitch_deg": math.degrees(camera.pitch),
        "roll_deg": math.degrees(camera.roll),
        "height_m": camera.height,
    }
    position: dict[str, Any] = {}
    if camera.lat is not None:
        position["lat_deg"] = camera.lat
        position["lon_deg"] = camera.lon
    if camera.position != (0.0, 0.0):
        position["north_m"], position["east_m"] = camera.position
    if position:
        data["position"] = position
    return data


def save_camera(
    camera: PinholeCamera,
    path: str | Path,
    format: Literal["seawatch", "opencv"] = "seawatch",
    *,
    description: str | None = None,
) -> Path:
    """Write a camera file; returns its path.

    ``format="seawatch"``: the seawatch camera file (JSON for a ``.json`` name, YAML
    otherwise). ``format="opencv"``: ``cv2.FileStorage`` YAML/XML/JSON chosen by the
    suffix (``.yml``, ``.yaml``, ``.xml``, ``.json``) with ``image_width``,
    ``image_height``, ``camera_matrix``, ``distortion_coefficients`` and the seawatch
    additions (mounting attitude in degrees, height, position) — readable by OpenCV
    and by :func:`load_camera`. ``description`` is kept by the seawatch format only.
    """
    if not isinstance(camera, PinholeCamera):
        raise ValueError(f"camera: expected a PinholeCamera, got {type(camera).__name__}")
    p = Path(path)
    if format == "seawatch":
        data = camera_to_dict(camera, description)
        if p.suffix.lower() == ".json":
            p.write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")
        else:
            header = "# seawatch camera file (see seawatch.io.camera_file for the schema)\n"
            p.write_text(
                header + yaml.safe_dump(data, sort_keys=False, default_flow_style=None),
                encoding="utf-8",
            )
        return p
    if format != "opencv":
        raise ValueError(f"format: expected 'seawatch' or 'opencv', got {format!r}")
    if p.suffix.lower() not in _CV_SUFFIXES:
        raise ValueError(
            f"path: an OpenCV camera file needs one of the suffixes {', '.join(_CV_SUFFIXES)}, "
            f"got {p.name!r}"
        )
    fs = cv2.FileStorage(str(p), cv2.FILE_STORAGE_WRITE)
    if not fs.isOpened():
        raise ValueError(f"path: cannot write {p}")
    try:
        fs.write("image_width", int(camera.image_size[0]))
        fs.write("image_height", int(camera.image_size[1]))
        fs.write("camera_matrix", np.array(camera.K))
        fs.write("distortion_coefficients", np.array(camera.dist).reshape(-1, 1))
        fs.write("mount_heading_deg", math.degrees(camera.heading))
        fs.write("mount_pitch_deg", math.degrees(camera.pitch))
        fs.write("mount_roll_deg", math.degrees(camera.roll))
        if camera.height is not None:
            fs.write("height_m", float(camera.height))
        if camera.lat is not None:
            fs.write("lat_deg", float(camera.lat))
            fs.write("lon_deg", float(camera.lon))  # type: ignore[arg-type]
        if camera.position != (0.0, 0.0):
            fs.write("north_m", float(camera.position[0]))
            fs.write("east_m", float(camera.position[1]))
    finally:
        fs.release()
    return p
