"""Tables, plots and reports of seawatch results (matplotlib with the Agg backend, no GUI).

* :mod:`seawatch.report.geojson` — ``tracks.geojson`` (a line per track, points with
  times; :class:`GeoJsonSink` rewrites it atomically as a video is processed).
* :mod:`seawatch.report.annotate` — boxes, ids, MMSI, range, speed and the horizon drawn
  on frames; :class:`AnnotatedVideo` writes ``annotated.mp4`` (fragmented MP4).
* :mod:`seawatch.report.html` — ``report.html``: self-contained (no network) plan view,
  range-vs-time plots, per-track table, error tables and the AIS cross-check.
"""

from seawatch.report.annotate import AnnotatedVideo, Annotator
from seawatch.report.geojson import (
    GeoJsonSink,
    TrackSeries,
    load_tracks,
    tracks_to_geojson,
    write_geojson,
)
from seawatch.report.html import render_report, write_report

__all__ = [
    "AnnotatedVideo",
    "Annotator",
    "GeoJsonSink",
    "TrackSeries",
    "load_tracks",
    "render_report",
    "tracks_to_geojson",
    "write_geojson",
    "write_report",
]
