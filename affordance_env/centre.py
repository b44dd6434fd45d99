"""Where an object stands on the table, from the points of it that the range camera sees: a pure function.

The camera sees one side of the object, and part of it when an arm hides the rest: the mean of the visible
points, or of their highest ones, lies toward the camera and toward the part in view. :func:`object_centre` fits
the object's shape class (sphere, cube, cylinder standing or lying, as long as it is wide) resting on the table to
the points instead: the centre's height is then half the object's size above the table top, and what is fitted
is the centre (x, y), the size and, for a cube or a lying cylinder, the yaw. The residual of a point is its signed
distance to the shape's surface; the fit is Levenberg-Marquardt on Huber-weighted residuals, started from the
centre of the visible top, the size its height above the table and a few yaws, the best fit kept. A cylinder is
fitted standing and lying, and the better one kept: a standing cylinder that toppled lies.

The arithmetic is elementwise numpy, :mod:`affordance_env.linalg`'s products and solver and :mod:`math`'s cosine
and sine of Python floats, so the estimate has the same bits on every x86-64 CPU.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from affordance_env.exceptions import InvalidValueError
from affordance_env.linalg import matmul, solve_spd
from affordance_env.objects import PRIMITIVES, SIZE_LIMITS

#: The visible top, whose centre starts the fit: the points within this of its height [m]. 3 mm: two and a half
#: times the range noise's deviation where the head sees the table (1.2 mm, :mod:`affordance_env.range_noise`), and
#: a sphere's cap 3 mm deep is a fifth of its diameter wide or more (2 sqrt(3 mm r) at r <= 7.5 cm).
TOP_DEPTH = 0.003
#: The share of the highest points that may be the range noise's strays, not the top [1]: with the Kinect model the
#: highest point of a cube was 8 mm above its top (721 points), of another 33 mm (2717 points).
TOP_OUTLIERS = 0.02
#: Points beyond this from the surface count less (Huber's weight, scale / |residual|) [m]: the range noise's
#: deviation (1.2 mm, :mod:`affordance_env.range_noise`) is within it, stray points beyond it.
HUBER_SCALE = 0.002
#: At most this many points are fitted [points], taken evenly through the visible ones (a 0.1 m object fills 2000-3000
#: pixels of the 160 x 120 camera). Measured over 300 objects placed over the workspaces, exact and noisy ranges:
#: the 95th percentile of the error 0.2 and 1.0 mm with 400 points, 0.3 and 1.4 mm with 200, for 12 and 9 ms of CPU.
MAX_POINTS = 400
#: Levenberg-Marquardt's iterations per start, its first damping and the least it falls to (relative to the normal
#: matrix's diagonal): a parameter that the points do not tell (the yaw of a cube seen from above alone) leaves the
#: matrix singular, which the damping keeps solvable.
ITERATIONS, DAMPING, MIN_DAMPING = 30, 1e-3, 1e-6
#: Every start is fitted this many iterations [1]; the best one goes on for :data:`ITERATIONS`.
START_ITERATIONS = 5
#: Finite-difference steps of the parameters (centre and size [m], yaw [rad]) for the Jacobian.
STEPS = (1e-5, 1e-5, 1e-5, 1e-5)
#: The yaws each start tries [rad]: a cube repeats every 90 degrees, a lying cylinder every 180 degrees.
START_YAWS = {"box": tuple(k * math.pi / 8 for k in range(4)), "lying": tuple(k * math.pi / 4 for k in range(4))}
#: The fewest points that place a shape by four numbers; with fewer, the visible top's centre is the estimate.
MIN_POINTS = 8


def _local(points: np.ndarray, params: np.ndarray, table_top: float) -> tuple[np.ndarray, ...]:
    """The points in the frame of a shape resting on the table with ``params`` (x, y, size, yaw): its centre at
    (x, y, table_top + size / 2), its x axis at ``yaw`` from the world's; and the half size."""
    x, y, size, yaw = (float(v) for v in params)
    c, s = math.cos(yaw), math.sin(yaw)
    dx, dy, dz = points[:, 0] - x, points[:, 1] - y, points[:, 2] - (table_top + size / 2)
    return dx * c + dy * s, dy * c - dx * s, dz, size / 2


def _round(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Signed distance of the 2-D offsets (``a``, ``b``) beyond a rectangle's half sides (negative inside)."""
    a_out, b_out = np.maximum(a, 0.0), np.maximum(b, 0.0)
    outside = np.sqrt(a_out * a_out + b_out * b_out)
    return outside + np.minimum(np.maximum(a, b), 0.0)


def _sphere(points: np.ndarray, params: np.ndarray, table_top: float) -> np.ndarray:
    u, v, w, h = _local(points, params, table_top)
    return np.sqrt(u * u + v * v + w * w) - h


def _box(points: np.ndarray, params: np.ndarray, table_top: float) -> np.ndarray:
    u, v, w, h = _local(points, params, table_top)
    q = np.stack([np.abs(u) - h, np.abs(v) - h, np.abs(w) - h])
    q_out = np.maximum(q, 0.0)
    outside = np.sqrt(np.sum(q_out * q_out, axis=0))
    return outside + np.minimum(np.max(q, axis=0), 0.0)


def _standing(points: np.ndarray, params: np.ndarray, table_top: float) -> np.ndarray:
    u, v, w, h = _local(points, params, table_top)
    return _round(np.sqrt(u * u + v * v) - h, np.abs(w) - h)


def _lying(points: np.ndarray, params: np.ndarray, table_top: float) -> np.ndarray:
    u, v, w, h = _local(points, params, table_top)  # the axis along the shape's x
    return _round(np.sqrt(v * v + w * w) - h, np.abs(u) - h)


Residuals = Callable[[np.ndarray, np.ndarray, float], np.ndarray]
#: The shapes each primitive may rest as, with the yaws their fits start from (a single one: yaw is not fitted).
SHAPES: dict[str, tuple[tuple[Residuals, tuple[float, ...]], ...]] = {
    "sphere": ((_sphere, (0.0,)),),
    "box": ((_box, START_YAWS["box"]),),
    "cylinder": ((_standing, (0.0,)), (_lying, START_YAWS["lying"])),
}


def _cost(r: np.ndarray) -> float:
    """Huber's cost of the residuals [m^2]."""
    a = np.abs(r)
    return float(np.sum(np.where(a <= HUBER_SCALE, 0.5 * r * r, HUBER_SCALE * (a - 0.5 * HUBER_SCALE))))


def _fit(residuals: Residuals, points: np.ndarray, start: np.ndarray, table_top: float, free: int,
         iterations: int) -> tuple[np.ndarray, float]:
    """Levenberg-Marquardt from ``start`` over the first ``free`` parameters, at most ``iterations`` steps; the
    parameters and their cost."""
    params, damping = start.copy(), DAMPING
    r = residuals(points, params, table_top)
    cost = _cost(r)
    for _ in range(iterations):
        J = np.empty((len(r), free))
        for i in range(free):
            step = np.zeros(4)
            step[i] = STEPS[i]
            J[:, i] = (residuals(points, params + step, table_top) - residuals(points, params - step, table_top)) / (
                2 * STEPS[i])
        weights = np.minimum(1.0, HUBER_SCALE / np.maximum(np.abs(r), 1e-12))  # Huber's, as reweighted squares
        Jw = J * weights[:, None]
        A, g = matmul(Jw.T, J), matmul(Jw.T, r)
        diagonal = np.diag(A).copy()
        if not np.max(diagonal) > 0.0:  # no parameter moves a residual: nothing to fit
            break
        improved = False
        while damping < 1e6:
            A_damped = A + np.diag(damping * np.maximum(diagonal, 1e-9 * np.max(diagonal)))
            trial = params.copy()
            try:
                trial[:free] -= solve_spd(A_damped, g)
            except np.linalg.LinAlgError:  # singular still: damp more
                damping *= 10
                continue
            trial[2] = min(max(trial[2], SIZE_LIMITS[0] / 2), SIZE_LIMITS[1] * 2)
            r_trial = residuals(points, trial, table_top)
            cost_trial = _cost(r_trial)
            if cost_trial < cost:
                params, r, improved = trial, r_trial, cost - cost_trial > 1e-12 * cost
                cost, damping = cost_trial, max(damping / 10, MIN_DAMPING)
                break
            damping *= 10
        if not improved:
            break
    return params, cost


def top_height(points: np.ndarray) -> float:
    """The height of the visible top [m]: the highest point but for the highest :data:`TOP_OUTLIERS` of them."""
    z = np.sort(points[:, 2])
    return float(z[len(z) - 1 - int(TOP_OUTLIERS * (len(z) - 1))])


def visible_top_centre(points: np.ndarray) -> np.ndarray:
    """The centre (x, y) [m] of the visible top: the mean of the points at most :data:`TOP_DEPTH` below
    :func:`top_height`."""
    top = points[points[:, 2] >= top_height(points) - TOP_DEPTH]
    return np.sum(top[:, :2], axis=0) / len(top)


def object_centre(points: np.ndarray, primitive: str, table_top: float) -> np.ndarray:
    """Where an object resting on the table stands, from the points of it that the camera sees.

    Args:
        points: The visible points of the object [m], world frame, (k, 3) with k >= 1.
        primitive: Its shape class: ``"sphere"``, ``"box"`` (a cube) or ``"cylinder"`` (as long as it is wide,
            standing or lying).
        table_top: The table top's height [m], world frame.

    Returns:
        The centre (x, y) [m] of the shape that fits the points best, resting on the table with its size and (for a
        cube or a lying cylinder) yaw fitted; with fewer than :data:`MIN_POINTS` points, the centre of the visible
        top (:func:`visible_top_centre`). An object seen only in part is placed by the part in view: where that
        part does not tell (a cube's top alone), the fit stays near the visible top's centre.
    """
    p = np.asarray(points, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) == 0 or not np.all(np.isfinite(p)):
        raise InvalidValueError(f"points must be finite points (k, 3) [m] with k >= 1, got shape {p.shape}.")
    if primitive not in PRIMITIVES:
        raise InvalidValueError(f"primitive must be one of {PRIMITIVES}, got {primitive!r}.")
    number = isinstance(table_top, int | float | np.floating) and not isinstance(table_top, bool)
    if not (number and np.isfinite(table_top)):
        raise InvalidValueError(f"table_top must be a finite height [m], got {table_top!r}.")
    top = visible_top_centre(p)
    if len(p) < MIN_POINTS:
        return top
    if len(p) > MAX_POINTS:
        p = p[np.linspace(0, len(p) - 1, MAX_POINTS).astype(np.int64)]
    size = min(max(top_height(p) - table_top, SIZE_LIMITS[0] / 2), SIZE_LIMITS[1] * 2)
    best, best_cost = None, math.inf
    for residuals, yaws in SHAPES[primitive]:
        free = 4 if len(yaws) > 1 else 3
        for yaw in yaws:
            start = np.array([top[0], top[1], size, yaw])
            params, cost = _fit(residuals, p, start, table_top, free, START_ITERATIONS)
            if cost < best_cost:
                best, best_cost = (residuals, params, free), cost
    residuals, params, free = best
    return _fit(residuals, p, params, table_top, free, ITERATIONS)[0][:2].copy()


__all__ = ["object_centre", "visible_top_centre", "TOP_DEPTH"]
