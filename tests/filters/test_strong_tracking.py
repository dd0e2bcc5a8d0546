"""Tests of the Strong Tracking Kalman Filter (ALGORITHMS.md §2)."""

from __future__ import annotations

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter as FilterPyKF

from seawatch.filters.kalman import KalmanFilter
from seawatch.filters.strong_tracking import StrongTrackingKalmanFilter, StrongTrackingResult
from seawatch.models.kinematic import constant_velocity, position_measurement


def cv_model(dim: int = 2, dt: float = 1.0, sigma_a: float = 0.1, sigma_z: float = 2.0):
    F, Q = constant_velocity(dim, dt, sigma_a)
    H = position_measurement(dim, 2)
    R = sigma_z**2 * np.eye(dim)
    return F, H, Q, R


def reference_stkf(F, H, Q, R, x0, P0, zs, beta, rho, lam_max, late=False):
    """Plain-numpy transcription of ALGORITHMS.md §2 steps 1–6 (one track).

    Returns posterior states and covariances, the applied factors, the faded priors and
    the factors computed from each step's own innovation (1 where z is missing).
    """
    x, P = np.array(x0, float), np.array(P0, float)
    V = None
    lam_next = 1.0
    xs, Ps, applied, Pps, computed = [], [], [], [], []
    for z in zs:
        x_minus = F @ x
        FPF = F @ P @ F.T
        if np.any(np.isnan(z)):
            lam = lam_applied = lam_next = 1.0
            P_minus = FPF + Q
            x, P = x_minus, P_minus
        else:
            nu = z - H @ x_minus
            V = np.outer(nu, nu) if V is None else (rho * V + np.outer(nu, nu)) / (1 + rho)
            N = V - H @ Q @ H.T - beta * R
            M = H @ FPF @ H.T
            lam = min(max(1.0, np.trace(N) / np.trace(M)), lam_max)
            if late:
                lam_applied, lam_next = lam_next, lam
            else:
                lam_applied = lam
            P_minus = lam_applied * FPF + Q
            S = H @ P_minus @ H.T + R
            K = P_minus @ H.T @ np.linalg.inv(S)
            x = x_minus + K @ nu
            IKH = np.eye(len(x)) - K @ H
            P = IKH @ P_minus @ IKH.T + K @ R @ K.T
        xs.append(x)
        Ps.append(P)
        applied.append(lam_applied)
        Pps.append(P_minus)
        computed.append(lam)
    return np.array(xs), np.array(Ps), np.array(applied), np.array(Pps), np.array(computed)


def test_huge_beta_keeps_lambda_one_and_equals_filterpy_kalman_filter_step_by_step():
    F, H, Q, R = cv_model()
    x0 = np.array([10.0, -5.0, 1.0, 0.5])
    P0 = np.diag([4.0, 4.0, 9.0, 9.0])
    rng = np.random.default_rng(1234)
    zs = np.cumsum(rng.normal(size=(200, 2)), axis=0) + rng.normal(scale=2.0, size=(200, 2))
    stkf = StrongTrackingKalmanFilter(F, H, Q, R, x0, P0, beta=1e12)
    ref = FilterPyKF(dim_x=4, dim_z=2)
    ref.F, ref.H, ref.Q, ref.R = F, H, Q, R
    ref.x, ref.P = x0.copy(), P0.copy()
    for z in zs:
        stkf.predict()
        ref.predict()
        stkf.update(z)
        ref.update(z)
        assert stkf.fading_factor == 1.0
        np.testing.assert_allclose(stkf.x, ref.x, rtol=1e-12, atol=1e-10)
        np.testing.assert_allclose(stkf.P, ref.P, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(stkf.y, ref.y, rtol=1e-12, atol=1e-10)
        np.testing.assert_allclose(stkf.S, ref.S, rtol=1e-12)
    res = StrongTrackingKalmanFilter(F, H, Q, R, x0, P0, beta=1e12).filter(zs)
    np.testing.assert_allclose(res.states[-1], ref.x, rtol=1e-12, atol=1e-10)
    assert np.all(res.fading_factors == 1.0)


def test_fading_factor_matches_hand_computed_trace_ratio_in_scalar_model():
    q, r, beta, rho = 0.1, 0.5, 4.5, 0.95
    x0, P0 = 0.0, 1.0
    f = StrongTrackingKalmanFilter([[1.0]], [[1.0]], [[q]], [[r]], [x0], [[P0]])
    # step 1 (first step, V = nu^2): nu = 3, N = 9 - q - beta r = 6.65, M = F P0 F = 1
    f.step([3.0])
    lam1 = (9.0 - q - beta * r) / 1.0
    assert f.fading_factor == pytest.approx(lam1, rel=1e-14)
    Pm1 = lam1 * P0 + q  # the factor multiplies F P F^T only, not Q
    assert f.P_prior[0, 0] == pytest.approx(Pm1, rel=1e-14)
    K1 = Pm1 / (Pm1 + r)
    x1 = x0 + K1 * 3.0
    P1 = (1 - K1) ** 2 * Pm1 + K1**2 * r
    assert f.x[0] == pytest.approx(x1, rel=1e-14)
    assert f.P[0, 0] == pytest.approx(P1, rel=1e-13)
    # step 2: V = (rho V1 + nu^2) / (1 + rho), M = P1
    z2 = x1 + 2.5
    f.step([z2])
    V2 = (rho * 9.0 + 2.5**2) / (1 + rho)
    lam2 = max(1.0, (V2 - q - beta * r) / P1)
    assert lam2 > 1.0
    assert f.fading_factor == pytest.approx(lam2, rel=1e-13)
    assert f.P_prior[0, 0] == pytest.approx(lam2 * P1 + q, rel=1e-13)
    Pm2 = lam2 * P1 + q
    K2 = Pm2 / (Pm2 + r)
    x2 = z2 - 2.5 + K2 * 2.5
    P2 = (1 - K2) ** 2 * Pm2 + K2**2 * r
    assert f.x[0] == pytest.approx(x2, rel=1e-13)
    # step 3: innovation 0.5; V still remembers the large ones (effective memory ~2)
    f.step([x2 + 0.5])
    V3 = (rho * V2 + 0.5**2) / (1 + rho)
    assert f.fading_factor == pytest.approx(max(1.0, (V3 - q - beta * r) / P2), rel=1e-12)
    # a small first innovation gives tr N < 0, hence lambda = 1
    g = StrongTrackingKalmanFilter([[1.0]], [[1.0]], [[q]], [[r]], [x0], [[P0]])
    g.step([1.0])
    assert 1.0 - q - beta * r < 0 and g.fading_factor == 1.0
    assert g.P_prior[0, 0] == pytest.approx(P0 + q, rel=1e-15)


@pytest.mark.parametrize("late", [False, True])
def test_filter_equals_numpy_transcription_of_the_spec_including_missing_steps(late):
    F, H, Q, R = cv_model(dim=1, dt=0.04, sigma_a=0.05, sigma_z=0.3)
    x0, P0 = np.array([0.0, 1.5]), np.diag([1.0, 0.25])
    rng = np.random.default_rng(1234)
    T = 150
    speed = np.where(np.arange(T) < 60, 1.5, 3.0)
    zs = (np.cumsum(speed) * 0.04 + rng.normal(scale=0.3, size=T))[:, None]
    zs[[10, 61, 62, 100]] = np.nan
    res = StrongTrackingKalmanFilter(F, H, Q, R, x0, P0, late_fading=late).filter(zs)
    xs, Ps, lams, Pps, own = reference_stkf(F, H, Q, R, x0, P0, zs, 4.5, 0.95, 100.0, late)
    np.testing.assert_allclose(res.states, xs, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(res.covariances, Ps, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(res.fading_factors, lams, rtol=1e-12)
    np.testing.assert_allclose(res.predicted_covariances, Pps, rtol=1e-10, atol=1e-14)
    assert lams.max() > 1.5  # the manoeuvre at step 60 really triggers fading
    missing = np.isnan(zs[:, 0])
    assert np.all(res.fading_factors[missing] == 1.0)
    assert np.all(np.isnan(res.nis[missing])) and np.all(np.isfinite(res.states))
    if late:  # the factor computed from step k's innovation is applied at step k+1
        measured = ~missing[1:]
        np.testing.assert_allclose(res.fading_factors[1:][measured], own[:-1][measured])
        assert res.fading_factors[0] == 1.0
    else:
        np.testing.assert_allclose(res.fading_factors, own)


def test_stkf_recovers_from_a_velocity_jump_faster_than_the_plain_kalman_filter():
    rng = np.random.default_rng(1234)
    runs, T, jump, dt = 300, 160, 80, 1.0
    F, H, Q, R = cv_model(dim=1, dt=dt, sigma_a=0.02, sigma_z=1.0)
    x = np.zeros((runs, T, 2))
    x[:, 0] = [0.0, 1.0]
    for k in range(1, T):
        x[:, k] = x[:, k - 1] @ F.T
        if k == jump:
            x[:, k, 1] += 2.0  # abrupt manoeuvre: speed 1 -> 3 units per step
    zs = x[..., :1] + rng.normal(size=(runs, T, 1))
    x0, P0 = np.array([0.0, 1.0]), np.diag([1.0, 0.1])
    st = StrongTrackingKalmanFilter(F, H, Q, R, x0, P0).filter(zs)
    kf = KalmanFilter(F, H, Q, R, x0, P0).filter(zs)
    err_st = np.abs(st.states[..., 0] - x[..., 0])
    err_kf = np.abs(kf.states[..., 0] - x[..., 0])
    after = slice(jump, jump + 30)
    assert err_st[:, after].mean() < 0.5 * err_kf[:, after].mean()
    assert st.fading_factors[:, jump : jump + 5].mean() > 5.0
    # at steady state, before the jump, the STKF is hardly worse than the KF
    before = slice(40, jump)
    assert err_st[:, before].mean() < 1.2 * err_kf[:, before].mean()


def test_batched_filter_equals_looped_single_track_runs():
    F, H, Q, R = cv_model()
    rng = np.random.default_rng(1234)
    batch, T = (3, 2), 60
    x0 = rng.normal(size=(*batch, 4))
    P0 = np.diag([4.0, 4.0, 1.0, 1.0])
    zs = np.cumsum(rng.normal(scale=2.0, size=(*batch, T, 2)), axis=-2)
    zs[0, 1, 5] = np.nan
    res = StrongTrackingKalmanFilter(F, H, Q, R, x0, P0).filter(zs)
    assert isinstance(res, StrongTrackingResult)
    assert res.states.shape == (*batch, T, 4) and res.fading_factors.shape == (*batch, T)
    for i in range(batch[0]):
        for j in range(batch[1]):
            single = StrongTrackingKalmanFilter(F, H, Q, R, x0[i, j], P0)
            for k in range(T):
                single.step(zs[i, j, k])
                np.testing.assert_allclose(single.x, res.states[i, j, k], rtol=1e-13, atol=1e-12)
                assert single.fading_factor == res.fading_factors[i, j, k]
            np.testing.assert_allclose(single.P, res.covariances[i, j, -1], rtol=1e-13)


def test_one_initial_state_broadcasts_over_monte_carlo_runs_and_per_step_batch_matches():
    # 80 runs >= PARALLEL_MIN_TRACKS: filter() takes the multi-core kernel, the per-step
    # loop the serial one
    F, H, Q, R = cv_model(dim=1)
    rng = np.random.default_rng(1234)
    zs = rng.normal(scale=2.0, size=(80, 40, 1)) + np.arange(40)[:, None]
    zs[3, 10] = np.nan
    x0, P0 = np.array([0.0, 1.0]), np.eye(2)
    res = StrongTrackingKalmanFilter(F, H, Q, R, x0, P0, late_fading=True).filter(zs)
    assert res.states.shape == (80, 40, 2)
    stepper = StrongTrackingKalmanFilter(F, H, Q, R, x0, P0, late_fading=True)
    for k in range(40):
        stepper.step(zs[:, k])
        np.testing.assert_allclose(stepper.fading_factor, res.fading_factors[:, k])
    assert stepper.batch_shape == (80,)
    np.testing.assert_allclose(stepper.x, res.states[:, -1], rtol=1e-13)
    np.testing.assert_allclose(stepper.fading_factor, res.fading_factors[:, -1])


def test_lambda_max_clamps_the_fading_factor_after_an_outlier():
    F, H, Q, R = cv_model(dim=1)
    f = StrongTrackingKalmanFilter(F, H, Q, R, [0.0, 0.0], np.eye(2), lambda_max=10.0)
    f.predict()
    FPF = F @ np.eye(2) @ F.T
    f.update([1e4])  # c = tr N / tr M is about 1e8 / 2
    assert f.fading_factor == 10.0
    np.testing.assert_allclose(f.P_prior, 10.0 * FPF + Q, rtol=1e-14)


def test_missing_measurement_is_plain_prediction_and_keeps_v():
    F, H, Q, R = cv_model(dim=1)
    x0, P0 = np.array([0.0, 1.0]), np.eye(2)
    a = StrongTrackingKalmanFilter(F, H, Q, R, x0, P0)
    a.step([5.0])
    x1, P1 = a.x, a.P
    a.step(None)
    np.testing.assert_allclose(a.x, F @ x1, rtol=1e-14)
    np.testing.assert_allclose(a.P, F @ P1 @ F.T + Q, rtol=1e-14)
    assert a.fading_factor == 1.0 and np.isnan(a.nis) and np.all(np.isnan(a.y))
    a.step([np.nan])  # NaN is the same as None
    res = StrongTrackingKalmanFilter(F, H, Q, R, x0, P0).filter([[5.0], [np.nan], [np.nan]])
    np.testing.assert_allclose(a.x, res.states[-1], rtol=1e-14)
    # V unchanged over the gap: the next factor equals the spec transcription's
    zs = np.array([[5.0], [np.nan], [np.nan], [20.0]])
    ref_lams = reference_stkf(F, H, Q, R, x0, P0, zs, 4.5, 0.95, 100.0)[2]
    a.step([20.0])
    assert a.fading_factor == pytest.approx(ref_lams[-1], rel=1e-12)
    assert ref_lams[-1] > 1.0


def test_predict_twice_counts_the_skipped_update_as_missing():
    F, H, Q, R = cv_model(dim=1)
    a = StrongTrackingKalmanFilter(F, H, Q, R, [0.0, 1.0], np.eye(2))
    b = StrongTrackingKalmanFilter(F, H, Q, R, [0.0, 1.0], np.eye(2))
    a.predict()
    a.predict()
    a.update([2.0])
    b.step(None)
    b.step([2.0])
    np.testing.assert_allclose(a.x, b.x, rtol=1e-14)
    np.testing.assert_allclose(a.P, b.P, rtol=1e-14)


def test_per_step_measurement_noise_equals_step_by_step_override():
    F, H, Q, R = cv_model(dim=1, dt=0.04)
    rng = np.random.default_rng(1234)
    T = 30
    Rs = (0.1 + 0.05 * np.arange(T))[:, None, None] ** 2
    zs = rng.normal(size=(T, 1))
    res = StrongTrackingKalmanFilter(F, H, Q, R, [0.0, 1.0], np.eye(2)).filter(zs, R=Rs)
    f = StrongTrackingKalmanFilter(F, H, Q, R, [0.0, 1.0], np.eye(2))
    for k in range(T):
        f.step(zs[k], R=Rs[k])
        np.testing.assert_allclose(f.S[0, 0], res.innovation_covariances[k, 0, 0], rtol=1e-13)
    np.testing.assert_allclose(f.x, res.states[-1], rtol=1e-13)
    np.testing.assert_allclose(res.innovation_covariances[..., 0, 0] - Rs[:, 0, 0] > 0, True)


def test_nis_and_covariance_outputs_are_consistent():
    F, H, Q, R = cv_model()
    rng = np.random.default_rng(1234)
    zs = rng.normal(scale=3.0, size=(40, 2))
    res = StrongTrackingKalmanFilter(F, H, Q, R, np.zeros(4), np.eye(4)).filter(zs)
    y, S = res.innovations, res.innovation_covariances
    nis = np.einsum("ti,tij,tj->t", y, np.linalg.inv(S), y)
    np.testing.assert_allclose(res.nis, nis, rtol=1e-10)
    np.testing.assert_allclose(S, H @ res.predicted_covariances @ H.T + R, rtol=1e-12)
    np.testing.assert_allclose(res.covariances, np.swapaxes(res.covariances, -1, -2))
    assert np.all(np.linalg.eigvalsh(res.covariances) > 0)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"F": np.ones((2, 3))}, "F"),
        ({"F": [[1.0, np.nan], [0.0, 1.0]]}, "F"),
        ({"H": np.ones((1, 3))}, "H"),
        ({"Q": [[1.0, 2.0], [2.0, 1.0]]}, "Q"),
        ({"R": [[0.0]]}, "R"),
        ({"x0": [0.0, 1.0, 2.0]}, "x0"),
        ({"x0": [0.0, np.inf]}, "x0"),
        ({"P0": [[1.0, 0.0], [0.0, -1.0]]}, "P0"),
        ({"beta": 0.5}, "beta"),
        ({"rho": 0.0}, "rho"),
        ({"rho": 1.5}, "rho"),
        ({"lambda_max": 0.9}, "lambda_max"),
    ],
)
def test_bad_constructor_arguments_raise_value_error_naming_them(kwargs, name):
    args = {
        "F": [[1.0, 1.0], [0.0, 1.0]],
        "H": [[1.0, 0.0]],
        "Q": 0.01 * np.eye(2),
        "R": [[1.0]],
        "x0": [0.0, 1.0],
        "P0": np.eye(2),
    }
    options = {k: kwargs.pop(k) for k in ("beta", "rho", "lambda_max") if k in kwargs}
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        StrongTrackingKalmanFilter(**args, **options)


def test_bad_measurements_and_call_order_raise():
    F, H, Q, R = cv_model(dim=1)
    f = StrongTrackingKalmanFilter(F, H, Q, R, [0.0, 1.0], np.eye(2))
    with pytest.raises(RuntimeError, match="predict"):
        f.update([1.0])
    f.predict()
    with pytest.raises(ValueError, match="z"):
        f.update([1.0, 2.0])
    with pytest.raises(ValueError, match="inf"):
        f.update([np.inf])
    with pytest.raises(ValueError, match="R"):
        f.update([1.0], R=[[-1.0]])
    with pytest.raises(ValueError, match="zs"):
        f.filter(np.ones(5))
    with pytest.raises(ValueError, match="zs"):
        f.filter(np.ones((5, 2)))
    with pytest.raises(ValueError, match="R"):
        f.filter(np.ones((5, 1)), R=np.ones((3, 1, 1)))
    with pytest.raises(ValueError, match="batch"):
        StrongTrackingKalmanFilter(F, H, Q, R, np.zeros((3, 2)), np.eye(2)).filter(
            np.ones((4, 5, 1))
        )
