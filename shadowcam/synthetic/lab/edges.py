"""Exact image positions of straight scene edges: the edges of the coloured squares of the
scene's planes (``BackPlane`` objects with a ``squares`` texture: the back plane, panels).

The ``squares`` texture (``scene.Texture``) puts squares with edges along straight lines of
the back plane's coordinates. Their images are found here exactly, through the camera's
optics (mirrors, thick glass) if any: along every pixel-centre row (for edges of constant
plane x) or column (constant plane y) the camera coordinate where the bent ray meets the
edge line is bracketed on a fine grid and refined by bisection. The same world points give
the dual coordinates (the analytic shadow times of the sweeps ``u`` and ``v``), so one set
of edge points measures straightness in the primal view and in the dual view.

Offers
------
EdgePoints : world points on square edges with their camera and dual coordinates.
square_edge_points : trace the edges of the planes' squares into the camera and dual views.
"""

from dataclasses import dataclass

import numpy as np

from shadowcam.synthetic.lab.optics import intersect_through_optics, trace_through_optics
from shadowcam.synthetic.lab.raycast import SURFACE_OFFSET, intersect_back_plane, occluded
from shadowcam.synthetic.lab.scene import (
    SQUARE_FILL,
    BackPlane,
    DistantLight,
    camera_rays,
    wire_shadow_time,
)


@dataclass(frozen=True)
class EdgePoints:
    """Points on straight scene edges.

    Attributes
    ----------
    camera_xy : (N, 2) float64
        Camera (col, row) pixel-centre index of each point (through the optics).
    world : (N, 3) float64
        World points (on the back plane, exactly on an edge line).
    dual_uv : (N, 2) float64
        Dual coordinates (u, v) = analytic shadow times of the sweeps ``u``, ``v``.
    label : (N,) int64
        Line id: points with one label lie on one straight world line (the collinear
        edges of a row or column of squares).
    segment : (N,) int64
        Edge id: points with one segment id lie on one edge of one square.
    lit : (N,) bool
        The point faces the light and sees the light centre (it has a shadow time).
    through_optics : (N,) bool
        The camera ray met an optical element (False: the camera sees the point directly).
    """

    camera_xy: np.ndarray
    world: np.ndarray
    dual_uv: np.ndarray
    label: np.ndarray
    segment: np.ndarray
    lit: np.ndarray
    through_optics: np.ndarray


def _line_count(a, margin):
    """Number of edge lines at or below plane coordinate `a` (in cells), for each entry."""
    cell = np.floor(a)
    frac = a - cell
    return 2 * cell + (frac >= margin) + (frac >= 1.0 - margin)


def _line_position(count, margin):
    """Plane coordinate (in cells) of edge line number `count` (as counted by _line_count)."""
    odd = count % 2 == 1
    return np.where(odd, (count - 1) / 2 + margin, count / 2 - margin)


def _plane_coords_of_rays(scene, plane, x, y):
    """Coordinates (N, 2) on `plane` where the bent camera rays through (x, y) meet it."""
    origins, dirs = camera_rays(scene.camera, x, y)
    bent = trace_through_optics(scene.optics, origins, dirs)
    t = np.full(len(x), np.inf)
    ok = bent.valid
    t[ok] = intersect_back_plane(bent.origins[ok], bent.directions[ok], plane)
    with np.errstate(invalid="ignore"):
        points = bent.origins + np.where(np.isfinite(t), t, np.nan)[:, None] * bent.directions
    return plane.plane_coords(points)


def _crossings(scene, plane, axis, step, iterations):
    """Edge crossings of `plane`'s squares along pixel-centre rows (axis 0: lines of
    constant plane x) or columns (axis 1: constant plane y). Returns camera (x, y) and the
    line number."""
    cam = scene.camera
    scale = plane.material.texture.scale
    margin = (1.0 - SQUARE_FILL) / 2.0
    n_lines, length = (cam.height, cam.width) if axis == 0 else (cam.width, cam.height)
    along = np.arange(0.0, length + step / 2, step)
    fixed = np.arange(n_lines) + 0.5
    f_grid, a_grid = np.meshgrid(fixed, along, indexing="ij")
    xy = (a_grid, f_grid) if axis == 0 else (f_grid, a_grid)
    coord = _plane_coords_of_rays(scene, plane, xy[0].ravel(), xy[1].ravel())[:, axis] / scale
    coord = coord.reshape(f_grid.shape)
    with np.errstate(invalid="ignore"):
        count = _line_count(coord, margin)
    ok = np.isfinite(count[:, :-1]) & np.isfinite(count[:, 1:])
    ok &= np.abs(count[:, 1:] - count[:, :-1]) == 1
    line_i, k = np.nonzero(ok)
    line = np.maximum(count[line_i, k], count[line_i, k + 1])
    target = _line_position(line, margin)
    lo, hi = along[k], along[k + 1]
    sign_lo = np.sign(coord[line_i, k] - target)
    fix = fixed[line_i]
    for _ in range(int(iterations)):
        mid = 0.5 * (lo + hi)
        pts = (mid, fix) if axis == 0 else (fix, mid)
        value = _plane_coords_of_rays(scene, plane, *pts)[:, axis] / scale - target
        same = np.sign(value) == sign_lo
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    mid = 0.5 * (lo + hi)
    x, y = (mid, fix) if axis == 0 else (fix, mid)
    return x, y, line


def square_edge_points(scene, *, step=0.25, iterations=48):
    """Trace the edges of the coloured squares of the scene's planes into the camera and dual views.

    Parameters
    ----------
    scene : scenes.Scene
        At least one ``BackPlane`` must carry a ``squares`` texture (e.g. presets
        ``tabletop_squares``, ``panels``); its optics (if any) bend the camera rays.
    step : float
        Bracketing grid step along rows / columns (camera pixels); an edge line must not be
        crossed twice within one step.
    iterations : int
        Bisection steps (each halves the bracket).

    Returns
    -------
    EdgePoints
        One point per pixel-centre row crossing a square's vertical edge and per
        pixel-centre column crossing a horizontal edge, where the bent camera ray meets the
        square's plane first; labels are distinct per plane.
    """
    planes = [(i, o) for i, o in enumerate(scene.objects) if isinstance(o, BackPlane)
              and o.material.texture is not None and o.material.texture.kind == "squares"]
    if not planes:
        raise ValueError("scene: its back plane must carry a 'squares' texture")
    if not (np.isfinite(step) and 0 < step <= 1):
        raise ValueError(f"step: must be in (0, 1] camera pixels, got {step!r}")
    if int(iterations) < 1:
        raise ValueError(f"iterations: must be >= 1, got {iterations!r}")
    margin = (1.0 - SQUARE_FILL) / 2.0
    parts = []
    for index, plane in planes:
        scale = plane.material.texture.scale
        for axis in (0, 1):
            x, y, line = _crossings(scene, plane, axis, step, iterations)
            origins, dirs = camera_rays(scene.camera, x, y)
            hits, bent = intersect_through_optics(scene.objects, scene.optics, origins, dirs)
            on_plane = hits.object_id == index
            across = plane.plane_coords(np.nan_to_num(hits.point))[:, 1 - axis] / scale
            cell = np.floor(across)
            frac = across - cell
            on_square = (frac >= margin) & (frac < 1.0 - margin)
            keep = on_plane & on_square
            key = np.stack([np.full(keep.sum(), index), np.full(keep.sum(), axis), line[keep],
                            cell[keep]], axis=1)
            parts.append((x[keep], y[keep], hits.point[keep], hits.normal[keep], key,
                          bent.interactions[keep] > 0))
    x, y, world, normal, key, through = (np.concatenate(p) for p in zip(*parts))
    key = key.astype(np.int64)
    _, label = np.unique(key[:, :3], axis=0, return_inverse=True)
    _, segment = np.unique(key, axis=0, return_inverse=True)
    light = scene.light
    if isinstance(light, DistantLight):
        to_light, dist = np.broadcast_to(light.direction, world.shape), np.inf
    else:
        rel = light.center - world
        dist = np.linalg.norm(rel, axis=1)
        to_light = rel / dist[:, None]
    faces = (normal * to_light).sum(axis=1) > 0
    lit = faces & ~occluded(scene.objects, world + SURFACE_OFFSET * normal, to_light, dist)
    dual_uv = np.stack([wire_shadow_time(world, scene.sweeps[s], light) for s in ("u", "v")],
                       axis=1)
    return EdgePoints(camera_xy=np.stack([x - 0.5, y - 0.5], axis=1), world=world,
                      dual_uv=dual_uv, label=label.ravel().astype(np.int64),
                      segment=segment.ravel().astype(np.int64), lit=lit,
                      through_optics=through)
