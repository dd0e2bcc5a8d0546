"""Kinematic models against their continuous-time definitions (matrix exponential and
the Van Loan integral) and the DWNA/DWPA closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.linalg import expm

from seawatch.models import constant_acceleration, constant_velocity, position_measurement


def van_loan(A: np.ndarray, G: np.ndarray, q: float, T: float) -> tuple[np.ndarray, np.ndarray]:
    """Discretise dx = A x dt + G dW (PSD q): F = e^{AT}, Q = ∫ e^{As} G q Gᵀ e^{Aᵀs} ds."""
    n = A.shape[0]
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n] = -A
    M[:n, n:] = q * G @ G.T
    M[n:, n:] = A.T
    E = expm(M * T)
    F = E[n:, n:].T
    return F, F @ E[:n, n:]


@given(T=st.floats(0.01, 5.0), s=st.floats(0.01, 10.0), dim=st.integers(1, 3))
def test_cv_continuous_noise_equals_van_loan_integral(T, s, dim):
    F, Q = constant_velocity(dim, T, s, noise="continuous")
    A = np.kron(np.array([[0.0, 1.0], [0.0, 0.0]]), np.eye(dim))
    G = np.kron(np.array([[0.0], [1.0]]), np.eye(dim))
    F_ref, Q_ref = van_loan(A, G, s * s, T)
    np.testing.assert_allclose(F, F_ref, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(Q, Q_ref, rtol=1e-7, atol=1e-12 * np.abs(Q_ref).max())


@given(T=st.floats(0.01, 3.0), s=st.floats(0.01, 10.0), dim=st.integers(1, 3))
def test_ca_continuous_noise_equals_van_loan_integral(T, s, dim):
    F, Q = constant_acceleration(dim, T, s, noise="continuous")
    A = np.kron(np.diag([1.0, 1.0], k=1), np.eye(dim))
    G = np.kron(np.array([[0.0], [0.0], [1.0]]), np.eye(dim))
    F_ref, Q_ref = van_loan(A, G, s * s, T)
    np.testing.assert_allclose(F, F_ref, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(Q, Q_ref, rtol=1e-6, atol=1e-11 * np.abs(Q_ref).max())


@given(T=st.floats(0.01, 5.0), s=st.floats(0.01, 10.0))
def test_discrete_white_noise_acceleration_is_piecewise_constant_acceleration(T, s):
    # DWNA: an acceleration a ~ N(0, s^2) held over one interval moves p by a T^2/2 and v by a T.
    F, Q = constant_velocity(1, T, s)
    g = np.array([T * T / 2, T])
    np.testing.assert_allclose(Q, s * s * np.outer(g, g), rtol=1e-14)
    assert np.linalg.matrix_rank(Q, tol=1e-12 * Q.max()) == 1
    np.testing.assert_allclose(F, expm(np.array([[0.0, T], [0.0, 0.0]])), rtol=1e-14)


def test_discrete_wiener_acceleration_matches_seed_002_eq_21():
    T, s = 0.04, 0.1
    _, Q = constant_acceleration(1, T, s)
    expected = (
        s * s * np.array([[T**4 / 4, T**3 / 2, T**2 / 2], [T**3 / 2, T**2, T], [T**2 / 2, T, 1.0]])
    )
    np.testing.assert_allclose(Q, expected, rtol=1e-14)


def test_multi_axis_state_is_positions_first_and_axes_independent():
    F, Q = constant_velocity(3, 0.5, 2.0)
    F1, Q1 = constant_velocity(1, 0.5, 2.0)
    for axis in range(3):
        idx = [axis, axis + 3]
        np.testing.assert_array_equal(F[np.ix_(idx, idx)], F1)
        np.testing.assert_array_equal(Q[np.ix_(idx, idx)], Q1)
    assert np.count_nonzero(Q) == 3 * 4  # no cross-axis terms
    H = position_measurement(3, 2)
    x = np.array([1.0, 2.0, 3.0, 10.0, 20.0, 30.0])
    np.testing.assert_array_equal(H @ x, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal((F @ x)[:3], [6.0, 12.0, 18.0])


@given(
    T=st.floats(0.01, 5.0),
    sigmas=st.lists(st.floats(0.0, 10.0), min_size=1, max_size=3),
    noise=st.sampled_from(["discrete", "continuous"]),
)
def test_per_axis_noise_is_each_axis_own_single_axis_model(T, sigmas, noise):
    """A per-axis sigma_a (an image track's horizontal and vertical acceleration noise):
    on each axis the single-axis model with that axis's sigma, no cross-axis terms."""
    dim = len(sigmas)
    F, Q = constant_velocity(dim, T, sigmas, noise=noise)
    F_iso, _ = constant_velocity(dim, T, 1.0, noise=noise)
    np.testing.assert_array_equal(F, F_iso)
    for axis, s in enumerate(sigmas):
        idx = [axis, axis + dim]
        _, Q1 = constant_velocity(1, T, s, noise=noise)
        np.testing.assert_allclose(Q[np.ix_(idx, idx)], Q1, rtol=1e-12, atol=0.0)
    off = np.ones_like(Q, bool)
    for axis in range(dim):
        off[np.ix_([axis, axis + dim], [axis, axis + dim])] = False
    assert not Q[off].any()


@pytest.mark.parametrize("sigma", [[1.0], [1.0, 2.0, 3.0], [1.0, -0.5], [1.0, float("nan")]])
def test_a_per_axis_noise_of_the_wrong_length_or_sign_raises_naming_sigma_a(sigma):
    with pytest.raises(ValueError, match=r"^sigma_a: expected a number >= 0 or 2"):
        constant_velocity(2, 0.1, sigma)


@pytest.mark.parametrize(
    ("args", "name"),
    [
        ((0, 0.1, 1.0), "dim"),
        ((4, 0.1, 1.0), "dim"),
        ((2.5, 0.1, 1.0), "dim"),
        ((2, 0.0, 1.0), "dt"),
        ((2, float("nan"), 1.0), "dt"),
        ((2, 0.1, -1.0), "sigma"),
    ],
)
def test_bad_model_arguments_raise_value_error_naming_them(args, name):
    for model in (constant_velocity, constant_acceleration):
        with pytest.raises(ValueError, match=rf"^{name}"):
            model(*args)
    with pytest.raises(ValueError, match=r"^noise"):
        constant_velocity(1, 0.1, 1.0, noise="white")
