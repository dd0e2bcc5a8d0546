"""OSPA and GOSPA: hand-checkable values, brute force and the metric axioms.

The small examples are those of Stone Soup's ``metricgenerator/tests/test_ospametric.py``
(MIT), worked out by hand here from the definitions (Schuhmacher et al. 2008 eq. (3);
García-Fernández et al. 2017 eq. (1)).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from seawatch.metrics import gospa, gospa_series, ospa, ospa_series


def _line(values) -> np.ndarray:
    return np.asarray(values, dtype=float).reshape(-1, 1)


# ------------------------------------------------------------------ hand-checked values


@pytest.mark.parametrize("p", [1, 2, math.inf])
def test_ospa_of_equal_offsets_is_the_offset(p):
    # every point moved by 0.5 (then by 0.2): the optimal assignment pairs i with i
    assert ospa(_line(np.arange(5) + 0.5), _line(np.arange(5)), c=10, p=p) == pytest.approx(0.5)
    assert ospa(_line(np.arange(5) + 1.2), _line(np.arange(5) + 1), c=10, p=p) == pytest.approx(0.2)


@pytest.mark.parametrize(
    ("p", "first", "second"),
    [
        (1, (4 * 0.5 + 10) / 5, (4 * 0.2 + 10) / 5),  # 2.4, 2.16
        (2, math.sqrt((4 * 0.25 + 100) / 5), math.sqrt((4 * 0.04 + 100) / 5)),  # 4.494, 4.476
        (math.inf, 10.0, 10.0),
    ],
)
def test_ospa_cardinality_error_costs_c_per_missing_point(p, first, second):
    truth = _line(np.arange(5))
    assert ospa(_line(np.arange(4) + 0.5), truth, c=10, p=p) == pytest.approx(first, rel=1e-5)
    assert ospa(_line(np.arange(4) + 1.2), truth + 1, c=10, p=p) == pytest.approx(second, rel=1e-5)


def test_gospa_sums_instead_of_averaging_and_prefers_pairs_to_misses():
    g = gospa(_line(np.arange(5)), _line(np.arange(5) + 0.5), c=10, p=1)
    assert g.distance == pytest.approx(2.5) and (g.missed, g.false) == (0, 0)
    # shifted by 1: pairing i with i costs 5; pairing i+1 with i+1 (four zeros) and one
    # miss plus one false would cost 10 / 2 + 10 / 2 = 10
    g = gospa(_line(np.arange(5)), _line(np.arange(5) + 1), c=10, p=1)
    assert g.distance == pytest.approx(5.0) and g.localisation == pytest.approx(5.0)


def test_gospa_decomposition_into_localisation_missed_and_false():
    # truths {1, 2, 3}, estimates {2, 1, 100}: 3 is missed, 100 is false (c = 2, p = 2)
    g = gospa(_line([1, 2, 3]), _line([2, 1, 100]), c=2, p=2)
    assert (g.localisation, g.missed, g.false) == (0.0, 1, 1)
    assert g.distance == pytest.approx(math.sqrt(2**2 / 2 * 2))
    assert sorted(map(tuple, g.assignment.tolist())) == [(0, 1), (1, 0)]


def test_empty_sets():
    empty = np.empty((0, 2))
    pts = np.array([[0.0, 0.0], [3.0, 4.0]])
    assert ospa(empty, empty, c=5) == 0.0
    assert ospa(pts, empty, c=5) == 5.0 and ospa([], pts, c=5) == 5.0
    g = gospa(empty, pts, c=4, p=1)
    assert (g.distance, g.missed, g.false) == (4.0, 0, 2)


# ------------------------------------------------------------------ brute force


def _ospa_brute(X, Y, c, p):
    m, n = len(X), len(Y)
    if m > n:
        X, Y, m, n = Y, X, n, m
    if n == 0:
        return 0.0
    best = math.inf
    for perm in itertools.permutations(range(n), m):
        s = sum(min(c, float(np.linalg.norm(X[i] - Y[j]))) ** p for i, j in enumerate(perm))
        best = min(best, s)
    return ((best + c**p * (n - m)) / n) ** (1 / p)


def _gospa_brute(X, Y, c, p):
    m, n = len(X), len(Y)
    best = math.inf
    # every partial matching: choose which truths are paired, with which estimates
    for k in range(min(m, n) + 1):
        for rows in itertools.combinations(range(m), k):
            for cols in itertools.permutations(range(n), k):
                s = sum(
                    float(np.linalg.norm(X[i] - Y[j])) ** p for i, j in zip(rows, cols, strict=True)
                )
                best = min(best, s + c**p / 2 * (m + n - 2 * k))
    return best ** (1 / p)


def test_ospa_and_gospa_equal_brute_force_over_all_assignments():
    rng = np.random.default_rng(1234)
    for _ in range(40):
        X = rng.uniform(0, 10, size=(rng.integers(0, 5), 2))
        Y = rng.uniform(0, 10, size=(rng.integers(0, 5), 2))
        for p in (1, 2, 3.5):
            assert ospa(X, Y, c=4.0, p=p) == pytest.approx(_ospa_brute(X, Y, 4.0, p))
            assert gospa(X, Y, c=4.0, p=p).distance == pytest.approx(_gospa_brute(X, Y, 4.0, p))


def test_ospa_with_infinite_order_is_the_bottleneck_assignment():
    rng = np.random.default_rng(1234)
    for _ in range(20):
        X = rng.uniform(0, 10, size=(4, 2))
        Y = rng.uniform(0, 10, size=(4, 2))
        want = min(
            max(min(6.0, float(np.linalg.norm(X[i] - Y[j]))) for i, j in enumerate(perm))
            for perm in itertools.permutations(range(4))
        )
        assert ospa(X, Y, c=6.0, p=math.inf) == pytest.approx(want)


# ------------------------------------------------------------------ metric axioms

point_sets = arrays(
    np.float64,
    st.tuples(st.integers(0, 4), st.just(2)),
    elements=st.floats(-20, 20, allow_nan=False, width=32),
)


@given(point_sets, point_sets, point_sets)
def test_ospa_and_gospa_are_metrics_bounded_by_c(x, y, z):
    c, p = 5.0, 2.0
    for d in (lambda a, b: ospa(a, b, c, p), lambda a, b: gospa(a, b, c, p).distance):
        assert d(x, x) == pytest.approx(0.0, abs=1e-12)
        assert d(x, y) == pytest.approx(d(y, x), abs=1e-9)
        assert d(x, z) <= d(x, y) + d(y, z) + 1e-9
    assert 0.0 <= ospa(x, y, c, p) <= c + 1e-12


@given(point_sets)
def test_distance_is_zero_only_for_equal_sets(x):
    if len(x) == 0:
        return
    moved = x.copy()
    moved[0, 0] += 0.25
    assert ospa(x, moved, c=5.0) > 0.0 and gospa(x, moved, c=5.0).distance > 0.0
    assert ospa(x, x[:-1], c=5.0) > 0.0 and gospa(x, x[:-1], c=5.0).distance > 0.0


# ------------------------------------------------------------------ sequences and bad input


def test_series_apply_the_metric_at_every_time_step():
    xs = [_line([0, 1]), _line([]), _line([5])]
    ys = [_line([0.5, 1.5]), _line([3]), _line([])]
    np.testing.assert_allclose(ospa_series(xs, ys, c=2), [0.5, 2.0, 2.0])
    g = gospa_series(xs, ys, c=2, p=1)
    np.testing.assert_allclose(g.distance, [1.0, 1.0, 1.0])
    assert g.missed.tolist() == [0, 0, 1] and g.false.tolist() == [0, 1, 0]
    with pytest.raises(ValueError, match="ys"):
        ospa_series(xs, ys[:2], c=2)


def test_bad_arguments_raise_naming_them():
    pts = np.zeros((2, 2))
    with pytest.raises(ValueError, match="c"):
        ospa(pts, pts, c=0.0)
    with pytest.raises(ValueError, match="p"):
        ospa(pts, pts, c=1.0, p=0.5)
    with pytest.raises(ValueError, match="p"):
        gospa(pts, pts, c=1.0, p=math.inf)
    with pytest.raises(ValueError, match="y"):
        ospa(pts, np.zeros((2, 3)), c=1.0)
    with pytest.raises(ValueError, match="x"):
        gospa(np.array([[np.nan, 0.0]]), pts, c=1.0)
    with pytest.raises(ValueError, match="x"):
        ospa(np.zeros((2, 2, 2)), pts, c=1.0)
