"""The paper's 49 features of one range snapshot, as a pure function of arrays (no simulator).

Akgun et al. 2009, section III.B: the object of interest is segmented in the range image (here: a mask given
by the simulator) and described by 24 shape, 18 size and 7 hand-object relation features, in the order of
:data:`FEATURE_NAMES`:

- shape: a unit normal at every object pixel of the organised point grid, oriented towards the camera;
  12-bin histograms of its latitude ``arcsin(n_z)`` and longitude ``atan2(n_y, n_x)`` in the world frame, as
  fractions.
- size: mean point and range, pixel count, orientation of the principal image axis, and the extremum points
  A, B (on the principal axis) and C, D (on the perpendicular axis) with their 3-D, range and image distances.
- relation: object minus hand, in the image (pixel centroid minus the hand's projection) and in 3-D (mean
  object point minus hand position).

Image conventions: ``u`` is the column, ``v`` the row, pixel centres at integer indices, ``v`` pointing down.

Conventions this module fixes:

- Bin edges are shifted down by :data:`EDGE_TOLERANCE_RAD` (0.57 deg), so that a normal on an edge up to
  rounding or settling falls in the bin above it: a vertical face (latitude 0) counts in ``normal_lat_06``, a
  face whose normal points along world -x (longitude +-pi) in ``normal_lon_00``. A normal within
  :data:`VERTICAL_TOLERANCE_RAD` of vertical has no meaningful longitude and counts as longitude 0
  (``normal_lon_06``). Objects resting on the table settle tilted by a few 1e-4 rad; without these
  tolerances the top of a standing cylinder (most of its pixels) would land in a longitude bin chosen by
  the direction of that tilt, and its sides would split between two latitude bins. Pixels
  without a normal (no object neighbour in a direction, or collinear neighbours) are left out, so each
  histogram sums to 1, or is all zeros when no pixel has a normal.
- A and B are the object pixels within half a pixel of the principal axis (the line through the pixel
  centroid along the major eigenvector of the (u, v) covariance) with the smallest and largest projection onto
  it; C and D likewise on the perpendicular axis. If no object pixel lies that close to an axis, the pixels
  nearest to it are used; ties go to the first pixel in row-major order. So A-B of a rectangle is its
  length, not a diagonal that flips with rounding.
- ``orientation`` is the angle of the principal axis from the +u axis towards +v, in (-pi/2, pi/2]; it is 0
  when the covariance is isotropic up to rounding (a disc, a single pixel).
- An invisible object (empty mask) gets :data:`NOT_VISIBLE_VALUES`: all zeros, which is also what its
  histograms (no normals) and pixel count are.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from affordance_env.exceptions import InvalidValueError
from affordance_env.linalg import einsum, matmul

N_FEATURES = 49
#: Bins of each normal histogram.
N_BINS = 12
#: Histogram bin edges are shifted down by this angle [rad], see the module docstring.
EDGE_TOLERANCE_RAD = 0.01
#: Normals closer than this to vertical [rad] count as longitude 0, see the module docstring.
VERTICAL_TOLERANCE_RAD = 0.01
#: Largest accepted magnitude of a coordinate or range [m]; keeps every feature finite in float32.
MAX_ABS_METRES = 1e6
#: Largest accepted magnitude of the hand's image coordinates [pixels].
MAX_ABS_PIXELS = 1e12
#: Half-width of the band around a principal axis in which the extremum points are searched [pixels].
AXIS_BAND_HALF_WIDTH_PX = 0.5
#: Tangents spanning a sine of angle below this give no normal (collinear neighbours).
_MIN_SINE_TANGENTS = 1e-6
#: The rows of the tangents, in the order that lines up each coordinate of the cross product's two products.
_CYCLIC_ROWS = np.array([1, 2, 0, 1])
#: Latitude (row 0) and longitude (row 1) [rad] are shifted by these so that the lowest bin starts at 0, less the
#: edge tolerance ...
_BIN_SHIFT = np.array([[np.pi / 2 + EDGE_TOLERANCE_RAD], [np.pi + EDGE_TOLERANCE_RAD]])
#: ... and scaled by these into bin widths.
_BIN_SCALE = np.array([[N_BINS / np.pi], [N_BINS / (2.0 * np.pi)]])
#: Relative anisotropy of the pixel covariance below which the orientation is taken as 0.
_ISOTROPY_TOLERANCE = 1e-9
#: A principal axis closer than this to -pi/2 [rad] is reported as +pi/2 (the same axis).
_ORIENTATION_WRAP_TOLERANCE_RAD = 1e-9


def _feature_table() -> tuple[tuple[str, str, str, str], ...]:
    """(name, group, unit, description) of each feature, in order."""
    lat_width, lon_width = 180 // N_BINS, 360 // N_BINS
    shape = [
        (
            f"normal_lat_{i:02d}",
            "shape",
            "fraction",
            f"share of object normals with latitude in [{-90 + lat_width * i}, {-75 + lat_width * i}) deg",
        )
        for i in range(N_BINS)
    ] + [
        (
            f"normal_lon_{i:02d}",
            "shape",
            "fraction",
            f"share of object normals with longitude in [{-180 + lon_width * i}, {-150 + lon_width * i}) deg",
        )
        for i in range(N_BINS)
    ]
    size = [
        ("mean_x", "size", "m", "mean world x of the object points"),
        ("mean_y", "size", "m", "mean world y of the object points"),
        ("mean_z", "size", "m", "mean world z of the object points"),
        ("mean_range", "size", "m", "mean distance from the camera centre along the object pixels' rays"),
        ("pixel_count", "size", "pixels", "number of object pixels"),
        ("orientation", "size", "rad", "angle of the principal image axis A-B from +u to +v, (-pi/2, pi/2]"),
    ]
    for seg in ("ab", "cd"):
        ends = seg.upper()
        size += [
            (f"{seg}_dx", "size", "m", f"|x difference| of the extremum points {ends[0]}, {ends[1]} (world)"),
            (f"{seg}_dy", "size", "m", f"|y difference| of the extremum points {ends[0]}, {ends[1]} (world)"),
            (f"{seg}_dz", "size", "m", f"|z difference| of the extremum points {ends[0]}, {ends[1]} (world)"),
            (f"{seg}_distance", "size", "m", f"3-D distance between {ends[0]} and {ends[1]}"),
            (f"{seg}_range_diff", "size", "m", f"ray distance |range_{ends[0]} - range_{ends[1]}|"),
        ]
    size += [
        ("ab_image_distance", "size", "pixels", "image distance between A and B"),
        ("cd_image_distance", "size", "pixels", "image distance between C and D"),
    ]
    relation = [
        ("hand_image_dx", "relation", "pixels", "object pixel centroid u minus hand u"),
        ("hand_image_dy", "relation", "pixels", "object pixel centroid v minus hand v"),
        ("hand_image_distance", "relation", "pixels", "image distance between object centroid and hand"),
        ("hand_dx", "relation", "m", "mean object x minus hand x (world)"),
        ("hand_dy", "relation", "m", "mean object y minus hand y (world)"),
        ("hand_dz", "relation", "m", "mean object z minus hand z (world)"),
        ("hand_distance", "relation", "m", "3-D distance between mean object point and hand"),
    ]
    return tuple(shape + size + relation)


_TABLE = _feature_table()
FEATURE_NAMES: tuple[str, ...] = tuple(row[0] for row in _TABLE)
#: Group of each feature: "shape", "size" or "relation".
FEATURE_GROUPS: dict[str, str] = {row[0]: row[1] for row in _TABLE}
FEATURE_UNITS: dict[str, str] = {row[0]: row[2] for row in _TABLE}
FEATURE_DESCRIPTIONS: dict[str, str] = {row[0]: row[3] for row in _TABLE}
#: Features of an object that is not visible (empty mask): all zeros. Read-only.
NOT_VISIBLE_VALUES: np.ndarray = np.zeros(N_FEATURES, dtype=np.float32)
NOT_VISIBLE_VALUES.flags.writeable = False


@dataclass(frozen=True)
class Features:
    """The features of one snapshot.

    Attributes:
        values: The 49 features in the order of :data:`FEATURE_NAMES`, (49,) float32, made read-only; units
            in :data:`FEATURE_UNITS`.
        visible: Whether the object had at least one pixel; if not, ``values`` is :data:`NOT_VISIBLE_VALUES`.
        n_pixels: Number of object pixels [pixels].
    """

    values: np.ndarray
    visible: bool
    n_pixels: int

    def __post_init__(self) -> None:
        if self.values.shape != (N_FEATURES,) or self.values.dtype != np.float32:
            raise InvalidValueError(
                f"Features.values must be a ({N_FEATURES},) float32 array, "
                f"got shape {self.values.shape} and dtype {self.values.dtype}."
            )
        self.values.flags.writeable = False

    def as_dict(self) -> dict[str, float]:
        """Feature name -> value."""
        return dict(zip(FEATURE_NAMES, self.values.tolist(), strict=True))


def compute_features(
    p_world_points: np.ndarray,
    ranges: np.ndarray,
    mask: np.ndarray,
    p_world_camera: np.ndarray,
    p_world_hand: np.ndarray,
    uv_hand: np.ndarray,
) -> Features:
    """The 49 features of the masked object in one range snapshot of H x W pixels.

    Args:
        p_world_points: Point hit by each pixel's ray in the world frame [m], (H, W, 3); anything (NaN, inf)
            where ``mask`` is False, finite where it is True.
        ranges: Distance from the camera centre along each ray [m], (H, W); anything off the mask.
        mask: Object pixels, (H, W) bool.
        p_world_camera: Camera centre in the world frame [m], (3,); normals are turned to face it.
        p_world_hand: Hand position in the world frame [m], (3,).
        uv_hand: Hand projected in the image (u = column, v = row) [pixels], (2,); may lie outside the image
            but must be finite (a hand behind the camera has no projection: the caller decides what to pass).

    Returns:
        The features; :data:`NOT_VISIBLE_VALUES` with ``visible=False`` if the mask is empty.

    Raises:
        ValueError: If an argument has the wrong shape or dtype, or a value that must be finite is not.
    """
    points, ranges, mask, p_world_camera, p_world_hand, uv_hand = _validated(
        p_world_points, ranges, mask, p_world_camera, p_world_hand, uv_hand
    )
    # object pixels, row-major, in the full image. Here and below, array methods and ufunc reductions stand for
    # np.flatnonzero, np.take, np.stack, .sum(), .min(), .max(): the same operations without their Python layers.
    image_index = mask.ravel().nonzero()[0]
    if image_index.size == 0:
        return Features(NOT_VISIBLE_VALUES.copy(), visible=False, n_pixels=0)
    # (3, k), gathered along the pixel axis (contiguous when the camera hands out its (3, n) points transposed)
    p_world_obj = np.ascontiguousarray(points.reshape(-1, 3).T.take(image_index, axis=1), dtype=np.float64)
    return _object_features(image_index, mask.shape[1], p_world_obj, ranges.reshape(-1).take(image_index),
                            p_world_camera, p_world_hand, uv_hand)


def object_features(
    image_index: np.ndarray,
    width: int,
    p_world_obj: np.ndarray,
    range_obj: np.ndarray,
    p_world_camera: np.ndarray,
    p_world_hand: np.ndarray,
    uv_hand: np.ndarray,
) -> Features:
    """:func:`compute_features` from the object's pixels alone: their flat indices in an image ``width`` pixels
    wide (``np.flatnonzero(mask)``, increasing), their points ((3, k) [m], world frame) and their ranges ((k,) [m]);
    the same features, bit for bit, without the rest of the image. The other arguments as there."""
    p_world_camera = _finite_vector("p_world_camera", p_world_camera, 3, MAX_ABS_METRES, "m")
    p_world_hand = _finite_vector("p_world_hand", p_world_hand, 3, MAX_ABS_METRES, "m")
    uv_hand = _finite_vector("uv_hand", uv_hand, 2, MAX_ABS_PIXELS, "pixels")
    image_index = np.asarray(image_index)
    if image_index.size == 0:
        return Features(NOT_VISIBLE_VALUES.copy(), visible=False, n_pixels=0)
    p_world_obj = np.ascontiguousarray(p_world_obj, dtype=np.float64)
    if p_world_obj.shape != (3, image_index.size) or np.shape(range_obj) != (image_index.size,):
        raise InvalidValueError(f"p_world_obj must be (3, k) and range_obj (k,) for k = {image_index.size} pixels, got "
                                f"shapes {p_world_obj.shape} and {np.shape(range_obj)}.")
    return _object_features(image_index, int(width), p_world_obj, np.asarray(range_obj), p_world_camera,
                            p_world_hand, uv_hand)


def _object_features(image_index: np.ndarray, width: int, p_world_obj: np.ndarray, range_obj: np.ndarray,
                     p_world_camera: np.ndarray, p_world_hand: np.ndarray, uv_hand: np.ndarray) -> Features:
    """The features of the object's pixels (flat indices, increasing), points (3, k) float64, contiguous, and
    ranges (k,), the other arguments checked."""
    v_obj, u_obj = np.divmod(image_index, width)
    # Bounding box of the object, padded by one non-object pixel so that every neighbour index exists: the
    # object's pixels in that padded crop, row-major (the full image's order), found from their rows and columns
    # instead of by copying the crop and searching it again.
    r0, c0, c1 = int(v_obj[0]), int(np.minimum.reduce(u_obj)), int(np.maximum.reduce(u_obj)) + 1
    grid_shape = (int(v_obj[-1]) + 1 - r0 + 2, c1 - c0 + 2)
    pixel_index = (v_obj - (r0 - 1)) * grid_shape[1] + (u_obj - (c0 - 1))
    range_obj = range_obj.astype(np.float64)
    _check_on_mask(p_world_obj, range_obj)
    uv_obj = np.array((u_obj, v_obj), dtype=np.float64)

    n_obj = int(image_index.size)
    uv_centroid = np.add.reduce(uv_obj, axis=1) / n_obj
    p_world_mean = np.add.reduce(p_world_obj, axis=1) / n_obj
    d_uv = (uv_centroid - uv_hand).tolist()
    d_world = (p_world_mean - p_world_hand).tolist()
    values = np.empty(N_FEATURES, dtype=np.float32)
    values[0:24] = _normal_histograms(p_world_obj, pixel_index, grid_shape, p_world_camera)
    values[24:42] = _size_features(p_world_obj, range_obj, uv_obj, uv_centroid, p_world_mean)
    values[42:49] = [*d_uv, math.hypot(*d_uv), *d_world, math.hypot(*d_world)]
    return Features(values, visible=True, n_pixels=n_obj)


#: Index of ``orientation``, an axis angle: its effect is wrapped (see :func:`effect_features`).
ORIENTATION_INDEX = FEATURE_NAMES.index("orientation")


def wrap_axis_angle(angle: np.ndarray | float) -> np.ndarray:
    """An angle between two undirected axes [rad], wrapped into (-pi/2, pi/2]: the smallest turn between them."""
    angle = np.asarray(angle, dtype=np.float64)
    return angle - np.pi * np.ceil((angle - np.pi / 2) / np.pi)


def effect_features(initial: np.ndarray, final: np.ndarray) -> np.ndarray:
    """The effect of an interaction: ``final - initial`` features, (49,) float32 (or (n, 49) for rows).

    Every feature is a plain difference except ``orientation``, the angle of an undirected image axis in
    (-pi/2, pi/2]: its difference is wrapped into (-pi/2, pi/2], so that an object turning by a degree across the
    wrap reads as a degree, not as about pi.
    """
    initial = np.asarray(initial, dtype=np.float64)
    final = np.asarray(final, dtype=np.float64)
    if initial.shape != final.shape or initial.shape[-1:] != (N_FEATURES,):
        raise InvalidValueError(f"initial and final must both be (..., {N_FEATURES}) feature arrays, got shapes "
                         f"{initial.shape} and {final.shape}.")
    effect = final - initial
    effect[..., ORIENTATION_INDEX] = wrap_axis_angle(effect[..., ORIENTATION_INDEX])
    return effect.astype(np.float32)


def _normal_histograms(
    p_world_obj: np.ndarray, pixel_index: np.ndarray, grid_shape: tuple[int, int], p_world_camera: np.ndarray
) -> np.ndarray:
    """Latitude then longitude histograms (2 x 12 fractions) of the object normals.

    Args:
        p_world_obj: Object points in the world frame [m], (3, k).
        pixel_index: Their flat (row-major) pixel indices in a grid of ``grid_shape`` whose border pixels are
            not object pixels, (k,) increasing.
        grid_shape: (rows, columns) of that grid.
        p_world_camera: Camera centre in the world frame [m], (3,).

    The tangents at a pixel are central differences to its right/left and down/up neighbours when both are
    object pixels, one-sided differences when only one is; a pixel without a tangent in either direction (a
    zero tangent), or with parallel tangents, has no normal. Normals are turned to face the camera.
    """
    own = np.arange(pixel_index.size)
    slot = np.full(grid_shape[0] * grid_shape[1], -1, dtype=np.intp)  # grid pixel -> object point, or -1
    slot[pixel_index] = own
    width = grid_shape[1]
    # The right, down, left and up neighbours of every pixel at once, (4, k); a missing neighbour is replaced by
    # the pixel itself: central or one-sided difference, or zero.
    neighbour = slot.take(pixel_index + np.array([[1], [width], [-1], [-width]]))  # take: slot[...], faster
    neighbour = np.where(neighbour >= 0, neighbour, own)
    # (3, 4, k) points of the neighbours; differences (3, 2, k): [:, 0] the tangent along u (right - left),
    # [:, 1] along v (down - up). The same subtractions of the same points as one tangent at a time.
    gathered = p_world_obj.take(neighbour, axis=1)
    tangents = gathered[:, :2] - gathered[:, 2:]
    # The cross product t_u x t_v, row i = t_u[i+1] t_v[i+2] - t_u[i+2] t_v[i+1] (indices mod 3): the rows of
    # ``cyclic`` are those of ``tangents`` in the order 1, 2, 0, 1, so that cyclic[i] is index i+1, cyclic[i+1]
    # index i+2 (views, one copy); the same products and differences as n_x, n_y, n_z written out.
    cyclic = tangents.take(_CYCLIC_ROWS, axis=0)
    first, second = cyclic[:3], cyclic[1:]
    normal = first[:, 0] * second[:, 1] - second[:, 0] * first[:, 1]  # (3, k)
    # Per pixel, n . n (its squared length) and n . (camera - point) (>= 0: it faces the camera), each as
    # x + y, then + z, like ``n_x * n_x + n_y * n_y + n_z * n_z``: both summed from one (2, 3, k) array.
    products = np.empty((2, 3, normal.shape[1]))
    np.multiply(normal, normal, out=products[0])
    np.multiply(normal, p_world_camera[:, None] - p_world_obj, out=products[1])
    sums = products[:, 0] + products[:, 1]
    sums += products[:, 2]
    n_sq = sums[0]
    # |t_u|^2 and |t_v|^2 by one einsum over both: the same sums as einsum("ij,ij->j") of each
    lengths_sq = einsum("ijk,ijk->jk", tangents, tangents)  # np.einsum, without its Python layer
    ok = n_sq > _MIN_SINE_TANGENTS**2 * (lengths_sq[0] * lengths_sq[1])
    n_normals = int(np.count_nonzero(ok))
    if n_normals == 0:
        return np.zeros(2 * N_BINS)
    if n_normals < n_sq.size:  # pixels without a normal are left out
        normal, sums = normal[:, ok], sums[:, ok]
    n_sq, toward = sums
    normal *= np.where(toward >= 0.0, 1.0, -1.0) / np.sqrt(n_sq)  # unit normals, turned to face the camera
    n_x, n_y, n_z = normal

    # Bin of an angle: floor((angle - lowest edge + tolerance) / bin width); the top latitude edge (pi/2) is
    # closed, and longitude bin 12 (just below +pi, within the tolerance) wraps round to bin 0. Latitude (row 0)
    # and longitude (row 1) are shifted, scaled and floored together, each by its own constants.
    angles = np.empty((2, n_normals))
    np.arcsin(np.minimum(np.maximum(n_z, -1.0), 1.0), out=angles[0])  # np.clip to [-1, 1] without its layers
    np.arctan2(n_y, n_x, out=angles[1])
    squares = normal[:2] * normal[:2]
    angles[1][squares[0] + squares[1] < math.sin(VERTICAL_TOLERANCE_RAD) ** 2] = 0.0  # vertical: longitude 0
    angles += _BIN_SHIFT
    angles *= _BIN_SCALE
    bins = angles.astype(np.intp)
    np.minimum(bins[0], N_BINS - 1, out=bins[0])
    bins[1][bins[1] >= N_BINS] = 0
    bins[1] += N_BINS  # the longitude histogram follows the latitude one
    return np.bincount(bins.ravel(), minlength=2 * N_BINS) / n_normals


def _size_features(
    p_world_obj: np.ndarray,
    range_obj: np.ndarray,
    uv_obj: np.ndarray,
    uv_centroid: np.ndarray,
    p_world_mean: np.ndarray,
) -> list[float]:
    """The 18 size features from the object points (3, k) [m], ranges (k,) [m] and pixels (2, k) [pixels]."""
    duv = uv_obj - uv_centroid[:, None]
    scatter = matmul(duv, duv.T)  # k times the covariance [pixels^2]; the angle does not depend on the scale
    (c_uu, c_uv), (_, c_vv) = scatter.tolist()
    if math.hypot(c_uu - c_vv, 2.0 * c_uv) <= _ISOTROPY_TOLERANCE * (c_uu + c_vv):
        theta = 0.0
    else:
        theta = 0.5 * math.atan2(2.0 * c_uv, c_uu - c_vv)
    if theta <= -math.pi / 2 + _ORIENTATION_WRAP_TOLERANCE_RAD:  # same axis: report +pi/2, never -pi/2
        theta = math.pi / 2
    cos_t, sin_t = math.cos(theta), math.sin(theta)
    # Each pixel's coordinates along (row 0) and across (row 1) the principal axis [pixels]:
    # along = du cos + dv sin, across = dv cos - du sin, in two products and one sum over both rows
    # (dv cos + du (-sin) is dv cos - du sin exactly: negation is exact, and x + (-y) is x - y).
    axes = duv * cos_t
    axes += duv[::-1] * np.array([[sin_t], [-sin_t]])
    distance = np.abs(axes)  # |along|, |across|
    nearest = np.minimum.reduce(distance, axis=1).tolist()
    i_a, i_b = _extremes_on_axis(axes[0], distance[1], nearest[1])
    i_c, i_d = _extremes_on_axis(axes[1], distance[0], nearest[0])

    out = [*p_world_mean.tolist(), float(np.add.reduce(range_obj)) / range_obj.size, float(range_obj.size), theta]
    # The four extremum points, ranges and pixels as Python floats: the differences and absolute values below are
    # the same IEEE operations as numpy's on these float64 values, without an array call for each.
    ends = [i_a, i_b, i_c, i_d]
    points, end_ranges, pixels = p_world_obj[:, ends].T.tolist(), range_obj[ends].tolist(), uv_obj[:, ends].T.tolist()
    for i, j in ((0, 1), (2, 3)):
        d_world = [abs(a - b) for a, b in zip(points[i], points[j], strict=True)]
        out += [*d_world, math.hypot(*d_world), abs(end_ranges[i] - end_ranges[j])]
    for i, j in ((0, 1), (2, 3)):
        out.append(math.hypot(*(a - b for a, b in zip(pixels[i], pixels[j], strict=True))))
    return out


def _extremes_on_axis(along: np.ndarray, distance: np.ndarray, nearest: float) -> tuple[int, int]:
    """Indices of the pixels with the smallest and largest ``along`` among those nearest the axis.

    ``along`` are the pixels' coordinates along the axis and ``distance`` their distances from it [pixels]
    (``nearest`` the smallest); the candidates are the pixels within :data:`AXIS_BAND_HALF_WIDTH_PX` of the
    axis, or the nearest ones if there are none.
    """
    band = (distance <= max(AXIS_BAND_HALF_WIDTH_PX, nearest) + 1e-9).nonzero()[0]
    along_band = along.take(band)  # along[band]
    return int(band[np.argmin(along_band)]), int(band[np.argmax(along_band)])


def _validated(
    p_world_points: np.ndarray,
    ranges: np.ndarray,
    mask: np.ndarray,
    p_world_camera: np.ndarray,
    p_world_hand: np.ndarray,
    uv_hand: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The arguments of :func:`compute_features` as arrays, after checking shapes, dtypes and finiteness."""
    points = _real_array("p_world_points", p_world_points)
    if points.ndim != 3 or points.shape[2] != 3:
        raise InvalidValueError(f"p_world_points must have shape (H, W, 3), got shape {points.shape}.")
    grid = points.shape[:2]
    ranges_arr = _real_array("ranges", ranges)
    if ranges_arr.shape != grid:
        raise InvalidValueError(
            f"ranges must have shape (H, W) = {grid} like p_world_points, got shape {ranges_arr.shape}."
        )
    mask_arr = np.asarray(mask)
    if mask_arr.dtype != np.bool_:
        raise InvalidValueError(f"mask must be a boolean array (dtype bool), got dtype {mask_arr.dtype}.")
    if mask_arr.shape != grid:
        raise InvalidValueError(
            f"mask must have shape (H, W) = {grid} like p_world_points, got shape {mask_arr.shape}."
        )
    camera = _finite_vector("p_world_camera", p_world_camera, 3, MAX_ABS_METRES, "m")
    hand = _finite_vector("p_world_hand", p_world_hand, 3, MAX_ABS_METRES, "m")
    uv = _finite_vector("uv_hand", uv_hand, 2, MAX_ABS_PIXELS, "pixels")
    return points, ranges_arr, mask_arr, camera, hand, uv


def _real_array(name: str, value: np.ndarray) -> np.ndarray:
    """``value`` as an array of a real dtype (integer or floating, not bool), else a ValueError naming it."""
    arr = np.asarray(value)
    # np.issubdtype(dtype, np.floating or np.integer), without its Python layers
    real = issubclass(arr.dtype.type, np.floating | np.integer)
    if arr.dtype.type is np.bool_ or not real:
        raise InvalidValueError(f"{name} must have a real floating or integer dtype, got dtype {arr.dtype}.")
    return arr


def _finite_vector(name: str, value: np.ndarray, size: int, max_abs: float, unit: str) -> np.ndarray:
    """``value`` as a float (size,) vector with entries finite and within +-``max_abs``, else ValueError."""
    vec = np.asarray(_real_array(name, value), dtype=np.float64)  # no copy of a float64 vector: only read
    if vec.shape != (size,):
        raise InvalidValueError(f"{name} must have shape ({size},), got shape {vec.shape}.")
    if not all(abs(x) <= max_abs for x in vec.tolist()):  # NaN fails the comparison as in numpy
        raise InvalidValueError(f"{name} must be finite and within +-{max_abs:g} {unit}, got {vec.tolist()}.")
    return vec


def _check_on_mask(p_world_obj: np.ndarray, range_obj: np.ndarray) -> None:
    """Raise ValueError unless object points (3, k) and ranges (k,) [m] are finite, bounded, ranges >= 0."""
    # The usual case in two reductions each: a NaN makes the maximum (minimum) NaN, which fails the comparison,
    # so any bad value goes on to the pixel-by-pixel checks below, which name it.
    if (np.maximum.reduce(np.abs(p_world_obj), axis=None) <= MAX_ABS_METRES
            and np.minimum.reduce(range_obj) >= 0.0 and np.maximum.reduce(range_obj) <= MAX_ABS_METRES):
        return
    bad_points = ~(np.abs(p_world_obj) <= MAX_ABS_METRES).all(axis=0)
    if bad_points.any():
        raise InvalidValueError(
            f"p_world_points must be finite and within +-{MAX_ABS_METRES:g} m wherever mask is True, got "
            f"{int(bad_points.sum())} object pixels that are not, "
            f"e.g. {p_world_obj[:, np.argmax(bad_points)].tolist()}."
        )
    bad_ranges = ~((range_obj >= 0.0) & (range_obj <= MAX_ABS_METRES))
    if bad_ranges.any():
        raise InvalidValueError(
            f"ranges must be finite and within [0, {MAX_ABS_METRES:g}] m wherever mask is True, got "
            f"{int(bad_ranges.sum())} object pixels that are not, e.g. {range_obj[bad_ranges][0]!r}."
        )
