"""Metric range camera by MuJoCo ray casting: no OpenGL, so it works headless and in CI.

One ray per pixel through the pixel centre of a pinhole camera attached to a MuJoCo camera element;
``mujoco.mj_multiRay`` returns the distance and the geom hit by each ray, which gives the object mask for free,
as the paper marks object pixels from the simulator.

Image conventions: ``u`` is the column, ``v`` the row, pixel centres at integer indices. MuJoCo cameras look
along their -z axis with +x to the right of the image and +y up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from affordance_env.exceptions import InvalidValueError
from affordance_env.linalg import einsum, matmul
from affordance_env.pinhole import Intrinsics

#: The 8 corners of a box of half-sizes 1.
_CORNERS = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
#: Its 12 edges: pairs of corners that differ in one coordinate.
_EDGES = [(a, b) for a in range(8) for b in range(a + 1, 8) if np.sum(_CORNERS[a] != _CORNERS[b]) == 1]
#: Its corners' signs as Python floats, in the same order.
_CORNER_SIGNS: tuple[tuple[float, float, float], ...] = tuple(tuple(corner) for corner in _CORNERS.tolist())
#: How far in front of the camera a box's image is bounded [m] (:func:`_in_front`).
_NEAR = 1e-3


@dataclass(frozen=True)
class RangeImage:
    """One range snapshot.

    Attributes:
        ranges: Distance along each pixel's ray [m], (H, W) float32; ``inf`` where nothing was hit.
        geom_ids: MuJoCo geom hit by each ray, (H, W) int32; -1 where nothing was hit.
        p_world_points: Point hit by each ray in the world frame [m], (H, W, 3) float64; NaN where no hit. None
            when captured with ``points=False``: :meth:`points_of` then computes the points of the pixels asked for.
        p_world_camera: Camera centre in the world frame [m], (3,).
        R_world_camera: Camera orientation (columns: camera x, y, z axes in the world frame), (3, 3).
        intrinsics: The pinhole intrinsics used.
        normals: Unit surface normal at each hit point in the world frame, (H, W, 3); NaN where no hit. Only
            when captured with ``normals=True`` (the range-noise model needs them), else None.
        rays: With ``points=False``: each pixel's unit ray direction in the world frame as rows x, y, z, (3, H W);
            else None.
        distances: With ``points=False``: the distance along each ray [m] in float64, (H W,) (NaN or anything
            where nothing was hit); else None.
    """

    ranges: np.ndarray
    geom_ids: np.ndarray
    p_world_points: np.ndarray | None
    p_world_camera: np.ndarray
    R_world_camera: np.ndarray
    intrinsics: Intrinsics
    normals: np.ndarray | None = None
    rays: np.ndarray | None = None
    distances: np.ndarray | None = None

    def points_of(self, pixels: np.ndarray) -> np.ndarray:
        """The points hit at ``pixels`` (flat indices ``v * width + u``) [m], world frame, as rows x, y, z, (3, k):
        ``p_world_points`` there, bit for bit (computed as capture computes every pixel's, p + d * distance, when
        the image was captured without its points)."""
        if self.p_world_points is not None:
            return self.p_world_points.reshape(-1, 3).T.take(pixels, axis=1)
        points = self.rays.take(pixels, axis=1)
        points *= self.distances.take(pixels)
        points += self.p_world_camera[:, None]
        return points

    def mask_of(self, geom_id: int) -> np.ndarray:
        """Boolean (H, W) mask of the pixels that see geom ``geom_id``."""
        return self.geom_ids == geom_id

    def project(self, p_world: np.ndarray) -> np.ndarray:
        """Pixel coordinates (u, v) of a world point; may lie outside the image; NaN if behind the camera."""
        return project(p_world, self.p_world_camera, self.R_world_camera, self.intrinsics)


def project(p_world: np.ndarray, p_world_camera: np.ndarray, R_world_camera: np.ndarray, K: Intrinsics) -> np.ndarray:
    """Pinhole projection of a world point [m] to (u, v) pixels (NaN when the point is behind the camera)."""
    p_world = np.asarray(p_world, dtype=float)
    if p_world.shape == (3,):  # one point, as the callers pass it: in Python floats, the same bits (_to_camera)
        x, y, z = _to_camera(*p_world.tolist(), np.asarray(p_world_camera, dtype=float).tolist(),
                             np.asarray(R_world_camera, dtype=float).ravel().tolist())
    else:
        p_camera = matmul(p_world - p_world_camera, R_world_camera)
        x, y, z = p_camera[0], p_camera[1], p_camera[2]
    depth = -z
    if depth <= 1e-9:
        return np.array([np.nan, np.nan])
    return np.array([K.cx + K.fx * x / depth, K.cy - K.fy * y / depth])


def _in_front(corners: np.ndarray, near: float = _NEAR) -> np.ndarray:
    """The points of a box's 8 corners (camera frame, looking along -z) that lie at least ``near`` [m] in front
    of the camera, and the points where the box's edges cross that plane: their projections bound the image of
    the part of the box in front of the camera."""
    depth = -corners[:, 2]
    front = depth >= near
    if front.all():  # the usual case: the whole box is in front
        return corners
    points = [corners[front]]
    for a, b in _EDGES:
        if front[a] != front[b]:
            t = (near - depth[a]) / (depth[b] - depth[a])
            points.append((corners[a] + t * (corners[b] - corners[a]))[None])
    return np.concatenate(points)


# Small products in Python floats. A handful of 3-vectors (a box's 8 corners, a sphere's centre, a point to
# project) cost a dozen array calls each through linalg.matmul, for a few dozen multiplications: this module does
# some of them in Python floats instead, in the same IEEE operations in the same order, so with the same bits
# (tests/test_camera.py holds them to linalg.matmul). That order is einsum's, the loops linalg.matmul runs (numpy's
# baseline build, the same on every x86-64 CPU):
#
# - a point times the camera's rotation, ``matmul(p, R)`` of one point (``"i,ij->j"``) or of a box's 8 corners
#   (``"...ij,jk->...ik"``, (8, 3) by (3, 3)): each output adds its three products one after another,
#   (a0 + a1) + a2;
# - three contiguous products reduced to one number: a rotation's row times a vector (``"gij,gcj->gci"``), a
#   squared length (``"i,i->"`` of linalg.norm), a ray's direction times an axis (``"...ij,j->...i"``): the
#   two-lane loop adds the third product to the first, then the second, (a0 + a2) + a1.
#
# einsum starts every sum from +0, which the ``+ 0.0`` below stands for: it turns a -0 into +0, and changes
# nothing else.


def _to_camera(x: float, y: float, z: float, p_world_camera: list[float],
               R_world_camera: list[float]) -> tuple[float, float, float]:
    """``matmul(p - p_world_camera, R_world_camera)`` of one world point ``p = (x, y, z)`` [m] (the camera's
    position [m], its orientation row-major, 9 floats): the point in the camera frame [m], bit for bit."""
    d0, d1, d2 = x - p_world_camera[0], y - p_world_camera[1], z - p_world_camera[2]
    R = R_world_camera
    return (((d0 * R[0] + d1 * R[3]) + d2 * R[6]) + 0.0, ((d0 * R[1] + d1 * R[4]) + d2 * R[7]) + 0.0,
            ((d0 * R[2] + d1 * R[5]) + d2 * R[8]) + 0.0)


class RangeCamera:
    """Ray-cast range camera on a MuJoCo camera element.

    Args:
        model: The compiled model.
        camera: Name of the MuJoCo camera the sensor is mounted on.
        width: Image width [pixels].
        height: Image height [pixels].
        fovy_deg: Vertical field of view [deg]; defaults to the camera element's ``fovy``.
        max_range: Rays longer than this report no hit [m].
        geom_groups: Geom groups the camera sees (MuJoCo ``geom_group`` values). The default is the world (group
            0: table, floor, object) and the robot's arm from the upper arm down (group 2), which occludes the
            object as on a real camera; not the rest of the robot (group 1), which the camera never sees and
            whose meshes would make each image cost six times as much.
        support: Name of a static, axis-aligned box of group 0 whose upward face most rays end on (the table top),
            or None. The rays that meet that face are intersected with its plane in closed form, a few
            nanoseconds each instead of MuJoCo's generic ray query (150-300 ns per ray in this scene); MuJoCo still
            casts every ray that misses the face, among all of group 0, and every ray that something else of group
            0 (the object) may end first, among the moving bodies alone (the face ends it otherwise): inside the
            image rectangle that bounds that geom's box and the cone of its bounding sphere. The image is the same:
            the same geoms hit and the same float32 ranges; a face pixel's float64 distance (and point) may differ
            from MuJoCo's box distance in its last bit.

    Group 0 is ray cast for every pixel; the geoms of the other groups (the arm's detailed meshes, whose rays
    cost microseconds each) only in a second pass, for the pixels whose rays may meet them (inside the image
    rectangles of their bounding boxes and the cones of their bounding spheres), and whose nearer hits replace the
    first pass's: the same image as one pass over all groups.
    :meth:`capture` can limit that pass further to the pixels that see given geoms (``occluded``): the arm then
    appears only where it hides them, and the rest of the image is the world's.
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        camera: str = "range_camera",
        width: int = 128,
        height: int = 128,
        fovy_deg: float | None = None,
        max_range: float = 5.0,
        geom_groups: tuple[int, ...] = (0, 2),
        support: str | None = None,
    ) -> None:
        camera_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera)
        if camera_id < 0:
            names = [model.camera(i).name for i in range(model.ncam)]
            raise InvalidValueError(f"Camera {camera!r} does not exist in the model. Available cameras: {names}")
        if not max_range > 0:
            raise InvalidValueError(f"max_range must be positive [m], got {max_range!r}.")
        self.model = model
        self.camera_id = camera_id
        fovy = model.cam_fovy[camera_id] if fovy_deg is None else fovy_deg
        self.intrinsics = Intrinsics.from_fovy(width, height, fovy)
        self.max_range = float(max_range)
        if any(g not in range(6) for g in geom_groups):
            raise InvalidValueError(f"geom_groups must be within 0..5, got {geom_groups!r}.")
        self._world_group = np.array([g == 0 and g in geom_groups for g in range(6)], dtype=np.uint8)
        self._bounded_group = np.array([g != 0 and g in geom_groups for g in range(6)], dtype=np.uint8)
        #: Geoms of the bounded pass (read once: set_object changes only the object's geoms, in group 0 or 3).
        self._bounded_geoms = np.flatnonzero(self._bounded_group[np.clip(model.geom_group, 0, 5)]
                                             & (model.geom_group >= 0) & (model.geom_group <= 5))
        #: Whether the camera sees group 0 (the world pass casts it).
        self._sees_world = bool(self._world_group.any())
        self._support = None if support is None or not self._sees_world else self._support_face(support)
        self._d_camera_rays = self.intrinsics.ray_directions().reshape(-1, 3)
        # The rays as three rows (x, y, z): rotating them is one small matrix product, and each coordinate is a
        # contiguous row for the per-ray arithmetic below.
        self._d_camera_rays_T = np.ascontiguousarray(self._d_camera_rays.T)
        #: The same as three (H, W) planes in the order x, z, y, in which a ray's cosine to an axis adds its products
        #: (:meth:`_mark_near`).
        self._d_camera_xzy = np.ascontiguousarray(self._d_camera_rays_T.reshape(3, height, width)[[0, 2, 1]])
        self._not_plane = model.geom_type != int(mujoco.mjtGeom.mjGEOM_PLANE)  # geom types never change
        #: Pixels of an image [rays].
        self._n_rays = width * height
        # Scratch for the support face's per-ray test (a ray coordinate [m], one comparison), made once and
        # reused by every capture (as the image buffers were before: one capture at a time per camera).
        self._scratch = np.empty(self._n_rays)
        self._scratch_test = np.empty(self._n_rays, dtype=bool)
        #: The geoms of group 0 other than the support face and the planes, for the geom groups they were read from
        #: (``set_object`` moves the object's geoms between group 0 and a hidden one): ``(groups, geoms, whether they
        #: are exactly the geoms of group 0 on moving bodies)``.
        self._others: tuple[bytes, np.ndarray, bool] | None = None

    def _support_face(self, name: str) -> tuple[int, float, np.ndarray, np.ndarray]:
        """(geom id, height, lower and upper x-y corners) of the upward face of the box ``name``."""
        model = self.model
        geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
        if geom < 0:
            raise InvalidValueError(f"support: the model has no geom named {name!r}.")
        data = mujoco.MjData(model)
        mujoco.mj_kinematics(model, data)
        R = data.geom_xmat[geom].reshape(3, 3)
        if (model.geom_type[geom] != mujoco.mjtGeom.mjGEOM_BOX or model.geom_group[geom] != 0
                or model.body_weldid[model.geom_bodyid[geom]] != 0 or not np.allclose(R, np.eye(3), atol=1e-12)):
            raise InvalidValueError(
                f"support: geom {name!r} must be a box of group 0, fixed to the world and aligned with "
                             "its axes.")
        centre, half = data.geom_xpos[geom], model.geom_size[geom]
        top = float(centre[2] + half[2])
        planes = np.flatnonzero((model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE) & (model.geom_group == 0))
        for plane in planes:  # a plane of the world may never end a ray before the face does
            if data.geom_xpos[plane, 2] >= top or not np.allclose(data.geom_xmat[plane, 8], 1.0):
                raise InvalidValueError(
                    f"support: the plane {model.geom(plane).name!r} is not below the face of {name!r}.")
        return int(geom), top, centre[:2] - half[:2], centre[:2] + half[:2]

    def _cast(self, data: mujoco.MjData, p_world_camera: np.ndarray, d_world: np.ndarray, rays: np.ndarray,
              group: np.ndarray, normal: np.ndarray | None, static: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """MuJoCo's nearest hit (geom ids, distances [m]; normals written into ``normal``, (3 * rays.size,)) of
        the rays ``rays`` (flat pixel indices; ``d_world``: the unit ray directions as rows x, y, z, (3, n)) among
        the geoms of ``group``; ``static=False``: only those of bodies that are not fixed to the world."""
        ids, dist = np.empty(rays.size, np.int32), np.empty(rays.size)
        # The rays' directions gathered as (rays.size, 3) rows, the layout mj_multiRay reads (a copy either way).
        directions = d_world.take(rays, axis=1).T.copy()
        mujoco.mj_multiRay(self.model, data, p_world_camera, directions.reshape(-1), group, static, -1, ids, dist,
                           normal, rays.size, self.max_range)
        return ids, dist

    def _world_others(self, support: int) -> tuple[np.ndarray, bool]:
        """The geoms of group 0 that may end a ray before the support face ``support``: all but that box and the
        planes (which lie below it), and whether none of them is fixed to the world (a cast among the bodies that
        are not, ``static=False``, then meets exactly them). Recomputed only when the geom groups changed since
        the last call."""
        groups = self.model.geom_group
        key = groups.tobytes()  # 4 bytes per geom: cheaper to compare than the geoms are to find again
        if self._others is None or self._others[0] != key:
            world = np.flatnonzero(groups == 0)
            others = np.flatnonzero((groups == 0) & self._not_plane)
            others = others[others != support]
            model = self.model
            moving = world[model.body_weldid[model.geom_bodyid[world]] != 0]
            self._others = key, others, np.array_equal(moving, others)
        return self._others[1], self._others[2]

    def _world_pass(self, data: mujoco.MjData, p_world_camera: np.ndarray, R_world_camera: np.ndarray,
                    d_world: np.ndarray, normal: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, bool]:
        """Nearest hit of every ray among the geoms of group 0: ``(geom ids (n,) int32, distances [m] (n,),
        whether some ray hit nothing)``, fresh arrays; normals into ``normal`` ((n, 3)) if not None (``d_world``:
        the unit ray directions as rows x, y, z, (3, n)). A distance is meaningless where the geom id is -1."""
        n = self._n_rays
        if self._support is None:
            geom_ids, dist = np.empty(n, np.int32), np.empty(n)
            mujoco.mj_multiRay(
                self.model, data, p_world_camera, np.ascontiguousarray(d_world.T).reshape(-1), self._world_group,
                True, -1, geom_ids, dist, None if normal is None else normal.reshape(-1), n, self.max_range,
            )
            return geom_ids, dist, bool(np.logical_or.reduce(geom_ids < 0))
        geom, top, low, high = self._support
        if p_world_camera[2] > top:
            # Where each ray meets the face's plane: its distance t [m] and its x, y [m]; the face's rays are those
            # with 0 < t <= max_range and x, y within the face. The tests are the same comparisons of the same
            # floats as ``(t > 0) & (t <= max_range) & (x >= low_x) & ...``, folded into one boolean array with
            # scratch buffers instead of nine temporaries.
            x, test = self._scratch, self._scratch_test
            with np.errstate(divide="ignore", invalid="ignore"):  # a ray parallel to the face: t = +-inf, x NaN
                t = (top - p_world_camera[2]) / d_world[2]
                on_face = t > 0
                np.less_equal(t, self.max_range, out=test)
                on_face &= test
                for axis in (0, 1):
                    np.multiply(t, d_world[axis], out=x)
                    x += p_world_camera[axis]  # p + t d, as t d + p: the same sum
                    np.greater_equal(x, low[axis], out=test)
                    on_face &= test
                    np.less_equal(x, high[axis], out=test)
                    on_face &= test
            # Every ray ends on the face at t, except those cast below, which overwrite their pixels: so the ids
            # and distances start as the face's everywhere (no masked writes), and t is the distances' array.
            geom_ids, dist = np.full(n, geom, np.int32), t
            if normal is not None:
                normal[:] = (0.0, 0.0, 1.0)
            face = on_face
            cast = np.logical_not(on_face)  # the rays that miss the face ...
        else:  # the camera below the face never sees its top: every ray is cast
            geom_ids, dist = np.empty(n, np.int32), np.empty(n)
            face, cast = None, np.ones(n, dtype=bool)
        # ... and the face's rays that may meet the other geoms of group 0 (the object), which may end them first.
        others, moving = self._world_others(geom)
        K = self.intrinsics
        face_rays = None
        if others.size and face is not None and moving:
            # The face's rays near the object are cast among the moving bodies alone (those geoms, see
            # _world_others): the face ends them at t, and MuJoCo's nearest hit among the floor (below the face),
            # the table (t) and the others is the others' where it is nearer than t, or as near and of a lower id.
            near = np.zeros((K.height, K.width), dtype=bool)
            self._mark_near(others, data, p_world_camera, R_world_camera, near)
            face_rays = np.logical_and(near.ravel(), face, out=face).nonzero()[0]  # the near rays off it are cast
        elif others.size:
            self._mark_near(others, data, p_world_camera, R_world_camera, cast.reshape(K.height, K.width))
        if face_rays is not None and face_rays.size:
            face_normal = None if normal is None else np.empty(3 * face_rays.size)
            ids, ray_dist = self._cast(data, p_world_camera, d_world, face_rays, self._world_group, face_normal,
                                       static=False)
            on_face_dist = dist[face_rays]
            nearer = (ids >= 0) & ((ray_dist < on_face_dist) | ((ray_dist == on_face_dist) & (ids < geom)))
            hit = face_rays[nearer]
            geom_ids[hit], dist[hit] = ids[nearer], ray_dist[nearer]
            if normal is not None:
                normal[hit] = face_normal.reshape(-1, 3)[nearer]
        rays = cast.nonzero()[0]
        if not rays.size:
            return geom_ids, dist, False
        ray_normal = None if normal is None else np.empty(3 * rays.size)
        ids, ray_dist = self._cast(data, p_world_camera, d_world, rays, self._world_group, ray_normal)
        geom_ids[rays], dist[rays] = ids, ray_dist
        if normal is not None:
            normal[rays] = ray_normal.reshape(-1, 3)
        # only a cast ray can miss (the face's rays end on it): whether one did, from the cast rays alone
        return geom_ids, dist, bool(np.logical_or.reduce(ids < 0))

    def pose(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        """``(p_world_camera, R_world_camera)`` from the current kinematics (``mj_kinematics`` must be current)."""
        return data.cam_xpos[self.camera_id].copy(), data.cam_xmat[self.camera_id].reshape(3, 3).copy()

    def _may_hide(self, geoms: np.ndarray, targets: np.ndarray, data: mujoco.MjData,
                  p_world_camera: np.ndarray) -> np.ndarray:
        """Which of ``geoms`` may hide some of ``targets`` from the camera: those whose bounding sphere meets the
        cone of rays through a target's bounding sphere (a cheap, conservative test)."""
        # The cones of the geoms and of the targets in one pass over both (every step is per geom, so each value
        # is what a pass over either alone gives): its cost is in the number of array calls, not their size.
        ids = np.concatenate((geoms, targets))
        offset = data.geom_xpos.take(ids, axis=0) - p_world_camera  # take: geom_xpos[ids], faster
        # np.linalg.norm(offset, axis=1) is this sum of squares and root, here without its Python checks
        distance = np.sqrt(np.add.reduce(offset * offset, axis=1))
        radius = self.model.geom_rbound.take(ids)
        half_angle = np.where(distance > radius, np.arcsin(np.minimum(radius / distance, 1.0)), np.pi)
        direction = offset / distance[:, None]
        g = geoms.size
        between = np.arccos(np.minimum(np.maximum(matmul(direction[:g], direction[g:].T), -1.0), 1.0))  # (g, t)
        return np.logical_or.reduce(between <= half_angle[:g, None] + half_angle[None, g:], axis=1)  # .any(axis=1)

    def _rectangles(self, geoms: np.ndarray, data: mujoco.MjData, p_world_camera: np.ndarray | list[float],
                    R_world_camera: np.ndarray | list[float]) -> list[tuple[int, int, int, int, int]]:
        """Pixel rectangles (geom, column from, to, row from, to; ends excluded) that bound the images of the
        oriented bounding boxes of ``geoms`` (a box's projection lies within that of its 8 corners). The camera's
        pose as arrays (3,), (3, 3), or as the Python floats of :meth:`_box_corners_camera`."""
        K = self.intrinsics
        cx, cy, fx, fy = K.cx, K.cy, K.fx, K.fy
        p_camera_list = p_world_camera if isinstance(p_world_camera, list) else p_world_camera.tolist()
        R_camera_list = R_world_camera if isinstance(R_world_camera, list) else R_world_camera.ravel().tolist()
        rectangles = []
        for geom in geoms.tolist():
            corners = self._box_corners_camera(geom, data, p_camera_list, R_camera_list)
            # The usual case in Python floats: the whole box at least _NEAR in front, and every projection finite
            # (a NaN or inf makes the sum so; a diverged state takes the general path, which refuses it as before).
            u, v = [], []
            for x, y, z in corners:
                depth = -z
                if not depth >= _NEAR:
                    break
                u.append(cx + fx * x / depth)
                v.append(cy - fy * y / depth)
            if len(u) == len(corners) and math.isfinite(sum(u) + sum(v)):
                bounds = (math.floor(min(u)), math.ceil(max(u)), math.floor(min(v)), math.ceil(max(v)))
            else:
                points = _in_front(np.array(corners))  # the box clipped to the part in front of the camera
                if points.shape[0] == 0:
                    continue
                depth = -points[:, 2]
                u_array = K.cx + K.fx * points[:, 0] / depth
                v_array = K.cy - K.fy * points[:, 1] / depth
                bounds = (int(np.floor(u_array.min())), int(np.ceil(u_array.max())), int(np.floor(v_array.min())),
                          int(np.ceil(v_array.max())))
            u0, u1 = max(0, bounds[0]), min(K.width, bounds[1] + 1)
            v0, v1 = max(0, bounds[2]), min(K.height, bounds[3] + 1)
            if u0 < u1 and v0 < v1:
                rectangles.append((geom, u0, u1, v0, v1))
        return rectangles

    def _box_corners_camera(self, geom: int, data: mujoco.MjData, p_world_camera: list[float],
                            R_world_camera: list[float]) -> list[tuple[float, float, float]]:
        """The 8 corners (in :data:`_CORNERS`' order) of the bounding box of ``geom`` (MuJoCo's ``geom_aabb``,
        in the geom's frame) in the camera frame [m], from the camera's position [m] and its orientation
        (row-major, 9 floats).

        Bit for bit ``matmul(geom_xpos + einsum("ij,cj->ci", geom_xmat, aabb_centre + aabb_half * _CORNERS)
        - p_world_camera, R_world_camera)``, in Python floats: a box is 8 points, for which a dozen small array
        calls cost several times the arithmetic (see the note above :func:`_to_camera` for the order of the
        sums; the rotation into the camera frame is :func:`_to_camera`'s, written out).
        """
        c0, c1, c2, h0, h1, h2 = self.model.geom_aabb[geom].tolist()
        r0, r1, r2, r3, r4, r5, r6, r7, r8 = data.geom_xmat[geom].tolist()
        x0, x1, x2 = data.geom_xpos[geom].tolist()
        p0, p1, p2 = p_world_camera
        q0, q1, q2, q3, q4, q5, q6, q7, q8 = R_world_camera
        corners = []
        for s0, s1, s2 in _CORNER_SIGNS:
            o0, o1, o2 = c0 + h0 * s0, c1 + h1 * s1, c2 + h2 * s2
            # the corner relative to the camera: geom_xpos + R o - p, R o a rotation's rows times a vector
            d0 = (x0 + (((r0 * o0 + r2 * o2) + r1 * o1) + 0.0)) - p0
            d1 = (x1 + (((r3 * o0 + r5 * o2) + r4 * o1) + 0.0)) - p1
            d2 = (x2 + (((r6 * o0 + r8 * o2) + r7 * o1) + 0.0)) - p2
            corners.append((((d0 * q0 + d1 * q3) + d2 * q6) + 0.0, ((d0 * q1 + d1 * q4) + d2 * q7) + 0.0,
                            ((d0 * q2 + d1 * q5) + d2 * q8) + 0.0))
        return corners

    def _mark_near(self, geoms: np.ndarray, data: mujoco.MjData, p_world_camera: np.ndarray,
                   R_world_camera: np.ndarray, inside: np.ndarray) -> None:
        """Set ``inside`` ((H, W) bool, in place) at the pixels whose rays may meet ``geoms``: those inside a
        geom's rectangle (:meth:`_rectangles`) and within the cone of rays that meet its bounding sphere (MuJoCo's
        ``geom_rbound``, about its ``geom_xpos``). Other pixels are left as they are.

        The rectangle bounds the geom's box, the cone its sphere: for a ball the cone is its silhouette, where
        the rectangle of its bounding cube holds twice as many pixels.
        """
        p_camera_list, R_camera_list = p_world_camera.tolist(), R_world_camera.ravel().tolist()
        for geom, u0, u1, v0, v1 in self._rectangles(geoms, data, p_camera_list, R_camera_list):
            # the sphere's centre in the camera frame and its distance [m]: matmul(geom_xpos - p, R) and
            # linalg.norm of it, bit for bit, in Python floats (see the note above _to_camera)
            c0, c1, c2 = _to_camera(*data.geom_xpos[geom].tolist(), p_camera_list, R_camera_list)
            distance = math.sqrt(((c0 * c0 + c2 * c2) + c1 * c1) + 0.0)  # einsum "i,i->": (0 + 2) + 1
            radius = float(self.model.geom_rbound[geom]) * (1.0 + 1e-6) + 1e-9  # a hair wider: never too tight
            if distance <= radius:  # the camera is inside the sphere: the whole rectangle
                inside[v0:v1, u0:u1] = True
                continue
            # a ray meets the sphere iff its angle to the centre is at most asin(radius / distance)
            cos_cone = math.sqrt(1.0 - (radius / distance) ** 2)
            # the cosine of each ray's angle to the centre, matmul(rays (v1 - v0, u1 - u0, 3), centre / distance)
            # bit for bit: einsum over the rays' x, z, y planes adds one plane's products after another, so in the
            # order (x + z) + y in which einsum adds each ray's three contiguous products (see the note above
            # _to_camera), and in one pass over each plane instead of a loop over three products per pixel
            axis = np.array([c0 / distance, c2 / distance, c1 / distance])  # x, z, y
            cosine = einsum("ijk,i->jk", self._d_camera_xzy[:, v0:v1, u0:u1], axis)  # np.einsum
            inside[v0:v1, u0:u1] |= cosine >= cos_cone

    def _rays_near(self, geoms: np.ndarray, data: mujoco.MjData, p_world_camera: np.ndarray,
                   R_world_camera: np.ndarray, candidates: np.ndarray | None = None) -> np.ndarray:
        """Flat indices of the pixels whose rays may meet ``geoms`` (:meth:`_mark_near`); all of them, or those of
        ``candidates`` (flat indices)."""
        K = self.intrinsics
        if geoms.size == 0 or (candidates is not None and candidates.size == 0):
            return np.empty(0, dtype=np.intp)
        inside = np.zeros((K.height, K.width), dtype=bool)
        self._mark_near(geoms, data, p_world_camera, R_world_camera, inside)
        if candidates is not None:
            return candidates[inside.ravel()[candidates]]
        return inside.ravel().nonzero()[0]

    def _bounded_cast(self, data: mujoco.MjData, p_world_camera: np.ndarray, d_world: np.ndarray,
                      rays: np.ndarray, at: np.ndarray, geom_ids: np.ndarray, dist: np.ndarray,
                      normal: np.ndarray | None) -> None:
        """Cast ``rays`` (flat pixel indices) among the bounded groups (the arm) and, where one hits nearer than
        what ``geom_ids``, ``dist`` [m] (and ``normal``, (., 3)) hold at the positions ``at``, put its hit there."""
        near_normal = None if normal is None else np.empty(3 * rays.size)
        ids, near = self._cast(data, p_world_camera, d_world, rays, self._bounded_group, near_normal)
        nearer = (ids >= 0) & ((geom_ids[at] < 0) | (near < dist[at]))
        geom_ids[at[nearer]] = ids[nearer]
        dist[at[nearer]] = near[nearer]
        if normal is not None:
            normal[at[nearer]] = near_normal.reshape(-1, 3)[nearer]

    def _window_pass(self, data: mujoco.MjData, p_world_camera: np.ndarray, R_world_camera: np.ndarray,
                     d_world: np.ndarray, occluded: int | np.ndarray, targets: np.ndarray, normals: bool,
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
        """What the rays that may meet ``targets`` (:meth:`_rays_near`) hit, among all the groups the camera sees
        (the bounded ones only where they may hide ``occluded``, as :meth:`capture` casts them): ``(rays (m,)
        flat pixel indices, increasing; geom ids (m,), -1 for no hit; distances (m,) [m]; normals (m, 3) or
        None)``. ``d_world``: the unit ray directions as rows x, y, z, (3, n)."""
        rays = self._rays_near(targets, data, p_world_camera, R_world_camera)
        normal = np.empty((rays.size, 3)) if normals else None
        if rays.size and self._sees_world:
            ids, dist = self._cast(data, p_world_camera, d_world, rays, self._world_group,
                                   None if normal is None else normal.reshape(-1))
        else:
            ids, dist = np.full(rays.size, -1, np.int32), np.empty(rays.size)
        geoms = self._bounded_geoms
        if geoms.size:
            geoms = geoms[self._may_hide(geoms, targets, data, p_world_camera)]
        if geoms.size:  # the arm may hide the targets: cast it over their pixels
            seen = ids == occluded if np.ndim(occluded) == 0 else np.isin(ids, occluded)
            near = self._rays_near(geoms, data, p_world_camera, R_world_camera, rays[seen])
            if near.size:
                self._bounded_cast(data, p_world_camera, d_world, near, np.searchsorted(rays, near), ids, dist,
                                   normal)
        return rays, ids, dist, normal

    def locate(self, data: mujoco.MjData, geom: int) -> tuple[np.ndarray, np.ndarray]:
        """Where the camera sees ``geom`` now: its pixels (flat indices ``v * width + u``, row-major) and the
        points hit there ((k, 3) [m], world frame), as ``capture(data, occluded=geom, window=True)`` has them
        (``flatnonzero(mask_of(geom))`` and ``p_world_points[mask]``, the same bits), without the rest of the
        image: what looking for an object needs."""
        p_world_camera, R_world_camera = self.pose(data)
        d_world = matmul(R_world_camera, self._d_camera_rays_T)
        rays, ids, dist, _ = self._window_pass(data, p_world_camera, R_world_camera, d_world, geom,
                                               np.array(geom, ndmin=1), False)
        seen = ids == geom
        pixels = rays[seen]
        points = d_world.take(pixels, axis=1)  # (3, k): p + d * range, as capture computes each pixel's point
        points *= dist[seen]
        points += p_world_camera[:, None]
        return pixels, points.T.copy()  # (k, 3), row-major like p_world_points[mask]

    def capture(self, data: mujoco.MjData, normals: bool = False,
                occluded: int | np.ndarray | None = None, window: bool = False, points: bool = True) -> RangeImage:
        """Cast one ray per pixel from the camera's current pose and return the range snapshot.

        Args:
            data: The simulation state (kinematics current).
            normals: Also return the surface normals of the hit points.
            occluded: Geom id(s) (the object of interest): the non-world groups are cast only over the pixels
                that see these in the world pass, where they may hide them. None: wherever they may be seen.
            window: Cast only the pixels whose rays may meet the ``occluded`` geoms (:meth:`_rays_near`), the
                only ones that can see them, and report no hit elsewhere: the mask of those geoms, and their
                pixels' ranges and points, are those of the whole image (what looking for the object needs;
                :meth:`locate` gives just those).
            points: Compute every pixel's point (``p_world_points``); False: leave them to
                :meth:`RangeImage.points_of` for the pixels that need them (the image keeps the rays and distances).
        """
        n = self._n_rays
        p_world_camera, R_world_camera = self.pose(data)
        d_world = matmul(R_world_camera, self._d_camera_rays_T)  # (3, n): rows x, y, z; fresh, later the points
        targets = None if occluded is None else np.array(occluded, ndmin=1)  # as np.atleast_1d, in one call
        if window:
            if occluded is None:
                raise InvalidValueError("window=True casts only where the occluded geoms may be seen: give occluded.")
            return self._window_image(data, p_world_camera, R_world_camera, d_world, occluded, targets, normals)
        normal = np.empty((n, 3)) if normals else None
        if self._sees_world:
            geom_ids, dist, missed = self._world_pass(data, p_world_camera, R_world_camera, d_world, normal)
        else:
            geom_ids, dist, missed = np.full(n, -1, np.int32), np.empty(n), True
        geoms = self._bounded_geoms
        if geoms.size:  # the bounded pass: the arm, where it may be seen (or hide ``occluded``)
            candidates = None
            if occluded is not None:
                geoms = geoms[self._may_hide(geoms, targets, data, p_world_camera)]
                if not geoms.size:
                    candidates = np.empty(0, np.intp)
                elif np.ndim(occluded) == 0:
                    candidates = (geom_ids == occluded).nonzero()[0]
                else:
                    candidates = np.isin(geom_ids, occluded).nonzero()[0]
            rays = self._rays_near(geoms, data, p_world_camera, R_world_camera, candidates)
            if rays.size:
                self._bounded_cast(data, p_world_camera, d_world, rays, rays, geom_ids, dist, normal)
        # The points p + d * range, NaN where nothing was hit, written over the directions (not needed any more);
        # ranges inf there. When every ray hit something (the usual image: the table and the floor fill it; the
        # bounded pass only turns misses into hits) the masked copies are skipped: they would copy every distance.
        miss = geom_ids < 0 if missed else None
        if miss is not None and miss.any():
            ranges = np.where(miss, np.inf, dist).astype(np.float32)
            dist = np.where(miss, np.nan, dist)
            if normals:
                normal[miss] = np.nan
        else:
            ranges = dist.astype(np.float32)
        if not points:
            return self._image(ranges, geom_ids, None, p_world_camera, R_world_camera, normal, d_world, dist)
        hits = d_world
        hits *= dist
        hits += p_world_camera[:, None]  # (3, n); its transpose is the (n, 3) view below
        return self._image(ranges, geom_ids, hits, p_world_camera, R_world_camera, normal)

    def _window_image(self, data: mujoco.MjData, p_world_camera: np.ndarray, R_world_camera: np.ndarray,
                      d_world: np.ndarray, occluded: int | np.ndarray, targets: np.ndarray,
                      normals: bool) -> RangeImage:
        """:meth:`capture` with ``window=True``: the rays of :meth:`_window_pass` written into a whole image that
        is a miss everywhere else (geom id -1, range inf, point and normal NaN)."""
        n = self._n_rays
        rays, ids, dist, window_normal = self._window_pass(data, p_world_camera, R_world_camera, d_world, occluded,
                                                           targets, normals)
        hit = ids >= 0
        pixels, dist = rays[hit], dist[hit]
        geom_ids = np.full(n, -1, np.int32)
        geom_ids[pixels] = ids[hit]
        ranges = np.full(n, np.inf, np.float32)
        ranges[pixels] = dist  # float64 to float32 as astype rounds it
        points = np.full((3, n), np.nan)  # what d * NaN + p gives where nothing was hit
        hit_points = d_world.take(pixels, axis=1)
        hit_points *= dist
        hit_points += p_world_camera[:, None]
        points[:, pixels] = hit_points
        normal = None
        if normals:
            normal = np.full((n, 3), np.nan)
            normal[pixels] = window_normal[hit]
        return self._image(ranges, geom_ids, points, p_world_camera, R_world_camera, normal)

    def _image(self, ranges: np.ndarray, geom_ids: np.ndarray, points: np.ndarray | None,
               p_world_camera: np.ndarray, R_world_camera: np.ndarray, normal: np.ndarray | None,
               rays: np.ndarray | None = None, distances: np.ndarray | None = None) -> RangeImage:
        """The :class:`RangeImage` of per-ray arrays: ranges (n,) float32 [m], geom ids (n,), points (3, n) [m]
        (handed out as the (H, W, 3) view of their transpose) or None, normals (n, 3) or None, and without points
        the rays (3, n) and distances (n,) [m]."""
        K = self.intrinsics
        return RangeImage(
            ranges=ranges.reshape(K.height, K.width),
            geom_ids=geom_ids.reshape(K.height, K.width),
            p_world_points=None if points is None else points.T.reshape(K.height, K.width, 3),
            p_world_camera=p_world_camera,
            R_world_camera=R_world_camera,
            intrinsics=K,
            normals=None if normal is None else normal.reshape(K.height, K.width, 3),
            rays=rays,
            distances=distances,
        )
