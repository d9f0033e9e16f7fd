"""Camera-specific checks of the shadow cameras against known scene geometry.

The dual-coordinate RMSE itself is ``lab.accuracy.dual_coord_errors`` (also for the
cross-slit camera, against its exact pair of times). Here:

* straightness (paper V, Fig. 14, 15): straight scene edges seen through a mirror or glass are
  bent in the primal view; the dual view from the estimated (u, v) straightens them. Measured
  on the same exact edge points: their camera positions (primal) and the estimated (u, v)
  interpolated at those positions (dual), each by ``cameras.straightness.edge_straightness``.
* parallelism (orthographic camera, IV, Fig. 7): parallel scene edges at different depths
  stay parallel in an orthographic view (the spread of the directions of their fitted lines)
  and equal objects keep their size whatever their depth (the magnification, dual px per
  scene unit across a family of parallel edges, of its nearer over its farther half).
* redundancy: the dual-coordinate RMSE of the linear camera from all sweeps over that from
  two of them.
* sweep geometry (virtual intrinsics, Fig. 12): the slant and speed of every sweep beyond the
  first two, measured from the shadow times alone (their affine relation to the first two
  sweeps' times, mapped to dual coordinates with the first two sweeps' declared geometry),
  against the declared ``angle_deg`` and ``speed``.

Offers
------
sample_coordinates : estimated (u, v) maps read at sub-pixel camera positions (bilinear).
straightness_primal_dual : straightness of edges in the primal view and in the estimated dual view.
line_direction_spread : spread (deg) of the directions of the lines fitted to labelled point sets.
parallel_edges : parallelism and size ratio at two depths of parallel straight edges in a view.
PARALLEL_TARGETS : tolerances of the orthographic view's parallelism (deg) and size ratio.
parallelism_check : the orthographic check on the ground truth's straight edges, with targets.
redundancy_gain : RMSE ratio of the linear camera from a subset of sweeps over all sweeps.
SWEEP_GEOMETRY_TARGETS : tolerances of the measured sweep slant (deg) and speed (relative).
sweep_geometry_errors : measured slant and speed of the extra sweeps against their declaration.
sweep_geometry_targets : target rows (value, threshold, pass) of those errors.
camera_grid_map : map from the ground truth's dual grid to a camera model's grid.
linear_redundancy : dual RMSE of the linear camera from all sweeps and from two, same pixels.
DUAL_STRAIGHTNESS_TARGET : largest RMS deviation (dual px) of straight edges in the dual view.
straightness_check : straightness of the ground truth's edges seen through optics, with its target.
add_camera_checks : the camera-specific checks of a capture added to its accuracy report.
"""

import math

import numpy as np

from shadowcam._shared.validation import check_array, check_same_shape
from shadowcam.cameras.models import sweep_rows
from shadowcam.cameras.straightness import edge_straightness


def sample_coordinates(u, v, camera_xy):
    """Bilinear read of coordinate maps at camera positions; NaN unless all four neighbours
    are finite (a hole stays a hole).

    Parameters
    ----------
    u, v : (rows, cols) ndarray
        Coordinate maps (NaN = none).
    camera_xy : (N, 2) ndarray
        Camera (col, row) pixel-centre indices.

    Returns
    -------
    (N, 2) float64 ndarray
        ``(u, v)`` per position.
    """
    u = check_array(np.asarray(u, dtype=np.float64), "u", ndim=2)
    v = np.asarray(v, dtype=np.float64)
    check_same_shape({"u": u, "v": v})
    xy = check_array(np.asarray(camera_xy, dtype=np.float64), "camera_xy", shape=(None, 2))
    rows, cols = u.shape
    x, y = xy[:, 0], xy[:, 1]
    inside = (x >= 0) & (x <= cols - 1) & (y >= 0) & (y <= rows - 1)
    c0 = np.clip(np.floor(np.nan_to_num(x)), 0, max(cols - 2, 0)).astype(int)
    r0 = np.clip(np.floor(np.nan_to_num(y)), 0, max(rows - 2, 0)).astype(int)
    fx, fy = x - c0, y - r0
    out = []
    for m in (u, v):
        value = ((1 - fx) * (1 - fy) * m[r0, c0] + fx * (1 - fy) * m[r0, c0 + 1]
                 + (1 - fx) * fy * m[r0 + 1, c0] + fx * fy * m[r0 + 1, c0 + 1])
        out.append(np.where(inside, value, np.nan))
    out = np.stack(out, axis=1)
    out[~np.all(np.isfinite(out), axis=1)] = np.nan  # a point lacking either coordinate has none
    return out


def straightness_primal_dual(u, v, camera_xy, labels, *, min_points=5):
    """Straightness of straight scene edges in the primal view and in the estimated dual view.

    Parameters
    ----------
    u, v : (rows, cols) ndarray
        Estimated dual coordinates.
    camera_xy : (N, 2) ndarray
        Camera (col, row) positions of exact edge points (e.g. ``synthetic.lab.edges``).
    labels : (N,) int ndarray
        Edge label of each point.
    min_points : int
        Edges with fewer points (with dual coordinates) are not measured.

    Returns
    -------
    dict
        ``primal_rms``, ``dual_rms`` (pixels, pooled over the edges both measure),
        ``n_edges``, ``n_points``.
    """
    labels = np.asarray(labels)
    xy = np.asarray(camera_xy, dtype=np.float64)
    if labels.shape != (len(xy),):
        raise ValueError(f"labels must have shape ({len(xy)},); got {labels.shape}")
    uv = sample_coordinates(u, v, xy)
    keep = np.all(np.isfinite(uv), axis=1) & np.all(np.isfinite(xy), axis=1)
    counts = np.bincount(np.unique(labels[keep], return_inverse=True)[1]) if keep.any() else []
    kept_labels = np.unique(labels[keep])[np.asarray(counts) >= int(min_points)] if keep.any() else []
    keep &= np.isin(labels, kept_labels)
    if not keep.any():
        raise ValueError("camera_xy: no edge has enough points with dual coordinates")
    primal = edge_straightness(xy[keep], labels=labels[keep].astype(np.int64), min_points=min_points)
    dual = edge_straightness(uv[keep], labels=labels[keep].astype(np.int64), min_points=min_points)
    return {"primal_rms": primal.overall_rms, "dual_rms": dual.overall_rms,
            "n_edges": int(len(kept_labels)), "n_points": int(keep.sum())}


def line_direction_spread(points, labels, *, min_points=3):
    """Spread (max - min, degrees) of the directions of lines fitted to labelled point sets.

    Parameters
    ----------
    points : (N, 2) ndarray
        2-D points (camera or dual coordinates), finite.
    labels : (N,) int ndarray
        Set of each point; each set lies on one straight scene edge.
    min_points : int

    Returns
    -------
    float
        0 for parallel lines; directions are compared modulo 180 deg around their mean.
    """
    points = check_array(np.asarray(points, dtype=np.float64), "points", shape=(None, 2))
    labels = np.asarray(labels)
    angles = []
    for label in np.unique(labels):
        pts = points[labels == label]
        if len(pts) < int(min_points):
            continue
        _, _, vt = np.linalg.svd(pts - pts.mean(axis=0), full_matrices=False)
        angles.append(math.atan2(vt[0, 1], vt[0, 0]))
    if len(angles) < 2:
        raise ValueError("labels: at least two edges with min_points points are needed")
    return _angle_spread(angles)


def _angle_spread(angles):
    """Spread (max - min, degrees) of line angles (radians), modulo 180 deg around their mean."""
    doubled = np.exp(2j * np.array(angles))  # directions modulo 180 deg
    mean = np.angle(doubled.mean())
    offsets = np.angle(doubled * np.exp(-1j * mean)) / 2
    return float(np.degrees(offsets.max() - offsets.min()))


def _fit_line(points):
    """Centroid and unit direction (first principal axis) of (n, d) points."""
    centre = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - centre, full_matrices=False)
    return centre, vt[0]


def _robust_line(points, *, k=4.0, floor=1e-3):
    """:func:`_fit_line` of the 2-D points within k robust sigmas (1.4826 MAD, at least
    `floor`) of a first fit: drops points read across a silhouette. Returns the centre, the
    direction and the direction's standard error (radians): RMS residual across the line
    (``n - 2`` degrees of freedom) over the root sum of squares of the positions along it
    (NaN with fewer than three inliers)."""
    centre, direction = _fit_line(points)
    normal = np.array([-direction[1], direction[0]])
    distance = np.abs((points - centre) @ normal)
    inlier = distance <= max(k * 1.4826 * np.median(distance), floor)
    if inlier.sum() >= 2:
        centre, direction = _fit_line(points[inlier])
    rel = points[inlier] - centre
    normal = np.array([-direction[1], direction[0]])
    n = len(rel)
    se = (math.sqrt(np.sum((rel @ normal) ** 2) / (n - 2) / np.sum((rel @ direction) ** 2))
          if n >= 3 else float("nan"))
    return centre, direction, se


def _two_depth_groups(depth):
    """Near mask of the split of `depth` into two groups of at least two with the least
    within-group sum of squares (two-means in one dimension): the gap between two depth
    layers, or about the middle of a continuous range of depths."""
    order = np.sort(depth)
    costs = [np.var(order[:i]) * i + np.var(order[i:]) * (len(order) - i)
             for i in range(2, len(order) - 1)]
    return depth <= order[1 + int(np.argmin(costs))]


def parallel_edges(points, world, labels, *, toward_light, light_position=None, min_points=5):
    """Parallelism and size ratio at two depths of parallel straight scene edges in a view.

    Edges are grouped into families of parallel world lines (world directions within
    0.5 deg). Each edge's line in the view is fitted to its points within 4 robust sigmas
    of a first fit (points read across a silhouette are dropped), with the standard error
    of its direction from the residuals across it. Per family of two or
    more edges: the spread of the directions of those lines (as
    :func:`line_direction_spread`). For the family whose edges span the widest
    range of depths (along `toward_light`), with four or more edges: its edges are split
    into a near and a far group by depth (two-means: two depth layers are separated at their
    gap, a continuous range about its middle); in each group the view position of an edge
    across the family's direction is fitted linearly against its world position across it
    (the magnification, view px per scene unit); ``size_ratio`` is near over far. An
    orthographic view has spread 0 and size ratio 1; a perspective view from the light
    magnifies near edges more (ratio about the depth ratio far / near).

    Parameters
    ----------
    points : (N, 2) ndarray
        View positions of the edge points (e.g. dual (u, v)); NaN rows are dropped.
    world : (N, 3) ndarray
        World positions of the same points (exact, on straight edges).
    labels : (N,) int ndarray
        Edge of each point (one straight world line per label).
    toward_light : (3,) array_like
        Direction from the scene toward the light (depth = distance against it).
    light_position : (3,) array_like, optional
        A point light's position, for ``depth_ratio`` (None: a distant light, no ratio).
    min_points : int
        Edges with fewer points are not used.

    Returns
    -------
    dict
        ``spread_deg`` (largest over the families), ``spread_se_deg`` (standard error of
        the difference of two of that family's directions, from the two largest of its
        edges' direction errors), ``n_edges``, ``n_families``,
        ``size_ratio``, ``depth_ratio`` (mean distance to `light_position` of the far half
        over the near half; None for a distant light) and ``size_edges`` (edges of the
        measured family); these three None without a family of four edges.
    """
    points = check_array(np.asarray(points, dtype=np.float64), "points", shape=(None, 2))
    world = check_array(np.asarray(world, dtype=np.float64), "world", shape=(len(points), 3))
    labels = np.asarray(labels)
    if labels.shape != (len(points),):
        raise ValueError(f"labels: expected shape ({len(points)},), got {labels.shape}")
    axis = np.asarray(toward_light, dtype=np.float64)
    if axis.shape != (3,) or not np.all(np.isfinite(axis)) or not np.linalg.norm(axis) > 0:
        raise ValueError(f"toward_light: expected a non-zero 3-vector, got {toward_light!r}")
    axis = axis / np.linalg.norm(axis)
    keep = np.all(np.isfinite(points), axis=1) & np.all(np.isfinite(world), axis=1)
    edges = []  # (label, view centre, view direction, its standard error, world centre, world direction)
    for label in np.unique(labels[keep]):
        sel = keep & (labels == label)
        if sel.sum() >= int(min_points):
            edges.append((label, *_robust_line(points[sel]), *_fit_line(world[sel])))
    if len(edges) < 2:
        raise ValueError("labels: at least two edges with min_points points are needed")
    families = []
    for edge in edges:
        home = next((f for f in families if abs(f[0][5] @ edge[5]) > math.cos(math.radians(0.5))),
                    None)
        if home is None:
            families.append([edge])
        else:
            home.append(edge)
    pairs = [f for f in families if len(f) >= 2]
    spreads = [_angle_spread([math.atan2(e[2][1], e[2][0]) for e in f]) for f in pairs]
    if not spreads:
        raise ValueError("labels: no two edges are parallel in the world")
    se = np.sort([e[3] for e in pairs[int(np.argmax(spreads))]])[-2:]
    out = {"spread_deg": float(max(spreads)),
           "spread_se_deg": float(np.degrees(np.sqrt(np.sum(se**2)))), "n_edges": len(edges),
           "n_families": len(spreads), "size_ratio": None, "depth_ratio": None,
           "size_edges": None}
    wide = [f for f in families if len(f) >= 4]
    if not wide:
        return out
    depth_of = lambda f: np.array([-(e[4] @ axis) for e in f])  # noqa: E731
    family = max(wide, key=lambda f: np.ptp(depth_of(f)))
    depth = depth_of(family)
    direction = family[0][5]
    across = family[-1][4] - family[0][4]
    across -= (across @ direction) * direction
    across /= np.linalg.norm(across)
    mean_dir = _fit_line(np.array([e[2] * np.sign(e[2] @ family[0][2]) for e in family]
                                  + [-e[2] * np.sign(e[2] @ family[0][2]) for e in family]))[1]
    normal = np.array([-mean_dir[1], mean_dir[0]])
    w = np.array([e[4] @ across for e in family])
    p = np.array([e[1] @ normal for e in family])
    near = _two_depth_groups(depth)
    if near.sum() < 2 or (~near).sum() < 2:
        return out
    slope = [abs(np.polyfit(w[half], p[half], 1)[0]) for half in (near, ~near)]
    ratio = None
    if light_position is not None:
        dist = np.linalg.norm(np.array([e[4] for e in family])
                              - np.asarray(light_position, dtype=np.float64), axis=1)
        ratio = float(dist[~near].mean() / dist[near].mean())
    out.update(size_ratio=float(slope[0] / slope[1]), depth_ratio=ratio,
               size_edges=len(family))
    return out


def redundancy_gain(errors_subset, errors_all):
    """Ratio of the dual-coordinate RMSE from a subset of sweeps to that from all sweeps.

    Parameters
    ----------
    errors_subset, errors_all : dict
        ``lab.accuracy.dual_coord_errors`` results, evaluated on the same truth.

    Returns
    -------
    float
        > 1 when the extra sweeps lower the error.
    """
    return float(errors_subset["rmse"] / errors_all["rmse"])


#: tolerances of the sweep-geometry check: slant error (deg) and relative speed error
SWEEP_GEOMETRY_TARGETS = {"angle_error_deg": 0.5, "speed_rel_error": 0.01}


def _trimmed_affine(t, t_a, t_b, *, min_points, rounds=3, k=4.0):
    """Least-squares ``t = alpha t_a + beta t_b + c`` on finite pixels, dropping residuals
    beyond `k` robust sigmas (1.4826 MAD) in each round."""
    ok = np.isfinite(t) & np.isfinite(t_a) & np.isfinite(t_b)
    if ok.sum() < min_points:
        return None, int(ok.sum())
    design = np.column_stack([t_a[ok], t_b[ok], np.ones(int(ok.sum()))])
    target = t[ok]
    keep = np.ones(len(target), dtype=bool)
    for _ in range(rounds):
        coef, *_ = np.linalg.lstsq(design[keep], target[keep], rcond=None)
        residual = design @ coef - target
        sigma = 1.4826 * np.median(np.abs(residual[keep])) + 1e-12
        new = np.abs(residual) <= k * sigma
        if new.sum() < min_points or np.array_equal(new, keep):
            break
        keep = new
    return coef, int(keep.sum())


def sweep_geometry_errors(times, sweeps, *, dual_shape, min_points=50):
    """Measured slant and speed of every sweep beyond the first two, against the declaration.

    The first two sweeps define the dual coordinates (their declared rows
    ``t = a u + b v + c``, :func:`shadowcam.cameras.models.sweep_rows`); a further sweep's
    times are fitted as ``t_k = alpha t_1 + beta t_2 + c`` (trimmed least squares), which in
    dual coordinates is the row ``(a_k, b_k) = (alpha, beta) M`` with ``M`` the first two
    rows; slant ``atan2(b_k, a_k)`` and speed ``1 / hypot(a_k, b_k)``.

    Parameters
    ----------
    times : mapping of str to (rows, cols) ndarray
        Measured shadow times per sweep (frames, NaN = none).
    sweeps : list of dict
        :func:`shadowcam.cameras.models.declared_sweeps` with ``frames``; at least three.
    dual_shape : (int, int)
        ``(N_v, N_u)`` of the dual grid.
    min_points : int
        Pixels timed in all three sweeps needed for a fit.

    Returns
    -------
    dict
        Per extra sweep: ``angle_deg`` (declared), ``angle_measured_deg``,
        ``angle_error_deg`` (wrapped to [-180, 180)), ``speed``, ``speed_measured``,
        ``speed_rel_error``, ``n_points``; NaN measures when fewer than `min_points`.

    Raises
    ------
    ValueError
        Fewer than three sweeps, a sweep without times, the first two sweeps parallel.
    """
    if len(sweeps) < 3:
        raise ValueError(f"sweeps: need at least three (two define the dual axes); got {len(sweeps)}")
    missing = [s["name"] for s in sweeps if s["name"] not in times]
    if missing:
        raise ValueError(f"times: no shadow times of sweeps {missing}")
    rows = sweep_rows(sweeps, dual_shape=dual_shape)
    basis = rows[:2, :2]
    if abs(np.linalg.det(basis)) < 1e-9 * np.abs(basis).max() ** 2:
        raise ValueError(f"sweeps: the first two sweeps {[s['name'] for s in sweeps[:2]]} are "
                         "parallel; they cannot define the dual axes")
    t_a, t_b = (np.asarray(times[s["name"]], dtype=np.float64) for s in sweeps[:2])
    out = {}
    for sweep in sweeps[2:]:
        coef, n = _trimmed_affine(np.asarray(times[sweep["name"]], dtype=np.float64), t_a, t_b,
                                  min_points=int(min_points))
        entry = {"angle_deg": float(sweep["angle_deg"]), "speed": float(sweep["speed"]),
                 "n_points": n, "angle_measured_deg": math.nan, "angle_error_deg": math.nan,
                 "speed_measured": math.nan, "speed_rel_error": math.nan}
        if coef is not None:
            a_k, b_k = np.asarray(coef[:2]) @ basis
            measured = math.degrees(math.atan2(b_k, a_k))
            speed = 1.0 / math.hypot(a_k, b_k)
            entry.update(angle_measured_deg=measured, speed_measured=speed,
                         angle_error_deg=(measured - sweep["angle_deg"] + 180.0) % 360.0 - 180.0,
                         speed_rel_error=speed / sweep["speed"] - 1.0)
        out[sweep["name"]] = entry
    return out


def sweep_geometry_targets(errors):
    """Target rows of :func:`sweep_geometry_errors` (``|error| <=`` :data:`SWEEP_GEOMETRY_TARGETS`).

    Returns
    -------
    list of dict
        ``target`` (``sweep_angle_error_deg`` or ``sweep_speed_rel_error``), ``sweep``,
        ``value`` (absolute error), ``threshold``, ``comparison`` (``<=``), ``pass``
        (False for a NaN measure).
    """
    rows = []
    for sweep, entry in errors.items():
        for key, threshold in SWEEP_GEOMETRY_TARGETS.items():
            value = abs(float(entry[key]))
            rows.append({"target": f"sweep_{key}", "sweep": sweep, "value": value,
                         "threshold": threshold, "comparison": "<=",
                         "pass": bool(value <= threshold)})
    return rows


def camera_grid_map(attrs, *, truth_sweeps=("u", "v")):
    """Map from the ground truth's dual grid to a camera model's dual grid, or None.

    The ground truth's reciprocal render lies on the grid of the exact times of two sweeps
    (``(t_a, t_b)`` of `truth_sweeps`, centre of column i at ``t_a = i``). The cross-slit
    camera's grid is that pair of times; the linear camera's grid is the mask plane, where
    each sweep's time is the exact affine function ``t_k = a_k u + b_k v + c_k``
    (attr ``sweep_rows``), so the map is the inverse of the two sweeps' rows.

    Parameters
    ----------
    attrs : mapping
        Attributes of a dual-coordinates dataset of a camera model (``method``, ``sweeps``
        and, for ``linear``, ``sweep_rows``).
    truth_sweeps : (str, str)
        The sweeps whose exact times span the ground truth's grid.

    Returns
    -------
    (3, 3) float64 ndarray or None
        Homography ``(t_a, t_b) -> (u, v)``; None for another model or when the camera
        has not both sweeps.
    """
    method = attrs.get("method")
    names = str(attrs.get("sweeps", "")).split()
    if method == "cross_slit" and names == list(truth_sweeps):
        return np.eye(3)
    if method != "linear" or not all(s in names for s in truth_sweeps):
        return None
    rows = np.asarray(attrs["sweep_rows"], dtype=np.float64).reshape(len(names), 3)
    to_times = np.vstack([rows[names.index(s)] for s in truth_sweeps] + [[0.0, 0.0, 1.0]])
    return np.linalg.inv(to_times)


def linear_redundancy(shadow_time, description, truth_times, *, pair=("u", "v"), dual_shape=None):
    """Dual-coordinate RMSE of the linear camera from all its sweeps and from two of them.

    Both estimates (:func:`shadowcam.cameras.models.camera_coords_from_shadow_time`, model
    ``linear``) are scored against the exact coordinates on the same pixels (valid in both,
    with exact times), so their ratio is the gain of the redundant sweeps.

    Parameters
    ----------
    shadow_time : xarray.Dataset
        ``shadow_time (sweep, row, col)`` of every declared sweep.
    description : mapping
        Capture description with three or more sweeps.
    truth_times : mapping of str to (rows, cols) ndarray
        Exact shadow times of the sweeps of `pair` (NaN = none).
    pair : (str, str)
        The two sweeps of the smaller estimate; their exact times give the truth.
    dual_shape : (int, int), optional
        ``(N_v, N_u)``; default the linear camera's.

    Returns
    -------
    dict
        ``sweeps_all``, ``sweeps_two`` (names), ``rmse_all``, ``rmse_two`` (dual px),
        ``n_pixels``, ``gain`` (``rmse_two / rmse_all``, > 1 when the redundancy lowers the
        error) and ``reduction`` (``1 - rmse_all / rmse_two``).
    """
    from shadowcam.cameras.models import camera_coords_from_shadow_time

    sweeps = list(description["sweeps"])
    names = [s["name"] for s in sweeps]
    if len(sweeps) < 3 or not all(p in names for p in pair):
        raise ValueError(f"description.sweeps: needs three or more sweeps including {list(pair)}; "
                         f"got {names}")
    full = camera_coords_from_shadow_time(shadow_time, description, model="linear",
                                          dual_shape=dual_shape)
    shape = (int(full.attrs["dual_height"]), int(full.attrs["dual_width"]))
    two = camera_coords_from_shadow_time(
        shadow_time, {**description, "sweeps": [s for s in sweeps if s["name"] in pair]},
        model="linear", dual_shape=shape)
    grid = camera_grid_map(full.attrs, truth_sweeps=pair)
    t_a, t_b = (np.asarray(truth_times[p], dtype=np.float64) for p in pair)
    w = grid[2, 0] * t_a + grid[2, 1] * t_b + grid[2, 2]
    true_u = (grid[0, 0] * t_a + grid[0, 1] * t_b + grid[0, 2]) / w
    true_v = (grid[1, 0] * t_a + grid[1, 1] * t_b + grid[1, 2]) / w
    keep = full["valid"].values & two["valid"].values & np.isfinite(true_u) & np.isfinite(true_v)
    if not keep.any():
        raise ValueError("truth_times: no pixel has exact times and coordinates from both estimates")

    def rmse(coords):
        du = coords["u"].values[keep] - true_u[keep]
        dv = coords["v"].values[keep] - true_v[keep]
        return float(np.sqrt(np.mean(du**2 + dv**2)))

    rmse_all, rmse_two = rmse(full), rmse(two)
    return {"sweeps_all": " ".join(names), "sweeps_two": " ".join(pair), "rmse_all": rmse_all,
            "rmse_two": rmse_two, "n_pixels": int(keep.sum()), "gain": rmse_two / rmse_all,
            "reduction": 1.0 - rmse_all / rmse_two}


#: largest RMS distance (dual px) of straight scene edges from their line in the dual view
DUAL_STRAIGHTNESS_TARGET = 0.5


def straightness_check(dual_coords, ground_truth, *, min_points=5):
    """Straightness of the ground truth's straight edges seen through the optics, with its target.

    Parameters
    ----------
    dual_coords : xarray.Dataset
        ``u``, ``v`` over ``(row, col)``; attrs ``dual_height``, ``dual_width``.
    ground_truth : xarray.Dataset
        ``edge_camera_xy (edge_point, cam_xy)``, ``edge_label``, ``edge_lit``,
        ``edge_through_optics`` (the renderer's edge points).
    min_points : int
        Edges with fewer points are not measured.

    Returns
    -------
    report : dict or None
        :func:`straightness_primal_dual` of the lit edge points seen through the optics;
        None when the ground truth has no such points.
    target : dict or None
        ``dual_straightness_rms_px`` row (``value``, ``threshold``
        :data:`DUAL_STRAIGHTNESS_TARGET`, ``comparison`` ``<=``, ``pass``).
    """
    if "edge_camera_xy" not in ground_truth:
        return None, None
    keep = ground_truth["edge_lit"].values & ground_truth["edge_through_optics"].values
    if not keep.any():
        return None, None
    report = straightness_primal_dual(
        dual_coords["u"].transpose("row", "col").values, dual_coords["v"].transpose("row", "col").values,
        ground_truth["edge_camera_xy"].values[keep], ground_truth["edge_label"].values[keep],
        min_points=min_points)
    value = float(report["dual_rms"])
    return report, {"target": "dual_straightness_rms_px", "sweep": None, "value": value,
                    "threshold": DUAL_STRAIGHTNESS_TARGET, "comparison": "<=",
                    "pass": bool(value <= DUAL_STRAIGHTNESS_TARGET)}


#: orthographic view: largest spread of parallel edges' directions (deg), largest |size
#: ratio - 1| of equal objects at two depths
PARALLEL_TARGETS = {"dual_parallel_spread_deg": 0.5, "dual_size_ratio_error": 0.01}


def parallelism_check(dual_coords, ground_truth, *, min_points=5):
    """The orthographic check on the ground truth's straight edges, with its targets.

    The lit edge points' estimated (u, v) (read at their exact camera positions) go to
    :func:`parallel_edges` with their world positions and the light of the ground truth's
    ``geometry`` attr.

    Parameters
    ----------
    dual_coords : xarray.Dataset
        ``u``, ``v`` over ``(row, col)``.
    ground_truth : xarray.Dataset
        ``edge_camera_xy``, ``edge_world``, ``edge_label``, ``edge_lit``; attr ``geometry``.
    min_points : int

    Returns
    -------
    report : dict or None
        :func:`parallel_edges` of the estimated view and, as ``truth``, of the exact one
        (the edges' analytic dual coordinates are not stored: the estimate's own edge set);
        None without edge points.
    targets : list of dict
        ``dual_parallel_spread_deg`` and ``dual_size_ratio_error`` rows
        (:data:`PARALLEL_TARGETS`).
    """
    import json

    if "edge_world" not in ground_truth or "geometry" not in ground_truth.attrs:
        return None, []
    keep = ground_truth["edge_lit"].values
    if keep.sum() < 2 * min_points:
        return None, []
    light = json.loads(ground_truth.attrs["geometry"])["light"]
    world = ground_truth["edge_world"].values[keep].astype(np.float64)
    if "direction" in light and "position" not in light:
        toward, position = np.asarray(light["direction"], dtype=np.float64), None
    else:
        position = np.asarray(light["position"], dtype=np.float64)
        toward = position - world.mean(axis=0)
    uv = sample_coordinates(dual_coords["u"].transpose("row", "col").values,
                            dual_coords["v"].transpose("row", "col").values,
                            ground_truth["edge_camera_xy"].values[keep])
    report = parallel_edges(uv, world, ground_truth["edge_label"].values[keep],
                            toward_light=toward, light_position=position, min_points=min_points)
    values = {"dual_parallel_spread_deg": report["spread_deg"],
              "dual_size_ratio_error": (abs(report["size_ratio"] - 1.0)
                                        if report["size_ratio"] is not None else None)}
    targets = [{"target": name, "sweep": None, "value": value,
                "threshold": PARALLEL_TARGETS[name], "comparison": "<=",
                "pass": bool(value is not None and value <= PARALLEL_TARGETS[name])}
               for name, value in values.items()]
    return report, targets


def add_camera_checks(report, shadow_time, ground_truth, *, camera_model, description,
                      dual_coords=None):
    """Add the camera-specific checks of a lab capture to an accuracy report (in place).

    * three or more scene sweeps: ``sweep_geometry`` (:func:`sweep_geometry_errors`, with
      targets) and, for the linear camera, ``redundancy`` (:func:`linear_redundancy`);
    * straight edges seen through optics in the ground truth: ``straightness``
      (:func:`straightness_check`, with its target);
    * the orthographic camera with straight edges in the ground truth: ``parallelism``
      (:func:`parallelism_check`, with its targets).

    Parameters
    ----------
    report : dict
        ``lab.accuracy.accuracy_report`` output (``targets``, ``all_targets_pass`` updated).
    shadow_time, ground_truth : xarray.Dataset
    camera_model : str
        The capture plan's camera model.
    description : mapping
        The capture plan's capture description (``sweeps`` with ``frames``).
    dual_coords : xarray.Dataset, optional

    Returns
    -------
    dict
        `report`.
    """
    sweeps = list(description.get("sweeps", ()))
    if len(sweeps) >= 3:
        times = {s["name"]: shadow_time["shadow_time"].sel(sweep=s["name"]).transpose("row", "col").values
                 for s in sweeps}
        n = int(sweeps[0]["frames"])
        report["sweep_geometry"] = sweep_geometry_errors(times, sweeps, dual_shape=(n, n))
        report["targets"] += sweep_geometry_targets(report["sweep_geometry"])
        if camera_model == "linear":
            report["redundancy"] = linear_redundancy(
                shadow_time, description, {s: ground_truth[f"t_{s}"].values for s in ("u", "v")})
    if dual_coords is not None:
        found, target = straightness_check(dual_coords, ground_truth)
        if found is not None:
            report["straightness"] = found
            report["targets"].append(target)
        if camera_model == "orthographic":
            found, targets = parallelism_check(dual_coords, ground_truth)
            if found is not None:
                report["parallelism"] = found
                report["targets"] += targets
    report["all_targets_pass"] = bool(report["targets"]) and all(t["pass"] for t in report["targets"])
    return report
