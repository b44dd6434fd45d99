"""TapAffordanceGoal-v2: five behaviours in one world, an object that stays, goals, snapshots and reach."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import affordance_env  # noqa: F401 (registers the envs)
from affordance_env import snapshots
from affordance_env.centre import visible_top_centre
from affordance_env.exceptions import InvalidValueError
from affordance_env.features import FEATURE_NAMES
from affordance_env.goal_env import FlatActionWrapper, TapAffordanceGoalEnv, goal_distance
from affordance_env.objects import as_resting, object_geometry
from affordance_env.outcome import ObjectMonitor
from affordance_env.registry import BEHAVIOR_NAMES
from affordance_env.tap_env import TapAffordanceEnv
from affordance_env.workspace import in_any_workspace, in_workspace, sample_in_workspace

SMALL = {"camera_width": 40, "camera_height": 30}


@pytest.fixture(scope="module")
def env():
    env = TapAffordanceGoalEnv(**SMALL)
    yield env
    env.close()


def test_check_env_and_registration():
    env = gym.make("TapAffordanceGoal-v2", **SMALL)
    check_env(env.unwrapped, skip_render_check=True)
    assert env.spec.max_episode_steps == 5
    assert env.unwrapped.behaviors == ("tap", "tap_back", "push", "grasp", "draw")
    env.close()


def test_the_object_stays_where_the_interaction_left_it_for_every_behaviour(env):
    obs, info = env.reset(seed=4, options={"object_type": "sphere", "size": 0.05, "position": (-0.32, 0.05),
                                           "goal": (-0.45, -0.2)})
    np.testing.assert_allclose(obs["desired_goal"], (-0.45, -0.2))
    pose = info["object"]["pose"]
    for k, behavior in enumerate(BEHAVIOR_NAMES):
        reachable = env.feasible(k, np.zeros(3))
        obs, reward, terminated, truncated, info = env.step({"behavior": k, "params": np.zeros(3, np.float32)})
        assert info["behavior"] == behavior and (info["failure"] is None) == reachable, info["failure"]
        # each interaction starts where the last one left the object (at rest while the head turned to it)
        np.testing.assert_allclose(info["object"]["initial_pose"], pose, atol=1e-9)
        pose = info["object"]["final_pose"]
        assert obs["achieved_goal"] == pytest.approx(pose[:2], abs=0.01)  # seen where it is
        assert reward == env.compute_reward(obs["achieved_goal"], obs["desired_goal"], info)
        if terminated:
            break


def test_interactions_of_the_two_arms_move_the_object_their_way(env):
    env.reset(seed=1, options={"object_type": "sphere", "size": 0.05, "position": (-0.30, 0.05)})
    _, _, _, _, tap = env.step({"behavior": "tap", "params": np.zeros(3)})
    assert tap["displacement"] > 0.05 and tap["success"]  # the ball rolls
    env.reset(seed=1, options={"object_type": "box", "size": 0.05, "position": (-0.30, 0.05)})
    _, _, _, _, grasp = env.step({"behavior": "grasp", "params": np.array([0.0, -0.3, 0.0])})
    assert grasp["success"] and grasp["grasp"]["rise"] > 0.05  # the left hand lifts it ...
    moved = grasp["object"]["final_pose"][:2] - grasp["object"]["initial_pose"][:2]
    assert moved[1] < -0.05  # ... and puts it down to the robot's left (-y in the root frame), as asked
    env.reset(seed=1, options={"object_type": "box", "size": 0.05, "position": (-0.32, 0.0)})
    _, _, _, _, draw = env.step({"behavior": "draw", "params": np.zeros(3)})
    moved = draw["object"]["final_pose"][:2] - draw["object"]["initial_pose"][:2]
    assert draw["failure"] is None and moved[0] > 0.04 and abs(moved[1]) < 0.02  # toward the robot (+x)


@pytest.mark.parametrize(("object_type", "position", "params"), [
    ("box", (-0.30, 0.10), (0.4, 0.3, 0.0)),
    ("vertical_cylinder", (-0.32, 0.05), (-0.3, 0.5, 0.0)),
    ("sphere", (-0.28, 0.12), (0.25, -0.4, 0.0)),
])
def test_pick_and_place_puts_a_held_object_down_at_rest_where_asked(env, object_type, position, params):
    from affordance_env.behaviors.grasp import PLACE_RANGE

    env.reset(seed=0, options={"object_type": object_type, "size": 0.05, "position": position})
    start = env.get_state()
    assert env.feasible("grasp", params)
    _, _, _, _, info = env.step({"behavior": "grasp", "params": np.array(params, np.float32)})
    asked = np.asarray(info["object"]["initial_pose"][:2]) + PLACE_RANGE * np.asarray(params[:2])
    assert info["success"] and info["outcome"] == "rest"
    assert np.linalg.norm(info["object"]["pose"][:2] - asked) < 0.01
    # a place off the table is refused before anything moves
    assert not env.feasible("grasp", (1.0, 0.0, 0.0), state=start)


def test_a_ball_grasped_at_the_near_edge_and_put_down_on_the_table_stays_on_it(env, monkeypatch):
    # 8 mm inside the table's near edge, the closing fingers draw the ball's centre 1 mm beyond it, 5 mm up, and
    # the hand carries it 8.6 cm away and puts it down: held over the edge, it never left the table
    samples, sample = [], ObjectMonitor.sample

    def recorded(monitor, time, p, v, w):
        samples.append((monitor, monitor.held, p[0]))
        sample(monitor, time, p, v, w)

    monkeypatch.setattr(ObjectMonitor, "sample", recorded)
    x_edge = float(env.unwrapped.world.table.high[0])
    env.reset(seed=0, options={"object_type": "sphere", "size": 0.0456, "position": (x_edge - 0.008, 0.109)})
    _, _, _, _, info = env.step({"behavior": "grasp", "params": np.array([-0.37, -0.23, -0.52], np.float32)})
    assert any(held and x > x_edge for _, held, x in samples)  # in the hand, over the edge
    assert not samples[-1][1] and not samples[-1][0].held  # let go: the monitor knows it
    assert info["failure"] is None and info["success"]
    assert info["outcome"] == "rest" and info["object"]["pose"][0] < x_edge - 0.05


def test_a_grasp_40_cm_out_lifts_the_ball_without_leaning_onto_the_held_arm(env):
    # There the torso's IK, unbounded, pitched it 49 degrees and rolled it -29: the held right arm's forearm met the
    # table and held the torso up, and the hand closed 3 cm above the ball, on nothing
    world = env.unwrapped.world
    held_arm_on_table = []
    world.on_step(lambda time: held_arm_on_table.append("chest" in world.physics.links_touching_table()))
    try:
        env.reset(seed=0, options={"object_type": "sphere", "size": 0.07, "position": (-0.40, 0.10), "yaw": 0.0})
        assert env.feasible("grasp", np.zeros(3))
        _, _, _, _, info = env.step({"behavior": "grasp", "params": np.zeros(3, np.float32)})
    finally:
        world.on_step(None)
    assert held_arm_on_table and not any(held_arm_on_table)
    assert info["failure"] is None and info["success"] and info["grasp"]["rise"] > 0.05


def test_feasible_from_a_snapshot_answers_for_it_and_leaves_the_env_as_it_was(env):
    env.reset(seed=0, options={"object_type": "box", "size": 0.06, "position": (-0.30, 0.05)})
    start = env.get_state()
    env.step({"behavior": "push", "params": np.zeros(3)})  # the box is now elsewhere
    now = env.get_state()
    params = np.array([0.0, 0.0, 0.0])
    answers = {b: env.feasible(b, params, state=start) for b in BEHAVIOR_NAMES}
    after = env.get_state()
    for field in ("qpos", "qvel", "ctrl", "act"):  # nothing moved
        np.testing.assert_array_equal(getattr(after.world.physics[1], field), getattr(now.world.physics[1], field))
    assert after.world.arm == now.world.arm and after.obs is now.obs
    env.set_state(start)
    assert answers == {b: env.feasible(b, params) for b in BEHAVIOR_NAMES}


def test_an_outcome_from_a_snapshot_is_the_steps_bit_for_bit_and_leaves_the_env_as_it_was(env):
    """outcome(): what step() would do from the snapshot, on every key that does not come of the observation after
    it, and the env (world, episode, generator) as it was; a kinematic failure is an outcome too."""
    env.reset(seed=2, options={"object_type": "sphere", "size": 0.06, "position": (-0.30, 0.05)})
    start = env.get_state()
    env.step({"behavior": "push", "params": np.zeros(3)})  # the ball is now elsewhere
    now = env.get_state()
    shared = ("failure", "rolled", "outcome", "success", "displacement", "behavior")
    for behavior, params in (("tap", np.array([0.3, -0.2, 0.5], np.float32)),
                             ("grasp", np.array([0.25, -0.5, 0.0], np.float32))):
        got = env.outcome(behavior, params, state=start)
        after = env.get_state()
        for field in ("qpos", "qvel"):  # nothing moved
            np.testing.assert_array_equal(getattr(after.world.physics[1], field),
                                          getattr(now.world.physics[1], field))
        assert after.obs is now.obs and after.steps == now.steps and after.rng == now.rng
        env.set_state(start)
        *_, info = env.step({"behavior": behavior, "params": params})
        assert {k: info[k] for k in shared} == {k: got[k] for k in shared}
        np.testing.assert_array_equal(got["effect"], info["effect"])
        for key in ("initial_pose", "final_pose"):
            np.testing.assert_array_equal(got["object"][key], info["object"][key])
        assert not {"is_success", "distance", "true_position"} & set(got)
        env.set_state(now)
    with pytest.raises(ValueError, match="behavior"):
        env.outcome("kick", np.zeros(3))


def test_the_object_pose_has_the_same_key_after_reset_and_after_step(env):
    _, info = env.reset(seed=3)
    assert set(info["object"]) >= {"pose"}
    _, _, _, _, info = env.step({"behavior": "tap", "params": np.zeros(3)})
    np.testing.assert_array_equal(info["object"]["pose"], info["object"]["final_pose"])


def test_relation_features_are_measured_to_the_same_palm_whichever_arm_acts():
    right = TapAffordanceEnv(behavior="tap", two_arms=True, **SMALL)
    left = TapAffordanceEnv(behavior="grasp", two_arms=True, **SMALL)
    one_armed = TapAffordanceEnv(behavior="grasp", **SMALL)
    options = {"object_type": "box", "size": 0.06, "position": (-0.3, 0.0)}
    features = [e.reset(seed=0, options=options)[0]["features"] for e in (right, left, one_armed)]
    image = [FEATURE_NAMES.index(name) for name in ("hand_image_dx", "hand_image_dy", "hand_image_distance")]
    other = np.setdiff1d(np.arange(len(FEATURE_NAMES)), image)
    # the same world: the right arm servoed at home, or held there, is seen within a pixel and measured within 0.1 mm
    np.testing.assert_allclose(features[0][other], features[1][other], atol=1e-4)
    np.testing.assert_allclose(features[0][image], features[1][image], atol=0.5)
    hand = [FEATURE_NAMES.index(name) for name in ("hand_dx", "hand_dy", "hand_dz", "hand_distance")]
    assert not np.allclose(features[0][hand], features[2][hand], atol=0.05)  # the one-armed grasp: the left palm


def test_goals_are_drawn_on_the_table_inside_the_workspaces_at_the_asked_distance(env):
    for seed in range(12):
        obs, info = env.reset(seed=seed)
        d = goal_distance(obs["achieved_goal"], obs["desired_goal"])
        assert 0.10 - 1e-9 <= d <= 0.25 + 1e-9 and info["distance"] == pytest.approx(d)
        assert in_any_workspace(obs["desired_goal"])


def test_compute_reward_is_vectorised_and_matches_the_tolerance(env):
    achieved = np.array([[0.0, 0.0], [0.0, 0.0], [0.1, 0.0]])
    desired = np.array([[0.0, 0.029], [0.0, 0.031], [0.1, 0.0]])
    np.testing.assert_array_equal(env.compute_reward(achieved, desired, {}), [0.0, -1.0, 0.0])
    dense = TapAffordanceGoalEnv.__new__(TapAffordanceGoalEnv)
    dense.reward_type, dense.goal_tolerance = "dense", 0.03
    np.testing.assert_allclose(dense.compute_reward(achieved, desired, {}), [-0.029, -0.031, 0.0])


def test_reaching_the_goal_terminates_and_an_episode_is_truncated_after_five_steps():
    env = gym.make("TapAffordanceGoal-v2", **SMALL)
    obs, _ = env.reset(seed=2, options={"object_type": "box", "size": 0.05, "position": (-0.30, 0.05)})
    env.unwrapped._goal = obs["achieved_goal"].copy()  # already there: any interaction that leaves it ends it
    _, reward, terminated, _, info = env.step({"behavior": "grasp", "params": np.array([0.0, 0.0, 1.0])})
    assert info["is_success"] == terminated == (reward == 0.0)
    env.reset(seed=2, options={"object_type": "box", "size": 0.09, "position": (-0.30, 0.05), "goal": (-0.5, 0.3)})
    for step in range(5):
        _, _, terminated, truncated, _ = env.step({"behavior": "grasp", "params": np.zeros(3)})  # too big: stays
        assert not terminated and truncated == (step == 4)
    env.close()


def test_a_restore_gives_the_same_interaction_bit_for_bit(env):
    env.reset(seed=5, options={"object_type": "sphere", "size": 0.06})
    env.step({"behavior": "grasp", "params": np.zeros(3)})  # the world is now the left arm's
    state = env.get_state()
    action = {"behavior": "tap", "params": np.array([0.2, -0.3, 0.4], np.float32)}
    first = env.step(action)
    env.step({"behavior": "push", "params": np.zeros(3)})
    env.set_state(state)
    again = env.step(action)
    np.testing.assert_array_equal(first[0]["observation"]["range"], again[0]["observation"]["range"])
    np.testing.assert_array_equal(first[4]["effect"], again[4]["effect"])
    np.testing.assert_array_equal(first[4]["object"]["final_pose"], again[4]["object"]["final_pose"])


@pytest.mark.parametrize(("object_type", "size", "position", "yaw"), [
    ("horizontal_cylinder", 0.092, (-0.221, 0.186), -0.166),  # the left arm hides the part toward +y
    ("sphere", 0.07, (-0.211, 0.186), 0.0),
    ("box", 0.084, (-0.227, 0.192), -0.249),
])
def test_achieved_goal_is_where_the_object_stands_though_an_arm_hides_part_of_it(env, object_type, size, position,
                                                                                    yaw):
    obs, info = env.reset(seed=0, options={"object_type": object_type, "size": size, "position": position,
                                           "yaw": yaw})
    truth = info["true_position"]
    np.testing.assert_array_equal(truth, info["object"]["pose"][:2])
    top = visible_top_centre(env.world.seen.snapshot.object_points)
    assert goal_distance(top, truth) > 0.015  # the visible top's centre is centimetres off ...
    assert goal_distance(obs["achieved_goal"], truth) < 0.003  # ... where the object stands is not


def test_trying_actions_from_a_snapshot_does_not_bring_the_time_limit_nearer():
    env = gym.make("TapAffordanceGoal-v2", max_episode_steps=2, **SMALL)
    env.reset(seed=0, options={"object_type": "box", "size": 0.05, "position": (-0.3, 0.05), "goal": (-0.45, -0.2)})
    tap = {"behavior": "tap", "params": np.zeros(3, np.float32)}
    start = snapshots.get_state(env)
    assert start.steps == 0
    for _ in range(2):  # two actions tried from the start: each the episode's first step
        snapshots.set_state(env, start)
        assert env.step(tap)[3] is False
    after_one = snapshots.get_state(env)
    assert after_one.steps == 1
    snapshots.set_state(env, after_one)
    assert env.step(tap)[3] is True  # the second step of the episode: truncated, as without the snapshot
    env.unwrapped.set_state(start)  # the env alone: the TimeLimit's count stays where it was
    assert env.step(tap)[3] is True
    env.close()


@pytest.mark.parametrize("steps", [-1, 1.5, True, "2"])
def test_a_state_whose_step_count_is_not_a_count_is_refused_and_restores_nothing(env, steps):
    import dataclasses

    env.reset(seed=0)
    before = env.get_state()
    with pytest.raises(InvalidValueError, match="its step count is"):
        env.set_state(dataclasses.replace(before, steps=steps, goal=np.array([-0.4, 0.1])))
    assert env.get_state().goal.tolist() == before.goal.tolist()


def test_feasible_agrees_with_the_interactions_ik(env):
    agree = 0
    draws = [("tap", (-0.30, 0.05)), ("push", (-0.30, 0.30)), ("grasp", (-0.30, -0.25)), ("grasp", (-0.30, 0.10)),
             ("tap_back", (-0.25, -0.30))]
    for behavior, xy in draws:
        env.reset(seed=0, options={"object_type": "box", "size": 0.06, "position": xy})
        feasible = env.feasible(behavior, np.zeros(3))
        _, _, _, _, info = env.step({"behavior": behavior, "params": np.zeros(3)})
        reached = info["ik"]["success"]  # measured whether or not another failure came first
        agree += feasible == reached
        assert feasible == in_workspace(behavior, np.array(xy))
    assert agree == len(draws)


def test_feasible_answers_as_the_whole_ik_budget_would_in_fewer_iterations(env, monkeypatch):
    # feasible()'s IK gives up on a pose once its error stands still beyond the behaviours' tolerances; the answers
    # must be those of IK calls that spend their whole budget
    from affordance_env.kinematics import Kinematics
    from affordance_env.motion import MotionExecutor

    iterations = []
    solve = Kinematics.solve_ik

    def counted(self, *args, **kwargs):
        result = solve(self, *args, **kwargs)
        iterations.append(result.iterations)
        return result

    monkeypatch.setattr(Kinematics, "solve_ik", counted)
    ik = MotionExecutor.ik

    def in_full(self, p, q, hand, check=False):  # every IK as an interaction solves it
        return ik(self, p, q, hand)

    rng = np.random.default_rng(4)
    actions = [(b, rng.uniform(-1, 1, 3)) for b in BEHAVIOR_NAMES for _ in range(8)]
    answers, spent = {}, {}
    for check in (True, False):
        if not check:
            monkeypatch.setattr(MotionExecutor, "ik", in_full)
        iterations.clear()
        answers[check] = []
        for xy in ((-0.30, -0.20), (-0.45, 0.15), (-0.20, 0.05)):
            env.reset(seed=1, options={"object_type": "box", "size": 0.05, "position": xy})
            answers[check] += [env.feasible(b, a) for b, a in actions]
        spent[check] = sum(iterations)
    assert answers[True] == answers[False] and 0 < sum(answers[True]) < len(answers[True])
    assert spent[True] < 0.95 * spent[False]  # 9 % fewer here (the grasp's IK, bounded, slides along its torso range)


def test_feasible_refuses_a_grasp_whose_lift_from_a_high_first_touch_is_out_of_reach(env):
    # A large lying cylinder at the far edge of the grasp's reach, gripped high: the descent stops at the first
    # touch, above the grasp pose, and the lift from there leaves the arm's reach (5 cm short at its top).
    pose = [-0.4324, 0.1631, -0.0215, 0.70561, 0.04591, 0.70561, -0.04591]
    env.reset(seed=0, options={"object_type": "horizontal_cylinder", "size": 0.097, "object_pose": pose,
                               "goal": (-0.365, 0.252)})
    params = np.array([-0.89, -0.42, 0.1])
    assert not env.feasible("grasp", params)
    _, _, _, _, info = env.step({"behavior": "grasp", "params": params.astype(np.float32)})
    assert not info["ik"]["success"]


@pytest.mark.parametrize(("object_type", "xy", "size", "params"), [
    ("vertical_cylinder", (-0.2381, 0.1192), 0.0679, (-0.868, 0.683, -0.867)),
    ("box", (-0.2199, 0.2022), 0.0473, (-0.951, 0.317, -0.177)),
])
def test_feasible_refuses_a_pick_and_place_whose_carry_ends_out_of_reach(env, object_type, xy, size, params):
    # Put down at the edge of the left arm's reach: the object hangs in the closed hand 1-2 cm from where the grasp
    # aimed it, so the carry, which brings the object over the place asked, ends that far beyond the nominal pose,
    # out of reach (the nominal pose and the line to it are within it).
    env.reset(seed=0, options={"object_type": object_type, "size": size, "position": xy})
    params = np.array(params, dtype=np.float32)
    assert not env.feasible("grasp", params)
    _, _, _, _, info = env.step({"behavior": "grasp", "params": params})
    assert not info["ik"]["success"]


@pytest.mark.slow
def test_feasible_refuses_a_reach_that_sweeps_into_the_object(env):
    # Draw 93 of ``python benchmarks/feasible.py --seed 1``: the tap_back's reach crosses over a ball, its targets
    # 1.1 mm into it as the palm comes down fast; the arm knocks the ball 4 cm away before the stroke.
    env.reset(seed=93, options={"object_type": "sphere", "size": 0.08421, "position": (-0.26187, -0.13671)})
    params = np.array([0.3872, 0.0772, 0.7755], dtype=np.float32)
    assert not env.feasible("tap_back", params)
    _, _, _, _, info = env.step({"behavior": "tap_back", "params": params})
    assert info["ik"]["success"] and info["failure"].startswith("reach: the arm moved the object")


@pytest.mark.slow
def test_feasible_refuses_a_pick_and_place_off_the_table_though_its_poses_are_reached(env):
    # Draw 43 of ``python benchmarks/feasible.py --seed 0``: a pick and place asked to put a small lying cylinder
    # down 19 cm nearer the robot, beyond the table's near edge. Every pose is within the arm's reach and the hand
    # holds the cylinder, but it cannot be put down there: feasible() refuses it.
    env.reset(seed=43, options={"object_type": "horizontal_cylinder", "size": 0.04263, "position": (-0.22907, -0.00848),
                                "yaw": 0.04357})
    params = np.array([0.9774, -0.6341, 0.926], dtype=np.float32)
    assert not env.feasible("grasp", params)
    _, _, _, _, info = env.step({"behavior": "grasp", "params": params})
    assert info["ik"]["success"] and info["grasp"]["rise"] > 0.05  # held, and carried where it was asked ...
    assert info["outcome"] == "off_table"  # ... off the table


def test_bad_actions_options_and_goals_get_clear_errors(env):
    env.reset(seed=0)
    with pytest.raises(ValueError, match="Unknown behavior 'kick'"):
        env.step({"behavior": "kick", "params": np.zeros(3)})
    with pytest.raises(ValueError, match="index in 0..4"):
        env.step({"behavior": 7, "params": np.zeros(3)})
    with pytest.raises(ValueError, match=r"\[-1, 1\]"):
        env.step({"behavior": 0, "params": np.full(3, 2.0)})
    with pytest.raises(ValueError, match="keys 'behavior'"):
        env.step(np.zeros(3))
    with pytest.raises(ValueError, match="goal must be"):
        env.reset(options={"goal": (5.0, 0.0)})
    with pytest.raises(ValueError, match="Unknown reset option"):
        env.reset(options={"target": (0.0, 0.0)})


def test_flat_action_wrapper_runs_the_highest_scoring_behaviour():
    wrapper = FlatActionWrapper(TapAffordanceGoalEnv.__new__(TapAffordanceGoalEnv))
    assert wrapper.action_space.shape == (8,)
    action = wrapper.action(np.array([0.1, -0.2, 0.9, 0.3, -0.4, 0.5, -0.5, 0.0]))
    assert action["behavior"] == 2 and action["params"].tolist() == [0.5, -0.5, 0.0]
    with pytest.raises(ValueError, match="8 finite values"):
        wrapper.action(np.zeros(3))


@pytest.mark.parametrize("object_type", ["vertical_cylinder", "box"])
def test_any_resting_pose_can_be_placed_and_plans_read_it(object_type):
    env = TapAffordanceEnv(**SMALL)
    lying = np.array([np.sqrt(0.5), 0.0, np.sqrt(0.5), 0.0])  # a standing cylinder toppled along x
    g = object_geometry(object_type, 0.06)
    _, info = env.reset(seed=0, options={"object_type": object_type, "size": 0.06,
                                         "object_pose": (-0.3, 0.02, env.physics.table_top + 0.03, *lying)})
    assert info["object"]["pose"][:2] == pytest.approx((-0.3, 0.02), abs=2e-3)
    planned = env.world.seen.geometry  # what the plans are made from
    expected = "horizontal_cylinder" if object_type == "vertical_cylinder" else "box"
    assert planned.object_type == expected and as_resting(g, lying)[0].object_type == expected
    with pytest.raises(ValueError, match="object_pose must be"):
        env.reset(options={"object_pose": (-0.3, 0.0, 5.0, 1, 0, 0, 0)})
    with pytest.raises(ValueError, match="exclude each other"):
        env.reset(options={"object_pose": (-0.3, 0.0, 0.0, 1, 0, 0, 0), "yaw": 0.1})


def test_workspaces_sample_inside_themselves():
    rng = np.random.default_rng(0)
    for name in BEHAVIOR_NAMES:
        points = np.array([sample_in_workspace(name, rng) for _ in range(50)])
        assert np.all(in_workspace(name, points))
    assert not in_any_workspace(np.array([-0.7, 0.0]))  # far side of the table: out of every arm's reach
    with pytest.raises(ValueError, match="Unknown behavior"):
        in_workspace("kick", np.zeros(2))


def test_every_vector_step_is_an_interaction():
    envs = gym.make_vec("TapAffordanceGoal-v2", 2, camera_width=32, camera_height=24)
    assert envs.metadata["autoreset_mode"] == gym.vector.AutoresetMode.SAME_STEP
    envs.reset(seed=0)
    ended = 0
    for _ in range(6):  # more than an episode's 5 interactions: each env ends one and starts the next
        actions = {"behavior": np.array([0, 2]), "params": np.zeros((2, 3), np.float32)}
        obs, rewards, terminated, truncated, infos = envs.step(actions)
        done = terminated | truncated
        if done.any():  # the episode's last interaction, and already the next episode's first observation
            assert list(infos["final_info"]["behavior"][done]) == list(np.array(["tap", "push"])[done])
        if (~done).any():
            assert list(infos["behavior"][~done]) == list(np.array(["tap", "push"])[~done])
        ended += int(done.sum())
        assert obs["desired_goal"].shape == (2, 2)
    assert ended >= 2  # truncated after 5 at the latest
    envs.close()
