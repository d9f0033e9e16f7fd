"""The source's far-field candela table and its IES LM-63-2002 and EULUMDAT files.

The far field is the rays' flux per solid angle: the flux-conserving rendering
(:func:`shadowcam.lightfield.render.irradiance_on_plane`) on a plane far beyond the
source, whose grid is a tangent-plane grid of directions (pitch ``tan(bin)``); a bin's
solid angle is ``pitch**2 * cos(theta)**3``. Angles follow photometric type C with the
source's optical axis (+z) as nadir: vertical angle ``gamma`` (= theta) from the axis,
horizontal angle ``C`` (= phi) from the screen's +x (col) axis towards +y (rows).

Offers
------
tangent_grid_intensity : intensity (cd) at (theta, phi) from a flux grid over tangent-plane directions.
far_field_table : the candela table ``(C, gamma)`` of a rays dataset, as a DataArray.
format_ies : IES LM-63-2002 text of a candela table.
format_ldt : EULUMDAT text of a candela table.
write_photometry : write a table as ``.ies`` or ``.ldt`` (chosen by suffix), atomically.
"""

from pathlib import Path

import numpy as np
import xarray as xr
from scipy.ndimage import map_coordinates

from shadowcam._shared.atomic import atomic_path
from shadowcam._shared.validation import check_array, check_in, check_positive
from shadowcam.lightfield.render import irradiance_on_plane

#: distance of the far plane, mm (the source's size is negligible against it)
FAR_DISTANCE_MM = 1.0e7


def tangent_grid_intensity(flux, pitch, theta, phi):
    """Intensity (cd) in directions from a grid of flux binned over tangent-plane directions.

    Parameters
    ----------
    flux : (S, S) ndarray
        Flux (lm) per bin; bin ``(i, j)`` is centred at ``tan`` coordinates
        ``((j - (S-1)/2) * pitch, (i - (S-1)/2) * pitch)`` (x along cols, y along rows).
    pitch : float
        Bin pitch in tangent units.
    theta, phi : ndarray
        Directions in degrees (broadcast together).

    Returns
    -------
    ndarray
        Intensity in cd, bilinearly interpolated (0 outside the grid).
    """
    flux = check_array(flux, "flux", ndim=2)
    check_positive(pitch, "pitch", finite=True)
    h, w = flux.shape
    tx = (np.arange(w) - (w - 1) / 2) * pitch
    ty = (np.arange(h) - (h - 1) / 2) * pitch
    cos3 = (1.0 + tx[None, :] ** 2 + ty[:, None] ** 2) ** -1.5
    intensity = flux / (pitch**2 * cos3)
    theta, phi = np.broadcast_arrays(np.radians(theta), np.radians(phi))
    t = np.tan(theta)
    cols = t * np.cos(phi) / pitch + (w - 1) / 2
    rows = t * np.sin(phi) / pitch + (h - 1) / 2
    return map_coordinates(intensity, [rows.ravel(), cols.ravel()], order=1, cval=0.0).reshape(theta.shape)


def far_field_table(rays, *, vertical_angles, horizontal_angles, bin_deg=1.0):
    """Candela table of the source described by a rays dataset.

    Parameters
    ----------
    rays : xarray.Dataset
        See :func:`shadowcam.lightfield.rays.rays_dataset`.
    vertical_angles : (V,) array_like, keyword-only
        Gamma (from the optical axis), degrees in ``[0, 90)``.
    horizontal_angles : (Hz,) array_like, keyword-only
        C angles, degrees in ``[0, 360]``.
    bin_deg : float, keyword-only
        Angular resolution of the tangent-plane grid near the axis, degrees.

    Returns
    -------
    xarray.DataArray
        ``(C, gamma)`` intensities in cd.
    """
    gamma = check_array(vertical_angles, "vertical_angles", ndim=1, dtype_kind="iuf").astype(np.float64)
    c = check_array(horizontal_angles, "horizontal_angles", ndim=1, dtype_kind="iuf").astype(np.float64)
    if gamma.size == 0 or not (gamma.min() >= 0 and gamma.max() < 90):
        raise ValueError(f"vertical_angles must lie in [0, 90) degrees; got {gamma.min()}..{gamma.max()}")
    if c.size == 0 or not (c.min() >= 0 and c.max() <= 360):
        raise ValueError(f"horizontal_angles must lie in [0, 360] degrees; got {c.min()}..{c.max()}")
    check_positive(bin_deg, "bin_deg", finite=True)
    pitch = np.tan(np.radians(bin_deg))
    direction = rays["direction"].values
    slopes = np.abs(direction[..., :2] / direction[..., 2:3])
    extent = float(np.nanmax(slopes)) * 1.05 + 2 * pitch
    size = int(np.ceil(2 * extent / pitch)) + 3
    plane = irradiance_on_plane(rays, centre=(0.0, 0.0, FAR_DISTANCE_MM), shape=(size, size),
                                pixel_size=pitch * FAR_DISTANCE_MM)
    flux = plane.values.astype(np.float64) * (pitch * FAR_DISTANCE_MM * 1e-3) ** 2
    table = tangent_grid_intensity(flux, pitch, gamma[None, :], c[:, None])
    return xr.DataArray(table, dims=("C", "gamma"), coords={"C": c, "gamma": gamma},
                        attrs={"units": "cd", "long_name": "luminous intensity",
                               "photometric_type": "C (nadir = optical axis +z)", "bin_deg": float(bin_deg)})


def _numbers(values, per_line=10, fmt="{:.6g}"):
    values = [fmt.format(float(v)) for v in values]
    return "\n".join(" ".join(values[i:i + per_line]) for i in range(0, len(values), per_line))


def _checked_table(table):
    values = check_array(table.values, "table", ndim=2, dtype_kind="f")
    if table.dims != ("C", "gamma"):
        raise ValueError(f"table must have dims ('C', 'gamma'); got {table.dims}")
    if not np.all(np.isfinite(values)) or values.min() < 0:
        raise ValueError("table must hold finite intensities >= 0; got NaN, infinite or negative values")
    return values


def format_ies(table, *, name="shadowcam light field"):
    """IES LM-63-2002 text of a ``(C, gamma)`` candela table (absolute photometry, type C)."""
    values = _checked_table(table)
    c = table["C"].values
    gamma = table["gamma"].values
    lines = ["IESNA:LM-63-2002", "[TEST] shadowcam light-field capture", "[MANUFAC] shadowcam",
             f"[LUMINAIRE] {name}", "TILT=NONE",
             # lamps, lumens per lamp (-1: absolute), multiplier, nV, nH, type C, metres, w, l, h
             f"1 -1 1 {gamma.size} {c.size} 1 2 0 0 0",
             "1 1 0",
             _numbers(gamma), _numbers(c)]
    lines += [_numbers(row) for row in values]
    return "\n".join(lines) + "\n"


def format_ldt(table, *, name="shadowcam light field"):
    """EULUMDAT text of a ``(C, gamma)`` candela table.

    C planes must be equally spaced from 0 and cover ``[0, 360)`` (no symmetry), gamma
    equally spaced from 0. Intensities are stored in cd/klm of the lamp flux, which is
    the table's integral over the sphere part it covers.
    """
    values = _checked_table(table)
    c = table["C"].values
    gamma = table["gamma"].values
    dc = c[1] - c[0] if c.size > 1 else 360.0
    if c[0] != 0 or not np.allclose(np.diff(c), dc) or not np.isclose(c[-1] + dc, 360.0):
        raise ValueError(f"table C angles must be equally spaced over [0, 360); got {c.tolist()}")
    dg = gamma[1] - gamma[0] if gamma.size > 1 else 0.0
    if gamma[0] != 0 or not np.allclose(np.diff(gamma), dg):
        raise ValueError(f"table gamma angles must be equally spaced from 0; got {gamma.tolist()}")
    g = np.radians(gamma)
    band = np.radians(dg) * np.sin(g) if gamma.size > 1 else np.zeros_like(g)
    flux = float(np.sum(values.mean(axis=0) * band) * 2 * np.pi)
    check_positive(flux, "table flux")
    header = ["shadowcam", "1", "0", str(c.size), f"{dc:g}", str(gamma.size), f"{dg:g}",
              "shadowcam light field", name, "1", "source.ldt", "shadowcam",
              "0", "0", "0", "0", "0", "0", "0", "0", "0",  # dimensions and luminous-area heights, mm
              "100", "100", "1", "0", "1", "1",  # DFF %, LORL %, conversion factor, tilt, lamp sets, lamps
              "light-field capture", f"{flux:.6g}", "0", "0", "0"]  # lamp type, flux lm, CCT, CRI, W
    header += ["0"] * 10
    body = [f"{v:g}" for v in c] + [f"{v:g}" for v in gamma]
    body += [f"{v:.6g}" for v in (values * 1000.0 / flux).ravel()]
    return "\r\n".join(header + body) + "\r\n"


def write_photometry(path, table, *, name="shadowcam light field"):
    """Write a candela table as IES (``.ies``) or EULUMDAT (``.ldt``), atomically; return the path."""
    path = Path(path)
    check_in(path.suffix.lower(), "path suffix", (".ies", ".ldt"))
    text = format_ies(table, name=name) if path.suffix.lower() == ".ies" else format_ldt(table, name=name)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="latin-1", newline="")
    return path
