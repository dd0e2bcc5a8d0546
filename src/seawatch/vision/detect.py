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
* :class:`~seawatch.vision.external.OnnxDetector` — a YOLO-style ONNX model through
  onnxruntime (optional extra), and :class:`~seawatch.vision.external.CallableDetector`
  — any user function that returns boxes (:mod:`seawatch.vision.external`).

Pixels: ``x``/``u`` right, ``y``/``v`` down, origin at the centre of the top-left pixel
(INTERFACES.md), so the pixel in row r and column c covers ``[c - 0.5, c + 0.5] ×
[r - 0.5, r + 0.5]``. A box is its top-left corner ``(x, y)`` and size ``(w, h)`` [px];
the water-line point ``(u_wl, v_wl)`` [px] is where the hull meets the water, at the
middle of the hull: the hull/sea edge located to a fraction of a pixel (per column, the
coverage integral of the intensity step between hull and sea; a robust line through the
hull's columns).

Colour frames are taken in OpenCV's BGR(A) order; grey frames may be 8-bit, 16-bit
(thermal) or float. Intensities stay in the frame's own units (grey levels or counts).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, Literal, Protocol, runtime_checkable

import cv2
import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray
from scipy.special import ndtri as _ndtri

from seawatch._validation import FloatArray, in_range, int_pair, integer, positive
from seawatch.vision.planes import _image_planes
from seawatch.vision.waterline import _frame_ships, _waterline, waterline_points

__all__ = [
    "DETECTION_COLUMNS",
    "POLARITIES",
    "ClassicalShipDetector",
    "Detections",
    "Detector",
    "PreparedFrame",
    "sea_region",
    "waterline_points",
]

DETECTION_COLUMNS = ("x", "y", "w", "h", "score", "u_wl", "v_wl")
"""Columns of :attr:`Detections.boxes`: box top-left corner x, y [px], width w and height
h [px], score [0, 1], water-line point u_wl, v_wl [px]."""

Polarity = Literal["both", "bright", "dark"]
POLARITIES: tuple[str, ...] = ("both", "bright", "dark")
"""The ships :class:`ClassicalShipDetector` looks for (``polarity``)."""


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


def _horizon_points(horizon: Any) -> tuple[float, float, float, float] | None:
    """A horizon's line ``(x0, y0, x1, y1)`` [px], from an object with those attributes
    (a :class:`~seawatch.vision.horizon.HorizonEstimate`) or four numbers; None for None,
    a horizon not found or a line written as NaN."""
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
    return x0, y0, x1, y1


def _horizon_ends(horizon: Any, width: int) -> tuple[float, float] | None:
    """Rows [px] of the horizon line at columns 0 and ``width - 1``, or None."""
    line = _horizon_points(horizon)
    if line is None:
        return None
    x0, y0, x1, y1 = line
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


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _cfar_pixel(g, L, R, EL, ER, polarity):  # pragma: no cover - compiled
    """One pixel's outputs of the contrast kernels from its value ``g`` and its training
    windows' means ``L``, ``R`` and detail ``EL``, ``ER``: ``(max(L, R), min(L, R),
    g − (L + R)/2, sqrt(min(EL, ER)), c)`` with ``c`` by ``polarity`` (1 bright, 2 dark,
    0 the larger)."""
    h = max(L, R)
    lw = min(L, R)
    if polarity == 1:
        c = g - h
    elif polarity == 2:
        c = lw - g
    else:
        c = max(g - h, lw - g)
    return h, lw, g - 0.5 * (L + R), np.sqrt(max(0.0, min(EL, ER))), c


@njit(cache=True, nogil=True, error_model="numpy")
def _contrast_kernel(  # pragma: no cover - compiled
    gs, b5, guard, flank, polarity, hi, lo, d, c, tex
):
    """Greatest-of CFAR contrast and least-of clutter level of every pixel.

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
    for r in range(H):
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
            hr[j], lr[j], dr[j], tr[j], cr[j] = _cfar_pixel(
                np.float64(g1[j]), L[j], R[j], EL[j], ER[j], polarity
            )


@njit(cache=True, nogil=True, error_model="numpy")
def _censored_contrast_kernel(  # pragma: no cover - compiled
    gs, b5, keep, r0, r1, c0, c1, guard, flank, polarity, min_count, hi, lo, d, c, tex
):
    """:func:`_contrast_kernel` on rows ``r0 … r1 − 1``, columns ``c0 … c1 − 1`` with
    censored training windows: only pixels with ``keep`` (uint8, 1) count, so another
    target (or its part) in a window neither shifts the background mean nor raises the
    detail. A window with fewer than ``min_count`` kept pixels (it left the image, or
    holds mostly an object) is void; one void side takes the other's value, two void
    sides give ``c = d = tex = 0`` and ``hi = lo = g``. Outputs are (r1 − r0, c1 − c0)."""
    H, W = gs.shape
    a = max(0, c0 - guard - flank)  # prefix sums over the columns the windows reach
    b = min(W, c1 + guard + flank + 1)
    P = np.zeros(b - a + 1)
    Q = np.zeros(b - a + 1)
    N = np.zeros(b - a + 1)
    for r in range(r0, r1):
        ra, rb = max(r - 1, 0), min(r + 1, H - 1)
        acc = 0.0
        acc2 = 0.0
        accn = 0.0
        g0, g1, g2 = gs[ra], gs[r], gs[rb]
        m0, m1, m2 = b5[ra], b5[r], b5[rb]
        k0, k1, k2 = keep[ra], keep[r], keep[rb]
        for j in range(a, b):  # branch-free: a kept pixel counts with weight 1
            w0, w1, w2 = np.float64(k0[j]), np.float64(k1[j]), np.float64(k2[j])
            e0 = g0[j] - m0[j]
            e1 = g1[j] - m1[j]
            e2 = g2[j] - m2[j]
            acc += w0 * g0[j] + w1 * g1[j] + w2 * g2[j]
            acc2 += w0 * np.float64(e0 * e0) + w1 * np.float64(e1 * e1) + w2 * np.float64(e2 * e2)
            accn += w0 + w1 + w2
            P[j - a + 1] = acc
            Q[j - a + 1] = acc2
            N[j - a + 1] = accn
        o = r - r0
        for j in range(c0, c1):
            k = j - c0
            l0, l1 = max(0, j - guard - flank) - a, max(0, j - guard) - a
            m0, m1 = min(W, j + guard + 1) - a, min(W, j + guard + 1 + flank) - a
            nl = N[l1] - N[l0]
            nr = N[m1] - N[m0]
            okl = nl >= min_count
            okr = nr >= min_count
            g = np.float64(gs[r, j])
            if not okl and not okr:
                hi[o, k] = g
                lo[o, k] = g
                c[o, k] = 0.0
                d[o, k] = 0.0
                tex[o, k] = 0.0
                continue
            L = (P[l1] - P[l0]) / nl if okl else 0.0
            EL = (Q[l1] - Q[l0]) / nl if okl else 0.0
            R = (P[m1] - P[m0]) / nr if okr else L
            ER = (Q[m1] - Q[m0]) / nr if okr else EL
            if not okl:
                L = R
                EL = ER
            hi[o, k], lo[o, k], d[o, k], tex[o, k], c[o, k] = _cfar_pixel(g, L, R, EL, ER, polarity)


@njit(cache=True, nogil=True)
def _grow_kernel(z, sign, threshold, border, grow, visited, queue):  # pragma: no cover - compiled
    """Hysteresis segmentation: the 8-connected components of ``z > grow`` that hold a
    seed ``z > threshold`` (seeds in row-major order; none within ``border`` pixels of the
    left, right and bottom edges), found by breadth-first flood fill (cost ∝ their size).

    ``sign`` (uint8, the shape of ``z``, or 1 × 1 for none) gives each pixel's polarity
    bits (1 bright, 2 dark, 3 either): a component joins only pixels that share a bit
    with its seed, so a dark hull and the bright glint beside it are two components.
    ``visited`` (uint8, flat, all zero) and ``queue`` (flat, size ≥ H·W) are work
    buffers, ``visited`` is zero again on return. Returns the inclusive boxes
    ``(c0, r0, c1, r1)``, peak ``z``, area [px] and polarity bits (the OR of its
    pixels') per component.
    """
    signed = sign.shape[0] == z.shape[0] and sign.shape[1] == z.shape[1]
    H, W = z.shape
    cap = 64
    boxes = np.empty((cap, 4), np.int64)
    peaks = np.empty(cap, np.float32)
    areas = np.empty(cap, np.int64)
    pols = np.empty(cap, np.uint8)
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
                pols2 = np.empty(cap, np.uint8)
                pols2[:k] = pols[:k]
                pols = pols2
            seed = sign[sr, sc] if signed else np.uint8(3)
            pol = np.uint8(0)
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
                pol |= sign[r, c] if signed else np.uint8(3)
                for rr in range(max(0, r - 1), min(H, r + 2)):
                    for cc in range(max(0, c - 1), min(W, c + 2)):
                        qq = rr * W + cc
                        if (
                            visited[qq] == 0
                            and z[rr, cc] > grow
                            and (not signed or sign[rr, cc] & seed)
                        ):
                            visited[qq] = 1
                            queue[top] = qq
                            top += 1
            boxes[k, 0] = c0
            boxes[k, 1] = r0
            boxes[k, 2] = c1
            boxes[k, 3] = r1
            peaks[k] = pk
            areas[k] = top - start
            pols[k] = pol
            k += 1
    for i in range(top):
        visited[queue[i]] = 0
    return boxes[:k], peaks[:k], areas[:k], pols[:k]


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
def _shear_kernel(src, starts, fy, out):  # pragma: no cover - compiled
    """The sheared band (``out.shape[0]`` rows): row ``i`` is :func:`_shear_row` at
    ``y = i``."""
    for i in range(out.shape[0]):
        _shear_row(src, starts, fy, i, out[i])


@njit(cache=True, nogil=True)
def _shear_half_kernel(src, starts, fy, out):  # pragma: no cover - compiled
    """The sheared band at half resolution (``out.shape[0]`` rows): ``out[i, j]`` is the
    mean of the sheared band (:func:`_shear_kernel`) over rows ``2i, 2i + 1`` and columns
    ``2j, 2j + 1``."""
    rows = np.empty((2, fy.shape[0]), np.float32)
    quarter = np.float32(0.25)
    for i in range(out.shape[0]):
        _shear_row(src, starts, fy, 2 * i, rows[0])
        _shear_row(src, starts, fy, 2 * i + 1, rows[1])
        a = rows[0]
        b = rows[1]
        oi = out[i]
        for j in range(out.shape[1]):
            oi[j] = quarter * ((a[2 * j] + a[2 * j + 1]) + (b[2 * j] + b[2 * j + 1]))


_REFINE_FLOOR = 0.15
"""Least mask threshold of the candidate refinement as a fraction of the candidate's 95th
percentile contrast (``ClassicalShipDetector._refine_mask``)."""
_TRIM_RATIO = 2.0 / 3.0
"""An object mask's pixels of the other polarity beyond its own polarity's columns or under
them are dropped when under this fraction of its strongest pixel
(:func:`_trim_other_polarity`)."""


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
    a: NDArray,
    cell_h: int,
    cell_w: int,
    step: int,
    quantile: float,
    censor: NDArray[np.bool_] | None = None,
) -> tuple[NDArray, int, int]:
    """Per-cell robust spread of the values ``a`` (``cell_h × cell_w`` cells, a
    ``step``-subsampled grid): ``q_p(|a|) / Φ⁻¹((1 + p)/2)`` with ``p = quantile`` (σ for
    Gaussian values; unmoved while outliers fill less than ``1 − p`` of a cell), then the
    median of each cell and its two horizontal neighbours. With ``censor`` (True where a
    value is no noise sample) the quantile is of the other values: of the cell's when
    they are at least a quarter of it, else of its row of cells' when they are (a long
    ship's shadow covers whole cells), else of all. Returns the grid and the cell size
    actually used."""
    h, w = a.shape
    ch = max(step, min(cell_h, h) // step * step)
    cw = max(step, min(cell_w, w) // step * step)
    hv, wv = -(-h // step), -(-w // step)  # the subsampled grid's shape
    sh, sw = ch // step, cw // step
    ny, nx = -(-hv // sh), -(-wv // sw)
    cells = np.empty((ny, nx, sh * sw), np.float32)
    reflect = min(hv, wv) > max(sh, sw)
    _gather_cells(a, step, sh, sw, ny, nx, reflect, cells)
    k = int(quantile * (sh * sw - 1))
    q = np.partition(cells, k, axis=2)[:, :, k]
    if censor is not None and censor.any():
        kept = np.where(censor, np.float32(np.inf), a).astype(np.float32)
        _gather_cells(kept, step, sh, sw, ny, nx, reflect, cells)
        n = np.isfinite(cells).sum(axis=2)
        enough = n >= 0.25 * sh * sw
        q = np.where(enough, _finite_quantile(cells, n, quantile), q)
        rows = cells.reshape(ny, 1, nx * sh * sw)
        n_row = n.sum(axis=1, keepdims=True)
        q_row = _finite_quantile(rows, n_row, quantile)
        q = np.where(~enough & (n_row >= 0.25 * nx * sh * sw), q_row, q)
    q = q * np.float32(1.0 / _ndtri(0.5 + 0.5 * quantile))
    if nx >= 3:
        q = _median3_rows(q)
    return q, ch, cw


def _finite_quantile(cells: NDArray, n: NDArray, quantile: float) -> NDArray:
    """The ``quantile`` of the finite values along the last axis of ``cells`` (``n`` of
    them per row, the rest +inf), by the same rank as :func:`_cell_grid`'s."""
    k = np.maximum(0, (quantile * (n - 1)).astype(np.int64))
    return np.take_along_axis(np.sort(cells, axis=-1), k[..., None], axis=-1)[..., 0]


def _window_counts(
    strong: NDArray[np.bool_], guard: int, flank: int
) -> tuple[NDArray, NDArray, NDArray]:
    """Per pixel, the ``strong`` pixels in its 3-row column (``strong`` dilated by a row
    up and down) and in its left and right training windows (3 rows × ``flank``
    columns, ``guard`` columns beside it, as :func:`_contrast_kernel`'s; cut at the
    image's edges)."""
    s = cv2.dilate(strong.view(np.uint8), np.ones((3, 1), np.uint8))
    h, w = s.shape
    cs = np.zeros((h, w + 1), np.int32)
    np.cumsum(s, axis=1, out=cs[:, 1:])
    j = np.arange(w)
    left = cs[:, np.clip(j - guard, 0, w)] - cs[:, np.clip(j - guard - flank, 0, w)]
    right = cs[:, np.clip(j + guard + flank + 1, 0, w)] - cs[:, np.clip(j + guard + 1, 0, w)]
    return s, left, right


def _window_hits(strong: NDArray[np.bool_], guard: int, flank: int) -> NDArray[np.bool_]:
    """Where a pixel or one of its training windows (:func:`_window_counts`) holds a
    ``strong`` pixel: its ``|g − (L + R)/2|`` is a target's contrast, no noise sample."""
    s, left, right = _window_counts(strong, guard, flank)
    return (left > 0) | (right > 0) | (s > 0)


def _one_sided_hits(strong: NDArray[np.bool_], guard: int, flank: int) -> NDArray[np.bool_]:
    """The pixels within ``guard + flank`` columns of the left or right edge, where the
    contrast kernels have one training window (:func:`_contrast_kernel`), whose window
    (:func:`_window_counts`) holds a ``strong`` pixel: there a target in it makes its own
    sea beside it look like a target of the other polarity."""
    _, left, right = _window_counts(strong, guard, flank)
    w = strong.shape[1]
    edge = min(guard + flank, w)
    out = np.zeros(strong.shape, bool)
    out[:, :edge] = right[:, :edge] > 0  # left edge: the right window
    out[:, w - edge :] |= left[:, w - edge :] > 0  # right edge: the left window
    return out


def _wide_blocks(
    d: NDArray, c: NDArray, tex: NDArray, cell_h: int, floor: float, threshold: float
) -> NDArray[np.bool_]:
    """9 × 9 blocks of the finest scale that hold a target wider than the noise cells:
    at least ``_STRONG_SHARE`` of their pixels with contrast ``c`` above ``threshold``
    times the noise of their row of cells across the whole width (the 30 % quantile of
    ``|d|``, which a target filling up to two thirds of the width leaves unmoved) or the
    local detail ``tex``, where larger [units of ``d``]."""
    row = _cell_noise(d, cell_h, d.shape[1], floor, step=2, quantile=0.3)
    return _strong_blocks((c > threshold * np.maximum(row, tex)).astype(np.float32), 9)


def _strong_blocks(hot: NDArray, size: int) -> NDArray[np.bool_]:
    """The ``size × size`` blocks (whole ones, from the top-left corner) of the 0/1 map
    ``hot`` (float32) in which at least ``_STRONG_SHARE`` of the pixels are 1."""
    hb, wb = hot.shape[0] // size, hot.shape[1] // size
    if hb == 0 or wb == 0:
        return np.zeros((hb, wb), bool)
    share = cv2.resize(hot[: hb * size, : wb * size], (wb, hb), interpolation=cv2.INTER_AREA)
    return share >= _STRONG_SHARE


def _upsample(q: NDArray, shape: tuple[int, int], ch: int, cw: int, floor: float) -> NDArray:
    """A cell grid bilinearly interpolated to ``shape`` (cells of ``ch × cw``), floored."""
    q = np.maximum(q, np.float32(floor))
    full = cv2.resize(q, (q.shape[1] * cw, q.shape[0] * ch), interpolation=cv2.INTER_LINEAR)
    return full[: shape[0], : shape[1]]


def _cell_noise(
    d: NDArray,
    cell_h: int,
    cell_w: int,
    floor: float,
    step: int = 2,
    quantile: float = 0.5,
    censor: NDArray[np.bool_] | None = None,
) -> NDArray:
    """Robust noise level [units] of the contrast ``d`` per cell (:func:`_cell_grid`,
    ``censor`` the values that are no noise samples), interpolated back to the size of
    ``d`` and floored at ``floor``."""
    q, ch, cw = _cell_grid(d, cell_h, cell_w, step, quantile, censor)
    return _upsample(q, d.shape, ch, cw, floor)


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


def _paint_boxes(mask: NDArray, cands: list[_Candidate], f: int = 1, value: int = 0) -> None:
    """Set ``mask`` (a map at scale ``f``) to ``value`` (default 0: cleared) over the
    candidates' inclusive boxes (working pixels), in place."""
    for c in cands:
        x0, y0, x1, y1 = (int(v) // f for v in c.box)
        mask[max(0, y0) : y1 + 1, max(0, x0) : x1 + 1] = value


def _peak_at(z: NDArray, box: NDArray, f: int) -> tuple[float, float]:
    """Where in ``box`` (x0, y0, x1, y1 inclusive, working pixels) the map ``z`` of
    scale ``f`` peaks: the peak pixel's centre (u, v) [working pixels]."""
    x0, y0, x1, y1 = (int(b) // f for b in box)
    win = z[max(0, y0) : y1 + 1, max(0, x0) : x1 + 1]
    r, c = np.unravel_index(int(np.argmax(win)), win.shape)
    return (max(0, x0) + c + 0.5) * f, (max(0, y0) + r + 0.5) * f


def _holds(box: NDArray, u: float, v: float, slack: float) -> bool:
    """Whether the point (u, v) lies in ``box`` (inclusive, working pixels), widened by
    ``slack`` px on every side."""
    return bool(
        box[0] - slack <= u <= box[2] + 1 + slack and box[1] - slack <= v <= box[3] + 1 + slack
    )


def _area(box: NDArray) -> float:
    """Area of an inclusive box (x0, y0, x1, y1) [pixels]."""
    return float((box[2] - box[0] + 1) * (box[3] - box[1] + 1))


def _frac_inside(inner: NDArray, outer: NDArray) -> float:
    """Fraction of box ``inner`` (x0, y0, x1, y1 inclusive) that lies inside ``outer``."""
    iw = min(inner[2], outer[2]) - max(inner[0], outer[0]) + 1
    ih = min(inner[3], outer[3]) - max(inner[1], outer[1]) + 1
    if iw <= 0 or ih <= 0:
        return 0.0
    return float(iw * ih / _area(inner))


def _overlap(a: NDArray, b: NDArray) -> bool:
    return bool(a[0] <= b[2] and b[0] <= a[2] and a[1] <= b[3] and b[1] <= a[3])


@dataclass(frozen=True)
class PreparedFrame:
    """A frame made ready for detection (:meth:`ClassicalShipDetector.prepare`).

    Attributes:
        frame: the working band and geometry; None when no sea is in view.
        sea_mask: the (H, W) sea mask given, or None.
        ends: the horizon's rows at the left and right borders [px], or None.
    """

    frame: _Frame | None
    sea_mask: NDArray[np.bool_] | None
    ends: tuple[float, float] | None


_NO_SIGN = np.full((1, 1), 3, np.uint8)  # one polarity only: every pixel joins


def _polarity_bits(d: NDArray, out: NDArray | None = None) -> NDArray:
    """Each pixel's polarity bits for :func:`_grow_kernel` from the signed contrast ``d``
    (grey levels): 1 brighter than its background (``d > 0``), 2 darker (``d <= 0``);
    written into ``out`` (uint8, the shape of ``d``) when given."""
    bits = np.empty(d.shape, np.uint8) if out is None else out
    np.less_equal(d, 0, out=bits.view(np.bool_))
    bits += 1
    return bits


_POLARITY_CODE = {"both": 0, "bright": 1, "dark": 2}  # the contrast kernels' ``polarity``

_CENSOR_GAP = 3
"""Least gap [working px] above or below a candidate to a target found with censored
windows (:meth:`ClassicalShipDetector._censored`): nearer, it is the candidate's own
rim (the smoothing spreads a hull by a pixel, the box grows by one more). Beside it the
gap is the CFAR's ``guard``."""
_STRONG_SHARE = 0.25
"""From the third scale on, a level pixel is a target's whose block holds at least this
share of finest-scale pixels above the detection threshold: the sea beside it, whose
training windows hold it, is left out of the noise cells (``_window_hits``). Measured
on the rendered large ship magnified (session 30): with a block's any one pixel (0), the
sea texture's own small detections censored nearly every cell at twice the magnification
and the ship was lost; 0.5 lost it at 23.6 % of the frame's width, 0.25 keeps it."""
_WIDE_ASPECT = 4.0
"""A target of the wide-target pass (:meth:`ClassicalShipDetector._wide`) is at most this
many times wider than high (its component at its scale). Near enough to be wider than
the noise cells, a ship shows its hull's and superstructure's height; the sun's glare
band under the horizon beside a ship, 66 × 6.6 and 80 × 7.6 px in the rendered lighting
case, is not one (session 32: with no limit lighting's mean CLE rose 2.896 → 2.954 %;
with 3 to 6 the six WaSR images keep the same boxes)."""
_WIDE_FACTOR = 1.5
"""The wide-target pass asks its component's peak z to exceed this many times the
detection threshold: its noise is the 30 % quantile of a row of cells across the width
at a coarse scale, few independent samples. On the 24 rendered clips its components
that were no ship (cloud shadows, the frame's left and right edges, where a CFAR has
one training window) peaked at z 6.0–8.5, the WaSR buoy and white hull at 12.9–22.2
(session 32; a tuned value, from those two sets)."""


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
    sign: NDArray = field(default_factory=lambda: _NO_SIGN)  # polarity bits per pixel
    # (1 bright, 2 dark, 3 either)
    window: tuple[int, int] = (0, 0)  # the CFAR's (guard, flank) at this scale [px]
    planes: tuple[NDArray, NDArray] | None = None  # smoothed plane g and its 5 × 5 mean
    source: NDArray | None = None  # the scale's working band, before the smoothing
    blocks: NDArray[np.bool_] | None = None  # finest scale: its 9 × 9 blocks that hold a
    # target wider than the noise cells (:func:`_wide_blocks`), None when not looked for


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
    quantum: float = 0.0  # the grey levels' quantum [units] (0: continuous)
    _rows: NDArray | None = None  # grey rows converted from ``colour`` (grey_rows)
    _done: NDArray | None = None

    def grey_crop(self, y0: int, y1: int, x0: int, x1: int) -> NDArray:
        """Rows ``y0 … y1 − 1``, columns ``x0 … x1 − 1`` of the full-resolution grey frame
        (float32; converted from the colour frame on demand)."""
        return self.grey_rows(y0, y1)[:, x0:x1].astype(np.float32)

    def ycc_crop(self, y0: int, y1: int, x0: int, x1: int) -> NDArray:
        """Rows ``y0 … y1 − 1``, columns ``x0 … x1 − 1`` of the colour frame in (Y, Cr,
        Cb) (float32, (rows, columns, 3)); a colour frame only."""
        assert self.colour is not None
        crop = np.ascontiguousarray(self.colour[y0:y1, x0:x1])
        return cv2.cvtColor(crop, cv2.COLOR_BGR2YCrCb).astype(np.float32)

    def grey_rows(self, y0: int, y1: int) -> NDArray:
        """Rows ``y0 … y1 − 1`` (within the frame) of the full-resolution grey frame, all
        columns (converted from a colour frame once per row and kept)."""
        if self.grey is not None:
            return self.grey[y0:y1]
        assert self.colour is not None
        H, W = self.shape
        if self._rows is None:
            self._rows = np.empty((H, W), self.colour.dtype)
            self._done = np.zeros(H, dtype=bool)
        todo = np.flatnonzero(~self._done[y0:y1])
        if todo.size:
            a, b = y0 + int(todo[0]), y0 + int(todo[-1]) + 1
            cv2.cvtColor(self.colour[a:b], cv2.COLOR_BGR2GRAY, dst=self._rows[a:b])
            self._done[a:b] = True
        return self._rows[y0:y1]

    def box_to_work(self, box: NDArray) -> tuple[float, float, float, float]:
        """Inclusive band-pixel box → unsheared working-pixel box (x0, y0, x1, y1)."""
        x0, y0, x1, y1 = (float(v) for v in box)
        lo = hi = 0.0
        if self.off is not None:
            seg = self.off[max(0, int(x0)) : int(x1) + 1]
            if seg.size:
                lo, hi = float(seg.min()), float(seg.max())
        return x0, y0 + self.wtop + lo, x1, y1 + self.wtop + hi


# a refined object: box x, y, w, h, water-line point u, v [px] and area [px²]
_Object = tuple[float, float, float, float, float, float, float]


@dataclass
class _Candidate:
    box: NDArray  # x0, y0, x1, y1: inclusive working-pixel indices in the band
    level: int
    peak: float  # peak z
    polarity: int = 3  # bits: 1 bright, 2 dark (3: both, or a colour contrast)
    maps: _Level | None = None  # its own finest-scale maps (censored windows), else None


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
       quantile over a quarter of the width, from the third scale on leaving out the
       sea whose training windows hold a finest-scale target, ``_window_hits``: there
       ``|g − (L + R)/2|`` is a long ship's contrast, no noise; then the median of three
       horizontal cells);
       ``σ_ring`` = the RMS local detail ``g − box5(g)`` in the quieter of the two
       training windows (high over glitter, whitecaps, textured land). Statistic
       ``z = c / σ``; for a colour frame the chroma planes' ``z`` (at half the working
       resolution) join in at the finest scale, ``z = max(z_Y, z_Cr, z_Cb)``, so that a
       boat as bright as the sea but of another colour is found.
    4. Hysteresis: 8-connected components of ``z > grow_threshold`` that hold a seed
       ``z > threshold`` (seeds within ``border`` working pixels of the left, right and
       bottom edges are ignored). Clutter-map test: with ``ρ`` the fraction of
       ``z > grow_threshold`` pixels around a candidate (0.13 % for Gaussian noise), it
       must reach ``z_peak > threshold · √(1 + ρ / clutter_rate)`` — a candidate that
       holds a shorter finer one that passed is tried again with the passed ones left
       out of its ring (a ship beside another is no clutter). A coarse candidate
       narrow enough for the next finer scale gives way to the finer ones it overlaps
       that hold its peak; a wider one replaces the finer ones inside it. Fragments of
       one ship (hull and superstructure) are merged when they overlap on one axis with
       a gap of at most ``merge_gap`` × the smaller height on the other; a bright and a
       dark one only when the bright one is stacked on the dark one (:meth:`_mergeable`).
       With ``censor=True`` (the default) the targets the candidates hide are looked
       for too (:meth:`_censored`): around them the finest scale is computed again with
       their boxes left out of the training windows and noise cells, and components
       clear of every candidate join as candidates of their own (merged only with one
       another), refined on those censored maps.
    4b. With ``wide=True`` (the default; not with ``temporal``) targets wider than the
       noise cells, whose own contrast fills the cells and holds their ``z`` down at
       every scale (a moored yacht 80 px long in a 512-px frame, a buoy of 100 px), are
       looked for in a pass of their own (:meth:`_wide`): 9 × 9 blocks of the finest
       scale where a quarter of the pixels exceed the threshold against the noise of
       their whole row of cells across the width (:func:`_wide_blocks`) mark the
       sea to leave out of the coarser scales' noise cells, computed again; components
       seeded below the horizon (grown past it: a close ship's superstructure joins its
       hull), wider than the next finer scale's CFAR sees, at most ``_WIDE_ASPECT``
       times wider than high and peaking above ``_WIDE_FACTOR`` × the threshold,
       through the clutter test and not the echo of a target in the one training window
       near the frame's edge (:meth:`_echo`), replace the candidates of their polarity
       inside them. The candidates of steps 4–5 are left as they were.
    5. Inside each candidate, at full resolution, an object mask — ``refine="mask"``
       (default, :meth:`_refine_mask`): the pixels whose noise-normalised contrast
       against the level's CFAR backgrounds exceeds 0.4 × its 95th percentile p in the
       candidate, or the detection threshold where that is lower (at least 0.15 p), in
       the components that touch it, less the fainter pixels of the other polarity
       beside the ends of the candidate's own and under them (a glare band behind a
       dark hull, a glint streak under it: :func:`_trim_other_polarity`);
       ``refine="flank"``
       (:meth:`_refine`, :meth:`_segment`): the object against a background of its own
       (per line parallel to the horizon, from flanks 1.5–3.5 object widths away), by
       polarity, with hysteresis, the window grown until the whole ship is in it —
       whole ships where the CFAR's own shadow hides a long hull, parts of less contrast
       (superstructure, masts) joined, background structure reaching the window's edge
       (a glint path) dropped; it costs a few ms per candidate more. Then
       (:meth:`_ships`): the box is the extent of the object's pixels that are at least
       half covered, its left and right ends then to a fraction of a pixel where they
       can be measured (:func:`_subpixel_ends`: the coverage integral across each end);
       the water-line point is the hull/sea edge at the middle of the
       hull's columns, to a fraction of a pixel (:mod:`seawatch.vision.waterline`: per
       column the coverage integral of the unsmoothed intensity step between the hull's
       and the sea's levels — or colours —, which neither the smoothing, the threshold
       nor a symmetric lens or codec blur moves; a Theil–Sen line through the columns),
       or, when that edge is too faint, the bottom edge of the lowest object pixel
       within the central half of the box's columns. Where the water line jumps between
       flat levels, the object is two ships, one in front of the
       other or side by side, each boxed with its own water line; detections that are a
       part of another (a superstructure boxed alone, two candidates of one ship) are
       dropped (:func:`_distinct`). With ``refine="mask"`` a bright candidate (of the
       brightness polarity alone) is kept only if the flank refinement finds an object
       in it too: glitter, the sun path's own structure running on beyond the flank
       windows, is none (the mask refinement keeps the boxes).
    6. A box is kept if its water-line point lies on the sea (``sea_mask``, or on or
       below the horizon line with ``horizon_tolerance · H`` of slack; the box itself may
       rise above the horizon), its sides are ≥ ``min_size`` (1.5 px: the rendered lighting
       case's 7.2 × 1.8 px boat is boxed 1.6–3.1 px high, 5–95 %, and under 2 px in 80 of
       its 295 boxes over three renderings; with 2 px those frames lost it) and
       ≤ ``max_size`` × the frame's, its aspect ratios ``w/h`` and ``h/w`` are within
       ``max_aspect`` and its object area is ≥ ``min_area``.
       ``score = 1 − exp(−(z_peak / threshold)² / 2)`` (0.39 at the threshold, 0.86 at
       twice it).

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
        min_size: float = 1.5,
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
        refine: Literal["mask", "flank"] = "mask",
        censor: bool = True,
        wide: bool = True,
    ) -> None:
        self.threshold = positive("threshold", threshold)
        self.grow_threshold = positive("grow_threshold", grow_threshold)
        if self.grow_threshold > self.threshold:
            raise ValueError(
                f"grow_threshold: expected <= threshold ({threshold}), got {grow_threshold}"
            )
        if polarity not in POLARITIES:
            raise ValueError(f"polarity: expected 'both', 'bright' or 'dark', got {polarity!r}")
        self.polarity: Polarity = polarity
        self.work_height = integer("work_height", work_height, 16)
        self.levels = integer("levels", levels, 1)
        self.guard = integer("guard", guard, 1)
        self.flank = integer("flank", flank, 2)
        self.cell = int_pair("cell", cell, ("rows", "cols"), 2)
        self.min_size = positive("min_size", min_size)
        self.min_area = positive("min_area", min_area, allow_zero=True)
        self.max_size = in_range("max_size", max_size, 0.0, 1.0, lo_open=True)
        try:
            flat, tall = (float(v) for v in max_aspect)
        except (TypeError, ValueError):
            raise ValueError(
                f"max_aspect: expected (w/h, h/w) limits, got {max_aspect!r}"
            ) from None
        if not (flat >= 1 and tall >= 1 and math.isfinite(flat) and math.isfinite(tall)):
            raise ValueError(f"max_aspect: expected finite limits >= 1, got {max_aspect!r}")
        self.max_aspect = (flat, tall)
        self.border = integer("border", border, 0)
        self.merge_gap = positive("merge_gap", merge_gap, allow_zero=True)
        self.max_above = in_range("max_above", max_above, 0.0, 1.0)
        self.horizon_tolerance = in_range("horizon_tolerance", horizon_tolerance, 0.0, 1.0)
        self.temporal = bool(temporal)
        self._rate = in_range("temporal_rate", temporal_rate, 0.0, 1.0, lo_open=True)
        self._tms: dict[int, _TemporalModel] = {}
        self.clutter_rate = positive("clutter_rate", clutter_rate, allow_zero=True)
        self.max_candidates = integer("max_candidates", max_candidates, 1)
        self.colour = bool(colour)
        if refine not in ("mask", "flank"):
            raise ValueError(f"refine: expected 'mask' or 'flank', got {refine!r}")
        self.refine: Literal["mask", "flank"] = refine
        self.censor = bool(censor)
        self.wide = bool(wide)
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
        return self.detect_prepared(self.prepare(image, sea_mask=sea_mask, horizon=horizon))

    def prepare(
        self, image: ArrayLike, *, sea_mask: ArrayLike | None = None, horizon: Any = None
    ) -> PreparedFrame:
        """The first step of :meth:`__call__` alone: the frame's working band (and chroma
        planes), for :meth:`detect_prepared`. It keeps no state and writes into fresh
        arrays, so it may run in another thread, frames ahead of the detection (as
        :meth:`~seawatch.vision.tracker.VisualTracker.stream` does).

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
            return PreparedFrame(None, mask, ends)
        return PreparedFrame(self._frame(grey, colour, mask, ends, quantum), mask, ends)

    def detect_prepared(self, prepared: PreparedFrame) -> Detections:
        """The detections of a frame made ready by :meth:`prepare` (the remaining steps
        of :meth:`__call__`; give the frames in video order when ``temporal``)."""
        fr, mask, ends = prepared.frame, prepared.sea_mask, prepared.ends
        if fr is None:
            return Detections.empty()
        H, W = fr.shape
        band = fr.band
        bmin, bmax = cv2.minMaxLoc(band)[:2]
        if bmin == bmax:
            return Detections.empty()  # a constant frame holds nothing
        quantum_floor = 0.5 * fr.quantum / math.sqrt(max(1.0, fr.sx * fr.sy))
        floor = max(quantum_floor, 1e-4 * (bmax - bmin), 1e-12)
        levels = self._levels(band, floor, fr)
        cands = self._candidates(levels, band.shape)
        if not cands:
            return Detections.empty()
        tol = self.horizon_tolerance * H
        every = cands
        cands = [c for c in cands if self._near_sea(c, fr, mask, ends, tol)]
        cands = self._clutter_test(cands, levels[0])
        hidden = []
        if self.censor and not self.temporal and cands:
            hidden = self._censored(every, cands, levels[0], floor)
        cands = self._merge(self._resolve_scales(cands, levels))
        if levels[0].blocks is not None:  # wide=True, not temporal (:meth:`_level`)
            wide = [
                c
                for c in self._wide(levels, band, floor, fr, cands)
                if self._near_sea(c, fr, mask, ends, tol)
            ]
            if wide:  # they replace the candidates of their polarity inside them
                kept = [
                    c
                    for c in cands
                    if not any(
                        c.polarity & w.polarity and _frac_inside(c.box, w.box) >= 0.5 for w in wide
                    )
                ]
                cands = kept + wide
        # a target found beside a candidate is another object: merged only with its kind
        cands += self._merge([c for c in hidden if self._near_sea(c, fr, mask, ends, tol)])
        # merged, a ship's candidate reaches down to its hull: one whose bottom is above
        # the sea by more than its height is a cloud or a coast feature
        cands = [c for c in cands if self._near_sea(c, fr, mask, ends, tol, 1.0)]
        out, polarity = [], []
        refine = self._refine if self.refine == "flank" else self._refine_mask
        for c in cands:
            lv = c.maps or levels[c.level]
            objects = refine(c, lv, fr)
            if objects and self.refine == "mask" and c.polarity == 1:
                # a bright candidate must also stand out against a background of its own
                # (:meth:`_refine`): a glitter streak is the sun path's structure
                # running on beyond any window, a ship is not
                if not self._refine(c, lv, fr):
                    continue
            for x, y, w, h, u, v, area in objects:
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
                polarity.append(c.polarity)
        if not out:
            return Detections.empty()
        arr = np.array(out, dtype=np.float64)
        order = np.argsort(-arr[:, 4], kind="stable")
        arr = arr[order]
        return Detections(arr[_distinct(arr, np.array(polarity)[order])])

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
            band = self._shear(work, wtop + off, wh - wtop)
        chroma = []
        if cwork is not None and ww >= 2 and wh - wtop >= 2:
            # Cr, Cb of the working frame, sheared like the band, at half its resolution:
            # half-band pixel (i, j) is the mean of band rows 2i, 2i + 1, columns 2j, 2j + 1
            ycc = cv2.cvtColor(cwork, cv2.COLOR_BGR2YCrCb)
            shift = np.full(ww, wtop, np.float32) if off is None else wtop + off
            for ch_index in (1, 2):
                p = cv2.extractChannel(ycc, ch_index)  # contiguous rows shear faster
                half = self._shear(p, shift, wh - wtop, half=True)
                lo_c, hi_c = cv2.minMaxLoc(np.ascontiguousarray(half[::2, ::2]))[:2]
                if hi_c - lo_c < 2.0 * max(quantum, 1e-6 * max(abs(hi_c), 1.0)):
                    continue  # a flat chroma plane (a grey frame stored as colour)
                chroma.append((ch_index, half))
        hrow = top - wtop if ends is not None or mask is not None else 0.0
        return _Frame((H, W), grey, band, wtop, sx, sy, off, hrow, colour, chroma, quantum)

    @staticmethod
    def _shear(src: NDArray, shift: NDArray, rows: int, half: bool = False) -> NDArray:
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
        if half:  # fresh arrays: prepare() may run ahead of the detection
            out = np.empty((rows // 2, shift.size // 2), np.float32)
            _shear_half_kernel(src, starts, fy, out)
        else:
            out = np.empty((rows, shift.size), np.float32)
            _shear_kernel(src, starts, fy, out)
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
            strong = None
            if k == 0:
                g = band
            else:
                g = cv2.resize(band[: hk * f, : wk * f], (wk, hk), interpolation=cv2.INTER_AREA)
                if k >= 2:  # the finest scale's targets, by level pixel
                    hot = cv2.threshold(out[0].z, self.threshold, 1.0, cv2.THRESH_BINARY)[1]
                    strong = _strong_blocks(hot, f)
            out.append(self._level(g, f, floor / f, guard, flank, fr, strong))
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
        self,
        g: NDArray,
        tag: str,
        factor: int,
        floor: float,
        guard: int,
        flank: int,
        pol: int,
        strong: NDArray | None = None,
        wide: bool = False,
    ) -> tuple[
        tuple[NDArray, NDArray], NDArray, NDArray, NDArray, NDArray, NDArray, NDArray | None
    ]:
        """Smoothed plane and its 5 × 5 mean, CFAR backgrounds, signed contrast ``d``,
        contrast ``c`` and noise ``σ`` of one plane at one scale (class docstring, steps
        2–3); with ``wide`` (finest scale) also its :func:`_wide_blocks`, else None."""
        shape = g.shape
        blocks = None
        gs = cv2.GaussianBlur(
            g, (3, 3), 0.8, dst=self._buffer(f"g{tag}", shape), borderType=cv2.BORDER_REPLICATE
        )
        b5 = cv2.blur(gs, (5, 5), dst=self._buffer(f"b{tag}", shape))
        hi, lo, d, c, tex = (self._buffer(f"{n}{tag}", shape) for n in ("hi", "lo", "d", "c", "t"))
        _contrast_kernel(gs, b5, guard, flank, pol, hi, lo, d, c, tex)
        if factor == 1:
            base = _cell_noise(d, self.cell[0], self.cell[1], floor, step=2)
            if wide:
                blocks = _wide_blocks(d, c, tex, self.cell[0], floor, self.threshold)
        else:  # coarser scales: cells of a quarter of the width, every pixel
            ch, cw = max(4, self.cell[0] // 2), max(16, shape[1] // 4)
            hit = None if strong is None else _window_hits(strong, guard, flank)
            base = _cell_noise(d, ch, cw, floor, step=1, quantile=0.3, censor=hit)
        sigma = np.maximum(base, tex, out=tex)
        return (gs, b5), hi, lo, d, c, sigma, blocks

    def _level(
        self,
        g: NDArray,
        factor: int,
        floor: float,
        guard: int,
        flank: int,
        fr: _Frame,
        strong: NDArray[np.bool_] | None = None,
        suffix: str = "",
    ) -> _Level:
        """Contrast, noise and statistic maps of one scale (class docstring, steps 2–3);
        at the finest scale of a colour frame the chroma planes' statistics join in
        (``z = max(z_Y, z_Cr, z_Cb)``), so that a boat of the sea's brightness but not its
        colour is found."""
        pol = _POLARITY_CODE[self.polarity]
        wide = factor == 1 and self.wide and not self.temporal
        planes, hi, lo, d, c, sigma, blocks = self._contrast(
            g, f"y{factor}{suffix}", factor, floor, guard, flank, pol, strong, wide
        )
        gs = planes[0]
        if self.temporal:
            c, sigma = self._apply_temporal(gs, hi, lo, d, sigma, fr, factor)
        z = np.divide(c, sigma, out=c)
        sign = _NO_SIGN
        if pol == 0:  # bright where g > (L + R)/2 (then g − max(L, R) > min(L, R) − g)
            sign = _polarity_bits(d, self._work(f"sign{factor}{suffix}", d.shape, np.uint8))
        chroma = None
        if factor == 1 and fr.chroma:
            chroma = []
            gc, fc = max(1, guard // 2), max(4, flank // 2)
            for ch_index, plane in fr.chroma:
                if plane.shape[1] < 2 * (gc + fc) + 1 or plane.shape[0] < 4:
                    continue
                _, hc, lc, _, cc, sc, _ = self._contrast(
                    plane, f"c{ch_index}", 1, 2.0 * floor, gc, fc, 0
                )
                zc = cv2.resize(np.divide(cc, sc, out=cc), (z.shape[1], z.shape[0]))
                if pol == 0:  # a colour contrast has no brightness polarity
                    np.putmask(sign, zc > z, 3)
                np.maximum(z, zc, out=z)
                chroma.append((ch_index, hc, lc, sc))
        window = (guard, flank)
        return _Level(factor, hi, lo, sigma, z, chroma, sign, window, planes, g, blocks)

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
        for k, lv in enumerate(levels):
            z = lv.z
            f = lv.factor
            b = -(-self.border // f)
            hz, wz = z.shape
            visited = self._work(f"visited{f}", hz * wz, np.uint8, zero=True)
            queue = self._work(f"queue{f}", hz * wz, np.int64)
            boxes, peaks, _, pols = _grow_kernel(
                z,
                lv.sign,
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
            ok = self._ship_shaped(w, h, shape, f)
            for i in np.flatnonzero(ok)[np.argsort(-peaks[ok])][: self.max_candidates]:
                x0, y0, x1, y1 = boxes[i]
                box = np.array([x0 * f, y0 * f, (x1 + 1) * f - 1, (y1 + 1) * f - 1], float)
                cands.append(_Candidate(box, k, float(peaks[i]), int(pols[i])))
        return cands

    def _censored(
        self, cands: list[_Candidate], around: list[_Candidate], lv0: _Level, floor: float
    ) -> list[_Candidate]:
        """Step 4b: the targets that the candidates hid. Around each candidate that passed
        the clutter test (``around``) the finest scale is computed again with censored
        training windows and noise cells (:func:`_censored_contrast_kernel`: the boxes
        of all ``cands``, grown by a pixel, left out), within a noise cell's rows and
        the windows' or a cell's reach in columns of it (luma only); components of the
        new statistic that hold a seed and stay clear of every candidate (``_CENSOR_GAP``
        rows above or below, ``guard`` columns beside) are new candidates (also through
        the clutter-map test, on the censored statistic), with these maps for their
        refinement. Measured (session 23, rendered lighting case,
        frame 50): the 7 × 2 px boat 18 px left of the ferry had ``z`` = 2.4 — the
        ferry in its right window and in its noise cell (σ 15 against the sea's 4–6) —,
        and 10.6 with both censored. Over the 24 rendered clips (8 cases × 3 renderings,
        session 22's horizons): the lighting boat is tracked in 408 of its 600 frames
        instead of 321 and crossing's sailboat in 576 instead of 418; the other six cases
        are unchanged to the last digit; boxes on no ship 1,198 → 1,200. The CLE rises
        with the hard frames it adds (lighting 2.59 → 2.93 %: the boat's white cabin is
        invisible in the glare; crossing 6.76 → 6.79 %). With a 3-px clearance beside a
        candidate too (instead of ``guard``), it boxed the end of a long hull that the
        CFAR's own shadow cut off as a ship of its own, and glint beside glint (boxes on
        no ship 1,251); merged with the other candidates, crossing's container ship took
        the ferry's fragments (seed 2: 14.0 → 18.7 %). Cost on the 1080p benchmark clip:
        about 1.7 ms a frame, 7 % of the detection (the passed candidates' neighbourhoods
        only)."""
        if not cands or lv0.planes is None:
            return []
        # the level's own planes: the work buffers may have been dropped since (_work)
        gs, b5 = lv0.planes
        H, W = gs.shape
        guard, flank = lv0.window
        keep = self._work("keep", (H, W), np.uint8)
        keep.fill(1)
        reach = max(guard + flank, self.cell[1])  # windows and noise cells it reaches
        for c in cands:
            x0, y0, x1, y1 = (int(v) for v in c.box)
            keep[max(0, y0 - 1) : y1 + 2, max(0, x0 - 1) : x1 + 2] = 0
        rects = []
        for c in around:
            x0, y0, x1, y1 = (int(v) for v in c.box)
            rects.append(
                [
                    max(0, y0 - self.cell[0]),
                    min(H, y1 + self.cell[0] + 1),
                    max(0, x0 - reach),
                    min(W, x1 + reach + 1),
                ]
            )
        # a new component must stay clear of every candidate: _CENSOR_GAP rows above
        # and below, ``guard`` columns beside (nearer on the same rows it is the end of
        # the candidate's hull that the CFAR's own shadow cut off)
        old = np.array([c.box for c in cands])
        near = old + np.array([-guard, -_CENSOR_GAP, guard, _CENSOR_GAP], float)
        pol = _POLARITY_CODE[self.polarity]
        maps: _Level | None = None
        out: list[_Candidate] = []
        for r0, r1, c0, c1 in _union_rects(rects):
            n, m = r1 - r0, c1 - c0
            hi, lo, d, c, tex = (np.empty((n, m), np.float32) for _ in range(5))
            _censored_contrast_kernel(
                gs, b5, keep, r0, r1, c0, c1, guard, flank, pol, 1.5 * flank, hi, lo, d, c, tex
            )
            sigma = np.maximum(_cell_noise(d, self.cell[0], self.cell[1], floor), tex)
            z = np.divide(c, sigma, out=c)
            z *= keep[r0:r1, c0:c1]  # a candidate's own pixels join no component
            sign = _NO_SIGN
            if pol == 0:
                sign = _polarity_bits(d)
            boxes, peaks, _, pols = _grow_kernel(
                z,
                sign,
                np.float32(self.threshold),
                self.border,
                np.float32(self.grow_threshold),
                np.zeros(n * m, np.uint8),
                np.empty(n * m, np.int64),
            )
            if boxes.shape[0] == 0:
                continue
            ii = cv2.integral((z > self.grow_threshold).view(np.uint8))
            found = []
            w, h = boxes[:, 2] - boxes[:, 0] + 1, boxes[:, 3] - boxes[:, 1] + 1
            for i in np.flatnonzero(self._ship_shaped(w, h, (H, W), 1)):
                box = boxes[i].astype(float)
                shifted = box + np.array([c0, r0, c0, r0], float)
                if any(_overlap(b, shifted) for b in near):
                    continue
                cand = _Candidate(box, 0, float(peaks[i]), int(pols[i]))
                if self._clutter_pass(cand, ii, z.shape):
                    cand.box = shifted
                    found.append(cand)
            if not found:
                continue
            if maps is None:  # the finest scale's maps, censored where a target was found
                maps = replace(
                    lv0,
                    bg_bright=lv0.bg_bright.copy(),
                    bg_dark=lv0.bg_dark.copy(),
                    sigma=lv0.sigma.copy(),
                    z=lv0.z.copy(),
                    sign=lv0.sign.copy(),
                )
            maps.bg_bright[r0:r1, c0:c1] = hi
            maps.bg_dark[r0:r1, c0:c1] = lo
            maps.sigma[r0:r1, c0:c1] = sigma
            maps.z[r0:r1, c0:c1] = z
            if pol == 0:
                maps.sign[r0:r1, c0:c1] = sign
            for cand in found:
                cand.maps = maps
            out += found
        return out

    def _wide(
        self,
        levels: list[_Level],
        band: NDArray,
        floor: float,
        fr: _Frame,
        cands: list[_Candidate],
    ) -> list[_Candidate]:
        """Targets wider than the noise cells (class docstring, step 4b): the coarser
        scales again, with the sea whose training windows hold a wide block of the finest
        scale (:func:`_wide_blocks`) left out of their noise cells and seeds only below
        the horizon. A component, grown past it, wider than the next finer scale's
        CFAR sees whole, of a ship's shape, at most ``_WIDE_ASPECT`` times wider than
        high, whose peak exceeds ``_WIDE_FACTOR`` times the threshold and that passes the
        clutter test at its own scale (ring without the candidates and the components
        that touch it: a dark stern or shadow beside a white hull is its own part) and
        that no candidate of its polarity spans, is a candidate with these maps, unless
        it is another target's echo (:meth:`_echo`)."""
        blocks = levels[0].blocks
        if blocks is None or not blocks.any():  # none on a frame without a wide target
            return []
        out: list[_Candidate] = []
        for k, lv in enumerate(levels[1:], start=1):
            f = lv.factor
            hk, wk = lv.z.shape
            share = cv2.resize(blocks.astype(np.float32), (wk, hk), interpolation=cv2.INTER_AREA)
            guard, flank = lv.window
            lw = self._level(lv.source, f, floor / f, guard, flank, fr, share > 0, suffix="w")
            # seeds lie on the sea; components grow past the horizon (a superstructure)
            cap = np.float32(self.threshold) * np.float32(0.999)
            sky = lw.z[: max(0, min(hk, math.floor(fr.hrow / f)))]
            np.minimum(sky, cap, out=sky)
            boxes, peaks, _, pols = _grow_kernel(
                lw.z,
                lw.sign,
                np.float32(self.threshold),
                -(-self.border // f),
                np.float32(self.grow_threshold),
                np.zeros(hk * wk, np.uint8),
                np.empty(hk * wk, np.int64),
            )
            if boxes.shape[0] == 0:
                continue
            w = (boxes[:, 2] - boxes[:, 0] + 1) * f
            h = (boxes[:, 3] - boxes[:, 1] + 1) * f
            ok = (
                self._ship_shaped(w, h, band.shape, f)
                & (w > (2 * self.guard + 1) * 3 ** (k - 1))
                & (w <= _WIDE_ASPECT * h)
                & (peaks > _WIDE_FACTOR * self.threshold)
            )
            grow = (lw.z > self.grow_threshold).view(np.uint8).copy()
            _paint_boxes(grow, cands, f)  # targets that passed are no clutter
            for i in np.flatnonzero(ok):
                x0, y0, x1, y1 = boxes[i]
                ring = grow.copy()
                for a0, b0, a1, b1 in boxes:  # itself and the components that touch it
                    if a0 <= x1 + 1 and a1 >= x0 - 1 and b0 <= y1 + 1 and b1 >= y0 - 1:
                        ring[b0 : b1 + 1, a0 : a1 + 1] = 0
                cand = _Candidate(boxes[i].astype(float), k, float(peaks[i]), int(pols[i]))
                if not self._clutter_pass(cand, cv2.integral(ring), lw.z.shape):
                    continue
                cand.box = np.array([x0 * f, y0 * f, (x1 + 1) * f - 1, (y1 + 1) * f - 1], float)
                cand.maps = lw
                spanned = any(
                    o.polarity & cand.polarity
                    and _overlap(o.box, cand.box)
                    and o.box[2] - o.box[0] >= 0.8 * (cand.box[2] - cand.box[0])
                    for o in cands + out
                )
                if not spanned:
                    out.append(cand)
        return [c for c in out if not self._echo(c, cands + out)]

    def _echo(self, c: _Candidate, targets: list[_Candidate]) -> bool:
        """Whether every seed of wide candidate ``c`` (``z`` above the threshold in its
        box, of its polarity) lies within guard + flank of the left or right edge with
        its one training window on a target of the other polarity
        (:func:`_one_sided_hits`): the sea beside that target, echoing it."""
        lv = c.maps
        f, (guard, flank) = lv.factor, lv.window
        held = np.zeros(lv.z.shape, np.uint8)
        _paint_boxes(held, [t for t in targets if not t.polarity & c.polarity], f, 1)
        if not held.any():
            return False
        x0, y0, x1, y1 = (int(v) // f for v in c.box)
        win = np.s_[y0 : y1 + 1, x0 : x1 + 1]
        seeds = lv.z[win] > self.threshold
        if lv.sign.shape == lv.z.shape:  # polarity "both": seeds of its own polarity
            seeds &= (lv.sign[win] & c.polarity) > 0
        return not (seeds & ~_one_sided_hits(held > 0, guard, flank)[win]).any()

    def _ship_shaped(
        self, w: NDArray, h: NDArray, shape: tuple[int, int], f: int
    ) -> NDArray[np.bool_]:
        """Which components of ``w × h`` working pixels (found at scale ``f``) a ship may
        be: at most ``max_size`` of the band ``shape`` and within ``max_aspect``, with a
        level pixel of slack."""
        wide, tall = self.max_aspect
        return (
            (w <= self.max_size * shape[1] + f)
            & (h <= self.max_size * shape[0] + f)
            & (w <= wide * h + f)
            & (h <= tall * w + f)
        )

    def _clutter_test(self, cands: list[_Candidate], lv0: _Level) -> list[_Candidate]:
        """Clutter-map threshold: with ``ρ`` the fraction of finest-scale pixels with
        ``z > grow_threshold`` in a ring around the candidate (its box grown by ``flank``
        columns and 8 rows each side, the box itself left out; 0.13 % for Gaussian
        noise, several % on glitter, whitecaps and textured land), a candidate is kept
        when ``z_peak > threshold · √(1 + ρ / clutter_rate)``. A candidate that fails
        but holds (at least half of) a finer candidate of its polarity that passed, one
        at most 4 times smaller and at least 15 % shorter — the same hull, whose ends
        the finer scale's CFAR windows do not show — is tried once more with the boxes
        of the candidates of its polarity that passed left out of its ring: a ship
        beside another is no clutter (the rendered meeting case, seed 1, frame 9: the
        ferry's whole-hull candidate failed on the workboat's pixels in its ring, and its
        box was the 24 px of its 40 that its finest scale sees). Without those limits a
        coarse candidate of glint or haze around a small boat, or a flat one under a
        ship's superstructure, passed too (lighting 4.09 → 9.06 %, crossing 7.95 →
        8.79 %, three renderings)."""
        if not cands or self.clutter_rate == 0:
            return cands
        grow = (lv0.z > self.grow_threshold).view(np.uint8)
        ii = cv2.integral(grow)
        passed = [self._clutter_pass(c, ii, grow.shape) for c in cands]
        for pol in (1, 2):
            clear = [c for i, c in enumerate(cands) if passed[i] and c.polarity & pol]
            failed = [
                i
                for i, c in enumerate(cands)
                if not passed[i]
                and c.polarity & pol
                and any(
                    d.level < c.level
                    and _frac_inside(d.box, c.box) >= 0.5
                    and _area(c.box) <= 4.0 * _area(d.box)
                    and c.box[2] - c.box[0] >= 1.15 * (d.box[2] - d.box[0])
                    for d in clear
                )
            ]
            if not failed or not clear:
                continue
            masked = grow.copy()
            _paint_boxes(masked, clear)
            ii_clear = cv2.integral(masked)
            for i in failed:
                passed[i] = self._clutter_pass(cands[i], ii_clear, grow.shape)
        return [c for c, ok in zip(cands, passed, strict=True) if ok]

    def _clutter_pass(self, c: _Candidate, ii: NDArray, shape: tuple[int, int]) -> bool:
        """Whether candidate ``c`` passes the clutter-map threshold with the ring's
        count from the integral image ``ii`` of the grow mask (:meth:`_clutter_test`)."""
        hz, wz = shape
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
        return c.peak > self.threshold * math.sqrt(1.0 + rho / self.clutter_rate)

    def _near_sea(
        self,
        c: _Candidate,
        fr: _Frame,
        mask: NDArray[np.bool_] | None,
        ends: tuple[float, float] | None,
        tol: float,
        heights: float = 2.0,
    ) -> bool:
        """Pre-filter before merging: a candidate whose bottom lies above the sea by more
        than ``tol`` plus ``heights`` times its own height (2: a ship's upper part) can
        be no ship (full-frame pixels)."""
        if mask is None and ends is None:
            return True
        x0, y0, x1, y1 = fr.box_to_work(c.box)
        h = (y1 - y0 + 1) * fr.sy
        u = 0.5 * (x0 + x1 + 1) * fr.sx - 0.5
        v = (y1 + 1) * fr.sy - 0.5
        return _in_sea(u, v, mask, ends, fr.shape, tol + heights * h)

    def _resolve_scales(self, cands: list[_Candidate], levels: list[_Level]) -> list[_Candidate]:
        """Coarse-to-fine arbitration: a coarse candidate narrow enough for the next finer
        scale gives way to the finer candidates it overlaps that hold its peak (a
        fragment beside it — a superstructure whose hull the finer scales lost — does not
        take its place); a wider one, or one whose peak no finer candidate holds,
        replaces the finer candidates that lie (at least half) inside it — of a shared polarity only
        (a dark hull inside a wide bright glint path stays)."""
        if len({c.level for c in cands}) < 2:
            return cands
        alive = [True] * len(cands)
        for i in sorted(range(len(cands)), key=lambda i: cands[i].level):
            ci = cands[i]
            if ci.level == 0 or not alive[i]:
                continue
            capacity = (2 * self.guard + 1) * 3 ** (ci.level - 1)
            width = ci.box[2] - ci.box[0] + 1
            finer = [
                j
                for j, c in enumerate(cands)
                if alive[j] and c.level < ci.level and c.polarity & ci.polarity
            ]
            over = [j for j in finer if _overlap(cands[j].box, ci.box)]
            if over:  # those holding its peak
                f = levels[ci.level].factor
                u, v = _peak_at(levels[ci.level].z, ci.box, f)
                over = [j for j in over if _holds(cands[j].box, u, v, f)]
            if width <= capacity and over:
                alive[i] = False
            else:
                for j in finer:
                    if _frac_inside(cands[j].box, ci.box) >= 0.5:
                        alive[j] = False
                        ci.peak = max(ci.peak, cands[j].peak)
        return [c for c, a in zip(cands, alive, strict=True) if a]

    def _mergeable(self, a: _Candidate, b: _Candidate) -> bool:
        """:meth:`_merge`'s rule for two candidates (inclusive boxes ``(x0, y0, x1, y1)``):
        near on one axis and overlapping on the other; of opposite polarities (one
        bright, one dark) only when stacked — the bright one above the dark one on shared
        columns, its top and bottom higher than the other's: a pale superstructure on a
        dark hull, not the bright glint beside, around or below a dark hull. (A dark part
        above a bright one was merged too up to session 16: looking into a low sun, a
        ferry's dark hull joined the glitter streak under it, and the streaks below that
        one, into one 215 × 129 px box on the rendered lighting case, seed 1, the ferry
        itself not boxed; a white hull under a dark deck-house is now two boxes.) Not a
        box that hangs below the other's bottom by half its height or more and shares
        under half of their smaller width and height with it: a nearer boat whose corner
        reaches a far ship's bottom rows — unless both are bright only (glitter)."""
        opposite = not a.polarity & b.polarity
        if a.box[1] + a.box[3] > b.box[1] + b.box[3]:
            a, b = b, a  # a the upper
        bright_on_top = a.polarity == 1
        bright_only = a.polarity == b.polarity == 1
        a, b = a.box, b.box
        hmin = min(a[3] - a[1], b[3] - b[1]) + 1
        wmin = min(a[2] - a[0], b[2] - b[0]) + 1
        gap = max(1.0, self.merge_gap * hmin)
        gx = max(a[0], b[0]) - min(a[2], b[2]) - 1
        gy = max(a[1], b[1]) - min(a[3], b[3]) - 1
        if opposite:
            return bool(bright_on_top and gx < 0 and gy <= gap and a[1] < b[1] and a[3] <= b[3])
        if (
            not bright_only
            and b[3] - a[3] >= 0.5 * (b[3] - b[1] + 1)
            and -gx < 0.5 * wmin
            and -gy < 0.5 * hmin
        ):
            # a nearer boat at a far ship's corner (the crossing case, seed 0, frames
            # 178-199: the 14 x 5 px boat, the container ship and the ferry were one
            # 107 x 31 px box). Glitter still merges: held together it is one large box
            # that no ship's track takes (split, lighting's second rendering: pieces
            # beside the ferry took its track, 4.41 -> 5.24 %)
            return False
        return bool((gx < 0 and gy <= gap) or (gy < 0 and gx <= gap) or max(gx, gy) < 1)

    def _merge(self, cands: list[_Candidate]) -> list[_Candidate]:
        """Merge the fragments of one ship (hull and superstructure, a hull cut by a wave):
        boxes that overlap on one axis with a gap of at most ``merge_gap`` × the smaller
        box height (at least one pixel) on the other, or that touch diagonally; of
        opposite polarities only when stacked (:meth:`_mergeable`)."""
        cands = list(cands)
        changed = True
        while changed and len(cands) > 1:
            changed = False
            for i in range(len(cands)):
                for j in range(i + 1, len(cands)):
                    if self._mergeable(cands[i], cands[j]):
                        a, b = cands[i].box, cands[j].box
                        box = np.concatenate([np.minimum(a[:2], b[:2]), np.maximum(a[2:], b[2:])])
                        level = min(cands[i].level, cands[j].level)
                        peak = max(cands[i].peak, cands[j].peak)
                        cands[i] = _Candidate(
                            box,
                            level,
                            peak,
                            cands[i].polarity | cands[j].polarity,
                            cands[i].maps or cands[j].maps,
                        )
                        del cands[j]
                        changed = True
                        break
                if changed:
                    break
        return cands

    def _refine(self, c: _Candidate, lv: _Level, fr: _Frame) -> list[_Object]:
        """Full-resolution objects of a candidate: per object its box (x, y, w, h), water-
        line point (u, v) [px] and area [px²]; none when nothing stands out.

        The objects are segmented against a background of their own (:meth:`_segment`)
        in a window around the candidate (half its width ``w`` on either side, at least
        8 px; a quarter of its height above and below, at least 4 px; the background's
        flanks from 1.5 w to 3.5 w beyond it, or what lies between the window and the
        frame's edge). An object that reaches the
        window's edge may be longer or taller than the candidate (a superstructure that
        stood out at a fine scale, the end of a long hull): the window is grown around
        it and the segmentation repeated (at most three times). Parts that still reach
        the window's edge are the background's own structure (a glint path, a wave
        crest or a coastline running on; a greatest-of CFAR does not see them either)
        and are dropped; the
        remaining parts that touch (a dark hull under a bright superstructure) are one
        object, unless it is no ship as a whole (:meth:`_ships`), when each part is tried
        alone (a dark hull touching a bright glint patch).
        """
        sx, sy = fr.sx, fr.sy
        H, W = fr.shape
        bx0, by0, bx1, by1 = fr.box_to_work(c.box)  # unsheared working pixels
        core = (
            max(0, math.floor(bx0 * sx)),
            max(0, math.floor(by0 * sy)),
            min(W, math.ceil((bx1 + 1) * sx)),
            min(H, math.ceil((by1 + 1) * sy)),
        )  # full-frame pixels [x0, x1) × [y0, y1)
        if core[2] - core[0] < 1 or core[3] - core[1] < 1:
            return []
        ext = core
        for _ in range(3):
            we, he = ext[2] - ext[0], ext[3] - ext[1]
            rx, ry = max(8, we // 2), max(4, he // 4 + 2)
            win = (
                max(0, ext[0] - rx),
                max(0, ext[1] - ry),
                min(W, ext[2] + rx),
                min(H, ext[3] + ry),
            )
            # the flanks: from 1.5 w to 3.5 w beyond the object, clear of a hull up to four
            # times as long as its superstructure was
            near, far = max(2 * rx, 3 * we // 2), max(4 * rx, 7 * we // 2)
            left = (max(0, ext[0] - far), max(0, ext[0] - near))
            right = (min(W, ext[2] + near), min(W, ext[2] + far))
            if left[1] - left[0] < 8:  # cut by the frame's edge: what lies beside the window
                left = (0, win[0])
            if right[1] - right[0] < 8:
                right = (win[2], W)
            flanks = (left, right)
            parts, absdiff, colour = self._segment(fr, lv, win, flanks, core)
            if not parts:
                return []
            boxes = np.array([_mask_extent(p) for p in parts])  # r0, r1, c0, c1
            r0, r1 = int(boxes[:, 0].min()), int(boxes[:, 1].max())
            c0, c1 = int(boxes[:, 2].min()), int(boxes[:, 3].max())
            if c1 - c0 + 1 > self.max_size * W or r1 - r0 + 1 > self.max_size * H:
                break  # too large for a ship already: no wider window
            # reaching the window's edge (not the frame's): perhaps more of it beyond
            edges = (win[1] > 0, win[3] < H, win[0] > 0, win[2] < W)
            last = (win[3] - win[1] - 1, win[2] - win[0] - 1)
            spill = (
                (r0 == 0 and edges[0])
                or (r1 == last[0] and edges[1])
                or (c0 == 0 and edges[2])
                or (c1 == last[1] and edges[3])
            )
            if not spill:
                break
            ext = (
                min(ext[0], win[0] + c0),
                min(ext[1], win[1] + r0),
                max(ext[2], win[0] + c1 + 1),
                max(ext[3], win[1] + r1 + 1),
            )
        inside = [
            p
            for p, b in zip(parts, boxes, strict=True)
            if not (b[0] == 0 and edges[0])
            and not (b[1] == last[0] and edges[1])
            and not (b[2] == 0 and edges[2])
            and not (b[3] == last[1] and edges[3])
        ]
        out: list[_Object] = []
        for group in _touching_groups(inside):
            found = self._ships(fr, win, sum(group[1:], group[0]), absdiff, colour)
            if found is None and len(group) > 1:  # no ship as a whole: its parts alone
                found = []  # (a dark hull touching a bright glint patch)
                for part in group:
                    found += self._ships(fr, win, part, absdiff, colour) or []
            out += found or []
        return out

    @staticmethod
    def _ships(
        fr: _Frame,
        win: tuple[int, int, int, int],
        mask: NDArray,
        absdiff: NDArray,
        colour: bool,
        keep: bool = False,
    ) -> list[_Object] | None:
        """Boxes, water-line points and areas of the ships in an object mask of the
        window ``win`` (:func:`_frame_ships`), from its pixels that are at least half
        covered: whose ``absdiff`` is at least half the largest within two pixels (the
        smoothing's halo is no object; a thin mast or a partly covered pixel of the
        hull's edge is, when more than half of it is covered), and at least a quarter of
        the object's median on that row (a faint pixel that is its own neighbourhood's
        largest — a wave trough run on from the hull's end — is no object either). None
        when it is no ship, unless ``keep``: then the whole mask with the bottom of its
        central columns as the water line."""
        r0, r1, c0, c1 = _mask_extent(mask)
        r0, c0 = max(0, r0 - 2), max(0, c0 - 2)
        m = mask[r0 : r1 + 3, c0 : c1 + 3]
        obj = np.where(m, absdiff[r0 : r1 + 3, c0 : c1 + 3], np.float32(0.0)).astype(np.float32)
        level = _row_median(obj, m)  # rows without object pixels: NaN, no level
        half = m & (obj >= 0.5 * cv2.dilate(obj, np.ones((5, 5), np.uint8)))
        half &= obj >= 0.25 * np.nan_to_num(level)[:, None]
        if half.any():
            mask = np.zeros_like(mask)
            mask[r0 : r1 + 3, c0 : c1 + 3] = half
        r0, r1, c0, c1 = _mask_extent(mask)
        X0, Y0 = win[0] + c0, win[1] + r0
        obj_box = mask[r0 : r1 + 1, c0 : c1 + 1]
        ships = _frame_ships(fr, obj_box, X0, Y0, colour)
        if not ships:
            if not keep:
                return None
            ships = [(0, obj_box.shape[1] - 1, 0, obj_box.shape[0] - 1, None, None, None)]
        out = []
        for sc0, sc1, sr0, sr1, u, v, low in ships:
            ship = obj_box[sr0 : sr1 + 1, sc0 : sc1 + 1]
            x, y = X0 + sc0 - 0.5, Y0 + sr0 - 0.5
            if u is None or v is None:  # no measurable hull/sea edge: the mask's bottom
                uu, vv = _waterline(ship)
                u, v = x + uu, y + vv
            w, h = float(sc1 - sc0 + 1), float(sr1 - sr0 + 1)
            ends = _subpixel_ends(fr, ship, X0 + sc0, Y0 + sr0)
            if ends is not None:  # the ends to a fraction of a pixel; u moves with them
                u += 0.5 * (ends[0] + ends[1]) - (x + 0.5 * w)
                x, w = ends[0], ends[1] - ends[0]
            if low is not None and low > y:
                # a ship's lowest point is on its water line: the box ends there, to a
                # fraction of a pixel (the smoothing's spill below a strong hull can
                # hold a half-covered row under it)
                h = float(low) - y
            else:  # the box holds its water line: a sub-pixel edge may lie in the row
                h = max(h, float(v) - y)  # below the last half-covered one
            out.append((x, y, w, h, u, v, float(np.count_nonzero(ship))))
        return out

    def _refine_mask(self, c: _Candidate, lv: _Level, fr: _Frame) -> list[_Object]:
        """``refine="mask"``: the objects of a candidate from its level's own contrast
        (class docstring, step 5): in the candidate's box plus a margin (a quarter of
        its height and the level's factor, at least two working pixels), the pixels
        whose noise-normalised contrast against the level's CFAR backgrounds (luma and
        chroma) exceeds 0.4 × its 95th percentile p over the candidate — or, where that is
        higher, the detection threshold itself, but at least 0.15 p (a superstructure
        five times fainter than its hull is still part of the ship) —, in the components
        that touch the candidate (:func:`_joined`); with both polarities, less the
        fainter pixels of the other polarity beside and under the candidate's own
        (:func:`_trim_other_polarity`), in what is still joined to it; then
        :meth:`_ships` (half-covered pixels, sub-pixel water line, ships whose water
        lines jump)."""
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
            return []
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
        sig = cv2.remap(lv.sigma, mx, my, **remap)  # in noise units, like z
        bright_res = dark_res = None
        if self.polarity == "bright":
            res = (g - hi) / sig
        elif self.polarity == "dark":
            res = (lo - g) / sig
        else:
            bright_res, dark_res = (g - hi) / sig, (lo - g) / sig
            res = np.maximum(bright_res, dark_res)
        chroma = False
        if lv.chroma and fr.colour is not None:
            luma = res.copy()
            np.maximum(res, _chroma_contrast(fr, lv, (gx0, gy0, gx1, gy1), inner, mx, my), out=res)
            chroma = bool(np.any(res > luma + 1e-6))
        # the candidate's own pixels (no margin)
        cx0 = max(0, math.floor(bx0 * sx) - fx0)
        cx1 = min(fx1 - fx0, math.ceil((bx1 + 1) * sx) - fx0)
        cy0 = max(0, math.floor(by0 * sy) - fy0)
        cy1 = min(fy1 - fy0, math.ceil((by1 + 1) * sy) - fy0)
        core = res[cy0:cy1, cx0:cx1]
        if core.size == 0:
            return []
        peak = _percentile(core, 95.0) if core.size >= 20 else float(core.max())
        if peak <= 0:
            return []
        # a pixel as strong as a detection belongs to the object even where a much
        # stronger part (a dark hull under a pale superstructure) sets the 95th
        # percentile; never below a fraction of it (the strong part's halo)
        thr = min(0.4 * peak, max(self.threshold, _REFINE_FLOOR * peak))
        own = (cy0, cy1, cx0, cx1)
        sel = _joined(res > thr, own)
        if sel is not None and bright_res is not None and dark_res is not None:
            trimmed = _trim_other_polarity(sel, bright_res, dark_res, thr, own)
            if trimmed is not sel:  # what is still joined to the candidate
                sel = _joined(trimmed, own)
        if sel is None:
            return []
        win = (fx0, fy0, fx1, fy1)
        return self._ships(fr, win, sel, np.maximum(res, 0.0), chroma, keep=True) or []

    def _segment(
        self,
        fr: _Frame,
        lv: _Level,
        inner: tuple[int, int, int, int],
        flanks: tuple[tuple[int, int], tuple[int, int]],
        core: tuple[int, int, int, int],
    ) -> tuple[list[NDArray[np.bool_]], NDArray, bool]:
        """Object parts in the full-frame region ``inner`` = (x0, y0, x1, y1) [px, x1/y1
        exclusive] around a candidate whose own pixels are ``core`` (same form).

        Background ``b``: per line parallel to the horizon, the medians of the flanks —
        the column ranges ``flanks`` (left, right; about :data:`_FLANK_SAMPLES` columns
        of each, :func:`_line_samples`, :func:`_flank_stats`) — linear in the column
        between them (:func:`_line_values`): the sea (or sky) on both sides of the
        object. Residual ``g − b`` smoothed by a 3 × 3 Gaussian (σ = 0.8 px), divided per
        row by the robust spread (1.4826 · MAD) of the flanks about their medians — the
        larger of the whole flanks' and that of the row's line and its neighbours (a
        horizon or cloud edge that the background does not follow exactly) — scaled by
        the smoothing's share of the noise (the ratio of the smoothed and unsmoothed
        residuals' spreads in the region): the statistic ``z``, bright (``z > 0``) and
        dark (``z < 0``) apart. For colour frames whose candidate stands
        out in chroma rather than luma, the level's chroma statistic joins in
        (``max(|z|, z_chroma)``, one part without polarity).

        Parts: per polarity (as configured), the 8-connected components of
        ``|z| ≥ max(grow_threshold, 0.4 · peak)`` that hold a pixel of the candidate
        with ``|z| ≥ max(threshold − 1, 0.5 · peak)``, ``peak`` the 95th percentile of
        ``|z|`` over the candidate's own pixels, plus the significant pieces of
        ``|z| ≥ max(grow_threshold, 0.2 · peak)`` attached to them (:meth:`_attach`: a
        superstructure or a mast of less contrast than the hull). Returns the parts
        (masks of ``inner``), the distance of each pixel from the background (``|g − b|``,
        or in (Y, Cr, Cb) where chroma joined in), whose half-covered pixels give an
        object's box, and whether it is a colour distance.
        """
        X0, Y0, X1, Y1 = inner
        nr, nc = Y1 - Y0, X1 - X0
        empty = np.zeros((0, 0), np.float32)
        if nr < 2 or nc < 2:
            return [], empty, False
        slope = 0.0  # the horizon's slope [frame rows per column]
        if fr.off is not None and fr.off.size > 1:
            slope = float(fr.off[-1] - fr.off[0]) / (fr.off.size - 1) * fr.sy / fr.sx
            if abs(slope) * (flanks[1][1] - flanks[0][0]) < 0.25:
                slope = 0.0
        cm = 0.5 * (X0 + X1 - 1)
        (la, lb), (ra_, rb_) = flanks
        lc = np.arange(la, lb, max(1, (lb - la) // _FLANK_SAMPLES))
        rc = np.arange(ra_, rb_, max(1, (rb_ - ra_) // _FLANK_SAMPLES))
        if lc.size + rc.size < 8:  # no room for flanks (a frame-wide object): the region
            lc, rc = np.arange(X0, X1, max(1, nc // _FLANK_SAMPLES)), np.zeros(0, int)
        cols = np.r_[lc, rc].astype(np.intp)
        samples = _line_samples(fr, Y0, nr, cols, slope * (cols - cm), colour=False)
        meds, spread_raw, sigma_raw = _flank_stats(samples, lc.size)
        xs = np.arange(X0, X1)
        dx = slope * (xs - cm)
        raw = fr.grey_crop(Y0, Y1, X0, X1)
        diff = raw - _line_values(meds, lc, rc, xs, dx)
        res = cv2.GaussianBlur(diff, (3, 3), 0.8, borderType=cv2.BORDER_REPLICATE)
        lo_v, hi_v = cv2.minMaxLoc(raw)[:2]
        floor = max(0.3 * fr.quantum, 1e-4 * (hi_v - lo_v), 1e-12)
        # the smoothing's share of the noise (estimated in the region, where the object
        # inflates both spreads alike), applied to the flanks' clean spreads
        kappa = min(1.0, _mad(res[::2, ::2]) / max(_mad(diff[::2, ::2]), 1e-12))
        sigma = max(kappa * sigma_raw, floor)
        line_sigma = np.maximum(kappa * spread_raw, sigma).astype(np.float32)
        zs = res * (1.0 / line_sigma)[:, None]  # signed
        pol = {"both": (1.0, -1.0), "bright": (1.0,), "dark": (-1.0,)}[self.polarity]
        zl = np.abs(zs) if len(pol) == 2 else np.maximum(pol[0] * zs, 0.0)
        ca, ra, cb, rb = core[0] - X0, core[1] - Y0, core[2] - X0, core[3] - Y0
        zlc = zl[ra:rb, ca:cb]
        if zlc.size == 0:
            return [], empty, False
        luma_peak = _percentile(zlc, 95.0) if zlc.size >= 20 else float(zlc.max())
        z, peak, chroma = zl, luma_peak, False
        if lv.chroma and fr.colour is not None:  # chroma, where it may carry the candidate
            zc_chroma = self._chroma_z(fr, lv, core)
            if zc_chroma.size and float(zc_chroma.max()) > 0.5 * float(zlc.max()):
                chroma = True
                z = np.maximum(zl, self._chroma_z(fr, lv, inner))
                zc = z[ra:rb, ca:cb]
                peak = _percentile(zc, 95.0) if zc.size >= 20 else float(zc.max())
        grow = max(self.grow_threshold, 0.2 * peak)
        seed = max(self.threshold - 1.0, 0.5 * peak)
        strict = max(self.grow_threshold, 0.4 * peak)
        if peak < seed:
            return [], empty, False
        luma = luma_peak >= 0.5 * peak  # luma carries the object
        planes = [np.maximum(p * zs, 0.0) for p in pol] if luma else [z]
        parts: list[NDArray[np.bool_]] = []
        for zp in planes:
            n, labels = cv2.connectedComponents((zp >= strict).view(np.uint8), connectivity=8)
            seeded = np.zeros(n, dtype=bool)
            seeded[labels[ra:rb, ca:cb][zp[ra:rb, ca:cb] >= seed]] = True
            seeded[0] = False
            if not seeded.any():
                continue
            sel = seeded[labels]
            if luma and grow < strict:
                sel = self._attach(zp, sel, grow, strict)
            n, labels = cv2.connectedComponents(sel.view(np.uint8), connectivity=8)
            parts += [labels == k for k in range(1, n)]
        if not parts or not chroma:  # luma shows it: its distance is luma's
            return parts, np.abs(diff), False
        # colour: the distance from the background in (Y, Cr, Cb), so that a hull of the
        # sea's luma but not its colour under a bright cabin is no less the ship's; only
        # where the parts are (and two pixels around)
        union = parts[0] if len(parts) == 1 else np.logical_or.reduce(parts)
        r0, r1, c0, c1 = _mask_extent(union)
        r0, c0, r1, c1 = max(0, r0 - 2), max(0, c0 - 2), min(nr, r1 + 3), min(nc, c1 + 3)
        ycc_s = _line_samples(fr, Y0, nr, cols, slope * (cols - cm), colour=True)
        ycc = fr.ycc_crop(Y0 + r0, Y0 + r1, X0 + c0, X0 + c1)
        dist = np.zeros((nr, nc), np.float32)
        part_d = diff[r0:r1, c0:c1]
        acc = part_d * part_d
        for ch in (1, 2):
            m_ch = _flank_stats(np.ascontiguousarray(ycc_s[:, :, ch]), lc.size)[0]
            bg_ch = _line_values(m_ch, lc, rc, xs[c0:c1], dx[c0:c1])[r0:r1]
            dc = ycc[:, :, ch] - bg_ch
            acc += dc * dc
        dist[r0:r1, c0:c1] = np.sqrt(acc)
        return parts, dist, True

    @staticmethod
    def _attach(z: NDArray, obj: NDArray[np.bool_], low: float, strict: float) -> NDArray:
        """``obj`` plus the pieces of ``z ≥ low`` attached to it that are significant as a
        whole, ``Σ (z − low) ≥ 2 · strict`` over the piece, not wholly under it and not
        reaching past its columns by more than an eighth of its width (2 px at least) —
        a superstructure, a mast or the end of a hull of less contrast than the rest
        joins; a few noise or clutter pixels next to the object, a wave crest, wake or
        reflection under its water line, or a wave trough running on beside it, do
        not."""
        n, labels = cv2.connectedComponents((z >= low).view(np.uint8), connectivity=8)
        hold = np.zeros(n, dtype=bool)
        hold[labels[obj]] = True
        hold[0] = False
        extra = hold[labels] & ~obj
        if not extra.any():
            return obj
        k, parts = cv2.connectedComponents(extra.view(np.uint8), connectivity=8)
        weight = np.bincount(parts.ravel(), weights=(z - low).ravel(), minlength=k)
        good = weight >= 2.0 * strict
        good[0] = False
        if good.any():
            rows = np.arange(obj.shape[0])[:, None]
            has = obj.any(axis=0)
            low_row = np.where(has, np.max(np.where(obj, rows, -1), axis=0), -1)
            rr, cc = np.nonzero(parts)
            pk = parts[rr, cc]
            # under the water line: every pixel below obj's lowest in its column
            above = (low_row[cc] < 0) | (rr <= low_row[cc])
            good &= np.bincount(pk, weights=above, minlength=k) > 0
            # running on beside it (a wave trough, a glint streak): past obj's columns
            cols = np.flatnonzero(has)
            slack = max(2, (cols[-1] - cols[0] + 1) // 8)
            out = (cc < cols[0] - slack) | (cc > cols[-1] + slack)
            good &= np.bincount(pk, weights=out, minlength=k) == 0
        return obj | good[parts]

    def _chroma_z(self, fr: _Frame, lv: _Level, win: tuple[int, int, int, int]) -> NDArray:
        """The chroma statistic of the finest level (class docstring, step 3), at the
        full-resolution pixels of the window ``win`` (its CFAR backgrounds and noise
        sampled there)."""
        X0, Y0, X1, Y1 = win
        H, W = fr.shape
        cw = (np.arange(X0, X1, dtype=np.float32) + 0.5) / fr.sx - 0.5  # working columns
        rw = (np.arange(Y0, Y1, dtype=np.float32) + 0.5) / fr.sy - fr.wtop  # band edge rows
        mx, my = np.meshgrid(cw, rw - 0.5)
        if fr.off is not None:
            shift = np.interp(cw, np.arange(fr.off.size), fr.off).astype(np.float32)
            my -= shift[None, :]
        gx0, gy0 = max(0, X0 - 1), max(0, Y0 - 1)
        gx1, gy1 = min(W, X1 + 1), min(H, Y1 + 1)
        inner = (slice(Y0 - gy0, Y1 - gy0), slice(X0 - gx0, X1 - gx0))
        return np.maximum(_chroma_contrast(fr, lv, (gx0, gy0, gx1, gy1), inner, mx, my), 0.0)


def _union_rects(rects: list[list[int]]) -> list[list[int]]:
    """Rectangles ``[r0, r1, c0, c1]`` (half-open) merged until none overlap: each result
    is the bounding rectangle of a group of overlapping ones."""
    out = [list(r) for r in rects]
    merged = True
    while merged:
        merged = False
        for i in range(len(out)):
            for j in range(i + 1, len(out)):
                a, b = out[i], out[j]
                if a[0] < b[1] and b[0] < a[1] and a[2] < b[3] and b[2] < a[3]:
                    out[i] = [min(a[0], b[0]), max(a[1], b[1]), min(a[2], b[2]), max(a[3], b[3])]
                    del out[j]
                    merged = True
                    break
            if merged:
                break
    return out


def _joined(mask: NDArray[np.bool_], core: tuple[int, int, int, int]) -> NDArray[np.bool_] | None:
    """The 8-connected components of ``mask`` that hold a pixel of ``core`` (r0, r1, c0,
    c1; ends exclusive), or None when none does."""
    n, labels = cv2.connectedComponents(mask.view(np.uint8), connectivity=8)
    r0, r1, c0, c1 = core
    touching = np.zeros(n, dtype=bool)
    touching[labels[r0:r1, c0:c1].ravel()] = True
    touching[0] = False
    if not touching.any():
        return None
    return touching[labels] if n > 2 else labels > 0


def _trim_other_polarity(
    sel: NDArray[np.bool_],
    bright: NDArray,
    dark: NDArray,
    thr: float,
    core: tuple[int, int, int, int],
) -> NDArray[np.bool_]:
    """An object mask without the pixels of the other polarity than the candidate's
    that lie beyond the columns of its own polarity's pixels or under their lowest
    one in a column, and stand out less than two thirds as much as its strongest
    pixel: a ship's parts of either contrast (a pale superstructure on a dark hull) lie
    within its length and above its water line, while a sunlit haze or glare band
    behind a dark hull — brighter than the CFAR background that the hull darkens
    around it — runs on beyond the hull's ends, and a glint streak (or a white hull's
    shadow) lies on the water under it.
    ``bright``, ``dark``: the polarities' contrasts (noise units) on the mask's grid;
    ``thr``: the mask's threshold; ``core``: the candidate's own rows and columns of
    that grid (r0, r1, c0, c1; ends exclusive), whose 95th percentiles of the two
    contrasts give its polarity. Returns ``sel`` itself when nothing is dropped."""
    r0, r1, c0, c1 = core
    cb, cd = bright[r0:r1, c0:c1], dark[r0:r1, c0:c1]
    if cb.size == 0 or not sel.any():
        return sel
    own_dark = _percentile(cd, 95.0) >= _percentile(cb, 95.0)
    own, other = (dark, bright) if own_dark else (bright, dark)
    mixed = sel & (other > own)  # the mask's pixels of the other polarity
    if not mixed.any():
        return sel
    own_px = sel & (own > thr) & ~mixed
    if not own_px.any():
        return sel
    cols = np.flatnonzero(own_px.any(axis=0))
    outside = np.ones(sel.shape, dtype=bool)
    outside[:, cols[0] : cols[-1] + 1] = False
    rows = np.arange(sel.shape[0])[:, None]
    low = np.where(own_px, rows, -1).max(axis=0)  # the own pixels' lowest row, per column
    outside |= (rows > low) & (low >= 0)
    weaker = other < _TRIM_RATIO * float(own[own_px].max())
    drop = mixed & weaker & outside
    return sel & ~drop if drop.any() else sel


def _chroma_contrast(
    fr: _Frame,
    lv: _Level,
    crop: tuple[int, int, int, int],
    inner: tuple[slice, slice],
    mx: NDArray,
    my: NDArray,
) -> NDArray:
    """The largest noise-normalised CFAR contrast of the chroma planes (Cr, Cb; class
    docstring, step 3) at full-resolution pixels: the frame's colour ``crop`` (x0, y0,
    x1, y1, one pixel of context for the smoothing) cut to ``inner``, against the finest
    level's chroma backgrounds and noise sampled at its working coordinates (mx, my)."""
    assert fr.colour is not None and lv.chroma is not None
    x0, y0, x1, y1 = crop
    ycc = fr.ycc_crop(y0, y1, x0, x1)
    ycc = cv2.GaussianBlur(ycc, (3, 3), 0.8, borderType=cv2.BORDER_REPLICATE)[inner]
    cx, cy = (mx + 0.5) / 2 - 0.5, (my + 0.5) / 2 - 0.5  # half-resolution planes
    remap = {"interpolation": cv2.INTER_LINEAR, "borderMode": cv2.BORDER_REPLICATE}
    out = np.full(mx.shape, -np.inf, np.float32)
    for ch_index, hc, lc, sc in lv.chroma:
        gc = ycc[:, :, ch_index]
        hi_c = cv2.remap(hc, cx, cy, **remap)
        lo_c = cv2.remap(lc, cx, cy, **remap)
        rc = np.maximum(gc - hi_c, lo_c - gc) / cv2.remap(sc, cx, cy, **remap)
        np.maximum(out, rc, out=out)
    return out


def _row_median(values: NDArray, mask: NDArray[np.bool_]) -> NDArray:
    """Median of each row's ``values`` where ``mask`` (NaN for a row without any):
    ``np.nanmedian`` of the masked rows from one sort, without its masked-array path."""
    n = mask.sum(axis=1)
    v = np.sort(np.where(mask, values, np.inf), axis=1)
    r = np.arange(v.shape[0])
    lo = v[r, np.maximum(n - 1, 0) // 2]
    hi = v[r, n // 2 - (n == 0)]
    return np.where(n > 0, 0.5 * (lo + hi), np.nan).astype(values.dtype)


def _mad(a: NDArray) -> float:
    """Robust spread ``1.4826 · median(|a − median(a)|)`` of the values ``a``."""
    a = a.ravel()
    return 1.4826 * float(np.median(np.abs(a - np.median(a))))


@njit(cache=True, nogil=True)
def _flank_kernel(samples, n_left, meds, spread):  # pragma: no cover - compiled
    """Per row of ``samples`` (rows, n): the median of the first ``n_left`` values and of
    the rest (NaN for an empty side) into ``meds`` (rows, 2), and the median absolute
    deviation of all values from their side's median into ``spread`` (rows,)."""
    rows, n = samples.shape
    buf = np.empty(n, np.float64)
    dev = np.empty(n, np.float64)
    for r in range(rows):
        for side in range(2):
            a = 0 if side == 0 else n_left
            b = n_left if side == 0 else n
            if b <= a:
                meds[r, side] = np.nan
                continue
            for j in range(a, b):
                buf[j - a] = samples[r, j]
            meds[r, side] = np.median(buf[: b - a])
            for j in range(a, b):
                dev[j] = abs(samples[r, j] - meds[r, side])
        spread[r] = np.median(dev[:n])


def _flank_stats(samples: NDArray, n_left: int) -> tuple[list[NDArray | None], NDArray, float]:
    """Per line of the flank samples (:func:`_line_samples`; the first ``n_left`` columns
    the left flank's): the two flanks' medians (None for an empty flank), the robust
    spread about them (1.4826 · MAD, the largest of each line's and its neighbours') and
    the robust spread of all samples (the background's noise) [units]."""
    rows = samples.shape[0]
    meds = np.empty((rows, 2))
    spread = np.empty(rows)
    _flank_kernel(np.ascontiguousarray(samples, dtype=np.float32), n_left, meds, spread)
    spread *= 1.4826
    overall = float(np.median(spread))
    spread = np.maximum(spread, np.maximum(np.r_[spread[1:], 0.0], np.r_[0.0, spread[:-1]]))
    out = [None if np.isnan(meds[0, k]) else meds[:, k].astype(np.float32) for k in (0, 1)]
    return out, spread, overall


def _line_samples(fr: _Frame, y0: int, nr: int, cols: NDArray, d: NDArray, colour: bool) -> NDArray:
    """Frame values on lines parallel to the horizon at the columns ``cols``: line ``r``
    (0 … nr − 1) meets column ``cols[j]`` at frame row ``y0 + r + d[j]`` (linear between
    rows, edge rows repeated). Grey (nr, n), or (Y, Cr, Cb) (nr, n, 3) with ``colour``."""
    H = fr.shape[0]
    lo = math.floor(float(d.min())) if d.size else 0
    hi = math.ceil(float(d.max())) + 1 if d.size else 1
    rows = np.clip(np.arange(y0 + lo, y0 + nr + hi), 0, H - 1)
    a, b = int(rows[0]), int(rows[-1]) + 1  # rows is a clipped run: a slice, repeated
    if colour:
        assert fr.colour is not None
        block = np.take(fr.colour[a:b], cols, axis=1)
        block = cv2.cvtColor(block, cv2.COLOR_BGR2YCrCb)
    else:
        block = np.take(fr.grey_rows(a, b), cols, axis=1)
    block = block[rows - a].astype(np.float32)
    if not np.any(d):
        return block[-lo : -lo + nr]
    pos = np.arange(nr, dtype=np.float32)[:, None] + (d - lo).astype(np.float32)[None, :]
    i0 = np.clip(np.floor(pos).astype(np.intp), 0, block.shape[0] - 2)
    f = np.clip(pos - i0, 0.0, 1.0)
    j = np.arange(cols.size)[None, :]
    if block.ndim == 3:
        f = f[:, :, None]
    return block[i0, j] * (1.0 - f) + block[i0 + 1, j] * f


def _line_values(
    meds: list[NDArray | None], lc: NDArray, rc: NDArray, xs: NDArray, d: NDArray
) -> NDArray:
    """The background (nr, len(xs)) at frame columns ``xs`` whose rows lie ``d`` below
    their lines' (see :func:`_line_samples`), from the per-line medians of the left
    flank (columns ``lc``) and the right one (``rc``): linear in the column between the
    flanks' centres (a horizontal gradient of the sea or sky — a glint path, haze — is
    followed; outside them it keeps the nearer flank's value); one flank, or flanks of
    fewer than four columns, give one value per line."""
    left, right = meds
    if left is None or right is None or lc.size < 4 or rc.size < 4:
        both = [m for m in meds if m is not None]
        left = right = both[0] if len(both) == 1 else 0.5 * (both[0] + both[1])
        t = np.zeros(xs.size, np.float32)
    else:
        cl, cr = float(lc.mean()), float(rc.mean())
        t = np.clip((xs - cl) / (cr - cl), 0.0, 1.0).astype(np.float32)
    nr = left.shape[0]
    lines = (left[:, None] + (right - left)[:, None] * t[None, :]).astype(np.float32)
    if not np.any(d):
        return lines
    cx = np.broadcast_to(np.arange(xs.size, dtype=np.float32)[None, :], lines.shape)
    cy = np.arange(nr, dtype=np.float32)[:, None] - d.astype(np.float32)[None, :]
    return cv2.remap(lines, cx, cy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)


def _distinct(
    rows: NDArray, polarity: NDArray, overlap: float = 0.7, wl_tol: float = 0.5
) -> NDArray[np.intp]:
    """Indices (in the given order) of the detections (rows of :data:`DETECTION_COLUMNS`)
    that are no part of another: taken largest box first, a detection is dropped when
    more than ``overlap`` of its box lies inside a kept box of a shared ``polarity``
    (bits: 1 bright, 2 dark, per row) and its water line is not more than
    ``wl_tol`` [px] below that one's (two candidates that refined to one ship, or a
    superstructure boxed alone; a ship in front of another has its own, lower, water
    line and stays, and so does a dark hull inside a bright glint path's box)."""
    order = np.argsort(-(rows[:, 2] * rows[:, 3]), kind="stable")
    keep: list[int] = []
    for i in order.tolist():
        x, y, w, h = rows[i, :4]
        dup = False
        for j in keep:
            X, Y, Wj, Hj = rows[j, :4]
            iw = min(x + w, X + Wj) - max(x, X)
            ih = min(y + h, Y + Hj) - max(y, Y)
            if (
                iw > 0
                and ih > 0
                and iw * ih > overlap * w * h
                and rows[i, 6] <= rows[j, 6] + wl_tol
                and polarity[i] & polarity[j]
            ):
                dup = True
                break
        if not dup:
            keep.append(i)
    return np.array(sorted(keep), dtype=np.intp)


def _subpixel_ends(
    fr: _Frame, ship: NDArray[np.bool_], fx0: int, fy0: int
) -> tuple[float, float] | None:
    """The left and right ends [frame px, pixel centres at integers] of a ship whose mask
    ``ship`` (its box's rows and columns) has its top-left pixel at frame pixel ``(fx0,
    fy0)``, to a fraction of a pixel; None where neither can be measured (an end that
    cannot keeps the mask's).

    The mask's ends are whole pixels (a pixel at least half covered is the ship's), so a
    distant ship's box stays put for frames while the ship moves a fraction of a pixel
    and then jumps by one. At each end, over the rows whose mask reaches that end's
    column (the ship's farthest point there: a bow's tip, not its taper): the
    background is the per-row median of :data:`_END_FLANK` columns beyond the coverage
    window (what lies beside that end: the sea, or the ship behind); each pixel's
    difference from it — luma, or (Y, Cr, Cb) projected on the ship's mean difference,
    so that noise averages out instead of adding up — averaged over the rows and
    divided by its median over the inner columns is the column's covered fraction
    ``f``. The ends are the coverage integrals ``x_l = c_0 + 1.5 − Σ_{c_0−2 … c_0+1} f``
    and ``x_r = c_1 − 1.5 + Σ_{c_1−1 … c_1+2} f`` (``c_0, c_1`` the mask's end columns):
    for an area-sampled end exactly its position, and a symmetric blur (the lens, the
    codec) moves the contrast across it without changing the integral — as the water
    line's (:func:`seawatch.vision.waterline._edge_waterline`). An end keeps the mask's
    where the frame's edge is too near, the integral's noise (four columns of the
    background's spread over the rows) would exceed :data:`_END_SIGMA` px, the
    background beside it is not flat (a column of it, or the window's outer one, a
    quarter of the level from it: another object, glint), or the integral lies more
    than a pixel from the mask's end. The project's own addition [NEW]."""
    nr, nc = ship.shape
    W = fr.shape[1]
    if nc < 3:
        return None
    lo = max(0, fx0 - 2 - _END_FLANK)  # the frame's columns lo … hi − 1 are read
    hi = min(W, fx0 + nc + 2 + _END_FLANK)
    if fr.colour is not None:
        img = fr.ycc_crop(fy0, fy0 + nr, lo, hi)
    else:
        img = fr.grey_crop(fy0, fy0 + nr, lo, hi)[:, :, None]
    ends = [fx0 - 0.5, fx0 + nc - 0.5]  # the mask's
    measured = False
    x0 = fx0 - lo  # the mask's first column in the crop
    for side in (0, 1):
        a = x0 - 2 if side == 0 else x0 + nc - 2  # the coverage window a … a + 3
        fa = a - _END_FLANK if side == 0 else a + 4  # the background beside the window
        if fa < 0 or fa + _END_FLANK > hi - lo:
            continue
        reach = np.ascontiguousarray(ship[:, 0 if side == 0 else -1])
        total = _end_kernel(img, reach, a, fa, _END_FLANK, x0 + 1, x0 + nc - 1, side, _END_SIGMA)
        if math.isnan(total):
            continue
        end = lo + (a + 3.5 - total if side == 0 else a - 0.5 + total)
        if abs(end - ends[side]) <= 1.0:
            ends[side], measured = end, True
    return (ends[0], ends[1]) if measured else None


@njit(cache=True, nogil=True)
def _end_kernel(img, reach, a, fa, nflank, i0, i1, side, max_sigma):  # pragma: no cover
    """Σ f over the coverage window ``a … a + 3`` of one end (:func:`_subpixel_ends`), or
    NaN where it cannot be measured: ``img`` (rows, cols, channels) float32, ``reach``
    the rows that reach the end, background columns ``fa … fa + nflank − 1``, inner
    columns ``i0 … i1 − 1``, ``side`` 0 left / 1 right, ``max_sigma`` the largest noise
    [px] of the end. Compiled: a handful of small medians per end, a few µs instead of
    the ~0.3 ms of numpy calls on arrays this small."""
    nch = img.shape[2]
    rows = np.flatnonzero(reach)
    n = rows.size
    ni = i1 - i0
    if n == 0 or ni < 1:
        return np.nan
    bg = np.empty((n, nch), np.float64)
    buf = np.empty(nflank, np.float64)
    for k in range(n):
        for ch in range(nch):
            for j in range(nflank):
                buf[j] = img[rows[k], fa + j, ch]
            bg[k, ch] = np.median(buf)
    mean = np.zeros(nch)
    for k in range(n):
        for c in range(i0, i1):
            for ch in range(nch):
                mean[ch] += img[rows[k], c, ch] - bg[k, ch]
    norm = 0.0
    for ch in range(nch):
        mean[ch] /= n * ni
        norm += mean[ch] * mean[ch]
    if norm == 0.0:
        return np.nan
    unit = mean / np.sqrt(norm)

    def column(c):  # the row mean of the projected difference in column c
        acc = 0.0
        for k in range(n):
            for ch in range(nch):
                acc += (img[rows[k], c, ch] - bg[k, ch]) * unit[ch]
        return acc / n

    cols = np.empty(ni)
    for c in range(i0, i1):
        cols[c - i0] = column(c)
    level = np.median(cols)
    flank = np.empty(n * nflank)
    fcol = np.empty(nflank)
    for j in range(nflank):
        acc = 0.0
        for k in range(n):
            v = 0.0
            for ch in range(nch):
                v += (img[rows[k], fa + j, ch] - bg[k, ch]) * unit[ch]
            flank[k * nflank + j] = v
            acc += v
        fcol[j] = acc / n
    spread = 1.4826 * np.median(np.abs(flank - np.median(flank)))
    # the integral's noise, four columns' worth, below a whole-pixel end's (0.29 px)
    if level <= 0.0 or 2.0 * spread / np.sqrt(n) > max_sigma * level:
        return np.nan
    f = np.empty(4)
    for j in range(4):
        f[j] = column(a + j) / level
    outer = f[0] if side == 0 else f[3]
    if abs(outer) >= 0.25 or np.abs(fcol).max() >= 0.25 * level:
        return np.nan  # no flat background beside it
    return f.sum()  # unclipped: noise and a ringing edge's lobes average out


def _mask_extent(mask: NDArray[np.bool_]) -> tuple[int, int, int, int]:
    """Inclusive extent ``(r0, r1, c0, c1)`` of a non-empty mask."""
    rr = np.flatnonzero(mask.any(axis=1))
    cc = np.flatnonzero(mask.any(axis=0))
    return int(rr[0]), int(rr[-1]), int(cc[0]), int(cc[-1])


def _touching_groups(parts: list[NDArray[np.bool_]]) -> list[list[NDArray[np.bool_]]]:
    """The groups of masks that touch (8-neighbours) or stack: overlapping columns
    with at most ``max(2, h/4)`` rows between them (``h`` the shorter part's height; a
    superstructure over its hull across a faint line, such as the horizon's), taken
    transitively."""
    if len(parts) < 2:
        return [[p] for p in parts]
    ext = [_mask_extent(p) for p in parts]
    grown = []
    for p, (r0, r1, _, _) in zip(parts, ext, strict=True):
        k = 1 + 2 * max(2, (r1 - r0 + 1) // 4)
        grown.append(cv2.dilate(p.view(np.uint8), np.ones((k, 3), np.uint8)) > 0)
    group = list(range(len(parts)))

    def root(i: int) -> int:
        while group[i] != i:
            group[i] = group[group[i]]
            i = group[i]
        return i

    for i in range(len(parts)):
        for j in range(i + 1, len(parts)):
            if root(i) != root(j) and np.any(grown[i] & parts[j]):
                group[root(j)] = root(i)
    out: dict[int, list[NDArray[np.bool_]]] = {}
    for i, p in enumerate(parts):
        out.setdefault(root(i), []).append(p)
    return list(out.values())


_FLANK_SAMPLES = 32
_END_FLANK = 4  # columns of background beside each end of a ship (_subpixel_ends)
_END_SIGMA = 0.25  # largest noise [px] of a sub-pixel end measured (_subpixel_ends)
"""Columns per flank (at most about) whose medians give a window's background."""
