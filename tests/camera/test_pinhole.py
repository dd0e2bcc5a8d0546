"""Tests of the pinhole camera: pixels ↔ rays ↔ (azimuth, elevation) (ALGORITHMS.md §4.3)."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from seawatch.camera import PinholeCamera

# Seed 000's data-sheet camera: 1920x1080, 70 degree horizontal field of view.
IDEAL = PinholeCamera.from_fov(1920, 1080, 70.0)
# OpenCV's sample calibration (../shared/data/opencv/left_intrinsics.yml): strong
# barrel distortion with k3, 640x480.
LEFT_K = np.array(
    [[535.91573396163199, 0.0, 342.28315473308373], [0.0, 535.91573396163199, 235.57082909788173],
     [0.0, 0.0, 1.0]]
)  # fmt: skip
LEFT_DIST = np.array(
    [-0.26637260909660682, -0.038588898922304653, 0.0017831947042852964,
     -0.00028122100441115472, 0.23839153080878486]
)  # fmt: skip
DISTORTED = PinholeCamera.from_matrix(LEFT_K, LEFT_DIST, (640, 480))
# A rational (8-coefficient) model with unequal focal lengths.
RATIONAL = PinholeCamera(
    fx=800.0,
    fy=780.0,
    cx=330.0,
    cy=250.0,
    image_size=(640, 480),
    dist=(0.1, -0.05, 0.001, -0.002, 0.01, 0.05, -0.02, 0.003),
)
CAMERAS = {"ideal": IDEAL, "distorted": DISTORTED, "rational": RATIONAL}

angle_deg = st.floats(-30.0, 30.0)
heading_rad = st.floats(-math.pi, math.pi)
unit = st.floats(0.0, 1.0)


def _ang_diff(a, b):
    """Smallest signed difference of two angles [rad]."""
    return np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b))))


def _pixel_in(camera, fu, fv):
    w, h = camera.image_size
    return np.array([-0.5 + fu * w, -0.5 + fv * h])


# ---------------------------------------------------------------- construction
def test_from_fov_focal_length_is_half_width_over_tan_half_fov():
    cam = PinholeCamera.from_fov(1920, 1080, 70.0)
    f = 960.0 / math.tan(math.radians(35.0))
    assert cam.fx == pytest.approx(f, rel=1e-15)
    assert cam.fy == pytest.approx(f, rel=1e-15)
    assert (cam.cx, cam.cy) == (959.5, 539.5)
    assert cam.image_size == (1920, 1080)
    assert math.degrees(cam.hfov) == pytest.approx(70.0, rel=1e-14)
    assert cam.dist == (0.0,) * 5 and not cam.has_distortion


def test_from_fov_with_vertical_fov_sets_fy_from_it():
    cam = PinholeCamera.from_fov(1920, 1080, 70.0, vfov_deg=40.0)
    assert cam.fy == pytest.approx(540.0 / math.tan(math.radians(20.0)), rel=1e-15)


def test_from_fov_keyword_height_is_the_camera_height_above_the_sea():
    cam = PinholeCamera.from_fov(1920, 1080, 70.0, height=12.5, pitch=-0.1)
    assert cam.height == 12.5 and cam.image_size == (1920, 1080) and cam.pitch == -0.1


def test_from_matrix_reads_the_opencv_matrix_and_pads_four_coefficients():
    cam = PinholeCamera.from_matrix(LEFT_K, LEFT_DIST[:4].reshape(1, 4), (640, 480))
    np.testing.assert_array_equal(cam.K, LEFT_K)
    assert cam.dist == (*LEFT_DIST[:4], 0.0)


def test_with_attitude_returns_a_new_camera_and_keeps_the_original():
    cam = IDEAL.with_attitude(pitch=-0.2)
    assert cam.pitch == -0.2 and cam.heading == IDEAL.heading and IDEAL.pitch == 0.0
    assert cam.with_attitude(heading=1.0, roll=0.3) == PinholeCamera.from_fov(
        1920, 1080, 70.0, heading=1.0, pitch=-0.2, roll=0.3
    )


# ---------------------------------------------------------------- closed forms
@pytest.mark.parametrize("heading", [0.0, 1.0, -2.0, 3.0])
def test_principal_point_of_level_camera_maps_to_heading_and_zero_elevation(heading):
    cam = IDEAL.with_attitude(heading=heading)
    az, el = cam.pixel_to_angles([cam.cx, cam.cy])
    assert _ang_diff(az, heading) == pytest.approx(0.0, abs=1e-15)
    assert 0.0 <= az < 2 * math.pi
    assert el == pytest.approx(0.0, abs=1e-15)
    az_p, el_p = cam.pixel_to_angles([cam.cx, cam.cy], frame="platform")
    assert az_p == pytest.approx(0.0, abs=1e-15) and el_p == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("dv", [-300.0, -1.0, 1.0, 250.0])
def test_pixel_rows_above_centre_have_positive_elevation_atan_dv_over_f(dv):
    cam = RATIONAL.with_attitude(heading=0.7)
    # ideal pixel on the centre column dv rows from the principal point
    uv = cam.distort([cam.cx, cam.cy + dv])
    az, el = cam.pixel_to_angles(uv)
    assert el == pytest.approx(-math.atan(dv / cam.fy), abs=1e-12)
    assert _ang_diff(az, 0.7) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("du", [-500.0, 40.0, 900.0])
def test_pixel_columns_right_of_centre_have_platform_azimuth_atan_du_over_f(du):
    cam = IDEAL.with_attitude(heading=-1.2)
    az, el = cam.pixel_to_angles([cam.cx + du, cam.cy], frame="platform")
    assert az == pytest.approx(math.atan(du / cam.fx), abs=1e-14)
    assert el == pytest.approx(0.0, abs=1e-15)


def test_camera_pitched_down_5_deg_sees_the_true_horizon_5_deg_above_its_centre():
    cam = IDEAL.with_attitude(heading=0.3, pitch=math.radians(-5.0))
    uv = cam.angles_to_pixel(0.3, 0.0)
    np.testing.assert_allclose(
        uv, [cam.cx, cam.cy - cam.fy * math.tan(math.radians(5.0))], rtol=0, atol=1e-9
    )
    _, el = cam.pixel_to_angles([cam.cx, cam.cy])
    assert el == pytest.approx(math.radians(-5.0), abs=1e-15)


@pytest.mark.parametrize("roll_deg", [-20.0, 10.0])
def test_positive_roll_lowers_the_right_side_of_the_image(roll_deg):
    # Ray r_c = (t, 0, 1) → body (1, t, 0) → R_x(phi): (1, t cos phi, t sin phi) (D down)
    phi = math.radians(roll_deg)
    cam = IDEAL.with_attitude(roll=phi)
    du = 400.0
    t = du / cam.fx
    _, el = cam.pixel_to_angles([cam.cx + du, cam.cy])
    expected = -math.atan2(t * math.sin(phi), math.hypot(1.0, t * math.cos(phi)))
    assert el == pytest.approx(expected, abs=1e-14)
    assert np.sign(el) == -np.sign(roll_deg)


def test_world_azimuth_is_heading_plus_platform_azimuth():
    cam = DISTORTED.with_attitude(heading=5.5, pitch=-0.1, roll=0.2)
    rng = np.random.default_rng(1234)
    uv = rng.uniform([0, 0], [639, 479], size=(50, 2))
    az_w, el_w = cam.pixel_to_angles(uv, frame="world")
    az_p, el_p = cam.pixel_to_angles(uv, frame="platform")
    np.testing.assert_allclose(_ang_diff(az_w, az_p + 5.5), 0.0, atol=1e-13)
    np.testing.assert_allclose(el_w, el_p, atol=1e-15)
    assert np.all((az_w >= 0) & (az_w < 2 * math.pi)) and np.all(np.abs(az_p) <= math.pi)


def test_rays_are_unit_and_the_principal_ray_is_the_optical_axis():
    cam = DISTORTED.with_attitude(heading=0.4, pitch=-0.3, roll=0.1)
    rng = np.random.default_rng(1234)
    uv = rng.uniform([0, 0], [639, 479], size=(20, 2))
    for frame in ("camera", "world", "platform"):
        np.testing.assert_allclose(np.linalg.norm(cam.pixel_to_ray(uv, frame), axis=-1), 1.0)
    np.testing.assert_allclose(cam.pixel_to_ray([cam.cx, cam.cy]), [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(
        cam.pixel_to_ray([cam.cx, cam.cy], "world"), cam.R_nc[:, 2], atol=1e-15
    )


@given(
    name=st.sampled_from(sorted(CAMERAS)),
    scale=st.sampled_from([0.25, 0.5, 2 / 3, 1.5, 2.0]),
    daz=st.floats(-30.0, 30.0),
    del_=st.floats(-20.0, 20.0),
)
def test_resized_camera_sees_each_direction_at_the_scaled_pixel(name, scale, daz, del_):
    """The same view sampled on a grid ``scale`` times as fine: a direction seen at pixel
    p (centres at integers) is seen at scale (p + ½) − ½, lens distortion included; the
    angles of a pixel are those of its scaled pixel, and the attitude is kept."""
    cam = CAMERAS[name].with_attitude(0.3, math.radians(-2.0), math.radians(1.5))
    w, h = cam.image_size
    small = cam.resized((round(w * scale), round(h * scale)))
    assert small.image_size == (round(w * scale), round(h * scale))
    assert (small.heading, small.pitch, small.roll, small.dist) == (
        cam.heading, cam.pitch, cam.roll, cam.dist)  # fmt: skip
    az, el = 0.3 + math.radians(daz), math.radians(-2.0 + del_)
    uv = cam.angles_to_pixel(az, el)
    assume(np.all(np.isfinite(uv)) and -0.5 <= uv[0] <= w - 0.5 and -0.5 <= uv[1] <= h - 0.5)
    sx, sy = small.image_size[0] / w, small.image_size[1] / h
    expected = [sx * (uv[0] + 0.5) - 0.5, sy * (uv[1] + 0.5) - 0.5]
    np.testing.assert_allclose(small.angles_to_pixel(az, el), expected, rtol=0, atol=1e-6)
    back = small.pixel_to_angles(expected)
    assert abs(_ang_diff(back[0], az)) < 1e-9 and abs(back[1] - el) < 1e-9


@given(
    name=st.sampled_from(sorted(CAMERAS)),
    scale=st.floats(0.3, 3.0),
    daz=st.floats(-10.0, 10.0),
    del_=st.floats(-5.0, 5.0),
    cu=st.floats(0.2, 0.8),
    cv=st.floats(0.2, 0.8),
)
def test_zoomed_camera_sees_each_direction_at_the_magnified_pixel(name, scale, daz, del_, cu, cv):
    """A zoom magnifies the image by ``scale`` about a centre c: the direction seen at
    pixel p is seen at c + scale (p − c), lens distortion included, and a pixel's angles
    are those of its unmagnified pixel (the world stage of a zooming camera)."""
    cam = CAMERAS[name].with_attitude(0.3, math.radians(-2.0), math.radians(1.5))
    w, h = cam.image_size
    centre = np.array([cu * w, cv * h])
    zoomed = cam.zoomed(scale, tuple(centre))
    assert (zoomed.image_size, zoomed.dist, zoomed.heading) == (
        cam.image_size,
        cam.dist,
        cam.heading,
    )
    az, el = 0.3 + math.radians(daz), math.radians(-2.0 + del_)
    uv = cam.angles_to_pixel(az, el)
    assume(np.all(np.isfinite(uv)) and -0.5 <= uv[0] <= w - 0.5 and -0.5 <= uv[1] <= h - 0.5)
    expected = centre + scale * (uv - centre)
    np.testing.assert_allclose(zoomed.angles_to_pixel(az, el), expected, rtol=0, atol=1e-6)
    back = zoomed.pixel_to_angles(expected)
    assert abs(_ang_diff(back[0], az)) < 1e-9 and abs(back[1] - el) < 1e-9
    assert cam.zoomed(scale).cx == pytest.approx(cam.cx)  # about the principal point


def test_zoomed_rejects_a_bad_scale():
    with pytest.raises(ValueError, match="scale"):
        IDEAL.zoomed(0.0)


def test_resized_rejects_a_bad_size():
    with pytest.raises(ValueError, match="image_size"):
        IDEAL.resized((960, 0))
    with pytest.raises(ValueError, match="image_size"):
        IDEAL.resized((960.5, 540))


# ---------------------------------------------------------------- round trips
@given(
    name=st.sampled_from(sorted(CAMERAS)),
    fu=unit,
    fv=unit,
    heading=heading_rad,
    pitch=angle_deg,
    roll=angle_deg,
)
def test_pixel_to_angles_to_pixel_round_trip(name, fu, fv, heading, pitch, roll):
    cam = CAMERAS[name].with_attitude(heading, math.radians(pitch), math.radians(roll))
    uv = _pixel_in(cam, fu, fv)
    for frame in ("world", "platform"):
        az, el = cam.pixel_to_angles(uv, frame=frame)
        back = cam.angles_to_pixel(az, el, frame=frame)
        np.testing.assert_allclose(back, uv, rtol=0, atol=1e-8)


@given(
    name=st.sampled_from(sorted(CAMERAS)),
    daz=st.floats(-35.0, 35.0),
    del_=st.floats(-25.0, 25.0),
    heading=heading_rad,
    pitch=st.floats(-20.0, 20.0),
    roll=angle_deg,
)
def test_angles_to_pixel_to_angles_round_trip_to_1e9_rad(name, daz, del_, heading, pitch, roll):
    cam = CAMERAS[name].with_attitude(heading, math.radians(pitch), math.radians(roll))
    az0 = heading + math.radians(daz)
    el0 = math.radians(pitch + del_)
    uv = cam.angles_to_pixel(az0, el0)
    w, h = cam.image_size
    assume(np.all(np.isfinite(uv)) and -0.5 <= uv[0] <= w - 0.5 and -0.5 <= uv[1] <= h - 0.5)
    az, el = cam.pixel_to_angles(uv)
    assert abs(_ang_diff(az, az0)) < 1e-9
    assert abs(el - el0) < 1e-9


@pytest.mark.parametrize("name", sorted(CAMERAS))
def test_undistort_matches_opencv_and_distort_inverts_it(name):
    cam = CAMERAS[name]
    rng = np.random.default_rng(1234)
    uv = rng.uniform([-0.5, -0.5], np.subtract(cam.image_size, 0.5), size=(200, 2))
    ideal = cam.undistort(uv)
    ref = cv2.undistortPoints(
        uv.reshape(-1, 1, 2),
        np.array(cam.K),
        np.array(cam.dist),
        P=np.array(cam.K),
        criteria=(cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 200, 1e-16),
    ).reshape(-1, 2)
    np.testing.assert_allclose(ideal, ref, rtol=0, atol=1e-8)
    np.testing.assert_allclose(cam.distort(ideal), uv, rtol=0, atol=1e-9)


@pytest.mark.parametrize("name", sorted(CAMERAS))
def test_angles_to_pixel_agrees_with_cv2_project_points_posed_by_r_nc(name):
    cam = CAMERAS[name].with_attitude(heading=2.0, pitch=math.radians(-7.0), roll=0.15)
    rng = np.random.default_rng(1234)
    az = 2.0 + rng.uniform(-0.4, 0.4, 100)
    el = math.radians(-7.0) + rng.uniform(-0.3, 0.3, 100)
    # world points on the unit sphere in NED, camera at the origin: x_c = R_nc^T x_n
    pts = np.column_stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)])
    rvec, _ = cv2.Rodrigues(np.ascontiguousarray(cam.R_nc.T))
    ref, _ = cv2.projectPoints(pts, rvec, np.zeros(3), np.array(cam.K), np.array(cam.dist))
    np.testing.assert_allclose(cam.angles_to_pixel(az, el), ref.reshape(-1, 2), atol=1e-8)


def test_directions_behind_the_camera_give_nan_pixels():
    cam = IDEAL.with_attitude(heading=1.0)
    uv = cam.angles_to_pixel([1.0, 1.0 + math.pi, 1.0 + math.pi / 2], [0.0, 0.0, 0.0])
    assert np.all(np.isfinite(uv[0])) and np.all(np.isnan(uv[1:]))


# ---------------------------------------------------------------- uncertainty
@pytest.mark.parametrize("name", sorted(CAMERAS))
def test_angle_jacobian_matches_central_differences(name):
    cam = CAMERAS[name].with_attitude(heading=0.5, pitch=-0.2, roll=0.25)
    rng = np.random.default_rng(1234)
    uv = rng.uniform([0, 0], np.subtract(cam.image_size, 1), size=(30, 2))
    jac = cam.angle_jacobian(uv)
    step = 1e-3
    num = np.empty_like(jac)
    for k in range(2):
        e = np.zeros(2)
        e[k] = step
        az_p, el_p = cam.pixel_to_angles(uv + e)
        az_m, el_m = cam.pixel_to_angles(uv - e)
        num[:, 0, k] = _ang_diff(az_p, az_m) / (2 * step)
        num[:, 1, k] = (el_p - el_m) / (2 * step)
    np.testing.assert_allclose(jac, num, rtol=1e-6, atol=1e-12)


def test_angle_sigma_at_the_centre_of_a_level_pinhole_is_sigma_px_over_f():
    cam = PinholeCamera(fx=1500.0, fy=1400.0, cx=960.0, cy=540.0, image_size=(1920, 1080))
    cov = cam.with_attitude(heading=2.5).angle_covariance([cam.cx, cam.cy], 0.5)
    np.testing.assert_allclose(cov, np.diag([(0.5 / 1500.0) ** 2, (0.5 / 1400.0) ** 2]), rtol=1e-14)
    quant = cam.angle_covariance([[cam.cx, cam.cy]] * 3, [1 / math.sqrt(12)] * 3)
    assert math.sqrt(quant[1, 1, 1]) == pytest.approx(0.2887 / 1400.0, rel=1e-3)  # §4.3 pitfall


def test_angle_covariance_is_symmetric_psd_and_batched():
    cam = DISTORTED.with_attitude(pitch=-0.3, roll=0.2)
    uv = np.random.default_rng(1234).uniform([0, 0], [639, 479], size=(4, 5, 2))
    cov = cam.angle_covariance(uv, 0.7)
    assert cov.shape == (4, 5, 2, 2)
    np.testing.assert_allclose(cov, np.swapaxes(cov, -1, -2), rtol=1e-12)
    assert np.all(np.linalg.eigvalsh(cov) > 0)


# ---------------------------------------------------------------- shapes, NaN, bad input
def test_batch_shapes_are_preserved():
    cam = DISTORTED.with_attitude(pitch=-0.1)
    uv = np.random.default_rng(1234).uniform([0, 0], [639, 479], size=(3, 4, 2))
    az, el = cam.pixel_to_angles(uv)
    assert az.shape == el.shape == (3, 4)
    assert cam.pixel_to_ray(uv).shape == (3, 4, 3)
    assert cam.angle_jacobian(uv).shape == (3, 4, 2, 2)
    assert cam.angles_to_pixel(az, el).shape == (3, 4, 2)
    assert cam.angles_to_pixel(az, 0.0).shape == (3, 4, 2)
    assert np.shape(cam.pixel_to_angles([1.0, 2.0])[0]) == ()


@pytest.mark.parametrize("name", sorted(CAMERAS))
def test_nan_pixels_give_nan_angles_and_leave_other_rows_alone(name):
    cam = CAMERAS[name].with_attitude(pitch=-0.05)
    uv = np.array([[100.0, 200.0], [np.nan, 30.0], [300.0, np.inf], [50.0, 60.0]])
    az, el = cam.pixel_to_angles(uv)
    assert np.all(np.isnan(az[1:3])) and np.all(np.isnan(el[1:3]))
    good_az, good_el = cam.pixel_to_angles(uv[[0, 3]])
    np.testing.assert_array_equal(az[[0, 3]], good_az)
    np.testing.assert_array_equal(el[[0, 3]], good_el)
    assert np.all(np.isnan(cam.angle_jacobian(uv)[1:3]))
    assert np.all(np.isnan(cam.angles_to_pixel([np.nan, 0.0], [0.0, np.nan])))


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"fx": -1.0}, "fx"),
        ({"fy": 0.0}, "fy"),
        ({"cx": np.nan}, "cx"),
        ({"image_size": (0, 480)}, "image_size"),
        ({"image_size": (640.5, 480)}, "image_size"),
        ({"image_size": (640, 480, 3)}, "image_size"),
        ({"dist": (0.1, 0.2, 0.3)}, "dist"),
        ({"dist": (0.1, np.nan, 0.0, 0.0, 0.0)}, "dist"),
        ({"height": -3.0}, "height"),
        ({"lat": 50.0}, "lat"),
        ({"lat": 95.0, "lon": 0.0}, "lat"),
        ({"position": (1.0,)}, "position"),
        ({"pitch": np.inf}, "pitch"),
    ],
)
def test_bad_constructor_arguments_raise_value_error_naming_them(kwargs, name):
    args = {"fx": 500.0, "fy": 500.0, "cx": 320.0, "cy": 240.0, "image_size": (640, 480)}
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        PinholeCamera(**args)


def test_bad_matrices_and_fov_raise_value_error_naming_them():
    skew = LEFT_K.copy()
    skew[0, 1] = 0.5
    with pytest.raises(ValueError, match="K"):
        PinholeCamera.from_matrix(skew, LEFT_DIST, (640, 480))
    with pytest.raises(ValueError, match="K"):
        PinholeCamera.from_matrix(LEFT_K[:2], LEFT_DIST, (640, 480))
    with pytest.raises(ValueError, match="dist"):
        PinholeCamera.from_matrix(LEFT_K, np.zeros((2, 5)), (640, 480))
    with pytest.raises(ValueError, match="hfov_deg"):
        PinholeCamera.from_fov(1920, 1080, 180.0)
    with pytest.raises(ValueError, match="image_width"):
        PinholeCamera.from_fov(-1920, 1080, 70.0)


def test_bad_method_inputs_raise_value_error_naming_them():
    with pytest.raises(ValueError, match="uv"):
        IDEAL.pixel_to_angles(np.zeros((5, 3)))
    with pytest.raises(ValueError, match="uv"):
        IDEAL.pixel_to_ray(3.0)
    with pytest.raises(ValueError, match="uv_ideal"):
        IDEAL.distort(np.zeros(3))
    with pytest.raises(ValueError, match="frame"):
        IDEAL.pixel_to_angles([1.0, 2.0], frame="camera")
    with pytest.raises(ValueError, match="frame"):
        IDEAL.angles_to_pixel(0.0, 0.0, frame="body")
    with pytest.raises(ValueError, match="azimuth, elevation"):
        IDEAL.angles_to_pixel(np.zeros(3), np.zeros(4))
    with pytest.raises(ValueError, match="ray"):
        IDEAL.ray_to_pixel(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="sigma_px"):
        IDEAL.angle_covariance([1.0, 2.0], -1.0)
