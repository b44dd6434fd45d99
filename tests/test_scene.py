"""The simulated world: the iCub URDF made simulable, named, stable, and the objects of the paper."""

import mujoco
import numpy as np
import pytest

from affordance_env.objects import OBJECT_TYPES, object_geometry
from affordance_env.physics import TapPhysics
from affordance_env.robot_model import ACTIVE_JOINTS, CONTACT_LINKS, HELD_ARM_TORSO_RANGES, get_variant
from affordance_env.scene import BACK_EMF, build_model, table_extent
from affordance_env.scene_index import as_slice
from affordance_env.table import table_extent as table_extent_read


def test_every_element_is_named(model):
    kinds = {
        "body": (model.nbody, mujoco.mjtObj.mjOBJ_BODY),
        "joint": (model.njnt, mujoco.mjtObj.mjOBJ_JOINT),
        "geom": (model.ngeom, mujoco.mjtObj.mjOBJ_GEOM),
        "camera": (model.ncam, mujoco.mjtObj.mjOBJ_CAMERA),
        "actuator": (model.nu, mujoco.mjtObj.mjOBJ_ACTUATOR),
        "site": (model.nsite, mujoco.mjtObj.mjOBJ_SITE),
    }
    for kind, (count, obj) in kinds.items():
        assert count > 0, kind
        for i in range(count):
            name = mujoco.mj_id2name(model, obj, i)
            if kind == "body" and i == 0:
                assert name == "world"
            assert name, f"{kind} {i} has no name"


def test_actuated_joints_and_home_keyframe(model):
    servos_then_back_emf = [*ACTIVE_JOINTS, *(f"{n}{BACK_EMF}" for n in ACTIVE_JOINTS)]
    assert [model.actuator(i).name for i in range(model.nu)] == servos_then_back_emf
    assert model.key("home").id == 0
    hinge_names = [model.joint(i).name for i in range(model.njnt) if model.jnt_type[i] == mujoco.mjtJoint.mjJNT_HINGE]
    assert hinge_names == list(ACTIVE_JOINTS)


def test_robot_never_collides_with_itself(model):
    robot_geoms = [g for g in range(model.ngeom) if model.geom(g).name.endswith("_collision")]
    assert len(robot_geoms) > 10
    for a in robot_geoms:
        for b in robot_geoms:
            touches = (model.geom_contype[a] & model.geom_conaffinity[b]) or (
                model.geom_contype[b] & model.geom_conaffinity[a]
            )
            assert not touches, (model.geom(a).name, model.geom(b).name)
    table = model.geom("table_top").id
    hand_geoms = [g for g in robot_geoms if model.body(model.geom_bodyid[g]).name in CONTACT_LINKS]
    assert hand_geoms
    def touch(a, b):
        ct, ca = model.geom_contype, model.geom_conaffinity
        return bool((ct[a] & ca[b]) or (ct[b] & ca[a]))

    floor, sphere = model.geom("floor").id, model.geom("object_sphere").id
    for g in hand_geoms:
        assert touch(g, table) and touch(g, sphere)  # the hand rests on the table and taps the object
        assert not touch(g, floor)
    assert touch(sphere, table) and touch(sphere, floor)  # objects rest on the table, and fall to the floor


def test_the_table_read_from_the_xml_is_the_compiled_scenes():
    # affordance_env.table reads the table top from assets/scene.xml without MuJoCo: the same numbers, exactly.
    assert table_extent_read() == table_extent()


def test_a_rotated_table_is_refused_not_misread(tmp_path, monkeypatch):
    import affordance_env.table as table

    scene = (table.assets_dir() / "scene.xml").read_text()
    (tmp_path / "scene.xml").write_text(scene.replace('<body name="table" pos="-0.46 0 -0.085">',
                                                      '<body name="table" pos="-0.46 0 -0.085" euler="0 0 0.3">'))
    monkeypatch.setattr(table, "assets_dir", lambda: tmp_path)
    table.table_extent.cache_clear()
    try:
        with pytest.raises(ValueError, match="body 'table' rotated"):
            table.table_extent()
    finally:
        table.table_extent.cache_clear()


def test_the_table_is_finite_and_objects_fall_off_its_edge(physics):
    low, high = physics.table_extent()
    assert 0.5 <= high[0] - low[0] <= 0.9 and 0.8 <= high[1] - low[1] <= 1.6  # a lab table's size [m]
    geometry = object_geometry("sphere", 0.05)
    physics.set_object(geometry, np.array([-0.4, low[1] + 0.03]), 0.0)
    physics.step(50)
    assert physics.object_on_table()
    physics.data.qvel[physics.object_qvel + 1] = -0.5  # roll it over the edge at y = low
    physics.step(500)
    p = physics.object_pose()[:3]
    assert not physics.object_on_table() and p[1] < low[1]
    assert p[2] == pytest.approx(model_floor_height(physics) + geometry.half_height, abs=2e-3)  # on the floor


def model_floor_height(physics) -> float:
    floor = physics.model.geom("floor").id
    return float(physics.data.geom_xpos[floor][2])


@pytest.mark.parametrize("object_type", OBJECT_TYPES)
def test_scene_steps_two_seconds_under_control_noise_without_warnings(object_type):
    physics = TapPhysics(build_model())
    physics.reset_home()
    physics.set_object(object_geometry(object_type, 0.07), np.array([-0.30, 0.03]), 0.1)
    rng = np.random.default_rng(0)
    home = physics.joint_targets()
    n = round(2.0 / physics.model.opt.timestep)
    for _ in range(0, n, 10):
        physics.set_joint_targets(home + rng.normal(0.0, 0.02, home.shape))
        physics.step(10)
    assert physics.unstable() is None
    assert all(w.number == 0 for w in physics.data.warning)
    assert physics.object_on_table()
    # the object rests where it was put; the robot stays near home
    assert np.linalg.norm(physics.object_pose()[:2] - [-0.30, 0.03]) < 0.01
    assert np.max(np.abs(physics.joint_positions() - home)) < 0.1


def test_objects_rest_on_the_table(physics):
    for object_type in OBJECT_TYPES:
        for size in (0.04, 0.045, 0.10):
            geometry = object_geometry(object_type, size)
            physics.reset_home()
            physics.set_object(geometry, np.array([-0.3, 0.03]), 0.0)
            p0 = physics.object_pose()[:3]
            physics.step(2500)  # 5 s: with a coarse convex collider a small lying cylinder creeps along
            assert np.linalg.norm(physics.object_pose()[:3] - p0) < 1e-3, (object_type, size)
            assert physics.object_speed() < 1e-3
            assert abs(p0[2] - physics.table_top - geometry.half_height) < 2e-3


def test_a_lying_cylinder_left_alone_does_not_creep(physics):
    # Placements and yaws as the environment draws them. With MuJoCo's default convex-collision tolerance
    # the contacts of a small cylinder sit 0.15 mm off its centre at some of these, and it rolls away by
    # itself (up to 1.4 mm in 5 s here).
    rng = np.random.default_rng(0)
    creep = []
    for size in (0.04, 0.042, 0.1):
        for _ in range(4):
            xy = np.array([-0.30, 0.03]) + rng.uniform(-0.03, 0.03, 2)
            physics.reset_home()
            physics.set_object(object_geometry("horizontal_cylinder", size), xy, rng.uniform(-0.25, 0.25))
            physics.step(100)
            p0 = physics.object_pose()[:3]
            physics.step(2500)  # 5 s
            creep.append(np.linalg.norm(physics.object_pose()[:3] - p0))
    assert max(creep) < 1e-3, max(creep)


def test_set_object_keeps_robot_state(physics):
    q = physics.joint_positions()
    physics.set_object(object_geometry("box", 0.05), np.array([-0.3, 0.03]), 0.0)
    np.testing.assert_array_equal(physics.joint_positions(), q)


def test_object_geometry_sizes_and_mass():
    sphere = object_geometry("sphere", 0.06)
    assert sphere.geom_size[0] == pytest.approx(0.03)
    assert sphere.mass == pytest.approx(300 * 4 / 3 * np.pi * 0.03**3)
    assert sphere.inertia == pytest.approx(np.full(3, 0.4 * sphere.mass * 0.03**2))
    box = object_geometry("box", 0.06)
    assert box.mass == pytest.approx(300 * 0.06**3)
    assert box.inertia == pytest.approx(np.full(3, box.mass * 0.06**2 / 6))
    lying = object_geometry("horizontal_cylinder", 0.06)
    standing = object_geometry("vertical_cylinder", 0.06)
    assert lying.primitive == standing.primitive == "cylinder"
    assert lying.mass == standing.mass == pytest.approx(300 * np.pi * 0.03**2 * 0.06)
    across = lying.mass * (3 * 0.03**2 + 0.06**2) / 12
    assert lying.inertia == pytest.approx([across, across, 0.5 * lying.mass * 0.03**2])  # axis is the body z
    assert not np.allclose(lying.quat_rest, standing.quat_rest)


@pytest.mark.parametrize("bad", ["cube", "Sphere", ""])
def test_unknown_object_type_lists_valid_choices(bad):
    with pytest.raises(ValueError, match="sphere, box, horizontal_cylinder, vertical_cylinder"):
        object_geometry(bad, 0.05)


@pytest.mark.parametrize("bad", [0.0, -0.05, float("nan"), float("inf")])
def test_non_positive_or_non_finite_size_is_refused(bad):
    with pytest.raises(ValueError, match="size"):
        object_geometry("box", bad)


@pytest.mark.parametrize("variant", ["tap", "grasp"])
def test_joint_queries_follow_the_simulation_in_every_variant(variant):
    # The robot's joint positions, velocities and targets are read from the live state at every call, whatever
    # the layout of the variant's joints in MuJoCo's arrays (the grasp's are not one run of indices).
    physics = TapPhysics(build_model(variant), variant)
    physics.reset_home()
    q = physics.joint_targets()
    q[: len(q) // 2] += 0.2
    physics.set_joint_targets(q)
    for _ in range(3):
        physics.step(5)
        np.testing.assert_array_equal(physics.joint_velocities(), physics.data.qvel[physics.robot_qvel])
        np.testing.assert_array_equal(physics.joint_positions(), physics.data.qpos[physics.robot_qpos])
    assert np.abs(physics.joint_velocities()).max() > 0.1  # the robot moves


def test_robot_indices_become_a_slice_only_where_they_run_one_after_another_upward():
    # A slice indexes a view of the data; indices in any other order must stay as they are, or a control tick
    # would read and write other joints' entries.
    assert as_slice(np.array([4, 5, 6])) == slice(4, 7)
    for indices in (np.array([4, 6, 7]), np.array([6, 5, 4]), np.array([3, 3]), np.array([], dtype=int)):
        assert as_slice(indices) is indices


def test_the_held_right_arm_stays_above_the_table_within_the_left_arms_torso_ranges():
    # HELD_ARM_TORSO_RANGES' claim: anywhere in the box (5 degree steps, every yaw) the held arm's collision meshes
    # stay at least 1.4 cm above the table top; beyond it (the 49 degrees and -29 an unbounded grasp IK asked for)
    # its forearm is in the table
    assert get_variant("two_arms_left").ik_ranges == HELD_ARM_TORSO_RANGES
    model = build_model("two_arms_left")
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    table = model.geom("table_top").id
    chest = model.body("chest").id
    held = [g for g in range(model.ngeom) if model.geom_bodyid[g] == chest and model.geom_contype[g]]
    assert len(held) == 3  # the right forearm, wrist and hand
    adr = {name: model.joint(name).qposadr[0] for name in ("torso_pitch", "torso_roll", "torso_yaw")}
    (_, pitch_max), (roll_min, _) = HELD_ARM_TORSO_RANGES["torso_pitch"], HELD_ARM_TORSO_RANGES["torso_roll"]

    def clearance(pitch: float, roll: float, yaw: float) -> float:
        data.qpos[adr["torso_pitch"]], data.qpos[adr["torso_roll"]], data.qpos[adr["torso_yaw"]] = pitch, roll, yaw
        mujoco.mj_kinematics(model, data)
        return min(mujoco.mj_geomDistance(model, data, g, table, 0.5, None) for g in held)

    lower, upper = model.jnt_range[model.joint("torso_pitch").id]
    box = [clearance(p, r, y) for p in np.arange(lower, pitch_max + 1e-9, np.radians(5.0))
           for r in np.arange(roll_min, model.jnt_range[model.joint("torso_roll").id][1] + 1e-9, np.radians(5.0))
           for y in np.radians(np.arange(-50.0, 50.1, 5.0))]
    assert min(box) > 0.0135
    assert clearance(np.radians(49.0), np.radians(-29.0), np.radians(8.0)) < 0.0
