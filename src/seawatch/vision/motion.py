"""Camera motion between frames: the sideways image shift of a panning or yawing camera.

Issue 6, "a swaying or panning camera". A ship tracked in pixels moves with the camera as
well as over the sea: a pan of ±4° in 3 s moves a 960-px, 60° view by up to 5 px a frame,
a yawing boat's camera by several. The constant-velocity model of the visual tracker lags
those accelerations. :class:`CameraMotion` measures the horizontal translation of the
image between consecutive frames and accumulates it into an *offset*: the current
frame's content lies at ``pixel - offset`` in the first frame's coordinates. The visual
tracker subtracts it from the detections and adds it back to its tracks (camera-motion
compensation, as in BoT-SORT, Aharon et al. 2022, with a global translation instead of a
feature homography).

Measurement: phase correlation (Kuglin & Hines 1975, ``cv2.phaseCorrelate``,
Hann-windowed) of the two grey frames above the horizon (sky, clouds, coast), downscaled
by a whole factor to about ``width`` px (a fraction, 0.75 with area averaging, shrank
the shifts measured on a textured test frame by 2.4 %). On the rendered clips it gives a
pan to 0.13 px a frame. Refining it by ECC alignment (``cv2.findTransformECC``) was
tried: exact on a synthetic texture, but on the rendered crossing case the coast above
the horizon drew it 23 px off over 200 frames of a fixed camera, and the pan case came
out worse (0.48 → 0.58 % CLE). Above the horizon, because the sea is no
rigid background: its waves travel, and on the rendered demo clip (a fixed camera, 10
frames/s) the whole frame correlates at a steady 1 px a frame to the left, where the
sky alone gives 0.0. Sea scenes have few corners for sparse optical flow (a handful on
the rendered cases, with shifts of ±10 px on a fixed camera); the phase of the whole
band's spectrum holds the faint texture of clouds and haze. A pure rotation of the
camera moves every pixel alike, whatever its distance, so the translation is the pan in
the middle of the view. Without a horizon, or with under :data:`MIN_SKY` of the frame
above it, nothing is measured.

Only the horizontal shift is used (``offset[1]`` stays 0). The vertical one — pitch
sway — is slow beside the tracker's model, and the world stage takes each frame's pitch
and roll from the horizon: measured on the moving-platform clips, adding the sky's
vertical shift took uav-sea's EKF position error from 20.7 to 23.6 m and range-1km's from
31.6 to 35.6 m, the horizon's row change to 21.3 and 34.2 m (crossing, whose coast
bends the horizon, 8.3 → 9.9 % CLE); the horizontal shift alone, 20.7 and 31.6 m.

Gate: a fixed camera's frames still register at shifts of a tenth of a pixel (clouds,
compression), now and then at a lone peak of ±10 px (sensor noise on lossless footage),
and adding either up would wander the tracks. The offset therefore grows only while the
camera moves. A pan starts when the median shift of the last ``window`` frames is at
least ``gate_px`` (not before over half of ``window`` frames are measured: the first
shift of the lossless renders, 0.9 px, would have started one), and goes on while the mean size of
their shifts is at least half of it (through the turns of a pan to and fro). A shift
further than :data:`_JUMP_PX` from the window's median is replaced by that median (a pan
changes smoothly). Only frames whose phase-correlation peak is at least
``min_response`` are measured: 0.7–1.0 on the day skies of the rendered cases and
moving-platform clips, 0.16 (median) on the night case's grain, whose weak peaks fall
anywhere (±20 px; with 0.1 its fixed camera wandered 175 px in 8 s and its CLE went
1.19 → 12.8 %). A cut, a blank frame or a clear sky gives no peak. On a fixed camera
the offset stays 0 and the tracker is exactly the uncompensated one.
"""

from __future__ import annotations

from collections import deque
from typing import Any

import cv2
import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import FloatArray, integer, positive

__all__ = ["MIN_SKY", "CameraMotion"]

MIN_SKY = 0.08
"""Least part of the frame height above the horizon (less its margin) to measure on."""
_MARGIN = 0.02  # [of the height] left out above the horizon: ships' upper works
_JUMP_PX = 2.0  # [px a frame] farthest a pan's shift lies from the window's median


class CameraMotion:
    """Accumulated image translation of a moving camera (module docstring).

    Args:
        width: frames are downscaled by the whole factor that keeps them at least this
            wide [px] before the correlation.
        window: frames whose shifts decide whether the camera moves.
        gate_px: least median shift [px per frame] that starts a pan (half of it, as
            the mean shift size, keeps it going).
        min_response: least phase-correlation peak of a shift that is used (0–1).

    Attributes:
        offset: the accumulated shift (x, y) [px]: the current frame's content lies at
            ``pixel - offset`` in the first frame's coordinates (y: 0, module docstring).
        shift: the last frame's measured shift (x, y) [px] (0 when unknown).
        moving: whether the last frame counted as camera motion.
    """

    def __init__(
        self,
        width: int = 480,
        window: int = 9,
        gate_px: float = 0.5,
        min_response: float = 0.5,
    ) -> None:
        self.width = integer("width", width, 16)
        self.window = integer("window", window, 1)
        self.gate_px = positive("gate_px", gate_px, allow_zero=True)
        self.min_response = positive("min_response", min_response, allow_zero=True)
        self.reset()

    def reset(self) -> None:
        """Forget the previous frame and the offset (a new video)."""
        self.offset = np.zeros(2)
        self.shift = np.zeros(2)
        self.moving = False
        self._prev: FloatArray | None = None
        self._prev_shape: tuple[int, ...] | None = None
        self._shifts: deque[float] = deque(maxlen=self.window)  # as measured
        self._steps: deque[float] = deque(maxlen=self.window)  # odd peaks replaced

    def update(self, image: ArrayLike, horizon: Any = None) -> FloatArray:
        """Measure the next frame (in frame order) and return the offset (x, y) [px].

        ``horizon``: the frame's :class:`~seawatch.vision.horizon.HorizonEstimate`; the
        rows above it are measured (none without one). A frame of another size than the
        previous one restarts the measurement (the offset is kept: the caller decides
        what a size change means)."""
        img = np.asarray(image)
        k = max(1, img.shape[1] // self.width)  # a whole factor (module docstring)
        height = img.shape[0] // k
        band = self._band(img, k, self._sky_rows(horizon, height, k))
        prev, prev_shape = self._prev, self._prev_shape
        self._prev, self._prev_shape = band, img.shape
        self.shift = np.zeros(2)
        if prev is None or prev_shape != img.shape:
            self._shifts.clear()
            self._steps.clear()
            self.moving = False
            return self.offset.copy()
        rows = min(band.shape[0], prev.shape[0])
        if rows >= MIN_SKY * height:
            a, b = prev[:rows], band[:rows]
            hann = cv2.createHanningWindow(a.shape[::-1], cv2.CV_32F)  # 0.1 ms
            self.shift[0] = self._register(a, b, hann) * k
        step = float(self.shift[0])
        self._shifts.append(step)
        typical = float(np.median(self._shifts))
        if abs(step - typical) > _JUMP_PX:  # an odd peak, no pan's change: the pan goes on
            step = typical
        self._steps.append(step)
        if self.moving:  # a pan goes on while its steps are not small (through its turns)
            self.moving = float(np.mean(np.abs(self._steps))) >= 0.5 * self.gate_px
        else:  # and starts when most of the window's shifts say so, at least half of it
            enough = 2 * len(self._shifts) > self.window
            self.moving = enough and abs(typical) >= self.gate_px
        if self.moving:
            self.offset = self.offset + np.array([step, 0.0])
        return self.offset.copy()

    def _register(self, a: FloatArray, b: FloatArray, hann: FloatArray) -> float:
        """Horizontal shift [px of ``a``] of ``b``'s content against ``a``'s by phase
        correlation; 0 when its peak is under ``min_response``."""
        (dx, dy), response = cv2.phaseCorrelate(a, b, hann)
        if not (response >= self.min_response and np.isfinite(dx) and np.isfinite(dy)):
            return 0.0
        return float(dx)

    def _sky_rows(self, horizon: Any, height: int, k: int) -> int:
        """Rows of the frame downscaled by ``k`` (``height`` rows) above the horizon's
        highest point, less a margin (0 without a horizon)."""
        if horizon is None or not getattr(horizon, "found", False):
            return 0
        top = min(float(horizon.y0), float(horizon.y1)) / k - _MARGIN * height
        return int(np.clip(np.floor(top), 0, height))

    @staticmethod
    def _band(img: np.ndarray, k: int, rows: int) -> FloatArray:
        """The top ``rows`` rows of the frame downscaled by ``k``, grey float32 (the
        colour conversion and the area averaging on the frame's own pixel type, and only
        on the sky: a 1080p frame's band costs about a millisecond)."""
        width = img.shape[1] // k
        if rows == 0:
            return np.empty((0, width), np.float32)
        part = img[: rows * k, : width * k]
        if part.dtype not in (np.uint8, np.uint16, np.float32):
            part = part.astype(np.float32)
        if part.ndim == 3:
            part = part[..., :3] if part.shape[2] >= 3 else part[..., 0]
        if part.ndim == 3:
            part = cv2.cvtColor(np.ascontiguousarray(part), cv2.COLOR_BGR2GRAY)
        if k > 1:
            part = cv2.resize(part, (width, rows), interpolation=cv2.INTER_AREA)
        g = np.asarray(part, dtype=np.float32)
        return np.where(np.isfinite(g), g, 0.0).astype(np.float32)
