"""The run summary's schema (solvers/summary.py, its sections, its versions solvers/summary_versions.py; issues 39
and 48): every key a run of each engine and solver summarizes is declared with a unit and a meaning, summary.json
round-trips, a misspelt key fails loudly, the summary reads as a mapping of its flat keys, mypy refuses a writer of a
wrongly typed section, and an old summary.json is read where it can be or refused in one line."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import textwrap
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pytest
from conftest import assert_one_error_line
from typer.testing import CliRunner

import shakermill as sm
from shakermill import cli
from shakermill.analysis.sections import further_nodes
from shakermill.engines.records import StateHistory, attributes
from shakermill.io.runs import load_run, to_jsonable, write_run
from shakermill.solvers.result import end_temperatures
from shakermill.solvers.summary import (
    FAMILIES,
    Summary,
    SummaryKeyError,
    declared,
    declared_name,
    family_members,
    summary_keys,
    unit_of,
)
from shakermill.solvers.summary_versions import SCHEMA_VERSION, SummaryVersionError, summary_from_document

# A short run of each engine and solver, and what its summary must hold besides the keys of every run.
RUNS = {
    "1-D": ({"duration": 1.0}, ()),
    "dem, three balls": (
        {"preset": "spex8000m-3d", "n_balls": 3, "duration": 0.2},
        ("n_balls", "ball_temperatures_C", "balls_steady_C", "dissipated_normal_W", "heat_sliding_W", "charge_regime"),
    ),
    "mill-head": (
        {"preset": "spex8000m-3d", "thermal_model": "mill-head", "n_balls": 2, "duration": 0.2},
        ("holder_C", "holder_steady_C", "heat_paths_W"),
    ),
    "averaged": (
        {"solver": "averaged", "duration": 600.0, "attractor_starts": 2},
        ("averaged_heat_power_W", "averaging_window_s", "averaging_converged", "n_attractors"),
    ),
}
# A key's unit from its name's suffix, as the keys are named (omega_hz is a frequency, not a rate of events).
SUFFIX_UNITS = (
    ("_steady_C_low", "°C"),
    ("_C_per_min", "°C/min"),
    ("_rad_s", "rad/s"),
    ("_m_s", "m/s"),
    ("_C", "°C"),
    ("_K", "K"),
    ("_W", "W"),
    ("_J", "J"),
    ("_hz", "1/s"),
    ("_min", "min"),
    ("_mm", "mm"),
    ("_s", "s"),
)


@pytest.fixture(scope="module", params=list(RUNS))
def run(request) -> tuple[str, sm.Result]:
    settings, _ = RUNS[request.param]
    settings = dict(settings)
    params = sm.default_parameters(settings.pop("preset", "spex8000m"), record_windows=(), **settings)
    return request.param, sm.simulate(params)


def same(a, b) -> bool:
    """Equal, NaN equal to NaN (a number that was not finite is null in JSON and NaN read back)."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[key], b[key]) for key in a)
    return a == b


@pytest.mark.slow
def test_every_key_a_run_summarizes_is_declared_with_its_unit_and_meaning(run):
    name, result = run
    summary = result.summary
    assert isinstance(summary, Summary) and result.success, result.message
    flat = summary.flat()
    for key in flat:
        assert declared(key).meaning, key
    for key in RUNS[name][1]:
        assert summary.has(key), (name, key)
    if name == "averaged":
        assert summary.solver == "averaged"
    # What each engine's run leaves out is absent, not null: a one-ball engine has no balls' keys or channels.
    if name in ("1-D", "averaged"):
        assert summary.charge is None and "n_balls" not in flat and summary.dissipated_by_channel_W == {}
    assert (summary.temperatures.holder is None) == (name != "mill-head")


@pytest.mark.slow
def test_summary_json_round_trips(run, tmp_path):
    _, result = run
    flat = result.summary.flat()
    # Through JSON as summary.json and run --json write it: non-finite numbers null, read back as NaN.
    text = json.dumps(to_jsonable(flat), allow_nan=False)
    assert same(Summary.from_flat(json.loads(text)).flat(), flat)
    folder = write_run(result, tmp_path / "run", preset="spex8000m")
    document = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
    assert document["schema_version"] == SCHEMA_VERSION
    assert same(load_run(folder).summary.flat(), flat)


def test_every_declared_key_has_a_meaning_and_the_unit_its_name_says():
    keys = summary_keys()
    assert len(keys) == len({key.name for key in keys}) > 100
    for key in keys:
        assert len(key.meaning) > 10, key.name
        name = key.name.replace("{channel}", "x").replace("{threshold}", "x")
        suffix = next((unit for end, unit in SUFFIX_UNITS if name.endswith(end)), None)
        if suffix is not None and name not in ("omega_hz", "ball_ball_impacts"):
            assert key.unit == suffix, (key.name, key.unit)
    assert unit_of("omega_hz") == "Hz" and unit_of("omega_rpm") == "rpm" and unit_of("vial_ball_ratio") == ""
    assert unit_of("heat_rolling_W") == "W" and unit_of("stress_events_above_0.01J_hz") == "1/s"
    # A family is declared by its pattern, its members found by it.
    assert {family.pattern for family in FAMILIES} <= {key.name for key in keys}
    columns = ["ball_C", "stress_power_above_0.001J_W", "stress_power_above_0.01J_W", "heat_power_W"]
    assert family_members(columns, "stress_power_above_{threshold}_W") == {
        "stress_power_above_0.001J_W": "0.001J",
        "stress_power_above_0.01J_W": "0.01J",
    }


def test_a_misspelt_key_fails_loudly_with_the_nearest_one(default_run_20s):
    summary = default_run_20s.summary
    with pytest.raises(SummaryKeyError, match="'ball_steady_c' is not a summary key.*did you mean 'ball_steady_C'"):
        summary.value("ball_steady_c")
    with pytest.raises(SummaryKeyError):
        declared_name("impact_rate_per_s")
    with pytest.raises(SummaryKeyError):
        summary.updated(ball_c=20.0)
    # As a mapping too, a misspelt key is no key (with the nearest one in its message).
    with pytest.raises(KeyError, match="did you mean 'ball_steady_C'"):
        summary["ball_steady_c"]  # noqa: B018
    assert "ball_steady_c" not in summary and summary.get("ball_steady_c") is None
    assert summary.value("ball_C") == summary.ball_C and summary.number("ball_C") == summary.ball_C
    # Declared but not of this run: an optional key is None (NaN as a number); a family's members are the run's own,
    # so a channel a one-ball engine has not is no key of its summary.
    assert summary.value("holder_C") is None and math.isnan(summary.number("holder_C"))
    assert not summary.has("n_balls") and summary.has("ball_steady_C") and not summary.has("heat_normal_W")
    with pytest.raises(SummaryKeyError, match="'heat_normal_W' is no key of this run's summary \\(its channels: none"):
        summary.value("heat_normal_W")


def test_the_summary_is_frozen_and_an_update_is_checked(default_run_20s):
    summary = default_run_20s.summary
    with pytest.raises(ValueError):
        summary.ball_C = 30.0
    changed = summary.updated(validation_caveat="said", ball_C=30.0)
    assert (changed.ball_C, changed.validation_caveat, summary.validation_caveat) == (30.0, "said", None)
    with pytest.raises(ValueError):
        summary.updated(impacts="many")


def test_the_summary_is_a_read_only_mapping_of_its_flat_keys(default_run_20s):
    """For a notebook: ``summary["key"]`` beside the attributes, over the keys summary.json has (issue 48)."""
    summary = default_run_20s.summary
    flat = summary.flat()
    assert isinstance(summary, Mapping)
    assert summary["ball_steady_C"] == summary.ball_steady_C and summary["impacts"] == summary.impacts.count
    assert summary["heat_paths_W"] == summary.heat_paths_W and summary["tau_min"] == summary.tau_min
    assert list(summary) == list(summary.keys()) == list(flat) and len(summary) == len(flat)
    assert same(dict(summary.items()), flat)
    assert "ball_C" in summary and "stress_events_above_0.001J_hz" in summary
    # A key of no value in this run is declared, but no key of its mapping: None through get and value.
    assert "holder_C" not in summary and summary.get("holder_C") is None and summary.value("holder_C") is None
    with pytest.raises(KeyError, match="'holder_C': this run's summary has no value"):
        summary["holder_C"]  # noqa: B018
    with pytest.raises(TypeError):
        summary["ball_C"] = 30.0  # type: ignore[index]
    # What it gives is a copy: the frozen summary does not change through it.
    summary["warnings"].append("said here")
    summary["heat_paths_W"]["a path"] = 1.0
    assert "said here" not in summary.warnings and "a path" not in summary.heat_paths_W


def test_the_sections_are_nested_where_clearer_and_flat_on_disk(run):
    """The temperatures by node, the steady state, the impacts, the averaging and the balls are sections of their
    own in Python; summary.json has their fields under the keys of version 2."""
    name, result = run
    summary = result.summary
    flat = summary.flat()
    assert summary.temperatures.by_node()["vial"] == summary.vial_C == flat["vial_C"]
    assert summary.steady is not None and summary.steady.ball == flat["ball_steady_C"]
    assert summary.steady.slowest_time_constant_min == flat["slowest_time_constant_min"]
    assert (summary.impacts.count, summary.impacts.rate_hz) == (flat["impacts"], flat["impact_rate_hz"])
    assert "count" not in flat and "temperatures" not in flat and "impacts" in flat
    if name == "averaged":
        assert summary.averaging is not None and summary.averaging.window_s == flat["averaging_window_s"]
        assert summary.attractors is not None and summary.attractors.count == flat["n_attractors"]
    else:
        assert summary.averaging is None and not any(key.startswith("averag") for key in flat)
    if name.startswith("dem"):
        assert summary.charge is not None and summary.charge.n_balls == flat["n_balls"] == 3
        assert summary.impacts.on_walls == flat["wall_impacts"]
    if name == "mill-head":
        assert summary.further_nodes() == {"holder": (flat["holder_C"], flat["holder_steady_C"])}


# A writer of each kind mypy refuses: a section of the wrong type returned, a field of the wrong type, a misspelt
# field, and a section given to the summary in the place of another.
WRONG_WRITERS = """
from shakermill.analysis.attractors import AttractorSection
from shakermill.analysis.fit import FitSection
from shakermill.analysis.steady import SteadySection
from shakermill.analysis.stress_energy import StressSection
from shakermill.solvers.summary import Summary
from shakermill.solvers.summary_sections import (
    EndTemperatures, Heat, Impacts, Inputs, Numerics, Outcome, PredictionIntervals,
)


def attractors(impacts: Impacts) -> AttractorSection:
    return impacts


def averaging(window: float) -> PredictionIntervals:
    return PredictionIntervals(
        ball_C_low="low", ball_C_high=1.0, vial_C_low=1.0, vial_C_high=1.0, ball_steady_C_low=1.0,
        ball_steady_C_high=1.0, vial_steady_C_low=1.0, vial_steady_C_high=1.0, note="",
    )


def numerics() -> Numerics:
    return Numerics(
        step=1, rejected_steps=0, rhs_evaluations=1, wall_time_s=1.0, energy_audit_residual=0.0,
        energy_projection_relative=0.0,
    )


def composed(
    outcome: Outcome, fit: FitSection, temperatures: EndTemperatures, steady: SteadySection, impacts: Impacts,
    heat: Heat, numerics: Numerics, inputs: Inputs, stress: StressSection,
) -> Summary:
    return Summary.compose(
        outcome=outcome, fit=stress, temperatures=temperatures, steady=steady, impacts=impacts, heat=heat,
        charge=None, numerics=numerics, inputs=inputs, stress=stress, averaging=None, attractors=None, warnings=[],
        notes=[],
    )
"""


@pytest.mark.slow
def test_mypy_refuses_a_writer_of_a_wrongly_typed_section(tmp_path):
    """The sections are checked where they are built (``make test`` runs mypy over the package's writers); here the
    same check on writers made wrong on purpose, each refused on its line."""
    root = Path(__file__).resolve().parents[2]
    snippet = tmp_path / "wrong_writers.py"
    snippet.write_text(textwrap.dedent(WRONG_WRITERS), encoding="utf-8")
    checked = subprocess.run(
        [sys.executable, "-m", "mypy", "--config-file", str(root / "pyproject.toml"), str(snippet)],
        cwd=root,
        # The package's source, as make test checks it (the editable install carries no py.typed marker).
        env={**os.environ, "MYPYPATH": str(root / "src")},
        capture_output=True,
        text=True,
        check=False,
    )
    assert checked.returncode == 1, checked.stdout + checked.stderr
    lines = textwrap.dedent(WRONG_WRITERS).splitlines()

    def line_of(text: str) -> int:
        return next(number for number, line in enumerate(lines, 1) if text in line)

    found = {
        (int(line.split(":")[1]), line.rsplit("[", 1)[-1].rstrip("]"))
        for line in checked.stdout.splitlines()
        if ": error: " in line
    }
    assert found == {
        (line_of("    return impacts"), "return-value"),
        (line_of('ball_C_low="low"'), "arg-type"),
        (line_of("    return Numerics("), "call-arg"),
        (line_of("fit=stress"), "arg-type"),
    }, checked.stdout


def history_of(**nodes: float) -> StateHistory:
    """A history of the nodes ``theta_<node>`` (K) at two samples, with the balls' own and the °C copies."""
    variables = {f"theta_{node}": (np.array([293.15, kelvin]), attributes("K", node)) for node, kelvin in nodes.items()}
    variables["theta_balls"] = (np.full((2, 3), 300.0), attributes("K", "each ball"))
    variables["theta_ball_C"] = (np.array([20.0, 25.0]), attributes("degC", "ball"))
    return StateHistory(np.array([0.0, 1.0]), variables, {"theta_balls": ("time", "ball")})


def test_the_temperature_of_every_node_at_the_end_comes_from_its_history_variable():
    found = end_temperatures(history_of(ball=303.15, vial=298.15, air=294.15, holder=295.15, powder=310.15))
    assert found == pytest.approx({"ball": 30.0, "vial": 25.0, "air": 21.0, "holder": 22.0, "powder": 37.0}, abs=1e-12)
    # An engine that still calls the holder the clamp: its temperature is the holder's.
    assert further_nodes({"clamp": 27.0, "powder": 30.0}) == (27.0, {"powder": 30.0})
    # A node no key names (one an extension adds) is of the family {node}_C; a key of no declared form fails loudly.
    flat = sm.simulate(sm.default_parameters(duration=0.1)).summary.flat()
    with_lid = Summary.from_flat({**flat, "lid_C": 20.0, "lid_steady_C": 21.0})
    assert with_lid.temperatures.others == {"lid": 20.0} and with_lid.value("lid_steady_C") == 21.0
    assert with_lid.steady is not None and with_lid.steady.by_node()["lid"] == 21.0
    assert "lid_C" in with_lid.flat() and unit_of("lid_C") == "°C"
    assert with_lid.further_nodes() == {"lid": (20.0, 21.0)}
    with pytest.raises(ValueError, match="'lid_temperature_K' is not a summary key"):
        Summary.from_flat({**flat, "lid_temperature_K": 293.0})
    # Built as a section, a node of no such name (or one of the named nodes' names) is refused: its key would not read
    # back, or would be another's.
    fields = {name: getattr(with_lid, name) for name in Summary.model_fields}
    for others in ({"jar_lid": 20.0}, {"vial": 20.0}):
        temperatures = with_lid.temperatures.model_copy(update={"others": others})
        with pytest.raises(ValueError, match=f"the member '{next(iter(others))}'"):
            Summary(**{**fields, "temperatures": temperatures})


def version_1(summary: Summary, **changes) -> dict:
    """``summary`` as an older shakermill wrote it: the clamp's keys for the holder's, ``changes`` applied (None
    removes a key)."""
    flat = to_jsonable(summary.flat())
    for old, new in (("clamp_C", "holder_C"), ("clamp_steady_C", "holder_steady_C")):
        if new in flat:
            flat[old] = flat.pop(new)
    for key, value in changes.items():
        if value is None:
            flat.pop(key, None)
        else:
            flat[key] = value
    return flat


def test_a_version_1_summary_is_brought_forward_where_it_can_be(default_run_20s):
    summary = default_run_20s.summary
    old = version_1(summary, clamp_C=24.0, exponential_fit_describes_run=None, stress_window_s=None, gone_key=1.0)
    read = summary_from_document(old, None)
    assert read.temperatures.holder == 24.0 and read.exponential_fit_describes_run is True
    assert math.isnan(read.stress_window_s) and read.ball_C == summary.ball_C
    assert summary_from_document(version_1(summary), 1).flat().keys() == summary.flat().keys()


# Summaries as shakermill wrote them at version 2 (issue 39; spex8000m-3d-mill-head, 3 balls, 0.2 s; the averaged 1-D
# default with its attractor probe; spex8000m-calibrated with its intervals; spex8000m-3d, 5 balls, averaged).
VERSION_2 = Path(__file__).resolve().parents[1] / "data" / "summary-v2"


# The keys of impacts as MODEL.md §14.4 defines them and of the settled regime (schema 4).
ADDED_IN_VERSION_4 = (
    "contact_records_hz",
    "touch_rate_hz",
    "stress_energy_weighted_median_J",
    "stress_energy_weighted_p90_J",
    "charge_regime_from_s",
    "charge_regime_lasting_share",
    "charge_regime_fast_impact_rate_hz",
    "charge_regime_active_share",
    "charge_regime_switch_interval_s",
)


@pytest.mark.parametrize("name", ["mill-head", "oned-averaged", "calibrated", "dem-averaged"])
def test_a_version_2_summary_is_read_into_the_sections_with_every_key_as_it_was(name):
    document = json.loads((VERSION_2 / f"{name}.json").read_text(encoding="utf-8"))
    assert document["schema_version"] == 2
    stored = document["summary"]
    read = summary_from_document(stored, 2)
    # Flat again, the same keys and values, null read as NaN; and those version 4 added (issue 50), NaN.
    flat = read.flat()
    added = {key: flat.pop(key) for key in ADDED_IN_VERSION_4 if key in flat}
    assert added and all(math.isnan(value) for value in added.values()) and not set(added) & set(stored)
    assert same(flat, {key: math.nan if value is None else value for key, value in stored.items()})
    assert read.ball_C == stored["ball_C"] and read.impacts.count == stored["impacts"]
    if name == "mill-head":
        assert read.temperatures.holder == stored["holder_C"] and read.charge is not None
        assert read.impacts.between_balls == stored["ball_ball_impacts"]
        assert read.heat_by_channel_W["sliding"] == stored["heat_sliding_W"]
    if name in ("oned-averaged", "dem-averaged"):
        assert read.averaging is not None and read.averaging.replicas == stored["averaging_replicas"]
    if name == "oned-averaged":
        assert read.attractors is not None and read.attractors.count == stored["n_attractors"]
    if name == "calibrated":
        assert read.intervals is not None and read.intervals.ball_steady_C_high == stored["ball_steady_C_high"]
        assert read.intervals.note == stored["interval_note"]
        assert read.validation_caveat == stored["validation_caveat"]


def test_a_version_1_averaged_summary_gets_the_keys_its_sections_added_since():
    """A version-1 averaged run predates the replicas and the grouped batches: one replica, the batches NaN."""
    stored = json.loads((VERSION_2 / "oned-averaged.json").read_text(encoding="utf-8"))["summary"]
    for added_since in ("averaging_replicas", "averaging_batch_s", "averaging_batch_autocorrelation"):
        del stored[added_since]
    read = summary_from_document(stored, None)
    assert read.averaging is not None and read.averaging.replicas == 1
    assert math.isnan(read.averaging.batch_s) and math.isnan(read.averaging.batch_autocorrelation)
    assert read.averaging.window_s == stored["averaging_window_s"]
    # A section of which the older document has nothing is not made up.
    assert read.charge is None and read.intervals is None


def test_a_summary_of_a_version_this_one_cannot_read_is_refused_in_one_line(default_run_20s):
    summary = default_run_20s.summary
    with pytest.raises(SummaryVersionError, match="older shakermill \\(summary schema 1\\).*no summary key 'impacts'"):
        summary_from_document(version_1(summary, impacts=None), None)
    with pytest.raises(SummaryVersionError, match="newer shakermill") as newer:
        summary_from_document(to_jsonable(summary.flat()), SCHEMA_VERSION + 1)
    assert not newer.value.older and "\n" not in str(newer.value)
    with pytest.raises(ValueError, match="no summary key 'impacts'"):
        summary_from_document(version_1(summary, impacts=None), SCHEMA_VERSION)


def make_version_1(folder: Path, **changes) -> None:
    path = folder / "summary.json"
    document = json.loads(path.read_text(encoding="utf-8"))
    del document["schema_version"]
    for key, value in changes.items():
        if value is None:
            document["summary"].pop(key)
        else:
            document["summary"][key] = value
    path.write_text(json.dumps(document), encoding="utf-8")


@pytest.mark.slow
@pytest.mark.parametrize("command", ["plot", "report"])
def test_plot_and_report_read_an_old_run_folder_or_refuse_it_in_one_line(command, default_run_20s, tmp_path):
    runner = CliRunner()
    readable = write_run(default_run_20s, tmp_path / "old", preset="spex8000m")
    make_version_1(readable, exponential_fit_describes_run=None, stress_window_s=None)
    outcome = runner.invoke(cli.app, [command, str(readable)])
    assert outcome.exit_code == 0, outcome.stderr
    refused = write_run(default_run_20s, tmp_path / "older", preset="spex8000m")
    make_version_1(refused, impacts=None)
    outcome = runner.invoke(cli.app, [command, str(refused)])
    assert outcome.exit_code != 0
    assert_one_error_line(outcome.stderr, str(refused), "summary schema 1", "re-run it", "shakermill run")
