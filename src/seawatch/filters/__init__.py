"""Estimation filters of the source papers (ALGORITHMS.md §1–§3, §5)."""

from seawatch.filters.adaptive_range import AdaptiveRangeFilter
from seawatch.filters.diffuse_rls import (
    DiffuseRLS,
    DiffuseRLSBank,
    DiffuseRLSResult,
    SlidingWindowDiffuseRLS,
)
from seawatch.filters.fractional import (
    AdaptiveFractionalKalmanFilter,
    FractionalKalmanFilter,
    fractional_cv_matrix,
    gl_coefficients,
)
from seawatch.filters.kalman import KalmanFilter
from seawatch.filters.nonlinear import ExtendedKalmanFilter, UnscentedKalmanFilter
from seawatch.filters.result import FilterResult
from seawatch.filters.strong_tracking import StrongTrackingKalmanFilter, StrongTrackingResult

__all__ = [
    "AdaptiveFractionalKalmanFilter",
    "AdaptiveRangeFilter",
    "DiffuseRLS",
    "DiffuseRLSBank",
    "DiffuseRLSResult",
    "ExtendedKalmanFilter",
    "FilterResult",
    "FractionalKalmanFilter",
    "KalmanFilter",
    "SlidingWindowDiffuseRLS",
    "StrongTrackingKalmanFilter",
    "StrongTrackingResult",
    "UnscentedKalmanFilter",
    "fractional_cv_matrix",
    "gl_coefficients",
]
