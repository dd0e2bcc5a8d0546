"""Stereo triangulation (ALGORITHMS.md §6, seed 003 eqs. 1–3).

Truths: ``cv2.triangulatePoints`` (the homogeneous DLT), exact projections of known
points, per-point ``numpy.linalg.lstsq`` (the inhomogeneous least squares), the seed's
published path length, closed forms of the rectified pair, and Monte Carlo.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from seawatch.camera.stereo import (
    SEED003_CALIBRATION,
    StereoRig,
    TriangulationFlag,
    depth_bias,
    depth_sigma,
    disparity_to_depth,
    projection_matrices_from_calibration,
    rectified_point,
    triangulate,
    triangulate_points,
    triangulation_covariance,
)


def _K(f: float, cx: float = 320.0, cy: float = 240.0, fy: float | None = None) -> np.ndarray:
    return np.array([[f, 0.0, cx], [0.0, f if fy is None else fy, cy], [0.0, 0.0, 1.0]])


def _project(P: np.ndarray, X: np.ndarray) -> np.ndarray:
    x = np.hstack([X, np.ones((len(X), 1))]) @ P.T
    return x[:, :2] / x[:, 2:]


def _random_rig(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    K1 = _K(rng.uniform(400, 2000), rng.uniform(280, 360), rng.uniform(200, 280))
    K2 = _K(rng.uniform(400, 2000), rng.uniform(280, 360), rng.uniform(200, 280))
    rvec = rng.normal(0.0, 0.05, 3)
    T = np.array([-rng.uniform(0.1, 1.0), rng.normal(0, 0.02), rng.normal(0, 0.05)])
    return projection_matrices_from_calibration(K1, K2, rvec, T)


def _ferry_pixels() -> tuple[np.ndarray, np.ndarray]:
    """Seed 003 experiment 1 feature point 2, linearly interpolated over 400 frames."""
    t = np.linspace(0.0, 1.0, 400)[:, None]
    left = np.array([416.587, 110.500]) * (1 - t) + np.array([67.891, 111.370]) * t
    right = np.array([448.761, 108.761]) * (1 - t) + np.array([53.978, 111.370]) * t
    return left, right


# ----------------------------------------------------------------------------- OpenCV
@given(seed=st.integers(0, 10_000))
def test_homogeneous_dlt_agrees_with_cv2_triangulate_points(seed: int) -> None:
    rng = np.random.default_rng(seed)
    P1, P2 = _random_rig(rng)
    X = np.column_stack(
        [rng.uniform(-3, 3, 20), rng.uniform(-2, 2, 20), rng.uniform(2.0, 40.0, 20)]
    )
    x1 = _project(P1, X) + rng.normal(0, 0.5, (20, 2))
    x2 = _project(P2, X) + rng.normal(0, 0.5, (20, 2))
    H = cv2.triangulatePoints(P1, P2, x1.T.copy(), x2.T.copy())
    ref = (H[:3] / H[3]).T
    ours = triangulate([P1, P2], [x1, x2])
    np.testing.assert_allclose(ours, ref, rtol=1e-6, atol=0)


@given(seed=st.integers(0, 10_000), views=st.integers(2, 5))
def test_noise_free_points_are_recovered_by_both_methods_from_any_number_of_views(
    seed: int, views: int
) -> None:
    rng = np.random.default_rng(seed)
    Ps = []
    for _ in range(views):
        R, _ = cv2.Rodrigues(rng.normal(0, 0.1, 3))
        t = rng.normal(0, 0.5, 3)
        Ps.append(_K(rng.uniform(500, 1500)) @ np.hstack([R, t[:, None]]))
    X = np.column_stack([rng.uniform(-2, 2, 10), rng.uniform(-2, 2, 10), rng.uniform(5, 30, 10)])
    pix = [_project(P, X) for P in Ps]
    for method in ("homogeneous", "inhomogeneous"):
        res = triangulate_points(Ps, pix, method)
        np.testing.assert_allclose(res.points, X, rtol=1e-8)
        assert np.all(res.flags == 0)
        assert np.all(res.reprojection_error < 1e-6)


def test_inhomogeneous_method_is_the_per_point_least_squares_of_seed003_eq3() -> None:
    rng = np.random.default_rng(1234)
    P1, P2 = SEED003_CALIBRATION.projection_matrices()
    left, right = _ferry_pixels()
    left, right = left[::40] + rng.normal(0, 1, (10, 2)), right[::40] + rng.normal(0, 1, (10, 2))
    ours = triangulate([P1, P2], [left, right], method="inhomogeneous")
    for i in range(10):
        rows, rhs = [], []
        for P, (u, v) in ((P1, left[i]), (P2, right[i])):
            rows += [u * P[2, :3] - P[0, :3], v * P[2, :3] - P[1, :3]]
            rhs += [P[0, 3] - u * P[2, 3], P[1, 3] - v * P[2, 3]]
        ref = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)[0]
        np.testing.assert_allclose(ours[i], ref, rtol=1e-9)


# ----------------------------------------------------------------------------- seed 003
def test_seed003_tables_give_a_207_2_mm_baseline() -> None:
    assert SEED003_CALIBRATION.baseline == pytest.approx(207.2, abs=0.05)
    assert SEED003_CALIBRATION.unit == "mm"
    _, P2 = SEED003_CALIBRATION.projection_matrices()
    # the right camera centre (null vector of P2) lies |T| from the left one (origin)
    _, _, vh = np.linalg.svd(P2)
    C2 = vh[-1, :3] / vh[-1, 3]
    assert np.linalg.norm(C2) == pytest.approx(207.2, abs=0.05)
    np.testing.assert_allclose(C2, -SEED003_CALIBRATION.R.T @ SEED003_CALIBRATION.T, rtol=1e-9)
    np.testing.assert_allclose(SEED003_CALIBRATION.rvec, [0.03266, -0.00424, -0.00525], atol=1e-12)


def test_seed003_ferry_path_is_26_4507_m_inhomogeneous_and_30_78_m_homogeneous() -> None:
    P = SEED003_CALIBRATION.projection_matrices()
    left, right = _ferry_pixels()
    lengths = {}
    for method in ("inhomogeneous", "homogeneous"):
        res = triangulate_points(P, [left, right], method)
        assert np.all(res.flags == 0)
        X_m = res.points / 1000.0  # tables in mm
        lengths[method] = np.sum(np.linalg.norm(np.diff(X_m, axis=0), axis=1))
    assert lengths["inhomogeneous"] == pytest.approx(26.4507, abs=5e-5)  # the seed's figure
    assert lengths["homogeneous"] == pytest.approx(30.78, abs=0.01)


# ----------------------------------------------------------------------------- flags
def test_parallel_rays_are_flagged_at_infinity_for_both_methods() -> None:
    P1, P2 = SEED003_CALIBRATION.projection_matrices()
    directions = np.array([[0.1, 0.05, 1.0], [-0.2, 0.0, 1.0]])
    # a point at infinity: pixel = K R d in each view
    x1 = _project(P1, directions * 1e15)
    x2 = (P2[:, :3] @ directions.T).T
    x2 = x2[:, :2] / x2[:, 2:]
    near = _project(P1, np.array([[0.0, 0.0, 5000.0]])), _project(P2, np.array([[0.0, 0, 5000.0]]))
    for method in ("homogeneous", "inhomogeneous"):
        res = triangulate_points(
            [P1, P2], [np.vstack([x1, near[0]]), np.vstack([x2, near[1]])], method
        )
        assert res.flags.tolist() == [TriangulationFlag.AT_INFINITY] * 2 + [0]
        assert np.all(res.parallax[:2] < 1e-9)
        assert res.parallax[2] == pytest.approx(207.2 / 5000.0, rel=0.01)
    hom = triangulate_points([P1, P2], [x1, x2]).homogeneous
    assert np.all(np.abs(hom[:, 3]) < 1e-12)  # X[3] ≈ 0


def test_point_behind_the_cameras_fails_cheirality() -> None:
    P1, P2 = projection_matrices_from_calibration(_K(800), _K(800), np.zeros(3), [-0.5, 0, 0])
    X = np.array([[0.2, 0.1, -10.0], [0.2, 0.1, 10.0]])
    res = triangulate_points([P1, P2], [_project(P1, X), _project(P2, X)])
    assert res.flags.tolist() == [TriangulationFlag.BEHIND_CAMERA, 0]
    assert res.depths[0, 0] < 0 and res.depths[:, 1] == pytest.approx([10.0, 10.0])


def test_nan_pixels_give_nan_rows_without_disturbing_the_others() -> None:
    P1, P2 = SEED003_CALIBRATION.projection_matrices()
    left, right = _ferry_pixels()
    left, right = left[:3].copy(), right[:3].copy()
    left[1, 0] = np.nan
    res = triangulate_points([P1, P2], [left, right])
    assert res.flags.tolist() == [0, TriangulationFlag.INVALID, 0]
    assert np.isnan(res.points[1]).all() and np.isfinite(res.points[[0, 2]]).all()
    clean = triangulate([P1, P2], [left[[0, 2]], right[[0, 2]]])
    np.testing.assert_allclose(res.points[[0, 2]], clean, rtol=1e-12)


def test_bad_inputs_raise_value_errors_naming_the_argument() -> None:
    P1, P2 = SEED003_CALIBRATION.projection_matrices()
    x = np.zeros((3, 2))
    with pytest.raises(ValueError, match="projections"):
        triangulate([P1], [x])
    with pytest.raises(ValueError, match=r"projections\[1\]"):
        triangulate([P1, P2[:2]], [x, x])
    with pytest.raises(ValueError, match=r"projections\[0\]"):
        triangulate([np.full((3, 4), np.nan), P2], [x, x])
    with pytest.raises(ValueError, match=r"points\[1\]"):
        triangulate([P1, P2], [x, np.zeros((3, 3))])
    with pytest.raises(ValueError, match=r"points\[1\]"):
        triangulate([P1, P2], [x, np.zeros((4, 2))])
    with pytest.raises(ValueError, match="points"):
        triangulate([P1, P2], [x])
    with pytest.raises(ValueError, match="method"):
        triangulate([P1, P2], [x, x], method="svd")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="rotation"):
        projection_matrices_from_calibration(_K(1), _K(1), np.ones((3, 3)), np.zeros(3))
    with pytest.raises(ValueError, match="K2"):
        projection_matrices_from_calibration(_K(1), np.eye(4), np.zeros(3), np.zeros(3))


# ----------------------------------------------------------------------------- covariance
def test_triangulation_covariance_matches_monte_carlo_of_the_dlt() -> None:
    rng = np.random.default_rng(1234)
    P1, P2 = projection_matrices_from_calibration(
        _K(1000), _K(1050, 330, 250), [0.01, -0.03, 0.0], [-0.4, 0.01, 0.02]
    )
    X = np.array([[1.0, -0.5, 20.0]])
    x1, x2 = _project(P1, X), _project(P2, X)
    sigma = 0.5
    cov = triangulation_covariance([P1, P2], X, sigma)[0]
    n = 20_000
    sims = triangulate(
        [P1, P2],
        [x1 + sigma * rng.standard_normal((n, 2)), x2 + sigma * rng.standard_normal((n, 2))],
    )
    err = sims - X
    emp = np.cov(err.T)
    np.testing.assert_allclose(np.sqrt(np.diag(emp)), np.sqrt(np.diag(cov)), rtol=0.05)
    # normalised errors: E[e^T C^-1 e] = 3
    nees = np.einsum("ni,ij,nj->n", err, np.linalg.inv(cov), err)
    assert np.mean(nees) == pytest.approx(3.0, rel=0.05)


def test_triangulation_covariance_depth_term_is_the_rectified_z2_sigma_over_fb() -> None:
    f, B, Z = 1200.0, 0.3, 25.0
    P1, P2 = projection_matrices_from_calibration(_K(f), _K(f), np.zeros(3), [-B, 0, 0])
    X = np.array([0.0, 0.0, Z])
    cov = triangulation_covariance([P1, P2], X, 0.5)
    # disparity noise sigma_d = sqrt(2) * 0.5 px; the ML estimate uses both rows, the
    # depth error is Z^2 sigma_d / (f B) (§6.3)
    assert math.sqrt(cov[2, 2]) == pytest.approx(
        float(depth_sigma(f * B / Z, f, B, math.sqrt(2) * 0.5)), rel=1e-3
    )


def test_triangulation_covariance_handles_nan_and_infinity_and_bad_sigma() -> None:
    P1, P2 = SEED003_CALIBRATION.projection_matrices()
    cov = triangulation_covariance([P1, P2], [[np.nan, 0, 0], [0, 0, 5000.0]], [0.5, 0.8])
    assert np.isnan(cov[0]).all() and np.isfinite(cov[1]).all()
    with pytest.raises(ValueError, match="sigma_px"):
        triangulation_covariance([P1, P2], [0, 0, 5000.0], -1.0)
    with pytest.raises(ValueError, match="X"):
        triangulation_covariance([P1, P2], np.zeros((2, 2)), 1.0)


# ----------------------------------------------------------------------------- rectified
@given(u=st.floats(0, 640), v=st.floats(0, 480), d=st.floats(0.5, 200.0), B=st.floats(0.05, 2.0))
def test_rectified_point_equals_the_triangulation_of_a_rectified_rig(
    u: float, v: float, d: float, B: float
) -> None:
    f, cx, cy = 900.0, 321.5, 239.5
    P1, P2 = projection_matrices_from_calibration(
        _K(f, cx, cy), _K(f, cx, cy), np.zeros(3), [-B, 0, 0]
    )
    X = rectified_point(u, v, d, f, B, cx, cy)
    ref = triangulate([P1, P2], [[u, v], [u - d, v]])[0]
    np.testing.assert_allclose(X, ref, rtol=1e-8, atol=1e-9)
    assert disparity_to_depth(d, f, B) == pytest.approx(f * B / d, rel=1e-15)


def test_depth_sigma_is_the_derivative_of_depth_and_the_bias_matches_monte_carlo() -> None:
    f, B, d, s = 800.0, 0.2, 6.0, 0.7
    eps = 1e-6
    dZ = (disparity_to_depth(d + eps, f, B) - disparity_to_depth(d - eps, f, B)) / (2 * eps)
    assert depth_sigma(d, f, B, s) == pytest.approx(abs(dZ) * s, rel=1e-6)
    Z = disparity_to_depth(d, f, B)
    assert depth_sigma(d, f, B, s) == pytest.approx(Z**2 * s / (f * B), rel=1e-12)
    rng = np.random.default_rng(1234)
    samples = f * B / (d + s * rng.standard_normal(400_000))
    samples = samples[np.abs(samples - Z) < 10 * Z]  # drop the rare near-zero disparities
    assert np.mean(samples) - Z == pytest.approx(depth_bias(d, f, B, s), rel=0.15)


def test_zero_and_negative_disparities_give_inf_and_nan() -> None:
    Z = disparity_to_depth([0.0, -1.0, np.nan, 4.0], 800.0, 0.2)
    assert math.isinf(Z[0]) and Z[0] > 0 and np.isnan(Z[1:3]).all() and Z[3] == 40.0
    pts = rectified_point(300.0, 200.0, [0.0, 4.0], 800.0, 0.2, 320.0, 240.0)
    assert pts.shape == (2, 3) and np.isfinite(pts[1]).all()
    with pytest.raises(ValueError, match="baseline"):
        disparity_to_depth(1.0, 800.0, 0.0)


# ----------------------------------------------------------------------------- rigs
def test_stereo_rig_undistorts_before_triangulating() -> None:
    rng = np.random.default_rng(1234)
    dist_l = np.array([-0.25, 0.08, 0.001, -0.0005, 0.0])
    dist_r = np.array([-0.2, 0.05, -0.001, 0.0005, 0.0])
    rig = StereoRig.from_rotation_vector(
        _K(540, 330, 240),
        _K(545, 325, 245),
        [0.003, -0.004, 0.002],
        [-0.0836, 0.001, 0.0013],
        dist_left=dist_l,
        dist_right=dist_r,
    )
    X = np.column_stack(
        [rng.uniform(-0.2, 0.2, 8), rng.uniform(-0.1, 0.1, 8), rng.uniform(0.4, 1, 8)]
    )
    xl, _ = cv2.projectPoints(X, np.zeros(3), np.zeros(3), rig.K_left, dist_l)
    xr, _ = cv2.projectPoints(X, rig.rvec, rig.T, rig.K_right, dist_r)
    res = rig.triangulate(xl.reshape(-1, 2), xr.reshape(-1, 2))
    np.testing.assert_allclose(res.points, X, atol=1e-6)
    raw = rig.triangulate(xl.reshape(-1, 2), xr.reshape(-1, 2), undistort=False)
    assert np.max(np.abs(raw.points - X)) > 1e-3
    with pytest.raises(ValueError, match="unit"):
        StereoRig(_K(1), _K(1), np.eye(3), np.zeros(3), unit="ft")
