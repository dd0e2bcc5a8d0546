"""Centre location error (ALGORITHMS.md §1.6) against hand-computed values."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from seawatch.metrics.cle import SCALE_RATIO, box_iou, centre_location_error


def test_single_target_cle_matches_hand_computed_3_4_5_offsets():
    gt = np.array([[0.0, 0.0, 30.0, 40.0], [10.0, 0.0, 30.0, 40.0], [20.0, 0.0, 30.0, 40.0]])
    est = gt.copy()
    est[:, 0] += 3.0  # centre offsets (3, 4) -> CLE 5 px
    est[:, 1] += 4.0
    est[2, :2] += [30.0, 40.0]  # frame 2: offsets (33, 44) -> CLE 55 px
    r = centre_location_error(est, gt)
    assert r.per_frame == pytest.approx([5.0, 5.0, 55.0])
    assert r.mean_px == pytest.approx(65.0 / 3)
    assert r.mean_percent == pytest.approx((5 + 5 + 55) / 50.0 * 100 / 3)  # diagonal 50 px
    assert r.precision == pytest.approx(200.0 / 3)  # 2 of 3 frames <= 20 px
    assert r.coverage == 1.0


def test_missing_estimate_fails_precision_but_not_mean():
    gt = np.array([[0.0, 0.0, 6.0, 8.0]] * 4)
    est = gt.copy()
    est[1] = np.nan
    gt[3] = np.nan  # target absent in frame 3
    r = centre_location_error(est, gt)
    assert math.isnan(r.per_frame[1]) and math.isnan(r.per_frame[3])
    assert r.mean_px == 0.0
    assert r.precision == pytest.approx(200.0 / 3)  # frames 0, 2 of the 3 truth frames
    assert r.coverage == pytest.approx(2 / 3)


def test_threshold_is_configurable():
    gt = np.array([[0.0, 0.0, 10.0, 10.0]])
    est = np.array([[12.0, 0.0, 10.0, 10.0]])
    assert centre_location_error(est, gt).precision == 100.0
    assert centre_location_error(est, gt, threshold=10.0).precision == 0.0


def test_mot_rows_match_tracks_to_objects_by_overlap_not_id():
    # two objects; track 7 follows object 2 and track 9 follows object 1 (ids unrelated)
    gt, est = [], []
    for k in range(5):
        gt += [[k, 1, 0.0, 0.0, 10, 10], [k, 2, 100.0, 0.0, 10, 10]]
        est += [[k, 9, 1.0, 0.0, 10, 10], [k, 7, 100.0, 2.0, 10, 10]]
    r = centre_location_error(np.array(est, float), np.array(gt, float))
    assert r.matches == {7: 2, 9: 1}
    assert r.per_frame.reshape(5, 2) == pytest.approx(np.tile([1.0, 2.0], (5, 1)))
    assert r.mean_px == pytest.approx(1.5)


def test_brief_jump_to_neighbour_stays_with_majority_object():
    gt, est = [], []
    for k in range(6):
        gt += [[k, 1, 0.0, 0.0, 10, 10], [k, 2, 30.0, 0.0, 10, 10]]
        x = 30.0 if k == 5 else 0.0  # track 1 jumps onto object 2 in the last frame
        est.append([k, 1, x, 0.0, 10, 10])
    r = centre_location_error(np.array(est, float), np.array(gt, float))
    assert r.matches == {1: 1}
    per = r.per_frame.reshape(6, 2)
    assert per[:5, 0] == pytest.approx(0.0)
    assert per[5, 0] == pytest.approx(30.0)  # scored against its own ship
    assert np.all(np.isnan(per[:, 1]))


def test_a_box_many_times_an_object_s_area_is_no_estimate_of_it():
    """A ship (50 x 12 px) and a boat (7 x 2 px) 40 px to its left; a glitter track's
    box (48 x 13 px) holds the boat in frames 0-49 while no track is on it, then the
    boat's own track takes it in frames 50-99. By the sum of IoU (0.022 a frame) the
    glitter track would belong to the boat and its 50 frames, 12 px off, would be the
    boat's error (rendered lighting case); its box is 45 times the boat's area, so it
    is no estimate of the boat: the boat is scored on its own track alone, and its
    first 50 frames have no estimate. The boat's track, matched, is scored in every
    frame but the one where its box is off in scale (frame 99: 80 x 20 px, merged with
    the ship): there the boat has no estimate."""
    gt, est = [], []
    for k in range(100):
        gt += [[k, 1, 100.0, 200.0, 50, 12], [k, 2, 53.0, 205.0, 7, 2]]
        if k < 50:
            est.append([k, 5, 30.0, 200.0, 48, 13])  # holds the boat, centre 12.5 px off
        else:
            boat = [56.0, 205.0, 7, 2] if k < 99 else [20.0, 196.0, 80, 20]
            est.append([k, 6, *boat])
        est.append([k, 1, 100.0, 200.0, 50, 12])
    r = centre_location_error(np.array(est, float), np.array(gt, float))
    assert r.matches == {1: 1, 6: 2}
    per = r.per_frame.reshape(100, 2)
    assert np.all(np.isnan(per[:50, 1]))
    assert per[50:99, 1] == pytest.approx(3.0)
    assert np.isnan(per[99, 1])
    assert r.coverage == pytest.approx(149 / 200)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    w=st.floats(2.0, 60.0),
    h=st.floats(1.0, 20.0),
    scale=st.floats(1.05, 40.0),
    aspect=st.floats(0.5, 2.0),
    dx=st.floats(-0.5, 0.5),
    dy=st.floats(-0.5, 0.5),
)
def test_a_track_is_matched_to_an_object_only_at_its_scale(w, h, scale, aspect, dx, dy):
    """Property of the several-object match: a track's box that holds a lone object
    (its area ``scale`` times the object's, its centre shifted by up to a quarter of
    its size) is matched to the object, and scored, exactly when the areas are within
    SCALE_RATIO of each other; else the object has no estimate at all."""
    tw = w * np.sqrt(scale * aspect)
    th = h * np.sqrt(scale / aspect)
    cx, cy = 200.0 + 0.5 * w, 100.0 + 0.5 * h
    gt = np.array([[k, 1, 200.0, 100.0, w, h] for k in range(5)], float)
    ox, oy = cx + dx * 0.5 * (tw - w), cy + dy * 0.5 * (th - h)  # the box holds the object
    est = np.array([[k, 3, ox - 0.5 * tw, oy - 0.5 * th, tw, th] for k in range(5)], float)
    r = centre_location_error(est, gt)
    if scale <= SCALE_RATIO:
        assert r.matches == {3: 1}
        assert r.per_frame == pytest.approx(np.full(5, np.hypot(ox - cx, oy - cy)))
    else:
        assert r.matches == {}
        assert np.all(np.isnan(r.per_frame)) and r.coverage == 0.0


def test_box_iou_closed_forms():
    assert box_iou([0, 0, 10, 10], [5, 0, 10, 10]) == pytest.approx(50 / 150)
    assert box_iou([0, 0, 10, 10], [20, 0, 10, 10]) == 0.0
    assert box_iou([0, 0, 0, 0], [0, 0, 0, 0]) == 0.0


@pytest.mark.parametrize("bad", [np.zeros((3, 3)), np.zeros(4), np.zeros((2, 5))])
def test_bad_shapes_raise_naming_est_boxes(bad):
    with pytest.raises(ValueError, match="est_boxes"):
        centre_location_error(bad, np.zeros((3, 4)))


def test_frame_count_mismatch_raises():
    with pytest.raises(ValueError, match="est_boxes"):
        centre_location_error(np.zeros((2, 4)), np.zeros((3, 4)))
