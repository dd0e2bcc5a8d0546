"""Estimation filters of the source papers (ALGORITHMS.md §1–§3, §5)."""

from seawatch.filters.adaptive_range import AdaptiveRangeFilter
from seawatch.filters.kalman import KalmanFilter
from seawatch.filters.nonlinear import ExtendedKalmanFilter, UnscentedKalmanFilter
from seawatch.filters.result import FilterResult

__all__ = [
    "AdaptiveRangeFilter",
    "ExtendedKalmanFilter",
    "FilterResult",
    "KalmanFilter",
    "UnscentedKalmanFilter",
]
