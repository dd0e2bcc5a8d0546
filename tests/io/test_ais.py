"""Tests of AIS input (``seawatch.io.ais``): CSV and NMEA readers, tracks, interpolation.

Real data (``../shared/data/ais/``, see its README): the Solent file of decoded reports
(Stone Soup ``docs/demos/SolentAIS_20160112_130211.csv``, MIT) and raw NMEA samples of
the pyais tests (``nmea_data_sample.txt``, ``timestamped.ais``, MIT). Independent
references: the files read with the ``csv`` module and plain string matching, and pyais's
own ``FileReaderStream`` decoding.
"""

from __future__ import annotations

import csv
import math
import warnings
from collections import Counter
from datetime import UTC, datetime
from functools import reduce
from pathlib import Path

import numpy as np
import pytest

from seawatch.geometry import geodetic_to_north_east, north_east_to_geodetic
from seawatch.io import ais

DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "ais"
SOLENT = DATA / "solent_2016-01-12_1302-1344.csv"
SAMPLE = DATA / "nmea_data_sample.txt"
STAMPED = DATA / "timestamped.ais"
KNOT = 1852.0 / 3600.0


def _need(path: Path) -> Path:
    if not path.exists():
        pytest.skip(f"AIS test data not found at {path} (../shared/data/ais, see its README)")
    return path


@pytest.fixture(scope="module")
def solent() -> ais.AisTable:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ais.AisWarning)
        return ais.read_ais_csv(_need(SOLENT))


@pytest.fixture(scope="module")
def sample() -> ais.AisTable:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ais.AisWarning)
        return ais.read_ais_nmea(_need(SAMPLE))


def _raw_rows(path: Path) -> list[list[str]]:
    with path.open(newline="") as fh:
        return list(csv.reader(fh))[1:]


def _nmea(body: str) -> str:
    """An NMEA sentence with its checksum (XOR of the characters between ! and *)."""
    chk = reduce(lambda a, c: a ^ ord(c), body, 0)
    return f"!{body}*{chk:02X}"


# ------------------------------------------------------------------ Solent CSV
def test_solent_csv_keeps_every_row_but_the_corrupt_longitude_54_83(solent):
    rows = _raw_rows(_need(SOLENT))
    assert len(rows) == 8783 == solent.counts["rows"]
    corrupt = [i for i, r in enumerate(rows) if float(r[3]) > 0]  # every other lon is west
    assert len(corrupt) == 1 and rows[corrupt[0]][3].startswith("54.83")
    assert len(solent) == 8782 == solent.counts["kept"]
    assert [s.line for s in solent.skipped] == [corrupt[0] + 2]  # header is line 1
    assert solent.skipped[0].reason == "impossible jump"
    assert np.all(solent.lon < 0) and 54.83 not in np.round(solent.lon, 2)
    assert solent.vessels.size == len({r[1] for r in rows}) == 84
    assert "1 skipped" in solent.summary() and "impossible jump" in solent.summary()


def test_solent_csv_warns_naming_the_corrupt_line():
    with pytest.warns(ais.AisWarning, match=r"line 8209: impossible jump.*245188000"):
        ais.read_ais_csv(_need(SOLENT))


def test_csv_converts_knots_and_degrees_and_parses_times_as_utc_seconds(solent):
    rows = _raw_rows(_need(SOLENT))
    first = rows[0]  # 2016-01-12 13:02:11.218, 235070762, ..., COG 157.8, SOG 5.9
    expected_t = datetime(2016, 1, 12, 13, 2, 11, 218000, tzinfo=UTC).timestamp()
    assert solent.time[0] == pytest.approx(expected_t, abs=1e-6)
    assert solent.mmsi[0] == int(first[1])
    assert solent.lat[0] == float(first[2]) and solent.lon[0] == float(first[3])
    assert solent.cog[0] == pytest.approx(math.radians(float(first[4])), rel=1e-12)
    assert solent.sog[0] == pytest.approx(float(first[5]) * 1852 / 3600, rel=1e-12)
    assert np.all(np.isnan(solent.heading))
    # the whole file spans 13:02-13:44 UTC
    assert solent.time.min() == pytest.approx(expected_t, abs=1e-6)
    end = datetime(2016, 1, 12, 13, 45, tzinfo=UTC).timestamp()
    assert solent.time.max() < end


def test_csv_bad_rows_are_counted_and_skipped_with_their_lines(tmp_path):
    text = (
        "Time,MMSI,Latitude_degrees,Longitude_degrees,COG_degrees,SOG_knots\n"
        "2016-01-12 13:00:00,111111111,50.80,-1.10,90,10\n"  # line 2 ok
        "not a time,111111111,50.80,-1.10,90,10\n"  # 3 unparsable time
        "2016-01-12 13:00:10,111111111,fifty,-1.10,90,10\n"  # 4 unparsable lat
        "2016-01-12 13:00:10,111111111,95.0,-1.10,90,10\n"  # 5 out of range
        "2016-01-12 13:00:10,111111111,50.80,-1.10\n"  # 6 too few fields
        "2016-01-12 13:00:10,111111111,50.80,-1.0997,90,10\n"  # 7 ok (~51 m in 10 s)
        "2016-01-12 13:00:20,111111111,50.80,-0.90,90,10\n"  # 8 jump: 14 km in 10 s
        "2016-01-12 13:00:30,111111111,50.80,-1.0989,90,102.3\n"  # 9 ok, SOG n/a
        "2016-01-12 13:00:40,111111111,50.80,-1.0985,360,\n"  # 10 ok, COG n/a, SOG empty
        "2016-01-12 13:00:40,222222222,91,181,360,102.3\n"  # 11 position n/a
    )
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.warns(ais.AisWarning) as rec:
        table = ais.read_ais_csv(path)
    assert table.counts["rows"] == 10
    assert list(table.line) == [2, 7, 9, 10]
    skipped = {s.line: s.reason for s in table.skipped}
    assert skipped == {
        3: "unparsable",
        4: "unparsable",
        5: "out of range",
        6: "unparsable",
        8: "impossible jump",
        11: "out of range",
    }
    assert table.counts["unparsable"] == 3 and table.counts["out of range"] == 2
    messages = [str(w.message) for w in rec]
    for line in skipped:
        assert any(f"line {line}:" in m for m in messages)
    assert np.isnan(table.sog[2]) and np.isnan(table.cog[3]) and np.isnan(table.sog[3])
    assert table.cog[0] == pytest.approx(math.pi / 2)


def test_impossible_first_fix_is_the_one_removed_not_the_good_track_after_it(tmp_path):
    lines = ["Time,MMSI,Latitude_degrees,Longitude_degrees,COG_degrees,SOG_knots"]
    lines.append("2016-01-12 13:00:00,123456789,10.0,10.0,0,0")  # nonsense first fix
    for k in range(1, 6):
        lines.append(f"2016-01-12 13:00:{10 * k:02d},123456789,{50.8 + 1e-4 * k},-1.1,0,10")
    path = tmp_path / "first.csv"
    path.write_text("\n".join(lines) + "\n")
    with pytest.warns(ais.AisWarning, match="line 2: impossible jump"):
        table = ais.read_ais_csv(path)
    assert list(table.line) == [3, 4, 5, 6, 7]


def test_csv_without_the_columns_names_what_is_missing(tmp_path):
    path = tmp_path / "x.csv"
    path.write_text("Time,MMSI,lat\n2016-01-12 13:00:00,1,50\n")
    with pytest.raises(ValueError, match=r"missing column\(s\) Longitude_degrees, COG_degrees"):
        ais.read_ais_csv(path)


def test_missing_file_raises_file_not_found(tmp_path):
    for reader in (ais.read_ais_csv, ais.read_ais_nmea, ais.read_ais):
        with pytest.raises(FileNotFoundError, match=r"nope\.csv"):
            reader(tmp_path / "nope.csv")


# ------------------------------------------------------------------ NMEA
def test_nmea_sample_decodes_778_messages_as_pyais_counts_them(sample):
    from pyais.stream import FileReaderStream

    ok = types = 0
    type_counts: Counter[int] = Counter()
    for msg in FileReaderStream(str(_need(SAMPLE))):
        try:
            d = msg.decode()
        except Exception:
            continue
        ok += 1
        type_counts[d.msg_type] += 1
    types = sum(type_counts[t] for t in (1, 2, 3, 18, 19))
    assert ok == 778 == sample.counts["decoded"]  # the data README's figure
    assert sample.counts["position_reports"] == types
    assert sample.counts["other_types"] == 778 - types


def test_nmea_sample_counts_its_bad_lines(sample):
    lines = _need(SAMPLE).read_text().splitlines()
    empty = [i + 1 for i, ln in enumerate(lines) if ln.split(",")[5:6] == [""]]
    first_parts = [i + 1 for i, ln in enumerate(lines) if ln.startswith("!AIVDM,2,1,")]
    second_parts = [ln for ln in lines if ln.startswith("!AIVDM,2,2,")]
    assert len(lines) == sample.counts["rows"] == 898
    assert len(empty) == 100 and sample.counts["undecodable"] == 100
    assert not second_parts and len(first_parts) == 20 == sample.counts["incomplete"]
    skipped = {s.line for s in sample.skipped if s.reason in ("undecodable", "incomplete")}
    assert skipped == set(empty) | set(first_parts)
    # rows = position reports with a position (lat 91 / lon 181 means none)
    assert len(sample) == sample.counts["position_reports"] - sample.counts["no position"]
    assert np.all(np.abs(sample.lat) <= 90) and np.all(np.abs(sample.lon) <= 180)
    assert set(np.unique(sample.msg_type)) <= {1, 2, 3, 18, 19}
    assert np.all(np.isnan(sample.time))  # this file has no timestamps


def test_nmea_rows_match_pyais_decoding_and_si_units(sample):
    from pyais import decode

    line = _need(SAMPLE).read_text().splitlines()[2]  # !AIVDM,1,1,,A,13RlIW?04F1b...
    ref = decode(line)
    row = int(np.flatnonzero(sample.line == 3)[0])
    assert sample.mmsi[row] == ref.mmsi
    assert sample.lat[row] == pytest.approx(ref.lat) and sample.lon[row] == pytest.approx(ref.lon)
    assert sample.sog[row] == pytest.approx(ref.speed * KNOT)
    assert sample.cog[row] == pytest.approx(math.radians(ref.course))
    if ref.heading != 511:
        assert sample.heading[row] == pytest.approx(math.radians(ref.heading))


def test_gatehouse_lines_timestamp_the_message_after_them():
    with warnings.catch_warnings():
        warnings.simplefilter("error", ais.AisWarning)  # nothing in this file is bad
        table = ais.read_ais_nmea(_need(STAMPED))
    assert len(table) == 4
    t08 = datetime(2008, 5, 9, 0, 0, 0, 10000, tzinfo=UTC).timestamp()
    t09 = datetime(2009, 5, 9, 0, 0, 0, 10000, tzinfo=UTC).timestamp()
    assert table.time[0] == pytest.approx(t08) and table.time[2] == pytest.approx(t09)
    assert np.isnan(table.time[1]) and np.isnan(table.time[3])  # no $PGHP before them
    assert list(table.mmsi) == [367309370, 413355820, 445451000, 412764890]


def test_multi_sentence_messages_are_joined_and_broken_ones_counted(tmp_path):
    payload = "15NBj>PP1gG>1PVKTDTUJOv00<0M"  # a type-1 report (timestamped.ais)
    single = _nmea(f"AIVDM,1,1,,B,{payload},0")
    frag1 = _nmea(f"AIVDM,2,1,7,B,{payload[:14]},0")
    frag2 = _nmea(f"AIVDM,2,2,7,B,{payload[14:]},0")
    orphan = _nmea(f"AIVDM,2,2,3,A,{payload[14:]},0")
    bad_sum = single[:-2] + ("00" if single[-2:] != "00" else "01")
    stamped = "\\s:rcv,c:1452603731*00\\" + single  # tag block receiver time
    path = tmp_path / "frag.nmea"
    path.write_text("\n".join([single, frag1, frag2, orphan, bad_sum, "$GPGGA,x*00", stamped]))
    with pytest.warns(ais.AisWarning):
        table = ais.read_ais_nmea(path)
    assert len(table) == 3 and list(table.line) == [1, 2, 7]
    assert table.mmsi[0] == table.mmsi[1] == 367309370
    assert table.lat[1] == table.lat[0] and table.lon[1] == table.lon[0]
    assert {(s.line, s.reason) for s in table.skipped} == {(4, "incomplete"), (5, "bad checksum")}
    assert table.counts["ignored_lines"] == 1
    assert table.time[2] == 1452603731.0 and np.isnan(table.time[0])


def test_read_ais_tells_nmea_from_csv(solent):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ais.AisWarning)
        assert ais.read_ais(_need(STAMPED)).counts["decoded"] == 4
        assert len(ais.read_ais(_need(SOLENT))) == len(solent)


# ------------------------------------------------------------------ tracks
def test_tracks_are_time_sorted_without_duplicate_times(solent):
    trs = ais.tracks(solent)
    assert sorted(trs) == list(trs) == sorted(int(m) for m in solent.vessels)
    pairs = Counter(zip(solent.mmsi.tolist(), solent.time.tolist(), strict=True))
    assert sum(len(t) for t in trs.values()) == len(pairs)  # one report per (vessel, time)
    for tr in trs.values():
        assert np.all(np.diff(tr.time) > 0)


def test_tracks_keep_the_first_report_of_a_repeated_time(tmp_path):
    path = tmp_path / "dup.csv"
    path.write_text(
        "Time,MMSI,Latitude_degrees,Longitude_degrees,COG_degrees,SOG_knots\n"
        "2016-01-12 13:00:20,5,50.8002,-1.1,0,1\n"
        "2016-01-12 13:00:00,5,50.8000,-1.1,0,1\n"
        "2016-01-12 13:00:20,5,50.8003,-1.1,0,1\n"
        "2016-01-12 13:00:10,5,50.8001,-1.1,0,1\n"
    )
    tr = ais.tracks(ais.read_ais_csv(path))[5]
    assert list(tr.line) == [3, 5, 2]
    assert list(tr.lat) == [50.8, 50.8001, 50.8002]


def test_tracks_leave_out_reports_without_time_with_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ais.AisWarning)
        table = ais.read_ais_nmea(_need(STAMPED))
    with pytest.warns(ais.AisWarning, match="2 reports without a time"):
        trs = ais.tracks(table)
    assert sorted(trs) == [367309370, 445451000]


# ------------------------------------------------------------------ interpolation
def _track(times, ne, v, origin=(50.78, -1.1), mmsi=1):
    """An AisTrack from positions in the tangent plane at origin and velocities [m/s]."""
    lat, lon = north_east_to_geodetic(np.asarray(ne, float), *origin)
    v = np.asarray(v, float)
    return ais.AisTrack(
        mmsi=mmsi,
        time=np.asarray(times, float),
        lat=np.atleast_1d(lat),
        lon=np.atleast_1d(lon),
        sog=np.hypot(v[:, 0], v[:, 1]),
        cog=np.mod(np.arctan2(v[:, 1], v[:, 0]), 2 * np.pi),
        heading=np.full(len(times), np.nan),
        line=np.arange(len(times)),
    )


def test_interpolation_reproduces_constant_velocity_motion_exactly():
    v = np.array([3.0, -4.0])
    t = np.array([0.0, 7.0, 19.0, 30.0])
    ne = np.array([100.0, 200.0]) + t[:, None] * v
    tr = _track(t, ne, np.tile(v, (4, 1)))
    tq = np.linspace(0.0, 30.0, 61)
    s = ais.interpolate_track(tr, tq, origin=(50.78, -1.1))
    assert np.all(s.valid)
    expect = np.array([100.0, 200.0]) + tq[:, None] * v
    np.testing.assert_allclose(np.stack([s.north, s.east], -1), expect, atol=1e-6)
    np.testing.assert_allclose(s.speed, 5.0, rtol=1e-9)
    np.testing.assert_allclose(s.course, math.atan2(-4.0, 3.0) + 2 * math.pi, rtol=1e-9)
    lat, lon = north_east_to_geodetic(expect, 50.78, -1.1)
    np.testing.assert_allclose(s.lat, lat, atol=1e-10)
    np.testing.assert_allclose(s.lon, lon, atol=1e-10)


def test_interpolation_passes_through_the_fixes_in_another_origin_frame():
    t = np.array([0.0, 10.0, 20.0])
    ne = np.array([[0.0, 0.0], [50.0, 10.0], [90.0, 40.0]])
    v = np.array([[5.0, 0.5], [4.5, 2.0], [3.5, 3.5]])
    tr = _track(t, ne, v)
    s = ais.interpolate_track(tr, t, origin=(50.79, -1.12))
    ref = geodetic_to_north_east(tr.lat, tr.lon, 50.79, -1.12)
    np.testing.assert_allclose(np.stack([s.north, s.east], -1), ref, atol=1e-6)
    np.testing.assert_allclose(s.velocity, v, atol=1e-9)  # the reports, consistent ones


def test_course_turns_the_short_way_through_north():
    # 350° then 10° at the same speed: halfway the course is 0°, not 180°
    v = 5.0 * np.array(
        [[math.cos(math.radians(a)), math.sin(math.radians(a))] for a in (350.0, 10.0)]
    )
    ne = np.array([[0.0, 0.0], [50.0, 0.0]])
    s = ais.interpolate_track(_track([0.0, 10.0], ne, v), [5.0], origin=(50.78, -1.1))
    assert min(s.course[0], 2 * math.pi - s.course[0]) < 1e-9
    assert s.speed[0] == pytest.approx(5.0 * math.cos(math.radians(10.0)))
    assert math.atan2(s.velocity[0, 1], s.velocity[0, 0]) == pytest.approx(0.0, abs=1e-12)


def test_outside_the_track_and_inside_long_gaps_nothing_is_invented():
    t = np.array([0.0, 10.0, 400.0, 410.0])
    ne = np.array([[0.0, 0.0], [50.0, 0.0], [2000.0, 0.0], [2050.0, 0.0]])
    v = np.tile([5.0, 0.0], (4, 1))
    tr = _track(t, ne, v)
    s = ais.interpolate_track(tr, [-1.0, 5.0, 200.0, 400.0, 405.0, 411.0], origin=(50.78, -1.1))
    assert list(s.valid) == [False, True, False, True, True, False]
    assert np.all(np.isnan(s.north[~s.valid])) and np.all(np.isnan(s.speed[~s.valid]))
    s2 = ais.interpolate_track(tr, [200.0], origin=(50.78, -1.1), max_gap=400.0)
    assert s2.valid[0] and s2.north[0] == pytest.approx(50.0 + 5.0 * 190.0, abs=1e-6)


def test_an_implausible_reported_course_does_not_bend_the_track():
    t = np.array([0.0, 10.0, 20.0])
    ne = np.array([[0.0, 0.0], [60.0, 0.0], [120.0, 0.0]])
    v = np.array([[6.0, 0.0], [-6.0, 0.0], [6.0, 0.0]])  # the middle COG is 180° wrong
    s = ais.interpolate_track(_track(t, ne, v), np.linspace(0, 20, 41), origin=(50.78, -1.1))
    assert np.all(np.diff(s.north) > 0)  # no doubling back
    np.testing.assert_allclose(s.north, 6.0 * np.linspace(0, 20, 41), atol=1e-6)
    np.testing.assert_allclose(s.speed, 6.0, atol=1e-9)


def test_interpolation_rejects_bad_arguments(solent):
    tr = next(iter(ais.tracks(solent).values()))
    with pytest.raises(ValueError, match="max_gap"):
        ais.interpolate_track(tr, [0.0], max_gap=0.0)
    with pytest.raises(ValueError, match="times"):
        ais.interpolate_track(tr, [[0.0]])
    with pytest.raises(ValueError, match="track"):
        ais.interpolate_track("not a track", [0.0])  # type: ignore[arg-type]


def test_subset_keeps_the_selected_rows_and_the_file_record(solent):
    sub = solent.subset(solent.mmsi == 235007473)
    assert len(sub) == int(np.sum(solent.mmsi == 235007473)) > 0
    assert set(sub.mmsi.tolist()) == {235007473}
    assert sub.skipped == solent.skipped and sub.source == solent.source
    with pytest.raises(ValueError, match="mask"):
        solent.subset([True])
