"""Pinocchio and MuJoCo read the same URDF: they agree on frames; the IK reaches the tap workspace."""

import mujoco
import numpy as np
import pytest

from affordance_env.behaviors import BEHAVIORS
from affordance_env.behaviors.grasp import grasp_orientation
from affordance_env.kinematics import Kinematics
from affordance_env.robot_model import ACTIVE_JOINTS, HELD_ARM_TORSO_RANGES
from affordance_env.scene import home_qpos


@pytest.fixture(scope="module")
def kinematics():
    return Kinematics()


def test_mujoco_and_pinocchio_agree_on_hand_and_head(model, kinematics):
    data = mujoco.MjData(model)
    qadr = [model.jnt_qposadr[model.joint(n).id] for n in ACTIVE_JOINTS]
    palm, head = model.site("palm").id, model.site("head").id
    rng = np.random.default_rng(1)
    worst = 0.0
    for _ in range(50):
        q = rng.uniform(kinematics.lower, kinematics.upper)
        data.qpos[qadr] = q
        mujoco.mj_kinematics(model, data)
        for site, pose in ((palm, kinematics.hand_pose(q)), (head, kinematics.head_pose(q))):
            worst = max(worst, np.linalg.norm(data.site_xpos[site] - pose.translation))
            np.testing.assert_allclose(data.site_xmat[site].reshape(3, 3), pose.rotation, atol=1e-6)
    assert worst < 1e-3


def test_ik_reaches_the_tap_workspace(kinematics):
    rng = np.random.default_rng(2)
    q_home = np.zeros(kinematics.nq)
    q_home[ACTIVE_JOINTS.index("r_shoulder_pitch")] = -0.6
    q_home[ACTIVE_JOINTS.index("r_shoulder_roll")] = 0.45
    q_home[ACTIVE_JOINTS.index("r_elbow")] = 1.2
    R = BEHAVIORS["tap"].R_world_hand
    reached = 0
    n = 200
    for _ in range(n):
        target = rng.uniform([-0.36, -0.05, -0.04], [-0.22, 0.20, 0.10])
        result = kinematics.solve_ik(target, q_home, R)
        assert np.all(result.q >= kinematics.lower - 1e-9) and np.all(result.q <= kinematics.upper + 1e-9)
        reached_pose = kinematics.hand_pose(result.q).translation
        # the reported error is the true error: a failure is never hidden
        assert np.linalg.norm(reached_pose - target) == pytest.approx(result.position_error, abs=1e-9)
        if result.success:
            assert result.position_error <= 1e-3
            reached += 1
    assert reached / n >= 0.95


def test_ik_keeps_to_narrower_joint_ranges(kinematics):
    q_home = np.zeros(kinematics.nq)
    q_home[ACTIVE_JOINTS.index("r_elbow")] = 1.2
    wrist = ACTIVE_JOINTS.index("r_wrist_yaw")
    ranges = {"r_wrist_yaw": (-0.35, -0.30)}  # the lower end lies beyond the joint's own limit: intersected
    lower, upper = kinematics.joint_limits(ranges)
    assert lower[wrist] == kinematics.lower[wrist] and upper[wrist] == -0.30
    result = kinematics.solve_ik(np.array([-0.30, 0.08, 0.0]), q_home, BEHAVIORS["tap"].R_world_hand,
                                 joint_ranges=ranges)
    assert result.success
    assert kinematics.lower[wrist] <= result.q[wrist] <= -0.30
    # without ranges, the limits are the model's
    assert kinematics.joint_limits(None)[0] is kinematics.lower
    assert kinematics.ik_lower is kinematics.lower and kinematics.ik_upper is kinematics.upper


def test_the_left_arms_ik_keeps_the_torso_off_the_held_right_arm():
    # in the scene with both arms, from home to 41 cm out, the unbounded grasp IK pitches the torso 46 degrees and
    # rolls it -28, which lowers the held right arm onto the table

    left = Kinematics(variant="two_arms_left")
    pitch, roll = left.joint_names.index("torso_pitch"), left.joint_names.index("torso_roll")
    lower, upper = left.joint_limits()
    assert lower is left.ik_lower and upper is left.ik_upper
    assert upper[pitch] == HELD_ARM_TORSO_RANGES["torso_pitch"][1] < left.upper[pitch]
    assert lower[roll] == HELD_ARM_TORSO_RANGES["torso_roll"][0] > left.lower[roll]
    home = home_qpos("two_arms_left")
    result = left.solve_ik(np.array([-0.41, 0.06, 0.0]), np.array([home[name] for name in left.joint_names]),
                           grasp_orientation(0.0))
    assert result.success and result.q[pitch] <= upper[pitch] and result.q[roll] >= lower[roll]
    with pytest.raises(ValueError, match="misses the limits the IK keeps to"):
        left.joint_limits({"torso_pitch": (0.7, 0.8)})


@pytest.mark.parametrize("ranges, match", [({"neck_yaw": (0.0, 0.1)}, "not a joint the IK moves"),
                                           ({"r_wrist_yaw": (0.5, 0.6)}, "misses the limits the IK keeps to")])
def test_bad_joint_ranges_raise(kinematics, ranges, match):
    with pytest.raises(ValueError, match=match):
        kinematics.solve_ik(np.array([-0.30, 0.08, 0.0]), np.zeros(kinematics.nq), joint_ranges=ranges)


def test_unreachable_target_is_reported_as_failure(kinematics):
    target = np.array([-2.0, 0.0, 0.0])
    result = kinematics.solve_ik(target, np.zeros(kinematics.nq), max_iterations=20)
    assert not result.success
    assert result.position_error > 1.0
    # the error reported is the one of the configuration returned, not of an earlier iterate
    reached = kinematics.hand_pose(result.q).translation
    assert result.position_error == pytest.approx(np.linalg.norm(target - reached), rel=1e-9)


def test_a_check_gives_up_on_a_target_out_of_reach_once_it_stands_still_and_answers_as_the_whole_budget(
        kinematics):
    q_home = np.zeros(kinematics.nq)
    q_home[ACTIVE_JOINTS.index("r_elbow")] = 1.2
    R = BEHAVIORS["tap"].R_world_hand
    accept = (0.005, 0.35)  # the behaviours' tolerances (motion.IK_POSITION_TOLERANCE, IK_ORIENTATION_TOLERANCE)
    rng = np.random.default_rng(3)
    saved, gave_up = 0, 0
    for target in rng.uniform([-0.60, -0.30, -0.10], [-0.10, 0.40, 0.30], (60, 3)):  # within reach and beyond
        full = kinematics.solve_ik(target, q_home, R)
        check = kinematics.solve_ik(target, q_home, R, give_up_beyond=accept)
        assert (full.position_error <= accept[0] and full.orientation_error <= accept[1]) == \
            (check.position_error <= accept[0] and check.orientation_error <= accept[1])
        if full.success:  # a target reached: the same solution, bit for bit
            assert np.array_equal(full.q, check.q) and full.iterations == check.iterations
        saved += full.iterations - check.iterations
        gave_up += check.iterations < full.iterations
        # the error reported is the one of the configuration returned
        reached = kinematics.hand_pose(check.q).translation
        assert check.position_error == pytest.approx(np.linalg.norm(target - reached), rel=1e-9)
    assert gave_up >= 5 and saved > 500  # of the 17 targets it misses, 8 stand still, after 47-112 iterations


@pytest.mark.parametrize("bad", [np.array([np.nan, 0, 0]), np.zeros(2)])
def test_bad_targets_raise(kinematics, bad):
    with pytest.raises(ValueError, match="p_world_target"):
        kinematics.solve_ik(bad, np.zeros(kinematics.nq))


def test_unknown_frame_lists_available_frames():
    with pytest.raises(ValueError, match="Available frames"):
        Kinematics(hand_frame="r_hnd")


def test_a_target_orientation_that_is_not_a_rotation_is_refused_even_after_a_good_one(kinematics):
    q = np.zeros(kinematics.nq)
    target = kinematics.hand_pose(q)
    kinematics.solve_ik(target.translation, q, target.rotation)  # checked once, then taken as known
    for bad in (2.0 * target.rotation, target.rotation[:, ::-1] * [1.0, 1.0, 1.1], np.eye(2)):
        with pytest.raises(ValueError, match="R_world_target must be a 3x3 rotation"):
            kinematics.solve_ik(target.translation, q, bad)
    kinematics.solve_ik(target.translation, q, target.rotation)
