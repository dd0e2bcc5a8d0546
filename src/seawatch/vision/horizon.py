"""Sea-horizon detection in one frame, temporal smoothing over frames, and the sea mask.

Issue 6, "Horizon and sea region"; the detected line feeds the camera-attitude geometry
of ALGORITHMS.md §4.3 ("With roll and pitch from the detected horizon line", via
:func:`seawatch.camera.attitude_from_horizon` and :meth:`HorizonEstimate.line`).

Method (classical, no learned weights)
--------------------------------------
The frame is reduced by an integer factor ``k`` to about ``work_width`` columns
(``cv2.INTER_AREA``; for ``k > 4`` a bilinear step to twice the working size first) and
converted to a luma ``g`` normalised so that its 1st–99th percentiles map to 0–1, plus
the colour channels on the same scale. Then:

1. **Edge evidence.** ``g_y = ∂g/∂y`` (Sobel after a Gaussian of σ = 1 px;
   σ_g = 1.4826 · median |g_y| is the robust gradient noise). The columns are grouped
   into ``S = 32`` vertical strips; in each strip the *signed* mean
   ``P_s(y) = mean_x g_y`` keeps the coherent horizon edge and cancels the random-sign
   wave texture of the sea.
2. **Line candidates.** Each strip's positive and negative parts are saturated,
   ``V_s(y) = max(±P_s, 0) / (max_y max(±P_s, 0) + 4 m)`` (m = median |P|), so that
   one strip with a strong edge (a boat, a pier) cannot outvote the others; a Hough
   transform over lines ``y = c + t (x − x_c)`` with ``|atan t| ≤ max_tilt`` accumulates
   ``E±(c, t) = mean_s V±_s(c + t (x_s − x_c))``; the ``n_candidates`` best local maxima
   of each polarity are refined (with the lines of ``previous``/``camera``, if given).
3. **Refinement and quality.** Each strip takes the polarity of its own ``P_s`` at the
   line (a horizon can be sky/sea on one side and coast/sea on the other). Every
   column's edge point is the maximum of ``±g_y`` within ±``search`` px (3 % of the
   height, halved twice), located to sub-pixel by a parabola through the three samples
   about the peak; a line is fitted to the points by iteratively re-weighted least
   squares (Tukey biweight, scale 1.5 px, weights ∝ edge strength). Its **quality** is
   ``q = mean_x [inlier(x) (1 − exp(−s(x) / 3 σ_g))] · mean_s (1 − exp(−(ρ_s − 1)₊ / 3))``:
   ``inlier`` — the column's strongest edge within the full search window lies within
   1.5 px of the line and exceeds 3 σ_g; ``ρ_s`` — the *prominence* of the strip's
   ``|P_s|`` at the line over its mean in the rows 3 … max(8, 6 % h) away on the quieter
   side (sea texture makes many similar parallel "lines", a horizon one).
4. **Region test (sky/sea statistics).** For each strip, the mean feature vectors
   (colour or luma, and texture ``|g_x| + |g_y − ḡ_y|``, ``ḡ_y`` the strip's mean of
   that row: a straight edge across the strip, the line itself, is no texture; each
   in units of its 10–90 % spread) of a
   band of 4 % of the height just above the line (A), one just below (B) and the next
   two bands below that (B₂) give ``r_s = ‖A − B‖ − ‖B − B₂‖``: the regions either side
   differ, and the region below continues without another boundary — the sea. A line
   along the top of a coastline band (B = land, B₂ = sea) or along a haze band scores
   low; ``r`` is the median over strips (robust to boats on the line). This is the
   region-based idea of the classical sky/ground horizon detectors (Ettinger et al.
   2003; Fefilatyev et al. 2006), with "sea continues below" as the prior.
5. **Selection: the lowest good line.** Candidates with ``r ≥ 0.03`` and a median edge
   strength along the line of at least 0.5 σ_g are *plausible*; among those whose
   ``q · prior`` is at least half the best, the lowest line (largest ``c``) wins: edges
   above the sea horizon (coastline, clouds, haze, the top of piers) are rejected in
   favour of it, edges inside the sea (waves, wakes, glint) are too short or too
   weak to compete. Candidates within 2 working px of the lowest (mean vertical
   distance over the width) are the same line found twice, e.g. crossing it at the
   centre with another tilt: the one with the better ``q · prior`` stands for them.
   ``prior = Π (0.5 + 0.5 exp(−d² / 2 σ_p²))`` over ``previous`` and
   the ``camera``'s nominal horizon (d = mean vertical distance between the lines,
   σ_p = 5 % of the height, or ``prior_sigma`` for ``previous`` where that is less:
   :class:`HorizonTracker` gives its predicted spread): it favours, never forbids. The
   confidence is ``sqrt(q · prior · (1 − exp(−r / 0.5)))`` in [0, 1]; ``found`` is
   ``confidence ≥ min_confidence`` (0.3).
6. **Sub-pixel refinement on the full-resolution image.** Steps 1–5 locate the line
   to about a working row (``k`` image rows: 8 at 1080p); the reduction's sampling
   and a brightness ramp under the edge (haze brightening the sea toward the horizon)
   put it up to 2 px low at 1080p. So the line is refined on the original pixels: the
   columns are grouped into at most 160 bins; each bin's mean luma profile across the
   line (columns aligned on the row nearest the line, ±(1.25 k + 1) rows searched)
   gives the edge row as the vertex of the parabola through the three central
   differences about the gradient peak of the strip's polarity (exact for a step that
   a pixel averages over its area or point-samples, within a few hundredths of a pixel
   under a lens blur, and, unlike the area- or moment-preserving edge, hardly pulled
   by a ramp on either side); bins whose step ``|a − b|`` (the mean levels beyond the
   transition) is under 5 times their profile noise are dropped; a robust line goes
   through the rest (lines through pairs of bins and the coarse line as starts, then
   IRLS with Tukey's biweight, cut-off from the MAD within 1–2 px, weights
   ``min(|a − b|, median)`` so that a dark hull is no better evidence than the
   horizon). The refined line may
   move the ends by at most ``2 k + 1`` px and needs at least 30 % of the bins within
   its cut-off; otherwise the coarse line stands. If the refined line holds less than
   half the bins (not one straight edge: e.g. a line through a hull on one side and
   the horizon on the other), a candidate with a better ``q · prior`` that crosses it
   inside the image and does hold half the bins replaces it.
6b. **The straightest edge.** A refined line that holds under 80 % of the bins may join
   two edges: the sky/sea edge on the open side and the top of a coast that sits on the
   horizon on the other (the coast's own water line, the sea's true edge there, is a
   weak edge of the other polarity and seldom a candidate). The line through the most
   bin edge points within 0.5 px (every pair a quarter of the width apart tried, then a
   least-squares fit to its points; at least a quarter of the points, spanning a quarter
   of the width) replaces it when it moves an end by more than 2 px and neither up by
   more than 1 % of the height (a coast on the horizon lies above the sea's edge, never
   below it; the refined line's far end, extrapolated, may lie a little low), keeps the
   tilt limits, and has the higher region score (step 4), each score weighed by the
   line's prior (a tracked horizon decides a close call for the line it continues):
   the straight sky/sea part, extended across the coast. Where the coarse line meets
   the sky/sea edge only near one border, the horizon beyond lies outside the bins'
   search window: if the bins give no such line, each bin's strongest edge of the
   refined line's polarity from 2 px above it to 8 % of the height below it is taken
   instead, and the straightest line through those is tried the same way.

The thresholds were chosen on synthetic scenes and checked on six real images, a
real thermal clip and rendered footage (see the tests); the confidence is a score,
not a probability.

The line found is the upper edge of the visible sea. Where the sea ends at the sky
this is the horizon (on rendered footage within 0.05 px of the painted boundary); at
a coast it is the coast's water line, at or below the horizon; in a harbour it is the
water line of the nearest piers or hulls, which can lie some pixels below the true
(IMU) horizon.

An image without contrast (all black, all white), with no straight edge across it, or
with no sea-like region below any candidate (camera pointing down at the sea or up at
the sky) gives ``found = False`` and a low confidence; the returned line is then the
best guess (or the image centre row if there is none).

Pixel coordinates: x right, y down, origin at the centre of the top-left pixel (as in
INTERFACES.md, "Horizon JSON").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from seawatch.camera.horizon import HorizonLine, horizon_line
from seawatch.camera.pinhole import PinholeCamera
from seawatch.filters.kalman import KalmanFilter
from seawatch.models.kinematic import constant_velocity
from seawatch.vision.planes import image_array

__all__ = [
    "HorizonEstimate",
    "HorizonTracker",
    "detect_horizon",
    "sea_mask",
]


# --------------------------------------------------------------------------------------
# result
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class HorizonEstimate:
    """A horizon line in one image.

    The line passes through ``(x0, y0)`` and ``(x1, y1)``, its points at the left and
    right image borders (``x0 = 0``, ``x1 = width − 1``) [px]; x right, y down, origin at
    the centre of the top-left pixel. ``rho`` [px] and ``theta`` [rad] are the same line
    in OpenCV's Hough form ``x cos θ + y sin θ = ρ`` with θ in [0, π) (as
    :class:`seawatch.camera.HorizonLine`).

    Attributes:
        found: whether a horizon was detected (``confidence ≥`` the detector's threshold).
        x0, y0, x1, y1: the line at the left and right borders [px].
        confidence: detection confidence in [0, 1] [-].
        rho: Hough distance from the pixel origin [px].
        theta: Hough normal angle [rad].
        width, height: size of the image the line belongs to [px].
    """

    found: bool
    x0: float
    y0: float
    x1: float
    y1: float
    confidence: float
    rho: float
    theta: float
    width: int
    height: int

    @classmethod
    def from_endpoints(
        cls,
        y0: float,
        y1: float,
        width: int,
        height: int,
        *,
        found: bool = True,
        confidence: float = 1.0,
    ) -> HorizonEstimate:
        """The line through (0, y0) and (width − 1, y1) [px] of a ``width × height`` image."""
        if not (isinstance(width, int | np.integer) and width >= 2):
            raise ValueError(f"width: expected an integer >= 2 px, got {width!r}")
        if not (isinstance(height, int | np.integer) and height >= 2):
            raise ValueError(f"height: expected an integer >= 2 px, got {height!r}")
        if not (math.isfinite(y0) and math.isfinite(y1)):
            raise ValueError(f"y0, y1: expected finite rows, got {y0!r}, {y1!r}")
        if not (0.0 <= confidence <= 1.0):
            raise ValueError(f"confidence: expected a value in [0, 1], got {confidence!r}")
        x1 = float(width - 1)
        line = HorizonLine.from_points((0.0, float(y0)), (x1, float(y1)))
        return cls(
            found=bool(found),
            x0=0.0,
            y0=float(y0),
            x1=x1,
            y1=float(y1),
            confidence=float(confidence),
            rho=float(line.rho),
            theta=float(line.theta),
            width=int(width),
            height=int(height),
        )

    @property
    def slope(self) -> float:
        """dy/dx of the line [px/px]."""
        return (self.y1 - self.y0) / (self.x1 - self.x0)

    @property
    def offset(self) -> float:
        """Row of the line at the centre column ``(width − 1) / 2`` [px]."""
        return 0.5 * (self.y0 + self.y1)

    @property
    def tilt(self) -> float:
        """Angle of the line from the image x axis, positive clockwise on screen [rad]."""
        return math.atan(self.slope)

    @property
    def line(self) -> HorizonLine:
        """The line as a :class:`seawatch.camera.HorizonLine` (observed pixels).

        For :func:`seawatch.camera.attitude_from_horizon` with a camera with lens
        distortion, pass ``((x0, y0), (x1, y1))`` instead, which is undistorted there.
        """
        return HorizonLine.from_points((self.x0, self.y0), (self.x1, self.y1))

    @property
    def points(self) -> NDArray[np.float64]:
        """((x0, y0), (x1, y1)) as a (2, 2) array [px]."""
        return np.array([[self.x0, self.y0], [self.x1, self.y1]])

    def y_at(self, x: ArrayLike) -> NDArray[np.float64]:
        """Row(s) of the line at column(s) ``x`` [px]."""
        xa = np.asarray(x, dtype=np.float64)
        return self.y0 + self.slope * (xa - self.x0)

    def to_dict(self) -> dict[str, Any]:
        """``found, x0, y0, x1, y1, confidence`` as in INTERFACES.md (Horizon JSON)."""
        return {
            "found": self.found,
            "x0": self.x0,
            "y0": round(self.y0, 3),
            "x1": self.x1,
            "y1": round(self.y1, 3),
            "confidence": round(self.confidence, 4),
        }


def sea_mask(
    shape: tuple[int, ...], estimate: HorizonEstimate, *, margin: float = 0.0
) -> NDArray[np.bool_]:
    """Boolean mask of the sea: pixels strictly below the horizon line.

    ``shape`` is the image shape ((H, W) or (H, W, C)); the line is rescaled if the
    estimate was made on an image of another size. A pixel (row v, column u) is sea
    when ``v > y(u) − margin`` [px] (a positive ``margin`` also takes ``margin`` rows
    above the line, e.g. for the superstructure of ships on the horizon). If the
    horizon was not found the mask is all False.
    """
    if len(shape) < 2 or shape[0] < 1 or shape[1] < 1:
        raise ValueError(f"shape: expected (H, W) or (H, W, C), got {shape!r}")
    h, w = int(shape[0]), int(shape[1])
    if not math.isfinite(margin):
        raise ValueError(f"margin: expected a finite number of pixels, got {margin!r}")
    if not estimate.found:
        return np.zeros((h, w), dtype=bool)
    sx = w / estimate.width
    sy = h / estimate.height
    u = np.arange(w, dtype=np.float64)
    y_line = (estimate.y_at((u + 0.5) / sx - 0.5) + 0.5) * sy - 0.5 - margin
    v = np.arange(h, dtype=np.float64)[:, None]
    return v > y_line[None, :]


# --------------------------------------------------------------------------------------
# detector
# --------------------------------------------------------------------------------------

_STRIPS = 32  # vertical strips of the Hough stage
_TUKEY_C = 1.5  # [working px] scale of the IRLS biweight and of the inlier test
_REGION_SCALE = 0.5  # [feature-spread units] region score giving region' = 1
_PRIOR_SIGMA = 0.05  # [image heights] width of the previous-line prior
_LOWEST_RATIO = 0.5  # candidates with quality >= this × the best compete for "lowest"
_REGION_MIN = 0.03  # [feature-spread units] least region score of a sea horizon
_CONTRAST_MIN = 0.5  # [σ_g] least median edge strength along a sea horizon


@njit(cache=True, nogil=True, fastmath=True)
def _hough(P: np.ndarray, xs: np.ndarray, xc: float, slopes: np.ndarray, m: float) -> np.ndarray:
    """Hough accumulators E[k, i, c] for the two gradient polarities k = (+, −) (step 2).

    ``V_s(y) = max(±P_s(y), 0) / (max_y max(±P_s, 0) + 4 m)``, then
    ``E[k, i, c] = mean_s V_s(c + t_i (x_s − x_c))`` with linear interpolation between
    rows; rows outside the image contribute 0.
    """
    h, n_strips = P.shape
    V = np.zeros((2, n_strips, h + 2), dtype=np.float32)  # one zero row either side
    for s in range(n_strips):
        mp = 0.0
        mn = 0.0
        for y in range(h):
            v = P[y, s]
            mp = max(mp, v)
            mn = max(mn, -v)
        for y in range(h):
            v = P[y, s]
            V[0, s, y + 1] = max(v, 0.0) / (mp + 4.0 * m)
            V[1, s, y + 1] = max(-v, 0.0) / (mn + 4.0 * m)
    out = np.zeros((2, slopes.shape[0], h), dtype=np.float32)
    for i in range(slopes.shape[0]):
        for s in range(n_strips):
            off = slopes[i] * (xs[s] - xc)
            r = math.floor(off)
            f = np.float32(off - r)
            g = np.float32(1.0) - f
            # rows c with 0 <= c + off <= h - 1; padded V covers the two border rows
            c0 = max(0, -r - 1)
            c1 = min(h, h - r)
            if c1 <= c0:
                continue
            for k in range(2):
                src = V[k, s, c0 + r + 1 : c1 + r + 2]  # rows c0 + r + 1 …, as views so
                dst = out[k, i, c0:c1]  # that the loop runs on contiguous memory
                for m in range(c1 - c0):
                    dst[m] += g * src[m] + f * src[m + 1]
    out *= np.float32(1.0 / n_strips)
    return out


@njit(cache=True, nogil=True)
def _refine(
    gy: np.ndarray,
    P: np.ndarray,
    sw: float,
    c: float,
    t: float,
    noise: float,
    noise_p: float,
    search: float,
    tukey: float,
) -> tuple[float, float, float, float, float, bool]:
    """Fit a line to the per-column edge points near (c, t) (step 3).

    Each strip's polarity is the sign of its mean gradient ``P_s`` at the line (so a
    horizon whose polarity changes along its length, sky/sea on one side and
    coast/sea on the other, is followed throughout). Returns ``(c, t, quality, support,
    contrast, ok)``: quality = mean over columns of ``inlier · (1 − exp(−s / 3 σ_g))``.
    """
    h, w = gy.shape
    n_strips = P.shape[1]
    xc = (w - 1) / 2.0
    py = np.zeros(w)
    st = np.zeros(w)
    pol = np.zeros(n_strips)
    search0 = search
    for _outer in range(3):
        r = math.ceil(search)
        for s in range(n_strips):
            y = c + t * ((s + 0.5) * sw - 0.5 - xc)
            yi = math.floor(y + 0.5)
            best = 0.0
            for yy in range(max(0, yi - 1), min(h, yi + 2)):
                if abs(P[yy, s]) > abs(best):
                    best = P[yy, s]
            pol[s] = 1.0 if best > 0 else (-1.0 if best < 0 else 0.0)
        for x in range(w):
            s = min(int((x + 0.5) / sw), n_strips - 1)
            p = pol[s]
            yc = c + t * (x - xc)
            lo = max(1, math.floor(yc) - r)
            hi = min(h - 2, math.ceil(yc) + r)
            bv = 0.0
            by = -1
            for yy in range(lo, hi + 1):
                v = p * gy[yy, x] if p != 0.0 else abs(gy[yy, x])
                if v > bv:
                    bv = v
                    by = yy
            if by < 0:
                st[x] = 0.0
                py[x] = yc
                continue
            if p != 0.0:
                vm = p * gy[by - 1, x]
                vp = p * gy[by + 1, x]
            else:
                vm = abs(gy[by - 1, x])
                vp = abs(gy[by + 1, x])
            den = vm - 2.0 * bv + vp
            delta = 0.5 * (vm - vp) / den if den < 0.0 else 0.0
            py[x] = by + min(0.5, max(-0.5, delta))
            st[x] = bv
        # iteratively re-weighted least squares, Tukey biweight
        for _it in range(4):
            sw_ = 0.0
            sx = 0.0
            sy = 0.0
            for x in range(w):
                u = (py[x] - (c + t * (x - xc))) / (2.0 * tukey)
                if abs(u) < 1.0 and st[x] > 0.0:
                    wt = (1.0 - u * u) ** 2 * st[x] / noise
                    sw_ += wt
                    sx += wt * (x - xc)
                    sy += wt * py[x]
            if sw_ <= 0.0:
                return c, t, 0.0, 0.0, 0.0, False
            xm = sx / sw_
            ym = sy / sw_
            sxx = 0.0
            sxy = 0.0
            for x in range(w):
                u = (py[x] - (c + t * (x - xc))) / (2.0 * tukey)
                if abs(u) < 1.0 and st[x] > 0.0:
                    wt = (1.0 - u * u) ** 2 * st[x] / noise
                    sxx += wt * (x - xc - xm) ** 2
                    sxy += wt * (x - xc - xm) * (py[x] - ym)
            if sxx <= 0.0:
                return c, t, 0.0, 0.0, 0.0, False
            t = sxy / sxx
            c = ym - t * xm
        search = max(2.0, 0.5 * search)
    # final pass: the edge point must be the strongest within the initial search window
    r = math.ceil(search0)
    n_in = 0
    q = 0.0
    near = np.zeros(w)
    for x in range(w):
        p = pol[min(int((x + 0.5) / sw), n_strips - 1)]
        yc = c + t * (x - xc)
        lo = max(1, math.floor(yc) - r)
        hi = min(h - 2, math.ceil(yc) + r)
        bv = 0.0
        by = -1
        for yy in range(lo, hi + 1):
            v = p * gy[yy, x] if p != 0.0 else abs(gy[yy, x])
            if v > bv:
                bv = v
                by = yy
        if by >= 0 and abs(by - yc) <= tukey + 0.5:
            near[x] = bv
            if bv > 3.0 * noise:
                n_in += 1
                q += 1.0 - math.exp(-bv / (3.0 * noise))
    # prominence: the strip-mean gradient at the line against the same in the rows on
    # its quieter side (sea texture gives many similar parallel "lines", a horizon one)
    coh = 0.0
    inner = 3
    outer = max(8, int(0.06 * h))
    for s in range(n_strips):
        y = c + t * ((s + 0.5) * sw - 0.5 - xc)
        yi = math.floor(y + 0.5)
        if yi < 0 or yi >= h:
            continue
        best = 0.0
        for yy in range(max(0, yi - 1), min(h, yi + 2)):
            best = max(best, abs(P[yy, s]))
        bg_a = 0.0
        bg_b = 0.0
        na = 0
        nb = 0
        for d in range(inner, outer + 1):
            if yi - d >= 0:
                bg_a += abs(P[yi - d, s])
                na += 1
            if yi + d < h:
                bg_b += abs(P[yi + d, s])
                nb += 1
        bg_a = bg_a / na if na > 0 else 0.0
        bg_b = bg_b / nb if nb > 0 else 0.0
        bg = min(bg_a, bg_b)
        ratio = best / (bg + 0.5 * noise_p)
        coh += 1.0 - math.exp(-max(0.0, ratio - 1.0) / 3.0)
    q *= coh / n_strips
    contrast = np.median(near) / noise
    return c, t, q / w, n_in / w, contrast, True


@njit(cache=True, nogil=True)
def _region(
    cum: np.ndarray, c: float, t: float, xs: np.ndarray, xc: float, band: int, gap: int
) -> float:
    """Median over strips of ``‖A − B‖ − ‖B − B₂‖`` (step 4): A, B the bands just above
    and below the line, B₂ the next ``2 band`` rows below B (mean features)."""
    h = cum.shape[0] - 1
    n_strips = cum.shape[1]
    nf = cum.shape[2]
    vals = np.empty(n_strips)
    n = 0
    for s in range(n_strips):
        yi = math.floor(c + t * (xs[s] - xc) + 0.5)
        a0 = yi - gap - band
        a1 = yi - gap
        b0 = yi + gap
        b1 = yi + gap + band
        if a0 < 0 or b1 > h:
            continue
        c1 = min(h, b1 + 2 * band)
        dab = 0.0
        dbb = 0.0
        for f in range(nf):
            A = (cum[a1, s, f] - cum[a0, s, f]) / (a1 - a0)
            B = (cum[b1, s, f] - cum[b0, s, f]) / (b1 - b0)
            dab += (A - B) ** 2
            if c1 - b1 >= 2:
                B2 = (cum[c1, s, f] - cum[b1, s, f]) / (c1 - b1)
                dbb += (B - B2) ** 2
        vals[n] = math.sqrt(dab) - math.sqrt(dbb)
        n += 1
    if n < max(3, n_strips // 4):
        return 0.0
    return np.median(vals[:n])


# --------------------------------------------------------------------------------------
# full-resolution sub-pixel refinement (step 6)
# --------------------------------------------------------------------------------------

_FINE_BINS = 160  # most column bins of the full-resolution refinement
_FINE_SNR = 5.0  # least |step| / profile noise of a bin that enters the line fit
_FINE_SCALE = (1.0, 2.0)  # [full px] bounds of the Tukey cut-off of the final line fit
_FINE_MIN_SUPPORT = 0.3  # least fraction of the bins on the fine line for it to be used
_FINE_GOOD = 0.5  # a fine line with less support makes crossing candidates compete
_SAME_LINE = 2.0  # [working px] candidates closer than this (mean |Δy|) are one line
_STRAIGHT_BELOW = 0.8  # step 6b runs where the refined line holds fewer of the bins
_STRAIGHT_TOL = 0.5  # [full px] an edge point within this of a line is on it (step 6b)
_STRAIGHT_MIN = 0.25  # least fraction of the edge points on the straightest line
_STRAIGHT_SPAN = 0.25  # least fraction of the width its points (and a hypothesis) span
_STRAIGHT_MOVE = 2.0  # [full px] it replaces the refined line only if an end moves more
_STRAIGHT_ABOVE = 0.01  # [image heights] nor if an end rises more (a coast's top)
_STRAIGHT_DEPTH = 0.08  # [image heights] how far below the line step 6b looks after that
_LUMA_BGR = np.array([0.114, 0.587, 0.299])  # ITU-R BT.601 weights (OpenCV's BGR2GRAY)
_LUMA_GREY = np.array([1.0])
_BGR2GREY = cv2.COLOR_BGR2GRAY


@njit(cache=True, nogil=True)
def _fine_profiles(
    img: np.ndarray, wts: np.ndarray, y0: float, t: float, R: int, bin_w: int, nb: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Mean luma profiles across the line in column bins (step 6).

    Column ``x`` contributes its rows ``r0(x) − R … r0(x) + R``, ``r0(x)`` the row
    nearest the line ``y0 + t x`` [px], to the profile of bin ``x // bin_w`` (luma =
    ``Σ_ch wts[ch] img[r, x, ch]``). Returns ``prof`` (nb, 2R + 1) and, per bin, the mean
    ``r0`` and the mean column [px] and the number of columns that contributed (0 where
    the band leaves the image).
    """
    H, W, C = img.shape
    n = 2 * R + 1
    prof = np.zeros((nb, n))
    rbar = np.zeros(nb)
    xbar = np.zeros(nb)
    cnt = np.zeros(nb)
    r0 = np.empty(W, dtype=np.int64)
    for x in range(W):
        r0[x] = math.floor(y0 + t * x + 0.5)
        if r0[x] - R < 0 or r0[x] + R > H - 1:
            r0[x] = -1
            continue
        b = min(x // bin_w, nb - 1)
        rbar[b] += r0[x]
        xbar[b] += x
        cnt[b] += 1.0
    # row by row: along a profile row, neighbouring columns are neighbours in memory
    w0 = wts[0]
    w1 = wts[1] if C > 2 else 0.0
    w2 = wts[2] if C > 2 else 0.0
    for k in range(n):
        for b in range(nb):
            acc = 0.0
            for x in range(b * bin_w, min(W, (b + 1) * bin_w)):
                if r0[x] < 0:
                    continue
                r = r0[x] - R + k
                if C > 2:
                    acc += w0 * img[r, x, 0] + w1 * img[r, x, 1] + w2 * img[r, x, 2]
                else:
                    acc += w0 * img[r, x, 0]
            prof[b, k] = acc
    for b in range(nb):
        if cnt[b] > 0:
            for k in range(n):
                prof[b, k] /= cnt[b]
            rbar[b] /= cnt[b]
            xbar[b] /= cnt[b]
    return prof, rbar, xbar, cnt


@njit(cache=True, nogil=True)
def _fine_peaks(prof: np.ndarray, pol: np.ndarray, R: int, S: int) -> tuple[np.ndarray, np.ndarray]:
    """Per bin: the row of the strongest central difference of the bin's polarity
    ``pol`` (+1 brighter below, −1 darker below, 0 either) within ±S rows of the profile
    centre, and the RMS width [px] of that gradient peak (over the contiguous run above
    10 % of the peak); −1 and NaN where there is none."""
    nb, n = prof.shape
    peak = np.full(nb, -1, dtype=np.int64)
    width = np.full(nb, np.nan)
    for b in range(nb):
        p = prof[b]
        s = pol[b]
        best = 0.0
        kb = -1
        for k in range(max(1, R - S), min(n - 1, R + S + 1)):
            d = 0.5 * (p[k + 1] - p[k - 1])
            v = s * d if s != 0.0 else abs(d)
            if v > best:
                best = v
                kb = k
        if kb < 0:
            continue
        peak[b] = kb
        sw = 0.0
        s1 = 0.0
        s2 = 0.0
        for direction in (-1, 1):
            k = kb if direction < 0 else kb + 1
            while 1 <= k < n - 1:
                d = 0.5 * (p[k + 1] - p[k - 1])
                v = s * d if s != 0.0 else abs(d)
                if v < 0.1 * best:
                    break
                sw += v
                s1 += v * (k - kb)
                s2 += v * (k - kb) ** 2
                k += direction
        mu = s1 / sw
        width[b] = math.sqrt(max(s2 / sw - mu * mu, 0.0))
    return peak, width


@njit(cache=True, nogil=True)
def _fine_edges(
    prof: np.ndarray, peak: np.ndarray, pol: np.ndarray, g: int, m: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sub-pixel edge row of each bin's profile (profile coordinates), the step
    ``D = a − b`` there and the profile noise of the bin (step 6).

    The edge is the vertex of the parabola through the three central differences
    ``d_k = (p_{k+1} − p_{k−1}) / 2`` (signed by the bin's polarity) about the peak
    ``k_p``: ``e = k_p + (d_{k−1} − d_{k+1}) / (2 (d_{k−1} − 2 d_k + d_{k+1}))``. It is
    exact for a step that a pixel averages over its area (the three differences are
    then ``(1 − f) D/2, D/2, f D/2`` for the fraction ``f`` of the edge pixel above the
    line, so ``e = k_p − ½ + f``) and for a point-sampled step (``0, D/2, D/2``:
    ``e = k_p + ½``), and within a few hundredths of a pixel under a Gaussian lens blur
    up to σ = 2 px; unlike the mean of the gradient (the area-preserving edge) it is
    hardly pulled by a brightness ramp on either side (haze brightening the sea toward
    the horizon: 0.1 px for a ramp of a quarter of the step, against 0.25 px).
    The levels ``a`` (above) and ``b`` (below) are the mean profile over the ``m`` rows
    beyond ``e ± g`` (a transition half-window ``g``), the noise the RMS of those rows
    about their means. NaN where the windows leave the profile or the step has not the
    bin's polarity (pol > 0: brighter below, D < 0).
    """
    nb, n = prof.shape
    e_out = np.full(nb, np.nan)
    d_out = np.zeros(nb)
    noise = np.full(nb, np.nan)
    for b in range(nb):
        kp = peak[b]
        lo = kp - g
        hi = kp + g
        if kp < 2 or kp > n - 3 or lo - m < 0 or hi + m > n - 1:
            continue
        p = prof[b]
        a = 0.0
        bl = 0.0
        for k in range(m):
            a += p[lo - m + k]
            bl += p[hi + 1 + k]
        a /= m
        bl /= m
        D = a - bl
        if D == 0.0 or (pol[b] > 0.0 and D > 0.0) or (pol[b] < 0.0 and D < 0.0):
            continue
        sg = -1.0 if D > 0.0 else 1.0  # brighter below: positive differences
        dm = sg * 0.5 * (p[kp] - p[kp - 2])
        d0 = sg * 0.5 * (p[kp + 1] - p[kp - 1])
        dp = sg * 0.5 * (p[kp + 2] - p[kp])
        den = dm - 2.0 * d0 + dp
        delta = 0.5 * (dm - dp) / den if den < 0.0 else 0.0
        var = 0.0
        for k in range(m):
            var += (p[lo - m + k] - a) ** 2 + (p[hi + 1 + k] - bl) ** 2
        e_out[b] = kp + min(0.5, max(-0.5, delta))
        d_out[b] = D
        noise[b] = math.sqrt(var / (2 * m))
    return e_out, d_out, noise


@njit(cache=True, nogil=True)
def _tukey_score(
    x: np.ndarray, y: np.ndarray, w: np.ndarray, c: float, t: float, cut: float
) -> float:
    """``Σ w_i (1 − u_i²)²`` over ``|u_i| < 1``, ``u_i = (y_i − c − t x_i) / cut``."""
    sc = 0.0
    for i in range(x.shape[0]):
        u = (y[i] - c - t * x[i]) / cut
        if abs(u) < 1.0:
            sc += w[i] * (1.0 - u * u) ** 2
    return sc


@njit(cache=True, nogil=True)
def _robust_line(
    x: np.ndarray,
    y: np.ndarray,
    w: np.ndarray,
    c0: float,
    t0: float,
    s_min: float,
    s_max: float,
    half: float,
    dev: float,
) -> tuple[float, float, int]:
    """Robust weighted line ``y = c + t x`` (x centred by the caller) (step 6).

    Start: the best of the coarse line ``(c0, t0)`` and the lines through pairs of (up
    to 24 evenly spread) points at least a quarter of the span apart, by the weighted
    Tukey score with cut-off ``s_max``; then iteratively re-weighted least squares with
    Tukey's biweight, its cut-off ``4.685 × 1.4826 × MAD`` of the residuals inside the
    current cut-off, kept within ``[s_min, s_max]`` [px]. Returns ``(c, t, inliers)``,
    the number of points inside the final cut-off.
    """
    n = x.shape[0]
    best_c, best_t = c0, t0
    best = _tukey_score(x, y, w, c0, t0, s_max)
    step = max(1, n // 24)
    span = x[n - 1] - x[0]
    for i in range(0, n, step):
        for j in range(i + step, n, step):
            dx = x[j] - x[i]
            if dx < 0.25 * span:
                continue
            t = (y[j] - y[i]) / dx
            c = y[i] - t * x[i]
            if abs(c - c0) + half * abs(t - t0) > dev:
                continue
            sc = _tukey_score(x, y, w, c, t, s_max)
            if sc > best:
                best, best_c, best_t = sc, c, t
    c, t = best_c, best_t
    cut = s_max
    res = np.empty(n)
    for _it in range(10):
        k = 0
        for i in range(n):
            r = abs(y[i] - c - t * x[i])
            if r < cut:
                res[k] = r
                k += 1
        if k < 2:
            break
        cut = min(max(4.685 * 1.4826 * np.median(res[:k]), s_min), s_max)
        sw = 0.0
        sx = 0.0
        sy = 0.0
        for i in range(n):
            u = (y[i] - c - t * x[i]) / cut
            if abs(u) < 1.0:
                wt = w[i] * (1.0 - u * u) ** 2
                sw += wt
                sx += wt * x[i]
                sy += wt * y[i]
        if sw <= 0.0:
            break
        mx = sx / sw
        my = sy / sw
        sxx = 0.0
        sxy = 0.0
        for i in range(n):
            u = (y[i] - c - t * x[i]) / cut
            if abs(u) < 1.0:
                wt = w[i] * (1.0 - u * u) ** 2
                sxx += wt * (x[i] - mx) ** 2
                sxy += wt * (x[i] - mx) * (y[i] - my)
        if sxx <= 0.0:
            break
        t_new = sxy / sxx
        c_new = my - t_new * mx
        moved = abs(c_new - c) + 0.5 * span * abs(t_new - t)
        c, t = c_new, t_new
        if moved < 1e-3:
            break
    inl = 0
    for i in range(n):
        if abs(y[i] - c - t * x[i]) < cut:
            inl += 1
    return c, t, inl


@njit(cache=True, nogil=True)
def _strip_polarity(
    P: np.ndarray, x: np.ndarray, sx: float, sw: float, c: float, t: float
) -> np.ndarray:
    """Sign of the strip-mean gradient ``P`` (working rows × strips) at the working line
    ``c + t (x_w − x_c)``, largest magnitude of the three nearest rows, at the full-res
    columns ``x`` (+1: brighter below)."""
    h, n_strips = P.shape
    xc = 0.5 * (n_strips * sw - 1.0)
    out = np.zeros(x.shape[0])
    for i in range(x.shape[0]):
        xw = (x[i] + 0.5) / sx - 0.5
        s = min(max(int((xw + 0.5) / sw), 0), n_strips - 1)
        yi = math.floor(c + t * ((s + 0.5) * sw - 0.5 - xc) + 0.5)
        best = 0.0
        for yy in range(max(0, yi - 1), min(h, yi + 2)):
            if abs(P[yy, s]) > abs(best):
                best = P[yy, s]
        out[i] = 1.0 if best > 0.0 else (-1.0 if best < 0.0 else 0.0)
    return out


@njit(cache=True, nogil=True)
def _fine_points(
    prof: np.ndarray,
    rbar: np.ndarray,
    xbar: np.ndarray,
    pol: np.ndarray,
    R: int,
    S: int,
    g_max: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Step 6's edge points of the bin profiles: each bin's edge row (:func:`_fine_peaks`,
    :func:`_fine_edges`; ``rbar`` the bins' mean rows [px] at the profile centre) where
    its step ``|D|`` is at least ``_FINE_SNR`` times its profile noise (or the median
    noise, if larger). Returns the points' columns and rows [px] and ``|D|``, in bin
    order; none when under 4 bins have an edge."""
    nb = prof.shape[0]
    none = np.empty(0)
    peak, width = _fine_peaks(prof, pol, R, S)
    wid = np.empty(nb)
    k = 0
    for b in range(nb):
        if peak[b] >= 0:
            wid[k] = width[b]
            k += 1
    if k < 4:
        return none, none, none
    # transition half-window: 2.5 RMS widths of the edge, at least 2 px; levels over
    # max(3, g) rows beyond it
    g = min(max(math.ceil(2.5 * np.median(wid[:k]) + 0.5), 2), g_max)
    e, D, noise = _fine_edges(prof, peak, pol, g, max(3, g))
    k = 0
    for b in range(nb):
        if np.isfinite(e[b]):
            wid[k] = noise[b]
            k += 1
    if k < 4:
        return none, none, none
    noise_ref = np.median(wid[:k])
    xb = np.empty(nb)
    yb = np.empty(nb)
    wb = np.empty(nb)
    n = 0
    for b in range(nb):
        if np.isfinite(e[b]) and abs(D[b]) >= _FINE_SNR * max(noise[b], noise_ref):
            xb[n] = xbar[b]
            yb[n] = rbar[b] - R + e[b]
            wb[n] = abs(D[b])
            n += 1
    return xb[:n], yb[:n], wb[:n]


@njit(cache=True, nogil=True)
def _fine_fit(
    prof: np.ndarray,
    rbar: np.ndarray,
    xbar: np.ndarray,
    cnt: np.ndarray,
    pol: np.ndarray,
    R: int,
    S: int,
    g_max: int,
    y0: float,
    t: float,
    xm: float,
    s_max: float,
    dev: float,
) -> tuple[float, float, float]:
    """Step 6 on the bin profiles: the bins' edge points (:func:`_fine_points`) and the
    robust line through them
    (:func:`_robust_line`, weights ``min(|D|, median |D|)``: a dark hull is no better
    evidence than the horizon), which may move the ends of the coarse line ``y0 + t x``
    by at most ``dev`` [px]. Returns ``(n0, n1, support, x, y)``: the refined rows at the
    first and last column [px] (NaN where there are too few bins or the fit moved
    further), the fraction of the bins with columns that lie within the fit's cut-off,
    and the bins' edge points (column, row) [px] that entered the fit."""
    nb = prof.shape[0]
    n_used = 0
    for b in range(nb):
        if cnt[b] > 0:
            n_used += 1
    x, y, wb = _fine_points(prof, rbar, xbar, pol, R, S, g_max)
    n = x.shape[0]
    if n < 4:
        return np.nan, np.nan, 0.0, np.empty(0), np.empty(0)
    xb = x - xm
    cap = np.median(wb)
    for i in range(n):
        wb[i] = min(wb[i], cap)
    c, tt, inliers = _robust_line(xb, y, wb, y0 + t * xm, t, _FINE_SCALE[0], s_max, xm, dev)
    support = inliers / max(n_used, 1)
    n0 = c - tt * xm
    n1 = c + tt * xm
    xs, ys = xb + xm, y
    if max(abs(n0 - y0), abs(n1 - (y0 + 2.0 * t * xm))) > dev:
        return np.nan, np.nan, support, xs, ys
    return n0, n1, support, xs, ys


def _fine_bins(width: int) -> tuple[int, int]:
    """Step 6's column bins of an image ``width`` [px] wide: (bin width, bin count), at
    most :data:`_FINE_BINS` bins of equal width (the last one shorter)."""
    nb = min(_FINE_BINS, max(8, width // 2))
    bin_w = -(-width // nb)
    return bin_w, -(-width // bin_w)


def _line_profiles(
    arr: np.ndarray, y0: float, y1: float, R: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Step 6's column-bin profiles (:func:`_fine_profiles`, bins :func:`_fine_bins`)
    of ``arr`` across the line (y0, y1) [full px], ``R`` px either side: from the band of
    rows around the line as float32 luma (one compiled kernel for every input type; for
    colour, vectorised luma is cheaper than weighting the channels pixel by pixel), or,
    for a steep line in a colour image, from the whole image. Returns ``(prof, rbar,
    xbar, cnt)`` with ``rbar`` in image rows [px]."""
    H, W = arr.shape[:2]
    t = (y1 - y0) / (W - 1)
    bin_w, nb = _fine_bins(W)
    top = max(0, math.floor(min(y0, y1) + 0.5) - R)
    bottom = min(H, math.floor(max(y0, y1) + 0.5) + R + 1)
    if arr.ndim == 2 or 0 < bottom - top <= 3 * (2 * R + 1):
        band = arr[top:bottom] if arr.ndim == 2 else cv2.cvtColor(arr[top:bottom], _BGR2GREY)
        img, wts, y_top = band.astype(np.float32).reshape(-1, W, 1), _LUMA_GREY, top
    else:
        img, wts, y_top = arr, _LUMA_BGR, 0  # a steep line in a colour image
    prof, rbar, xbar, cnt = _fine_profiles(img, wts, y0 - y_top, t, R, bin_w, nb)
    return prof, rbar + y_top, xbar, cnt


@dataclass(frozen=True)
class _Fine:
    """Step 6's refined line: rows ``y0``, ``y1`` at the first and last column [px], the
    fraction of the bins on it (``support``) and the bins' edge points ``x``, ``y`` [px]."""

    y0: float
    y1: float
    support: float
    x: np.ndarray
    y: np.ndarray
    polarity: float  # the bins' majority polarity (+1: brighter below)


def _straightest(x: np.ndarray, y: np.ndarray, width: int) -> tuple[float, float] | None:
    """Step 6b: the line through the most edge points ``(x, y)`` [px] within
    :data:`_STRAIGHT_TOL` of it (every pair of points at least :data:`_STRAIGHT_SPAN` of
    the ``width`` apart as a hypothesis, exhaustively: deterministic), refitted by least
    squares to its points; its rows at the first and last column [px], or None when it
    holds under :data:`_STRAIGHT_MIN` of the points or they span under
    :data:`_STRAIGHT_SPAN` of the width.

    Hand-written: a deterministic exhaustive RANSAC over at most 160 bins (12,720 pairs,
    one vectorised residual matrix); OpenCV's and scikit-image's RANSAC are randomised."""
    n = x.size
    if n < 4:
        return None
    i, j = np.triu_indices(n, 1)
    far = np.abs(x[j] - x[i]) >= _STRAIGHT_SPAN * width
    i, j = i[far], j[far]
    if i.size == 0:
        return None
    t = (y[j] - y[i]) / (x[j] - x[i])
    c = y[i] - t * x[i]
    count = (np.abs(y[None, :] - (c[:, None] + t[:, None] * x[None, :])) <= _STRAIGHT_TOL).sum(1)
    k = int(np.argmax(count))
    on = np.abs(y - (c[k] + t[k] * x)) <= _STRAIGHT_TOL
    if on.sum() < _STRAIGHT_MIN * n or np.ptp(x[on]) < _STRAIGHT_SPAN * width:
        return None
    tt, cc = np.polyfit(x[on], y[on], 1)
    return float(cc), float(cc + tt * (width - 1))


def _fine_line(
    arr: np.ndarray,
    y0: float,
    y1: float,
    P: np.ndarray,
    sx: float,
    sy: float,
    cw: tuple[float, float, float],
) -> _Fine | None:
    """Step 6: the coarse line (y0, y1) [full px] refined on the full-resolution image
    ``arr``: a :class:`_Fine` (the line, its support, the bins' edge points), or None
    (too few bins with an edge near it, too little support, or a correction beyond two
    working rows: keep the coarse line).

    ``P``, ``sx``, ``sy``, ``cw`` are the working image's strip-mean gradients, its
    reduction factors (full px per working px) and the coarse line in working
    coordinates ``(c, t, strip width)``: the expected polarity of each bin is the sign
    of ``P`` at the line; the error of the coarse line is about a working row.
    """
    W = arr.shape[1]
    t = (y1 - y0) / (W - 1)
    S = math.ceil(1.25 * sy) + 1  # search half-range of the edge [px]
    g_max = max(3, math.ceil(sy))  # largest transition half-window [px]
    R = S + 2 * g_max + 1
    prof, rbar, xbar, cnt = _line_profiles(arr, y0, y1, R)
    pol = _strip_polarity(P, xbar, sx, cw[2], cw[0], cw[1])
    dev = 2.0 * sy + 1.0  # largest correction at the ends: two working rows [px]
    s_max = max(_FINE_SCALE[1], 0.25 * sy)
    n0, n1, support, ex, ey = _fine_fit(
        prof, rbar, xbar, cnt, pol, R, S, g_max, y0, t, 0.5 * (W - 1), s_max, dev
    )
    if not (math.isfinite(n0) and support >= _FINE_MIN_SUPPORT):
        return None
    polarity = 1.0 if float(np.sum(pol)) > 0.0 else -1.0
    return _Fine(float(n0), float(n1), float(support), ex, ey, polarity)


def _edges_below(
    arr: np.ndarray, y0: float, y1: float, depth: float, polarity: float, sy: float
) -> tuple[np.ndarray, np.ndarray]:
    """Step 6b's wider search: per column bin, the strongest edge of ``polarity`` (+1:
    brighter below) from 2 px above the line (y0, y1) [full px] to ``depth`` [px] below
    it, with step 6's sub-pixel row and signal-to-noise test; the edge points (column,
    row) [px]. The sea horizon under a coast lies at or below a line along the coast's
    top, as far below as the coast is high."""
    S = math.ceil(0.5 * depth) + 2  # search half-range about the band's middle [px]
    g_max = max(3, math.ceil(sy))
    R = S + 2 * g_max + 1
    prof, rbar, xbar, _ = _line_profiles(arr, y0 + 0.5 * depth, y1 + 0.5 * depth, R)
    pol = np.full(prof.shape[0], polarity)
    x, y, _ = _fine_points(prof, rbar, xbar, pol, R, S, g_max)
    return x, y


def _local_maxima(E: np.ndarray, count: int, rad_t: int, rad_c: int) -> list[tuple[int, int]]:
    """Indices of up to ``count`` best peaks of E with non-maximum suppression."""
    work = E.copy()
    peaks: list[tuple[int, int]] = []
    for _ in range(count):
        i, j = np.unravel_index(int(np.argmax(work)), work.shape)
        if work[i, j] <= 0:
            break
        peaks.append((int(i), int(j)))
        work[max(0, i - rad_t) : i + rad_t + 1, max(0, j - rad_c) : j + rad_c + 1] = 0
    return peaks


@dataclass(frozen=True)
class _Candidate:
    c: float  # row at the centre column [working px]
    t: float  # slope [-]
    quality: float
    support: float
    contrast: float
    region: float
    prior: float = 1.0


def _as_image(image: ArrayLike) -> np.ndarray:
    arr = image_array(image)
    if arr.ndim == 3 and arr.shape[2] == 4:
        arr = arr[:, :, :3]
    H, W = arr.shape[:2]
    if H < 16 or W < 16:
        raise ValueError(f"image: too small for horizon detection ({W}x{H} px, need 16x16)")
    if arr.dtype not in (np.uint8, np.uint16, np.float32):
        arr = arr.astype(np.float32)
    if arr.dtype == np.float32 and not np.isfinite(arr).all():
        raise ValueError("image: contains NaN or inf pixels")
    return np.ascontiguousarray(arr)


def _percentiles(a: np.ndarray, qs: tuple[float, ...], axis: int | None = None) -> np.ndarray:
    """``np.percentile(a, qs, axis=axis)`` (linear interpolation; ``axis`` None, or 0 of a
    2-D array) from one sort (numpy's vectorised sort beats a partition at several
    ranks), without numpy's general-purpose overhead: the same numbers."""
    a = np.asarray(a)
    # the sample runs along the last axis of a C-contiguous (columns, n) array
    b = a.reshape(1, -1) if axis is None else np.ascontiguousarray(a.T)
    n = b.shape[1]
    v = (n - 1) * (np.asarray(qs, dtype=np.float64) / 100.0)
    lo = np.floor(v).astype(np.intp)
    hi = np.minimum(lo + 1, n - 1)
    t = (v - lo)[:, None]
    part = np.sort(b, axis=1)
    x, y = part[:, lo].T, part[:, hi].T
    d = y - x
    out = np.where(t >= 0.5, y - d * (1 - t), x + d * t)
    return out[:, 0] if axis is None else out


def _prepare(arr: np.ndarray, work_width: int) -> tuple[np.ndarray, np.ndarray, float, float]:
    """(luma, colour, sx, sy): working-resolution luma (h, w) and colour (h, w, C) float32,
    both normalised so that the luma's 1st–99th percentiles map to 0–1, and the scale
    factors full/working along x and y."""
    H, W = arr.shape[:2]
    k = max(1, round(W / work_width))
    w, h = max(16, W // k), max(16, H // k)
    if k > 4:
        # bilinear to twice the working size (a 2 × 2 mean every k/2 pixels), then a
        # 2 × 2 area mean: 16 samples per working pixel at a tenth of INTER_AREA's cost
        mid = cv2.resize(arr, (2 * w, 2 * h), interpolation=cv2.INTER_LINEAR)
        small = cv2.resize(mid, (w, h), interpolation=cv2.INTER_AREA).astype(np.float32)
    else:
        small = cv2.resize(arr, (w, h), interpolation=cv2.INTER_AREA).astype(np.float32)
    luma = cv2.cvtColor(small, cv2.COLOR_BGR2GRAY) if small.ndim == 3 else small
    lo, hi = _percentiles(luma[::2, ::2], (1.0, 99.0))
    spread = float(hi - lo)
    scale = np.float32(1.0 / spread if spread > 0 else 0.0)
    luma = (luma - np.float32(lo)) * scale
    colour = (small - np.float32(lo)) * scale if small.ndim == 3 else luma[:, :, None]
    return luma, colour, W / w, H / h


_MIN_CONFIDENCE = 0.3  # default confidence for ``found`` (detect_horizon; the tracker's
# weak-detection floor is a fraction of it)


def detect_horizon(
    image: ArrayLike,
    *,
    previous: HorizonEstimate | None = None,
    camera: PinholeCamera | None = None,
    max_tilt_deg: float = 25.0,
    work_width: int = 256,
    n_candidates: int = 6,
    min_confidence: float = _MIN_CONFIDENCE,
    prior_sigma: float | None = None,
) -> HorizonEstimate:
    """Detect the sea horizon in one image (module docstring: method and scores).

    Args:
        image: (H, W) grey or (H, W, 3|4) BGR(A) pixels; uint8, uint16 or float.
        previous: the estimate of the previous frame; favours nearby lines (a prior,
            not a constraint: a clearly better line elsewhere still wins).
        camera: a camera with a known mounting attitude and height; centres the tilt
            range on its nominal horizon's tilt and favours lines near the nominal
            horizon (as ``previous`` does).
        max_tilt_deg: largest tilt of the line from the image rows [deg] (the camera
            roll range), in (0, 60].
        work_width: working width [px]; the image is reduced by an integer factor to
            about this many columns (speed against precision).
        n_candidates: Hough peaks kept per gradient polarity.
        min_confidence: confidence at and above which ``found`` is True.
        prior_sigma: how far from ``previous`` the line may be expected [px of
            ``previous``'s image] (e.g. a tracker's predicted spread); the prior's
            width σ_p is the smaller of this and 5 % of the height (None: 5 %).

    Returns:
        HorizonEstimate in the pixel coordinates of ``image``.
    """
    if not (isinstance(max_tilt_deg, int | float) and 0 < max_tilt_deg <= 60):
        raise ValueError(f"max_tilt_deg: expected a tilt in (0, 60] degrees, got {max_tilt_deg!r}")
    if not (isinstance(work_width, int) and work_width >= 32):
        raise ValueError(f"work_width: expected an integer >= 32 px, got {work_width!r}")
    if not (isinstance(n_candidates, int) and n_candidates >= 1):
        raise ValueError(f"n_candidates: expected an integer >= 1, got {n_candidates!r}")
    if not (0.0 <= min_confidence <= 1.0):
        raise ValueError(f"min_confidence: expected a value in [0, 1], got {min_confidence!r}")
    if prior_sigma is not None and not (
        isinstance(prior_sigma, int | float) and math.isfinite(prior_sigma) and prior_sigma > 0
    ):
        raise ValueError(f"prior_sigma: expected a positive number of pixels, got {prior_sigma!r}")
    if previous is not None and not isinstance(previous, HorizonEstimate):
        raise ValueError(f"previous: expected a HorizonEstimate or None, got {type(previous)}")
    arr = _as_image(image)
    H, W = arr.shape[:2]
    luma, colour, sx, sy = _prepare(arr, work_width)
    h, w = luma.shape
    xc = (w - 1) / 2.0
    xw_ends = (np.array([0.0, W - 1.0]) + 0.5) / sx - 0.5  # border columns, working px

    def to_full(c: float, t: float) -> tuple[float, float]:
        """Working line (centre row c, slope t) → full-resolution y0, y1."""
        yf = (c + t * (xw_ends - xc) + 0.5) * sy - 0.5
        return float(yf[0]), float(yf[1])

    def to_work(y0: float, y1: float) -> tuple[float, float]:
        """Full-resolution rows y0, y1 at the border columns → working (c, t)."""
        yw = (np.array([y0, y1]) + 0.5) / sy - 0.5
        t = float((yw[1] - yw[0]) / (xw_ends[1] - xw_ends[0]))
        return float(yw[0] + t * (xc - xw_ends[0])), t

    def result(c: float, t: float, conf: float) -> HorizonEstimate:
        conf = float(np.clip(conf, 0.0, 1.0))
        y0, y1 = to_full(c, t)
        found = conf >= min_confidence and conf > 0.0
        return HorizonEstimate.from_endpoints(y0, y1, W, H, found=found, confidence=conf)

    if float(luma.max() - luma.min()) <= 0.0:  # no contrast at all (all black/white)
        return result((h - 1) / 2.0, 0.0, 0.0)

    # prior lines in working coordinates (centre row, slope)
    priors: list[tuple[float, float, float]] = []
    tilt_centre = 0.0
    nominal = _nominal(camera, W, H)
    for est in (previous, nominal):
        if est is None or not est.found:
            continue
        scale = H / est.height  # a line found at another resolution
        c_p, t_p = to_work((est.y0 + 0.5) * scale - 0.5, (est.y1 + 0.5) * scale - 0.5)
        sigma = _PRIOR_SIGMA * h
        if est is previous and prior_sigma is not None:
            sigma = min(sigma, prior_sigma * scale / sy)
        priors.append((c_p, t_p, sigma))
        if est is nominal:
            tilt_centre = math.atan(t_p)

    # 1. edge evidence
    blurred = cv2.GaussianBlur(luma, (0, 0), 1.0)
    gy = cv2.Sobel(blurred, cv2.CV_32F, 0, 1, ksize=3) * np.float32(0.125)
    gx = cv2.Sobel(blurred, cv2.CV_32F, 1, 0, ksize=3) * np.float32(0.125)
    noise = 1.4826 * float(np.median(np.abs(gy[::2, ::2]))) + 1e-6
    n_strips = min(_STRIPS, w // 4)
    sw = w / n_strips
    P = cv2.resize(gy, (n_strips, h), interpolation=cv2.INTER_AREA)  # strip means
    xs = (np.arange(n_strips) + 0.5) * sw - 0.5
    m = float(np.median(np.abs(P))) + 1e-6
    tilt = math.radians(max_tilt_deg)
    lo_t = math.tan(max(-1.5, tilt_centre - tilt))
    hi_t = math.tan(min(1.5, tilt_centre + tilt))
    # slope step: two working pixels over the half width (the refinement does the rest)
    n_t = max(3, math.ceil((hi_t - lo_t) * w / 4.0) | 1)
    slopes = np.linspace(lo_t, hi_t, n_t)

    # 2. Hough candidates for each polarity
    E = _hough(P, xs, xc, slopes, m)
    raw: list[tuple[float, float, float]] = []
    rad_t = max(1, n_t // 16)
    rad_c = max(2, h // 40)
    for k in range(2):
        for i, j in _local_maxima(E[k], n_candidates, rad_t, rad_c):
            raw.append((float(j), float(slopes[i]), float(E[k, i, j])))
    raw.sort(key=lambda r: -r[2])
    starts = [(c, t) for c, t, _ in raw[: 2 * n_candidates]] + [p[:2] for p in priors]

    def prior_of(c: float, t: float) -> float:
        """The priors' weight of the working line (c, t): 1 on each, 0.5 far away."""
        prior = 1.0
        for pc, pt, sigma in priors:
            d = abs(c - pc) + 0.25 * w * abs(t - pt)  # mean |Δy| over the width
            prior *= 0.5 + 0.5 * math.exp(-0.5 * (d / sigma) ** 2)
        return prior

    # 3. refinement, 4. region statistics
    cum = _strip_features(colour, gx, gy, P)
    band = max(3, round(0.04 * h))
    search = max(3.0, 0.03 * h)
    cands: list[_Candidate] = []
    for c0, t0 in starts:
        c, t, q, support, contrast, ok = _refine(
            gy, P, sw, c0, t0, noise, 1.4826 * m, search, _TUKEY_C
        )
        if not ok or not (lo_t * 1.05 - 1e-9 <= t <= hi_t * 1.05 + 1e-9) or not 0 <= c < h:
            continue
        region = float(_region(cum, c, t, xs, xc, band, 2))
        cands.append(_Candidate(c, t, q, support, contrast, region, prior_of(c, t)))
    if not cands:
        return result((h - 1) / 2.0, 0.0, 0.0)

    # 5. selection: the lowest good line with sea-like continuation below
    plausible = [cd for cd in cands if cd.region >= _REGION_MIN and cd.contrast >= _CONTRAST_MIN]
    if not plausible:
        best = max(cands, key=lambda cd: cd.quality * cd.prior)
        return result(best.c, best.t, 0.0)
    top = max(cd.quality * cd.prior for cd in plausible)
    eligible = [cd for cd in plausible if cd.quality * cd.prior >= _LOWEST_RATIO * top]
    lowest = max(eligible, key=lambda cd: cd.c)
    # candidates within _SAME_LINE of the lowest (mean |Δy| over the width) are the same
    # line found twice (e.g. crossing it at the centre with another tilt): the better wins
    same = [
        cd
        for cd in eligible
        if abs(cd.c - lowest.c) + 0.25 * w * abs(cd.t - lowest.t) <= _SAME_LINE
    ]
    best = max(same, key=lambda cd: cd.quality * cd.prior)

    # 6. sub-pixel refinement on the full-resolution image; a line that does not hold
    # as one straight edge at full resolution gives way to a candidate crossing it
    def refine(cd: _Candidate) -> _Fine | None:
        return _fine_line(arr, *to_full(cd.c, cd.t), P, sx, sy, (cd.c, cd.t, sw))

    chosen, fine = best, refine(best)
    if fine is None or fine.support < _FINE_GOOD:
        # not one straight edge at full resolution: another fit of the same edge that
        # crosses the chosen line inside the image (e.g. through a hull on one side and
        # the horizon on the other) and holds as one straight edge replaces it
        def ends(cd: _Candidate) -> tuple[float, float]:
            return cd.c - cd.t * xc, cd.c + cd.t * (w - 1 - xc)

        b0, b1 = ends(best)
        crossing = [
            cd
            for cd in eligible
            if (ends(cd)[0] - b0) * (ends(cd)[1] - b1) < 0.0
            and cd.quality * cd.prior > best.quality * best.prior
        ]
        for cd in sorted(crossing, key=lambda cd: -cd.quality * cd.prior):
            alt = refine(cd)
            if alt is not None and alt.support >= _FINE_GOOD:
                chosen, fine = cd, alt
                break
    y0, y1 = to_full(chosen.c, chosen.t) if fine is None else (fine.y0, fine.y1)
    region_score, prior = chosen.region, chosen.prior
    # 6b. a line that holds few of the bins may join two edges (the sky/sea edge on the
    # open side and the top of a coast on the other): the straightest edge among the
    # bins, or else among the edges below it, replaces it where it lies nowhere above it
    # (the sea's edge is the lowest) and is the better sea horizon by the region test
    if fine is not None and fine.support < _STRAIGHT_BELOW:

        def straighter(alt_ends: tuple[float, float] | None) -> float | None:
            """The region score of ``alt_ends`` where it may replace (y0, y1), else None."""
            if (
                alt_ends is None
                or max(abs(alt_ends[0] - y0), abs(alt_ends[1] - y1)) <= _STRAIGHT_MOVE
                or min(alt_ends[0] - y0, alt_ends[1] - y1) < -_STRAIGHT_ABOVE * H
            ):
                return None
            c_a, t_a = to_work(*alt_ends)
            r_a = float(_region(cum, c_a, t_a, xs, xc, band, 2))
            # with a previous line, each weighed by its prior: the one it continues wins
            # a close call (two edges of about one score would otherwise alternate)
            ahead = r_a * prior_of(c_a, t_a) > region_score * prior_of(*to_work(y0, y1))
            ok = lo_t <= t_a <= hi_t and 0.0 <= c_a < h and ahead
            return r_a if ok else None

        alt_ends = _straightest(fine.x, fine.y, W)
        r_a = straighter(alt_ends)
        if r_a is None:  # the sea's edge may lie beyond the bins' reach: look lower
            below = _edges_below(arr, y0, y1, _STRAIGHT_DEPTH * H, fine.polarity, sy)
            alt_ends = _straightest(*below, W)
            r_a = straighter(alt_ends)
        if r_a is not None and alt_ends is not None:
            (y0, y1), region_score = alt_ends, r_a
            prior = prior_of(*to_work(y0, y1))  # the line's own, not the coarse one's
    region = 1.0 - math.exp(-region_score / _REGION_SCALE)
    conf = float(np.clip(math.sqrt(chosen.quality * prior * region), 0.0, 1.0))
    found = conf >= min_confidence and conf > 0.0
    return HorizonEstimate.from_endpoints(y0, y1, W, H, found=found, confidence=conf)


def _nominal(camera: PinholeCamera | None, W: int, H: int) -> HorizonEstimate | None:
    """The horizon of a camera with known attitude and height, or None."""
    if camera is None:
        return None
    if not isinstance(camera, PinholeCamera):
        raise ValueError(f"camera: expected a PinholeCamera or None, got {type(camera)}")
    if camera.height is None:
        raise ValueError("camera: needs a height above the sea to predict the horizon")
    line = horizon_line(camera)
    cw, ch = camera.image_size
    pts = line.endpoints(cw)
    if not np.all(np.isfinite(pts)):
        return None
    y0, y1 = ((pts[:, 1] + 0.5) * (H / ch) - 0.5).tolist()
    return HorizonEstimate.from_endpoints(y0, y1, W, H, found=True, confidence=1.0)


def _strip_features(
    colour: np.ndarray, gx: np.ndarray, gy: np.ndarray, P: np.ndarray
) -> np.ndarray:
    """Cumulative row sums (h + 1, S, C + 1) of strip-mean features: the colour channels
    and the texture ``|g_x| + |g_y − P|`` (``P`` the strip-row means of ``g_y``, (h, S);
    Gaussian σ = 1 px), each divided by its robust spread (10th to 90th percentile over
    the strip means), so that distances are in spread units.

    The texture leaves out the strip's mean vertical gradient: a straight edge across
    the strip — the horizon itself — is no texture, while waves and clouds are. With
    ``|∇g|`` the horizon's own edge, blurred over the rows next to it, made the band
    just below it look like another region (rendered night clip, seed 0: the region
    test failed a line with 99 % support, and the tracked horizon was lost in 16 of 200 frames).

    A grey frame's one channel is weighted √3: distances are then those of the same
    frame stored as BGR (three equal channels), so a thermal camera's 1-channel frames
    and their 3-channel copies give one line (before, the 1-channel MarDCT frames lost
    the horizon in 19 of their first 20 frames that their RGBA copies keep)."""
    h, w = colour.shape[:2]
    n_strips = P.shape[1]
    row_mean = cv2.resize(P, (w, h), interpolation=cv2.INTER_NEAREST)
    tex = cv2.GaussianBlur(np.abs(gx) + np.abs(gy - row_mean), (0, 0), 1.0)
    col = cv2.resize(colour, (n_strips, h), interpolation=cv2.INTER_AREA).reshape(h, n_strips, -1)
    tx = cv2.resize(tex, (n_strips, h), interpolation=cv2.INTER_AREA).reshape(h, n_strips, 1)
    F = np.concatenate([col, tx], axis=2)
    q1, q9 = _percentiles(F.reshape(-1, F.shape[2]), (10.0, 90.0), axis=0)
    F = F / np.maximum(q9 - q1, 1e-3)
    if colour.shape[2] == 1:
        F[..., 0] *= math.sqrt(3.0)
    cum = np.zeros((h + 1, n_strips, F.shape[2]), dtype=np.float64)
    np.cumsum(F, axis=0, out=cum[1:])
    return cum


# --------------------------------------------------------------------------------------
# tracker
# --------------------------------------------------------------------------------------

_CHI2_2DOF_999 = 13.815510557964274  # 99.9 % quantile of chi-square with 2 degrees of freedom
_WEAK_FRACTION = 0.5  # a detection under the found threshold but above this × it, in the
# gate, keeps the track (weighted by its confidence) instead of counting as a miss


class HorizonTracker:
    """Temporal smoothing of the horizon over frames: a Kalman filter with gating.

    The state is the line's rows at the left and right image borders and their rates,
    ``x = [y0, y1, ẏ0, ẏ1]`` [px, px/s], with the nearly-constant-velocity model of
    :func:`seawatch.models.constant_velocity` (DWNA, seed 002 eqs. 9–11; acceleration
    noise ``sigma_a`` [px/s²]) — a camera swaying in pitch moves both ends together,
    in roll in opposite directions. Each frame:

    1. predict to the frame time;
    2. run :func:`detect_horizon` with the predicted line as ``previous`` (a prior);
       once the track has held for a second of frames (``fps`` accepted detections),
       with the prior's width the predicted spread of a detection about the line,
       ``sqrt(max(P⁻₀₀, P⁻₁₁) + σ_m²)`` (σ_m = ``sigma_measurement``), where that is
       under 5 % of the height: a coast on the horizon whose top scores about as well
       as the sea's edge below it no longer takes the line in one frame (rendered
       crossing, seed 0: the line had gone 29 px up at one end at frame 169 and stayed
       there). A young track keeps the wide prior: it may have started on a wrong line;
    3. if the detection is found — or is under the found threshold by at most half
       (a weak detection, e.g. the sea's edge seen only between coasts) — gate it:
       innovation ``ν = z − H x⁻``, ``S = H P⁻ Hᵀ + R``, ``NIS = νᵀ S⁻¹ ν``; with
       ``NIS ≤ gate`` (default the 99.9 % point of χ²₂) it updates the filter
       (:class:`seawatch.filters.KalmanFilter`, Joseph form) with
       ``R = (sigma_measurement / confidence)² I``; otherwise the frame is
       predict-only (an outlier: a coastline, a wake, a glint). A weak detection
       that the gate accepts keeps the track like a found one (before, five in a row
       dropped it, and the next frame started again without a prior);
    4. after ``max_misses`` consecutive frames without an accepted detection the track
       is dropped: the output is ``found = False`` until a found detection starts it
       again.

    A detection that disagrees with the track for ``max_misses`` frames in a row therefore
    replaces it (the camera really moved). The output line is the filtered state; its
    confidence is the detection's (below the found threshold for a weak one), or, while
    coasting, the last one times ``0.7 ** misses``. ``age`` counts the accepted
    detections of the current track.

    Args:
        sigma_a: acceleration noise of the line ends [px/s²]; None = half an image
            height per s² (a boat's sway; raise it for fast motion, lower it to smooth more).
        sigma_measurement: standard deviation of a confident detection [px]; None =
            0.4 % of the image height.
        gate: NIS threshold for accepting a detection (2 degrees of freedom).
        max_misses: frames without an accepted detection before the track is dropped.
        fps: frame rate assumed when ``update`` gets no time [1/s].
        **detector: keyword arguments for :func:`detect_horizon` (e.g. ``max_tilt_deg``).
    """

    def __init__(
        self,
        *,
        sigma_a: float | None = None,
        sigma_measurement: float | None = None,
        gate: float = _CHI2_2DOF_999,
        max_misses: int = 5,
        fps: float = 25.0,
        **detector: Any,
    ) -> None:
        for name, value in (("sigma_a", sigma_a), ("sigma_measurement", sigma_measurement)):
            if value is not None and not (
                isinstance(value, int | float) and math.isfinite(value) and value > 0
            ):
                raise ValueError(f"{name}: expected a positive number of pixels, got {value!r}")
        if not (isinstance(gate, int | float) and gate > 0):
            raise ValueError(f"gate: expected a positive NIS threshold, got {gate!r}")
        if not (isinstance(max_misses, int) and max_misses >= 1):
            raise ValueError(f"max_misses: expected an integer >= 1, got {max_misses!r}")
        if not (isinstance(fps, int | float) and math.isfinite(fps) and fps > 0):
            raise ValueError(f"fps: expected a frame rate > 0 per second, got {fps!r}")
        unknown = set(detector) - {
            "max_tilt_deg",
            "work_width",
            "n_candidates",
            "min_confidence",
            "camera",
        }
        if unknown:
            raise ValueError(f"detector: unknown detect_horizon option(s) {sorted(unknown)}")
        self.sigma_a = sigma_a
        self.sigma_measurement = sigma_measurement
        self.gate = float(gate)
        self.max_misses = max_misses
        self.fps = float(fps)
        self.detector = detector
        self.reset()

    def reset(self) -> None:
        """Forget the track (the next found detection starts a new one)."""
        self._kf: Any = None
        self._time: float | None = None
        self._size: tuple[int, int] | None = None
        self.misses = 0
        self.age = 0
        self._confidence = 0.0
        self.last_detection: HorizonEstimate | None = None
        self.last_nis: float = math.nan

    @property
    def tracking(self) -> bool:
        """Whether a track exists (it may be coasting on predictions)."""
        return self._kf is not None

    def _scales(self, height: int) -> tuple[float, float]:
        sa = self.sigma_a if self.sigma_a is not None else 0.5 * height
        sm = self.sigma_measurement if self.sigma_measurement is not None else 0.004 * height
        return sa, sm

    def _estimate(self, found: bool, confidence: float) -> HorizonEstimate:
        assert self._kf is not None and self._size is not None
        w, h = self._size
        x = self._kf.x
        return HorizonEstimate.from_endpoints(
            float(x[0]), float(x[1]), w, h, found=found, confidence=float(confidence)
        )

    def update(self, image: ArrayLike, time: float | None = None) -> HorizonEstimate:
        """Detect the horizon in ``image`` (taken at ``time`` [s]) and filter it."""
        arr = np.asarray(image)
        if arr.ndim < 2:
            raise ValueError(f"image: expected a (H, W) or (H, W, C) image, got {arr.shape}")
        size = (int(arr.shape[1]), int(arr.shape[0]))
        if self._size is not None and size != self._size:
            self.reset()  # a new stream or a size change: start again
        prior, spread = None, None
        if self._kf is not None:
            prior, spread = self._predicted(time, size)
            if self.age < self.fps:  # a young track may have started on a wrong line
                spread = None
        det = detect_horizon(arr, previous=prior, prior_sigma=spread, **self.detector)
        return self.step(det, time)

    def _predicted(
        self, time: float | None, size: tuple[int, int]
    ) -> tuple[HorizonEstimate, float]:
        """The track's line predicted to ``time`` and the spread of the next detection
        about it [px] (without changing the filter): ``sqrt(max(P⁻₀₀, P⁻₁₁) + σ_m²)``,
        the predicted covariance of the ends and a confident detection's variance."""
        assert self._kf is not None
        dt = self._dt(time)
        x = self._kf.x
        y0, y1 = float(x[0] + dt * x[2]), float(x[1] + dt * x[3])
        F, Q = self._motion(dt, size[1])
        sm = self._scales(size[1])[1]
        P = F @ self._kf.P @ F.T + Q
        spread = math.sqrt(max(P[0, 0], P[1, 1]) + sm * sm)
        line = HorizonEstimate.from_endpoints(y0, y1, size[0], size[1], confidence=1.0)
        return line, spread

    def _motion(self, dt: float, height: int) -> tuple[np.ndarray, np.ndarray]:
        """F and Q of the line ends over ``dt`` [s]: the filter's own for one frame
        interval, else the CWNA model's for ``dt`` (``sigma_a`` of an image ``height``
        px high)."""
        assert self._kf is not None
        if abs(dt * self.fps - 1.0) < 1e-6:
            return self._kf.F, self._kf.Q
        return constant_velocity(2, dt, self._scales(height)[0])

    def _dt(self, time: float | None) -> float:
        if time is None or self._time is None:
            return 1.0 / self.fps
        dt = float(time) - self._time
        if not dt > 0:
            raise ValueError(f"time: expected a time after {self._time} s, got {time!r}")
        return dt

    def step(self, detection: HorizonEstimate, time: float | None = None) -> HorizonEstimate:
        """Filter one per-frame detection (made elsewhere) taken at ``time`` [s]."""
        if not isinstance(detection, HorizonEstimate):
            raise ValueError(f"detection: expected a HorizonEstimate, got {type(detection)}")
        if time is not None and not math.isfinite(time):
            raise ValueError(f"time: expected a finite time in seconds, got {time!r}")
        size = (detection.width, detection.height)
        if self._size is not None and size != self._size:
            self.reset()
        self.last_detection = detection
        sa, sm = self._scales(detection.height)
        z = np.array([detection.y0, detection.y1])
        R = (sm / max(detection.confidence, 0.05)) ** 2 * np.eye(2)
        if self._kf is None:
            if not detection.found:
                return detection
            F, Q = constant_velocity(2, 1.0 / self.fps, sa)
            H = np.hstack([np.eye(2), np.zeros((2, 2))])
            v0 = 0.5 * detection.height  # [px/s] initial rate uncertainty
            P0 = np.diag([R[0, 0], R[1, 1], v0 * v0, v0 * v0])
            self._kf = KalmanFilter(F, H, Q, R, np.array([z[0], z[1], 0.0, 0.0]), P0)
            self._size = size
            self._time = None if time is None else float(time)
            self.misses = 0
            self.age = 1
            self._confidence = detection.confidence
            self.last_nis = 0.0
            return self._estimate(True, detection.confidence)
        F, Q = self._motion(self._dt(time), detection.height)
        self._kf.predict(F=F, Q=Q)
        self._time = None if time is None else float(time)
        accepted = False
        self.last_nis = math.nan
        floor = _WEAK_FRACTION * float(self.detector.get("min_confidence", _MIN_CONFIDENCE))
        if detection.found or detection.confidence >= floor:
            x, P = self._kf.x, self._kf.P
            nu = z - x[:2]
            S = P[:2, :2] + R
            nis = float(nu @ np.linalg.solve(S, nu))
            self.last_nis = nis
            accepted = nis <= self.gate
        if accepted:
            self._kf.update(z, R=R)
            self.misses = 0
            self.age += 1
            self._confidence = detection.confidence
            return self._estimate(True, detection.confidence)
        self.misses += 1
        if self.misses >= self.max_misses:
            lost = self._estimate(False, 0.0)
            self.reset()
            if detection.found:  # the horizon really moved: start again from this one
                return self.step(detection, time)
            return lost
        return self._estimate(True, self._confidence * 0.7**self.misses)
