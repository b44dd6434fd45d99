"""The iCub's motor limits: the largest speed of each joint and the largest torque of each motor.

The URDF of ``icub-models`` gives the torso, neck and arm joints and the mk3 hand's joints ``effort`` and
``velocity`` limits of 50 000, placeholders. The values here come from the iCub's own configuration and
documentation; ``assets/README.md`` gives the source of each. The simulation applies the torque limits to the
position servos (MuJoCo's ``actuatorfrcrange``, with gravity compensation routed through the actuators, as the
iCub's controllers compensate gravity with the same motors), and every move the robot makes is planned within
the velocity limits (:mod:`affordance_env.trajectory`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from affordance_env.exceptions import InvalidValueError
from affordance_env.robot_model import HAND_COUPLINGS, HAND_DRIVEN_JOINTS, coupled_slope_max

_DEG = np.pi / 180.0

#: The arm, torso and neck joints' speed limit [rad/s]: ``jntVelMax 100`` deg/s of every joint of the iCub's own
#: simulation configuration in ``icub-models`` (``iCub/conf/gazebo_icub_torso.ini``, ``..._left_arm...ini``,
#: ``..._head_without_eyes.ini``), within the iCub maintainers' guidance for the real robot (peaks below
#: 200 deg/s). The real robots' firmware files set 1000 deg/s, a placeholder.
ARM_SPEED_LIMIT = 100.0 * _DEG
#: The mk3 hand's motors' speed limit [rad/s]: ``jntVelMax 180`` deg/s for its 7 motors in ``icub-models``'
#: ``iCub/conf_left_hand_mk3/left_hand_phys.ini``; half the no-load speed of its motor and gearhead (a Faulhaber
#: 1331T012SR, 9 900 rpm, through 159:1: 373 deg/s).
FINGER_SPEED_LIMIT = 180.0 * _DEG

#: Largest joint speed [rad/s] by joint name (arm joints without their side prefix). See ``assets/README.md``.
JOINT_VELOCITY_LIMITS: dict[str, float] = {
    **{name: ARM_SPEED_LIMIT for name in ("torso_pitch", "torso_roll", "torso_yaw", "neck_pitch", "neck_roll",
                                          "neck_yaw", "shoulder_pitch", "shoulder_roll", "shoulder_yaw", "elbow",
                                          "wrist_prosup", "wrist_pitch", "wrist_yaw")},
    **{name: FINGER_SPEED_LIMIT for name in HAND_DRIVEN_JOINTS},
}
#: Largest motor torque at the joint [N m] by joint name (arm joints without their side prefix); every value and
#: its source in ``assets/README.md``:
#:
#: - torso, shoulder, elbow: 20 N m, the current limit of the v2.5 arm's boards (``motorPeakCurrents`` 5 A,
#:   robots-configuration iCubGenova02 ``left_arm-eb1-j0_3-mc.xml``) times the torque constant of the Moog
#:   brushless motor (0.041 N m/A) times its 100:1 harmonic drive;
#: - torso pitch and roll: 40 N m, the two 20 N m motors that drive them through the torso's differential
#:   (robots-configuration iCubGenova02 ``torso-eb5-j0_2-mec.xml``, ``matrixM2J``: each of these joints moves at
#:   half the sum of the two motors' speeds, so by the balance of power its torque is the sum of theirs; the limit
#:   of one joint while the other needs none, which the simulation's per-joint limits cannot share);
#: - wrist: 2 N m, the full scale of the wrist joints' torque in the iCub's arm configuration (``TorqueMax``);
#: - neck: 5 N m, no source: about four times the head's gravity torque at the neck pitch (1.2 N m);
#: - fingers (the mk3 hand's 7 motors): 0.3 N m, the continuous torque of the Faulhaber 1331T012SR (3.2 mN m)
#:   through its 159:1 gearhead (``Gearbox_M2J 159``) at 60 % efficiency.
JOINT_TORQUE_LIMITS: dict[str, float] = {
    **{name: 20.0 for name in ("torso_yaw", "shoulder_pitch", "shoulder_roll", "shoulder_yaw", "elbow")},
    **{name: 40.0 for name in ("torso_pitch", "torso_roll")},
    **{name: 2.0 for name in ("wrist_prosup", "wrist_pitch", "wrist_yaw")},
    **{name: 5.0 for name in ("neck_pitch", "neck_roll", "neck_yaw")},
    **{name: 0.3 for name in HAND_DRIVEN_JOINTS},
}


def _side_free(name: str) -> str:
    return name[2:] if name.startswith(("l_", "r_")) and not name.startswith("l_hand_") else name


def velocity_limits(joints: Sequence[str]) -> np.ndarray:
    """Velocity limits [rad/s] of ``joints``, in their order. A coupled distal finger joint, which has no motor,
    moves at its proximal joint's limit times the linkage's largest transmission ratio."""
    limits = []
    for name in joints:
        if name in HAND_COUPLINGS:
            proximal = HAND_COUPLINGS[name][0]
            limits.append(JOINT_VELOCITY_LIMITS[proximal] * coupled_slope_max(name))
        else:
            limits.append(_lookup(JOINT_VELOCITY_LIMITS, name, "velocity"))
    return np.array(limits)


def torque_limits(joints: Sequence[str]) -> np.ndarray:
    """Torque limits [N m] of the motors of ``joints``, in their order."""
    return np.array([_lookup(JOINT_TORQUE_LIMITS, name, "torque") for name in joints])


def _lookup(table: dict[str, float], name: str, what: str) -> float:
    key = name if name in table else _side_free(name)
    if key not in table:
        raise InvalidValueError(f"No {what} limit for joint {name!r}. Joints with one: {', '.join(sorted(table))}.")
    return table[key]
