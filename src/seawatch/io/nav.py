"""Platform navigation (NAV) input: the position and attitude of a moving camera platform.

The edge where NAV units become SI (STYLE.md): heading, course, pitch and roll in degrees
become radians (heading and course in [0, 2π), clockwise from true North), speeds in knots
become m/s, times become seconds (since 1970-01-01 UTC when the file gives dates).
Positions are kept both as WGS-84 latitude/longitude [deg] (as everywhere in
:mod:`seawatch.geometry.geodesy`) and as (north, east) [m] in the local tangent plane at
``(lat0, lon0)`` (:func:`seawatch.geometry.geodetic_to_north_east`; default origin: the
first fix). Attitude conventions are the camera's (:class:`seawatch.camera.PinholeCamera`):
pitch positive bow-up, roll positive starboard-down.

Two file kinds, told apart by the first line that is neither blank nor a ``#`` comment
(a line starting with ``$``, ``!`` or ``\\`` is NMEA 0183, anything else a CSV header):

CSV (:func:`read_nav_csv`)
    A header row, then one row per epoch. Columns (case-insensitive, aliases in
    :data:`CSV_COLUMNS`): ``time`` (seconds, e.g. since the epoch or since the start of
    the recording, or ISO 8601 date-time, naive = UTC); a position: ``lat``/``lon``
    [deg], or ``north``/``east`` [m], or ``x``/``y`` [m] (seawatch's frame: x North,
    y East) in the tangent plane at ``(lat0, lon0)``; ``heading`` [deg]; optional
    ``pitch``, ``roll`` [deg], ``height`` (camera height above the sea [m]), ``course``
    [deg] and ``speed`` (``speed``/``speed_mps`` in m/s; ``sog``/``sog_knots``/
    ``speed_kn`` in knots). A row may leave the position or the heading empty (a
    heading-only or position-only epoch).

NMEA 0183 (:func:`read_nav_nmea`, decoded with pynmea2)
    ``GGA`` (fix quality > 0) and ``RMC`` (status ``A``) give positions and UTC
    times of day, ``RMC`` and ``ZDA`` the date, ``HDT`` the true heading, ``VTG`` and
    ``RMC`` course and speed over ground, ``$PASHR`` (attitude) heading, roll and pitch
    with its own time. Sentences without a time (``HDT``, ``VTG``) belong to the epoch of
    the latest timed sentence before them (the first of each kind after it counts).
    Times of day are unwrapped across midnight and dated by the first ``RMC``/``ZDA``
    date (``date=`` for files without one; otherwise the times are seconds since
    midnight of the first day, with a :class:`NavWarning`). Tag blocks (``\\…\\``) are
    stripped; other sentence types, AIS sentences (``!AIVDM``/``!AIVDO``) included, are
    ignored (``counts["ignored"]``). GGA's altitude is the antenna's, not the camera's
    height, and is not used.

Heading from course: where no true heading is known within :data:`MAX_GAP` seconds of
an epoch but its course over ground is (VTG/RMC or a ``course`` column) and the speed is
unknown or at least :data:`MIN_COURSE_SPEED`, the heading is taken as the course over
ground (flagged in :attr:`NavTrack.heading_from_course`): the bow points along the track
when the vessel makes way, up to drift and leeway of a few degrees.

Bad input is counted and skipped, never fatal: unparsable rows or sentences, wrong
checksums, positions outside [−90, 90]° × [−180, 180]°, NMEA sentences without a fix,
repeated times (the first row in file order is kept). Each skipped line raises a
:class:`NavWarning` naming the file and line (the first :data:`MAX_WARNINGS`, then one
summary warning); :attr:`NavTrack.skipped` and :attr:`NavTrack.counts` keep them all. A
missing file raises ``FileNotFoundError``; a file without the required columns, without
any usable position fix or without any heading or course raises ``ValueError`` naming
the file and what is missing.

Time alignment with a video: a frame at video time ``t`` [s] has the NAV pose
``track.pose_at(t + t0)``, where ``t0`` is the NAV time of the video's first frame,
given by the user (``--start``, parsed by :func:`parse_time`). Outside the NAV span the
pose is extrapolated linearly for at most ``max_extrapolation`` (1 s), then unknown
(:meth:`NavTrack.pose_at`).
"""

from __future__ import annotations

import csv
import math
import os
import warnings
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seawatch._validation import FloatArray, as_float_array, positive
from seawatch.geometry.geodesy import geodetic_to_north_east, north_east_to_geodetic
from seawatch.io.ais import MAX_WARNINGS, SkippedRow, _existing_file, _warn_skipped

__all__ = [
    "CSV_COLUMNS",
    "KNOT",
    "MAX_EXTRAPOLATION",
    "MAX_GAP",
    "MAX_WARNINGS",
    "MIN_COURSE_SPEED",
    "NavPoses",
    "NavTrack",
    "NavWarning",
    "parse_time",
    "read_nav",
    "read_nav_csv",
    "read_nav_nmea",
]

KNOT = 1852.0 / 3600.0
"""One knot [m/s]."""
MAX_EXTRAPOLATION = 1.0
"""Longest linear extrapolation beyond NAV data [s] (issue 7: "at most 1 s")."""
MAX_GAP = 10.0
"""Longest gap between NAV samples [s] bridged by interpolation (a 1 Hz GNSS that drops
a few fixes is still bridged; a longer outage is unknown apart from the extrapolation
allowance at its ends)."""
MIN_COURSE_SPEED = 0.5
"""Slowest speed [m/s] (about 1 kn) at which course over ground stands in for heading."""

CSV_COLUMNS: Mapping[str, tuple[str, ...]] = {
    "time": ("time", "t", "time_s", "timestamp", "datetime", "utc"),
    "lat": ("lat", "latitude", "lat_deg", "latitude_deg", "latitude_degrees"),
    "lon": ("lon", "long", "lng", "longitude", "lon_deg", "longitude_deg", "longitude_degrees"),
    "north": ("north", "north_m", "n"),
    "east": ("east", "east_m", "e"),
    "x": ("x", "x_m"),
    "y": ("y", "y_m"),
    "heading": ("heading", "heading_deg", "hdg", "true_heading", "yaw", "yaw_deg"),
    "pitch": ("pitch", "pitch_deg"),
    "roll": ("roll", "roll_deg"),
    "height": ("height", "height_m", "camera_height"),
    "course": ("course", "course_deg", "cog", "cog_deg", "cog_degrees"),
    "speed": ("speed", "speed_mps", "sog_mps"),
    "speed_kn": ("sog", "sog_knots", "speed_kn", "speed_knots", "sog_kn"),
}
"""Accepted CSV header names per field (case-insensitive). ``x``/``y`` are North/East."""


class NavWarning(UserWarning):
    """NAV input problem: a skipped line, or poses requested outside the NAV data."""


# ==========================================================================================
# time
# ==========================================================================================


def parse_time(value: str | float, name: str = "time") -> float:
    """A user time → seconds: a number (seconds, e.g. since 1970-01-01 UTC) or ISO 8601.

    ISO 8601 date-times without a zone are UTC; ``Z`` and ``±hh:mm`` offsets are honoured
    (``2016-01-12T13:02:11Z``, ``2016-01-12 13:02:11.5``, ``1452603731.5`` are the same
    instant). Used for ``seawatch track --start`` (the NAV/AIS time of the video's first
    frame) and for CSV time columns.

    Args:
        value: the time, as text or a number.
        name: the argument's name for the error message.

    Returns:
        Seconds (since 1970-01-01 UTC for a date-time).

    Raises:
        ValueError: naming ``name``, when the value is neither a finite number nor an ISO
            8601 date-time.
    """
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
        v = float(value)
        if not math.isfinite(v):
            raise ValueError(f"{name}: expected a finite time, got {value!r}")
        return v
    if not isinstance(value, str):
        raise ValueError(f"{name}: expected seconds or an ISO 8601 date-time, got {value!r}")
    s = value.strip()
    try:
        v = float(s)
    except ValueError:
        pass
    else:
        if not math.isfinite(v):
            raise ValueError(f"{name}: expected a finite time, got {value!r}")
        return v
    iso = s[:-1] + "+00:00" if s.endswith(("Z", "z")) else s
    try:
        dt = datetime.fromisoformat(iso)
    except ValueError:
        raise ValueError(
            f"{name}: expected seconds or an ISO 8601 UTC date-time "
            f"(e.g. 2016-01-12T13:02:11Z), got {value!r}"
        ) from None
    if dt.tzinfo is None:
        dt = dt.replace(tzinfo=UTC)
    return dt.timestamp()


# ==========================================================================================
# results
# ==========================================================================================


@dataclass(frozen=True, eq=False)
class NavPoses:
    """Platform poses at requested times (:meth:`NavTrack.pose_at`).

    Attributes:
        time: the requested times [s], (T,).
        north, east: platform position in the NAV tangent plane [m], (T,).
        lat, lon: the same positions [deg], (T,); NaN if the NAV has no geodetic origin.
        heading: true heading [rad] in [0, 2π), clockwise from North, (T,).
        pitch, roll: attitude [rad] (bow-up, starboard-down positive), (T,); NaN where
            the NAV has none.
        height: camera height above the sea [m], (T,); NaN where the NAV has none.
        velocity: platform velocity (v_north, v_east) [m/s] of the position segment
            used, (T, 2).
        valid: True where position and heading are known (interpolated, or extrapolated
            by at most ``max_extrapolation``), (T,); every other field is NaN elsewhere.
        extrapolated: True where a valid pose was extrapolated rather than
            interpolated, (T,).
    """

    time: FloatArray
    north: FloatArray
    east: FloatArray
    lat: FloatArray
    lon: FloatArray
    heading: FloatArray
    pitch: FloatArray
    roll: FloatArray
    height: FloatArray
    velocity: FloatArray
    valid: NDArray[np.bool_]
    extrapolated: NDArray[np.bool_]

    def __len__(self) -> int:
        return int(self.time.size)


_FIELDS = ("north", "east", "lat", "lon", "heading", "pitch", "roll", "height", "speed", "course")


@dataclass(frozen=True, eq=False)
class NavTrack:
    """A platform's navigation record, one row per epoch, strictly increasing in time.

    A row may lack its position (NaN north/east/lat/lon: a heading-only epoch) or its
    heading (NaN); :meth:`pose_at` interpolates each quantity over the rows where it is
    known. Build one from a file with :func:`read_nav`, or from arrays with
    :meth:`from_arrays`.

    Attributes:
        time: epoch times [s], (N,), strictly increasing.
        north, east: position in the tangent plane at (lat0, lon0) [m], (N,).
        lat, lon: WGS-84 position [deg], (N,); NaN if the origin is unknown.
        heading: true heading [rad] in [0, 2π), (N,); NaN where unknown.
        pitch, roll: attitude [rad], (N,); NaN where unknown.
        height: camera height above the sea [m], (N,); NaN where unknown.
        speed: speed over ground [m/s], (N,); NaN where unknown.
        course: course over ground [rad] in [0, 2π), (N,); NaN where unknown.
        heading_from_course: True where the heading is the course over ground, (N,).
        lat0, lon0: origin of the tangent plane [deg]; NaN if the file had only local
            north/east and no origin was given.
        source: the file read ("" if built from arrays).
        skipped: every skipped line, in file order.
        counts: ``rows`` (data rows or sentences seen), ``kept`` (epochs), ``skipped``,
            one count per skip reason, and reader-specific counts (NMEA: ``fixes``,
            ``headings``, ``ignored``, ``untimed``).
    """

    time: FloatArray
    north: FloatArray
    east: FloatArray
    lat: FloatArray
    lon: FloatArray
    heading: FloatArray
    pitch: FloatArray
    roll: FloatArray
    height: FloatArray
    speed: FloatArray
    course: FloatArray
    heading_from_course: NDArray[np.bool_]
    lat0: float = math.nan
    lon0: float = math.nan
    source: str = ""
    skipped: tuple[SkippedRow, ...] = ()
    counts: Mapping[str, int] = field(default_factory=dict)

    def __post_init__(self) -> None:
        t = self.time
        if t.ndim != 1 or t.size == 0:
            raise ValueError(f"time: expected a non-empty 1-D array, got shape {t.shape}")
        if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0.0):
            raise ValueError("time: expected finite, strictly increasing times [s]")
        for name in (*_FIELDS, "heading_from_course"):
            if getattr(self, name).shape != t.shape:
                raise ValueError(
                    f"{name}: expected shape {t.shape} (one value per epoch), "
                    f"got {getattr(self, name).shape}"
                )

    def __len__(self) -> int:
        return int(self.time.size)

    @property
    def span(self) -> tuple[float, float]:
        """(first, last) time [s] at which both a position and a heading are known."""
        pos = np.isfinite(self.north) & np.isfinite(self.east)
        hd = np.isfinite(self.heading)
        if not (pos.any() and hd.any()):
            return math.nan, math.nan
        return (
            max(float(self.time[pos][0]), float(self.time[hd][0])),
            min(float(self.time[pos][-1]), float(self.time[hd][-1])),
        )

    @classmethod
    def from_arrays(
        cls,
        time: ArrayLike,
        north: ArrayLike,
        east: ArrayLike,
        heading: ArrayLike,
        *,
        pitch: ArrayLike | None = None,
        roll: ArrayLike | None = None,
        height: ArrayLike | None = None,
        lat0: float = math.nan,
        lon0: float = math.nan,
        source: str = "",
    ) -> NavTrack:
        """A NAV track from arrays in SI units (e.g. a simulated platform).

        Args:
            time: epoch times [s], (N,), strictly increasing.
            north, east: positions in the tangent plane at (lat0, lon0) [m], (N,).
            heading: true heading [rad], (N,) (wrapped to [0, 2π)).
            pitch, roll: attitude [rad], (N,), optional. height: camera height [m].
            lat0, lon0: the plane's geodetic origin [deg] (NaN: none; lat/lon are NaN).
            source: a name for messages.
        """
        t = as_float_array("time", time, ndim=1)
        arrays: dict[str, FloatArray] = {}
        for name, value in (("north", north), ("east", east), ("heading", heading)):
            arrays[name] = _same_length(name, value, t.size)
        for name, opt in (("pitch", pitch), ("roll", roll), ("height", height)):
            arrays[name] = (
                np.full(t.size, np.nan) if opt is None else _same_length(name, opt, t.size)
            )
        arrays["heading"] = np.mod(arrays["heading"], 2.0 * np.pi)
        la0, lo0 = _check_origin(lat0, lon0, allow_nan=True)
        lat, lon = _geodetic(arrays["north"], arrays["east"], la0, lo0)
        nan = np.full(t.size, np.nan)
        return cls(
            time=t,
            lat=lat,
            lon=lon,
            speed=nan,
            course=nan.copy(),
            heading_from_course=np.zeros(t.size, dtype=bool),
            lat0=la0,
            lon0=lo0,
            source=source,
            **arrays,
        )

    def pose_at(
        self,
        times: ArrayLike,
        *,
        max_extrapolation: float = MAX_EXTRAPOLATION,
        max_gap: float = MAX_GAP,
    ) -> NavPoses:
        """Platform pose at arbitrary times: linear interpolation, ≤ 1 s extrapolation.

        Each quantity (north, east, heading, pitch, roll, height) is interpolated over
        the epochs where it is known. Samples closer than ``max_gap`` in time form a
        run; inside a run the value is the linear interpolation between the two
        samples around the time (headings unwrapped first, so 359° → 1° passes through
        North; result wrapped to [0, 2π)). Outside every run, within
        ``max_extrapolation`` of the nearest run end, it is extrapolated linearly with
        the slope of that end's segment (held constant for a one-sample run); farther
        away it is unknown. A pose is ``valid`` where position and heading are both
        known; pitch, roll and height are NaN where unknown without affecting validity
        (the camera file's values stand in). Invalid poses are NaN throughout.

        One :class:`NavWarning` per call if any requested time is not inside a run,
        giving how many seconds of the requested span are not covered, how many poses
        were extrapolated and how many are unknown.

        Args:
            times: requested times [s] on the NAV clock (video time + the NAV time of
                the first frame), (T,) or scalar.
            max_extrapolation: longest extrapolation [s], >= 0.
            max_gap: longest gap between samples bridged by interpolation [s], > 0.

        Returns:
            NavPoses.
        """
        tq = np.atleast_1d(as_float_array("times", times, ndim=(0, 1)))
        ext = positive("max_extrapolation", max_extrapolation, allow_zero=True)
        gap = positive("max_gap", max_gap)
        pos_ok = np.isfinite(self.north) & np.isfinite(self.east)
        north, vn, cov_p, run_p, _ = _interp(self.time, self.north, pos_ok, tq, ext, gap)
        east, ve, _, _, _ = _interp(self.time, self.east, pos_ok, tq, ext, gap)
        hd_ok = np.isfinite(self.heading)
        unwrapped = np.full(self.time.size, np.nan)
        unwrapped[hd_ok] = np.unwrap(self.heading[hd_ok])
        heading, _, cov_h, run_h, _ = _interp(self.time, unwrapped, hd_ok, tq, ext, gap)
        heading = np.mod(heading, 2.0 * np.pi)
        extra = {}
        for name in ("pitch", "roll", "height"):
            v = getattr(self, name)
            extra[name] = _interp(self.time, v, np.isfinite(v), tq, ext, gap)[0]
        valid = cov_p & cov_h & np.isfinite(tq)
        inside = run_p & run_h & valid
        out = {
            "north": north,
            "east": east,
            "heading": heading,
            **extra,
        }
        for k in out:
            out[k] = np.where(valid, out[k], np.nan)
        vel = np.where(valid[:, None], np.stack([vn, ve], axis=-1), np.nan)
        lat, lon = _geodetic(out["north"], out["east"], self.lat0, self.lon0)
        if not np.all(inside):
            self._warn_coverage(tq, pos_ok, hd_ok, gap, ext, valid, inside)
        return NavPoses(
            time=tq,
            lat=lat,
            lon=lon,
            velocity=vel,
            valid=valid,
            extrapolated=valid & ~inside,
            **out,
        )

    def _warn_coverage(
        self,
        tq: FloatArray,
        pos_ok: NDArray[np.bool_],
        hd_ok: NDArray[np.bool_],
        gap: float,
        ext: float,
        valid: NDArray[np.bool_],
        inside: NDArray[np.bool_],
    ) -> None:
        name = Path(self.source).name if self.source else "NAV"
        finite = tq[np.isfinite(tq)]
        n_ext = int(np.sum(valid & ~inside))
        n_bad = int(np.sum(~valid))
        if finite.size == 1:
            what = (
                f"the requested time {_fmt_time(float(finite[0]))} is not covered by the NAV data"
            )
        elif finite.size:
            lo, hi = float(finite.min()), float(finite.max())
            covered = _intersect(_runs(self.time[pos_ok], gap), _runs(self.time[hd_ok], gap))
            within = sum(max(0.0, min(b, hi) - max(a, lo)) for a, b in covered)
            missing = (hi - lo) - within
            s0, s1 = self.span
            what = (
                f"{missing:.3g} s of the requested {hi - lo:.3g} s "
                f"({_fmt_time(lo)} to {_fmt_time(hi)}) are not covered by the NAV data "
                f"({_fmt_time(s0)} to {_fmt_time(s1)}, gaps over {gap:g} s not bridged)"
            )
        else:
            what = "no requested time is finite"
        warnings.warn(
            NavWarning(
                f"{name}: {what}: {n_ext} of {tq.size} poses extrapolated by at most "
                f"{ext:g} s, {n_bad} marked unknown"
            ),
            stacklevel=3,
        )


def _fmt_time(t: float) -> str:
    """A time for messages: ISO 8601 UTC if it looks like epoch seconds, else seconds."""
    if math.isfinite(t) and abs(t) > 1e8:
        return datetime.fromtimestamp(t, UTC).isoformat(timespec="milliseconds")
    return f"{t:.3f} s"


def _same_length(name: str, value: ArrayLike, n: int) -> FloatArray:
    arr = as_float_array(name, value, ndim=1)
    if arr.size != n:
        raise ValueError(f"{name}: expected {n} values (one per time), got {arr.size}")
    return arr


def _check_origin(lat0: Any, lon0: Any, *, allow_nan: bool) -> tuple[float, float]:
    try:
        la, lo = float(lat0), float(lon0)
    except (TypeError, ValueError):
        raise ValueError(f"lat0/lon0: expected numbers [deg], got {lat0!r}, {lon0!r}") from None
    if allow_nan and math.isnan(la) and math.isnan(lo):
        return la, lo
    if not (math.isfinite(la) and abs(la) <= 90.0):
        raise ValueError(f"lat0: expected a latitude in [-90, 90] deg, got {lat0!r}")
    if not (math.isfinite(lo) and abs(lo) <= 180.0):
        raise ValueError(f"lon0: expected a longitude in [-180, 180] deg, got {lon0!r}")
    return la, lo


def _geodetic(
    north: FloatArray, east: FloatArray, lat0: float, lon0: float
) -> tuple[FloatArray, FloatArray]:
    """(lat, lon) [deg] of tangent-plane points; NaN where unknown or without an origin."""
    lat = np.full(north.shape, np.nan)
    lon = np.full(north.shape, np.nan)
    ok = np.isfinite(north) & np.isfinite(east)
    if math.isfinite(lat0) and math.isfinite(lon0) and np.any(ok):
        la, lo = north_east_to_geodetic(np.stack([north[ok], east[ok]], -1), lat0, lon0)
        lat[ok] = la
        lon[ok] = lo
    return lat, lon


def _runs(t: FloatArray, gap: float) -> list[tuple[float, float]]:
    """Intervals [first, last] of samples whose consecutive spacing is at most ``gap``."""
    if t.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(t) > gap)
    starts = np.r_[0, breaks + 1]
    ends = np.r_[breaks, t.size - 1]
    return [(float(t[a]), float(t[b])) for a, b in zip(starts, ends, strict=True)]


def _intersect(
    a: list[tuple[float, float]], b: list[tuple[float, float]]
) -> list[tuple[float, float]]:
    """Intersection of two sorted lists of disjoint closed intervals."""
    out = []
    i = j = 0
    while i < len(a) and j < len(b):
        lo = max(a[i][0], b[j][0])
        hi = min(a[i][1], b[j][1])
        if lo <= hi:
            out.append((lo, hi))
        if a[i][1] < b[j][1]:
            i += 1
        else:
            j += 1
    return out


def _interp(
    t_all: FloatArray,
    v_all: FloatArray,
    known: NDArray[np.bool_],
    tq: FloatArray,
    ext: float,
    gap: float,
) -> tuple[FloatArray, FloatArray, NDArray[np.bool_], NDArray[np.bool_], NDArray[np.bool_]]:
    """Piecewise-linear interpolation inside runs, bounded linear extrapolation outside.

    Returns (value, slope [per s], known, inside a run, extrapolated), each (T,).
    """
    T = tq.size
    val = np.full(T, np.nan)
    slope = np.full(T, np.nan)
    inside = np.zeros(T, dtype=bool)
    t = t_all[known]
    v = v_all[known]
    n = t.size
    if n == 0:
        return val, slope, inside.copy(), inside, inside.copy()
    seg_dt = np.diff(t)
    seg_ok = seg_dt <= gap
    seg_slope = np.where(seg_ok, np.diff(v) / np.where(seg_ok, seg_dt, 1.0), 0.0)
    fin = np.isfinite(tq)
    tqs = np.where(fin, tq, t[0] - 2 * gap - ext - 1.0)
    i = np.searchsorted(t, tqs, side="right") - 1  # last sample at or before tq
    # exact hits and interior points of a bridged segment
    exact = (i >= 0) & (t[np.clip(i, 0, n - 1)] == tqs)
    if n >= 2:
        lo = np.clip(i, 0, n - 2)
        in_seg = (i >= 0) & (i <= n - 2) & seg_ok[lo]
        s = (tqs - t[lo]) / np.where(in_seg, seg_dt[lo], 1.0)
        val = np.where(in_seg, v[lo] + s * (v[lo + 1] - v[lo]), val)
        slope = np.where(in_seg, seg_slope[lo], slope)
        inside |= in_seg
    ie = np.clip(i, 0, n - 1)
    hit = exact & ~inside
    if np.any(hit):
        val[hit] = v[ie[hit]]
        # the slope of the segment ending at the sample (0 if none or a gap)
        if n >= 2:
            slope[hit] = np.where(ie[hit] >= 1, seg_slope[np.clip(ie[hit] - 1, 0, n - 2)], 0.0)
        else:
            slope[hit] = 0.0
    inside |= exact
    # extrapolation from the nearest run end within ext
    rest = ~inside & fin
    if np.any(rest):
        left = np.clip(i, 0, n - 1)  # run end before tq (valid if i >= 0)
        right = np.clip(i + 1, 0, n - 1)  # run start after tq (valid if i + 1 < n)
        d_left = np.where(i >= 0, tqs - t[left], np.inf)
        d_right = np.where(i + 1 < n, t[right] - tqs, np.inf)
        use_left = rest & (d_left <= d_right) & (d_left <= ext)
        use_right = rest & ~use_left & (d_right <= ext)
        if n >= 2:
            sl_left = np.where(left >= 1, seg_slope[np.clip(left - 1, 0, n - 2)], 0.0)
            sl_right = np.where(right <= n - 2, seg_slope[np.clip(right, 0, n - 2)], 0.0)
        else:
            sl_left = sl_right = np.zeros(T)
        val = np.where(use_left, v[left] + sl_left * np.where(use_left, d_left, 0.0), val)
        slope = np.where(use_left, sl_left, slope)
        val = np.where(use_right, v[right] - sl_right * np.where(use_right, d_right, 0.0), val)
        slope = np.where(use_right, sl_right, slope)
        extrap = use_left | use_right
    else:
        extrap = np.zeros(T, dtype=bool)
    return val, slope, inside | extrap, inside, extrap


# ==========================================================================================
# shared reading helpers
# ==========================================================================================


def _position_problem(lat: float, lon: float) -> str | None:
    if not (math.isfinite(lat) and math.isfinite(lon)):
        return "latitude/longitude not finite"
    if abs(lat) > 90.0 or abs(lon) > 180.0:
        return f"latitude {lat:g} / longitude {lon:g} outside [-90, 90] x [-180, 180] deg"
    return None


def _finish(
    p: Path,
    rows: dict[str, list[float]],
    skipped: list[SkippedRow],
    n_rows: int,
    *,
    local: bool,
    lat0: float | None,
    lon0: float | None,
    extra_counts: Mapping[str, int] | None = None,
) -> NavTrack:
    """Sort, deduplicate, convert to the tangent plane, fill heading from course, check."""
    t = np.asarray(rows["time"], dtype=np.float64)
    line = np.asarray(rows["line"], dtype=np.int64)
    order = np.lexsort((line, t))
    t = t[order]
    cols = {k: np.asarray(v, dtype=np.float64)[order] for k, v in rows.items() if k != "time"}
    dup = np.r_[False, np.diff(t) == 0.0]
    for k in np.flatnonzero(dup):
        skipped.append(
            SkippedRow(
                int(cols["line"][k]),
                "duplicate time",
                f"time {t[k]:.6g} s already read; kept the first",
            )
        )
    keep = ~dup
    t = t[keep]
    cols = {k: v[keep] for k, v in cols.items()}
    skipped.sort(key=lambda s: s.line)
    pos_ok = np.isfinite(cols["a"]) & np.isfinite(cols["b"])
    if not np.any(pos_ok):
        _warn_skipped(p, skipped, n_rows, NavWarning, "lines")
        raise ValueError(f"{p}: no usable position fix in {n_rows} rows")
    # heading from course over ground where no true heading is near (module docstring)
    heading = np.mod(cols["heading"], 2.0 * np.pi)
    course = cols["course"]
    speed = cols["speed"]
    has_hd = np.isfinite(heading)
    if np.any(has_hd):
        th = t[has_hd]
        j = np.searchsorted(th, t)
        d_next = np.where(j < th.size, th[np.minimum(j, th.size - 1)] - t, np.inf)
        d_prev = np.where(j > 0, t - th[np.maximum(j - 1, 0)], np.inf)
        near = np.minimum(d_next, d_prev) <= MAX_GAP
    else:
        near = np.zeros(t.size, dtype=bool)
    moving = ~np.isfinite(speed) | (speed >= MIN_COURSE_SPEED)
    from_course = ~has_hd & ~near & np.isfinite(course) & moving
    heading = np.where(from_course, course, heading)
    if not np.any(np.isfinite(heading)):
        _warn_skipped(p, skipped, n_rows, NavWarning, "lines")
        raise ValueError(
            f"{p}: no heading: the file has no true heading (a heading column, HDT or "
            f"$PASHR) and no course over ground while making way (course/VTG/RMC at "
            f">= {MIN_COURSE_SPEED} m/s)"
        )
    if local:
        north, east = cols["a"], cols["b"]
        la0, lo0 = (
            (math.nan, math.nan)
            if lat0 is None and lon0 is None
            else _check_origin(lat0, lon0, allow_nan=False)
        )
        lat, lon = _geodetic(north, east, la0, lo0)
    else:
        lat, lon = cols["a"], cols["b"]
        if lat0 is None and lon0 is None:
            first = int(np.flatnonzero(pos_ok)[0])
            la0, lo0 = float(lat[first]), float(lon[first])
        else:
            la0, lo0 = _check_origin(lat0, lon0, allow_nan=False)
        north = np.full(t.size, np.nan)
        east = np.full(t.size, np.nan)
        ne = geodetic_to_north_east(lat[pos_ok], lon[pos_ok], la0, lo0)
        north[pos_ok] = ne[..., 0]
        east[pos_ok] = ne[..., 1]
    counts = {"rows": n_rows, "kept": int(t.size), "skipped": len(skipped)}
    counts.update(Counter(s.reason for s in skipped))
    counts.update(extra_counts or {})
    counts["heading_from_course"] = int(np.sum(from_course))
    _warn_skipped(p, skipped, n_rows, NavWarning, "lines")
    return NavTrack(
        time=t,
        north=north,
        east=east,
        lat=lat,
        lon=lon,
        heading=heading,
        pitch=cols["pitch"],
        roll=cols["roll"],
        height=cols["height"],
        speed=speed,
        course=course,
        heading_from_course=from_course,
        lat0=la0,
        lon0=lo0,
        source=str(p),
        skipped=tuple(skipped),
        counts=counts,
    )


_ROW_KEYS = ("time", "a", "b", "heading", "pitch", "roll", "height", "speed", "course", "line")


# ==========================================================================================
# CSV
# ==========================================================================================


def _csv_columns(header: Sequence[str], p: Path) -> tuple[dict[str, int], bool]:
    names = [h.strip().lower() for h in header]
    where: dict[str, int] = {}
    for key, aliases in CSV_COLUMNS.items():
        for a in aliases:
            if a in names:
                where[key] = names.index(a)
                break
    missing = []
    if "time" not in where:
        missing.append("time")
    if "lat" in where and "lon" in where:
        local = False
    elif "north" in where and "east" in where:
        local = True
        where["a"], where["b"] = where["north"], where["east"]
    elif "x" in where and "y" in where:
        local = True
        where["a"], where["b"] = where["x"], where["y"]
    else:
        local = False
        missing.append("a position (lat and lon [deg], north and east [m], or x and y [m])")
    if not local and "lat" in where and "lon" in where:
        where["a"], where["b"] = where["lat"], where["lon"]
    if "heading" not in where and "course" not in where:
        missing.append("heading (or course) [deg]")
    if missing:
        raise ValueError(
            f"{p}: not a NAV table: missing column(s) {'; '.join(missing)} "
            f"(header: {', '.join(h.strip() for h in header)})"
        )
    return where, local


def read_nav_csv(
    path: str | os.PathLike[str], *, lat0: float | None = None, lon0: float | None = None
) -> NavTrack:
    """Read a NAV table from CSV (columns in the module docstring and :data:`CSV_COLUMNS`).

    Degrees become radians and knots m/s at this edge. Rows are sorted by time; a
    repeated time keeps the first row in file order.

    Args:
        path: the CSV file.
        lat0, lon0: origin of the local tangent plane [deg]. With lat/lon columns the
            default is the first fix; with north/east or x/y columns they give the
            plane's geodetic origin (default: none, lat/lon are NaN).

    Returns:
        NavTrack.

    Raises:
        FileNotFoundError: the file does not exist.
        ValueError: no header with a time, a position and a heading or course column;
            no usable position; no heading at all (message names the file).
    """
    p = _existing_file(path, "NAV")
    rows: dict[str, list[float]] = {k: [] for k in _ROW_KEYS}
    skipped: list[SkippedRow] = []
    n_rows = 0
    with p.open(newline="", encoding="utf-8", errors="replace") as fh:
        reader = csv.reader(fh)
        header: list[str] | None = None
        for row in reader:
            if not row or all(not c.strip() for c in row) or row[0].lstrip().startswith("#"):
                continue
            header = row
            break
        if header is None:
            raise ValueError(f"{p}: empty file, expected a NAV table with a header row")
        where, local = _csv_columns(header, p)
        width = len(header)
        for row in reader:
            line = reader.line_num
            if not row or all(not c.strip() for c in row) or row[0].lstrip().startswith("#"):
                continue
            n_rows += 1
            if len(row) != width:
                skipped.append(
                    SkippedRow(line, "unparsable", f"{len(row)} fields, expected {width}")
                )
                continue
            try:
                rec = _csv_record(row, where)
            except ValueError as exc:
                skipped.append(SkippedRow(line, "unparsable", str(exc)))
                continue
            if not local and math.isfinite(rec["a"]):
                problem = _position_problem(rec["a"], rec["b"])
                if problem is not None:
                    skipped.append(SkippedRow(line, "out of range", problem))
                    continue
            if not any(math.isfinite(rec[k]) for k in ("a", "heading", "pitch", "roll", "course")):
                skipped.append(SkippedRow(line, "empty", "no position, heading or attitude"))
                continue
            rec["line"] = line
            for k in _ROW_KEYS:
                rows[k].append(rec[k])
    if not rows["time"]:
        _warn_skipped(p, skipped, n_rows, NavWarning, "lines")
        raise ValueError(f"{p}: no usable position fix in {n_rows} rows")
    return _finish(p, rows, skipped, n_rows, local=local, lat0=lat0, lon0=lon0)


def _cell(row: Sequence[str], where: Mapping[str, int], key: str) -> float:
    """The float in column ``key`` (NaN if the column is absent or the cell empty)."""
    if key not in where:
        return math.nan
    text = row[where[key]].strip()
    if not text or text.lower() in ("nan", "na", "null", "none"):
        return math.nan
    try:
        v = float(text)
    except ValueError:
        raise ValueError(f"{key} {text!r} is not a number") from None
    if not math.isfinite(v):
        raise ValueError(f"{key} {text!r} is not finite")
    return v


def _csv_record(row: Sequence[str], where: Mapping[str, int]) -> dict[str, float]:
    rec = {"time": parse_time(row[where["time"]].strip(), "time")}
    a, b = _cell(row, where, "a"), _cell(row, where, "b")
    if math.isfinite(a) != math.isfinite(b):
        raise ValueError("only one of the two position coordinates is given")
    rec["a"], rec["b"] = a, b
    rec["heading"] = math.radians(_cell(row, where, "heading"))
    rec["pitch"] = math.radians(_cell(row, where, "pitch"))
    rec["roll"] = math.radians(_cell(row, where, "roll"))
    rec["height"] = _cell(row, where, "height")
    course = _cell(row, where, "course")
    rec["course"] = math.radians(course % 360.0) if math.isfinite(course) else math.nan
    speed = _cell(row, where, "speed")
    if not math.isfinite(speed):
        speed = _cell(row, where, "speed_kn") * KNOT
    rec["speed"] = speed
    return rec


# ==========================================================================================
# NMEA
# ==========================================================================================


def _tod_seconds(ts: Any) -> float:
    """Seconds since midnight of a pynmea2 ``datetime.time`` (else ValueError)."""
    if not hasattr(ts, "hour"):
        raise ValueError(f"bad time of day {ts!r}")
    return ts.hour * 3600.0 + ts.minute * 60.0 + ts.second + ts.microsecond * 1e-6


def _nmea_position(msg: Any) -> tuple[float, float]:
    if not (msg.lat and msg.lon and msg.lat_dir in ("N", "S") and msg.lon_dir in ("E", "W")):
        raise LookupError("no position")
    lat, lon = float(msg.latitude), float(msg.longitude)
    problem = _position_problem(lat, lon)
    if problem is not None:
        raise LookupError(problem)
    return lat, lon


def _float_or_nan(value: Any) -> float:
    if value is None or value == "":
        return math.nan
    try:
        v = float(value)
    except (TypeError, ValueError):
        return math.nan
    return v if math.isfinite(v) else math.nan


def read_nav_nmea(
    path: str | os.PathLike[str],
    *,
    lat0: float | None = None,
    lon0: float | None = None,
    date: str | None = None,
) -> NavTrack:
    """Read a NAV record from NMEA 0183 sentences (pynmea2; sentences in the module docstring).

    Epochs are the distinct UTC times of the timed sentences (GGA, RMC, ZDA, $PASHR);
    HDT and VTG join the epoch of the latest timed sentence before them (those before
    any timed sentence are counted in ``counts["untimed"]`` and dropped). Times of day
    are unwrapped across midnight (a jump back by more than 12 h is the next day) and
    dated by the first RMC or ZDA date, else by ``date``.

    Skipped, each with a :class:`NavWarning` naming the line: sentences pynmea2 cannot
    parse (``"unparsable"``), wrong checksums (``"bad checksum"``), GGA with fix quality
    0 or RMC with status V or an empty/out-of-range position (``"no fix"``). Other
    sentence types are ignored (``counts["ignored"]``).

    Args:
        path: text file of NMEA sentences.
        lat0, lon0: origin of the tangent plane [deg] (default: the first fix).
        date: UTC date (``YYYY-MM-DD``) of the first sentence, for files without RMC/ZDA.

    Returns:
        NavTrack (``counts`` adds ``fixes``, ``headings``, ``ignored``, ``untimed``).

    Raises:
        FileNotFoundError: the file does not exist.
        ValueError: no usable fix, no heading or course, or a bad ``date``.
    """
    import pynmea2

    p = _existing_file(path, "NAV")
    first_date: float | None = None
    if date is not None:
        try:
            d = datetime.fromisoformat(str(date).strip()).date()
        except ValueError:
            raise ValueError(f"date: expected an ISO date YYYY-MM-DD, got {date!r}") from None
        first_date = datetime(d.year, d.month, d.day, tzinfo=UTC).timestamp()
    epochs: dict[float, dict[str, float]] = {}
    skipped: list[SkippedRow] = []
    n_sent = n_ignored = n_untimed = n_fix = n_head = 0
    day = 0
    prev_tod: float | None = None
    current: float | None = None  # unwrapped time (s since midnight of day 0) of the epoch
    seen: set[str] = set()  # untimed kinds already attached to the current epoch
    anchor: tuple[float, float] | None = None  # (unwrapped time, epoch seconds) of a date

    def epoch(tod: float, line: int) -> float:
        nonlocal day, prev_tod, current, seen
        if prev_tod is not None:
            if tod < prev_tod - 43200.0:
                day += 1
            elif tod > prev_tod + 43200.0:
                day -= 1
        prev_tod = tod
        t = day * 86400.0 + tod
        if t != current:
            current = t
            seen = set()
        epochs.setdefault(t, {"line": float(line)})
        return t

    def put(t: float, key: str, value: float) -> None:
        rec = epochs[t]
        if key not in rec and math.isfinite(value):
            rec[key] = value

    with p.open("r", encoding="ascii", errors="replace") as fh:
        for line_no, raw in enumerate(fh, start=1):
            text = raw.strip()
            if not text or text.startswith("#"):
                continue
            if text.startswith("\\"):
                end = text.find("\\", 1)
                text = text[end + 1 :] if end > 0 else text
            n_sent += 1
            if text.startswith("!"):  # AIS (!AIVDM/!AIVDO) in a mixed log: not NAV
                n_ignored += 1
                continue
            if not text.startswith("$"):
                skipped.append(SkippedRow(line_no, "unparsable", f"not NMEA: {text[:60]!r}"))
                continue
            try:
                msg = pynmea2.parse(text)
            except pynmea2.ChecksumError:
                skipped.append(SkippedRow(line_no, "bad checksum", text[:100]))
                continue
            except pynmea2.SentenceTypeError:
                n_ignored += 1
                continue
            except (pynmea2.ParseError, ValueError, TypeError, AttributeError) as exc:
                skipped.append(SkippedRow(line_no, "unparsable", str(exc)[:100] or text[:100]))
                continue
            kind = type(msg).__name__
            try:
                if kind in ("GGA", "RMC"):
                    t = epoch(_tod_seconds(msg.timestamp), line_no)
                    if kind == "RMC":
                        ds = msg.datestamp
                        if anchor is None and hasattr(ds, "year"):
                            mid = datetime(ds.year, ds.month, ds.day, tzinfo=UTC).timestamp()
                            anchor = (t, mid + (t - day * 86400.0))
                    ok = (msg.gps_qual or 0) > 0 if kind == "GGA" else msg.status == "A"
                    if not ok:
                        raise LookupError(
                            "fix quality 0" if kind == "GGA" else f"status {msg.status!r}"
                        )
                    if kind == "RMC":
                        put(t, "course", _deg_to_rad(msg.true_course))
                        put(t, "speed", _float_or_nan(msg.spd_over_grnd) * KNOT)
                    lat, lon = _nmea_position(msg)
                    put(t, "a", lat)
                    put(t, "b", lon)
                    n_fix += 1
                elif kind == "ZDA":
                    t = epoch(_tod_seconds(msg.timestamp), line_no)
                    if anchor is None and msg.year and msg.month and msg.day:
                        mid = datetime(
                            int(msg.year), int(msg.month), int(msg.day), tzinfo=UTC
                        ).timestamp()
                        anchor = (t, mid + (t - day * 86400.0))
                elif kind == "ASHRATT":
                    t = epoch(_tod_seconds(msg.timestamp), line_no)
                    hd = _deg_to_rad(msg.true_heading)
                    put(t, "heading", hd)
                    put(t, "roll", _float_rad(msg.roll))
                    put(t, "pitch", _float_rad(msg.pitch))
                    n_head += int(math.isfinite(hd))
                elif kind in ("HDT", "VTG"):
                    if current is None:
                        n_untimed += 1
                        continue
                    if kind in seen:
                        continue
                    seen.add(kind)
                    if kind == "HDT":
                        hd = _deg_to_rad(msg.heading)
                        put(current, "heading", hd)
                        n_head += int(math.isfinite(hd))
                    else:
                        put(current, "course", _deg_to_rad(msg.true_track))
                        kn = _float_or_nan(msg.spd_over_grnd_kts)
                        if not math.isfinite(kn):
                            kn = _float_or_nan(msg.spd_over_grnd_kmph) / 1.852
                        put(current, "speed", kn * KNOT)
                else:
                    n_ignored += 1
            except LookupError as exc:
                skipped.append(SkippedRow(line_no, "no fix", f"{kind}: {exc}"))
            except (ValueError, TypeError, AttributeError) as exc:
                skipped.append(SkippedRow(line_no, "unparsable", f"{kind}: {exc}"[:100]))
    if anchor is not None:
        offset = anchor[1] - anchor[0]
    elif first_date is not None:
        offset = first_date
    else:
        offset = 0.0
        if epochs:
            warnings.warn(
                NavWarning(
                    f"{p}: no date (RMC or ZDA) in the file and no date given: times are "
                    "seconds since midnight UTC of the first day"
                ),
                stacklevel=2,
            )
    rows: dict[str, list[float]] = {k: [] for k in _ROW_KEYS}
    for t, rec in epochs.items():
        if not any(k in rec for k in ("a", "heading", "pitch", "roll", "course")):
            continue  # a time without anything usable (void fix, ZDA alone)
        rows["time"].append(t + offset)
        for k in _ROW_KEYS[1:]:
            rows[k].append(rec.get(k, math.nan))
    if not rows["time"]:
        _warn_skipped(p, skipped, n_sent, NavWarning, "lines")
        raise ValueError(f"{p}: no usable position fix in {n_sent} NMEA sentences")
    extra = {"fixes": n_fix, "headings": n_head, "ignored": n_ignored, "untimed": n_untimed}
    return _finish(p, rows, skipped, n_sent, local=False, lat0=lat0, lon0=lon0, extra_counts=extra)


def _deg_to_rad(value: Any) -> float:
    v = _float_or_nan(value)
    return math.radians(v % 360.0) if math.isfinite(v) else math.nan


def _float_rad(value: Any) -> float:
    v = _float_or_nan(value)
    return math.radians(v) if math.isfinite(v) else math.nan


# ==========================================================================================
# either kind
# ==========================================================================================


def read_nav(
    path: str | os.PathLike[str],
    *,
    lat0: float | None = None,
    lon0: float | None = None,
    date: str | None = None,
) -> NavTrack:
    """Read a NAV file of either kind: NMEA 0183 (:func:`read_nav_nmea`) or CSV.

    The kind is decided by the first line that is neither blank nor a ``#`` comment: a
    line starting with ``$``, ``!`` or ``\\`` means NMEA, anything else a CSV table.

    Args:
        path: the NAV file.
        lat0, lon0: origin of the local tangent plane [deg] (default: the first fix;
            for a CSV of local north/east, the plane's geodetic origin if known).
        date: UTC date of an NMEA file without RMC/ZDA sentences (ignored for CSV).

    Raises:
        FileNotFoundError: the file does not exist.
        ValueError: missing columns, no usable fix, no heading (message names the file).
    """
    p = _existing_file(path, "NAV")
    with p.open("rb") as fh:
        for raw in fh:
            text = raw.strip()
            if not text or text.startswith(b"#"):
                continue
            if text[:1] in (b"!", b"$", b"\\"):
                return read_nav_nmea(p, lat0=lat0, lon0=lon0, date=date)
            break
    return read_nav_csv(p, lat0=lat0, lon0=lon0)
