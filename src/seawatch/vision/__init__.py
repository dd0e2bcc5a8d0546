"""Image-space processing: pixels in, marks and boxes out.

* :mod:`seawatch.vision.marks` — point marks of small targets from one frame: adaptive
  thresholding (local mean + k·σ) and cell-averaging CFAR, connected components and an
  intensity-weighted centroid per mark (the input ``Z_k`` of the track-before-detect,
  ALGORITHMS.md §8). ``extract_marks(image)`` returns an (M, 4) array of
  (row, col, intensity, area).
* :mod:`seawatch.vision.horizon` — the sea horizon per frame (``detect_horizon``), its
  temporal smoothing (``HorizonTracker``) and the sea region below it (``sea_mask``).
"""

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
    "MARK_COLUMNS",
    "HorizonEstimate",
    "HorizonTracker",
    "adaptive_mask",
    "cfar_mask",
    "detect_horizon",
    "extract_marks",
    "grayscale",
    "marks_from_mask",
    "sea_mask",
]
