"""Gating, association, track management and track-before-detect (pixels and points).

* :class:`~seawatch.tracking.gate_tbd.GateTBD` — the two-gate ("strobe")
  track-before-detect of seed 004 (ALGORITHMS.md §8.1), with its per-frame
  :class:`FrameStats`, whole-sequence :class:`TBDResult` and :func:`group_marks`.
* :class:`~seawatch.tracking.mtt.MultiTargetTracker` — ships as boxes or points:
  Mahalanobis gating, global-nearest-neighbour assignment, M-of-N confirmation,
  deletion after K misses, any filter of :mod:`seawatch.filters` per track.
"""

from seawatch.tracking.gate_tbd import FrameStats, GateTBD, TBDResult, group_marks
from seawatch.tracking.mtt import MultiTargetTracker, TrackStates, gnn_assign, tracks_to_mot

__all__ = [
    "FrameStats",
    "GateTBD",
    "MultiTargetTracker",
    "TBDResult",
    "TrackStates",
    "gnn_assign",
    "group_marks",
    "tracks_to_mot",
]
