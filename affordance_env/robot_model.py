"""The iCub description shared by simulation and kinematics: one URDF, one list of moving joints per variant.

MuJoCo (:mod:`affordance_env.scene`) and Pinocchio (:mod:`affordance_env.kinematics`) both read the URDF text
returned by :func:`icub_urdf`, and both lock every joint outside a variant's active joints at zero. That is the
single source of truth for the robot's geometry.

Variants (:data:`VARIANTS`):

- ``"tap"`` (the default): torso, neck and right arm move; the right hand is the V2.5 model's rigid hand.
  :data:`ACTIVE_JOINTS`, :data:`REACH_JOINTS`, :data:`HAND_FRAME` and :data:`CONTACT_LINKS` are this variant's.
- ``"grasp"``: torso, neck and left arm move, and the left hand is the fingered ``left_hand_mk3`` of
  ``icub-models`` (:func:`hand_urdf`), mounted in ``l_hand_dh_frame`` at :data:`HAND_MOUNT_POS` in place of the
  V2.5 left hand. Its 11 finger joints are driven by 7 motors, as on the real hand: each distal joint follows
  its proximal one (:data:`HAND_COUPLINGS`).
- ``"two_arms"`` and ``"two_arms_left"``: the robot with both, the right arm with the V2.5 hand and the left arm
  with the fingered hand, the arm that does not act held rigid at its home pose (:data:`HELD_AT_HOME`). The
  first moves the right arm, the second the left arm and its fingers; both see and measure the relation features
  to the right palm (the ``palm`` site), whichever arm acts.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import icub_models
import numpy as np

from affordance_env.exceptions import InvalidValueError

#: The URDF model of ``icub-models`` we use: iCub 2.5 as simulated in Gazebo (fixed base at ``root_link``).
ICUB_MODEL = "iCubGazeboV2_5"

TORSO_JOINTS: tuple[str, ...] = ("torso_pitch", "torso_roll", "torso_yaw")
NECK_JOINTS: tuple[str, ...] = ("neck_pitch", "neck_roll", "neck_yaw")
ARM_JOINTS: tuple[str, ...] = (
    "r_shoulder_pitch",
    "r_shoulder_roll",
    "r_shoulder_yaw",
    "r_elbow",
    "r_wrist_prosup",
    "r_wrist_pitch",
    "r_wrist_yaw",
)
#: Joints that move, in the order used for ``qpos``/``ctrl`` of the robot everywhere in the project.
ACTIVE_JOINTS: tuple[str, ...] = TORSO_JOINTS + NECK_JOINTS + ARM_JOINTS
#: Joints the inverse kinematics of the right hand may use (torso and arm; the neck is for gaze).
REACH_JOINTS: tuple[str, ...] = TORSO_JOINTS + ARM_JOINTS

#: Frame of the palm centre: ``r_hand_dh_frame`` of the URDF. Its z axis is the palm normal, its x axis
#: points along the fingers.
HAND_FRAME = "r_hand_dh_frame"
#: Frame the range camera is mounted on.
HEAD_FRAME = "head"

#: Robot links that may touch the world (table, objects). All other links collide with nothing.
CONTACT_LINKS: tuple[str, ...] = ("r_hand", "r_wrist_1", "r_forearm")
#: URDF links of the right arm that can come into the head camera's view.
CAMERA_VISIBLE_LINKS: tuple[str, ...] = ("r_upper_arm", "r_elbow_1", "r_forearm", "r_wrist_1", "r_hand")

# --- the grasp variant: left arm and the fingered left_hand_mk3 ------------------------------------------------
LEFT_ARM_JOINTS: tuple[str, ...] = (
    "l_shoulder_pitch",
    "l_shoulder_roll",
    "l_shoulder_yaw",
    "l_elbow",
    "l_wrist_prosup",
    "l_wrist_pitch",
    "l_wrist_yaw",
)
#: The fingered hand model of ``icub-models`` (share/iCub/robots/left_hand_mk3/model.urdf): 12 links, 11 joints.
HAND_MODEL = "left_hand_mk3"
#: Its root link (the palm).
HAND_ROOT_LINK = "l_hand_palm_link"
#: The 7 joints driven by a motor, in the order of the real hand's motors: thumb opposition (the metacarpus),
#: thumb rotation, thumb flexion, index adduction, index, middle and little-finger flexion.
HAND_DRIVEN_JOINTS: tuple[str, ...] = (
    "l_hand_metacarpus_joint",
    "l_hand_thumb_rotation_joint",
    "l_hand_thumb_proximal_joint",
    "l_hand_index_adduction_joint",
    "l_hand_index_proximal_joint",
    "l_hand_medium_proximal_joint",
    "l_hand_pinky_proximal_joint",
)
#: Coupling of the real hand: each distal joint follows its proximal joint through a four-bar linkage
#: (robotology/gazebo-yarp-plugins, HandMk3CouplingHandler). Quartic fits of that linkage, distal = sum_i c_i q^i
#: with q the proximal angle [rad] (largest error 1.4 degrees for the fingers, 1.6 for the thumb); they reproduce
#: the distal joints' limits. Keyed by distal joint: (proximal joint, (c0, ..., c4)).
_FINGER_COUPLING = (0.0244, 1.5402, -1.091, 0.8078, -0.1891)
_THUMB_COUPLING = (0.0274, 1.066, -1.0794, 0.8669, -0.229)
HAND_COUPLINGS: dict[str, tuple[str, tuple[float, ...]]] = {
    "l_hand_thumb_distal_joint": ("l_hand_thumb_proximal_joint", _THUMB_COUPLING),
    "l_hand_index_distal_joint": ("l_hand_index_proximal_joint", _FINGER_COUPLING),
    "l_hand_medium_distal_joint": ("l_hand_medium_proximal_joint", _FINGER_COUPLING),
    "l_hand_pinky_distal_joint": ("l_hand_pinky_proximal_joint", _FINGER_COUPLING),
}
#: The open hand (driven joints [rad]): fingers straight, the thumb turned under the palm to face them (the
#: metacarpus, thumb opposition, at 1.1 rad: at 0 the thumb lies in the palm's plane, pointing away from the
#: fingers' side; the grasp turns it further as it closes).
HAND_OPEN: dict[str, float] = {
    "l_hand_metacarpus_joint": 0.9,
    "l_hand_thumb_rotation_joint": 0.0,
    "l_hand_thumb_proximal_joint": 0.0,
    "l_hand_index_adduction_joint": 0.0,
    "l_hand_index_proximal_joint": 0.0,
    "l_hand_medium_proximal_joint": 0.0,
    "l_hand_pinky_proximal_joint": 0.0,
}
#: All 11 joints of the hand: the driven ones, then the coupled distal ones.
HAND_JOINTS: tuple[str, ...] = HAND_DRIVEN_JOINTS + tuple(HAND_COUPLINGS)
#: Links of the mk3 hand.
HAND_LINKS: tuple[str, ...] = (
    "l_hand_palm_link",
    "l_hand_index_proximal_link",
    "l_hand_index_medial_link",
    "l_hand_index_fingertip_link",
    "l_hand_medium_medial_link",
    "l_hand_medium_fingertip_link",
    "l_hand_pinky_medial_link",
    "l_hand_pinky_fingertip_link",
    "l_hand_metacarpus_link",
    "l_hand_thumb_proximal_link",
    "l_hand_thumb_medial_link",
    "l_hand_thumb_fingertip_link",
)
#: The V2.5 model's frame the mk3 palm is mounted in, and the palm link's position in it [m], with no rotation
#: (both have the fingers along +x and the thumb on -y). No file of icub-models assembles the mk3 hand on an
#: arm; this offset overlays the mk3 hand on the V2.5 hand mesh it replaces (``assets/README.md``,
#: ``docs/hand_mount.png``).
HAND_MOUNT_FRAME = "l_hand_dh_frame"
HAND_MOUNT_POS: tuple[float, float, float] = (0.0185, -0.0017, 0.0023)


def coupled_position(distal: str, q_proximal: float | np.ndarray) -> float | np.ndarray:
    """Angle [rad] of the coupled ``distal`` joint when its proximal joint is at ``q_proximal`` [rad]."""
    if distal not in HAND_COUPLINGS:
        raise InvalidValueError(f"{distal!r} is not a coupled joint. Coupled joints: {', '.join(HAND_COUPLINGS)}.")
    q = q_proximal if isinstance(q_proximal, np.ndarray) else float(q_proximal)  # a scalar as a float: fast
    angle = 0.0
    for c in reversed(HAND_COUPLINGS[distal][1]):  # Horner's scheme
        angle = angle * q + c
    return angle


def coupled_slope_max(distal: str) -> float:
    """Largest rate of the coupled ``distal`` joint per unit rate of its proximal joint, over the proximal joint's
    range (0 to 95 degrees): how much faster than its motor's joint the linkage can turn it."""
    if distal not in HAND_COUPLINGS:
        raise InvalidValueError(f"{distal!r} is not a coupled joint. Coupled joints: {', '.join(HAND_COUPLINGS)}.")
    c = HAND_COUPLINGS[distal][1]
    q = np.linspace(0.0, np.radians(95.0), 200)
    return float(np.max(np.abs(sum(i * c[i] * q ** (i - 1) for i in range(1, len(c))))))


@dataclass(frozen=True)
class RobotVariant:
    """Which joints move and which links touch the world, for one use of the robot.

    Attributes:
        name: ``"tap"`` or ``"grasp"``.
        arm_joints: The arm that acts, shoulder to wrist.
        active_joints: Every joint that moves, in the order used for ``qpos`` of the robot everywhere in the
            project (MuJoCo's and Pinocchio's own orders differ; both are mapped by name).
        actuated_joints: The active joints that have a position servo (all but the coupled distal finger joints).
        reach_joints: Joints the inverse kinematics of the hand may use (torso and arm; the neck is for gaze).
        hand_frame: URDF frame of the palm centre (z along the palm normal, x along the fingers).
        contact_links: Links that may touch the world (table, objects); all others collide with nothing.
        camera_visible_links: Links that can come into the head camera's view (ray cast over the object).
        fingered: Whether the acting hand is the fingered mk3 hand (its finger joints move).
        mk3_hand: Whether the left hand is the fingered mk3 hand (moving or held).
        held: Joints that do not move and are held at these angles [rad] instead of at zero (the other arm at its
            home pose).
        ik_ranges: Narrower ranges ``{joint: (low, high)}`` [rad] of reach joints that every inverse kinematics of
            this variant keeps to, on top of the joints' own limits: what the scene itself forbids (see
            :data:`HELD_ARM_TORSO_RANGES`).
        palm_sites: MuJoCo sites at the palms' centres, (site, frame) pairs; ``palm`` is the one the relation
            features are measured to.
        palm_site: The site at the acting palm's centre.
    """

    name: str
    arm_joints: tuple[str, ...]
    active_joints: tuple[str, ...]
    actuated_joints: tuple[str, ...]
    reach_joints: tuple[str, ...]
    hand_frame: str
    contact_links: tuple[str, ...]
    camera_visible_links: tuple[str, ...]
    fingered: bool
    mk3_hand: bool = False
    held: Mapping[str, float] = dataclasses.field(default_factory=dict)
    ik_ranges: Mapping[str, tuple[float, float]] = dataclasses.field(default_factory=dict)
    palm_sites: tuple[tuple[str, str], ...] = (("palm", HAND_FRAME),)
    palm_site: str = "palm"


# The mk3 palm has no joint of its own: in the simulation it is fused into "l_hand", the link that the wrist turns
# (the V2.5 hand mesh is removed from it); the fingers are the other mk3 links.
_LEFT_CONTACT_LINKS: tuple[str, ...] = ("l_forearm", "l_wrist_1", "l_hand", *HAND_LINKS[1:])
_LEFT_VISIBLE_LINKS: tuple[str, ...] = ("l_upper_arm", "l_elbow_1", "l_forearm", "l_wrist_1", "l_hand", *HAND_LINKS[1:])

VARIANTS: dict[str, RobotVariant] = {
    "tap": RobotVariant(
        name="tap",
        arm_joints=ARM_JOINTS,
        active_joints=ACTIVE_JOINTS,
        actuated_joints=ACTIVE_JOINTS,
        reach_joints=REACH_JOINTS,
        hand_frame=HAND_FRAME,
        contact_links=CONTACT_LINKS,
        camera_visible_links=CAMERA_VISIBLE_LINKS,
        fingered=False,
    ),
    "grasp": RobotVariant(
        name="grasp",
        arm_joints=LEFT_ARM_JOINTS,
        active_joints=TORSO_JOINTS + NECK_JOINTS + LEFT_ARM_JOINTS + HAND_JOINTS,
        actuated_joints=TORSO_JOINTS + NECK_JOINTS + LEFT_ARM_JOINTS + HAND_DRIVEN_JOINTS,
        reach_joints=TORSO_JOINTS + LEFT_ARM_JOINTS,
        hand_frame="l_hand_dh_frame",
        contact_links=_LEFT_CONTACT_LINKS,
        camera_visible_links=_LEFT_VISIBLE_LINKS,
        fingered=True,
        mk3_hand=True,
        palm_sites=(("palm", "l_hand_dh_frame"),),
    ),
}

#: The home pose of each arm, in which it is held while the other one acts (the ``home`` keyframes of
#: :mod:`affordance_env.scene`, whose values these are): the right arm, and the left arm with its open hand.
HELD_AT_HOME: dict[str, dict[str, float]] = {
    "right": {"r_shoulder_pitch": -1.4, "r_shoulder_roll": 0.6, "r_shoulder_yaw": 0.0, "r_elbow": 1.5,
              "r_wrist_prosup": 0.0, "r_wrist_pitch": 0.0, "r_wrist_yaw": -0.33},
    "left": {"l_shoulder_pitch": -1.4, "l_shoulder_roll": 0.6, "l_shoulder_yaw": 0.0, "l_elbow": 1.5,
             "l_wrist_prosup": 0.0, "l_wrist_pitch": 0.0, "l_wrist_yaw": 0.0, **HAND_OPEN,
             **{distal: float(coupled_position(distal, HAND_OPEN[proximal]))
                for distal, (proximal, _) in HAND_COUPLINGS.items()}},
}
#: How far the torso may lean while the left arm acts and the right one is held at home beside it (the scene with both
#: arms), on top of the joints' own limits [rad]: pitched forward at most 35 degrees, rolled to -20 degrees at most.
#: The held right arm is rigid and touches the table: pitching further and rolling further negative lowers its
#: forearm onto the table top, which then holds the torso up short of where the inverse kinematics put it.
#: Unbounded, the grasp's IK pitched the torso 45-50 degrees and rolled it -25 to -30 for objects 38-42 cm in front
#: of the robot, and those grasps closed their fingers 3 cm above and 2 cm beside where they were planned, on
#: nothing. Within these ranges the held arm stays at least 1.4 cm above the table top at every torso yaw (its
#: collision meshes against the table over the whole box, in 5 degree steps). The draw keeps the same 35 degrees
#: for the same reason (``affordance_env.behaviors.draw.DRAW_JOINT_RANGES``).
HELD_ARM_TORSO_RANGES: dict[str, tuple[float, float]] = {
    "torso_pitch": (-np.pi, float(np.radians(35.0))),
    "torso_roll": (float(np.radians(-20.0)), np.pi),
}
_TWO_PALMS = (("palm", HAND_FRAME), ("left_palm", "l_hand_dh_frame"))
VARIANTS["two_arms"] = dataclasses.replace(
    VARIANTS["tap"], name="two_arms", mk3_hand=True, held=HELD_AT_HOME["left"],
    contact_links=CONTACT_LINKS + _LEFT_CONTACT_LINKS,
    camera_visible_links=CAMERA_VISIBLE_LINKS + _LEFT_VISIBLE_LINKS, palm_sites=_TWO_PALMS)
VARIANTS["two_arms_left"] = dataclasses.replace(
    VARIANTS["grasp"], name="two_arms_left", held=HELD_AT_HOME["right"], ik_ranges=HELD_ARM_TORSO_RANGES,
    contact_links=_LEFT_CONTACT_LINKS + CONTACT_LINKS,
    camera_visible_links=_LEFT_VISIBLE_LINKS + CAMERA_VISIBLE_LINKS, palm_sites=_TWO_PALMS, palm_site="left_palm")


def get_variant(name: str) -> RobotVariant:
    """The robot variant called ``name``; raises ValueError listing the valid names."""
    if name not in VARIANTS:
        raise InvalidValueError(f"Unknown robot variant {name!r}. Valid variants: {', '.join(VARIANTS)}.")
    return VARIANTS[name]


def icub_package_dir() -> Path:
    """Directory that ``package://iCub/`` in the URDF refers to (it holds ``meshes/``)."""
    path = Path(icub_models.get_models_path()).parent.parent / "iCub"
    if not (path / "meshes").is_dir():
        raise FileNotFoundError(
            f"icub-models meshes not found at {path / 'meshes'}; reinstall the 'icub-models' package."
        )
    return path


@functools.cache
def icub_urdf() -> str:
    """URDF text of :data:`ICUB_MODEL` with ``package://iCub/`` replaced by the installed mesh directory."""
    text = Path(icub_models.get_model_file(ICUB_MODEL)).read_text()
    return text.replace("package://iCub/", f"{icub_package_dir()}/")


@functools.cache
def hand_urdf() -> str:
    """URDF text of the :data:`HAND_MODEL` hand with ``package://iCub/`` replaced by the installed mesh directory."""
    path = icub_package_dir().parent / "iCub" / "robots" / HAND_MODEL / "model.urdf"
    if not path.is_file():
        raise FileNotFoundError(f"The {HAND_MODEL} hand model was not found at {path}; it ships with icub-models >= "
                                "3.0: reinstall the 'icub-models' package.")
    return path.read_text().replace("package://iCub/", f"{icub_package_dir()}/")
