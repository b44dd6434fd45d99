"""Joint and Cartesian trajectories of the robot's moves: pure functions of arrays, sampled at the control period.

Every move of the robot, the reach, the stroke, the grasp's descent, closing, lift, carry and put-down, the
fingers opening and the way home, is one of these trajectories, followed by the position servos of
:mod:`affordance_env.motion` with velocity and acceleration feedforward:

- :func:`minimum_jerk`: a joint-space move through via points, each segment a minimum-jerk profile (start and
  end at rest), stretched until no joint exceeds its velocity limit.
- :func:`line_profile`: the distance along a straight Cartesian line over time, at a constant cruise speed
  reached and left smoothly, or from and to rest.

Nothing here needs the simulator.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from affordance_env.exceptions import InvalidValueError
from affordance_env.linalg import matmul

#: The minimum-jerk profile 10 t^3 - 15 t^4 + 6 t^5 peaks at this multiple of its mean speed.
PEAK_SPEED_FACTOR = 1.875
#: Share of the shorter of two consecutive segments of a move through via points during which both run.
VIA_BLEND = 0.5


@dataclass(frozen=True)
class JointTrajectory:
    """Joint targets sampled every ``dt`` from ``dt`` on (the start, at time 0, is where the move begins).

    Attributes:
        q: Positions [rad], (ticks, joints).
        qd: Velocities [rad/s], (ticks, joints).
        qdd: Accelerations [rad/s^2], (ticks, joints).
        dt: Sampling period [s].
    """

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    dt: float

    def __len__(self) -> int:
        return len(self.q)

    @property
    def duration(self) -> float:
        """Duration of the move [s]."""
        return len(self.q) * self.dt


def _check_limits(velocity_limit: np.ndarray | float, n_joints: int) -> np.ndarray:
    limit = np.asarray(velocity_limit, dtype=np.float64)
    if limit.shape != (n_joints,):  # a scalar (or a broadcastable array): broadcast; a vector as it is
        limit = np.broadcast_to(limit, (n_joints,))
    if not np.logical_and.reduce(np.isfinite(limit) & (limit > 0)):  # .all(), without its Python layer
        raise InvalidValueError(f"velocity_limit must be positive and finite for every joint, got {velocity_limit!r}.")
    return limit


def minimum_jerk(q_from: np.ndarray, waypoints: list[np.ndarray] | np.ndarray, velocity_limit: np.ndarray | float,
                 dt: float, *, duration: float | None = None, min_duration: float = 0.0,
                 blend: float = VIA_BLEND) -> JointTrajectory:
    """A move from ``q_from`` through ``waypoints`` to the last one, at rest at both ends.

    One minimum-jerk segment per waypoint; each starts ``blend`` of the shorter segment's duration before the
    previous one ends, so the joints pass near the via points at speed instead of stopping there. Each segment
    lasts the shortest time in which no joint exceeds its limit (at least ``min_duration``), and the whole is
    stretched until no joint exceeds its limit where segments overlap.

    Args:
        q_from: Start [rad], (joints,).
        waypoints: Via points and goal [rad], (n, joints).
        velocity_limit: Largest speed of each joint [rad/s], (joints,) or a scalar.
        dt: Sampling period [s].
        duration: If given, the move lasts this long [s], or longer where a joint would exceed its limit.
        min_duration: Shortest segment [s].
        blend: Overlap of consecutive segments, a share of the shorter one, in [0, 1).

    Returns:
        The samples at dt, 2 dt, ... up to the end of the move (at least one).
    """
    q_from = np.asarray(q_from, dtype=np.float64)
    points = np.atleast_2d(np.asarray(waypoints, dtype=np.float64))
    if points.shape[1:] != q_from.shape or q_from.ndim != 1 or len(points) == 0:
        raise InvalidValueError(f"waypoints must be (n, {q_from.size}) for a start of shape {q_from.shape}, got "
                         f"{points.shape}.")
    if not (0.0 <= blend < 1.0):
        raise InvalidValueError(f"blend must lie in [0, 1), got {blend!r}.")
    if not dt > 0:
        raise InvalidValueError(f"dt must be positive [s], got {dt!r}.")
    limit = _check_limits(velocity_limit, q_from.size)
    # np.diff(np.vstack([q_from, points]), axis=0), without the two wrappers: each row minus the one before
    stacked = np.concatenate((q_from[None, :], points))
    deltas = stacked[1:] - stacked[:-1]
    # np.max and ndarray.any as the ufunc reductions they run, without their Python layers (here and below)
    lengths = np.maximum(max(min_duration, 1e-9),
                         PEAK_SPEED_FACTOR * np.maximum.reduce(np.abs(deltas) / limit, axis=1))
    starts = np.zeros(len(deltas))
    for k in range(1, len(deltas)):
        starts[k] = starts[k - 1] + lengths[k - 1] - blend * min(lengths[k - 1], lengths[k])
    end = float(np.maximum.reduce(starts + lengths))
    if not np.logical_or.reduce(deltas, axis=None):
        return _hold(q_from, end, dt, duration)

    def grid(stretch: float) -> tuple[np.ndarray, float]:
        """Each segment's progress (ticks, segments) at the samples of the move stretched ``stretch`` times, and
        the real seconds per unstretched second."""
        n = max(1, round(stretch * end / dt))
        t = (np.arange(1, n + 1) * (end / n))[:, None]  # unstretched time of each sample
        return ((t - starts) / lengths).clip(0.0, 1.0), n * dt / end  # np.clip's own method, without its wrapper

    def velocity(tau: np.ndarray, time_scale: float) -> np.ndarray:
        rate = 30.0 * tau ** 2 * (1.0 + tau * (tau - 2.0)) / lengths
        return matmul(rate, deltas) / time_scale

    # The velocities decide how far the move must stretch: the positions and accelerations are computed once,
    # for the samples kept.
    tau, time_scale = grid(1.0)
    qd = velocity(tau, time_scale)
    # Overlapping segments may add up, and rounding to whole samples shortens by up to half a sample.
    stretch = max(1.0, float(np.maximum.reduce(np.abs(qd) / limit, axis=None)))
    if duration is not None:
        stretch = max(stretch, duration / end)
    if stretch > 1.0:
        tau, time_scale = grid(stretch)
        qd = velocity(tau, time_scale)
        over = float(np.maximum.reduce(np.abs(qd) / limit, axis=None))
        if over > 1.0:  # the rounding to whole samples: one sample more
            tau, time_scale = grid(stretch * over + dt / end)
            qd = velocity(tau, time_scale)
    position = tau ** 3 * (10.0 + tau * (6.0 * tau - 15.0))
    acceleration = 60.0 * tau * (1.0 + tau * (2.0 * tau - 3.0)) / lengths ** 2
    return JointTrajectory(q_from + matmul(position, deltas), qd, matmul(acceleration, deltas) / time_scale ** 2, dt)


def _hold(q_from: np.ndarray, end: float, dt: float, duration: float | None) -> JointTrajectory:
    """What :func:`minimum_jerk` gives for a move that goes nowhere (every waypoint at ``q_from``), lasting ``end``
    [s] unstretched, without its arithmetic: the same samples, bit for bit.

    Every product with a zero delta is zero and einsum sums them from +0, so the velocities and accelerations are
    +0, no joint exceeds its limit (the move stretches only to ``duration``), and the positions are
    ``q_from + 0.0`` (a -0 becomes +0, as there)."""
    stretch = 1.0 if duration is None else max(1.0, duration / end)
    n = max(1, round(stretch * end / dt))
    zeros = np.zeros((n, q_from.size))
    return JointTrajectory(zeros + (q_from + 0.0), zeros, zeros.copy(), dt)


def line_profile(length: float, speed: float, dt: float, *, ramp: float = 0.0, from_rest: bool = True,
                 to_rest: bool = True) -> np.ndarray:
    """Distance travelled along a straight line at each sample dt, 2 dt, ... [m], and its speed [m/s].

    The line is covered at ``speed``; a start from rest (``from_rest``) and a stop at rest (``to_rest``) each take
    ``ramp`` [s], along half a minimum-jerk speed profile (the speed rises as 10 u^3 - 15 u^4 + 6 u^5 over the ramp,
    u from 0 to 1), covering ``speed * ramp / 2``. Without a ramp the speed steps. If the line is too short for the
    ramps at full speed, the cruise speed is lowered so that the ramps meet.

    Returns:
        (samples, 2): distance [m] and speed [m/s]; the last sample is at ``length``.
    """
    if not (length > 0 and np.isfinite(length)):
        raise InvalidValueError(f"length must be positive [m], got {length!r}.")
    if not (speed > 0 and np.isfinite(speed)):
        raise InvalidValueError(f"speed must be positive [m/s], got {speed!r}.")
    if not (dt > 0 and ramp >= 0):
        raise InvalidValueError(f"dt must be positive and ramp non-negative [s], got dt={dt!r}, ramp={ramp!r}.")
    up = ramp if from_rest else 0.0
    down = ramp if to_rest else 0.0
    ramp_length = speed * (up + down) / 2
    if ramp_length > length:  # no room to cruise: the cruise speed that lets the ramps meet
        speed *= length / ramp_length
        ramp_length = length
    total = up + down + (length - ramp_length) / speed
    n = max(1, int(np.ceil(total / dt - 1e-9)))
    t = np.arange(1, n + 1) * dt
    t[-1] = min(t[-1], total)

    def ramp_up(tt: np.ndarray, width: float) -> tuple[np.ndarray, np.ndarray]:
        """Distance and speed after ``tt`` of a ramp of ``width`` from rest to ``speed``."""
        u = np.clip(tt / width, 0.0, 1.0)
        v = speed * u ** 3 * (10.0 + u * (6.0 * u - 15.0))
        s = speed * width * u ** 4 * (2.5 + u * (u - 3.0))  # the integral of v
        return s, v

    s = np.empty(n)
    v = np.empty(n)
    cruise_end = total - down
    for i, ti in enumerate(t):
        if up > 0 and ti < up:
            s[i], v[i] = (float(x) for x in ramp_up(np.array(ti), up))
        elif ti <= cruise_end:
            s[i], v[i] = speed * up / 2 + speed * (ti - up), speed
        else:
            s_left, v_left = ramp_up(np.array(total - ti), down)
            s[i], v[i] = length - float(s_left), float(v_left)
    s[-1], v[-1] = length, 0.0 if to_rest else speed
    return np.column_stack([s, v])
