"""The named motions of the vial (MODEL.md section 12.2) by name: every module of ``parameters/motions/`` that
declares a ``MOTION`` (:class:`~shakermill.parameters.motions.KinematicModel`), in the order of the modules' names.
A new motion is a module there and its keys' group in ``parameters/groups/``; the choices of ``kinematics``, the
engine that moves the vial by every motion and the rule of which keys a run of a motion reads follow from here."""

from __future__ import annotations

import importlib
import pkgutil

from shakermill.parameters import motions
from shakermill.parameters.motions import KinematicModel, Term


def _discovered() -> dict[str, KinematicModel]:
    found: dict[str, KinematicModel] = {}
    for module_info in pkgutil.iter_modules(motions.__path__):
        model = getattr(importlib.import_module(f"{motions.__name__}.{module_info.name}"), "MOTION", None)
        if isinstance(model, KinematicModel):
            if model.name in found:
                raise ValueError(f"two motions are named {model.name!r}: {module_info.name} and another")
            found[model.name] = model
    return found


KINEMATIC_MODELS: dict[str, KinematicModel] = _discovered()


def motion_terms(kinematics: str, values: object) -> tuple[Term, ...]:
    """The Fourier terms of the model ``kinematics``, its keys read (SI) as attributes of ``values`` (a
    ``Parameters``)."""
    model = KINEMATIC_MODELS[kinematics]
    return model.terms(*(getattr(values, key) for key in model.keys))
