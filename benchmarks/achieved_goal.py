"""How far TapAffordanceGoal-v2's ``achieved_goal`` (where the camera sees the object stand) lies from the object's
true centre, per object type, and how often the env's success flag disagrees with the truth.

    python benchmarks/achieved_goal.py [--objects 150] [--position-range workspace] [--range-noise kinect_v1]
                                       [--episodes 0]

``--objects`` resets (seeds 0, 1, ...), each an object placed as the env places them: the error of ``achieved_goal``
against ``info["true_position"]`` per object type (a cylinder by how it rests: standing or lying), median, 95th
percentile, largest [mm], the share within 1 cm and n, for the objects seen whole and for those seen in part (an
arm hides part of them, or the image's edge cuts them: fewer of their pixels than a camera that sees the table and
the object alone has, or a pixel on the image's edge); the same for the centre of the visible top (the points
within 3 mm of its height), for comparison; and the time the fit takes. ``--episodes``: that many episodes (seeds
0, 1, ...) in which the planner, with the shipped models, brings the object toward the goal (as
``examples/use_affordances.py`` does); each step's ``info["is_success"]`` against the truth
(``info["true_position"]`` within the goal tolerance).
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict

import numpy as np

from affordance_env.camera import RangeCamera
from affordance_env.centre import object_centre, visible_top_centre
from affordance_env.goal_env import TapAffordanceGoalEnv, goal_distance

#: A cylinder whose axis is within this of the vertical stands (the cosine of 45 degrees).
STANDING = np.cos(np.pi / 4)


def type_name(info: dict) -> str:
    """The object's type, a cylinder named by how it rests now."""
    name = info["object"]["type"]
    if "cylinder" not in name:
        return name
    w, x, y, _ = info["object"]["pose"][3:]
    return "standing cylinder" if abs(1 - 2 * (x * x + y * y)) >= STANDING else "lying cylinder"


def seen_whole(env: TapAffordanceGoalEnv, world_camera: RangeCamera) -> bool:
    """Whether the last observation saw all of the object: as many pixels as a camera that sees only the table and
    the object, none on the image's edge."""
    physics = env.world.physics
    mask = env.world.seen.snapshot.mask.astype(bool)
    alone = world_camera.capture(physics.data, occluded=physics.active_geom).mask_of(physics.active_geom)
    edge = mask[0].any() or mask[-1].any() or mask[:, 0].any() or mask[:, -1].any()
    return bool(mask.sum() == alone.sum() and not edge)


def table(errors: dict[str, list[float]], title: str) -> None:
    print(f"\n{title}")
    if not errors:
        print("none")
        return
    print(f"{'object':18s} {'median':>7s} {'p95':>7s} {'max':>7s} {'<=1 cm':>7s} {'n':>4s}   [mm]")
    rows = sorted(errors.items()) + [("all", [e for v in errors.values() for e in v])]
    for name, values in rows:
        if not values:
            continue
        e = np.array(values) * 1e3
        print(f"{name:18s} {np.median(e):7.1f} {np.percentile(e, 95):7.1f} {e.max():7.1f} "
              f"{np.mean(e <= 10.0):7.1%} {len(e):4d}")


def errors_at_reset(env: TapAffordanceGoalEnv, objects: int) -> None:
    world = env.world
    camera = world.camera
    world_camera = RangeCamera(world.physics.model, width=camera.intrinsics.width, height=camera.intrinsics.height,
                               fovy_deg=env.options.camera_fovy, geom_groups=(0,), support="table_top")
    whole, part, top_whole, top_part = (defaultdict(list) for _ in range(4))
    fits = []
    for seed in range(objects):
        obs, info = env.reset(seed=seed)
        if not info["visible"]:
            continue
        points = world.seen.snapshot.object_points
        start = time.process_time()  # the CPU it takes: others' load on the machine does not count
        object_centre(points, world.physics.geometry.primitive, world.table.top)
        fits.append(time.process_time() - start)
        error = float(goal_distance(obs["achieved_goal"], info["true_position"]))
        top_error = float(goal_distance(visible_top_centre(points), info["true_position"]))
        is_whole = seen_whole(env, world_camera)
        (whole if is_whole else part)[type_name(info)].append(error)
        (top_whole if is_whole else top_part)[type_name(info)].append(top_error)
    table(whole, "objects seen whole: |achieved_goal - true_position|")
    table(part, "objects seen in part")
    table(top_whole, "for comparison, the visible top's centre (centre.visible_top_centre): objects seen whole")
    table(top_part, "the visible top's centre: objects seen in part")
    print(f"\nthe fit (centre.object_centre), CPU time: median {np.median(fits) * 1e3:.1f} ms, "
          f"largest {np.max(fits) * 1e3:.1f} ms, {len(fits)} objects")


def success_agreement(env: TapAffordanceGoalEnv, episodes: int) -> None:
    from affordance_env.registry import BEHAVIOR_NAMES
    from affordance_env.workspace import in_workspace
    from affordance_learning import load_action_model
    from affordance_learning.planning.planner import Planner

    planner = Planner({behavior: load_action_model(behavior) for behavior in BEHAVIOR_NAMES})
    steps = disagree = successes = 0
    for seed in range(episodes):
        obs, _ = env.reset(seed=seed)
        for left in range(5, 0, -1):
            choice = planner.toward(obs["observation"]["features"], obs["achieved_goal"], obs["desired_goal"],
                                    env.goal_tolerance, feasible=env.feasible, steps_left=left,
                                    reachable=in_workspace)
            if choice.behavior is None:
                break
            obs, _, terminated, _, info = env.step({"behavior": choice.behavior,
                                                    "params": choice.params.astype(np.float32)})
            truth = bool(goal_distance(info["true_position"], obs["desired_goal"]) <= env.goal_tolerance)
            steps, disagree, successes = steps + 1, disagree + (truth != info["is_success"]), successes + truth
            if terminated:
                break
    print(f"\nsuccess flag against the truth: {steps - disagree} of {steps} steps agree "
          f"({(steps - disagree) / max(steps, 1):.1%}); {successes} steps truly within the tolerance; "
          f"{episodes} episodes")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--objects", type=int, default=150)
    parser.add_argument("--position-range", default="workspace", choices=("canonical", "workspace"))
    parser.add_argument("--range-noise", default=None, choices=(None, "kinect_v1"))
    parser.add_argument("--episodes", type=int, default=0)
    args = parser.parse_args()
    env = TapAffordanceGoalEnv(position_range=args.position_range, range_noise=args.range_noise)
    print(f"position_range={args.position_range!r}, range_noise={args.range_noise!r}")
    errors_at_reset(env, args.objects)
    if args.episodes:
        success_agreement(env, args.episodes)
    env.close()


if __name__ == "__main__":
    main()
