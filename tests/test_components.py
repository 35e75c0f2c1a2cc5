"""A new component touches its own code, its key group and at most one registration line (issue 48).

A made-up lid (a node of the thermal network with a heat-capacity key and a conductance read only with a lid) and a
made-up vial motion (an orbital shaker) are each added to a copy of the package as a real engineer would add them, and
the copy is compared with the package: which files are new, which lines changed. A fresh interpreter then runs the
copy: the new keys are read where they apply, refused where they do not (a lone impact and the 1-D engine included,
with no list edited), listed by `shakermill keys`, and cited in the paper's preset. The powder, a component already,
is named in its own code, its key group and its registration line alone."""

from __future__ import annotations

import ast
import difflib
import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "shakermill"

LID_MODULE = '''
"""A made-up lid on the vessel: joined to it, losing heat to the room."""

from shakermill.engines.thermal import kernel
from shakermill.engines.thermal.nodes import VESSEL, NetworkDraft, Node
from shakermill.engines.thermal.paths import fixed_conductance
from shakermill.parameters.groups.lid import LidKeys


def add_node(draft: NetworkDraft) -> None:
    lid = LidKeys.of(draft.params)
    if lid.lid_heat_capacity <= 0.0:
        return
    vial = draft.one_of_role(VESSEL)
    node = draft.add(Node("lid", "lid", lid.lid_heat_capacity, "lid", keys=("lid_heat_capacity",)))
    draft.paths += [
        fixed_conductance("vial → lid", vial, node, lid.lid_conductance, "a test's", "a test's"),
        fixed_conductance("lid → room", node, kernel.ROOM, 0.2, "a test's", "a test's"),
    ]
'''
LID_GROUP = '''
"""The made-up lid's keys."""

from shakermill.parameters.fields import quantity
from shakermill.parameters.key_group import NETWORK_NODE, KeyGroup, When


class LidKeys(KeyGroup):
    """A lid on the vessel: its heat capacity (0: no lid) and its joint to the vessel."""

    title = "the lid"
    rule = When("lid_heat_capacity", lambda capacity: capacity > 0, "a run without a lid does not read it")
    role = NETWORK_NODE

    lid_heat_capacity: float = quantity(
        "J/K", "heat capacity of the lid; 0: none", default=0.0, source="a test's lid", thermal_only=True, ge=0, le=1e4
    )
    lid_conductance: float = quantity(
        "W/K", "vessel-to-lid conductance", default=0.5, source="a test's lid", thermal_only=True, ge=0, le=1e3
    )
'''
ORBIT_MODULE = '''
"""A made-up orbital shaker: the vial's centre on a horizontal circle, the vial not turning."""

from shakermill.parameters.motions import KinematicModel, Term


def orbit_terms(orbit_radius: float) -> tuple[Term, ...]:
    return (("x", 1, orbit_radius, 0.0), ("y", 1, 0.0, orbit_radius))


MOTION = KinematicModel("orbital", "an orbital shaker", orbit_terms)
'''
ORBIT_GROUP = '''
"""The made-up orbital shaker's key."""

from shakermill.parameters.fields import quantity
from shakermill.parameters.key_group import BY_MOTION, VIAL_MOTION, KeyGroup


class OrbitKeys(KeyGroup):
    """The radius of the vial's circle."""

    title = "the orbit"
    rule = BY_MOTION
    role = VIAL_MOTION

    orbit_radius: float = quantity("m", "radius of the orbit", default=0.01, source="a test's orbit", gt=0, le=0.5)
'''

# What a fresh interpreter checks in a copy of the package, printing what it found as JSON.
CHECKS_PRELUDE = """
import json
import shakermill as sm
from shakermill.parameters.config import load_config
from shakermill.parameters.engine_keys import ENGINE_KEYS
from shakermill.parameters.errors import ParameterError

def refusal(**kwargs):
    try:
        load_config(**kwargs)
    except ParameterError as exc:
        return str(exc)
    return None
"""
LID_CHECKS = (
    CHECKS_PRELUDE
    + """
from shakermill.engines.thermal.network import build_network
from shakermill.parameters.presets import PRESETS

params = sm.default_parameters("spex8000m-3d", n_balls=2, lid_heat_capacity=40.0)
network = build_network(params, [params.ball_radius] * 2, [1.0] * 2, ["ball 0", "ball 1"], "a test's")
lid = next(node for node in network.nodes if node.name == "lid")
print(json.dumps({
    "capacity": lid.capacity,
    "paths": [path.name for path in network.paths if "lid" in path.name],
    "without": [node.name for node in build_network(sm.default_parameters("spex8000m-3d", n_balls=2),
                [params.ball_radius] * 2, [1.0] * 2, ["ball 0", "ball 1"], "a test's").nodes],
    "on_1d": refusal(overrides=["lid_heat_capacity=40"]),
    "without_lid": refusal(preset="spex8000m-3d", overrides=["lid_conductance=1"]),
    "with_lid": refusal(preset="spex8000m-3d", overrides=["lid_heat_capacity=40", "lid_conductance=1"]),
    "source": PRESETS["spex8000m"].values["lid_heat_capacity"].source,
    "thermal_only": "lid_heat_capacity" in ENGINE_KEYS["dem"].thermal_only_keys,
}))
"""
)
ORBIT_CHECKS = (
    CHECKS_PRELUDE
    + """
from shakermill.parameters.kinematic_models import motion_terms

params = sm.default_parameters("spex8000m-3d", kinematics="orbital", orbit_radius=0.02)
print(json.dumps({
    "terms": motion_terms("orbital", params),
    "dem_reads": "orbit_radius" in ENGINE_KEYS["dem"].reads and "orbital" in ENGINE_KEYS["dem"].kinematics,
    "on_spex": refusal(preset="spex8000m-3d", overrides=["orbit_radius=0.02"]),
    "on_orbit": refusal(preset="spex8000m-3d", overrides=["kinematics=orbital", "orbit_radius=0.02"]),
    "on_1d": refusal(overrides=["orbit_radius=0.02"]),
}))
"""
)


def copy_with(tmp_path: Path, new_files: dict[str, str], edit: tuple[str, str, str] | None = None) -> Path:
    """A copy of the package under ``tmp_path/src`` with ``new_files`` (path: text) written and, where given, one
    replacement (file, old, new) made in a file: what an engineer adds for a new component."""
    copied = tmp_path / "src" / "shakermill"
    shutil.copytree(SRC, copied, ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
    for relative, text in new_files.items():
        (copied / relative).write_text(textwrap.dedent(text).lstrip(), encoding="utf-8")
    if edit is not None:
        relative, old, new = edit
        path = copied / relative
        source = path.read_text(encoding="utf-8")
        assert source.count(old) == 1, old
        path.write_text(source.replace(old, new), encoding="utf-8")
    return copied


def touched(copied: Path) -> tuple[set[str], dict[str, int]]:
    """The files of ``copied`` the package lacks, and for each file both hold, how many of its lines differ."""
    names = {str(path.relative_to(copied)) for path in copied.rglob("*.py")}
    ours = {str(path.relative_to(SRC)) for path in SRC.rglob("*.py")}
    changed = {}
    for name in names & ours:
        before = (SRC / name).read_text(encoding="utf-8").splitlines()
        after = (copied / name).read_text(encoding="utf-8").splitlines()
        lines = sum(1 for line in difflib.ndiff(before, after) if line[:1] == "+")
        if lines:
            changed[name] = lines
    return names - ours, changed


def run_in(copied: Path, *args: str) -> subprocess.CompletedProcess[str]:
    environment = {**os.environ, "PYTHONPATH": str(copied.parent), "NUMBA_CACHE_DIR": str(copied.parent / "cache")}
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, env=environment, timeout=300)


def checked(copied: Path, script: str) -> dict:
    completed = run_in(copied, "-c", script)
    assert completed.returncode == 0, completed.stderr
    return json.loads(completed.stdout.splitlines()[-1])


def one_error_line(copied: Path, *command: str) -> str:
    completed = run_in(copied, "-m", "shakermill.cli", *command)
    assert completed.returncode == 2, (completed.stdout, completed.stderr)
    (line,) = completed.stderr.strip().splitlines()
    return line


@pytest.mark.slow
def test_a_new_node_with_keys_is_its_module_its_key_group_and_one_registration_line(tmp_path):
    copied = copy_with(
        tmp_path,
        {"engines/thermal/lid.py": LID_MODULE, "parameters/groups/lid.py": LID_GROUP},
        ("engines/thermal/network.py", '("mill_head", "powder")', '("mill_head", "powder", "lid")'),
    )
    added, changed = touched(copied)
    assert added == {"engines/thermal/lid.py", "parameters/groups/lid.py"}
    assert changed == {"engines/thermal/network.py": 1}
    found = checked(copied, LID_CHECKS)
    assert found["capacity"] == 40.0 and found["paths"] == ["vial → lid", "lid → room"]
    assert "lid" not in found["without"]
    assert found["on_1d"] == (
        "lid_heat_capacity: set explicitly, but the 1-D engine (engine = '1d') does not read it; it applies to "
        "engine = 'dem'"
    )
    assert found["without_lid"] == "lid_conductance: set explicitly, but a run without a lid does not read it"
    assert found["with_lid"] is None
    assert found["source"] == "a test's lid" and found["thermal_only"]
    # A lone impact refuses the new keys, and the keys command lists them under their component, no list edited.
    refused = one_error_line(copied, "impact", "--speed", "1", "--set", "lid_heat_capacity=40")
    assert refused.startswith("error: lid_heat_capacity: a lone impact does not read it") and "the lid" in refused
    listed = run_in(copied, "-m", "shakermill.cli", "keys", "lid")
    assert listed.returncode == 0 and "the lid" in listed.stdout and "lid_conductance" in listed.stdout


@pytest.mark.slow
def test_a_new_rigid_vial_motion_is_its_module_and_its_key_group(tmp_path):
    copied = copy_with(
        tmp_path, {"parameters/motions/orbital.py": ORBIT_MODULE, "parameters/groups/orbit.py": ORBIT_GROUP}
    )
    added, changed = touched(copied)
    assert added == {"parameters/motions/orbital.py", "parameters/groups/orbit.py"} and changed == {}
    found = checked(copied, ORBIT_CHECKS)
    assert found["terms"] == [["x", 1, 0.02, 0.0], ["y", 1, 0.0, 0.02]] and found["dem_reads"]
    assert found["on_spex"] == (
        "orbit_radius: set explicitly, but kinematics = 'spex8000m' does not read it; it applies to kinematics = "
        "'orbital'"
    )
    assert found["on_orbit"] is None and "the 1-D engine" in found["on_1d"]
    assert one_error_line(copied, "impact", "--speed", "1", "--set", "orbit_radius=0.02").startswith(
        "error: orbit_radius: a lone impact does not read it"
    )


# The powder's own code: its node, and the study of it with its rows in `validate` and on the validation page.
POWDER_OWN = {
    "engines/thermal/powder.py",
    "studies/validation/powder.py",
    "studies/validation/report.py",
    "cli/validating.py",
    "views/validation_page.py",
}


def test_the_powder_is_named_in_its_own_code_its_key_group_and_its_registration_line_alone():
    naming = {
        str(path.relative_to(SRC)) for path in SRC.rglob("*.py") if names_in_code(path.read_text("utf-8"), "powder")
    }
    assert POWDER_OWN <= naming
    assert naming - POWDER_OWN == {"parameters/groups/powder.py", "engines/thermal/network.py"}
    network = (SRC / "engines/thermal/network.py").read_text(encoding="utf-8")
    (line,) = lines_naming(network, "powder")
    assert network.splitlines()[line - 1] == 'NODE_EXTENSIONS: tuple[str, ...] = ("mill_head", "powder")'


def test_a_vial_motion_is_named_in_its_module_and_its_key_group_alone():
    for key, own in (
        ("revolution_radius", {"parameters/motions/planetary.py", "parameters/groups/planetary.py"}),
        ("lateral_amplitude", {"parameters/motions/spex8000m.py", "parameters/groups/spex_clamp.py"}),
        ("swing_radius", {"parameters/motions/mixer_mill_arc.py", "parameters/groups/mixer_arc.py"}),
    ):
        naming = {
            str(path.relative_to(SRC)) for path in SRC.rglob("*.py") if names_in_code(path.read_text("utf-8"), key)
        }
        assert naming == own, key


def lines_naming(source: str, word: str) -> set[int]:
    """The lines on which ``word`` is in a name, an attribute, an argument, an import or a string of ``source`` that is
    not prose: a string that is a statement of its own (a docstring) or holds a space (a message, a source)."""
    tree = ast.parse(source)
    prose = {id(node.value) for node in ast.walk(tree) if isinstance(node, ast.Expr)}
    lines = set()
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
            lines.add(node.lineno)
    return lines


def names_in_code(source: str, word: str) -> bool:
    return bool(lines_naming(source, word))


def test_names_in_code_sees_code_and_not_prose() -> None:
    assert names_in_code("x = params.powder_mass", "powder")
    assert names_in_code("from a.powder import add", "powder")
    assert names_in_code("KEYS = ('powder_mass',)", "powder")
    assert not names_in_code('"""The powder."""\n# the powder\nx = "no powder here"', "powder")
