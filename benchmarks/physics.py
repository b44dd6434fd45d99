"""Simulation speed of the tap scene against the physics limit.

Prints steps per second of (a) the full scene (iCub, table, one object) at the home pose with the servos
holding it, and (b) a bare MuJoCo scene with the same table and object and no robot, measured in the same
run, and their ratio: how close the robot model comes to the cost of the physics it has to do anyway; then,
from MuJoCo's own timers, where a step of each scene goes (microseconds per step, by pipeline stage).

    python benchmarks/physics.py [--steps 20000] [--object sphere]
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np

from affordance_env.objects import OBJECT_TYPES, object_geometry
from affordance_env.physics import TapPhysics
from affordance_env.scene import build_model

BARE_SCENE = """
<mujoco>
  <option timestep="0.002" integrator="implicitfast" cone="elliptic" impratio="10" ccd_tolerance="1e-9"
          ccd_iterations="200"/>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.05" pos="0 0 -0.7"/>
    <geom name="table_top" type="box" size="0.3 0.5 0.015" pos="-0.46 0 -0.085" friction="0.4 0.0005 0.001"/>
    <body name="object" pos="{x} {y} {z}" quat="{quat}">
      <freejoint/>
      <geom type="{primitive}" size="{size}" condim="6" friction="0.4 0.0005 0.001" mass="{mass}"/>
    </body>
  </worldbody>
</mujoco>
"""


def steps_per_second(model: mujoco.MjModel, data: mujoco.MjData, steps: int) -> float:
    mujoco.mj_step(model, data, 100)  # warm up
    start = time.perf_counter()
    mujoco.mj_step(model, data, steps)
    return steps / (time.perf_counter() - start)


#: MuJoCo's timers reported, as (label, timer); the nested ones are indented.
STAGES = (
    ("step", mujoco.mjtTimer.mjTIMER_STEP),
    ("  position", mujoco.mjtTimer.mjTIMER_POSITION),
    ("    kinematics", mujoco.mjtTimer.mjTIMER_POS_KINEMATICS),
    ("    inertia", mujoco.mjtTimer.mjTIMER_POS_INERTIA),
    ("    collision: broad phase", mujoco.mjtTimer.mjTIMER_COL_BROAD),
    ("    collision: narrow phase", mujoco.mjtTimer.mjTIMER_COL_NARROW),
    ("    making constraints", mujoco.mjtTimer.mjTIMER_POS_MAKE),
    ("  velocity (passive, bias)", mujoco.mjtTimer.mjTIMER_VELOCITY),
    ("  actuation", mujoco.mjtTimer.mjTIMER_ACTUATION),
    ("  constraint solver", mujoco.mjtTimer.mjTIMER_CONSTRAINT),
    ("  integration", mujoco.mjtTimer.mjTIMER_ADVANCE),
)


def stage_times(model: mujoco.MjModel, data: mujoco.MjData, steps: int) -> dict[str, float]:
    """Microseconds per step in each of STAGES over ``steps`` steps."""
    mujoco.mj_step(model, data, 100)
    for _, timer in STAGES:
        data.timer[timer].duration = 0.0
        data.timer[timer].number = 0
    mujoco.mj_step(model, data, steps)
    return {label: 1e6 * data.timer[timer].duration / steps for label, timer in STAGES}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--steps", type=int, default=20000)
    parser.add_argument("--object", default="sphere", choices=OBJECT_TYPES)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()

    geometry = object_geometry(args.object, 0.06)
    physics = TapPhysics(build_model())
    physics.reset_home()
    physics.set_object(geometry, np.array([-0.30, 0.03]), 0.0)
    pose = physics.object_pose()
    size = " ".join(f"{s:g}" for s in geometry.geom_size if s > 0)
    bare_xml = BARE_SCENE.format(
        x=pose[0], y=pose[1], z=pose[2], quat=" ".join(f"{q:g}" for q in pose[3:]), primitive=geometry.primitive,
        size=size, mass=geometry.mass,
    )
    bare = mujoco.MjModel.from_xml_string(bare_xml)
    bare_data = mujoco.MjData(bare)

    full_rates, bare_rates = [], []
    for _ in range(args.repeats):  # interleaved, so both see the same machine load
        physics.reset_home()
        physics.set_object(geometry, np.array([-0.30, 0.03]), 0.0)
        full_rates.append(steps_per_second(physics.model, physics.data, args.steps))
        mujoco.mj_resetData(bare, bare_data)
        bare_rates.append(steps_per_second(bare, bare_data, args.steps))
    full, bare_rate = max(full_rates), max(bare_rates)
    timestep_ms = physics.model.opt.timestep * 1e3
    print(f"object: {args.object} (6 cm), {args.steps} steps of {timestep_ms:g} ms, best of {args.repeats}")
    print(f"  tap scene (iCub nq={physics.model.nq}, nu={physics.model.nu}): {full:10,.0f} steps/s")
    print(f"  bare scene (table + object)         : {bare_rate:10,.0f} steps/s")
    print(f"  ratio tap scene / bare scene        : {full / bare_rate:10.2f}")
    print(f"  real-time factor of the tap scene   : {full * physics.model.opt.timestep:10.1f} x")
    physics.reset_home()
    physics.set_object(geometry, np.array([-0.30, 0.03]), 0.0)
    mujoco.mj_resetData(bare, bare_data)
    stages = stage_times(physics.model, physics.data, args.steps), stage_times(bare, bare_data, args.steps)
    print("where a step goes (MuJoCo's timers, microseconds per step): tap scene | bare scene")
    for label, _ in STAGES:
        print(f"  {label:<28}: {stages[0][label]:6.2f} | {stages[1][label]:6.2f}")


if __name__ == "__main__":
    main()
