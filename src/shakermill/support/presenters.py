"""How objects of the lower layers show themselves, filled in by the layer that draws.

``Parameters`` and ``Result`` offer ``_repr_html_`` and ``plot()`` in a notebook, but HTML tables
and figures are made by :mod:`shakermill.views`, a layer above them. Instead of importing upwards,
they ask for the presenter registered here under a name; importing ``shakermill`` registers the
views' presenters (cheaply: the views import Matplotlib only when they draw).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

_PRESENTERS: dict[str, Callable[..., Any]] = {}


def register(name: str, presenter: Callable[..., Any]) -> None:
    _PRESENTERS[name] = presenter


def present(name: str, *args: Any, **kwargs: Any) -> Any:
    """What the presenter registered as ``name`` makes of the arguments."""
    try:
        presenter = _PRESENTERS[name]
    except KeyError:
        raise LookupError(f"nothing presents {name!r}: import shakermill (the package) first") from None
    return presenter(*args, **kwargs)
