"""A reflector light source with exact ground truth: its ray family, screen irradiance and far field.

The source is described by the ray through each point ``(x, y)`` of the mask plane
``z = z_mask`` (lengths in mm, the optical axis along +z, the source near the origin).
The ray's slope (lateral mm per mm of z) is radial, ``s(r)``, with ``s' = m(r) * (1 +
ripple * cos(2 pi r / ring_period))`` and ``m(r) = slope_max / r0 * sech(r / r0)**2``: the
reflector makes the outer rays nearly parallel and the ripple focuses them into caustic
rings that sharpen with distance (the pattern changes shape, not just scale), plus a
small twist (a tangential slope) so that the rays do not share a point. ``ripple < 1``
keeps one ray per screen point at every distance. The flux density through the mask
(lm / mm^2) has rings of its own and an azimuthal lobe.

Ground truth is computed by tracing a fine regular grid of rays (deterministic
quadrature) and splatting their flux bilinearly onto a pixel grid (screens), or their
tubes by exact area onto the equal-area direction chart (far field).

Offers
------
ReflectorSource : the source (ray family, flux density, ground truth on planes and at infinity).
"""

from dataclasses import dataclass

import numpy as np

from shadowcam.lightfield.photometry_export import far_field_grid, sample_far_field
from shadowcam.lightfield.render import plane_frame, splat_bilinear


@dataclass(frozen=True)
class ReflectorSource:
    """A compact source with a reflector, described at the mask plane.

    Parameters
    ----------
    z_mask : float
        Mask plane distance from the source, mm.
    aperture : float
        Radius of the beam at the mask plane, mm.
    slope_max, r0 : float
        Reflector slope profile ``s(r) ~ slope_max * tanh(r / r0)``.
    ripple, ring_period : float
        Caustic-ring strength (< 1) and radial period at the mask, mm.
    twist : float
        Tangential slope per mm of radius.
    flux_scale : float
        Peak flux density through the mask, lm / mm^2.
    """

    z_mask: float = 50.0
    aperture: float = 10.0
    slope_max: float = 0.25
    r0: float = 8.0
    ripple: float = 0.8
    ring_period: float = 2.5
    twist: float = 0.002
    flux_scale: float = 1.0

    def _slope_table(self):
        r = np.linspace(0.0, self.aperture * 1.2, 24001)
        m = self.slope_max / self.r0 / np.cosh(r / self.r0) ** 2
        ds = m * (1.0 + self.ripple * np.cos(2 * np.pi * r / self.ring_period))
        s = np.concatenate([[0.0], np.cumsum(0.5 * (ds[1:] + ds[:-1]) * np.diff(r))])
        return r, s

    def rays(self, x, y):
        """Directions ``(..., 3)`` (dz = 1) of the rays through mask points ``(x, y)`` mm."""
        r_table, s_table = self._slope_table()
        x = np.asarray(x, np.float64)
        y = np.asarray(y, np.float64)
        r = np.hypot(x, y)
        slope = np.interp(r, r_table, s_table)
        with np.errstate(invalid="ignore", divide="ignore"):
            ux, uy = np.where(r > 0, x / r, 0.0), np.where(r > 0, y / r, 0.0)
        tangential = self.twist * r
        return np.stack([slope * ux - tangential * uy, slope * uy + tangential * ux, np.ones_like(r)], -1)

    def flux_density(self, x, y):
        """Flux per mask area (lm / mm^2) of the rays through mask points ``(x, y)``."""
        x = np.asarray(x, np.float64)
        y = np.asarray(y, np.float64)
        r = np.hypot(x, y)
        phi = np.arctan2(y, x)
        edge = 0.5 * (1.0 - np.tanh((r - self.aperture) / 0.15))
        rings = 0.75 + 0.25 * np.cos(2 * np.pi * r / (1.7 * self.ring_period)) ** 2
        lobe = 1.0 + 0.25 * np.cos(phi - 0.6) * np.clip(r / self.aperture, 0, 1)
        return self.flux_scale * edge * rings * lobe

    def quadrature(self, n):
        """``n x n`` mask points covering the beam: ``x, y, flux`` (lm) per ray, each ``(n*n,)``."""
        half = self.aperture + 1.0
        step = 2 * half / n
        centres = -half + (np.arange(n) + 0.5) * step
        x, y = np.meshgrid(centres, centres, indexing="xy")
        x, y = x.ravel(), y.ravel()
        return x, y, self.flux_density(x, y) * step * step

    def hits(self, x, y, *, centre, normal=(0.0, 0.0, 1.0), up=(0.0, 1.0, 0.0)):
        """Plane coordinates ``(..., 2)`` (mm along the plane's col and row axes) of the rays through ``(x, y)``."""
        origin, e_col, e_row, n = plane_frame(centre, normal, up)
        d = self.rays(x, y)
        p = np.stack([x, y, np.full_like(np.asarray(x, np.float64), self.z_mask)], -1)
        t = ((origin - p) @ n) / (d @ n)
        hit = p + t[..., None] * d - origin
        return np.stack([hit @ e_col, hit @ e_row], -1)

    def irradiance(self, *, centre, shape, pixel_size, normal=(0.0, 0.0, 1.0), up=(0.0, 1.0, 0.0), n=1536):
        """Ground-truth irradiance (lux) on a plane grid, bilinear-splat filtered.

        Parameters
        ----------
        centre : (3,) array_like
            Centre of the grid, mm.
        shape : (rows, cols)
        pixel_size : float
            Grid pitch, mm.
        normal, up : (3,) array_like
            Plane normal and the direction of increasing rows.
        n : int
            Quadrature rays per side.

        Returns
        -------
        (rows, cols) float64 ndarray
        """
        x, y, flux = self.quadrature(n)
        uv = self.hits(x, y, centre=centre, normal=normal, up=up)
        cols = uv[:, 0] / pixel_size + (shape[1] - 1) / 2
        rows = uv[:, 1] / pixel_size + (shape[0] - 1) / 2
        grid = splat_bilinear(rows, cols, flux, shape)
        return grid / (pixel_size * 1e-3) ** 2

    def far_field_grid(self, *, resolution_deg, size=None, n=768):
        """Ground-truth intensity (cd) per cell of the equal-area direction chart.

        The quadrature's ``n x n`` ray tubes splatted exactly as the capture's tubes are
        (:func:`shadowcam.lightfield.photometry_export.far_field_grid`): the integral of
        the intensity over each cell, divided by its solid angle, to within the
        quadrature's tube size. `resolution_deg` and `size` as that function.
        """
        x, y, flux = self.quadrature(n)
        d = self.rays(x, y).reshape(n, n, 3)
        return far_field_grid(d, flux.reshape(n, n), resolution_deg=resolution_deg, size=size)

    def far_field(self, theta, phi, *, resolution_deg, n=768):
        """Ground-truth intensity (cd) in directions ``theta`` (from the axis), ``phi`` (from +x), degrees.

        :meth:`far_field_grid` sampled bilinearly (as a capture's candela table is).
        """
        return sample_far_field(self.far_field_grid(resolution_deg=resolution_deg, n=n), theta, phi)
