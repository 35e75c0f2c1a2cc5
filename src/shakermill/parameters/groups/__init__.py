"""Every key group of a run (:mod:`shakermill.parameters.key_group`), one module per component.

The core groups, below, are the keys every layer reads as attributes of ``Parameters`` (``params.omega``): they are
the bases of :class:`CoreKeys`, and whoever reads one names it (an engine's ``reads``, a lone impact's). Every other
group in this folder is a component's (a node of the thermal network, a coating of the contacts, a vial motion): it is
found here by itself (:data:`COMPONENTS`), says what it is (``role``), and its own code reads it through the group
(``PowderHeat.of(params).powder_heat_share``). A new component's keys are a module here and nothing else.
"""

from __future__ import annotations

import importlib
import pkgutil
from typing import Any

from shakermill.parameters.groups.balls import Balls, OneBallStart, SeveralBalls
from shakermill.parameters.groups.contacts import BallPairs, ContactDamping, DemContacts, VialWall
from shakermill.parameters.groups.dem import DemAveraging, DemStepping, EnduringContacts, LabFrame, WhatAnImpactIs
from shakermill.parameters.groups.geometry import Drive, Stroke, Vial
from shakermill.parameters.groups.one_d import OneDAveraging, OneDIntegrator
from shakermill.parameters.groups.paper_network import ContactHeat, HeatSplit, NetworkChoice, PaperNetwork, RoomLoss
from shakermill.parameters.groups.run import AveragedSolver, RunControl
from shakermill.parameters.key_group import KeyGroup


# The core groups, last first: pydantic gathers fields from the last base first, so that they are listed in the order
# of CORE below.
class CoreKeys(
    WhatAnImpactIs,
    DemAveraging,
    EnduringContacts,
    DemStepping,
    LabFrame,
    HeatSplit,
    BallPairs,
    DemContacts,
    SeveralBalls,
    OneDAveraging,
    OneDIntegrator,
    NetworkChoice,
    RoomLoss,
    PaperNetwork,
    ContactHeat,
    ContactDamping,
    VialWall,
    OneBallStart,
    Balls,
    Stroke,
    Drive,
    Vial,
    AveragedSolver,
    RunControl,
):
    """The core groups' keys, typed: what every layer reads as an attribute of ``Parameters``."""


# In the order `shakermill keys` lists them.
CORE: tuple[type[KeyGroup], ...] = tuple(reversed(CoreKeys.__bases__))


def _in_this_folder() -> tuple[type[KeyGroup], ...]:
    """Every group its modules declare, module by module in the order of their names, each in its module's order."""
    found: list[type[KeyGroup]] = []
    for module_info in pkgutil.iter_modules(__path__):
        module = importlib.import_module(f"{__name__}.{module_info.name}")
        found += [
            value
            for value in vars(module).values()
            if isinstance(value, type) and issubclass(value, KeyGroup) and value.__module__ == module.__name__
        ]
    return tuple(found)


# The components' groups: every group of this folder that is not core.
COMPONENTS: tuple[type[KeyGroup], ...] = tuple(group for group in _in_this_folder() if group not in CORE)
GROUPS: tuple[type[KeyGroup], ...] = (*CORE, *COMPONENTS)
GROUP_OF: dict[str, type[KeyGroup]] = {key: group for group in GROUPS for key in group.keys()}
if len(GROUP_OF) != sum(len(group.keys()) for group in GROUPS):
    raise ValueError("a key is declared by two groups: each key belongs to one component")


def marked(key: str, mark: str) -> Any:
    """What ``key``'s field says of ``mark`` (parameters/fields.py: unit, description, source, per_ball, material,
    thermal_only), or None."""
    extra = GROUP_OF[key].model_fields[key].json_schema_extra
    return extra.get(mark) if isinstance(extra, dict) else None


def default_of(key: str) -> Any:
    """``key``'s default: the value of the paper's preset (parameters/presets.py), cited by its field's source."""
    return GROUP_OF[key].model_fields[key].default


def keys_of(*groups: type[KeyGroup]) -> frozenset[str]:
    """The keys of ``groups``."""
    return frozenset(key for group in groups for key in group.keys())


def keys_of_role(role: str) -> frozenset[str]:
    """The keys of every component group of ``role``."""
    return keys_of(*(group for group in GROUPS if group.role == role))
