"""Sea-surface ranging (ALGORITHMS.md §4.1, §4.2, §7(a); seed 000 eqs. 3–5).

Independent truths: the sea-surface measurement model of ``seawatch.models.angles``
(written separately, forward direction), explicit circle geometry, the closed forms and
worked examples of the spec, finite differences and Monte Carlo.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from seawatch.geometry.sea import (
    EARTH_RADIUS,
    RangeFlag,
    curved_sea_range,
    effective_radius,
    flat_error_limit,
    flat_sea_range,
    horizon_dip,
    horizon_distance,
    range_sigma,
    sea_depression,
    sea_position,
    sea_position_covariance,
    sea_range,
)
from seawatch.models.angles import SeaSurfaceAngles

RE = EARTH_RADIUS / (1.0 - 0.14)
ARCMIN = math.radians(1.0 / 60.0)

heights = st.floats(0.5, 500.0)


def _curved_depression_by_circle(D: float, h: float, Re: float) -> float:
    """Depression of a sea point at arc distance D, from plain circle geometry."""
    phi = D / Re
    cam = np.array([0.0, Re + h])
    target = np.array([Re * math.sin(phi), Re * math.cos(phi)])
    v = target - cam
    return math.atan2(-v[1], v[0])


# ----------------------------------------------------------------------------- flat
@given(d=st.floats(1.0, 1e5), h=heights)
def test_flat_range_inverts_the_flat_depression_angle(d: float, h: float) -> None:
    beta = math.atan2(h, d)
    assert flat_sea_range(beta, h) == pytest.approx(d, rel=1e-12)


def test_flat_range_is_h_over_tan_beta_seed000_eq5() -> None:
    beta = np.radians([1.0, 5.0, 30.0, 89.0])
    np.testing.assert_allclose(flat_sea_range(beta, 20.0), 20.0 / np.tan(beta), rtol=1e-14)


def test_flat_range_at_or_above_the_horizon_is_inf_never_negative() -> None:
    r = sea_range([-0.3, -1e-9, 0.0, 1e-3], 10.0)
    assert np.all(np.isinf(r.range[:3])) and np.all(r.range[:3] > 0)
    assert r.flag.tolist() == [RangeFlag.ABOVE_HORIZON] * 3 + [RangeFlag.OK]
    assert np.isfinite(r.range[3])


def test_nan_and_beyond_nadir_depressions_give_nan_rows_not_exceptions() -> None:
    for curved in (False, True):
        r = sea_range([np.nan, 0.01, 2.0, np.inf], 10.0, curved=curved)
        assert np.isnan(r.range[[0, 2, 3]]).all()
        assert r.flag.tolist() == [2, 0, 2, 2]
    r = sea_range(0.01, [10.0, np.nan])
    assert r.flag.tolist() == [0, 2] and np.isnan(r.range[1])


def test_bad_configuration_raises_value_error_naming_the_argument() -> None:
    with pytest.raises(ValueError, match="height"):
        flat_sea_range(0.01, -1.0)
    with pytest.raises(ValueError, match="height"):
        curved_sea_range(0.01, 0.0)
    with pytest.raises(ValueError, match="refraction"):
        curved_sea_range(0.01, 10.0, refraction=1.0)
    with pytest.raises(ValueError, match="sigma_depression"):
        range_sigma(0.01, 10.0, -1e-3)
    with pytest.raises(ValueError, match="tolerance"):
        flat_error_limit(10.0, tolerance=0.0)


def test_scalar_inputs_give_scalars_and_arrays_broadcast() -> None:
    assert np.ndim(flat_sea_range(0.01, 10.0)) == 0
    out = curved_sea_range(np.full((3, 1), 0.01), np.array([5.0, 10.0]))
    assert out.shape == (3, 2)


# ----------------------------------------------------------------------------- curved
@given(h=heights, frac=st.floats(1e-4, 0.95))
def test_curved_range_inverts_the_independent_sea_surface_model(h: float, frac: float) -> None:
    D = frac * math.sqrt(2.0 * RE * h)
    model = SeaSurfaceAngles(height=h, curved=True, refraction=0.14)
    delta = model(np.array([D, 0.0]))[1]
    assert curved_sea_range(delta, h) == pytest.approx(D, rel=1e-7)


@given(h=heights, frac=st.floats(1e-4, 0.99), k=st.floats(0.0, 0.2))
def test_curved_range_matches_plain_circle_geometry(h: float, frac: float, k: float) -> None:
    Re = EARTH_RADIUS / (1.0 - k)
    D = frac * math.sqrt(2.0 * Re * h)
    delta = _curved_depression_by_circle(D, h, Re)
    assert curved_sea_range(delta, h, refraction=k) == pytest.approx(D, rel=1e-6)
    assert sea_depression(D, h, curved=True, refraction=k) == pytest.approx(delta, rel=1e-9)


@given(h=heights, delta_deg=st.floats(0.01, 1.0))
def test_curved_range_agrees_with_the_small_angle_form_within_0_1_percent(
    h: float, delta_deg: float
) -> None:
    delta = math.radians(delta_deg)
    disc = delta * delta - 2.0 * h / RE
    if disc <= 0.0:
        assert math.isinf(curved_sea_range(delta, h))
        return
    approx = RE * (delta - math.sqrt(disc))
    assert curved_sea_range(delta, h) == pytest.approx(approx, rel=1e-3)


def test_curved_range_approaches_flat_range_at_short_distance() -> None:
    beta = math.atan2(10.0, 100.0)
    assert curved_sea_range(beta, 10.0) == pytest.approx(flat_sea_range(beta, 10.0), rel=1e-4)


def test_spec_example_flat_model_errors_at_5_m_height() -> None:
    # ALGORITHMS.md §4.2: h = 5 m, true 3 km -> flat 2.68 km; true 6 km -> flat 4.04 km.
    delta = [sea_depression(D, 5.0, curved=True) for D in (3000.0, 6000.0)]
    assert flat_sea_range(delta[0], 5.0) == pytest.approx(2680.0, abs=10.0)
    assert flat_sea_range(delta[1], 5.0) == pytest.approx(4040.0, abs=10.0)


def test_spec_example_visible_horizon_reference_pitfall_gives_43_percent() -> None:
    # §4.1 pitfall: h = 10 m, 2 km: beta ≈ 5.1 mrad, dip ≈ 1.6 mrad, flat on (beta - dip) ≈ 2.9 km.
    beta = sea_depression(2000.0, 10.0, curved=True)
    dip = horizon_dip(10.0)
    assert beta == pytest.approx(5.1e-3, abs=0.05e-3)
    assert dip == pytest.approx(1.6e-3, abs=0.05e-3)
    wrong = flat_sea_range(beta - dip, 10.0)
    assert wrong / 2000.0 - 1.0 == pytest.approx(0.43, abs=0.02)


def test_horizon_dip_and_distance_match_the_navigation_rules_of_thumb() -> None:
    h = np.array([1.0, 5.0, 25.0])
    # geometric dip 1.93' sqrt(h); apparent (almanac, k ≈ 0.165) 1.76' sqrt(h)
    np.testing.assert_allclose(horizon_dip(h, 0.0) / ARCMIN, 1.93 * np.sqrt(h), rtol=5e-3)
    np.testing.assert_allclose(horizon_dip(h, 0.165) / ARCMIN, 1.76 * np.sqrt(h), rtol=5e-3)
    # horizon distance about 2.08 sqrt(h) nmi with k = 0.14; h = 5 m: 0.0666 deg, 8.6 km
    np.testing.assert_allclose(horizon_distance(h) / 1852.0, 2.08 * np.sqrt(h), rtol=5e-3)
    assert math.degrees(horizon_dip(5.0)) == pytest.approx(0.0666, abs=1e-4)
    assert horizon_distance(5.0) == pytest.approx(8600.0, rel=5e-3)
    # exact identities: cos(dip) = R_e / (R_e + h)
    np.testing.assert_allclose(np.cos(horizon_dip(h)), RE / (RE + h), rtol=1e-15)


def test_curved_range_is_inf_above_the_dip_and_the_horizon_just_below() -> None:
    h = 20.0
    dip = horizon_dip(h)
    r = sea_range([dip * (1 - 1e-6), dip * (1 + 1e-9), 0.0, -0.1], h, curved=True)
    assert r.flag.tolist() == [1, 0, 1, 1]
    assert math.isinf(r.range[0])
    # at the dip the ray grazes the sea at the horizon: arc length R_e * dip
    assert r.range[1] == pytest.approx(RE * dip, rel=1e-3)
    assert r.range[1] == pytest.approx(horizon_distance(h), rel=1e-3)


def test_effective_radius_is_r_over_one_minus_k() -> None:
    assert effective_radius(0.14) == pytest.approx(6_371_000.0 / 0.86, rel=1e-15)
    assert effective_radius(0.0) == EARTH_RADIUS


# ----------------------------------------------------------------------------- limit
@pytest.mark.parametrize("h", [2.0, 5.0, 10.0, 50.0, 100.0])
def test_flat_error_limit_is_where_the_flat_error_reaches_one_percent(h: float) -> None:
    D = float(flat_error_limit(h))
    model = SeaSurfaceAngles(height=h, curved=True)
    for factor, want in ((1.0, 0.01), (0.9, None), (1.1, None)):
        delta = model(np.array([factor * D, 0.0]))[1]
        err = 1.0 - flat_sea_range(delta, h) / (factor * D)
        if want is not None:
            assert err == pytest.approx(want, rel=1e-6)
        elif factor < 1:
            assert err < 0.01
        else:
            assert err > 0.01
    # first order: D ≈ sqrt(2 R_e h tol / (1 - tol)), a tenth of the horizon distance
    assert D == pytest.approx(math.sqrt(2 * RE * h * 0.01 / 0.99), rel=1e-4)


def test_flat_error_limit_is_vectorised_and_handles_nan_and_large_tolerances() -> None:
    out = flat_error_limit(np.array([5.0, np.nan]))
    assert np.isfinite(out[0]) and np.isnan(out[1])
    assert math.isinf(flat_error_limit(5.0, tolerance=0.6))
    assert flat_error_limit(5.0, tolerance=0.05) > flat_error_limit(5.0, tolerance=0.01)


# ----------------------------------------------------------------------------- positions
@given(
    north=st.floats(-5000, 5000),
    east=st.floats(-5000, 5000),
    heading=st.floats(-math.pi, math.pi),
    h=st.floats(2.0, 200.0),
    curved=st.booleans(),
)
def test_sea_position_recovers_the_target_from_its_angles(
    north: float, east: float, heading: float, h: float, curved: bool
) -> None:
    obs = np.array([120.0, -40.0])
    target = obs + np.array([north, east])
    if math.hypot(north, east) < 1.0:
        return
    model = SeaSurfaceAngles(height=h, observer=obs, heading=heading, curved=curved)
    alpha, beta = model(target)
    pos = sea_position(obs, heading, alpha, beta, h, curved=curved)
    assert pos.flag == RangeFlag.OK
    np.testing.assert_allclose(pos.xy, target, rtol=0, atol=1e-6 * math.hypot(north, east) + 1e-9)
    assert pos.range == pytest.approx(math.hypot(north, east), rel=1e-7)


def test_sea_position_seed000_eqs_3_4_north_east_convention() -> None:
    # heading East (90°), target 30° to the right -> bearing 120°, flat range 100 m
    h = 10.0
    beta = math.atan2(h, 100.0)
    pos = sea_position([0.0, 0.0], math.radians(90), math.radians(30), beta, h)
    np.testing.assert_allclose(
        pos.xy, [100 * math.cos(math.radians(120)), 100 * math.sin(math.radians(120))], atol=1e-9
    )
    assert pos.bearing == pytest.approx(math.radians(120))


def test_sea_position_flags_rows_in_a_batch_without_raising() -> None:
    pos = sea_position(
        np.array([[0.0, 0.0], [0.0, 0.0], [np.nan, 0.0], [0.0, 0.0]]),
        0.0,
        np.array([0.1, 0.1, 0.1, np.nan]),
        np.array([-0.01, 0.01, 0.01, 0.01]),
        10.0,
    )
    assert pos.flag.tolist() == [1, 0, 2, 2]
    assert math.isinf(pos.range[0]) and np.isnan(pos.xy[0]).all()
    assert np.isfinite(pos.xy[1]).all()
    assert np.isnan(pos.xy[2:]).all() and np.isnan(pos.range[2:]).all()
    assert pos.ok.tolist() == [False, True, False, False]


def test_sea_position_rejects_a_bad_observer_shape() -> None:
    with pytest.raises(ValueError, match="observer_xy"):
        sea_position([0.0, 0.0, 0.0], 0.0, 0.0, 0.01, 10.0)


# ----------------------------------------------------------------------------- sigma
def test_flat_range_sigma_is_the_section_7a_bound_with_its_worked_example() -> None:
    # h = 10 m, sigma_beta = 2.5e-4 rad: 0.25 m at 100 m, 6.3 m at 500 m, 25 m at 1 km,
    # 225 m at 3 km (ALGORITHMS.md §7(a))
    d = np.array([100.0, 500.0, 1000.0, 3000.0])
    h = 10.0
    beta = np.arctan2(h, d)
    sig = range_sigma(beta, h, 2.5e-4)
    np.testing.assert_allclose(sig, 2.5e-4 * (d**2 + h**2) / h, rtol=1e-12)
    np.testing.assert_allclose(sig, [0.25, 6.3, 25.0, 225.0], rtol=0.02)


@given(h=st.floats(2.0, 100.0), frac=st.floats(0.01, 0.8), curved=st.booleans())
def test_range_sigma_matches_finite_differences_of_the_range(
    h: float, frac: float, curved: bool
) -> None:
    D = frac * math.sqrt(2 * RE * h)
    beta = float(sea_depression(D, h, curved=curved))
    eps = beta * 1e-6
    num_b = (sea_range(beta + eps, h, curved).range - sea_range(beta - eps, h, curved).range) / (
        2 * eps
    )
    dh = h * 1e-6
    num_h = (sea_range(beta, h + dh, curved).range - sea_range(beta, h - dh, curved).range) / (
        2 * dh
    )
    sb, sh = 1e-4, 0.3
    want = math.hypot(num_b * sb, num_h * sh)
    assert range_sigma(beta, h, sb, sh, curved=curved) == pytest.approx(want, rel=1e-4)


def test_curved_range_sigma_follows_the_spec_sensitivity_and_diverges_at_the_horizon() -> None:
    h, sb = 10.0, 1e-4
    for D in (500.0, 2000.0, 5000.0):
        beta = sea_depression(D, h, curved=True)
        approx = sb / abs(h / D**2 - 1 / (2 * RE))
        assert range_sigma(beta, h, sb, curved=True) == pytest.approx(approx, rel=0.01)
    near = sea_depression(0.999 * RE * horizon_dip(h), h, curved=True)
    assert range_sigma(near, h, sb, curved=True) > 1e5
    assert math.isinf(range_sigma(-0.01, h, sb, curved=True))
    assert np.isnan(range_sigma(np.nan, h, sb))


def test_flat_height_error_gives_relative_range_error_sigma_h_over_h() -> None:
    d, h = 800.0, 12.0
    beta = math.atan2(h, d)
    assert range_sigma(beta, h, 0.0, 0.6) / d == pytest.approx(0.6 / h, rel=1e-12)


def test_position_covariance_matches_monte_carlo() -> None:
    rng = np.random.default_rng(1234)
    h, heading, alpha = 15.0, math.radians(40.0), math.radians(-25.0)
    beta = math.atan2(h, 1500.0)
    s_a, s_b, s_h = 2e-3, 1e-4, 0.2
    cov = sea_position_covariance(heading, alpha, beta, h, s_a, s_b, s_h, curved=True)
    n = 100_000
    pos = sea_position(
        [0.0, 0.0],
        heading,
        alpha + s_a * rng.standard_normal(n),
        beta + s_b * rng.standard_normal(n),
        h + s_h * rng.standard_normal(n),
        curved=True,
    )
    emp = np.cov(pos.xy.T)
    np.testing.assert_allclose(np.sqrt(np.diag(emp)), np.sqrt(np.diag(cov)), rtol=0.05)
    corr_emp = emp[0, 1] / math.sqrt(emp[0, 0] * emp[1, 1])
    corr = cov[0, 1] / math.sqrt(cov[0, 0] * cov[1, 1])
    assert corr_emp == pytest.approx(corr, abs=0.03)


def test_position_covariance_is_symmetric_psd_and_adds_the_observer_covariance() -> None:
    alpha = np.linspace(-1, 1, 7)
    cov = sea_position_covariance(0.3, alpha, 0.01, 10.0, 1e-3, 1e-4)
    assert cov.shape == (7, 2, 2)
    np.testing.assert_array_equal(cov, np.swapaxes(cov, -1, -2))
    assert np.all(np.linalg.eigvalsh(cov) >= 0)
    plus = sea_position_covariance(
        0.3, alpha, 0.01, 10.0, 1e-3, 1e-4, observer_covariance=4.0 * np.eye(2)
    )
    np.testing.assert_allclose(plus - cov, np.broadcast_to(4.0 * np.eye(2), cov.shape), atol=1e-9)
    # the trace is rotation invariant: sigma_D^2 + D^2 sigma_theta^2
    D = flat_sea_range(0.01, 10.0)
    want = range_sigma(0.01, 10.0, 1e-4) ** 2 + D**2 * 1e-6
    np.testing.assert_allclose(np.trace(cov, axis1=-2, axis2=-1), want, rtol=1e-12)


def test_position_covariance_is_nan_for_flagged_rows() -> None:
    cov = sea_position_covariance(0.0, 0.0, np.array([0.01, -0.01, np.nan]), 10.0, 1e-3, 1e-4)
    assert np.isfinite(cov[0]).all() and np.isnan(cov[1:]).all()
    with pytest.raises(ValueError, match="observer_covariance"):
        sea_position_covariance(0.0, 0.0, 0.01, 10.0, 1e-3, 1e-4, observer_covariance=np.ones(3))
