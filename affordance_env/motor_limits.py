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


#: Each motor's torque-speed curve at its joint: the stall torque [N m] at its driver's largest voltage, falling
#: linearly to zero at the no-load speed [rad/s] (the back-EMF line of a DC or brushless motor), as
#: ``(stall torque, no-load speed)``. The torque a motor gives is the smaller of its current limit
#: (:data:`JOINT_TORQUE_LIMITS`) and this line: a plateau, then the line. Sources (``assets/README.md``, "Motor
#: limits"): the motors' data sheets and windings in robots-configuration (``motorSpecs``) and the iCub
#: documentation, their gear ratios and couplings (``Gearbox_M2J``, ``matrixM2J`` in ``*-mec.xml``), 40 V for the
#: brushless drivers at their 95 % PWM cap and 12 V for the DC motors, the hand's at its controller's 89 % output
#: cap (``maxOutput`` 3000 of 3360):
#:
#: - shoulder (Moog C2900576, 0.664 ohm, 0.041 V s/rad, 100:1, the shoulder's cable coupling 1.625 faster):
#:   203 N m, 327 deg/s;
#: - elbow (the same motor at 100:1, as the iCub 3 documentation names it): 203 N m, 531 deg/s;
#: - torso roll and pitch (two of them through the differential): 406 N m, 531 deg/s; torso yaw (one through
#:   181.8:1): 369 N m, 292 deg/s;
#: - neck pitch and roll (Faulhaber 2342S012CR, 85 mN m stall, 8 570 rpm, 161.68:1, two motors through the
#:   differential): 27 N m, 318 deg/s; neck yaw: no source names its motor, taken as the same through 100:1:
#:   8.5 N m, 514 deg/s;
#: - wrist prosup (2342S012CR, 100:1): 8.5 N m, 514 deg/s; wrist pitch and yaw (a Faulhaber 1331T012SR through
#:   159:1 at 60 %, the gearhead the configuration gives): 0.94 N m, 374 deg/s;
#: - the mk3 hand's motors (1331T012SR, 9.9 mN m, 9 900 rpm, 159:1 at 60 %, at 89 % of 12 V): 0.84 N m, 333 deg/s.
JOINT_TORQUE_SPEED: dict[str, tuple[float, float]] = {
    **{name: (203.0, 327.0 * _DEG) for name in ("shoulder_pitch", "shoulder_roll", "shoulder_yaw")},
    "elbow": (203.0, 531.0 * _DEG),
    **{name: (406.0, 531.0 * _DEG) for name in ("torso_pitch", "torso_roll")},
    "torso_yaw": (369.0, 292.0 * _DEG),
    **{name: (27.0, 318.0 * _DEG) for name in ("neck_pitch", "neck_roll")},
    "neck_yaw": (8.5, 514.0 * _DEG),
    "wrist_prosup": (8.5, 514.0 * _DEG),
    **{name: (0.94, 374.0 * _DEG) for name in ("wrist_pitch", "wrist_yaw")},
    **{name: (0.84, 333.0 * _DEG) for name in HAND_DRIVEN_JOINTS},
}


def torque_speed(joints: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """The stall torques [N m] and no-load speeds [rad/s] of the motors of ``joints`` (:data:`JOINT_TORQUE_SPEED`),
    in their order."""
    curves = np.array([_lookup(JOINT_TORQUE_SPEED, name, "torque-speed") for name in joints]).reshape(-1, 2)
    return curves[:, 0], curves[:, 1]


def back_emf_damping(joints: Sequence[str]) -> np.ndarray:
    """The slope of each motor's torque-speed line at its joint [N m s/rad]: stall torque over no-load speed."""
    stall, no_load = torque_speed(joints)
    return stall / no_load


def available_torque(current: np.ndarray, stall: np.ndarray, no_load: np.ndarray, along: np.ndarray) -> np.ndarray:
    """The largest torque [N m] motors give: the smaller of their ``current`` limit and their torque-speed line
    (``stall`` torque [N m], ``no_load`` speed [rad/s]) at ``along`` [rad/s], their joint's speed in the
    direction of the torque (negative: braking, where the line rises above the stall torque); never below 0."""
    return np.maximum(np.minimum(current, stall * (1.0 - along / no_load)), 0.0)


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
