"""The engines by name (the key ``engine``): the built-in ones, imported when first asked for, and any registered
with :func:`register`. Everything above the engines reaches an engine through here, never by its module."""

from __future__ import annotations

from typing import TYPE_CHECKING

from shakermill.parameters.engine_keys import ENGINE_KEYS, declare, undeclare

if TYPE_CHECKING:
    from shakermill.engines.interface import Engine, EngineDescription

_REGISTERED: dict[str, type[Engine]] = {}


def register(engine: type[Engine]) -> None:
    """Make ``engine`` (a class implementing :class:`~shakermill.engines.interface.Engine`) the one that runs
    ``engine = <its name>``: parameters accept the name, and simulate, the files, the figures and the command
    line run and read it through its description."""
    declare(engine.description.keys)
    _REGISTERED[engine.description.name] = engine


def unregister(name: str) -> None:
    """Take a registered engine out again (one registered for a while: a test, a notebook)."""
    del _REGISTERED[name]
    undeclare(name)


def engine_names() -> tuple[str, ...]:
    """Every engine's name: the built-in ones and those registered."""
    return tuple(ENGINE_KEYS)


def engine_named(name: str) -> type[Engine]:
    """The engine class of ``name``; KeyError for a name no engine has."""
    if name in _REGISTERED:
        return _REGISTERED[name]
    # Imported here, when a run first needs it: the compiled code loads with it.
    if name == "1d":
        from shakermill.engines.one_d.engine import OneDimensionalEngine

        return OneDimensionalEngine
    if name == "dem":
        from shakermill.engines.dem.engine import DemEngine

        return DemEngine
    raise KeyError(f"no engine is named {name!r}; known: {', '.join(map(repr, ENGINE_KEYS))}")


def describe(name: str) -> EngineDescription:
    """The description of engine ``name``, without loading its compiled code."""
    if name in _REGISTERED:
        return _REGISTERED[name].description
    if name == "1d":
        from shakermill.engines.one_d.description import DESCRIPTION

        return DESCRIPTION
    if name == "dem":
        from shakermill.engines.dem.description import DESCRIPTION

        return DESCRIPTION
    raise KeyError(f"no engine is named {name!r}; known: {', '.join(map(repr, ENGINE_KEYS))}")
