"""Gating, association, track management and track-before-detect (pixels and points).

* :class:`~seawatch.tracking.gate_tbd.GateTBD` — the two-gate ("strobe")
  track-before-detect of seed 004 (ALGORITHMS.md §8.1), with its per-frame
  :class:`FrameStats`, whole-sequence :class:`TBDResult` and :func:`group_marks`.
* :class:`~seawatch.tracking.mtt.MultiTargetTracker` — ships as boxes or points:
  Mahalanobis gating, global-nearest-neighbour assignment, M-of-N confirmation,
  deletion after K misses, any filter of :mod:`seawatch.filters` per track.
* :class:`~seawatch.tracking.world.WorldTracker` — world-frame estimation of each ship
  track from its angles: point-wise geometry, diffuse-RLS smoothing, EKF/UKF (seed 000).
* :class:`~seawatch.tracking.ais_match.AisAssociator` — camera tracks ↔ AIS vessels.
"""

from seawatch.tracking.ais_match import AisAssociation, AisAssociator, ViewWedge
from seawatch.tracking.gate_tbd import FrameStats, GateTBD, TBDResult, group_marks
from seawatch.tracking.mtt import MultiTargetTracker, TrackStates, gnn_assign, tracks_to_mot
from seawatch.tracking.world import ESTIMATORS, PlatformPose, WorldEstimates, WorldTracker

__all__ = [
    "ESTIMATORS",
    "AisAssociation",
    "AisAssociator",
    "FrameStats",
    "GateTBD",
    "MultiTargetTracker",
    "PlatformPose",
    "TBDResult",
    "TrackStates",
    "ViewWedge",
    "WorldEstimates",
    "WorldTracker",
    "gnn_assign",
    "group_marks",
    "tracks_to_mot",
]
