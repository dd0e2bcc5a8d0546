"""The command-line contract (INTERFACES.md): --version, --help with an example, one JSON
document on stdout with --json, exit codes 0 / 1 / 2."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from seawatch import __version__
from seawatch.cli import app
from seawatch.io.camera_file import load_camera

runner = CliRunner()


def test_version_prints_the_installed_version():
    result = runner.invoke(app, ["--version"])
    assert result.exit_code == 0
    assert __version__ in result.stdout


COMMANDS = sorted(typer.main.get_command(app).commands)  # type: ignore[attr-defined]


def test_the_commands_of_this_stage_exist():
    assert {"demo", "bench"} <= set(COMMANDS)


@pytest.mark.parametrize("command", COMMANDS)
def test_every_sub_command_help_shows_an_example(command):
    result = runner.invoke(app, [command, "--help"])
    assert result.exit_code == 0
    assert "Example" in result.stdout and f"seawatch {command}" in result.stdout


def _all_commands(group, path=()):
    """(path, click command) of every leaf command under a click group."""
    for name, cmd in sorted(group.commands.items()):
        if hasattr(cmd, "commands"):
            yield from _all_commands(cmd, (*path, name))
        else:
            yield (*path, name), cmd


def test_help_text_keeps_its_units_and_one_line_summaries():
    """Rich markup takes ``[s]``, ``[px]`` or ``[deg]`` for style tags and drops them:
    no option's or command's help may lose a bracketed word (a unit) when rendered, and
    every command's summary in ``seawatch --help`` is one line of the docstring, not
    its source's line breaks (both seen in session 15: "Clip length ." for
    "Clip length [s].", "estimates.csv,\n tracks.geojson")."""
    import re

    from rich.text import Text

    root = typer.main.get_command(app)
    tag = re.compile(r"\[/?(?:bold|cyan|yellow|red|dim|italic)(?: \w+)*\]|\[/\]")
    checked = 0
    for path, cmd in _all_commands(root):
        texts = [p.help for p in cmd.params if getattr(p, "help", None)] + [cmd.help or ""]
        for text in texts:
            shown = Text.from_markup(text).plain
            for word in re.findall(r"\[[^\]]*[a-zA-Z][^\]]*\]", tag.sub("", text)):
                assert word.lstrip("\\") in shown, (path, word, shown)
                checked += 1
        summary = (cmd.help or "").split("\n\n")[0]
        assert "\n" not in summary, (path, summary)
    assert checked >= 10  # the units of synth, track, horizon and the time options


def test_bench_filters_json_is_one_document_with_ratios_and_agreement():
    result = runner.invoke(app, ["bench", "filters", "--size", "2000", "--repeats", "1", "--json"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["benchmark"] == "filters"
    names = {r["name"] for r in doc["results"]}
    assert names >= {"seawatch.filter", "seawatch.step", "filterpy.KalmanFilter", "numpy.loop"}
    assert doc["ratios"]["seawatch.filter/filterpy.KalmanFilter"] > 0
    assert doc["agreement"]["max_rel_diff"] <= 1e-9 and doc["agreement"]["ok"]


def test_unknown_benchmark_is_bad_input_exit_2():
    result = runner.invoke(app, ["bench", "warp-drive"])
    assert result.exit_code == 2
    assert "warp-drive" in result.output


def test_unknown_option_is_a_usage_error_exit_2():
    result = runner.invoke(app, ["bench", "filters", "--no-such-option"])
    assert result.exit_code == 2


def test_demo_tracks_real_solent_traffic_and_reports_the_errors(tmp_path):
    result = runner.invoke(app, ["demo", "--out", str(tmp_path), "--json"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    names = {path.rsplit("/", 1)[-1] for path in doc["outputs"]}
    want = {"tracks.csv", "estimates.csv", "tracks.geojson", "annotated.mp4", "report.html"}
    assert want | {"camera.yaml"} <= names
    for path in doc["outputs"]:
        assert (tmp_path / path.rsplit("/", 1)[-1]).stat().st_size > 0
    errors = doc["errors"]
    keys = {"rmse_position_m", "rmse_range_percent", "cle_px", "id_switches", "mota", "idf1"}
    assert keys <= set(errors) and errors["frames_scored"] > 100
    # the AIS cross-check labels tracks with the MMSIs of the rendered vessels
    clip = json.loads((tmp_path / "clip" / "clip.json").read_text())
    assert doc["ais"]["matches"] and all(m["mmsi"] in clip["mmsi"] for m in doc["ais"]["matches"])
    # the camera file written is the one the clip was rendered with
    assert load_camera(tmp_path / "camera.yaml") == load_camera(tmp_path / "clip" / "camera.yaml")


def test_experiment_json_has_the_interfaces_shape(tmp_path):
    result = runner.invoke(
        app,
        ["experiment", "air-range", "--runs", "2", "--seed", "4", "--out", str(tmp_path), "--json"],
    )
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert (doc["scenario"], doc["runs"], doc["seed"]) == ("air-range", 2, 4)
    keys = {"estimator", "metric", "unit", "mean", "stderr", "paper", "params"}
    assert all(keys <= set(r) for r in doc["results"])
    # errors.csv, range_error.png and the paper's Figs. 3-6
    names = {Path(p).name for p in doc["outputs"]}
    assert {"errors.csv", "range_error.png"} <= names and len(names) == 6
    assert all(Path(p).is_file() for p in doc["outputs"])


@pytest.mark.parametrize(
    "args",
    [
        ["experiment", "no-such-paper"],
        ["experiment", "air-range", "--table", "2"],
        ["experiment", "air-range", "--fov", "30"],
        ["experiment", "air-range", "--crf", "0"],
        ["experiment", "ship-video", "--crf", "60"],
        ["experiment", "air-range", "--case", "small"],
        ["experiment", "air-range", "--polarity", "dark"],
        ["experiment", "ship-video", "--case", "tiny"],
        ["experiment", "ship-video", "--case", "small", "--polarity", "grey"],
    ],
)
def test_experiment_bad_name_or_option_is_exit_2(args):
    result = runner.invoke(app, args)
    assert result.exit_code == 2
