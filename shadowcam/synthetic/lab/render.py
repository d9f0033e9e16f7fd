"""Render synthetic lab sweep captures with exact ground truth (direct illumination only).

The scene is static, so primary rays and scene shadow rays are cast once
(``trace_light_paths``): every (pixel sub-sample, light sample) pair that carries light
becomes a *light path* with its radiance contribution. A wire of radius r blocks a path
during an analytic interval of frames (``raycast.wire_occlusion_interval``), so a whole
sweep is the reference image minus the contributions of the paths blocked in each frame,
accumulated with a difference array over time (no per-frame ray casting at all). Partial
wire coverage of a pixel's sub-samples gives a smooth dip.

Optical elements on the camera side (``optics``: mirrors, thick glass; paper section V) bend
the camera's rays only: shading, shadow times and all ground truth follow the bent ray, while
the light, its shadow rays and the wire ignore the elements; the reciprocal render's light,
the camera's, leaves through them.

Radiometry: radiance ``L = f_r I cos_L / d_L^2`` (point / area samples of intensity I) or
``f_r E cos_L`` (distant light, irradiance E), with the reciprocal BRDF of
``scene.Material``; a point must face both the light and the viewer.

Offers
------
LightPaths : the static light paths of one view (see ``trace_light_paths``).
trace_light_paths : cast primary and shadow rays once for a camera, light and objects.
render_image : (rows, cols, 3) image of a view from its light paths.
footprint_variance : per-axis second moment of a rendered pixel's footprint (its sub-samples).
sweep_frames : (T, rows, cols, 3) frames of one wire sweep from the light paths
    (optionally with the wire pushed off its plane per frame: non-planar motion).
pixel_centre_ground_truth : exact per-pixel GT (P, lit, shadow times, cosines, distances);
    each sweep's time under the sweep's own light.
plane_homography : camera (col, row) pixel-centre index -> back-plane (x, y) homography
    (projective for a pinhole, affine for an orthographic camera).
render_reciprocal : the reciprocal render (the dual or a virtual sweep-pair camera at the
    light, the primal camera as a point light, or as a distant light when orthographic).
CaptureRenderer, prepare_capture : a whole capture (every sweep of the scene, each under its
    own light, plus cal_<sweep> calibration sweeps, reference, ground-truth xarray Dataset)
    with sweeps rendered on demand.
SWEEP_INDEX : sweep name -> index used to seed sensor noise.
"""

import json
import logging
from dataclasses import dataclass, replace

import numpy as np
import xarray as xr

from shadowcam.synthetic.lab.area_occlusion import blocked_share, exact_occlusion, extreme_offset
from shadowcam.synthetic.lab.optics import (
    camera_light_through_optics, camera_pixels_of_points, intersect_through_optics,
)
from shadowcam.synthetic.lab.raycast import SURFACE_OFFSET, intersect_scene, occluded, wire_occlusion_interval
from shadowcam.synthetic.lab.scene import (
    AreaLight, DistantLight, OrthographicCamera, PinholeCamera, PointLight, camera_rays, dual_camera,
    light_samples, project, wire_shadow_time,
)
from shadowcam.synthetic.lab.scenes import calibration_scene

log = logging.getLogger(__name__)

#: sweep name -> index used in noise seeds ``[seed, index, frame]`` (reference: 9)
SWEEP_INDEX = {"u": 0, "v": 1, "cal_u": 2, "cal_v": 3, "reference": 9}

_CHUNK = 1 << 18  # rays per batch


@dataclass(frozen=True)
class LightPaths:
    """Static light transport of one view: one entry per lit (sub-sample, light sample) pair.

    Attributes
    ----------
    shape : (rows, cols)
    pixel : (n,) int64 flat pixel index ``row * cols + col``
    points : (n, 3) float64 scene point of the sub-sample
    light : (n, 3) float64 light sample position (or unit direction for a distant light)
    radiance : (n, 3) float64 contribution to the pixel value (already divided by the
        number of sub-samples per pixel)
    distant : bool
    """

    shape: tuple
    pixel: np.ndarray
    points: np.ndarray
    light: np.ndarray
    radiance: np.ndarray
    distant: bool


def _subpixel_grid(rows, cols, supersample):
    """Pixel-edge (x, y) of a supersample x supersample grid of stratum centres per pixel."""
    k = np.arange(supersample)
    offsets = (k + 0.5) / supersample
    r, c, oy, ox = np.meshgrid(np.arange(rows), np.arange(cols), offsets, offsets,
                               indexing="ij")
    return (c + ox).ravel(), (r + oy).ravel()


def _view_dirs(camera, points):
    if isinstance(camera, OrthographicCamera):
        return np.broadcast_to(-camera.R[2], points.shape)
    if callable(getattr(camera, "view_dirs", None)):  # virtual cameras (lab.virtual)
        return camera.view_dirs(points)
    rel = camera.center - points
    return rel / np.linalg.norm(rel, axis=1, keepdims=True)


def _brdf(objects, object_id, albedo, normal, to_light, to_view):
    """(N, 3) BRDF value ``albedo/pi + ks (s+8)/(8 pi) (n.h)^s`` (reciprocal)."""
    f = albedo / np.pi
    spec = np.array([o.material.specular for o in objects])[object_id]
    if np.any(spec > 0):
        shin = np.array([o.material.shininess for o in objects])[object_id]
        h = to_light + to_view
        h /= np.linalg.norm(h, axis=1, keepdims=True)
        nh = np.clip((normal * h).sum(axis=1), 0.0, None)
        f = f + (spec * (shin + 8) / (8 * np.pi) * nh**shin)[:, None]
    return f


def _primary_hits(objects, camera, x, y, optics):
    """Hits of the camera rays through pixel-edge (x, y), bent by `optics`.

    Returns (hits, to_view, path_length): without optics `to_view` and `path_length` are
    None (the view direction is toward the camera centre); with optics `to_view` (N, 3) is
    the reverse of the bent ray's last direction and `path_length` (N,) the unfolded length
    of the camera ray from the camera centre to the hit.
    """
    origins, dirs = camera_rays(camera, x, y)
    if not optics:
        return intersect_scene(objects, origins, dirs), None, None
    hits, bent = intersect_through_optics(objects, optics, origins, dirs)
    return hits, -bent.directions, np.where(hits.hit, bent.path_length + hits.distance, np.nan)


def _shade(objects, hits_sel, camera, light, to_view=None):
    """Per light sample: (to_light_end, radiance (n, 3)) for the hit points in `hits_sel`.

    `hits_sel` is (point, normal, object_id, albedo); `to_view` (n, 3) overrides the
    direction toward the camera centre. Yields one entry per light sample; radiance is 0
    where the point does not face the light/viewer or is occluded.
    """
    points, normal, object_id, albedo = hits_sel
    positions, directions, weights = light_samples(light)
    if to_view is None:
        to_view = _view_dirs(camera, points)
    cos_c = (normal * to_view).sum(axis=1)
    n_samples = len(weights)
    for k in range(n_samples):
        if directions is not None:
            to_light = np.broadcast_to(directions[k], points.shape)
            dist = np.full(len(points), np.inf)
            falloff = np.ones(len(points))
            end = to_light
        else:
            rel = positions[k] - points
            dist = np.linalg.norm(rel, axis=1)
            to_light = rel / dist[:, None]
            falloff = 1.0 / dist**2
            end = np.broadcast_to(positions[k], points.shape)
        cos_l = (normal * to_light).sum(axis=1)
        ok = (cos_l > 0) & (cos_c > 0)
        idx = np.flatnonzero(ok)
        start = points[idx] + SURFACE_OFFSET * normal[idx]
        blocked = occluded(objects, start, to_light[idx], dist[idx])
        ok[idx[blocked]] = False
        f = _brdf(objects, object_id, albedo, normal, to_light, to_view)
        radiance = f * (weights[k] * (cos_l * falloff)[:, None])
        radiance[~ok] = 0.0
        yield end, radiance, ok


def footprint_variance(supersample):
    """Per-axis second moment, px^2, of a pixel's footprint in the renders: its sub-samples.

    A pixel is the mean of ``s x s`` point samples at the centres of equal strata; along each
    axis they sit at ``(k + 1/2) / s - 1/2``, whose mean square is ``(s**2 - 1) / (12 s**2)``
    (1/12, the box, as ``s`` grows; 0 for one sample at the centre).
    """
    s = int(supersample)
    if s < 1:
        raise ValueError(f"supersample must be >= 1; got {supersample}")
    return (s * s - 1) / (12.0 * s * s)


def trace_light_paths(objects, camera, light, *, supersample=4, optics=()):
    """Cast primary rays and scene shadow rays once for a view.

    Parameters
    ----------
    objects : sequence of scene objects
    camera : PinholeCamera or OrthographicCamera
    light : PointLight, AreaLight or DistantLight
    supersample : int
        Sub-samples per pixel side (stratum centres of a regular grid; 1 = pixel centre).
    optics : sequence of optical elements
        Mirrors / thick glass that bend the primary rays (``optics``); empty = direct view.

    Returns
    -------
    LightPaths
    """
    supersample = int(supersample)
    if supersample < 1:
        raise ValueError(f"supersample must be >= 1; got {supersample}")
    rows, cols = camera.height, camera.width
    x, y = _subpixel_grid(rows, cols, supersample)
    per_pixel = supersample * supersample
    parts = {"pixel": [], "points": [], "light": [], "radiance": []}
    for start in range(0, len(x), _CHUNK):
        sl = slice(start, start + _CHUNK)
        hits, to_view, _ = _primary_hits(objects, camera, x[sl], y[sl], optics)
        sel = np.flatnonzero(hits.hit)
        pixel = (start + sel) // per_pixel
        data = (hits.point[sel], hits.normal[sel], hits.object_id[sel], hits.albedo[sel])
        to_view = None if to_view is None else to_view[sel]
        for end, radiance, ok in _shade(objects, data, camera, light, to_view):
            parts["pixel"].append(pixel[ok])
            parts["points"].append(data[0][ok])
            parts["light"].append(np.asarray(end)[ok])
            parts["radiance"].append(radiance[ok] / per_pixel)
    cat = {k: np.concatenate(v) if v else np.zeros((0, 3)) for k, v in parts.items()}
    return LightPaths(shape=(rows, cols), pixel=cat["pixel"].astype(np.int64),
                      points=cat["points"], light=cat["light"], radiance=cat["radiance"],
                      distant=isinstance(light, DistantLight))


def _pixel_sums(paths):
    n_pix = paths.shape[0] * paths.shape[1]
    return np.stack([np.bincount(paths.pixel, weights=paths.radiance[:, c], minlength=n_pix)
                     for c in range(3)], axis=-1)


def render_image(paths):
    """Return the (rows, cols, 3) float32 radiance image of `paths` (no wire)."""
    return _pixel_sums(paths).reshape(*paths.shape, 3).astype(np.float32)


def _offset_rate(paths, sweep, mask):
    """Shift of each path's blocked interval, in frames per scene unit of wire offset along
    the mask normal: the wire at ``p(k) + e n`` blocks path (P, L) when
    ``|t_c - k - e (n.w) / (v.w)| < half_width`` (``w = normalize(s x d)`` as in
    ``raycast.wire_occlusion_interval``). Zero for a distant light (n parallel to s)."""
    seg = paths.light if paths.distant else paths.light - paths.points
    w = np.cross(seg, sweep.direction)
    with np.errstate(divide="ignore", invalid="ignore"):
        w /= np.linalg.norm(w, axis=1, keepdims=True)
        return (w @ mask.normal) / (w @ sweep.velocity)


def _sweep_mask(mask, sweep):
    """`mask` moved onto the plane the sweep's wire moves in (when it is a parallel plane)."""
    height = (sweep.p0 - mask.origin) @ mask.normal
    if abs(height) <= 1e-12 * max(mask.n_u, mask.n_v) * mask.delta:
        return mask
    return replace(mask, origin=sweep.p0)


def _exposed_frames(paths, t_c, half, reference, n_frames, shutter):
    """Frames exposed over ``[k - shutter/2, k + shutter/2]``: each path loses its radiance
    times the fraction of the exposure the wire blocks it, the overlap of that window with
    ``(t_c - half, t_c + half)`` over `shutter`."""
    n_pix = reference.shape[0]
    ok = np.isfinite(t_c) & np.isfinite(half)
    t_c, half, pixel, radiance = t_c[ok], half[ok], paths.pixel[ok], paths.radiance[ok]
    start = np.floor(t_c - half - shutter / 2.0).astype(np.int64)
    span = int(np.max(np.ceil(t_c + half + shutter / 2.0) - start, initial=0)) + 1
    deficit = np.zeros((n_frames, n_pix, 3))
    for j in range(span):
        k = start + j
        overlap = (np.minimum(t_c + half, k + shutter / 2.0)
                   - np.maximum(t_c - half, k - shutter / 2.0))
        use = (overlap > 0) & (k >= 0) & (k < n_frames)
        weight = overlap[use] / shutter
        flat = k[use] * n_pix + pixel[use]
        for c in range(3):
            deficit[..., c] += np.bincount(flat, weights=weight * radiance[use, c],
                                           minlength=n_frames * n_pix).reshape(n_frames, n_pix)
    frames = np.clip(reference[None] - deficit, 0.0, None).astype(np.float32)
    return frames.reshape(n_frames, *paths.shape, 3)


def sweep_frames(paths, sweep, mask, *, path_offsets=None, shutter=0.0, light=None):
    """Frames of one wire sweep.

    Frame k shows the wire at ``p(k) = p0 + k v``; a light path is dark in frame k when the
    wire blocks it, i.e. ``|k - t_c| < half_width`` (``raycast.wire_occlusion_interval``).
    Under a continuous area light (`light` a disc, sphere or tube,
    ``area_occlusion.exact_occlusion``) each path instead loses the share of the whole
    source the wire blocks as seen from its scene point (``area_occlusion.blocked_share``;
    an open shutter averages it over ``EXPOSURE_INSTANTS`` instants): the light samples
    still shade and cast the scene's own shadows, but the wire's penumbra is that of the
    continuous source.
    With an open `shutter` the frame integrates the moving wire over its exposure: the path
    is dimmed by the fraction of ``[k - shutter/2, k + shutter/2]`` the wire blocks it (a
    real camera's motion blur: the hard-edged dip gets ramps, so its sampled shape carries
    the sub-frame shadow time; an instant exposure samples a boxcar).

    Parameters
    ----------
    paths : LightPaths
        Traced under the sweep's light.
    sweep : WireSweep
    mask : MaskPlane
        (a sweep moving in a parallel plane uses that plane.)
    path_offsets : (T,) array_like, optional
        Non-planar mask motion: in frame k the wire is displaced by ``path_offsets[k]``
        (scene units) along the mask normal ``n`` (the light's aim direction), i.e. it
        sits at ``p(k) + path_offsets[k] n``. Exact for an infinite wire (the finite
        wire's coverage is that of the planar path). None = planar motion.
    shutter : float
        Exposure of each frame as a fraction of the frame interval, in [0, 1]; 0 = an
        instant (the wire frozen at ``p(k)``). Not combined with `path_offsets`.
    light : PointLight, AreaLight or DistantLight, optional
        The light `paths` were traced under; needed only for the exact occlusion of a
        continuous area light (None: every light as its samples).

    Returns
    -------
    (T, rows, cols, 3) float32 ndarray
        Linear radiance, T = ``sweep.frames``.
    """
    shutter = float(shutter)
    if not 0.0 <= shutter <= 1.0:
        raise ValueError(f"shutter: must be in [0, 1] (fraction of the frame interval), got {shutter}")
    if shutter > 0 and path_offsets is not None:
        raise ValueError("shutter: an open shutter is not combined with path_offsets; pass one")
    n_frames = sweep.frames
    n_pix = paths.shape[0] * paths.shape[1]
    mask = _sweep_mask(mask, sweep)
    t_c, half = wire_occlusion_interval(paths.points, paths.light, sweep, mask,
                                        distant=paths.distant)
    reference = _pixel_sums(paths)  # float64: fully blocked pixels cancel to ~1e-18
    offsets = None
    if path_offsets is not None:
        offsets = np.asarray(path_offsets, dtype=np.float64)
        if offsets.shape != (n_frames,) or not np.all(np.isfinite(offsets)):
            raise ValueError(f"path_offsets: expected {n_frames} finite offsets (one per "
                             f"frame), got shape {offsets.shape}")
    if exact_occlusion(light):
        return _continuous_source_frames(paths, light, sweep, mask, reference, n_frames,
                                         offsets=offsets, shutter=shutter)
    if offsets is not None:
        return _frames_with_offsets(paths, t_c, half, _offset_rate(paths, sweep, mask),
                                    offsets, reference)
    if shutter > 0:
        return _exposed_frames(paths, t_c, half, reference, n_frames, shutter)
    with np.errstate(invalid="ignore"):
        first = np.floor(t_c - half) + 1  # strict inequality: open interval
        last = np.ceil(t_c + half) - 1
    first = np.clip(np.nan_to_num(first, nan=n_frames), 0, n_frames)
    last = np.clip(np.nan_to_num(last, nan=-1), -1, n_frames - 1)
    keep = np.isfinite(t_c) & (first <= last)
    base = paths.pixel[keep] * (n_frames + 1)
    index = np.concatenate([base + first[keep].astype(np.int64),
                            base + last[keep].astype(np.int64) + 1])
    frames = np.empty((n_frames, n_pix, 3), dtype=np.float32)
    for c in range(3):
        w = paths.radiance[keep, c]
        diff = np.bincount(index, weights=np.concatenate([w, -w]),
                           minlength=n_pix * (n_frames + 1))
        deficit = np.cumsum(diff.reshape(n_pix, n_frames + 1), axis=1)[:, :n_frames]
        frames[:, :, c] = np.clip(reference[:, c] - deficit.T, 0.0, None)
    return frames.reshape(n_frames, *paths.shape, 3)


#: sub-instants over an open shutter's exposure for a continuous area light (midpoint rule)
EXPOSURE_INSTANTS = 16


def _continuous_source_frames(paths, light, sweep, mask, reference, n_frames, *, offsets=None, shutter=0.0):
    """Frames under a continuous area light: each scene point's paths lose the share of the
    source the wire blocks from that point (``area_occlusion.blocked_share``), per frame;
    with `offsets` the wire of frame k is displaced along the mask normal, with an open
    `shutter` the share is averaged over :data:`EXPOSURE_INSTANTS` instants of the exposure."""
    n_pix = reference.shape[0]
    points, inverse = np.unique(paths.points, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    radiance = np.stack([np.bincount(inverse, weights=paths.radiance[:, c], minlength=len(points))
                         for c in range(3)], axis=-1)
    pixel = np.zeros(len(points), dtype=np.int64)
    pixel[inverse] = paths.pixel
    instants = ((np.arange(EXPOSURE_INSTANTS) + 0.5) / EXPOSURE_INSTANTS - 0.5) * shutter if shutter > 0 else [0.0]
    frames = np.empty((n_frames, n_pix, 3), dtype=np.float32)
    for k in range(n_frames):
        wire = sweep if offsets is None else replace(sweep, p0=sweep.p0 + offsets[k] * mask.normal)
        share = np.mean([blocked_share(points, light, wire, mask, np.full(len(points), k + lag))
                         for lag in instants], axis=0)
        for c in range(3):
            deficit = np.bincount(pixel, weights=share * radiance[:, c], minlength=n_pix)
            frames[k, :, c] = np.clip(reference[:, c] - deficit, 0.0, None)
    return frames.reshape(n_frames, *paths.shape, 3)


def _frames_with_offsets(paths, t_c, half, rate, offsets, reference):
    """Frame by frame: path blocked in frame k when ``|t_c - k - offsets[k] rate| < half``."""
    n_pix = reference.shape[0]
    frames = np.empty((len(offsets), n_pix, 3), dtype=np.float32)
    ok = np.isfinite(t_c) & np.isfinite(rate)
    t_c, half, rate = t_c[ok], half[ok], rate[ok]
    pixel, radiance = paths.pixel[ok], paths.radiance[ok]
    for k, offset in enumerate(offsets):
        blocked = np.abs(t_c - k - offset * rate) < half
        for c in range(3):
            deficit = np.bincount(pixel[blocked], weights=radiance[blocked, c], minlength=n_pix)
            frames[k, :, c] = np.clip(reference[:, c] - deficit, 0.0, None)
    return frames.reshape(len(offsets), *paths.shape, 3)


def _pixel_centres(camera):
    return _subpixel_grid(camera.height, camera.width, 1)


def _surface_terms(objects, points, normal, hit, eye_camera, light, to_view=None, dist_c=None):
    """cos_L, cos_C, dist_L, dist_C and scene visibility of the light centre, (N,) each.

    `to_view` (N, 3) and `dist_c` (N,) override the direction toward and the distance to
    the eye camera's centre (camera rays bent by optics)."""
    n = len(points)
    centre = light.direction if isinstance(light, DistantLight) else light.center
    if isinstance(light, DistantLight):
        to_light = np.broadcast_to(centre, points.shape)
        dist_l = np.full(n, np.inf)
    else:
        rel = centre - points
        dist_l = np.linalg.norm(rel, axis=1)
        to_light = rel / dist_l[:, None]
    if to_view is None:
        to_view = _view_dirs(eye_camera, points)
    if dist_c is None:  # infinite for orthographic and virtual (non-pinhole) eye cameras
        dist_c = (np.linalg.norm(eye_camera.center - points, axis=1)
                  if isinstance(eye_camera, PinholeCamera) else np.full(n, np.inf))
    with np.errstate(invalid="ignore"):
        cos_l = (normal * to_light).sum(axis=1)
        cos_c = (normal * to_view).sum(axis=1)
    faces = hit & (cos_l > 0) & (cos_c > 0)
    idx = np.flatnonzero(faces)
    blocked = occluded(objects, points[idx] + SURFACE_OFFSET * normal[idx], to_light[idx],
                       dist_l[idx])
    lit = faces.copy()
    lit[idx[blocked]] = False
    return cos_l, cos_c, dist_l, dist_c, lit


def pixel_centre_ground_truth(objects, camera, light, mask, sweeps, *, optics=()):
    """Exact ground truth at camera pixel centres.

    With `optics` every quantity follows the bent camera ray: ``P`` is where it meets the
    scene, ``cos_C`` uses the ray's last direction, ``dist_C`` is the unfolded path length
    from the camera centre and ``depth`` its component along the camera's optical axis
    (the depth of the virtual point on the unbent camera ray).

    Parameters
    ----------
    objects : sequence of scene objects
    camera : PinholeCamera or OrthographicCamera
    light : PointLight, AreaLight or DistantLight (area lights use their centre)
    mask : MaskPlane
    sweeps : dict of str to WireSweep
    sweeps : dict of str to WireSweep
        A sweep carrying its own light (``WireSweep.light``) is timed under that light.
    optics : sequence of optical elements
        Mirrors / thick glass that bend the primary rays; empty = direct view.

    Returns
    -------
    dict of str to ndarray
        ``P``, ``N`` (rows, cols, 3); ``hit``, ``lit`` (rows, cols) bool (lit: faces light and
        camera, light centre visible, wire excluded); ``cos_L``, ``cos_C``, ``dist_L``,
        ``dist_C``, ``depth``; ``object_id``; and for every sweep name s: ``t_<s>``
        (fractional frame, NaN where not lit by the sweep's light, not covered by the finite
        wire or outside [0, T-1]) and ``t_<s>_all`` (unrestricted); for a sweep with its own
        light also ``lit_<s>`` (lit by that light).
    """
    rows, cols = camera.height, camera.width
    x, y = _pixel_centres(camera)
    hits, to_view, unfolded = _primary_hits(objects, camera, x, y, optics)
    cos_l, cos_c, dist_l, dist_c, lit = _surface_terms(objects, hits.point, hits.normal,
                                                       hits.hit, camera, light, to_view,
                                                       unfolded)
    if unfolded is None:
        _, depth = project(camera, hits.point)
    else:
        depth = unfolded * (camera_rays(camera, x, y)[1] @ camera.R[2])
    out = {"P": hits.point, "N": hits.normal, "hit": hits.hit, "lit": lit, "cos_L": cos_l,
           "cos_C": cos_c, "dist_L": dist_l, "dist_C": dist_c, "depth": depth,
           "object_id": hits.object_id}
    for name, sweep in sweeps.items():
        sweep_light, sweep_lit = light, lit
        if sweep.light is not None and sweep.light is not light:
            sweep_light = sweep.light
            sweep_lit = _surface_terms(objects, hits.point, hits.normal, hits.hit, camera,
                                       sweep_light)[4]
            out[f"lit_{name}"] = sweep_lit
        distant = isinstance(sweep_light, DistantLight)
        centre = sweep_light.direction if distant else sweep_light.center
        light_pts = np.broadcast_to(centre, hits.point.shape)
        t_all = wire_shadow_time(hits.point, sweep, sweep_light)
        t_cov, _ = wire_occlusion_interval(np.nan_to_num(hits.point), light_pts, sweep,
                                           _sweep_mask(mask, sweep), distant=distant)
        ok = sweep_lit & np.isfinite(t_cov) & (t_all >= 0) & (t_all <= sweep.frames - 1)
        out[f"t_{name}_all"] = t_all
        out[f"t_{name}"] = np.where(ok, t_all, np.nan)
    return {k: np.asarray(v).reshape(rows, cols, *np.shape(v)[1:]) for k, v in out.items()}


def plane_homography(camera, plane):
    """Homography from camera pixel-centre index (col, row) to back-plane coordinates (x, y).

    Parameters
    ----------
    camera : PinholeCamera or OrthographicCamera
    plane : BackPlane

    Returns
    -------
    (3, 3) float64 ndarray
        ``H`` with ``[x, y, 1] ~ H [col, row, 1]``, normalised so ``H[2, 2] = 1`` (affine, last
        row (0, 0, 1), for an orthographic camera).
    """
    if isinstance(camera, OrthographicCamera):
        return _orthographic_plane_map(camera, plane)
    if not isinstance(camera, PinholeCamera):
        raise ValueError("camera: the plane homography needs a pinhole or orthographic camera")
    shift = np.array([[1.0, 0.0, 0.5], [0.0, 1.0, 0.5], [0.0, 0.0, 1.0]])  # index -> edge
    A = camera.R.T @ np.linalg.inv(camera.K) @ shift  # pixel index -> ray direction
    n, p0, c = plane.normal, plane.center, camera.center
    # (n.d)(X - p0) = [(c - p0) n^T + (n.(p0 - c)) I] d  for X on the ray c + s d
    M = np.outer(c - p0, n) + (n @ (p0 - c)) * np.eye(3)
    H = np.stack([plane.axis_x @ M @ A, plane.axis_y @ M @ A, n @ A])
    return H / H[2, 2]


def _orthographic_plane_map(camera, plane):
    """Affine map camera (col, row) pixel-centre index -> plane (x, y) of an orthographic camera:
    the ray origin is affine in (col, row) and moves onto the plane along the fixed direction."""
    d, n, s = camera.R[2], plane.normal, camera.pixel_size
    if abs(n @ d) < 1e-12:
        raise ValueError("plane: parallel to the orthographic camera's viewing direction")

    def onto_plane(vector):  # oblique projection along d onto the plane's directions
        return vector - d * (n @ vector) / (n @ d)

    o0 = (camera.center + (0.5 - camera.width / 2.0) * s * camera.R[0]
          + (0.5 - camera.height / 2.0) * s * camera.R[1])
    cols = [onto_plane(s * camera.R[0]), onto_plane(s * camera.R[1]),
            onto_plane(o0 - plane.center)]
    return np.array([[plane.axis_x @ c for c in cols], [plane.axis_y @ c for c in cols],
                     [0.0, 0.0, 1.0]])


def _reciprocal_light(camera, strength):
    """The primal camera as a light: a point light at a pinhole's centre, a distant light
    toward an orthographic camera."""
    if isinstance(camera, OrthographicCamera):
        return DistantLight(-camera.R[2], strength)
    return PointLight(camera.center, strength)


def _reciprocal_paths_through_optics(objects, camera, dual, strength, optics, supersample):
    """LightPaths of the dual view lit by the primal camera through its `optics`: each dual
    sub-sample's scene point receives ``strength * gain`` along every bent camera ray that
    reaches it (``optics.camera_light_through_optics``); ``light`` is where that ray leaves
    the optics."""
    rows, cols = dual.height, dual.width
    x, y = _subpixel_grid(rows, cols, supersample)
    per_pixel = supersample * supersample
    origins, dirs = camera_rays(dual, x, y)
    hits = intersect_scene(objects, origins, dirs)
    sel = np.flatnonzero(hits.hit)
    points, normal = hits.point[sel], hits.normal[sel]
    to_view = _view_dirs(dual, points)
    to_light, gain, exit_point = camera_light_through_optics(objects, optics, camera, points)
    strength = np.asarray(strength, dtype=np.float64)
    parts = {"pixel": [], "points": [], "light": [], "radiance": []}
    for b in range(gain.shape[1]):
        with np.errstate(invalid="ignore"):
            cos_l = (normal * to_light[:, b]).sum(axis=1)
        ok = (gain[:, b] > 0) & (cos_l > 0) & ((normal * to_view).sum(axis=1) > 0)
        f = _brdf(objects, hits.object_id[sel[ok]], hits.albedo[sel[ok]], normal[ok],
                  to_light[ok, b], to_view[ok])
        parts["pixel"].append(sel[ok] // per_pixel)
        parts["points"].append(points[ok])
        parts["light"].append(exit_point[ok, b])
        parts["radiance"].append(f * strength * (gain[ok, b] * cos_l[ok])[:, None] / per_pixel)
    cat = {k: np.concatenate(v) if v else np.zeros((0, 3)) for k, v in parts.items()}
    return LightPaths(shape=(rows, cols), pixel=cat["pixel"].astype(np.int64),
                      points=cat["points"], light=cat["light"], radiance=cat["radiance"],
                      distant=False)


def render_reciprocal(objects, camera, light, mask, *, supersample=4, optics=(), dual=None):
    """The reciprocal render and the dual-pixel geometry.

    The view from the dual camera (``scene.dual_camera``: pinhole at the light centre, or
    orthographic for a distant light; or the given virtual camera, e.g.
    ``lab.virtual.SweepPairCamera`` for skewed or cross-slit views) lit by the primal camera
    as a light with the light's intensity (irradiance for a distant light): a point light at
    a pinhole camera's centre, a distant light toward an orthographic camera (Fig. 8). Its
    pixel grid is the dual grid. With `optics` the camera's light leaves through them
    (Helmholtz reciprocity): it reaches the scene along the bent camera rays through the
    image pixels, with the irradiance their ray tubes carry
    (``optics.camera_light_through_optics``); a dual point is visible when a camera ray
    bent by them meets it first
    (``optics.camera_pixels_of_points``, solved to 0.01 camera pixel), and ``dual_cam_xy``
    is that ray's pixel.

    Parameters
    ----------
    objects : sequence of scene objects
    camera : PinholeCamera or OrthographicCamera
        The primal camera.
    light : PointLight, AreaLight or DistantLight
    mask : MaskPlane
    supersample : int
    optics : sequence of optical elements
        Mirrors / thick glass that bend the primal camera's rays (see above).
    dual : camera, optional
        The reciprocal view's camera; default ``dual_camera(mask, light)``.

    Returns
    -------
    dict of str to ndarray
        ``reciprocal`` (n_v, n_u, 3) float32; ``dual_P`` (n_v, n_u, 3); ``dual_hit``,
        ``dual_cam_visible`` (n_v, n_u) bool (dual_P faces the camera, is unoccluded from the
        camera centre and projects inside the image; with optics: a bent camera ray meets
        it first); ``dual_cam_xy`` (n_v, n_u, 2) camera
        (col, row) pixel-centre index of dual_P (NaN where not visible).
    """
    dual = dual_camera(mask, light) if dual is None else dual
    strength = light.irradiance if isinstance(light, DistantLight) else light.intensity
    swapped = _reciprocal_light(camera, strength)
    if optics:
        paths = _reciprocal_paths_through_optics(objects, camera, dual, strength, optics,
                                                 int(supersample))
    else:
        paths = trace_light_paths(objects, dual, swapped, supersample=supersample)
    reciprocal = render_image(paths)
    x, y = _pixel_centres(dual)
    origins, dirs = camera_rays(dual, x, y)
    hits = intersect_scene(objects, origins, dirs)
    _, cos_c, _, _, visible = _surface_terms(objects, hits.point, hits.normal, hits.hit,
                                             dual, swapped)
    if optics:
        faces_dual = hits.hit & (cos_c > 0)
        xy, visible = camera_pixels_of_points(objects, optics, camera,
                                              np.where(faces_dual[:, None], hits.point, np.nan))
        cam_xy = xy
    else:
        xy, depth = project(camera, np.nan_to_num(hits.point))
        inside = ((depth > 0) & (xy[:, 0] >= 0) & (xy[:, 0] <= camera.width)
                  & (xy[:, 1] >= 0) & (xy[:, 1] <= camera.height))
        visible &= inside
        cam_xy = np.where(visible[:, None], xy - 0.5, np.nan)
    shape = (dual.height, dual.width)
    return {"reciprocal": reciprocal, "dual_P": hits.point.reshape(*shape, 3),
            "dual_hit": hits.hit.reshape(shape), "dual_cam_visible": visible.reshape(shape),
            "dual_cam_xy": cam_xy.reshape(*shape, 2)}


def _edge_point_truth(scene):
    """GT variables of the exact points on the back plane's square edges (``edges``), if any.

    Straight scene edges measure the straightness of the primal and dual views
    (``cameras.accuracy.straightness_primal_dual``); only a back plane with a ``squares``
    texture has them.
    """
    from shadowcam.synthetic.lab.edges import square_edge_points

    plane = getattr(scene, "back_plane", None)
    texture = getattr(getattr(plane, "material", None), "texture", None)
    if getattr(texture, "kind", None) != "squares":
        return {}
    edges = square_edge_points(scene)
    dims = ("edge_point",)
    return {
        "edge_camera_xy": (dims + ("cam_xy",), edges.camera_xy.astype(np.float32), "pixel",
                           "camera (col, row) pixel-centre index of a point on a straight edge"),
        "edge_world": (dims + ("xyz",), edges.world.astype(np.float32), "scene_unit",
                       "world position of the edge point"),
        "edge_label": (dims, edges.label, "1", "straight world line of the edge point"),
        "edge_lit": (dims, edges.lit, "1", "edge point faces the light and sees its centre"),
        "edge_through_optics": (dims, edges.through_optics, "1",
                                "the camera sees the edge point through an optical element"),
    }


def _area_light_truth(scene, points, supersample):
    """GT variables of the dip interval under an area light (``interval_*``, ``penumbra_*``
    per sweep; ``reciprocal_<viewpoint>`` per viewpoint of ``lab.viewpoints.VIEWPOINTS`` and
    for the penumbra's outer edges, ``_extreme_point_views``).

    The tracker's entry and exit are the dip's half-depth crossings; through a wire wider
    than the source (an umbra) they are the times half the source's weight is blocked
    (``area_truth.area_light_times`` at fraction 0.5): the wire's leading and trailing edges
    passing the source's centre, for the centrally symmetric disc, square and sphere. So the
    viewpoint at fraction f across the interval is the view from the light's centre at
    fraction f across the wire (``viewpoint_camera``). Only the standard pair under the
    scene's light, seen directly.
    """
    from shadowcam.lab.viewpoints import VIEWPOINTS
    from shadowcam.synthetic.lab.area_truth import area_light_times
    from shadowcam.synthetic.lab.viewpoint_camera import viewpoint_camera

    light, names = scene.light, ("u", "v")
    if (not isinstance(light, AreaLight) or scene.optics or scene.dual_sweeps is not None
            or any(n not in scene.sweeps or scene.sweeps[n].light is not None for n in names)):
        return {}
    rc, vu, f32 = ("row", "col"), ("v", "u"), np.float32
    flat = points.reshape(-1, 3)
    data = {}
    for name, sweep in scene.sweeps.items():
        if sweep.light is not None:
            continue
        half = area_light_times(flat, sweep, scene.mask, light, fraction=0.5)
        outer = area_light_times(flat, sweep, scene.mask, light, fraction=0.0)
        for key, times, what in (
                ("interval_entry", half[0], "half the source blocked, entering (leading edge at its centre)"),
                ("interval_exit", half[1], "half the source blocked, leaving (trailing edge at its centre)"),
                ("penumbra_first", outer[0], "first source point blocked (the source's extreme point)"),
                ("penumbra_last", outer[1], "last source point freed (the source's other extreme point)")):
            data[f"{key}_{name}"] = (rc, times.reshape(points.shape[:2]).astype(f32), "frame",
                                     f"sweep {name}: {what}")
    views = {name: (light.center, fraction, f"the light's centre with the wires' lines at fraction "
                                             f"{fraction} across their width")
             for name, fraction in VIEWPOINTS.items()}
    views.update(_extreme_point_views(scene))
    for viewpoint, (source, fraction, what) in views.items():
        dual = viewpoint_camera(scene.sweeps, names, source, fraction, scene.mask)
        recip = render_reciprocal(scene.objects, scene.camera, light, scene.mask,
                                  supersample=supersample, dual=dual)
        data[f"reciprocal_{viewpoint}"] = (vu + ("channel",), recip["reciprocal"], "radiance",
                                           f"reciprocal render of viewpoint {viewpoint}: from {what}, "
                                           "the camera as a light")
        data[f"dual_cam_visible_{viewpoint}"] = (vu, recip["dual_cam_visible"], "1",
                                                 f"dual point of viewpoint {viewpoint} seen by the camera")
    return data


def _extreme_point_views(scene):
    """The views of the penumbra's outer edges: from the source's extreme points.

    The wire of sweep u moves along e_u, so it first blocks the source point of least e_u
    coordinate and last frees the one of greatest; likewise along e_v. With the light's
    plane parallel to the mask plane a point's u time depends on its e_u coordinate alone,
    so the corner (least u, least v) of the source's bounding box, seen through the wires'
    leading edges, has both sweeps' first times (``penumbra_first``; a corner of the
    bounding square for a disc, off the disc itself), the opposite corner through the
    trailing edges their last times (``penumbra_last``). The box is the continuous
    source's (``area_occlusion.extreme_offset``) where the renderer occludes it exactly,
    else its samples'. None when the planes are not parallel.
    """
    mask, light = scene.mask, scene.light
    if abs(abs(mask.normal @ light.normal) - 1.0) > 1e-9 or scene.sweeps["u"].velocity @ mask.e_u <= 0 \
            or scene.sweeps["v"].velocity @ mask.e_v <= 0:
        return {}
    if exact_occlusion(light):
        reach = np.array([extreme_offset(light, mask.e_u), extreme_offset(light, mask.e_v)])
        low, high, what = -reach, reach, "the continuous source's"
    else:
        positions = light_samples(light)[0]
        u, v = (positions - light.center) @ mask.e_u, (positions - light.center) @ mask.e_v
        low, high, what = np.array([u.min(), v.min()]), np.array([u.max(), v.max()]), "the samples'"
    return {"penumbra_first": (light.center + low[0] * mask.e_u + low[1] * mask.e_v, 0.0,
                               f"{what} bounding-box corner the wires reach first, through their leading edges"),
            "penumbra_last": (light.center + high[0] * mask.e_u + high[1] * mask.e_v, 1.0,
                              f"{what} bounding-box corner the wires leave last, through their trailing edges")}


def _light_attrs(light):
    light_d = {"type": type(light).__name__}
    for key in ("position", "direction", "intensity", "irradiance", "normal", "size", "shape"):
        if hasattr(light, key):
            value = getattr(light, key)
            light_d[key] = value.tolist() if isinstance(value, np.ndarray) else value
    return light_d


def _camera_attrs(cam):
    if isinstance(cam, OrthographicCamera):
        return {"type": "orthographic", "R_world_to_cam": cam.R.tolist(),
                "center": cam.center.tolist(), "pixel_size": cam.pixel_size,
                "width": cam.width, "height": cam.height,
                "convention": "pixel-edge (x, y) -> ray origin center + (x - width/2) "
                              "pixel_size R[0] + (y - height/2) pixel_size R[1], direction "
                              "R[2]; pixel (row r, col c) centre at pixel-edge (c + 0.5, r + 0.5)"}
    return {"K": cam.K.tolist(), "R_world_to_cam": cam.R.tolist(),
            "center": cam.center.tolist(), "width": cam.width, "height": cam.height,
            "convention": "X_cam = R (X - center); pixel (row r, col c) centre at "
                          "pixel-edge (c + 0.5, r + 0.5)"}


def _sweep_attrs(sweep):
    attrs = {"p0": sweep.p0.tolist(), "v": sweep.velocity.tolist(),
             "d": sweep.direction.tolist(), "frames": sweep.frames, "radius": sweep.radius,
             "length": sweep.length}
    if sweep.light is not None:
        attrs["light"] = _light_attrs(sweep.light)
    return attrs


def _geometry_attrs(scene):
    """JSON description of camera, light, mask plane and sweeps (like meta.json)."""
    mask = scene.mask
    geometry = {
        "camera": _camera_attrs(scene.camera),
        "light": _light_attrs(scene.light),
        "mask_plane": {"M0": mask.origin.tolist(), "n": mask.normal.tolist(),
                       "e_u": mask.e_u.tolist(), "e_v": mask.e_v.tolist(),
                       "delta": mask.delta, "N_u": mask.n_u, "N_v": mask.n_v,
                       "f_light_to_mask_plane": mask.focal},
        "sweeps": {k: _sweep_attrs(s) for k, s in scene.sweeps.items()},
    }
    if scene.dual_sweeps is not None:
        geometry["dual_sweeps"] = list(scene.dual_sweeps)
    return json.dumps(geometry)


def _sweep_light(scene, name):
    sweep = scene.sweeps[name]
    return scene.light if sweep.light is None else sweep.light


class CaptureRenderer:
    """A rendered capture: reference, ground truth, and sweeps rendered on demand.

    Build it with ``prepare_capture``. ``frames(name)`` returns the (T, rows, cols, 3)
    float32 linear frames of sweep `name` (every sweep of the scene, e.g. ``u``, ``v``, and
    the calibration sweeps ``cal_<sweep>``), each under the sweep's own light.
    """

    def __init__(self, scene, sweep_paths, reference, ground_truth, homography):
        self.scene = scene
        self.reference = reference
        self.ground_truth = ground_truth
        self.homography = homography
        self._paths = dict(sweep_paths)

    @property
    def sweep_names(self):
        """Names of the sweeps this capture renders."""
        return tuple(self._paths)

    def frames(self, name, *, path_offsets=None, shutter=0.0):
        """(T, rows, cols, 3) float32 frames of sweep `name` (see ``sweep_frames`` for
        `path_offsets`, the non-planar wire motion, and `shutter`, the exposure)."""
        if name not in self._paths:
            raise ValueError(f"name: no sweep {name!r}; available: {self.sweep_names}")
        base = name.removeprefix("cal_")
        return sweep_frames(self._paths[name], self.scene.sweeps[base], self.scene.mask,
                            path_offsets=path_offsets, shutter=shutter, light=_sweep_light(self.scene, base))


def _trace_per_light(objects, camera, scene, names, supersample, prefix=""):
    """LightPaths of each sweep, traced once per distinct light (sweep name -> paths);
    the camera rays are bent by the scene's optics."""
    by_light = {}
    out = {}
    for name in names:
        light = _sweep_light(scene, name)
        if id(light) not in by_light:
            by_light[id(light)] = trace_light_paths(objects, camera, light,
                                                    supersample=supersample,
                                                    optics=scene.optics)
        out[prefix + name] = by_light[id(light)]
    return out


def prepare_capture(scene, *, supersample=4, calibration=True):
    """Cast the static rays of a capture and compute its exact ground truth.

    Parameters
    ----------
    scene : Scene
        Its camera may be a pinhole or orthographic; each sweep is rendered and timed under
        its own light (``WireSweep.light``, default the scene's light).
    supersample : int
        Sub-samples per pixel side for the camera and the reciprocal renders.
    calibration : bool
        Also prepare the calibration sweeps ``cal_<sweep>`` over the scene's back plane alone.

    Returns
    -------
    CaptureRenderer
        With ``reference`` (rows, cols, 3) float32 (under the scene's light),
        ``ground_truth`` (xarray.Dataset, the standard GT names of docs/contracts.md plus
        P, N, cosines, distances, calibration GT; ``t_<sweep>`` for every sweep, ``lit_<sweep>``
        for a sweep with its own light; under an area light the dip intervals and the
        viewpoints' reciprocal renders of ``_area_light_truth``; the reciprocal render on the (u, v) grid of the dual
        camera, or of ``lab.virtual.SweepPairCamera`` of ``scene.dual_sweeps`` with
        u = t_a, v = t_b) and ``homography`` ((3, 3), or None without calibration or when
        the scene's optics bend the camera rays, which leaves no plane homography).
    """
    cam, light, mask, optics = scene.camera, scene.light, scene.mask, scene.optics
    names = tuple(scene.sweeps)
    sweep_paths = _trace_per_light(scene.objects, cam, scene, names, supersample)
    scene_paths = next((p for n, p in sweep_paths.items() if _sweep_light(scene, n) is light),
                       None)
    if scene_paths is None:
        scene_paths = trace_light_paths(scene.objects, cam, light, supersample=supersample,
                                        optics=optics)
    reference = render_image(scene_paths)
    log.info("traced %d light paths for %dx%d pixels", len(scene_paths.pixel), cam.height,
             cam.width)
    gt = pixel_centre_ground_truth(scene.objects, cam, light, mask, scene.sweeps,
                                   optics=optics)
    dual = None
    recip_name = "reciprocal render: pinhole at the light, point light at the camera"
    if optics:
        recip_name = ("reciprocal render: pinhole at the light, the camera's light through "
                      "its optics")
    if scene.dual_sweeps is not None:
        from shadowcam.synthetic.lab.virtual import sweep_pair_camera  # builds on scene, sweeps

        dual = sweep_pair_camera(scene.sweeps, scene.dual_sweeps, light=light)
        recip_name = ("reciprocal render: virtual camera of sweeps {} (u) and {} (v), the "
                      "camera as a light").format(*scene.dual_sweeps)
    recip = render_reciprocal(scene.objects, cam, light, mask, supersample=supersample,
                              optics=optics, dual=dual)
    n_v, n_u = recip["dual_hit"].shape
    f32 = np.float32
    rc, vu = ("row", "col"), ("v", "u")

    def time_long_name(name):
        dual_axis = f" (dual {name})" if name in ("u", "v") else ""
        return f"analytic shadow time of sweep {name}{dual_axis}"

    data = {f"t_{n}": (rc, gt[f"t_{n}"].astype(f32), "frame", time_long_name(n))
            for n in names}
    data.update({f"t_{n}_all": (rc, gt[f"t_{n}_all"].astype(f32), "frame",
                                f"t_{n} without lit/range limits") for n in names})
    data.update({
        "lit": (rc, gt["lit"], "1", "pixel-centre point faces light and camera, light visible"),
        "hit": (rc, gt["hit"], "1", "pixel-centre ray hits geometry"),
        "P": (rc + ("xyz",), gt["P"].astype(f32), "scene_unit", "world point at pixel centre"),
        "N": (rc + ("xyz",), gt["N"].astype(f32), "1", "surface normal at P"),
        "depth": (rc, gt["depth"].astype(f32), "scene_unit", "camera z of P"),
        "cos_L": (rc, gt["cos_L"].astype(f32), "1", "cosine between normal and light dir"),
        "cos_C": (rc, gt["cos_C"].astype(f32), "1", "cosine between normal and camera dir"),
        "dist_L": (rc, gt["dist_L"].astype(f32), "scene_unit", "distance P to light centre"),
        "dist_C": (rc, gt["dist_C"].astype(f32), "scene_unit", "distance P to camera centre"),
        "reference_linear": (rc + ("channel",), reference, "radiance",
                             "linear render without the wire"),
        "reciprocal": (vu + ("channel",), recip["reciprocal"], "radiance", recip_name),
        "dual_P": (vu + ("xyz",), recip["dual_P"].astype(f32), "scene_unit",
                   "world point at dual pixel centre"),
        "dual_cam_visible": (vu, recip["dual_cam_visible"], "1",
                             "dual_P seen by the camera (through its optics, if any), inside the image"),
        "dual_cam_xy": (vu + ("cam_xy",), recip["dual_cam_xy"].astype(f32), "pixel",
                        "camera (col, row) pixel-centre index of dual_P"),
    })
    data.update({f"lit_{n}": (rc, gt[f"lit_{n}"], "1",
                              f"pixel-centre point faces the light of sweep {n}, light visible")
                 for n in names if f"lit_{n}" in gt})
    data.update(_edge_point_truth(scene))
    data.update(_area_light_truth(scene, gt["P"], supersample))
    homography = None
    if calibration:
        cal = calibration_scene(scene)
        sweep_paths.update(_trace_per_light(cal.objects, cam, scene, names, supersample,
                                            prefix="cal_"))
        cgt = pixel_centre_ground_truth(cal.objects, cam, light, mask, scene.sweeps,
                                        optics=optics)
        plane = cal.back_plane
        homography = None if optics else plane_homography(cam, plane)
        xy = plane.plane_coords(cgt["P"].reshape(-1, 3)).reshape(cam.height, cam.width, 2)
        data.update({f"t_cal_{n}": (rc, cgt[f"t_{n}"].astype(f32), "frame",
                                    f"analytic shadow time of calibration sweep cal_{n}")
                     for n in names})
        data.update({
            "plane_xy": (rc + ("plane_axis",), xy.astype(f32), "scene_unit",
                         "back-plane coordinates (x, y) at pixel centre (calibration scene)"),
        })
        if homography is not None:
            data["calibration_homography"] = (
                ("h_row", "h_col"), homography, "1",
                "camera (col, row) pixel-centre index -> plane (x, y)")
    attrs = {"scene": scene.name, "seed": scene.seed, "supersample": int(supersample),
             "geometry": _geometry_attrs(scene),
             "convention": "arrays indexed [row, col] at pixel centres; dual pixel "
                           "(row j, col i) centre <-> u = i, v = j"}
    if scene.dual_sweeps is not None:
        attrs["dual_sweeps"] = "u = t_{}, v = t_{}".format(*scene.dual_sweeps)
    ds = xr.Dataset(
        {k: (dims, val, {"units": units, "long_name": name})
         for k, (dims, val, units, name) in data.items()},
        coords={"row": np.arange(cam.height), "col": np.arange(cam.width),
                "u": np.arange(n_u, dtype=np.float64),
                "v": np.arange(n_v, dtype=np.float64),
                "channel": ["R", "G", "B"], "xyz": ["x", "y", "z"]},
        attrs=attrs,
    )
    dual_names = scene.dual_sweeps or ("u", "v")
    ds["u"].attrs.update(units="dual_pixel", long_name=f"dual column (u = t_{dual_names[0]})")
    ds["v"].attrs.update(units="dual_pixel", long_name=f"dual row (v = t_{dual_names[1]})")
    return CaptureRenderer(scene, sweep_paths, reference, ds, homography)
