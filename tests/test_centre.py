"""Where an object stands, from the points of it a camera sees: synthetic point clouds of each shape, no simulator."""

import math

import numpy as np
import pytest

from affordance_env.centre import MIN_POINTS, object_centre, visible_top_centre
from affordance_env.exceptions import InvalidValueError

TABLE_TOP = 0.0
#: The head's camera, as in the scene: above the table, toward the robot (+x) from the objects [m].
CAMERA = np.array([0.05, 0.0, 0.45])


def _grid(n: int) -> np.ndarray:
    return (np.arange(n) + 0.5) / n * 2 - 1  # n values evenly over (-1, 1)


def surface(kind: str, size: float) -> tuple[np.ndarray, np.ndarray]:
    """Points (k, 3) on the surface of a shape of ``size`` [m] centred at the origin, and their outward normals."""
    h, n = size / 2, 40
    if kind == "sphere":
        k = np.arange(4000) + 0.5
        z = 1 - 2 * k / 4000
        a = math.pi * (1 + 5 ** 0.5) * k
        normals = np.stack([np.sqrt(1 - z * z) * np.cos(a), np.sqrt(1 - z * z) * np.sin(a), z], axis=1)
        return h * normals, normals
    if kind == "box":
        u, v = (g.ravel() for g in np.meshgrid(_grid(n), _grid(n)))
        points, normals = [], []
        for axis in range(3):
            for sign in (-1.0, 1.0):
                p = np.empty((len(u), 3))
                p[:, axis], p[:, (axis + 1) % 3], p[:, (axis + 2) % 3] = sign, u, v
                points.append(h * p)
                normals.append(np.eye(3)[axis] * sign + 0 * p)
        return np.concatenate(points), np.concatenate(normals)
    # a cylinder as long as it is wide, its axis along z
    a, z = (g.ravel() for g in np.meshgrid(np.linspace(0, 2 * math.pi, 4 * n, endpoint=False), _grid(n)))
    side = np.stack([np.cos(a), np.sin(a), z], axis=1)
    side_normals = np.stack([np.cos(a), np.sin(a), 0 * z], axis=1)
    x, y = (g.ravel() for g in np.meshgrid(_grid(n), _grid(n)))
    disk = x * x + y * y <= 1
    caps = [np.stack([x[disk], y[disk], s + 0 * x[disk]], axis=1) for s in (-1.0, 1.0)]
    cap_normals = [np.tile([0.0, 0.0, s], (disk.sum(), 1)) for s in (-1.0, 1.0)]
    return h * np.concatenate([side, *caps]), np.concatenate([side_normals, *cap_normals])


def seen(kind: str, size: float, xy: tuple[float, float], yaw: float = 0.0, lying: bool = False) -> np.ndarray:
    """The points of the shape resting on the table at ``xy`` [m] with ``yaw`` [rad] that face the camera (a convex
    shape: those are the ones it sees)."""
    points, normals = surface(kind, size)
    if lying:  # the axis along x
        turn = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
        points, normals = points @ turn.T, normals @ turn.T
    c, s = math.cos(yaw), math.sin(yaw)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    points = points @ R.T + np.array([xy[0], xy[1], TABLE_TOP + size / 2])
    normals = normals @ R.T
    facing = np.einsum("ij,ij->i", normals, CAMERA - points) > 0
    return points[facing]


CASES = {
    "sphere": ("sphere", "sphere", 0.06, 0.0, False),
    "box turned 30 degrees": ("box", "box", 0.08, math.radians(30), False),
    "box turned 80 degrees": ("box", "box", 0.05, math.radians(80), False),
    "standing cylinder": ("cylinder", "cylinder", 0.07, 0.0, False),
    "lying cylinder across": ("cylinder", "cylinder", 0.09, math.radians(90), True),
    "lying cylinder turned 40 degrees": ("cylinder", "cylinder", 0.06, math.radians(40), True),
}


@pytest.mark.parametrize("case", CASES)
def test_each_shape_seen_from_the_head_is_placed_at_its_centre(case):
    kind, primitive, size, yaw, lying = CASES[case]
    xy = (-0.30, 0.12)
    points = seen(kind, size, xy, yaw, lying)
    np.testing.assert_allclose(object_centre(points, primitive, TABLE_TOP), xy, atol=5e-4)


@pytest.mark.parametrize("case", [name for name in CASES if name != "box turned 30 degrees"])
def test_an_object_more_than_half_hidden_is_placed_by_the_part_in_view(case):
    # an arm hides the object's side toward -y, past its centre: the visible top's centre moves by a centimetre or
    # more, the fit does not. (A cube turned 30 degrees, hidden so, keeps no face whose extent fixes where it is
    # along the other: the fit may slide along it, as object_centre's docstring says.)
    kind, primitive, size, yaw, lying = CASES[case]
    xy = (-0.25, -0.18)
    points = seen(kind, size, xy, yaw, lying)
    points = points[points[:, 1] > xy[1] + size / 10]
    assert np.linalg.norm(visible_top_centre(points) - xy) > 0.01
    np.testing.assert_allclose(object_centre(points, primitive, TABLE_TOP), xy, atol=5e-4)


def test_noise_and_stray_points_move_the_estimate_by_at_most_a_millimetre():
    rng = np.random.default_rng(0)
    xy = (-0.32, 0.02)
    points = seen("box", 0.07, xy, math.radians(20))
    points = points + rng.normal(0.0, 0.001, points.shape)  # the Kinect model's spread at half a metre
    stray = rng.choice(len(points), len(points) // 100, replace=False)
    points[stray, 2] += 0.008  # a few points well above the top
    np.testing.assert_allclose(object_centre(points, "box", TABLE_TOP), xy, atol=1e-3)


def test_a_cylinder_is_fitted_lying_or_standing_whichever_it_does():
    # a standing cylinder that toppled: its primitive is still a cylinder, and the fit finds it lying
    xy = (-0.28, 0.0)
    for lying in (False, True):
        points = seen("cylinder", 0.08, xy, math.radians(60), lying)
        np.testing.assert_allclose(object_centre(points, "cylinder", TABLE_TOP), xy, atol=5e-4)


def test_the_table_height_sets_the_centre_height():
    xy = (-0.3, 0.05)
    points = seen("sphere", 0.05, xy) + np.array([0.0, 0.0, 0.7])  # the same sphere on a table 0.7 m high
    np.testing.assert_allclose(object_centre(points, "sphere", 0.7), xy, atol=5e-4)


def test_a_few_points_are_placed_at_their_top():
    points = seen("sphere", 0.05, (-0.3, 0.05))[:MIN_POINTS - 1]
    np.testing.assert_array_equal(object_centre(points, "sphere", TABLE_TOP), visible_top_centre(points))


@pytest.mark.parametrize(("points", "primitive", "table_top", "match"), [
    (np.zeros((0, 3)), "sphere", 0.0, "points must be finite points"),
    (np.zeros((5, 2)), "sphere", 0.0, r"got shape \(5, 2\)"),
    (np.full((5, 3), np.nan), "sphere", 0.0, "points must be finite"),
    (np.zeros((5, 3)), "cone", 0.0, "primitive must be one of .* got 'cone'"),
    (np.zeros((5, 3)), "box", float("nan"), "table_top must be a finite height"),
    (np.zeros((5, 3)), "box", "0.7", "table_top must be a finite height .* got '0.7'"),
])
def test_bad_input_is_refused_naming_it(points, primitive, table_top, match):
    with pytest.raises(InvalidValueError, match=match):
        object_centre(points, primitive, table_top)
