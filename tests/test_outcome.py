"""Outcome labels from measured motion: rolling, sliding, toppling, leaving the table, coming to rest.

The monitor is fed hand-made trajectories (no simulator), each the motion of a rigid body that a physicist would
name without hesitation; then the same labels are checked on simulated taps.
"""

import numpy as np
import pytest

from affordance_env.outcome import REST_DURATION, ObjectMonitor, outcome_labels, tilt

TABLE_TOP = 0.0
LOW, HIGH = np.array([-0.5, -0.5]), np.array([0.5, 0.5])
DT = 0.01


def _rot_x(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _quat_x(angle: float) -> np.ndarray:
    return np.array([np.cos(angle / 2), np.sin(angle / 2), 0.0, 0.0])


def _run(trajectory, radius: float) -> tuple[ObjectMonitor, np.ndarray]:
    """Feed ``trajectory(t) -> (p, angle about x, v, w_world)`` for 0.6 s; returns the monitor, final quat."""
    p0 = np.array([0.0, 0.2, radius])
    monitor = ObjectMonitor(TABLE_TOP, LOW, HIGH, p0, 0.0)
    angle = 0.0
    for k in range(1, 61):
        t = k * DT
        p, angle, v, w_world = trajectory(t)
        monitor.sample(t, p, v, w_world)
    return monitor, _quat_x(angle)


def test_a_ball_rolling_without_slipping_rolls():
    r, speed = 0.03, 0.2

    def roll(t):  # along -y: the ball turns about +x at speed / r, its lowest point at rest
        return np.array([0.0, 0.2 - speed * t, r]), speed * t / r, np.array([0.0, -speed, 0.0]), \
            np.array([speed / r, 0.0, 0.0])

    monitor, quat = _run(roll, r)
    assert monitor.rolling_distance == pytest.approx(0.12, rel=1e-6)
    labels = outcome_labels(monitor, _quat_x(0.0), quat, roll_threshold=0.03)
    assert labels.rolled and not labels.toppled  # its axes turned by 4 rad at a constant centre height
    assert labels.tilt > np.pi / 4


def test_a_sliding_box_does_not_roll():
    r, speed = 0.03, 0.2

    def slide(t):
        return np.array([0.0, 0.2 - speed * t, r]), 0.0, np.array([0.0, -speed, 0.0]), np.zeros(3)

    monitor, quat = _run(slide, r)
    assert monitor.rolling_distance == 0.0 and monitor.path_length == pytest.approx(0.12)
    labels = outcome_labels(monitor, _quat_x(0.0), quat, roll_threshold=0.03)
    assert not labels.rolled and not labels.toppled


def test_a_box_tipping_over_its_edge_topples_and_does_not_roll():
    r = 0.05  # a 10 cm cube tips over its edge at y = 0.15 by a quarter turn in 0.6 s
    edge = np.array([0.0, 0.2 - r, 0.0])
    rate = (np.pi / 2) / 0.6

    def tip(t):
        angle = rate * t
        arm = _rot_x(angle) @ np.array([0.0, r, r])  # centre relative to the edge
        w = np.array([rate, 0.0, 0.0])
        return edge + arm, angle, np.cross(w, arm), w

    monitor, quat = _run(tip, r)
    assert monitor.max_rise == pytest.approx(r * (np.sqrt(2) - 1), rel=1e-3)
    labels = outcome_labels(monitor, _quat_x(0.0), quat, roll_threshold=0.03)
    assert labels.toppled and not labels.rolled
    assert monitor.rolling_distance < 0.03  # only the top of the arc looks like rolling


def test_a_standing_cylinder_that_topples_then_rolls_away_is_both():
    r, speed, rate = 0.04, 0.2, (np.pi / 2) / 0.15
    edge = np.array([0.0, 0.2 - r, 0.0])

    def topple_then_roll(t):
        if t <= 0.15:
            angle = rate * t
            arm = _rot_x(angle) @ np.array([0.0, r, r])
            w = np.array([rate, 0.0, 0.0])
            return edge + arm, angle, np.cross(w, arm), w
        s = t - 0.15  # now lying, it rolls on along -y
        return np.array([0.0, 0.2 - 2 * r - speed * s, r]), np.pi / 2 + speed * s / r, \
            np.array([0.0, -speed, 0.0]), np.array([speed / r, 0.0, 0.0])

    monitor, quat = _run(topple_then_roll, r)
    labels = outcome_labels(monitor, _quat_x(0.0), quat, roll_threshold=0.03)
    assert labels.toppled and labels.rolled


def test_leaving_the_table_is_recorded_where_and_when_it_happens():
    r, speed = 0.02, 1.0

    def off(t):  # crosses the edge at y = -0.5 at t = 0.3
        return np.array([0.0, -0.2 - speed * t, r]), 0.0, np.array([0.0, -speed, 0.0]), np.zeros(3)

    monitor, _ = _run(off, r)
    assert monitor.left_table
    assert monitor.exit_time == pytest.approx(0.31)  # the first sample past the edge
    assert monitor.exit_position[1] == pytest.approx(-0.51)
    distance_at_exit = monitor.path_length
    assert distance_at_exit == pytest.approx(0.3, abs=1e-9)  # nothing is counted after the object left


def test_an_object_held_over_the_edge_has_not_left_the_table_until_it_falls():
    start = np.array([0.0, -0.49, TABLE_TOP + 0.02])
    still = (np.zeros(3), np.zeros(3))
    over_the_edge = np.array([0.0, -0.51, TABLE_TOP + 0.03])  # beyond y = -0.5, above the top
    for held in (True, False):
        monitor = ObjectMonitor(TABLE_TOP, LOW, HIGH, start, 0.0)
        monitor.held = held
        monitor.sample(0.01, over_the_edge, *still)
        assert monitor.left_table is not held
    # held, back over the table: still on it; let go beyond the edge, or fallen below the top in the hand: off it
    monitor = ObjectMonitor(TABLE_TOP, LOW, HIGH, start, 0.0)
    monitor.held = True
    monitor.sample(0.01, over_the_edge, *still)
    monitor.sample(0.02, start, *still)
    assert not monitor.left_table
    monitor.sample(0.03, np.array([0.0, -0.52, TABLE_TOP - 0.01]), *still)
    assert monitor.left_table and monitor.exit_time == 0.03 and monitor.exit_position[1] == -0.52
    monitor = ObjectMonitor(TABLE_TOP, LOW, HIGH, start, 0.0)
    monitor.held = True
    monitor.sample(0.01, over_the_edge, *still)
    monitor.held = False
    monitor.sample(0.02, over_the_edge, *still)
    assert monitor.left_table and monitor.exit_time == 0.02


def test_rest_counts_from_a_given_time():
    monitor = ObjectMonitor(TABLE_TOP, LOW, HIGH, np.array([0.0, 0.0, 0.02]), 0.0)
    still = (np.array([0.0, 0.0, 0.02]), np.zeros(3), np.zeros(3))
    moving = (np.array([0.0, 0.0, 0.02]), np.array([0.0, 0.1, 0.0]), np.zeros(3))
    monitor.sample(0.01, *still)
    assert monitor.at_rest(0.06) and not monitor.at_rest(0.06, since=0.05)  # still since 0, touched at 0.05
    monitor.sample(0.07, *moving)
    assert not monitor.at_rest(0.07)
    monitor.sample(0.08, *still)
    assert not monitor.at_rest(0.08 + REST_DURATION / 2) and monitor.at_rest(0.08 + REST_DURATION)


def test_tilt_of_the_initially_vertical_axis():
    upright = np.array([1.0, 0.0, 0.0, 0.0])
    assert tilt(upright, _quat_x(np.pi / 2)) == pytest.approx(np.pi / 2)
    spun = np.array([np.cos(0.5), 0.0, 0.0, np.sin(0.5)])  # about the vertical only
    assert tilt(upright, spun) == pytest.approx(0.0, abs=1e-9)
    # a lying cylinder (axis along world x) that rolls a quarter turn about its axis tilts its vertical too:
    # tilt alone cannot tell rolling from toppling (the centre's rise does)
    lying = np.array([np.sqrt(0.5), 0.0, np.sqrt(0.5), 0.0])
    rolled = np.empty(4)
    import mujoco

    mujoco.mju_mulQuat(rolled, _quat_x(np.pi / 2), lying)
    assert tilt(lying, rolled) == pytest.approx(np.pi / 2)
