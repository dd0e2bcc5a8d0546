"""Ship detection: boxes of ships on the sea and the water-line pixel of each box.

Issue 6, "Ship detection" (stage one of seed 000; the detector that feeds the visual
tracker of seed 001, ALGORITHMS.md §1). Three detectors share one calling convention,
the :class:`Detector` protocol ``detector(image, *, sea_mask=None, horizon=None)``,
and one result, :class:`Detections`:

* :class:`ClassicalShipDetector` — no weights. Horizontal greatest-of CFAR contrast on a
  downscaled, horizon-levelled copy of the frame (a pixel must stand out from the sea on
  *both* sides, at the same rows; luma, and chroma for colour frames), normalised by a
  robust local noise level, at a few scales; hysteresis segmentation, a clutter-map
  threshold, merging of a ship's fragments, full-resolution re-segmentation inside each
  candidate box, size/aspect and sea-region filters, and an optional temporal
  noise/clutter model.
* :class:`OnnxDetector` — a YOLO-style ONNX model through onnxruntime (optional extra).
* :class:`CallableDetector` — any user function that returns boxes.

Pixels: ``x``/``u`` right, ``y``/``v`` down, origin at the centre of the top-left pixel
(INTERFACES.md), so the pixel in row r and column c covers ``[c - 0.5, c + 0.5] ×
[r - 0.5, r + 0.5]``. A box is its top-left corner ``(x, y)`` and size ``(w, h)`` [px];
the water-line point ``(u_wl, v_wl)`` [px] is where the hull meets the water: the bottom
edge of the lowest object pixel near the box's centre column.

Colour frames are taken in OpenCV's BGR(A) order; grey frames may be 8-bit, 16-bit
(thermal) or float. Intensities stay in the frame's own units (grey levels or counts).
"""

from __future__ import annotations

import functools
import inspect
import itertools
import math
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, Protocol, runtime_checkable

import cv2
import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray
from scipy.special import ndtri as _ndtri

from seawatch._validation import FloatArray, in_range, positive

__all__ = [
    "DETECTION_COLUMNS",
    "CallableDetector",
    "ClassicalShipDetector",
    "Detections",
    "Detector",
    "OnnxDetector",
    "decode_yolo",
    "sea_region",
    "waterline_points",
]

DETECTION_COLUMNS = ("x", "y", "w", "h", "score", "u_wl", "v_wl")
"""Columns of :attr:`Detections.boxes`: box top-left corner x, y [px], width w and height
h [px], score [0, 1], water-line point u_wl, v_wl [px]."""

Polarity = Literal["both", "bright", "dark"]


# --------------------------------------------------------------------------------------
# result
# --------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Detections:
    """Ship boxes of one frame (Issue 6, INTERFACES.md "Detection JSON").

    ``boxes`` is an ``(N, 7)`` float array, one row per ship with the columns of
    :data:`DETECTION_COLUMNS`: ``x, y`` the box's top-left corner [px], ``w, h`` its
    width and height [px], ``score`` in [0, 1], ``u_wl, v_wl`` the water-line point [px].
    Rows are sorted by decreasing score. The array is read-only.
    """

    boxes: FloatArray

    def __post_init__(self) -> None:
        arr = np.array(self.boxes, dtype=np.float64, copy=True)
        if arr.size == 0:
            arr = np.zeros((0, 7))
        if arr.ndim != 2 or arr.shape[1] != 7:
            raise ValueError(
                f"boxes: expected an (N, 7) array of {', '.join(DETECTION_COLUMNS)}, "
                f"got shape {arr.shape}"
            )
        if not np.all(np.isfinite(arr)):
            raise ValueError("boxes: contains NaN or inf")
        if np.any(arr[:, 2:4] < 0):
            raise ValueError("boxes: negative width or height")
        if np.any((arr[:, 4] < 0) | (arr[:, 4] > 1)):
            raise ValueError("boxes: score outside [0, 1]")
        arr.setflags(write=False)
        object.__setattr__(self, "boxes", arr)

    @classmethod
    def empty(cls) -> Detections:
        """No boxes."""
        return cls(np.zeros((0, 7)))

    @classmethod
    def from_boxes(
        cls,
        xywh: ArrayLike,
        score: ArrayLike | None = None,
        waterline: ArrayLike | None = None,
    ) -> Detections:
        """Detections from ``(N, 4)`` boxes ``x, y, w, h`` [px], optional ``(N,)`` scores
        (default 1) and optional ``(N, 2)`` water-line points (default: bottom centre
        ``(x + w/2, y + h)``)."""
        b = np.asarray(xywh, dtype=np.float64)
        if b.size == 0:
            return cls.empty()
        if b.ndim != 2 or b.shape[1] != 4:
            raise ValueError(f"xywh: expected an (N, 4) array of x, y, w, h, got {b.shape}")
        n = b.shape[0]
        s = np.ones(n) if score is None else np.asarray(score, dtype=np.float64).reshape(-1)
        if s.shape != (n,):
            raise ValueError(f"score: expected {n} scores, got shape {s.shape}")
        if waterline is None:
            wl = np.column_stack([b[:, 0] + b[:, 2] / 2, b[:, 1] + b[:, 3]])
        else:
            wl = np.asarray(waterline, dtype=np.float64)
            if wl.shape != (n, 2):
                raise ValueError(f"waterline: expected shape ({n}, 2), got {wl.shape}")
        arr = np.column_stack([b, s, wl])
        order = np.argsort(-arr[:, 4], kind="stable")
        return cls(arr[order])

    def __len__(self) -> int:
        return int(self.boxes.shape[0])

    def _col(self, i: int) -> FloatArray:
        return self.boxes[:, i]

    x = property(lambda self: self._col(0), doc="Left edge of each box [px].")
    y = property(lambda self: self._col(1), doc="Top edge of each box [px].")
    w = property(lambda self: self._col(2), doc="Box width [px].")
    h = property(lambda self: self._col(3), doc="Box height [px].")
    score = property(lambda self: self._col(4), doc="Detection score in [0, 1].")
    u_wl = property(lambda self: self._col(5), doc="Water-line point, column [px].")
    v_wl = property(lambda self: self._col(6), doc="Water-line point, row [px].")

    @property
    def centers(self) -> FloatArray:
        """``(N, 2)`` box centres ``(x + w/2, y + h/2)`` [px]."""
        return self.boxes[:, :2] + self.boxes[:, 2:4] / 2

    def records(self) -> list[dict[str, float]]:
        """One ``{"x", "y", "w", "h", "score", "u_wl", "v_wl"}`` dict per box (JSON form)."""
        return [dict(zip(DETECTION_COLUMNS, map(float, row), strict=True)) for row in self.boxes]


@runtime_checkable
class Detector(Protocol):
    """What every ship detector is: ``detector(image, *, sea_mask=None, horizon=None)``.

    ``image`` is an (H, W) grey or (H, W, 3|4) BGR(A) frame; ``sea_mask`` an optional
    (H, W) bool array (True = sea); ``horizon`` an optional line (an object with
    ``x0, y0, x1, y1`` [px] and optionally ``found``, such as
    ``seawatch.vision.horizon.HorizonEstimate``, or a 4-sequence). Returns
    :class:`Detections`.
    """

    def __call__(
        self, image: ArrayLike, *, sea_mask: ArrayLike | None = None, horizon: Any = None
    ) -> Detections: ...


# --------------------------------------------------------------------------------------
# input handling
# --------------------------------------------------------------------------------------


def _image_planes(image: ArrayLike) -> tuple[NDArray | None, float, NDArray | None]:
    """The validated frame: its grey channel (uint8, uint16 or float32; None for a colour
    frame), its quantum [units] and the BGR colour frame (None for grey input).

    Raises ValueError naming ``image`` for a wrong shape or dtype, an empty or tiny frame,
    or NaN pixels.
    """
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


def _horizon_ends(horizon: Any, width: int) -> tuple[float, float] | None:
    """Rows [px] of the horizon line at columns 0 and ``width - 1``, or None."""
    if horizon is None:
        return None
    if hasattr(horizon, "x0"):
        if not bool(getattr(horizon, "found", True)):
            return None
        pts = [getattr(horizon, k) for k in ("x0", "y0", "x1", "y1")]
    else:
        try:
            pts = list(horizon)
        except TypeError:
            raise ValueError(
                "horizon: expected an object with x0, y0, x1, y1 or a sequence "
                f"(x0, y0, x1, y1), got {type(horizon).__name__}"
            ) from None
    try:
        x0, y0, x1, y1 = (float(v) for v in pts)
    except (TypeError, ValueError):
        raise ValueError(f"horizon: expected four numbers x0, y0, x1, y1, got {pts!r}") from None
    if not all(math.isfinite(v) for v in (x0, y0, x1, y1)):
        return None  # a "not found" line written as NaN
    if x1 == x0:
        raise ValueError("horizon: x0 == x1, the line is vertical (not a horizon)")
    slope = (y1 - y0) / (x1 - x0)
    return y0 - slope * x0, y0 + slope * (width - 1 - x0)


def _sea_mask(sea_mask: ArrayLike | None, shape: tuple[int, int]) -> NDArray[np.bool_] | None:
    if sea_mask is None:
        return None
    m = np.asarray(sea_mask)
    if m.shape != shape:
        raise ValueError(f"sea_mask: expected shape {shape} (the image's), got {m.shape}")
    if m.dtype != np.bool_:
        if m.dtype.kind not in "uif":
            raise ValueError(f"sea_mask: expected a bool array, got dtype {m.dtype}")
        m = m != 0
    return m


def sea_region(shape: tuple[int, int], horizon: Any) -> NDArray[np.bool_]:
    """The (H, W) bool mask of the pixels on or below a horizon line (True = sea).

    A plain fallback of ``seawatch.vision.horizon.sea_mask``: pixel (r, c) is sea when
    ``r >= y(c)``, with ``y(c)`` the line through ``(x0, y0)`` and ``(x1, y1)`` [px]. A
    ``None`` or not-found horizon gives an all-True mask.
    """
    h, w = int(shape[0]), int(shape[1])
    ends = _horizon_ends(horizon, w)
    if ends is None:
        return np.ones((h, w), dtype=bool)
    yl = np.linspace(ends[0], ends[1], w)
    return np.arange(h)[:, None] >= yl[None, :]


# --------------------------------------------------------------------------------------
# classical detector: contrast, noise, segmentation
# --------------------------------------------------------------------------------------


@njit(cache=True, nogil=True, error_model="numpy")
def _contrast_kernel(  # pragma: no cover - compiled
    gs, b5, r0, r1, guard, flank, polarity, hi, lo, d, c, tex
):
    """Greatest-of CFAR contrast and least-of clutter level, rows ``r0 … r1 − 1``.

    ``gs`` is the smoothed plane and ``b5`` its 5 × 5 box mean; ``e² = (gs − b5)²`` is
    the squared local detail. Per pixel: ``L``/``R`` = mean of ``gs`` over the 3-row ×
    ``flank``-column training windows that end ``guard`` columns left / start ``guard``
    columns right of it (rows past the top and bottom repeat the edge rows; a side that
    leaves the image takes the other side's value); ``hi = max(L, R)``,
    ``lo = min(L, R)``, ``d = g − (L + R)/2``, contrast ``c = g − hi`` (polarity 1,
    bright), ``lo − g`` (2, dark) or the larger (0, both); ``tex = sqrt(min(E_L, E_R))``
    with ``E`` the mean of ``e²`` over the same windows.
    """
    H, W = gs.shape
    P = np.empty(W + 1)
    Q = np.empty(W + 1)
    v = np.empty(W)
    q = np.empty(W)
    L = np.empty(W)
    R = np.empty(W)
    EL = np.empty(W)
    ER = np.empty(W)
    inv_n = 1.0 / (3.0 * flank)
    jl = guard + flank  # first column with a left window
    jr = W - guard - flank - 1  # last column with a right window
    for r in range(r0, r1):
        g0 = gs[max(r - 1, 0)]
        g1 = gs[r]
        g2 = gs[min(r + 1, H - 1)]
        m0 = b5[max(r - 1, 0)]
        m1 = b5[r]
        m2 = b5[min(r + 1, H - 1)]
        for j in range(W):  # 3-row sums of gs and e²
            e0 = g0[j] - m0[j]
            e1 = g1[j] - m1[j]
            e2 = g2[j] - m2[j]
            v[j] = np.float64(g0[j]) + np.float64(g1[j]) + np.float64(g2[j])
            q[j] = np.float64(e0 * e0) + np.float64(e1 * e1) + np.float64(e2 * e2)
        acc = 0.0
        acc2 = 0.0
        P[0] = 0.0
        Q[0] = 0.0
        for j in range(W):
            acc += v[j]
            acc2 += q[j]
            P[j + 1] = acc
            Q[j + 1] = acc2
        n_in = min(jr, W - 1) + 1 - jl  # columns jl … with both windows inside
        if n_in > 0:
            # slices, so that the loop runs from 0 over contiguous memory (vectorised):
            # the left window of column jl + k is P[k + flank] − P[k], the right one
            # P[jl + guard + 1 + flank + k] − P[jl + guard + 1 + k]
            La, ELa, Ra, ERa = L[jl:], EL[jl:], R[jl:], ER[jl:]
            p0, p1 = P[:], P[flank:]
            q0, q1 = Q[:], Q[flank:]
            pr0, pr1 = P[jl + guard + 1 :], P[jl + guard + 1 + flank :]
            qr0, qr1 = Q[jl + guard + 1 :], Q[jl + guard + 1 + flank :]
            for k in range(n_in):
                La[k] = (p1[k] - p0[k]) * inv_n
                ELa[k] = (q1[k] - q0[k]) * inv_n
                Ra[k] = (pr1[k] - pr0[k]) * inv_n
                ERa[k] = (qr1[k] - qr0[k]) * inv_n
        for j in range(0, min(jl, W)):  # no left window: the right one, or the row mean
            if j <= jr:
                R[j] = (P[j + guard + 1 + flank] - P[j + guard + 1]) * inv_n
                ER[j] = (Q[j + guard + 1 + flank] - Q[j + guard + 1]) * inv_n
            else:
                R[j] = P[W] / (3.0 * W)
                ER[j] = Q[W] / (3.0 * W)
            L[j] = R[j]
            EL[j] = ER[j]
        for j in range(max(jr + 1, jl, 0), W):  # no right window: the left one
            L[j] = (P[j - guard] - P[j - guard - flank]) * inv_n
            EL[j] = (Q[j - guard] - Q[j - guard - flank]) * inv_n
            R[j] = L[j]
            ER[j] = EL[j]
        hr = hi[r]
        lr = lo[r]
        dr = d[r]
        cr = c[r]
        tr = tex[r]
        for j in range(W):
            g = np.float64(g1[j])
            h = max(L[j], R[j])
            lw = min(L[j], R[j])
            hr[j] = h
            lr[j] = lw
            dr[j] = g - 0.5 * (L[j] + R[j])
            tr[j] = np.sqrt(max(0.0, min(EL[j], ER[j])))
            if polarity == 1:
                cr[j] = g - h
            elif polarity == 2:
                cr[j] = lw - g
            else:
                cr[j] = max(g - h, lw - g)


@njit(cache=True, nogil=True)
def _grow_kernel(z, threshold, border, grow, visited, queue):  # pragma: no cover - compiled
    """Hysteresis segmentation: the 8-connected components of ``z > grow`` that hold a
    seed ``z > threshold`` (seeds in row-major order; none within ``border`` pixels of the
    left, right and bottom edges), found by breadth-first flood fill (cost ∝ their size).

    ``visited`` (uint8, flat, all zero) and ``queue`` (flat, size ≥ H·W) are work
    buffers, ``visited`` is zero again on return. Returns the inclusive boxes
    ``(c0, r0, c1, r1)``, peak ``z`` and area [px] per component.
    """
    H, W = z.shape
    cap = 64
    boxes = np.empty((cap, 4), np.int64)
    peaks = np.empty(cap, np.float32)
    areas = np.empty(cap, np.int64)
    k = 0
    top = 0
    for sr in range(0, H - border):
        zr = z[sr, border : max(border, W - border)]  # a slice: a fast scan from 0
        for k0 in range(zr.shape[0]):
            if not zr[k0] > threshold:
                continue
            sc = border + k0
            p = sr * W + sc
            if visited[p]:
                continue
            if k == cap:
                cap *= 2
                boxes2 = np.empty((cap, 4), np.int64)
                boxes2[:k] = boxes[:k]
                boxes = boxes2
                peaks2 = np.empty(cap, np.float32)
                peaks2[:k] = peaks[:k]
                peaks = peaks2
                areas2 = np.empty(cap, np.int64)
                areas2[:k] = areas[:k]
                areas = areas2
            visited[p] = 1
            start = top
            queue[top] = p
            top += 1
            head = start
            r0, r1, c0, c1 = H, -1, W, -1
            pk = -np.inf
            while head < top:
                q = queue[head]
                head += 1
                r = q // W
                c = q - r * W
                r0 = min(r0, r)
                r1 = max(r1, r)
                c0 = min(c0, c)
                c1 = max(c1, c)
                pk = max(pk, z[r, c])
                for rr in range(max(0, r - 1), min(H, r + 2)):
                    for cc in range(max(0, c - 1), min(W, c + 2)):
                        qq = rr * W + cc
                        if visited[qq] == 0 and z[rr, cc] > grow:
                            visited[qq] = 1
                            queue[top] = qq
                            top += 1
            boxes[k, 0] = c0
            boxes[k, 1] = r0
            boxes[k, 2] = c1
            boxes[k, 3] = r1
            peaks[k] = pk
            areas[k] = top - start
            k += 1
    for i in range(top):
        visited[queue[i]] = 0
    return boxes[:k], peaks[:k], areas[:k]


@njit(cache=True, nogil=True)
def _shear_row(src, starts, fy, y, out):  # pragma: no cover - compiled
    """One sheared row: ``out[c]`` = ``src`` at row ``y + k + fy[c]`` of column ``c``,
    linearly interpolated between rows (rows past the edges repeat the edge row), ``k``
    the whole-row shift of the run of columns ``c`` lies in (``starts``: first column and
    shift of each run, the last row closing the runs)."""
    h = src.shape[0]
    for run in range(starts.shape[0] - 1):
        c0 = starts[run, 0]
        c1 = starts[run + 1, 0]
        y0 = y + starts[run, 1]
        # slices, so that the loop below runs from 0 over contiguous memory (vectorised)
        ra = src[min(max(y0, 0), h - 1), c0:c1]
        rb = src[min(max(y0 + 1, 0), h - 1), c0:c1]
        f = fy[c0:c1]
        o = out[c0:c1]
        for c in range(c1 - c0):
            a = np.float32(ra[c])
            o[c] = a + f[c] * (np.float32(rb[c]) - a)


@njit(cache=True, nogil=True)
def _shear_kernel(src, starts, fy, r0, r1, out):  # pragma: no cover - compiled
    """Rows ``r0 … r1 − 1`` of the sheared band: row ``i`` is :func:`_shear_row` at
    ``y = i``."""
    for i in range(r0, r1):
        _shear_row(src, starts, fy, i, out[i])


@njit(cache=True, nogil=True)
def _shear_half_kernel(src, starts, fy, r0, r1, out):  # pragma: no cover - compiled
    """Rows ``r0 … r1 − 1`` of the sheared band at half resolution: ``out[i, j]`` is the
    mean of the sheared band (:func:`_shear_kernel`) over rows ``2i, 2i + 1`` and columns
    ``2j, 2j + 1``."""
    rows = np.empty((2, fy.shape[0]), np.float32)
    quarter = np.float32(0.25)
    for i in range(r0, r1):
        _shear_row(src, starts, fy, 2 * i, rows[0])
        _shear_row(src, starts, fy, 2 * i + 1, rows[1])
        a = rows[0]
        b = rows[1]
        oi = out[i]
        for j in range(out.shape[1]):
            oi[j] = quarter * ((a[2 * j] + a[2 * j + 1]) + (b[2 * j] + b[2 * j + 1]))


def _percentile(a: NDArray, q: float) -> float:
    """``np.percentile(a, q)`` (linear method) of a float32 array, from one partition
    (the next order statistic is the least value above it): the same number."""
    flat = a.ravel()
    n = flat.size
    v = (n - 1) * (q / 100.0)
    lo = math.floor(v)
    t = v - lo
    part = np.partition(flat, lo)
    x = part[lo]
    y = part[lo + 1 :].min() if lo + 1 < n else x
    d = y - x
    if t >= 0.5:
        return float(y - d * np.float32(1.0 - t))
    return float(x + d * np.float32(t))


def _threads() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


@functools.cache
def _pool() -> ThreadPoolExecutor:
    return ThreadPoolExecutor(max_workers=_threads(), thread_name_prefix="seawatch-detect")


def _run_rows(
    kernel: Callable[..., None], rows: int, head: tuple[Any, ...], tail: tuple[Any, ...]
) -> None:
    """Run a row-range kernel ``kernel(*head, r0, r1, *tail)`` over ``rows`` rows.

    A large image is cut into a few bands per core that the calling thread and the pool's
    threads take in turn (the kernels release the GIL): on a busy machine a thread that
    loses its core holds up one small band, not half of the image.
    """
    workers = _threads()
    bands = max(1, min(4 * workers, rows // 48))
    if bands == 1 or workers == 1:
        kernel(*head, 0, rows, *tail)
        return
    edges = np.linspace(0, rows, bands + 1).astype(int).tolist()
    ticket = itertools.count()  # next() is atomic under the GIL

    def work() -> None:
        while (i := next(ticket)) < bands:
            kernel(*head, edges[i], edges[i + 1], *tail)

    jobs = [_pool().submit(work) for _ in range(min(workers, bands) - 1)]
    work()
    for j in jobs:
        j.result()


@njit(cache=True, nogil=True)
def _gather_cells(a, step, sh, sw, ny, nx, reflect, out):  # pragma: no cover - compiled
    """``|a|`` on the ``step``-subsampled grid ``a[::step, ::step]``, gathered into cells:
    ``out[cy, cx]`` holds the ``sh × sw`` samples of cell (cy, cx); cells past the grid's
    end are padded by reflection without repeating the edge, or by the edge value."""
    hv = (a.shape[0] + step - 1) // step
    wv = (a.shape[1] + step - 1) // step
    for cy in range(ny):
        for i in range(sh):
            r = cy * sh + i
            if r >= hv:
                r = 2 * hv - 2 - r if reflect else hv - 1
            row = a[r * step]
            for cx in range(nx):
                o = out[cy, cx]
                n = i * sw
                for j in range(sw):
                    c = cx * sw + j
                    if c >= wv:
                        c = 2 * wv - 2 - c if reflect else wv - 1
                    o[n + j] = abs(row[c * step])


@njit(cache=True, nogil=True)
def _median3_rows(q):  # pragma: no cover - compiled
    """The median of each value and its two horizontal neighbours (edges repeated)."""
    ny, nx = q.shape
    out = np.empty_like(q)
    for cy in range(ny):
        for cx in range(nx):
            x0 = q[cy, max(cx - 1, 0)]
            x1 = q[cy, cx]
            x2 = q[cy, min(cx + 1, nx - 1)]
            out[cy, cx] = max(min(x0, x1), min(max(x0, x1), x2))
    return out


def _cell_grid(
    a: NDArray, cell_h: int, cell_w: int, step: int, quantile: float
) -> tuple[NDArray, int, int]:
    """Per-cell robust spread of the values ``a`` (``cell_h × cell_w`` cells, a
    ``step``-subsampled grid): ``q_p(|a|) / Φ⁻¹((1 + p)/2)`` with ``p = quantile`` (σ for
    Gaussian values; unmoved while outliers fill less than ``1 − p`` of a cell), then the
    median of each cell and its two horizontal neighbours. Returns the grid and the cell
    size actually used."""
    h, w = a.shape
    ch = max(step, min(cell_h, h) // step * step)
    cw = max(step, min(cell_w, w) // step * step)
    hv, wv = -(-h // step), -(-w // step)  # the subsampled grid's shape
    sh, sw = ch // step, cw // step
    ny, nx = -(-hv // sh), -(-wv // sw)
    cells = np.empty((ny, nx, sh * sw), np.float32)
    _gather_cells(a, step, sh, sw, ny, nx, min(hv, wv) > max(sh, sw), cells)
    k = int(quantile * (sh * sw - 1))
    q = np.partition(cells, k, axis=2)[:, :, k] * np.float32(1.0 / _ndtri(0.5 + 0.5 * quantile))
    if nx >= 3:
        q = _median3_rows(q)
    return q, ch, cw


def _upsample(q: NDArray, shape: tuple[int, int], ch: int, cw: int, floor: float) -> NDArray:
    """A cell grid bilinearly interpolated to ``shape`` (cells of ``ch × cw``), floored."""
    q = np.maximum(q, np.float32(floor))
    full = cv2.resize(q, (q.shape[1] * cw, q.shape[0] * ch), interpolation=cv2.INTER_LINEAR)
    return full[: shape[0], : shape[1]]


def _cell_noise(
    d: NDArray, cell_h: int, cell_w: int, floor: float, step: int = 2, quantile: float = 0.5
) -> NDArray:
    """Robust noise level [units] of the contrast ``d`` per cell (:func:`_cell_grid`),
    interpolated back to the size of ``d`` and floored at ``floor``."""
    q, ch, cw = _cell_grid(d, cell_h, cell_w, step, quantile)
    return _upsample(q, d.shape, ch, cw, floor)


def _int(name: str, value: Any, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise ValueError(f"{name}: expected an integer >= {minimum}, got {value!r}")
    return int(value)


def _in_sea(
    u: float,
    v: float,
    mask: NDArray[np.bool_] | None,
    ends: tuple[float, float] | None,
    shape: tuple[int, int],
    tol: float,
) -> bool:
    """Whether the water-line point (u, v) [px] is on the sea, ``tol`` px of slack upward."""
    H, W = shape
    if mask is not None:
        col = min(W - 1, max(0, round(u)))
        r0 = min(H - 1, max(0, math.floor(v - 0.5)))
        r1 = min(H - 1, r0 + math.ceil(tol))
        return bool(mask[r0 : r1 + 1, col].any())
    if ends is not None:
        y_line = ends[0] + (ends[1] - ends[0]) * u / max(1, W - 1)
        return v >= y_line - tol
    return True


def _frac_inside(inner: NDArray, outer: NDArray) -> float:
    """Fraction of box ``inner`` (x0, y0, x1, y1 inclusive) that lies inside ``outer``."""
    iw = min(inner[2], outer[2]) - max(inner[0], outer[0]) + 1
    ih = min(inner[3], outer[3]) - max(inner[1], outer[1]) + 1
    if iw <= 0 or ih <= 0:
        return 0.0
    area = (inner[2] - inner[0] + 1) * (inner[3] - inner[1] + 1)
    return float(iw * ih / area)


def _overlap(a: NDArray, b: NDArray) -> bool:
    return bool(a[0] <= b[2] and b[0] <= a[2] and a[1] <= b[3] and b[1] <= a[3])


@dataclass
class _Level:
    """Contrast maps of one scale: level pixel (i, j) covers working pixels
    ``[i f, (i + 1) f) × [j f, (j + 1) f)`` of the processed band."""

    factor: int
    bg_bright: NDArray  # max(L, R): what a bright target must exceed [units]
    bg_dark: NDArray  # min(L, R): what a dark target must undercut [units]
    sigma: NDArray  # robust noise level [units]
    z: NDArray  # contrast / noise
    chroma: list[tuple[int, NDArray, NDArray, NDArray]] | None = None  # (channel, hi, lo, σ)


@dataclass
class _Frame:
    """One frame's working geometry: working pixel (r, c) of the band is the full-frame
    point ``((c + 0.5) sx − 0.5, (wtop + r + off[c] + 0.5) sy − 0.5)`` (``off`` = the
    horizon shear [working px], None = 0)."""

    shape: tuple[int, int]  # the frame's (H, W) [px]
    grey: NDArray | None  # the full-resolution grey frame (None: from ``colour``)
    band: NDArray  # float32 working band
    wtop: int
    sx: float
    sy: float
    off: NDArray | None
    hrow: float  # the horizon's (or sea top's) row in the band [working px]; 0 if unknown
    colour: NDArray | None = None  # the full-resolution BGR frame
    chroma: list[tuple[int, NDArray]] | None = None  # (YCrCb channel, half-resolution band)

    def grey_crop(self, y0: int, y1: int, x0: int, x1: int) -> NDArray:
        """Rows ``y0 … y1 − 1``, columns ``x0 … x1 − 1`` of the full-resolution grey frame
        (float32; converted from the colour frame on demand)."""
        if self.grey is not None:
            return self.grey[y0:y1, x0:x1].astype(np.float32)
        assert self.colour is not None
        crop = np.ascontiguousarray(self.colour[y0:y1, x0:x1])
        return cv2.cvtColor(crop, cv2.COLOR_BGR2GRAY).astype(np.float32)

    def box_to_work(self, box: NDArray) -> tuple[float, float, float, float]:
        """Inclusive band-pixel box → unsheared working-pixel box (x0, y0, x1, y1)."""
        x0, y0, x1, y1 = (float(v) for v in box)
        lo = hi = 0.0
        if self.off is not None:
            seg = self.off[max(0, int(x0)) : int(x1) + 1]
            if seg.size:
                lo, hi = float(seg.min()), float(seg.max())
        return x0, y0 + self.wtop + lo, x1, y1 + self.wtop + hi


@dataclass
class _Candidate:
    box: NDArray  # x0, y0, x1, y1: inclusive working-pixel indices in the band
    level: int
    peak: float  # peak z


class _TemporalModel:
    """Running mean and mean square of the signed contrast per working pixel (rows
    shifted so that the horizon stays at its first row), with a selective update."""

    def __init__(self, rate: float, rate_detected: float, warmup: int):
        self.rate = rate
        self.rate_detected = rate_detected
        self.warmup = warmup
        self.reset()

    def reset(self) -> None:
        self.mean: NDArray | None = None
        self.sq: NDArray | None = None
        self.seen: NDArray | None = None  # frames seen per model row
        self.n = 0
        self.ref = 0.0
        self.key: tuple[int, ...] | None = None


_DILATE = np.ones((5, 9), np.uint8)


def _pick(polarity: str, bright: NDArray, dark: NDArray) -> NDArray:
    """The contrast of the chosen polarity (float32)."""
    c = bright if polarity == "bright" else dark if polarity == "dark" else np.maximum(bright, dark)
    return c.astype(np.float32, copy=False)


class ClassicalShipDetector:
    """Ship boxes without learned weights: multi-scale greatest-of CFAR contrast with a
    robust noise normalisation, hysteresis segmentation and full-resolution refinement.

    Issue 6 "Ship detection" (classical detector: horizon-stabilised local-contrast
    saliency on the sea region, optional temporal background model). No paper gives
    this method; it is the project's own [NEW] design from standard parts (CA/GO-CFAR:
    Richards, *Fundamentals of Radar Signal Processing*, §16.3). Steps per frame:

    1. Grey frame (BGR → luma; a colour frame also gives its chroma Cr, Cb),
       area-downscaled by ``s = min(1, work_height / H)`` to the working image and, when
       a horizon line is given, sheared column by column so that the horizon is one row
       (horizon-stabilised coordinates); rows above the sea's top less ``max_above · H``
       are skipped.
    2. At scales ``3^k`` (k = 0 … ``levels − 1``): ``g`` = 3×3 Gaussian-smoothed image,
       ``L``/``R`` = means of the 3-row × ``flank`` windows ``guard`` pixels left and
       right (the same rows, so the sea's vertical gradient, the horizon and long wave
       crests cancel); bright contrast ``c⁺ = g − max(L, R)``, dark contrast
       ``c⁻ = min(L, R) − g`` (greatest-of CFAR: a step edge or the end of a long
       structure is no target; ships may be brighter or darker than the sea).
    3. Noise ``σ = max(σ_cell, σ_ring)``: ``σ_cell`` = robust spread of
       ``|g − (L + R)/2|`` in cells of ``cell`` pixels (median, at coarse scales the 30 %
       quantile over a quarter of the width, then the median of three horizontal cells);
       ``σ_ring`` = the RMS local detail ``g − box5(g)`` in the quieter of the two
       training windows (high over glitter, whitecaps, textured land). Statistic
       ``z = c / σ``; for a colour frame the chroma planes' ``z`` (at half the working
       resolution) join in at the finest scale, ``z = max(z_Y, z_Cr, z_Cb)``, so that a
       boat as bright as the sea but of another colour is found.
    4. Hysteresis: 8-connected components of ``z > grow_threshold`` that hold a seed
       ``z > threshold`` (seeds within ``border`` working pixels of the left, right and
       bottom edges are ignored). Clutter-map test: with ``ρ`` the fraction of
       ``z > grow_threshold`` pixels around a candidate (0.13 % for Gaussian noise), it
       must reach ``z_peak > threshold · √(1 + ρ / clutter_rate)``. A coarse candidate
       narrow enough for the next finer scale gives way to the finer ones it overlaps; a
       wider one replaces the finer ones inside it. Fragments of one ship (hull and
       superstructure) are merged when they overlap on one axis with a gap of at most
       ``merge_gap`` × the smaller height on the other.
    5. Inside each candidate, at full resolution: the pixels whose noise-normalised
       contrast exceeds 0.4 × its 95th percentile in the candidate (the components that
       touch the candidate) give the box and the water-line point: the bottom edge of the
       lowest object pixel within the central half of the box's columns.
    6. A box is kept if its water-line point lies on the sea (``sea_mask``, or on or
       below the horizon line with ``horizon_tolerance · H`` of slack; the box itself may
       rise above the horizon), its sides are ≥ ``min_size`` and ≤ ``max_size`` × the
       frame's, its aspect ratios ``w/h`` and ``h/w`` are within ``max_aspect`` and its
       object area is ≥ ``min_area``. ``score = 1 − exp(−(z_peak / threshold)² / 2)``
       (0.39 at the threshold, 0.86 at twice it).

    With ``temporal=True`` the detector keeps, per pixel of each scale in
    horizon-stabilised rows (frame rows when no horizon is given: a static camera), a
    running mean ``m`` (rate ``temporal_rate``, a fiftieth of it within a few pixels of
    anything that looks like a target) and a running variance ``v`` of the signed
    contrast ``g − (L + R)/2`` (learnt only where nothing looks like a target); after 5
    frames the statistic becomes ``(c± − max(±m, 0)) / max(σ, √v)``. Flickering
    sub-threshold clutter raises ``v``; persistent clutter (a thermal fixed-pattern hot
    spot, a moored buoy) fades after about ``50 / temporal_rate`` frames, and so would
    a ship that stays on the same pixels that long (1000 frames, 40 s at 25 frames/s, at
    the default rate). It does little against strong, changing sun glint (that is left
    to the tracker's confirmation logic). :meth:`reset` forgets it.

    Intensities stay in the frame's units; sizes are pixels of the full frame unless
    stated. A constant frame (all black or all white) gives no boxes. The detector
    keeps work buffers between calls: use one instance per thread.
    """

    def __init__(
        self,
        *,
        threshold: float = 6.0,
        grow_threshold: float = 3.0,
        polarity: Polarity = "both",
        work_height: int = 540,
        levels: int = 3,
        guard: int = 12,
        flank: int = 24,
        cell: tuple[int, int] = (8, 64),
        min_size: float = 2.0,
        min_area: float = 4.0,
        max_size: float = 0.5,
        max_aspect: tuple[float, float] = (15.0, 5.0),
        border: int = 8,
        merge_gap: float = 0.5,
        max_above: float = 0.25,
        horizon_tolerance: float = 0.005,
        temporal: bool = False,
        temporal_rate: float = 0.05,
        clutter_rate: float = 0.01,
        colour: bool = True,
        max_candidates: int = 200,
    ) -> None:
        self.threshold = positive("threshold", threshold)
        self.grow_threshold = positive("grow_threshold", grow_threshold)
        if self.grow_threshold > self.threshold:
            raise ValueError(
                f"grow_threshold: expected <= threshold ({threshold}), got {grow_threshold}"
            )
        if polarity not in ("both", "bright", "dark"):
            raise ValueError(f"polarity: expected 'both', 'bright' or 'dark', got {polarity!r}")
        self.polarity: Polarity = polarity
        self.work_height = _int("work_height", work_height, 16)
        self.levels = _int("levels", levels, 1)
        self.guard = _int("guard", guard, 1)
        self.flank = _int("flank", flank, 2)
        try:
            ch, cw = (int(v) for v in cell)
        except (TypeError, ValueError):
            raise ValueError(f"cell: expected (rows, cols), got {cell!r}") from None
        if ch < 2 or cw < 2:
            raise ValueError(f"cell: expected both sides >= 2 px, got {cell!r}")
        self.cell = (ch, cw)
        self.min_size = positive("min_size", min_size)
        self.min_area = positive("min_area", min_area, allow_zero=True)
        self.max_size = in_range("max_size", max_size, 0.0, 1.0, lo_open=True)
        try:
            wide, tall = (float(v) for v in max_aspect)
        except (TypeError, ValueError):
            raise ValueError(
                f"max_aspect: expected (w/h, h/w) limits, got {max_aspect!r}"
            ) from None
        if not (wide >= 1 and tall >= 1 and math.isfinite(wide) and math.isfinite(tall)):
            raise ValueError(f"max_aspect: expected finite limits >= 1, got {max_aspect!r}")
        self.max_aspect = (wide, tall)
        self.border = _int("border", border, 0)
        self.merge_gap = positive("merge_gap", merge_gap, allow_zero=True)
        self.max_above = in_range("max_above", max_above, 0.0, 1.0)
        self.horizon_tolerance = in_range("horizon_tolerance", horizon_tolerance, 0.0, 1.0)
        self.temporal = bool(temporal)
        self._rate = in_range("temporal_rate", temporal_rate, 0.0, 1.0, lo_open=True)
        self._tms: dict[int, _TemporalModel] = {}
        self.clutter_rate = positive("clutter_rate", clutter_rate, allow_zero=True)
        self.max_candidates = _int("max_candidates", max_candidates, 1)
        self.colour = bool(colour)
        self._buffers: dict[tuple[Any, ...], NDArray] = {}

    def reset(self) -> None:
        """Forget the temporal model (a new video, a scene cut)."""
        self._tms.clear()

    # ------------------------------------------------------------------ main entry
    def __call__(
        self, image: ArrayLike, *, sea_mask: ArrayLike | None = None, horizon: Any = None
    ) -> Detections:
        """Detect ships in one frame (steps in the class docstring).

        Args:
            image: (H, W) grey (uint8, uint16, float) or (H, W, 3|4) BGR(A) frame.
            sea_mask: optional (H, W) bool array, True on the sea; a box is kept when its
                water-line point is on the sea.
            horizon: optional horizon line (``x0, y0, x1, y1`` [px], e.g. a
                ``HorizonEstimate``; ignored when not found). Without ``sea_mask`` the
                sea is what lies below it; it also stabilises the temporal model.

        Returns:
            :class:`Detections`, highest score first.

        Raises:
            ValueError: naming ``image``, ``sea_mask`` or ``horizon`` for bad input.
        """
        grey, quantum, colour = _image_planes(image)
        if colour is not None and not self.colour:
            grey, colour = cv2.cvtColor(colour, cv2.COLOR_BGR2GRAY), None
        H, W = (grey if grey is not None else colour).shape[:2]  # type: ignore[union-attr]
        mask = _sea_mask(sea_mask, (H, W))
        ends = _horizon_ends(horizon, W)
        if mask is not None and not mask.any():
            return Detections.empty()
        fr = self._frame(grey, colour, mask, ends, quantum)
        if fr is None:
            return Detections.empty()
        band = fr.band
        bmin, bmax = cv2.minMaxLoc(band)[:2]
        if bmin == bmax:
            return Detections.empty()  # a constant frame holds nothing
        floor = max(0.5 * quantum / math.sqrt(max(1.0, fr.sx * fr.sy)), 1e-4 * (bmax - bmin), 1e-12)
        levels = self._levels(band, floor, fr)
        cands = self._candidates(levels, band.shape)
        if not cands:
            return Detections.empty()
        tol = self.horizon_tolerance * H
        cands = [c for c in cands if self._near_sea(c, fr, mask, ends, tol)]
        cands = self._clutter_test(cands, levels[0])
        cands = self._merge(self._resolve_scales(cands))
        out = []
        for c in cands:
            r = self._refine(c, levels[c.level], fr)
            if r is None:
                continue
            x, y, w, h, u, v, area = r
            if (
                min(w, h) < self.min_size
                or w > self.max_size * W
                or h > self.max_size * H
                or w > self.max_aspect[0] * h
                or h > self.max_aspect[1] * w
                or area < self.min_area
                or not _in_sea(u, v, mask, ends, (H, W), tol)
            ):
                continue
            score = 1.0 - math.exp(-0.5 * (c.peak / self.threshold) ** 2)
            out.append((x, y, w, h, score, u, v))
        if not out:
            return Detections.empty()
        arr = np.array(out, dtype=np.float64)
        return Detections(arr[np.argsort(-arr[:, 4], kind="stable")])

    def _frame(
        self,
        grey: NDArray | None,
        colour: NDArray | None,
        mask: NDArray[np.bool_] | None,
        ends: tuple[float, float] | None,
        quantum: float = 1.0,
    ) -> _Frame | None:
        """The working band: the frame area-downscaled to ``work_height`` rows, sheared so
        that the horizon is one row (horizon-stabilised coordinates), cut from ``max_above``
        above the sea's top to the bottom (and the chroma planes Cr, Cb of a colour frame,
        alike). None when no sea is in view. ``grey`` may be None for a colour frame."""
        H, W = (grey if grey is not None else colour).shape[:2]  # type: ignore[union-attr]
        s = min(1.0, self.work_height / H)
        wh, ww = max(8, round(H * s)), max(8, round(W * s))
        sy, sx = H / wh, W / ww  # full-frame pixels per working pixel
        off = None
        if mask is not None:
            top = float(np.flatnonzero(mask.any(axis=1))[0] + 0.5) / sy - 0.5
        elif ends is not None:
            # the line in working pixels: y_w(c) at the working columns' centres
            cols = (np.arange(ww) + 0.5) * sx - 0.5
            y_full = ends[0] + (ends[1] - ends[0]) * cols / max(1, W - 1)
            y_w = (y_full + 0.5) / sy - 0.5
            top = float(y_w.mean())
            if float(np.ptp(y_w)) >= 0.5:
                off = (y_w - top).astype(np.float32)
        else:
            top = 0.0
        if top >= wh - 1:
            return None
        wtop = int(min(wh - 8, max(0, math.floor(top - self.max_above * wh))))
        area = {"interpolation": cv2.INTER_AREA}
        same = (wh, ww) == (H, W)
        cwork = None
        if colour is not None:
            cwork = colour if same else cv2.resize(colour, (ww, wh), **area)
        if grey is not None:
            work = grey if same else cv2.resize(grey, (ww, wh), **area)
        else:  # the luma of the area mean is the area mean of the luma
            work = cv2.cvtColor(cwork, cv2.COLOR_BGR2GRAY)
        if off is None:
            band = work[wtop:].astype(np.float32)
        else:  # working row r of column c is read at r + off[c]: the horizon is one row
            band = self._shear(work, wtop + off, wh - wtop, "band")
        chroma = []
        if cwork is not None and ww >= 2 and wh - wtop >= 2:
            # Cr, Cb of the working frame, sheared like the band, at half its resolution:
            # half-band pixel (i, j) is the mean of band rows 2i, 2i + 1, columns 2j, 2j + 1
            ycc = cv2.cvtColor(cwork, cv2.COLOR_BGR2YCrCb)
            shift = np.full(ww, wtop, np.float32) if off is None else wtop + off
            for ch_index in (1, 2):
                p = cv2.extractChannel(ycc, ch_index)  # contiguous rows shear faster
                half = self._shear(p, shift, wh - wtop, f"chroma{ch_index}", half=True)
                lo_c, hi_c = cv2.minMaxLoc(np.ascontiguousarray(half[::2, ::2]))[:2]
                if hi_c - lo_c < 2.0 * max(quantum, 1e-6 * max(abs(hi_c), 1.0)):
                    continue  # a flat chroma plane (a grey frame stored as colour)
                chroma.append((ch_index, half))
        hrow = top - wtop if ends is not None or mask is not None else 0.0
        return _Frame((H, W), grey, band, wtop, sx, sy, off, hrow, colour, chroma)

    def _shear(
        self, src: NDArray, shift: NDArray, rows: int, name: str, half: bool = False
    ) -> NDArray:
        """``rows`` rows of ``src`` (float32), column ``c`` read from row ``i + shift[c]``
        (linear between rows, edge rows repeated): a per-column vertical shift [px].
        ``half``: the result's 2 × 2 means instead (``rows // 2`` rows, half the
        columns)."""
        shift = np.asarray(shift, dtype=np.float32)
        iy = np.floor(shift).astype(np.int64)
        fy = shift - iy.astype(np.float32)
        cut = np.flatnonzero(np.diff(iy)) + 1  # runs of columns with one whole shift
        starts = np.empty((cut.size + 2, 2), np.int64)
        starts[0] = 0, iy[0]
        starts[1:-1, 0] = cut
        starts[1:-1, 1] = iy[cut]
        starts[-1] = shift.size, 0
        if half:
            out = self._buffer(f"shear-{name}", (rows // 2, shift.size // 2))
            _run_rows(_shear_half_kernel, rows // 2, (src, starts, fy), (out,))
        else:
            out = self._buffer(f"shear-{name}", (rows, shift.size))
            _run_rows(_shear_kernel, rows, (src, starts, fy), (out,))
        return out

    # ------------------------------------------------------------------ steps
    def _levels(self, band: NDArray, floor: float, fr: _Frame) -> list[_Level]:
        """Contrast maps at scales 1, 3, 9, … while the scaled band holds the CFAR windows
        (the training windows shrink to fit a narrow image, down to 4 columns)."""
        out: list[_Level] = []
        for k in range(self.levels):
            f = 3**k
            hk, wk = band.shape[0] // f, band.shape[1] // f
            guard = self.guard if k > 0 else min(self.guard, max(1, (wk - 9) // 2))
            flank = min(self.flank, (wk - 1) // 2 - guard)
            if hk < 4 or flank < 4:
                break
            if k == 0:
                g = band
            else:
                g = cv2.resize(band[: hk * f, : wk * f], (wk, hk), interpolation=cv2.INTER_AREA)
            out.append(self._level(g, f, floor / f, guard, flank, fr))
        return out

    def _buffer(self, name: str, shape: tuple[int, ...]) -> NDArray:
        """A reusable float32 work array (fresh large arrays cost page faults per frame)."""
        return self._work(name, shape, np.float32)

    def _work(self, name: str, shape: Any, dtype: Any, zero: bool = False) -> NDArray:
        key = (name, shape if isinstance(shape, tuple) else (shape,), np.dtype(dtype).str)
        buf = self._buffers.get(key)
        if buf is None:
            if len(self._buffers) > 64:
                self._buffers.clear()
            buf = self._buffers[key] = (np.zeros if zero else np.empty)(shape, dtype)
        return buf

    def _contrast(
        self, g: NDArray, tag: str, factor: int, floor: float, guard: int, flank: int, pol: int
    ) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray, NDArray]:
        """Smoothed plane, CFAR backgrounds, signed contrast ``d``, contrast ``c`` and noise
        ``σ`` of one plane at one scale (class docstring, steps 2–3)."""
        shape = g.shape
        gs = cv2.GaussianBlur(
            g, (3, 3), 0.8, dst=self._buffer(f"g{tag}", shape), borderType=cv2.BORDER_REPLICATE
        )
        b5 = cv2.blur(gs, (5, 5), dst=self._buffer(f"b{tag}", shape))
        hi, lo, d, c, tex = (self._buffer(f"{n}{tag}", shape) for n in ("hi", "lo", "d", "c", "t"))
        _run_rows(_contrast_kernel, shape[0], (gs, b5), (guard, flank, pol, hi, lo, d, c, tex))
        if factor == 1:
            base = _cell_noise(d, self.cell[0], self.cell[1], floor, step=2)
        else:  # coarser scales: cells of a quarter of the width, every pixel
            ch, cw = max(4, self.cell[0] // 2), max(16, shape[1] // 4)
            base = _cell_noise(d, ch, cw, floor, step=1, quantile=0.3)
        sigma = np.maximum(base, tex, out=tex)
        return gs, hi, lo, d, c, sigma

    def _level(
        self,
        g: NDArray,
        factor: int,
        floor: float,
        guard: int,
        flank: int,
        fr: _Frame,
    ) -> _Level:
        """Contrast, noise and statistic maps of one scale (class docstring, steps 2–3);
        at the finest scale of a colour frame the chroma planes' statistics join in
        (``z = max(z_Y, z_Cr, z_Cb)``), so that a boat of the sea's brightness but not its
        colour is found."""
        pol = {"both": 0, "bright": 1, "dark": 2}[self.polarity]
        gs, hi, lo, d, c, sigma = self._contrast(g, f"y{factor}", factor, floor, guard, flank, pol)
        if self.temporal:
            c, sigma = self._apply_temporal(gs, hi, lo, d, sigma, fr, factor)
        z = np.divide(c, sigma, out=c)
        chroma = None
        if factor == 1 and fr.chroma:
            chroma = []
            gc, fc = max(1, guard // 2), max(4, flank // 2)
            for ch_index, plane in fr.chroma:
                if plane.shape[1] < 2 * (gc + fc) + 1 or plane.shape[0] < 4:
                    continue
                _, hc, lc, _, cc, sc = self._contrast(
                    plane, f"c{ch_index}", 1, 2.0 * floor, gc, fc, 0
                )
                zc = cv2.resize(np.divide(cc, sc, out=cc), (z.shape[1], z.shape[0]))
                np.maximum(z, zc, out=z)
                chroma.append((ch_index, hc, lc, sc))
        return _Level(factor, hi, lo, sigma, z, chroma)

    def _apply_temporal(
        self,
        gs: NDArray,
        hi: NDArray,
        lo: NDArray,
        d: NDArray,
        sigma: NDArray,
        fr: _Frame,
        factor: int,
    ) -> tuple[NDArray, NDArray]:
        """Temporal clutter/noise model of one scale (class docstring): the contrast and
        noise to use."""
        tm = self._tms.get(factor)
        if tm is None:
            tm = self._tms[factor] = _TemporalModel(self._rate, self._rate / 50, warmup=5)
        bright = gs - hi
        dark = lo - gs
        hb, wb = d.shape
        top = fr.wtop / factor  # the band's first row in this scale's frame rows
        wh = math.ceil(top) + hb + 2  # model rows
        if tm.key != (wh, wb):  # new frame size: start again
            tm.reset()
            tm.key = (wh, wb)
        h_row = (fr.hrow + fr.wtop) / factor  # the horizon's row (0 without a horizon)
        if tm.mean is None or tm.sq is None:
            tm.ref = h_row
            tm.mean = np.zeros((wh, wb), np.float32)
            tm.sq = np.zeros((wh, wb), np.float32)
            tm.seen = np.zeros((wh, 1), np.float32)
        # band row r is model row r + start (rows stabilised on the horizon)
        start = round(top - (h_row - tm.ref))
        lo_r, hi_r = max(0, start), min(wh, start + hb)
        if hi_r <= lo_r:
            return _pick(self.polarity, bright, dark), sigma
        rows = slice(lo_r - start, hi_r - start)  # band rows with a model row
        mean = tm.mean[lo_r:hi_r]
        sq = tm.sq[lo_r:hi_r]
        ready = tm.seen[lo_r:hi_r] >= tm.warmup
        if ready.any():
            var = np.maximum(sq - mean * mean, 0.0)
            sig = sigma[rows]
            sig[...] = np.where(ready, np.maximum(sig, np.sqrt(var)), sig)
            bright[rows] -= np.where(ready, np.maximum(mean, 0.0), 0.0)
            dark[rows] -= np.where(ready, np.maximum(-mean, 0.0), 0.0)
        # selective update: pixels that look like targets now learn at a tenth of the rate
        looks = (np.maximum(bright[rows], dark[rows]) > self.grow_threshold * sigma[rows]).view(
            np.uint8
        )
        looks = cv2.dilate(looks, _DILATE)  # a target's faint rim learns slowly too
        rate = np.where(looks > 0, np.float32(tm.rate_detected), np.float32(tm.rate))
        first = tm.seen[lo_r:hi_r] == 0  # new rows start from no clutter, spatial noise
        if first.any():
            sig2 = sigma[rows] * sigma[rows]
            sq[...] = np.where(first, sig2, sq)
        dd = d[rows]
        mean += rate * (dd - mean)
        # the spread learns only where nothing looks like a target: a ship that stays on
        # the same pixels must not raise its own noise level
        sq += np.where(looks > 0, np.float32(0.0), rate) * (dd * dd - sq)
        tm.seen[lo_r:hi_r] += 1
        tm.n += 1
        return _pick(self.polarity, bright, dark), sigma

    def _candidates(self, levels: list[_Level], shape: tuple[int, int]) -> list[_Candidate]:
        """Hysteresis components of each scale, as working-pixel boxes with their peak z;
        seeds within ``border`` working pixels of the left, right and bottom edges are
        ignored (vignetting, dead columns), and components too large or too elongated for
        a ship are dropped."""
        cands: list[_Candidate] = []
        max_w, max_h = self.max_size * shape[1], self.max_size * shape[0]
        wide, tall = self.max_aspect
        for k, lv in enumerate(levels):
            z = lv.z
            f = lv.factor
            b = -(-self.border // f)
            hz, wz = z.shape
            visited = self._work(f"visited{f}", hz * wz, np.uint8, zero=True)
            queue = self._work(f"queue{f}", hz * wz, np.int64)
            boxes, peaks, _ = _grow_kernel(
                z,
                np.float32(self.threshold),
                b,
                np.float32(self.grow_threshold),
                visited,
                queue,
            )
            if boxes.shape[0] == 0:
                continue
            w = (boxes[:, 2] - boxes[:, 0] + 1) * f
            h = (boxes[:, 3] - boxes[:, 1] + 1) * f
            ok = (w <= max_w + f) & (h <= max_h + f) & (w <= wide * h + f) & (h <= tall * w + f)
            for i in np.flatnonzero(ok)[np.argsort(-peaks[ok])][: self.max_candidates]:
                x0, y0, x1, y1 = boxes[i]
                box = np.array([x0 * f, y0 * f, (x1 + 1) * f - 1, (y1 + 1) * f - 1], float)
                cands.append(_Candidate(box, k, float(peaks[i])))
        return cands

    def _clutter_test(self, cands: list[_Candidate], lv0: _Level) -> list[_Candidate]:
        """Clutter-map threshold: with ``ρ`` the fraction of finest-scale pixels with
        ``z > grow_threshold`` in a ring around the candidate (its box grown by ``flank``
        columns and 8 rows each side, the box itself left out; 0.13 % for Gaussian
        noise, several % on glitter, whitecaps and textured land), a candidate is kept
        when ``z_peak > threshold · √(1 + ρ / clutter_rate)``."""
        if not cands or self.clutter_rate == 0:
            return cands
        grow = (lv0.z > self.grow_threshold).view(np.uint8)
        ii = cv2.integral(grow)
        hz, wz = grow.shape
        keep = []
        for c in cands:
            x0, y0, x1, y1 = (int(v) for v in c.box)
            bx0, by0 = max(0, x0), max(0, y0)
            bx1, by1 = min(wz, x1 + 1), min(hz, y1 + 1)
            gx = max(self.flank, (x1 - x0 + 1) // 2)
            gy = max(8, (y1 - y0 + 1) // 2)
            rx0, ry0 = max(0, x0 - gx), max(0, y0 - gy)
            rx1, ry1 = min(wz, x1 + 1 + gx), min(hz, y1 + 1 + gy)
            s_out = ii[ry1, rx1] - ii[ry0, rx1] - ii[ry1, rx0] + ii[ry0, rx0]
            s_in = ii[by1, bx1] - ii[by0, bx1] - ii[by1, bx0] + ii[by0, bx0]
            n = (ry1 - ry0) * (rx1 - rx0) - max(0, by1 - by0) * max(0, bx1 - bx0)
            rho = float(s_out - s_in) / max(1, n)
            if c.peak > self.threshold * math.sqrt(1.0 + rho / self.clutter_rate):
                keep.append(c)
        return keep

    def _near_sea(
        self,
        c: _Candidate,
        fr: _Frame,
        mask: NDArray[np.bool_] | None,
        ends: tuple[float, float] | None,
        tol: float,
    ) -> bool:
        """Pre-filter before merging: a candidate whose bottom lies above the sea by more
        than ``tol`` plus twice its own height can be neither a ship nor a ship's upper
        part (full-frame pixels)."""
        if mask is None and ends is None:
            return True
        x0, y0, x1, y1 = fr.box_to_work(c.box)
        h = (y1 - y0 + 1) * fr.sy
        u = 0.5 * (x0 + x1 + 1) * fr.sx - 0.5
        v = (y1 + 1) * fr.sy - 0.5
        return _in_sea(u, v, mask, ends, fr.shape, tol + 2 * h)

    def _resolve_scales(self, cands: list[_Candidate]) -> list[_Candidate]:
        """Coarse-to-fine arbitration: a coarse candidate narrow enough for the next finer
        scale gives way to the finer candidates it overlaps; a wider one replaces the
        finer candidates that lie (at least half) inside it."""
        if len({c.level for c in cands}) < 2:
            return cands
        alive = [True] * len(cands)
        for i in sorted(range(len(cands)), key=lambda i: cands[i].level):
            ci = cands[i]
            if ci.level == 0 or not alive[i]:
                continue
            capacity = (2 * self.guard + 1) * 3 ** (ci.level - 1)
            width = ci.box[2] - ci.box[0] + 1
            finer = [j for j, c in enumerate(cands) if alive[j] and c.level < ci.level]
            if width <= capacity:
                if any(_overlap(cands[j].box, ci.box) for j in finer):
                    alive[i] = False
            else:
                for j in finer:
                    if _frac_inside(cands[j].box, ci.box) >= 0.5:
                        alive[j] = False
                        ci.peak = max(ci.peak, cands[j].peak)
        return [c for c, a in zip(cands, alive, strict=True) if a]

    def _merge(self, cands: list[_Candidate]) -> list[_Candidate]:
        """Merge the fragments of one ship (hull and superstructure, a hull cut by a wave):
        boxes that overlap on one axis with a gap of at most ``merge_gap`` × the smaller
        box height (at least one pixel) on the other, or that touch diagonally."""
        cands = list(cands)
        changed = True
        while changed and len(cands) > 1:
            changed = False
            for i in range(len(cands)):
                for j in range(i + 1, len(cands)):
                    a, b = cands[i].box, cands[j].box
                    gap = max(1.0, self.merge_gap * (min(a[3] - a[1], b[3] - b[1]) + 1))
                    gx = max(a[0], b[0]) - min(a[2], b[2]) - 1
                    gy = max(a[1], b[1]) - min(a[3], b[3]) - 1
                    if (gx < 0 and gy <= gap) or (gy < 0 and gx <= gap) or max(gx, gy) < 1:
                        box = np.concatenate([np.minimum(a[:2], b[:2]), np.maximum(a[2:], b[2:])])
                        level = min(cands[i].level, cands[j].level)
                        cands[i] = _Candidate(box, level, max(cands[i].peak, cands[j].peak))
                        del cands[j]
                        changed = True
                        break
                if changed:
                    break
        return cands

    def _refine(
        self, c: _Candidate, lv: _Level, fr: _Frame
    ) -> tuple[float, float, float, float, float, float, float] | None:
        """Full-resolution object mask inside a candidate: box (x, y, w, h), water-line
        point (u, v) [px] and object area [px²]; None when nothing stands out."""
        sx, sy = fr.sx, fr.sy
        H, W = fr.shape
        bx0, by0, bx1, by1 = fr.box_to_work(c.box)  # unsheared working pixels
        m = max(2.0, 0.25 * (by1 - by0 + 1)) + lv.factor
        # crop in full-frame pixels (the candidate plus a margin)
        fx0 = max(0, math.floor((bx0 - m) * sx))
        fx1 = min(W, math.ceil((bx1 + 1 + m) * sx))
        fy0 = max(0, math.floor((by0 - m) * sy))
        fy1 = min(H, math.ceil((by1 + 1 + m) * sy))
        if fx1 - fx0 < 2 or fy1 - fy0 < 2:
            return None
        # the level's backgrounds, sampled at the crop's pixel centres
        f = lv.factor
        cw = (np.arange(fx0, fx1, dtype=np.float32) + 0.5) / sx - 0.5  # working columns
        rw = (np.arange(fy0, fy1, dtype=np.float32) + 0.5) / sy - fr.wtop  # band edge rows
        mx, my = np.meshgrid((cw + 0.5) / f - 0.5, rw / f - 0.5)
        if fr.off is not None:
            shift = np.interp(cw, np.arange(fr.off.size), fr.off).astype(np.float32)
            my -= shift[None, :] / f
        remap = {"interpolation": cv2.INTER_LINEAR, "borderMode": cv2.BORDER_REPLICATE}
        hi = cv2.remap(lv.bg_bright, mx, my, **remap)
        lo = cv2.remap(lv.bg_dark, mx, my, **remap)
        # the crop itself, smoothed like the working image (one pixel of context)
        gx0, gy0 = max(0, fx0 - 1), max(0, fy0 - 1)
        gx1, gy1 = min(W, fx1 + 1), min(H, fy1 + 1)
        inner = (slice(fy0 - gy0, fy0 - gy0 + fy1 - fy0), slice(fx0 - gx0, fx0 - gx0 + fx1 - fx0))
        g = fr.grey_crop(gy0, gy1, gx0, gx1)
        g = cv2.GaussianBlur(g, (3, 3), 0.8, borderType=cv2.BORDER_REPLICATE)[inner]
        if self.polarity == "bright":
            res = g - hi
        elif self.polarity == "dark":
            res = lo - g
        else:
            res = np.maximum(g - hi, lo - g)
        res /= cv2.remap(lv.sigma, mx, my, **remap)  # in noise units, like z
        if lv.chroma and fr.colour is not None:
            col = np.ascontiguousarray(fr.colour[gy0:gy1, gx0:gx1])
            ycc = cv2.cvtColor(col, cv2.COLOR_BGR2YCrCb).astype(np.float32)
            ycc = cv2.GaussianBlur(ycc, (3, 3), 0.8, borderType=cv2.BORDER_REPLICATE)[inner]
            cx, cy = (mx + 0.5) / 2 - 0.5, (my + 0.5) / 2 - 0.5  # half-resolution planes
            for ch_index, hc, lc, sc in lv.chroma:
                gc = ycc[:, :, ch_index]
                hi_c = cv2.remap(hc, cx, cy, **remap)
                lo_c = cv2.remap(lc, cx, cy, **remap)
                rc = np.maximum(gc - hi_c, lo_c - gc) / cv2.remap(sc, cx, cy, **remap)
                np.maximum(res, rc, out=res)
        # the candidate's own pixels (no margin)
        cx0 = max(0, math.floor(bx0 * sx) - fx0)
        cx1 = min(fx1 - fx0, math.ceil((bx1 + 1) * sx) - fx0)
        cy0 = max(0, math.floor(by0 * sy) - fy0)
        cy1 = min(fy1 - fy0, math.ceil((by1 + 1) * sy) - fy0)
        core = res[cy0:cy1, cx0:cx1]
        if core.size == 0:
            return None
        peak = _percentile(core, 95.0) if core.size >= 20 else float(core.max())
        if peak <= 0:
            return None
        obj = (res > 0.4 * peak).view(np.uint8)
        n, labels = cv2.connectedComponents(obj, connectivity=8)
        touching = np.zeros(n, dtype=bool)
        touching[labels[cy0:cy1, cx0:cx1].ravel()] = True
        touching[0] = False
        if not touching.any():
            return None
        sel = touching[labels] if n > 2 else labels > 0
        rr, cc = np.nonzero(sel)
        r0, r1, c0, c1 = int(rr.min()), int(rr.max()), int(cc.min()), int(cc.max())
        x, y = fx0 + c0 - 0.5, fy0 + r0 - 0.5
        w, h = float(c1 - c0 + 1), float(r1 - r0 + 1)
        u, v = _waterline(sel[r0 : r1 + 1, c0 : c1 + 1])
        return x, y, w, h, x + u, y + v, float(rr.size)


def _waterline(obj: NDArray[np.bool_]) -> tuple[float, float]:
    """Water-line point of an object mask cut to its box, relative to the box's top-left
    corner [px]: the bottom edge of the lowest object pixel within the central half of the
    columns, at the mean column of that row's pixels there."""
    w = obj.shape[1]
    half = max(1, round(w / 4))
    mid = w // 2
    c0, c1 = max(0, mid - half), min(w, mid + half + (w % 2))
    central = obj[:, c0:c1]
    rows = np.flatnonzero(central.any(axis=1))
    if rows.size == 0:  # hollow middle: the whole width
        central, c0 = obj, 0
        rows = np.flatnonzero(central.any(axis=1))
    r = int(rows[-1])
    u = c0 + float(np.flatnonzero(central[r]).mean()) + 0.5
    return u, r + 1.0


# --------------------------------------------------------------------------------------
# water line of a given box, for detectors that give boxes only
# --------------------------------------------------------------------------------------


def waterline_points(image: ArrayLike, xywh: ArrayLike) -> FloatArray:
    """Water-line points ``(u_wl, v_wl)`` [px] of given boxes, refined on the pixels.

    For boxes from a learned or user detector (no object mask). Per box: the sea
    background of each row is the median of the strips left and right of the box (half
    the box width each, at least 4 px) on that row; the object is the pixels inside the
    box (and ``max(2, h/4)`` rows below it) whose absolute difference from it exceeds
    ``max(3 σ, 0.4 · p95)`` (σ = 1.4826 · MAD of the strips' residuals, p95 = the 95th
    percentile of the box's differences); the water-line point is the bottom edge of the
    lowest object pixel within the central half of the box's columns, as for
    :class:`ClassicalShipDetector`. A box with no such pixels keeps its bottom centre
    ``(x + w/2, y + h)``.

    Args:
        image: (H, W) grey or (H, W, 3|4) BGR(A) frame.
        xywh: (N, 4) boxes: top-left corner x, y [px], width and height [px].

    Returns:
        (N, 2) array of ``(u_wl, v_wl)`` [px].
    """
    g, _, _ = _gray(image)
    b = np.asarray(xywh, dtype=np.float64)
    if b.size == 0:
        return np.zeros((0, 2))
    if b.ndim != 2 or b.shape[1] != 4 or not np.all(np.isfinite(b)):
        raise ValueError(f"xywh: expected a finite (N, 4) array of x, y, w, h, got {b.shape}")
    H, W = g.shape
    out = np.column_stack([b[:, 0] + b[:, 2] / 2, b[:, 1] + b[:, 3]])
    for i, (x, y, w, h) in enumerate(b):
        c0, c1 = max(0, round(x + 0.5)), min(W, round(x + w + 0.5))
        r0 = max(0, round(y + 0.5))
        r1 = min(H, round(y + h + 0.5 + max(2.0, h / 4)))
        if c1 - c0 < 1 or r1 - r0 < 1:
            continue
        s = max(4, (c1 - c0) // 2)
        left = g[r0:r1, max(0, c0 - s) : c0].astype(np.float32)
        right = g[r0:r1, c1 : min(W, c1 + s)].astype(np.float32)
        strips = np.concatenate([left, right], axis=1)
        if strips.shape[1] < 2:
            continue
        bg = np.median(strips, axis=1, keepdims=True)
        sigma = 1.4826 * float(np.median(np.abs(strips - bg))) + 1e-6
        diff = np.abs(g[r0:r1, c0:c1].astype(np.float32) - bg)
        thr = max(3.0 * sigma, 0.4 * float(np.percentile(diff, 95)))
        obj = diff > thr
        if not obj.any():
            continue
        u, v = _waterline(obj)
        out[i] = (c0 - 0.5 + u, r0 - 0.5 + v)
    return out


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
        try:
            iw, ih = (int(v) for v in input_size)
        except (TypeError, ValueError):
            raise ValueError(f"input_size: expected (width, height), got {input_size!r}") from None
        if iw < 8 or ih < 8:
            raise ValueError(f"input_size: expected at least 8×8 pixels, got {input_size!r}")
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
