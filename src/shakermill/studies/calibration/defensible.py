"""Where a fitted value can still be argued for physically, key by key, with the argument: a calibration bounds its
keys by these ranges, and a value on an edge says the data pull beyond what physics allows."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class DefensibleRange:
    """Where a fitted value can still be argued for physically, and the argument (SI units)."""

    low: float
    high: float
    reason: str

    def contains(self, value: float) -> bool:
        return self.low <= value <= self.high


CENGEL = "Çengel, Heat and Mass Transfer: free convection of gases 2-25, forced 25-250 W/(m²·K)"
DEFENSIBLE_RANGES: dict[str, DefensibleRange] = {
    "beta": DefensibleRange(
        0.1,
        3.0,
        "Whitaker's correlation (β = 1) holds to about ±30 % in steady flow; a factor 3 either way covers the "
        "unsteady, wall-bounded flow round a ball that reverses every few ms (the paper's 0.3 included)",
    ),
    "vial_mass": DefensibleRange(
        0.02,
        1.0,
        "from the steel of the two 19-mm end faces a few mm thick (~0.02 kg) to a whole hardened-steel vial "
        "with its cap (order 1 kg)",
    ),
    "h_outer": DefensibleRange(5.0, 250.0, f"{CENGEL}; the vial moves at up to ωX_v ≈ 2.8 m/s"),
    "h_inner": DefensibleRange(5.0, 250.0, f"{CENGEL}; the trapped air is stirred by the ball"),
    "outer_area": DefensibleRange(
        5.67e-4,
        0.03,
        "from the paper's two 19-mm end faces to the whole outer surface of a SPEX steel vial "
        "(~0.02 m² if it is about 57 mm × 76 mm: no published dimensions were found)",
    ),
    "inner_area": DefensibleRange(
        5.67e-4, 0.01, "from the paper's two end faces to the whole inner surface of a SPEX vial (~0.009 m², estimated)"
    ),
    "lam": DefensibleRange(
        0.25,
        0.75,
        "two steel bodies share the heat of a contact about evenly (equal thermal effusivities give 0.5); "
        "the paper's 0.368 lies inside",
    ),
    "drive_heat": DefensibleRange(
        0.01,
        30.0,
        "no published value: from nearly none to ~10 % of a motor of a few hundred watts reaching the clamp as heat "
        "(motor, bearings, the clamp's springs; an assumed bound, not a measurement)",
    ),
    "clamp_heat_capacity": DefensibleRange(
        200.0,
        10_000.0,
        "no published value: 0.4-20 kg of steel (c ≈ 460-500 J/(kg·K)) in the clamp, its arm and the parts of the mill "
        "head in good thermal contact with them",
    ),
    "clamp_loss": DefensibleRange(
        0.5,
        10.0,
        "no published value: 0.02-0.4 m² of clamp and head at ~25 W/(m²·K) of forced convection, plus conduction into "
        "the frame",
    ),
    "clamp_conductance": DefensibleRange(
        1.0,
        100.0,
        "steel-on-steel contact conductance 10³-10⁴ W/(m²·K) (Madhusudana 1996) over 10⁻³-10⁻² m² of clamped faces",
    ),
    "eta": DefensibleRange(
        0.7,
        1.0,
        "most plastic work in metals becomes heat (Taylor-Quinney coefficient ~0.9); with no powder in the "
        "vial little else can store it",
    ),
}
