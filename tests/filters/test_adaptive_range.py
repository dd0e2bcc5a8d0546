"""Tests of the ANCV/ANCA range filters (ALGORITHMS.md §5, seed 002)."""

from __future__ import annotations

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter as FilterPyKF
from hypothesis import given
from hypothesis import strategies as st

from seawatch.filters.adaptive_range import (
    AdaptiveRangeFilter,
    adaptation_statistic,
    size_range_std,
)
from seawatch.models.kinematic import constant_acceleration, constant_velocity

T = 0.04
F_PX, L_M, SL_PX = 40_000.0, 10.0, 1.0
SIZE_KW = {"sigma_l": SL_PX, "size": L_M, "focal": F_PX}


def _approach(n: int = 200, runs: int | None = None, seed: int = 1234) -> np.ndarray:
    """Raw size-based ranges of a target closing from 5 km at 200 m/s, (n,) or (runs, n)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * T
    d = 5000.0 - 200.0 * t + 0.3 * t * t
    shape = (n,) if runs is None else (runs, n)
    return F_PX * L_M / (F_PX * L_M / d + SL_PX * rng.standard_normal(shape))


def _start(z0: np.ndarray | float, n: int) -> tuple[np.ndarray, np.ndarray]:
    z0 = np.asarray(z0, dtype=float)
    x0 = np.zeros((*z0.shape, n))
    x0[..., 0] = z0
    P0 = np.diag([50.0**2, 300.0**2, 10.0**2][:n])
    return x0, P0


# ------------------------------------------------------------------ §5.1 noise
def test_size_range_std_is_d_squared_sigma_l_over_f_L():
    # seed 002 eq. 15: R = (d²/400 000)² m² for f = 40 000 px, L = 10 m, σ_l = 1 px
    sd = size_range_std([5000.0, 2500.0], SL_PX, L_M, F_PX)
    np.testing.assert_allclose(sd, [62.5, 15.625], rtol=1e-15)


# -------------------------------------------------------- §5.3 adaptation statistic
@given(
    a=st.floats(-50.0, 50.0),
    v0=st.floats(-300.0, 300.0),
    window=st.integers(1, 60),
    dt=st.sampled_from([0.01, 0.04, 0.1]),
)
def test_ancv_statistic_of_constant_acceleration_is_acceleration_squared(a, v0, window, dt):
    k = np.arange(80)
    v = v0 + a * k * dt  # velocities of a constant-acceleration motion
    stat = adaptation_statistic(v, dt, model="ncv", window=window)
    assert np.all(np.isnan(stat[:window]))
    np.testing.assert_allclose(stat[window:], a * a, rtol=1e-7, atol=1e-9)


@given(j=st.floats(-200.0, 200.0), a0=st.floats(-50.0, 50.0), window=st.integers(1, 60))
def test_anca_statistic_of_constant_jerk_is_jerk_times_T_squared(j, a0, window):
    t = np.arange(80) * T
    acc = a0 + j * t  # filtered accelerations (source="state")
    stat = adaptation_statistic(acc, T, model="nca", window=window, source="state")
    assert np.all(np.isnan(stat[:window]))
    np.testing.assert_allclose(stat[window:], (j * T) ** 2, rtol=1e-7, atol=1e-12)


@given(j=st.floats(-200.0, 200.0), a0=st.floats(-50.0, 50.0), window=st.integers(1, 60))
def test_anca_velocity_form_of_constant_jerk_is_jerk_times_T_squared(j, a0, window):
    t = np.arange(80) * T
    v = -200.0 + a0 * t + 0.5 * j * t * t  # ALGORITHMS.md §5.3: â from velocity differences
    stat = adaptation_statistic(v, T, model="nca", window=window, source="velocity")
    assert np.all(np.isnan(stat[: window + 1]))
    np.testing.assert_allclose(stat[window + 1 :], (j * T) ** 2, rtol=1e-6, atol=1e-9)


def test_statistic_equals_brute_force_window_mean_on_batched_series():
    rng = np.random.default_rng(1234)
    v = rng.normal(size=(3, 40))
    W = 7
    stat = adaptation_statistic(v, T, model="ncv", window=W)
    for b in range(3):
        for k in range(40):
            if k < W:
                assert np.isnan(stat[b, k])
            else:
                incs = [((v[b, i] - v[b, i - 1]) / T) ** 2 for i in range(k - W + 1, k + 1)]
                assert stat[b, k] == pytest.approx(sum(incs) / W, rel=1e-12)


def test_statistic_is_all_nan_when_the_series_is_shorter_than_the_window():
    assert np.all(np.isnan(adaptation_statistic(np.arange(10.0), T, window=50)))


# ----------------------------------------------------------- fixed NCV / NCA
@pytest.mark.parametrize(("model", "sigma"), [("ncv", 5.0), ("nca", 0.1)])
def test_fixed_noise_filter_matches_filterpy_with_range_dependent_R(model, sigma):
    zs = _approach(150)
    n = 2 if model == "ncv" else 3
    x0, P0 = _start(zs[0], n)
    flt = AdaptiveRangeFilter(model, T, x0, P0, adaptive=False, sigma=sigma, **SIZE_KW)
    res = flt.filter(zs[1:])

    F, Q = (constant_velocity if model == "ncv" else constant_acceleration)(1, T, sigma)
    ref = FilterPyKF(dim_x=n, dim_z=1)
    ref.x = x0.reshape(n, 1).copy()
    ref.P = P0.copy()
    ref.F, ref.Q = F, Q
    ref.H = np.eye(1, n)
    for k, z in enumerate(zs[1:]):
        ref.predict()
        d_pred = ref.x[0, 0]
        R = (d_pred**2 * SL_PX / (F_PX * L_M)) ** 2  # §5.1 at the predicted range
        ref.update(np.array([[z]]), R=np.array([[R]]))
        np.testing.assert_allclose(res.states[k], ref.x[:, 0], rtol=1e-10, atol=1e-8)
        np.testing.assert_allclose(res.covariances[k], ref.P, rtol=1e-8, atol=1e-10)
        assert res.measurement_variances[k] == pytest.approx(R, rel=1e-12)
    assert np.all(res.sigma_v == sigma)


def test_fixed_R_filter_equals_kalman_filter_batch_run():
    from seawatch.filters.kalman import KalmanFilter

    zs = _approach(100)
    x0, P0 = _start(zs[0], 2)
    res = AdaptiveRangeFilter("ncv", T, x0, P0, R=400.0, adaptive=False, sigma=3.0).filter(zs[1:])
    F, Q = constant_velocity(1, T, 3.0)
    ref = KalmanFilter(F, np.eye(1, 2), Q, 400.0, x0, P0).filter(zs[1:, None])
    np.testing.assert_allclose(res.states, ref.states, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(res.predicted_states, ref.predicted_states, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(res.nis, ref.nis, rtol=1e-9, atol=1e-12)


# -------------------------------------------------------- adaptive = fixed cases
@pytest.mark.parametrize("model", ["ncv", "nca"])
def test_adaptive_filter_whose_window_never_fills_equals_the_fixed_filter(model):
    zs = _approach(120, runs=4)
    n = 2 if model == "ncv" else 3
    x0, P0 = _start(zs[:, 0], n)
    s0 = 1.0 if model == "ncv" else 0.01
    adaptive = AdaptiveRangeFilter(model, T, x0, P0, window=500, **SIZE_KW).filter(zs[:, 1:])
    fixed = AdaptiveRangeFilter(model, T, x0, P0, adaptive=False, sigma=s0, **SIZE_KW).filter(
        zs[:, 1:]
    )
    np.testing.assert_array_equal(adaptive.states, fixed.states)
    np.testing.assert_array_equal(adaptive.covariances, fixed.covariances)


def test_adaptive_ncv_pinned_by_floor_and_cap_equals_fixed_ncv():
    zs = _approach(200, runs=3)
    x0, P0 = _start(zs[:, 0], 2)
    pinned = AdaptiveRangeFilter(
        "ncv", T, x0, P0, sigma=5.0, sigma_min=5.0, sigma_max=5.0, window=10, **SIZE_KW
    ).filter(zs[:, 1:])
    fixed = AdaptiveRangeFilter("ncv", T, x0, P0, adaptive=False, sigma=5.0, **SIZE_KW).filter(
        zs[:, 1:]
    )
    assert np.all(np.isfinite(pinned.statistic[:, 20:]))  # the adaptation did run
    np.testing.assert_allclose(pinned.states, fixed.states, rtol=1e-13, atol=1e-9)


# ------------------------------------------------------------ adaptation itself
@pytest.mark.parametrize(
    ("model", "source", "col"), [("ncv", "state", 1), ("nca", "state", 2), ("nca", "velocity", 1)]
)
def test_sigma_history_is_the_clipped_statistic_of_the_filters_own_estimates(model, source, col):
    zs = _approach(160, runs=2)
    n = 2 if model == "ncv" else 3
    x0, P0 = _start(zs[:, 0], n)
    W = 20
    flt = AdaptiveRangeFilter(model, T, x0, P0, window=W, source=source, **SIZE_KW)
    res = flt.filter(zs[:, 1:])
    offline = adaptation_statistic(res.states[..., col], T, model=model, window=W, source=source)
    np.testing.assert_allclose(res.statistic, offline, rtol=1e-9, equal_nan=True)
    expected = np.sqrt(np.clip(offline[:, :-1], flt.sigma_min**2, flt.sigma_max**2))
    expected = np.where(np.isnan(expected), flt.sigma, expected)
    np.testing.assert_allclose(res.sigma_v[:, 1:], expected, rtol=1e-12)
    assert np.all(res.sigma_v[:, 0] == flt.sigma)


def test_ancv_settles_at_the_true_acceleration_of_a_noise_free_ramp():
    # Noise-free constant range acceleration a: in steady state the NCV velocity increments
    # are exactly a T, so the statistic's fixed point is σ_v = |a| (ALGORITHMS.md §5.3).
    t = np.arange(600) * T
    a = 3.0
    d = 5000.0 - 200.0 * t + 0.5 * a * t * t
    flt = AdaptiveRangeFilter(
        "ncv", T, [d[0], -200.0], np.eye(2), R=1e-4, sigma_min=1e-3, sigma_max=1e3
    )
    res = flt.filter(d[1:])
    assert res.sigma_v[-1] == pytest.approx(abs(a), rel=1e-6)


@pytest.mark.parametrize("source", ["state", "velocity"])
def test_anca_settles_at_jerk_times_T_on_a_noise_free_cubic(source):
    t = np.arange(600) * T
    j = 0.5
    d = 5000.0 - 200.0 * t + 1.5 * t * t + j * t**3 / 6.0
    flt = AdaptiveRangeFilter(
        "nca", T, [d[0], -200.0, 3.0], np.eye(3), R=1e-4, sigma_min=1e-6, sigma_max=10.0,
        source=source,
    )  # fmt: skip
    res = flt.filter(d[1:])
    assert res.sigma_v[-1] == pytest.approx(j * T, rel=1e-4)


# ----------------------------------------------------------------- mechanics
def test_batch_of_runs_equals_runs_filtered_one_by_one():
    zs = _approach(120, runs=3)
    x0, P0 = _start(zs[:, 0], 3)
    batch = AdaptiveRangeFilter("nca", T, x0, P0, window=15, **SIZE_KW).filter(zs[:, 1:])
    for b in range(3):
        one = AdaptiveRangeFilter("nca", T, x0[b], P0, window=15, **SIZE_KW).filter(zs[b, 1:])
        np.testing.assert_allclose(batch.states[b], one.states, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(batch.sigma_v[b], one.sigma_v, rtol=1e-12)


def test_step_by_step_equals_filter_and_exposes_current_sigma():
    zs = _approach(90, runs=2)
    x0, P0 = _start(zs[:, 0], 2)
    res = AdaptiveRangeFilter("ncv", T, x0, P0, window=10, **SIZE_KW).filter(zs[:, 1:])
    flt = AdaptiveRangeFilter("ncv", T, x0, P0, window=10, **SIZE_KW)
    for k in range(zs.shape[1] - 1):
        np.testing.assert_array_equal(flt.sigma_v, res.sigma_v[:, k])
        flt.step(zs[:, k + 1])
        np.testing.assert_array_equal(flt.x, res.states[:, k])
    assert flt.R.shape == (2,)
    assert flt.nis.shape == (2,)


def test_one_initial_state_broadcasts_over_many_runs():
    zs = _approach(60, runs=4)
    x0, P0 = _start(5000.0, 2)
    res = AdaptiveRangeFilter("ncv", T, x0, P0, **SIZE_KW).filter(zs)
    assert res.states.shape == (4, 60, 2)
    assert res.sigma_v.shape == (4, 60)
    one = AdaptiveRangeFilter("ncv", T, x0, P0, **SIZE_KW).filter(zs[2])
    np.testing.assert_allclose(res.states[2], one.states, rtol=1e-12)


def test_measured_noise_range_evaluates_R_at_the_measurement():
    zs = _approach(50)
    x0, P0 = _start(zs[0], 2)
    res = AdaptiveRangeFilter("ncv", T, x0, P0, noise_range="measured", **SIZE_KW).filter(zs[1:])
    np.testing.assert_allclose(res.measurement_variances, (zs[1:] ** 2 / 400_000.0) ** 2)
    pred = AdaptiveRangeFilter("ncv", T, x0, P0, **SIZE_KW).filter(zs[1:])
    d_pred = pred.predicted_states[:, 0]
    np.testing.assert_allclose(pred.measurement_variances, (d_pred**2 / 400_000.0) ** 2)


def test_missing_measurement_is_a_predict_only_step_that_leaves_sigma_alone():
    zs = _approach(130, runs=2)
    zs[0, 80:83] = np.nan  # run 0 misses three frames, run 1 does not
    x0, P0 = _start(zs[:, 0], 2)
    res = AdaptiveRangeFilter("ncv", T, x0, P0, window=20, **SIZE_KW).filter(zs[:, 1:])
    assert np.all(np.isfinite(res.states))
    for k in (79, 80, 81):  # frames 80..82 are steps 79..81
        np.testing.assert_allclose(res.states[0, k], res.predicted_states[0, k])
        assert np.isnan(res.nis[0, k])
        assert res.statistic[0, k] == res.statistic[0, 78]
        assert res.sigma_v[0, k + 1] == res.sigma_v[0, k]
    assert np.all(np.isfinite(res.nis[1]))


def test_all_missing_measurements_never_produce_nan_states():
    x0, P0 = _start(5000.0, 3)
    res = AdaptiveRangeFilter("nca", T, x0, P0, **SIZE_KW).filter(np.full(30, np.nan))
    assert np.all(np.isfinite(res.states))
    assert np.all(res.sigma_v == 0.01)


# ---------------------------------------------------------------- bad inputs
GOOD = {"model": "ncv", "dt": T, "x0": [5000.0, 0.0], "P0": np.diag([100.0, 1e4])}


@pytest.mark.parametrize(
    ("change", "name"),
    [
        ({"model": "cv"}, "model"),
        ({"dt": 0.0}, "dt"),
        ({"dt": np.nan}, "dt"),
        ({"x0": [5000.0, 0.0, 0.0]}, "x0"),
        ({"x0": [np.nan, 0.0]}, "x0"),
        ({"P0": np.diag([1.0, -1.0])}, "P0"),
        ({"P0": [[1.0, np.nan], [np.nan, 1.0]]}, "P0"),
        ({"P0": np.eye(3)}, "P0"),
        ({"window": 0}, "window"),
        ({"window": 2.5}, "window"),
        ({"sigma": -1.0}, "sigma"),
        ({"sigma_min": 2.0, "sigma_max": 1.0}, "sigma_min"),
        ({"sigma": 200.0, "sigma_max": 100.0}, "sigma"),
        ({"source": "position"}, "source"),
        ({"noise_range": "true"}, "noise_range"),
        ({"R": 4.0}, "R"),  # R together with sigma_l/size/focal
        ({"R": -4.0, "sigma_l": None, "size": None, "focal": None}, "R"),
        ({"focal": None}, "focal"),
        ({"size": 0.0}, "size"),
    ],
)
def test_bad_constructor_argument_raises_value_error_naming_it(change, name):
    kwargs = {**GOOD, **SIZE_KW, **change}
    with pytest.raises(ValueError, match=name):
        AdaptiveRangeFilter(**kwargs)


def test_bad_measurements_raise_value_error_naming_them():
    flt = AdaptiveRangeFilter(**GOOD, **SIZE_KW)
    with pytest.raises(ValueError, match="z"):
        flt.step([1.0, 2.0])
    with pytest.raises(ValueError, match="z"):
        flt.step(np.inf)
    with pytest.raises(ValueError, match="zs"):
        flt.filter(np.array([5000.0, np.inf]))
    with pytest.raises(ValueError, match="zs"):
        flt.filter(5000.0)
    batch = AdaptiveRangeFilter("ncv", T, np.zeros((3, 2)), np.eye(2), **SIZE_KW)
    with pytest.raises(ValueError, match="zs"):
        batch.filter(np.ones((2, 10)))


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"model": "nca"}, "model"),
        ({"window": -1}, "window"),
        ({"dt": -1.0}, "dt"),
        ({"source": "x"}, "source"),
    ],
)
def test_bad_statistic_argument_raises_value_error_naming_it(kwargs, name):
    args = {"model": "ncv", "window": 5, "dt": T, "source": "state", **kwargs}
    if name == "model":
        args["model"] = "ca"
    with pytest.raises(ValueError, match=name):
        adaptation_statistic(np.arange(10.0), **args)
