"""Camera motion between frames: the sideways shift of a panning or yawing camera, and the
zoom of a camera that changes its focal length.

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

Zoom (a PTZ camera changing its focal length, an EO sight zooming in on a contact): the
frame is magnified by ``s`` about its centre ``c`` from one frame to the next, so a
point moves by ``(s − 1)(p − c)``, away from the centre or towards it. The real MarDCT
ir-3 clip (``../shared/data/mardct_ir3/``) zooms out by 5–8 % a frame in its frames
1–13: the boat, nearly still on the sea, crosses 150 px of the frame and stops dead when
the zoom does. The scale is measured from the horizontal shifts of the sky band's left
and right halves, ``s − 1 = (d_right − d_left) / (W/2)`` (their centres lie half the
band's width apart), refined by magnifying the earlier band by the scale found and
measuring the halves again, until a round changes it by under 0.1 % (at most three
rounds; a first round under 0.1 % gives exactly 1); the pan's shift is then the whole
band's against the magnified one. A half's first peak is weak under a zoom (the half is
stretched); both of the last round's must reach ``min_response``. Then the rows must
agree (:meth:`CameraMotion._vertical_agrees`): the band's upper and lower halves shift
alike once magnified, which a zoom does and a widening of the columns alone does not —
the rendered uav-sea clip, a boat's camera turning, widens its sky by 0.4–0.8 % a frame
across for 60 frames with the rows 0.2 % closer together. On MarDCT the scales add up to
0.456 at frame 17, where one registration of frames 0 and 17 (a search over the scale)
finds 0.455; the rendered fixed cameras (24 clips) measure no change but in 0–2 of 200
frames, at most 0.15 %, the moving ones at most 0.26 % (uav-sea) and 0.41 % (the pan
clip). A Fourier–Mellin registration (log-polar magnitude spectra, the textbook method)
was tried first: on MarDCT's zooming frames it gave scales within 0.4 % of 1 but one of
10.5, with peaks of 0.08–0.57.

A zoom starts when two frames in a row change the scale the same way by ``gate_zoom`` or
more, the first of them included (a zoom seldom lasts a window's frames: the clip's 13
would lose five), and goes on while the mean ``|ln s|`` of the window is at least half
of it; a frame not measured meanwhile takes the last step. Unlike a pan's, a zoom's
steps are not smoothed by the window's median, as a zoom lens stops dead. The zoom is
accumulated in ``scale`` and taken out about the frame's centre ``c``: the frame's pixel
``p`` is ``c + (p − c) / scale`` at the first frame's focal length, and the pan's
``offset`` is added up there (a shift ``d`` measured at ``scale`` is ``d / scale`` of
it). While zooming, the vertical shift is added up too: MarDCT's zoom centre lies about
12 px above the frame's (0.5–1 px a frame, 6 px by frame 17). Without a zoom ``scale``
is 1 and everything is as above.
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
_ZOOM_START = 2  # steps in a row beyond ``gate_zoom`` that start a zoom
_ZOOM_ROUNDS = 3  # most rounds of the scale's refinement (module docstring)
_ZOOM_DONE = 1e-3  # a round that changes the scale by less ends the refinement


class CameraMotion:
    """Accumulated image translation of a moving camera (module docstring).

    Args:
        width: frames are downscaled by the whole factor that keeps them at least this
            wide [px] before the correlation.
        window: frames whose shifts decide whether the camera moves.
        gate_px: least median shift [px per frame] that starts a pan (half of it, as
            the mean shift size, keeps it going).
        min_response: least phase-correlation peak of a shift that is used (0–1).
        gate_zoom: least median ``|ln s|`` of a frame's scale change that starts a zoom
            (0.005: a zoom of 0.5 % a frame, 2× in 5.6 s at 25 frames/s); half of it, as
            the mean, keeps it going.

    Attributes:
        offset: the accumulated shift (x, y) [px]: the current frame's content lies at
            ``centre + (pixel - centre) / scale - offset`` in the first frame's
            coordinates (y: 0, module docstring).
        scale: the accumulated zoom: a length in the first frame is ``scale`` times
            as long in the current one (1 for a camera that does not zoom).
        centre: the frame's centre (x, y) [px] about which it zooms.
        shift: the last frame's measured shift (x, y) [px] (0 when unknown).
        zoom: the last frame's measured scale change s (1 when unknown).
        moving: whether the last frame counted as a pan.
        zooming: whether the last frame counted as a zoom.
    """

    def __init__(
        self,
        width: int = 480,
        window: int = 9,
        gate_px: float = 0.5,
        min_response: float = 0.5,
        gate_zoom: float = 0.005,
    ) -> None:
        self.width = integer("width", width, 16)
        self.window = integer("window", window, 1)
        self.gate_px = positive("gate_px", gate_px, allow_zero=True)
        self.min_response = positive("min_response", min_response, allow_zero=True)
        self.gate_zoom = positive("gate_zoom", gate_zoom, allow_zero=True)
        self.reset()

    def reset(self) -> None:
        """Forget the previous frame, the offset and the scale (a new video)."""
        self.offset = np.zeros(2)
        self.scale = 1.0
        self.centre = np.zeros(2)
        self.shift = np.zeros(2)
        self.zoom = 1.0
        self.moving = False
        self.zooming = False
        self._prev: FloatArray | None = None
        self._prev_shape: tuple[int, ...] | None = None
        self._shifts: deque[float] = deque(maxlen=self.window)  # as measured
        self._steps: deque[float] = deque(maxlen=self.window)  # odd peaks replaced
        self._zooms: deque[float] = deque(maxlen=self.window)  # ln s, as measured

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
        self.centre = 0.5 * (np.array(img.shape[1::-1], float) - 1.0)  # [px]
        self.shift = np.zeros(2)
        self.zoom = 1.0
        if prev is None or prev_shape != img.shape:
            self._shifts.clear()
            self._steps.clear()
            self._zooms.clear()
            self.moving = self.zooming = False
            return self.offset.copy()
        rows = min(band.shape[0], prev.shape[0])
        at = (self.centre - 0.5 * (k - 1)) / k  # the centre in the band's pixels
        zoom = None  # the scale change measured (None: not measurable)
        if rows >= MIN_SKY * height:
            a, b = prev[:rows], band[:rows]
            zoom = self._scale(a, b, at)
        if zoom is None:  # a zoom goes on at its last step, else none is seen
            zoom = float(np.exp(self._zooms[-1])) if self.zooming else 1.0
        self._zooms.append(float(np.log(zoom)))
        missed = 1.0  # the zoom of the frames before it started
        if self.zooming:  # a zoom goes on while its steps are not small
            self.zooming = float(np.mean(np.abs(self._zooms))) >= 0.5 * self.gate_zoom
        else:  # and starts on two steps in a row beyond the gate, the same way
            last = list(self._zooms)[-_ZOOM_START:]
            self.zooming = len(last) == _ZOOM_START and (
                min(last) >= self.gate_zoom or max(last) <= -self.gate_zoom
            )
            if self.zooming:
                missed = float(np.exp(sum(last[:-1])))
        if self.zooming:
            self.zoom = zoom
        if rows >= MIN_SKY * height:
            if self.zoom != 1.0:  # the earlier band as the zoom leaves it
                a = _magnify(a, self.zoom, at)
            hann = cv2.createHanningWindow(a.shape[::-1], cv2.CV_32F)  # 0.1 ms
            self.shift[:] = np.multiply(self._register(a, b, hann), k)
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
        self.scale *= self.zoom * missed
        # at the first frame's focal length (module docstring); the vertical shift only
        # while zooming: the zoom's centre lies off the frame's
        rise = float(self.shift[1]) if self.zoom != 1.0 else 0.0
        if self.moving or rise:
            self.offset = self.offset + np.array([step if self.moving else 0.0, rise]) / self.scale
        return self.offset.copy()

    def _scale(self, a: FloatArray, b: FloatArray, centre: FloatArray) -> float | None:
        """The scale change s of ``b``'s content against ``a``'s about ``centre`` [px of
        ``a``] from the horizontal shifts of the bands' halves (module docstring); None
        when the last round's peaks are not both ``min_response`` or more (the first
        round's are weak under a zoom: each half is stretched), or s is not within
        (0.5, 2)."""
        half = a.shape[1] // 2
        if half < 8:
            return None
        hann = cv2.createHanningWindow((half, a.shape[0]), cv2.CV_32F)
        s, warped = 1.0, a
        for _ in range(_ZOOM_ROUNDS):
            shifts, peaks = [], []
            for part in (slice(0, half), slice(half, 2 * half)):
                (dx, dy), response = _correlate(warped[:, part], b[:, part], hann)
                if not (np.isfinite(dx) and np.isfinite(dy)):
                    return None
                shifts.append(dx)
                peaks.append(response)
            change = (shifts[1] - shifts[0]) / half  # the halves' centres: half apart
            if abs(change) < _ZOOM_DONE:
                break
            s *= 1.0 + change
            if not 0.5 < s < 2.0:
                return None
            warped = _magnify(a, s, centre)
        if min(peaks) < self.min_response:
            return None
        if s != 1.0 and not self._vertical_agrees(warped, b, float(np.log(s))):
            return 1.0
        return float(s)

    def _vertical_agrees(self, warped: FloatArray, b: FloatArray, log_s: float) -> bool:
        """Whether the band's upper and lower halves, ``warped`` by the scale found,
        shift alike in the vertical (within half of ``log_s`` as a scale over their
        distance): a zoom magnifies the rows as it does the columns, while a camera
        turning about a tilted axis (a boat's camera pitching as it yaws) or a sky
        that is not at infinity widens the band's content alone (the rendered
        uav-sea clip: 0.4–0.8 % a frame across for 60 frames, with the rows
        0.2 % closer together). A half without a peak of ``min_response`` cannot
        tell (MarDCT's upper half, an empty thermal sky: 0.02–0.3): it agrees."""
        half = warped.shape[0] // 2
        hann = cv2.createHanningWindow((warped.shape[1], half), cv2.CV_32F)
        rises = []
        for part in (slice(0, half), slice(half, 2 * half)):
            (_, dy), response = _correlate(warped[part], b[part], hann)
            if not (response >= self.min_response and np.isfinite(dy)):
                return True
            rises.append(dy)
        return abs((rises[1] - rises[0]) / half) <= 0.5 * abs(log_s)

    def _register(self, a: FloatArray, b: FloatArray, hann: FloatArray) -> tuple[float, float]:
        """Shift (x, y) [px of ``a``] of ``b``'s content against ``a``'s by phase
        correlation; (0, 0) when its peak is under ``min_response``."""
        (dx, dy), response = _correlate(a, b, hann)
        if not (response >= self.min_response and np.isfinite(dx) and np.isfinite(dy)):
            return 0.0, 0.0
        return float(dx), float(dy)

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


def _magnify(image: FloatArray, s: float, centre: FloatArray) -> FloatArray:
    """``image`` magnified by ``s`` about ``centre`` (x, y) [px], the same size (its
    border mirrored)."""
    cx, cy = float(centre[0]), float(centre[1])
    m = np.float32([[s, 0.0, (1.0 - s) * cx], [0.0, s, (1.0 - s) * cy]])
    size = (image.shape[1], image.shape[0])
    return cv2.warpAffine(image, m, size, flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)


def _correlate(a: FloatArray, b: FloatArray, hann: FloatArray) -> tuple[tuple[float, float], float]:
    """``cv2.phaseCorrelate(a, b, hann)`` on copies: OpenCV (5.0.0 here) multiplies its
    inputs by the window in place where their size needs no padding for the DFT
    (measured: a float32 band of 108 × 480 px, whole or a view of its rows, equals
    ``a · hann`` to the last bit afterwards; one of 106, 107 or 122–124 rows is left
    alone). Until session 29 the band kept for the next frame was so windowed, and
    windowed again there: on the rendered pan clip from frame 39 on (its sky band 108
    rows high), not on uav-sea's 1080p frames."""
    return cv2.phaseCorrelate(a.copy(), b.copy(), hann)  # type: ignore[no-any-return]
