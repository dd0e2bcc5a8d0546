"""Argument checks shared by every public constructor and method.

Each check names the argument and the expected shape or property, so that a user
who passes a bad matrix reads *which* matrix is bad and why (STYLE.md: errors name
the argument and the expected shape/units).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


def as_float_array(
    name: str, value: ArrayLike, ndim: int | Sequence[int] | None = None
) -> FloatArray:
    """Convert *value* to a float64 array, raising ValueError naming *name* on failure.

    ``ndim`` restricts the number of dimensions (an int or a collection of allowed ints).
    """
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name}: cannot convert to a float array ({exc})") from None
    if ndim is not None:
        allowed = (ndim,) if isinstance(ndim, int) else tuple(ndim)
        if arr.ndim not in allowed:
            raise ValueError(
                f"{name}: expected {' or '.join(map(str, allowed))}-D array, got shape {arr.shape}"
            )
    return arr


def finite(name: str, arr: FloatArray) -> FloatArray:
    """Raise ValueError if *arr* holds NaN or inf."""
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: contains NaN or inf")
    return arr


def matrix(
    name: str, value: ArrayLike, shape: tuple[int | None, int | None] | None = None
) -> FloatArray:
    """A finite 2-D float matrix, optionally of a given ``shape`` (None = any size on that axis)."""
    arr = finite(name, as_float_array(name, value, ndim=2))
    if shape is not None:
        for axis, want in enumerate(shape):
            if want is not None and arr.shape[axis] != want:
                raise ValueError(f"{name}: expected shape {_fmt(shape)}, got {arr.shape}")
    return arr


def vector(name: str, value: ArrayLike, size: int | None = None) -> FloatArray:
    """A finite 1-D float vector, optionally of a given ``size``."""
    arr = finite(name, as_float_array(name, value, ndim=(0, 1)))
    arr = np.atleast_1d(arr)
    if size is not None and arr.shape[0] != size:
        raise ValueError(f"{name}: expected length {size}, got {arr.shape[0]}")
    return arr


def covariance(
    name: str,
    value: ArrayLike,
    n: int,
    *,
    positive_definite: bool = False,
    batch: bool = False,
    rtol: float = 1e-9,
) -> FloatArray:
    """A finite, symmetric, PSD ``(n, n)`` covariance (``(..., n, n)`` if *batch*).

    A scalar or length-n vector is accepted as an isotropic or diagonal covariance.
    ``positive_definite=True`` additionally requires strict positive definiteness (for
    matrices that get inverted, like a measurement noise R).
    """
    arr = finite(name, as_float_array(name, value))
    if arr.ndim == 0:
        arr = float(arr) * np.eye(n)
    elif arr.ndim == 1 and arr.shape[0] == n:
        arr = np.diag(arr)
    if arr.ndim < 2 or arr.shape[-2:] != (n, n) or (arr.ndim > 2 and not batch):
        want = f"(..., {n}, {n})" if batch else f"({n}, {n})"
        raise ValueError(f"{name}: expected covariance of shape {want}, got {arr.shape}")
    scale = max(float(np.max(np.abs(arr))), 1e-300)
    if np.max(np.abs(arr - np.swapaxes(arr, -1, -2))) > rtol * scale * 1e3:
        raise ValueError(f"{name}: covariance is not symmetric")
    arr = 0.5 * (arr + np.swapaxes(arr, -1, -2))
    eig_min = np.min(np.linalg.eigvalsh(arr)) if n > 0 else 0.0
    if positive_definite and eig_min <= 0.0:
        raise ValueError(
            f"{name}: covariance must be positive definite (smallest eigenvalue {eig_min:.3g})"
        )
    if eig_min < -1e-9 * scale:
        raise ValueError(
            f"{name}: covariance is not positive semi-definite (smallest eigenvalue {eig_min:.3g})"
        )
    return arr


def linear_model(
    F: ArrayLike, H: ArrayLike, Q: ArrayLike, R: ArrayLike, *, transition: str = "F"
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Validated, contiguous (F, H, Q, R) of a linear-Gaussian model.

    F (n, n) square and finite (named ``transition`` in errors, e.g. "A" for the
    fractional filter), H (m, n) with m ≥ 1, Q (n, n) PSD, R (m, m) positive definite.
    """
    F = matrix(transition, F)
    n = F.shape[0]
    if F.shape != (n, n) or n == 0:
        raise ValueError(f"{transition}: expected a square (n, n) matrix, got {F.shape}")
    H = matrix("H", H, (None, n))
    m = H.shape[0]
    if m == 0:
        raise ValueError("H: expected at least one measurement row, got shape (0, n)")
    return (
        np.ascontiguousarray(F),
        np.ascontiguousarray(H),
        np.ascontiguousarray(covariance("Q", Q, n)),
        np.ascontiguousarray(covariance("R", R, m, positive_definite=True)),
    )


def positive(name: str, value: float, *, allow_zero: bool = False) -> float:
    """A finite scalar > 0 (or >= 0 with *allow_zero*)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a number, got {value!r}") from None
    if not np.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
        bound = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{name}: expected a finite number {bound}, got {value!r}")
    return v


def in_range(
    name: str, value: float, lo: float, hi: float, *, lo_open: bool = False, hi_open: bool = False
) -> float:
    """A finite scalar within [lo, hi] (ends optionally open)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a number, got {value!r}") from None
    bad = (not np.isfinite(v)) or v < lo or v > hi or (lo_open and v == lo) or (hi_open and v == hi)
    if bad:
        lb = "(" if lo_open else "["
        rb = ")" if hi_open else "]"
        raise ValueError(f"{name}: expected a value in {lb}{lo}, {hi}{rb}, got {value!r}")
    return v


def integer(name: str, value: object, minimum: int, maximum: int | None = None) -> int:
    """An integer (Python or numpy; not a bool) >= *minimum* and, if given, <= *maximum*."""
    ok = not isinstance(value, bool) and isinstance(value, int | np.integer)
    if not ok or value < minimum or (maximum is not None and value > maximum):  # type: ignore[operator]
        want = f">= {minimum}" if maximum is None else f"in {minimum} … {maximum}"
        raise ValueError(f"{name}: expected an integer {want}, got {value!r}")
    return int(value)  # type: ignore[call-overload]


def int_pair(name: str, value: object, labels: tuple[str, str], minimum: int) -> tuple[int, int]:
    """Two integers (e.g. a size in pixels) given as a pair, both >= *minimum*; *labels*
    name the two in the error message (``("width", "height")``)."""
    try:
        a, b = (int(v) for v in value)  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected ({labels[0]}, {labels[1]}), got {value!r}") from None
    if a < minimum or b < minimum:
        raise ValueError(f"{name}: expected both sides >= {minimum} px, got {value!r}")
    return a, b


def _fmt(shape: tuple[int | None, ...]) -> str:
    return "(" + ", ".join("any" if s is None else str(s) for s in shape) + ")"


ASPECT_TOLERANCE = 0.01
"""Frame sizes whose aspect ratios agree within this fraction show the same view at
another resolution: a camera file's intrinsics (:func:`seawatch.pipeline.track_video`)
and a search mask (:class:`seawatch.vision.external.MaskedDetector`) are scaled to them."""


def same_aspect(size: tuple[int, int], other: tuple[int, int]) -> bool:
    """Whether the (width, height) sizes ``size`` and ``other`` [px] have one aspect ratio,
    within :data:`ASPECT_TOLERANCE`."""
    return abs((size[0] / size[1]) / (other[0] / other[1]) - 1.0) <= ASPECT_TOLERANCE
