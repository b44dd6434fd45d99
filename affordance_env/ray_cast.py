"""Ray casting of a range image: MuJoCo's nearest hit of each pixel's ray, pass by pass.

A camera sees the world (geom group 0: table, floor, object) and bounded groups (the arm's detailed meshes, whose
rays cost microseconds each). The world pass casts every ray among group 0, except those that end on a support
face (the table top), which meet its plane in closed form; the bounded pass casts among the other groups only the
rays that :mod:`affordance_env.culling` says may meet them, and keeps their nearer hits. The image is the one a
single ``mujoco.mj_multiRay`` over all the groups gives. Rays start at the camera's centre ``p_world_camera``
[m]; their unit directions ``d_world`` are in the world frame as rows x, y, z, (3, n); distances are in metres
along the rays.
"""

from __future__ import annotations

import mujoco
import numpy as np

from affordance_env.culling import Culling
from affordance_env.exceptions import InvalidValueError
from affordance_env.pinhole import Intrinsics


def support_face(model: mujoco.MjModel, name: str) -> tuple[int, float, np.ndarray, np.ndarray]:
    """(geom id, height [m], lower and upper x-y corners [m]) of the upward face of the box ``name``, a box of
    group 0 fixed to the world and aligned with its axes, above every plane of group 0."""
    geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
    if geom < 0:
        raise InvalidValueError(f"support: the model has no geom named {name!r}.")
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    R = data.geom_xmat[geom].reshape(3, 3)
    if (model.geom_type[geom] != mujoco.mjtGeom.mjGEOM_BOX or model.geom_group[geom] != 0
            or model.body_weldid[model.geom_bodyid[geom]] != 0 or not np.allclose(R, np.eye(3), atol=1e-12)):
        raise InvalidValueError(
            f"support: geom {name!r} must be a box of group 0, fixed to the world and aligned with its axes.")
    centre, half = data.geom_xpos[geom], model.geom_size[geom]
    top = float(centre[2] + half[2])
    planes = np.flatnonzero((model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE) & (model.geom_group == 0))
    for plane in planes:  # a plane of the world may never end a ray before the face does
        if data.geom_xpos[plane, 2] >= top or not np.allclose(data.geom_xmat[plane, 8], 1.0):
            raise InvalidValueError(
                f"support: the plane {model.geom(plane).name!r} is not below the face of {name!r}.")
    return int(geom), top, centre[:2] - half[:2], centre[:2] + half[:2]


class RayCaster:
    """The ray casts of one camera's images.

    Args:
        model: The compiled model.
        intrinsics: The camera's pinhole intrinsics (the image has one ray per pixel).
        culling: The camera's culling, which picks the rays that may meet given geoms.
        max_range: Rays longer than this report no hit [m].
        geom_groups: Geom groups the camera sees (see :class:`~affordance_env.camera.RangeCamera`).
        support: Name of the support face's box (see :class:`~affordance_env.camera.RangeCamera`), or None.
    """

    def __init__(self, model: mujoco.MjModel, intrinsics: Intrinsics, culling: Culling, max_range: float,
                 geom_groups: tuple[int, ...], support: str | None) -> None:
        self.model, self.intrinsics, self.culling, self.max_range = model, intrinsics, culling, max_range
        if any(g not in range(6) for g in geom_groups):
            raise InvalidValueError(f"geom_groups must be within 0..5, got {geom_groups!r}.")
        self._world_group = np.array([g == 0 and g in geom_groups for g in range(6)], dtype=np.uint8)
        self._bounded_group = np.array([g != 0 and g in geom_groups for g in range(6)], dtype=np.uint8)
        #: Geoms of the bounded pass (read once: set_object changes only the object's geoms, in group 0 or 3).
        self._bounded_geoms = np.flatnonzero(self._bounded_group[np.clip(model.geom_group, 0, 5)]
                                             & (model.geom_group >= 0) & (model.geom_group <= 5))
        #: Whether the camera sees group 0 (the world pass casts it).
        self._sees_world = bool(self._world_group.any())
        #: The support face (:func:`support_face`), or None.
        self.support = None if support is None or not self._sees_world else support_face(model, support)
        self._not_plane = model.geom_type != int(mujoco.mjtGeom.mjGEOM_PLANE)  # geom types never change
        #: Pixels of an image [rays].
        self._n_rays = intrinsics.width * intrinsics.height
        # Scratch for the support face's per-ray test (a ray coordinate [m], one comparison), made once and
        # reused by every capture (as the image buffers were before: one capture at a time per camera).
        self._scratch = np.empty(self._n_rays)
        self._scratch_test = np.empty(self._n_rays, dtype=bool)
        #: The geoms of group 0 other than the support face and the planes, for the geom groups they were read from
        #: (``set_object`` moves the object's geoms between group 0 and a hidden one): ``(groups, geoms, whether they
        #: are exactly the geoms of group 0 on moving bodies)``.
        self._others: tuple[bytes, np.ndarray, bool] | None = None

    def cast(self, data: mujoco.MjData, p_world_camera: np.ndarray, d_world: np.ndarray, rays: np.ndarray,
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

    def image_pass(self, data: mujoco.MjData, p_world_camera: np.ndarray, R_world_camera: np.ndarray,
                   d_world: np.ndarray, normal: np.ndarray | None, occluded: int | np.ndarray | None,
                   targets: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, bool]:
        """Nearest hit of every ray among all the groups the camera sees: the world pass, then the bounded pass
        where the bounded groups may be seen, or where they may hide ``occluded`` (geom id(s); ``targets``: the same
        as an array, (k,)) if not None. ``(geom ids (n,) int32, distances [m] (n,), whether some ray may have hit
        nothing)``; normals into ``normal`` ((n, 3)) if not None. A distance is meaningless where the id is -1."""
        n = self._n_rays
        if self._sees_world:
            geom_ids, dist, missed = self.world_pass(data, p_world_camera, R_world_camera, d_world, normal)
        else:
            geom_ids, dist, missed = np.full(n, -1, np.int32), np.empty(n), True
        geoms = self._bounded_geoms
        if geoms.size:  # the bounded pass: the arm, where it may be seen (or hide ``occluded``)
            candidates = None
            if occluded is not None:
                geoms = geoms[self.culling.may_hide(geoms, targets, data, p_world_camera)]
                if not geoms.size:
                    candidates = np.empty(0, np.intp)
                elif np.ndim(occluded) == 0:
                    candidates = (geom_ids == occluded).nonzero()[0]
                else:
                    candidates = np.isin(geom_ids, occluded).nonzero()[0]
            rays = self.culling.rays_near(geoms, data, p_world_camera, R_world_camera, candidates)
            if rays.size:
                self.bounded_cast(data, p_world_camera, d_world, rays, rays, geom_ids, dist, normal)
        return geom_ids, dist, missed

    def world_pass(self, data: mujoco.MjData, p_world_camera: np.ndarray, R_world_camera: np.ndarray,
                   d_world: np.ndarray, normal: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, bool]:
        """Nearest hit of every ray among the geoms of group 0: ``(geom ids (n,) int32, distances [m] (n,),
        whether some ray hit nothing)``, fresh arrays; normals into ``normal`` ((n, 3)) if not None (``d_world``:
        the unit ray directions as rows x, y, z, (3, n)). A distance is meaningless where the geom id is -1."""
        n = self._n_rays
        if self.support is None:
            geom_ids, dist = np.empty(n, np.int32), np.empty(n)
            mujoco.mj_multiRay(
                self.model, data, p_world_camera, np.ascontiguousarray(d_world.T).reshape(-1), self._world_group,
                True, -1, geom_ids, dist, None if normal is None else normal.reshape(-1), n, self.max_range,
            )
            return geom_ids, dist, bool(np.logical_or.reduce(geom_ids < 0))
        geom, top, low, high = self.support
        if p_world_camera[2] > top:
            t, on_face = self._meet_face(p_world_camera, d_world, top, low, high)
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
            self.culling.mark_near(others, data, p_world_camera, R_world_camera, near)
            face_rays = np.logical_and(near.ravel(), face, out=face).nonzero()[0]  # the near rays off it are cast
        elif others.size:
            self.culling.mark_near(others, data, p_world_camera, R_world_camera, cast.reshape(K.height, K.width))
        if face_rays is not None and face_rays.size:
            face_normal = None if normal is None else np.empty(3 * face_rays.size)
            ids, ray_dist = self.cast(data, p_world_camera, d_world, face_rays, self._world_group, face_normal,
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
        ids, ray_dist = self.cast(data, p_world_camera, d_world, rays, self._world_group, ray_normal)
        geom_ids[rays], dist[rays] = ids, ray_dist
        if normal is not None:
            normal[rays] = ray_normal.reshape(-1, 3)
        # only a cast ray can miss (the face's rays end on it): whether one did, from the cast rays alone
        return geom_ids, dist, bool(np.logical_or.reduce(ids < 0))

    def _meet_face(self, p_world_camera: np.ndarray, d_world: np.ndarray, top: float, low: np.ndarray,
                   high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where each ray meets the support face's plane (height ``top`` [m], x-y corners ``low`` and ``high``
        [m]), from a camera above it: ``(t, on_face)``, its distance t [m] along each ray (n,) and whether the ray
        ends on the face (n,) bool.

        The face's rays are those with 0 < t <= max_range and x, y [m] within the face. The tests are the same
        comparisons of the same floats as ``(t > 0) & (t <= max_range) & (x >= low_x) & ...``, folded into one
        boolean array with scratch buffers instead of nine temporaries."""
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
        return t, on_face

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

    def bounded_cast(self, data: mujoco.MjData, p_world_camera: np.ndarray, d_world: np.ndarray,
                     rays: np.ndarray, at: np.ndarray, geom_ids: np.ndarray, dist: np.ndarray,
                     normal: np.ndarray | None) -> None:
        """Cast ``rays`` (flat pixel indices) among the bounded groups (the arm) and, where one hits nearer than
        what ``geom_ids``, ``dist`` [m] (and ``normal``, (., 3)) hold at the positions ``at``, put its hit there."""
        near_normal = None if normal is None else np.empty(3 * rays.size)
        ids, near = self.cast(data, p_world_camera, d_world, rays, self._bounded_group, near_normal)
        nearer = (ids >= 0) & ((geom_ids[at] < 0) | (near < dist[at]))
        geom_ids[at[nearer]] = ids[nearer]
        dist[at[nearer]] = near[nearer]
        if normal is not None:
            normal[at[nearer]] = near_normal.reshape(-1, 3)[nearer]

    def window_pass(self, data: mujoco.MjData, p_world_camera: np.ndarray, R_world_camera: np.ndarray,
                    d_world: np.ndarray, occluded: int | np.ndarray, targets: np.ndarray, normals: bool,
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
        """What the rays that may meet ``targets`` (:meth:`Culling.rays_near
        <affordance_env.culling.Culling.rays_near>`) hit, among all the groups the camera sees (the bounded ones
        only where they may hide ``occluded``, as :meth:`image_pass` casts them): ``(rays (m,) flat pixel indices,
        increasing; geom ids (m,), -1 for no hit; distances (m,) [m]; normals (m, 3) or None)``. ``d_world``: the
        unit ray directions as rows x, y, z, (3, n)."""
        rays = self.culling.rays_near(targets, data, p_world_camera, R_world_camera)
        normal = np.empty((rays.size, 3)) if normals else None
        if rays.size and self._sees_world:
            ids, dist = self.cast(data, p_world_camera, d_world, rays, self._world_group,
                                  None if normal is None else normal.reshape(-1))
        else:
            ids, dist = np.full(rays.size, -1, np.int32), np.empty(rays.size)
        geoms = self._bounded_geoms
        if geoms.size:
            geoms = geoms[self.culling.may_hide(geoms, targets, data, p_world_camera)]
        if geoms.size:  # the arm may hide the targets: cast it over their pixels
            seen = ids == occluded if np.ndim(occluded) == 0 else np.isin(ids, occluded)
            near = self.culling.rays_near(geoms, data, p_world_camera, R_world_camera, rays[seen])
            if near.size:
                self.bounded_cast(data, p_world_camera, d_world, near, np.searchsorted(rays, near), ids, dist,
                                  normal)
        return rays, ids, dist, normal
