"""Multi-target tracking of ships: gating, global nearest neighbour, M-of-N, deletion.

The classic track-oriented GNN tracker (Blackman & Popoli, *Design and Analysis of
Modern Tracking Systems*, 1999, §6.2 and §9.3; Bar-Shalom, Willett & Tian,
*Tracking and Data Fusion*, 2011, §3.2) for ships detected as points or boxes in the
image (pixels) or as points on the sea (metres). One scan:

1. **Predict** every track with its filter (nearly constant velocity model,
   ALGORITHMS.md §5.2: ``x = [x, y, vx, vy]``).
1a. **A ship boxed in pieces** (boxes, ``occlusion``): two or more boxes that lie wholly
   within one confirmed track's predicted box widened by its tolerance (and within no
   other track's), keep its water line (their bottoms within the tolerance of its
   predicted one) and together are no larger than the track plus its tolerance, while
   none of them is the whole ship (as wide as the track less its tolerance), are one
   box, their union: the track measures its whole ship, and a piece starts no track.
   Not where a tentative track follows one of them (IoU ≥ 1/2), nor past two scans in
   a row (:data:`_SPLIT_SCANS`): a box of two ships that comes apart for good is two.
2. **Gate** (Mahalanobis): ``d²_ij = y_ijᵀ S_i⁻¹ y_ij`` with ``y_ij = z_j − H x_i`` and
   ``S_i = H P_i Hᵀ + R_i``; detection j may update track i only if
   ``d²_ij <= gamma = chi2.ppf(gate_probability, 2)``. Vectorised over the candidate
   pairs of a sort-and-sweep prefilter (``|y| <= sqrt(gamma tr S_i)`` per axis), so the
   cost grows with the pairs near each other rather than with tracks × detections.
3. **Assign** (global nearest neighbour): among the gated pairs, the matching with the
   most pairs and, among those, the least total cost ``d²_ij + ln det S_i`` (the
   negative log-likelihood up to a constant, so a vague tentative track does not win a
   detection from a tight confirmed one), by ``scipy.optimize.linear_sum_assignment``
   on the rows and columns that have any gated pair.
4. **Update** assigned tracks with their detection (Kalman update, Joseph form);
   the others take a predict-only step (a miss).
4a. **Occlusion** (boxes, ``occlusion``): a detection box may hold two ships (merged) or
   only the visible part of one (cut by a ship in front). For a confirmed track, an edge
   of its box is *blocked* when it lies within another confirmed track's predicted span
   (on an axis where the two tracks' spans on the other axis overlap; a track of under a
   tenth of its area blocks nothing). Both edges free: the box is the track's (centre
   and size measured). One free edge: the centre is that edge moved inwards by half the
   track's remembered size, and the size is kept — unless the box is wider than that
   and its other edge stops at the near side of a ship in front (whose water line is
   lower by more than the tolerance; the box reaching at most σ_z into its span): the
   ship goes on behind that one, so it is at least its box, which is measured (a ship
   coming out from behind another). No free edge: the box's centre if its
   extent agrees with the track's size; on the vertical axis the bottom edge (the water
   line) for the nearest of the overlapping ships if it agrees with its predicted one;
   else the pair is not used and the track coasts. Gating uses these centres, so of two
   ships with one centre each takes the box of its own size; a track overlapping another
   (their predicted boxes, widened by the tolerance, overlap) also takes its edge of a
   merged box that went to the other, and is not restarted on a re-segmented box; a box
   that covers a third of two such tracks starts no track of its own. A track with
   25 detections or more (its height settled) whose box keeps its water line but whose
   top rises above the track's by more than twice the tolerance has something behind
   the ship in its box (a ship beyond it, a coast): its top edge is blocked too.
4b. **One ship's pieces** (boxes, ``occlusion``): two confirmed tracks that take the free
   edges of one box in 10 scans in a row (:data:`_PIECES_SCANS`) while its width stays
   within σ_z are one ship whose pieces (a hull split for a few frames) started a second
   track: two ships in one box drift apart or together, these tracks would keep the
   pieces' widths for ever. The one with more detections is restarted on the box, the
   other deleted.
5. **Manage tracks**: an unassigned detection starts a *tentative* track
   (``x0 = [z, 0, 0]``, ``P0 = diag(σ_z², σ_z², σ_v0², σ_v0²)``); a tentative track is
   *confirmed* once it has M detections among its last N scans (M-of-N, counting its
   birth) and is deleted as soon as it can no longer reach M within its first N scans;
   a confirmed track is deleted after K consecutive misses (with ``coast_ratio`` r, also
   once they reach r times its detections). A scan not made (a frame lost or dropped,
   ``step(None, observed=False)``) only predicts: it counts towards K but is no scan of
   the M-of-N window nor a miss of the ratio. Track ids are integers that are never
   reused.

Boxes ``(x, y, w, h)`` (top-left corner, width, height) are tracked by their centre;
the size is smoothed alongside by exponential smoothing of (w, h). The measurement noise
of a box centre may grow with the box: ``R_i = diag(max(σ_z, k w_i)², max(σ_z, k h_i)²)``
with ``k = sigma_z_rel`` and the track's smoothed size ``(w_i, h_i)``: a detector places
the edges of a large ship less surely than those of a small one (its masts, upper works
or a neighbour's bow boxed with it or not), and the larger error wins, as in the
occlusion tolerance ``max(σ_z, 15 %)``; ``k = 0``: ``R = σ_z² I``.

Speed: with the default linear Kalman filter all tracks live in stacked arrays
``X (T, 4)``, ``P (T, 4, 4)`` and every step is a handful of batched numpy operations
(no Python loop over tracks). Any other filter of :mod:`seawatch.filters` (the strong
tracking KF, the (adaptive) fractional KF) or a user factory runs as one filter object
per track.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment
from scipy.stats import chi2

from seawatch._validation import FloatArray, as_float_array, in_range, integer, positive
from seawatch.filters.fractional import FractionalKalmanFilter
from seawatch.filters.kalman import KalmanFilter
from seawatch.models.kinematic import axis_sigmas, constant_velocity, position_measurement

__all__ = [
    "MultiTargetTracker",
    "TrackFilter",
    "TrackStates",
    "gnn_assign",
    "tracks_to_mot",
]

_DIM = 2  # tracked position axes
_N = 2 * _DIM  # state size [x, y, vx, vy]
_RESTART_GROWTH = 10.0
"""Largest ratio of a detection's box area to a track's for the overlap stage's restart
(a hull that gains its superstructure: a few times; a boat merged into the box of the
ships passing in front of it: tens of times), and either way for the gate's pairs."""


def _same_scale(area_a: FloatArray, area_b: FloatArray) -> NDArray[np.bool_]:
    """Whether box areas [px² or m²] are within :data:`_RESTART_GROWTH` of each other,
    either way (broadcast): a box of another scale is another object or a speck of one."""
    return (area_a <= _RESTART_GROWTH * area_b) & (area_b <= _RESTART_GROWTH * area_a)


_EDGE_TOL = 0.15
"""Occlusion handling: a box edge within this fraction of a track's size (at least σ_z)
of a span or an extent counts as on it (:meth:`MultiTargetTracker._tolerance`)."""
_SETTLED_HITS = 25
"""Occlusion handling: detections after which a confirmed track's height is its ship's
(a top that then rises while the water line stays is something behind the ship)."""
_PIECES_SCANS = 10
"""Occlusion handling: scans in a row in which two tracks take the free edges of one box
of an unchanging width before they are taken for one ship's pieces (step 4b)."""
_SPLIT_SCANS = 2
"""Occlusion handling: scans in a row in which a track's box may come in pieces that are
united (step 1a); pieces that last longer are two ships (a box of two that comes apart)."""
_UNGATED = 1.0e12  # cost of a pair outside the gate inside the assignment solver


class TrackFilter(Protocol):
    """What the tracker needs of a per-track filter (every filter of seawatch.filters)."""

    x: Any
    P: Any

    def predict(self) -> None: ...

    def update(self, z: Any) -> None: ...


FilterFactory = Callable[[FloatArray, FloatArray], TrackFilter]


# --------------------------------------------------------------------------------------
# results
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class TrackStates:
    """The live tracks after one scan (rows in order of track id).

    Attributes:
        time: scan time [s, or frames when the tracker runs on frame numbers].
        ids: track ids, (k,) int64, stable over the life of a track, never reused.
        states: filter states ``[x, y, vx, vy]``, (k, 4), in the detections' units
            (px or m) and those units per time unit.
        covariances: state covariances, (k, 4, 4).
        confirmed: True for confirmed tracks, False for tentative ones, (k,).
        misses: consecutive scans without a detection, scans not made included
            (``step``'s ``observed``), (k,) int64 (0: updated in this scan; a confirmed
            track with misses > 0 is coasting on its prediction).
        hits: detections assigned to the track so far, (k,) int64.
        detection: index of the detection (in this scan's input, NaN rows counted)
            that updated or started the track, -1 if none, (k,) int64.
        boxes: smoothed boxes ``(x, y, w, h)`` around the estimated centre, (k, 4), in
            px; ``None`` when the detections are points.
        restarted: True where this scan restarted the track at an overlapping detection
            (``overlap_gate``), (k,); None: all False.
        anchored: True where this scan measured the track with a box not wholly its
            own (``occlusion``: an edge of it lay in another track's span), so that the
            box's centre, size and water line are not the track's, (k,); None: all
            False.
    """

    time: float
    ids: NDArray[np.int64]
    states: FloatArray
    covariances: FloatArray
    confirmed: NDArray[np.bool_]
    misses: NDArray[np.int64]
    hits: NDArray[np.int64]
    detection: NDArray[np.int64]
    boxes: FloatArray | None = None
    restarted: NDArray[np.bool_] | None = None
    anchored: NDArray[np.bool_] | None = None

    def __len__(self) -> int:
        return int(self.ids.shape[0])

    def __iter__(self) -> Iterator[tuple[int, FloatArray, FloatArray, str]]:
        """``(track_id, state, covariance, status)`` per track, status "confirmed" or
        "tentative"."""
        status = self.status
        for i in range(len(self)):
            yield int(self.ids[i]), self.states[i], self.covariances[i], str(status[i])

    @property
    def status(self) -> NDArray[np.str_]:
        """ "confirmed" or "tentative" per track, (k,)."""
        return np.where(self.confirmed, "confirmed", "tentative")

    @property
    def positions(self) -> FloatArray:
        """Estimated positions (centres for boxes), (k, 2)."""
        return self.states[:, :_DIM]

    def select(self, mask: NDArray[np.bool_]) -> TrackStates:
        """The subset of tracks where ``mask`` is True."""
        return TrackStates(
            time=self.time,
            ids=self.ids[mask],
            states=self.states[mask],
            covariances=self.covariances[mask],
            confirmed=self.confirmed[mask],
            misses=self.misses[mask],
            hits=self.hits[mask],
            detection=self.detection[mask],
            boxes=None if self.boxes is None else self.boxes[mask],
            restarted=None if self.restarted is None else self.restarted[mask],
            anchored=None if self.anchored is None else self.anchored[mask],
        )

    def confirmed_tracks(self) -> TrackStates:
        """Only the confirmed tracks."""
        return self.select(self.confirmed)


# --------------------------------------------------------------------------------------
# assignment
# --------------------------------------------------------------------------------------


def gnn_assign(cost: ArrayLike, gated: ArrayLike) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Global-nearest-neighbour assignment restricted to gated pairs.

    Finds, among the one-to-one matchings that use only pairs with ``gated[i, j]``, one
    with the most pairs and, among those, the least total ``cost`` (the solver sees
    ``cost`` on gated pairs and a prohibitive constant elsewhere, so every ungated pair it
    must use costs more than any gated matching could save; those pairs are dropped).
    Only rows and columns with at least one gated pair enter the solver.

    Args:
        cost: (T, D) cost of assigning detection j to track i (any finite real).
        gated: (T, D) bool, True where the pair passes the gate.

    Returns:
        ``(rows, cols)``: the assigned track and detection indices, sorted by row.
    """
    gate = np.asarray(gated, dtype=bool)
    c = np.asarray(cost, dtype=np.float64)
    if c.shape != gate.shape or c.ndim != 2:
        raise ValueError(f"cost: expected the shape of gated {gate.shape}, got {c.shape}")
    rows, cols = np.nonzero(gate)
    return _assign_pairs(rows, cols, c[rows, cols])


def _assign_pairs(
    rows: NDArray[np.intp], cols: NDArray[np.intp], cost: FloatArray
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """:func:`gnn_assign` on a sparse list of gated pairs ``(rows[k], cols[k], cost[k])``."""
    if rows.size == 0:
        empty = np.empty(0, np.int64)
        return empty, empty
    if not np.all(np.isfinite(cost)):
        raise ValueError("cost: contains NaN or inf on a gated pair")
    urows, ri = np.unique(rows, return_inverse=True)
    ucols, ci = np.unique(cols, return_inverse=True)
    sub = np.full((urows.size, ucols.size), _UNGATED)
    sub[ri, ci] = cost
    sub_gate = np.zeros(sub.shape, bool)
    sub_gate[ri, ci] = True
    r, k = linear_sum_assignment(sub)
    ok = sub_gate[r, k]
    return urows[r[ok]].astype(np.int64), ucols[k[ok]].astype(np.int64)


# --------------------------------------------------------------------------------------
# the tracker
# --------------------------------------------------------------------------------------


def _mahalanobis2(S: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``d² = yᵀ S⁻¹ y`` of 2-vectors ``y`` (n, 2) with 2 × 2 covariances ``S`` (n, 2, 2),
    by the closed-form inverse, and ``det S`` (n,)."""
    a, b, d = S[:, 0, 0], S[:, 0, 1], S[:, 1, 1]
    det = a * d - b * b
    return (d * y[:, 0] ** 2 - 2.0 * b * y[:, 0] * y[:, 1] + a * y[:, 1] ** 2) / det, det


class MultiTargetTracker:
    """GNN multi-target tracker with M-of-N confirmation (module docstring, steps 1–5).

    Args:
        filter_factory: the filter each track runs.

            * ``None`` or :class:`~seawatch.filters.KalmanFilter` (default): the linear
              Kalman filter, run batched over all tracks at once (fast path).
            * :class:`~seawatch.filters.StrongTrackingKalmanFilter` or any class taking
              ``(F, H, Q, R, x0, P0, **filter_options)``: one object per track built from
              the tracker's CV model.
            * :class:`~seawatch.filters.FractionalKalmanFilter` or
              :class:`~seawatch.filters.AdaptiveFractionalKalmanFilter`: one object per
              track from ``cls.for_image_tracking(dt, sigma_a, sigma_z, sigma_v0, x0,
              **filter_options)``.
            * any other callable ``factory(x0, P0) -> filter`` with ``predict()``,
              ``update(z)`` (``None`` for a miss) and attributes ``x`` (4,), ``P`` (4, 4).

            Gating uses each track's predicted ``P`` with the tracker's ``H`` and ``R``.
        dt: nominal scan interval [s or frames] (used when ``step`` gets no time).
        sigma_a: acceleration noise of the CV model [units/dt²] (discrete white-noise
            acceleration, ALGORITHMS.md §5.2): one for both axes, or one per axis.
        sigma_z: measurement noise of a detection position [px or m] (``R = σ_z² I``).
        sigma_z_rel: boxes only — the box-centre noise of a large box, as a fraction k
            of its width and height [–]: ``σ = max(σ_z, k · size)`` per axis (module
            docstring, ``R_i``); 0 (default): ``R = σ_z² I`` for every track.
        sigma_v0: initial velocity uncertainty of a new track [units/dt], about the
            largest speed expected.
        gate_probability: probability that a true detection falls inside the gate
            (``gamma = chi2.ppf(gate_probability, 2)``; 0.99 → 9.21).
        gate_threshold: the gate ``gamma`` on d² directly (overrides the probability).
        confirm_m, confirm_n: M-of-N confirmation (1 <= M <= N).
        delete_after: K, consecutive misses that delete a confirmed track (>= 1).
        coast_ratio: with a value r > 0, a confirmed track is also deleted once its
            consecutive misses reach r times the detections it has had (at least one):
            a track confirmed on three detections of glint or a wake coasts for a few
            frames, a ship seen for a hundred frames for the whole ``delete_after`` (the
            evidence a track has gathered bounds how long it lives on prediction alone,
            as a track score would). None (default): ``delete_after`` for every track.
        size_smoothing: weight of a new box size in the exponential smoothing of
            (w, h), in (0, 1] (1: no smoothing).
        overlap_gate: boxes only — a second association stage for what the gate left
            unpaired: a track and a detection whose boxes overlap by at least this
            fraction of the smaller box (intersection / smaller area, in (0, 1]) are
            paired, largest overlap first, and the track is restarted at the detection
            (centre and size; velocity and id kept) instead of updated. It keeps the id
            of a ship whose box is re-segmented — a hull that gains its superstructure,
            a bow that becomes a whole ship at the image edge — where the centre jumps
            out of the gate; a confirmed track's water line (the box's bottom edge)
            must stay within ``max(σ_z, 15 %)`` of its height (a piece of the ship
            above the water, or the ship with glint or a wake below it, is no
            re-segmentation). None (default): off.
        confirmed_first: a matching cascade (as in DeepSORT, Wojke et al. 2017): the
            confirmed tracks are assigned (gate, then overlap stage) before the
            tentative ones, which get only the detections left over — a track born on
            a fragment of a ship (a superstructure boxed alone for a frame) cannot take
            the ship from its confirmed track; in the overlap stage the track with the
            most detections is served first, so an established track, not one born a
            few frames ago on a piece of its ship, takes a re-segmented box. False
            (default): one assignment over all tracks, the most pairs first.
        occlusion: boxes only — occlusion handling by edge anchoring (module docstring,
            step 4a): a confirmed track is gated and updated with the centre its box
            gives once the box edges that lie within another confirmed track's span
            are set aside (a box of two merged ships, a ship cut by the one in front);
            a track whose box overlaps another's also takes its edge of a merged box
            assigned to the other, and is not restarted by the overlap stage. False
            (default): off.
        filter_options: extra keyword arguments for a filter class (see above).
    """

    def __init__(
        self,
        filter_factory: type | FilterFactory | None = None,
        *,
        dt: float = 1.0,
        sigma_a: float | ArrayLike = 0.5,
        sigma_z: float = 2.0,
        sigma_v0: float = 10.0,
        gate_probability: float = 0.99,
        gate_threshold: float | None = None,
        confirm_m: int = 3,
        confirm_n: int = 5,
        delete_after: int = 3,
        size_smoothing: float = 0.3,
        overlap_gate: float | None = None,
        confirmed_first: bool = False,
        occlusion: bool = False,
        filter_options: dict[str, Any] | None = None,
        coast_ratio: float | None = None,
        sigma_z_rel: float = 0.0,
    ) -> None:
        self.dt = positive("dt", dt)
        self.sigma_a = axis_sigmas(_DIM, sigma_a, "sigma_a")
        self._sigma_z_given = positive("sigma_z", sigma_z)  # [detector px] (set_pixel_size)
        self.sigma_v0 = positive("sigma_v0", sigma_v0)
        self.sigma_z_rel = positive("sigma_z_rel", sigma_z_rel, allow_zero=True)
        if gate_threshold is None:
            p = in_range("gate_probability", gate_probability, 0.0, 1.0, lo_open=True, hi_open=True)
            self.gate = float(chi2.ppf(p, _DIM))
        else:
            self.gate = positive("gate_threshold", gate_threshold)
        self.confirm_n = integer("confirm_n", confirm_n, 1)
        self.confirm_m = integer("confirm_m", confirm_m, 1)
        if self.confirm_m > self.confirm_n:
            raise ValueError(f"confirm_m: expected <= confirm_n = {confirm_n}, got {confirm_m}")
        if self.confirm_n > 62:
            raise ValueError(f"confirm_n: expected <= 62, got {confirm_n}")
        self.delete_after = integer("delete_after", delete_after, 1)
        self.coast_ratio = None if coast_ratio is None else positive("coast_ratio", coast_ratio)
        self.size_smoothing = in_range("size_smoothing", size_smoothing, 0.0, 1.0, lo_open=True)
        self.overlap_gate = (
            None
            if overlap_gate is None
            else in_range("overlap_gate", overlap_gate, 0.0, 1.0, lo_open=True)
        )
        self.confirmed_first = bool(confirmed_first)
        self.occlusion = bool(occlusion)
        self.filter_options = dict(filter_options or {})
        self.H = position_measurement(_DIM, 2)
        self.set_pixel_size(1.0)  # sigma_z, R, P0
        self.F, self.Q = constant_velocity(_DIM, self.dt, self.sigma_a)
        self._factory = self._make_factory(filter_factory)
        self.batched = self._factory is None
        self.reset()

    # ------------------------------------------------------------------ set-up
    def _make_factory(self, factory: type | FilterFactory | None) -> FilterFactory | None:
        opts = self.filter_options
        if factory is None or factory is KalmanFilter:
            if opts:
                raise ValueError(
                    f"filter_options: the default Kalman filter takes none, got {sorted(opts)}"
                )
            return None
        if isinstance(factory, type) and issubclass(factory, FractionalKalmanFilter):
            cls = factory

            def fractional(x0: FloatArray, P0: FloatArray) -> TrackFilter:
                return cls.for_image_tracking(
                    dt=self.dt, sigma_a=self.sigma_a, sigma_z=self.sigma_z,
                    sigma_v0=self.sigma_v0, x0=x0, **opts,
                )  # fmt: skip

            _probe(fractional, self.P0)
            return fractional
        if isinstance(factory, type):
            cls = factory

            def linear(x0: FloatArray, P0: FloatArray) -> TrackFilter:
                return cls(self.F, self.H, self.Q, self.R, x0, P0, **opts)

            _probe(linear, self.P0)
            return linear
        if not callable(factory):
            raise ValueError(
                f"filter_factory: expected a filter class or a callable, got {factory!r}"
            )
        if opts:
            raise ValueError("filter_options: only for filter classes, not for a factory")
        return factory

    def set_pixel_size(self, pixel: float) -> None:
        """The size of a detector's pixel in the tracker's coordinates for the scans to
        come (1 at the start): ``sigma_z``, the measurement noise floor given in the
        detector's pixels, is ``pixel`` times it there, in ``R``, the new tracks' ``P0``,
        the gates and the edge tolerances. A zooming camera's boxes, tracked at the
        first frame's focal length (:class:`~seawatch.vision.tracker.VisualTracker`),
        are measured on a grid ``1 / zoom`` times as coarse. The tracks' filters keep
        their own ``R`` only where ``sigma_z_rel`` is 0 (the per-scan ``R`` replaces it
        otherwise)."""
        self.sigma_z = self._sigma_z_given * positive("pixel", pixel)
        self.R = self.sigma_z**2 * np.eye(_DIM)
        self.P0 = np.diag([self.sigma_z**2] * _DIM + [self.sigma_v0**2] * _DIM)

    def reset(self, *, keep_ids: bool = False) -> None:
        """Forget all tracks and the last scan time; ids restart at 1, or with
        ``keep_ids`` continue after the last one given (the same stream, tracked anew)."""
        next_id = getattr(self, "_next_id", 1) if keep_ids else 1
        self._X = np.empty((0, _N))
        self._P = np.empty((0, _N, _N))
        self._ids = np.empty(0, np.int64)
        self._history = np.empty(0, np.int64)  # bit i: detection i scans ago
        self._age = np.empty(0, np.int64)  # scans since birth, birth scan = 1
        self._hits = np.empty(0, np.int64)
        self._misses = np.empty(0, np.int64)
        self._unseen = np.empty(0, np.int64)  # scans not made among the misses
        self._split = np.empty(0, np.int64)  # scans in a row boxed in pieces (step 1a)
        self._confirmed = np.empty(0, bool)
        self._size = np.empty((0, 2))
        self._filters: list[TrackFilter] = []
        self._next_id = next_id
        self._time: float | None = None
        self._anchored: tuple[NDArray[np.int64], FloatArray, NDArray[np.bool_]] | None = None
        self._own: tuple[FloatArray, FloatArray] | None = None  # _own_boxes of this scan
        self._S: FloatArray | None = None
        self._boxes: bool | None = None
        # step 4b: per pair of track ids that shared one box in the last scan it ran,
        # (scans in a row, least and largest box width)
        self._pieces: dict[tuple[int, int], tuple[int, float, float]] = {}

    @property
    def n_tracks(self) -> int:
        """Number of live tracks (tentative and confirmed)."""
        return int(self._ids.shape[0])

    # ------------------------------------------------------------------ input
    def _detections(self, detections: ArrayLike | None) -> tuple[FloatArray, FloatArray | None]:
        """Centres (D, 2) and sizes (D, 2) or None; rows with NaN/inf get NaN centres."""
        if detections is None:
            z = np.empty((0, _DIM))
        else:
            z = as_float_array("detections", detections)
        if z.ndim == 1 and z.size == 0:
            z = z.reshape(0, _DIM if not self._boxes else 4)
        if z.ndim != 2 or z.shape[1] not in (2, 4):
            raise ValueError(
                "detections: expected points (k, 2) or boxes (k, 4) as (x, y, w, h), "
                f"got shape {z.shape}"
            )
        boxes = z.shape[1] == 4
        if z.shape[0] > 0:
            if self._boxes is None:
                self._boxes = boxes
            elif self._boxes != boxes:
                kind = "boxes (k, 4)" if self._boxes else "points (k, 2)"
                raise ValueError(f"detections: this tracker tracks {kind}, got shape {z.shape}")
        if not boxes:
            return z, None
        if np.any(z[:, 2:] < 0):
            raise ValueError("detections: box width and height must be >= 0")
        return z[:, :2] + 0.5 * z[:, 2:], z[:, 2:]

    def _step_time(self, time: float | None) -> float:
        if time is None:
            return 0.0 if self._time is None else self._time + self.dt
        t = float(time)
        if not math.isfinite(t):
            raise ValueError(f"time: expected a finite number, got {time!r}")
        if self._time is not None and t <= self._time:
            raise ValueError(
                f"time: scans must come in increasing time order, got {t} after {self._time}"
            )
        return t

    # ------------------------------------------------------------------ one scan
    def step(
        self,
        detections: ArrayLike | None,
        time: float | None = None,
        *,
        stale: ArrayLike | None = None,
        observed: bool = True,
    ) -> TrackStates:
        """Process one scan of detections and return the live tracks.

        Args:
            detections: points (k, 2) as (x, y) or boxes (k, 4) as (x, y, w, h) with the
                top-left corner, in px or m; ``None`` or an empty array for an empty
                scan. Rows with NaN or inf are ignored (they keep their index in
                ``TrackStates.detection``).
            time: scan time [s or frames], strictly increasing; default: 0 for the
                first scan, then the previous time plus ``dt``. The prediction uses the
                actual interval (the default filter and the KalmanFilter class; other
                per-track filters need the nominal ``dt``).
            stale: (k,) flags of detections that repeat an earlier one exactly and so
                carry no new measurement (their error is the earlier one's: a box whose
                whole-pixel edges did not move, a duplicated frame): they are associated
                (and start tracks) as usual, and a track that takes one counts a hit,
                but its filter only predicts and its size is kept. None: every
                detection is new.
            observed: False for a scan that was not made (a frame the source lost or
                that was dropped to keep up with it; ``detections`` must then be None):
                the tracks are predicted to ``time`` and their consecutive misses go on
                (``delete_after`` bounds the time a track lives on prediction alone),
                but the scan is none of the evidence rules' scans — the M-of-N window
                does not move, and ``coast_ratio`` counts only the misses of scans made.
                A ship that was not looked for was not missed: with every other frame
                dropped a new track still confirms on three detections, and the coast
                ratio does not delete a young track for frames it was not looked for in.

        Returns:
            :class:`TrackStates` of every live track after this scan.
        """
        if not observed:
            if detections is not None:
                raise ValueError("detections: a scan not made (observed=False) has none")
            return self._unobserved(self._step_time(time))
        centres, sizes = self._detections(detections)
        repeat = np.zeros(centres.shape[0], bool)
        if stale is not None:
            repeat = np.asarray(stale, dtype=bool).reshape(-1)
            if repeat.shape[0] != centres.shape[0]:
                raise ValueError(
                    f"stale: expected one flag per detection ({centres.shape[0]}), "
                    f"got {repeat.shape[0]}"
                )
        t = self._step_time(time)
        dt = self.dt if self._time is None else t - self._time

        # 1. predict
        self._predict(dt)
        united = np.empty(0, np.int64)  # boxes made of one ship's pieces (step 1a)
        if sizes is not None and self.occlusion:
            centres, sizes, repeat, united = self._unite_pieces(centres, sizes, repeat)
        valid = np.flatnonzero(np.all(np.isfinite(centres), axis=1))
        if sizes is not None:
            valid = valid[np.all(np.isfinite(sizes[valid]), axis=1)]
        z = centres[valid]
        # 2.–3. gate and assign
        boxes = sizes is not None and self.overlap_gate is not None
        zs = None if sizes is None else sizes[valid]
        edges = None  # tracks measured by the free edges of their boxes
        self._anchored = None  # the gate's anchored centres of this scan (_anchor_pairs)
        self._own = None  # the tracks' own boxes of this scan (_own_boxes), for _anchor
        self._S = None  # the predicted tracks' innovation covariances, once computed
        if zs is not None and self.occlusion and self._confirmed.any():
            edges = self._confirmed.copy()
            self._own = self._own_boxes(z, zs)
        if self.confirmed_first:
            rows, cols, r2, c2 = self._cascade(z, zs if boxes else None, zs, edges)
        else:
            rows, cols = self._associate(z, sizes=zs, edges=edges)
        if boxes and not self.confirmed_first:
            r2, c2 = self._overlap_pairs(rows, cols, z, zs)  # type: ignore[arg-type]
        # 4. update assigned tracks, misses for the others
        zu = z[cols]
        explained = np.empty(0, np.int64)  # merged boxes of tracks in contact: no births
        anchored = np.zeros(self.n_tracks, bool)
        grow = np.ones((rows.size, _DIM), bool)  # axes whose size the detection updates
        if edges is not None:
            occ = self._occlusion(rows, cols, r2, c2, z, zs)  # type: ignore[arg-type]
            rows, cols, r2, c2, zu, grow, explained = occ
            anchored[rows[~grow.all(axis=1)]] = True
        anchored[rows[np.isin(valid[cols], united)]] = True  # no piece's water line
        assigned = np.zeros(self.n_tracks, bool)
        assigned[rows] = True
        self._S = None  # the update changes P
        new = ~repeat[valid[cols]]  # a repeated detection: no update, no size
        self._update(rows[new], zu[new])
        detection = np.full(self.n_tracks, -1, np.int64)
        detection[rows] = valid[cols]
        restarted = np.zeros(self.n_tracks, bool)
        if sizes is not None and rows.size:
            s = self.size_smoothing
            change = s * (sizes[valid[cols]] - self._size[rows])
            self._size[rows] += np.where(grow & new[:, None], change, 0.0)
        if boxes:
            if r2.size:
                restarted[r2] = True
                self._restart(r2, z[c2], sizes[valid[c2]])
                assigned[r2] = True
                detection[r2] = valid[c2]
                cols = np.concatenate([cols, c2])
        dead = np.zeros(self.n_tracks, bool)
        if boxes and edges is not None:  # 4b. one ship's pieces: one track again
            dead = self._pieces_of_one(detection, anchored, centres, sizes)  # type: ignore[arg-type]
        # 5. track management
        mask_n = (1 << self.confirm_n) - 1
        self._history = ((self._history << 1) | assigned) & mask_n
        self._age += 1
        self._hits += assigned
        self._misses = np.where(assigned, 0, self._misses + 1)
        self._unseen = np.where(assigned, 0, self._unseen)
        window_hits = _popcount(self._history)
        newly = ~self._confirmed & (window_hits >= self.confirm_m)
        self._confirmed |= newly
        can_confirm = window_hits + np.maximum(self.confirm_n - self._age, 0) >= self.confirm_m
        limit = np.full(self.n_tracks, float(self.delete_after))
        if self.coast_ratio is not None:
            ratio = np.maximum(self.coast_ratio * self._hits, 1.0)
            limit = np.minimum(limit, ratio + self._unseen)  # the ratio: scans made only
        keep = np.where(self._confirmed, self._misses < limit, can_confirm) & ~dead
        self._compress(keep)
        detection = detection[keep]
        restarted = restarted[keep]
        anchored = anchored[keep]
        free = np.ones(valid.size, bool)
        free[cols] = False
        free[explained] = False
        births = valid[free]
        self._birth(centres[births], None if sizes is None else sizes[births])
        detection = np.concatenate([detection, births.astype(np.int64)])
        restarted = np.concatenate([restarted, np.zeros(births.size, bool)])
        anchored = np.concatenate([anchored, np.zeros(births.size, bool)])
        self._time = t
        return self._report(t, detection, restarted, anchored)

    def _unobserved(self, t: float) -> TrackStates:
        """A scan not made (:meth:`step`'s ``observed=False``): predict, count the miss
        towards ``delete_after`` only, delete the tracks past it."""
        self._predict(self.dt if self._time is None else t - self._time)
        self._S = None
        self._misses += 1
        self._unseen += 1
        self._compress(self._misses < self.delete_after)
        self._time = t
        return self._report(t, np.full(self.n_tracks, -1, np.int64))

    def run(
        self, scans: Sequence[ArrayLike | None], times: ArrayLike | None = None
    ) -> list[TrackStates]:
        """:meth:`step` over a sequence of scans (``times`` optional, one per scan)."""
        if times is None:
            return [self.step(d) for d in scans]
        ts = as_float_array("times", times, ndim=1)
        if ts.shape[0] != len(scans):
            raise ValueError(f"times: expected {len(scans)} times, got {ts.shape[0]}")
        return [self.step(d, float(t)) for d, t in zip(scans, ts, strict=True)]

    # ------------------------------------------------------------------ pieces
    def _model(self, dt: float) -> tuple[FloatArray, FloatArray]:
        if abs(dt - self.dt) <= 1e-9 * self.dt:  # the nominal interval, up to rounding
            return self.F, self.Q
        return constant_velocity(_DIM, dt, self.sigma_a)

    def _predict(self, dt: float) -> None:
        """Time update of every track (ALGORITHMS.md §5.2 CV model)."""
        if self.n_tracks == 0:
            return
        F, Q = self._model(dt)
        if self.batched:
            self._X = self._X @ F.T
            P = F @ self._P @ F.T + Q
            self._P = 0.5 * (P + np.swapaxes(P, 1, 2))
            return
        for f in self._filters:
            if F is self.F:
                f.predict()
            else:
                try:
                    f.predict(F=F, Q=Q)  # type: ignore[call-arg]
                except TypeError:
                    raise ValueError(
                        f"time: an interval of {dt} differs from dt = {self.dt}; the filter "
                        f"{type(f).__name__} cannot change its model per step"
                    ) from None
        self._pull()

    def _pull(self) -> None:
        """Copy the per-track filters' estimates into the stacked arrays."""
        if self._filters:
            self._X = np.stack([np.asarray(f.x, dtype=np.float64) for f in self._filters])
            self._P = np.stack([np.asarray(f.P, dtype=np.float64) for f in self._filters])

    def _noise(self, rows: NDArray[np.int64] | slice = slice(None)) -> FloatArray:
        """Measurement covariances ``R_i`` (n, 2, 2) of tracks ``rows`` (default: all):
        ``diag(max(σ_z, sigma_z_rel · size)²)`` (module docstring); the (2, 2) ``R``
        itself, which broadcasts, when ``sigma_z_rel`` is 0."""
        if self.sigma_z_rel == 0.0:
            return self.R
        R = np.zeros((self._X[rows].shape[0], _DIM, _DIM))
        idx = np.arange(_DIM)
        R[:, idx, idx] = np.maximum(self.sigma_z, self.sigma_z_rel * self._size[rows]) ** 2
        return R

    def _innovation_covariance(self) -> FloatArray:
        """``S_i = H P_i Hᵀ + R_i`` (T, 2, 2) of the predicted tracks, computed once per
        scan: the gate (:meth:`_associate`, once per cascade group) and the occlusion
        stage share it."""
        if self._S is None:
            S = self.H @ self._P @ self.H.T + self._noise()
            self._S = 0.5 * (S + np.swapaxes(S, 1, 2))
        return self._S

    def _cascade(
        self,
        z: FloatArray,
        sizes: FloatArray | None,
        box_sizes: FloatArray | None = None,
        edges: NDArray[np.bool_] | None = None,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
        """The matching cascade (``confirmed_first``): the gate and the overlap stage for
        the confirmed tracks, then both for the tentative tracks on the detections left
        (``sizes``: None without the overlap stage; ``box_sizes``, ``edges``: see
        :meth:`_associate`). Returns the gate's (rows, detections) and the overlap
        stage's."""
        empty = np.empty(0, np.int64)
        rows, cols, r2, c2 = [empty], [empty], [empty], [empty]
        free = np.ones(z.shape[0], bool)
        for group, by_edges in ((self._confirmed.copy(), edges), (~self._confirmed, None)):
            r, c = self._associate(z, group, free, sizes=box_sizes, edges=by_edges)
            free[c] = False
            rows.append(r)
            cols.append(c)
            if sizes is not None:
                taken = np.concatenate(rows + r2)
                ro, co = self._overlap_pairs(taken, np.flatnonzero(~free), z, sizes, group)
                free[co] = False
                r2.append(ro)
                c2.append(co)
        return tuple(np.concatenate(a) for a in (rows, cols, r2, c2))  # type: ignore[return-value]

    def _associate(
        self,
        z: FloatArray,
        tracks: NDArray[np.bool_] | None = None,
        dets: NDArray[np.bool_] | None = None,
        *,
        sizes: FloatArray | None = None,
        edges: NDArray[np.bool_] | None = None,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Mahalanobis gate and GNN assignment; returns (track rows, detection indices),
        among the ``tracks`` and ``dets`` marked True (default: all). A track marked in
        ``edges`` (``occlusion``) is gated on every detection with the centre it would
        be measured by (:meth:`_anchor`, box ``sizes``): of two ships with one centre,
        each takes the box of its own size. With box ``sizes`` a box over
        :data:`_RESTART_GROWTH` times the track's area, or under its share, is not
        gated: it is another object or a speck of this one (a track on sun glitter,
        its box 30 times a small boat's, took the boat's box when it coasted over it).

        Candidate pairs come from a sort-and-sweep prefilter: ``d² <= gamma`` implies
        ``|y_x|, |y_y| <= sqrt(gamma · tr S)``, so only detections within that box of a
        track's predicted position (found by ``searchsorted`` on the x-sorted detections)
        get their exact d². The work grows with the pairs near each other, not with
        tracks × detections.
        """
        empty = np.empty(0, np.int64)
        T, D = self.n_tracks, z.shape[0]
        if T == 0 or D == 0:
            return empty, empty
        S = self._innovation_covariance()
        a, b, d = S[:, 0, 0], S[:, 0, 1], S[:, 1, 1]
        det = a * d - b * b
        if np.any(det <= 0.0):
            raise np.linalg.LinAlgError(
                "MultiTargetTracker: an innovation covariance H P Hᵀ + R is not positive "
                "definite; check sigma_z and the filter's covariance"
            )
        pred = self._X @ self.H.T  # (T, 2) predicted positions
        radius = np.sqrt(self.gate * (a + d))
        order = np.argsort(z[:, 0], kind="stable")
        zx = z[order, 0]
        lo = np.searchsorted(zx, pred[:, 0] - radius, side="left")
        hi = np.searchsorted(zx, pred[:, 0] + radius, side="right")
        counts = hi - lo
        total = int(counts.sum())
        if total == 0 and edges is None:
            return empty, empty
        rows = np.repeat(np.arange(T), counts)
        starts = np.repeat(lo - (np.cumsum(counts) - counts), counts)
        cols = order[starts + np.arange(total)]
        y = z[cols] - pred[rows]
        near = np.abs(y[:, 1]) <= radius[rows]
        rows, cols, y = rows[near], cols[near], y[near]
        if edges is not None and sizes is not None:  # these tracks: every detection
            ct = np.flatnonzero(edges)
            rest = ~edges[rows]
            cr, cc = np.repeat(ct, D), np.tile(np.arange(D), ct.size)
            za, free = self._anchor(cr, z[cc], sizes[cc])
            self._anchored = (ct, za.reshape(ct.size, D, _DIM), free.reshape(ct.size, D, _DIM))
            told = np.all(np.isfinite(za), axis=1)
            cr, cc, za = cr[told], cc[told], za[told]
            rows = np.concatenate([rows[rest], cr])
            cols = np.concatenate([cols[rest], cc])
            y = np.concatenate([y[rest], za - pred[cr]])
        # d² with the closed-form inverse of the 2 x 2 innovation covariances
        d2, detr = _mahalanobis2(S[rows], y)
        gated = d2 <= self.gate
        if sizes is not None:  # a box of another scale is another object (or a speck of it)
            area_t, area_d = np.prod(self._size[rows], axis=1), np.prod(sizes[cols], axis=1)
            gated &= _same_scale(area_t, area_d) | (area_t <= 0.0) | (area_d <= 0.0)
        if tracks is not None:
            gated &= tracks[rows]
        if dets is not None:
            gated &= dets[cols]
        rows, cols = rows[gated], cols[gated]
        return _assign_pairs(rows, cols, d2[gated] + np.log(detr[gated]))

    def _overlap_pairs(
        self,
        rows: NDArray[np.int64],
        cols: NDArray[np.int64],
        z: FloatArray,
        sizes: FloatArray,
        tracks: NDArray[np.bool_] | None = None,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Second stage (``overlap_gate``): unpaired tracks and detections whose boxes
        overlap by at least the gate (intersection over the smaller area), greedily by
        overlap (with ``confirmed_first``, the track with the most detections first),
        among the ``tracks`` marked True (default: all). Track boxes are the predicted
        centres with the smoothed sizes. Not paired: a box over ten times the track's
        area (:data:`_RESTART_GROWTH`), and for a confirmed track a box whose bottom
        edge (the water line) is farther than ``max(σ_z, 15 %)`` of the track's height
        from the predicted one."""
        empty = np.empty(0, np.int64)
        pool = np.arange(self.n_tracks) if tracks is None else np.flatnonzero(tracks)
        taken = np.zeros(self.n_tracks, bool)
        taken[rows] = True
        free_t = pool[~taken[pool]]
        used = np.zeros(z.shape[0], bool)
        used[cols] = True
        free_d = np.flatnonzero(~used)
        if free_t.size == 0 or free_d.size == 0:
            return empty, empty
        dc, ds = z[free_d], sizes[free_d]
        ov = self._overlaps(free_t, dc, ds)
        # a box many times larger than the track's is no re-segmentation of its ship but
        # ships merged into one box (one passing in front of another), and one many
        # times smaller a speck of it or another object inside its box: no restart
        area_t, area_d = np.prod(self._size[free_t], axis=1)[:, None], np.prod(ds, axis=1)[None]
        ov[~_same_scale(area_t, area_d)] = 0.0
        # a confirmed ship's water line (its box's bottom edge) stays where it was: a box
        # whose bottom is elsewhere is a piece of it above the water (a superstructure,
        # a mast) or holds something below it (glint, a wake), not its re-segmentation
        bottom_t = self._X[free_t, 1] + 0.5 * self._size[free_t, 1]
        tol = self._tolerance(self._size[free_t])[:, 1]
        moved = np.abs(dc[None, :, 1] + 0.5 * ds[None, :, 1] - bottom_t[:, None]) > tol[:, None]
        ov[moved & self._confirmed[free_t][:, None]] = 0.0
        if self.confirmed_first:  # pairs in the gate: most detections first, then overlap
            hits = np.where(ov >= self.overlap_gate, self._hits[free_t][:, None], -1)
            order = np.lexsort((-ov.ravel(), -hits.ravel()))
        else:
            order = np.argsort(-ov, axis=None, kind="stable")
        out_r, out_c = [], []
        for flat in order:
            i, j = divmod(int(flat), free_d.size)
            if ov[i, j] < self.overlap_gate:
                break
            if free_t[i] in out_r or free_d[j] in out_c:
                continue
            out_r.append(int(free_t[i]))
            out_c.append(int(free_d[j]))
        return np.array(out_r, np.int64), np.array(out_c, np.int64)

    def _overlaps(
        self, tracks: NDArray[np.int64], dc: FloatArray, ds: FloatArray, of_track: bool = False
    ) -> FloatArray:
        """Overlap (intersection over the smaller area; ``of_track``: over the track's
        area) of the predicted boxes of ``tracks`` (predicted centres, smoothed sizes)
        with the boxes ``dc`` ± ``ds``/2."""
        tc, ts = self._X[tracks, :_DIM], self._size[tracks]
        lo = np.maximum(tc[:, None] - 0.5 * ts[:, None], dc[None] - 0.5 * ds[None])
        hi = np.minimum(tc[:, None] + 0.5 * ts[:, None], dc[None] + 0.5 * ds[None])
        inter = np.prod(np.clip(hi - lo, 0.0, None), axis=2)
        area = np.prod(ts, axis=1)[:, None]
        smaller = area if of_track else np.minimum(area, np.prod(ds, axis=1)[None])
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(smaller > 0.0, inter / smaller, 0.0)

    def _iou(self, tracks: NDArray[np.int64], dc: FloatArray, ds: FloatArray) -> FloatArray:
        """Intersection over union of the predicted boxes of ``tracks`` (predicted
        centres, smoothed sizes) with the boxes ``dc`` ± ``ds``/2, (k, D); 0 where
        undefined (an empty box, a NaN row)."""
        area = np.prod(self._size[tracks], axis=1)[:, None]
        inter = self._overlaps(tracks, dc, ds, of_track=True) * area
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.nan_to_num(inter / (area + np.prod(ds, axis=1)[None] - inter))

    def _own_boxes(self, z: FloatArray, sizes: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Per track, the box of this scan that is its own — the one with the largest
        IoU with its predicted box, if that is 1/2 or more — as centre and size [px or
        m] (NaN where none is)."""
        c = np.full((self.n_tracks, _DIM), np.nan)
        s = np.full((self.n_tracks, _DIM), np.nan)
        if self.n_tracks == 0 or z.shape[0] == 0:
            return c, s
        iou = self._iou(np.arange(self.n_tracks), z, sizes)
        best = np.argmax(iou, axis=1)
        ok = iou[np.arange(self.n_tracks), best] >= 0.5
        c[ok], s[ok] = z[best[ok]], sizes[best[ok]]
        return c, s

    def _tolerance(self, size: FloatArray) -> FloatArray:
        """How near [px or m] a box edge must come to a span or an extent to count as
        on it, per axis of ``size``: ``max(σ_z, 15 %)`` of the size (:data:`_EDGE_TOL`)."""
        return np.maximum(self.sigma_z, _EDGE_TOL * size)

    def _contact(
        self, dc: FloatArray, ds: FloatArray
    ) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
        """Confirmed tracks that may occlude each other: their predicted boxes (predicted
        centre, smoothed size), each widened by its tolerance ``max(σ_z, 15 %)`` of its
        size, overlap; and the detections (boxes ``dc`` ± ``ds``/2) that cover at least
        a third of two such tracks (one box of both ships: it starts no track)."""
        out = np.zeros(self.n_tracks, bool)
        merged = np.zeros(dc.shape[0], bool)
        idx = np.flatnonzero(self._confirmed)
        if idx.size < 2:
            return out, merged
        c, s = self._X[idx, :_DIM], self._size[idx]
        half = 0.5 * s + self._tolerance(s)
        lo, hi = c - half, c + half
        inter = np.minimum(hi[:, None], hi[None]) - np.maximum(lo[:, None], lo[None])
        touch = np.all(inter > 0.0, axis=2)
        np.fill_diagonal(touch, False)
        out[idx] = touch.any(axis=1)
        if dc.shape[0] and out.any():
            covered = self._overlaps(idx, dc, ds, of_track=True) >= 1.0 / 3.0  # (k, D)
            # detection d covers tracks a and b that touch
            pair = covered[:, None, :] & covered[None, :, :] & touch[:, :, None]
            merged = pair.any(axis=(0, 1))
        return out, merged

    def _anchor(
        self, rows: NDArray[np.int64], dc: FloatArray, ds: FloatArray
    ) -> tuple[FloatArray, NDArray[np.bool_]]:
        """Centres of tracks ``rows`` measured from boxes ``dc`` ± ``ds``/2, per axis, and
        the axes on which the box gives the track's size too.

        An edge of the box is *blocked* where it lies (within ``max(σ_z, 15 %)`` of the
        track's size) inside the predicted span of another confirmed track that shares
        the track's span on the other axis and has at least a tenth of its area
        (:data:`_RESTART_GROWTH`; a wake or glint speck beside a ship blocks nothing):
        it may be that ship's outline or the seam between two merged ships — unless the
        box spans the whole of that ship's span (on both axes, within the tolerance), that
        ship has a box of its own in this scan (:meth:`_own_boxes`) and its water line is
        not above the track's: then the box is no merge of the two but the track seen
        around a ship in front of it, and its ends are its own — except for a track with
        :data:`_SETTLED_HITS` detections whose box is wider than its remembered width by
        more than the tolerance: its width is known, and the end the box shares with
        the ship in front is that ship's (the track's own end hidden behind it); the top edge
        of a track with :data:`_SETTLED_HITS` detections is blocked too where the box's
        bottom is on the track's predicted one (within the tolerance) and its top lies
        above the track's by more than twice the tolerance (something behind the
        ship: a ship beyond it, a coast; its height is known by then). A box bottom
        below the bottom of a ship behind the track (that ship's bottom above the
        track's predicted one) and nearer the track's predicted bottom than that ship's
        is not blocked by it: a union box's bottom is its lowest, the track's water
        line. With both
        edges free the box is the track's own: its centre and size are measured. With
        one free edge the centre is that edge moved inwards by half the track's
        remembered size, unless the blocked edge stops at the near side of every ship
        blocking it, each in front (its water line lower than the track's by more than
        the tolerance; the box reaching at most σ_z into its span) and the box is wider
        than the remembered width: the ship goes on behind them, so it is at least the
        box, which is measured as with both edges free. With none, the box's centre
        where its extent agrees with that size; on the vertical axis, else the bottom
        edge (the water line) if it agrees with the predicted one and no other track's
        predicted bottom over the track's columns is lower by more than σ_z / 2 (a
        nearer ship, whose water line the box's bottom may be); else NaN: the box does
        not tell where the track is (two ships crossing inside one box), and the pair
        is not used.

        Hand-written: trackers of merged blobs (e.g. Haritaoglu et al., W4, 2000)
        measure an occluded object by its visible outer edge; no library offers it for
        a Kalman box tracker."""
        c, s = self._X[rows, :_DIM], self._size[rows]
        lo, hi = dc - 0.5 * ds, dc + 0.5 * ds
        tol = self._tolerance(s)
        blocked_lo = np.zeros(lo.shape, bool)
        blocked_hi = np.zeros(hi.shape, bool)
        bound_lo = np.zeros(lo.shape, bool)  # the box is a lower bound of the ship's extent
        bound_hi = np.zeros(hi.shape, bool)
        nearest = np.ones(rows.size, bool)  # no ship below the track's bottom over its span
        others = np.flatnonzero(self._confirmed)
        if others.size:
            oc, oh = self._X[others, :_DIM], 0.5 * self._size[others]
            olo, ohi = (oc - oh)[None], (oc + oh)[None]  # (1, k, 2)
            tlo, thi = (c - 0.5 * s)[:, None], (c + 0.5 * s)[:, None]  # (P, 1, 2)
            shares = (np.minimum(thi, ohi) - np.maximum(tlo, olo) > 0.0)[..., ::-1]
            shares &= others[None, :, None] != rows[:, None, None]
            t = tol[:, None]
            area = np.prod(s, axis=1)[:, None]
            oarea = np.prod(self._size[others], axis=1)[None]
            shares &= (oarea * _RESTART_GROWTH > area)[..., None]  # not a speck on a ship
            on_lo = shares & (olo - t <= lo[:, None]) & (lo[:, None] <= ohi + t)
            on_hi = shares & (olo - t <= hi[:, None]) & (hi[:, None] <= ohi + t)
            # a box bottom below the water line of a ship behind the track (its bottom
            # above the track's), nearer the track's predicted bottom than that ship's:
            # the track's own water line (a union box's bottom is its lowest)
            hy, oy, ty = hi[:, None, 1], ohi[..., 1], thi[..., 1]
            on_hi[..., 1] &= ~((oy < ty) & (hy > oy) & (hy - oy > np.abs(hy - ty)))
            if self._own is not None:
                # a box around the whole of a ship not behind the track (its water line
                # not above the track's) that has another box of its own this scan is no
                # merge of the two: the track is seen around that ship, its ends are its own
                own_c, own_s = self._own[0][others][None], self._own[1][others][None]
                same = (np.abs(own_c - dc[:, None]) < 0.5) & (np.abs(own_s - ds[:, None]) < 0.5)
                apart = np.all(np.isfinite(own_c), axis=2) & ~np.all(same, axis=2)
                around = np.all((lo[:, None] <= olo + t) & (hi[:, None] >= ohi - t), axis=2)
                around &= apart & (ohi[..., 1] >= thi[..., 1])
                # a settled track whose box is wider than its width by more than the
                # tolerance: the end that the box shares with the ship in front may be
                # that ship's (the track's own end hidden behind it)
                wider = (self._hits[rows] >= _SETTLED_HITS) & (ds[:, 0] - s[:, 0] > tol[:, 0])
                around &= ~wider[:, None]
                on_lo[..., 0] &= ~around
                on_hi[..., 0] &= ~around
            blocked_lo, blocked_hi = on_lo.any(axis=1), on_hi.any(axis=1)
            # an edge that every span blocking it blocks from in front (its water line
            # lower by more than the tolerance) at its near side (the box reaching at
            # most σ_z into it): the ship goes on behind the other, it is at least the box
            front = (ohi[..., 1] > thi[..., 1] + t[..., 1])[..., None]  # (P, k, 1)
            into_lo = ohi - lo[:, None] > self.sigma_z
            into_hi = hi[:, None] - olo > self.sigma_z
            bound_lo = blocked_lo & ~np.any(on_lo & (~front | into_lo), 1)
            bound_hi = blocked_hi & ~np.any(on_hi & (~front | into_hi), 1)
            lower = ohi[..., 1] > thi[..., 1] + 0.5 * self.sigma_z
            nearest = ~np.any(shares[..., 1] & lower, axis=1)
        # a settled track whose box keeps its water line but rises above its top holds
        # something behind the ship (a ship beyond it, a coast, a crane): its top is set
        # aside as if another track's span blocked it
        top, bottom_t = c[:, 1] - 0.5 * s[:, 1], c[:, 1] + 0.5 * s[:, 1]
        blocked_lo[:, 1] |= (
            (self._hits[rows] >= _SETTLED_HITS)
            & (np.abs(hi[:, 1] - bottom_t) <= tol[:, 1])
            & (top - lo[:, 1] > 2.0 * tol[:, 1])
        )
        bottom = hi[:, 1] - 0.5 * s[:, 1]
        edge = np.full(dc.shape, np.nan)
        mine = nearest & (np.abs(bottom - c[:, 1]) <= tol[:, 1])
        edge[:, 1] = np.where(mine, bottom, np.nan)
        stuck = np.where(np.abs(ds - s) <= tol, dc, edge)
        # one free edge, the other bounding, and the box longer than the remembered
        # width: a ship coming out from behind another is measured by its box
        longer = (ds > s) & ((~blocked_lo & bound_hi) | (~blocked_hi & bound_lo))
        longer[:, 1] = False  # heights: the water line rules (below)
        free = (~blocked_lo & ~blocked_hi) | longer
        centre = np.where(
            free,
            dc,
            np.where(~blocked_lo, lo + 0.5 * s, np.where(~blocked_hi, hi - 0.5 * s, stuck)),
        )
        return centre, free

    def _anchor_pairs(
        self, rows: NDArray[np.int64], cols: NDArray[np.int64], z: FloatArray, sizes: FloatArray
    ) -> tuple[FloatArray, NDArray[np.bool_]]:
        """:meth:`_anchor` of the pairs (track ``rows``, detection ``cols``) for confirmed
        tracks — from the gate's computation of this scan where it made it (the same
        inputs, the same result) — and the box centre with both axes free for the
        others."""
        zu, free = z[cols].copy(), np.ones((rows.size, _DIM), bool)
        mine = self._confirmed[rows]
        if self._anchored is not None and rows.size:
            ct, za, fr = self._anchored
            pos = np.minimum(np.searchsorted(ct, rows), ct.size - 1)
            hit = mine & (ct[pos] == rows)
            zu[hit], free[hit] = za[pos[hit], cols[hit]], fr[pos[hit], cols[hit]]
            mine &= ~hit
        if mine.any():
            zu[mine], free[mine] = self._anchor(rows[mine], z[cols[mine]], sizes[cols[mine]])
        return zu, free

    def _occlusion(
        self,
        rows: NDArray[np.int64],
        cols: NDArray[np.int64],
        r2: NDArray[np.int64],
        c2: NDArray[np.int64],
        z: FloatArray,
        sizes: FloatArray,
    ) -> tuple[
        NDArray[np.int64],
        NDArray[np.int64],
        NDArray[np.int64],
        NDArray[np.int64],
        FloatArray,
        NDArray[np.bool_],
        NDArray[np.int64],
    ]:
        """Occlusion handling (``occlusion``, module docstring step 4a) of the gate's
        pairs ``rows, cols`` and the overlap stage's ``r2, c2``: returns the pairs to
        update, the overlap pairs still to restart, the measured centres (confirmed
        tracks: :meth:`_anchor`), the axes whose size the detection may update, and the
        detections that are boxes of several tracks (:meth:`_contact`)."""
        contact, merged = self._contact(z, sizes)
        # a track in contact is not restarted on a re-segmented box (it coasts): the box
        # may hold the other ship
        keep = ~contact[r2]
        r2, c2 = r2[keep], c2[keep]
        # a track in contact left without a detection takes its edge of a box that
        # covers it and reaches beyond the track that took the box (ships merged into
        # one box), if that edge is inside its gate
        idle = contact.copy()
        idle[rows] = False
        idle[r2] = False
        t = np.flatnonzero(idle)
        if t.size and z.shape[0]:
            ov = self._overlaps(t, z, sizes, of_track=True)
            if rows.size:
                taker = rows  # a box within the tolerance of its taker's is not shared
                tol = self._tolerance(self._size[taker])
                lo = self._X[taker, :_DIM] - 0.5 * self._size[taker] - tol
                hi = self._X[taker, :_DIM] + 0.5 * self._size[taker] + tol
                dc, dh = z[cols], 0.5 * sizes[cols]
                inside = np.all((dc - dh >= lo) & (dc + dh <= hi), axis=1)
                ov[:, cols[inside]] = 0.0
            best = np.argmax(ov, axis=1)
            ok = ov[np.arange(t.size), best] >= (self.overlap_gate or 0.5)
            t, best = t[ok], best[ok]
            if t.size:
                za, _ = self._anchor_pairs(t, best, z, sizes)
                y = za - self._X[t] @ self.H.T
                d2, _ = _mahalanobis2(self._innovation_covariance()[t], y)
                inside = d2 <= self.gate  # False for NaN: the box does not tell
                rows = np.concatenate([rows, t[inside]])
                cols = np.concatenate([cols, best[inside]])
        zu, free = self._anchor_pairs(rows, cols, z, sizes)
        told = np.all(np.isfinite(zu), axis=1)  # a box that does not tell: a miss
        return rows[told], cols[told], r2, c2, zu[told], free[told], np.flatnonzero(merged)

    def _restart(self, rows: NDArray[np.int64], z: FloatArray, sizes: FloatArray) -> None:
        """Restart tracks ``rows`` at detections ``z`` with their velocity and id kept:
        position σ_z, velocity covariance as it was (``overlap_gate``)."""
        x0 = self._X[rows].copy()
        x0[:, :_DIM] = z
        P0 = np.broadcast_to(self.P0, (rows.size, _N, _N)).copy()
        P0[:, _DIM:, _DIM:] = self._P[rows][:, _DIM:, _DIM:]
        self._X[rows] = x0
        self._P[rows] = P0
        self._size[rows] = sizes
        if self._factory is not None:
            for i, r in enumerate(rows):
                self._filters[int(r)] = self._factory(x0[i].copy(), P0[i].copy())
            self._pull()

    def _update(self, rows: NDArray[np.int64], z: FloatArray) -> None:
        """Kalman update of the assigned tracks (Joseph form), predict-only for the rest."""
        if self.batched:
            if rows.size == 0:
                return
            H, R = self.H, self._noise(rows)
            x = self._X[rows]
            P = self._P[rows]
            PHt = P @ H.T  # (a, 4, 2)
            S = H @ PHt + R
            K = np.linalg.solve(S, np.swapaxes(PHt, 1, 2)).transpose(0, 2, 1)  # P Hᵀ S⁻¹
            innov = z - x @ H.T
            self._X[rows] = x + np.einsum("aij,aj->ai", K, innov)
            A = np.eye(_N) - K @ H
            P = A @ P @ np.swapaxes(A, 1, 2) + K @ R @ np.swapaxes(K, 1, 2)
            self._P[rows] = 0.5 * (P + np.swapaxes(P, 1, 2))
            return
        zz: list[FloatArray | None] = [None] * len(self._filters)
        for i, r in enumerate(rows):
            zz[int(r)] = z[i]
        Rs = self._noise() if self.sigma_z_rel > 0.0 else None
        for k, (f, zi) in enumerate(zip(self._filters, zz, strict=True)):
            if Rs is None or zi is None:
                f.update(zi)
            else:
                f.update(zi, R=Rs[k])
        self._pull()

    def _compress(self, keep: NDArray[np.bool_]) -> None:
        if keep.all():
            return
        self._X = self._X[keep]
        self._P = self._P[keep]
        self._ids = self._ids[keep]
        self._history = self._history[keep]
        self._age = self._age[keep]
        self._hits = self._hits[keep]
        self._misses = self._misses[keep]
        self._unseen = self._unseen[keep]
        self._split = self._split[keep]
        self._confirmed = self._confirmed[keep]
        self._size = self._size[keep]
        if self._filters:
            self._filters = [f for f, k in zip(self._filters, keep, strict=True) if k]

    def _unite_pieces(
        self, centres: FloatArray, sizes: FloatArray, stale: NDArray[np.bool_]
    ) -> tuple[FloatArray, FloatArray, NDArray[np.bool_], NDArray[np.int64]]:
        """Step 1a (module docstring): a ship boxed in pieces in this scan is one box.

        Per confirmed track, the boxes (``centres`` ± ``sizes``/2) of this scan that lie
        wholly within its predicted box (predicted centre, smoothed size) widened by its
        tolerance ``max(σ_z, 15 %)`` on every side and within no other track's, and
        whose bottoms lie within the tolerance of its predicted water line (a hull's
        pieces; a boat seen beyond the ship over its deck is none): if two or more,
        none as wide as the track less its tolerance (a box of the whole ship: the
        others are something else), and their union no larger than the track plus its
        tolerance on either axis, the largest of them becomes their union (stale only
        if all were) and the others are dropped (NaN). So the track measures its whole
        ship, and a piece starts no track of its own, which step 4b would merge again
        only after it had taken an end of the ship's box in ten scans in a row (the
        crossing case, seed 0: a 15 × 5 px boat boxed in two pieces now and then in
        frames 161–172 kept a track 4 px too narrow for 30 frames). A box that a
        tentative track follows (IoU ≥ 1/2 with its predicted box) is none of the
        pieces, and a track's boxes are united in :data:`_SPLIT_SCANS` scans in a row
        at most: a track born on a box of two ships side by side (meeting) would
        otherwise never let the second ship start its own. Returns the centres, sizes
        and stale flags (copies) and the indices of the united boxes.

        Hand-written: a rule of this tracker's occlusion handling, which no library has."""
        ok = np.all(np.isfinite(centres), axis=1) & np.all(np.isfinite(sizes), axis=1)
        idx = np.flatnonzero(self._confirmed & np.all(self._size > 0.0, axis=1))
        if idx.size == 0 or np.count_nonzero(ok) < 2:
            self._split[:] = 0
            return centres, sizes, stale, np.empty(0, np.int64)
        c, s = self._X[idx, :_DIM], self._size[idx]
        tol = self._tolerance(s)
        lo, hi = c - 0.5 * s - tol, c + 0.5 * s + tol  # (k, 2) widened predicted boxes
        d_lo, d_hi = centres - 0.5 * sizes, centres + 0.5 * sizes  # (D, 2)
        inside = np.all((d_lo[None] >= lo[:, None]) & (d_hi[None] <= hi[:, None]), axis=2)
        inside &= ok[None] & (np.count_nonzero(inside, axis=0) == 1)[None]  # one track's
        young = np.flatnonzero(~self._confirmed)
        if young.size:  # a box that a tentative track follows (IoU >= 1/2) is that track's
            inside &= ~np.any(self._iou(young, centres, sizes) >= 0.5, axis=0)[None]
        # a piece of the hull keeps the ship's water line (its bottom within tolerance)
        bottom = np.abs(d_hi[None, :, 1] - (c[:, None, 1] + 0.5 * s[:, None, 1]))
        inside &= bottom <= tol[:, None, 1]
        centres, sizes, stale = centres.copy(), sizes.copy(), stale.copy()
        united = []
        split = np.zeros(self.n_tracks, bool)
        for k in np.flatnonzero(np.count_nonzero(inside, axis=1) >= 2):
            pieces = np.flatnonzero(inside[k])
            if np.any(sizes[pieces, 0] >= s[k, 0] - tol[k, 0]):
                continue  # one of them is the whole ship
            u_lo, u_hi = d_lo[pieces].min(axis=0), d_hi[pieces].max(axis=0)
            if np.any(u_hi - u_lo > s[k] + tol[k]):
                continue
            split[idx[k]] = True
            if self._split[idx[k]] >= _SPLIT_SCANS:
                continue  # pieces that last: two ships, each to start its own track
            big = int(pieces[np.argmax(np.prod(sizes[pieces], axis=1))])
            centres[big], sizes[big] = 0.5 * (u_lo + u_hi), u_hi - u_lo
            stale[big] = bool(stale[pieces].all())
            rest = pieces[pieces != big]
            centres[rest] = np.nan
            united.append(big)
        self._split = np.where(split, self._split + 1, 0)
        return centres, sizes, stale, np.asarray(united, np.int64)

    def _pieces_of_one(
        self,
        detection: NDArray[np.int64],
        anchored: NDArray[np.bool_],
        centres: FloatArray,
        sizes: FloatArray,
    ) -> NDArray[np.bool_]:
        """Step 4b (module docstring): the tracks to delete because they and another
        are one ship's pieces. Two confirmed tracks measured by one box (``detection``,
        per track the index into ``centres``/``sizes`` of this scan) through their free
        edges (``anchored``) in :data:`_PIECES_SCANS` consecutive scans, while the box's
        width stays within σ_z: two ships in one box drift apart or together (a ship
        coming out from behind another, crossing, overtaking), a ship boxed in pieces
        for a few frames, whose pieces started a second track, does not — the two
        tracks take the ends of its one box and keep the pieces' widths. The track with
        more detections (the older on a tie) is restarted on the box (its id and
        velocity kept, :meth:`_restart`); the other is returned for deletion.

        Hand-written: a rule of this tracker's occlusion handling, which no library has."""
        dead = np.zeros(self.n_tracks, bool)
        runs: dict[tuple[int, int], tuple[int, float, float]] = {}  # this scan's pairs
        idx = np.flatnonzero((detection >= 0) & anchored & self._confirmed)
        for d in np.unique(detection[idx]):
            pair = idx[detection[idx] == d]
            if pair.size != 2:
                continue
            a, b = int(pair[0]), int(pair[1])
            key = (int(min(self._ids[a], self._ids[b])), int(max(self._ids[a], self._ids[b])))
            w = float(sizes[d, 0])
            run, w_lo, w_hi = self._pieces.get(key, (0, w, w))  # a run goes on or starts
            run, w_lo, w_hi = run + 1, min(w_lo, w), max(w_hi, w)
            if run >= _PIECES_SCANS and w_hi - w_lo <= self.sigma_z:
                a_first = (self._hits[a], -self._ids[a]) >= (self._hits[b], -self._ids[b])
                keep, other = (a, b) if a_first else (b, a)
                self._restart(np.array([keep]), centres[d][None], sizes[d][None])
                dead[other] = True
            else:
                runs[key] = (run, w_lo, w_hi)
        self._pieces = runs  # a pair not sharing a box this scan ends its run
        return dead

    def _birth(self, z: FloatArray, sizes: FloatArray | None) -> None:
        """Tentative tracks ``x0 = [z, 0, 0]``, ``P0 = diag(σ_z², σ_z², σ_v0², σ_v0²)``."""
        k = z.shape[0]
        if k == 0:
            return
        x0 = np.zeros((k, _N))
        x0[:, :_DIM] = z
        P0 = np.broadcast_to(self.P0, (k, _N, _N))
        if self._factory is not None:
            self._filters.extend(self._factory(x0[i].copy(), self.P0.copy()) for i in range(k))
        self._X = np.concatenate([self._X, x0])
        self._P = np.concatenate([self._P, P0])
        self._ids = np.concatenate([self._ids, np.arange(self._next_id, self._next_id + k)])
        self._next_id += k
        ones = np.ones(k, np.int64)
        self._history = np.concatenate([self._history, ones])
        self._age = np.concatenate([self._age, ones])
        self._hits = np.concatenate([self._hits, ones])
        self._misses = np.concatenate([self._misses, np.zeros(k, np.int64)])
        self._unseen = np.concatenate([self._unseen, np.zeros(k, np.int64)])
        self._split = np.concatenate([self._split, np.zeros(k, np.int64)])
        self._confirmed = np.concatenate([self._confirmed, np.full(k, self.confirm_m <= 1)])
        size = np.zeros((k, 2)) if sizes is None else sizes
        self._size = np.concatenate([self._size, size])

    def _report(
        self,
        t: float,
        detection: NDArray[np.int64],
        restarted: NDArray[np.bool_] | None = None,
        anchored: NDArray[np.bool_] | None = None,
    ) -> TrackStates:
        boxes = None
        if self._boxes:
            boxes = np.concatenate([self._X[:, :_DIM] - 0.5 * self._size, self._size], axis=1)
        return TrackStates(
            time=t,
            ids=self._ids.copy(),
            states=self._X.copy(),
            covariances=self._P.copy(),
            confirmed=self._confirmed.copy(),
            misses=self._misses.copy(),
            hits=self._hits.copy(),
            detection=detection,
            boxes=boxes,
            restarted=restarted,
            anchored=anchored,
        )


def _probe(factory: FilterFactory, P0: FloatArray) -> None:
    """Build one filter now, so that bad ``filter_options`` fail at construction."""
    try:
        factory(np.zeros(_N), P0.copy())
    except (TypeError, ValueError) as exc:
        raise ValueError(f"filter_options: the filter rejects them: {exc}") from exc


def _popcount(v: NDArray[np.int64]) -> NDArray[np.int64]:
    """Number of set bits of each (non-negative, < 2**62) integer."""
    return np.bitwise_count(v).astype(np.int64)


def tracks_to_mot(
    history: Sequence[TrackStates],
    *,
    frames: ArrayLike | None = None,
    confirmed_only: bool = True,
    boxes: bool | None = None,
) -> FloatArray:
    """Rows ``(frame, id, x, y, w, h)`` (boxes) or ``(frame, id, x, y)`` (points) in MOT order.

    Args:
        history: the tracker's outputs, one per scan.
        frames: frame number of each scan (default 0, 1, 2, …).
        confirmed_only: only confirmed tracks (default), else tentative ones too.
        boxes: write boxes (default: when the tracker tracked boxes).

    Returns:
        (N, 6) or (N, 4) float array, sorted by frame then id; the input format of
        :func:`seawatch.metrics.mot_metrics`.
    """
    fr = np.arange(len(history)) if frames is None else as_float_array("frames", frames, ndim=1)
    if fr.shape[0] != len(history):
        raise ValueError(f"frames: expected {len(history)} frame numbers, got {fr.shape[0]}")
    use_boxes = boxes if boxes is not None else any(h.boxes is not None for h in history if len(h))
    parts = []
    for f, h in zip(fr, history, strict=True):
        sel = h.confirmed_tracks() if confirmed_only else h
        if len(sel) == 0:
            continue
        if use_boxes:
            if sel.boxes is None:
                raise ValueError("boxes: the tracks hold points, not boxes")
            geom = sel.boxes
        else:
            geom = sel.positions
        parts.append(np.column_stack([np.full(len(sel), f), sel.ids, geom]))
    width = 6 if use_boxes else 4
    return np.concatenate(parts) if parts else np.empty((0, width))
