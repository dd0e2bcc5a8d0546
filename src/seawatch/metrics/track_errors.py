"""Scores of a tracking run against synthetic ground truth: ``seawatch track --truth``.

:func:`score_tracks` compares the track table of a run (``tracks.csv``, INTERFACES.md
"Track table") with the ``truth.csv`` of the footage (INTERFACES.md "Synthetic footage")
and returns :class:`TrackErrors`, whose :meth:`TrackErrors.to_json` is the ``errors``
object of ``seawatch track --json``: ``rmse_position_m``, ``rmse_range_percent``,
``cle_px``, ``id_switches``, ``mota``, ``idf1`` plus the details below.

Matching (per frame, the same assignment as CLEAR-MOT)
------------------------------------------------------
Rows are paired by their ``frame`` number. In each frame the similarity of every truth
box and track box is their IoU (``match="iou"``, boxes ``(x, y, w, h)`` [px]; a pair is a
candidate when IoU ≥ ``threshold``, default 0.3: small, distant ships have boxes a few
pixels high, where a pixel or two of box error costs a lot of IoU) or, with
``match="centre"``, ``max(0, 1 − d / (2 gate))`` for the distance d [px] between the box
centres (a candidate when d ≤ ``gate_px``). The pairs are chosen as TrackEval's CLEAR
does (Bernardin & Stiefelhagen 2008): a pair that was matched in the previous frame
keeps priority (score + 1000), then the Hungarian assignment maximises the summed
similarity over the candidates (:func:`scipy.optimize.linear_sum_assignment`). MOTA,
ID switches and IDF1 come from TrackEval itself (:func:`seawatch.metrics.mot.mot_metrics`,
same similarity and threshold); the matched pairs here are exactly CLEAR's true
positives (``pairs == tp``).

Errors over the matched pairs
-----------------------------
* ``cle_px``: mean distance between the centres of the matched boxes [px].
* ``rmse_position_m``: ``sqrt(mean(|p̂ − p|²))`` with p̂ the row's ``(east_m, north_m)``
  and p the truth's [m] (rows without a position are left out and counted).
* ``rmse_range_percent``: ``100 · sqrt(mean(((r̂ − r) / r)²))`` with ``r = |p − c|``,
  ``r̂ = |p̂ − c|`` the horizontal distances from the camera's foot point c [m]. c is
  the camera's local ``position`` (the origin of the renderer's east/north: a camera
  file without ``north_m``/``east_m`` stands at (0, 0)); ``camera`` may be given as a
  camera or a camera file, else the ``camera.yaml`` beside ``truth.csv`` is used when it
  exists, else c = (0, 0).
* ``range_bins``: the same errors per truth-range bin (:data:`RANGE_BINS`, metres), with
  the signed mean relative range error (bias) — e.g. issue 7's "range error under 5 %
  at 1 km" is the 750–1250 m bin.

Pixel truth: a truth table without ``east_m``/``north_m`` (boxes annotated on a real
clip: ``frame``, ``object_id``, ``x``, ``y``, ``w``, ``h``) gives the box scores (MOTA,
IDF1, HOTA, CLE) alone; the position errors are NaN (null in the JSON).

Several estimators: ``positions`` maps an estimator name to the (east, north) column
names of ``tracks.csv`` to score (default ``{"tracks": ("east_m", "north_m")}``; the
first entry gives the headline numbers), and ``estimates`` names a long-form table with
one row per frame, track and estimator (columns ``frame``, ``track_id``,
``estimator``, ``east_m``, ``north_m``, as the pipeline's ``estimates.csv``): each
estimator's positions are scored over the pairs matched by the track boxes.

Truth too small to track: ``min_truth_height`` [px] (default 0: score everything) turns
truth rows with a lower box into "don't care" areas: they are removed, with the track
rows matched to them in that frame (neither hits nor false alarms).

Track rows without a box (empty x, y, w or h) cannot be matched and are left out.

Bad input: a missing or unreadable file, a missing column, a non-numeric cell in a
required column or a (frame, id) pair twice raises ValueError naming the file.
"""

from __future__ import annotations

import csv
import itertools
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
from scipy.optimize import linear_sum_assignment

from seawatch._validation import FloatArray, in_range, positive
from seawatch.metrics.mot import box_iou, mot_metrics

__all__ = [
    "RANGE_BINS",
    "ObjectCoverage",
    "PositionErrors",
    "RangeBin",
    "TrackErrors",
    "match_boxes",
    "score_tracks",
]

RANGE_BINS: tuple[float, ...] = (
    0.0, 250.0, 500.0, 750.0, 1250.0, 1750.0, 2500.0, 3500.0, 5000.0, 7500.0, math.inf,
)  # fmt: skip
"""Default edges of the truth-range bins [m]."""

Match = Literal["iou", "centre"]
_PathLike = str | os.PathLike[str]


# ----------------------------------------------------------------------------- results
@dataclass(frozen=True)
class RangeBin:
    """Position and range errors of the matched pairs whose truth range is in [lo, hi).

    Attributes:
        lo, hi: bin edges [m].
        pairs: pairs with a position estimate in the bin.
        rmse_position_m: position RMSE [m]; rmse_range_percent: RMS relative range
            error [%]; mean_range_error_percent: mean signed relative error [%]
            (NaN without pairs).
    """

    lo: float
    hi: float
    pairs: int
    rmse_position_m: float
    rmse_range_percent: float
    mean_range_error_percent: float

    def to_json(self) -> dict[str, Any]:
        """JSON-ready dictionary (``hi`` None for an open bin)."""
        return {
            "range_from_m": self.lo,
            "range_to_m": None if math.isinf(self.hi) else self.hi,
            "pairs": self.pairs,
            "rmse_position_m": _num(self.rmse_position_m),
            "rmse_range_percent": _num(self.rmse_range_percent),
            "mean_range_error_percent": _num(self.mean_range_error_percent),
        }


@dataclass(frozen=True, eq=False)
class PositionErrors:
    """World-position errors of one estimator over the matched pairs.

    Attributes:
        name: estimator name; columns: its (east, north) column names.
        pairs: matched pairs with a finite position estimate; missing: matched pairs
            without one.
        rmse_position_m: ``sqrt(mean(|p̂ − p|²))`` [m].
        rmse_range_percent: ``100 sqrt(mean(((r̂ − r)/r)²))`` [%].
        mean_range_error_percent: ``100 mean((r̂ − r)/r)`` [%] (bias).
        bins: the same per truth-range bin.
        position_error: |p̂ − p| per pair [m], (pairs,); range_error_percent: 100 (r̂ −
            r)/r per pair [%]; truth_range: r per pair [m]; frame, object_id, track_id:
            where each pair is, (pairs,).
    """

    name: str
    columns: tuple[str, str]
    pairs: int
    missing: int
    rmse_position_m: float
    rmse_range_percent: float
    mean_range_error_percent: float
    bins: tuple[RangeBin, ...]
    position_error: FloatArray
    range_error_percent: FloatArray
    truth_range: FloatArray
    frame: np.ndarray
    object_id: np.ndarray
    track_id: np.ndarray

    def to_json(self) -> dict[str, Any]:
        """Summary (no per-pair arrays)."""
        return {
            "columns": list(self.columns),
            "pairs": self.pairs,
            "pairs_without_position": self.missing,
            "rmse_position_m": _num(self.rmse_position_m),
            "rmse_range_percent": _num(self.rmse_range_percent),
            "mean_range_error_percent": _num(self.mean_range_error_percent),
            "range_bins": [b.to_json() for b in self.bins if b.pairs],
        }


@dataclass(frozen=True)
class ObjectCoverage:
    """How one truth object was tracked.

    Attributes:
        object_id: the truth id (an MMSI for AIS footage).
        frames: frames the object is in the (scored) truth.
        matched: frames in which a track was matched to it.
        track_ids: the matched track ids in order of first match (one id from entry to
            exit: a single entry and ``matched == frames``).
    """

    object_id: int
    frames: int
    matched: int
    track_ids: tuple[int, ...]

    def to_json(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        return {
            "object_id": self.object_id,
            "frames": self.frames,
            "matched": self.matched,
            "track_ids": list(self.track_ids),
        }


@dataclass(frozen=True, eq=False)
class TrackErrors:
    """Scores of a tracking run against the truth (module docstring).

    Attributes:
        rmse_position_m, rmse_range_percent: of the first estimator of ``positions`` [m,
            %] (NaN when it has no position).
        cle_px: mean centre location error of the matched boxes [px].
        id_switches, mota, motp, idf1, idp, idr, hota: TrackEval's CLEAR, Identity and
            HOTA scores (MOTP: mean IoU, or mean centre similarity with ``"centre"``).
        tp, fp, fn: matched, false and missed object-frames; mostly_tracked,
            fragmentations: CLEAR's MT and Frag.
        frames: frames scored; truth_rows, track_rows: rows scored; truth_objects:
            distinct truth ids; track_ids: distinct track ids.
        pairs: matched (truth, track) pairs (= tp).
        positions: per estimator, :class:`PositionErrors` (insertion order: the
            ``positions`` argument, then the ``estimates`` file's estimators).
        objects: per truth object, :class:`ObjectCoverage`.
        match, threshold, gate_px: the matching used.
        ignored_truth_rows, ignored_track_rows: rows removed as "don't care"
            (``min_truth_height``).
        camera_position: the camera foot point c (north, east) [m] used for ranges.
        tracks_file, truth_file, estimates_file: the inputs.
    """

    rmse_position_m: float
    rmse_range_percent: float
    cle_px: float
    id_switches: int
    mota: float
    idf1: float
    motp: float
    idp: float
    idr: float
    hota: float
    tp: int
    fp: int
    fn: int
    mostly_tracked: int
    fragmentations: int
    frames: int
    truth_rows: int
    track_rows: int
    truth_objects: int
    track_ids: int
    pairs: int
    positions: Mapping[str, PositionErrors]
    objects: tuple[ObjectCoverage, ...]
    match: str
    threshold: float
    gate_px: float | None
    ignored_truth_rows: int
    ignored_track_rows: int
    camera_position: tuple[float, float]
    tracks_file: str
    truth_file: str
    estimates_file: str | None = None
    extra: Mapping[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """The ``errors`` object (INTERFACES.md) and its details; NaN becomes None."""
        first = next(iter(self.positions.values()), None)
        return {
            "rmse_position_m": _num(self.rmse_position_m),
            "rmse_range_percent": _num(self.rmse_range_percent),
            "cle_px": _num(self.cle_px),
            "id_switches": self.id_switches,
            "mota": _num(self.mota),
            "idf1": _num(self.idf1),
            "motp": _num(self.motp),
            "idp": _num(self.idp),
            "idr": _num(self.idr),
            "hota": _num(self.hota),
            "tp": self.tp,
            "fp": self.fp,
            "fn": self.fn,
            "mostly_tracked": self.mostly_tracked,
            "fragmentations": self.fragmentations,
            "frames_scored": self.frames,
            "truth_rows": self.truth_rows,
            "track_rows": self.track_rows,
            "truth_objects": self.truth_objects,
            "track_ids": self.track_ids,
            "matched_pairs": self.pairs,
            "match": {
                "similarity": self.match,
                "threshold": self.threshold,
                **({"gate_px": self.gate_px} if self.gate_px is not None else {}),
            },
            "ignored": {
                "truth_rows": self.ignored_truth_rows,
                "track_rows": self.ignored_track_rows,
            },
            "camera_position_m": {
                "north": self.camera_position[0],
                "east": self.camera_position[1],
            },
            "range_bins": [] if first is None else [b.to_json() for b in first.bins if b.pairs],
            "estimators": {name: pe.to_json() for name, pe in self.positions.items()},
            "objects": [o.to_json() for o in self.objects],
            "files": {
                "tracks": self.tracks_file,
                "truth": self.truth_file,
                **({"estimates": self.estimates_file} if self.estimates_file else {}),
            },
        }


def _num(x: float) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


# ----------------------------------------------------------------------------- reading
@dataclass
class _Table:
    path: str
    columns: dict[str, list[str]]
    rows: int


def _read(label: str, path: _PathLike) -> _Table:
    """A CSV file as columns of strings (the header's names, stripped)."""
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"{label} {p}: file not found")
    try:
        with p.open(newline="", encoding="utf-8") as fh:
            reader = csv.reader(fh)
            header = next(reader, None)
            if header is None:
                raise ValueError(f"{label} {p}: empty file (expected a CSV header)")
            names = [h.strip() for h in header]
            cols: dict[str, list[str]] = {n: [] for n in names}
            n_rows = 0
            for line, row in enumerate(reader, start=2):
                if not row or all(not c.strip() for c in row):
                    continue
                if len(row) != len(names):
                    raise ValueError(
                        f"{label} {p}, line {line}: {len(row)} cells for {len(names)} columns"
                    )
                for n, c in zip(names, row, strict=True):
                    cols[n].append(c)
                n_rows += 1
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise ValueError(f"{label} {p}: not a readable CSV file ({exc})") from None
    return _Table(str(p), cols, n_rows)


def _require(label: str, table: _Table, names: Sequence[str]) -> None:
    missing = [n for n in names if n not in table.columns]
    if missing:
        raise ValueError(
            f"{label} {table.path}: missing column(s) {', '.join(missing)} "
            f"(has: {', '.join(table.columns) or 'none'})"
        )


def _floats(label: str, table: _Table, name: str, *, allow_empty: bool = True) -> FloatArray:
    out = np.empty(table.rows)
    for i, cell in enumerate(table.columns[name]):
        s = cell.strip()
        if not s:
            if not allow_empty:
                raise ValueError(f"{label} {table.path}, line {i + 2}: empty '{name}'")
            out[i] = math.nan
            continue
        try:
            out[i] = float(s)
        except ValueError:
            raise ValueError(
                f"{label} {table.path}, line {i + 2}: '{name}' is not a number: {s!r}"
            ) from None
    return out


def _ints(label: str, table: _Table, name: str) -> np.ndarray:
    v = _floats(label, table, name, allow_empty=False)
    if not np.all(np.isfinite(v)) or np.any(v != np.round(v)):
        raise ValueError(f"{label} {table.path}: column '{name}' must hold integers")
    return v.astype(np.int64)


def _boxes(label: str, table: _Table, id_col: str) -> tuple[np.ndarray, np.ndarray, FloatArray]:
    _require(label, table, ("frame", id_col, "x", "y", "w", "h"))
    frame = _ints(label, table, "frame")
    ids = _ints(label, table, id_col)
    box = np.stack([_floats(label, table, c) for c in ("x", "y", "w", "h")], -1)
    if np.unique(np.stack([frame, ids], -1), axis=0).shape[0] != frame.size:
        raise ValueError(
            f"{label} {table.path}: a {id_col} appears more than once in a frame (one row "
            "per object per frame expected; score a long-form table with estimates=)"
        )
    return frame, ids, box.reshape(-1, 4)


def _camera_position(camera: Any, truth_path: Path) -> tuple[float, float]:
    from seawatch.camera import PinholeCamera

    if camera is None:
        beside = truth_path.parent / "camera.yaml"
        if not beside.is_file():
            return (0.0, 0.0)
        camera = beside
    if isinstance(camera, PinholeCamera):
        return camera.position
    from seawatch.io.camera_file import load_camera

    try:
        return load_camera(camera).position
    except (OSError, ValueError) as exc:
        raise ValueError(f"camera {camera}: {exc}") from None


# ----------------------------------------------------------------------------- matching
def _similarity(g: FloatArray, t: FloatArray, match: Match, gate: float) -> FloatArray:
    if match == "iou":
        return box_iou(g, t)
    cg = g[:, :2] + 0.5 * g[:, 2:]
    ct = t[:, :2] + 0.5 * t[:, 2:]
    d = np.linalg.norm(cg[:, None, :] - ct[None, :, :], axis=-1)
    return np.maximum(0.0, 1.0 - d / (2.0 * gate))


def match_boxes(
    truth_frames: np.ndarray,
    truth_ids: np.ndarray,
    truth_boxes: FloatArray,
    track_frames: np.ndarray,
    track_ids: np.ndarray,
    track_boxes: FloatArray,
    *,
    match: Match = "iou",
    threshold: float = 0.3,
    gate_px: float = 20.0,
    frames: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """CLEAR-MOT's per-frame assignment of track rows to truth rows (module docstring).

    Args:
        truth_frames, truth_ids, truth_boxes: truth rows (N,), (N,), (N, 4) ``x, y, w, h``.
        track_frames, track_ids, track_boxes: track rows (M,), (M,), (M, 4).
        match: ``"iou"`` or ``"centre"``; threshold: least IoU (``"iou"``); gate_px:
            largest centre distance [px] (``"centre"``, similarity threshold 0.5).
        frames: the frames to match (default: all frames of either input).

    Returns:
        (truth row indices, track row indices) of the matched pairs, frame by frame.
    """
    thr = 0.5 if match == "centre" else threshold
    steps = np.union1d(truth_frames, track_frames) if frames is None else np.unique(frames)
    g_order = np.argsort(truth_frames, kind="stable")
    t_order = np.argsort(track_frames, kind="stable")
    g_lo = np.searchsorted(truth_frames[g_order], steps, "left")
    g_hi = np.searchsorted(truth_frames[g_order], steps, "right")
    t_lo = np.searchsorted(track_frames[t_order], steps, "left")
    t_hi = np.searchsorted(track_frames[t_order], steps, "right")
    eps = np.finfo(float).eps
    prev: dict[int, int] = {}  # truth id -> track id matched in the previous step
    out_g: list[int] = []
    out_t: list[int] = []
    for k in range(steps.size):
        gi = g_order[g_lo[k] : g_hi[k]]
        ti = t_order[t_lo[k] : t_hi[k]]
        now: dict[int, int] = {}
        if gi.size and ti.size:
            sim = _similarity(truth_boxes[gi], track_boxes[ti], match, gate_px)
            sim = np.nan_to_num(sim, nan=0.0)
            bonus = np.array(
                [[prev.get(int(g), None) == int(t) for t in track_ids[ti]] for g in truth_ids[gi]]
            )
            score = 1000.0 * bonus + sim
            score[sim < thr - eps] = 0.0
            rows, cols = linear_sum_assignment(-score)
            ok = score[rows, cols] > eps
            for r, c in zip(rows[ok], cols[ok], strict=True):
                out_g.append(int(gi[r]))
                out_t.append(int(ti[c]))
                now[int(truth_ids[gi[r]])] = int(track_ids[ti[c]])
        prev = now
    return np.asarray(out_g, np.int64), np.asarray(out_t, np.int64)


# ----------------------------------------------------------------------------- scoring
def _position_errors(
    name: str,
    columns: tuple[str, str],
    est: FloatArray,
    truth: FloatArray,
    origin: FloatArray,
    bins: Sequence[float],
    where: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> PositionErrors:
    """Errors of estimates ``est`` (P, 2) (east, north) against ``truth`` (P, 2); ranges
    from the camera foot point ``origin`` (P, 2) (east, north) of each pair [m]. A pair
    without an estimate or a truth position is left out (``missing``)."""
    ok = np.all(np.isfinite(est), axis=1) & np.all(np.isfinite(truth), axis=1)
    e, t = est[ok], truth[ok]
    c = origin[ok]
    err = np.hypot(*(e - t).T)
    r = np.hypot(*(t - c).T)
    r_hat = np.hypot(*(e - c).T)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(r > 0.0, (r_hat - r) / r, np.nan) * 100.0
    fin = np.isfinite(rel)

    def rms(x: FloatArray) -> float:
        return float(np.sqrt(np.mean(x**2))) if x.size else math.nan

    out_bins = []
    for lo, hi in itertools.pairwise(bins):
        m = (r >= lo) & (r < hi)
        mf = m & fin
        out_bins.append(
            RangeBin(
                lo=float(lo),
                hi=float(hi),
                pairs=int(m.sum()),
                rmse_position_m=rms(err[m]),
                rmse_range_percent=rms(rel[mf]),
                mean_range_error_percent=float(np.mean(rel[mf])) if mf.any() else math.nan,
            )
        )
    return PositionErrors(
        name=name,
        columns=columns,
        pairs=int(ok.sum()),
        missing=int((~ok).sum()),
        rmse_position_m=rms(err),
        rmse_range_percent=rms(rel[fin]),
        mean_range_error_percent=float(np.mean(rel[fin])) if fin.any() else math.nan,
        bins=tuple(out_bins),
        position_error=err,
        range_error_percent=rel,
        truth_range=r,
        frame=where[0][ok],
        object_id=where[1][ok],
        track_id=where[2][ok],
    )


def score_tracks(
    tracks_csv: _PathLike,
    truth_csv: _PathLike,
    *,
    camera: Any = None,
    positions: Mapping[str, tuple[str, str]] | None = None,
    estimates: _PathLike | None = None,
    estimate_columns: tuple[str, str] = ("east_m", "north_m"),
    match: Match = "iou",
    threshold: float = 0.3,
    gate_px: float = 20.0,
    min_truth_height: float = 0.0,
    frames: Sequence[int] | None = None,
    range_bins: Sequence[float] = RANGE_BINS,
) -> TrackErrors:
    """Score a track table against ground truth (module docstring).

    Args:
        tracks_csv: ``tracks.csv`` (columns ``frame``, ``track_id``, ``x``, ``y``, ``w``,
            ``h`` and the position columns of ``positions``).
        truth_csv: ``truth.csv`` of ``seawatch synth`` (``frame``, ``object_id``, ``x``,
            ``y``, ``w``, ``h``, ``east_m``, ``north_m``); without ``east_m`` and
            ``north_m`` (boxes annotated on a real clip) the pixel scores alone, the
            position errors NaN.
        camera: a :class:`~seawatch.camera.PinholeCamera` or camera file giving the foot
            point of the ranges (its ``position`` [m]); None: ``camera.yaml`` beside the
            truth if present, else (0, 0).
        positions: estimator name → (east column, north column) of ``tracks_csv``
            [m]; default ``{"tracks": ("east_m", "north_m")}``. The first gives the
            headline ``rmse_position_m``/``rmse_range_percent``.
        estimates: optional long-form table (``frame``, ``track_id``, ``estimator`` and
            ``estimate_columns``) scored per estimator over the box-matched pairs.
        estimate_columns: (east, north) column names of ``estimates``.
        match: ``"iou"`` (default) or ``"centre"``.
        threshold: least IoU of a match (``"iou"``), in [0, 1].
        gate_px: largest centre distance of a match [px] (``"centre"``).
        min_truth_height: truth boxes lower than this [px] are "don't care".
        frames: frames to score (default: every frame of either table).
        range_bins: increasing bin edges of the truth range [m].

    Returns:
        TrackErrors.

    Raises:
        ValueError: a missing, unreadable or malformed file (named), an unknown column,
            a truth without rows, or a bad argument.
    """
    if match not in ("iou", "centre"):
        raise ValueError(f"match: expected 'iou' or 'centre', got {match!r}")
    thr = in_range("threshold", threshold, 0.0, 1.0)
    gate = positive("gate_px", gate_px)
    min_h = positive("min_truth_height", min_truth_height, allow_zero=True)
    edges = np.asarray(range_bins, dtype=np.float64)
    if edges.ndim != 1 or edges.size < 2 or np.any(np.diff(edges) <= 0) or np.isnan(edges).any():
        raise ValueError(f"range_bins: expected increasing edges [m], got {list(range_bins)}")
    pos_cols = dict(positions) if positions is not None else {"tracks": ("east_m", "north_m")}
    for name, cols in pos_cols.items():
        if len(cols) != 2:
            raise ValueError(f"positions[{name!r}]: expected (east column, north column)")

    truth = _read("truth", truth_csv)
    trk = _read("tracks", tracks_csv)
    g_frame, g_id, g_box = _boxes("truth", truth, "object_id")
    t_frame, t_id, t_box = _boxes("tracks", trk, "track_id")
    if truth.rows == 0:
        raise ValueError(f"truth {truth.path}: no rows (no object in view): nothing to score")
    if "east_m" in truth.columns or "north_m" in truth.columns:
        _require("truth", truth, ("east_m", "north_m"))
        g_en = np.stack([_floats("truth", truth, "east_m"), _floats("truth", truth, "north_m")], -1)
    else:  # pixel truth (annotated boxes of a real clip): no position errors
        g_en = np.full((truth.rows, 2), np.nan)
    wide: dict[str, FloatArray] = {}
    for name, (ce, cn) in pos_cols.items():
        _require("tracks", trk, (ce, cn))
        wide[name] = np.stack([_floats("tracks", trk, ce), _floats("tracks", trk, cn)], -1)
    bad_box = ~np.all(np.isfinite(t_box), axis=1)
    if np.any(~np.all(np.isfinite(g_box), axis=1)):
        raise ValueError(f"truth {truth.path}: a box (x, y, w, h) is empty or not finite")
    centre = _camera_position(camera, Path(truth_csv))
    # ranges from the camera of each truth row: a moving platform's truth carries its
    # position (platform_north_m, platform_east_m); a fixed camera's is ``centre``
    g_origin = np.tile([centre[1], centre[0]], (truth.rows, 1))
    if "platform_east_m" in truth.columns and "platform_north_m" in truth.columns:
        pe = _floats("truth", truth, "platform_east_m")
        pn = _floats("truth", truth, "platform_north_m")
        known = np.isfinite(pe) & np.isfinite(pn)
        g_origin[known] = np.stack([pe[known], pn[known]], -1)
    steps = None if frames is None else np.unique(np.asarray(frames, dtype=np.int64))

    # rows in scope: chosen frames; track rows without a box cannot be matched (dropped)
    g_keep = np.ones(truth.rows, bool) if steps is None else np.isin(g_frame, steps)
    t_keep = ~bad_box & (np.ones(trk.rows, bool) if steps is None else np.isin(t_frame, steps))
    ignored_g = ignored_t = 0
    if min_h > 0.0:
        small = g_keep & (g_box[:, 3] < min_h)
        if small.any():
            gi, ti = _match(g_frame, g_id, g_box, t_frame, t_id, t_box, g_keep, t_keep,
                            match, thr, gate, steps)  # fmt: skip
            drop_t = ti[small[gi]]
            # also unmatched track rows lying on an ignored truth box
            sm = np.flatnonzero(small)
            matched = set(ti.tolist())
            for j in np.flatnonzero(t_keep):
                if int(j) in matched:
                    continue
                same = sm[g_frame[sm] == t_frame[j]]
                if same.size:
                    s = _similarity(g_box[same], t_box[j : j + 1], match, gate)
                    if np.any(s >= (0.5 if match == "centre" else thr)):
                        drop_t = np.append(drop_t, j)
            ignored_g = int(small.sum())
            ignored_t = int(np.unique(drop_t).size)
            g_keep &= ~small
            t_keep[drop_t] = False
    gi, ti = _match(g_frame, g_id, g_box, t_frame, t_id, t_box, g_keep, t_keep,
                    match, thr, gate, steps)  # fmt: skip

    # TrackEval on the scored rows
    g_rows = np.column_stack([g_frame, g_id, g_box])[g_keep]
    t_rows = np.column_stack([t_frame, t_id, t_box])[t_keep]
    if match == "iou":
        mm = mot_metrics(g_rows, t_rows, "iou", thr, frames=steps)
    else:
        gc = np.column_stack([g_rows[:, :2], g_rows[:, 2:4] + 0.5 * g_rows[:, 4:6]])
        tc = np.column_stack([t_rows[:, :2], t_rows[:, 2:4] + 0.5 * t_rows[:, 4:6]])
        mm = mot_metrics(gc, tc, "distance", 0.5, max_distance=2.0 * gate, frames=steps)
    clear, ident = mm.clear, mm.identity

    cg = g_box[gi, :2] + 0.5 * g_box[gi, 2:]
    ct = t_box[ti, :2] + 0.5 * t_box[ti, 2:]
    cle = float(np.mean(np.hypot(*(cg - ct).T))) if gi.size else math.nan
    where = (g_frame[gi], g_id[gi], t_id[ti])
    results: dict[str, PositionErrors] = {}
    for name, est in wide.items():
        results[name] = _position_errors(
            name, pos_cols[name], est[ti], g_en[gi], g_origin[gi], edges, where
        )
    est_file = None
    if estimates is not None:
        est_file = str(estimates)
        results.update(
            _long_form(estimates, estimate_columns, where, g_en[gi], g_origin[gi], edges, results)
        )
    first = next(iter(results.values()))

    objects = []
    for oid in np.unique(g_id[g_keep]):
        n_frames = int(np.sum(g_keep & (g_id == oid)))
        mine = g_id[gi] == oid
        order = np.argsort(g_frame[gi][mine], kind="stable")
        ids_seq = t_id[ti][mine][order]
        seen: list[int] = []
        for v in ids_seq.tolist():
            if v not in seen:
                seen.append(v)
        objects.append(ObjectCoverage(int(oid), n_frames, int(mine.sum()), tuple(seen)))
    n_frames_scored = (
        int(np.union1d(g_frame[g_keep], t_frame[t_keep]).size) if steps is None else steps.size
    )
    return TrackErrors(
        rmse_position_m=first.rmse_position_m,
        rmse_range_percent=first.rmse_range_percent,
        cle_px=cle,
        id_switches=clear.id_switches,
        mota=clear.mota,
        idf1=ident.idf1,
        motp=clear.motp,
        idp=ident.idp,
        idr=ident.idr,
        hota=mm.hota.hota,
        tp=clear.tp,
        fp=clear.fp,
        fn=clear.fn,
        mostly_tracked=clear.mostly_tracked,
        fragmentations=clear.fragmentations,
        frames=n_frames_scored,
        truth_rows=int(g_keep.sum()),
        track_rows=int(t_keep.sum()),
        truth_objects=int(np.unique(g_id[g_keep]).size),
        track_ids=int(np.unique(t_id[t_keep]).size),
        pairs=int(gi.size),
        positions=results,
        objects=tuple(objects),
        match=match,
        threshold=0.5 if match == "centre" else thr,
        gate_px=gate if match == "centre" else None,
        ignored_truth_rows=ignored_g,
        ignored_track_rows=ignored_t,
        camera_position=(float(centre[0]), float(centre[1])),
        tracks_file=trk.path,
        truth_file=truth.path,
        estimates_file=est_file,
    )


def _match(
    g_frame: np.ndarray,
    g_id: np.ndarray,
    g_box: FloatArray,
    t_frame: np.ndarray,
    t_id: np.ndarray,
    t_box: FloatArray,
    g_keep: np.ndarray,
    t_keep: np.ndarray,
    match: Match,
    thr: float,
    gate: float,
    steps: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`match_boxes` on the kept rows; indices into the full tables."""
    gk, tk = np.flatnonzero(g_keep), np.flatnonzero(t_keep)
    gi, ti = match_boxes(
        g_frame[gk], g_id[gk], g_box[gk], t_frame[tk], t_id[tk], t_box[tk],
        match=match, threshold=thr, gate_px=gate, frames=steps,
    )  # fmt: skip
    return gk[gi], tk[ti]


def _long_form(
    path: _PathLike,
    columns: tuple[str, str],
    where: tuple[np.ndarray, np.ndarray, np.ndarray],
    truth_en: FloatArray,
    origin: FloatArray,
    edges: FloatArray,
    taken: Mapping[str, PositionErrors],
) -> dict[str, PositionErrors]:
    """Per-estimator errors of a long-form estimates table over the matched pairs."""
    table = _read("estimates", path)
    ce, cn = columns
    _require("estimates", table, ("frame", "track_id", "estimator", ce, cn))
    frame = _ints("estimates", table, "frame")
    tid = _ints("estimates", table, "track_id")
    east = _floats("estimates", table, ce)
    north = _floats("estimates", table, cn)
    names = [s.strip() for s in table.columns["estimator"]]
    pair_index = {
        (int(f), int(t)): k for k, (f, t) in enumerate(zip(where[0], where[2], strict=True))
    }
    out: dict[str, PositionErrors] = {}
    for name in dict.fromkeys(names):  # file order, unique
        rows = [i for i, n in enumerate(names) if n == name]
        est = np.full((len(pair_index), 2), np.nan)
        seen: set[tuple[int, int]] = set()
        for i in rows:
            key = (int(frame[i]), int(tid[i]))
            if key in seen:
                raise ValueError(
                    f"estimates {table.path}, line {i + 2}: estimator {name!r} has track "
                    f"{key[1]} twice in frame {key[0]}"
                )
            seen.add(key)
            k = pair_index.get(key)
            if k is not None:
                est[k] = (east[i], north[i])
        label = name if name not in taken else f"{name} (estimates)"
        out[label] = _position_errors(label, columns, est, truth_en, origin, edges, where)
    return out
