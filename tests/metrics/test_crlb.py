"""Tests of the posterior Cramér–Rao bounds (ALGORITHMS.md §7, seawatch.metrics.crlb)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from seawatch.filters import KalmanFilter
from seawatch.metrics import crlb
from seawatch.models import constant_acceleration, constant_velocity, position_measurement


def _kalman_covariances(F, Q, Hs, Rs, P0):
    """Textbook KF covariance recursion (predict then update), written out here."""
    P = P0.copy()
    out = []
    for H, R in zip(Hs, Rs, strict=True):
        P = F @ P @ F.T + Q
        S = H @ P @ H.T + R
        K = P @ H.T @ np.linalg.inv(S)
        A = np.eye(P.shape[0]) - K @ H
        P = A @ P @ A.T + K @ R @ K.T
        out.append(P)
    return np.array(out)


def _dform_information(F, Q, H, R, J0, steps):
    """Tichavský's D-form (needs Q⁻¹), ALGORITHMS.md §7, for a full-rank Q."""
    Qi = np.linalg.inv(Q)
    D11 = F.T @ Qi @ F
    D12 = -F.T @ Qi
    D22 = Qi + H.T @ np.linalg.inv(R) @ H
    J = J0.copy()
    out = []
    for _ in range(steps):
        J = D22 - D12.T @ np.linalg.inv(J + D11) @ D12
        out.append(J)
    return np.array(out)


# ------------------------------------------------------------------ §7(b) linear-Gaussian
def test_linear_cv_bound_equals_kalman_filter_covariance_with_singular_dwna_q():
    F, Q = constant_velocity(2, 0.1, 0.7)  # DWNA: rank 2 of 4
    assert np.linalg.matrix_rank(Q) == 2
    H = position_measurement(2, 2)
    R = np.diag([4.0, 9.0])
    P0 = np.diag([100.0, 50.0, 4.0, 1.0])
    T = 300
    res = crlb.pcrb_linear(F, Q, H, R, P0, steps=T)
    rng = np.random.default_rng(1234)
    zs = rng.standard_normal((T, 2))
    kf = KalmanFilter(F, H, Q, R, np.zeros(4), P0).filter(zs)
    scale = np.max(np.abs(kf.covariances), axis=(1, 2), keepdims=True)
    assert np.max(np.abs(res.bound - kf.covariances) / scale) < 1e-10


def test_linear_bound_with_time_varying_h_and_r_equals_textbook_kalman_covariance():
    rng = np.random.default_rng(1234)
    F, Q = constant_acceleration(1, 0.05, 2.0)
    T = 120
    Hs = rng.standard_normal((T, 2, 3))
    A = rng.standard_normal((T, 2, 2))
    Rs = A @ np.swapaxes(A, -1, -2) + 0.1 * np.eye(2)
    P0 = np.diag([10.0, 5.0, 1.0])
    res = crlb.pcrb_linear(F, Q, Hs, Rs, P0)
    ref = _kalman_covariances(F, Q, Hs, Rs, P0)
    np.testing.assert_allclose(res.bound, ref, rtol=1e-9, atol=1e-12)


def test_singular_q_form_equals_tichavsky_d_form_when_q_is_full_rank():
    F, Q = constant_velocity(2, 0.2, 1.5, noise="continuous")  # CWNA: full rank
    H = position_measurement(2, 2)
    R = np.diag([2.0, 3.0])
    J0 = np.linalg.inv(np.diag([30.0, 30.0, 5.0, 5.0]))
    res = crlb.pcrb_linear(F, Q, H, R, J0=J0, steps=50)
    ref = _dform_information(F, Q, H, R, J0, 50)
    np.testing.assert_allclose(res.information, ref, rtol=1e-9)


def test_information_predict_equals_inverse_form_for_invertible_information():
    rng = np.random.default_rng(1234)
    F, Q = constant_velocity(2, 0.3, 0.4)
    for _ in range(5):
        A = rng.standard_normal((4, 4))
        J = A @ A.T + 0.5 * np.eye(4)
        ref = np.linalg.inv(Q + F @ np.linalg.inv(J) @ F.T)
        np.testing.assert_allclose(crlb.information_predict(J, F, Q), ref, rtol=1e-10)


def test_zero_q_gives_the_deterministic_form_of_section_7():
    F, _ = constant_velocity(1, 0.5, 1.0)
    H = np.array([[1.0, 0.0]])
    R = np.array([[4.0]])
    res = crlb.pcrb_linear(F, np.zeros((2, 2)), H, R, J0=np.zeros((2, 2)), steps=10)
    Fi = np.linalg.inv(F)
    J = np.zeros((2, 2))
    for k in range(10):
        J = Fi.T @ J @ Fi + H.T @ np.linalg.inv(R) @ H
        np.testing.assert_allclose(res.information[k], J, rtol=1e-12, atol=1e-15)


def test_diffuse_prior_is_the_limit_of_a_wide_proper_prior():
    F, Q = constant_velocity(1, 0.1, 0.5)
    H = np.array([[1.0, 0.0]])
    R = np.array([[0.25]])
    diffuse = crlb.pcrb_linear(F, Q, H, R, J0=np.zeros((2, 2)), steps=40)
    wide = crlb.pcrb_linear(F, Q, H, R, np.eye(2) * 1e10, steps=40)
    np.testing.assert_allclose(diffuse.bound[2:], wide.bound[2:], rtol=1e-6)


def test_unobserved_velocity_has_infinite_bound_and_position_the_measurement_noise():
    F, Q = constant_velocity(1, 0.1, 0.5)
    H = np.array([[1.0, 0.0]])
    res = crlb.pcrb_linear(F, Q, H, np.array([[0.25]]), J0=np.zeros((2, 2)), steps=3,
                           predict_first=False)  # fmt: skip
    assert np.isinf(res.bound[0, 1, 1])
    assert res.marginal(0)[0, 0, 0] == pytest.approx(0.25)
    assert np.all(np.isfinite(res.bound[1]))  # two positions pin down the velocity


def test_batch_least_squares_covariance_matches_recursion_for_a_static_straight_line():
    # NCV with Q = 0 and N equal-variance position fixes is linear regression of the
    # final [d, v] on the rows [1, -(N-1-j) T]: covariance σ² (AᵀA)⁻¹.
    T, sigma, N = 0.04, 3.0, 25
    res = crlb.air_range_pcrb(
        np.full(N, 2000.0), T, "ncv", 0.0, sigma_l=1.0, focal=2000.0**2 / sigma, size=1.0
    )
    A = np.stack([np.ones(N), -(N - 1 - np.arange(N)) * T], axis=1)
    np.testing.assert_allclose(res.bound[-1], sigma**2 * np.linalg.inv(A.T @ A), rtol=1e-9)


def test_air_range_information_is_inverse_size_range_variance():
    d = np.array([5000.0, 2500.0])
    res = crlb.air_range_pcrb(d, 0.04, "nca", 0.01, predict_first=False)
    sigma_d = d[0] ** 2 * 1.0 / (40_000.0 * 10.0)  # 62.5 m at 5 km (SCENARIOS.md)
    assert sigma_d == pytest.approx(62.5)
    assert res.information[0, 0, 0] == pytest.approx(1.0 / sigma_d**2)
    assert res.information.shape == (2, 3, 3)


def test_per_step_process_noise_equals_the_recursion_written_out():
    """Q (T, n, n): Q[k] drives the prediction into step k — against information_predict
    step by step, and a constant stack equals the single Q."""
    rng = np.random.default_rng(1234)
    d = rng.uniform(2000.0, 5000.0, 30)
    sig = rng.uniform(0.0, 0.5, 30)
    res = crlb.air_range_pcrb(d, 0.04, "nca", sig, predict_first=False)
    F, Q1 = constant_acceleration(1, 0.04, 1.0)
    J = np.zeros((3, 3))
    for k in range(d.size):
        if k:
            J = crlb.information_predict(J, F, sig[k] ** 2 * Q1)
        J = J + np.diag([(40_000.0 * 10.0 / d[k] ** 2) ** 2, 0.0, 0.0])
        np.testing.assert_allclose(res.information[k], J, rtol=1e-10, atol=1e-18)
    same = crlb.air_range_pcrb(d, 0.04, "nca", np.full(30, 0.3), predict_first=False)
    np.testing.assert_allclose(
        same.information,
        crlb.air_range_pcrb(d, 0.04, "nca", 0.3, predict_first=False).information,
        rtol=1e-12,
    )
    with pytest.raises(ValueError, match="sigma"):
        crlb.air_range_pcrb(d, 0.04, "nca", sig[:5])
    with pytest.raises(ValueError, match="Q"):
        crlb.pcrb_information(F, np.stack([Q1] * 4), np.zeros((5, 3, 3)), J0=np.zeros((3, 3)))


# ------------------------------------------------------------------ nonlinear measurement
def test_measurement_information_averages_over_sampled_trajectories():
    rng = np.random.default_rng(1234)
    H = rng.standard_normal((7, 5, 2, 4))
    R = np.diag([0.5, 2.0])
    info = crlb.measurement_information(H, R)
    ref = np.mean([[h.T @ np.linalg.inv(R) @ h for h in Hs] for Hs in H], axis=0)  # brute force
    np.testing.assert_allclose(info, ref, rtol=1e-12)


def test_nonlinear_bound_with_constant_jacobians_equals_linear_bound():
    F, Q = constant_velocity(2, 0.1, 0.3)
    H = position_measurement(2, 2)
    R = np.diag([1.0, 2.0])
    P0 = np.eye(4) * 50.0
    lin = crlb.pcrb_linear(F, Q, H, R, P0, steps=20)
    non = crlb.pcrb_nonlinear_measurement(F, Q, np.broadcast_to(H, (3, 20, 2, 4)), R, P0)
    np.testing.assert_allclose(non.information, lin.information, rtol=1e-12)


def _seed_angles(x, obs, psi, h):
    """Seed 000 eqs. 1–2 written out: α = atan2(p, r), β = atan2(h, k)."""
    ex, ey = x[0] - obs[0], x[1] - obs[1]
    p = -ex * math.sin(psi) + ey * math.cos(psi)
    r = ex * math.cos(psi) + ey * math.sin(psi)
    return np.array([math.atan2(p, r), math.atan2(h, math.hypot(ex, ey))])


def test_sea_surface_information_matches_finite_difference_fisher_information():
    x = np.array([400.0, 600.0, -3.0, -3.0])
    obs, psi, h = np.array([10.0, -5.0]), math.radians(50.0), 3.0
    sa, se = 2.6e-4, 4.5e-4
    Sp = np.diag([1.0, 0.5])
    eps = 1e-4
    Hx = np.zeros((2, 4))
    Gp = np.zeros((2, 2))
    for i in range(2):
        d = np.zeros(4)
        d[i] = eps
        Hx[:, i] = (_seed_angles(x + d, obs, psi, h) - _seed_angles(x - d, obs, psi, h)) / (2 * eps)
        Gp[:, i] = (_seed_angles(x, obs + d[:2], psi, h) - _seed_angles(x, obs - d[:2], psi, h)) / (
            2 * eps
        )
    R = np.diag([sa**2, se**2])
    # platform as a per-step nuisance: stack (x, n) with prior information Σp⁻¹ on n and
    # take the Schur complement (independent of the R_eff formula)
    A = np.hstack([Hx, Gp])
    full = A.T @ np.linalg.inv(R) @ A
    full[4:, 4:] += np.linalg.inv(Sp)
    ref = full[:4, :4] - full[:4, 4:] @ np.linalg.inv(full[4:, 4:]) @ full[4:, :4]
    info = crlb.sea_surface_angles_information(
        x[None, None], obs[None], psi, h, sa, se, observer_cov=Sp
    )
    np.testing.assert_allclose(info[0], ref, rtol=1e-6, atol=1e-12)
    known = crlb.sea_surface_angles_information(x[None, None], obs[None], psi, h, sa, se)
    np.testing.assert_allclose(known[0], Hx.T @ np.linalg.inv(R) @ Hx, rtol=1e-6, atol=1e-12)


def test_uav_sea_first_step_bound_is_the_single_measurement_geometry_bound():
    # one measurement, diffuse position prior, platform known: along the line of sight
    # the flat-sea range bound σ_β (d² + h²)/h, across it d σ_α (ALGORITHMS.md §7(a))
    sa, se, h = 0.88 * crlb.ARCMIN, 1.56 * crlb.ARCMIN, 3.0
    x = np.array([[400.0, 600.0, -2.98, -3.12]])
    res = crlb.uav_sea_pcrb(x, np.zeros((1, 2)), sigma_platform=None)
    P = res.marginal((0, 1))[0]
    d = math.hypot(400.0, 600.0)
    u = np.array([400.0, 600.0]) / d
    v = np.array([-u[1], u[0]])
    assert math.sqrt(u @ P @ u) == pytest.approx(
        float(crlb.flat_sea_range_bound(d, h, se)), rel=1e-9
    )
    assert math.sqrt(v @ P @ v) == pytest.approx(d * sa, rel=1e-9)


def test_uav_sea_bound_with_platform_noise_is_above_the_known_platform_bound():
    t = np.arange(713) * 0.1
    x = np.stack([400 - 2.98 * t, 600 - 3.12 * t, -2.98 + 0 * t, -3.12 + 0 * t], -1)
    obs = np.stack([2.55 * t, 4.33 * t], -1)
    noisy = crlb.uav_sea_pcrb(x, obs).rmse_bound((0, 1))
    known = crlb.uav_sea_pcrb(x, obs, sigma_platform=None).rmse_bound((0, 1))
    assert np.all(noisy >= known * (1 - 1e-12))
    assert noisy[-1] > 1.5 * known[-1]  # at 70 m the 1 m platform noise matters
    assert np.all(np.diff(noisy) < 0)  # information only grows on this approach


# ------------------------------------------------------------------ §7(a) static bounds
@pytest.mark.parametrize(
    ("d", "expected", "rel"), [(100.0, 0.25, 0.02), (500.0, 6.3, 0.01), (1000.0, 25.0, 1e-3),
                               (3000.0, 225.0, 1e-3)]
)  # fmt: skip
def test_flat_sea_range_bound_matches_the_spec_examples(d, expected, rel):
    assert float(crlb.flat_sea_range_bound(d, 10.0, 2.5e-4)) == pytest.approx(expected, rel=rel)


def test_flat_sea_range_bound_is_inverse_root_fisher_information_of_the_depression():
    d, h, s = np.array([50.0, 800.0, 4000.0]), 7.0, 3e-4
    eps = 1e-3
    slope = (np.arctan(h / (d + eps)) - np.arctan(h / (d - eps))) / (2 * eps)
    np.testing.assert_allclose(crlb.flat_sea_range_bound(d, h, s), s / np.abs(slope), rtol=1e-6)


def test_curved_sea_bound_exceeds_flat_and_is_infinite_at_the_horizon():
    h, s = 10.0, 2.5e-4
    Re = 6_371_000.0 / (1 - 0.14)
    horizon = math.sqrt(2 * Re * h)
    d = np.array([1000.0, 5000.0, 10_000.0])
    curved = crlb.curved_sea_range_bound(d, h, s)
    assert np.all(curved > crlb.flat_sea_range_bound(d, h, s) * 0.999)
    assert np.isinf(crlb.curved_sea_range_bound(horizon, h, s))


# ------------------------------------------------------------------ bad input
def test_bad_inputs_raise_value_errors_naming_the_argument():
    F, Q = constant_velocity(1, 0.1, 1.0)
    H = np.array([[1.0, 0.0]])
    R = np.array([[1.0]])
    with pytest.raises(ValueError, match="F"):
        crlb.pcrb_linear(np.ones((2, 3)), Q, H, R, np.eye(2), steps=3)
    with pytest.raises(ValueError, match="F"):
        crlb.pcrb_linear(np.zeros((2, 2)), Q, H, R, np.eye(2), steps=3)
    with pytest.raises(ValueError, match="Q"):
        crlb.pcrb_linear(F, -np.eye(2), H, R, np.eye(2), steps=3)
    with pytest.raises(ValueError, match="H"):
        crlb.pcrb_linear(F, Q, np.array([[np.nan, 0.0]]), R, np.eye(2), steps=3)
    with pytest.raises(ValueError, match="R"):
        crlb.pcrb_linear(F, Q, H, np.array([[0.0]]), np.eye(2), steps=3)
    with pytest.raises(ValueError, match="P0"):
        crlb.pcrb_linear(F, Q, H, R, np.eye(2), steps=3, J0=np.eye(2))
    with pytest.raises(ValueError, match="P0"):
        crlb.pcrb_linear(F, Q, H, R, steps=3)
    with pytest.raises(ValueError, match="P0"):
        crlb.pcrb_linear(F, Q, H, R, np.diag([1.0, -1.0]), steps=3)
    with pytest.raises(ValueError, match="steps"):
        crlb.pcrb_linear(F, Q, H, R, np.eye(2))
    with pytest.raises(ValueError, match="indices"):
        crlb.pcrb_linear(F, Q, H, R, np.eye(2), steps=2).marginal(5)
    with pytest.raises(ValueError, match="height"):
        crlb.flat_sea_range_bound(100.0, 0.0, 1e-3)
    with pytest.raises(ValueError, match="true_range"):
        crlb.air_range_pcrb([100.0, -5.0], 0.04)
    with pytest.raises(ValueError, match="model"):
        crlb.air_range_pcrb([100.0], 0.04, "ncj")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="observer"):
        crlb.sea_surface_angles_information(np.zeros((3, 4)), np.zeros((2, 2)), 0.0, 3.0, 1.0, 1.0)
