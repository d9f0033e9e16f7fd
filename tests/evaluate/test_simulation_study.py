"""Tests of shadowcam.evaluate.simulation_study and the ``shadowcam evaluate`` step.

A reduced study (two levels per factor, 48 x 48 camera) run through the CLI; the
facts checked are physical: errors against the exact ground truth grow with each
degradation, and added shadow-time noise adds in quadrature to the dual-coordinate error.
"""

import numpy as np
import pytest
import xarray as xr

from shadowcam.cli import main
from shadowcam.evaluate.simulation_study import FACTORS, StudySetting, run_study

SIZE = 48
LEVELS = {"frames": [32, 12], "thickness": [1, 10], "time_noise": [0, 2], "path_noise": [0, 10],
          "exposure": [0.8, 0.01], "bit_depth": [8, 16], "light_size": [0, 16]}


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("evaluate")
    params = ('{"levels": %s, "size": %d, "baseline": {"frames": 32}}'
              % (str(LEVELS).replace("'", '"'), SIZE))
    code = main(["evaluate", "--params", params, "--out", str(out / "study.nc"),
                 "--figures", str(out / "figures")])
    assert code == 0
    with xr.open_dataset(out / "study.nc", engine="h5netcdf") as ds:
        return ds.load(), out


def _metric(ds, factor, level, name):
    return float(ds[name].sel(factor=factor, level=level))


def test_study_dataset_and_figures(study):
    ds, out = study
    assert list(ds["factor"].values) == list(FACTORS)
    assert ds.sizes == {"factor": len(FACTORS), "level": 2}
    np.testing.assert_array_equal(ds["value"].sel(factor="thickness").values, [1, 10])
    assert (ds["status"].values == "ok").all()
    assert ds.attrs["step"] == "evaluate"
    for factor in FACTORS:
        assert (out / "figures" / f"study_{factor}.png").stat().st_size > 1000


def test_baseline_matches_ground_truth(study):
    ds, _ = study
    # noise-free thinnest wire, point light: (u, v) within a fraction of a dual pixel
    assert _metric(ds, "time_noise", 0, "dual_coord_rmse") < 0.35
    assert _metric(ds, "time_noise", 0, "dual_coord_coverage") > 0.95
    assert _metric(ds, "time_noise", 0, "shadow_time_p95") < 0.4
    # the masked error is smaller than the whole-image error (holes and unseen parts)
    assert _metric(ds, "time_noise", 0, "rel_rmse_masked") < _metric(ds, "time_noise", 0,
                                                                      "rel_rmse_whole")


def test_time_noise_adds_in_quadrature(study):
    ds, _ = study
    clean = _metric(ds, "time_noise", 0, "dual_coord_rmse")
    noisy = _metric(ds, "time_noise", 1, "dual_coord_rmse")
    expected = np.sqrt(clean**2 + 2 * 2.0**2)  # independent N(0, 2^2) on t_u and t_v
    assert noisy == pytest.approx(expected, rel=0.08)


@pytest.mark.parametrize("factor", ["thickness", "path_noise", "exposure", "light_size"])
def test_each_degradation_shows_as_error_or_as_flagged_pixels(study, factor):
    # never silently fine: the (u, v) error grows, or the pipeline flags the pixels
    # (thick wire, large source: the dip no longer fits the tracker window -> wide_dip)
    ds, _ = study
    grows = (_metric(ds, factor, 1, "dual_coord_rmse")
             > _metric(ds, factor, 0, "dual_coord_rmse") + 0.5)
    flagged = (_metric(ds, factor, 1, "dual_coord_coverage")
               < _metric(ds, factor, 0, "dual_coord_coverage") - 0.3)
    assert grows or flagged


def test_a_wire_too_thick_for_the_window_is_flagged_not_timed(study):
    # thickness 10 = a dip about 10 frames wide, the default window 9 frames
    ds, _ = study
    assert _metric(ds, "thickness", 0, "dual_coord_coverage") > 0.95
    assert _metric(ds, "thickness", 1, "dual_coord_coverage") < 0.2


def test_quantisation_alone_barely_matters_at_good_exposure(study):
    ds, _ = study
    a, b = (_metric(ds, "bit_depth", i, "dual_coord_rmse") for i in (0, 1))
    assert abs(a - b) < 0.05


def test_unusable_settings_are_flagged_not_guessed():
    # 5 frames per sweep: no pixel keeps 3 unshadowed frames, the pipeline refuses
    ds = run_study({"frames": [5]}, size=24, supersample=1)
    assert str(ds["status"].values[0, 0]).startswith("failed:")
    assert "too short" in str(ds["status"].values[0, 0])  # not blamed on the sweep directions
    assert np.isnan(ds["dual_coord_rmse"].values[0, 0])


def test_invalid_inputs_raise():
    with pytest.raises(ValueError, match="exposure"):
        StudySetting(exposure=2.0)
    with pytest.raises(ValueError, match="levels"):
        run_study({"speed": [1]})
