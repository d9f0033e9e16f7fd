"""Ground truth of a rendered light field on the grids its estimate is scored on.

The source's irradiance on each render's plane grid and its intensity on the far field's
equal-area chart, computed once (the ray quadrature is the costly part) and written as one
dataset that the accuracy step and the report figures both read.

Offers
------
truth_dataset : the true irradiance on each render grid and the true far field on the rays' chart.
"""

import numpy as np
import xarray as xr

from shadowcam.lightfield.photometry_export import far_field_grid, rays_resolution_deg


def truth_dataset(source, renders, ray_set):
    """The source's true irradiance on the renders' grids and its far field on the rays' chart.

    Parameters
    ----------
    source : shadowcam.synthetic.lightfield.source.ReflectorSource
        The rendered capture's source (its ``irradiance`` and ``far_field_grid``).
    renders : xarray.Dataset
        :func:`shadowcam.lightfield.stages.render_positions`: ``irradiance (position, row, col)``
        and ``pixel_size (position)`` mm, planes normal to +z centred on the axis.
    ray_set : xarray.Dataset
        Rays of the capture (:func:`shadowcam.lightfield.rays.rays_dataset`): the far field's
        cell size is the capture's angular resolution
        (:func:`~shadowcam.lightfield.photometry_export.rays_resolution_deg`) and its chart
        the size of the rays' own (:func:`~shadowcam.lightfield.photometry_export.far_field_grid`).

    Returns
    -------
    xarray.Dataset
        ``irradiance (position, row, col)`` lux on the renders' grids (``pixel_size`` as theirs);
        ``far_field (chart_row, chart_col)`` cd per equal-area cell, attribute ``resolution_deg``.
    """
    for name, data, keys, step in (("renders", renders, ("irradiance", "pixel_size"), "lightfield-render"),
                                   ("ray_set", ray_set, ("direction", "flux"), "lightfield-rays")):
        missing = [k for k in keys if k not in data]
        if missing:
            raise ValueError(f"{name} lacks the variables {missing}: write it with {step}")
    shape = renders["irradiance"].shape[1:]
    positions = renders["position"].values.astype(np.float64)
    pitches = renders["pixel_size"].values.astype(np.float64)
    irradiance = np.stack([source.irradiance(centre=(0.0, 0.0, float(z)), shape=shape, pixel_size=float(p))
                           for z, p in zip(positions, pitches)])
    resolution = rays_resolution_deg(ray_set)
    size = far_field_grid(ray_set["direction"].values, ray_set["flux"].values, resolution_deg=resolution).shape[0]
    far = source.far_field_grid(resolution_deg=resolution, size=size)
    return xr.Dataset(
        {"irradiance": (("position", "row", "col"), irradiance, {"units": "lx", "long_name": "true irradiance"}),
         "far_field": (("chart_row", "chart_col"), far.values,
                       {"units": "cd", "long_name": "true intensity per equal-area cell", "chart": far.attrs["chart"],
                        "resolution_deg": float(resolution)})},
        coords={"position": ("position", positions, {"units": "mm"}),
                "pixel_size": ("position", pitches, {"units": "mm"})},
        attrs={"resolution_deg": float(resolution)})
