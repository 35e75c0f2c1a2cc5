"""Cost and heat power of the 'dem' engine's contact step in lasting and brief contacts (MODEL.md §12.6).

Runs each case in 1-s batches and prints the wall and CPU seconds per simulated second, the share of
contact steps, and the heat power with its standard error over the batches (the first batch, the start
from rest, included). Compare a run on the branch with one on the code before it:
``PYTHONPATH=<old checkout>/src python benchmarks/bench_contact_step.py``. Figures: benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import shakermill as sm
from shakermill.engines.dem import model, stepper
from shakermill.engines.dem.engine import DemEngine
from shakermill.engines.status import REACHED_STOP

CASES = {
    # One ball falls onto the bore of the Ø38 vial and rests or rolls on it (axial drive, gravity on).
    "one ball, Ø38 bore": ({"engine": "dem", "n_balls": 1, "vial_diameter": "38 mm"}, 2),
    "one ball, Ø19 bore": ({"engine": "dem", "n_balls": 1}, 2),
    "five balls, Ø38 bore": ({"engine": "dem", "n_balls": 5, "vial_diameter": "38 mm"}, 4),
    # The 1-D limit: one ball on the axis, no gravity, no friction (deterministic).
    "1-D limit, Ø19": ({"engine": "dem", "gravity": False, "friction": 0.0, "convection_velocity": "ball"}, 5),
}


def run(keys: dict, seconds: int) -> dict[str, float]:
    engine = DemEngine(sm.default_parameters(**keys))
    heat, wall, cpu = [0.0], time.perf_counter(), time.process_time()
    for second in range(1, seconds + 1):
        status = engine.advance(float(second))
        if status != REACHED_STOP:
            raise RuntimeError(f"{keys}: {engine.explain(status)}")
        heat.append(float(engine.state.totals[model.HEAT_GENERATED]))
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    batches = np.diff(heat)
    c = engine.stepper_counters
    return {
        "wall": wall / seconds,
        "cpu": cpu / seconds,
        "steps": c[stepper.STEPS] / seconds,
        "contact": 100.0 * c[stepper.CONTACT_STEPS] / c[stepper.STEPS],
        "heat": float(batches.mean()),
        "se": float(batches.std(ddof=1) / np.sqrt(seconds)) if seconds > 1 else 0.0,
        "impacts": c[stepper.IMPACTS] / seconds,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--only", help="run only the cases whose name contains this text")
    args = parser.parse_args()
    DemEngine(sm.default_parameters(engine="dem", n_balls=2, vial_diameter="38 mm")).advance(0.01)  # compile
    header = (
        f"{'case':<22} {'sim s':>5} | {'wall/sim s':>10} {'CPU/sim s':>9} | {'steps/sim s':>11} "
        f"{'contact %':>9} | {'impacts/s':>9} | {'heat W':>9} {'±SE W':>8}"
    )
    print(header + "\n" + "-" * len(header))
    for name, (keys, seconds) in CASES.items():
        if args.only and args.only not in name:
            continue
        r = run(keys, seconds)
        print(
            f"{name:<22} {seconds:5d} | {r['wall']:10.2f} {r['cpu']:9.2f} | {r['steps']:11,.0f} {r['contact']:9.1f} | "
            f"{r['impacts']:9.1f} | {r['heat']:9.5f} {r['se']:8.5f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
