"""Ray correspondence of a light-field capture and the rays dataset.

Each screen position has a horizontal sweep (a vertical wire moving along the mask's
x) and a vertical one (a horizontal wire moving along y). Their shadow times at a
camera pixel, turned into mask positions ``x_mask = start + step * time``, name the
mask point the pixel's light passed through (paper VI, Fig. 17). A ray's origin is a pixel of
the anchor screen (the far one by default); its flux is the anchor screen's irradiance times
the pixel's screen area. Its direction, given the mask plane's position (as the stages give
it), is the line from the pixel's mask point on the mask plane to the pixel's flux centroid
on the anchor screen: the wire blocks exactly the light through that mask point,
and the anchor's mask error then tilts the ray by itself over the mask-to-anchor distance.
Without it, the ray goes to the other screen's point with the pixel's mask coordinates
(interpolated over that screen's mask coordinates, Clough-Tocher C1 cubic on their Delaunay
triangulation), which tilts it by the other screen's magnification times the mask error over
the screens' separation. Either way the other screen must see the mask point (else the ray
is flagged ``no_match_far``).

The shadow times come from the lab wing's streaming dip tracker
(:func:`shadowcam.lab.shadow_time.track_sweep`, memory independent of the number of
frames) fed HDR-merged frames (:func:`shadowcam.lightfield.hdr.merge_stream`).

Offers
------
REASONS : ray flag code -> meaning.
ANCHORS : the screens a ray can start from.
sweep_mask_positions : frames of one sweep (streamed) -> mask position per pixel, its std, flags, lit level.
screen_mask_map : the two sweeps of one screen + its geometry -> the screen's mask-coordinate map.
rays_dataset : near and far screen maps -> the rays dataset (row, col, axis).
write_rays : the rays dataset as a netCDF file (h5netcdf), atomically.
"""

import numpy as np
import xarray as xr
from scipy.interpolate import CloughTocher2DInterpolator, LinearNDInterpolator
from scipy.ndimage import distance_transform_edt

from shadowcam._shared.atomic import atomic_path
from shadowcam._shared.validation import check_in, check_positive, check_same_shape
from shadowcam.lab.shadow_time import summary_shadow_times, track_sweep
from shadowcam.lightfield.direction_fit import direction_noise, far_magnification, fit_directions
from shadowcam.lightfield.screen import flux_centroids

#: ray flag code -> meaning (0 = a ray)
REASONS = {
    0: "ok",
    1: "no_shadow_near",      # no reliable dip in one of the near screen's sweeps
    2: "no_match_far",        # the mask point is not seen reliably on the far screen
    3: "saturated",           # every bracket saturated: no irradiance
}
OK, NO_SHADOW_NEAR, NO_MATCH_FAR, SATURATED = range(4)


def sweep_mask_positions(blocks, shape, *, mask_start, mask_step, half_window=4, method="edge_fit",
                         progress=None):
    """Mask position whose shadow crosses each pixel, from one sweep's frames.

    Parameters
    ----------
    blocks : iterable of (T, H, W, 1) float ndarray
        Linear HDR frames in time order (e.g. :func:`shadowcam.lightfield.hdr.merge_stream`);
        NaN samples take no part.
    shape : (H, W)
    mask_start : float, keyword-only
        Mask position (mm, in the mask plane) of the wire's centre at frame 0.
    mask_step : float, keyword-only
        Wire motion per frame, mm (non-zero).
    half_window, method
        As :func:`shadowcam.lab.shadow_time.sweep_shadow_times`.
    progress : callable, optional

    Returns
    -------
    dict of (H, W) ndarrays
        ``position`` mm (NaN where flagged), ``position_std`` mm, ``flags``
        (:data:`shadowcam.lab.shadow_time.REASONS`), ``lit_level`` and ``n_frames``.
    """
    if not (np.isfinite(mask_step) and mask_step != 0):
        raise ValueError(f"mask_step must be a finite non-zero number; got {mask_step!r}")
    if not np.isfinite(mask_start):
        raise ValueError(f"mask_start must be finite; got {mask_start!r}")
    summary, _, _ = track_sweep(blocks, shape, half_window=half_window, saturation_level=np.inf,
                                progress=progress)
    result = summary_shadow_times(summary, method=method)
    ok = result["reason"] == 0
    position = np.where(ok, mask_start + mask_step * result["shadow_time"], np.nan)
    return {"position": position, "position_std": np.abs(mask_step) * result["time_std"],
            "flags": result["reason"], "lit_level": summary.lit_level, "n_frames": result["n_frames"]}


def screen_mask_map(horizontal, vertical, *, xy, area, position_mm):
    """One screen's map from camera pixels to mask coordinates and screen points.

    Parameters
    ----------
    horizontal, vertical : dict
        :func:`sweep_mask_positions` of the sweep along the mask's x and along its y.
    xy : (H, W, 2) ndarray
        Screen ``x, y`` mm of each pixel (:func:`shadowcam.lightfield.screen.screen_coordinates`).
    area : (H, W) ndarray
        Screen mm^2 per pixel.
    position_mm : float
        The screen's z.

    Returns
    -------
    dict
        ``mask`` (H, W, 2) mask ``x, y`` (NaN where either sweep is flagged), ``mask_std``
        (H, W), ``xy``, ``area``, ``irradiance`` (H, W, NaN where saturated), ``ok`` (H, W) bool,
        ``position_mm``.
    """
    check_positive(position_mm, "position_mm", finite=True)
    check_same_shape({"horizontal position": horizontal["position"], "vertical position": vertical["position"],
                      "xy[..., 0]": xy[..., 0], "area": area})
    mask = np.stack([horizontal["position"], vertical["position"]], -1)
    irradiance = 0.5 * (horizontal["lit_level"] + vertical["lit_level"])
    ok = np.all(np.isfinite(mask), axis=-1)
    std = np.hypot(horizontal["position_std"], vertical["position_std"])
    return {"mask": mask, "mask_std": np.where(ok, std, np.nan), "xy": np.asarray(xy, np.float64),
            "area": np.asarray(area, np.float64), "irradiance": irradiance, "ok": ok,
            "position_mm": float(position_mm)}


#: what a pixel without its own correspondence does in renders: take the local fit's direction
#: (``"fit"``), be left out (``"drop"``), or take the nearest found ray's (``"nearest"``)
EDGE_RAYS = ("fit", "drop", "nearest")

#: the screen whose pixels carry the rays: the far one (default; its partner point lies on the
#: near screen, of smaller magnification) or the near one
ANCHORS = ("far", "near")


def rays_dataset(near, far, *, anchor="far", mask_position_mm=None, footprint_variance=0.0, mask_std_scale=0.05,
                 smooth_directions=False, edge_rays="fit"):
    """The rays of a light field from its near and far screens' mask-coordinate maps.

    Each ray starts at a pixel of the `anchor` screen (its point is known exactly). With
    `mask_position_mm` its direction is the line from the pixel's mask point (on the mask
    plane) to the pixel's flux centroid on the anchor screen
    (:func:`shadowcam.lightfield.screen.flux_centroids`): the anchor's mask error ``e`` tilts
    it by ``e / (z_anchor - z_mask)``. Without it the ray goes through the point of the other
    screen with the pixel's mask coordinates (interpolated over that screen's mask map): the
    anchor pixel's mask error moves that point by the other screen's magnification (screen mm
    per mask mm), a tilt of that magnification times ``e`` over the screens' separation.
    In both, a pixel whose mask point the other screen does not see is flagged.

    Parameters
    ----------
    near, far : dict
        :func:`screen_mask_map` of the near and the far screen.
    anchor : {"far", "near"}, keyword-only
        :data:`ANCHORS`: the screen whose pixels carry the rays (origins, flux, grid).
    mask_position_mm : float, optional, keyword-only
        z of the mask plane (< the near screen's): the rays go through the anchor pixels' mask
        points. None: through the other screen's points.
    footprint_variance : float, keyword-only
        Per-axis second moment (px^2) of a camera pixel's footprint on the screen, for the
        flux centroid of the anchor pixels (with `mask_position_mm`; 0 = the pixel centres).
    mask_std_scale : float, keyword-only
        Mask-coordinate standard deviation (mm) at which the confidence is ``exp(-1/2)``.
    smooth_directions : bool, keyword-only
        Estimate directions by the weighted local-linear fit of
        :func:`shadowcam.lightfield.direction_fit.fit_directions` (noise propagated from the
        shadow-time std); else (default) each ray keeps its own measured direction: on the
        synthetic capture the direction errors are correlated between neighbouring rays, so
        the fit does not reduce them (docs/benchmarks.md).
    edge_rays : {"fit", "drop", "nearest"}, keyword-only
        :data:`EDGE_RAYS`: direction of a pixel without its own correspondence.

    Returns
    -------
    xarray.Dataset
        On the anchor screen's pixel grid ``(row, col)``: ``origin`` and ``direction``
        ``(row, col, axis)`` (mm; direction with unit z), ``irradiance`` (lux at the anchor
        screen), ``flux`` (lm through the pixel), ``mask`` ``(row, col, mask_axis)`` mm,
        ``confidence`` in [0, 1], ``direction_std`` (per axis, from the noise model; of the
        fit when smoothed) and ``flag`` (:data:`REASONS`; ``no_shadow_near`` means no shadow on
        the anchor screen, ``no_match_far`` no match on the other). A pixel whose ray is not found
        (flag > 0, confidence 0, ``mask`` NaN) keeps its flag; by `edge_rays` its direction
        is the local fit's from its neighbours (with that fit's std), or NaN with flux 0
        (left out of renders), or the nearest found ray's. Attributes: the screens' positions and
        camera pitches (``near_pitch_mm``, ``far_pitch_mm``: square root of the median
        pixel area), ``anchor``, ``origin_position_mm`` and ``through`` (``mask`` or ``screen``).
    """
    check_in(anchor, "anchor", ANCHORS)
    if mask_position_mm is not None and not (np.isfinite(mask_position_mm)
                                             and mask_position_mm < min(near["position_mm"], far["position_mm"])):
        raise ValueError(f"mask_position_mm must be a finite z below both screens' ({near['position_mm']}, "
                         f"{far['position_mm']}); got {mask_position_mm!r}: check the capture's mask position_mm")
    if not far["position_mm"] > near["position_mm"]:
        raise ValueError(f"far position_mm must be > near position_mm ({near['position_mm']}); got {far['position_mm']}")
    screens = {"near": near, "far": far}
    attrs = {"near_position_mm": near["position_mm"], "far_position_mm": far["position_mm"],
             "convention": "lengths in mm; +z from the source",
             "near_pitch_mm": float(np.sqrt(np.median(near["area"]))),
             "far_pitch_mm": float(np.sqrt(np.median(far["area"]))), "anchor": anchor,
             "through": "screen" if mask_position_mm is None else "mask"}
    near, far = screens[anchor], screens["near" if anchor == "far" else "far"]  # anchor, other
    z1, z2 = near["position_mm"], far["position_mm"]
    attrs["origin_position_mm"] = z1
    check_positive(mask_std_scale, "mask_std_scale", finite=True)
    check_in(edge_rays, "edge_rays", EDGE_RAYS)
    shape = near["ok"].shape
    flag = np.zeros(shape, np.uint8)
    flag[~near["ok"]] = NO_SHADOW_NEAR
    far_ok = far["ok"]
    if far_ok.sum() < 3:
        raise ValueError(f"{'near' if anchor == 'far' else 'far'} screen must have at least 3 pixels with shadow "
                         f"times of both sweeps; got {int(far_ok.sum())}: check that screen's sweeps")
    magnification = far_magnification(far["mask"], far["xy"], far_ok)
    interpolate = LinearNDInterpolator(far["mask"][far_ok], np.c_[far["xy"][far_ok], far["mask_std"][far_ok],
                                                                  magnification[far_ok]])
    matched = np.full(shape + (4,), np.nan)
    matched[near["ok"]] = interpolate(near["mask"][near["ok"]])
    # the far point itself: C1 cubic on the same triangulation (the mask -> screen map curves
    # within a far pixel near the caustics; a piecewise-linear point bends the ray there).
    # Where the cubic is undefined (its gradients at a degenerate, noise-folded triangle), the
    # linear point stays.
    cubic = CloughTocher2DInterpolator(interpolate.tri, far["xy"][far_ok])(near["mask"][near["ok"]])
    linear = matched[near["ok"], :2]
    matched[near["ok"], :2] = np.where(np.all(np.isfinite(cubic), -1, keepdims=True), cubic, linear)
    no_match = near["ok"] & ~np.all(np.isfinite(matched[..., :3]), axis=-1)
    flag[no_match] = NO_MATCH_FAR
    saturated = (flag == OK) & ~np.isfinite(near["irradiance"])
    flag[saturated] = SATURATED
    good = flag == OK
    x1 = near["xy"]
    origin = np.concatenate([x1, np.full(shape + (1,), z1)], -1)
    if mask_position_mm is None:
        measured = np.where(good[..., None], (matched[..., :2] - x1) / (z2 - z1), np.nan)
        noise = direction_noise(near["mask_std"], matched[..., 2], matched[..., 3], separation_mm=abs(z2 - z1))
    else:
        lever = z1 - mask_position_mm
        centroid = flux_centroids(x1, near["irradiance"], footprint_variance=footprint_variance)
        measured = np.where(good[..., None], (centroid - near["mask"]) / lever, np.nan)
        noise = near["mask_std"] / np.sqrt(2.0) / lever  # mask_std: both sweeps in quadrature
    noise = np.where(good, noise, np.nan)
    noise = np.where(np.isfinite(noise) | ~good, noise, np.nanmedian(noise) if np.isfinite(noise).any() else 1.0)
    if smooth_directions or edge_rays == "fit":
        fitted = fit_directions(measured, noise)
    slope, slope_std = measured, noise
    if smooth_directions:
        slope, slope_std = fitted["direction"], fitted["direction_std"]
    edge = ~good
    if edge_rays == "fit":
        slope = np.where(edge[..., None], fitted["direction"], slope)
        slope_std = np.where(edge, fitted["direction_std"], slope_std)
    elif edge_rays == "nearest" and good.any():
        _, (ri, ci) = distance_transform_edt(~good, return_indices=True)
        slope = np.where(edge[..., None], slope[ri, ci], slope)
        slope_std = np.where(edge, slope_std[ri, ci], slope_std)
    # a ray left without a direction carries no flux; its tube corners (shared with its
    # neighbours) take the nearest direction so that the neighbours' tubes stay closed
    carries = np.all(np.isfinite(slope), -1) & (good | (edge_rays != "drop"))
    if carries.any() and not carries.all():
        _, (ri, ci) = distance_transform_edt(~np.all(np.isfinite(slope), -1), return_indices=True)
        slope = slope[ri, ci]
    direction = np.concatenate([slope, np.ones(shape + (1,))], -1)
    irradiance = np.where(np.isfinite(near["irradiance"]), near["irradiance"], np.nan)
    # a dark pixel's HDR estimate scatters around 0 with the read noise; a tube carries no negative flux
    flux = np.maximum(irradiance, 0.0) * near["area"] * 1e-6
    flux = np.where(carries, flux, 0.0)
    std = np.hypot(near["mask_std"], matched[..., 2])
    confidence = np.where(good, np.exp(-0.5 * (std / mask_std_scale) ** 2), 0.0)
    mask = np.where(good[..., None], near["mask"], np.nan)
    dims2, dims3 = ("row", "col"), ("row", "col", "axis")
    return xr.Dataset(
        {
            "origin": (dims3, origin, {"units": "mm", "long_name": "ray origin on the anchor screen"}),
            "direction": (dims3, direction, {"units": "1", "long_name": "ray direction (dz = 1)"}),
            "irradiance": (dims2, irradiance, {"units": "lx", "long_name": "anchor-screen irradiance"}),
            "flux": (dims2, flux, {"units": "lm", "long_name": "flux of the ray tube through the pixel"}),
            "mask": (("row", "col", "mask_axis"), mask, {"units": "mm", "long_name": "mask point of the ray"}),
            "direction_std": (dims2, slope_std, {"units": "1", "long_name": "per-axis std of the ray direction"}),
            "confidence": (dims2, confidence, {"units": "1", "long_name": "ray confidence from the shadow-time noise"}),
            "flag": (dims2, flag, {"long_name": "ray reason code",
                                   "flag_values": list(REASONS), "flag_meanings": " ".join(REASONS.values())}),
        },
        coords={"row": np.arange(shape[0]), "col": np.arange(shape[1]), "axis": ["x", "y", "z"],
                "mask_axis": ["x", "y"]},
        attrs=attrs,
    )


def write_rays(path, rays):
    """Write a rays dataset as netCDF-4 (h5netcdf engine), atomically; return the path."""
    with atomic_path(path) as tmp:
        rays.to_netcdf(tmp, engine="h5netcdf")
    return path
