"""The frame a detector is given, as planes: validated, grey and colour (helpers shared by
:mod:`seawatch.vision.detect`, :mod:`seawatch.vision.waterline`,
:mod:`seawatch.vision.external`, :mod:`seawatch.vision.horizon` and
:mod:`seawatch.vision.marks`).

Colour frames are taken in OpenCV's BGR(A) order; grey frames may be 8-bit, 16-bit
(thermal) or float, kept in their own units.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray


def image_array(image: ArrayLike) -> NDArray:
    """``image`` as an array of a grey (H, W) or BGR(A) (H, W, 3|4) frame: a bool image
    becomes 0/1 uint8, a (H, W, 1) one (H, W); other values kept as they are.

    Raises ValueError naming ``image`` for a complex, object or other non-numeric dtype
    or any other shape (the checks every image entry point of :mod:`seawatch.vision`
    shares)."""
    arr = np.asarray(image)
    if arr.dtype == np.bool_:
        arr = arr.astype(np.uint8)
    if arr.dtype.kind not in "uif":
        raise ValueError(f"image: expected an integer or float image, got dtype {arr.dtype}")
    if arr.ndim == 3 and arr.shape[2] == 1:
        arr = arr[:, :, 0]
    if not (arr.ndim == 2 or (arr.ndim == 3 and arr.shape[2] in (3, 4))):
        raise ValueError(
            f"image: expected a (H, W) grey or (H, W, 3|4) BGR(A) image, got shape {arr.shape}"
        )
    return arr


def _image_planes(image: ArrayLike) -> tuple[NDArray | None, float, NDArray | None]:
    """The validated frame: its grey channel (uint8, uint16 or float32; None for a colour
    frame), its quantum [units] and the BGR colour frame (None for grey input).

    Raises ValueError naming ``image`` for a wrong shape or dtype, an empty or tiny frame,
    or NaN pixels.
    """
    arr = image_array(image)
    if arr.shape[0] < 8 or arr.shape[1] < 8:
        raise ValueError(f"image: expected at least 8×8 pixels, got shape {arr.shape[:2]}")
    quantum = 1.0
    if arr.dtype not in (np.uint8, np.uint16, np.float32):
        # integer grey levels keep a quantum of 1; colour is converted to float first
        quantum = 1.0 if arr.dtype.kind in "ui" and arr.ndim == 2 else 0.0
        arr = arr.astype(np.float32)
    elif arr.dtype == np.float32:
        quantum = 0.0
    arr = np.ascontiguousarray(arr)
    if arr.ndim == 3 and arr.shape[2] == 4:
        arr = cv2.cvtColor(arr, cv2.COLOR_BGRA2BGR)
    if arr.dtype == np.float32 and not math.isfinite(float(arr.sum(dtype=np.float64))):
        raise ValueError("image: contains NaN or inf pixels")
    if arr.ndim == 2:
        return arr, quantum, None
    return None, quantum, arr


def _gray(image: ArrayLike) -> tuple[NDArray, float, NDArray | None]:
    """The frame as one grey channel (uint8, uint16 or float32), its quantum [units] and
    the BGR colour frame (None for grey input).

    Colour is BGR(A) → luma (ITU-R BT.601 weights, ``cv2.cvtColor``). Raises ValueError
    naming ``image`` for a wrong shape or dtype, an empty or tiny frame, or NaN pixels.
    """
    grey, quantum, colour = _image_planes(image)
    if grey is None:
        assert colour is not None
        grey = cv2.cvtColor(colour, cv2.COLOR_BGR2GRAY)
    return grey, quantum, colour
