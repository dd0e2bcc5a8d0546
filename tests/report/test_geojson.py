"""tracks.geojson: RFC 7946 structure, coordinates and times against the simulated rows,
speeds against the simulated velocities, atomic rewrites, the incremental sink."""

from __future__ import annotations

import json
import math
import threading
from pathlib import Path

import numpy as np
import pytest

from seawatch.report.geojson import (
    GeoJsonSink,
    atomic_write_text,
    load_tracks,
    tracks_to_geojson,
    write_geojson,
)


def _strict_load(text: str) -> dict:
    def no_constant(name: str) -> None:
        raise AssertionError(f"non-standard JSON constant {name}")

    return json.loads(text, parse_constant=no_constant)


def _by_kind(doc: dict, kind: str) -> list[dict]:
    return [f for f in doc["features"] if f["properties"]["kind"] == kind]


def _rows_of(rows: list[dict[str, str]], tid: int) -> list[dict[str, str]]:
    return sorted((r for r in rows if int(r["track_id"]) == tid), key=lambda r: float(r["time"]))


def test_written_file_parses_as_rfc7946_feature_collection(tmp_path, tracks_csv, rows, sim):
    out = write_geojson(tmp_path / "tracks.geojson", tracks_csv, camera_lat=sim.cam_lat,
                        camera_lon=sim.cam_lon)  # fmt: skip
    assert out == tmp_path / "tracks.geojson"
    doc = _strict_load(out.read_text(encoding="utf-8"))
    assert doc["type"] == "FeatureCollection"
    for f in doc["features"]:
        assert f["type"] == "Feature" and set(f) >= {"geometry", "properties"}
        g = f["geometry"]
        pts = g["coordinates"] if g["type"] == "LineString" else [g["coordinates"]]
        assert g["type"] in ("LineString", "Point")
        for lon, lat in pts:
            assert -180.0 <= lon <= 180.0 and -90.0 <= lat <= 90.0
    (cam,) = _by_kind(doc, "camera")
    assert cam["geometry"]["coordinates"] == [sim.cam_lon, sim.cam_lat]
    # one line per track with more than one fix, a Point for the single-fix track
    tracks = {f["properties"]["track_id"]: f for f in _by_kind(doc, "track")}
    assert set(tracks) == set(sim.ships)
    assert tracks[1]["geometry"]["type"] == "LineString"
    assert tracks[3]["geometry"]["type"] == "Point"
    assert len(_by_kind(doc, "fix")) == len(rows)


def test_line_coordinates_and_times_equal_the_rows_in_time_order(tracks_csv, rows, sim):
    doc = tracks_to_geojson(tracks_csv, points=False)
    assert not _by_kind(doc, "fix") and not _by_kind(doc, "camera")
    for f in _by_kind(doc, "track"):
        p = f["properties"]
        mine = _rows_of(rows, p["track_id"])
        coords = f["geometry"]["coordinates"]
        coords = coords if f["geometry"]["type"] == "LineString" else [coords]
        want = np.array([[float(r["lon"]), float(r["lat"])] for r in mine])
        np.testing.assert_allclose(np.array(coords), want, rtol=0, atol=0.51e-7)  # 7 decimals
        assert p["times"] == pytest.approx([float(r["time"]) for r in mine], abs=1e-9)
        assert p["first_time"] == pytest.approx(float(mine[0]["time"]))
        assert p["last_time"] == pytest.approx(float(mine[-1]["time"]))
        assert p["fixes"] == len(mine)
        assert p["mmsi"] == (
            int(sim.ships[p["track_id"]][4]) if sim.ships[p["track_id"]][4] else None
        )


def test_fix_points_carry_their_time_and_track(tracks_csv, rows):
    doc = tracks_to_geojson(tracks_csv)
    fixes = _by_kind(doc, "fix")
    got = sorted((f["properties"]["track_id"], f["properties"]["time"]) for f in fixes)
    want = sorted((int(r["track_id"]), float(r["time"])) for r in rows)
    assert got == [(k, pytest.approx(t)) for k, t in want]
    by_key = {(int(r["track_id"]), float(r["time"])): r for r in rows}
    for f in fixes[:50]:
        r = by_key[(f["properties"]["track_id"], f["properties"]["time"])]
        lon, lat = f["geometry"]["coordinates"]
        assert lon == pytest.approx(float(r["lon"]), abs=0.51e-7)
        assert lat == pytest.approx(float(r["lat"]), abs=0.51e-7)
        assert f["properties"]["frame"] == int(r["frame"])


def test_mean_speed_is_the_simulated_speed_from_fit_or_table(tracks_csv, sim):
    tracks = {f["properties"]["track_id"]: f["properties"] for f in
              _by_kind(tracks_to_geojson(tracks_csv), "track")}  # fmt: skip
    for tid in (1, 2):
        vn, ve = sim.ships[tid][3]
        p = tracks[tid]
        assert p["mean_speed_mps"] == pytest.approx(math.hypot(vn, ve), abs=1e-3)
        assert p["mean_speed_kn"] == pytest.approx(math.hypot(vn, ve) * 3600 / 1852, abs=0.01)
        assert p["mean_course_deg"] == pytest.approx(
            math.degrees(math.atan2(ve, vn)) % 360, abs=0.01
        )
    assert tracks[1]["speed_source"] == "fit"  # no speed column: constant-velocity fit
    assert tracks[2]["speed_source"] == "table"
    assert tracks[3]["mean_speed_mps"] is None  # one fix: no speed


def test_fitted_speed_ignores_zero_mean_position_noise_unlike_a_path_length(rows):
    rng = np.random.default_rng(1234)
    noisy = []
    for r in rows:
        if r["track_id"] == "1":
            r = dict(r)
            r["north_m"] = repr(float(r["north_m"]) + rng.normal(0, 20.0))
            r["east_m"] = repr(float(r["east_m"]) + rng.normal(0, 20.0))
            noisy.append(r)
    (track,) = load_tracks(noisy)
    speed, src = track.mean_speed()
    assert src == "fit"
    # LS slope σ = σ_pos / sqrt(Σ(t - t̄)²) ≈ 20 / sqrt(241 · 300) ≈ 0.074 m/s per axis
    assert speed == pytest.approx(math.hypot(1.5, 4.0), abs=0.3)
    p = track.local_positions()
    path_speed = np.sum(np.hypot(*np.diff(p, axis=0).T)) / np.ptp(track.time)
    assert path_speed > 3 * speed  # why a path length is not used


def test_rows_without_position_are_skipped_and_a_camera_fills_them_from_north_east(rows, sim):
    blank = [dict(r, lat="", lon="") if k % 3 == 0 else r for k, r in enumerate(rows)]
    doc = tracks_to_geojson(blank)
    kept = sum(1 for k in range(len(rows)) if k % 3)
    assert len(_by_kind(doc, "fix")) == kept
    full = tracks_to_geojson(blank, camera_lat=sim.cam_lat, camera_lon=sim.cam_lon)
    ref = tracks_to_geojson(rows, camera_lat=sim.cam_lat, camera_lon=sim.cam_lon)
    got = {(f["properties"]["track_id"], f["properties"]["time"]): f["geometry"]["coordinates"]
           for f in _by_kind(full, "fix")}  # fmt: skip
    want = {(f["properties"]["track_id"], f["properties"]["time"]): f["geometry"]["coordinates"]
            for f in _by_kind(ref, "fix")}  # fmt: skip
    assert got.keys() == want.keys()
    for key, c in want.items():
        np.testing.assert_allclose(got[key], c, atol=2e-7)


def test_no_geodetic_position_gives_no_geojson_and_says_so(tmp_path, rows):
    pixel_only = [dict(r, lat="", lon="", north_m="", east_m="") for r in rows]
    with pytest.warns(UserWarning, match="no geodetic positions"):
        assert tracks_to_geojson(pixel_only) is None
    with pytest.warns(UserWarning, match="no GeoJSON"):
        assert write_geojson(tmp_path / "t.geojson", pixel_only) is None
    assert not (tmp_path / "t.geojson").exists()
    # north/east but no camera position: still nothing to put on a map
    with pytest.warns(UserWarning):
        assert tracks_to_geojson([dict(r, lat="", lon="") for r in rows]) is None


def test_camera_without_tracks_gives_a_collection_with_only_the_camera(sim):
    doc = tracks_to_geojson([], camera_lat=sim.cam_lat, camera_lon=sim.cam_lon)
    assert [f["properties"]["kind"] for f in doc["features"]] == ["camera"]


def test_epoch_adds_iso_utc_datetimes(tracks_csv):
    doc = tracks_to_geojson(tracks_csv, epoch=1_700_000_000.0)  # 2023-11-14T22:13:20Z
    fix = next(f for f in _by_kind(doc, "fix") if f["properties"]["time"] == 10.25)
    assert fix["properties"]["datetime"] == "2023-11-14T22:13:30.250Z"
    line = next(f for f in _by_kind(doc, "track") if f["properties"]["track_id"] == 2)
    assert line["properties"]["first_datetime"] == "2023-11-14T22:13:30.000Z"


def test_bad_input_raises_value_error_naming_the_problem(tmp_path, rows, sim):
    bad = tmp_path / "bad.csv"
    bad.write_text("time,frame,x\n0,0,1\n")
    with pytest.raises(ValueError, match=r"bad\.csv: no column track_id"):
        tracks_to_geojson(bad)
    with pytest.raises(ValueError, match=r"row 2: time 'soon'"):
        tracks_to_geojson([rows[0], dict(rows[1], time="soon")])
    with pytest.raises(ValueError, match="track_id"):
        tracks_to_geojson([dict(rows[0], track_id="1.5")])
    with pytest.raises(ValueError, match="camera_lat, camera_lon"):
        tracks_to_geojson(rows, camera_lat=sim.cam_lat)
    with pytest.raises(ValueError, match="camera_lat"):
        tracks_to_geojson(rows, camera_lat=91.0, camera_lon=0.0)
    with pytest.raises(FileNotFoundError):
        tracks_to_geojson(tmp_path / "missing.csv")


def test_rewrites_are_atomic_a_concurrent_reader_never_sees_half_a_file(tmp_path, rows):
    path = tmp_path / "tracks.geojson"
    write_geojson(path, rows[:10])
    stop = threading.Event()
    seen: list[int] = []
    errors: list[str] = []

    def reader() -> None:
        while not stop.is_set():
            try:
                doc = json.loads(path.read_text(encoding="utf-8"))
                seen.append(len(doc["features"]))
            except (json.JSONDecodeError, KeyError) as exc:
                errors.append(repr(exc))

    thread = threading.Thread(target=reader)
    thread.start()
    try:
        for n in range(20, len(rows), 20):
            write_geojson(path, rows[:n])
    finally:
        stop.set()
        thread.join()
    assert not errors and len(seen) > 5
    assert seen == sorted(seen)  # only whole, ever-growing documents
    assert [p.name for p in tmp_path.iterdir()] == ["tracks.geojson"]  # no temp files left


def test_failed_rewrite_keeps_the_previous_file_and_leaves_no_temp(tmp_path):
    path = tmp_path / "f.json"
    atomic_write_text(path, '{"ok": 1}')
    with pytest.raises(UnicodeEncodeError):
        atomic_write_text(path, '{"ok": "\ud800"}')  # lone surrogate: fails mid-write
    assert path.read_text() == '{"ok": 1}'
    assert [p.name for p in tmp_path.iterdir()] == ["f.json"]


def test_sink_rewrites_about_once_per_video_second_and_ends_with_every_row(tmp_path, rows, sim):
    path = tmp_path / "tracks.geojson"
    sink = GeoJsonSink(path, camera_lat=sim.cam_lat, camera_lon=sim.cam_lon, every_s=1.0,
                       overhead=0.999)  # fmt: skip
    by_time: dict[float, list[dict[str, str]]] = {}
    for r in rows:
        by_time.setdefault(float(r["time"]), []).append(r)
    for t, frame_rows in sorted(by_time.items()):
        sink.add(frame_rows, t)
        # what a crash now would leave: whole JSON, at most 1 s of video behind
        last = max(f["properties"]["time"] for f in _by_kind(_strict_load(path.read_text()), "fix"))
        assert t - last <= 1.0 + 1e-9
    assert 55 <= sink.writes <= 62  # 60 s of video
    sink.close()
    final = _strict_load(path.read_text())
    assert final == tracks_to_geojson(rows, camera_lat=sim.cam_lat, camera_lon=sim.cam_lon)


def test_sink_bounds_the_rewrite_overhead_on_wall_time(tmp_path, rows, sim):
    sink = GeoJsonSink(tmp_path / "t.geojson", camera_lat=sim.cam_lat, camera_lon=sim.cam_lon,
                       every_s=0.01, overhead=0.01)  # fmt: skip
    for k, r in enumerate(rows):
        sink.add([r], k * 0.25)  # far faster than real time: writes must be throttled
    assert 1 <= sink.writes < len(rows) // 4


def test_sink_bad_arguments_raise_value_error_naming_them(tmp_path):
    with pytest.raises(ValueError, match="every_s"):
        GeoJsonSink(tmp_path / "t.geojson", every_s=0.0)
    with pytest.raises(ValueError, match="overhead"):
        GeoJsonSink(tmp_path / "t.geojson", overhead=1.0)
    with pytest.raises(ValueError, match="path"):
        GeoJsonSink(tmp_path / "nowhere" / "t.geojson")
    with pytest.raises(ValueError, match="camera_lat"):
        GeoJsonSink(tmp_path / "t.geojson", camera_lat=1.0)


def test_csv_path_and_rows_give_the_same_document(tmp_path, rows, sim):
    p = sim.write_csv(Path(tmp_path / "t.csv"), rows)
    assert tracks_to_geojson(p) == tracks_to_geojson(rows)
