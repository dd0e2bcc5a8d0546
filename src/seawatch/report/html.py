"""``report.html``: a self-contained report of a ``seawatch track`` run (issue 7).

One HTML file with no external resource — inline CSS, figures as inline PNG (``data:``
URIs drawn with matplotlib's Agg canvas), no script, no web font, no ``http(s)`` URL, and
a Content-Security-Policy that forbids loading anything else — so it opens offline, from
an e-mail or an archive, and renders the same everywhere. Content:

* header: title, source, camera (position, height, heading, attitude, fields of view),
  frames and time span, warnings;
* plan view (North up, East right, m or km): the camera and its view wedge, each track's
  path labelled with its id/MMSI, AIS vessels when given;
* range against time per track (with the ±1-σ band where the table has ``sigma_range_m``);
* one table row per track (id, MMSI, first/last time, fixes, mean/min range, mean speed in
  m/s and kn, mean course);
* with ``errors`` (the ``errors`` object of INTERFACES.md, possibly with sub-tables per
  range bin or estimator) the error tables; with ``ais`` (``matches``, ``dark``,
  ``unseen``) the AIS cross-check.

Every string from the inputs is escaped (:func:`html.escape`). Works with no track at all
(a "no tracks" note instead of the figures).
"""

from __future__ import annotations

import base64
import html
import io
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from seawatch.geometry.geodesy import geodetic_to_north_east
from seawatch.report.annotate import track_colour
from seawatch.report.geojson import KNOT, TrackSeries, TrackSource, atomic_write_text, load_tracks

__all__ = ["render_report", "write_report"]

MAX_LABELS = 30
"""Most track labels drawn in the plan view (the tracks with the most fixes)."""

MAX_LEGEND = 15
"""Most tracks named in the range plot's legend."""

_UNITS = (
    ("_percent", "%"), ("_mps", "m/s"), ("_kn", "kn"), ("_px", "px"), ("_deg", "deg"),
    ("_arcmin", "arcmin"), ("_m", "m"), ("_s", "s"),
)  # fmt: skip

_CSS = """
:root{--fg:#1d2733;--muted:#5b6b7c;--line:#d5dde6;--bg:#ffffff;--band:#f3f6f9;--warn:#8a5a00}
*{box-sizing:border-box}
body{margin:0;padding:0 1.5rem 2rem;font:15px/1.45 system-ui,-apple-system,"Segoe UI",
Roboto,"Helvetica Neue",Arial,sans-serif;color:var(--fg);background:var(--bg)}
header{border-bottom:3px solid #0b5394;padding:1rem 0 .6rem;margin-bottom:1rem}
h1{margin:0 0 .2rem;font-size:1.6rem;color:#0b5394}
h2{font-size:1.2rem;margin:1.6rem 0 .5rem;border-bottom:1px solid var(--line)}
h3{font-size:1rem;margin:1rem 0 .4rem}
.meta{color:var(--muted);margin:0;font-size:.9rem}
.grid{display:flex;flex-wrap:wrap;gap:1.5rem}
table{border-collapse:collapse;font-size:.88rem;margin:.3rem 0 .8rem}
th,td{border:1px solid var(--line);padding:.25rem .55rem;text-align:right;vertical-align:top}
th{background:var(--band);font-weight:600}
td.l,th.l{text-align:left}
table.kv th{text-align:left;width:11rem}
table.kv td{text-align:left}
tbody tr:nth-child(even){background:#fafbfc}
.sw{display:inline-block;width:.8rem;height:.8rem;border-radius:2px;margin-right:.35rem;
vertical-align:-1px;border:1px solid rgba(0,0,0,.25)}
figure{margin:.4rem 0 1rem}
figure img{max-width:100%;height:auto;border:1px solid var(--line)}
figcaption{color:var(--muted);font-size:.85rem;max-width:60rem}
.note{background:var(--band);border-left:4px solid #0b5394;padding:.5rem .8rem;max-width:60rem}
.warn{color:var(--warn)}
ul.warn{margin:.2rem 0 .8rem}
footer{margin-top:2rem;color:var(--muted);font-size:.8rem}
code{font-size:.85rem}
"""

_CSP = "default-src 'none'; img-src data:; style-src 'unsafe-inline'"


# --------------------------------------------------------------------------------------
# small helpers
# --------------------------------------------------------------------------------------


def _e(value: Any) -> str:
    return html.escape(str(value), quote=True)


def _number(value: Any) -> str:
    """A number for a table cell: ``—`` for missing/NaN, 4 significant digits or so."""
    if value is None:
        return "—"
    if isinstance(value, bool | np.bool_):
        return "yes" if value else "no"
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        v = float(value)
        if not math.isfinite(v):
            return "—"
        a = abs(v)
        if a == 0.0:
            return "0"
        if a >= 1e7:
            return f"{v:.4g}"
        if a >= 10.0:
            return f"{v:.1f}"
        if a >= 1.0:
            return f"{v:.2f}"
        return f"{v:.3g}" if a >= 1e-3 else f"{v:.2e}"
    return _e(value)


def _unit(key: str) -> str:
    for suffix, unit in _UNITS:
        if key.endswith(suffix):
            return unit
    return ""


def _label(key: Any) -> str:
    """A column/metric name for display: underscores as spaces, the unit suffix dropped
    (the unit is shown separately)."""
    text = str(key)
    for suffix, _ in _UNITS:
        if text.endswith(suffix) and len(text) > len(suffix):
            text = text[: -len(suffix)]
            break
    return _e(text.replace("_", " "))


def _rgb(track_id: int) -> str:
    b, g, r = track_colour(track_id)
    return f"#{r:02x}{g:02x}{b:02x}"


def _png(fig: Figure) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=fig.dpi, metadata={"Software": None})
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _figure(uri: str, alt: str, caption: str) -> str:
    return f'<figure><img src="{uri}" alt="{_e(alt)}"><figcaption>{caption}</figcaption></figure>'


def _kv_table(rows: Iterable[tuple[str, str]]) -> str:
    body = "".join(f"<tr><th>{k}</th><td>{v}</td></tr>" for k, v in rows)
    return f'<table class="kv"><tbody>{body}</tbody></table>'


def _deg(rad: float | None, digits: int = 1) -> str:
    return "—" if rad is None else f"{math.degrees(rad):.{digits}f}°"


def _version() -> str:
    try:
        return metadata.version("seawatch")
    except metadata.PackageNotFoundError:  # pragma: no cover - not installed
        return "unknown"


# --------------------------------------------------------------------------------------
# sections
# --------------------------------------------------------------------------------------


def _run_section(summary: Mapping[str, Any], tracks: list[TrackSeries]) -> str:
    rows: list[tuple[str, str]] = []
    if "source" in summary:
        rows.append(("Source", f"<code>{_e(summary['source'])}</code>"))
    times = [t.time for t in tracks if len(t)]
    if "frames" in summary:
        rows.append(("Frames", _number(summary["frames"])))
    if times:
        t0 = min(float(t[0]) for t in times)
        t1 = max(float(t[-1]) for t in times)
        rows.append(("Time span of tracks", f"{t0:.2f} s – {t1:.2f} s ({t1 - t0:.2f} s)"))
    for key, name in (("duration_s", "Duration"), ("fps", "Frame rate [1/s]")):
        if key in summary:
            rows.append((name, _number(summary[key])))
    rows.append(("Tracks", str(len(tracks))))
    if "rows" in summary:
        rows.append(("Table rows", _number(summary["rows"])))
    shown = {"source", "frames", "duration_s", "fps", "tracks", "rows", "outputs", "warnings",
             "errors", "ais"}  # fmt: skip
    for key, value in summary.items():
        if key not in shown and (value is None or isinstance(value, str | int | float)):
            rows.append((_label(key), _number(value)))
    outputs = summary.get("outputs") or []
    if outputs:
        rows.append(("Outputs", " ".join(f"<code>{_e(Path(str(p)).name)}</code>" for p in outputs)))
    out = "<h2>Run</h2>" + _kv_table(rows)
    warns = [str(w) for w in (summary.get("warnings") or [])]
    if warns:
        items = "".join(f"<li>{_e(w)}</li>" for w in warns)
        out += f'<h3 class="warn">Warnings</h3><ul class="warn">{items}</ul>'
    return f'<section id="run">{out}</section>'


def _camera_section(camera: Any) -> str:
    if camera is None:
        body = '<p class="note">No camera: pixel tracks only (no angles, ranges or positions).</p>'
        return f'<section id="camera"><h2>Camera</h2>{body}</section>'
    rows: list[tuple[str, str]] = []
    lat, lon = getattr(camera, "lat", None), getattr(camera, "lon", None)
    if lat is not None and lon is not None:
        ns, ew = "N" if lat >= 0 else "S", "E" if lon >= 0 else "W"
        rows.append(("Position", f"{abs(lat):.6f}° {ns}, {abs(lon):.6f}° {ew} (WGS-84)"))
    else:
        rows.append(("Position", "not given (local coordinates only)"))
    pos = getattr(camera, "position", None)
    if pos is not None and any(pos):
        rows.append(("Local position", f"North {pos[0]:.1f} m, East {pos[1]:.1f} m"))
    height = getattr(camera, "height", None)
    rows.append(("Height above sea", "unknown" if height is None else f"{height:.2f} m"))
    rows.append(("Heading", _deg(getattr(camera, "heading", None))))
    rows.append(
        (
            "Pitch / roll",
            f"{_deg(getattr(camera, 'pitch', None), 2)} / {_deg(getattr(camera, 'roll', None), 2)}",
        )
    )
    hfov, vfov = getattr(camera, "hfov", None), getattr(camera, "vfov", None)
    if hfov is not None and vfov is not None:
        rows.append(("Field of view", f"{math.degrees(hfov):.1f}° × {math.degrees(vfov):.1f}°"))
    size = getattr(camera, "image_size", None)
    if size is not None:
        rows.append(("Image", f"{size[0]} × {size[1]} px"))
    fx = getattr(camera, "fx", None)
    if fx is not None:
        rows.append(("Focal length", f"{fx:.1f} px"))
    return f'<section id="camera"><h2>Camera</h2>{_kv_table(rows)}</section>'


def _positions(track: TrackSeries, camera: Any) -> np.ndarray:
    """(T, 2) North/East [m] in the camera's tangent plane (NaN where unknown)."""
    p = np.stack([track.north_m, track.east_m], axis=-1)
    lat0, lon0 = getattr(camera, "lat", None), getattr(camera, "lon", None)
    if np.any(np.isfinite(p).all(axis=1)):
        return p
    if lat0 is not None and lon0 is not None:
        ok = np.isfinite(track.lat) & np.isfinite(track.lon)
        if np.any(ok):
            p[ok] = geodetic_to_north_east(track.lat[ok], track.lon[ok], lat0, lon0)
        return p
    return track.local_positions() if camera is None else p


def _ais_paths(ais: Mapping[str, Any] | None, camera: Any) -> list[tuple[str, np.ndarray]]:
    """AIS vessels of ``ais["vessels"]`` as (mmsi, (T, 2) North/East [m]) paths."""
    if not ais or not ais.get("vessels"):
        return []
    vessels = ais["vessels"]
    items = (
        list(vessels.items())
        if isinstance(vessels, Mapping)
        else [(v.get("mmsi"), v) for v in vessels]
    )
    out = []
    lat0, lon0 = getattr(camera, "lat", None), getattr(camera, "lon", None)
    for mmsi, v in items:
        if "north_m" in v and "east_m" in v:
            p = np.stack([np.asarray(v["north_m"], float), np.asarray(v["east_m"], float)], -1)
        elif "lat" in v and "lon" in v and lat0 is not None and lon0 is not None:
            p = geodetic_to_north_east(np.asarray(v["lat"], float), np.asarray(v["lon"], float),
                                       lat0, lon0)  # fmt: skip
        else:
            continue
        p = np.atleast_2d(p)
        if np.any(np.isfinite(p).all(axis=1)):
            out.append((str(mmsi), p))
    return out


def _plan_view(
    tracks: list[TrackSeries], camera: Any, ais: Mapping[str, Any] | None
) -> tuple[str, str] | None:
    paths = [(t, _positions(t, camera)) for t in tracks]
    paths = [(t, p[np.isfinite(p).all(axis=1)]) for t, p in paths]
    paths = [(t, p) for t, p in paths if len(p)]
    vessels = _ais_paths(ais, camera)
    if not paths and not vessels and camera is None:
        return None
    cam = np.asarray(getattr(camera, "position", (0.0, 0.0)), float) if camera else None
    centre = cam if cam is not None else np.zeros(2)
    pts = [p for _, p in paths] + [p[np.isfinite(p).all(axis=1)] for _, p in vessels]
    reach = max((float(np.max(np.hypot(*(q - centre).T))) for q in pts if len(q)), default=0.0)
    if reach <= 0.0:
        height = getattr(camera, "height", None)
        reach = math.sqrt(2.0 * 6_371_000.0 * height) if height else 5000.0
    scale, unit = (1000.0, "km") if reach > 2000.0 else (1.0, "m")
    fig = Figure(figsize=(7.5, 7.0), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    if camera is not None:
        heading = float(getattr(camera, "heading", 0.0) or 0.0)
        hfov = float(getattr(camera, "hfov", 0.0) or 0.0)
        radius = 1.1 * reach
        az = heading + np.linspace(-hfov / 2.0, hfov / 2.0, 60)
        e = np.concatenate([[0.0], radius * np.sin(az), [0.0]]) + centre[1]
        n = np.concatenate([[0.0], radius * np.cos(az), [0.0]]) + centre[0]
        ax.fill(e / scale, n / scale, color="#9ecae1", alpha=0.25, lw=0, label="camera view")
        ax.plot(e / scale, n / scale, color="#6baed6", lw=0.8)
        ax.plot(centre[1] / scale, centre[0] / scale, marker="^", ms=11, color="#08306b",
                ls="none", label="camera")  # fmt: skip
    unseen = {str(m) for m in (ais or {}).get("unseen", []) or []}
    for k, (mmsi, p) in enumerate(vessels):
        colour = "#e6550d" if mmsi in unseen else "0.45"
        ax.plot(p[:, 1] / scale, p[:, 0] / scale, ls="--", lw=1.0, color=colour,
                label="AIS vessel" if k == 0 else None)  # fmt: skip
        last = p[np.isfinite(p).all(axis=1)][-1]
        ax.annotate(f"AIS {mmsi}", (last[1] / scale, last[0] / scale), fontsize=7, color=colour,
                    xytext=(3, -9), textcoords="offset points")  # fmt: skip
    labelled = {t.track_id for t, _ in sorted(paths, key=lambda tp: -len(tp[1]))[:MAX_LABELS]}
    for t, p in paths:
        colour = _rgb(t.track_id)
        ax.plot(p[:, 1] / scale, p[:, 0] / scale, "-", lw=1.6, color=colour, alpha=0.9)
        ax.plot(p[-1, 1] / scale, p[-1, 0] / scale, "o", ms=4, color=colour, mec="k", mew=0.4)
        if t.track_id in labelled:
            text = f"#{t.track_id}" + (f" {t.mmsi}" if t.mmsi else "")
            ax.annotate(text, (p[-1, 1] / scale, p[-1, 0] / scale), fontsize=8,
                        xytext=(4, 4), textcoords="offset points")  # fmt: skip
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"East [{unit}]")
    ax.set_ylabel(f"North [{unit}]")
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize=8)
    caption = (
        f"Plan view, North up, East right [{unit}]"
        + (", camera at the triangle with its horizontal field of view" if camera else "")
        + ". Track paths end at the dot"
        + (f"; the {MAX_LABELS} longest tracks are labelled" if len(paths) > MAX_LABELS else "")
        + ("; dashed: AIS vessels (orange: in view, never seen)" if vessels else "")
        + "."
    )
    return _png(fig), caption


def _range_plot(tracks: list[TrackSeries]) -> tuple[str, str] | None:
    with_range = [t for t in tracks if np.any(np.isfinite(t.range_m))]
    if not with_range:
        return None
    far = max(float(np.nanmax(t.range_m)) for t in with_range)
    scale, unit = (1000.0, "km") if far > 2000.0 else (1.0, "m")
    fig = Figure(figsize=(9.0, 4.2), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    banded = False
    for t in with_range:
        ok = np.isfinite(t.range_m)
        colour = _rgb(t.track_id)
        label = (
            (f"#{t.track_id}" + (f" {t.mmsi}" if t.mmsi else ""))
            if len(with_range) <= (MAX_LEGEND)
            else None
        )
        style = "o" if ok.sum() == 1 else "-"
        ax.plot(t.time[ok], t.range_m[ok] / scale, style, lw=1.3, ms=4, color=colour, label=label)
        s = t.sigma_range_m
        good = ok & np.isfinite(s)
        if np.any(good):
            banded = True
            lo = (t.range_m[good] - s[good]) / scale
            hi = (t.range_m[good] + s[good]) / scale
            ax.fill_between(t.time[good], lo, hi, color=colour, alpha=0.18, lw=0)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"range [{unit}]")
    ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    if len(with_range) <= MAX_LEGEND:
        ax.legend(fontsize=8, ncol=min(5, len(with_range)), loc="best")
    caption = "Range from the camera against time per track" + (", shaded ±1σ" if banded else "")
    return _png(fig), caption + "."


def _tracks_table(tracks: list[TrackSeries]) -> str:
    head = (
        "<tr><th class=l>Track</th><th class=l>MMSI</th><th>First [s]</th><th>Last [s]</th>"
        "<th>Fixes</th><th>Mean range [m]</th><th>Min range [m]</th>"
        "<th>Mean speed [m/s]</th><th>Mean speed [kn]</th><th>Course [deg]</th></tr>"
    )
    body = []
    fitted = False
    for t in tracks:
        r = t.range_m[np.isfinite(t.range_m)]
        speed, s_src = t.mean_speed()
        course, c_src = t.mean_course()
        mark_s = "*" if s_src == "fit" else ""
        mark_c = "*" if c_src == "fit" else ""
        fitted |= bool(mark_s or mark_c)
        body.append(
            "<tr>"
            f'<td class=l><span class="sw" style="background:{_rgb(t.track_id)}"></span>'
            f"{t.track_id}</td>"
            f"<td class=l>{_e(t.mmsi) if t.mmsi else '—'}</td>"
            f"<td>{t.time[0]:.2f}</td><td>{t.time[-1]:.2f}</td><td>{len(t)}</td>"
            f"<td>{_number(float(r.mean()) if r.size else None)}</td>"
            f"<td>{_number(float(r.min()) if r.size else None)}</td>"
            f"<td>{_number(speed)}{mark_s}</td><td>{_number(speed / KNOT)}{mark_s}</td>"
            f"<td>{_number(course)}{mark_c}</td>"
            "</tr>"
        )
    note = (
        '<p class="meta">* from a least-squares constant-velocity fit of the positions (the '
        "table has no speed/course).</p>"
        if fitted
        else ""
    )
    return f"<table><thead>{head}</thead><tbody>{''.join(body)}</tbody></table>{note}"


def _is_scalar(v: Any) -> bool:
    return v is None or isinstance(v, str | int | float | bool | np.generic)


def _records_table(rows: Sequence[Mapping[str, Any]], first: str | None = None) -> str:
    """A table of records (union of their keys as columns, in order of appearance)."""
    cols: list[str] = []
    for r in rows:
        cols.extend(k for k in r if k not in cols and _is_scalar(r[k]))
    head = "".join(
        f"<th{' class=l' if k == first else ''}>{_label(k)}"
        f"{f' [{_e(_unit(k))}]' if _unit(k) else ''}</th>"
        for k in cols
    )
    body = "".join(
        "<tr>"
        + "".join(f"<td{' class=l' if k == first else ''}>{_number(r.get(k))}</td>" for k in cols)
        + "</tr>"
        for r in rows
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _value_tables(title: str, value: Any, depth: int = 0) -> str:
    """Tables of a (nested) errors-like object: scalars as metric/value/unit rows,
    dicts of dicts and lists of dicts as tables, deeper levels recursively."""
    h = f"<h3>{_label(title)}</h3>" if title else ""
    if isinstance(value, Mapping):
        scalars = [(k, v) for k, v in value.items() if _is_scalar(v)]
        nested = [(k, v) for k, v in value.items() if not _is_scalar(v)]
        out = ""
        if scalars:
            rows = "".join(
                f"<tr><td class=l>{_label(k)}</td><td>{_number(v)}</td>"
                f"<td class=l>{_e(_unit(str(k)))}</td></tr>"
                for k, v in scalars
            )
            out += (
                "<table><thead><tr><th class=l>metric</th><th>value</th><th class=l>unit</th>"
                f"</tr></thead><tbody>{rows}</tbody></table>"
            )
        for k, v in nested:
            if (
                isinstance(v, Mapping)
                and v
                and all(isinstance(x, Mapping) and all(_is_scalar(y) for y in x.values())
                        for x in v.values())
            ):  # fmt: skip
                key = "bin" if "range" in str(k) else "name"
                records = [{key: name, **dict(inner)} for name, inner in v.items()]
                out += f"<h3>{_label(k)}</h3>" + _records_table(records, first=key)
            elif (
                isinstance(v, Sequence)
                and not isinstance(v, str)
                and v
                and all(isinstance(x, Mapping) for x in v)
            ):
                out += f"<h3>{_label(k)}</h3>" + _records_table(
                    list(v), first=next(iter(v[0]), None)
                )
            elif depth < 3:
                out += _value_tables(str(k), v, depth + 1)
        return h + out
    if isinstance(value, Sequence) and not isinstance(value, str):
        if value and all(isinstance(x, Mapping) for x in value):
            return h + _records_table(list(value), first=next(iter(value[0]), None))
        return h + f"<p>{', '.join(_number(x) for x in value) or '—'}</p>"
    return h + f"<p>{_number(value)}</p>"


def _ids_as_text(record: dict[str, Any]) -> dict[str, Any]:
    """Track ids and MMSIs are labels, not quantities: show them as integers' text."""
    for k in ("track_id", "mmsi"):
        v = record.get(k)
        if isinstance(v, int | float | np.integer | np.floating) and not isinstance(v, bool):
            record[k] = str(int(v)) if math.isfinite(v) else None
    return record


def _ais_section(ais: Mapping[str, Any]) -> str:
    out = "<h2>AIS cross-check</h2>"
    matches = ais.get("matches") or {}
    if isinstance(matches, Mapping):
        records = [{"track_id": k, "mmsi": v} for k, v in matches.items()]
    else:
        records = [dict(m) for m in matches]
    pairs = ais.get("pairs") or []
    if isinstance(pairs, Mapping):
        pairs = [{"track_id": k, **dict(v)} for k, v in pairs.items()]
    pairs = [_ids_as_text(dict(p)) for p in pairs if isinstance(p, Mapping)]
    records = [_ids_as_text(r) for r in records]
    by_pair = {(p.get("track_id"), p.get("mmsi")): p for p in pairs}
    for r in records:  # per-pair statistics of the matched pair
        extra = by_pair.get((r.get("track_id"), r.get("mmsi")), {})
        r.update({k: v for k, v in extra.items() if k not in r})
    out += f"<h3>Matched tracks ({len(records)})</h3>"
    out += _records_table(records, first="track_id") if records else "<p>None.</p>"
    dark = list(ais.get("dark") or [])
    unseen = list(ais.get("unseen") or [])
    out += f"<h3>Dark vessels: camera tracks with no AIS partner ({len(dark)})</h3>"
    out += f"<p>{', '.join('#' + _e(d) for d in dark)}</p>" if dark else "<p>None.</p>"
    out += f"<h3>AIS vessels in view but not seen ({len(unseen)})</h3>"
    out += f"<p>{', '.join(_e(u) for u in unseen)}</p>" if unseen else "<p>None.</p>"
    if len(pairs) > len(records):
        out += f"<h3>Every track–vessel pair associated at least once ({len(pairs)})</h3>"
        out += _records_table(pairs, first="track_id")
    return f'<section id="ais">{out}</section>'


# --------------------------------------------------------------------------------------
# the report
# --------------------------------------------------------------------------------------


def render_report(
    tracks_csv: TrackSource,
    *,
    camera: Any = None,
    summary: Mapping[str, Any] | None = None,
    errors: Mapping[str, Any] | None = None,
    ais: Mapping[str, Any] | None = None,
    title: str = "seawatch track report",
) -> str:
    """The HTML text of :func:`write_report` (same arguments, no file)."""
    summary = dict(summary or {})
    if errors is None and isinstance(summary.get("errors"), Mapping):
        errors = summary["errors"]
    tracks = [t for t in load_tracks(tracks_csv) if len(t)]
    now = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f'<meta http-equiv="Content-Security-Policy" content="{_CSP}">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f'<meta name="generator" content="seawatch {_e(_version())}">',
        f"<title>{_e(title)}</title><style>{_CSS}</style></head><body>",
        f"<header><h1>{_e(title)}</h1>",
    ]
    if "source" in summary:
        parts.append(f'<p class="meta">{_e(summary["source"])}</p>')
    parts.append(f'<p class="meta">generated {now} by seawatch {_e(_version())}</p></header>')
    parts.append(
        f'<div class="grid"><div>{_run_section(summary, tracks)}</div>'
        f"<div>{_camera_section(camera)}</div></div>"
    )
    if not tracks:
        parts.append(
            '<section id="tracks"><h2>Tracks</h2><p class="note">No tracks: no ship was '
            "tracked in this video.</p></section>"
        )
    plan = _plan_view(tracks, camera, ais)
    parts.append('<section id="plan"><h2>Plan view</h2>')
    if plan is not None:
        parts.append(_figure(plan[0], "plan view of the tracks around the camera", plan[1]))
    else:
        parts.append('<p class="note">No positions to draw (no camera: pixel tracks only).</p>')
    parts.append("</section>")
    if tracks:
        rng = _range_plot(tracks)
        parts.append('<section id="range"><h2>Range against time</h2>')
        if rng is not None:
            parts.append(_figure(rng[0], "range of each track against time", rng[1]))
        else:
            parts.append('<p class="note">No ranges (no camera: pixel tracks only).</p>')
        parts.append("</section>")
        parts.append(
            f'<section id="tracks"><h2>Tracks ({len(tracks)})</h2>{_tracks_table(tracks)}</section>'
        )
    if errors:
        parts.append(
            f'<section id="errors"><h2>Errors against the truth</h2>{_value_tables("", errors)}'
            "</section>"
        )
    if ais:
        parts.append(_ais_section(ais))
    parts.append(
        "<footer>Positions in the camera's local tangent plane (North, East); speeds over "
        "ground (1 kn = 1852 m/h); courses clockwise from North.</footer></body></html>"
    )
    return "\n".join(parts) + "\n"


def write_report(
    path: str | os.PathLike[str],
    tracks_csv: TrackSource,
    *,
    camera: Any = None,
    summary: Mapping[str, Any] | None = None,
    errors: Mapping[str, Any] | None = None,
    ais: Mapping[str, Any] | None = None,
    title: str = "seawatch track report",
) -> Path:
    """Write ``report.html``: a self-contained report of a ``seawatch track`` run.

    Args:
        path: the output file (written atomically: temporary file + ``os.replace``).
        tracks_csv: the track table, a ``tracks.csv`` path or rows
            (:func:`seawatch.report.geojson.load_tracks`).
        camera: the :class:`seawatch.camera.PinholeCamera` used (or an object with its
            attributes), or None for a pixel-only run.
        summary: the run's ``--json`` summary (:meth:`seawatch.pipeline.TrackRun.to_json`:
            ``frames``, ``rows``, ``outputs``, ``warnings``), optionally with ``source``,
            ``fps``, ``duration_s`` and further scalars (listed as they are); an
            ``errors`` entry is used when ``errors`` is None.
        errors: the ``errors`` object of INTERFACES.md (``rmse_position_m``,
            ``rmse_range_percent``, ``cle_px``, ``id_switches``, ``mota``, ``idf1``),
            possibly with sub-tables: a dict of dicts (e.g. per range bin or per
            estimator) or a list of records. Units come from the key suffixes
            (``_m``, ``_percent``, ``_px``, ``_deg``, ``_mps``, ``_s``).
        ais: the AIS cross-check: ``matches`` ({track_id: mmsi} or records),
            ``dark`` (track ids), ``unseen`` (MMSIs), optional ``pairs`` (records with
            ``track_id`` and per-pair statistics) and ``vessels`` ({mmsi: {north_m,
            east_m} or {lat, lon}} arrays, drawn in the plan view).
        title: the page title.

    Returns:
        The path written.
    """
    text = render_report(
        tracks_csv, camera=camera, summary=summary, errors=errors, ais=ais, title=title
    )
    return atomic_write_text(path, text)
