"""TapAffordance-v0 as a user meets it: Gymnasium's checker, determinism, the paper's phenomenon, errors."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import affordance_env
from affordance_env.tap_env import TapAffordanceEnv


@pytest.fixture(scope="module")
def env():
    env = TapAffordanceEnv()
    yield env
    env.close()


# Accepted checker warnings: the features are unbounded real numbers (Box(-inf, inf)).
@pytest.mark.filterwarnings("ignore:.*Box observation space m..imum value is .?infinity")
def test_gym_make_and_check_env():
    env = gym.make("TapAffordance-v0", camera_width=48, camera_height=40)
    with_checker_warnings = check_env(env.unwrapped, skip_render_check=True)
    assert with_checker_warnings is None
    obs, info = env.reset(seed=3)
    assert obs["range"].shape == (40, 48) and obs["mask"].shape == (40, 48)
    assert obs["features"].shape == (len(affordance_env.FEATURE_NAMES),)
    env.close()


def test_module_colon_id_works():
    env = gym.make("affordance_env:TapAffordance-v0")
    assert isinstance(env.unwrapped, TapAffordanceEnv)
    env.close()


def test_same_seed_gives_bit_identical_interaction():
    results = []
    for _ in range(2):
        env = TapAffordanceEnv()
        obs0, info0 = env.reset(seed=11)
        obs1, reward, terminated, truncated, info1 = env.step(np.array([0.3, -0.2, 0.5], dtype=np.float32))
        results.append((obs0, info0, obs1, reward, info1))
        env.close()
    (a0, ai0, a1, ar, ai1), (b0, bi0, b1, br, bi1) = results
    for key in a0:
        np.testing.assert_array_equal(a0[key], b0[key])
        np.testing.assert_array_equal(a1[key], b1[key])
    assert ar == br
    np.testing.assert_array_equal(ai1["effect"], bi1["effect"])
    np.testing.assert_array_equal(ai1["object"]["final_pose"], bi1["object"]["final_pose"])
    assert ai1["rolled"] == bi1["rolled"] and ai1["outcome"] == bi1["outcome"]


def test_info_after_step(env):
    _, info0 = env.reset(seed=5)
    assert info0["object"]["type"] in affordance_env.OBJECT_TYPES
    assert 0.04 <= info0["object"]["size"] <= 0.10
    assert info0["attention"]["success"]
    obs, reward, terminated, truncated, info = env.step(np.zeros(3))
    assert terminated and not truncated
    assert info["effect"].shape == (49,) and np.all(np.isfinite(info["effect"]))
    np.testing.assert_allclose(info["effect"], info["final_features"] - info["initial_features"], rtol=1e-6)
    assert reward == pytest.approx(info["displacement"])
    assert info["ik"]["success"] and info["contact"]
    assert info["outcome"] in ("rest", "off_table", "timeout")


def test_step_before_reset_or_twice_raises():
    env = TapAffordanceEnv()
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros(3))
    env.reset(seed=0)
    env.step(np.zeros(3))
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros(3))


@pytest.mark.parametrize(
    "action, match",
    [(np.array([np.nan, 0, 0]), "finite"), (np.zeros(4), "shape"), (np.array([0, 1.5, 0]), r"\[-1, 1\]")],
)
def test_bad_actions_get_clear_errors(env, action, match):
    env.reset(seed=0)
    with pytest.raises(ValueError, match=match):
        env.step(action)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"behavior": "kick"}, "tap, tap_back, push"),
        ({"object_types": ("cube",)}, "Valid types"),
        ({"size_range": (0.08, 0.05)}, "size_range"),
        ({"render_mode": "human"}, "render_mode"),
    ],
)
def test_bad_options_get_clear_errors(kwargs, match):
    with pytest.raises(ValueError, match=match):
        TapAffordanceEnv(**kwargs)


def test_reward_fn_is_used():
    env = TapAffordanceEnv(reward_fn=lambda info: 1.0 if info["rolled"] else -1.0)
    env.reset(seed=1)
    _, reward, _, _, info = env.step(np.zeros(3))
    assert reward == (1.0 if info["rolled"] else -1.0)


@pytest.mark.slow
def test_tap_rolls_spheres_and_lying_cylinders_but_not_boxes_or_standing_cylinders():
    rates = {}
    for object_type in affordance_env.OBJECT_TYPES:
        env = TapAffordanceEnv(object_types=(object_type,), camera_width=32, camera_height=32)
        rolled = []
        for seed in range(20):
            env.reset(seed=seed)
            rolled.append(env.step(np.zeros(3))[4]["rolled"])
        rates[object_type] = np.mean(rolled)
    assert rates["sphere"] >= 0.9 and rates["horizontal_cylinder"] >= 0.9, rates
    assert rates["box"] <= 0.1 and rates["vertical_cylinder"] <= 0.1, rates


def test_async_vector_env():
    envs = gym.vector.AsyncVectorEnv(
        [lambda: gym.make("TapAffordance-v0", camera_width=32, camera_height=32) for _ in range(2)]
    )
    obs, infos = envs.reset(seed=[1, 2])
    assert obs["features"].shape == (2, 49)
    obs, rewards, terminated, truncated, infos = envs.step(np.zeros((2, 3), dtype=np.float32))
    assert terminated.all() and rewards.shape == (2,)
    envs.close()


def _rss_mib() -> float:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return float("nan")


@pytest.mark.slow
def test_many_interactions_no_memory_growth_no_home_drift():
    env = TapAffordanceEnv(camera_width=32, camera_height=32)
    arm = [affordance_env.ACTIVE_JOINTS.index(n) for n in affordance_env.robot_model.ARM_JOINTS]
    homes = []
    for i in range(400):
        obs, _ = env.reset(seed=i)
        homes.append(obs["joints"][arm])
        env.step(env.action_space.sample())
        if i == 99:
            rss_start = _rss_mib()
    growth = _rss_mib() - rss_start
    assert growth < 15.0, f"memory grew by {growth:.1f} MiB over 300 interactions"
    homes = np.array(homes)
    # every interaction starts from the same arm pose: the home pose does not drift
    assert np.abs(homes - homes[0]).max() < 1e-3


def test_physics_fault_is_reported_and_the_next_reset_recovers():
    env = TapAffordanceEnv(camera_width=32, camera_height=32)
    env.reset(seed=2)
    physics = env.physics
    start = physics.data.time

    def corrupt(p):  # an absurd state half a second into the interaction
        if p.data.time > start + 0.5:
            p.data.qvel[p.object_qvel] = np.inf
            p.on_step = None

    physics.on_step = corrupt
    obs, reward, terminated, truncated, info = env.step(np.zeros(3))
    assert terminated
    assert info["failure"].startswith("physics:")
    assert info["outcome"] == "fault"
    assert np.all(np.isfinite(info["effect"])) and not info["effect"].any()
    assert all(np.all(np.isfinite(v)) for v in obs.values())
    assert env.observation_space.contains(obs)
    # the next interaction is healthy and identical to one in a fresh env
    obs_a, _ = env.reset(seed=3)
    _, _, _, _, info_a = env.step(np.zeros(3))
    fresh = TapAffordanceEnv(camera_width=32, camera_height=32)
    obs_b, _ = fresh.reset(seed=3)
    _, _, _, _, info_b = fresh.step(np.zeros(3))
    assert info_a["failure"] is None
    np.testing.assert_array_equal(obs_a["features"], obs_b["features"])
    np.testing.assert_array_equal(info_a["effect"], info_b["effect"])


def test_a_missed_tap_is_reported():
    env = TapAffordanceEnv(camera_width=32, camera_height=32)
    env.reset(seed=0)
    hand = env.physics.hand_geoms
    env.physics.model.geom_contype[hand] = env.physics.model.geom_conaffinity[hand] = 0  # a ghost hand
    _, _, _, _, info = env.step(np.zeros(3))
    assert not info["contact"] and info["failure"].startswith("tap:")


def test_an_untouched_object_has_no_effect():
    # A ghost hand never touches the object: the initial and final snapshots then see the same scene from
    # the same, still head, so the shape and size effects vanish (only the hand-relation features may change).
    env = TapAffordanceEnv()
    env.reset(seed=1)
    hand = env.physics.hand_geoms
    env.physics.model.geom_contype[hand] = env.physics.model.geom_conaffinity[hand] = 0
    _, _, _, _, info = env.step(np.zeros(3))
    groups = np.array([affordance_env.FEATURE_GROUPS[n] for n in affordance_env.FEATURE_NAMES])
    assert info["displacement"] < 1e-4
    effect = np.abs(info["effect"])
    assert effect[groups == "shape"].max() < 0.02
    assert effect[groups != "relation"][4] < 10  # pixel count changes by a few pixels at most


def test_outcome_is_checked_before_the_timeout():
    env = TapAffordanceEnv(object_types=("box",), settle_timeout=0.05, camera_width=32, camera_height=32)
    env.reset(seed=0)
    _, _, _, _, info = env.step(np.zeros(3))
    assert info["outcome"] == "rest"


@pytest.mark.parametrize("behavior", ["tap_back", "push"])
def test_other_behaviors_run_and_flag_what_they_cannot_do(behavior):
    env = TapAffordanceEnv(behavior=behavior, camera_width=32, camera_height=32)
    valid = 0
    for seed in range(12):
        env.reset(seed=seed)
        _, _, _, _, info = env.step(np.zeros(3))
        assert info["behavior"] == behavior
        assert np.all(np.isfinite(info["effect"]))
        if info["failure"] is None:
            valid += 1
            assert info["contact"] and info["ik"]["success"]
        else:
            assert info["failure"].split(":")[0] in ("reach", "ik", "tap", "perception")
    assert valid >= 3  # push and tap_back fail their reach more often than tap (see README)


def test_a_toppled_box_is_not_rolled():
    from affordance_env.tap_env import _toppled

    upright = np.array([1.0, 0.0, 0.0, 0.0])
    on_its_side = np.array([np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0])  # 90 degrees about x
    spun = np.array([np.cos(0.5), 0.0, 0.0, np.sin(0.5)])  # turned about the vertical only
    assert _toppled("box", upright, on_its_side) and _toppled("vertical_cylinder", upright, on_its_side)
    assert not _toppled("box", upright, spun)
    assert not _toppled("sphere", upright, on_its_side)  # rolling spheres turn about horizontal axes
    # a high, fast tap on a tall standing cylinder may knock it over; it is then reported, never "rolled"
    env = TapAffordanceEnv(object_types=("vertical_cylinder",), size_range=(0.09, 0.10), camera_width=32,
                           camera_height=32)
    for seed in range(4):
        env.reset(seed=seed)
        info = env.step(np.array([1.0, 0.0, 1.0]))[4]
        assert not (info["toppled"] and info["rolled"])
