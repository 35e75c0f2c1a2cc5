"""Nodes as data (engines/thermal/nodes.py): the powder node against hand-computed values and the published
orderings of its sign, and a second, made-up node added by a test alone through ``NODE_EXTENSIONS``: a node reaches
the stepping, the audit, the history and the steady state without an edit anywhere else."""

from __future__ import annotations

import ast
import math
from pathlib import Path

import numpy as np
import pytest

import shakermill as sm
from shakermill.analysis.steady import steady_state
from shakermill.engines.dem import model
from shakermill.engines.dem.description import CHANNELS
from shakermill.engines.dem.engine import DemEngine
from shakermill.engines.thermal import kernel, network
from shakermill.engines.thermal.network import NetworkLoad, build_network
from shakermill.engines.thermal.nodes import BALL_BALL, BALL_WALL, CONTACT_KINDS, HEAT_CHANNELS, Deposit, Node
from shakermill.engines.thermal.paths import fixed_conductance
from shakermill.engines.thermal.powder import wall_area
from shakermill.parameters.errors import ParameterError
from shakermill.physics import contact
from shakermill.solvers.averaged import integrate_network

SRC = Path(__file__).resolve().parents[2] / "src" / "shakermill"
# Five balls in the SPEX vial, a fraction of a second: enough impacts of both kinds for the routing to show.
FIVE_BALLS = {"n_balls": 5, "duration": 0.3, "solver": "full", "record_windows": ()}


def five_balls(**overrides: object) -> sm.Parameters:
    return sm.default_parameters("spex8000m-3d", **{**FIVE_BALLS, **overrides})


def test_the_powder_node_has_the_hand_computed_capacity_paths_and_share() -> None:
    params = five_balls(powder_mass=0.004, powder_contact_coefficient=300.0, powder_heat_share=0.4)
    built = DemEngine.network_for(params)
    powder = built.index_of_role("powder")
    assert built.nodes[powder].capacity == pytest.approx(0.004 * params.powder_heat_capacity, rel=1e-12)
    assert params.powder_heat_capacity == 449.0  # iron, the preset's powder_material
    conductance = {path.name: path.conductance for path in built.paths}
    d, length, radius = params.vial_diameter, params.vial_length, params.ball_radius
    assert wall_area(d, length) == pytest.approx(math.pi * d * length + math.pi * d**2 / 2, rel=1e-12)
    assert conductance["powder → vial"] == pytest.approx(300.0 * wall_area(d, length), rel=1e-12)
    assert conductance["powder → ball 3"] == pytest.approx(300.0 * 4 * math.pi * radius**2, rel=1e-12)
    assert conductance["powder → air"] == pytest.approx(params.h_inner * params.inner_area, rel=1e-12)
    nodes, shares = built.deposit_arrays()
    assert nodes.tolist() == [powder] and np.all(shares == 0.4)
    # Of a wall contact's 1 J: 0.4 to the powder, λ of the rest to the ball, the remainder to the vial.
    into = built.wall_contact_heat(1.0)
    assert into[powder] == pytest.approx(0.4) and into[0] == pytest.approx(0.6 * params.lam)
    assert into[built.vial] == pytest.approx(0.6 * (1 - params.lam)) and into.sum() == pytest.approx(1.0)


def test_without_powder_there_is_no_node_and_coated_contacts_keep_their_restitution() -> None:
    bare = five_balls()
    assert "powder" not in [node.role for node in DemEngine.network_for(bare).nodes]
    assert model.constants_from(bare).beta_e == contact.damping_ratio(bare.restitution)
    coated = five_balls(powder_mass=0.004, powder_restitution=0.45)
    k = model.constants_from(coated)
    assert k.beta_e == k.pair_beta_e == contact.damping_ratio(0.45)


def test_a_mill_with_powder_warms_its_vessel_more_at_the_same_heat() -> None:
    """The published orderings as the network's sign: the same contact heat into a mill with powder leaves its vial
    warmer after half an hour (El-Eskandarany's P5: ≈ +20 K against ≈ +10 K), the balls storing less of it, and the
    heat deposited in the powder reaches the vial. (At steady state the vial is where it was: in the paper's network
    all heat leaves through it.)"""
    heat = 10.0  # W of contact heat, all of it on the walls, each ball's share alike
    ends, steadies = {}, {}
    for mass in (0.0, 0.004):
        params = five_balls(powder_mass=mass, duration=1800.0, output_interval=60.0)
        built = DemEngine.network_for(params)
        into = built.wall_contact_heat(heat)
        into[: params.n_balls] = into[0] / params.n_balls
        load = NetworkLoad(into, np.ones(params.n_balls), heat, 1.0, np.zeros(2 * params.n_balls))
        ends[mass] = integrate_network(built, load, params).y[:-1, -1]
        steadies[mass] = (built, steady_state(built, load))
    vial = DemEngine.network_for(five_balls()).vial
    assert ends[0.004][vial] > ends[0.0][vial] + 1.0
    assert ends[0.004][:5].mean() < ends[0.0][:5].mean()
    coated_network, coated = steadies[0.004]
    assert coated.solved and coated.vial == pytest.approx(steadies[0.0][1].vial, rel=1e-9)
    theta = np.array([*coated.balls, coated.vial, coated.air, dict(coated.others)["powder"]])
    flows = coated_network.flows(theta, np.concatenate([np.ones(5), np.zeros(10)]))
    by_name = dict(zip((path.name for path in coated_network.paths), flows, strict=True))
    assert by_name["powder → vial"] > 0.0  # the powder's heat reaches the vessel


@pytest.mark.slow
def test_powder_takes_its_share_of_every_contact_heat_and_the_audit_closes() -> None:
    result = sm.simulate(five_balls(powder_mass=0.004, powder_heat_share=0.3))
    audit = result.energy
    assert result.success, result.message
    assert audit.relative_residual < 1e-9
    assert audit.heat_into["powder"] == pytest.approx(0.3 * audit.heat_generated, rel=1e-9)
    assert sum(audit.heat_into.values()) == pytest.approx(audit.heat_generated, rel=1e-12)
    columns = result.impact_columns
    assert np.sum(columns["heat_to_deposits"]) == pytest.approx(0.3 * np.sum(columns["heat_generated"]), rel=1e-9)
    assert "theta_powder" in result.history.variables


LID_SHARE = 0.1


def add_lid(draft: network.NetworkDraft) -> None:
    """A made-up node: a lid on the vessel, joined to it and losing heat to the room, taking a share of the heat of
    the balls' contacts with the wall (as if a sensor sat in the contact)."""
    vial = draft.one_of_role("vessel")
    lid = draft.add(Node("lid", "lid", 40.0, "lid"))
    draft.paths += [
        fixed_conductance("vial → lid", vial, lid, 0.5, "a test's", "a test's"),
        fixed_conductance("lid → room", lid, kernel.ROOM, 0.2, "a test's", "a test's"),
    ]
    draft.deposits.append(Deposit(lid, {BALL_WALL: dict.fromkeys(HEAT_CHANNELS, LID_SHARE)}, "a test's"))


@pytest.fixture(name="lid")
def lid_fixture(monkeypatch):
    monkeypatch.setattr(network, "NODE_EXTENSIONS", [*network.NODE_EXTENSIONS, add_lid])


@pytest.mark.slow
def test_a_node_added_by_a_test_alone_is_stepped_audited_recorded_and_solved(lid) -> None:
    result = sm.simulate(five_balls())
    assert result.success, result.message
    audit = result.energy
    assert audit.relative_residual < 1e-9 and audit.stored["lid"] > 0.0
    columns = result.impact_columns
    walls = columns["target"] != "ball"
    # The lid's share of the wall contacts that ended, none of the pairs'.
    assert np.sum(columns["heat_to_deposits"][~walls]) == 0.0
    assert np.sum(columns["heat_to_deposits"][walls]) == pytest.approx(
        LID_SHARE * np.sum(columns["heat_generated"][walls]), rel=1e-9
    )
    assert audit.heat_into["lid"] >= np.sum(columns["heat_to_deposits"])
    assert result.history["theta_lid"][-1] > result.params.initial_temperature
    assert "lid" in dict(result.steady.others)


def test_the_extensions_are_listed_once_and_the_kinds_and_channels_are_those_the_stepping_books() -> None:
    assert CONTACT_KINDS == (BALL_WALL, BALL_BALL)
    assert HEAT_CHANNELS == CHANNELS
    assert len(network.NODE_EXTENSIONS) == len(set(network.NODE_EXTENSIONS))
    params = five_balls(powder_mass=0.004, thermal_model="mill-head")
    built = build_network(params, [params.ball_radius] * 5, [1.0] * 5, [f"ball {i}" for i in range(5)], "a test's")
    assert [node.role for node in built.nodes[5:]] == ["vessel", "gas", "holder", "powder"]


# The files outside the powder's own code whose code names it (comments and docstrings aside): its keys, its default
# values with their sources, the keys the engines read, the keys a lone impact does not (its heat), its place among
# the extensions (and materials.toml, data, its material). A new file here means the powder has leaked into code that
# should loop over the nodes.
POWDER_FILES = {
    "solvers/impact.py",
    "parameters/keys.py",
    "parameters/presets.py",
    "parameters/engine_keys.py",
    "engines/thermal/network.py",
}
# Its own code: the node, and the study of it with its rows in `validate` and on the validation page.
POWDER_OWN = {
    "engines/thermal/powder.py",
    "studies/validation/powder.py",
    "studies/validation/report.py",
    "cli/validating.py",
    "views/validation_page.py",
}


def names_in_code(source: str, word: str) -> bool:
    """Whether ``word`` is in a name, an attribute, an argument, an import or a string of ``source`` that is not
    prose."""
    tree = ast.parse(source)
    # Prose: a string that is a statement of its own (a docstring) or holds a space (a message, a source).
    prose = {id(node.value) for node in ast.walk(tree) if isinstance(node, ast.Expr)}
    for node in ast.walk(tree):
        text = (
            node.id
            if isinstance(node, ast.Name)
            else node.attr
            if isinstance(node, ast.Attribute)
            else node.arg
            if isinstance(node, ast.arg)
            else node.value
            if isinstance(node, ast.Constant)
            and isinstance(node.value, str)
            and id(node) not in prose
            and " " not in node.value
            else " ".join([node.module or "", *(alias.name for alias in node.names)])
            if isinstance(node, ast.ImportFrom)
            else ""
        )
        if word in text.lower():
            return True
    return False


def test_names_in_code_sees_code_and_not_prose() -> None:
    assert names_in_code("x = params.powder_mass", "powder")
    assert names_in_code("from a.powder import add", "powder")
    assert names_in_code("KEYS = ('powder_mass',)", "powder")
    assert not names_in_code('"""The powder."""\n# the powder\nx = "no powder here"', "powder")


def test_the_powder_is_named_in_its_own_code_and_a_few_declared_places_only() -> None:
    naming = {
        str(path.relative_to(SRC))
        for path in SRC.rglob("*.py")
        if names_in_code(path.read_text(encoding="utf-8"), "powder")
    }
    assert POWDER_OWN <= naming
    assert naming - POWDER_OWN == POWDER_FILES


def test_a_powder_too_light_to_step_is_refused_naming_its_keys() -> None:
    with pytest.raises(ParameterError, match=r"^powder_mass, powder_heat_capacity, powder_contact_coefficient: the "):
        DemEngine(five_balls(powder_mass=1e-6, duration=0.01))


def test_a_load_measured_on_one_network_moves_onto_another_by_the_nodes_names() -> None:
    """Runs that differ in thermal-only keys share one measured mechanics: a mill head adds its holder before the
    powder, so the powder's heat must follow the powder, not its index."""
    paper = DemEngine.network_for(five_balls(powder_mass=0.004))
    mill_head = DemEngine.network_for(five_balls(powder_mass=0.004, thermal_model="mill-head"))
    heat = np.arange(1.0, len(paper.nodes) + 1.0)
    load = NetworkLoad(heat, np.ones(5), float(heat.sum()), 1.0)
    moved = load.moved(paper, mill_head)
    by_name = dict(zip((node.name for node in mill_head.nodes), moved.heat, strict=True))
    assert by_name["powder"] == heat[-1] and by_name["holder"] == 0.0 and by_name["vial"] == heat[paper.vial]
    assert load.moved(paper, paper) is load
