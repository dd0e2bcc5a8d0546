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

   the box size is smoothed exponentially alongside; a box that repeats one of the
   frame before exactly (:data:`STALE_LIMIT`) is associated but measures nothing — its
   track predicts;
3. confirmed tracks are reported, also while they coast on their prediction through a
   short occlusion or missed detections (up to ``delete_after`` frames).

With ``stabilise`` (default) each box is tracked in horizon-stabilised rows: its row
less how far the horizon's row at its column has moved since the first horizon taken,
and reported back in the frame's own rows. The camera's pitch and roll sway moves every
distant ship with the horizon, so it leaves the stabilised rows, where a ship's vertical
motion is its slow change of depression: the vertical acceleration noise is a fifth of
the horizontal by default (``sigma_a`` = (0.5, 0.1) px/frame² when the frames come with
horizons, 0.5 for both axes when they do not). The line is the frame's horizon
(:meth:`VisualTracker.horizon`, queued by :meth:`VisualTracker.stream` and
:meth:`VisualTracker.step`, or given to :meth:`VisualTracker.update`), taken once it has
settled (:data:`LINE_SETTLE`) and where it follows the lines before it
(:data:`LINE_GATE`); a frame whose horizon jumps or is not found takes their linear
prediction. Until the first line is taken the rows are the frame's. (The project's own
addition [NEW]: the seed tracks the box centre in the frame's pixels, §1.3.)

With ``motion`` (default) a moving camera's image shift and zoom are taken out first
(:class:`~seawatch.vision.motion.CameraMotion`, measured on each frame where its horizon
is found): the tracker filters the boxes in the first frame's coordinates and reports
them in the frame's own. A zoom is undone about the frame's centre ``c`` — a pixel ``p``
is ``c + (p − c) / scale``, box sizes are divided by ``scale``, and so is the horizon
line, before the stabilised rows — and the detector's noise floor ``sigma_z`` becomes
``sigma_z / scale`` there (:meth:`~seawatch.tracking.mtt.MultiTargetTracker.
set_pixel_size`); then the pan's accumulated shift is subtracted. A fixed camera
accumulates neither and is tracked as without it.

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
from numpy.typing import ArrayLike, NDArray

from seawatch._validation import FloatArray, as_float_array, in_range, integer, positive
from seawatch.filters import (
    AdaptiveFractionalKalmanFilter,
    FractionalKalmanFilter,
    KalmanFilter,
)
from seawatch.tracking.mtt import MultiTargetTracker, TrackStates
from seawatch.vision.detect import ClassicalShipDetector, Detections, _horizon_points
from seawatch.vision.motion import CameraMotion

__all__ = [
    "DEFAULT_ORDER",
    "FILTERS",
    "STABILISED_SIGMA_A",
    "STALE_LIMIT",
    "TRACK_COLUMNS",
    "VisualTracker",
    "frames_lost",
    "tracks_to_rows",
]

TRACK_COLUMNS: tuple[str, ...] = ("id", "x", "y", "w", "h", "u_wl", "v_wl", "misses")
"""Columns of a per-frame track array: track id, box top-left x, y [px], width w and
height h [px], water-line point u_wl, v_wl [px], consecutive missed detections [frames]."""

_FIND = object()  # detect(): find the horizon of the frame
_QUEUED = object()  # update(): the horizon queued for the frame

READ_THREAD = "seawatch-read"
"""Name of :meth:`VisualTracker.stream`'s thread that decodes, finds the horizon and
prepares each frame."""
DETECT_THREAD = "seawatch-detect"
"""Name of :meth:`VisualTracker.stream`'s thread that detects the ships."""

LINE_GATE = 1.0
"""Largest step [px] of the horizon's rows (at the image's ends) from the last two lines'
linear prediction that the stabilised rows follow (:class:`VisualTracker`): a camera's
sway moves it by a fraction of that per frame (the rendered cases: 0.13 px at most; a
small boat pitching 2° at 4 s: 0.14 px/frame² at 1000 px focal length)."""
LINE_HOLD = 5
"""Frames a horizon outside :data:`LINE_GATE` is held back before it is taken."""
LINE_SETTLE = 3
"""Consecutive horizons within :data:`LINE_GATE` of the two before them after which the
rows are stabilised at all (a horizon tracker still converging — the rendered lighting
case's second rendering: 20 px off at one end in its first frames — would move every
track)."""

STALE_LIMIT = 10
"""Consecutive frames a box (x, y, w, h) that repeats one of the frame before exactly is
taken as no new measurement (:class:`VisualTracker`): its error is the one before's. A
distant ship moves a fraction of a pixel per frame and the detector's box edges are
whole pixels, so its box stays put for a few frames and then jumps (the rendered small
case, a 10-px boat at 0.2 px/frame: 30 % of its boxes repeat, in runs of 1–6 frames,
though the pixels under them changed); a capture that duplicates frames repeats every
box. Measured as new, the repeats hold the track back where the box last jumped to. A
box that stays the same for longer is a still scene: measured again."""

STABILISED_SIGMA_A: tuple[float, float] = (0.5, 0.1)
"""Default acceleration noise (horizontal, vertical) [px/frame²] of a box centre in
horizon-stabilised rows (:class:`VisualTracker`, ``stabilise=True``; 0.5 for both without)."""

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


def _line_rows(line: FloatArray, u: FloatArray) -> FloatArray:
    """A line's ``(x0, y0, x1, y1)`` [px] rows [px] at columns ``u``."""
    x0, y0, x1, y1 = line
    return y0 + (y1 - y0) / (x1 - x0) * (u - x0)


def _line_jump(
    line: FloatArray, last: FloatArray, before: FloatArray | None, ahead: int = 1
) -> float:
    """How far [px] a line's rows at the ends of ``last`` lie from the linear prediction
    of ``before`` and ``last``, ``ahead`` frames after ``last`` (``last`` itself without
    ``before``) (:meth:`VisualTracker._lift`)."""
    ends = last[[0, 2]]
    pred = _line_rows(last, ends)
    if before is not None:
        pred = pred + ahead * (pred - _line_rows(before, ends))
    return float(np.max(np.abs(_line_rows(line, ends) - pred)))


class VisualTracker:
    """Ship boxes per frame → confirmed pixel tracks (module docstring, steps 1–3).

    Args:
        detector: a detector ``detector(image, horizon=...) -> Detections`` (or boxes);
            None: :class:`ClassicalShipDetector` with its defaults.
        filter: ``"afkf"``, ``"fkf"`` or ``"kf"`` (module docstring).
        order: fractional order alpha of afkf/fkf (ALGORITHMS.md §1.3;
            :data:`DEFAULT_ORDER`).
        memory: GL history length L of afkf/fkf (default 30).
        sigma_a: acceleration noise of the box centre [px/frame²] (Q0, §1.3): one for
            both axes or ``(horizontal, vertical)``; None: :data:`STABILISED_SIGMA_A`,
            (0.5, 0.1), when the first frame tracked comes with a horizon (``horizon``
            on, or one given to :meth:`update` / :meth:`track_detections`) and
            ``stabilise`` is on — the vertical in horizon-stabilised rows —, else 0.5.
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
        stabilise: track the boxes in horizon-stabilised rows (module docstring); while
            no horizon has been found the rows are the frame's.
        motion: camera-motion compensation (module docstring): a panning or yawing
            camera's frame-to-frame shift and a zooming camera's scale are measured in
            :meth:`stream` and :meth:`step` (not for precomputed detections given to
            :meth:`update` alone).
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
        sigma_a: float | tuple[float, float] | None = None,
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
        stabilise: bool = True,
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
        self.stabilise = bool(stabilise)
        self._sigma_a = sigma_a  # None: chosen at the first frame (update)
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
            sigma_a=STABILISED_SIGMA_A[0] if sigma_a is None else sigma_a,
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
        if self._sigma_a is None and np.ndim(self.mtt.sigma_a):
            # the first frame rebuilt the tracker with STABILISED_SIGMA_A: it chooses again
            self.mtt = MultiTargetTracker(self._factory, **self._mtt_args)
        self.mtt.reset()
        self._forget_repeats()
        self._offsets: dict[int, FloatArray] = {}
        self._frame = 0
        self._last_index: int | None = None  # source index of the last frame (coast_to)
        self.frames_dropped = 0
        """Frames :meth:`stream` dropped to keep up with a live source (its last call)."""
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
        tracks' pixels are another grid's, and so are the stabilised rows' lines); new
        tracks continue the ids."""
        self.mtt.reset(keep_ids=True)
        self._forget_repeats()
        self._offsets.clear()
        self._forget_lines()

    def _restart_motion(self) -> None:
        self._shifts: deque[FloatArray] = deque()  # offsets measured, not yet tracked
        self._zooms: deque[FloatArray] = deque()  # zooms measured, not yet tracked
        self._lines: deque[Any] = deque()  # horizons queued, not yet tracked
        self._forget_lines()
        self.camera_offset = np.zeros(2)
        """The accumulated camera shift (x, y) [px] of the last frame tracked
        (:class:`~seawatch.vision.motion.CameraMotion`; 0 for a fixed camera)."""
        self.camera_zoom = np.array([1.0, 0.0, 0.0])
        """The accumulated zoom of the last frame tracked and the frame centre it is
        taken out about, ``(scale, cx, cy)`` [–, px, px] (1 for a camera that does not
        zoom)."""
        self._pixel = 1.0  # the detector's pixel in the tracker's coordinates (1 / scale)
        self.mtt.set_pixel_size(1.0)
        if self._motion is not None:
            self._motion.reset()

    def _forget_repeats(self) -> None:
        self._last_boxes = np.empty((0, 4))  # the last frame's boxes, as detected
        self._repeats = np.empty(0, np.int64)  # frames each of them repeated the one before

    def _stale(self, boxes: FloatArray) -> NDArray[np.bool_]:
        """Flags of the boxes (k, 4) that repeat one of the last frame's to the last bit,
        for at most :data:`STALE_LIMIT` frames in a row (no new measurement)."""
        last = self._last_boxes
        count = np.zeros(boxes.shape[0], np.int64)
        if boxes.shape[0] and last.shape[0]:
            same = np.all(boxes[:, None, :] == last[None, :, :], axis=2)
            hit = same.any(axis=1)
            count[hit] = self._repeats[same.argmax(axis=1)[hit]] + 1
        self._last_boxes, self._repeats = boxes.copy(), count
        return (count >= 1) & (count <= STALE_LIMIT)

    def next_offset(self) -> FloatArray:
        """The camera offset (x, y) [px] measured for the next frame to track, taken from
        the queue :meth:`stream` fills (so that precomputed detections can be tracked
        with it later: :meth:`track_detections`); the last one when none is waiting."""
        if self._shifts:
            self.camera_offset = self._shifts.popleft()
        return self.camera_offset

    def next_zoom(self) -> FloatArray:
        """The camera zoom ``(scale, cx, cy)`` measured for the next frame to track, taken
        from the queue :meth:`stream` fills, as :meth:`next_offset`; the last one when
        none is waiting."""
        if self._zooms:
            self.camera_zoom = self._zooms.popleft()
        return self.camera_zoom

    def _forget_lines(self) -> None:
        """Start the stabilised rows afresh (no line taken)."""
        self._line: FloatArray | None = None  # the last line taken (x0, y0, x1, y1)
        self._line_before: FloatArray | None = None  # the line a frame before it
        self._held = 0  # frames since the last line taken
        self._given: tuple[FloatArray | None, FloatArray | None] = (None, None)
        self._steady = 0  # consecutive lines given that followed the two before them
        self._line_ref: FloatArray | None = None  # the first line taken: the reference

    def next_horizon(self) -> Any:
        """The horizon queued for the next frame to track (:meth:`stream`, :meth:`step`;
        so that precomputed detections can be tracked with it later:
        :meth:`track_detections`), or None when none is waiting."""
        return self._lines.popleft() if self._lines else None

    def _queue_frame(self, image: ArrayLike, horizon: Any) -> None:
        """Measure the next frame's camera shift and queue its horizon (frame order) for
        :meth:`update`."""
        if self._motion is not None:
            self._shifts.append(self._motion.update(image, horizon))
            self._zooms.append(np.r_[self._motion.scale, self._motion.centre])
        if self.stabilise:
            self._lines.append(horizon)

    def _lift(self, horizon: Any) -> FloatArray | None:
        """The frame's horizon line ``(x0, y0, x1, y1)`` [px] for stabilised rows: None
        until :data:`LINE_SETTLE` lines in a row followed the two before them (within
        :data:`LINE_GATE` of their linear prediction, at the image's ends); from then on
        the given one where found and within the gate of the last two lines taken (a
        horizon tracker that jumps onto glare would move every track), else — and where
        no horizon is found — their linear prediction (at most :data:`LINE_HOLD` frames
        ahead); a line that stays outside the gate for :data:`LINE_HOLD` frames is taken
        (the camera did move)."""
        points = _horizon_points(horizon)
        line = None if points is None or points[2] == points[0] else np.array(points)
        if self._line is None:  # not yet settled: lines that follow each other
            if line is None:
                return None
            g1, g0 = self._given
            ok = g1 is not None and _line_jump(line, g1, g0) <= LINE_GATE * self._pixel
            self._steady = self._steady + 1 if ok else 0
            self._given = (line, g1)
            if self._steady < LINE_SETTLE:
                return None
            self._line, self._line_before, self._line_ref = line, g1, line
            return line
        last, before = self._line, self._line_before
        ahead = self._held + 1  # frames since the last line taken
        if line is not None and (
            self._held >= LINE_HOLD
            or _line_jump(line, last, before, ahead) <= LINE_GATE * self._pixel
        ):
            # the line a frame before this one, on the way from the last one taken
            back = None if self._held >= LINE_HOLD else line - (line - last) / ahead
            self._line, self._line_before, self._held = line, back, 0
            return line
        self._held += 1
        return last if before is None else last + min(ahead, LINE_HOLD) * (last - before)

    def _rise(self, line: FloatArray | None, u: FloatArray) -> FloatArray:
        """How far [px] the horizon's rows at columns ``u`` lie below those of the first
        line taken, the reference (0 without a line)."""
        if line is None or self._line_ref is None:
            return np.zeros_like(u)
        return _line_rows(line, u) - _line_rows(self._line_ref, u)

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
        self,
        detections: Detections | ArrayLike | None,
        *,
        offset: ArrayLike | None = None,
        horizon: Any = _QUEUED,
        zoom: ArrayLike | None = None,
    ) -> FloatArray:
        """Track one frame's detections (steps 2–3); returns the confirmed tracks.

        Args:
            detections: :class:`Detections`, or boxes (k, 4) ``x, y, w, h`` [px], (k, 5)
                with a score or (k, 7) with the water-line point; None: no detection.
            offset: the frame's accumulated camera shift (x, y) [px]; default: the one
                :meth:`stream` or :meth:`step` measured for this frame, else the last.
            zoom: the frame's accumulated zoom ``(scale, cx, cy)`` (:meth:`next_zoom`);
                default: the one :meth:`stream` or :meth:`step` measured for this frame,
                else the last.
            horizon: the frame's horizon for the stabilised rows (a
                :class:`~seawatch.vision.horizon.HorizonEstimate`, a line
                ``(x0, y0, x1, y1)`` [px] or None); default: the one :meth:`stream` or
                :meth:`step` queued for this frame. Not found or None: the last lines'
                prediction (module docstring).

        Returns:
            (n, 8) float array of :data:`TRACK_COLUMNS`, rows in order of track id.
        """
        rows = _detection_rows(detections)
        rows = rows[rows[:, 4] >= self.min_score]
        stale = self._stale(rows[:, :4])  # in the frame's own pixels, as detected
        if offset is None:
            off = self.next_offset()
        else:
            off = self.camera_offset = as_float_array("offset", offset).reshape(2)
        if zoom is None:
            self.next_zoom()
        else:
            self.camera_zoom = as_float_array("zoom", zoom).reshape(3)
        scale, centre = self.camera_zoom[0], self.camera_zoom[1:]
        hz = self.next_horizon() if horizon is _QUEUED else horizon
        if self._frame == 0 and self._sigma_a is None and self.stabilise and hz is not None:
            # horizons come with the frames: the vertical noise of stabilised rows
            args = {**self._mtt_args, "sigma_a": STABILISED_SIGMA_A}
            self.mtt = MultiTargetTracker(self._factory, **args)
        scale = positive("zoom scale", scale)
        if 1.0 / scale != self._pixel:
            self._pixel = 1.0 / scale
            self.mtt.set_pixel_size(self._pixel)
        if scale != 1.0:  # to the first frame's focal length (module docstring)
            _magnify_rows(rows, 1.0 / scale, centre, box=0)
        if scale != 1.0 or off[1] != 0.0:  # the line too, into the first frame's rows
            points = _horizon_points(hz)
            if points is not None:
                ends = centre[[0, 1, 0, 1]] + (np.array(points) - centre[[0, 1, 0, 1]]) / scale
                hz = ends - [0.0, off[1], 0.0, off[1]]
        line = self._lift(hz) if self.stabilise else None
        # into stabilised rows (at each box's centre column and water-line point)
        rows[:, 1] -= self._rise(line, rows[:, 0] + 0.5 * rows[:, 2])
        rows[:, 6] -= self._rise(line, rows[:, 5])
        rows[:, 0:2] -= off  # into the first frame's coordinates
        rows[:, 5:7] -= off
        boxes = rows[:, :4] if rows.shape[0] else None
        states = self.mtt.step(boxes, float(self._frame), stale=stale if rows.shape[0] else None)
        self._frame += 1
        out = self._rows(states, rows)
        out[:, 1:3] += off  # back into this frame's pixels
        out[:, 5:7] += off
        out[:, 2] += self._rise(line, out[:, 1] + 0.5 * out[:, 3])
        out[:, 6] += self._rise(line, out[:, 5])
        if scale != 1.0:
            _magnify_rows(out, scale, centre, box=1)
        return out

    def coast(self, frames: int) -> None:
        """Predict every track over ``frames`` frames lost before the next one (a stream
        or recording that dropped them, or frames dropped to keep up with a live
        source): scans not made, at the last camera offset
        (:meth:`~seawatch.tracking.mtt.MultiTargetTracker.step`'s ``observed=False``),
        so the filters, whose model steps one frame at a time, keep their velocities
        per frame; the lost frames count towards ``delete_after`` (the time a track
        coasts) but not as misses of the evidence rules (M-of-N confirmation,
        ``coast_ratio``): a ship not looked for was not missed."""
        for _ in range(integer("frames", frames, 0)):
            self._forget_repeats()  # a frame lost between: no longer the one before
            if self.mtt.n_tracks == 0:
                break
            self.mtt.step(None, float(self._frame), observed=False)
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
        self._queue_frame(image, self.last_horizon)
        return self.update(detections)

    def stream(
        self, frames: Iterable[Any], *, ahead: bool = True, keep_up: bool | None = None
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

        A live source (a camera, a stream) does not wait for a caller that is slower than
        its frame rate: with ``keep_up`` a frame that arrives while the caller is three
        frames behind is dropped before its horizon and ships are looked for
        (:func:`~seawatch.io.prefetch.prefetch`'s ``skip``), so that the frames given
        stay a few frames behind the source instead of ever further (1080p on two
        cores without AVX-512: the track job runs at 21–25 frames/s by the hour; at 23.5
        frames/s it fell a second further behind a 25 frames/s camera every 16–20 s).
        The frames dropped are counted in :attr:`frames_dropped` and are missing from the
        iteration like frames the source lost: :meth:`coast_to` (or
        :meth:`track_frames`) coasts over them by their indices; a warning says when the
        first is dropped.

        Args:
            frames: images (H, W[, C]) or :class:`seawatch.io.video.Frame` objects (their
                ``time`` feeds the horizon tracker), e.g. a ``VideoReader``.
            ahead: False: everything in the calling thread (nothing is dropped).
            keep_up: drop frames to keep up (above); None (default): for a source that
                sends frames in real time, one whose ``realtime`` attribute is true (a
                ``VideoReader`` of a camera device or an RTSP, RTMP, UDP … stream), not
                for a file, a folder or an HTTP URL, whose frames wait to be read.
        """

        self.frames_dropped = 0
        prepare = getattr(self.detector, "prepare", None)
        finish = getattr(self.detector, "detect_prepared", None)
        split = callable(prepare) and callable(finish)

        def horizon(fr: Any) -> tuple[Any, Any, Any]:
            image = getattr(fr, "image", fr)
            hz = self.horizon(image, getattr(fr, "time", None))
            self._queue_frame(image, hz)
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

        from seawatch.io.prefetch import Skipped, prefetch

        # OpenCV's own worker threads wait for work by spinning: beside the stream's two
        # threads on two cores they burnt 3.5 ms of CPU per 1080p frame and gave nothing
        # (bench video, per-thread CPU); its calls run in the calling thread meanwhile
        threads = cv2.getNumThreads()
        cv2.setNumThreads(1)
        if keep_up is None:
            keep_up = bool(getattr(frames, "realtime", False))
        late = Skipped()
        try:
            ready = prefetch(frames, work=horizon, name=READ_THREAD, skip=late if keep_up else None)
            for item in prefetch(ready, work=detect, name=DETECT_THREAD):
                late.warn_once(" (their tracks coast)", stacklevel=2)
                self.frames_dropped = late.count
                yield item
            self.frames_dropped = late.count
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
        self,
        detections: Sequence[Any],
        offsets: Sequence[ArrayLike] | None = None,
        horizons: Sequence[Any] | None = None,
        zooms: Sequence[ArrayLike] | None = None,
    ) -> list[FloatArray]:
        """Per-frame confirmed tracks of precomputed per-frame detections (no detector).

        Lets several filters run on the very same detections (the ship-video scenario);
        ``offsets``: the frames' camera offsets (:meth:`next_offset` while they were
        detected); None: a fixed camera. ``horizons``: the frames' horizons for the
        stabilised rows (:meth:`next_horizon` while they were detected); None: none.
        ``zooms``: the frames' camera zooms (:meth:`next_zoom`); None: no zoom.
        """
        n = len(detections)
        for name, seq in (("offsets", offsets), ("horizons", horizons), ("zooms", zooms)):
            if seq is not None and len(seq) != n:
                raise ValueError(f"{name}: expected one per frame ({n}), got {len(seq)}")
        offs = [(0.0, 0.0)] * n if offsets is None else offsets
        lines = [None] * n if horizons is None else horizons
        scales = [(1.0, 0.0, 0.0)] * n if zooms is None else zooms
        return [
            self.update(d, offset=o, horizon=h, zoom=z)
            for d, o, h, z in zip(detections, offs, lines, scales, strict=True)
        ]

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


def _magnify_rows(rows: FloatArray, scale: float, centre: FloatArray, box: int) -> None:
    """Rows of boxes magnified by ``scale`` about ``centre`` (x, y) [px], in place: the
    box ``x, y, w, h`` in columns ``box`` … ``box + 3`` and the water-line point in
    columns 5–6 (a detection row ``x, y, w, h, score, u_wl, v_wl`` with ``box`` 0, a
    track row of :data:`TRACK_COLUMNS` with 1); each point ``c + scale (p − c)``, each
    size ``scale`` times."""
    for col in (box, 5):
        rows[:, col : col + 2] = centre + scale * (rows[:, col : col + 2] - centre)
    rows[:, box + 2 : box + 4] *= scale


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
