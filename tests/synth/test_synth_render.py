"""The synthetic-footage renderer (seawatch.synth.render) against independent truths:
closed-form ship positions, the camera's own projection and flat-sea inversion, the
horizon line of each frame's attitude, pixels of the rendered frames, PyAV read-back."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import av
import numpy as np
import pytest
from pymap3d import vincenty

from seawatch.camera import PinholeCamera, horizon_line
from seawatch.geometry import horizon_distance, sea_depression, sea_position
from seawatch.synth import (
    TRUTH_COLUMNS,
    Renderer,
    lighting_preset,
    make_ship,
    render,
    straight,
)

LAT, LON = 50.78, -1.09
H_CAM = 15.0
W, H = 640, 360


def _camera(hfov: float = 60.0, pitch_deg: float = 0.0, heading_deg: float = 30.0, **kw):
    return PinholeCamera.from_fov(
        W,
        H,
        hfov,
        height=kw.pop("height", H_CAM),
        heading=math.radians(heading_deg),
        pitch=math.radians(pitch_deg),
        lat=LAT,
        lon=LON,
        **kw,
    )


def _ahead(cam: PinholeCamera, forward: float, right: float) -> tuple[float, float]:
    c, s = math.cos(cam.heading), math.sin(cam.heading)
    return forward * c - right * s, forward * s + right * c


def _read(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


# ----------------------------------------------------------------------------- geometry
def test_waterline_pixel_is_the_projection_of_the_ship_position_and_inverts_on_a_flat_sea(
    tmp_path: Path,
) -> None:
    cam = _camera(pitch_deg=0.0)
    specs = [  # (forward, right, course, speed, length)
        (300.0, -40.0, 1.1, 5.0, 20.0),
        (800.0, 30.0, 2.5, 7.0, 60.0),
        (1500.0, 250.0, -0.4, 4.0, 120.0),
    ]
    ships = []
    for i, (f, r, c, v, L) in enumerate(specs):
        n0, e0 = _ahead(cam, f, r)
        ships.append(make_ship(i + 1, straight(n0, e0, c, v, 5.0), L))
    res = render(cam, ships, 0.4, 10.0, out_dir=tmp_path, seed=3)
    rows = _read(res.truth)
    assert list(rows[0].keys()) == list(TRUTH_COLUMNS)
    assert len(rows) == 4 * 3 and res.objects == (1, 2, 3)
    for row in rows:
        i = int(row["object_id"]) - 1
        f, r, c, v, _ = specs[i]
        t = float(row["time"])
        assert math.isclose(t, int(row["frame"]) / 10.0)
        n0, e0 = _ahead(cam, f, r)
        north, east = n0 + v * t * math.cos(c), e0 + v * t * math.sin(c)  # closed form
        assert math.isclose(float(row["north_m"]), north, abs_tol=1e-3)
        assert math.isclose(float(row["east_m"]), east, abs_tol=1e-3)
        rng = math.hypot(north, east)
        az, el = math.atan2(east, north), -math.atan2(H_CAM, rng)
        uv = cam.angles_to_pixel(az, el)
        uv_row = np.array([float(row["u_wl"]), float(row["v_wl"])])
        np.testing.assert_allclose(uv_row, uv, atol=2e-3)
        # invert the water-line pixel with flat-sea geometry (seed 000 eqs. 3-5)
        a, e = cam.pixel_to_angles(uv_row)
        pos = sea_position((0.0, 0.0), 0.0, a, -e, H_CAM)
        err = math.hypot(pos.xy[0] - north, pos.xy[1] - east)
        assert err < 0.005 * rng
        # the water line lies inside the box (bottom-centre of the hull)
        x, y, w, h = (float(row[k]) for k in "xywh")
        assert x <= uv_row[0] <= x + w and y <= uv_row[1] <= y + h + 1e-6
        # geodetic position: Vincenty distance and azimuth from the camera
        dist, az12 = vincenty.vdist(LAT, LON, float(row["lat"]), float(row["lon"]))
        assert math.isclose(float(dist), rng, rel_tol=2e-4)
        assert math.isclose(math.radians(float(az12)), az % (2 * math.pi), abs_tol=1e-4)
        assert math.isclose(float(row["range_m"]), rng, abs_tol=1e-3)


def test_panning_camera_moves_the_ships_by_the_yaw_and_keeps_the_world_and_horizon() -> None:
    """pan = (5°, 4 s): heading(t) = heading_0 + 5° sin(2 pi t / 4 s). At t = 1 s the
    camera has turned 5° to the right: a ship at relative azimuth a and depression d
    (level camera, no distortion) is seen at u = cx + fx tan(a − 5°), v = cy + fy tan(d) /
    cos(a − 5°) instead of a; its world position, azimuth and depression, and the horizon
    line, do not change."""
    cam = _camera(pitch_deg=0.0)
    n0, e0 = _ahead(cam, 900.0, 120.0)
    ships = [make_ship(1, straight(n0, e0, 1.0, 4.0, 10.0), 60.0)]
    fixed = Renderer(cam, ships, 10.0, seed=2)
    panned = Renderer(cam, ships, 10.0, seed=2, pan=(math.radians(5.0), 4.0))
    for k, turn in ((0, 0.0), (10, 5.0), (30, -5.0)):
        f0, f1 = fixed.frame(k), panned.frame(k)
        assert math.degrees(f1.camera.heading - cam.heading) == pytest.approx(turn, abs=1e-9)
        (o0,), (o1,) = f0.objects, f1.objects
        rel = math.atan2(o0.u_wl - cam.cx, cam.fx)  # level camera: u = cx + fx tan(a)
        assert o1.u_wl - cam.cx == pytest.approx(
            cam.fx * math.tan(rel - math.radians(turn)), abs=1e-6
        )
        # and v = cy + fy tan(depression) / cos(relative azimuth)
        ratio = math.cos(rel) / math.cos(rel - math.radians(turn))
        assert o1.v_wl - cam.cy == pytest.approx((o0.v_wl - cam.cy) * ratio, abs=1e-6)
        for key in ("north", "east", "azimuth", "depression", "range"):
            assert getattr(o1, key) == getattr(o0, key)
        assert f1.horizon == pytest.approx(f0.horizon, abs=1e-9)
    with pytest.raises(ValueError, match="pan"):
        Renderer(cam, ships, 10.0, pan=(math.radians(50.0), 4.0))
    with pytest.raises(ValueError, match="pan"):
        Renderer(cam, ships, 10.0, pan=(0.1, 0.0))
    with pytest.raises(ValueError, match="pan"):
        Renderer(cam, ships, 10.0, pan=(0.1,))  # type: ignore[arg-type]


def test_curved_earth_waterline_sits_at_the_curved_sea_depression() -> None:
    cam = _camera(hfov=10.0, pitch_deg=0.0, height=20.0)
    n0, e0 = _ahead(cam, 5000.0, 0.0)
    ship = make_ship(1, straight(n0, e0, 0.3, 5.0, 2.0), 80.0)
    for earth, curved in (("curved", True), ("flat", False)):
        r = Renderer(cam, [ship], 10.0, earth=earth)
        _, (obj,), _ = r.truth(0)
        _, el = cam.pixel_to_angles([obj.u_wl, obj.v_wl])
        expect = sea_depression(5000.0, 20.0, curved=curved)
        assert math.isclose(-float(el), float(expect), abs_tol=1e-9)
        assert math.isclose(obj.depression, float(expect), abs_tol=1e-12)


def test_ship_beyond_the_horizon_distance_is_absent_from_the_truth() -> None:
    cam = _camera(hfov=8.0)
    d_hor = float(horizon_distance(H_CAM, 0.14))
    # ship 1 steams towards the camera across the horizon distance; ship 2 stays beyond
    n0, e0 = _ahead(cam, d_hor + 305.0, 0.0)
    n2, e2 = _ahead(cam, d_hor + 2000.0, 100.0)
    inbound = straight(n0, e0, cam.heading + math.pi, 100.0, 6.0)
    ships = [
        make_ship(1, inbound, 150.0, kind="cargo"),
        make_ship(2, straight(n2, e2, 0.0, 5.0, 6.0), 200.0, kind="tanker"),
    ]
    r = Renderer(cam, ships, 10.0)
    seen = []
    for i in range(60):
        _, objs, _ = r.truth(i)
        ids = {o.object_id for o in objs}
        assert 2 not in ids
        rng = d_hor + 305.0 - 100.0 * i / 10.0
        assert (1 in ids) == (rng <= d_hor), (i, rng, d_hor)
        seen.append(1 in ids)
    assert any(seen) and not all(seen)


# ----------------------------------------------------------------------------- horizon
def test_horizon_csv_is_the_horizon_line_of_each_frames_swayed_attitude(tmp_path: Path) -> None:
    cam = _camera(pitch_deg=-2.0, roll=math.radians(1.0))
    roll_amp, pitch_amp, period = math.radians(0.6), math.radians(0.4), 1.5
    res = render(
        cam,
        [],
        2.0,
        10.0,
        out_dir=tmp_path,
        sway=(roll_amp, pitch_amp, period),
        lighting=lighting_preset("day", clouds=0.0),
        noise=False,
        seed=5,
    )
    rows = _read(res.horizon)
    assert len(rows) == 20 and [int(r["frame"]) for r in rows] == list(range(20))
    t = np.array([float(r["time"]) for r in rows])
    roll = np.radians([float(r["roll_deg"]) for r in rows])
    pitch = np.radians([float(r["pitch_deg"]) for r in rows])
    for row, p, q in zip(rows, pitch, roll, strict=True):
        line = horizon_line(cam.with_attitude(pitch=p, roll=q))
        ends = line.endpoints(W)
        got = [float(row[k]) for k in ("x0", "y0", "x1", "y1")]
        np.testing.assert_allclose(got, ends.ravel(), atol=2e-3)
    # the attitude is the mounting attitude plus sinusoids of the given amplitudes
    w_r, w_p = 2 * math.pi / period, 2 * math.pi / (0.77 * period)
    for series, base, amp, w in (
        (roll, cam.roll, roll_amp, w_r),
        (pitch, cam.pitch, pitch_amp, w_p),
    ):
        A = np.column_stack([np.sin(w * t), np.cos(w * t)])
        coef, *_ = np.linalg.lstsq(A, series - base, rcond=None)
        assert math.isclose(float(np.hypot(*coef)), amp, rel_tol=1e-6)
        np.testing.assert_allclose(A @ coef, series - base, atol=1e-7)


def test_painted_horizon_edge_lies_on_the_horizon_line_in_swayed_frames() -> None:
    cam = _camera(pitch_deg=-2.0)
    r = Renderer(
        cam,
        [],
        10.0,
        sway=(math.radians(0.8), math.radians(0.5), 1.3),
        lighting=lighting_preset("day", clouds=0.0),
        noise=False,
        seed=2,
    )
    for i in (0, 4, 9):
        fr = r.frame(i)
        line = horizon_line(fr.camera)
        y = fr.luma.astype(float)
        for u in (40, 320, 600):
            v_true = float(line.v_at(u))
            k = round(v_true)
            col = y[k - 6 : k + 7, u]
            sky, sea = col[:3].mean(), col[-3:].mean()
            assert sky - sea > 15.0  # a visible horizon: sky brighter than the far sea
            mid = 0.5 * (sky + sea)
            j = int(np.argmax(col < mid))
            v_edge = (k - 6) + (j - 1) + (col[j - 1] - mid) / (col[j - 1] - col[j])
            assert abs(v_edge - v_true) < 1.0, (i, u, v_edge, v_true)


# ----------------------------------------------------------------------------- pixels
def _ship_mask(r_with: Renderer, r_without: Renderer, index: int) -> np.ndarray:
    """Pixels a ship changed: luma differs from the ship-free render (same seed, so the
    same waves and noise) by more than 8 levels (ignores the faint anti-aliasing fringe)."""
    a = r_with.frame(index).luma.astype(int)
    b = r_without.frame(index).luma.astype(int)
    return np.abs(a - b) > 8


def _assert_box_fits(mask: np.ndarray, obj) -> None:
    rows = np.flatnonzero(mask.any(axis=1))
    cols = np.flatnonzero(mask.any(axis=0))
    assert rows.size and cols.size
    # every ship pixel (centre) inside the box, up to a one-pixel anti-aliasing fringe
    assert cols[0] >= obj.x - 1.0 and cols[-1] <= obj.x + obj.w + 1.0
    assert rows[0] >= obj.y - 1.0 and rows[-1] <= obj.y + obj.h + 1.0
    # tight: the box edges within 2 px of the pixels' extent (pixel edges at +-0.5)
    assert abs(obj.x - (cols[0] - 0.5)) <= 2.0
    assert abs(obj.x + obj.w - (cols[-1] + 0.5)) <= 2.0
    assert abs(obj.y - (rows[0] - 0.5)) <= 2.0
    assert abs(obj.y + obj.h - (rows[-1] + 0.5)) <= 2.0


@pytest.mark.parametrize(
    ("forward", "right", "length", "kind"),
    [(1500.0, -150.0, 120.0, "cargo"), (700.0, 80.0, 40.0, "ferry"), (1200.0, 0.0, 10.0, "boat")],
)
def test_truth_box_contains_the_ships_pixels_and_is_tight(
    forward: float, right: float, length: float, kind: str
) -> None:
    cam = _camera(hfov=40.0, pitch_deg=-1.0)
    n0, e0 = _ahead(cam, forward, right)
    ship = make_ship(7, straight(n0, e0, cam.heading + 1.2, 6.0, 5.0), length, kind=kind)
    sway = (math.radians(0.3), math.radians(0.2), 2.0)
    with_ship = Renderer(cam, [ship], 10.0, sway=sway, seed=9)
    empty = Renderer(cam, [], 10.0, sway=sway, seed=9)
    for i in (0, 7):
        (obj,) = with_ship.frame(i).objects
        assert obj.visible == 1.0
        _assert_box_fits(_ship_mask(with_ship, empty, i), obj)


def test_occluded_ship_box_covers_only_its_visible_pixels() -> None:
    cam = _camera(hfov=40.0, pitch_deg=-1.0)
    far_n, far_e = _ahead(cam, 2000.0, 30.0)
    near_n, near_e = _ahead(cam, 1200.0, 0.0)
    far = make_ship(1, straight(far_n, far_e, cam.heading + 1.57, 0.0, 5.0), 150.0, kind="cargo")
    near = make_ship(2, straight(near_n, near_e, cam.heading + 1.57, 0.0, 5.0), 80.0, kind="ferry")
    both = Renderer(cam, [far, near], 10.0, seed=4)
    near_only = Renderer(cam, [near], 10.0, seed=4)
    fr = both.frame(0)
    objs = {o.object_id: o for o in fr.objects}
    assert 0.0 < objs[1].visible < 0.9 and objs[2].visible == 1.0
    _assert_box_fits(_ship_mask(both, near_only, 0), objs[1])
    # a boat right behind the big ship is fully hidden: no truth row
    hid_n, hid_e = _ahead(cam, 2600.0, 0.0)
    hidden = make_ship(3, straight(hid_n, hid_e, 0.0, 0.0, 5.0), 8.0, kind="boat")
    big_n, big_e = _ahead(cam, 1000.0, 0.0)
    big = make_ship(4, straight(big_n, big_e, cam.heading + 1.57, 0.0, 5.0), 200.0, kind="tanker")
    _, objs2, _ = Renderer(cam, [hidden, big], 10.0).truth(0)
    assert [o.object_id for o in objs2] == [4]


def test_night_frames_are_grayscale_with_ships_warmer_than_the_sea() -> None:
    cam = _camera(hfov=40.0, pitch_deg=-1.0)
    n0, e0 = _ahead(cam, 800.0, 0.0)
    ship = make_ship(1, straight(n0, e0, cam.heading + 1.5, 5.0, 5.0), 50.0, kind="workboat")
    fr = Renderer(cam, [ship], 10.0, lighting="night", seed=1).frame(3)
    assert np.all(fr.yuv[H:] == 128)  # neutral chroma
    (obj,) = fr.objects
    y = fr.luma.astype(float)
    inside = y[int(obj.y + obj.h * 0.85), int(obj.x + 0.3 * obj.w) : int(obj.x + 0.7 * obj.w)]
    below = y[int(obj.y + obj.h + 6), int(obj.x) : int(obj.x + obj.w)]
    assert inside.mean() > below.mean() + 40.0


# ----------------------------------------------------------------------------- files
def test_video_reads_back_with_the_right_frame_count_size_and_pixels(tmp_path: Path) -> None:
    cam = PinholeCamera.from_fov(320, 180, 50.0, height=12.0, pitch=math.radians(-2.0))
    n0, e0 = _ahead(cam, 600.0, 0.0)
    ship = make_ship(1, straight(n0, e0, 1.5, 5.0, 5.0), 40.0)
    res = render(cam, [ship], 0.6, 10.0, out_dir=tmp_path, seed=8, lighting="dusk")
    assert res.frames == 6 and res.image_size == (320, 180)
    with av.open(str(res.video)) as container:
        stream = container.streams.video[0]
        assert (stream.codec_context.width, stream.codec_context.height) == (320, 180)
        frames = [f.to_ndarray(format="bgr24") for f in container.decode(stream)]
    assert len(frames) == 6
    expect = Renderer(cam, [ship], 10.0, seed=8, lighting="dusk").frame(0).bgr()
    assert np.abs(frames[0].astype(int) - expect).mean() < 4.0
    loaded = __import__("seawatch.io", fromlist=["load_camera"]).load_camera(res.camera)
    assert loaded.image_size == (320, 180) and math.isclose(loaded.height, 12.0)


def test_crf_0_is_lossless_and_a_higher_crf_is_not(tmp_path: Path) -> None:
    """libx264's crf 0 is lossless: the decoded I420 planes are the rendered ones, bit for
    bit (what ``seawatch experiment ship-video --crf 0`` relies on to isolate the
    compression's share of the error); crf 30 changes pixels."""
    cam = PinholeCamera.from_fov(320, 180, 50.0, height=12.0)
    n0, e0 = _ahead(cam, 600.0, 0.0)
    ship = make_ship(1, straight(n0, e0, 1.5, 5.0, 5.0), 40.0)
    expect = [Renderer(cam, [ship], 10.0, seed=4).frame(i).yuv for i in range(3)]
    for crf in (0, 30):
        res = render(cam, [ship], 0.3, 10.0, out_dir=tmp_path / str(crf), seed=4, crf=crf)
        with av.open(str(res.video)) as container:
            got = [f.to_ndarray(format="yuv420p") for f in container.decode(video=0)]
        assert len(got) == 3
        same = [np.array_equal(g, e) for g, e in zip(got, expect, strict=True)]
        assert all(same) if crf == 0 else not any(same), (crf, same)


def test_truth_and_horizon_files_grow_while_rendering(tmp_path: Path) -> None:
    cam = PinholeCamera.from_fov(320, 180, 50.0, height=12.0)
    n0, e0 = _ahead(cam, 500.0, 0.0)
    ship = make_ship(1, straight(n0, e0, 1.5, 5.0, 5.0), 30.0)
    seen: list[tuple[int, int, int]] = []

    def progress(done: int, total: int) -> None:
        if done in (1, 3):
            seen.append(
                (done, len(_read(tmp_path / "truth.csv")), len(_read(tmp_path / "horizon.csv")))
            )

    res = render(cam, [ship], 0.8, 10.0, out_dir=tmp_path, progress=progress)
    assert seen == [(1, 1, 1), (3, 3, 3)]
    assert res.rows == 8 and len(_read(res.truth)) == 8


def test_bad_inputs_raise_value_errors_naming_the_argument(tmp_path: Path) -> None:
    good = _camera()
    ship = make_ship(1, straight(500, 0, 0, 1, 5), 20.0)
    with pytest.raises(ValueError, match="height"):
        Renderer(PinholeCamera.from_fov(W, H, 60.0), [], 10.0)
    with pytest.raises(ValueError, match="even"):
        Renderer(PinholeCamera.from_fov(641, 360, 60.0, height=5.0), [], 10.0)
    with pytest.raises(ValueError, match="lighting"):
        Renderer(good, [], 10.0, lighting="noon")
    with pytest.raises(ValueError, match="unique"):
        Renderer(good, [ship, ship], 10.0)
    with pytest.raises(ValueError, match="fps"):
        Renderer(good, [], 0.0)
    with pytest.raises(ValueError, match="sway"):
        Renderer(good, [], 10.0, sway=(0.1, 0.1))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="earth"):
        Renderer(good, [], 10.0, earth="round")  # type: ignore[arg-type]
    blocker = tmp_path / "a-file"
    blocker.write_text("x")
    with pytest.raises(ValueError, match="out_dir"):
        render(good, [ship], 0.2, 10.0, out_dir=blocker / "sub")
    with pytest.raises(ValueError, match="duration"):
        render(good, [ship], -1.0, 10.0, out_dir=tmp_path)
    for crf in (-1, 52, 2.5, True):
        with pytest.raises(ValueError, match="crf"):
            render(good, [ship], 0.2, 10.0, out_dir=tmp_path, crf=crf)  # type: ignore[arg-type]
