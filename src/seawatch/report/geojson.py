"""``tracks.geojson``: the tracks of ``seawatch track`` for QGIS and web maps (issue 7).

One GeoJSON FeatureCollection (RFC 7946: WGS-84 ``[lon, lat]`` positions in degrees)
with, per track, a LineString (a Point for a track with a single fix) whose properties
hold the track id, the MMSI (or null), the times of its vertices [s], the first/last time,
the mean speed and course; optionally one Point per fix with its time ("points with
times"), and a Point for the camera when its position is known. The file is rewritten
while the video is processed (about once per second of video) and replaced atomically
(temporary file + :func:`os.replace`), so a reader never sees half a file and a crash
loses at most the last rewrite interval.

The input is a track table (INTERFACES.md "Track table", the columns of
:data:`seawatch.pipeline.TRACK_TABLE_COLUMNS`), as a ``tracks.csv`` path or as rows
(mappings of column name → value; empty strings and None are missing values).
:func:`load_tracks` turns it into one :class:`TrackSeries` per track, which the HTML
report (:mod:`seawatch.report.html`) uses too.

Positions: a row's ``lat``/``lon`` columns; where those are empty but ``north_m``/``east_m``
are known and the camera's geodetic position is given, the position is mapped from the
tangent plane at the camera (:func:`seawatch.geometry.geodesy.north_east_to_geodetic`, as
:mod:`seawatch.pipeline` does). Rows with no position are skipped. Without
any geodetic position (no ``lat``/``lon`` in the table and no camera position) there is no
GeoJSON: :func:`tracks_to_geojson` returns None and warns.
"""

from __future__ import annotations

import csv
import json
import math
import os
import tempfile
import time as _time
import warnings
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from seawatch.geometry.geodesy import geodetic_to_north_east, north_east_to_geodetic

__all__ = [
    "GeoJsonSink",
    "TrackSeries",
    "atomic_write_text",
    "load_tracks",
    "tracks_to_geojson",
    "write_geojson",
]

FloatArray = NDArray[np.float64]
TrackSource = str | os.PathLike[str] | Iterable[Mapping[str, Any]]

KNOT = 1852.0 / 3600.0
"""One knot [m/s]."""

COORDINATE_DECIMALS = 7
"""Decimals of the longitudes/latitudes written [deg] (1e-7° ≈ 1.1 cm)."""

_NUMERIC = (
    "frame", "lat", "lon", "north_m", "east_m", "range_m", "sigma_range_m", "speed_mps",
    "course_deg",
)  # fmt: skip


# --------------------------------------------------------------------------------------
# the track table
# --------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class TrackSeries:
    """The rows of one track of a track table, sorted by time.

    Columns keep the track table's names and display units (degrees at this edge);
    missing values are NaN.

    Attributes:
        track_id: the track's id [-].
        mmsi: the MMSI the track was labelled with most often (digits), or None.
        time: time of each fix from the start of the video [s], (T,).
        frame: frame index of each fix [-], (T,) (NaN if the table has none).
        lat, lon: WGS-84 latitude and longitude [deg], (T,).
        north_m, east_m: position in the camera's local tangent plane [m], (T,).
        range_m, sigma_range_m: range from the camera and its 1-σ [m], (T,).
        speed_mps: speed over ground [m/s], (T,).
        course_deg: course over ground, clockwise from North [deg], (T,).
    """

    track_id: int
    mmsi: str | None
    time: FloatArray
    frame: FloatArray
    lat: FloatArray
    lon: FloatArray
    north_m: FloatArray
    east_m: FloatArray
    range_m: FloatArray
    sigma_range_m: FloatArray
    speed_mps: FloatArray
    course_deg: FloatArray

    def __len__(self) -> int:
        return int(self.time.size)

    def local_positions(self) -> FloatArray:
        """(T, 2) positions (North, East) [m]: the table's ``north_m``/``east_m`` where any are
        known, else the lat/lon mapped to the tangent plane at the first geodetic fix; NaN
        rows where unknown."""
        if np.any(np.isfinite(self.north_m) & np.isfinite(self.east_m)):
            return np.stack([self.north_m, self.east_m], axis=-1)
        ok = np.isfinite(self.lat) & np.isfinite(self.lon)
        out = np.full((len(self), 2), np.nan)
        if np.any(ok):
            k = int(np.argmax(ok))
            out[ok] = geodetic_to_north_east(
                self.lat[ok], self.lon[ok], float(self.lat[k]), float(self.lon[k])
            )
        return out

    def fitted_velocity(self) -> tuple[float, float]:
        """Constant-velocity least-squares fit of the positions: (v_north, v_east) [m/s].

        The slope of ``p(t) = p0 + v t`` fitted to every fix with a position (ordinary
        least squares per axis), NaN with fewer than two distinct times. On a straight
        constant-speed track this is the true velocity, and unlike a path length it does
        not grow with the position noise.
        """
        p = self.local_positions()
        ok = np.isfinite(p).all(axis=1) & np.isfinite(self.time)
        t = self.time[ok]
        if t.size < 2 or np.ptp(t) <= 0.0:
            return math.nan, math.nan
        dt = t - t.mean()
        denom = float(dt @ dt)
        vn, ve = (dt @ (p[ok] - p[ok].mean(axis=0))) / denom
        return float(vn), float(ve)

    def mean_speed(self) -> tuple[float, str]:
        """Mean speed [m/s] and where it comes from.

        The mean of the table's ``speed_mps`` where it has values (source ``"table"``),
        else the speed of :meth:`fitted_velocity` (source ``"fit"``), else NaN (``""``).
        """
        s = self.speed_mps[np.isfinite(self.speed_mps)]
        if s.size:
            return float(s.mean()), "table"
        vn, ve = self.fitted_velocity()
        if math.isfinite(vn):
            return math.hypot(vn, ve), "fit"
        return math.nan, ""

    def mean_course(self) -> tuple[float, str]:
        """Mean course over ground [deg in [0, 360), clockwise from North] and its source.

        The circular mean of the table's ``course_deg`` where it has values (``"table"``),
        else the direction of :meth:`fitted_velocity` (``"fit"``), else NaN (``""``).
        """
        c = np.radians(self.course_deg[np.isfinite(self.course_deg)])
        if c.size:
            ang = math.atan2(float(np.sin(c).mean()), float(np.cos(c).mean()))
            return math.degrees(ang) % 360.0, "table"
        vn, ve = self.fitted_velocity()
        if math.isfinite(vn) and (vn or ve):
            return math.degrees(math.atan2(ve, vn)) % 360.0, "fit"
        return math.nan, ""


def _num(value: Any) -> float:
    if value is None:
        return math.nan
    if isinstance(value, str):
        value = value.strip()
        if not value:
            return math.nan
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def _mmsi(value: Any) -> str | None:
    if value is None:
        return None
    if isinstance(value, float | np.floating):
        return None if not math.isfinite(value) else str(int(value))
    text = str(value).strip()
    if not text or text.lower() in ("nan", "none", "null"):
        return None
    if text.endswith(".0") and text[:-2].isdigit():
        text = text[:-2]
    return text


class _Accumulator:
    """Rows of a track table, parsed and grouped per track as they arrive."""

    def __init__(self, name: str = "tracks") -> None:
        self.name = name
        self.rows = 0
        self.cols: dict[int, dict[str, list[float]]] = {}
        self.mmsi: dict[int, dict[str, int]] = {}

    def add(self, row: Mapping[str, Any]) -> None:
        self.rows += 1
        t = _num(row.get("time"))
        tid = _num(row.get("track_id"))
        if not math.isfinite(t):
            raise ValueError(
                f"{self.name}: row {self.rows}: time {row.get('time')!r} is not a number [s]"
            )
        if not math.isfinite(tid) or tid != int(tid):
            raise ValueError(
                f"{self.name}: row {self.rows}: track_id {row.get('track_id')!r} is not an integer"
            )
        k = int(tid)
        cols = self.cols.get(k)
        if cols is None:
            cols = self.cols[k] = {c: [] for c in ("time", *_NUMERIC)}
            self.mmsi[k] = {}
        cols["time"].append(t)
        for c in _NUMERIC:
            cols[c].append(_num(row.get(c)))
        m = _mmsi(row.get("mmsi"))
        if m is not None:
            self.mmsi[k][m] = self.mmsi[k].get(m, 0) + 1

    def series(self) -> list[TrackSeries]:
        out = []
        for k in sorted(self.cols):
            cols = {c: np.asarray(v, dtype=np.float64) for c, v in self.cols[k].items()}
            order = np.argsort(cols["time"], kind="stable")
            cols = {c: v[order] for c, v in cols.items()}
            votes = self.mmsi[k]
            mmsi = max(votes, key=lambda m: votes[m]) if votes else None
            out.append(TrackSeries(track_id=k, mmsi=mmsi, **cols))
        return out


def load_tracks(source: TrackSource) -> list[TrackSeries]:
    """The tracks of a track table, one :class:`TrackSeries` per track id, sorted by id.

    Args:
        source: a ``tracks.csv`` path (INTERFACES.md "Track table"), or rows: mappings of
            column name → value (str, number or None; empty is missing). Needs the
            ``time`` [s] and ``track_id`` columns; every other column is optional.

    Raises:
        FileNotFoundError: the file does not exist.
        ValueError: missing ``time``/``track_id`` column, or a row whose time or track id
            is not a number (the message names the row).
    """
    acc = _Accumulator()
    if isinstance(source, str | os.PathLike):
        path = Path(source)
        acc.name = str(path)
        with path.open(newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            header = reader.fieldnames or []
            missing = [c for c in ("time", "track_id") if c not in header]
            if missing:
                raise ValueError(f"{path}: no column {', '.join(missing)} (not a track table?)")
            for row in reader:
                acc.add(row)
    else:
        for row in source:
            acc.add(row)
    return acc.series()


# --------------------------------------------------------------------------------------
# GeoJSON
# --------------------------------------------------------------------------------------


def _f(value: float, digits: int) -> float | None:
    """A JSON number rounded to ``digits`` decimals, or None for NaN/inf."""
    value = float(value)
    return round(value, digits) if math.isfinite(value) else None


def _mmsi_json(mmsi: str | None) -> int | str | None:
    return int(mmsi) if mmsi is not None and mmsi.isdigit() else mmsi


def _iso(epoch: float | None, t: float) -> str | None:
    if epoch is None or not math.isfinite(t):
        return None
    stamp = datetime.fromtimestamp(epoch + t, tz=UTC)
    return stamp.isoformat(timespec="milliseconds").replace("+00:00", "Z")


def _geodetic(
    track: TrackSeries, camera_lat: float | None, camera_lon: float | None
) -> tuple[FloatArray, FloatArray]:
    """(lat, lon) [deg] per fix: the table's, else mapped from north/east at the camera."""
    lat, lon = track.lat.copy(), track.lon.copy()
    if camera_lat is None or camera_lon is None:
        return lat, lon
    need = ~(np.isfinite(lat) & np.isfinite(lon))
    need &= np.isfinite(track.north_m) & np.isfinite(track.east_m)
    if np.any(need):
        xy = np.stack([track.north_m[need], track.east_m[need]], axis=-1)
        la, lo = north_east_to_geodetic(xy, camera_lat, camera_lon)
        lat[need], lon[need] = la, lo
    return lat, lon


def _track_features(
    track: TrackSeries,
    camera_lat: float | None,
    camera_lon: float | None,
    points: bool,
    epoch: float | None,
) -> list[dict[str, Any]]:
    lat, lon = _geodetic(track, camera_lat, camera_lon)
    ok = np.isfinite(lat) & np.isfinite(lon)
    if not np.any(ok):
        return []
    d = COORDINATE_DECIMALS
    lon_w = (lon[ok] + 180.0) % 360.0 - 180.0  # RFC 7946 §4: longitudes in [-180, 180]
    coords = [[round(float(a), d), round(float(b), d)] for a, b in zip(lon_w, lat[ok], strict=True)]
    times = track.time[ok]
    speed, speed_src = track.mean_speed()
    course, course_src = track.mean_course()
    mmsi = _mmsi_json(track.mmsi)
    props: dict[str, Any] = {
        "kind": "track",
        "track_id": track.track_id,
        "mmsi": mmsi,
        "times": [_f(t, 6) for t in times],
        "first_time": _f(times[0], 6),
        "last_time": _f(times[-1], 6),
        "fixes": int(ok.sum()),
        "mean_speed_mps": _f(speed, 3),
        "mean_speed_kn": _f(speed / KNOT, 2),
        "speed_source": speed_src or None,
        "mean_course_deg": _f(course, 2),
        "course_source": course_src or None,
        "mean_range_m": _f(np.nanmean(track.range_m[ok]), 1)
        if np.any(np.isfinite(track.range_m[ok]))
        else None,
    }
    if epoch is not None:
        props["first_datetime"] = _iso(epoch, float(times[0]))
        props["last_datetime"] = _iso(epoch, float(times[-1]))
    geometry: dict[str, Any] = (
        {"type": "LineString", "coordinates": coords}
        if len(coords) > 1
        else {"type": "Point", "coordinates": coords[0]}
    )
    feats = [{"type": "Feature", "id": f"track-{track.track_id}", "geometry": geometry,
              "properties": props}]  # fmt: skip
    if points:
        idx = np.flatnonzero(ok)
        for j, c in zip(idx, coords, strict=True):
            t = float(track.time[j])
            p: dict[str, Any] = {
                "kind": "fix",
                "track_id": track.track_id,
                "mmsi": mmsi,
                "time": _f(t, 6),
                "frame": int(track.frame[j]) if math.isfinite(track.frame[j]) else None,
                "range_m": _f(track.range_m[j], 2),
                "speed_mps": _f(track.speed_mps[j], 3),
                "course_deg": _f(track.course_deg[j], 2),
            }
            if epoch is not None:
                p["datetime"] = _iso(epoch, t)
            feats.append(
                {"type": "Feature", "geometry": {"type": "Point", "coordinates": c},
                 "properties": p}
            )  # fmt: skip
    return feats


def _check_args(camera_lat: float | None, camera_lon: float | None, epoch: float | None) -> None:
    if (camera_lat is None) != (camera_lon is None):
        raise ValueError("camera_lat, camera_lon: give both or neither")
    if camera_lat is not None and not (
        math.isfinite(camera_lat) and abs(camera_lat) <= 90.0 and math.isfinite(camera_lon)
    ):
        raise ValueError(
            f"camera_lat, camera_lon: expected a latitude in [-90, 90] and a finite longitude "
            f"[deg], got ({camera_lat!r}, {camera_lon!r})"
        )
    if epoch is not None and not math.isfinite(epoch):
        raise ValueError(f"epoch: expected finite seconds since 1970-01-01 UTC, got {epoch!r}")


def _collection(
    tracks: list[TrackSeries],
    camera_lat: float | None,
    camera_lon: float | None,
    points: bool,
    epoch: float | None,
) -> dict[str, Any] | None:
    _check_args(camera_lat, camera_lon, epoch)
    has_geo = camera_lat is not None or any(
        np.any(np.isfinite(t.lat) & np.isfinite(t.lon)) for t in tracks
    )
    if not has_geo:
        warnings.warn(
            "tracks.geojson: no geodetic positions (the camera has no lat/lon and the track "
            "table none); no GeoJSON written",
            stacklevel=3,
        )
        return None
    features: list[dict[str, Any]] = []
    if camera_lat is not None:
        d = COORDINATE_DECIMALS
        features.append(
            {
                "type": "Feature",
                "id": "camera",
                "geometry": {"type": "Point",
                             "coordinates": [round(camera_lon, d), round(camera_lat, d)]},
                "properties": {"kind": "camera"},
            }
        )  # fmt: skip
    for track in tracks:
        features.extend(_track_features(track, camera_lat, camera_lon, points, epoch))
    return {"type": "FeatureCollection", "features": features}


def tracks_to_geojson(
    rows_or_csv_path: TrackSource,
    *,
    camera_lat: float | None = None,
    camera_lon: float | None = None,
    points: bool = True,
    epoch: float | None = None,
) -> dict[str, Any] | None:
    """A GeoJSON FeatureCollection (RFC 7946) of the tracks of a track table.

    Features, each with a ``kind`` property:

    * ``"track"``: one per track with a geodetic position, a LineString of its fixes in
      time order (a Point when it has one fix), coordinates ``[lon, lat]`` [deg] rounded
      to :data:`COORDINATE_DECIMALS` decimals; properties ``track_id``, ``mmsi`` (integer,
      or null), ``times`` (the time of each vertex [s from the start of the video]),
      ``first_time``, ``last_time`` [s], ``fixes``, ``mean_speed_mps`` / ``mean_speed_kn``
      with ``speed_source`` (``"table"``: mean of ``speed_mps``; ``"fit"``: least-squares
      constant-velocity fit of the positions, :meth:`TrackSeries.fitted_velocity`),
      ``mean_course_deg`` with ``course_source``, ``mean_range_m``;
    * ``"fix"`` (with ``points=True``, the default): a Point per fix with ``track_id``,
      ``mmsi``, ``time`` [s], ``frame``, ``range_m``, ``speed_mps``, ``course_deg``;
    * ``"camera"``: a Point at ``(camera_lon, camera_lat)`` when given.

    With ``epoch`` (the UTC time of video time 0, seconds since 1970), fixes also get an
    ISO-8601 ``datetime`` and tracks ``first_datetime``/``last_datetime`` (for QGIS's
    temporal controller). Missing numbers are null (the document is strict JSON).

    Args:
        rows_or_csv_path: ``tracks.csv`` path or rows (see :func:`load_tracks`).
        camera_lat, camera_lon: the camera's WGS-84 position [deg], used for the camera
            feature and to map ``north_m``/``east_m`` of rows without ``lat``/``lon``.
        points: include the per-fix Point features.
        epoch: UTC time of video time 0 [s since 1970-01-01], or None.

    Returns:
        The FeatureCollection, or None (with a warning) when there is no geodetic position
        at all: no camera position and no ``lat``/``lon`` in the table.
    """
    return _collection(load_tracks(rows_or_csv_path), camera_lat, camera_lon, points, epoch)


def atomic_write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically: a temporary file in the same folder,
    flushed and fsync'ed, then :func:`os.replace` — readers see the old or the new file,
    never half of one, and a crash leaves the previous version."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    return path


def _dump(doc: dict[str, Any]) -> str:
    return json.dumps(doc, separators=(",", ":"), allow_nan=False) + "\n"


def write_geojson(
    path: str | os.PathLike[str],
    rows_or_csv_path: TrackSource,
    *,
    camera_lat: float | None = None,
    camera_lon: float | None = None,
    points: bool = True,
    epoch: float | None = None,
) -> Path | None:
    """Write :func:`tracks_to_geojson` to ``path`` atomically (see :func:`atomic_write_text`).

    Returns the path, or None (nothing written, with a warning) when the tracks have no
    geodetic position.
    """
    doc = tracks_to_geojson(
        rows_or_csv_path, camera_lat=camera_lat, camera_lon=camera_lon, points=points, epoch=epoch
    )
    if doc is None:
        return None
    return atomic_write_text(path, _dump(doc))


class GeoJsonSink:
    """``tracks.geojson`` kept up to date while a video is processed.

    Rows are parsed once as they arrive (:meth:`add`); the file is rewritten atomically
    when at least ``every_s`` seconds of video have passed since the last write *and* the
    wall-clock time since then is at least ``(1 − overhead) / overhead`` times the last
    write's duration — so rewriting costs at most about ``overhead`` of the run even when
    the file grows large (a long video: the interval then stretches beyond ``every_s``).
    :meth:`close` writes the final file.

    Args:
        path: the output file.
        camera_lat, camera_lon, points, epoch: as :func:`tracks_to_geojson`.
        every_s: video time between rewrites [s], > 0.
        overhead: the largest share of wall time spent rewriting, in (0, 1).
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        *,
        camera_lat: float | None = None,
        camera_lon: float | None = None,
        points: bool = True,
        epoch: float | None = None,
        every_s: float = 1.0,
        overhead: float = 0.1,
    ) -> None:
        if not (isinstance(every_s, int | float) and math.isfinite(every_s) and every_s > 0):
            raise ValueError(f"every_s: expected a time > 0 [s], got {every_s!r}")
        if not (isinstance(overhead, int | float) and 0.0 < overhead < 1.0):
            raise ValueError(f"overhead: expected a fraction in (0, 1), got {overhead!r}")
        self.path = Path(path)
        if not self.path.parent.is_dir():
            raise ValueError(f"path: folder {self.path.parent} does not exist")
        _check_args(camera_lat, camera_lon, epoch)
        self.camera_lat, self.camera_lon = camera_lat, camera_lon
        self.points, self.epoch = points, epoch
        self.every_s, self.overhead = float(every_s), float(overhead)
        self.writes = 0
        self._acc = _Accumulator(str(self.path))
        self._last_video = -math.inf
        self._next_wall = -math.inf
        self._warned = False
        self._closed = False

    def add(self, rows: Iterable[Mapping[str, Any]], time: float) -> bool:
        """Add the rows of the frame at video ``time`` [s]; rewrite the file if it is due.

        Returns whether the file was rewritten.
        """
        if self._closed:
            raise ValueError(f"{self.path}: sink is closed")
        for row in rows:
            self._acc.add(row)
        if time - self._last_video < self.every_s or _time.monotonic() < self._next_wall:
            return False
        self._last_video = time
        return self.write() is not None

    def write(self) -> Path | None:
        """Rewrite the file now with every row so far; None when there is no geodetic position
        (warned once)."""
        t0 = _time.monotonic()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            doc = _collection(
                self._acc.series(), self.camera_lat, self.camera_lon, self.points, self.epoch
            )
        if doc is None:
            if not self._warned:
                self._warned = True
                for w in caught:
                    warnings.warn(str(w.message), stacklevel=2)
            return None
        atomic_write_text(self.path, _dump(doc))
        self.writes += 1
        spent = _time.monotonic() - t0
        self._next_wall = _time.monotonic() + spent * (1.0 - self.overhead) / self.overhead
        return self.path

    def close(self) -> Path | None:
        """Write the final file (idempotent); returns its path or None (no geodetic position)."""
        if self._closed:
            return self.path if self.writes else None
        self._closed = True
        return self.write()

    def __enter__(self) -> GeoJsonSink:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
