"""Issue 7's track targets on rendered moving-platform footage (seawatch.synth.platform_clip).

Each preset of :data:`PRESETS` is rendered at 960×540 and 5 frames/s (half the pixels and
half the frame rate of the measured 1080p/10 fps runs in docs/results/track/, to keep this
file near 90 s), tracked by :func:`seawatch.pipeline.track_video` with the clip's NAV and
mounted camera, and scored in the platform frame (ranges from the moving camera) against
the renderer's exact truth. The issue's targets are asserted as stated; where one is not
met, the test is a strict xfail whose reason gives the numbers measured here. The "5 % at
1 km" target is stated for 1080p: at 960×540 one pixel is twice the angle, so the check
here is stricter than the issue's (the 1080p number is in docs/results/track/).

The clip itself is checked against independent truths: the world-frame truth is the
targets' own constant-velocity motion, the NAV is the platform's, and the mounted camera
rotated by the NAV heading and the frame's sway projects the world-frame geometry onto
the rendered water-line pixel.
"""

from __future__ import annotations

import csv
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from seawatch.geometry.sea import sea_depression
from seawatch.io import load_camera
from seawatch.io.nav import read_nav
from seawatch.pipeline import track_video
from seawatch.synth.platform_clip import (
    PRESETS,
    ClipTarget,
    platform_clip_preset,
    render_platform_clip,
    score_platform_run,
)

SMALL = {"width": 960, "height_px": 540, "fps": 5.0}

# measured at 960×540, 5 frames/s (seed 0) — the reasons of the strict xfails below
XFAIL: dict[tuple[str, str], str] = {
    ("uav-sea", "rmse30"): (
        "issue 7 'EKF 30 % below point-wise geometry' not met since the horizon refines "
        "the attitude in every frame it is found (session 17): EKF 51.6 m vs geometry "
        "58.0 m (ratio 0.89; 1080p: 16.6 vs 19.4 m, 0.86); both were worse before, when "
        "frames under confidence 0.5 took the attitude without the sway: EKF 74.6 m, "
        "geometry 166.0 m (ratio 0.45). What is left is a bias, which no filtering "
        "removes: at 1080p the EKF's range error is 2.78 % RMS with a mean of -2.73 % "
        "at 250-500 m and 4.19 % with -4.10 % at 500-750 m (about 0.27 px on the "
        "water line)"
    ),
}


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def _col(rows: list[dict[str, str]], name: str) -> np.ndarray:
    return np.array([float(r[name]) if r[name] != "" else np.nan for r in rows])


@pytest.fixture(scope="module", params=list(PRESETS))
def scored(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory):
    name = request.param
    base = tmp_path_factory.mktemp(name)
    clip = render_platform_clip(base / "clip", **platform_clip_preset(name, **SMALL))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        track_video(
            clip.video,
            base / "run",
            camera=load_camera(clip.camera),
            platform=read_nav(clip.nav),
            start=0.0,
            truth=clip.truth_world,
            annotate=False,
            report=False,
        )
    return name, clip, score_platform_run(base / "run", clip.out_dir)


def _check(request: pytest.FixtureRequest, target: str, ok: bool, numbers: str) -> None:
    """Assert a target; a known miss (:data:`XFAIL`) is a strict xfail (a pass fails)."""
    name = request.node.callspec.params["scored"]
    reason = XFAIL.get((name, target))
    if reason is not None:
        request.applymarker(pytest.mark.xfail(reason=reason, strict=True))
    assert ok, f"{name}: {target} not met: {numbers}"


# ----------------------------------------------------------------------------- the targets
def test_ekf_position_rmse_at_least_30_percent_below_pointwise_geometry(
    scored, request: pytest.FixtureRequest
) -> None:
    _, _, err = scored
    geo, ekf = err.positions["geometry"], err.positions["ekf"]
    assert ekf.pairs > 0.8 * geo.pairs  # the EKF reports (almost) wherever geometry does
    ratio = ekf.rmse_position_m / geo.rmse_position_m
    _check(
        request,
        "rmse30",
        ratio <= 0.7,
        f"EKF {ekf.rmse_position_m:.1f} m vs geometry {geo.rmse_position_m:.1f} m "
        f"(ratio {ratio:.2f})",
    )


def test_ekf_position_rmse_no_worse_than_geometry_in_every_range_bin(
    scored, request: pytest.FixtureRequest
) -> None:
    _, _, err = scored
    geo = {b.lo: b for b in err.positions["geometry"].bins}
    worse = [
        f"{b.lo:.0f}-{b.hi:.0f} m: EKF {b.rmse_position_m:.1f} > geometry "
        f"{geo[b.lo].rmse_position_m:.1f} m"
        for b in err.positions["ekf"].bins
        if b.pairs and geo[b.lo].pairs and b.rmse_position_m > geo[b.lo].rmse_position_m
    ]
    assert any(b.pairs for b in err.positions["ekf"].bins)
    _check(request, "bins", not worse, "; ".join(worse))


def test_mota_above_0_8_with_at_most_one_identity_switch(
    scored, request: pytest.FixtureRequest
) -> None:
    _, _, err = scored
    _check(
        request,
        "mot",
        err.mota > 0.8 and err.id_switches <= 1,
        f"MOTA {err.mota:.3f}, {err.id_switches} ID switches",
    )


def test_every_ship_in_view_keeps_one_track_id_from_entry_to_exit(
    scored, request: pytest.FixtureRequest
) -> None:
    _, _, err = scored
    assert err.objects, "no truth object scored"
    many = [f"object {o.object_id}: ids {o.track_ids}" for o in err.objects if len(o.track_ids) > 1]
    missed = [o.object_id for o in err.objects if o.matched == 0]
    _check(request, "one-id", not many and not missed, f"{many}, never tracked {missed}")


@pytest.mark.parametrize("scored", ["range-1km"], indirect=True)
def test_ekf_range_error_under_5_percent_at_1km_for_a_10m_camera(
    scored, request: pytest.FixtureRequest
) -> None:
    _, clip, err = scored
    assert clip.mounted.height == 10.0
    b = next(b for b in err.positions["ekf"].bins if b.lo == 750.0)
    assert b.pairs > 0.8 * clip.render.frames
    _check(
        request,
        "range1km",
        b.rmse_range_percent < 5.0,
        f"{b.rmse_range_percent:.2f} % RMS (bias {b.mean_range_error_percent:+.2f} %) at 960x540",
    )


# ----------------------------------------------------------------------------- the clip
@pytest.fixture(scope="module")
def tiny(tmp_path_factory: pytest.TempPathFactory):
    kw = platform_clip_preset("uav-sea", width=640, height_px=360, fps=5.0, duration=3.0, seed=3)
    return render_platform_clip(tmp_path_factory.mktemp("tiny"), **kw)


def test_world_truth_is_the_targets_own_constant_velocity_motion(tiny) -> None:
    rows = _rows(tiny.truth_world)
    assert rows
    target = tiny.targets[0]  # SCENARIOS uav-sea: from (400, 600) m at (-2.98, -3.12) m/s
    t = _col(rows, "time")
    expect = np.array([400.0, 600.0]) + t[:, None] * np.array([-2.98, -3.12])
    got = np.stack([_col(rows, "north_m"), _col(rows, "east_m")], -1)
    np.testing.assert_allclose(got, expect, atol=2e-3)
    np.testing.assert_allclose(_col(rows, "speed_mps"), math.hypot(*target.velocity), atol=1e-3)
    platform = t[:, None] * np.array([2.55, 4.33])
    np.testing.assert_allclose(
        np.stack([_col(rows, "platform_north_m"), _col(rows, "platform_east_m")], -1),
        platform,
        atol=1e-3,
    )
    # range: from the moving camera, unchanged from the relative truth
    np.testing.assert_allclose(_col(rows, "range_m"), np.hypot(*(expect - platform).T), rtol=1e-5)
    np.testing.assert_allclose(_col(rows, "range_m")[0], math.hypot(400.0, 600.0), rtol=1e-5)


def test_nav_gives_the_platform_track_and_the_mounted_camera_has_no_heading(tiny) -> None:
    nav = read_nav(tiny.nav)
    t = np.array([0.0, 1.1, 2.9])
    pose = nav.pose_at(t)
    np.testing.assert_allclose(pose.north, 2.55 * t, atol=1e-3)
    np.testing.assert_allclose(pose.east, 4.33 * t, atol=1e-3)
    np.testing.assert_allclose(np.degrees(pose.heading), 50.0, atol=1e-6)
    assert nav.lat0 == pytest.approx(tiny.lat0) and nav.lon0 == pytest.approx(tiny.lon0)
    cam = load_camera(tiny.camera)
    assert cam.heading == 0.0 and cam.position == (0.0, 0.0)
    assert cam.lat is None and cam.lon is None
    assert cam.height == 3.0 and cam.pitch == pytest.approx(math.radians(-1.0))
    assert cam.image_size == (640, 360)


def test_mounted_camera_turned_by_nav_heading_projects_world_geometry_to_water_line(
    tiny,
) -> None:
    rows = _rows(tiny.truth_world)
    hz = {int(r["frame"]): r for r in _rows(tiny.horizon)}
    pose = read_nav(tiny.nav).pose_at(_col(rows, "time"))
    mounted = load_camera(tiny.camera)
    rel = np.stack([_col(rows, "north_m") - pose.north, _col(rows, "east_m") - pose.east], -1)
    az = np.arctan2(rel[:, 1], rel[:, 0])
    dep = sea_depression(np.hypot(*rel.T), 3.0, curved=True)
    uv = np.array(
        [
            mounted.with_attitude(
                heading=mounted.heading + pose.heading[i],
                pitch=math.radians(float(hz[int(r["frame"])]["pitch_deg"])),
                roll=math.radians(float(hz[int(r["frame"])]["roll_deg"])),
            ).angles_to_pixel(az[i], -dep[i])
            for i, r in enumerate(rows)
        ]
    )
    got = np.stack([_col(rows, "u_wl"), _col(rows, "v_wl")], -1)
    np.testing.assert_allclose(uv, got, atol=0.02)  # truth written to 1e-4 px, angles 1e-6°


def test_bad_clip_arguments_raise_value_error_naming_them(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="targets"):
        render_platform_clip(tmp_path, targets=())
    with pytest.raises(ValueError, match="velocity"):
        ClipTarget(0.0, 100.0, (np.nan, 1.0))
    with pytest.raises(ValueError, match="kind"):
        ClipTarget(0.0, 100.0, (1.0, 1.0), kind="submarine")
    with pytest.raises(ValueError, match="height"):
        render_platform_clip(tmp_path, height=-3.0)
    with pytest.raises(ValueError, match="platform_velocity"):
        render_platform_clip(tmp_path, platform_velocity=(1.0, 2.0, 3.0))
    with pytest.raises(ValueError, match="height_px"):
        render_platform_clip(tmp_path, height_px=270)
    with pytest.raises(ValueError, match="name"):
        platform_clip_preset("uav-air")
    with pytest.raises(ValueError, match="targets"):
        render_platform_clip(
            tmp_path, targets=(ClipTarget(1.0, 9.0, (0.0, 1.0)), ClipTarget(2.0, 9.0, (0.0, 1.0)))
        )
