"""Track tables scored against synthetic truth (seawatch.metrics.track_errors): zero
errors for the truth itself, closed-form errors for shifted, scaled, swapped, missing
and extra rows, several estimators, the camera foot point, "don't care" truth, and bad
files."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

from seawatch.camera import PinholeCamera
from seawatch.io import save_camera
from seawatch.metrics.mot import clear_metrics
from seawatch.metrics.track_errors import TrackErrors, match_boxes, score_tracks

FRAMES = 10
TRUTH_COLS = ["time", "frame", "object_id", "x", "y", "w", "h", "east_m", "north_m"]


def _truth_rows() -> list[dict]:
    """Two ships over 10 frames: object 1 at 400–490 m, object 2 at 1.2 km, well apart."""
    rows = []
    for f in range(FRAMES):
        rows.append(
            dict(time=f / 10, frame=f, object_id=1, x=100 + 3 * f, y=200, w=40, h=12,
                 east_m=-300.0 - 10 * f, north_m=300.0)
        )  # fmt: skip
        rows.append(
            dict(time=f / 10, frame=f, object_id=2, x=600 - 2 * f, y=190, w=20, h=8,
                 east_m=-1200.0 + 5 * f, north_m=-100.0)
        )  # fmt: skip
    return rows


def _write(path: Path, rows: list[dict], columns: list[str] | None = None) -> Path:
    cols = columns or list(rows[0])
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, cols, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    return path


def _as_tracks(rows: list[dict], ids: dict[int, int] | None = None) -> list[dict]:
    out = []
    for r in rows:
        t = dict(r)
        t["track_id"] = (ids or {}).get(r["object_id"], r["object_id"] + 10)
        del t["object_id"]
        out.append(t)
    return out


@pytest.fixture
def truth(tmp_path: Path) -> Path:
    return _write(tmp_path / "truth.csv", _truth_rows(), TRUTH_COLS)


def _score(tmp_path: Path, truth: Path, tracks: list[dict], **kw) -> TrackErrors:
    return score_tracks(_write(tmp_path / "tracks.csv", tracks), truth, **kw)


def test_truth_scored_against_itself_has_no_error(tmp_path: Path, truth: Path) -> None:
    res = _score(tmp_path, truth, _as_tracks(_truth_rows()))
    assert res.rmse_position_m == 0.0 and res.rmse_range_percent == 0.0 and res.cle_px == 0.0
    assert res.id_switches == 0 and res.mota == 1.0 and res.idf1 == 1.0
    assert res.pairs == res.tp == 2 * FRAMES and res.fp == res.fn == 0
    assert [o.track_ids for o in res.objects] == [(11,), (12,)]
    assert all(o.matched == o.frames == FRAMES for o in res.objects)
    doc = res.to_json()
    for key in ("rmse_position_m", "rmse_range_percent", "cle_px", "id_switches", "mota", "idf1"):
        assert key in doc
    json.dumps(doc, allow_nan=False)


def test_every_position_moved_10_m_gives_an_rmse_of_10_m(tmp_path: Path, truth: Path) -> None:
    tracks = _as_tracks(_truth_rows())
    for t in tracks:
        t["east_m"] += 6.0
        t["north_m"] -= 8.0
    res = _score(tmp_path, truth, tracks)
    assert res.rmse_position_m == pytest.approx(10.0, abs=1e-9)
    assert res.cle_px == 0.0 and res.mota == 1.0


def test_positions_5_percent_farther_give_a_5_percent_range_error(
    tmp_path: Path, truth: Path
) -> None:
    rows = _truth_rows()
    tracks = _as_tracks(rows)
    for t in tracks:
        t["east_m"] *= 1.05
        t["north_m"] *= 1.05
    res = _score(tmp_path, truth, tracks)
    assert res.rmse_range_percent == pytest.approx(5.0, abs=1e-9)
    pe = res.positions["tracks"]
    assert pe.mean_range_error_percent == pytest.approx(5.0, abs=1e-9)
    r = np.array([math.hypot(t["east_m"], t["north_m"]) for t in rows])
    assert res.rmse_position_m == pytest.approx(0.05 * math.sqrt(np.mean(r**2)), rel=1e-12)
    # range bins: object 1 at 424–495 m in [250, 500), object 2 at ~1.2 km in [750, 1250)
    bins = {(b.lo, b.hi): b for b in pe.bins if b.pairs}
    assert bins[(250.0, 500.0)].pairs == FRAMES and bins[(750.0, 1250.0)].pairs == FRAMES
    assert bins[(750.0, 1250.0)].rmse_range_percent == pytest.approx(5.0, abs=1e-9)
    assert sum(b.pairs for b in pe.bins) == res.pairs


def test_ranges_are_measured_from_the_camera_foot_point(tmp_path: Path, truth: Path) -> None:
    c = np.array([150.0, -80.0])  # camera at north 150, east -80
    tracks = _as_tracks(_truth_rows())
    for t in tracks:  # 5 % farther from the camera, not from the origin
        t["north_m"] = c[0] + 1.05 * (t["north_m"] - c[0])
        t["east_m"] = c[1] + 1.05 * (t["east_m"] - c[1])
    cam = PinholeCamera.from_fov(640, 360, 50.0, height=10.0, position=(150.0, -80.0))
    res = _score(tmp_path, truth, tracks, camera=cam)
    assert res.rmse_range_percent == pytest.approx(5.0, abs=1e-9)
    assert res.camera_position == (150.0, -80.0)
    save_camera(cam, truth.parent / "camera.yaml")  # found beside truth.csv by default
    assert _score(tmp_path, truth, tracks).rmse_range_percent == pytest.approx(5.0, abs=1e-9)
    origin = _score(tmp_path, truth, tracks, camera=PinholeCamera.from_fov(640, 360, 50.0))
    assert abs(origin.rmse_range_percent - 5.0) > 0.5


def test_one_id_swap_counts_two_switches_and_the_hand_computed_mota_idf1(
    tmp_path: Path, truth: Path
) -> None:
    tracks = _as_tracks(_truth_rows())
    for t in tracks:  # from frame 5 on, track 11 follows object 2 and track 12 object 1
        if t["frame"] >= 5:
            t["track_id"] = 23 - t["track_id"]
    res = _score(tmp_path, truth, tracks)
    # CLEAR: TP 20, FP 0, FN 0, IDSW 2 -> MOTA = 1 - 2/20; identity: best whole-track
    # mapping keeps 5 frames of each -> IDTP 10, IDFP 10, IDFN 10 -> IDF1 = 20/40
    assert res.id_switches == 2
    assert res.mota == pytest.approx(0.9)
    assert res.idf1 == pytest.approx(0.5)
    assert res.rmse_position_m == 0.0  # positions still follow the matched ships
    assert [o.track_ids for o in res.objects] == [(11, 12), (12, 11)]


def test_missing_and_extra_track_rows_are_misses_and_false_alarms(
    tmp_path: Path, truth: Path
) -> None:
    tracks = [t for t in _as_tracks(_truth_rows()) if not (t["track_id"] == 12 and t["frame"] < 4)]
    for f in range(5):  # a false track far from both ships
        tracks.append(dict(time=f / 10, frame=f, track_id=99, x=1500, y=600, w=10, h=5,
                           east_m=0.0, north_m=-50.0))  # fmt: skip
    res = _score(tmp_path, truth, tracks)
    assert (res.tp, res.fn, res.fp) == (16, 4, 5)
    assert res.mota == pytest.approx(1.0 - (4 + 5) / 20)
    assert res.objects[1].matched == 6 and res.objects[1].frames == FRAMES
    assert res.track_ids == 3 and res.rmse_position_m == 0.0


def test_boxes_moved_2_px_give_a_cle_of_2_px(tmp_path: Path, truth: Path) -> None:
    tracks = _as_tracks(_truth_rows())
    for t in tracks:
        t["x"] += 2.0
    res = _score(tmp_path, truth, tracks)
    assert res.cle_px == pytest.approx(2.0) and res.mota == 1.0


def test_iou_threshold_and_centre_gate_decide_the_matches(tmp_path: Path, truth: Path) -> None:
    tracks = _as_tracks(_truth_rows())
    for t in tracks:
        t["x"] += 0.6 * t["w"]  # IoU = 0.4 w h / (1.6 w h) = 0.25
    assert _score(tmp_path, truth, tracks).tp == 0
    low = _score(tmp_path, truth, tracks, threshold=0.2)
    assert low.tp == 20 and low.mota == 1.0
    # centres 24 px (object 1) and 12 px (object 2) apart
    gate = _score(tmp_path, truth, tracks, match="centre", gate_px=15.0)
    assert gate.tp == FRAMES and gate.fn == FRAMES and gate.fp == FRAMES
    assert gate.cle_px == pytest.approx(12.0)
    assert _score(tmp_path, truth, tracks, match="centre", gate_px=30.0).tp == 20


def test_every_estimator_gets_its_own_position_errors(tmp_path: Path, truth: Path) -> None:
    tracks = _as_tracks(_truth_rows())
    for t in tracks:
        t["geometry_east_m"] = t["east_m"] + 3.0
        t["geometry_north_m"] = t["north_m"] + 4.0
    long_rows = []
    for k, t in enumerate(tracks):
        base = dict(time=t["time"], frame=t["frame"], track_id=t["track_id"])
        long_rows.append(
            dict(base, estimator="ekf", east_m=t["east_m"] - 6.0, north_m=t["north_m"] + 8.0)
        )
        if k % 2 == 0:  # "ukf" has every other row, exact
            long_rows.append(dict(base, estimator="ukf", east_m=t["east_m"], north_m=t["north_m"]))
    est = _write(tmp_path / "estimates.csv", long_rows)
    res = _score(
        tmp_path,
        truth,
        tracks,
        positions={
            "best": ("east_m", "north_m"),
            "geometry": ("geometry_east_m", "geometry_north_m"),
        },
        estimates=est,
    )
    assert list(res.positions) == ["best", "geometry", "ekf", "ukf"]
    assert res.rmse_position_m == 0.0  # the first entry is the headline
    assert res.positions["geometry"].rmse_position_m == pytest.approx(5.0)
    assert res.positions["ekf"].rmse_position_m == pytest.approx(10.0)
    ukf = res.positions["ukf"]
    assert (ukf.pairs, ukf.missing, ukf.rmse_position_m) == (10, 10, 0.0)
    assert set(res.to_json()["estimators"]) == {"best", "geometry", "ekf", "ukf"}


def test_rows_without_a_position_are_left_out_of_the_position_errors(
    tmp_path: Path, truth: Path
) -> None:
    tracks = _as_tracks(_truth_rows())
    for t in tracks[:4]:
        t["east_m"] = t["north_m"] = ""
    for t in tracks[4:]:
        t["east_m"] += 10.0
    res = _score(tmp_path, truth, tracks)
    assert res.positions["tracks"].missing == 4 and res.positions["tracks"].pairs == 16
    assert res.rmse_position_m == pytest.approx(10.0) and res.mota == 1.0


def test_truth_lower_than_min_height_is_dont_care(tmp_path: Path, truth: Path) -> None:
    tracks = _as_tracks(_truth_rows())
    tracks = [t for t in tracks if not (t["track_id"] == 11 and t["frame"] >= 6)]
    res = _score(tmp_path, truth, tracks, min_truth_height=10.0)  # object 2 (8 px) ignored
    assert res.ignored_truth_rows == FRAMES and res.ignored_track_rows == FRAMES
    assert (res.tp, res.fp, res.fn) == (6, 0, 4)
    assert res.mota == pytest.approx(0.6) and res.truth_objects == 1
    full = _score(tmp_path, truth, tracks)
    assert (full.tp, full.fp, full.fn) == (16, 0, 4)


def test_matched_pairs_are_clears_true_positives_on_a_cluttered_scene(tmp_path: Path) -> None:
    rng = np.random.default_rng(1234)
    truth_rows, track_rows = [], []
    for f in range(30):
        for oid in range(6):
            x, y = 60.0 * oid + 2.0 * f, 100.0 + 15.0 * (oid % 2)
            truth_rows.append(dict(time=f, frame=f, object_id=oid, x=x, y=y, w=50, h=20,
                                   east_m=oid, north_m=f))  # fmt: skip
            if rng.random() < 0.85:
                dx, dy = rng.normal(0.0, 6.0, 2)
                tid = oid if rng.random() < 0.95 else oid + 100
                track_rows.append(dict(time=f, frame=f, track_id=tid, x=x + dx, y=y + dy, w=50,
                                       h=20, east_m=oid, north_m=f))  # fmt: skip
        for k in range(2):
            x, y = rng.uniform(0, 400), rng.uniform(80, 150)
            track_rows.append(
                dict(time=f, frame=f, track_id=500 + k, x=x, y=y, w=40, h=18, east_m=0, north_m=0)
            )
    truth = _write(tmp_path / "truth.csv", truth_rows)
    res = score_tracks(_write(tmp_path / "tracks.csv", track_rows), truth)
    g = np.array([[r["frame"], r["object_id"], r["x"], r["y"], r["w"], r["h"]] for r in truth_rows])
    t = np.array([[r["frame"], r["track_id"], r["x"], r["y"], r["w"], r["h"]] for r in track_rows])
    clear = clear_metrics(g, t, "iou", 0.3)
    assert res.pairs == res.tp == clear.tp and res.id_switches == clear.id_switches
    gi, ti = match_boxes(g[:, 0], g[:, 1], g[:, 2:], t[:, 0], t[:, 1], t[:, 2:])
    assert np.all(g[gi, 0] == t[ti, 0]) and gi.size == clear.tp


def test_bad_files_raise_value_error_naming_the_file(tmp_path: Path, truth: Path) -> None:
    tracks = _write(tmp_path / "tracks.csv", _as_tracks(_truth_rows()))
    with pytest.raises(ValueError, match=r"nope\.csv"):
        score_tracks(tmp_path / "nope.csv", truth)
    with pytest.raises(ValueError, match=r"truth .*missing\.csv"):
        score_tracks(tracks, tmp_path / "missing.csv")
    no_col = _write(tmp_path / "t2.csv", _truth_rows(), ["frame", "object_id", "x", "y", "w", "h",
                                                         "north_m"])  # fmt: skip
    with pytest.raises(ValueError, match=r"t2\.csv.*east_m"):
        score_tracks(tracks, no_col)
    bad = _as_tracks(_truth_rows())
    bad[3]["x"] = "abc"
    with pytest.raises(ValueError, match=r"tracks .*line 5.*'x'"):
        score_tracks(_write(tmp_path / "bad.csv", bad), truth)
    dup = _as_tracks(_truth_rows())
    dup[1]["track_id"] = dup[0]["track_id"]
    with pytest.raises(ValueError, match=r"dup\.csv.*more than once"):
        score_tracks(_write(tmp_path / "dup.csv", dup), truth)
    empty = tmp_path / "empty.csv"
    empty.write_text(",".join(TRUTH_COLS) + "\n")
    with pytest.raises(ValueError, match="no rows"):
        score_tracks(tracks, empty)
    (tmp_path / "binary.csv").write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(ValueError, match=r"binary\.csv"):
        score_tracks(tmp_path / "binary.csv", truth)
    with pytest.raises(ValueError, match="match"):
        score_tracks(tracks, truth, match="overlap")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="threshold"):
        score_tracks(tracks, truth, threshold=1.5)
    with pytest.raises(ValueError, match=r"tracks.*geo_east"):
        score_tracks(tracks, truth, positions={"g": ("geo_east", "geo_north")})


def test_pixel_truth_without_positions_gives_the_pixel_scores_alone(
    tmp_path: Path, truth: Path
) -> None:
    """Boxes annotated on a real clip (``frame``, ``object_id``, ``x``, ``y``, ``w``,
    ``h``; no ``east_m``/``north_m``): the same matches, MOTA, IDF1, HOTA and CLE as
    against the full truth, and no position errors (null in the JSON) instead of an
    error."""
    tracks = _as_tracks(_truth_rows())
    for t in tracks[:8]:
        t["x"] += 3.0
    tracks = [t for t in tracks if not (t["track_id"] == 12 and t["frame"] > 6)]
    pixels = _write(tmp_path / "boxes.csv", _truth_rows(), ["frame", "object_id", "x", "y", "w",
                                                            "h"])  # fmt: skip
    full, px = _score(tmp_path, truth, tracks), _score(tmp_path, pixels, tracks)
    for name in ("cle_px", "mota", "idf1", "hota", "tp", "fp", "fn", "id_switches", "pairs"):
        assert getattr(px, name) == getattr(full, name), name
    assert full.rmse_position_m == 0.0 and math.isnan(px.rmse_position_m)
    doc = px.to_json()
    assert doc["rmse_position_m"] is None and doc["rmse_range_percent"] is None
    assert doc["mota"] == pytest.approx(full.mota)
    assert px.positions["tracks"].missing == px.pairs


def test_ranges_of_a_moving_platform_are_taken_from_each_rows_camera(tmp_path: Path) -> None:
    # the platform sails east at 10 m/s; a ship stays 1000 m due north of it, the track
    # reads it 1050 m north: +5 % range in every frame (ranges from the fixed origin would
    # give 1000..1050 m true ranges and a varying error)
    rows = []
    for f in range(FRAMES):
        rows.append(
            dict(time=f, frame=f, object_id=1, x=100, y=200, w=40, h=12,
                 east_m=10.0 * f, north_m=1000.0, platform_east_m=10.0 * f,
                 platform_north_m=0.0)
        )  # fmt: skip
    truth = _write(tmp_path / "truth_world.csv", rows)
    tracks = _as_tracks(rows)
    for t in tracks:
        t["north_m"] = 1050.0
    res = _score(tmp_path, truth, tracks)
    assert res.rmse_range_percent == pytest.approx(5.0, abs=1e-9)
    assert res.rmse_position_m == pytest.approx(50.0, abs=1e-9)
