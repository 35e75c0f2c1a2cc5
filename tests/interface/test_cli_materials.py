"""`shakermill materials` and the material keys on the command line."""

from __future__ import annotations

import json

import pytest
from conftest import assert_one_error_line
from typer.testing import CliRunner

from shakermill import cli
from shakermill.parameters import materials
from shakermill.studies.sweeps.storage import load_sweep

runner = CliRunner()


def invoke(*args: str):
    return runner.invoke(cli.app, list(args))


def test_the_table_lists_every_material_with_units_in_the_headers():
    outcome = invoke("materials")
    assert outcome.exit_code == 0, outcome.stderr
    for name in materials.names():
        assert name in outcome.stdout
    for header in ("ρ (kg/m³)", "E (GPa)", "c (J/(kg·K))", "k (W/(m·K))", "not applied"):
        assert header in outcome.stdout
    assert "630" in outcome.stdout  # tungsten carbide's E in GPa


def test_one_material_shows_every_value_with_its_unit_and_source():
    outcome = invoke("materials", "wc")
    assert outcome.exit_code == 0, outcome.stderr
    text = " ".join(outcome.stdout.split())
    for fragment in ("tungsten-carbide", "15000", "kg/m^3", "6.3e+11", "Pa", "W/(m*K)", "makeitfrom.com", "assumption"):
        assert fragment in text, fragment


def test_json_holds_si_values_units_and_sources():
    everything = json.loads(invoke("materials", "--json").stdout)["materials"]
    assert [entry["name"] for entry in everything] == list(materials.names())
    one = json.loads(invoke("materials", "zirconia", "--json").stdout)
    assert one["density"] == {
        "value": 6050.0,
        "unit": "kg/m^3",
        "source": materials.material("zirconia").density.source,
    }
    assert one["youngs_modulus"]["value"] == 205e9
    assert one["restitution"]["value"] == list(materials.material("zirconia").restitution.value)
    for key in materials.PROPERTIES:
        assert one[key]["source"]


def test_an_unknown_material_is_one_error_line_listing_the_names():
    outcome = invoke("materials", "unobtainium")
    assert outcome.exit_code == 2
    assert_one_error_line(outcome.stderr, "unknown material 'unobtainium'", "tungsten-carbide", "agate")
    outcome = invoke("keys")  # the key listing names the materials too
    assert "ball_material" in outcome.stdout and "ball_materials" in outcome.stdout


def test_run_refuses_an_unknown_material_with_one_line(tmp_path):
    outcome = invoke("run", "--set", "ball_material=gold", "--out", str(tmp_path / "r"))
    assert outcome.exit_code == 2
    assert_one_error_line(outcome.stderr, "ball_material: unknown material 'gold'")


@pytest.mark.slow
def test_a_sweep_over_the_ball_material(tmp_path):
    folder = tmp_path / "by-material"
    outcome = invoke(
        "sweep", "--set", "duration=60", "--set", "record_windows=", "--grid", "ball_material=steel,zirconia",
        "--workers", "1", "--out", str(folder),
    )  # fmt: skip
    assert outcome.exit_code == 0, outcome.stderr
    table = load_sweep(folder).table
    assert list(table["ball_material"]) == ["hardened-steel", "zirconia"]
    assert table["error"].isna().all()
    # A lighter ball of lower heat capacity: less heat per impact, and a different steady state.
    assert table["theta_inf_C"].iloc[0] != table["theta_inf_C"].iloc[1]
