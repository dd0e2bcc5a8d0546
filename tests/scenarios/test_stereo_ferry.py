"""Scenario ``stereo-ferry`` (seed 003): stereo ranging + KF / STKF / stereo-initialised STKF.

SCENARIOS.md ``stereo-ferry``; ALGORITHMS.md §2, §6. The truths used here are
independent of the code under test: the seed's own pixel coordinates and figures, a
brute-force Monte Carlo of the triangulation, OpenCV's ``correctMatches``, a truth
simulated in the test with the filter's own model, and Table 3 of the paper.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import math

import cv2
import numpy as np
import pytest

from seawatch.camera import SEED003_CALIBRATION, triangulate
from seawatch.scenarios import stereo_ferry as sf
from seawatch.scenarios.base import ExperimentResult

TABLE3 = {  # seed 003 Table 3: (position, speed) RMSE of the one-step prediction error
    1: {"kf": (1.3901, 0.1329), "stkf": (0.3706, 0.1054), "stereo-stkf": (0.3373, 0.0911)},
    2: {"kf": (1.0992, 0.2645), "stkf": (0.8218, 0.1606), "stereo-stkf": (0.5579, 0.1258)},
}
RUNS = 12


@pytest.fixture(scope="module")
def result(tmp_path_factory: pytest.TempPathFactory) -> tuple[ExperimentResult, object]:
    out = tmp_path_factory.mktemp("stereo_ferry")
    return sf.run(runs=RUNS, seed=0, out_dir=out, late_fading=True), out


@pytest.fixture(scope="module")
def result_stereo_prior() -> ExperimentResult:
    return sf.run(runs=RUNS, seed=0, variant="stereo-prior")


def _paired(values_a: np.ndarray, values_b: np.ndarray) -> tuple[float, float]:
    """Mean and standard error of the paired difference a − b over runs."""
    d = values_a - values_b
    return float(np.mean(d)), float(np.std(d, ddof=1) / math.sqrt(d.size))


# ----------------------------------------------------------------------------- the seed
def test_seed_exp1_point2_path_is_26_4507_m_with_the_inhomogeneous_least_squares() -> None:
    # seed 003 §5.3: pixels of frames 1 and 400, linearly interpolated over 400 frames
    t = np.linspace(0.0, 1.0, 400)[:, None]
    left = np.array([416.587, 110.500]) * (1 - t) + np.array([67.891, 111.370]) * t
    right = np.array([448.761, 108.761]) * (1 - t) + np.array([53.978, 111.370]) * t
    X = triangulate(SEED003_CALIBRATION.projection_matrices(), [left, right], "inhomogeneous")
    path_m = np.sum(np.linalg.norm(np.diff(X / 1000.0, axis=0), axis=1))
    assert path_m == pytest.approx(26.4507, abs=5e-5)  # the paper's figure
    assert path_m / 16.0 == pytest.approx(1.6532, abs=5e-5)  # its 1.6532 m/s
    assert sf.seed_path_length() == pytest.approx(path_m, rel=1e-12)
    # the scenario's vectorised solver is the same least squares
    fast = sf.triangulate_inhomogeneous(*sf.projection_matrices_mm(), left, right)
    np.testing.assert_allclose(fast, X, rtol=1e-9)
    # and the homogeneous DLT gives the longer 30.78 m (ALGORITHMS.md §6.1)
    assert sf.seed_path_length("homogeneous") == pytest.approx(30.78, abs=0.01)


def test_vectorised_inhomogeneous_solver_equals_library_triangulate_near_and_far() -> None:
    rng = np.random.default_rng(1234)
    geo = sf.ferry_geometry()
    P1, P2 = sf.projection_matrices_mm()
    X = geo.points(rng.uniform(0.0, 320.0, 300))
    left = sf.project(P1, X) + rng.normal(0.0, 0.5, (300, 2))
    right = sf.project(P2, X) + rng.normal(0.0, 0.5, (300, 2))
    ref = triangulate([P1, P2], [left, right], "inhomogeneous")
    np.testing.assert_allclose(sf.triangulate_inhomogeneous(P1, P2, left, right), ref, rtol=1e-7)


def test_optimal_correction_matches_cv2_correct_matches() -> None:
    rng = np.random.default_rng(1234)
    geo = sf.ferry_geometry()
    P1, P2 = sf.projection_matrices_mm()
    X = geo.points(rng.uniform(0.0, 320.0, 500))
    left = sf.project(P1, X) + rng.normal(0.0, 0.5, (500, 2))
    right = sf.project(P2, X) + rng.normal(0.0, 0.5, (500, 2))
    # fundamental matrix built independently from OpenCV's rotation of the rig's rvec
    R, _ = cv2.Rodrigues(np.array([0.03266, -0.00424, -0.00525]))
    t = np.array([-206.29240, 0.20595, 19.50555])
    tx = np.array([[0, -t[2], t[1]], [t[2], 0, -t[0]], [-t[1], t[0], 0]])
    F = np.linalg.inv(SEED003_CALIBRATION.K_right).T @ tx @ R
    F = F @ np.linalg.inv(SEED003_CALIBRATION.K_left)
    ref_l, ref_r = cv2.correctMatches(F, left[None], right[None])
    ours_l, ours_r = sf.optimal_correction(F, left, right)
    np.testing.assert_allclose(ours_l, ref_l[0], atol=1e-6)
    np.testing.assert_allclose(ours_r, ref_r[0], atol=1e-6)


# ----------------------------------------------------------------------------- the truth
@pytest.mark.parametrize(("number", "speed", "seconds"), [(1, 1.5683, 200.0), (2, 2.2509, 137.0)])
def test_truth_runs_the_measured_average_speed_for_the_papers_duration(
    number: int, speed: float, seconds: float
) -> None:
    exp = sf.EXPERIMENTS[number]
    gens = [np.random.default_rng(i) for i in range(40)]
    truth = sf.simulate_truth(exp, gens)
    assert truth.along.shape == (40, round(seconds * 25) + 1)  # 25 frames/s, frame 0 included
    assert truth.time[-1] == pytest.approx(seconds)
    np.testing.assert_allclose(truth.along[:, -1], speed * seconds, rtol=1e-12)  # ≈ 300 m
    np.testing.assert_allclose(truth.along[:, 0], 0.0)
    # small fluctuations: OU with 0.05 m/s std (less after removing each run's mean)
    dv = truth.speed - speed
    assert 0.03 < np.std(dv) < 0.055
    assert np.max(np.abs(dv)) < 0.3
    # positions are the trapezoidal integral of the speed
    np.testing.assert_allclose(
        np.diff(truth.along, axis=1), 0.02 * (truth.speed[:, 1:] + truth.speed[:, :-1])
    )


def test_geometry_starts_at_the_seeds_first_fix_and_stays_in_both_images() -> None:
    geo = sf.ferry_geometry()
    assert np.linalg.norm(geo.start) == pytest.approx(17.93, abs=0.01)  # tens of metres
    P1, P2 = sf.projection_matrices_mm()
    X = geo.points(np.linspace(0.0, 320.0, 200))
    rng_m = np.linalg.norm(X, axis=1)
    assert np.all(np.diff(rng_m) > 0)  # receding
    for P in (P1, P2):
        uv = sf.project(P, X)
        assert np.all((uv[:, 0] >= 0) & (uv[:, 0] < 640) & (uv[:, 1] >= 0) & (uv[:, 1] < 480))
    # frame 1 reprojects near the seed's pixels (the start is their triangulation; the
    # seed's pair is not exactly on an epipolar line, hence ~1 px)
    np.testing.assert_allclose(sf.project(P1, geo.start[None])[0], [416.587, 110.5], atol=1.0)
    np.testing.assert_allclose(sf.project(P2, geo.start[None])[0], [448.761, 108.761], atol=1.0)


def test_measurement_variance_is_the_stereo_depth_error_and_matches_monte_carlo() -> None:
    geo = sf.ferry_geometry()
    s = np.array([0.0, 25.0, 100.0, 300.0])
    sigma = np.sqrt(sf.along_track_variance(geo, s))
    Z = geo.ranges(s)
    B = SEED003_CALIBRATION.baseline / 1000.0
    sd = math.sqrt(2.0) * 0.5  # disparity error for 0.5 px per image
    # ALGORITHMS.md §6.3, Z² σ_d / (f B), with f between the two cameras' focal lengths
    assert np.all(sigma > Z**2 * sd / (1285.05 * B) * 0.95)
    assert np.all(sigma < Z**2 * sd / (1087.09 * B) * 1.05)
    assert sigma[0] == pytest.approx(0.91, abs=0.01) and sigma[-1] == pytest.approx(285, rel=0.01)
    # brute force: the spread of the reprojection-optimal along-track estimate at the
    # start (17.9 m; farther out the Z² nonlinearity adds a few per cent: 6 % at 43 m)
    rng = np.random.default_rng(1234)
    P1, P2 = sf.projection_matrices_mm()
    X = geo.points(np.zeros(20000))
    left = sf.project(P1, X) + rng.normal(0, 0.5, X[:, :2].shape)
    right = sf.project(P2, X) + rng.normal(0, 0.5, X[:, :2].shape)
    est = sf.triangulate_reference("optimal", P1, P2, left, right) / 1000.0
    along = (est - geo.start) @ geo.direction
    assert np.std(along) == pytest.approx(sigma[0], rel=0.03)
    # the scenario's interpolated R equals the exact one
    grid = np.linspace(-2.0, 330.0, 977)
    np.testing.assert_allclose(
        sf._interpolated_variance(geo, grid, 0.5), sf.along_track_variance(geo, grid), rtol=2e-5
    )


# ----------------------------------------------------------------------------- filters
def test_kf_nis_is_one_when_the_filter_model_generates_the_data() -> None:
    # truth drawn from the filters' own CV model (F, Q) and z = s + N(0, R(s))
    rng = np.random.default_rng(1234)
    exp = dataclasses.replace(sf.EXPERIMENTS[1], duration=20.0)
    F, Q = sf.process_noise()
    runs, N = 200, exp.frames
    gamma = np.array([0.04**2 / 2, 0.04])  # seed eq. 5: Γ a_t, Q = σ_a² Γ Γᵀ
    sigma_a = math.sqrt(Q[1, 1]) / 0.04
    np.testing.assert_allclose(Q, sigma_a**2 * np.outer(gamma, gamma))
    x = np.zeros((runs, N, 2))
    x[:, 0] = [0.0, exp.speed_guess]
    x[:, 0, 1] += rng.normal(0.0, sf.INITIAL_SPEED_STD_MPS, runs)
    for k in range(1, N):
        x[:, k] = x[:, k - 1] @ F.T + sigma_a * rng.standard_normal((runs, 1)) * gamma
    R = sf.along_track_variance(sf.ferry_geometry(), x[..., 0])
    z = x[..., 0] + np.sqrt(R) * rng.standard_normal((runs, N))
    pred = sf.run_filter("kf", exp, z, R)
    assert pred.nis.shape == (runs, N - 1)
    assert np.mean(pred.nis) == pytest.approx(1.0, abs=0.03)  # χ²₁ mean; se ≈ 0.007
    # the innovation is the observation minus the one-step prediction
    np.testing.assert_allclose(pred.innovations, z[:, 1:] - pred.states[..., 0], atol=1e-9)


def test_kf_nis_is_one_on_stereo_measurements_within_the_16_s_video_window() -> None:
    exp = dataclasses.replace(sf.EXPERIMENTS[1], duration=16.0)
    batch = sf.simulate_batch(exp, [np.random.default_rng(i) for i in range(100)])
    pred = sf.run_filter("kf", exp, batch.z, batch.R)
    assert np.mean(pred.nis) == pytest.approx(1.0, abs=0.05)


def test_the_three_filters_share_x0_p0_q_r_and_differ_only_in_the_initial_speed() -> None:
    assert (sf.BETA, sf.RHO) == (4.5, 0.95)  # seed 003's STKF factors
    exp = dataclasses.replace(sf.EXPERIMENTS[2], duration=4.0)
    batch = sf.simulate_batch(exp, [np.random.default_rng(i) for i in range(5)])
    x0, P0 = sf.initial_state(batch.z[:, 0], batch.R[:, 0], exp.initial_speed("stkf"))
    assert exp.initial_speed("kf") == 2.2 and exp.initial_speed("stkf") == 2.2
    assert exp.initial_speed("stereo-stkf") == 2.2509
    np.testing.assert_allclose(x0[:, 0], batch.z[:, 0])
    np.testing.assert_allclose(P0[:, 1, 1], 0.1**2)
    # until its first fading factor > 1 the STKF is exactly the KF (same x0, P0, Q, R)
    stkf = sf.run_filter("stkf", exp, batch.z, batch.R)
    kf = sf.run_filter("kf", exp, batch.z, batch.R)
    assert np.all(stkf.fading >= 1.0)
    for b in range(5):
        first = int(np.argmax(stkf.fading[b] > 1.0)) if np.any(stkf.fading[b] > 1.0) else None
        np.testing.assert_allclose(stkf.states[b, :first], kf.states[b, :first], rtol=1e-10)
    stereo = sf.run_filter("stereo-stkf", exp, batch.z, batch.R)
    np.testing.assert_allclose(stereo.states[:, 0, 1] - stkf.states[:, 0, 1], 2.2509 - 2.2)


# ----------------------------------------------------------------------------- the claims
def _per_run(exp_number: int, estimators: tuple[str, ...], seconds: float, runs: int):
    exp = dataclasses.replace(sf.EXPERIMENTS[exp_number], duration=seconds)
    batch = sf.simulate_batch(exp, sf._run_generators(7, exp_number, runs))
    out = {}
    for est in estimators:
        errs = sf.prediction_errors(batch, sf.run_filter(est, exp, batch.z, batch.R))
        out[est] = {m: np.sqrt(np.mean(e**2, axis=1)) for m, e in errs.items()}
    return out


@pytest.mark.xfail(
    strict=True,
    reason=(
        "The paper's KF > STKF > stereo+STKF does not hold, with P0 matched to the initial "
        "speed errors (variant matched, speed sigma 0.1 m/s) or trusting the stereo speed "
        "accuracy (variant stereo-prior, 0.027 / 0.035 m/s). 1000 runs, seed 0, paper metric "
        "position [m] / speed [m/s], whole run, both variants: exp. 1 KF 251.9/8862, STKF "
        "353.6/9447, stereo+STKF 353.6/9447 (paper 1.39/0.133, 0.371/0.105, 0.337/0.091); "
        "exp. 2 KF 247.0/8607, STKF 340.7/9119, stereo+STKF 340.7/9119 (paper 1.10/0.265, "
        "0.822/0.161, 0.558/0.126). First 16 s, stereo-prior: exp. 1 3.117/3.291/3.287 m, "
        "109.4/109.7/109.7 m/s; exp. 2 4.650/4.993/4.991 m, 163.7/164.3/164.3 m/s (matched "
        "within 0.003 m). Against the truth (16 s, stereo-prior) KF 0.28 m / 0.058 m/s, STKF "
        "1.04 m / 1.07 m/s (exp. 1). STKF > stereo+STKF holds in the 16-s window (by 0.001-"
        "0.004 m), KF > STKF nowhere: the fading test needs an innovation bias of about 1.9 "
        "sigma_z (1.7 m at 18 m, 9.7 m at 43 m), the 0.07 m/s speed error makes 0.07 t <= "
        "1.1 m, so the fading factor fires only on noise (1.7 % of the first 2 s with the "
        "guess, 1.7 % with the stereo speed, 10 % beyond 16 s) and each firing turns the "
        "filter into a two-point differentiator; the KF corrects 0.07 m/s within seconds."
    ),
)
@pytest.mark.parametrize("variant", ["matched", "stereo-prior"])
def test_paper_ordering_kf_worse_than_stkf_worse_than_stereo_stkf(
    variant: str, result, result_stereo_prior
) -> None:
    res = result[0] if variant == "matched" else result_stereo_prior
    for e in (1, 2):
        for window in ({}, {"window_s": [0.0, 16.0]}):
            for metric in ("rmse_position_pred", "rmse_speed_pred"):
                kf, stkf, stereo = (
                    res.find(est, metric, experiment=e, **window)["mean"] for est in sf.ESTIMATORS
                )
                assert kf > stkf > stereo, (e, window, metric, kf, stkf, stereo)


def test_kf_beats_stkf_against_the_truth_when_its_model_matches_the_simulation() -> None:
    # variant "matched": Q, R and P0 are those of the simulation, so the KF is the MMSE
    # filter and no fading can help; the reverse of the paper's first inequality
    for e in (1, 2):
        r = _per_run(e, ("kf", "stkf"), 16.0, 40)
        for metric in ("rmse_position_pred_truth", "rmse_speed_pred_truth", "rmse_position_pred"):
            d, se = _paired(r["stkf"][metric], r["kf"][metric])
            assert d > 3 * se, (e, metric, d, se)


def test_stereo_prior_speed_std_is_the_spread_of_a_weighted_fit_through_the_16_s_video() -> None:
    # brute force: 400 stereo fixes (16 s) of a constant-speed ferry, 0.5 px per
    # coordinate, the seed's triangulation, a straight line fitted with weights 1/Z⁴
    # (ALGORITHMS.md §6.3: σ_Z ∝ Z²); the spread of its slope is the stereo speed accuracy
    rng = np.random.default_rng(1234)
    geo = sf.ferry_geometry()
    P1, P2 = sf.projection_matrices_mm()
    t = np.arange(400) * 0.04
    for e, expected in ((1, 0.0265), (2, 0.0355)):
        v = sf.EXPERIMENTS[e].speed
        X = geo.points(v * t)
        runs = 2000
        left = sf.project(P1, X) + rng.normal(0.0, 0.5, (runs, 400, 2))
        right = sf.project(P2, X) + rng.normal(0.0, 0.5, (runs, 400, 2))
        z = (sf.triangulate_inhomogeneous(P1, P2, left, right) / 1000.0 - geo.start) @ geo.direction
        w = np.linalg.norm(X, axis=1) ** -4.0
        A = np.stack([np.ones_like(t), t], axis=1)
        coef = np.linalg.solve(A.T @ (w[:, None] * A), (A.T * w) @ z.T)  # (2, runs)
        sigma = sf.stereo_speed_std(sf.EXPERIMENTS[e])
        assert np.std(coef[1]) == pytest.approx(sigma, rel=0.05)  # se of a std: 1.6 %
        assert sigma == pytest.approx(expected, abs=5e-4)
        # the seed's own estimate (first and last fix) is an order of magnitude worse
        assert np.std((z[:, -1] - z[:, 0]) / t[-1]) > 10 * sigma
        assert sf.initial_speed_std(sf.EXPERIMENTS[e], "stereo-prior") == sigma
        assert sf.initial_speed_std(sf.EXPERIMENTS[e], "matched") == 0.1


def _with_guess_error(exp_number: int, error: float, runs: int, variant: str):
    """16-s runs of the three filters with the guess ``error`` m/s below the truth's mean."""
    base = sf.EXPERIMENTS[exp_number]
    exp = dataclasses.replace(base, duration=16.0, speed_guess=base.speed - error)
    batch = sf.simulate_batch(exp, sf._run_generators(11, exp_number, runs))
    out = {}
    for est in sf.ESTIMATORS:
        pred = sf.run_filter(est, exp, batch.z, batch.R, variant=variant)
        errs = sf.prediction_errors(batch, pred)
        out[est] = {m: np.sqrt(np.mean(e**2, axis=1)) for m, e in errs.items()}
        out[est]["faded_2s"] = np.mean(pred.fading[:, :50] > 1.0, axis=1)
    return out


def test_the_papers_speed_error_is_invisible_to_the_fading_test_so_kf_beats_stkf() -> None:
    # the fading test fires when the innovation power exceeds about β R: a bias b shows
    # only if b² > (β − 1) R. The guess's 0.068 / 0.051 m/s error gives b ≤ 0.068 t, less
    # than half of √(β − 1) σ_Z over the whole video even with §6.3's smaller σ_Z (the
    # larger focal length, 1285 px)
    B = SEED003_CALIBRATION.baseline / 1000.0
    for e in (1, 2):
        exp = sf.EXPERIMENTS[e]
        t = np.linspace(0.0, 16.0, 401)
        Z = sf.ferry_geometry().ranges(exp.speed * t)
        sigma_z = Z**2 * math.sqrt(2.0) * 0.5 / (1285.05 * B)
        assert np.all((exp.speed - exp.speed_guess) * t < 0.5 * math.sqrt(sf.BETA - 1) * sigma_z)
        # so even when all three trust the stereo speed accuracy (the variant the paper
        # implies), the KF stays ahead of the STKF over the video
        r = _with_guess_error(e, exp.speed - exp.speed_guess, 60, "stereo-prior")
        for metric in ("rmse_position_pred", "rmse_position_pred_truth"):
            d, se = _paired(r["stkf"][metric], r["kf"][metric])
            assert d > 3 * se, (e, metric, d, se)


def test_stkf_beats_kf_once_the_initial_speed_error_is_large_enough_to_see() -> None:
    # a 1 m/s error (15 × the paper's) makes a 1 m bias within a second: the fading factor
    # fires early, the STKF recovers and the paper's ordering holds in the position column
    r = _with_guess_error(1, 1.0, 60, "stereo-prior")
    d, se = _paired(r["stkf"]["faded_2s"], r["stereo-stkf"]["faded_2s"])
    assert d > 3 * se, (d, se)  # fires on the mismatch
    for metric in ("rmse_position_pred", "rmse_position_pred_truth"):
        kf, stkf, stereo = (r[est][metric] for est in sf.ESTIMATORS)
        d1, se1 = _paired(kf, stkf)
        d2, se2 = _paired(stkf, stereo)
        assert d1 > 3 * se1 and d2 > 3 * se2, (metric, d1, se1, d2, se2)


def test_stereo_start_helps_the_stkf_only_in_the_start_up_transient() -> None:
    # the initial speed (0.068 / 0.051 m/s closer to the truth) is the only difference
    for e in (1, 2):
        r = _per_run(e, ("stkf", "stereo-stkf"), 4.0, 60)
        d, se = _paired(
            r["stkf"]["rmse_speed_pred_truth"], r["stereo-stkf"]["rmse_speed_pred_truth"]
        )
        assert d > 3 * se, (e, d, se)  # stereo + STKF better in the first 4 s
    res = _per_run(1, ("stkf", "stereo-stkf"), 200.0, 4)
    for metric in ("rmse_position_pred", "rmse_speed_pred"):  # the paper's, whole run
        a, b = res["stkf"][metric], res["stereo-stkf"][metric]
        np.testing.assert_allclose(a, b, rtol=1e-3)  # the transient is gone


# ----------------------------------------------------------------------------- records
def test_records_follow_interfaces_and_carry_table3(result) -> None:
    res, _ = result
    doc = json.loads(json.dumps(res.to_json()))
    assert doc["scenario"] == "stereo-ferry" and doc["runs"] == RUNS and doc["seed"] == 0
    keys = {"estimator", "metric", "unit", "mean", "stderr", "paper", "params"}
    assert all(set(r) == keys for r in doc["results"])
    for e in (1, 2):
        for est in sf.ESTIMATORS:
            for i, (metric, unit) in enumerate(
                (("rmse_position_pred", "m"), ("rmse_speed_pred", "m/s"))
            ):
                rec = res.find(est, metric, experiment=e)
                assert rec["params"] == {"experiment": e}
                assert rec["unit"] == unit and rec["paper"] == TABLE3[e][est][i]
                assert math.isfinite(rec["mean"]) and rec["stderr"] > 0
            for metric in ("rmse_position_pred_truth", "rmse_speed_pred_truth"):
                assert res.find(est, metric, experiment=e)["paper"] is None
            window = res.find(est, "rmse_position_pred", experiment=e, window_s=[0.0, 16.0])
            assert window["mean"] < res.find(est, "rmse_position_pred", experiment=e)["mean"]
        for late in sf.LATE_ESTIMATORS:  # the ablation
            assert res.find(late, "rmse_position_pred", experiment=e)["paper"] is None
        for method in ("inhomogeneous", "homogeneous", "optimal"):
            near = res.find(
                f"triangulation-{method}", "rmse_range", experiment=e, range_m=[0.0, 50.0]
            )
            assert 2.0 < near["mean"] < 8.0  # σ 0.9 → 5.2 m over 18–50 m
    assert set(doc["ordering"]) == {"1", "2"}
    assert doc["ordering"]["1"]["run"]["rmse_position_pred"]["holds"] is False
    assert doc["variant"] == "matched"
    assert doc["initial_speed_std_mps"] == {"1": 0.1, "2": 0.1}
    for e in ("1", "2"):
        periods = doc["diagnostics"][e]["fading_fraction_by_period"]
        assert set(periods) == set(sf.ESTIMATORS + sf.LATE_ESTIMATORS)
        assert periods["kf"] == {"0-2s": 0.0, "2-16s": 0.0, "16s-end": 0.0}
        assert all(0.0 <= f <= 1.0 for p in periods.values() for f in p.values())


def test_seed_triangulation_understates_far_ranges_while_the_optimal_one_is_median_unbiased(
    result,
) -> None:
    res, _ = result
    for e in (1, 2):
        far = {"range_m": [200.0, None], "experiment": e}
        seed = res.find("triangulation-inhomogeneous", "median_error_range", **far)
        opt = res.find("triangulation-optimal", "median_error_range", **far)
        assert seed["mean"] < -50.0  # about −100 m at 200–330 m
        assert abs(opt["mean"]) < 5 * opt["stderr"] + 2.0


def test_outputs_are_written_table3_beside_the_paper_and_plots(result) -> None:
    res, out = result
    names = sorted(p.name for p in res.outputs)
    assert names == [
        "prediction_error_exp1.png",
        "prediction_error_exp2.png",
        "table3.csv",
        "triangulation.csv",
    ]
    assert all(p.stat().st_size > 1000 for p in res.outputs)
    with (out / "table3.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 2 * 5  # 2 experiments × (3 filters + 2 ablations)
    row = next(r for r in rows if r["experiment"] == "2" and r["estimator"] == "stereo-stkf")
    assert float(row["rmse_position_pred_paper_m"]) == 0.5579
    assert float(row["rmse_speed_pred_paper_mps"]) == 0.1258
    rec = res.find("stereo-stkf", "rmse_position_pred", experiment=2)
    assert float(row["rmse_position_pred_m"]) == pytest.approx(rec["mean"], rel=1e-3)


def test_one_experiment_and_run_draws_do_not_depend_on_the_number_of_runs() -> None:
    a = sf.run(runs=3, seed=5, experiment=2, variant="stereo-prior")
    b = sf.run(runs=3, seed=5, experiment=2, variant="stereo-prior")
    assert a.results == b.results
    assert {r["params"]["experiment"] for r in a.results} == {2}
    g3 = sf._run_generators(5, 2, 3)
    g1 = sf._run_generators(5, 2, 1)
    assert g3[0].standard_normal() == g1[0].standard_normal()
    # the fading diagnostics per period recomputed from the same runs
    exp = sf.EXPERIMENTS[2]
    batch = sf.simulate_batch(exp, sf._run_generators(5, 2, 3))
    fading = sf.run_filter("stkf", exp, batch.z, batch.R, variant="stereo-prior").fading
    t = np.arange(1, exp.frames) * 0.04
    got = a.extra["diagnostics"]["2"]["fading_fraction_by_period"]["stkf"]
    early, video = t < 2.0 + 1e-9, t < 16.0 + 1e-9  # frames 1-50, 1-400
    for name, sel in (("0-2s", early), ("2-16s", video & ~early), ("16s-end", ~video)):
        assert got[name] == pytest.approx(np.mean(fading[:, sel] > 1.0), rel=1e-12)
    assert a.extra["initial_speed_std_mps"] == {"2": sf.stereo_speed_std(exp)}


# ----------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"runs": 0}, "runs"),
        ({"runs": 2.5}, "runs"),
        ({"runs": 2, "experiment": 3}, "experiment"),
        ({"runs": 2, "experiment": True}, "experiment"),
        ({"runs": 2, "variant": "paper"}, "variant"),
        ({"runs": 2, "variant": None}, "variant"),
    ],
)
def test_bad_arguments_raise_value_error_naming_them(kwargs: dict, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        sf.run(**kwargs)


def test_bad_noise_and_estimator_names_raise() -> None:
    geo = sf.ferry_geometry()
    with pytest.raises(ValueError, match="sigma_px"):
        sf.along_track_variance(geo, [0.0, 1.0], sigma_px=-0.5)
    with pytest.raises(ValueError, match="along"):
        sf.along_track_variance(geo, ["x"])
    z = np.zeros((2, 5))
    with pytest.raises(ValueError, match="estimator"):
        sf.run_filter("ekf", sf.EXPERIMENTS[1], z, np.ones((2, 5)))
    with pytest.raises(ValueError, match="frames"):
        sf.stereo_speed_std(sf.EXPERIMENTS[1], frames=1)
    with pytest.raises(ValueError, match="sigma_px"):
        sf.stereo_speed_std(sf.EXPERIMENTS[1], sigma_px=0.0)
    with pytest.raises(ValueError, match="speed_std"):
        sf.initial_state([0.0], [1.0], 1.5, speed_std=-0.1)
    with pytest.raises(ValueError, match="variant"):
        sf.run_filter("kf", sf.EXPERIMENTS[1], z, np.ones((2, 5)), variant="tight")
    with pytest.raises(ValueError, match="method"):
        sf.triangulate_reference("svd", *sf.projection_matrices_mm(), z[:, :2], z[:, :2])
