"""Metric range camera by MuJoCo ray casting: no OpenGL, so it works headless and in CI.

One ray per pixel through the pixel centre of a pinhole camera attached to a MuJoCo camera element;
``mujoco.mj_multiRay`` returns the distance and the geom hit by each ray, which gives the object mask for free,
as the paper marks object pixels from the simulator.

Image conventions: ``u`` is the column, ``v`` the row, pixel centres at integer indices. MuJoCo cameras look
along their -z axis with +x to the right of the image and +y up.

This module assembles the images; the pinhole geometry is :mod:`affordance_env.pinhole`, the ray casts
:mod:`affordance_env.ray_cast`, and the choice of the rays each pass casts :mod:`affordance_env.culling`.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from affordance_env.culling import Culling
from affordance_env.exceptions import InvalidValueError
from affordance_env.linalg import matmul
from affordance_env.pinhole import Intrinsics, project
from affordance_env.ray_cast import RayCaster

__all__ = ["Intrinsics", "RangeCamera", "RangeImage", "project"]


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
        self._d_camera_rays = self.intrinsics.ray_directions().reshape(-1, 3)
        # The rays as three rows (x, y, z): rotating them is one small matrix product, and each coordinate is a
        # contiguous row for the per-ray arithmetic below.
        self._d_camera_rays_T = np.ascontiguousarray(self._d_camera_rays.T)
        #: Pixels of an image [rays].
        self._n_rays = width * height
        #: Which rays may meet which geoms (:mod:`affordance_env.culling`).
        self.culling = Culling(model, self.intrinsics, self._d_camera_rays_T)
        #: The passes of MuJoCo's ray casts (:mod:`affordance_env.ray_cast`).
        self.ray_caster = RayCaster(model, self.intrinsics, self.culling, self.max_range, geom_groups, support)

    def pose(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        """``(p_world_camera, R_world_camera)`` from the current kinematics (``mj_kinematics`` must be current)."""
        return data.cam_xpos[self.camera_id].copy(), data.cam_xmat[self.camera_id].reshape(3, 3).copy()

    def capture(self, data: mujoco.MjData, normals: bool = False,
                occluded: int | np.ndarray | None = None, window: bool = False, points: bool = True) -> RangeImage:
        """Cast one ray per pixel from the camera's current pose and return the range snapshot.

        Args:
            data: The simulation state (kinematics current).
            normals: Also return the surface normals of the hit points.
            occluded: Geom id(s) (the object of interest): the non-world groups are cast only over the pixels
                that see these in the world pass, where they may hide them. None: wherever they may be seen.
            window: Cast only the pixels whose rays may meet the ``occluded`` geoms (:meth:`Culling.rays_near
                <affordance_env.culling.Culling.rays_near>`), the
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
        geom_ids, dist, missed = self.ray_caster.image_pass(data, p_world_camera, R_world_camera, d_world, normal,
                                                            occluded, targets)
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

    def locate(self, data: mujoco.MjData, geom: int) -> tuple[np.ndarray, np.ndarray]:
        """Where the camera sees ``geom`` now: its pixels (flat indices ``v * width + u``, row-major) and the
        points hit there ((k, 3) [m], world frame), as ``capture(data, occluded=geom, window=True)`` has them
        (``flatnonzero(mask_of(geom))`` and ``p_world_points[mask]``, the same bits), without the rest of the
        image: what looking for an object needs."""
        p_world_camera, R_world_camera = self.pose(data)
        d_world = matmul(R_world_camera, self._d_camera_rays_T)
        rays, ids, dist, _ = self.ray_caster.window_pass(data, p_world_camera, R_world_camera, d_world, geom,
                                                         np.array(geom, ndmin=1), False)
        seen = ids == geom
        pixels = rays[seen]
        points = d_world.take(pixels, axis=1)  # (3, k): p + d * range, as capture computes each pixel's point
        points *= dist[seen]
        points += p_world_camera[:, None]
        return pixels, points.T.copy()  # (k, 3), row-major like p_world_points[mask]

    def _window_image(self, data: mujoco.MjData, p_world_camera: np.ndarray, R_world_camera: np.ndarray,
                      d_world: np.ndarray, occluded: int | np.ndarray, targets: np.ndarray,
                      normals: bool) -> RangeImage:
        """:meth:`capture` with ``window=True``: the rays of :meth:`RayCaster.window_pass
        <affordance_env.ray_cast.RayCaster.window_pass>` written into a whole image that
        is a miss everywhere else (geom id -1, range inf, point and normal NaN)."""
        n = self._n_rays
        rays, ids, dist, window_normal = self.ray_caster.window_pass(data, p_world_camera, R_world_camera, d_world,
                                                                     occluded, targets, normals)
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
