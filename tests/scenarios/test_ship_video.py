"""ship-video scenario: record shapes and the order sweep (tiny run)."""

from __future__ import annotations

import math

import cv2
import pytest

from seawatch.scenarios import ship_video
from seawatch.scenarios.ship_video import run


def test_record_shapes_and_sweep(tmp_path):
    res = run(
        cases=["small"], width=640, height=360, small_scale=3, duration=1.6,
        orders=(0.8, 1.0), out_dir=tmp_path,
    )  # fmt: skip
    assert res.scenario == "ship-video" and res.runs == 1
    for est in ("afkf", "fkf", "kf"):
        for metric, unit in (("cle_px", "px"), ("cle_percent", "%"), ("cle_precision", "%")):
            rec = res.find(est, metric, case="small")
            assert rec["unit"] == unit and rec["params"] == {"case": "small"}
            assert math.isfinite(rec["mean"]) and rec["stderr"] is None
    for a in (0.8, 1.0):
        assert res.find("afkf", "cle_percent", order=a)["params"] == {"order": a}
    assert len(res.results) == 9 + 2
    assert set(res.extra["ordering"]) == {"small"}
    assert res.extra["best_order"] in (0.8, 1.0)
    assert (tmp_path / "cle.csv").exists() and (tmp_path / "small" / "video.mp4").exists()
    assert res.extra["crf"] == 20
    # the figures: a PNG of two panels with drawn content, listed among the outputs
    png = cv2.imread(str(tmp_path / "cle.png"))
    assert png is not None and png.shape == (462, 1210, 3) and png.std() > 10
    assert tmp_path / "cle.png" in res.outputs


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match="cases"):
        run(cases=["tiny"])
    with pytest.raises(ValueError, match="runs"):
        run(runs=0)
    for crf in (-1, 52, 1.5):
        with pytest.raises(ValueError, match="crf"):
            run(cases=["large"], crf=crf)
    with pytest.raises(ValueError, match="polarity"):
        run(cases=["large"], polarity="grey")


def test_dark_polarity_drops_the_glitters_tracks_in_the_lighting_case():
    """The lighting case faces a low sun: with the detector looking for dark ships only
    (``polarity="dark"``), no glitter track takes the distant boat's CLE (8 s, three
    renderings: afkf 4.09 → 2.66 %, README); on 4 s here 4.24 → 2.54 % (afkf), with
    the ordering afkf ≤ fkf ≤ kf (2.54, 2.54, 2.64 %). (On 2 s, as up to session 18,
    the ordering no longer holds since session 19's horizon-stabilised rows, which
    start once the horizon has settled: afkf 2.60, kf 2.54 %; before, 2.40 and 2.47.
    Before session 16's detector changes, which drop most glitter boxes with both
    polarities too, the default gave 10.5 % on 2 s.)"""
    opts = {"cases": ["lighting"], "duration": 4.0}
    both = run(**opts)
    dark = run(polarity="dark", **opts)
    assert dark.extra["polarity"] == "dark" and both.extra["polarity"] == "both"
    e_both = both.find("afkf", "cle_percent", case="lighting")["mean"]
    e_dark = dark.find("afkf", "cle_percent", case="lighting")["mean"]
    assert e_dark < 0.75 * e_both, (e_dark, e_both)
    assert dark.extra["ordering"]["lighting"]


def test_chunked_units_give_the_records_of_one_run(tmp_path):
    opts = {"cases": ["large"], "width": 320, "height": 180, "duration": 0.8}
    assert ship_video.units(2, **opts) == 2
    whole = run(runs=2, seed=3, **opts)
    parts = [ship_video.chunk([u], 2, 3, **opts) for u in (0, 1)]
    split = ship_video.merge(parts, 2, 3, tmp_path, **opts)
    assert split.results == whole.results and split.extra == whole.extra
    assert (tmp_path / "cle.csv").read_text().count("\n") == 1 + 2 * 3
    assert cv2.imread(str(tmp_path / "cle.png")) is not None
    with pytest.raises(ValueError, match="payloads"):
        ship_video.merge(parts[:1], 2, 3, **opts)
    with pytest.raises(ValueError, match="indices"):
        ship_video.chunk([2], 2, 3, **opts)
