"""Scores of estimates and tracks against the truth.

* :mod:`seawatch.metrics.mot` — CLEAR-MOT (MOTA, MOTP, ID switches, FP, FN), identity
  (IDF1, IDP, IDR) and HOTA through TrackEval's metric classes, on pixel boxes (IoU) or
  points (distance): :func:`mot_metrics` for all three at once.
* :mod:`seawatch.metrics.cle` — the centre location error of visual tracking (§1.6): mean
  px, percent of the box diagonal, precision at 20 px.
* :mod:`seawatch.metrics.crlb` — the posterior Cramér–Rao bound (Tichavský recursion in a
  singular-Q-safe form, ALGORITHMS.md §7) for linear models, sea-surface angle
  measurements (uav-sea, solent-ais) and image-size range (air-range).
* :mod:`seawatch.metrics.ospa` — OSPA and GOSPA distances between point sets, per time
  step and over a sequence.
"""

from seawatch.metrics.cle import CLEResult, centre_location_error
from seawatch.metrics.crlb import (
    PCRBResult,
    air_range_pcrb,
    curved_sea_range_bound,
    flat_sea_range_bound,
    pcrb_information,
    pcrb_linear,
    pcrb_nonlinear_measurement,
    sea_surface_angles_pcrb,
    uav_sea_pcrb,
)
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
from seawatch.metrics.track_errors import TrackErrors, score_tracks

__all__ = [
    "CLEResult",
    "ClearMetrics",
    "GospaResult",
    "GospaSeries",
    "HotaMetrics",
    "IdentityMetrics",
    "MOTMetrics",
    "PCRBResult",
    "TrackErrors",
    "air_range_pcrb",
    "box_iou",
    "centre_location_error",
    "clear_metrics",
    "curved_sea_range_bound",
    "flat_sea_range_bound",
    "gospa",
    "gospa_series",
    "hota_metrics",
    "identity_metrics",
    "mot_data",
    "mot_metrics",
    "ospa",
    "ospa_series",
    "pcrb_information",
    "pcrb_linear",
    "pcrb_nonlinear_measurement",
    "score_tracks",
    "sea_surface_angles_pcrb",
    "uav_sea_pcrb",
]
