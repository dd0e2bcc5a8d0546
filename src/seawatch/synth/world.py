"""Ships in world coordinates for the synthetic-footage renderer (`seawatch synth`).

A :class:`Ship` is a small solid model — a hull and superstructure blocks, each a convex
prism in the ship frame — moving along a :class:`Trajectory`: sampled times with the
position (x North, y East) [m] of the ship's reference point (midship, on the
waterline) and its heading (bow direction, clockwise from North) [rad], linearly
interpolated between samples (the heading along the shorter arc).

Ship frame: x forward (towards the bow), y to starboard, z up from the waterline [m].
A point (x, y, z) of a ship at (n, e) with heading psi is at

    north = n + x cos(psi) - y sin(psi),     east = e + x sin(psi) + y cos(psi),     up = z.

Trajectory helpers build the encounters of the seed 001 videos: :func:`straight`,
:func:`through` (a straight track passing a point at a given time), :func:`turning`
(straight, constant-rate turn, straight), :func:`meeting` (two ships on reciprocal
courses passing each other), :func:`overtaking` and :func:`crossing`. :func:`make_ship`
gives a ship of a kind (boat, sailboat, workboat, ferry, cargo, tanker) with sensible
proportions; :func:`ships_from_tracks` turns per-vessel time/position/heading arrays
(e.g. AIS tracks) into ships.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import FloatArray, as_float_array, in_range, positive

__all__ = [
    "KINDS",
    "Prism",
    "Ship",
    "Trajectory",
    "crossing",
    "hull_prism",
    "kind_for_length",
    "make_ship",
    "meeting",
    "overtaking",
    "ships_from_tracks",
    "straight",
    "through",
    "turning",
]

RGB = tuple[float, float, float]
ShipKind = Literal["boat", "sailboat", "workboat", "ferry", "cargo", "tanker"]
KINDS: tuple[str, ...] = ("boat", "sailboat", "workboat", "ferry", "cargo", "tanker")
"""Ship kinds known to :func:`make_ship`."""

_TWO_PI = 2.0 * math.pi


def _wrap_2pi(a: ArrayLike) -> FloatArray:
    return np.mod(np.asarray(a, dtype=np.float64), _TWO_PI)


# ----------------------------------------------------------------------------- trajectory
@dataclass(frozen=True, eq=False)
class Trajectory:
    """Sampled ship track, linearly interpolated in time.

    Attributes:
        time: (T,) sample times [s], strictly increasing, T >= 2.
        north: (T,) x North of the ship's reference point (midship, waterline) [m].
        east: (T,) y East [m].
        heading: (T,) bow direction, clockwise from North [rad] (stored wrapped to
            [0, 2 pi); interpolated along the shorter arc).

    The ship exists only within [time[0], time[-1]]: :meth:`state` returns NaN outside.
    """

    time: FloatArray
    north: FloatArray
    east: FloatArray
    heading: FloatArray
    _unwrapped: FloatArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        t = as_float_array("time", self.time, ndim=1)
        if t.size < 2:
            raise ValueError(f"time: expected at least 2 samples, got {t.size}")
        if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0.0):
            raise ValueError("time: expected finite, strictly increasing sample times [s]")
        arrays = {}
        for name in ("north", "east", "heading"):
            a = np.broadcast_to(as_float_array(name, getattr(self, name), ndim=(0, 1)), t.shape)
            if not np.all(np.isfinite(a)):
                raise ValueError(f"{name}: contains NaN or inf")
            arrays[name] = np.array(a, dtype=np.float64)
        heading = _wrap_2pi(arrays["heading"])
        unwrapped = np.unwrap(heading)
        for name, value in (
            ("time", t.copy()),
            ("north", arrays["north"]),
            ("east", arrays["east"]),
            ("heading", heading),
            ("_unwrapped", unwrapped),
        ):
            value.setflags(write=False)
            set_(self, name, value)

    @property
    def start(self) -> float:
        """First sample time [s]."""
        return float(self.time[0])

    @property
    def end(self) -> float:
        """Last sample time [s]."""
        return float(self.time[-1])

    def position(self, t: ArrayLike) -> FloatArray:
        """(north, east) [m] at time(s) t [s], shape (..., 2); NaN outside the time span."""
        tt = as_float_array("t", t)
        inside = (tt >= self.time[0]) & (tt <= self.time[-1])
        n = np.interp(tt, self.time, self.north)
        e = np.interp(tt, self.time, self.east)
        out = np.stack([n, e], -1)
        out[~inside] = np.nan
        return out

    def heading_at(self, t: ArrayLike) -> FloatArray:
        """Heading [rad] in [0, 2 pi) at time(s) t; NaN outside the time span."""
        tt = as_float_array("t", t)
        inside = (tt >= self.time[0]) & (tt <= self.time[-1])
        h = _wrap_2pi(np.interp(tt, self.time, self._unwrapped))
        return np.where(inside, h, np.nan)

    def velocity(self, t: ArrayLike) -> FloatArray:
        """(v_north, v_east) [m/s] at time(s) t: the velocity of the sample interval holding t.

        At a sample time the later interval is used (the last sample uses the last
        interval). NaN outside the time span.
        """
        tt = as_float_array("t", t)
        inside = (tt >= self.time[0]) & (tt <= self.time[-1])
        dt = np.diff(self.time)
        vn = np.diff(self.north) / dt
        ve = np.diff(self.east) / dt
        k = np.clip(np.searchsorted(self.time, tt, side="right") - 1, 0, dt.size - 1)
        out = np.stack([vn[k], ve[k]], -1)
        out[~inside] = np.nan
        return out

    def state(self, t: float) -> tuple[float, float, float, float] | None:
        """(north [m], east [m], heading [rad], speed [m/s]) at time t, or None outside.

        The scalar fast path of :meth:`position`, :meth:`heading_at` and :meth:`velocity`
        (same interpolation).
        """
        times = self.time
        if not (times[0] <= t <= times[-1]):
            return None
        k = min(max(int(np.searchsorted(times, t, side="right")) - 1, 0), times.size - 2)
        t0 = float(times[k])
        dt = float(times[k + 1]) - t0
        f = (t - t0) / dt
        n0, n1 = float(self.north[k]), float(self.north[k + 1])
        e0, e1 = float(self.east[k]), float(self.east[k + 1])
        h0, h1 = float(self._unwrapped[k]), float(self._unwrapped[k + 1])
        n = n0 + (n1 - n0) * f
        e = e0 + (e1 - e0) * f
        heading = (h0 + (h1 - h0) * f) % _TWO_PI
        speed = math.hypot(n1 - n0, e1 - e0) / dt
        return n, e, heading, speed


def _sample_times(start: float, end: float, dt: float) -> FloatArray:
    n = max(1, math.ceil((end - start) / dt - 1e-9))
    return np.linspace(start, end, n + 1)


def straight(
    north: float,
    east: float,
    course: float,
    speed: float,
    duration: float,
    *,
    start: float = 0.0,
) -> Trajectory:
    """Constant-velocity track from (north, east) [m] at time ``start`` [s].

    ``course`` [rad] clockwise from North (also the heading), ``speed`` [m/s] >= 0,
    ``duration`` [s] > 0. Two samples: linear interpolation is exact.
    """
    v = positive("speed", speed, allow_zero=True)
    d = positive("duration", duration)
    c = in_range("course", course, -np.inf, np.inf, lo_open=True, hi_open=True)
    t = np.array([start, start + d])
    n = north + v * (t - start) * math.cos(c)
    e = east + v * (t - start) * math.sin(c)
    return Trajectory(t, n, e, np.full(2, c))


def through(
    north: float,
    east: float,
    course: float,
    speed: float,
    at_time: float,
    *,
    start: float = 0.0,
    end: float,
) -> Trajectory:
    """Constant-velocity track that passes (north, east) [m] at time ``at_time`` [s].

    Exists from ``start`` to ``end`` [s]; ``course`` [rad] clockwise from North, ``speed``
    [m/s].
    """
    if not end > start:
        raise ValueError(f"end: expected end > start ({start!r}), got {end!r}")
    v = positive("speed", speed, allow_zero=True)
    n0 = north - v * (at_time - start) * math.cos(course)
    e0 = east - v * (at_time - start) * math.sin(course)
    return straight(n0, e0, course, v, end - start, start=start)


def turning(
    north: float,
    east: float,
    course: float,
    speed: float,
    duration: float,
    *,
    turn_rate: float,
    turn_start: float = 0.0,
    turn_end: float | None = None,
    start: float = 0.0,
    dt: float = 0.1,
) -> Trajectory:
    """Straight, then a constant-rate turn, then straight again.

    Starts at (north, east) [m] on ``course`` [rad] at time ``start`` [s] with ``speed``
    [m/s]; turns at ``turn_rate`` [rad/s] (positive = clockwise, to starboard) between
    ``turn_start`` and ``turn_end`` [s] (default: to the end). The arc is exact at the
    samples (every ``dt`` [s]); the chord error between samples is v ω dt² / 8
    (≈ 1e-4 m for 10 m/s, 3 deg/s, dt = 0.1 s).
    """
    d = positive("duration", duration)
    v = positive("speed", speed, allow_zero=True)
    step = positive("dt", dt)
    end = start + d
    t1 = end if turn_end is None else min(max(turn_end, start), end)
    t0 = min(max(turn_start, start), t1)
    t = _sample_times(start, end, step)
    t = np.unique(np.concatenate([t, [t0, t1]]))
    # heading as a function of time: constant, linear, constant
    turned = turn_rate * (np.clip(t, t0, t1) - t0)
    heading = course + turned
    # position: integrate v (cos, sin)(heading) exactly, piecewise
    n = np.empty_like(t)
    e = np.empty_like(t)
    for i, ti in enumerate(t):
        s_before = min(ti, t0) - start  # straight before the turn
        s_turn = max(0.0, min(ti, t1) - t0)
        s_after = max(0.0, ti - t1)
        nn = north + v * s_before * math.cos(course)
        ee = east + v * s_before * math.sin(course)
        if s_turn > 0.0:
            if abs(turn_rate) < 1e-12:
                nn += v * s_turn * math.cos(course)
                ee += v * s_turn * math.sin(course)
            else:
                c1 = course + turn_rate * s_turn
                nn += v / turn_rate * (math.sin(c1) - math.sin(course))
                ee += v / turn_rate * (math.cos(course) - math.cos(c1))
        if s_after > 0.0:
            c2 = course + turn_rate * (t1 - t0)
            nn += v * s_after * math.cos(c2)
            ee += v * s_after * math.sin(c2)
        n[i] = nn
        e[i] = ee
    return Trajectory(t, n, e, heading)


def meeting(
    north: float,
    east: float,
    course: float,
    speeds: tuple[float, float],
    separation: float,
    at_time: float,
    *,
    start: float = 0.0,
    end: float,
) -> tuple[Trajectory, Trajectory]:
    """Two ships on reciprocal courses passing each other (head-on meeting).

    The first ship steers ``course`` [rad], the second ``course + pi``; at ``at_time`` [s]
    they are abeam of each other, symmetric about the point (north, east) [m], with
    ``separation`` [m] between their tracks (the first ship to port of the point as
    seen along ``course``, the second to starboard). ``speeds`` [m/s].
    """
    off_n = -math.sin(course) * separation / 2.0  # starboard unit vector (-sin, cos)
    off_e = math.cos(course) * separation / 2.0
    a = through(north - off_n, east - off_e, course, speeds[0], at_time, start=start, end=end)
    b = through(
        north + off_n, east + off_e, course + math.pi, speeds[1], at_time, start=start, end=end
    )
    return a, b


def overtaking(
    north: float,
    east: float,
    course: float,
    speeds: tuple[float, float],
    separation: float,
    at_time: float,
    *,
    start: float = 0.0,
    end: float,
) -> tuple[Trajectory, Trajectory]:
    """A faster ship overtaking a slower one on parallel tracks.

    Both steer ``course`` [rad]; the slow ship (``speeds[0]`` [m/s]) runs to port of
    (north, east) [m] and the fast one (``speeds[1]``) to starboard, ``separation`` [m]
    apart; the fast one is abeam of the slow one at ``at_time`` [s].
    """
    if speeds[1] <= speeds[0]:
        raise ValueError(f"speeds: the second (overtaking) ship must be faster, got {speeds!r}")
    off_n = -math.sin(course) * separation / 2.0
    off_e = math.cos(course) * separation / 2.0
    slow = through(north - off_n, east - off_e, course, speeds[0], at_time, start=start, end=end)
    fast = through(north + off_n, east + off_e, course, speeds[1], at_time, start=start, end=end)
    return slow, fast


def crossing(
    north: float,
    east: float,
    courses: Sequence[float],
    speeds: Sequence[float],
    at_times: Sequence[float],
    *,
    offsets: Sequence[float] | None = None,
    start: float = 0.0,
    end: float,
) -> tuple[Trajectory, ...]:
    """Several ships whose tracks cross near (north, east) [m].

    Ship i steers ``courses[i]`` [rad] at ``speeds[i]`` [m/s] and passes the crossing
    point — shifted by ``offsets[i]`` [m] to its starboard (default 0) — at
    ``at_times[i]`` [s]. Give the ships different times so they do not collide.
    """
    if not (len(courses) == len(speeds) == len(at_times)):
        raise ValueError("courses, speeds, at_times: expected sequences of the same length")
    offs = [0.0] * len(courses) if offsets is None else list(offsets)
    if len(offs) != len(courses):
        raise ValueError("offsets: expected one offset per ship")
    out = []
    for c, v, tp, o in zip(courses, speeds, at_times, offs, strict=True):
        pn = north - math.sin(c) * o
        pe = east + math.cos(c) * o
        out.append(through(pn, pe, c, v, tp, start=start, end=end))
    return tuple(out)


# ----------------------------------------------------------------------------- ship model
@dataclass(frozen=True, eq=False)
class Prism:
    """A convex prism of a ship model, in the ship frame (x fwd, y starboard, z up) [m].

    ``outline`` (K, 2) is a convex polygon extruded between ``lo`` and ``hi`` along
    ``axis``: for ``axis="z"`` the outline is in the (x, y) plane (a hull or a
    deck-house), for ``axis="y"`` in the (x, z) plane (a sail or a thin mast).
    ``color`` is sRGB (0–255) in daylight; ``temperature`` in [0, 1] is the brightness
    in the thermal (night) rendering.

    Derived: ``vertices`` (2K, 3) — the ``lo`` cap then the ``hi`` cap — and ``faces``,
    a tuple of (vertex indices, outward unit normal (3,)) in the ship frame.
    """

    outline: FloatArray
    lo: float
    hi: float
    color: RGB = (120.0, 120.0, 120.0)
    temperature: float = 0.6
    axis: Literal["z", "y"] = "z"
    vertices: FloatArray = field(init=False, repr=False)
    faces: tuple[tuple[tuple[int, ...], FloatArray], ...] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        o = as_float_array("outline", self.outline, ndim=2)
        if o.shape[0] < 3 or o.shape[1] != 2 or not np.all(np.isfinite(o)):
            raise ValueError(f"outline: expected (K >= 3, 2) finite points [m], got {o.shape}")
        lo = float(self.lo)
        hi = float(self.hi)
        if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
            raise ValueError(f"lo, hi: expected finite lo < hi [m], got {self.lo!r}, {self.hi!r}")
        if self.axis not in ("z", "y"):
            raise ValueError(f"axis: expected 'z' or 'y', got {self.axis!r}")
        in_range("temperature", self.temperature, 0.0, 1.0)
        # orient the outline counter-clockwise in its plane
        x, y = o[:, 0], o[:, 1]
        area2 = float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
        if area2 == 0.0:
            raise ValueError("outline: degenerate polygon (zero area)")
        if area2 < 0.0:
            o = o[::-1].copy()
        k = o.shape[0]
        if self.axis == "z":
            verts = np.concatenate(
                [
                    np.column_stack([o[:, 0], o[:, 1], np.full(k, lo)]),
                    np.column_stack([o[:, 0], o[:, 1], np.full(k, hi)]),
                ]
            )
            cap_lo, cap_hi = np.array([0.0, 0.0, -1.0]), np.array([0.0, 0.0, 1.0])
        else:
            verts = np.concatenate(
                [
                    np.column_stack([o[:, 0], np.full(k, lo), o[:, 1]]),
                    np.column_stack([o[:, 0], np.full(k, hi), o[:, 1]]),
                ]
            )
            cap_lo, cap_hi = np.array([0.0, -1.0, 0.0]), np.array([0.0, 1.0, 0.0])
        centre = verts.mean(axis=0)
        faces: list[tuple[tuple[int, ...], FloatArray]] = [
            (tuple(range(k)), cap_lo),
            (tuple(range(k, 2 * k)), cap_hi),
        ]
        for i in range(k):
            j = (i + 1) % k
            idx = (i, j, k + j, k + i)
            p = verts[list(idx)]
            nrm = np.cross(p[1] - p[0], p[3] - p[0])
            norm = np.linalg.norm(nrm)
            if norm == 0.0:
                continue
            nrm = nrm / norm
            if np.dot(nrm, p.mean(axis=0) - centre) < 0.0:
                nrm = -nrm
            faces.append((idx, nrm))
        verts.setflags(write=False)
        set_(self, "outline", o)
        set_(self, "lo", lo)
        set_(self, "hi", hi)
        set_(self, "vertices", verts)
        set_(self, "faces", tuple(faces))


@dataclass(frozen=True, eq=False)
class Ship:
    """A ship: hull and superstructure prisms moving along a trajectory.

    Attributes:
        object_id: identifier written to ``truth.csv`` (e.g. an MMSI for AIS traffic).
        length: overall length [m] (the hull's x extent).
        beam: width [m].
        height: hull freeboard above the waterline [m] (deck height).
        superstructure: prisms on or above the deck (deck-houses, funnel, containers,
            mast, sail), in the ship frame.
        trajectory: where the ship is and where its bow points.
        hull: the hull prism (built from length/beam/height by :func:`hull_prism` when
            not given): a pointed bow, a slightly narrower transom, from the waterline
            (z = 0) to the deck.
        hull_color: sRGB of the hull in daylight; hull_temperature: thermal brightness in
            [0, 1].
        kind: free-text kind (see :data:`KINDS`).
    """

    object_id: int
    length: float
    beam: float
    height: float
    superstructure: tuple[Prism, ...]
    trajectory: Trajectory
    hull_color: RGB = (40.0, 44.0, 52.0)
    hull_temperature: float = 0.55
    kind: str = "ship"
    hull: Prism | None = None

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "length", positive("length", self.length))
        set_(self, "beam", positive("beam", self.beam))
        set_(self, "height", positive("height", self.height))
        if not isinstance(self.trajectory, Trajectory):
            raise ValueError(f"trajectory: expected a Trajectory, got {type(self.trajectory)}")
        parts = tuple(self.superstructure)
        for p in parts:
            if not isinstance(p, Prism):
                raise ValueError(f"superstructure: expected Prism parts, got {type(p)}")
        set_(self, "superstructure", parts)
        if self.hull is None:
            set_(
                self,
                "hull",
                hull_prism(
                    self.length, self.beam, self.height, self.hull_color, self.hull_temperature
                ),
            )

    @property
    def parts(self) -> tuple[Prism, ...]:
        """The hull then the superstructure prisms."""
        assert self.hull is not None
        return (self.hull, *self.superstructure)

    @property
    def top(self) -> float:
        """Highest point of the model above the waterline [m]."""
        return max(p.vertices[:, 2].max() for p in self.parts)


def hull_prism(
    length: float,
    beam: float,
    height: float,
    color: RGB = (40.0, 44.0, 52.0),
    temperature: float = 0.55,
) -> Prism:
    """The hull: a hexagonal footprint (pointed bow over the forward 18 %, transom 90 % of
    the beam) extruded from the waterline to the deck at ``height`` [m]."""
    half_l = length / 2.0
    half_b = beam / 2.0
    outline = np.array(
        [
            [half_l, 0.0],
            [half_l - 0.18 * length, half_b],
            [-half_l, 0.9 * half_b],
            [-half_l, -0.9 * half_b],
            [half_l - 0.18 * length, -half_b],
        ]
    )
    return Prism(outline, 0.0, height, color, temperature)


def _box(x0: float, x1: float, half_w: float, z0: float, z1: float, color: RGB, temp: float):
    outline = np.array([[x0, -half_w], [x1, -half_w], [x1, half_w], [x0, half_w]])
    return Prism(outline, z0, z1, color, temp)


_HULL_COLORS: tuple[RGB, ...] = (
    (32.0, 36.0, 44.0),  # near black
    (30.0, 48.0, 86.0),  # navy
    (110.0, 36.0, 30.0),  # red-brown
    (58.0, 64.0, 66.0),  # dark grey
    (205.0, 205.0, 200.0),  # white
    (20.0, 70.0, 60.0),  # dark green
)
_WHITE: RGB = (226.0, 226.0, 218.0)
_CREAM: RGB = (212.0, 204.0, 180.0)


def kind_for_length(length: float) -> str:
    """The ship kind :func:`make_ship` draws for a hull of ``length`` [m] when none is
    given: boat under 15 m, workboat under 60 m, cargo beyond."""
    if length < 15.0:
        return "boat"
    if length < 60.0:
        return "workboat"
    return "cargo"


def make_ship(
    object_id: int,
    trajectory: Trajectory,
    length: float,
    *,
    kind: str | None = None,
    beam: float | None = None,
    seed: int | None = None,
) -> Ship:
    """A ship of a kind with sensible proportions for its ``length`` [m].

    Kinds (:data:`KINDS`; default by length: < 15 m boat, < 60 m workboat, else cargo):

    - ``boat``: beam L/3, freeboard 0.12 L, a cabin amidships;
    - ``sailboat``: beam L/3.2, a sail (a thin triangular prism) 1.3 L high;
    - ``workboat``: beam L/4.5, freeboard 0.06 L + 1 m, a wheelhouse forward of midship
      and a mast;
    - ``ferry``: beam L/6, freeboard 0.08 L, two long deck-houses and a funnel;
    - ``cargo``: beam L/6.5, freeboard 0.09 L, container stacks, an aft bridge and funnel;
    - ``tanker``: beam L/5.5, freeboard 0.06 L, an aft bridge and funnel.

    ``seed`` picks the colours (default: the object id), so a ship looks the same in
    every render.
    """
    L = positive("length", length)
    kind = kind_for_length(L) if kind is None else kind
    if kind not in KINDS:
        raise ValueError(f"kind: expected one of {', '.join(KINDS)}, got {kind!r}")
    rng = np.random.default_rng(abs(int(object_id if seed is None else seed)) % (2**32))
    hull_color = _HULL_COLORS[int(rng.integers(len(_HULL_COLORS)))]
    white = _WHITE if rng.random() < 0.6 else _CREAM
    parts: list[Prism] = []
    if kind == "boat":
        B = L / 3.0 if beam is None else beam
        H = 0.12 * L
        hull_color = _HULL_COLORS[4] if rng.random() < 0.5 else hull_color
        parts.append(_box(-0.15 * L, 0.2 * L, 0.35 * B, H, H + 0.13 * L, white, 0.65))
        hull_t = 0.6
    elif kind == "sailboat":
        B = L / 3.2 if beam is None else beam
        H = 0.1 * L
        hull_color = _HULL_COLORS[4]
        parts.append(_box(-0.2 * L, 0.1 * L, 0.3 * B, H, H + 0.08 * L, white, 0.55))
        sail = np.array([[0.15 * L, H + 0.1 * L], [-0.3 * L, H + 0.1 * L], [0.12 * L, 1.3 * L]])
        parts.append(Prism(sail, -0.05, 0.05, (236.0, 236.0, 230.0), 0.35, axis="y"))
        hull_t = 0.5
    elif kind == "workboat":
        B = L / 4.5 if beam is None else beam
        H = 0.06 * L + 1.0
        parts.append(_box(-0.05 * L, 0.22 * L, 0.42 * B, H, H + 0.1 * L + 1.5, white, 0.7))
        parts.append(_box(0.05 * L, 0.09 * L, 0.04 * B, H, H + 0.25 * L + 3.0, hull_color, 0.6))
        hull_t = 0.6
    elif kind == "ferry":
        B = L / 6.0 if beam is None else beam
        H = 0.08 * L
        hull_color = _HULL_COLORS[int(rng.integers(len(_HULL_COLORS)))]
        parts.append(_box(-0.42 * L, 0.32 * L, 0.48 * B, H, H + 0.06 * L, white, 0.7))
        parts.append(_box(-0.3 * L, 0.22 * L, 0.4 * B, H + 0.06 * L, H + 0.1 * L, white, 0.72))
        parts.append(
            _box(-0.12 * L, -0.05 * L, 0.12 * B, H + 0.1 * L, H + 0.15 * L, hull_color, 0.95)
        )
        hull_t = 0.6
    elif kind == "cargo":
        B = L / 6.5 if beam is None else beam
        H = 0.09 * L
        stack_colors: tuple[RGB, ...] = (
            (150.0, 60.0, 40.0),
            (40.0, 80.0, 130.0),
            (170.0, 140.0, 60.0),
            (70.0, 110.0, 70.0),
        )
        for x0 in np.arange(-0.28 * L, 0.3 * L, 0.1 * L):
            c = stack_colors[int(rng.integers(len(stack_colors)))]
            h_stack = (0.035 + 0.02 * rng.random()) * L
            parts.append(_box(x0, x0 + 0.09 * L, 0.45 * B, H, H + h_stack, c, 0.5))
        parts.append(_box(-0.45 * L, -0.33 * L, 0.48 * B, H, H + 0.13 * L, white, 0.7))
        parts.append(_box(-0.47 * L, -0.42 * L, 0.15 * B, H, H + 0.17 * L, hull_color, 1.0))
        hull_t = 0.55
    else:  # tanker
        B = L / 5.5 if beam is None else beam
        H = 0.06 * L
        parts.append(_box(-0.46 * L, -0.36 * L, 0.48 * B, H, H + 0.12 * L, white, 0.7))
        parts.append(_box(-0.48 * L, -0.44 * L, 0.15 * B, H, H + 0.16 * L, hull_color, 1.0))
        parts.append(_box(-0.3 * L, 0.4 * L, 0.05 * B, H, H + 0.012 * L + 0.5, white, 0.5))
        hull_t = 0.55
    return Ship(
        object_id=int(object_id),
        length=L,
        beam=positive("beam", B),
        height=H,
        superstructure=tuple(parts),
        trajectory=trajectory,
        hull_color=hull_color,
        hull_temperature=hull_t,
        kind=kind,
    )


# ----------------------------------------------------------------------------- tracks hook
_DEFAULT_LENGTH = 25.0


def _track_items(tracks: Any) -> Iterable[tuple[Any, Mapping[str, Any]]]:
    if isinstance(tracks, Mapping):
        return tracks.items()
    items = []
    for i, tr in enumerate(tracks):
        if not isinstance(tr, Mapping):
            raise ValueError(f"tracks[{i}]: expected a mapping of arrays, got {type(tr)}")
        if "object_id" not in tr:
            raise ValueError(f"tracks[{i}]: missing 'object_id'")
        items.append((tr["object_id"], tr))
    return items


def ships_from_tracks(
    tracks: Mapping[Any, Mapping[str, ArrayLike]] | Iterable[Mapping[str, Any]],
    *,
    default_length: float = _DEFAULT_LENGTH,
) -> list[Ship]:
    """Ships from per-vessel arrays — the hook for rendering AIS traffic.

    ``tracks`` maps an object id (e.g. an MMSI) to a mapping with arrays ``time`` [s],
    ``north`` [m], ``east`` [m] (the vessel's position in the camera's tangent plane) and
    optionally ``heading`` [rad] (NaN where unknown: filled with the course over ground
    from the positions, or the nearest known heading when the vessel is stopped),
    ``length`` [m] (scalar or array; NaN/missing: ``default_length``), ``beam`` [m] and
    ``kind`` (:data:`KINDS`; default by length). A sequence of such mappings with an
    ``object_id`` key is accepted too. Samples are sorted by time; repeated times keep
    the first sample. A vessel with fewer than two samples is skipped with a warning.
    """
    ships: list[Ship] = []
    for key, tr in _track_items(tracks):
        for name in ("time", "north", "east"):
            if name not in tr:
                raise ValueError(f"tracks[{key!r}]: missing array {name!r}")
        t = as_float_array(f"tracks[{key!r}].time", tr["time"], ndim=1)
        n = as_float_array(f"tracks[{key!r}].north", tr["north"], ndim=1)
        e = as_float_array(f"tracks[{key!r}].east", tr["east"], ndim=1)
        if not (t.shape == n.shape == e.shape):
            raise ValueError(f"tracks[{key!r}]: time, north, east must have the same length")
        hd = tr.get("heading")
        h = np.full(t.shape, np.nan) if hd is None else as_float_array("heading", hd, ndim=(0, 1))
        h = np.broadcast_to(h, t.shape).astype(np.float64)
        ok = np.isfinite(t) & np.isfinite(n) & np.isfinite(e)
        t, n, e, h = t[ok], n[ok], e[ok], h[ok]
        order = np.argsort(t, kind="stable")
        t, n, e, h = t[order], n[order], e[order], h[order]
        keep = np.concatenate([[True], np.diff(t) > 0.0]) if t.size else np.zeros(0, bool)
        t, n, e, h = t[keep], n[keep], e[keep], h[keep]
        if t.size < 2:
            warnings.warn(
                f"tracks[{key!r}]: fewer than two samples with a time and position; skipped",
                stacklevel=2,
            )
            continue
        h = _fill_heading(t, n, e, h)
        length = _scalar_length(tr.get("length"), default_length)
        beam_v = tr.get("beam")
        beam = None
        if beam_v is not None:
            bv = np.asarray(beam_v, dtype=np.float64)
            bv = bv[np.isfinite(bv) & (bv > 0)]
            beam = float(np.median(bv)) if bv.size else None
        kind = tr.get("kind")
        oid = int(key) if not isinstance(key, int) else key
        ships.append(make_ship(oid, Trajectory(t, n, e, h), length, kind=kind, beam=beam))
    return ships


def _scalar_length(value: Any, default: float) -> float:
    if value is None:
        return default
    v = np.asarray(value, dtype=np.float64).ravel()
    v = v[np.isfinite(v) & (v > 0.0)]
    return float(np.median(v)) if v.size else default


def _fill_heading(t: FloatArray, n: FloatArray, e: FloatArray, h: FloatArray) -> FloatArray:
    """Unknown headings (NaN) ← course over ground; stopped vessels ← nearest known value."""
    h = h.copy()
    missing = ~np.isfinite(h)
    if not np.any(missing):
        return h
    dn = np.gradient(n, t)
    de = np.gradient(e, t)
    moving = np.hypot(dn, de) > 0.2
    cog = np.arctan2(de, dn)
    fill = missing & moving
    h[fill] = cog[fill]
    still = ~np.isfinite(h)
    if np.any(still):
        known = np.flatnonzero(np.isfinite(h))
        if known.size == 0:
            h[:] = 0.0
        else:
            idx = np.flatnonzero(still)
            nearest = known[np.argmin(np.abs(t[idx, None] - t[None, known]), axis=1)]
            h[idx] = h[nearest]
    return h
