"""Association of camera tracks with AIS vessels in world coordinates (issue 7, ``--ais``).

An online associator: each :meth:`AisAssociator.update` receives the camera tracks of one
instant (positions in the local tangent plane, x North, y East [m], with covariances and
optionally velocities) and

1. **Samples the AIS vessels** at that time (:meth:`AisAssociator.vessels_at`). The knots
   (position and velocity at every report, in the tangent plane at ``(lat0, lon0)``) are
   those of :func:`seawatch.io.ais.interpolate_track`, computed once per vessel at
   construction; between two reports at most ``max_gap`` apart the position is that
   function's cubic Hermite curve and the velocity its linear blend of the knot
   velocities, evaluated here for all vessels at once (calling ``interpolate_track`` per
   vessel per frame costs about 0.3 s a frame on the Solent file's 84 vessels; the
   tests check that both give the same positions). Outside the reports, or inside a
   longer gap, a vessel is dead-reckoned from its nearest report with that report's
   velocity for at most ``max_extrapolation`` (30 s: two to ten missed class-A
   reports); farther away it is not available.
2. **Gates** every (track, vessel) pair (Bar-Shalom, Willett & Tian, *Tracking and Data
   Fusion*, 2011, §3.2): position innovation ``y = z_track − p_ais`` with covariance
   ``S = P_track + σ_ais² I``, ``σ_ais² = sigma_ais² + (age · sigma_ais_drift)²`` (a
   report ``age`` seconds old has drifted), and ``d² = yᵀ S⁻¹ y ≤ chi2.ppf(
   gate_probability, 2)`` and ``|y| ≤ gate_m``. When the track's velocity and the
   vessel's are both known, the velocity difference must pass the same kind of gate
   (course/speed gate) with ``S_v = P_v,track + sigma_ais_velocity² I``.
3. **Assigns** one-to-one by global nearest neighbour
   (:func:`seawatch.tracking.mtt.gnn_assign`, ``scipy.optimize.linear_sum_assignment``)
   with the negative log-likelihood cost ``d² + ln det S + d_v²`` (``d_v²`` replaced by
   its expectation 2 when a velocity is unknown), less ``continuity`` for the pair that
   matches the track's current label (a prior for the identity already established:
   two vessels passing close do not swap their tracks' assignments on a few noisy
   frames).
4. **Votes and labels** (rules chosen here; documented in :class:`AisAssociator`): a
   track gets the label MMSI ``m`` once it was assigned to ``m`` in ``min_frames``
   consecutive frames, or in at least ``min_frames`` frames that are at least
   ``majority`` of all its assignments; a label changes only when another vessel wins
   ``switch_frames`` consecutive frames (hysteresis); a label is never dropped for lack
   of matches (AIS gaps, detections lost).
5. **Visibility**: vessels for which ``in_view`` (a callable on their positions, e.g. a
   :class:`ViewWedge`) is true accumulate in-view time; those in view for at least
   ``unseen_after`` seconds that never became a track's label are *unseen*.

:meth:`AisAssociator.result` gives the labels (``matches``), the *dark* tracks (seen in
at least ``min_frames`` frames inside the AIS file's time span, never labelled) and the
*unseen* vessels, with per-pair statistics.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.stats import chi2

from seawatch._validation import FloatArray, as_float_array, covariance, in_range, integer, positive
from seawatch.io.ais import MAX_GAP, AisTable, interpolate_track, tracks
from seawatch.tracking.mtt import gnn_assign

__all__ = [
    "MAX_EXTRAPOLATION",
    "AisAssociation",
    "AisAssociator",
    "PairStats",
    "VesselStates",
    "ViewWedge",
    "in_view_wedge",
]

MAX_EXTRAPOLATION = 30.0
"""Longest dead reckoning of an AIS vessel beyond its reports [s]."""

ViewTest = Callable[[FloatArray, FloatArray], ArrayLike]
"""``in_view(north, east) -> bool array``: which positions [m] the camera should see."""


# ==========================================================================================
# the view test
# ==========================================================================================


def in_view_wedge(
    north: ArrayLike,
    east: ArrayLike,
    *,
    heading: float,
    hfov: float,
    max_range: float,
    min_range: float = 0.0,
    origin: tuple[float, float] = (0.0, 0.0),
) -> NDArray[np.bool_]:
    """Whether sea positions lie in a camera's horizontal view wedge.

    A point at bearing ``β = atan2(east − e0, north − n0)`` (clockwise from North) and
    horizontal distance ``r`` from the camera at ``origin = (n0, e0)`` is in view when
    ``|wrap(β − heading)| ≤ hfov / 2`` and ``min_range ≤ r ≤ max_range``. NaN positions
    are not in view.

    Args:
        north, east: positions [m] (arrays, broadcast).
        heading: azimuth of the optical axis [rad], clockwise from North.
        hfov: horizontal field of view [rad], in (0, 2π].
        max_range: farthest distance seen [m] (e.g. the detection range or the horizon).
        min_range: nearest distance seen [m] (e.g. where the sea leaves the image).
        origin: the camera's (north, east) [m].

    Returns:
        Boolean array of the broadcast shape.
    """
    n = as_float_array("north", north)
    e = as_float_array("east", east)
    h = in_range("heading", heading, -1e3, 1e3)
    fov = in_range("hfov", hfov, 0.0, 2.0 * math.pi, lo_open=True)
    r_max = positive("max_range", max_range)
    r_min = positive("min_range", min_range, allow_zero=True)
    if r_min > r_max:
        raise ValueError(f"min_range: expected <= max_range ({r_max:g} m), got {min_range!r}")
    n0, e0 = (float(v) for v in origin)
    if not (math.isfinite(n0) and math.isfinite(e0)):
        raise ValueError(f"origin: expected a finite (north, east) [m], got {origin!r}")
    dn, de = n - n0, e - e0
    r = np.hypot(dn, de)
    off = np.abs(np.mod(np.arctan2(de, dn) - h + math.pi, 2.0 * math.pi) - math.pi)
    with np.errstate(invalid="ignore"):
        return (off <= 0.5 * fov + 1e-12) & (r >= r_min) & (r <= r_max)


@dataclass(frozen=True)
class ViewWedge:
    """A camera's horizontal view wedge as an ``in_view`` callable (:func:`in_view_wedge`).

    Attributes:
        heading: azimuth of the optical axis [rad], clockwise from North.
        hfov: horizontal field of view [rad].
        max_range: farthest distance seen [m]. min_range: nearest [m].
        north, east: the camera's position in the tangent plane [m].
    """

    heading: float
    hfov: float
    max_range: float
    min_range: float = 0.0
    north: float = 0.0
    east: float = 0.0

    def __post_init__(self) -> None:
        in_view_wedge(
            0.0,
            0.0,
            heading=self.heading,
            hfov=self.hfov,
            max_range=self.max_range,
            min_range=self.min_range,
            origin=(self.north, self.east),
        )

    def __call__(self, north: ArrayLike, east: ArrayLike) -> NDArray[np.bool_]:
        return in_view_wedge(
            north,
            east,
            heading=self.heading,
            hfov=self.hfov,
            max_range=self.max_range,
            min_range=self.min_range,
            origin=(self.north, self.east),
        )


# ==========================================================================================
# results
# ==========================================================================================


@dataclass(frozen=True, eq=False)
class VesselStates:
    """The AIS vessels available at one time (:meth:`AisAssociator.vessels_at`).

    Attributes:
        time: the time [s since the epoch].
        mmsi: vessel identities, (V,) int64.
        north, east: positions in the associator's tangent plane [m], (V,).
        velocity: (v_north, v_east) [m/s], (V, 2).
        velocity_known: True where the vessel's velocity is known (two reports or more,
            or a reported speed), (V,).
        sigma: 1-σ position error per axis [m], ``sqrt(sigma_ais² + (age ·
            sigma_ais_drift)²)``, (V,).
        age: time to the nearest report [s], (V,).
        extrapolated: True where dead-reckoned rather than interpolated, (V,).
    """

    time: float
    mmsi: NDArray[np.int64]
    north: FloatArray
    east: FloatArray
    velocity: FloatArray
    velocity_known: NDArray[np.bool_]
    sigma: FloatArray
    age: FloatArray
    extrapolated: NDArray[np.bool_]

    def __len__(self) -> int:
        return int(self.mmsi.size)


@dataclass(frozen=True)
class PairStats:
    """How often one camera track was assigned to one AIS vessel.

    Attributes:
        track_id: the camera track. mmsi: the vessel.
        frames: frames in which the pair was assigned.
        mean_distance: mean distance between track and vessel over those frames [m].
        longest_streak: most consecutive assigned frames.
        first_time, last_time: first and last assigned time [s since the epoch].
    """

    track_id: int
    mmsi: int
    frames: int
    mean_distance: float
    longest_streak: int
    first_time: float
    last_time: float


@dataclass(frozen=True, eq=False)
class AisAssociation:
    """Outcome of an association run (:meth:`AisAssociator.result`).

    Attributes:
        matches: final label per labelled track, ``{track_id: mmsi}`` (a vessel may
            label several tracks, e.g. one ship tracked twice in succession).
        dark: tracks seen in at least ``min_frames`` frames inside the AIS time span that
            never got a label (vessels without AIS), sorted.
        unseen: MMSIs in view for at least ``unseen_after`` seconds that never became a
            track's label, sorted.
        pairs: statistics of every (track, vessel) pair ever assigned, sorted by
            (track_id, mmsi).
        history: label changes per labelled track, ``{track_id: ((time, mmsi), …)}``.
        in_view_time: seconds each vessel spent in view (vessels ever in view only).
        track_frames: frames with a usable position per track.
        frames: number of updates.
    """

    matches: Mapping[int, int]
    dark: tuple[int, ...]
    unseen: tuple[int, ...]
    pairs: tuple[PairStats, ...]
    history: Mapping[int, tuple[tuple[float, int], ...]]
    in_view_time: Mapping[int, float]
    track_frames: Mapping[int, int]
    frames: int

    def as_dict(self) -> dict[str, Any]:
        """A JSON-ready summary (``matches``, ``dark``, ``unseen``, ``pairs``)."""
        return {
            "matches": [{"track_id": k, "mmsi": v} for k, v in sorted(self.matches.items())],
            "dark": list(self.dark),
            "unseen": list(self.unseen),
            "pairs": [
                {
                    "track_id": p.track_id,
                    "mmsi": p.mmsi,
                    "frames": p.frames,
                    "mean_distance_m": p.mean_distance,
                }
                for p in self.pairs
            ],
        }


@dataclass
class _Pair:
    frames: int = 0
    dist_sum: float = 0.0
    streak: int = 0
    longest: int = 0
    first: float = math.nan
    last: float = math.nan


@dataclass
class _Track:
    label: int | None = None
    frames: int = 0  # usable frames
    covered: int = 0  # usable frames inside the AIS time span
    votes: int = 0  # frames with any assignment
    pairs: dict[int, _Pair] = field(default_factory=dict)
    history: list[tuple[float, int]] = field(default_factory=list)


# ==========================================================================================
# the associator
# ==========================================================================================


class AisAssociator:
    """Online association of camera tracks with AIS vessels (module docstring, steps 1–5).

    Label rule (per track; ``m_k`` is the vessel assigned to it in this frame):

    * a pair's *streak* counts its consecutive assignments; it restarts at 0 when the
      track, with a usable position, is assigned to another vessel, or is left
      unassigned while the vessel was available. Frames where the track has no usable
      position (absent, NaN) or the vessel has no AIS sample change nothing, so gaps in
      time or detections do not break a streak;
    * an unlabelled track takes label ``m`` when ``streak(m) ≥ min_frames``, or when
      ``frames(m) ≥ min_frames`` and ``frames(m) ≥ majority · (all assignments of the
      track)`` (a clear majority over intermittent matches);
    * a labelled track switches to ``m ≠ label`` only when ``streak(m) ≥ switch_frames``
      (default ``3 · min_frames``): strong, uninterrupted evidence;
    * labels are never removed. Frames count calls of :meth:`update`: call it at a steady
      rate (every video frame, or subsampled, e.g. 1–5 Hz) and choose ``min_frames``
      for that rate.

    Args:
        table: AIS reports (:func:`seawatch.io.read_ais`); rows without a time are left
            out (with an AisWarning from :func:`seawatch.io.ais.tracks`).
        lat0, lon0: origin of the tangent plane the camera tracks are given in [deg].
        gate_probability: position gate, ``d² ≤ chi2.ppf(p, 2)``.
        velocity_gate_probability: velocity gate, likewise.
        gate_m: largest track–vessel distance accepted [m] whatever the covariances
            (None: no limit).
        sigma_track: 1-σ per axis of a camera position when no covariance is given [m].
        sigma_track_velocity: 1-σ per axis of a camera velocity when no 4×4 covariance
            is given [m/s].
        sigma_ais: 1-σ per axis of an AIS position at its report time [m].
        sigma_ais_drift: growth of the AIS position error with the report's age [m/s].
        sigma_ais_velocity: 1-σ per axis of an AIS velocity [m/s].
        max_extrapolation: longest dead reckoning beyond the reports [s].
        max_gap: longest gap between reports interpolated [s].
        min_frames: frames needed for a label (see the rule above), >= 1.
        switch_frames: consecutive frames needed to change a label (default 3·min_frames).
        majority: share of a track's assignments that makes a clear majority, in (0.5, 1].
        continuity: cost bonus of the pair matching the track's current label.
        in_view: default view test ``in_view(north, east) -> bool`` (e.g. a fixed shore
            camera's :class:`ViewWedge`); None: only per-update tests count.
        unseen_after: in-view time that makes a never-labelled vessel *unseen* [s].
        max_step: longest time between updates credited as in-view time [s] (a gap in
            the video must not make every vessel "in view" for its whole length).

    Attributes:
        mmsi: the vessels with timed reports, ascending, (V,) int64.
        time_span: (first, last) AIS report time [s since the epoch] (NaN if none).
        gamma, gamma_velocity: the chi-square gate thresholds.
    """

    def __init__(
        self,
        table: AisTable,
        *,
        lat0: float,
        lon0: float,
        gate_probability: float = 0.999,
        velocity_gate_probability: float = 0.999,
        gate_m: float | None = 1000.0,
        sigma_track: float = 25.0,
        sigma_track_velocity: float = 2.0,
        sigma_ais: float = 10.0,
        sigma_ais_drift: float = 0.5,
        sigma_ais_velocity: float = 0.5,
        max_extrapolation: float = MAX_EXTRAPOLATION,
        max_gap: float = MAX_GAP,
        min_frames: int = 5,
        switch_frames: int | None = None,
        majority: float = 2.0 / 3.0,
        continuity: float = 4.0,
        in_view: ViewTest | None = None,
        unseen_after: float = 10.0,
        max_step: float = 5.0,
    ) -> None:
        if not isinstance(table, AisTable):
            raise ValueError(f"table: expected an AisTable, got {type(table).__name__}")
        self.lat0 = in_range("lat0", lat0, -90.0, 90.0)
        self.lon0 = in_range("lon0", lon0, -180.0, 180.0)
        p = in_range("gate_probability", gate_probability, 0.0, 1.0, lo_open=True, hi_open=True)
        pv = in_range(
            "velocity_gate_probability",
            velocity_gate_probability,
            0.0,
            1.0,
            lo_open=True,
            hi_open=True,
        )
        self.gamma = float(chi2.ppf(p, 2))
        self.gamma_velocity = float(chi2.ppf(pv, 2))
        self.gate_m = None if gate_m is None else positive("gate_m", gate_m)
        self.sigma_track = positive("sigma_track", sigma_track)
        self.sigma_track_velocity = positive("sigma_track_velocity", sigma_track_velocity)
        self.sigma_ais = positive("sigma_ais", sigma_ais)
        self.sigma_ais_drift = positive("sigma_ais_drift", sigma_ais_drift, allow_zero=True)
        self.sigma_ais_velocity = positive("sigma_ais_velocity", sigma_ais_velocity)
        self.max_extrapolation = positive("max_extrapolation", max_extrapolation, allow_zero=True)
        self.max_gap = positive("max_gap", max_gap)
        self.min_frames = integer("min_frames", min_frames, 1)
        self.switch_frames = (
            3 * self.min_frames
            if switch_frames is None
            else integer("switch_frames", switch_frames, 1)
        )
        self.majority = in_range("majority", majority, 0.5, 1.0, lo_open=True)
        self.continuity = positive("continuity", continuity, allow_zero=True)
        if in_view is not None and not callable(in_view):
            raise ValueError("in_view: expected a callable in_view(north, east) -> bool array")
        self.in_view = in_view
        self.unseen_after = positive("unseen_after", unseen_after, allow_zero=True)
        self.max_step = positive("max_step", max_step, allow_zero=True)
        self._build_knots(table)
        self._tracks: dict[int, _Track] = {}
        self._in_view_time: dict[int, float] = {}
        self._ever_labelled: set[int] = set()
        self._last_time: float | None = None
        self._frames = 0

    # ------------------------------------------------------------------------------------
    # AIS sampling
    # ------------------------------------------------------------------------------------

    def _build_knots(self, table: AisTable) -> None:
        """Per-vessel knots from ais.interpolate_track at the report times, concatenated."""
        per_vessel = tracks(table)
        ts, ps, vs, owner, vknown = [], [], [], [], []
        mmsi = []
        for i, (m, tr) in enumerate(per_vessel.items()):
            knots = interpolate_track(
                tr, tr.time, origin=(self.lat0, self.lon0), max_gap=self.max_gap
            )
            ts.append(tr.time)
            ps.append(np.stack([knots.north, knots.east], axis=-1))
            vs.append(knots.velocity)
            owner.append(np.full(tr.time.size, i))
            mmsi.append(m)
            vknown.append(len(tr) >= 2 or bool(np.isfinite(tr.sog[0])))
        self.mmsi = np.asarray(mmsi, dtype=np.int64)
        if not ts:
            self._t = np.empty(0)
            self._p = np.empty((0, 2))
            self._v = np.empty((0, 2))
            self._start = self._end = np.empty(0, dtype=np.int64)
            self._vknown = np.empty(0, dtype=bool)
            self._tref = self._block = 0.0
            self._key = np.empty(0)
            self.time_span = (math.nan, math.nan)
            return
        self._t = np.concatenate(ts)
        self._p = np.concatenate(ps)
        self._v = np.concatenate(vs)
        lengths = np.array([t.size for t in ts])
        self._end = np.cumsum(lengths)
        self._start = self._end - lengths
        self._vknown = np.asarray(vknown, dtype=bool)
        self._tref = float(self._t.min())
        span = float(self._t.max()) - self._tref
        self._block = span + 3.0
        self._key = np.concatenate(owner) * self._block + (self._t - self._tref)
        self.time_span = (self._tref, self._tref + span)

    def vessels_at(self, time: float) -> VesselStates:
        """The AIS vessels available at ``time`` with their positions and uncertainties.

        Interpolation between reports at most ``max_gap`` apart (the cubic Hermite curve
        of :func:`seawatch.io.ais.interpolate_track`, velocity blended linearly), else
        dead reckoning from the nearest report within ``max_extrapolation``
        (``p = p_i + v_i (t − t_i)``); vessels farther from any report are left out.

        Args:
            time: [s since the epoch].
        """
        t = _finite_time(time)
        V = self.mmsi.size
        if V == 0:
            z = np.empty(0)
            return VesselStates(
                t, self.mmsi, z, z, np.empty((0, 2)), np.empty(0, bool), z, z, np.empty(0, bool)
            )
        q = min(max(t - self._tref, -1.0), self._block - 2.0)
        j = np.searchsorted(self._key, np.arange(V) * self._block + q, side="right") - 1
        has_lo = j >= self._start
        has_hi = j + 1 < self._end
        lo = np.clip(j, 0, self._t.size - 1)
        hi = np.clip(j + 1, 0, self._t.size - 1)
        t_lo = np.where(has_lo, self._t[lo], -np.inf)
        t_hi = np.where(has_hi, self._t[hi], np.inf)
        d_lo = t - t_lo
        d_hi = t_hi - t
        age = np.minimum(d_lo, d_hi)
        seg = has_lo & has_hi & (t_hi - t_lo <= self.max_gap)
        # cubic Hermite between the knots (ais.interpolate_track's formula)
        dt = np.where(seg, t_hi - t_lo, 1.0)
        s = np.where(seg, d_lo / dt, 0.0)[:, None]
        h00 = 2 * s**3 - 3 * s**2 + 1
        h10 = s**3 - 2 * s**2 + s
        h01 = -2 * s**3 + 3 * s**2
        h11 = s**3 - s**2
        p_lo, p_hi, v_lo, v_hi = self._p[lo], self._p[hi], self._v[lo], self._v[hi]
        pos = h00 * p_lo + h10 * dt[:, None] * v_lo + h01 * p_hi + h11 * dt[:, None] * v_hi
        vel = (1 - s) * v_lo + s * v_hi
        # dead reckoning from the nearest report
        use_lo = ~seg & has_lo & (d_lo <= d_hi) & (d_lo <= self.max_extrapolation)
        use_hi = ~seg & ~use_lo & has_hi & (d_hi <= self.max_extrapolation)
        pos = np.where(use_lo[:, None], p_lo + v_lo * np.where(use_lo, d_lo, 0.0)[:, None], pos)
        pos = np.where(use_hi[:, None], p_hi - v_hi * np.where(use_hi, d_hi, 0.0)[:, None], pos)
        vel = np.where(use_lo[:, None], v_lo, np.where(use_hi[:, None], v_hi, vel))
        ok = seg | use_lo | use_hi
        sigma = np.sqrt(self.sigma_ais**2 + (age * self.sigma_ais_drift) ** 2)
        return VesselStates(
            time=t,
            mmsi=self.mmsi[ok],
            north=pos[ok, 0],
            east=pos[ok, 1],
            velocity=vel[ok],
            velocity_known=self._vknown[ok],
            sigma=sigma[ok],
            age=age[ok],
            extrapolated=~seg[ok],
        )

    # ------------------------------------------------------------------------------------
    # one frame
    # ------------------------------------------------------------------------------------

    def update(
        self,
        time: float,
        track_ids: ArrayLike,
        north: ArrayLike,
        east: ArrayLike,
        covariance: ArrayLike | None = None,
        velocity: ArrayLike | None = None,
        in_view: ViewTest | None = None,
    ) -> dict[int, int | None]:
        """Associate the camera tracks of one instant; return each track's current label.

        Args:
            time: the instant [s since the epoch] (NAV/AIS clock), not before the last.
            track_ids: camera track ids, (K,) distinct integers.
            north, east: track positions in the tangent plane at (lat0, lon0) [m], (K,);
                NaN rows are tracks without a position now (no vote).
            covariance: (K, 2, 2) position covariances [m²] or (K, 4, 4) state
                covariances of ``[north, east, v_north, v_east]`` (positions first, as
                :func:`seawatch.models.constant_velocity`); rows of NaN-position tracks
                may be NaN. None: ``sigma_track² I``.
            velocity: (K, 2) track velocities (v_north, v_east) [m/s], NaN rows unknown;
                None: no velocity gate.
            in_view: this frame's view test (e.g. the :class:`ViewWedge` of a moving
                platform's pose); None: the constructor's.

        Returns:
            ``{track_id: mmsi or None}`` for every track of this call.

        Raises:
            ValueError: time not finite or earlier than the last update; inconsistent
                shapes; duplicate ids; bad covariances (naming the argument).
        """
        t = _finite_time(time)
        if self._last_time is not None and t < self._last_time:
            raise ValueError(
                f"time: {t!r} is earlier than the previous update ({self._last_time!r})"
            )
        ids, z, P, Pv, vel = self._inputs(track_ids, north, east, covariance, velocity)
        K = ids.size
        usable = np.isfinite(z).all(axis=1)
        vs = self.vessels_at(t)
        V = len(vs)
        assigned: dict[int, tuple[int, float]] = {}  # track index -> (mmsi, distance)
        if K and V and np.any(usable):
            assigned = self._associate(ids, z, P, Pv, vel, usable, vs)
        covered = self.time_span[0] <= t <= self.time_span[1]
        available = set(vs.mmsi.tolist())
        for k in range(K):
            tid = int(ids[k])
            state = self._tracks.setdefault(tid, _Track())
            if not usable[k]:
                continue
            state.frames += 1
            state.covered += int(covered)
            self._vote(state, t, assigned.get(k), available)
        view = in_view if in_view is not None else self.in_view
        if view is not None and V:
            if not callable(view):
                raise ValueError("in_view: expected a callable in_view(north, east) -> bool")
            seen = np.asarray(view(vs.north, vs.east), dtype=bool)
            if seen.shape != (V,):
                raise ValueError(
                    f"in_view: expected a boolean array of shape ({V},), got {seen.shape}"
                )
            step = 0.0 if self._last_time is None else min(t - self._last_time, self.max_step)
            for m in vs.mmsi[seen].tolist():
                self._in_view_time[m] = self._in_view_time.get(m, 0.0) + step
        self._last_time = t
        self._frames += 1
        return {int(i): self._tracks[int(i)].label for i in ids}

    def _inputs(
        self,
        track_ids: ArrayLike,
        north: ArrayLike,
        east: ArrayLike,
        cov: ArrayLike | None,
        velocity: ArrayLike | None,
    ) -> tuple[NDArray[np.int64], FloatArray, FloatArray, FloatArray, FloatArray]:
        raw = np.asarray(track_ids)
        if raw.ndim != 1 or (raw.size and not np.issubdtype(raw.dtype, np.integer)):
            raise ValueError(f"track_ids: expected a 1-D array of integers, got {raw!r}")
        ids = raw.astype(np.int64)
        K = ids.size
        if np.unique(ids).size != K:
            raise ValueError("track_ids: expected distinct ids")
        n = as_float_array("north", north, ndim=1)
        e = as_float_array("east", east, ndim=1)
        if n.size != K or e.size != K:
            raise ValueError(
                f"north/east: expected {K} values (one per track id), got {n.size} and {e.size}"
            )
        z = np.stack([n, e], axis=-1)
        usable = np.isfinite(z).all(axis=1)
        P = np.broadcast_to(self.sigma_track**2 * np.eye(2), (K, 2, 2)).copy()
        Pv = np.broadcast_to(self.sigma_track_velocity**2 * np.eye(2), (K, 2, 2)).copy()
        if cov is not None:
            c = as_float_array("covariance", cov, ndim=3)
            if c.shape not in ((K, 2, 2), (K, 4, 4)):
                raise ValueError(
                    f"covariance: expected shape ({K}, 2, 2) or ({K}, 4, 4), got {c.shape}"
                )
            if np.any(usable):
                c_ok = covariance("covariance", c[usable], c.shape[-1], batch=True)
                P[usable] = c_ok[:, :2, :2]
                if c.shape[-1] == 4:
                    Pv[usable] = c_ok[:, 2:, 2:]
        vel = np.full((K, 2), np.nan)
        if velocity is not None:
            v = as_float_array("velocity", velocity, ndim=2)
            if v.shape != (K, 2):
                raise ValueError(f"velocity: expected shape ({K}, 2) [m/s], got {v.shape}")
            if np.any(np.isinf(v)):
                raise ValueError("velocity: contains inf")
            vel = v
        return ids, z, P, Pv, vel

    def _associate(
        self,
        ids: NDArray[np.int64],
        z: FloatArray,
        P: FloatArray,
        Pv: FloatArray,
        vel: FloatArray,
        usable: NDArray[np.bool_],
        vs: VesselStates,
    ) -> dict[int, tuple[int, float]]:
        """Gate and assign (module docstring steps 2–3): {track index: (mmsi, distance)}."""
        p_ais = np.stack([vs.north, vs.east], axis=-1)
        y = z[:, None, :] - p_ais[None, :, :]  # (K, V, 2)
        S = P[:, None, :, :] + (vs.sigma**2)[None, :, None, None] * np.eye(2)
        d2, logdet = _mahalanobis2(y, S)
        dist = np.hypot(y[..., 0], y[..., 1])
        gated = usable[:, None] & (d2 <= self.gamma)
        if self.gate_m is not None:
            gated &= dist <= self.gate_m
        vterm = np.full(d2.shape, 2.0)  # E[chi2_2] where a velocity is unknown
        has_v = np.isfinite(vel).all(axis=1)[:, None] & vs.velocity_known[None, :]
        if np.any(has_v):
            yv = vel[:, None, :] - vs.velocity[None, :, :]
            Sv = Pv[:, None, :, :] + self.sigma_ais_velocity**2 * np.eye(2)
            d2v, _ = _mahalanobis2(np.where(has_v[..., None], yv, 0.0), Sv)
            gated &= ~has_v | (d2v <= self.gamma_velocity)
            vterm = np.where(has_v, d2v, vterm)
        cost = np.where(gated, d2 + logdet + vterm, 0.0)
        labels = np.array(
            [-1 if (lab := self._label_of(int(i))) is None else lab for i in ids],
            dtype=np.int64,
        )
        cost = cost - self.continuity * (labels[:, None] == vs.mmsi[None, :])
        rows, cols = gnn_assign(cost, gated)
        return {
            int(r): (int(vs.mmsi[c]), float(dist[r, c])) for r, c in zip(rows, cols, strict=True)
        }

    def _label_of(self, tid: int) -> int | None:
        st = self._tracks.get(tid)
        return None if st is None else st.label

    def _vote(
        self, state: _Track, t: float, match: tuple[int, float] | None, available: set[int]
    ) -> None:
        """Streaks, votes and the label rule of :class:`AisAssociator` for one track."""
        m_k = None if match is None else match[0]
        for m, pair in state.pairs.items():
            if m != m_k and (m_k is not None or m in available):
                pair.streak = 0
        if match is None:
            return
        m, d = match
        pair = state.pairs.setdefault(m, _Pair(first=t))
        pair.frames += 1
        pair.dist_sum += d
        pair.streak += 1
        pair.longest = max(pair.longest, pair.streak)
        pair.last = t
        state.votes += 1
        if state.label is None:
            if pair.streak >= self.min_frames or (
                pair.frames >= self.min_frames and pair.frames >= self.majority * state.votes
            ):
                self._set_label(state, t, m)
        elif m != state.label and pair.streak >= self.switch_frames:
            self._set_label(state, t, m)

    def _set_label(self, state: _Track, t: float, m: int) -> None:
        state.label = m
        state.history.append((t, m))
        self._ever_labelled.add(m)

    # ------------------------------------------------------------------------------------
    # outcome
    # ------------------------------------------------------------------------------------

    @property
    def labels(self) -> dict[int, int | None]:
        """Current label of every track seen so far, ``{track_id: mmsi or None}``."""
        return {tid: st.label for tid, st in self._tracks.items()}

    def result(self) -> AisAssociation:
        """Labels, dark tracks, unseen vessels and pair statistics so far."""
        matches = {
            tid: st.label for tid, st in sorted(self._tracks.items()) if st.label is not None
        }
        dark = tuple(
            sorted(
                tid
                for tid, st in self._tracks.items()
                if st.label is None and st.covered >= self.min_frames
            )
        )
        unseen = tuple(
            sorted(
                m
                for m, s in self._in_view_time.items()
                if s >= self.unseen_after and m not in self._ever_labelled
            )
        )
        pairs = tuple(
            PairStats(
                track_id=tid,
                mmsi=m,
                frames=p.frames,
                mean_distance=p.dist_sum / p.frames,
                longest_streak=p.longest,
                first_time=p.first,
                last_time=p.last,
            )
            for tid, st in sorted(self._tracks.items())
            for m, p in sorted(st.pairs.items())
        )
        return AisAssociation(
            matches=matches,
            dark=dark,
            unseen=unseen,
            pairs=pairs,
            history={tid: tuple(st.history) for tid, st in self._tracks.items() if st.history},
            in_view_time=dict(sorted(self._in_view_time.items())),
            track_frames={tid: st.frames for tid, st in sorted(self._tracks.items())},
            frames=self._frames,
        )


def _mahalanobis2(y: FloatArray, S: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``yᵀ S⁻¹ y`` and ``ln det S`` for stacks of 2-vectors and 2×2 SPD matrices."""
    a, b, d = S[..., 0, 0], S[..., 0, 1], S[..., 1, 1]
    det = a * d - b * b
    if np.any(det <= 0.0):
        raise np.linalg.LinAlgError(
            "innovation covariance S = P_track + sigma_ais^2 I is singular (det <= 0)"
        )
    y0, y1 = y[..., 0], y[..., 1]
    return (d * y0 * y0 - 2.0 * b * y0 * y1 + a * y1 * y1) / det, np.log(det)


def _finite_time(time: Any) -> float:
    try:
        t = float(time)
    except (TypeError, ValueError):
        raise ValueError(f"time: expected seconds since the epoch, got {time!r}") from None
    if not math.isfinite(t):
        raise ValueError(f"time: expected a finite time [s], got {time!r}")
    return t
