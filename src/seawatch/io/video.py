"""Frames in, frames out: one iterator over video files, live streams, cameras and image folders.

The edge of the image stage (issue 6, "Video in"). :class:`VideoReader` yields
:class:`Frame` objects — ``index``, ``time`` [s], ``image`` and, for image folders, the
``file`` — from

* **video files** (mp4, avi, mkv, mov, ts, …) decoded with PyAV (FFmpeg);
* **live sources**: a URL (``rtsp://``, ``http(s)://``, ``udp://``, ``rtmp://``, …) or a
  camera device (an index such as ``0`` or ``"0"``, or a path such as ``/dev/video0``),
  opened with PyAV, or with OpenCV's FFmpeg/V4L backend where PyAV cannot open it;
* **image folders**: every image file in the folder, in natural sort order of the file
  names (``frame2.png`` before ``frame10.png``; zero-padded names sort as plain text),
  with ``time = k / fps`` for the k-th image; and a single image file (one frame).

Images
------
``image`` is a numpy array in OpenCV's conventions: (H, W, 3) **BGR** for colour, (H, W)
for grayscale; ``uint8`` for 8-bit sources, ``uint16`` for 16-bit ones (e.g. 16-bit
thermal PNG/TIFF, ``gray16le`` video), ``float32`` for floating-point TIFFs (values as
stored; NaN or inf pixels — a radiometric camera's dead ones — filled with the image's
median, see :attr:`VideoReader.filled`). An alpha channel is dropped (RGBA → BGR). A
video with a display rotation (a phone's portrait video) is turned upright, as players
do. With ``gray=True`` every frame is converted to one channel (luma, ITU-R BT.601),
which for video is the decoder's Y plane and the cheapest way to feed a grayscale
pipeline.

Time
----
``time`` [s] comes from the presentation timestamps (PTS) of the decoded frames, counted
from the start of the stream (the container's stream start time, or the first frame's PTS
for a live source), so the first frame of a file is at 0 s. A frame without a PTS gets
the previous time plus one nominal frame interval. ``index`` is the frame's ordinal in
the source, before decimation: 0, 1, 2, … for a video (frames lost to corruption keep
their indices, so that indices match the frame numbers of the file), the position among
the sorted image files for a folder.

Options
-------
``start`` / ``end`` [s] select frames with ``start <= time < end``; ``step`` keeps every
k-th of those (the first one kept is the first at or after ``start``); ``max_frames`` stops
after that many frames have been yielded.

Failure modes (issue 6, "Bad input")
------------------------------------
* a missing file or folder, a file FFmpeg cannot open, a file without a video stream,
  a source with no frames at all, an empty folder (no image files), a camera or URL that
  cannot be opened → :class:`VideoError` (a ``ValueError``) naming the source;
* a corrupt frame in the middle of a video is skipped with a :class:`VideoWarning` and
  counted in :attr:`VideoReader.skipped`: the number of frames lost is the larger of the
  packets that failed to decode and the frames missing from the timestamp sequence
  (a jump of more than 1.5 nominal frame intervals; constant-frame-rate streams);
* a file in an image folder that is not an image (by its extension) is skipped with a
  warning; an image file that cannot be decoded is skipped with a warning and counted;
* a change of frame size mid-stream gives a warning, and the frames are delivered as
  they are (downstream decides);
* timestamps that jump back (concatenated recordings, a camera restart, a wrap-around)
  give a warning and the time continues from the previous frame, so that ``time``
  always increases; a single frame a few intervals late (decoder reordering broken by
  corruption) is dropped; a forward jump of more than 10 s is reported, not counted as
  lost frames;
* a stream that drops (a network error, a truncated file) ends the iteration with a
  warning; the frames before it have been yielded. A live source (URL or camera) is
  opened again instead with ``reconnect=N``: up to N attempts in a row, waiting
  ``reconnect_wait`` seconds before the first and twice as long before each next one
  (at most 30 s); each loss and each reconnection is reported. Frames after a
  reconnection continue the time on the wall clock (``time`` = the last frame's time
  plus the seconds the source was away) and the indices by the frames the source would
  have sent meanwhile, so a consumer sees the gap (:attr:`VideoReader.reconnects`,
  :attr:`VideoReader.lost_seconds`).

:class:`VideoWriter` encodes BGR/grayscale frames with PyAV (H.264 ``libx264``,
``yuv420p``, with an MPEG-4 Part 2 fallback where libx264 is missing; FFV1 for 16-bit
grayscale), for the renderer (``seawatch synth``) and annotated outputs.
"""

from __future__ import annotations

import math
import os
import re
import time as _time
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any, Literal

import av
import cv2
import numpy as np
from numpy.typing import NDArray

from seawatch._validation import integer

__all__ = [
    "IMAGE_EXTENSIONS",
    "Frame",
    "VideoError",
    "VideoReader",
    "VideoWarning",
    "VideoWriter",
    "read_image",
]

IMAGE_EXTENSIONS = frozenset(
    {".png", ".jpg", ".jpeg", ".jpe", ".tif", ".tiff", ".bmp", ".dib", ".pgm", ".ppm", ".pnm",
     ".pbm", ".webp", ".jp2", ".sr", ".ras", ".hdr", ".pic"}
)  # fmt: skip
"""File name extensions (lower case) read as images; anything else in a folder is skipped."""

SourceKind = Literal["file", "folder", "image", "url", "device"]

REALTIME_SCHEMES = (
    "rtsp://",
    "rtsps://",
    "rtmp://",
    "rtmps://",
    "rtp://",
    "udp://",
    "srt://",
    "tcp://",
)
"""URL schemes of sources that send frames in real time (:attr:`VideoReader.realtime`)."""

_URL = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*://")
_MAX_WARNINGS = 10  # individual warnings per kind before they are summarised at the end
_MAX_GAP_S = 10.0  # [s] longer forward timestamp jumps are discontinuities, not lost frames
RATE_TAG = "seawatch_frame_rate"
"""Container tag in which :class:`VideoWriter` stores its frame rate (a fraction, e.g.
``"25"`` or ``"30000/1001"``), read back by :class:`VideoReader` as the file's rate."""
RECONNECT_WAIT_MAX = 30.0
"""Longest wait between two attempts to reopen a dropped live source [s]."""


class VideoError(ValueError):
    """A video source cannot be read: missing, undecodable, empty or without frames.

    The message names the source. A ``ValueError``, so that the command line maps it to
    exit code 2 (bad input).
    """


class VideoWarning(UserWarning):
    """Something went wrong in a stream that is not fatal (corrupt frame, size change, drop)."""


@dataclass(frozen=True, eq=False)
class Frame:
    """One decoded frame.

    Attributes:
        index: ordinal of the frame in its source, before decimation (0-based) [-].
        time: presentation time from the start of the stream [s].
        image: pixels, (H, W, 3) BGR or (H, W) grayscale; uint8, uint16 (16-bit sources)
            or float32 (floating-point TIFF).
        file: the image file, for a folder or image source; None for video.
    """

    index: int
    time: float
    image: NDArray[Any]
    file: Path | None = None

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) of the image [px]."""
        return int(self.image.shape[1]), int(self.image.shape[0])


# --------------------------------------------------------------------------------------
# images
# --------------------------------------------------------------------------------------


def _natural_key(name: str) -> tuple[object, ...]:
    parts = re.split(r"(\d+)", name)
    return tuple((0, int(p), p) if p.isdigit() else (1, p.lower(), p) for p in parts if p)


def _normalise_image(img: NDArray[Any], gray: bool) -> NDArray[Any]:
    """OpenCV's IMREAD_UNCHANGED result → (H, W) or (H, W, 3) BGR, alpha dropped."""
    if img.ndim == 3 and img.shape[2] == 1:
        img = img[:, :, 0]
    elif img.ndim == 3 and img.shape[2] == 4:
        img = cv2.cvtColor(img, cv2.COLOR_BGRA2BGR)
    elif img.ndim == 3 and img.shape[2] == 2:  # gray + alpha
        img = np.ascontiguousarray(img[:, :, 0])
    if img.dtype not in (np.uint8, np.uint16, np.float32):
        if np.issubdtype(img.dtype, np.floating):
            img = img.astype(np.float32)
        elif img.dtype == np.int8:
            img = img.view(np.uint8) ^ np.uint8(0x80)
        else:  # int16/int32 (rare TIFFs): clip into 16 bits
            img = np.clip(img, 0, 65535).astype(np.uint16)
    if gray and img.ndim == 3:
        img = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
    return np.ascontiguousarray(img)


def read_image(path: str | os.PathLike[str], *, gray: bool = False) -> NDArray[Any]:
    """Read one image file in the reader's conventions (BGR/gray; uint8, uint16 or float32).

    Reads the bytes and decodes with ``cv2.imdecode(..., IMREAD_UNCHANGED)`` (so any file
    name works and 16-bit PNG/TIFF keep their 16 bits); RGBA loses its alpha. Raises
    :class:`VideoError` naming the file if it is missing or not a decodable image.
    """
    p = Path(path)
    try:
        data = np.fromfile(p, dtype=np.uint8)
    except OSError as exc:
        raise VideoError(f"{p}: cannot read image file ({exc.strerror or exc})") from None
    img = cv2.imdecode(data, cv2.IMREAD_UNCHANGED) if data.size else None
    if img is None or img.size == 0:
        raise VideoError(f"{p}: not a decodable image")
    return _normalise_image(img, gray)


# --------------------------------------------------------------------------------------
# reader
# --------------------------------------------------------------------------------------


def _realtime(kind: SourceKind, source: object) -> bool:
    """Whether a source of this kind sends its frames in real time (a camera device, a
    URL of :data:`REALTIME_SCHEMES`)."""
    if kind == "device":
        return True
    return kind == "url" and str(source).lower().startswith(REALTIME_SCHEMES)


def _classify(source: object) -> tuple[SourceKind, str | int | Path]:
    if isinstance(source, bool):
        raise VideoError(f"source: expected a path, URL or camera index, got {source!r}")
    if isinstance(source, int):
        if source < 0:
            raise VideoError(f"camera {source}: a device index must be >= 0")
        return "device", source
    if isinstance(source, os.PathLike):
        source = os.fspath(source)
    if not isinstance(source, str):
        raise VideoError(f"source: expected a path, URL or camera index, got {source!r}")
    if not source.strip():
        raise VideoError("source: empty source name")
    if _URL.match(source):
        if source.lower().startswith("file://"):
            return _classify(source[7:])
        return "url", source
    path = Path(source)
    if source.isdigit() and not path.exists():
        return "device", int(source)
    if source.startswith("/dev/") and not path.is_file():
        return "device", source
    if path.is_dir():
        return "folder", path
    if path.is_file():
        return ("image" if path.suffix.lower() in IMAGE_EXTENSIONS else "file"), path
    if not path.exists():
        raise VideoError(f"{source}: no such file or folder")
    raise VideoError(f"{source}: not a regular file or folder")


class VideoReader:
    """Iterate over the frames of a video file, live stream, camera or image folder.

    See the module docstring for the sources, conventions and failure modes. Opening
    happens in the constructor, so a missing or undecodable source fails at once with a
    :class:`VideoError`; iterating decodes. Every iteration starts from the beginning
    (a live source is reconnected). Use as a context manager or call :meth:`close` to
    release an open container early.

    Args:
        source: a path (video file, image file or image folder), a URL, or a camera
            device (index ``0``/``"0"`` or path ``/dev/video0``).
        step: keep every ``step``-th frame (decimation), ``>= 1``.
        start: first time to deliver [s] (inclusive), ``>= 0``.
        end: time at which to stop [s] (exclusive); None = to the end.
        max_frames: stop after this many frames were yielded; None = no limit.
        fps: frame rate for image folders [1/s], ``time = k / fps`` (default 1, i.e.
            time = file position); for video it overrides nothing (PTS are used).
        gray: deliver single-channel (luma) images.
        timeout: seconds to wait for a live source to open or deliver data.
        backend: ``"auto"`` (PyAV, then OpenCV for live sources), ``"pyav"`` or
            ``"opencv"`` (live sources and files only).
        reconnect: attempts to open a live source again after it drops, in a row
            (0: the iteration ends at the drop; files and folders never reconnect).
        reconnect_wait: seconds before the first attempt; doubled before each further
            attempt of the same loss, at most :data:`RECONNECT_WAIT_MAX`.

    Attributes:
        skipped: frames lost to corruption (video) or undecodable image files (folder)
            during the last iteration.
        filled: floating-point images (folder) whose NaN or inf pixels — a radiometric
            thermal camera's dead or invalid pixels — were filled with the median of
            the image's finite pixels during the last iteration (the first is reported
            with a warning, the others only counted; an image without a finite pixel is
            skipped and counted in ``skipped``).
        kind: ``"file"``, ``"folder"``, ``"image"``, ``"url"`` or ``"device"``.
        reconnects: times a dropped live source was opened again (last iteration).
        lost_seconds: seconds without frames across those reconnections [s].
    """

    def __init__(
        self,
        source: str | os.PathLike[str] | int,
        *,
        step: int = 1,
        start: float = 0.0,
        end: float | None = None,
        max_frames: int | None = None,
        fps: float | None = None,
        gray: bool = False,
        timeout: float = 10.0,
        backend: Literal["auto", "pyav", "opencv"] = "auto",
        reconnect: int = 0,
        reconnect_wait: float = 1.0,
    ) -> None:
        step = integer("step", step, 1)
        reconnect = integer("reconnect", reconnect, 0)
        if not (isinstance(reconnect_wait, int | float) and 0 <= reconnect_wait < math.inf):
            raise ValueError(f"reconnect_wait: expected seconds >= 0, got {reconnect_wait!r}")
        if not (isinstance(start, int | float) and math.isfinite(start) and start >= 0):
            raise ValueError(f"start: expected a finite time >= 0 s, got {start!r}")
        if end is not None and not (isinstance(end, int | float) and end > start):
            raise ValueError(f"end: expected a time > start ({start} s), got {end!r}")
        if max_frames is not None and (
            isinstance(max_frames, bool) or not isinstance(max_frames, int) or max_frames < 1
        ):
            raise ValueError(f"max_frames: expected an integer >= 1, got {max_frames!r}")
        if fps is not None and not (
            isinstance(fps, int | float) and math.isfinite(fps) and fps > 0
        ):
            raise ValueError(f"fps: expected a frame rate > 0 per second, got {fps!r}")
        if not (isinstance(timeout, int | float) and timeout > 0):
            raise ValueError(f"timeout: expected seconds > 0, got {timeout!r}")
        if backend not in ("auto", "pyav", "opencv"):
            raise ValueError(f"backend: expected 'auto', 'pyav' or 'opencv', got {backend!r}")
        self.step = int(step)
        self.start = float(start)
        self.end = None if end is None else float(end)
        self.max_frames = max_frames
        self.gray = bool(gray)
        self.timeout = float(timeout)
        self.backend = backend
        self.reconnect = reconnect
        self.reconnect_wait = float(reconnect_wait)
        self.skipped = 0
        self.filled = 0
        self.reconnects = 0
        self.lost_seconds = 0.0
        self.kind, self._target = _classify(source)
        self.source = str(source)
        self._folder_fps = 1.0 if fps is None else float(fps)
        self._files: list[Path] = []
        self._handle: Any = None  # an opened container/capture, for the first iteration
        self._size: tuple[int, int] | None = None
        self._rotation_noted = False
        self._rate: float | None = None
        self._count: int | None = None
        if self.kind in ("folder", "image"):
            self._open_images()
        else:
            self._handle = self._open_stream()

    # -------------------------------------------------------------- public properties
    @property
    def live(self) -> bool:
        """True for URLs and camera devices (no known length, may drop)."""
        return self.kind in ("url", "device")

    @property
    def realtime(self) -> bool:
        """True for a source that sends its frames at their own rate whether or not they
        are read (a camera device; an ``rtsp``, ``rtmp``, ``rtp``, ``udp``, ``srt`` or
        ``tcp`` stream): a reader slower than it must drop frames to keep up. An HTTP
        URL may be a file served as fast as it is read: not counted."""
        return _realtime(self.kind, self.source)

    @property
    def size(self) -> tuple[int, int] | None:
        """(width, height) [px] announced by the source (first image of a folder), or None;
        upright once the first frame has shown a display rotation of 90° or 270°."""
        return self._size

    @property
    def fps(self) -> float | None:
        """Nominal frame rate [1/s]: the stream's average rate, or ``fps`` for a folder."""
        return self._rate

    @property
    def frame_count(self) -> int | None:
        """Frames (image files) in the source, if the container says; None if unknown.

        Counts the whole source, before ``start``/``end``/``step``/``max_frames``.
        """
        return self._count

    @property
    def expected_frames(self) -> int | None:
        """Frames an iteration will deliver, after ``start``/``end``/``step``/
        ``max_frames`` (for a progress bar; the window from the nominal rate); None when
        the source's length is unknown (a live source)."""
        if self._count is None:
            return None
        first, last = 0, self._count
        if self._rate:
            first = min(last, math.ceil(self.start * self._rate - 1e-9))
            if self.end is not None:
                last = min(last, math.ceil(self.end * self._rate - 1e-9))
        total = math.ceil(max(0, last - first) / self.step)
        return total if self.max_frames is None else min(total, self.max_frames)

    def __repr__(self) -> str:
        return f"VideoReader({self.source!r}, kind={self.kind!r}, size={self._size})"

    def __enter__(self) -> VideoReader:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Release an open container or capture (iteration reopens as needed)."""
        handle, self._handle = self._handle, None
        if handle is not None:
            try:
                handle.close() if hasattr(handle, "close") else handle.release()
            except Exception:  # closing a broken stream must not raise
                pass

    def __iter__(self) -> Iterator[Frame]:
        self.skipped = 0
        self.filled = 0
        self.reconnects = 0
        self.lost_seconds = 0.0
        if self.kind in ("folder", "image"):
            return self._iter_images()
        handle, self._handle = self._handle, None
        if handle is None:
            handle = self._open_stream()
        if self.live and self.reconnect:
            return self._iter_reconnecting(handle)
        return self._iter_handle(handle, _Cursor())

    def _iter_handle(self, handle: Any, cursor: _Cursor) -> Iterator[Frame]:
        if isinstance(handle, cv2.VideoCapture):
            return self._iter_opencv(handle, cursor)
        return self._iter_pyav(handle, cursor)

    def _iter_reconnecting(self, handle: Any) -> Iterator[Frame]:
        """Frames of a live source, opened again after each drop (``reconnect``): at most
        ``reconnect`` attempts in a row, counted until a connection delivers a frame."""
        cursor = _Cursor()
        attempt = 0
        while True:
            before = cursor.delivered
            if handle is not None:
                try:
                    yield from self._iter_handle(handle, cursor)
                except VideoError:  # a connection without a frame: a failed attempt
                    if cursor.index < 0:
                        raise  # the first one: the source gives no frames at all
                if cursor.stopped:  # end time or max_frames reached
                    return
                if cursor.delivered > before:
                    if attempt:
                        self._note_back(cursor)
                    attempt = 0
            if attempt == self.reconnect:
                warnings.warn(
                    f"{self.source}: not back after {attempt} attempt(s); "
                    f"{cursor.delivered} frames kept",
                    VideoWarning,
                    stacklevel=2,
                )
                return
            attempt += 1
            wait = min(self.reconnect_wait * 2.0 ** (attempt - 1), RECONNECT_WAIT_MAX)
            lost = f"lost after frame {cursor.index}; " if attempt == 1 else ""
            warnings.warn(
                f"{self.source}: {lost}reconnecting in {wait:g} s "
                f"(attempt {attempt} of {self.reconnect})",
                VideoWarning,
                stacklevel=2,
            )
            _time.sleep(wait)
            try:
                handle = self._open_stream()
            except VideoError as exc:
                warnings.warn(str(exc), VideoWarning, stacklevel=2)
                handle = None
                continue
            cursor.resume(_time.monotonic() - cursor.wall, self._rate)

    def _note_back(self, cursor: _Cursor) -> None:
        """Report a reconnection whose connection has delivered frames again."""
        self.reconnects += 1
        self.lost_seconds += cursor.away
        warnings.warn(
            f"{self.source}: reconnected after {cursor.away:.1f} s without frames; "
            f"frames go on at index {cursor.resumed_at}",
            VideoWarning,
            stacklevel=3,
        )

    # -------------------------------------------------------------- selection
    def _select(self, t: float, kept: int) -> tuple[bool, bool]:
        """(deliver this frame?, stop after it?) for a frame at time t, given frames in window."""
        if self.end is not None and t >= self.end:
            return False, True
        if t < self.start:
            return False, False
        return kept % self.step == 0, False

    # -------------------------------------------------------------- image folders
    def _open_images(self) -> None:
        if self.kind == "image":
            self._files = [Path(self._target)]
        else:
            folder = Path(self._target)
            try:
                entries = sorted(
                    (e for e in folder.iterdir() if not e.name.startswith(".")),
                    key=lambda e: _natural_key(e.name),
                )
            except OSError as exc:
                raise VideoError(f"{folder}: cannot list folder ({exc.strerror or exc})") from None
            files = [e for e in entries if e.is_file()]
            self._files = [e for e in files if e.suffix.lower() in IMAGE_EXTENSIONS]
            others = [e.name for e in files if e.suffix.lower() not in IMAGE_EXTENSIONS]
            if not self._files:
                extra = f" (found only: {', '.join(others[:5])})" if others else ""
                raise VideoError(f"{folder}: no image files in folder{extra}")
            for name in others:
                warnings.warn(
                    f"{folder}: skipping {name} (not an image file)", VideoWarning, stacklevel=3
                )
        self._count = len(self._files)
        self._rate = self._folder_fps
        try:  # size of the first readable image, for information only
            first = read_image(self._files[0], gray=self.gray)
            self._size = (first.shape[1], first.shape[0])
        except VideoError:
            self._size = None

    def _iter_images(self) -> Iterator[Frame]:
        kept = delivered = 0
        shape: tuple[int, ...] | None = None
        decoded = 0
        for k, path in enumerate(self._files):
            t = k / self._folder_fps
            take, stop = self._select(t, kept)
            if stop:
                break
            if t < self.start:
                continue
            kept += 1
            if not take:
                continue
            try:
                img = read_image(path, gray=self.gray)
                if img.dtype == np.float32:
                    img = self._fill_invalid(img, path)
            except VideoError as exc:
                self.skipped += 1
                warnings.warn(f"{exc}; skipped", VideoWarning, stacklevel=2)
                continue
            decoded += 1
            if shape is not None and img.shape != shape:
                warnings.warn(
                    f"{path}: image size changed from {_fmt_shape(shape)} to "
                    f"{_fmt_shape(img.shape)}",
                    VideoWarning,
                    stacklevel=2,
                )
            shape = img.shape
            yield Frame(index=k, time=t, image=img, file=path)
            delivered += 1
            if self.max_frames is not None and delivered >= self.max_frames:
                return
        if decoded == 0 and kept > 0 and self.skipped > 0:
            raise VideoError(f"{self.source}: none of the {self.skipped} image files could be read")

    def _fill_invalid(self, img: NDArray[Any], path: Path) -> NDArray[Any]:
        """A floating-point image with its NaN/inf pixels filled with the median of its
        finite ones (counted in :attr:`filled`, the first one reported); VideoError when
        no pixel is finite."""
        bad = ~np.isfinite(img)
        if not bad.any():
            return img
        if bad.all():
            raise VideoError(f"{path}: no finite pixel (all NaN or inf)")
        out = img.copy()
        out[bad] = np.median(img[~bad])
        if self.filled == 0:
            warnings.warn(
                f"{path}: {int(bad.sum())} NaN or inf pixel(s) (dead or invalid) filled with "
                "the image's median; later images with such pixels are only counted",
                VideoWarning,
                stacklevel=3,
            )
        self.filled += 1
        return out

    # -------------------------------------------------------------- PyAV / OpenCV opening
    def _open_stream(self) -> Any:
        errors: list[str] = []
        if self.backend in ("auto", "pyav"):
            try:
                return self._open_pyav()
            except VideoError as exc:
                if self.backend == "pyav" or self.kind == "file":
                    raise
                errors.append(f"PyAV: {exc}")
        try:
            return self._open_opencv()
        except VideoError as exc:
            errors.append(f"OpenCV: {exc}")
        raise VideoError(f"{self._describe()}: cannot open ({'; '.join(errors)})")

    def _describe(self) -> str:
        if self.kind == "device":
            return f"camera {self._target}"
        return str(self._target)

    def _open_pyav(self) -> Any:
        target = self._target
        fmt: str | None = None
        options: dict[str, str] = {}
        if self.kind == "device":
            if os.name == "posix" and Path("/dev").is_dir() and not _is_macos():
                fmt = "v4l2"
                target = f"/dev/video{target}" if isinstance(target, int) else target
            elif _is_macos():
                fmt, target = "avfoundation", str(target)
            else:
                raise VideoError(f"camera {target}: no PyAV device input on this system")
        elif self.kind == "url" and str(target).lower().startswith(("rtsp://", "rtsps://")):
            options["rtsp_transport"] = "tcp"
        try:
            container = av.open(
                str(target),
                format=fmt,
                options=options,
                timeout=(self.timeout, self.timeout) if self.live else None,
            )
        except av.error.FileNotFoundError:
            raise VideoError(f"{self._describe()}: no such file or device") from None
        except (av.error.FFmpegError, OSError) as exc:
            raise VideoError(f"{self._describe()}: cannot open as video ({_why(exc)})") from None
        if not container.streams.video:
            container.close()
            raise VideoError(f"{self._describe()}: contains no video stream")
        stream = container.streams.video[0]
        stream.thread_type = "AUTO"
        ctx = stream.codec_context
        if ctx.width and ctx.height:
            self._size = (int(ctx.width), int(ctx.height))
        self._rate = _tagged_rate(container.metadata) or _nominal_rate(
            stream.average_rate, stream.guessed_rate
        )
        self._count = int(stream.frames) if stream.frames else None
        return container

    def _open_opencv(self) -> cv2.VideoCapture:
        target = self._target
        if self.kind == "device":
            cap = cv2.VideoCapture(target if isinstance(target, int) else str(target))
        else:
            cap = cv2.VideoCapture(str(target), cv2.CAP_FFMPEG)
        if not cap.isOpened():
            cap.release()
            raise VideoError(f"{self._describe()}: cannot open")
        w = int(cap.get(cv2.CAP_PROP_FRAME_WIDTH))
        h = int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT))
        self._size = (w, h) if w and h else None
        rate = cap.get(cv2.CAP_PROP_FPS)
        self._rate = float(rate) if rate and math.isfinite(rate) and 0 < rate < 1000 else None
        n = int(cap.get(cv2.CAP_PROP_FRAME_COUNT))
        self._count = n if n > 0 and not self.live else None
        return cap

    # -------------------------------------------------------------- PyAV iteration
    def _convert(self, frame: av.VideoFrame) -> NDArray[Any]:
        name = frame.format.name
        if name.startswith(("gray", "ya")) or name in ("monob", "monow"):
            deep = any(d in name for d in ("9", "10", "12", "14", "16", "32"))
            img = frame.to_ndarray(format="gray16le" if deep else "gray")
        elif self.gray:
            img = frame.to_ndarray(format="gray")
        else:
            img = frame.to_ndarray(format="bgr24")
        return self._upright(img, getattr(frame, "rotation", 0))

    def _upright(self, img: NDArray[Any], rotation: float) -> NDArray[Any]:
        """The frame as it is meant to be shown: a phone's portrait video is stored as
        landscape pixels with a display matrix (``rotation``, degrees counter-clockwise,
        FFmpeg's convention) that players apply and decoders do not; turned here by
        that multiple of 90° (reported once). Other angles are left alone (warned)."""
        if not rotation:
            return img
        quarter = round(rotation / 90.0)
        if abs(rotation - 90.0 * quarter) > 1e-6:
            if not self._rotation_noted:
                self._rotation_noted = True
                warnings.warn(
                    f"{self._describe()}: display rotation of {rotation:g} degrees is not a "
                    "multiple of 90: frames left as stored",
                    VideoWarning,
                    stacklevel=4,
                )
            return img
        if quarter % 4 == 0:
            return img
        img = np.ascontiguousarray(np.rot90(img, k=quarter % 4))
        if not self._rotation_noted:
            self._rotation_noted = True
            self._size = (int(img.shape[1]), int(img.shape[0]))
            turn = {1: "90 degrees counter-clockwise", 2: "180 degrees", 3: "90 degrees clockwise"}
            warnings.warn(
                f"{self._describe()}: frames turned upright ({turn[quarter % 4]}), as the "
                "file's display matrix asks (e.g. a phone's portrait video)",
                VideoWarning,
                stacklevel=4,
            )
        return img

    def _decoded(self, container: Any, log: _Log, state: dict[str, int]) -> Iterator[Any]:
        """Decoded PyAV frames; corrupt packets skipped and counted, a failing demux ends."""
        stream = container.streams.video[0]
        packets = container.demux(stream)
        while True:
            try:
                packet = next(packets)
            except StopIteration:
                return
            except (av.error.FFmpegError, OSError) as exc:
                where = f"after frame {state['index']}"
                log.warn("drop", f"stream ended {where} ({_why(exc)}); frames kept")
                break
            try:
                frames = packet.decode()
            except (av.error.FFmpegError, OSError) as exc:
                state["decode_errors"] += 1
                where = f"after frame {state['index']}"
                log.warn("corrupt", f"corrupt data {where} skipped ({_why(exc)})")
                continue
            yield from frames
        try:  # the stream dropped: flush what the decoder still holds
            yield from stream.decode(None)
        except (av.error.FFmpegError, OSError):
            return

    def _iter_pyav(self, container: Any, cursor: _Cursor) -> Iterator[Frame]:
        log = _Log(self.source)
        stream = container.streams.video[0]
        tb = stream.time_base
        origin = stream.start_time if (stream.start_time is not None and not self.live) else None
        interval = 1.0 / self._rate if self._rate else None
        state = {"index": cursor.index, "decode_errors": 0}  # index of the last frame seen
        gap_missing = 0
        shift = cursor.offset  # [s] added to the PTS times (a discontinuity, a reconnection)
        late_run = 0  # consecutive frames older than the last one
        last_t: float | None = None
        kept, delivered, decoded = cursor.kept, cursor.delivered, 0
        shape: tuple[int, ...] | None = cursor.shape
        ended_by_user = False
        try:
            for vf in self._decoded(container, log, state):
                decoded += 1
                if vf.pts is not None and tb is not None:
                    if origin is None:
                        origin = vf.pts
                    t = float((vf.pts - origin) * tb) + shift
                else:
                    t = (last_t + (interval or 0.0)) if last_t is not None else 0.0
                step_t = interval or 0.04
                if last_t is not None and t <= last_t:
                    late_run += 1
                    restart = t - shift < 3.0 * step_t or last_t - t > 60.0 or late_run > 3
                    if not restart:
                        # a late frame (decoder reordering broken by corruption): already
                        # counted in the gap it falls into; dropped to keep time monotonic
                        log.warn("corrupt", f"out-of-order frame at {t:.3f} s dropped")
                        continue
                    # the timestamps restart (concatenated streams, a reconnect, a wrap):
                    # time goes on from the last frame
                    log.warn(
                        "discontinuity",
                        f"timestamps jump back from {last_t:.3f} s to {t:.3f} s; "
                        "times continue from the previous frame",
                    )
                    shift += last_t + step_t - t
                    t = last_t + step_t
                late_run = 0
                # timestamps that jump by more than 1.5 frame intervals: frames were lost
                missing = 0
                if interval and last_t is not None and t - last_t > 1.5 * interval:
                    if t - last_t <= _MAX_GAP_S:
                        missing = round((t - last_t) / interval) - 1
                        gap_missing += missing
                        log.warn(
                            "corrupt",
                            f"{missing} frame(s) missing between {last_t:.3f} s and "
                            f"{t:.3f} s (corrupt or dropped data)",
                        )
                    else:
                        log.warn(
                            "discontinuity",
                            f"timestamps jump from {last_t:.3f} s to {t:.3f} s",
                        )
                self.skipped = cursor.skipped + max(state["decode_errors"], gap_missing)
                state["index"] += 1 + missing
                last_t = t
                take, stop = self._select(t, kept)
                if stop:
                    ended_by_user = True
                    break
                if t < self.start:
                    continue
                kept += 1
                if not take:
                    continue
                image = self._convert(vf)
                if shape is not None and image.shape != shape:
                    log.warn(
                        "size",
                        f"frame {state['index']}: size changed from {_fmt_shape(shape)} to "
                        f"{_fmt_shape(image.shape)}",
                    )
                shape = image.shape
                cursor.seen(state["index"], t, kept, delivered + 1, shape)
                yield Frame(index=state["index"], time=t, image=image)
                delivered += 1
                if self.max_frames is not None and delivered >= self.max_frames:
                    ended_by_user = True
                    break
        finally:
            self.skipped = cursor.skipped + max(state["decode_errors"], gap_missing)
            cursor.close(self.skipped, kept, ended_by_user)
            container.close()
            log.summary()
        if decoded == 0:
            lost = f" ({self.skipped} corrupt)" if self.skipped else ""
            raise VideoError(f"{self._describe()}: no decodable video frames{lost}")
        seen = state["index"] + 1
        if (
            not ended_by_user
            and not self.live
            and self._count
            and seen < self._count - 1
            and "drop" not in log.seen
        ):
            warnings.warn(
                f"{self.source}: ended after {seen} of {self._count} frames "
                "(truncated or corrupt file); frames kept",
                VideoWarning,
                stacklevel=2,
            )

    # -------------------------------------------------------------- OpenCV iteration
    def _iter_opencv(self, cap: cv2.VideoCapture, cursor: _Cursor) -> Iterator[Frame]:
        log = _Log(self.source)
        kept, delivered = cursor.kept, cursor.delivered
        index = cursor.index
        t0 = _time.monotonic() - cursor.offset  # live: wall-clock time since the first frame
        shape: tuple[int, ...] | None = cursor.shape
        stopped = False
        try:
            while True:
                ok, img = cap.read()
                if not ok or img is None:
                    if self.live:
                        log.warn("drop", f"stream ended after frame {index}; frames kept")
                    break
                index += 1
                msec = cap.get(cv2.CAP_PROP_POS_MSEC)
                t = msec / 1000.0 if (msec and msec > 0 and not self.live) else None
                if t is None:
                    t = (_time.monotonic() - t0) if self.live else index / (self._rate or 25.0)
                take, stop = self._select(t, kept)
                if stop:
                    stopped = True
                    break
                if t < self.start:
                    continue
                kept += 1
                if not take:
                    continue
                image = _normalise_image(img, self.gray)
                if shape is not None and image.shape != shape:
                    log.warn(
                        "size",
                        f"frame {index}: size changed from {_fmt_shape(shape)} to "
                        f"{_fmt_shape(image.shape)}",
                    )
                shape = image.shape
                cursor.seen(index, t, kept, delivered + 1, shape)
                yield Frame(index=index, time=t, image=image)
                delivered += 1
                if self.max_frames is not None and delivered >= self.max_frames:
                    stopped = True
                    break
        finally:
            cursor.close(cursor.skipped, kept, stopped)
            cap.release()
            log.summary()
        if index < 0:
            raise VideoError(f"{self._describe()}: no decodable video frames")


@dataclass
class _Cursor:
    """Where an iteration over a stream stands, carried across reconnections: the source
    index to go on from, the last frame delivered (index, time [s], image shape, wall
    clock [s]), the frames in the window and delivered, frames skipped so far, the time
    offset [s] for the next connection's PTS, and whether the iteration was ended by
    ``end`` / ``max_frames``."""

    index: int = -1
    last: int = -1
    time: float | None = None
    kept: int = 0
    delivered: int = 0
    skipped: int = 0
    offset: float = 0.0
    shape: tuple[int, ...] | None = None
    wall: float = 0.0
    stopped: bool = False
    away: float = 0.0
    resumed_at: int = 0

    def seen(self, index: int, t: float, kept: int, delivered: int, shape: tuple[int, ...]) -> None:
        """A frame is being delivered."""
        self.index = self.last = index
        self.time, self.kept, self.delivered = t, kept, delivered
        self.shape, self.wall = shape, _time.monotonic()

    def close(self, skipped: int, kept: int, stopped: bool) -> None:
        """The connection ended (``stopped``: by ``end`` or ``max_frames``)."""
        self.skipped, self.kept, self.stopped = skipped, kept, stopped

    def resume(self, away: float, rate: float | None) -> None:
        """A new connection ``away`` seconds after the last frame: its first frame is
        that long after the last one, its index after the frames sent meanwhile at
        ``rate`` [1/s] (the next index if the rate is unknown)."""
        self.away = away
        self.offset = (self.time or 0.0) + away
        self.resumed_at = self.last + (max(1, round(away * rate)) if rate else 1)
        self.index = self.resumed_at - 1


class _Log:
    """Warnings of one iteration: the first few of each kind individually, then a count."""

    def __init__(self, source: str) -> None:
        self.source = source
        self.counts: dict[str, int] = {}
        self.seen: set[str] = set()

    def warn(self, kind: str, message: str) -> None:
        self.seen.add(kind)
        n = self.counts.get(kind, 0) + 1
        self.counts[kind] = n
        if n <= _MAX_WARNINGS:
            warnings.warn(f"{self.source}: {message}", VideoWarning, stacklevel=4)

    def summary(self) -> None:
        for kind, n in self.counts.items():
            if n > _MAX_WARNINGS:
                warnings.warn(
                    f"{self.source}: {n - _MAX_WARNINGS} more '{kind}' warnings not shown",
                    VideoWarning,
                    stacklevel=4,
                )


def _tagged_rate(metadata: Any) -> float | None:
    """The frame rate a :class:`VideoWriter` stored in the container (:data:`RATE_TAG`)
    [frames/s], or None (no tag, or not a rate in (0, 1000))."""
    try:
        rate = float(Fraction(str(metadata.get(RATE_TAG, ""))))
    except (ValueError, ZeroDivisionError):
        return None
    return rate if 0.0 < rate < 1000.0 else None


def _nominal_rate(average: Any, guessed: Any) -> float | None:
    """The stream's frame rate [frames/s]: its base rate (FFmpeg's r_frame_rate, PyAV's
    ``guessed_rate``) where the average rate (frames over duration) is up to a third
    below it — frames were lost from a constant-rate stream, so the average is lower —
    else the average rate (a variable-rate stream whose base rate is a finer time grid;
    interlaced video, whose base rate is often its field rate, twice the frame rate),
    else whichever is known. None when neither is."""
    avg = float(average) if average else 0.0
    base = float(guessed) if guessed else 0.0
    if 0.0 < avg <= base < 1.5 * avg:
        return base
    return next((r for r in (avg, base) if 0.0 < r < math.inf), None)


def _why(exc: BaseException) -> str:
    text = getattr(exc, "strerror", None) or str(exc) or type(exc).__name__
    return str(text)


def _fmt_shape(shape: tuple[int, ...]) -> str:
    kind = "gray" if len(shape) == 2 else ("BGR" if shape[2] == 3 else f"{shape[2]} channels")
    return f"{shape[1]}x{shape[0]} {kind}"


def _is_macos() -> bool:
    return os.uname().sysname == "Darwin" if hasattr(os, "uname") else False


# --------------------------------------------------------------------------------------
# writer
# --------------------------------------------------------------------------------------


class VideoWriter:
    """Encode frames into a video file with PyAV (for the renderer and annotated output).

    ``write(image)`` takes (H, W, 3) BGR or (H, W) grayscale ``uint8`` images (and BGRA,
    whose alpha is dropped); the first frame fixes the size, and later frames must
    match it. Frame ``k`` gets the presentation time ``k / fps`` [s]. The default codec
    is H.264 (``libx264``, ``yuv420p``, constant quality ``crf``), with MPEG-4 Part 2
    (``mpeg4``) as the fallback where libx264 is not available; ``codec="ffv1"`` (in
    ``.mkv``/``.avi``) stores ``uint16`` grayscale frames losslessly (``gray16le``), e.g.
    16-bit thermal video. ``yuv420p`` needs even sizes: an odd width or height is padded
    by one replicated column/row on the right/bottom (pixel coordinates are unchanged).
    MP4/MOV files are written with the index at the front (``+faststart``), so a file
    cut short later still plays up to the cut. The frame rate is stored in the
    container's tag :data:`RATE_TAG`: a file of frames written at gaps in time
    (``pts``, frames dropped upstream) has an average rate below it, and FFmpeg's guess
    of the rate from the timestamps is the gaps' (every third frame: 25/3), so
    :class:`VideoReader` takes the tag for the frames' indices.

    Args:
        path: output file; its extension picks the container (``.mp4``, ``.mkv``, …).
        fps: frame rate [1/s], > 0.
        codec: FFmpeg encoder name (``"libx264"``, ``"mpeg4"``, ``"ffv1"``, …).
        crf: libx264 constant rate factor (0 lossless … 51 worst; 18 ≈ visually lossless).
        preset: libx264 speed preset (``"ultrafast"`` … ``"veryslow"``).
        gop: keyframe interval in frames (None = encoder default).
        options: further encoder options (FFmpeg private options, strings).
        container_options: muxer options (strings) that replace the defaults, e.g.
            ``{"movflags": "+frag_keyframe+empty_moov+default_base_moof",
            "frag_duration": "250000", "flush_packets": "1"}`` for a fragmented MP4
            that stays playable up to the last fragment when the writer is killed.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        fps: float = 25.0,
        *,
        codec: str = "libx264",
        crf: int = 18,
        preset: str = "veryfast",
        gop: int | None = None,
        options: dict[str, str] | None = None,
        container_options: dict[str, str] | None = None,
    ) -> None:
        if not (isinstance(fps, int | float) and math.isfinite(fps) and fps > 0):
            raise ValueError(f"fps: expected a frame rate > 0 per second, got {fps!r}")
        if not (isinstance(crf, int) and 0 <= crf <= 51):
            raise ValueError(f"crf: expected an integer in [0, 51], got {crf!r}")
        if gop is not None and not (isinstance(gop, int) and gop >= 1):
            raise ValueError(f"gop: expected an integer >= 1, got {gop!r}")
        self.path = Path(path)
        if not self.path.parent.is_dir():
            raise ValueError(f"path: folder {self.path.parent} does not exist")
        if self.path.is_dir():
            raise ValueError(f"path: {self.path} is a folder")
        self.fps = float(fps)
        self.codec = codec
        self.crf = crf
        self.preset = preset
        self.gop = gop
        self.options = dict(options or {})
        self.container_options = dict(container_options or {})
        self.frames_written = 0
        self._last_pts = -1  # the last frame's presentation time [frame periods]
        self._container: Any = None
        self._stream: Any = None
        self._shape: tuple[int, ...] | None = None
        self._deep = False
        self._pad = (0, 0)
        self._closed = False

    def __enter__(self) -> VideoWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _open(self, image: NDArray[Any]) -> None:
        h, w = image.shape[:2]
        self._deep = image.dtype == np.uint16
        rate = Fraction(self.fps).limit_denominator(100_000)
        fmt_opts = {}
        mp4 = self.path.suffix.lower() in (".mp4", ".mov", ".m4v")
        if mp4:
            fmt_opts["movflags"] = "+faststart"
        fmt_opts.update(self.container_options)
        if mp4 and "use_metadata_tags" not in fmt_opts.get("movflags", ""):
            # the MP4 muxer keeps tags it does not know, RATE_TAG, only with this flag
            fmt_opts["movflags"] = fmt_opts.get("movflags", "") + "+use_metadata_tags"
        try:
            container = av.open(str(self.path), "w", options=fmt_opts)
        except (av.error.FFmpegError, OSError, ValueError) as exc:
            raise ValueError(f"path: cannot create video file {self.path} ({_why(exc)})") from None
        container.metadata[RATE_TAG] = str(rate)
        codecs = [self.codec] if self._deep else [self.codec, "mpeg4"]
        stream = None
        last_error = ""
        for name in dict.fromkeys(codecs):
            try:
                stream = container.add_stream(name, rate=rate)
                break
            except (av.error.FFmpegError, ValueError, LookupError) as exc:
                last_error = _why(exc)
        if stream is None:
            container.close()
            _remove(self.path)
            raise ValueError(f"codec: cannot encode with {self.codec!r} ({last_error})")
        if self._deep:
            pix_fmt = "gray16le"
            if "gray16le" not in _pix_fmts(stream):
                container.close()
                _remove(self.path)
                raise ValueError(
                    f"image: 16-bit frames need a lossless 16-bit codec such as "
                    f"VideoWriter('{self.path.with_suffix('.mkv').name}', codec='ffv1'); "
                    f"{stream.codec_context.name!r} cannot store them"
                )
            pad = (0, 0)
        else:
            pix_fmt = "yuv420p"
            fmts = _pix_fmts(stream)
            if fmts and pix_fmt not in fmts:
                pix_fmt = next(iter(fmts))
            pad = (h % 2, w % 2) if pix_fmt == "yuv420p" else (0, 0)
            if any(pad):
                warnings.warn(
                    f"{self.path}: odd frame size {w}x{h} padded to {w + pad[1]}x{h + pad[0]} "
                    "for yuv420p",
                    VideoWarning,
                    stacklevel=3,
                )
        stream.width, stream.height = w + pad[1], h + pad[0]
        stream.pix_fmt = pix_fmt
        stream.time_base = Fraction(1, 1) / rate
        if self.gop is not None:
            stream.codec_context.gop_size = self.gop
        name = stream.codec_context.name
        opts = {}
        if name == "libx264":
            opts = {"crf": str(self.crf), "preset": self.preset}
        elif name == "mpeg4":
            stream.codec_context.bit_rate = max(int(0.25 * w * h * self.fps), 500_000)
            stream.codec_context.qmax = 8
        opts.update(self.options)
        stream.options = opts
        self.codec = name
        self._container, self._stream, self._pad = container, stream, pad
        self._shape = image.shape

    @property
    def last_pts(self) -> int:
        """The last frame's presentation time [frame periods]; -1 before the first."""
        return self._last_pts

    def write(self, image: NDArray[Any], pts: int | None = None) -> None:
        """Append one frame (BGR/BGRA/gray uint8, or gray uint16 with a 16-bit codec).

        ``pts``: the frame's presentation time in frame periods (``1 / fps``) from the
        video's start, after the last frame's — a gap leaves the frames between out and
        keeps the later ones at their times (frames dropped or lost upstream); default:
        the frame after the last one.
        """
        if self._closed:
            raise ValueError(f"{self.path}: writer is closed")
        if pts is not None and (isinstance(pts, bool) or int(pts) != pts or pts <= self._last_pts):
            raise ValueError(
                f"pts: expected an integer after the last frame's ({self._last_pts}), got {pts!r}"
            )
        img = np.asarray(image)
        if img.ndim == 3 and img.shape[2] == 4:
            img = img[:, :, :3]
        if img.ndim == 3 and img.shape[2] == 1:
            img = img[:, :, 0]
        if not (img.ndim == 2 or (img.ndim == 3 and img.shape[2] == 3)):
            raise ValueError(f"image: expected (H, W) or (H, W, 3) pixels, got shape {img.shape}")
        if img.dtype not in (np.uint8, np.uint16) or (img.dtype == np.uint16 and img.ndim == 3):
            raise ValueError(
                f"image: expected uint8 BGR/gray or uint16 gray pixels, got {img.dtype} "
                f"with shape {img.shape}"
            )
        if img.shape[0] < 2 or img.shape[1] < 2:
            raise ValueError(f"image: frame too small ({img.shape[1]}x{img.shape[0]})")
        if self._container is None:
            self._open(img)
        elif img.shape != self._shape or (img.dtype == np.uint16) != self._deep:
            raise ValueError(
                f"image: frame {self.frames_written} has shape {img.shape} {img.dtype}, the "
                f"video has {self._shape} {'uint16' if self._deep else 'uint8'}"
            )
        if any(self._pad):
            pad = ((0, self._pad[0]), (0, self._pad[1])) + (((0, 0),) if img.ndim == 3 else ())
            img = np.pad(img, pad, mode="edge")
        fmt = "gray16le" if self._deep else ("gray" if img.ndim == 2 else "bgr24")
        frame = av.VideoFrame.from_ndarray(np.ascontiguousarray(img), format=fmt)
        frame.pts = self._last_pts = self._last_pts + 1 if pts is None else int(pts)
        for packet in self._stream.encode(frame):
            self._container.mux(packet)
        self.frames_written += 1

    def close(self) -> None:
        """Flush the encoder and finish the file (idempotent).

        A writer that received no frames writes no file (and warns).
        """
        if self._closed:
            return
        self._closed = True
        if self._container is None:
            warnings.warn(
                f"{self.path}: no frames written; no file created", VideoWarning, stacklevel=2
            )
            return
        try:
            for packet in self._stream.encode(None):
                self._container.mux(packet)
        finally:
            self._container.close()


def _pix_fmts(stream: Any) -> set[str]:
    try:
        return {f.name for f in (stream.codec_context.codec.video_formats or ())}
    except Exception:
        return set()


def _remove(path: Path) -> None:
    try:
        path.unlink()
    except OSError:
        pass
