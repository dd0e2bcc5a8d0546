"""Centre location error (CLE) of tracked boxes, ALGORITHMS.md §1.6 (seed 001).

Per frame and truth object::

    CLE_k = sqrt((u_hat_k - u_k^gt)^2 + (v_hat_k - v_k^gt)^2)        [px]

with ``(u, v)`` the box centres. The paper's "percent" is ambiguous, so three numbers
are reported (§1.6):

* ``mean_px``: mean CLE [px] over the frames that have an estimate;
* ``mean_percent``: mean of ``CLE / (ground-truth box diagonal) * 100`` [%] over the same
  frames;
* ``precision``: percentage of the truth frames with ``CLE <= threshold`` (OTB
  convention, 20 px by default); a truth frame without an estimate counts as a failure.

Several objects: estimates and truth are MOT-style rows ``(frame, id, x, y, w, h)``.
Each track id is matched to the truth object it overlaps most over the whole sequence
(the largest sum of per-frame IoU; ties to the lower object id), so a track that
briefly jumps to a neighbour still belongs to its ship. Only frames where the track's
box is of the object's scale count (areas within :data:`SCALE_RATIO` of each other): a
box tens of times larger than a small boat, that holds it (a track on sun glitter
passing over it), is no estimate of the boat, however often it covers it — nor is it
scored as one in the frames of a track matched to the object (a glitter track that
ends on the boat): those frames have no estimate (they fail the precision and lower
the coverage). A truth object may own several
track ids (a track lost and started again); in a frame where two of its tracks are
present, the one with the larger IoU with the truth box is scored.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import FloatArray, as_float_array, positive

__all__ = ["SCALE_RATIO", "CLEResult", "box_iou", "centre_location_error"]

SCALE_RATIO = 10.0
"""Several objects: a track's box is an estimate of an object (counts towards their
match, and is scored) only in the frames where their areas are within this factor of
each other."""


@dataclass(frozen=True)
class CLEResult:
    """Centre location error of one sequence (ALGORITHMS.md §1.6).

    Attributes:
        mean_px: mean CLE over the truth rows that have an estimate [px] (NaN if none).
        mean_percent: mean of CLE / ground-truth box diagonal × 100 over those rows [%].
        precision: truth rows with CLE <= ``threshold`` over all truth rows × 100 [%]
            (a row without an estimate fails).
        per_frame: CLE of every truth row [px], NaN where no estimate covers it; (T,) for
            single-target (T, 4) input, (N,) aligned with the truth rows for MOT input.
        coverage: fraction of truth rows with an estimate [0–1].
        threshold: the precision threshold [px].
        matches: track id → truth object id (MOT input; ``{0: 0}`` for single-target).
    """

    mean_px: float
    mean_percent: float
    precision: float
    per_frame: FloatArray
    coverage: float
    threshold: float
    matches: dict[int, int] = field(default_factory=dict)


def box_iou(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """Intersection over union of boxes ``(x, y, w, h)`` [px], broadcast over rows.

    Boxes with zero area give IoU 0.
    """
    A = np.asarray(a, dtype=np.float64)
    B = np.asarray(b, dtype=np.float64)
    ix = np.minimum(A[..., 0] + A[..., 2], B[..., 0] + B[..., 2]) - np.maximum(A[..., 0], B[..., 0])
    iy = np.minimum(A[..., 1] + A[..., 3], B[..., 1] + B[..., 3]) - np.maximum(A[..., 1], B[..., 1])
    inter = np.clip(ix, 0.0, None) * np.clip(iy, 0.0, None)
    union = A[..., 2] * A[..., 3] + B[..., 2] * B[..., 3] - inter
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(union > 0.0, inter / np.where(union > 0.0, union, 1.0), 0.0)


def _rows(name: str, value: ArrayLike) -> tuple[FloatArray, bool]:
    """(N, 6) MOT rows from (T, 4) frame-aligned boxes or (N, 6) rows; flag single-target."""
    arr = as_float_array(name, value)
    if arr.ndim == 2 and arr.shape[1] == 4:
        keep = np.all(np.isfinite(arr), axis=1)
        frames = np.arange(arr.shape[0], dtype=np.float64)
        rows = np.column_stack([frames, np.zeros(arr.shape[0]), arr])[keep]
        return rows, True
    if arr.ndim == 2 and arr.shape[1] == 6:
        if not np.all(np.isfinite(arr[:, :2])):
            raise ValueError(f"{name}: frame and id columns must be finite")
        return arr[np.all(np.isfinite(arr[:, 2:]), axis=1)], False
    if arr.size == 0:
        return np.empty((0, 6)), False
    raise ValueError(
        f"{name}: expected boxes (T, 4) as (x, y, w, h) per frame or MOT rows (N, 6) as "
        f"(frame, id, x, y, w, h), got shape {arr.shape}"
    )


def centre_location_error(
    est_boxes: ArrayLike, gt_boxes: ArrayLike, *, threshold: float = 20.0
) -> CLEResult:
    """Centre location error of tracked boxes against the truth, ALGORITHMS.md §1.6.

    Args:
        est_boxes: estimated boxes [px], either (T, 4) ``(x, y, w, h)`` per frame of one
            target (NaN rows: no estimate) or MOT rows (N, 6) ``(frame, id, x, y, w, h)``
            of any number of tracks (see the module docstring for the matching).
        gt_boxes: truth boxes [px] in the same layout ((T, 4) with NaN rows where the
            target is absent, or (M, 6) rows with object ids). Both inputs must use the
            same layout.
        threshold: precision threshold on CLE [px] (OTB: 20).

    Returns:
        :class:`CLEResult`.

    Raises:
        ValueError: naming ``est_boxes`` or ``gt_boxes`` for a bad shape, or mixed layouts.
    """
    thr = positive("threshold", threshold)
    est, single_e = _rows("est_boxes", est_boxes)
    gt, single_g = _rows("gt_boxes", gt_boxes)
    a_e = np.asarray(est_boxes)
    a_g = np.asarray(gt_boxes)
    if a_e.size and a_g.size and single_e != single_g:
        raise ValueError(
            "est_boxes: must have the layout of gt_boxes ((T, 4) boxes or (N, 6) MOT rows)"
        )
    if single_g and a_e.size and a_e.shape[0] != a_g.shape[0]:
        raise ValueError(
            f"est_boxes: expected {a_g.shape[0]} frames like gt_boxes, got {a_e.shape[0]}"
        )
    n = gt.shape[0]
    per_frame = np.full(n, np.nan)
    matches: dict[int, int] = {}
    if n and est.shape[0]:
        # all (est row, gt row) pairs in the same frame
        order = np.argsort(gt[:, 0], kind="stable")
        gf = gt[order, 0]
        lo = np.searchsorted(gf, est[:, 0], side="left")
        hi = np.searchsorted(gf, est[:, 0], side="right")
        counts = hi - lo
        ei = np.repeat(np.arange(est.shape[0]), counts)
        gi = order[np.repeat(lo - (np.cumsum(counts) - counts), counts) + np.arange(counts.sum())]
        iou = box_iou(est[ei, 2:], gt[gi, 2:])
        tids, t_inv = np.unique(est[ei, 1], return_inverse=True)
        oids, o_inv = np.unique(gt[gi, 1], return_inverse=True)
        # a box over SCALE_RATIO times the object's area, or under its 1/SCALE_RATIO, is
        # no estimate of that object (a glint track's box over a small boat): its
        # overlap does not count towards the match
        ae, ag = np.prod(est[ei, 4:6], axis=1), np.prod(gt[gi, 4:6], axis=1)
        scaled = (ae <= SCALE_RATIO * ag) & (ag <= SCALE_RATIO * ae)
        total = np.zeros((tids.size, oids.size))
        np.add.at(total, (t_inv, o_inv), np.where(scaled, iou, 0.0))
        best = np.argmax(total, axis=1)  # ties: first (lowest) object id
        owned = total[np.arange(tids.size), best] > 0.0
        if single_g:  # one target: the estimate is its estimate whatever the overlap
            owned[:] = True
        for k in np.flatnonzero(owned):
            matches[int(tids[k])] = int(oids[best[k]])
        mine = owned[t_inv] & (best[t_inv] == o_inv) & (scaled | single_g)
        ei, gi, iou = ei[mine], gi[mine], iou[mine]
        # per truth row keep the owned estimate with the largest IoU
        pick = np.lexsort((-iou, gi))
        first = np.ones(pick.size, bool)
        first[1:] = gi[pick][1:] != gi[pick][:-1]
        ei, gi = ei[pick][first], gi[pick][first]
        ce = est[ei, 2:4] + 0.5 * est[ei, 4:6]
        cg = gt[gi, 2:4] + 0.5 * gt[gi, 4:6]
        per_frame[gi] = np.hypot(ce[:, 0] - cg[:, 0], ce[:, 1] - cg[:, 1])
    has = np.isfinite(per_frame)
    diag = np.hypot(gt[:, 4], gt[:, 5])
    if has.any():
        mean_px = float(np.mean(per_frame[has]))
        with np.errstate(divide="ignore", invalid="ignore"):
            mean_pct = float(np.mean(per_frame[has] / diag[has] * 100.0))
    else:
        mean_px = mean_pct = float("nan")
    precision = (
        float(np.mean(has & (np.nan_to_num(per_frame, nan=np.inf) <= thr)) * 100.0)
        if n
        else float("nan")
    )
    if single_g:
        full = np.full(a_g.shape[0], np.nan)
        full[gt[:, 0].astype(np.int64)] = per_frame
        per_frame = full
    return CLEResult(
        mean_px=mean_px,
        mean_percent=mean_pct,
        precision=precision,
        per_frame=per_frame,
        coverage=float(has.mean()) if n else float("nan"),
        threshold=thr,
        matches=matches,
    )
