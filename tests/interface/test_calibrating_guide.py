"""The calibration guide's example, as docs/guide/calibrating.md writes it (issue 37, point 1): its configuration,
its curve and its command, read from the page, end with a fitted preset that holds the mill it was fitted for.

Run here without the posterior (--no-posterior: its ~2400 network evaluations take four minutes); the whole example,
posterior included, is timed by benchmarks/bench_calibrating_guide.py."""

from __future__ import annotations

import json
import re
import shlex
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
GUIDE = ROOT / "docs" / "guide" / "calibrating.md"


def guide_example() -> tuple[str, str, list[str]]:
    """The guide's my-mill.toml, its vial.csv and the arguments of its first calibrate command."""
    text = GUIDE.read_text(encoding="utf-8")
    config = next(block for block in re.findall(r"```toml\n(.*?)```", text, re.S) if block.startswith("# my-mill.toml"))
    curve = next(block for block in re.findall(r"```text\n(.*?)```", text, re.S) if block.startswith("time_min,vial_C"))
    command = next(line for line in text.splitlines() if line.startswith(".venv/bin/shakermill calibrate my-mill.toml"))
    return config, curve, shlex.split(command)[2:]


@pytest.mark.slow
def test_the_guides_calibration_as_written_ends_with_a_fitted_preset_of_its_mill(tmp_path):
    config, curve, arguments = guide_example()
    (tmp_path / "my-mill.toml").write_text(config, encoding="utf-8")
    (tmp_path / "vial.csv").write_text(curve, encoding="utf-8")
    assert arguments == ["my-mill.toml", "--curve", "vial.csv", "--out", "my-mill-fitted.toml"]
    completed = subprocess.run(
        [sys.executable, "-m", "shakermill.cli", "calibrate", *arguments, "--no-posterior", "--json"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=1800,
    )
    assert completed.returncode == 0, completed.stderr[-3000:]
    fit = json.loads(completed.stdout)
    assert fit["status"] == "fitted" and fit["output"] == "my-mill-fitted.toml"
    # Piped, it said what it was doing: the mechanics it measured once, then the fit's evaluations.
    assert "calibrate: fitting beta, vial_mass, h_outer" in completed.stderr
    assert fit["curve_rms_K"] < 1.0
    written = tomllib.loads((tmp_path / "my-mill-fitted.toml").read_text(encoding="utf-8"))
    assert written["preset"] == "spex8000m-3d"
    assert written["n_balls"] == 2 and written["ball_material"] == "zirconia"
    for key, value in fit["fitted"].items():
        assert written[key] == pytest.approx(value, rel=1e-12)
    # A vial's curve does not support the balls' steady state: its standard error says so.
    assert fit["prediction_stderr"]["ball_steady_C"] > 0.5 * (fit["predictions"]["ball_steady_C"] - 22.0)
    assert fit["prediction_stderr"]["vial_steady_C"] < 0.5 * (fit["predictions"]["vial_steady_C"] - 22.0)
