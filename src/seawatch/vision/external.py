"""Ship detectors from elsewhere: a user's own function or an ONNX model.

Issue 6, "Ship detection": the pluggable detector interface beside the classical one of
:mod:`seawatch.vision.detect`. Both follow its :class:`~seawatch.vision.detect.Detector`
protocol ``detector(image, *, sea_mask=None, horizon=None)`` and return
:class:`~seawatch.vision.detect.Detections`:

* :class:`CallableDetector` — any user function that returns boxes;
* :class:`OnnxDetector` — a YOLO-style ONNX model through onnxruntime (optional extra),
  its raw output decoded by :func:`decode_yolo`;
* :class:`MaskedDetector` — any detector limited to a user's search region (a mask
  image: not the own bow, a pier or the camera's text overlay);
* :func:`make_detector` — the detector of the command line's detector options (an ONNX
  model or the classical detector, optionally masked), for ``seawatch detect``,
  ``track`` and ``batch``.

Their boxes get the water-line point of :func:`seawatch.vision.detect.waterline_points`
(the hull/sea edge inside the box) and are kept only on the sea, as the classical
detector's are. Pixels and boxes as in :mod:`seawatch.vision.detect`.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Literal

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from seawatch._validation import FloatArray, in_range, int_pair, same_aspect
from seawatch.vision.detect import POLARITIES, Detections, _horizon_ends, _in_sea, _sea_mask
from seawatch.vision.planes import _gray
from seawatch.vision.waterline import waterline_points

__all__ = ["CallableDetector", "MaskedDetector", "OnnxDetector", "decode_yolo", "make_detector"]


def _in_sea_boxes(
    det: Detections, shape: tuple[int, int], sea_mask: ArrayLike | None, horizon: Any, tol: float
) -> Detections:
    """Keep the boxes whose water-line point lies on the sea (mask or horizon line)."""
    mask = _sea_mask(sea_mask, shape)
    ends = _horizon_ends(horizon, shape[1])
    if (mask is None and ends is None) or len(det) == 0:
        return det
    keep = [
        i
        for i, (u, v) in enumerate(zip(det.u_wl, det.v_wl, strict=True))
        if _in_sea(float(u), float(v), mask, ends, shape, tol * shape[0])
    ]
    return Detections(det.boxes[keep])


# --------------------------------------------------------------------------------------
# user callables
# --------------------------------------------------------------------------------------


def _as_detections(result: Any, what: str) -> tuple[Detections, bool]:
    """A detector's output as Detections; the flag says whether it had water-line points.

    Accepted: :class:`Detections`; an (N, 4) ``x, y, w, h``, (N, 5) ``… score`` or
    (N, 7) ``… score, u_wl, v_wl`` array-like; a list of dicts with those keys.
    """
    if isinstance(result, Detections):
        return result, True
    if result is None:
        return Detections.empty(), True
    if isinstance(result, list | tuple) and result and isinstance(result[0], dict):
        rows = []
        has_wl = all("u_wl" in r and "v_wl" in r for r in result)
        for r in result:
            try:
                x, y, w, h = (float(r[k]) for k in ("x", "y", "w", "h"))
            except (KeyError, TypeError, ValueError):
                raise ValueError(
                    f"{what}: each box dict needs numbers x, y, w, h (got keys {sorted(r)})"
                ) from None
            score = float(r.get("score", 1.0))
            u = float(r["u_wl"]) if has_wl else x + w / 2
            v = float(r["v_wl"]) if has_wl else y + h
            rows.append((x, y, w, h, score, u, v))
        arr = np.array(rows, dtype=np.float64)
    else:
        try:
            arr = np.asarray(result, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(
                f"{what}: expected Detections, an (N, 4|5|7) array or a list of box dicts, "
                f"got {type(result).__name__}"
            ) from None
        if arr.size == 0:
            return Detections.empty(), True
        if arr.ndim != 2 or arr.shape[1] not in (4, 5, 7):
            raise ValueError(
                f"{what}: expected an (N, 4|5|7) array (x, y, w, h[, score[, u_wl, v_wl]]), "
                f"got shape {arr.shape}"
            )
        has_wl = arr.shape[1] == 7
        if arr.shape[1] == 4:
            arr = np.column_stack([arr, np.ones(len(arr))])
        if arr.shape[1] == 5:
            arr = np.column_stack([arr, arr[:, 0] + arr[:, 2] / 2, arr[:, 1] + arr[:, 3]])
    try:
        det = Detections(arr[np.argsort(-arr[:, 4], kind="stable")])
    except ValueError as exc:
        raise ValueError(f"{what}: {exc}") from None
    return det, has_wl


class CallableDetector:
    """A user function as a :class:`Detector` (Issue 6: "their own callable that returns
    boxes").

    ``fn(image)`` — or ``fn(image, sea_mask=..., horizon=...)`` when it accepts those
    keywords — returns :class:`Detections`, an (N, 4) ``x, y, w, h`` [px], (N, 5)
    ``…, score`` or (N, 7) ``…, score, u_wl, v_wl`` array-like, or a list of dicts with
    those keys. Missing scores are 1; missing water-line points are refined on the
    pixels with :func:`waterline_points` (``refine_waterline=True``) or set to the boxes'
    bottom centres. With a sea mask or horizon, boxes whose water-line point is not on
    the sea are dropped (``filter_sea=True``; ``horizon_tolerance`` × H of slack).
    """

    def __init__(
        self,
        fn: Callable[..., Any],
        *,
        refine_waterline: bool = True,
        filter_sea: bool = True,
        horizon_tolerance: float = 0.005,
    ) -> None:
        if not callable(fn):
            raise ValueError(f"fn: expected a callable, got {type(fn).__name__}")
        self.fn = fn
        self.refine_waterline = bool(refine_waterline)
        self.filter_sea = bool(filter_sea)
        self.horizon_tolerance = in_range("horizon_tolerance", horizon_tolerance, 0.0, 1.0)
        try:
            params = inspect.signature(fn).parameters
            self._kw = {"sea_mask", "horizon"} <= set(params) or any(
                p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values()
            )
        except (TypeError, ValueError):  # builtins without a signature
            self._kw = False

    def __call__(
        self, image: ArrayLike, *, sea_mask: ArrayLike | None = None, horizon: Any = None
    ) -> Detections:
        """Run the function on one frame and normalise its boxes (class docstring)."""
        g, _, _ = _gray(image)  # validates the image
        if self._kw:
            result = self.fn(image, sea_mask=sea_mask, horizon=horizon)
        else:
            result = self.fn(image)
        det, has_wl = _as_detections(result, "fn's result")
        if len(det) and not has_wl and self.refine_waterline:
            wl = waterline_points(g, det.boxes[:, :4])
            det = Detections(np.column_stack([det.boxes[:, :5], wl]))
        if self.filter_sea:
            det = _in_sea_boxes(det, g.shape, sea_mask, horizon, self.horizon_tolerance)
        return det


# --------------------------------------------------------------------------------------
# ONNX models (YOLO family)
# --------------------------------------------------------------------------------------

YoloLayout = Literal["auto", "yolov8", "yolov5", "end2end"]


def _nms(boxes: NDArray, scores: NDArray, iou: float) -> NDArray[np.intp]:
    """Greedy non-maximum suppression of ``(N, 4)`` x0, y0, x1, y1 boxes; kept indices,
    best first."""
    order = np.argsort(-scores, kind="stable")
    area = np.maximum(boxes[:, 2] - boxes[:, 0], 0) * np.maximum(boxes[:, 3] - boxes[:, 1], 0)
    keep: list[int] = []
    while order.size:
        i = int(order[0])
        keep.append(i)
        rest = order[1:]
        xx0 = np.maximum(boxes[i, 0], boxes[rest, 0])
        yy0 = np.maximum(boxes[i, 1], boxes[rest, 1])
        xx1 = np.minimum(boxes[i, 2], boxes[rest, 2])
        yy1 = np.minimum(boxes[i, 3], boxes[rest, 3])
        inter = np.maximum(xx1 - xx0, 0) * np.maximum(yy1 - yy0, 0)
        union = area[i] + area[rest] - inter
        ratio = np.where(union > 0, inter / np.where(union > 0, union, 1), 0.0)
        order = rest[ratio <= iou]
    return np.array(keep, dtype=np.intp)


def decode_yolo(
    output: ArrayLike,
    *,
    layout: YoloLayout = "auto",
    score_threshold: float = 0.25,
    iou_threshold: float = 0.45,
    classes: Sequence[int] | None = None,
) -> tuple[FloatArray, FloatArray, NDArray[np.intp]]:
    """Boxes from a YOLO-style output tensor (model-input pixels), after NMS.

    Layouts (batch of one; a leading batch axis of 1 is dropped):

    * ``"yolov8"`` (Ultralytics YOLOv8/v11 export): ``(4 + nc, A)`` — per anchor the box
      centre and size ``cx, cy, w, h`` [input px] then ``nc`` class scores in [0, 1];
      score = the best class score.
    * ``"yolov5"``: ``(A, 5 + nc)`` — ``cx, cy, w, h``, objectness, ``nc`` class
      probabilities; score = objectness × the best class probability.
    * ``"end2end"`` (models exported with NMS, e.g. YOLOv10): ``(N, 6)`` — ``x0, y0, x1,
      y1, score, class``; no NMS is applied.
    * ``"auto"``: ``(C, A)`` with ``C < A`` is yolov8, otherwise yolov5.

    Args:
        output: the model's first output.
        layout: one of the above.
        score_threshold: least score kept, in [0, 1].
        iou_threshold: boxes overlapping a better one by more than this IoU are dropped
            (class-agnostic: ships are one kind of object here).
        classes: class indices to keep (e.g. ``[8]`` for COCO "boat"); None keeps all.

    Returns:
        ``(boxes, scores, class_ids)``: (N, 4) ``x0, y0, x1, y1`` [input px], (N,), (N,).
    """
    out = np.asarray(output, dtype=np.float64)
    while out.ndim > 2 and out.shape[0] == 1:
        out = out[0]
    if out.ndim != 2:
        raise ValueError(f"output: expected a (C, A) or (A, C) YOLO tensor, got {out.shape}")
    if layout not in ("auto", "yolov8", "yolov5", "end2end"):
        raise ValueError(f"layout: expected auto, yolov8, yolov5 or end2end, got {layout!r}")
    score_threshold = in_range("score_threshold", score_threshold, 0.0, 1.0)
    iou_threshold = in_range("iou_threshold", iou_threshold, 0.0, 1.0)
    if layout == "auto":
        layout = "yolov8" if out.shape[0] < out.shape[1] else "yolov5"
    if layout == "end2end":
        if out.shape[1] != 6:
            raise ValueError(f"output: end2end layout needs (N, 6) rows, got {out.shape}")
        xyxy, scores, cls = out[:, :4], out[:, 4], out[:, 5].astype(np.intp)
    else:
        if layout == "yolov8":
            if out.shape[0] < 5:
                raise ValueError(f"output: yolov8 layout needs (4 + nc, A), got {out.shape}")
            t = out.T
            cls_scores = t[:, 4:]
            cls = np.argmax(cls_scores, axis=1)
            scores = cls_scores[np.arange(len(t)), cls]
        else:
            if out.shape[1] < 6:
                raise ValueError(f"output: yolov5 layout needs (A, 5 + nc), got {out.shape}")
            t = out
            cls = np.argmax(t[:, 5:], axis=1)
            scores = t[:, 4] * t[np.arange(len(t)), 5 + cls]
        cx, cy, w, h = t[:, 0], t[:, 1], t[:, 2], t[:, 3]
        xyxy = np.column_stack([cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2])
    keep = np.isfinite(scores) & (scores >= score_threshold) & np.all(np.isfinite(xyxy), axis=1)
    if classes is not None:
        keep &= np.isin(cls, np.asarray(list(classes), dtype=np.intp))
    xyxy, scores, cls = xyxy[keep], scores[keep], cls[keep]
    if layout != "end2end" and len(scores):
        k = _nms(xyxy, scores, iou_threshold)
        xyxy, scores, cls = xyxy[k], scores[k], cls[k]
    order = np.argsort(-scores, kind="stable")
    return xyxy[order], np.clip(scores[order], 0.0, 1.0), cls[order]


class OnnxDetector:
    """A YOLO-style ONNX model as a :class:`Detector`, run with onnxruntime (an optional
    dependency: ``pip install onnxruntime``).

    Expected model: one image input ``(1, 3, S_h, S_w)`` float32, RGB, values in [0, 1]
    (a fixed input size is read from the model; a dynamic one is ``input_size``), the
    frame letterboxed into it (aspect kept, grey 114 padding, centred); first output a
    YOLO tensor decoded by :func:`decode_yolo` (``layout``). Grey frames are repeated to
    three channels; 16-bit and float frames are stretched from their 0.5–99.5 %
    percentiles to [0, 1]. Boxes are mapped back to frame pixels, water-line points
    refined with :func:`waterline_points` (``refine_waterline``), and boxes off the sea
    dropped when a sea mask or horizon is given.

    Args:
        model_path: the ``.onnx`` file.
        input_size: ``(width, height)`` for a model with dynamic input dimensions.
        layout, score_threshold, iou_threshold, classes: see :func:`decode_yolo`.
        providers: onnxruntime execution providers (default: all available).

    Raises:
        FileNotFoundError: naming ``model_path`` when the file is missing.
        ImportError: when onnxruntime is not installed (with the install command).
    """

    def __init__(
        self,
        model_path: str | Path,
        *,
        input_size: tuple[int, int] = (640, 640),
        layout: YoloLayout = "auto",
        score_threshold: float = 0.25,
        iou_threshold: float = 0.45,
        classes: Sequence[int] | None = None,
        providers: Sequence[str] | None = None,
        refine_waterline: bool = True,
        filter_sea: bool = True,
        horizon_tolerance: float = 0.005,
    ) -> None:
        path = Path(model_path)
        if not path.is_file():
            raise FileNotFoundError(f"model_path: no such ONNX model file: {path}")
        if layout not in ("auto", "yolov8", "yolov5", "end2end"):
            raise ValueError(f"layout: expected auto, yolov8, yolov5 or end2end, got {layout!r}")
        iw, ih = int_pair("input_size", input_size, ("width", "height"), 8)
        self.score_threshold = in_range("score_threshold", score_threshold, 0.0, 1.0)
        self.iou_threshold = in_range("iou_threshold", iou_threshold, 0.0, 1.0)
        self.layout: YoloLayout = layout
        self.classes = None if classes is None else [int(c) for c in classes]
        self.refine_waterline = bool(refine_waterline)
        self.filter_sea = bool(filter_sea)
        self.horizon_tolerance = in_range("horizon_tolerance", horizon_tolerance, 0.0, 1.0)
        try:
            import onnxruntime as ort  # optional dependency, imported on use
        except ImportError:
            raise ImportError(
                "OnnxDetector needs onnxruntime, which is not installed: "
                "pip install onnxruntime (or onnxruntime-gpu)"
            ) from None
        self.model_path = path
        self.session = ort.InferenceSession(
            str(path), providers=list(providers) if providers else ort.get_available_providers()
        )
        inp = self.session.get_inputs()[0]
        self.input_name = inp.name
        shape = list(inp.shape)
        if len(shape) != 4 or (isinstance(shape[1], int) and shape[1] != 3):
            raise ValueError(
                f"model_path: expected an image input (1, 3, H, W), got {inp.name} {shape}"
            )
        h_m = shape[2] if isinstance(shape[2], int) else ih
        w_m = shape[3] if isinstance(shape[3], int) else iw
        self.input_size = (int(w_m), int(h_m))

    def _prepare(self, image: ArrayLike) -> tuple[NDArray, float, float, float]:
        arr = np.asarray(image)
        g, _, colour = _gray(arr)
        if colour is None:
            src = np.repeat(g[:, :, None], 3, axis=2)
        else:
            src = colour
        if src.dtype != np.uint8:
            lo, hi = np.percentile(src[::4, ::4], [0.5, 99.5])
            src = np.clip((src.astype(np.float32) - lo) / max(float(hi - lo), 1e-12), 0, 1)
            src = (src * 255).astype(np.uint8)
        rgb = cv2.cvtColor(np.ascontiguousarray(src), cv2.COLOR_BGR2RGB)
        H, W = rgb.shape[:2]
        tw, th = self.input_size
        r = min(tw / W, th / H)
        nw, nh = max(1, round(W * r)), max(1, round(H * r))
        px, py = (tw - nw) / 2, (th - nh) / 2
        canvas = np.full((th, tw, 3), 114, np.uint8)
        x0, y0 = round(px - 0.1), round(py - 0.1)
        canvas[y0 : y0 + nh, x0 : x0 + nw] = cv2.resize(
            rgb, (nw, nh), interpolation=cv2.INTER_LINEAR
        )
        blob = canvas.transpose(2, 0, 1)[None].astype(np.float32) / 255.0
        return blob, r, float(x0), float(y0)

    def __call__(
        self, image: ArrayLike, *, sea_mask: ArrayLike | None = None, horizon: Any = None
    ) -> Detections:
        """Run the model on one frame (class docstring)."""
        g, _, _ = _gray(image)
        blob, r, px, py = self._prepare(image)
        output = self.session.run(None, {self.input_name: blob})[0]
        xyxy, scores, _ = decode_yolo(
            output,
            layout=self.layout,
            score_threshold=self.score_threshold,
            iou_threshold=self.iou_threshold,
            classes=self.classes,
        )
        if len(scores) == 0:
            return Detections.empty()
        H, W = g.shape
        # input pixels (edges) → frame pixel coordinates (origin at the top-left centre)
        x0 = np.clip((xyxy[:, 0] - px) / r, 0, W) - 0.5
        y0 = np.clip((xyxy[:, 1] - py) / r, 0, H) - 0.5
        x1 = np.clip((xyxy[:, 2] - px) / r, 0, W) - 0.5
        y1 = np.clip((xyxy[:, 3] - py) / r, 0, H) - 0.5
        xywh = np.column_stack([x0, y0, x1 - x0, y1 - y0])
        ok = (xywh[:, 2] > 0) & (xywh[:, 3] > 0)
        xywh, scores = xywh[ok], scores[ok]
        wl = waterline_points(g, xywh) if self.refine_waterline else None
        det = Detections.from_boxes(xywh, scores, wl)
        if self.filter_sea:
            det = _in_sea_boxes(det, g.shape, sea_mask, horizon, self.horizon_tolerance)
        return det


# --------------------------------------------------------------------------------------
# a user's search region
# --------------------------------------------------------------------------------------


class MaskedDetector:
    """A detector whose boxes are kept only where a user's search region allows.

    ``region`` is an (H, W) array or an image file (PNG, …): non-zero where ships may
    be, zero where not — the own boat's bow or rail, a pier, the camera's on-screen text
    (a time stamp on the sea would be boxed in every frame). A box is kept when its
    water-line point lies in the region (the detectors' own sea test, on the user's
    mask). Frames of another size than the mask's but of its aspect ratio
    (:func:`~seawatch._validation.same_aspect`) use the mask scaled to them (nearest
    pixel); another aspect ratio is a ValueError naming ``--mask``. Forwards
    ``prepare``/``detect_prepared`` (the classical detector's split across threads,
    :meth:`seawatch.vision.tracker.VisualTracker.stream`) and ``reset``.
    """

    def __init__(self, detector: Any, region: ArrayLike | str | Path) -> None:
        if not callable(detector):
            raise ValueError(f"detector: expected a callable detector, got {detector!r}")
        if isinstance(region, str | Path):
            img = cv2.imread(str(region), cv2.IMREAD_GRAYSCALE)
            if img is None:
                raise ValueError(f"--mask {region}: not a readable image")
            region = img
        m = np.asarray(region)
        if m.ndim != 2 or min(m.shape) < 1:
            raise ValueError(f"--mask: expected an (H, W) image, got shape {m.shape}")
        keep = m != 0
        if not keep.any():
            raise ValueError("--mask: the region is empty (every pixel is zero)")
        self.detector = detector
        self.region = keep
        self._scaled: dict[tuple[int, int], NDArray[np.bool_]] = {}
        if callable(getattr(detector, "prepare", None)) and callable(
            getattr(detector, "detect_prepared", None)
        ):
            self.prepare = self._prepare
            self.detect_prepared = self._detect_prepared

    def reset(self) -> None:
        """Reset the wrapped detector (when it has a ``reset``)."""
        reset = getattr(self.detector, "reset", None)
        if callable(reset):
            reset()

    def region_for(self, shape: tuple[int, int]) -> NDArray[np.bool_]:
        """The region for frames of ``shape`` = (H, W) (the mask, or it scaled)."""
        if shape == self.region.shape:
            return self.region
        got = self._scaled.get(shape)
        if got is None:
            (mh, mw), (h, w) = self.region.shape, shape
            if not same_aspect((w, h), (mw, mh)):
                raise ValueError(
                    f"--mask: {mw}x{mh}, the frames are {w}x{h} (another aspect ratio)"
                )
            small = cv2.resize(self.region.astype(np.uint8), (w, h), cv2.INTER_NEAREST)
            got = self._scaled[shape] = small != 0
        return got

    def _keep(self, det: Any, shape: tuple[int, int]) -> Detections:
        det, _ = _as_detections(det, "detector's result")
        if len(det) == 0:
            return det
        return _in_sea_boxes(det, shape, self.region_for(shape), None, 0.0)

    def __call__(
        self, image: ArrayLike, *, sea_mask: ArrayLike | None = None, horizon: Any = None
    ) -> Detections:
        """Detect with the wrapped detector and keep the boxes in the region."""
        shape = np.shape(image)[:2]
        try:
            det = self.detector(image, sea_mask=sea_mask, horizon=horizon)
        except TypeError:
            det = self.detector(image)
        return self._keep(det, (int(shape[0]), int(shape[1])))

    def _prepare(self, image: ArrayLike, **kw: Any) -> tuple[Any, tuple[int, int]]:
        shape = np.shape(image)[:2]
        return self.detector.prepare(image, **kw), (int(shape[0]), int(shape[1]))

    def _detect_prepared(self, prepared: tuple[Any, tuple[int, int]]) -> Detections:
        inner, shape = prepared
        return self._keep(self.detector.detect_prepared(inner), shape)


# --------------------------------------------------------------------------------------
# the command line's detector options
# --------------------------------------------------------------------------------------


def make_detector(
    model: str | Path | None = None,
    *,
    threshold: float | None = None,
    polarity: str = "both",
    temporal: bool = False,
    mask: str | Path | None = None,
) -> Any:
    """The ship detector of the detector options of ``seawatch detect``/``track``/``batch``.

    Args:
        model: a YOLO-style ONNX model (:class:`OnnxDetector`); None: the classical
            detector (:class:`~seawatch.vision.detect.ClassicalShipDetector`).
        threshold: the model's score threshold in [0, 1] (default 0.25), or the classical
            detector's threshold in noise units (default 6; its hysteresis low threshold
            is min(3, threshold)).
        polarity: ships the classical detector looks for in luma: ``both``, ``dark``
            (looking into the sun, hulls are silhouettes and bright boxes are glitter) or
            ``bright``; a hull of another colour than the sea is found by its chroma
            either way. (On the MarDCT thermal frames ``bright`` finds the same boat as
            ``both`` with more false boxes, 25 against 13 in 88 frames: the arbitration
            between the polarities also removes clutter.)
        temporal: the classical detector's temporal clutter model.
        mask: an image file of the search region (:class:`MaskedDetector`), or None.

    Raises:
        ValueError: naming the option (``--model``, ``--threshold``, ``--polarity``,
            ``--mask``) for a missing model or mask file, a missing onnxruntime or a bad
            value.
    """
    from seawatch.vision.detect import ClassicalShipDetector

    if polarity not in POLARITIES:
        raise ValueError(f"--polarity: expected both, dark or bright, got {polarity!r}")
    if mask is not None:
        inner = make_detector(model, threshold=threshold, polarity=polarity, temporal=temporal)
        if not Path(mask).is_file():
            raise ValueError(f"--mask {mask}: no such image file")
        return MaskedDetector(inner, mask)
    if model is not None:
        path = Path(model)
        if not path.is_file():
            raise ValueError(f"--model {path}: no such ONNX model file")
        if threshold is not None and not 0.0 <= threshold <= 1.0:
            raise ValueError(f"--threshold: a model score in [0, 1], got {threshold}")
        try:
            return OnnxDetector(path, score_threshold=0.25 if threshold is None else threshold)
        except ImportError as exc:
            raise ValueError(f"--model {path}: {exc}") from None
    thr = 6.0 if threshold is None else float(threshold)
    if not thr > 0:
        raise ValueError(f"--threshold: expected a number of noise units > 0, got {thr}")
    return ClassicalShipDetector(
        threshold=thr,
        grow_threshold=min(3.0, thr),
        temporal=temporal,
        polarity=polarity,  # type: ignore[arg-type]
    )
