"""The grasp variant of the robot: the left arm with the fingered mk3 hand, in MuJoCo and in Pinocchio."""

import mujoco
import numpy as np
import pytest

from affordance_env.kinematics import Kinematics
from affordance_env.objects import object_geometry
from affordance_env.physics import TapPhysics
from affordance_env.robot_model import (
    ARM_JOINTS,
    HAND_COUPLINGS,
    HAND_DRIVEN_JOINTS,
    HAND_JOINTS,
    HAND_LINKS,
    LEFT_ARM_JOINTS,
    coupled_position,
    get_variant,
)
from affordance_env.scene import BACK_EMF, PHALANX_LINKS, SEEN_ROBOT_GEOM_GROUP, build_model, home_qpos, robot_spec

GRASP = get_variant("grasp")


@pytest.fixture(scope="module")
def grasp_model():
    return build_model("grasp")


@pytest.fixture(scope="module")
def grasp_kinematics():
    return Kinematics(variant="grasp")


def _touch(model, a, b):
    ct, ca = model.geom_contype, model.geom_conaffinity
    return bool((ct[a] & ca[b]) or (ct[b] & ca[a]))


def test_joints_actuators_and_home(grasp_model):
    model = grasp_model
    hinges = {model.joint(i).name for i in range(model.njnt) if model.jnt_type[i] == mujoco.mjtJoint.mjJNT_HINGE}
    assert hinges == set(GRASP.active_joints)
    assert len(GRASP.active_joints) == 3 + 3 + 7 + 11
    assert not hinges & set(ARM_JOINTS)  # the right arm is locked
    # a servo per motor, then the motors' back-EMF (scene.BACK_EMF), in the same order
    assert [model.actuator(i).name for i in range(model.nu)] == [*GRASP.actuated_joints,
                                                                 *(f"{n}{BACK_EMF}" for n in GRASP.actuated_joints)]
    assert set(GRASP.actuated_joints) == set(GRASP.active_joints) - set(HAND_COUPLINGS)
    assert len(HAND_DRIVEN_JOINTS) == 7
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    home = home_qpos("grasp")
    for name in GRASP.active_joints:
        assert data.qpos[model.jnt_qposadr[model.joint(name).id]] == pytest.approx(home[name])
    assert home["l_hand_metacarpus_joint"] > 0.8  # the thumb is turned under the palm, facing the fingers


def test_the_v25_left_hand_is_replaced_by_the_mk3_hand(grasp_model):
    model = grasp_model
    meshes = {model.mesh(model.geom_dataid[g]).name for g in range(model.ngeom)
              if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH}
    assert not any("sim_sea_2-5_l_hand_prt" in name for name in meshes)
    assert any("sim_l_hand_palm_naked_prt" in name for name in meshes)
    # the palm, which has no joint, is fused into l_hand and is all that link weighs now
    assert model.body_mass[model.body("l_hand").id] == pytest.approx(0.100139)
    for link in HAND_LINKS[1:]:
        assert model.body(link).id > 0


def test_hand_inertias_are_physical(grasp_model):
    model = grasp_model
    for link in ("l_hand", *HAND_LINKS[1:]):
        b = model.body(link).id
        inertia = np.sort(model.body_inertia[b])
        assert np.all(inertia > 0), link
        assert not np.any(np.isclose(inertia, 0.01)), link  # the URDF's placeholder is gone
        assert inertia[0] + inertia[1] >= inertia[2] * (1 - 1e-9), link  # triangle inequality
        # of the order of a solid of the link's mass and size (1-10 cm): m (1 mm)^2 < I < m (5 cm)^2
        assert model.body_mass[b] * 1e-6 < inertia[0] and inertia[2] < model.body_mass[b] * 2.5e-3, link
    palm = np.sort(model.body_inertia[model.body("l_hand").id])
    np.testing.assert_allclose(palm, [2.64e-5, 5.75e-5, 8.01e-5], rtol=0.02)
    tip = np.sort(model.body_inertia[model.body("l_hand_index_fingertip_link").id])
    np.testing.assert_allclose(tip, [5.44e-7, 1.69e-6, 1.69e-6], rtol=0.02)


def test_collisions_hand_touches_world_never_itself(grasp_model):
    model = grasp_model
    robot = [g for g in range(model.ngeom) if "_collision" in model.geom(g).name]
    body = {g: model.body(model.geom_bodyid[g]).name for g in robot}
    # the URDF link of each geom: a link without a joint is fused into its parent body, its geoms keep its name
    link = {g: model.geom(g).name.split("_collision")[0] for g in robot}
    hand = [g for g in robot if body[g] in GRASP.contact_links]
    assert {body[g] for g in hand} == set(GRASP.contact_links)
    table, sphere = model.geom("table_top").id, model.geom("object_sphere").id
    for a in robot:
        for b in robot:
            assert not _touch(model, a, b), (model.geom(a).name, model.geom(b).name)  # no self-contact
    for g in hand:
        assert _touch(model, g, table) and _touch(model, g, sphere)
    for g in set(robot) - set(hand):
        assert not _touch(model, g, table) and not _touch(model, g, sphere), body[g]
    fingertip = model.geom("l_hand_index_fingertip_link_collision").id
    assert model.geom_friction[fingertip][0] == pytest.approx(1.0) and model.geom_priority[fingertip] == 1
    # a phalanx collides through its capsule, and its mesh is only seen
    visual = [g for g in range(model.ngeom) if "_visual" in model.geom(g).name]
    link.update({g: model.geom(g).name.split("_visual")[0] for g in visual})
    assert {link[g] for g in visual} == set(PHALANX_LINKS)
    for g in visual:
        assert not _touch(model, g, table) and not _touch(model, g, sphere), link[g]
    # the left arm from the upper arm down is what the range camera casts (a phalanx: its mesh); the right arm is not
    for g in robot + visual:
        seen = model.geom_group[g] == SEEN_ROBOT_GEOM_GROUP
        visible = link[g] in GRASP.camera_visible_links or link[g] in HAND_LINKS
        assert seen == (visible and not (g in robot and link[g] in PHALANX_LINKS)), model.geom(g).name
    assert not any(link[g].startswith("r_") and model.geom_group[g] == SEEN_ROBOT_GEOM_GROUP for g in robot)


def test_phalanges_collide_through_capsules_that_span_their_meshes(grasp_model):
    model = grasp_model
    for phalanx in PHALANX_LINKS:
        mesh, capsule = model.geom(f"{phalanx}_visual").id, model.geom(f"{phalanx}_collision").id
        assert model.geom_type[mesh] == mujoco.mjtGeom.mjGEOM_MESH
        assert model.geom_type[capsule] == mujoco.mjtGeom.mjGEOM_CAPSULE
        R_link_mesh, R_link_capsule = np.empty(9), np.empty(9)
        mujoco.mju_quat2Mat(R_link_mesh, model.geom_quat[mesh])
        mujoco.mju_quat2Mat(R_link_capsule, model.geom_quat[capsule])
        start, count = model.mesh_vertadr[model.geom_dataid[mesh]], model.mesh_vertnum[model.geom_dataid[mesh]]
        p_link_mesh = model.mesh_vert[start : start + count] @ R_link_mesh.reshape(3, 3).T + model.geom_pos[mesh]
        radius, half_length = model.geom_size[capsule][:2]
        axis = R_link_capsule.reshape(3, 3)[:, 2]
        np.testing.assert_allclose(np.abs(axis), [1, 0, 0], atol=1e-12)  # along the phalanx, the link's x
        centre = model.geom_pos[capsule]
        capsule_low = centre - [half_length + radius, radius, radius]
        capsule_high = centre + [half_length + radius, radius, radius]
        # its ends where the mesh's are, and its surface across the pad (z) where the mesh's is
        np.testing.assert_allclose(capsule_low[[0, 2]], p_link_mesh.min(axis=0)[[0, 2]], atol=1e-9)
        np.testing.assert_allclose(capsule_high[[0, 2]], p_link_mesh.max(axis=0)[[0, 2]], atol=1e-9)
        # and as wide as the mesh within 1.5 mm (a phalanx is 16-18 mm wide and 16-19 mm thick)
        width = p_link_mesh.max(axis=0)[1] - p_link_mesh.min(axis=0)[1]
        assert abs(2 * radius - width) < 3e-3, phalanx


def test_couplings_name_the_real_joints(grasp_model):
    model = grasp_model
    assert model.neq == len(HAND_COUPLINGS)
    for e in range(model.neq):
        assert model.eq_type[e] == mujoco.mjtEq.mjEQ_JOINT
        distal = model.joint(model.eq_obj1id[e]).name
        proximal = model.joint(model.eq_obj2id[e]).name
        assert HAND_COUPLINGS[distal][0] == proximal
        np.testing.assert_allclose(model.eq_data[e, :5], HAND_COUPLINGS[distal][1])
    # the quartic fits reach the distal joints' limits when the proximal joints are at theirs
    for distal, (proximal, _) in HAND_COUPLINGS.items():
        upper = model.jnt_range[model.joint(proximal).id, 1]
        assert coupled_position(distal, upper) == pytest.approx(model.jnt_range[model.joint(distal).id, 1], abs=0.02)


def test_tap_variant_keeps_the_left_arm_locked_and_has_no_hand():
    spec = robot_spec("tap")
    names = {j.name for j in spec.joints}
    assert not names & set(LEFT_ARM_JOINTS) and not names & set(HAND_JOINTS)


def test_unknown_variant_lists_valid_ones():
    with pytest.raises(ValueError, match="tap, grasp"):
        build_model("pinch")


def test_mujoco_and_pinocchio_agree_on_the_grasp_palm_and_fingers(grasp_model, grasp_kinematics):
    model, kinematics = grasp_model, grasp_kinematics
    data = mujoco.MjData(model)
    qadr = [model.jnt_qposadr[model.joint(n).id] for n in kinematics.joint_names]
    palm = model.site("palm").id
    thumb_tip = kinematics.model.getFrameId("l_hand_thumb_fingertip_link")
    rng = np.random.default_rng(1)
    worst = 0.0
    for _ in range(50):
        q = rng.uniform(kinematics.lower, kinematics.upper)  # every active joint, fingers included
        data.qpos[qadr] = q
        mujoco.mj_kinematics(model, data)
        pose = kinematics.hand_pose(q)
        worst = max(worst, np.linalg.norm(data.site_xpos[palm] - pose.translation))
        np.testing.assert_allclose(data.site_xmat[palm].reshape(3, 3), pose.rotation, atol=1e-6)
        # the fingers too: the hand's joint order differs between the two, and is mapped by name
        tip = kinematics.frame_pose(q, thumb_tip).translation
        worst = max(worst, np.linalg.norm(data.xpos[model.body("l_hand_thumb_fingertip_link").id] - tip))
    assert worst < 1e-3


def test_distal_joints_follow_while_the_fingers_close_and_nothing_touches_itself(grasp_model):
    physics = TapPhysics(grasp_model, "grasp")
    physics.reset_home()
    joints = GRASP.active_joints
    q_open = physics.joint_targets()
    q_closed = q_open.copy()
    for name in ("l_hand_index_proximal_joint", "l_hand_medium_proximal_joint", "l_hand_pinky_proximal_joint",
                 "l_hand_thumb_proximal_joint"):
        q_closed[joints.index(name)] = physics.ctrl_high[GRASP.actuated_joints.index(name)]
    worst = 0.0
    robot_geoms = set(physics.hand_geoms.tolist())
    for k in range(1, 51):  # a 0.5 s ramp, as the grasp closes the hand
        physics.set_joint_targets(q_open + (q_closed - q_open) * k / 50)
        physics.step(5)
        q = physics.joint_positions()
        for distal, (proximal, _) in HAND_COUPLINGS.items():
            worst = max(worst, abs(q[joints.index(distal)] - coupled_position(distal, q[joints.index(proximal)])))
        for g1, g2 in physics.data.contact.geom[: physics.data.ncon]:
            assert not (g1 in robot_geoms and g2 in robot_geoms)
    assert np.degrees(worst) < 2.0
    physics.step(100)
    q = physics.joint_positions()
    assert q[joints.index("l_hand_index_proximal_joint")] > 1.5  # the fingers closed (no object in the way)
    assert q[joints.index("l_hand_index_distal_joint")] > 1.4
    assert physics.unstable() is None


@pytest.mark.parametrize("object_type", ["box", "horizontal_cylinder"])
def test_grasp_scene_steps_under_control_noise_and_objects_rest(object_type):
    physics = TapPhysics(build_model("grasp"), "grasp")  # its own model: set_object changes it
    assert physics.model.opt.timestep == pytest.approx(0.005)
    rng = np.random.default_rng(0)
    for size, yaw in ((0.042, 0.2), (0.07, -0.1)):  # a small lying cylinder is the one that could creep
        physics.reset_home()
        physics.set_object(object_geometry(object_type, size), np.array([-0.31, 0.04]), yaw)
        home = physics.joint_targets()
        physics.step(20)
        p0 = physics.object_pose()[:3]
        for _ in range(200):  # 2 s, the servos' targets jittered as in the tap scene's test
            physics.set_joint_targets(home + rng.normal(0.0, 0.02, home.shape))
            physics.step(2)
        assert physics.unstable() is None and all(w.number == 0 for w in physics.data.warning)
        assert np.linalg.norm(physics.object_pose()[:3] - p0) < 2e-4, (object_type, size)
        assert np.max(np.abs(physics.joint_positions() - home)) < 0.1
