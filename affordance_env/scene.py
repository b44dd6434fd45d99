"""Build the MuJoCo model: the iCub from its URDF, attached into the table scene of ``assets/scene.xml``.

Every step that changes the URDF robot is listed in ``assets/README.md``; :func:`build_spec` is that list in code.
Two robot variants (:data:`affordance_env.robot_model.VARIANTS`): ``"tap"``, the right arm with the V2.5 hand,
and ``"grasp"``, the left arm with the fingered ``left_hand_mk3`` hand (:func:`hand_spec`).
"""

from __future__ import annotations

import functools
from collections.abc import Mapping

import mujoco
import numpy as np

from affordance_env.assets_path import assets_dir
from affordance_env.exceptions import InvalidValueError
from affordance_env.linalg import matmul
from affordance_env.model_cache import cached_model
from affordance_env.motor_limits import back_emf_damping, torque_limits, torque_speed
from affordance_env.robot_model import (
    CAMERA_VISIBLE_LINKS,  # noqa: F401 (the tap variant's, named here beside the geom groups as before)
    HAND_COUPLINGS,
    HAND_JOINTS,
    HAND_LINKS,
    HAND_MOUNT_FRAME,
    HAND_MOUNT_POS,
    HAND_OPEN,
    HAND_ROOT_LINK,
    HEAD_FRAME,
    NECK_JOINTS,
    TORSO_JOINTS,
    coupled_position,
    get_variant,
    hand_urdf,
    icub_urdf,
)

_PREFIX = "icub:"

#: Collision bits (see assets/scene.xml): robot links in CONTACT_LINKS are type 2 (the object takes 2) and take
#: 4 (the table box), so they touch the object and the table but never each other; other robot geoms touch nothing.
ROBOT_CONTYPE, ROBOT_CONAFFINITY = 2, 4

#: Geom groups (the world's geoms are in group 0; MuJoCo's renderer draws groups 0-2): the robot's parts that
#: the head's range camera can see, the acting arm from the upper arm down (CAMERA_VISIBLE_LINKS of the tap
#: variant, ``camera_visible_links`` of a variant), are in SEEN_ROBOT_GEOM_GROUP; the rest of the robot, which
#: the camera never sees (torso, head, the hanging other arm), is in ROBOT_GEOM_GROUP and is not ray cast: with
#: it the range image costs six times as much and looks the same.
ROBOT_GEOM_GROUP, SEEN_ROBOT_GEOM_GROUP = 1, 2

#: Sliding friction of the hand's contact geoms (they take priority over the object's friction).
HAND_FRICTION = 0.3
#: Contact stiffness of every robot geom that touches the world (they take priority over the object's and the
#: table's, so their values govern hand-object and hand-table contacts): MuJoCo's solref (time constant [s],
#: damping ratio) and solimp. 10 ms, the shortest time constant that MuJoCo resolves stably at the interactions'
#: 5 ms timestep (two steps), and an impedance of 0.99, nearly hard: a finger pressing with its motor's full
#: torque sinks about a millimetre into what it holds, where MuJoCo's default (20 ms, 0.9-0.95) let it sink 3-15
#: mm. Critically damped for the fingers (they squeeze, they do not strike); the tapping hand's damping ratio
#: sets the palm's restitution on a struck object (PALM_RESTITUTION).
CONTACT_SOLREF = (0.01, 1.0)
CONTACT_SOLIMP = (0.995, 0.995, 0.001, 0.5, 2.0)
#: Coefficient of restitution of an object struck by the palm of the tapping hand (or its back): the share of its
#: approach speed a ball takes away from a still palm. The iCub's palm is its plastic shell under the tactile
#: skin, a few millimetres of soft silicone over the sensors; a hard ball on such an elastomer-covered pad
#: rebounds with 0.2-0.4 of its speed (a bare plastic shell: 0.6-0.8). PALM_SOLREF gives it: its damping ratio
#: 0.4 returns 0.27-0.31 of the speed at 0.06-0.54 m/s at the stroke's 2 ms timestep
#: (``tests/test_physics_limits.py`` measures it). At 1 (critical damping) a ball would keep a tenth of its
#: speed, as on a lump of clay.
PALM_RESTITUTION = 0.3
PALM_SOLREF = (0.01, 0.4)
#: Friction of the fingered hand's geoms (grasp variant): sliding, torsional [m], rolling [m]. The mk3 hand's
#: fingertips and palm carry the iCub's tactile skin under a silicone cover; silicone rubber on wood or plastic
#: has a sliding friction coefficient of about 1 (0.8-1.2 in handbook tables), which is what lets a hand hold
#: an object by squeezing it. Torsional: (2/3) mu a for a soft pad pressed to a contact patch of radius a of
#: about 5 mm. Rolling: 0.1 mm, a soft pad's small resistance to rolling an object between the fingers.
FINGER_FRICTION = (1.0, 0.0033, 0.0001)
#: Contact dimensionality of the fingered hand: 4, sliding and torsional friction, the "soft finger" contact
#: model of grasping (a pad resists a held object's spin about the contact normal).
FINGER_CONDIM = 4
#: Links of the fingered hand that collide through a capsule fitted to their mesh (:func:`phalanx_capsules`) instead
#: of through the mesh's convex hull: the phalanges, the medial and distal links of the index, middle and little
#: fingers and of the thumb. Each is a rounded bar, 26-45 mm long, 16-19 mm thick across its pad and 16-18 mm wide:
#: a capsule along its length whose radius is half its thickness puts the gripping surface, and the rounded tip,
#: where the mesh has them. Its contacts are cheaper to compute, and one capsule touches a face with one or two
#: contacts where a hull gave two to four. The palm, the index finger's knuckle link and the thumb's metacarpus and
#: proximal link are blocks, not bars, and keep their hulls.
PHALANX_LINKS: tuple[str, ...] = tuple(link for link in HAND_LINKS
                                       if link.endswith(("_medial_link", "_fingertip_link")))
#: Geom group of the phalanges' capsules, which only collide: neither the range camera nor the renderer sees them;
#: both see the link's mesh, kept as a geom that collides with nothing.
COLLISION_GEOM_GROUP = 3

#: Position-servo stiffness per joint group [N m / rad].
SERVO_KP: dict[str, float] = {"torso": 300.0, "neck": 50.0, "arm": 60.0, "wrist": 10.0}
#: Name suffix of each motor's back-EMF actuator (see build_spec, step 6).
BACK_EMF = "_back_emf"
#: Joint armature added for a stable servo [kg m^2].
ARMATURE = 0.02
#: Joint damping [N m s / rad]: a small viscous friction. The servos are critically damped by their actuators;
#: 1 N m s/rad on top overdamped the wrist (0.6 s to settle after each move).
DAMPING = 0.1
#: Finger joints of the mk3 hand (grasp variant). Position-servo stiffness [N m / rad]: a finger presses with at
#: most its motor's torque (0.3 N m, ``motor_limits``), reached at a tracking error of 0.15 rad, the most the hand's
#: controller lets a finger's target lead it (``TapPhysics.finger_reach``): a finger that loses what it pressed on
#: then closes that gap at its servo's pace, at most 0.15 x sqrt(kp / armature) / e = 2.5 rad/s (141 deg/s,
#: critically damped), within its 180 deg/s limit (at kp = 1, 0.3 rad would give 200 deg/s). Damping
#: [N m s / rad] and armature [kg m^2]: the URDF's damping of 1 N m s/rad is a placeholder that, against kp = 1,
#: makes the fingers lag 30 degrees behind a 1 s closing ramp (time constant damping / kp = 1 s); 0.03 is a small
#: gear friction and the fingers track to a fraction of a degree. The armature, the reflected inertia of the
#: finger's motor and gearbox, keeps the light links (10-17 g, inertias of 1e-6 kg m^2) well conditioned: 1e-3
#: kg m^2 gives a servo period of 2 pi sqrt(1e-3 / 2) = 0.14 s, 28 timesteps of the grasp scene.
HAND_KP, HAND_DAMPING, HAND_ARMATURE = 2.0, 0.03, 1e-3
#: Timestep of the grasp variant [s]. The tap scene's 2 ms resolves the impact of a tap; a grasp has no impact,
#: and its fastest dynamics are resolved at 5 ms with at least 2 steps per time constant (MuJoCo's stability
#: bound): the contacts' (10 ms, CONTACT_SOLREF), the finger coupling's (10 ms, below), the finger servos'
#: (sqrt(armature / kp) = 32 ms) and the arm servos' (25 ms and more). It divides the 10 ms control tick.
GRASP_TIMESTEP = 0.005
#: Ratio of the frictional to the normal constraints' impedance (MuJoCo's ``impratio``, elliptic cones) of the
#: grasp variant: friction as hard as the grip's normal forces, so that a held object does not creep in the
#: fingers (the tap scene's 10 let it creep at up to 2 mm/s under a steady squeeze; at 300, 0.1-0.6 mm/s) without
#: raising the friction coefficients themselves.
GRASP_IMPRATIO = 300.0
#: Coupling of the distal finger joints to their proximal joints (MuJoCo ``equality joint``): the linkage is
#: stiff, so the constraint is solved with a time constant of 10 ms (2 timesteps of the grasp variant, MuJoCo's
#: stable minimum) and critical damping.
COUPLING_SOLREF = (0.01, 1.0)

#: Range camera: position in the head frame [m] (about eye height, in front of the head origin) and its
#: orientation (MuJoCo cameras look along their -z axis; this one looks along the head's z axis, image up =
#: head y).
RANGE_CAMERA_POS_HEAD = (0.0, 0.035, 0.06)
RANGE_CAMERA_QUAT_HEAD = (0.0, 0.0, 1.0, 0.0)
RANGE_CAMERA_FOVY_DEG = 50.0

#: The ``home`` keyframe: arm raised above the table beside the workspace, head looking down at the table; the
#: wrist yawed as every stroke holds it (``affordance_env.behaviors.stroke.FOREARM_RAISED``), so reaching does not
#: swing it. The forearm's lowest point is 14.8 cm above the table top, so an object of any size (at most 10 cm)
#: that rolls under the arm waiting at home passes beneath it (at the earlier 5.8 cm, large lying cylinders tapped
#: back towards home came to rest against the forearm).
HOME_QPOS: dict[str, float] = {
    "torso_pitch": 0.4,
    "torso_roll": 0.0,
    "torso_yaw": 0.0,
    "neck_pitch": -0.5,
    "neck_roll": 0.0,
    "neck_yaw": 0.0,
    "r_shoulder_pitch": -1.4,
    "r_shoulder_roll": 0.6,
    "r_shoulder_yaw": 0.0,
    "r_elbow": 1.5,
    "r_wrist_prosup": 0.0,
    "r_wrist_pitch": 0.0,
    "r_wrist_yaw": -0.33,
}


#: The ``home`` keyframe of the grasp variant: the left arm raised as the right one is for the tap (the left
#: arm's joint axes mirror the right arm's, so the same angles give the mirror pose), the hand open
#: (HAND_OPEN: the thumb opposed to the fingers) and each distal joint where its coupling puts it.
GRASP_HOME_QPOS: dict[str, float] = {
    **{name: HOME_QPOS[name] for name in TORSO_JOINTS + NECK_JOINTS},
    "l_shoulder_pitch": -1.4,
    "l_shoulder_roll": 0.6,
    "l_shoulder_yaw": 0.0,
    "l_elbow": 1.5,
    "l_wrist_prosup": 0.0,
    "l_wrist_pitch": 0.0,
    "l_wrist_yaw": 0.0,
    **HAND_OPEN,
    **{distal: float(coupled_position(distal, HAND_OPEN[proximal]))
       for distal, (proximal, _) in HAND_COUPLINGS.items()},
}


def home_qpos(variant: str = "tap") -> dict[str, float]:
    """Joint angles [rad] of the ``home`` keyframe of the robot ``variant``, by joint name: the moving arm at its
    home (HOME_QPOS for the right arm, GRASP_HOME_QPOS for the left arm and its fingered hand)."""
    home = {**HOME_QPOS, **GRASP_HOME_QPOS}
    return {name: home[name] for name in get_variant(variant).active_joints}


def _servo_kp(joint: str) -> float:
    if joint in TORSO_JOINTS:
        return SERVO_KP["torso"]
    if joint in NECK_JOINTS:
        return SERVO_KP["neck"]
    if joint in HAND_JOINTS:
        return HAND_KP
    if joint.endswith(("_wrist_prosup", "_wrist_pitch", "_wrist_yaw")):
        return SERVO_KP["wrist"]
    return SERVO_KP["arm"]


def hand_inertias() -> dict[str, list[float]]:
    """Inertia tensors of the mk3 hand's links whose URDF inertia is a placeholder, from their meshes.

    The URDF gives 11 of its 12 links Ixx = Iyy = Izz = 0.01 kg m^2, a placeholder some thousand times too large
    for links of 10-100 g. Each link's tensor is computed from its (closed) mesh as a solid of uniform density
    (MuJoCo's exact mesh inertia), scaled by the URDF mass over the mesh's mass, and expressed in the link frame
    about the URDF's centre of mass (the mesh's centroid lies within 0.3 mm of it). Returns
    ``{link: [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]}`` [kg m^2] for those links.
    """
    spec = mujoco.MjSpec.from_string(hand_urdf())
    spec.compiler.fusestatic = False
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_TRUE
    for mesh in spec.meshes:
        mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_EXACT
    placeholder = {body.name: body.mass for body in spec.bodies
                   if body.name != "world" and np.allclose(body.fullinertia[:3], 0.01)}
    model = spec.compile()
    tensors = {}
    for name, urdf_mass in placeholder.items():
        b = model.body(name).id
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, model.body_iquat[b])
        R = R.reshape(3, 3)
        inertia = (urdf_mass / model.body_mass[b]) * matmul(matmul(R, np.diag(model.body_inertia[b])), R.T)
        tensors[name] = [inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2]]
    return tensors


@functools.cache
def phalanx_capsules() -> dict[str, tuple[tuple[float, float, float], float, float]]:
    """The collision capsule of each link in PHALANX_LINKS, fitted to the link's mesh.

    A phalanx's link frame has x along its length and y along its joints' axes, so z is across its pad. The capsule
    lies along x through the centre of the mesh's bounding box (in the link frame); its radius is half the box's
    z extent, the phalanx's thickness, and its rounded ends touch the box's ends. Returns
    ``{link: (centre [m] (3,), half-length of the axis segment [m], radius [m])}``.
    """
    spec = mujoco.MjSpec.from_string(hand_urdf())
    spec.compiler.fusestatic = False
    model = spec.compile()
    capsules = {}
    for link in PHALANX_LINKS:
        body = model.body(link).id
        vertices = []
        for g in np.flatnonzero(model.geom_bodyid == body):
            mesh = model.geom_dataid[g]
            R = np.empty(9)
            mujoco.mju_quat2Mat(R, model.geom_quat[g])
            start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
            vertices.append(matmul(model.mesh_vert[start : start + count], R.reshape(3, 3).T) + model.geom_pos[g])
        p_link_vertices = np.vstack(vertices)
        low, high = p_link_vertices.min(axis=0), p_link_vertices.max(axis=0)
        extent = high - low
        if np.argmax(extent) != 0:
            raise InvalidValueError(f"{link} is expected to be longest along its x axis; its mesh extends {extent} m.")
        radius = float(extent[2] / 2)
        capsules[link] = (tuple(float(c) for c in (low + high) / 2), float(extent[0] / 2 - radius), radius)
    return capsules


def _contact_geom(geom: mujoco.MjsGeom, solref: tuple[float, float] = CONTACT_SOLREF) -> None:
    geom.contype = ROBOT_CONTYPE
    geom.conaffinity = ROBOT_CONAFFINITY
    geom.priority = 1
    geom.solref = list(solref)
    geom.solimp = list(CONTACT_SOLIMP)


def hand_spec() -> mujoco.MjSpec:
    """The ``left_hand_mk3`` hand as MuJoCo reads its URDF, made simulable (see ``assets/README.md``)."""
    spec = mujoco.MjSpec.from_string(hand_urdf())
    inertias = hand_inertias()
    capsules = phalanx_capsules()
    for body in spec.bodies:
        if body.name == "world":
            continue
        # Plausible inertias in place of the URDF's placeholders; the URDF's mass and centre of mass are kept.
        if body.name in inertias:
            body.fullinertia = inertias[body.name]
        body.gravcomp = 1.0
        geoms = list(body.geoms)
        if body.name in capsules:  # the mesh is only seen; a capsule collides in its place
            for i, geom in enumerate(geoms):
                geom.name = f"{body.name}_visual" + (f"_{i}" if i else "")
                geom.contype = geom.conaffinity = 0
                geom.group = SEEN_ROBOT_GEOM_GROUP
            centre, half_length, radius = capsules[body.name]
            capsule = body.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, pos=list(centre), size=[radius, half_length, 0],
                                    quat=[np.sqrt(0.5), 0.0, np.sqrt(0.5), 0.0])  # the capsule's z along the link's x
            geoms = [capsule]
        for i, geom in enumerate(geoms):
            geom.name = f"{body.name}_collision" + (f"_{i}" if i else "")
            # Contact bits as the tap's hand: the hand touches objects and the table, never itself.
            _contact_geom(geom)
            geom.friction = list(FINGER_FRICTION)
            geom.condim = FINGER_CONDIM
            geom.group = COLLISION_GEOM_GROUP if body.name in capsules else SEEN_ROBOT_GEOM_GROUP
        for geom in body.geoms:
            geom.rgba = [0.75, 0.75, 0.78, 1.0] if body.name == HAND_ROOT_LINK else [0.35, 0.35, 0.38, 1.0]
    for joint in spec.joints:
        joint.damping = [HAND_DAMPING, 0.0, 0.0]
        joint.armature = HAND_ARMATURE
    return spec


def robot_spec(variant: str = "tap") -> mujoco.MjSpec:
    """The iCub as MuJoCo reads its URDF, made simulable (see ``assets/README.md``)."""
    robot = get_variant(variant)
    contact_links = robot.contact_links
    visible_links = robot.camera_visible_links
    spec = mujoco.MjSpec.from_string(icub_urdf())
    # 1. Lock every joint the project does not move (legs, the other arm): the bodies become static and are fused;
    #    a held joint (the other arm at home) is locked at its angle.
    _lock_joints(spec, robot.active_joints, robot.held)
    if robot.mk3_hand:
        _replace_hand(spec)
    # 2. Collisions: only the acting hand, wrist and forearm touch the world; nothing touches the robot itself.
    for body in spec.bodies:
        for i, geom in enumerate(body.geoms):
            geom.name = f"{body.name}_collision" + (f"_{i}" if i else "")
            contact = body.name in contact_links
            geom.contype = 0
            geom.conaffinity = 0
            geom.rgba = [0.75, 0.75, 0.78, 1.0]
            geom.group = SEEN_ROBOT_GEOM_GROUP if body.name in visible_links else ROBOT_GEOM_GROUP
            if contact:
                # The hand's shell is smooth plastic: low friction, and it wins over the object's friction.
                geom.friction = [HAND_FRICTION, 0.005, 0.0001]
                _contact_geom(geom, PALM_SOLREF)
        # 3. Gravity compensation on every link, as the iCub's own controllers do.
        if body.name != "world":
            body.gravcomp = 1.0
    # 4. Joint damping and armature for stable position servos.
    for joint in spec.joints:
        joint.damping = [DAMPING, 0.0, 0.0]
        joint.armature = ARMATURE
    # 5. Palm sites (for hand queries) and the range camera in the head.
    for site, frame in robot.palm_sites:
        spec.body(frame).add_site(name=site, size=[0.005, 0.005, 0.005], rgba=[0.2, 0.8, 0.2, 0.0])
    head = spec.body(HEAD_FRAME)
    head.add_site(name="head", size=[0.01, 0.01, 0.01], rgba=[0, 0, 0, 0])
    head.add_camera(name="range_camera", pos=list(RANGE_CAMERA_POS_HEAD), quat=list(RANGE_CAMERA_QUAT_HEAD),
                    fovy=RANGE_CAMERA_FOVY_DEG)
    if robot.mk3_hand:
        _attach_hand(spec)
        _lock_joints(spec, robot.active_joints, robot.held)  # the hand's own joints, when it is held
    return spec


def _lock_joints(spec: mujoco.MjSpec, active: tuple[str, ...], held: Mapping[str, float]) -> None:
    """Delete every joint of ``spec`` not in ``active``; the body of a joint in ``held`` is first turned by its
    angle about the joint's axis (every joint of the URDFs is at its body's origin), so it stays there."""
    for joint in list(spec.joints):
        if joint.name in active:
            continue
        angle = held.get(joint.name, 0.0)
        if angle:
            if np.any(joint.pos):
                raise InvalidValueError(
                    f"joint {joint.name!r} is not at its body's origin; it cannot be held at an angle.")
            body = joint.parent
            turn = np.empty(4)
            mujoco.mju_axisAngle2Quat(turn, np.asarray(joint.axis, dtype=float), angle)
            quat = np.empty(4)
            mujoco.mju_mulQuat(quat, np.asarray(body.quat, dtype=float), turn)
            body.quat = quat
        spec.delete(joint)


def _replace_hand(spec: mujoco.MjSpec) -> None:
    """Remove the V2.5 left hand (its mesh and its mass, those of the whole V2.5 hand) from ``l_hand``."""
    hand = spec.body("l_hand")
    for geom in list(hand.geoms):
        spec.delete(geom)
    # The link keeps no mass of its own: the mk3 palm, fused into it, brings its own.
    hand.explicitinertial = False
    hand.mass = 0.0
    hand.fullinertia = [np.nan] * 6  # unset: no inertia of its own
    hand.inertia = [0.0, 0.0, 0.0]
    hand.ipos = [0.0, 0.0, 0.0]


def _attach_hand(spec: mujoco.MjSpec) -> None:
    """Mount the mk3 hand (:func:`hand_spec`) in HAND_MOUNT_FRAME, at HAND_MOUNT_POS, without rotation."""
    frame = spec.body(HAND_MOUNT_FRAME).add_frame(name="mk3_mount", pos=list(HAND_MOUNT_POS))
    prefix = "mk3:"
    frame.attach_body(hand_spec().body(HAND_ROOT_LINK), prefix, "")
    # Back to the URDF's names (meshes keep the prefix: geoms refer to them by name).
    for elements in (spec.bodies, spec.joints, spec.geoms):
        for element in elements:
            if element.name.startswith(prefix):
                element.name = element.name.removeprefix(prefix)


def build_spec(variant: str = "tap") -> mujoco.MjSpec:
    """The full scene: table, object and lights from ``assets/scene.xml`` with the robot ``variant`` attached."""
    variant_ = get_variant(variant)
    spec = mujoco.MjSpec.from_file(str(assets_dir() / "scene.xml"))
    spec.compiler.fusestatic = True  # the URDF's fixed links (frames, sensors) fold into their moving parents
    robot = robot_spec(variant)
    frame = spec.worldbody.add_frame(name="robot_base")
    # Attach under a prefix (MuJoCo warns that unprefixed attachments may not save), then give the robot's
    # elements back their URDF names so that MuJoCo and Pinocchio share them. Meshes keep the prefix: geoms
    # refer to them by name.
    frame.attach_body(robot.body("root_link"), _PREFIX, "")
    for elements in (spec.bodies, spec.joints, spec.geoms, spec.sites, spec.cameras):
        for element in elements:
            if element.name.startswith(_PREFIX):
                element.name = element.name.removeprefix(_PREFIX)
    # 6. Position actuators on every actuated joint. (No sensors: a touch sensor on the palm cost 4-9 % of every
    #    step, and the contacts between hand and object are read from the contact list when needed.)
    #    Each motor's torque is limited (motor_limits), gravity compensation included: it is routed through the
    #    actuators, as the iCub's controllers compensate gravity with the same motors.
    #    Each motor is a DC motor: its current limit caps the joint's torque (actuatorfrcrange, applied to all the
    #    joint's actuators together), and its driver's largest voltage the torque along the back-EMF line
    #    (motor_limits.JOINT_TORQUE_SPEED): the servo's command is capped at the stall torque (forcerange) and a
    #    second actuator, the back-EMF, subtracts the line's slope times the speed. The servo's own damping is
    #    lowered by that slope (compile_scene), so that below both limits the servo is what it was.
    torque_limit = dict(zip(variant_.actuated_joints, torque_limits(variant_.actuated_joints), strict=True))
    stall, _ = torque_speed(variant_.actuated_joints)
    emf = back_emf_damping(variant_.actuated_joints)
    for joint in spec.joints:
        if joint.name in variant_.active_joints:
            joint.actgravcomp = True
            joint.actfrclimited = False  # the URDF's placeholder effort (50 000); a motor's limit below
    for name, stall_torque in zip(variant_.actuated_joints, stall, strict=True):
        joint = spec.joint(name)
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_position(kp=_servo_kp(name), dampratio=1.0)
        act.ctrlrange = joint.range
        act.ctrllimited = True
        act.forcerange = [-stall_torque, stall_torque]
        act.forcelimited = True
        joint.actfrcrange = [-torque_limit[name], torque_limit[name]]
        joint.actfrclimited = True
    for name, slope in zip(variant_.actuated_joints, emf, strict=True):  # after every servo: their ids stay
        act = spec.add_actuator(name=f"{name}{BACK_EMF}", target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.gaintype = mujoco.mjtGain.mjGAIN_FIXED
        act.gainprm[0] = 0.0
        act.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        act.biasprm[:3] = [0.0, 0.0, -float(slope)]
        act.ctrllimited = False
    # 6b. The fingered hand's coupling: each distal joint follows its proximal joint; the grasp's timestep.
    if variant_.fingered:
        spec.option.timestep = GRASP_TIMESTEP
        spec.option.impratio = GRASP_IMPRATIO
    for distal, (proximal, coefficients) in HAND_COUPLINGS.items() if variant_.fingered else ():
        equality = spec.add_equality(name=f"{distal}_coupling", type=mujoco.mjtEq.mjEQ_JOINT, name1=distal,
                                     name2=proximal, objtype=mujoco.mjtObj.mjOBJ_JOINT, solref=list(COUPLING_SOLREF))
        data = np.zeros(len(equality.data))  # polycoef: distal = sum_i data[i] proximal^i, i = 0..4
        data[: len(coefficients)] = coefficients
        equality.data = data
    # 7. The home keyframe.
    home = home_qpos(variant)
    model = spec.compile()
    qpos = model.qpos0.copy()
    for name, value in home.items():
        qpos[model.jnt_qposadr[model.joint(name).id]] = value
    ctrl = np.array([home[name] for name in variant_.actuated_joints] + [0.0] * len(variant_.actuated_joints))
    spec.add_key(name="home", qpos=qpos.tolist(), ctrl=ctrl.tolist())
    return spec


def compile_scene(variant: str = "tap") -> mujoco.MjModel:
    """Compile :func:`build_spec`, then lower each servo's damping by its motor's back-EMF slope, which the
    back-EMF actuator applies (MuJoCo's ``dampratio`` gives the servo's damping only when it compiles)."""
    model = build_spec(variant).compile()
    actuated = get_variant(variant).actuated_joints
    servos = [model.actuator(name).id for name in actuated]
    model.actuator_biasprm[servos, 2] += back_emf_damping(actuated)  # biasprm[2] is minus the damping
    return model


def build_model(variant: str = "tap") -> mujoco.MjModel:
    """Compile :func:`build_spec` (about half a second: the robot meshes are processed), or load the same model
    from the cache of compiled models (:mod:`affordance_env.model_cache`) in a tenth of that."""
    urdfs = (icub_urdf(), hand_urdf()) if get_variant(variant).mk3_hand else (icub_urdf(),)
    return cached_model(variant, urdfs, lambda: compile_scene(variant))


@functools.cache
def table_extent() -> tuple[tuple[float, float], tuple[float, float]]:
    """The (lower, upper) corners (x, y) [m] of the table top of ``assets/scene.xml``, what
    :meth:`TapPhysics.table_extent <affordance_env.physics.TapPhysics.table_extent>` gives in a built scene, read
    from the table scene alone (no robot: milliseconds, once per process)."""
    model = mujoco.MjModel.from_xml_path(str(assets_dir() / "scene.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    table = model.geom("table_top").id
    centre, half = data.geom_xpos[table, :2], model.geom_size[table, :2]
    return tuple(map(float, centre - half)), tuple(map(float, centre + half))
