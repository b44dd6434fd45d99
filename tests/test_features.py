"""The 49 features against analytic ground truth, on a synthetic pinhole range camera (pure numpy, no MuJoCo).

The test camera casts one ray through each pixel centre and intersects it analytically with a plane
rectangle, a sphere or an oriented box. Its orientation ``R_world_camera`` has as columns the image right
(+u), image down (+v) and forward (optical axis) directions in the world frame.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import hypothesis.extra.numpy as hnp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from affordance_env.features import (
    EDGE_TOLERANCE_RAD,
    FEATURE_DESCRIPTIONS,
    FEATURE_GROUPS,
    FEATURE_NAMES,
    FEATURE_UNITS,
    N_FEATURES,
    NOT_VISIBLE_VALUES,
    VERTICAL_TOLERANCE_RAD,
    Features,
    compute_features,
    effect_features,
    wrap_axis_angle,
)

INDEX = {name: i for i, name in enumerate(FEATURE_NAMES)}
LAT = slice(INDEX["normal_lat_00"], INDEX["normal_lat_11"] + 1)
LON = slice(INDEX["normal_lon_00"], INDEX["normal_lon_11"] + 1)
SHAPE = slice(0, 24)


# ----------------------------------------------------------------------------------------------------
# A synthetic pinhole range camera and analytic ray intersections
# ----------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PinholeCamera:
    """Square-pixel pinhole camera; principal point at the image centre; focal length in pixels."""

    width: int
    height: int
    focal_px: float
    p_world_camera: np.ndarray
    R_world_camera: np.ndarray

    @property
    def uv_principal(self) -> np.ndarray:
        """Principal point (u, v) [pixels]."""
        return np.array([(self.width - 1) / 2.0, (self.height - 1) / 2.0])

    def ray_directions(self) -> np.ndarray:
        """Unit ray directions in the world frame, (H, W, 3)."""
        v, u = np.mgrid[0 : self.height, 0 : self.width].astype(float)
        cu, cv = self.uv_principal
        d_camera = np.stack([(u - cu) / self.focal_px, (v - cv) / self.focal_px, np.ones_like(u)], axis=-1)
        d_camera /= np.linalg.norm(d_camera, axis=-1, keepdims=True)
        return d_camera @ self.R_world_camera.T

    def project(self, p_world: np.ndarray) -> np.ndarray:
        """Pixel coordinates (u, v) of a world point in front of the camera."""
        p_camera = self.R_world_camera.T @ (np.asarray(p_world, float) - self.p_world_camera)
        return self.uv_principal + self.focal_px * p_camera[:2] / p_camera[2]

    def snapshot(self, distance: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Points (H, W, 3) [m, NaN on misses], ranges (H, W) [m, inf on misses], mask, from hit distances."""
        mask = np.isfinite(distance)
        ranges = np.where(mask, distance, np.inf)
        points = self.p_world_camera + self.ray_directions() * np.where(mask, distance, np.nan)[..., None]
        return points, ranges, mask

    def features(self, distance: np.ndarray, p_world_hand: np.ndarray | None = None) -> Features:
        """Features of the object hit at ``distance`` [m]; the hand is 1 m ahead of the camera by default."""
        points, ranges, mask = self.snapshot(distance)
        hand = self.p_world_camera + self.R_world_camera[:, 2] if p_world_hand is None else p_world_hand
        return compute_features(points, ranges, mask, self.p_world_camera, hand, self.project(hand))


def look_at(
    p_world_camera: tuple[float, float, float],
    p_world_target: tuple[float, float, float],
    up: tuple[float, float, float] = (0.0, 0.0, 1.0),
    size: int = 128,
    focal_px: float = 500.0,
) -> PinholeCamera:
    """Camera at ``p_world_camera`` looking at ``p_world_target``, image up towards ``up``."""
    p_cam = np.asarray(p_world_camera, float)
    forward = np.asarray(p_world_target, float) - p_cam
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)
    return PinholeCamera(size, size, focal_px, p_cam, np.stack([right, down, forward], axis=1))


def ray_rectangle(
    camera: PinholeCamera,
    p_world_centre: np.ndarray,
    axis_1: np.ndarray,
    axis_2: np.ndarray,
    half_1: float,
    half_2: float,
) -> np.ndarray:
    """Hit distance [m] of each ray with a rectangle (unit axes, half sizes [m]); inf on a miss."""
    d = camera.ray_directions()
    normal = np.cross(axis_1, axis_2)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = ((p_world_centre - camera.p_world_camera) @ normal) / (d @ normal)
    p_local = camera.p_world_camera + d * t[..., None] - p_world_centre
    hit = (t > 0) & (np.abs(p_local @ axis_1) <= half_1) & (np.abs(p_local @ axis_2) <= half_2)
    return np.where(hit, t, np.inf)


def ray_sphere(camera: PinholeCamera, p_world_centre: np.ndarray, radius: float) -> np.ndarray:
    """Hit distance [m] of each ray with a sphere; inf on a miss."""
    d = camera.ray_directions()
    oc = p_world_centre - camera.p_world_camera
    b = d @ oc
    disc = b**2 - (oc @ oc - radius**2)
    hit = disc >= 0
    return np.where(hit, b - np.sqrt(np.where(hit, disc, 0.0)), np.inf)


def ray_box(
    camera: PinholeCamera, p_world_centre: np.ndarray, R_world_box: np.ndarray, half_extents: np.ndarray
) -> np.ndarray:
    """Hit distance [m] of each ray with an oriented box (slab method); inf on a miss."""
    d_box = camera.ray_directions() @ R_world_box
    o_box = R_world_box.T @ (camera.p_world_camera - p_world_centre)
    with np.errstate(divide="ignore", invalid="ignore"):
        t_1 = (-half_extents - o_box) / d_box
        t_2 = (half_extents - o_box) / d_box
    t_near = np.nanmax(np.minimum(t_1, t_2), axis=-1)
    t_far = np.nanmin(np.maximum(t_1, t_2), axis=-1)
    hit = (t_near <= t_far) & (t_near > 0)
    return np.where(hit, t_near, np.inf)


def rot_z(angle: float) -> np.ndarray:
    """Rotation about world z by ``angle`` [rad]."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def true_normal_histograms(points: np.ndarray, mask: np.ndarray, p_world_centre: np.ndarray) -> np.ndarray:
    """Latitude and longitude histograms of a sphere's exact outward normals at the object pixels.

    Binned as documented: edges shifted down by the edge tolerance, near-vertical normals at longitude 0.
    """
    n = points[mask] - p_world_centre
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    lat_deg = np.degrees(np.arcsin(n[:, 2]) + EDGE_TOLERANCE_RAD)
    lon_deg = np.degrees(np.arctan2(n[:, 1], n[:, 0]) + EDGE_TOLERANCE_RAD)
    lon_deg[np.hypot(n[:, 0], n[:, 1]) < math.sin(VERTICAL_TOLERANCE_RAD)] = np.degrees(EDGE_TOLERANCE_RAD)
    lat_bin = np.clip(np.floor((lat_deg + 90.0) / 15.0), 0, 11).astype(int)
    lon_bin = np.floor((lon_deg + 180.0) / 30.0).astype(int) % 12
    return np.concatenate([np.bincount(lat_bin, minlength=12), np.bincount(lon_bin, minlength=12)]) / len(n)


def assert_valid(features: Features) -> None:
    """49 finite float32 values."""
    assert features.values.shape == (N_FEATURES,)
    assert features.values.dtype == np.float32
    assert np.all(np.isfinite(features.values)), dict(zip(FEATURE_NAMES, features.values, strict=True))


# ----------------------------------------------------------------------------------------------------
# The feature table
# ----------------------------------------------------------------------------------------------------
def test_feature_table_names_groups_units_descriptions() -> None:
    assert N_FEATURES == 49
    assert len(FEATURE_NAMES) == 49 and len(set(FEATURE_NAMES)) == 49
    assert all(re.fullmatch(r"[a-z][a-z0-9]*(_[a-z0-9]+)*", name) for name in FEATURE_NAMES)
    groups = [FEATURE_GROUPS[name] for name in FEATURE_NAMES]
    assert groups == ["shape"] * 24 + ["size"] * 18 + ["relation"] * 7
    assert set(FEATURE_GROUPS) == set(FEATURE_UNITS) == set(FEATURE_DESCRIPTIONS) == set(FEATURE_NAMES)
    assert all(FEATURE_UNITS[name] and FEATURE_DESCRIPTIONS[name] for name in FEATURE_NAMES)
    assert all("\n" not in FEATURE_DESCRIPTIONS[name] for name in FEATURE_NAMES)
    assert {FEATURE_UNITS[name] for name in FEATURE_NAMES[:24]} == {"fraction"}
    assert FEATURE_NAMES[:2] == ("normal_lat_00", "normal_lat_01") and FEATURE_NAMES[12] == "normal_lon_00"
    assert FEATURE_NAMES[24:30] == ("mean_x", "mean_y", "mean_z", "mean_range", "pixel_count", "orientation")
    assert FEATURE_NAMES[-7:] == (
        "hand_image_dx",
        "hand_image_dy",
        "hand_image_distance",
        "hand_dx",
        "hand_dy",
        "hand_dz",
        "hand_distance",
    )
    assert NOT_VISIBLE_VALUES.shape == (49,) and NOT_VISIBLE_VALUES.dtype == np.float32
    assert np.all(np.isfinite(NOT_VISIBLE_VALUES)) and not NOT_VISIBLE_VALUES.flags.writeable


# ----------------------------------------------------------------------------------------------------
# Size features
# ----------------------------------------------------------------------------------------------------
def test_mean_range_of_a_plane_seen_head_on() -> None:
    distance_m = 0.6
    camera = look_at((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    y_axis, z_axis = np.array([0.0, 1, 0]), np.array([0.0, 0, 1])
    t = ray_rectangle(camera, np.array([distance_m, 0, 0]), y_axis, z_axis, 1.0, 1.0)
    points, ranges, mask = camera.snapshot(t)
    v, u = np.mgrid[0:128, 0:128]
    rho_px = np.hypot(u - 63.5, v - 63.5)
    mask &= rho_px <= 20.0  # a disc of the plane about the optical axis
    hand = np.array([0.2, 0.0, 0.0])
    f = compute_features(points, ranges, mask, camera.p_world_camera, hand, camera.project(hand)).values
    assert abs(f[INDEX["mean_range"]] - distance_m) < 1e-3
    exact_mean_range = np.mean(distance_m * np.sqrt(1.0 + (rho_px[mask] / camera.focal_px) ** 2))
    assert f[INDEX["mean_range"]] == pytest.approx(exact_mean_range, abs=1e-6)
    assert f[INDEX["mean_x"]] == pytest.approx(distance_m, abs=1e-6)
    assert f[INDEX["mean_y"]] == pytest.approx(0.0, abs=1e-6)
    assert f[INDEX["mean_z"]] == pytest.approx(0.0, abs=1e-6)
    assert f[INDEX["pixel_count"]] == mask.sum()


@pytest.mark.parametrize(("distance_m", "radius_m", "focal_px"), [(1.0, 0.08, 300.0), (0.4, 0.1, 120.0)])
def test_sphere_pixel_count_is_its_projection(distance_m: float, radius_m: float, focal_px: float) -> None:
    camera = look_at((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), focal_px=focal_px)
    features = camera.features(ray_sphere(camera, np.array([distance_m, 0, 0]), radius_m))
    radius_px = focal_px * radius_m / math.sqrt(distance_m**2 - radius_m**2)
    assert features.values[INDEX["pixel_count"]] == pytest.approx(math.pi * radius_px**2, rel=0.05)
    assert features.n_pixels == features.values[INDEX["pixel_count"]] and features.visible
    # A disc: A-B and C-D are diameters, whatever the (isotropic) orientation.
    assert features.values[INDEX["ab_image_distance"]] == pytest.approx(2 * radius_px, abs=2.0)
    assert features.values[INDEX["cd_image_distance"]] == pytest.approx(2 * radius_px, abs=2.0)


def rectangle_features(angle_rad: float, length_m: float = 0.08, width_m: float = 0.04) -> Features:
    """A fronto-parallel rectangle 0.5 m ahead of the camera, its long side at ``angle_rad`` in the image."""
    camera = look_at((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))  # 1 pixel = 1 mm at 0.5 m
    right, down = camera.R_world_camera[:, 0], camera.R_world_camera[:, 1]
    axis_1 = math.cos(angle_rad) * right + math.sin(angle_rad) * down
    axis_2 = -math.sin(angle_rad) * right + math.cos(angle_rad) * down
    t = ray_rectangle(camera, np.array([0.5, 0, 0]), axis_1, axis_2, length_m / 2, width_m / 2)
    return camera.features(t)


@pytest.mark.parametrize("angle_deg", [0.0, 20.0, 45.0, -30.0, 70.0, -80.0, 90.0])
def test_box_face_extent_and_orientation(angle_deg: float) -> None:
    angle = math.radians(angle_deg)
    f = rectangle_features(angle).values
    assert_valid(Features(f.copy(), True, 1))
    assert f[INDEX["ab_distance"]] == pytest.approx(0.08, abs=5e-3)
    assert f[INDEX["cd_distance"]] == pytest.approx(0.04, abs=5e-3)
    assert f[INDEX["ab_dx"]] == pytest.approx(0.0, abs=1e-9)  # the face is the plane x = 0.5
    assert f[INDEX["ab_dy"]] == pytest.approx(0.08 * abs(math.cos(angle)), abs=5e-3)
    assert f[INDEX["ab_dz"]] == pytest.approx(0.08 * abs(math.sin(angle)), abs=5e-3)
    assert f[INDEX["ab_image_distance"]] == pytest.approx(80.0, abs=5.0)
    assert f[INDEX["cd_image_distance"]] == pytest.approx(40.0, abs=5.0)
    orientation = f[INDEX["orientation"]]
    assert -math.pi / 2 < orientation <= math.pi / 2
    wrapped_error = (orientation - angle + math.pi / 2) % math.pi - math.pi / 2
    assert abs(wrapped_error) < math.radians(2.0)


def test_orientation_of_a_vertical_principal_axis_is_plus_half_pi() -> None:
    for angle in (math.pi / 2, -math.pi / 2):
        orientation = rectangle_features(angle).values[INDEX["orientation"]]
        assert orientation == pytest.approx(math.pi / 2, abs=1e-6)


def test_orientation_of_mirror_symmetric_tall_shapes_is_plus_half_pi() -> None:
    # A shape symmetric about a vertical image axis has a vertical principal axis; rounding makes its pixel
    # covariance slightly negative or positive, so the angle comes out as -pi/2 or +pi/2: always +pi/2 reported.
    points, ranges, empty = plane_snapshot(24, 24)
    rng = np.random.default_rng(0)
    for _ in range(60):
        mask = empty.copy()
        half = rng.random((20, 5)) < 0.6
        half[:, -1] = True  # connected across the axis, and taller than wide
        mask[2:22, 5:10] = half
        mask[2:22, 14:9:-1] = half  # the mirror image about column 9.5
        assert call(points, ranges, mask).values[INDEX["orientation"]] == pytest.approx(math.pi / 2, abs=1e-9)


def test_orientation_effect_of_a_small_turn_across_the_wrap_is_small() -> None:
    # A rectangle near vertical in the image turns by 2 degrees across +-pi/2: its orientation feature jumps
    # from about +pi/2 to about -pi/2, but the effect is the 2-degree turn.
    before = rectangle_features(math.radians(89.0)).values
    after = rectangle_features(math.radians(91.0)).values
    k = INDEX["orientation"]
    assert before[k] > 1.5 and after[k] < -1.5  # the raw features sit on both sides of the wrap
    effect = effect_features(before, after)
    assert effect[k] == pytest.approx(math.radians(2.0), abs=math.radians(1.0))
    back = effect_features(after, before)
    assert back[k] == pytest.approx(-math.radians(2.0), abs=math.radians(1.0))
    others = np.arange(len(before)) != k
    np.testing.assert_allclose(effect[others], (after - before)[others], rtol=1e-6, atol=1e-6)
    for turn in np.linspace(-3 * math.pi, 3 * math.pi, 37):
        assert -math.pi / 2 < wrap_axis_angle(turn) <= math.pi / 2
        assert math.cos(2 * float(wrap_axis_angle(turn))) == pytest.approx(math.cos(2 * turn), abs=1e-9)
    with pytest.raises(ValueError, match="feature arrays"):
        effect_features(before, after[:10])


def test_ray_distance_of_a_receding_face() -> None:
    camera = look_at((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    right, down, forward = camera.R_world_camera.T
    tilt = math.radians(40.0)
    axis_1 = math.cos(tilt) * right + math.sin(tilt) * forward  # the long side recedes from the camera
    centre = np.array([0.5, 0.0, 0.0])
    f = camera.features(ray_rectangle(camera, centre, axis_1, down, 0.05, 0.01)).values
    p_near, p_far = centre - 0.05 * axis_1, centre + 0.05 * axis_1
    true_range_diff = np.linalg.norm(p_far) - np.linalg.norm(p_near)
    assert f[INDEX["ab_range_diff"]] == pytest.approx(true_range_diff, abs=5e-3)
    assert f[INDEX["ab_distance"]] == pytest.approx(0.1, abs=5e-3)
    assert f[INDEX["ab_dx"]] == pytest.approx(0.1 * math.sin(tilt), abs=5e-3)
    assert f[INDEX["cd_range_diff"]] == pytest.approx(0.0, abs=1e-3)


# ----------------------------------------------------------------------------------------------------
# Shape features
# ----------------------------------------------------------------------------------------------------
def test_sphere_normals_spread_over_latitude_and_match_the_true_normals() -> None:
    camera = look_at((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), focal_px=300.0)
    centre = np.array([1.0, 0.0, 0.0])
    t = ray_sphere(camera, centre, 0.08)
    features = camera.features(t)
    lat, lon = features.values[LAT], features.values[LON]
    assert np.count_nonzero(lat) >= 5
    assert lat.sum() == pytest.approx(1.0, abs=1e-5) and lon.sum() == pytest.approx(1.0, abs=1e-5)
    # The camera looks along +x: the visible normals point towards -x, longitude beyond +-90 degrees.
    assert lon[3:9].sum() == pytest.approx(0.0, abs=0.01)
    points, _, mask = camera.snapshot(t)
    assert np.abs(features.values[SHAPE] - true_normal_histograms(points, mask, centre)).max() < 0.02


@pytest.mark.parametrize("tilt_rad", [0.0, 1e-6, 4e-4, 5e-3])
def test_box_face_seen_head_on_fills_one_bin(tilt_rad: float) -> None:
    camera = look_at((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    # Normal -x, turned by tilt_rad down and towards +y, as after rounding or settling on a table: latitude 0
    # and longitude pi lie on bin edges, and a normal just below an edge counts in the bin above it.
    c, s = math.cos(tilt_rad), math.sin(tilt_rad)
    R_world_box = np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]]) @ rot_z(-tilt_rad)
    t = ray_box(camera, np.array([0.6, 0.0, 0.0]), R_world_box, np.array([0.05, 0.04, 0.03]))
    f = camera.features(t).values
    assert f[INDEX["normal_lat_06"]] >= 0.95
    assert f[INDEX["normal_lon_00"]] >= 0.95


@pytest.mark.parametrize("tilt_rad", [0.0, 4e-4, 5e-3])
def test_top_face_seen_from_above_and_plane_seen_from_below(tilt_rad: float) -> None:
    above = look_at((0.6, 0.0, 0.6), (0.6, 0.0, 0.0), up=(1.0, 0.0, 0.0))
    c, s = math.cos(tilt_rad), math.sin(tilt_rad)
    R_world_box = rot_z(1.0) @ np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]) @ rot_z(0.3)
    f = above.features(ray_box(above, np.array([0.6, 0.0, 0.0]), R_world_box, np.array([0.05, 0.04, 0.03])))
    assert f.values[INDEX["normal_lat_11"]] >= 0.95
    assert f.values[INDEX["normal_lon_06"]] >= 0.95  # a (nearly) vertical normal counts as longitude 0
    below = look_at((0.6, 0.0, -0.6), (0.6, 0.0, 0.0), up=(1.0, 0.0, 0.0))
    x_axis, y_axis = np.array([1.0, 0, 0]), np.array([0.0, 1, 0])
    f = below.features(ray_rectangle(below, np.array([0.6, 0.0, 0.0]), x_axis, y_axis, 0.05, 0.05))
    assert f.values[INDEX["normal_lat_00"]] == pytest.approx(1.0)  # normals face the camera: down


def test_face_along_world_y_falls_in_the_bin_above_the_edge() -> None:
    camera = look_at((0.0, -0.6, 0.0), (0.0, 0.0, 0.0))  # looks along +y at a face whose normal is -y
    f = camera.features(ray_box(camera, np.zeros(3), np.eye(3), np.array([0.05, 0.05, 0.05]))).values
    assert f[INDEX["normal_lon_03"]] == pytest.approx(1.0)  # longitude -90 degrees: edge of bins 2 and 3
    assert f[INDEX["normal_lat_06"]] == pytest.approx(1.0)


def test_sphere_and_box_differ_in_shape() -> None:
    camera = look_at((0.0, 0.0, 0.4), (0.6, 0.0, 0.0), focal_px=200.0)
    centre = np.array([0.6, 0.0, 0.0])
    sphere = camera.features(ray_sphere(camera, centre, 0.05)).values[SHAPE]
    box = camera.features(ray_box(camera, centre, rot_z(0.5), np.full(3, 0.05))).values[SHAPE]
    assert np.abs(sphere - box).sum() > 0.5
    assert np.count_nonzero(box[:12] > 0.02) <= 3  # two visible faces: at most a few latitude bins


# ----------------------------------------------------------------------------------------------------
# Relation features
# ----------------------------------------------------------------------------------------------------
def test_hand_object_distances() -> None:
    camera = look_at((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    centre = np.array([0.5, 0.0, 0.0])
    t = ray_rectangle(camera, centre, np.array([0.0, 1, 0]), np.array([0.0, 0, 1]), 0.03, 0.03)
    p_world_hand = np.array([0.3, 0.12, -0.07])
    f = camera.features(t, p_world_hand).values
    true_difference = centre - p_world_hand
    assert f[INDEX["hand_distance"]] == pytest.approx(np.linalg.norm(true_difference), abs=1e-3)
    for i, name in enumerate(("hand_dx", "hand_dy", "hand_dz")):
        assert f[INDEX[name]] == pytest.approx(true_difference[i], abs=1e-3)
    uv_difference = camera.project(centre) - camera.project(p_world_hand)
    assert f[INDEX["hand_image_dx"]] == pytest.approx(uv_difference[0], abs=0.5)
    assert f[INDEX["hand_image_dy"]] == pytest.approx(uv_difference[1], abs=0.5)
    assert f[INDEX["hand_image_distance"]] == pytest.approx(np.hypot(*uv_difference), abs=0.5)


# ----------------------------------------------------------------------------------------------------
# Degenerate and invalid inputs
# ----------------------------------------------------------------------------------------------------
def plane_snapshot(height: int = 16, width: int = 20) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points and ranges of a plane filling a small image, with an empty mask."""
    camera = PinholeCamera(width, height, 50.0, np.zeros(3), look_at((0, 0, 0), (1, 0, 0)).R_world_camera)
    points, ranges, _ = camera.snapshot(
        ray_rectangle(camera, np.array([0.5, 0, 0]), np.array([0.0, 1, 0]), np.array([0.0, 0, 1]), 9, 9)
    )
    return points, ranges, np.zeros((height, width), dtype=bool)


def call(points: np.ndarray, ranges: np.ndarray, mask: np.ndarray, **overrides: np.ndarray) -> Features:
    """compute_features with a default camera, hand and hand projection."""
    args = {
        "p_world_camera": np.zeros(3),
        "p_world_hand": np.array([0.3, 0.1, 0.0]),
        "uv_hand": np.array([2.0, 3.0]),
    } | overrides
    return compute_features(points, ranges, mask, **args)


@pytest.mark.filterwarnings("error")
def test_empty_mask_gives_the_not_visible_values() -> None:
    points, ranges, mask = plane_snapshot()
    points[:] = np.nan
    ranges[:] = np.inf
    features = call(points, ranges, mask)
    assert not features.visible and features.n_pixels == 0
    np.testing.assert_array_equal(features.values, NOT_VISIBLE_VALUES)
    assert features.values.dtype == np.float32


@pytest.mark.filterwarnings("error")
def test_one_pixel_and_lines_of_pixels_are_finite() -> None:
    points, ranges, empty = plane_snapshot()
    one = empty.copy()
    one[3, 4] = True
    f = call(points, ranges, one)
    assert_valid(f)
    assert f.visible and f.n_pixels == 1 and f.values[INDEX["pixel_count"]] == 1
    assert f.values[INDEX["orientation"]] == 0.0 and f.values[INDEX["ab_distance"]] == 0.0
    assert not f.values[SHAPE].any()  # no neighbours, no normal
    assert f.values[INDEX["hand_image_dx"]] == 4 - 2.0 and f.values[INDEX["hand_image_dy"]] == 3 - 3.0

    row, column, diagonal = empty.copy(), empty.copy(), empty.copy()
    row[5, 2:12] = True
    column[2:12, 7] = True
    diagonal[np.arange(10), np.arange(10)] = True
    for line, orientation, length_px in (
        (row, 0.0, 9.0),
        (column, math.pi / 2, 9.0),
        (diagonal, math.pi / 4, 9.0 * math.sqrt(2)),
        (diagonal[:, ::-1], -math.pi / 4, 9.0 * math.sqrt(2)),
    ):
        f = call(points, ranges, line)
        assert_valid(f)
        assert f.values[INDEX["orientation"]] == pytest.approx(orientation, abs=1e-6)
        assert f.values[INDEX["ab_image_distance"]] == pytest.approx(length_px, abs=1e-4)
        assert not f.values[SHAPE].any()  # collinear pixels: no normal

    block = empty.copy()
    block[4:6, 4:6] = True  # 2 x 2: one-sided differences only, still a normal at every pixel
    f = call(points, ranges, block)
    assert_valid(f)
    assert f.values[LAT].sum() == pytest.approx(1.0)


def test_features_ignore_everything_off_the_mask() -> None:
    camera = look_at((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), focal_px=120.0)
    points, ranges, mask = camera.snapshot(ray_sphere(camera, np.array([0.5, 0.0, 0.0]), 0.1))
    hand = np.array([0.3, 0.1, 0.0])
    reference = call(points, ranges, mask, p_world_hand=hand).values
    rng = np.random.default_rng(0)
    garbage_points = rng.choice(np.array([np.nan, np.inf, -np.inf, 1e300, 0.0]), size=points.shape)
    garbage_ranges = rng.choice(np.array([np.nan, np.inf, -1.0, 0.0]), size=ranges.shape)
    points = np.where(mask[..., None], points, garbage_points)
    ranges = np.where(mask, ranges, garbage_ranges)
    np.testing.assert_array_equal(call(points, ranges, mask, p_world_hand=hand).values, reference)


@st.composite
def snapshots(draw: st.DrawFn) -> tuple[np.ndarray, ...]:
    """Small grids: random, flat or identical points; random, full or empty masks; junk off the mask."""
    height, width = draw(st.integers(1, 9)), draw(st.integers(1, 9))
    dtype = draw(st.sampled_from([np.float32, np.float64]))
    coordinate = st.floats(-50.0, 50.0, width=32)
    layout = draw(st.sampled_from(["random", "flat", "identical"]))
    if layout == "random":
        points = draw(hnp.arrays(np.float64, (height, width, 3), elements=coordinate))
    else:
        v, u = np.mgrid[0:height, 0:width].astype(float)
        points = np.stack([u, v, np.zeros_like(u)], axis=-1) * (layout == "flat")
    mask_kind = draw(st.sampled_from(["random", "all", "none"]))
    if mask_kind == "random":
        mask = draw(hnp.arrays(np.bool_, (height, width)))
    else:
        mask = np.full((height, width), mask_kind == "all")
    ranges = draw(hnp.arrays(np.float64, (height, width), elements=st.floats(0.0, 100.0)))
    off_mask = draw(st.sampled_from([np.nan, np.inf, -np.inf, 0.0]))
    points = np.where(mask[..., None], points, off_mask).astype(dtype)
    ranges = np.where(mask, ranges, off_mask).astype(dtype)
    camera = draw(hnp.arrays(np.float64, 3, elements=coordinate))
    hand = draw(hnp.arrays(np.float64, 3, elements=coordinate))
    uv_hand = draw(hnp.arrays(np.float64, 2, elements=st.floats(-1e6, 1e6)))
    return points, ranges, mask, camera, hand, uv_hand


@pytest.mark.filterwarnings("error")
@settings(max_examples=300, deadline=None)
@given(snapshots())
def test_any_valid_snapshot_gives_49_finite_float32_values(snapshot: tuple[np.ndarray, ...]) -> None:
    points, ranges, mask, camera, hand, uv_hand = snapshot
    features = compute_features(points, ranges, mask, camera, hand, uv_hand)
    assert_valid(features)
    assert features.visible == bool(mask.any()) and features.n_pixels == int(mask.sum())
    for histogram in (features.values[LAT], features.values[LON]):
        assert np.all(histogram >= 0) and histogram.sum() in (0, pytest.approx(1.0, abs=1e-5))
    assert -math.pi / 2 < features.values[INDEX["orientation"]] <= math.pi / 2 or not features.visible


def bad_inputs() -> list[tuple[str, dict[str, np.ndarray]]]:
    """(argument named in the error, keyword arguments of compute_features) pairs."""
    points, ranges, mask = plane_snapshot(6, 5)
    mask[2:4, 1:3] = True
    good = {
        "p_world_points": points,
        "ranges": ranges,
        "mask": mask,
        "p_world_camera": np.zeros(3),
        "p_world_hand": np.array([0.3, 0.1, 0.0]),
        "uv_hand": np.array([2.0, 3.0]),
    }
    nan_on_mask, negative_range = points.copy(), ranges.copy()
    nan_on_mask[2, 1, 0] = np.nan
    negative_range[3, 2] = -0.1
    cases = [
        ("p_world_points", {"p_world_points": points[..., :2]}),
        ("p_world_points", {"p_world_points": points[..., 0]}),
        ("p_world_points", {"p_world_points": points.astype(complex)}),
        ("p_world_points", {"p_world_points": nan_on_mask}),
        ("ranges", {"ranges": ranges[:-1]}),
        ("ranges", {"ranges": ranges.astype(str)}),
        ("ranges", {"ranges": negative_range}),
        ("mask", {"mask": mask[:, :-1]}),
        ("mask", {"mask": mask.astype(int)}),
        ("p_world_camera", {"p_world_camera": np.array([0.0, np.inf, 0.0])}),
        ("p_world_hand", {"p_world_hand": np.array([np.nan, 0.0, 0.0])}),
        ("p_world_hand", {"p_world_hand": np.zeros(2)}),
        ("uv_hand", {"uv_hand": np.array([np.nan, 1.0])}),
        ("uv_hand", {"uv_hand": np.zeros(3)}),
    ]
    return [(name, good | change) for name, change in cases]


@pytest.mark.parametrize(("argument", "kwargs"), bad_inputs())
def test_bad_inputs_raise_an_error_naming_the_argument(argument: str, kwargs: dict[str, np.ndarray]) -> None:
    with pytest.raises(ValueError, match=rf"^{argument} must") as error:
        compute_features(**kwargs)
    assert "got" in str(error.value)


def test_features_values_are_read_only_and_checked() -> None:
    features = rectangle_features(0.3)
    with pytest.raises(ValueError, match="read-only"):
        features.values[0] = 1.0
    assert features.as_dict()["pixel_count"] == features.n_pixels
    with pytest.raises(ValueError, match="Features.values"):
        Features(np.zeros(48, dtype=np.float32), True, 1)
