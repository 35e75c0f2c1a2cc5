"""``shakermill uncertainty``: an answer over its assumed inputs, stored, resumable and refused in one line when
asked wrongly (issue 36)."""

from __future__ import annotations

import json

import pytest
from conftest import assert_one_error_line
from typer.testing import CliRunner

from shakermill import cli
from shakermill.studies.sweeps.storage import load_sweep

runner = CliRunner()
# Twenty seconds of the paper's one ball at full resolution, with λ and β uncertain: eight members in seconds.
CHEAP = [
    "--set",
    "duration=20",
    "--full-resolution",
    "--assume",
    "lam=0.3:0.5",
    "--assume",
    "beta=0.5:1.5:log-uniform",
    "-n",
    "8",
    "--workers",
    "1",
]


def invoke(*args: str):
    return runner.invoke(cli.app, ["uncertainty", *args])


@pytest.mark.slow
def test_an_ensemble_reports_quantiles_and_the_inputs_that_decide_them_and_resumes(tmp_path):
    out = tmp_path / "ensemble"
    first = invoke(*CHEAP, "--out", str(out), "--json")
    assert first.exit_code == 0, first.stderr
    printed = json.loads(first.stdout)
    stored = json.loads((out / "summary.json").read_text())
    assert stored == printed and stored["members"] == 8 and stored["failed"] == 0
    assert [item["key"] for item in stored["inputs"]] == ["lam", "beta"]
    assert stored["inputs"][1]["distribution"] == "log-uniform"
    rise = stored["headlines"]["ball_rise_K"]
    assert rise["p5"] < rise["p50"] < rise["p95"]
    # λ sends the heat into the ball, β takes it out over minutes: after 20 s the rise is λ's.
    assert rise["deciding"][0] == "lam" and rise["sobol_total"]["lam"] > 0.9
    # No calibration's posterior in the paper's preset: the variance is the assumed inputs' and the members' noise.
    assert set(rise["parts"]) == {"assumed inputs", "unexplained"} and rise["parts"]["assumed inputs"] > 0.9
    # The mechanics do not see λ or β: the heat power differs only by the integrator's tolerance, which no
    # surrogate predicts, so no input is said to decide it; the impact rate is the same in every member.
    heat = stored["headlines"]["heat_power_W"]
    assert heat["deciding"] == [] and heat["surrogate_q2"] < 0.5 and heat["p5"] == pytest.approx(heat["p95"], rel=1e-3)
    assert stored["headlines"]["impact_rate_hz"]["varies"] is False
    members = load_sweep(out).table
    assert len(members) == 8 and set(members["lam"]) <= {value for value in members["lam"] if 0.3 <= value <= 0.5}
    page = (out / "report.html").read_text()
    assert "balls&#x27; mean rise at the end" in page or "balls' mean rise at the end" in page
    assert "lam 1.00" in page or f"lam {rise['sobol_total']['lam']:.2f}" in page
    # The same ensemble again: every member is read back, none recomputed, the same numbers.
    stamps = {path.name: path.stat().st_mtime_ns for path in (out / "points").iterdir()}
    again = invoke(*CHEAP, "--out", str(out), "--json")
    assert again.exit_code == 0 and json.loads(again.stdout)["headlines"] == printed["headlines"]
    assert {path.name: path.stat().st_mtime_ns for path in (out / "points").iterdir()} == stamps


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["-n", "6"], ("members: 6 is not allowed", "a power of two")),
        (["--preset", "pulverisette7", "--vary", "frction"], ("--vary frction: no range is stated", "friction")),
        (["--assume", "friction=0.5"], ("--assume 'friction=0.5'", "KEY=LOW:HIGH")),
        (
            ["--preset", "spex8000m-3d", "--assume", "swing_radius=0.05:0.1"],
            ("--assume swing_radius", "does not read it"),
        ),
        (["--preset", "spex8000m-3d", "--assume", "friction=0.2:7"], ("[assumed.friction]", "allowed range [0, 5]")),
        (["--preset", "spex8000m-3d", "--assume", "n_balls=1:3"], ("not a numeric key",)),
        # The paper's 1-D preset states no assumed inputs.
        (["--set", "duration=20"], ("assumed inputs: none to vary",)),
    ],
)
def test_bad_requests_are_one_line_and_exit_2(tmp_path, args, fragments):
    result = invoke(*args, "--out", str(tmp_path / "ensemble"))
    assert result.exit_code == 2, result.stdout
    assert_one_error_line(result.stderr, *fragments)
