"""Synthetic sea footage with exact ground truth: the renderer behind `seawatch synth`.

A camera (`seawatch.camera.PinholeCamera`, with a height above the sea) watches ships
(`seawatch.synth.world.Ship`) move over the sea. Each frame is drawn and its ground truth
computed from the same projection, so the truth is exact:

- World (ALGORITHMS.md "Conventions", §4.1): local NED, the camera ``height`` metres above
  the sea at its ``position`` (x North, y East). ``earth="flat"`` (default): the sea is
  the plane ``down = +height`` below the camera, so a point (n, e, z up) is seen along
  the NED vector ``(n - n_c, e - e_c, height - z)`` — exactly what the flat-sea ranging
  of §4.1 (`seawatch.geometry.sea_position`) inverts. ``earth="curved"``: the sea is the
  sphere of effective radius ``R_e = R / (1 - k)`` (§4.2, k = 0.14), the point at arc
  distance D sits ``2 (R_e + z) sin^2(D / 2 R_e)`` lower and ``(R_e + z) sin(D / R_e)``
  away — what `sea_depression(..., curved=True)` describes.
- Projection: every hull/superstructure corner is projected with the camera of that
  frame (`PinholeCamera.ray_to_pixel`, lens distortion included), the frame's camera
  being the mounting attitude plus the sway (:func:`sway_attitude`). A prism's silhouette
  is the convex hull of its projected corners; ships are painted far to near (occlusion
  by depth order).
- Horizon: `seawatch.camera.horizon_line` of the frame's camera (the visible horizon at
  the dip of §4.2 for the camera height); ships farther than the horizon distance
  (`seawatch.geometry.horizon_distance`) are hidden. On the flat sea a water line
  farther than half the horizon distance projects above that line (the flat sea's own
  horizon is the true horizontal): use ``earth="curved"`` for long ranges (AIS traffic).
  Ships with a corner less than 1 m in front of the camera are not drawn (and have no
  truth row).

Ground truth per frame (INTERFACES.md "Synthetic footage"): ``truth.csv`` — one row per
visible object: ``time`` (video time [s]), ``frame``, ``object_id``, ``x``, ``y``, ``w``,
``h`` (box: the extent of the visible projected silhouette, clipped to the image,
in pixel coordinates with the origin at the centre of the top-left pixel, so a box
covering pixel columns i..j has x = i - 0.5 and w = j - i + 1), ``u_wl``, ``v_wl`` (the
water-line pixel: the projection of the ship's reference point, midship on the
waterline), ``east_m``, ``north_m`` (the reference point in the camera's local frame),
``lat``, ``lon`` (when the camera has a geodetic position; empty otherwise), then
``range_m``, ``azimuth_deg`` (clockwise from North), ``depression_deg`` (below the
true horizontal), ``heading_deg``, ``speed_mps``, ``length_m``, ``top_m`` (highest point
above the waterline) and ``visible`` (unoccluded fraction of the in-image silhouette,
1 = not occluded; fully occluded or out-of-view objects have no row). ``horizon.csv``:
``frame``, ``x0``, ``y0``, ``x1``, ``y1`` (the horizon line at the left and right image
borders, as in the horizon JSON), then ``time``, ``pitch_deg``, ``roll_deg`` (the frame's
camera attitude). Both are flushed after every frame.

Picture (cheap, vectorised; no per-pixel Python): frames are drawn directly in the
encoder's YUV 4:2:0 layout (BT.601, limited range), so no colour conversion is needed
before encoding. A static background — sky gradient with haze towards the horizon,
clouds, the sun, an optional coastline band standing on the horizon, and the sea's base
brightness and colour (water colour, Fresnel reflection of the sky, cloud shadows, sun
glint envelope, haze) — is built once on a roll-free "canvas" camera with margins. Each
frame adds moving waves to the sea's luma (two periodic noise tiles shifted in time and
looked up through a fixed perspective map with a level-of-detail cap, so the texture is
compressed toward the horizon without aliasing; sun glitter where the glint envelope
lifts wave crests into saturation), then, when the camera sways, warps the canvas into
the frame with the exact rotation homography ``K R_canvas^T R_frame K^-1`` (which keeps
the painted horizon on ``horizon_line`` of the frame's camera), paints the ships (shaded
faces, anti-aliased edges, distance haze) and adds sensor noise. Lighting presets:
``day``, ``dusk`` (dark, warm, low sun) and ``night`` (thermal-like grayscale: warm ships
bright on a dark sea, low-contrast noise); see :data:`LIGHTINGS`.

The background ignores lens distortion (ships and truth do not).
"""

from __future__ import annotations

import csv
import dataclasses
import math
import queue
import threading
import time as _time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import cv2
import numpy as np
from numpy.typing import NDArray

from seawatch._validation import FloatArray, in_range, integer, positive
from seawatch.camera import PinholeCamera, horizon_line
from seawatch.geometry import horizon_dip, horizon_distance, north_east_to_geodetic
from seawatch.geometry.sea import effective_radius
from seawatch.synth.world import Ship

__all__ = [
    "HORIZON_COLUMNS",
    "LIGHTINGS",
    "RENDER_VERSION",
    "TRUTH_COLUMNS",
    "Lighting",
    "ObjectTruth",
    "RenderResult",
    "RenderedFrame",
    "Renderer",
    "lighting_preset",
    "render",
    "sway_attitude",
]

RENDER_VERSION = 2
"""Changes whenever the renderer paints different pixels for the same scene (2: the
horizon row is an area-weighted sky/sea mix), so that clips cached by the benchmark and
the demo are rendered again rather than reused."""

RGB = tuple[float, float, float]
Earth = Literal["flat", "curved"]
Progress = Callable[[int, int], None]

TRUTH_COLUMNS: tuple[str, ...] = (
    "time",
    "frame",
    "object_id",
    "x",
    "y",
    "w",
    "h",
    "u_wl",
    "v_wl",
    "east_m",
    "north_m",
    "lat",
    "lon",
    "range_m",
    "azimuth_deg",
    "depression_deg",
    "heading_deg",
    "speed_mps",
    "length_m",
    "top_m",
    "visible",
)
"""Columns of ``truth.csv`` (the first thirteen are INTERFACES.md's)."""

HORIZON_COLUMNS: tuple[str, ...] = (
    "frame",
    "x0",
    "y0",
    "x1",
    "y1",
    "time",
    "pitch_deg",
    "roll_deg",
)
"""Columns of ``horizon.csv`` (the first five are INTERFACES.md's)."""

_REFRACTION = 0.14
_TILE = 512  # wave / cloud tile size [texels]
_TEXEL_M = 0.2  # finest wave texel [m]
_NOISE_PAD = 32
_NEAR_M = 1.0  # points closer than this along the optical axis are not drawn [m]


# ----------------------------------------------------------------------------- lighting
@dataclass(frozen=True)
class Lighting:
    """Lighting and atmosphere of a render (colours sRGB 0–255, angles [rad]).

    Attributes:
        name: preset name.
        thermal: thermal-like grayscale rendering (ships drawn by temperature).
        sky_zenith, sky_horizon: sky colour high up and at the horizon.
        sea_near: water colour looking down; sea_far: sea colour at the horizon (haze).
        land: coastline colour before haze.
        cloud: cloud colour; clouds: cloud cover in [0, 1].
        sun_azimuth: sun azimuth relative to the camera heading, clockwise [rad].
        sun_elevation: sun elevation [rad] (<= 0: no sun, no glint).
        sun_color: colour of the sun, glint and glitter.
        glint: sun-glint strength in [0, 1]; glint_spread: (azimuth, depression) widths
            of the glint envelope [rad].
        wave_amplitude: wave luma contrast near the camera [Y levels, of 219].
        visibility: haze e-folding distance [m].
        cloud_shadows: strength of uneven light on the sea (cloud shadows and a
            brightness gradient across the view) in [0, 1].
        ambient: fraction of light on ship faces that face away from the sun.
        noise: sensor noise standard deviation [Y levels].
    """

    name: str
    thermal: bool
    sky_zenith: RGB
    sky_horizon: RGB
    sea_near: RGB
    sea_far: RGB
    land: RGB
    cloud: RGB
    clouds: float
    sun_azimuth: float
    sun_elevation: float
    sun_color: RGB
    glint: float
    glint_spread: tuple[float, float]
    wave_amplitude: float
    visibility: float
    cloud_shadows: float
    ambient: float
    noise: float


LIGHTINGS: dict[str, Lighting] = {
    "day": Lighting(
        name="day",
        thermal=False,
        sky_zenith=(92.0, 140.0, 205.0),
        sky_horizon=(196.0, 210.0, 224.0),
        sea_near=(24.0, 52.0, 72.0),
        sea_far=(150.0, 168.0, 184.0),
        land=(86.0, 98.0, 80.0),
        cloud=(236.0, 238.0, 242.0),
        clouds=0.35,
        sun_azimuth=math.radians(-35.0),
        sun_elevation=math.radians(38.0),
        sun_color=(255.0, 250.0, 236.0),
        glint=0.35,
        glint_spread=(math.radians(6.0), math.radians(6.0)),
        wave_amplitude=10.0,
        visibility=12000.0,
        cloud_shadows=0.0,
        ambient=0.45,
        noise=1.6,
    ),
    "dusk": Lighting(
        name="dusk",
        thermal=False,
        sky_zenith=(38.0, 46.0, 86.0),
        sky_horizon=(222.0, 142.0, 86.0),
        sea_near=(14.0, 18.0, 30.0),
        sea_far=(150.0, 100.0, 78.0),
        land=(40.0, 34.0, 40.0),
        cloud=(150.0, 96.0, 90.0),
        clouds=0.3,
        sun_azimuth=math.radians(22.0),
        sun_elevation=math.radians(3.0),
        sun_color=(255.0, 196.0, 120.0),
        glint=0.6,
        glint_spread=(math.radians(2.5), math.radians(3.0)),
        wave_amplitude=7.0,
        visibility=7000.0,
        cloud_shadows=0.0,
        ambient=0.35,
        noise=2.5,
    ),
    "night": Lighting(
        name="night",
        thermal=True,
        sky_zenith=(30.0, 30.0, 30.0),
        sky_horizon=(56.0, 56.0, 56.0),
        sea_near=(104.0, 104.0, 104.0),
        sea_far=(86.0, 86.0, 86.0),
        land=(118.0, 118.0, 118.0),
        cloud=(60.0, 60.0, 60.0),
        clouds=0.25,
        sun_azimuth=0.0,
        sun_elevation=-0.5,
        sun_color=(255.0, 255.0, 255.0),
        glint=0.0,
        glint_spread=(0.1, 0.1),
        wave_amplitude=4.0,
        visibility=20000.0,
        cloud_shadows=0.0,
        ambient=1.0,
        noise=3.0,
    ),
}
"""Lighting presets by name: ``day``, ``dusk``, ``night`` (thermal-like)."""


def lighting_preset(name: str, **changes: Any) -> Lighting:
    """A lighting preset (:data:`LIGHTINGS`) with some fields changed."""
    if name not in LIGHTINGS:
        raise ValueError(f"lighting: expected one of {', '.join(LIGHTINGS)}, got {name!r}")
    return dataclasses.replace(LIGHTINGS[name], **changes)


# ----------------------------------------------------------------------------- colour
# BT.601 limited range (studio swing): Y in [16, 235], Cb/Cr in [16, 240].
_YCC = (
    np.array(
        [
            [65.481, 128.553, 24.966],
            [-37.797, -74.203, 112.0],
            [112.0, -93.786, -18.214],
        ]
    )
    / 255.0
)
_YCC_OFF = np.array([16.0, 128.0, 128.0])


def _ycc(rgb: Any) -> FloatArray:
    """sRGB (..., 3) in 0–255 → BT.601 limited-range (Y, Cb, Cr) (..., 3)."""
    return np.asarray(rgb, dtype=np.float64) @ _YCC.T + _YCC_OFF


def _ycc_scalar(r: float, g: float, b: float) -> tuple[float, float, float]:
    """:func:`_ycc` for one colour, in plain floats."""
    return (
        16.0 + (65.481 * r + 128.553 * g + 24.966 * b) / 255.0,
        128.0 + (-37.797 * r - 74.203 * g + 112.0 * b) / 255.0,
        128.0 + (112.0 * r - 93.786 * g - 18.214 * b) / 255.0,
    )


def _lerp(a: Any, b: Any, f: Any) -> Any:
    return a + (b - a) * f


def _periodic_noise(rng: np.random.Generator, size: int, sx: float, sy: float) -> NDArray:
    """Smooth periodic noise tile (size, size), float32, zero mean, unit std.

    White noise filtered with an anisotropic Gaussian (std sx, sy texels along x, y) in
    the Fourier domain, so it tiles seamlessly (BORDER_WRAP).
    """
    white = rng.standard_normal((size, size))
    k = np.fft.fftfreq(size)
    g = np.exp(-2.0 * np.pi**2 * ((sx * k[None, :]) ** 2 + (sy * k[:, None]) ** 2))
    out = np.fft.ifft2(np.fft.fft2(white) * g).real
    out -= out.mean()
    out /= out.std() + 1e-12
    return out.astype(np.float32)


# ----------------------------------------------------------------------------- sway
def sway_attitude(
    camera: PinholeCamera,
    t: float,
    sway: tuple[float, float, float] | None,
    phases: tuple[float, float] = (0.0, 1.3),
) -> tuple[float, float]:
    """(pitch, roll) [rad] of a swaying camera at video time t [s].

    ``sway = (roll_amp, pitch_amp, period)`` [rad, rad, s]:

        roll(t)  = roll_0  + roll_amp  sin(2 pi t / period + phase_r)
        pitch(t) = pitch_0 + pitch_amp sin(2 pi t / (0.77 period) + phase_p)

    (the pitch period is shorter so the motion does not repeat as one ellipse). None
    gives the mounting attitude.
    """
    if sway is None:
        return camera.pitch, camera.roll
    ra, pa, period = sway
    w = 2.0 * math.pi / period
    roll = camera.roll + ra * math.sin(w * t + phases[0])
    pitch = camera.pitch + pa * math.sin(w * t / 0.77 + phases[1])
    return pitch, roll


# ----------------------------------------------------------------------------- results
@dataclass(frozen=True)
class ObjectTruth:
    """Ground truth of one visible object in one frame (see the module docstring).

    Pixels [px] (origin at the centre of the top-left pixel), metres, radians.
    """

    object_id: int
    x: float
    y: float
    w: float
    h: float
    u_wl: float
    v_wl: float
    north: float
    east: float
    range: float
    azimuth: float
    depression: float
    heading: float
    speed: float
    length: float
    top: float
    visible: float


@dataclass(frozen=True, eq=False)
class RenderedFrame:
    """One rendered frame with its truth.

    Attributes:
        index: frame number (0-based).
        time: video time [s] (index / fps).
        camera: the camera of this frame (mounting attitude plus sway and pan).
        yuv: (3 H / 2, W) uint8 I420 image (BT.601 limited range), as encoded.
        objects: visible objects, far to near.
        horizon: (x0, y0, x1, y1) [px], the horizon line at the image borders.
    """

    index: int
    time: float
    camera: PinholeCamera
    yuv: NDArray[np.uint8]
    objects: tuple[ObjectTruth, ...]
    horizon: tuple[float, float, float, float]

    @property
    def luma(self) -> NDArray[np.uint8]:
        """The Y plane (H, W), a view."""
        return self.yuv[: self.camera.image_size[1]]

    def bgr(self) -> NDArray[np.uint8]:
        """The frame as an (H, W, 3) BGR image (OpenCV's I420 conversion is BT.601 limited
        range, the encoding used here)."""
        return cv2.cvtColor(self.yuv, cv2.COLOR_YUV2BGR_I420)


@dataclass(frozen=True)
class RenderResult:
    """What :func:`render` wrote.

    Attributes:
        out_dir: output folder; video, camera, truth, horizon: the four files.
        frames: frames written; fps: frame rate [1/s]; duration: frames / fps [s].
        image_size: (width, height) [px].
        objects: ids of the objects that appear in truth.csv, sorted.
        rows: rows of truth.csv.
        seconds: wall time of the render, encoding included [s].
    """

    out_dir: Path
    video: Path
    camera: Path
    truth: Path
    horizon: Path
    frames: int
    fps: float
    duration: float
    image_size: tuple[int, int]
    objects: tuple[int, ...]
    rows: int
    seconds: float

    @property
    def frames_per_second(self) -> float:
        """Render + encode speed [frames/s]."""
        return self.frames / self.seconds if self.seconds > 0 else math.inf

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready summary (paths as strings)."""
        return {
            "out": str(self.out_dir),
            "outputs": {
                "video": str(self.video),
                "camera": str(self.camera),
                "truth": str(self.truth),
                "horizon": str(self.horizon),
            },
            "frames": self.frames,
            "fps": self.fps,
            "duration_s": self.duration,
            "width": self.image_size[0],
            "height": self.image_size[1],
            "objects": list(self.objects),
            "truth_rows": self.rows,
            "render_seconds": self.seconds,
            "render_fps": self.frames_per_second,
        }


# ----------------------------------------------------------------------------- renderer
@dataclass
class _Projected:
    """A ship projected in one frame (internal)."""

    ship: Ship
    north: float
    east: float
    heading: float
    speed: float
    range: float
    azimuth: float
    depression: float
    wl: FloatArray  # (2,) water-line pixel
    parts: list[tuple[int, FloatArray, FloatArray]]  # (part index, pixels (2K, 2), ned (2K, 3))
    bbox: tuple[float, float, float, float]  # continuous, unclipped (x0, y0, x1, y1)


class Renderer:
    """Frame-by-frame renderer (see the module docstring); :func:`render` writes files.

    Args:
        camera: the camera (needs ``height`` [m]; even image width and height, as
            4:2:0 video needs).
        ships: the ships (unique ``object_id``).
        fps: frame rate [1/s].
        lighting: a preset name of :data:`LIGHTINGS` or a :class:`Lighting`.
        sway: (roll_amp [rad], pitch_amp [rad], period [s]) or None (:func:`sway_attitude`).
        pan: (amplitude [rad], period [s]) of a camera panning to and fro about its
            mounting heading, ``heading(t) = heading_0 + amplitude sin(2 pi t / period)``
            (a scanning PTZ camera, a yawing boat), or None. The world stays put: the
            ships, the sun glint and the coastline move across the frame.
        coastline: draw a coastline band standing on the horizon.
        seed: seeds the waves, clouds, coastline, sway phases and sensor noise; the same
            seed gives the same pixels.
        earth: ``"flat"`` or ``"curved"`` sea (module docstring).
        start_time: trajectory time of frame 0 [s] (video time is index / fps).
        noise: add sensor noise.
    """

    def __init__(
        self,
        camera: PinholeCamera,
        ships: Sequence[Ship],
        fps: float,
        *,
        lighting: str | Lighting = "day",
        sway: tuple[float, float, float] | None = None,
        coastline: bool = False,
        seed: int = 0,
        earth: Earth = "flat",
        start_time: float = 0.0,
        noise: bool = True,
        pan: tuple[float, float] | None = None,
    ) -> None:
        if not isinstance(camera, PinholeCamera):
            raise ValueError(f"camera: expected a PinholeCamera, got {type(camera).__name__}")
        if camera.height is None:
            raise ValueError("camera: the camera has no height above the sea (height_m)")
        w, h = camera.image_size
        if w % 2 or h % 2:
            raise ValueError(
                f"camera: image_size {camera.image_size} must have an even width and height "
                "(4:2:0 video)"
            )
        if abs(camera.pitch) >= math.radians(80.0):
            raise ValueError("camera: pitch must be within ±80° so that the sea is in view")
        self.camera = camera
        self.ships = tuple(ships)
        ids = [s.object_id for s in self.ships]
        for s in self.ships:
            if not isinstance(s, Ship):
                raise ValueError(f"ships: expected Ship objects, got {type(s).__name__}")
        if len(set(ids)) != len(ids):
            raise ValueError("ships: object_id values must be unique")
        self.fps = positive("fps", fps)
        if isinstance(lighting, str):
            if lighting not in LIGHTINGS:
                raise ValueError(
                    f"lighting: expected one of {', '.join(LIGHTINGS)}, got {lighting!r}"
                )
            lighting = LIGHTINGS[lighting]
        if not isinstance(lighting, Lighting):
            raise ValueError(f"lighting: expected a name or a Lighting, got {lighting!r}")
        self.lighting = lighting
        if sway is not None:
            if len(sway) != 3:
                raise ValueError("sway: expected (roll_amp [rad], pitch_amp [rad], period [s])")
            ra = in_range("sway roll_amp", sway[0], 0.0, 0.5)
            pa = in_range("sway pitch_amp", sway[1], 0.0, 0.5)
            period = positive("sway period", sway[2])
            sway = None if ra == 0.0 and pa == 0.0 else (ra, pa, period)
        self.sway = sway
        if pan is not None:
            if len(pan) != 2:
                raise ValueError("pan: expected (amplitude [rad], period [s])")
            amp = in_range("pan amplitude", pan[0], 0.0, math.pi / 4)
            pan = None if amp == 0.0 else (amp, positive("pan period", pan[1]))
        self.pan = pan
        if earth not in ("flat", "curved"):
            raise ValueError(f"earth: expected 'flat' or 'curved', got {earth!r}")
        self.earth: Earth = earth
        self.coastline = bool(coastline)
        self.seed = int(seed)
        self.start_time = float(start_time)
        self.noise = bool(noise)
        self.height_m = float(camera.height)
        self.dip = float(horizon_dip(self.height_m, _REFRACTION))
        self.horizon_distance = float(horizon_distance(self.height_m, _REFRACTION))
        self._re = effective_radius(_REFRACTION)
        rng = np.random.default_rng([self.seed, 7])
        self._phases = (float(rng.uniform(0, 2 * np.pi)), float(rng.uniform(0, 2 * np.pi)))
        self._background_ready = False  # built on the first painted frame
        L = self.lighting
        az = camera.heading + L.sun_azimuth
        self._sun_ned = (
            math.cos(L.sun_elevation) * math.cos(az),
            math.cos(L.sun_elevation) * math.sin(az),
            -math.sin(L.sun_elevation),
        )

    # ------------------------------------------------------------ attitude
    def camera_at(self, index: int) -> PinholeCamera:
        """The camera of frame ``index``: mounting attitude plus sway and pan."""
        if self.sway is None and self.pan is None:
            return self.camera
        t = index / self.fps
        pitch, roll = sway_attitude(self.camera, t, self.sway, self._phases)
        heading = self.camera.heading
        if self.pan is not None:
            heading += self.pan[0] * math.sin(2.0 * math.pi * t / self.pan[1])
        return self.camera.with_attitude(heading=heading, pitch=pitch, roll=roll)

    # ------------------------------------------------------------ background
    def _canvas_camera(self) -> tuple[PinholeCamera, bool]:
        cam = self.camera
        w, h = cam.image_size
        level = PinholeCamera(
            fx=cam.fx,
            fy=cam.fy,
            cx=cam.cx,
            cy=cam.cy,
            image_size=(w, h),
            heading=cam.heading,
            pitch=cam.pitch,
            roll=0.0,
            height=cam.height,
        )
        if self.sway is None and self.pan is None and cam.roll == 0.0:
            return level, False
        attitudes = [(cam.heading, cam.pitch, cam.roll)]
        ra, pa = (self.sway[0], self.sway[1]) if self.sway is not None else (0.0, 0.0)
        yaws = (0.0,) if self.pan is None else (-self.pan[0], 0.0, self.pan[0])
        for dy in yaws:
            for dr in (-ra, ra):
                for dp in (-pa, pa):
                    attitudes.append((cam.heading + dy, cam.pitch + dp, cam.roll + dr))
        corners = np.array([[-0.5, -0.5, 1.0], [w - 0.5, -0.5, 1.0], [-0.5, h - 0.5, 1.0]])
        corners = np.vstack([corners, [w - 0.5, h - 0.5, 1.0]])
        pts = []
        for heading, pitch, roll in attitudes:
            H = self._homography(level, cam.with_attitude(heading=heading, pitch=pitch, roll=roll))
            p = corners @ H.T
            pts.append(p[:, :2] / p[:, 2:3])
        allp = np.vstack(pts)
        ml = max(0, math.ceil(-allp[:, 0].min()) + 4)
        mt = max(0, math.ceil(-allp[:, 1].min()) + 4)
        mr = max(0, math.ceil(allp[:, 0].max() - (w - 1)) + 4)
        mb = max(0, math.ceil(allp[:, 1].max() - (h - 1)) + 4)
        ml += ml % 2
        mt += mt % 2
        mr += mr % 2
        mb += mb % 2
        canvas = dataclasses.replace(
            level, cx=cam.cx + ml, cy=cam.cy + mt, image_size=(w + ml + mr, h + mt + mb)
        )
        return canvas, True

    @staticmethod
    def _homography(canvas: PinholeCamera, frame_cam: PinholeCamera) -> FloatArray:
        """Frame pixel → canvas pixel: ``K_c R_c^T R_f K_f^-1`` (pure rotation)."""
        return canvas.K @ canvas.R_nc.T @ frame_cam.R_nc @ np.linalg.inv(frame_cam.K)

    def _sky_rgb(self, e: FloatArray) -> FloatArray:
        """Sky colour (..., 3) at elevation e above the visible horizon [rad]."""
        L = self.lighting
        f = 1.0 - np.exp(-np.maximum(e, 0.0) / 0.16)
        return _lerp(
            np.asarray(L.sky_horizon, np.float32),
            np.asarray(L.sky_zenith, np.float32),
            f[..., None],
        )

    def _build_background(self, rng: np.random.Generator) -> None:
        L = self.lighting
        canvas, warp = self._canvas_camera()
        self._canvas = canvas
        self._warp = warp
        wc, hc = canvas.image_size
        hline = horizon_line(canvas)
        v_h = float(hline.v_at(canvas.cx))
        v0 = int(min(max(math.floor(v_h) + 1, 0), hc))
        self._v0 = v0
        self._v_h = v_h
        u = (np.arange(wc, dtype=np.float64) - canvas.cx) / canvas.fx
        v = (np.arange(hc, dtype=np.float64) - canvas.cy) / canvas.fy
        R = canvas.R_pc
        rf = (R[0, 0] * u[None, :] + R[0, 1] * v[:, None] + R[0, 2]).astype(np.float32)
        rr = (R[1, 0] * u[None, :] + R[1, 1] * v[:, None] + R[1, 2]).astype(np.float32)
        rd = (R[2, 0] * u[None, :] + R[2, 1] * v[:, None] + R[2, 2]).astype(np.float32)
        hor = np.hypot(rf, rr)
        el = np.arctan2(-rd, hor)  # elevation above the true horizontal
        az = np.arctan2(rr, rf)  # relative to the camera heading
        rgb = np.empty((hc, wc, 3), np.float32)

        # --- sky (rows above the horizon)
        if v0 > 0:
            e = el[:v0] + self.dip
            sky = self._sky_rgb(e)
            if L.clouds > 0.0:
                tile = _periodic_noise(rng, _TILE, 9.0, 5.0) + 0.5 * _periodic_noise(
                    rng, _TILE, 3.0, 2.0
                )
                mx = (az[:v0] * canvas.fx / 10.0).astype(np.float32)
                my = (0.012 * canvas.fy / (np.maximum(e, 0.0) + 0.1)).astype(np.float32)
                cl = cv2.remap(tile, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP)
                cover = np.clip((cl - (1.2 - 2.0 * L.clouds)) * 0.8, 0.0, 1.0)
                cover *= 1.0 - np.exp(-np.maximum(e, 0.0) / 0.05)
                sky = _lerp(sky, np.asarray(L.cloud, np.float32), cover[..., None])
            if L.sun_elevation > 0.0:
                s = self._sun_dir_platform()
                cosg = (rf[:v0] * s[0] + rr[:v0] * s[1] + rd[:v0] * s[2]) / np.sqrt(
                    rf[:v0] ** 2 + rr[:v0] ** 2 + rd[:v0] ** 2
                )
                gam = np.arccos(np.clip(cosg, -1.0, 1.0))
                glow = 0.55 * np.exp(-gam / 0.06) + np.where(gam < 0.0047, 1.0, 0.0)
                sky = _lerp(
                    sky, np.asarray(L.sun_color, np.float32), np.clip(glow, 0, 1)[..., None]
                )
            if self.coastline:
                sky = self._coast(rng, sky, az[:v0], el[:v0])
            rgb[:v0] = sky

        # --- sea (rows below the horizon): static colour at full resolution, wave maps and
        # gains at half resolution (the waves are smooth; upsampled per frame)
        if v0 < hc:
            self._build_sea(rng, rgb, rf[v0:], rr[v0:], rd[v0:], az[v0:])
        ycc = _ycc(rgb).astype(np.float32)
        self._canvas_y = np.clip(np.rint(ycc[..., 0]), 0, 255).astype(np.uint8)
        # the last sky row, untouched: the row holding the horizon is re-blended per frame
        self._sky_row = self._canvas_y[max(v0 - 1, 0)].astype(np.float32)
        half = cv2.resize(ycc[..., 1:], (wc // 2, hc // 2), interpolation=cv2.INTER_AREA)
        self._canvas_u = np.clip(np.rint(half[..., 0]), 0, 255).astype(np.uint8)
        self._canvas_v = np.clip(np.rint(half[..., 1]), 0, 255).astype(np.uint8)
        # wave tiles: wind waves (crests across the view) and a longer swell
        fine = _periodic_noise(rng, _TILE, 2.5, 1.2)
        tile_a = (_periodic_noise(rng, _TILE, 7.0, 2.2) + 0.55 * fine) / 1.14
        tile_b = _periodic_noise(rng, _TILE, 16.0, 6.0)
        # 2 x 2 copies (plus a border texel): any shifted (TILE + 2)² window is a view
        self._tile_a = np.pad(tile_a, ((0, _TILE + 2), (0, _TILE + 2)), mode="wrap")
        self._tile_b = np.pad(tile_b, ((0, _TILE + 2), (0, _TILE + 2)), mode="wrap")
        self._tile_buf = np.empty((_TILE + 1, _TILE + 1), np.float32)

    def _sun_dir_platform(self) -> FloatArray:
        L = self.lighting
        return np.array(
            [
                math.cos(L.sun_elevation) * math.cos(L.sun_azimuth),
                math.cos(L.sun_elevation) * math.sin(L.sun_azimuth),
                -math.sin(L.sun_elevation),
            ]
        )

    def _coast(self, rng: np.random.Generator, sky: NDArray, az: NDArray, el: NDArray) -> NDArray:
        """A coastline band standing on the horizon over part of the view."""
        L = self.lighting
        half = 0.5 * self.camera.hfov + 0.05
        grid = np.linspace(-half, half, 2048)
        prof = np.cumsum(rng.standard_normal(grid.size))
        prof = cv2.GaussianBlur(prof.reshape(1, -1), (0, 0), 25).ravel()
        prof = (prof - prof.min()) / (np.ptp(prof) + 1e-12)
        a0 = rng.uniform(-half, -0.2 * half)
        a1 = rng.uniform(0.3 * half, half)
        taper = np.clip((grid - a0) / 0.03, 0, 1) * np.clip((a1 - grid) / 0.03, 0, 1)
        amp = max(0.006, 24.0 / self.camera.fy)
        height = amp * (0.25 + 0.75 * prof) * taper
        land_h = np.interp(az, grid, height).astype(np.float32)
        above = el + self.dip  # elevation above the visible horizon
        mask = (above < land_h) & (land_h > 0)
        tex = (0.02 if L.thermal else 0.08) * np.sin(az * 900.0 + 3.0 * np.sin(el * 400.0))
        land = np.asarray(L.land, np.float32) * (1.0 + tex[..., None])
        land = _lerp(land, np.asarray(L.sky_horizon, np.float32), 0.45)
        return np.where(mask[..., None], land, sky)

    def _sea_geometry(
        self, rf: NDArray, rr: NDArray, rd: NDArray
    ) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        """Flat-sea ground distance, forward and right offsets [m] and depression [rad]."""
        h = self.height_m
        hor = np.hypot(rf, rr)
        rd = np.maximum(rd, 1e-6)
        return h * hor / rd, h * rf / rd, h * rr / rd, np.arctan2(rd, hor)

    def _glint(self, az: NDArray, dep: NDArray) -> NDArray:
        """Sun-glint envelope in [0, glint] around the sun's mirror direction."""
        L = self.lighting
        if L.sun_elevation <= 0.0 or L.glint <= 0.0:
            return np.zeros_like(az)
        daz = np.angle(np.exp(1j * (az - L.sun_azimuth)))
        return (
            L.glint
            * np.exp(
                -0.5 * (daz / L.glint_spread[0]) ** 2
                - 0.5 * ((dep - L.sun_elevation) / L.glint_spread[1]) ** 2
            )
        ).astype(np.float32)

    def _shade(self, rng_tile: NDArray | None, a: NDArray, c: NDArray, dist: NDArray, az: NDArray):
        """Uneven light on the sea: cloud shadows fading with distance, a brightness slope."""
        L = self.lighting
        if rng_tile is None:
            return np.ones_like(dist)
        sx = np.mod(c / 120.0, 256.0).astype(np.float32)
        sy = np.mod(a / 120.0, 256.0).astype(np.float32)
        sh = cv2.remap(rng_tile, sx, sy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP)
        shade = 1.0 - L.cloud_shadows * 0.45 * np.clip(sh + 0.3, 0.0, 1.5) * np.exp(-dist / 4000.0)
        return shade * (1.0 + 0.25 * L.cloud_shadows * np.sin(az - L.sun_azimuth + 0.6))

    def _build_sea(
        self,
        rng: np.random.Generator,
        rgb: NDArray,
        rf: NDArray,
        rr: NDArray,
        rd: NDArray,
        az: NDArray,
    ) -> None:
        L = self.lighting
        v0 = self._v0
        canvas = self._canvas
        dist, a, c, dep = self._sea_geometry(rf, rr, rd)
        fh = 1.0 - np.exp(-dist / L.visibility)
        refl = 0.02 + 0.98 * (1.0 - np.sin(dep)) ** 5  # Schlick's Fresnel, water
        if L.thermal:
            refl = 0.5 * refl  # thermal: the sea's own emission keeps it warmer than the sky
        # a rough sea reflects a darker mix of sky than the sky just above the horizon, so
        # the horizon stays a visible edge
        sky_mirror = self._sky_rgb(np.maximum(dep - self.dip, 0.0)) * 0.8
        col = _lerp(np.asarray(L.sea_near, np.float32), sky_mirror, refl[..., None])
        shadow_tile = _periodic_noise(rng, 256, 6.0, 6.0) if L.cloud_shadows > 0.0 else None
        col = col * self._shade(shadow_tile, a, c, dist, az)[..., None]
        glint = self._glint(az, dep)
        sun = np.asarray(L.sun_color, np.float32)
        col = _lerp(col, sun, np.minimum(0.45 * glint, 0.6)[..., None])
        col = _lerp(col, np.asarray(L.sea_far, np.float32), fh[..., None])
        rgb[v0:] = col
        base = _ycc(col)[..., 0].astype(np.float32)
        if base.shape[0] % 2:
            base = np.vstack([base, base[-1:]])
        # half-resolution base luma (2 x 2 means), on the grid of the wave maps below
        self._sea_base = cv2.resize(
            base, (base.shape[1] // 2, base.shape[0] // 2), interpolation=cv2.INTER_AREA
        )

        # half-resolution grid: pixel (k, j) is centred on full-res (v0 + 2k + 0.5, 2j + 0.5)
        wc, hc = canvas.image_size
        n_rows = hc - v0
        m = (n_rows + 1) // 2
        uh = (2.0 * np.arange(wc // 2) + 0.5 - canvas.cx) / canvas.fx
        vh = (v0 + 2.0 * np.arange(m) + 0.5 - canvas.cy) / canvas.fy
        R = canvas.R_pc
        hf = R[0, 0] * uh[None, :] + R[0, 1] * vh[:, None] + R[0, 2]
        hr = R[1, 0] * uh[None, :] + R[1, 1] * vh[:, None] + R[1, 2]
        hd = R[2, 0] * uh[None, :] + R[2, 1] * vh[:, None] + R[2, 2]
        dist, a, c, dep = self._sea_geometry(hf, hr, hd)
        haz = np.arctan2(hr, hf)
        fh = 1.0 - np.exp(-dist / L.visibility)
        # level of detail: at most one texel per (half-res) pixel along either image axis
        if a.shape[0] > 1:
            da = np.abs(np.diff(a, axis=0))
            da = np.vstack([da, da[-1:]])
        else:
            da = np.full_like(a, _TEXEL_M)
        dc = np.abs(np.gradient(c, axis=1)) if c.shape[1] > 1 else np.zeros_like(c)
        k = np.minimum(1.0, _TEXEL_M / np.maximum(np.maximum(da, dc), 1e-6))
        map_x = c * k / _TEXEL_M
        map_y = np.empty_like(a)
        map_y[-1] = a[-1] / _TEXEL_M
        if a.shape[0] > 1:
            inc = (a[:-1] - a[1:]) * k[:-1] / _TEXEL_M
            map_y[:-1] = map_y[-1] + np.cumsum(inc[::-1], axis=0)[::-1]
        # pre-wrapped float maps into a tile padded by one texel: no border handling needed
        self._map_x = np.mod(map_x, _TILE).astype(np.float32)
        self._map_y = np.mod(map_y, _TILE).astype(np.float32)
        shade = self._shade(shadow_tile, a, c, dist, haz)
        gain = L.wave_amplitude * (1.0 - fh) * (0.35 + 0.65 * k) * shade
        self._sea_gain = np.ascontiguousarray(gain.astype(np.float32))
        # sun glitter: wave crests above 0.7 sigma inside the glint envelope go bright
        glint_half = self._glint(haz, dep)
        self._glitter_gain = (
            np.ascontiguousarray((glint_half * 140.0).astype(np.float32))
            if np.any(glint_half > 1e-3)
            else None
        )
        self._glitter_buf = np.empty_like(self._sea_gain)
        self._sea_rows = n_rows
        self._wave_half = np.empty((m, wc // 2), np.float32)
        self._wave_u8 = np.empty((m, wc // 2), np.uint8)
        self._wave_full = np.empty((2 * m, wc), np.uint8) if 2 * m != n_rows else None

    # ------------------------------------------------------------ noise
    def _build_noise(self) -> None:
        w, h = self.camera.image_size
        sigma = self.lighting.noise if self.noise else 0.0
        if sigma <= 0.0:
            self._noise_pos = self._noise_neg = None
            return
        rng = np.random.default_rng([self.seed, 11])
        n = np.rint(rng.normal(0.0, sigma, (h + _NOISE_PAD, w + _NOISE_PAD)))
        n = np.clip(n, -127, 127)
        self._noise_pos = np.maximum(n, 0).astype(np.uint8)
        self._noise_neg = np.maximum(-n, 0).astype(np.uint8)

    # ------------------------------------------------------------ per frame
    def _waves(self, t: float) -> NDArray:
        """Wave tile at video time t, (TILE + 1)² with a wrapped border texel.

        Two periodic tiles drifting at different velocities (wind waves towards the
        camera, an oblique swell), shifted by sub-texel amounts and summed.
        """
        va = 1.4 / _TEXEL_M  # wind waves [texels/s]
        vb = 2.6 / _TEXEL_M  # swell [texels/s]
        wa = _shifted_tile(self._tile_a, 0.15 * va * t, va * t)
        wb = _shifted_tile(self._tile_b, -0.5 * vb * t, 0.8 * vb * t)
        return cv2.addWeighted(wa, 0.8, wb, 0.6, 0.0, dst=self._tile_buf)

    def _sea_luma(self, t: float, dst: NDArray) -> None:
        """Sea luma with waves at video time t into ``dst`` (the canvas rows below v0)."""
        tile = self._waves(t)
        cv2.remap(
            tile,
            self._map_x,
            self._map_y,
            cv2.INTER_LINEAR,
            dst=self._wave_half,
            borderMode=cv2.BORDER_REPLICATE,
        )
        if self._glitter_gain is not None:
            cv2.threshold(self._wave_half, 0.7, 0.0, cv2.THRESH_TOZERO, dst=self._glitter_buf)
            cv2.multiply(self._glitter_buf, self._glitter_gain, dst=self._glitter_buf)
            cv2.multiply(self._wave_half, self._sea_gain, dst=self._wave_half)
            cv2.add(self._wave_half, self._glitter_buf, dst=self._wave_half)
        else:
            cv2.multiply(self._wave_half, self._sea_gain, dst=self._wave_half)
        cv2.add(self._wave_half, self._sea_base, dst=self._wave_half)
        cv2.convertScaleAbs(self._wave_half, dst=self._wave_u8)
        m, wh = self._wave_u8.shape
        size = (2 * wh, 2 * m)
        if self._wave_full is None:
            cv2.resize(self._wave_u8, size, dst=dst, interpolation=cv2.INTER_LINEAR)
        else:
            cv2.resize(self._wave_u8, size, dst=self._wave_full, interpolation=cv2.INTER_LINEAR)
            np.copyto(dst, self._wave_full[: self._sea_rows])

    def _ensure_background(self) -> None:
        if not self._background_ready:
            self._build_background(np.random.default_rng([self.seed, 8]))
            self._build_noise()
            self._background_ready = True

    def _blend_horizon_row(self, y: NDArray) -> None:
        """Anti-alias the sky/sea boundary of the level canvas: the pixel row holding the
        horizon row ``v_h`` (row r covers [r − 0.5, r + 0.5]) gets the area-weighted mix
        of the sky row above and the sea row below, so the painted edge is the geometric
        horizon of horizon.csv to a fraction of a pixel (not the nearest row boundary)."""
        v0 = self._v0
        if not 0 < v0 < y.shape[0]:
            return
        f = v0 - 0.5 - self._v_h  # sea fraction of row v0 − 1 (> 0) or −sky fraction of row v0
        if f > 0.0:  # f is fixed per clip: row v0 − 1 is rewritten from the kept sky row
            mix = (1.0 - f) * self._sky_row + f * y[v0].astype(np.float32)
            y[v0 - 1] = np.clip(np.rint(mix), 0, 255).astype(np.uint8)
        elif f < 0.0:  # row v0 is repainted with sea every frame
            mix = (1.0 + f) * y[v0].astype(np.float32) - f * self._sky_row
            y[v0] = np.clip(np.rint(mix), 0, 255).astype(np.uint8)

    def _paint_background(self, index: int, cam: PinholeCamera, buf: NDArray) -> None:
        self._ensure_background()
        w, h = cam.image_size
        t = index / self.fps
        v0 = self._v0
        y_plane = buf[:h]
        u_plane = buf[h : h + h // 4].reshape(h // 2, w // 2)
        v_plane = buf[h + h // 4 :].reshape(h // 2, w // 2)
        has_sea = v0 < self._canvas_y.shape[0]
        if not self._warp:
            if has_sea:
                self._sea_luma(t, y_plane[v0:])
            y_plane[:v0] = self._canvas_y[:v0]
            self._blend_horizon_row(y_plane)
            np.copyto(u_plane, self._canvas_u)
            np.copyto(v_plane, self._canvas_v)
            return
        if has_sea:
            self._sea_luma(t, self._canvas_y[v0:])
        self._blend_horizon_row(self._canvas_y)
        H = self._homography(self._canvas, cam)
        flags = cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP
        cv2.warpPerspective(
            self._canvas_y, H, (w, h), dst=y_plane, flags=flags, borderMode=cv2.BORDER_REPLICATE
        )
        # chroma: pixel (i, j) of a half-size plane sits at luma (2i + 0.5, 2j + 0.5)
        S = np.array([[0.5, 0.0, -0.25], [0.0, 0.5, -0.25], [0.0, 0.0, 1.0]])
        Hc = S @ H @ np.linalg.inv(S)
        size = (w // 2, h // 2)
        flags = cv2.INTER_NEAREST | cv2.WARP_INVERSE_MAP  # chroma is smooth; luma has the edges
        cv2.warpPerspective(
            self._canvas_u, Hc, size, dst=u_plane, flags=flags, borderMode=cv2.BORDER_REPLICATE
        )
        cv2.warpPerspective(
            self._canvas_v, Hc, size, dst=v_plane, flags=flags, borderMode=cv2.BORDER_REPLICATE
        )

    def _project(self, index: int, cam: PinholeCamera) -> list[_Projected]:
        """Project every ship present at this frame (not hidden by the horizon)."""
        t = self.start_time + index / self.fps
        pn, pe = cam.position
        h = self.height_m
        live: list[tuple[Ship, tuple[float, float, float, float], float]] = []
        for ship in self.ships:
            st = ship.trajectory.state(t)
            if st is None:
                continue
            rng_m = math.hypot(st[0] - pn, st[1] - pe)
            if rng_m > self.horizon_distance:
                continue
            live.append((ship, st, rng_m))
        if not live:
            return []
        chunks = []
        for ship, (n, e, psi, _), _ in live:
            cs, sn = math.cos(psi), math.sin(psi)
            for part in ship.parts:
                vtx = part.vertices
                north = n + vtx[:, 0] * cs - vtx[:, 1] * sn - pn
                east = e + vtx[:, 0] * sn + vtx[:, 1] * cs - pe
                chunks.append(np.column_stack([north, east, vtx[:, 2]]))
            chunks.append(np.array([[n - pn, e - pe, 0.0]]))
        pts = np.vstack(chunks)
        ned = self._to_ned(pts)
        rc = ned @ cam.R_nc  # camera-frame coordinates (x right, y down, z forward)
        pix = cam.ray_to_pixel(ned, frame="world")
        pix[rc[:, 2] < _NEAR_M] = np.nan
        out: list[_Projected] = []
        k = 0
        for ship, (n, e, psi, speed), rng_m in live:
            parts = []
            ok = True
            for j, part in enumerate(ship.parts):
                m = part.vertices.shape[0]
                p = pix[k : k + m]
                if not np.all(np.isfinite(p)) or np.any(np.abs(p) > 1e6):
                    ok = False
                parts.append((j, p, ned[k : k + m]))
                k += m
            wl = pix[k]
            k += 1
            if not ok:
                continue
            allp = np.vstack([p for _, p, _ in parts])
            bbox = (
                float(allp[:, 0].min()),
                float(allp[:, 1].min()),
                float(allp[:, 0].max()),
                float(allp[:, 1].max()),
            )
            if self.earth == "flat":
                dep = math.atan2(h, rng_m)
            else:
                phi = rng_m / self._re
                dep = math.atan2(
                    h + 2.0 * self._re * math.sin(0.5 * phi) ** 2, self._re * math.sin(phi)
                )
            out.append(
                _Projected(
                    ship=ship,
                    north=n,
                    east=e,
                    heading=psi,
                    speed=speed,
                    range=rng_m,
                    azimuth=math.atan2(e - pe, n - pn) % (2.0 * math.pi),
                    depression=dep,
                    wl=wl,
                    parts=parts,
                    bbox=bbox,
                )
            )
        out.sort(key=lambda p: -p.range)
        return out

    def _to_ned(self, pts: FloatArray) -> FloatArray:
        """(north, east, up) relative to the camera's ground point → NED from the camera."""
        h = self.height_m
        if self.earth == "flat":
            return np.column_stack([pts[:, 0], pts[:, 1], h - pts[:, 2]])
        re = self._re
        d = np.hypot(pts[:, 0], pts[:, 1])
        phi = d / re
        rz = re + pts[:, 2]
        horiz = rz * np.sin(phi)
        scale = np.divide(horiz, d, out=np.ones_like(d), where=d > 0)
        down = h - pts[:, 2] + 2.0 * rz * np.sin(0.5 * phi) ** 2
        return np.column_stack([pts[:, 0] * scale, pts[:, 1] * scale, down])

    def _ship_colors(
        self, part: Any, normal_ned: tuple[float, float, float] | None, rng_m: float
    ) -> tuple[float, float, float]:
        """(Y, Cb, Cr) of a face (or of the whole part when ``normal_ned`` is None).

        Daylight: the part colour times ``ambient + (1 - ambient) max(0, n · sun)``, hazed
        towards the horizon sky colour by ``1 - exp(-range / visibility)``. Thermal: a grey
        level from the part's temperature (roofs and decks a little colder).
        """
        L = self.lighting
        fh = 1.0 - math.exp(-rng_m / L.visibility)
        if L.thermal:
            temp = part.temperature
            if normal_ned is not None and normal_ned[2] < -0.5:
                temp *= 0.9  # decks and roofs radiate to the cold sky
            g = 60.0 + 190.0 * temp
            g += (L.sky_horizon[0] - g) * 0.5 * fh
            return _ycc_scalar(g, g, g)
        if normal_ned is None:
            lit = L.ambient + (1.0 - L.ambient) * 0.5
        else:
            s = self._sun_ned
            cosi = normal_ned[0] * s[0] + normal_ned[1] * s[1] + normal_ned[2] * s[2]
            lit = L.ambient + (1.0 - L.ambient) * max(0.0, cosi)
        hz = L.sky_horizon
        r, g, b = (c * lit + (hc - c * lit) * fh for c, hc in zip(part.color, hz, strict=True))
        return _ycc_scalar(r, g, b)

    def _paint_ships(self, projected: list[_Projected], buf: NDArray, cam: PinholeCamera) -> None:
        w, h = cam.image_size
        y_plane = buf[:h]
        u_plane = buf[h : h + h // 4].reshape(h // 2, w // 2)
        v_plane = buf[h + h // 4 :].reshape(h // 2, w // 2)
        for pr in projected:
            x0, y0, x1, y1 = pr.bbox
            if x1 < -0.5 or y1 < -0.5 or x0 > w - 0.5 or y0 > h - 0.5:
                continue
            small = (y1 - y0) < 8.0 or (x1 - x0) < 8.0
            ship = pr.ship
            order = list(range(len(ship.parts)))
            supers = sorted(order[1:], key=lambda j: -_sq_norm(pr.parts[j][2].mean(axis=0)))
            order = [0, *supers] if self.height_m > ship.height else [*supers, 0]
            cs, sn = math.cos(pr.heading), math.sin(pr.heading)
            for j in order:
                _, pix, ned = pr.parts[j]
                part = ship.parts[j]
                col = self._ship_colors(part, None, pr.range)
                inner = _shrink(pix)
                _fill(y_plane, cv2.convexHull(inner.astype(np.float32)), col[0], aa=True)
                chroma = _shrink((pix - 0.5) * 0.5)  # half-size plane coordinates
                hull_c = cv2.convexHull(chroma.astype(np.float32))
                _fill(u_plane, hull_c, col[1], aa=True)
                _fill(v_plane, hull_c, col[2], aa=True)
                if small:
                    continue
                ned_l = ned.tolist()
                for idx, nrm in part.faces:
                    nx, ny, nz = float(nrm[0]), float(nrm[1]), float(nrm[2])
                    nw = (nx * cs - ny * sn, nx * sn + ny * cs, -nz)
                    p = ned_l[idx[0]]
                    if nw[0] * p[0] + nw[1] * p[1] + nw[2] * p[2] >= 0.0:
                        continue  # back face
                    fc = self._ship_colors(part, nw, pr.range)
                    _fill(y_plane, inner[list(idx)], fc[0], aa=False)

    def _truth(self, projected: list[_Projected], cam: PinholeCamera) -> list[ObjectTruth]:
        w, h = cam.image_size
        out: list[ObjectTruth] = []
        near_first = sorted(projected, key=lambda p: p.range)
        for i, pr in enumerate(near_first):
            x0, y0, x1, y1 = pr.bbox
            cx0, cy0 = max(x0, -0.5), max(y0, -0.5)
            cx1, cy1 = min(x1, w - 0.5), min(y1, h - 0.5)
            if cx1 <= cx0 or cy1 <= cy0:
                continue
            occluders = [
                q
                for q in near_first[:i]
                if q.bbox[0] < cx1 and q.bbox[2] > cx0 and q.bbox[1] < cy1 and q.bbox[3] > cy0
            ]
            visible = 1.0
            if occluders:
                res = _visible_box(pr, occluders, (cx0, cy0, cx1, cy1))
                if res is None:
                    continue
                (cx0, cy0, cx1, cy1), visible = res
            out.append(
                ObjectTruth(
                    object_id=pr.ship.object_id,
                    x=cx0,
                    y=cy0,
                    w=cx1 - cx0,
                    h=cy1 - cy0,
                    u_wl=float(pr.wl[0]),
                    v_wl=float(pr.wl[1]),
                    north=pr.north,
                    east=pr.east,
                    range=pr.range,
                    azimuth=pr.azimuth,
                    depression=pr.depression,
                    heading=pr.heading,
                    speed=pr.speed,
                    length=pr.ship.length,
                    top=pr.ship.top,
                    visible=visible,
                )
            )
        out.sort(key=lambda o: -o.range)
        return out

    def _add_noise(self, index: int, buf: NDArray, cam: PinholeCamera) -> None:
        if self._noise_pos is None or self._noise_neg is None:
            return
        w, h = cam.image_size
        rng = np.random.default_rng([self.seed, 13, index])
        dy, dx = (int(x) for x in rng.integers(0, _NOISE_PAD + 1, 2))
        y_plane = buf[:h]
        cv2.add(y_plane, self._noise_pos[dy : dy + h, dx : dx + w], dst=y_plane)
        dy2, dx2 = (int(x) for x in rng.integers(0, _NOISE_PAD + 1, 2))
        cv2.subtract(y_plane, self._noise_neg[dy2 : dy2 + h, dx2 : dx2 + w], dst=y_plane)

    def render_into(
        self, index: int, buf: NDArray[np.uint8], *, ships: bool = True
    ) -> tuple[PinholeCamera, list[ObjectTruth], tuple[float, float, float, float]]:
        """Draw frame ``index`` into ``buf`` ((3H/2, W) uint8 I420); return its camera,
        truth and horizon (x0, y0, x1, y1). ``ships=False`` draws the empty sea (the truth
        is still computed)."""
        cam = self.camera_at(index)
        self._paint_background(index, cam, buf)
        projected = self._project(index, cam)
        if ships:
            self._paint_ships(projected, buf, cam)
        self._add_noise(index, buf, cam)
        truth = self._truth(projected, cam)
        ends = horizon_line(cam, refraction=_REFRACTION).endpoints(cam.image_size[0])
        horizon = (float(ends[0, 0]), float(ends[0, 1]), float(ends[1, 0]), float(ends[1, 1]))
        return cam, truth, horizon

    def truth(
        self, index: int
    ) -> tuple[PinholeCamera, list[ObjectTruth], tuple[float, float, float, float]]:
        """Camera, ground truth and horizon of frame ``index`` without drawing it."""
        cam = self.camera_at(index)
        truth = self._truth(self._project(index, cam), cam)
        ends = horizon_line(cam, refraction=_REFRACTION).endpoints(cam.image_size[0])
        horizon = (float(ends[0, 0]), float(ends[0, 1]), float(ends[1, 0]), float(ends[1, 1]))
        return cam, truth, horizon

    def frame(self, index: int, *, ships: bool = True) -> RenderedFrame:
        """Render frame ``index`` (>= 0) into a new buffer."""
        if index < 0:
            raise ValueError(f"index: expected a frame number >= 0, got {index}")
        w, h = self.camera.image_size
        buf = np.empty((h * 3 // 2, w), np.uint8)
        cam, truth, horizon = self.render_into(index, buf, ships=ships)
        return RenderedFrame(index, index / self.fps, cam, buf, tuple(truth), horizon)


def _shifted_tile(tile2: NDArray, sx: float, sy: float) -> NDArray:
    """A periodic tile sampled at (x + sx, y + sy), as an (n + 1)² wrapped tile.

    ``tile2`` holds 2 × 2 copies of the (n, n) tile plus two border texels, so the
    integer part of the shift is a window (a view) and only the fraction needs a
    bilinear warp (a warp with BORDER_WRAP is slow for large shifts).
    """
    n = (tile2.shape[0] - 2) // 2
    ix, iy = math.floor(sx), math.floor(sy)
    i, j = iy % n, ix % n
    window = tile2[i : i + n + 2, j : j + n + 2]
    m = np.array([[1.0, 0.0, sx - ix], [0.0, 1.0, sy - iy]])
    return cv2.warpAffine(
        window,
        m,
        (n + 1, n + 1),
        flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
        borderMode=cv2.BORDER_REPLICATE,
    )


def _shrink(pts: NDArray) -> NDArray:
    """Polygon vertices (K, 2) pulled in by half a pixel along each axis (about the centre
    of their bounding box) so that OpenCV's pixel-inclusive filling covers the polygon's
    true extent: ``fillConvexPoly`` covers pixel centres up to half a pixel outside the
    given vertices (LINE_8 rounds them, LINE_AA fills them fully and adds a fringe).

    One affine map per part, so faces that share an edge still share it.
    """
    x0, y0 = pts.min(axis=0).tolist()
    x1, y1 = pts.max(axis=0).tolist()
    wx, wy = x1 - x0, y1 - y0
    sx = (wx - 1.0) / wx if wx > 1.0 else 0.0
    sy = (wy - 1.0) / wy if wy > 1.0 else 0.0
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    out = np.empty_like(pts)
    out[:, 0] = cx + (pts[:, 0] - cx) * sx
    out[:, 1] = cy + (pts[:, 1] - cy) * sy
    return out


def _sq_norm(v: NDArray) -> float:
    x, y, z = v.tolist()
    return x * x + y * y + z * z


def _fill(plane: NDArray, pts: NDArray, value: float, aa: bool) -> None:
    """Fill the convex polygon with vertices ``pts`` ((K, 2) or (K, 1, 2) pixels) on a plane."""
    p = np.rint(np.asarray(pts, dtype=np.float64).reshape(-1, 2) * 16.0).astype(np.int32)
    line = cv2.LINE_AA if aa else cv2.LINE_8
    cv2.fillConvexPoly(plane, p, float(value), lineType=line, shift=4)


def _visible_box(
    pr: _Projected, occluders: list[_Projected], box: tuple[float, float, float, float]
) -> tuple[tuple[float, float, float, float], float] | None:
    """Box and unoccluded fraction of a ship partly hidden by nearer ones (raster test).

    Pixels whose centres lie inside the ship's silhouette, minus those inside a nearer
    ship's silhouette; the box is their extent (±0.5 px) within the continuous box.
    None when nothing is visible.
    """
    x0, y0, x1, y1 = box
    i0, i1 = math.ceil(x0), math.floor(x1)
    j0, j1 = math.ceil(y0), math.floor(y1)
    if i1 < i0 or j1 < j0:  # smaller than a pixel: visible unless its centre is covered
        cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
        for q in occluders:
            for _, p, _ in q.parts:
                hull = cv2.convexHull(p.astype(np.float32))
                if cv2.pointPolygonTest(hull, (cx, cy), False) >= 0:
                    return None
        return box, 1.0
    shape = (j1 - j0 + 1, i1 - i0 + 1)
    own = np.zeros(shape, np.uint8)
    occ = np.zeros(shape, np.uint8)
    off = np.array([i0, j0], dtype=np.float64)
    for _, p, _ in pr.parts:
        _fill(own, cv2.convexHull(_shrink(p - off).astype(np.float32)), 1, aa=False)
    for q in occluders:
        for _, p, _ in q.parts:
            _fill(occ, cv2.convexHull(_shrink(p - off).astype(np.float32)), 1, aa=False)
    n_own = int(own.sum())
    vis = own & (1 - occ)
    n_vis = int(vis.sum())
    if n_own == 0:
        return box, 1.0
    if n_vis == 0:
        return None
    rows = np.flatnonzero(vis.any(axis=1))
    cols = np.flatnonzero(vis.any(axis=0))
    bx0 = max(x0, i0 + cols[0] - 0.5)
    bx1 = min(x1, i0 + cols[-1] + 0.5)
    by0 = max(y0, j0 + rows[0] - 0.5)
    by1 = min(y1, j0 + rows[-1] + 0.5)
    return (bx0, by0, bx1, by1), n_vis / n_own


# ----------------------------------------------------------------------------- video out
class _VideoEncoder:
    """H.264 (libx264) MP4 writer for I420 frames, encoding on a background thread.

    A small local writer (PyAV) rather than `seawatch.io.video.VideoWriter`, which takes
    BGR images, converts them with swscale and encodes in the caller's thread (about
    twice the CPU per 1080p frame, and no overlap): the renderer draws I420 directly, so
    frames are copied into ``av.VideoFrame`` as they are, then encoded and muxed by a
    worker so that rendering and encoding overlap on two cores. Tagged BT.601 limited
    range (OpenCV's I420 ↔ BGR convention).
    """

    def __init__(
        self, path: Path, width: int, height: int, fps: float, crf: int, preset: str
    ) -> None:
        from fractions import Fraction

        import av

        self._av = av
        # index at the front, as seawatch.io.video.VideoWriter writes MP4 files
        self._container = av.open(str(path), mode="w", options={"movflags": "+faststart"})
        rate = Fraction(fps).limit_denominator(1001)
        stream = self._container.add_stream("libx264", rate=rate)
        stream.width = width
        stream.height = height
        stream.pix_fmt = "yuv420p"
        stream.options = {"crf": str(crf), "preset": preset}
        cc = stream.codec_context
        cc.colorspace = 5  # ITU-R BT.601 (BT.470BG / SMPTE 170M matrix)
        cc.color_range = 1  # limited (MPEG)
        self._stream = stream
        self._queue: queue.Queue[Any] = queue.Queue(maxsize=4)
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._work, name="synth-encoder", daemon=True)
        self._thread.start()
        self._index = 0

    def _work(self) -> None:
        while True:
            frame = self._queue.get()
            if frame is None:
                break
            if self._error is not None:
                continue
            try:
                for packet in self._stream.encode(frame):
                    self._container.mux(packet)
            except BaseException as exc:  # reported to the caller
                self._error = exc

    def write(self, yuv: NDArray[np.uint8]) -> None:
        """Queue one I420 frame (copied)."""
        if self._error is not None:
            raise RuntimeError(f"video encoding failed: {self._error}") from self._error
        frame = self._av.VideoFrame.from_ndarray(yuv, format="yuv420p")
        frame.pts = self._index
        frame.color_range = 1
        self._index += 1
        self._queue.put(frame)

    def close(self) -> None:
        """Flush the encoder and close the file."""
        self._queue.put(None)
        self._thread.join()
        try:
            if self._error is None:
                for packet in self._stream.encode():
                    self._container.mux(packet)
        finally:
            self._container.close()
        if self._error is not None:
            raise RuntimeError(f"video encoding failed: {self._error}") from self._error


def _fmt(x: float, nd: int) -> str:
    return "" if not math.isfinite(x) else f"{x:.{nd}f}"


def render(
    camera: PinholeCamera,
    ships: Sequence[Ship],
    duration: float,
    fps: float,
    *,
    out_dir: str | Path,
    lighting: str | Lighting = "day",
    sway: tuple[float, float, float] | None = None,
    coastline: bool = False,
    seed: int = 0,
    progress: Progress | None = None,
    earth: Earth = "flat",
    start_time: float = 0.0,
    noise: bool = True,
    crf: int = 20,
    preset: str = "ultrafast",
    description: str | None = None,
    pan: tuple[float, float] | None = None,
) -> RenderResult:
    """Render ``duration`` [s] of footage at ``fps`` [1/s] into ``out_dir``.

    Writes ``video.mp4`` (H.264, yuv420p), ``camera.yaml`` (the mounting camera, via
    `seawatch.io.save_camera`), ``truth.csv`` and ``horizon.csv`` (module docstring),
    the CSVs flushed after every frame. ``progress(done, total)`` is called after each
    frame. Other arguments as in :class:`Renderer`; ``crf``/``preset`` are libx264's
    (``crf`` 0–51, lower is better; 0 is lossless: the decoded I420 frames are exactly
    the rendered ones, so compression can be told apart from the rest of a pipeline's
    error). Returns a :class:`RenderResult`.
    """
    from seawatch.io import save_camera

    d = positive("duration", duration)
    f = positive("fps", fps)
    crf = integer("crf", crf, 0, 51)
    n_frames = max(1, round(d * f))
    renderer = Renderer(
        camera,
        ships,
        f,
        lighting=lighting,
        sway=sway,
        coastline=coastline,
        seed=seed,
        earth=earth,
        start_time=start_time,
        noise=noise,
        pan=pan,
    )
    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".seawatch-write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise ValueError(f"out_dir: cannot write to {out}: {exc}") from None
    paths = {
        "video": out / "video.mp4",
        "camera": out / "camera.yaml",
        "truth": out / "truth.csv",
        "horizon": out / "horizon.csv",
    }
    save_camera(camera, paths["camera"], description=description)
    w, h = camera.image_size
    t_start = _time.perf_counter()
    seen: set[int] = set()
    rows = 0
    geo = camera.lat is not None and camera.lon is not None
    with (
        paths["truth"].open("w", newline="", encoding="utf-8") as tf,
        paths["horizon"].open("w", newline="", encoding="utf-8") as hf,
    ):
        tw = csv.writer(tf)
        hw = csv.writer(hf)
        tw.writerow(TRUTH_COLUMNS)
        hw.writerow(HORIZON_COLUMNS)
        tf.flush()
        hf.flush()
        encoder = _VideoEncoder(paths["video"], w, h, f, crf, preset)
        buf = np.empty((h * 3 // 2, w), np.uint8)
        try:
            for i in range(n_frames):
                cam, truth, hz = renderer.render_into(i, buf)
                encoder.write(buf)
                t = i / f
                if truth and geo:
                    rel = np.array(
                        [[o.north - cam.position[0], o.east - cam.position[1]] for o in truth]
                    )
                    lat, lon = north_east_to_geodetic(rel, cam.lat, cam.lon)
                    lat = np.atleast_1d(lat)
                    lon = np.atleast_1d(lon)
                else:
                    lat = lon = np.full(len(truth), np.nan)
                for k, o in enumerate(truth):
                    tw.writerow(
                        (
                            _fmt(t, 6),
                            i,
                            o.object_id,
                            _fmt(o.x, 4),
                            _fmt(o.y, 4),
                            _fmt(o.w, 4),
                            _fmt(o.h, 4),
                            _fmt(o.u_wl, 4),
                            _fmt(o.v_wl, 4),
                            _fmt(o.east, 4),
                            _fmt(o.north, 4),
                            _fmt(float(lat[k]), 9),
                            _fmt(float(lon[k]), 9),
                            _fmt(o.range, 4),
                            _fmt(math.degrees(o.azimuth), 6),
                            _fmt(math.degrees(o.depression), 7),
                            _fmt(math.degrees(o.heading), 4),
                            _fmt(o.speed, 4),
                            _fmt(o.length, 3),
                            _fmt(o.top, 3),
                            _fmt(o.visible, 4),
                        )
                    )
                    seen.add(o.object_id)
                rows += len(truth)
                hw.writerow(
                    (
                        i,
                        _fmt(hz[0], 4),
                        _fmt(hz[1], 4),
                        _fmt(hz[2], 4),
                        _fmt(hz[3], 4),
                        _fmt(t, 6),
                        _fmt(math.degrees(cam.pitch), 6),
                        _fmt(math.degrees(cam.roll), 6),
                    )
                )
                tf.flush()
                hf.flush()
                if progress is not None:
                    progress(i + 1, n_frames)
        finally:
            encoder.close()
    seconds = _time.perf_counter() - t_start
    return RenderResult(
        out_dir=out,
        video=paths["video"],
        camera=paths["camera"],
        truth=paths["truth"],
        horizon=paths["horizon"],
        frames=n_frames,
        fps=f,
        duration=n_frames / f,
        image_size=(w, h),
        objects=tuple(sorted(seen)),
        rows=rows,
        seconds=seconds,
    )
