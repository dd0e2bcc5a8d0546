"""Gate ("strobe") track-before-detect for many small targets.

ALGORITHMS.md §8.1 [REC], seed 004 (Fisenko, Mozheiko, Fisenko, Vilesov, Fedorov). Input
per frame: the point marks ``Z_k`` of a binary image, (row, col) in pixels (row down,
col right, origin at the top-left pixel centre), in a frame of ``frame_size = (rows,
cols)`` pixels. Frame k:

1. **Continuation with branching** (small gate). Every track predicts its next mark
   with the two-point constant-velocity rule ``p = 2 z_{k-1} − z_{k-2}`` (px). Every mark
   ``c`` with ``‖c − p‖_∞ ≤ a_s`` (square gate of ``small_gate = 2 a_s + 1`` px, edges
   inclusive) forms a branch ``τ ⊕ c`` that inherits the track's history. A branch is
   accepted when its linearity test passes (``linearity``), on the window of its m
   points (the last N marks with the candidate, see below):

   * ``"pooled-ls"`` (default, the spec's rule, §8.1): the least-squares line
     ``z(t) = a + b t`` (both coordinates, t in frames) leaves the pooled RMS residual

         s = sqrt(SSR / (2m − 4)) ≤ eps      (px; eps = ``linearity_threshold`` = 2.55)

     At m = 3 this is ``‖c − p‖₂ ≤ sqrt(12) eps``.
   * ``"orthogonal"`` (the alternative of ALGORITHMS.md §8.2): the geometric (total
     least squares) line through the m marks in the image plane, time ignored, leaves
     the perpendicular RMS residual

         s = sqrt(Σ d_⊥² / (m − 2)) ≤ eps     (px; eps = ``linearity_threshold`` = 1.96)

     where ``Σ d_⊥² = λ_min(S)``, the smaller eigenvalue of the 2×2 scatter matrix
     ``S = Σ_j (z_j − z̄)(z_j − z̄)ᵀ`` [px²] (the least sum of squared perpendicular
     distances over all lines). The spacing along the line is constrained only by the
     small gate.

   The parent is replaced by its accepted branches; a track with none is deleted
   (L = ``max_misses`` = 1).
2. **Mark usage.** A mark used by an accepted branch of length ≥ N is flagged *used*
   (``seed_exclusion="confirmed"``); with ``"extended"`` (the §8.2 alternative) every
   mark that extended any track (any accepted branch, tentative or confirmed) is.
3. **Initiation** (big gate). Seeds are the marks of frame k−1 not flagged *used* there
   (``seed_exclusion="confirmed"`` or True, the spec's default; ``"extended"``;
   ``"none"`` or False is the seed's literal rule: every mark of k−1 is a seed). Every
   pair (seed s, mark z of frame k) with ``‖z − s‖_∞ ≤ a_b`` (``large_gate = 2 a_b +
   1``) starts a two-point track. A mark may extend tracks and be the second point of
   new pairs at the same time.
4. **Confirmation.** A track whose length reaches N = ``n_frames`` (a mark in each of N
   consecutive frames) is confirmed and reported at that frame, so the delay is N−1
   frames. The per-frame statistics count the tracks that reached exactly N
   (``new_tracks``, the §8 false-alarm statistic when no target is present) and the
   distinct marks that end them (``new_marks``, the paper's "false marks").

Choices this implementation makes where §8.1 leaves room (tests check each one):

* **Sliding window.** The linearity check and the reported velocity use the last N
  marks of a track ("linearity must hold only in a sliding window of a short sequence
  of frames", seed 004, conclusions). For a tentative track this is all of its marks,
  as §8.1 says; only confirmed tracks longer than N are affected.
* **Confirmed tracks keep one branch.** A confirmed track that finds several accepted
  marks continues with the best-fitting one (smallest SSR of the LS line in time, ties
  to the lower mark index), so its id stays unique and stable (§8.3 pitfalls). Every
  accepted mark is still flagged *used* (step 2). Tentative tracks branch in full (up to
  the caps below). The ranking uses the LS line in time under the orthogonal test too:
  λ_min ignores the spacing along the line, so ranked by it a collinear clutter mark at
  the wrong distance would often win (measured on the clutter-tbd Fig. 4 case: 2.5
  id switches per sequence and 96.6 % of target-frames reported, against 0.05 and 99.9
  % with the spec's test).
* **Duplicates are merged.** Confirmed tracks whose windows (last N marks) are
  identical continue identically from then on; only the oldest (lowest id) is kept
  (§8.3 pitfalls). Sharing only the last marks is not enough: two targets crossing at
  a shallow angle may share marks for a frame or two and must both survive. The
  statistics of step 4 are counted before merging; ids are given after merging.
* **Output.** One row per confirmed track that received a mark in this frame:
  ``(track_id, row, col, v_row, v_col)``: the mark itself (px) and the least-squares
  slope over the window (px/frame). Ids start at 1 and are kept while a confirmed
  track continues.
* **L > 1.** ``max_misses`` applies to confirmed tracks: they coast through up to L−1
  frames without a mark (the prediction extrapolates the last two marks over the gap,
  and the line fit uses the true frame times). A tentative track is deleted at its
  first miss: it can no longer have a mark in each of N consecutive frames.

Bounded work in dense clutter (§8.3 pitfalls, "branch explosion"): a tentative track
keeps at most ``max_branches`` branches per frame (the best-fitting), a seed starts at
most ``max_pairs`` pairs (the nearest in Chebyshev distance), and the tracker holds at
most ``max_tracks`` tracks (the per-seed and per-track caps are tightened to stay
within it, then the longest tracks and the nearest new pairs are kept). Whenever a cap
binds, a ``RuntimeWarning`` says so and the frame's statistics count it. Marks outside
the frame are dropped with a ``RuntimeWarning`` and counted.

Speed: the marks of a frame go into a uniform grid (a counting sort) whose square cells
hold about one mark each (16–256 px). A small-gate query visits the cells its square
overlaps; a big-gate query visits rings of cells around the seed and stops at the
gate, or, for a capped seed, as soon as its nearest marks are certain. This is the grid
equivalent of the Chebyshev k-d tree query of §8.3. The tracks are rows of fixed-size
history arrays processed by compiled (numba) kernels, with no Python object per track:
about 0.4–0.6 ms per 1080×1920 frame with 300 clutter marks and ~1000 new pairs, N = 4
(``seawatch bench tbd``), and about 1 s for a frame of 100,000 marks after another such
frame (caps binding).

The ties of the linearity test (``SSR ≤ eps² (2m − 4)``, or ``λ_min ≤ eps² (m − 2)``) and
of the best-branch choice (smallest SSR) are resolved with a relative tolerance of 1e-9,
which only absorbs rounding: with integer marks, distinct residuals differ by far more.
"""

from __future__ import annotations

import itertools
import math
import numbers
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

_RTOL = 1e-9
"""Relative tolerance of the linearity test ``SSR ≤ eps² (2m − 4)`` (rounding only)."""

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]


# --------------------------------------------------------------------------------------
# compiled kernels
# --------------------------------------------------------------------------------------


@njit(cache=True)
def _grid_index(marks, cell_px, n_cell_rows, n_cell_cols):  # pragma: no cover - compiled
    """Counting sort of the marks into square cells: (cell start offsets, mark order)."""
    m = marks.shape[0]
    n_cells = n_cell_rows * n_cell_cols
    start = np.zeros(n_cells + 1, np.int64)
    cell = np.empty(m, np.int64)
    for i in range(m):
        r = min(int(marks[i, 0]) // cell_px, n_cell_rows - 1)
        c = min(int(marks[i, 1]) // cell_px, n_cell_cols - 1)
        cell[i] = r * n_cell_cols + c
        start[cell[i] + 1] += 1
    for j in range(n_cells):
        start[j + 1] += start[j]
    fill = start[:-1].copy()
    order = np.empty(m, np.int64)
    for i in range(m):
        order[fill[cell[i]]] = i
        fill[cell[i]] += 1
    return start, order


@njit(cache=True)
def _cell_span(lo, hi, cell_px, n):  # pragma: no cover - compiled
    """Cells [a, b] covering the coordinate interval [lo, hi] (empty when a > b)."""
    a = math.floor(lo / cell_px)
    b = math.floor(hi / cell_px)
    if a < 0:
        a = 0
    if b > n - 1:
        b = n - 1
    return a, b


@njit(cache=True)
def _branch_ssr(hist, htime, t, w, n_frames, k, cr, cc):  # pragma: no cover - compiled
    """SSR [px²] of the LS line through the branch window: the track's last marks (at most
    N − 1 of them) and the candidate (k, cr, cc). Returns (SSR, m)."""
    first = 1 if w >= n_frames else 0
    m = w - first + 1
    mt = 0.0
    mr = cr
    mc = cc
    for j in range(first, w):
        mt += htime[t, j] - k
        mr += hist[t, j, 0]
        mc += hist[t, j, 1]
    mt /= m
    mr /= m
    mc /= m
    dt = -mt
    dr = cr - mr
    dc = cc - mc
    stt = dt * dt
    s_tr = dt * dr
    s_tc = dt * dc
    srr = dr * dr
    scc = dc * dc
    for j in range(first, w):
        dt = htime[t, j] - k - mt
        dr = hist[t, j, 0] - mr
        dc = hist[t, j, 1] - mc
        stt += dt * dt
        s_tr += dt * dr
        s_tc += dt * dc
        srr += dr * dr
        scc += dc * dc
    ssr = srr - s_tr * s_tr / stt + scc - s_tc * s_tc / stt
    if ssr < 0.0:
        ssr = 0.0
    return ssr, m


@njit(cache=True)
def _lambda_min(srr, scc, src):  # pragma: no cover - compiled
    """Smaller eigenvalue [px²] of the symmetric 2×2 matrix [[srr, src], [src, scc]] (a
    scatter matrix, so ≥ 0): ``det / λ_max``, which keeps its relative precision when the
    points are nearly collinear (λ_min ≪ λ_max)."""
    half = 0.5 * (srr + scc)
    diff = 0.5 * (srr - scc)
    lam_max = half + math.sqrt(diff * diff + src * src)
    if lam_max <= 0.0:
        return 0.0
    lam = (srr * scc - src * src) / lam_max
    return lam if lam > 0.0 else 0.0


@njit(cache=True)
def _branch_orth(hist, htime, t, w, n_frames, cr, cc):  # pragma: no cover - compiled
    """Σ d_⊥² [px²] of the orthogonal (total least squares) line through the branch
    window in the image plane: λ_min of the scatter matrix of the track's last marks (at
    most N − 1 of them) and the candidate (cr, cc). Returns (Σ d_⊥², m)."""
    first = 1 if w >= n_frames else 0
    m = w - first + 1
    mr = cr
    mc = cc
    for j in range(first, w):
        mr += hist[t, j, 0]
        mc += hist[t, j, 1]
    mr /= m
    mc /= m
    dr = cr - mr
    dc = cc - mc
    srr = dr * dr
    scc = dc * dc
    src = dr * dc
    for j in range(first, w):
        dr = hist[t, j, 0] - mr
        dc = hist[t, j, 1] - mc
        srr += dr * dr
        scc += dc * dc
        src += dr * dc
    return _lambda_min(srr, scc, src), m


@njit(cache=True)
def _argsort(keys):  # pragma: no cover - compiled
    """Stable argsort of a 1-D float array (bottom-up merge sort; plain loops compile fast)."""
    n = keys.shape[0]
    idx = np.arange(n)
    tmp = np.empty(n, np.int64)
    width = 1
    while width < n:
        for lo in range(0, n, 2 * width):
            mid = min(lo + width, n)
            hi = min(lo + 2 * width, n)
            a, b, o = lo, mid, lo
            while a < mid and b < hi:
                if keys[idx[b]] < keys[idx[a]]:
                    tmp[o] = idx[b]
                    b += 1
                else:
                    tmp[o] = idx[a]
                    a += 1
                o += 1
            while a < mid:
                tmp[o] = idx[a]
                a += 1
                o += 1
            while b < hi:
                tmp[o] = idx[b]
                b += 1
                o += 1
        idx, tmp = tmp, idx
        width *= 2
    return idx


@njit(cache=True)
def _kth_smallest(values, n, k, work):  # pragma: no cover - compiled
    """The k-th smallest (0-based) of values[:n] by quickselect on the buffer ``work``."""
    for i in range(n):
        work[i] = values[i]
    lo, hi = 0, n - 1
    while lo < hi:
        pivot = work[(lo + hi) // 2]
        i, j = lo, hi
        while i <= j:
            while work[i] < pivot:
                i += 1
            while work[j] > pivot:
                j -= 1
            if i <= j:
                work[i], work[j] = work[j], work[i]
                i += 1
                j -= 1
        if k <= j:
            hi = j
        elif k >= i:
            lo = i
        else:
            break
    return work[k]


@njit(cache=True)
def _extend_search(
    hist,
    htime,
    length,
    n_frames,
    k,
    marks,
    start,
    order,
    cell_px,
    ncr,
    ncc,
    a_s,
    thr,
    used,
    cap,
    orth,
    used_len,
):  # pragma: no cover - compiled
    """Steps 1–2 for every track: the marks in its small gate around the CV prediction that
    pass the linearity test (pooled LS SSR ≤ thr[m], or with ``orth`` the orthogonal
    Σ d_⊥² ≤ thr[m]), and the *used* flags of the marks taken by accepted branches of
    length ≥ ``used_len`` (N: confirmed branches; 3: every branch).

    Returns (accepted count per track, mark index, pooled LS SSR, complete) with the accepted
    candidates grouped by track, in track order; ``complete`` is False when more than
    ``cap`` candidates were accepted (call again with a larger cap).
    """
    n_tracks = length.shape[0]
    n_acc = np.zeros(n_tracks, np.int64)
    cand_i = np.empty(cap, np.int64)
    cand_s = np.empty(cap)
    n = 0
    for t in range(n_tracks):
        w = min(length[t], n_frames)
        t1 = htime[t, w - 1]
        t0 = htime[t, w - 2]
        r1 = hist[t, w - 1, 0]
        c1 = hist[t, w - 1, 1]
        r0 = hist[t, w - 2, 0]
        c0 = hist[t, w - 2, 1]
        if t1 - t0 == 1 and k - t1 == 1:
            pr = 2.0 * r1 - r0
            pc = 2.0 * c1 - c0
        else:  # a coasting confirmed track (max_misses > 1): extrapolate over the gap
            f = (k - t1) / (t1 - t0)
            pr = r1 + (r1 - r0) * f
            pc = c1 + (c1 - c0) * f
        ra, rb = _cell_span(pr - a_s, pr + a_s, cell_px, ncr)
        ca, cb = _cell_span(pc - a_s, pc + a_s, cell_px, ncc)
        for rr in range(ra, rb + 1):
            for cq in range(ca, cb + 1):
                cell = rr * ncc + cq
                for p in range(start[cell], start[cell + 1]):
                    i = order[p]
                    mr = marks[i, 0]
                    mc = marks[i, 1]
                    if abs(mr - pr) <= a_s and abs(mc - pc) <= a_s:
                        ssr, m = _branch_ssr(hist, htime, t, w, n_frames, k, mr, mc)
                        res = ssr
                        if orth:
                            res, m = _branch_orth(hist, htime, t, w, n_frames, mr, mc)
                        if res <= thr[m]:
                            if n == cap:
                                return n_acc, cand_i, cand_s, False  # caller retries bigger
                            cand_i[n] = i
                            cand_s[n] = ssr  # branches rank by the LS line in time
                            n += 1
                            n_acc[t] += 1
                            if length[t] + 1 >= used_len:
                                used[i] = True
    return n_acc, cand_i[:n], cand_s[:n], True


@njit(cache=True)
def _extend_fill(
    hist, htime, length, misses, ids, n_frames, max_misses, k, marks, n_acc, cand_i, cand_s, lim
):  # pragma: no cover - compiled
    """Step 1's surviving rows: each accepted branch (a confirmed track keeps its best; a
    tentative one its ``lim`` best, by SSR then mark index) and coasting confirmed tracks.

    Returns the new rows (hist, time, length, misses, id, mark index or −1, SSR) and the
    number of tentative tracks whose branches were capped.
    """
    n_tracks = length.shape[0]
    keep = np.zeros(n_tracks, np.int64)
    rows = 0
    n_capped = 0
    for t in range(n_tracks):
        confirmed = length[t] >= n_frames
        if n_acc[t] == 0:
            if confirmed and misses[t] + 1 < max_misses:
                keep[t] = 1  # coasting
        else:
            c = 1 if confirmed else lim
            if n_acc[t] > c:
                if not confirmed:
                    n_capped += 1
                keep[t] = c
            else:
                keep[t] = n_acc[t]
        rows += keep[t]
    o_hist = np.zeros((rows, n_frames, 2))
    o_time = np.zeros((rows, n_frames), np.int64)
    o_len = np.empty(rows, np.int64)
    o_miss = np.empty(rows, np.int64)
    o_id = np.empty(rows, np.int64)
    o_mark = np.empty(rows, np.int64)
    o_ssr = np.empty(rows)
    r = 0
    seg = 0
    for t in range(n_tracks):
        n = n_acc[t]
        c = keep[t]
        if c == 0:
            seg += n
            continue
        if n == 0:  # coasting confirmed track
            for q in range(n_frames):
                o_hist[r, q, 0] = hist[t, q, 0]
                o_hist[r, q, 1] = hist[t, q, 1]
                o_time[r, q] = htime[t, q]
            o_len[r] = length[t]
            o_miss[r] = misses[t] + 1
            o_id[r] = ids[t]
            o_mark[r] = -1
            o_ssr[r] = 0.0
            r += 1
            continue
        if n > c:  # the c best-fitting first: by SSR (equal to rounding: lower mark index)
            for a in range(seg, seg + c):
                best = a
                for b in range(a + 1, seg + n):
                    tol = 1e-9 * (1.0 + cand_s[best])
                    if cand_s[b] < cand_s[best] - tol or (
                        cand_s[b] <= cand_s[best] + tol and cand_i[b] < cand_i[best]
                    ):
                        best = b
                cand_s[a], cand_s[best] = cand_s[best], cand_s[a]
                cand_i[a], cand_i[best] = cand_i[best], cand_i[a]
        w = min(length[t], n_frames)
        first = 1 if w >= n_frames else 0
        for j in range(seg, seg + c):
            i = cand_i[j]
            q = 0
            for p in range(first, w):
                o_hist[r, q, 0] = hist[t, p, 0]
                o_hist[r, q, 1] = hist[t, p, 1]
                o_time[r, q] = htime[t, p]
                q += 1
            o_hist[r, q, 0] = marks[i, 0]
            o_hist[r, q, 1] = marks[i, 1]
            o_time[r, q] = k
            o_len[r] = length[t] + 1
            o_miss[r] = 0
            o_id[r] = ids[t]
            o_mark[r] = i
            o_ssr[r] = cand_s[j]
            r += 1
        seg += n
    return o_hist, o_time, o_len, o_miss, o_id, o_mark, o_ssr, n_capped


@njit(cache=True)
def _pairs(
    seeds, seed_ok, marks, start, order, cell_px, ncr, ncc, a_b, cap, buf_i, buf_d
):  # pragma: no cover - compiled
    """Step 3: (seed, mark, Chebyshev distance) in the big gate, ≤ cap nearest per seed.

    Cells are visited in square rings around the seed's cell; the search stops once the
    ring's distance bound exceeds the gate or, with ``cap`` marks in hand, the cap-th
    nearest of them (so a capped seed in dense clutter looks at a few cells only).
    Returns (seed index, mark index, distance [px], number of seeds capped).
    """
    n_seeds = seeds.shape[0]
    n_ok = 0
    for s in range(n_seeds):
        if seed_ok[s]:
            n_ok += 1
    out_s = np.empty(n_ok * cap, np.int64)
    out_m = np.empty(n_ok * cap, np.int64)
    out_d = np.empty(n_ok * cap)
    work = np.empty(buf_d.shape[0])
    n = 0
    n_capped = 0
    if cap == 0:
        return out_s, out_m, out_d, n_capped
    for s in range(n_seeds):
        if not seed_ok[s]:
            continue
        sr = seeds[s, 0]
        sc = seeds[s, 1]
        r0 = int(sr) // cell_px
        c0 = int(sc) // cell_px
        cnt = 0
        j = 0
        while True:
            for rr in range(r0 - j, r0 + j + 1):
                if rr < 0 or rr >= ncr:
                    continue
                edge = rr == r0 - j or rr == r0 + j
                step = 1 if edge else 2 * j
                for cq in range(c0 - j, c0 + j + 1, max(step, 1)):
                    if cq < 0 or cq >= ncc:
                        continue
                    cell = rr * ncc + cq
                    for p in range(start[cell], start[cell + 1]):
                        i = order[p]
                        d = max(abs(marks[i, 0] - sr), abs(marks[i, 1] - sc))
                        if d <= a_b:
                            buf_i[cnt] = i
                            buf_d[cnt] = d
                            cnt += 1
            j += 1
            # every mark not yet seen is at least this far from the seed
            bound = min(
                sr - (r0 - j + 1) * cell_px,
                (r0 + j) * cell_px - sr,
                sc - (c0 - j + 1) * cell_px,
                (c0 + j) * cell_px - sc,
            )
            if bound > a_b or (j > ncr and j > ncc):
                break
            if cnt >= cap and _kth_smallest(buf_d, cnt, cap - 1, work) < bound:
                break
        if cnt <= cap:
            for q in range(cnt):
                out_s[n] = s
                out_m[n] = buf_i[q]
                out_d[n] = buf_d[q]
                n += 1
        else:  # the cap nearest (ties in visiting order)
            n_capped += 1
            th = _kth_smallest(buf_d, cnt, cap - 1, work)
            took = 0
            for q in range(cnt):
                if buf_d[q] < th:
                    out_s[n] = s
                    out_m[n] = buf_i[q]
                    out_d[n] = buf_d[q]
                    n += 1
                    took += 1
            for q in range(cnt):
                if took == cap:
                    break
                if buf_d[q] == th:
                    out_s[n] = s
                    out_m[n] = buf_i[q]
                    out_d[n] = buf_d[q]
                    n += 1
                    took += 1
    return out_s[:n], out_m[:n], out_d[:n], n_capped


@njit(cache=True)
def _finish(
    e_hist, e_time, e_len, e_miss, e_id, e_mark, n_frames, next_id, seeds, marks, p_seed, p_mark, k
):  # pragma: no cover - compiled
    """Step 4 and the new state: confirmation statistics, merging of confirmed tracks with
    identical windows (the oldest survives), ids for the newly confirmed, the new pairs
    appended, and the frame's detections (id, row, col, v_row, v_col) sorted by id.

    Returns (hist, time, length, misses, ids, detections, detection mark index, marks
    ending newly confirmed tracks, distinct such marks, next id).
    """
    rows = e_len.shape[0]
    n_marks = marks.shape[0]
    # statistics of step 4, before merging
    n_new = 0
    for r in range(rows):
        if e_len[r] == n_frames and e_mark[r] >= 0:
            n_new += 1
    new_marks = np.empty(n_new, np.int64)
    seen = np.zeros(n_marks, np.bool_)
    n_distinct = 0
    j = 0
    for r in range(rows):
        if e_len[r] == n_frames and e_mark[r] >= 0:
            new_marks[j] = e_mark[r]
            j += 1
            if not seen[e_mark[r]]:
                seen[e_mark[r]] = True
                n_distinct += 1
    # merging: confirmed rows ending at the same position, compared window by window
    alive = np.ones(rows, np.bool_)
    n_conf = 0
    for r in range(rows):
        if e_len[r] >= n_frames and e_mark[r] >= 0:
            n_conf += 1
    conf = np.empty(n_conf, np.int64)
    age = np.empty(n_conf, np.int64)
    j = 0
    for r in range(rows):
        if e_len[r] >= n_frames and e_mark[r] >= 0:
            conf[j] = r
            age[j] = e_id[r] if e_id[r] > 0 else next_id + r
            j += 1
    # group by the position of the last mark (a key equal for equal positions; rows of
    # different positions sharing a key are told apart by the window comparison)
    key = np.empty(n_conf)
    width = 0.0
    for x in range(n_conf):
        width = max(width, marks[e_mark[conf[x]], 1] + 1.0)
    for x in range(n_conf):
        m = e_mark[conf[x]]
        key[x] = marks[m, 0] * width + marks[m, 1]
    srt = _argsort(key)
    a = 0
    while a < n_conf:
        b = a + 1
        while b < n_conf and key[srt[b]] == key[srt[a]]:
            b += 1
        for x in range(a, b):  # a row dies if an older row has the identical window
            rx = conf[srt[x]]
            for y in range(a, b):
                ry = conf[srt[y]]
                if y == x or age[srt[y]] > age[srt[x]] or not alive[ry]:
                    continue
                same = True
                for q in range(n_frames):
                    if (
                        e_time[rx, q] != e_time[ry, q]
                        or e_hist[rx, q, 0] != e_hist[ry, q, 0]
                        or e_hist[rx, q, 1] != e_hist[ry, q, 1]
                    ):
                        same = False
                        break
                if same:
                    alive[rx] = False
                    break
        a = b
    # ids for the newly confirmed survivors, in row order
    for r in range(rows):
        if alive[r] and e_len[r] == n_frames and e_mark[r] >= 0 and e_id[r] == 0:
            e_id[r] = next_id
            next_id += 1
    # new state: surviving rows, then the pairs
    n_alive = 0
    for r in range(rows):
        if alive[r]:
            n_alive += 1
    n_pairs = p_seed.shape[0]
    total = n_alive + n_pairs
    hist = np.zeros((total, n_frames, 2))
    htime = np.zeros((total, n_frames), np.int64)
    length = np.empty(total, np.int64)
    misses = np.empty(total, np.int64)
    ids = np.empty(total, np.int64)
    out_row = np.empty(n_conf, np.int64)
    n_out = 0
    j = 0
    for r in range(rows):
        if not alive[r]:
            continue
        for q in range(n_frames):
            hist[j, q, 0] = e_hist[r, q, 0]
            hist[j, q, 1] = e_hist[r, q, 1]
            htime[j, q] = e_time[r, q]
        length[j] = e_len[r]
        misses[j] = e_miss[r]
        ids[j] = e_id[r]
        if e_len[r] >= n_frames and e_mark[r] >= 0:
            out_row[n_out] = r
            n_out += 1
        j += 1
    for p in range(n_pairs):
        hist[j, 0, 0] = seeds[p_seed[p], 0]
        hist[j, 0, 1] = seeds[p_seed[p], 1]
        hist[j, 1, 0] = marks[p_mark[p], 0]
        hist[j, 1, 1] = marks[p_mark[p], 1]
        htime[j, 0] = k - 1
        htime[j, 1] = k
        length[j] = 2
        misses[j] = 0
        ids[j] = 0
        j += 1
    # detections: the mark, and the LS slope over the window (px/frame)
    id_out = np.empty(n_out, np.int64)
    for i in range(n_out):
        id_out[i] = e_id[out_row[i]]
    by_id = _argsort(id_out.astype(np.float64))
    det = np.empty((n_out, 5))
    det_mark = np.empty(n_out, np.int64)
    for i in range(n_out):
        r = out_row[by_id[i]]
        mt = 0.0
        for q in range(n_frames):
            mt += e_time[r, q]
        mt /= n_frames
        stt = 0.0
        s_r = 0.0
        s_c = 0.0
        for q in range(n_frames):
            dt = e_time[r, q] - mt
            stt += dt * dt
            s_r += dt * e_hist[r, q, 0]
            s_c += dt * e_hist[r, q, 1]
        det[i, 0] = e_id[r]
        det[i, 1] = marks[e_mark[r], 0]
        det[i, 2] = marks[e_mark[r], 1]
        det[i, 3] = s_r / stt
        det[i, 4] = s_c / stt
        det_mark[i] = e_mark[r]
    return hist, htime, length, misses, ids, det, det_mark, new_marks, n_distinct, next_id


# --------------------------------------------------------------------------------------
# public API
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FrameStats:
    """Statistics of one processed frame (ALGORITHMS.md §8.1 step 4).

    Attributes:
        frame: frame number.
        marks: marks processed (inside the frame).
        dropped: marks dropped because they lie outside the frame.
        new_tracks: tracks that reached exactly N marks in this frame (newly confirmed;
            the §8 false-alarm statistic when no target is present).
        new_marks: distinct marks of this frame that end those tracks (the paper's
            "false marks" count when no target is present).
        confirmed: confirmed detections reported for this frame (rows of ``push``).
        tentative: tentative tracks (fewer than N marks) alive after the frame.
        pairs: two-point tracks started by the big gate in this frame.
        capped_branches: tentative tracks whose branches were capped in this frame.
        capped_pairs: seeds whose big-gate pairs were capped in this frame.
        new_track_marks: (new_tracks,) index into this frame's marks (as pushed, before
            dropping) of the mark that ends each newly confirmed track.
        detection_marks: (confirmed,) index into this frame's marks (as pushed) of the
            mark of each reported detection row.
    """

    frame: int
    marks: int
    dropped: int
    new_tracks: int
    new_marks: int
    confirmed: int
    tentative: int
    pairs: int
    capped_branches: int
    capped_pairs: int
    new_track_marks: IntArray
    detection_marks: IntArray


@dataclass(frozen=True)
class TBDResult:
    """Output of :meth:`GateTBD.run` over a whole sequence.

    Attributes:
        frames: (K,) the frame numbers given (skipped numbers are processed as empty
            frames but have no entry here; nothing can be confirmed in them).
        detections: (D, 6) rows ``(frame, track_id, row, col, v_row, v_col)``: every
            confirmed detection, position in px, velocity in px/frame.
        detection_marks: (D,) index of each detection's mark in its frame's marks.
        new_tracks: (K,) tracks that reached exactly N marks per frame.
        new_marks: (K,) distinct marks ending those tracks per frame.
        confirmed: (K,) confirmed detections per frame.
        tentative: (K,) tentative tracks alive after each frame.
        pairs: (K,) new two-point tracks per frame.
        dropped: (K,) marks dropped (outside the frame) per frame.
    """

    frames: IntArray
    detections: FloatArray
    detection_marks: IntArray
    new_tracks: IntArray
    new_marks: IntArray
    confirmed: IntArray
    tentative: IntArray
    pairs: IntArray
    dropped: IntArray


def _gate_size(name: str, value: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{name}: expected an odd integer gate size in px, got {value!r}")
    v = int(value)
    if v < 1 or v % 2 == 0:
        raise ValueError(f"{name}: expected an odd integer gate size >= 1 px, got {v}")
    return v


def _count(name: str, value: int, lo: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or int(value) < lo:
        raise ValueError(f"{name}: expected an integer >= {lo}, got {value!r}")
    return int(value)


DEFAULT_LINEARITY_THRESHOLD: dict[str, float] = {"pooled-ls": 2.55, "orthogonal": 1.96}
"""eps [px] of each linearity test (ALGORITHMS.md §8.1 and §8.2, inferred from Table 2)."""

SEED_RULES = ("confirmed", "extended", "none")
"""Seeding rules of §8.1 step 3 (and §8.2's alternative); True = "confirmed", False = "none"."""


def _seed_rule(value: bool | str) -> str:
    if value is True or value is False or isinstance(value, np.bool_):
        return "confirmed" if value else "none"
    if isinstance(value, str) and value in SEED_RULES:
        return value
    raise ValueError(
        f"seed_exclusion: expected True, False or one of {', '.join(SEED_RULES)}, got {value!r}"
    )


def _frame_number(name: str, value: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{name}: expected an integer frame number, got {value!r}")
    return int(value)


class GateTBD:
    """Two-gate track-before-detect: ALGORITHMS.md §8.1, seed 004.

    Args:
        frame_size: (rows, cols) of the frame in px, e.g. ``(1080, 1920)``.
        large_gate: side of the square big (initiation) gate in px, odd (``2 a_b + 1``).
        small_gate: side of the square small (confirmation) gate in px, odd (``2 a_s + 1``).
        n_frames: N, consecutive frames with a mark needed for confirmation (≥ 3).
        max_misses: L, consecutive misses that delete a confirmed track (1 = the paper).
        linearity_threshold: eps [px], the largest accepted RMS residual of the
            linearity test: ``sqrt(SSR / (2m − 4))`` of the LS line through a track's
            window (``"pooled-ls"``), or ``sqrt(Σ d_⊥² / (m − 2))`` of the orthogonal line
            (``"orthogonal"``). None (default): the rule's own value,
            :data:`DEFAULT_LINEARITY_THRESHOLD` (2.55 px pooled-ls, 1.96 px orthogonal,
            ALGORITHMS.md §8.2).
        seed_exclusion: which marks of frame k−1 may not seed (§8.1 step 3):
            ``"confirmed"`` or True (default) the marks used by confirmed (length ≥ N)
            branches; ``"extended"`` the marks used by any accepted branch (the §8.2
            alternative); ``"none"`` or False, the seed text's literal rule (every
            mark seeds).
        max_branches: most branches a tentative track keeps per frame (best-fitting).
        max_pairs: most big-gate pairs one seed starts per frame (nearest).
        max_tracks: most tracks (tentative + confirmed) held at once (memory bound).
        linearity: the linearity test of step 1: ``"pooled-ls"`` (default, §8.1: per-axis
            LS line in time, pooled residual) or ``"orthogonal"`` (§8.2's alternative:
            geometric line in the image plane, perpendicular residual).

    Streaming: :meth:`push` one frame's marks at a time; its statistics are then in
    :attr:`last_stats` (:class:`FrameStats`). Whole sequence: :meth:`run`.

    Example:
        >>> tbd = GateTBD((1080, 1920), n_frames=3)
        >>> for k in range(3):
        ...     out = tbd.push([[100 + 5 * k, 200 + 7 * k]])
        >>> out.tolist()  # track 1 confirmed at frame 2 (delay N − 1): id, row, col, v_row, v_col
        [[1.0, 110.0, 214.0, 5.0, 7.0]]
    """

    def __init__(
        self,
        frame_size: tuple[int, int] | Sequence[int],
        large_gate: int = 161,
        small_gate: int = 23,
        n_frames: int = 4,
        max_misses: int = 1,
        linearity_threshold: float | None = None,
        seed_exclusion: bool | str = True,
        max_branches: int = 16,
        max_pairs: int = 32,
        max_tracks: int = 200_000,
        *,
        linearity: str = "pooled-ls",
    ) -> None:
        try:
            size = tuple(frame_size)
        except TypeError:
            raise ValueError(
                f"frame_size: expected (rows, cols) in px, got {frame_size!r}"
            ) from None
        if len(size) != 2:
            raise ValueError(f"frame_size: expected (rows, cols) in px, got {frame_size!r}")
        rows = _count("frame_size", size[0], 1)
        cols = _count("frame_size", size[1], 1)
        self.frame_size = (rows, cols)
        self.large_gate = _gate_size("large_gate", large_gate)
        self.small_gate = _gate_size("small_gate", small_gate)
        self.n_frames = _count("n_frames", n_frames, 3)
        self.max_misses = _count("max_misses", max_misses, 1)
        if not isinstance(linearity, str) or linearity not in DEFAULT_LINEARITY_THRESHOLD:
            raise ValueError(
                f"linearity: expected one of {', '.join(DEFAULT_LINEARITY_THRESHOLD)}, "
                f"got {linearity!r}"
            )
        self.linearity = str(linearity)
        if linearity_threshold is None:
            linearity_threshold = DEFAULT_LINEARITY_THRESHOLD[self.linearity]
        try:
            eps = float(linearity_threshold)
        except (TypeError, ValueError):
            raise ValueError(
                f"linearity_threshold: expected a number of px, got {linearity_threshold!r}"
            ) from None
        if not math.isfinite(eps) or eps < 0:
            raise ValueError(
                "linearity_threshold: expected a finite number >= 0 px, got "
                f"{linearity_threshold!r}"
            )
        self.linearity_threshold = eps
        self.seed_rule = _seed_rule(seed_exclusion)
        """The seeding rule: ``"confirmed"``, ``"extended"`` or ``"none"``."""
        self.seed_exclusion = self.seed_rule != "none"
        """True when some marks are excluded from seeding (``seed_rule`` is not "none")."""
        self.max_branches = _count("max_branches", max_branches, 1)
        self.max_pairs = _count("max_pairs", max_pairs, 1)
        self.max_tracks = _count("max_tracks", max_tracks, 1)
        self._max_row, self._max_col = float(rows - 1), float(cols - 1)
        self._a_b = (self.large_gate - 1) / 2.0
        self._a_s = (self.small_gate - 1) / 2.0
        m = np.arange(self.n_frames + 1, dtype=np.float64)
        dof = 2.0 * m - 4.0 if self.linearity == "pooled-ls" else m - 2.0
        thr = eps * eps * dof  # SSR or Σ d_⊥² [px²] accepted at m marks
        self._thr = np.where(m >= 3, thr * (1.0 + _RTOL) + 1e-12, -1.0)
        self.reset()

    # ---------------------------------------------------------------- state
    def reset(self) -> None:
        """Forget all tracks and marks; the next ``push`` is a first frame."""
        n = self.n_frames
        self._hist = np.zeros((0, n, 2))
        self._time = np.zeros((0, n), np.int64)
        self._len = np.zeros(0, np.int64)
        self._miss = np.zeros(0, np.int64)
        self._id = np.zeros(0, np.int64)
        self._prev_marks = np.zeros((0, 2))
        self._prev_used = np.zeros(0, bool)
        self._frame: int | None = None
        self._next_id = 1
        self.last_stats: FrameStats | None = None

    @property
    def frame(self) -> int | None:
        """Number of the last processed frame (None before the first)."""
        return self._frame

    @property
    def n_tracks(self) -> int:
        """Tracks held (tentative and confirmed)."""
        return int(self._len.size)

    # ---------------------------------------------------------------- input
    def _validate(self, marks: ArrayLike) -> tuple[FloatArray, IntArray | None, int]:
        """Marks as a C-contiguous (M, 2) float array, the original index of each kept mark
        (None when none was dropped) and the number dropped outside the frame."""
        try:
            z = np.asarray(marks, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"marks: cannot convert to a float array ({exc})") from None
        if z.size == 0:
            return np.zeros((0, 2)), None, 0
        if z.ndim != 2 or z.shape[1] != 2:
            raise ValueError(f"marks: expected an (M, 2) array of (row, col) px, got {z.shape}")
        lo = z.min(axis=0)
        hi = z.max(axis=0)
        if lo[0] >= 0 and lo[1] >= 0 and hi[0] <= self._max_row and hi[1] <= self._max_col:
            return np.ascontiguousarray(z), None, 0  # all inside (NaN fails every test)
        if not np.all(np.isfinite(z)):
            bad = int(np.flatnonzero(~np.all(np.isfinite(z), axis=1))[0])
            raise ValueError(f"marks: row {bad} contains NaN or inf")
        inside = (z[:, 0] >= 0) & (z[:, 0] <= self._max_row)
        inside &= (z[:, 1] >= 0) & (z[:, 1] <= self._max_col)
        index = np.flatnonzero(inside)
        return np.ascontiguousarray(z[index]), index, int(z.shape[0] - index.size)

    # ---------------------------------------------------------------- processing
    def push(self, marks: ArrayLike, frame: int | None = None) -> FloatArray:
        """Process one frame's marks; return its confirmed detections.

        Args:
            marks: (M, 2) mark positions (row, col) in px; ``[]`` for an empty frame.
                Marks outside ``[0, rows−1] × [0, cols−1]`` are dropped with a warning.
            frame: optional frame number; must exceed the previous one. Skipped frame
                numbers are processed as empty frames. Default: previous + 1 (or 0).

        Returns:
            (C, 5) rows ``(track_id, row, col, v_row, v_col)`` sorted by id: position in
            px (the mark), velocity in px/frame (LS slope over the last N marks). Per-frame
            statistics are in :attr:`last_stats`.
        """
        z, index, dropped = self._validate(marks)
        if frame is None:
            k = 0 if self._frame is None else self._frame + 1
        else:
            k = _frame_number("frame", frame)
            if self._frame is not None:
                if k <= self._frame:
                    raise ValueError(
                        f"frame: frame numbers must increase; got frame {k} after frame "
                        f"{self._frame}"
                    )
                gap = k - self._frame - 1
                for _ in range(min(gap, self.max_misses + 1)):
                    self._step(np.zeros((0, 2)), None, 0, self._frame + 1)
                if gap > self.max_misses + 1:  # nothing can survive the rest of the gap
                    self._frame = k - 1
        if dropped:
            warnings.warn(
                f"GateTBD frame {k}: dropped {dropped} mark(s) outside the "
                f"{self.frame_size[0]}x{self.frame_size[1]} frame",
                RuntimeWarning,
                stacklevel=2,
            )
        return self._step(z, index, dropped, k)

    def _step(self, z: FloatArray, index: IntArray | None, dropped: int, k: int) -> FloatArray:
        n_frames = self.n_frames
        n_marks = z.shape[0]
        rows_px, cols_px = self.frame_size
        # grid cells of about one mark each (16 … 256 px): few cells per gate query
        cell_px = int(min(max(math.sqrt(rows_px * cols_px / max(n_marks, 1)), 16.0), 256.0))
        ncr = (rows_px - 1) // cell_px + 1
        ncc = (cols_px - 1) // cell_px + 1
        start, order = _grid_index(z, cell_px, ncr, ncc)
        used = np.zeros(n_marks, bool)
        n_old = self._len.size

        # 1-2. continuation with branching, mark usage
        cap, complete = 4 * n_old + 64, False
        while not complete:
            n_acc, cand_i, cand_s, complete = _extend_search(
                self._hist, self._time, self._len, n_frames, k, z, start, order, cell_px, ncr,
                ncc, self._a_s, self._thr, used, cap, self.linearity == "orthogonal",
                3 if self.seed_rule == "extended" else n_frames,
            )  # fmt: skip
            cap *= 4
        fill = (self._hist, self._time, self._len, self._miss, self._id, n_frames)
        fill += (self.max_misses, k, z, n_acc)
        e_hist, e_time, e_len, e_miss, e_id, e_mark, e_ssr, capped_b = _extend_fill(
            *fill, cand_i, cand_s, self.max_branches
        )
        if e_len.size > self.max_tracks:  # tighten the branch cap to the track budget
            lim = max(1, self.max_tracks // max(1, n_old))
            e_hist, e_time, e_len, e_miss, e_id, e_mark, e_ssr, capped_b = _extend_fill(
                *fill, cand_i, cand_s, lim
            )
        pruned = 0
        if e_len.size > self.max_tracks:  # keep confirmed, then longest, then best fit
            keep = np.lexsort((e_ssr, -e_len))[: self.max_tracks]
            keep.sort()
            pruned = e_len.size - keep.size
            e_hist, e_time, e_len, e_miss = e_hist[keep], e_time[keep], e_len[keep], e_miss[keep]
            e_id, e_mark = e_id[keep], e_mark[keep]

        # 3. initiation: pairs (unused seed of k−1, mark of k) in the big gate
        seeds = self._prev_marks
        ok = ~self._prev_used if self.seed_exclusion else np.ones(seeds.shape[0], bool)
        n_ok = int(np.count_nonzero(ok))
        budget = self.max_tracks - e_len.size
        capped_p = 0
        if n_ok and n_marks:
            cap = min(self.max_pairs, max(1, budget // n_ok)) if budget > 0 else 0
            buf_i = np.empty(n_marks, np.int64)
            buf_d = np.empty(n_marks)
            p_seed, p_mark, p_dist, capped_p = _pairs(
                seeds, ok, z, start, order, cell_px, ncr, ncc, self._a_b, cap, buf_i, buf_d
            )
            if cap == 0:
                capped_p = n_ok
            if p_seed.size > budget:
                keep = np.sort(np.argsort(p_dist, kind="stable")[: max(budget, 0)])
                pruned += p_seed.size - keep.size
                p_seed, p_mark = p_seed[keep], p_mark[keep]
        else:
            p_seed = p_mark = np.zeros(0, np.int64)
        n_pairs = int(p_seed.size)
        if capped_b or capped_p or pruned:
            warnings.warn(
                f"GateTBD frame {k}: {n_marks} marks, {n_old} tracks: branches capped for "
                f"{capped_b} track(s) (max_branches={self.max_branches}), pairs capped for "
                f"{capped_p} seed(s) (max_pairs={self.max_pairs}), {pruned} track(s) dropped "
                f"(max_tracks={self.max_tracks}); tracking in this frame is incomplete",
                RuntimeWarning,
                stacklevel=3,
            )

        # 4. confirmation, merging, ids; the new state; the detections
        res = _finish(
            e_hist, e_time, e_len, e_miss, e_id, e_mark, n_frames, self._next_id, seeds, z,
            p_seed, p_mark, k,
        )  # fmt: skip
        self._hist, self._time, self._len, self._miss, self._id = res[:5]
        det, det_mark, new_marks, n_new_marks, self._next_id = res[5:]
        self._prev_marks = z
        self._prev_used = used
        self._frame = k
        if index is not None:
            new_marks, det_mark = index[new_marks], index[det_mark]
        self.last_stats = FrameStats(
            frame=k,
            marks=n_marks,
            dropped=dropped,
            new_tracks=int(new_marks.size),
            new_marks=int(n_new_marks),
            confirmed=int(det.shape[0]),
            tentative=int(np.count_nonzero(self._len < n_frames)),
            pairs=n_pairs,
            capped_branches=int(capped_b),
            capped_pairs=int(capped_p),
            new_track_marks=new_marks,
            detection_marks=det_mark,
        )
        return det

    def run(
        self, frames: Sequence[ArrayLike], frame_numbers: Sequence[int] | None = None
    ) -> TBDResult:
        """Process a whole sequence from a fresh state (:meth:`reset` first).

        Args:
            frames: per frame, its (M_k, 2) marks (row, col) in px.
            frame_numbers: optional increasing frame numbers, one per entry of ``frames``
                (gaps are empty frames); default 0, 1, 2, …

        Raises:
            ValueError: frame numbers that do not increase (naming the frame), or bad marks.
        """
        frames = list(frames)
        if frame_numbers is None:
            numbers_ = list(range(len(frames)))
        else:
            numbers_ = [_frame_number("frame_numbers", f) for f in frame_numbers]
            if len(numbers_) != len(frames):
                raise ValueError(
                    f"frame_numbers: expected {len(frames)} numbers (one per frame), "
                    f"got {len(numbers_)}"
                )
            for a, b in itertools.pairwise(numbers_):
                if b <= a:
                    raise ValueError(
                        f"frame_numbers: frame numbers must increase; frame {b} follows frame {a}"
                    )
        self.reset()
        done, stats, dets, dmarks = [], [], [], []
        for f, marks in zip(numbers_, frames, strict=True):
            out = self.push(marks, frame=f)
            done.append(f)
            st = self.last_stats
            assert st is not None
            stats.append(st)
            if out.shape[0]:
                dets.append(np.column_stack((np.full(out.shape[0], float(f)), out)))
                dmarks.append(st.detection_marks)
        det = np.concatenate(dets) if dets else np.zeros((0, 6))
        dm = np.concatenate(dmarks) if dmarks else np.zeros(0, np.int64)

        def col(name: str) -> IntArray:
            return np.array([getattr(s, name) for s in stats], dtype=np.int64)

        return TBDResult(
            frames=np.array(done, dtype=np.int64),
            detections=det,
            detection_marks=dm,
            new_tracks=col("new_tracks"),
            new_marks=col("new_marks"),
            confirmed=col("confirmed"),
            tentative=col("tentative"),
            pairs=col("pairs"),
            dropped=col("dropped"),
        )


def group_marks(table: ArrayLike) -> tuple[list[int], list[FloatArray]]:
    """Split a mark table of rows ``(frame, row, col, …)`` into frames for :meth:`GateTBD.run`.

    Rows of one frame must be contiguous and frame numbers must not decrease.

    Returns:
        (frame numbers, list of (M_k, 2) mark arrays (row, col) px), one entry per frame
        number present in the table.

    Raises:
        ValueError: naming the row and frame where the frame numbers decrease, or a bad
            table shape / non-integer frame number.
    """
    t = np.asarray(table, dtype=np.float64)
    if t.size == 0:
        return [], []
    if t.ndim != 2 or t.shape[1] < 3:
        raise ValueError(f"marks: expected rows of (frame, row, col), got shape {t.shape}")
    f = t[:, 0]
    if not np.all(np.isfinite(f)) or np.any(f != np.round(f)):
        bad = int(np.flatnonzero(~np.isfinite(f) | (f != np.round(f)))[0])
        raise ValueError(f"marks: row {bad}: frame number {f[bad]!r} is not an integer")
    fi = f.astype(np.int64)
    back = np.flatnonzero(np.diff(fi) < 0)
    if back.size:
        r = int(back[0]) + 1
        raise ValueError(
            f"marks: frame numbers must not decrease; frame {fi[r]} at row {r} follows "
            f"frame {fi[r - 1]}"
        )
    cuts = np.flatnonzero(np.diff(fi)) + 1
    starts = np.concatenate(([0], cuts))
    ends = np.concatenate((cuts, [fi.size]))
    frames = [np.ascontiguousarray(t[a:b, 1:3]) for a, b in zip(starts, ends, strict=True)]
    return [int(fi[a]) for a in starts], frames
