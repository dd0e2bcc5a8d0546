"""Tests of camera attitude rotations and horizon ↔ pitch/roll (ALGORITHMS.md §4.2, §4.3)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from seawatch.camera import (
    R_BC,
    HorizonLine,
    PinholeCamera,
    attitude_from_horizon,
    attitude_from_rotation,
    horizon_dip,
    horizon_line,
    rotation_nc,
)

IDEAL = PinholeCamera.from_fov(1920, 1080, 70.0, height=10.0)
DISTORTED = PinholeCamera(
    fx=535.9,
    fy=535.9,
    cx=342.3,
    cy=235.6,
    image_size=(640, 480),
    dist=(-0.266, -0.0386, 0.00178, -0.00028, 0.2384),
    height=10.0,
)
R_EARTH = 6_371_000.0


# ---------------------------------------------------------------- rotations
def test_rotation_nc_equals_scipy_intrinsic_zyx_euler_times_r_bc():
    rng = np.random.default_rng(1234)
    psi = rng.uniform(-math.pi, math.pi, 20)
    theta = rng.uniform(-1.5, 1.5, 20)
    phi = rng.uniform(-math.pi, math.pi, 20)
    ref = Rotation.from_euler("ZYX", np.column_stack([psi, theta, phi])).as_matrix() @ R_BC
    np.testing.assert_allclose(rotation_nc(psi, theta, phi), ref, atol=1e-15)


def test_rotation_nc_broadcasts_and_is_a_proper_rotation():
    r = rotation_nc(np.linspace(0, 1, 4)[:, None], np.linspace(-0.5, 0.5, 3), 0.2)
    assert r.shape == (4, 3, 3, 3)
    np.testing.assert_allclose(
        r @ np.swapaxes(r, -1, -2), np.broadcast_to(np.eye(3), r.shape), atol=1e-15
    )
    np.testing.assert_allclose(np.linalg.det(r), 1.0)


def test_level_camera_looks_north_with_image_right_east_and_image_down_down():
    np.testing.assert_array_equal(rotation_nc(0.0, 0.0, 0.0), [[0, 0, 1], [1, 0, 0], [0, 1, 0]])


def test_sign_conventions_pitch_up_roll_right_side_down_heading_clockwise():
    # optical axis (camera z) for pitch +10 deg points above the horizon (negative Down)
    assert rotation_nc(0.0, math.radians(10.0), 0.0)[2, 2] < 0
    # image right (camera x) for roll +10 deg points below the horizon (positive Down)
    assert rotation_nc(0.0, 0.0, math.radians(10.0))[2, 0] > 0
    # heading +90 deg: optical axis East
    np.testing.assert_allclose(rotation_nc(math.pi / 2, 0.0, 0.0)[:, 2], [0, 1, 0], atol=1e-16)


@given(heading=st.floats(-3.1, 3.1), pitch=st.floats(-1.5, 1.5), roll=st.floats(-3.1, 3.1))
def test_attitude_from_rotation_inverts_rotation_nc(heading, pitch, roll):
    psi, theta, phi = attitude_from_rotation(rotation_nc(heading, pitch, roll))
    assert abs(psi - heading) < 1e-9 and abs(theta - pitch) < 1e-9 and abs(phi - roll) < 1e-9


def test_camera_with_pitch_minus_5_deg_sees_the_true_horizon_5_deg_above_centre():
    cam = IDEAL.with_attitude(heading=1.0, pitch=math.radians(-5.0))
    u, v = cam.angles_to_pixel(1.0, 0.0)
    assert u == pytest.approx(cam.cx, abs=1e-9)
    assert cam.cy - v == pytest.approx(cam.fy * math.tan(math.radians(5.0)), rel=1e-12)


# ---------------------------------------------------------------- dip (§4.2)
def test_horizon_dip_is_arccos_re_over_re_plus_h_and_matches_the_spec_examples():
    h = np.array([0.5, 2.0, 5.0, 10.0, 100.0, 1000.0])
    re = R_EARTH / (1 - 0.14)
    np.testing.assert_allclose(horizon_dip(h), np.arccos(re / (re + h)), rtol=1e-7, atol=1e-12)
    assert math.degrees(horizon_dip(5.0)) == pytest.approx(0.0666, abs=5e-5)  # §4.2 example
    # geometric dip 1.93' sqrt(h); nautical almanac 1.76' sqrt(h) with k ≈ 0.165
    assert math.degrees(horizon_dip(9.0, 0.0)) * 60 == pytest.approx(1.93 * 3, rel=3e-3)
    assert math.degrees(horizon_dip(9.0, 0.165)) * 60 == pytest.approx(1.76 * 3, rel=5e-3)
    # §4.1 example: h = 10 m, k = 0.14 → dip ≈ 1.6 mrad
    assert horizon_dip(10.0) == pytest.approx(1.6e-3, abs=0.05e-3)


@pytest.mark.parametrize("height", [2.0, 10.0, 100.0])
def test_level_camera_sees_the_horizon_dip_below_the_principal_point_row(height):
    cam = PinholeCamera(fx=1200.0, fy=1100.0, cx=950.0, cy=530.0, image_size=(1920, 1080))
    line = horizon_line(cam, height)
    dip = math.acos((R_EARTH / 0.86) / (R_EARTH / 0.86 + height))
    np.testing.assert_allclose(
        line.v_at([0.0, cam.cx, 1919.0]) - cam.cy, cam.fy * math.tan(dip), rtol=1e-6
    )


def test_horizon_line_holds_the_boresight_horizon_point_and_the_horizontal_cross_direction():
    cam = IDEAL.with_attitude(heading=2.0, pitch=math.radians(-4.0), roll=math.radians(7.0))
    line = horizon_line(cam)
    dip = float(horizon_dip(cam.height))
    # the visible horizon towards the boresight azimuth: depression = dip
    p = cam.angles_to_pixel(2.0, -dip)
    assert abs(line.coefficients @ [p[0], p[1], 1.0]) < 1e-9
    # the vanishing point of the horizontal direction across the boresight (az + 90 deg)
    right_n = np.array([math.cos(2.0 + math.pi / 2), math.sin(2.0 + math.pi / 2), 0.0])
    vp = cam.K @ cam.R_nc.T @ right_n
    assert abs(line.coefficients @ vp) < 1e-9 * np.linalg.norm(vp)


def test_off_axis_the_true_horizon_lies_below_the_line():
    cam = IDEAL.with_attitude(pitch=math.radians(-2.0))
    line = horizon_line(cam)
    dip = float(horizon_dip(cam.height))
    for az in (-0.5, 0.5):
        u, v = cam.angles_to_pixel(az, -dip)
        assert v > line.v_at(u)


def test_positive_roll_raises_the_right_end_of_the_horizon():
    ends = horizon_line(IDEAL.with_attitude(roll=math.radians(10.0))).endpoints(1920)
    assert ends[1, 1] < ends[0, 1]
    slope = (ends[0, 1] - ends[1, 1]) / (ends[1, 0] - ends[0, 0])
    assert slope == pytest.approx(math.tan(math.radians(10.0)), rel=1e-3)


# ---------------------------------------------------------------- round trips
@given(
    heading=st.floats(-math.pi, math.pi),
    pitch=st.floats(-20.0, 20.0),
    roll=st.floats(-30.0, 30.0),
    height=st.floats(2.0, 100.0),
)
def test_attitude_from_horizon_inverts_horizon_line(heading, pitch, roll, height):
    cam = IDEAL.with_attitude(heading, math.radians(pitch), math.radians(roll))
    line = horizon_line(cam, height)
    for given_line in (line, line.endpoints(1920), np.array([line.rho, line.theta])):
        att = attitude_from_horizon(cam, given_line, height)
        assert abs(att.pitch - math.radians(pitch)) < 1e-9
        assert abs(att.roll - math.radians(roll)) < 1e-9
        assert att.dip == pytest.approx(float(horizon_dip(height)), rel=1e-15)


@given(pitch=st.floats(-20.0, 20.0), roll=st.floats(-30.0, 30.0), height=st.floats(2.0, 100.0))
def test_attitude_from_horizon_undistorts_observed_points(pitch, roll, height):
    cam = DISTORTED.with_attitude(pitch=math.radians(pitch), roll=math.radians(roll))
    line = horizon_line(cam, height)
    observed = cam.distort(line.endpoints(640))  # the line as seen in the raw image
    att = attitude_from_horizon(cam, observed, height)
    assert abs(att.pitch - math.radians(pitch)) < 1e-9
    assert abs(att.roll - math.radians(roll)) < 1e-9


def test_attitude_from_horizon_is_batched_and_nan_lines_give_nan():
    pitches = np.radians([-10.0, 0.0, 5.0])
    rolls = np.radians([3.0, -20.0, 0.0])
    pts = np.stack(
        [
            horizon_line(IDEAL.with_attitude(pitch=p, roll=r)).endpoints(1920)
            for p, r in zip(pitches, rolls, strict=True)
        ]
        + [np.full((2, 2), np.nan)]
    )
    att = attitude_from_horizon(IDEAL, pts)
    assert att.pitch.shape == att.roll.shape == (4,)
    np.testing.assert_allclose(att.pitch[:3], pitches, atol=1e-12)
    np.testing.assert_allclose(att.roll[:3], rolls, atol=1e-12)
    assert np.isnan(att.pitch[3]) and np.isnan(att.roll[3])
    two = attitude_from_horizon(IDEAL, np.array([[500.0, 1.5], [520.0, 1.6]]), form="rho_theta")
    assert two.pitch.shape == (2,)


def test_horizon_line_forms_agree_and_follow_the_hough_convention():
    line = HorizonLine.from_points([0.0, 500.0], [1919.0, 450.0])
    a, b, _ = line.coefficients
    assert a * a + b * b == pytest.approx(1.0) and b > 0 and 0 <= line.theta < math.pi
    other = HorizonLine.from_rho_theta(line.rho, line.theta)
    np.testing.assert_allclose(other.coefficients, line.coefficients, atol=1e-15)
    np.testing.assert_allclose(line.endpoints(1920), [[0.0, 500.0], [1919.0, 450.0]], atol=1e-9)


def test_bad_horizon_inputs_raise_value_error_naming_them():
    with pytest.raises(ValueError, match="line"):
        attitude_from_horizon(IDEAL, np.zeros(3))
    with pytest.raises(ValueError, match="form"):
        attitude_from_horizon(IDEAL, np.zeros((2, 2)), form="hough")
    with pytest.raises(ValueError, match="height"):
        horizon_line(PinholeCamera.from_fov(640, 480, 60.0))
    with pytest.raises(ValueError, match="height"):
        horizon_dip(-1.0)
    with pytest.raises(ValueError, match="refraction"):
        horizon_dip(5.0, refraction=1.0)
    with pytest.raises(ValueError, match="optical axis"):
        horizon_line(IDEAL.with_attitude(pitch=-math.pi / 2))
    with pytest.raises(ValueError, match="coefficients"):
        HorizonLine(np.zeros(2))
