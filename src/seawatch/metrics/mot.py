"""CLEAR-MOT, identity and HOTA metrics through TrackEval's metric classes.

* CLEAR-MOT (Bernardin & Stiefelhagen, *EURASIP J. Image Video Process.* 2008):
  ``MOTA = 1 − (FN + FP + IDSW) / GT`` and MOTP, the mean similarity of the matches.
* Identity (Ristani et al., *ECCV Workshops* 2016): ``IDF1 = 2 IDTP / (2 IDTP + IDFP +
  IDFN)`` with IDP, IDR, under the best one-to-one mapping of whole trajectories.
* HOTA (Luiten et al., *IJCV* 129, 2021): ``HOTA_α = sqrt(DetA_α · AssA_α)`` averaged
  over the localisation thresholds α = 0.05, 0.10, …, 0.95.

The numbers come from TrackEval 1.3.0's own classes (``trackeval.metrics.CLEAR``,
``Identity``, ``HOTA`` and their ``eval_sequence``), fed with a data dictionary built
here (ids per frame, similarity matrices). py-motmetrics is not used (broken on NumPy 2,
DEPENDENCIES.md).

Similarity between a ground-truth object and a track in one frame:

* ``"iou"``: intersection over union of the boxes ``(x, y, w, h)`` in px;
* ``"distance"``: ``max(0, 1 − d / max_distance)`` for the Euclidean distance d between
  points (x, y) (TrackEval's Euclidean similarity, ``zero_distance = max_distance``), in
  the points' unit (px or m).

A pair counts as a match for CLEAR and identity when its similarity is at least
``threshold`` (IoU >= 0.5 by default; for distances: ``d <= (1 − threshold) ·
max_distance``).

Inputs are MOT rows: (N, >= 6) ``frame, id, x, y, w, h, …`` for boxes, (N, >= 4)
``frame, id, x, y, …`` for points (:func:`seawatch.io.mot.read_mot`,
:func:`seawatch.tracking.mtt.tracks_to_mot`).
"""

from __future__ import annotations

import contextlib
import functools
import io
from dataclasses import asdict, dataclass
from types import ModuleType
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import FloatArray, as_float_array, in_range, positive

__all__ = [
    "ClearMetrics",
    "HotaMetrics",
    "IdentityMetrics",
    "MOTMetrics",
    "box_iou",
    "clear_metrics",
    "hota_metrics",
    "identity_metrics",
    "mot_data",
    "mot_metrics",
]

Similarity = Literal["iou", "distance"]


@functools.cache
def _trackeval() -> ModuleType:
    """Import TrackEval quietly (it prints a harmless BURST/pycocotools error on import)."""
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            import trackeval
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise ImportError(
            "the MOT metrics need TrackEval: pip install --no-deps trackeval tabulate "
            "(see DEPENDENCIES.md)"
        ) from exc
    return trackeval


# --------------------------------------------------------------------------------------
# results
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ClearMetrics:
    """CLEAR-MOT scores of one sequence (TrackEval ``CLEAR``).

    Attributes:
        mota: multi-object tracking accuracy, ``(TP − FP − IDSW) / (TP + FN)``.
        motp: mean similarity of the matches (IoU, or ``1 − d / max_distance``).
        moda: detection accuracy ``(TP − FP) / (TP + FN)``.
        tp, fp, fn: matched, false and missed object-frames.
        id_switches: matches whose track id differs from the object's previous one.
        mostly_tracked, partially_tracked, mostly_lost: objects tracked > 80 %,
            20–80 %, < 20 % of their frames.
        fragmentations: interruptions of an object's tracked stretches.
        motp_distance: mean distance of the matches in the points' unit
            (``(1 − MOTP) · max_distance``) for ``similarity="distance"``, else None.
    """

    mota: float
    motp: float
    moda: float
    tp: int
    fp: int
    fn: int
    id_switches: int
    mostly_tracked: int
    partially_tracked: int
    mostly_lost: int
    fragmentations: int
    motp_distance: float | None = None


@dataclass(frozen=True)
class IdentityMetrics:
    """Identity scores of one sequence (TrackEval ``Identity``).

    Attributes:
        idf1: identity F1, ``2 IDTP / (2 IDTP + IDFP + IDFN)``.
        idp, idr: identity precision and recall.
        idtp, idfp, idfn: identity true positives, false positives, false negatives
            (object-frames) under the best trajectory-to-trajectory mapping.
    """

    idf1: float
    idp: float
    idr: float
    idtp: int
    idfp: int
    idfn: int


@dataclass(frozen=True)
class HotaMetrics:
    """HOTA scores of one sequence (TrackEval ``HOTA``), averaged over α.

    Attributes:
        hota: higher-order tracking accuracy, mean over α of ``sqrt(DetA_α AssA_α)``.
        deta, assa: detection and association accuracy (means over α).
        loca: localisation accuracy (mean over α).
        alphas: the thresholds α, (19,).
        hota_alpha: HOTA at each α, (19,).
    """

    hota: float
    deta: float
    assa: float
    loca: float
    alphas: FloatArray
    hota_alpha: FloatArray


@dataclass(frozen=True)
class MOTMetrics:
    """All three families for one sequence (:func:`mot_metrics`)."""

    clear: ClearMetrics
    identity: IdentityMetrics
    hota: HotaMetrics

    @property
    def mota(self) -> float:
        return self.clear.mota

    @property
    def idf1(self) -> float:
        return self.identity.idf1

    def as_dict(self) -> dict[str, Any]:
        """Flat JSON-ready dictionary (arrays as lists)."""
        out: dict[str, Any] = {}
        for part in (self.clear, self.identity, self.hota):
            for key, value in asdict(part).items():
                out[key] = value.tolist() if isinstance(value, np.ndarray) else value
        return out


# --------------------------------------------------------------------------------------
# building TrackEval's data dictionary
# --------------------------------------------------------------------------------------


def box_iou(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """Intersection over union of boxes ``(x, y, w, h)``: (n, 4) × (k, 4) → (n, k).

    Zero-area boxes have IoU 0 with everything.
    """
    A = as_float_array("a", a).reshape(-1, 4)
    B = as_float_array("b", b).reshape(-1, 4)
    ax2, ay2 = A[:, 0] + A[:, 2], A[:, 1] + A[:, 3]
    bx2, by2 = B[:, 0] + B[:, 2], B[:, 1] + B[:, 3]
    iw = np.minimum(ax2[:, None], bx2[None]) - np.maximum(A[:, 0][:, None], B[:, 0][None])
    ih = np.minimum(ay2[:, None], by2[None]) - np.maximum(A[:, 1][:, None], B[:, 1][None])
    inter = np.clip(iw, 0.0, None) * np.clip(ih, 0.0, None)
    union = (A[:, 2] * A[:, 3])[:, None] + (B[:, 2] * B[:, 3])[None] - inter
    safe = np.where(union > 0.0, union, 1.0)
    return np.where(union > 0.0, inter / safe, 0.0)


def _rows(name: str, rows: ArrayLike, width: int) -> FloatArray:
    arr = as_float_array(name, rows)
    if arr.ndim == 1 and arr.size == 0:
        arr = arr.reshape(0, width)
    if arr.ndim != 2 or arr.shape[1] < width:
        cols = "frame, id, x, y, w, h" if width == 6 else "frame, id, x, y"
        raise ValueError(f"{name}: expected rows (N, >= {width}) of {cols}, got {arr.shape}")
    if not np.all(np.isfinite(arr[:, :width])):
        raise ValueError(f"{name}: contains NaN or inf")
    if np.any(arr[:, :2] != np.round(arr[:, :2])):
        raise ValueError(f"{name}: frame and id columns must hold integers")
    return arr


def mot_data(
    gt: ArrayLike,
    tracks: ArrayLike,
    similarity: Similarity = "iou",
    *,
    max_distance: float | None = None,
    frames: ArrayLike | None = None,
) -> dict[str, Any]:
    """TrackEval's per-sequence data dictionary for ``eval_sequence``.

    Ids of each side are mapped to 0..K-1 in increasing order; the time steps are
    ``frames`` (default: every frame present in either input, sorted).

    Returns:
        dict with ``gt_ids``, ``tracker_ids`` (lists of int arrays per time step),
        ``similarity_scores`` (list of (n_gt_t, n_trk_t) arrays), ``num_timesteps``,
        ``num_gt_ids``, ``num_tracker_ids``, ``num_gt_dets``, ``num_tracker_dets``.

    Raises:
        ValueError: naming the input for bad shapes or an id twice in one frame, or
            ``max_distance`` missing for distances.
    """
    if similarity == "iou":
        width = 6
    elif similarity == "distance":
        width = 4
        if max_distance is None:
            raise ValueError("max_distance: required with similarity='distance'")
        max_distance = positive("max_distance", max_distance)
    else:
        raise ValueError(f"similarity: expected 'iou' or 'distance', got {similarity!r}")
    g = _rows("gt", gt, width)
    t = _rows("tracks", tracks, width)
    for name, arr in (("gt", g), ("tracks", t)):
        if np.unique(arr[:, :2], axis=0).shape[0] != arr.shape[0]:
            raise ValueError(f"{name}: an id appears more than once in a frame")
    steps = (
        np.union1d(g[:, 0], t[:, 0])
        if frames is None
        else np.unique(as_float_array("frames", frames, ndim=1))
    )
    g_ids, g_idx = np.unique(g[:, 1], return_inverse=True)
    t_ids, t_idx = np.unique(t[:, 1], return_inverse=True)
    g_order = np.argsort(g[:, 0], kind="stable")
    t_order = np.argsort(t[:, 0], kind="stable")
    g_bounds = (
        np.searchsorted(g[g_order, 0], steps, side="left"),
        np.searchsorted(g[g_order, 0], steps, side="right"),
    )
    t_bounds = (
        np.searchsorted(t[t_order, 0], steps, side="left"),
        np.searchsorted(t[t_order, 0], steps, side="right"),
    )
    data: dict[str, Any] = {"gt_ids": [], "tracker_ids": [], "similarity_scores": []}
    for k in range(steps.shape[0]):
        gi = g_order[g_bounds[0][k] : g_bounds[1][k]]
        ti = t_order[t_bounds[0][k] : t_bounds[1][k]]
        data["gt_ids"].append(g_idx[gi].astype(int))
        data["tracker_ids"].append(t_idx[ti].astype(int))
        if similarity == "iou":
            sim = box_iou(g[gi, 2:6], t[ti, 2:6])
        else:
            d = np.linalg.norm(g[gi, None, 2:4] - t[None, ti, 2:4], axis=-1)
            sim = np.maximum(0.0, 1.0 - d / max_distance)
        data["similarity_scores"].append(sim)
    data["num_timesteps"] = int(steps.shape[0])
    data["num_gt_ids"] = int(g_ids.shape[0])
    data["num_tracker_ids"] = int(t_ids.shape[0])
    data["num_gt_dets"] = int(sum(a.shape[0] for a in data["gt_ids"]))
    data["num_tracker_dets"] = int(sum(a.shape[0] for a in data["tracker_ids"]))
    return data


# --------------------------------------------------------------------------------------
# the metrics
# --------------------------------------------------------------------------------------


def _threshold(threshold: float) -> float:
    return in_range("threshold", threshold, 0.0, 1.0)


def _quiet(fn: Any, *args: Any) -> Any:
    with contextlib.redirect_stdout(io.StringIO()):
        return fn(*args)


def _clear(data: dict[str, Any], threshold: float, max_distance: float | None) -> ClearMetrics:
    te = _trackeval()
    metric = _quiet(te.metrics.CLEAR, {"THRESHOLD": threshold, "PRINT_CONFIG": False})
    res = _quiet(metric.eval_sequence, data)
    motp = float(res["MOTP"])
    return ClearMetrics(
        mota=float(res["MOTA"]),
        motp=motp,
        moda=float(res["MODA"]),
        tp=int(res["CLR_TP"]),
        fp=int(res["CLR_FP"]),
        fn=int(res["CLR_FN"]),
        id_switches=int(res["IDSW"]),
        mostly_tracked=int(res["MT"]),
        partially_tracked=int(res["PT"]),
        mostly_lost=int(res["ML"]),
        fragmentations=int(res["Frag"]),
        motp_distance=None
        if max_distance is None or res["CLR_TP"] == 0
        else (1.0 - motp) * max_distance,
    )


def _identity(data: dict[str, Any], threshold: float) -> IdentityMetrics:
    te = _trackeval()
    metric = _quiet(te.metrics.Identity, {"THRESHOLD": threshold, "PRINT_CONFIG": False})
    res = _quiet(metric.eval_sequence, data)
    return IdentityMetrics(
        idf1=float(res["IDF1"]),
        idp=float(res["IDP"]),
        idr=float(res["IDR"]),
        idtp=int(res["IDTP"]),
        idfp=int(res["IDFP"]),
        idfn=int(res["IDFN"]),
    )


def _hota(data: dict[str, Any]) -> HotaMetrics:
    te = _trackeval()
    metric = _quiet(te.metrics.HOTA)
    res = _quiet(metric.eval_sequence, data)
    return HotaMetrics(
        hota=float(np.mean(res["HOTA"])),
        deta=float(np.mean(res["DetA"])),
        assa=float(np.mean(res["AssA"])),
        loca=float(np.mean(res["LocA"])),
        alphas=np.asarray(metric.array_labels, dtype=np.float64),
        hota_alpha=np.asarray(res["HOTA"], dtype=np.float64),
    )


def clear_metrics(
    gt: ArrayLike,
    tracks: ArrayLike,
    similarity: Similarity = "iou",
    threshold: float = 0.5,
    *,
    max_distance: float | None = None,
    frames: ArrayLike | None = None,
) -> ClearMetrics:
    """CLEAR-MOT (MOTA, MOTP, ID switches, FP, FN, …) of tracks against ground truth.

    Args:
        gt, tracks: MOT rows (module docstring).
        similarity: ``"iou"`` (boxes, px) or ``"distance"`` (points).
        threshold: least similarity of a match (IoU, or ``1 − d / max_distance``).
        max_distance: distance at which the similarity reaches 0 (points' unit);
            required for ``"distance"``.
        frames: the frames of the sequence (default: all frames of either input).
    """
    th = _threshold(threshold)
    data = mot_data(gt, tracks, similarity, max_distance=max_distance, frames=frames)
    return _clear(data, th, max_distance if similarity == "distance" else None)


def identity_metrics(
    gt: ArrayLike,
    tracks: ArrayLike,
    similarity: Similarity = "iou",
    threshold: float = 0.5,
    *,
    max_distance: float | None = None,
    frames: ArrayLike | None = None,
) -> IdentityMetrics:
    """Identity scores (IDF1, IDP, IDR); arguments as :func:`clear_metrics`."""
    th = _threshold(threshold)
    data = mot_data(gt, tracks, similarity, max_distance=max_distance, frames=frames)
    return _identity(data, th)


def hota_metrics(
    gt: ArrayLike,
    tracks: ArrayLike,
    similarity: Similarity = "iou",
    *,
    max_distance: float | None = None,
    frames: ArrayLike | None = None,
) -> HotaMetrics:
    """HOTA, DetA, AssA, LocA (means over α); arguments as :func:`clear_metrics`."""
    data = mot_data(gt, tracks, similarity, max_distance=max_distance, frames=frames)
    return _hota(data)


def mot_metrics(
    gt: ArrayLike,
    tracks: ArrayLike,
    similarity: Similarity = "iou",
    threshold: float = 0.5,
    *,
    max_distance: float | None = None,
    frames: ArrayLike | None = None,
) -> MOTMetrics:
    """CLEAR-MOT, identity and HOTA in one call; arguments as :func:`clear_metrics`.

    Example (FVessel Video-01, the authors' tracker against the ground truth, IoU >= 0.5):
    MOTA 0.8672, IDF1 0.8474, HOTA 0.6524.
    """
    th = _threshold(threshold)
    data = mot_data(gt, tracks, similarity, max_distance=max_distance, frames=frames)
    md = max_distance if similarity == "distance" else None
    return MOTMetrics(clear=_clear(data, th, md), identity=_identity(data, th), hota=_hota(data))
