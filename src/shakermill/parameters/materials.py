"""The materials library: milling media with every value's unit and source, read from ``materials.toml``.

A material stands for the elastic and thermal keys of a ball or a vial (:data:`FILLED`): the keys
``ball_material``, ``vial_material`` and, per ball, ``ball_materials`` fill them in
(:func:`shakermill.parameters.keys.with_materials`). Its restitution and friction are ranges for a ball
on the same material and are only shown: both belong to a pair of surfaces, vary with the impact speed,
and the presets' ``restitution`` and ``friction`` are calibrated, so a material never changes them.
"""

from __future__ import annotations

import functools
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from shakermill.parameters.errors import ParameterError
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
    "melting_point": ("K", "melting point T_m (onset, 1 atm), where known"),
}
# The properties a material fills in: ``ball_<property>`` and ``vial_<property>`` where such a key exists.
FILLED = ("density", "youngs_modulus", "poisson_ratio", "heat_capacity", "conductivity")
RANGES = ("restitution", "friction")
# Properties a material may lack: a ceramic that decomposes before it melts, or a value no source was found for.
OPTIONAL = ("melting_point",)


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
    melting_point: Sourced | None = None

    def properties(self) -> dict[str, Sourced]:
        """Every property the material has (an optional one it lacks is left out)."""
        return {name: getattr(self, name) for name in PROPERTIES if getattr(self, name) is not None}

    def as_dict(self) -> dict[str, object]:
        """JSON-ready: name, description, aliases and every property as {value, unit, source} (SI)."""
        described: dict[str, object] = {
            "name": self.name,
            "description": self.description,
            "aliases": list(self.aliases),
        }
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
    properties = {key: _sourced(name, key, entry.get(key)) for key in PROPERTIES if key not in OPTIONAL or key in entry}
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


def allowed_for(key: str) -> str:
    """The values ``key`` takes: one name (``ball_material``, ``vial_material``) or a list of them
    (``ball_materials``)."""
    return (
        f"an empty list or n_balls names, each {allowed_names()}"
        if key == "ball_materials"
        else f"'' (none) or {allowed_names()}"
    )


def name_in(key: str, value: Any) -> str:
    """The canonical material name of a name or alias of a key naming one material ('' or None: none)."""
    return "" if value is None or not str(value).strip() else _named(key, value)


def names_in(key: str, value: Any) -> str | tuple[str, ...]:
    """Canonical material names from a name or alias ('' or None: none), or for ``ball_materials`` from
    "wc, zirconia" (the command line) or a list (TOML, Python); :class:`ParameterError` naming ``key`` otherwise."""
    if key != "ball_materials":
        return name_in(key, value)
    items = [item for item in value.split(",") if item.strip()] if isinstance(value, str) else value
    if not isinstance(items, (list, tuple)):
        raise ParameterError(
            f"{key}: expected a list of material names, one per ball, got {quoted(value)}; allowed {allowed_for(key)}"
        )
    return tuple(_named(key, item) for item in items)


def _named(key: str, name: Any) -> str:
    try:
        return material(name).name
    except UnknownMaterial as exc:
        raise ParameterError(f"{key}: {exc}") from None


def filled_keys(
    layer: Mapping[str, Any], keys: Sequence[str], per_ball_key_of: Mapping[str, str], material_keys: Sequence[str]
) -> dict[str, tuple[Any, str]]:
    """The ``keys`` that the materials named in ``layer`` fill in, each with the material's value and source: the
    properties of what each of ``material_keys`` names (``ball_material`` fills ``ball_density``, ...), each ball's
    per-ball list (``ball_materials``, its list key by ``per_ball_key_of``)."""
    filled: dict[str, tuple[Any, str]] = {}
    for key in material_keys:
        prefix = key.removesuffix("material")
        name = name_in(key, layer.get(key, ""))
        if name:
            found = material(name)
            for prop in FILLED:
                if prefix + prop in keys:
                    value = getattr(found, prop)
                    filled[prefix + prop] = (value.value, f"material {name}: {value.source}")
    per_ball = [material(name) for name in names_in("ball_materials", layer.get("ball_materials", ()))]
    for prop in FILLED if per_ball else ():
        sources = dict.fromkeys(f"{found.name}: {getattr(found, prop).source}" for found in per_ball)
        values = tuple(getattr(found, prop).value for found in per_ball)
        filled[per_ball_key_of[f"ball_{prop}"]] = (values, f"ball_materials: {'; '.join(sources)}")
    return filled
