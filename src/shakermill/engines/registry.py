"""The engines by name (the key ``engine``): the built-in ones, imported when first asked for, and any registered
with :func:`register`. Everything above the engines reaches an engine through here, never by its module."""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING

from shakermill.parameters.engine_keys import BUILT_IN, ENGINE_KEYS, declare, undeclare

if TYPE_CHECKING:
    from shakermill.engines.interface import Engine, EngineDescription

# Where each built-in engine lives: its description's module, and its class's module and name. Imported when a
# run first needs them, so that the compiled code loads only with the engine that runs.
_BUILT_IN_MODULES = {
    "1d": ("shakermill.engines.one_d.description", "shakermill.engines.one_d.engine", "OneDimensionalEngine"),
    "dem": ("shakermill.engines.dem.description", "shakermill.engines.dem.engine", "DemEngine"),
}
_REGISTERED: dict[str, type[Engine]] = {}


def register(engine: type[Engine]) -> None:
    """Make ``engine`` (a class implementing :class:`~shakermill.engines.interface.Engine`) the one that runs
    ``engine = <its name>``: parameters accept the name, and simulate, the files, the figures and the command
    line run and read it through its description. A built-in engine's name cannot be taken."""
    name = engine.description.name
    if name in BUILT_IN:
        raise ValueError(f"engine {name!r} is built in")
    declare(engine.description.keys)
    _REGISTERED[name] = engine


def unregister(name: str) -> None:
    """Take a registered engine out again (one registered for a while: a test, a notebook)."""
    undeclare(name)
    del _REGISTERED[name]


def engine_names() -> tuple[str, ...]:
    """Every engine's name: the built-in ones and those registered."""
    return tuple(ENGINE_KEYS)


def _built_in(name: str) -> tuple[str, str, str]:
    if name not in _BUILT_IN_MODULES:
        raise KeyError(f"no engine is named {name!r}; known: {', '.join(map(repr, ENGINE_KEYS))}")
    return _BUILT_IN_MODULES[name]


def engine_named(name: str) -> type[Engine]:
    """The engine class of ``name``; KeyError for a name no engine has."""
    if name in _REGISTERED:
        return _REGISTERED[name]
    _, module, class_name = _built_in(name)
    return getattr(import_module(module), class_name)


def describe(name: str) -> EngineDescription:
    """The description of engine ``name``, without loading its compiled code."""
    if name in _REGISTERED:
        return _REGISTERED[name].description
    module, _, _ = _built_in(name)
    return import_module(module).DESCRIPTION
