"""Tests of the fractional-order Kalman filters FKF and AFKF (ALGORITHMS.md §1)."""

from __future__ import annotations

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter as FilterPyKF
from hypothesis import given
from hypothesis import strategies as st
from scipy.special import binom
from scipy.stats import chi2

from seawatch.filters.fractional import (
    AdaptiveFractionalKalmanFilter,
    AdaptiveFractionalResult,
    FractionalKalmanFilter,
    fractional_cv_matrix,
    gl_coefficients,
)
from seawatch.filters.result import FilterResult
from seawatch.models.kinematic import constant_velocity

# ---------------------------------------------------------------------- helpers


def reference_fkf(A, H, Q, R, x0, P0, zs, order, memory):
    """Plain-numpy transcription of ALGORITHMS.md §1.4 (absolute coordinates, one track).

    GL coefficients from the closed form (-1)^j binom(alpha, j); full lists of past
    estimates, truncated at ``memory`` terms.
    """
    n = len(x0)
    alpha = np.broadcast_to(np.asarray(order, float), (n,))
    Y = [np.diag((-1.0) ** j * binom(alpha, j)) for j in range(memory + 1)]
    xs_hist, Ps_hist = [np.array(x0, float)], [np.array(P0, float)]
    out_x, out_P = [], []
    for z in zs:
        k = len(xs_hist) - 1
        J = min(k + 1, memory)
        x_t = A @ xs_hist[-1] - sum(Y[j] @ xs_hist[-j] for j in range(1, J + 1))
        AY1 = A - Y[1]
        P_t = AY1 @ Ps_hist[-1] @ AY1.T + Q
        P_t = P_t + sum((Y[j] @ Ps_hist[-j] @ Y[j].T for j in range(2, J + 1)), np.zeros((n, n)))
        if np.any(np.isnan(z)):
            x, P = x_t, P_t
        else:
            S = H @ P_t @ H.T + R
            K = P_t @ H.T @ np.linalg.inv(S)
            x = x_t + K @ (z - H @ x_t)
            IKH = np.eye(n) - K @ H
            P = IKH @ P_t @ IKH.T + K @ R @ K.T
        xs_hist.append(x)
        Ps_hist.append(P)
        out_x.append(x)
        out_P.append(P)
    return np.array(out_x), np.array(out_P)


def simulate_cv(rng, runs, T, sigma_a, sigma_z, *, jump_at=None, dv=(3.0, 0.0)):
    """Image-plane CV truth (px, px/frame) with DWNA noise and an optional velocity jump."""
    F, _ = constant_velocity(2, 1.0, sigma_a)
    x = np.zeros((runs, T, 4))
    x[:, 0] = [800.0, 400.0, 0.5, -0.2]
    for k in range(1, T):
        a = rng.normal(scale=sigma_a, size=(runs, 2))
        x[:, k] = x[:, k - 1] @ F.T
        x[:, k, :2] += 0.5 * a
        x[:, k, 2:] += a
        if k == jump_at:
            x[:, k, 2:] += dv
    zs = x[..., :2] + rng.normal(scale=sigma_z, size=(runs, T, 2))
    return x, zs


# ------------------------------------------------------------- GL coefficients


def test_gl_coefficients_match_closed_form_signed_binomials():
    for alpha in (0.3, 0.8, 0.95, 1.0, 1.7):
        j = np.arange(40)
        np.testing.assert_allclose(
            gl_coefficients(alpha, 40), (-1.0) ** j * binom(alpha, j), rtol=1e-12, atol=1e-300
        )
    np.testing.assert_allclose(
        gl_coefficients(0.8, 5), [1.0, -0.8, -0.08, -0.032, -0.0176], rtol=1e-14
    )
    vec = gl_coefficients([0.5, 0.9, 1.0], 6)
    assert vec.shape == (6, 3)
    for i, a in enumerate((0.5, 0.9, 1.0)):
        np.testing.assert_allclose(vec[:, i], gl_coefficients(a, 6), rtol=1e-15)
    assert np.all(gl_coefficients(1.0, 10)[2:] == 0.0)  # integer order: no memory


def test_memory_weights_sum_below_one_as_in_the_spec():
    c = gl_coefficients(0.9, 51)
    for L, expected in ((5, 0.975), (10, 0.987), (50, 0.997)):
        assert -c[1 : L + 1].sum() == pytest.approx(expected, abs=1e-3)  # spec: 3 digits
    assert np.all(c[1:] < 0)


def test_predict_only_recursion_reproduces_the_gl_difference_weights():
    # A = 0, Q = 0, scalar state 1: x_{k+1} = -sum_{j=1..min(k+1, L)} c_j x_{k+1-j}
    L, alpha = 5, 0.9
    f = FractionalKalmanFilter([[0.0]], [[1.0]], [[0.0]], [[1.0]], [1.0], [[0.0]],
                               order=alpha, memory=L, relative=False)  # fmt: skip
    c = (-1.0) ** np.arange(L + 1) * binom(alpha, np.arange(L + 1))
    hist = [1.0]
    for _ in range(12):
        f.predict()
        J = min(len(hist), L)
        hist.append(-sum(c[j] * hist[-j] for j in range(1, J + 1)))
        assert f.x[0] == pytest.approx(hist[-1], rel=1e-14)


# ------------------------------------------------------------------ the FKF


def test_order_one_reproduces_the_integer_order_cv_kalman_filter():
    rng = np.random.default_rng(1234)
    _, zs = simulate_cv(rng, 1, 300, 0.5, 2.0)
    zs = zs[0]
    for relative, atol in ((False, 1e-12), (True, 1e-9)):
        f = FractionalKalmanFilter.for_image_tracking(
            order=1.0, sigma_a=0.5, x0=[zs[0, 0], zs[0, 1], 0.0, 0.0], relative=relative
        )
        res = f.filter(zs[1:])
        ref = FilterPyKF(dim_x=4, dim_z=2)
        ref.F = fractional_cv_matrix(2, 1.0) + np.eye(4)
        ref.H, ref.Q, ref.R = f.H, f.Q, f.R
        ref.x, ref.P = np.array([zs[0, 0], zs[0, 1], 0.0, 0.0]), f.P0.copy()
        for k, z in enumerate(zs[1:]):
            ref.predict()
            ref.update(z)
            np.testing.assert_allclose(res.states[k], ref.x, rtol=1e-14, atol=atol)
            np.testing.assert_allclose(res.covariances[k], ref.P, rtol=1e-12, atol=1e-13)
            np.testing.assert_allclose(res.nis[k], ref.mahalanobis**2, rtol=1e-8)
    np.testing.assert_array_equal(fractional_cv_matrix(2, 1.0) + np.eye(4), ref.F)


@pytest.mark.parametrize("order", [0.7, [0.6, 0.8, 0.95, 1.0]])
def test_filter_equals_numpy_transcription_with_truncated_memory(order):
    rng = np.random.default_rng(1234)
    n, T, L = 4, 40, 6
    A = 0.3 * rng.normal(size=(n, n))
    H = rng.normal(size=(2, n))
    G = rng.normal(size=(n, n))
    Q = 0.1 * G @ G.T
    R = np.diag([0.5, 0.8])
    x0, P0 = rng.normal(size=n), np.eye(n)
    zs = rng.normal(size=(T, 2))
    zs[[3, 17, 18]] = np.nan
    ref_x, ref_P = reference_fkf(A, H, Q, R, x0, P0, zs, order, L)
    for relative in (False, True):
        f = FractionalKalmanFilter(A, H, Q, R, x0, P0, order=order, memory=L, relative=relative)
        res = f.filter(zs)
        if not relative:  # in relative coordinates the origin (hence the pull) moves
            np.testing.assert_allclose(res.states, ref_x, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(res.covariances, ref_P, rtol=1e-10, atol=1e-12)
    # per-step API gives the same as filter()
    g = FractionalKalmanFilter(A, H, Q, R, x0, P0, order=order, memory=L, relative=False)
    for k in range(T):
        g.step(zs[k])
        np.testing.assert_allclose(g.x, ref_x[k], rtol=1e-10, atol=1e-12)
    assert g.history_length == L - 1


def test_history_memory_is_constant_over_a_long_stream():
    f = FractionalKalmanFilter.for_image_tracking(order=0.9, memory=20)
    rng = np.random.default_rng(1234)
    zs = 500.0 + rng.normal(scale=2.0, size=(10_001, 2))
    f.step(zs[0])
    f.step(zs[1])
    nbytes = f.history_nbytes
    for z in zs[2:]:
        f.step(z)
    assert f.history_nbytes == nbytes == 19 * (4 + 16) * 8
    assert f.history_length == 19
    res = f.filter(zs)  # and a 10,000-step block through the compiled loop
    assert f.history_nbytes == nbytes
    assert np.all(np.isfinite(res.states))


def test_relative_coordinates_remove_the_origin_pull_on_a_stationary_target():
    # alpha = 0.95, L = 30: the memory weights sum to s < 1, so in absolute pixel
    # coordinates the model pulls u toward 0 by (1 - s) u per frame; the filter absorbs
    # the pull into a spurious velocity v = (1 - s) / s * u (ALGORITHMS.md §1.2 pitfall).
    rng = np.random.default_rng(1234)
    target = np.array([1000.0, 600.0])
    zs = target + rng.normal(scale=2.0, size=(64, 300, 2))
    s = -gl_coefficients(0.95, 31)[1:].sum()
    rel = FractionalKalmanFilter.for_image_tracking(order=0.95, relative=True).filter(zs)
    ab = FractionalKalmanFilter.for_image_tracking(order=0.95, relative=False).filter(zs)
    late = slice(100, None)
    bias_rel = (rel.states[:, late, :2] - target).mean(axis=(0, 1))
    vel_rel = rel.states[:, late, 2:].mean(axis=(0, 1))
    vel_abs = ab.states[:, late, 2:].mean(axis=(0, 1))
    assert np.all(np.abs(bias_rel) < 0.1)
    assert np.all(np.abs(vel_rel) < 0.02)
    np.testing.assert_allclose(vel_abs, (1 - s) / s * target, rtol=0.05)
    assert vel_abs[0] > 1.5  # px/frame for a target that does not move


@given(
    orders=st.lists(st.floats(0.5, 1.0), min_size=4, max_size=4),
    memory=st.integers(1, 12),
    seed=st.integers(0, 2**16),
)
def test_covariances_stay_symmetric_positive_semidefinite(orders, memory, seed):
    rng = np.random.default_rng(seed)
    f = FractionalKalmanFilter.for_image_tracking(order=orders, memory=memory, sigma_a=0.3)
    zs = 300.0 + np.cumsum(rng.normal(size=(60, 2)), axis=0)
    zs[rng.random(60) < 0.2] = np.nan
    zs[0] = 300.0
    res = f.filter(zs)
    for P in (res.covariances, res.predicted_covariances):
        np.testing.assert_array_equal(P, np.swapaxes(P, -1, -2))
        eig = np.linalg.eigvalsh(P)
        assert np.all(eig >= -1e-9 * np.abs(eig).max(axis=-1, keepdims=True))
    assert np.all(np.isfinite(res.states))


def test_first_measurement_initialises_the_image_tracker():
    f = FractionalKalmanFilter.for_image_tracking(dt=1.0, sigma_a=1.0, sigma_z=2.0, sigma_v0=4.0)
    g = np.array([0.5, 1.0])  # DWNA per axis: sigma_a^2 [T^2/2, T]^T [T^2/2, T]
    np.testing.assert_allclose(f.Q, np.kron(np.outer(g, g), np.eye(2)))
    np.testing.assert_array_equal(f.A, [[0, 0, 1, 0], [0, 0, 0, 1], [0, 0, 0, 0], [0, 0, 0, 0]])
    np.testing.assert_array_equal(f.H, [[1, 0, 0, 0], [0, 1, 0, 0]])
    np.testing.assert_allclose(f.R, 4.0 * np.eye(2))
    np.testing.assert_allclose(f.P0, np.diag([4.0, 4.0, 16.0, 16.0]))
    assert not f.initialised
    with pytest.raises(RuntimeError, match="first measurement"):
        f.predict()
    zs = np.array([[640.0, 360.0], [641.0, 360.5], [np.nan, np.nan], [643.5, 361.0]])
    res = f.filter(zs)
    np.testing.assert_array_equal(res.states[0], [640.0, 360.0, 0.0, 0.0])
    np.testing.assert_array_equal(res.covariances[0], f.P0)
    assert np.isnan(res.nis[0]) and np.isnan(res.nis[2]) and np.isfinite(res.nis[3])
    stepper = FractionalKalmanFilter.for_image_tracking(sigma_v0=4.0)
    for z in zs:
        stepper.step(z)
    np.testing.assert_allclose(stepper.x, res.states[-1], rtol=1e-14)
    np.testing.assert_allclose(stepper.P, res.covariances[-1], rtol=1e-14)


def test_missing_measurement_is_predict_only_and_history_advances():
    f = FractionalKalmanFilter.for_image_tracking(x0=[100.0, 50.0, 1.0, 0.0])
    f.step([101.0, 50.0])
    assert f.history_length == 1
    f.predict()
    prior_x, prior_P = f.x, f.P
    f.update(None)
    np.testing.assert_array_equal(f.x, prior_x)
    np.testing.assert_array_equal(f.P, prior_P)
    assert np.isnan(f.nis) and np.all(np.isnan(f.y))
    f.step([np.nan, np.nan])
    assert f.history_length == 3
    assert np.all(np.isfinite(f.x))


def test_update_with_a_step_covariance_is_the_joseph_update_with_it():
    """``update(z, R=...)``: eqs. (16)–(18) with that R for this step only; a huge variance
    on one coordinate measured at its prediction leaves the one-coordinate update."""
    f = FractionalKalmanFilter.for_image_tracking(x0=[100.0, 50.0, 1.0, 0.5], sigma_z=2.0)
    for z in ([101.2, 50.3], [101.9, 51.2], [103.1, 51.4]):
        f.step(z)
    f.predict()
    x_prior, P_prior, H = f.x, f.P, f.H
    z = np.array([104.6, 52.9])
    R2 = np.array([[1.0, 0.3], [0.3, 9.0]])
    f.update(z, R=R2)
    K = P_prior @ H.T @ np.linalg.inv(H @ P_prior @ H.T + R2)
    A = np.eye(4) - K @ H
    np.testing.assert_allclose(f.x, x_prior + K @ (z - H @ x_prior), rtol=1e-12)
    np.testing.assert_allclose(f.P, A @ P_prior @ A.T + K @ R2 @ K.T, rtol=1e-10, atol=1e-12)
    f.predict()  # the next update is back to the filter's own R
    x_prior, P_prior = f.x, f.P
    f.update(z)
    K = P_prior @ H.T @ np.linalg.inv(H @ P_prior @ H.T + f.R)
    np.testing.assert_allclose(f.x, x_prior + K @ (z - H @ x_prior), rtol=1e-12)
    # x only: y measured at its prediction with a variance 1e8 σ_z²
    f.predict()
    x_prior, P_prior = f.x, f.P
    f.update([106.0, (H @ x_prior)[1]], R=np.diag([4.0, 4e8]))
    h = H[:1]
    k = P_prior @ h.T / (h @ P_prior @ h.T + 4.0)
    np.testing.assert_allclose(f.x, x_prior + (k * (106.0 - x_prior[0])).ravel(), rtol=1e-9)
    for bad in (np.eye(3), np.array([[1.0, 0.5], [0.0, 1.0]]), np.diag([1.0, np.nan])):
        with pytest.raises(ValueError, match="R"):
            f.update(z, R=bad)


def test_batched_filter_equals_looped_single_tracks():
    rng = np.random.default_rng(1234)
    _, zs = simulate_cv(rng, 6, 50, 0.5, 2.0)
    zs = zs.reshape(3, 2, 50, 2)
    zs[1, 1, 7] = np.nan
    res = AdaptiveFractionalKalmanFilter.for_image_tracking(order=0.9).filter(zs)
    assert isinstance(res, AdaptiveFractionalResult) and isinstance(res, FilterResult)
    assert res.states.shape == (3, 2, 50, 4) and res.q_scales.shape == (3, 2, 50)
    for i in range(3):
        for j in range(2):
            single = AdaptiveFractionalKalmanFilter.for_image_tracking(order=0.9)
            for k in range(50):
                assert single.initialised == (k > 0)
                if k > 0:  # the gain used by the prediction of step k
                    assert single.q_scale == res.q_scales[i, j, k]
                single.step(zs[i, j, k])
            np.testing.assert_allclose(single.x, res.states[i, j, -1], rtol=1e-13)
            np.testing.assert_allclose(single.P, res.covariances[i, j, -1], rtol=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"order": 0.0}, "order"),
        ({"order": -0.5}, "order"),
        ({"order": [0.9, 0.9, 0.9]}, "order"),
        ({"order": np.nan}, "order"),
        ({"memory": 0}, "memory"),
        ({"memory": 2.5}, "memory"),
        ({"A": np.ones((2, 3))}, "A"),
        ({"A": [[np.nan, 1.0], [0.0, 0.0]]}, "A"),
        ({"H": np.ones((1, 3))}, "H"),
        ({"Q": -np.eye(2)}, "Q"),
        ({"R": [[0.0]]}, "R"),
        ({"P0": [[1.0, 2.0], [2.0, 1.0]]}, "P0"),
        ({"x0": [1.0, 2.0, 3.0]}, "x0"),
    ],
)
def test_bad_fkf_arguments_raise_value_error_naming_them(kwargs, name):
    args = {
        "A": [[0.0, 1.0], [0.0, 0.0]],
        "H": [[1.0, 0.0]],
        "Q": 0.01 * np.eye(2),
        "R": [[1.0]],
        "x0": [0.0, 1.0],
        "P0": np.eye(2),
    }
    options = {k: kwargs.pop(k) for k in ("order", "memory") if k in kwargs}
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        FractionalKalmanFilter(**args, **options)


def test_bad_measurements_and_helpers_raise():
    f = FractionalKalmanFilter.for_image_tracking()
    with pytest.raises(ValueError, match="first measurement"):
        f.update([np.nan, 3.0])
    with pytest.raises(ValueError, match="z"):
        f.update([1.0, 2.0, 3.0])
    f.update([1.0, 2.0])
    with pytest.raises(ValueError, match="inf"):
        f.update([np.inf, 2.0])
    with pytest.raises(ValueError, match="zs"):
        f.filter(np.ones(4))
    with pytest.raises(ValueError, match="count"):
        gl_coefficients(0.5, 0)
    with pytest.raises(ValueError, match="order"):
        gl_coefficients(0.0, 3)
    with pytest.raises(ValueError, match="dt"):
        fractional_cv_matrix(2, 0.0)
    with pytest.raises(ValueError, match="sigma_z"):
        FractionalKalmanFilter.for_image_tracking(sigma_z=-1.0)


# ----------------------------------------------------------------- the AFKF


def test_afkf_at_steady_state_with_a_consistent_model_keeps_gain_near_one():
    rng = np.random.default_rng(1234)
    sa, sz = 0.05, 2.0
    _, zs = simulate_cv(rng, 200, 300, sa, sz)
    afkf = AdaptiveFractionalKalmanFilter.for_image_tracking(order=1.0, sigma_a=sa, sigma_z=sz)
    res = afkf.filter(zs)
    eta = res.nis[:, 50:] / 2
    assert 0.93 < eta.mean() < 1.07
    assert res.q_scales[:, 50:].mean() < 1.2
    assert np.all(res.q_scales >= 1.0)


@pytest.mark.parametrize("order", [1.0, 0.95])
def test_afkf_raises_the_gain_after_a_manoeuvre_and_recovers_faster_than_the_fkf(order):
    rng = np.random.default_rng(1234)
    sa, sz, jump = 0.05, 2.0, 150
    x, zs = simulate_cv(rng, 200, 200, sa, sz, jump_at=jump)
    model = {"order": order, "sigma_a": sa, "sigma_z": sz}
    adaptive = AdaptiveFractionalKalmanFilter.for_image_tracking(**model).filter(zs)
    constant = FractionalKalmanFilter.for_image_tracking(**model).filter(zs)
    err_a = np.linalg.norm(adaptive.states[..., :2] - x[..., :2], axis=-1)
    err_c = np.linalg.norm(constant.states[..., :2] - x[..., :2], axis=-1)
    after = slice(jump, jump + 40)
    assert adaptive.q_scales[:, jump + 1 : jump + 15].mean() > 3.0
    assert adaptive.q_scales[:, 100:jump].mean() < 1.35
    assert err_a[:, after].mean() < 0.85 * err_c[:, after].mean()


def test_rule_r1_gain_is_the_clamped_windowed_mean_nis_used_one_step_later():
    rng = np.random.default_rng(1234)
    _, zs = simulate_cv(rng, 1, 80, 0.05, 2.0, jump_at=40, dv=(4.0, 0.0))
    zs = zs[0]
    zs[20] = np.nan
    gain, W, g_max = 2.0, 4, 30.0
    f = AdaptiveFractionalKalmanFilter.for_image_tracking(
        order=0.9, sigma_a=0.05, gain=gain, window=W, g_max=g_max
    )
    res = f.filter(zs)
    etas: list[float] = []
    expected = [1.0]  # no innovation yet
    g = 1.0
    for k in range(len(zs) - 1):
        if np.isfinite(res.nis[k]):
            etas.append(res.nis[k] / 2)
            g = min(g_max, 1 + gain * max(0.0, float(np.mean(etas[-W:])) - 1))
        expected.append(g)
    np.testing.assert_allclose(res.q_scales, expected, rtol=1e-12)
    assert max(expected) == g_max  # the manoeuvre hits the clamp
    etas.append(res.nis[-1] / 2)
    assert f.eta_bar == pytest.approx(np.mean(etas[-W:]), rel=1e-12)


def test_rule_r2_settles_then_returns_to_transient_when_nis_exceeds_the_bound():
    rng = np.random.default_rng(1234)
    sa, sz, W = 0.05, 2.0, 5
    _, zs = simulate_cv(rng, 1, 120, sa, sz)
    zs = zs[0]
    f = AdaptiveFractionalKalmanFilter.for_image_tracking(
        order=1.0, sigma_a=sa, sigma_z=sz, rule="R2", window=W
    )
    assert f.rule == "R2" and f.gain == 4.0
    f.update(zs[0])
    assert f.q_scale == 5.0  # transient at the start: Q = (1 + lambda) Q0
    for z in zs[1:]:
        f.step(z)
    assert bool(f.steady) and f.q_scale == 1.0
    bound = chi2.ppf(0.99, 2 * W) / (2 * W)
    etas = []
    for _ in range(W):  # a sudden 40 px offset: the windowed NIS exceeds the bound
        f.step(zs[-1] + [40.0, 0.0])
        etas.append(float(f.nis) / 2)
        if np.mean(etas) > bound:
            break
    assert np.mean(etas) > bound
    assert not bool(f.steady) and f.q_scale == 5.0


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"rule": "R3"}, "rule"),
        ({"gain": 0.0}, "gain"),
        ({"window": 0}, "window"),
        ({"g_max": 0.5}, "g_max"),
        ({"delta": 0.0}, "delta"),
        ({"order": 0.0}, "order"),
    ],
)
def test_bad_afkf_arguments_raise_value_error_naming_them(kwargs, name):
    with pytest.raises(ValueError, match=name):
        AdaptiveFractionalKalmanFilter.for_image_tracking(**kwargs)
