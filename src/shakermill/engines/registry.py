"""The engines by name (the key ``engine``): the built-in ones, imported when first asked for, and any registered
with :func:`register`. Everything above the engines reaches an engine through here, never by its module."""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING

from shakermill.engines.interface import ENGINE_CORE, Replicas
from shakermill.parameters.engine_keys import BUILT_IN, ENGINE_KEYS, declare, undeclare
from shakermill.parameters.keys import FIELD_NAMES

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
    """Make ``engine`` (a class implementing the core :class:`~shakermill.engines.interface.Engine`, and the
    capabilities it derives from) the one that runs ``engine = <its name>``: parameters accept the name and the keys
    it reads, and simulate, the files, the figures and the command line run and read it through its description.
    A built-in engine's name cannot be taken; a class that lacks part of the contract is refused
    (:func:`contract_problem`), with a ``ValueError``."""
    name = engine.description.name
    if name in BUILT_IN:
        raise ValueError(f"engine {name!r} is built in")
    problem = contract_problem(engine)
    if problem is not None:
        raise ValueError(f"engine {name!r}: {problem}")
    declare(engine.description.keys)
    _REGISTERED[name] = engine


def contract_problem(engine: type[Engine]) -> str | None:
    """What the engine class ``engine`` lacks of the contract, in one phrase, or None: a member of the core
    (``engines.interface.Engine``), a key it says it reads that ``Parameters`` has not, or the capability
    ``Replicas`` where its keys name a ``replicas_key``. mypy checks the built-in engines' contract statically; this
    checks an engine registered from outside the package when it is registered."""
    missing = [member for member in ENGINE_CORE if not hasattr(engine, member)]
    if missing:
        return f"lacks {', '.join(missing)} of the engine core (engines.interface.Engine)"
    keys = engine.description.keys
    unknown = sorted(keys.reads - set(FIELD_NAMES))
    if unknown:
        return f"reads {', '.join(map(repr, unknown))}, which Parameters has no key of (EngineKeys.reads)"
    if keys.replicas_key is not None and not issubclass(engine, Replicas):
        return f"names replicas_key = {keys.replicas_key!r} without the capability Replicas (engines.interface)"
    return None


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
