import numpy as np
import xarray as xr

from shadowcam.lightfield.render import irradiance_on_plane


def _point_source_rays(intensity, z=100.0, n=161, half=60.0):
    """Rays of an isotropic point source at the origin, on a grid of the plane z."""
    x = np.linspace(-half, half, n)
    xx, yy = np.meshgrid(x, x, indexing="xy")
    pitch = x[1] - x[0]
    d2 = xx**2 + yy**2 + z**2
    irradiance = intensity * z / d2**1.5  # I cos / d^2, d in m -> lux with I in cd
    irradiance = irradiance * 1e6
    origin = np.stack([xx, yy, np.full_like(xx, z)], -1)
    direction = np.stack([xx / z, yy / z, np.ones_like(xx)], -1)
    return xr.Dataset({"origin": (("row", "col", "axis"), origin),
                       "direction": (("row", "col", "axis"), direction),
                       "flux": (("row", "col"), irradiance * pitch**2 * 1e-6)})


def test_inverse_square_and_cosine_on_a_tilted_plane():
    intensity = 100.0
    rays = _point_source_rays(intensity)
    tilt = np.radians(30)
    normal = np.array([np.sin(tilt), 0.0, np.cos(tilt)])
    centre = np.array([0.0, 0.0, 250.0])
    plane = irradiance_on_plane(rays, centre=centre, normal=normal, shape=(40, 40), pixel_size=2.0)
    # analytic irradiance at the grid points: I cos(angle to normal) / d^2
    up = np.array([0.0, 1.0, 0.0])
    e_row = up - (up @ normal) * normal
    e_row /= np.linalg.norm(e_row)
    e_col = np.cross(e_row, normal)
    rr, cc = np.meshgrid(plane["y"].values, plane["x"].values, indexing="ij")
    points = centre + rr[..., None] * e_row + cc[..., None] * e_col
    d = np.linalg.norm(points, axis=-1)
    truth = intensity * np.abs(points @ normal) / d / (d * 1e-3) ** 2
    inner = (slice(2, -2), slice(2, -2))
    error = np.abs(plane.values[inner] / truth[inner] - 1)
    assert np.median(error) < 3e-3 and error.max() < 0.02


def test_splat_tubes_of_folded_tubes_is_never_below_zero_and_keeps_the_flux():
    # noisy, folded tubes (as direction noise folds a far field's tubes): the exact-area shares of
    # a flux >= 0 are >= 0 (a cell at -1e-11 cd made the captured light field's IES table refuse)
    from shadowcam.lightfield.render import splat_tubes

    for seed in range(5):
        rng = np.random.default_rng(seed)
        v, u = np.mgrid[:40, :40] * 0.3 - 6.0
        u, v = u + rng.normal(0, 0.4, u.shape), v + rng.normal(0, 0.4, v.shape)
        flux = rng.uniform(0, 1, u.shape)
        grid = splat_tubes(u, v, flux, shape=(40, 40), pitch=0.5)   # 20 x 20 chart units: every tube inside
        assert grid.min() >= 0.0
        assert np.isclose(grid.sum(), flux.sum(), rtol=1e-9)
