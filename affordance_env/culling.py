"""Which rays of a range image may meet which geoms: the culling that spares the ray caster most rays.

A ray (one per pixel, :mod:`affordance_env.pinhole`) may meet a geom only inside the image rectangle that bounds the
projection of the geom's bounding box (MuJoCo's ``geom_aabb``) and inside the cone of rays through its bounding
sphere (``geom_rbound`` about ``geom_xpos``); a geom may hide another only where the cones of their bounding
spheres overlap. Both tests are conservative: every ray that meets the geom is kept. Positions are in the world
frame [m]; the camera's pose is ``p_world_camera`` [m] and ``R_world_camera`` (columns: its axes in the world).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from affordance_env.linalg import einsum, matmul
from affordance_env.pinhole import Intrinsics, to_camera

#: The 8 corners of a box of half-sizes 1.
CORNERS = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
#: Its 12 edges: pairs of corners that differ in one coordinate.
_EDGES = [(a, b) for a in range(8) for b in range(a + 1, 8) if np.sum(CORNERS[a] != CORNERS[b]) == 1]
#: Its corners' signs as Python floats, in the same order.
_CORNER_SIGNS: tuple[tuple[float, float, float], ...] = tuple(tuple(corner) for corner in CORNERS.tolist())
#: How far in front of the camera a box's image is bounded [m] (:func:`_in_front`).
_NEAR = 1e-3


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


def box_corners_camera(aabb: list[float], xmat: list[float], xpos: list[float], p_world_camera: list[float],
                       R_world_camera: list[float]) -> list[tuple[float, float, float]]:
    """The 8 corners (in :data:`CORNERS`' order) of a geom's bounding box in the camera frame [m].

    Args (Python floats):
        aabb: The geom's ``geom_aabb``: its box's centre and half-sizes in the geom's frame [m], 6 floats.
        xmat: The geom's orientation in the world frame (``geom_xmat``, row-major, 9 floats).
        xpos: The geom's position in the world frame (``geom_xpos``) [m].
        p_world_camera: The camera's position [m].
        R_world_camera: The camera's orientation (row-major, 9 floats).

    Bit for bit ``matmul(xpos + einsum("ij,cj->ci", xmat, aabb_centre + aabb_half * CORNERS) - p_world_camera,
    R_world_camera)``, in Python floats: a box is 8 points, for which a dozen small array calls cost several times
    the arithmetic (see the note above :func:`affordance_env.pinhole.to_camera` for the order of the sums; the
    rotation into the camera frame is ``to_camera``'s, written out).
    """
    c0, c1, c2, h0, h1, h2 = aabb
    r0, r1, r2, r3, r4, r5, r6, r7, r8 = xmat
    x0, x1, x2 = xpos
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


class Culling:
    """The rays of a camera's image that may meet given geoms.

    Args:
        model: The compiled model (its ``geom_aabb`` and ``geom_rbound`` are read at every call: the object's
            change with it).
        intrinsics: The camera's pinhole intrinsics.
        d_camera_rays_T: Every pixel's unit ray direction in the camera frame as rows x, y, z, (3, H W).
    """

    def __init__(self, model: mujoco.MjModel, intrinsics: Intrinsics, d_camera_rays_T: np.ndarray) -> None:
        self.model = model
        self.intrinsics = intrinsics
        #: The rays as three (H, W) planes in the order x, z, y, in which a ray's cosine to an axis adds its products
        #: (:meth:`mark_near`).
        self._d_camera_xzy = np.ascontiguousarray(
            d_camera_rays_T.reshape(3, intrinsics.height, intrinsics.width)[[0, 2, 1]])

    def rectangles(self, geoms: np.ndarray, data: mujoco.MjData, p_world_camera: np.ndarray | list[float],
                   R_world_camera: np.ndarray | list[float]) -> list[tuple[int, int, int, int, int]]:
        """Pixel rectangles (geom, column from, to, row from, to; ends excluded) that bound the images of the
        oriented bounding boxes of ``geoms`` (a box's projection lies within that of its 8 corners). The camera's
        pose as arrays (3,), (3, 3), or as the Python floats of :func:`box_corners_camera`."""
        K = self.intrinsics
        cx, cy, fx, fy = K.cx, K.cy, K.fx, K.fy
        p_camera_list = p_world_camera if isinstance(p_world_camera, list) else p_world_camera.tolist()
        R_camera_list = R_world_camera if isinstance(R_world_camera, list) else R_world_camera.ravel().tolist()
        aabb, xmat, xpos = self.model.geom_aabb, data.geom_xmat, data.geom_xpos
        rectangles = []
        for geom in geoms.tolist():
            corners = box_corners_camera(aabb[geom].tolist(), xmat[geom].tolist(), xpos[geom].tolist(), p_camera_list,
                                         R_camera_list)
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

    def mark_near(self, geoms: np.ndarray, data: mujoco.MjData, p_world_camera: np.ndarray,
                  R_world_camera: np.ndarray, inside: np.ndarray) -> None:
        """Set ``inside`` ((H, W) bool, in place) at the pixels whose rays may meet ``geoms``: those inside a
        geom's rectangle (:meth:`rectangles`) and within the cone of rays that meet its bounding sphere (MuJoCo's
        ``geom_rbound``, about its ``geom_xpos``). Other pixels are left as they are.

        The rectangle bounds the geom's box, the cone its sphere: for a ball the cone is its silhouette, where
        the rectangle of its bounding cube holds twice as many pixels.
        """
        p_camera_list, R_camera_list = p_world_camera.tolist(), R_world_camera.ravel().tolist()
        for geom, u0, u1, v0, v1 in self.rectangles(geoms, data, p_camera_list, R_camera_list):
            # the sphere's centre in the camera frame and its distance [m]: matmul(geom_xpos - p, R) and
            # linalg.norm of it, bit for bit, in Python floats (see the note above pinhole.to_camera)
            c0, c1, c2 = to_camera(*data.geom_xpos[geom].tolist(), p_camera_list, R_camera_list)
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
            # pinhole.to_camera), and in one pass over each plane instead of a loop over three products per pixel
            axis = np.array([c0 / distance, c2 / distance, c1 / distance])  # x, z, y
            cosine = einsum("ijk,i->jk", self._d_camera_xzy[:, v0:v1, u0:u1], axis)  # np.einsum
            inside[v0:v1, u0:u1] |= cosine >= cos_cone

    def rays_near(self, geoms: np.ndarray, data: mujoco.MjData, p_world_camera: np.ndarray,
                  R_world_camera: np.ndarray, candidates: np.ndarray | None = None) -> np.ndarray:
        """Flat indices of the pixels whose rays may meet ``geoms`` (:meth:`mark_near`); all of them, or those of
        ``candidates`` (flat indices)."""
        K = self.intrinsics
        if geoms.size == 0 or (candidates is not None and candidates.size == 0):
            return np.empty(0, dtype=np.intp)
        inside = np.zeros((K.height, K.width), dtype=bool)
        self.mark_near(geoms, data, p_world_camera, R_world_camera, inside)
        if candidates is not None:
            return candidates[inside.ravel()[candidates]]
        return inside.ravel().nonzero()[0]

    def may_hide(self, geoms: np.ndarray, targets: np.ndarray, data: mujoco.MjData,
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
