"""Tests of platform NAV input (``seawatch.io.nav``): CSV and NMEA readers, poses, times.

Independent references: pymap3d's geodetic ↔ ENU conversion (the tangent plane), the
standard library's datetime (times), NMEA sentences written here by hand with their
XOR checksums (not by pynmea2), and closed-form platform motion (constant velocity,
constant turn rate) for the interpolation and the 1 s extrapolation rule.
"""

from __future__ import annotations

import math
import re
import warnings
from datetime import UTC, datetime
from functools import reduce
from pathlib import Path

import numpy as np
import pymap3d
import pytest
from hypothesis import given
from hypothesis import strategies as st

from seawatch.io import nav

LAT0, LON0 = 50.80, -1.10
T0 = datetime(2016, 1, 12, 13, 0, 0, tzinfo=UTC).timestamp()


def _latlon(north, east):
    lat, lon, _ = pymap3d.enu2geodetic(east, north, 0.0, LAT0, LON0, 0.0)
    return np.asarray(lat), np.asarray(lon)


def _ne(lat, lon, lat0=LAT0, lon0=LON0):
    e, n, _ = pymap3d.geodetic2enu(lat, lon, 0.0, lat0, lon0, 0.0)
    return np.asarray(n), np.asarray(e)


def _iso(t: float) -> str:
    return datetime.fromtimestamp(t, UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


def _nmea(body: str) -> str:
    chk = reduce(lambda a, c: a ^ ord(c), body, 0)
    return f"${body}*{chk:02X}"


def _ddmm(value: float, is_lat: bool) -> tuple[str, str]:
    hemi = ("N" if value >= 0 else "S") if is_lat else ("E" if value >= 0 else "W")
    v = abs(value)
    deg = int(v)
    minutes = (v - deg) * 60.0
    text = f"{deg:02d}{minutes:09.6f}" if is_lat else f"{deg:03d}{minutes:09.6f}"
    return text, hemi


def _hhmmss(t: float) -> str:
    d = datetime.fromtimestamp(t, UTC)
    return f"{d.hour:02d}{d.minute:02d}{d.second + d.microsecond * 1e-6:05.2f}"


def _gga(t: float, lat: float, lon: float, quality: int = 1) -> str:
    la, ha = _ddmm(lat, True)
    lo, ho = _ddmm(lon, False)
    return _nmea(f"GPGGA,{_hhmmss(t)},{la},{ha},{lo},{ho},{quality},09,0.9,12.0,M,47.0,M,,")


def _rmc(t: float, lat: float, lon: float, sog_kn: float, cog: float, status="A") -> str:
    la, ha = _ddmm(lat, True)
    lo, ho = _ddmm(lon, False)
    d = datetime.fromtimestamp(t, UTC).strftime("%d%m%y")
    return _nmea(f"GPRMC,{_hhmmss(t)},{status},{la},{ha},{lo},{ho},{sog_kn:.2f},{cog:.2f},{d},,")


def _write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def _quiet(fn, *args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", nav.NavWarning)
        return fn(*args, **kw)


# ------------------------------------------------------------------ CSV
def test_csv_lat_lon_iso_times_become_tangent_plane_metres_and_radians(tmp_path):
    north = np.array([0.0, 40.0, 80.0, 120.0])
    east = np.array([0.0, 30.0, 60.0, 90.0])
    lat, lon = _latlon(north, east)
    rows = ["Time,Latitude,Longitude,Heading_deg,Pitch,Roll,Height_m"]
    for k in range(4):
        rows.append(
            f"{_iso(T0 + 10 * k)},{lat[k]:.10f},{lon[k]:.10f},{350 + 5 * k},{k},{-k},{20 + k}"
        )
    track = nav.read_nav(_write(tmp_path, "nav.csv", "\n".join(rows) + "\n"))
    assert track.time == pytest.approx(T0 + 10 * np.arange(4), abs=1e-6)
    assert (track.lat0, track.lon0) == (pytest.approx(lat[0]), pytest.approx(lon[0]))
    assert track.north == pytest.approx(north, abs=1e-4)
    assert track.east == pytest.approx(east, abs=1e-4)
    assert track.heading == pytest.approx(np.radians([350, 355, 0, 5]), abs=1e-12)
    assert track.pitch == pytest.approx(np.radians([0, 1, 2, 3]))
    assert track.roll == pytest.approx(np.radians([0, -1, -2, -3]))
    assert track.height == pytest.approx([20, 21, 22, 23])
    assert not track.heading_from_course.any()
    assert track.counts["kept"] == 4 and track.counts["skipped"] == 0


def test_csv_given_origin_sets_the_tangent_plane(tmp_path):
    lat, lon = _latlon(np.array([500.0, 600.0]), np.array([-200.0, -100.0]))
    text = "t,lat,lon,hdg\n" + "".join(f"{k},{lat[k]:.10f},{lon[k]:.10f},90\n" for k in range(2))
    track = nav.read_nav(_write(tmp_path, "n.csv", text), lat0=LAT0, lon0=LON0)
    assert track.north == pytest.approx([500.0, 600.0], abs=1e-4)
    assert track.east == pytest.approx([-200.0, -100.0], abs=1e-4)
    assert track.time == pytest.approx([0.0, 1.0])  # plain seconds stay seconds


@pytest.mark.parametrize(
    "header", ["time,x,y,heading", "Time_s,North_m,East_m,Heading_deg", "t,north,east,yaw"]
)
def test_csv_local_x_y_and_north_east_columns_mean_north_then_east(tmp_path, header):
    text = header + "\n0,100,-50,45\n2,110,-40,47\n"
    track = nav.read_nav(_write(tmp_path, "local.csv", text))
    assert track.north == pytest.approx([100.0, 110.0])
    assert track.east == pytest.approx([-50.0, -40.0])
    assert np.all(np.isnan(track.lat)) and math.isnan(track.lat0)
    with_origin = nav.read_nav(tmp_path / "local.csv", lat0=LAT0, lon0=LON0)
    n, e = _ne(with_origin.lat, with_origin.lon)
    assert n == pytest.approx([100.0, 110.0], abs=1e-4)
    assert e == pytest.approx([-50.0, -40.0], abs=1e-4)


def test_csv_rows_are_sorted_and_a_repeated_time_keeps_the_first(tmp_path):
    text = "time,x,y,heading\n2,20,0,0\n0,0,0,0\n1,10,0,0\n1,99,0,0\n"
    with pytest.warns(nav.NavWarning, match=r"line 5: duplicate time"):
        track = nav.read_nav(_write(tmp_path, "dup.csv", text))
    assert track.time.tolist() == [0.0, 1.0, 2.0]
    assert track.north.tolist() == [0.0, 10.0, 20.0]
    assert track.counts["duplicate time"] == 1


def test_csv_bad_rows_are_counted_and_warned_with_their_lines(tmp_path):
    text = (
        "time,lat,lon,heading\n"
        "0,50.8,-1.1,10\n"  # 2 ok
        "one,50.8,-1.1,10\n"  # 3 bad time
        "2,50.8,-1.1\n"  # 4 too few fields
        "3,95,-1.1,10\n"  # 5 out of range
        "4,50.8,west,10\n"  # 6 bad number
        "5,,,\n"  # 7 nothing
        "6,50.8001,-1.1,12\n"  # 8 ok
    )
    with pytest.warns(nav.NavWarning) as rec:
        track = nav.read_nav(_write(tmp_path, "bad.csv", text))
    reasons = {s.line: s.reason for s in track.skipped}
    assert reasons == {
        3: "unparsable",
        4: "unparsable",
        5: "out of range",
        6: "unparsable",
        7: "empty",
    }
    assert track.counts["rows"] == 7 and track.counts["kept"] == 2
    messages = [str(w.message) for w in rec]
    for line in reasons:
        assert any(f"bad.csv, line {line}:" in m for m in messages)


def test_csv_heading_comes_from_course_only_while_making_way(tmp_path):
    text = (
        "time,x,y,cog,sog\n"
        "0,0,0,90,5\n"  # 5 kn: heading = course
        "1,2.5,0,91,5\n"
        "2,5,0,270,0.2\n"  # 0.2 kn: course meaningless, heading unknown
    )
    track = nav.read_nav(_write(tmp_path, "cog.csv", text))
    assert track.heading[:2] == pytest.approx(np.radians([90, 91]))
    assert math.isnan(track.heading[2])
    assert track.heading_from_course.tolist() == [True, True, False]
    assert track.speed == pytest.approx(np.array([5, 5, 0.2]) * 1852 / 3600)
    assert track.course == pytest.approx(np.radians([90, 91, 270]))


def test_course_does_not_replace_a_true_heading_known_nearby(tmp_path):
    text = "time,x,y,heading,course\n0,0,0,10,40\n1,1,0,,40\n2,2,0,12,40\n30,3,0,,40\n"
    track = nav.read_nav(_write(tmp_path, "mix.csv", text))
    # row at 1 s: true heading 1 s away -> interpolated later, not the course;
    # row at 30 s: no heading within MAX_GAP -> the course stands in
    assert math.isnan(track.heading[1])
    assert track.heading[3] == pytest.approx(math.radians(40))
    assert track.heading_from_course.tolist() == [False, False, False, True]


# ------------------------------------------------------------------ NMEA
def _nmea_day(tmp_path: Path) -> tuple[Path, dict]:
    """Five GGA fixes 5 s apart across midnight, RMC dating the second, HDT and VTG."""
    start = datetime(2015, 12, 31, 23, 59, 50, tzinfo=UTC).timestamp()
    north = 12.0 * np.arange(5)
    east = 3.0 * np.arange(5)
    lat, lon = _latlon(north, east)
    lines = []
    for k in range(5):
        t = start + 5 * k
        lines.append(_gga(t, lat[k], lon[k]))
        if k == 1:
            lines.append(_rmc(t, lat[k], lon[k], 4.9, 14.0))
        lines.append(_nmea(f"HEHDT,{(358.0 + k) % 360:.1f},T"))
        lines.append(_nmea(f"HEHDT,{(100.0 + k) % 360:.1f},T"))  # a second one: ignored
        lines.append(_nmea("GPVTG,14.0,T,,M,4.9,N,9.07,K,A"))
    lines.insert(0, _nmea("HEHDT,200.0,T"))  # before any time: untimed, dropped
    lines.append(_nmea("GPGSV,1,1,00"))  # another type: ignored
    truth = {"start": start, "lat": lat, "lon": lon}
    return _write(tmp_path, "nav.nmea", "\n".join(lines) + "\n"), truth


def test_nmea_fixes_are_dated_by_rmc_and_unwrapped_across_midnight(tmp_path):
    path, truth = _nmea_day(tmp_path)
    track = nav.read_nav(path)
    assert track.time == pytest.approx(truth["start"] + 5 * np.arange(5), abs=1e-6)
    assert track.lat == pytest.approx(truth["lat"], abs=1e-8)
    assert track.lon == pytest.approx(truth["lon"], abs=1e-8)
    n, e = _ne(track.lat, track.lon, truth["lat"][0], truth["lon"][0])
    assert track.north == pytest.approx(n, abs=1e-3)
    assert track.east == pytest.approx(e, abs=1e-3)
    assert track.heading == pytest.approx(np.radians([358, 359, 0, 1, 2]), abs=1e-12)
    assert track.course == pytest.approx(np.full(5, math.radians(14.0)))
    assert track.speed == pytest.approx(np.full(5, 4.9 * 1852 / 3600))
    assert track.counts["untimed"] == 1 and track.counts["ignored"] == 1
    assert track.counts["skipped"] == 0


def test_nmea_without_heading_sentences_uses_course_over_ground(tmp_path):
    start = T0
    lat, lon = _latlon(np.arange(3) * 10.0, np.zeros(3))
    lines = [_rmc(start + k, lat[k], lon[k], 8.0, 3.0 + k) for k in range(3)]
    track = nav.read_nav(_write(tmp_path, "rmc.nmea", "\n".join(lines)))
    assert track.heading == pytest.approx(np.radians([3.0, 4.0, 5.0]))
    assert track.heading_from_course.all()
    assert track.time == pytest.approx(start + np.arange(3), abs=1e-6)


def test_nmea_bad_sentences_are_counted_and_warned_with_their_lines(tmp_path):
    lat, lon = _latlon(np.zeros(2), np.zeros(2))
    good = _gga(T0, lat[0], lon[0])
    lines = [
        _rmc(T0, lat[0], lon[0], 1.0, 0.0),  # 1 ok (date)
        good[:-2] + "00",  # 2 bad checksum
        "some text",  # 3 not NMEA
        _gga(T0 + 1, lat[0], lon[0], quality=0),  # 4 no fix
        _rmc(T0 + 2, lat[0], lon[0], 1.0, 0.0, status="V"),  # 5 void fix
        _nmea("GPGGA,12x519,abc"),  # 6 garbage time
        _gga(T0 + 3, lat[1], lon[1]),  # 7 ok
        _nmea("HEHDT,45.0,T"),  # 8 ok
        "!AIVDO,1,1,,,B5NJ;PP005l4ot5Isbl03wsUkP06,0*76",  # 9 own-ship AIS: ignored
    ]
    with pytest.warns(nav.NavWarning) as rec:
        track = nav.read_nav(_write(tmp_path, "bad.nmea", "\n".join(lines) + "\n"))
    reasons = {s.line: s.reason for s in track.skipped}
    assert reasons == {
        2: "bad checksum",
        3: "unparsable",
        4: "no fix",
        5: "no fix",
        6: "unparsable",
    }
    messages = [str(w.message) for w in rec]
    for line in reasons:
        assert any(f"bad.nmea, line {line}:" in m for m in messages)
    assert track.time == pytest.approx([T0, T0 + 3], abs=1e-6)
    assert track.counts["ignored"] == 1 and track.counts["rows"] == 9


def test_nmea_without_a_date_warns_and_the_date_argument_dates_it(tmp_path):
    lat, lon = _latlon(np.zeros(2), np.zeros(2))
    t = datetime(2016, 1, 12, 13, 0, 5, tzinfo=UTC).timestamp()
    text = "\n".join([_gga(t, lat[0], lon[0]), _nmea("GPHDT,10.0,T")])
    path = _write(tmp_path, "nodate.nmea", text)
    with pytest.warns(nav.NavWarning, match="no date"):
        track = nav.read_nav(path)
    assert track.time[0] == pytest.approx(13 * 3600 + 5)
    dated = nav.read_nav(path, date="2016-01-12")
    assert dated.time[0] == pytest.approx(t, abs=1e-6)
    with pytest.raises(ValueError, match="date"):
        nav.read_nav(path, date="12/01/2016")


def test_pashr_attitude_gives_heading_roll_and_pitch(tmp_path):
    lat, lon = _latlon(np.zeros(1), np.zeros(1))
    lines = [
        _rmc(T0, lat[0], lon[0], 0.0, 0.0),
        _nmea(f"PASHR,{_hhmmss(T0)},123.40,T,-1.50,2.25,0.00,0.02,0.02,0.05,1,0"),
    ]
    track = nav.read_nav(_write(tmp_path, "ashr.nmea", "\n".join(lines)))
    assert track.heading[0] == pytest.approx(math.radians(123.4))
    assert track.roll[0] == pytest.approx(math.radians(-1.5))
    assert track.pitch[0] == pytest.approx(math.radians(2.25))


def test_read_nav_tells_nmea_from_csv_by_the_first_line(tmp_path):
    path, _ = _nmea_day(tmp_path)
    assert nav.read_nav(path).counts.get("fixes") == 6  # NMEA reader (5 GGA + 1 RMC)
    csv_path = _write(tmp_path, "x.txt", "# a comment\n\ntime,x,y,heading\n0,0,0,0\n")
    assert "fixes" not in nav.read_nav(csv_path).counts


# ------------------------------------------------------------------ bad input
def test_missing_file_raises_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"nope\.csv"):
        nav.read_nav(tmp_path / "nope.csv")


@pytest.mark.parametrize(
    ("header", "missing"),
    [
        ("lat,lon,heading", "time"),
        ("time,lat,heading", "position"),
        ("time,lat,lon", "heading"),
    ],
)
def test_csv_without_required_columns_names_the_file_and_what_is_missing(tmp_path, header, missing):
    path = _write(tmp_path, "cols.csv", header + "\n1,2,3\n")
    with pytest.raises(ValueError, match=rf"cols\.csv.*{missing}"):
        nav.read_nav(path)


def test_no_usable_fix_or_no_heading_is_a_value_error_naming_the_file(tmp_path):
    no_fix = _write(tmp_path, "nofix.csv", "time,lat,lon,heading\n0,,,10\n1,,,11\n")
    with pytest.raises(ValueError, match=r"nofix\.csv: no usable position fix"):
        nav.read_nav(no_fix)
    no_hdg = _write(tmp_path, "nohdg.csv", "time,x,y,heading\n0,0,0,\n1,1,0,\n")
    with pytest.raises(ValueError, match=r"nohdg\.csv: no heading"):
        nav.read_nav(no_hdg)
    lat, lon = _latlon(np.zeros(1), np.zeros(1))
    gga_only = _write(tmp_path, "gga.nmea", _gga(T0, lat[0], lon[0]) + "\n")
    with pytest.raises(ValueError, match=r"gga\.nmea: no heading"):
        _quiet(nav.read_nav, gga_only)
    with pytest.raises(ValueError, match="empty"):
        nav.read_nav(_write(tmp_path, "empty.csv", "\n# nothing\n"))


def test_bad_origin_and_bad_arrays_are_value_errors_naming_the_argument(tmp_path):
    path = _write(tmp_path, "o.csv", "time,lat,lon,heading\n0,50,-1,0\n")
    with pytest.raises(ValueError, match="lat0"):
        nav.read_nav(path, lat0=95.0, lon0=0.0)
    with pytest.raises(ValueError, match="north"):
        nav.NavTrack.from_arrays([0, 1], [0.0], [0, 0], [0, 0])
    with pytest.raises(ValueError, match="time"):
        nav.NavTrack.from_arrays([0, 0], [0, 1], [0, 0], [0, 0])
    track = nav.NavTrack.from_arrays([0, 1], [0, 1], [0, 0], [0, 0])
    with pytest.raises(ValueError, match="max_extrapolation"):
        track.pose_at([0.5], max_extrapolation=-1)
    with pytest.raises(ValueError, match="max_gap"):
        track.pose_at([0.5], max_gap=0)
    with pytest.raises(ValueError, match="times"):
        track.pose_at([[0.5]])


# ------------------------------------------------------------------ poses
def _platform() -> nav.NavTrack:
    """Constant velocity (3, -4) m/s, heading turning at 2 deg/s through North, 1 Hz."""
    t = T0 + np.arange(11.0)
    k = np.arange(11.0)
    return nav.NavTrack.from_arrays(
        t,
        100.0 + 3.0 * k,
        -50.0 - 4.0 * k,
        np.radians(350.0 + 2.0 * k),
        pitch=np.radians(0.1 * k),
        lat0=LAT0,
        lon0=LON0,
    )


def test_pose_interpolation_reproduces_constant_velocity_and_turn_rate():
    track = _platform()
    s = np.array([0.0, 0.25, 4.5, 5.0, 9.75, 10.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error", nav.NavWarning)  # all inside: no warning
        poses = track.pose_at(T0 + s)
    assert poses.valid.all() and not poses.extrapolated.any()
    assert poses.north == pytest.approx(100.0 + 3.0 * s, abs=1e-9)
    assert poses.east == pytest.approx(-50.0 - 4.0 * s, abs=1e-9)
    expected = np.mod(np.radians(350.0 + 2.0 * s), 2 * np.pi)
    assert np.abs(np.angle(np.exp(1j * (poses.heading - expected)))).max() < 1e-9
    assert poses.velocity == pytest.approx(np.tile([3.0, -4.0], (6, 1)), abs=1e-9)
    assert poses.pitch == pytest.approx(np.radians(0.1 * s))
    assert np.all(np.isnan(poses.roll)) and np.all(np.isnan(poses.height))
    lat, lon = _latlon(poses.north, poses.east)
    assert poses.lat == pytest.approx(lat, abs=1e-9)
    assert poses.lon == pytest.approx(lon, abs=1e-9)


def test_pose_extrapolates_at_most_one_second_then_is_unknown_with_one_warning():
    track = _platform()  # data 0..10 s
    s = np.array([-3.0, -1.5, -0.5, 5.0, 10.8, 11.0, 11.2, 13.0])
    with pytest.warns(nav.NavWarning) as rec:
        poses = track.pose_at(T0 + s)
    assert len(rec) == 1
    msg = str(rec[0].message)
    # requested 16 s (-3..13), covered 0..10: 6 s not covered
    assert re.search(r"\b6 s of the requested 16 s", msg), msg
    assert "3 of 8 poses extrapolated" in msg and "4 marked unknown" in msg
    assert poses.valid.tolist() == [False, False, True, True, True, True, False, False]
    assert poses.extrapolated.tolist() == [False, False, True, False, True, True, False, False]
    ok = poses.valid
    assert poses.north[ok] == pytest.approx(100.0 + 3.0 * s[ok], abs=1e-5)  # linear
    assert poses.east[ok] == pytest.approx(-50.0 - 4.0 * s[ok], abs=1e-5)
    for name in ("north", "east", "heading", "lat", "lon", "pitch"):
        assert np.all(np.isnan(getattr(poses, name)[~ok])), name
    assert np.all(np.isnan(poses.velocity[~ok]))


def test_max_extrapolation_zero_gives_exactly_the_span():
    track = _platform()
    with pytest.warns(nav.NavWarning):
        poses = track.pose_at(T0 + np.array([-1e-6, 0.0, 10.0, 10.0 + 1e-6]), max_extrapolation=0)
    assert poses.valid.tolist() == [False, True, True, False]


def test_video_time_alignment_with_a_start_time():
    track = _platform()
    start = nav.parse_time("2016-01-12T13:00:02Z")
    poses = track.pose_at(np.array([0.0, 1.0]) + start)  # video times 0 and 1 s
    assert poses.north == pytest.approx([106.0, 109.0])


def test_gap_longer_than_max_gap_is_unknown_except_near_its_ends():
    t = np.array([0.0, 1.0, 2.0, 30.0, 31.0])
    track = nav.NavTrack.from_arrays(t, t * 2.0, np.zeros(5), np.zeros(5))
    q = np.array([1.5, 2.5, 16.0, 29.5, 30.5])
    with pytest.warns(nav.NavWarning, match="gaps over 10 s") as rec:
        poses = track.pose_at(q)
    assert poses.valid.tolist() == [True, True, False, True, True]
    assert poses.extrapolated.tolist() == [False, True, False, True, False]
    assert poses.north[[0, 1, 3, 4]] == pytest.approx([3.0, 5.0, 59.0, 61.0])
    # the uncovered part of 1.5..30.5 s is the 28 s gap between 2 and 30 s
    assert "28 s of the requested 29 s" in str(rec[0].message)
    bridged = track.pose_at(q, max_gap=30.0)
    assert bridged.valid.all() and bridged.north[2] == pytest.approx(32.0)


def test_attitude_and_height_outside_their_samples_do_not_invalidate_the_pose():
    t = np.arange(5.0)
    roll = np.array([np.nan, 0.1, 0.2, np.nan, np.nan])
    track = nav.NavTrack.from_arrays(t, t, t, np.zeros(5), roll=roll, height=np.full(5, 15.0))
    poses = track.pose_at([0.5, 1.5, 3.5])
    assert poses.valid.all()
    assert poses.roll[1] == pytest.approx(0.15)
    assert poses.roll[0] == pytest.approx(0.05)  # 0.5 s before the first roll sample
    assert math.isnan(poses.roll[2])  # 1.5 s after the last one
    assert poses.height == pytest.approx([15.0, 15.0, 15.0])


def test_nmea_heading_only_epochs_fill_the_heading_between_fixes(tmp_path):
    lat, lon = _latlon(np.array([0.0, 20.0]), np.zeros(2))
    lines = [
        _rmc(T0, lat[0], lon[0], 0.0, 0.0),
        _nmea(f"PASHR,{_hhmmss(T0 + 0.5)},30.00,T,0.00,0.00,0.00,0.02,0.02,0.05,1,0"),
        _gga(T0 + 2, lat[1], lon[1]),
        _nmea("GPHDT,20.0,T"),
        _nmea(f"PASHR,{_hhmmss(T0 + 0.1)},10.00,T,0.00,0.00,0.00,0.02,0.02,0.05,1,0"),
    ]
    track = nav.read_nav(_write(tmp_path, "mixed.nmea", "\n".join(lines)))
    assert len(track) == 4  # 0, 0.1, 0.5 and 2 s
    poses = track.pose_at(T0 + np.array([0.1, 1.0, 1.25]))
    assert poses.valid.all()
    assert poses.north == pytest.approx([1.0, 10.0, 12.5], abs=1e-3)
    assert np.degrees(poses.heading) == pytest.approx([10.0, 26.6666667, 25.0])


@given(
    st.lists(st.floats(0.05, 3.0), min_size=2, max_size=12),
    st.lists(st.floats(-1e4, 1e4), min_size=12, max_size=12),
)
def test_poses_pass_through_the_samples_and_stay_between_neighbours(steps, values):
    t = np.cumsum(steps)
    v = np.asarray(values[: t.size])
    track = nav.NavTrack.from_arrays(t, v, -v, np.zeros(t.size))
    at = track.pose_at(t)
    assert at.valid.all() and np.array_equal(at.north, v)
    mid = 0.5 * (t[1:] + t[:-1])
    between = track.pose_at(mid).north
    assert np.all(between >= np.minimum(v[1:], v[:-1]) - 1e-9)
    assert np.all(between <= np.maximum(v[1:], v[:-1]) + 1e-9)


# ------------------------------------------------------------------ parse_time
def test_parse_time_accepts_iso_utc_offsets_and_epoch_seconds():
    t = datetime(2016, 1, 12, 13, 2, 11, 500000, tzinfo=UTC).timestamp()
    for text in (
        "2016-01-12T13:02:11.5Z",
        "2016-01-12 13:02:11.5",
        "2016-01-12T14:02:11.5+01:00",
        f"{t}",
        t,
    ):
        assert nav.parse_time(text) == pytest.approx(t, abs=1e-6), text
    with pytest.raises(ValueError, match="start"):
        nav.parse_time("yesterday", name="start")
    with pytest.raises(ValueError, match="start"):
        nav.parse_time(float("nan"), name="start")
