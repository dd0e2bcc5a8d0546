"""Visual tracking of ship boxes: detector → multi-target tracker → pixel tracks (seed 001).

Issue 6, "Visual tracking"; ALGORITHMS.md §1.3–1.5. Per frame:

1. the horizon (:class:`~seawatch.vision.horizon.HorizonTracker`) and the ship boxes
   (a :class:`~seawatch.vision.detect.Detector`, by default the
   :class:`~seawatch.vision.detect.ClassicalShipDetector`) of the frame;
2. the boxes enter a :class:`~seawatch.tracking.mtt.MultiTargetTracker` (Mahalanobis gate,
   GNN assignment, M-of-N confirmation): each track's box centre ``[u, v, u_dot, v_dot]``
   runs the chosen filter —

   * ``"afkf"``: :class:`~seawatch.filters.AdaptiveFractionalKalmanFilter` (§1.5, rule
     R1, fractional order ``order``, memory ``memory``),
   * ``"fkf"``: :class:`~seawatch.filters.FractionalKalmanFilter` (§1.4, constant Q),
   * ``"kf"``: the integer-order Kalman filter (the CV model; §1.3: the FKF at order 1);

   the box size is smoothed exponentially alongside;
3. confirmed tracks are reported, also while they coast on their prediction through a
   short occlusion or missed detections (up to ``delete_after`` frames).

With ``motion`` (default) a moving camera's image shift is taken out first
(:class:`~seawatch.vision.motion.CameraMotion`, measured on each frame where its horizon
is found): the tracker filters the boxes in the first frame's coordinates (pixel minus
the accumulated shift) and reports them in the frame's own; a fixed camera accumulates no
shift and is tracked as without it.

The water-line pixel of a track is its box centre plus a smoothed offset from the box
centre to the detector's water-line point (the bottom-centre of the box until a
detection gives one).

Track rows: :data:`TRACK_COLUMNS` = ``id, x, y, w, h, u_wl, v_wl, misses`` [–, px, px,
px, px, px, px, frames]; ``x, y`` is the box's top-left corner.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable, Iterator, Sequence
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import FloatArray, as_float_array, in_range, integer, positive
from seawatch.filters import (
    AdaptiveFractionalKalmanFilter,
    FractionalKalmanFilter,
    KalmanFilter,
)
from seawatch.tracking.mtt import MultiTargetTracker, TrackStates
from seawatch.vision.detect import ClassicalShipDetector, Detections
from seawatch.vision.motion import CameraMotion

__all__ = [
    "DEFAULT_ORDER",
    "FILTERS",
    "TRACK_COLUMNS",
    "VisualTracker",
    "frames_lost",
    "tracks_to_rows",
]

TRACK_COLUMNS: tuple[str, ...] = ("id", "x", "y", "w", "h", "u_wl", "v_wl", "misses")
"""Columns of a per-frame track array: track id, box top-left x, y [px], width w and
height h [px], water-line point u_wl, v_wl [px], consecutive missed detections [frames]."""

_FIND = object()  # detect(): find the horizon of the frame

READ_THREAD = "seawatch-read"
"""Name of :meth:`VisualTracker.stream`'s thread that decodes, finds the horizon and
prepares each frame."""
DETECT_THREAD = "seawatch-detect"
"""Name of :meth:`VisualTracker.stream`'s thread that detects the ships."""

DEFAULT_ORDER = 0.95
"""Default fractional order alpha of the AFKF/FKF (ALGORITHMS.md §1.3: tunable 0.8–1.0)."""

FilterName = Literal["afkf", "fkf", "kf"]
FILTERS: tuple[str, ...] = ("afkf", "fkf", "kf")
"""The filters :class:`VisualTracker` offers (ship-video estimators of INTERFACES.md)."""


def _detection_rows(det: Detections | ArrayLike | None) -> FloatArray:
    """(k, 7) rows ``x, y, w, h, score, u_wl, v_wl`` from Detections or an array."""
    if det is None:
        return np.empty((0, 7))
    if isinstance(det, Detections):
        return np.asarray(det.boxes, dtype=np.float64).reshape(-1, 7)
    arr = as_float_array("detections", det)
    if arr.size == 0:
        return np.empty((0, 7))
    if arr.ndim != 2 or arr.shape[1] not in (4, 5, 7):
        raise ValueError(
            "detections: expected boxes (k, 4) as (x, y, w, h), (k, 5) with a score or "
            f"(k, 7) with the water-line point, got shape {arr.shape}"
        )
    out = np.empty((arr.shape[0], 7))
    out[:, :4] = arr[:, :4]
    out[:, 4] = arr[:, 4] if arr.shape[1] >= 5 else 1.0
    if arr.shape[1] == 7:
        out[:, 5:] = arr[:, 5:]
    else:  # bottom-centre of the box
        out[:, 5] = arr[:, 0] + 0.5 * arr[:, 2]
        out[:, 6] = arr[:, 1] + arr[:, 3]
    return out


class VisualTracker:
    """Ship boxes per frame → confirmed pixel tracks (module docstring, steps 1–3).

    Args:
        detector: a detector ``detector(image, horizon=...) -> Detections`` (or boxes);
            None: :class:`ClassicalShipDetector` with its defaults.
        filter: ``"afkf"``, ``"fkf"`` or ``"kf"`` (module docstring).
        order: fractional order alpha of afkf/fkf (ALGORITHMS.md §1.3;
            :data:`DEFAULT_ORDER`).
        memory: GL history length L of afkf/fkf (default 30).
        sigma_a: acceleration noise of the box centre [px/frame²] (Q0, §1.3).
        sigma_z: box-centre jitter of the detector [px] (R = σ_z² I).
        sigma_z_rel: the jitter of a large box as a fraction k of its size:
            ``R = diag(max(σ_z, k w)², max(σ_z, k h)²)`` with the track's smoothed size
            (:class:`~seawatch.tracking.mtt.MultiTargetTracker`); 0: σ_z alone. The
            default, 3 %, changes nothing for boxes under 67 px (2 px / 3 %) and gives a
            270-px hull σ = 8 px: its track holds when the box loses a neighbour's bow
            (a 40-px jump of its centre) or its upper works (FVessel, README).
        sigma_v0: initial velocity std of a new track [px/frame].
        gate_probability: gate of the association (χ²₂ probability).
        confirm_m, confirm_n: M-of-N confirmation.
        delete_after: consecutive missed frames after which a confirmed track is
            dropped (the occlusion it survives by prediction).
        coast_ratio: a confirmed track is also dropped once its missed frames reach
            this times its detections (a track confirmed on a few frames of glint or
            wake coasts a few frames, a ship seen for long the whole ``delete_after``);
            None: ``delete_after`` for every track.
        size_smoothing: weight of a new box size in the exponential smoothing, (0, 1].
        overlap_gate: second association stage of the tracker (:class:`~seawatch.
            tracking.mtt.MultiTargetTracker`): an unpaired track and detection whose boxes
            overlap by this fraction of the smaller box continue the same id (a ship
            entering at the image edge, a hull that gains its superstructure); None: off.
        confirmed_first: the matching cascade of the tracker (confirmed tracks are
            assigned before tentative ones): a track born on a fragment of a ship cannot
            take the ship from its confirmed track.
        occlusion: occlusion handling of the tracker (:class:`~seawatch.tracking.mtt.
            MultiTargetTracker`, step 4a): where confirmed ships' boxes overlap, each is
            measured by the edges of its detection that lie outside the other ships'
            spans, with its remembered size (a box of both ships, a ship cut by the one
            in front); its water-line offset is then not updated.
        min_score: detections with a lower score are ignored.
        horizon: estimate the horizon per frame and give it to the detector (sea region).
        motion: camera-motion compensation (module docstring): a panning or yawing
            camera's frame-to-frame shift is measured in :meth:`stream` and :meth:`step`
            (not for precomputed detections given to :meth:`update` alone).
        fps: frame rate used when frames come without times [1/s].
        filter_options: further keyword arguments of the AFKF/FKF (``rule``, ``gain``,
            ``window``, ``g_max``, ``delta``).

    Time is counted in frames inside the filters (velocities in px/frame, §1.3).
    """

    def __init__(
        self,
        detector: Any = None,
        filter: FilterName = "afkf",
        order: float = DEFAULT_ORDER,
        memory: int = 30,
        *,
        sigma_a: float = 0.5,
        sigma_z: float = 2.0,
        sigma_z_rel: float = 0.03,
        sigma_v0: float = 5.0,
        gate_probability: float = 0.999,
        confirm_m: int = 3,
        confirm_n: int = 5,
        delete_after: int = 12,
        coast_ratio: float | None = 2.0,
        size_smoothing: float = 0.3,
        overlap_gate: float | None = 0.5,
        confirmed_first: bool = True,
        occlusion: bool = True,
        min_score: float = 0.0,
        horizon: bool = True,
        motion: bool = True,
        fps: float = 25.0,
        filter_options: dict[str, Any] | None = None,
    ) -> None:
        if filter not in FILTERS:
            raise ValueError(f"filter: expected one of {', '.join(FILTERS)}, got {filter!r}")
        if detector is not None and not callable(detector):
            raise ValueError(f"detector: expected a callable detector, got {detector!r}")
        self.detector = ClassicalShipDetector() if detector is None else detector
        self.filter = filter
        self.order = positive("order", order)
        self.memory = integer("memory", memory, 1)
        self.min_score = in_range("min_score", min_score, 0.0, 1.0)
        self.fps = positive("fps", fps)
        self.use_horizon = bool(horizon)
        self._motion = CameraMotion() if motion else None
        opts = dict(filter_options or {})
        if filter == "kf":
            if opts:
                raise ValueError("filter_options: the Kalman filter takes none")
            factory: Any = KalmanFilter
        else:
            factory = AdaptiveFractionalKalmanFilter if filter == "afkf" else FractionalKalmanFilter
            opts = {"order": self.order, "memory": self.memory, **opts}
        self._mtt_args: dict[str, Any] = dict(
            dt=1.0,
            sigma_a=sigma_a,
            sigma_z=sigma_z,
            sigma_v0=sigma_v0,
            gate_probability=gate_probability,
            confirm_m=confirm_m,
            confirm_n=confirm_n,
            delete_after=delete_after,
            coast_ratio=coast_ratio,
            size_smoothing=size_smoothing,
            overlap_gate=overlap_gate,
            confirmed_first=confirmed_first,
            occlusion=occlusion,
            filter_options=opts or None,
            sigma_z_rel=sigma_z_rel,
        )
        self._factory = factory
        self.mtt = MultiTargetTracker(factory, **self._mtt_args)
        self._smooth = float(size_smoothing)
        self.reset()

    def reset(self) -> None:
        """Forget all tracks, the horizon and the frame count (a new video)."""
        self.mtt.reset()
        self._offsets: dict[int, FloatArray] = {}
        self._frame = 0
        self._last_index: int | None = None  # source index of the last frame (coast_to)
        self._restart_motion()
        self._horizon: Any = None
        self.last_horizon: Any = None
        """The horizon (:class:`~seawatch.vision.horizon.HorizonEstimate`) of the last
        frame given to :meth:`detect`, or None (horizon off or no frame yet)."""
        if self.use_horizon:
            from seawatch.vision.horizon import HorizonTracker

            self._horizon = HorizonTracker(fps=self.fps)
        reset = getattr(self.detector, "reset", None)
        if callable(reset):
            reset()

    def restart_tracks(self) -> None:
        """Forget the tracks, not the horizon nor the detector (a frame-size change: the
        tracks' pixels are another grid's); new tracks continue the ids."""
        self.mtt.reset(keep_ids=True)
        self._offsets.clear()

    def _restart_motion(self) -> None:
        self._shifts: deque[FloatArray] = deque()  # offsets measured, not yet tracked
        self.camera_offset = np.zeros(2)
        """The accumulated camera shift (x, y) [px] of the last frame tracked
        (:class:`~seawatch.vision.motion.CameraMotion`; 0 for a fixed camera)."""
        if self._motion is not None:
            self._motion.reset()

    def next_offset(self) -> FloatArray:
        """The camera offset (x, y) [px] measured for the next frame to track, taken from
        the queue :meth:`stream` fills (so that precomputed detections can be tracked
        with it later: :meth:`track_detections`); the last one when none is waiting."""
        if self._shifts:
            self.camera_offset = self._shifts.popleft()
        return self.camera_offset

    def _measure_motion(self, image: ArrayLike, horizon: Any) -> None:
        """Measure the next frame's camera shift (frame order) for :meth:`update`."""
        if self._motion is not None:
            self._shifts.append(self._motion.update(image, horizon))

    # ------------------------------------------------------------------ per frame
    def horizon(self, image: ArrayLike, time: float | None = None) -> Any:
        """The horizon of the next frame (the smoothed :class:`~seawatch.vision.horizon.
        HorizonEstimate`; None with the horizon off). Call it once per frame, in frame
        order, and hand the result to :meth:`detect` — it may run ahead in another thread
        (the track job finds a frame's horizon while the previous frame is detected)."""
        return self._horizon.update(image, time) if self._horizon is not None else None

    def detect(
        self, image: ArrayLike, time: float | None = None, *, horizon: Any = _FIND
    ) -> FloatArray:
        """Detections (k, 7) ``x, y, w, h, score, u_wl, v_wl`` of one frame (step 1);
        ``horizon``: the frame's :meth:`horizon` when found already (default: found
        here)."""
        hz = self.horizon(image, time) if horizon is _FIND else horizon
        self.last_horizon = hz
        return self._detect(image, hz)

    def _detect(self, image: ArrayLike, hz: Any) -> FloatArray:
        try:
            det = self.detector(image, horizon=hz)
        except TypeError:
            det = self.detector(image)
        return _detection_rows(det)

    def update(
        self, detections: Detections | ArrayLike | None, *, offset: ArrayLike | None = None
    ) -> FloatArray:
        """Track one frame's detections (steps 2–3); returns the confirmed tracks.

        Args:
            detections: :class:`Detections`, or boxes (k, 4) ``x, y, w, h`` [px], (k, 5)
                with a score or (k, 7) with the water-line point; None: no detection.
            offset: the frame's accumulated camera shift (x, y) [px]; default: the one
                :meth:`stream` or :meth:`step` measured for this frame, else the last.

        Returns:
            (n, 8) float array of :data:`TRACK_COLUMNS`, rows in order of track id.
        """
        rows = _detection_rows(detections)
        rows = rows[rows[:, 4] >= self.min_score]
        if offset is None:
            off = self.next_offset()
        else:
            off = self.camera_offset = as_float_array("offset", offset).reshape(2)
        rows[:, 0:2] -= off  # into the first frame's coordinates
        rows[:, 5:7] -= off
        states = self.mtt.step(rows[:, :4] if rows.shape[0] else None, float(self._frame))
        self._frame += 1
        out = self._rows(states, rows)
        out[:, 1:3] += off  # back into this frame's pixels
        out[:, 5:7] += off
        return out

    def coast(self, frames: int) -> None:
        """Predict every track over ``frames`` frames lost before the next one (a stream
        or recording that dropped them): empty scans at the last camera offset, so the
        filters, whose model steps one frame at a time, keep their velocities per frame
        and the missed frames count towards deletion (none once no track is left)."""
        for _ in range(integer("frames", frames, 0)):
            if self.mtt.n_tracks == 0:
                break
            self.mtt.step(None, float(self._frame))
            self._frame += 1

    def coast_to(self, index: int, step: int = 1) -> None:
        """Before the frame of source index ``index``: :meth:`coast` over the frames lost
        since the last index given here (:func:`frames_lost`; ``step``: source frames
        between two frames delivered), and remember ``index``."""
        last, self._last_index = self._last_index, int(index)
        if last is not None:
            self.coast(frames_lost(index, last, step))

    def step(self, image: ArrayLike, time: float | None = None) -> FloatArray:
        """Detect and track one frame; the confirmed tracks (:meth:`update`)."""
        detections = self.detect(image, time)
        self._measure_motion(image, self.last_horizon)
        return self.update(detections)

    def stream(
        self, frames: Iterable[Any], *, ahead: bool = True
    ) -> Iterator[tuple[Any, Any, FloatArray]]:
        """``(frame, horizon, detections)`` of each frame, in order (step 1: the
        :meth:`horizon` and :meth:`detect` of each frame; hand the detections to
        :meth:`update`).

        With ``ahead`` the frames are read and their horizons found (and, with a detector
        that has ``prepare``/``detect_prepared`` such as the classical one, their working
        bands made) in one background thread and their ships detected in another, a few
        frames ahead of the caller
        (:func:`seawatch.io.prefetch.prefetch`): decoding, detection and the caller's
        tracking of earlier frames overlap on two cores (the decoder, OpenCV and the
        compiled kernels release the GIL). The results are those of the sequential
        loop: each stage keeps the frame order, and the horizon tracker and the
        detector see the frames one at a time. While it runs, OpenCV's thread pool is
        off (``cv2.setNumThreads(1)``, restored after). Stopping the iteration early
        stops both threads and closes ``frames``.

        Args:
            frames: images (H, W[, C]) or :class:`seawatch.io.video.Frame` objects (their
                ``time`` feeds the horizon tracker), e.g. a ``VideoReader``.
            ahead: False: everything in the calling thread.
        """

        prepare = getattr(self.detector, "prepare", None)
        finish = getattr(self.detector, "detect_prepared", None)
        split = callable(prepare) and callable(finish)

        def horizon(fr: Any) -> tuple[Any, Any, Any]:
            image = getattr(fr, "image", fr)
            hz = self.horizon(image, getattr(fr, "time", None))
            self._measure_motion(image, hz)
            # a detector that can prepare a frame apart (the classical one: its working
            # band) does so here, which balances the two threads
            return fr, hz, prepare(image, horizon=hz) if split else None  # type: ignore[misc]

        def detect(item: tuple[Any, Any, Any]) -> tuple[Any, Any, FloatArray]:
            fr, hz, ready = item
            if split:
                return fr, hz, _detection_rows(finish(ready))  # type: ignore[misc]
            return fr, hz, self._detect(getattr(fr, "image", fr), hz)

        if not ahead:
            yield from map(detect, map(horizon, frames))
            return
        import cv2

        from seawatch.io.prefetch import prefetch

        # OpenCV's own worker threads wait for work by spinning: beside the stream's two
        # threads on two cores they burnt 3.5 ms of CPU per 1080p frame and gave nothing
        # (bench video, per-thread CPU); its calls run in the calling thread meanwhile
        threads = cv2.getNumThreads()
        cv2.setNumThreads(1)
        try:
            ready = prefetch(frames, work=horizon, name=READ_THREAD)
            yield from prefetch(ready, work=detect, name=DETECT_THREAD)
        finally:
            cv2.setNumThreads(threads)

    def track_frames(self, frames: Iterable[Any], *, ahead: bool = True) -> list[FloatArray]:
        """Per-frame confirmed tracks of a frame sequence (:meth:`stream` →
        :meth:`update`).

        Args:
            frames: images (H, W[, C]) or :class:`seawatch.io.video.Frame` objects (their
                ``time`` feeds the horizon tracker), e.g. a ``VideoReader``.
            ahead: detect ahead in background threads (:meth:`stream`).

        Frames lost in between (a ``Frame`` index that skips more than the source's
        ``step``, e.g. a ``VideoReader``'s decimation) are coasted over (:meth:`coast_to`).

        Returns:
            one (n_k, 8) array of :data:`TRACK_COLUMNS` per frame given.
        """
        out = []
        step = int(getattr(frames, "step", 1) or 1)
        for fr, hz, det in self.stream(frames, ahead=ahead):
            index = getattr(fr, "index", None)
            if index is not None:
                self.coast_to(index, step)
            self.last_horizon = hz
            out.append(self.update(det))
        return out

    def track_detections(
        self, detections: Sequence[Any], offsets: Sequence[ArrayLike] | None = None
    ) -> list[FloatArray]:
        """Per-frame confirmed tracks of precomputed per-frame detections (no detector).

        Lets several filters run on the very same detections (the ship-video scenario);
        ``offsets``: the frames' camera offsets (:meth:`next_offset` while they were
        detected); None: a fixed camera.
        """
        if offsets is None:
            return [self.update(d, offset=(0.0, 0.0)) for d in detections]
        if len(offsets) != len(detections):
            raise ValueError(
                f"offsets: expected one per frame ({len(detections)}), got {len(offsets)}"
            )
        return [self.update(d, offset=o) for d, o in zip(detections, offsets, strict=True)]

    # ------------------------------------------------------------------ output
    def _rows(self, st: TrackStates, det: FloatArray) -> FloatArray:
        live = set(int(i) for i in st.ids)
        for gone in [k for k in self._offsets if k not in live]:
            del self._offsets[gone]
        boxes = st.boxes if st.boxes is not None else np.zeros((len(st), 4))
        centres = st.states[:, :2]
        for i, tid in enumerate(st.ids):
            tid = int(tid)
            j = int(st.detection[i])
            if j < 0 or j >= det.shape[0]:
                continue
            if st.anchored is not None and st.anchored[i]:
                continue  # a box not wholly its own: its water line may be another ship's
            c = det[j, :2] + 0.5 * det[j, 2:4]
            off = det[j, 5:7] - c
            if not np.all(np.isfinite(off)):
                continue
            prev = self._offsets.get(tid)
            if st.restarted is not None and st.restarted[i]:
                prev = None  # a re-segmented box: its own water-line offset from now on
            self._offsets[tid] = off if prev is None else prev + self._smooth * (off - prev)
        sel = np.flatnonzero(st.confirmed)
        out = np.empty((sel.size, len(TRACK_COLUMNS)))
        for r, i in enumerate(sel):
            tid = int(st.ids[i])
            off = self._offsets.get(tid)
            if off is None:
                off = np.array([0.0, 0.5 * boxes[i, 3]])
            out[r, 0] = tid
            out[r, 1:5] = boxes[i]
            out[r, 5:7] = centres[i] + off
            out[r, 7] = st.misses[i]
        return out


def frames_lost(index: int, last_index: int, step: int = 1) -> int:
    """Frames lost between two frames delivered ``step`` source frames apart, from their
    source indices (rounded to whole steps; 0 when none or when the index went back)."""
    return max(0, (int(index) - int(last_index) + step // 2) // step - 1)


def tracks_to_rows(per_frame: Sequence[FloatArray]) -> FloatArray:
    """MOT rows ``(frame, id, x, y, w, h)`` from per-frame track arrays (frames 0, 1, …).

    The input of :func:`seawatch.metrics.cle.centre_location_error`.
    """
    parts = [
        np.column_stack([np.full(t.shape[0], k, np.float64), t[:, :5]])
        for k, t in enumerate(per_frame)
        if t.shape[0]
    ]
    return np.concatenate(parts) if parts else np.empty((0, 6))
