"""Point marks from an image: adaptive thresholding, CA-CFAR, connected components.

The per-frame front end of the small-target track-before-detect (ALGORITHMS.md §8: the
"marks" ``Z_k``). A frame becomes a binary detection mask, the mask becomes connected
components, and each component becomes one mark: its intensity-weighted centroid, its
peak intensity and its area.

Two detectors, both on a training window of ``(2 h_o + 1)²`` pixels around the cell
under test (CUT), with an optional guard box of ``(2 h_g + 1)²`` pixels (CUT included)
excluded from the statistics:

* **Cell-averaging CFAR** (Richards, *Fundamentals of Radar Signal Processing*, 2nd ed.,
  §16.3; the image form of Stone Soup's ``feeder.image.CFAR``): with ``p = x`` or
  ``p = x²`` (``squared``, square-law detection) and ``p̄`` the mean of ``p`` over the
  ``N_t = (2 h_o + 1)² − (2 h_g + 1)²`` training cells (``h_o = train + guard``,
  ``h_g = guard``), the CUT is a detection when ``p / p̄ > alpha``.
* **Adaptive threshold** (local mean + k·σ): ``x > μ + k σ`` and ``x − μ > min_contrast``
  with μ, σ the mean and standard deviation of ``x`` over the window (guard box excluded
  when ``guard`` is given; otherwise the CUT is part of its own window).

Window sums are running column/row sums in one compiled pass (``numba``, a band of rows
per CPU thread, no full-frame temporaries besides the mask); the connected components
come from a union-find over the detected pixels only (8- or 4-connectivity, the
components of ``cv2.connectedComponents``). Sums are accumulated in float64, so integer
images (8/16-bit) give exactly the brute-force result (Stone Soup's
``expected_result_cfar.png`` is reproduced pixel for pixel).

Coordinates are pixels, ``row`` down and ``col`` right, origin at the centre of the
top-left pixel; intensities are in the image's own units (grey levels).
"""

from __future__ import annotations

import functools
import itertools
import math
import os
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Literal

import cv2
import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from seawatch._validation import FloatArray, integer, positive
from seawatch.vision.planes import image_array

__all__ = [
    "MARK_COLUMNS",
    "adaptive_mask",
    "cfar_mask",
    "extract_marks",
    "grayscale",
    "marks_from_mask",
]

MARK_COLUMNS = ("row", "col", "intensity", "area")
"""Columns of a marks array: centroid row and column [px], peak intensity [grey levels],
area [px]."""

Border = Literal["valid", "clip"]
Method = Literal["cfar", "adaptive"]

_MODE_CFAR_LINEAR = 0
_MODE_CFAR_SQUARED = 1
_MODE_ADAPTIVE = 2
_MIN_BAND_ROWS = 64


# --------------------------------------------------------------------------------------
# input handling
# --------------------------------------------------------------------------------------


def grayscale(image: ArrayLike) -> NDArray:
    """The grey image the detectors work on: uint8 for 8-bit input, float64 otherwise.

    (H, W) images keep their values (8/16-bit or other integers and floats are converted
    to float64 exactly); (H, W, 1) is squeezed; (H, W, 3) and (H, W, 4) are taken as
    OpenCV's BGR/BGRA order and converted with the ITU-R BT.601 luma weights
    ``0.299 R + 0.587 G + 0.114 B`` (``cv2.cvtColor`` for 8/16-bit and float32 images,
    which rounds integer results). A bool image becomes 0/1 uint8.

    Raises:
        ValueError: naming ``image`` for other shapes, complex or object dtypes, an
            empty image, or NaN/inf pixels.
    """
    arr = image_array(image)
    if arr.ndim == 3:
        if arr.dtype in (np.uint8, np.uint16, np.float32):
            code = cv2.COLOR_BGR2GRAY if arr.shape[2] == 3 else cv2.COLOR_BGRA2GRAY
            arr = cv2.cvtColor(np.ascontiguousarray(arr), code)
        else:
            b, g, r = (arr[:, :, i].astype(np.float64) for i in range(3))
            arr = 0.299 * r + 0.587 * g + 0.114 * b
    if arr.size == 0:
        raise ValueError(f"image: empty image of shape {arr.shape}")
    if arr.dtype.kind == "f" and not math.isfinite(float(np.sum(arr, dtype=np.float64))):
        raise ValueError("image: contains NaN or inf pixels")
    if arr.dtype != np.uint8:  # one compiled kernel for 8-bit video, one for the rest
        arr = arr.astype(np.float64, copy=False)
    return np.ascontiguousarray(arr)


def _border(border: str) -> bool:
    if border not in ("valid", "clip"):
        raise ValueError(f"border: expected 'valid' or 'clip', got {border!r}")
    return border == "clip"


def _check_window(shape: tuple[int, int], ho: int, clip: bool, what: str) -> None:
    size = 2 * ho + 1
    if not clip and (shape[0] < size or shape[1] < size):
        raise ValueError(
            f"image: a {shape[0]}×{shape[1]} image is smaller than the {size}×{size} "
            f"{what} window (use border='clip' or a smaller window)"
        )


# --------------------------------------------------------------------------------------
# compiled detection pass
# --------------------------------------------------------------------------------------


@njit(cache=True)
def _add_row(x, r, sign, s1, s2, mode):
    """Column sums of row r: ``s1 += sign p`` (p = x, or x² for squared CFAR) and, for the
    adaptive threshold, ``s2 += sign x²``."""
    W = x.shape[1]
    if mode == _MODE_CFAR_SQUARED:
        for c in range(W):
            v = np.float64(x[r, c])
            s1[c] += sign * (v * v)
    elif mode == _MODE_ADAPTIVE:
        for c in range(W):
            v = np.float64(x[r, c])
            s1[c] += sign * v
            s2[c] += sign * (v * v)
    else:
        for c in range(W):
            s1[c] += sign * np.float64(x[r, c])


@njit(cache=True)
def _prefix(a, b, Pa, Pb):
    """Row prefix sums ``Pa[c + 1] = sum(a[:c + 1])`` and the same for b (one loop, two
    independent dependency chains)."""
    acc_a = 0.0
    acc_b = 0.0
    Pa[0] = 0.0
    Pb[0] = 0.0
    for c in range(a.shape[0]):
        acc_a += a[c]
        acc_b += b[c]
        Pa[c + 1] = acc_a
        Pb[c + 1] = acc_b


@njit(cache=True)
def _bounds(c, ho, hg, W, clamp):
    """Column ranges ``[lo, hi)`` of the window and ``[glo, ghi)`` of the guard box."""
    if clamp:
        return max(0, c - ho), min(W, c + ho + 1), max(0, c - hg), min(W, c + hg + 1)
    return c - ho, c + ho + 1, c - hg, c + hg + 1


@njit(cache=True, error_model="numpy")
def _row_cfar(xr, c0, c1, clamp, ho, hg, nrb, nrg, PB, PG, squared, alpha, mr, br):
    """CA-CFAR test of columns ``[c0, c1)`` of one row: ``p / mean(p) > alpha``.

    The mask row is written for every column (a vectorisable loop; IEEE semantics, so a
    zero training mean gives ``p / 0 = inf``); background levels only for detections.
    Returns the number of detections.
    """
    W = xr.shape[0]
    count = 0
    for c in range(c0, c1):
        lo, hi, glo, ghi = _bounds(c, ho, hg, W, clamp)
        mean = ((PB[hi] - PB[lo]) - (PG[ghi] - PG[glo])) / (nrb * (hi - lo) - nrg * (ghi - glo))
        v = np.float64(xr[c])
        p = v * v if squared else v
        h = p / mean > alpha
        mr[c] = h
        count += h
    if count:
        for c in range(c0, c1):
            if mr[c]:
                lo, hi, glo, ghi = _bounds(c, ho, hg, W, clamp)
                n = nrb * (hi - lo) - nrg * (ghi - glo)
                mean = ((PB[hi] - PB[lo]) - (PG[ghi] - PG[glo])) / n
                br[c] = math.sqrt(max(mean, 0.0)) if squared else mean
    return count


@njit(cache=True, error_model="numpy")
def _row_adaptive(xr, c0, c1, clamp, ho, hg, nrb, nrg, P, k, min_contrast, mr, br):
    """Adaptive test ``x > mu + k sigma`` and ``x - mu > min_contrast`` of columns
    ``[c0, c1)`` of one row (P: prefix sums of x and x² for window and guard box)."""
    W = xr.shape[0]
    PB1, PB2, PG1, PG2 = P[0], P[1], P[2], P[3]
    k2 = k * k
    count = 0
    for c in range(c0, c1):
        lo, hi, glo, ghi = _bounds(c, ho, hg, W, clamp)
        n = nrb * (hi - lo) - nrg * (ghi - glo)
        mu = ((PB1[hi] - PB1[lo]) - (PG1[ghi] - PG1[glo])) / n
        m2 = ((PB2[hi] - PB2[lo]) - (PG2[ghi] - PG2[glo])) / n
        var = max(m2 - mu * mu, 0.0)
        d = np.float64(xr[c]) - mu
        # x > mu + k sigma  <=>  d > 0 and d² > k² sigma² (k >= 0): no square root
        h = (d > 0.0) & (d * d > k2 * var) & (d > min_contrast)
        mr[c] = h
        count += h
        br[c] = mu
    return count


@njit(cache=True, nogil=True)
def _band(x, r_start, r_stop, ho, hg, clip, mode, alpha, k, min_contrast, mask, bg, counts):
    """Detection over rows ``[r_start, r_stop)``; writes mask, background and row counts.

    Column sums cover rows ``[r - ho, r + ho]`` (big window) and ``[r - hg, r + hg]``
    (guard box), clipped to the image, updated by one row in and one row out per image
    row; the window sums along a row come from prefix sums of the column sums. ``hg < 0``
    means no guard box (its sums stay zero). The window sums of integer images are exact
    (float64 sums of integers below 2**53).
    """
    H, W = x.shape
    guard = hg >= 0
    hgc = max(hg, 0)
    adaptive = mode == _MODE_ADAPTIVE
    squared = mode == _MODE_CFAR_SQUARED
    col = np.zeros((4, W))  # column sums: big p|x, big x², guard p|x, guard x²
    P = np.zeros((4, W + 1))  # their prefix sums along the row
    lev = np.empty(W)
    c_lo, c_hi = (0, W) if clip else (ho, W - ho)
    inner_lo = max(c_lo, ho)
    inner_hi = max(inner_lo, min(c_hi, W - ho))
    # rows of the first window except its last one (added at the top of the loop)
    for r in range(max(0, r_start - ho), min(H, r_start + ho)):
        _add_row(x, r, 1.0, col[0], col[1], mode)
    if guard:
        for r in range(max(0, r_start - hg), min(H, r_start + hg)):
            _add_row(x, r, 1.0, col[2], col[3], mode)
    ranges = [(inner_lo, inner_hi, False)]
    if clip:
        ranges.append((c_lo, min(inner_lo, c_hi), True))
        ranges.append((inner_hi, c_hi, True))
    for r in range(r_start, r_stop):
        if r + ho < H:
            _add_row(x, r + ho, 1.0, col[0], col[1], mode)
        if guard and r + hg < H:
            _add_row(x, r + hg, 1.0, col[2], col[3], mode)
        nrb = min(H, r + ho + 1) - max(0, r - ho)
        nrg = min(H, r + hg + 1) - max(0, r - hg) if guard else 0
        _prefix(col[0], col[2], P[0], P[2])
        if adaptive:
            _prefix(col[1], col[3], P[1], P[3])
        n = 0
        for c0, c1, clamp in ranges:
            if adaptive:
                n += _row_adaptive(
                    x[r], c0, c1, clamp, ho, hgc, nrb, nrg, P, k, min_contrast, mask[r], lev
                )
            else:
                n += _row_cfar(
                    x[r], c0, c1, clamp, ho, hgc, nrb, nrg, P[0], P[2], squared, alpha,
                    mask[r], lev,
                )  # fmt: skip
        if n:
            for c in range(c_lo, c_hi):
                if mask[r, c]:
                    bg[r, c] = lev[c]
        counts[r] = n
        if r - ho >= 0:
            _add_row(x, r - ho, -1.0, col[0], col[1], mode)
        if guard and r - hg >= 0:
            _add_row(x, r - hg, -1.0, col[2], col[3], mode)


def _run(
    x: NDArray, ho: int, hg: int, clip: bool, mode: int, alpha: float, k: float, mc: float
) -> tuple[NDArray[np.uint8], FloatArray, NDArray[np.int64]]:
    """Mask (uint8 0/1), background level (valid where the mask is set), detections per row.

    The rows are split into bands run on a thread pool (the kernel releases the GIL).
    """
    H = x.shape[0]
    r_lo, r_hi = (0, H) if clip else (ho, H - ho)
    bands = max(1, min(_threads(), (r_hi - r_lo) // _MIN_BAND_ROWS))
    mask = np.zeros(x.shape, np.uint8)
    bg = np.empty(x.shape)  # written only where the mask is set
    counts = np.zeros(H, np.int64)
    edges = np.linspace(r_lo, r_hi, bands + 1).astype(int)
    jobs = [
        (x, int(a), int(e), ho, hg, clip, mode, alpha, k, mc, mask, bg, counts)
        for a, e in itertools.pairwise(edges)
        if a < e
    ]
    if len(jobs) == 1:
        _band(*jobs[0])
    else:
        list(_pool().map(lambda job: _band(*job), jobs))
    return mask, bg, counts


def _threads() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


@functools.cache
def _pool() -> ThreadPoolExecutor:
    return ThreadPoolExecutor(max_workers=_threads(), thread_name_prefix="seawatch-marks")


Detection = tuple[NDArray[np.uint8], FloatArray, NDArray[np.int64]]


def _cfar(
    x: NDArray, train: int, guard: int, alpha: float, squared: bool, border: str
) -> Detection:
    t = integer("train", train, 1)
    g = integer("guard", guard, 0)
    a = positive("alpha", alpha)
    clip = _border(border)
    _check_window(x.shape, t + g, clip, "CFAR")
    mode = _MODE_CFAR_SQUARED if squared else _MODE_CFAR_LINEAR
    return _run(x, t + g, g, clip, mode, a, 0.0, 0.0)


def _adaptive(
    x: NDArray, window: int, k: float, guard: int | None, min_contrast: float, border: str
) -> Detection:
    if (
        isinstance(window, bool)
        or not isinstance(window, int | np.integer)
        or window < 3
        or window % 2 == 0
    ):
        raise ValueError(f"window: expected an odd integer >= 3, got {window!r}")
    ho = int(window) // 2
    hg = -1
    if guard is not None:
        hg = integer("guard", guard, 0)
        if hg >= ho:
            raise ValueError(
                f"guard: the guard box ({2 * hg + 1} px) must be smaller than the window "
                f"({window} px)"
            )
    kk = positive("k", k, allow_zero=True)
    mc = positive("min_contrast", min_contrast, allow_zero=True)
    clip = _border(border)
    _check_window(x.shape, ho, clip, "adaptive-threshold")
    return _run(x, ho, hg, clip, _MODE_ADAPTIVE, 0.0, kk, mc)


def cfar_mask(
    image: ArrayLike,
    *,
    train: int = 10,
    guard: int = 4,
    alpha: float = 4.0,
    squared: bool = True,
    border: Border = "valid",
) -> NDArray[np.bool_]:
    """Cell-averaging CFAR detection mask (module docstring; Richards 2014 §16.3).

    A pixel is a detection when ``p / p̄ > alpha`` with ``p = x²`` (``squared``) or
    ``p = x``, ``p̄`` the mean of ``p`` over the training cells: the
    ``(2 (train + guard) + 1)²`` window minus the ``(2 guard + 1)²`` guard box. (The
    linear form assumes a non-negative image.)

    Args:
        image: (H, W) grey image (8/16-bit integer or float) or (H, W, 3|4) BGR(A).
        train: training band width [px] on each side of the guard box (>= 1).
        guard: guard half-size [px] (>= 0; 0 excludes only the CUT itself).
        alpha: threshold factor on the power (squared) or amplitude ratio (> 0).
        squared: square-law detection (compare powers instead of amplitudes).
        border: ``"valid"``: only pixels whose whole window lies inside the image are
            tested (the standard CA-CFAR; a band of ``train + guard`` px is never
            detected); ``"clip"``: windows are clipped at the edges and the mean taken
            over the training cells that remain.

    Returns:
        Bool mask of shape (H, W).
    """
    x = grayscale(image)
    return _cfar(x, train, guard, alpha, squared, border)[0].view(np.bool_)


def adaptive_mask(
    image: ArrayLike,
    *,
    window: int = 31,
    k: float = 4.0,
    guard: int | None = None,
    min_contrast: float = 0.0,
    border: Border = "clip",
) -> NDArray[np.bool_]:
    """Adaptive-threshold detection mask ``x > μ + k σ`` (module docstring).

    Args:
        image: (H, W) grey image or (H, W, 3|4) BGR(A).
        window: odd side of the square statistics window [px] (>= 3).
        k: threshold in local standard deviations (>= 0).
        guard: half-size [px] of a box around the CUT excluded from μ and σ (the box
            must be smaller than the window); ``None``: the whole window, CUT included.
        min_contrast: also require ``x − μ > min_contrast`` [grey levels] (>= 0), so a
            flat patch (σ = 0) does not detect pixels a hair above μ.
        border: ``"clip"`` (default: statistics over the part of the window inside the
            image) or ``"valid"`` (only pixels whose whole window fits).

    Returns:
        Bool mask of shape (H, W).
    """
    x = grayscale(image)
    return _adaptive(x, window, k, guard, min_contrast, border)[0].view(np.bool_)


# --------------------------------------------------------------------------------------
# connected components and marks
# --------------------------------------------------------------------------------------


def _connectivity(connectivity: int) -> int:
    if connectivity not in (4, 8):
        raise ValueError(f"connectivity: expected 4 or 8, got {connectivity!r}")
    return int(connectivity)


@njit(cache=True)
def _label_pixels(mask, counts, eight):
    """Connected components of the set pixels, by union-find over the pixel list.

    Pixels are visited in raster order (only rows with ``counts > 0``); each is joined
    with its set neighbours W and N (and NW, NE for 8-connectivity) through ``last[c]``,
    the latest set pixel of column c. A NW neighbour hidden by an overwritten ``last``
    entry is the W pixel's N neighbour, so it is joined through W. Components are
    numbered 0, 1, … in the raster order of their first pixel (the components of
    ``cv2.connectedComponents``; OpenCV numbers 8-connected ones in 2×2-block order).

    Returns:
        (rows, cols, labels, n_components) of the set pixels.
    """
    H, W = mask.shape
    total = 0
    for r in range(H):
        total += counts[r]
    rr = np.empty(total, np.int64)
    cc = np.empty(total, np.int64)
    parent = np.empty(total, np.int64)
    last = np.full(W, -1, np.int64)
    n = 0
    for r in range(H):
        if counts[r] == 0:
            continue
        for c in range(W):
            if not mask[r, c]:
                continue
            rr[n] = r
            cc[n] = c
            parent[n] = n
            for dc in (-1, 0, 1):
                cn = c + dc
                if cn < 0 or cn >= W:
                    continue
                j = last[cn]
                if j < 0:
                    continue
                if dc == -1 and rr[j] == r:
                    pass  # W neighbour
                elif rr[j] != r - 1 or (not eight and dc != 0):
                    continue  # not adjacent (or a diagonal with 4-connectivity)
                # union, keeping the smaller index (the earlier pixel) as the root
                a = j
                while parent[a] != a:
                    parent[a] = parent[parent[a]]
                    a = parent[a]
                b = n
                while parent[b] != b:
                    b = parent[b]
                if a < b:
                    parent[b] = a
                elif b < a:
                    parent[a] = b
            last[c] = n
            n += 1
    labels = np.empty(total, np.int64)
    k = 0
    for i in range(total):
        root = i
        while parent[root] != root:
            root = parent[root]
        if root == i:
            labels[i] = k
            k += 1
        else:
            labels[i] = labels[root]
    return rr, cc, labels, k


def _components(
    x: NDArray,
    mask: NDArray[np.uint8],
    level: FloatArray | None,
    counts: NDArray[np.int64] | None,
    connectivity: int,
    min_area: int,
    max_area: int | None,
) -> FloatArray:
    """Label the mask's connected components and reduce each one to a mark.

    The components are those of ``cv2.connectedComponents``, found by union-find on the
    set pixels only (rows without detections are skipped) and ordered by their first
    pixel in raster order. Centroid weights are ``max(x − level, 0)``
    (background-subtracted intensity) where a background ``level`` is known, else
    ``x − min(x) + 1`` over the detected pixels; a component whose weights sum to zero
    gets its plain pixel centroid.
    """
    if counts is None:
        counts = np.count_nonzero(mask, axis=1).astype(np.int64)
    rr, cc, lab, n = _label_pixels(mask, counts, connectivity == 8)
    if n == 0:
        return np.empty((0, 4))
    v = x[rr, cc].astype(np.float64)
    if level is not None:
        w = np.maximum(v - level[rr, cc], 0.0)
    else:
        w = v - v.min() + 1.0
    # offsets from each component's first pixel keep the sums small (a one-pixel mark is
    # exactly at its pixel); labels are numbered in order of first pixel
    first = np.flatnonzero(np.r_[True, lab[1:] > np.maximum.accumulate(lab)[:-1]])
    r0 = rr[first].astype(np.float64)
    c0 = cc[first].astype(np.float64)
    dr = rr - r0[lab]
    dc = cc - c0[lab]
    area = np.bincount(lab, minlength=n).astype(np.float64)
    sw = np.bincount(lab, weights=w, minlength=n)
    swr = np.bincount(lab, weights=w * dr, minlength=n)
    swc = np.bincount(lab, weights=w * dc, minlength=n)
    mr = np.bincount(lab, weights=dr, minlength=n)
    mc = np.bincount(lab, weights=dc, minlength=n)
    peak = np.full(n, -np.inf)
    np.maximum.at(peak, lab, v)
    weighted = sw > 0.0
    safe_sw = np.where(weighted, sw, 1.0)
    row = r0 + np.where(weighted, swr / safe_sw, mr / area)
    col = c0 + np.where(weighted, swc / safe_sw, mc / area)
    out = np.column_stack([row, col, peak, area])
    keep = out[:, 3] >= min_area
    if max_area is not None:
        keep &= out[:, 3] <= max_area
    return np.ascontiguousarray(out[keep])


def _areas(min_area: int, max_area: int | None) -> tuple[int, int | None]:
    lo = integer("min_area", min_area, 1)
    if max_area is None:
        return lo, None
    hi = integer("max_area", max_area, 1)
    if hi < lo:
        raise ValueError(f"max_area: expected >= min_area = {lo}, got {hi}")
    return lo, hi


def marks_from_mask(
    image: ArrayLike,
    mask: ArrayLike,
    *,
    connectivity: int = 8,
    min_area: int = 1,
    max_area: int | None = None,
) -> FloatArray:
    """Marks of a given detection mask: one per connected component.

    Args:
        image: the (H, W) grey or (H, W, 3|4) BGR(A) image the mask was made from.
        mask: (H, W) bool/0-1 mask (any non-zero pixel is a detection).
        connectivity: 8 (default) or 4 neighbours.
        min_area, max_area: keep components with ``min_area <= area <= max_area`` [px].

    Returns:
        (M, 4) float array with columns ``MARK_COLUMNS``: centroid (row, col) [px],
        weighted by ``x − min(x) + 1`` over the detected pixels, peak intensity, area.
    """
    x = grayscale(image)
    m = np.asarray(mask)
    if m.shape != x.shape:
        raise ValueError(f"mask: expected shape {x.shape} (the image's), got {m.shape}")
    m8 = np.ascontiguousarray(m != 0).view(np.uint8)
    lo, hi = _areas(min_area, max_area)
    return _components(x, m8, None, None, _connectivity(connectivity), lo, hi)


def extract_marks(
    image: ArrayLike,
    method: Method = "cfar",
    *,
    connectivity: int = 8,
    min_area: int = 1,
    max_area: int | None = None,
    **detector: Any,
) -> FloatArray:
    """Point marks of one frame: detection mask, connected components, centroids.

    ALGORITHMS.md §8 input ``Z_k``; the detectors are described in the module docstring.

    Args:
        image: (H, W) grey image (uint8, uint16, other integers or float) or an
            (H, W, 3|4) BGR(A) colour image (converted to grey, :func:`grayscale`).
        method: ``"cfar"`` (cell-averaging CFAR, options of :func:`cfar_mask`: ``train``,
            ``guard``, ``alpha``, ``squared``, ``border``) or ``"adaptive"`` (local mean
            + k σ, options of :func:`adaptive_mask`: ``window``, ``k``, ``guard``,
            ``min_contrast``, ``border``).
        connectivity: 8 (default) or 4 neighbours for the connected components.
        min_area, max_area: keep components of ``min_area <= area <= max_area`` px.
        **detector: the detector options above (defaults as in the mask functions).

    Returns:
        (M, 4) float array, columns ``MARK_COLUMNS`` = (row, col, intensity, area):
        the centroid [px] weighted by the background-subtracted intensity
        ``max(x − b, 0)`` (b: the training mean for linear CFAR, the RMS of the training
        cells for squared CFAR, μ for the adaptive threshold; a component with zero total
        weight gets its plain pixel centroid), the peak grey level of the component and
        its area [px]. Rows are in the raster order of each component's first pixel.
        A frame without detections gives shape (0, 4).

    Raises:
        ValueError: naming the argument for a bad image, bad or unknown options, or an
            image smaller than the window with ``border="valid"``.
    """
    x = grayscale(image)
    conn = _connectivity(connectivity)
    lo, hi = _areas(min_area, max_area)
    if method == "cfar":
        allowed, func = _CFAR_OPTIONS, _cfar
    elif method == "adaptive":
        allowed, func = _ADAPTIVE_OPTIONS, _adaptive
    else:
        raise ValueError(f"method: expected 'cfar' or 'adaptive', got {method!r}")
    unknown = sorted(set(detector) - set(allowed))
    if unknown:
        raise ValueError(
            f"{unknown[0]}: not an option of method={method!r}; options: {', '.join(allowed)}"
        )
    mask, level, counts = func(x, **{**allowed, **detector})
    return _components(x, mask, level, counts, conn, lo, hi)


_CFAR_OPTIONS: dict[str, Any] = {
    "train": 10,
    "guard": 4,
    "alpha": 4.0,
    "squared": True,
    "border": "valid",
}
_ADAPTIVE_OPTIONS: dict[str, Any] = {
    "window": 31,
    "k": 4.0,
    "guard": None,
    "min_contrast": 0.0,
    "border": "clip",
}
