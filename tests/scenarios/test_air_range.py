"""Tests of the ``air-range`` scenario (SCENARIOS.md, seed 002)."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter as FilterPyKF
from scipy.linalg import solve_discrete_are

from seawatch.metrics.crlb import PCRBResult
from seawatch.models.kinematic import constant_acceleration, constant_velocity
from seawatch.scenarios import air_range as ar

G = 9.80665
ESTIMATORS = [
    "raw", "ncv-1", "ncv-5", "ncv-10", "nca-0.001", "nca-0.01", "nca-0.1", "ancv", "anca",
]  # fmt: skip
FIXED = [e for e in ESTIMATORS if e.startswith(("ncv", "nca"))]
SPEC = {s.name: s for s in ar.ESTIMATORS}


@pytest.fixture(scope="module")
def truth() -> ar.AirRangeTrajectory:
    return ar.trajectory()


@pytest.fixture(scope="module")
def result() -> ar.AirRangeResult:
    return ar.run(runs=100, seed=0)


def _mean(result: ar.AirRangeResult, est: str, metric: str) -> tuple[float, float]:
    rec = result.record(est, metric)
    return rec["mean"], rec["stderr"]


# ------------------------------------------------------------------ geometry
def test_trajectory_starts_at_5_km_range_with_25_frames_per_second(truth):
    assert truth.range[0] == pytest.approx(5000.0, abs=1e-9)
    np.testing.assert_allclose(np.diff(truth.time), 0.04, rtol=1e-12)


def test_level_flight_has_1000_m_miss_distance_300_m_height_and_200_m_per_s(truth):
    level = truth.time < truth.pullup_time
    p = truth.position[level]
    np.testing.assert_allclose(p[:, 1], 1000.0)  # horizontal offset of the flight line
    np.testing.assert_allclose(p[:, 2], 300.0)  # height
    # the straight line's closest horizontal approach to the camera is the miss distance
    np.testing.assert_allclose(np.diff(p[:, 0]) / 0.04, 200.0, rtol=1e-10)
    assert np.min(np.hypot(p[:, 0], p[:, 1])) > 1000.0
    assert np.all(p[:, 0] < 0.0)  # not yet past the camera


def test_pullup_starts_at_2500_m_range(truth):
    t_p = truth.pullup_time
    # independent recomputation: straight line at 200 m/s from the 5 km start point
    x_start = -math.sqrt(5000.0**2 - 1000.0**2 - 300.0**2)
    x = x_start + 200.0 * t_p
    assert math.sqrt(x * x + 1000.0**2 + 300.0**2) == pytest.approx(2500.0, abs=1e-6)
    level = truth.time < t_p
    assert truth.range[level][-1] > 2500.0 > truth.range[~level][0]


def test_pullup_acceleration_is_3_g_from_second_differences_of_positions(truth):
    p, dt = truth.position, truth.dt
    acc = (p[2:] - 2.0 * p[1:-1] + p[:-2]) / dt**2  # central differences of the sampled path
    t_mid = truth.time[1:-1]
    arc = t_mid > truth.pullup_time + dt
    level = t_mid < truth.pullup_time - dt
    np.testing.assert_allclose(np.linalg.norm(acc[arc], axis=1), 3.0 * G, rtol=1e-4)
    np.testing.assert_allclose(acc[level], 0.0, atol=1e-6)
    assert np.all(acc[arc, 2] > 0.0)  # upwards: a pull-up in the vertical plane
    np.testing.assert_allclose(np.linalg.norm(truth.velocity, axis=1), 200.0, rtol=1e-12)


def _independent_range(t: float) -> float:
    """Slant range of the resolved path, recomputed from SCENARIOS.md's description."""
    closest2 = 1000.0**2 + 300.0**2
    x_start, x_pull = -math.sqrt(5000.0**2 - closest2), -math.sqrt(2500.0**2 - closest2)
    t_pull = (x_pull - x_start) / 200.0
    if t < t_pull:
        x, z = x_start + 200.0 * t, 300.0
    else:
        rho, w = 200.0**2 / (3 * G), 3 * G / 200.0
        x = x_pull + rho * math.sin(w * (t - t_pull))
        z = 300.0 + rho * (1.0 - math.cos(w * (t - t_pull)))
    return math.sqrt(x * x + 1000.0**2 + z * z)


def test_run_ends_at_the_last_frame_before_the_range_starts_to_grow(truth):
    assert np.all(np.diff(truth.range) < 0.0)
    h = 1e-4
    t_last = truth.time[-1]
    slope_last = _independent_range(t_last + h) - _independent_range(t_last - h)
    slope_next = _independent_range(t_last + 0.04 + h) - _independent_range(t_last + 0.04 - h)
    assert slope_last < 0.0 < slope_next  # the range minimum lies within the next frame
    for k in (0, 100, 327, 400, truth.time.size - 1):
        assert truth.range[k] == pytest.approx(_independent_range(truth.time[k]), rel=1e-12)
    assert truth.range[-1] == pytest.approx(1764.37, abs=0.01)


def test_analytic_range_derivatives_match_finite_differences(truth):
    d, dt = truth.range, truth.dt
    rate_fd = (d[2:] - d[:-2]) / (2 * dt)
    acc_fd = (d[2:] - 2 * d[1:-1] + d[:-2]) / dt**2
    smooth = np.abs(truth.time[1:-1] - truth.pullup_time) > 2 * dt
    # central differences are exact to O(dt² · d''') ≈ 0.0016 · 10 / 6 m/s here
    np.testing.assert_allclose(truth.range_rate[1:-1][smooth], rate_fd[smooth], atol=5e-3)
    np.testing.assert_allclose(
        truth.range_acceleration[1:-1][smooth], acc_fd[smooth], rtol=1e-3, atol=5e-3
    )


def test_bad_geometry_raises_value_error_naming_the_argument():
    with pytest.raises(ValueError, match="pullup_range"):
        ar.trajectory(pullup_range=6000.0)
    with pytest.raises(ValueError, match="dt"):
        ar.trajectory(dt=0.0)
    with pytest.raises(ValueError, match="runs"):
        ar.simulate(runs=0)


# -------------------------------------------------------------- measurements
def test_raw_range_error_std_matches_sigma_d_at_5_and_2_5_km(truth):
    meas = ar.simulate(runs=4000, seed=1234)
    err = meas.range - truth.range
    k25 = int(np.argmin(np.abs(truth.range - 2500.0)))
    for k in (0, k25):
        sigma_d = truth.range[k] ** 2 * 1.0 / (40_000.0 * 10.0)
        # standard error of a std estimate from 4000 samples is ~1.1 %
        assert np.std(err[:, k]) == pytest.approx(sigma_d, rel=0.05)
    assert truth.range[0] ** 2 / 400_000.0 == pytest.approx(62.5)
    assert 2500.0**2 / 400_000.0 == pytest.approx(15.625)


def test_simulation_is_reproducible_from_its_seed():
    a, b, c = ar.simulate(3, seed=7), ar.simulate(3, seed=7), ar.simulate(3, seed=8)
    np.testing.assert_array_equal(a.range, b.range)
    assert not np.array_equal(a.range, c.range)
    np.testing.assert_allclose(a.range * a.image_size, 40_000.0 * 10.0, rtol=1e-12)


# ------------------------------------------------------------------- results
def test_records_have_every_interfaces_name_and_field(result):
    names = [(r["estimator"], r["metric"]) for r in result.records]
    ratios = [f"{m}_over_crlb" for m in ar.METRICS]
    expected = {(e, m) for e in ESTIMATORS for m in (*ar.METRICS, *ratios)}
    expected |= {("crlb", m) for m in ar.METRICS}
    assert len(names) == len(set(names)) and set(names) == expected
    for r in result.records:
        assert set(r) == {"estimator", "metric", "unit", "mean", "stderr", "paper", "params"}
        assert r["unit"] == ("1" if r["metric"] in ratios else "m")
        assert r["mean"] > 0.0
        if r["estimator"] == "crlb":
            assert r["stderr"] is None  # the bound is computed, not sampled
        else:
            assert 0.0 < r["stderr"] < 0.1 * r["mean"]
    assert result.errors["raw"].shape == (100, result.truth.range.size)


def test_rms_errors_are_recomputed_from_the_per_frame_errors(result):
    e = result.errors["ancv"]
    far = result.truth.range > 2500.0
    per_run = np.sqrt(np.mean(e[:, far] ** 2, axis=1))
    mean, se = _mean(result, "ancv", "rmse_range_far")
    assert mean == pytest.approx(per_run.mean(), rel=1e-12)
    assert se == pytest.approx(per_run.std(ddof=1) / 10.0, rel=1e-12)


@pytest.mark.parametrize("est", ESTIMATORS[1:])
def test_every_filter_beats_raw_range_far_from_the_camera(result, est):
    raw, raw_se = _mean(result, "raw", "rmse_range_far")
    m, se = _mean(result, est, "rmse_range_far")
    assert m + 3 * se < raw - 3 * raw_se


@pytest.mark.parametrize(
    "est",
    [
        pytest.param(
            "ncv-1",
            marks=pytest.mark.xfail(
                strict=True,
                reason="σ_v = 1 m/s² cannot follow the 3 g pull-up (range acceleration up to "
                "47 m/s²): near RMS 68.7 m, whole-run 40.6 m against raw 32.1 m (100 runs, seed 0)",
            ),
        ),
        *ESTIMATORS[2:],
    ],
)
def test_filter_beats_raw_range_over_the_whole_run(result, est):
    raw, raw_se = _mean(result, "raw", "rmse_range")
    m, se = _mean(result, est, "rmse_range")
    assert m + 3 * se < raw - 3 * raw_se


@pytest.mark.parametrize(("small", "large"), [("ncv-1", "ncv-10"), ("nca-0.001", "nca-0.1")])
def test_paper_claim_large_sigma_is_better_late(result, small, large):
    m_small, se_small = _mean(result, small, "rmse_range_near")
    m_large, se_large = _mean(result, large, "rmse_range_near")
    assert m_large + 3 * se_large < m_small - 3 * se_small


def _paired(result, a: str, b: str, lo: int, hi: int) -> tuple[float, float, float]:
    """Mean per-run RMS of b, and mean and standard error of (RMS b − RMS a) over runs."""
    ra = np.sqrt(np.mean(result.errors[a][:, lo:hi] ** 2, axis=1))
    rb = np.sqrt(np.mean(result.errors[b][:, lo:hi] ** 2, axis=1))
    diff = rb - ra
    return float(rb.mean()), float(diff.mean()), float(diff.std(ddof=1) / math.sqrt(diff.size))


@pytest.mark.xfail(
    strict=True,
    reason="not reproduced: in the level flight after the larger-σ filter has converged "
    "(convergence_frame, √(P/P_ss) ≤ 1.25: ncv-10 from 4.64 s / 4.10 km, nca-0.1 from 8.44 s "
    "/ 3.37 km; ncv-1 converges only at 15.0 s on the pull-up, nca-0.001 never) ncv-1 is "
    "22 % worse than ncv-10 (6.33 vs 5.17 m, paired difference −1.17 ± 0.08 m) and nca-0.001 "
    "equals nca-0.1 (4.56 vs 4.58 m, +0.02 ± 0.02 m); before that, in the start transient, "
    "all σ_v agree to 0.2 % (100 runs, seed 0)",
)
@pytest.mark.parametrize(("small", "large"), [("ncv-1", "ncv-10"), ("nca-0.001", "nca-0.1")])
def test_paper_claim_small_sigma_is_better_early(result, small, large):
    # "early" as the paper means it: the approach once the filters have left their start
    # transient (the larger σ_v converges first), up to the pull-up; paired over runs, and
    # material (the paper's Figs. 3-4 show a visible difference): at least 5 % lower RMS
    lo = ar.convergence_frame(SPEC[large])
    hi = int(np.sum(result.truth.range > 2500.0))
    assert lo < hi
    rms_large, diff, se = _paired(result, small, large, lo, hi)
    assert diff > 3 * se and diff > 0.05 * rms_large


@pytest.mark.xfail(
    strict=True,
    reason="not reproduced: in the level flight after the adaptation starts (frame 51, "
    "2.04 s, to the pull-up) ANCA is 6.6 % worse than the NCA it starts from (nca-0.01: "
    "8.36 vs 7.84 m, paired −0.52 ± 0.05 m): the first full window holds the diffuse start's "
    "convergence and lifts σ_v from 0.01 to ~1 m/s², a hundred times the truth's change of "
    "range acceleration per frame (0.002-0.024 m/s²), and the filters' errors there are "
    "limited by the start, not by lag (100 runs, seed 0)",
)
def test_paper_claim_anca_is_substantially_better_than_nca_in_the_initial_part(result):
    lo = ar.WINDOW + 1  # first frame predicted with an adapted σ_v
    hi = int(np.sum(result.truth.range > 2500.0))
    rms_nca, diff, se = _paired(result, "anca", "nca-0.01", lo, hi)
    assert diff > 3 * se and diff > 0.10 * rms_nca


def test_paper_claim_both_adaptive_models_estimate_range_about_equally_well(result):
    # seed 002: "both models estimate the range equally well", "about ±10 m"
    ancv, _ = _mean(result, "ancv", "rmse_range")
    anca, _ = _mean(result, "anca", "rmse_range")
    assert abs(ancv - anca) < 0.1 * min(ancv, anca)
    assert 8.0 < ancv < 12.0 and 8.0 < anca < 12.0


@pytest.mark.parametrize("adaptive", ["ancv", "anca"])
@pytest.mark.parametrize("fixed", FIXED)
def test_each_adaptive_filter_beats_every_fixed_noise_filter_over_the_whole_run(
    result, adaptive, fixed
):
    # seawatch's own target (SCENARIOS.md air-range): paired comparison over the same runs
    a = np.sqrt(np.mean(result.errors[adaptive] ** 2, axis=1))
    f = np.sqrt(np.mean(result.errors[fixed] ** 2, axis=1))
    diff = f - a
    assert diff.mean() > 3 * diff.std(ddof=1) / math.sqrt(diff.size)


def test_adaptive_sigma_starts_at_the_papers_values_and_then_adapts(result):
    s_ancv, s_anca = result.sigma_v["ancv"], result.sigma_v["anca"]
    assert np.all(s_ancv[:, 1:51] == 1.0)  # σ_v² = 1 until the 50-frame window is full
    assert np.all(s_anca[:, 1:51] == 0.01)  # σ_v² = 1e-4
    assert np.all(s_ancv[:, -1] != 1.0)
    assert np.all(s_anca[:, -1] != 0.01)
    assert np.all(np.isnan(s_ancv[:, 0]))


# ----------------------------------------------------------------------- demo
def test_run_demo_writes_the_table_the_plot_and_figs_3_to_6(tmp_path):
    calls = []
    demo = ar.run_demo(tmp_path / "out", runs=3, seed=0, progress=lambda d, t: calls.append((d, t)))
    assert demo.table_path == tmp_path / "out" / "errors.csv"
    assert [p.name for p in demo.figure_paths] == list(ar.FIGURES)
    for path in (demo.plot_path, *demo.figure_paths):
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with demo.table_path.open() as fh:
        rows = list(csv.DictReader(fh))
    assert [r["estimator"] for r in rows] == [*ESTIMATORS, "crlb"]
    assert float(rows[0]["rmse_range_m"]) == pytest.approx(demo.rows[0]["rmse_range_m"], abs=1e-4)
    assert rows[-1]["rmse_range_over_crlb"] == ""  # the bound's own row has no ratio
    ratio = float(rows[1]["rmse_range_far_over_crlb"])
    assert ratio == pytest.approx(demo.result.record("ncv-1", "rmse_range_far_over_crlb")["mean"],
                                  abs=1e-4)  # fmt: skip
    assert calls[-1] == (len(ESTIMATORS), len(ESTIMATORS))
    assert [d for d, _ in calls] == list(range(1, len(ESTIMATORS) + 1))


# ---------------------------------------------------------------------- bound
@pytest.fixture(scope="module")
def bound() -> PCRBResult:
    return ar.pcrb()


def test_bound_equals_a_kalman_covariance_with_the_truths_own_process_noise(truth, bound):
    # §7(b): linear-Gaussian, so the PCRB is the covariance of the Kalman filter with the
    # same prior, Q_k and R_k (FilterPy as the independent reference). The process noise
    # is the truth's change of range acceleration per frame, R_k = σ_d(true range)².
    T = truth.dt
    gamma = np.array([T * T / 2.0, T, 1.0])
    kf = FilterPyKF(dim_x=3, dim_z=1)
    kf.F = np.array([[1.0, T, T * T / 2.0], [0.0, 1.0, T], [0.0, 0.0, 1.0]])
    kf.H = np.array([[1.0, 0.0, 0.0]])
    sigma_d = truth.range**2 / (40_000.0 * 10.0)
    # frame 0: diffuse range + the first measurement; rate, acceleration at 1 σ = truth
    kf.P = np.diag([sigma_d[0] ** 2, truth.range_rate[0] ** 2, truth.range_acceleration[0] ** 2])
    np.testing.assert_allclose(bound.bound[0], kf.P, rtol=1e-12)
    jump = np.diff(truth.range_acceleration)
    for k in range(1, truth.range.size):
        kf.predict(Q=jump[k - 1] ** 2 * np.outer(gamma, gamma))
        kf.update(np.array([0.0]), R=np.array([[sigma_d[k] ** 2]]))
        if k in (1, 50, 327, 328, truth.range.size - 1):
            np.testing.assert_allclose(bound.bound[k], kf.P, rtol=1e-7, atol=1e-12)
    assert bound.rmse_bound(0)[0] == pytest.approx(62.5)


def test_bound_never_exceeds_the_single_frame_sigma_d(truth, bound):
    b = bound.rmse_bound(0)
    sigma_d = truth.range**2 / 400_000.0
    assert np.all(b <= sigma_d * (1 + 1e-12))
    assert np.all(b[1:] < sigma_d[1:])  # every later frame adds the past frames' information


def test_crlb_records_are_the_rms_bound_and_the_ratios_pooled_rmse_over_it(result, bound):
    b = bound.rmse_bound(0)
    np.testing.assert_allclose(result.bound, b, rtol=1e-12)
    far = result.truth.range > 2500.0
    for metric, mask in (("rmse_range", np.ones_like(far)), ("rmse_range_far", far),
                         ("rmse_range_near", ~far)):  # fmt: skip
        rms_b = math.sqrt(np.mean(b[mask] ** 2))
        assert result.record("crlb", metric)["mean"] == pytest.approx(rms_b, rel=1e-12)
        e = result.errors["anca"][:, mask]
        pooled = math.sqrt(np.mean(e**2))
        rec = result.record("anca", f"{metric}_over_crlb")
        assert rec["mean"] == pytest.approx(pooled / rms_b, rel=1e-12)


@pytest.mark.parametrize("est", ESTIMATORS)
def test_no_estimator_beats_the_bound_beyond_monte_carlo_error(result, bound, est):
    b2 = bound.rmse_bound(0) ** 2
    e2 = result.errors[est] ** 2
    n = e2.shape[0]
    for lo in range(1, b2.size, 25):  # one-second blocks (frame 0 is the raw range)
        per_run = e2[:, lo : lo + 25].mean(axis=1)  # each run's MSE in the block
        se = per_run.std(ddof=1) / math.sqrt(n)
        # 4 standard errors: a run's errors within one second are nearly a single draw,
        # so the block MSEs are heavy-tailed (seed 0: the NCV filters sit 3.3 se below at
        # 6-7 s, where the exact MSE of the next test is at the bound)
        assert per_run.mean() + 4 * se >= b2[lo : lo + 25].mean(), f"frames {lo}-{lo + 24}"
    for metric in ar.METRICS:
        rec = result.record(est, f"{metric}_over_crlb")
        assert rec["mean"] + 3 * rec["stderr"] >= 1.0


@pytest.mark.parametrize("est", FIXED)
def test_exact_mse_of_each_fixed_noise_filter_is_never_below_the_bound(truth, bound, est):
    # No Monte Carlo: a linear filter (R at the true range) on the deterministic truth has
    # error = bias (from the truth's motion, which its model does not follow) + noise with
    # a covariance that the recursion below propagates exactly.
    spec = SPEC[est]
    T = truth.dt
    n = 2 if spec.model == "ncv" else 3
    F = np.array([[1.0, T, T * T / 2], [0.0, 1.0, T], [0.0, 0.0, 1.0]])[:n, :n]
    g = np.array([T * T / 2, T, 1.0])[:n] if n == 3 else np.array([T * T / 2, T])
    Q = spec.sigma**2 * np.outer(g, g)
    R = (truth.range**2 / 400_000.0) ** 2
    x = np.stack([truth.range, truth.range_rate, truth.range_acceleration], axis=1)[:, :n]
    P = np.diag([R[0], 300.0**2, 10.0**2][:n])  # the scenario's start, x0 = [z0, 0(, 0)]
    bias = np.concatenate([[0.0], -x[0, 1:]])
    C = np.zeros((n, n))
    C[0, 0] = R[0]
    mse = np.empty(truth.range.size)
    mse[0] = R[0]
    for k in range(1, mse.size):
        P = F @ P @ F.T + Q
        K = P[:, 0] / (P[0, 0] + R[k])
        A = np.eye(n) - np.outer(K, np.eye(n)[0])
        bias = A @ (F @ bias - (x[k] - F @ x[k - 1]))
        C = A @ F @ C @ F.T @ A.T + np.outer(K, K) * R[k]
        P = A @ P
        mse[k] = bias[0] ** 2 + C[0, 0]
    assert np.all(np.sqrt(mse) >= (1 - 1e-3) * bound.rmse_bound(0))


def test_steady_state_variance_matches_scipys_riccati_solution():
    for make, sigma in ((constant_velocity, 1.0), (constant_acceleration, 0.1)):
        F, Q = make(1, 0.04, sigma)
        R = np.array([62.5**2, 15.6**2, 2.0**2])
        got = ar.steady_state_variance(F, Q, R)
        h = np.zeros((F.shape[0], 1))
        h[0, 0] = 1.0
        for r, p in zip(R, got, strict=True):
            Pp = solve_discrete_are(F.T, h, Q, np.array([[r]]))[0, 0]
            assert p == pytest.approx(Pp - Pp**2 / (Pp + r), rel=1e-9)
    with pytest.raises(ValueError, match="R"):
        ar.steady_state_variance(F, Q, [0.0])
    with pytest.raises(ValueError, match="Q"):
        ar.steady_state_variance(F, -Q, [1.0])  # not positive semi-definite
    with pytest.raises(ValueError, match="F"):
        ar.steady_state_variance(F[:2], Q, [1.0])


def test_convergence_frame_is_the_first_frame_within_the_tolerance_of_steady_state(truth):
    frames = {n: ar.convergence_frame(SPEC[n]) for n in FIXED}
    # a larger process noise forgets the diffuse start sooner
    assert frames["ncv-10"] < frames["ncv-5"] < frames["ncv-1"]
    assert frames["nca-0.1"] < frames["nca-0.01"] <= frames["nca-0.001"]
    # independent recomputation for ncv-10: FilterPy covariance, SciPy Riccati solution
    k_c, T = frames["ncv-10"], truth.dt
    sigma_d = truth.range**2 / 400_000.0
    kf = FilterPyKF(dim_x=2, dim_z=1)
    kf.F = np.array([[1.0, T], [0.0, 1.0]])
    kf.H = np.array([[1.0, 0.0]])
    kf.Q = 100.0 * np.array([[T**4 / 4, T**3 / 2], [T**3 / 2, T**2]])
    kf.P = np.diag([sigma_d[0] ** 2, 300.0**2])
    ratios = []
    for k in range(1, k_c + 1):
        kf.predict()
        kf.update(np.array([0.0]), R=np.array([[sigma_d[k] ** 2]]))
        if k >= k_c - 1:
            Pp = solve_discrete_are(kf.F.T, kf.H.T, kf.Q, np.array([[sigma_d[k] ** 2]]))[0, 0]
            ratios.append(math.sqrt(kf.P[0, 0] / (Pp - Pp**2 / (Pp + sigma_d[k] ** 2))))
    assert ratios[0] > 1.25 >= ratios[1]


def test_convergence_frame_rejects_adaptive_filters_and_tolerances_up_to_one():
    with pytest.raises(ValueError, match="spec"):
        ar.convergence_frame(SPEC["ancv"])
    with pytest.raises(ValueError, match="tolerance"):
        ar.convergence_frame(SPEC["ncv-1"], tolerance=1.0)


def test_window_means_follow_the_papers_eqs_16_and_23(result):
    meas = ar.simulate(2, seed=0)  # runs 0 and 1 of the result fixture
    for name, k in (("ncv-5", 60), ("nca-0.01", 200)):
        spec = SPEC[name]
        res = ar.make_filter(spec, meas.range[:, 0]).filter(meas.range[:, 1:])
        # frames 1..N-1 are res.states[:, 0..N-2]; the window ends at frame k
        if spec.model == "ncv":
            v = res.states[:, k - 51 : k, 1]  # v̂ at frames k-50 .. k
            expected = np.mean(np.diff(v, axis=1) / 0.04, axis=1)  # eq. 16
        else:
            a = res.states[:, k - 51 : k, 2]
            expected = np.mean(np.diff(a, axis=1), axis=1)  # eq. 23
        got = result.window_mean[name][:2, k]
        np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-12)
        assert np.all(np.isnan(result.window_mean[name][:, :50]))
