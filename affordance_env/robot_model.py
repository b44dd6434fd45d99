"""The iCub description shared by simulation and kinematics: one URDF, one list of moving joints.

MuJoCo (:mod:`affordance_env.scene`) and Pinocchio (:mod:`affordance_env.kinematics`) both read the URDF text
returned by :func:`icub_urdf`, and both lock every joint outside :data:`ACTIVE_JOINTS` at zero. That is the
single source of truth for the robot's geometry.
"""

from __future__ import annotations

import functools
from pathlib import Path

import icub_models

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
