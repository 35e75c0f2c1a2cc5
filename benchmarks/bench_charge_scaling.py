"""Cost of the 'dem' engine against the number of balls (issue 38): 10, 100 and 1000 steel balls of 5 mm in one
500-ml planetary bowl (Ø100 x 63.7 mm, the Pulverisette 7's motion), each run from its packed start for the same
simulated window, in CPU seconds per simulated second. The reference, measured in the same run, is the search
over every pair that the neighbour list replaced (the list forced to hold every pair: what the engine did before).

Prints, per charge, the CPU time, the steps, the cost per ball-step and the neighbour-list builds, then the exponent
of cost against balls fitted over the charges (1: linear). Usage: python benchmarks/bench_charge_scaling.py
[--window SECONDS] [--balls 10,100,1000] [--reference-up-to 1000]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import shakermill as sm
from shakermill.engines.dem import model
from shakermill.engines.dem.engine import DemEngine

BOWL = {
    "ball_radius": 2.5e-3,
    "vial_diameter": 0.1,
    "vial_length": 0.0637,
    "outer_diameter": 0.12,
    "outer_length": 0.08,
    "record_windows": (),
}


def measure(balls: int, window: float, every_pair: bool) -> dict[str, float]:
    params = sm.default_parameters("pulverisette7", n_balls=balls, duration=window, output_interval=window, **BOWL)
    own_skin = model.neighbour_skin
    if every_pair:
        model.neighbour_skin = lambda radius: math.inf
    try:
        engine = DemEngine(params, horizon=window)
    finally:
        model.neighbour_skin = own_skin
    engine.compiled_call(1e-6, 10)  # compiled and warm before the clock starts
    start = time.process_time()
    while engine.compiled_call(window, 10_000_000) != 0:
        pass
    cpu = time.process_time() - start
    counters = engine.counters()
    return {
        "cpu_per_second": cpu / window,
        "steps": counters["steps"],
        "builds": counters["neighbour_builds"],
        "ns_per_ball_step": 1e9 * cpu / (counters["steps"] * balls),
        "cpu": cpu,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--window", type=float, default=0.004, help="simulated seconds per charge")
    parser.add_argument("--balls", default="10,100,1000")
    parser.add_argument("--reference-up-to", type=int, default=1000, help="largest charge also run over every pair")
    args = parser.parse_args()
    counts = [int(value) for value in args.balls.split(",")]
    print(f"# {args.window:g} s of the packed start of each charge, CPU seconds per simulated second, 2.5-mm radius")
    print(f"{'balls':>6} {'search':>10} {'CPU-s/s':>10} {'steps':>9} {'ns/ball-step':>13} {'builds':>7}")
    listed = []
    for balls in counts:
        for every_pair in (False, True):
            if every_pair and balls > args.reference_up_to:
                continue
            figures = measure(balls, args.window, every_pair)
            if not every_pair:
                listed.append(figures["cpu_per_second"])
            name = "every pair" if every_pair else "list"
            print(
                f"{balls:>6} {name:>10} {figures['cpu_per_second']:>10.1f} {figures['steps']:>9} "
                f"{figures['ns_per_ball_step']:>13.0f} {figures['builds']:>7}",
                flush=True,
            )
    exponent = np.polyfit(np.log(counts), np.log(listed), 1)[0]
    print(f"cost ∝ balls^{exponent:.2f} with the neighbour list over {counts[0]}-{counts[-1]} balls (1: linear)")


if __name__ == "__main__":
    main()
