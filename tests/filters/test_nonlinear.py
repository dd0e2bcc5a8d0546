"""Tests of the extended and unscented Kalman filters (seawatch.filters.nonlinear)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from filterpy.kalman import ExtendedKalmanFilter as FPExtendedKalmanFilter
from filterpy.kalman import KalmanFilter as FPKalmanFilter
from filterpy.kalman import MerweScaledSigmaPoints
from filterpy.kalman import UnscentedKalmanFilter as FPUnscentedKalmanFilter
from scipy import stats

from seawatch.filters.nonlinear import ExtendedKalmanFilter, UnscentedKalmanFilter
from seawatch.models import constant_velocity
from seawatch.models.angles import LinearMeasurement, SeaSurfaceAngles, wrap_angle

FILTERS = [ExtendedKalmanFilter, UnscentedKalmanFilter]
SIGMA = 5e-4  # angle noise [rad] (0.5 mrad)


def _circular_mean(sigmas, Wm):
    return np.arctan2(Wm @ np.sin(sigmas), Wm @ np.cos(sigmas))


def _angle_residual(a, b):
    return wrap_angle(np.asarray(a) - np.asarray(b))


def _sea_problem(rng, T=40, height=10.0, x0=(866.0, 500.0, -3.0, 2.0), sigma_a=0.05, dt=1.0):
    """One NCV truth at ~1 km from a camera at the origin and its noisy sea angles."""
    F, Q = constant_velocity(2, dt, sigma_a)
    model = SeaSurfaceAngles(height)
    x = np.array(x0, dtype=float)
    truth = []
    for _ in range(T):
        x = F @ x + np.array([0.5 * dt**2, 0.5 * dt**2, dt, dt]) * sigma_a * rng.standard_normal(4)
        truth.append(x)
    truth = np.array(truth)
    zs = model(truth) + SIGMA * rng.standard_normal((T, 2))
    return F, Q, model, np.eye(2) * SIGMA**2, truth, zs


P0_SEA = np.diag([40.0**2, 40.0**2, 1.0, 1.0])


# ---------------------------------------------------------------- linear reduction
@pytest.mark.parametrize("cls", FILTERS)
def test_linear_measurement_reproduces_filterpy_kalman_filter(cls):
    rng = np.random.default_rng(1234)
    F, Q = constant_velocity(2, 0.5, 0.7)
    H = rng.normal(size=(3, 4))
    A = rng.normal(size=(3, 3))
    R = A @ A.T + 0.5 * np.eye(3)
    x0 = rng.normal(size=4) * 10
    B = rng.normal(size=(4, 4))
    P0 = B @ B.T + np.eye(4)
    zs = rng.normal(size=(30, 3)) * 5
    zs[7] = np.nan  # a missed measurement: predict only

    ours = cls(F, Q, LinearMeasurement(H), R, x0, P0)
    ref = FPKalmanFilter(dim_x=4, dim_z=3)
    ref.x, ref.P, ref.F, ref.Q, ref.H, ref.R = x0.copy(), P0.copy(), F, Q, H, R
    for z in zs:
        ours.predict()
        ref.predict()
        np.testing.assert_allclose(ours.x, ref.x, rtol=1e-9, atol=1e-9)
        missing = np.isnan(z).any()
        ours.update(z)
        ref.update(None if missing else z)
        np.testing.assert_allclose(ours.x, ref.x, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(ours.P, ref.P, rtol=1e-9, atol=1e-9)
        if missing:
            assert np.all(np.isnan(ours.y)) and np.isnan(ours.nis)
        else:
            np.testing.assert_allclose(ours.y, ref.y, rtol=1e-9, atol=1e-9)
            np.testing.assert_allclose(ours.S, ref.S, rtol=1e-9, atol=1e-9)
            assert ours.nis == pytest.approx(float(ref.y @ np.linalg.solve(ref.S, ref.y)))


# ------------------------------------------------------------------------- EKF
def test_ekf_single_step_matches_textbook_equations():
    F, Q = constant_velocity(2, 0.1, 0.3)
    h, xo, yo, psi = 7.0, 20.0, -30.0, math.radians(50.0)
    model = SeaSurfaceAngles(h, observer=(xo, yo), heading=psi)
    R = np.diag([(0.88 / 60 * math.pi / 180) ** 2, (1.56 / 60 * math.pi / 180) ** 2])
    x0 = np.array([400.0, 600.0, -2.98, -3.12])
    P0 = np.diag([30.0, 50.0, 2.0, 3.0]) ** 2
    z = np.array([0.16, 0.0095])

    ekf = ExtendedKalmanFilter(F, Q, model, R, x0, P0)
    ekf.predict()
    ekf.update(z)

    # textbook EKF, written out with the §7(a) Jacobian and seed 000 eqs. 1–2
    xp = F @ x0
    Pp = F @ P0 @ F.T + Q
    dx, dy = xp[0] - xo, xp[1] - yo
    rho = math.hypot(dx, dy)
    zhat = np.array([math.atan2(dy, dx) - psi, math.atan(h / rho)])
    g = h / (rho**2 + h**2)
    Hj = np.array([[-dy / rho**2, dx / rho**2, 0, 0], [-g * dx / rho, -g * dy / rho, 0, 0]])
    y = z - zhat
    S = Hj @ Pp @ Hj.T + R
    K = Pp @ Hj.T @ np.linalg.inv(S)
    x1 = xp + K @ y
    I_KH = np.eye(4) - K @ Hj
    P1 = I_KH @ Pp @ I_KH.T + K @ R @ K.T

    np.testing.assert_allclose(ekf.y, y, rtol=1e-10)
    np.testing.assert_allclose(ekf.S, S, rtol=1e-10)
    np.testing.assert_allclose(ekf.x, x1, rtol=1e-10)
    np.testing.assert_allclose(ekf.P, P1, rtol=1e-9, atol=1e-12 * np.max(np.abs(P1)))
    assert ekf.nis == pytest.approx(y @ np.linalg.solve(S, y), rel=1e-10)


def test_ekf_matches_filterpy_ekf_with_wrapped_residual_over_many_steps():
    rng = np.random.default_rng(1234)
    F, Q, model, R, _, zs = _sea_problem(rng, T=50)
    x0 = np.array([900.0, 470.0, -2.0, 1.0])
    ours = ExtendedKalmanFilter(F, Q, model, R, x0, P0_SEA)
    ref = FPExtendedKalmanFilter(dim_x=4, dim_z=2)
    ref.x, ref.P, ref.F, ref.Q, ref.R = x0.copy(), P0_SEA.copy(), F, Q, R
    for z in zs:
        ours.predict()
        ours.update(z)
        ref.predict()
        ref.update(z, HJacobian=model.jacobian, Hx=model, residual=_angle_residual)
        np.testing.assert_allclose(ours.x, ref.x, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(ours.P, ref.P, rtol=1e-8, atol=1e-9 * np.max(np.abs(ref.P)))


def test_ekf_with_linear_transition_function_equals_ekf_with_matrix():
    rng = np.random.default_rng(1234)
    F, Q, model, R, _, zs = _sea_problem(rng, T=30)
    x0 = np.array([900.0, 470.0, -2.0, 1.0])
    lin = ExtendedKalmanFilter(F, Q, model, R, x0, P0_SEA).filter(zs)
    fun = ExtendedKalmanFilter(
        None,
        Q,
        model,
        R,
        x0,
        P0_SEA,
        transition=lambda x: x @ F.T,
        transition_jacobian=lambda x: np.broadcast_to(F, (*x.shape[:-1], 4, 4)),
    ).filter(zs)
    np.testing.assert_allclose(fun.states, lin.states, rtol=1e-12)
    np.testing.assert_allclose(fun.covariances, lin.covariances, rtol=1e-10, atol=1e-12)


# ------------------------------------------------------------------------- UKF
@pytest.mark.parametrize(
    ("alpha", "beta", "kappa"), [(1.0, 2.0, 0.0), (0.5, 2.0, 1.0), (0.1, 2.0, 0.0)]
)
def test_ukf_matches_filterpy_ukf_with_merwe_sigma_points_on_sea_angles(alpha, beta, kappa):
    rng = np.random.default_rng(1234)
    F, Q, model, R, _, zs = _sea_problem(rng, T=40)
    x0 = np.array([900.0, 470.0, -2.0, 1.0])
    ours = UnscentedKalmanFilter(F, Q, model, R, x0, P0_SEA, alpha=alpha, beta=beta, kappa=kappa)
    points = MerweScaledSigmaPoints(4, alpha=alpha, beta=beta, kappa=kappa)
    ref = FPUnscentedKalmanFilter(
        dim_x=4,
        dim_z=2,
        dt=1.0,
        hx=model,
        fx=lambda x, dt: F @ x,
        points=points,
        z_mean_fn=_circular_mean,
        residual_z=_angle_residual,
    )
    ref.x, ref.P, ref.Q, ref.R = x0.copy(), P0_SEA.copy(), Q, R
    np.testing.assert_allclose(ours.Wm, points.Wm, rtol=1e-14)
    np.testing.assert_allclose(ours.Wc, points.Wc, rtol=1e-14)
    for z in zs:
        ours.predict()
        ref.predict()
        ours.update(z)
        ref.update(z)
        np.testing.assert_allclose(ours.y, ref.y, rtol=1e-8, atol=1e-12)
        np.testing.assert_allclose(ours.S, ref.S, rtol=1e-8)
        np.testing.assert_allclose(ours.x, ref.x, rtol=1e-8, atol=1e-8)
        np.testing.assert_allclose(ours.P, ref.P, rtol=1e-8, atol=1e-8 * np.max(np.abs(ref.P)))


def _coordinated_turn(dt):
    """Nonlinear CT model with the turn rate w in the state [x, y, vx, vy, w]."""

    def f(s):
        x, y, vx, vy, w = np.moveaxis(s, -1, 0)
        wt = w * dt
        small = np.abs(wt) < 1e-9
        wsafe = np.where(small, 1.0, w)
        sin_w = np.where(small, dt, np.sin(wt) / wsafe)
        cos_w = np.where(small, 0.0, (1 - np.cos(wt)) / wsafe)
        c, s_ = np.cos(wt), np.sin(wt)
        return np.stack(
            [
                x + sin_w * vx - cos_w * vy,
                y + cos_w * vx + sin_w * vy,
                c * vx - s_ * vy,
                s_ * vx + c * vy,
                w,
            ],
            axis=-1,
        )

    return f


def test_ukf_with_nonlinear_transition_matches_filterpy_ukf():
    rng = np.random.default_rng(1234)
    dt = 1.0
    f = _coordinated_turn(dt)
    model = SeaSurfaceAngles(15.0, heading=0.3)
    R = np.eye(2) * SIGMA**2
    Q = np.diag([0.1, 0.1, 0.05, 0.05, 1e-5])
    s = np.array([800.0, 300.0, -4.0, 3.0, 0.02])
    truth = []
    for _ in range(30):
        s = f(s) + rng.multivariate_normal(np.zeros(5), Q)
        truth.append(s)
    zs = model(np.array(truth)) + SIGMA * rng.standard_normal((30, 2))
    x0 = np.array([830.0, 280.0, -3.0, 3.5, 0.0])
    P0 = np.diag([40.0**2, 40.0**2, 2.0, 2.0, 0.03**2])
    ours = UnscentedKalmanFilter(f, Q, model, R, x0, P0)
    points = MerweScaledSigmaPoints(5, alpha=1.0, beta=2.0, kappa=0.0)
    ref = FPUnscentedKalmanFilter(
        dim_x=5,
        dim_z=2,
        dt=dt,
        hx=model,
        fx=lambda x, dt: f(x),
        points=points,
        z_mean_fn=_circular_mean,
        residual_z=_angle_residual,
    )
    ref.x, ref.P, ref.Q, ref.R = x0.copy(), P0.copy(), Q, R
    for z in zs:
        ours.predict()
        ref.predict()
        np.testing.assert_allclose(ours.x, ref.x, rtol=1e-9, atol=1e-10)
        ours.update(z)
        ref.update(z)
        np.testing.assert_allclose(ours.x, ref.x, rtol=1e-8, atol=1e-10)
        np.testing.assert_allclose(ours.P, ref.P, rtol=1e-8, atol=1e-8 * np.max(np.abs(ref.P)))


def test_ukf_with_linear_transition_function_equals_ukf_with_matrix():
    rng = np.random.default_rng(1234)
    F, Q, model, R, _, zs = _sea_problem(rng, T=30)
    x0 = np.array([900.0, 470.0, -2.0, 1.0])
    lin = UnscentedKalmanFilter(F, Q, model, R, x0, P0_SEA).filter(zs)
    fun = UnscentedKalmanFilter(lambda x: x @ F.T, Q, model, R, x0, P0_SEA).filter(zs)
    np.testing.assert_allclose(fun.states, lin.states, rtol=1e-10)
    np.testing.assert_allclose(fun.covariances, lin.covariances, rtol=1e-8, atol=1e-10)


def test_ukf_default_weights_are_non_negative_and_sum_to_one():
    F, Q = constant_velocity(2, 1.0, 0.1)
    ukf = UnscentedKalmanFilter(
        F, Q, SeaSurfaceAngles(10.0), np.eye(2) * 1e-6, [900, 0, 0, 0], P0_SEA
    )
    assert np.all(ukf.Wm >= 0) and np.all(ukf.Wc >= 0)
    assert ukf.Wm.sum() == pytest.approx(1.0)
    # the sigma points reproduce the mean and covariance they were drawn from
    chi = ukf.sigma_points()
    np.testing.assert_allclose(ukf.Wm @ chi, ukf.x, rtol=1e-14)
    d = chi - ukf.x
    np.testing.assert_allclose(
        np.einsum("k,ki,kj->ij", ukf.Wc, d, d) - 2 * np.outer(d[0], d[0]), P0_SEA, rtol=1e-12
    )


# ------------------------------------------------------------ angle wrapping
@pytest.mark.parametrize("cls", FILTERS)
def test_azimuth_near_plus_minus_pi_gives_a_small_innovation(cls):
    F, Q = constant_velocity(2, 1.0, 0.01)
    model = SeaSurfaceAngles(10.0)
    bearing = math.radians(179.9)
    x0 = np.array([1000 * math.cos(bearing), 1000 * math.sin(bearing), 0.0, 0.0])
    P0 = np.diag([1.0, 1.0, 0.01, 0.01])
    f = cls(F, Q, model, np.eye(2) * SIGMA**2, x0, P0)
    f.predict()
    z = np.array([math.radians(-179.9), math.atan2(10.0, 1000.0)])
    f.update(z)
    assert f.y[0] == pytest.approx(math.radians(0.2), abs=1e-5)  # not ~ -359.8 deg
    assert abs(f.y[1]) < 1e-5
    # the estimate moved towards the measured bearing, across the ±180° line
    post = math.atan2(f.x[1], f.x[0])
    assert abs(wrap_angle(post - z[0])) < abs(wrap_angle(bearing - z[0]))
    assert math.hypot(f.x[0], f.x[1]) == pytest.approx(1000.0, rel=1e-3)


@pytest.mark.parametrize("cls", FILTERS)
def test_tracking_across_the_azimuth_cut_is_invariant_to_the_heading(cls):
    # A target crosses due South. With heading 0 its relative azimuth jumps from -pi to
    # +pi; with heading pi it passes smoothly through 0. Wrapped residuals and circular
    # means must make both runs identical.
    rng = np.random.default_rng(1234)
    F, Q = constant_velocity(2, 1.0, 0.05)
    T = 80
    truth = np.array([[-1000.0, -160.0 + 4.0 * k, 0.0, 4.0] for k in range(1, T + 1)])
    base = SeaSurfaceAngles(10.0)
    noise = SIGMA * rng.standard_normal((T, 2))
    R = np.eye(2) * SIGMA**2
    x0 = np.array([-1030.0, -150.0, 0.5, 3.0])
    P0 = np.diag([40.0**2, 40.0**2, 1.0, 1.0])
    runs = []
    for psi in (0.0, math.pi):
        model = base.at(heading=psi)
        zs = model(truth) + noise
        zs[:, 0] = wrap_angle(zs[:, 0])
        runs.append(cls(F, Q, model, R, x0, P0).filter(zs))
    a, b = runs
    assert np.ptp(wrap_angle(np.arctan2(truth[:, 1], truth[:, 0]))) > 6  # it does cross
    np.testing.assert_allclose(a.states, b.states, rtol=0, atol=1e-6)
    np.testing.assert_allclose(a.covariances, b.covariances, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(a.nis, b.nis, rtol=1e-6, atol=1e-9)
    assert np.max(np.abs(a.innovations[:, 0])) < 0.05  # never a 2π jump


# -------------------------------------------------------------- Monte Carlo
@pytest.fixture(scope="module")
def sea_monte_carlo():
    """200 runs x 100 steps: camera 10 m high, target ~1 km away, 0.5 mrad angle noise."""
    rng = np.random.default_rng(1234)
    N, T, h = 200, 100, 10.0
    F, Q = constant_velocity(2, 1.0, 0.05)
    model = SeaSurfaceAngles(h)
    R = np.eye(2) * SIGMA**2
    x0 = np.array([866.0, 500.0, -3.0, 2.0])
    # truth: DWNA, one acceleration sample w per axis and step (x += [w/2, w] per axis)
    truth = np.empty((N, T, 4))
    x = np.broadcast_to(x0, (N, 4)).copy()
    for k in range(T):
        w = rng.standard_normal((N, 2)) * 0.05
        x = x @ F.T + np.concatenate([0.5 * w, w], axis=-1)
        truth[:, k] = x
    zs = model(truth) + SIGMA * rng.standard_normal((N, T, 2))
    init = x0 + rng.standard_normal((N, 4)) @ np.linalg.cholesky(P0_SEA).T
    results = {cls: cls(F, Q, model, R, init, P0_SEA).filter(zs) for cls in FILTERS}
    # point-wise geometry (seed 000 eqs. 3–5): d = h / tan(beta)
    d = h / np.tan(zs[..., 1])
    geometry = np.stack([d * np.cos(zs[..., 0]), d * np.sin(zs[..., 0])], axis=-1)
    return truth, results, geometry


def _anees(truth, res):
    e = truth - res.states
    nees = np.einsum("...i,...i->...", e, np.linalg.solve(res.covariances, e[..., None])[..., 0])
    return nees.mean(axis=0)  # average over runs, per step


@pytest.mark.parametrize("cls", FILTERS)
def test_sea_tracking_is_consistent_and_beats_point_wise_geometry(cls, sea_monte_carlo):
    truth, results, geometry = sea_monte_carlo
    res = results[cls]
    N, _, n = truth.shape
    anees = _anees(truth, res)
    lo, hi = stats.chi2.ppf([0.005, 0.995], N * n) / N
    # once converged (last quarter) the average NEES lies in the 99 % chi-square band of
    # a 200-run average (steps are correlated in time, so their mean is tested)
    assert lo < anees[-25:].mean() < hi
    # position RMSE across runs close to the filter's own sqrt(trace P_pos)
    err = np.sum((res.states[..., :2] - truth[..., :2]) ** 2, axis=-1)
    rmse = np.sqrt(err.mean(axis=0))
    spread = np.sqrt(np.mean(res.covariances[..., 0, 0] + res.covariances[..., 1, 1], axis=0))
    np.testing.assert_allclose(rmse[-25:].mean(), spread[-25:].mean(), rtol=0.15)
    # average NIS ≈ m = 2
    assert np.nanmean(res.nis) == pytest.approx(2.0, rel=0.1)
    # and far better than point-wise geometry from each frame alone
    geo = np.sqrt(np.sum((geometry - truth[..., :2]) ** 2, axis=-1).mean(axis=0))
    assert rmse.mean() < 0.5 * geo.mean()
    assert rmse[-25:].mean() < 0.25 * geo[-25:].mean()


def test_ukf_is_more_consistent_than_ekf_while_the_range_is_uncertain(sea_monte_carlo):
    # With a 40 m range sigma at 1 km the EKF's linearisation of the depression is
    # noticeably off and it is overconfident at first; the UKF stays in the band.
    truth, results, _ = sea_monte_carlo
    N, _, n = truth.shape
    lo, hi = stats.chi2.ppf([0.005, 0.995], N * n) / N
    ukf = _anees(truth, results[UnscentedKalmanFilter])
    ekf = _anees(truth, results[ExtendedKalmanFilter])
    assert np.mean((ukf > lo) & (ukf < hi)) >= 0.9  # measured: 99 of 100 steps
    assert lo < ukf[:20].mean() < hi  # measured: 3.98
    assert ekf[:20].mean() > 1.5 * hi  # measured: 8.8, overconfident


# ------------------------------------------------------- batches, per-step models
@pytest.mark.parametrize("cls", FILTERS)
def test_batched_runs_with_per_run_observers_equal_single_runs(cls):
    rng = np.random.default_rng(1234)
    F, Q = constant_velocity(2, 1.0, 0.05)
    B, T = 3, 25
    R = np.eye(2) * SIGMA**2
    x0 = np.array([[900.0, 450.0, -2.0, 1.0], [-700.0, 600.0, 1.0, 0.0], [300.0, -800.0, 0, 2]])
    # a moving platform, observed with a per-run position error (as in uav-sea)
    track = np.array([[2.55 * k, 4.33 * k] for k in range(T)])
    observers = track[:, None, :] + rng.normal(size=(T, B, 2))
    models = [SeaSurfaceAngles(5.0, observer=observers[k], heading=0.9) for k in range(T)]
    zs = np.stack([models[k](x0 @ np.linalg.matrix_power(F, k + 1).T) for k in range(T)], axis=1)
    zs = zs + SIGMA * rng.standard_normal(zs.shape)
    zs[1, 5] = np.nan
    batched = cls(F, Q, SeaSurfaceAngles(5.0), R, x0 + 20.0, P0_SEA).filter(zs, measurements=models)
    assert batched.states.shape == (B, T, 4)
    assert batched.covariances.shape == (B, T, 4, 4)
    assert batched.nis.shape == (B, T) and np.isnan(batched.nis[1, 5])
    for b in range(B):
        single_models = [m.at(observer=observers[k, b]) for k, m in enumerate(models)]
        single = cls(F, Q, SeaSurfaceAngles(5.0), R, x0[b] + 20.0, P0_SEA).filter(
            zs[b], measurements=single_models
        )
        np.testing.assert_allclose(batched.states[b], single.states, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(batched.covariances[b], single.covariances, rtol=1e-10)
        np.testing.assert_allclose(batched.innovations[b], single.innovations, rtol=1e-10)


@pytest.mark.parametrize("cls", FILTERS)
def test_filter_equals_the_predict_update_loop_and_records_priors(cls):
    rng = np.random.default_rng(1234)
    F, Q, model, R, _, zs = _sea_problem(rng, T=15)
    x0 = np.array([900.0, 470.0, -2.0, 1.0])
    res = cls(F, Q, model, R, x0, P0_SEA).filter(zs)
    f = cls(F, Q, model, R, x0, P0_SEA)
    for k, z in enumerate(zs):
        f.predict()
        np.testing.assert_array_equal(res.predicted_states[k], f.x)
        np.testing.assert_array_equal(res.predicted_covariances[k], f.P)
        f.update(z)
        np.testing.assert_array_equal(res.states[k], f.x)
        np.testing.assert_array_equal(res.innovation_covariances[k], f.S)
        assert res.nis[k] == f.nis


@pytest.mark.parametrize("cls", FILTERS)
def test_missing_measurement_is_a_predict_only_step_for_that_track(cls):
    F, Q = constant_velocity(2, 1.0, 0.05)
    model = SeaSurfaceAngles(10.0)
    x0 = np.array([[900.0, 470.0, -2.0, 1.0], [600.0, -300.0, 1.0, 1.0]])
    f = cls(F, Q, model, np.eye(2) * SIGMA**2, x0, P0_SEA)
    f.predict()
    x_prior, P_prior = f.x.copy(), f.P.copy()
    z = model(x0 @ F.T) + 1e-3
    z[0, 1] = np.nan
    f.update(z)
    np.testing.assert_array_equal(f.x[0], x_prior[0])
    np.testing.assert_array_equal(f.P[0], P_prior[0])
    assert np.all(np.isnan(f.y[0])) and np.isnan(f.nis[0])
    assert not np.allclose(f.x[1], x_prior[1]) and np.isfinite(f.nis[1])
    assert np.all(np.isfinite(f.S))
    f.update(None)  # None: every track predict-only
    np.testing.assert_array_equal(f.x[0], x_prior[0])
    assert np.all(np.isnan(f.nis))


# ------------------------------------------------------------------- bad input
def _args():
    F, Q = constant_velocity(2, 1.0, 0.1)
    return {
        "F": F,
        "Q": Q,
        "measurement": SeaSurfaceAngles(10.0),
        "R": np.eye(2) * 1e-6,
        "x0": np.array([900.0, 0.0, 0.0, 0.0]),
        "P0": np.eye(4),
    }


@pytest.mark.parametrize("cls", FILTERS)
@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("F", np.full((4, 4), np.nan)),
        ("F", np.ones((4, 3))),
        ("Q", np.ones((4, 4)) - 2 * np.eye(4)),
        ("R", np.zeros((2, 2))),
        ("R", np.eye(3)),
        ("x0", np.zeros(3)),
        ("x0", np.array([np.nan, 0, 0, 0])),
        ("P0", -np.eye(4)),
        ("P0", np.ones((5, 4, 4))),
        ("measurement", "not a model"),
        ("measurement", (1, 2)),
    ],
)
def test_bad_constructor_arguments_raise_value_error_naming_them(cls, name, value):
    args = _args()
    args[name] = value
    if name == "P0" and value.ndim == 3:
        args["x0"] = np.zeros((3, 4))  # batch 3 against P0 batch 5
    F = args.pop("F")
    with pytest.raises(ValueError, match=name):
        cls(F, **args)


def test_ekf_needs_jacobians_and_one_kind_of_transition():
    a = _args()
    with pytest.raises(ValueError, match="measurement"):
        ExtendedKalmanFilter(a["F"], a["Q"], lambda x: x[..., :2], a["R"], a["x0"], a["P0"])
    with pytest.raises(ValueError, match="transition_jacobian"):
        ExtendedKalmanFilter(
            None, a["Q"], a["measurement"], a["R"], a["x0"], a["P0"], transition=lambda x: x
        )
    with pytest.raises(ValueError, match="F"):
        ExtendedKalmanFilter(
            a["F"],
            a["Q"],
            a["measurement"],
            a["R"],
            a["x0"],
            a["P0"],
            transition=lambda x: x,
            transition_jacobian=lambda x: x,
        )
    # a plain callable is enough for the UKF; R tells the measurement size
    ukf = UnscentedKalmanFilter(a["F"], a["Q"], lambda x: x[..., :2], a["R"], a["x0"], a["P0"])
    assert ukf.dim_z == 2


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"alpha": 0.0}, "alpha"),
        ({"alpha": np.nan}, "alpha"),
        ({"kappa": -4.0}, "kappa"),
        ({"beta": np.inf}, "beta"),
    ],
)
def test_bad_ukf_parameters_raise_value_error(kwargs, name):
    a = _args()
    with pytest.raises(ValueError, match=name):
        UnscentedKalmanFilter(a.pop("F"), **a, **kwargs)


@pytest.mark.parametrize("cls", FILTERS)
def test_bad_measurements_raise_value_error(cls):
    a = _args()
    f = cls(a.pop("F"), **a)
    with pytest.raises(ValueError, match="z"):
        f.update(np.array([0.1, np.inf]))
    with pytest.raises(ValueError, match="z"):
        f.update(np.array([0.1, 0.2, 0.3]))
    with pytest.raises(ValueError, match="zs"):
        f.filter(np.zeros((5, 3)))
    with pytest.raises(ValueError, match="measurements"):
        f.filter(np.zeros((5, 2)), measurements=[None] * 4)
    with pytest.raises(ValueError, match="R"):
        f.update(np.zeros(2), R=np.diag([1.0, -1.0]))
    with pytest.raises(ValueError, match="measurement"):
        f.update(np.zeros(2), measurement=(lambda x: np.zeros(3), lambda x: np.zeros((3, 4))))


def test_ukf_raises_linalg_error_when_p_is_not_positive_definite():
    a = _args()
    ukf = UnscentedKalmanFilter(a.pop("F"), **a)
    ukf.P = np.zeros((4, 4))  # positive semi-definite but singular: no Cholesky factor
    with pytest.raises(np.linalg.LinAlgError, match="not positive definite"):
        ukf.update(np.array([0.0, 0.01]))
