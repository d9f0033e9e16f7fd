"""Workflow test: dual_view.viewpoints gives one dual view per viewpoint across the dip interval."""

import numpy as np
import pytest
import xarray as xr

DS = "synthetic_tiny"
pytestmark = pytest.mark.slow  # runs the lab DAG


def test_each_viewpoint_gets_its_shadow_times_and_dual_view(tmp_path, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path)
    config = ["--config", f"datasets=[{DS}]", 'dual_view={"viewpoints": ["entry", "exit", "centre"]}']
    result = snakemake(["--cores", "2", *config], workdir)
    assert result.returncode == 0, result.stdout[-4000:]
    with xr.open_dataset(workdir / f"results/{DS}/shadow_time.nc") as main:
        entry, exit_ = main["interval_entry"].values, main["interval_exit"].values
    for name, fraction in (("entry", 0.0), ("exit", 1.0), ("centre", 0.5)):
        folder = workdir / f"results/{DS}/viewpoints/{name}"
        with xr.open_dataset(folder / "shadow_time.nc") as view:
            np.testing.assert_allclose(view["shadow_time"].values, entry + fraction * (exit_ - entry),
                                       rtol=1e-6, equal_nan=True)
            assert view.attrs["viewpoint_fraction"] == fraction
        for stem in ("dual_coords.nc", "dual_view.nc", "dual_view.png"):
            assert (folder / stem).is_file()
    # the exit view sees each point later in each sweep than the entry view: its dual
    # coordinates are larger by the interval's length
    with xr.open_dataset(workdir / f"results/{DS}/viewpoints/entry/dual_coords.nc") as a, \
            xr.open_dataset(workdir / f"results/{DS}/viewpoints/exit/dual_coords.nc") as b:
        shift = (b["u"] - a["u"]).values
    assert np.nanmedian(shift) > 0.5
