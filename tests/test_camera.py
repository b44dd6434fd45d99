"""The ray-cast range camera and attention, against analytic ground truth."""

import math

import mujoco
import numpy as np
import pytest

from affordance_env.attention import attend
from affordance_env.camera import Intrinsics, RangeCamera
from affordance_env.kinematics import Kinematics
from affordance_env.motion import MotionExecutor
from affordance_env.objects import object_geometry
from affordance_env.tap_env import TapAffordanceEnv

WALL_SCENE = """
<mujoco>
  <worldbody>
    <camera name="cam" pos="0 0 0" xyaxes="1 0 0 0 1 0" fovy="60"/>
    <geom name="wall" type="box" size="2 2 0.01" pos="0 0 -{d}"/>
    <geom name="ball" type="sphere" size="0.1" pos="0.3 0.2 -{ball}"/>
  </worldbody>
</mujoco>
"""


@pytest.fixture(scope="module")
def wall():
    model = mujoco.MjModel.from_xml_string(WALL_SCENE.format(d=1.01, ball=0.8))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def test_range_of_a_plane_is_exact(wall):
    model, data = wall
    camera = RangeCamera(model, "cam", width=64, height=48)
    image = camera.capture(data)
    K = camera.intrinsics
    u, v = np.meshgrid(np.arange(K.width), np.arange(K.height))
    # a plane at z = -1 m (front face of the wall), seen head-on: range = 1 / cos(angle off axis)
    expected = np.sqrt(1.0 + ((u - K.cx) / K.fx) ** 2 + ((v - K.cy) / K.fy) ** 2)
    wall_pixels = image.mask_of(model.geom("wall").id)
    assert wall_pixels.sum() > 0.8 * K.width * K.height
    np.testing.assert_allclose(image.ranges[wall_pixels], expected[wall_pixels], atol=1e-3)
    # points lie on the plane, and project back onto their own pixel
    np.testing.assert_allclose(image.p_world_points[wall_pixels][:, 2], -1.0, atol=1e-6)
    for row, col in [(0, 0), (20, 30), (47, 63)]:
        if wall_pixels[row, col]:
            np.testing.assert_allclose(image.project(image.p_world_points[row, col]), [col, row], atol=1e-6)


def test_mask_of_a_sphere_matches_its_projection(wall):
    model, data = wall
    camera = RangeCamera(model, "cam", width=256, height=256)
    image = camera.capture(data)
    mask = image.mask_of(model.geom("ball").id)
    K = camera.intrinsics
    centre = np.array([0.3, 0.2, -0.8])
    d = np.linalg.norm(centre)
    # a sphere seen at angle theta off the optical axis images as an ellipse of area
    # pi (f r / sqrt(d^2 - r^2))^2 / cos(theta)^3 (small-angle sphere)
    cos_theta = 0.8 / d
    expected = np.pi * (K.fx * 0.1 / np.sqrt(d**2 - 0.1**2)) ** 2 / cos_theta**3
    assert mask.sum() == pytest.approx(expected, rel=0.02)
    np.testing.assert_allclose(image.project(centre), np.argwhere(mask).mean(axis=0)[::-1], atol=2.0)
    assert np.all(np.linalg.norm(image.p_world_points[mask] - centre, axis=1) == pytest.approx(0.1, abs=1e-6))


def test_no_hit_is_inf_and_nan():
    model = mujoco.MjModel.from_xml_string('<mujoco><worldbody><camera name="cam"/></worldbody></mujoco>')
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    image = RangeCamera(model, "cam", width=8, height=8).capture(data)
    assert np.all(np.isinf(image.ranges)) and np.all(image.geom_ids == -1)
    assert np.all(np.isnan(image.p_world_points))


@pytest.mark.parametrize(
    "kwargs, match",
    [({"camera": "eye"}, "Available cameras"), ({"width": 1}, "resolution"), ({"fovy_deg": 0.0}, "fovy"),
     ({"max_range": -1.0}, "max_range"), ({"geom_groups": (7,)}, "geom_groups")],
)
def test_bad_camera_arguments(wall, kwargs, match):
    with pytest.raises(ValueError, match=match):
        RangeCamera(wall[0], **{"camera": "cam", **kwargs})


def test_intrinsics_from_fovy():
    K = Intrinsics.from_fovy(128, 96, 90.0)
    assert K.fy == pytest.approx(48.0) and K.fx == K.fy
    assert (K.cx, K.cy) == (63.5, 47.5)


def test_attention_centres_the_object(physics):
    camera = RangeCamera(physics.model, width=32, height=32)
    motion = MotionExecutor(physics, Kinematics())
    physics.set_object(object_geometry("box", 0.06), np.array([-0.33, 0.0]), 0.0)
    result = attend(physics, camera, motion.move_joints)
    assert result.success and result.visible
    full = RangeCamera(physics.model, width=128, height=128).capture(physics.data)
    mask = full.mask_of(physics.active_geom)
    centroid = np.argwhere(mask).mean(axis=0)
    assert np.linalg.norm(centroid - 63.5) < 3.0  # pixels of the 128 x 128 image


def test_attention_searches_for_an_object_out_of_view_and_reports_one_it_cannot_find(physics):
    camera = RangeCamera(physics.model, width=32, height=32)
    motion = MotionExecutor(physics, Kinematics())
    physics.set_object(object_geometry("sphere", 0.05), np.array([-0.45, -0.30]), 0.0)  # far corner, out of view
    assert not camera.capture(physics.data).mask_of(physics.active_geom).any()
    result = attend(physics, camera, motion.move_joints)
    assert result.visible  # found by looking around
    physics.reset_home()
    physics.set_object(object_geometry("sphere", 0.05), np.array([-0.45, -0.30]), 0.0)
    physics.data.qpos[physics.object_qpos + 2] -= 0.5  # under the table: nowhere to be seen
    q_before = physics.joint_targets()
    result = attend(physics, camera, motion.move_joints)
    assert not result.visible and not result.success
    np.testing.assert_allclose(physics.joint_targets(), q_before, atol=1e-9)  # the head looks where it did


def _occluding_view(env, distance: float):
    """The env after reset with the palm moved onto the ray from the camera to the object, ``distance`` [m]
    before the object; returns (env camera image, image of a camera that sees no robot)."""
    physics = env.physics
    camera = env.camera
    p_cam, _ = camera.pose(physics.data)
    p_obj = physics.object_pose()[:3]
    target = p_obj + distance * (p_cam - p_obj) / np.linalg.norm(p_cam - p_obj)
    q = env.kinematics.solve_ik(target, physics.joint_positions(), position_tolerance=2e-3).q
    physics.data.qpos[physics.robot_qpos] = q
    mujoco.mj_forward(physics.model, physics.data)
    blind = RangeCamera(physics.model, width=camera.intrinsics.width, height=camera.intrinsics.height,
                        fovy_deg=57.4, geom_groups=(0,))
    return camera.capture(physics.data, occluded=physics.active_geom), blind.capture(physics.data)


def test_the_hand_occludes_the_object_as_on_a_real_camera():
    env = TapAffordanceEnv(camera_width=80, camera_height=60)
    env.reset(seed=0, options={"object_type": "box", "size": 0.08})
    seen, without_robot = _occluding_view(env, 0.08)
    geom = env.physics.active_geom
    hidden = without_robot.mask_of(geom) & ~seen.mask_of(geom)
    assert hidden.sum() > 0.3 * without_robot.mask_of(geom).sum()  # the hand hides much of the box ...
    assert seen.mask_of(geom).sum() > 0  # ... but not all of it: the mask is the visible part
    hand = set(env.physics.hand_geoms.tolist())
    assert set(np.unique(seen.geom_ids[hidden]).tolist()) <= hand  # what hides it is the hand, wrist, forearm
    assert np.all(seen.ranges[hidden] < without_robot.ranges[hidden])  # nearer than the box behind it
    # the same as casting the arm over the whole image, where the object is concerned
    everywhere = env.camera.capture(env.physics.data)
    np.testing.assert_array_equal(everywhere.geom_ids[without_robot.mask_of(geom)],
                                  seen.geom_ids[without_robot.mask_of(geom)])


def test_an_arm_that_hides_nothing_changes_nothing():
    env = TapAffordanceEnv(camera_width=80, camera_height=60)
    env.reset(seed=0, options={"object_type": "sphere", "size": 0.06})
    physics = env.physics
    # the arm lowered into view beside the object (home holds it out of view)
    for name, value in (("r_shoulder_pitch", -1.0), ("r_shoulder_roll", 0.45), ("r_elbow", 1.2)):
        physics.data.qpos[physics.model.jnt_qposadr[physics.model.joint(name).id]] = value
    mujoco.mj_forward(physics.model, physics.data)
    seen = env.world.look(env.np_random)
    everywhere = env.camera.capture(physics.data)
    blind = RangeCamera(physics.model, width=80, height=60, fovy_deg=57.4, geom_groups=(0,)).capture(physics.data)
    assert (everywhere.geom_ids != blind.geom_ids).any()  # the arm is in view at home, beside the object ...
    # ... and the observation, which casts it only where it could hide the object, is the world's exactly
    np.testing.assert_array_equal(seen.ranges, np.where(np.isfinite(blind.ranges), blind.ranges, 0.0))
    np.testing.assert_array_equal(seen.mask, blind.mask_of(physics.active_geom))


def _images_along_interactions(env, interactions, every=37):
    """The states (qpos, qvel) after reset and every ``every`` physics step calls of the interactions, each
    (reset options, action)."""
    physics = env.physics
    step, calls = physics.step, [0]
    states = []

    def counting_step(n=1):
        step(n)
        calls[0] += 1
        if calls[0] % every == 0:
            states.append((physics.data.qpos.copy(), physics.data.qvel.copy()))

    physics.step = counting_step
    try:
        for seed, (options, action) in enumerate(interactions):
            env.reset(seed=seed, options=options)
            states.append((physics.data.qpos.copy(), physics.data.qvel.copy()))
            env.step(action)
    finally:
        physics.step = step
    return states


def test_the_table_face_in_closed_form_gives_mujocos_image():
    # The env's camera intersects the table's top face in closed form; a camera that leaves every ray to MuJoCo
    # must see exactly the same image, with the object on the table, rolling off it, under the hand, and fallen.
    env = TapAffordanceEnv(camera_width=80, camera_height=60)
    mujoco_only = RangeCamera(env.physics.model, width=80, height=60, fovy_deg=57.4)
    interactions = [({"object_type": "box"}, np.zeros(3)), ({"object_type": "sphere"}, np.array([1.0, -1.0, 0.5])),
                    ({"object_type": "sphere", "size": 0.08, "position": (-0.3, -0.1)}, np.array([0.0, 0.0, 1.0]))]
    states = _images_along_interactions(env, interactions)
    data = env.physics.data
    assert not env.physics.object_on_table()  # the ball left the table ...
    env.physics.step(250)  # ... and falls to the floor
    states.append((data.qpos.copy(), data.qvel.copy()))
    faces = off_table = 0
    for qpos, qvel in states:
        data.qpos[:], data.qvel[:] = qpos, qvel
        mujoco.mj_forward(env.physics.model, data)
        for normals in (False, True):
            fast = env.camera.capture(data, normals=normals, occluded=env.physics.active_geom)
            slow = mujoco_only.capture(data, normals=normals, occluded=env.physics.active_geom)
            # the same geoms, float32 ranges and normals, and the object's points bit for bit; a face pixel's
            # float64 distance may differ from MuJoCo's box distance in its last bit
            np.testing.assert_array_equal(fast.geom_ids, slow.geom_ids)
            np.testing.assert_array_equal(fast.ranges, slow.ranges)
            mask = fast.mask_of(env.physics.active_geom)
            np.testing.assert_array_equal(fast.p_world_points[mask], slow.p_world_points[mask])
            if normals:
                np.testing.assert_array_equal(fast.normals, slow.normals)
        faces += (fast.geom_ids == env.physics.table_geom).mean() > 0.5
        off_table += not env.physics.object_on_table()
    assert faces == len(states) and off_table > 0  # the face was in view throughout, and an object fell


def test_a_support_that_is_not_an_axis_aligned_box_is_refused(wall):
    model, _ = wall
    with pytest.raises(ValueError, match="'ball' must be a box"):
        RangeCamera(model, "cam", width=8, height=8, support="ball")
    with pytest.raises(ValueError, match="no geom named 'table'"):
        RangeCamera(model, "cam", width=8, height=8, support="table")


def test_a_window_capture_sees_the_object_as_the_whole_image_does():
    # Attention looks only inside the object's image rectangle: its mask, ranges and points must be those of the
    # whole image, with the arm in front of the object, the object rolling and fallen, and nothing hit elsewhere.
    env = TapAffordanceEnv(camera_width=80, camera_height=60)
    geom = env.physics.active_geom
    interactions = [({"object_type": "box"}, np.zeros(3)), ({"object_type": "sphere"}, np.array([1.0, -1.0, 0.5])),
                    ({"object_type": "vertical_cylinder", "size": 0.08}, np.array([0.0, 0.0, 1.0]))]
    states = _images_along_interactions(env, interactions)
    data = env.physics.data
    seen = 0
    for qpos, qvel in states:
        data.qpos[:], data.qvel[:] = qpos, qvel
        mujoco.mj_forward(env.physics.model, data)
        geom = env.physics.active_geom
        whole = env.camera.capture(data, occluded=geom)
        window = env.camera.capture(data, occluded=geom, window=True)
        mask = whole.mask_of(geom)
        np.testing.assert_array_equal(window.mask_of(geom), mask)
        np.testing.assert_array_equal(window.ranges[mask], whole.ranges[mask])
        np.testing.assert_array_equal(window.p_world_points[mask], whole.p_world_points[mask])
        rectangle = np.zeros(mask.shape, bool)
        rectangle.flat[env.camera.culling.rays_near(np.array([geom]), data, *env.camera.pose(data))] = True
        assert mask[~rectangle].sum() == 0 and np.all(window.geom_ids[~rectangle] == -1)  # nothing cast outside
        assert np.all(window.geom_ids[rectangle] == whole.geom_ids[rectangle])
        seen += mask.sum() > 0
    assert seen > 0.5 * len(states)
    with pytest.raises(ValueError, match="give occluded"):
        env.camera.capture(data, window=True)


def test_the_rays_cast_for_a_ball_are_about_its_silhouette():
    # The object's rays are those inside both its box's image rectangle and its bounding sphere's cone: for a
    # ball, about its silhouette, where the rectangle of its bounding cube holds twice as many.
    env = TapAffordanceEnv()
    env.reset(seed=0, options={"object_type": "sphere", "size": 0.08})
    data, geom = env.physics.data, env.physics.active_geom
    rays = env.camera.culling.rays_near(np.array([geom]), data, *env.camera.pose(data))
    mask = env.camera.capture(data, occluded=geom).mask_of(geom)
    assert set(np.flatnonzero(mask).tolist()) <= set(rays.tolist())
    ((_, u0, u1, v0, v1),) = env.camera.culling.rectangles(np.array([geom]), data, *env.camera.pose(data))
    assert rays.size < 1.3 * mask.sum() and (u1 - u0) * (v1 - v0) > 1.6 * mask.sum()


def _rotations(rng: np.random.Generator, n: int) -> list[np.ndarray]:
    """``n`` rotation matrices: random ones, and signed permutations (exact zeros in every row)."""
    rotations = []
    for i in range(n):
        if i % 5 == 0:
            rotations.append(np.eye(3)[rng.permutation(3)] * rng.choice([-1.0, 1.0], 3))
        else:
            q = rng.normal(size=4)
            w, x, y, z = q / np.sqrt(np.sum(q * q))
            rotations.append(np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                                       [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                                       [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]))
    return rotations


def test_the_products_in_python_floats_are_linalg_s_bit_for_bit():
    # The camera computes a box's corners, a sphere's centre and distance, and a point's projection in Python
    # floats, in the order of einsum's sums (the loops linalg.matmul runs): the same bits as the array products,
    # signed zeros included, or an image would differ in a pixel at the edge of a rectangle or a cone.
    from affordance_env.culling import CORNERS, box_corners_camera
    from affordance_env.linalg import matmul, norm
    from affordance_env.pinhole import project, to_camera

    rng = np.random.default_rng(0)
    K = Intrinsics.from_fovy(33, 25, 57.4)
    for R, R_camera in zip(_rotations(rng, 400), _rotations(rng, 400), strict=True):
        aabb = np.concatenate([rng.normal(size=3) * rng.choice([0.0, 0.01]), rng.uniform(0.0, 0.2, 3)])
        x_geom, p_camera = rng.normal(size=3) * rng.choice([0.0, 0.5]), rng.normal(size=3)
        arrays = matmul(x_geom + np.einsum("ij,cj->ci", R, aabb[:3] + aabb[3:] * CORNERS) - p_camera, R_camera)
        floats = box_corners_camera(aabb.tolist(), R.ravel().tolist(), x_geom.tolist(), p_camera.tolist(),
                                    R_camera.ravel().tolist())
        np.testing.assert_array_equal(np.array(floats).view(np.int64), arrays.view(np.int64))
        centre = matmul(x_geom - p_camera, R_camera)
        c = to_camera(*x_geom.tolist(), p_camera.tolist(), R_camera.ravel().tolist())
        np.testing.assert_array_equal(np.array(c).view(np.int64), centre.view(np.int64))
        assert math.sqrt(((c[0] * c[0] + c[2] * c[2]) + c[1] * c[1]) + 0.0) == norm(centre)
        depth = -centre[2]
        expected = [np.nan, np.nan] if depth <= 1e-9 else [K.cx + K.fx * centre[0] / depth,
                                                            K.cy - K.fy * centre[1] / depth]
        np.testing.assert_array_equal(project(x_geom, p_camera, R_camera, K), expected)
        # a ray's cosine to an axis, as the cone of a sphere takes it, on the rays' x, z, y planes, in windows
        axis = centre / norm(centre)
        rays = K.ray_directions()
        xzy = np.ascontiguousarray(rays.transpose(2, 0, 1)[[0, 2, 1]])
        v0, u0 = rng.integers(0, K.height), rng.integers(0, K.width)
        v1, u1 = rng.integers(v0 + 1, K.height + 1), rng.integers(u0 + 1, K.width + 1)
        np.testing.assert_array_equal(np.einsum("ijk,i->jk", xzy[:, v0:v1, u0:u1], axis[[0, 2, 1]]).view(np.int64),
                                      matmul(rays[v0:v1, u0:u1], axis).view(np.int64))


def test_locate_gives_the_window_capture_s_object_pixels_and_points():
    # What attention looks at: the pixels and points of the object in a window capture, bit for bit, with the
    # arm in front of the object and the object out of view.
    env = TapAffordanceEnv(camera_width=40, camera_height=30)
    interactions = [({"object_type": "box"}, np.zeros(3)), ({"object_type": "sphere"}, np.array([1.0, -1.0, 0.5]))]
    states = _images_along_interactions(env, interactions, every=53)
    data, camera = env.physics.data, env.camera  # a 40 x 30 camera like the attention's
    seen = 0
    for qpos, qvel in states:
        data.qpos[:], data.qvel[:] = qpos, qvel
        mujoco.mj_forward(env.physics.model, data)
        geom = env.physics.active_geom
        image = camera.capture(data, occluded=geom, window=True)
        mask = image.mask_of(geom)
        pixels, points = camera.locate(data, geom)
        np.testing.assert_array_equal(pixels, np.flatnonzero(mask))
        np.testing.assert_array_equal(points.view(np.int64), image.p_world_points[mask].view(np.int64))
        assert points.flags.c_contiguous  # summed row after row, as p_world_points[mask] is
        seen += pixels.size > 0
    assert 0 < seen


SUPPORT_SCENE = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1" pos="0 0 0"/>
    <geom name="table" type="box" size="0.4 0.5 0.02" pos="0 0 0.5"/>
    {post}
    <body name="ball" pos="-0.05 0.05 0.56">
      <freejoint/>
      <geom name="ball" type="sphere" size="0.04"/>
    </body>
    <camera name="above" pos="0.7 0 1.1" xyaxes="0 1 0 -0.6 0 0.8" fovy="60"/>
    <camera name="below" pos="0.7 0 0.515" xyaxes="0 1 0 -0.15 0 1" fovy="60"/>
  </worldbody>
</mujoco>
"""


@pytest.mark.parametrize("camera", ["above", "below"])
@pytest.mark.parametrize("static_post", [True, False])
def test_the_support_face_gives_mujocos_image_beside_a_fixed_geom_and_from_below(camera, static_post):
    # A geom of group 0 fixed to the world beside the object (the rays near it are cast among all of group 0, not
    # among the moving bodies alone), and a camera below the face (which never sees its top: every ray is cast):
    # the closed-form face must give the image MuJoCo gives alone.
    box = '<geom name="post" type="box" size="0.03 0.03 0.06"/>'
    # a post fixed to the world, or on a body of its own (then every geom beside the face moves)
    where = 'pos="0.12 -0.1 0.58"'
    xml = box.replace("/>", f" {where}/>") if static_post else f"<body {where}><freejoint/>{box}</body>"
    model = mujoco.MjModel.from_xml_string(SUPPORT_SCENE.format(post=xml))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    ball, post = model.geom("ball").id, model.geom("post").id
    fast = RangeCamera(model, camera, width=64, height=48, geom_groups=(0,), support="table")
    slow = RangeCamera(model, camera, width=64, height=48, geom_groups=(0,))
    for normals in (False, True):
        a = fast.capture(data, normals=normals, occluded=ball)
        b = slow.capture(data, normals=normals, occluded=ball)
        np.testing.assert_array_equal(a.geom_ids, b.geom_ids)
        np.testing.assert_array_equal(a.ranges, b.ranges)
        mask = a.mask_of(ball)
        np.testing.assert_array_equal(a.p_world_points[mask], b.p_world_points[mask])
        if normals:
            np.testing.assert_array_equal(a.normals, b.normals)
    assert {ball, post} <= set(np.unique(a.geom_ids).tolist())  # both are in view ...
    on_table = a.p_world_points[a.geom_ids == model.geom("table").id]
    top = fast.ray_caster.support[1]
    assert (np.abs(on_table[:, 2] - top) < 1e-9).any() == (camera == "above")  # ... and the face only from above
