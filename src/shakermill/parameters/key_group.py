"""Key groups: the keys one component of a run reads (the run's control, the vial and its drive, the contact law, the
paper's network, the powder, a vial motion, ...), declared once as the fields of a :class:`KeyGroup` with their units,
bounds, meanings and cited defaults (:mod:`fields`), and the one rule for when a run reads them.

``Parameters`` gathers every group (``parameters/groups/``) with the flat names users type, and everything that says
who reads what is derived from the groups: each engine's keys (``engine_keys.reads_of``), the refusal of a key a run
would not read (``engine_keys.Reader``), the keys a lone impact reads, the preset of the paper's values
(``presets.SPEX_8000M``), ``shakermill keys`` and the documentation's table of keys.

A core group is named by whoever reads it (an engine, a lone impact); a component group says what it is
(:attr:`KeyGroup.role`: a node of the thermal network, a coating of the contacts, a vial motion) and whoever takes
components of that kind reads it, so that a new component is its code and its group.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, Self

from pydantic import BaseModel, ConfigDict

from shakermill.parameters.kinematic_models import KINEMATIC_MODELS

# The kinds of component group (:attr:`KeyGroup.role`). An engine that extends its thermal network with nodes
# (engines/thermal/network.py, NODE_EXTENSIONS) reads every NETWORK_NODE group; an engine or a lone impact whose
# contacts follow the 'dem' contact law reads every CONTACT_COATING group; an engine reads the VIAL_MOTION groups of
# the motions it moves the vial by.
NETWORK_NODE = "network node"
CONTACT_COATING = "contact coating"
VIAL_MOTION = "vial motion"


@dataclass(frozen=True)
class Always:
    """Every run of an engine that reads the group reads its keys."""

    @property
    def deciding(self) -> tuple[str, ...]:
        """The keys whose values decide whether a run reads the group."""
        return ()

    def refusal(self, key: str, run: Mapping[str, Any]) -> str | None:
        """Why a run with the deciding values ``run`` does not read ``key`` of the group (a phrase), or None."""
        return None

    def active(self, run: Mapping[str, Any]) -> bool:
        """Whether a run with the deciding values ``run`` reads the group (what it supersedes gives way)."""
        return True


@dataclass(frozen=True)
class When:
    """A run reads the group's keys where its value of ``key`` passes ``reads``; ``key`` itself, where it is the
    group's, is always read (it is what switches the others on). ``refused`` says why not, ``{value}`` the run's
    value."""

    key: str
    reads: Callable[[Any], bool]
    refused: str

    @property
    def deciding(self) -> tuple[str, ...]:
        return (self.key,)

    def refusal(self, key: str, run: Mapping[str, Any]) -> str | None:
        value = run[self.key]
        return None if key == self.key or self.reads(value) else self.refused.format(value=value)

    def active(self, run: Mapping[str, Any]) -> bool:
        return self.reads(run[self.key])


@dataclass(frozen=True)
class ByMotion:
    """A run reads a key where the vial motion it names (``kinematics``) takes it (its terms' arguments)."""

    @property
    def deciding(self) -> tuple[str, ...]:
        return ("kinematics",)

    def refusal(self, key: str, run: Mapping[str, Any]) -> str | None:
        kinematics = run["kinematics"]
        if key in KINEMATIC_MODELS[kinematics].keys:
            return None
        readers = " or ".join(repr(name) for name, model in KINEMATIC_MODELS.items() if key in model.keys)
        return f"kinematics = {kinematics!r} does not read it; it applies to kinematics = {readers}"

    def active(self, run: Mapping[str, Any]) -> bool:
        return True


ReadRule = Always | When | ByMotion
# The rules as the groups take them, typed as any rule: a group's class attribute is then a ReadRule to mypy whatever
# its rule, as the gathering of every group into one class needs.
ALWAYS: ReadRule = Always()
BY_MOTION: ReadRule = ByMotion()


def only_with_solver(solver: str) -> ReadRule:
    """The rule of a solver's own keys."""
    return When(
        "solver",
        lambda value: value == solver,
        f"the {{value!r}} solver does not read it; it applies to solver = {solver!r}",
    )


def only_with_network(network: str) -> ReadRule:
    """The rule of one thermal network's own keys (``thermal_model``)."""
    return When(
        "thermal_model",
        lambda value: value == network,
        f"the {{value!r}} network does not read it; it applies to thermal_model = {network!r}",
    )


class KeyGroup(BaseModel):
    """The keys of one component of a run, as pydantic fields (:mod:`fields`: unit, bounds, meaning, cited default),
    with the rule for when a run reads them. A group's class attributes say what it is; its fields are what
    ``Parameters`` gathers, and a component reads its own keys through its group (``PowderHeat.of(params)``)."""

    model_config = ConfigDict(frozen=True, extra="forbid", validate_default=True, allow_inf_nan=False)

    # What the keys are of, for `shakermill keys` and messages: "the powder's heat".
    title: ClassVar[str] = ""
    # When a run of an engine that reads the group reads its keys.
    rule: ClassVar[ReadRule] = ALWAYS
    # What kind of component the group is (NETWORK_NODE, CONTACT_COATING, VIAL_MOTION), read by whoever takes such
    # components; None for a core group, read by whoever names it.
    role: ClassVar[str | None] = None
    # Keys of other groups that a run reading this group does not read (the powder's coating replaces the bare
    # contacts' restitution), and why.
    supersedes: ClassVar[frozenset[str]] = frozenset()
    superseded_because: ClassVar[str] = ""

    @classmethod
    def check_across(cls, params: Any) -> None:
        """Refuse, with a ValueError naming the key, values of the group's keys that the rest of the run (``params``,
        every group's keys) makes impossible; a group with no such check has none."""

    @classmethod
    def keys(cls) -> tuple[str, ...]:
        """The group's keys, in the order it declares them."""
        return tuple(cls.model_fields)

    @classmethod
    def of(cls, params: object) -> Self:
        """``params`` (a ``Parameters``, which gathers every group) as this group: its keys typed for mypy."""
        if not isinstance(params, cls):
            raise TypeError(f"{type(params).__name__} does not hold the keys of {cls.__name__}")
        return params
