"""OSPA and GOSPA distances between finite sets of points.

* **OSPA** (Schuhmacher, Vo & Vo, *IEEE Trans. Signal Process.* 56(8), 2008, eq. (3)):
  for ``X = {x_1..x_m}``, ``Y = {y_1..y_n}`` with ``m <= n`` (else swap), cut-off
  ``c > 0`` and order ``1 <= p < inf``,

      d_p^(c)(X, Y) = ( (1/n) ( min_π Σ_{i=1..m} d^(c)(x_i, y_π(i))^p + c^p (n − m) ) )^(1/p)

  with ``d^(c)(x, y) = min(c, ||x − y||)``; 0 for two empty sets. For ``p = inf``:
  ``min_π max_i d^(c)(x_i, y_π(i))`` when ``m = n``, else ``c``.
* **GOSPA** (García-Fernández, Rahmathullah & Svensson, *FUSION* 2017, eq. (1) and
  Prop. 1 for α = 2): no normalisation by n and a cardinality penalty ``c^p / α``,

      d_p^(c,α)(X, Y) = ( min_π Σ_{i=1..m} d^(c)(x_i, y_π(i))^p + (c^p / α)(n − m) )^(1/p).

  With α = 2 it equals the assignment form
  ``( Σ_assigned ||x − y||^p + (c^p / 2)(missed + false) )^(1/p)`` where only pairs closer
  than c are assigned; this gives the decomposition into localisation error, missed
  targets and false targets.

The optimal assignment is ``scipy.optimize.linear_sum_assignment`` on the cut-off
distances raised to p. Points are rows of (k, d) arrays in any unit; the distances come
out in that unit.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import maximum_bipartite_matching

from seawatch._validation import FloatArray, as_float_array, in_range, positive

__all__ = ["GospaResult", "GospaSeries", "gospa", "gospa_series", "ospa", "ospa_series"]


@dataclass(frozen=True)
class GospaResult:
    """GOSPA distance and its decomposition (α = 2).

    Attributes:
        distance: GOSPA distance (points' unit).
        localisation: ``Σ ||x − y||^p`` over the assigned pairs (unit^p).
        missed: number of truth points left unassigned.
        false: number of estimated points left unassigned.
        assignment: (a, 2) int array of assigned (truth index, estimate index) pairs.
    """

    distance: float
    localisation: float
    missed: int
    false: int
    assignment: NDArray[np.int64]


@dataclass(frozen=True)
class GospaSeries:
    """GOSPA per time step: arrays of shape (T,) matching :class:`GospaResult` fields."""

    distance: FloatArray
    localisation: FloatArray
    missed: NDArray[np.int64]
    false: NDArray[np.int64]


def _points(name: str, value: ArrayLike, dim: int | None = None) -> FloatArray:
    arr = as_float_array(name, value)
    if arr.ndim == 1 and arr.size == 0:
        arr = arr.reshape(0, dim or 0)
    if arr.ndim != 2:
        raise ValueError(f"{name}: expected points of shape (k, d), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: contains NaN or inf")
    return arr


def _pair(x: ArrayLike, y: ArrayLike) -> tuple[FloatArray, FloatArray]:
    X = _points("x", x)
    Y = _points("y", y)
    if X.shape[0] == 0 and Y.shape[0] > 0:
        X = X.reshape(0, Y.shape[1])
    if Y.shape[0] == 0 and X.shape[0] > 0:
        Y = Y.reshape(0, X.shape[1])
    if X.shape[0] and Y.shape[0] and X.shape[1] != Y.shape[1]:
        raise ValueError(f"y: expected points of dimension {X.shape[1]}, got {Y.shape[1]}")
    return X, Y


def _distances(X: FloatArray, Y: FloatArray) -> FloatArray:
    return np.linalg.norm(X[:, None, :] - Y[None, :, :], axis=-1)


def _order(p: float, allow_inf: bool) -> float:
    v = float(p)
    if allow_inf and v == math.inf:
        return v
    return in_range("p", v, 1.0, math.inf, hi_open=True)


def ospa(x: ArrayLike, y: ArrayLike, c: float, p: float = 1.0) -> float:
    """OSPA distance between two point sets (module docstring; Schuhmacher 2008 eq. (3)).

    Args:
        x, y: (m, d) and (n, d) point sets (either may be empty).
        c: cut-off (> 0, points' unit): the largest penalty of one point.
        p: order, ``1 <= p``, or ``inf``.

    Returns:
        The distance in ``[0, c]``; 0 for two empty sets, c if exactly one is empty.
    """
    c = positive("c", c)
    p = _order(p, allow_inf=True)
    X, Y = _pair(x, y)
    m, n = X.shape[0], Y.shape[0]
    if m > n:
        X, Y, m, n = Y, X, n, m
    if n == 0:
        return 0.0
    if m == 0:
        return c
    D = np.minimum(_distances(X, Y), c)
    if p == math.inf:
        return c if m != n else _bottleneck(D)
    r, k = linear_sum_assignment(D**p)
    total = float(np.sum(D[r, k] ** p)) + c**p * (n - m)
    return (total / n) ** (1.0 / p)


def _bottleneck(D: FloatArray) -> float:
    """min over perfect matchings of the largest entry (square D), by bisection."""
    values = np.unique(D)
    lo, hi = 0, values.shape[0] - 1
    n = D.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        graph = csr_matrix(D <= values[mid])
        matched = maximum_bipartite_matching(graph, perm_type="column")
        if np.count_nonzero(matched >= 0) == n:
            hi = mid
        else:
            lo = mid + 1
    return float(values[lo])


def gospa(x: ArrayLike, y: ArrayLike, c: float, p: float = 1.0) -> GospaResult:
    """GOSPA distance with α = 2 and its decomposition (García-Fernández 2017, Prop. 1).

    Args:
        x: truth points (m, d).
        y: estimated points (n, d).
        c: cut-off (> 0, points' unit); a missed or false point costs ``c^p / 2``.
        p: order, ``1 <= p < inf``.

    Returns:
        :class:`GospaResult` (distance, localisation, missed, false, assignment).
    """
    c = positive("c", c)
    p = _order(p, allow_inf=False)
    X, Y = _pair(x, y)
    m, n = X.shape[0], Y.shape[0]
    pairs = np.empty((0, 2), np.int64)
    loc = 0.0
    if m and n:
        D = _distances(X, Y)
        r, k = linear_sum_assignment(np.minimum(D, c) ** p)
        near = D[r, k] < c  # a pair at the cut-off costs as much as a miss plus a false
        pairs = np.column_stack([r[near], k[near]]).astype(np.int64)
        loc = float(np.sum(D[r[near], k[near]] ** p))
    a = pairs.shape[0]
    missed, false = m - a, n - a
    total = loc + c**p / 2.0 * (missed + false)
    return GospaResult(
        distance=total ** (1.0 / p),
        localisation=loc,
        missed=int(missed),
        false=int(false),
        assignment=pairs,
    )


def ospa_series(
    xs: Sequence[ArrayLike], ys: Sequence[ArrayLike], c: float, p: float = 1.0
) -> FloatArray:
    """OSPA at each time step of two equally long sequences of point sets, (T,).

    The mean over time, ``ospa_series(...).mean()``, is the usual single figure.
    """
    if len(xs) != len(ys):
        raise ValueError(f"ys: expected {len(xs)} time steps like xs, got {len(ys)}")
    return np.array([ospa(a, b, c, p) for a, b in zip(xs, ys, strict=True)], dtype=np.float64)


def gospa_series(
    xs: Sequence[ArrayLike], ys: Sequence[ArrayLike], c: float, p: float = 1.0
) -> GospaSeries:
    """GOSPA (α = 2) at each time step of truth sets ``xs`` and estimate sets ``ys``."""
    if len(xs) != len(ys):
        raise ValueError(f"ys: expected {len(xs)} time steps like xs, got {len(ys)}")
    res = [gospa(a, b, c, p) for a, b in zip(xs, ys, strict=True)]
    return GospaSeries(
        distance=np.array([r.distance for r in res], dtype=np.float64),
        localisation=np.array([r.localisation for r in res], dtype=np.float64),
        missed=np.array([r.missed for r in res], dtype=np.int64),
        false=np.array([r.false for r in res], dtype=np.int64),
    )
