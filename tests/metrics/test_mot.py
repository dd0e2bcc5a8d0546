"""CLEAR-MOT, identity and HOTA through TrackEval.

Independent truths: the verified TrackEval numbers and py-motmetrics 1.4.0's numbers on
FVessel Video-01 (``../shared/data/fvessel/``, MIT, FVessel repository
``02_demo_metric/sample/``; values in ``../shared/data/README.md``), and small sequences
whose scores are worked out by hand from the metric definitions.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from seawatch.io.mot import read_mot
from seawatch.metrics import (
    box_iou,
    clear_metrics,
    hota_metrics,
    identity_metrics,
    mot_data,
    mot_metrics,
)

FVESSEL = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "fvessel"


def _fvessel() -> tuple[np.ndarray, np.ndarray]:
    gt = FVESSEL / "Video-01_gt_tracking.txt"
    if not gt.exists():
        pytest.skip(f"FVessel sample not found at {FVESSEL}")
    return read_mot(gt), read_mot(FVESSEL / "Video-01_re_tracking.txt")


def test_fvessel_authors_tracker_scores_match_the_verified_trackeval_numbers():
    gt, tracks = _fvessel()
    m = mot_metrics(gt, tracks, "iou", 0.5)
    assert m.mota == pytest.approx(0.8672, abs=5e-5)
    assert m.idf1 == pytest.approx(0.8474, abs=5e-5)
    assert m.hota.hota == pytest.approx(0.6524, abs=5e-5)


def test_fvessel_at_iou_0_3_matches_py_motmetrics_counts():
    gt, tracks = _fvessel()
    clear = clear_metrics(gt, tracks, "iou", 0.3)
    ident = identity_metrics(gt, tracks, "iou", 0.3)
    assert (clear.id_switches, clear.fp, clear.fn) == (2, 144, 31)
    assert clear.mota == pytest.approx(0.8964, abs=5e-5)
    assert ident.idf1 == pytest.approx(0.8519, abs=5e-5)


def test_single_calls_agree_with_the_combined_call():
    gt, tracks = _fvessel()
    both = mot_metrics(gt, tracks)
    assert clear_metrics(gt, tracks) == both.clear
    assert identity_metrics(gt, tracks) == both.identity
    assert hota_metrics(gt, tracks).hota == both.hota.hota


def test_hand_worked_id_switch_halves_idf1_and_costs_one_in_mota():
    # one object at the origin for 4 frames; the tracker changes id after frame 1
    gt = np.array([[f, 1, 0.0, 0.0] for f in range(4)])
    tracks = np.array([[f, 10 if f < 2 else 11, 0.0, 0.0] for f in range(4)])
    m = mot_metrics(gt, tracks, "distance", max_distance=1.0)
    assert (m.clear.tp, m.clear.fp, m.clear.fn, m.clear.id_switches) == (4, 0, 0, 1)
    assert m.mota == pytest.approx((4 - 0 - 1) / 4)
    # best id mapping 1 -> 10: IDTP 2, IDFN 2, IDFP 2 -> IDF1 = 4 / (4 + 2 + 2)
    assert m.idf1 == pytest.approx(0.5)
    # DetA = 1 at every alpha (exact positions); each match's association score is
    # TPA / (TPA + FNA + FPA) = 2 / (2 + 2 + 0) -> AssA 0.5, HOTA = sqrt(0.5)
    assert m.hota.deta == pytest.approx(1.0)
    assert m.hota.assa == pytest.approx(0.5)
    assert m.hota.hota == pytest.approx(math.sqrt(0.5))


def test_perfect_tracks_score_one_everywhere():
    gt, _ = _fvessel()
    tracks = gt.copy()
    tracks[:, 1] += 100  # ids need not coincide
    m = mot_metrics(gt, tracks)
    assert m.mota == 1.0 and m.idf1 == 1.0 and m.hota.hota == pytest.approx(1.0)
    assert m.clear.motp == pytest.approx(1.0)


def test_distance_matching_threshold_and_motp_in_the_points_unit():
    gt = np.array([[0, 1, 0.0, 0.0], [0, 2, 100.0, 0.0]])
    tracks = np.array([[0, 7, 2.0, 0.0], [0, 8, 103.0, 0.0]])
    # similarity 1 - d / 5: 0.6 (match) and 0.4 (no match at threshold 0.5)
    c = clear_metrics(gt, tracks, "distance", 0.5, max_distance=5.0)
    assert (c.tp, c.fp, c.fn) == (1, 1, 1)
    assert c.motp == pytest.approx(0.6) and c.motp_distance == pytest.approx(2.0)
    c = clear_metrics(gt, tracks, "distance", 0.3, max_distance=5.0)
    assert c.tp == 2 and c.motp_distance == pytest.approx(2.5)


def test_empty_tracks_or_truth_count_every_object_as_missed_or_false():
    gt, _ = _fvessel()
    none = np.empty((0, 6))
    c = clear_metrics(gt, none)
    assert c.fn == gt.shape[0] and c.tp == 0 and c.mota == 0.0
    c = clear_metrics(none, gt)
    assert c.fp == gt.shape[0] and c.tp == 0


def test_box_iou_known_values():
    a = np.array([[0, 0, 2, 2], [0, 0, 2, 2], [5, 5, 0, 0]])
    b = np.array([[0, 0, 2, 2], [1, 0, 2, 2], [10, 10, 1, 1]])
    iou = box_iou(a, b)
    assert iou[0, 0] == 1.0 and iou[1, 1] == pytest.approx(2 / 6) and iou[0, 2] == 0.0
    assert np.all(iou[2] == 0.0)  # a zero-area box overlaps nothing
    assert box_iou(np.empty((0, 4)), b).shape == (0, 3)


def test_trackeval_data_maps_ids_to_consecutive_indices_per_frame():
    gt = np.array([[3, 50, 0, 0, 1, 1], [3, 7, 5, 5, 1, 1], [5, 50, 0, 0, 1, 1]])
    tr = np.array([[4, 9, 0, 0, 1, 1]])
    data = mot_data(gt, tr)
    assert data["num_timesteps"] == 3 and data["num_gt_ids"] == 2
    assert [a.tolist() for a in data["gt_ids"]] == [[1, 0], [], [1]]
    assert [a.tolist() for a in data["tracker_ids"]] == [[], [0], []]
    assert data["similarity_scores"][0].shape == (2, 0)


def test_bad_inputs_raise_naming_the_argument():
    gt = np.array([[0, 1, 0, 0, 1, 1]])
    with pytest.raises(ValueError, match="gt"):
        mot_metrics(np.array([[0, 1, 0, 0, 1, 1], [0, 1, 2, 2, 1, 1]]), gt)
    with pytest.raises(ValueError, match="tracks"):
        mot_metrics(gt, np.zeros((2, 3)))
    with pytest.raises(ValueError, match="tracks"):
        mot_metrics(gt, np.array([[0.5, 1, 0, 0, 1, 1]]))
    with pytest.raises(ValueError, match="max_distance"):
        mot_metrics(gt, gt, "distance")
    with pytest.raises(ValueError, match="similarity"):
        mot_metrics(gt, gt, "giou")
    with pytest.raises(ValueError, match="threshold"):
        mot_metrics(gt, gt, threshold=1.5)
    with pytest.raises(ValueError, match="gt"):
        mot_metrics(np.array([[0, 1, np.nan, 0, 1, 1]]), gt)
