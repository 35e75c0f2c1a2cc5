"""The 1-D drive along the vial's axis (MODEL.md §1): x = X_v sin θ."""

from __future__ import annotations

from shakermill.parameters.motions import KinematicModel, Term


def axial_terms(amplitude: float) -> tuple[Term, ...]:
    """x = X_v sin θ (MODEL.md §1): the 1-D drive."""
    return (("x", 1, 0.0, amplitude),)


MOTION = KinematicModel("axial", "the 1-D drive along the vial's axis (MODEL.md §1)", axial_terms)
