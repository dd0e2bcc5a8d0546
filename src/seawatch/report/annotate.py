"""``annotated.mp4``: the tracks drawn on the video (issue 7).

:class:`Annotator` draws on a BGR frame (OpenCV): each track's box in a colour of its own
(:func:`track_colour`), a label next to the box with the track id, the MMSI if any, the
range (``850 m`` below 1 km, ``2.41 km`` above) and the speed in knots (``12.3 kn``) below
the box (where the sea is: above it the label would hide masts and superstructure), a
ring on the water-line point, and the horizon line. :class:`AnnotatedVideo` draws and
encodes frame by frame through :class:`seawatch.io.video.VideoWriter` (H.264 MP4); it keeps
no frames itself.

Crash safety: the MP4 is written *fragmented* (``frag_keyframe+empty_moov``, a fragment at
most every :data:`FRAGMENT_S` seconds, packets flushed to the file as they are muxed), so a
crash, Ctrl-C or kill leaves a playable file holding all but the last fragment and the
encoder's look-ahead (measured: 0.6–0.7 s lost at 25 fps, of which ≈0.5 s is libx264's
look-ahead). A plain MP4 keeps its index at the end and is unplayable until closed. The
fragmented file plays everywhere MP4 does (it is the DASH/MSE layout); players show no
total duration until the file is complete.
"""

from __future__ import annotations

import colorsys
import math
import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any, Protocol

import cv2
import numpy as np
from numpy.typing import NDArray

from seawatch.io.video import VideoWriter
from seawatch.report.geojson import KNOT

__all__ = ["AnnotatedVideo", "Annotator", "HorizonLike", "format_range", "track_colour"]

FRAGMENT_S = 0.25
"""Longest duration of one MP4 fragment [s] (what a crash can lose, plus encoder delay)."""

FRAGMENTED_MP4 = {
    "movflags": "+frag_keyframe+empty_moov+default_base_moof",
    "frag_duration": str(round(FRAGMENT_S * 1e6)),
    "flush_packets": "1",
}
"""Muxer options of ``annotated.mp4``: fragments of at most :data:`FRAGMENT_S`, each packet
flushed to the file as it is muxed."""


def _is_mp4(path: str | os.PathLike[str]) -> bool:
    return Path(path).suffix.lower() in (".mp4", ".mov", ".m4v")


_GOLDEN = 0.6180339887498949
_FONT = cv2.FONT_HERSHEY_SIMPLEX
_HORIZON_BGR = (255, 255, 0)  # cyan


class HorizonLike(Protocol):
    """A horizon line such as :class:`seawatch.vision.horizon.HorizonEstimate`: the line
    through (x0, y0) and (x1, y1) [px], drawn only when ``found``."""

    found: bool
    x0: float
    y0: float
    x1: float
    y1: float


def track_colour(track_id: int) -> tuple[int, int, int]:
    """A bright colour for a track id, as (B, G, R) in 0–255.

    Hues step by the golden ratio of a turn per id, so that consecutive ids get well
    separated colours; the same id always gets the same colour (the HTML report uses it
    too, reversed to RGB).
    """
    hue = (int(track_id) * _GOLDEN) % 1.0
    r, g, b = colorsys.hsv_to_rgb(hue, 0.85, 1.0)
    return round(b * 255), round(g * 255), round(r * 255)


def format_range(range_m: float) -> str:
    """Range for a label: whole metres below 1 km (``850 m``), km with two decimals above
    (``2.41 km``); empty for NaN/inf."""
    if not math.isfinite(range_m) or range_m < 0:
        return ""
    return f"{range_m:.0f} m" if range_m < 999.5 else f"{range_m / 1000.0:.2f} km"


def _num(value: Any) -> float:
    if value is None or (isinstance(value, str) and not value.strip()):
        return math.nan
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def _mmsi(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float | np.floating):
        return str(int(value)) if math.isfinite(value) else ""
    text = str(value).strip()
    if text.endswith(".0") and text[:-2].isdigit():
        text = text[:-2]
    return "" if text.lower() in ("nan", "none") else text


def _to_bgr8(image: NDArray[Any]) -> NDArray[np.uint8]:
    img = np.asarray(image)
    if img.ndim == 3 and img.shape[2] == 4:
        img = img[:, :, :3]
    if img.ndim == 3 and img.shape[2] == 1:
        img = img[:, :, 0]
    if not (img.ndim == 2 or (img.ndim == 3 and img.shape[2] == 3)):
        raise ValueError(f"image: expected (H, W) or (H, W, 3) pixels, got shape {img.shape}")
    if img.dtype == np.uint16:
        img = (img.astype(np.float32) / 257.0 + 0.5).astype(np.uint8)
    elif img.dtype != np.uint8:
        if not np.issubdtype(img.dtype, np.number):
            raise ValueError(f"image: expected numeric pixels, got {img.dtype}")
        img = np.clip(np.nan_to_num(img.astype(np.float32)), 0, 255).astype(np.uint8)
    if img.ndim == 2:
        img = cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
    return np.ascontiguousarray(img)


class Annotator:
    """Draws tracks and the horizon on video frames.

    Sizes scale with the image (line thickness ≈ height/540 px, text ≈ 0.45·height/540)
    unless given. Labels sit below the box, on the sea (above it where there is no room),
    on a backing in the track's colour (:func:`track_colour`); units are on the labels:
    range in m/km, speed in knots (``kn``; 1 kn = 1852/3600 m/s).

    Args:
        thickness: line thickness [px], ≥ 1 (None: from the image height).
        font_scale: OpenCV font scale, > 0 (None: from the image height).
        show_time: write ``t = …s  frame …`` in the top-left corner when the time is given.
    """

    def __init__(
        self,
        *,
        thickness: int | None = None,
        font_scale: float | None = None,
        show_time: bool = True,
    ) -> None:
        if thickness is not None and not (isinstance(thickness, int) and thickness >= 1):
            raise ValueError(f"thickness: expected an integer >= 1 [px], got {thickness!r}")
        if font_scale is not None and not (
            isinstance(font_scale, int | float) and math.isfinite(font_scale) and font_scale > 0
        ):
            raise ValueError(f"font_scale: expected a number > 0, got {font_scale!r}")
        self.thickness = thickness
        self.font_scale = font_scale
        self.show_time = bool(show_time)

    def _sizes(self, height: int) -> tuple[int, float, int]:
        t = self.thickness or max(1, round(height / 540))
        fs = self.font_scale or max(0.35, 0.45 * height / 540)
        return t, fs, max(1, round(fs * 2.2))

    def label(self, row: Mapping[str, Any]) -> list[str]:
        """The label lines of one track row: ``#id[ MMSI]`` and ``range  speed kn``."""
        tid = _num(row.get("track_id"))
        first = f"#{int(tid)}" if math.isfinite(tid) else "#?"
        mmsi = _mmsi(row.get("mmsi"))
        if mmsi:
            first += f" {mmsi}"
        parts = [format_range(_num(row.get("range_m")))]
        speed = _num(row.get("speed_mps"))
        if math.isfinite(speed) and speed >= 0:
            parts.append(f"{speed / KNOT:.1f} kn")
        second = "  ".join(p for p in parts if p)
        return [first, second] if second else [first]

    def draw(
        self,
        image: NDArray[Any],
        tracks: Iterable[Mapping[str, Any]] = (),
        horizon: HorizonLike | None = None,
        *,
        time: float | None = None,
        frame: int | None = None,
    ) -> NDArray[np.uint8]:
        """A copy of ``image`` with the tracks and the horizon drawn on it.

        Args:
            image: (H, W, 3) BGR or (H, W) gray; uint8 (uint16 is scaled by 1/257, floats
                are clipped to [0, 255]).
            tracks: rows of the track table for this frame (mappings with ``track_id``,
                ``x``, ``y``, ``w``, ``h`` [px, top-left corner and size], optional
                ``u_wl``, ``v_wl`` [px], ``range_m`` [m], ``speed_mps`` [m/s], ``mmsi``;
                empty strings/None are missing). A row without a finite box is skipped.
            horizon: the frame's horizon (drawn when ``found``), or None.
            time: video time [s] for the corner stamp; frame: frame index for it.

        Returns:
            (H, W, 3) uint8 BGR.
        """
        img = _to_bgr8(image).copy()
        h_img, w_img = img.shape[:2]
        t, fs, ft = self._sizes(h_img)
        if horizon is not None and bool(getattr(horizon, "found", False)):
            pts = [_num(getattr(horizon, k, None)) for k in ("x0", "y0", "x1", "y1")]
            if all(math.isfinite(p) for p in pts):
                p0, p1 = (round(pts[0]), round(pts[1])), (round(pts[2]), round(pts[3]))
                ok, p0, p1 = cv2.clipLine((0, 0, w_img, h_img), p0, p1)
                if ok:
                    cv2.line(img, p0, p1, _HORIZON_BGR, t, cv2.LINE_AA)
        for row in tracks:
            box = [_num(row.get(k)) for k in ("x", "y", "w", "h")]
            if not all(math.isfinite(v) for v in box):
                continue
            x, y, w, h = box
            tid = _num(row.get("track_id"))
            colour = track_colour(int(tid) if math.isfinite(tid) else 0)
            x0, y0 = round(x), round(y)
            x1, y1 = round(x + w), round(y + h)
            cv2.rectangle(img, (x0, y0), (x1, y1), colour, t, cv2.LINE_AA)
            u, v = _num(row.get("u_wl")), _num(row.get("v_wl"))
            if math.isfinite(u) and math.isfinite(v):
                cv2.circle(img, (round(u), round(v)), t + 2, colour, max(1, t // 2), cv2.LINE_AA)
            self._text(img, self.label(row), (x0, y0, x1, y1), colour, t, fs, ft)
        if self.show_time and time is not None and math.isfinite(time):
            stamp = f"t = {time:.2f} s" + (f"  frame {frame}" if frame is not None else "")
            self._text(img, [stamp], None, (255, 255, 255), t, fs, ft)
        return img

    @staticmethod
    def _text(
        img: NDArray[np.uint8],
        lines: list[str],
        box: tuple[int, int, int, int] | None,
        colour: tuple[int, int, int],
        t: int,
        fs: float,
        ft: int,
    ) -> None:
        h_img, w_img = img.shape[:2]
        sizes = [cv2.getTextSize(s, _FONT, fs, ft) for s in lines]
        line_h = max(sz[0][1] + sz[1] for sz in sizes) + 2 * t
        block_w = max(sz[0][0] for sz in sizes) + 4 * t
        block_h = line_h * len(lines) + 2 * t
        if box is None:  # corner stamp: white on a darkened backing
            left, top = 2 * t, 2 * t
            ink = (255, 255, 255)
        else:  # below the box, on the sea (above it the masts would be hidden) …
            left = box[0]
            top = box[3] + t + 2
            if top + block_h > h_img:
                top = box[1] - t - 2 - block_h  # … or above it at the bottom of the image
            luma = 0.114 * colour[0] + 0.587 * colour[1] + 0.299 * colour[2]
            ink = (0, 0, 0) if luma > 140 else (255, 255, 255)
        left = int(min(max(left, 0), max(w_img - block_w, 0)))
        top = int(min(max(top, 0), max(h_img - block_h, 0)))
        right, bottom = min(left + block_w, w_img - 1), min(top + block_h, h_img - 1)
        roi = img[top : bottom + 1, left : right + 1]
        if box is None:
            roi[...] = (roi.astype(np.uint16) * 3 // 10).astype(np.uint8)
        else:
            roi[...] = colour  # the track's colour as the backing: readable on any scene
        for k, s in enumerate(lines):
            base = top + t + (k + 1) * line_h - sizes[k][1] - t
            cv2.putText(img, s, (left + 2 * t, base), _FONT, fs, ink, ft, cv2.LINE_AA)


class AnnotatedVideo:
    """``annotated.mp4``: frames annotated by an :class:`Annotator`, encoded one by one.

    Wraps :class:`seawatch.io.video.VideoWriter` (H.264, ``yuv420p``): frame ``k`` is shown
    at ``k / fps`` [s]. The MP4 is fragmented (see the module docstring), so a crash keeps
    everything but the last ≈ :data:`FRAGMENT_S` s plus the encoder's look-ahead.

    Args:
        path: output file (``.mp4``; its folder must exist).
        fps: frame rate [1/s], > 0.
        size: (width, height) of every frame [px]; a frame of another size is refused.
        annotator: the :class:`Annotator` to draw with (default: ``Annotator()``).
        crf: H.264 constant rate factor (0 lossless … 51 worst).
        preset: libx264 speed preset.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        fps: float,
        size: tuple[int, int],
        *,
        annotator: Annotator | None = None,
        crf: int = 23,
        preset: str = "veryfast",
    ) -> None:
        try:
            w, h = (int(v) for v in size)
            valid = len(size) == 2 and all(v == int(v) for v in size)
        except (TypeError, ValueError):
            valid = False
        if not valid or w < 2 or h < 2:
            raise ValueError(f"size: expected (width, height) integers >= 2 [px], got {size!r}")
        self.size = (w, h)
        self.annotator = annotator if annotator is not None else Annotator()
        self._writer = VideoWriter(
            path,
            fps,
            crf=crf,
            preset=preset,
            container_options=FRAGMENTED_MP4 if _is_mp4(path) else None,
        )
        self.path = self._writer.path
        self.fps = self._writer.fps

    @property
    def frames_written(self) -> int:
        """Frames encoded so far [-]."""
        return self._writer.frames_written

    @property
    def last_pts(self) -> int:
        """The last frame's presentation time [frame periods]; -1 before the first."""
        return self._writer.last_pts

    def write(
        self,
        image: NDArray[Any],
        tracks: Iterable[Mapping[str, Any]] = (),
        horizon: HorizonLike | None = None,
        *,
        time: float | None = None,
        frame: int | None = None,
        fit: bool = False,
        pts: int | None = None,
    ) -> None:
        """Annotate one frame (:meth:`Annotator.draw`) and append it to the video.

        ``pts``: its presentation time in frame periods from the video's start
        (:meth:`seawatch.io.video.VideoWriter.write`; default the next frame), so that
        frames dropped or lost before it leave a gap in time, not a jump in the motion.
        ``fit``: a frame of another size than the video's (a stream whose resolution
        changed) is drawn at its own size and then scaled to the video's; without it such
        a frame is a ValueError."""
        shape = np.shape(image)
        other = len(shape) < 2 or (shape[1], shape[0]) != self.size
        if other and not (fit and len(shape) >= 2 and min(shape[:2]) >= 1):
            raise ValueError(
                f"image: frame {self.frames_written} is "
                f"{shape[1] if len(shape) > 1 else '?'}x{shape[0] if shape else '?'}, "
                f"the video is {self.size[0]}x{self.size[1]}"
            )
        drawn = self.annotator.draw(image, tracks, horizon, time=time, frame=frame)
        if other:
            drawn = cv2.resize(drawn, self.size, interpolation=cv2.INTER_AREA)
        self._writer.write(drawn, pts)

    def close(self) -> None:
        """Finish the file (idempotent; no frames → no file, with a warning)."""
        self._writer.close()

    def __enter__(self) -> AnnotatedVideo:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
