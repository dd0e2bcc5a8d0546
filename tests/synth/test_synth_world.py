"""Ship models and trajectories of seawatch.synth.world against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from seawatch.synth.world import (
    KINDS,
    Prism,
    Ship,
    Trajectory,
    crossing,
    make_ship,
    meeting,
    overtaking,
    ships_from_tracks,
    straight,
    through,
    turning,
)


def test_straight_track_matches_constant_velocity_closed_form() -> None:
    course, v = math.radians(30.0), 6.0
    tr = straight(100.0, -50.0, course, v, 20.0, start=2.0)
    t = np.array([2.0, 5.5, 13.25, 22.0])
    pos = tr.position(t)
    np.testing.assert_allclose(pos[:, 0], 100.0 + v * (t - 2.0) * math.cos(course), atol=1e-9)
    np.testing.assert_allclose(pos[:, 1], -50.0 + v * (t - 2.0) * math.sin(course), atol=1e-9)
    np.testing.assert_allclose(tr.heading_at(t), course, atol=1e-12)
    np.testing.assert_allclose(np.hypot(*tr.velocity(t).T), v, rtol=1e-12)


def test_state_fast_path_agrees_with_vectorised_methods() -> None:
    rng = np.random.default_rng(1234)
    t = np.sort(rng.uniform(0.0, 30.0, 12))
    t[0], t[-1] = 0.0, 30.0
    tr = Trajectory(t, rng.normal(0, 100, 12), rng.normal(0, 100, 12), rng.uniform(0, 6.2, 12))
    for ti in [0.0, *rng.uniform(0.0, 30.0, 20), 30.0, *t[1:-1]]:
        n, e, h, s = tr.state(float(ti))
        np.testing.assert_allclose([n, e], tr.position(ti), atol=1e-9)
        assert math.isclose(h, float(tr.heading_at(ti)), abs_tol=1e-12)
        assert math.isclose(s, float(np.hypot(*tr.velocity(ti))), rel_tol=1e-12)


def test_ship_absent_outside_its_time_span() -> None:
    tr = straight(0.0, 0.0, 0.0, 5.0, 10.0, start=5.0)
    assert tr.state(4.99) is None and tr.state(15.01) is None
    assert np.all(np.isnan(tr.position([0.0, 20.0])))
    assert np.all(np.isnan(tr.heading_at([0.0, 20.0])))


def test_heading_interpolates_along_the_shorter_arc_across_north() -> None:
    tr = Trajectory([0.0, 1.0], [0.0, 0.0], [0.0, 0.0], [math.radians(350.0), math.radians(10.0)])
    assert math.isclose(float(tr.heading_at(0.5)), 0.0, abs_tol=1e-12) or math.isclose(
        float(tr.heading_at(0.5)), 2 * math.pi, abs_tol=1e-12
    )
    assert math.isclose(math.degrees(float(tr.heading_at(0.25))), 355.0, abs_tol=1e-9)


def test_turning_track_keeps_speed_and_follows_a_circle_of_radius_v_over_omega() -> None:
    v, w = 8.0, math.radians(3.0)
    tr = turning(0.0, 0.0, 0.0, v, 40.0, turn_rate=w, turn_start=10.0, turn_end=30.0, dt=0.05)
    # constant speed along the path
    steps = np.hypot(np.diff(tr.north), np.diff(tr.east)) / np.diff(tr.time)
    np.testing.assert_allclose(steps, v, rtol=1e-5)
    # heading turns by w * 20 s
    assert math.isclose(float(tr.heading_at(40.0)), w * 20.0, rel_tol=1e-12)
    # during the turn the ship stays on the circle centred to starboard of the turn start
    p0 = tr.position(10.0)
    centre = p0 + (v / w) * np.array([-math.sin(0.0), math.cos(0.0)])
    t = np.linspace(10.0, 30.0, 41)
    r = np.linalg.norm(tr.position(t) - centre, axis=1)
    np.testing.assert_allclose(r, v / w, rtol=1e-9)


def test_meeting_ships_are_abeam_at_the_meeting_time_on_reciprocal_courses() -> None:
    course = math.radians(70.0)
    a, b = meeting(500.0, 200.0, course, (5.0, 7.0), 120.0, 6.0, start=0.0, end=12.0)
    pa, pb = a.position(6.0), b.position(6.0)
    np.testing.assert_allclose((pa + pb) / 2, [500.0, 200.0], atol=1e-9)
    d = pb - pa
    assert math.isclose(float(np.linalg.norm(d)), 120.0, rel_tol=1e-12)
    assert abs(float(d @ [math.cos(course), math.sin(course)])) < 1e-9  # abeam
    diff = (float(b.heading_at(3.0)) - float(a.heading_at(3.0))) % (2 * math.pi)
    assert math.isclose(diff, math.pi, abs_tol=1e-12)


def test_overtaking_ship_is_faster_and_abeam_at_the_given_time() -> None:
    slow, fast = overtaking(0.0, 0.0, 0.0, (3.0, 9.0), 80.0, 5.0, start=0.0, end=10.0)
    assert fast.state(5.0)[3] > slow.state(5.0)[3]
    d = fast.position(5.0) - slow.position(5.0)
    assert abs(d[0]) < 1e-9 and math.isclose(abs(d[1]), 80.0)
    assert fast.position(0.0)[0] < slow.position(0.0)[0]  # behind at the start
    assert fast.position(10.0)[0] > slow.position(10.0)[0]  # ahead at the end
    with pytest.raises(ValueError, match="speeds"):
        overtaking(0.0, 0.0, 0.0, (9.0, 3.0), 80.0, 5.0, end=10.0)


def test_crossing_ships_pass_their_points_at_their_times() -> None:
    trs = crossing(
        1000.0, 0.0, [0.5, 2.0, 4.0], [5.0, 6.0, 7.0], [3.0, 5.0, 7.0], offsets=[0, 50, -50], end=10
    )
    for tr, c, tp, off in zip(trs, [0.5, 2.0, 4.0], [3.0, 5.0, 7.0], [0, 50, -50], strict=True):
        expect = np.array([1000.0 - math.sin(c) * off, math.cos(c) * off])
        np.testing.assert_allclose(tr.position(tp), expect, atol=1e-9)


def test_through_passes_the_point_at_the_time() -> None:
    tr = through(10.0, 20.0, 1.0, 4.0, 7.5, start=0.0, end=10.0)
    np.testing.assert_allclose(tr.position(7.5), [10.0, 20.0], atol=1e-9)


def test_prism_faces_have_outward_normals() -> None:
    ship = make_ship(3, straight(0, 0, 0, 1, 1), 120.0, kind="cargo")
    for part in ship.parts:
        v = part.vertices
        assert len(part.faces) == part.outline.shape[0] + 2
        for idx, n in part.faces:
            p0 = v[idx[0]]
            # every vertex lies on or behind the face's plane
            assert np.all((v - p0) @ n <= 1e-9)
            # the face's vertices lie in its plane
            np.testing.assert_allclose((v[list(idx)] - p0) @ n, 0.0, atol=1e-9)


@pytest.mark.parametrize("kind", KINDS)
def test_make_ship_has_the_requested_length_and_beam(kind: str) -> None:
    ship = make_ship(1, straight(0, 0, 0, 1, 1), 50.0, kind=kind)
    hull = ship.hull.vertices
    assert math.isclose(np.ptp(hull[:, 0]), 50.0)
    assert math.isclose(np.ptp(hull[:, 1]), ship.beam, rel_tol=1e-12)
    assert np.isclose(hull[:, 2].min(), 0.0) and np.isclose(hull[:, 2].max(), ship.height)
    assert ship.top > ship.height
    assert ship.kind == kind


def test_ships_from_tracks_fills_unknown_heading_with_course_over_ground() -> None:
    t = np.array([0.0, 10.0, 10.0, 20.0, 30.0])  # a repeated time
    north = np.array([0.0, 0.0, 5.0, 0.0, 0.0])
    east = np.array([0.0, 50.0, 99.0, 100.0, 150.0])
    heading = np.array([np.nan, np.nan, np.nan, math.radians(80.0), np.nan])
    ships = ships_from_tracks(
        {235000001: {"time": t, "north": north, "east": east, "heading": heading, "length": 30.0}}
    )
    (ship,) = ships
    assert ship.object_id == 235000001 and ship.length == 30.0
    tr = ship.trajectory
    assert tr.time.size == 4  # repeated time dropped (first kept)
    np.testing.assert_allclose(tr.heading[[0, 1, 3]], math.pi / 2, atol=1e-12)  # due east
    assert math.isclose(tr.heading[2], math.radians(80.0))


def test_ships_from_tracks_skips_single_sample_tracks_with_a_warning() -> None:
    with pytest.warns(UserWarning, match="fewer than two"):
        ships = ships_from_tracks(
            [
                {"object_id": 1, "time": [0.0], "north": [0.0], "east": [0.0]},
                {"object_id": 2, "time": [0.0, 1.0], "north": [0.0, 1.0], "east": [0.0, 0.0]},
            ]
        )
    assert [s.object_id for s in ships] == [2]
    assert ships[0].length == 25.0  # the default


def test_bad_inputs_raise_value_errors_naming_the_argument() -> None:
    with pytest.raises(ValueError, match="time"):
        Trajectory([0.0, 0.0], [0, 1], [0, 1], [0, 0])
    with pytest.raises(ValueError, match="time"):
        Trajectory([0.0], [0], [0], [0])
    with pytest.raises(ValueError, match="north"):
        Trajectory([0.0, 1.0], [0, np.nan], [0, 1], [0, 0])
    with pytest.raises(ValueError, match="length"):
        make_ship(1, straight(0, 0, 0, 1, 1), -3.0)
    with pytest.raises(ValueError, match="kind"):
        make_ship(1, straight(0, 0, 0, 1, 1), 30.0, kind="submarine")
    with pytest.raises(ValueError, match="speed"):
        straight(0, 0, 0, -1.0, 10.0)
    with pytest.raises(ValueError, match="outline"):
        Prism(np.zeros((2, 2)), 0.0, 1.0)
    with pytest.raises(ValueError, match="lo, hi"):
        Prism(np.eye(3)[:, :2], 2.0, 1.0)
    with pytest.raises(ValueError, match="trajectory"):
        Ship(1, 10.0, 3.0, 1.0, (), trajectory="nope")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="missing array 'east'"):
        ships_from_tracks({1: {"time": [0, 1], "north": [0, 1]}})
