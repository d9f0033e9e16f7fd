import numpy as np
import pytest
import xarray as xr

from shadowcam.lightfield.photometry_export import (
    capture_resolution_deg, equal_area_chart, far_field_grid, far_field_table, write_photometry)


def _table():
    c = np.arange(0.0, 360.0, 15.0)
    gamma = np.arange(0.0, 41.0, 2.0)
    values = 1500 * np.exp(-(gamma[None, :] / 18) ** 2) * (1 + 0.3 * np.cos(np.radians(c))[:, None]) + 3.0
    return xr.DataArray(values, dims=("C", "gamma"), coords={"C": c, "gamma": gamma})


def test_ies_read_back_by_photompy(tmp_path):
    photompy = pytest.importorskip("photompy")
    table = _table()
    path = write_photometry(tmp_path / "source.ies", table)
    ies = photompy.IESFile.read(str(path))
    phot = ies.photometry
    thetas, phis = np.asarray(phot.thetas), np.asarray(phot.phis)
    values = np.asarray(phot.values)
    assert np.allclose(thetas, table["gamma"]) and np.allclose(phis, table["C"])
    assert values.shape == table.shape
    assert np.abs(values / table.values - 1).max() < 0.01


def test_ldt_read_back_by_eulumdat_py(tmp_path):
    pyldt = pytest.importorskip("pyldt")
    table = _table()
    path = write_photometry(tmp_path / "source.ldt", table)
    ldt = pyldt.LdtReader.read(path)
    flux = ldt.header.lamp_flux[0] * ldt.header.num_lamps[0]
    candela = np.asarray(ldt.intensities) * flux / 1000.0
    assert np.allclose(ldt.header.c_angles, table["C"]) and np.allclose(ldt.header.g_angles, table["gamma"])
    assert np.abs(candela / table.values - 1).max() < 0.01


def test_bad_table_leaves_no_file(tmp_path):
    table = _table().copy()
    table[0, 0] = np.nan
    with pytest.raises(ValueError, match="table must hold finite intensities"):
        write_photometry(tmp_path / "source.ies", table)
    assert list(tmp_path.iterdir()) == []


def _cos_n_rays(n_power, *, z=100.0, half=50.0, count=201, peak=100.0):
    """Rays of a point source ``I = peak cos(gamma)**n`` through a screen grid at `z` (mm): directions, flux (lm)."""
    t = np.linspace(-half, half, count)
    x, y = np.meshgrid(t, t, indexing="xy")
    r2 = x**2 + y**2 + z**2
    cos = z / np.sqrt(r2)
    area = (t[1] - t[0]) ** 2 * 1e-6
    flux = peak * cos**n_power * cos / (r2 * 1e-6) * area
    return np.stack([x / z, y / z, np.ones_like(x)], -1), flux


def _exact_cell_mean(intensity, grid, sub=24):
    """Mean of ``intensity(gamma_rad)`` over each chart cell of `grid` (sub x sub samples per cell)."""
    pitch = np.radians(grid.attrs["resolution_deg"])
    offsets = (np.arange(sub) + 0.5) / sub - 0.5
    x = grid["x"].values[None, :, None, None] + pitch * offsets[None, None, None, :]
    y = grid["y"].values[:, None, None, None] + pitch * offsets[None, None, :, None]
    gamma = 2 * np.arcsin(np.minimum(np.hypot(x, y) / 2, 1.0))
    return intensity(gamma).mean(axis=(2, 3))


@pytest.mark.parametrize("n_power", [1, 3])
def test_far_field_of_a_cos_n_emitter_is_its_exact_cell_mean(n_power):
    direction, flux = _cos_n_rays(n_power)
    grid = far_field_grid(direction, flux, resolution_deg=1.0)
    cell_sr = np.radians(1.0) ** 2
    assert np.isclose(grid.values.sum() * cell_sr, flux.sum(), rtol=1e-9)  # flux kept
    exact = _exact_cell_mean(lambda g: 100.0 * np.cos(g) ** n_power, grid)
    gamma = 2 * np.degrees(np.arcsin(np.hypot(grid["x"].values[None, :], grid["y"].values[:, None]) / 2))
    inside = gamma < 24.0  # cells well inside the screen's 26.6 deg field
    error = np.abs(grid.values[inside] / exact[inside] - 1)
    assert np.median(error) < 1e-3 and error.max() < 5e-3
    table = far_field_table(xr.Dataset({"direction": (("row", "col", "axis"), direction),
                                        "flux": (("row", "col"), flux)}),
                            vertical_angles=[0.0, 10.0, 20.0], horizontal_angles=[0.0, 45.0, 200.0],
                            resolution_deg=1.0)
    assert np.allclose(table.values, 100.0 * np.cos(np.radians([0.0, 10.0, 20.0])) ** n_power, rtol=5e-3)


def test_equal_area_chart_area_is_solid_angle():
    # a cone of half-angle g covers 2 pi (1 - cos g) sr; in the chart a disc of radius 2 sin(g / 2)
    g = np.radians(35.0)
    x, y = equal_area_chart(np.array([np.sin(g), 0.0, np.cos(g)]))
    assert np.isclose(np.pi * (x**2 + y**2), 2 * np.pi * (1 - np.cos(g)))
    assert np.isclose(capture_resolution_deg(1.0, 2.0, 300.0), np.degrees(0.01))
    with pytest.raises(ValueError, match="separation_mm"):
        capture_resolution_deg(1.0, 2.0, 0.0)
    with pytest.raises(ValueError, match="resolution_deg"):
        far_field_grid(np.ones((2, 2, 3)), np.ones((2, 2)), resolution_deg=-1.0)
