"""AIS input: decoded CSV tables and raw ``!AIVDM``/``!AIVDO`` NMEA, per-vessel tracks.

The edge where AIS units become SI (STYLE.md): speed over ground (SOG) in knots becomes
m/s (1 kn = 1852/3600 m/s), course over ground (COG) and true heading in degrees become
radians in [0, 2π); latitude and longitude stay in degrees (as everywhere in
:mod:`seawatch.geometry.geodesy`); times become seconds since 1970-01-01 UTC. AIS
"not available" codes become NaN: SOG 102.3 kn, COG 360°, heading 511°; a report whose
latitude is 91° or longitude 181° has no position and is skipped.

Readers
-------
:func:`read_ais_csv` reads decoded reports with the columns of the Solent file
(``../shared/data/ais/solent_2016-01-12_1302-1344.csv``, Stone Soup, MIT):
``Time, MMSI, Latitude_degrees, Longitude_degrees, COG_degrees, SOG_knots`` (a few
common aliases are accepted, see :data:`CSV_COLUMNS`). :func:`read_ais_nmea` decodes
position reports (message types 1, 2, 3, 18, 19) from raw NMEA 0183 sentences with
pyais, joining multi-sentence messages, and takes times from Gatehouse ``$PGHP``
wrapper lines or NMEA 4.10 tag blocks (``\\c:<unix time>*hh\\``) when the file has
them (the ``timestamped.ais`` format of the pyais tests: a ``$PGHP,1,YYYY,M,D,h,m,s,
ms,…`` line timestamps the sentence after it); otherwise the times are NaN.

Bad input is counted and skipped, never fatal: unparsable rows, positions outside
[−90, 90]° × [−180, 180]°, and isolated fixes that imply an impossible speed (a jump
faster than :data:`MAX_SPEED` plus :data:`JUMP_SLACK` from both neighbours of the same
vessel, such as the Solent file's row with longitude 54.83°); for NMEA, sentences with a
bad checksum, messages that fail to decode (e.g. an empty payload), fragments of
multi-sentence messages that never complete, and position reports without a position.
Each skipped row raises an :class:`AisWarning` naming the file and line (the first
:data:`MAX_WARNINGS` of them, then one summary warning), and the returned table keeps
the full list (:attr:`AisTable.skipped`), the counts (:attr:`AisTable.counts`) and a
one-line :meth:`AisTable.summary`. A missing file raises ``FileNotFoundError``; a CSV
without the required columns raises ``ValueError`` naming the file and the columns.

Tracks
------
:func:`tracks` splits a table into per-vessel :class:`AisTrack` arrays (time-sorted,
reports at a repeated time dropped: the first in file order is kept).
:func:`interpolate_track` samples a track at arbitrary times in a local tangent plane
(x North, y East): positions by cubic Hermite interpolation through the fixes with the
reported velocities as tangents, speed and course from the reported velocity vector
interpolated linearly (see its docstring for why, and for the checks on the reports).

Sources of the test data: Stone Soup (``docs/demos/SolentAIS_20160112_130211.csv``,
MIT) and pyais (``tests/``, MIT); see ``../shared/data/README.md``.
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

from seawatch._validation import FloatArray, as_float_array
from seawatch.geometry.geodesy import geodetic_to_north_east, north_east_to_geodetic

__all__ = [
    "CSV_COLUMNS",
    "JUMP_SLACK",
    "KNOT",
    "MAX_GAP",
    "MAX_SPEED",
    "MAX_WARNINGS",
    "POSITION_TYPES",
    "AisTable",
    "AisTrack",
    "AisWarning",
    "SkippedRow",
    "TrackSample",
    "interpolate_track",
    "read_ais",
    "read_ais_csv",
    "read_ais_nmea",
    "tracks",
]

KNOT = 1852.0 / 3600.0
"""One knot [m/s]."""
MAX_SPEED = 60.0 * KNOT
"""Fastest credible vessel speed [m/s] (60 kn; high-speed craft reach ~50 kn)."""
JUMP_SLACK = 100.0
"""Distance [m] allowed on top of ``MAX_SPEED · Δt`` between two fixes (GNSS jitter,
fixes a fraction of a second apart)."""
MAX_GAP = 200.0
"""Longest gap between fixes [s] that :func:`interpolate_track` bridges by default (an
anchored class-A station reports every 3 minutes, give or take a few seconds)."""
MAX_WARNINGS = 10
"""Skipped rows warned about one by one; the rest are counted in one summary warning."""
POSITION_TYPES = (1, 2, 3, 18, 19)
"""AIS message types that carry a position report (class A 1–3, class B 18–19)."""

_SOG_NA = 102.3  # knots: "not available"
_COG_NA = 360.0  # degrees
_HEADING_NA = 511  # degrees

CSV_COLUMNS: Mapping[str, tuple[str, ...]] = {
    "time": ("time", "timestamp", "datetime", "basedatetime"),
    "mmsi": ("mmsi",),
    "lat": ("latitude_degrees", "latitude", "lat"),
    "lon": ("longitude_degrees", "longitude", "lon", "long"),
    "cog": ("cog_degrees", "cog", "course"),
    "sog": ("sog_knots", "sog", "speed"),
}
"""Accepted CSV header names per field (case-insensitive), the Solent file's first."""
_CSV_DISPLAY = {
    "time": "Time",
    "mmsi": "MMSI",
    "lat": "Latitude_degrees",
    "lon": "Longitude_degrees",
    "cog": "COG_degrees",
    "sog": "SOG_knots",
}


class AisWarning(UserWarning):
    """A row, line or sentence of an AIS file was skipped (the message names where)."""


@dataclass(frozen=True)
class SkippedRow:
    """One skipped input row.

    Attributes:
        line: 1-based line number in the file (the first line of a multi-sentence message).
        reason: short category (``"unparsable"``, ``"out of range"``, ``"impossible jump"``,
            ``"bad checksum"``, ``"undecodable"``, ``"incomplete"``, ``"no position"``).
        detail: what was wrong, in words.
    """

    line: int
    reason: str
    detail: str


@dataclass(frozen=True, eq=False)
class AisTable:
    """AIS position reports, one row per report, in file order.

    Attributes:
        time: report time [s since 1970-01-01 UTC], (N,); NaN where the file has none.
        mmsi: vessel identity (MMSI), (N,) int64.
        lat, lon: WGS-84 latitude and longitude [deg], (N,).
        sog: speed over ground [m/s], (N,); NaN if not available.
        cog: course over ground [rad] clockwise from North in [0, 2π), (N,); NaN if not
            available.
        heading: true heading [rad] in [0, 2π), (N,); NaN if not available (always for CSV).
        msg_type: AIS message type (0 for CSV rows), (N,) int64.
        line: 1-based line number of each row in the file, (N,) int64.
        source: the file read.
        skipped: every skipped row, in file order.
        counts: what was read: ``rows`` (data rows or sentences seen), ``kept``,
            ``skipped`` and one count per skip reason; NMEA adds ``messages`` (complete
            messages), ``decoded``, ``position_reports``, ``other_types`` and
            ``ignored_lines`` (blank, comment and non-AIS lines).
    """

    time: FloatArray
    mmsi: NDArray[np.int64]
    lat: FloatArray
    lon: FloatArray
    sog: FloatArray
    cog: FloatArray
    heading: FloatArray
    msg_type: NDArray[np.int64]
    line: NDArray[np.int64]
    source: str = ""
    skipped: tuple[SkippedRow, ...] = ()
    counts: Mapping[str, int] = field(default_factory=dict)

    def __len__(self) -> int:
        return int(self.mmsi.size)

    @property
    def vessels(self) -> NDArray[np.int64]:
        """The distinct MMSIs, sorted."""
        return np.unique(self.mmsi)

    def summary(self) -> str:
        """One line: rows read, kept and skipped, by reason."""
        reasons = Counter(s.reason for s in self.skipped)
        why = ", ".join(f"{n} {r}" for r, n in sorted(reasons.items()))
        name = Path(self.source).name if self.source else "AIS table"
        text = (
            f"{name}: {self.counts.get('rows', len(self) + len(self.skipped))} rows, "
            f"{len(self)} kept ({self.vessels.size} vessels), {len(self.skipped)} skipped"
        )
        if "decoded" in self.counts:
            text += f"; {self.counts['decoded']} messages decoded"
        return text + (f" ({why})" if why else "")

    def subset(self, mask: ArrayLike) -> AisTable:
        """The rows where the boolean ``mask`` (N,) is True (skips and counts unchanged)."""
        m = np.asarray(mask, dtype=bool)
        if m.shape != self.mmsi.shape:
            raise ValueError(f"mask: expected a boolean array of shape {self.mmsi.shape}")
        return _table(
            {k: getattr(self, k)[m] for k in _COLUMNS}, self.source, self.skipped, self.counts
        )


_COLUMNS = ("time", "mmsi", "lat", "lon", "sog", "cog", "heading", "msg_type", "line")


def _table(
    cols: Mapping[str, Any],
    source: str,
    skipped: Sequence[SkippedRow],
    counts: Mapping[str, int],
) -> AisTable:
    ints = ("mmsi", "msg_type", "line")
    arrays = {k: np.asarray(cols[k], dtype=np.int64 if k in ints else np.float64) for k in _COLUMNS}
    return AisTable(**arrays, source=source, skipped=tuple(skipped), counts=dict(counts))


# ==========================================================================================
# shared helpers
# ==========================================================================================


def _existing_file(path: str | os.PathLike[str], kind: str = "AIS") -> Path:
    """``path`` as a Path; FileNotFoundError ("<kind> file not found") or ValueError."""
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"{kind} file not found: {p}")
    if not p.is_file():
        raise ValueError(f"path: {p} is not a file")
    return p


def _warn_skipped(
    source: Path,
    skipped: Sequence[SkippedRow],
    total: int,
    category: type[UserWarning] = AisWarning,
    unit: str = "rows",
) -> None:
    """One warning of ``category`` per skipped row (the first MAX_WARNINGS), then a
    summary over all ``total`` ``unit`` read (also used by :mod:`seawatch.io.nav`)."""
    for s in skipped[:MAX_WARNINGS]:
        warnings.warn(
            category(f"{source}, line {s.line}: {s.reason}: {s.detail}; skipped"), stacklevel=3
        )
    if len(skipped) > MAX_WARNINGS:
        reasons = Counter(s.reason for s in skipped)
        why = ", ".join(f"{n} {r}" for r, n in sorted(reasons.items()))
        warnings.warn(
            category(
                f"{source}: {len(skipped)} of {total} {unit} skipped in total ({why}); "
                f"{len(skipped) - MAX_WARNINGS} more not listed one by one"
            ),
            stacklevel=3,
        )


def _angle_rad(value: float, na: float) -> float:
    """Degrees in [0, na) → radians; the not-available code or anything else → NaN."""
    if not math.isfinite(value) or value < 0.0 or value >= na:
        return math.nan
    return math.radians(value)


def _speed_mps(knots: float) -> float:
    """Knots in [0, 102.3) → m/s; 102.3 (not available), negative or NaN → NaN."""
    if not math.isfinite(knots) or knots < 0.0 or knots >= _SOG_NA - 1e-9:
        return math.nan
    return knots * KNOT


def _position_problem(lat: float, lon: float) -> str | None:
    if not (math.isfinite(lat) and math.isfinite(lon)):
        return "latitude/longitude not finite"
    if abs(lat) > 90.0 or abs(lon) > 180.0:
        if lat == 91.0 or lon == 181.0:
            return f"position not available (lat {lat:g}, lon {lon:g})"
        return f"latitude {lat:g} / longitude {lon:g} outside [-90, 90] x [-180, 180] deg"
    return None


def _haversine(lat1: FloatArray, lon1: FloatArray, lat2: FloatArray, lon2: FloatArray) -> Any:
    """Great-circle distance [m] on the mean sphere (R = 6 371 km), for the jump check."""
    p1, p2 = np.radians(lat1), np.radians(lat2)
    dp = p2 - p1
    dl = np.radians(lon2 - lon1)
    a = np.sin(dp / 2) ** 2 + np.cos(p1) * np.cos(p2) * np.sin(dl / 2) ** 2
    return 2.0 * 6_371_000.0 * np.arcsin(np.sqrt(np.clip(a, 0.0, 1.0)))


def _jump_outliers(
    time: FloatArray, mmsi: NDArray[np.int64], lat: FloatArray, lon: FloatArray
) -> dict[int, str]:
    """Rows (indices) whose fix is impossible against most of its neighbours.

    Per vessel, in time order, each fix is compared with up to two fixes before and two
    after it: a pair is impossible when their distance exceeds ``MAX_SPEED · |Δt| +
    JUMP_SLACK``. A fix impossible against more than half of its neighbours is an outlier
    (an isolated bad fix is impossible against all of them, a good fix next to it against
    one). Rows without a time are not checked.
    """
    out: dict[int, str] = {}
    timed = np.flatnonzero(np.isfinite(time))
    if timed.size < 2:
        return out
    order = timed[np.lexsort((time[timed], mmsi[timed]))]
    ids = mmsi[order]
    starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    ends = np.r_[starts[1:], ids.size]
    for s, e in zip(starts, ends, strict=True):
        idx = order[s:e]
        n = idx.size
        if n < 2:
            continue
        t, la, lo = time[idx], lat[idx], lon[idx]
        bad = np.zeros(n, dtype=np.int64)
        tot = np.zeros(n, dtype=np.int64)
        for k in (1, 2):
            if n <= k:
                break
            d = _haversine(la[:-k], lo[:-k], la[k:], lo[k:])
            imp = (d > MAX_SPEED * np.abs(t[k:] - t[:-k]) + JUMP_SLACK).astype(np.int64)
            tot[:-k] += 1
            tot[k:] += 1
            bad[:-k] += imp
            bad[k:] += imp
        for i in np.flatnonzero(2 * bad > tot):
            nb = np.array([j for j in (i - 2, i - 1, i + 1, i + 2) if 0 <= j < n])
            dist = _haversine(la[i], lo[i], la[nb], lo[nb])
            j = int(nb[np.argmax(dist)])
            dt_ij = abs(float(t[i] - t[j]))
            speed = float(dist.max()) / dt_ij / KNOT if dt_ij > 0 else math.inf
            out[int(idx[i])] = (
                f"MMSI {int(ids[s])}: fix ({la[i]:.5f}, {lo[i]:.5f}) is "
                f"{float(dist.max()) / 1000:.3g} km from the fix {dt_ij:.3g} s apart "
                f"({speed:.3g} kn > {MAX_SPEED / KNOT:.0f} kn)"
            )
    return out


# ==========================================================================================
# CSV
# ==========================================================================================


def _parse_time(text: str) -> float:
    """ISO 8601 date-time (naive = UTC) or a number of seconds since the epoch → seconds."""
    s = text.strip()
    try:
        v = float(s)
    except ValueError:
        pass
    else:
        if not math.isfinite(v):
            raise ValueError(f"time {s!r} is not finite")
        return v
    if s.endswith("Z"):
        s = s[:-1] + "+00:00"
    dt = datetime.fromisoformat(s)
    if dt.tzinfo is None:
        dt = dt.replace(tzinfo=UTC)
    return dt.timestamp()


def _header_map(header: Sequence[str], source: Path) -> dict[str, int]:
    names = [h.strip().lower() for h in header]
    where: dict[str, int] = {}
    missing = []
    for key, aliases in CSV_COLUMNS.items():
        for a in aliases:
            if a in names:
                where[key] = names.index(a)
                break
        else:
            missing.append(_CSV_DISPLAY[key])
    if missing:
        raise ValueError(
            f"{source}: not an AIS table: missing column(s) {', '.join(missing)} "
            f"(header: {', '.join(h.strip() for h in header)}; expected the columns "
            "Time, MMSI, Latitude_degrees, Longitude_degrees, COG_degrees, SOG_knots)"
        )
    return where


def read_ais_csv(path: str | os.PathLike[str]) -> AisTable:
    """Read decoded AIS position reports from a CSV file (the Solent file's columns).

    Columns (header names case-insensitive, aliases in :data:`CSV_COLUMNS`): ``Time`` (ISO
    8601, naive times are UTC, or seconds since the epoch), ``MMSI``, ``Latitude_degrees``,
    ``Longitude_degrees``, ``COG_degrees``, ``SOG_knots``; other columns are ignored.
    Units at this edge: SOG knots → m/s, COG degrees → radians (module docstring).

    Skipped, each with an :class:`AisWarning` naming the line: rows with the wrong number
    of fields or unparsable values (``"unparsable"``), positions outside the valid range
    (``"out of range"``), fixes that imply an impossible speed (``"impossible jump"``, see
    :data:`MAX_SPEED`). An empty or out-of-range COG/SOG is not a reason to skip a row:
    it becomes NaN.

    Args:
        path: the CSV file.

    Returns:
        AisTable with the kept rows in file order; ``counts["rows"]`` data rows were read.

    Raises:
        FileNotFoundError: the file does not exist.
        ValueError: the file has no header with the required columns.
    """
    p = _existing_file(path)
    cols: dict[str, list[float]] = {k: [] for k in _COLUMNS}
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
            raise ValueError(f"{p}: empty file, expected an AIS table with a header row")
        where = _header_map(header, p)
        width = len(header)
        for row in reader:
            line = reader.line_num
            if not row or all(not c.strip() for c in row):
                continue
            n_rows += 1
            if len(row) != width:
                skipped.append(
                    SkippedRow(line, "unparsable", f"{len(row)} fields, expected {width}")
                )
                continue
            try:
                t = _parse_time(row[where["time"]])
                mmsi_f = float(row[where["mmsi"]])
                lat = float(row[where["lat"]])
                lon = float(row[where["lon"]])
            except ValueError as exc:
                skipped.append(SkippedRow(line, "unparsable", str(exc)))
                continue
            if not (math.isfinite(mmsi_f) and mmsi_f == int(mmsi_f) and 0 < mmsi_f < 1e9):
                skipped.append(SkippedRow(line, "unparsable", f"MMSI {row[where['mmsi']]!r}"))
                continue
            problem = _position_problem(lat, lon)
            if problem is not None:
                skipped.append(SkippedRow(line, "out of range", problem))
                continue
            cog = _float_or_nan(row[where["cog"]])
            sog = _float_or_nan(row[where["sog"]])
            cols["time"].append(t)
            cols["mmsi"].append(int(mmsi_f))
            cols["lat"].append(lat)
            cols["lon"].append(lon)
            cols["cog"].append(_angle_rad(cog, _COG_NA))
            cols["sog"].append(_speed_mps(sog))
            cols["heading"].append(math.nan)
            cols["msg_type"].append(0)
            cols["line"].append(line)
    table = _table(cols, str(p), (), {})
    jumps = _jump_outliers(table.time, table.mmsi, table.lat, table.lon)
    if jumps:
        keep = np.ones(len(table), dtype=bool)
        for i, detail in jumps.items():
            keep[i] = False
            skipped.append(SkippedRow(int(table.line[i]), "impossible jump", detail))
        table = _table({k: getattr(table, k)[keep] for k in _COLUMNS}, str(p), (), {})
    skipped.sort(key=lambda s: s.line)
    counts = _counts(n_rows, len(table), skipped)
    _warn_skipped(p, skipped, n_rows)
    return _table({k: getattr(table, k) for k in _COLUMNS}, str(p), skipped, counts)


def _float_or_nan(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return math.nan


def _counts(rows: int, kept: int, skipped: Sequence[SkippedRow], **extra: int) -> dict[str, int]:
    counts = {"rows": rows, "kept": kept, "skipped": len(skipped)}
    counts.update(Counter(s.reason for s in skipped))
    counts.update(extra)
    return counts


# ==========================================================================================
# NMEA
# ==========================================================================================


def _tag_block_time(sentence: Any) -> float:
    """Receiver time of an NMEA 4.10 tag block ``c:`` field [s], NaN if absent."""
    tb = getattr(sentence, "tag_block", None)
    if tb is None:
        return math.nan
    try:
        tb.init()
        ts = tb.receiver_timestamp
    except Exception:  # a malformed tag block only loses its time
        return math.nan
    if ts is None:
        return math.nan
    try:
        v = float(ts)
    except (TypeError, ValueError):
        return math.nan
    return v / 1000.0 if v > 1e11 else v  # milliseconds in some feeds


def read_ais_nmea(path: str | os.PathLike[str]) -> AisTable:
    """Decode AIS position reports from raw NMEA 0183 ``!AIVDM``/``!AIVDO`` sentences (pyais).

    Line by line: blank lines, ``#`` comments and sentences other than AIS and ``$PGHP``
    are ignored (``counts["ignored_lines"]``). Multi-sentence messages are joined by
    (sequence id, channel, fragment count) when their fragments arrive complete and in
    order (as pyais's streams do). Complete messages are decoded by pyais
    (``counts["messages"]``, ``counts["decoded"]``); those of types 1, 2, 3, 18 and 19
    become rows (``counts["position_reports"]``), other decoded types are counted in
    ``counts["other_types"]``.

    Times: a Gatehouse ``$PGHP,1,Y,M,D,h,m,s,ms,…`` line timestamps the AIS message
    that follows it (the ``timestamped.ais`` format); a tag block's ``c:`` field gives the
    receiver time; messages with neither have time NaN.

    Skipped, each an :class:`AisWarning` naming the line (first fragment's line for a
    multi-sentence message): sentences that are not valid NMEA (``"unparsable"``) or have
    a wrong checksum (``"bad checksum"``), messages that fail to decode, e.g. an empty
    payload (``"undecodable"``), fragments whose message never completes
    (``"incomplete"``), position reports with the not-available position 91°/181° or out
    of range (``"no position"``), and impossible jumps when times are known.

    Args:
        path: text file of NMEA sentences (any line endings).

    Returns:
        AisTable (``msg_type`` per row; units as in the module docstring).

    Raises:
        FileNotFoundError: the file does not exist.
    """
    from pyais.messages import AISSentence, GatehouseSentence, NMEAMessage, NMEASentenceFactory

    p = _existing_file(path)
    cols: dict[str, list[float]] = {k: [] for k in _COLUMNS}
    skipped: list[SkippedRow] = []
    n_sentences = n_ignored = n_messages = n_decoded = n_position = n_other = 0
    pending_time = math.nan  # from a $PGHP wrapper, for the next AIS message
    buffers: dict[tuple[Any, ...], tuple[list[Any], int, float]] = {}

    def add_message(msg: Any, line: int, t: float) -> None:
        nonlocal n_messages, n_decoded, n_position, n_other
        n_messages += 1
        try:
            decoded = msg.decode()
        except Exception as exc:  # pyais raises several types for bad payloads
            detail = f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__
            skipped.append(SkippedRow(line, "undecodable", detail[:200]))
            return
        n_decoded += 1
        mtype = int(decoded.msg_type)
        if mtype not in POSITION_TYPES:
            n_other += 1
            return
        n_position += 1
        lat = float(decoded.lat) if decoded.lat is not None else math.nan
        lon = float(decoded.lon) if decoded.lon is not None else math.nan
        problem = _position_problem(lat, lon)
        if problem is not None:
            skipped.append(SkippedRow(line, "no position", f"type {mtype}: {problem}"))
            return
        speed = getattr(decoded, "speed", None)
        course = getattr(decoded, "course", None)
        heading = getattr(decoded, "heading", None)
        cols["time"].append(t)
        cols["mmsi"].append(int(decoded.mmsi))
        cols["lat"].append(lat)
        cols["lon"].append(lon)
        cols["sog"].append(_speed_mps(float(speed)) if speed is not None else math.nan)
        cols["cog"].append(_angle_rad(float(course), _COG_NA) if course is not None else math.nan)
        cols["heading"].append(
            _angle_rad(float(heading), 360.0)
            if heading is not None and int(heading) != _HEADING_NA
            else math.nan
        )
        cols["msg_type"].append(mtype)
        cols["line"].append(line)

    with p.open("rb") as fh:
        for line_no, raw in enumerate(fh, start=1):
            text = raw.strip()
            if not text or text.startswith(b"#"):
                n_ignored += 1
                continue
            body = text
            if body.startswith(b"\\"):
                end = body.find(b"\\", 1)
                body = body[end + 1 :] if end > 0 else body
            is_ais = body[:1] == b"!" and body[3:6].upper() in (b"VDM", b"VDO")
            is_gatehouse = body[:5].upper() == b"$PGHP"
            if not (is_ais or is_gatehouse):
                n_ignored += 1
                continue
            n_sentences += 1
            try:
                sentence = NMEASentenceFactory.produce(text)
            except Exception as exc:  # pyais: Invalid/UnknownMessageException; never fatal
                skipped.append(SkippedRow(line_no, "unparsable", str(exc)[:200] or "bad sentence"))
                if is_gatehouse:
                    pending_time = math.nan  # a broken time line must not date the next message
                continue
            if isinstance(sentence, GatehouseSentence):
                ts = getattr(sentence, "timestamp", None)
                pending_time = ts.replace(tzinfo=UTC).timestamp() if ts is not None else math.nan
                continue
            if not isinstance(sentence, AISSentence):
                n_ignored += 1
                continue
            if not sentence.is_valid:
                skipped.append(
                    SkippedRow(line_no, "bad checksum", text.decode("ascii", "replace")[:100])
                )
                continue
            t = _tag_block_time(sentence)
            if math.isnan(t):
                t = pending_time
            pending_time = math.nan
            if sentence.is_single:
                add_message(sentence, line_no, t)
                continue
            slot = (sentence.seq_id, sentence.channel, sentence.talker_id, sentence.frag_cnt)
            if sentence.frag_num == 1:
                if slot in buffers:
                    old = buffers.pop(slot)
                    skipped.append(
                        SkippedRow(old[1], "incomplete", "fragment of an unfinished message")
                    )
                buffers[slot] = ([sentence], line_no, t)
            elif slot in buffers and sentence.frag_num == len(buffers[slot][0]) + 1:
                buffers[slot][0].append(sentence)
            else:
                skipped.append(
                    SkippedRow(
                        line_no,
                        "incomplete",
                        f"fragment {sentence.frag_num} of {sentence.frag_cnt} without the "
                        "fragments before it",
                    )
                )
                continue
            parts, first_line, t0 = buffers[slot]
            if len(parts) == sentence.frag_cnt:
                del buffers[slot]
                add_message(NMEAMessage.assemble_from_iterable(parts), first_line, t0)
    for parts, first_line, _ in buffers.values():
        skipped.append(
            SkippedRow(
                first_line,
                "incomplete",
                f"multi-sentence message: {len(parts)} of {parts[0].frag_cnt} fragments",
            )
        )
    table = _table(cols, str(p), (), {})
    jumps = _jump_outliers(table.time, table.mmsi, table.lat, table.lon)
    if jumps:
        keep = np.ones(len(table), dtype=bool)
        for i, detail in jumps.items():
            keep[i] = False
            skipped.append(SkippedRow(int(table.line[i]), "impossible jump", detail))
        table = _table({k: getattr(table, k)[keep] for k in _COLUMNS}, str(p), (), {})
    skipped.sort(key=lambda s: s.line)
    counts = _counts(
        n_sentences,
        len(table),
        skipped,
        messages=n_messages,
        decoded=n_decoded,
        position_reports=n_position,
        other_types=n_other,
        ignored_lines=n_ignored,
    )
    _warn_skipped(p, skipped, n_sentences)
    return _table({k: getattr(table, k) for k in _COLUMNS}, str(p), skipped, counts)


def read_ais(path: str | os.PathLike[str]) -> AisTable:
    """Read an AIS file of either kind: raw NMEA (:func:`read_ais_nmea`) or a CSV table.

    The kind is decided by the first line that is neither blank nor a ``#`` comment: a
    line starting with ``!``, ``$`` or ``\\`` (an NMEA sentence or tag block) means NMEA,
    anything else a CSV table with a header row.

    Raises:
        FileNotFoundError: the file does not exist.
        ValueError: a CSV file without the required columns.
    """
    p = _existing_file(path)
    with p.open("rb") as fh:
        for raw in fh:
            text = raw.strip()
            if not text or text.startswith(b"#"):
                continue
            if text[:1] in (b"!", b"$", b"\\"):
                return read_ais_nmea(p)
            break
    return read_ais_csv(p)


# ==========================================================================================
# tracks
# ==========================================================================================


@dataclass(frozen=True, eq=False)
class AisTrack:
    """The reports of one vessel, sorted by time, one per time.

    Attributes:
        mmsi: the vessel's MMSI.
        time: report times [s since the epoch], (K,), strictly increasing.
        lat, lon: positions [deg], (K,).
        sog: speed over ground [m/s], (K,), NaN if not available.
        cog: course over ground [rad], (K,), NaN if not available.
        heading: true heading [rad], (K,), NaN if not available.
        line: source line of each report, (K,).
    """

    mmsi: int
    time: FloatArray
    lat: FloatArray
    lon: FloatArray
    sog: FloatArray
    cog: FloatArray
    heading: FloatArray
    line: NDArray[np.int64]

    def __len__(self) -> int:
        return int(self.time.size)

    @property
    def span(self) -> tuple[float, float]:
        """(first, last) report time [s]."""
        return float(self.time[0]), float(self.time[-1])


def tracks(table: AisTable) -> dict[int, AisTrack]:
    """Per-vessel tracks of an AIS table, keyed by MMSI (ascending).

    Each track is sorted by time; of several reports at the same time the first in file
    order is kept. Rows without a time (NaN, e.g. NMEA without timestamps) cannot be
    ordered and are left out, with one :class:`AisWarning` giving their number.
    """
    if not isinstance(table, AisTable):
        raise ValueError(f"table: expected an AisTable, got {type(table).__name__}")
    timed = np.isfinite(table.time)
    if not np.all(timed):
        warnings.warn(
            AisWarning(
                f"{table.source or 'AIS table'}: {int(np.sum(~timed))} reports without a "
                "time left out of the tracks"
            ),
            stacklevel=2,
        )
    idx = np.flatnonzero(timed)
    # stable sort by (mmsi, time), file order breaking ties
    idx = idx[np.lexsort((table.line[idx], table.time[idx], table.mmsi[idx]))]
    out: dict[int, AisTrack] = {}
    if idx.size == 0:
        return out
    ids = table.mmsi[idx]
    starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    ends = np.r_[starts[1:], ids.size]
    for s, e in zip(starts, ends, strict=True):
        sel = idx[s:e]
        t = table.time[sel]
        keep = np.r_[True, np.diff(t) > 0.0]
        sel = sel[keep]
        out[int(ids[s])] = AisTrack(
            mmsi=int(ids[s]),
            time=table.time[sel],
            lat=table.lat[sel],
            lon=table.lon[sel],
            sog=table.sog[sel],
            cog=table.cog[sel],
            heading=table.heading[sel],
            line=table.line[sel],
        )
    return out


@dataclass(frozen=True, eq=False)
class TrackSample:
    """A track sampled at given times (:func:`interpolate_track`).

    Attributes:
        time: the requested times [s], (T,).
        north, east: position in the tangent plane at ``origin`` [m], (T,).
        lat, lon: the same positions [deg], (T,).
        velocity: (v_north, v_east) [m/s], (T, 2).
        speed: speed over ground [m/s], (T,).
        course: course over ground [rad] in [0, 2π), (T,); NaN where the speed is 0.
        valid: True where the time lies within the track and no longer gap than
            ``max_gap`` is bridged, (T,); all other fields are NaN elsewhere.
        origin: (lat0, lon0) [deg] of the tangent plane.
    """

    time: FloatArray
    north: FloatArray
    east: FloatArray
    lat: FloatArray
    lon: FloatArray
    velocity: FloatArray
    speed: FloatArray
    course: FloatArray
    valid: NDArray[np.bool_]
    origin: tuple[float, float]


def _knot_velocities(t: FloatArray, ne: FloatArray, sog: FloatArray, cog: FloatArray) -> FloatArray:
    """Velocity (v_n, v_e) [m/s] at each fix: the report if plausible, else the chord.

    The chord velocity is the central difference of the positions (one-sided at the
    ends). A report is used when SOG is known, COG is known (or the speed is below
    0.1 m/s, where the course does not matter) and it differs from the chord velocity by
    at most max(2 m/s, half the chord speed): GNSS Doppler velocities are far less noisy
    than differences of jittery fixes, but a wrong COG must not bend the track.
    """
    n = t.size
    if n == 1:
        v = np.zeros((1, 2))
        if np.isfinite(sog[0]) and (np.isfinite(cog[0]) or sog[0] < 0.1):
            c = 0.0 if not np.isfinite(cog[0]) else cog[0]
            v[0] = sog[0] * np.array([math.cos(c), math.sin(c)])
        return v
    chord = np.stack([np.gradient(ne[:, 0], t), np.gradient(ne[:, 1], t)], axis=-1)
    c = np.where(np.isfinite(cog), cog, 0.0)
    rep = np.stack([sog * np.cos(c), sog * np.sin(c)], axis=-1)
    known = np.isfinite(sog) & (np.isfinite(cog) | (sog < 0.1))
    diff = np.hypot(*(rep - chord).T)
    tol = np.maximum(2.0, 0.5 * np.hypot(*chord.T))
    use = known & (diff <= tol)
    return np.where(use[:, None], np.where(np.isfinite(rep), rep, 0.0), chord)


def interpolate_track(
    track: AisTrack,
    times: ArrayLike,
    *,
    origin: tuple[float, float] | None = None,
    max_gap: float = MAX_GAP,
) -> TrackSample:
    """Position, speed and course of a vessel at arbitrary times, in a local tangent plane.

    The fixes are mapped to (north, east) [m] in the tangent plane at ``origin``
    (:func:`seawatch.geometry.geodetic_to_north_east`; default origin: the first fix).
    Between two fixes i, i+1 (Δ = t_{i+1} − t_i, s = (t − t_i)/Δ):

        position  p(t) = h00(s) p_i + h10(s) Δ v_i + h01(s) p_{i+1} + h11(s) Δ v_{i+1}
                  (cubic Hermite: h00 = 2s³ − 3s² + 1, h10 = s³ − 2s² + s,
                   h01 = −2s³ + 3s², h11 = s³ − s²)
        velocity  v(t) = (1 − s) v_i + s v_{i+1}

    with v_i the reported velocity (SOG, COG) at fix i when it is plausible, else the
    chord estimate (see ``_knot_velocities``). Speed and course are those of v(t): the
    velocity *vector* is interpolated, so the course turns the short way through North and
    speed and course always describe the same vector, and the positions pass through
    every fix with the reported velocity as their derivative there. Between fixes the
    velocity is the interpolated report rather than the derivative of the cubic, because
    differentiating a curve through fixes with metres of GNSS jitter a second or two
    apart gives velocity errors of metres per second, while the reports (Doppler) are
    smooth. Course is NaN where the speed is below 1e-3 m/s.

    Args:
        track: one vessel (:func:`tracks`).
        times: sample times [s since the epoch], (T,).
        origin: (lat0, lon0) [deg] of the tangent plane (e.g. the camera's foot point).
        max_gap: longest interval between fixes bridged [s]; times inside a longer gap,
            before the first or after the last fix are invalid (NaN). A time equal to a
            fix is always valid.

    Returns:
        TrackSample.
    """
    if not isinstance(track, AisTrack):
        raise ValueError(f"track: expected an AisTrack, got {type(track).__name__}")
    tq = as_float_array("times", times, ndim=1)
    gap = float(max_gap)
    if not gap > 0.0:
        raise ValueError(f"max_gap: expected a positive number of seconds, got {max_gap!r}")
    lat0, lon0 = (
        (float(track.lat[0]), float(track.lon[0]))
        if origin is None
        else (float(origin[0]), float(origin[1]))
    )
    t = track.time
    ne = geodetic_to_north_east(track.lat, track.lon, lat0, lon0)
    ne = np.atleast_2d(ne)
    v = _knot_velocities(t, ne, track.sog, track.cog)
    T = tq.size
    north = np.full(T, np.nan)
    east = np.full(T, np.nan)
    vel = np.full((T, 2), np.nan)
    exact = np.zeros(T, dtype=bool)
    if t.size:
        j = np.searchsorted(t, tq, side="left")
        hit = (j < t.size) & (t[np.minimum(j, t.size - 1)] == tq)
        exact = hit & np.isfinite(tq)
        north[exact] = ne[j[exact], 0]
        east[exact] = ne[j[exact], 1]
        vel[exact] = v[j[exact]]
    if t.size >= 2:
        i = np.clip(np.searchsorted(t, tq, side="right") - 1, 0, t.size - 2)
        dt = t[i + 1] - t[i]
        inside = (tq >= t[0]) & (tq <= t[-1]) & (dt <= gap) & ~exact
        ii = i[inside]
        d = dt[inside]
        s = (tq[inside] - t[ii]) / d
        h00 = 2 * s**3 - 3 * s**2 + 1
        h10 = s**3 - 2 * s**2 + s
        h01 = -2 * s**3 + 3 * s**2
        h11 = s**3 - s**2
        p = (
            h00[:, None] * ne[ii]
            + (h10 * d)[:, None] * v[ii]
            + h01[:, None] * ne[ii + 1]
            + (h11 * d)[:, None] * v[ii + 1]
        )
        north[inside] = p[:, 0]
        east[inside] = p[:, 1]
        vel[inside] = (1 - s)[:, None] * v[ii] + s[:, None] * v[ii + 1]
    valid = np.isfinite(north)
    speed = np.hypot(vel[:, 0], vel[:, 1])
    with np.errstate(invalid="ignore"):
        course = np.where(speed > 1e-3, np.mod(np.arctan2(vel[:, 1], vel[:, 0]), 2 * np.pi), np.nan)
    lat = np.full(T, np.nan)
    lon = np.full(T, np.nan)
    if np.any(valid):
        la, lo = north_east_to_geodetic(np.stack([north[valid], east[valid]], -1), lat0, lon0)
        lat[valid] = la
        lon[valid] = lo
    return TrackSample(
        time=tq,
        north=north,
        east=east,
        lat=lat,
        lon=lon,
        velocity=vel,
        speed=speed,
        course=course,
        valid=valid,
        origin=(lat0, lon0),
    )
