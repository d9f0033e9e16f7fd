"""The source's far field (intensity over directions), its candela table and IES / EULUMDAT files.

The intensity in a direction is the irradiance times ``d**2`` on a screen at distance
``d -> infinity``: each ray tube's flux spread over its solid-angle footprint. The
directions are charted by Lambert's azimuthal equal-area projection about the optical
axis (+z), ``(x, y) = sqrt(2 / (1 + d_z)) (d_x, d_y)`` for unit ``d``, in which area is
solid angle; the tubes are splatted on a square grid of that chart by exact area shares
(:func:`shadowcam.lightfield.render.splat_tubes`, the code of the screen renders), so a
cell's intensity is its flux over its area (sr), with no Jacobian approximation. The
cell size is the angular resolution the capture supports (:func:`capture_resolution_deg`):
the angular width of the light through one near-screen and one far-screen camera pixel.
Angles follow photometric type C with the optical axis as nadir: vertical angle
``gamma`` (= theta) from the axis, horizontal angle ``C`` (= phi) from the screen's +x
(col) axis towards +y (rows).

Offers
------
equal_area_chart : chart coordinates of directions.
capture_resolution_deg : the angular resolution of a two-screen capture.
far_field_grid : intensity (cd) per equal-area cell of a grid of ray tubes, as a DataArray.
sample_far_field : a far-field grid sampled at (theta, phi).
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
from shadowcam.lightfield.render import splat_tubes


def equal_area_chart(direction):
    """Lambert azimuthal equal-area coordinates ``x, y`` of directions ``(..., 3)`` about +z.

    Area in the chart is solid angle (sr); near the axis the coordinates are radians.
    """
    d = np.asarray(direction, np.float64)
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.sqrt(2.0 / (1.0 + d[..., 2]))
    return k * d[..., 0], k * d[..., 1]


def _chart_of_angles(theta, phi):
    theta, phi = np.broadcast_arrays(np.radians(theta), np.radians(phi))
    rho = 2.0 * np.sin(theta / 2.0)
    return rho * np.cos(phi), rho * np.sin(phi)


def capture_resolution_deg(near_pitch_mm, far_pitch_mm, separation_mm):
    """Angular resolution of a two-screen capture, degrees: ``(p_near + p_far) / separation``.

    Light through one near-screen and one far-screen camera pixel (pitches ``p``, mm on
    the screens) spans this angle; finer structure of the far field is not resolved.
    """
    for value, name in ((near_pitch_mm, "near_pitch_mm"), (far_pitch_mm, "far_pitch_mm"),
                        (separation_mm, "separation_mm")):
        check_positive(value, name, finite=True)
    return float(np.degrees((near_pitch_mm + far_pitch_mm) / separation_mm))


def far_field_grid(direction, flux, *, resolution_deg, size=None):
    """Intensity of a grid of ray tubes, per cell of the equal-area chart.

    Parameters
    ----------
    direction : (H, W, 3) ndarray
        Direction of the ray at each tube's centre (any length, +z forward).
    flux : (H, W) ndarray
        Flux of each tube, lm (non-finite: dropped).
    resolution_deg : float, keyword-only
        Cell size, degrees of the chart near the axis (cells are ``radians(resolution_deg)**2`` sr).
    size : int, optional, keyword-only
        Cells per side (centred on the axis); default: enough to hold every direction.

    Returns
    -------
    xarray.DataArray
        ``(row, col)`` intensity in cd (flux over the cell's solid angle), with chart
        coordinates ``y`` (rows) and ``x`` (cols).
    """
    direction = check_array(direction, "direction", ndim=3)
    flux = check_array(flux, "flux", shape=direction.shape[:2])
    check_positive(resolution_deg, "resolution_deg", finite=True)
    pitch = np.radians(resolution_deg)
    x, y = equal_area_chart(direction)
    if size is None:
        reach = float(np.nanmax(np.hypot(x, y)))
        size = 2 * int(np.ceil(reach / pitch)) + 5
    elif not (int(size) == size and size >= 1):
        raise ValueError(f"size must be a positive int; got {size!r}")
    size = int(size)
    values = splat_tubes(x, y, flux, shape=(size, size), pitch=pitch) / pitch**2
    axis = (np.arange(size) - (size - 1) / 2) * pitch
    return xr.DataArray(values, dims=("row", "col"), coords={"y": ("row", axis), "x": ("col", axis)},
                        attrs={"units": "cd", "long_name": "luminous intensity per equal-area cell",
                               "chart": "Lambert azimuthal equal-area about +z", "resolution_deg": float(resolution_deg)})


def sample_far_field(grid, theta, phi):
    """Bilinear samples of a :func:`far_field_grid` at ``theta`` (from the axis), ``phi`` (from +x), degrees."""
    values = check_array(np.asarray(grid), "grid", ndim=2)
    pitch = np.radians(float(grid.attrs["resolution_deg"]))
    x, y = _chart_of_angles(theta, phi)
    h, w = values.shape
    cols = x / pitch + (w - 1) / 2
    rows = y / pitch + (h - 1) / 2
    return map_coordinates(values, [rows.ravel(), cols.ravel()], order=1, cval=0.0).reshape(x.shape)


def rays_resolution_deg(rays):
    """:func:`capture_resolution_deg` of a rays dataset (its screens' camera pitches and positions)."""
    missing = [k for k in ("near_pitch_mm", "far_pitch_mm") if k not in rays.attrs]
    if missing:
        raise ValueError(f"rays dataset lacks the attributes {missing}: write it again with "
                         "lightfield-rays, or pass resolution_deg")
    return capture_resolution_deg(rays.attrs["near_pitch_mm"], rays.attrs["far_pitch_mm"],
                                  rays.attrs["far_position_mm"] - rays.attrs["near_position_mm"])


def far_field_table(rays, *, vertical_angles, horizontal_angles, resolution_deg=None):
    """Candela table of the source described by a rays dataset.

    Parameters
    ----------
    rays : xarray.Dataset
        See :func:`shadowcam.lightfield.rays.rays_dataset`.
    vertical_angles : (V,) array_like, keyword-only
        Gamma (from the optical axis), degrees in ``[0, 90)``.
    horizontal_angles : (Hz,) array_like, keyword-only
        C angles, degrees in ``[0, 360]``.
    resolution_deg : float, optional, keyword-only
        Cell size of the :func:`far_field_grid`; default the capture's (:func:`rays_resolution_deg`).

    Returns
    -------
    xarray.DataArray
        ``(C, gamma)`` intensities in cd (the grid sampled bilinearly).
    """
    gamma = check_array(vertical_angles, "vertical_angles", ndim=1, dtype_kind="iuf").astype(np.float64)
    c = check_array(horizontal_angles, "horizontal_angles", ndim=1, dtype_kind="iuf").astype(np.float64)
    if gamma.size == 0 or not (gamma.min() >= 0 and gamma.max() < 90):
        raise ValueError(f"vertical_angles must lie in [0, 90) degrees; got {gamma.min()}..{gamma.max()}")
    if c.size == 0 or not (c.min() >= 0 and c.max() <= 360):
        raise ValueError(f"horizontal_angles must lie in [0, 360] degrees; got {c.min()}..{c.max()}")
    if resolution_deg is None:
        resolution_deg = rays_resolution_deg(rays)
    grid = far_field_grid(rays["direction"].values, rays["flux"].values, resolution_deg=resolution_deg)
    table = sample_far_field(grid, gamma[None, :], c[:, None])
    return xr.DataArray(table, dims=("C", "gamma"), coords={"C": c, "gamma": gamma},
                        attrs={"units": "cd", "long_name": "luminous intensity",
                               "photometric_type": "C (nadir = optical axis +z)",
                               "resolution_deg": float(resolution_deg)})


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
