"""report.html: self-contained (no external resource), balanced tags, escaped strings,
the per-track table against the simulated ships, the error and AIS tables, no tracks."""

from __future__ import annotations

import base64
import re
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from seawatch.report.html import render_report, write_report

VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source",
        "track", "wbr"}  # fmt: skip

ERRORS = {
    "rmse_position_m": 23.4,
    "rmse_range_percent": 2.1,
    "cle_px": 1.8,
    "id_switches": 0,
    "mota": 0.93,
    "idf1": 0.95,
    "by_range": {
        "0-1 km": {"rmse_position_m": 5.2, "n": 120},
        "1-3 km": {"rmse_position_m": 31.0, "n": 380},
    },
    "by_estimator": [
        {"estimator": "ekf", "rmse_position_m": 20.1},
        {"estimator": "geometry", "rmse_position_m": 35.25},
    ],
}
AIS = {  # as seawatch.tracking.ais_match.AisAssociation.as_dict() gives it
    "matches": [{"track_id": 2, "mmsi": 235000001}],
    "dark": [1, 3],
    "unseen": [235000009],
    "pairs": [
        {"track_id": 2, "mmsi": 235000002, "frames": 3, "mean_distance_m": 80.0},
        {"track_id": 2, "mmsi": 235000001, "frames": 160, "mean_distance_m": 12.3},
    ],
    "vessels": {"235000009": {"north_m": [-3000.0, -2900.0], "east_m": [1000.0, 1100.0]}},
}
SUMMARY = {"source": "clip.mp4", "frames": 1501, "rows": 403, "tracks": 3,
           "outputs": ["/out/tracks.csv", "/out/report.html"], "warnings": []}  # fmt: skip


class _Doc(HTMLParser):
    """Checks that every non-void tag is closed in order; collects tables and images."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.stack: list[str] = []
        self.problems: list[str] = []
        self.tags: list[str] = []
        self.images: list[str] = []
        self.tables: list[list[list[str]]] = []
        self._cell: list[str] | None = None
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        if tag == "img":
            self.images.append(dict(attrs).get("src", ""))
        if tag not in VOID:
            self.stack.append(tag)
        if tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self._cell = []

    def handle_endtag(self, tag):
        if tag in VOID:
            return
        if not self.stack or self.stack[-1] != tag:
            self.problems.append(f"</{tag}> closes <{self.stack[-1] if self.stack else None}>")
            return
        self.stack.pop()
        if tag in ("td", "th") and self._cell is not None:
            self.tables[-1][-1].append("".join(self._cell).strip())
            self._cell = None

    def handle_data(self, data):
        self.text.append(data)
        if self._cell is not None:
            self._cell.append(data)


def _parse(text: str) -> _Doc:
    doc = _Doc()
    doc.feed(text)
    doc.close()
    assert not doc.problems, doc.problems[:5]
    assert not doc.stack, f"unclosed: {doc.stack}"
    return doc


@pytest.fixture(scope="module")
def full_report(sim, tmp_path_factory) -> Path:
    """report.html of the simulated ships with a camera, errors and AIS (rendered once)."""
    folder = tmp_path_factory.mktemp("report")
    tracks_csv = sim.write_csv(folder / "tracks.csv", sim.ship_rows())
    return write_report(folder / "report.html", tracks_csv, camera=sim.make_camera(),
                        summary=SUMMARY, errors=ERRORS, ais=AIS)  # fmt: skip


def _table_with(doc: _Doc, header: str) -> list[list[str]]:
    return next(t for t in doc.tables if t and header in t[0])


def test_report_is_self_contained_valid_and_small(full_report):
    text = full_report.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>")
    doc = _parse(text)
    outside_data = re.sub(r"data:image/png;base64,[A-Za-z0-9+/=]+", "", text)
    assert not re.search(r"https?:|//[a-z]|url\(", outside_data, re.IGNORECASE)  # no URL
    assert "script" not in doc.tags and "link" not in doc.tags and "@import" not in text
    assert "Content-Security-Policy" in text and "default-src 'none'" in text
    assert len(doc.images) == 2  # plan view, range plot
    for src in doc.images:
        head, data = src.split(",", 1)
        assert head == "data:image/png;base64"
        assert base64.b64decode(data, validate=True)[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(text) < 600_000
    assert [p.name for p in full_report.parent.iterdir() if p.name.startswith(".")] == []


def test_track_table_matches_the_simulated_ships(full_report, rows, sim):
    doc = _parse(full_report.read_text(encoding="utf-8"))
    table = _table_with(doc, "Track")
    header, body = table[0], table[1:]
    assert [r[0] for r in body] == ["1", "2", "3"]
    col = {name: k for k, name in enumerate(header)}
    for r in body:
        tid = int(r[0])
        mine = [x for x in rows if int(x["track_id"]) == tid]
        rng = np.array([float(x["range_m"]) for x in mine])
        times = [float(x["time"]) for x in mine]
        assert float(r[col["First [s]"]]) == pytest.approx(min(times), abs=0.005)
        assert float(r[col["Last [s]"]]) == pytest.approx(max(times), abs=0.005)
        assert int(r[col["Fixes"]]) == len(mine)
        assert float(r[col["Mean range [m]"]]) == pytest.approx(rng.mean(), abs=0.051)
        assert float(r[col["Min range [m]"]]) == pytest.approx(rng.min(), abs=0.051)
        assert r[col["MMSI"]] == (sim.ships[tid][4] or "—")
        if tid == 3:  # one fix: no speed or course
            assert r[col["Mean speed [m/s]"]] == "—" and r[col["Course [deg]"]] == "—"
            continue
        vn, ve = sim.ships[tid][3]
        speed = float(r[col["Mean speed [m/s]"]].rstrip("*"))
        assert speed == pytest.approx(np.hypot(vn, ve), abs=0.006)
        knots = float(r[col["Mean speed [kn]"]].rstrip("*"))
        assert knots == pytest.approx(np.hypot(vn, ve) * 3600 / 1852, abs=0.006)
        course = float(r[col["Course [deg]"]].rstrip("*"))
        assert course == pytest.approx(np.degrees(np.arctan2(ve, vn)) % 360, abs=0.051)
        assert r[col["Mean speed [m/s]"]].endswith("*") == (tid == 1)  # fitted, footnoted


def test_header_lists_source_camera_frames_and_time_span(full_report):
    doc = _parse(full_report.read_text(encoding="utf-8"))
    text = " ".join(doc.text)
    assert "clip.mp4" in text and "1501" in text
    assert "0.00 s – 60.00 s" in text
    assert "50.780000° N, 1.100000° W" in text
    assert "10.00 m" in text and "200.0°" in text and "60.0° × 36.0°" in text
    assert "tracks.csv" in text and "/out/" not in text


def test_every_input_string_is_escaped(tracks_csv, camera):
    evil = "<script>alert('x')</script>&"
    summary = dict(SUMMARY, source=evil, warnings=[evil], note=evil)
    ais = dict(AIS, dark=[evil], unseen=[evil])
    text = render_report(tracks_csv, camera=camera, summary=summary, ais=ais, title=evil,
                         errors={evil: 1.0, "by_bin": {evil: {evil: evil}}})  # fmt: skip
    doc = _parse(text)
    assert "script" not in doc.tags and "<script>" not in text
    assert text.count("&lt;script&gt;") >= 7
    assert evil in " ".join(doc.text)  # shown as text


def test_error_and_ais_tables_show_values_and_units(full_report):
    doc = _parse(full_report.read_text(encoding="utf-8"))
    metrics = {r[0]: (r[1], r[2]) for r in _table_with(doc, "metric")[1:]}
    assert metrics["rmse position"] == ("23.4", "m")
    assert metrics["rmse range"] == ("2.10", "%")
    assert metrics["cle"] == ("1.80", "px")
    assert metrics["id switches"] == ("0", "")
    assert metrics["mota"] == ("0.93", "")
    bins = _table_with(doc, "bin")
    assert bins[0] == ["bin", "rmse position [m]", "n"]
    assert bins[1:] == [["0-1 km", "5.20", "120"], ["1-3 km", "31.0", "380"]]
    est = _table_with(doc, "estimator")
    assert est[1:] == [["ekf", "20.1"], ["geometry", "35.2"]]
    matched, every = [t for t in doc.tables if t and "track id" in t[0]]
    assert matched[0] == ["track id", "mmsi", "frames", "mean distance [m]"]
    assert matched[1:] == [["2", "235000001", "160", "12.3"]]  # the stats of its own pair
    assert len(every) == 3 and every[1] == ["2", "235000002", "3", "80.0"]
    text = " ".join(doc.text)
    assert "Dark vessels: camera tracks with no AIS partner (2)" in text and "#1, #3" in text
    assert "AIS vessels in view but not seen (1)" in text and "235000009" in text


def test_ais_matches_may_be_a_mapping_of_track_to_mmsi(tracks_csv):
    doc = _parse(render_report(tracks_csv, ais={"matches": {2: 235000001.0}, "dark": []}))
    assert _table_with(doc, "track id")[1:] == [["2", "235000001"]]
    assert "camera tracks with no AIS partner (0)" in " ".join(doc.text)


def test_errors_in_the_summary_are_used_when_not_given_separately(tracks_csv):
    doc = _parse(render_report(tracks_csv, summary=dict(SUMMARY, errors={"mota": 0.5})))
    assert _table_with(doc, "metric")[1] == ["mota", "0.5", ""]


def test_zero_tracks_gives_a_clear_note_and_a_valid_page(tmp_path, camera, sim):
    empty = sim.write_csv(tmp_path / "tracks.csv", [])
    text = render_report(empty, camera=camera, summary=dict(SUMMARY, rows=0, tracks=0))
    doc = _parse(text)
    assert "No tracks" in " ".join(doc.text)
    assert len(doc.images) == 1  # the plan view still shows the camera and its view
    text = render_report(empty, summary={})  # no camera either
    doc = _parse(text)
    assert "No tracks" in " ".join(doc.text) and not doc.images


def test_pixel_only_run_says_there_are_no_positions(rows, sim):
    pixel = [dict(r, range_m="", lat="", lon="", north_m="", east_m="", sigma_range_m="")
             for r in rows]  # fmt: skip
    doc = _parse(render_report(pixel, summary={"warnings": ["no --camera: pixel tracks only"]}))
    text = " ".join(doc.text)
    assert "No camera: pixel tracks only" in text
    assert "No positions to draw" in text and "No ranges" in text
    assert not doc.images
    assert [r[0] for r in _table_with(doc, "Track")[1:]] == ["1", "2", "3"]


def test_many_tracks_keep_the_report_small(tmp_path, rows):
    many = []
    for k in range(30):  # 30 copies of the ships, shifted: 90 tracks, 12k rows
        for r in rows:
            many.append(dict(r, track_id=str(int(r["track_id"]) + 10 * k),
                             north_m=repr(float(r["north_m"]) + 37.0 * k)))  # fmt: skip
    out = write_report(tmp_path / "r.html", many, summary=SUMMARY)
    _parse(out.read_text(encoding="utf-8"))
    assert Path(out).stat().st_size < 1_500_000
