"""Straightness of straight scene edges in an image: do straight lines stay straight?

Paper section V (Fig. 14, 15): a view through a curved mirror or thick glass bends straight
scene edges, and the dual view from a perspective light straightens them again. The measure
is the RMS distance (pixels) of edge points from the total-least-squares line fitted to each
edge. It works on any 2-D coordinates: camera pixels of a primal image, or dual
coordinates ``(u, v)`` of the same scene points.

Offers
------
EdgeStraightness : per-edge and overall RMS distance of edge points from their fitted lines.
edge_straightness : measure it from edge points with labels, or from an image and a label
    map of bands around each edge.
edge_points_from_image : sub-pixel edge points (gradient-weighted centroids across each band).
"""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class EdgeStraightness:
    """Straightness of K edges.

    Attributes
    ----------
    labels : (K,) int64
        Edge labels.
    rms : (K,) float64
        RMS distance of each edge's points from its fitted line (NaN for edges with fewer
        than ``min_points`` points).
    n_points : (K,) int64
        Points per edge.
    overall_rms : float
        RMS distance pooled over the points of all measured edges (NaN if none).
    """

    labels: np.ndarray
    rms: np.ndarray
    n_points: np.ndarray
    overall_rms: float


def _line_residuals(points):
    """Signed distances (n,) of (n, 2) points from their total-least-squares line."""
    centred = points - points.mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    return centred @ vt[-1]


def edge_points_from_image(image, labels):
    """Sub-pixel edge points of the edges marked by a label map.

    Every label k > 0 marks a band of pixels straddling one straight (or bent) edge. The
    band's long direction (principal axis of its pixel positions) decides the scan: for a
    band closer to vertical each row across it gives one point, the centroid of the columns
    weighted by the image's gradient magnitude; likewise per column for a band closer to
    horizontal.

    Parameters
    ----------
    image : (M, N) or (M, N, C) ndarray
        Intensity or colour image (colour channels are averaged).
    labels : (M, N) int ndarray
        Band label per pixel; 0 = no edge.

    Returns
    -------
    points : (P, 2) float64 ndarray
        Edge points as (row, col).
    point_labels : (P,) int64 ndarray
        The band label of each point.
    """
    image = np.asarray(image)
    if image.ndim not in (2, 3) or image.shape[0] < 2 or image.shape[1] < 2:
        raise ValueError(f"image: expected (M, N) or (M, N, C), got shape {image.shape}")
    labels = np.asarray(labels)
    if labels.shape != image.shape[:2] or not np.issubdtype(labels.dtype, np.integer):
        raise ValueError(f"labels: expected an integer (M, N) = {image.shape[:2]} label map, "
                         f"got {labels.dtype} {labels.shape}")
    gray = image.astype(np.float64)
    if gray.ndim == 3:
        gray = gray.mean(axis=2)
    g_row, g_col = np.gradient(gray)
    magnitude = np.hypot(g_row, g_col)
    points, point_labels = [], []
    for label in np.unique(labels[labels > 0]):
        rows, cols = np.nonzero(labels == label)
        if len(rows) < 3:
            continue
        spread = np.cov(np.stack([rows, cols]).astype(np.float64))
        _, vecs = np.linalg.eigh(spread)
        vertical = abs(vecs[0, -1]) >= abs(vecs[1, -1])  # long axis mostly along rows
        scan, across = (rows, cols) if vertical else (cols, rows)
        weight = magnitude[rows, cols]
        total = np.bincount(scan, weights=weight)
        moment = np.bincount(scan, weights=weight * across)
        count = np.bincount(scan)
        line = np.flatnonzero((count >= 2) & (total > 0))
        centroid = moment[line] / total[line]
        pts = np.stack([line, centroid] if vertical else [centroid, line], axis=1)
        points.append(pts.astype(np.float64))
        point_labels.append(np.full(len(pts), label, dtype=np.int64))
    if not points:
        return np.zeros((0, 2)), np.zeros(0, dtype=np.int64)
    return np.concatenate(points), np.concatenate(point_labels)


def edge_straightness(data, *, labels, min_points=3):
    """RMS distance of edge points from the straight line fitted to each edge.

    Parameters
    ----------
    data : (P, 2) ndarray or (M, N) / (M, N, C) ndarray
        Edge points in any 2-D pixel coordinates (camera (col, row), dual (u, v), ...), or
        an image whose edges are located with ``edge_points_from_image``.
    labels : (P,) int ndarray or (M, N) int ndarray
        With points: the edge label of each point (points sharing a label lie on one
        straight scene edge). With an image: a label map of bands around the edges
        (0 = none).
    min_points : int
        Edges with fewer points are not measured (rms NaN).

    Returns
    -------
    EdgeStraightness
        Distances are in the units of the coordinates (pixels). Residuals are plain
        perpendicular distances from the total-least-squares line (no degrees-of-freedom
        correction).
    """
    data = np.asarray(data)
    labels = np.asarray(labels)
    if int(min_points) < 3:
        raise ValueError(f"min_points: must be >= 3 (a line through 2 points fits exactly), "
                         f"got {min_points!r}")
    if labels.ndim == 2:
        points, point_labels = edge_points_from_image(data, labels)
    else:
        if data.ndim != 2 or data.shape[1] != 2:
            raise ValueError(f"data: expected (P, 2) edge points, got shape {data.shape}")
        if labels.shape != (len(data),) or not np.issubdtype(labels.dtype, np.integer):
            raise ValueError(f"labels: expected ({len(data)},) integer edge labels, "
                             f"got {labels.dtype} {labels.shape}")
        points, point_labels = data.astype(np.float64), labels.astype(np.int64)
        if not np.all(np.isfinite(points)):
            raise ValueError("data: edge points must be finite (drop the NaN ones first)")
    unique = np.unique(point_labels)
    rms = np.full(len(unique), np.nan)
    n_points = np.zeros(len(unique), dtype=np.int64)
    squares = []
    for k, label in enumerate(unique):
        pts = points[point_labels == label]
        n_points[k] = len(pts)
        if len(pts) < int(min_points):
            continue
        residual = _line_residuals(pts)
        rms[k] = np.sqrt(np.mean(residual**2))
        squares.append(residual**2)
    overall = float(np.sqrt(np.mean(np.concatenate(squares)))) if squares else float("nan")
    return EdgeStraightness(labels=unique, rms=rms, n_points=n_points, overall_rms=overall)
