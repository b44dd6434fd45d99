"""How physical the interactions are, measured from MuJoCo's state at every physics step.

    python benchmarks/physics_audit.py [--episodes 40] [--behavior tap tap_back push grasp draw] [--seed 1000]
                                       [--action canonical|random]

Canonical interactions (action 0; ``--action random``: uniform in [-1, 1], drawn from the seed) from seeds
``--seed``, ``--seed + 1``, ...; ``mujoco.mj_step`` is wrapped before
the project is imported, so every step the environment takes is seen, whatever calls it. Per behaviour it prints:

- joint speed peaks [deg/s] of the arm and torso, of the neck and of the finger motors, against their limits
  (``affordance_env.motor_limits``), and the largest motor torque as a share of its limit and how many
  interactions saturate a motor (99.9 % of its limit or more);
- penetration [mm] of the robot (hand, fingers, wrist, forearm) into the object and of the object into the
  table: median and largest over interactions of each interaction's deepest;
- interactions whose arm touches the object when the final snapshot is taken, and failures;
- for the grasp: the first touch (which link, in which phase, the palm's speed), the grip while the object is
  held (total normal force of the hand's contacts, its multiple of the object's weight, the largest single
  contact force), the object's slip in the hand during the hold (speed in the palm's frame), the object's
  vertical speed when it meets the table at the put-down, touches after the hand opened, how far failed grasps
  moved the object, and the share held per third of sizes.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
_real_step = mujoco.mj_step
_TRACE: dict[str, object] = {}


class Trace:
    """What one interaction does, step by step."""

    def __init__(self, env) -> None:
        u = env.unwrapped
        self.physics, self.motion = u.physics, u.motion
        m = self.physics.model
        joints = self.physics.variant.active_joints
        self.dofs = self.physics.robot_qvel
        self.groups = {
            "arm": [i for i, n in enumerate(joints) if re.search(r"shoulder|elbow|wrist|torso", n)],
            "neck": [i for i, n in enumerate(joints) if n.startswith("neck")],
            "fingers": [i for i, n in enumerate(joints) if n in self.physics.variant.actuated_joints
                        and n.startswith("l_hand")],
        }
        self.limit = u.motion.velocity_limit
        self.torque_limit = self.physics.torque_limit
        self.motors = [i for i, n in enumerate(joints) if n in self.physics.variant.actuated_joints]
        try:  # releases before the motors' torque-speed curves had the current limit alone
            from affordance_env.motor_limits import available_torque, torque_speed

            self._torque_speed = torque_speed([joints[i] for i in self.motors])
            self._available = available_torque
        except ImportError:
            self._torque_speed = None
        self.speed_peak = {g: 0.0 for g in self.groups}
        self.speed_ratio = {g: 0.0 for g in self.groups}
        self.torque_ratio = 0.0
        self.pen_robot = self.pen_table = 0.0
        #: Phases of the deepest robot-object and object-table penetrations and of the fastest joint.
        self.pen_robot_phase = self.pen_table_phase = self.speed_phase = ""
        self.first_touch: tuple[str, str, float] | None = None
        self.grip: list[float] = []
        self.grip_max_contact = 0.0
        self.slip: list[float] = []
        self.table_touch_speed: float | None = None
        self.table_touch_phase = ""
        self.after_release = False
        self._clear_after_release = False
        self.after_release_what: tuple[str, list[str]] | None = None
        self._was_on_table = True
        self._p_palm = None
        self._force = np.zeros(6)
        self.hand_geom = np.zeros(m.ngeom, dtype=bool)
        self.hand_geom[self.physics.hand_geoms] = True

    def sample(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        ph, phase = self.physics, self.motion.phase
        qd = np.abs(d.qvel[self.dofs])
        for g, idx in self.groups.items():
            if idx:
                if float(qd[idx].max()) > self.speed_peak[g]:
                    self.speed_peak[g] = float(qd[idx].max())
                    if g == "fingers" or (g == "arm" and not self.groups["fingers"]):
                        self.speed_phase = phase
                self.speed_ratio[g] = max(self.speed_ratio[g], float((qd[idx] / self.limit[idx]).max()))
        # Against what the motor gives at its speed: the smaller of its current limit and its torque-speed line
        # (which rises above the stall torque when the motor brakes, turning against its torque).
        signed = d.qfrc_actuator[self.dofs][self.motors]
        tau = np.abs(signed)
        if self._torque_speed is None:
            limit = self.torque_limit[self.motors]
        else:
            stall, no_load = self._torque_speed
            along = np.sign(signed) * d.qvel[self.dofs][self.motors]  # > 0: turning the way it pushes
            limit = self._available(self.torque_limit[self.motors], stall, no_load, along)
        if len(tau):
            self.torque_ratio = max(self.torque_ratio, float((tau / np.maximum(limit, 1e-9)).max()))
        obj, table = ph.active_geom, ph.table_geom
        grip = 0.0
        hand_touch = table_touch = False
        for i in range(d.ncon):
            c = d.contact[i]
            g1, g2 = int(c.geom[0]), int(c.geom[1])
            if obj not in (g1, g2):
                continue
            other = g2 if g1 == obj else g1
            if self.hand_geom[other]:
                hand_touch = True
                if -float(c.dist) > self.pen_robot:
                    self.pen_robot, self.pen_robot_phase = -float(c.dist), phase
                if self.first_touch is None:
                    self.first_touch = (m.body(m.geom_bodyid[other]).name, phase, self._palm_speed(d))
                if phase == "hold":
                    mujoco.mj_contactForce(m, d, i, self._force)
                    grip += abs(self._force[0])
                    self.grip_max_contact = max(self.grip_max_contact, abs(self._force[0]))
            elif other == table:
                table_touch = True
                if -float(c.dist) > self.pen_table:
                    self.pen_table, self.pen_table_phase = -float(c.dist), phase
        if phase == "hold":
            self.grip.append(grip)
            R = d.site_xmat[ph.palm_site].reshape(3, 3)
            p_rel = R.T @ (d.qpos[ph.object_qpos:ph.object_qpos + 3] - d.site_xpos[ph.palm_site])
            self.slip.append(p_rel.copy())
        if (phase in ("carry", "place", "open", "home") and table_touch and not self._was_on_table
                and self.table_touch_speed is None):
            self.table_touch_speed = abs(float(d.qvel[ph.object_qvel + 2]))
            self.table_touch_phase = phase
        if phase in ("retreat", "home") and not hand_touch:
            self._clear_after_release = True
        if phase in ("retreat", "home") and hand_touch and self._clear_after_release and not self.after_release:
            self.after_release = True
            links = {m.body(m.geom_bodyid[int(g)]).name for c in d.contact[:d.ncon] for g in c.geom
                     if self.hand_geom[int(g)]}
            self.after_release_what = (phase, sorted(links))
        self._was_on_table = table_touch
        self._p_palm = d.site_xpos[ph.palm_site].copy()

    def _palm_speed(self, d: mujoco.MjData) -> float:
        if self._p_palm is None:
            return 0.0
        p_palm = d.site_xpos[self.physics.palm_site]
        return float(np.linalg.norm(p_palm - self._p_palm) / self.physics.model.opt.timestep)

    def slip_speed(self, dt: float) -> float:
        """Median speed of the object in the palm's frame during the hold [m/s]."""
        if len(self.slip) < 20:
            return float("nan")
        p = np.array(self.slip)
        half = len(p) // 4  # after the first quarter of the hold: the grip has settled
        return float(np.linalg.norm(p[-1] - p[half]) / ((len(p) - 1 - half) * dt))


def stepper(m, d, nstep=1):
    for _ in range(int(nstep)):
        _real_step(m, d)
        t = _TRACE.get("t")
        if t is not None:
            t.sample(m, d)


mujoco.mj_step = stepper
import gymnasium as gym  # noqa: E402

import affordance_env  # noqa: E402,F401
from affordance_env.registration import ENV_ID  # noqa: E402
from affordance_env.registry import BEHAVIOR_NAMES  # noqa: E402

_OLD_GRASP_PHASES = ("reach", "descend", "close", "squeeze", "lift", "hold", "place", "open", "retreat")


def _label_phases(motion) -> None:
    """Executors of releases before 0.4 did not say what they do: name the grasp's ramps and holds in order."""
    if hasattr(motion, "phase"):
        return
    motion.phase = "idle"
    calls = {"n": 0}

    def named(method):
        def wrapper(*args, **kwargs):
            motion.phase = _OLD_GRASP_PHASES[min(calls["n"], len(_OLD_GRASP_PHASES) - 1)]
            calls["n"] += 1
            return method(*args, **kwargs)
        return wrapper

    for name in ("_ramp", "_hold"):
        setattr(motion, name, named(getattr(motion, name)))
    grasp, go_home = motion.grasp, motion.go_home

    def grasp_named(plan):
        calls["n"] = 0
        return grasp(plan)

    def home_named(*args, **kwargs):
        motion.phase = "home"
        return go_home(*args, **kwargs)

    motion.grasp, motion.go_home = grasp_named, home_named


def audit(behavior: str, episodes: int, seed0: int, action: str = "canonical") -> dict:
    env = gym.make(ENV_ID, behavior=behavior)
    u = env.unwrapped
    _label_phases(u.motion)
    if not hasattr(u.motion, "velocity_limit"):  # releases before 0.4: 100 deg/s everywhere, no torque limits
        u.motion.velocity_limit = np.full(len(u.physics.variant.active_joints), np.radians(100.0))
        u.physics.torque_limit = np.full(len(u.physics.variant.active_joints), np.inf)
    rows = []
    for seed in range(seed0, seed0 + episodes):
        env.reset(seed=seed)
        trace = Trace(env)
        _TRACE["t"] = trace
        params = np.zeros(3) if action == "canonical" else np.random.default_rng(seed).uniform(-1.0, 1.0, 3)
        _, _, _, _, info = env.step(params)
        _TRACE["t"] = None
        ph = u.physics
        end_touch = ph.hand_touches_object()
        mass = float(ph.model.body_mass[ph.object_body])
        rows.append(dict(trace=trace, info=info, end_touch=end_touch, weight=9.81 * mass,
                         size=float(info["object"]["size"]), success=bool(info["success"]),
                         failure=info["failure"], disp=float(info["displacement"])))
    env.close()
    return {"behavior": behavior, "rows": rows, "dt": u.physics.model.opt.timestep, "action": action}


def report(result: dict) -> None:
    rows = [r for r in result["rows"] if not (r["failure"] or "").startswith(("physics", "ik"))]
    beh = result["behavior"]
    print(f"\n## {beh}: {len(result['rows'])} {result['action']} interactions, {len(result['rows']) - len(rows)} "
          "not executed (physics or ik failures)")
    failures = [r["failure"] for r in result["rows"] if r["failure"]]
    if failures:
        kinds: dict[str, int] = {}
        for f in failures:
            kinds[f.split(":")[0]] = kinds.get(f.split(":")[0], 0) + 1
        print(f"failures: {kinds}")
    for g in ("arm", "neck", "fingers"):
        peaks = [np.degrees(r["trace"].speed_peak[g]) for r in rows if r["trace"].groups[g]]
        if peaks:
            ratio = max(r["trace"].speed_ratio[g] for r in rows)
            print(f"{g:8s} joint speed peak: median {np.median(peaks):6.1f}, max {max(peaks):6.1f} deg/s "
                  f"({ratio:.2f} of the limit)")
    saturated = sum(r["trace"].torque_ratio >= 0.999 for r in rows)
    print(f"largest motor torque: {max(r['trace'].torque_ratio for r in rows):.2f} of its limit; a motor saturated in "
          f"{saturated}/{len(rows)} interactions")
    pr = np.array([r["trace"].pen_robot for r in rows]) * 1e3
    pt = np.array([r["trace"].pen_table for r in rows]) * 1e3
    print(f"penetration robot-object [mm]: median {np.median(pr):.2f}, max {pr.max():.2f}; "
          f"object-table: median {np.median(pt):.2f}, max {pt.max():.2f}")
    deep = sorted(rows, key=lambda r: -r["trace"].pen_robot)[:3]
    print("deepest robot-object: " + ", ".join(f"{1e3 * r['trace'].pen_robot:.1f} mm in {r['trace'].pen_robot_phase}"
                                                 for r in deep))
    deep = sorted(rows, key=lambda r: -r["trace"].pen_table)[:3]
    print("deepest object-table: " + ", ".join(f"{1e3 * r['trace'].pen_table:.1f} mm in {r['trace'].pen_table_phase}"
                                                 for r in deep))
    fast = sorted(rows, key=lambda r: -max(r["trace"].speed_ratio.values()))[:3]
    print("fastest joints: " + ", ".join(f"{max(r['trace'].speed_ratio.values()):.2f} of the limit in "
                                         f"{r['trace'].speed_phase}" for r in fast))
    print(f"arm touching the object at the final snapshot: {sum(r['end_touch'] for r in rows)}/{len(rows)}")
    if beh != "grasp":
        return
    firsts = [r["trace"].first_touch for r in rows if r["trace"].first_touch]
    links: dict[str, int] = {}
    for link, phase, _ in firsts:
        key = f"{link.removeprefix('l_hand_').removesuffix('_link')} ({phase})"
        links[key] = links.get(key, 0) + 1
    speeds = [s for _, _, s in firsts]
    print(f"first touch: {dict(sorted(links.items(), key=lambda kv: -kv[1]))}; palm speed median "
          f"{np.median(speeds):.3f}, max {max(speeds):.3f} m/s")
    held = [r for r in rows if r["success"]]
    if held:
        grip = np.array([np.median(r["trace"].grip) for r in held])
        ratio = np.array([np.median(r["trace"].grip) / r["weight"] for r in held])
        single = np.array([r["trace"].grip_max_contact for r in held])
        slip = np.array([r["trace"].slip_speed(result["dt"]) for r in held]) * 1e3
        print(f"grip while held: total {np.median(grip):.1f} N median ({grip.min():.1f}-{grip.max():.1f}), "
              f"{np.median(ratio):.0f}x the weight ({ratio.min():.0f}-{ratio.max():.0f}x); largest contact "
              f"{single.max():.1f} N")
        print(f"slip in the hand during the hold: median {np.nanmedian(slip):.2f}, max {np.nanmax(slip):.2f} mm/s")
        put = [r["trace"].table_touch_speed for r in held if r["trace"].table_touch_speed is not None]
        if put:
            phases: dict[str, int] = {}
            for r in held:
                phases[r["trace"].table_touch_phase] = phases.get(r["trace"].table_touch_phase, 0) + 1
            print(f"put-down: a held object meets the table at median {np.median(put):.3f}, max {max(put):.3f} m/s; "
                  f"in phase {phases}")
    touched = sum(r["trace"].after_release for r in rows)
    print(f"touches after the hand opened and was clear of the object: {touched}/{len(rows)} "
          + str([(r["info"]["object"]["type"], round(r["size"], 3), r["success"], r["trace"].after_release_what)
                 for r in rows if r["trace"].after_release][:4]))
    failed = [r["disp"] for r in rows if not r["success"]]
    if failed:
        print(f"failed grasps move the object: median {100 * np.median(failed):.1f} cm (n = {len(failed)}); "
              f"held ones {100 * np.median([r['disp'] for r in held]):.1f} cm" if held else "")
    sizes = np.array([r["size"] for r in rows])
    ok = np.array([r["success"] for r in rows], float)
    q1, q2 = np.quantile(sizes, [1 / 3, 2 / 3])
    print(f"held per third of sizes (small, middle, large): {ok[sizes <= q1].mean():.2f}, "
          f"{ok[(sizes > q1) & (sizes <= q2)].mean():.2f}, {ok[sizes > q2].mean():.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=40)
    parser.add_argument("--behavior", nargs="+", default=list(BEHAVIOR_NAMES))
    parser.add_argument("--seed", type=int, default=1000)
    parser.add_argument("--action", choices=("canonical", "random"), default="canonical")
    args = parser.parse_args()
    for behavior in args.behavior:
        report(audit(behavior, args.episodes, args.seed, args.action))


if __name__ == "__main__":
    main()
