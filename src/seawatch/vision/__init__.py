"""Image-space processing: pixels in, marks and boxes out.

* :mod:`seawatch.vision.marks` — point marks of small targets from one frame: adaptive
  thresholding (local mean + k·σ) and cell-averaging CFAR, connected components and an
  intensity-weighted centroid per mark (the input ``Z_k`` of the track-before-detect,
  ALGORITHMS.md §8). ``extract_marks(image)`` returns an (M, 4) array of
  (row, col, intensity, area).
* :mod:`seawatch.vision.horizon` — the sea horizon per frame (``detect_horizon``), its
  temporal smoothing (``HorizonTracker``) and the sea region below it (``sea_mask``).
* :mod:`seawatch.vision.detect` — ship boxes with their water-line points: the classical
  weight-free ``ClassicalShipDetector``; :mod:`seawatch.vision.external` —
  ``OnnxDetector`` (optional onnxruntime) and ``CallableDetector`` for a user's own
  function.
"""

from seawatch.vision.detect import (
    DETECTION_COLUMNS,
    ClassicalShipDetector,
    Detections,
    Detector,
)
from seawatch.vision.external import CallableDetector, OnnxDetector
from seawatch.vision.horizon import HorizonEstimate, HorizonTracker, detect_horizon, sea_mask
from seawatch.vision.marks import (
    MARK_COLUMNS,
    adaptive_mask,
    cfar_mask,
    extract_marks,
    grayscale,
    marks_from_mask,
)

__all__ = [
    "DETECTION_COLUMNS",
    "MARK_COLUMNS",
    "CallableDetector",
    "ClassicalShipDetector",
    "Detections",
    "Detector",
    "HorizonEstimate",
    "HorizonTracker",
    "OnnxDetector",
    "adaptive_mask",
    "cfar_mask",
    "detect_horizon",
    "extract_marks",
    "grayscale",
    "marks_from_mask",
    "sea_mask",
]
