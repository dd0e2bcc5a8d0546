"""AIS traffic rendered by a camera (seawatch.synth.ais_scene): truth against the AIS
interpolation, the vessels in view against an independent projection, clip.json timing,
hull defaults, the busiest window and the demo camera.

Data: the packaged Solent AIS file (Stone Soup, MIT; seawatch/data/README.md).
"""

from __future__ import annotations

import csv
import json
import math
import warnings
from datetime import datetime
from pathlib import Path

import numpy as np
import pytest

from seawatch.camera import PinholeCamera
from seawatch.geometry import horizon_distance
from seawatch.geometry.geodesy import north_east_to_geodetic
from seawatch.io.ais import AisTrack, interpolate_track, read_ais, tracks
from seawatch.models import SeaSurfaceAngles
from seawatch.scenarios.solent_ais import default_ais_path
from seawatch.synth.ais_scene import (
    DEMO,
    SPEED_CLASSES,
    ais_ships,
    busiest_start,
    demo_camera,
    read_vessel_static,
    render_ais,
    vessel_size,
)

FPS = 5.0
DURATION = 2.0


@pytest.fixture(scope="module")
def solent():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the file's one corrupt row is reported and skipped
        table = read_ais(default_ais_path())
    return table, tracks(table)


@pytest.fixture(scope="module")
def small_camera() -> PinholeCamera:
    return demo_camera(640, 360)


@pytest.fixture(scope="module")
def clip(tmp_path_factory, solent, small_camera):
    table, _ = solent
    out = tmp_path_factory.mktemp("ais_clip")
    res = render_ais(table, small_camera, out_dir=out, start=DEMO.start, duration=DURATION, fps=FPS)
    with (out / "truth.csv").open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    return res, rows


def _waterline_pixels(camera: PinholeCamera, north, east) -> np.ndarray:
    """Water-line pixel of sea-surface points through the angle model (curved sea,
    k = 0.14) and the camera — independent of the module's own projection."""
    model = SeaSurfaceAngles(camera.height, (0.0, 0.0), camera.heading, curved=True)
    z = model(np.stack([np.asarray(north), np.asarray(east)], -1))
    return camera.angles_to_pixel(z[..., 0], -z[..., 1], frame="platform")


def test_truth_positions_are_the_interpolated_ais_positions_at_the_frame_times(
    solent, small_camera, clip
) -> None:
    _, vessel_tracks = solent
    _, rows = clip
    assert rows
    cam = small_camera
    for r in rows:
        t = DEMO.start + float(r["time"])
        s = interpolate_track(vessel_tracks[int(r["object_id"])], [t], origin=(cam.lat, cam.lon))
        assert s.valid[0]
        assert float(r["north_m"]) == pytest.approx(s.north[0], abs=2e-3)
        assert float(r["east_m"]) == pytest.approx(s.east[0], abs=2e-3)
        assert float(r["lat"]) == pytest.approx(s.lat[0], abs=1e-8)
        assert float(r["lon"]) == pytest.approx(s.lon[0], abs=1e-8)
        assert float(r["time"]) == pytest.approx(int(r["frame"]) / FPS, abs=1e-6)


def test_truth_water_line_is_the_ais_position_seen_through_the_camera(small_camera, clip) -> None:
    _, rows = clip
    n = np.array([float(r["north_m"]) for r in rows])
    e = np.array([float(r["east_m"]) for r in rows])
    uv = _waterline_pixels(small_camera, n, e)
    got = np.array([[float(r["u_wl"]), float(r["v_wl"])] for r in rows])
    np.testing.assert_allclose(got, uv, atol=0.02)


def test_truth_holds_exactly_the_vessels_in_view(solent, small_camera, clip) -> None:
    _, vessel_tracks = solent
    res, rows = clip
    cam = small_camera
    w, h = cam.image_size
    horizon = float(horizon_distance(cam.height, 0.14))
    by_frame: dict[int, dict[int, dict]] = {}
    for r in rows:
        by_frame.setdefault(int(r["frame"]), {})[int(r["object_id"])] = r
    sizes = res.scene.sizes
    frames = np.arange(res.frames)
    times = DEMO.start + frames / FPS
    expected_any: set[int] = set()
    for mmsi, tr in vessel_tracks.items():
        s = interpolate_track(tr, times, origin=(cam.lat, cam.lon))
        uv = _waterline_pixels(cam, s.north, s.east)
        rng = np.hypot(s.north, s.east)
        with np.errstate(invalid="ignore"):
            inside = (
                s.valid
                & (rng < horizon)
                & (uv[:, 0] > 2.0)
                & (uv[:, 0] < w - 3.0)
                & (uv[:, 1] > 2.0)
                & (uv[:, 1] < h - 3.0)
            )
        for k in np.flatnonzero(inside):
            present = by_frame.get(int(frames[k]), {})
            if mmsi not in present:  # only a nearer ship's box may hide it
                u, v = uv[k]
                assert any(
                    float(o["x"]) <= u <= float(o["x"]) + float(o["w"])
                    and float(o["y"]) <= v <= float(o["y"]) + float(o["h"])
                    for o in present.values()
                ), f"MMSI {mmsi} in view at frame {k} but not in truth.csv"
            expected_any.add(mmsi)
        # a truth row means some part of the hull is in the image: its water line is
        # at most half its length (in pixels, plus a margin) outside
        for k, fr in enumerate(frames):
            r = by_frame.get(int(fr), {}).get(mmsi)
            if r is None:
                continue
            half = 0.5 * sizes[mmsi].length * cam.fx / rng[k] + 3.0
            assert -half <= uv[k, 0] <= w + half
    ids = {int(r["object_id"]) for r in rows}
    assert len(expected_any) >= 2 and expected_any <= ids
    assert tuple(sorted(ids)) == res.objects
    assert set(res.scene.in_view) <= ids


def test_clip_json_aligns_video_time_zero_with_ais_time(clip) -> None:
    res, rows = clip
    doc = json.loads(Path(res.clip).read_text())
    assert doc["start_epoch"] == DEMO.start
    parsed = datetime.fromisoformat(doc["start_utc"].replace("Z", "+00:00")).timestamp()
    assert parsed == pytest.approx(doc["start_epoch"], abs=1e-3)
    assert doc["mmsi"] == sorted({int(r["object_id"]) for r in rows})
    assert Path(doc["ais"]).resolve() == default_ais_path().resolve()
    assert doc["frames"] == res.frames == round(DURATION * FPS)
    assert doc["fps"] == FPS and doc["duration_s"] == pytest.approx(DURATION)
    lines = Path(res.horizon).read_text().splitlines()
    assert len(lines) == res.frames + 1
    assert {v["mmsi"] for v in doc["vessels"]} >= set(doc["mmsi"])
    assert doc["camera"]["lat"] == pytest.approx(50.7781)


def _track(mmsi: int, sog: float | list[float], n: int = 5) -> AisTrack:
    t = np.arange(n) * 10.0
    s = np.broadcast_to(np.asarray(sog, dtype=float), (n,)).copy()
    return AisTrack(
        mmsi=mmsi,
        time=t,
        lat=50.7 + 1e-5 * np.arange(n),
        lon=np.full(n, -1.1),
        sog=s,
        cog=np.zeros(n),
        heading=np.full(n, np.nan),
        line=np.arange(n),
    )


@pytest.mark.parametrize(
    ("sog", "kind", "length"),
    [
        (15.0, "ferry", 40.0),
        (12.0, "ferry", 40.0),
        (8.0, "ferry", 80.0),
        (4.0, "workboat", 30.0),
        (2.0, "workboat", 18.0),
        (0.3, "boat", 12.0),
    ],
)
def test_hull_defaults_by_speed_follow_the_documented_classes(sog, kind, length) -> None:
    size = vessel_size(_track(1, sog))
    assert (size.kind, size.length, size.source) == (kind, length, "speed")
    assert SPEED_CLASSES[-1][0] == 0.0


def test_hull_speed_is_the_90th_percentile_so_a_waiting_ferry_stays_a_ferry() -> None:
    sog = [0.0] * 8 + [10.0, 10.0]  # 90th percentile of ten reports: 10 m/s
    assert vessel_size(_track(1, sog, n=10)).kind == "ferry"


def test_ship_type_and_length_columns_override_the_speed_rule(tmp_path: Path) -> None:
    # a MarineCadastre-style export: read_ais reads the positions, the static columns
    # give the hull
    path = tmp_path / "mc.csv"
    header = "MMSI,BaseDateTime,LAT,LON,SOG,COG,VesselType,Length,Width\n"
    body = []
    for k in range(5):
        ts = f"2016-01-12T13:00:{10 * k:02d}"
        body.append(f"111,{ts},50.70,-1.10,0.1,0,70,183,32\n")  # cargo, sizes given
        body.append(f"222,{ts},50.71,-1.10,0.1,0,36,,\n")  # sailing, no size
        body.append(f"333,{ts},50.72,-1.10,0.1,0,,,\n")  # nothing: speed rule
    path.write_text(header + "".join(body))
    static = read_vessel_static(path)
    assert static[111].ship_type == 70 and static[111].length == 183 and static[111].beam == 32
    table = read_ais(path)
    vt = tracks(table)
    s111 = vessel_size(vt[111], static[111])
    assert (s111.kind, s111.length, s111.beam, s111.source) == ("cargo", 183.0, 32.0, "ais")
    s222 = vessel_size(vt[222], static[222])
    assert (s222.kind, s222.length, s222.source) == ("sailboat", 12.0, "type")
    s333 = vessel_size(vt[333], static.get(333))
    assert (s333.kind, s333.length, s333.source) == ("boat", 12.0, "speed")
    given = vessel_size(vt[333], None, (55.0, "tanker"))
    assert (given.kind, given.length, given.source) == ("tanker", 55.0, "given")
    assert read_vessel_static(default_ais_path()) == {}  # the Solent file has no such columns


def _write_csv(
    path: Path, camera: PinholeCamera, vessels: list[tuple[int, float, float, float, float]]
):
    """Vessels (mmsi, forward [m], right [m], first time [s], last time [s]) standing
    still relative to the camera, one report every 10 s, times after 2016-01-12 13:00."""
    base = datetime.fromisoformat("2016-01-12T13:00:00+00:00").timestamp()
    psi = camera.heading
    lines = ["Time,MMSI,Latitude_degrees,Longitude_degrees,COG_degrees,SOG_knots"]
    for mmsi, fwd, right, t0, t1 in vessels:
        n = fwd * math.cos(psi) - right * math.sin(psi)
        e = fwd * math.sin(psi) + right * math.cos(psi)
        lat, lon = north_east_to_geodetic(np.array([n, e]), camera.lat, camera.lon)
        for t in np.arange(t0, t1 + 1e-9, 10.0):
            stamp = datetime.fromtimestamp(base + t).strftime("%Y-%m-%d %H:%M:%S")
            lines.append(f"{stamp},{mmsi},{float(lat):.8f},{float(lon):.8f},0,0")
    path.write_text("\n".join(lines) + "\n")
    return base


def test_busiest_window_is_where_most_vessels_are_in_view(tmp_path: Path) -> None:
    cam = demo_camera(640, 360)
    path = tmp_path / "ais.csv"
    # A in view (ahead, 500 m) over [100, 160] s, B over [130, 200] s, C always but
    # behind the camera: the 30 s window with both A and B is [130, 160] alone
    base = _write_csv(
        path,
        cam,
        [(1, 500.0, 0.0, 100.0, 160.0), (2, 500.0, 60.0, 130.0, 200.0), (3, -800.0, 0, 0, 300)],
    )
    assert busiest_start(path, cam, 30.0) == pytest.approx(base + 130.0)
    scene = ais_ships(path, cam, duration=30.0, fps=2.0)
    assert scene.start == pytest.approx(base + 130.0)
    assert scene.in_view == (1, 2) and scene.mmsi == (1, 2)  # C is never near the view
    assert np.all(scene.counts == 2)
    assert scene.sizes[1].kind == "boat"  # SOG 0: a 12 m boat


def test_bad_camera_start_and_empty_view_raise_naming_the_problem(solent) -> None:
    table, _ = solent
    no_geo = PinholeCamera.from_fov(640, 360, 50.0, height=10.0)
    with pytest.raises(ValueError, match="lat_deg"):
        ais_ships(table, no_geo, start=DEMO.start)
    no_height = PinholeCamera.from_fov(640, 360, 50.0, lat=50.78, lon=-1.09)
    with pytest.raises(ValueError, match="height_m"):
        ais_ships(table, no_height, start=DEMO.start)
    with pytest.raises(ValueError, match="start"):
        ais_ships(table, demo_camera(640, 360), start=DEMO.start + 86400.0)
    inland = PinholeCamera.from_fov(640, 360, 50.0, height=10.0, lat=51.5, lon=-1.09)
    with pytest.raises(ValueError, match="no vessel"):
        ais_ships(table, inland, start=DEMO.start)
    with pytest.raises(FileNotFoundError):
        ais_ships("/nonexistent/ais.csv", demo_camera(640, 360))


def test_demo_clip_has_ships_crossing_entering_and_leaving_the_view(solent) -> None:
    table, vessel_tracks = solent
    cam = demo_camera()
    assert cam.image_size == (1920, 1080) and 10.0 <= cam.height <= 20.0
    assert 50.7 < cam.lat < 50.85 and -1.35 < cam.lon < -1.0  # the Solent
    scene = ais_ships(table, cam, start=DEMO.start, duration=DEMO.duration, fps=2.0)
    assert DEMO.duration * DEMO.fps <= 400  # a short clip for the 3-minute demo
    times = DEMO.start + np.arange(0.0, DEMO.duration + 1e-9, 0.5)
    w, h = cam.image_size
    u = {}
    for mmsi in scene.in_view:
        s = interpolate_track(vessel_tracks[mmsi], times, origin=(cam.lat, cam.lon))
        uv = _waterline_pixels(cam, s.north, s.east)
        with np.errstate(invalid="ignore"):
            seen = s.valid & (uv[:, 0] >= 0) & (uv[:, 0] < w) & (uv[:, 1] >= 0) & (uv[:, 1] < h)
        u[mmsi] = np.where(seen, uv[:, 0], np.nan)
    near = [
        m for m in scene.in_view if np.nanmin(np.hypot(*_ne(vessel_tracks[m], times, cam))) < 3000.0
    ]
    assert len(scene.in_view) >= 4 and len(near) >= 3
    enters = [m for m, x in u.items() if np.isnan(x[0]) and np.isfinite(x).any()]
    leaves = [m for m, x in u.items() if np.isfinite(x).any() and np.isnan(x[-1])]
    assert enters and leaves
    crossings = 0
    for a in u:
        for b in u:
            both = np.isfinite(u[a]) & np.isfinite(u[b])
            if a < b and both.sum() > 1:
                d = np.sign(u[a][both] - u[b][both])
                crossings += bool(np.any(d != d[0]))
    assert crossings >= 1


def _ne(track: AisTrack, times: np.ndarray, cam: PinholeCamera) -> tuple[np.ndarray, np.ndarray]:
    s = interpolate_track(track, times, origin=(cam.lat, cam.lon))
    return s.north, s.east
