"""The main job, first stage: video in, tracked ships and their point-wise positions out.

Wires the image stage to the geometry, nothing more (STYLE.md: the pipeline only wires):
frames (:class:`seawatch.io.video.VideoReader`) → horizon + ship detector + visual
tracker (:class:`seawatch.vision.tracker.VisualTracker`) → water-line pixel of each
track → with a camera, (azimuth, depression) through
:meth:`seawatch.camera.PinholeCamera.pixel_to_angles` and the point-wise curved-sea
position of seed 000 eqs. 3–5 / ALGORITHMS.md §4.2
(:func:`seawatch.geometry.sea_position`) with its 1-σ covariance for the camera's pixel
noise. Rows go to ``tracks.csv`` (INTERFACES.md columns) frame by frame, flushed, so an
interruption loses at most the frame in progress.

Not yet here (issue 7): the world-frame filters (EKF/UKF on the angles, diffuse-RLS
smoothing and forecasts) that give speed and course, the platform NAV input, AIS
association and the report; their columns are written empty.
"""

from __future__ import annotations

import csv
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from seawatch.camera.pinhole import PinholeCamera
from seawatch.geometry.geodesy import north_east_to_geodetic
from seawatch.geometry.sea import range_sigma, sea_position, sea_position_covariance
from seawatch.io.video import VideoReader
from seawatch.vision.tracker import VisualTracker

TRACK_TABLE_COLUMNS: tuple[str, ...] = (
    "time", "frame", "track_id", "x", "y", "w", "h", "u_wl", "v_wl", "azimuth_deg",
    "depression_deg", "range_m", "east_m", "north_m", "lat", "lon", "speed_mps",
    "course_deg", "sigma_range_m", "sigma_east_m", "sigma_north_m", "mmsi",
)  # fmt: skip
"""Columns of ``tracks.csv`` (INTERFACES.md "Track table"), in this order."""

PIXEL_SIGMA = 1.0
"""Default 1-σ of the water-line pixel [px] (detector jitter plus quantisation)."""


@dataclass(frozen=True)
class TrackRun:
    """What :func:`track_video` produced.

    Attributes:
        frames: frames processed.
        rows: rows written to ``tracks.csv``.
        tracks: distinct track ids seen.
        outputs: files written.
        warnings: warning messages (e.g. no camera: pixel tracks only).
    """

    frames: int
    rows: int
    tracks: int
    outputs: list[Path] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def to_json(self) -> dict[str, Any]:
        """The ``--json`` summary of ``seawatch track``."""
        return {
            "frames": self.frames,
            "rows": self.rows,
            "tracks": self.tracks,
            "outputs": [str(p) for p in self.outputs],
            "warnings": list(self.warnings),
        }


def _cell(value: float | None) -> str:
    return "" if value is None or not math.isfinite(value) else f"{value:.6g}"


def geo_reference(
    camera: PinholeCamera, uv: np.ndarray, sigma_px: float = PIXEL_SIGMA
) -> dict[str, np.ndarray]:
    """Angles, range and position of water-line pixels ``uv`` (k, 2) seen by ``camera``.

    Azimuth is clockwise from North, depression below the true horizontal (= −elevation),
    range the curved-sea arc distance with standard refraction (§4.2); rows at or above
    the horizon get range +inf and NaN position (never an exception). σ's propagate the
    isotropic pixel noise ``sigma_px`` through the camera Jacobian (§4.3) and the
    geometry (§4.2, §7a). Units: degrees at this edge for the angles, metres otherwise.
    """
    if camera.height is None:
        raise ValueError("camera: the camera file gives no height above the sea (height_m)")
    az, el = camera.pixel_to_angles(uv, frame="world")
    dep = -np.asarray(el)
    cov = camera.angle_covariance(uv, sigma_px)
    s_az = np.sqrt(cov[..., 0, 0])
    s_dep = np.sqrt(cov[..., 1, 1])
    pos = sea_position(camera.position, 0.0, az, dep, camera.height, curved=True)
    with np.errstate(invalid="ignore"):
        s_rng = range_sigma(dep, camera.height, s_dep, curved=True)
        pcov = sea_position_covariance(0.0, az, dep, camera.height, s_az, s_dep, curved=True)
    out = {
        "azimuth_deg": np.degrees(az),
        "depression_deg": np.degrees(dep),
        "range_m": np.asarray(pos.range, dtype=float),
        "north_m": pos.xy[..., 0],
        "east_m": pos.xy[..., 1],
        "sigma_range_m": np.asarray(s_rng, dtype=float),
        "sigma_north_m": np.sqrt(pcov[..., 0, 0]),
        "sigma_east_m": np.sqrt(pcov[..., 1, 1]),
    }
    if camera.lat is not None and camera.lon is not None:
        lat, lon = north_east_to_geodetic(pos.xy, camera.lat, camera.lon)
        out["lat"], out["lon"] = np.asarray(lat), np.asarray(lon)
    return out


def track_video(
    source: str | Path,
    out_dir: Path,
    *,
    camera: PinholeCamera | None = None,
    filter: str = "afkf",
    step: int = 1,
    max_frames: int | None = None,
    sigma_px: float = PIXEL_SIGMA,
    progress: Callable[[int, int | None], None] | None = None,
) -> TrackRun:
    """Track the ships of a video, stream or image folder into ``out_dir/tracks.csv``.

    Args:
        source: video file, URL, device or image folder (:class:`VideoReader`).
        out_dir: output folder (created; an unwritable one fails before any work).
        camera: the calibrated, mounted camera; None gives pixel tracks only (angle,
            range and position columns empty, with a warning).
        filter: the visual tracker's filter, ``afkf`` (default), ``fkf`` or ``kf``.
        step, max_frames: frame decimation and limit.
        sigma_px: 1-σ of the water-line pixel [px] for the position uncertainty.
        progress: ``progress(frames_done, frames_total_or_None)``.
    """
    out_dir = Path(out_dir)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        path = out_dir / "tracks.csv"
        sink = path.open("w", newline="", encoding="utf-8")
    except OSError as exc:
        raise ValueError(f"--out {out_dir}: cannot write ({exc.strerror})") from None
    notes: list[str] = []
    if camera is None:
        notes.append("no --camera: pixel tracks only (angle, range and position columns are empty)")
        warnings.warn(notes[-1], stacklevel=2)
    reader = VideoReader(source, step=step, max_frames=max_frames)
    tracker = VisualTracker(filter=filter, fps=reader.fps or 25.0)
    total = reader.frame_count
    frames = rows = 0
    ids: set[int] = set()
    with sink:
        writer = csv.writer(sink)
        writer.writerow(TRACK_TABLE_COLUMNS)
        for frame in reader:
            tracks = tracker.step(frame.image, frame.time)
            geo = geo_reference(camera, tracks[:, 5:7], sigma_px) if camera and len(tracks) else {}
            for k, row in enumerate(tracks):
                values = {
                    "time": frame.time,
                    "frame": frame.index,
                    "track_id": int(row[0]),
                    **dict(zip(("x", "y", "w", "h", "u_wl", "v_wl"), row[1:7], strict=True)),
                    **{name: float(col[k]) for name, col in geo.items()},
                }
                writer.writerow(
                    [
                        str(values[c]) if c in ("frame", "track_id") else _cell(values.get(c))
                        for c in TRACK_TABLE_COLUMNS
                    ]
                )
                ids.add(int(row[0]))
                rows += 1
            sink.flush()
            frames += 1
            if progress is not None:
                progress(frames, total)
    return TrackRun(frames=frames, rows=rows, tracks=len(ids), outputs=[path], warnings=notes)
