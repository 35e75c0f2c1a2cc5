"""The typed sections of a run's summary (issue 48): what each computation reports, built where it is computed, and
composed into :class:`~shakermill.solvers.summary.Summary` by the solvers.

A section is a frozen pydantic model: one field per number, in the unit its annotation names (``Celsius``: °C,
``PerSecond``: 1/s, ...; a bare ``float`` or ``int`` has none) and with its meaning as the field's docstring, so that
mypy checks every writer's names and types where it builds one, and pydantic checks the values a ``summary.json``
holds. A field's key in the flat summary (``summary.json``, ``run --json``, a sweep table's columns) is its name, or
the one a :class:`Key` in its annotation gives (``Annotated[Watts, Key("averaged_heat_power_W")]``: the averaging's
``heat_power_W``). A key with a ``{placeholder}`` names a *family*: a mapping by member whose flat keys follow the
pattern (``dissipated_{channel}_W``). The flat keys and their declarations are gathered in ``solvers/summary.py``,
the one module that reads a summary by a key's name.

The sections of the analyses are here and beside their computations (``fit.py``, ``steady.py``, ``stress_energy.py``,
``attractors.py``); the sections of the solvers and the studies in ``solvers/summary_sections.py``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Annotated, ClassVar

from pydantic import BaseModel, ConfigDict, Field

from shakermill.engines.thermal.nodes import NODE_NAME

# The thermal network's nodes renamed since version 1 of the summary: the clamp and mill head is the holder. An engine
# that still names the node so has its keys under the new name.
RENAMED_NODES = {"clamp": "holder"}


@dataclass(frozen=True)
class Unit:
    """The unit of a summary key, as its annotation carries it (``Annotated[float, Unit("°C")]``)."""

    symbol: str


@dataclass(frozen=True)
class Key:
    """A section field's key in the flat summary where it is not the field's name: ``pattern``, with a
    ``{placeholder}`` for a family's member (a mapping's key), whose names match ``member`` (a regular expression)."""

    pattern: str
    member: str = ".+"


Celsius = Annotated[float, Unit("°C")]
Kelvin = Annotated[float, Unit("K")]
Minutes = Annotated[float, Unit("min")]
Seconds = Annotated[float, Unit("s")]
Watts = Annotated[float, Unit("W")]
Joules = Annotated[float, Unit("J")]
PerSecond = Annotated[float, Unit("1/s")]
MetresPerSecond = Annotated[float, Unit("m/s")]
Millimetres = Annotated[float, Unit("mm")]
CelsiusPerMinute = Annotated[float, Unit("°C/min")]
RadiansPerSecond = Annotated[float, Unit("rad/s")]
Hertz = Annotated[float, Unit("Hz")]
PerMinute = Annotated[float, Unit("rpm")]


class Section(BaseModel):
    """One section of a run's summary: frozen, its fields declared with their units and meanings."""

    model_config = ConfigDict(frozen=True, extra="forbid", use_attribute_docstrings=True)

    @classmethod
    def key_of(cls, name: str) -> Key:
        """The flat key (or a family's pattern) of the field ``name``."""
        marked = [item for item in cls.model_fields[name].metadata if isinstance(item, Key)]
        return marked[0] if marked else Key(name)

    @classmethod
    def meaning_of(cls, name: str) -> str:
        """What the field ``name`` means, in one paragraph."""
        return " ".join((cls.model_fields[name].description or "").split())


class NodeTemperatures(Section):
    """A temperature of every node of the thermal network, by node: the ball, the vial and the air every network has,
    the holder of a ``mill-head`` network, and the further nodes an extension adds. A subclass names what the
    temperatures are (``node_meaning``) and their keys (``node_key``, ``{node}`` for the node's name)."""

    node_key: ClassVar[str]
    node_meaning: ClassVar[str]
    # The fields that hold one node each (their name the node's); ``others`` holds the further nodes by name.
    NAMED_NODES: ClassVar[tuple[str, ...]] = ("ball", "vial", "air", "holder")

    ball: Celsius
    """The ball (with several balls, their mean)"""
    vial: Celsius
    """The vial"""
    air: Celsius
    """The inner air"""
    holder: Celsius | None = None
    """The holder, where the network has one (``thermal_model = 'mill-head'``: the clamp and mill head; ``clamp`` in
    the keys of version 1)"""
    others: dict[str, Celsius] = Field(default_factory=dict)
    """Each further node of the thermal network, by its name (one word of lower-case letters): one an extension of
    ``engines/thermal/network.py`` adds, as the powder"""

    @classmethod
    def key_of(cls, name: str) -> Key:
        if name in cls.NAMED_NODES:
            return Key(cls.node_key.replace("{node}", name))
        if name == "others":
            return Key(cls.node_key, NODE_NAME)
        return super().key_of(name)

    @classmethod
    def meaning_of(cls, name: str) -> str:
        meaning = super().meaning_of(name)
        return f"{meaning}: {cls.node_meaning}" if name in (*cls.NAMED_NODES, "others") else meaning

    def by_node(self) -> dict[str, float]:
        """Every node's temperature (°C) by its name, the ball, the vial and the air first."""
        named = {"ball": self.ball, "vial": self.vial, "air": self.air, "holder": self.holder}
        return {**{node: value for node, value in named.items() if value is not None}, **self.others}


def node_key(node: str) -> str:
    """The name a thermal network's node has in the summary's keys (``holder`` for an engine's ``clamp``)."""
    return RENAMED_NODES.get(node, node)


def further_nodes(temperatures: Mapping[str, float]) -> tuple[float | None, dict[str, float]]:
    """Of the temperatures (°C) of the nodes beyond the ball, the vial and the air, by the network's names: the
    holder's (None without one) and the others' by their names in the summary's keys (:func:`node_key`)."""
    renamed = {node_key(node): value for node, value in temperatures.items()}
    return renamed.pop("holder", None), renamed
