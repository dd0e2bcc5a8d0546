"""The main job: a camera video in, geo-referenced ship tracks out (issue 7).

This module only wires the stages (STYLE.md); each stage is its own module:

1. frames — :class:`seawatch.io.video.VideoReader` (file, image folder, stream, device);
2. image stage — :class:`seawatch.vision.tracker.VisualTracker`: horizon, ship boxes,
   visual tracks with their water-line pixel (seed 001, ALGORITHMS.md §1);
3. camera pose per frame — the camera file's intrinsics (scaled to the frames when
   they are the same view at another resolution, also when a stream's resolution
   changes; frames of another aspect ratio stop the job as bad input; the focal length
   scaled by the zoom the visual tracker measured, the file's being the first
   frame's: :meth:`seawatch.camera.PinholeCamera.zoomed`), height and
   attitude; on a moving platform the NAV pose (:mod:`seawatch.io.nav`) gives position
   and heading; the detected horizon refines pitch and roll
   (:func:`seawatch.camera.attitude_from_horizon`, §4.3) when it is found with
   confidence and lies within :data:`HORIZON_TOLERANCE` of the file's attitude — with
   ``attitude="horizon"``, and by default (``"auto"``) on a moving platform, whose NAV
   gives no (or a coarse) pitch and roll;
4. angles — water-line pixel → azimuth (clockwise from North) and depression (below the
   true horizontal) with their covariance for the pixel noise
   (:meth:`seawatch.camera.PinholeCamera.pixel_to_angles`, ``angle_covariance``);
5. world estimation — :class:`seawatch.tracking.world.WorldTracker`: point-wise
   curved-sea geometry (seed 000 alg. 1), diffuse-RLS AR smoothing with forecasts
   (alg. 2), and world-frame CV EKF/UKF on the angles with the platform's position
   noise — position, speed, course, their uncertainty and +10 s / +30 s forecasts;
6. AIS cross-check — :class:`seawatch.tracking.ais_match.AisAssociator` (MMSI labels,
   "dark" tracks, AIS vessels in view but unseen);
7. outputs, written as they are produced — ``tracks.csv`` (INTERFACES.md "Track table",
   the ``best`` estimator, one row per track per frame, flushed once per frame in a
   single write so that a kill loses at most the frame in progress), ``estimates.csv``
   (every estimator, long form), ``tracks.geojson`` (rewritten about once per second of
   video), ``annotated.mp4`` (fragmented MP4), and at the end ``report.html`` and, with a
   truth file, the errors of :func:`seawatch.metrics.track_errors.score_tracks`.

A frame-size change mid-stream restarts the visual tracks (new ids; their pixels are
another grid's) and is noted in the run's warnings; ``annotated.mp4`` keeps the first
size.

Times: video time [s] from the first frame; ``start`` [s since 1970-01-01 UTC] is the
absolute time of frame 0, needed to align NAV and AIS (``seawatch synth ais`` writes it
to ``clip.json`` beside the video, which is read when no ``start`` is given).
"""

from __future__ import annotations

import json
import math
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from seawatch._validation import same_aspect
from seawatch.camera.horizon import attitude_from_horizon
from seawatch.camera.pinhole import PinholeCamera
from seawatch.geometry.geodesy import north_east_to_geodetic
from seawatch.io.track_table import TableWriter
from seawatch.io.video import VideoReader
from seawatch.tracking.world import ESTIMATORS, PlatformPose, WorldEstimates, WorldTracker
from seawatch.vision.tracker import VisualTracker

__all__ = [
    "ESTIMATE_COLUMNS",
    "FORECAST_HORIZONS",
    "PIXEL_SIGMA",
    "TRACK_TABLE_COLUMNS",
    "TrackRun",
    "check_options",
    "read_clip_start",
    "track_video",
]

FORECAST_HORIZONS: tuple[float, ...] = (10.0, 30.0)
"""Forecast horizons [s] of the track table (issue 7: +10 s and +30 s)."""


def _forecast_columns() -> tuple[str, ...]:
    cols: list[str] = []
    for tau in FORECAST_HORIZONS:
        s = f"{tau:g}s"
        cols += [f"forecast_north_m_{s}", f"forecast_east_m_{s}"]
        cols += [f"forecast_lat_{s}", f"forecast_lon_{s}"]
    return tuple(cols)


TRACK_TABLE_COLUMNS: tuple[str, ...] = (
    "time", "frame", "track_id", "x", "y", "w", "h", "u_wl", "v_wl", "azimuth_deg",
    "depression_deg", "range_m", "east_m", "north_m", "lat", "lon", "speed_mps",
    "course_deg", "sigma_range_m", "sigma_east_m", "sigma_north_m", "mmsi",
    "estimator", *_forecast_columns(),
)  # fmt: skip
"""Columns of ``tracks.csv``: INTERFACES.md "Track table" in its order, then the estimator
that gave the position columns and the forecast positions at :data:`FORECAST_HORIZONS`."""

ESTIMATE_COLUMNS: tuple[str, ...] = (
    "time", "frame", "track_id", "estimator", "north_m", "east_m", "lat", "lon",
    "range_m", "sigma_range_m", "sigma_north_m", "sigma_east_m", "speed_mps",
    "course_deg", "nis", *_forecast_columns(),
)  # fmt: skip
"""Columns of ``estimates.csv``: every estimator's output, one row per track, frame and
estimator (long form)."""

PIXEL_SIGMA = 1.0
"""Default 1-σ of the water-line pixel [px] (detector jitter plus quantisation)."""

COAST_SECONDS = 3.0
"""How long a confirmed track survives without detections, by prediction [s] (at least
:data:`REPORT_COAST_FRAMES`): a ship does not vanish, it passes behind another one.
On the demo clip (10 frames/s) 3 s instead of 12 frames (1.2 s) keeps the far vessel's
id behind the large one for longer (ID switches 3 → 2, EKF position RMSE 49.9 → 37.3 m)."""

REPORT_COAST_FRAMES = 12
"""A coasting track's rows are written for this many frames without a detection (the
visual tracker's default life); after that it lives on silently (:data:`COAST_SECONDS`)
so that its id and world filter resume when the ship reappears. Writing every coasted row
made the hidden vessel's 3 s of predictions false positives (uav-sea MOTA 0.901 → 0.799)."""

WORLD_SIGMA_A = 0.5
"""Process noise √q of the world EKF/UKF [m/s^1.5] (CWNA): real traffic turns and changes
speed; on the demo clip 0.5 gave 19 % lower position RMSE than 0.1 (102.8 m against
127.0 m, measured with the session-3 detector, before its water-line fix); with the
fixed water line (session 4, before :data:`WORLD_ROBUST_GATE`): 0.2 → 42.6 m, 0.5 → 37.3 m,
1.0 → 34.7 m (geometry 41.1 m)."""

WORLD_ROBUST_GATE = 0.99
"""Gate probability of the world EKF/UKF's robust update (``WorldTracker(robust_gate=)``):
a water line whose innovation is beyond the 99 % χ² gate — two ships merged into one box,
a box on a superstructure — is down-weighted instead of moving the range. Measured before
the detector's session-5 refinement change: demo EKF 37.3 → 34.9 m (geometry 41.1 m; gate
0.95: 36.5 m), uav-sea 27.6 → 21.0 m, range-1km 4.1 → 2.9 % at 1 km
(``docs/results/track/measure.py``)."""

MIN_TRUTH_PX = 5.0
"""Truth boxes less than this tall [px] (vessels far beyond a classical detector's reach)
are "don't care" when a run is scored: neither a miss nor, for a track on them, a false
alarm (:func:`seawatch.metrics.track_errors.score_tracks`)."""

AIS_RATE = 5.0
"""Rate of the AIS association updates [1/s] (every frame at most)."""

AttitudeMode = Literal["auto", "horizon", "file"]
HORIZON_CONFIDENCE = 0.3
"""Least horizon confidence for an attitude refinement [-]: the detector's own "found"
level (:func:`seawatch.vision.detect_horizon`'s ``min_confidence``); the tracker's
gate and :data:`HORIZON_TOLERANCE` keep a wrong line out. At 0.5 the refinement was off
in 130 of the 710 frames of the rendered uav-sea clip (92 of 600 of range-1km), whose
tracked lines were all within 0.17 px at 1080p: those frames took the file's attitude, without
the mast's sway (±0.25°, as much as the depression of a ship 700 m from a 3 m camera),
and point-wise geometry was 2.3 times worse (45.2 against 19.5 m)."""
HORIZON_TOLERANCE = math.radians(3.0)
"""Largest pitch or roll change [rad] the horizon may make to the camera file's attitude
(a "horizon" farther off is a coastline or a wake, not the sea horizon)."""


@dataclass(frozen=True)
class TrackRun:
    """What :func:`track_video` produced (the ``--json`` summary of ``seawatch track``).

    Attributes:
        frames: frames processed.
        rows: rows written to ``tracks.csv``.
        tracks: distinct track ids seen.
        outputs: files written.
        warnings: warning messages (no camera, NAV not covering the video, …).
        errors: with a truth file, the INTERFACES.md ``errors`` object (and details).
        ais: with AIS, the cross-check (matches, dark, unseen), else None.
        interrupted: the run stopped early (Ctrl-C, a signal, a stream that ended).
        frames_dropped: frames of a live source dropped to keep up with it (``keep_up``).
    """

    frames: int
    rows: int
    tracks: int
    outputs: list[Path] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    errors: dict[str, Any] | None = None
    ais: dict[str, Any] | None = None
    interrupted: bool = False
    frames_dropped: int = 0

    def to_json(self) -> dict[str, Any]:
        """The ``--json`` summary of ``seawatch track``."""
        doc: dict[str, Any] = {
            "frames": self.frames,
            "frames_dropped": self.frames_dropped,
            "rows": self.rows,
            "tracks": self.tracks,
            "outputs": [str(p) for p in self.outputs],
            "warnings": list(self.warnings),
        }
        if self.errors is not None:
            doc["errors"] = self.errors
        if self.ais is not None:
            doc["ais"] = self.ais
        if self.interrupted:
            doc["interrupted"] = True
        return doc


def read_clip_start(source: str | Path) -> float | None:
    """Absolute time of frame 0 [s since the epoch] from ``clip.json`` beside ``source``.

    ``seawatch synth ais`` writes ``clip.json`` with ``start_epoch``; None when there is
    no such file (or it has no start).
    """
    p = Path(source)
    sidecar = (p if p.is_dir() else p.parent) / "clip.json"
    if not sidecar.is_file():
        return None
    try:
        value = json.loads(sidecar.read_text(encoding="utf-8")).get("start_epoch")
    except (OSError, ValueError, AttributeError):
        return None
    return float(value) if isinstance(value, int | float) and math.isfinite(value) else None


# ------------------------------------------------------------------------------ per frame
class _Pose:
    """The camera of each frame: file attitude, NAV pose, horizon refinement (step 3)."""

    def __init__(
        self,
        camera: PinholeCamera,
        platform: Any,
        start: float | None,
        attitude: AttitudeMode,
        notes: list[str],
    ) -> None:
        self.camera = camera
        self.platform = platform
        self.start = start
        self.use_horizon = attitude == "horizon" or (attitude == "auto" and platform is not None)
        self.notes = notes
        self._nav_warned = False
        self.lat0, self.lon0 = camera.lat, camera.lon
        if platform is not None:
            self.lat0, self.lon0 = platform.lat0, platform.lon0

    def at(
        self, time: float, horizon: Any, zoom: Any = None
    ) -> tuple[PinholeCamera | None, PlatformPose | None]:
        """(camera with its world attitude, platform pose) at video time ``time`` [s];
        (None, None) where the NAV does not cover the time (positions unknown).
        ``zoom``: the frame's camera zoom ``(scale, cx, cy)`` measured by the visual
        tracker (:attr:`~seawatch.vision.tracker.VisualTracker.camera_zoom`): the
        camera file's focal length is the first frame's, and a zoom scales it
        (:meth:`~seawatch.camera.PinholeCamera.zoomed`)."""
        cam = self.camera
        if zoom is not None and float(zoom[0]) != 1.0:
            cam = cam.zoomed(float(zoom[0]), (float(zoom[1]), float(zoom[2])))
        pose = None
        if self.platform is not None:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                nav = self.platform.pose_at(np.array([time + (self.start or 0.0)]))
            if caught and not self._nav_warned:
                self._nav_warned = True
                self.notes.append(f"--platform: {caught[0].message}")
            if not bool(nav.valid[0]):
                return None, None
            pitch = cam.pitch + (0.0 if np.isnan(nav.pitch[0]) else float(nav.pitch[0]))
            roll = cam.roll + (0.0 if np.isnan(nav.roll[0]) else float(nav.roll[0]))
            cam = cam.with_attitude(
                heading=(cam.heading + float(nav.heading[0])) % (2 * math.pi),
                pitch=pitch,
                roll=roll,
            )
            h = float(nav.height[0])
            pose = PlatformPose(
                north=float(nav.north[0]),
                east=float(nav.east[0]),
                height=h if math.isfinite(h) and h > 0 else None,
                sigma_position=float(getattr(self.platform, "sigma_position", 0.0) or 0.0),
                velocity_north=float(nav.velocity[0, 0]),
                velocity_east=float(nav.velocity[0, 1]),
            )
        if self.use_horizon and horizon is not None and getattr(horizon, "found", False):
            if float(getattr(horizon, "confidence", 0.0)) >= HORIZON_CONFIDENCE:
                line = np.array([[horizon.x0, horizon.y0], [horizon.x1, horizon.y1]])
                att = attitude_from_horizon(cam, line, height=cam.height)
                dp, dr = float(att.pitch) - cam.pitch, float(att.roll) - cam.roll
                if abs(dp) <= HORIZON_TOLERANCE and abs(dr) <= HORIZON_TOLERANCE:
                    cam = cam.with_attitude(pitch=float(att.pitch), roll=float(att.roll))
        return cam, pose


BOX_COLUMNS = ("x", "y", "w", "h", "u_wl", "v_wl")

VIEW_SHIP_LENGTH = 20.0
"""Length [m] of the smallest vessel that "should be in view" (AIS cross-check)."""
VIEW_MIN_PIXELS = 5.0
"""Its least length in the image [px] to count as visible."""
VIEW_SHIP_TOP = 10.0
"""Its height above the sea [m], for the distance at which it sinks below the horizon."""


def _view_wedge(camera: PinholeCamera, platform: PlatformPose | None) -> Any:
    """Where an AIS vessel "should be in view": inside the horizontal field of view, no
    farther than a 20 m vessel is 5 px long, and not hidden by the earth's curvature
    (camera horizon distance plus that of a 10 m superstructure, §4.2)."""
    from seawatch.geometry.sea import horizon_distance
    from seawatch.tracking.ais_match import ViewWedge

    hfov = 2.0 * math.atan(0.5 * camera.image_size[0] / camera.fx)
    h = camera.height if platform is None or platform.height is None else platform.height
    seen = VIEW_SHIP_LENGTH * camera.fx / VIEW_MIN_PIXELS
    hidden = float(horizon_distance(h) + horizon_distance(VIEW_SHIP_TOP))
    return ViewWedge(
        heading=camera.heading,
        hfov=hfov,
        max_range=min(seen, hidden),
        north=0.0 if platform is None else platform.north,
        east=0.0 if platform is None else platform.east,
    )


def _angles(
    camera: PinholeCamera, uv: np.ndarray, sigma_px: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Azimuth, depression [rad] (k,) and their covariance (k, 2, 2) [rad²] of pixels."""
    az, el = camera.pixel_to_angles(uv, frame="world")
    cov = np.array(camera.angle_covariance(uv, sigma_px), dtype=float)
    cov[..., 0, 1] = -cov[..., 0, 1]  # (azimuth, elevation) → (azimuth, depression)
    cov[..., 1, 0] = -cov[..., 1, 0]
    return np.asarray(az, float) % (2 * math.pi), -np.asarray(el, float), cov


_GEO_KEYS: tuple[tuple[str, str, str, str], ...] = (
    ("north_m", "east_m", "lat", "lon"),
    *(
        (f"forecast_north_m_{t:g}s", f"forecast_east_m_{t:g}s", f"forecast_lat_{t:g}s",
         f"forecast_lon_{t:g}s")
        for t in FORECAST_HORIZONS
    ),
)  # fmt: skip
"""(north, east) cell pairs and the (lat, lon) cells they give."""


def _estimate_cells(est: WorldEstimates, k: int) -> dict[str, Any]:
    """The position, motion and forecast cells of track ``k`` of one estimator (lat/lon
    come later, for all rows of a frame at once: :func:`_add_geodetic`)."""
    cov = est.covariance[k]
    cells: dict[str, Any] = {
        "north_m": float(est.north[k]),
        "east_m": float(est.east[k]),
        "range_m": float(est.range[k]),
        "sigma_range_m": float(est.sigma_range[k]),
        "sigma_north_m": math.sqrt(cov[0, 0]) if cov[0, 0] >= 0 else math.nan,
        "sigma_east_m": math.sqrt(cov[1, 1]) if cov[1, 1] >= 0 else math.nan,
        "speed_mps": float(est.speed[k]),
        "course_deg": math.degrees(float(est.course[k])),
        "nis": None if est.nis is None else float(est.nis[k]),
    }
    for tau in FORECAST_HORIZONS:
        f = est.forecasts.get(tau)
        if f is not None:
            cells[f"forecast_north_m_{tau:g}s"] = float(f[k, 0])
            cells[f"forecast_east_m_{tau:g}s"] = float(f[k, 1])
    return cells


def _add_geodetic(rows: list[dict[str, Any]], lat0: Any, lon0: Any) -> None:
    """Fill the lat/lon cells of ``rows`` from their north/east cells, one geodesy call."""
    if lat0 is None or lon0 is None or not rows:
        return
    where: list[tuple[int, str, str]] = []
    ne: list[tuple[float, float]] = []
    for i, row in enumerate(rows):
        for kn, ke, klat, klon in _GEO_KEYS:
            n, e = row.get(kn), row.get(ke)
            if n is not None and e is not None and math.isfinite(n) and math.isfinite(e):
                where.append((i, klat, klon))
                ne.append((n, e))
    if not ne:
        return
    lat, lon = north_east_to_geodetic(np.array(ne), lat0, lon0)
    for (i, klat, klon), la, lo in zip(where, np.atleast_1d(lat), np.atleast_1d(lon), strict=True):
        rows[i][klat], rows[i][klon] = float(la), float(lo)


# ------------------------------------------------------------------------------ the job
def _prepare_out(out_dir: Path) -> Path:
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        probe = out_dir / ".seawatch-write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise ValueError(f"--out {out_dir}: cannot write ({exc.strerror or exc})") from None
    return out_dir


def check_options(estimator: str, attitude: str) -> None:
    """ValueError naming ``--estimator`` or ``--attitude`` when either is not one of the
    choices of :func:`track_video` (the CLI checks before reading any input)."""
    if estimator not in ESTIMATORS:
        raise ValueError(f"--estimator: expected one of {', '.join(ESTIMATORS)}, got {estimator!r}")
    if attitude not in ("auto", "horizon", "file"):
        raise ValueError(f"--attitude: expected auto, horizon or file, got {attitude!r}")


def _camera_for(camera: PinholeCamera, size: tuple[int, int], where: str) -> PinholeCamera:
    """The camera for frames of ``size`` = (width, height) [px]: the camera itself, or
    its :meth:`~seawatch.camera.PinholeCamera.resized` copy for the same view at another
    resolution (:func:`~seawatch._validation.same_aspect`). ValueError naming
    ``--camera`` and ``where`` for another aspect ratio: a crop or another camera, whose
    pixels cannot be told apart from the calibrated ones' by their size alone."""
    if size == camera.image_size:
        return camera
    (cw, ch), (w, h) = camera.image_size, size
    if not same_aspect(size, camera.image_size):
        raise ValueError(
            f"--camera: calibrated for {cw}x{ch} frames, {where} is {w}x{h} (another aspect "
            "ratio: a crop or another camera); calibrate the camera for this stream"
        )
    return camera.resized(size)


def track_video(
    source: str | Path,
    out_dir: str | Path,
    *,
    camera: PinholeCamera | None = None,
    platform: Any = None,
    ais: Any = None,
    truth: str | Path | None = None,
    start: float | None = None,
    filter: str = "afkf",
    estimator: str = "ekf",
    attitude: AttitudeMode = "auto",
    step: int = 1,
    max_frames: int | None = None,
    begin: float = 0.0,
    end: float | None = None,
    fps: float | None = None,
    reconnect: int = 0,
    keep_up: bool | None = None,
    sigma_px: float = PIXEL_SIGMA,
    annotate: bool = True,
    report: bool = True,
    parquet: bool = False,
    detector: Any = None,
    world_options: Mapping[str, Any] | None = None,
    progress: Callable[[int, int | None], None] | None = None,
) -> TrackRun:
    """Track the ships of a video, stream or image folder into ``out_dir`` (module docstring).

    Args:
        source: video file, URL, device or image folder (:class:`VideoReader`).
        out_dir: output folder (created; an unwritable one fails before any work).
        camera: the calibrated, mounted camera; None gives pixel tracks only (angle,
            range and position columns empty, with a warning).
        platform: a :class:`seawatch.io.nav.NavTrack` for a camera on a moving
            platform (its heading adds to the camera's mounting heading), else None.
        ais: a :class:`seawatch.io.ais.AisTable` to cross-check the tracks with.
        truth: ``truth.csv`` of ``seawatch synth`` to score the run against.
        start: absolute time of frame 0 [s since the epoch] (NAV/AIS alignment); None:
            from ``clip.json`` beside the source, else the NAV's first time.
        filter: the visual tracker's filter, ``afkf`` (default), ``fkf`` or ``kf``.
        estimator: the world estimator of the ``tracks.csv`` positions (``ekf``
            default; ``ukf``, ``diffuse-rls``, ``geometry``); all go to ``estimates.csv``.
        attitude: ``horizon`` (pitch and roll refined by the detected horizon each
            frame — a mast that sways by tenths of a degree moves the range at 1 km by
            several per cent), ``file`` (the camera file's attitude plus the NAV's
            pitch/roll) or ``auto`` (default: ``horizon`` on a moving platform, ``file``
            for a fixed camera, whose surveyed attitude needs no per-frame estimate; on
            the demo clip both give geometry 80 m RMS, the horizon being found to
            0.03 px).
        step, max_frames: frame decimation and limit.
        begin, end: the video times to track, ``begin <= time < end`` [s from the video's
            start] (``start`` stays the UTC time of the video's frame 0).
        fps: frame rate of an image folder [1/s] (its frames' times, hence speeds and
            how long a track coasts); None: 1, with a warning when positions are made.
        reconnect: attempts to reopen a live source that drops (:class:`VideoReader`);
            frames more than ``max(COAST_SECONDS, 3 step / fps)`` apart (a reconnection, a
            gap in a recording) restart the visual tracks with new ids.
        keep_up: drop frames when the job falls behind a source that does not wait, so
            that its outputs stay a few frames behind the source instead of ever further
            (:meth:`~seawatch.vision.tracker.VisualTracker.stream`; the tracks coast over
            the frames dropped, which are counted in ``frames_dropped``); None (default):
            for a source that sends frames in real time (a camera device, an RTSP, RTMP,
            UDP … stream), not for a file, a folder or an HTTP URL.
        sigma_px: 1-σ of the water-line pixel [px].
        annotate, report, parquet: write ``annotated.mp4``, ``report.html``,
            ``tracks.parquet``.
        detector: the ship detector (default: the classical detector).
        world_options: further keyword arguments of
            :class:`~seawatch.tracking.world.WorldTracker` (``sigma_a``, ``ar_order``, …).
        progress: ``progress(frames_done, frames_total_or_None)``.

    Returns:
        :class:`TrackRun`. Ctrl-C (KeyboardInterrupt) ends the run early with every
        output closed and the report written for the frames done (``interrupted``).

    Raises:
        ValueError: bad input, naming it (also raised by the readers:
            :class:`seawatch.io.video.VideoError` for a missing or undecodable video).
    """
    check_options(estimator, attitude)
    out = _prepare_out(Path(out_dir))
    notes: list[str] = []

    def note(text: str) -> None:
        notes.append(text)
        warnings.warn(text, stacklevel=3)

    if camera is None:
        note("no --camera: pixel tracks only (angle, range and position columns are empty)")
        if platform is not None or ais is not None:
            note("no --camera: --platform and --ais are ignored")
            platform = ais = None
    elif camera.height is None:
        raise ValueError("--camera: the camera file gives no height above the sea (height_m)")
    elif platform is None and (camera.lat is None or camera.lon is None):
        if ais is not None:
            raise ValueError(
                "--camera: the camera file has no lat/lon and there is no --platform NAV: "
                "AIS positions cannot be placed relative to the camera"
            )
    if ais is not None and len(getattr(ais, "skipped", ())):
        note(f"--ais: {ais.summary()}")  # undecodable messages are counted and skipped
    if start is None:
        start = read_clip_start(source)
    if start is None and platform is not None:
        start = float(platform.span[0])
        note(f"--platform: no --start; video time 0 taken as the NAV's first time {start:.3f} s")
    if ais is not None and start is None:
        note("--ais: no --start and no clip.json beside the video: AIS cross-check skipped")
        ais = None

    reader = VideoReader(
        source,
        step=step,
        max_frames=max_frames,
        start=begin,
        end=end,
        fps=fps,
        reconnect=reconnect,
    )
    if fps is None and reader.kind == "folder" and camera is not None:
        note(
            f"{source}: an image folder without --fps: frames taken 1 s apart (speeds, "
            "courses and forecasts assume it)"
        )
    fps = reader.fps or 25.0
    gap_limit = max(COAST_SECONDS, 3.0 * step / fps)  # [s] a longer gap ends every track
    coast = max(REPORT_COAST_FRAMES, round(COAST_SECONDS * fps / step))  # frames tracked
    # the world filters take the pixel tracks in the frame's rows: with horizon-stabilised
    # rows and their small vertical noise (VisualTracker's default) the point-wise
    # geometry gains (demo 54.0 -> 41.5 m) but the demo's EKF loses 1.5 m (31.0 -> 32.5 m),
    # its input filtered twice (README, ship-video)
    vtracker = VisualTracker(
        detector=detector, filter=filter, fps=fps, delete_after=coast, stabilise=False
    )
    pose = _Pose(camera, platform, start, attitude, notes) if camera is not None else None
    world = None
    if camera is not None:
        ifov = 1.0 / camera.fx
        world = WorldTracker(
            camera.height,
            sigma_angle=sigma_px * ifov,
            horizons=FORECAST_HORIZONS,
            best=estimator,
            frame_interval=step / fps,
            **{
                "sigma_a": WORLD_SIGMA_A,
                "robust_gate": WORLD_ROBUST_GATE,
                **dict(world_options or {}),
            },
        )
    lat0 = pose.lat0 if pose is not None else None
    lon0 = pose.lon0 if pose is not None else None

    tracks_out = TableWriter(out / "tracks.csv", TRACK_TABLE_COLUMNS, parquet=parquet)
    est_out = TableWriter(out / "estimates.csv", ESTIMATE_COLUMNS) if world is not None else None
    geo_sink = None
    if lat0 is not None and lon0 is not None:
        from seawatch.report.geojson import GeoJsonSink

        geo_sink = GeoJsonSink(
            out / "tracks.geojson", camera_lat=lat0, camera_lon=lon0, epoch=start
        )
    associator = None
    ais_every = 1
    if ais is not None and lat0 is not None:
        from seawatch.tracking.ais_match import AisAssociator

        associator = AisAssociator(ais, lat0=lat0, lon0=lon0)
        ais_every = max(1, round(fps / step / AIS_RATE))
    video_out = None
    first_index = 0  # annotated.mp4's first source frame
    total = reader.expected_frames
    done: list[int] = []  # source indices of the frames tracked (scored with --truth)
    ids: set[int] = set()
    labels: dict[int, int | None] = {}
    live_ids: set[int] = set()
    interrupted = False
    # the next frames are decoded in one thread and their horizons and ships found in
    # another (VisualTracker.stream) while this one is tracked and written
    frames_ahead = vtracker.stream(reader, keep_up=keep_up)
    size: tuple[int, int] | None = None
    last_time: float | None = None

    def restart(why: str) -> None:
        """New visual tracks (new ids) and no world tracks, with a note saying why."""
        nonlocal live_ids
        note(f"{why}: the visual tracks restart with new ids")
        vtracker.restart_tracks()
        if world is not None:
            world.drop(np.fromiter(live_ids, np.int64))
            live_ids = set()

    try:
        for frame, horizon, detections in frames_ahead:
            if last_time is not None and frame.time - last_time > gap_limit:
                restart(
                    f"frame {frame.index}: {frame.time - last_time:.1f} s after the frame before "
                    "(a stream that dropped, a gap in the recording)"
                )
            # frames lost in between (counted by the reader): the tracks coast over them
            vtracker.coast_to(frame.index, step)
            last_time = float(frame.time)
            shape = frame.image.shape
            if (shape[1], shape[0]) != size:
                if size is not None:  # the stream's resolution changed (VideoReader warns)
                    restart(
                        f"frame {frame.index}: the frame size changed from {size[0]}x{size[1]} "
                        f"to {shape[1]}x{shape[0]}"
                    )
                size = (shape[1], shape[0])
                if pose is not None and camera is not None:
                    where = f"frame {frame.index} of {source}"
                    pose.camera = _camera_for(camera, size, where)
                    if size != camera.image_size:
                        s = size[0] / camera.image_size[0]
                        note(
                            f"--camera: calibrated for {camera.image_size[0]}x"
                            f"{camera.image_size[1]} frames, {where} is {size[0]}x{size[1]}: "
                            f"the intrinsics are scaled by {s:.4g}"
                        )
            rows = vtracker.update(detections)
            t = float(frame.time)
            k = rows.shape[0]
            tids = rows[:, 0].astype(np.int64)
            records: list[dict[str, Any]] = [
                {
                    "time": t,
                    "frame": int(frame.index),
                    "track_id": int(tids[i]),
                    **dict(
                        zip(
                            BOX_COLUMNS,
                            map(float, rows[i, 1:7]),
                            strict=True,
                        )
                    ),
                }
                for i in range(k)
            ]
            shown = rows[:, 7] <= REPORT_COAST_FRAMES  # rows to write (all: world filters)
            if world is not None and pose is not None:
                gone = live_ids - set(tids.tolist())
                if gone:
                    world.drop(np.fromiter(gone, np.int64))
                live_ids = set(tids.tolist())
                cam, ppose = pose.at(t, horizon, vtracker.camera_zoom)
                if cam is not None and k:
                    az, dep, cov = _angles(cam, rows[:, 5:7], sigma_px)
                    # a coasting visual track (no detection this frame) reports its pixel
                    # prediction: no measurement for the world filters
                    coasting = rows[:, 7] > 0
                    estimates = world.update(
                        t,
                        tids,
                        np.where(coasting, np.nan, az),
                        np.where(coasting, np.nan, dep),
                        angle_covariance=cov,
                        platform=ppose,
                    )
                    best = estimates[estimator]
                    for i, rec in enumerate(records):
                        rec["azimuth_deg"] = math.degrees(float(az[i]))
                        rec["depression_deg"] = math.degrees(float(dep[i]))
                    est_rows = [
                        {**rec, "estimator": name, **_estimate_cells(est, i)}
                        for name, est in estimates.items()
                        for i, rec in enumerate(records)
                    ]
                    _add_geodetic(est_rows, lat0, lon0)
                    # tracks.csv rows are the chosen estimator's rows of estimates.csv
                    first = list(estimates).index(estimator) * len(records)
                    for i, rec in enumerate(records):
                        rec.update(est_rows[first + i])
                    for j, row in enumerate(est_rows):
                        if shown[j % k]:
                            est_out.write(row)  # type: ignore[union-attr]
                    if associator is not None and len(done) % ais_every == 0:
                        view = _view_wedge(cam, ppose)
                        vel = np.stack(
                            [best.speed * np.cos(best.course), best.speed * np.sin(best.course)], -1
                        )
                        labels.update(
                            associator.update(
                                start + t, tids, best.north, best.east, best.covariance, vel, view
                            )
                        )
                    for rec in records:
                        mmsi = labels.get(rec["track_id"])
                        rec["mmsi"] = mmsi
                elif k:
                    for rec in records:
                        rec["estimator"] = estimator
            records = [rec for i, rec in enumerate(records) if shown[i]]
            for rec in records:
                tracks_out.write(rec)
                ids.add(rec["track_id"])
            tracks_out.flush()
            if est_out is not None:
                est_out.flush()
            if geo_sink is not None:
                geo_sink.add(records, t)
            if annotate:
                if video_out is None:
                    from seawatch.report.annotate import AnnotatedVideo

                    h, w = frame.image.shape[:2]
                    video_out = AnnotatedVideo(out / "annotated.mp4", fps / step, (w, h))
                    first_index = int(frame.index)
                # at the source's time: frames dropped to keep up or lost leave gaps
                pts = max((int(frame.index) - first_index) // step, video_out.last_pts + 1)
                video_out.write(
                    frame.image, records, horizon, time=t, frame=int(frame.index), fit=True,
                    pts=pts,
                )  # fmt: skip
            done.append(int(frame.index))
            if progress is not None:
                progress(len(done), total)
    except KeyboardInterrupt:
        interrupted = True
        note(f"interrupted after {len(done)} frames; outputs hold every frame done")
    finally:
        frames_ahead.close()  # type: ignore[attr-defined]
        outputs = tracks_out.close()
        if est_out is not None:
            outputs += est_out.close()
        if video_out is not None:
            video_out.close()
            outputs.append(out / "annotated.mp4")
        if geo_sink is not None:
            g = geo_sink.close()
            if g is not None:
                outputs.append(g)
    ais_doc = associator.result().as_dict() if associator is not None else None
    errors = None
    if truth is not None:
        from seawatch.metrics.track_errors import score_tracks

        errors = score_tracks(
            out / "tracks.csv",
            truth,
            camera=camera,
            estimates=out / "estimates.csv" if est_out is not None else None,
            min_truth_height=MIN_TRUTH_PX,
            frames=done,  # a frame skipped by --step or --max-frames is no miss
        ).to_json()
    if vtracker.frames_dropped:
        notes.append(
            f"{vtracker.frames_dropped} frame(s) dropped to keep up with the source "
            "(their tracks coasted)"
        )
    run = TrackRun(
        frames=len(done),
        frames_dropped=vtracker.frames_dropped,
        rows=tracks_out.rows,
        tracks=len(ids),
        outputs=outputs,
        warnings=notes,
        errors=errors,
        ais=ais_doc,
        interrupted=interrupted,
    )
    if report:
        from seawatch.report.html import write_report

        summary = {**run.to_json(), "source": str(source), "fps": fps}
        path = write_report(
            out / "report.html", out / "tracks.csv", camera=camera, summary=summary,
            errors=errors, ais=ais_doc,
        )  # fmt: skip
        run.outputs.append(path)
    return run


def error_summary(errors: Mapping[str, Any] | None) -> list[str]:
    """Three lines summarising an ``errors`` object (``seawatch demo``)."""
    if not errors:
        return []
    e = errors
    n = e.get("id_switches", 0)
    return [
        f"position RMSE {e.get('rmse_position_m', float('nan')):.1f} m, range error "
        f"{e.get('rmse_range_percent', float('nan')):.2f} %",
        f"MOTA {e.get('mota', float('nan')):.3f}, IDF1 {e.get('idf1', float('nan')):.3f}, "
        f"{n} identity switch{'' if n == 1 else 'es'}",
        f"box centre error {e.get('cle_px', float('nan')):.1f} px",
    ]
