"""TableWriter: rows written per flush in one piece, cells formatted, Parquet optional."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

from seawatch.io.track_table import TableWriter, read_table


def test_rows_appear_only_at_flush_and_cells_round_trip(tmp_path):
    path = tmp_path / "t.csv"
    w = TableWriter(path, ("a", "b", "c", "d"))
    assert path.read_bytes() == b"a,b,c,d\r\n"  # the header is on disk at once
    w.write({"a": np.int64(3), "b": 50.79031234567, "c": math.nan, "e": "ignored"})
    w.write({"a": 4, "b": -1.5e-9, "c": None, "d": "x,y"})
    # Python and numpy floats alike: 10 significant digits, non-finite values empty
    w.write({"a": True, "b": np.float64(2.0) / 3, "c": -math.inf, "d": np.float32(0.25)})
    assert path.read_bytes() == b"a,b,c,d\r\n"  # nothing before the flush
    w.flush()
    rows = read_table(path)
    assert rows == [
        {"a": "3", "b": "50.79031235", "c": "", "d": ""},
        {"a": "4", "b": "-1.5e-09", "c": "", "d": "x,y"},
        {"a": "1", "b": "0.6666666667", "c": "", "d": "0.25"},
    ]
    assert w.close() == [path] and w.rows == 3


def test_bad_tables_name_the_file(tmp_path):
    with pytest.raises(ValueError, match="no such file"):
        read_table(tmp_path / "none.csv")
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    with pytest.raises(ValueError, match=r"empty\.csv"):
        read_table(empty)
    with pytest.raises(ValueError, match="cannot write"):
        TableWriter(tmp_path / "no" / "such" / "t.csv", ("a",))


def test_parquet_without_pyarrow_is_a_clear_error(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "pyarrow", None)  # as if not installed
    with pytest.raises(ValueError, match=r"--parquet: needs pyarrow.*seawatch\[parquet\]"):
        TableWriter(tmp_path / "t.csv", ("a",), parquet=True)


def test_parquet_copy_holds_the_csv_rows(tmp_path):
    """pyarrow is in the test extras, so the parquet copy is written and read back."""
    import pyarrow.parquet as pq

    w = TableWriter(tmp_path / "t.csv", ("a", "b"), parquet=True)
    w.write({"a": 1, "b": 2.5})
    w.flush()
    out = w.close()
    table = pq.read_table(out[1]).to_pydict()
    assert table == {"a": [1], "b": [2.5]}


def test_a_flush_cut_by_an_interrupt_writes_no_row_twice_and_counts_what_is_in_the_file(
    tmp_path,
):
    """SIGTERM/Ctrl-C (KeyboardInterrupt) right after a flush's write and before it
    returns: ``close`` flushes again, which must not repeat the rows already handed
    over; ``rows`` equals the rows in the file (the track job reports it)."""
    w = TableWriter(tmp_path / "t.csv", ["a", "b"])
    real = w._fh

    class CutAfterWrite:
        closed = False

        def write(self, data):
            real.write(data)
            raise KeyboardInterrupt  # arrives once the bytes are in the file

        def close(self):
            real.close()

    w.write({"a": 1, "b": 2})
    w.write({"a": 3, "b": 4})
    w._fh = CutAfterWrite()
    with pytest.raises(KeyboardInterrupt):
        w.flush()
    w._fh = real
    w.close()
    lines = (tmp_path / "t.csv").read_text().splitlines()
    assert lines == ["a,b", "1,2", "3,4"]
    assert w.rows == 2
