"""Scores of estimates and tracks against the truth.

* :mod:`seawatch.metrics.mot` — CLEAR-MOT (MOTA, MOTP, ID switches, FP, FN), identity
  (IDF1, IDP, IDR) and HOTA through TrackEval's metric classes, on pixel boxes (IoU) or
  points (distance): :func:`mot_metrics` for all three at once.
* :mod:`seawatch.metrics.ospa` — OSPA and GOSPA distances between point sets, per time
  step and over a sequence.
"""

from seawatch.metrics.mot import (
    ClearMetrics,
    HotaMetrics,
    IdentityMetrics,
    MOTMetrics,
    box_iou,
    clear_metrics,
    hota_metrics,
    identity_metrics,
    mot_data,
    mot_metrics,
)
from seawatch.metrics.ospa import (
    GospaResult,
    GospaSeries,
    gospa,
    gospa_series,
    ospa,
    ospa_series,
)

__all__ = [
    "ClearMetrics",
    "GospaResult",
    "GospaSeries",
    "HotaMetrics",
    "IdentityMetrics",
    "MOTMetrics",
    "box_iou",
    "clear_metrics",
    "gospa",
    "gospa_series",
    "hota_metrics",
    "identity_metrics",
    "mot_data",
    "mot_metrics",
    "ospa",
    "ospa_series",
]
