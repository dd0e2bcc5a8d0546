"""The ``ship-video`` cases (SCENARIOS.md, seed 001): rendered CCTV-like sequences.

The paper's CCTV videos are not available, so the project renders equivalent sequences
with ground truth. A shore camera on a mast (15 m above the sea, 60° horizontal field of
view, looking 3° down, by default 1920×1080 at 25 frames/s, 10 s) at Southsea,
looking south over Spithead, watches:

==============  ==========================================================================
``small``       a 10 m boat 1.6 km out crossing the view — a few pixels high
``medium``      a 40 m workboat 1 km out, turning slowly towards the camera
``large``       a 150 m container ship 1.5 km out
``lighting``    a ferry crossing a strong sun-glint path under uneven light (clouds, cloud
                shadows), the sun low in view — the paper's "complex lighting"
``night``       thermal-like night footage: a workboat and a cargo ship
``meeting``     two ships on reciprocal courses passing each other (the nearer one
                occludes the farther one)
``overtaking``  a ferry overtaking a slower workboat on a parallel course
``crossing``    four ships of different sizes crossing near one point, coastline behind
==============  ==========================================================================

Every case moves the camera with a small mast sway (a few tenths of a degree of roll and
pitch). Encounters are timed from the clip's middle, so a longer ``duration`` keeps the
event in view.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from seawatch.camera import PinholeCamera
from seawatch.synth.render import Lighting, RenderResult, lighting_preset, render
from seawatch.synth.world import (
    Ship,
    Trajectory,
    crossing,
    make_ship,
    meeting,
    overtaking,
    through,
    turning,
)

__all__ = ["CASES", "ShipVideoCase", "case_camera", "render_case", "ship_video_case"]

CASES: tuple[str, ...] = (
    "small",
    "medium",
    "large",
    "lighting",
    "night",
    "meeting",
    "overtaking",
    "crossing",
)
"""Case names of ``seawatch synth ship-video --case``."""

CAMERA_LAT = 50.7780
CAMERA_LON = -1.0880
CAMERA_HEADING = math.pi  # south
CAMERA_HEIGHT = 15.0
CAMERA_PITCH = math.radians(-3.0)
HFOV_DEG = 60.0


@dataclass(frozen=True)
class ShipVideoCase:
    """A rendered ship-video case: everything :func:`seawatch.synth.render` needs.

    Attributes:
        name, description: the case.
        camera: the camera (mounting attitude, height 15 m, geodetic position).
        ships: the ships and their trajectories (times 0 … duration).
        lighting: the lighting.
        sway: (roll_amp [rad], pitch_amp [rad], period [s]).
        coastline: whether a coastline stands on the horizon.
        seed: the render seed.
    """

    name: str
    description: str
    camera: PinholeCamera
    ships: tuple[Ship, ...]
    lighting: Lighting
    sway: tuple[float, float, float] | None
    coastline: bool
    seed: int


def case_camera(width: int = 1920, height: int = 1080) -> PinholeCamera:
    """The cases' shore camera: 60° hfov, 15 m up, heading south, pitched 3° down."""
    return PinholeCamera.from_fov(
        width,
        height,
        HFOV_DEG,
        height=CAMERA_HEIGHT,
        heading=CAMERA_HEADING,
        pitch=CAMERA_PITCH,
        lat=CAMERA_LAT,
        lon=CAMERA_LON,
    )


def _at(forward: float, right: float) -> tuple[float, float]:
    """(north, east) [m] of a point ``forward`` along and ``right`` of the camera axis."""
    c, s = math.cos(CAMERA_HEADING), math.sin(CAMERA_HEADING)
    return forward * c - right * s, forward * s + right * c


def _course(relative_deg: float) -> float:
    """World course [rad] of a course given relative to the camera heading [deg]
    (+90 = moving right across the image)."""
    return CAMERA_HEADING + math.radians(relative_deg)


def _pass(
    forward: float, right: float, rel_course: float, speed: float, at: float, end: float
) -> Trajectory:
    n, e = _at(forward, right)
    return through(n, e, _course(rel_course), speed, at, start=0.0, end=end)


_SWAY = (math.radians(0.25), math.radians(0.18), 6.5)


def _small(d: float) -> tuple[list[Ship], dict]:
    ships = [make_ship(1, _pass(1600.0, 0.0, 88.0, 5.0, d / 2, d), 10.0, kind="boat")]
    return ships, {"sway": (math.radians(0.1), math.radians(0.08), 7.0)}


def _medium(d: float) -> tuple[list[Ship], dict]:
    n, e = _at(1000.0, -0.6 * 7.0 * d / 2)
    traj = turning(
        n,
        e,
        _course(95.0),
        7.0,
        d,
        turn_rate=math.radians(0.8),
        turn_start=0.3 * d,
        turn_end=0.8 * d,
    )
    return [make_ship(1, traj, 40.0, kind="workboat")], {"sway": _SWAY}


def _large(d: float) -> tuple[list[Ship], dict]:
    ships = [make_ship(1, _pass(1500.0, 60.0, -92.0, 7.0, d / 2, d), 150.0, kind="cargo")]
    return ships, {"sway": _SWAY}


def _lighting(d: float) -> tuple[list[Ship], dict]:
    sun_rel = 8.0
    glint_right = 900.0 * math.tan(math.radians(sun_rel))
    ships = [
        make_ship(1, _pass(900.0, glint_right, 90.0, 6.0, d / 2, d), 60.0, kind="ferry"),
        make_ship(
            2,
            _pass(1400.0, 1400.0 * math.tan(math.radians(sun_rel)) - 110.0, -85.0, 4.0, d / 2, d),
            12.0,
            kind="boat",
        ),
    ]
    light = lighting_preset(
        "day",
        sun_azimuth=math.radians(sun_rel),
        sun_elevation=math.radians(4.0),
        glint=1.0,
        glint_spread=(math.radians(4.0), math.radians(3.5)),
        clouds=0.6,
        cloud_shadows=0.8,
        sky_zenith=(110.0, 150.0, 200.0),
    )
    return ships, {"sway": _SWAY, "lighting": light}


def _night(d: float) -> tuple[list[Ship], dict]:
    ships = [
        make_ship(1, _pass(800.0, -40.0, 80.0, 6.0, d / 2, d), 30.0, kind="workboat"),
        make_ship(2, _pass(2000.0, 150.0, -95.0, 7.5, d / 2, d), 120.0, kind="cargo"),
    ]
    return ships, {"sway": _SWAY, "lighting": lighting_preset("night")}


def _meeting(d: float) -> tuple[list[Ship], dict]:
    n, e = _at(1200.0, 0.0)
    # course to the right; the first ship keeps to port of the point (farther away); they
    # start apart in the image, overlap at mid-clip and end apart again
    a, b = meeting(n, e, _course(90.0), (8.0, 8.0), 140.0, d / 2, start=0.0, end=d)
    ships = [
        make_ship(1, a, 60.0, kind="ferry"),
        make_ship(2, b, 35.0, kind="workboat"),
    ]
    return ships, {"sway": _SWAY}


def _overtaking(d: float) -> tuple[list[Ship], dict]:
    n, e = _at(1100.0, 0.0)
    slow, fast = overtaking(n, e, _course(-90.0), (3.5, 9.0), 110.0, d / 2, start=0.0, end=d)
    ships = [
        make_ship(1, slow, 35.0, kind="workboat"),
        make_ship(2, fast, 80.0, kind="ferry"),
    ]
    return ships, {"sway": _SWAY}


def _crossing(d: float) -> tuple[list[Ship], dict]:
    # two ships whose image paths cross at mid-clip (the nearer in front), a boat running
    # diagonally across both, and a slow sailboat beyond
    trajs = crossing(
        *_at(0.0, 0.0),
        courses=[_course(90.0), _course(-90.0)],
        speeds=[9.0, 7.0],
        at_times=[0.5 * d, 0.5 * d],
        offsets=[-900.0, 1700.0],  # to each ship's starboard: 900 m and 1700 m out
        start=0.0,
        end=d,
    )
    boat = _pass(600.0, -60.0, 135.0, 8.0, 0.3 * d, d)
    sail = _pass(1200.0, 120.0, -60.0, 3.0, 0.7 * d, d)
    ships = [
        make_ship(1, trajs[0], 60.0, kind="ferry"),
        make_ship(2, trajs[1], 110.0, kind="cargo"),
        make_ship(3, boat, 14.0, kind="boat"),
        make_ship(4, sail, 12.0, kind="sailboat"),
    ]
    return ships, {"sway": _SWAY, "coastline": True}


_BUILDERS: dict[str, tuple[Callable[[float], tuple[list[Ship], dict]], str]] = {
    "small": (_small, "a 10 m boat 1.6 km out: a small target a few pixels high"),
    "medium": (_medium, "a 40 m workboat 1 km out, turning slowly"),
    "large": (_large, "a 150 m container ship 1.5 km out"),
    "lighting": (_lighting, "complex lighting: sun low in view, strong glint, cloud shadows"),
    "night": (_night, "thermal-like night footage: two ships"),
    "meeting": (_meeting, "two ships meeting head-on, the nearer occluding the farther"),
    "overtaking": (_overtaking, "a ferry overtaking a slower workboat"),
    "crossing": (_crossing, "four ships of different sizes crossing, coastline behind"),
}


def ship_video_case(
    name: str,
    *,
    duration: float = 10.0,
    width: int = 1920,
    height: int = 1080,
    seed: int = 0,
) -> ShipVideoCase:
    """The case ``name`` (:data:`CASES`) for a clip of ``duration`` [s] at width×height [px].

    ``seed`` is offset by the case's index so that the cases differ from each other.
    """
    if name not in _BUILDERS:
        raise ValueError(f"case: unknown case {name!r}; expected one of {', '.join(CASES)}")
    if not duration > 0.0 or not math.isfinite(duration):
        raise ValueError(f"duration: expected a positive number of seconds, got {duration!r}")
    build, description = _BUILDERS[name]
    ships, opts = build(float(duration))
    return ShipVideoCase(
        name=name,
        description=description,
        camera=case_camera(width, height),
        ships=tuple(ships),
        lighting=opts.get("lighting", lighting_preset("day")),
        sway=opts.get("sway"),
        coastline=bool(opts.get("coastline", False)),
        seed=int(seed) + CASES.index(name),
    )


def render_case(
    name: str,
    out_dir: str | Path,
    *,
    duration: float = 10.0,
    fps: float = 25.0,
    width: int = 1920,
    height: int = 1080,
    seed: int = 0,
    progress: Callable[[int, int], None] | None = None,
    crf: int = 20,
    pan: tuple[float, float] | None = None,
) -> RenderResult:
    """Render the case ``name`` into ``out_dir`` (video.mp4, camera.yaml, truth.csv,
    horizon.csv) with :func:`seawatch.synth.render` (``crf``: libx264's quality, 0
    lossless; ``pan``: (amplitude [rad], period [s]) of a camera panning to and fro, as
    :class:`~seawatch.synth.render.Renderer`; None: the case's fixed heading)."""
    case = ship_video_case(name, duration=duration, width=width, height=height, seed=seed)
    return render(
        case.camera,
        case.ships,
        duration,
        fps,
        out_dir=out_dir,
        lighting=case.lighting,
        sway=case.sway,
        coastline=case.coastline,
        seed=case.seed,
        progress=progress,
        crf=crf,
        pan=pan,
        description=f"seawatch synth ship-video --case {name}: {case.description}",
    )
