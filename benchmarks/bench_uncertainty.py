"""The uncertainty ensemble of issue 36: what an answer costs when it says what it hangs on.

Part ``spex``: the SPEX 8000M with five 12.7-mm balls for an hour (``spex8000m-3d-calibrated``, the preset whose
one-ball fit the five-ball measurement tests), over every assumed input that preset states (ten: friction and
restitution of ball-ball and ball-wall contacts, rolling resistance, λ, the clamp's lateral and yaw amplitudes, the
outside's emissivity and the clamp's conductance). Target: at most 15 min of wall time on 2 cores. It prints the
wall time, the members, the 90 % intervals of the balls' and the vial's rises with the measured ones (Takacs &
McHenry 2006: +46 K and +21 K after an hour) and the three inputs with the largest total Sobol' index.

Part ``planetary``: ``pulverisette7`` with its friction uncertain alone (0.1-0.6), the averaging target loosened to
5 %: the regimes found, their share and the stress-energy median per regime.

    .venv/bin/python benchmarks/bench_uncertainty.py --only spex          # ~10 min on 2 cores
    .venv/bin/python benchmarks/bench_uncertainty.py --only planetary     # ~11 min on 2 cores
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import shakermill as sm
from shakermill.parameters.presets import PRESETS
from shakermill.studies.ensembles.ensemble import ensemble_inputs, run_ensemble

TARGET_S = 15 * 60.0
MEASURED_RISES_K = {"ball_rise_K": 46.0, "vial_rise_K": 21.0}


def ensemble(preset: str, overrides: dict, members: int, only: tuple[str, ...] = ()) -> None:
    params = sm.default_parameters(preset, **overrides)
    inputs, posterior = ensemble_inputs(PRESETS[preset], params, [], only)
    with tempfile.TemporaryDirectory(prefix="bench_uncertainty_") as folder:
        wall = time.perf_counter()
        found = run_ensemble(
            params, inputs, Path(folder) / "ensemble", members, workers=2, preset=preset, posterior=posterior
        )
        wall = time.perf_counter() - wall
    fitted = "" if posterior is None else f" and the posterior of {', '.join(posterior.keys)}"
    print(
        f"\n{preset} {overrides}: {members} members over {len(inputs)} inputs ({', '.join(i.key for i in inputs)})"
        f"{fitted}"
    )
    print(f"  wall {wall:.0f} s on 2 workers ({wall / TARGET_S:.0%} of the 15-min target); {found.failed} failed")
    for spread in found.headlines:
        deciding = ", ".join(f"{key} {spread.total[key]:.2f}" for key in spread.deciding[:3]) or "n/a"
        measured = MEASURED_RISES_K.get(spread.key)
        inside = (
            ""
            if measured is None
            else (
                f"; measured {measured:+g} K "
                f"{'inside' if spread.quantiles[0] <= measured <= spread.quantiles[2] else 'OUTSIDE'}"
            )
        )
        print(
            f"  {spread.label}: 5/50/95 % {spread.quantiles[0]:.4g} / {spread.quantiles[1]:.4g} / "
            f"{spread.quantiles[2]:.4g} {spread.unit} (Q² {spread.surrogate_q2:.2f}; deciding: {deciding}){inside}"
        )
    for name, regime in found.regimes.items():
        medians = regime["medians"]
        print(
            f"  regime {name}: {regime['members']} members ({regime['share']:.0%}); heat {medians['heat_power_W']:.3g} "
            "W, "
            f"stress energy median {medians['stress_energy_median_J'] * 1e3:.3g} mJ, "
            f"fast impacts {medians.get('fast_impact_rate_hz', float('nan')):.0f}/s"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", choices=("spex", "planetary"))
    parser.add_argument("--members", type=int, default=64)
    arguments = parser.parse_args()
    sm.simulate(sm.default_parameters("spex8000m-3d", duration=1.0, solver="full"))  # Numba's cache, warm
    if arguments.only in (None, "spex"):
        ensemble("spex8000m-3d-calibrated", {"n_balls": 5}, arguments.members)
    if arguments.only in (None, "planetary"):
        ensemble("pulverisette7", {"dem_averaging_rel_error": 0.05}, 8, only=("friction",))


if __name__ == "__main__":
    main()
