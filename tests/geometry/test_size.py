"""Known-size ranging (ALGORITHMS.md §5.1, seed 002 eqs. 14–15).

Truths: the seed's own numbers, pinhole projection of 3-D segments (cv2.projectPoints),
and Monte Carlo.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from seawatch.geometry.size import (
    size_range,
    size_range_sigma,
    subtended_angle,
    subtended_range,
    subtended_range_sigma,
)

K = np.array([[1200.0, 0.0, 640.0], [0.0, 1200.0, 360.0], [0.0, 0.0, 1.0]])


def _project(points: np.ndarray, dist: np.ndarray | None = None) -> np.ndarray:
    d = np.zeros(5) if dist is None else dist
    uv, _ = cv2.projectPoints(points.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), K, d)
    return uv.reshape(-1, 2)


def _segment(d: float, L: float, theta: float) -> np.ndarray:
    """Ends of a segment of length L centred at distance d along a ray at off-axis angle
    theta (in the x-z plane), perpendicular to that ray: a radial extent in the image."""
    centre = d * np.array([math.sin(theta), 0.0, math.cos(theta)])
    axis = np.array([math.cos(theta), 0.0, -math.sin(theta)])
    return np.stack([centre - 0.5 * L * axis, centre + 0.5 * L * axis])


@given(d=st.floats(10.0, 1e5), L=st.floats(0.5, 100.0), f=st.floats(100.0, 5e4))
def test_size_range_inverts_the_pinhole_image_size(d: float, L: float, f: float) -> None:
    l_px = f * L / d
    assert size_range(l_px, L, f) == pytest.approx(d, rel=1e-12)


def test_seed002_measurement_variance_is_d_squared_over_400000_squared() -> None:
    # seed 002: f = 40 000 px, L = 10 m (G2 aircraft), sigma_l = 1 px -> R = (d^2 / 400 000)^2
    d = np.array([2500.0, 4000.0, 5000.0])
    l_px = 40_000.0 * 10.0 / d
    sig = size_range_sigma(l_px, 10.0, 40_000.0, 1.0)
    np.testing.assert_allclose(sig**2, (d**2 / 400_000.0) ** 2, rtol=1e-12)


def test_size_sigma_with_uncertain_true_size_matches_monte_carlo() -> None:
    rng = np.random.default_rng(1234)
    f, L, l_px, s_l, s_L = 2000.0, 20.0, 25.0, 0.5, 1.0
    sig = size_range_sigma(l_px, L, f, s_l, s_L)
    assert sig / size_range(l_px, L, f) == pytest.approx(math.hypot(s_l / l_px, s_L / L), rel=1e-12)
    n = 200_000
    samples = f * (L + s_L * rng.standard_normal(n)) / (l_px + s_l * rng.standard_normal(n))
    assert np.std(samples) == pytest.approx(sig, rel=0.03)


def test_size_range_bad_data_gives_inf_or_nan_and_bad_config_raises() -> None:
    out = size_range([0.0, -3.0, np.nan, 10.0], 5.0, 1000.0)
    assert math.isinf(out[0]) and out[0] > 0
    assert np.isnan(out[1]) and np.isnan(out[2]) and out[3] == 500.0
    s = size_range_sigma([0.0, -3.0, 10.0], 5.0, 1000.0, 1.0)
    assert math.isinf(s[0]) and np.isnan(s[1]) and np.isfinite(s[2])
    with pytest.raises(ValueError, match="focal_px"):
        size_range(10.0, 5.0, 0.0)
    with pytest.raises(ValueError, match="true_size"):
        size_range(10.0, np.nan, 1000.0)
    with pytest.raises(ValueError, match="sigma_px"):
        size_range_sigma(10.0, 5.0, 1000.0, -1.0)


def test_subtended_range_equals_f_l_over_l_on_the_axis() -> None:
    l_px = 37.0
    a = np.array([K[0, 2] - l_px / 2, K[1, 2]])
    b = np.array([K[0, 2] + l_px / 2, K[1, 2]])
    assert subtended_range(a, b, 8.0, K) == pytest.approx(size_range(l_px, 8.0, K[0, 0]), rel=1e-12)


@given(theta_deg=st.floats(-30.0, 30.0), d=st.floats(20.0, 5000.0), L=st.floats(1.0, 50.0))
def test_subtended_range_recovers_off_axis_distance_exactly(
    theta_deg: float, d: float, L: float
) -> None:
    ends = _project(_segment(d, L, math.radians(theta_deg)))
    assert subtended_range(ends[0], ends[1], L, K) == pytest.approx(d, rel=1e-9)


def test_naive_size_range_is_13_percent_wrong_at_20_degrees_and_subtended_is_not() -> None:
    # §5.1 pitfall: a radial extent at 20° off axis images as f L / (d cos^2 theta)
    d, L, theta = 1000.0, 10.0, math.radians(20.0)
    ends = _project(_segment(d, L, theta))
    naive = size_range(np.linalg.norm(ends[1] - ends[0]), L, K[0, 0])
    # the image is f L / (d cos^2 theta): 1/cos^2(20°) - 1 = 13 % too large
    assert d / naive - 1.0 == pytest.approx(1.0 / math.cos(theta) ** 2 - 1.0, rel=1e-3)
    assert d / naive - 1.0 == pytest.approx(0.13, abs=0.005)
    assert subtended_range(ends[0], ends[1], L, K) == pytest.approx(d, rel=1e-9)


def test_subtended_range_with_lens_distortion_undistorts_first() -> None:
    dist = np.array([-0.2, 0.05, 0.001, -0.001, 0.0])
    ends = _project(_segment(300.0, 6.0, math.radians(15)), dist)
    assert subtended_range(ends[0], ends[1], 6.0, K, dist) == pytest.approx(300.0, rel=1e-6)
    assert abs(subtended_range(ends[0], ends[1], 6.0, K) / 300.0 - 1) > 1e-3


def test_subtended_angle_is_vectorised_and_nan_rows_propagate() -> None:
    a = np.array([[600.0, 360.0], [np.nan, 0.0]])
    b = np.array([[700.0, 360.0], [1.0, 1.0]])
    phi = subtended_angle(a, b, K)
    want = math.atan(60 / 1200) + math.atan(40 / 1200)
    assert phi.shape == (2,) and phi[0] == pytest.approx(want, rel=1e-12) and np.isnan(phi[1])
    with pytest.raises(ValueError, match="end_a"):
        subtended_angle(np.zeros(3), b, K)
    with pytest.raises(ValueError, match="camera_matrix"):
        subtended_angle(a, b, np.eye(2))


def test_subtended_sigma_equals_size_sigma_on_axis_and_matches_monte_carlo_off_axis() -> None:
    l_px, L, s = 40.0, 10.0, 0.7
    a = np.array([K[0, 2] - l_px / 2, K[1, 2]])
    b = np.array([K[0, 2] + l_px / 2, K[1, 2]])
    want = size_range_sigma(l_px, L, K[0, 0], math.sqrt(2) * s)
    assert subtended_range_sigma(a, b, L, K, s) == pytest.approx(want, rel=1e-5)

    rng = np.random.default_rng(1234)
    ends = _project(_segment(800.0, L, math.radians(25)))
    sig = subtended_range_sigma(ends[0], ends[1], L, K, s, sigma_size=0.3)
    n = 100_000
    noisy_a = ends[0] + s * rng.standard_normal((n, 2))
    noisy_b = ends[1] + s * rng.standard_normal((n, 2))
    samples = subtended_range(noisy_a, noisy_b, L + 0.3 * rng.standard_normal(n), K)
    assert np.std(samples) == pytest.approx(sig, rel=0.03)
