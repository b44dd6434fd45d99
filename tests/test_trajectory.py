"""The robot's trajectories as pure functions: minimum-jerk joint moves within velocity limits, Cartesian line
profiles. No simulator."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from affordance_env.trajectory import PEAK_SPEED_FACTOR, line_profile, minimum_jerk

DT = 0.01


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3), st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3),
       st.lists(st.floats(0.5, 4.0), min_size=3, max_size=3))
def test_a_move_stays_within_every_joints_limit_and_ends_at_rest_at_its_goal(q0, q1, limit):
    q0, q1, limit = np.array(q0), np.array(q1), np.array(limit)
    move = minimum_jerk(q0, [q1], limit, DT)
    assert np.all(np.abs(move.qd) <= limit * (1 + 1e-9))
    np.testing.assert_allclose(move.q[-1], q1, atol=1e-12)
    np.testing.assert_allclose(move.qd[-1], 0.0, atol=1e-9)
    # and it is not slower than it needs to be: the slowest joint's peak is within a sample of its limit
    if np.max(np.abs(q1 - q0)) > 0.1:
        assert np.max(np.abs(move.qd) / limit) > 0.9


def test_the_slowest_joint_sets_the_duration_and_the_others_keep_pace():
    move = minimum_jerk(np.zeros(2), [np.array([1.0, 1.0])], np.array([1.0, 4.0]), DT)
    assert move.duration == pytest.approx(PEAK_SPEED_FACTOR * 1.0 / 1.0, abs=DT)
    np.testing.assert_allclose(move.q[:, 0], move.q[:, 1])  # one profile for all joints: a straight joint path


def test_a_longer_duration_is_kept_and_a_shorter_one_is_not():
    limit = np.array([1.0])
    assert minimum_jerk(np.zeros(1), [np.ones(1)], limit, DT, duration=3.0).duration == pytest.approx(3.0, abs=DT)
    short = minimum_jerk(np.zeros(1), [np.ones(1)], limit, DT, duration=0.5)
    assert short.duration >= PEAK_SPEED_FACTOR - DT and np.max(np.abs(short.qd)) <= 1.0 + 1e-9


def test_via_points_are_passed_at_speed_within_the_limits():
    via, goal = np.array([1.0, 0.0]), np.array([1.0, 1.0])
    move = minimum_jerk(np.zeros(2), [via, goal], 2.0, DT)
    assert np.all(np.abs(move.qd) <= 2.0 + 1e-9)
    np.testing.assert_allclose(move.q[-1], goal, atol=1e-12)
    distance = np.linalg.norm(move.q - via, axis=1)
    assert distance.min() < 0.3  # near the via point, without stopping there
    assert np.linalg.norm(move.qd[np.argmin(distance)]) > 0.5


def test_the_acceleration_is_the_derivative_of_the_velocity():
    move = minimum_jerk(np.zeros(1), [np.ones(1)], 1.0, 0.001)
    np.testing.assert_allclose(np.gradient(move.qd[:, 0], 0.001)[5:-5], move.qdd[5:-5, 0], atol=1e-2)
    np.testing.assert_allclose(np.gradient(move.q[:, 0], 0.001)[5:-5], move.qd[5:-5, 0], atol=1e-3)


@pytest.mark.parametrize("bad", [dict(velocity_limit=0.0), dict(velocity_limit=np.nan), dict(dt=0.0),
                                 dict(blend=1.0), dict(waypoints=[np.zeros(3)])])
def test_bad_moves_raise(bad):
    kwargs = dict(q_from=np.zeros(2), waypoints=[np.ones(2)], velocity_limit=1.0, dt=DT) | bad
    with pytest.raises(ValueError):
        minimum_jerk(**kwargs)


@pytest.mark.parametrize("to_rest", [True, False])
def test_a_line_reaches_its_end_at_its_speed_and_never_faster(to_rest):
    profile = line_profile(0.08, 0.05, DT, ramp=0.1, to_rest=to_rest)
    s, v = profile[:, 0], profile[:, 1]
    assert s[-1] == pytest.approx(0.08) and np.all(np.diff(s) >= 0)
    assert np.all(v <= 0.05 + 1e-12) and v[0] < 0.01  # from rest ...
    assert v[-1] == (0.0 if to_rest else 0.05)  # ... to rest, or at speed
    # the distance is the integral of the speed
    np.testing.assert_allclose(np.diff(s)[5:-5], (0.5 * (v[1:] + v[:-1]) * DT)[5:-5], rtol=0.02)
    cruise = 0.08 / 0.05 + 0.1 * (1 + to_rest) / 2
    assert len(profile) * DT == pytest.approx(cruise, abs=DT)


def test_a_line_too_short_for_its_ramps_cruises_slower():
    profile = line_profile(0.002, 0.05, DT, ramp=0.2)
    assert profile[-1, 0] == pytest.approx(0.002) and profile[:, 1].max() < 0.05


@pytest.mark.parametrize("bad", [dict(length=0.0), dict(speed=-1.0), dict(dt=0.0), dict(ramp=-0.1)])
def test_bad_lines_raise(bad):
    with pytest.raises(ValueError):
        line_profile(**(dict(length=0.1, speed=0.1, dt=DT) | bad))
