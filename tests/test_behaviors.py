"""Stroke planning is a pure function: where the hand starts and ends, for each behaviour and action."""

import numpy as np
import pytest

from affordance_env.behaviors import BEHAVIORS, check_action, get_behavior, is_success
from affordance_env.behaviors.draw import DRAW_GAP, DRAW_PAST, DRAW_PAST_RANGE, DRAW_SPEED, PALM_OFFSET
from affordance_env.behaviors.stroke import CLEARANCE, FOLLOW_THROUGH, SPEED_CANONICAL, half_extent_along, plan_stroke
from affordance_env.objects import object_geometry

TABLE = -0.07


@pytest.mark.parametrize("name", list(BEHAVIORS))
def test_hand_orientations_are_rotations(name):
    R = BEHAVIORS[name].R_world_hand
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0)


def test_canonical_tap_starts_beside_the_object_at_clearance():
    sphere = object_geometry("sphere", 0.06)
    p_object = np.array([-0.30, 0.03, TABLE + 0.03])
    plan = plan_stroke(get_behavior("tap"), sphere, p_object, 0.0, TABLE, np.zeros(3))
    np.testing.assert_allclose(plan.direction, [0, -1, 0])
    # the palm surface (1.2 cm in front of the palm frame) is CLEARANCE from the sphere's side
    gap = plan.p_start[1] - 0.012 - (p_object[1] + 0.03)
    assert gap == pytest.approx(CLEARANCE)
    assert plan.p_start[0] == pytest.approx(p_object[0])
    assert plan.speed == pytest.approx(SPEED_CANONICAL)
    # without contact, the palm surface would end FOLLOW_THROUGH beyond where the object's far side was
    assert plan.p_end[1] - 0.012 == pytest.approx(p_object[1] - 0.03 - FOLLOW_THROUGH)
    # the tap comes straight from home, which is on its side of the object; the behaviours whose hand
    # crosses over or comes around the object pass above it, clearing its top with the hand's lowest point
    assert plan.p_above is None
    for name in ("tap_back", "push"):
        above = plan_stroke(get_behavior(name), sphere, p_object, 0.0, TABLE, np.zeros(3)).p_above
        assert above[2] - 0.033 > TABLE + 0.06


def test_action_moves_height_lateral_offset_and_speed():
    box = object_geometry("box", 0.08)
    p_object = np.array([-0.30, 0.03, TABLE + 0.04])
    base = plan_stroke(get_behavior("tap"), box, p_object, 0.0, TABLE, np.zeros(3))
    moved = plan_stroke(get_behavior("tap"), box, p_object, 0.0, TABLE, np.array([1.0, 1.0, 1.0]))
    # the tap moves along -y; its "across" direction is +x (direction turned by +90 degrees)
    np.testing.assert_allclose(moved.p_start - base.p_start, [0.02, 0.0, 0.015], atol=1e-12)
    np.testing.assert_allclose(moved.p_end - base.p_end, [0.02, 0.0, 0.015], atol=1e-12)  # a parallel stroke
    assert moved.speed == pytest.approx(3 * SPEED_CANONICAL)  # hardest: 3 x the canonical speed
    gentle = plan_stroke(get_behavior("tap"), box, p_object, 0.0, TABLE, np.array([0.0, 0.0, -1.0]))
    assert gentle.speed == pytest.approx(SPEED_CANONICAL / 3)


def test_push_and_tap_back_move_the_other_ways():
    assert np.allclose(get_behavior("push").direction, [-1, 0])
    assert np.allclose(get_behavior("tap_back").direction, [0, 1])


def test_box_extent_grows_with_yaw():
    box = object_geometry("box", 0.06)
    assert half_extent_along(box, 0.0, np.array([0.0, -1.0])) == pytest.approx(0.03)
    assert half_extent_along(box, np.pi / 4, np.array([0.0, -1.0])) == pytest.approx(0.03 * np.sqrt(2))
    sphere = object_geometry("sphere", 0.06)
    assert half_extent_along(sphere, 0.7, np.array([1.0, 0.0])) == pytest.approx(0.03)


@pytest.mark.parametrize(
    "action, match", [([0, 0], "shape"), ([0, np.inf, 0], "finite"), ([0, 0, -1.01], r"\[-1, 1\]")]
)
def test_bad_actions(action, match):
    with pytest.raises(ValueError, match=match):
        check_action(np.array(action, dtype=float))


def test_unknown_behavior_lists_valid_ones():
    with pytest.raises(ValueError, match="tap, tap_back, push, grasp, draw"):
        get_behavior("pinch")


def test_success_rules():
    assert BEHAVIORS["tap"].success_rule == BEHAVIORS["tap_back"].success_rule == "rolled"
    assert BEHAVIORS["push"].success_rule == "moved"
    assert is_success("rolled", True, 0.0) is True and is_success("rolled", False, 0.2) is False
    assert is_success("moved", False, 0.031) is True and is_success("moved", True, 0.02) is False
    assert is_success("moved", False, 0.02, threshold=0.01) is True
    np.testing.assert_array_equal(is_success("moved", np.zeros(3, bool), np.array([0.01, 0.03, 0.05])),
                                  [False, False, True])
    with pytest.raises(ValueError, match="rolled"):
        is_success("slid", True, 0.1)


def test_canonical_draw_reaches_behind_the_object_and_drags_it_toward_the_robot():
    box = object_geometry("box", 0.08)
    p_object = np.array([-0.30, 0.03, TABLE + 0.04])
    draw = get_behavior("draw")
    plan = draw.plan(box, p_object, 0.0, TABLE, np.zeros(3))
    np.testing.assert_allclose(plan.direction, [1, 0, 0])  # +x: toward the robot
    # the palm surface starts DRAW_GAP beyond the object's far side, and the palm stops DRAW_PAST past its centre
    assert p_object[0] - 0.04 - (plan.p_start[0] + PALM_OFFSET) == pytest.approx(DRAW_GAP)
    assert plan.p_end[0] == pytest.approx(p_object[0] + DRAW_PAST)
    assert plan.p_start[1] == plan.p_end[1] == pytest.approx(p_object[1])
    # it drags to the line's end and stops at rest there, instead of a follow-through past the first touch
    assert plan.follow_through == np.inf and plan.to_rest and plan.speed == pytest.approx(DRAW_SPEED)
    # it comes from above the start: the hand crosses over the object to get behind it
    assert plan.p_above[:2] == pytest.approx(plan.p_start[:2]) and plan.p_above[2] - 0.033 > TABLE + 0.08
    # the palm faces the robot (and the table): it can pull, not only push
    normal = draw.R_world_hand[:, 2]
    assert normal[0] > 0.5 and normal[2] < 0


def test_draw_action_moves_the_line_across_lengthens_it_and_speeds_it_up():
    sphere = object_geometry("sphere", 0.06)
    p_object = np.array([-0.30, 0.03, TABLE + 0.03])
    draw = get_behavior("draw")
    base = draw.plan(sphere, p_object, 0.0, TABLE, np.zeros(3))
    moved = draw.plan(sphere, p_object, 0.0, TABLE, np.array([1.0, 1.0, 1.0]))
    np.testing.assert_allclose(moved.p_start - base.p_start, [0.0, 0.02, 0.0], atol=1e-12)
    np.testing.assert_allclose(moved.p_end - base.p_end, [DRAW_PAST_RANGE, 0.02, 0.0], atol=1e-12)
    assert moved.speed == pytest.approx(2 * DRAW_SPEED)
    assert draw.plan(sphere, p_object, 0.0, TABLE, np.array([0.0, -1.0, -1.0])).speed == pytest.approx(DRAW_SPEED / 2)
