"""MOTChallenge text files: ``frame, id, x, y, w, h, conf, X, Y, Z`` per line.

The format of the MOTChallenge benchmarks (Milan et al., *MOT16: A Benchmark for
Multi-Object Tracking*, arXiv:1603.00831, §3.3) and of the FVessel data set: one box per
line, comma separated (whitespace also accepted), ``x, y`` the top-left corner and
``w, h`` the size of the box in pixels; the trailing columns (confidence, world
coordinates) are optional and default to -1 when written.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import FloatArray, as_float_array

__all__ = ["MOT_COLUMNS", "read_mot", "write_mot"]

MOT_COLUMNS = ("frame", "id", "x", "y", "w", "h", "conf", "X", "Y", "Z")
"""Column names of a MOT file; ``x, y, w, h`` in px (top-left corner, size)."""


def read_mot(path: str | os.PathLike[str], *, min_columns: int = 6) -> FloatArray:
    """Read a MOT file into an (N, C) float array, C >= ``min_columns``.

    Lines may be comma or whitespace separated; blank lines and lines starting with
    ``#`` are skipped. Rows keep the file order.

    Args:
        path: the text file.
        min_columns: the least number of columns every row must have (6 for boxes:
            frame, id, x, y, w, h; 4 for points: frame, id, x, y).

    Returns:
        (N, C) float64 array; an empty file gives shape (0, min_columns).

    Raises:
        ValueError: naming the file and line for a ragged or non-numeric line, too few
            columns, NaN/inf values or a box with negative size.
        FileNotFoundError: if the file does not exist.
    """
    p = Path(path)
    rows: list[list[float]] = []
    width: int | None = None
    with p.open(encoding="utf-8") as fh:
        for number, line in enumerate(fh, start=1):
            text = line.strip()
            if not text or text.startswith("#"):
                continue
            fields = text.split(",") if "," in text else text.split()
            try:
                values = [float(f) for f in fields]
            except ValueError:
                raise ValueError(f"{p}: line {number}: not a row of numbers: {text!r}") from None
            if width is None:
                width = len(values)
                if width < min_columns:
                    raise ValueError(
                        f"{p}: line {number}: expected at least {min_columns} columns "
                        f"({', '.join(MOT_COLUMNS[:min_columns])}), got {width}"
                    )
            elif len(values) != width:
                raise ValueError(
                    f"{p}: line {number}: expected {width} columns like the first row, "
                    f"got {len(values)}"
                )
            rows.append(values)
    if not rows:
        return np.empty((0, min_columns))
    arr = np.asarray(rows, dtype=np.float64)
    if not np.all(np.isfinite(arr)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(arr), axis=1))[0])
        raise ValueError(f"{p}: row {bad + 1}: contains NaN or inf")
    if min_columns >= 6 and np.any(arr[:, 4:6] < 0):
        bad = int(np.flatnonzero(np.any(arr[:, 4:6] < 0, axis=1))[0])
        raise ValueError(f"{p}: row {bad + 1}: negative box width or height")
    return arr


def write_mot(path: str | os.PathLike[str], rows: ArrayLike) -> Path:
    """Write (N, C) rows, C >= 6 (frame, id, x, y, w, h, …), as a 10-column MOT file.

    Frame and id are written as integers, the box with up to 3 decimals; missing
    trailing columns (conf, X, Y, Z) are written as -1.

    Returns:
        The path written.
    """
    arr = as_float_array("rows", rows)
    if arr.ndim == 1 and arr.size == 0:
        arr = arr.reshape(0, 6)
    if arr.ndim != 2 or arr.shape[1] < 6 or arr.shape[1] > len(MOT_COLUMNS):
        raise ValueError(f"rows: expected shape (N, 6..10), got {arr.shape}")
    full = np.full((arr.shape[0], len(MOT_COLUMNS)), -1.0)
    full[:, : arr.shape[1]] = arr
    p = Path(path)
    with p.open("w", encoding="utf-8") as fh:
        for r in full:
            box = ",".join(f"{v:.3f}".rstrip("0").rstrip(".") for v in r[2:])
            fh.write(f"{int(r[0])},{int(r[1])},{box}\n")
    return p
