"""Tests of the sea-surface angle measurement model (ALGORITHMS.md §4.1, §4.2, §7(a))."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from seawatch.models.angles import (
    EARTH_RADIUS,
    LinearMeasurement,
    MeasurementModel,
    SeaSurfaceAngles,
    wrap_angle,
)

RE = EARTH_RADIUS / (1.0 - 0.14)  # §4.2 effective radius with k = 0.14


def _target(observer, rho, bearing, vx=1.0, vy=-2.0):
    """State [x_north, y_east, vx, vy] at horizontal distance rho and true bearing."""
    return np.array(
        [observer[0] + rho * math.cos(bearing), observer[1] + rho * math.sin(bearing), vx, vy]
    )


def _central_difference(model, x, step):
    """dh/dx by central differences (angle differences wrapped), shape (2, n)."""
    cols = []
    for j in range(x.size):
        e = np.zeros(x.size)
        e[j] = step
        cols.append(wrap_angle(model(x + e) - model(x - e)) / (2 * step))
    return np.stack(cols, axis=-1)


geometry = {
    "rho": st.floats(50.0, 10_000.0),
    "bearing": st.floats(-math.pi, math.pi),
    "height": st.floats(2.0, 50.0),
    "heading": st.floats(-math.pi, math.pi),
    "ox": st.floats(-1000.0, 1000.0),
    "oy": st.floats(-1000.0, 1000.0),
    "curved": st.booleans(),
}


@given(**geometry)
def test_jacobian_matches_central_differences(rho, bearing, height, heading, ox, oy, curved):
    model = SeaSurfaceAngles(height, observer=(ox, oy), heading=heading, curved=curved)
    x = _target((ox, oy), rho, bearing)
    H = model.jacobian(x)
    H_fd = _central_difference(model, x, step=1e-4 * rho)
    assert H.shape == (2, 4)
    for row in range(2):
        scale = np.max(np.abs(H_fd[row]))
        np.testing.assert_allclose(H[row], H_fd[row], rtol=0, atol=1e-6 * scale)
    assert np.all(H[:, 2:] == 0.0)  # velocity columns are zero (§7(a))


@given(**geometry)
def test_jacobian_equals_section_7a_closed_forms_flat(
    rho, bearing, height, heading, ox, oy, curved
):
    if curved:
        return
    model = SeaSurfaceAngles(height, observer=(ox, oy), heading=heading)
    x = _target((ox, oy), rho, bearing)
    dx, dy = x[0] - ox, x[1] - oy
    r = math.hypot(dx, dy)
    g = height / (r * r + height * height)
    expected = np.array([[-dy / r**2, dx / r**2, 0, 0], [-g * dx / r, -g * dy / r, 0, 0]])
    np.testing.assert_allclose(model.jacobian(x), expected, rtol=1e-12, atol=1e-18)


@given(**geometry)
def test_flat_angles_invert_to_seed_000_eqs_3_to_5(rho, bearing, height, heading, ox, oy, curved):
    # seed 000 eqs. 3–5: d = h / tan(beta), x = x_o + d cos(alpha + psi), y = ...
    model = SeaSurfaceAngles(height, observer=(ox, oy), heading=heading)
    x = _target((ox, oy), rho, bearing)
    alpha, beta = model(x)
    d = height / math.tan(beta)
    assert d == pytest.approx(rho, rel=1e-11)
    assert ox + d * math.cos(alpha + heading) == pytest.approx(x[0], abs=1e-8 * rho)
    assert oy + d * math.sin(alpha + heading) == pytest.approx(x[1], abs=1e-8 * rho)
    assert -math.pi < alpha <= math.pi


def test_azimuth_is_wrapped_to_half_open_interval_at_plus_minus_pi():
    model = SeaSurfaceAngles(10.0)
    deg = math.radians
    az_plus = model(_target((0, 0), 1000.0, deg(179.9)))[0]
    az_minus = model(_target((0, 0), 1000.0, deg(-179.9)))[0]
    assert az_plus == pytest.approx(deg(179.9), abs=1e-12)
    assert az_minus == pytest.approx(deg(-179.9), abs=1e-12)
    # due South is +pi exactly (the interval is (-pi, pi]), also for a -0.0 East offset
    assert model(np.array([-1000.0, 0.0]))[0] == math.pi
    assert model(np.array([-1000.0, -0.0]))[0] == math.pi
    # relative to a heading of 170 deg, a target at -170 deg is 20 deg to the right
    rel = model.at(heading=deg(170.0))(_target((0, 0), 1000.0, deg(-170.0)))[0]
    assert rel == pytest.approx(deg(20.0), abs=1e-12)


def test_wrap_angle_maps_into_minus_pi_pi_and_keeps_the_angle():
    a = np.linspace(-20.0, 20.0, 4001)
    w = wrap_angle(a)
    assert np.all(w > -math.pi) and np.all(w <= math.pi)
    np.testing.assert_allclose(np.cos(w), np.cos(a), atol=1e-12)
    np.testing.assert_allclose(np.sin(w), np.sin(a), atol=1e-12)
    assert wrap_angle(-math.pi) == math.pi and wrap_angle(math.pi) == math.pi


@given(rho=st.floats(50.0, 500.0), height=st.floats(2.0, 50.0))
def test_curved_depression_reduces_to_flat_at_short_range(rho, height):
    flat = SeaSurfaceAngles(height)(np.array([rho, 0.0]))[1]
    curved = SeaSurfaceAngles(height, curved=True)(np.array([rho, 0.0]))[1]
    # curvature adds D/(2 R_e) to the tangent h/D; through atan that is
    # (D/(2 R_e)) / (1 + h^2/D^2) to first order — at most 3.4e-5 rad here
    first_order = rho / (2 * RE) * rho**2 / (rho**2 + height**2)
    assert 0.0 < curved - flat < 4e-5
    assert curved - flat == pytest.approx(first_order, rel=1e-3)


@given(frac=st.floats(0.01, 0.95), height=st.floats(2.0, 50.0))
def test_curved_depression_matches_section_4_2_closed_forms(frac, height):
    D_hor = math.sqrt(2 * RE * height)
    D = frac * D_hor
    delta = SeaSurfaceAngles(height, curved=True)(np.array([0.0, D]))[1]
    # exact ray–sphere range of §4.2 recovers D (the model is its exact inverse)
    C = RE + height
    disc = C**2 * math.sin(delta) ** 2 - (2 * RE * height + height**2)
    s = C * math.sin(delta) - math.sqrt(disc)
    phi = math.atan2(s * math.cos(delta), C - s * math.sin(delta))
    assert RE * phi == pytest.approx(D, rel=1e-7)
    # small-angle forward form delta ≈ h/D + D/(2 R_e) and its inverse (§4.2, < 0.1 %)
    if delta < math.radians(1.0):
        assert delta == pytest.approx(height / D + D / (2 * RE), rel=1e-3)
        D_closed = RE * (delta - math.sqrt(delta**2 - 2 * height / RE))
        assert D_closed == pytest.approx(D, rel=1e-3)


@given(height=st.floats(2.0, 50.0))
def test_curved_depression_at_the_horizon_equals_the_dip(height):
    # the tangent point lies at central angle dip = arccos(R_e / (R_e + h)) (§4.2),
    # and the line of sight to it is depressed by exactly that angle
    dip = math.acos(RE / (RE + height))
    delta = SeaSurfaceAngles(height, curved=True)(np.array([RE * dip, 0.0]))[1]
    assert delta == pytest.approx(dip, rel=1e-8)
    assert dip == pytest.approx(math.sqrt(2 * height / RE), rel=1e-3)


@given(frac=st.floats(0.05, 0.8), height=st.floats(2.0, 50.0))
def test_curved_jacobian_matches_section_7a_spherical_form(frac, height):
    rho = max(frac * math.sqrt(2 * RE * height), 20 * height)  # h/rho <= 5 %
    H = SeaSurfaceAngles(height, curved=True).jacobian(np.array([rho, 0.0, 0.0, 0.0]))
    approx = -(height / rho**2 - 1 / (2 * RE))  # §7(a): d beta / d rho, spherical
    assert H[1, 0] == pytest.approx(approx, rel=0.01)


def test_observer_batch_broadcasts_against_states_and_sigma_points():
    rng = np.random.default_rng(1234)
    observers = rng.uniform(-100, 100, (5, 2))
    headings = rng.uniform(-3, 3, 5)
    heights = rng.uniform(2, 50, 5)
    model = SeaSurfaceAngles(heights, observer=observers, heading=headings, curved=True)
    x = rng.uniform(-3000, 3000, (5, 4))
    sigma = rng.uniform(-3000, 3000, (9, 5, 4))  # (2n+1, B, n)
    z, H = model(x), model.jacobian(x)
    zs, Hs = model(sigma), model.jacobian(sigma)
    assert z.shape == (5, 2) and H.shape == (5, 2, 4)
    assert zs.shape == (9, 5, 2) and Hs.shape == (9, 5, 2, 4)
    for b in range(5):
        single = SeaSurfaceAngles(
            heights[b], observer=observers[b], heading=headings[b], curved=True
        )
        np.testing.assert_array_equal(z[b], single(x[b]))
        np.testing.assert_array_equal(H[b], single.jacobian(x[b]))
        np.testing.assert_array_equal(zs[:, b], single(sigma[:, b]))


def test_at_returns_a_moved_model_and_leaves_the_original_unchanged():
    model = SeaSurfaceAngles(10.0, observer=(0.0, 0.0), heading=0.0)
    moved = model.at((100.0, 0.0), heading=math.pi / 2)
    x = np.array([100.0, 500.0, 0.0, 0.0])
    assert moved(x)[0] == pytest.approx(0.0, abs=1e-15)  # due East = along the heading
    assert moved(x)[1] == pytest.approx(math.atan2(10.0, 500.0))
    assert model(x)[0] == pytest.approx(math.atan2(500.0, 100.0))
    assert moved.height == 10.0 and moved.curved is False
    assert np.array_equal(model.observer, [0.0, 0.0])


def test_models_satisfy_the_measurement_protocol_and_flag_angles():
    sea = SeaSurfaceAngles(5.0)
    lin = LinearMeasurement(np.eye(2, 4))
    assert isinstance(sea, MeasurementModel) and isinstance(lin, MeasurementModel)
    assert sea.angular == (True, True) and sea.dim_z == 2
    assert lin.angular == (False, False) and lin.dim_z == 2
    assert LinearMeasurement(np.eye(2, 4), angular=(True, False)).angular == (True, False)
    assert sea.effective_radius == pytest.approx(RE)


def test_linear_measurement_is_h_x_with_constant_jacobian():
    rng = np.random.default_rng(1234)
    H = rng.normal(size=(3, 5))
    lin = LinearMeasurement(H)
    x = rng.normal(size=(7, 5))
    np.testing.assert_allclose(lin(x), np.array([H @ xi for xi in x]), rtol=1e-13)
    assert lin.jacobian(x).shape == (7, 3, 5)
    np.testing.assert_array_equal(lin.jacobian(x)[3], H)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"height": 0.0}, "height"),
        ({"height": -3.0}, "height"),
        ({"height": math.nan}, "height"),
        ({"height": [5.0, -1.0]}, "height"),
        ({"height": 5.0, "observer": (1.0, 2.0, 3.0)}, "observer"),
        ({"height": 5.0, "observer": (1.0, math.inf)}, "observer"),
        ({"height": 5.0, "heading": math.nan}, "heading"),
        ({"height": 5.0, "refraction": 1.0}, "refraction"),
        ({"height": 5.0, "refraction": -0.1}, "refraction"),
        ({"height": 5.0, "curved": "yes"}, "curved"),
        ({"height": 5.0, "earth_radius": 0.0}, "earth_radius"),
    ],
)
def test_bad_configuration_raises_value_error_naming_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=name):
        SeaSurfaceAngles(**kwargs)


def test_bad_state_and_linear_model_shapes_raise_value_error():
    with pytest.raises(ValueError, match="x"):
        SeaSurfaceAngles(5.0)(np.array([1.0]))
    with pytest.raises(ValueError, match="x"):
        SeaSurfaceAngles(5.0).jacobian(np.float64(3.0))
    with pytest.raises(ValueError, match="H"):
        LinearMeasurement(np.ones(3))
    with pytest.raises(ValueError, match="H"):
        LinearMeasurement(np.array([[1.0, np.nan]]))
    with pytest.raises(ValueError, match="angular"):
        LinearMeasurement(np.eye(2), angular=(True,))
    with pytest.raises(ValueError, match="x"):
        LinearMeasurement(np.eye(2, 4))(np.ones(3))
