import numpy as np
import pytest
import xarray as xr

from shadowcam.lightfield.photometry_export import tangent_grid_intensity, write_photometry


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


def test_tangent_grid_intensity_of_an_isotropic_source():
    pitch = 0.01
    n = 101
    t = (np.arange(n) - 50) * pitch
    cos3 = (1 + t[None, :] ** 2 + t[:, None] ** 2) ** -1.5
    flux = 7.0 * pitch**2 * cos3  # 7 cd everywhere
    assert np.allclose(tangent_grid_intensity(flux, pitch, np.array([0.0, 10.0, 20.0]), np.array([0, 45, 200])), 7.0)
