"""seawatch.vision.waterline: the compiled (numba) kernels of the water-line reading against
plain numpy references.

The references are the numpy forms the kernels replaced (kept here, verbatim but for
names); the kernels must give the same numbers — exactly, since the kernels repeat
numpy's float32/float64 operations in numpy's order — on random masks and crops (grey
and colour, integer and continuous levels, masks touching the crop's edges, one- and
two-row objects, flat sea) with fixed seeds.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from seawatch.vision.detect import _mad
from seawatch.vision.waterline import (
    _column_edges,
    _hull_contrast_kernel,
    _level_breaks_kernel,
    _theil_sen,
)


def _median3(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Element-wise median of three arrays (the numpy form the kernels replaced)."""
    return np.maximum(np.minimum(a, b), np.minimum(np.maximum(a, b), c))


def _column_edges_ref(
    raw: np.ndarray, obj: np.ndarray, quantum: float = 0.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The numpy form of :func:`seawatch.vision.waterline._column_edges`."""
    H = obj.shape[0]
    cols = np.flatnonzero(obj.any(axis=0))
    bottom = H - 1 - np.argmax(obj[::-1, cols], axis=0)
    top = np.argmax(obj[:, cols], axis=0)
    g = raw if raw.dtype == np.float32 else raw.astype(np.float32)
    if g.ndim == 2:
        g = g[:, :, None]
    nch = g.shape[2]

    def at(r: np.ndarray) -> np.ndarray:  # (columns, channels)
        return g[np.clip(r, 0, H - 1), cols]

    sea = np.stack([at(bottom + k) for k in (3, 4, 5)])
    i_s = np.median(sea, axis=0)
    sigma = max(1.4826 * float(np.median(np.abs(sea - i_s))), quantum, 1e-6)
    start = bottom - 1
    above = np.stack([at(start - k) for k in (1, 2, 3)])
    n_in = ((start - 1) >= top).astype(int) + ((start - 2) >= top) + ((start - 3) >= top)
    n_in = n_in[:, None]
    i_h = np.where(
        n_in >= 3,
        np.median(above, axis=0),
        np.where(n_in == 2, 0.5 * (above[0] + above[1]), above[0]),
    )
    thin = n_in[:, 0] == 0
    if thin.any():
        span = np.stack([at(bottom - k) for k in (0, 1, 2)])
        inside = np.stack([(bottom - k) >= top for k in (0, 1, 2)])
        dist = np.sqrt(np.sum((span - i_s) ** 2, axis=2))
        pick = np.argmax(np.where(inside, dist, -1.0), axis=0)
        i_h = np.where(thin[:, None], span[pick, np.arange(cols.size)], i_h)
        start = np.where(thin, bottom - pick, start)
    axis = i_h - i_s
    norm2 = np.sum(axis * axis, axis=1)
    weak = norm2 < (4.0 * sigma) ** 2 * nch
    axis = np.where(weak[:, None], 0.0, axis / np.where(weak, 1.0, norm2)[:, None])
    edge = start - 0.5
    for k in range(6):
        r = start + k
        cov = np.clip(np.sum((at(r) - i_s) * axis, axis=1), 0.0, 1.0)
        edge = edge + np.where(r <= bottom + 2, cov, 0.0)
    return cols, bottom, top, np.where(weak, np.nan, edge)


def _theil_sen_ref(x: np.ndarray, y: np.ndarray, u: float) -> tuple[float, float, float]:
    """The numpy form of :func:`seawatch.vision.waterline._theil_sen`."""
    n = x.size
    if n < 2:
        return float(y[0]), 0.0, 0.0
    sub = np.linspace(0, n - 1, 24).round().astype(int) if n > 24 else np.arange(n)
    i, j = np.triu_indices(sub.size, 1)
    dx = x[sub][j] - x[sub][i]
    ok = dx != 0
    slope = float(np.median((y[sub][j] - y[sub][i])[ok] / dx[ok])) if ok.any() else 0.0
    r = y - slope * (x - u)
    return float(np.median(r)), slope, _mad(r)


def _hull_crop(
    rng: np.random.Generator, h: int, w: int, nch: int, integer: bool
) -> tuple[np.ndarray, np.ndarray]:
    """A crop with a hull (sloping, anti-aliased bottom edge) over sea, and a mask of
    the hull with ragged columns, thin columns and stray pixels."""
    base = rng.uniform(40, 200, size=nch)
    hull = base + rng.choice([-1, 1]) * rng.uniform(3, 90, size=nch)
    rows = np.arange(h)[:, None]
    wl = rng.uniform(1, h - 2) + rng.uniform(-0.2, 0.2) * (np.arange(w) - w / 2)
    cover = np.clip(wl[None, :] - rows + 0.5, 0.0, 1.0)[:, :, None]
    img = base + cover * (hull - base) + rng.normal(0, rng.uniform(0.2, 4), (h, w, nch))
    if integer:
        img = np.clip(np.round(img), 0, 255)
    img = img.astype(np.float32)
    mask = cover[:, :, 0] > rng.uniform(0.2, 0.8)
    mask &= rng.random((h, w)) > rng.uniform(0.0, 0.3)  # ragged
    mask[rng.integers(0, h, 3), rng.integers(0, w, 3)] = True  # strays, thin columns
    mask[:, rng.random(w) < 0.1] = False
    if nch == 1:
        img = img[:, :, 0]
    return img, mask


def _assert_same(got: tuple, ref: tuple) -> None:
    for a, b in zip(got, ref, strict=True):
        assert a.shape == b.shape
        np.testing.assert_array_equal(a, b)  # NaN where NaN, the same numbers elsewhere


@pytest.mark.parametrize("nch", [1, 3])
@pytest.mark.parametrize("integer", [True, False])
def test_column_edges_kernel_equals_numpy(nch, integer):
    rng = np.random.default_rng(11 + nch + 2 * integer)
    for _ in range(150):
        h, w = int(rng.integers(4, 30)), int(rng.integers(1, 60))
        img, mask = _hull_crop(rng, h, w, nch, integer)
        if not mask.any():
            mask[rng.integers(0, h), rng.integers(0, w)] = True
        quantum = float(rng.choice([0.0, 1.0, 2.5]))
        _assert_same(_column_edges(img, mask, quantum), _column_edges_ref(img, mask, quantum))


def test_column_edges_kernel_edge_cases():
    rng = np.random.default_rng(5)
    # uint8 and uint16 crops (converted to float32), a one-row and a one-column object
    img8 = rng.integers(0, 256, (12, 9)).astype(np.uint8)
    img16 = rng.integers(0, 65536, (12, 9)).astype(np.uint16)
    for img in (img8, img16):
        for mask in (np.zeros((12, 9), bool), np.zeros((12, 9), bool)):
            mask[5, 2:7] = True
            _assert_same(_column_edges(img, mask, 1.0), _column_edges_ref(img, mask, 1.0))
            mask[:, 4] = True  # a column reaching the crop's top and bottom rows
            _assert_same(_column_edges(img, mask, 1.0), _column_edges_ref(img, mask, 1.0))
    # a flat sea (σ from the quantum) and hulls exactly at, just under and over 4 σ
    for contrast in (3.0, 3.5, 4.0, 4.5, 64.0):
        img = np.full((10, 8), 100.0, np.float32)
        img[:4] += np.float32(contrast)
        mask = np.zeros((10, 8), bool)
        mask[:4] = True
        for quantum in (0.0, 1.0):
            _assert_same(_column_edges(img, mask, quantum), _column_edges_ref(img, mask, quantum))
    # the whole crop is object: every row past the mask repeats the last one
    img = rng.normal(100, 10, (6, 5, 3)).astype(np.float32)
    mask = np.ones((6, 5), bool)
    _assert_same(_column_edges(img, mask), _column_edges_ref(img, mask))


def test_theil_sen_kernel_equals_numpy():
    rng = np.random.default_rng(7)
    for n in [1, 2, 3, 5, 24, 25, 40, 97, 300]:
        for _ in range(20):
            x = np.sort(rng.choice(np.arange(400), size=n, replace=False)).astype(np.float64)
            if rng.random() < 0.3:
                x = np.sort(rng.integers(0, max(2, n // 2), n)).astype(np.float64)  # ties
            y = 0.1 * rng.normal() * x + rng.normal(0, rng.uniform(0.01, 2), n)
            if rng.random() < 0.2:
                y = np.round(y)  # many equal slopes and residuals
            u = float(rng.uniform(x.min(), x.max() + 1))
            got = _theil_sen(x, y, u)
            ref = _theil_sen_ref(x, y, u)
            assert got == ref
            assert all(type(v) is float for v in got)
    same_x = np.full(5, 3.0)  # no pair with a slope: slope 0
    assert _theil_sen(same_x, np.arange(5.0), 1.0) == _theil_sen_ref(same_x, np.arange(5.0), 1.0)


def _hull_contrast_ref(rgb: np.ndarray, cols: np.ndarray, bottom: np.ndarray):
    """The numpy form of the hull/sea levels in :func:`seawatch.vision.waterline._frame_ships`."""
    last = rgb.shape[0] - 1
    pick = [rgb[np.clip(bottom + k, 0, last), cols] for k in (-3, -2, -2, 3, 4, 5)]
    sea = _median3(*pick[3:])
    hull = _median3(*pick[:3]) - sea
    noise = 1.4826 * float(np.median(np.abs(np.stack(pick[3:]) - sea)))
    return hull, noise


def _level_breaks_ref(e: np.ndarray, jump: float):
    """The numpy form of the breaks of :func:`seawatch.vision.waterline._waterline_levels`."""
    n = e.size
    em = e.copy()
    em[1:-1] = _median3(e[:-2], e[1:-1], e[2:])
    d = np.diff(e)
    noise = _mad(d) / math.sqrt(2.0)
    J = max(jump, 4.0 * noise)
    ext = np.r_[em[0], em[0], em, em[-1], em[-1]]
    med = _median3(ext[:-2], ext[1:-1], ext[2:])
    step = np.abs(med[3 : n + 2] - med[: n - 1])
    breaks = [
        i for i in range(n - 1) if step[i] >= J and step[i] == step[max(0, i - 2) : i + 3].max()
    ]
    return breaks, J


@pytest.mark.parametrize("nch", [1, 3])
def test_hull_contrast_kernel_equals_numpy(nch):
    rng = np.random.default_rng(21 + nch)
    for _ in range(200):
        h, w = int(rng.integers(1, 25)), int(rng.integers(1, 50))
        rgb = rng.normal(100, rng.uniform(0.5, 30), (h, w, nch)).astype(np.float32)
        if rng.random() < 0.5:
            rgb = np.round(rgb)  # integer levels: many ties
        cols = np.flatnonzero(rng.random(w) < 0.7)
        if cols.size == 0:
            cols = np.array([0])
        bottom = rng.integers(0, h, cols.size)  # rows ± 3 … 5 clipped to the crop
        hull, noise = _hull_contrast_kernel(rgb, cols, bottom)
        ref_hull, ref_noise = _hull_contrast_ref(rgb, cols, bottom)
        np.testing.assert_array_equal(hull, ref_hull)
        assert hull.dtype == ref_hull.dtype
        assert noise == ref_noise


def test_level_breaks_kernel_equals_numpy():
    rng = np.random.default_rng(31)
    for _ in range(400):
        n = int(rng.integers(9, 120))
        e = 20.0 + rng.normal(0, rng.uniform(0.05, 0.6), n)
        for _ in range(int(rng.integers(0, 4))):  # steps: a second ship's water line
            e[int(rng.integers(1, n)) :] += rng.uniform(-3.0, 3.0)
        if rng.random() < 0.3:
            e = np.round(e * 4) / 4  # quantised edges: equal steps, ties for the maximum
        jump = float(rng.choice([0.5, 1.0, 2.0]))
        breaks, J = _level_breaks_kernel(e, jump)
        ref_breaks, ref_J = _level_breaks_ref(e, jump)
        assert breaks.tolist() == ref_breaks
        assert J == ref_J
