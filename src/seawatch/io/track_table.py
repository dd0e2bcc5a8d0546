"""Row tables written as they are produced: ``tracks.csv`` and friends (INTERFACES.md).

:class:`TableWriter` writes one CSV row per call, flushed after every frame
(:meth:`TableWriter.flush`), so an interruption — a crash, Ctrl-C or ``kill`` — loses at
most the frame in progress: CSV is the crash-safe primary format. With ``parquet=True``
the same rows also go to a Parquet file when the writer is closed (pyarrow, optional:
``pip install 'seawatch[parquet]'``); a Parquet file has its index at the end, so it can
only be complete when the run ends, which is why it is not the primary format.

Cells: integers as written, floats with 10 significant digits (``%.10g``: 1e-8° of
latitude ≈ 1 mm), NaN/inf/None as empty cells, strings verbatim.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["TableWriter", "read_table"]


def _cell(value: Any) -> str:
    if type(value) is float:  # the common case first (a track job writes ~100k cells)
        return f"{value:.10g}" if math.isfinite(value) else ""
    if value is None:
        return ""
    if isinstance(value, str):
        return value
    if isinstance(value, bool | np.bool_):
        return "1" if value else "0"
    if isinstance(value, int | np.integer):
        return str(int(value))
    f = float(value)
    return f"{f:.10g}" if math.isfinite(f) else ""


class TableWriter:
    """A CSV table written row by row, flushed on demand, optionally mirrored to Parquet.

    Args:
        path: the CSV file (its folder must exist; opened for writing at once, so an
            unwritable path fails before any work).
        columns: the header, in order; rows may hold further keys (ignored) and miss
            some (empty cells).
        parquet: also write ``path`` with the suffix ``.parquet`` on :meth:`close`.
    """

    def __init__(self, path: str | Path, columns: Sequence[str], *, parquet: bool = False) -> None:
        self.path = Path(path)
        self.columns = tuple(columns)
        if not self.columns:
            raise ValueError("columns: expected at least one column name")
        if parquet:
            try:
                import pyarrow  # noqa: F401
            except ImportError:
                raise ValueError(
                    "--parquet: needs pyarrow, which is not installed "
                    "(pip install 'seawatch[parquet]')"
                ) from None
        self.parquet_path = self.path.with_suffix(".parquet") if parquet else None
        self._kept: list[list[str]] | None = [] if parquet else None
        try:
            # unbuffered: each flush() is one write() of whole rows, so a kill between two
            # flushes leaves only complete rows in the file
            self._fh = self.path.open("wb", buffering=0)
        except OSError as exc:
            raise ValueError(f"{self.path}: cannot write ({exc.strerror})") from None
        self._buf = io.StringIO()
        self._csv = csv.writer(self._buf)
        self._csv.writerow(self.columns)
        self._write(self._take())  # the header: written now, and no row
        self.rows = 0

    def write(self, row: Mapping[str, Any]) -> None:
        """Append one row (a mapping column → value); not flushed until :meth:`flush`."""
        cells = [_cell(row.get(c)) for c in self.columns]
        self._csv.writerow(cells)
        if self._kept is not None:
            self._kept.append(cells)

    def flush(self) -> None:
        """Hand the rows written since the last flush to the operating system in one write
        (call once per frame). ``rows`` counts the rows handed over: the buffer is taken
        before the write, so a flush cut short by Ctrl-C or SIGTERM (``close`` flushes
        again) never writes a row twice, and ``rows`` is the number of rows in the file."""
        data = self._take()
        if data:
            # counted first: a signal's handler runs when the write returns
            self.rows += data.count(b"\n")  # one line per row: cells hold no newline
            self._write(data)

    def _take(self) -> bytes:
        """The buffered lines, encoded; the buffer is emptied."""
        data = self._buf.getvalue().encode("utf-8")
        self._buf.seek(0)
        self._buf.truncate()
        return data

    def _write(self, data: bytes) -> None:
        view = memoryview(data)
        while view:  # a regular file takes it whole; the loop covers short writes
            view = view[self._fh.write(view) :]

    def close(self) -> list[Path]:
        """Close the CSV (and write the Parquet copy); returns the files written."""
        if self._fh.closed:
            return [self.path]
        self.flush()
        self._fh.close()
        out = [self.path]
        if self.parquet_path is not None and self._kept is not None:
            import pyarrow as pa
            import pyarrow.csv as pacsv
            import pyarrow.parquet as pq

            table: Any = (
                pacsv.read_csv(self.path)
                if self.rows
                else pa.table({c: pa.array([], pa.string()) for c in self.columns})
            )
            pq.write_table(table, self.parquet_path)
            out.append(self.parquet_path)
        return out

    def __enter__(self) -> TableWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def read_table(path: str | Path) -> list[dict[str, str]]:
    """The rows of a CSV table as dicts of strings (empty cells as ``""``).

    Raises ValueError naming the file when it is missing, empty or not a CSV table.
    """
    p = Path(path)
    try:
        with p.open(newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            if not reader.fieldnames:
                raise ValueError(f"{p}: empty file, expected a CSV header")
            return list(reader)
    except FileNotFoundError:
        raise ValueError(f"{p}: no such file") from None
    except (UnicodeDecodeError, csv.Error) as exc:
        raise ValueError(f"{p}: not a readable CSV table ({exc})") from None
