"""MOT text files: reading the FVessel sample, round trips and malformed files.

FVessel Video-01 ground truth (``../shared/data/fvessel/``, MIT; README: 5 ships,
1,709 boxes over 621 frames at 1 Hz) is the independent truth for the reader.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from seawatch.io.mot import MOT_COLUMNS, read_mot, write_mot

FVESSEL = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "fvessel"


def test_fvessel_ground_truth_has_the_documented_boxes_ships_and_frames():
    path = FVESSEL / "Video-01_gt_tracking.txt"
    if not path.exists():
        pytest.skip(f"FVessel sample not found at {FVESSEL}")
    rows = read_mot(path)
    assert rows.shape == (1709, len(MOT_COLUMNS))
    assert np.unique(rows[:, 1]).size == 5
    assert np.unique(rows[:, 0]).size == 621
    np.testing.assert_array_equal(rows[0, :6], [0, 0, 558, 720, 388, 71])


def test_write_then_read_round_trips_and_pads_to_ten_columns(tmp_path):
    rows = np.array([[1, 3, 10.5, 20.25, 30.0, 40.125], [2, 3, 11.0, 21.0, 30.0, 40.0]])
    path = write_mot(tmp_path / "t.txt", rows)
    back = read_mot(path)
    assert back.shape == (2, 10)
    np.testing.assert_array_equal(back[:, :6], rows)
    np.testing.assert_array_equal(back[:, 6:], -1.0)
    assert path.read_text().splitlines()[0] == "1,3,10.5,20.25,30,40.125,-1,-1,-1,-1"


def test_whitespace_separated_files_comments_and_blank_lines_are_read(tmp_path):
    path = tmp_path / "w.txt"
    path.write_text("# frame id x y w h\n\n1 2 3 4 5 6\n2 2 3 4 5 6\n")
    np.testing.assert_array_equal(read_mot(path), [[1, 2, 3, 4, 5, 6], [2, 2, 3, 4, 5, 6]])


def test_points_files_need_only_four_columns(tmp_path):
    path = tmp_path / "p.txt"
    path.write_text("0,1,2.5,3.5\n")
    assert read_mot(path, min_columns=4).shape == (1, 4)
    with pytest.raises(ValueError, match="columns"):
        read_mot(path)


def test_empty_file_gives_no_rows(tmp_path):
    path = tmp_path / "e.txt"
    path.write_text("")
    assert read_mot(path).shape == (0, 6)
    write_mot(tmp_path / "e2.txt", np.empty((0, 6)))
    assert read_mot(tmp_path / "e2.txt").shape == (0, 6)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("1,2,3,4,5,6\n1,2,3,4,5\n", "line 2"),
        ("1,2,3,4,5,x\n", "line 1"),
        ("1,2,3,4,-5,6\n", "negative"),
        ("1,2,3,4,5,nan\n", "NaN"),
    ],
)
def test_malformed_files_raise_naming_file_and_line(tmp_path, text, message):
    path = tmp_path / "bad.txt"
    path.write_text(text)
    with pytest.raises(ValueError, match=message) as err:
        read_mot(path)
    assert "bad.txt" in str(err.value)


def test_missing_file_and_bad_rows_to_write_raise(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_mot(tmp_path / "nope.txt")
    with pytest.raises(ValueError, match="rows"):
        write_mot(tmp_path / "x.txt", np.zeros((2, 4)))
