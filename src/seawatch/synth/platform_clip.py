"""Rendered footage from a camera on a MOVING platform, with NAV and world-frame truth.

The renderer (:func:`seawatch.synth.render`) films from a fixed camera. A camera of fixed
attitude (heading, pitch, roll) on a platform moving at ``p_o(t)`` sees a ship at
``p(t)`` exactly where a fixed camera at the origin sees a ship at ``p(t) − p_o(t)``: the
projection depends only on the relative position and the attitude (ALGORITHMS.md §4.1,
seed 000 eqs. 1–2). :func:`render_platform_clip` therefore renders the targets' motion
*relative* to the platform with the existing renderer (camera heading = the platform's
heading, the ships keeping their world headings, so their silhouettes are right), then
writes, beside the renderer's outputs, what a real moving-platform recording gives:

- ``nav.csv`` — the platform track in the NAV CSV format of
  :func:`seawatch.io.nav.read_nav`: ``time`` [s] (video time: ``start = 0``), ``lat``,
  ``lon`` [deg], ``heading`` [deg] (the camera's heading, so the camera file's mounting
  heading is 0); one row per frame and one after the last;
- ``camera.yaml`` — rewritten as the *mounted* camera: mounting heading 0, the render's
  pitch, roll and height, no position (the NAV gives it); the render's fixed camera is
  kept as ``render_camera.yaml``;
- ``truth_world.csv`` — ``truth.csv`` with ``east_m``, ``north_m``, ``lat``, ``lon`` in the
  world frame (relative position + platform position; the tangent plane at the
  platform's start, which is the NAV's first fix and so the pipeline's origin),
  ``speed_mps`` the target's world speed, ``range_m`` (and every pixel and angle column)
  unchanged, and two added columns ``platform_north_m``, ``platform_east_m`` (the
  camera's foot point of that frame [m]);
- ``clip.json`` — the parameters, the platform and target motion, the render summary.

What this neglects: the sea texture's apparent motion — the waves are drawn as on a sea at
rest relative to the camera, so the sea does not stream past as the platform moves (a
detector that keys on the background flow would see none); the platform's heading is
constant (no yaw), and its pitch and roll are the renderer's sway only. Ship shapes,
water-line pixels, horizon, occlusion and truth are exact.

Scoring: :func:`score_platform_run` scores a run against ``truth_world.csv``, whose
``platform_north_m``/``platform_east_m`` columns make
:func:`seawatch.metrics.track_errors.score_tracks` measure each row's range from the moving
camera (the range columns and range bins), world positions as they are.

Presets (:data:`PRESETS`, :func:`platform_clip_preset`):

``uav-sea``
    SCENARIOS.md ``uav-sea``: h = 3 m, 1920×1080, 70° HFOV, platform from (0, 0) at
    (2.55, 4.33) m/s (North, East), heading 50°; a 20 m workboat from (400, 600) m at
    (−2.98, −3.12) m/s; 71 s (it leaves the field of view at 71.2 s), range 721 → 70 m.
``range-1km``
    the issue's "range error under 5 % at 1 km for a 10 m camera height": h = 10 m,
    platform heading 90° at 3 m/s; a 50 m ferry crossing the view left to right at
    8 m/s while its range falls from 1180 m to 980 m; 60 s.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from seawatch._validation import in_range, positive, vector
from seawatch.camera import PinholeCamera
from seawatch.geometry import north_east_to_geodetic
from seawatch.synth.render import TRUTH_COLUMNS, RenderResult, render
from seawatch.synth.world import KINDS, Trajectory, make_ship

__all__ = [
    "DEFAULT_LAT0",
    "DEFAULT_LON0",
    "PRESETS",
    "ClipTarget",
    "PlatformClip",
    "platform_clip_preset",
    "render_platform_clip",
    "score_platform_run",
]

DEFAULT_LAT0 = 50.70
"""Latitude [deg] of the platform's start (open water south-east of the Solent)."""
DEFAULT_LON0 = -1.05
"""Longitude [deg] of the platform's start."""

SWAY = (math.radians(0.25), math.radians(0.18), 6.5)
"""Default sway (roll amplitude [rad], pitch amplitude [rad], period [s]): the
``ship-video`` cases' mast sway."""

WORLD_EXTRA_COLUMNS = ("platform_north_m", "platform_east_m")
"""Columns added to ``truth_world.csv`` (the platform's position of the frame [m])."""


@dataclass(frozen=True)
class ClipTarget:
    """A ship moving at constant velocity in the world frame.

    Attributes:
        north, east: position at video time 0 [m] in the tangent plane at the platform's
            start (x North, y East).
        velocity: (v_north, v_east) [m/s].
        length: overall length [m]; kind: a :data:`seawatch.synth.world.KINDS` name or
            None (by length).
        object_id: its truth id.
    """

    north: float
    east: float
    velocity: tuple[float, float]
    length: float = 20.0
    kind: str | None = "workboat"
    object_id: int = 1

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        p = vector("position", (self.north, self.east), 2)
        set_(self, "north", float(p[0]))
        set_(self, "east", float(p[1]))
        v = vector("velocity", self.velocity, 2)
        set_(self, "velocity", (float(v[0]), float(v[1])))
        set_(self, "length", positive("length", self.length))
        if self.kind is not None and self.kind not in KINDS:
            raise ValueError(f"kind: expected one of {', '.join(KINDS)}, got {self.kind!r}")

    @property
    def course(self) -> float:
        """World course over ground [rad], clockwise from North (its bow direction)."""
        return math.atan2(self.velocity[1], self.velocity[0]) % (2.0 * math.pi)

    def position(self, t: Any) -> np.ndarray:
        """(north, east) [m] at times ``t`` [s], (..., 2)."""
        t = np.asarray(t, dtype=np.float64)[..., None]
        return np.array([self.north, self.east]) + t * np.asarray(self.velocity)


@dataclass(frozen=True)
class PlatformClip:
    """What :func:`render_platform_clip` wrote (all paths in ``out_dir``).

    Attributes:
        out_dir, video, camera (mounted camera file), render_camera, truth (relative,
            the renderer's), truth_world, nav, horizon, meta (``clip.json``).
        render: the renderer's :class:`~seawatch.synth.render.RenderResult`.
        mounted: the mounted camera (heading 0, no position).
        lat0, lon0: the world frame's geodetic origin [deg] (the platform's start).
        platform_velocity: (v_north, v_east) [m/s]; heading: camera heading [rad].
        targets: the targets.
    """

    out_dir: Path
    video: Path
    camera: Path
    render_camera: Path
    truth: Path
    truth_world: Path
    nav: Path
    horizon: Path
    meta: Path
    render: RenderResult
    mounted: PinholeCamera
    lat0: float
    lon0: float
    platform_velocity: tuple[float, float]
    heading: float
    targets: tuple[ClipTarget, ...] = field(default_factory=tuple)

    def platform_position(self, t: Any) -> np.ndarray:
        """Platform (north, east) [m] at video times ``t`` [s], (..., 2)."""
        t = np.asarray(t, dtype=np.float64)[..., None]
        return t * np.asarray(self.platform_velocity)


PRESETS: Mapping[str, Mapping[str, Any]] = {
    "uav-sea": {
        "height": 3.0,
        "platform_velocity": (2.55, 4.33),
        "heading": math.radians(50.0),
        "targets": (ClipTarget(400.0, 600.0, (-2.98, -3.12), 20.0, "workboat", 1),),
        "duration": 71.0,
        "pitch": math.radians(-1.0),
    },
    "range-1km": {
        "height": 10.0,
        "platform_velocity": (0.0, 3.0),
        "heading": math.radians(90.0),
        # forward 1150 m (East), 250 m left (North) of the camera axis, crossing to the
        # right (South) at 8 m/s and closing at 0.3 m/s: range 1177 → ~980 m in 60 s
        "targets": (ClipTarget(250.0, 1150.0, (-8.0, -0.3), 50.0, "ferry", 1),),
        "duration": 60.0,
        "pitch": math.radians(-1.0),
    },
}
"""Named clips (module docstring): keyword arguments of :func:`render_platform_clip`."""


def platform_clip_preset(name: str, **changes: Any) -> dict[str, Any]:
    """The keyword arguments of preset ``name`` (:data:`PRESETS`) with ``changes``."""
    if name not in PRESETS:
        raise ValueError(f"name: expected one of {', '.join(PRESETS)}, got {name!r}")
    return {**PRESETS[name], **changes}


def render_platform_clip(
    out_dir: str | Path,
    *,
    height: float = 3.0,
    platform_velocity: Sequence[float] = (2.55, 4.33),
    heading: float = math.radians(50.0),
    targets: Sequence[ClipTarget] | None = None,
    duration: float = 71.0,
    fps: float = 10.0,
    width: int = 1920,
    height_px: int = 1080,
    hfov: float = 70.0,
    pitch: float = math.radians(-1.0),
    roll: float = 0.0,
    sway: tuple[float, float, float] | None = SWAY,
    seed: int = 0,
    lat0: float = DEFAULT_LAT0,
    lon0: float = DEFAULT_LON0,
    lighting: str = "day",
    earth: str = "curved",
    progress: Callable[[int, int], None] | None = None,
) -> PlatformClip:
    """Render footage from a camera on a platform moving at constant velocity.

    The targets' motion relative to the platform is rendered by a fixed camera at the
    origin with the platform's heading (module docstring); NAV, mounted camera and
    world-frame truth are written beside the video. Default: SCENARIOS.md ``uav-sea``.

    Args:
        out_dir: output folder (created).
        height: camera height above the sea [m], > 0.
        platform_velocity: (v_north, v_east) [m/s]; the platform starts at (0, 0).
        heading: camera (and NAV) heading [rad], clockwise from North.
        targets: ships (:class:`ClipTarget`, world frame); None: the ``uav-sea`` target.
        duration: clip length [s]; fps: frame rate [1/s].
        width, height_px: image size [px] (even; a multiple of 4 — the encoder's YUV
            4:2:0 planes); hfov: horizontal field of view [deg].
        pitch, roll: mounting attitude [rad] (pitch < 0 looks down).
        sway: (roll amplitude [rad], pitch amplitude [rad], period [s]) or None.
        seed: render seed (waves, noise).
        lat0, lon0: geodetic position of the platform's start [deg].
        lighting, earth: as :func:`seawatch.synth.render` (default curved sea, as the
            pipeline's world estimators assume).
        progress: ``progress(done, total)`` per rendered frame.

    Returns:
        :class:`PlatformClip`.

    Raises:
        ValueError: naming the argument, for bad parameters.
    """
    from seawatch.io import save_camera

    h = positive("height", height)
    vp = vector("platform_velocity", platform_velocity, 2)
    vp_t = (float(vp[0]), float(vp[1]))
    psi = float(in_range("heading", heading, -4.0 * math.pi, 4.0 * math.pi)) % (2.0 * math.pi)
    dur = positive("duration", duration)
    f = positive("fps", fps)
    la0 = float(in_range("lat0", lat0, -89.0, 89.0))
    lo0 = float(in_range("lon0", lon0, -180.0, 180.0))
    tgts = tuple(PRESETS["uav-sea"]["targets"] if targets is None else targets)
    if not tgts:
        raise ValueError("targets: expected at least one ClipTarget")
    for i, tg in enumerate(tgts):
        if not isinstance(tg, ClipTarget):
            raise ValueError(f"targets[{i}]: expected a ClipTarget, got {type(tg).__name__}")
    if len({tg.object_id for tg in tgts}) != len(tgts):
        raise ValueError("targets: object ids must be distinct")

    if int(width) != width or width < 16 or int(width) % 2:
        raise ValueError(f"width: expected an even number of pixels >= 16, got {width!r}")
    if int(height_px) != height_px or height_px < 16 or int(height_px) % 4:
        raise ValueError(f"height_px: expected a multiple of 4 pixels >= 16, got {height_px!r}")
    cam = PinholeCamera.from_fov(
        int(width), int(height_px), float(hfov), height=h, heading=psi, pitch=pitch, roll=roll
    )
    n_frames = max(1, round(dur * f))
    t_end = n_frames / f
    ts = np.array([0.0, t_end + 1.0])
    ships = []
    for tg in tgts:
        rel = tg.position(ts) - ts[:, None] * np.asarray(vp_t)
        traj = Trajectory(ts, rel[:, 0], rel[:, 1], np.full(2, tg.course))
        ships.append(make_ship(tg.object_id, traj, tg.length, kind=tg.kind))

    out = Path(out_dir)
    result = render(
        cam,
        ships,
        dur,
        f,
        out_dir=out,
        lighting=lighting,
        sway=sway,
        seed=seed,
        earth=earth,  # type: ignore[arg-type]
        progress=progress,
        description="moving-platform clip: fixed camera rendering the relative motion",
    )
    render_cam = out / "render_camera.yaml"
    save_camera(cam, render_cam, description="the renderer's fixed camera (relative frame)")
    mounted = cam.with_attitude(heading=0.0)
    save_camera(mounted, result.camera, description="mounted camera; heading from nav.csv")

    # NAV: one row per frame and one after the last (pose_at interpolates)
    nav_t = np.arange(n_frames + 1) / f
    nav_p = nav_t[:, None] * np.asarray(vp_t)
    nav_lat, nav_lon = north_east_to_geodetic(nav_p, la0, lo0)
    nav_path = out / "nav.csv"
    with nav_path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(("time", "lat", "lon", "heading"))
        for t, la, lo in zip(nav_t, np.atleast_1d(nav_lat), np.atleast_1d(nav_lon), strict=True):
            w.writerow((f"{t:.6f}", f"{la:.10f}", f"{lo:.10f}", f"{math.degrees(psi):.6f}"))

    speeds = {tg.object_id: math.hypot(*tg.velocity) for tg in tgts}
    world_path = out / "truth_world.csv"
    _world_truth(result.truth, world_path, vp_t, la0, lo0, speeds)

    clip = PlatformClip(
        out_dir=out,
        video=result.video,
        camera=result.camera,
        render_camera=render_cam,
        truth=result.truth,
        truth_world=world_path,
        nav=nav_path,
        horizon=result.horizon,
        meta=out / "clip.json",
        render=result,
        mounted=mounted,
        lat0=la0,
        lon0=lo0,
        platform_velocity=vp_t,
        heading=psi,
        targets=tgts,
    )
    meta = {
        "kind": "seawatch-platform-clip/1",
        "start_epoch": 0.0,
        "height_m": h,
        "heading_deg": math.degrees(psi),
        "platform_velocity_mps": list(vp_t),
        "lat0": la0,
        "lon0": lo0,
        "hfov_deg": float(hfov),
        "image_size": [int(width), int(height_px)],
        "pitch_deg": math.degrees(pitch),
        "roll_deg": math.degrees(roll),
        "sway": None if sway is None else [math.degrees(sway[0]), math.degrees(sway[1]), sway[2]],
        "earth": earth,
        "targets": [
            {
                "object_id": tg.object_id,
                "north_m": tg.north,
                "east_m": tg.east,
                "velocity_mps": list(tg.velocity),
                "length_m": tg.length,
                "kind": tg.kind,
            }
            for tg in tgts
        ],
        "render": result.to_json(),
    }
    clip.meta.write_text(json.dumps(meta, indent=2, default=str) + "\n", encoding="utf-8")
    return clip


def _world_truth(
    src: Path,
    dst: Path,
    vp: tuple[float, float],
    lat0: float,
    lon0: float,
    speeds: Mapping[int, float],
) -> None:
    """``truth.csv`` (relative) → ``truth_world.csv`` (module docstring)."""
    with src.open(newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    with dst.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow((*TRUTH_COLUMNS, *WORLD_EXTRA_COLUMNS))
        if not rows:
            return
        t = np.array([float(r["time"]) for r in rows])
        pn, pe = t * vp[0], t * vp[1]
        north = np.array([float(r["north_m"]) for r in rows]) + pn
        east = np.array([float(r["east_m"]) for r in rows]) + pe
        lat, lon = north_east_to_geodetic(np.stack([north, east], -1), lat0, lon0)
        lat, lon = np.atleast_1d(lat), np.atleast_1d(lon)
        for i, r in enumerate(rows):
            r = dict(r)
            r["north_m"], r["east_m"] = f"{north[i]:.4f}", f"{east[i]:.4f}"
            r["lat"], r["lon"] = f"{lat[i]:.9f}", f"{lon[i]:.9f}"
            r["speed_mps"] = f"{speeds.get(int(r['object_id']), math.nan):.4f}"
            w.writerow((*(r[c] for c in TRUTH_COLUMNS), f"{pn[i]:.4f}", f"{pe[i]:.4f}"))


# ------------------------------------------------------------------------------ scoring
def score_platform_run(run_dir: str | Path, clip_dir: str | Path, **options: Any) -> Any:
    """Score a pipeline run on a platform clip (module docstring, "Scoring").

    ``run_dir`` holds the run's ``tracks.csv`` (and ``estimates.csv``); ``clip_dir`` the
    clip's ``truth_world.csv``. ``options`` go to
    :func:`seawatch.metrics.track_errors.score_tracks` (default ``min_truth_height`` = the
    pipeline's ``MIN_TRUTH_PX``). Returns its
    :class:`~seawatch.metrics.track_errors.TrackErrors`: ranges and range bins from the
    moving camera.
    """
    from seawatch.metrics.track_errors import score_tracks
    from seawatch.pipeline import MIN_TRUTH_PX

    run = Path(run_dir)
    estimates = run / "estimates.csv"
    opts = {"min_truth_height": MIN_TRUTH_PX, **options}
    return score_tracks(
        run / "tracks.csv",
        Path(clip_dir) / "truth_world.csv",
        estimates=estimates if estimates.is_file() else None,
        **opts,
    )
