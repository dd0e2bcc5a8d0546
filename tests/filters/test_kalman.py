"""KalmanFilter against independent truths: FilterPy, exact rational arithmetic, the
closed-form alpha-beta steady state, chi-square NIS statistics, and batch/step/chunk
consistency."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter as FilterPyKF
from hypothesis import given
from hypothesis import strategies as st
from scipy import stats

from seawatch.filters import KalmanFilter
from seawatch.models import constant_velocity, position_measurement


def cv_problem(seed: int = 0, steps: int = 300, dim: int = 2):
    rng = np.random.default_rng(seed)
    F, Q = constant_velocity(dim, 0.1, 0.7)
    H = position_measurement(dim, 2)
    R = np.diag(rng.uniform(0.5, 3.0, dim))
    x = np.zeros(2 * dim)
    truth, zs = [], []
    for _ in range(steps):
        x = F @ x + rng.multivariate_normal(np.zeros(2 * dim), Q)
        truth.append(x)
        zs.append(H @ x + rng.multivariate_normal(np.zeros(dim), R))
    x0 = np.zeros(2 * dim)
    P0 = np.eye(2 * dim) * 50.0
    return F, H, Q, R, x0, P0, np.array(zs), np.array(truth)


def test_filter_matches_filterpy_states_and_covariances():
    F, H, Q, R, x0, P0, zs, _ = cv_problem()
    ref = FilterPyKF(dim_x=4, dim_z=2)
    ref.F, ref.H, ref.Q, ref.R, ref.x, ref.P = F, H, Q, R, x0.copy(), P0.copy()
    xs, Ps = [], []
    for z in zs:
        ref.predict()
        ref.update(z)
        xs.append(ref.x.copy())
        Ps.append(ref.P.copy())
    res = KalmanFilter(F, H, Q, R, x0, P0).filter(zs)
    np.testing.assert_allclose(res.states, np.array(xs), rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(res.covariances, np.array(Ps), rtol=1e-10, atol=1e-12)


def test_per_step_api_equals_whole_sequence_filter():
    F, H, Q, R, x0, P0, zs, _ = cv_problem(seed=3, steps=50)
    kf = KalmanFilter(F, H, Q, R, x0, P0)
    res = KalmanFilter(F, H, Q, R, x0, P0).filter(zs)
    for t, z in enumerate(zs):
        kf.predict()
        np.testing.assert_allclose(kf.x, res.predicted_states[t], rtol=1e-13, atol=1e-12)
        kf.update(z)
        np.testing.assert_allclose(kf.x, res.states[t], rtol=1e-13, atol=1e-12)
        np.testing.assert_allclose(kf.P, res.covariances[t], rtol=1e-13, atol=1e-13)
        np.testing.assert_allclose(kf.y, res.innovations[t], rtol=1e-12, atol=1e-12)
        assert kf.nis == pytest.approx(res.nis[t], rel=1e-12)


def _exact_kf(F, H, Q, R, x, P, zs):
    """Textbook KF in exact rational arithmetic (independent of the compiled kernels)."""

    def mat(a):
        return [[Fraction(v) for v in row] for row in a]

    def mul(a, b):
        return [
            [sum(a[i][k] * b[k][j] for k in range(len(b))) for j in range(len(b[0]))]
            for i in range(len(a))
        ]

    def add(a, b, s=1):
        return [[a[i][j] + s * b[i][j] for j in range(len(a[0]))] for i in range(len(a))]

    def tr(a):
        return [list(r) for r in zip(*a, strict=True)]

    def inv2(a):  # 1x1 or 2x2
        if len(a) == 1:
            return [[1 / a[0][0]]]
        det = a[0][0] * a[1][1] - a[0][1] * a[1][0]
        return [[a[1][1] / det, -a[0][1] / det], [-a[1][0] / det, a[0][0] / det]]

    F, H, Q, R, P = mat(F), mat(H), mat(Q), mat(R), mat(P)
    x = [[Fraction(v)] for v in x]
    eye = [[Fraction(int(i == j)) for j in range(len(P))] for i in range(len(P))]
    out = []
    for z in zs:
        x = mul(F, x)
        P = add(mul(mul(F, P), tr(F)), Q)
        S = add(mul(mul(H, P), tr(H)), R)
        K = mul(mul(P, tr(H)), inv2(S))
        y = add([[Fraction(v)] for v in z], mul(H, x), -1)
        x = add(x, mul(K, y))
        A = add(eye, mul(K, H), -1)
        P = add(mul(mul(A, P), tr(A)), mul(mul(K, R), tr(K)))
        nis = mul(mul(tr(y), inv2(S)), y)[0][0]
        out.append(([float(v[0]) for v in x], [[float(v) for v in r] for r in P], float(nis)))
    return out


def test_two_step_scalar_example_computed_by_hand():
    # F = H = Q = R = P0 = 1, x0 = 0, z = (2, 1):
    # step 1: P- = 2, S = 3, K = 2/3, x = 4/3, P = 2/3, NIS = 4/3
    # step 2: P- = 5/3, S = 8/3, K = 5/8, y = -1/3, x = 9/8, P = 5/8, NIS = 1/24
    res = KalmanFilter([[1.0]], [[1.0]], 1.0, 1.0, [0.0], 1.0).filter([[2.0], [1.0]])
    np.testing.assert_allclose(res.states[:, 0], [4 / 3, 9 / 8], rtol=1e-15)
    np.testing.assert_allclose(res.covariances[:, 0, 0], [2 / 3, 5 / 8], rtol=1e-15)
    np.testing.assert_allclose(res.nis, [4 / 3, 1 / 24], rtol=1e-14)


def test_two_step_cv_example_matches_exact_rational_arithmetic():
    F = [[1, 1], [0, 1]]
    H = [[1, 0]]
    Q = [[Fraction(1, 4), Fraction(1, 2)], [Fraction(1, 2), 1]]
    R = [[2]]
    P0 = [[4, 1], [1, 3]]
    zs = [[Fraction(3, 2)], [Fraction(-1, 3)]]
    exact = _exact_kf(F, H, Q, R, [1, -1], P0, zs)
    to_f = lambda a: np.array(a, dtype=float)  # noqa: E731
    res = KalmanFilter(to_f(F), to_f(H), to_f(Q), to_f(R), [1.0, -1.0], to_f(P0)).filter(to_f(zs))
    for t, (x, P, nis) in enumerate(exact):
        np.testing.assert_allclose(res.states[t], x, rtol=1e-14)
        np.testing.assert_allclose(res.covariances[t], P, rtol=1e-14)
        assert res.nis[t] == pytest.approx(nis, rel=1e-13)


@given(
    sigma_v=st.floats(0.01, 10.0),
    sigma_w=st.floats(0.1, 10.0),
    T=st.floats(0.02, 2.0),
)
def test_steady_state_gain_equals_kalata_alpha_beta_closed_form(sigma_v, sigma_w, T):
    # Kalata (1984): DWNA model, position measurement; tracking index lam = sigma_v T^2 / sigma_w.
    lam = sigma_v * T * T / sigma_w
    r = np.sqrt(lam * lam + 8 * lam)
    alpha = -(lam * lam + 8 * lam - (lam + 4) * r) / 8
    beta = (lam * lam + 4 * lam - lam * r) / 4
    F, Q = constant_velocity(1, T, sigma_v)
    H = position_measurement(1, 2)
    kf = KalmanFilter(F, H, Q, sigma_w**2, [0.0, 0.0], np.eye(2) * 1e3)
    steps = int(min(20000, 50 + 40 / max(alpha, 1e-3)))
    res = kf.filter(np.zeros((steps, 1)))
    gain = res.predicted_covariances[-1] @ H.T / res.innovation_covariances[-1, 0, 0]
    assert gain[0, 0] == pytest.approx(alpha, rel=1e-6, abs=1e-9)
    assert gain[1, 0] == pytest.approx(beta / T, rel=1e-6, abs=1e-9)


def test_nis_is_chi_square_with_m_degrees_of_freedom_for_a_consistent_filter():
    F, H, Q, R, x0, P0, zs, _ = cv_problem(seed=11, steps=4000)
    res = KalmanFilter(F, H, Q, R, x0, P0).filter(zs)
    nis = res.nis[100:]
    # mean of N chi2(2) variables: 99.9 % band
    n = nis.size
    lo, hi = stats.chi2.ppf([0.0005, 0.9995], 2 * n) / n
    assert lo < nis.mean() < hi


def test_estimation_error_matches_reported_covariance():
    F, H, Q, R, x0, P0, zs, truth = cv_problem(seed=5, steps=3000)
    res = KalmanFilter(F, H, Q, R, x0, P0).filter(zs)
    err = (res.states - truth)[200:]
    Pinv = np.linalg.inv(res.covariances[200:])
    nees = np.einsum("ti,tij,tj->t", err, Pinv, err)
    assert 3.7 < nees.mean() < 4.3  # E[NEES] = n = 4


def test_batched_tracks_equal_independent_single_runs():
    rng = np.random.default_rng(7)
    F, H, Q, R, _, _, _, _ = cv_problem()
    B, T = 70, 40  # >= PARALLEL_MIN_TRACKS: the multi-core kernel
    zs = rng.normal(size=(B, T, 2)) * 5
    zs[3, 10] = np.nan
    x0 = rng.normal(size=(B, 4))
    P0 = np.eye(4) * rng.uniform(1, 100, size=(B, 1, 1))
    batch = KalmanFilter(F, H, Q, R, x0, P0).filter(zs)
    for b in (0, 3, 41, 69):
        single = KalmanFilter(F, H, Q, R, x0[b], P0[b]).filter(zs[b])
        np.testing.assert_array_equal(batch.states[b], single.states)
        np.testing.assert_array_equal(batch.covariances[b], single.covariances)
    small = KalmanFilter(F, H, Q, R, x0[:5], P0[:5]).filter(zs[:5])  # serial kernel
    np.testing.assert_array_equal(small.states, batch.states[:5])


def test_batch_axes_broadcast_one_initial_state_over_many_runs():
    F, H, Q, R, x0, P0, zs, _ = cv_problem(steps=20)
    runs = np.stack([zs, zs + 1.0, zs - 2.0]).reshape(3, 1, 20, 2)
    res = KalmanFilter(F, H, Q, R, x0, P0).filter(runs)
    assert res.states.shape == (3, 1, 20, 4)
    single = KalmanFilter(F, H, Q, R, x0, P0).filter(zs + 1.0)
    np.testing.assert_allclose(res.states[1, 0], single.states, rtol=1e-14)


def test_per_step_batch_with_per_track_process_noise():
    F, H, Q, R, x0, P0, zs, _ = cv_problem(steps=10)
    scales = np.array([0.5, 1.0, 4.0])
    kf = KalmanFilter(F, H, Q, R, np.tile(x0, (3, 1)), P0)
    singles = [KalmanFilter(F, H, Q * s, R, x0, P0) for s in scales]
    for z in zs:
        kf.predict(Q=Q * scales[:, None, None])
        kf.update(np.tile(z, (3, 1)))
        for s in singles:
            s.predict()
            s.update(z)
    for b, s in enumerate(singles):
        np.testing.assert_allclose(kf.x[b], s.x, rtol=1e-13)


def test_missing_measurement_is_a_predict_only_step():
    F, H, Q, R, x0, P0, zs, _ = cv_problem(steps=30)
    zs[12] = np.nan
    zs[20, 1] = np.nan  # a partly missing measurement is missing
    res = KalmanFilter(F, H, Q, R, x0, P0).filter(zs)
    for t in (12, 20):
        np.testing.assert_array_equal(res.states[t], res.predicted_states[t])
        np.testing.assert_array_equal(res.covariances[t], res.predicted_covariances[t])
        np.testing.assert_allclose(res.predicted_states[t], F @ res.states[t - 1], rtol=1e-14)
        assert np.isnan(res.nis[t]) and np.all(np.isnan(res.innovations[t]))
    assert np.all(np.isfinite(res.states))
    kf = KalmanFilter(F, H, Q, R, x0, P0)
    kf.predict()
    prior = kf.x.copy()
    kf.update(None)
    np.testing.assert_array_equal(kf.x, prior)


def test_chunked_stream_equals_one_pass():
    F, H, Q, R, x0, P0, zs, _ = cv_problem(steps=60)
    whole = KalmanFilter(F, H, Q, R, x0, P0).filter(zs)
    kf = KalmanFilter(F, H, Q, R, x0, P0)
    parts = [kf.filter(zs[:25]).states, kf.filter(zs[25:]).states]
    np.testing.assert_allclose(np.concatenate(parts), whole.states, rtol=1e-14)


@given(
    q=st.floats(1e-4, 1e2),
    r=st.floats(1e-3, 1e3),
    p0=st.floats(1e-3, 1e6),
    seed=st.integers(0, 1000),
)
def test_covariance_stays_symmetric_psd_and_update_never_increases_it(q, r, p0, seed):
    rng = np.random.default_rng(seed)
    F, Q = constant_velocity(3, 0.5, q)
    H = position_measurement(3, 2)
    zs = rng.normal(size=(40, 3)) * np.sqrt(r) * 3
    res = KalmanFilter(F, H, Q, r, np.zeros(6), p0).filter(zs)
    P, Pp = res.covariances, res.predicted_covariances
    np.testing.assert_array_equal(P, np.swapaxes(P, -1, -2))
    scale = np.max(np.abs(Pp), axis=(-1, -2))
    assert np.all(np.linalg.eigvalsh(P).min(axis=-1) >= -1e-9 * scale)
    # P_post <= P_prior in the Loewner order
    assert np.all(np.linalg.eigvalsh(Pp - P).min(axis=-1) >= -1e-9 * scale)


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"F": np.ones((4, 3))}, "F"),
        ({"F": np.full((4, 4), np.nan)}, "F"),
        ({"H": np.ones((2, 3))}, "H"),
        ({"Q": -np.eye(4)}, "Q"),
        ({"Q": np.ones((3, 3))}, "Q"),
        ({"R": np.zeros((2, 2))}, "R"),
        ({"R": np.array([[1.0, 2.0], [0.0, 1.0]])}, "R"),
        ({"x0": np.zeros(3)}, "x0"),
        ({"x0": np.array([0, 0, np.inf, 0])}, "x0"),
        ({"P0": np.diag([1.0, 1.0, -1.0, 1.0])}, "P0"),
    ],
)
def test_bad_constructor_arguments_raise_value_error_naming_them(kwargs, name):
    F, H, Q, R, x0, P0, _, _ = cv_problem(steps=1)
    args = {"F": F, "H": H, "Q": Q, "R": R, "x0": x0, "P0": P0} | kwargs
    with pytest.raises(ValueError, match=rf"^{name}:"):
        KalmanFilter(**args)


def test_bad_measurements_raise_value_error_naming_them():
    F, H, Q, R, x0, P0, zs, _ = cv_problem(steps=5)
    kf = KalmanFilter(F, H, Q, R, x0, P0)
    with pytest.raises(ValueError, match=r"^zs:"):
        kf.filter(zs[:, :1])
    with pytest.raises(ValueError, match=r"^z:"):
        kf.update([1.0, 2.0, 3.0])
    bad = zs.copy()
    bad[2, 0] = np.inf
    with pytest.raises(ValueError, match=r"^z: contains inf"):
        kf.filter(bad)


def test_singular_measurement_noise_override_is_rejected_naming_it():
    kf = KalmanFilter(np.eye(2), [[1.0, 0.0]], np.zeros((2, 2)), 1.0, [0.0, 0.0], np.zeros((2, 2)))
    kf.predict()
    with pytest.raises(ValueError, match=r"^R: covariance must be positive definite"):
        kf.update([1.0], R=[[0.0]])


def test_overflowing_state_raises_instead_of_returning_nan():
    kf = KalmanFilter([[1e200]], [[1.0]], 0.0, 1.0, [1e200], 1.0)
    with pytest.raises(FloatingPointError, match="non-finite"):
        kf.predict()
