"""What an interaction did to the object, measured from its motion alone (never from its type).

:class:`ObjectMonitor` follows the object's state at every simulation step of an interaction, whatever the
arm is doing, and records:

- when and where the object's centre left the table top (it then falls to the floor): beyond the top's edges or
  below it, except while the hand holds it up (:attr:`ObjectMonitor.held`) over the edge, where it has not fallen;
- the distance its centre covered while *rolling* on the table: moving with its lowest point nearly at rest
  (``|v_contact| <= ROLL_SLIP_RATIO |v|``, where ``v_contact = v + w x (-h z)`` is the velocity of the point
  ``h`` below the centre, ``h`` the centre's height above the table) and at constant height
  (``|v_z| <= ROLL_VERTICAL_RATIO |v_xy|``). A sliding object fails the first test, an object tipping over an
  edge the second (its centre rises and falls), except briefly at the top of the tip;
- the highest its centre rose above where it started;
- since when it has been still (linear and angular speed below :data:`REST_SPEED`, :data:`REST_ANGULAR_SPEED`).

The labels are pure functions of those records and of the initial and final poses:

- ``rolled``: the rolling distance exceeds the roll threshold;
- ``toppled``: the axis that was vertical at the start ends tilted by more than :data:`TOPPLE_ANGLE`, and the
  centre rose on the way by more than :data:`TOPPLE_RISE` of its initial height above the table, as it must to
  tip over an edge (a cube's centre rises by 41 % of its height); a rolling ball or lying cylinder turns its
  body axes by any angle at a constant centre height, so it does not count as toppled.

A standing cylinder that topples and then rolls away is both ``toppled`` and ``rolled``.

A grasp's label, :func:`grasp_success`, is measured at the end of the hold, with the hand lifted and still:
the object was lifted (its centre rose by at least :data:`GRASP_LIFT_THRESHOLD`), it touches the hand and not
the table, so the hand alone holds it up.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from affordance_env.linalg import dot

#: The object is still when its linear speed [m/s] and angular speed [rad/s] are below these ...
REST_SPEED, REST_ANGULAR_SPEED = 0.01, 0.3
#: ... and at rest once it has been still this long [s].
REST_DURATION = 0.05
#: Rolling: contact-point speed at most this share of the centre's horizontal speed ...
ROLL_SLIP_RATIO = 0.3
#: ... and vertical speed at most this share of it.
ROLL_VERTICAL_RATIO = 0.2
#: Centre speeds below this [m/s] count as no motion (neither rolling nor sliding).
MIN_MOTION_SPEED = 1e-3
#: Toppled: the initially vertical body axis tilted by more than this [rad] ...
TOPPLE_ANGLE = math.pi / 4
#: ... and the centre rose by more than this share of its initial height above the table.
TOPPLE_RISE = 0.1
#: A grasp lifted the object if its centre rose at least this much [m] by the end of the hold. The palm rises
#: 8 cm: a held object rises with it, a few millimetres less if it sagged in the grip, while an object the hand
#: did not enclose stays on the table or is pushed and tipped by a few centimetres at most.
GRASP_LIFT_THRESHOLD = 0.05


class ObjectMonitor:
    """Follows the object of a :class:`~affordance_env.physics.TapPhysics` through one interaction.

    Args:
        table_top: Height of the table top [m].
        table_low: Lower corner of the table top in world x, y [m], (2,).
        table_high: Upper corner of the table top in world x, y [m], (2,).
        p_world_start: Object centre when the interaction starts [m], (3,).
        time: Simulation time when the interaction starts [s].
    """

    def __init__(self, table_top: float, table_low: np.ndarray, table_high: np.ndarray,
                 p_world_start: np.ndarray, time: float) -> None:
        self.table_top = float(table_top)
        self._x0, self._y0 = float(table_low[0]), float(table_low[1])
        self._x1, self._y1 = float(table_high[0]), float(table_high[1])
        self.z_start = float(p_world_start[2])
        #: Simulation time [s] and centre position [m] when the object left the table; None while on it.
        self.exit_time: float | None = None
        self.exit_position: np.ndarray | None = None
        #: Distance the centre covered while rolling on the table [m].
        self.rolling_distance = 0.0
        #: Distance the centre covered on the table, rolling or not [m].
        self.path_length = 0.0
        #: Highest rise of the centre above its start while on the table [m].
        self.max_rise = 0.0
        #: Simulation time since which the object has been still [s]; None while it moves.
        self.still_since: float | None = time
        #: The hand holds the object up (set by the behaviour that lifts it, for as long as its hand may hold it):
        #: its centre carried beyond the table top's edges, above the top's height, has not left the table. A
        #: grasp near the near edge draws the object a few millimetres toward the robot as the fingers close on it
        #: and lift it (a 4.6 cm ball 8 mm inside the edge: its centre 1 mm beyond it, 5 mm up, in the closing
        #: hand, then carried and put down 8.6 cm away), and a held object may pass over the edge on its way to where
        #: it is put down.
        self.held = False
        self._time = float(time)

    @property
    def left_table(self) -> bool:
        """Whether the object's centre has left the table top."""
        return self.exit_time is not None

    def at_rest(self, time: float, since: float = -math.inf) -> bool:
        """Whether the object has been still for :data:`REST_DURATION` at ``time``, counting from ``since`` [s]."""
        return self.still_since is not None and time - max(self.still_since, since) >= REST_DURATION - 1e-9

    def sample(self, time: float, p: Sequence[float], v: Sequence[float], w: Sequence[float]) -> None:
        """Take the object's state at ``time`` [s].

        Args:
            time: Simulation time [s].
            p: Centre position in the world frame [m], 3 numbers.
            v: Linear velocity of the centre in the world frame [m/s], 3 numbers.
            w: Angular velocity in the world frame [rad/s], 3 numbers.
        """
        # Called at every control tick of an interaction: plain float arithmetic, names bound locally.
        sqrt = math.sqrt
        dt = time - self._time
        self._time = time
        vx, vy, vz = v
        wx, wy, wz = w
        speed = sqrt(vx * vx + vy * vy + vz * vz)
        if speed < REST_SPEED and sqrt(wx * wx + wy * wy + wz * wz) < REST_ANGULAR_SPEED:
            if self.still_since is None:
                self.still_since = time
        else:
            self.still_since = None
        if self.exit_time is not None:
            return
        x, y, z = p
        if not (self._x0 <= x <= self._x1 and self._y0 <= y <= self._y1 and z > self.table_top):
            if self.held and z > self.table_top:
                return  # in the hand, over the edge: not fallen, and not on the table either
            self.exit_time = time
            self.exit_position = np.array([x, y, z], dtype=np.float64)
            return
        rise = z - self.z_start
        if rise > self.max_rise:  # max(self.max_rise, rise), as max() picks it
            self.max_rise = rise
        speed_xy = sqrt(vx * vx + vy * vy)
        if speed_xy < MIN_MOTION_SPEED or dt <= 0.0:
            return
        self.path_length += speed_xy * dt
        h = z - self.table_top
        slip = sqrt((vx - h * wy) ** 2 + (vy + h * wx) ** 2 + vz * vz)
        if slip <= ROLL_SLIP_RATIO * speed_xy and abs(vz) <= ROLL_VERTICAL_RATIO * speed_xy:
            self.rolling_distance += speed_xy * dt


def tilt(quat_initial: np.ndarray, quat_final: np.ndarray) -> float:
    """Angle [rad] between the vertical and where the body axis that was vertical at the start ends up."""
    R0, R1 = np.empty(9), np.empty(9)
    mujoco.mju_quat2Mat(R0, np.asarray(quat_initial, dtype=np.float64))
    mujoco.mju_quat2Mat(R1, np.asarray(quat_final, dtype=np.float64))
    up_body = R0.reshape(3, 3)[2]  # the world's z axis in the body's frame: R0.T @ (0, 0, 1)
    return float(np.arccos(np.clip(dot(R1.reshape(3, 3)[2], up_body), -1.0, 1.0)))


@dataclass(frozen=True)
class Labels:
    """The outcome labels of one interaction (see the module docstring)."""

    rolled: bool
    toppled: bool
    tilt: float


def outcome_labels(monitor: ObjectMonitor, quat_initial: np.ndarray, quat_final: np.ndarray,
                   roll_threshold: float) -> Labels:
    """``rolled`` and ``toppled`` from what the monitor measured and the initial and final orientations."""
    angle = tilt(quat_initial, quat_final)
    height = monitor.z_start - monitor.table_top
    toppled = angle > TOPPLE_ANGLE and monitor.max_rise > TOPPLE_RISE * height
    return Labels(rolled=monitor.rolling_distance > roll_threshold, toppled=bool(toppled), tilt=angle)


def grasp_success(rise: float, links_holding: Sequence[str], on_table: bool,
                  threshold: float = GRASP_LIFT_THRESHOLD) -> bool:
    """Whether a grasp holds the object, at the end of the hold: its centre rose at least ``threshold`` [m],
    hand links touch it (``links_holding``, their names) and the table does not (``on_table``)."""
    return bool(rise >= threshold and len(links_holding) > 0 and not on_table)
