"""Gate track-before-detect (ALGORITHMS.md §8.1, seed 004): hand-made mark sequences with
obvious answers, a plain brute-force reference implementation of §8.1 on small random
cases (per-frame outputs compared exactly), and bad input."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from seawatch.tracking import GateTBD, group_marks

FRAME = (1080, 1920)


def line(p0, v, frames):
    """Marks of a target on a straight line, one (1, 2) array per frame."""
    return [np.array([[p0[0] + v[0] * k, p0[1] + v[1] * k]], dtype=float) for k in range(frames)]


def push_all(tbd, frames):
    outs, stats = [], []
    for z in frames:
        outs.append(tbd.push(z))
        stats.append(tbd.last_stats)
    return outs, stats


# --------------------------------------------------------------------------------------
# hand-made sequences
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("n", [3, 4, 5])
def test_straight_target_is_confirmed_exactly_at_frame_N_minus_1_with_true_velocity(n):
    tbd = GateTBD(FRAME, n_frames=n)
    outs, stats = push_all(tbd, line((200, 300), (3, -7), 8))
    for k in range(n - 1):
        assert outs[k].shape == (0, 5)
    for k in range(n - 1, 8):
        assert outs[k].shape == (1, 5)
        tid, row, col, vr, vc = outs[k][0]
        assert tid == 1  # stable id while the confirmed track continues
        assert (row, col) == (200 + 3 * k, 300 - 7 * k)
        assert vr == pytest.approx(3.0, abs=1e-12) and vc == pytest.approx(-7.0, abs=1e-12)
    assert stats[n - 1].new_tracks == 1 and stats[n - 1].new_marks == 1


def test_one_miss_deletes_the_track_and_a_new_id_follows_N_minus_1_frames_later():
    n = 4
    frames = line((100, 100), (5, 5), 12)
    frames[6] = np.zeros((0, 2))  # the target is missed once
    outs, _ = push_all(GateTBD(FRAME, n_frames=n), frames)
    assert [o.shape[0] for o in outs] == [0, 0, 0, 1, 1, 1, 0, 0, 0, 0, 1, 1]
    assert outs[5][0, 0] == 1 and outs[10][0, 0] == 2  # re-confirmed at 7 + N − 1 = 10


def test_two_misses_allowed_keep_the_id_when_max_misses_is_2():
    frames = line((100, 100), (5, 5), 12)
    frames[6] = np.zeros((0, 2))
    outs, _ = push_all(GateTBD(FRAME, n_frames=4, max_misses=2), frames)
    assert [o.shape[0] for o in outs] == [0, 0, 0, 1, 1, 1, 0, 1, 1, 1, 1, 1]
    assert {o[0, 0] for o in outs if o.size} == {1.0}
    # the line fit spans the gap: the true velocity still comes out
    assert outs[8][0, 3:] == pytest.approx([5.0, 5.0], abs=1e-12)


@pytest.mark.parametrize(
    ("offset", "accepted"),
    [((8, 0), True), ((9, 0), False), ((6, 6), True), ((7, 6), False), ((0, -8), True)],
)
def test_m3_linearity_accepts_exactly_offsets_within_sqrt12_eps(offset, accepted):
    # N = 3: the third mark must lie within sqrt(12)·eps = 8.83 px of p = 2 z1 − z0,
    # although every offset here is inside the 23×23 small gate
    eps = 2.55
    assert (math.hypot(*offset) <= math.sqrt(12) * eps) == accepted
    z = [[[500, 500]], [[500, 510]], [[500 + offset[0], 520 + offset[1]]]]
    outs, stats = push_all(GateTBD(FRAME, n_frames=3, linearity_threshold=eps), z)
    assert (outs[2].shape[0] == 1) == accepted
    assert stats[2].new_tracks == int(accepted)


def test_gates_are_inclusive_chebyshev_squares():
    # big gate 161: a displacement of exactly 80 px on both axes starts a pair, 81 does not
    for d, pairs in ((80, 1), (81, 0)):
        tbd = GateTBD(FRAME)
        tbd.push([[300, 300]])
        tbd.push([[300 + d, 300 - d]])
        assert tbd.last_stats.pairs == pairs
    # small gate 23: a mark exactly 11 px from the prediction is a candidate, 12 is not
    for d, confirmed in ((11, 1), (12, 0)):
        tbd = GateTBD(FRAME, n_frames=3, linearity_threshold=100.0)
        push_all(tbd, [[[300, 300]], [[300, 320]], [[300 + d, 340 - d]]])
        assert tbd.last_stats.confirmed == confirmed


def test_two_marks_in_a_small_gate_branch_the_track_with_inherited_history():
    # N = 4: after two frames, two marks fit the line; each branch keeps the first two
    # marks and is confirmed with its own continuation at frame 3
    z = [
        [[400, 400]],
        [[400, 410]],
        [[403, 420], [397, 420]],
        [[406, 430], [394, 430]],  # each 12 px outside the other branch's small gate
    ]
    outs, stats = push_all(GateTBD(FRAME, n_frames=4), z)
    assert stats[2].tentative >= 2  # two 3-mark branches (plus new pairs)
    assert stats[3].new_tracks == 2 and stats[3].new_marks == 2
    got = sorted(tuple(r[1:]) for r in outs[3])
    # LS slopes over the inherited (0, 0), (0, 10) and the branch's own two marks
    t = np.arange(4.0)
    up = np.polyfit(t, [400, 400, 403, 406], 1)[0]
    down = np.polyfit(t, [400, 400, 397, 394], 1)[0]
    assert got == [
        pytest.approx((394, 430, down, 10.0)),
        pytest.approx((406, 430, up, 10.0)),
    ]


def test_seed_exclusion_and_merging_give_one_output_row_per_target():
    # a confirmed target's marks are not seeds (default): one duplicate confirmation right
    # after confirmation (the pair started before it), then none; the literal rule
    # confirms a duplicate every frame. Duplicates are merged: always one row, id 1.
    frames = line((500, 500), (4, 9), 10)
    _, strict = push_all(GateTBD(FRAME, n_frames=3), frames)
    outs, literal = push_all(GateTBD(FRAME, n_frames=3, seed_exclusion=False), frames)
    assert [s.new_tracks for s in strict] == [0, 0, 1, 1, 0, 0, 0, 0, 0, 0]
    assert [s.new_tracks for s in literal] == [0, 0, 1, 1, 1, 1, 1, 1, 1, 1]
    assert all(o.shape[0] == 1 and o[0, 0] == 1 for o in outs[2:])


def test_stationary_target_with_one_pixel_jitter_is_tracked():
    rng = np.random.default_rng(1234)
    frames = [np.array([[700, 900]]) + rng.integers(-1, 2, size=(1, 2)) for _ in range(20)]
    outs, _ = push_all(GateTBD(FRAME, n_frames=4), frames)
    assert all(o.shape[0] == 1 and o[0, 0] == 1 for o in outs[3:])


def test_two_crossing_targets_sharing_a_mark_both_continue():
    a = line((100, 100), (10, 10), 11)
    b = line((200, 100), (-10, 10), 11)
    frames = [np.concatenate((p, q)) for p, q in zip(a, b, strict=True)]
    frames[5] = frames[5][:1]  # both at (150, 150): one mark
    outs, _ = push_all(GateTBD(FRAME, n_frames=4), frames)
    assert outs[5].shape[0] == 2 and set(outs[5][:, 0]) == {1, 2}
    for k in (6, 10):
        by_id = {int(r[0]): tuple(r[1:3]) for r in outs[k]}
        assert by_id == {1: tuple(a[k][0]), 2: tuple(b[k][0])} or by_id == {
            2: tuple(a[k][0]),
            1: tuple(b[k][0]),
        }
        assert by_id[int(outs[5][0, 0])] != by_id[int(outs[5][1, 0])]


def test_run_matches_push_and_gaps_in_frame_numbers_are_empty_frames():
    frames = line((100, 100), (5, 5), 8)
    res = GateTBD(FRAME, n_frames=3).run(frames, frame_numbers=[0, 1, 2, 3, 10, 11, 12, 13])
    assert res.frames.tolist() == [0, 1, 2, 3, 10, 11, 12, 13]
    assert res.detections[:, 0].tolist() == [2, 3, 12, 13]
    assert res.detections[:, 1].tolist() == [1, 1, 2, 2]  # the gap deleted track 1
    outs, _ = push_all(GateTBD(FRAME, n_frames=3), frames[:4])
    np.testing.assert_array_equal(res.detections[:2, 1:], np.concatenate(outs))


def test_docstring_example():
    tbd = GateTBD((1080, 1920), n_frames=3)
    for k in range(3):
        out = tbd.push([[100 + 5 * k, 200 + 7 * k]])
    assert out.tolist() == [[1.0, 110.0, 214.0, 5.0, 7.0]]


# --------------------------------------------------------------------------------------
# §8.2's alternative: orthogonal linearity test, seed exclusion of every extending mark
# --------------------------------------------------------------------------------------


def svd_residual(points):
    """sqrt(Σ d_⊥² / (m − 2)) of the total-least-squares line, from numpy's SVD."""
    xy = np.asarray(points, float)
    sv = np.linalg.svd(xy - xy.mean(axis=0), compute_uv=False)
    return math.sqrt(sv[-1] ** 2 / (len(xy) - 2))


def test_orthogonal_kernel_equals_the_smallest_singular_value_of_the_centred_points():
    from seawatch.tracking.gate_tbd import _branch_orth

    rng = np.random.default_rng(1234)
    for trial in range(300):
        m = int(rng.integers(3, 6))
        if trial % 3 == 0:  # nearly collinear, far from the origin, fast: precision check
            base, v = rng.uniform(0, 1900, 2), rng.uniform(-80, 80, 2)
            pts = base + np.arange(m)[:, None] * v + rng.integers(-1, 2, (m, 2))
        else:
            pts = rng.integers(0, 1080, (m, 2)).astype(float)
        hist = np.zeros((1, 5, 2))
        hist[0, : m - 1] = pts[:-1]
        htime = np.arange(5)[None, :]
        got, got_m = _branch_orth(hist, htime, 0, m - 1, 5, pts[-1, 0], pts[-1, 1])
        xy = pts - pts.mean(axis=0)
        want = np.linalg.svd(xy, compute_uv=False)[-1] ** 2
        assert got_m == m
        assert got == pytest.approx(want, rel=1e-9, abs=1e-7)


def test_orthogonal_test_accepts_exactly_the_tracks_within_eps_of_the_svd_line():
    # N = 3: confirmation at frame 2 iff the third mark is in the small gate and the
    # three marks' TLS residual is <= 1.96 px (ties skipped), whatever the spacing
    rng = np.random.default_rng(1234)
    seen = {True: 0, False: 0}
    for _ in range(150):
        z0 = rng.integers(200, 800, 2)
        z1 = z0 + rng.integers(-80, 81, 2)
        z2 = 2 * z1 - z0 + rng.integers(-11, 12, 2)
        want = svd_residual([z0, z1, z2])
        if abs(want - 1.96) < 1e-6:
            continue
        tbd = GateTBD(FRAME, n_frames=3, linearity="orthogonal")
        outs, _ = push_all(tbd, [[z0], [z1], [z2]])
        assert (outs[2].shape[0] == 1) == (want <= 1.96)
        seen[want <= 1.96] += 1
    assert min(seen.values()) > 20  # both outcomes exercised


def test_orthogonal_test_ignores_spacing_along_the_line_but_not_lateral_offsets():
    # (0,0), (0,10), (0,30): collinear, 10 px past the CV prediction (inside the 23-px gate)
    along = [[[500, 500]], [[500, 510]], [[500, 530]]]
    # (0,0), (0,10), (5,20): 5 px lateral offset, TLS residual > 1.96 px
    lateral = [[[500, 500]], [[500, 510]], [[505, 520]]]
    assert svd_residual([[500, 500], [500, 510], [505, 520]]) > 1.96
    for frames, pooled, orth in ((along, False, True), (lateral, True, False)):
        a, _ = push_all(GateTBD(FRAME, n_frames=3), frames)  # default: pooled LS, 2.55 px
        b, _ = push_all(GateTBD(FRAME, n_frames=3, linearity="orthogonal"), frames)
        assert (a[2].shape[0] == 1, b[2].shape[0] == 1) == (pooled, orth)


def test_extended_seed_exclusion_removes_marks_that_extended_a_tentative_track():
    # N = 5: the frame-2 mark extends the pair (0, 1) to a 3-mark tentative track.
    # "confirmed" still seeds with it (one new pair at frame 3); "extended" does not.
    frames = line((300, 300), (4, 6), 4)
    pairs = {}
    for rule in ("confirmed", "extended", "none", True, False):
        _, stats = push_all(GateTBD(FRAME, n_frames=5, seed_exclusion=rule), frames)
        pairs[rule] = [s.pairs for s in stats]
    assert pairs["confirmed"] == pairs[True] == pairs["none"] == pairs[False] == [0, 1, 1, 1]
    assert pairs["extended"] == [0, 1, 1, 0]


def test_default_is_the_spec_rule_with_unchanged_threshold_and_attributes():
    tbd = GateTBD(FRAME)
    assert (tbd.linearity, tbd.linearity_threshold) == ("pooled-ls", 2.55)
    assert (tbd.seed_rule, tbd.seed_exclusion) == ("confirmed", True)
    assert GateTBD(FRAME, linearity="orthogonal").linearity_threshold == 1.96
    literal = GateTBD(FRAME, seed_exclusion=False)
    assert (literal.seed_rule, literal.seed_exclusion) == ("none", False)
    # explicit spec settings give identical per-frame outputs on random clutter + targets
    rng = np.random.default_rng(1234)
    frames = random_case(rng, 15, (200, 300), n_clutter=60, n_targets=4)
    a = GateTBD((200, 300), n_frames=3).run(frames)
    b = GateTBD(
        (200, 300),
        n_frames=3,
        linearity="pooled-ls",
        linearity_threshold=2.55,
        seed_exclusion="confirmed",
    ).run(frames)
    np.testing.assert_array_equal(a.detections, b.detections)
    np.testing.assert_array_equal(a.new_tracks, b.new_tracks)
    assert a.new_tracks.sum() > 0


# --------------------------------------------------------------------------------------
# brute-force reference implementation of §8.1 (with the module's documented choices)
# --------------------------------------------------------------------------------------


def ls_fit(pts):
    """SSR of the LS line through (t, r, c) points and the slopes (v_r, v_c), by lstsq."""
    t = np.array([p[0] for p in pts], float)
    a = np.column_stack((np.ones_like(t), t))
    ssr, slopes = 0.0, []
    for j in (1, 2):
        y = np.array([p[j] for p in pts], float)
        coef = np.linalg.lstsq(a, y, rcond=None)[0]
        ssr += float(np.sum((y - a @ coef) ** 2))
        slopes.append(coef[1])
    return ssr, slopes


def orth_fit(pts):
    """Σ d_⊥² of the total-least-squares line through the (r, c) of (t, r, c) points: the
    smallest squared singular value of the centred points (numpy SVD)."""
    xy = np.array([p[1:] for p in pts], float)
    return float(np.linalg.svd(xy - xy.mean(axis=0), compute_uv=False)[-1] ** 2)


def reference(
    frames,
    frame_size,
    large_gate,
    small_gate,
    n,
    eps,
    seed_exclusion=True,
    linearity="pooled-ls",
    seed_rule=None,
):
    """Literal per-track loops over every mark: per frame, the detections as {id: row}
    and (new_tracks, new_marks). ``linearity="orthogonal"``: the SVD line of
    :func:`orth_fit` with ``sqrt(Σ d_⊥² / (m − 2)) ≤ eps`` accepts (a confirmed track
    still keeps the branch with the smallest LS SSR); ``seed_rule="extended"``: every
    mark that extended any track is excluded from seeding."""
    if seed_rule is None:
        seed_rule = "confirmed" if seed_exclusion else "none"
    a_b, a_s = (large_gate - 1) // 2, (small_gate - 1) // 2
    tracks = []  # dicts: pts [(t, r, c)], id
    prev, prev_used, next_id = [], set(), 1
    out = []
    for k, z in enumerate(frames):
        z = [tuple(map(float, m)) for m in z]
        used, ext = set(), []
        for tr in tracks:
            pts = tr["pts"]
            pr = 2 * pts[-1][1] - pts[-2][1]
            pc = 2 * pts[-1][2] - pts[-2][2]
            acc = []
            for i, (r, c) in enumerate(z):
                if abs(r - pr) <= a_s and abs(c - pc) <= a_s:
                    window = ([*pts, (k, r, c)])[-n:]
                    ssr = ls_fit(window)[0]  # branches rank by the LS line in time
                    if linearity == "orthogonal":
                        res, dof = orth_fit(window), len(window) - 2
                    else:
                        res, dof = ssr, 2 * len(window) - 4
                    if math.sqrt(res / dof) <= eps + 1e-9:
                        acc.append((ssr, i))
            if len(pts) + 1 >= n or seed_rule == "extended":
                used |= {i for _, i in acc}
            if len(pts) >= n and acc:  # best fit; SSR equal to 6 decimals: lower index
                acc = [min(acc, key=lambda a: (round(a[0], 6), a[1]))]
            for _, i in acc:
                ext.append({"pts": [*pts, (k, *z[i])], "id": tr["id"], "mark": i})
        fresh = [e for e in ext if len(e["pts"]) == n]
        stats = (len(fresh), len({e["mark"] for e in fresh}))
        conf = [(e["id"] if e["id"] else next_id + j, j) for j, e in enumerate(ext)]
        seen, dead = set(), set()
        for _, j in sorted(c for c in conf if len(ext[c[1]]["pts"]) >= n):
            key = tuple(ext[j]["pts"][-n:])
            if key in seen:
                dead.add(j)
            seen.add(key)
        ext = [e for j, e in enumerate(ext) if j not in dead]
        for e in ext:
            if len(e["pts"]) == n and e["id"] == 0:
                e["id"], next_id = next_id, next_id + 1
        dets = {}
        for e in ext:
            if len(e["pts"]) >= n:
                _, (vr, vc) = ls_fit(e["pts"][-n:])
                dets[e["id"]] = (*e["pts"][-1][1:], vr, vc)
        out.append((dets, stats))
        pairs = []
        for s_i, s in enumerate(prev):
            if seed_rule != "none" and s_i in prev_used:
                continue
            for m_i, m in enumerate(z):
                if max(abs(m[0] - s[0]), abs(m[1] - s[1])) <= a_b:
                    pairs.append({"pts": [(k - 1, *s), (k, *m)], "id": 0, "mark": m_i})
        tracks = ext + pairs
        prev, prev_used = z, used
    return out


def random_case(rng, frames, size, n_clutter, n_targets):
    rows, cols = size
    targets = [
        (rng.uniform(10, rows - 10), rng.uniform(10, cols - 10), *rng.uniform(-3, 3, 2))
        for _ in range(n_targets)
    ]
    out = []
    for k in range(frames):
        pts = [
            (np.clip(round(r + vr * k + rng.normal(0, 0.5)), 0, rows - 1),
             np.clip(round(c + vc * k + rng.normal(0, 0.5)), 0, cols - 1))
            for r, c, vr, vc in targets
        ]  # fmt: skip
        clutter = np.column_stack(
            (rng.integers(0, rows, n_clutter), rng.integers(0, cols, n_clutter))
        )
        z = np.concatenate((np.array(pts, float).reshape(-1, 2), clutter))
        out.append(z[rng.permutation(len(z))])
    return out


@pytest.mark.parametrize(
    ("n", "large", "small", "eps", "seed_exclusion", "linearity"),
    [
        (3, 21, 7, 1.0, True, "pooled-ls"),
        (4, 21, 9, 1.5, True, "pooled-ls"),
        (3, 15, 7, 0.8, False, "pooled-ls"),
        (5, 25, 9, 2.55, True, "pooled-ls"),
        # ALGORITHMS.md §8.2's alternative: orthogonal line, extended seed exclusion
        (3, 21, 7, 0.7, "extended", "orthogonal"),
        (4, 21, 9, 1.0, "extended", "orthogonal"),
        (5, 25, 9, 1.96, "extended", "orthogonal"),
        (4, 21, 9, 1.0, "confirmed", "orthogonal"),
        (4, 21, 9, 1.5, "extended", "pooled-ls"),
    ],
)
def test_per_frame_outputs_equal_a_brute_force_reference(
    n, large, small, eps, seed_exclusion, linearity
):
    rng = np.random.default_rng(1234)
    size = (40, 60)
    rule = seed_exclusion if isinstance(seed_exclusion, str) else None
    for _ in range(3):
        frames = random_case(rng, 12, size, n_clutter=12, n_targets=3)
        ref = reference(
            frames, size, large, small, n, eps, seed_exclusion is not False, linearity, rule
        )
        tbd = GateTBD(
            size,
            large,
            small,
            n,
            linearity_threshold=eps,
            seed_exclusion=seed_exclusion,
            linearity=linearity,
        )
        id_map: dict[int, set[int]] = {}
        confirmations = 0
        for z, (want, stats) in zip(frames, ref, strict=True):
            got = tbd.push(z)
            st = tbd.last_stats
            assert (st.new_tracks, st.new_marks) == stats
            confirmations += stats[0]
            assert got.shape[0] == len(want)
            assert len(set(got[:, 0])) == got.shape[0]  # ids unique within a frame
            rows_want = sorted(tuple(np.round(v, 6)) for v in want.values())
            rows_got = sorted(tuple(np.round(r[1:], 6)) for r in got)
            for a, b in zip(rows_got, rows_want, strict=True):
                assert a == pytest.approx(b, abs=1e-9)
            # ids: a consistent relabelling over the whole sequence (a row may match more
            # than one reference track when two windows give the same position and slope)
            for r in got:
                match = {i for i, v in want.items() if np.allclose(v, r[1:], atol=1e-9)}
                id_map[int(r[0])] = id_map.get(int(r[0]), match) & match
                assert id_map[int(r[0])], "a track id changed its reference track"
        assert confirmations > 0  # the case exercised confirmation


# --------------------------------------------------------------------------------------
# bad and extreme input
# --------------------------------------------------------------------------------------


def test_empty_frames_are_fine_and_delete_tracks():
    tbd = GateTBD(FRAME, n_frames=3)
    assert tbd.push([]).shape == (0, 5)
    assert tbd.push(np.zeros((0, 2))).shape == (0, 5)
    push_all(tbd, line((10, 10), (1, 1), 4))
    assert tbd.n_tracks > 0
    tbd.push([])
    assert tbd.n_tracks == 0 and tbd.last_stats.marks == 0


def test_marks_outside_the_frame_are_dropped_with_a_warning_and_counted():
    tbd = GateTBD((100, 200), n_frames=3)
    frames = [[[-1, 5], [10, 10], [100, 5]], [[10, 12], [5, 200]], [[10, 14], [50, 50]]]
    with pytest.warns(RuntimeWarning, match="dropped 2 mark"):
        tbd.push(frames[0])
    assert tbd.last_stats.dropped == 2 and tbd.last_stats.marks == 1
    with pytest.warns(RuntimeWarning, match="dropped 1 mark"):
        tbd.push(frames[1])
    out = tbd.push(frames[2])
    assert out[:, 1:3].tolist() == [[10, 14]]
    assert tbd.last_stats.detection_marks.tolist() == [0]  # index into the pushed array


def test_frame_numbers_must_increase():
    frames = line((10, 10), (1, 1), 3)
    with pytest.raises(ValueError, match="frame 1 follows frame 2"):
        GateTBD(FRAME).run(frames, frame_numbers=[0, 2, 1])
    with pytest.raises(ValueError, match="frame 4 follows frame 4"):
        GateTBD(FRAME).run(frames, frame_numbers=[3, 4, 4])
    tbd = GateTBD(FRAME)
    tbd.push(frames[0], frame=5)
    with pytest.raises(ValueError, match="got frame 5 after frame 5"):
        tbd.push(frames[1], frame=5)
    with pytest.raises(ValueError, match="frame 1 at row 3 follows frame 2"):
        group_marks([[0, 1, 1], [2, 1, 1], [2, 3, 3], [1, 4, 4]])


def test_group_marks_splits_a_mark_table_by_frame():
    numbers, frames = group_marks([[0, 1, 2, 7], [0, 3, 4, 7], [2, 5, 6, 99.0]])
    assert numbers == [0, 2]
    assert [f.tolist() for f in frames] == [[[1, 2], [3, 4]], [[5, 6]]]
    with pytest.raises(ValueError, match="not an integer"):
        group_marks([[0.5, 1, 2]])


def test_bad_marks_raise_value_error_naming_marks():
    tbd = GateTBD(FRAME)
    with pytest.raises(ValueError, match="marks: expected an \\(M, 2\\)"):
        tbd.push(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="marks: row 1 contains NaN"):
        tbd.push([[1, 2], [np.nan, 3]])
    with pytest.raises(ValueError, match="marks: cannot convert"):
        tbd.push([["a", "b"]])


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"frame_size": (1080,)}, "frame_size"),
        ({"frame_size": (0, 10)}, "frame_size"),
        ({"large_gate": 160}, "large_gate"),
        ({"small_gate": 0}, "small_gate"),
        ({"n_frames": 2}, "n_frames"),
        ({"max_misses": 0}, "max_misses"),
        ({"linearity_threshold": float("nan")}, "linearity_threshold"),
        ({"linearity_threshold": -1}, "linearity_threshold"),
        ({"max_branches": 0}, "max_branches"),
        ({"max_tracks": 1.5}, "max_tracks"),
        ({"linearity": "svd"}, "linearity"),
        ({"linearity": None}, "linearity"),
        ({"seed_exclusion": "sometimes"}, "seed_exclusion"),
        ({"seed_exclusion": 1}, "seed_exclusion"),
    ],
)
def test_bad_configuration_raises_value_error_naming_the_argument(kwargs, name):
    args = {"frame_size": FRAME, **kwargs}
    with pytest.raises(ValueError, match=name):
        GateTBD(**args)


def test_100000_marks_degrade_gracefully_with_capped_branches_and_a_warning():
    rng = np.random.default_rng(1234)

    def clutter(n):
        return np.column_stack((rng.integers(0, 1080, n), rng.integers(0, 1920, n)))

    tbd = GateTBD(FRAME, n_frames=4, max_tracks=50_000)
    tbd.push(clutter(300))
    tbd.push(clutter(300))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for _ in range(2):
            tbd.push(clutter(100_000))
            assert tbd.n_tracks <= 50_000  # bounded memory
        tbd.push(clutter(300))
    msgs = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
    assert msgs and all("incomplete" in m for m in msgs)
    assert any("pairs capped" in m for m in msgs)
    # it recovers: ordinary frames afterwards are processed normally and quietly
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for _ in range(3):
            tbd.push(clutter(300))
    assert tbd.n_tracks < 5_000


def test_bench_json_shape_and_agreement_with_the_naive_reference():
    from seawatch.bench import tbd as bench

    doc = bench.run(frames=40, clutter=150, n_frames=3, reference_frames=10)
    assert doc["benchmark"] == "tbd"
    names = {r["name"] for r in doc["results"]}
    assert names == {"seawatch.GateTBD", "naive.python", "realtime.25fps"}
    assert doc["ratios"]["seawatch.GateTBD/naive.python"] > 1
    assert doc["agreement"]["ok"] and doc["agreement"]["detections_compared"] > 0
    assert doc["targets"]["seawatch.GateTBD"]["target"] == 250.0
