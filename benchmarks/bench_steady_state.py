"""Cost of the thermal steady state (MODEL.md §11) of a large charge (issue 49, point 10): Newton's root on the
network's Jacobian assembled path by path, against the reference measured in the same run, MINPACK's trust region
with its Jacobian differenced one node at a time (``scipy.optimize.root``, method 'hybr', what
``analysis/steady.py`` did before), on the same network and load.

The charge: N steel balls of Ø5 mm in the Pulverisette 7's 500-ml bowl (as ``bench_charge_scaling.py``), its load
the velocity terms and contact conductances of 0.1 ms of its packed start, each ball heated by 10 mW. Prints the
CPU time of each root (median of ``--repeats``), of the time constants (the eigenvalues of the Jacobian at the
root), and how far the two roots differ. Usage: python benchmarks/bench_steady_state.py [--balls 500,2000]
[--repeats 3]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from scipy.optimize import root

import shakermill as sm
from shakermill.analysis import steady
from shakermill.engines.dem.engine import DemEngine
from shakermill.engines.dem.model import network_of

BOWL = {
    "ball_radius": 2.5e-3,
    "vial_diameter": 0.1,
    "vial_length": 0.0637,
    "outer_diameter": 0.12,
    "outer_length": 0.08,
    "record_windows": (),
}
WINDOW = 1e-4  # s of the packed start whose velocity terms and conductances load the network
HEAT_PER_BALL = 0.01  # W


def cpu_seconds(work, repeats: int) -> tuple[float, object]:
    """The median CPU time of ``repeats`` calls of ``work`` and the last call's answer."""
    times, answer = [], None
    for _ in range(repeats):
        start = time.process_time()
        answer = work()
        times.append(time.process_time() - start)
    return statistics.median(times), answer


def measure(balls: int, repeats: int) -> dict[str, float]:
    params = sm.default_parameters("pulverisette7", n_balls=balls, duration=WINDOW, output_interval=WINDOW, **BOWL)
    engine = DemEngine(params, horizon=WINDOW)
    while engine.compiled_call(WINDOW, 10_000_000) != 0:
        pass
    measured = engine.measured()
    network = network_of(params)
    heat = np.zeros(len(network.nodes))
    heat[:balls] = HEAT_PER_BALL
    load = engine.load(heat, measured.terms / engine.t, np.asarray(measured.conduction) / engine.t)
    drives, free = load.drives, network.free

    def rates(theta: np.ndarray) -> np.ndarray:
        return network.rates(network.with_free(theta), load.heat, drives)[0][free]

    def slopes(theta: np.ndarray, step: float) -> np.ndarray:
        return network.jacobian(network.with_free(theta), drives, step)

    guess = np.full(free.size, network.ambient + 10.0)
    newton_cpu, newton = cpu_seconds(lambda: steady._newton(rates, slopes, guess), repeats)
    reference_cpu, reference = cpu_seconds(lambda: root(rates, guess, method="hybr", tol=1e-12).x, 1)
    jacobian = slopes(newton, steady.TIME_CONSTANT_STEP)
    eigen_cpu, _ = cpu_seconds(lambda: np.linalg.eigvals(jacobian), repeats)
    whole_cpu, state = cpu_seconds(lambda: steady.steady_state(network, load), repeats)
    return {
        "nodes": free.size,
        "newton": newton_cpu,
        "reference": reference_cpu,
        "eigvals": eigen_cpu,
        "whole": whole_cpu,
        "difference": float(np.max(np.abs(newton - reference))),
        "ball_C": state.ball - 273.15,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--balls", default="500,2000")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    print(f"# CPU s; Newton, eigenvalues and the whole steady state: median of {args.repeats}; MINPACK: one call")
    print(
        f"{'balls':>6} {'nodes':>6} {'Newton':>8} {'MINPACK':>8} {'ratio':>6} {'eigvals':>8} {'whole':>7} "
        f"{'max |Δθ| K':>11} {'ball °C':>8}"
    )
    for balls in (int(value) for value in args.balls.split(",")):
        figures = measure(balls, args.repeats)
        print(
            f"{balls:>6} {figures['nodes']:>6} {figures['newton']:>8.2f} {figures['reference']:>8.2f} "
            f"{figures['reference'] / figures['newton']:>6.1f} {figures['eigvals']:>8.2f} {figures['whole']:>7.2f} "
            f"{figures['difference']:>11.2g} {figures['ball_C']:>8.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
