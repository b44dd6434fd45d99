"""Wrong input to the API is refused before any work, with a message that names the value and what is expected; and
what the API returns is what its documentation says."""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pandas as pd
import pytest
from gymnasium.utils.passive_env_checker import data_shares_objects

import affordance_env  # noqa: F401 (registers the envs)
from affordance_env.features import FEATURE_NAMES
from affordance_env.physics import TapPhysics
from affordance_env.registry import BEHAVIOR_NAMES
from affordance_env.scene import build_model, table_extent
from affordance_env.tap_env import TapAffordanceEnv
from affordance_learning import predict_effect
from affordance_learning.planning.effect_model import ActionEffectModel
from affordance_learning.planning.goals import Place, Roll
from affordance_learning.planning.planner import Planner

N = len(FEATURE_NAMES)


@pytest.fixture(scope="module")
def model() -> ActionEffectModel:
    """An effect model of the real inputs: the 49 features and the 3 parameters; objects move dx = 0.1 a0."""
    rng = np.random.default_rng(0)
    X = np.column_stack([rng.normal(size=(200, N)), rng.uniform(-1, 1, (200, 3))])
    zeros = np.zeros(200)
    Y = pd.DataFrame({"dx": 0.1 * X[:, N], "dy": zeros, "rolled": (X[:, N] > 0).astype(float), "off_table": zeros,
                      "lifted": zeros})
    return ActionEffectModel(n_estimators=10, random_state=0).fit(X, Y)


@pytest.fixture(scope="module")
def planner(model) -> Planner:
    return Planner({"push": model}, n_candidates=8)


# --- the planner ------------------------------------------------------------------------------------------------
def test_a_model_of_an_unknown_behaviour_is_refused_naming_the_known_ones(model):
    with pytest.raises(ValueError, match="'kick'") as error:
        Planner({"kick": model})
    assert all(name in str(error.value) for name in BEHAVIOR_NAMES)
    with pytest.raises(TypeError, match="fitted ActionEffectModel, got str"):
        Planner({"push": "model.joblib"})


def test_features_of_the_wrong_length_are_refused_naming_the_length(planner):
    for features in (np.zeros(N + 2), np.zeros(N - 1), np.zeros((2, N))):
        with pytest.raises(ValueError, match=rf"49 feature values \(affordance_env.FEATURE_NAMES\).*{features.shape}"):
            planner.choose(features, Roll())
        with pytest.raises(ValueError, match="49 feature values"):
            planner.toward(features, (-0.3, 0.0), (-0.25, 0.0), 0.03)
    assert planner.choose(np.zeros((1, N)), Roll()).behavior == "push"  # one row is one vector


def test_a_place_goal_needs_where_the_object_is(planner):
    with pytest.raises(ValueError, match="a Place goal needs start_xy.*got None"):
        planner.choose(np.zeros(N), Place((-0.3, 0.0)))
    with pytest.raises(ValueError, match=r"start_xy must be .*\(x, y\).*got \(0.1, nan\)"):
        planner.choose(np.zeros(N), Place((-0.3, 0.0)), (0.1, float("nan")))
    assert planner.choose(np.zeros(N), Place((-0.3, 0.0)), (-0.35, 0.0)).behavior == "push"


def test_a_goal_of_another_type_is_a_type_error_naming_the_goal_types(planner):
    for goal in ("roll", {"kind": "roll"}, None):
        with pytest.raises(TypeError, match="goal must be one of Roll, Lift, Move, Place, Percept") as error:
            planner.choose(np.zeros(N), goal)
        assert repr(goal) in str(error.value)
    with pytest.raises(TypeError, match="goal_from_dict"):
        planner.scores(np.zeros(N), {"kind": "roll"})


def test_toward_refuses_a_target_off_the_table(planner):
    (x0, y0), (x1, y1) = table_extent()
    for target in ((x1 + 0.01, 0.0), (x0 - 0.01, 0.0), (-0.3, y1 + 0.01), (-0.3, y0 - 0.01)):
        with pytest.raises(ValueError, match=rf"target_xy must be .* on the table top, x in \[{x0:.2f}, {x1:.2f}\]"):
            planner.toward(np.zeros(N), (-0.3, 0.0), target, 0.03)
    assert planner.toward(np.zeros(N), (-0.3, 0.0), (x1, y1), 0.03).behavior == "push"  # the edge is on it


def test_the_planners_table_is_the_environments():
    low, high = TapPhysics(build_model("tap")).table_extent()
    np.testing.assert_allclose(table_extent(), (low, high))


# --- snapshots of the world ---------------------------------------------------------------------------------------
def test_a_state_restores_only_into_an_env_of_the_same_robot_model():
    grasp = TapAffordanceEnv(behavior="grasp", camera_width=32, camera_height=24)
    tap = TapAffordanceEnv(behavior="tap", camera_width=32, camera_height=24)
    push = TapAffordanceEnv(behavior="push", camera_width=32, camera_height=24)
    with pytest.raises(ValueError, match="the 'grasp' robot model of the left arm; this world has right arm: 'tap'"):
        tap.set_state(grasp.get_state())
    with pytest.raises(ValueError, match="the 'tap' robot model of the right arm; this world has left arm: 'grasp'"):
        grasp.set_state(tap.get_state())
    push.set_state(tap.get_state())  # the same model: the push arm takes over the tap's world
    for env in (grasp, tap, push):
        env.close()


def test_steps_from_a_restored_state_return_infos_of_their_own():
    # The README's get_state / set_state example, stepped again from the restored state, under gym.make's checker.
    env = gym.make("TapAffordance-v2", camera_width=32, camera_height=24)
    obs, reset_info = env.reset(seed=3)
    kept = reset_info["object"]["pose"].copy()
    state = env.unwrapped.get_state()
    with warnings.catch_warnings():
        warnings.filterwarnings("error", message=".*share an object")
        first = env.step(np.zeros(3))[4]
        env.unwrapped.set_state(state)
        second = env.step(np.zeros(3))[4]
    assert not data_shares_objects(first, second)
    first["object"]["initial_pose"][:] = 0.0  # a user's changes to one step's info stay in it ...
    first["initial_features"][:] = 0.0
    env.unwrapped.set_state(state)
    third = env.step(np.zeros(3))[4]
    np.testing.assert_array_equal(third["object"]["initial_pose"], second["object"]["initial_pose"])
    np.testing.assert_array_equal(third["initial_features"], second["initial_features"])
    reset_info["object"]["pose"][:] = 0.0  # ... and to the reset's info too
    env.unwrapped.set_state(state)
    np.testing.assert_array_equal(env.step(np.zeros(3))[4]["object"]["initial_pose"], kept)
    env.close()


# --- predict_effect -----------------------------------------------------------------------------------------------
def test_predict_effect_gives_one_result_for_one_vector_and_a_batch_for_a_batch():
    features = np.random.default_rng(0).normal(size=(3, N))
    batch = predict_effect(features)
    assert batch.category.shape == (3,) and batch.effect.shape == (3, N)
    one = predict_effect(features[1])
    assert isinstance(one.category, int) and one.category == batch.category[1]
    np.testing.assert_array_equal(one.effect, batch.effect[1])
    row = predict_effect(features[1:2])  # a batch of one stays a batch
    assert row.category.shape == (1,) and row.effect.shape == (1, N)


# --- values that are not numbers --------------------------------------------------------------------------------
NOT_NUMBERS = ("abc", ["a", "b", "c"], b"abc", {"a": 1}, {1, 2, 3}, [[0], [0, 0], 0], [1j, 0, 0], [True, False, True],
               ["0.1", "0", "0"])


def test_an_action_that_is_not_three_real_numbers_is_refused_naming_it():
    env = TapAffordanceEnv(camera_width=32, camera_height=24)
    env.reset(seed=0)
    for action in NOT_NUMBERS:
        for call in (env.step, env.feasible):
            with pytest.raises(ValueError, match=r"action must be 3 real numbers in \[-1, 1\], got") as error:
                call(action)
            assert repr(action) in str(error.value)
    assert env.step([0, 0, 0])[4]["failure"] is None  # plain numbers in a list are an action


def test_the_goal_envs_behaviour_must_be_a_name_or_an_integer_index():
    from affordance_env.goal_env import TapAffordanceGoalEnv

    env = TapAffordanceGoalEnv(camera_width=32, camera_height=24)
    env.reset(seed=0)
    for behavior in (np.nan, np.inf, None, True, 1j, b"tap", 1.5, -1, 5):
        with pytest.raises(ValueError, match=r"'behavior' must be an index in 0..4") as error:
            env.feasible(behavior, np.zeros(3))
        assert repr(behavior) in str(error.value)
    assert isinstance(env.feasible(np.int64(0), np.zeros(3)), bool) and isinstance(env.feasible(2.0, np.zeros(3)), bool)


def test_compute_reward_refuses_goals_that_are_not_positions_and_never_rewards_a_nan_goal():
    from affordance_env.goal_env import TapAffordanceGoalEnv

    env = TapAffordanceGoalEnv(camera_width=32, camera_height=24)
    assert env.compute_reward(np.zeros(2), np.zeros(2), {}) == 0.0  # reached
    assert env.compute_reward(np.zeros(2), np.array([np.nan, np.nan]), {}) == -1.0  # a goal without a place
    np.testing.assert_array_equal(env.compute_reward(np.zeros((3, 2)), np.full((3, 2), 0.5), {}), -np.ones(3))
    for achieved, desired, match in ((np.zeros(3), np.zeros(2), r"\(\.\.\., 2\) \[m\], got shapes \(3,\) and \(2,\)"),
                                     (np.zeros((3, 2)), np.zeros((4, 2)), "same length, got shapes"),
                                     ("ab", np.zeros(2), "achieved_goal must be positions")):
        with pytest.raises(ValueError, match=match):
            env.compute_reward(achieved, desired, {})


def test_the_planner_refuses_what_is_not_a_number_and_a_start_off_the_table(planner):
    with pytest.raises(ValueError, match="features must be the object's 49 feature values"):
        planner.choose(["a"] * N, Roll())
    with pytest.raises(ValueError, match=r"within \+-3.4e\+38 \(float32\)"):
        planner.choose(np.full(N, 1e39), Roll())
    with pytest.raises(ValueError, match="start_xy must be .* on the table top"):
        planner.choose(np.zeros(N), Roll(), start_xy=(5.0, 5.0))
    with pytest.raises(ValueError, match="target_xy must be .* on the table top"):
        planner.choose(np.zeros(N), Place((5.0, 5.0)), start_xy=(-0.3, 0.0))
    with pytest.raises(ValueError, match="Unknown behavior 'kick'"):
        planner.note_failure("kick", np.zeros(3))
    with pytest.raises(ValueError, match=r"params must be the behaviour's 3 finite parameters, or None, got shape "
                                         r"\(2,\)"):
        planner.note_failure("push", np.zeros(2))
    with pytest.raises(ValueError, match="tolerance must be a finite number, got 'x'"):
        planner.toward(np.zeros(N), (-0.3, 0.0), (-0.25, 0.0), "x")
    with pytest.raises(ValueError, match="random_state must be an integer >= 0"):
        Planner(planner.models, random_state=-1)


def test_predict_effect_refuses_an_action_or_features_that_are_not_real_numbers():
    for action in ("abc", {"a": 1}, [1j, 0, 0]):
        with pytest.raises(ValueError, match=r"action must be the behaviour's 3 parameters in \[-1, 1\]"):
            predict_effect(np.zeros(N), behavior="tap", action=action)
    with pytest.raises(ValueError, match="features must be real numbers"):
        predict_effect([[0.0] * N, [0.0] * (N - 1)], behavior="tap")
    with pytest.raises(ValueError, match=r"within \+-3.4e\+38 \(float32\)"):
        predict_effect(np.full(N, 1e39), behavior="tap")


def test_a_damaged_state_is_refused_before_anything_is_restored():
    import dataclasses

    env = TapAffordanceEnv(camera_width=32, camera_height=24)
    env.reset(seed=0)
    state = env.get_state()
    env.reset(seed=1)
    before = env.get_state()
    world = state.world
    for damaged, match in ((dataclasses.replace(state, rng={}), "random generator's state"),
                           (dataclasses.replace(state, world=dataclasses.replace(world, q_home=None)), "home posture"),
                           (dataclasses.replace(state, world=dataclasses.replace(world, initial="x")), "observation"),
                           (dataclasses.replace(state, world=dataclasses.replace(world, arm=["x"])), "robot model")):
        with pytest.raises(ValueError, match=match):
            env.set_state(damaged)
        np.testing.assert_array_equal(env.get_state().world.physics[1].qpos, before.world.physics[1].qpos)
        assert env.np_random.bit_generator.state == before.rng  # the generator put back too


def test_a_camera_too_large_to_allocate_and_a_reward_fn_that_is_no_function_are_refused_at_construction():
    with pytest.raises(ValueError, match=r"camera resolution must be integers in 2..4096, got width=20000"):
        gym.make("TapAffordance-v2", camera_width=20000, camera_height=20000)
    with pytest.raises(ValueError, match="reward_fn must be a function of the step's info"):
        TapAffordanceEnv(reward_fn=5)
    env = TapAffordanceEnv(camera_width=32, camera_height=24, reward_fn=lambda info: "high")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="reward_fn must return a number, returned 'high'"):
        env.step(np.zeros(3))


def test_a_fingerprint_file_that_is_not_a_fingerprint_is_refused_before_any_collection(tmp_path):
    import json

    from affordance_learning.paper.reproduce import check_fingerprint

    (tmp_path / "results.json").write_text(json.dumps({"config": {"behavior": "tap", "seed": 0}}))
    (tmp_path / "fingerprint.json").write_text(json.dumps([1, 2]))
    with pytest.raises(ValueError, match="fingerprint.json is not a fingerprint"):
        check_fingerprint(tmp_path)
