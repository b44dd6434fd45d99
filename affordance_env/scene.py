"""Build the MuJoCo model: the iCub from its URDF, attached into the table scene of ``assets/scene.xml``.

Every step that changes the URDF robot is listed in ``assets/README.md``; :func:`build_spec` is that list in code.
"""

from __future__ import annotations

import mujoco
import numpy as np

from affordance_env.assets_path import assets_dir
from affordance_env.robot_model import (
    ACTIVE_JOINTS,
    ARM_JOINTS,
    CONTACT_LINKS,
    HAND_FRAME,
    HEAD_FRAME,
    NECK_JOINTS,
    TORSO_JOINTS,
    icub_urdf,
)

_PREFIX = "icub:"

#: Collision bits (see assets/scene.xml): robot links in CONTACT_LINKS are type 2 (the object takes 2) and take
#: 4 (the table box), so they touch the object and the table but never each other; other robot geoms touch nothing.
ROBOT_CONTYPE, ROBOT_CONAFFINITY = 2, 4

#: Geom groups (the world's geoms are in group 0; MuJoCo's renderer draws groups 0-2): the robot's parts that
#: the head's range camera can see, the right arm from the upper arm down, are in SEEN_ROBOT_GEOM_GROUP; the rest
#: of the robot, which the camera never sees (torso, head, the hanging left arm), is in ROBOT_GEOM_GROUP and is
#: not ray cast: with it the range image costs six times as much and looks the same.
ROBOT_GEOM_GROUP, SEEN_ROBOT_GEOM_GROUP = 1, 2
#: URDF links of the arm that can come into the camera's view.
CAMERA_VISIBLE_LINKS: tuple[str, ...] = ("r_upper_arm", "r_elbow_1", "r_forearm", "r_wrist_1", "r_hand")

#: Sliding friction of the hand's contact geoms (they take priority over the object's friction).
HAND_FRICTION = 0.3

#: Position-servo stiffness per joint group [N m / rad].
SERVO_KP: dict[str, float] = {"torso": 300.0, "neck": 50.0, "arm": 60.0, "wrist": 10.0}
#: Joint armature added for a stable servo [kg m^2].
ARMATURE = 0.02
#: Joint damping [N m s / rad]: a small viscous friction. The servos are critically damped by their actuators;
#: 1 N m s/rad on top overdamped the wrist (0.6 s to settle after each move).
DAMPING = 0.1

#: Range camera: position in the head frame [m] (about eye height, in front of the head origin) and its
#: orientation (MuJoCo cameras look along their -z axis; this one looks along the head's z axis, image up =
#: head y).
RANGE_CAMERA_POS_HEAD = (0.0, 0.035, 0.06)
RANGE_CAMERA_QUAT_HEAD = (0.0, 0.0, 1.0, 0.0)
RANGE_CAMERA_FOVY_DEG = 50.0

#: The ``home`` keyframe: arm raised above the table beside the workspace, head looking down at the table; the
#: wrist yawed as every stroke holds it (``behaviors.FOREARM_RAISED``), so reaching does not swing it.
HOME_QPOS: dict[str, float] = {
    "torso_pitch": 0.4,
    "torso_roll": 0.0,
    "torso_yaw": 0.0,
    "neck_pitch": -0.5,
    "neck_roll": 0.0,
    "neck_yaw": 0.0,
    "r_shoulder_pitch": -1.0,
    "r_shoulder_roll": 0.45,
    "r_shoulder_yaw": 0.0,
    "r_elbow": 1.2,
    "r_wrist_prosup": 0.0,
    "r_wrist_pitch": 0.0,
    "r_wrist_yaw": -0.33,
}


def _servo_kp(joint: str) -> float:
    if joint in TORSO_JOINTS:
        return SERVO_KP["torso"]
    if joint in NECK_JOINTS:
        return SERVO_KP["neck"]
    if joint in ARM_JOINTS[4:]:
        return SERVO_KP["wrist"]
    return SERVO_KP["arm"]


def robot_spec() -> mujoco.MjSpec:
    """The iCub as MuJoCo reads its URDF, made simulable (see ``assets/README.md``)."""
    spec = mujoco.MjSpec.from_string(icub_urdf())
    # 1. Lock every joint the project does not move (legs, left arm): the bodies become static and are fused.
    for joint in list(spec.joints):
        if joint.name not in ACTIVE_JOINTS:
            spec.delete(joint)
    # 2. Collisions: only the right hand, wrist and forearm touch the world; nothing touches the robot itself.
    for body in spec.bodies:
        for i, geom in enumerate(body.geoms):
            geom.name = f"{body.name}_collision" + (f"_{i}" if i else "")
            contact = body.name in CONTACT_LINKS
            geom.contype = ROBOT_CONTYPE if contact else 0
            geom.conaffinity = ROBOT_CONAFFINITY if contact else 0
            geom.rgba = [0.75, 0.75, 0.78, 1.0]
            geom.group = SEEN_ROBOT_GEOM_GROUP if body.name in CAMERA_VISIBLE_LINKS else ROBOT_GEOM_GROUP
            if contact:
                # The hand's shell is smooth plastic: low friction, and it wins over the object's friction.
                geom.friction = [HAND_FRICTION, 0.005, 0.0001]
                geom.priority = 1
        # 3. Gravity compensation on every link, as the iCub's own controllers do.
        if body.name != "world":
            body.gravcomp = 1.0
    # 4. Joint damping and armature for stable position servos.
    for joint in spec.joints:
        joint.damping = [DAMPING, 0.0, 0.0]
        joint.armature = ARMATURE
    # 5. Palm site (for hand queries) and the range camera in the head.
    palm = spec.body(HAND_FRAME)
    palm.add_site(name="palm", size=[0.005, 0.005, 0.005], rgba=[0.2, 0.8, 0.2, 0.0])
    head = spec.body(HEAD_FRAME)
    head.add_site(name="head", size=[0.01, 0.01, 0.01], rgba=[0, 0, 0, 0])
    head.add_camera(name="range_camera", pos=list(RANGE_CAMERA_POS_HEAD), quat=list(RANGE_CAMERA_QUAT_HEAD),
                    fovy=RANGE_CAMERA_FOVY_DEG)
    return spec


def build_spec() -> mujoco.MjSpec:
    """The full scene: table, object and lights from ``assets/scene.xml`` with the robot attached."""
    spec = mujoco.MjSpec.from_file(str(assets_dir() / "scene.xml"))
    spec.compiler.fusestatic = True  # the URDF's fixed links (frames, sensors) fold into their moving parents
    robot = robot_spec()
    frame = spec.worldbody.add_frame(name="robot_base")
    # Attach under a prefix (MuJoCo warns that unprefixed attachments may not save), then give the robot's
    # elements back their URDF names so that MuJoCo and Pinocchio share them. Meshes keep the prefix: geoms
    # refer to them by name.
    frame.attach_body(robot.body("root_link"), _PREFIX, "")
    for elements in (spec.bodies, spec.joints, spec.geoms, spec.sites, spec.cameras):
        for element in elements:
            if element.name.startswith(_PREFIX):
                element.name = element.name.removeprefix(_PREFIX)
    # 6. Position actuators on every active joint. (No sensors: a touch sensor on the palm cost 9 % of every
    #    step, and the contacts between hand and object are read from the contact list when needed.)
    for name in ACTIVE_JOINTS:
        joint = spec.joint(name)
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_position(kp=_servo_kp(name), dampratio=1.0)
        act.ctrlrange = joint.range
        act.ctrllimited = True
    # 7. The home keyframe.
    model = spec.compile()
    qpos = model.qpos0.copy()
    for name, value in HOME_QPOS.items():
        qpos[model.jnt_qposadr[model.joint(name).id]] = value
    ctrl = np.array([HOME_QPOS[name] for name in ACTIVE_JOINTS])
    spec.add_key(name="home", qpos=qpos.tolist(), ctrl=ctrl.tolist())
    return spec


def build_model() -> mujoco.MjModel:
    """Compile :func:`build_spec` (about 1 s: the robot meshes are processed)."""
    return build_spec().compile()

