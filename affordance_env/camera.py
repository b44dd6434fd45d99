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
from affordance_env.linalg import matmul, norm
from affordance_env.pinhole import Intrinsics

#: The 8 corners of a box of half-sizes 1.
_CORNERS = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
#: Its 12 edges: pairs of corners that differ in one coordinate.
_EDGES = [(a, b) for a in range(8) for b in range(a + 1, 8) if np.sum(_CORNERS[a] != _CORNERS[b]) == 1]


@dataclass(frozen=True)
class RangeImage:
    """One range snapshot.

    Attributes:
        ranges: Distance along each pixel's ray [m], (H, W) float32; ``inf`` where nothing was hit.
        geom_ids: MuJoCo geom hit by each ray, (H, W) int32; -1 where nothing was hit.
        p_world_points: Point hit by each ray in the world frame [m], (H, W, 3) float64; NaN where no hit.
        p_world_camera: Camera centre in the world frame [m], (3,).
        R_world_camera: Camera orientation (columns: camera x, y, z axes in the world frame), (3, 3).
        intrinsics: The pinhole intrinsics used.
        normals: Unit surface normal at each hit point in the world frame, (H, W, 3); NaN where no hit. Only
            when captured with ``normals=True`` (the range-noise model needs them), else None.
    """

    ranges: np.ndarray
    geom_ids: np.ndarray
    p_world_points: np.ndarray
    p_world_camera: np.ndarray
    R_world_camera: np.ndarray
    intrinsics: Intrinsics
    normals: np.ndarray | None = None

    def mask_of(self, geom_id: int) -> np.ndarray:
        """Boolean (H, W) mask of the pixels that see geom ``geom_id``."""
        return self.geom_ids == geom_id

    def project(self, p_world: np.ndarray) -> np.ndarray:
        """Pixel coordinates (u, v) of a world point; may lie outside the image; NaN if behind the camera."""
        return project(p_world, self.p_world_camera, self.R_world_camera, self.intrinsics)


def project(p_world: np.ndarray, p_world_camera: np.ndarray, R_world_camera: np.ndarray, K: Intrinsics) -> np.ndarray:
    """Pinhole projection of a world point to (u, v) pixels (NaN when the point is behind the camera)."""
    p_camera = matmul(np.asarray(p_world, dtype=float) - p_world_camera, R_world_camera)
    depth = -p_camera[2]
    if depth <= 1e-9:
        return np.array([np.nan, np.nan])
    return np.array([K.cx + K.fx * p_camera[0] / depth, K.cy - K.fy * p_camera[1] / depth])


def _in_front(corners: np.ndarray, near: float = 1e-3) -> np.ndarray:
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
            casts every ray that misses the face, and every ray that something else of group 0 (the object) may
            end first: inside the image rectangle that bounds that geom's box and the cone of its bounding sphere.
            The image is the same, to the last bits of the face's ranges.

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
        self._support = None if support is None or not self._world_group.any() else self._support_face(support)
        self._d_camera_rays = self.intrinsics.ray_directions().reshape(-1, 3)
        self._d_camera_grid = self._d_camera_rays.reshape(height, width, 3)  # the same rays by row and column
        # The rays as three rows (x, y, z): rotating them is one small matrix product, and each coordinate is a
        # contiguous row for the per-ray arithmetic below.
        self._d_camera_rays_T = np.ascontiguousarray(self._d_camera_rays.T)
        self._not_plane = model.geom_type != int(mujoco.mjtGeom.mjGEOM_PLANE)  # geom types never change
        n = width * height
        self._geom_ids = np.empty(n, dtype=np.int32)
        self._dist = np.empty(n, dtype=np.float64)

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
              group: np.ndarray, normal: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        """MuJoCo's nearest hit (geom ids, distances; normals written into ``normal``) of the rays ``rays``
        (``d_world``: the ray directions as rows x, y, z, (3, n))."""
        ids, dist = np.empty(rays.size, np.int32), np.empty(rays.size)
        mujoco.mj_multiRay(self.model, data, p_world_camera, np.ascontiguousarray(d_world[:, rays].T).reshape(-1),
                           group, True, -1, ids, dist, normal, rays.size, self.max_range)
        return ids, dist

    def _world_pass(self, data: mujoco.MjData, p_world_camera: np.ndarray, R_world_camera: np.ndarray,
                    d_world: np.ndarray, normal: np.ndarray | None) -> None:
        """Nearest hit of every ray among the geoms of group 0, into ``self._geom_ids``, ``self._dist``
        (``d_world``: the ray directions as rows x, y, z, (3, n))."""
        if self._support is None:
            mujoco.mj_multiRay(
                self.model, data, p_world_camera, np.ascontiguousarray(d_world.T).reshape(-1), self._world_group,
                True, -1,
                self._geom_ids, self._dist, normal, len(self._dist), self.max_range,
            )
            return
        geom, top, low, high = self._support
        on_face = np.zeros(len(self._dist), dtype=bool)
        if p_world_camera[2] > top:
            with np.errstate(divide="ignore", invalid="ignore"):
                t = (top - p_world_camera[2]) / d_world[2]
            x = p_world_camera[0] + t * d_world[0]
            y = p_world_camera[1] + t * d_world[1]
            on_face = (t > 0) & (t <= self.max_range) & (x >= low[0]) & (x <= high[0]) & (y >= low[1]) & (y <= high[1])
            self._geom_ids[on_face] = geom
            self._dist[on_face] = t[on_face]
            if normal is not None:
                normal.reshape(-1, 3)[on_face] = (0.0, 0.0, 1.0)
        # Geoms of group 0 that may end a ray before the face: all but the box and the planes below it.
        model = self.model
        others = np.flatnonzero((model.geom_group == 0) & self._not_plane)
        others = others[others != geom]
        cast = ~on_face  # and the face's rays that may meet those geoms (the others are cast already)
        cast[self._rays_near(others, data, p_world_camera, R_world_camera)] = True
        rays = np.flatnonzero(cast)
        if rays.size:
            ray_normal = np.empty(3 * rays.size) if normal is not None else None
            ids, dist = self._cast(data, p_world_camera, d_world, rays, self._world_group, ray_normal)
            self._geom_ids[rays], self._dist[rays] = ids, dist
            if normal is not None:
                normal.reshape(-1, 3)[rays] = ray_normal.reshape(-1, 3)

    def pose(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        """``(p_world_camera, R_world_camera)`` from the current kinematics (``mj_kinematics`` must be current)."""
        return data.cam_xpos[self.camera_id].copy(), data.cam_xmat[self.camera_id].reshape(3, 3).copy()

    def _may_hide(self, geoms: np.ndarray, targets: np.ndarray, data: mujoco.MjData,
                  p_world_camera: np.ndarray) -> np.ndarray:
        """Which of ``geoms`` may hide some of ``targets`` from the camera: those whose bounding sphere meets the
        cone of rays through a target's bounding sphere (a cheap, conservative test)."""
        def cone(ids: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            offset = data.geom_xpos[ids] - p_world_camera
            distance = np.linalg.norm(offset, axis=1)
            radius = self.model.geom_rbound[ids]
            half_angle = np.where(distance > radius, np.arcsin(np.minimum(radius / distance, 1.0)), np.pi)
            return offset / distance[:, None], half_angle

        d_geom, a_geom = cone(geoms)
        d_target, a_target = cone(targets)
        between = np.arccos(np.minimum(np.maximum(matmul(d_geom, d_target.T), -1.0), 1.0))  # (geoms, targets)
        return (between <= a_geom[:, None] + a_target[None, :]).any(axis=1)

    def _rectangles(self, geoms: np.ndarray, data: mujoco.MjData, p_world_camera: np.ndarray,
                    R_world_camera: np.ndarray) -> list[tuple[int, int, int, int, int]]:
        """Pixel rectangles (geom, column from, to, row from, to; ends excluded) that bound the images of the
        oriented bounding boxes of ``geoms`` (a box's projection lies within that of its 8 corners)."""
        K = self.intrinsics
        aabb = self.model.geom_aabb[geoms]  # centre and half-sizes in each geom's frame
        R = data.geom_xmat[geoms].reshape(-1, 3, 3)
        p_world = data.geom_xpos[geoms][:, None, :] + np.einsum(
            "gij,gcj->gci", R, aabb[:, None, :3] + aabb[:, None, 3:] * _CORNERS)
        p_camera = matmul(p_world - p_world_camera, R_world_camera)  # (geoms, 8, 3)
        rectangles = []
        for geom, corners in zip(geoms.tolist(), p_camera, strict=True):
            points = _in_front(corners)  # the box clipped to the part in front of the camera
            if points.shape[0] == 0:
                continue
            z = -points[:, 2]
            u = K.cx + K.fx * points[:, 0] / z
            v = K.cy - K.fy * points[:, 1] / z
            u0, u1 = max(0, int(np.floor(u.min()))), min(K.width, int(np.ceil(u.max())) + 1)
            v0, v1 = max(0, int(np.floor(v.min()))), min(K.height, int(np.ceil(v.max())) + 1)
            if u0 < u1 and v0 < v1:
                rectangles.append((geom, u0, u1, v0, v1))
        return rectangles

    def _rays_near(self, geoms: np.ndarray, data: mujoco.MjData, p_world_camera: np.ndarray,
                   R_world_camera: np.ndarray, candidates: np.ndarray | None = None) -> np.ndarray:
        """Flat indices of the pixels whose rays may meet ``geoms``: those inside a geom's rectangle
        (:meth:`_rectangles`) and within the cone of rays that meet its bounding sphere (MuJoCo's
        ``geom_rbound``, about its ``geom_xpos``); all of them, or those of ``candidates`` (flat indices).

        The rectangle bounds the geom's box, the cone its sphere: for a ball the cone is its silhouette, where
        the rectangle of its bounding cube holds twice as many pixels.
        """
        K = self.intrinsics
        if geoms.size == 0 or (candidates is not None and candidates.size == 0):
            return np.empty(0, dtype=np.intp)
        inside = np.zeros((K.height, K.width), dtype=bool)
        for geom, u0, u1, v0, v1 in self._rectangles(geoms, data, p_world_camera, R_world_camera):
            centre = matmul(data.geom_xpos[geom] - p_world_camera, R_world_camera)  # camera frame
            distance = norm(centre)
            radius = float(self.model.geom_rbound[geom]) * (1.0 + 1e-6) + 1e-9  # a hair wider: never too tight
            if distance <= radius:  # the camera is inside the sphere: the whole rectangle
                inside[v0:v1, u0:u1] = True
                continue
            # a ray meets the sphere iff its angle to the centre is at most asin(radius / distance)
            cos_cone = math.sqrt(1.0 - (radius / distance) ** 2)
            inside[v0:v1, u0:u1] |= matmul(self._d_camera_grid[v0:v1, u0:u1], centre / distance) >= cos_cone
        if candidates is not None:
            return candidates[inside.ravel()[candidates]]
        return np.flatnonzero(inside)

    def capture(self, data: mujoco.MjData, normals: bool = False,
                occluded: int | np.ndarray | None = None, window: bool = False) -> RangeImage:
        """Cast one ray per pixel from the camera's current pose and return the range snapshot.

        Args:
            data: The simulation state (kinematics current).
            normals: Also return the surface normals of the hit points.
            occluded: Geom id(s) (the object of interest): the non-world groups are cast only over the pixels
                that see these in the world pass, where they may hide them. None: wherever they may be seen.
            window: Cast only the pixels whose rays may meet the ``occluded`` geoms (:meth:`_rays_near`), the
                only ones that can see them, and report no hit elsewhere: the mask of those geoms, and their
                pixels' ranges and points, are those of the whole image (what looking for the object needs).
        """
        K = self.intrinsics
        p_world_camera, R_world_camera = self.pose(data)
        d_world = matmul(R_world_camera, self._d_camera_rays_T)  # (3, n): rows x, y, z
        normal = np.empty(3 * len(self._dist)) if normals else None
        self._geom_ids[:] = -1
        if window:
            if occluded is None:
                raise InvalidValueError("window=True casts only where the occluded geoms may be seen: give occluded.")
            rays = self._rays_near(np.atleast_1d(occluded), data, p_world_camera, R_world_camera)
            if rays.size and self._world_group.any():
                ray_normal = np.empty(3 * rays.size) if normals else None
                self._geom_ids[rays], self._dist[rays] = self._cast(data, p_world_camera, d_world, rays,
                                                                    self._world_group, ray_normal)
                if normals:
                    normal.reshape(-1, 3)[rays] = ray_normal.reshape(-1, 3)
        elif self._world_group.any():
            self._world_pass(data, p_world_camera, R_world_camera, d_world, normal)
        geoms, candidates = self._bounded_geoms, None
        if occluded is not None:
            geoms = geoms[self._may_hide(geoms, np.atleast_1d(occluded), data, p_world_camera)]
            if not geoms.size:
                candidates = np.empty(0, np.intp)
            elif np.ndim(occluded) == 0:
                candidates = np.flatnonzero(self._geom_ids == occluded)
            else:
                candidates = np.flatnonzero(np.isin(self._geom_ids, occluded))
        rays = self._rays_near(geoms, data, p_world_camera, R_world_camera, candidates)
        if rays.size:
            near_normal = np.empty(3 * rays.size) if normals else None
            ids, dist = self._cast(data, p_world_camera, d_world, rays, self._bounded_group, near_normal)
            nearer = (ids >= 0) & ((self._geom_ids[rays] < 0) | (dist < self._dist[rays]))
            self._geom_ids[rays[nearer]] = ids[nearer]
            self._dist[rays[nearer]] = dist[nearer]
            if normals:
                normal.reshape(-1, 3)[rays[nearer]] = near_normal.reshape(-1, 3)[nearer]
        hit = self._geom_ids >= 0
        dist = np.where(hit, self._dist, np.inf)
        points = d_world * np.where(hit, self._dist, np.nan)
        points += p_world_camera[:, None]  # (3, n); its transpose is the (n, 3) view below
        return RangeImage(
            ranges=dist.reshape(K.height, K.width).astype(np.float32),
            geom_ids=self._geom_ids.reshape(K.height, K.width).copy(),
            p_world_points=points.T.reshape(K.height, K.width, 3),
            p_world_camera=p_world_camera,
            R_world_camera=R_world_camera,
            intrinsics=K,
            normals=None if normal is None else np.where(
                hit[:, None], normal.reshape(-1, 3), np.nan).reshape(K.height, K.width, 3),
        )
