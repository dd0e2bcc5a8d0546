"""Marks from images: CA-CFAR, adaptive threshold, connected components, centroids.

Independent truths: Stone Soup's expected CFAR output and connected-component labels for
its test image (``../shared/data/cfar/``, MIT, from ``stonesoup/feeder/tests/test_image``,
made with train 10, guard 4, alpha 4, squared), brute-force window loops written here,
and the analytic centre of a symmetric blob.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from seawatch.vision import (
    adaptive_mask,
    cfar_mask,
    extract_marks,
    grayscale,
    marks_from_mask,
)

CFAR_DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "cfar"


def _read(name: str) -> np.ndarray:
    path = CFAR_DATA / name
    if not path.exists():
        pytest.skip(f"Stone Soup CFAR test data not found at {CFAR_DATA}")
    return cv2.imread(str(path), cv2.IMREAD_UNCHANGED)


# ------------------------------------------------------------------ brute force


def _cfar_brute(img, train, guard, alpha, squared, clip):
    x = img.astype(np.float64)
    p = x * x if squared else x
    H, W = x.shape
    ho = train + guard
    out = np.zeros((H, W), bool)
    for r in range(H):
        for c in range(W):
            if not clip and (r < ho or c < ho or r >= H - ho or c >= W - ho):
                continue
            win = np.zeros((H, W), bool)
            win[max(0, r - ho) : r + ho + 1, max(0, c - ho) : c + ho + 1] = True
            win[max(0, r - guard) : r + guard + 1, max(0, c - guard) : c + guard + 1] = False
            mean = p[win].mean()
            with np.errstate(divide="ignore", invalid="ignore"):
                out[r, c] = p[r, c] / mean > alpha
    return out


def _adaptive_brute(img, window, k, guard, min_contrast):
    x = img.astype(np.float64)
    H, W = x.shape
    h = window // 2
    out = np.zeros((H, W), bool)
    for r in range(H):
        for c in range(W):
            win = np.zeros((H, W), bool)
            win[max(0, r - h) : r + h + 1, max(0, c - h) : c + h + 1] = True
            if guard is not None:
                win[max(0, r - guard) : r + guard + 1, max(0, c - guard) : c + guard + 1] = False
            vals = x[win]
            mu, sd = vals.mean(), vals.std()
            out[r, c] = x[r, c] > mu + k * sd and x[r, c] - mu > min_contrast
    return out


# ------------------------------------------------------------------ Stone Soup data


def test_cfar_reproduces_stone_soup_expected_mask_pixel_for_pixel():
    img = _read("test_img.png")
    expected = _read("expected_result_cfar.png")
    mask = cfar_mask(img, train=10, guard=4, alpha=4, squared=True)
    assert int(np.count_nonzero(expected)) == 80
    np.testing.assert_array_equal(mask.astype(np.uint8) * 255, expected)


def test_cfar_result_is_the_same_for_8_bit_16_bit_and_float_copies_of_the_image():
    img = _read("test_img.png")
    expected = _read("expected_result_cfar.png") > 0
    for image in (img.astype(np.uint16), img.astype(np.float32), img.astype(np.float64) / 7.0):
        np.testing.assert_array_equal(cfar_mask(image), expected)


def test_connected_components_of_the_cfar_mask_match_stone_soup_labels():
    img = _read("test_img.png")
    expected = _read("expected_result_ccl.png")
    mask = cfar_mask(img).astype(np.uint8) * 255
    n, labels = cv2.connectedComponents(mask)
    assert n - 1 == 16 == expected.max()
    np.testing.assert_array_equal(labels, expected)


def _raster_order(labels: np.ndarray) -> np.ndarray:
    """Label numbers (background 0 excluded) sorted by their first pixel in raster order
    (OpenCV numbers 8-connected components in 2×2-block scan order instead)."""
    ids, first = np.unique(labels.ravel(), return_index=True)
    return ids[ids > 0][np.argsort(first[ids > 0])]


def test_marks_of_stone_soup_image_are_its_16_components_with_their_areas():
    img = _read("test_img.png")
    labels = _read("expected_result_ccl.png")
    marks = extract_marks(img, train=10, guard=4, alpha=4, squared=True)
    assert marks.shape == (16, 4)
    order = _raster_order(labels)
    areas = np.bincount(labels.ravel())[order]
    np.testing.assert_array_equal(marks[:, 3], areas)
    assert marks[:, 3].sum() == 80
    for i, (row, col, peak, _area) in zip(order, marks, strict=True):
        rr, cc = np.nonzero(labels == i)
        assert rr.min() <= row <= rr.max() and cc.min() <= col <= cc.max()
        assert peak == img[rr, cc].max()


def test_colour_image_in_bgr_order_is_converted_to_grey():
    img = _read("test_img.png")
    bgr = np.dstack([img, img, img])
    np.testing.assert_array_equal(grayscale(bgr), img)
    np.testing.assert_array_equal(extract_marks(bgr), extract_marks(img))
    bgra = np.dstack([img, img, img, np.full_like(img, 255)])
    np.testing.assert_array_equal(cfar_mask(bgra), cfar_mask(img))


# ------------------------------------------------------------------ brute force checks


@pytest.mark.parametrize("squared", [True, False])
@pytest.mark.parametrize("border", ["valid", "clip"])
@pytest.mark.parametrize("guard", [0, 2])
def test_cfar_equals_a_brute_force_window_loop(squared, border, guard):
    rng = np.random.default_rng(1234)
    img = rng.integers(0, 60, size=(23, 31)).astype(np.uint8)
    img[7:9, 12:14] = 250
    img[0, 0] = 255  # a corner target only the clipped windows can see
    got = cfar_mask(img, train=3, guard=guard, alpha=2.5, squared=squared, border=border)
    want = _cfar_brute(img, 3, guard, 2.5, squared, border == "clip")
    np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("guard", [None, 1])
def test_adaptive_threshold_equals_a_brute_force_mean_plus_k_sigma(guard):
    rng = np.random.default_rng(1234)
    img = rng.normal(100.0, 5.0, size=(21, 26))
    img[10, 10] += 40.0
    img[3:5, 20] += 30.0
    got = adaptive_mask(img, window=7, k=2.0, guard=guard, min_contrast=1.0)
    want = _adaptive_brute(img, 7, 2.0, guard, 1.0)
    np.testing.assert_array_equal(got, want)


def test_weighted_centroid_of_a_symmetric_blob_is_its_subpixel_centre():
    rr, cc = np.mgrid[0:120, 0:160]
    centre = (47.3, 88.6)
    blob = 200.0 * np.exp(-((rr - centre[0]) ** 2 + (cc - centre[1]) ** 2) / (2 * 1.5**2))
    img = 20.0 + blob
    for method, options in (("cfar", {"train": 8, "guard": 5}), ("adaptive", {"window": 25})):
        marks = extract_marks(img, method, **options)
        assert marks.shape[0] == 1, method
        row, col, peak, area = marks[0]
        assert abs(row - centre[0]) < 0.1 and abs(col - centre[1]) < 0.1, method
        assert peak == img.max()
        assert area == np.count_nonzero(
            cfar_mask(img, **options) if method == "cfar" else adaptive_mask(img, **options)
        )


def test_connectivity_four_splits_diagonal_neighbours_that_eight_joins():
    img = np.zeros((10, 10), np.uint8)
    mask = np.zeros((10, 10), bool)
    mask[4, 4] = mask[5, 5] = True
    img[mask] = 100
    assert marks_from_mask(img, mask, connectivity=8).shape == (1, 4)
    marks4 = marks_from_mask(img, mask, connectivity=4)
    np.testing.assert_allclose(marks4[:, :2], [[4, 4], [5, 5]])


@pytest.mark.parametrize("connectivity", [4, 8])
def test_components_equal_opencv_components_in_size_centroid_and_peak(connectivity):
    rng = np.random.default_rng(1234)
    for density in (0.05, 0.3, 0.6):
        mask = rng.random((47, 53)) < density
        img = rng.integers(1, 200, size=mask.shape).astype(np.uint8)
        n, labels, stats, _ = cv2.connectedComponentsWithStats(
            mask.astype(np.uint8), connectivity=connectivity
        )
        marks = marks_from_mask(img, mask, connectivity=connectivity)
        assert marks.shape[0] == n - 1
        order = _raster_order(labels)
        np.testing.assert_array_equal(marks[:, 3], stats[order, cv2.CC_STAT_AREA])
        for k in (0, n // 2, n - 2):
            rr, cc = np.nonzero(labels == order[k])
            w = img[rr, cc] - img[mask].min() + 1.0
            np.testing.assert_allclose(marks[k, :2], [rr @ w / w.sum(), cc @ w / w.sum()])
            assert marks[k, 2] == img[rr, cc].max()


def test_area_limits_drop_small_and_large_components():
    img = np.zeros((20, 20), np.uint8)
    img[2, 2] = 200  # 1 px
    img[10:12, 10:12] = 200  # 4 px
    img[15:19, 2:8] = 200  # 24 px
    mask = img > 0
    assert sorted(marks_from_mask(img, mask)[:, 3]) == [1, 4, 24]
    assert marks_from_mask(img, mask, min_area=2, max_area=10)[:, 3].tolist() == [4]


# ------------------------------------------------------------------ degenerate and bad input


def test_flat_and_black_frames_give_no_marks():
    for img in (np.full((64, 64), 77, np.uint8), np.zeros((64, 64))):
        for method in ("cfar", "adaptive"):
            marks = extract_marks(img, method)
            assert marks.shape == (0, 4)


def test_nan_or_inf_pixels_raise_naming_the_image():
    img = np.ones((40, 40))
    img[3, 3] = np.nan
    with pytest.raises(ValueError, match="image"):
        extract_marks(img)
    img[3, 3] = np.inf
    with pytest.raises(ValueError, match="image"):
        cfar_mask(img)


def test_bad_shapes_and_dtypes_raise_naming_the_image():
    with pytest.raises(ValueError, match="image"):
        extract_marks(np.zeros((4, 5, 6)))
    with pytest.raises(ValueError, match="image"):
        extract_marks(np.zeros(10))
    with pytest.raises(ValueError, match="image"):
        extract_marks(np.zeros((0, 5)))
    with pytest.raises(ValueError, match="image"):
        extract_marks(np.zeros((40, 40), complex))
    with pytest.raises(ValueError, match="image"):  # smaller than the 29 x 29 window
        cfar_mask(np.zeros((20, 50)))
    assert cfar_mask(np.zeros((20, 50)), border="clip").shape == (20, 50)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"train": 0}, "train"),
        ({"guard": -1}, "guard"),
        ({"alpha": 0.0}, "alpha"),
        ({"alpha": float("nan")}, "alpha"),
        ({"border": "wrap"}, "border"),
        ({"window": 8}, "window"),
        ({"connectivity": 6}, "connectivity"),
        ({"min_area": 0}, "min_area"),
        ({"min_area": 5, "max_area": 2}, "max_area"),
        ({"k": 1.0}, "k"),  # an adaptive option given to the CFAR method
    ],
)
def test_bad_parameters_raise_naming_the_parameter(kwargs, name):
    with pytest.raises(ValueError, match=name):
        extract_marks(np.zeros((40, 40), np.uint8), **kwargs)


def test_bad_adaptive_parameters_raise_naming_the_parameter():
    img = np.zeros((40, 40))
    with pytest.raises(ValueError, match="guard"):
        adaptive_mask(img, window=7, guard=3)
    with pytest.raises(ValueError, match="k"):
        adaptive_mask(img, k=-1.0)
    with pytest.raises(ValueError, match="method"):
        extract_marks(img, "otsu")
    with pytest.raises(ValueError, match="mask"):
        marks_from_mask(img, np.zeros((3, 3), bool))
