"""Tests of the camera-track ↔ AIS associator (``seawatch.tracking.ais_match``).

AIS input always goes through the real reader: simulated vessels are written as CSV files
with the Solent file's columns and read back with :func:`seawatch.io.read_ais`.
Independent references: the simulated truth (closed-form straight-line motion), pymap3d
for the tangent plane, :func:`seawatch.io.ais.interpolate_track` called per vessel (the
associator evaluates the same curve vectorised), hand-counted frames for the label
rules, and the real Solent AIS file (Stone Soup ``docs/demos/SolentAIS_20160112_130211
.csv``, MIT; see ``../shared/data/README.md``) for the "every vessel gets its own MMSI"
check.
"""

from __future__ import annotations

import json
import math
import warnings
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pymap3d
import pytest
from hypothesis import given
from hypothesis import strategies as st

from seawatch.io import ais
from seawatch.tracking.ais_match import AisAssociator, ViewWedge, in_view_wedge

SOLENT = (
    Path(__file__).resolve().parents[2]
    / ".."
    / "shared"
    / "data"
    / "ais"
    / "solent_2016-01-12_1302-1344.csv"
)
LAT0, LON0 = 50.80, -1.10
T0 = datetime(2016, 1, 12, 13, 0, 0, tzinfo=UTC).timestamp()
KNOT = 1852.0 / 3600.0
HEADER = "Time,MMSI,Latitude_degrees,Longitude_degrees,COG_degrees,SOG_knots"

A, B, C, U, S = 201000001, 201000002, 201000003, 201000004, 201000005
VESSELS = {
    A: ((1500.0, -600.0), (0.0, 4.0)),  # eastbound, crosses B 28 m apart at t = 155 s
    B: ((900.0, 40.0), (4.0, 0.0)),  # northbound
    C: ((2000.0, -500.0), (0.0, 0.0)),  # at anchor, in view
    U: ((2500.0, 400.0), (0.5, 0.0)),  # in view, never seen by the camera: unseen
    S: ((-1000.0, 0.0), (0.0, 3.0)),  # behind the camera: not expected in view
}
DARK = ((1000.0, 300.0), (-2.0, 1.0))  # a camera track without AIS
WEDGE = ViewWedge(heading=0.0, hfov=math.radians(60.0), max_range=4000.0)


def _truth(motion, t):
    (n0, e0), (vn, ve) = motion
    s = np.asarray(t, dtype=float) - T0
    return np.stack([n0 + vn * s, e0 + ve * s], axis=-1)


def _row(t: float, mmsi: int, north: float, east: float, vn: float, ve: float) -> str:
    lat, lon, _ = pymap3d.enu2geodetic(east, north, 0.0, LAT0, LON0, 0.0)
    cog = math.degrees(math.atan2(ve, vn)) % 360.0
    sog = math.hypot(vn, ve) / KNOT
    stamp = datetime.fromtimestamp(t, UTC).strftime("%Y-%m-%d %H:%M:%S.%f")[:-3]
    return f"{stamp},{mmsi},{lat:.9f},{lon:.9f},{cog:.1f},{sog:.2f}"


def _write_ais(path: Path, vessels, *, start=-60.0, stop=360.0, every=6.0, jitter=2.0, seed=1):
    """AIS reports of straight-line vessels every ``every`` s with GNSS jitter, as CSV."""
    rng = np.random.default_rng(seed)
    rows = [HEADER]
    for i, (mmsi, motion) in enumerate(vessels.items()):
        for t in T0 + start + i + np.arange(0.0, stop - start, every):
            n, e = _truth(motion, t) + rng.normal(0.0, jitter, 2)
            rows.append(_row(t, mmsi, n, e, *motion[1]))
    path.write_text("\n".join(rows) + "\n")
    return ais.read_ais(path)


@pytest.fixture(scope="module")
def table(tmp_path_factory) -> ais.AisTable:
    return _write_ais(tmp_path_factory.mktemp("ais") / "sim.csv", VESSELS)


def _assoc(table, **kw) -> AisAssociator:
    return AisAssociator(table, lat0=LAT0, lon0=LON0, **kw)


def _camera(t, rng, sigma):
    """Tracks 11..14: noisy copies of A, B, C and the dark vessel; true velocities."""
    z = np.stack([_truth(VESSELS[m], t) for m in (A, B, C)] + [_truth(DARK, t)])
    v = np.array([VESSELS[A][1], VESSELS[B][1], VESSELS[C][1], DARK[1]])
    return z + rng.normal(0.0, sigma, z.shape), v + rng.normal(0.0, 0.5, v.shape)


# ------------------------------------------------------------------ AIS sampling
def test_vessel_positions_equal_interpolate_track_between_reports(table):
    assoc = _assoc(table)
    per_vessel = ais.tracks(table)
    for t in T0 + np.array([0.0, 3.3, 151.7, 299.9]):
        vs = assoc.vessels_at(t)
        assert set(vs.mmsi.tolist()) == set(VESSELS)
        for k, m in enumerate(vs.mmsi):
            ref = ais.interpolate_track(per_vessel[int(m)], [t], origin=(LAT0, LON0))
            assert ref.valid[0] and not vs.extrapolated[k]
            assert vs.north[k] == pytest.approx(ref.north[0], abs=1e-6)
            assert vs.east[k] == pytest.approx(ref.east[0], abs=1e-6)
            assert vs.velocity[k] == pytest.approx(ref.velocity[0], abs=1e-9)
            # and the truth (reports jitter by 2 m)
            assert np.hypot(*(_truth(VESSELS[int(m)], t) - [vs.north[k], vs.east[k]])) < 8.0


def test_vessels_are_dead_reckoned_for_at_most_max_extrapolation(table):
    assoc = _assoc(table)
    last = ais.tracks(table)[S].time[-1]
    vs = assoc.vessels_at(last + 29.0)
    k = list(vs.mmsi).index(S)
    assert vs.extrapolated[k] and vs.age[k] == pytest.approx(29.0, abs=1e-6)
    assert vs.sigma[k] == pytest.approx(math.hypot(10.0, 0.5 * 29.0))
    truth = _truth(VESSELS[S], last + 29.0)
    assert np.hypot(vs.north[k] - truth[0], vs.east[k] - truth[1]) < 10.0
    assert S not in assoc.vessels_at(last + 31.0).mmsi
    first = ais.tracks(table)[S].time[0]
    assert S in assoc.vessels_at(first - 29.0).mmsi
    assert S not in assoc.vessels_at(first - 31.0).mmsi


def test_inside_a_long_report_gap_vessels_are_not_invented(tmp_path):
    rows = [HEADER]
    for t in np.r_[np.arange(0.0, 101.0, 10.0), np.arange(400.0, 501.0, 10.0)]:
        rows.append(_row(T0 + t, A, 0.0, 2.0 * t, 0.0, 2.0))
    path = tmp_path / "gap.csv"
    path.write_text("\n".join(rows) + "\n")
    assoc = _assoc(ais.read_ais(path))
    assert A not in assoc.vessels_at(T0 + 250.0).mmsi  # 300 s gap > MAX_GAP (200 s)
    vs = assoc.vessels_at(T0 + 110.0)  # 10 s after the last report before the gap
    assert vs.extrapolated[0] and vs.east[0] == pytest.approx(220.0, abs=1.0)
    assert vs.sigma[0] == pytest.approx(math.hypot(10.0, 5.0))
    vs = assoc.vessels_at(T0 + 55.0)
    assert not vs.extrapolated[0] and vs.age[0] == pytest.approx(5.0)


# ------------------------------------------------------------------ the scenario
@pytest.mark.parametrize("use_velocity", [False, True])
def test_labels_dark_and_unseen_with_no_swap_where_two_vessels_cross(table, use_velocity):
    rng = np.random.default_rng(1234)
    sigma = 15.0
    assoc = _assoc(table, in_view=WEDGE)
    cov = np.broadcast_to(sigma**2 * np.eye(2), (4, 2, 2))
    ever = {11: set(), 12: set()}
    gap = []
    for t in T0 + np.arange(0.0, 301.0):
        z, v = _camera(t, rng, sigma)
        gap.append(np.hypot(*(_truth(VESSELS[A], t) - _truth(VESSELS[B], t))))
        labels = assoc.update(
            t, [11, 12, 13, 14], z[:, 0], z[:, 1], cov, v if use_velocity else None
        )
        for k in ever:
            if labels[k] is not None:
                ever[k].add(labels[k])
    assert min(gap) < 30.0  # the crossing is close: within 2 sigma of the camera noise
    res = assoc.result()
    assert res.matches == {11: A, 12: B, 13: C}
    assert ever == {11: {A}, 12: {B}}  # never labelled with the other one
    assert res.history[11] == ((T0 + 4.0, A),) and res.history[12] == ((T0 + 4.0, B),)
    assert res.dark == (14,)
    assert res.unseen == (U,)  # S is behind the camera
    assert S not in res.in_view_time
    assert res.in_view_time[U] == pytest.approx(300.0)
    stats = {(p.track_id, p.mmsi): p for p in res.pairs}
    assert stats[11, A].frames >= 290
    # mean distance of a 2-D Gaussian error (sigma 15 m) is sigma sqrt(pi/2) = 18.8 m
    assert stats[13, C].mean_distance == pytest.approx(15.0 * math.sqrt(math.pi / 2), rel=0.2)
    json.dumps(res.as_dict())


def test_a_time_gap_keeps_labels_and_credits_at_most_max_step_of_view_time(table):
    rng = np.random.default_rng(1234)
    assoc = _assoc(table, in_view=WEDGE, max_step=5.0)
    times = T0 + np.r_[np.arange(0.0, 101.0), np.arange(200.0, 301.0)]
    for t in times:
        z, _ = _camera(t, rng, 10.0)
        labels = assoc.update(t, [11, 12, 13], z[:3, 0], z[:3, 1])
    assert labels == {11: A, 12: B, 13: C}
    res = assoc.result()
    assert [len(h) for h in res.history.values()] == [1, 1, 1]
    # 100 steps of 1 s, the 100 s gap credited as 5 s, 100 steps of 1 s
    assert res.in_view_time[U] == pytest.approx(205.0)
    assert res.frames == times.size


def test_nan_positions_give_no_votes_and_keep_the_current_label(table):
    rng = np.random.default_rng(1234)
    assoc = _assoc(table)
    usable = 0
    previous = None
    for k, t in enumerate(T0 + np.arange(0.0, 60.0)):
        z, _ = _camera(t, rng, 10.0)
        nan_now = k < 20 or k % 2 == 0
        if nan_now:
            z[0] = np.nan
        cov = np.broadcast_to(100.0 * np.eye(2), (4, 2, 2)).copy()
        if nan_now:
            cov[0] = np.nan  # a track without a position may have a NaN covariance too
        labels = assoc.update(t, [11, 12, 13, 14], z[:, 0], z[:, 1], covariance=cov)
        usable += not nan_now
        if nan_now:
            assert labels[11] == previous
        previous = labels[11]
    res = assoc.result()
    assert res.track_frames[11] == usable == 20
    assert res.matches[11] == A
    # labelled at its 5th usable frame: k = 21, 23, 25, 27, 29
    assert res.history[11] == ((T0 + 29.0, A),)


# ------------------------------------------------------------------ label rules
def _one_vessel_table(tmp_path, vessels=None):
    return _write_ais(tmp_path / "one.csv", vessels or {C: VESSELS[C]}, jitter=0.0)


def test_label_after_min_frames_consecutive_assignments(tmp_path):
    assoc = _assoc(_one_vessel_table(tmp_path), min_frames=7)
    n, e = VESSELS[C][0]
    got = [assoc.update(T0 + k, [5], [n], [e])[5] for k in range(10)]
    assert got == [None] * 6 + [C] * 4


def test_a_clear_majority_labels_intermittent_matches_and_a_split_does_not(tmp_path):
    table = _one_vessel_table(tmp_path, {C: VESSELS[C], U: VESSELS[U]})
    pos = {C: VESSELS[C][0], U: _truth(VESSELS[U], T0)}
    # three frames at C, one at U, repeated: C never has 5 in a row, but 5 of 6 votes
    assoc = _assoc(table, min_frames=5)
    got = []
    for k in range(12):
        m = U if k % 4 == 3 else C
        got.append(assoc.update(T0 + k, [5], [pos[m][0]], [pos[m][1]])[5])
    assert got == [None] * 5 + [C] * 7
    # one frame each: no clear majority, no label
    assoc = _assoc(table, min_frames=5)
    for k in range(40):
        m = U if k % 2 else C
        assert assoc.update(T0 + k, [5], [pos[m][0]], [pos[m][1]])[5] is None
    assert assoc.result().dark == (5,)


def test_a_label_changes_only_after_switch_frames_consecutive_frames(table):
    assoc = _assoc(table, min_frames=5)  # switch_frames = 15
    got = []
    for k, t in enumerate(T0 + np.arange(0.0, 60.0)):
        a, c = _truth(VESSELS[A], t), _truth(VESSELS[C], t)
        first, second = (a, c) if k < 30 else (c, a)  # the camera tracker swaps at k = 30
        got.append(assoc.update(t, [21, 22], [first[0], second[0]], [first[1], second[1]]))
    assert [g[21] for g in got] == [None] * 4 + [A] * 40 + [C] * 16
    assert [g[22] for g in got] == [None] * 4 + [C] * 40 + [A] * 16
    assert assoc.result().history[21] == ((T0 + 4.0, A), (T0 + 44.0, C))


def test_velocity_gate_rejects_a_vessel_going_the_other_way(table):
    p = _truth(VESSELS[A], T0)
    reverse = -np.array([VESSELS[A][1]])  # (0, -4) m/s against A's (0, 4)

    def first_label(**kw):
        assoc = _assoc(table, min_frames=1)
        return assoc.update(T0, [1], [p[0]], [p[1]], **kw)[1]

    assert first_label() == A
    assert first_label(velocity=reverse) is None
    # a track whose velocity is known only vaguely (sigma 10 m/s) passes the gate
    cov = np.diag([100.0, 100.0, 100.0, 100.0])[None]
    assert first_label(velocity=reverse, covariance=cov) == A
    assert first_label(velocity=np.array([[np.nan, np.nan]])) == A  # unknown: no gate


def test_an_empty_ais_table_labels_nothing_and_claims_no_dark_vessel(tmp_path):
    path = tmp_path / "empty.csv"
    path.write_text(HEADER + "\n")
    assoc = _assoc(ais.read_ais(path), in_view=WEDGE)
    for k in range(10):
        assert assoc.update(T0 + k, [1], [100.0], [0.0]) == {1: None}
    res = assoc.result()
    assert res.matches == {} and res.dark == () and res.unseen == ()


# ------------------------------------------------------------------ the view wedge
def test_view_wedge_wraps_through_north_and_limits_range():
    heading, fov = math.radians(350.0), math.radians(40.0)
    bearings = np.radians([329.0, 331.0, 350.0, 5.0, 9.0, 11.0, 180.0])
    n, e = 1000.0 * np.cos(bearings), 1000.0 * np.sin(bearings)
    got = in_view_wedge(n, e, heading=heading, hfov=fov, max_range=2000.0)
    assert got.tolist() == [False, True, True, True, True, False, False]
    r = np.array([50.0, 150.0, 1999.0, 2001.0, np.nan])
    got = in_view_wedge(r, 0.0 * r, heading=0.0, hfov=fov, max_range=2000.0, min_range=100.0)
    assert got.tolist() == [False, True, True, False, False]
    moved = ViewWedge(heading=math.pi / 2, hfov=fov, max_range=100.0, north=500.0, east=500.0)
    assert moved([500.0, 500.0], [550.0, 450.0]).tolist() == [True, False]


@given(
    st.floats(0.0, 2 * math.pi),
    st.floats(0.1, 3.0),
    st.lists(st.tuples(st.floats(-5e3, 5e3), st.floats(-5e3, 5e3)), min_size=1, max_size=20),
    st.floats(-math.pi, math.pi),
)
def test_view_wedge_is_invariant_to_rotating_camera_and_targets_together(h, fov, pts, rot):
    p = np.array(pts)
    base = in_view_wedge(p[:, 0], p[:, 1], heading=h, hfov=fov, max_range=4000.0)
    c, s = math.cos(rot), math.sin(rot)
    n = c * p[:, 0] - s * p[:, 1]  # rotate clockwise (towards East) by rot
    e = s * p[:, 0] + c * p[:, 1]
    turned = in_view_wedge(n, e, heading=h + rot, hfov=fov, max_range=4000.0)
    bearing = np.arctan2(p[:, 1], p[:, 0])
    off = np.abs(np.angle(np.exp(1j * (bearing - h))))
    r = np.hypot(p[:, 0], p[:, 1])
    clear = (np.abs(off - fov / 2) > 1e-9) & (np.abs(r - 4000.0) > 1e-6)  # not on an edge
    assert np.array_equal(base[clear], turned[clear])


def test_view_wedge_rejects_bad_limits():
    with pytest.raises(ValueError, match="hfov"):
        in_view_wedge(0.0, 0.0, heading=0.0, hfov=0.0, max_range=1.0)
    with pytest.raises(ValueError, match="max_range"):
        ViewWedge(heading=0.0, hfov=1.0, max_range=-1.0)
    with pytest.raises(ValueError, match="min_range"):
        in_view_wedge(0.0, 0.0, heading=0.0, hfov=1.0, max_range=1.0, min_range=2.0)
    with pytest.raises(ValueError, match="origin"):
        in_view_wedge(0.0, 0.0, heading=0.0, hfov=1.0, max_range=1.0, origin=(np.nan, 0.0))


# ------------------------------------------------------------------ bad input
def test_constructor_rejects_bad_configuration_naming_the_argument(table):
    with pytest.raises(ValueError, match="table"):
        AisAssociator("ais.csv", lat0=LAT0, lon0=LON0)  # type: ignore[arg-type]
    for kw, name in [
        ({"lat0": 95.0}, "lat0"),
        ({"min_frames": 0}, "min_frames"),
        ({"switch_frames": 2.5}, "switch_frames"),
        ({"majority": 0.4}, "majority"),
        ({"gate_probability": 1.0}, "gate_probability"),
        ({"sigma_ais": -1.0}, "sigma_ais"),
        ({"in_view": "wedge"}, "in_view"),
    ]:
        args = {"lat0": LAT0, "lon0": LON0, **kw}
        with pytest.raises(ValueError, match=name):
            AisAssociator(table, **args)


def test_update_rejects_bad_data_naming_the_argument(table):
    assoc = _assoc(table)
    ok = {"track_ids": [1, 2], "north": [0.0, 1.0], "east": [0.0, 1.0]}
    bad = [
        ({"north": [0.0]}, "north"),
        ({"track_ids": [1, 1]}, "track_ids"),
        ({"track_ids": [1.5, 2.0]}, "track_ids"),
        ({"covariance": np.ones((2, 3, 3))}, "covariance"),
        ({"covariance": np.full((2, 2, 2), np.nan)}, "covariance"),
        ({"covariance": np.array([[[1.0, 0.0], [0.0, -1.0]]] * 2)}, "covariance"),
        ({"velocity": np.zeros((2, 3))}, "velocity"),
        ({"in_view": lambda n, e: np.ones(2, bool)}, "in_view"),
    ]
    for change, name in bad:
        with pytest.raises(ValueError, match=name):
            assoc.update(T0, **{**ok, **change})
    assoc.update(T0 + 10.0, **ok)
    with pytest.raises(ValueError, match="time"):
        assoc.update(T0 + 5.0, **ok)
    with pytest.raises(ValueError, match="time"):
        assoc.update(float("nan"), **ok)


# ------------------------------------------------------------------ real AIS data
def test_solent_vessels_seen_with_noise_are_each_labelled_with_their_own_mmsi():
    if not SOLENT.exists():
        pytest.skip(f"Solent AIS file not found at {SOLENT} (../shared/data/ais, see README)")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ais.AisWarning)
        table = ais.read_ais(SOLENT)
    lat0, lon0 = 50.78, -1.15
    times = table.time.min() + 300.0 + np.arange(0.0, 120.0)
    truth = {}
    for mmsi, track in ais.tracks(table).items():
        sample = ais.interpolate_track(track, times, origin=(lat0, lon0))
        if sample.valid.all():
            truth[mmsi] = sample
    mmsi = sorted(truth)
    assert len(mmsi) >= 50
    pos = np.stack([np.stack([truth[m].north, truth[m].east], -1) for m in mmsi])  # (V, T, 2)
    vel = np.stack([truth[m].velocity for m in mmsi])
    rng = np.random.default_rng(1234)
    sigma = 5.0  # several moored vessels lie 8-12 m apart: noise must stay below that
    cov = np.broadcast_to(sigma**2 * np.eye(2), (len(mmsi), 2, 2))
    assoc = AisAssociator(table, lat0=lat0, lon0=lon0)
    for k, t in enumerate(times):
        z = pos[:, k] + rng.normal(0.0, sigma, (len(mmsi), 2))
        v = vel[:, k] + rng.normal(0.0, 0.3, (len(mmsi), 2))
        assoc.update(t, np.arange(len(mmsi)), z[:, 0], z[:, 1], cov, v)
    res = assoc.result()
    assert res.matches == dict(enumerate(mmsi))
    assert res.dark == ()
    assert all(len(h) == 1 for h in res.history.values())
