"""The water line of a ship: where its hull meets the sea, to a fraction of a pixel.

Issue 6, "Ship detection": the water-line point of a box is what stage two ranges from
(seed 000 eqs. 1–5). Read from an object mask and the frame: per hull column, the
coverage integral of the intensity step between hull and sea (the edge of a step blurred
by any symmetric kernel, to a fraction of a pixel), a Theil–Sen line through the
columns, and the split of an object whose columns' water lines jump (two ships, one in
front of the other) by water-line level and hull colour. Used by the classical detector's
candidate refinement (:mod:`seawatch.vision.detect`) and, through
:func:`waterline_points`, by any detector that gives boxes only
(:mod:`seawatch.vision.external`). The per-column loops are numba kernels (the numpy forms
were call overhead on a few values per column; ``tests/vision/test_detect_kernels.py``
checks each against its numpy form).

Pixels as in :mod:`seawatch.vision.detect`: the pixel in row r and column c covers
``[c − ½, c + ½] × [r − ½, r + ½]``.
"""

from __future__ import annotations

import functools
import itertools
import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from seawatch._validation import FloatArray
from seawatch.vision.planes import _gray

if TYPE_CHECKING:
    from seawatch.vision.detect import _Frame

__all__ = ["waterline_points"]


_WL_BELOW = 6
"""Rows of sea under an object's lowest mask pixel that :func:`_edge_waterline` reads."""

_WL_RAGGED = 1.0
"""Largest robust spread [px] of a ship's per-column water-line edges about their line:
a hull meets the sea along a straight (or gently bending) edge; a patch of sun glitter,
a whitecap or a cloud's bottom does not."""

_WL_MIN_COLUMNS = 16
"""Hull columns from which an object without a measurable water line is no ship."""


@njit(cache=True, nogil=True)
def _mid3(a, b, c):  # pragma: no cover - compiled
    """The middle one of three values (what ``np.median`` of the three gives, for values
    that are not NaN)."""
    return max(min(a, b), min(max(a, b), c))


@njit(cache=True, nogil=True)
def _median_f32(a):  # pragma: no cover - compiled
    """``float(np.median(a))`` of a non-empty float32 array (sorted in place): the middle
    value, or the float32 mean of the two middle ones, as numpy computes it."""
    a.sort()
    h = a.size // 2
    if a.size % 2 == 1:
        return np.float64(a[h])
    return np.float64((a[h - 1] + a[h]) / np.float32(2.0))


@njit(cache=True, nogil=True)
def _sea_levels(g, cols, bottom):  # pragma: no cover - compiled
    """Per column ``cols[j]`` of a float32 (H, W, C) crop whose lowest mask row is
    ``bottom[j]``: the sea's level, the middle of rows ``b + 3 … b + 5`` (clipped to the
    crop), (n, C); and every one of those rows' deviation from it, (3 n C,) — for the
    sea's noise. Shared by the edge and hull-contrast kernels."""
    H = g.shape[0]
    nch = g.shape[2]
    n = cols.size
    level = np.empty((n, nch), np.float32)
    dev = np.empty(3 * n * nch, np.float32)
    k = 0
    for j in range(n):
        c = cols[j]
        b = bottom[j]
        r3, r4, r5 = min(b + 3, H - 1), min(b + 4, H - 1), min(b + 5, H - 1)
        for ch in range(nch):
            s0, s1, s2 = g[r3, c, ch], g[r4, c, ch], g[r5, c, ch]
            m = _mid3(s0, s1, s2)
            level[j, ch] = m
            dev[k] = abs(s0 - m)
            dev[k + 1] = abs(s1 - m)
            dev[k + 2] = abs(s2 - m)
            k += 3
    return level, dev


@njit(cache=True, nogil=True)
def _column_edges_kernel(g, obj, quantum):  # pragma: no cover - compiled
    """:func:`_column_edges` on a float32 (H, W, C) crop ``g`` and its (H, W) mask.

    Compiled because the numpy form ran a dozen gathers, stacks and medians of a few
    values per object (about 0.8 ms per object, most of it call overhead). It repeats
    numpy's float32 arithmetic step by step (channel sums left to right, as numpy's sum
    over a short last axis; the 4 σ test in float32, as numpy compares a float32 array
    with a Python float), so the edges are the same numbers.
    """
    H, W, nch = g.shape
    n = 0
    for c in range(W):
        for r in range(H):
            if obj[r, c]:
                n += 1
                break
    cols = np.empty(n, np.int64)
    bottom = np.empty(n, np.int64)
    top = np.empty(n, np.int64)
    edge = np.empty(n, np.float64)
    if n == 0:
        return cols, bottom, top, edge
    j = 0
    for c in range(W):
        t = -1
        for r in range(H):
            if obj[r, c]:
                t = r
                break
        if t < 0:
            continue
        b = t
        for r in range(H - 1, t - 1, -1):
            if obj[r, c]:
                b = r
                break
        cols[j] = c
        top[j] = t
        bottom[j] = b
        j += 1
    # sea level per column: the middle of rows b + 3 … b + 5; σ from all their deviations
    i_s, dev = _sea_levels(g, cols, bottom)
    sigma = max(1.4826 * _median_f32(dev), quantum, 1e-6)
    weak_below = np.float32((4.0 * sigma) ** 2 * nch)
    i_h = np.empty(nch, np.float32)
    axis = np.empty(nch, np.float32)
    for j in range(n):
        c = cols[j]
        b = bottom[j]
        t = top[j]
        start = b - 1  # the transition window: rows b - 1 ... b + 2
        n_in = int(start - 1 >= t) + int(start - 2 >= t) + int(start - 3 >= t)
        ra = min(max(start - 1, 0), H - 1)
        rb = min(max(start - 2, 0), H - 1)
        rc = min(max(start - 3, 0), H - 1)
        for ch in range(nch):
            a0, a1, a2 = g[ra, c, ch], g[rb, c, ch], g[rc, c, ch]
            if n_in >= 3:
                i_h[ch] = _mid3(a0, a1, a2)
            elif n_in == 2:
                i_h[ch] = np.float32(0.5) * (a0 + a1)
            else:
                i_h[ch] = a0
        if n_in == 0:  # no mask row above the window: the most contrasted mask pixel
            pick = 0
            best = np.float32(0.0)
            for kk in range(3):
                rr = b - kk
                if rr >= t:
                    ri = min(max(rr, 0), H - 1)
                    acc = np.float32(0.0)
                    for ch in range(nch):
                        e = g[ri, c, ch] - i_s[j, ch]
                        acc = e * e if ch == 0 else acc + e * e
                    dist = np.sqrt(acc)
                else:
                    dist = np.float32(-1.0)
                if kk == 0 or dist > best:
                    best = dist
                    pick = kk
            ri = min(max(b - pick, 0), H - 1)
            for ch in range(nch):
                i_h[ch] = g[ri, c, ch]
            start = b - pick
        norm2 = np.float32(0.0)
        for ch in range(nch):
            axis[ch] = i_h[ch] - i_s[j, ch]
            sq = axis[ch] * axis[ch]
            norm2 = sq if ch == 0 else norm2 + sq
        if norm2 < weak_below:
            edge[j] = np.nan
            continue
        for ch in range(nch):
            axis[ch] = axis[ch] / norm2
        e_c = np.float64(start) - 0.5
        for kk in range(6):  # window rows start … b + 2 (at most 6)
            r = start + kk
            if r > b + 2:
                continue
            ri = min(max(r, 0), H - 1)
            cov = np.float32(0.0)
            for ch in range(nch):
                p = (g[ri, c, ch] - i_s[j, ch]) * axis[ch]
                cov = p if ch == 0 else cov + p
            e_c += np.float64(min(max(cov, np.float32(0.0)), np.float32(1.0)))
        edge[j] = e_c
    return cols, bottom, top, edge


def _column_edges(
    raw: NDArray, obj: NDArray[np.bool_], quantum: float = 0.0
) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Per column of an object mask: the column, its lowest and highest mask rows and its
    sub-pixel hull/sea edge [px, rows of ``raw``] (NaN where too faint to measure; see
    :func:`_edge_waterline`). ``raw`` is the unsmoothed (H, W) grey or (H, W, C) colour
    crop under the mask (rows past it repeat its last row). For colour, each pixel is
    projected on the axis from the sea's colour to the hull's, ``(c − c_s)·(c_h − c_s) /
    |c_h − c_s|²`` (linear in the hull's coverage of the pixel, like the grey level).
    Compiled: :func:`_column_edges_kernel`."""
    g = raw if raw.dtype == np.float32 else raw.astype(np.float32)
    if g.ndim == 2:
        g = g[:, :, None]
    return _column_edges_kernel(
        np.ascontiguousarray(g), np.ascontiguousarray(obj, dtype=np.bool_), float(quantum)
    )


@njit(cache=True, nogil=True)
def _theil_sen_kernel(x, y, u, sub):  # pragma: no cover - compiled
    """:func:`_theil_sen` for at least two points, ``sub`` the indices of the points
    whose pairwise slopes count. Compiled because the numpy form (index pairs, fancy
    indexing, three medians) cost about 0.3 ms a line in call overhead, for a few
    hundred pairs; the same float64 operations, so the same numbers."""
    m = sub.size
    slopes = np.empty(m * (m - 1) // 2, np.float64)
    k = 0
    for i in range(m):
        xi = x[sub[i]]
        yi = y[sub[i]]
        for j in range(i + 1, m):
            dx = x[sub[j]] - xi
            if dx != 0:
                slopes[k] = (y[sub[j]] - yi) / dx
                k += 1
    slope = np.median(slopes[:k]) if k > 0 else 0.0
    r = np.empty(x.size, np.float64)
    for i in range(x.size):
        r[i] = y[i] - slope * (x[i] - u)
    v = np.median(r)
    return v, slope, 1.4826 * np.median(np.abs(r - v))


@functools.lru_cache(maxsize=256)
def _theil_sen_subset(n: int) -> NDArray[np.int64]:
    """Indices of the at most 24 evenly spread points of ``n`` whose pairwise slopes
    :func:`_theil_sen` takes (read-only, cached per ``n``)."""
    sub = np.linspace(0, n - 1, 24).round().astype(np.int64) if n > 24 else np.arange(n)
    sub.flags.writeable = False
    return sub


def _theil_sen(x: NDArray, y: NDArray, u: float) -> tuple[float, float, float]:
    """The Theil–Sen line through ``(x, y)`` (median of the pairwise slopes of at most 24
    evenly spread points; median intercept): its value at ``u``, its slope and the
    robust spread of the residuals about it (1.4826 · MAD). Compiled:
    :func:`_theil_sen_kernel`."""
    n = x.size
    if n < 2:
        return float(y[0]), 0.0, 0.0
    v, slope, spread = _theil_sen_kernel(
        np.ascontiguousarray(x, dtype=np.float64),
        np.ascontiguousarray(y, dtype=np.float64),
        float(u),
        _theil_sen_subset(n),
    )
    return float(v), float(slope), float(spread)


def _theil_sen_at(x: NDArray, y: NDArray, u: float) -> float:
    """Value at ``u`` of the Theil–Sen line through ``(x, y)`` (:func:`_theil_sen`)."""
    return _theil_sen(x, y, u)[0]


def _edge_waterline(
    raw: NDArray, obj: NDArray[np.bool_], quantum: float = 0.0
) -> tuple[float, float] | None:
    """Sub-pixel water-line point ``(u, v)`` [px] of one object, relative to the centre of
    the top-left pixel of ``raw``; None when the hull/sea edge is too weak to measure.

    ``raw`` is the unsmoothed grey crop and ``obj`` the object mask on it (same shape),
    with :data:`_WL_BELOW` rows under the mask's lowest pixel (rows past the crop repeat
    its last row). Hull columns: those whose lowest mask pixel ``b_c`` lies in the lowest
    30 % of the object (masts, sails and superstructure stop higher). Per hull column:

    * sea level ``I_s`` = median of rows ``b_c + 3 … b_c + 5``; hull level ``I_h`` = the
      median of the mask rows among ``b_c − 2 … b_c − 4`` (the hull just above the
      transition window ``r_s = b_c − 1 … b_c + 2``; two of three rows are hull when a
      superstructure stands on a hull of four rows); a column of two mask rows or fewer
      takes its most contrasted mask pixel as ``I_h`` and starts the window there;
    * the edge is the coverage integral across the transition,
      ``e_c = r_s − 1/2 + Σ_{r = r_s … b_c + 2} clip((g_r − I_s) / (I_h − I_s), 0, 1)``:
      for an area-sampled step edge it is the edge's position exactly, and a symmetric
      blur (lens, codec) moves intensity across the edge without changing the integral —
      unlike the bottom of a thresholded mask, which moves with the threshold, the blur
      and the pixel grid;
    * columns whose contrast ``|I_h − I_s|`` is under 4 σ (σ = 1.4826 · MAD of the sea
      rows about their column levels, at least ``quantum``) are left out.

    The water line is a Theil–Sen line through the kept ``(c, e_c)`` (median of pairwise
    slopes, median intercept: a hull seen at an angle slopes, and an occluding hull or a
    wave crest under a minority of the columns does not move it), evaluated at ``u``, the
    middle of the hull columns' extent (midship, for a hull seen side-on). None when
    fewer than two columns, or fewer than a quarter of the hull columns, are kept.
    """
    if not obj.any():
        return None
    return _hull_waterline(*_column_edges(raw, obj, quantum))


def _hull_waterline(
    cols: NDArray, bottom: NDArray, top: NDArray, edge: NDArray
) -> tuple[float, float] | None:
    """The water-line point of :func:`_edge_waterline` from the per-column arrays of
    :func:`_column_edges` (hull columns, Theil–Sen line at their middle)."""
    rb = int(bottom.max())
    hull = bottom >= rb - max(1, round(0.3 * (rb - int(top.min()) + 1)))
    u = 0.5 * (float(cols[hull][0]) + float(cols[hull][-1]))
    keep = hull & np.isfinite(edge)
    n = int(keep.sum())
    if n < max(2, 0.25 * int(hull.sum())):
        return None
    return u, _theil_sen_at(cols[keep].astype(np.float64), edge[keep], u)


@njit(cache=True, nogil=True)
def _level_breaks_kernel(e, jump):  # pragma: no cover - compiled
    """The breaks of :func:`_waterline_levels` along measured edges ``e`` [px] (the
    measured columns in order), and the jump ``J`` [px] they pass. Compiled because the
    numpy form (running medians, a MAD, a Python loop over the columns) was call
    overhead; the same float64 operations, so the same numbers."""
    n = e.size
    em = e.copy()
    for i in range(1, n - 1):
        em[i] = _mid3(e[i - 1], e[i], e[i + 1])
    d = np.empty(n - 1, np.float64)
    for i in range(n - 1):
        d[i] = e[i + 1] - e[i]
    noise = 1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(2.0)
    J = max(jump, 4.0 * noise)
    # between columns i and i + 1: the medians of the three edges after and before
    ext = np.empty(n + 4, np.float64)
    ext[0] = ext[1] = em[0]
    ext[2 : n + 2] = em
    ext[n + 2] = ext[n + 3] = em[n - 1]
    med = np.empty(n + 2, np.float64)  # centred, j = -1 … n
    for i in range(n + 2):
        med[i] = _mid3(ext[i], ext[i + 1], ext[i + 2])
    step = np.empty(n - 1, np.float64)
    for i in range(n - 1):
        step[i] = abs(med[i + 3] - med[i])
    breaks = np.empty(n - 1, np.int64)
    nb = 0
    for i in range(n - 1):
        if step[i] >= J:
            top = step[max(0, i - 2)]
            for k in range(max(0, i - 2) + 1, min(n - 1, i + 3)):
                top = max(top, step[k])
            if step[i] == top:
                breaks[nb] = i
                nb += 1
    return breaks[:nb], J


def _waterline_levels(
    cols: NDArray,
    edge: NDArray,
    jump: float = 1.0,
    hull: NDArray | None = None,
    sigma: float = 0.0,
    jump_in_front: float = 0.8,
) -> list[NDArray] | None:
    """Columns of the ships in one object mask whose water line jumps: two ships at
    different ranges, one in front of the other or side by side (the farther one's water
    line is higher in the image). None for one ship.

    Along the columns with a measured edge (``edge`` [px], NaN where none), a break is
    where the medians of the three (running-median-smoothed) edges before and after
    differ by at least ``J = max(jump, 4 σ)`` (σ the edges' noise, from the MAD of their
    differences), one per transition — also across columns without a measured edge
    between them: the sea between two ships side by side, where the break belongs (a
    gap was once no break, and the break fell one column into the next ship: the
    ferry of the rendered meeting case took the workboat's first column and the sea
    before it, its box 8 px long); ``jump`` = 1 px: a hull whose darker stern is
    drawn a pixel lower stays one ship in 99 % of the demo's frames, the ships of the
    rendered meeting and overtaking cases at 960×540 (1.1–1.3 px apart) split in 77 %
    and 68 % of theirs (0.8 px: 96 % of the demo's frames, 86 % and 100 %). Levels are
    the runs between breaks of at least four columns whose Theil–Sen slope is at most
    0.25 px per column (flat: a single hull's water line slopes, bends and rises to a
    raked bow, but has no second flat level); levels within ``J / 2`` of each other
    belong to one ship (the two visible ends of a ship behind a nearer one). Returns one
    column-index array (into ``cols``) per ship of at least ``max(6, n / 4)`` columns
    (``n`` measured columns: no ship is split off a hull's end), or None when there is
    only one. With ``hull`` (the hull's level per column, :func:`_column_edges`), the
    ships' hulls must also differ — by at least ``max(8 σ, 0.08 × the hulls' typical
    contrast)`` (``sigma`` the noise): one hull whose drawn water line steps by a pixel
    (a sloping edge rendered without anti-aliasing) stays one ship.

    A smaller jump, ``jump_in_front`` = 0.8 px, splits a ship seen in front of another's
    middle: the farther level on both sides of the nearer one's columns, which no single
    hull draws (its stern steps at one end). In the rendered overtaking case (1.0–1.1 px
    apart) the near ship is then boxed (IoU ≥ 0.5) in 177 of 200 frames instead of 143;
    the demo's boxes are unchanged. Two levels side by side keep ``jump``: at 0.8 px the
    demo's one hull split in 21 of 261 frames (3 at 1 px) and its tracker made 3 ID
    switches instead of 1.
    """
    found = _split_levels(cols, edge, jump, hull, sigma)
    if found is not None or jump_in_front >= jump:
        return found
    found = _split_levels(cols, edge, jump_in_front, hull, sigma)
    if found is None:
        return None
    # the smaller jump only for a ship in front of another's middle: the far ship's
    # level on both sides of the near one's columns
    order = sorted(range(len(found)), key=lambda k: float(np.median(edge[found[k]])))
    for a, far in enumerate(order):
        for near in order[a + 1 :]:
            c_far, c_near = cols[found[far]], cols[found[near]]
            if c_far.min() < c_near.min() and c_far.max() > c_near.max():
                return found
    return None


def _split_levels(
    cols: NDArray, edge: NDArray, jump: float, hull: NDArray | None, sigma: float
) -> list[NDArray] | None:
    """:func:`_waterline_levels` for one jump ``jump`` [px]."""
    ok = np.flatnonzero(np.isfinite(edge))
    n = ok.size
    if n < 9:
        return None
    c, e = cols[ok], edge[ok]
    found, J = _level_breaks_kernel(np.ascontiguousarray(e, dtype=np.float64), float(jump))
    breaks = found.tolist()
    if not breaks:
        return None
    runs = []
    for a, b in itertools.pairwise([0, *[k + 1 for k in breaks], n]):
        if b - a >= 4:  # a level: four columns or more, flat
            x = c[a:b].astype(np.float64)
            if abs(_theil_sen(x, e[a:b], x[0])[1]) <= 0.25:
                runs.append((a, b))
    if len(runs) < 2:
        return None
    levels = sorted((float(np.median(e[a:b])), a, b) for a, b in runs)
    groups: list[list[tuple[int, int]]] = [[(levels[0][1], levels[0][2])]]
    last = levels[0][0]
    for lev, a, b in levels[1:]:
        if lev - last < 0.5 * J:
            groups[-1].append((a, b))
        else:
            groups.append([(a, b)])
        last = lev
    out = [ok[np.concatenate([np.arange(a, b) for a, b in g])] for g in groups]
    out = [g for g in out if g.size >= max(6, 0.25 * n)]
    if len(out) < 2:
        return None
    if hull is not None:  # two ships: two hulls, of two colours or brightnesses
        levels_h = np.array([np.median(hull[g], axis=0) for g in out])
        norm = np.sqrt(np.sum(np.reshape(hull[ok], (ok.size, -1)) ** 2, axis=1))
        spread = max(8.0 * sigma, 0.08 * float(np.median(norm)))
        apart = [
            np.sqrt(np.sum((levels_h[i] - levels_h[j]) ** 2)) >= spread
            for i in range(len(out))
            for j in range(i + 1, len(out))
        ]
        if not all(apart):
            return None
    return out


@njit(cache=True, nogil=True)
def _hull_contrast_kernel(rgb, cols, bottom):  # pragma: no cover - compiled
    """Per column ``cols[j]`` of a float32 (H, W, C) crop whose lowest mask row is
    ``bottom[j]``: the hull's level less the sea's (the middle of rows ``b − 3, b − 2,
    b − 2`` less that of rows ``b + 3 … b + 5``, rows clipped to the crop) and the sea
    rows' noise ``1.4826 · median |sea − its column's level|`` [units]. Compiled because
    the numpy form (six gathers, a stack and a median per object) was call overhead; the
    same float32 operations, so the same numbers."""
    H = rgb.shape[0]
    nch = rgb.shape[2]
    sea, dev = _sea_levels(rgb, cols, bottom)
    hull = np.empty((cols.size, nch), np.float32)
    for j in range(cols.size):
        c = cols[j]
        b = bottom[j]
        h3, h2 = min(max(b - 3, 0), H - 1), min(max(b - 2, 0), H - 1)
        for ch in range(nch):
            hull[j, ch] = _mid3(rgb[h3, c, ch], rgb[h2, c, ch], rgb[h2, c, ch]) - sea[j, ch]
    return hull, 1.4826 * _median_f32(dev)


def _line_low(v: float, slope: float, at: float, cols: NDArray) -> float:
    """Lowest point (largest row) [px] of the line ``v + slope · (c − at)`` over the
    columns ``cols`` (ascending): at the first or the last of them."""
    return v + max(slope * (float(cols[0]) - at), slope * (float(cols[-1]) - at))


# one ship of an object mask (:func:`_frame_ships`): its columns c0, c1 and rows r0, r1
# (mask pixels, inclusive), water-line point u, v and lowest water-line point [frame px]
_ShipSpan = tuple[int, int, int, int, float | None, float | None, float | None]


def _frame_ships(
    fr: _Frame, obj: NDArray[np.bool_], x0: int, y0: int, colour: bool = False
) -> list[_ShipSpan]:
    """The ships of an object mask whose top-left pixel is frame pixel ``(x0, y0)``, read
    from the full-resolution grey frame: per ship ``(c0, c1, r0, r1, u, v, low)``, its
    columns and rows (inclusive, mask pixels), its water-line point and the lowest point
    of its water line over the columns whose edge was measured (the silhouette's bottom)
    [frame px] (None when too faint; :func:`_edge_waterline`). One ship unless the water line jumps
    (:func:`_waterline_levels`): then per ship its columns' span, the rows of its columns
    and the water line of its columns. None at all when the object is no ship: its
    water-line edges scatter about their line by more than :data:`_WL_RAGGED` (sun
    glitter, whitecaps), or it has at least :data:`_WL_MIN_COLUMNS` hull columns and
    fewer than a quarter of them show a hull/sea edge."""
    h, w = obj.shape
    y1 = min(fr.shape[0], y0 + h + _WL_BELOW)
    if colour and fr.colour is not None:  # (Y, Cr, Cb): a hull may differ in colour only
        raw = fr.ycc_crop(y0, y1, x0, x0 + w)
    else:
        raw = fr.grey_crop(y0, y1, x0, x0 + w)
    mask = np.zeros(raw.shape[:2], dtype=bool)
    mask[:h] = obj
    cols, bottom, top, edge = _column_edges(raw, mask, fr.quantum)
    # the hull's colour (Y, Cr, Cb; grey for a grey frame) per column, from the sea's
    if fr.colour is not None and not colour:
        rgb = fr.ycc_crop(y0, y1, x0, x0 + w)
    else:
        rgb = raw if raw.ndim == 3 else raw[:, :, None]
    hull, noise = _hull_contrast_kernel(np.ascontiguousarray(rgb), cols, bottom)
    groups = _waterline_levels(cols, edge, hull=hull, sigma=max(noise, 0.5 * fr.quantum))
    if groups is None:
        rb = int(bottom.max())
        hull = bottom >= rb - max(1, round(0.3 * (rb - int(top.min()) + 1)))
        keep = hull & np.isfinite(edge)
        n_hull = int(hull.sum())
        if int(keep.sum()) < max(2, 0.25 * n_hull):
            if n_hull >= _WL_MIN_COLUMNS:
                return []  # a large object without a water line: not a ship
            return [(0, w - 1, 0, h - 1, None, None, None)]
        u = 0.5 * (float(cols[hull][0]) + float(cols[hull][-1]))
        v, slope, ragged = _theil_sen(cols[keep].astype(np.float64), edge[keep], u)
        if ragged > _WL_RAGGED:
            return []
        low = _line_low(v, slope, u, cols[keep])
        return [(0, w - 1, 0, h - 1, x0 + u, y0 + v, y0 + low)]
    # a ship's columns are runs of the object's adjacent columns, not across a gap of
    # sea: a level's stray columns in another run (where it holds under a quarter of
    # what it holds in its main run) are another ship's, whose bow's edge lay on this
    # level (the rendered meeting case, seed 1, frame 0: the ferry's box reached over
    # the 10-px gap to the workboat's first column, 52.8 px for its 39.5)
    run = np.concatenate(([0], np.cumsum(np.diff(cols) > 1)))
    groups = [_main_runs(g, run) for g in groups]
    fits = []
    for g in groups:
        x = cols[g].astype(np.float64)
        v, slope, ragged = _theil_sen(x, edge[g], float(x.mean()))
        if ragged > _WL_RAGGED:
            return []
        fits.append((float(x.mean()), v, slope))
    # every column with an edge joins the ship whose water line passes nearest (a bow
    # rising from a level, a transition column); the far ship spans the near one
    line = np.stack([v + k * (cols - m) for m, v, k in fits])
    meas = np.isfinite(edge)
    near = np.where(meas, np.argmin(np.abs(line - np.where(meas, edge, 0.0)), axis=0), -1)
    # the levels must describe the object's water line: most columns on them, and the
    # rest near one (a glint patch's ragged bottom has flat stretches too)
    resid = edge[meas] - line[near[meas], np.flatnonzero(meas)]
    on_levels = sum(g.size for g in groups)
    if on_levels < 0.5 * meas.sum() or 1.4826 * float(np.median(np.abs(resid))) > _WL_RAGGED:
        return []
    # a column in a run where its nearest level's ship has no level column belongs to
    # the ship whose run it is (a bow rising to the other's level beyond a gap of sea)
    counts = np.zeros((len(groups), int(run[-1]) + 1), np.int64)
    for k, g in enumerate(groups):
        np.add.at(counts[k], run[g], 1)
    owner = np.where(counts.any(axis=0), np.argmax(counts, axis=0), -1)
    stray = (near >= 0) & (counts[np.maximum(near, 0), run] == 0)
    near = np.where(stray, owner[run], near)
    out: list[_ShipSpan] = []
    for k, g in enumerate(groups):
        own = near == k
        own[g] = True
        c0, c1 = int(cols[own].min()), int(cols[own].max())
        span = (cols >= c0) & (cols <= c1)
        r0 = int(top[span].min()) if k == 0 else int(top[own].min())
        r1 = int(bottom[own].max())
        u = 0.5 * (c0 + c1)
        m, v, slope = fits[k]
        ec = cols[own & meas]  # the columns whose edge was measured
        low = _line_low(v, slope, m, ec if ec.size else np.array([c0, c1]))
        out.append((c0, c1, r0, r1, x0 + u, y0 + v + slope * (u - m), y0 + low))
    return out


def _main_runs(group: NDArray, run: NDArray) -> NDArray:
    """The indices ``group`` (into an object's columns) that lie in its main runs of
    adjacent columns (``run``: each column's run number): those holding at least a
    quarter of what its largest run holds."""
    ids, counts = np.unique(run[group], return_counts=True)
    if ids.size < 2:
        return group
    keep = ids[counts >= 0.25 * counts.max()]
    return group[np.isin(run[group], keep)]


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
    percentile of the box's differences); the water-line point is the sub-pixel hull/sea
    edge of that object, as for :class:`ClassicalShipDetector` (coverage integral per hull
    column, Theil–Sen line evaluated at the middle of the hull; the bottom edge of the
    lowest object pixel within the central half of the box's columns when the edge is too
    weak to measure). A box with no such pixels keeps its bottom centre
    ``(x + w/2, y + h)``.

    Args:
        image: (H, W) grey or (H, W, 3|4) BGR(A) frame.
        xywh: (N, 4) boxes: top-left corner x, y [px], width and height [px].

    Returns:
        (N, 2) array of ``(u_wl, v_wl)`` [px].
    """
    g, quantum, _ = _gray(image)
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
        raw = g[r0 : min(H, r1 + _WL_BELOW), c0:c1]
        mask = np.zeros(raw.shape, dtype=bool)
        mask[: obj.shape[0]] = obj
        wl = _edge_waterline(raw, mask, quantum)
        if wl is not None:
            out[i] = (c0 + wl[0], r0 + wl[1])
            continue
        u, v = _waterline(obj)
        out[i] = (c0 - 0.5 + u, r0 - 0.5 + v)
    return out
