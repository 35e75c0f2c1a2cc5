"""`shakermill impact`: one impact on its own, its JSON object, its table and its one-line errors."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import assert_one_error_line
from typer.testing import CliRunner

import shakermill as sm
from shakermill import cli
from shakermill.physics import contact

SHAKERMILL = Path(sys.executable).parent / "shakermill"
JSON_KEYS = [
    "normal_restitution",
    "tangential_velocity_out_m_s",
    "angular_velocity_rad_s",
    "contact_time_s",
    "max_overlap_m",
    "max_normal_force_N",
    "dissipated_J",
    "dissipated_normal_J",
    "dissipated_tangential_J",
    "dissipated_sliding_J",
    "dissipated_rolling_J",
]
# Fine contact steps: the measured restitution is then within 4e-4 of the given one (tests/solvers/test_impact.py).
FINE = ["--set", "contact_step_fraction=0.02"]

runner = CliRunner()


def invoke(*args: str):
    return runner.invoke(cli.app, ["impact", *args])


def test_json_holds_exactly_the_documented_keys():
    result = invoke("--speed", "1", "--angle", "30", "--json", *FINE)
    assert result.exit_code == 0, result.stderr
    assert result.stdout.count("\n") == 1
    outcome = json.loads(result.stdout)
    assert list(outcome) == JSON_KEYS
    assert outcome["normal_restitution"] == pytest.approx(0.7, abs=1e-3)  # the default preset's e


def test_settings_reach_the_impact():
    settings = ["--set", "restitution=0.5", "--set", "friction=0", *FINE]
    result = invoke("--speed", "2", "--angle", "30", "--json", *settings)
    assert result.exit_code == 0, result.stderr
    outcome = json.loads(result.stdout)
    assert outcome["normal_restitution"] == pytest.approx(0.5, abs=1e-3)
    # Without friction nothing acts along the end face: the ball keeps V sin θ and gets no spin.
    assert outcome["tangential_velocity_out_m_s"] == pytest.approx(1.0, rel=1e-12)
    assert outcome["angular_velocity_rad_s"] == 0.0


def test_spin_angle_and_ball_target_are_passed_on():
    spinning = invoke("--speed", "1", "--angle", "60", "--spin", "300", "--set", "rolling_friction=0.05", "--json")
    assert json.loads(spinning.stdout)["dissipated_rolling_J"] > 0.0
    ball = invoke("--speed", "1", "--target", "ball", "--set", "pair_restitution=0.9", "--json", *FINE)
    assert json.loads(ball.stdout)["normal_restitution"] == pytest.approx(0.9, abs=1e-3)
    # The end face's restitution is not the balls': set for a ball target, it is refused, not ignored.
    refused = invoke("--speed", "1", "--target", "ball", "--set", "restitution=0.9", "--json")
    assert refused.exit_code == 2 and "restitution: an impact on a ball does not read it" in refused.stderr


def test_a_ball_too_large_for_the_default_vial_is_accepted():
    """The vial's size plays no part in a lone impact: the command makes room for any allowed ball."""
    settings = ["--set", "ball_radius=0.1", "--set", "restitution=1", "--set", "friction=0"]
    result = invoke("--speed", "0.2", "--json", *settings)
    assert result.exit_code == 0, result.stderr
    assert json.loads(result.stdout)["normal_restitution"] == pytest.approx(1.0, abs=1e-3)


def test_without_json_a_table_with_units():
    result = invoke("--speed", "1", "--angle", "45")
    assert result.exit_code == 0, result.stderr
    for fragment in ("normal restitution", "contact time", "µs", "largest overlap", "µm", "by sliding", "rad/s"):
        assert fragment in result.stdout


@pytest.mark.parametrize(
    "args, fragments",
    [
        (["--speed", "0"], ("--speed", "0 < speed <= 1000 m/s")),
        (["--speed", "1", "--angle", "90"], ("--angle", "0 <= angle < 90°")),
        (["--speed", "1", "--target", "floor"], ("--target", "'wall', 'ball'")),
        (["--speed", "1", "--spin", "1e9"], ("--spin",)),
        (["--speed", "1", "--set", "restitution=2"], ("restitution", "(0, 1]")),
        (["--angle", "10"], ("--speed",)),
    ],
)
def test_bad_input_exits_2_with_one_line_naming_the_option(args, fragments):
    result = invoke(*args)
    assert result.exit_code == 2
    assert_one_error_line(result.stderr, *fragments)


@pytest.mark.parametrize(
    "setting, fragments",
    [
        # Issue 25: computed steel (578 N for 1007 N) and made 9154 balls for the impact's own vial.
        ("ball_materials=wc", ("ball_materials: a lone impact does not read it", "several balls applies to runs")),
        ("fill=0.3", ("fill: a lone impact does not read it", "it reads the contact law alone (the balls,")),
        ("engine=1d", ("engine: a lone impact does not read it", "the run applies to runs")),
        ("yaw_amplitude=0.1", ("yaw_amplitude:", "the SPEX 8000M clamp applies to runs")),
        ("duration=5", ("duration:", "the run applies to runs")),
    ],
)
def test_keys_a_lone_impact_does_not_read_are_refused_with_why(setting, fragments):
    result = invoke("--speed", "2", "--set", setting)
    assert result.exit_code == 2
    assert_one_error_line(result.stderr, *fragments)


def test_the_scalar_ball_material_reaches_the_impact_and_a_bound_with_a_unit_is_accepted():
    steel, carbide = (invoke("--speed", "2", "--json", "--set", f"ball_material={name}") for name in ("steel", "wc"))
    assert json.loads(carbide.stdout)["max_normal_force_N"] > 1.5 * json.loads(steel.stdout)["max_normal_force_N"]
    smallest = invoke("--speed", "0.01", "--json", "--set", "ball_radius=25um")
    assert smallest.exit_code == 0, smallest.stderr
    assert json.loads(smallest.stdout)["max_overlap_m"] > 0.0


def test_a_speed_too_slow_to_resolve_is_refused_at_once_with_numbers():
    result = invoke("--speed", "1e-300")
    assert result.exit_code == 2
    assert_one_error_line(result.stderr, "--speed: 1e-300 m/s is too slow to resolve", "allowed speed·cos(angle) >= ")
    assert "(0 s)" not in result.stderr


def test_an_impact_the_engine_cannot_resolve_exits_2_naming_the_cause():
    result = invoke("--speed", "30", "--set", "ball_youngs_modulus=1e8")
    assert result.exit_code == 2
    assert_one_error_line(result.stderr, "overlap exceeded 5 %", "contact_step_fraction")


@pytest.mark.slow
def test_installed_command_refuses_a_negative_speed_in_one_line():
    command = [str(SHAKERMILL), "impact", "--speed", "-1"]
    completed = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert completed.returncode == 2
    assert completed.stdout == ""
    assert completed.stderr == "error: --speed: -1 m/s is out of range; allowed 0 < speed <= 1000 m/s\n"


# The Chung & Ooi (2011) verification set through the command itself (inputs: docs/notes/dem-references.md §1;
# the full set, with more angles and speeds, is in tests/solvers/test_impact.py).
RIGID_WALL = ["--set", "vial_youngs_modulus=1.2e12"]
ALUMINA = [
    "--set",
    "ball_radius=2.5mm",
    "--set",
    "ball_density=4000",
    "--set",
    "ball_youngs_modulus=3.8e11",
    "--set",
    "ball_poisson_ratio=0.23",
]


def impact_json(*args: str) -> dict:
    result = invoke("--json", *args)
    assert result.exit_code == 0, result.stderr
    return json.loads(result.stdout)


def hertz(mass: float, radius: float, modulus: float, speed: float) -> tuple[float, float, float]:
    overlap = contact.hertz_max_overlap(mass, radius, modulus, speed)
    return (
        contact.hertz_contact_time(mass, radius, modulus, speed),
        overlap,
        contact.hertz_force(overlap, modulus, radius),
    )


@pytest.mark.parametrize(
    "target, settings",
    [
        # Test 1: two glass balls (R = 10 mm, E = 48 GPa, ν = 0.2) meeting at 20 m/s, e = 1
        (
            "ball",
            [
                "--set",
                "ball_radius=10mm",
                "--set",
                "ball_density=2800",
                "--set",
                "ball_youngs_modulus=4.8e10",
                "--set",
                "ball_poisson_ratio=0.2",
            ],
        ),
        # Test 2: an aluminium ball (R = 0.1 m, E = 70 GPa, ν = 0.3) on a rigid plane at 0.2 m/s, e = 1
        (
            "wall",
            [
                "--set",
                "ball_radius=0.1",
                "--set",
                "ball_density=2699",
                "--set",
                "ball_youngs_modulus=7e10",
                "--set",
                "ball_poisson_ratio=0.3",
                *RIGID_WALL,
            ],
        ),
    ],
    ids=["test 1", "test 2"],
)
def test_chung_ooi_elastic_normal_impacts_follow_hertz(target, settings):
    speed = 20.0 if target == "ball" else 0.2
    elastic = "pair_restitution=1" if target == "ball" else "restitution=1"
    outcome = impact_json("--speed", str(speed), "--target", target, "--set", elastic, *settings, *FINE)
    # The command makes the vial large enough for any ball; so does this, for the ball's mass and moduli.
    params = sm.default_parameters(
        vial_length=1.0, vial_diameter=0.9, **dict(item.split("=", 1) for item in settings[1::2])
    )
    own = (params.ball_youngs_modulus, params.ball_poisson_ratio)
    if target == "ball":
        mass, radius, modulus = params.ball_mass / 2, params.ball_radius / 2, contact.effective_modulus(*own, *own)
    else:
        other = (params.vial_youngs_modulus, params.vial_poisson_ratio)
        mass, radius, modulus = params.ball_mass, params.ball_radius, contact.effective_modulus(*own, *other)
    contact_time, overlap, force = hertz(mass, radius, modulus, speed)
    assert outcome["contact_time_s"] == pytest.approx(contact_time, rel=0.01)
    assert outcome["max_overlap_m"] == pytest.approx(overlap, rel=0.01)
    assert outcome["max_normal_force_N"] == pytest.approx(force, rel=0.01)
    assert outcome["normal_restitution"] == pytest.approx(1.0, abs=1e-3)


@pytest.mark.parametrize("restitution", ["0.2", "0.6", "1.0"])
def test_chung_ooi_3_restitution_is_the_given_one(restitution):
    outcome = impact_json(
        "--speed", "3.9", "--set", f"restitution={restitution}", "--set", "friction=0", *ALUMINA, *RIGID_WALL, *FINE
    )
    assert outcome["normal_restitution"] == pytest.approx(float(restitution), abs=1e-3)


def test_chung_ooi_4_gross_sliding_changes_velocity_and_spin_as_coulomb_says():
    """Alumina, e = 0.98, μ = 0.092, 3.9 m/s at 60° from the normal: sliding throughout."""
    outcome = impact_json(
        "--speed",
        "3.9",
        "--angle",
        "60",
        "--set",
        "restitution=0.98",
        "--set",
        "friction=0.092",
        *ALUMINA,
        *RIGID_WALL,
        *FINE,
    )
    normal = 3.9 * math.cos(math.radians(60.0))
    change = 0.092 * 1.98 * normal
    assert 3.9 * math.sin(math.radians(60.0)) - outcome["tangential_velocity_out_m_s"] == pytest.approx(
        change, rel=0.02
    )
    assert outcome["angular_velocity_rad_s"] == pytest.approx(2.5 * change / 2.5e-3, rel=0.02)
    assert outcome["dissipated_sliding_J"] > 0.0
