"""TapAffordance-v2 as a user meets it: Gymnasium's checker, determinism, the paper's phenomenon, errors."""


import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import affordance_env
import affordance_env.world as world_module
from affordance_env.behaviors import stroke
from affordance_env.features import FEATURE_NAMES, effect_features
from affordance_env.options import EnvOptions
from affordance_env.range_noise import kinect_axial_sigma
from affordance_env.tap_env import TapAffordanceEnv
from affordance_env.workspace import in_workspace


@pytest.fixture(scope="module")
def env():
    env = TapAffordanceEnv()
    yield env
    env.close()


# Accepted checker warnings: the features are unbounded real numbers (Box(-inf, inf)).
@pytest.mark.filterwarnings("ignore:.*Box observation space m..imum value is .?infinity")
def test_gym_make_and_check_env():
    env = gym.make("TapAffordance-v2", camera_width=48, camera_height=40)
    with_checker_warnings = check_env(env.unwrapped, skip_render_check=True)
    assert with_checker_warnings is None
    obs, info = env.reset(seed=3)
    assert obs["range"].shape == (40, 48) and obs["mask"].shape == (40, 48)
    assert obs["features"].shape == (len(affordance_env.FEATURE_NAMES),)
    env.close()


def test_module_colon_id_works():
    env = gym.make("affordance_env:TapAffordance-v2")
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
    np.testing.assert_allclose(info["effect"], effect_features(info["initial_features"], info["final_features"]))
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
        ({"camera_width": 1}, "camera resolution"),
        ({"settle_timeout": 0.0}, "settle_timeout"),
        ({"range_noise": "lidar"}, "kinect_v1"),
        ({"size_range": ("small", "big")}, r"size_range must be \(low, high\) in metres, got \('small', 'big'\)"),
        ({"camera_fovy": "wide"}, "camera_fovy must be a vertical field of view in degrees, got 'wide'"),
        ({"position_range": "table"}, r"position_range must be one of \('canonical', 'workspace'\), got 'table'"),
    ],
)
def test_bad_options_get_clear_errors(kwargs, match, monkeypatch):
    with pytest.raises(ValueError, match=match):
        TapAffordanceEnv(**kwargs)
    # the data options alone are refused the same way, without building a model (as a collection checks them)
    if "render_mode" not in kwargs:
        monkeypatch.setattr(world_module, "build_model", lambda *a: pytest.fail("the check built a model"))
        with pytest.raises(ValueError, match=match):
            EnvOptions.checked(**kwargs)
        EnvOptions.checked(**{"behavior": "push", "camera_width": 32, "camera_height": 24})
        with pytest.raises(ValueError, match="colour"):
            EnvOptions.checked(colour="red")


def test_reward_fn_is_used():
    env = TapAffordanceEnv(reward_fn=lambda info: 1.0 if info["rolled"] else -1.0)
    env.reset(seed=1)
    _, reward, _, _, info = env.step(np.zeros(3))
    assert reward == (1.0 if info["rolled"] else -1.0)


@pytest.fixture(scope="module")
def canonical_taps():
    """80 canonical taps with the default camera: (type, info) of every valid interaction."""
    env = TapAffordanceEnv()
    taps = []
    for seed in range(80):
        env.reset(seed=seed)
        info = env.step(np.zeros(3))[4]
        assert info["failure"] is None, info["failure"]
        taps.append((info["object"]["type"], info))
    env.close()
    return taps


@pytest.mark.slow
def test_tap_rolls_spheres_and_lying_cylinders_and_they_stay_in_view(canonical_taps):
    rollable = [info for t, info in canonical_taps if t in ("sphere", "horizontal_cylinder")]
    other = [info for t, info in canonical_taps if t not in ("sphere", "horizontal_cylinder")]
    assert len(rollable) >= 25 and len(other) >= 25
    assert np.mean([i["rolled"] for i in rollable]) >= 0.9
    assert np.mean([i["rolled"] for i in other]) <= 0.1
    rolled = [i for _, i in canonical_taps if i["rolled"]]
    assert np.mean([i["outcome"] == "rest" and i["visible"] for i in rolled]) >= 0.85


@pytest.mark.slow
def test_effects_of_real_taps_carry_the_motion(canonical_taps):
    xyz = [FEATURE_NAMES.index(n) for n in ("mean_x", "mean_y", "mean_z")]
    seen = [i for _, i in canonical_taps if i["visible"]]
    travel = np.array([i["displacement"] for i in seen])
    moved = np.array([np.linalg.norm(i["effect"][xyz]) for i in seen])
    from scipy.stats import spearmanr

    assert spearmanr(travel, moved).statistic >= 0.8
    # A rolled object seen where it stopped: its effect is its motion, not minus its initial look
    for info in (i for i in seen if i["rolled"]):
        assert np.abs(info["effect"] + info["initial_features"]).max() > 0.05
        assert np.linalg.norm(info["effect"][xyz]) == pytest.approx(info["displacement"], rel=0.35)


def test_async_vector_env():
    envs = gym.vector.AsyncVectorEnv(
        [lambda: gym.make("TapAffordance-v2", camera_width=32, camera_height=32) for _ in range(2)]
    )
    obs, infos = envs.reset(seed=[1, 2])
    assert obs["features"].shape == (2, 49)
    obs, rewards, terminated, truncated, infos = envs.step(np.zeros((2, 3), dtype=np.float32))
    assert terminated.all() and rewards.shape == (2,)
    envs.close()


def test_every_vector_step_is_an_interaction():
    # gym.make_vec resets each env within the step that ends its one-interaction episode (AutoresetMode.SAME_STEP,
    # declared in the env's metadata): with Gymnasium's default, every second step would be a reset, reward 0.
    envs = gym.make_vec("TapAffordance-v2", 2, camera_width=32, camera_height=24)
    assert envs.metadata["autoreset_mode"] == gym.vector.AutoresetMode.SAME_STEP
    envs.reset(seed=0)
    objects = []
    for _ in range(3):
        obs, rewards, terminated, truncated, infos = envs.step(np.zeros((2, 3), dtype=np.float32))
        assert terminated.all() and not truncated.any()
        assert list(infos["final_info"]["behavior"]) == ["tap", "tap"]  # both envs ran an interaction ...
        assert np.all(rewards == infos["final_info"]["displacement"]) and np.all(rewards > 0)
        objects.append(tuple(infos["final_info"]["object"]["size"]))
        assert obs["features"].shape == (2, 49)  # ... and the observation is already the next object's
    assert len(set(objects)) == 3  # a new object every step
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
    assert effect[FEATURE_NAMES.index("pixel_count")] < 10  # a few pixels at most
    assert np.abs(effect[[FEATURE_NAMES.index(n) for n in ("mean_x", "mean_y", "mean_z")]]).max() < 1e-3


def test_outcome_is_checked_before_the_timeout():
    env = TapAffordanceEnv(object_types=("box",), settle_timeout=0.05, camera_width=32, camera_height=32)
    env.reset(seed=0)
    _, _, _, _, info = env.step(np.zeros(3))
    assert info["outcome"] == "rest"


@pytest.mark.parametrize("behavior", ["tap_back", "push", "draw"])
def test_other_behaviors_reach_their_stroke_and_move_the_object_their_way(behavior):
    # The canonical action over 60 seeds: at most 3 interactions (5 %) may fail, and each valid one moves the object
    # the way the behaviour strokes (tap_back: +y, push: -x, draw: +x; lying cylinders pushed end-on veer the most).
    env = TapAffordanceEnv(behavior=behavior, camera_width=32, camera_height=32)
    direction = env.behavior.direction
    failures, veered = [], []
    for seed in range(60):
        env.reset(seed=seed)
        _, _, _, _, info = env.step(np.zeros(3))
        assert info["behavior"] == behavior
        assert np.all(np.isfinite(info["effect"]))
        if info["failure"] is not None:
            failures.append((seed, info["failure"]))
            continue
        assert info["contact"] and info["ik"]["success"]
        travel = info["object"]["final_pose"][:2] - info["object"]["initial_pose"][:2]
        assert np.linalg.norm(travel) > 0.005, seed
        if not travel @ direction > 0.5 * np.linalg.norm(travel):
            veered.append((seed, info["object"]["type"], travel))
        if behavior == "draw":  # the draw brings every object at least 2 cm toward the robot
            assert travel[0] >= 0.02, (seed, travel)
    assert len(failures) <= 3, failures
    # a lying cylinder, pushed on its end by the back of the hand turned 15 degrees, may turn aside more than it
    # goes forward (3 of the 60 here: 2 cm aside, 1 cm forward), never anything else
    assert len(veered) <= 4 and all(t == "horizontal_cylinder" for _, t, _ in veered), veered
    assert not (behavior == "draw" and veered), veered


def test_a_stroke_started_off_its_pose_is_reported(monkeypatch):
    # The servos bring the hand within a few millimetres of the pre-stroke pose; asked for 10 micrometres, the
    # interaction is reported as a reach failure, not kept as a sample.
    env = TapAffordanceEnv(camera_width=32, camera_height=32)
    env.reset(seed=0)
    assert env.step(np.zeros(3))[4]["failure"] is None
    monkeypatch.setattr(stroke, "MAX_START_ERROR", 1e-5)
    env.reset(seed=0)
    info = env.step(np.zeros(3))[4]
    assert info["failure"].startswith("reach: the stroke started"), info["failure"]
    assert info["success"] is False


def test_the_first_touch_is_found_to_the_step_while_far_ticks_run_unwatched(monkeypatch):
    # Far from the object the stroke runs whole control ticks without a contact check after each step; the
    # touch, its time and the hand's speed are those found by watching every step of the stroke.
    import affordance_env.motion as motion

    def interactions():
        env = TapAffordanceEnv(camera_width=32, camera_height=24)
        out = []
        for seed, action in ((0, np.zeros(3)), (1, np.zeros(3)), (2, np.array([0.4, -0.6, 0.9]))):
            env.reset(seed=seed)
            info = env.step(action)[4]
            out.append((info["contact"], info["hand_speed"], info["effect"].tolist(), info["outcome_time"]))
        return out

    skipping = interactions()
    monkeypatch.setattr(motion, "CONTACT_WATCH_DISTANCE", np.inf)  # watch every step of the stroke
    assert all(contact for contact, *_ in skipping)
    assert interactions() == skipping


def test_the_stroke_steps_at_2_ms_and_the_rest_of_a_tap_at_the_free_timestep(env):
    # The impact is resolved at the scene's 2 ms: every step from the start of the stroke to the end of its
    # follow-through, the first touch among them; the head turning, the reach, the way home and the wait for the
    # object step at FREE_TIMESTEP, and the model keeps its own timestep between interactions.
    import affordance_env.motion as motion

    physics, seen = env.physics, []
    step = physics.step

    def recording(n: int = 1) -> None:
        step(n)
        seen.append((physics.model.opt.timestep, physics.hand_touches_object()))

    physics.step = recording
    try:
        env.reset(seed=0)
        in_reset = len(seen)
        assert env.step(np.zeros(3))[4]["contact"]
    finally:
        del physics.step
    timesteps = np.array([timestep for timestep, _ in seen])
    fine = np.flatnonzero(timesteps == 0.002)
    assert fine.size > 50 and fine[0] > in_reset and np.all(np.diff(fine) == 1)  # one block, inside step()
    assert np.all(np.delete(timesteps, fine) == motion.FREE_TIMESTEP) and fine[-1] < len(seen) - 50
    first_touch = next(i for i, (_, touching) in enumerate(seen) if touching)
    assert fine[0] < first_touch <= fine[-1]
    assert physics.model.opt.timestep == 0.002


def test_success_is_rolled_for_taps_and_moved_for_push():
    tap = TapAffordanceEnv(camera_width=32, camera_height=24)
    for object_type, succeeds in (("sphere", True), ("box", False)):  # a tapped ball rolls, a box slides
        tap.reset(seed=0, options={"object_type": object_type, "size": 0.06})
        info = tap.step(np.zeros(3))[4]
        assert info["failure"] is None
        assert type(info["success"]) is bool and info["success"] is info["rolled"] is succeeds
    # push: success is the displacement beyond roll_threshold, rolling or sliding; a pushed box slides about 1 cm
    for threshold, succeeds in ((0.03, False), (0.005, True)):
        push = TapAffordanceEnv(behavior="push", roll_threshold=threshold, camera_width=32, camera_height=24)
        push.reset(seed=0, options={"object_type": "box", "size": 0.06})
        info = push.step(np.zeros(3))[4]
        assert info["failure"] is None and not info["rolled"]
        assert 0.005 < info["displacement"] < 0.03
        assert type(info["success"]) is bool and info["success"] is succeeds
    push.reset(seed=0, options={"object_type": "sphere", "size": 0.06})
    info = push.step(np.zeros(3))[4]
    assert info["success"] and info["displacement"] > 0.03
    # a failed interaction is no success
    hand = push.physics.hand_geoms
    push.physics.model.geom_contype[hand] = push.physics.model.geom_conaffinity[hand] = 0  # a ghost hand
    push.reset(seed=0, options={"object_type": "sphere", "size": 0.06})
    info = push.step(np.zeros(3))[4]
    assert info["failure"].startswith("tap:") and info["success"] is False


def test_labels_come_from_the_motion_a_toppled_box_is_not_rolled():
    # On a grippy surface a hard, high tap tips a 6 cm box over its edge: it travels 9 cm, but by tipping, not
    # by rolling; a ball rolls. The labels say so from the measured motion, with no reference to the type.
    env = TapAffordanceEnv(camera_width=32, camera_height=24)
    model = env.physics.model
    for g in (env.physics.table_geom, *env.physics.object_geoms.values()):
        model.geom_friction[g, 0] = 1.5
    env.reset(seed=0, options={"object_type": "box", "size": 0.06})
    info = env.step(np.array([1.0, 0.0, 1.0]))[4]
    assert info["failure"] is None
    assert info["toppled"] and not info["rolled"], info
    assert info["tilt"] == pytest.approx(np.pi / 2, abs=0.2) and info["displacement"] > 0.05
    env.reset(seed=0, options={"object_type": "sphere", "size": 0.06})
    info = env.step(np.zeros(3))[4]
    assert info["rolled"] and not info["toppled"]
    assert info["rolling_distance"] > 0.8 * info["displacement"]


def test_leaving_the_table_is_measured_when_it_happens_not_when_the_arm_is_back(monkeypatch):
    # A hard tap sends a ball off the table's edge 40 cm away, about a second after the tap. With the arm going home
    # at once the ball leaves after the arm is back; with the arm waiting 1.5 s above before it goes home, the ball
    # has fallen by the final snapshot. Either way its travel is measured to the edge, where it left the table: the
    # same within a few millimetres, where its landing point would be some 10 cm further.
    travels, heights = [], []
    for wait in (0.0, 1.5):
        env = TapAffordanceEnv(camera_width=32, camera_height=24)
        go_home = env.motion.go_home

        def waiting_home(*args, _go_home=go_home, _env=env, _wait=wait, **kwargs):
            if _wait:
                _env.motion.hold(_wait)
            return _go_home(*args, **kwargs)

        monkeypatch.setattr(env.motion, "go_home", waiting_home)
        env.reset(seed=4, options={"object_type": "sphere", "size": 0.08, "position": (-0.3, -0.1)})
        info = env.step(np.array([0.0, 0.0, 1.0]))[4]
        assert info["outcome"] == "off_table" and info["failure"] is None, (info["outcome"], info["failure"])
        travels.append(info["displacement"])
        heights.append(info["object"]["final_pose"][2])
    low, _ = env.physics.table_extent()
    assert heights[0] > env.physics.table_top > heights[1] + 0.1  # at the edge, then fallen
    assert travels[0] == pytest.approx(travels[1], abs=5e-3)
    assert travels[0] == pytest.approx(-0.1 - low[1], abs=0.02)  # from y = -0.1 to the edge at y = low


def test_rest_is_detected_while_the_arm_withdraws():
    env = TapAffordanceEnv(camera_width=32, camera_height=24)
    env.reset(seed=0, options={"object_type": "box", "size": 0.06})
    info = env.step(np.zeros(3))[4]
    # the box stops a fraction of a second after the touch, long before the arm is home (over 0.5 s)
    assert info["outcome"] == "rest" and info["outcome_time"] < 0.4


def test_reset_options_place_the_chosen_object_and_unknown_keys_are_refused():
    env = TapAffordanceEnv(camera_width=32, camera_height=24)
    _, info = env.reset(seed=0, options={"object_type": "box", "size": 0.05, "position": (-0.35, 0.0),
                                         "yaw": 0.2})
    assert info["object"]["type"] == "box" and info["object"]["size"] == 0.05
    np.testing.assert_allclose(info["object"]["pose"][:2], [-0.35, 0.0], atol=2e-3)
    assert 2 * np.arctan2(info["object"]["pose"][6], info["object"]["pose"][3]) == pytest.approx(0.2, abs=1e-3)
    with pytest.raises(ValueError, match="object_type, size, position, yaw"):
        env.reset(seed=0, options={"colour": "red"})
    with pytest.raises(ValueError, match="on the table top"):
        env.reset(seed=0, options={"position": (-2.0, 0.0)})
    with pytest.raises(ValueError, match="Valid types"):
        env.reset(seed=0, options={"object_type": "cube"})
    with pytest.raises(ValueError, match=r"options must be a dict with keys among \('object_type', .*got 'sphere'"):
        env.reset(seed=0, options="sphere")
    with pytest.raises(ValueError, match="reset option 'size': .* got 'big'"):
        env.reset(seed=0, options={"size": "big"})
    with pytest.raises(ValueError, match="yaw must be a finite angle .* got 'left'"):
        env.reset(seed=0, options={"yaw": "left"})


@pytest.mark.parametrize("behavior", ["push", "grasp"])
def test_position_range_workspace_spreads_objects_over_the_behaviours_workspace(behavior):
    env = TapAffordanceEnv(behavior=behavior, camera_width=32, camera_height=24, position_range="workspace")
    canonical = TapAffordanceEnv(behavior=behavior, camera_width=32, camera_height=24)
    spread = np.array([env.reset(seed=i)[1]["object"]["pose"][:2] for i in range(12)])
    near = np.array([canonical.reset(seed=i)[1]["object"]["pose"][:2] for i in range(4)])
    assert np.all(np.abs(near - (-0.30, 0.03)) < 0.035)  # the default: within +-3 cm of the paper's spot
    assert np.all(in_workspace(behavior, spread))
    assert np.ptp(spread, axis=0).min() > 0.10  # over the workspace, not around one spot
    far = spread[np.abs(spread - (-0.30, 0.03)).max(axis=1) > 0.05]
    assert len(far) >= 6
    for i, xy in enumerate(spread[:4]):  # seen, and reachable, where they were placed
        _, info = env.reset(seed=i)
        assert info["visible"]
        _, _, _, _, info = env.step(np.zeros(3, np.float32))
        assert info["ik"]["success"], (xy, info["failure"])


def test_feasible_tells_from_the_kinematics_whether_the_step_will_reach():
    env = TapAffordanceEnv(behavior="push", camera_width=32, camera_height=24)
    for xy, reachable in (((-0.30, 0.0), True), ((-0.30, 0.30), False)):  # push cannot reach far to the left
        env.reset(seed=0, options={"object_type": "box", "size": 0.06, "position": xy})
        time = env.physics.data.time
        assert env.feasible(np.zeros(3)) is reachable
        assert env.physics.data.time == time  # no physics step
        _, _, _, _, info = env.step(np.zeros(3, np.float32))
        assert info["ik"]["success"] is reachable
    with pytest.raises(ValueError, match="behavior 'grasp' is not one of this world's: push"):
        env.world.feasible("grasp", np.zeros(3))


def test_feasible_refuses_a_stroke_whose_reach_sweeps_the_arm_into_the_object():
    env = TapAffordanceEnv(behavior="tap", position_range="workspace", camera_width=40, camera_height=30)
    env.reset(seed=91)  # a lying cylinder in the arm's way to the pre-stroke pose of this tap
    params = np.array([-0.35, 0.383, 0.004])
    assert not env.feasible(params)
    _, _, _, _, info = env.step(params.astype(np.float32))  # the IK reaches every pose, but ...
    assert info["ik"]["success"] and info["failure"].startswith("reach: the arm moved the object")


def test_feasible_refuses_a_reach_whose_targets_pass_within_a_few_millimetres_of_the_object(monkeypatch):
    # A push whose reach's targets pass 0.7 mm from a box on the way down: the arm, a millimetre or two behind its
    # targets, touches the box and moves it 7 mm before the stroke.
    import affordance_env.behaviors.stroke as stroke

    env = TapAffordanceEnv(behavior="push", position_range="workspace", camera_width=40, camera_height=30)
    params = np.array([0.9981, -0.4757, 0.6981])
    env.reset(seed=62)
    assert not env.feasible(params)
    monkeypatch.setattr(stroke, "REACH_CLEARANCE", 0.0)  # only no penetration of the targets asked: accepted
    assert env.feasible(params)
    _, _, _, _, info = env.step(params.astype(np.float32))
    assert info["ik"]["success"] and info["failure"].startswith("reach: the arm moved the object by 7.2 mm")


def test_an_object_out_of_view_is_searched_for_and_seen():
    env = TapAffordanceEnv(behavior="grasp", camera_width=32, camera_height=24)
    # 26 cm to the robot's left: outside the view of the head's first gaze, inside the grasp's workspace
    _, info = env.reset(seed=0, options={"object_type": "sphere", "size": 0.06, "position": (-0.32, 0.26)})
    assert info["visible"] and info["attention"]["visible"]


def test_gym_make_refuses_a_render_mode_the_env_lacks_naming_those_it_has():
    # not Gymnasium's HumanRendering wrapper (and its "pygame is not installed"): the env's own refusal
    with pytest.raises(ValueError, match=r"render_mode must be None or one of \['rgb_array', 'rgb_array_list'\], "
                                         "got 'human'"):
        gym.make("TapAffordance-v2", render_mode="human")


def test_range_noise_is_seeded_and_realistic():
    exact = TapAffordanceEnv(camera_width=64, camera_height=48)
    noisy = TapAffordanceEnv(camera_width=64, camera_height=48, range_noise="kinect_v1")
    obs_exact, _ = exact.reset(seed=2)
    obs_noisy, _ = noisy.reset(seed=2)
    again, _ = TapAffordanceEnv(camera_width=64, camera_height=48, range_noise="kinect_v1").reset(seed=2)
    np.testing.assert_array_equal(obs_noisy["range"], again["range"])  # same seed, same noise
    np.testing.assert_array_equal(obs_noisy["mask"], obs_exact["mask"])
    # the error of each pixel's depth, in units of the model's deviation for it, is a standard normal
    image = exact.camera.capture(exact.physics.data, normals=True)
    hit = np.isfinite(image.ranges)
    rays = (image.p_world_points[hit] - image.p_world_camera) / image.ranges[hit][:, None]
    cos_axis = -(rays @ image.R_world_camera[:, 2])
    depth = image.ranges[hit] * cos_axis
    incidence = np.arccos(np.clip(np.abs(np.sum(image.normals[hit] * rays, axis=1)), 0.0, 1.0))
    z_error = (obs_noisy["range"][hit] - obs_exact["range"][hit]) * cos_axis
    normalised = z_error / kinect_axial_sigma(depth, incidence)
    assert abs(np.mean(normalised)) < 0.05 and np.std(normalised) == pytest.approx(1.0, abs=0.05)
    assert 1.0e-3 < np.median(kinect_axial_sigma(depth, incidence)) < 2.0e-3  # about 1.2 mm at the table
    with pytest.raises(ValueError, match="kinect_v1"):
        TapAffordanceEnv(range_noise="lidar")


def test_a_snapshot_of_a_moving_robot_is_a_failure_not_a_sample():
    env = TapAffordanceEnv(camera_width=32, camera_height=24)
    _, info0 = env.reset(seed=0)
    assert info0["still"]
    physics = env.physics
    neck = physics.robot_qvel[affordance_env.ACTIVE_JOINTS.index("neck_yaw")]

    def shake_the_head(p):  # a disturbance the neck servo keeps fighting: the head never comes to rest
        p.data.qfrc_applied[neck] = 2.0 * np.sin(40.0 * p.data.time)

    physics.on_step = shake_the_head
    info = env.step(np.zeros(3))[4]
    assert info["failure"] is not None and info["failure"].startswith("snapshot: the robot was still moving at "
                                                                       "the final snapshot"), info["failure"]
    physics.on_step = None
    physics.data.qfrc_applied[:] = 0.0
    env.reset(seed=0)
    assert env.step(np.zeros(3))[4]["failure"] is None  # the same interaction, still: a valid sample


def test_kinect_noise_model_values():
    # Nguyen, Izadi and Lovell 2012: 0.0012 + 0.0019 (z - 0.4)^2 m head-on; steeply more at grazing incidence
    assert kinect_axial_sigma(0.4, 0.0) == pytest.approx(1.2e-3)
    assert kinect_axial_sigma(2.0, 0.0) == pytest.approx(1.2e-3 + 1.9e-3 * 1.6**2)
    assert kinect_axial_sigma(1.0, np.pi / 4) == pytest.approx(1.2e-3 + 1.9e-3 * 0.36 + 1e-4 * 1.0)
    assert kinect_axial_sigma(1.0, np.pi / 2) == kinect_axial_sigma(1.0, np.deg2rad(80.0))  # clipped, finite


def test_feasible_refuses_a_stroke_whose_reach_rests_the_forearm_on_the_table(monkeypatch):
    # A low tap_back near the robot's left, in the scene with both arms: the reach's servo targets put the forearm
    # 8.5 mm into the table; the forearm then rests on it and the stroke starts 15 mm off its pose.
    import affordance_env.behaviors.stroke as stroke

    env = TapAffordanceEnv(behavior="tap_back", two_arms=True, camera_width=32, camera_height=24)
    pose = (-0.23601, -0.10064, -0.04474, 1.0, 0.0, 0.0, 0.0)
    action = np.array([-0.6319, -0.1912, 0.4824])
    env.reset(seed=86, options={"object_type": "vertical_cylinder", "size": 0.0505, "object_pose": pose})
    assert not env.feasible(action)
    monkeypatch.setattr(stroke, "REACH_TABLE_PENETRATION", 1.0)  # the table not asked: the IK alone would accept it
    assert env.feasible(action)
    _, _, _, _, info = env.step(action.astype(np.float32))
    assert info["failure"].startswith("reach: the stroke started")
