"""Tests of the diffuse RLS filters (ALGORITHMS.md §3, seed 000 eqs. 14–20).

Independent truths: noiseless AR processes (exact parameters and continuations), the
batch minimum-norm weighted least-squares solution (``np.linalg.lstsq``), the literal
seed recursion with ``np.linalg.pinv``, batch ridge regression, ``np.roots`` and
``np.unwrap``.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from seawatch.filters.diffuse_rls import (
    DiffuseRLS,
    DiffuseRLSBank,
    DiffuseRLSResult,
    SlidingWindowDiffuseRLS,
    ar_is_stable,
    unwrap_step,
    wrap_angle,
)

# --------------------------------------------------------------------------------------
# references
# --------------------------------------------------------------------------------------


def random_stable_ar(rng: np.random.Generator, p: int) -> np.ndarray:
    """Coefficients a_1..a_p of an AR(p) with random roots of modulus 0.3–0.9."""
    roots: list[complex] = []
    while len(roots) < p:
        r = rng.uniform(0.3, 0.9)
        if p - len(roots) >= 2 and rng.random() < 0.5:
            ang = rng.uniform(0.3, np.pi - 0.3)
            roots += [r * np.exp(1j * ang), r * np.exp(-1j * ang)]
        else:
            roots.append(r * rng.choice([-1.0, 1.0]))
    return -np.poly(roots).real[1:]


def ar_series(a: np.ndarray, c: float, start: np.ndarray, T: int, noise=None) -> np.ndarray:
    """y_t = Σ a_i y_{t−i} + c (+ noise_t), started from the p values ``start``."""
    p = a.size
    y = np.empty(T)
    y[:p] = start
    for t in range(p, T):
        y[t] = sum(a[i] * y[t - 1 - i] for i in range(p)) + c
        if noise is not None:
            y[t] += noise[t]
    return y


def regressor(x: np.ndarray, s: int, p: int, intercept: bool) -> np.ndarray:
    return np.array([x[s - 1 - i] for i in range(p)] + ([1.0] if intercept else []))


def batch_min_norm(x, p, intercept, lam, t, first=None, rows=None, rcond=1e-10):
    """argmin ‖θ‖ over argmin Σ_s λ^(t−s) (x_s − H_s θ)², rows s = max(p, first)..t."""
    lo = p if first is None else max(p, first)
    ss = [s for s in range(lo, t + 1) if rows is None or rows[s]]
    n = p + int(intercept)
    if not ss:
        return np.zeros(n)
    A = np.array([regressor(x, s, p, intercept) for s in ss])
    w = np.sqrt(lam ** (t - np.array(ss, dtype=float)))
    return np.linalg.lstsq(A * w[:, None], x[ss] * w, rcond=rcond)[0]


def seed_recursion(x, p, intercept, lam, rcond=1e-10):
    """Seed 000 eqs. 14–16 literally: W_t = λW + HᵀH, K = W⁺Hᵀ, θ += K(y − Hθ)."""
    n = p + int(intercept)
    W = np.zeros((n, n))
    theta = np.zeros(n)
    out = np.zeros((x.size, n))
    for t in range(x.size):
        W = lam * W
        if t >= p:
            h = regressor(x, t, p, intercept)
            W = W + np.outer(h, h)
            K = np.linalg.pinv(W, rcond=rcond, hermitian=True) @ h
            theta = theta + K * (x[t] - h @ theta)
        out[t] = theta
    return out


def rel_err(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(1.0, np.max(np.abs(b))))


# --------------------------------------------------------------------------------------
# exact recovery without noise (the seed's claim after eq. 16)
# --------------------------------------------------------------------------------------


@given(
    p=st.integers(1, 5),
    seed=st.integers(0, 2**32 - 1),
    intercept=st.booleans(),
    increments=st.booleans(),
)
def test_noiseless_ar_parameters_exact_from_sample_p_plus_n_and_not_before(
    p, seed, intercept, increments
):
    rng = np.random.default_rng(seed)
    a = random_stable_ar(rng, p)
    c = rng.normal() if intercept else 0.0
    n = p + int(intercept)
    T = 2 * p + 14
    x = ar_series(a, c, rng.normal(size=p), T)
    # with increments the AR process is the series of differences of y
    y = np.concatenate([[0.7], 0.7 + np.cumsum(x)]) if increments else x
    off = int(increments)  # y has one sample more than x
    res = DiffuseRLS(p, intercept=intercept, increments=increments).filter(y)
    truth = np.r_[a, [c] if intercept else []]
    t1 = np.arange(1, y.size + 1)  # 1-based sample number
    # rank grows by one per regressor row: rows start at sample p + 1 (+1 with increments)
    expected_rank = np.clip(t1 - p - off, 0, n)
    np.testing.assert_array_equal(res.rank, expected_rank)
    exact_from = p + n + off  # 1-based: 2p (no intercept), 2p + 1 (intercept), +1 incr.
    np.testing.assert_array_equal(res.ready, t1 >= exact_from)
    after = res.parameters[exact_from - 1 :]
    assert rel_err(after, np.broadcast_to(truth, after.shape)) < 1e-8
    before = res.parameters[exact_from - 2]
    assert np.max(np.abs(before - truth)) > 1e-6  # min-norm interpolant, not yet exact


# --------------------------------------------------------------------------------------
# equality with batch min-norm weighted least squares
# --------------------------------------------------------------------------------------


def _series_with_rank_deficient_start(rng, T=90):
    """A constant stretch (rank-1 regressors beyond the first n rows), then noisy AR data."""
    y = np.empty(T)
    y[:12] = 0.4
    y[12:] = ar_series(np.array([1.2, -0.5, 0.2]), 0.05, np.array([0.4, 0.4, 0.4]), T - 9)[3:]
    y[12:] += 0.05 * rng.normal(size=T - 12)
    return y


@pytest.mark.parametrize("lam", [1.0, 0.95])
@pytest.mark.parametrize("intercept", [False, True])
def test_theta_equals_batch_min_norm_weighted_lstsq_including_rank_deficient(lam, intercept):
    rng = np.random.default_rng(1234)
    y = _series_with_rank_deficient_start(rng)
    p = 3
    res = DiffuseRLS(p, lam, intercept=intercept, floor=0.0).filter(y)
    ranks = []
    for t in range(y.size):
        ref = batch_min_norm(y, p, intercept, lam, t)
        assert rel_err(res.parameters[t], ref) < 1e-9, t
        ranks.append(res.rank[t])
    assert ranks[8] == 1  # rank-deficient well beyond the first n rows
    assert ranks[-1] == p + int(intercept)


@pytest.mark.parametrize("lam", [1.0, 0.95])
def test_theta_equals_literal_seed_recursion_eqs_14_to_16(lam):
    rng = np.random.default_rng(1234)
    y = _series_with_rank_deficient_start(rng)
    ref = seed_recursion(y, 3, True, lam)
    res = DiffuseRLS(3, lam, intercept=True, floor=0.0).filter(y)
    assert rel_err(res.parameters, ref) < 1e-9


@pytest.mark.parametrize("lam", [1.0, 0.98])
def test_near_constant_angle_series_matches_lstsq_where_normal_equations_fail(lam):
    # §3.5 pitfall: nearly collinear lags. cond(A) ≈ 1e5, so cond(W = AᵀA) ≈ 1e10 and
    # pinv(W, 1e-10) in eqs. 14–16 drops a direction; the square-root form does not.
    rng = np.random.default_rng(1234)
    T, p = 300, 3
    y = 0.5 + 1e-3 * np.arange(T) + 1e-5 * rng.normal(size=T)
    ref = np.array([batch_min_norm(y, p, False, lam, t) for t in range(T)])
    ours = DiffuseRLS(p, lam, floor=0.0).filter(y).parameters
    assert rel_err(ours[20:], ref[20:]) < 1e-8
    assert rel_err(seed_recursion(y, p, False, lam)[20:], ref[20:]) > 1e-3


def test_floor_gives_batch_ridge_solution_once_full_rank():
    rng = np.random.default_rng(1234)
    y = ar_series(np.array([1.5, -0.7]), 0.0, rng.normal(size=2), 120, rng.normal(size=120))
    lam, floor, p = 0.9, 1e-3, 2  # a large floor so that its effect is visible
    res = DiffuseRLS(p, lam, floor=floor).filter(y)
    for t in range(p + p - 1, y.size):
        ss = np.arange(p, t + 1)
        A = np.array([regressor(y, s, p, False) for s in ss])
        w = lam ** (t - ss)
        W = A.T @ (w[:, None] * A)
        b = A.T @ (w * y[ss])
        delta = floor * np.trace(W) / p
        ridge = np.linalg.solve(W + delta * np.eye(p), b)
        assert rel_err(res.parameters[t], ridge) < 1e-9, t


def test_floor_limits_windup_after_long_unexcited_stretch():
    rng = np.random.default_rng(1234)
    T0, L = 100, 350
    x = np.zeros(T0 + L + 20)
    x[:2] = rng.normal(size=2)
    for t in range(2, T0):
        x[t] = 1.5 * x[t - 1] - 0.7 * x[t - 2] + rng.normal()
    x[T0:] = x[T0 - 1]  # no excitation: W shrinks like 0.9^t off the (1, 1) direction
    k = T0 + L
    x[k] += 1e-3  # one slightly exciting sample
    jumps = {}
    for floor in (0.0, 1e-8):
        par = DiffuseRLS(2, 0.9, floor=floor).filter(x).parameters
        jumps[floor] = np.max(np.abs(par[k + 1] - par[k - 1]))
        assert np.all(np.isfinite(par))
    assert jumps[0.0] > 1.0  # wind-up: a 1e-3 disturbance swings θ by O(1)
    assert jumps[1e-8] < 0.25 * jumps[0.0]


# --------------------------------------------------------------------------------------
# forecasts (seed eq. 20)
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("p", [1, 2, 3, 4, 5])
@pytest.mark.parametrize("intercept", [False, True])
@pytest.mark.parametrize("sliding", [False, True])
def test_forecast_of_noiseless_ar_equals_true_continuation(p, intercept, sliding):
    rng = np.random.default_rng(1234 + p)
    a = random_stable_ar(rng, p)
    c = 0.3 if intercept else 0.0
    J, T = 20, 2 * p + 8  # a stable AR decays: forecast while the data still excite it
    full = ar_series(a, c, rng.normal(size=p), T + J)
    f = (
        SlidingWindowDiffuseRLS(p, 2 * p + 4, intercept=intercept)
        if sliding
        else DiffuseRLS(p, intercept=intercept)
    )
    for v in full[:T]:
        f.update(v)
    fc = f.forecast(J)
    assert f.last_forecast_stable is True
    assert f.ready
    np.testing.assert_allclose(fc, full[T:], rtol=0, atol=1e-8 * max(1, np.max(np.abs(full))))
    # the whole-series path stores the same forecasts
    res = f.filter(full[:T], horizon=J)
    np.testing.assert_allclose(res.forecasts[-1], fc, rtol=0, atol=1e-12)


@pytest.mark.parametrize("order", [1, 3, 5])
@pytest.mark.parametrize("sliding", [False, True])
def test_forecast_of_linear_ramp_with_increments_is_exact(order, sliding):
    t = np.arange(60)
    ramp = 0.3 + 0.01 * t
    f = (
        SlidingWindowDiffuseRLS(order, 20, increments=True)
        if sliding
        else DiffuseRLS(order, increments=True)
    )
    for v in ramp[:45]:
        f.update(v)
    np.testing.assert_allclose(f.forecast(15), ramp[45:], rtol=0, atol=1e-12)
    assert f.last_forecast_stable is True


def test_unstable_ar_forecast_falls_back_to_constant_rate():
    y = ar_series(np.array([1.1]), 0.0, np.array([0.5]), 12)  # root 1.1: explosive
    f = DiffuseRLS(1)
    for v in y:
        f.update(v)
    np.testing.assert_allclose(f.theta, [1.1], rtol=1e-12)
    fc = f.forecast(5)
    assert f.last_forecast_stable is False
    rate = y[-1] - y[-2]  # mean increment of the last p = 1 samples
    np.testing.assert_allclose(fc, y[-1] + rate * np.arange(1, 6), rtol=1e-12)


@given(coeffs=st.lists(st.floats(-2.5, 2.5), min_size=1, max_size=8))
def test_ar_is_stable_agrees_with_np_roots(coeffs):
    a = np.array(coeffs)
    modulus = np.max(np.abs(np.roots(np.r_[1.0, -a])))
    margin = 1e-6
    if abs(modulus - (1 + margin)) < 1e-6:
        return  # too close to the boundary to decide in floating point
    assert ar_is_stable(a, margin) == (modulus < 1 + margin)


# --------------------------------------------------------------------------------------
# sliding window (seed eqs. 17–19)
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("lam", [1.0, 0.95])
@pytest.mark.parametrize("intercept", [False, True])
@pytest.mark.parametrize("increments", [False, True])
def test_sliding_window_equals_lstsq_on_last_window_samples(lam, intercept, increments):
    rng = np.random.default_rng(1234)
    T, p, M = 100, 3, 12
    y = np.cumsum(rng.normal(size=T))
    if not increments:
        y[40] = np.nan  # a missing sample: no row, regressors use the prediction
    # a leading missing sample must not shift the window
    f = SlidingWindowDiffuseRLS(p, M, lam, intercept=intercept, increments=increments)
    res = f.filter(np.r_[np.nan, y])
    par = res.parameters[1:]
    if increments:
        x, rows, par = np.diff(y), np.ones(T - 1, bool), par[1:]  # x_s = y_{s+1} − y_s
    else:
        x = np.where(np.isnan(y), res.filtered[1:], y)  # effective series (fitted form)
        rows = np.isfinite(y)
    for t in range(x.size):
        if not rows[t]:
            np.testing.assert_array_equal(par[t], par[t - 1])
            continue
        ref = batch_min_norm(x, p, intercept, lam, t, first=t - M + 1, rows=rows)
        assert rel_err(par[t], ref) < 1e-9, t


def test_sliding_window_recovers_from_impulse_burst_faster_than_growing_memory():
    rng = np.random.default_rng(1234)
    T, burst = 900, slice(300, 320)
    x = np.zeros(T)
    for t in range(2, T):
        x[t] = 1.6 * x[t - 1] - 0.8 * x[t - 2] + rng.normal(scale=0.1)
    y = x.copy()
    y[burst] += rng.normal(scale=5.0, size=20)  # impulse noise (seed Fig. 5)
    truth = np.array([1.6, -0.8])

    def error(res: DiffuseRLSResult) -> np.ndarray:
        return np.max(np.abs(res.parameters - truth), axis=1)

    def recovery(res: DiffuseRLSResult) -> int:
        """Samples after the burst until θ is back within 0.1 of the truth (T if never)."""
        good = np.nonzero(error(res)[burst.stop :] < 0.1)[0]
        return int(good[0]) if good.size else T

    grow = DiffuseRLS(2).filter(y)
    slide = SlidingWindowDiffuseRLS(2, 60).filter(y)
    assert error(grow)[299] < 0.1 and error(slide)[299] < 0.1  # both fine before
    assert error(slide)[burst.stop] > 0.5 and error(grow)[burst.stop] > 0.5  # both upset
    assert recovery(slide) <= 60 + 40  # the burst leaves the window
    assert recovery(grow) > 3 * recovery(slide)
    assert np.median(error(slide)[400:]) < 0.1 < np.median(error(grow)[400:])


# --------------------------------------------------------------------------------------
# angles
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("cls", [DiffuseRLS, SlidingWindowDiffuseRLS])
def test_azimuth_crossing_pi_is_unwrapped_without_jump(cls):
    rng = np.random.default_rng(1234)
    t = np.arange(300)
    truth = 3.0 + 0.002 * t  # crosses +π at t ≈ 71
    meas = wrap_angle(truth + 1e-4 * rng.normal(size=t.size))
    assert np.max(np.abs(np.diff(meas))) > 6  # the input jumps by 2π
    kw = {"window": 40} if cls is SlidingWindowDiffuseRLS else {}
    res = cls(3, angle=True, **kw).filter(meas)
    assert np.all(res.filtered > -np.pi) and np.all(res.filtered <= np.pi)
    steps = wrap_angle(np.diff(res.filtered))
    assert np.max(np.abs(steps)) < 0.01
    np.testing.assert_array_less(np.abs(wrap_angle(res.filtered - truth))[10:], 1e-3)
    assert np.all(np.abs(res.parameters[-1]) < 10)  # fitted in unwrapped space


def test_azimuth_ramp_forecast_across_pi_is_exact_and_wrapped():
    t = np.arange(80)
    truth = 2.9 + 0.01 * t  # crosses π at t ≈ 24
    f = DiffuseRLS(2, increments=True, angle=True)
    for v in wrap_angle(truth[:20]):
        f.update(v)
    fc = f.forecast(30)
    np.testing.assert_allclose(fc, wrap_angle(truth[20:50]), rtol=0, atol=1e-12)
    assert np.all(fc > -np.pi) and np.all(fc <= np.pi)


def test_unwrap_step_matches_np_unwrap_and_wrap_angle_range():
    rng = np.random.default_rng(1234)
    walk = np.cumsum(rng.uniform(-2.5, 2.5, size=500))
    wrapped = wrap_angle(walk)
    assert np.all(wrapped > -np.pi) and np.all(wrapped <= np.pi)
    np.testing.assert_allclose(np.cos(wrapped - walk), 1.0, atol=1e-12)
    assert wrap_angle(np.pi) == np.pi and wrap_angle(-np.pi) == np.pi
    out = [wrapped[0]]
    for v in wrapped[1:]:
        out.append(unwrap_step(out[-1], v))
    np.testing.assert_allclose(out, np.unwrap(wrapped), rtol=0, atol=1e-9)


# --------------------------------------------------------------------------------------
# missing samples, model form, streaming vs batch
# --------------------------------------------------------------------------------------


def test_missing_sample_is_predict_only_and_feeds_prediction_to_regressors():
    rng = np.random.default_rng(1234)
    T, p, k = 60, 2, 30
    y = ar_series(np.array([1.5, -0.7]), 0.0, rng.normal(size=2), T, 0.1 * rng.normal(size=T))
    y[k] = np.nan
    res = DiffuseRLS(p).filter(y)
    np.testing.assert_array_equal(res.parameters[k], res.parameters[k - 1])
    h = regressor(y, k, p, False)
    pred = h @ res.parameters[k - 1]
    assert res.filtered[k] == pytest.approx(pred, rel=1e-12)
    x = y.copy()
    x[k] = pred
    rows = np.isfinite(y)
    for t in range(k, T):
        assert rel_err(res.parameters[t], batch_min_norm(x, p, False, 1.0, t, rows=rows)) < 1e-9


def test_leading_missing_samples_give_nan_then_start_cleanly():
    y = np.r_[np.nan, np.nan, ar_series(np.array([0.8]), 0.0, np.array([1.0]), 10)]
    f = DiffuseRLS(1)
    out = [f.update(None if i == 0 else v) for i, v in enumerate(y)]
    assert np.isnan(out[0]) and np.isnan(out[1])
    assert np.all(np.isfinite(out[2:]))
    np.testing.assert_allclose(f.theta, [0.8], rtol=1e-12)
    assert f.n_samples == y.size


def test_model_form_runs_fitted_model_on_its_own_estimates_seed_eq_20():
    rng = np.random.default_rng(1234)
    T, p = 80, 2
    y = ar_series(np.array([1.5, -0.7]), 0.0, rng.normal(size=2), T, 0.05 * rng.normal(size=T))
    fitted = DiffuseRLS(p).filter(y)
    model = DiffuseRLS(p, filtered="model").filter(y)
    np.testing.assert_array_equal(model.parameters, fitted.parameters)  # same estimation
    first_ready = int(np.argmax(fitted.ready))
    ref = y.copy()  # measured values until W first reaches full rank
    for t in range(first_ready, T):
        ref[t] = sum(fitted.parameters[t, i] * ref[t - 1 - i] for i in range(p))
    np.testing.assert_allclose(model.filtered, ref, rtol=1e-10, atol=1e-12)
    # fitted form: H_t θ_t with measured regressors
    for t in range(p, T):
        assert fitted.filtered[t] == pytest.approx(
            regressor(y, t, p, False) @ fitted.parameters[t], rel=1e-12, abs=1e-14
        )


def test_model_form_reproduces_noiseless_ar_exactly():
    rng = np.random.default_rng(1234)
    y = ar_series(random_stable_ar(rng, 3), 0.0, rng.normal(size=3), 50)
    res = DiffuseRLS(3, filtered="model").filter(y)
    np.testing.assert_allclose(res.filtered, y, rtol=0, atol=1e-9)


@pytest.mark.parametrize("cls", [DiffuseRLS, SlidingWindowDiffuseRLS])
@pytest.mark.parametrize("form", ["fitted", "model"])
@pytest.mark.parametrize("increments", [False, True])
def test_streaming_update_equals_whole_series_filter(cls, form, increments):
    rng = np.random.default_rng(1234)
    y = wrap_angle(np.cumsum(0.3 * rng.normal(size=70)))
    y[[5, 20, 21, 50]] = np.nan
    kw = {"window": 15} if cls is SlidingWindowDiffuseRLS else {}
    f = cls(3, forgetting=0.97, filtered=form, increments=increments, angle=True, **kw)
    res = f.filter(y, horizon=4)
    for t, v in enumerate(y):
        out = f.update(v)
        assert out == res.filtered[t] or (np.isnan(out) and np.isnan(res.filtered[t]))
        np.testing.assert_array_equal(f.theta, res.parameters[t])
        assert f.ready == res.ready[t] and f.rank == res.rank[t]
        np.testing.assert_array_equal(f.forecast(4), res.forecasts[t])
        assert f.last_forecast_stable == res.forecast_stable[t]
    assert f.n_samples == y.size and f.filtered == res.filtered[-1]


def test_leading_batch_axes_run_each_series_independently():
    rng = np.random.default_rng(1234)
    ys = np.cumsum(rng.normal(size=(2, 3, 50)), axis=-1)
    f = SlidingWindowDiffuseRLS(2, 10, intercept=True)
    res = f.filter(ys, horizon=3)
    assert res.filtered.shape == (2, 3, 50)
    assert res.parameters.shape == (2, 3, 50, 3)
    assert res.ready.shape == res.rank.shape == (2, 3, 50)
    assert res.forecasts.shape == (2, 3, 50, 3)
    one = f.filter(ys[1, 2], horizon=3)
    np.testing.assert_array_equal(res.parameters[1, 2], one.parameters)
    np.testing.assert_array_equal(res.forecasts[1, 2], one.forecasts)
    assert f.filter(ys[0, 0]).forecasts is None


# --------------------------------------------------------------------------------------
# bad input and speed
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"order": 0}, "order"),
        ({"order": -1}, "order"),
        ({"order": 2.5}, "order"),
        ({"order": True}, "order"),
        ({"order": 2, "forgetting": 0.0}, "forgetting"),
        ({"order": 2, "forgetting": 1.01}, "forgetting"),
        ({"order": 2, "forgetting": float("nan")}, "forgetting"),
        ({"order": 2, "filtered": "smoothed"}, "filtered"),
        ({"order": 2, "rcond": 0.0}, "rcond"),
        ({"order": 2, "floor": -1e-8}, "floor"),
        ({"order": 2, "stability_margin": -1.0}, "stability_margin"),
    ],
)
def test_bad_constructor_arguments_raise_naming_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=name):
        DiffuseRLS(**kwargs)


@pytest.mark.parametrize("window", [0, 3, 2.0, None])
def test_window_shorter_than_order_plus_one_is_rejected(window):
    with pytest.raises(ValueError, match="window"):
        SlidingWindowDiffuseRLS(3, window)
    SlidingWindowDiffuseRLS(3, 4)  # order + 1 is the shortest allowed


@pytest.mark.parametrize("steps", [float("nan"), float("inf"), 0, -2, 2.5, "3", True])
def test_non_finite_or_non_integer_forecast_steps_are_rejected(steps):
    f = DiffuseRLS(2)
    for v in (0.1, 0.2, 0.3, 0.5):
        f.update(v)
    with pytest.raises(ValueError, match="steps"):
        f.forecast(steps)
    assert f.forecast(3.0).shape == (3,)


def test_bad_measurements_are_rejected():
    f = DiffuseRLS(2)
    with pytest.raises(ValueError, match="y"):
        f.update(float("inf"))
    with pytest.raises(ValueError, match="y"):
        f.update("north")
    with pytest.raises(ValueError, match="ys"):
        f.filter([0.1, np.inf, 0.3])
    with pytest.raises(ValueError, match="ys"):
        f.filter(0.1)
    with pytest.raises(ValueError, match="ys"):
        f.filter(np.zeros((3, 0)))
    with pytest.raises(ValueError, match="horizon"):
        f.filter([0.1, 0.2], horizon=0)
    assert f.n_samples == 0


# ----------------------------------------------------------------------------- many streams
@pytest.mark.parametrize("sliding", [False, True])
def test_bank_equals_one_filter_per_stream_with_gaps_restarts_and_forecasts(sliding):
    """Every slot of a DiffuseRLSBank behaves exactly as its own DiffuseRLS (angle and
    level channels), with missing samples, NaN samples, restarts, a grown bank and slots
    advanced in any order or not at all."""
    rng = np.random.default_rng(42)
    if sliding:
        make = [
            lambda: SlidingWindowDiffuseRLS(3, 40, angle=True),
            lambda: SlidingWindowDiffuseRLS(3, 40),
        ]
    else:
        make = [lambda: DiffuseRLS(3, 0.99, angle=True), lambda: DiffuseRLS(3, 0.99)]
    bank = DiffuseRLSBank([m() for m in make], slots=2)
    refs: dict[int, list] = {}
    steps = np.array([1, 4, 9])
    for k in range(160):
        if k == 60:
            bank.grow(5)  # existing streams are kept
        n_slots = 2 if k < 60 else 5
        slots = rng.permutation(n_slots)[: rng.integers(1, n_slots + 1)]
        y = np.column_stack(
            [np.pi - 0.3 + 0.01 * k + 0.01 * rng.standard_normal(slots.size),  # crosses ±π
             10.0 + np.sin(0.1 * k + slots) + 0.05 * rng.standard_normal(slots.size)]
        )  # fmt: skip
        y[:, 0] = (y[:, 0] + np.pi) % (2 * np.pi) - np.pi
        y[rng.random(slots.size) < 0.1, 1] = np.nan
        missing = rng.integers(0, 3, slots.size) * (rng.random(slots.size) < 0.2)
        reset = rng.random(slots.size) < 0.02
        filt, fc, ok = bank.step(slots, y, missing=missing, reset=reset, steps=steps)
        for i, s in enumerate(slots):
            if s not in refs or reset[i]:
                refs[int(s)] = [m() for m in make]
            stable = True
            for c, ref in enumerate(refs[int(s)]):
                for _ in range(missing[i]):
                    ref.update(np.nan)
                v = ref.update(y[i, c])
                np.testing.assert_allclose(filt[i, c], v, rtol=1e-12, atol=1e-12)
                if ref.rank == ref.n_params:
                    f = ref.forecast(int(steps.max()))[steps - 1]
                    np.testing.assert_allclose(fc[i, :, c], f, rtol=1e-12, atol=1e-12)
                    stable = stable and ref.last_forecast_stable
                else:
                    assert np.all(np.isnan(fc[i, :, c]))
                    stable = False
            assert ok[i] == stable


def test_bank_clear_is_the_diffuse_start_and_bad_inputs_name_themselves():
    bank = DiffuseRLSBank([DiffuseRLS(2)], slots=3)
    for k in range(10):
        bank.step([0, 1], [[float(k)], [2.0 * k]])
    bank.clear([1])
    filt, _, _ = bank.step([1], [[5.0]])
    fresh = DiffuseRLS(2)
    assert filt[0, 0] == fresh.update(5.0)
    with pytest.raises(ValueError, match="templates"):
        DiffuseRLSBank([DiffuseRLS(2), DiffuseRLS(3)])
    with pytest.raises(ValueError, match="templates"):
        DiffuseRLSBank([])
    with pytest.raises(ValueError, match="slots"):
        bank.step([3], [[1.0]])
    with pytest.raises(ValueError, match="slots"):
        bank.step([0, 0], [[1.0], [1.0]])
    with pytest.raises(ValueError, match="samples"):
        bank.step([0], [[1.0, 2.0]])
    with pytest.raises(ValueError, match="missing"):
        bank.step([0], [[1.0]], missing=[-1])
    with pytest.raises(ValueError, match="steps"):
        bank.step([0], [[1.0]], steps=[0])
    with pytest.raises(ValueError, match="slots"):
        bank.grow(2)  # cannot shrink
