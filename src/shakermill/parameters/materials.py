"""The materials library: milling media with every value's unit and source, read from ``materials.toml``.

A material stands for the elastic and thermal keys of a ball or a vial (:data:`FILLED`): the keys
``ball_material``, ``vial_material`` and, per ball, ``ball_materials`` fill them in
(:func:`shakermill.parameters.schema.with_materials`). Its restitution and friction are ranges for a ball
on the same material and are only shown: both belong to a pair of surfaces, vary with the impact speed,
and the presets' ``restitution`` and ``friction`` are calibrated, so a material never changes them.
"""

from __future__ import annotations

import functools
import tomllib
from dataclasses import dataclass
from pathlib import Path

from shakermill.support.limits import quoted

LIBRARY_FILE = Path(__file__).parent / "materials.toml"

# Each property's SI unit, as the library file must write it, and what it is.
PROPERTIES: dict[str, tuple[str, str]] = {
    "density": ("kg/m^3", "density ρ"),
    "youngs_modulus": ("Pa", "Young's modulus E"),
    "poisson_ratio": ("", "Poisson ratio ν"),
    "heat_capacity": ("J/(kg*K)", "specific heat c"),
    "conductivity": ("W/(m*K)", "thermal conductivity k"),
    "restitution": ("", "restitution e on the same material (shown, not applied)"),
    "friction": ("", "friction μ on the same material (shown, not applied)"),
}
# The properties a material fills in: ``ball_<property>`` and ``vial_<property>`` where such a key exists.
FILLED = ("density", "youngs_modulus", "poisson_ratio", "heat_capacity", "conductivity")
RANGES = ("restitution", "friction")


class UnknownMaterial(ValueError):
    """A name that is no material of the library; the message lists the allowed names."""


@dataclass(frozen=True)
class Sourced:
    """One property of a material in SI: a number, or a (low, high) range, with its unit and source."""

    value: float | tuple[float, float]
    unit: str
    source: str


@dataclass(frozen=True)
class Material:
    """A milling medium at room temperature (SI units, see :data:`PROPERTIES`)."""

    name: str
    description: str
    aliases: tuple[str, ...]
    density: Sourced
    youngs_modulus: Sourced
    poisson_ratio: Sourced
    heat_capacity: Sourced
    conductivity: Sourced
    restitution: Sourced
    friction: Sourced

    def properties(self) -> dict[str, Sourced]:
        return {name: getattr(self, name) for name in PROPERTIES}

    def as_dict(self) -> dict[str, object]:
        """JSON-ready: name, description, aliases and every property as {value, unit, source} (SI)."""
        described: dict[str, object] = {"name": self.name, "description": self.description, "aliases": list(self.aliases)}
        for key, sourced in self.properties().items():
            value = list(sourced.value) if isinstance(sourced.value, tuple) else sourced.value
            described[key] = {"value": value, "unit": sourced.unit, "source": sourced.source}
        return described


@functools.cache
def library() -> dict[str, Material]:
    """Every material of ``materials.toml`` by name, in the file's order (read once)."""
    with LIBRARY_FILE.open("rb") as handle:
        document = tomllib.load(handle)
    return {name: _material(name, entry) for name, entry in document.items()}


def _material(name: str, entry: dict) -> Material:
    properties = {key: _sourced(name, key, entry.get(key)) for key in PROPERTIES}
    extra = set(entry) - set(PROPERTIES) - {"description", "aliases"}
    if extra:
        raise ValueError(f"{LIBRARY_FILE.name}: [{name}] has unknown entries {sorted(extra)}")
    return Material(name, str(entry["description"]), tuple(entry.get("aliases", ())), **properties)


def _sourced(name: str, key: str, entry: dict | None) -> Sourced:
    """One property, checked: the library file is data, and a slip in it must not reach a run."""
    unit = PROPERTIES[key][0]
    where = f"{LIBRARY_FILE.name}: [{name}] {key}"
    if entry is None or entry.get("unit") != unit or not str(entry.get("source", "")).strip():
        raise ValueError(f"{where}: needs a value, unit = {unit!r} and a source")
    value = entry["value"]
    if key in RANGES:
        low, high = value
        if not 0 <= low <= high:
            raise ValueError(f"{where}: expected a range [low, high], got {value}")
        return Sourced((float(low), float(high)), unit, entry["source"])
    return Sourced(float(value), unit, entry["source"])


def names() -> tuple[str, ...]:
    return tuple(library())


@functools.cache
def _aliases() -> dict[str, str]:
    return {alias: material.name for material in library().values() for alias in material.aliases}


def material(name: str) -> Material:
    """The material ``name`` or one of its aliases (case and surrounding space ignored)."""
    given = str(name).strip()
    wanted = given.lower()
    found = library().get(_aliases().get(wanted, wanted))
    if found is None:
        raise UnknownMaterial(f"unknown material {quoted(given)}; allowed {allowed_names()}")
    return found


def allowed_names() -> str:
    aliases = ", ".join(f"{alias} = {canonical}" for alias, canonical in _aliases().items())
    return f"one of {', '.join(names())} (aliases: {aliases})"

