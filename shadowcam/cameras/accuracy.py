"""Camera-specific checks of the shadow cameras against known scene geometry.

The dual-coordinate RMSE itself is ``lab.accuracy.dual_coord_errors`` (also for the
cross-slit camera, against its exact pair of times). Here:

* straightness (paper V, Fig. 14, 15): straight scene edges seen through a mirror or glass are
  bent in the primal view; the dual view from the estimated (u, v) straightens them. Measured
  on the same exact edge points: their camera positions (primal) and the estimated (u, v)
  interpolated at those positions (dual), each by ``cameras.straightness.edge_straightness``.
* parallelism (orthographic camera, IV, Fig. 7): parallel scene edges at different depths
  stay parallel in an orthographic view: the spread of the directions of their fitted lines.
* redundancy: the dual-coordinate RMSE of the linear camera from all sweeps over that from
  two of them.

Offers
------
sample_coordinates : estimated (u, v) maps read at sub-pixel camera positions (bilinear).
straightness_primal_dual : straightness of edges in the primal view and in the estimated dual view.
line_direction_spread : spread (deg) of the directions of the lines fitted to labelled point sets.
redundancy_gain : RMSE ratio of the linear camera from a subset of sweeps over all sweeps.
"""

import math

import numpy as np

from shadowcam._shared.validation import check_array, check_same_shape
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
    doubled = np.exp(2j * np.array(angles))  # directions modulo 180 deg
    mean = np.angle(doubled.mean())
    offsets = np.angle(doubled * np.exp(-1j * mean)) / 2
    return float(np.degrees(offsets.max() - offsets.min()))


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
